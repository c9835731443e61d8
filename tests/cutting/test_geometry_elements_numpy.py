"""The compiled edge elements (the one chip geometry along the edge, which the dynamics'
process uses too) against the same discretisation written with numpy arrays from the
profile's formulas: nose arc, straight major and minor edges, linspace element boundaries,
Gauss-Legendre chip areas between radial levels."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robobore.cutting.geometry import (
    BoringInsert,
    edge_elements,
    trailing_intersection,
)


def _point(ins, s):
    """(zeta, drop, kappa_local) of the edge at arc lengths ``s``, by masks."""
    s = np.asarray(s, float)
    r, k, ke = ins.nose_radius_m, ins.kappa, ins.kappa_end
    zeta, drop, kl = np.empty_like(s), np.empty_like(s), np.empty_like(s)
    arc = (s >= -r * ke) & (s <= r * k)
    zeta[arc], drop[arc], kl[arc] = r * np.sin(s[arc] / r), r * (1 - np.cos(s[arc] / r)), s[arc] / r
    lead = s > r * k
    t = s[lead] - r * k
    zeta[lead] = r * math.sin(k) + t * math.cos(k)
    drop[lead] = r * (1 - math.cos(k)) + t * math.sin(k)
    kl[lead] = k
    trail = s < -r * ke
    t = -s[trail] - r * ke
    zeta[trail] = -r * math.sin(ke) - t * math.cos(ke)
    drop[trail] = r * (1 - math.cos(ke)) + t * math.sin(ke)
    kl[trail] = -ke
    return zeta, drop, kl


def _width(ins, d):
    """Tool profile width at drop ``d``: leading side minus trailing side."""
    r, k, ke = ins.nose_radius_m, ins.kappa, ins.kappa_end
    circ = np.sqrt(np.clip(r * r - (r - np.minimum(d, 2 * r)) ** 2, 0.0, None))
    d_lead, d_trail = r * (1 - math.cos(k)), r * (1 - math.cos(ke))
    if math.isclose(k, math.pi / 2):
        b = np.where(d <= d_lead, circ, r)
    else:
        b = np.where(d <= d_lead, circ, r * math.sin(k) + (d - d_lead) / math.tan(k))
    a = np.where(d <= d_trail, -circ, -(r * math.sin(ke) + (d - d_trail) / math.tan(ke)))
    return b - a


def _reference(ins, depth, f, n, n_quad, trailing, n_trailing):
    r, k, ke = ins.nose_radius_m, ins.kappa, ins.kappa_end
    d_arc = r * (1 - math.cos(k))
    s_end = (r * math.acos(1 - depth / r) if depth <= d_arc
             else r * k + (depth - d_arc) / math.sin(k))
    edges = np.linspace(0.0, s_end, n + 1)
    d_edges = np.minimum(_point(ins, edges)[1], depth)
    d_edges[-1] = depth
    s = 0.5 * (edges[1:] + edges[:-1])
    dS = np.diff(edges)
    xg, wg = np.polynomial.legendre.leggauss(n_quad)
    d1, d2 = d_edges[:-1, None], d_edges[1:, None]
    dd = 0.5 * (d1 + d2) + 0.5 * (d2 - d1) * xg[None, :]
    area_e = (0.5 * (d2 - d1)[:, 0]) * (np.minimum(f, _width(ins, dd)) * wg[None, :]).sum(axis=1)
    h, db = area_e / dS, dS.copy()
    n_tr = 0
    if trailing:
        z = -trailing_intersection(ins, depth, f)
        s_i = (-r * math.asin(min(z / r, 1.0)) if z <= r * math.sin(ke)
               else -(r * ke + (z - r * math.sin(ke)) / math.cos(ke)))
        nt = n_trailing or max(1, round(n * (-s_i) / s_end))
        s_c = -r * ke
        if s_i < s_c:
            L_str, L_arc = s_c - s_i, -s_c
            n_str = max(1, round(nt * L_str / (L_str + L_arc)))
            t_edges = np.concatenate([np.linspace(s_i, s_c, n_str + 1),
                                      np.linspace(s_c, 0.0, max(1, nt - n_str) + 1)[1:]])
        else:
            t_edges = np.linspace(s_i, 0.0, nt + 1)
        n_tr = t_edges.size - 1
        s = np.concatenate([0.5 * (t_edges[1:] + t_edges[:-1]), s])
        dS = np.concatenate([np.diff(t_edges), dS])
        h = np.concatenate([np.zeros(n_tr), h])
        db = np.concatenate([np.zeros(n_tr), db])
    zeta, drop, kl = _point(ins, s)
    return {"s": s, "zeta": zeta, "drop": drop, "kappa": kl, "h": h, "db": db, "dS": dS}, n_tr


@pytest.mark.parametrize("kappa_deg,end_deg", [(45.0, 5.0), (75.0, 15.0), (90.0, 5.0),
                                               (95.0, 30.0), (107.0, 3.0)])
@pytest.mark.parametrize("feed_m", [0.05e-3, 0.3e-3, 1.5e-3])
@pytest.mark.parametrize("trailing,n_trailing", [(True, None), (True, 7), (False, None)])
def test_edge_elements_equal_the_numpy_discretisation(kappa_deg, end_deg, feed_m, trailing,
                                                      n_trailing):
    """Depths inside the nose and beyond it, feeds whose trailing contact ends on the arc and
    on the straight minor edge, 24 and 40 elements, 16- and 5-point chip areas."""
    ins = BoringInsert(nose_radius_m=0.4e-3, approach_angle_deg=kappa_deg,
                       end_edge_angle_deg=end_deg)
    for depth in np.geomspace(5e-6, 0.05, 11):
        for n, n_quad in ((24, 16), (40, 5)):
            ref, n_tr = _reference(ins, float(depth), feed_m, n, n_quad, trailing, n_trailing)
            el = edge_elements(ins, float(depth), feed_m, n, n_quad, trailing_edge=trailing,
                               n_trailing=n_trailing, exact_area=False)
            assert el.n_trailing == n_tr
            for name, v in ref.items():
                got = getattr(el, name)
                assert got.shape == v.shape, name
                assert np.abs(got - v).max() <= 1e-12 * max(np.abs(v).max(), 1e-300), name
            area = float((ref["h"] * ref["db"]).sum())
            assert abs(el.area_elements - area) <= 1e-12 * area


@pytest.mark.parametrize("kappa_deg", [45.0, 90.0, 107.0])
def test_profile_point_and_width_equal_the_formulas(kappa_deg):
    """BoringInsert.point on both straight edges and the arc (a 2-D array keeps its shape), and
    the profile width between the tip and beyond twice the nose radius."""
    from robobore.cutting.geometry import _width_at_drop

    ins = BoringInsert(nose_radius_m=0.8e-3, approach_angle_deg=kappa_deg,
                       end_edge_angle_deg=20.0)
    s = np.linspace(-3e-3, 3e-3, 603).reshape(3, 201)
    zeta, drop, kl, curv = ins.point(s)
    for got, ref in zip((zeta, drop, kl), _point(ins, s), strict=True):
        assert got.shape == s.shape
        assert np.abs(got - ref).max() <= 1e-12 * np.abs(ref).max()
    arc = (s >= -0.8e-3 * ins.kappa_end) & (s <= 0.8e-3 * ins.kappa)
    assert np.array_equal(curv, np.where(arc, 1 / 0.8e-3, 0.0))
    d = np.linspace(0.0, 2.5e-3, 401).reshape(401, 1)
    w = _width_at_drop(ins, d)
    assert w.shape == d.shape
    assert np.abs(w - _width(ins, d)).max() <= 1e-12 * np.abs(_width(ins, d)).max()
    assert _width_at_drop(ins, np.array([0.0]))[0] == 0.0
