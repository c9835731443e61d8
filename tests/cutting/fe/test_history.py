"""The engines' shared end of step (robobore.cutting.fe.engine.history): the column layout of both
engines, the time averages and samples, and the stop conditions, on hand-made arrays."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robobore.cutting.fe.engine import chunk_loop as CL
from robobore.cutting.fe.engine import history as H
from robobore.cutting.fe.engine import kernels as K
from robobore.cutting.fe.engine import kernels3d as K3


def test_both_layouts_follow_the_history_column_order():
    c2 = H.columns(2, 6, 1)
    assert (K.H_T, K.H_FX, K.H_UX, K.H_NCONT, K.H_FX_RAKE) == (H.H_T, c2["force"], c2["disp"],
                                                                c2["ncont"], c2["split"])
    assert (K.H_FY, K.H_UY, K.H_FY_FLANK) == (K.H_FX + 1, K.H_UX + 1, K.H_FX_RAKE + 5)
    assert K.H_TIP_X == c2["tool"] and K.N_HIST == c2["n_hist"]
    c3 = H.columns(3, 0, 2)
    assert (K3.H_T, K3.H_FX, K3.H_UX, K3.H_NCONT) == (H.H_T, c3["force"], c3["disp"],
                                                      c3["ncont"])
    assert (K3.H_FZ, K3.H_UZ) == (K3.H_FX + 2, K3.H_UX + 2)
    assert (K3.H_TIPX, K3.H_THETA) == (c3["tool"], c3["tool"] + 1) and K3.N_HIST == c3["n_hist"]
    for mod, c in ((K, c2), (K3, c3)):
        e0 = c["energy"]
        assert (mod.H_EKIN, mod.H_EINT, mod.H_EPL, mod.H_EHG, mod.H_EFRIC, mod.H_EEXT,
                mod.H_EERO) == tuple(e0 + j for j in (H.HE_KIN, H.HE_INT, H.HE_PL, H.HE_HG,
                                                       H.HE_FRIC, H.HE_EXT, H.HE_ERO))


def test_an_engine_description_must_name_every_slot():
    with pytest.raises(ValueError, match="NDIM"):
        H.make_end_step(lambda f: f, {"NDIM": 2}, None, None)


def _state2(n_hist=3, sample_dt=1.0, t_end=10.0):
    """A 2D engine's small arrays: one node, one element, the tool at rest."""
    prm = np.zeros(K.N_PRM)
    prm[K.P_CFL] = 0.5
    prm[K.P_DTMIN] = 1e-3
    prm[K.P_SAMPLE_DT] = sample_dt
    prm[K.P_TEND] = t_end
    tool = np.zeros(K.N_TOOL)
    es = (np.array([2.0]), np.array([3.0]), np.array([4.0]), np.array([3.0]), np.array([5.0]),
          np.array([1.0]), np.array([0.5]), np.array([1], np.int8), np.array([0.25]),
          np.array([0.125]), np.array([0.0]), np.array([0.0]))
    return dict(ist=np.zeros(K.N_IST, np.int64), clock=np.zeros(3), prm=prm, tool=tool,
                en=np.zeros(K.N_EN), hacc=np.zeros(K.N_HIST),
                hist=np.full((n_hist, K.N_HIST), np.nan), es=es)


def _end(s, dt, fx=0.0, ncont=0, split=None, bad=-1, dtmin=1.0):
    split = np.zeros(6) if split is None else split
    s["clock"][1] = dt
    return CL._end_step(dt, bad, dtmin, fx, 0.0, 0.0, ncont, split, s["ist"], s["clock"],
                        s["prm"], s["tool"], s["en"], s["hacc"], s["hist"], s["es"])


def test_a_sample_holds_the_time_averages_the_tool_tip_and_the_energies():
    s = _state2()
    tool = s["tool"]
    split = np.arange(6.0)
    # two steps in the first sample interval (0.4 s, then 0.6 s) with different forces
    tool[K.T_FX], tool[K.T_UY], tool[K.T_GX], tool[K.T_UX] = 10.0, 1.0, 7.0, 0.5
    assert _end(s, 0.4, ncont=3, split=split)
    tool[K.T_FX] = 20.0
    s["en"][K.E_EXT] = 9.0
    assert _end(s, 0.6, ncont=1, split=2.0 * split)
    h = s["hist"][0]
    assert h[K.H_T] == 1.0 and s["ist"][K.I_SAMPLE] == 1 and s["ist"][K.I_STEP] == 2
    assert h[K.H_FX] == (0.4 * 10.0 + 0.6 * 20.0) / 1.0
    assert h[K.H_UY] == 1.0 and h[K.H_UX] == 0.5 and h[K.H_FY] == 0.0
    assert h[K.H_NCONT] == (0.4 * 3 + 0.6 * 1) / 1.0
    assert np.allclose(h[K.H_FX_RAKE:K.H_FX_RAKE + 6], 1.6 * split, rtol=1e-15)
    assert h[K.H_TIP_X] == 7.5
    assert h[K.H_EKIN] == 0.5 * 2.0 * (3.0 * 3.0 + 4.0 * 4.0)
    assert (h[K.H_EINT], h[K.H_EPL], h[K.H_EHG]) == (5.0, 1.0, 0.5)
    assert h[K.H_EFRIC] == 0.25 + 0.125 and h[K.H_EEXT] == 9.0 and h[K.H_EERO] == 0.0
    assert np.all(s["hacc"] == 0.0) and s["clock"][2] == 0.0
    assert s["clock"][0] == 1.0 and s["clock"][1] == 0.5  # the next step: cfl * dtmin
    assert np.all(np.isnan(s["hist"][1]))


def test_the_run_stops_at_its_end_time_with_the_energy_totals():
    s = _state2(t_end=0.5)
    assert not _end(s, 0.5)
    assert s["ist"][K.I_STATUS] == K.STATUS_DONE and s["en"][K.E_INT] == 5.0


@pytest.mark.parametrize("kw, status", [
    ({"fx": math.nan}, K.STATUS_NONFINITE),
    ({"dtmin": 1e-3}, K.STATUS_DT_COLLAPSE),
    ({"bad": 4}, K.STATUS_INVERTED),
    ({"dtmin": 1e30}, K.STATUS_NO_ELEMENTS),
])
def test_a_stopped_step_sets_its_status(kw, status):
    s = _state2()
    assert not _end(s, 0.1, **kw)
    assert s["ist"][K.I_STATUS] == status
    counted = status in (K.STATUS_NONFINITE, K.STATUS_DT_COLLAPSE)
    # the 2D engine does not count a step stopped by an inverted element or an empty mesh
    assert s["ist"][K.I_STEP] == int(counted) and s["clock"][0] == (0.1 if counted else 0.0)
    if status == K.STATUS_INVERTED:
        assert s["ist"][K.I_BADELEM] == 4
    assert np.all(np.isnan(s["hist"]))


def test_the_3d_engine_counts_a_step_stopped_by_an_inverted_element():
    prm = np.zeros(K3.N_PRM)
    prm[K3.P_CFL], prm[K3.P_SAMPLE_DT], prm[K3.P_TEND] = 0.5, 1.0, 10.0
    ist, clock = np.zeros(K3.N_IST, np.int64), np.zeros(3)
    hist = np.full((2, K3.N_HIST), np.nan)
    es = tuple(np.zeros(1) for _ in range(7)) + (np.ones(1, np.int8),) + tuple(
        np.zeros(1) for _ in range(4))
    ok = K3._end_step3(0.1, 2, 1.0, 0.0, 0.0, 0.0, 0, np.zeros(1), ist, clock, prm,
                       np.zeros(K3.N_TOOL), np.zeros(K3.N_EN), np.zeros(K3.N_HIST), hist, es)
    assert not ok and ist[K3.I_STATUS] == K3.STATUS_INVERTED and ist[K3.I_BADELEM] == 2
    assert ist[K3.I_STEP] == 1 and clock[0] == 0.1
