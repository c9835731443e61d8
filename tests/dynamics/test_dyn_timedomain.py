"""Time-domain simulation against the lobes, mode coupling, static forces, surface."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robobore.cutting.forces import CuttingCoefficients, boring_forces
from robobore.cutting.geometry import BoringInsert
from robobore.dynamics.chatter import classify
from robobore.dynamics.process import boring_process
from robobore.dynamics.semidiscretization import monodromy_spectral_radius
from robobore.dynamics.stability import (
    lobes_frequency_domain,
    mode_coupling,
    mode_coupling_limit,
    sdof_pocket_speeds,
)
from robobore.dynamics.structure import ToolPointStructure
from robobore.dynamics.timedomain import SimulationSettings, simulate, summarize


@pytest.mark.parametrize("speed", ["pocket", 9500.0])
def test_time_domain_agrees_with_lobes(sdof, contract_process, speed):
    """At a lobe-minimum (pocket) speed and at a speed on the flank, 0.9 x the
    frequency-domain critical depth decays and 1.1 x grows over 150 revolutions."""
    n = sdof_pocket_speeds(250.0, 0.012, 1, 3)[1] if speed == "pocket" else speed
    b = lobes_frequency_domain(sdof, contract_process, np.array([n])).critical_depth_m[0]
    lo = classify(simulate(sdof, contract_process, SimulationSettings(n, 0.9 * b, 150)))
    hi = classify(simulate(sdof, contract_process, SimulationSettings(n, 1.1 * b, 150)))
    assert lo.chatter is False and lo.vibration_growth < 0.5
    assert hi.chatter and hi.vibration_growth > 2.0
    assert hi.chatter_frequency_Hz == pytest.approx(255.0, abs=8.0)


def test_tool_leaves_cut_and_vibration_saturates(sdof, contract_process):
    """Well above the limit the tool jumps out of the cut (h <= 0: no force, surface kept), so
    the chatter amplitude stays bounded (nonlinear saturation) instead of growing forever."""
    n = 9500.0
    b = lobes_frequency_domain(sdof, contract_process, np.array([n])).critical_depth_m[0]
    ds = simulate(sdof, contract_process, SimulationSettings(n, 1.5 * b, 400))
    v = classify(ds)
    assert v.chatter and v.tool_left_cut_fraction > 0.05
    x = ds["displacement"].values[:, 0]
    Ns = ds.attrs["samples_per_rev"]
    late = np.abs(x[-50 * Ns:]).max()
    mid = np.abs(x[-150 * Ns:-100 * Ns]).max()
    assert late < 1.5 * mid  # saturated, not exponential


def test_diverging_cut_stops_flagged_not_nan(sdof, contract_process):
    """A growing cut whose tool-point displacement passes the divergence limit stops at the
    last whole revolution, is flagged ``diverged`` and classified vibratory; outputs stay
    finite (no NaN, no exception). The limit here is set low (2 x the nominal chip) so that the
    1.1 x critical-depth case of the contract example reaches it; without the limit the same
    run completes all revolutions (checked: it saturates far below any overflow)."""
    n = sdof_pocket_speeds(250.0, 0.012, 1, 3)[1]
    b = lobes_frequency_domain(sdof, contract_process, np.array([n])).critical_depth_m[0]
    free = simulate(sdof, contract_process, SimulationSettings(n, 1.5 * b, 150))
    assert not free.attrs["diverged"] and free.attrs["revolutions"] == 150
    xmax = np.abs(free["displacement"].values).max()
    lim = 0.5 * xmax
    ds = simulate(sdof, contract_process,
                  SimulationSettings(n, 1.5 * b, 150, divergence_limit_m=lim))
    assert ds.attrs["diverged"] == 1
    revs = ds.attrs["revolutions"]
    assert 1 <= revs < 150
    assert ds["displacement"].shape[0] == revs * ds.attrs["samples_per_rev"]
    assert np.all(np.isfinite(ds["displacement"].values))
    assert ds.attrs["diverged_at_s"] >= revs * 60.0 / n
    v = classify(ds)
    assert v.chatter and any("diverged" in r for r in v.reasons)


def test_divergence_in_first_revolution_is_a_clear_error(sdof, contract_process):
    from robobore.errors import ConfigError, NumericalError

    n = 9500.0
    b = lobes_frequency_domain(sdof, contract_process, np.array([n])).critical_depth_m[0]
    with pytest.raises(NumericalError, match="first revolution"):
        simulate(sdof, contract_process,
                 SimulationSettings(n, b, 10, divergence_limit_m=1e-12))
    with pytest.raises(ConfigError, match="divergence"):
        simulate(sdof, contract_process, SimulationSettings(n, b, 10, divergence_limit_m=0.0))


def test_mode_coupling_case(coupling_case):
    """Two orthogonal close modes, force between them (Pan et al. 2006): at 60 um and 2500
    r/min each mode alone is regeneratively stable (classical per-mode lobes), the
    mode-coupling criterion flags instability, and the simulation grows at a frequency between
    the two modes; at 15 um all agree it is stable."""
    st, pr = coupling_case()
    n, b = 2500.0, 60e-6
    per_mode = [lobes_frequency_domain(ToolPointStructure.from_modes([m]), pr,
                                       np.array([n])).critical_depth_m[0] for m in st.modes()]
    assert min(per_mode) > b  # regeneration of each mode alone: stable
    assert mode_coupling(st, pr, b).unstable and mode_coupling_limit(st, pr) < b
    v = classify(simulate(st, pr, SimulationSettings(n, b, 150)))
    assert v.chatter and v.vibration_growth > 2
    assert 19.5 < v.chatter_frequency_Hz < 21.5
    assert not mode_coupling(st, pr, 15e-6).unstable
    assert classify(simulate(st, pr, SimulationSettings(n, 15e-6, 150))).chatter is False


def _rigid():
    return ToolPointStructure.from_modes([
        {"frequency_Hz": 3000.0, "damping_ratio": 0.05, "stiffness_N_per_m": 1e12,
         "direction": d} for d in ([1, 0, 0], [0, 1, 0], [0, 0, 1])])


def test_rigid_boring_reproduces_static_forces():
    """On a (nearly) rigid structure the simulated boring forces equal the static mechanistic
    model: rotating force of amplitude sqrt(Ft^2 + Fr^2) in X and Y, constant feed force (1 %)."""
    ins = BoringInsert(nose_radius_m=0.4e-3)
    c = CuttingCoefficients(Ktc=1.6e9, Krc=0.0, Kfc=0.3e9, Kte=2e4, Kfe=4e4)
    ap, f = 0.3e-3, 0.15e-3
    pr = boring_process(ins, c, ap, f, n_elements=30)
    ds = simulate(_rigid(), pr, SimulationSettings(300.0, ap, 6, samples_per_rev=720), ins)
    s = summarize(ds)
    ref = boring_forces(ins, ap, f, c, n_elements=30)
    amp = math.hypot(ref["tangential_N"], ref["radial_N"])
    assert s["force_amplitude_N"]["x"] == pytest.approx(amp, rel=0.01)
    assert s["force_amplitude_N"]["y"] == pytest.approx(amp, rel=0.01)
    assert s["force_mean_N"]["z"] == pytest.approx(ref["feed_N"], rel=0.01)
    assert ds["force"].attrs["units"] == "N" and ds["displacement"].attrs["units"] == "m"


def test_trailing_edge_rubs_with_a_feed_set_length():
    """The trailing side of the nose (rubbing elements, h0 = 0): rigid tool, edge coefficients
    only (Ktc negligible). A process built at 0.3 mm and simulated at 0.15 mm is the chip at
    0.15 mm (the process is rebuilt at the simulated depth): tangential amplitude
    Kte (L_lead + L_trail) and feed mean from the element orientations of edge_elements at
    0.15 mm (1 %). Linearised once at 0.3 mm with its widths scaled to 0.15 mm instead
    (``fixed()``), the leading edge would stretch while the trailing side keeps its length.
    The trailing elements carry no chip width and leave the regenerative directional matrix
    and the depth-modulation stiffness unchanged (1e-12)."""
    from robobore.cutting.geometry import edge_elements

    ins = BoringInsert(nose_radius_m=0.4e-3)
    c = CuttingCoefficients(Ktc=1.0, Krc=0.0, Kfc=0.0, Kte=2e4, Kfe=4e4)
    ref, a, f = 0.3e-3, 0.15e-3, 0.15e-3
    pr = boring_process(ins, c, ref, f, n_elements=30)
    off = boring_process(ins, c, ref, f, n_elements=30, trailing_edge=False)
    el = edge_elements(ins, ref, f, 30)
    tr = el.trailing
    assert np.all(pr.h0[tr] == 0) and np.all(pr.width_per_depth[tr] == 0)
    assert np.all(pr.edge_per_depth[tr] == 0) and np.allclose(pr.edge_fixed_m[tr], el.dS[tr])
    assert np.all(pr.edge_fixed_m[~tr] == 0)
    th = np.linspace(0.0, 2 * np.pi, 7)
    assert np.allclose(pr.directional_matrix(th), off.directional_matrix(th), rtol=1e-12,
                       atol=0)
    assert np.allclose(pr.process_stiffness(th), off.process_stiffness(th), rtol=1e-12,
                       atol=0)
    settings = SimulationSettings(300.0, a, 6, samples_per_rev=720)
    s = summarize(simulate(_rigid(), pr, settings, ins))
    ea = edge_elements(ins, a, f, 30)
    ta = ea.trailing
    ft = 2e4 * (ea.leading_length + ea.trailing_length)
    ff = -4e4 * np.sum(np.sin(ea.kappa) * ea.dS)
    fr = -4e4 * np.sum(np.cos(ea.kappa) * ea.dS)
    assert s["force_amplitude_N"]["x"] == pytest.approx(math.hypot(ft, fr), rel=0.01)
    assert s["force_mean_N"]["z"] == pytest.approx(ff, rel=0.01)
    assert np.any(ta)
    # the same run from the process built at 0.15 mm
    s2 = summarize(simulate(_rigid(), boring_process(ins, c, a, f, n_elements=30), settings,
                            ins))
    assert s2["force_amplitude_N"]["x"] == pytest.approx(s["force_amplitude_N"]["x"],
                                                         rel=1e-12)
    # linearised once at 0.3 mm: the leading edge stretched linearly, the trailing side kept
    sf = summarize(simulate(_rigid(), pr.fixed(), settings, ins))
    ft_fixed = 2e4 * (el.leading_length * a / ref + el.trailing_length)
    ff_fixed = -4e4 * (np.sum(np.sin(el.kappa[~tr]) * el.dS[~tr]) * a / ref
                       + np.sum(np.sin(el.kappa[tr]) * el.dS[tr]))
    fr_fixed = -4e4 * (np.sum(np.cos(el.kappa[~tr]) * el.dS[~tr]) * a / ref
                       + np.sum(np.cos(el.kappa[tr]) * el.dS[tr]))
    assert sf["force_amplitude_N"]["x"] == pytest.approx(math.hypot(ft_fixed, fr_fixed),
                                                         rel=0.01)
    assert sf["force_mean_N"]["z"] == pytest.approx(ff_fixed, rel=0.01)


def test_surface_roughness_of_round_nose():
    """Rigid tool, feed inside the nose arc: Ra = f^2 / (18 sqrt(3) r) = 0.0321 f^2 / r and
    Rz = f^2 / (8 r) (circular-arc feed marks, e.g. Shaw, Metal Cutting Principles). 3 %."""
    ins = BoringInsert(nose_radius_m=0.8e-3, end_edge_angle_deg=30.0)
    c = CuttingCoefficients(Ktc=1.6e9, Krc=0.0, Kfc=0.3e9)
    f = 0.2e-3
    pr = boring_process(ins, c, 0.5e-3, f)
    ds = simulate(_rigid(), pr, SimulationSettings(300.0, 0.5e-3, 50, 360), ins)
    assert ds.attrs["Ra_m"] == pytest.approx(f**2 / (18 * math.sqrt(3) * 0.8e-3), rel=0.03)
    assert ds.attrs["Rz_m"] == pytest.approx(f**2 / (8 * 0.8e-3), rel=0.03)


def test_two_inserts_halve_the_lobe_speeds(sdof):
    """Delay 1/(N n): two inserts cutting at once (fixed force direction) see the delay of one
    insert at twice the speed and twice the force per depth: b_2(n) = b_1(2 n) / 2 (exact);
    the simulation (surface regenerated insert by insert) agrees at 0.9 / 1.1 x."""
    from robobore.dynamics.process import single_point_process

    p1 = single_point_process(1e9, [1, 0, 0], [1, 0, 0], 1e-4, n_inserts=1)
    p2 = single_point_process(1e9, [1, 0, 0], [1, 0, 0], 1e-4, n_inserts=2)
    s = np.array([4000.0, 6000.0, 8000.0])
    a = lobes_frequency_domain(sdof, p1, 2 * s).critical_depth_m
    b = lobes_frequency_domain(sdof, p2, s).critical_depth_m
    assert np.allclose(a, 2 * b, rtol=1e-9)
    n = 4332.0  # half of the second pocket speed: 2 inserts at 0.9 x limit decay
    lim = lobes_frequency_domain(sdof, p2, np.array([n])).critical_depth_m[0]
    assert classify(simulate(sdof, p2, SimulationSettings(n, 0.9 * lim, 150))).chatter is False
    assert classify(simulate(sdof, p2, SimulationSettings(n, 1.1 * lim, 150))).chatter


def test_pressure_foot_suppresses_vibration():
    """Paper: the pressure foot (P = 0.3 MPa) suppresses the feed-direction vibration. With the
    assumed contact model the feed amplitude at ap = 0.05 mm, f = 0.5 mm/r, 300 r/min drops by
    more than 10 x and the robot's frequencies rise."""
    import tomllib
    from pathlib import Path

    from robobore.dynamics.config import (
        DynamicsConfig,
        build_process,
        build_structure,
    )
    from robobore.io.config import validate_model

    ex = Path(__file__).resolve().parents[2] / "examples" / "boring_paper.toml"
    raw = tomllib.loads(ex.read_text())
    raw["cutting"].update(speed_rpm=300.0, depth_mm=0.05, feed_mm_per_rev=0.5)
    amps = []
    freqs = []
    for foot in (None, {"pressure_MPa": 0.3}):
        r = {**raw, "equivalent": dict(raw["equivalent"])}
        if foot:
            r["equivalent"]["pressure_foot"] = foot
        cfg = validate_model(DynamicsConfig, r)
        st = build_structure(cfg)
        ds = simulate(st, build_process(cfg), SimulationSettings(300.0, 0.05e-3, 40),
                      cfg.insert.to_insert())
        amps.append(summarize(ds)["feed_amplitude_m"])
        freqs.append(st.frequency_Hz)
    assert amps[1] < 0.1 * amps[0]
    assert np.all(freqs[1] > freqs[0])


def test_zoh_discretisation_matches_matrix_exponential(sdof):
    """Closed-form ZOH step = expm of the augmented state matrix (Van Loan), to 1e-10."""
    from scipy.linalg import expm

    from robobore.dynamics.timedomain import modal_zoh

    dt = 1.3e-4
    Phi, Gam = modal_zoh(sdof, dt)
    w, z, m = sdof.omega[0], sdof.damping_ratio[0], sdof.modal_mass[0]
    H = np.array([[0, 1, 0], [-w * w, -2 * z * w, 1 / m], [0, 0, 0]])
    E = expm(H * dt)
    assert np.allclose(Phi[0], E[:2, :2], rtol=1e-10, atol=1e-14)
    assert np.allclose(Gam[0], E[:2, 2], rtol=1e-10, atol=1e-20)


def test_rotating_bar_semidiscretization_vs_time_domain():
    """Rotating boring bar (time-periodic directions) on a stiff, machine-tool-like structure
    where the static deflection is a negligible part of the depth: the semi-discretised
    (Floquet) critical depth separates decaying (0.9 x) from growing (1.1 x) simulations."""
    from robobore.cutting.coefficient_sets import ti64_coefficients
    from robobore.dynamics.semidiscretization import critical_depth_semidiscretization

    st = ToolPointStructure.from_modes([
        {"frequency_Hz": 180.0, "damping_ratio": 0.02, "stiffness_N_per_m": 2.0e7,
         "direction": [1, 0, 0]},
        {"frequency_Hz": 210.0, "damping_ratio": 0.025, "stiffness_N_per_m": 2.5e7,
         "direction": [0, 1, 0]},
        {"frequency_Hz": 300.0, "damping_ratio": 0.03, "stiffness_N_per_m": 8e7,
         "direction": [0, 0, 1]}])
    ins = BoringInsert(nose_radius_m=0.4e-3, approach_angle_deg=75.0)
    pr = boring_process(ins, ti64_coefficients(30.0), 1.0e-3, 0.1e-3)
    n = 3000.0
    b = critical_depth_semidiscretization(st, pr, n)
    lo = classify(simulate(st, pr, SimulationSettings(n, 0.9 * b, 150)))
    hi = classify(simulate(st, pr, SimulationSettings(n, 1.1 * b, 150)))
    assert lo.chatter is False and lo.vibration_growth < 0.1
    assert hi.chatter and hi.vibration_growth > 5


@pytest.mark.parametrize("speed", [300.0, 700.0])
def test_robot_boring_semidiscretization_vs_time_domain(speed):
    """The robot example (modes 6.9-24.6 Hz, ~3 N/um, TC4, nose 0.4 mm): semi-discretisation
    linearised about the steady deflected path separates decaying (0.9 x) from growing
    (1.1 x) simulations over 150 revolutions."""
    from pathlib import Path

    from robobore.dynamics.config import build_process, build_structure, load_dynamics_config
    from robobore.dynamics.semidiscretization import critical_depth_semidiscretization

    ex = Path(__file__).resolve().parents[2] / "examples" / "boring_paper.toml"
    cfg, _ = load_dynamics_config(ex)
    st, pr = build_structure(cfg), build_process(cfg)
    b = critical_depth_semidiscretization(st, pr, speed)
    for fac, chatter in ((0.9, False), (1.1, True)):
        v = classify(simulate(st, pr, SimulationSettings(speed, fac * b, 150)))
        rho = monodromy_spectral_radius(st, pr, speed, fac * b)
        # the simulated cut's growth per revolution is the lobes' spectral radius
        assert v.chatter is chatter and v.chatter_decided
        assert v.floquet_multiplier == pytest.approx(rho, abs=2e-3)


@pytest.mark.parametrize("depth_mm", [0.3, 3.0])
def test_a_continued_run_is_the_longer_run_digit_for_digit(depth_mm):
    """TimeDomainRun.extend continues from the modal state, the surface and when each angle
    was cut: R revolutions extended by R are the 2R-revolution run, every sample equal (a
    decaying and a diverging cut)."""
    from robobore.cutting.coefficient_sets import ti64_coefficients
    from robobore.dynamics.timedomain import SimulationSettings, TimeDomainRun, simulate

    st = ToolPointStructure.from_modes([
        {"frequency_Hz": 40.0, "damping_ratio": 0.03, "stiffness_N_per_m": 2e6,
         "direction": [1, 0, 0]},
        {"frequency_Hz": 55.0, "damping_ratio": 0.02, "stiffness_N_per_m": 3e6,
         "direction": [0, 1, 0]}])
    pr = boring_process(BoringInsert(), ti64_coefficients(30.0), depth_mm * 1e-3, 0.15e-3)
    s1 = SimulationSettings(600.0, depth_mm * 1e-3, 12, 240)
    run = TimeDomainRun(st, pr, s1)
    run.extend(12)
    cont = run.dataset()
    full = simulate(st, pr, SimulationSettings(600.0, depth_mm * 1e-3, 24, 240))
    assert cont.attrs == full.attrs
    for name in full.data_vars:
        assert np.array_equal(cont[name].values, full[name].values, equal_nan=True), name
