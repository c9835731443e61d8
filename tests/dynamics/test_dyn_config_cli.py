# ruff: noqa: E501  (the contract TOML is quoted verbatim from the issue)
"""Config contract and CLI: the contract TOML is accepted; bad configs name the key."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

from robobore.cli import app

EX = Path(__file__).resolve().parents[2] / "examples"
runner = CliRunner()

CONTRACT = """
[structure]   # tool-point modes, boring frame: x horizontal, y vertical, z feed
modes = [ { frequency_Hz = 250.0, damping_ratio = 0.012, stiffness_N_per_m = 2.26e8, direction = [0.866, 0.5, 0.0] } ]
[process]
cutting_coefficient_N_per_m2 = 1.0e9   # force magnitude per unit chip area (depth x chip thickness)
force_direction = [1.0, 0.0, 0.0]      # unit vector of the cutting force on the tool
chip_normal = [1.0, 0.0, 0.0]          # tool displacement along this changes the chip thickness
feed_mm_per_rev = 0.1
[speed_rpm]
min = 2000.0
max = 14000.0
count = 601
"""


def _write(tmp_path, text, name="c.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_lobes_contract_json(tmp_path):
    p = _write(tmp_path, CONTRACT)
    r = runner.invoke(app, ["lobes", str(p), "--json", "--method", "frequency"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert len(d["speed_rpm"]) == 601 and len(d["critical_depth_mm"]) == 601
    assert len(d["chatter_frequency_Hz"]) == 601
    ref = 2 * 2.26e8 * 0.012 * 1.012 / (1e9 * (0.866**2 / (0.866**2 + 0.25))) * 1e3
    assert d["absolute_limit_mm"] == pytest.approx(ref, rel=5e-3)


def test_simulate_contract_json_and_netcdf(tmp_path):
    p = _write(tmp_path, CONTRACT)
    nc = tmp_path / "out.nc"
    r = runner.invoke(app, ["simulate", "boring", str(p), "--speed-rpm", "9500", "--depth-mm",
                            "5", "--revolutions", "60", "--json", "--out", str(nc)])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    for k in ("stable", "chatter_frequency_Hz", "vibration_growth", "force_mean_N",
              "force_amplitude_N", "feed_amplitude_um"):
        assert k in d
    # no Ra tolerance in the config: the paper's criterion is not judged
    assert d["chatter"] is False and d["stable"] is None and d["chatter_frequency_Hz"] is None
    assert set(d["force_mean_N"]) == {"x", "y", "z"}
    # force = K a h u: 1e9 * 5e-3 * 1e-4 = 500 N along x at steady state
    assert d["force_mean_N"]["x"] == pytest.approx(500.0, rel=0.02)
    import xarray as xr

    with xr.open_dataset(nc) as ds:
        assert ds["force"].attrs["units"] == "N" and "robobore_config" in ds.attrs


def test_boring_example_runs(tmp_path):
    r = runner.invoke(app, ["simulate", "boring", str(EX / "boring_paper.toml"), "--json",
                            "--revolutions", "20"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert 5.0 < d["force_amplitude_N"]["x"] < 100.0  # tens of newtons (paper condition)
    r = runner.invoke(app, ["lobes", str(EX / "boring_paper.toml"), "--json", "--plot",
                            str(tmp_path)])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "lobes.png").is_file()


def test_simulate_feed_and_pressure_options():
    """--feed-mm-per-rev overrides the config's feed (the mean feed force and the chip grow with
    it); --pressure-MPa switches the foot; bad values are refused naming the option."""
    base = ["simulate", "boring", str(EX / "boring_paper.toml"), "--json", "--revolutions", "10"]
    d1 = json.loads(runner.invoke(app, base + ["--feed-mm-per-rev", "0.1"]).stdout)
    d2 = json.loads(runner.invoke(app, base + ["--feed-mm-per-rev", "0.2"]).stdout)
    assert d2["force_amplitude_N"]["x"] > 1.2 * d1["force_amplitude_N"]["x"]
    r = runner.invoke(app, base + ["--pressure-MPa", "0.3"])
    assert r.exit_code == 0, r.output
    for opt, val in (("--feed-mm-per-rev", "0"), ("--pressure-MPa", "-1")):
        r = runner.invoke(app, base + [opt, val])
        assert r.exit_code == 2 and opt in r.output


def test_model_equivalent_command():
    r = runner.invoke(app, ["model", "equivalent", "--stiffness-N-per-m", "1.2e6,0.9e6,1.5e6",
                            "--frequencies-Hz", "6.9,16.8,24.6", "--damping-N-s-per-m", "23.7",
                            "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    m = 1.2e6 / (2 * math.pi * 6.9) ** 2
    assert d["mass_kg"]["x"] == pytest.approx(m)
    assert d["damping_ratio"]["x"] == pytest.approx(23.7 / (2 * math.sqrt(1.2e6 * m)))


@pytest.mark.parametrize("old, new, key", [
    ("stiffness_N_per_m = 2.26e8", "stiffness_N_per_m = -2.26e8", "structure.modes.0.stiffness"),
    ("direction = [0.866, 0.5, 0.0]", "direction = [0.0, 0.0, 0.0]", "structure.modes.0.direction"),
    ("direction = [0.866, 0.5, 0.0]", "direction = [0.88, 0.5, 0.0]",
     "structure.modes.0.direction"),
    ("force_direction = [1.0, 0.0, 0.0]", "force_direction = [0.0, 0.0, 0.0]",
     "process.force_direction"),
    ("count = 601", "count = 0", "speed_rpm.count"),
    ("min = 2000.0", "min = -5.0", "speed_rpm.min"),
    ("feed_mm_per_rev = 0.1", "feed_mm_per_rev = 0.1\nfeed_typo = 1", "process.feed_typo"),
])
def test_bad_config_names_key(tmp_path, old, new, key):
    p = _write(tmp_path, CONTRACT.replace(old, new))
    r = runner.invoke(app, ["lobes", str(p), "--json"])
    assert r.exit_code == 2
    assert key in r.output and "c.toml" in r.output


def test_missing_sections(tmp_path):
    text = CONTRACT.split("[process]")[0]
    p = _write(tmp_path, text)
    r = runner.invoke(app, ["lobes", str(p)])
    assert r.exit_code == 2 and "missing section 'process'" in r.output
    assert "'insert', 'bore', 'cutting'" in r.output
    p = _write(tmp_path, "[process]" + CONTRACT.split("[process]")[1])
    r = runner.invoke(app, ["lobes", str(p)])
    assert r.exit_code == 2 and "'structure'" in r.output


@pytest.mark.parametrize("opt, val, key", [("--speed-rpm", "0", "--speed-rpm"),
                                           ("--depth-mm", "-1", "--depth-mm"),
                                           ("--depth-mm", "80", "--depth-mm")])
def test_out_of_range_options(tmp_path, opt, val, key):
    p = _write(tmp_path, CONTRACT)
    args = ["simulate", "boring", str(p), "--speed-rpm", "5000", "--depth-mm", "1"]
    args[args.index(opt) + 1] = val
    r = runner.invoke(app, args)
    assert r.exit_code == 2 and key in r.output


def test_api_run_boring_overrides():
    """One-call API: condition overrides (feed, foot pressure) act as documented."""
    from robobore.dynamics.api import lobes, run_boring

    ex = EX / "boring_paper.toml"
    base = run_boring(ex, revolutions=20)
    more_feed = run_boring(ex, feed_mm_per_rev=0.3, revolutions=20)
    foot = run_boring(ex, pressure_MPa=0.3, revolutions=20)
    assert more_feed.force_amplitude_N.x > base.force_amplitude_N.x
    assert foot.feed_amplitude_um < base.feed_amplitude_um
    assert base.speed_rpm == 300.0 and base.depth_mm == 0.05
    d = lobes(EX / "lobes_single_point.toml", method="frequency")
    assert len(d.critical_depth_mm) == 601


def test_model_equivalent_from_json_files(tmp_path):
    """The robot-stiffness and modal JSON contracts, a user assignment and the foot."""
    s = tmp_path / "stiff.json"
    s.write_text(json.dumps({"directional_stiffness_N_per_m": {"x": 1e6, "y": 2e6, "z": 3e6}}))
    m = tmp_path / "modes.json"
    m.write_text(json.dumps({"modes": [
        {"frequency_Hz": f, "damping_ratio": z, "mpc": 0.9}
        for f, z in zip([6.9, 16.8, 24.6, 25.34, 47.5], [0.035, 0.028, 0.02, 0.022, 0.05],
                        strict=True)]}))
    r = runner.invoke(app, ["model", "equivalent", "--stiffness-file", str(s), "--modes-file",
                            str(m), "--assign", "0,2,4", "--foot-pressure-MPa", "0.3", "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["damping_ratio"]["x"] > 0.035  # the foot adds contact damping
    assert d["frequency_Hz"]["z"] > 47.5 and "user mapping" in d["notes"][0]
    r = runner.invoke(app, ["model", "equivalent", "--stiffness-file", str(s), "--modes-file",
                            str(m), "--assign", "0,2,9"])
    assert r.exit_code == 2 and "assignment.z" in r.output


def test_cutting_trailing_edge_switch(tmp_path):
    """``[cutting] trailing_edge`` (default true) reaches the process: the trailing side of the
    nose adds depth-independent edge lengths, false leaves none; a non-boolean names the key."""
    from robobore.dynamics.config import build_process, load_dynamics_config

    text = (EX / "boring_paper.toml").read_text()
    on = build_process(load_dynamics_config(EX / "boring_paper.toml")[0])
    assert on.edge_fixed_m.sum() == pytest.approx(82.907e-6, rel=1e-4)  # r 0.4, 5 deg, f 0.15
    p = _write(tmp_path, text.replace("depth_mm = 0.05", "depth_mm = 0.05\ntrailing_edge = false"))
    off = build_process(load_dynamics_config(p)[0])
    assert not off.edge_fixed_m.any() and off.n_elements < on.n_elements
    p = _write(tmp_path, text.replace("depth_mm = 0.05", "depth_mm = 0.05\ntrailing_edge = 3"))
    r = runner.invoke(app, ["lobes", str(p), "--json"])
    assert r.exit_code == 2 and "cutting.trailing_edge" in r.output
