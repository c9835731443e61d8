"""Benchmark of ``calibrate dynamics`` (not a test): the SYNTHETIC validation over seeds.

Truth robot (robobore.dynamics.calibrate_synthetic): the example robot of
examples/boring_paper.toml with damping x0.6 in every direction and the x stiffness x1.3;
12 observed cuts per seed (one speed per twelfth of 200-3000 r/min, depth within x/ 1.35 of
the truth's limit, labels flipped with probability 0.1); 24 held-out speeds. What the same
cuts carry: ``verdicts`` (chatter or stable only), ``frequency`` (verdicts, and the chatter
cuts' chatter frequency with 1 % measurement noise), ``amplitude`` (verdicts, and the stable
cuts' feed amplitude with 5 % + 0.1 um measurement noise), ``frequency+amplitude`` (all of
them); ``both``: the verdicts and the amplitude runs. Prints per configuration, per seed and
over all seeds: the share of held-out speeds whose corrected median critical depth is within
10 % of the truth (goal: all) beside the share the band's own width forecasts
(calibrate_synthetic.within_10pct_share), the 90 % band's coverage of the truth (goal >= 85 %),
the median relative error of the corrected and the uncorrected model, and the calibration's wall
and CPU time on 12 observations (goal: under 1 min on 2 cores).

Run: NUMBA_NUM_THREADS=1 python benchmarks/bench_calibrate.py [--seeds 10] [--first 0]
     [--observed verdicts|frequency|amplitude|frequency+amplitude|both] [--json FILE]
     [--plot DIR] [--design stratified|sequential] [--criterion mean|point]

``--design sequential``: the first 4 cuts stratified over quarters of the range, then 8 cuts
proposed one at a time from the posterior of the cuts so far (robobore.dynamics.design,
``--criterion``); the
wall and CPU time of the design's 8 calibrations is printed beside the last one's.
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

import numpy as np

from robobore.dynamics.band import critical_depths
from robobore.dynamics.calibrate import Observation, build_problem
from robobore.dynamics.calibrate_synthetic import truth_structure, validate_seed, validation_case
from robobore.dynamics.config import load_dynamics_config

ROOT = Path(__file__).resolve().parents[1]


def print_figures(w, wu, we, c, ec, eu) -> None:
    """The validation's figures over the seeds: per-seed shares within 10 % of the truth
    (corrected ``w``, uncorrected ``wu``, the band's forecast ``we``), coverage ``c`` and
    median errors (corrected ``ec``, uncorrected ``eu``), each an array over the seeds."""
    print(f"  corrected within 10 % of the truth: {w.mean():.1%} of speeds "
          f"(seeds: min {w.min():.0%}, median {np.median(w):.0%}); uncorrected: {wu.mean():.1%}; "
          f"the band's own forecast: {we.mean():.1%}")
    print(f"  90 % band covers the truth: {c.mean():.1%} (seeds: min {c.min():.0%})")
    print(f"  median relative error: corrected {np.median(ec):.3f}, uncorrected "
          f"{np.median(eu):.3f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--first", type=int, default=0)
    ap.add_argument("--config", default=str(ROOT / "examples" / "boring_paper.toml"))
    ap.add_argument("--observed", choices=("verdicts", "frequency", "amplitude",
                                            "frequency+amplitude", "both"),
                    default="frequency+amplitude",
                    help="what the cuts carry: verdicts only, verdicts + chatter frequency, "
                         "verdicts + feed amplitude, all of them; both: the verdicts and the "
                         "amplitude runs")
    ap.add_argument("--design", choices=("stratified", "sequential"), default="stratified",
                    help="the cuts' design: stratified (one per twelfth of the range) or "
                         "sequential (4 stratified, 8 proposed from the posterior)")
    ap.add_argument("--criterion", choices=("mean", "point"), default="mean",
                    help="the sequential design's criterion (robobore.dynamics.design): mean "
                         "marginal information over the speeds, or the verdict's information "
                         "at the cut's speed")
    ap.add_argument("--json", default=None, help="write the per-seed results here")
    ap.add_argument("--plot", default=None, help="write the first seed's band figure here")
    args = ap.parse_args()
    cfg, _ = load_dynamics_config(args.config)
    configs = {"verdicts": [(False, False)], "frequency": [(False, True)],
               "amplitude": [(True, False)], "frequency+amplitude": [(True, True)],
               "both": [(False, False), (True, False)]}[args.observed]
    out = []
    for amp, freq in configs:
        out += run_config(cfg, args, amp, freq)
    if args.json:
        Path(args.json).write_text(json.dumps(out, indent=2) + "\n")


def run_config(cfg, args, amp: bool, freq: bool = False) -> list[dict]:
    label = {(False, False): "verdicts only", (True, False): "verdicts + feed amplitude",
             (False, True): "verdicts + chatter frequency",
             (True, True): "verdicts + chatter frequency + feed amplitude"}[(amp, freq)]
    if args.plot:
        case = validation_case(cfg, args.first, feed_amplitude=amp, chatter_frequency=freq,
                               design=args.design, criterion=args.criterion)
        from robobore.dynamics.plots import plot_band

        cal = case["calibration"]
        tag = (("_frequency" if freq else "") + ("_amplitude" if amp else "")
               + ("_sequential" if args.design == "sequential" else ""))
        p = plot_band(cal.band, args.plot, cal.nominal_m, case["observations"],
                      name=f"calibrate_synthetic_seed{args.first}{tag}.png",
                      truth_m=case["truth"],
                      title=f"SYNTHETIC seed {args.first} ({label}): corrected lobes, 90 % band, "
                            "truth")
        print(f"figure: {p}")
    else:  # compiles the kernels (numba cache) before the timed runs
        pb = build_problem(cfg, [Observation(1, 1e3, 1e-3, False)])
        critical_depths(truth_structure(pb.structure), pb.process, np.array([1e3]))
    runs = []
    crit = f", criterion {args.criterion}" if args.design == "sequential" else ""
    print(f"SYNTHETIC calibration validation ({label}; {args.design} design{crit}), "
          f"{args.config}, NUMBA_NUM_THREADS="
          f"{os.environ.get('NUMBA_NUM_THREADS', '-')}, {os.cpu_count()} CPUs, load average "
          f"{os.getloadavg()[0]:.1f}")
    print(f"{'seed':>4} {'within10%':>9} {'forecast':>8} {'cover90':>8} {'err corr':>8} "
          f"{'err nom':>8} {'flip':>4} {'wall s':>7} {'cpu s':>6} {'design wall':>11} "
          f"{'design cpu':>10}")
    for seed in range(args.first, args.first + args.seeds):
        r = validate_seed(cfg, seed, feed_amplitude=amp, chatter_frequency=freq,
                          design=args.design, criterion=args.criterion)
        runs.append(r)
        print(f"{seed:4d} {r.within_10pct:9.2f} {r.expected_within_10pct:8.2f} "
              f"{r.coverage_90:8.2f} "
              f"{r.median_error_corrected:8.3f} {r.median_error_uncorrected:8.3f} "
              f"{r.flipped:4d} {r.seconds:7.1f} {r.cpu_seconds:6.1f} {r.design_seconds:11.1f} "
              f"{r.design_cpu_seconds:10.1f}", flush=True)
    w = np.array([r.within_10pct for r in runs])
    c = np.array([r.coverage_90 for r in runs])
    ec = np.array([r.median_error_corrected for r in runs])
    eu = np.array([r.median_error_uncorrected for r in runs])
    wu = np.array([r.within_10pct_uncorrected for r in runs])
    we = np.array([r.expected_within_10pct for r in runs])
    t = np.array([r.seconds for r in runs])
    cpu = np.array([r.cpu_seconds for r in runs])
    print(f"{label} ({args.design} design), over {len(runs)} seeds x 24 held-out speeds:")
    print_figures(w, wu, we, c, ec, eu)
    print(f"  calibrate (12 observations, band at 24 speeds): wall {np.median(t):.1f} s median "
          f"(max {t.max():.1f}), CPU {np.median(cpu):.1f} s median; "
          f"{len(runs) / t.sum() * 60:.2f} calibrations per minute")
    if args.design == "sequential":
        dw = np.array([r.design_seconds for r in runs])
        dc = np.array([r.design_cpu_seconds for r in runs])
        print(f"  sequential design (8 calibrations on 4-11 cuts, band at 28 candidate speeds): "
              f"wall {np.median(dw):.1f} s median (max {dw.max():.1f}), CPU "
              f"{np.median(dc):.1f} s median")
    return [r.to_dict() for r in runs]


if __name__ == "__main__":
    main()
