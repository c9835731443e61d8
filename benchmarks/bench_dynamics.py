"""Benchmarks of the process stage (not tests): prints throughput.

1. Time-domain simulation: 100 revolutions x 2000 samples/rev with 5 tool-point modes
   (the robot's modal example), both for the single-point contract and the boring bar
   (24 edge elements). Target: < 0.5 s after compilation.
2. Frequency-domain lobe map: critical depth at 600 spindle speeds and the 600 x 200
   (speed x depth) stability map, 5 modes. Target: < 5 s on 2 cores.

Run: python benchmarks/bench_dynamics.py   (note the machine load, `uptime`, with the figures)
"""

from __future__ import annotations

import os
import time

import numpy as np

from robobore.cutting.forces import ti64_coefficients
from robobore.cutting.geometry import BoringInsert
from robobore.dynamics.process import boring_process, single_point_process
from robobore.dynamics.stability import lobes_frequency_domain
from robobore.dynamics.structure import ToolPointStructure
from robobore.dynamics.timedomain import SimulationSettings, simulate

F = [6.9, 16.8, 24.6, 25.34, 47.5]
Z = [0.035, 0.028, 0.020, 0.022, 0.050]
DIRS = [[1, 0, 0], [0, 1, 0], [0, 0, 1], [0.6, 0.8, 0], [0, 0.6, 0.8]]


def structure() -> ToolPointStructure:
    return ToolPointStructure.from_modes([
        {"frequency_Hz": f, "damping_ratio": z, "stiffness_N_per_m": 3e6, "direction": d}
        for f, z, d in zip(F, Z, DIRS, strict=True)])


def best_of(fn, repeat=5):
    ts = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t)
    return min(ts), float(np.median(ts))


def main() -> None:
    print(f"load average: {os.getloadavg()}, cpus: {os.cpu_count()}")
    st = structure()
    procs = {
        "single-point": single_point_process(1e9, [0.8, 0.6, 0], [1, 0, 0], 1e-4),
        "boring (24 elements)": boring_process(BoringInsert(), ti64_coefficients(30.0), 0.05e-3,
                                               0.15e-3, n_elements=24),
    }
    for name, pr in procs.items():
        s = SimulationSettings(300.0, 0.05e-3, 100, 2000)
        simulate(st, pr, s)  # compile / warm
        best, med = best_of(lambda pr=pr, s=s: simulate(st, pr, s))
        steps = 100 * 2000
        print(f"time domain [{name}]: 100 rev x 2000 samples, 5 modes: best {best:.3f} s, "
              f"median {med:.3f} s ({steps / best / 1e6:.2f} M steps/s)  target < 0.5 s")
    speeds = np.linspace(100.0, 3000.0, 600)
    depths = np.linspace(0.0, 0.5e-3, 200)
    for name, pr in procs.items():
        lobes_frequency_domain(st, pr, speeds)  # compile / warm

        def lobe_map(pr=pr):
            r = lobes_frequency_domain(st, pr, speeds)
            return depths[None, :] < r.critical_depth_m[:, None]  # (600, 200) stable map

        best, med = best_of(lobe_map, 3)
        print(f"lobe map [{name}]: 600 speeds x 200 depths, 5 modes: best {best:.3f} s, "
              f"median {med:.3f} s  target < 5 s")


if __name__ == "__main__":
    main()
