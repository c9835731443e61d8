"""Mechanistic boring forces and coefficients."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from robobore.cutting.coefficient_files import load_coefficients
from robobore.cutting.coefficient_sets import (
    DUCOBU_FILE,
    ducobu_fits,
    orthogonal_parameters_from_data,
    orthogonal_to_oblique,
    ti64_coefficients,
)
from robobore.cutting.forces import CuttingCoefficients, boring_forces, element_forces
from robobore.cutting.geometry import BoringInsert, edge_elements
from robobore.errors import ConfigError


def test_ducobu_fit_reproduces_data():
    """The least-squares line through the measured Fc(h) at 30 m/min passes within 3 N/mm of
    every point (reading accuracy 0.5 N/mm; scatter of the measurement)."""
    fits = ducobu_fits()
    k = fits[30.0]
    data = json.loads(DUCOBU_FILE.read_text())
    for h in ("40", "60", "80"):
        pred = (k["Kte"] + k["Ktc"] * float(h) * 1e-6) / 1e3
        assert pred == pytest.approx(data["measured"]["Fc"][h]["30"], abs=3.0)
    assert 1.0e9 < k["Ktc"] < 3.0e9  # N/m^2, TC4 order of magnitude (Altintas: ~2 GPa)


def test_orthogonal_oblique_roundtrip():
    """i = 0: tau_s, phi, beta from (Ktc, Kfc, chip ratio) map back to the same Ktc, Kfc."""
    p = orthogonal_parameters_from_data(1.6e9, 0.3e9, 1.8, math.radians(15))
    ktc, kfc, krc = orthogonal_to_oblique(p.shear_stress_Pa, p.shear_angle_rad,
                                          p.friction_angle_rad, p.rake_rad, 0.0)
    assert ktc == pytest.approx(1.6e9, rel=1e-12)
    assert kfc == pytest.approx(0.3e9, rel=1e-12)
    assert krc == pytest.approx(0.0, abs=1e-3)


def test_oblique_hand_value():
    """Altintas (2012) example style: tau=613 MPa, phi=30 deg, beta=25 deg, a=5 deg, i=10 deg."""
    tau, phi, beta, a, i = 613e6, *np.radians([30.0, 25.0, 5.0, 10.0])
    bn = math.atan(math.tan(beta) * math.cos(i))
    W = math.sqrt(math.cos(phi + bn - a) ** 2 + math.tan(i) ** 2 * math.sin(bn) ** 2)
    ktc_hand = tau / math.sin(phi) * (math.cos(bn - a) + math.tan(i) ** 2 * math.sin(bn)) / W
    ktc, kfc, krc = orthogonal_to_oblique(tau, phi, beta, a, i)
    assert ktc == pytest.approx(ktc_hand, rel=1e-12)
    assert krc > 0 and kfc > 0


def test_element_forces_sum_is_coefficient_times_area():
    """Without edge terms the tangential force is exactly Ktc x chip area."""
    c = CuttingCoefficients(Ktc=2e9, Krc=0.0, Kfc=0.8e9)
    el = edge_elements(BoringInsert(), 0.3e-3, 0.1e-3, 50)
    ef = element_forces(el, c)
    assert ef.tangential == pytest.approx(2e9 * el.area_elements, rel=1e-12)


@pytest.mark.parametrize("kend", [5.0, 60.0])
def test_edge_forces_act_on_the_whole_engaged_edge(kend):
    """Edge coefficients only (Ktc negligible): the tangential edge force is Kte x the engaged
    length, leading edge plus the trailing side of the nose back to the previous pass (with a
    60 deg end edge that side is the arc r asin(f / (2 r)), exact). The thrust Kfe dS is
    normal to the local edge, so its sums are Kfe times the profile's extent:
    feed = -Kfe (ap - drop_i), radial = -Kfe (zeta_end - zeta_i) (drop_i, zeta_i: where the
    trailing contact ends), i.e. the trailing side pushes the tool FORWARD along the feed.
    Tolerances: 1e-12 (sums of lengths), 5e-5 (midpoint rule of the orientation on the arc,
    40 elements: 7e-6 measured; dropping the trailing side changes the feed sum by 11 %)."""
    r, ap, f = 0.4e-3, 0.05e-3, 0.15e-3
    ins = BoringInsert(nose_radius_m=r, approach_angle_deg=90.0, end_edge_angle_deg=kend)
    c = CuttingCoefficients(Ktc=1e-6, Krc=0.0, Kfc=0.0, Kte=2e4, Kfe=3e4)
    el = edge_elements(ins, ap, f, 40)
    ef = element_forces(el, c)
    L_lead = r * math.acos(1 - ap / r)
    if kend == 60.0:
        assert el.trailing_length == pytest.approx(r * math.asin(f / (2 * r)), rel=1e-9)
    assert ef.tangential == pytest.approx(2e4 * (L_lead + el.trailing_length), rel=1e-12)
    zi = el.trailing_end_zeta_m
    di = float(ins.drop(np.array([zi]))[0])
    z_end = math.sqrt(r * r - (r - ap) ** 2)
    assert ef.feed == pytest.approx(-3e4 * (ap - di), rel=5e-5)
    assert ef.radial == pytest.approx(-3e4 * (z_end - zi), rel=5e-5)
    # per element |thrust| = Kfe dS on both sides
    tr = el.trailing
    fe = -ef.dFf * np.sin(el.kappa)
    assert np.all(fe[tr] > 0) and np.all(fe[~tr] <= 0)
    assert fe[tr].sum() == pytest.approx(3e4 * di, rel=5e-5)
    # the leading-edge-only model misses exactly the trailing part
    off = element_forces(edge_elements(ins, ap, f, 40, trailing_edge=False), c)
    assert ef.tangential - off.tangential == pytest.approx(2e4 * el.trailing_length, rel=1e-9)
    assert off.feed == pytest.approx(-3e4 * ap, rel=5e-5)


def test_boring_forces_trailing_edge_switch():
    """boring_forces(trailing_edge=False) is the leading-edge-only model: same shearing part,
    the difference is the trailing side's edge force (tangential Kte L_trail, 1e-9)."""
    ins = BoringInsert()
    c = ti64_coefficients(37.7)
    on = boring_forces(ins, 0.05e-3, 0.15e-3, c)
    off = boring_forces(ins, 0.05e-3, 0.15e-3, c, trailing_edge=False)
    L = on["elements"].trailing_length
    assert on["tangential_N"] - off["tangential_N"] == pytest.approx(c.Kte * L, rel=1e-9)
    assert on["radial_N"] < off["radial_N"] < 0  # more thrust inwards
    assert on["feed_N"] > off["feed_N"]  # the trailing thrust pushes forward: less feed force
    assert on["chip_area_m2"] == off["chip_area_m2"]


def test_kappa90_straight_edge_forces_go_to_feed():
    """Sharp corner approximated by a 1 um nose, kappa_r = 90 deg: thrust is all along -Z and
    equals Kfc times the chip area ap f minus the saw-tooth the 5 deg end edge leaves,
    f^2 tan(5 deg) / 2 (hand calculation), to 1e-3."""
    c = CuttingCoefficients(Ktc=2e9, Krc=0.0, Kfc=0.8e9)
    ins = BoringInsert(nose_radius_m=1e-6, approach_angle_deg=90.0)
    r = boring_forces(ins, 1e-3, 0.1e-3, c)
    area = 1e-3 * 0.1e-3 - 0.5 * (0.1e-3) ** 2 * math.tan(math.radians(5.0))
    assert r["feed_N"] == pytest.approx(-0.8e9 * area, rel=1e-3)
    assert abs(r["radial_N"]) < 2e-3 * abs(r["feed_N"])


def test_paper_condition_forces_and_trends():
    """Paper condition ap = 0.05 mm, f = 0.15 mm/r, n = 300 r/min, TC4 (bore 40 mm, assumed):
    tens of newtons; forces grow with ap and f, flat in n above the measured speed range."""
    ins = BoringInsert()

    def amp(ap, f, n):
        vc = math.pi * 0.040 * n
        r = boring_forces(ins, ap * 1e-3, f * 1e-3, ti64_coefficients(vc))
        return float(np.hypot(*r["amplitude_N"][:2]))

    a0 = amp(0.05, 0.15, 300)
    assert 10.0 < a0 < 100.0
    assert amp(0.1, 0.15, 300) > a0 and amp(0.05, 0.2, 300) > a0
    assert amp(0.05, 0.15, 500) == pytest.approx(a0, rel=0.05)


def test_coefficients_file_roundtrip(tmp_path):
    c = ti64_coefficients(10.0)
    p = tmp_path / "k.json"
    p.write_text(json.dumps(c.to_dict()))
    assert load_coefficients(p) == c
    t = tmp_path / "k.toml"
    t.write_text('Ktc_N_per_m2 = 2e9\nKfc_N_per_m2 = 1e9\nKte_N_per_m = 3e4\nprovenance = "FE"\n')
    c2 = load_coefficients(t)
    assert c2.Ktc == 2e9 and c2.Kte == 3e4 and c2.Krc == 0.0 and c2.provenance == "FE"
    t.write_text('Kfc_N_per_m2 = 1e9\n')
    with pytest.raises(ConfigError, match="Ktc_N_per_m2"):
        load_coefficients(t)
    with pytest.raises(ConfigError, match="Ktc_N_per_m2"):
        CuttingCoefficients(Ktc=-1.0, Krc=0.0, Kfc=0.0)
