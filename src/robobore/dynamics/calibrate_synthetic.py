"""SYNTHETIC validation of :mod:`robobore.dynamics.calibrate`: observed cuts made by a known
truth robot, the calibration run on them, its corrected lobes compared with the truth's.

Ground truth (:func:`truth_structure`): the config's equivalent model (the identified example
robot of ``examples/boring_paper.toml``) with every direction's damping ratio x0.6 and the
``x`` direction's stiffness x1.3 (frequency held, as the calibration's model does).

Design of the cuts (:func:`synthetic_observations`): 12 speeds, one drawn uniformly in each of
12 equal slices of the speed range (stratified: the cuts spread over the lobes); at each speed
a depth ``a_truth(n) exp(u)``, ``u`` uniform in +-0.3 (the test cuts of an engineer who
brackets the limit within a factor 1.35 either side); the label is the truth's verdict
(chatter above its chatter limit, :func:`~robobore.dynamics.semidiscretization.chatter_limit`)
flipped with probability 0.1 (label noise).
Held-out speeds: 24 speeds drawn uniformly over the range with the same seed.

Sequential design (:func:`sequential_observations`, ``design="sequential"``): the first
:data:`N_FIRST_CUTS` (4) cuts stratified as above over quarters of the range (the seed's
first speed positions, depth factors and flips), then one cut at a time at the speed and
depth :func:`~robobore.dynamics.design.propose_cuts` proposes (criterion ``"mean"`` unless
told) from the calibration on the cuts
so far (its band at :data:`N_CANDIDATES` (28) candidate speeds, the centres of equal slices of
the range), labelled by the truth with the flip of the seed's draw for that cut; 12 cuts in
all. The seed's random streams are drawn as for the stratified design, so the held-out speeds,
the flips and the measurement noises per cut index are the same.

Feed amplitudes (``feed_amplitude=True``): every stable cut carries the feed amplitude a
grating scale measures, the truth's steady periodic orbit at the cut
(:func:`~robobore.dynamics.timedomain.nominal_cut_deflection`, half peak-to-peak of the feed
displacement) with a measurement noise of :data:`AMPLITUDE_NOISE_REL` (5 %) relative plus
:data:`AMPLITUDE_NOISE_ABS_M` (0.1 um) absolute, drawn from a second random stream of the seed
so that the cuts and the verdicts are the same with and without them; a reading below the
scale's resolution (0.1 um) is not reported. A chattering cut's
amplitude is set by the chatter's own limit cycle (the tool leaving the cut), which the linear
forced response does not predict, so chatter cuts carry none.

Chatter frequencies (``chatter_frequency=True``): every cut with the verdict chatter carries
the frequency of the truth's critical Floquet multiplier at the cut's speed and depth
(:func:`~robobore.dynamics.semidiscretization.critical_multiplier`, the branch nearest the
natural frequency of the mode that carries it: the spectrum's peak) with a relative
measurement noise of :data:`FREQUENCY_NOISE_REL` (1 %), from a third random stream of the seed.
A cut whose verdict was flipped to chatter reports the frequency of the truth's least-damped
regenerative vibration at that cut (the same multiplier, inside the unit circle).
Every observation and result made here is labelled SYNTHETIC.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from robobore.dynamics.band import critical_depths, scaled_structure
from robobore.dynamics.calibrate import LikelihoodSettings, Observation, build_problem, calibrate
from robobore.errors import ConfigError

#: The truth robot: damping factor of every direction, and one direction's stiffness factor.
TRUTH_DAMPING_FACTOR = 0.6
TRUTH_STIFFNESS_FACTOR = 1.3
TRUTH_STIFFNESS_AXIS = 0
N_CUTS = 12
N_HELD_OUT = 24
DEPTH_SPREAD_LN = 0.3
LABEL_NOISE = 0.1
#: Measurement noise of the SYNTHETIC feed amplitudes: relative, and absolute [m].
AMPLITUDE_NOISE_REL = 0.05
AMPLITUDE_NOISE_ABS_M = 1e-7
#: Relative measurement noise of the SYNTHETIC chatter frequencies.
FREQUENCY_NOISE_REL = 0.01
#: Sequential design: stratified cuts before the first proposal, and candidate speeds.
N_FIRST_CUTS = 4
N_CANDIDATES = 28


def truth_feed_amplitude(truth, process, speed_rpm: float, depth_m: float) -> float:
    """Half peak-to-peak feed (z) displacement [m] of the truth's steady cut (the orbit of
    :func:`~robobore.dynamics.timedomain.nominal_cut_deflection`)."""
    from robobore.dynamics.timedomain import nominal_cut_deflection

    pr = process.at_depth(depth_m)
    r1, r0 = nominal_cut_deflection(truth, pr, speed_rpm)
    z = depth_m * r1[:, 2] + r0[:, 2]
    return 0.5 * float(z.max() - z.min())


def truth_structure(structure):
    """The truth's structure from the identified one (module docstring)."""
    log_k = np.zeros(3)
    log_k[TRUTH_STIFFNESS_AXIS] = np.log(TRUTH_STIFFNESS_FACTOR)
    return scaled_structure(structure, np.zeros(3), np.full(3, np.log(TRUTH_DAMPING_FACTOR)),
                            log_k)


def truth_chatter_frequency(truth, process, speed_rpm: float, depth_m: float) -> float:
    """Chatter frequency [Hz] of the truth's critical Floquet multiplier at a cut (the branch
    nearest the natural frequency of the mode that carries it)."""
    from robobore.dynamics.semidiscretization import critical_multiplier

    return critical_multiplier(truth, process, speed_rpm, depth_m)[1]


def _measured(obs: list[Observation], truth, process, seed: int, feed_amplitude: bool,
              chatter_frequency: bool, first: int = 0) -> list[Observation]:
    """The cuts with what they carry besides the verdict (module docstring): ``obs[j]`` is cut
    ``first + j`` of the seed and takes that draw of its amplitude and frequency noise
    streams."""
    from dataclasses import replace

    obs = list(obs)
    if feed_amplitude:
        rng2 = np.random.default_rng([seed, 1])
        noise = rng2.standard_normal((N_CUTS, 2))
        for i, o in enumerate(obs):
            if o.chatter:
                continue
            a = truth_feed_amplitude(truth, process, o.speed_rpm, o.depth_m)
            a = (a * (1.0 + AMPLITUDE_NOISE_REL * noise[first + i, 0])
                 + AMPLITUDE_NOISE_ABS_M * noise[first + i, 1])
            if a >= AMPLITUDE_NOISE_ABS_M:
                obs[i] = replace(o, feed_amplitude_m=float(a))
    if chatter_frequency:
        rng3 = np.random.default_rng([seed, 2])
        noise = rng3.standard_normal(N_CUTS)
        for i, o in enumerate(obs):
            if not o.chatter:
                continue
            f = truth_chatter_frequency(truth, process, o.speed_rpm, o.depth_m)
            if np.isfinite(f):
                obs[i] = replace(o, chatter_frequency_Hz=float(f * (1.0 + FREQUENCY_NOISE_REL
                                                                    * noise[first + i])))
    return obs


def _draws(seed: int, speed_range: tuple[float, float], n_slices: int):
    """The seed's draws in their order: speeds (one per slice of ``n_slices``, from the first
    ``n_slices`` of :data:`N_CUTS` uniform positions), depth factors, label flips, held-out
    speeds."""
    rng = np.random.default_rng(seed)
    lo, hi = speed_range
    pos = rng.uniform(0, 1, N_CUTS)
    edges = np.linspace(lo, hi, n_slices + 1)
    speeds = edges[:-1] + pos[:n_slices] * np.diff(edges)
    factor = np.exp(rng.uniform(-DEPTH_SPREAD_LN, DEPTH_SPREAD_LN, N_CUTS))
    flip = rng.uniform(0, 1, N_CUTS) < LABEL_NOISE
    held = np.sort(rng.uniform(lo, hi, N_HELD_OUT))
    return speeds, factor, flip, held


def synthetic_observations(problem, speed_range: tuple[float, float], seed: int,
                           feed_amplitude: bool = False, chatter_frequency: bool = False
                           ) -> tuple[list[Observation], np.ndarray, np.ndarray]:
    """SYNTHETIC cuts of the truth robot (module docstring): the observations (stable cuts
    with their measured feed amplitude when ``feed_amplitude``, chatter cuts with their
    measured chatter frequency when ``chatter_frequency``), the held-out speeds and the
    truth's critical depths there [m]."""
    speeds, factor, flip, held = _draws(seed, speed_range, N_CUTS)
    truth = truth_structure(problem.structure)
    a_t = critical_depths(truth, problem.process, speeds)
    depth = a_t * factor
    chatter = depth > a_t
    obs = [Observation(i + 1, float(n), float(a), bool(c != f))
           for i, (n, a, c, f) in enumerate(zip(speeds, depth, chatter, flip, strict=True))]
    obs = _measured(obs, truth, problem.process, seed, feed_amplitude, chatter_frequency)
    return obs, held, critical_depths(truth, problem.process, held)


def candidate_speeds(speed_range: tuple[float, float] = (200.0, 3000.0),
                     count: int = N_CANDIDATES) -> np.ndarray:
    """The sequential design's candidate speeds [r/min]: the centres of ``count`` equal slices
    of the range (a fixed grid; the held-out speeds are drawn uniformly, apart from it)."""
    lo, hi = speed_range
    edges = np.linspace(lo, hi, count + 1)
    return 0.5 * (edges[:-1] + edges[1:])


def sequential_observations(config: Any, problem, speed_range: tuple[float, float], seed: int,
                            settings: LikelihoodSettings | None = None,
                            feed_amplitude: bool = False, chatter_frequency: bool = False,
                            progress: Any = None, criterion: str = "mean"
                            ) -> tuple[list[Observation], np.ndarray, np.ndarray, list]:
    """SYNTHETIC cuts of the sequential design (module docstring): :data:`N_FIRST_CUTS`
    stratified cuts (one speed per slice, the depths and flips of the seed's first draws),
    then one cut at a time proposed by :func:`~robobore.dynamics.design.propose_cuts` (its
    ``criterion``) from the
    calibration on the cuts so far (band at :func:`candidate_speeds`), labelled by the truth
    with the flip of the seed's draw for that cut. Returns the cuts, the held-out speeds (the
    stratified design's of the same seed), the truth's critical depths there [m] and the
    proposals."""
    from robobore.dynamics.design import propose_cuts

    speeds, factor, flip, held = _draws(seed, speed_range, N_FIRST_CUTS)
    truth = truth_structure(problem.structure)
    pr = problem.process
    a_t = critical_depths(truth, pr, speeds)
    obs = [Observation(i + 1, float(n), float(a * k), bool((a * k > a) != f))
           for i, (n, a, k, f) in enumerate(zip(speeds, a_t, factor[:N_FIRST_CUTS],
                                                 flip[:N_FIRST_CUTS], strict=True))]
    obs = _measured(obs, truth, pr, seed, feed_amplitude, chatter_frequency)
    grid = candidate_speeds(speed_range)
    proposals = []
    for i in range(N_FIRST_CUTS, N_CUTS):
        cal = calibrate(config, obs, settings, speeds=grid)
        cut = propose_cuts(cal, 1, criterion=criterion)[0]
        proposals.append(cut)
        a = float(critical_depths(truth, pr, np.array([cut.speed_rpm]))[0])
        new = Observation(i + 1, cut.speed_rpm, cut.depth_m, bool((cut.depth_m > a) != flip[i]))
        obs = obs + _measured([new], truth, pr, seed, feed_amplitude, chatter_frequency, i)
        if progress is not None:
            progress(i + 1)
    return obs, held, critical_depths(truth, pr, held), proposals


@dataclass(frozen=True)
class ValidationRun:
    """One seed: the fraction of held-out speeds whose corrected median critical depth is
    within 10 % of the truth, the 90 % band's coverage of the truth, the median relative error
    of the corrected and of the uncorrected model, labels flipped, the calibration's run time
    and CPU time [s], the MAP factors, whether the stable cuts carried feed amplitudes and the
    chatter cuts chatter frequencies, the share within 10 % the band itself forecasts
    (:func:`within_10pct_share`), the design of the cuts (``stratified`` or ``sequential``)
    and the wall and CPU time [s] of the sequential design's calibrations before the last
    (0 for the stratified design), the cuts (speed [r/min], depth [mm], chatter) and the
    sequential design's criterion."""

    seed: int
    within_10pct: float
    coverage_90: float
    median_error_corrected: float
    median_error_uncorrected: float
    within_10pct_uncorrected: float
    flipped: int
    seconds: float
    cpu_seconds: float
    factors: dict[str, float]
    feed_amplitude: bool = False
    chatter_frequency: bool = False
    expected_within_10pct: float = float("nan")
    design: str = "stratified"
    design_seconds: float = 0.0
    design_cpu_seconds: float = 0.0
    cuts: tuple = ()
    criterion: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {"seed": self.seed, "within_10pct": self.within_10pct,
                "coverage_90": self.coverage_90,
                "median_error_corrected": self.median_error_corrected,
                "median_error_uncorrected": self.median_error_uncorrected,
                "within_10pct_uncorrected": self.within_10pct_uncorrected,
                "flipped_labels": self.flipped, "seconds": self.seconds,
                "cpu_seconds": self.cpu_seconds,
                "factors": self.factors, "feed_amplitude": self.feed_amplitude,
                "chatter_frequency": self.chatter_frequency,
                "expected_within_10pct": self.expected_within_10pct, "design": self.design,
                "design_seconds": self.design_seconds,
                "design_cpu_seconds": self.design_cpu_seconds,
                "cuts": [list(c) for c in self.cuts], "criterion": self.criterion,
                "kind": "SYNTHETIC"}


#: The designs of the cuts :func:`validation_case` makes.
DESIGNS = ("stratified", "sequential")


def validation_case(config: Any, seed: int,
                    speed_range: tuple[float, float] = (200.0, 3000.0),
                    settings: LikelihoodSettings | None = None,
                    feed_amplitude: bool = False,
                    chatter_frequency: bool = False,
                    design: str = "stratified", criterion: str = "mean") -> dict[str, Any]:
    """The SYNTHETIC cuts of ``seed`` (with feed amplitudes when ``feed_amplitude``, chatter
    frequencies when ``chatter_frequency``; ``design`` ``stratified``:
    :func:`synthetic_observations`, ``sequential``: :func:`sequential_observations` with the
    design ``criterion``) and
    their calibration: ``observations``, ``held_out``
    speeds, the ``truth``'s critical depths there [m], the ``calibration`` (band at the
    held-out speeds), ``flipped`` labels, its wall and CPU ``seconds``, the ``proposals`` and
    the wall and CPU ``design_seconds`` of the sequential design."""
    from robobore.dynamics.config import load_dynamics_config

    if design not in DESIGNS:
        raise ConfigError("unknown design of the cuts", field="design", value=design,
                          expected=" or ".join(DESIGNS))
    cfg, _ = load_dynamics_config(config) if not hasattr(config, "equivalent") else (config, 0)
    problem = build_problem(cfg, [Observation(1, 1000.0, 1e-3, False)], settings)
    t0, c0 = time.perf_counter(), time.process_time()
    proposals: list = []
    if design == "stratified":
        obs, held, truth = synthetic_observations(problem, speed_range, seed, feed_amplitude,
                                                  chatter_frequency)
    else:
        obs, held, truth, proposals = sequential_observations(
            cfg, problem, speed_range, seed, settings, feed_amplitude, chatter_frequency,
            criterion=criterion)
    d_wall, d_cpu = time.perf_counter() - t0, time.process_time() - c0
    a_t = critical_depths(truth_structure(problem.structure), problem.process,
                          np.array([o.speed_rpm for o in obs]))
    flipped = sum(int(o.chatter != (o.depth_m > a)) for o, a in zip(obs, a_t, strict=True))
    t0, c0 = time.perf_counter(), time.process_time()
    cal = calibrate(cfg, obs, settings, speeds=held)
    dt, cpu = time.perf_counter() - t0, time.process_time() - c0
    seq = design == "sequential"
    return {"observations": obs, "held_out": held, "truth": truth, "calibration": cal,
            "flipped": flipped, "seconds": dt, "cpu_seconds": cpu, "proposals": proposals,
            "design_seconds": (d_wall if seq else 0.0, d_cpu if seq else 0.0)}


def within_10pct_share(log_sd: np.ndarray) -> np.ndarray:
    """The probability, per speed, that the truth lies within 10 % of the band's median when
    the truth is distributed as the band says (Gaussian in ``ln a_crit`` with ``log_sd``): the
    share of held-out speeds within 10 % that the band itself forecasts. A band as wide as the
    information in the cuts allows forecasts fewer speeds within 10 % than all of them."""
    from scipy.stats import norm

    sd = np.asarray(log_sd, float)
    with np.errstate(divide="ignore"):
        p = norm.cdf(np.log(1.1) / sd) - norm.cdf(np.log(0.9) / sd)
    return np.where(sd > 0, p, 1.0)


def validate_seed(config: Any, seed: int, speed_range: tuple[float, float] = (200.0, 3000.0),
                  settings: LikelihoodSettings | None = None,
                  feed_amplitude: bool = False,
                  chatter_frequency: bool = False,
                  design: str = "stratified", criterion: str = "mean") -> ValidationRun:
    """Make the SYNTHETIC cuts of ``seed`` (``design``: :data:`DESIGNS`; ``criterion``: the
    sequential design's, :data:`~robobore.dynamics.design.CRITERIA`), calibrate on them,
    compare at the held-out speeds (:func:`validation_case`)."""
    c = validation_case(config, seed, speed_range, settings, feed_amplitude, chatter_frequency,
                        design, criterion)
    cal, truth = c["calibration"], c["truth"]
    b = cal.band
    err_c = np.abs(b.median_m / truth - 1.0)
    err_u = np.abs(cal.nominal_m / truth - 1.0)
    cover = (b.lower_m <= truth) & (truth <= b.upper_m)
    factors = {r["name"]: r["value"] for r in cal.parameters()}
    expected = float(np.mean(within_10pct_share(b.log_sd)))
    return ValidationRun(seed, float(np.mean(err_c <= 0.1)), float(np.mean(cover)),
                         float(np.median(err_c)), float(np.median(err_u)),
                         float(np.mean(err_u <= 0.1)), int(c["flipped"]), c["seconds"],
                         c["cpu_seconds"], factors, feed_amplitude, chatter_frequency,
                         expected, design, *c["design_seconds"],
                         tuple((o.speed_rpm, o.depth_m * 1e3, o.chatter)
                               for o in c["observations"]),
                         criterion if design == "sequential" else "")


__all__ = ["truth_structure", "synthetic_observations", "validate_seed", "validation_case", "ValidationRun",
           "TRUTH_DAMPING_FACTOR", "TRUTH_STIFFNESS_FACTOR", "TRUTH_STIFFNESS_AXIS", "N_CUTS",
           "N_HELD_OUT", "LABEL_NOISE", "write_example_observations", "truth_feed_amplitude",
           "AMPLITUDE_NOISE_REL", "AMPLITUDE_NOISE_ABS_M", "FREQUENCY_NOISE_REL",
           "within_10pct_share", "sequential_observations", "candidate_speeds", "DESIGNS",
           "N_FIRST_CUTS", "N_CANDIDATES",
           "truth_chatter_frequency"]


def write_example_observations(path: Any, config: Any, seed: int = 0) -> Any:
    """Write the SYNTHETIC cuts of ``seed`` (:func:`synthetic_observations`) as an observations
    CSV with a header saying what they are (the bundled ``examples/boring_paper_cuts.csv``)."""
    from robobore.dynamics.calibrate import write_observations_csv
    from robobore.dynamics.config import load_dynamics_config

    cfg, _ = load_dynamics_config(config) if not hasattr(config, "equivalent") else (config, 0)
    problem = build_problem(cfg, [Observation(1, 1000.0, 1e-3, False)])
    obs, _, _ = synthetic_observations(problem, (200.0, 3000.0), seed)
    return write_observations_csv(path, obs, (
        f"SYNTHETIC observed cuts (seed {seed}): robobore.dynamics.calibrate_synthetic\n"
        f"truth: the config's robot with damping x{TRUTH_DAMPING_FACTOR} and "
        f"{'xyz'[TRUTH_STIFFNESS_AXIS]} stiffness x{TRUTH_STIFFNESS_FACTOR}; labels flipped "
        f"with probability {LABEL_NOISE}\n"
        "made by: write_example_observations(path, 'examples/boring_paper.toml', seed)"))
