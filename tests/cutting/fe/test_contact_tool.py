"""Rigid-tool contact and the tool on springs/dampers.

References: the analytic tool shape (rake line, edge arc, flank line) is checked against
hand-computed distances; free vibration of a damped oscillator m u'' + c u' + k u = 0:
omega_d = omega_n sqrt(1 - zeta^2), logarithmic decrement delta = 2 pi zeta / sqrt(1 - zeta^2)
(Thomson & Dahl, *Theory of Vibration with Applications*, sec. 2.6).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import elastic_tc4, strip_mesh
from hypothesis import given, settings
from hypothesis import strategies as st

from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.engine.chunk_driver import advance
from robobore.cutting.fe.engine.state2d import default_prm, make_state
from robobore.cutting.fe.physics import tool_contact as P

RAKE = math.radians(15.0)
CLR = math.radians(2.0)
NR = (-math.cos(RAKE), math.sin(RAKE))
NF = (math.sin(CLR), -math.cos(CLR))


def test_tool_gap_hand_values():
    r = 20e-6
    # straight below the edge centre: on the arc, gap = distance - r
    g, nx, ny = P.tool_gap(0.0, -30e-6, 0.0, 0.0, *NR, *NF, r)
    assert g == pytest.approx(10e-6) and (nx, ny) == pytest.approx((0.0, -1.0))
    # a point on the rake side, 50 um up the face, 5 um off it
    tr = (NR[1], -NR[0])
    p = (50e-6 * tr[0] + (r + 5e-6) * NR[0], 50e-6 * tr[1] + (r + 5e-6) * NR[1])
    g, nx, ny = P.tool_gap(*p, 0.0, 0.0, *NR, *NF, r)
    assert g == pytest.approx(5e-6) and (nx, ny) == pytest.approx(NR)
    # inside, just behind the rake face: penetration 2 um
    p = (50e-6 * tr[0] + (r - 2e-6) * NR[0], 50e-6 * tr[1] + (r - 2e-6) * NR[1])
    g, nx, ny = P.tool_gap(*p, 0.0, 0.0, *NR, *NF, r)
    assert g == pytest.approx(-2e-6) and (nx, ny) == pytest.approx(NR)


@settings(max_examples=200, deadline=None)
@given(px=st.floats(-1e-4, 1e-4), py=st.floats(-1e-4, 1e-4), r=st.floats(0.0, 5e-5))
def test_tool_gap_is_a_distance(px, py, r):
    """Property: moving a point by d along the returned normal changes the gap by d (it is
    a signed distance with unit gradient) and the normal has unit length."""
    if math.hypot(px, py) < 1e-9:
        return
    g, nx, ny = P.tool_gap(px, py, 0.0, 0.0, *NR, *NF, r)
    assert math.hypot(nx, ny) == pytest.approx(1.0)
    d = 1e-8
    g2, _, _ = P.tool_gap(px + d * nx, py + d * ny, 0.0, 0.0, *NR, *NF, r)
    assert g2 - g == pytest.approx(d, rel=1e-3, abs=1e-13)


def test_contact_law_coulomb_and_cap():
    m, dt = 1e-6, 1e-8
    # sliding fast: friction = mu * Fn, opposite to the sliding velocity
    fx, fy, fn, ft, fd = P.contact_force(-1e-8, (0.0, 1.0), (1.0, 0.0), (0.0, 0.0), m, 1e-5, dt,
                                         (0.2, 1e30, 0.1, 0.0))
    assert fd == 0.0
    assert fn == pytest.approx(0.1 * m / dt**2 * 1e-8)
    assert ft == pytest.approx(0.2 * fn) and fy == pytest.approx(fn)
    # tangent t = (-ny, nx) = (-1, 0); vt = -1 (sliding along +x) -> friction along t positive
    assert fx == pytest.approx(-0.2 * fn)
    # shear cap: tau * length below mu * Fn
    _, _, fn2, ft2, _ = P.contact_force(-1e-8, (0.0, 1.0), (1.0, 0.0), (0.0, 0.0), m, 1e-5, dt,
                                        (0.2, 1e5, 0.1, 0.0))
    assert 1e5 * 1e-5 < 0.2 * fn2
    assert abs(ft2) == pytest.approx(1e5 * 1e-5)
    # sticking: small slip velocity -> force stopping it in one step
    _, _, _, ft3, _ = P.contact_force(-1e-8, (0.0, 1.0), (1e-9, 0.0), (0.0, 0.0), m, 1e-5, dt,
                                      (0.2, 1e30, 0.1, 0.0))
    assert abs(ft3) == pytest.approx(m * 1e-9 / dt)
    # no contact
    assert P.contact_force(1e-9, (0.0, 1.0), (1.0, 0.0), (0.0, 0.0), m, 1e-5, dt,
                           (0.2, 1e30, 0.1, 0.3)) == (0.0, 0.0, 0.0, 0.0, 0.0)


def test_contact_law_return_mapping_on_the_trial_velocity():
    """The stick force stops the *trial* sliding velocity (start-of-step velocity plus this
    step's element forces), so a node pushed along the tool by its elements sticks while the
    push is below mu Fn and then slides against exactly mu Fn -- not against the numerical
    viscous force m v / dt that stopping only the start-of-step velocity would give."""
    m, dt, mu, pf = 1e-6, 1e-8, 0.2, 0.1
    fn = pf * m / dt**2 * 1e-8
    # at rest, pushed along +x (= -t) by 0.5 mu Fn: static friction balances it exactly
    fx, _, _, ft, _ = P.contact_force(-1e-8, (0.0, 1.0), (0.0, 0.0), (0.5 * mu * fn, 123.0), m,
                                      1e-5, dt, (mu, 1e30, pf, 0.0))
    assert fx == pytest.approx(-0.5 * mu * fn) and abs(ft) == pytest.approx(0.5 * mu * fn)
    # pushed by 3 mu Fn: slides, friction mu Fn against the push
    fx, _, _, ft, _ = P.contact_force(-1e-8, (0.0, 1.0), (0.0, 0.0), (3 * mu * fn, 0.0), m, 1e-5,
                                      dt, (mu, 1e30, pf, 0.0))
    assert fx == pytest.approx(-mu * fn)
    # sliding slowly (m v / dt = 0.1 mu Fn) and pushed on by 2 mu Fn: Coulomb, not m v / dt
    v = 0.1 * mu * fn * dt / m
    fx, *_ = P.contact_force(-1e-8, (0.0, 1.0), (v, 0.0), (2 * mu * fn, 0.0), m, 1e-5, dt,
                             (mu, 1e30, pf, 0.0))
    assert fx == pytest.approx(-mu * fn)
    # the push's normal part does not enter the friction
    _, _, fn2, ft2, _ = P.contact_force(-1e-8, (0.0, 1.0), (0.0, 0.0), (0.0, -5 * fn), m, 1e-5, dt,
                                        (mu, 1e30, pf, 0.0))
    assert fn2 == pytest.approx(fn) and ft2 == 0.0


def test_contact_damping():
    """Viscous normal damping c = 2 zeta sqrt(k m) on the relative normal velocity (exact),
    never adhesive: a node leaving the tool fast gets no pull (fn >= 0)."""
    m, dt, pf, z = 1e-6, 1e-8, 0.1, 0.2
    k = pf * m / dt**2
    c = 2 * z * (k * m) ** 0.5
    # approaching along -n at 0.01 m/s: the damping adds c * 0.01 to the penalty force
    _, fy, fn, _, fd = P.contact_force(-1e-8, (0.0, 1.0), (0.0, -0.01), (0.0, 0.0), m, 1e-5, dt,
                                       (0.0, 1e30, pf, z))
    assert fd == pytest.approx(c * 0.01, rel=1e-12)
    assert fn == pytest.approx(k * 1e-8 + c * 0.01, rel=1e-12) and fy == pytest.approx(fn)
    # leaving at 10 m/s: the damping would pull harder than the spring pushes -> fn = 0
    _, _, fn2, _, fd2 = P.contact_force(-1e-8, (0.0, 1.0), (0.0, 10.0), (0.0, 0.0), m, 1e-5, dt,
                                        (0.0, 1e30, pf, z))
    assert fn2 == 0.0 and fd2 == pytest.approx(-k * 1e-8)


def test_rake_face_contact_patch():
    """A 200 x 100 um elastic TC4 block, fixed at x = 0, pushed by the rake face (rake 0) at
    0.05 m/s by 0.2 um: no node penetrates the tool by more than 2 % of the element size,
    and the tool force matches the plane-strain bar stiffness E/(1-nu^2) * H * delta / L
    within 10 % (end restraint and elastic dynamics)."""
    L, H, le = 200e-6, 100e-6, 10e-6
    nodes, conn = strip_mesh(20, 10, L, H)
    fixed = nodes[:, 0] < 1e-15
    mat = elastic_tc4()
    prm = default_prm()
    prm[layout.P_NRX], prm[layout.P_NRY] = -1.0, 0.0
    prm[layout.P_NFX], prm[layout.P_NFY] = math.sin(CLR), -math.cos(CLR)
    prm[layout.P_R] = 2e-6
    prm[layout.P_MU] = 0.2
    prm[layout.P_VC] = 0.05
    prm[layout.P_SAMPLE_DT] = 1e-7
    gap0 = 0.1e-6
    st = make_state(nodes, conn, fixed, mat, prm=prm, n_samples=100,
                    tool_center=(L + 2e-6 + gap0, -1e-6))
    delta = 0.2e-6
    t_end = (gap0 + delta) / 0.05
    advance(st, t_end)
    cx, cy = st.tool[layout.T_GX], st.tool[layout.T_GY]
    gaps = np.array([P.tool_gap(st.x[i], st.y[i], cx, cy, *prm[layout.P_NRX:layout.P_NFY + 1],
                                prm[layout.P_R])[0] for i in range(len(st.x))])
    assert -gaps.min() < 0.02 * le
    contact = gaps < 0
    assert contact.sum() == 11  # the whole right face
    e1 = mat.E / (1 - mat.nu**2)
    # the face moved by delta minus the penetration
    f_static = e1 * H * (delta + np.mean(gaps[contact])) / L
    f_tool = st.tool[layout.T_FX]  # force on the tool at the last step [N/m]
    assert f_tool == pytest.approx(f_static, rel=0.10)


def test_tool_support_free_vibration_scalar():
    m, k, zeta = 0.5, 2.0e7, 0.03
    c = 2 * zeta * math.sqrt(k * m)
    wn = math.sqrt(k / m)
    dt = 2e-7
    u, v = 1e-6, 0.0
    us = []
    for _ in range(int(0.01 / dt)):
        u, v = P.tool_support_step(u, v, 0.0, k, c, m, dt)
        us.append(u)
    us = np.array(us)
    t = dt * np.arange(1, len(us) + 1)
    _check_oscillation(t, us, wn, zeta)


def _check_oscillation(t, u, wn, zeta):
    s = np.sign(u)
    idx = np.where(np.diff(s) != 0)[0]
    tz = t[idx] - u[idx] * (t[idx + 1] - t[idx]) / (u[idx + 1] - u[idx])
    period = 2 * np.mean(np.diff(tz))
    wd = wn * math.sqrt(1 - zeta**2)
    assert 2 * math.pi / period == pytest.approx(wd, rel=5e-3)
    # logarithmic decrement from successive positive peaks
    peaks = [np.max(u[(t >= a) & (t < b)]) for a, b in zip(tz[1:-2:2], tz[3::2], strict=False)]
    dec = np.mean(np.log(np.array(peaks[:-1]) / np.array(peaks[1:])))
    assert dec / math.sqrt(4 * math.pi**2 + dec**2) == pytest.approx(zeta, rel=0.03)


def test_tool_support_in_solver_loop():
    """Tool released from 1 um in x and y, no workpiece contact: the loop's 2-DOF tool
    oscillates at its natural frequency with its damping."""
    nodes, conn = strip_mesh(2, 2, 20e-6, 20e-6)
    mat = elastic_tc4()
    prm = default_prm()
    m, k, zeta = 0.2, 5.0e6, 0.05
    c = 2 * zeta * math.sqrt(k * m)
    prm[layout.P_SUPPORT] = 1.0
    prm[layout.P_KX] = prm[layout.P_KY] = k
    prm[layout.P_CX] = prm[layout.P_CY] = c
    prm[layout.P_MX] = prm[layout.P_MY] = m
    prm[layout.P_SAMPLE_DT] = 5e-6
    prm[layout.P_MS] = 1e6  # big steps: the workpiece is idle here
    st = make_state(nodes, conn, nodes[:, 1] < 1e-15, mat, prm=prm, n_samples=3000,
                    tool_center=(1.0, 1.0))
    st.tool[layout.T_UX] = 1e-6
    st.tool[layout.T_UY] = 1e-6
    advance(st, 0.012, chunk_steps=10**6)
    h = st.hist[np.isfinite(st.hist[:, layout.H_T])]
    # samples are averages over the interval: compare with the sampled interval mid-times
    _check_oscillation(h[:, layout.H_T] - 2.5e-6, h[:, layout.H_UX], math.sqrt(k / m), zeta)
    np.testing.assert_allclose(h[:, layout.H_UY], h[:, layout.H_UX], rtol=1e-9, atol=1e-15)
