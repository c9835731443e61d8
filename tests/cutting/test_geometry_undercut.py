"""Approach angles up to 107.5 deg (undercut boring bars): chip area and the chip-thickness
distribution along the edge against an independent geometric computation.

The reference is a fine raster of the chip cross-section: the tool outline is built here as
a polygon from the insert's definition (nose arc of radius r tangent to the tip, major edge at
kappa to the feed axis, minor edge at kappa' on the trailing side), and a point of the
section (axial zeta, radial drop d, 0 <= d <= ap) is chip when it lies inside the tool at
the current pass and outside it at every earlier pass (the tool shifted back by k f,
k = 1, 2, ...). The module computes the same area by a 1-D integral and attributes it to the
edge by radial levels; the raster shares neither.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from matplotlib.path import Path as MplPath

from robobore.cutting.geometry import (
    BoringInsert,
    chip_area,
    edge_elements,
)
from robobore.errors import ConfigError
from robobore.io.sections import APPROACH_ANGLE_MAX_DEG


def _outline(r, kappa_deg, kappa_end_deg, far, n_arc=300):
    """Tool outline (zeta, drop) [m]: trailing far point, trailing edge and arc, tip, leading
    arc and edge, leading far point, closed at a large drop behind the edge."""
    k, ke = math.radians(kappa_deg), math.radians(kappa_end_deg)
    lead = [(r * math.sin(p), r * (1 - math.cos(p))) for p in np.linspace(0, k, n_arc)]
    trail = [(-r * math.sin(p), r * (1 - math.cos(p))) for p in np.linspace(0, ke, n_arc)]
    zl, dl = lead[-1]
    lead_far = (zl + far * math.cos(k), dl + far * math.sin(k))
    zt, dt = trail[-1]
    trail_far = (zt - far * math.cos(ke), dt + far * math.sin(ke))
    pts = [trail_far, *trail[::-1], *lead[1:], lead_far]
    big = max(lead_far[1], trail_far[1]) + far
    pts += [(lead_far[0], big), (trail_far[0], big)]
    return MplPath(np.asarray(pts))


def _raster(r, kappa_deg, kappa_end_deg, ap, f, n=700):
    k, ke = math.radians(kappa_deg), math.radians(kappa_end_deg)
    far = 2 * (ap + r) / min(math.sin(k), math.sin(ke))  # the edges well beyond the cut
    tool = _outline(r, kappa_deg, kappa_end_deg, far)
    z_lo = -(r + 3 * f)
    z_hi = r + f
    dz = (z_hi - z_lo) / n
    dd = ap / n
    z = z_lo + dz * (np.arange(n) + 0.5)
    d = dd * (np.arange(n) + 0.5)
    Z, D = np.meshgrid(z, d, indexing="ij")
    P = np.column_stack([Z.ravel(), D.ravel()])
    chip = tool.contains_points(P)
    # an earlier pass k reaches the raster while its trailing edge at level ap is ahead of it
    z_trail = -(r * math.sin(ke) + max(ap - r * (1 - math.cos(ke)), 0.0) / math.tan(ke))
    for j in range(1, int((z_hi - min(z_trail, z_lo)) / f) + 2):  # the tool k f back
        idx = np.flatnonzero(chip)
        if idx.size == 0:
            break
        chip[idx] = ~tool.contains_points(P[idx] + np.array([j * f, 0.0]))
    return chip.reshape(Z.shape), D, dz * dd


CASES = [(90.0, 30.0, 0.3e-3, 0.1e-3), (95.0, 30.0, 0.3e-3, 0.1e-3),
         (107.5, 30.0, 1.0e-3, 0.2e-3), (95.0, 30.0, 1.0e-3, 0.25e-3),
         (107.5, 5.0, 0.05e-3, 0.15e-3),
         # a cusp deeper than the nose (feed above r): the undercut edge bounds it
         (100.0, 20.0, 0.6e-3, 0.45e-3)]


@pytest.mark.parametrize(("kappa", "kappa_end", "ap", "f"), CASES)
def test_chip_area_and_distribution_against_a_raster(kappa, kappa_end, ap, f):
    r = 0.4e-3
    ins = BoringInsert(nose_radius_m=r, approach_angle_deg=kappa, end_edge_angle_deg=kappa_end)
    chip, D, cell = _raster(r, kappa, kappa_end, ap, f)
    a_ref = chip.sum() * cell
    e = edge_elements(ins, ap, f, n_elements=20)
    assert chip_area(ins, ap, f) == pytest.approx(a_ref, rel=0.01)
    assert e.area_elements == pytest.approx(a_ref, rel=0.01)
    # distribution along the edge: the raster's chip in each leading element's band of radial
    # levels (drop of its end points on the outline) against the element's h db
    lead = ~e.trailing
    s0, s1 = e.s[lead] - e.dS[lead] / 2, e.s[lead] + e.dS[lead] / 2
    k = math.radians(kappa)

    def drop_at(s):
        return np.where(s <= r * k, r * (1 - np.cos(np.minimum(s, r * k) / r)),
                        r * (1 - math.cos(k)) + (s - r * k) * math.sin(k))

    d0, d1 = np.minimum(drop_at(s0), ap), np.minimum(drop_at(s1), ap)
    d1[-1] = ap
    per_elem_ref = np.array([(chip & (D >= a) & (D < b)).sum() * cell for a, b in zip(d0, d1)])
    per_elem = e.h[lead] * e.db[lead]
    assert np.abs(per_elem - per_elem_ref).sum() <= 0.02 * a_ref
    # on the straight, fully covered part of the major edge: h = f sin(kappa)
    straight = (e.s[lead] > r * k) & (_width_ok(ins, e.drop[lead], f))
    if straight.any():
        assert np.allclose(e.h[lead][straight], f * math.sin(k), rtol=1e-6)


def _width_ok(ins, d, f):
    """Levels where the tool is wider than the feed (the chip slice is a full f long)."""
    r, k, ke = ins.nose_radius_m, ins.kappa, ins.kappa_end
    b = r * math.sin(k) + (d - r * (1 - math.cos(k))) / math.tan(k)
    a = -(r * math.sin(ke) + (d - r * (1 - math.cos(ke))) / math.tan(ke))
    return (b - a) > 1.05 * f


def test_undercut_insert_limits():
    BoringInsert(approach_angle_deg=APPROACH_ANGLE_MAX_DEG)
    with pytest.raises(ConfigError, match="107.5"):
        BoringInsert(approach_angle_deg=110.0)
    with pytest.raises(ConfigError, match="radians"):
        BoringInsert(approach_angle_deg=1.57)
    with pytest.raises(ConfigError, match="included angle"):
        BoringInsert(approach_angle_deg=107.5, end_edge_angle_deg=75.0)


@pytest.mark.parametrize("kappa", [60.0, 90.0, 100.0, 107.5])
def test_force_model_on_a_straight_edge_matches_the_hand_calculation(kappa):
    """A sharp-nosed insert (r = 1 um) deep in the cut is one straight edge at kappa: the
    shearing forces resolve as feed = A (-Kfc sin k + Krc cos k), radial = A (-Kfc cos k -
    Krc sin k), tangential = Ktc A with A = ap f minus the triangular cusp (edge
    coefficients 0); the undercut edge (kappa > 90 deg) included."""
    from robobore.cutting.forces import CuttingCoefficients, boring_forces

    c = CuttingCoefficients(Ktc=1.8e9, Krc=0.6e9, Kfc=0.3e9)
    ap, f = 1.0e-3, 0.1e-3
    res = boring_forces(BoringInsert(nose_radius_m=1e-6, approach_angle_deg=kappa,
                                     end_edge_angle_deg=30.0), ap, f, c, n_elements=200)
    k, ke = math.radians(kappa), math.radians(30.0)
    # the cusp between passes is the triangle between the minor edge and the previous
    # pass's major edge, width w(d) = d (cot k + cot k') at depth d (undercut: cot k < 0)
    A = ap * f - f * f / (2 * (1 / math.tan(k) + 1 / math.tan(ke)))
    assert res["chip_area_m2"] == pytest.approx(A, rel=2e-3)
    assert res["tangential_N"] == pytest.approx(c.Ktc * A, rel=2e-3)
    assert res["feed_N"] == pytest.approx(A * (-c.Kfc * math.sin(k) + c.Krc * math.cos(k)),
                                          rel=5e-3, abs=2e-3 * c.Ktc * A)
    assert res["radial_N"] == pytest.approx(A * (-c.Kfc * math.cos(k) - c.Krc * math.sin(k)),
                                            rel=5e-3, abs=2e-3 * c.Ktc * A)
