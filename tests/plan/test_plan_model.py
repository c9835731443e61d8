"""Pose-dependent model: closed-form two-link arm, consistency with the stiffness model and an
independent (finite-difference) multibody computation, calibration, IK branches, and the
batched critical depth against the stability module."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robobore.errors import InputError
from robobore.plan.inertia import ToolBody
from robobore.plan.model import PoseModel, calibrate
from robobore.robot.description import LinkInertia, Robot, get_robot
from robobore.robot.kinematics import fk

PAPER_Q = np.radians([-48.38, 54.82, 6.86, -54.16, 107.43, -21.95])
K6 = np.array([3.0e6, 4.0e6, 2.6e6, 4.7e5, 4.5e5, 2.6e5])
TOOL = ToolBody(60.0, (0.0, 0.0, 0.15), (0.95, 0.95, 0.3, 0.0, 0.0, 0.0))


@pytest.fixture(scope="module")
def rb():
    return get_robot("irb6600-175-2.55")


def two_link_closed_form(l1, l2, m1, m2, k1, k2, th2):
    """Natural frequencies [Hz] of a planar 2R arm with point masses at the link ends and
    joint springs: det(K - w^2 M) = 0 with M11 = (m1+m2) l1^2 + m2 l2^2 + 2 m2 l1 l2 c2,
    M12 = m2 l2^2 + m2 l1 l2 c2, M22 = m2 l2^2 (e.g. Spong et al. 2006, sec. 7.3)."""
    c2 = np.cos(th2)
    M11 = (m1 + m2) * l1 ** 2 + m2 * l2 ** 2 + 2 * m2 * l1 * l2 * c2
    M12 = m2 * l2 ** 2 + m2 * l1 * l2 * c2
    M22 = m2 * l2 ** 2
    a = M11 * M22 - M12 ** 2
    b = k1 * M22 + k2 * M11
    disc = np.sqrt(b * b - 4 * a * k1 * k2)
    w2 = np.stack([(b - disc) / (2 * a), (b + disc) / (2 * a)], axis=1)
    return np.sqrt(w2) / (2 * np.pi)


def test_two_link_frequencies_match_closed_form_at_20_postures():
    l1, l2, m1, m2, k1, k2 = 1.0, 0.7, 20.0, 8.0, 5.0e4, 2.0e4
    zero = (0.0,) * 6
    r = Robot("planar-2r", (0.0, 0.0), (l1, l2), (0.0, 0.0), (0.0, 0.0), (-3.1, -3.1),
              (3.1, 3.1), links=(LinkInertia(m1, (0, 0, 0), zero),
                                 LinkInertia(m2, (0, 0, 0), zero)))
    th2 = np.linspace(-3.0, 3.0, 20)
    Q = np.column_stack([np.linspace(-1, 1, 20), th2])  # q1 must not matter
    pm = PoseModel(r, np.array([k1, k2]), np.zeros(2)).modes(Q, frame="base")
    ref = two_link_closed_form(l1, l2, m1, m2, k1, k2, th2)
    err = np.abs(pm.frequency_Hz / ref - 1)
    assert err.max() < 0.005
    assert err.max() < 1e-9  # the model is exact for this case


def test_static_compliance_is_the_stiffness_model(rb):
    from robobore.robot.stiffness import directional_stiffness_xyz

    pm = PoseModel(rb, K6, np.zeros(6), tool=TOOL).modes(PAPER_Q)
    ref = directional_stiffness_xyz(rb, PAPER_Q, K6, frame="boring")
    assert np.allclose(pm.directional_stiffness[0], [ref[a] for a in "xyz"], rtol=1e-9)
    # the modal sum reproduces the compliance; the FRF tends to it at w -> 0
    w = 2 * np.pi * pm.frequency_Hz[0]
    Cm = np.einsum("ja,jb,j->ab", pm.u[0], pm.u[0], 1 / w ** 2)
    assert np.allclose(Cm, pm.compliance[0], rtol=1e-8, atol=1e-15)
    G0 = pm.frf(0, np.array([1e-6]))[:, :, 0]
    assert np.allclose(G0.real, pm.compliance[0], rtol=1e-6, atol=1e-15)


def test_mass_matrix_matches_independent_finite_difference_multibody(rb, monkeypatch):
    """The SYNTHETIC truth code (Jacobians by central differences, its own transform chain)
    with rigid links, the library masses and no bending must give the planner's modes."""
    import robobore.plan.synthetic as S

    monkeypatch.setattr(S, "TRUTH_MASS_FACTOR", np.ones(6))
    monkeypatch.setattr(S, "RIGID_SHARE", 1.0)
    truth = S.TruthRobot(rb, bend_scale=1e6)
    ev = truth.evaluate(PAPER_Q)
    pm = PoseModel(rb, S.TRUTH_JOINT_K, S.TRUTH_JOINT_C, tool=S.TOOL).modes(PAPER_Q)
    assert np.allclose(ev["frequency_Hz"][:6], pm.frequency_Hz[0], rtol=1e-5)
    assert np.allclose(ev["damping_ratio"][:6], pm.damping_ratio[0], rtol=1e-4)
    assert np.allclose(ev["directional_stiffness"], pm.directional_stiffness[0], rtol=1e-5)


def test_mass_matrix_symmetric_positive_and_batched(rb):
    model = PoseModel(rb, K6, np.zeros(6), tool=TOOL)
    rng = np.random.default_rng(0)
    Q = PAPER_Q + rng.normal(0, 0.4, (100, 6))
    M = model.mass_matrix(Q)
    assert np.allclose(M, np.swapaxes(M, 1, 2), atol=1e-10)
    assert np.all(np.linalg.eigvalsh(M) > 0)
    M1 = np.stack([model.mass_matrix(q) for q in Q[:5]])
    assert np.allclose(M[:5], M1, rtol=1e-12, atol=1e-12)


def test_calibration_recovers_a_known_model(rb):
    """Modes of the model with known link scales and joint dampers: the calibration matches
    the frequencies (residual ~0) and the damping ratios (the weak pull towards common
    stiffness-proportional damping costs < 0.5 %); joint 6, which these modes do not move at
    this posture (tool point on its axis), keeps a damper."""
    truth = PoseModel(rb, K6, np.array([3000, 3000, 800, 150, 80, 30.0]), tool=TOOL,
                      link_scale=np.array([1.2, 0.8, 1.1, 0.9, 1.0, 1.0]))
    md = truth.modes(PAPER_Q)
    f, z = md.frequency_Hz[0, :5], md.damping_ratio[0, :5]
    cal = calibrate(PoseModel(rb, K6, np.zeros(6), tool=TOOL), PAPER_Q, f, z)
    assert np.abs(cal.frequency_error_percent).max() < 1.0
    assert np.abs(cal.frequency_error_percent).max() < np.abs(
        100 * (cal.uncalibrated_frequency_Hz / f - 1)).max()
    assert np.allclose(cal.model_damping_ratio, z, rtol=5e-3)
    assert cal.model.c_Nms_per_rad[5] > 0


def test_equivalent_model_per_direction(rb):
    model = PoseModel(rb, K6, np.array([3000, 3000, 800, 150, 80, 30.0]), tool=TOOL)
    em = model.equivalent(PAPER_Q)
    pm = model.modes(PAPER_Q)
    for i, a in enumerate("xyz"):
        u = em.unit(a)
        assert u.stiffness_N_per_m == pytest.approx(pm.directional_stiffness[0, i])
        assert u.mass_kg == pytest.approx(u.stiffness_N_per_m
                                          / (2 * math.pi * u.frequency_Hz) ** 2)
        assert u.frequency_Hz in pm.frequency_Hz[0]


def test_missing_inertial_data_names_robot():
    from robobore.errors import ConfigError

    r = Robot("bare", (0.0,), (1.0,), (0.0,), (0.0,), (-1.0,), (1.0,), file="bare.toml")
    with pytest.raises(ConfigError) as ei:
        PoseModel(r, np.array([1e5]), np.zeros(1))
    msg = str(ei.value)
    assert "bare.toml" in msg and "links" in msg and "mass_kg" in msg


# ----------------------------------------------------------------------------- IK
def test_ik_all_branches_verified_by_fk(rb):
    from robobore.plan.ik import ik_all

    rng = np.random.default_rng(1)
    lo, hi = np.array(rb.lower_limit_rad), np.array(rb.upper_limit_rad)
    q = rng.uniform(0.9 * lo, 0.9 * hi, (300, 6))
    q[:, [3, 5]] = rng.uniform(-np.pi, np.pi, (300, 2))
    T = fk(rb, q)
    Q, ok = ik_all(rb, T[:, :3, :3], T[:, :3, 3])
    found = np.nanmin(np.max(np.abs(Q - q[:, None, :]), axis=2), axis=1)
    assert np.all(found < 1e-8)  # the original posture is one of the branches
    reach = np.all(np.isfinite(Q), axis=2)
    Tb = fk(rb, Q[reach])
    assert np.abs(Tb - np.repeat(T, reach.sum(1), axis=0)).max() < 1e-10
    lims = (Q >= lo - 1e-9) & (Q <= hi + 1e-9)
    assert np.array_equal(ok, reach & np.all(lims, axis=2))


# ----------------------------------------------------------------------------- chatter
@pytest.fixture(scope="module")
def paper_process():
    from importlib import resources

    from robobore.cutting import coefficient_files
    from robobore.cutting.geometry import BoringInsert
    from robobore.dynamics.process import boring_process

    co = coefficient_files.load_coefficients(str(resources.files("robobore") / "data"
                                                 / "paper_example" / "tc4_fe_coefficients.json"))
    ins = BoringInsert(0.4e-3, 90.0, 5.0, 7.0, 0.0, 7.0, 20e-6, 1)
    return boring_process(ins, co, 0.05e-3, 0.15e-3)


def test_critical_depth_matches_stability_module(rb, paper_process):
    from robobore.dynamics.stability import lobes_frequency_domain
    from robobore.plan.chatter import critical_depth_range

    model = PoseModel(rb, K6, np.array([3000, 3000, 800, 150, 80, 30.0]), tool=TOOL)
    Q = PAPER_Q + np.random.default_rng(2).normal(0, 0.2, (4, 6))
    pm = model.modes(Q)
    # the planner's screen linearises the process once, at the cutting depth
    fixed = paper_process.fixed()
    A0 = fixed.mean_directional_matrix()
    for lo, hi in ((150.0, 1100.0), (2000.0, 20000.0)):
        b, _, n = critical_depth_range(pm.frequency_Hz, pm.damping_ratio, pm.u, A0, lo, hi)
        assert np.all((n >= lo * (1 - 1e-9)) & (n <= hi * (1 + 1e-9)))
        for i in range(Q.shape[0]):
            L = lobes_frequency_domain(pm.structure(i), fixed, np.linspace(lo, hi, 4000))
            assert b[i] == pytest.approx(L.critical_depth_m.min(), rel=5e-3)


def test_feed_amplitude_is_the_time_domain_s(rb, paper_process):
    """The planner's feed amplitude (the steady cut's half peak-to-peak Z) is what
    ``simulate`` reports on the same structure and process at 300 r/min, 0.05 mm where the
    cut is stable (it starts on that steady cut and settles back to it): within 1 % (measured
    1e-5) at the postures of three that do not chatter, and the lobes' spectral radius says
    which do."""
    from robobore.dynamics.chatter import classify
    from robobore.dynamics.semidiscretization import monodromy_spectral_radius
    from robobore.dynamics.timedomain import SimulationSettings, simulate, summarize
    from robobore.plan.scoring import steady_feed_amplitude

    model = PoseModel(rb, K6, np.array([3000, 3000, 800, 150, 80, 30.0]), tool=TOOL)
    Q = PAPER_Q + np.random.default_rng(3).normal(0, 0.2, (3, 6))
    pm = model.modes(Q)
    stable = 0
    for i in range(3):
        st = pm.structure(i, 1e-3)
        amp = steady_feed_amplitude(st, paper_process, 0.05e-3, 300.0)
        ds = simulate(st, paper_process, SimulationSettings(300.0, 0.05e-3, 60))
        v = classify(ds)
        rho = monodromy_spectral_radius(st, paper_process, 300.0, 0.05e-3)
        assert v.chatter == (rho > 1.0)
        if not v.chatter:
            stable += 1
            assert amp == pytest.approx(summarize(ds)["feed_amplitude_m"], rel=0.01)
    assert stable >= 2


def test_modal_frf_vs_direct_solve_with_joint_dampers(rb):
    """The modal FRF (classical-damping approximation of the joint dampers) against the
    direct solve J_v (K - w^2 M + i w C)^-1 J_v^T over 1-200 Hz: within 1 % of the peak."""
    from robobore.robot.kinematics import fk_jacobian

    C = np.array([3000, 3000, 800, 150, 80, 30.0])
    model = PoseModel(rb, K6, C, tool=TOOL)
    pm = model.modes(PAPER_Q)
    M = model.mass_matrix(PAPER_Q)
    _, J = fk_jacobian(rb, PAPER_Q)
    Jv = pm.R[0].T @ J[:3]
    w = 2 * np.pi * np.linspace(1.0, 200.0, 2000)
    G = pm.frf(0, w)
    Gd = np.stack([Jv @ np.linalg.solve(np.diag(K6) - wi ** 2 * M + 1j * wi * np.diag(C), Jv.T)
                   for wi in w], axis=-1)
    assert np.abs(G - Gd).max() <= 0.01 * np.abs(Gd).max()


def test_link_bending_model_consistent_and_optional():
    """Joints + link beams (VJM): the modal static limit equals the compliance, which equals
    the identification basis sum; negligible link compliance gives the joint-only model."""
    from robobore.plan import synthetic as S
    from robobore.plan.bending import LinkBending, compliance_basis, redundancy

    rb = get_robot("irb6600-175-2.55")
    q = PAPER_Q
    cb = np.array([1 / 4.5e7, 1 / 2.2e7, 1 / 1.2e7, 1 / 1.2e7])
    lb = (LinkBending(2, tuple(cb[:2]), 1e-4), LinkBending(4, tuple(cb[2:]), 1e-4))
    m = PoseModel(rb, S.TRUTH_JOINT_K, S.TRUTH_JOINT_C, tool=S.TOOL, link_bending=lb)
    # lower-arm in-plane tip rotation is axis 3's screw, forearm bending one is axis 5's
    assert m.n_dof == 12 and redundancy(rb, lb)[0].shape == (12, 14)
    pm = m.modes(q)
    w = 2 * np.pi * pm.frequency_Hz[0]
    static = np.einsum("ja,jb,j->ab", pm.u[0], pm.u[0], 1 / w ** 2)
    assert np.allclose(static, pm.compliance[0], rtol=1e-8, atol=1e-16)
    B = compliance_basis(rb, q, (0, 0, 0), (2, 4))[0]
    C6 = np.einsum("k,kab->ab", np.r_[1 / S.TRUTH_JOINT_K, cb], B)
    R = pm.R[0]
    assert np.allclose(R.T @ C6[:3, :3] @ R, pm.compliance[0], rtol=1e-9, atol=1e-16)
    assert np.all(pm.damping_ratio > 0)
    tiny = tuple(LinkBending(li, (1e-15, 1e-15)) for li in (2, 4))
    m0 = PoseModel(rb, S.TRUTH_JOINT_K, S.TRUTH_JOINT_C, tool=S.TOOL)
    m1 = PoseModel(rb, S.TRUTH_JOINT_K, S.TRUTH_JOINT_C, tool=S.TOOL, link_bending=tiny)
    p0, p1 = m0.modes(q), m1.modes(q)
    assert np.allclose(p1.frequency_Hz[0, :6], p0.frequency_Hz[0], rtol=1e-6)
    assert np.allclose(p1.compliance[0], p0.compliance[0], rtol=1e-6)
    # bending lowers the frequencies and softens the tool point
    assert np.all(pm.frequency_Hz[0, :6] < p0.frequency_Hz[0])
    assert np.all(np.diag(pm.compliance[0]) > np.diag(p0.compliance[0]))
    with pytest.raises(InputError):
        PoseModel(rb, S.TRUTH_JOINT_K, S.TRUTH_JOINT_C, link_bending=(LinkBending(2, (-1, 0)),))


def test_several_speed_ranges_in_one_pass_are_each_range_alone():
    """critical_depth_ranges (one pass over the frequency grid for several speed ranges) gives
    each range's critical_depth_range, digit for digit, a one-speed range included."""
    from robobore.plan.chatter import critical_depth_range, critical_depth_ranges

    rng = np.random.default_rng(5)
    f = rng.uniform(5, 60, (40, 6))
    z = rng.uniform(0.01, 0.06, (40, 6))
    u = rng.normal(size=(40, 6, 3)) * 1e-3
    A0 = rng.normal(size=(3, 3)) * 1e9
    ranges = [(300.0, 300.0), (150.0, 1500.0), (1000.0, 3000.0)]
    b, fch, n = critical_depth_ranges(f, z, u, A0, ranges)
    for q, (lo, hi) in enumerate(ranges):
        b1, f1, n1 = critical_depth_range(f, z, u, A0, lo, hi)
        assert np.array_equal(b[:, q], b1) and np.isfinite(b1).any()
        assert np.array_equal(fch[:, q], f1, equal_nan=True)
        assert np.array_equal(n[:, q], n1, equal_nan=True)
