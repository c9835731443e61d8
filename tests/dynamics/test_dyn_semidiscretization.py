"""Semi-discretisation critical-depth search: robust on identified and random robot models,
agreement with the frequency domain where both apply, and the identification-to-lobes journey.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from robobore.cli import app
from robobore.cutting.coefficient_sets import ti64_coefficients
from robobore.cutting.geometry import BoringInsert
from robobore.dynamics.process import boring_process, single_point_process
from robobore.dynamics.semidiscretization import (
    DEPTH_SCAN_HI_M,
    critical_depth_semidiscretization,
    monodromy_spectral_radius,
)
from robobore.dynamics.stability import (
    lobes_frequency_domain,
    lobes_semidiscretization,
    sdof_absolute_limit,
    sdof_pocket_speeds,
)
from robobore.dynamics.structure import ToolPointStructure

EX = Path(__file__).resolve().parents[2] / "examples"
runner = CliRunner()


def _identified(tmp_path: Path) -> tuple[Path, Path]:
    """The outputs of ``identify stiffness --example --json`` and ``identify modes --example
    --json`` (the bundled SYNTHETIC campaign and hammer test), written as a user would."""
    s, m = tmp_path / "stiffness.json", tmp_path / "modes.json"
    r = runner.invoke(app, ["identify", "stiffness", "--example", "--json"])
    assert r.exit_code == 0, r.output
    s.write_text(r.stdout)
    r = runner.invoke(app, ["identify", "modes", "--example", "--json"])
    assert r.exit_code == 0, r.output
    m.write_text(r.stdout)
    return s, m


def test_lobes_of_the_identified_robot_in_one_command(tmp_path):
    """Acceptance (issue 31): from the identification outputs, the robot's semi-discretisation
    lobes are one command with a process-only TOML, no hand-editing; every speed gets a
    critical depth (finite, 0 or stable up to the scan top), never an error."""
    s, m = _identified(tmp_path)
    r = runner.invoke(app, ["lobes", str(EX / "boring_process.toml"), "--stiffness-file",
                            str(s), "--modes-file", str(m), "--json", "--plot",
                            str(tmp_path / "plots")])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["method"] == "semi-discretization"
    assert len(d["critical_depth_mm"]) == 96 and (tmp_path / "plots" / "lobes.png").is_file()
    depths = [math.inf if v is None else v for v in d["critical_depth_mm"]]
    assert all(v >= 0.0 for v in depths)
    fin = [v for v in depths if 0.0 < v < math.inf]
    # a robot of ~1 N/um boring TC4: finite limits at most speeds, of the order of the
    # paper's depths of cut (0.05-0.3 mm)
    assert len(fin) >= 48 and 0.005 < float(np.median(fin)) < 5.0


def test_identified_robot_crossing_is_bracketed(tmp_path):
    """At the paper's speeds the returned depth separates stable (x 0.99) from unstable
    (x 1.01) monodromy spectral radii on the identified example robot (the bundled campaign's,
    1.61 / 1.32 / 1.16 N/um: a case whose crossing a careless root bracket misses); a 0 is
    unstable down to the scan floor, an inf stable at the scan top."""
    from robobore.dynamics.config import build_process, build_structure, load_dynamics_config

    s, m = _identified(tmp_path)
    cfg, raw = load_dynamics_config(EX / "boring_process.toml", s, m)
    assert raw["model"]["stiffness_file"] == str(s.resolve())
    st, pr = build_structure(cfg), build_process(cfg)
    finite = 0
    for n in (200.0, 300.0, 500.0, 800.0, 1000.0, 1030.0):
        b = critical_depth_semidiscretization(st, pr, n)
        if b == 0.0:
            assert monodromy_spectral_radius(st, pr, n, DEPTH_SCAN_HI_M * 1e-7) >= 1.0
        elif b == math.inf:
            assert monodromy_spectral_radius(st, pr, n, DEPTH_SCAN_HI_M) < 1.0
        else:
            finite += 1
            assert monodromy_spectral_radius(st, pr, n, 0.99 * b) < 1.0
            assert monodromy_spectral_radius(st, pr, n, 1.01 * b) >= 1.0
    assert finite >= 3


def _random_robot(rng: np.random.Generator) -> ToolPointStructure:
    """A robot-like three-axis model: three orthogonal units (random frame), 4-60 Hz,
    0.3-10 N/um, 1-8 % damping."""
    q, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    f = np.sort(rng.uniform(4.0, 60.0, 3))
    k = 10 ** rng.uniform(np.log10(3e5), np.log10(1e7), 3)
    z = rng.uniform(0.01, 0.08, 3)
    return ToolPointStructure.from_modes([
        {"frequency_Hz": float(f[i]), "damping_ratio": float(z[i]),
         "stiffness_N_per_m": float(k[i]), "direction": q[:, i].tolist()} for i in range(3)])


@pytest.mark.slow
def test_200_random_robot_models_never_fail():
    """200 random robot-like three-axis models (seeded) with the rotating boring bar, two
    random speeds each in 150-1500 r/min: the search returns 0, a bracketed depth or inf
    (stable up to the scan top), never an exception."""
    rng = np.random.default_rng(31)
    ins = BoringInsert(nose_radius_m=0.4e-3, approach_angle_deg=90.0)
    counts = {"finite": 0, "zero": 0, "stable": 0}
    for _ in range(200):
        st = _random_robot(rng)
        pr = boring_process(ins, ti64_coefficients(30.0), rng.uniform(0.05, 0.3) * 1e-3,
                            rng.uniform(0.1, 0.5) * 1e-3)
        for n in rng.uniform(150.0, 1500.0, 2):
            b = critical_depth_semidiscretization(st, pr, float(n))
            assert b == 0.0 or b == math.inf or 0.0 < b < DEPTH_SCAN_HI_M
            counts["zero" if b == 0.0 else "stable" if b == math.inf else "finite"] += 1
    assert counts["finite"] > 200  # most cases have a finite critical depth


def test_sdof_semidiscretization_matches_closed_form_and_frequency_domain(sdof,
                                                                         contract_process):
    """Single mode (the contract case): at the first four pocket speeds semi-discretisation
    gives the closed-form absolute limit within 2 %, and at 12 speeds across the lobes the
    frequency-domain critical depth within 2 %."""
    ref = sdof_absolute_limit(2.26e8, 0.012, 1.0e9, float(sdof.directions[0, 0]) ** 2)
    pk = sdof_pocket_speeds(250.0, 0.012, 1, 4)
    sd = lobes_semidiscretization(sdof, contract_process, pk).critical_depth_m
    assert np.allclose(sd, ref, rtol=0.02)
    sp = np.linspace(3000.0, 9000.0, 12)
    fd = lobes_frequency_domain(sdof, contract_process, sp).critical_depth_m
    sd = lobes_semidiscretization(sdof, contract_process, sp).critical_depth_m
    ok = np.isfinite(fd) & (fd < DEPTH_SCAN_HI_M)
    assert ok.sum() >= 8
    assert np.allclose(sd[ok], fd[ok], rtol=0.02)
    assert np.all(np.isinf(sd[~ok]))  # above the scan top: stable up to it


def test_well_separated_robot_modes_agree_with_frequency_domain():
    """Three orthogonal robot-like modes (7, 17, 25 Hz) and a fixed-direction single-point
    process (both methods apply): critical depths agree within 2 % at 10 speeds."""
    st = ToolPointStructure.from_modes([
        {"frequency_Hz": 7.0, "damping_ratio": 0.035, "stiffness_N_per_m": 1.6e6,
         "direction": [1, 0, 0]},
        {"frequency_Hz": 17.0, "damping_ratio": 0.028, "stiffness_N_per_m": 1.3e6,
         "direction": [0, 1, 0]},
        {"frequency_Hz": 25.0, "damping_ratio": 0.02, "stiffness_N_per_m": 1.2e6,
         "direction": [0, 0, 1]}])
    a, b = np.radians(30.0), np.radians(20.0)
    pr = single_point_process(2e9, [np.cos(a), np.sin(a), 0.0], [np.cos(b), 0.0, np.sin(b)],
                              1e-4)
    sp = np.linspace(200.0, 1100.0, 10)
    fd = lobes_frequency_domain(st, pr, sp).critical_depth_m
    sd = lobes_semidiscretization(st, pr, sp).critical_depth_m
    assert np.all(np.isfinite(fd)) and np.all(np.isfinite(sd))
    assert np.allclose(sd, fd, rtol=0.02)


def test_model_files_in_the_toml_resolved_relative_to_it(tmp_path):
    """``[model]`` keys name the identification outputs relative to the TOML; simulate boring
    runs from them, and from an equivalent-model JSON (``model equivalent --json``)."""
    d = tmp_path / "job"
    d.mkdir()
    s, m = _identified(d)
    text = (EX / "boring_process.toml").read_text()
    (d / "p.toml").write_text('[model]\nstiffness_file = "stiffness.json"\n'
                              'modes_file = "modes.json"\n' + text)
    r = runner.invoke(app, ["simulate", "boring", str(d / "p.toml"), "--revolutions", "20",
                            "--json"])
    assert r.exit_code == 0, r.output
    a = json.loads(r.stdout)
    r = runner.invoke(app, ["model", "equivalent", "--stiffness-file", str(s), "--modes-file",
                            str(m), "--json"])
    assert r.exit_code == 0, r.output
    (tmp_path / "eq.json").write_text(r.stdout)
    r = runner.invoke(app, ["simulate", "boring", str(EX / "boring_process.toml"),
                            "--equivalent-file", str(tmp_path / "eq.json"),
                            "--revolutions", "20", "--json"])
    assert r.exit_code == 0, r.output
    b = json.loads(r.stdout)
    assert b["feed_amplitude_um"] == pytest.approx(a["feed_amplitude_um"], rel=1e-9)


@pytest.mark.parametrize("args, msg", [
    (["--stiffness-file", "S"], "needs a modes file"),
    (["--equivalent-file", "E", "--modes-file", "M"], "not both"),
    (["--equivalent-file", "missing.json"], "file not found"),
])
def test_model_file_errors_name_the_option(tmp_path, args, msg):
    s, m = _identified(tmp_path)
    e = tmp_path / "e.json"
    e.write_text("{}")
    args = [{"S": str(s), "M": str(m), "E": str(e)}.get(x, x) for x in args]
    r = runner.invoke(app, ["lobes", str(EX / "boring_process.toml"), *args])
    assert r.exit_code == 2 and msg in r.output, r.output


def test_model_given_twice_is_refused(tmp_path):
    s, m = _identified(tmp_path)
    r = runner.invoke(app, ["lobes", str(EX / "boring_paper.toml"), "--stiffness-file", str(s),
                            "--modes-file", str(m)])
    assert r.exit_code == 2 and "given twice" in r.output


def test_arpack_and_dense_spectral_radius_agree():
    """Large monodromy matrices go to ARPACK: the spectral radius equals the dense one."""
    from robobore.dynamics import semidiscretization as S

    st = ToolPointStructure.from_modes([
        {"frequency_Hz": 7.0, "damping_ratio": 0.035, "stiffness_N_per_m": 1.6e6,
         "direction": [1, 0, 0]},
        {"frequency_Hz": 25.0, "damping_ratio": 0.02, "stiffness_N_per_m": 1.2e6,
         "direction": [0, 1, 0]}])
    pr = boring_process(BoringInsert(nose_radius_m=0.4e-3), ti64_coefficients(30.0), 1e-4,
                        1.5e-4)
    old = S.DENSE_EIG_MAX
    try:
        for depth in (2e-5, 1e-4, 3e-4):
            S.DENSE_EIG_MAX = 10_000
            dense = monodromy_spectral_radius(st, pr, 200.0, depth)
            S.DENSE_EIG_MAX = 10
            sparse = monodromy_spectral_radius(st, pr, 200.0, depth)
            assert sparse == pytest.approx(dense, rel=1e-8)
    finally:
        S.DENSE_EIG_MAX = old


def test_unconditionally_stable_is_reported_with_its_limit(tmp_path):
    """A mode orthogonal to the chip normal cannot regenerate: no critical depth at any speed;
    the CLI says "unconditionally stable up to 50 mm" and the JSON gives nulls and the limit."""
    p = tmp_path / "c.toml"
    p.write_text("""
[[structure.modes]]
frequency_Hz = 250.0
damping_ratio = 0.05
stiffness_N_per_m = 5e9
direction = [1.0, 0.0, 0.0]
[process]
cutting_coefficient_N_per_m2 = 1.0e9
force_direction = [1.0, 0.0, 0.0]
chip_normal = [0.0, 1.0, 0.0]
feed_mm_per_rev = 0.1
[speed_rpm]
min = 2000.0
max = 3000.0
count = 5
""")
    r = runner.invoke(app, ["lobes", str(p), "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["critical_depth_mm"] == [None] * 5 and d["absolute_limit_mm"] is None
    assert d["depth_scan_max_mm"] == pytest.approx(50.0) and d["stable_speeds"] == 5
    assert "unconditionally stable up to 50 mm" in d["notes"][0]
    r = runner.invoke(app, ["lobes", str(p)])
    assert r.exit_code == 0 and "none up to 50" in r.output


def test_radius_above_one_where_the_cut_is_interrupted_leaves_the_window_above(tmp_path):
    """The identified example robot at 1100 r/min: the spectral radius is above 1 at vanishing
    depth, where the steady cut is interrupted (the depth-independent trailing-edge force
    pulls the tool out of a shallow cut), so the linearisation says nothing there. The
    chatter-free window starts where the cut stays in the material and ends at the first
    crossing of 1 above it; inside it (0.05 mm) the radius and the simulated multiplier
    agree and the time domain decides no chatter."""
    from robobore.dynamics.chatter import classify
    from robobore.dynamics.config import build_process, build_structure, load_dynamics_config
    from robobore.dynamics.semidiscretization import chatter_free_window, interrupted_below
    from robobore.dynamics.timedomain import SimulationSettings, simulate

    s, m = _identified(tmp_path)
    cfg, _ = load_dynamics_config(EX / "boring_process.toml", s, m)
    st, pr = build_structure(cfg), build_process(cfg)
    n = 1100.0
    below, ac = chatter_free_window(st, pr, n)
    assert 0.0 < below < 0.05e-3 < ac < 0.5e-3
    assert monodromy_spectral_radius(st, pr, n, 5e-6) >= 1.0  # the linear answer down there
    assert interrupted_below(st, pr, n, 0.9 * below) >= 0.9 * below  # but the cut is out
    assert interrupted_below(st, pr, n, 1.1 * below) < 1.1 * below
    assert monodromy_spectral_radius(st, pr, n, 0.99 * ac) < 1.0
    assert monodromy_spectral_radius(st, pr, n, 1.01 * ac) >= 1.0
    a = 0.05e-3
    rho = monodromy_spectral_radius(st, pr, n, a)
    v = classify(simulate(st, pr, SimulationSettings(n, a, revolutions=150),
                          cfg.insert.to_insert()))
    assert v.chatter_decided and not v.chatter and not v.tool_leaves_cut
    assert rho < 1.0 and abs(v.floquet_multiplier - rho) < 5e-3


def test_critical_depth_does_not_depend_on_what_ran_before():
    """A limit is a function of its arguments: the Arnoldi warm starts live within one search
    (semidiscretization._search_scope), so a search after others of the same monodromy
    dimension (another robot, other speeds) returns the same digits as the first one."""
    from robobore.dynamics import semidiscretization as sd
    from robobore.dynamics.band import critical_depths
    from robobore.dynamics.calibrate import Observation, build_problem
    from robobore.dynamics.config import load_dynamics_config

    root = Path(__file__).resolve().parents[2]
    cfg, _ = load_dynamics_config(root / "examples" / "boring_paper.toml")
    pb = build_problem(cfg, [Observation(1, 1e3, 1e-3, False)])
    st, pr = pb.structure, pb.process
    speeds = np.array([700.0, 1250.0, 2300.0])
    assert sd.auto_steps(st, pr, 700.0) * 3 + 6 > sd.DENSE_EIG_MAX  # the Arnoldi path
    first = critical_depths(st, pr, speeds)
    other = pb.structure_at(np.array([-0.5, -0.3, -0.4, 0.25, -0.1, 0.05]))
    critical_depths(other, pr, speeds[::-1])  # leaves eigenvectors of the same dimensions
    critical_depths(other, pr, speeds + 37.0)
    again = critical_depths(st, pr, speeds)
    assert np.array_equal(first, again), (first, again)
    assert sd._WARM_STARTS.get() is None  # nothing kept once the searches end
    rho = sd.monodromy_spectral_radius(st, pr, 1250.0, float(first[1]))
    critical_depths(other, pr, speeds)
    assert sd.monodromy_spectral_radius(st, pr, 1250.0, float(first[1])) == rho


def test_a_structure_whose_nominal_cut_map_overflows_gives_a_limit_not_an_error():
    """A structure far from any robot (x stiffness x e^-12, x damping x e^-17) whose
    one-revolution map of the nominal cut overflows at a deep trial depth: no steady orbit,
    and the search goes on."""
    from robobore.dynamics.calibrate import Observation, build_problem
    from robobore.dynamics.config import load_dynamics_config
    from robobore.dynamics.semidiscretization import critical_depth_semidiscretization
    from robobore.dynamics.timedomain import nominal_cut_deflection

    root = Path(__file__).resolve().parents[2]
    cfg, _ = load_dynamics_config(root / "examples" / "boring_paper.toml")
    pb = build_problem(cfg, [Observation(1, 1e3, 1e-3, False)])
    st = pb.structure_at(np.array([-16.825, -0.617, -0.538, -12.308, -0.148, -0.159]))
    deep = pb.process.at_depth(0.02)
    assert nominal_cut_deflection(st, deep, 1250.0) is None
    assert nominal_cut_deflection(st, pb.process.at_depth(1e-3), 1250.0) is not None
    a = critical_depth_semidiscretization(st, pb.process, 1250.0, guess_m=0.02)
    assert math.isfinite(a) and 0.0 <= a < 0.02
