"""3D engine vs 2D engine on the same orthogonal cut (plane-strain slab cross-check).

Usage::

    python benchmarks/validate_fe3d_planestrain.py [--h-um 100] [--vc 80] [--length-mm 0.3]
        [--element-um 10] [--rake 7] [--clearance 7] [--edge-um 20] [--hourglass S V]
        [--out results.json]

Runs the 2D engine (``robobore fe orthogonal`` physics, node splitting 5 um above the edge's
lowest point, Rech friction table) and the 3D engine on a plane-strain slab of the same cut
(:mod:`robobore.cutting.fe.models.slab3d`), and prints cutting and feed force per unit width from
both with the relative differences, energy errors, hourglass fractions and wall times. The
default is the condition of the paper example's FE calibration (h = 100 um, 80 m/min, rake 7,
clearance 7, edge 20 um, 10 um elements). Results go to ``--out`` (atomic JSON) when given.
"""

from __future__ import annotations

import argparse
import json
import os
import time


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--h-um", type=float, default=100.0)
    ap.add_argument("--vc", type=float, default=80.0, help="cutting speed [m/min]")
    ap.add_argument("--length-mm", type=float, default=0.3)
    ap.add_argument("--element-um", type=float, default=10.0)
    ap.add_argument("--rake", type=float, default=7.0)
    ap.add_argument("--clearance", type=float, default=7.0)
    ap.add_argument("--edge-um", type=float, default=20.0)
    ap.add_argument("--hourglass", type=float, nargs=2, default=(0.05, 0.05),
                    metavar=("STIFFNESS", "VISCOUS"))
    ap.add_argument("--out", default=None)
    a = ap.parse_args()

    from robobore.cutting.fe.config.orthogonal import parse_config
    from robobore.cutting.fe.models.orthogonal import simulate_orthogonal
    from robobore.cutting.fe.models.slab3d import simulate_slab3
    from robobore.io.results import atomic_write_text

    d = {"parameters": "a_priori", "material": {"name": "TC4"},
         "tool": {"rake_deg": a.rake, "clearance_deg": a.clearance,
                  "edge_radius_um": a.edge_um},
         "cut": {"uncut_chip_thickness_um": a.h_um, "cutting_speed_m_per_min": a.vc,
                 "length_mm": a.length_mm, "width_mm": 1.0},
         "contact": {"friction": "table"},
         "mesh": {"frame": "workpiece", "element_size_um": a.element_um,
                  "separation": "node_split",
                  "separation_height_um": 5.0},
         "solver": {"mass_scaling": 100.0, "heat_conduction": False,
                    "hourglass_stiffness": a.hourglass[0],
                    "hourglass_viscous": a.hourglass[1]}}
    cfg = parse_config(d)
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cpus")
    t0 = time.perf_counter()
    r2 = simulate_orthogonal(cfg).to_dict()
    w2 = time.perf_counter() - t0
    t0 = time.perf_counter()
    r3 = simulate_slab3(cfg).to_dict()
    w3 = time.perf_counter() - t0
    out = {"config": d, "2d": {k: r2[k] for k in ("cutting_force_N_per_mm",
                                                  "feed_force_N_per_mm", "energy_error",
                                                  "eroded_chip_mass_fraction")},
           "3d_slab": r3, "wall_s": {"2d": w2, "3d_slab": w3}}
    for key in ("cutting_force_N_per_mm", "feed_force_N_per_mm"):
        rel = (r3[key] - r2[key]) / abs(r2[key])
        out[f"relative_difference_{key}"] = rel
        print(f"{key:24s}: 2D {r2[key]:8.2f}   3D slab {r3[key]:8.2f}   ({100 * rel:+.1f} %)")
    print(f"energy error: 2D {r2['energy_error']:.3%}, 3D {r3['energy_error']:.3%}; "
          f"3D hourglass / internal {r3['hourglass_fraction']:.1%}; eroded 3D elements "
          f"{r3['eroded']} of {r3['n_elements']}; wall 2D {w2:.1f} s, 3D {w3:.1f} s")
    if a.out:
        atomic_write_text(a.out, json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
