"""Summary of a ``bench_calibrate.py --json`` record over a range of its seeds (not a test).

Prints the record's per-seed lines for seeds FIRST..FIRST+SEEDS-1 and, over them, the figures
``bench_calibrate.py`` prints (share within 10 % of the truth, the band's forecast, the 90 %
band's coverage, median errors) and the time per seed: the final calibration's, and for the
sequential design that calibration plus the design's 8 (CPU and wall, median and max).

Run: python benchmarks/bench_calibrate_summary.py RECORD.json [--first 0] [--seeds 10]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
from bench_calibrate import print_figures


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("record", help="a JSON list written by bench_calibrate.py --json")
    ap.add_argument("--first", type=int, default=0)
    ap.add_argument("--seeds", type=int, default=10)
    args = ap.parse_args()
    path = Path(args.record)
    runs = json.loads(path.read_text())
    if not isinstance(runs, list):
        sys.exit(f"{path}: expected a JSON list of per-seed results (bench_calibrate.py --json), "
                 f"got a {type(runs).__name__}")
    want = range(args.first, args.first + args.seeds)
    sel = [r for r in runs if r["seed"] in want]
    missing = sorted(set(want) - {r["seed"] for r in sel})
    if missing:
        sys.exit(f"{path}: seeds {missing} not in the record (it holds seeds "
                 f"{min(r['seed'] for r in runs)}-{max(r['seed'] for r in runs)})")
    print(f"{path.name}, seeds {args.first}-{args.first + args.seeds - 1}")
    print(f"{'seed':>4} {'within10%':>9} {'forecast':>8} {'cover90':>8} {'err corr':>8} "
          f"{'err nom':>8} {'flip':>4} {'wall s':>7} {'cpu s':>6} {'design wall':>11} "
          f"{'design cpu':>10}")
    for r in sel:
        print(f"{r['seed']:4d} {r['within_10pct']:9.2f} {r['expected_within_10pct']:8.2f} "
              f"{r['coverage_90']:8.2f} {r['median_error_corrected']:8.3f} "
              f"{r['median_error_uncorrected']:8.3f} {r['flipped_labels']:4d} "
              f"{r['seconds']:7.1f} {r['cpu_seconds']:6.1f} {r.get('design_seconds', 0.0):11.1f} "
              f"{r.get('design_cpu_seconds', 0.0):10.1f}")
    w = np.array([r["within_10pct"] for r in sel])
    c = np.array([r["coverage_90"] for r in sel])
    we = np.array([r["expected_within_10pct"] for r in sel])
    wu = np.array([r["within_10pct_uncorrected"] for r in sel])
    ec = np.array([r["median_error_corrected"] for r in sel])
    eu = np.array([r["median_error_uncorrected"] for r in sel])
    wall = np.array([r["seconds"] + r.get("design_seconds", 0.0) for r in sel])
    cpu = np.array([r["cpu_seconds"] + r.get("design_cpu_seconds", 0.0) for r in sel])
    print(f"over {len(sel)} seeds x 24 held-out speeds:")
    print_figures(w, wu, we, c, ec, eu)
    print(f"  per seed (final calibration + design): CPU {np.median(cpu):.1f} s median "
          f"(max {cpu.max():.1f}), wall {np.median(wall):.1f} s median (max {wall.max():.1f})")


if __name__ == "__main__":
    main()
