"""Benchmarks of the measure stage (not tests): prints time and, with ``--accuracy N``, the
confusion table of chatter detection on N SYNTHETIC records of the time-domain simulation.

1. ``detect_chatter`` on a 30 s, 10 kHz, 3-channel SYNTHETIC record (robobore.measure.synthetic),
   without and with the spindle speed. Target: < 1 s on one core after the first run.
2. ``--accuracy N [--seed S]``: records ``S .. S + N - 1``, labelled by the simulation's verdict
   (robobore.dynamics.chatter.classify): confusion table, share right, chatter-frequency error
   against the simulation's chatter frequency (target: >= 98 % right, within 2 %).
   ``--low-speed``: the records of the low-speed regime (robobore.measure.synthetic.LOW_SPEED:
   150-1000 r/min, 8 s, half of them with a once-per-revolution interruption of the cut).
   ``--speed-wander W``: the spindle speed wanders with a relative standard deviation W
   (robobore.measure.synthetic, "Speed wander").

Run: NUMBA_NUM_THREADS=1 python benchmarks/bench_measure.py [--accuracy 200] [--low-speed]
[--speed-wander 0.003]
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from robobore.measure.detect import DetectSettings, detect_chatter
from robobore.measure.synthetic import LOW_SPEED, simulated_record


def best_of(fn, repeat=5):
    ts = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t)
    return min(ts)


def speed() -> None:
    rec = simulated_record(7, duration_s=30.0, n_channels=3)
    n = rec.truth["speed_rpm"]
    t = time.perf_counter()
    detect_chatter(rec)
    first = time.perf_counter() - t
    print(f"record: {rec.n_channels} channels x {rec.n_samples} samples "
          f"({rec.duration_s:g} s at {rec.sample_rate_Hz:g} Hz), SYNTHETIC, "
          f"chatter = {rec.truth['chatter']}")
    print(f"detect chatter, first run: {first:.3f} s")
    for label, st in (("speed estimated", DetectSettings()),
                      ("speed given", DetectSettings(speed_rpm=n))):
        dt = best_of(lambda st=st: detect_chatter(rec, st))
        print(f"detect chatter, {label}: {dt:.3f} s "
              f"({rec.n_channels * rec.n_samples / dt / 1e6:.1f} M samples/s; target < 1 s)")


def accuracy(n: int, seed: int, **kw) -> None:
    for given in (False, True):
        conf = {"chatter, detected": 0, "chatter, missed": 0, "stable, called chatter": 0,
                "stable, right": 0}
        ferr, bad = [], []
        for s in range(seed, seed + n):
            r = simulated_record(s, **kw)
            tr = r.truth
            d = detect_chatter(r, DetectSettings(speed_rpm=tr["speed_rpm"] if given else None,
                                                 n_inserts=tr["n_inserts"]))
            if tr["chatter"]:
                conf["chatter, detected" if d.chatter else "chatter, missed"] += 1
                if d.chatter:
                    ferr.append(abs(d.chatter_frequency_Hz / tr["chatter_frequency_Hz"] - 1))
            else:
                conf["stable, called chatter" if d.chatter else "stable, right"] += 1
            if d.chatter != tr["chatter"]:
                bad.append(s if "speed_range_rpm" not in kw
                           else f"{s} ({tr['speed_rpm']:.0f} r/min)")
        right = (conf["chatter, detected"] + conf["stable, right"]) / n
        fe = np.array(ferr)
        regime = ", low-speed regime" if "speed_range_rpm" in kw else ""
        if kw.get("speed_wander"):
            regime += f", speed wander {kw['speed_wander']:g}"
        print(f"\nspeed {'given' if given else 'not given'}: {n} records (seeds {seed}.."
              f"{seed + n - 1}{regime}), right {100 * right:.1f} %")
        print(f"  {'':16s}{'detected chatter':>18s}{'detected stable':>18s}")
        print(f"  {'truth chatter':16s}{conf['chatter, detected']:>18d}"
              f"{conf['chatter, missed']:>18d}")
        print(f"  {'truth stable':16s}{conf['stable, called chatter']:>18d}"
              f"{conf['stable, right']:>18d}")
        if fe.size:
            print(f"  chatter frequency error: median {100 * np.median(fe):.3f} %, max "
                  f"{100 * fe.max():.3f} %, within 2 %: {100 * np.mean(fe <= 0.02):.1f} %")
        print(f"  wrong: seeds {bad}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--accuracy", type=int, default=0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--low-speed", action="store_true")
    ap.add_argument("--speed-wander", type=float, default=0.0)
    ap.add_argument("--no-speed-run", action="store_true", help="skip the timing")
    a = ap.parse_args()
    print(f"NUMBA_NUM_THREADS={os.environ.get('NUMBA_NUM_THREADS', '(default)')}, "
          f"load {os.getloadavg()[0]:.2f}")
    if not a.no_speed_run:
        speed()
    if a.accuracy:
        kw = dict(LOW_SPEED) if a.low_speed else {}
        if a.speed_wander:
            kw["speed_wander"] = a.speed_wander
        accuracy(a.accuracy, a.seed, **kw)
