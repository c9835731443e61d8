"""Newton iterations of the Johnson-Cook return (``johnson_cook.jc_return_py``) from its two
possible starts, over states drawn from the range of a cut, and the compiled return's speed.

The package solves q - 3 G d - sigma_y(eps_p + d, d / dt, T) = 0 by a safeguarded Newton
method started at the smaller of the perfectly plastic increment (q - sigma_y0) / (3 G) and
dt eps0 exp((q / sigma_y0 - 1) / C) (docs/fe.md, "Model"); the comparison start is the
perfectly plastic increment alone. This script runs the package's own ``jc_return_py`` as
Python with a counting ``abs`` bound in (one call per iteration) and, for the comparison
start, a ``math.exp`` that answers infinity (``_solve``); it checks that the current start's
root equals the compiled return's for every sample, and prints the mean and largest
iteration counts of both starts and the compiled return's speed. TC4 constants of the
material library.

    python benchmarks/jc_return_iterations.py [--samples 20000] [--seed 0]
"""

from __future__ import annotations

import argparse
import math
import time
import types

import numpy as np
from numba import njit

from robobore.material import johnson_cook as jc
from robobore.material.library import load_material


class _Counter:
    """``abs`` for the instrumented solve: the solve calls it once per Newton iteration (its
    convergence test), so the calls count the iterations."""

    def __init__(self) -> None:
        self.n = 0

    def __call__(self, v):
        self.n += 1
        return abs(v)


#: ``math`` for the instrumented solve with the previous start: ``exp`` answers infinity, so the
#: rate bound never undercuts the perfectly plastic increment
_NO_RATE_BOUND = types.SimpleNamespace(log=math.log, exp=lambda x: math.inf)


def _solve(q, ep0, T, dt, G, k, start):
    """The package's own return mapping (``jc.make_jc_return`` given the plain-Python callees),
    run as Python with two of its globals swapped for instrumentation (this script only):
    ``abs`` counts the iterations, and for ``start = "perfectly_plastic"`` ``math.exp``
    answers infinity. Returns (d, iterations)."""
    count = _Counter()
    ret = jc.make_jc_return(jc_athermal=jc.jc_athermal_py,
                            homologous_temperature=jc.homologous_temperature_py)
    g = dict(ret.__globals__, abs=count)
    if start == "perfectly_plastic":
        g["math"] = _NO_RATE_BOUND
    counted = types.FunctionType(ret.__code__, g, ret.__name__, ret.__defaults__,
                                 ret.__closure__)
    d, _ = counted(q, ep0, T, dt, G, *k)
    return d, count.n


@njit(cache=True)
def _returns(q, ep, T, dt, G, a, b, n, c, m, e0, tr, tm, eh, out):
    for i in range(q.shape[0]):
        out[i] = jc.jc_return(q[i], ep[i], T[i], dt[i], G, a, b, n, c, m, e0, tr, tm, eh)[0]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=20000)
    ap.add_argument("--seed", type=int, default=0)
    a_ = ap.parse_args()
    mt = load_material("TC4")
    G = mt.G
    k = (mt.A, mt.B, mt.n, mt.C, mt.m, mt.eps_dot0, mt.T_room, mt.T_melt,
         mt.hardening_strain_limit)
    rng = np.random.default_rng(a_.seed)
    N = a_.samples
    ep = rng.uniform(0.0, 3.0, N)
    T = rng.uniform(300.0, 1100.0, N)
    log_rate = rng.uniform(2.0, 6.0, N)
    dt = 10.0 ** rng.uniform(-9.0, -8.0, N)
    d_true = 10.0 ** log_rate * dt
    q = 3.0 * G * d_true + np.array([jc.jc_flow_stress(e + d, d / s, t, *k)
                                     for e, d, s, t in zip(ep, d_true, dt, T, strict=True)])
    print(f"{N} states: plastic strain 0-3, 300-1100 K, rates 1e2-1e6 1/s, steps 1-10 ns")
    out = np.empty(N)
    _returns(q[:10], ep[:10], T[:10], dt[:10], G, *k, out[:10])  # compile / load
    t0 = time.perf_counter()
    _returns(q, ep, T, dt, G, *k, out)
    wall = time.perf_counter() - t0
    for start in ("perfectly_plastic", "current"):
        res = [_solve(q[i], ep[i], T[i], dt[i], G, k, start) for i in range(N)]
        its = np.array([r[1] for r in res])
        dd = np.array([r[0] for r in res])
        rel = float(np.max(np.abs(dd - d_true) / d_true))
        print(f"start {start:17s}: iterations mean {its.mean():5.2f}, max {its.max():2d}; "
              f"largest |d - d_true| / d_true {rel:.1e}")
        if start == "current":
            same = float(np.max(np.abs(dd - out) / out))
            print(f"compiled jc_return vs the same solve run as Python: largest relative "
                  f"difference {same:.1e}")
    print(f"package jc_return (compiled, serial): {N / wall / 1e6:.2f} million returns/s")


if __name__ == "__main__":
    main()
