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
    from robobore.cutting.fe.config.orthogonal import load_fe_config

    load_fe_config(p)


def _fe_boring(p: Path):
    from robobore.cutting.fe.config.boring3d import load_boring_config

    load_boring_config(p)


def _calibration(p: Path):
    from robobore.cutting.calibration_config import load_calibration_config

    load_calibration_config(p)


def _sweep(p: Path):
    from robobore.study.conditions import load_sweep_config

    load_sweep_config(p)


def _paper(p: Path):
    from robobore.study.paper_config import load_paper_config

    load_paper_config(p)


def _material(p: Path):
    from robobore.material import load_material

    load_material(p)


def _robot(p: Path):
    from robobore.robot.description import load_robot_file

    load_robot_file(p)


def _campaign(p: Path):
    from robobore.robot.campaign_io import read_campaign

    read_campaign(p, robot="irb6600-175-2.55")


def _measured(p: Path):
    from robobore.study.compare import read_measured_csv

    read_measured_csv(p)


def _coefficients(p: Path):
    from robobore.cutting.coefficient_files import load_coefficients

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


# ----------------------------------------------------------------------------- unit slips
_CAMP = DATA / "campaign_irb6600" / "campaign.csv"
_LINES = _CAMP.read_text().splitlines()
_HEAD = _LINES[0].split(",")
_POS = [c for c in _HEAD if c.endswith("_m")]


@settings(max_examples=25, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(row=st.integers(1, len(_LINES) - 1), col=st.sampled_from(_POS))
def test_campaign_position_in_mm_is_never_silent(tmp_path, row, col):
    """A laser-tracker or load-point position given in mm (x 1e3) in a metre column is an
    error naming the file, the row and the column -- whichever cell it is."""
    from robobore.errors import DataError
    from robobore.robot.campaign_io import read_campaign

    lines = list(_LINES)
    cells = lines[row].split(",")
    j = _HEAD.index(col)
    v = float(cells[j]) * 1e3
    cells[j] = repr(v)
    lines[row] = ",".join(cells)
    p = tmp_path / "campaign.csv"
    p.write_text("\n".join(lines) + "\n")
    if abs(v) <= 50.0:  # a position within 5 cm of the base: mm and m overlap
        return
    with pytest.raises(DataError) as ei:
        read_campaign(p)
    m = str(ei.value)
    assert "campaign.csv" in m and f"row {row}" in m and col in m and "looks like mm" in m


_TC4 = (PKG / "material" / "library" / "tc4.toml").read_text()
_TC4_KEYS = re.findall(r"^(\w+) = (-?[\d.]+)", _TC4, flags=re.M)


@settings(max_examples=25, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(i=st.integers(0, len(_TC4_KEYS) - 1), factor=st.sampled_from([1e3, 1e6, 1e9]))
def test_material_constant_slipped_by_1e3_or_more_is_refused(tmp_path, i, factor):
    """Every constant of the bundled material, multiplied by 1e3, 1e6 or 1e9, is refused
    (except those that are 0, and the reference strain rate, whose plausible range spans
    1e-6 .. 1e6 1/s in published fits)."""
    from robobore.errors import ConfigError
    from robobore.material import load_material

    key, val = _TC4_KEYS[i]
    text = re.sub(rf"^{key} = {re.escape(val)}", f"{key} = {float(val) * factor!r}", _TC4,
                  count=1, flags=re.M)
    p = tmp_path / "m.toml"
    p.write_text(text)
    if float(val) == 0.0 or key == "eps_dot0_per_s":
        return
    with pytest.raises(ConfigError, match=rf"m\.toml.*{key}"):
        load_material(p)
