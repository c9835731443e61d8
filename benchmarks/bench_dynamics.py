"""Benchmarks of the process stage (not tests): prints throughput.

1. Time-domain simulation: 100 revolutions x 2000 samples/rev with 5 tool-point modes
   (the robot's modal example), both for the single-point contract and the boring bar
   (24 edge elements). Target: < 0.5 s after compilation.
2. Frequency-domain lobe map: critical depth at 600 spindle speeds and the 600 x 200
   (speed x depth) stability map, 5 modes. Target: < 5 s on 2 cores.

3. ``--reference-tree PATH``: ``simulate boring`` runs (``robobore.dynamics.api.run_boring``
   with the config's own sampling and run length) of examples/boring_paper.toml at the
   ``CONDITIONS``, this tree against another checkout's ``src`` in subprocesses, alternated
   ``--pairs`` times; prints the median wall time of each tree, the samples per revolution
   and revolutions each chose, and the ratio of the medians (the trees share the load), of the
   wall time and of the process's CPU time (less sensitive to other work on the cores).

Run: python benchmarks/bench_dynamics.py [--reference-tree ../ref] [--pairs 3]
(note the machine load, `uptime`, with the figures)
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from robobore.cutting.coefficient_sets import ti64_coefficients
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


ROOT = Path(__file__).resolve().parents[1]
#: (speed r/min, depth mm) of the paired time-domain runs: the paper's condition, two far
#: from the example robot's limit, and 0.8 / 1.0 / 1.25 x its limit at 554 r/min (0.695 mm),
#: where growth is slow and an undecided run is lengthened
CONDITIONS = [(300.0, 0.15), (700.0, 0.1), (1000.0, 0.3), (554.3, 0.556), (554.3, 0.695),
              (554.3, 0.869)]

CHILD = r"""
import json, sys, time
from robobore.dynamics.api import run_boring
cfg, conds = sys.argv[1], json.loads(sys.argv[2])
run_boring(cfg, speed_rpm=conds[0][0], depth_mm=conds[0][1], revolutions=5)  # compile / warm
out = []
for n, a in conds:
    t, c = time.perf_counter(), time.process_time()
    s = run_boring(cfg, speed_rpm=n, depth_mm=a)
    s = s.to_dict() if hasattr(s, "to_dict") else s  # a reference tree may return the dict
    dt, dc = time.perf_counter() - t, time.process_time() - c
    out.append({"speed_rpm": n, "depth_mm": a, "wall_s": dt, "cpu_s": dc,
                "chatter": s.get("chatter"),
                "samples_per_rev": s.get("samples_per_rev"),
                "revolutions": s.get("revolutions_simulated", s.get("revolutions"))})
print("RESULT" + json.dumps(out))
"""


def timedomain_run(tree: Path) -> list[dict]:
    env = {**os.environ, "PYTHONPATH": str(tree / "src"), "NUMBA_NUM_THREADS": "1",
           "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
    out = subprocess.run([sys.executable, "-c", CHILD, str(ROOT / "examples" / "boring_paper.toml"),
                          json.dumps(CONDITIONS)], env=env, capture_output=True, text=True,
                         check=True)
    line = [ln for ln in out.stdout.splitlines() if ln.startswith("RESULT")][-1]
    return json.loads(line[len("RESULT"):])


def paired_timedomain(ref: Path, pairs: int) -> None:
    load = os.getloadavg()[0]
    mine, theirs = [], []
    for _ in range(pairs):
        mine.append(timedomain_run(ROOT))
        theirs.append(timedomain_run(ref))
    print(f"simulate boring, examples/boring_paper.toml, {pairs} alternated pairs, "
          f"load {load:.1f}:")
    tot_m = [sum(r["wall_s"] for r in run) for run in mine]
    tot_r = [sum(r["wall_s"] for r in run) for run in theirs]
    for i, (n, a) in enumerate(CONDITIONS):
        m = statistics.median(run[i]["wall_s"] for run in mine)
        r = statistics.median(run[i]["wall_s"] for run in theirs)
        cm = statistics.median(run[i]["cpu_s"] for run in mine)
        cr = statistics.median(run[i]["cpu_s"] for run in theirs)
        print(f"  {n:6.0f} r/min {a:.2f} mm: this tree {m:.2f} s "
              f"({mine[0][i]['samples_per_rev']} samples/rev x {mine[0][i]['revolutions']} rev,"
              f" chatter {mine[0][i]['chatter']}), reference {r:.2f} s "
              f"({theirs[0][i]['samples_per_rev']} x {theirs[0][i]['revolutions']}, chatter "
              f"{theirs[0][i]['chatter']}); this/reference {m / r:.2f} (CPU time {cm / cr:.2f})")
    cpu_m = statistics.median(sum(r["cpu_s"] for r in run) for run in mine)
    cpu_r = statistics.median(sum(r["cpu_s"] for r in run) for run in theirs)
    print(f"  all: this tree {statistics.median(tot_m):.2f} s, reference "
          f"{statistics.median(tot_r):.2f} s; this/reference "
          f"{statistics.median(tot_m) / statistics.median(tot_r):.2f} (CPU time "
          f"{cpu_m / cpu_r:.2f})")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reference-tree", type=Path, default=None)
    ap.add_argument("--pairs", type=int, default=3)
    a = ap.parse_args()
    if a.reference_tree is not None:
        paired_timedomain(a.reference_tree, a.pairs)
        return
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
