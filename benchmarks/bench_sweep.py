"""Throughput of the sweep machinery itself (results store + Dask), not of any model.

A null runner returns a small Dataset at once (a 200-sample time series and the summary
scalars), so conditions/s measures the overhead per condition: scheduling, transfer of the
result to the client, the atomic netCDF write, the index. Also times the demo runner.

    python benchmarks/bench_sweep.py [--n 400] [--workers 2]

Prints one line per mode with conditions/s and the 1-minute load average (the machine is
shared; compare figures only at similar load).
"""

from __future__ import annotations

import argparse
import os
import shutil
import tempfile
import time

import numpy as np
import xarray as xr

from robobore.study.conditions import SweepConfig, expand_conditions
from robobore.study.sweep import SweepPlan, run_sweep


def null_runner(condition, context):
    t = np.linspace(0.0, 1.0, 200)
    return xr.Dataset(
        {"z_um": ("time_s", np.sin(t * condition["speed_rpm"])),
         "force_amplitude_x_N": ((), 1.0), "feed_amplitude_um": ((), 2.0),
         "stable": ((), True)},
        coords={"time_s": t},
    )


def plan(n: int, runner: str = "demo") -> SweepPlan:
    speeds = list(np.linspace(200, 1000, max(1, n // 4)).round(6))
    cfg = SweepConfig.model_validate({
        "sweep": {"name": "bench", "runner": runner},
        "grid": {"speed_rpm": speeds, "feed_mm_per_rev": [0.1, 0.3],
                 "depth_of_cut_mm": [0.05, 0.2]},
        "model": {"duration_s": 2.0},
    })
    return SweepPlan.from_config(cfg, expand_conditions(cfg))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=400, help="conditions per run")
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args()
    p = plan(args.n)
    modes = [
        ("serial, store only", dict(workers=0)),
        (f"dask threads x{args.workers}", dict(workers=args.workers, processes=False)),
        (f"dask processes x{args.workers}", dict(workers=args.workers, processes=True)),
    ]
    print(f"{len(p.items)} conditions per run; load average {os.getloadavg()[0]:.2f} "
          f"on {os.cpu_count()} CPUs")
    for runner_name, fn in (("null runner (overhead)", null_runner), ("demo runner", None)):
        for label, kw in modes:
            d = tempfile.mkdtemp(prefix="robobore-bench-")
            try:
                t0 = time.perf_counter()
                out = run_sweep(p, d, runner=fn, **kw)
                wall = time.perf_counter() - t0
                t1 = time.perf_counter()
                again = run_sweep(p, d, runner=fn, **kw)  # resume: everything skipped
                skip = time.perf_counter() - t1
                assert out.computed == len(p.items) and again.skipped == len(p.items)
                print(f"{runner_name:24s} {label:22s} {len(p.items) / wall:8.1f} conditions/s "
                      f"(wall {wall:6.2f} s incl. cluster start; resume check "
                      f"{skip:5.2f} s; load {os.getloadavg()[0]:.2f})")
            finally:
                shutil.rmtree(d, ignore_errors=True)


if __name__ == "__main__":
    main()
