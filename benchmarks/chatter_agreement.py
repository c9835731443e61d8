"""Lobes against the time domain on random SYNTHETIC boring cuts (robobore.dynamics.crosscheck).

For each cut: the semi-discretisation critical depth a_c, then `simulate` at 0.8 a_c and
1.25 a_c at the default sampling and at twice it; the cut agrees when both 0.8 runs say no
chatter and both 1.25 runs say chatter. A critical depth of 0 (no chatter-free depth) is
checked too: the time domain at 1.25 x the depth below which the steady cut is interrupted
(or the first depth above it, in steps of 1.25, where the steady cut is in the material; at
the scan's lowest depth, 5 um, where the cut is in the material down to vanishing depth),
where the lobes say chatter, must say chatter, or the disagreement is counted and printed. ``--fixed`` checks the lobes of the process linearised
once at 0.05 mm (widths scaled with the depth) instead of the process rebuilt at each depth.

    python benchmarks/chatter_agreement.py --cuts 100 --seed 44 [--fixed] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import math
import time

import numpy as np

from robobore.dynamics.crosscheck import check_cut, random_cut


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cuts", type=int, default=100)
    ap.add_argument("--seed", type=int, default=44)
    ap.add_argument("--fixed", action="store_true",
                    help="lobes of the process linearised once at 0.05 mm")
    ap.add_argument("--revolutions", type=int, default=None)
    ap.add_argument("--json", default=None)
    a = ap.parse_args()
    rng = np.random.default_rng(a.seed)
    rows = []
    t0 = time.perf_counter()
    counts = {"agree": 0, "disagree": 0, "zero": 0, "stable": 0}
    for i in range(a.cuts):
        cut = random_cut(rng, label=f"cut {i}")
        pr = cut.process().fixed() if a.fixed else None
        res = check_cut(cut, process=pr, revolutions=a.revolutions)
        d = res.to_dict()
        rows.append(d)
        if not res.applicable:
            counts["zero" if res.critical_depth_m == 0.0 else "stable"] += 1
            ic = res.interrupted_confirmed
            if ic is not None:
                counts["interrupted"] = counts.get("interrupted", 0) + 1
                counts["interrupted_confirmed"] = counts.get("interrupted_confirmed", 0) + ic
            zc = res.zero_confirmed
            if zc is not None:
                counts["zero_checked"] = counts.get("zero_checked", 0) + 1
                counts["zero_confirmed"] = counts.get("zero_confirmed", 0) + zc
                if not zc:
                    z = [r for r in res.runs if r.get("zero_check")][0]
                    print(f"{cut.label}: n {cut.speed_rpm:.0f} f {cut.feed_per_rev_m * 1e3:.3f} "
                          f"r {cut.insert.nose_radius_m * 1e3:.2f} limit 0 (interrupted "
                          f"below {res.interrupted_below_m * 1e3:.4g} mm) -> time domain at "
                          f"{z['depth_mm']:.4g} mm: no chatter (multiplier "
                          f"{z['floquet_multiplier']:.4f}, decided {z['decided']}, tool leaves "
                          f"the cut {z['tool_leaves_cut']}; SD radius "
                          f"{z['sd_spectral_radius']:.4f})", flush=True)
            continue
        counts["agree" if res.agrees else "disagree"] += 1
        counts["nonlinear"] = counts.get("nonlinear", 0) + int(res.nonlinear)
        counts["undecided"] = counts.get("undecided", 0) + sum(not r["decided"]
                                                              for r in res.runs)
        if not res.agrees:
            bad = [(r["factor"], r["sampling"], r["chatter"], r["decided"],
                    round(r["floquet_multiplier"], 4), r["tool_leaves_cut"]) for r in res.runs]
            print(f"{cut.label}: n {cut.speed_rpm:.0f} f {cut.feed_per_rev_m * 1e3:.3f} "
                  f"r {cut.insert.nose_radius_m * 1e3:.2f} a_c {res.critical_depth_m * 1e3:.4g} mm "
                  f"f_n {np.round(cut.structure.frequency_Hz, 1).tolist()} -> {bad}", flush=True)
    dt = time.perf_counter() - t0
    n_app = counts["agree"] + counts["disagree"]
    strict = sum(1 for r in rows if r["agrees"] is not None
                 and all(x["chatter"] == (x["factor"] > 1.0) for x in r["runs"]))
    print(f"verdicts on the side of the limit without the nonlinear exemption: {strict}/{n_app}; "
          f"limit 0 because the steady cut is interrupted up to the linear limit: "
          f"{counts.get('interrupted', 0)} (time domain finds the tool leaving the cut below "
          f"it: {counts.get('interrupted_confirmed', 0)})")
    print(f"limit 0 checked by the time domain where the lobes say chatter: "
          f"{counts.get('zero_checked', 0)}, it says chatter on "
          f"{counts.get('zero_confirmed', 0)} (disagree: "
          f"{counts.get('zero_checked', 0) - counts.get('zero_confirmed', 0)})")
    print(f"lobes: {'fixed at 0.05 mm' if a.fixed else 'rebuilt at each depth'}; "
          f"{a.cuts} cuts (seed {a.seed}), {n_app} with a finite limit: agree "
          f"{counts['agree']}/{n_app}; limit 0: {counts['zero']}, stable to 50 mm: "
          f"{counts['stable']}; runs where the tool leaves the cut in "
          f"{counts.get('nonlinear', 0)} cuts; undecided runs {counts.get('undecided', 0)}; "
          f"{dt:.1f} s")
    if a.json:
        with open(a.json, "w") as fh:
            json.dump({"counts": counts, "seconds": dt, "rows": rows}, fh, indent=1,
                      default=lambda o: None if isinstance(o, float) and not math.isfinite(o)
                      else str(o))


if __name__ == "__main__":
    main()
