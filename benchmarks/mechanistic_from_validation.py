"""Mechanistic coefficients fitted to the validated FE model's nine points, against their FE
points and the measurements (issue 27's acceptance on the coefficients).

Reads the FE forces the validated model gave at the nine measured conditions (rows stored in
benchmarks/measured/fe_validation_2026-11-23/calibrated_rech_x1.5_sliding_hardening0.6_nocap_*:
the default model written out, 10 um elements, 0.3 mm, rake 15 deg, edge radius 20 um; the
configs are the ones ``robobore fe validate examples/fe_orthogonal.toml`` runs, see
tests/cutting/fe/test_validation_config.py), fits them with ``robobore.cutting.calibrate``
(Fc = Kte + Ktc h, Ff = Kfe + Kfc h, pooled over the speeds, as ``robobore calibrate forces``),
and prints per point: the fit against its FE point and against the measurement
(../shared/data/ti64_orthogonal_cutting_forces.json). No FE is run.

    python benchmarks/mechanistic_from_validation.py [--data PATH]
"""

from __future__ import annotations

import argparse
import json
import re
from pathlib import Path

from robobore.cutting import calibrate as cal

ROOT = Path(__file__).resolve().parents[1]
ROWS = ROOT / "benchmarks" / "measured" / "fe_validation_2026-11-23"
DATA = ROOT.parent / "shared" / "data" / "ti64_orthogonal_cutting_forces.json"


def fe_points() -> dict[tuple[float, float], tuple[float, float]]:
    """(h, vc) -> (Fc, Ff) N/mm of the nine stored validation rows."""
    out = {}
    d = json.loads((ROWS / "calibrated_rech_x1.5_sliding_hardening0.6_nocap_5points.json")
                   .read_text())
    for r in d["rows"]:
        out[(r["h_um"], r["vc_m_per_min"])] = (r["Fc_sim"], r["Ff_sim"])
    txt = (ROWS / "calibrated_rech_x1.5_sliding_hardening0.6_nocap_4points.txt").read_text()
    for line in txt.splitlines():
        m = re.match(r"\s*(\d+)\s+(\d+) \|\s*\S+\s+(\S+)\s+\S+ \|\s*\S+\s+(\S+)", line)
        if m:
            out[(float(m[1]), float(m[2]))] = (float(m[3]), float(m[4]))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=DATA)
    a = ap.parse_args()
    meas = json.loads(a.data.read_text())["measured"]
    pts = fe_points()
    hs = sorted({h for h, _ in pts})
    vs = sorted({v for _, v in pts})
    cfg = cal.calibration_from_mapping(
        {"calibration": {"uncut_chip_thickness_um": hs, "cutting_speed_m_per_min": vs,
                         "fe_config": {"cut": {"length_mm": 0.3},
                                       "mesh": {"element_size_um": 10.0}}},
         "insert": {"rake_deg": 15.0, "edge_radius_um": 20.0, "clearance_deg": 2.0},
         "material": {"name": "TC4"}}, source="mechanistic_from_validation")
    recs = [{"h_um": h, "vc_m_per_min": v, "Fc_N_per_m": pts[(h, v)][0] * 1e3,
             "Ff_N_per_m": pts[(h, v)][1] * 1e3, "cached": True, "fe": {}}
            for h in hs for v in vs]
    d = cal.calibrate(cfg, recs)
    o = d["orthogonal"]
    print(f"# pooled fit over {len(recs)} FE points: Ktc {o['Ktc_N_per_m2'] / 1e9:.4f} GPa, "
          f"Kte {o['Kte_N_per_m'] / 1e3:.2f} N/mm, Kfc {o['Kfc_N_per_m2'] / 1e9:.4f} GPa, "
          f"Kfe {o['Kfe_N_per_m'] / 1e3:.2f} N/mm; warnings: {d['warnings'] or 'none'}")
    print(f"{'h':>4} {'vc':>4} | {'Fc fit':>7} {'Fc FE':>7} {'vs FE%':>7} {'Fc meas':>7} "
          f"{'vs meas%':>8} | {'Ff fit':>6} {'Ff FE':>6} {'vs FE%':>7} {'Ff meas':>7} "
          f"{'vs meas%':>8}")
    worst = {"fe_c": 0.0, "fe_f": 0.0, "m_c": 0.0, "m_f": 0.0}
    for h in hs:
        for v in vs:
            fc = (o["Kte_N_per_m"] + o["Ktc_N_per_m2"] * h * 1e-6) * 1e-3
            ff = (o["Kfe_N_per_m"] + o["Kfc_N_per_m2"] * h * 1e-6) * 1e-3
            fcf, fff = pts[(h, v)]
            fcm, ffm = meas["Fc"][f"{h:g}"][f"{v:g}"], meas["Ff"][f"{h:g}"][f"{v:g}"]
            e = (fc / fcf - 1, ff / fff - 1, fc / fcm - 1, ff / ffm - 1)
            for k, x in zip(worst, e, strict=True):
                worst[k] = max(worst[k], abs(x))
            print(f"{h:4.0f} {v:4.0f} | {fc:7.1f} {fcf:7.1f} {100 * e[0]:+7.1f} {fcm:7.1f} "
                  f"{100 * e[2]:+8.1f} | {ff:6.1f} {fff:6.1f} {100 * e[1]:+7.1f} {ffm:7.1f} "
                  f"{100 * e[3]:+8.1f}")
    # per-speed fits (the file's per_speed_fits; the boring model takes one set, so these
    # show what a speed-dependent coefficient model would reach)
    pw = {"fe_c": 0.0, "fe_f": 0.0, "m_c": 0.0, "m_f": 0.0}
    for v in vs:
        k = d["per_speed_fits"][f"{v:g}"]
        for h in hs:
            fc = (k["Kte_N_per_m"] + k["Ktc_N_per_m2"] * h * 1e-6) * 1e-3
            ff = (k["Kfe_N_per_m"] + k["Kfc_N_per_m2"] * h * 1e-6) * 1e-3
            fcf, fff = pts[(h, v)]
            fcm, ffm = meas["Fc"][f"{h:g}"][f"{v:g}"], meas["Ff"][f"{h:g}"][f"{v:g}"]
            for key, x in zip(pw, (fc / fcf - 1, ff / fff - 1, fc / fcm - 1, ff / ffm - 1),
                              strict=True):
                pw[key] = max(pw[key], abs(x))
    print(f"# per-speed fits, max |error|: vs FE Fc {100 * pw['fe_c']:.1f} %, Ff "
          f"{100 * pw['fe_f']:.1f} %; vs measured Fc {100 * pw['m_c']:.1f} %, Ff "
          f"{100 * pw['m_f']:.1f} %")
    print(f"# pooled fit, max |error|: fit vs FE Fc {100 * worst['fe_c']:.1f} %, Ff "
          f"{100 * worst['fe_f']:.1f} % (target 5 %); fit vs measured Fc "
          f"{100 * worst['m_c']:.1f} % (target 10 %), Ff "
          f"{100 * worst['m_f']:.1f} % (target 25 %)")


if __name__ == "__main__":
    main()
