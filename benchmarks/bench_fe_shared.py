"""FE throughput on a shared machine: quiet, and beside one other CPU-bound process.

For the 2D default model (the contract config ``examples/fe_orthogonal.toml``, a shortened
cut) and the 3D boring model at the paper condition (``examples/fe_boring_paper.toml`` on the
workpiece frame at mass scaling 100, a fixed number of steps), it runs the same stretch of
simulation four ways in one process:

- ``quiet, fixed``: all of numba's threads on every chunk, nothing else running;
- ``quiet, adaptive``: the default (:class:`robobore.cutting.fe.engine.threads.ThreadGovernor`
  chooses all threads or one per chunk from the measured rate);
- ``shared, fixed`` and ``shared, adaptive``: the same with one CPU-bound competitor process
  (a Python busy loop) started before and killed after the run.

It prints element-updates per second (wall) and each run's share of the quiet adaptive run
(the default's quiet throughput). On a machine with ``c`` cores, one competitor leaves a fair
share of ``(c - 1) / c``... at most, and 1/2 on two cores. Other load on the machine distorts
every figure: the load average is printed; take figures with nothing else running.

    python benchmarks/bench_fe_shared.py [--engine 2d|3d|both] [--length-mm 0.03]
        [--steps-3d 9700] [--element-um-3d 12.5] [--threads N]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

import numba

from robobore.cutting.fe.engine.threads import ThreadGovernor

ROOT = Path(__file__).resolve().parents[1]


def _load() -> float:
    return os.getloadavg()[0]


class Competitor:
    """One CPU-bound process (a Python busy loop) for the ``with`` block."""

    def __enter__(self):
        self.p = subprocess.Popen([sys.executable, "-c", "while True: pass"])
        time.sleep(0.5)
        return self

    def __exit__(self, *exc):
        self.p.kill()
        self.p.wait()


def run_2d(length_mm: float, adaptive: bool) -> tuple[float, dict]:
    from robobore.cutting.fe.config.orthogonal import load_fe_config
    from robobore.cutting.fe.engine.chunk_driver import advance
    from robobore.cutting.fe.models.orthogonal import setup_orthogonal

    cfg = load_fe_config(ROOT / "examples" / "fe_orthogonal.toml")
    cfg.cut.length_mm = length_mm
    s = setup_orthogonal(cfg)
    st = s.state
    ne = st.conn.shape[0]
    gov = ThreadGovernor()
    t0 = time.perf_counter()
    steps = advance(st, s.t_end, chunk_steps=cfg.solver.chunk_steps, adaptive_threads=adaptive,
                    governor=gov)
    wall = time.perf_counter() - t0
    return ne * steps / wall, {"elements": ne, "steps": steps, "wall_s": wall, "gov": gov}


def run_3d(n_steps: int, element_um: float, adaptive: bool) -> tuple[float, dict]:
    from robobore.cutting.fe.config.boring3d import parse_boring_config
    from robobore.cutting.fe.engine.state3d import advance3
    from robobore.cutting.fe.models.boring3d import setup_boring
    from robobore.io.config import load_toml

    d = load_toml(ROOT / "examples" / "fe_boring_paper.toml")
    d["mesh"]["element_size_um"] = element_um
    # the workpiece frame at mass scaling 100, as in the stored measurements
    # (benchmarks/measured/fe_shared_machine/)
    d["mesh"]["frame"] = "workpiece"
    d["solver"]["mass_scaling"] = 100.0
    cfg = parse_boring_config(d)
    s = setup_boring(cfg)
    st = s.state
    t_end = st.time + n_steps * float(st.clock[1])
    gov = ThreadGovernor()
    t0 = time.perf_counter()
    steps = advance3(st, t_end, chunk_steps=cfg.solver.chunk_steps, adaptive_threads=adaptive,
                     governor=gov)
    wall = time.perf_counter() - t0
    return st.n_elements * steps / wall, {"elements": st.n_elements, "steps": steps,
                                          "wall_s": wall, "gov": gov}


def measure(label: str, fn) -> None:
    fn(True)  # warm-up: compile or load numba's cache
    runs = {}
    for shared in (False, True):
        for adaptive in (False, True):
            load0 = _load()
            if shared:
                with Competitor():
                    rate, info = fn(adaptive)
            else:
                rate, info = fn(adaptive)
            key = ("shared" if shared else "quiet") + (", adaptive" if adaptive else ", fixed")
            runs[key] = rate
            print(f"{label} {key:17s}: {rate / 1e6:6.3f} M element-updates/s  "
                  f"({info['elements']} elements x {info['steps']} steps, "
                  f"{info['wall_s']:.1f} s; load {load0:.2f} -> {_load():.2f})", flush=True)
            if adaptive:
                print("    chunks (threads:steps/s): " + " ".join(
                    f"{t}:{n / w:.0f}" for t, n, w in info["gov"].log[1:]), flush=True)
    ref = runs["quiet, adaptive"]
    print(f"{label} share of the quiet default (adaptive) run: "
          + ", ".join(f"{k} {v / ref:.2f}" for k, v in runs.items()), flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--engine", choices=("2d", "3d", "both"), default="both")
    ap.add_argument("--length-mm", type=float, default=0.03, help="2D cut length [mm]")
    ap.add_argument("--steps-3d", type=int, default=9700,
                    help="3D steps (enough chunks for the thread governor to settle)")
    ap.add_argument("--element-um-3d", type=float, default=12.5)
    ap.add_argument("--threads", type=int, default=None)
    args = ap.parse_args()
    if args.threads:
        numba.set_num_threads(args.threads)
    print(f"# FE throughput, quiet and beside one CPU-bound process: {os.cpu_count()} CPUs, "
          f"{numba.get_num_threads()} numba threads ({numba.config.THREADING_LAYER} layer)",
          flush=True)
    if args.engine in ("2d", "both"):
        measure("2D contract", lambda a: run_2d(args.length_mm, a))
    if args.engine in ("3d", "both"):
        measure("3D paper", lambda a: run_3d(args.steps_3d, args.element_um_3d, a))


if __name__ == "__main__":
    main()
