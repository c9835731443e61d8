"""Boring chip geometry: chip area and local chip thickness (Atabey et al. 2003; Kaymakci 2012)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from robobore.cutting.geometry import (
    BoringInsert,
    chip_area,
    edge_elements,
    scallop_area,
    trailing_intersection,
)
from robobore.errors import ConfigError


def test_area_is_ap_times_f_when_scallop_negligible():
    """Fully engaged edge, f << r: A = ap f (textbook), here within 3e-4 (scallop f^2/(12 r ap))."""
    ins = BoringInsert(nose_radius_m=1.2e-3, approach_angle_deg=75.0)
    ap, f = 1.0e-3, 0.05e-3
    assert chip_area(ins, ap, f) == pytest.approx(ap * f, rel=3e-4)


def test_scallop_closed_form():
    """Cusp left by a round nose, feed inside the nose: the material above the tip level per
    feed period is integral of x^2/(2r) over [-f/2, f/2] = f^3 / (24 r) (parabolic arc)."""
    ins = BoringInsert(nose_radius_m=0.8e-3)
    f = 0.1e-3
    assert scallop_area(ins, f) == pytest.approx(f**3 / (24 * 0.8e-3), rel=2e-3)


def test_straight_edge_thickness_is_f_sin_kappa():
    """On the straight major edge the local chip thickness is f sin(kappa_r) (exact)."""
    ins = BoringInsert(nose_radius_m=0.2e-3, approach_angle_deg=60.0)
    el = edge_elements(ins, 2e-3, 0.1e-3, 200)
    straight = np.isclose(el.kappa, math.radians(60.0))
    # away from the nose the thickness is the straight-edge value
    far = straight & (el.drop > 0.5e-3)
    assert far.sum() > 20
    assert np.allclose(el.h[far], 0.1e-3 * math.sin(math.radians(60.0)), rtol=1e-6)


def test_depth_inside_nose_uses_arc_only():
    ins = BoringInsert(nose_radius_m=0.8e-3, approach_angle_deg=90.0)
    el = edge_elements(ins, 0.05e-3, 0.15e-3, 40)
    lead, tr = ~el.trailing, el.trailing
    assert np.all((el.kappa[lead] >= 0) & (el.kappa[lead] < math.pi / 2))
    # the trailing side reaches just past the arc (r sin 5 deg = 69.7 um < f/2) onto the
    # 5 deg minor edge
    assert np.all((el.kappa[tr] < 0) & (el.kappa[tr] >= -math.radians(5.0) - 1e-15))
    assert np.all(el.drop <= 0.05e-3 + 1e-12)
    assert el.h.max() < 0.15e-3


@settings(max_examples=40, deadline=None)
@given(
    r=st.floats(0.2e-3, 1.6e-3),
    kappa=st.floats(45.0, 90.0),
    kend=st.floats(2.0, 30.0),
    ap=st.floats(0.02e-3, 2e-3),
    f=st.floats(0.02e-3, 0.4e-3),
)
def test_area_properties(r, kappa, kend, ap, f):
    """Properties: A = ap f - scallop (exact identity, 1e-3, when the cusp lies below the
    pre-bore surface); A <= ap f (1e-4, quadrature); elements sum to A (0.5 %, two
    independent quadratures); local thickness never exceeds the feed; widths positive."""
    ins = BoringInsert(nose_radius_m=r, approach_angle_deg=kappa, end_edge_angle_deg=kend)
    A = chip_area(ins, ap, f)
    S = scallop_area(ins, f)
    assert A <= ap * f * (1 + 1e-4)  # quadrature error at the kappa = 90 deg corner ~ 4e-5
    z = np.linspace(-f, 0.0, 4001)
    cusp = np.max(np.minimum(ins.drop(z), ins.drop(z + f)))
    if cusp <= ap:  # the whole cusp lies below the pre-bore surface
        assert A + S == pytest.approx(ap * f, rel=1e-3)
    el = edge_elements(ins, ap, f, 60)
    assert el.area_elements == pytest.approx(A, rel=5e-3)
    assert np.all(el.h <= f * (1 + 1e-9)) and np.all(el.db >= 0)
    # trailing side of the nose: rubbing only, chip identity unchanged, ends on the
    # intersection with the previous pass (or the pre-bore surface): the contact gap there
    # is zero (1e-12 m, bisection to f 2^-80), and the edge is continuous up to the tip
    lead = edge_elements(ins, ap, f, 60, trailing_edge=False)
    assert el.area_elements == lead.area_elements
    tr = el.trailing
    assert el.n_trailing >= 1 and np.all(el.h[tr] == 0) and np.all(el.db[tr] == 0)
    assert np.all(el.kappa[tr] < 0) and np.all(el.kappa[~tr] >= 0)
    assert np.all(np.diff(el.s) > 0) and np.all(el.dS > 0)
    zi = el.trailing_end_zeta_m
    assert -f < zi < 0
    gap = min(ap, float(ins.drop(np.array([zi + f]))[0])) - float(ins.drop(np.array([zi]))[0])
    assert abs(gap) < 1e-12
    assert el.trailing_length == pytest.approx(-(el.s[0] - 0.5 * el.dS[0]), rel=1e-12)
    assert el.s[el.n_trailing - 1] + 0.5 * el.dS[el.n_trailing - 1] == pytest.approx(0, abs=1e-15)
    assert el.leading_length == pytest.approx(lead.engaged_length, rel=1e-12)


@pytest.mark.parametrize("r_mm, f_mm, ap_mm", [(0.4, 0.15, 0.05), (0.8, 0.3, 0.1),
                                               (0.2, 0.05, 0.5), (1.2, 0.1, 2.0)])
def test_trailing_length_of_a_round_nose(r_mm, f_mm, ap_mm):
    """Feed inside the nose arc (end-edge angle 60 deg, so the arc reaches past -f/2): the
    current arc meets the previous pass's at zeta = -f/2 and the engaged trailing arc is
    r asin(f / (2 r)) long (exact; 1e-9 relative, bisection)."""
    r, f, ap = r_mm * 1e-3, f_mm * 1e-3, ap_mm * 1e-3
    ins = BoringInsert(nose_radius_m=r, approach_angle_deg=75.0, end_edge_angle_deg=60.0)
    el = edge_elements(ins, ap, f, 40)
    assert el.trailing_end_zeta_m == pytest.approx(-f / 2, rel=1e-9)
    assert el.trailing_length == pytest.approx(r * math.asin(f / (2 * r)), rel=1e-9)
    assert el.engaged_length == pytest.approx(el.leading_length + el.trailing_length, rel=1e-12)
    # element count in proportion to the length (leading 40), at least 1
    assert el.n_trailing == max(1, round(40 * el.trailing_length / el.leading_length))


def test_trailing_intersection_on_the_minor_edge():
    """Small end-edge angle (5 deg, the FE runs' CCMT-type insert, r 0.4 mm) at the paper's
    feed 0.15 mm/r: the nose arc ends at zeta = -r sin 5 deg = -34.9 um, before -f/2, and the
    current profile meets the previous pass's arc on the straight minor edge. Independent
    closed form: r (1 - cos ke) + (-z - r sin ke) tan ke = r - sqrt(r^2 - (z + f)^2), solved by
    brentq; engaged length r ke + (-z - r sin ke) / cos ke. zeta_i = -82.7 um (the 3D FE's
    contact reaches -83 um). 1e-9 relative."""
    r, ke, f, ap = 0.4e-3, math.radians(5.0), 0.15e-3, 0.05e-3
    ins = BoringInsert(nose_radius_m=r, approach_angle_deg=90.0, end_edge_angle_deg=5.0)

    def gap(z):
        return r * (1 - math.cos(ke)) + (-z - r * math.sin(ke)) * math.tan(ke) - (
            r - math.sqrt(r * r - (z + f) ** 2))

    z_ref = brentq(gap, -f, -r * math.sin(ke), xtol=1e-16, rtol=1e-15)
    assert -83e-6 < z_ref < -82e-6
    L_ref = r * ke + (-z_ref - r * math.sin(ke)) / math.cos(ke)
    el = edge_elements(ins, ap, f, 40)
    assert el.trailing_end_zeta_m == pytest.approx(z_ref, rel=1e-9)
    assert trailing_intersection(ins, ap, f) == pytest.approx(z_ref, rel=1e-9)
    assert el.trailing_length == pytest.approx(L_ref, rel=1e-9)
    assert el.trailing_length > r * math.asin(f / (2 * r)) * 1.09  # longer than the arc rule
    # the arc / minor-edge corner is an element boundary: straight elements have kappa = -ke
    tr = el.trailing
    straight = tr & (el.s < -r * ke)
    assert straight.sum() >= 1 and np.allclose(el.kappa[straight], -ke, rtol=0, atol=1e-15)
    assert np.all(el.kappa[tr & ~straight] > -ke)
    assert np.any(np.isclose(np.cumsum(el.dS[tr]) + el.s[0] - 0.5 * el.dS[0], -r * ke,
                             rtol=0, atol=1e-15))


def test_trailing_edge_limited_by_the_prebore_surface():
    """Depth below the cusp height (ap 3 um < f^2 / (8 r) = 7 um): the trailing contact ends
    where the nose reaches the pre-bore surface, zeta = -sqrt(r^2 - (r - ap)^2) (exact)."""
    r, f, ap = 0.4e-3, 0.15e-3, 3e-6
    ins = BoringInsert(nose_radius_m=r, end_edge_angle_deg=60.0)
    el = edge_elements(ins, ap, f, 20)
    z = -math.sqrt(r * r - (r - ap) ** 2)
    assert el.trailing_end_zeta_m == pytest.approx(z, rel=1e-9)
    assert el.trailing_length == pytest.approx(r * math.asin(-z / r), rel=1e-9)


def test_trailing_edge_switch_and_count():
    """trailing_edge=False gives the leading edge only; n_trailing sets
    the count; a bad count names the field."""
    ins = BoringInsert()
    off = edge_elements(ins, 0.05e-3, 0.15e-3, 30, trailing_edge=False)
    assert off.n_trailing == 0 and off.n == 30 and np.all(off.h > 0)
    on = edge_elements(ins, 0.05e-3, 0.15e-3, 30, n_trailing=7)
    assert on.n_trailing == 7 and on.n == 37  # 4 on the minor edge, 3 on the arc
    assert edge_elements(ins, 0.05e-3, 0.15e-3, 1).n_trailing >= 1
    with pytest.raises(ConfigError) as ei:
        edge_elements(ins, 0.05e-3, 0.15e-3, 30, n_trailing=0)
    assert ei.value.field == "n_trailing"


@pytest.mark.parametrize("kw, key", [
    ({"nose_radius_m": -1e-3}, "insert.nose_radius_m"),
    ({"approach_angle_deg": 120.0}, "insert.approach_angle_deg"),
    ({"n_inserts": 0}, "insert.n_inserts"),
])
def test_bad_insert(kw, key):
    with pytest.raises(ConfigError) as ei:
        BoringInsert(**kw)
    assert ei.value.field == key


def test_bad_depth():
    with pytest.raises(ConfigError, match="depth_m"):
        edge_elements(BoringInsert(), -1e-3, 1e-4)
