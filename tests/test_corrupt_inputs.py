"""Property tests: every bundled example input, corrupted (a cell or value changed, a unit
slip x1e3, another encoding, truncated), gives either a clean result or a RoboboreError whose
message names the file -- never another exception type."""

from __future__ import annotations

import re
import shutil
import warnings
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from robobore.errors import RoboboreError

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"
DATA = ROOT / "src" / "robobore" / "data"
PKG = ROOT / "src" / "robobore"

NUM = re.compile(rb"(?<![A-Za-z_0-9.])-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?(?![A-Za-z_0-9])")


# ----------------------------------------------------------------------------- readers
def _dynamics(p: Path):
    from robobore.dynamics.config import build_process, build_structure, load_dynamics_config

    cfg, _ = load_dynamics_config(p)
    build_structure(cfg, str(p))
    build_process(cfg, str(p))


def _fe(p: Path):
    from robobore.cutting.fe.config import load_fe_config

    load_fe_config(p)


def _fe_boring(p: Path):
    from robobore.cutting.fe.boring3d import load_boring_config

    load_boring_config(p)


def _calibration(p: Path):
    from robobore.cutting.calibrate import load_calibration_config

    load_calibration_config(p)


def _sweep(p: Path):
    from robobore.study.conditions import load_sweep_config

    load_sweep_config(p)


def _paper(p: Path):
    from robobore.study.paper import load_paper_config

    load_paper_config(p)


def _material(p: Path):
    from robobore.material import load_material

    load_material(p)


def _robot(p: Path):
    from robobore.robot.kinematics import load_robot_file

    load_robot_file(p)


def _campaign(p: Path):
    from robobore.robot.campaign_io import read_campaign

    read_campaign(p, robot="irb6600-175-2.55")


def _measured(p: Path):
    from robobore.study.compare import read_measured_csv

    read_measured_csv(p)


def _coefficients(p: Path):
    from robobore.cutting.forces import load_coefficients

    load_coefficients(p)


def _uff(p: Path):
    from robobore.modal.io import load_input

    load_input(p)


#: (bundled file, reader, files that must lie next to it)
TARGETS = {
    "boring_paper": (EX / "boring_paper.toml", _dynamics, ()),
    "lobes_single_point": (EX / "lobes_single_point.toml", _dynamics, ()),
    "fe_orthogonal": (EX / "fe_orthogonal.toml", _fe, ()),
    "fe_boring_paper": (EX / "fe_boring_paper.toml", _fe_boring, ()),
    "calibration": (EX / "calibration_boring_chip.toml", _calibration, ()),
    "sweep_demo": (EX / "sweep_demo.toml", _sweep, ()),
    "paper": (DATA / "paper_example" / "paper.toml", _paper,
              (DATA / "paper_example" / "tc4_fe_coefficients.json",
               DATA / "paper_example" / "measured_synthetic.csv")),
    "material": (PKG / "material" / "library" / "tc4.toml", _material, ()),
    "robot": (PKG / "robot" / "library" / "irb6600-175-2.55.toml", _robot, ()),
    "campaign": (DATA / "campaign_irb6600" / "campaign.csv", _campaign, ()),
    "measured": (DATA / "paper_example" / "measured_synthetic.csv", _measured, ()),
    "coefficients": (DATA / "paper_example" / "tc4_fe_coefficients.json", _coefficients, ()),
    "uff": (DATA / "hammer_test" / "robot_hammer_test.uff", _uff, ()),
}


# ----------------------------------------------------------------------------- corruptions
REPLACEMENTS = [b"nan", b"inf", b"true", b"", b"abc", b"1e308", b"-1", b"0", b"[1, 2]",
                b'"x"']


def _scale(tok: bytes, f: float) -> bytes:
    try:
        return repr(float(tok) * f).encode()
    except ValueError:
        return tok


@st.composite
def corruptions(draw, data: bytes):
    """(description, corrupted bytes)."""
    kind = draw(st.sampled_from(["cell", "x1e3", "x1e-3", "x100", "encoding", "truncate",
                                 "bytes"]))
    nums = list(NUM.finditer(data[:200_000]))
    if kind in ("cell", "x1e3", "x1e-3", "x100") and nums:
        m = nums[draw(st.integers(0, len(nums) - 1))]
        tok = m.group(0)
        new = {"cell": lambda: draw(st.sampled_from(REPLACEMENTS)),
               "x1e3": lambda: _scale(tok, 1e3), "x1e-3": lambda: _scale(tok, 1e-3),
               "x100": lambda: _scale(tok, 100.0)}[kind]()
        return f"{kind} {tok!r}->{new!r} at {m.start()}", data[:m.start()] + new + data[m.end():]
    if kind == "encoding":
        enc = draw(st.sampled_from(["utf-16", "utf-32", "latin-1-bom"]))
        text = data.decode("utf-8", "replace")
        if enc == "latin-1-bom":
            return enc, b"\xff\xfe" + text.replace("e", "\xe9").encode("latin-1", "replace")
        return enc, text.encode(enc)
    if kind == "bytes":
        pos = draw(st.integers(0, max(len(data) - 1, 0)))
        junk = draw(st.binary(min_size=1, max_size=8))
        return f"bytes {junk!r} at {pos}", data[:pos] + junk + data[pos + 1:]
    cut = draw(st.integers(0, max(len(data) - 1, 0)))
    return f"truncate at {cut}", data[:cut]


def _check(name: str, tmp: Path, desc: str, blob: bytes) -> None:
    src, reader, extra = TARGETS[name]
    d = tmp / name
    if d.exists():
        shutil.rmtree(d)
    d.mkdir(parents=True)
    for e in extra:
        shutil.copy(e, d / e.name)
    p = d / src.name
    p.write_bytes(blob)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            reader(p)
    except RoboboreError as exc:
        assert src.name in str(exc), f"{desc}: error does not name the file: {exc}"
    except Exception as exc:  # noqa: BLE001 -- the property under test
        raise AssertionError(f"{name}, {desc}: {type(exc).__name__}: {exc}") from exc


@pytest.mark.parametrize("name", sorted(TARGETS))
def test_bundled_input_is_accepted_as_is(name, tmp_path):
    src = TARGETS[name][0]
    _check(name, tmp_path, "unchanged", src.read_bytes())
    # and it did load (not an error naming the file)
    d = tmp_path / name
    TARGETS[name][1](d / src.name)


def _property(name: str, n: int):
    data = TARGETS[name][0].read_bytes()

    @settings(max_examples=n, deadline=None, derandomize=True,
              suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture,
                                     HealthCheck.data_too_large])
    @given(c=corruptions(data))
    def run(tmp_path_factory, c):
        _check(name, tmp_path_factory.mktemp("c"), *c)

    return run


@pytest.mark.parametrize("name", sorted(TARGETS))
def test_corrupted_input_gives_result_or_error_naming_the_file(name, tmp_path_factory):
    n = 8 if name == "uff" else 30
    _property(name, n)(tmp_path_factory)
