"""Throughput of the 2D explicit FE cutting engine (element updates per second).

Runs the contract config (examples/fe_orthogonal.toml: the default, validated model -- tool
frame, h = 60 um, 10 um elements, 2.5 um round the edge, 0.3 mm of tool travel) or a shorter
cut, after a warm-up that compiles/loads the numba cache, and prints the wall time, steps,
element updates per second, threads and the machine load.

    python benchmarks/bench_fe2d.py [--length-mm 1.0] [--element-um 10] [--threads N]
        [--config FILE] [--conduction]

``--config`` measures another config (e.g. examples/fe_orthogonal_edge.toml, a
workpiece-frame model); ``--length-mm`` / ``--element-um`` then override
its values only when given. ``--conduction`` sets solver.heat_conduction.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numba

from robobore.cutting.fe.config import load_fe_config
from robobore.cutting.fe.solver import simulate_orthogonal

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "fe_orthogonal.toml"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--length-mm", type=float, default=None, help="default: the config's "
                    "(0.3 for the contract)")
    ap.add_argument("--element-um", type=float, default=None, help="default: the config's "
                    "(10 for the contract)")
    ap.add_argument("--threads", type=int, default=None)
    ap.add_argument("--config", type=Path, default=EXAMPLE)
    ap.add_argument("--conduction", action="store_true")
    args = ap.parse_args()
    if args.threads:
        numba.set_num_threads(args.threads)
    cfg = load_fe_config(args.config)
    if args.conduction:
        cfg.solver.heat_conduction = True
    warm = cfg.model_copy(deep=True)
    warm.cut.length_mm = 0.02
    t0 = time.perf_counter()
    simulate_orthogonal(warm)
    print(f"warm-up (compile or load cache): {time.perf_counter() - t0:.1f} s")
    if args.length_mm is not None:
        cfg.cut.length_mm = args.length_mm
    if args.element_um is not None:
        cfg.mesh.element_size_um = args.element_um
    print(f"config {args.config}, {cfg.cut.length_mm} mm, {cfg.mesh.element_size_um} um, "
          f"frame {cfg.mesh.frame}, conduction {cfg.solver.heat_conduction}")
    load0 = os.getloadavg()
    res = simulate_orthogonal(cfg)
    s = res.summary
    print(f"threads {numba.get_num_threads()} ({numba.threading_layer()}), load before "
          f"{load0[0]:.2f}, after {os.getloadavg()[0]:.2f}")
    print(f"elements {s['n_elements']}, steps {s['steps']}, wall {s['wall_time_s']:.1f} s")
    print(f"element updates per second: {s['element_updates_per_s'] / 1e6:.2f} million")
    print(f"Fc {s['cutting_force_N_per_mm']:.1f} N/mm, Ff {s['feed_force_N_per_mm']:.1f} N/mm,"
          f" chip ratio {s['chip_ratio']:.2f}, energy error {s['energy_error']:.3f}")


if __name__ == "__main__":
    main()
