"""FE throughput of this checkout against another git revision, measured in the same run.

    python benchmarks/bench_fe_before_after.py --ref REV [--repeats 3] [--json OUT]
        [--cases CASE ...] [--paired [--paired-length X]]

Builds REV in a temporary git worktree and runs the same cases on both trees, interleaved
(ref, this, ref, this, ...) so that a change of machine load hits both alike: the 2D contract
config (`examples/fe_orthogonal.toml`, 0.3 mm) and the 3D paper condition
(`examples/fe_boring_paper.toml` on the workpiece frame at mass scaling 100, 12.5 um elements,
0.05 mm of cut, no tool support). Each run
is a fresh `python -m robobore fe orthogonal|boring CONFIG --json` process with PYTHONPATH on
that tree's `src` and a numba cache of its own in a temporary folder (numba checks a cached
function against its own source file only, so a checkout's `__pycache__` can hold code compiled
against an older version of a function it calls; the figures are of the trees as they are); one
short warm-up run per tree and case fills those caches first. `--cases` picks cases. Prints
the element updates per second (median of the repeats) of both trees, their ratio, and whether
the forces agree to 1e-9 (a restructure must not change them). The machine load (1-minute
average) is printed with each run: take figures with nothing else running.

`--paired`: each repeat runs the two trees at once, one numba thread each, so both see the
same machine state, and the ratio is the median of the pairs' ratios; `--paired-length X`
runs the cases' cut lengths times X. On the 2-core machine two-thread runs one after the
other move by about 4 %; the 2D contract config's pairs (0.15 mm) stay within about 1 % of
each other (the checkout against itself, `--ref HEAD`: 0.998-1.003), the 3D paper
condition's (0.1 mm) within about 2 % with an occasional outlier of 5 %: read the median of
three or more (`benchmarks/measured/fe_before_after/`).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

sys.path.insert(0, str(ROOT / "src"))
from robobore.io.config import dump_toml, load_toml  # noqa: E402

#: case -> (example, overrides, CLI subcommand, force keys)
CASES = {
    "2D contract": ("fe_orthogonal.toml", {("cut", "length_mm"): 0.3}, "orthogonal"),
    # the workpiece frame at mass scaling 100, as in the stored reference runs
    "3D paper 12.5 um": ("fe_boring_paper.toml", {("cut", "cut_length_mm"): 0.05,
                                                  ("mesh", "element_size_um"): 12.5,
                                                  ("mesh", "frame"): "workpiece",
                                                  ("solver", "mass_scaling"): 100.0},
                         "boring"),
}


def _config(case: str, tmp: Path, warmup: bool, scale: float = 1.0) -> Path:
    example, over, _ = CASES[case]
    d = load_toml(ROOT / "examples" / example)
    d.pop("tool_support", None)
    for (sec, key), v in over.items():
        d.setdefault(sec, {})[key] = v
    sec, key = next(iter(over))  # the cut length
    d[sec][key] = 0.02 if warmup else d[sec][key] * scale
    p = tmp / (case.replace(" ", "_") + ("_warm" if warmup else "") + ".toml")
    p.write_text(dump_toml(d))
    return p


def _start(tree: Path, case: str, cfg: Path, cache: Path, threads: int | None = None):
    env = dict(os.environ, PYTHONPATH=str(tree / "src"), NUMBA_CACHE_DIR=str(cache))
    if threads is not None:
        env["NUMBA_NUM_THREADS"] = str(threads)
    sub = CASES[case][2]
    return subprocess.Popen([sys.executable, "-m", "robobore", "fe", sub, str(cfg), "--json"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)


def _result(proc, tree: Path, case: str) -> dict:
    stdout, stderr = proc.communicate()
    if proc.returncode != 0:
        raise SystemExit(f"{tree}: {case} failed:\n{stderr[-3000:]}")
    r = json.loads(stdout)
    forces = (r.get("force_rotating_N")
              or {"cutting": r.get("cutting_force_N_per_mm"),
                  "feed": r.get("feed_force_N_per_mm")})
    rate = r["element_updates_per_s"]
    return {"rate": float(rate), "forces": forces, "load": os.getloadavg()[0]}


def _same_forces(fa: dict, fb: dict) -> bool:
    return all(abs(fa[k] - fb[k]) <= 1e-9 * max(abs(fa[k]), 1e-300) for k in fa)


def _run(tree: Path, case: str, cfg: Path, cache: Path) -> dict:
    return _result(_start(tree, case, cfg, cache), tree, case)


def _pair(trees: dict, case: str, cfg: Path, caches: dict) -> dict:
    # both trees at once, one numba thread each: one core each, the same machine state
    procs = {name: _start(tree, case, cfg, caches[name], threads=1)
             for name, tree in trees.items()}
    return {name: _result(p, trees[name], case) for name, p in procs.items()}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ref", required=True, help="git revision to compare with (e.g. a tag)")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--json", default=None, help="write the figures to this file")
    ap.add_argument("--cases", nargs="+", choices=list(CASES), default=list(CASES),
                    metavar="CASE", help=f"cases to run (default all: {', '.join(CASES)})")
    ap.add_argument("--paired", action="store_true",
                    help="run the two trees at once, one numba thread each (one core each), "
                    "and report the median of the pairs' ratios: steadier than two-thread "
                    "runs one after the other")
    ap.add_argument("--paired-length", type=float, default=1.0,
                    help="the cases' cut length times this (default 1)")
    a = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as t:
        tmp = Path(t)
        ref_tree = tmp / "ref"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", "-q",
                        str(ref_tree), a.ref], check=True)
        try:
            trees = {"ref": ref_tree, "this": ROOT}
            res: dict = {"ref": a.ref, "cases": {}}
            caches = {name: tmp / f"numba_{name}" for name in trees}
            for case in a.cases:
                for name, tree in trees.items():
                    _run(tree, case, _config(case, tmp, warmup=True), caches[name])
                runs: dict[str, list] = {"ref": [], "this": []}
                ratios = []
                cfg = _config(case, tmp, warmup=False, scale=a.paired_length)
                for i in range(a.repeats):
                    if a.paired:
                        pr = _pair(trees, case, cfg, caches)
                        for name in trees:
                            runs[name].append(pr[name])
                        ratios.append(pr["this"]["rate"] / pr["ref"]["rate"])
                        print(f"{case:18s} pair #{i + 1}: ref {pr['ref']['rate'] / 1e6:6.2f}, "
                              f"this {pr['this']['rate'] / 1e6:6.2f} M/s, this / ref "
                              f"{ratios[-1]:.3f}", flush=True)
                        continue
                    for name, tree in trees.items():
                        r = _run(tree, case, cfg, caches[name])
                        runs[name].append(r)
                        print(f"{case:18s} {name:4s} #{i + 1}: {r['rate'] / 1e6:6.2f} M/s "
                              f"(load {r['load']:.1f})", flush=True)
                med = {k: statistics.median(r["rate"] for r in v) for k, v in runs.items()}
                ratio = statistics.median(ratios) if a.paired else med["this"] / med["ref"]
                same = all(_same_forces(ra["forces"], rb["forces"])
                           for ra, rb in zip(runs["ref"], runs["this"], strict=True))
                res["cases"][case] = {"ref_M_per_s": med["ref"] / 1e6,
                                      "this_M_per_s": med["this"] / 1e6,
                                      "ratio": ratio, "paired": a.paired,
                                      "pair_ratios": ratios,
                                      "forces_equal_1e-9": same, "runs": runs}
                print(f"{case:18s} ref {med['ref'] / 1e6:.2f} M/s, this "
                      f"{med['this'] / 1e6:.2f} M/s, ratio {ratio:.3f}"
                      f"{' (median of the pairs)' if a.paired else ''}, "
                      f"forces equal to 1e-9: {same}", flush=True)
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force",
                            str(ref_tree)], check=False)
    if a.json:
        Path(a.json).write_text(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
