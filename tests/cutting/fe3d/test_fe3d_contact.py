"""3D contact law and insert geometry; rigid-insert contact patch without excess penetration.

The contact law is the 2D engine's (mass-proportional penalty, viscous normal damping,
Coulomb, shear cap;
:func:`robobore.cutting.fe.physics.tool_contact.contact_force_py`) with a tangential vector; the
insert's signed distance is the 2D wedge (:func:`tool_contact.tool_gap_py`) in the normal
section of the nose-radius edge.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robobore.cutting.fe.engine.state3d import advance3, box_mesh, default_prm3, make_state3
from robobore.cutting.fe.hex import layout3d, scalar3d
from robobore.cutting.fe.physics.tool_contact import contact_force_py, tool_gap_py
from robobore.material import Material, load_material

RN, KAP, KEND, RAKE, CLR, RE = 0.4e-3, math.radians(90), math.radians(5), math.radians(7), \
    math.radians(7), 20e-6


def gap(p):
    return scalar3d.insert_gap3_py(p[0], p[1], p[2], RN, KAP, KEND, RAKE, CLR, RE, 0.0)


def test_contact_force3_hand_calculation():
    """Normal penalty F = pf m / dt^2 (-g); sliding capped by mu Fn, opposite to sliding;
    a 2D-plane case equals the 2D law."""
    m, dt, pf, mu = 2e-9, 1e-8, 0.1, 0.3
    fx, fy, fz, fn, ft, *_ = scalar3d.contact_force3_py(-1e-7, (0, 1, 0), (5.0, 0.0, 0.0),
                                                        (0.0, 0.0, 0.0), m, 1.0, dt,
                                                        (mu, 1e30, pf, 0.0))
    assert fn == pytest.approx(pf * m / dt**2 * 1e-7)
    assert fy == pytest.approx(fn)
    assert ft == pytest.approx(mu * fn)  # m v / dt = 1 N > mu Fn = 0.06 N
    assert fx == pytest.approx(-mu * fn) and fz == 0.0
    # stick: small sliding velocity -> the force that stops it in one step
    *_, ft2, tx, ty, tz, _ = scalar3d.contact_force3_py(-1e-7, (0, 1, 0), (0.0, 0.0, 1e-3),
                                                        (0.0, 0.0, 0.0), m, 1.0, dt,
                                                        (mu, 1e30, pf, 0.0))
    assert ft2 == pytest.approx(m * 1e-3 / dt) and tz == pytest.approx(1.0)
    # shear cap
    *_, ft3, _, _, _, _ = scalar3d.contact_force3_py(-1e-7, (0, 1, 0), (5.0, 0.0, 0.0),
                                                     (0.0, 0.0, 0.0), m, 1e-12, dt,
                                                     (mu, 1e9, pf, 0.0))
    assert ft3 == pytest.approx(1e9 * 1e-12)
    # 2D equivalence in the x-y plane
    f2 = contact_force_py(-1e-7, (0.6, 0.8), (0.3, -0.2), (0.0, 0.0), m, 1.0, dt,
                          (mu, 1e30, pf, 0.0))
    f3 = scalar3d.contact_force3_py(-1e-7, (0.6, 0.8, 0.0), (0.3, -0.2, 0.0), (0.0, 0.0, 0.0), m,
                                    1.0, dt, (mu, 1e30, pf, 0.0))
    assert f3[0] == pytest.approx(f2[0]) and f3[1] == pytest.approx(f2[1]) and f3[2] == 0.0
    # return mapping on the trial velocity, as in 2D: the element forces' tangential part
    # enters the stick force (static friction balances a push below mu Fn)
    fn = pf * m / dt**2 * 1e-7
    push = (0.0, 0.4 * mu * fn, 0.3 * mu * fn)  # y is normal: only z is tangential
    *_, ft4, tx, ty, tz, _ = scalar3d.contact_force3_py(-1e-7, (0, 1, 0), (0.0, 0.0, 0.0), push, m,
                                                        1.0, dt, (mu, 1e30, pf, 0.0))
    assert ft4 == pytest.approx(0.3 * mu * fn) and tz == pytest.approx(1.0)
    g2 = contact_force_py(-1e-7, (0.6, 0.8), (0.3, -0.2), (0.5, -0.7), m, 1.0, dt,
                          (mu, 1e30, pf, 0.0))
    g3 = scalar3d.contact_force3_py(-1e-7, (0.6, 0.8, 0.0), (0.3, -0.2, 0.0), (0.5, -0.7, 0.0), m,
                                    1.0, dt, (mu, 1e30, pf, 0.0))
    assert g3[0] == pytest.approx(g2[0]) and g3[1] == pytest.approx(g2[1])


def test_contact_force3_damping_is_the_2d_law():
    """Viscous normal damping c = 2 zeta sqrt(k m) on the relative normal velocity, never
    adhesive, as the 2D law (tests/cutting/fe/test_contact_tool.py): in the x-y plane the 3D
    law returns the 2D law's force, normal force and damping part; a node leaving fast gets
    no pull; the out-of-plane velocity does not enter the normal damping."""
    m, dt, pf, mu, z = 1e-6, 1e-8, 0.1, 0.3, 0.7
    k = pf * m / dt**2
    c = 2 * z * (k * m) ** 0.5
    for vr in ((0.3, -0.2), (-0.05, -0.01), (0.0, 10.0)):
        f2 = contact_force_py(-1e-8, (0.6, 0.8), (vr[0], vr[1]), (0.5, -0.7), m, 1.0, dt,
                              (mu, 1e30, pf, z))
        f3 = scalar3d.contact_force3_py(-1e-8, (0.6, 0.8, 0.0), (vr[0], vr[1], 0.0),
                                        (0.5, -0.7, 0.0), m, 1.0, dt, (mu, 1e30, pf, z))
        assert f3[0] == pytest.approx(f2[0], rel=1e-12) and f3[1] == pytest.approx(f2[1],
                                                                                   rel=1e-12)
        assert f3[3] == pytest.approx(f2[2], rel=1e-12) and f3[8] == pytest.approx(f2[4],
                                                                                   rel=1e-12)
        assert f3[3] >= 0.0
    # approaching along -y at 0.01 m/s (and sliding in z): fd = c * 0.01 exactly
    f = scalar3d.contact_force3_py(-1e-8, (0.0, 1.0, 0.0), (0.0, -0.01, 0.2), (0.0, 0.0, 0.0), m,
                                   1.0, dt, (mu, 1e30, pf, z))
    assert f[8] == pytest.approx(c * 0.01, rel=1e-12)
    assert f[3] == pytest.approx(k * 1e-8 + c * 0.01, rel=1e-12)
    # leaving at 10 m/s: no adhesion
    f = scalar3d.contact_force3_py(-1e-8, (0.0, 1.0, 0.0), (0.0, 10.0, 0.0), (0.0, 0.0, 0.0), m,
                                   1.0, dt, (mu, 1e30, pf, z))
    assert f[3] == 0.0 and f[8] == pytest.approx(-k * 1e-8)


def test_insert_gap_reference_points():
    """Below the tip by d: gap = d (edge circle); on the nose arc at angle psi below by d:
    gap = d; ahead of the rounded edge at the apex height: gap = u - r_e; the normal section
    at the tip equals the 2D wedge."""
    for d in (1e-6, 5e-6):
        g, nx, ny, nz = gap((0.0, -d, 0.0))
        assert g == pytest.approx(d, rel=1e-9)
        assert ny == pytest.approx(-1.0)
        for psi in (0.3, -0.05, 1.2):
            rr = RN + d
            p = (0.0, RN - rr * math.cos(psi), rr * math.sin(psi))
            assert gap(p)[0] == pytest.approx(d, rel=1e-9, abs=1e-12)
    g, nx, ny, nz = gap((RE + 3e-6, RE, 0.0))
    assert g == pytest.approx(3e-6, rel=1e-9) and nx == pytest.approx(1.0)
    for px, py in ((2e-5, 4e-5), (-1e-5, -5e-6), (-6e-5, 5e-6), (1e-6, 1e-4)):
        g3 = gap((px, py, 0.0))
        g2 = tool_gap_py(-px, py - RE, 0.0, 0.0, -math.cos(RAKE), math.sin(RAKE),
                         math.sin(CLR), -math.cos(CLR), RE)
        assert g3[0] == pytest.approx(g2[0], rel=1e-9, abs=1e-15)


@settings(max_examples=60, deadline=None)
@given(st.floats(-5e-5, 5e-5), st.floats(-3e-5, 6e-5), st.floats(-1.5e-4, 3e-4),
       st.floats(1e-7, 2e-6))
def test_insert_gap_normal_is_unit_and_consistent(px, py, pz, h):
    """The normal is a unit vector; stepping along it by h changes the gap by h (the gap is
    a distance field near the surface) to within 5 %."""
    g, nx, ny, nz = gap((px, py, pz))
    assert math.isclose(nx * nx + ny * ny + nz * nz, 1.0, rel_tol=1e-9)
    if abs(g) < 1e-5:
        g2 = gap((px + h * nx, py + h * ny, pz + h * nz))[0]
        assert g2 - g == pytest.approx(h, rel=0.05, abs=1e-9)


def test_rigid_insert_contact_patch_without_penetration():
    """An elastic block pushed up (bottom face at 0.05 m/s, 0.4 um past first touch) against
    the stationary insert nose: the largest penetration stays below 2 % of the element size
    (the 2D engine's criterion) and the insert is pushed out of the material."""
    d = load_material("TC4").to_dict()
    d.update(A=1e15, B=0.0)
    mat = Material.from_dict(d)
    le = 10e-6
    nodes, conn, idx = box_mesh(8, 4, 8, 8 * le, 4 * le, 8 * le,
                                origin=(-4 * le, -4 * le - 0.1e-6, -4 * le))
    fixed = np.zeros(len(nodes), np.int64)
    bottom = idx[:, 0, :].ravel()
    fixed[bottom] = 7
    p = default_prm3()
    p[layout3d.P_TOOL] = 1.0
    p[layout3d.P_RN], p[layout3d.P_KAPPA], p[layout3d.P_KEND] = RN, KAP, KEND
    p[layout3d.P_RAKE], p[layout3d.P_CLR], p[layout3d.P_RE] = RAKE, CLR, RE
    p[layout3d.P_MU] = 0.3
    p[layout3d.P_MS] = 100.0
    p[layout3d.P_SAMPLE_DT] = 1e-7
    s = make_state3(nodes, conn, fixed, mat, prm=p, n_samples=400, tool_tip=(0.0, 0.0, 0.0))
    s.vy[bottom] = 0.05
    worst = 0.0
    for k in range(1, 11):
        advance3(s, k * 1e-6)
        g = np.array([gap((s.x[n], s.y[n], s.z[n]))[0] for n in range(len(nodes))])
        worst = max(worst, float(-g.min()))
    assert np.abs(s.cf[:, :3]).sum() > 0, "block never reached the insert"
    assert worst < 0.02 * le
    fy = s.hist[np.isfinite(s.hist[:, scalar3d.H_T]), scalar3d.H_FY]
    assert fy[-1] > 0  # the insert is pushed up (out of the material)
