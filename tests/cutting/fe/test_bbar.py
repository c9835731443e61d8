"""The fully integrated B-bar quad (``solver.element = "q4_bbar"``).

References: Hughes T.J.R. (1980), "Generalization of selective integration procedures to
anisotropic and nonlinear media", IJNME 15, 1413-1418 (B-bar); Nagtegaal, Parks & Rice (1974)
(one volumetric constraint per element: no locking in isochoric flow); Belytschko, Liu, Moran
(2000), sec. 8.5 (mean-dilatation quad; its stiffness sum_k detJ_k Bbar_k^T D Bbar_k with
2x2 Gauss points has only the three rigid-body modes as zero-energy modes).

The kernel's small-displacement stiffness is probed column by column (one node velocity over
one tiny step from a stress-free state) and compared with an independent numpy assembly of
the B-bar stiffness; tolerance 1e-6 relative (the probe's geometric update is 1e-9 of the
element size).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import elastic_tc4, strip_mesh

from robobore.cutting.fe.config.orthogonal import parse_config
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.engine.chunk_driver import advance
from robobore.cutting.fe.engine.chunk_loop import Phases
from robobore.cutting.fe.engine.groups2d import groups_of
from robobore.cutting.fe.engine.state2d import default_prm, make_state
from robobore.cutting.fe.quad import bbar
from robobore.cutting.fe.quad import element as q_element
from robobore.errors import ConfigError
from robobore.material import Material, load_material

TC4 = load_material("TC4")
#: the compiled loop and state of the B-bar element
BBAR = Phases(element="bbar")
# a distorted convex quad (counter-clockwise) [m]
QUAD = np.array([[0.0, 0.0], [11e-6, 1e-6], [12e-6, 9e-6], [-1e-6, 10e-6]])


def _bbar_prm():
    prm = default_prm()
    prm[layout.P_BV1] = 0.0
    prm[layout.P_BV2] = 0.0
    return prm


def _kernel_stiffness(mat: Material, nodes=QUAD) -> np.ndarray:
    """8x8 stiffness of the B-bar kernel: f_int = K u for u = v dt, one column per dof."""
    conn = np.array([[0, 1, 2, 3]])
    dt = 1e-12
    v = 1e3 * 1e-6  # u = 1e-15 m = 1e-10 of the element
    Kmat = np.zeros((8, 8))
    for j in range(8):
        st = make_state(nodes, conn, np.zeros(4, bool), mat, prm=_bbar_prm(), phases=BBAR)
        st.vx[:] = 0.0
        st.vy[:] = 0.0
        (st.vx if j % 2 == 0 else st.vy)[j // 2] = v
        st.x += dt * st.vx
        st.y += dt * st.vy
        bbar.element_update_bbar(*groups_of(st)[:4], st.gps, st.mat, st.prm, dt, layout.ERODE_NONE)
        f = np.column_stack([st.fex[0], st.fey[0]]).ravel()
        Kmat[:, j] = f / (v * dt)
    return Kmat


def _reference_stiffness(E: float, nu: float, nodes=QUAD) -> np.ndarray:
    """Independent numpy B-bar stiffness (strain order xx, yy, zz, gamma_xy)."""
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    G = E / (2 * (1 + nu))
    D = np.zeros((4, 4))
    D[:3, :3] = lam
    D[:3, :3] += 2 * G * np.eye(3)
    D[3, 3] = G
    xi_n = np.array([-1, 1, 1, -1.0])
    eta_n = np.array([-1, -1, 1, 1.0])
    g = 1 / math.sqrt(3)
    gauss = [(-g, -g), (g, -g), (g, g), (-g, g)]
    grads, dets = [], []
    for xi, eta in gauss:
        dN = np.array([0.25 * xi_n * (1 + eta_n * eta), 0.25 * eta_n * (1 + xi_n * xi)])
        J = dN @ nodes
        grads.append(np.linalg.solve(J, dN))  # (2, 4): dN/dx, dN/dy
        dets.append(np.linalg.det(J))
    area = sum(dets)
    mean = sum(d * gr for d, gr in zip(dets, grads, strict=True)) / area
    m = np.array([1.0, 1.0, 1.0, 0.0])
    Kref = np.zeros((8, 8))
    for d, gr in zip(dets, grads, strict=True):
        B = np.zeros((4, 8))
        B[0, 0::2] = gr[0]
        B[1, 1::2] = gr[1]
        B[3, 0::2] = gr[1]
        B[3, 1::2] = gr[0]
        div = np.zeros(8)
        div[0::2] = gr[0]
        div[1::2] = gr[1]
        dbar = np.zeros(8)
        dbar[0::2] = mean[0]
        dbar[1::2] = mean[1]
        Bbar = B + np.outer(m, dbar - div) / 3.0
        Kref += d * Bbar.T @ D @ Bbar
    return Kref


def _mat(E: float, nu: float) -> Material:
    d = elastic_tc4().to_dict()
    d.update(E=E, nu=nu)
    return Material.from_dict(d)


def test_kernel_stiffness_equals_bbar_assembly():
    mat = elastic_tc4()
    Kk = _kernel_stiffness(mat)
    Kr = _reference_stiffness(mat.E, mat.nu)
    np.testing.assert_allclose(Kk, Kr, rtol=1e-6, atol=1e-6 * np.abs(Kr).max())


def test_only_rigid_body_modes_have_zero_energy():
    """No hourglass mode: exactly 3 zero eigenvalues (2 translations, 1 rotation). The
    one-point element without hourglass control has 5 (mutation check of the test)."""
    mat = elastic_tc4()
    ev = np.linalg.eigvalsh(0.5 * (_kernel_stiffness(mat) + _kernel_stiffness(mat).T))
    assert np.sum(np.abs(ev) < 1e-6 * ev.max()) == 3
    # the same probe on the one-point element (hourglass off) finds the two hourglass modes
    conn = np.array([[0, 1, 2, 3]])
    cols = []
    for j in range(8):
        prm = default_prm()
        prm[layout.P_HGS] = prm[layout.P_HGV] = prm[layout.P_BV1] = prm[layout.P_BV2] = 0.0
        st = make_state(QUAD, conn, np.zeros(4, bool), mat, prm=prm)
        (st.vx if j % 2 == 0 else st.vy)[j // 2] = 1e-3
        st.x += 1e-12 * st.vx
        st.y += 1e-12 * st.vy
        q_element.element_update(*groups_of(st)[:4], st.mat, st.prm, 1e-12, layout.ERODE_NONE)
        cols.append(np.column_stack([st.fex[0], st.fey[0]]).ravel() / 1e-15)
    K1 = np.array(cols).T
    ev1 = np.linalg.eigvalsh(0.5 * (K1 + K1.T))
    assert np.sum(np.abs(ev1) < 1e-6 * ev1.max()) == 5


def test_one_volumetric_constraint_per_element():
    """Mean dilatation: raising the bulk modulus at a fixed shear modulus changes the
    stiffness by a rank-1 matrix (one constraint per element: no volumetric locking)."""
    G = elastic_tc4().G
    nu1, nu2 = 0.3, 0.4999
    K1 = _kernel_stiffness(_mat(2 * G * (1 + nu1), nu1))
    K2 = _kernel_stiffness(_mat(2 * G * (1 + nu2), nu2))
    s = np.linalg.svd(K2 - K1, compute_uv=False)
    assert s[1] < 1e-6 * s[0]


@pytest.mark.parametrize("kind", ["shear", "extension"])
def test_homogeneous_flow_follows_the_flow_curve(kind):
    """Homogeneous simple shear / isochoric plane-strain extension of one element: every
    Gauss point follows sigma_JC(eps_p, rate, T) (rtol 1e-6, as the one-point element) and
    the pressure stays ~0 in the isochoric case."""
    g = 2.0e4
    size, dt, n = 10e-6, 2e-9, 4000
    nodes = np.array([[0, 0], [size, 0], [size, size], [0, size]], float)
    conn = np.array([[0, 1, 2, 3]])
    st = make_state(nodes, conn, np.zeros(4, bool), TC4, prm=_bbar_prm(), phases=BBAR)
    out = []
    for _ in range(n):
        if kind == "shear":
            vx, vy = g * st.y, 0.0 * st.y
        else:
            vx, vy = -0.5 * g * st.x, 0.5 * g * st.y
        st.vx[:] = vx
        st.vy[:] = vy
        t0 = st.temp[0]
        st.x += dt * vx
        st.y += dt * vy
        bbar.element_update_bbar(*groups_of(st)[:4], st.gps, st.mat, st.prm, dt, layout.ERODE_NONE)
        s = st.gps[0]
        q = np.sqrt(1.5 * (s[:, 0] ** 2 + s[:, 1] ** 2 + s[:, 2] ** 2 + 2 * s[:, 3] ** 2))
        out.append((q.min(), q.max(), st.eps_p[0], st.rate[0], t0, st.pres[0]))
    h = np.array(out)
    plastic = h[:, 2] > 0.02
    assert plastic.sum() > 500
    flow = np.array([TC4.flow_stress(a, r, t) for a, r, t in h[plastic][:, 2:5]])
    np.testing.assert_allclose(h[plastic, 0], flow, rtol=1e-6)
    np.testing.assert_allclose(h[plastic, 1], flow, rtol=1e-6)
    if kind == "extension":
        assert np.max(np.abs(h[:, 5])) < 1e-3 * np.max(h[:, 1])
    # Taylor-Quinney heating from the Gauss-point plastic work
    assert st.temp[0] - 293.0 == pytest.approx(
        0.9 * st.plast[0] / st.area0[0] / (TC4.rho * TC4.cp), rel=0.02)


def test_elastic_bar_period_and_energy_bbar():
    """As test_element.test_elastic_bar_period_and_energy, with the B-bar element and no
    hourglass control at all: period 4 L / c to 2 %, energy conserved to 0.5 %."""
    nx, length, thick, v0 = 200, 2e-3, 1e-5, 0.5
    nodes, conn = strip_mesh(nx, 1, length, thick)
    fixed = nodes[:, 0] < 1e-15
    prm = _bbar_prm()
    prm[layout.P_HGV] = prm[layout.P_HGS] = 0.0
    prm[layout.P_SAMPLE_DT] = 2e-8
    mat = elastic_tc4()
    st = make_state(nodes, conn, fixed, mat, prm=prm, n_samples=20000, phases=BBAR)
    st.vx[:] = v0 * np.sin(0.5 * math.pi * st.x / length)
    st.vx[fixed] = 0.0
    tip = np.argmax(st.x + st.y)
    c = math.sqrt(mat.E / (1 - mat.nu**2) / mat.rho)
    T = 4 * length / c
    ke0 = 0.5 * np.sum(st.mass * st.vx**2)
    xs, ts = [], []
    for k in range(60):
        advance(st, (k + 1) * 1.5 * T / 60, chunk_steps=10**7)
        xs.append(st.x[tip] - st.x0[tip])
        ts.append(st.time)
    h = st.hist[np.isfinite(st.hist[:, layout.H_T])]
    energies = h[:, layout.H_EKIN] + h[:, layout.H_EINT] + h[:, layout.H_EHG]
    assert np.max(np.abs(energies - ke0)) / ke0 < 5e-3
    assert np.all(h[:, layout.H_EHG] == 0.0)
    xs, ts = np.array(xs), np.array(ts)
    i = np.argmax(xs < 0)
    t_zero = ts[i - 1] + (ts[i] - ts[i - 1]) * xs[i - 1] / (xs[i - 1] - xs[i])
    assert t_zero == pytest.approx(T / 2, rel=0.02)


def test_bbar_config():
    base = {"tool": {"rake_deg": 15.0, "clearance_deg": 2.0, "edge_radius_um": 20.0},
            "cut": {"uncut_chip_thickness_um": 60.0, "cutting_speed_m_per_min": 30.0,
                    "length_mm": 1.0, "width_mm": 1.0},
            "mesh": {"element_size_um": 10.0, "frame": "workpiece"},
            "solver": {"element": "q4_bbar"}}
    assert parse_config(base).solver.element == "q4_bbar"
    base["solver"] = {"element": "q8"}
    with pytest.raises(ConfigError, match="solver.element"):
        parse_config(base)
