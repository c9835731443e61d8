"""3D hexahedral engine: element kinematics, constitutive response, waves, energy, stability.

References: Flanagan & Belytschko (1981) IJNME 17:679 (mean-gradient hexahedron, patch test);
Johnson & Cook (1983) (flow stress); Belytschko, Liu & Moran (2000) ch. 6 (explicit step,
energy balance); Graff (1975) *Wave motion in elastic solids* (dilatational wave speed
c = sqrt((K + 4G/3)/rho) under lateral confinement).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from robobore.cutting.fe.ale.groups3d import groups3_of
from robobore.cutting.fe.engine import kernels3d as K3
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.engine.groups2d import groups_of
from robobore.cutting.fe.engine.state3d import (
    advance3,
    box_mesh,
    default_prm3,
    hex_volumes,
    make_state3,
)
from robobore.cutting.fe.hex import layout3d, scalar3d
from robobore.errors import NumericalError
from robobore.material import Material, load_material
from robobore.material import johnson_cook as jc


def elastic_tc4() -> Material:
    d = load_material("TC4").to_dict()
    d.update(A=1e15, B=0.0)
    return Material.from_dict(d)


def _distorted_cube(rng):
    nodes, conn, _ = box_mesh(1, 1, 1, 1e-3, 1e-3, 1e-3)
    return nodes + rng.uniform(-1.5e-4, 1.5e-4, nodes.shape), conn


def _one_update(st, dt=1e-30):
    nodes, cells, elems, out, _ = groups3_of(st)
    K3.element_update3(nodes, cells, st.layer, elems, out, st.mat, st.prm, dt,
                       layout3d.ERODE_NONE)


def test_volume_derivative_matches_numerical():
    """f = -p dV/dx_I under a pure pressure p: FB eq. (79) terms vs a central difference of
    the exact (2x2x2 Gauss) volume of a distorted hexahedron; tolerance 1e-7 relative."""
    rng = np.random.default_rng(3)
    nodes, conn = _distorted_cube(rng)
    st = make_state3(nodes, conn, np.zeros(8, np.int64), elastic_tc4())
    p = 1e8
    st.pres[:] = p
    _one_update(st)
    f = st.fe[0].reshape(8, 3)
    h = 1e-9
    num = np.zeros((8, 3))
    for i in range(8):
        g = conn[0, i]  # corner i of the element is global node g
        for k in range(3):
            a = nodes.copy()
            b = nodes.copy()
            a[g, k] += h
            b[g, k] -= h
            num[i, k] = (hex_volumes(a, conn)[0] - hex_volumes(b, conn)[0]) / (2 * h)
    np.testing.assert_allclose(f, -p * num, rtol=1e-7, atol=1e-7 * p * np.abs(num).max())


def test_patch_test_constant_strain_on_distorted_mesh():
    """Linear velocity field on a 2x2x2 mesh with a displaced interior node: every element
    gets the same strain rate and stress (to round-off), hourglass modes stay at zero and the
    interior node is in equilibrium (FB 1981, sec. 4)."""
    nodes, conn, idx = box_mesh(2, 2, 2, 2e-3, 2e-3, 2e-3)
    centre = idx[1, 1, 1]
    nodes[centre] += np.array([2e-4, -1.5e-4, 1e-4])
    st = make_state3(nodes, conn, np.zeros(len(nodes), np.int64), elastic_tc4())
    A = np.array([[1.0, 0.4, -0.2], [0.1, -0.5, 0.3], [0.2, -0.1, 0.7]])  # 1/s
    v = nodes @ A.T
    st.vx[:], st.vy[:], st.vz[:] = v[:, 0], v[:, 1], v[:, 2]
    _one_update(st, dt=1e-7)
    np.testing.assert_allclose(st.sd, np.broadcast_to(st.sd[0], st.sd.shape), rtol=1e-9,
                               atol=1e-9 * np.abs(st.sd).max())
    np.testing.assert_allclose(st.pres, st.pres[0], rtol=1e-9)
    assert np.abs(st.qh).max() < 1e-9 * np.abs(st.sd).max() * 1e-6
    # expected deviatoric stress 2 G dev(D) dt
    D = 0.5 * (A + A.T)
    G = st.mat[jc.E_MOD] / (2 * (1 + st.mat[jc.NU]))
    dev = D - np.trace(D) / 3 * np.eye(3)
    np.testing.assert_allclose(st.sd[0, 0], 2 * G * dev[0, 0] * 1e-7, rtol=1e-6)
    np.testing.assert_allclose(st.sd[0, 3], 2 * G * dev[0, 1] * 1e-7, rtol=1e-6)
    # interior node: gathered force vanishes
    fsum = np.zeros(3)
    for e in range(st.n_elements):
        for c in range(8):
            if conn[e, c] == centre:
                fsum += st.fe[e, 3 * c:3 * c + 3]
    assert np.linalg.norm(fsum) < 1e-9 * np.abs(st.fe).max()


def _tension_state(rate, mat):
    L = 1e-3
    nodes, conn, _ = box_mesh(1, 1, 1, L, L, L)
    fixed = np.zeros(8, np.int64)
    fixed[nodes[:, 0] == 0] |= scalar3d.FIX_X
    fixed[nodes[:, 1] == 0] |= scalar3d.FIX_Y
    fixed[nodes[:, 2] == 0] |= scalar3d.FIX_Z
    fixed[nodes[:, 0] == L] |= scalar3d.FIX_X
    st = make_state3(nodes, conn, fixed, mat)
    st.vx[:] = rate * nodes[:, 0]
    return st, nodes, L


def test_uniaxial_tension_follows_johnson_cook():
    """Single hexahedron in uniaxial tension at 1000/s: sigma_xx equals the JC flow stress
    at the element's plastic strain, strain rate and (adiabatic) temperature, lateral stress
    is zero, and eps_p = ln(L/L0) - sigma/E. Tolerance 1 % (inertia of the lateral nodes)."""
    mat = load_material("TC4")
    rate = 1000.0
    st, nodes, L = _tension_state(rate, mat)
    a = st.mat
    for target in (0.05, 0.12, 0.2):
        advance3(st, target / rate)
        lx = st.x[nodes[:, 0] == L].mean()
        sxx = st.sd[0, 0] - st.pres[0]
        syy = st.sd[0, 1] - st.pres[0]
        eps_closed = math.log(lx / L) - sxx / mat.E
        assert st.eps_p[0] == pytest.approx(eps_closed, rel=0.01)
        sy = jc.jc_flow_stress(eps_closed, st.rate[0], st.temp[0], a[jc.A], a[jc.B], a[jc.N],
                               a[jc.C], a[jc.M], a[jc.EPS0], a[jc.TROOM], a[jc.TMELT],
                               a[jc.EPS_HMAX])
        assert sxx == pytest.approx(sy, rel=0.01)
        assert abs(syy) < 0.01 * sxx
    # adiabatic heating: dT = beta * W_p / (rho cp)
    wp = st.plast[0] / st.vol0[0]
    assert st.temp[0] - mat.T_room == pytest.approx(
        mat.taylor_quinney * wp / (mat.rho * mat.cp), rel=0.02)


def test_simple_shear_follows_johnson_cook():
    """Single hexahedron in simple shear (top face moved along x at 500/s shear rate): the
    von Mises stress sqrt(3) tau equals the JC flow stress at eps_p = (gamma - tau/G)/sqrt(3)
    for small rotation (gamma <= 0.1). Tolerance 2 %."""
    mat = load_material("TC4")
    L = 1e-3
    nodes, conn, _ = box_mesh(1, 1, 1, L, L, L)
    gdot = 500.0
    fixed = np.full(8, 7, np.int64)
    st = make_state3(nodes, conn, fixed, mat)
    st.vx[:] = gdot * nodes[:, 1]
    gamma = 0.1
    advance3(st, gamma / gdot)
    tau = st.sd[0, 3]
    G = mat.E / (2 * (1 + mat.nu))
    eps_closed = (gamma - tau / G) / math.sqrt(3.0)
    assert st.eps_p[0] == pytest.approx(eps_closed, rel=0.02)
    a = st.mat
    sy = jc.jc_flow_stress(eps_closed, st.rate[0], st.temp[0], a[jc.A], a[jc.B], a[jc.N],
                           a[jc.C], a[jc.M], a[jc.EPS0], a[jc.TROOM], a[jc.TMELT],
                           a[jc.EPS_HMAX])
    assert math.sqrt(3.0) * tau == pytest.approx(sy, rel=0.02)


def _confined_bar(n=60, L=6e-3):
    h = L / n
    nodes, conn, _ = box_mesh(n, 1, 1, L, h, h)
    fixed = np.full(len(nodes), scalar3d.FIX_Y | scalar3d.FIX_Z, np.int64)
    return nodes, conn, fixed, L


def test_dilatational_wave_speed_in_confined_bar():
    """A velocity step at x = 0 of a laterally confined elastic bar: the front (v = v0/2)
    reaches x = L/2 at t = (L/2)/c_d, c_d = sqrt((K + 4G/3)/rho). Tolerance 3 %."""
    mat = elastic_tc4()
    nodes, conn, fixed, L = _confined_bar()
    fixed[nodes[:, 0] == 0] |= scalar3d.FIX_X
    st = make_state3(nodes, conn, fixed, mat)
    v0 = 0.1
    st.vx[nodes[:, 0] == 0] = v0
    K_ = mat.E / (3 * (1 - 2 * mat.nu))
    G = mat.E / (2 * (1 + mat.nu))
    cd = math.sqrt((K_ + 4 * G / 3) / mat.rho)
    probe = np.where(np.isclose(nodes[:, 0], L / 2))[0]
    t_arr = None
    t_prev, v_prev = 0.0, 0.0
    while st.time < 0.9 * L / cd:
        advance3(st, st.time + 2 * st.clock[1], chunk_steps=1)
        vm = float(st.vx[probe].mean())
        if vm >= 0.5 * v0:
            t_arr = t_prev + (0.5 * v0 - v_prev) / (vm - v_prev) * (st.time - t_prev)
            break
        t_prev, v_prev = st.time, vm
    assert t_arr is not None
    assert (L / 2) / t_arr == pytest.approx(cd, rel=0.03)


def test_elastic_energy_conservation():
    """Free vibration of an elastic bar (initial cosine velocity, no supports): kinetic +
    internal (+ hourglass) energy stays at the initial kinetic energy within 1 %."""
    mat = elastic_tc4()
    nodes, conn, _, L = _confined_bar(n=20, L=4e-3)
    st = make_state3(nodes, conn, np.zeros(len(nodes), np.int64), mat)
    st.vx[:] = 0.2 * np.cos(math.pi * nodes[:, 0] / L)  # first free-free mode, no rigid part
    e0 = 0.5 * np.sum(st.mass * st.vx**2)
    period = 2 * L / math.sqrt(mat.E / mat.rho)  # free-free bar, first mode (order of)
    ie_max = 0.0
    for frac in (0.25, 0.5, 0.75, 1.0):
        advance3(st, frac * period)
        tot = st.en[layout.E_KIN] + st.en[layout.E_INT] + st.en[layout.E_HG]
        assert tot == pytest.approx(e0, rel=0.01)
        ie_max = max(ie_max, st.en[layout.E_INT])
    assert ie_max > 0.3 * e0  # the energy really went through the elements


def test_unstable_run_stops_with_clear_message():
    """A time step 5x the stable one blows up: NumericalError naming the step and cause."""
    mat = elastic_tc4()
    nodes, conn, _, L = _confined_bar(n=10, L=2e-3)
    st = make_state3(nodes, conn, np.zeros(len(nodes), np.int64), mat)
    st.vx[:] = 0.2 * np.sin(math.pi * nodes[:, 0] / L)
    st.prm[layout3d.P_CFL] = 5.0
    st.clock[1] *= 5.0 / 0.8
    with pytest.raises(NumericalError, match="unstable at step"):
        advance3(st, 1.0, chunk_steps=200)


def test_bad_mesh_rejected():
    from robobore.errors import ConfigError

    nodes, conn, _ = box_mesh(1, 1, 1, 1e-3, 1e-3, 1e-3)
    with pytest.raises(ConfigError, match="non-positive volume"):
        make_state3(nodes, conn[:, [1, 0, 3, 2, 5, 4, 7, 6]], np.zeros(8, np.int64),
                    elastic_tc4())
    with pytest.raises(ConfigError, match="mesh must be"):
        make_state3(nodes[:, :2], conn, np.zeros(8, np.int64), elastic_tc4())
    assert default_prm3().shape == (layout3d.N_PRM,)


@pytest.mark.parametrize("hgs, hgv", [(0.05, 0.0), (0.0, 0.05)])
def test_hourglass_resistance_matches_2d_quad_in_plane_strain(hgs, hgv):
    """A cube driven in the in-plane hourglass mode (x velocity ~ xi*eta, uniform along z) gets,
    per unit thickness, the same nodal hourglass forces as the 2D engine's square quad with the
    same coefficients (stiffness part after one step, viscous part): one [solver] setting
    means the same in both engines. Tolerance 1e-9 relative (same formulas, rounding only).
    Before the scaling was aligned the cube resisted 3x (stiffness) and 2x (viscous) more, and
    a plane-strain slab cut by the 3D engine gave 1.5x the 2D cutting force."""
    from robobore.cutting.fe.engine import layout
    from robobore.cutting.fe.engine.state2d import default_prm, make_state
    from robobore.cutting.fe.quad import element as q_element

    a = 10e-6
    v0 = 0.1
    dt = 1e-9
    mat = elastic_tc4()
    nodes, conn, _ = box_mesh(1, 1, 1, a, a, a)
    p3 = default_prm3()
    p3[layout3d.P_HGS], p3[layout3d.P_HGV] = hgs, hgv
    p3[layout3d.P_BV1], p3[layout3d.P_BV2] = 0.0, 0.0
    st = make_state3(nodes, conn, np.zeros(8, np.int64), mat, prm=p3)
    xi = np.sign(st.x - 0.5 * a)
    eta = np.sign(st.y - 0.5 * a)
    st.vx[:] = v0 * xi * eta
    _one_update(st, dt)
    f3 = np.zeros(8)
    for k in range(8):
        f3[conn[0, k]] = st.fe[0, 3 * k]
    nodes2 = np.array([[0, 0], [a, 0], [a, a], [0, a]], float)
    p2 = default_prm()
    p2[layout.P_HGS], p2[layout.P_HGV], p2[layout.P_BV1], p2[layout.P_BV2] = hgs, hgv, 0.0, 0.0
    s2 = make_state(nodes2, np.array([[0, 1, 2, 3]]), np.zeros(4, bool), mat, prm=p2)
    s2.vx[:] = v0 * np.sign(s2.x - 0.5 * a) * np.sign(s2.y - 0.5 * a)
    q_element.element_update(*groups_of(s2)[:4], s2.mat, s2.prm, dt, layout.ERODE_NONE)
    for k in range(4):
        # the cube's two nodes above the quad's node k (z = 0 and z = a), per unit thickness
        sel = (np.abs(st.x - nodes2[k, 0]) < 1e-12) & (np.abs(st.y - nodes2[k, 1]) < 1e-12)
        f_cube = f3[sel].sum() / a
        f_quad = s2.fex[0, k]
        assert f_quad != 0.0
        assert f_cube == pytest.approx(f_quad, rel=1e-9)
