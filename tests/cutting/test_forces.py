"""Mechanistic boring forces and coefficients."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from robobore.cutting.forces import (
    CuttingCoefficients,
    boring_forces,
    ducobu_fits,
    element_forces,
    load_coefficients,
    orthogonal_parameters_from_data,
    orthogonal_to_oblique,
    ti64_coefficients,
)
from robobore.cutting.geometry import BoringInsert, edge_elements
from robobore.errors import ConfigError


def test_ducobu_fit_reproduces_data():
    """The least-squares line through the measured Fc(h) at 30 m/min passes within 3 N/mm of
    every point (reading accuracy 0.5 N/mm; scatter of the measurement)."""
    fits = ducobu_fits()
    k = fits[30.0]
    data = json.load(open(__import__("robobore.cutting.forces", fromlist=["x"]).DUCOBU_FILE))
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
