"""The set-up of the semi-discretisation at a trial depth (the steady deflection and the
process at that depth): the nominal-cut orbit against the dense composition of the
time-domain map's steps, the process against the chip geometry's edge elements."""

from __future__ import annotations

import numpy as np
import pytest

from robobore.cutting.coefficient_sets import ti64_coefficients
from robobore.cutting.geometry import BoringInsert
from robobore.dynamics import semidiscretization as sd
from robobore.dynamics.process import boring_process
from robobore.dynamics.structure import ToolPointStructure
from robobore.dynamics.timedomain import nominal_cut_deflection

#: SYNTHETIC robot-like tool point: three modes of 7-25 Hz in three directions
MODES = [
    {"frequency_Hz": 6.9, "damping_ratio": 0.03, "stiffness_N_per_m": 1.2e6,
     "direction": [0.8, 0.6, 0.0]},
    {"frequency_Hz": 16.8, "damping_ratio": 0.025, "stiffness_N_per_m": 2.5e6,
     "direction": [-0.6, 0.8, 0.0]},
    {"frequency_Hz": 24.6, "damping_ratio": 0.02, "stiffness_N_per_m": 4.0e6,
     "direction": [0.0, 0.6, 0.8]},
]


@pytest.fixture(scope="module")
def structure():
    return ToolPointStructure.from_modes(MODES)


def _dense_orbit(structure, pr, speed, Ns, depths):
    """Reference: the nominal-chip orbit of the time-domain map with each step's full
    (2m, 2m) matrix from ``process_stiffness`` and the nominal force at each depth from the
    process arrays, the Ns steps composed densely; displacements (Ns, 3) per depth."""
    from robobore.dynamics.timedomain import modal_zoh

    m = structure.n_modes
    dt = 60.0 / (speed * Ns)
    Phi, Gam = modal_zoh(structure, dt)
    D = structure.directions
    theta = 2 * np.pi * (np.arange(Ns) + 0.5) / Ns
    Pm = np.einsum("jo,noi,ki->njk", D, pr.process_stiffness(theta), D)
    A0 = np.zeros((2 * m, 2 * m))
    for j in range(m):
        A0[np.ix_([j, m + j], [j, m + j])] = Phi[j]
    G = np.zeros((2 * m, m))
    G[np.arange(m), np.arange(m)] = Gam[:, 0]
    G[m + np.arange(m), np.arange(m)] = Gam[:, 1]
    S = np.hstack([np.eye(m), 0.5 * dt * np.eye(m)])  # q + half_dt q'
    out = []
    for a in depths:
        f0 = ((pr.width_per_depth * a * pr.h0) @ pr.shear
              + (pr.edge_per_depth * a + pr.edge_fixed_m) @ pr.edge)
        F = np.zeros((Ns, 3))
        for p in range(pr.n_inserts):
            F += np.einsum("nki,k->ni", pr.basis(theta + 2 * np.pi * p / pr.n_inserts), f0)
        As = [A0 + G @ Pm[i] @ S for i in range(Ns)]
        bs = [G @ (D @ F[i]) for i in range(Ns)]
        T, c = np.eye(2 * m), np.zeros(2 * m)
        for A, b in zip(As, bs, strict=True):
            T, c = A @ T, A @ c + b
        x = np.linalg.solve(np.eye(2 * m) - T, c)
        r = np.empty((Ns, 3))
        for i in range(Ns):
            r[i] = x[:m] @ D
            x = As[i] @ x + bs[i]
        out.append(r)
    return out


@pytest.mark.parametrize("n_inserts", [1, 2, 3])
@pytest.mark.parametrize("depth_m", [0.2e-3, 0.7e-3, 3.0e-3])
def test_nominal_cut_orbit_is_the_dense_map_orbit(structure, n_inserts, depth_m):
    """The compiled orbit (rank-one steps) equals the orbit of the dense step matrices, through
    the time domain's nominal_cut_deflection and periodic_orbit and the lobes' steady
    deflection."""
    from robobore.dynamics.timedomain import periodic_orbit

    ins = BoringInsert(nose_radius_m=0.4e-3, approach_angle_deg=75.0, n_inserts=n_inserts)
    pr = boring_process(ins, ti64_coefficients(), depth_m, 0.15e-3)
    Ns = int(np.ceil(sd.DEFLECTION_SAMPLES / n_inserts) * n_inserts)
    for speed in (150.0, 433.0, 1100.0):
        ref_a, ref1, ref0 = _dense_orbit(structure, pr, speed, Ns, (depth_m, 1.0, 0.0))
        ref1 = ref1 - ref0
        r1, r0 = nominal_cut_deflection(structure, pr, speed, sd.DEFLECTION_SAMPLES)
        q1, q0 = sd._deflection_parts_uncached(structure, pr, speed)
        for got, ref in ((r1, ref1), (r0, ref0), (q1, ref1), (q0, ref0)):
            assert got.shape == ref.shape
            assert np.abs(got - ref).max() <= 1e-11 * np.abs(ref).max()
        r_t = periodic_orbit(structure, pr, Ns, depth_m, speed)[3]
        assert np.abs(r_t - ref_a).max() <= 1e-11 * np.abs(ref_a).max()


def test_deflection_without_trailing_edge_has_no_fixed_part(structure):
    ins = BoringInsert(nose_radius_m=0.4e-3, approach_angle_deg=90.0)
    pr = boring_process(ins, ti64_coefficients(), 1e-3, 0.1e-3, trailing_edge=False)
    q1, q0 = sd._deflection_parts_uncached(structure, pr, 500.0)
    r1, _ = nominal_cut_deflection(structure, pr, 500.0, sd.DEFLECTION_SAMPLES)
    assert q0 is None
    assert np.abs(q1 - r1).max() <= 1e-11 * np.abs(r1).max()


def _process_from_edge_elements(ins, c, depth_m, feed_m, trailing):
    """The process arrays of :func:`boring_process` formed from
    :func:`robobore.cutting.geometry.edge_elements` with numpy (the coefficients, chip widths
    above the minimum chip thickness and trailing-side edge lengths)."""
    from robobore.cutting.geometry import edge_elements

    el = edge_elements(ins, depth_m, feed_m / ins.n_inserts, 24, trailing_edge=trailing,
                       exact_area=False)
    trail = el.trailing
    sk, ck = np.sin(el.kappa), np.cos(el.kappa)
    one = np.ones_like(sk)
    return {"h0": el.h, "width_per_depth": el.db / depth_m * (el.h >= 0.25 * ins.edge_radius_m),
            "edge_per_depth": np.where(trail, 0.0, el.dS / depth_m),
            "edge_fixed_m": np.where(trail, el.dS, 0.0),
            "normal": np.column_stack([0 * one, -ck, -sk]),
            "shear": np.column_stack([-c.Ktc * one, -c.Kfc * ck - c.Krc * sk,
                                      -c.Kfc * sk + c.Krc * ck]),
            "edge": np.column_stack([-c.Kte * one, -c.Kfe * ck - c.Kre * sk,
                                     -c.Kfe * sk + c.Kre * ck])}


@pytest.mark.parametrize("kappa_deg,end_deg", [(45.0, 5.0), (90.0, 5.0), (95.0, 30.0),
                                               (107.0, 3.0)])
@pytest.mark.parametrize("feed_m", [0.05e-3, 0.3e-3, 1.5e-3])
@pytest.mark.parametrize("trailing", [True, False])
def test_process_elements_are_the_edge_elements(kappa_deg, end_deg, feed_m, trailing):
    """Depths inside the nose and beyond it, feeds whose trailing contact ends on the arc and
    on the straight minor edge, 1 and 3 inserts: the process arrays formed from edge_elements."""
    c = ti64_coefficients()
    for n_ins in (1, 3):
        ins = BoringInsert(nose_radius_m=0.4e-3, approach_angle_deg=kappa_deg,
                           end_edge_angle_deg=end_deg, n_inserts=n_ins)
        for depth in np.geomspace(5e-6, 0.05, 13):
            ref = _process_from_edge_elements(ins, c, float(depth), feed_m, trailing)
            pr = boring_process(ins, c, float(depth), feed_m, trailing_edge=trailing)
            for name, v in ref.items():
                got = getattr(pr, name)
                assert got.shape == v.shape, name
                assert np.abs(got - v).max() <= 1e-13 * max(np.abs(v).max(), 1e-300), name


def test_process_without_minimum_chip_thickness_keeps_the_trailing_side_chipless():
    """With no minimum chip thickness every leading element carries a chip width, and the
    rubbing-only trailing elements (h = 0) still none."""
    ins = BoringInsert(nose_radius_m=0.8e-3, approach_angle_deg=75.0)
    pr = boring_process(ins, ti64_coefficients(), 1e-3, 0.2e-3, min_chip_thickness_m=0.0)
    tr = pr.edge_fixed_m > 0
    assert tr.sum() >= 1 and np.all(pr.width_per_depth[tr] == 0.0)
    assert np.all(pr.width_per_depth[~tr] == pr.edge_per_depth[~tr])
    assert np.all(pr.edge_per_depth[tr] == 0.0)


def test_process_at_depth_keeps_the_geometry_and_label():
    ins = BoringInsert(nose_radius_m=0.8e-3, approach_angle_deg=75.0, n_inserts=2)
    pr = boring_process(ins, ti64_coefficients(), 1e-3, 0.2e-3)
    at = pr.at_depth(0.4e-3)
    assert at.geometry == pr.geometry and at.label == pr.label
    assert at.reference_depth_m == 0.4e-3
    ref = boring_process(ins, ti64_coefficients(), 0.4e-3, 0.2e-3)
    assert np.array_equal(at.h0, ref.h0) and np.array_equal(at.edge, ref.edge)


@pytest.mark.parametrize("bad", [{"depth_m": 0.0}, {"depth_m": 0.06}, {"feed_per_rev_m": 0.0},
                                 {"n_elements": 0}])
def test_process_bad_input_is_named(bad):
    from robobore.errors import ConfigError

    args = {"depth_m": 1e-3, "feed_per_rev_m": 0.1e-3, "n_elements": 24, **bad}
    with pytest.raises(ConfigError) as e:
        boring_process(BoringInsert(), ti64_coefficients(), **args)
    assert ("depth" in str(e.value)) or ("feed" in str(e.value)) or ("element" in str(e.value))


@pytest.mark.parametrize("scale", [1e-2, 1.0, 300.0])
def test_modal_step_matrices_equal_the_augmented_exponential(scale):
    """The step matrices formed on the blocks of the modal system matrix (the last m columns
    of both Gammas) equal scipy's exponential of the augmented matrix, from a small
    regenerative term to one that needs doublings."""
    rng = np.random.default_rng(5)
    m, k = 3, 16
    om = 2 * np.pi * np.array([6.9, 16.8, 24.6])
    L = np.zeros((k, 2 * m, 2 * m))
    for q in range(k):
        L[q, :m, m:] = np.eye(m)
        L[q, m:, :m] = -np.diag(om**2) + 0.1 * scale * np.outer(om, om) * rng.standard_normal(
            (m, m))
        L[q, m:, m:] = np.diag(-2 * 0.03 * om)
    dt = 0.4 / k
    Phi, G0, G1 = np.empty_like(L), np.empty((k, 2 * m, m)), np.empty((k, 2 * m, m))
    sd._step_matrices_modal(L, dt, Phi, G0, G1)
    R = sd._step_matrices(L, dt)
    for got, ref in ((Phi, R[0]), (G0, R[1][:, :, m:]), (G1, R[2][:, :, m:])):
        assert np.abs(got - ref).max() <= 1e-12 * np.abs(ref).max()


def test_process_matrices_follow_a_replaced_copy():
    """A copy by dataclasses.replace shares the memo but not the arrays: its per-unit-depth
    matrices are its own."""
    from dataclasses import replace

    pr = boring_process(BoringInsert(), ti64_coefficients(), 1e-3, 0.1e-3)
    core, vec, _ = sd._process_matrices(pr)
    pr2 = replace(pr, shear=2.0 * pr.shear)
    core2, vec2, _ = sd._process_matrices(pr2)
    assert np.allclose(core2, 2.0 * core, rtol=1e-14, atol=0.0)
    assert not np.allclose(vec2, vec)
    assert sd._process_matrices(pr)[0] is not core2
