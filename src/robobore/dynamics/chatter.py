"""Verdicts on a simulated (or measured) cut, each by its cause.

A cut gets separate, named verdicts (:func:`classify`, :class:`ChatterVerdict`):

* ``chatter`` -- self-excited (regenerative) vibration: the vibration GROWS from pitch to
  pitch. The measure is the Floquet multiplier of the simulated cut
  (:func:`floquet_multiplier`): the growth per insert pitch ``tau`` of the regenerative
  displacement ``|r(t) - r(t - tau)|`` (a stable cut settles on a motion that repeats every
  pitch, so this decays as ``rho^k``, ``rho`` the spectral radius of the linearised cut's
  monodromy matrix, which the semi-discretisation lobes compute), fitted on the per-pitch
  maxima of the second half of the run, with its standard error. Chatter when the multiplier
  exceeds 1; the verdict is ``decided`` when ``|ln rho|`` exceeds three standard errors
  (:data:`DECISION_SIGMAS`), else the run is too short to decide near the limit and says so
  (``chatter_decided`` false, a reason naming the multiplier; ``simulate`` callers lengthen the
  run). Where the tool leaves the cut in the last ``tail_fraction`` of the run the cut is
  nonlinear (the chip is interrupted) and the verdict names why the tool leaves it
  (``tool_leaves_cut_cause``): ``"forced vibration"`` -- the motion repeats every pitch to
  below :data:`AMPLITUDE_RESOLUTION_M` (a bounded forced vibration interrupts the cut; growth
  ratios of sub-resolution values are not findings), or the multiplier, fitted as above,
  decides that the regenerative vibration decays: no chatter; ``"regenerative vibration"``
  -- the vibration grew from the quietest point of the first half and stays
  (:func:`vibration_growth` and :func:`amplitude_growth` both above ``growth_limit``) to a
  regenerative displacement beyond the linear range (:data:`LINEAR_FRACTION` of the chip: the
  feed per insert, or the depth where smaller),
  or the multiplier decides that it grows: chatter (``chatter_cause`` "tool leaves the cut"
  or "regenerative"); ``"undecided"`` otherwise. A run that diverged (tool-point displacement above
  the divergence limit) is chatter. A cut whose vibration does not grow is not chatter,
  however rough. Reported with it: the chatter frequency (largest spectral peak away from the
  tooth-passing harmonics ``k N n / 60``, in the last ``tail_fraction`` of the run; none for a
  run that diverged, whose record stops before a spectrum means anything) and the
  non-harmonic energy fraction of the displacement (:func:`harmonic_analysis`).
* ``surface_finish`` -- ``"ok"`` / ``"rough"``: Ra of the machined profile AFTER removing its
  form (least-squares line: offset and taper, :func:`robobore.dynamics.timedomain.roughness`)
  against the tolerance; ``None`` without a tolerance. Feed marks alone can make a cut rough.
* ``tool_leaves_cut`` -- an insert is out of the material (chip area <= 0) in some of the
  last ``tail_fraction`` of the run (``tool_left_cut_fraction`` > 0): the cut is interrupted,
  the linear models no longer apply.
* ``paper_stable`` -- the paper's own criterion (its "stable" / "vibratory"): vibratory when
  Ra (form removed) exceeds the tolerance, when the cut chatters or when the run diverged;
  stable when Ra is within the tolerance and the cut does not chatter; ``None`` (not judged)
  without a tolerance, unless the cut chatters or diverged. It is a roughness criterion: it
  calls a cut vibratory whose feed marks alone exceed the tolerance. The study summaries keep
  it under the name ``stable``, so that measured data classified the paper's way compare with
  it. No verdict says stable while another says chatter or diverged.

Amplitudes below :data:`AMPLITUDE_RESOLUTION_M` (1 nm, below what a displacement sensor or a
profilometer on a boring cell resolves) are below resolution: :func:`resolved` says so, and
ratios of such values are not findings.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
import xarray as xr
from numba import njit

from robobore.dynamics.timedomain import column_means


class Regenerative(NamedTuple):
    """The regenerative displacement ``r(t) - r(t - tau)`` of a run, once: its norm ``d``,
    feed (z) part ``feed`` (absolute) and radial (x, y) part ``radial`` (norms), each
    (n_samples - samples_per_delay,) [m], and ``xmax`` = max ``|displacement|`` [m]."""

    d: np.ndarray
    feed: np.ndarray
    radial: np.ndarray
    xmax: float


@njit(cache=True)
def _regenerative_kernel(X, s, d, feed, radial):  # pragma: no cover - numba
    xmax = 0.0
    for i in range(X.shape[0]):
        for c in range(3):
            a = abs(X[i, c])
            if a > xmax:
                xmax = a
    for i in range(X.shape[0] - s):
        ex = X[i + s, 0] - X[i, 0]
        ey = X[i + s, 1] - X[i, 1]
        ez = X[i + s, 2] - X[i, 2]
        exy = ex * ex + ey * ey
        d[i] = math.sqrt(exy + ez * ez)
        feed[i] = abs(ez)
        radial[i] = math.sqrt(exy)
    return xmax


def regenerative(displacement: np.ndarray, samples_per_delay: int) -> Regenerative:
    """:class:`Regenerative` of ``displacement`` (n_samples, 3) [m] over one delay of
    ``samples_per_delay`` samples (one compiled pass shared by the chatter measures)."""
    X = np.ascontiguousarray(displacement, dtype=float)
    s = int(samples_per_delay)
    n = max(X.shape[0] - s, 0)
    d, feed, radial = np.empty(n), np.empty(n), np.empty(n)
    xmax = float(_regenerative_kernel(X, s, d, feed, radial)) if X.size else 0.0
    return Regenerative(d, feed, radial, xmax)


def vibration_growth(displacement: np.ndarray, samples_per_delay: int,
                     regen: Regenerative | None = None) -> float:
    """Growth of the envelope of ``|r(t) - r(t - tau)|``: its maximum over the last delay
    period over the smallest per-delay maximum of the first half of the run.

    Measured from the quietest point of the first half, not from the first delay, so that
    the decay of the entry transient does not hide growth that follows it, and vibration
    that grew and then saturated (the tool leaving the cut) still reads as grown.
    ``displacement``: (n_samples, 3) [m]; ``regen``: its :func:`regenerative` when already
    computed. Returns 0 when the last envelope is at round-off
    level (:data:`ROUNDOFF`), i.e. the motion repeats every delay.
    """
    s = int(samples_per_delay)
    if np.shape(displacement)[0] < 3 * s:
        return math.nan
    r = regen if regen is not None else regenerative(displacement, s)
    return _growth(r.d, s, r.xmax)


def _growth(d: np.ndarray, period: int, xmax: float) -> float:
    """Last period's maximum of ``d`` over the smallest period maximum of the first half."""
    n = d.shape[0] // period
    peaks = d[:n * period].reshape(n, period).max(axis=1)
    first_half = peaks[:max(1, n // 2)]
    return _ratio(float(first_half.min()), float(d[-period:].max()), xmax)


#: Relative floor of the regenerative displacement: below ``ROUNDOFF x max |displacement|``
#: a difference is round-off of an exactly periodic motion, not vibration.
ROUNDOFF = 1e-9


def _ratio(first: float, last: float, xmax: float) -> float:
    floor = ROUNDOFF * xmax
    if last <= floor:
        return 0.0
    return float(last / max(first, floor)) if max(first, floor) > 0 else math.inf


#: Floquet-multiplier fit: per-pitch maxima below this fraction of the largest displacement
#: are round-off (left out), and a verdict is decided when ``|ln rho|`` exceeds
#: :data:`DECISION_SIGMAS` standard errors of the fit and :data:`DECISION_FLOOR` absolutely.
FLOQUET_FLOOR = 1e-7
DECISION_SIGMAS = 3.0
DECISION_FLOOR = 1e-4
#: Linear range of a simulated cut for the multiplier fit: regenerative vibration up to this
#: fraction of the depth of cut (:func:`floquet_multiplier`).
LINEAR_FRACTION = 0.1
#: Amplitudes below this [m] are below resolution (1 nm).
AMPLITUDE_RESOLUTION_M = 1e-9


def resolved(amplitude_m: float) -> bool:
    """True when ``amplitude_m`` is at or above :data:`AMPLITUDE_RESOLUTION_M`."""
    return bool(math.isfinite(amplitude_m) and amplitude_m >= AMPLITUDE_RESOLUTION_M)


def floquet_multiplier(displacement: np.ndarray, samples_per_delay: int,
                       tail_fraction: float = 0.5, min_delays: int = 6,
                       linear_limit_m: float | None = None,
                       regen: Regenerative | None = None) -> tuple[float, float, int]:
    """Growth per delay of the regenerative displacement: ``(rho, se_ln_rho, delays)``.

    ``d(t) = |r(t) - r(t - tau)|`` (``tau`` = ``samples_per_delay`` samples) decays or grows as
    ``rho^k`` over the delays ``k`` once the other Floquet modes have died out, ``rho`` the
    largest Floquet multiplier of the linear cut. ``ln`` of the per-delay maxima of ``d`` is
    fitted by least squares against ``k`` over the last ``tail_fraction`` of the delays (at
    least ``min_delays``), leaving out maxima at round-off level (below :data:`FLOQUET_FLOOR`
    of the largest displacement); where the envelope reaches round-off before the tail, over
    the last ``min_delays`` delays above it. Returns ``rho = exp(slope)``, the standard error
    of ``ln rho`` and the number of delays fitted; ``(0, 0, 0)`` when ``d`` is at round-off
    throughout (a motion that repeats every delay); NaN with fewer than ``min_delays + 1``
    delays in the run.

    ``linear_limit_m``: the linear range of the cut (:func:`classify` passes
    :data:`LINEAR_FRACTION` of the depth of cut). A growing vibration leaves it (the depth
    modulation and the chip thickness are no longer small perturbations and its growth slows
    down); the run is then fitted only up to the first delay whose maximum exceeds the limit
    (the last ``tail_fraction`` of those delays), so that the estimate is the linear cut's
    multiplier. ``regen``: the :func:`regenerative` displacement when already computed."""
    s = int(samples_per_delay)
    n = np.shape(displacement)[0] // s - 1
    if n < min_delays + 1:
        return math.nan, math.nan, 0
    r = regen if regen is not None else regenerative(displacement, s)
    pk = r.d[:n * s].reshape(n, s).max(axis=1)
    floor = FLOQUET_FLOOR * r.xmax
    if linear_limit_m is not None and linear_limit_m > 0.0:
        over = np.nonzero(pk > linear_limit_m)[0]
        if over.size and over[0] >= min_delays + 1:
            n = int(over[0])
            pk = pk[:n]
    valid = np.nonzero(pk > floor)[0]
    if valid.size < 2:
        return 0.0, 0.0, 0
    start = n - max(min_delays, int(round(n * tail_fraction)))
    use = valid[valid >= start]
    if use.size < min_delays:
        use = valid[-min_delays:] if valid.size >= min_delays else valid
    k = use.astype(float)
    y = np.log(pk[use])
    kc = k - k.mean()
    sxx = float(kc @ kc)
    if sxx <= 0.0:
        return math.nan, math.nan, int(use.size)
    slope = float(kc @ (y - y.mean())) / sxx
    res = y - y.mean() - slope * kc
    dof = max(1, use.size - 2)
    se = math.sqrt(float(res @ res) / dof / sxx)
    return math.exp(slope), se, int(use.size)


@functools.lru_cache(maxsize=8)
def _hanning(n: int) -> np.ndarray:
    """``np.hanning(n)``, kept for the lengths in use (read-only)."""
    w = np.hanning(n)
    w.flags.writeable = False
    return w


def harmonic_analysis(signal: np.ndarray, fs: float, tooth_freq: float,
                      band_rel: float = 0.02) -> tuple[float, float]:
    """Non-harmonic energy ratio and the largest non-harmonic peak frequency [Hz].

    ``signal``: (n,) or (n, c). Bands of half-width ``max(band_rel * f_tooth, 2 bins)`` around
    every harmonic of the tooth-passing frequency (including 0 Hz) count as harmonic.
    """
    x = np.asarray(signal, float)
    if x.ndim == 1:
        x = x[:, None]
    x = x - column_means(x)
    n = x.shape[0]
    win = _hanning(n)[:, None]
    P = (np.abs(np.fft.rfft(x * win, axis=0)) ** 2).sum(axis=1)
    f = np.fft.rfftfreq(n, 1.0 / fs)
    df = f[1] - f[0]
    half = max(band_rel * tooth_freq, 2.5 * df)
    k = np.round(f / tooth_freq)
    harm = np.abs(f - k * tooth_freq) <= half
    tot = P.sum()
    if tot <= 0:
        return 0.0, math.nan
    ratio = float(P[~harm].sum() / tot)
    Pn = np.where(harm, 0.0, P)
    return ratio, float(f[int(np.argmax(Pn))])


def amplitude_growth(displacement: np.ndarray, samples_per_rev: int,
                     samples_per_delay: int, regen: Regenerative | None = None
                     ) -> dict[str, float]:
    """Growth of the per-revolution amplitude of the regenerative displacement.

    ``max |r(t) - r(t - tau)|`` per revolution for the feed (Z) and radial (X, Y) parts of
    ``displacement`` (n_samples, 3) [m]: the last revolution's over the smallest of the first
    half of the run (as :func:`vibration_growth`). Returns ``{"feed", "radial"}``; NaN with
    fewer than 3 revolutions, 0 when the last amplitude is at round-off level. ``regen``:
    the :func:`regenerative` displacement when already computed.
    """
    ns, s = int(samples_per_rev), int(samples_per_delay)
    revs = np.shape(displacement)[0] // ns
    if revs < 3:
        return {"feed": math.nan, "radial": math.nan}
    r = regen if regen is not None else regenerative(displacement, s)
    m = revs * ns - s
    return {"feed": _growth(r.feed[:m], ns, r.xmax),
            "radial": _growth(r.radial[:m], ns, r.xmax)}


@dataclass(frozen=True)
class ChatterVerdict:
    """The verdicts on one simulated cut (see the module docstring)."""

    chatter: bool
    surface_finish: str | None
    tool_leaves_cut: bool
    paper_stable: bool | None
    vibration_growth: float
    feed_amplitude_growth: float
    radial_amplitude_growth: float
    nonharmonic_energy_ratio: float
    chatter_frequency_Hz: float | None
    dominant_nonharmonic_Hz: float
    roughness_Ra_m: float
    roughness_Rz_m: float
    form_slope_um_per_mm: float
    roughness_ok: bool
    tool_left_cut_fraction: float
    reasons: tuple[str, ...]
    floquet_multiplier: float = math.nan
    floquet_multiplier_se: float = math.nan
    chatter_decided: bool = True
    chatter_cause: str | None = None
    tool_leaves_cut_cause: str | None = None

    def verdicts(self) -> dict[str, Any]:
        """The named verdicts: ``chatter``, ``surface_finish``, ``tool_leaves_cut``,
        ``paper_criterion`` ("stable" / "vibratory" / None: not judged)."""
        paper = None if self.paper_stable is None else (
            "stable" if self.paper_stable else "vibratory")
        return {"chatter": self.chatter, "surface_finish": self.surface_finish,
                "tool_leaves_cut": self.tool_leaves_cut, "paper_criterion": paper}

    def to_dict(self) -> dict[str, Any]:
        d = dict(self.__dict__)
        d["reasons"] = list(self.reasons)
        return d


def _regenerative_tail(regen: Regenerative, samples_per_delay: int) -> float:
    """Largest regenerative displacement ``|r(t) - r(t - tau)|`` over the last delay [m]."""
    s = int(samples_per_delay)
    if regen.d.shape[0] < s:
        return math.inf
    return float(regen.d[-s:].max())


def _chip_scale(feed_per_rev_m: float, depth: float, n_inserts: int) -> float:
    """The size of the chip [m]: the feed per insert, or the depth where it is smaller."""
    fz = float(feed_per_rev_m) / max(int(n_inserts), 1)
    vals = [v for v in (fz, depth) if math.isfinite(v) and v > 0]
    return min(vals) if vals else math.inf


class ChatterDecision(NamedTuple):
    """The chatter verdict of a record (:func:`chatter_decision`), and the measures behind it.

    ``rule`` names what decided it: ``"diverged"``, ``"repeats every pitch"`` (the tool leaves
    the cut in a motion that repeats to below resolution), ``"grown out of the cut"``,
    ``"too short"`` (no multiplier: fewer than 7 pitches) or ``"multiplier"``.
    ``tail``: the largest regenerative displacement over the last pitch [m] (NaN when the
    tool stays in the cut). ``left_cause``: None when the tool stays in the cut."""

    chatter: bool
    decided: bool
    cause: str | None
    left_cause: str | None
    rule: str
    floquet_multiplier: float
    floquet_multiplier_se: float
    vibration_growth: float
    feed_amplitude_growth: float
    radial_amplitude_growth: float
    tool_left_cut_fraction: float
    tail: float


def chatter_decision(displacement: np.ndarray, chip_area: np.ndarray, samples_per_rev: int,
                     n_inserts: int, depth_m: float = math.nan,
                     feed_per_rev_m: float = math.nan, diverged: bool = False,
                     growth_limit: float = 1.0, tail_fraction: float = 0.3
                     ) -> ChatterDecision:
    """The chatter verdict (``chatter``, ``decided`` and their cause) of a record: the
    tool-point ``displacement`` (n_samples, 3) [m] and ``chip_area`` (n_samples, n_inserts)
    [m^2] of whole revolutions of ``samples_per_rev`` samples; :func:`classify` gives the same
    verdict on the record's Dataset (it adds the spectrum, the surface and the reasons).
    ``diverged``: the run stopped at the divergence limit (chatter)."""
    Ns = int(samples_per_rev)
    N = int(n_inserts)
    spd = Ns // N
    X = displacement
    regen = regenerative(X, spd)
    g = vibration_growth(X, spd, regen)
    ag = amplitude_growth(X, Ns, spd, regen)
    n0 = int(X.shape[0] * (1 - tail_fraction))
    left = float(np.mean(chip_area[n0:] <= 0))
    amp = max((v for v in ag.values() if math.isfinite(v)), default=math.nan)
    grows = (math.isfinite(g) and g > growth_limit and math.isfinite(amp)
             and amp > growth_limit)
    depth = float(depth_m)
    rho, se, _ = floquet_multiplier(X, spd, linear_limit_m=(
        LINEAR_FRACTION * depth if math.isfinite(depth) and depth > 0 else None), regen=regen)
    tail = _regenerative_tail(regen, spd) if left > 0 else math.nan
    decided = True
    cause = None
    left_cause = None
    if diverged:
        chatter, cause, rule = True, "diverged", "diverged"
    elif left > 0 and tail < AMPLITUDE_RESOLUTION_M:
        # the tool leaves the cut, but the motion repeats every insert pitch to below the
        # amplitude resolution: a bounded forced vibration that interrupts the cut, not
        # chatter (growth ratios of sub-resolution values are not findings)
        chatter, left_cause, rule = False, "forced vibration", "repeats every pitch"
    elif left > 0 and grows and tail > LINEAR_FRACTION * _chip_scale(feed_per_rev_m, depth, N):
        # regenerative vibration grown out of the linear range takes the tool out of the cut:
        # the regenerative displacement is a fraction of the chip thickness (the feed per
        # insert sets it; the depth where it is smaller) -- a forced vibration that
        # interrupts the cut leaves it orders of magnitude below
        chatter, cause, left_cause = True, "tool leaves the cut", "regenerative vibration"
        rule = "grown out of the cut"
    elif not math.isfinite(rho):
        chatter, decided, rule = grows, False, "too short"
        if left > 0:
            left_cause = "undecided"
    else:
        ln = math.log(rho) if rho > 0 else -math.inf
        decided = abs(ln) > max(DECISION_SIGMAS * se, DECISION_FLOOR)
        chatter = rho > 1.0
        rule = "multiplier"
        if left > 0:
            left_cause = ("undecided" if not decided else
                          "regenerative vibration" if chatter else "forced vibration")
        if chatter:
            cause = "regenerative"
    return ChatterDecision(bool(chatter), bool(decided), cause,
                           left_cause if left > 0 else None, rule, rho, se, g, ag["feed"],
                           ag["radial"], left, tail)


def classify(ds: xr.Dataset, growth_limit: float = 1.0, ra_tolerance_m: float | None = None,
             tail_fraction: float = 0.3, decision: ChatterDecision | None = None
             ) -> ChatterVerdict:
    """The verdicts on a simulation Dataset (:func:`~robobore.dynamics.timedomain.simulate`);
    see the module docstring. ``reasons`` lists, for each verdict that flags the cut, why.
    The chatter verdict is :func:`chatter_decision`'s on the Dataset's record; ``decision``:
    that decision when the caller has already made it (on the same record, with the same
    ``growth_limit`` and ``tail_fraction``)."""
    Ns = int(ds.attrs["samples_per_rev"])
    N = int(ds.attrs["n_inserts"])
    X = ds["displacement"].values
    diverged = bool(int(ds.attrs.get("diverged", 0)))
    dec = decision if decision is not None else chatter_decision(
        X, ds["chip_area"].values, Ns, N, float(ds.attrs.get("depth_m", math.nan)),
        float(ds.attrs.get("feed_per_rev_m", math.nan)), diverged, growth_limit,
        tail_fraction)
    g, rho, se, left = (dec.vibration_growth, dec.floquet_multiplier,
                        dec.floquet_multiplier_se, dec.tool_left_cut_fraction)
    fs = 1.0 / float(ds.attrs["dt_s"])
    tooth = float(ds.attrs["speed_rpm"]) / 60.0 * N
    n0 = int(X.shape[0] * (1 - tail_fraction))
    ratio, fpk = harmonic_analysis(X[n0:], fs, tooth)
    ra = float(ds.attrs.get("Ra_m", math.nan))
    rz = float(ds.attrs.get("Rz_m", math.nan))
    slope = float(ds.attrs.get("form_slope_um_per_mm", math.nan))
    has_tol = ra_tolerance_m is not None and math.isfinite(ra)
    r_ok = True if not has_tol else ra <= ra_tolerance_m
    chatter, decided = dec.chatter, dec.decided
    reasons = []
    if dec.rule == "diverged":
        reasons.append(f"chatter: vibration diverged (tool-point displacement above "
                       f"{float(ds.attrs['divergence_limit_m']) * 1e3:.3g} mm at "
                       f"t = {float(ds.attrs['diverged_at_s']):.4g} s)")
    elif dec.rule == "repeats every pitch":
        reasons.append(f"no chatter: the forced vibration takes the tool out of the cut and "
                       f"the motion repeats every insert pitch (regenerative displacement "
                       f"{dec.tail * 1e9:.2g} nm, below the "
                       f"{AMPLITUDE_RESOLUTION_M * 1e9:g} nm resolution)")
    elif dec.rule == "grown out of the cut":
        reasons.append(f"chatter: vibration grows and the tool leaves the cut (nonlinear: "
                       f"regenerative envelope x{g:.3g}, feed amplitude "
                       f"x{dec.feed_amplitude_growth:.3g}, radial "
                       f"x{dec.radial_amplitude_growth:.3g}) at {fpk:.4g} Hz")
    elif dec.rule == "too short":
        reasons.append("undecided: the run is too short for a growth estimate (fewer than 7 "
                       "insert pitches); lengthen [simulation] revolutions")
    else:
        if left > 0 and decided and not chatter:
            reasons.append(f"no chatter: the forced vibration takes the tool out of the "
                           f"cut; the regenerative vibration decays x{rho:.4g} per insert "
                           f"pitch (+-{se:.2g} in ln)")
        if chatter:
            reasons.append(f"chatter: vibration grows x{rho:.4g} per insert pitch (Floquet "
                           f"multiplier of the simulated cut, +-{se:.2g} in ln) at "
                           f"{fpk:.4g} Hz")
        if not decided:
            reasons.append(f"undecided: multiplier {rho:.5g} per insert pitch (+-{se:.2g} in "
                           "ln) is within the fit's uncertainty of 1: the cut is at its "
                           "stability limit; lengthen [simulation] revolutions to decide")
    if not r_ok:
        reasons.append(f"rough: Ra {ra * 1e6:.3g} um (form removed) above tolerance "
                       f"{ra_tolerance_m * 1e6:.3g} um")
    if left > 0:
        reasons.append(f"tool leaves the cut in {100 * left:.3g} % of the last "
                       f"{100 * tail_fraction:.3g} % of the run")
    finish = None if not has_tol else ("ok" if r_ok else "rough")
    if diverged or chatter or not r_ok:
        paper_stable: bool | None = False
    else:
        paper_stable = True if has_tol else None
    if paper_stable is None:
        reasons.append("paper's criterion not judged: no Ra tolerance "
                       "([simulation] ra_tolerance_um)")
    freq = fpk if (chatter and not diverged and math.isfinite(fpk) and fpk > 0) else None
    return ChatterVerdict(chatter, finish, left > 0, paper_stable, g, dec.feed_amplitude_growth,
                          dec.radial_amplitude_growth, ratio, freq, fpk, ra, rz, slope, r_ok,
                          left, tuple(reasons), rho, se, decided, dec.cause, dec.left_cause)


__all__ = ["vibration_growth", "regenerative", "Regenerative", "amplitude_growth", "harmonic_analysis", "classify",
           "chatter_decision", "ChatterDecision",
           "ChatterVerdict", "floquet_multiplier", "resolved", "FLOQUET_FLOOR",
           "DECISION_SIGMAS", "DECISION_FLOOR", "AMPLITUDE_RESOLUTION_M", "LINEAR_FRACTION"]
