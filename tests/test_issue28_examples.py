"""Each example of issue 28's "Why" list, through the command a user would run: a one-line
error naming the file (or option) and the key, or, for the relative-path case, the right file.

Examples checked elsewhere with the same inputs (not repeated here): the material constants
(E in MPa, D1 = nan; tests/test_ranges.py, function level, because the FE commands that read
materials run FE simulations); a FE mesh of 0.01 um (tests/test_outputs_and_errors.py,
parse level); a zero-byte result on resume (tests/study/test_study_kill.py).
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from robobore.cli import app

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"
DATA = ROOT / "src" / "robobore" / "data"
PAPER = DATA / "paper_example"
runner = CliRunner()


def _replace(text: str, old: str, new: str) -> str:
    assert old in text, old  # the example input still has what the case corrupts
    return text.replace(old, new)


def _campaign_mm(t: Path):
    lines = (DATA / "campaign_irb6600" / "campaign.csv").read_text().splitlines()
    i = lines[0].split(",").index("x_m")
    cells = lines[1].split(",")
    cells[i] = repr(float(cells[i]) * 1e3)
    lines[1] = ",".join(cells)
    (t / "camp.csv").write_text("\n".join(lines) + "\n")
    return (["identify", "stiffness", str(t / "camp.csv"), "--robot", "irb6600-175-2.55"],
            ["camp.csv", "row 1", "'x_m'", "looks like mm; expected m"])


def _robot_mm(t: Path):
    src = (ROOT / "src/robobore/robot/library/irb6600-175-2.55.toml").read_text()
    (t / "r.toml").write_text(_replace(src, "d_m = [0.780, 0.0, 0.0, 1.142, 0.0, 0.200]",
                                       "d_m = [780.0, 0.0, 0.0, 1142.0, 0.0, 200.0]"))
    return (["robot", "fk", "--joints-deg", "0,10,10,0,30,0", "--robot-file", str(t / "r.toml")],
            ["r.toml", "d_m.0", "looks like mm; expected m"])


def _tcp_mm(t: Path):
    return (["robot", "fk", "--joints-deg", "0,10,10,0,30,0", "--tcp-m", "0,0,250"],
            ["'--tcp-m'", "looks like mm; expected m"])


_EQ = ["model", "equivalent", "--stiffness-N-per-m", "3e6,2.5e6,4e6", "--frequencies-Hz",
       "6.9,16.8,24.6"]


def _damping_percent(t: Path):
    return ([*_EQ, "--damping-ratios", "3.5,2.8,2.0"], ["'--damping-ratios'", "percent"])


def _stiffness_n_per_um(t: Path):
    return (["model", "equivalent", "--stiffness-N-per-m", "3,2.5,4", "--frequencies-Hz",
             "6.9,16.8,24.6", "--damping-ratios", "0.035,0.028,0.02"],
            ["'--stiffness-N-per-m'", "looks like N/um"])


def _coef_n_per_mm2(t: Path):
    d = json.loads((PAPER / "tc4_fe_coefficients.json").read_text())
    d["coefficients"]["Ktc_N_per_m2"] /= 1e6
    (t / "k.json").write_text(json.dumps(d))
    (t / "c.toml").write_text(_replace((EX / "boring_paper.toml").read_text(),
                                       'material = "TC4"', 'file = "k.json"'))
    return (["lobes", str(t / "c.toml")], ["k.json", "Ktc_N_per_m2", "N/mm^2"])


def _depth_true(t: Path):
    (t / "c.toml").write_text(_replace((EX / "boring_paper.toml").read_text(),
                                       "depth_mm = 0.05", "depth_mm = true"))
    return (["simulate", "boring", str(t / "c.toml")], ["c.toml", "cutting.depth_mm", "boolean"])


def _npz(t: Path, name: str, **over):
    from robobore.modal.example import example_path
    from robobore.modal.frf import estimate_frf
    from robobore.modal.io import load_input

    frf = estimate_frf(load_input(example_path())).frf
    arrays = {"frequency_Hz": frf.frequency_Hz, "frf": frf.frf,
              "frf_type": np.array(frf.frf_type),
              "coherence": np.full(frf.frf.shape, 0.99)}
    arrays.update({k: (v(arrays[k]) if callable(v) else v) for k, v in over.items()})
    np.savez(t / name, **arrays)
    return t / name


def _coherence(t: Path):
    p = _npz(t, "coh.npz", coherence=lambda c: np.full(c.shape, 1.7))
    return (["identify", "modes", str(p)], ["coh.npz", "coherence", "1.7"])


def _freq_x1e9(t: Path):
    p = _npz(t, "f.npz", frequency_Hz=lambda f: f * 1e9)
    return (["identify", "modes", str(p)], ["f.npz", "frequency_Hz", "Hz"])


def _pickled_npz(t: Path):
    p = _npz(t, "p.npz", frf=lambda f: np.array([{"a": 1}] * f.shape[-1], dtype=object))
    return (["identify", "modes", str(p)], ["p.npz", "pickle"])


def _paper_copy(t: Path, old: str | None = None, new: str | None = None) -> Path:
    d = t / "paper"
    shutil.copytree(PAPER, d)
    if old is not None:
        (d / "paper.toml").write_text(_replace((d / "paper.toml").read_text(), old, new))
    return d


def _typo_section_fast(t: Path):
    d = _paper_copy(t, "\n[calibration]", "\n[calibratoin]")
    return (["paper", str(d / "paper.toml"), "--fast", "--out", str(t / "o")],
            ["paper.toml", "calibratoin", "unknown key"])


def _paper_corrupt_coefficients(t: Path):
    d = _paper_copy(t)
    (d / "tc4_fe_coefficients.json").write_text('{"coefficients": {"Ktc_N_per_m2": 1.0e9,')
    return (["paper", str(d / "paper.toml"), "--fast", "--out", str(t / "o")],
            ["tc4_fe_coefficients.json", "JSON"])


def _band3(t: Path):
    d = _paper_copy(t, "band_Hz = [3.0, 60.0]", "band_Hz = [3]")
    return (["paper", str(d / "paper.toml"), "--fast", "--out", str(t / "o")],
            ["paper.toml", "modal.band_Hz"])


def _plot_is_a_file(t: Path):
    (t / "afile").write_text("x")
    return (["lobes", str(EX / "lobes_single_point.toml"), "--plot", str(t / "afile")],
            ["'--plot'", "afile", "existing file, not a folder"])


def _out_uncreatable(t: Path):
    (t / "afile").write_text("x")
    return (["robot", "campaign", str(t / "afile" / "c.csv")],
            ["'OUT'", "afile", "is an existing file, not a folder"])


def _utf16_toml(t: Path):
    (t / "u16.toml").write_bytes((EX / "lobes_single_point.toml").read_text().encode("utf-16"))
    return (["lobes", str(t / "u16.toml")], ["u16.toml", "UTF-16"])


def _binary_toml(t: Path):
    (t / "bin.toml").write_bytes(bytes(range(256)) * 4)
    return (["sweep", str(t / "bin.toml"), "--out", str(t / "o")], ["bin.toml", "UTF-8"])


def _equivalent_list(t: Path):
    from robobore.equivalent import EquivalentModel

    em = EquivalentModel.from_stiffness_and_modes(
        {"directional_stiffness_N_per_m": {"x": 3e6, "y": 2.5e6, "z": 4e6}},
        {"modes": [{"frequency_Hz": f, "damping_ratio": 0.03} for f in (6.9, 16.8, 24.6)]})
    d = em.to_dict()
    d["stiffness_N_per_m"] = [3e6, 2.5e6, 4e6]
    (t / "eq.json").write_text(json.dumps(d))
    return (["simulate", "boring", str(EX / "boring_process.toml"), "--equivalent-file",
             str(t / "eq.json")], ["eq.json", "stiffness_N_per_m", "table"])


def _huge_sweep(t: Path):
    (t / "big.toml").write_text(
        '[sweep]\nname = "big"\nrunner = "demo"\n[grid]\n'
        'speed_rpm = {start = 100, stop = 3000, num = 10000}\n'
        'feed_mm_per_rev = {start = 0.05, stop = 0.3, num = 10000}\n'
        'depth_of_cut_mm = {start = 0.1, stop = 1, num = 10000}\n')
    return (["sweep", str(t / "big.toml"), "--out", str(t / "o")],
            ["big.toml", "'grid'", "1e+12 conditions"])


def _huge_hammer_test(t: Path):
    return (["identify", "virtual-hammer-test", str(t / "h.uff"), "--sample-rate-hz", "1e7",
             "--duration-s", "1e4"], ["--sample-rate-hz", "memory", "1e+11 samples"])


def _huge_time_domain(t: Path):
    return (["simulate", "boring", str(EX / "boring_paper.toml"), "--revolutions", "20000",
             "--samples-per-rev", "200000"], ["revolutions", "memory"])


CASES = {
    "laser-tracker positions in mm": _campaign_mm,
    "robot lengths in mm": _robot_mm,
    "tool point in mm": _tcp_mm,
    "damping ratios in percent": _damping_percent,
    "stiffness in N/um": _stiffness_n_per_um,
    "coefficients in N/mm^2": _coef_n_per_mm2,
    "depth_mm = true": _depth_true,
    "coherence 1.7": _coherence,
    "frequency axis x1e9": _freq_x1e9,
    "typo'd section under --fast": _typo_section_fast,
    "output path is a file": _plot_is_a_file,
    "output path cannot be created": _out_uncreatable,
    "UTF-16 TOML": _utf16_toml,
    "binary TOML": _binary_toml,
    "corrupt coefficients JSON in paper": _paper_corrupt_coefficients,
    "band_Hz = [3]": _band3,
    "equivalent-model JSON with a list for a table": _equivalent_list,
    "pickled NPZ": _pickled_npz,
    "1e12-condition sweep": _huge_sweep,
    "1e11-sample virtual test": _huge_hammer_test,
    "20,000 revolutions x 200,000 samples": _huge_time_domain,
}


@pytest.mark.parametrize("name", list(CASES))
def test_why_example_is_one_clear_line(name, tmp_path):
    args, words = CASES[name](tmp_path)
    r = runner.invoke(app, args)
    assert r.exit_code == 2, r.output
    assert "Traceback" not in r.output
    errors = [ln for ln in r.output.splitlines() if ln.startswith("error:")]
    assert len(errors) == 1, r.output  # one line, whatever the terminal width
    for w in words:
        assert w in errors[0], (w, errors[0])


def test_why_missing_speed_section_says_which_range(tmp_path):
    """No [speed_rpm] in a lobes config: the documented default range, said in the result."""
    text = (EX / "lobes_single_point.toml").read_text()
    assert "[speed_rpm]" in text
    (tmp_path / "l.toml").write_text(text.split("[speed_rpm]")[0])
    r = runner.invoke(app, ["lobes", str(tmp_path / "l.toml"), "--json"])
    assert r.exit_code == 0, r.output
    notes = json.loads(r.stdout)["notes"]
    assert any("no [speed_rpm] section" in n and "100 .. 3000 r/min" in n for n in notes)
    assert "Without a `[speed_rpm]` section `robobore lobes` uses 100 .. 3000 r/min" in " ".join(
        (ROOT / "docs" / "process.md").read_text().split())


def test_why_relative_path_gives_the_file_next_to_the_config(tmp_path, monkeypatch):
    """A stray same-named coefficients file (Ktc x 1.58) in the current folder is not used:
    the run gives the same result as from any other folder."""
    coef = json.loads((PAPER / "tc4_fe_coefficients.json").read_text())
    stray = json.loads(json.dumps(coef))
    stray["coefficients"]["Ktc_N_per_m2"] *= 1.58
    cfgdir, cwd, other = tmp_path / "cfg", tmp_path / "cwd", tmp_path / "other"
    for d in (cfgdir, cwd, other):
        d.mkdir()
    (cfgdir / "coef.json").write_text(json.dumps(coef))
    (cwd / "coef.json").write_text(json.dumps(stray))
    (cfgdir / "c.toml").write_text(_replace((EX / "boring_paper.toml").read_text(),
                                            'material = "TC4"', 'file = "coef.json"'))
    out = {}
    for d in (other, cwd):
        monkeypatch.chdir(d)
        r = runner.invoke(app, ["simulate", "boring", str(cfgdir / "c.toml"), "--revolutions",
                                "4", "--samples-per-rev", "64", "--json"])
        assert r.exit_code == 0, r.output
        out[d.name] = json.loads(r.stdout)["force_mean_N"]
    assert out["cwd"] == out["other"]
    (cfgdir / "c.toml").write_text(_replace((EX / "boring_paper.toml").read_text(),
                                            'material = "TC4"', 'file = "stray.json"'))
    (cwd / "stray.json").write_text(json.dumps(stray))  # only in the cwd: an error
    r = runner.invoke(app, ["simulate", "boring", str(cfgdir / "c.toml")])
    assert r.exit_code == 2 and "c.toml" in r.output and "coefficients.file" in r.output


@pytest.mark.slow
def test_why_paper_with_a_third_of_its_conditions_failed_exits_1(tmp_path, monkeypatch):
    """The real study (reduced set, --fast, serial) with the boring runner failing at one of
    the three speeds: exit 1, the report and the summary written and naming the failures."""
    import robobore.study.runners as runners
    from robobore.errors import ConfigError

    real = runners.boring_runner

    def failing(condition, context):
        if float(condition["speed_rpm"]) == 800.0:
            raise ConfigError("stub failure at 800 r/min", file="paper_small.toml",
                              field="grid.speed_rpm", value=800.0)
        return real(condition, context)

    monkeypatch.setattr(runners, "boring_runner", failing)
    text = (PAPER / "paper.toml").read_text()
    lines = []
    for ln in text.splitlines():
        key = ln.split("=")[0].strip()
        if key == "speed_rpm" and ln.startswith("speed_rpm = ["):
            ln = "speed_rpm = [300.0, 550.0, 800.0]"
        elif key == "feed_mm_per_rev" and ln.startswith("feed_mm_per_rev = ["):
            ln = "feed_mm_per_rev = [0.15]"
        elif key == "depth_of_cut_mm" and ln.startswith("depth_of_cut_mm = ["):
            ln = "depth_of_cut_mm = [0.05]"
        elif key in ("revolutions", "count"):
            ln = f"{key} = 40"
        lines.append(ln)
    d = _paper_copy(tmp_path)
    (d / "paper.toml").write_text("\n".join(lines) + "\n")
    out = tmp_path / "out"
    r = runner.invoke(app, ["paper", str(d / "paper.toml"), "--fast", "--workers", "0",
                            "--out", str(out), "--json"])
    assert r.exit_code == 1, r.output
    res = json.loads(r.stdout)
    assert res["failed"] and len(res["failed"]) * 3 == res["conditions"], res["failed"]
    assert all("800 r/min" in f["error"] for f in res["failed"])
    assert Path(res["report"]).is_file()
    assert (out / "paper_summary.json").is_file()
    assert "800 r/min" in Path(res["report"]).read_text()
    r = runner.invoke(app, ["paper", str(d / "paper.toml"), "--fast", "--workers", "0",
                            "--out", str(out), "--json", "--allow-failures"])
    assert r.exit_code == 0, r.output
