"""3D contact friction: the 2D engine's friction laws, read at each contact node's sliding speed.

The boring config's ``[contact]`` is the 2D engine's (same law names, table, velocity, filter
and shear-cap defaults); the 3D node update reads the law's table at the node's filtered
sliding speed with the 2D engine's lookup function re-bound to the 3D parameter slots.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from robobore.cutting.fe.config.boring3d import parse_boring_config
from robobore.cutting.fe.config.contact import ContactSection
from robobore.cutting.fe.config.engine_settings import apply_friction_settings
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.engine.state2d import default_prm
from robobore.cutting.fe.engine.state3d import box_mesh, default_prm3, make_state3
from robobore.cutting.fe.hex import layout3d, scalar3d
from robobore.cutting.fe.quad import node_contact
from robobore.errors import ConfigError
from robobore.material import load_material
from robobore.material.friction import friction_law

RN, KAP, KEND, RAKE, CLR, RE = 0.4e-3, math.radians(90), math.radians(5), math.radians(7), \
    math.radians(7), 20e-6
LAW = friction_law("rech2013_calibrated")


def _base(**extra):
    d = {"cut": {"depth_of_cut_mm": 0.05, "feed_mm_per_rev": 0.15, "speed_rpm": 300.0},
         "mesh": {"element_size_um": 12.5}}
    d.update(extra)
    return d


def test_boring_config_defaults_to_the_validated_law():
    """No [contact] friction: the law rech2013_calibrated (table x 1.5, read at the sliding
    speed, no shear cap) and the material file's hardening hold (TC4: 0.6)."""
    c = parse_boring_config(_base())
    assert c.contact._law == "rech2013_calibrated"
    assert c.contact.friction == "table" and c.contact.friction_velocity == "sliding"
    assert c.contact.shear_limit_MPa == LAW.shear_limit_MPa == 5000.0
    np.testing.assert_array_equal(c.contact.table()[1], LAW.mu)
    assert c.material.strain_limit() is None
    assert load_material("TC4", hardening_strain_limit=None).hardening_strain_limit == 0.6
    # the a-priori switch: the source's law at the cutting speed, shear cap 576, plain JC
    a = parse_boring_config(_base(parameters="a_priori"))
    assert a.contact._law == "rech2013" and a.contact.friction_velocity == "cutting_speed"
    assert a.contact.shear_limit_MPa == 576.0 and a.material.strain_limit() == math.inf
    # a constant: no table slots
    k = parse_boring_config(_base(contact={"friction": 0.3}))
    p = apply_friction_settings(default_prm3(), k.contact, 37.7, layout3d)
    assert p[layout3d.P_MU] == 0.3 and p[layout3d.P_MUTAB_N] == 0.0


@pytest.mark.parametrize("contact, match", [
    ({"friction": "coulomb_0.3"}, "unknown friction"),
    ({"friction": 2.5}, "0..2"),
    ({"normal_damping": 1.5}, "normal_damping"),
    ({"thermal_conductance_W_per_m2K": 1e12}, "thermal_conductance_W_per_m2K"),
    ({"friction_heat_fraction": 1.5}, "friction_heat_fraction"),
    ({"friction": 0.3, "friction_velocity": "sliding"}, "constant coefficient"),
])
def test_bad_contact_keys_name_the_key(contact, match):
    with pytest.raises(ConfigError, match=match):
        parse_boring_config(_base(contact=contact), source="bad.toml")


def test_table_lookup_is_the_2d_engines():
    """The same section gives the same table in the 2D and 3D slots, and the 3D lookup
    returns what the 2D one does: the law's coefficients at its velocities, linear between,
    constant beyond the ends."""
    c = ContactSection()
    p3 = apply_friction_settings(default_prm3(), c, 37.7, layout3d)
    p2 = apply_friction_settings(default_prm(), c, 37.7, layout)
    assert p3[layout3d.P_MUTAB_N] == p2[layout.P_MUTAB_N] == len(LAW.mu)
    assert p3[layout3d.P_SLIP_TAU] == p2[layout.P_SLIP_TAU] == pytest.approx(1e-6 / (37.7 / 60.0))
    for v_m_min, mu in zip(LAW.velocity_m_per_min, LAW.mu, strict=True):
        assert scalar3d.friction_at3(p3, v_m_min / 60.0) == pytest.approx(mu, abs=1e-15)
    for v in (0.0, 0.1, 8.75 / 60.0, 0.4, 5.0):
        assert scalar3d.friction_at3(p3, v) == node_contact.friction_at_py(p2, v)
    assert scalar3d.friction_at3(p3, 8.75 / 60.0) == pytest.approx(0.5 * (0.33 + 0.315))


def _node_on_rake(speed: float, slip_tau_steps: float):
    """One node 0.1 nm inside the insert's rake face, sliding up it at ``speed`` [m/s]; one
    node update. Returns (Coulomb ratio of its contact force, its filtered speed, dt)."""
    le = 20e-6
    nodes, conn, _ = box_mesh(1, 1, 1, le, le, le, origin=(-2 * le, -2 * le, -le / 2))
    p = apply_friction_settings(default_prm3(), ContactSection(), 37.7, layout3d)
    p[layout3d.P_TOOL] = 1.0
    p[layout3d.P_RN], p[layout3d.P_KAPPA], p[layout3d.P_KEND] = RN, KAP, KEND
    p[layout3d.P_RAKE], p[layout3d.P_CLR], p[layout3d.P_RE] = RAKE, CLR, RE
    s = make_state3(nodes, conn, np.zeros(len(nodes), np.int64), load_material("TC4"), prm=p,
                    tool_tip=(0.0, 0.0, 0.0))
    dt = float(s.clock[1])
    s.prm[layout3d.P_SLIP_TAU] = slip_tau_steps * dt
    y = 30e-6
    lo, hi = 10e-6, 20e-6  # the rake face crosses y = 30 um between these x
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if scalar3d.insert_gap3_py(mid, y, 0.0, RN, KAP, KEND, RAKE, CLR, RE, 0.0)[0] < -1e-10:
            lo = mid
        else:
            hi = mid
    g, nx, ny, nz = scalar3d.insert_gap3_py(lo, y, 0.0, RN, KAP, KEND, RAKE, CLR, RE, 0.0)
    assert -2e-10 < g < 0.0 and nz == 0.0
    s.x[0], s.y[0], s.z[0] = lo, y, 0.0
    s.vx[0], s.vy[0] = -ny * speed, nx * speed  # up the rake face (tangent)
    scalar3d.hex_node(0, s.x, s.y, s.z, s.vx, s.vy, s.vz, s.mass, s.fixed, s.ptr, s.nel, s.ncorner,
                s.alive, s.vol0, s.fe, s.cf, s.fric, s.pen, s.ndead, s.ero_ke, s.nwork, s.prm,
                0.0, 0.0, 0.0, 0.0, 0.0, 0.0, dt, s.pairs)
    f = s.cf[0, :3]
    n = np.array([nx, ny, nz])
    fn = float(f @ n)
    ft = float(np.linalg.norm(f - fn * n))
    assert fn > 0.0
    return ft / fn, float(s.cf[0, 3]), dt


@pytest.mark.parametrize("v_m_min, mu", [(5.0, 0.36), (30.0, 0.27), (8.75, 0.3225)])
def test_contact_node_reads_the_law_at_its_sliding_speed(v_m_min, mu):
    """A node sliding on the rake (fast enough to slip, not stick) gets the friction force
    mu(v) Fn with mu the law's coefficient at its sliding speed v: 0.36 at 5 m/min, 0.27 at
    30 m/min (rech2013_calibrated), interpolated between table points."""
    ratio, vs, _ = _node_on_rake(v_m_min / 60.0, slip_tau_steps=0.5)  # tau < dt: no filter
    assert vs == pytest.approx(v_m_min / 60.0, rel=1e-12)
    assert ratio == pytest.approx(mu, rel=1e-9)


def test_sliding_speed_is_low_pass_filtered():
    """With the filter's time constant 4 steps, a node that starts sliding at 30 m/min
    reads the table at a quarter of it after one step (the 2D engine's filter)."""
    v = 30.0 / 60.0
    ratio, vs, _ = _node_on_rake(v, slip_tau_steps=4.0)
    assert vs == pytest.approx(0.25 * v, rel=1e-12)
    p = apply_friction_settings(default_prm(), ContactSection(), 37.7, layout)
    assert ratio == pytest.approx(node_contact.friction_at_py(p, 0.25 * v), rel=1e-9)
