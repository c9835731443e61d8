"""Thermal contact of the 2D engine: conduction across a tied parting line, frictional heat
into the workpiece, and the tool as a heat sink behind an interface conductance.

References: the 1D temperature step T = T0 + dT/2 erfc((y - y0) / (2 sqrt(alpha t)))
(Carslaw & Jaeger 1959, sec. 2.4) for conduction across the parting line; the heat balances
are exact identities of the finite-volume update (tolerance 1e-12 relative, round-off).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import strip_mesh

from robobore.cutting.fe.config.orthogonal import parse_config
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.engine.chunk_driver import advance
from robobore.cutting.fe.engine.chunk_loop import Phases
from robobore.cutting.fe.engine.groups2d import groups_of
from robobore.cutting.fe.engine.state2d import default_prm, make_state, parting_edges
from robobore.cutting.fe.mesh.orthogonal import _split_nodes
from robobore.cutting.fe.models.orthogonal import setup_orthogonal
from robobore.cutting.fe.physics import thermal2d
from robobore.errors import ConfigError
from robobore.material import load_material

TC4 = load_material("TC4")
RCP = TC4.rho * TC4.cp


def _split_column(ny: int = 160, lx: float = 5e-6, ly: float = 8e-4):
    """A one-element-wide column, its nodes doubled on the middle line y = ly / 2."""
    nodes, conn = strip_mesh(1, ny, lx, ly)
    j = ny // 2
    line = np.array([j * 2, j * 2 + 1])
    above = np.arange(j, ny)
    nodes, twin = _split_nodes(nodes, conn, line, above)
    return nodes, conn, twin, 0.5 * ly


def _step_state(nodes, conn, twin, y0, t0k, dT):
    prm = default_prm()
    prm[layout.P_MS] = 1e6  # large mechanical step; the thermal mass is never scaled
    prm[layout.P_COND_EVERY] = 1
    st = make_state(nodes, conn, np.zeros(nodes.shape[0], bool), TC4, prm=prm, twin=twin,
                    phases=Phases(conduction=True))
    yc = st.y[conn].mean(axis=1)
    st.temp[:] = np.where(yc > y0, t0k + dT, t0k)
    return st, yc


def test_parting_edges_pair_the_elements_across_the_line():
    nodes, conn, twin, y0 = _split_column(ny=8, ly=8e-5)
    pp = parting_edges(conn, twin)
    assert pp.shape == (1, 4)
    e1, e2, na, nb = pp[0]
    yc = nodes[conn].mean(axis=1)[:, 1]
    assert {bool(yc[e1] > y0), bool(yc[e2] > y0)} == {True, False}
    # the nodes are the first element's, on the line, and doubled
    assert set(conn[e1]) >= {na, nb}
    assert np.allclose(nodes[[na, nb], 1], y0)
    assert twin[na] >= 0 and twin[nb] >= 0
    assert parting_edges(conn, None).shape == (0, 4)


def test_heat_crosses_a_tied_parting_line_as_in_a_continuous_body():
    """Temperature step on the parting line of a split column: with the pairs tied the
    result is the erfc solution (tolerance 2 % of dT, as the continuous strip in
    test_element); heat conserved to 1e-12. Released pairs are a free (adiabatic) surface:
    the cold half stays exactly cold."""
    from scipy.special import erfc

    nodes, conn, twin, y0 = _split_column()
    t0k, dT = 293.0, 400.0
    st, yc = _step_state(nodes, conn, twin, y0, t0k, dT)
    assert st.ppair.shape[0] == 1
    heat0 = np.sum(st.temp * st.area0)
    alpha = TC4.k / RCP
    t_end = (40e-6) ** 2 / alpha
    advance(st, t_end, chunk_steps=10**6)
    exact = t0k + 0.5 * dT * erfc((y0 - yc) / (2.0 * math.sqrt(alpha * st.time)))
    assert np.max(np.abs(st.temp - exact)) < 0.02 * dT
    assert np.sum(st.temp * st.area0) == pytest.approx(heat0, rel=1e-12)
    # released pairs: nothing crosses
    st2, yc2 = _step_state(nodes, conn, twin, y0, t0k, dT)
    st2.tied[:] = 0
    advance(st2, t_end, chunk_steps=10**6)
    assert np.all(st2.temp[yc2 < y0] == t0k)
    assert np.sum(st2.temp * st2.area0) == pytest.approx(heat0, rel=1e-12)


def _block(nx=4, ny=2, lx=40e-6, ly=20e-6, temp=800.0):
    nodes, conn = strip_mesh(nx, ny, lx, ly)
    st = make_state(nodes, conn, np.zeros(nodes.shape[0], bool), TC4, prm=default_prm())
    st.temp[:] = temp
    # centroids and areas, as conduct() leaves them for the thermal contact
    thermal2d.conduct(st.conn, st.x, st.y, st.alive, st.enbr, st.temp, st.tbuf, 0.0, RCP, 0.0)
    return st


def _heat(st):
    return float(np.sum(RCP * st.tbuf[:, 2] * st.temp))


def _tool_heat(st, hc, eta, t_tool, dt):
    nodes, quads, state, _out, contact, _ale = groups_of(st)
    thermal2d.tool_heat(nodes, quads, state, contact, st.enbr, st.fheat, st.tbuf, st.tcq, RCP,
                        (hc, eta, t_tool, dt))


def test_frictional_heat_goes_into_the_workpiece_once():
    """A fraction eta of the frictional dissipation booked on the nodes heats their
    elements (exactly, 1e-12), and only what was booked since the last call."""
    st = _block()
    top = np.where(np.isclose(st.y, 20e-6))[0]
    st.fric[top] = np.linspace(1e-4, 5e-4, top.size)  # J per m of width
    h0 = _heat(st)
    _tool_heat(st, 0.0, 0.3, 293.0, 1e-7)
    assert _heat(st) - h0 == pytest.approx(0.3 * st.fric.sum(), rel=1e-12)
    assert np.all(st.temp > 800.0 - 1e-9)
    h1 = _heat(st)
    _tool_heat(st, 0.0, 0.3, 293.0, 1e-7)
    assert _heat(st) == h1
    st.fric[top[0]] += 2e-4
    _tool_heat(st, 0.0, 0.3, 293.0, 1e-7)
    assert _heat(st) - h1 == pytest.approx(0.3 * 2e-4, rel=1e-12)


def test_tool_conductance_draws_hc_L_dT_from_the_contact():
    """All nodes of the top surface in contact: the heat drawn in dt is hc * L * (T_tool -
    T) * dt with L the surface length (1e-12). Nodes not in contact exchange nothing; a huge
    conductance is capped and cannot cool below the tool."""
    st = _block()
    top = np.where(np.isclose(st.y, 20e-6))[0]
    st.cfy[top] = -1.0  # contact forces on the workpiece
    h0 = _heat(st)
    hc, dt = 1e5, 1e-7
    _tool_heat(st, hc, 0.5, 293.0, dt)
    assert _heat(st) - h0 == pytest.approx(hc * 40e-6 * (293.0 - 800.0) * dt, rel=1e-12)
    assert np.all(st.temp[:4] == 800.0)  # the bottom row shares no node with the surface
    # only the middle three top nodes in contact: the two edges between them, L = 20 um
    st = _block()
    st.cfy[top[1:4]] = -1.0
    h0 = _heat(st)
    _tool_heat(st, hc, 0.5, 293.0, dt)
    assert _heat(st) - h0 == pytest.approx(hc * 20e-6 * (293.0 - 800.0) * dt, rel=1e-12)
    # stability cap: a very large conductance does not overshoot the tool temperature
    st = _block()
    st.cfy[top] = -1.0
    for _ in range(50):
        _tool_heat(st, 1e12, 0.5, 293.0, 1e-3)
    assert np.all(st.temp >= 293.0 - 1e-9)
    assert np.min(st.temp) < 300.0


def _short_cut_cfg(**contact):
    return parse_config({
        "material": {"name": "TC4"},
        "tool": {"rake_deg": 15.0, "clearance_deg": 2.0, "edge_radius_um": 20.0},
        "cut": {"uncut_chip_thickness_um": 60.0, "cutting_speed_m_per_min": 30.0,
                "length_mm": 0.05},
        "contact": {"friction": 0.18, **contact},
        "parameters": "a_priori",
        "mesh": {"frame": "workpiece", "element_size_um": 15.0, "separation": "node_split",
                 "separation_height_um": 5.0},
        "solver": {"mass_scaling": 100.0, "heat_conduction": True},
    })


def test_config_keys_reach_the_kernel_and_are_checked():
    su = setup_orthogonal(_short_cut_cfg(thermal_conductance_W_per_m2K=2e5,
                                         friction_heat_fraction=0.7, tool_temperature_K=400.0))
    p = su.state.prm
    assert (p[layout.P_HC], p[layout.P_FHEAT], p[layout.P_TTOOL]) == (2e5, 0.7, 400.0)
    assert su.state.ppair.shape[0] > 0
    su = setup_orthogonal(_short_cut_cfg())
    assert su.state.prm[layout.P_TTOOL] == TC4.T_room
    for key, value in (("friction_heat_fraction", 1.5), ("thermal_conductance_W_per_m2K", -1.0),
                       ("tool_temperature_K", 0.0)):
        with pytest.raises(ConfigError) as ei:
            _short_cut_cfg(**{key: value})
        assert f"contact.{key}" in str(ei.value)


def test_the_tool_sink_cools_the_cut():
    """A short cut with conduction: the tool as a strong heat sink (1e7 W/m2K, all
    frictional heat into the tool) leaves the workpiece with less heat than an adiabatic
    tool that takes none of the frictional heat (all of it into the workpiece)."""
    from robobore.cutting.fe.models.orthogonal import run_orthogonal

    def heat(**contact):
        su = setup_orthogonal(_short_cut_cfg(**contact))
        run_orthogonal(su)
        st = su.state
        live = st.alive == 1
        return float(np.sum((st.temp[live] - TC4.T_room) * st.area0[live]))

    hot = heat(thermal_conductance_W_per_m2K=0.0, friction_heat_fraction=1.0)
    cold = heat(thermal_conductance_W_per_m2K=1e7, friction_heat_fraction=0.0)
    assert cold < 0.95 * hot
