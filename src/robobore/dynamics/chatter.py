"""Verdicts on a simulated (or measured) cut, each by its cause.

A cut gets separate, named verdicts (:func:`classify`, :class:`ChatterVerdict`):

* ``chatter`` -- self-excited (regenerative) vibration: the vibration GROWS over the
  revolutions. Two measures must both exceed ``growth_limit`` (default 1): the envelope of
  the regenerative displacement ``|r(t) - r(t - tau)|`` (``tau`` = insert pitch; a stable
  process settles on a motion that repeats every pitch, so this decays) over the last delay
  period divided by the smallest per-delay envelope of the first half of the run
  (:func:`vibration_growth`: the decay of the entry transient neither hides growth after it
  nor counts as growth, and vibration that grew and saturated reads as grown), and the same
  growth of the per-revolution amplitude of that displacement in the feed (Z) or radial (XY)
  direction (:func:`amplitude_growth`). A run that diverged (tool-point displacement above
  the divergence limit) is chatter. A cut whose amplitude does not grow is not chatter,
  however rough. Reported with it: the chatter frequency
  (largest spectral peak away from the tooth-passing harmonics ``k N n / 60``, in the last
  ``tail_fraction`` of the run) and the non-harmonic energy fraction of the displacement
  (:func:`harmonic_analysis`).
* ``surface_finish`` -- ``"ok"`` / ``"rough"``: Ra of the machined profile AFTER removing its
  form (least-squares line: offset and taper, :func:`robobore.dynamics.timedomain.roughness`)
  against the tolerance; ``None`` without a tolerance. Feed marks alone can make a cut rough.
* ``tool_leaves_cut`` -- an insert is out of the material (chip area <= 0) in some of the
  last ``tail_fraction`` of the run (``tool_left_cut_fraction`` > 0): the cut is interrupted,
  the linear models no longer apply.
* ``paper_stable`` -- the paper's own criterion (its "stable" / "vibratory"): vibratory when
  Ra (form removed) exceeds the tolerance, or when the run diverged. It is a roughness
  criterion: it calls a cut vibratory whose feed marks alone exceed the tolerance. The study
  summaries keep it under the name ``stable``, so that measured data classified the paper's
  way compare with it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr


def vibration_growth(displacement: np.ndarray, samples_per_delay: int) -> float:
    """Growth of the envelope of ``|r(t) - r(t - tau)|``: its maximum over the last delay
    period over the smallest per-delay maximum of the first half of the run.

    Measured from the quietest point of the first half, not from the first delay, so that
    the decay of the entry transient does not hide growth that follows it, and vibration
    that grew and then saturated (the tool leaving the cut) still reads as grown.
    ``displacement``: (n_samples, 3) [m]. Returns 0 when the last envelope is at round-off
    level (:data:`ROUNDOFF`), i.e. the motion repeats every delay.
    """
    X = np.asarray(displacement, float)
    s = int(samples_per_delay)
    if X.shape[0] < 3 * s:
        return math.nan
    d = np.linalg.norm(X[s:] - X[:-s], axis=1)
    return _growth(d, s, X)


def _growth(d: np.ndarray, period: int, X: np.ndarray) -> float:
    """Last period's maximum of ``d`` over the smallest period maximum of the first half."""
    n = d.shape[0] // period
    peaks = d[:n * period].reshape(n, period).max(axis=1)
    first_half = peaks[:max(1, n // 2)]
    return _ratio(float(first_half.min()), float(d[-period:].max()), X)


#: Relative floor of the regenerative displacement: below ``ROUNDOFF x max |displacement|``
#: a difference is round-off of an exactly periodic motion, not vibration.
ROUNDOFF = 1e-9


def _ratio(first: float, last: float, X: np.ndarray) -> float:
    floor = ROUNDOFF * float(np.abs(X).max()) if X.size else 0.0
    if last <= floor:
        return 0.0
    return float(last / max(first, floor)) if max(first, floor) > 0 else math.inf


def harmonic_analysis(signal: np.ndarray, fs: float, tooth_freq: float,
                      band_rel: float = 0.02) -> tuple[float, float]:
    """Non-harmonic energy ratio and the largest non-harmonic peak frequency [Hz].

    ``signal``: (n,) or (n, c). Bands of half-width ``max(band_rel * f_tooth, 2 bins)`` around
    every harmonic of the tooth-passing frequency (including 0 Hz) count as harmonic.
    """
    x = np.asarray(signal, float)
    if x.ndim == 1:
        x = x[:, None]
    x = x - x.mean(axis=0)
    n = x.shape[0]
    win = np.hanning(n)[:, None]
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
                     samples_per_delay: int) -> dict[str, float]:
    """Growth of the per-revolution amplitude of the regenerative displacement.

    ``max |r(t) - r(t - tau)|`` per revolution for the feed (Z) and radial (X, Y) parts of
    ``displacement`` (n_samples, 3) [m]: the last revolution's over the smallest of the first
    half of the run (as :func:`vibration_growth`). Returns ``{"feed", "radial"}``; NaN with
    fewer than 3 revolutions, 0 when the last amplitude is at round-off level.
    """
    X = np.asarray(displacement, float)
    ns, s = int(samples_per_rev), int(samples_per_delay)
    revs = X.shape[0] // ns
    if revs < 3:
        return {"feed": math.nan, "radial": math.nan}
    D = X[s:revs * ns] - X[:revs * ns - s]
    out = {}
    for name, d in (("feed", np.abs(D[:, 2])), ("radial", np.linalg.norm(D[:, :2], axis=1))):
        out[name] = _growth(d, ns, X)
    return out


@dataclass(frozen=True)
class ChatterVerdict:
    """The verdicts on one simulated cut (see the module docstring)."""

    chatter: bool
    surface_finish: str | None
    tool_leaves_cut: bool
    paper_stable: bool
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

    def verdicts(self) -> dict[str, Any]:
        """The named verdicts: ``chatter``, ``surface_finish``, ``tool_leaves_cut``,
        ``paper_criterion`` ("stable" / "vibratory")."""
        return {"chatter": self.chatter, "surface_finish": self.surface_finish,
                "tool_leaves_cut": self.tool_leaves_cut,
                "paper_criterion": "stable" if self.paper_stable else "vibratory"}

    def to_dict(self) -> dict[str, Any]:
        d = dict(self.__dict__)
        d["reasons"] = list(self.reasons)
        return d


def classify(ds: xr.Dataset, growth_limit: float = 1.0, ra_tolerance_m: float | None = None,
             tail_fraction: float = 0.3) -> ChatterVerdict:
    """The verdicts on a simulation Dataset (:func:`~robobore.dynamics.timedomain.simulate`);
    see the module docstring. ``reasons`` lists, for each verdict that flags the cut, why."""
    Ns = int(ds.attrs["samples_per_rev"])
    N = int(ds.attrs["n_inserts"])
    spd = Ns // N
    X = ds["displacement"].values
    g = vibration_growth(X, spd)
    ag = amplitude_growth(X, Ns, spd)
    fs = 1.0 / float(ds.attrs["dt_s"])
    tooth = float(ds.attrs["speed_rpm"]) / 60.0 * N
    n0 = int(X.shape[0] * (1 - tail_fraction))
    ratio, fpk = harmonic_analysis(X[n0:], fs, tooth)
    ra = float(ds.attrs.get("Ra_m", math.nan))
    rz = float(ds.attrs.get("Rz_m", math.nan))
    slope = float(ds.attrs.get("form_slope_um_per_mm", math.nan))
    has_tol = ra_tolerance_m is not None and math.isfinite(ra)
    r_ok = True if not has_tol else ra <= ra_tolerance_m
    area = ds["chip_area"].values
    left = float(np.mean(area[n0:] <= 0))
    diverged = bool(int(ds.attrs.get("diverged", 0)))
    amp = max((v for v in ag.values() if math.isfinite(v)), default=math.nan)
    grows = (math.isfinite(g) and g > growth_limit and math.isfinite(amp)
             and amp > growth_limit)
    chatter = diverged or grows
    reasons = []
    if diverged:
        reasons.append(f"chatter: vibration diverged (tool-point displacement above "
                       f"{float(ds.attrs['divergence_limit_m']) * 1e3:.3g} mm at "
                       f"t = {float(ds.attrs['diverged_at_s']):.4g} s)")
    elif grows:
        reasons.append(f"chatter: vibration grows (regenerative envelope x{g:.3g}, feed "
                       f"amplitude x{ag['feed']:.3g}, radial x{ag['radial']:.3g}) at "
                       f"{fpk:.4g} Hz")
    if not r_ok:
        reasons.append(f"rough: Ra {ra * 1e6:.3g} um (form removed) above tolerance "
                       f"{ra_tolerance_m * 1e6:.3g} um")
    if left > 0:
        reasons.append(f"tool leaves the cut in {100 * left:.3g} % of the last "
                       f"{100 * tail_fraction:.3g} % of the run")
    finish = None if not has_tol else ("ok" if r_ok else "rough")
    paper_stable = r_ok and not diverged
    return ChatterVerdict(chatter, finish, left > 0, paper_stable, g, ag["feed"], ag["radial"],
                          ratio, fpk if chatter else None, fpk, ra, rz, slope, r_ok, left,
                          tuple(reasons))


__all__ = ["vibration_growth", "amplitude_growth", "harmonic_analysis", "classify",
           "ChatterVerdict"]
