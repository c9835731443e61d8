"""Friction as a function of the sliding velocity (``contact.friction_velocity = "sliding"``).

Reference: a tribometer gives the Coulomb coefficient against the *sliding* velocity (Rech et
al. 2013, CIRP Annals 62, 79-82, the source of the Ti6Al4V table bundled in
robobore.cutting.fe.config.orthogonal); a slip-rate-dependent table is read piecewise linearly and
is constant beyond its ends (as Abaqus' friction tables). The engine looks the coefficient up
per contact node and step at the node's sliding speed relative to the tool.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import elastic_tc4, strip_mesh

from robobore.cutting.fe.config.orthogonal import parse_config
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.engine.chunk_driver import advance
from robobore.cutting.fe.engine.state2d import default_prm, make_state
from robobore.cutting.fe.physics import tool_contact as P
from robobore.cutting.fe.quad import node_contact
from robobore.errors import ConfigError


def _prm(v_m_s, mu):
    p = default_prm()
    p[layout.P_MU] = 0.123
    p[layout.P_MUTAB_N] = len(v_m_s)
    p[layout.P_MUTAB_V:layout.P_MUTAB_V + len(v_m_s)] = v_m_s
    p[layout.P_MUTAB_MU:layout.P_MUTAB_MU + len(mu)] = mu
    return p


def test_friction_at_is_the_piecewise_linear_table():
    p = _prm([0.1, 0.5, 1.0], [0.4, 0.2, 0.25])
    for speed, want in [(0.0, 0.4), (0.1, 0.4), (0.3, 0.3), (0.5, 0.2), (0.75, 0.225),
                        (1.0, 0.25), (7.0, 0.25)]:
        assert node_contact.friction_at(p, speed) == pytest.approx(want, rel=1e-14)
        assert node_contact.friction_at_py(p, speed) == pytest.approx(want, rel=1e-14)
        assert node_contact.friction_at(p, speed) == pytest.approx(
            float(np.interp(speed, [0.1, 0.5, 1.0], [0.4, 0.2, 0.25])), rel=1e-14)
    p[layout.P_MUTAB_N] = 0  # no table: the constant coefficient
    assert node_contact.friction_at(p, 0.3) == 0.123


def _cfg(**contact):
    return {"tool": {"rake_deg": 15, "clearance_deg": 2, "edge_radius_um": 20},
            "cut": {"uncut_chip_thickness_um": 60, "cutting_speed_m_per_min": 30,
                    "length_mm": 0.02},
            "contact": {"friction": "table", **contact},
            "mesh": {"element_size_um": 20, "frame": "tool", "edge_element_um": 5},
            "solver": {"mass_scaling": 100, "n_samples": 20}}


@pytest.mark.parametrize("contact, words", [
    ({"friction": 0.2, "friction_velocity": "sliding"}, "need friction"),
    ({"friction": 0.2, "friction_table_velocity_m_per_min": [0, 10],
      "friction_table_mu": [0.3, 0.2]}, "need friction"),
    ({"friction_table_velocity_m_per_min": [0, 10]}, "give both"),
    ({"friction_table_velocity_m_per_min": [0, 10], "friction_table_mu": [0.3]}, "same number"),
    ({"friction_table_velocity_m_per_min": list(range(9)), "friction_table_mu": [0.2] * 9},
     "2..8"),
    ({"friction_table_velocity_m_per_min": [10, 5], "friction_table_mu": [0.3, 0.2]},
     "increasing"),
    ({"friction_table_velocity_m_per_min": [-1, 5], "friction_table_mu": [0.3, 0.2]},
     "increasing|negative value"),
    ({"friction_table_velocity_m_per_min": [0, 5], "friction_table_mu": [0.3, 2.5]}, "0..2"),
    ({"sliding_filter_um": 2.0}, "not used"),
    ({"friction_velocity": "sliding", "sliding_filter_um": 0.0}, "greater than 0"),
])
def test_friction_table_config_errors(contact, words):
    with pytest.raises(ConfigError, match=words) as e:
        parse_config(_cfg(**contact))
    assert "contact" in str(e.value)


def test_friction_table_at_the_cutting_speed():
    c = parse_config(_cfg(friction_table_velocity_m_per_min=[0, 60],
                          friction_table_mu=[0.5, 0.1]))
    assert c.friction_coefficient() == pytest.approx(0.3)
    assert c.friction_law() == "Coulomb, user table at the cutting speed"
    c = parse_config(_cfg())  # the bundled Rech et al. table: 0.18 at 30 m/min
    assert c.friction_coefficient() == pytest.approx(0.18)
    assert "Rech" in c.friction_law()


def _sliding_block(vc, table_v_m_s, table_mu, tau=None):
    """A 200 x 40 um elastic TC4 block, fixed at its bottom, its top 1 nm inside a flat
    tool face (clearance 0, flank normal (0, -1)) that slides over it in -x at ``vc``."""
    L, H = 200e-6, 40e-6
    nodes, conn = strip_mesh(20, 4, L, H)
    prm = _prm(table_v_m_s, table_mu)
    prm[layout.P_MS] = 100.0  # quasi-static: the friction's shear wave moves the nodes little
    prm[layout.P_R] = 2e-6
    prm[layout.P_NRX], prm[layout.P_NRY] = -1.0, 0.0
    prm[layout.P_NFX], prm[layout.P_NFY] = 0.0, -1.0
    prm[layout.P_VC] = vc
    prm[layout.P_CDAMP] = 1.0  # critically damped contact: the 1 nm overlap settles, no chatter
    # sliding-speed filter: 0.2 um of the 5 um travel
    prm[layout.P_SLIP_TAU] = 0.2e-6 / vc if tau is None else tau
    st = make_state(nodes, conn, nodes[:, 1] < 1e-15, elastic_tc4(), prm=prm,
                    tool_center=(-10e-6, H + 2e-6 - 1e-9))
    advance(st, 5e-6 / vc)  # 5 um of sliding
    cx, cy = st.tool[layout.T_GX], st.tool[layout.T_GY]
    out = []
    for n in np.flatnonzero(np.hypot(st.cfx, st.cfy) > 0):
        _, gnx, gny = P.tool_gap(st.x[n], st.y[n], cx, cy, -1.0, 0.0, 0.0, -1.0, 2e-6)
        fn = st.cfx[n] * gnx + st.cfy[n] * gny
        ft = -st.cfx[n] * gny + st.cfy[n] * gnx
        vt = -(st.vx[n] + vc) * gny + st.vy[n] * gnx
        out.append((abs(vt), abs(ft) / fn, st.vslip[n]))
    return np.array(out)


def test_the_engine_slides_against_the_table_at_the_sliding_speed():
    """A tool face sliding over a block at 0.5 and at 0.25 m/s with mu falling linearly
    from 0.5 at rest to 0.1 at 1 m/s (and the constant coefficient P_MU = 0.123 unused):
    every node of the top face is in contact and slides at about the tool's speed (within
    10 %: the elastic block shears a little); its filtered sliding speed (time constant
    0.2 um of the 5 um travel) is the tool's speed within 1 %, and it carries exactly
    (1e-9) the table's coefficient at that speed -- 0.3 and 0.4 (within 0.005)."""
    v_tab, mu_tab = [0.0, 1.0], [0.5, 0.1]
    for vc, mu_vc in ((0.5, 0.3), (0.25, 0.4)):
        r = _sliding_block(vc, v_tab, mu_tab)
        assert len(r) == 21
        assert np.allclose(r[:, 0], vc, rtol=0.1)
        assert np.allclose(r[:, 2], vc, rtol=0.01)
        assert np.allclose(r[:, 1], np.interp(r[:, 2], v_tab, mu_tab), rtol=1e-9)
        assert np.allclose(r[:, 1], mu_vc, atol=0.005)


def test_the_3d_slab_reads_the_table_at_the_sliding_speed():
    from robobore.cutting.fe.hex import layout3d
    from robobore.cutting.fe.models.slab3d import setup_slab3

    cfg = parse_config({"tool": {"rake_deg": 15, "clearance_deg": 2, "edge_radius_um": 20},
                        "cut": {"uncut_chip_thickness_um": 60, "cutting_speed_m_per_min": 30,
                                "length_mm": 0.05},
                        "contact": {"friction": "table", "friction_velocity": "sliding"},
                        "mesh": {"element_size_um": 20, "separation": "node_split",
                                 "frame": "workpiece"}})
    p = setup_slab3(cfg).state.prm
    v, mu = cfg.contact.table()
    assert p[layout3d.P_MUTAB_N] == v.size
    np.testing.assert_array_equal(p[layout3d.P_MUTAB_V:layout3d.P_MUTAB_V + v.size], v / 60.0)
    np.testing.assert_array_equal(p[layout3d.P_MUTAB_MU:layout3d.P_MUTAB_MU + v.size], mu)
    assert p[layout3d.P_SLIP_TAU] == pytest.approx(cfg.contact.sliding_filter_um * 1e-6 / 0.5)


def test_no_filter_time_constant_reads_the_raw_speed():
    """prm[P_SLIP_TAU] = 0 (the block test's state built by hand without it): the table is
    read at the node's unfiltered speed, no division by zero."""
    r = _sliding_block(0.5, [0.0, 1.0], [0.5, 0.1], tau=0.0)
    assert len(r) == 21 and np.all(np.isfinite(r))
    assert np.allclose(r[:, 1], np.interp(r[:, 2], [0.0, 1.0], [0.5, 0.1]), rtol=1e-9)
