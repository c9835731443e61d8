"""The bundled cutting-coefficient sets and the orthogonal-to-oblique transformation.

The TC4 default (:func:`ti64_coefficients`) is fitted by code from the bundled measured
orthogonal data (see ``coefficients/README.md``); :func:`tc4_fe_coefficients` is the paper
example's FE-calibrated set; :func:`orthogonal_to_oblique` gives the classical
orthogonal-to-oblique transformation (Armarego; Budak, Altintas & Armarego 1996; Altintas'
textbook eq. 2.x) from shear stress, shear angle, friction angle, rake and inclination, which
:func:`ti64_oblique_coefficients` applies to an inclined insert.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from robobore.cutting.coefficient_files import load_coefficients
from robobore.cutting.forces import CuttingCoefficients
from robobore.cutting.geometry import BoringInsert

COEFF_DIR = Path(__file__).with_name("coefficients")
DUCOBU_FILE = COEFF_DIR / "ti64_orthogonal_cutting_forces.json"

__all__ = ["COEFF_DIR", "DUCOBU_FILE", "fit_linear_edge_model", "ducobu_fits",
           "ti64_coefficients", "TI64_CHIP_THICKNESS_M", "TC4_FE_FILE", "TC4_NAMES",
           "TC4_FE_NAMES", "tc4_fe_coefficients", "OrthogonalParameters",
           "orthogonal_parameters_from_data", "orthogonal_to_oblique",
           "ti64_oblique_coefficients"]


def fit_linear_edge_model(h_m: np.ndarray, force_N_per_m: np.ndarray) -> tuple[float, float]:
    """Least-squares fit ``F = Ke + Kc h`` (per unit width); returns ``(Kc [N/m^2], Ke [N/m])``."""
    h = np.asarray(h_m, float)
    F = np.asarray(force_N_per_m, float)
    A = np.column_stack([h, np.ones_like(h)])
    (kc, ke), *_ = np.linalg.lstsq(A, F, rcond=None)
    return float(kc), float(ke)


@lru_cache(maxsize=1)
def _ducobu() -> dict[str, Any]:
    return json.loads(DUCOBU_FILE.read_text())


def ducobu_fits() -> dict[float, dict[str, float]]:
    """Per cutting speed [m/min]: fitted Ktc, Kte, Kfc, Kfe and chip ratio (bundled TC4 data)."""
    data = _ducobu()["measured"]
    hs = sorted(data["Fc"], key=float)
    speeds = sorted(data["Fc"][hs[0]], key=float)
    out = {}
    for v in speeds:
        h = np.array([float(x) * 1e-6 for x in hs])
        fc = np.array([data["Fc"][x][v] for x in hs]) * 1e3  # N/mm -> N/m
        ff = np.array([data["Ff"][x][v] for x in hs]) * 1e3
        ktc, kte = fit_linear_edge_model(h, fc)
        kfc, kfe = fit_linear_edge_model(h, ff)
        rc = float(np.mean([data["chip_ratio"][x][v] for x in hs]))
        out[float(v)] = {"Ktc": ktc, "Kte": kte, "Kfc": kfc, "Kfe": kfe, "chip_ratio": rc}
    return out


def ti64_coefficients(cutting_speed_m_per_min: float | None = 30.0) -> CuttingCoefficients:
    """TC4 (Ti-6Al-4V) default coefficients from the bundled measured orthogonal data.

    Linear interpolation of the per-speed fits in cutting speed; held constant outside the
    measured range 5-30 m/min (said in the provenance). Rake 15 deg, inclination 0, so the
    lateral coefficients are 0; use :func:`orthogonal_to_oblique` for an inclined insert.
    """
    fits = ducobu_fits()
    v = np.array(sorted(fits))
    vc = float(v[-1] if cutting_speed_m_per_min is None else cutting_speed_m_per_min)
    note = ""
    if vc < v[0] or vc > v[-1]:
        note = f"; vc = {vc:.3g} m/min outside the measured {v[0]:g}-{v[-1]:g} m/min: held at edge"
    vq = float(np.clip(vc, v[0], v[-1]))
    vals = {k: float(np.interp(vq, v, [fits[s][k] for s in v]))
            for k in ("Ktc", "Kte", "Kfc", "Kfe")}
    prov = ("TC4: least-squares fit Fc = Kte + Ktc h, Ff = Kfe + Kfc h of measured orthogonal "
            "forces (Ducobu et al., CIRP 2022; rake 15 deg, edge radius 20 um), "
            f"interpolated at vc = {vq:.3g} m/min" + note)
    warn = (f"cutting speed {vc:.3g} m/min outside the measured {v[0]:g}-{v[-1]:g} m/min of "
            f"the TC4 coefficients: held at the {vq:g} m/min fit",) if note else ()
    return CuttingCoefficients(Ktc=vals["Ktc"], Krc=0.0, Kfc=vals["Kfc"], Kte=vals["Kte"],
                               Kre=0.0, Kfe=vals["Kfe"], provenance=prov, speed_m_per_min=vq,
                               warnings=warn, chip_thickness_range_m=TI64_CHIP_THICKNESS_M)


#: Uncut chip thicknesses [m] of the measured TC4 data the default coefficients are fitted to.
TI64_CHIP_THICKNESS_M = (40e-6, 80e-6)

#: The FE-calibrated TC4 set of the paper example (rake 7 deg, edge radius 20 um, h 60-90 um,
#: 37.7 m/min): opt-in as ``material = "TC4-FE"``; the validated default is the measured set
#: (:func:`ti64_coefficients`; the evidence: docs/process.md, "The TC4 coefficient sets").
TC4_FE_FILE = Path(__file__).resolve().parents[1] / "data" / "paper_example" / \
    "tc4_fe_coefficients.json"
#: Names of the TC4 sets for ``[coefficients] material``: the measured default, the FE opt-in.
TC4_NAMES = ("TC4", "TI6AL4V", "TI-6AL-4V")
TC4_FE_NAMES = ("TC4-FE",)


def tc4_fe_coefficients(cutting_speed_m_per_min: float | None = None) -> CuttingCoefficients:
    """The paper example's FE-calibrated TC4 set (:data:`TC4_FE_FILE`), with the warning of a
    cutting speed outside its calibrated 37.7 m/min and its chip-thickness range 60-90 um
    (:meth:`CuttingCoefficients.domain_warnings`)."""
    return load_coefficients(TC4_FE_FILE, cutting_speed_m_per_min)


@dataclass(frozen=True)
class OrthogonalParameters:
    """Orthogonal cutting parameters: shear stress [Pa], shear angle, friction angle, rake [rad]."""

    shear_stress_Pa: float
    shear_angle_rad: float
    friction_angle_rad: float
    rake_rad: float


def orthogonal_parameters_from_data(Ktc: float, Kfc: float, chip_ratio: float,
                                    rake_rad: float) -> OrthogonalParameters:
    """Shear angle, friction angle and shear stress from orthogonal shearing coefficients.

    ``chip_ratio`` = chip thickness / uncut chip thickness (> 1). Merchant/Armarego relations:
    ``tan phi = r cos a / (1 - r sin a)`` with ``r = 1/chip_ratio``;
    ``beta = a + atan(Kfc/Ktc)``; ``tau_s = (Ktc cos phi - Kfc sin phi) sin phi``.
    """
    r = 1.0 / chip_ratio
    phi = math.atan2(r * math.cos(rake_rad), 1.0 - r * math.sin(rake_rad))
    beta = rake_rad + math.atan2(Kfc, Ktc)
    tau = (Ktc * math.cos(phi) - Kfc * math.sin(phi)) * math.sin(phi)
    return OrthogonalParameters(tau, phi, beta, rake_rad)


def orthogonal_to_oblique(shear_stress_Pa: float, shear_angle_rad: float,
                          friction_angle_rad: float, rake_rad: float,
                          inclination_rad: float = 0.0,
                          chip_flow_angle_rad: float | None = None) -> tuple[float, float, float]:
    """Orthogonal-to-oblique transformation: returns ``(Ktc, Kfc, Krc)`` in N/m^2.

    Assumptions (Armarego & Whitfield; Budak, Altintas & Armarego 1996): normal shear angle =
    orthogonal shear angle, normal rake = rake, chip flow angle = inclination (Stabler) unless
    given, normal friction angle from ``tan beta_n = tan beta_a cos eta``::

        Ktc = tau/sin(phi_n) (cos(bn-an) + tan i tan eta sin bn) / W
        Kfc = tau/(sin(phi_n) cos i) sin(bn-an) / W
        Krc = tau/sin(phi_n) (cos(bn-an) tan i - tan eta sin bn) / W
        W = sqrt(cos^2(phi_n + bn - an) + tan^2 eta sin^2 bn)

    Here Kfc is the thrust (normal to the edge) and Krc the lateral (along the edge) coefficient.
    """
    i = inclination_rad
    eta = i if chip_flow_angle_rad is None else chip_flow_angle_rad
    an = rake_rad
    bn = math.atan(math.tan(friction_angle_rad) * math.cos(eta))
    pn = shear_angle_rad
    W = math.sqrt(math.cos(pn + bn - an) ** 2 + math.tan(eta) ** 2 * math.sin(bn) ** 2)
    t = shear_stress_Pa / math.sin(pn)
    ktc = t * (math.cos(bn - an) + math.tan(i) * math.tan(eta) * math.sin(bn)) / W
    kfc = t / math.cos(i) * math.sin(bn - an) / W
    krc = t * (math.cos(bn - an) * math.tan(i) - math.tan(eta) * math.sin(bn)) / W
    return ktc, kfc, krc


def ti64_oblique_coefficients(insert: BoringInsert,
                              cutting_speed_m_per_min: float = 30.0) -> CuttingCoefficients:
    """TC4 coefficients for an inclined insert via the orthogonal-to-oblique route.

    Shear stress, shear angle and friction angle come from the bundled measured data
    (:func:`orthogonal_parameters_from_data`, measured rake 15 deg); the friction angle is
    shifted with the rake (beta - alpha kept, Merchant) to the insert's rake. Edge
    coefficients are kept from the linear fit.
    """
    base = ti64_coefficients(cutting_speed_m_per_min)
    fits = ducobu_fits()
    v = np.array(sorted(fits))
    vq = float(np.clip(cutting_speed_m_per_min, v[0], v[-1]))
    rc = float(np.interp(vq, v, [fits[s]["chip_ratio"] for s in v]))
    p = orthogonal_parameters_from_data(base.Ktc, base.Kfc, rc, math.radians(15.0))
    a = math.radians(insert.rake_deg)
    phi = p.shear_angle_rad + 0.5 * (a - p.rake_rad)
    ktc, kfc, krc = orthogonal_to_oblique(p.shear_stress_Pa, phi, p.friction_angle_rad, a,
                                          math.radians(insert.inclination_deg))
    return CuttingCoefficients(ktc, krc, kfc, base.Kte, 0.0, base.Kfe,
                               provenance=base.provenance + "; orthogonal-to-oblique with "
                               f"tau_s = {p.shear_stress_Pa / 1e6:.0f} MPa, "
                               f"beta = {math.degrees(p.friction_angle_rad):.1f} deg, "
                               f"phi = {math.degrees(phi):.1f} deg",
                               speed_m_per_min=base.speed_m_per_min)
