"""Learning from the cut: the robot's equivalent model corrected by observed test cuts.

Observations (:func:`read_observations`) are cuts with their measured verdict (chatter or
stable) and, where known, the chatter frequency and the feed amplitude. The model is the
config's equivalent model with per-direction factors on the damping ratio and on the
stiffness (frequency held: the hammer test measures it best, so the mass follows the
stiffness), and, where the data need it, a process-damping coefficient.

Likelihood (one term per observation):

* verdict: ``P(chatter) = eps + (1 - 2 eps) Phi(ln(a / a_crit(n)) / s)``, ``a_crit`` the
  lobes' chatter limit at the cut's speed (and feed): the semi-discretisation linear limit,
  above the interruption where the steady cut is interrupted at vanishing depth
  (:func:`~robobore.dynamics.semidiscretization.chatter_limit`), ``eps`` the label-noise rate,
  ``s`` the spread of the verdict about the limit (:class:`LikelihoodSettings`);
* chatter frequency (chatter cuts): Gaussian about the frequency of the semi-discretisation's
  critical Floquet multiplier at the cut's speed and depth
  (:func:`~robobore.dynamics.semidiscretization.critical_multiplier`, the branch ``(arg mu /
  2 pi + k) / T`` nearest the observed frequency), standard deviation ``frequency_sd`` (2 %)
  of it, mixed at the label-noise rate ``eps`` with a frequency uniform over one branch
  spacing ``1 / T`` (a detector that reports a peak of no chatter branch). The frequency
  says which direction carries the chatter at each speed, and so how the dynamic stiffness
  is shared between the directions, which verdicts alone leave to the prior;
* feed amplitude (stable cuts): Gaussian about the steady forced response's half
  peak-to-peak feed displacement ``A``
  (:func:`~robobore.dynamics.timedomain.nominal_cut_deflection`, the orbit the time domain
  starts from), standard deviation ``sqrt((r A)^2 + f^2)`` for a measurement noise of ``r``
  relative plus ``f`` absolute (5 % + 0.1 um, a grating scale's; :class:`LikelihoodSettings`). The amplitude depends on the stiffness and the damping of
  every direction (the depth-modulation stiffness couples x and y into the feed), so stable
  cuts pin the stiffness and the verdicts then pin the damping.

Parametrisation: log factors on the damping ratio and on the stiffness per direction. The
lobes alone depend on a direction's dynamic stiffness at resonance, close to ``k zeta``, so
verdicts alone pin the sum of the two log factors of a direction and leave their difference to
the prior; the Laplace covariance carries that ridge into the band (the band is as sure as the
lobes are, not as the factors are). Feed amplitudes break the ridge.

Posterior: maximum a posteriori and the Laplace approximation (MacKay 2003, *Information
Theory, Inference, and Learning Algorithms*, ch. 27; Bishop 2006, *Pattern Recognition and
Machine Learning*, section 4.4) on the log factors, with the predictions linearised about the
current estimate and re-linearised until the estimate stops moving (Gauss-Newton iteration of
the iterated extended Kalman filter, Bell & Cathey 1993), the first linearisations with a
wider verdict spread (:data:`SPREAD_SCHEDULE`). Covariance: the inverse of the likelihood's
curvature at the estimate (the last linearised posterior's Hessian less the prior precision,
negative eigenvalues clipped at 0) plus the prior precision, so no direction is wider than the
prior. Priors: Gaussian in the log factors, centred on
1, correlated within the damping and within the stiffness group (:class:`LikelihoodSettings`).
Process damping
(``c = C a / v``, Altintas, Eynian & Onozuka 2008, added to the units' damping as the
revolution average of a radial damper) is kept only when it lowers the Bayesian information
criterion ``BIC = -2 ln L + p ln n`` (Schwarz 1978).
"""

from __future__ import annotations

import csv
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy.optimize import minimize
from scipy.stats import norm

from robobore.dynamics.band import (
    DEPTH_FLOOR_M,
    LobeBand,
    Z90,
    clipped,
    critical_depths,
    lobe_band,
    scaled_structure,
)
from robobore.dynamics.semidiscretization import (
    DEPTH_SCAN_HI_M,
    chatter_limit,
    critical_multiplier,
)
from robobore.dynamics.structure import ToolPointStructure
from robobore.errors import ConfigError, InputError

AXES = ("x", "y", "z")

# --------------------------------------------------------------------------- observations
#: Verdict words accepted in the ``verdict`` column (case-insensitive).
CHATTER_WORDS = frozenset({"chatter", "unstable", "yes", "true", "1"})
STABLE_WORDS = frozenset({"stable", "no", "false", "0", "ok"})
#: Columns of an observations CSV: required, optional, and free-text ones that are ignored.
REQUIRED_COLUMNS = ("speed_rpm", "depth_mm", "verdict")
OPTIONAL_COLUMNS = ("feed_mm_per_rev", "chatter_frequency_hz", "feed_amplitude_um")
TEXT_COLUMNS = ("id", "note")


@dataclass(frozen=True)
class Observation:
    """One observed cut: ``row`` (1-based data row), speed [r/min], depth [m], feed [mm/r] or
    None (the config's), ``chatter``, chatter frequency [Hz] and feed amplitude [m] or None."""

    row: int
    speed_rpm: float
    depth_m: float
    chatter: bool
    feed_mm_per_rev: float | None = None
    chatter_frequency_Hz: float | None = None
    feed_amplitude_m: float | None = None

    def to_dict(self) -> dict[str, Any]:
        return {"row": self.row, "speed_rpm": self.speed_rpm, "depth_mm": self.depth_m * 1e3,
                "verdict": "chatter" if self.chatter else "stable",
                "feed_mm_per_rev": self.feed_mm_per_rev,
                "chatter_frequency_Hz": self.chatter_frequency_Hz,
                "feed_amplitude_um": None if self.feed_amplitude_m is None
                else self.feed_amplitude_m * 1e6}


def _number(text: str, column: str, quantity: str, file: str, row: int) -> float:
    from robobore.io.ranges import check_value

    return check_value(text.strip(), quantity, file=file, row=row, field=column,
                       kind=InputError)


def read_observations(path: str | Path) -> list[Observation]:
    """Read an observations CSV (header row; columns :data:`REQUIRED_COLUMNS`, optionally
    :data:`OPTIONAL_COLUMNS` and the free-text :data:`TEXT_COLUMNS`). Empty optional cells
    mean "not known". Errors (:class:`~robobore.errors.InputError`) name the file, the data row,
    the column, the value and what was expected."""
    from robobore.io.readers import read_text

    src = str(path)
    text = read_text(path, "observations file")
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise InputError("empty observations file", file=src,
                         expected="a header row (" + ", ".join(REQUIRED_COLUMNS)
                                  + ") and one row per cut")
    reader = csv.reader(lines)
    header = [h.strip() for h in next(reader)]
    allowed = set(REQUIRED_COLUMNS) | set(OPTIONAL_COLUMNS) | set(TEXT_COLUMNS)
    for col in header:
        if col not in allowed:
            raise InputError("unknown column", file=src, field=col,
                             expected="columns " + ", ".join(REQUIRED_COLUMNS + OPTIONAL_COLUMNS
                                                             + TEXT_COLUMNS))
    for col in REQUIRED_COLUMNS:
        if col not in header:
            raise InputError("missing column", file=src, field=col,
                             expected="the columns " + ", ".join(REQUIRED_COLUMNS)
                                      + " (speed in r/min, depth in mm, chatter|stable)")
    idx = {c: header.index(c) for c in header}
    out = []
    for r, cells in enumerate(reader, start=1):
        if len(cells) != len(header):
            raise InputError("wrong number of cells", file=src, row=r, value=len(cells),
                             expected=f"{len(header)} cells as in the header")

        def cell(c: str) -> str | None:
            if c not in idx:
                return None
            v = cells[idx[c]].strip()
            return v or None

        for c in REQUIRED_COLUMNS:
            if cell(c) is None:
                raise InputError("empty cell", file=src, row=r, field=c,
                                 expected="a value (speed in r/min, depth in mm, "
                                          "chatter|stable)")
        n = _number(cell("speed_rpm"), "speed_rpm", "speed_rpm", src, r)
        if n <= 0:
            raise InputError("spindle speed must be positive", file=src, row=r,
                             field="speed_rpm", value=n, expected="a speed > 0 in r/min")
        a = _number(cell("depth_mm"), "depth_mm", "depth_mm", src, r)
        if a <= 0:
            raise InputError("depth of cut must be positive", file=src, row=r,
                             field="depth_mm", value=a, expected="a depth > 0 in mm")
        word = cell("verdict").lower()
        if word in CHATTER_WORDS:
            chatter = True
        elif word in STABLE_WORDS:
            chatter = False
        else:
            raise InputError("unknown verdict", file=src, row=r, field="verdict",
                             value=cell("verdict"),
                             expected="chatter (or " + ", ".join(sorted(CHATTER_WORDS - {
                                 "chatter"})) + ") or stable (or " + ", ".join(sorted(
                                     STABLE_WORDS - {"stable"})) + ")")
        f = cell("feed_mm_per_rev")
        feed = None if f is None else _number(f, "feed_mm_per_rev", "feed_mm_per_rev", src, r)
        if feed is not None and feed <= 0:
            raise InputError("feed must be positive", file=src, row=r, field="feed_mm_per_rev",
                             value=feed, expected="a feed > 0 in mm/r")
        fc = cell("chatter_frequency_hz")
        fch = None if fc is None else _number(fc, "chatter_frequency_hz", "frequency_Hz",
                                              src, r)
        if fch is not None and fch <= 0:
            raise InputError("chatter frequency must be positive", file=src, row=r,
                             field="chatter_frequency_hz", value=fch,
                             expected="a frequency > 0 in Hz")
        fa = cell("feed_amplitude_um")
        amp = None if fa is None else _number(fa, "feed_amplitude_um", "length_um", src, r)
        if amp is not None and amp <= 0:
            raise InputError("feed amplitude must be positive", file=src, row=r,
                             field="feed_amplitude_um", value=amp,
                             expected="an amplitude > 0 in um")
        out.append(Observation(r, n, a * 1e-3, chatter, feed, fch,
                               None if amp is None else amp * 1e-6))
    if not out:
        raise InputError("no observations", file=src, expected="one row per observed cut")
    return out


def write_observations_csv(path: str | Path, observations: list[Observation],
                           comment: str = "") -> Path:
    """Write observations as the CSV :func:`read_observations` reads (atomically), with
    ``comment`` as ``#`` lines above the header."""
    from robobore.io.results import atomic_write_text

    cols = list(REQUIRED_COLUMNS) + list(OPTIONAL_COLUMNS)
    lines = [f"# {c}" for c in comment.splitlines()] + [",".join(cols)]
    for o in observations:
        vals = [f"{o.speed_rpm:.6g}", f"{o.depth_m * 1e3:.6g}",
                "chatter" if o.chatter else "stable",
                "" if o.feed_mm_per_rev is None else f"{o.feed_mm_per_rev:.6g}",
                "" if o.chatter_frequency_Hz is None else f"{o.chatter_frequency_Hz:.6g}",
                "" if o.feed_amplitude_m is None else f"{o.feed_amplitude_m * 1e6:.6g}"]
        lines.append(",".join(vals))
    return atomic_write_text(path, "\n".join(lines) + "\n")


# --------------------------------------------------------------------------- settings
@dataclass(frozen=True)
class LikelihoodSettings:
    """``label_noise``: the rate ``eps`` at which a test cut's verdict is wrong (0.1: the
    chatter detector's goal of 92 % right on real records, rounded up; a verdict by ear or by
    the surface is no better). ``verdict_spread``: ``s``, the spread of the verdict about the
    limit in ``ln`` depth (0.1: a cut within about 10 % of its limit grows or decays so slowly
    that a test cut of a few seconds may show either). ``frequency_sd``: relative standard
    deviation of a measured chatter frequency about the model's (0.02: a spectrum of a cut of a
    few seconds resolves a few tenths of a hertz, and the model's frequency moves by about 1 %
    between the limit and a cut 30 % above it); ``amplitude_sd`` and ``amplitude_floor_m``: the
    feed amplitude's measurement noise, relative (0.05) and absolute (1e-7 m: a grating scale
    of 0.1 um resolution); raise them where the forced-response model itself is less sure.
    Priors on the log factors: ``damping_prior_sd`` 0.42 (90 % within x/ 2: identified robot
    damping ratios scatter by that much between tests, postures and in the cut),
    ``stiffness_prior_sd`` 0.25 (90 % within x/ 1.5: static stiffness identified within tens
    of % and posture dependent); the process-damping coefficient ``C`` [N/m]: log-normal about
    ``process_damping_ref`` (1e5 N/m), ``process_damping_prior_sd`` 2.8 (90 % within x/ 100).
    ``prior_correlation``: correlation of the three directions' log factors within the damping
    group and within the stiffness group (0.7: the three directions' values come from one
    hammer test and one stiffness identification, so their errors are largely shared -- the
    same processing, the same joints -- and the cut changes the damping of all of them alike);
    the marginal widths are the ones above."""

    label_noise: float = 0.1
    verdict_spread: float = 0.1
    frequency_sd: float = 0.02
    amplitude_sd: float = 0.05
    amplitude_floor_m: float = 1e-7
    damping_prior_sd: float = 0.42
    stiffness_prior_sd: float = 0.25
    process_damping_ref: float = 1e5
    process_damping_prior_sd: float = 2.8
    prior_correlation: float = 0.7
    max_iterations: int = 6
    trust_step: float = 0.7
    fd_step: float = 0.05

    def __post_init__(self) -> None:
        if not 0.0 <= self.label_noise < 0.5:
            raise ConfigError("label-noise rate out of range", field="label_noise",
                              value=self.label_noise, expected="0 <= eps < 0.5")
        if not 0.0 <= self.prior_correlation < 1.0:
            raise ConfigError("prior correlation out of range", field="prior_correlation",
                              value=self.prior_correlation, expected="0 <= rho < 1")
        if not self.verdict_spread > 0:
            raise ConfigError("verdict spread must be positive", field="verdict_spread",
                              value=self.verdict_spread, expected="s > 0 (in ln depth)")


# --------------------------------------------------------------------------- the model
@dataclass
class CalibrationProblem:
    """The config's robot and process with the observations: ``structure`` (the first three
    modes are the equivalent units x, y, z), ``processes`` per feed, the bore diameter (for the
    cutting speed of process damping; None for a single-point process)."""

    structure: ToolPointStructure
    process: Any
    processes: dict[float | None, Any]
    observations: list[Observation]
    diameter_m: float | None
    settings: LikelihoodSettings = field(default_factory=LikelihoodSettings)
    nominal_limits: np.ndarray | None = None
    _prior_prec: dict = field(default_factory=dict, repr=False)

    # ------------------------------------------------------------------ parameters
    def names(self, with_pd: bool) -> tuple[str, ...]:
        n = tuple(f"damping_{a}" for a in AXES) + tuple(f"stiffness_{a}" for a in AXES)
        return n + (("process_damping",) if with_pd else ())

    def prior_sd(self, with_pd: bool) -> np.ndarray:
        s = self.settings
        sd = [s.damping_prior_sd] * 3 + [s.stiffness_prior_sd] * 3
        return np.array(sd + ([s.process_damping_prior_sd] if with_pd else []))

    def structure_at(self, theta: np.ndarray, depth_m: float = 0.0,
                     speed_rpm: float = 1.0) -> ToolPointStructure:
        """The structure at log factors ``theta``; with a process-damping entry, its damper
        ``C a / v`` at ``depth_m`` and ``speed_rpm`` added to the units' damping."""
        st = scaled_structure(self.structure, np.zeros(3), theta[:3], theta[3:6])
        if theta.size > 6 and self.diameter_m is not None and depth_m > 0:
            v = math.pi * self.diameter_m * speed_rpm / 60.0
            c = self.settings.process_damping_ref * math.exp(theta[6]) * depth_m / v
            D = st.directions
            w = 0.5 * (D[:, 0] ** 2 + D[:, 1] ** 2)  # revolution average of a radial damper
            m = st.stiffness_N_per_m / st.omega ** 2
            z = st.damping_ratio + c * w / (2.0 * m * st.omega)
            st = ToolPointStructure(st.frequency_Hz, np.minimum(z, 0.95),
                                    st.stiffness_N_per_m, D)
        return st

    # ------------------------------------------------------------------ predictions
    def predictions(self, theta: np.ndarray, guess: np.ndarray | None = None) -> np.ndarray:
        """The predictions the likelihood compares with the observations, in order: ``ln
        a_crit`` at every observation (with process damping at the cut's depth), the chatter
        frequency [Hz] of each chatter cut that gives one, ``ln`` feed amplitude [m] of each
        stable cut that gives one."""
        obs = self.observations
        g = np.empty(len(obs))
        for i, o in enumerate(obs):
            st = self.structure_at(theta, o.depth_m, o.speed_rpm)
            gm = None if guess is None else math.exp(guess[i])
            gm = gm if gm is not None and DEPTH_FLOOR_M < gm < DEPTH_SCAN_HI_M else None
            a = chatter_limit(st, self.processes[o.feed_mm_per_rev], o.speed_rpm, guess_m=gm)
            g[i] = math.log(float(clipped(a)))
        extra = []
        for o in obs:
            if o.chatter and o.chatter_frequency_Hz is not None:
                st = self.structure_at(theta, o.depth_m, o.speed_rpm)
                pr = self.processes[o.feed_mm_per_rev]
                _, f, _ = critical_multiplier(st, pr, o.speed_rpm, o.depth_m,
                                              near_Hz=o.chatter_frequency_Hz)
                if not math.isfinite(f):  # overflow far beyond the limit: half a branch off
                    f = o.chatter_frequency_Hz + 0.5 * pr.n_inserts * o.speed_rpm / 60.0
                extra.append(f)
        for o in obs:
            if not o.chatter and o.feed_amplitude_m is not None:
                extra.append(math.log(max(self.feed_amplitude(theta, o), 1e-15)))
        return np.concatenate([g, np.asarray(extra, float)])

    def feed_amplitude(self, theta: np.ndarray, o: Observation) -> float:
        """Half peak-to-peak feed (z) displacement [m] of the steady cut at ``o``."""
        from robobore.dynamics.timedomain import nominal_cut_deflection

        st = self.structure_at(theta, o.depth_m, o.speed_rpm)
        pr = self.processes[o.feed_mm_per_rev].at_depth(o.depth_m)
        parts = nominal_cut_deflection(st, pr, o.speed_rpm)
        if parts is None:
            return float("nan")
        r1, r0 = parts
        z = o.depth_m * r1[:, 2] + r0[:, 2]
        return 0.5 * float(z.max() - z.min())

    def _terms(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        obs = self.observations
        la = np.log([o.depth_m for o in obs])
        y = np.array([o.chatter for o in obs], float)
        fobs = [o.chatter_frequency_Hz for o in obs if o.chatter and o.chatter_frequency_Hz]
        aobs = [math.log(o.feed_amplitude_m) for o in obs
                if not o.chatter and o.feed_amplitude_m is not None]
        return la, y, np.asarray(fobs, float), np.asarray(aobs, float)

    def log_likelihood(self, pred: np.ndarray, theta: np.ndarray | None = None,
                       spread: float | None = None) -> float:
        """ln L of the predictions :meth:`predictions` returns (``spread``: the verdict's
        spread ``s`` in place of the settings' one, as the fit's continuation uses)."""
        s = self.settings
        la, y, fobs, aobs = self._terms()
        n = la.size
        z = (la - pred[:n]) / (spread or s.verdict_spread)
        p = s.label_noise + (1.0 - 2.0 * s.label_noise) * norm.cdf(z)
        p = np.clip(p, 1e-300, 1.0 - 1e-16)
        ll = float(np.sum(y * np.log(p) + (1.0 - y) * np.log1p(-p)))
        k = n
        if fobs.size:
            fp = pred[k:k + fobs.size]
            sd = s.frequency_sd * fobs
            dens = np.exp(-0.5 * ((fobs - fp) / sd) ** 2) / (math.sqrt(2 * math.pi) * sd)
            dens = np.where(np.isfinite(dens), dens, 0.0)
            ll += float(np.sum(np.log((1.0 - s.label_noise) * dens
                                      + s.label_noise * self._branch_density())))
            k += fobs.size
        if aobs.size:
            ap = np.exp(pred[k:k + aobs.size])
            ok = np.isfinite(ap)
            sd = np.hypot(s.amplitude_sd * ap[ok], s.amplitude_floor_m)
            ll += float(np.sum(-0.5 * ((np.exp(aobs[ok]) - ap[ok]) / sd) ** 2 - np.log(sd)))
        return ll

    def _branch_density(self) -> np.ndarray:
        """Density [1/Hz] of a chatter frequency that belongs to no predicted branch: uniform
        over one branch spacing (the insert passing frequency) of each chatter cut."""
        out = []
        for o in self.observations:
            if o.chatter and o.chatter_frequency_Hz is not None:
                pr = self.processes[o.feed_mm_per_rev]
                out.append(60.0 / (pr.n_inserts * o.speed_rpm))
        return np.asarray(out, float)

    def prior_cov(self, with_pd: bool) -> np.ndarray:
        """Prior covariance of the log factors (:class:`LikelihoodSettings`)."""
        sd = self.prior_sd(with_pd)
        rho = self.settings.prior_correlation
        C = np.diag(sd ** 2)
        for g in (slice(0, 3), slice(3, 6)):
            blk = np.full((3, 3), rho) + (1.0 - rho) * np.eye(3)
            C[g, g] = blk * np.outer(sd[g], sd[g])
        return C

    def log_prior(self, theta: np.ndarray) -> float:
        P = self._prior_prec.get(theta.size)
        if P is None:
            P = self._prior_prec[theta.size] = np.linalg.inv(self.prior_cov(theta.size > 6))
        return float(-0.5 * theta @ P @ theta)

    @property
    def n_data(self) -> int:
        _, _, fobs, aobs = self._terms()
        return len(self.observations) + fobs.size + aobs.size


def build_problem(config: Any, observations: list[Observation],
                  settings: LikelihoodSettings | None = None,
                  source: str | None = None) -> CalibrationProblem:
    """The :class:`CalibrationProblem` of a dynamics config (a path, or a validated
    :class:`~robobore.dynamics.config.DynamicsConfig`) and observations."""
    from robobore.dynamics.config import (
        DynamicsConfig,
        build_coefficients,
        build_process,
        build_structure,
        load_dynamics_config,
    )

    if isinstance(config, DynamicsConfig):
        cfg = config
    else:
        cfg, _ = load_dynamics_config(config)
        source = source or str(config)
    if cfg.equivalent is None:
        raise ConfigError("calibration needs the robot's equivalent model", file=source,
                          field="equivalent",
                          expected="[equivalent] values or [model] files in the config")
    st = build_structure(cfg, source)
    coef = build_coefficients(cfg, source) if cfg.is_boring else None
    base = build_process(cfg, source, coefficients=coef)
    procs: dict[float | None, Any] = {None: base}
    for o in observations:
        f = o.feed_mm_per_rev
        if f is None or f in procs:
            continue
        if not cfg.is_boring:
            raise InputError("a feed per cut needs a boring config", file=source,
                             row=o.row, field="feed_mm_per_rev", value=f,
                             expected="an empty feed_mm_per_rev column for a [process] config")
        c2 = cfg.model_copy(update={"cutting": cfg.cutting.model_copy(
            update={"feed_mm_per_rev": float(f)})})
        procs[f] = build_process(c2, source, coefficients=coef)
    diameter = cfg.bore.diameter_mm * 1e-3 if cfg.is_boring else None
    return CalibrationProblem(st, base, procs, list(observations), diameter,
                              settings or LikelihoodSettings())


# --------------------------------------------------------------------------- the fit
@dataclass(frozen=True)
class Fit:
    """One model's posterior: parameter names, MAP log factors, Laplace covariance, ln L and
    ln prior at the MAP, BIC, iterations, predictions at the MAP."""

    names: tuple[str, ...]
    theta: np.ndarray
    cov: np.ndarray
    log_likelihood: float
    log_prior: float
    bic: float
    iterations: int
    predictions: np.ndarray


def _hessian(f: Callable[[np.ndarray], float], x: np.ndarray, h: float = 1e-3) -> np.ndarray:
    n = x.size
    H = np.empty((n, n))
    for i in range(n):
        for j in range(i, n):
            ei = np.zeros(n)
            ej = np.zeros(n)
            ei[i] = h
            ej[j] = h
            v = (f(x + ei + ej) - f(x + ei - ej) - f(x - ei + ej) + f(x - ei - ej)) / (4 * h * h)
            H[i, j] = H[j, i] = v
    return H


#: Linearisations of the process-damping fit (it starts from the fit without it).
PD_ITERATIONS = 2
#: Verdict spreads of the fit's first linearisations (continuation; module docstring).
SPREAD_SCHEDULE = (0.8, 0.3)


def posterior_cov(hessian: np.ndarray, prior_cov: np.ndarray) -> np.ndarray:
    """Laplace covariance from the Hessian of the negative log posterior at the estimate.

    The posterior precision is the likelihood's curvature (``hessian`` less the prior
    precision, its negative eigenvalues clipped at 0) plus the prior precision: a direction the
    linearised likelihood leaves flat, or curves the wrong way, keeps its prior precision, so no
    direction is wider than the prior (``prior_cov - cov`` is positive semi-definite); where the
    likelihood's curvature is positive semi-definite the result is ``inv(hessian)``."""
    H = 0.5 * (hessian + hessian.T)
    P = np.linalg.inv(prior_cov)
    lam, U = np.linalg.eigh(H - P)
    cov = np.linalg.inv((U * np.maximum(lam, 0.0)) @ U.T + P)
    return 0.5 * (cov + cov.T)


def fit(problem: CalibrationProblem, with_pd: bool = False,
        start: np.ndarray | None = None, progress: Callable[[int], None] | None = None,
        max_iterations: int | None = None, continuation: bool = True) -> Fit:
    """MAP and Laplace covariance of the log factors (module docstring). ``progress(1)`` per
    prediction set computed. ``continuation``: begin with the wider verdict spreads of
    :data:`SPREAD_SCHEDULE` (off when starting from an earlier fit's estimate)."""
    s = problem.settings
    p = 9 - 3 + (1 if with_pd else 0)
    theta = np.zeros(p) if start is None else np.asarray(start, float).copy()
    iters = max_iterations or s.max_iterations
    pred = problem.predictions(theta, problem.nominal_limits)
    if progress is not None:
        progress(1)
    n_obs = len(problem.observations)
    it = 0
    J = np.zeros((pred.size, p))
    # continuation in the verdict spread: a wrong verdict far from the limit sits on the
    # flat eps plateau of the likelihood, so the first linearisations see a wider spread
    # (SPREAD_SCHEDULE) and the fit ends on the settings' spread
    sched = [max(x, s.verdict_spread) for x in SPREAD_SCHEDULE] if continuation else []
    iters = max(iters, len(sched) + 1)
    for it in range(1, iters + 1):
        spread = sched[it - 1] if it <= len(sched) else s.verdict_spread
        guess = pred[:n_obs]
        for j in range(p):
            e = np.zeros(p)
            e[j] = s.fd_step
            J[:, j] = (problem.predictions(theta + e, guess) - pred) / s.fd_step
            if progress is not None:
                progress(1)
        t0, p0 = theta.copy(), pred.copy()

        def neg(t: np.ndarray, t0=t0, p0=p0, spread=spread) -> float:
            return -(problem.log_likelihood(p0 + J @ (t - t0), t, spread)
                     + problem.log_prior(t))

        bounds = [(t0[j] - s.trust_step, t0[j] + s.trust_step) for j in range(p)]
        res = minimize(neg, t0, method="L-BFGS-B", bounds=bounds)
        step = res.x - theta
        theta = res.x
        pred = problem.predictions(theta, pred[:n_obs])
        if progress is not None:
            progress(1)
        if float(np.max(np.abs(step))) < 0.02 and spread == s.verdict_spread:
            break
    t0, p0 = theta.copy(), pred.copy()

    def neg_final(t: np.ndarray) -> float:
        return -(problem.log_likelihood(p0 + J @ (t - t0), t) + problem.log_prior(t))

    cov = posterior_cov(_hessian(neg_final, theta), problem.prior_cov(with_pd))
    ll = problem.log_likelihood(pred, theta)
    bic = -2.0 * ll + p * math.log(max(problem.n_data, 1))
    return Fit(problem.names(with_pd), theta, cov, ll, problem.log_prior(theta), bic, it, pred)


# --------------------------------------------------------------------------- results
@dataclass(frozen=True)
class Calibration:
    """The result: the chosen ``fit`` (and the other model's ``alternative``), the
    ``band`` of the corrected lobes, the nominal lobes ``nominal_m`` at the band's speeds,
    the corrected equivalent model, the observations with their chatter probability under the
    nominal and the corrected model, settings and the run time."""

    fit: Fit
    alternative: Fit | None
    band: LobeBand
    nominal_m: np.ndarray
    equivalent: Any
    observations: list[Observation]
    p_chatter_nominal: np.ndarray
    p_chatter_corrected: np.ndarray
    settings: LikelihoodSettings
    notes: tuple[str, ...]
    seconds: float

    def parameters(self) -> list[dict[str, Any]]:
        """One row per parameter: the factor (MAP) and its 90 % interval (5 %, 95 %)."""
        rows = []
        sd = np.sqrt(np.diag(self.fit.cov))
        for name, t, s in zip(self.fit.names, self.fit.theta, sd, strict=True):
            if name == "process_damping":
                c0 = self.settings.process_damping_ref
                rows.append({"name": "process_damping_N_per_m", "value": c0 * math.exp(t),
                             "p05": c0 * math.exp(t - Z90 * s), "p95": c0 * math.exp(t + Z90 * s),
                             "log_sd": float(s), "unit": "N/m"})
            else:
                rows.append({"name": name + "_factor", "value": math.exp(t),
                             "p05": math.exp(t - Z90 * s), "p95": math.exp(t + Z90 * s),
                             "log_sd": float(s), "unit": "1"})
        return rows

    def to_dict(self) -> dict[str, Any]:
        f = self.fit
        sel = {"chosen": "with process damping" if "process_damping" in f.names
               else "damping and stiffness factors",
               "criterion": "BIC = -2 ln L + p ln n (lower is better)",
               "bic": f.bic, "log_likelihood": f.log_likelihood, "parameters": len(f.names),
               "n_data": len(f.predictions)}
        if self.alternative is not None:
            sel["alternative_bic"] = self.alternative.bic
            sel["alternative_log_likelihood"] = self.alternative.log_likelihood
            sel["alternative_parameters"] = len(self.alternative.names)
        s = self.settings
        return {
            "kind": "calibration of the equivalent model by observed cuts",
            "posterior": "MAP + Laplace on log factors, predictions re-linearised "
                         f"({f.iterations} iterations)",
            "parameters": self.parameters(),
            "covariance_log": f.cov.tolist(), "parameter_names": list(f.names),
            "model_selection": sel,
            "likelihood": {"label_noise": s.label_noise, "verdict_spread": s.verdict_spread,
                           "frequency_sd": s.frequency_sd, "amplitude_sd": s.amplitude_sd,
                           "amplitude_floor_um": s.amplitude_floor_m * 1e6,
                           "damping_prior_sd": s.damping_prior_sd,
                           "stiffness_prior_sd": s.stiffness_prior_sd,
                           "prior_correlation": s.prior_correlation},
            "observations": [{**o.to_dict(), "p_chatter_nominal": float(pn),
                              "p_chatter_corrected": float(pc)}
                             for o, pn, pc in zip(self.observations, self.p_chatter_nominal,
                                                  self.p_chatter_corrected, strict=True)],
            "nominal_critical_depth_mm": (self.nominal_m * 1e3).tolist(),
            "band": self.band.to_dict(),
            "equivalent": self.equivalent.to_dict(),
            "notes": list(self.notes), "seconds": self.seconds}

    def to_dataset(self):
        """The band with the nominal lobes and the observations (xarray, units in attrs)."""
        ds = self.band.to_dataset()
        ds["critical_depth_nominal"] = ("speed", self.nominal_m * 1e3, {"units": "mm"})
        ds["observed_speed"] = ("cut", [o.speed_rpm for o in self.observations],
                                {"units": "r/min"})
        ds["observed_depth"] = ("cut", [o.depth_m * 1e3 for o in self.observations],
                                {"units": "mm"})
        ds["observed_chatter"] = ("cut", np.array([o.chatter for o in self.observations], int),
                                  {"units": "1", "long_name": "1 chatter, 0 stable"})
        ds["parameter_value"] = ("parameter", [r["value"] for r in self.parameters()],
                                 {"units": "1 (factors); N/m (process damping)"})
        ds["parameter_p05"] = ("parameter", [r["p05"] for r in self.parameters()],
                               {"units": "1 (factors); N/m (process damping)"})
        ds["parameter_p95"] = ("parameter", [r["p95"] for r in self.parameters()],
                               {"units": "1 (factors); N/m (process damping)"})
        ds = ds.assign_coords(parameter=("parameter", [r["name"] for r in self.parameters()]))
        ds.attrs["posterior"] = "MAP + Laplace (log factors)"
        return ds


def corrected_equivalent(em: Any, fit_: Fit, note: str) -> Any:
    """The equivalent model with the MAP factors applied (frequency held) and the posterior's
    95 % ranges of stiffness and damping ratio in ``uncertainty``."""
    from dataclasses import replace

    from robobore.dynamics.band import Z95

    sd = np.sqrt(np.diag(fit_.cov))
    k, z, unc = {}, {}, {}
    for i, a in enumerate(AXES):
        td, ts = fit_.theta[i], fit_.theta[3 + i]
        sdd, sds = sd[i], sd[3 + i]
        z[a] = em.damping_ratio[a] * math.exp(td)
        k[a] = em.stiffness_N_per_m[a] * math.exp(ts)
        unc[a] = {"damping_ratio": [z[a] * math.exp(-Z95 * sdd), z[a] * math.exp(Z95 * sdd)],
                  "stiffness_N_per_m": [k[a] * math.exp(-Z95 * sds),
                                        k[a] * math.exp(Z95 * sds)]}
    return replace(em, stiffness_N_per_m=k, damping_ratio=z, notes=tuple(em.notes) + (note,),
                   uncertainty=unc)


def p_chatter(problem: CalibrationProblem, g: np.ndarray) -> np.ndarray:
    """P(chatter) of each observation for predicted ``ln a_crit`` ``g`` (label noise
    included)."""
    s = problem.settings
    la = np.log([o.depth_m for o in problem.observations])
    return s.label_noise + (1 - 2 * s.label_noise) * norm.cdf((la - g) / s.verdict_spread)


def band_curve(problem: CalibrationProblem, with_pd: bool, speeds: np.ndarray,
               pd_depth_iterations: int = 2) -> Callable[[np.ndarray, np.ndarray | None],
                                                         np.ndarray]:
    """``curve(theta, guess)``: critical depths [m] at ``speeds`` of the config's process for
    log factors ``theta``; with process damping, its damper at the limit itself (the depth
    fixed point iterated ``pd_depth_iterations`` times from the limit without it)."""
    pr = problem.process

    def curve(theta: np.ndarray, guess: np.ndarray | None) -> np.ndarray:
        a = critical_depths(problem.structure_at(theta[:6]), pr, speeds, guess)
        if not with_pd:
            return a
        for _ in range(pd_depth_iterations):
            for i, n in enumerate(speeds):
                st = problem.structure_at(theta, float(a[i]), float(n))
                g = float(a[i]) if DEPTH_FLOOR_M < a[i] < DEPTH_SCAN_HI_M else None
                a[i] = float(clipped(chatter_limit(st, pr, float(n), guess_m=g)))
        return a

    return curve


def calibrate(config: Any, observations: list[Observation],
              settings: LikelihoodSettings | None = None, speeds: np.ndarray | None = None,
              source: str | None = None, depth_count: int = 60,
              progress: Callable[[str, int, int], None] | None = None,
              em: Any = None, allow_process_damping: bool = True) -> Calibration:
    """Calibrate the config's equivalent model by ``observations`` (module docstring).

    ``speeds`` [r/min]: where the band is computed (default 40 speeds over the config's speed
    range). ``progress(task, done, total)`` as :func:`robobore.clitools.stage_progress` takes
    it. ``em``: the config's equivalent model (default: built from its ``[equivalent]``)."""
    from robobore.dynamics.band import band_evaluations
    from robobore.dynamics.config import DynamicsConfig, load_dynamics_config, speed_range

    t_start = time.perf_counter()
    if isinstance(config, DynamicsConfig):
        cfg = config
    else:
        cfg, _ = load_dynamics_config(config)
        source = source or str(config)
    problem = build_problem(cfg, observations, settings, source)
    s = problem.settings
    if speeds is None:
        sp, _ = speed_range(cfg)
        speeds = np.linspace(sp.min, sp.max, 40)
    speeds = np.asarray(speeds, float)
    notes = []

    def tick(task: str, total: int):
        done = [0]

        def adv(k: int = 1) -> None:
            done[0] += k
            if progress is not None:
                progress(task, min(done[0], total), total)

        return adv

    n0 = 1 + max(s.max_iterations, len(SPREAD_SCHEDULE) + 1) * 7
    adv = tick("fit: damping and stiffness factors", n0)
    problem.nominal_limits = None
    f0 = fit(problem, False, progress=adv)
    if progress is not None:
        progress("fit: damping and stiffness factors", n0, n0)
    chosen, other = f0, None
    pd_possible = allow_process_damping and problem.diameter_m is not None
    if pd_possible:
        n1 = 1 + PD_ITERATIONS * 8
        adv = tick("fit: with process damping", n1)
        problem.nominal_limits = f0.predictions[:len(observations)]
        f1 = fit(problem, True, start=np.concatenate([f0.theta, [0.0]]), progress=adv,
                 max_iterations=PD_ITERATIONS, continuation=False)
        if progress is not None:
            progress("fit: with process damping", n1, n1)
        if f1.bic < f0.bic:
            chosen, other = f1, f0
        else:
            other = f1
    else:
        notes.append("process damping not considered (a single-point [process] config has no "
                     "bore diameter for the cutting speed)" if allow_process_damping
                     else "process damping not considered (turned off)")
    with_pd = "process_damping" in chosen.names
    g_nom = np.log(clipped(critical_depths(problem.structure, problem.process, speeds)))
    nominal = np.exp(g_nom)
    curve = band_curve(problem, with_pd, speeds)
    total = band_evaluations(chosen.cov)
    adv = tick("band: corrected lobes", total)
    band = lobe_band(curve, chosen.theta, chosen.cov, speeds, chosen.names, "observations",
                     depth_count=depth_count, progress=adv)
    pn = problem.predictions(np.zeros(6), f0.predictions[:len(observations)])[:len(observations)]
    pc = chosen.predictions[:len(observations)]
    if em is None:
        em = cfg.equivalent.to_model()
    note = ("corrected by {} observed cuts (robobore calibrate dynamics): factors ".format(
        len(observations)) + ", ".join(f"{n} {math.exp(t):.3g}" for n, t in zip(
            chosen.names[:6], chosen.theta[:6], strict=True)))
    if with_pd:
        notes.append("process damping (C = {:.3g} N/m) is not part of the equivalent model "
                     "file; the band includes it".format(s.process_damping_ref
                                                         * math.exp(chosen.theta[6])))
    em_c = corrected_equivalent(em, chosen, note)
    return Calibration(chosen, other, band, nominal, em_c, list(observations),
                       p_chatter(problem, pn), p_chatter(problem, pc), s, tuple(notes),
                       time.perf_counter() - t_start)


__all__ = ["Observation", "read_observations", "write_observations_csv", "LikelihoodSettings",
           "CalibrationProblem", "build_problem", "Fit", "fit", "Calibration", "calibrate",
           "corrected_equivalent", "p_chatter", "band_curve", "CHATTER_WORDS", "STABLE_WORDS",
           "REQUIRED_COLUMNS", "OPTIONAL_COLUMNS"]
