"""Wall time of the main job: ``robobore paper --fast`` and ``robobore paper`` (cold cache),
with the time of each stage.

Acceptance: from a fresh install the README's first command finishes the report in under 10
minutes on 2 cores with a cold FE cache, and under 2 minutes with ``--fast``. The stage times
are the study's own records (``paper_summary.json`` ``timings_s``): stiffness identification,
modal identification, equivalent model, FE force calibration, the sweep of the conditions,
lobes, comparison and checks, report (with results.nc and the posture map), total.

Usage::

    python benchmarks/bench_paper.py [--mode fast|cold|both] [--workers 2] [--keep DIR]
                                     [--reference-tree PATH --pairs 2]

``--reference-tree PATH``: the same mode with this tree's and that checkout's ``src`` on
``PYTHONPATH``, alternated ``--pairs`` times, and the ratio of the median wall times (the two
share the machine's load).

Each mode runs the real command (``python -m robobore paper``) in a subprocess with a fresh
output folder and (cold) a fresh, empty ``ROBOBORE_CACHE_DIR`` and numba cache is NOT
cleared (a fresh install compiles the numba kernels on first use: run once in a fresh venv
for that figure). Prints the wall time, the CPU time of the whole process tree (less
sensitive to the machine's load), the per-stage timings from ``paper_summary.json``
and the load average (the machine is shared: timings are noisy).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path


ROOT = Path(__file__).resolve().parents[1]


def _tree_cpu(proc: subprocess.Popen) -> float:
    """Wait for ``proc``; the CPU time [s] (user + system) of its whole process tree, every
    process sampled every 0.1 s (processes forked by a pool server are not children that
    ``RUSAGE_CHILDREN`` would count)."""
    import psutil

    seen: dict[int, float] = {}
    root = psutil.Process(proc.pid)
    while proc.poll() is None:
        try:
            procs = [root, *root.children(recursive=True)]
        except psutil.Error:
            procs = []
        for ch in procs:
            try:
                t = ch.cpu_times()
                seen[ch.pid] = t.user + t.system
            except psutil.Error:
                pass
        time.sleep(0.1)
    return sum(seen.values())


def run(mode: str, workers: int, keep: Path | None, tree: Path = ROOT) -> dict:
    tmp = Path(tempfile.mkdtemp(prefix=f"bench-paper-{mode}-"))
    out = (keep / mode) if keep else tmp / "out"
    env = dict(os.environ)
    env["PYTHONPATH"] = str(tree / "src")
    env["ROBOBORE_CACHE_DIR"] = str(tmp / "cache")  # cold: empty FE cache
    cmd = [sys.executable, "-m", "robobore", "paper", "--out", str(out), "--json",
           "--workers", str(workers)]
    if mode == "fast":
        cmd.append("--fast")
    load0 = os.getloadavg()
    t0 = time.perf_counter()
    with tempfile.TemporaryFile("w+") as fo, tempfile.TemporaryFile("w+") as fe:
        proc = subprocess.Popen(cmd, env=env, stdout=fo, stderr=fe, text=True)
        cpu = _tree_cpu(proc)
        wall = time.perf_counter() - t0
        fo.seek(0)
        fe.seek(0)
        p = subprocess.CompletedProcess(cmd, proc.returncode, fo.read(), fe.read())
    load1 = os.getloadavg()
    if p.returncode != 0:
        print(p.stderr[-3000:], file=sys.stderr)
        raise SystemExit(f"robobore paper ({mode}) failed with exit code {p.returncode}")
    res = json.loads(p.stdout)
    return {"mode": mode, "wall_s": wall, "conditions": res["conditions"],
            "computed": res["computed"], "stable": res["stable"],
            "vibratory": res["vibratory"], "timings_s": res.get("timings_s"),
            "cpu_s": cpu, "load_before": load0, "load_after": load1}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mode", choices=("fast", "cold", "both"), default="both")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--keep", type=Path, default=None, help="keep outputs under this folder")
    ap.add_argument("--reference-tree", type=Path, default=None)
    ap.add_argument("--pairs", type=int, default=2)
    a = ap.parse_args()
    modes = ("fast", "cold") if a.mode == "both" else (a.mode,)
    if a.reference_tree is not None:
        for m in modes:
            mine, ref = [], []
            for _ in range(a.pairs):
                for tree, acc in ((ROOT, mine), (a.reference_tree, ref)):
                    r = run(m, a.workers, None, tree)
                    acc.append(r["wall_s"])
                    print(f"{m:>5} {tree}: {r['wall_s']:.1f} s (CPU of the process tree "
                          f"{r['cpu_s']:.1f} s), load "
                          f"{r['load_before'][0]:.1f} -> {r['load_after'][0]:.1f}; stages: "
                          + ", ".join(f"{k} {v:.1f} s" for k, v in (r["timings_s"] or {}).items()))
            import statistics

            print(f"{m:>5}: this tree median {statistics.median(mine):.1f} s, reference "
                  f"{statistics.median(ref):.1f} s; ratio reference/this "
                  f"{statistics.median(ref) / statistics.median(mine):.2f}")
        return
    print(f"# robobore paper wall time, {os.cpu_count()} CPUs, workers {a.workers}")
    for m in modes:
        r = run(m, a.workers, a.keep)
        per_min = 60.0 * r["computed"] / r["wall_s"]
        print(f"{m:>5}: {r['wall_s']:7.1f} s wall ({r['cpu_s']:.1f} s CPU), "
              f"{r['computed']}/{r['conditions']} conditions "
              f"({per_min:.1f} conditions/min end to end), stable {r['stable']}, "
              f"vibratory {r['vibratory']}, load {r['load_before'][0]:.1f} -> "
              f"{r['load_after'][0]:.1f}")
        print("       stages: " + ", ".join(f"{k} {v:.1f} s"
                                            for k, v in (r["timings_s"] or {}).items()))
    load = os.getloadavg()
    print(f"# load average now {load[0]:.2f} {load[1]:.2f} {load[2]:.2f} (1/5/15 min)")


if __name__ == "__main__":
    main()
