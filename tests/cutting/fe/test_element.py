"""Element kernel: one-element flow curves, elastic bar wave speed and energy conservation.

References: Belytschko, Liu, Moran (2000), *Nonlinear Finite Elements*, sec. 6.3 (explicit
central difference: a lumped-mass elastic model conserves energy to O(dt^2)); bar wave speed
c = sqrt(E' / rho) for a thin plane-strain strip, E' = E / (1 - nu^2) (Graff, *Wave Motion in
Elastic Solids*, 1975, sec. 8.1, long-wave limit), fundamental period of a fixed-free bar
T = 4 L / c.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import elastic_tc4, strip_mesh

from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.engine.chunk_driver import advance
from robobore.cutting.fe.engine.chunk_loop import Phases
from robobore.cutting.fe.engine.groups2d import groups_of
from robobore.cutting.fe.engine.state2d import default_prm, make_state
from robobore.cutting.fe.quad import element as q_element
from robobore.errors import NumericalError
from robobore.material import load_material

TC4 = load_material("TC4")


def _drive_one_element(velocity, total_strain_measure, n_steps=4000, dt=2e-9, size=10e-6,
                       mat=TC4):
    """Prescribe a homogeneous velocity field v(x) on one square element; returns history."""
    nodes = np.array([[0, 0], [size, 0], [size, size], [0, size]], float)
    conn = np.array([[0, 1, 2, 3]])
    prm = default_prm()
    prm[layout.P_HGS] = 0.0
    prm[layout.P_HGV] = 0.0
    prm[layout.P_BV1] = 0.0
    prm[layout.P_BV2] = 0.0
    st = make_state(nodes, conn, np.zeros(4, bool), mat, prm=prm)
    out = []
    for _ in range(n_steps):
        vx, vy = velocity(st.x, st.y)
        st.vx[:] = vx
        st.vy[:] = vy
        st.x += dt * vx
        st.y += dt * vy
        q_element.element_update(*groups_of(st)[:4], st.mat, st.prm, dt, layout.ERODE_NONE)
        q = math.sqrt(1.5 * (st.sdx[0] ** 2 + st.sdy[0] ** 2 + st.sdz[0] ** 2
                             + 2 * st.sdxy[0] ** 2))
        out.append((total_strain_measure(st), q, st.eps_p[0], st.rate[0], st.temp[0],
                    st.sdxy[0], st.pres[0]))
    return np.array(out), st


def test_simple_shear_follows_flow_curve():
    """Simple shear v_x = g y: von Mises stress equals sigma_JC(eps_p, rate, T) once yielded;
    eps_p -> gamma/sqrt(3) minus the elastic part; adiabatic heating = 0.9 W_p / (rho cp)."""
    g = 2.0e4  # 1/s
    h, st = _drive_one_element(lambda x, y: (g * y, 0.0 * y), lambda s: 0.0, n_steps=5000)
    gamma = g * 2e-9 * np.arange(1, 5001)
    q, ep, rate, T = h[:, 1], h[:, 2], h[:, 3], h[:, 4]
    plastic = ep > 0.05
    assert plastic.sum() > 1000
    # the return uses the temperature at the start of the increment (explicit coupling)
    t_start = np.r_[293.0, T[:-1]]
    flow = np.array([TC4.flow_stress(e, r, t) for e, r, t in zip(ep, rate, t_start,
                                                                 strict=True)])
    np.testing.assert_allclose(q[plastic], flow[plastic], rtol=1e-6)
    # total equivalent strain gamma/sqrt(3) = eps_p + elastic part q/(3G) (small-strain split)
    np.testing.assert_allclose(ep[plastic] + q[plastic] / (3 * TC4.G),
                               gamma[plastic] / math.sqrt(3), rtol=0.02)
    # equivalent plastic rate = g / sqrt(3)
    assert np.median(rate[plastic]) == pytest.approx(g / math.sqrt(3), rel=0.01)
    # Taylor-Quinney heating: dT = 0.9 * plastic work / (rho cp)
    wp = st.plast[0] / st.area0[0]
    assert T[-1] - 293.0 == pytest.approx(0.9 * wp / (TC4.rho * TC4.cp), rel=0.02)


def test_simple_shear_with_a_hardening_strain_limit_follows_the_held_flow_curve():
    """material.hardening_strain_limit = 0.05: the element follows the flow curve whose
    hardening term stops at eps_p = 0.05 (closed form: sigma_JC(min(eps_p, 0.05), rate, T)),
    and beyond it the stress no longer grows with strain, only falls with the temperature."""
    lim = load_material("TC4", hardening_strain_limit=0.05)
    g = 2.0e4  # 1/s
    h, _ = _drive_one_element(lambda x, y: (g * y, 0.0 * y), lambda s: 0.0, n_steps=5000,
                              mat=lim)
    q, ep, rate, T = h[:, 1], h[:, 2], h[:, 3], h[:, 4]
    t_start = np.r_[293.0, T[:-1]]
    plastic = ep > 0.01
    beyond = ep > 0.06
    assert beyond.sum() > 1000
    held = np.array([TC4.flow_stress(min(e, 0.05), r, t)
                     for e, r, t in zip(ep, rate, t_start, strict=True)])
    np.testing.assert_allclose(q[plastic], held[plastic], rtol=1e-6)
    # the plain law would be harder there by B (eps^n - 0.05^n) times the other factors
    plain = np.array([TC4.flow_stress(e, r, t) for e, r, t in zip(ep, rate, t_start,
                                                                    strict=True)])
    assert np.all(plain[beyond] > q[beyond])
    assert plain[-1] > 1.04 * q[-1]  # at eps_p ~0.115: 653 MPa (0.115^0.45 - 0.05^0.45) ~ 6 %
    # beyond the limit the stress decreases as the element heats (no hardening left)
    assert np.all(np.diff(q[beyond]) <= 1e-6 * q[beyond][1:])


def test_plane_strain_extension_follows_flow_curve():
    """Isochoric plane-strain extension v = (-e x, e y): eps_p rate = 2 e / sqrt(3)."""
    e = 1.0e4
    h, st = _drive_one_element(lambda x, y: (-e * x, e * y), lambda s: 0.0, n_steps=4000)
    q, ep, rate, T = h[:, 1], h[:, 2], h[:, 3], h[:, 4]
    plastic = ep > 0.02
    assert plastic.sum() > 500
    t_start = np.r_[293.0, T[:-1]]
    flow = np.array([TC4.flow_stress(a, r, t) for a, r, t in zip(ep, rate, t_start,
                                                                 strict=True)])
    np.testing.assert_allclose(q[plastic], flow[plastic], rtol=1e-6)
    assert np.median(rate[plastic]) == pytest.approx(2 * e / math.sqrt(3), rel=0.01)
    # isochoric: pressure stays ~0 (no volumetric strain, no locking)
    assert np.max(np.abs(h[:, 6])) < 1e-3 * np.max(q)


def _bar(nx=200, ny=1, length=2e-3, thickness=1e-5, v0=0.5):
    nodes, conn = strip_mesh(nx, ny, length, thickness)
    fixed = nodes[:, 0] < 1e-15
    prm = default_prm()
    prm[layout.P_HGV] = 0.0
    prm[layout.P_BV1] = 0.0
    prm[layout.P_BV2] = 0.0
    prm[layout.P_SAMPLE_DT] = 2e-8
    mat = elastic_tc4()
    st = make_state(nodes, conn, fixed, mat, prm=prm, n_samples=20000)
    st.vx[:] = v0 * np.sin(0.5 * math.pi * st.x / length)
    st.vx[fixed] = 0.0
    return st, mat, length


def test_elastic_bar_period_and_energy():
    st, mat, L = _bar()
    tip = np.argmax(st.x + st.y)
    E1 = mat.E / (1 - mat.nu**2)
    c = math.sqrt(E1 / mat.rho)
    T = 4 * L / c
    xs, ts = [], []
    ke0 = 0.5 * np.sum(st.mass * st.vx**2)
    energies = []
    n_chunks = 60
    for k in range(n_chunks):
        advance(st, (k + 1) * 1.5 * T / n_chunks, chunk_steps=10**7)
        xs.append(st.x[tip] - st.x0[tip])
        ts.append(st.time)
    h = st.hist[np.isfinite(st.hist[:, layout.H_T])]
    energies = h[:, layout.H_EKIN] + h[:, layout.H_EINT] + h[:, layout.H_EHG]
    # energy conserved to 0.5 % (central difference, no viscosity)
    assert np.max(np.abs(energies - ke0)) / ke0 < 5e-3
    # period from the first zero crossing of the tip displacement after its maximum (T/2)
    xs = np.array(xs)
    ts = np.array(ts)
    i = np.argmax(xs < 0)
    t_zero = ts[i - 1] + (ts[i] - ts[i - 1]) * xs[i - 1] / (xs[i - 1] - xs[i])
    assert t_zero == pytest.approx(T / 2, rel=0.02)


def test_instability_is_reported_not_nan():
    st, mat, L = _bar(nx=20, length=2e-4)
    st.prm[layout.P_CFL] = 3.0  # far above the stable step
    st.clock[1] *= 3.0 / 0.8
    with pytest.raises(NumericalError, match="step .* time"):
        advance(st, 1e-5, chunk_steps=500)


def test_heat_conduction_matches_erfc_and_conserves_heat():
    """A temperature step in a strip (no motion) spreads as the 1D solution
    T = T0 + dT/2 erfc((x - x0) / (2 sqrt(alpha t))) (Carslaw & Jaeger 1959, sec. 2.4),
    alpha = k / (rho cp); heat (sum rho cp A T) is conserved. Tolerance: 2 % of dT (cell
    values of 5 um cells against the point solution), heat to 1e-12."""
    from scipy.special import erfc

    nx, lx, ly = 160, 8e-4, 5e-6
    nodes, conn = strip_mesh(nx, 1, lx, ly)
    prm = default_prm()
    prm[layout.P_MS] = 1e6  # large mechanical step; the thermal mass is never scaled
    prm[layout.P_COND_EVERY] = 1
    st = make_state(nodes, conn, np.zeros(nodes.shape[0], bool), TC4, prm=prm,
                    phases=Phases(conduction=True))
    xc = st.x[conn].mean(axis=1)
    x0 = 0.5 * lx
    t0k, dT = 293.0, 400.0
    st.temp[:] = np.where(xc < x0, t0k + dT, t0k)
    heat0 = np.sum(st.temp * st.area0)
    alpha = TC4.k / (TC4.rho * TC4.cp)
    t_end = (40e-6) ** 2 / alpha  # diffusion length 2 sqrt(alpha t) = 80 um << lx / 2
    advance(st, t_end, chunk_steps=10**6)
    exact = t0k + 0.5 * dT * erfc((xc - x0) / (2.0 * math.sqrt(alpha * st.time)))
    assert np.max(np.abs(st.temp - exact)) < 0.02 * dT
    assert np.sum(st.temp * st.area0) == pytest.approx(heat0, rel=1e-12)
    # and without conduction (the adiabatic loop) nothing moves
    prm[layout.P_COND_EVERY] = 0
    st2 = make_state(nodes, conn, np.zeros(nodes.shape[0], bool), TC4, prm=prm)
    st2.temp[:] = np.where(xc < x0, t0k + dT, t0k)
    advance(st2, t_end, chunk_steps=10**6)
    assert np.max(np.abs(st2.temp - np.where(xc < x0, t0k + dT, t0k))) == 0.0
