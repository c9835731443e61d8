"""Semi-discretisation lobes per speed on the example robot (examples/boring_paper.toml).

Prints the wall time and the CPU time (``time.process_time``, less sensitive to the load of
other jobs) per speed of ``lobes_semidiscretization`` over ``--speeds`` speeds of 150-1100
r/min (one BLAS thread, numba compiled beforehand) and the machine's load; with
``--reference-tree PATH`` the same run of another checkout's ``src`` in a subprocess,
alternated ``--pairs`` times, and the ratios of the medians (the two trees share the
machine's load). With ``--depth-tree PATH`` (a checkout of the same model,
e.g. main) the largest relative change of the finite critical depths against that tree's and
whether the same speeds are 0 / stable up to the scan top.

    python benchmarks/bench_lobes_sd.py [--speeds 48] [--reference-tree ../b2e27da] [--pairs 3]
                                        [--depth-tree ../main]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CHILD = r"""
import json, sys, time
import numpy as np
from robobore.dynamics.config import build_process, build_structure, load_dynamics_config
from robobore.dynamics.stability import lobes_semidiscretization
cfg, _ = load_dynamics_config(sys.argv[1])
st, pr = build_structure(cfg), build_process(cfg)
sp = np.linspace(150.0, 1100.0, int(sys.argv[2]))
lobes_semidiscretization(st, pr, sp[:2])
t, c = time.perf_counter(), time.process_time()
L = lobes_semidiscretization(st, pr, sp)
dt, dc = time.perf_counter() - t, time.process_time() - c
print("RESULT" + json.dumps({"ms_per_speed": 1e3 * dt / sp.size,
                             "cpu_ms_per_speed": 1e3 * dc / sp.size,
                             "critical_depth_mm": (L.critical_depth_m * 1e3).tolist()}))
"""


def run(tree: Path, speeds: int) -> dict:
    env = {**os.environ, "PYTHONPATH": str(tree / "src"), "NUMBA_NUM_THREADS": "1",
           "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
    out = subprocess.run([sys.executable, "-c", CHILD, str(ROOT / "examples" / "boring_paper.toml"),
                          str(speeds)], env=env, capture_output=True, text=True, check=True)
    line = [ln for ln in out.stdout.splitlines() if ln.startswith("RESULT")][-1]
    return json.loads(line[len("RESULT"):])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speeds", type=int, default=48)
    ap.add_argument("--reference-tree", type=Path, default=None)
    ap.add_argument("--pairs", type=int, default=3)
    ap.add_argument("--depth-tree", type=Path, default=None)
    a = ap.parse_args()
    load = os.getloadavg()[0]
    mine, ref, mine_cpu, ref_cpu = [], [], [], []
    depths = None
    for _ in range(a.pairs if a.reference_tree else 1):
        r = run(ROOT, a.speeds)
        depths = r["critical_depth_mm"]
        mine.append(r["ms_per_speed"])
        mine_cpu.append(r["cpu_ms_per_speed"])
        if a.reference_tree:
            q = run(a.reference_tree, a.speeds)
            ref.append(q["ms_per_speed"])
            ref_cpu.append(q.get("cpu_ms_per_speed", float("nan")))
    end_load = os.getloadavg()[0]

    def fmt(v):
        return ", ".join(f"{x:.1f}" for x in v)

    print(f"semi-discretisation lobes, examples/boring_paper.toml, {a.speeds} speeds "
          f"150-1100 r/min, load {load:.1f} (start) / {end_load:.1f} (end): this tree "
          f"{statistics.median(mine):.1f} ms/speed wall ({fmt(mine)}), "
          f"{statistics.median(mine_cpu):.1f} ms/speed CPU ({fmt(mine_cpu)})")
    if ref:
        print(f"reference {a.reference_tree}: {statistics.median(ref):.1f} ms/speed wall "
              f"({fmt(ref)}), {statistics.median(ref_cpu):.1f} ms/speed CPU ({fmt(ref_cpu)})")
        print(f"ratio reference/this: wall {statistics.median(ref) / statistics.median(mine):.2f}"
              f", CPU {statistics.median(ref_cpu) / statistics.median(mine_cpu):.2f}")
    if a.depth_tree is not None:
        other = run(a.depth_tree, a.speeds)["critical_depth_mm"]
        same = all((x == y) or (0 < x < 1e9 and 0 < y < 1e9)
                   for x, y in zip(depths, other, strict=True))
        rel = [abs(x / y - 1) for x, y in zip(depths, other, strict=True)
               if 0 < y < float("inf") and 0 < x < float("inf")]
        print(f"critical depths against {a.depth_tree}: max relative change "
              f"{100 * max(rel):.3f} % over {len(rel)} finite limits; same speeds at 0 / "
              f"stable: {same}")


if __name__ == "__main__":
    main()
