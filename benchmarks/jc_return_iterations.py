"""Newton iterations of the Johnson-Cook return (``johnson_cook.jc_return_py``) from its two
possible starts, over states drawn from the range of a cut, and the compiled return's speed.

The package solves q - 3 G d - sigma_y(eps_p + d, d / dt, T) = 0 by a safeguarded Newton
method. Until session 14 it started at the perfectly plastic increment (q - sigma_y0) / (3 G);
it now starts at the smaller of that and dt eps0 exp((q / sigma_y0 - 1) / C) (docs/fe.md,
"A faster Johnson-Cook return"). This script carries a counting transcription of the solve
with either start (``_solve``), checks that its current-start root equals the compiled
package return's for every sample, and prints the mean and largest iteration counts of
both starts and the package's returns per second. TC4 constants of the material library.

    python benchmarks/jc_return_iterations.py [--samples 20000] [--seed 0]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from numba import njit

from robobore.material import johnson_cook as jc
from robobore.material.library import load_material


def _solve(q, ep0, T, dt, G, a, b, n, c, m, e0, tr, tm, start):
    """Counting transcription of jc_return_py; returns (d, iterations)."""
    therm = 1.0 - min(max((T - tr) / (tm - tr), 0.0), 1.0) ** m
    sy0 = (a + b * max(ep0, 0.0) ** n) * therm
    if q <= sy0:
        return 0.0, 0
    lo, hi = 0.0, q / (3.0 * G)
    d = (q - sy0) / (3.0 * G)
    if start == "current" and c > 0.0:
        x = (q / sy0 - 1.0) / c
        if x < 700.0:
            d = min(d, dt * e0 * math.exp(x))
    for it in range(60):
        ep = ep0 + d
        epn = ep**n
        hard = a + b * epn
        r = d / (dt * e0)
        rate = 1.0 + c * math.log(r) if r > 1.0 else 1.0
        f = q - 3.0 * G * d - hard * rate * therm
        if f == 0.0 and start == "current":
            return d, it + 1
        if f > 0.0:
            lo = d
        else:
            hi = d
        dhard = n * b * epn / ep if ep > 1e-12 else 1e12 * b
        fp = -3.0 * G - (dhard * rate + hard * (c / d if r > 1.0 else 0.0)) * therm
        dn = d - f / fp
        if not (lo < dn < hi):
            dn = 0.5 * (lo + hi)
        if abs(dn - d) <= 1e-14 + 1e-12 * d:
            return dn, it + 1
        d = dn
    return d, 60


@njit(cache=True)
def _returns(q, ep, T, dt, G, a, b, n, c, m, e0, tr, tm, out):
    for i in range(q.shape[0]):
        out[i] = jc.jc_return(q[i], ep[i], T[i], dt[i], G, a, b, n, c, m, e0, tr, tm)[0]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=20000)
    ap.add_argument("--seed", type=int, default=0)
    a_ = ap.parse_args()
    mt = load_material("TC4")
    G = mt.G
    k = (mt.A, mt.B, mt.n, mt.C, mt.m, mt.eps_dot0, mt.T_room, mt.T_melt)
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
        res = [_solve(q[i], ep[i], T[i], dt[i], G, *k, start) for i in range(N)]
        its = np.array([r[1] for r in res])
        dd = np.array([r[0] for r in res])
        rel = float(np.max(np.abs(dd - d_true) / d_true))
        print(f"start {start:17s}: iterations mean {its.mean():5.2f}, max {its.max():2d}; "
              f"largest |d - d_true| / d_true {rel:.1e}")
        if start == "current":
            same = float(np.max(np.abs(dd - out) / out))
            print(f"package jc_return vs this transcription: largest relative difference "
                  f"{same:.1e}")
    print(f"package jc_return (compiled, serial): {N / wall / 1e6:.2f} million returns/s")


if __name__ == "__main__":
    main()
