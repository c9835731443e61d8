"""A corpus of malformed inputs on every input path, run through the CLI (or, for the configs
whose commands run FE simulations or the whole paper study, through their parse step).

    python benchmarks/malformed_corpus.py [--out /tmp/corpus] [--timeout 60] [--workers 2]
                                          [--only TEXT]

The cases come from three generators: this module corrupts every bundled example input (the
list below), ``benchmarks/malformed_corpus_identity.py`` adds the paths that join files
(identity mix-ups of robot, posture, tool point and frame, unit slips in identification and
model files, the planner, FE validation's measured file, the Python API, ``sweep
--scheduler`` with a silent server, CSV separators), and
``benchmarks/malformed_corpus_more.py`` adds the output paths (files where
folders are expected, folders that cannot be created), huge requests (size guards),
encodings and corrupt files on each reader, partial failures (exit code) and durability
(a sweep killed at random points and resumed, a zero-byte result recomputed). ``fe`` and
``calibrate`` commands run with the FE time stepping replaced by a stub (see ``NO_FE``): no
case runs an FE simulation.

Each case is generated from a bundled example input by a documented corruption: a unit slip
on one key or column (m given in mm, N/m in N/um, N/m^2 in N/mm^2, a damping ratio in
percent, GPa in MPa, ...), NaN / a boolean / text / an empty cell, a typo'd section or key,
another encoding (UTF-16), binary junk, truncation, a list where a table is expected, a
pickled NPZ array, a stray same-named file in the current folder, bad command-line options.
Every case runs in its own folder (cwd = a separate sub-folder) under ``--out``.

Outcome classes (one per case):

* ``clear``     -- non-zero exit, no traceback, the error line names the file (or the option)
  and says what was got or expected;
* ``vague``     -- non-zero exit, no traceback, but the message lacks the file/option or the
  expectation;
* ``traceback`` -- a Python traceback was printed;
* ``silent``    -- exit 0 although the input is wrong (a unit slip, NaN, ... accepted), or,
  for the stray-file cases, a result different from the clean run's;
* ``ok``        -- exit 0 on an input that is still valid (a control, a benign truncation)
  with the right result;
* ``rejected``  -- a control (unchanged bundled input) refused;
* ``hang``      -- no answer within ``--timeout`` seconds.

Prints the table of outcomes by class and by input path, and the non-clear cases; writes
all cases with their output to ``<out>/corpus.json``. Throughput: cases per second.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import time
import tomllib
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"
DATA = ROOT / "src" / "robobore" / "data"
PKG = ROOT / "src" / "robobore"
sys.path.insert(0, str(ROOT / "src"))
from robobore.io.config import dump_toml  # noqa: E402

#: parse-only drivers (commands that would run FE simulations or the whole paper study)
PARSE = {
    "fe": "from robobore.cutting.fe.config.orthogonal import load_fe_config as f",
    "fe_boring": "from robobore.cutting.fe.config.boring3d import load_boring_config as f",
    "calibration": "from robobore.cutting.calibration_config import load_calibration_config as f",
    "paper": "from robobore.study.paper_config import load_paper_config as f",
    "material": "from robobore.material import load_material as f",
    "sweep": "from robobore.study.conditions import load_sweep_config as f",
    "measured": "from robobore.study.compare import read_measured_csv as f",
    "plan": "from robobore.plan.config import load_plan_config as f",
}
#: ``fe`` / ``calibrate`` commands with the FE time stepping replaced by a stub: the stub
#: reads the material file as the run's set-up does first (``setup_orthogonal``,
#: ``simulate_boring``), then stops the process. The corpus never runs an FE simulation, and
#: a case that would start one is reported (it must be refused before that).
NO_FE = ("import sys\n"
         "import robobore.cutting.calibrate as c\n"
         "import robobore.cutting.calibration_runs as r\n"
         "import robobore.cutting.fe.models.boring3d as b\n"
         "import robobore.cutting.fe.models.orthogonal as s\n"
         "from robobore.material import load_material\n"
         "def _stub(cfg=None, *a, source=None, **k):\n"
         "    m = getattr(cfg, 'material', None)\n"
         "    if m is not None:\n"
         "        load_material(m.name, source=source)\n"
         "    print('corpus: an FE simulation would start here', file=sys.stderr)\n"
         "    sys.exit(97)\n"
         "s.simulate_orthogonal = b.simulate_boring = r.run_fe_point = c.run_grid = _stub\n"
         "sys.argv[0] = 'robobore'\n"
         "from robobore.cli import main\n"
         "main()\n")
DRIVER = ("import sys\nfrom robobore.errors import RoboboreError\n{imp}\ntry:\n    f(sys.argv[1])\n"
          "except RoboboreError as e:\n    print('error:', e, file=sys.stderr); sys.exit(2)\n")


@dataclass
class Case:
    path_kind: str  # which input path (campaign CSV, process TOML, ...)
    desc: str
    files: dict[str, bytes]  # written into the case folder
    argv: list[str]  # "{d}" is replaced by the case folder
    must_fail: bool  # a wrong input: exit 0 is "silent"
    names: tuple[str, ...]  # what a clear error names (a file name or an option)
    cwd_files: dict[str, bytes] = field(default_factory=dict)  # stray files in the cwd
    same_as: str | None = None  # stray-file cases: the clean run's stdout must match
    control: bool = False
    pattern: str | None = None  # a regular expression the error must match (instead of names)
    mode: str = "error"  # error | partial | script (malformed_corpus_more)
    outcome: str = ""
    rc: int | None = None
    stderr_tail: str = ""


NUM = re.compile(r"(?<![A-Za-z_0-9.\"])-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?(?![A-Za-z_0-9\"])")


def _cli(*args: str) -> list[str]:
    if args and args[0] in ("fe", "calibrate"):
        return [sys.executable, "-c", NO_FE, *args]
    return [sys.executable, "-m", "robobore", *args]


def _parse(kind: str, fname: str) -> list[str]:
    return [sys.executable, "-c", DRIVER.format(imp=PARSE[kind]), "{d}/" + fname]


# ----------------------------------------------------------------------------- slips
#: realistic unit slips by name ending: (factor, words)
SLIPS = [
    ("_N_per_m2", 1e-6, "N/mm^2 for N/m^2"), ("_N_per_m", 1e-6, "N/um for N/m"),
    ("_Nm_per_rad", 1e-3, "N m/mrad"), ("damping_ratio", 100.0, "percent for a ratio"),
    ("_GPa", 1e3, "MPa for GPa"), ("pressure_MPa", 1e6, "Pa for MPa"),
    ("A_MPa", 1e6, "Pa for MPa"), ("B_MPa", 1e6, "Pa for MPa"),
    ("_kg_m3", 1e-3, "g/cm^3 for kg/m^3"), ("feed_mm_per_rev", 1e3, "um/r for mm/r"),
    ("depth_mm", 1e3, "um for mm"), ("depth_of_cut_mm", 1e3, "um for mm"),
    ("_m", 1e3, "mm for m"), ("coherence", 1.7, "coherence > 1"),
]


def _slip_for(key: str) -> tuple[float, str] | None:
    last = [p for p in key.split(".") if p not in ("x", "y", "z", "min", "max", "start",
                                                   "stop") and not p.isdigit()][-1]
    if last in ("K_feed_N_per_m2",):
        return 1e-6, "N/mm^2 for N/m^2"
    for suf, f, w in SLIPS:
        if last.endswith(suf) and (suf.startswith("_") or last == suf or last.endswith(suf)):
            if suf == "_m" and last.endswith(("_per_m", "_N_s_per_m")):
                continue
            return f, w
    return None


def _leaves(d, prefix=""):
    if isinstance(d, dict):
        for k, v in d.items():
            yield from _leaves(v, f"{prefix}.{k}" if prefix else str(k))
    elif isinstance(d, list):
        for i, v in enumerate(d):
            yield from _leaves(v, f"{prefix}.{i}")
    elif isinstance(d, int | float) and not isinstance(d, bool):
        yield prefix, d


def _set(d, key, value):
    parts = key.split(".")
    cur = d
    for p in parts[:-1]:
        cur = cur[int(p)] if isinstance(cur, list) else cur[p]
    last = parts[-1]
    if isinstance(cur, list):
        cur[int(last)] = value
    else:
        cur[last] = value


# ----------------------------------------------------------------------------- generators
def toml_cases(kind: str, src: Path, argv_of, extra: dict[str, bytes] | None = None,
               max_slips: int = 12) -> list[Case]:
    text = src.read_bytes()
    data = tomllib.loads(text.decode())
    fname = src.name
    extra = extra or {}
    cases = [Case(kind, "control: unchanged", {fname: text, **extra}, argv_of(fname), False,
                  (fname,), control=True)]

    def mk(desc, blob, must=True):
        cases.append(Case(kind, desc, {fname: blob, **extra}, argv_of(fname), must, (fname,)))

    leaves = list(_leaves(data))
    slips = [(k, v, _slip_for(k)) for k, v in leaves]
    slips = [(k, v, s) for k, v, s in slips if s is not None and v != 0]
    for k, v, (f, w) in slips[:max_slips]:
        d = tomllib.loads(text.decode())
        _set(d, k, v * f if w != "coherence > 1" else 1.7)
        mk(f"unit slip {k} ({w}): {v!r} -> {v * f!r}", dump_toml(d).encode())
    numeric = [k for k, _ in leaves]
    for i, bad in enumerate(["nan", "true", '"abc"', "inf"]):
        if not numeric:
            break
        k = numeric[(i * 7 + 3) % len(numeric)]
        d = tomllib.loads(text.decode())
        _set(d, k, {"nan": float("nan"), "true": True, '"abc"': "abc",
                    "inf": float("inf")}[bad])
        mk(f"{bad} in {k}", dump_toml(d).encode())
    sections = [k for k, v in data.items() if isinstance(v, dict)]
    if sections:
        s = sections[0]
        mk(f"typo'd section [{s}x]", re.sub(rf"^\[{re.escape(s)}\]", f"[{s}x]",
                                              text.decode(), count=1, flags=re.M).encode())
    mk("UTF-16 encoded", text.decode().encode("utf-16"))
    mk("binary junk", b"\x00\x01\x02\xff\xfe" * 20)
    mk("empty file", b"")
    mk("truncated at 40 %", text[: int(len(text) * 0.4)], must=False)
    return cases


def csv_cases(kind: str, src: Path, argv_of, slip_cols: dict[str, tuple[float, str]],
              bad_cols: list[str]) -> list[Case]:
    text = src.read_text()
    lines = text.splitlines()
    hi = next(i for i, ln in enumerate(lines) if ln and not ln.startswith("#"))
    head = lines[hi].split(",")
    fname = src.name
    cases = [Case(kind, "control: unchanged", {fname: text.encode()}, argv_of(fname), False,
                  (fname,), control=True)]

    def first_nonzero_rows(col: str, k: int = 2) -> list[int]:
        j = head.index(col)
        rows = [r - hi for r in range(hi + 1, len(lines))
                if len(lines[r].split(",")) == len(head) and float(lines[r].split(",")[j]) != 0]
        return rows[:k]

    def with_cell(row: int, col: str, fn) -> bytes:
        ls = list(lines)
        cells = ls[hi + row].split(",")
        j = head.index(col)
        cells[j] = fn(cells[j])
        ls[hi + row] = ",".join(cells)
        return ("\n".join(ls) + "\n").encode()

    def with_column(col: str, fn) -> bytes:
        ls = list(lines)
        j = head.index(col)
        for r in range(hi + 1, len(ls)):
            cells = ls[r].split(",")
            if len(cells) == len(head):
                cells[j] = fn(cells[j])
                ls[r] = ",".join(cells)
        return ("\n".join(ls) + "\n").encode()

    for col, (f, w) in slip_cols.items():
        for row in first_nonzero_rows(col):
            cases.append(Case(kind, f"unit slip {col} row {row} ({w})",
                              {fname: with_cell(row, col, lambda c, f=f: repr(float(c) * f))},
                              argv_of(fname), True, (fname,)))
        cases.append(Case(kind, f"unit slip whole column {col} ({w})",
                          {fname: with_column(col, lambda c, f=f: repr(float(c) * f))},
                          argv_of(fname), True, (fname,)))
    for col in bad_cols:
        for bad in ("nan", "true", "abc", "", "inf", "1,5"):
            # an empty amplitude cell in a measured CSV means "not measured" (documented)
            must = not (bad == "" and kind.startswith("measured") and "amplitude" in col)
            cases.append(Case(kind, f"{bad!r} in {col} row 2",
                              {fname: with_cell(2, col, lambda c, b=bad: b)}, argv_of(fname),
                              must, (fname,)))
    cases.append(Case(kind, "UTF-16 encoded", {fname: text.encode("utf-16")}, argv_of(fname),
                      True, (fname,)))
    cases.append(Case(kind, "binary junk", {fname: os.urandom(300)}, argv_of(fname), True,
                      (fname,)))
    cases.append(Case(kind, "header only", {fname: (lines[hi] + "\n").encode()}, argv_of(fname),
                      True, (fname,)))
    cases.append(Case(kind, "column renamed", {fname: text.replace(head[-2], head[-2] + "x", 1)
                                               .encode()}, argv_of(fname), True, (fname,)))
    cases.append(Case(kind, "truncated mid-row", {fname: text.encode()[: len(text) // 2 + 3]},
                      argv_of(fname), False, (fname,)))
    return cases


def json_cases(kind: str, fname: str, good: dict, argv, slips: list[tuple[str, float, str]],
               extra: dict[str, bytes] | None = None, names: tuple[str, ...] = ()) -> list[Case]:
    extra = extra or {}
    names = names or (fname,)
    blob = json.dumps(good, indent=1).encode()
    cases = [Case(kind, "control: unchanged", {fname: blob, **extra}, argv, False, names,
                  control=True)]
    for key, f, w in slips:
        d = json.loads(blob)
        cur = d
        parts = key.split(".")
        for p in parts[:-1]:
            cur = cur[int(p)] if isinstance(cur, list) else cur[p]
        last = int(parts[-1]) if isinstance(cur, list) else parts[-1]
        cur[last] = cur[last] * f if w != "set" else f
        cases.append(Case(kind, f"{key}: {w}", {fname: json.dumps(d).encode(), **extra}, argv,
                          True, names))
    cases.append(Case(kind, "not JSON", {fname: blob[:-5], **extra}, argv, True, names))
    cases.append(Case(kind, "UTF-16 encoded", {fname: blob.decode().encode("utf-16"), **extra},
                      argv, True, names))
    cases.append(Case(kind, "a list at top level", {fname: b"[1, 2, 3]", **extra}, argv, True,
                      names))
    return cases


#: the description prefixes of benchmarks/malformed_corpus_measured.py
MEASURED_PREFIXES = ("meas:", "cut:", "cmp:", "paper:", "oma:", "uff:", "vht:", "fit:", "api2:")


def build_corpus(workdir: Path, only: list[str] | None = None) -> list[Case]:
    if only and all(o in MEASURED_PREFIXES for o in only):  # those cases' fixtures only
        return measured_cases(workdir / "fixtures_measured")
    cases: list[Case] = []
    # --- process TOMLs through the CLI
    cases += toml_cases("process TOML (lobes)", EX / "lobes_single_point.toml",
                        lambda f: _cli("lobes", "{d}/" + f, "--json"))
    cases += toml_cases("process TOML (simulate boring)", EX / "boring_paper.toml",
                        lambda f: _cli("simulate", "boring", "{d}/" + f, "--revolutions", "3",
                                       "--json"))
    # --- FE, calibration, paper, sweep, material TOMLs: parse step only
    cases += toml_cases("FE 2D TOML (parse)", EX / "fe_orthogonal.toml",
                        lambda f: _parse("fe", f))
    cases += toml_cases("FE 3D TOML (parse)", EX / "fe_boring_paper.toml",
                        lambda f: _parse("fe_boring", f))
    cases += toml_cases("calibration TOML (parse)", EX / "calibration_boring_chip.toml",
                        lambda f: _parse("calibration", f))
    pe = DATA / "paper_example"
    cases += toml_cases("paper TOML (parse)", pe / "paper.toml", lambda f: _parse("paper", f),
                        extra={n: (pe / n).read_bytes() for n in ("tc4_fe_coefficients.json",
                                                                  "measured_synthetic.csv")})
    cases += toml_cases("sweep TOML (parse)", EX / "sweep_demo.toml",
                        lambda f: _parse("sweep", f))
    cases += toml_cases("material TOML (parse)", PKG / "material" / "library" / "tc4.toml",
                        lambda f: _parse("material", f))
    fe_text = (EX / "fe_orthogonal.toml").read_text()
    for old, new, why in (("cutting_speed_m_per_min = 30.0", "cutting_speed_m_per_min = 0.5",
                           "m/s for m/min"),
                          ("edge_radius_um = 20.0", "edge_radius_um = 0.02", "mm for um")):
        assert old in fe_text, old
        cases.append(Case("FE 2D TOML (parse)", f"{new} ({why}, a slip downwards)",
                          {"fe_orthogonal.toml": fe_text.replace(old, new).encode()},
                          _parse("fe", "fe_orthogonal.toml"), True, ("fe_orthogonal.toml",)))
    tc4_text = (PKG / "material" / "library" / "tc4.toml").read_text()
    for old, new in (("A_MPa = 997.9", "A_MPa = 0.9979"), ("B_MPa = 653.1", "B_MPa = 0.6531")):
        assert old in tc4_text, old
        cases.append(Case("material TOML (parse)", f"{new} (GPa for MPa, a slip downwards)",
                          {"tc4.toml": tc4_text.replace(old, new).encode()},
                          _parse("material", "tc4.toml"), True, ("tc4.toml",)))
    cases += toml_cases("robot TOML (robot fk)", PKG / "robot" / "library" /
                        "irb6600-175-2.55.toml",
                        lambda f: _cli("robot", "fk", "--joints-deg", "0,10,10,0,30,0",
                                       "--robot-file", "{d}/" + f, "--json"))
    plan_src = EX / "plan_paper_bore.toml"
    plan_text = plan_src.read_text().replace(
        "../src/robobore/data/paper_example/tc4_fe_coefficients.json", "tc4_fe_coefficients.json")
    plan_tmp = workdir / "plan_paper_bore.toml"
    workdir.mkdir(parents=True, exist_ok=True)
    plan_tmp.write_text(plan_text)
    cases += toml_cases("plan TOML (parse)", plan_tmp, lambda f: _parse("plan", f), extra={
        "tc4_fe_coefficients.json": (pe / "tc4_fe_coefficients.json").read_bytes(),
        **{f"plan_paper_bore/{n}": (EX / "plan_paper_bore" / n).read_bytes()
           for n in ("joint_stiffness.json", "modes.json")}})
    # --- campaign CSV through identify stiffness
    cases += csv_cases("campaign CSV (identify stiffness)", DATA / "campaign_irb6600" /
                       "campaign.csv",
                       lambda f: _cli("identify", "stiffness", "{d}/" + f, "--robot",
                                      "irb6600-175-2.55", "--json"),
                       {"x_m": (1e3, "mm for m"), "load_point_z_m": (1e3, "mm for m")},
                       ["y_m", "force_x_N", "q2_deg"])
    camp_lines = (DATA / "campaign_irb6600" / "campaign.csv").read_text().splitlines()
    camp_head = camp_lines[0].split(",")
    kn = [camp_lines[0]]
    for ln in camp_lines[1:]:
        cells = ln.split(",")
        for col in ("force_x_N", "force_y_N", "force_z_N"):
            cells[camp_head.index(col)] = repr(float(cells[camp_head.index(col)]) / 1e3)
        kn.append(",".join(cells))
    cases.append(Case("campaign CSV (identify stiffness)", "all forces in kN (N / 1e3)",
                      {"campaign.csv": ("\n".join(kn) + "\n").encode()},
                      _cli("identify", "stiffness", "{d}/campaign.csv", "--robot",
                           "irb6600-175-2.55", "--json"), True, ("campaign.csv",)))
    # --- measured CSV (parse; compare needs a store)
    cases += csv_cases("measured CSV (parse)", pe / "measured_synthetic.csv",
                       lambda f: _parse("measured", f),
                       {"depth_of_cut_mm": (1e3, "um for mm"),
                        "feed_mm_per_rev": (1e3, "um/r for mm/r"),
                        "pressure_MPa": (1e6, "Pa for MPa")},
                       ["force_amplitude_x_N", "speed_rpm"])
    mlines = (pe / "measured_synthetic.csv").read_text().splitlines()
    mhi = next(i for i, ln in enumerate(mlines) if ln and not ln.startswith("#"))
    mhead = mlines[mhi].split(",")
    for col in ("depth_of_cut_mm", "feed_mm_per_rev"):
        ls = list(mlines)
        cells = ls[mhi + 1].split(",")
        cells[mhead.index(col)] = repr(float(cells[mhead.index(col)]) / 1e3)
        ls[mhi + 1] = ",".join(cells)
        cases.append(Case("measured CSV (parse)", f"unit slip {col} row 1 (m for mm, downwards)",
                          {"measured_synthetic.csv": ("\n".join(ls) + "\n").encode()},
                          _parse("measured", "measured_synthetic.csv"), True,
                          ("measured_synthetic.csv",)))
    # --- coefficients JSON named by a process config
    coef = json.loads((pe / "tc4_fe_coefficients.json").read_text())
    cfg = (EX / "boring_paper.toml").read_text().replace('material = "TC4"',
                                                         'file = "coef.json"')
    cases += json_cases("coefficients JSON (lobes)", "coef.json", coef,
                        _cli("lobes", "{d}/boring.toml", "--json"),
                        [("coefficients.Ktc_N_per_m2", 1e-6, "N/mm^2 for N/m^2"),
                         ("coefficients.Kfc_N_per_m2", 1e-6, "N/mm^2 for N/m^2"),
                         ("coefficients.Kte_N_per_m", 1e-3, "N/mm for N/m"),
                         ("coefficients.Ktc_N_per_m2", True, "set"),
                         ("coefficients.Ktc_N_per_m2", "abc", "set"),
                         ("coefficients.Ktc_N_per_m2", [1, 2], "set"),
                         ("coefficients", [1, 2], "set")],
                        extra={"boring.toml": cfg.encode()}, names=("coef.json",))
    # --- modes / stiffness JSON through model equivalent
    modes = {"band_Hz": [3.0, 60.0],
             "modes": [{"frequency_Hz": 6.9, "damping_ratio": 0.035},
                       {"frequency_Hz": 16.8, "damping_ratio": 0.028},
                       {"frequency_Hz": 24.6, "damping_ratio": 0.020}]}
    stiff = {"directional_stiffness_N_per_m": {"x": 3.0e6, "y": 2.5e6, "z": 4.0e6}}
    eq = _cli("model", "equivalent", "--stiffness-file", "{d}/stiffness.json", "--modes-file",
              "{d}/modes.json", "--json")
    cases += json_cases("modes JSON (model equivalent)", "modes.json", modes, eq,
                        [("modes.0.damping_ratio", 100.0, "percent for a ratio"),
                         ("modes.2.frequency_Hz", 1e3, "kHz for Hz"),
                         ("modes.1.frequency_Hz", 1e9, "axis x1e9"),
                         ("modes.0.damping_ratio", True, "set"),
                         ("modes.0", [1, 2], "set"),
                         ("modes", {"a": 1}, "set")],
                        extra={"stiffness.json": json.dumps(stiff).encode()})
    cases += json_cases("stiffness JSON (model equivalent)", "stiffness.json", stiff, eq,
                        [("directional_stiffness_N_per_m.x", 1e-6, "N/um for N/m"),
                         ("directional_stiffness_N_per_m.y", 1e-3, "N/mm for N/m"),
                         ("directional_stiffness_N_per_m", [3e6, 2.5e6, 4e6], "set"),
                         ("directional_stiffness_N_per_m.z", None, "set")],
                        extra={"modes.json": json.dumps(modes).encode()})
    # --- UFF hammer test
    uff = (DATA / "hammer_test" / "robot_hammer_test.uff").read_bytes()
    ufa = _cli("identify", "modes", "{d}/hammer.uff", "--json")
    cases.append(Case("UFF (identify modes)", "control: unchanged", {"hammer.uff": uff}, ufa,
                      False, ("hammer.uff",), control=True))
    for desc, blob, must in [
        ("truncated at 50 %", uff[: len(uff) // 2], True),
        ("truncated at 3 %", uff[: len(uff) // 33], True),
        ("UTF-16 encoded", uff.decode("latin-1").encode("utf-16"), True),
        ("binary junk", os.urandom(2000), True),
        ("empty", b"", True),
        ("a number replaced by text", _replace_nth_number(uff, 500, b"abc"), True),
        ("a number replaced by nan", _replace_nth_number(uff, 800, b"nan"), True),
        ("sampling interval x1e-9", _scale_abscissa(uff, 1e-9), True),
    ]:
        cases.append(Case("UFF (identify modes)", desc, {"hammer.uff": blob}, ufa, must,
                          ("hammer.uff",)))
    # --- NPZ FRFs
    cases += npz_cases(workdir)
    # --- relative paths: a stray same-named file in the current folder
    stray = json.loads(json.dumps(coef))
    stray["coefficients"]["Ktc_N_per_m2"] *= 1.58
    for cmd in (["lobes", "{d}/boring.toml", "--json"],
                ["simulate", "boring", "{d}/boring.toml", "--revolutions", "3", "--json"]):
        files = {"boring.toml": cfg.encode(), "coef.json": json.dumps(coef).encode()}
        clean = Case("relative path (stray file in cwd)", f"clean {cmd[0]}", files, _cli(*cmd),
                     False, ("boring.toml",), control=True)
        cases.append(clean)
        cases.append(Case("relative path (stray file in cwd)", f"stray coef.json, {cmd[0]}",
                          files, _cli(*cmd), False, ("boring.toml",),
                          cwd_files={"coef.json": json.dumps(stray).encode()},
                          same_as=clean.desc))
        cases.append(Case("relative path (stray file in cwd)", f"file only in cwd, {cmd[0]}",
                          {"boring.toml": cfg.encode()}, _cli(*cmd), True,
                          ("boring.toml",), cwd_files={"coef.json": json.dumps(coef).encode()}))
    tc4 = (PKG / "material" / "library" / "tc4.toml").read_text()
    fe = (EX / "fe_orthogonal.toml").read_text()
    fe = fe.replace('name = "TC4"', 'name = "my.toml"') if 'name = "TC4"' in fe else \
        '[material]\nname = "my.toml"\n' + fe
    cases.append(Case("relative path (stray file in cwd)", "FE material only in cwd (parse)",
                      {"fe.toml": fe.encode()}, _parse("fe", "fe.toml"), True, ("fe.toml",),
                      cwd_files={"my.toml": tc4.encode()}))
    # --- options
    b = "{d}/boring.toml"
    opt_files = {"boring.toml": (EX / "boring_paper.toml").read_bytes()}
    for args, name in [
        (["simulate", "boring", b, "--speed-rpm", "nan"], "--speed-rpm"),
        (["simulate", "boring", b, "--depth-mm", "-1"], "--depth-mm"),
        (["simulate", "boring", b, "--depth-mm", "50"], "--depth-mm"),
        (["simulate", "boring", b, "--feed-mm-per-rev", "150"], "--feed-mm-per-rev"),
        (["simulate", "boring", b, "--pressure-MPa", "300000"], "--pressure-MPa"),
        (["simulate", "boring", b, "--revolutions", "0"], "--revolutions"),
        (["simulate", "boring", b, "--revolutions", "20000", "--samples-per-rev", "200000"],
         "--samples-per-rev"),
        (["robot", "fk", "--joints-deg", "0,10,10,0,30,0", "--tcp-m", "0,0,250"], "--tcp-m"),
        (["robot", "fk", "--joints-deg", "a,b"], "--joints-deg"),
        (["identify", "modes", "--example", "--band-hz", "3e9", "6e9"], "--band-hz"),
        (["identify", "stiffness", "--example", "--sigma-um", "nan"], "--sigma-um"),
        (["model", "equivalent", "--stiffness-N-per-m", "3,2.5,4", "--frequencies-Hz",
          "6.9,16.8,24.6", "--damping-ratios", "0.035,0.028,0.02"], "--stiffness-N-per-m"),
        (["model", "equivalent", "--stiffness-N-per-m", "3e6,2.5e6,4e6", "--frequencies-Hz",
          "6.9,16.8,24.6", "--damping-ratios", "3.5,2.8,2.0"], "--damping-ratios"),
        (["identify", "virtual-hammer-test", "{d}/h.uff", "--duration-s", "6000"],
         "--duration-s"),
        (["identify", "virtual-hammer-test", "{d}/h.uff", "--noise", "1.5"], "--noise"),
        (["identify", "virtual-hammer-test", "{d}/h.uff", "--seed", "-1"], "--seed"),
        (["identify", "virtual-hammer-test", "{d}/h.uff", "--sample-rate-hz", "2e7"],
         "--sample-rate-hz"),
        (["identify", "stiffness", "--example", "--cond-limit", "0.5"], "--cond-limit"),
        (["identify", "modes", "--example", "--modes", "0"], "--modes"),
        (["identify", "modes", "--example", "--max-order", "5000"], "--max-order"),
        (["identify", "modes", "--example", "--exp-window-tau-s", "inf"], "--exp-window-tau-s"),
        (["identify", "modes", "--example", "--approx-hz", "7,1.7e7"], "--approx-hz"),
        (["robot", "campaign", "{d}/c.csv", "--pressures-MPa", "0,0.3", "--piston-area-m2",
          "1667"], "--piston-area-m2"),
        (["robot", "campaign", "{d}/c.csv", "--sigma-um", "-3"], "--sigma-um"),
        (["robot", "campaign", "{d}/c.csv", "--load-levels-N", "0,250e3,500e3"],
         "--load-levels-N"),
        (["model", "equivalent", "--stiffness-N-per-m", "3e6,2.5e6,4e6", "--frequencies-Hz",
          "6.9,16.8,24.6", "--damping-ratios", "0.035,0.028,0.02", "--foot-pressure-MPa",
          "0.3", "--foot-piston-diameter-mm", "50000"], "--foot-piston-diameter-mm"),
        (["model", "equivalent", "--stiffness-N-per-m", "3e6,2.5e6,4e6", "--frequencies-Hz",
          "6.9,16.8,24.6", "--damping-ratios", "0.035,0.028,0.02", "--foot-pressure-MPa",
          "0.3", "--foot-normal-stiffness-N-per-m", "3"], "--foot-normal-stiffness-N-per-m"),
        (["model", "equivalent", "--stiffness-N-per-m", "3e6,2.5e6,4e6", "--frequencies-Hz",
          "6.9,16.8,24.6", "--damping-N-s-per-m", "nan"], "--damping-N-s-per-m"),
        (["robot", "stiffness", "--joints-deg", "0,-20,20,0,30,0",
          "--joint-stiffness-Nm-per-rad", "1e4,1e4,1e4,1e3,1e3,0.1"],
         "--joint-stiffness-Nm-per-rad"),
        (["paper", "--fast", "--out", "{d}/p", "--workers", "-1"], "--workers"),
    ]:
        cases.append(Case("command-line options", " ".join(args[1:] if args[0] != "simulate"
                                                           else args[3:]),
                          opt_files, _cli(*args, "--json"), True, (name,)))
    cases += more_cases(workdir / "fixtures")
    cases += identity_cases(workdir / "fixtures_identity")
    cases += measured_cases(workdir / "fixtures_measured")
    return cases


def _kind_of(desc: str, argv: list[str]) -> str:
    """The input path a case of malformed_corpus_more exercises."""
    head, _, rest = desc.partition(":")
    if head == "out":
        return "output paths (--out, --plot, --vtk, --report, OUT)"
    if head == "size":
        return "huge requests (size guards)"
    if head == "fail":
        return "partial failure (exit code)"
    if head == "resume":
        return "durability / resume"
    if head == "slip":
        return "process TOML (simulate boring)"
    kinds = {"id": "identity (robot, posture, tool point, frame)",
             "unit": "unit slips in identification / model files",
             "plan": "planner (plan posture)", "fe": "FE validation (measured file)",
             "api": "Python API", "sweep": "sweep (--scheduler, runner)",
             "csv": "CSV separators, CSV as UFF",
             "meas": "detect chatter", "cut": "measure cut", "cmp": "compare with a manifest",
             "paper": "compare on a paper folder", "oma": "identify modes --operational",
             "uff": "UFF variants (identify modes)",
             "vht": "virtual hammer test --robot-file",
             "fit": "files that do not fit (modes, coefficients)", "api2": "Python API"}
    if head in kinds:
        return kinds[head]
    r = rest.lower()
    for words, kind in ((("--scheduler", "--frf-type"), "command-line options"),
                        (("npz",), "NPZ FRF (identify modes)"),
                        (("uff", "hammer"), "UFF (identify modes)"),
                        (("store",), "results store"),
                        (("campaign", "measured", "csv"), "CSV files (campaign, measured)"),
                        (("json", "coefficient", "stiffness", "modes", "equivalent"),
                         "JSON files (coefficients, stiffness, modes)"),
                        (("toml", "config", "material", "robot file", "band_hz", "fe "),
                         "TOML files (encodings, corrupt)")):
        if any(w in r for w in words):
            return kind
    return "other"


def more_cases(fixtures: Path) -> list[Case]:
    """The cases of benchmarks/malformed_corpus_more.py as :class:`Case` objects."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import malformed_corpus_more as more

    out = []
    for desc, argv, pattern, mode in more.build(fixtures):
        argv = [str(a) for a in argv]
        cmd = argv if mode == "script" else _cli(*argv)
        out.append(Case(_kind_of(desc, argv), desc, {}, cmd, mode != "script", (),
                        pattern=pattern, mode=mode))
    return out


def identity_cases(fixtures: Path) -> list[Case]:
    """The cases of benchmarks/malformed_corpus_identity.py as :class:`Case` objects."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import malformed_corpus_identity as ident

    out = []
    for desc, argv, pattern, mode in ident.build(fixtures):
        cmd = argv if mode == "script" else _cli(*argv)
        out.append(Case(_kind_of(desc, argv), desc, {}, cmd, mode != "script", (),
                        pattern=pattern, mode=mode))
    return out


def measured_cases(fixtures: Path) -> list[Case]:
    """The cases of benchmarks/malformed_corpus_measured.py as :class:`Case` objects."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import malformed_corpus_measured as meas

    out = []
    for desc, argv, pattern, mode in meas.build(fixtures):
        cmd = argv if mode == "script" else _cli(*argv)
        out.append(Case(_kind_of(desc, argv), desc, {}, cmd, mode != "script", (),
                        pattern=pattern, mode=mode))
    return out


def _replace_nth_number(blob: bytes, n: int, new: bytes) -> bytes:
    text = blob.decode("latin-1")
    ms = list(NUM.finditer(text))
    m = ms[min(n, len(ms) - 1)]
    return (text[:m.start()] + new.decode() + text[m.end():]).encode("latin-1")


def _scale_abscissa(blob: bytes, f: float) -> bytes:
    """Scale every record's abscissa increment (UFF 58, record 7, 3rd field)."""
    sys.path.insert(0, str(ROOT / "src"))
    import pyuff

    from robobore.modal.example import example_path  # noqa: F401  (same file as the bundled)

    tmp = Path("/tmp") / f"corpus_uff_{os.getpid()}.uff"
    tmp.write_bytes(blob)
    sets = pyuff.UFF(str(tmp)).read_sets()
    for s in sets:
        if s.get("type") == 58:
            s["abscissa_inc"] = float(s["abscissa_inc"]) * f
            if "x" in s:
                s["x"] = s["x"] * f
    out = Path("/tmp") / f"corpus_uff_{os.getpid()}_s.uff"
    if out.exists():
        out.unlink()
    u = pyuff.UFF(str(out))
    for s in sets:
        u.write_sets(s, mode="add")
    data = out.read_bytes()
    tmp.unlink()
    out.unlink()
    return data


def npz_cases(workdir: Path) -> list[Case]:
    import io

    import numpy as np

    sys.path.insert(0, str(ROOT / "src"))
    from robobore.modal.example import example_path
    from robobore.modal.frf import estimate_frf
    from robobore.modal.frf_data import FRFData
    from robobore.modal.io import load_input

    d = load_input(example_path())
    frf = d if isinstance(d, FRFData) else estimate_frf(d).frf
    base = {"frequency_Hz": frf.frequency_Hz, "frf": frf.frf,
            "frf_type": np.array(frf.frf_type)}
    if frf.coherence is not None:
        base["coherence"] = frf.coherence

    def npz(**over) -> bytes:
        buf = io.BytesIO()
        arrays = {**base, **over}
        np.savez(buf, **{k: v for k, v in arrays.items() if v is not None})
        return buf.getvalue()

    argv = _cli("identify", "modes", "{d}/frf.npz", "--json")
    good = npz()
    n = frf.frequency_Hz.size
    coh = np.full(frf.frf.shape, 1.7)
    cases = [Case("NPZ FRF (identify modes)", "control: unchanged", {"frf.npz": good}, argv,
                  False, ("frf.npz",), control=True)]
    for desc, blob in [
        ("frequency axis x1e9", npz(frequency_Hz=frf.frequency_Hz * 1e9)),
        ("coherence 1.7", npz(coherence=coh)),
        ("NaN in the frequency axis", npz(frequency_Hz=np.where(np.arange(n) == 5, np.nan,
                                                                frf.frequency_Hz))),
        ("pickled object array", npz(frequency_Hz=np.array([object()] * n, dtype=object))),
        ("boolean frequency axis", npz(frequency_Hz=np.ones(n, bool))),
        ("frf missing", npz(frf=None)),
        ("truncated", good[: len(good) // 2]),
        ("not a zip", b"hello"),
        ("frf wrong shape", npz(frf=frf.frf[0])),
        ("frf magnitudes only (real)", npz(frf=np.abs(frf.frf))),
        ("frf all zero", npz(frf=np.zeros_like(frf.frf))),
        ("two frequency lines", npz(frequency_Hz=frf.frequency_Hz[:2], frf=frf.frf[..., :2],
                                    coherence=None if frf.coherence is None else
                                    frf.coherence[..., :2])),
    ]:
        cases.append(Case("NPZ FRF (identify modes)", desc, {"frf.npz": blob}, argv, True,
                          ("frf.npz",)))
    return cases


# ----------------------------------------------------------------------------- running
def run_case(i: int, c: Case, out: Path, timeout: float) -> Case:
    d = out / f"case{i:04d}"
    if d.exists():
        shutil.rmtree(d)
    (d / "cwd").mkdir(parents=True)
    for n, b in c.files.items():
        (d / n).parent.mkdir(parents=True, exist_ok=True)
        (d / n).write_bytes(b)
    for n, b in c.cwd_files.items():
        (d / "cwd" / n).write_bytes(b)
    argv = [a.replace("{d}", str(d)) for a in c.argv]
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "NUMBA_NUM_THREADS": "1",
           "COLUMNS": "400"}
    env.pop("ROBOBORE_NO_RANGE_CHECK", None)
    try:
        p = subprocess.run(argv, cwd=d / "cwd", env=env, capture_output=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        c.outcome, c.rc = "hang", None
        return c
    c.rc = p.returncode
    err = p.stderr.decode(errors="replace")
    (d / "stdout").write_bytes(p.stdout)
    c.stderr_tail = err[-600:]
    sout = p.stdout.decode(errors="replace")
    if "Traceback (most recent call last)" in err + sout:
        c.outcome = "traceback"
    elif c.mode == "script":  # a multi-step check: exit 0 and "OK" when right
        ok = p.returncode == 0 and sout.strip().splitlines()[-1:][0].startswith("OK")
        c.outcome = "ok" if ok else "silent"
        c.stderr_tail = (sout + err)[-600:]
    elif c.mode == "partial":  # a failed condition: exit 1, the failure named
        named = re.search(c.pattern or "", sout + err, re.I) is not None
        c.outcome = ("clear" if p.returncode == 1 and named else
                     "silent" if p.returncode == 0 else "vague")
        c.stderr_tail = (sout + err)[-600:]
    elif c.pattern is not None and p.returncode != 0:
        lines = [ln for ln in err.splitlines() if "error" in ln.lower()]
        line = " ".join(lines) if lines else err.strip()
        named = re.search(c.pattern, line, re.I) is not None and "<config>" not in line
        says = any(w in line.lower() for w in ("expected", "got", "missing", "give ",
                                                "cannot", "not ", "refus"))
        c.outcome = "clear" if named and says else "vague"
    elif p.returncode == 0:
        if c.control or not c.must_fail:
            c.outcome = "ok"
        else:
            c.outcome = "silent"
    else:
        line = next((ln for ln in err.splitlines() if "error" in ln.lower()), err.strip())
        # the file, or the option with or without its dashes
        named = any(n.lower() in line.lower()
                    or n.lstrip("-").replace("-", "_").lower() in line.lower()
                    for n in c.names)
        says = any(w in line.lower() for w in ("expected", "got", "missing", "give ",
                                                "should be"))
        c.outcome = "clear" if named and says else "vague"
        if c.control:
            c.outcome = "rejected"
    return c


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="/tmp/robobore-corpus")
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--only", default="",
                    help="run only the cases whose input path or description contains this "
                         "(several: TEXT1|TEXT2)")
    a = ap.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    only = a.only.split("|")
    cases = [c for c in build_corpus(out, only)
             if any(o in c.path_kind or o in c.desc for o in only)]
    t0 = time.perf_counter()
    with ThreadPoolExecutor(a.workers) as ex:
        done = list(ex.map(lambda ic: run_case(ic[0], ic[1], out, a.timeout), enumerate(cases)))
    # stray-file cases: the result must equal the clean run's
    by_desc = {(c.path_kind, c.desc): i for i, c in enumerate(done)}
    for i, c in enumerate(done):
        if c.same_as is not None and c.outcome == "ok":
            j = by_desc[(c.path_kind, c.same_as)]
            a_out = (out / f"case{i:04d}" / "stdout").read_bytes()
            b_out = (out / f"case{j:04d}" / "stdout").read_bytes()
            if a_out != b_out:
                c.outcome = "silent"
    dt = time.perf_counter() - t0
    classes = ["clear", "ok", "vague", "traceback", "silent", "rejected", "hang"]
    kinds = sorted({c.path_kind for c in done})
    w = max(len(k) for k in kinds) + 2
    print(f"{'input path':<{w}}" + "".join(f"{k:>10}" for k in classes) + f"{'total':>8}")
    for k in kinds:
        row = [sum(1 for c in done if c.path_kind == k and c.outcome == cl) for cl in classes]
        print(f"{k:<{w}}" + "".join(f"{v:>10}" for v in row) + f"{sum(row):>8}")
    tot = [sum(1 for c in done if c.outcome == cl) for cl in classes]
    print(f"{'TOTAL':<{w}}" + "".join(f"{v:>10}" for v in tot) + f"{sum(tot):>8}")
    print(f"\n{len(done)} cases ({sum(1 for c in done if c.control)} controls) in {dt:.0f} s: "
          f"{len(done) / dt:.2f} cases/s")
    bad = [c for c in done if c.outcome not in ("clear", "ok")]
    if bad:
        print("\nnot clear:")
        for c in bad:
            last = c.stderr_tail.strip().splitlines()[-1:] if c.stderr_tail.strip() else [""]
            print(f"  [{c.outcome}] {c.path_kind}: {c.desc}: {last[0][:300]}")
    (out / "corpus.json").write_text(json.dumps(
        [{"path_kind": c.path_kind, "desc": c.desc, "must_fail": c.must_fail,
          "control": c.control, "outcome": c.outcome, "rc": c.rc, "stderr": c.stderr_tail}
         for c in done], indent=1))


if __name__ == "__main__":
    main()
