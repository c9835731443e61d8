"""Mechanistic boring forces at the 3D FE runs' condition, with and without the trailing edge.

Usage::

    python benchmarks/boring_model_trailing_edge.py [COEF.json ...] [--json]

The insert, depth, feed and speed are those of ``examples/fe_boring_paper.toml`` (the 3D FE
boring runs of docs/fe3d.md: ap 0.05 mm, f 0.15 mm/r, 300 r/min, D 40 mm, CCMT-type insert
r 0.4 mm, end-edge angle 5 deg). Coefficient sets: the default TC4 coefficients
(``ti64_coefficients`` at the run's 37.7 m/min), the bundled FE calibration
(``data/paper_example/tc4_fe_coefficients.json``) and every file given. For each:
``cutting.forces.boring_forces`` (tangential / radial / feed on the tool, N) with the trailing
side of the nose (the default) and without it (``trailing_edge=False``), and the stored 3D
FE forces ``FE_N`` relative to the model, magnitudes.
No FE is run. Cheap (well under a second per set).
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: 3D FE rotating-frame forces [N] (t, r, f) of ``bench_fe3d.py paper`` runs with the friction
#: table at the cutting speed and the 576 MPa cap; the current engine's runs with that physics
#: (benchmarks/measured/gpu_h100_2026-11-22/paper3d_refinement.json) differ by up to 11 %
#: (the 10 um feed force), and the default physics' figures are in docs/fe3d.md.
FE_N = {"5 um": (16.51, -7.00, -1.57), "6.25 um": (16.85, -8.02, -1.72),
        "10 um": (18.54, -9.25, -2.00)}


def main() -> None:
    from robobore.cutting.coefficient_files import load_coefficients
    from robobore.cutting.coefficient_sets import ti64_coefficients
    from robobore.cutting.forces import boring_forces
    from robobore.cutting.geometry import BoringInsert
    from robobore.io.config import load_toml

    ap_ = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap_.add_argument("coefficients", nargs="*", type=Path)
    ap_.add_argument("--json", action="store_true")
    a = ap_.parse_args()

    d = load_toml(ROOT / "examples" / "fe_boring_paper.toml")
    i, c = d["insert"], d["cut"]
    ins = BoringInsert(nose_radius_m=i["nose_radius_mm"] * 1e-3,
                       approach_angle_deg=i["approach_angle_deg"],
                       end_edge_angle_deg=i["end_edge_angle_deg"], rake_deg=i["rake_deg"],
                       inclination_deg=i["inclination_deg"],
                       clearance_deg=i["clearance_deg"], edge_radius_m=i["edge_radius_um"] * 1e-6)
    ap, f = c["depth_of_cut_mm"] * 1e-3, c["feed_mm_per_rev"] * 1e-3
    vc = math.pi * c["bore_diameter_mm"] * 1e-3 * c["speed_rpm"]  # m/min
    sets = {f"default TC4 (Ducobu fit, {vc:.1f} m/min)": ti64_coefficients(vc),
            "bundled FE calibration (tc4_fe_coefficients.json)": load_coefficients(
                ROOT / "src" / "robobore" / "data" / "paper_example" / "tc4_fe_coefficients.json")}
    for p in a.coefficients:
        sets[p.name] = load_coefficients(p)
    rows = []
    for name, coef in sets.items():
        for trail in (False, True):
            m = boring_forces(ins, ap, f, coef, trailing_edge=trail)
            el = m["elements"]
            mv = (m["tangential_N"], m["radial_N"], m["feed_N"])
            rows.append({"coefficients": name, "trailing_edge": trail,
                         "model_N": mv, "engaged_length_um": el.engaged_length * 1e6,
                         "trailing_length_um": el.trailing_length * 1e6,
                         "trailing_end_zeta_um": el.trailing_end_zeta_m * 1e6,
                         "fe_vs_model_pct": {k: [100 * (abs(x) - abs(y)) / abs(y)
                                                 for x, y in zip(v, mv, strict=True)]
                                             for k, v in FE_N.items()}})
    if a.json:
        print(json.dumps(rows, indent=1))
        return
    r0 = rows[1]
    print(f"# ap {ap * 1e3:g} mm, f {f * 1e3:g} mm/r, vc {vc:.1f} m/min, r "
          f"{ins.nose_radius_m * 1e3:g} mm, end edge {ins.end_edge_angle_deg:g} deg: trailing "
          f"contact to zeta {r0['trailing_end_zeta_um']:.2f} um, {r0['trailing_length_um']:.2f} "
          f"um of edge (leading {r0['engaged_length_um'] - r0['trailing_length_um']:.2f} um)")
    for r in rows:
        t, rr, ff = r["model_N"]
        fe = "  ".join(f"{k}: " + " / ".join(f"{x:+.1f}" for x in v) + " %"
                       for k, v in r["fe_vs_model_pct"].items())
        print(f"{r['coefficients'][:48]:48s} {'with' if r['trailing_edge'] else 'w/o ':4s} "
              f"{t:7.2f} {rr:7.2f} {ff:7.2f} N | FE vs model {fe}")


if __name__ == "__main__":
    main()
