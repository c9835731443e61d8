"""Benchmark of operational modal analysis (robobore.modal.oma, SSI-COV): speed and accuracy.

Run:  python benchmarks/bench_oma.py [--repeats 3] [--seeds 5]

1. Speed (issue acceptance: 60 s at 2 kHz on 7 channels in under 5 s on 2 cores): the
   bundled robot truth's SYNTHETIC accelerations (7 channels, 60 s at 2048 Hz, random
   excitation), band 3-60 Hz, without and with the jackknife over segments; best of
   ``--repeats``, with the load average.
2. Accuracy over ``--seeds`` SYNTHETIC records (300 s): the IRB 6600 multibody model (band
   3-40 Hz) under random and cutting (300 r/min) excitation, the bundled robot truth (band
   3-60 Hz) under cutting at 300 r/min; max |relative error| of f and zeta per mode found.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from robobore.modal.oma import identify_operational, simulate_operational
from robobore.modal.virtual import EXAMPLE_POSTURE_DEG, robot_boring_truth
from robobore.plan.virtual_hammer import robot_truth
from robobore.robot.campaign import IRB6600_ASSUMED_JOINT_STIFFNESS_NM_PER_RAD as K


def load() -> str:
    try:
        return "load avg (1/5/15 min) " + " ".join(f"{v:.2f}" for v in os.getloadavg())
    except OSError:
        return "load avg n/a"


def bench_speed(repeats: int) -> None:
    rec = simulate_operational(robot_boring_truth(), 60.0, 2048.0, seed=0)
    print("== speed: 7 channels, 60 s at 2048 Hz, band 3-60 Hz ==")
    for unc in (False, True):
        t = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            identify_operational(rec, (3.0, 60.0), uncertainty=unc)
            t.append(time.perf_counter() - t0)
        print(f"{'with' if unc else 'without'} uncertainty: best {min(t):.3f} s, "
              f"median {np.median(t):.3f} s")
    print(load())


def bench_accuracy(seeds: int) -> None:
    irb = robot_truth("irb6600-175-2.55", EXAMPLE_POSTURE_DEG, K)[0]
    bundled = robot_boring_truth()
    cases = [("IRB 6600 multibody, random", irb, 2048.0, (3.0, 40.0), None, 3),
             ("IRB 6600 multibody, cutting 300 r/min", irb, 2048.0, (3.0, 40.0), 300.0, 3),
             ("bundled robot, cutting 300 r/min", bundled, 256.0, (3.0, 60.0), 300.0, 5)]
    print(f"\n== accuracy: 300 s records, {seeds} seeds ==")
    for name, tr, fs, band, rpm, nm in cases:
        ef, ez, found = [], [], 0
        for s in range(seeds):
            rec = simulate_operational(tr, 300.0, fs, spindle_rpm=rpm, seed=100 + s)
            r = identify_operational(rec, band, spindle_rpm=rpm, uncertainty=False)
            ok = 0
            for f, z in zip(tr.frequencies_Hz[:nm], tr.damping_ratios[:nm], strict=True):
                k = int(np.argmin(np.abs(r.frequencies_Hz - f)))
                if abs(r.frequencies_Hz[k] / f - 1) < 0.02:
                    ok += 1
                    ef.append(abs(r.frequencies_Hz[k] / f - 1))
                    ez.append(abs(r.damping_ratios[k] / z - 1))
            found += ok == nm
        print(f"{name:40s}: all {nm} modes in {found}/{seeds}; max |df/f| "
              f"{100 * max(ef):.2f} %, max |dzeta/zeta| {100 * max(ez):.1f} %")
    print(load())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--seeds", type=int, default=5)
    a = ap.parse_args()
    bench_speed(a.repeats)
    bench_accuracy(a.seeds)


if __name__ == "__main__":
    main()
