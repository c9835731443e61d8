"""Boring chip geometry: chip area and local chip thickness (Atabey et al. 2003; Kaymakci 2012)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robobore.cutting.geometry import BoringInsert, chip_area, edge_elements, scallop_area
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
    assert np.all((el.kappa >= 0) & (el.kappa < math.pi / 2))
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
