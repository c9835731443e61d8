"""The engines' shared end of step (robobore.cutting.fe.engine.history): the column layout of both
engines, the time averages and samples, and the stop conditions, on hand-made arrays."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robobore.cutting.fe.engine import chunk_loop as CL
from robobore.cutting.fe.engine import history as H
from robobore.cutting.fe.engine import kernels3d as K3
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.hex import layout3d, scalar3d


def test_both_layouts_follow_the_history_column_order():
    c2 = H.columns(2, 6, 1)
    assert (layout.H_T, layout.H_FX, layout.H_UX, layout.H_NCONT, layout.H_FX_RAKE) == (
        H.H_T, c2["force"], c2["disp"], c2["ncont"], c2["split"])
    assert (layout.H_FY, layout.H_UY, layout.H_FY_FLANK) == (
        layout.H_FX + 1, layout.H_UX + 1, layout.H_FX_RAKE + 5)
    assert layout.H_TIP_X == c2["tool"] and layout.N_HIST == c2["n_hist"]
    c3 = H.columns(3, 0, 2)
    assert (scalar3d.H_T, scalar3d.H_FX, scalar3d.H_UX, scalar3d.H_NCONT) == (
        H.H_T, c3["force"], c3["disp"], c3["ncont"])
    assert (scalar3d.H_FZ, scalar3d.H_UZ) == (scalar3d.H_FX + 2, scalar3d.H_UX + 2)
    assert (scalar3d.H_TIPX, scalar3d.H_THETA) == (c3["tool"], c3["tool"] + 1)
    assert scalar3d.N_HIST == c3["n_hist"]
    for mod, c in ((layout, c2), (scalar3d, c3)):
        e0 = c["energy"]
        assert (mod.H_EKIN, mod.H_EINT, mod.H_EPL, mod.H_EHG, mod.H_EFRIC, mod.H_EEXT,
                mod.H_EERO) == tuple(e0 + j for j in (H.HE_KIN, H.HE_INT, H.HE_PL, H.HE_HG,
                                                       H.HE_FRIC, H.HE_EXT, H.HE_ERO))


def test_an_engine_description_must_name_every_slot():
    with pytest.raises(ValueError, match="NDIM"):
        H.make_end_step(lambda f: f, {"NDIM": 2}, None, None)


def _state2(n_hist=3, sample_dt=1.0, t_end=10.0):
    """A 2D engine's small arrays: one node, one element, the tool at rest."""
    prm = np.zeros(layout.N_PRM)
    prm[layout.P_CFL] = 0.5
    prm[layout.P_DTMIN] = 1e-3
    prm[layout.P_SAMPLE_DT] = sample_dt
    prm[layout.P_TEND] = t_end
    tool = np.zeros(layout.N_TOOL)
    es = (np.array([2.0]), np.array([3.0]), np.array([4.0]), np.array([3.0]), np.array([5.0]),
          np.array([1.0]), np.array([0.5]), np.array([1], np.int8), np.array([0.25]),
          np.array([0.125]), np.array([0.0]), np.array([0.0]))
    return dict(ist=np.zeros(layout.N_IST, np.int64), clock=np.zeros(3), prm=prm, tool=tool,
                en=np.zeros(layout.N_EN), hacc=np.zeros(layout.N_HIST),
                hist=np.full((n_hist, layout.N_HIST), np.nan), es=es)


def _end(s, dt, fx=0.0, ncont=0, split=None, bad=-1, dtmin=1.0):
    split = np.zeros(6) if split is None else split
    s["clock"][1] = dt
    return CL._end_step(dt, (dtmin, bad), (fx, 0.0, 0.0, ncont), split, s["ist"], s["clock"],
                        s["prm"], s["tool"], s["en"], s["hacc"], s["hist"], s["es"])


def test_a_sample_holds_the_time_averages_the_tool_tip_and_the_energies():
    s = _state2()
    tool = s["tool"]
    split = np.arange(6.0)
    # two steps in the first sample interval (0.4 s, then 0.6 s) with different forces
    tool[layout.T_FX], tool[layout.T_UY], tool[layout.T_GX], tool[layout.T_UX] = 10.0, 1.0, 7.0, 0.5
    assert _end(s, 0.4, ncont=3, split=split)
    tool[layout.T_FX] = 20.0
    s["en"][layout.E_EXT] = 9.0
    assert _end(s, 0.6, ncont=1, split=2.0 * split)
    h = s["hist"][0]
    assert h[layout.H_T] == 1.0 and s["ist"][layout.I_SAMPLE] == 1 and s["ist"][layout.I_STEP] == 2
    assert h[layout.H_FX] == (0.4 * 10.0 + 0.6 * 20.0) / 1.0
    assert h[layout.H_UY] == 1.0 and h[layout.H_UX] == 0.5 and h[layout.H_FY] == 0.0
    assert h[layout.H_NCONT] == (0.4 * 3 + 0.6 * 1) / 1.0
    assert np.allclose(h[layout.H_FX_RAKE:layout.H_FX_RAKE + 6], 1.6 * split, rtol=1e-15)
    assert h[layout.H_TIP_X] == 7.5
    assert h[layout.H_EKIN] == 0.5 * 2.0 * (3.0 * 3.0 + 4.0 * 4.0)
    assert (h[layout.H_EINT], h[layout.H_EPL], h[layout.H_EHG]) == (5.0, 1.0, 0.5)
    assert h[layout.H_EFRIC] == 0.25 + 0.125 and h[layout.H_EEXT] == 9.0 and h[layout.H_EERO] == 0.0
    assert np.all(s["hacc"] == 0.0) and s["clock"][2] == 0.0
    assert s["clock"][0] == 1.0 and s["clock"][1] == 0.5  # the next step: cfl * dtmin
    assert np.all(np.isnan(s["hist"][1]))


def test_the_run_stops_at_its_end_time_with_the_energy_totals():
    s = _state2(t_end=0.5)
    assert not _end(s, 0.5)
    assert s["ist"][layout.I_STATUS] == layout.STATUS_DONE and s["en"][layout.E_INT] == 5.0


@pytest.mark.parametrize("kw, status", [
    ({"fx": math.nan}, layout.STATUS_NONFINITE),
    ({"dtmin": 1e-3}, layout.STATUS_DT_COLLAPSE),
    ({"bad": 4}, layout.STATUS_INVERTED),
    ({"dtmin": 1e30}, layout.STATUS_NO_ELEMENTS),
])
def test_a_stopped_step_sets_its_status(kw, status):
    s = _state2()
    assert not _end(s, 0.1, **kw)
    assert s["ist"][layout.I_STATUS] == status
    counted = status in (layout.STATUS_NONFINITE, layout.STATUS_DT_COLLAPSE)
    # the 2D engine does not count a step stopped by an inverted element or an empty mesh
    assert s["ist"][layout.I_STEP] == int(counted) and s["clock"][0] == (0.1 if counted else 0.0)
    if status == layout.STATUS_INVERTED:
        assert s["ist"][layout.I_BADELEM] == 4
    assert np.all(np.isnan(s["hist"]))


def test_the_3d_engine_counts_a_step_stopped_by_an_inverted_element():
    prm = np.zeros(layout3d.N_PRM)
    prm[layout3d.P_CFL], prm[layout3d.P_SAMPLE_DT], prm[layout3d.P_TEND] = 0.5, 1.0, 10.0
    ist, clock = np.zeros(layout.N_IST, np.int64), np.zeros(3)
    hist = np.full((2, scalar3d.N_HIST), np.nan)
    es = tuple(np.zeros(1) for _ in range(7)) + (np.ones(1, np.int8),) + tuple(
        np.zeros(1) for _ in range(4))
    ok = K3._end_step3(0.1, (1.0, 2), (0.0, 0.0, 0.0, 0), np.zeros(1), ist, clock, prm,
                       np.zeros(scalar3d.N_TOOL), np.zeros(layout.N_EN),
                       np.zeros(scalar3d.N_HIST), hist, es)
    assert not ok and ist[layout.I_STATUS] == layout.STATUS_INVERTED and ist[layout.I_BADELEM] == 2
    assert ist[layout.I_STEP] == 1 and clock[0] == 0.1
