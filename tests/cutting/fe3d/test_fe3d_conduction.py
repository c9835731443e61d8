"""Heat conduction of the 3D engine (cutting/fe/physics/thermal3d.py): the face table, a 1D
diffusion against the analytic solution, exact heat conservation, the bound of the explicit update,
conduction across tied (not parted) faces of node splitting, the thermal contact with the
insert, and the boring model with and without conduction."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robobore.cutting.fe.ale.groups3d import groups3_of
from robobore.cutting.fe.config.boring3d import parse_boring_config
from robobore.cutting.fe.engine.chunk_driver import energy_error
from robobore.cutting.fe.engine.state3d import advance3, box_mesh, make_state3, split_node_layer
from robobore.cutting.fe.hex import layout3d
from robobore.cutting.fe.models.boring3d import setup_boring
from robobore.cutting.fe.physics.thermal3d import (
    conduct3,
    face_neighbours,
    tool_heat3,
)
from robobore.errors import ConfigError
from robobore.material import load_material

TC4 = load_material("TC4")
RCP = TC4.rho * TC4.cp
KCOND = TC4.k


def _bar(nx: int, le: float, twin_row: int | None = None):
    nodes, conn, idx = box_mesh(nx, 2, 2, nx * le, 2 * le, 2 * le)
    fixed = np.zeros(len(nodes), np.int64)
    twin = None
    if twin_row is not None:
        nodes, conn, fixed, twin = split_node_layer(nodes, conn, fixed, idx, twin_row)
    return make_state3(nodes, conn, fixed, TC4, twin=twin)


def _conduct(st, dt_th):
    nodes, cells, elems, _, contact = groups3_of(st)
    conduct3(nodes, cells, elems, contact, st.tbuf, KCOND, RCP, dt_th)


def _heat_groups(st):
    # the groups of tool_heat3 before theat: nodes, ncorner, cells, elems, contact
    nodes, cells, elems, _, contact = groups3_of(st)
    return nodes, st.ncorner, cells, elems, contact


def _heat(st) -> float:
    return float(np.sum(RCP * st.vol0 * st.temp))


def test_face_table_of_a_box():
    nodes, conn, _ = box_mesh(3, 4, 5, 3.0, 4.0, 5.0)
    enbr = face_neighbours(conn)
    assert enbr.shape == (60, 6)
    # free faces = the box's surface: 2 (4*5 + 3*5 + 3*4)
    assert int(np.sum(enbr == -1)) == 2 * (20 + 15 + 12)
    assert not np.any(enbr <= -2)
    for e in range(60):  # symmetric: my neighbour across a face has me across one of its own
        for nb in enbr[e][enbr[e] >= 0]:
            assert e in enbr[nb]
    with pytest.raises(ValueError, match="more than two"):
        face_neighbours(np.vstack([conn, conn[:1]]))


def test_face_table_marks_parting_faces():
    nodes, conn, idx = box_mesh(4, 3, 2, 4.0, 3.0, 2.0)
    fixed = np.zeros(len(nodes), np.int64)
    nodes, conn, fixed, twin = split_node_layer(nodes, conn, fixed, idx, 1)
    enbr = face_neighbours(conn, twin)
    # the parting layer j = 1: one face per (i, k) element column, seen from both sides
    assert int(np.sum(enbr <= -2)) == 2 * 4 * 2
    # without the twins the two sides are free surfaces
    assert int(np.sum(face_neighbours(conn) == -1)) == int(np.sum(enbr < 0))


def test_step_diffuses_as_the_analytic_solution_and_conserves_heat():
    """A bar of 80 elements, step of 100 K at its middle: after t the finite-volume solution
    matches T = T0 + 50 (1 + erf(x / (2 sqrt(alpha t)))) (the bar's ends are ~6 diffusion
    lengths away); heat is conserved to rounding."""
    le = 2e-6
    nx = 80
    st = _bar(nx, le)
    cx = np.array([np.mean(st.x[c]) for c in st.conn])
    x0 = 0.5 * nx * le
    st.temp[:] = np.where(cx > x0, 400.0, 300.0)
    q0 = _heat(st)
    alpha = KCOND / RCP
    dt_th = 0.1 * le * le / alpha  # well inside the explicit limit le^2 / (2 alpha)
    t = 0.0
    while math.sqrt(alpha * t) < 6 * le:
        _conduct(st, dt_th)
        t += dt_th
    exact = 300.0 + 50.0 * (1.0 + np.array([math.erf((x - x0) / (2 * math.sqrt(alpha * t)))
                                            for x in cx]))
    assert np.max(np.abs(st.temp - exact)) < 1.0  # K, of a 100 K step (finite volumes, le^2)
    assert abs(_heat(st) / q0 - 1.0) < 1e-13


def test_huge_step_stays_bounded():
    """The conductance cap keeps the explicit update a convex combination at any dt_th."""
    st = _bar(10, 5e-6)
    rng = np.random.default_rng(1)
    st.temp[:] = 300.0 + 500.0 * rng.random(st.temp.size)
    lo, hi = st.temp.min(), st.temp.max()
    q0 = _heat(st)
    for _ in range(20):
        _conduct(st, 1.0)  # 1 s: ~1e5 explicit limits
        assert st.temp.min() >= lo - 1e-9 and st.temp.max() <= hi + 1e-9
    assert abs(_heat(st) / q0 - 1.0) < 1e-13
    assert st.temp.max() - st.temp.min() < 0.3 * (hi - lo)  # and it does mix


@pytest.mark.parametrize("tied", [True, False])
def test_heat_crosses_a_parting_face_until_its_nodes_part(tied):
    st = _bar(2, 5e-6, twin_row=1)
    below = np.array([np.mean(st.y[c]) for c in st.conn]) < 5e-6
    st.temp[:] = np.where(below, 300.0, 500.0)
    if not tied:
        st.pairs[:, 1] = 0
    _conduct(st, 1e-6)
    moved = np.abs(st.temp - np.where(below, 300.0, 500.0)).max()
    assert bool(moved > 1.0) is tied


def test_frictional_heat_and_contact_with_the_cold_insert():
    """A node's frictional dissipation heats its elements by eta of it; a node in contact
    loses h A (T - T_tool) dt to the insert (A: a quarter of each free face round it, in
    proportion to its other nodes in contact)."""
    le = 10e-6
    st = _bar(2, le)
    n_all = st.x.size
    top = np.flatnonzero(np.isclose(st.y, 2 * le))  # the top face's 3 x 3 nodes
    mid = top[np.argmin((st.x[top] - le) ** 2 + (st.z[top] - le) ** 2)]
    # frictional heat only
    st.fric[mid] = 1e-6  # J
    q0 = _heat(st)
    tool_heat3(*_heat_groups(st), st.theat, RCP, 0.0, 0.5, 293.0, 1e-7)
    assert _heat(st) - q0 == pytest.approx(0.5e-6, rel=1e-12)
    # the second pass books only new dissipation
    q1 = _heat(st)
    tool_heat3(*_heat_groups(st), st.theat, RCP, 0.0, 0.5, 293.0, 1e-7)
    assert _heat(st) == pytest.approx(q1, rel=1e-15)
    # contact: the whole top face touches a 293 K insert, the block at 800 K
    st.temp[:] = 800.0
    st.cf[top, 1] = -1.0
    hc, dt = 1e5, 1e-9
    q2 = _heat(st)
    tool_heat3(*_heat_groups(st), st.theat, RCP, hc, 0.0, 293.0, dt)
    area = (2 * le) ** 2  # every top-face node in contact: the whole face exchanges (the
    # side faces touch along an edge only: no area)
    assert q2 - _heat(st) == pytest.approx(hc * area * (800.0 - 293.0) * dt, rel=1e-12)
    # one corner node out of contact: the top face element at that corner touches over a
    # triangle (half its area)
    corner = top[np.argmin(st.x[top] + st.z[top])]
    st.cf[corner, 1] = 0.0
    st.temp[:] = 800.0
    q3 = _heat(st)
    tool_heat3(*_heat_groups(st), st.theat, RCP, hc, 0.0, 293.0, dt)
    area = 3.5 * le * le
    assert q3 - _heat(st) == pytest.approx(hc * area * (800.0 - 293.0) * dt, rel=1e-12)
    assert n_all == st.x.size


def _boring(conduction: bool):
    d = {"cut": {"depth_of_cut_mm": 0.05, "feed_mm_per_rev": 0.15, "speed_rpm": 300.0,
                 "cut_length_mm": 0.05},
         "mesh": {"element_size_um": 16.6, "frame": "workpiece", "ahead_mm": 0.03},
         "solver": {"mass_scaling": 400.0, "n_samples": 20, "heat_conduction": conduction}}
    return setup_boring(parse_boring_config(d))


def test_boring_run_conducts_heat_out_of_the_shear_zone():
    """The paper's boring condition on a coarse mesh, with and without conduction: the
    conducting run passes heat on (peak temperature lower, more elements warmed), keeps its
    energy balance, and its conduction clock follows the run."""
    runs = {}
    for cond in (False, True):
        s = _boring(cond)
        st = s.state
        assert bool(st.prm[layout3d.P_COND_EVERY] > 0) is cond
        advance3(st, s.t_end)
        t_room = TC4.T_room
        runs[cond] = (float(st.temp.max()), int(np.sum(st.temp > t_room + 1.0)),
                      energy_error(st.en), float(st.prm[layout3d.P_COND_T]), st.time,
                      float(st.clock[1]))
    (pk_a, warm_a, err_a, *_), (pk_c, warm_c, err_c, tc, t, dt) = runs[False], runs[True]
    assert pk_c < pk_a
    assert warm_c > warm_a
    assert err_c < 0.1 and err_a < 0.1
    assert 0 <= t - tc < 10.5 * dt  # the last pass within the last 10 steps


def test_bad_thermal_keys_name_the_key():
    d = {"cut": {"depth_of_cut_mm": 0.05, "feed_mm_per_rev": 0.15, "speed_rpm": 300.0},
         "mesh": {"element_size_um": 16.6}, "solver": {"conduction_interval": 0}}
    with pytest.raises(ConfigError, match="conduction_interval"):
        parse_boring_config(d)
