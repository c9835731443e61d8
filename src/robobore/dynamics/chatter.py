"""Chatter indicators from simulated (or measured) signals.

* ``vibration_growth``: envelope of the regenerative displacement ``|r(t) - r(t - tau)|``
  (``tau`` = insert pitch) over the last delay period divided by that over the first one. A
  stable process settles on a motion that repeats every pitch (forced vibration at the
  tooth-passing frequency and its harmonics), so the envelope decays; chatter makes it grow.
* ``nonharmonic_energy_ratio`` and ``chatter_frequency_Hz``: spectrum of the displacement over
  the last part of the run; energy outside narrow bands around the tooth-passing harmonics
  ``k N n / 60`` divided by the total; the chatter frequency is the largest peak outside them.
* roughness (Ra of the machined surface) against a tolerance -- the paper's own criterion
  (a cut is called vibratory when the surface roughness exceeds the requirement).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr


def vibration_growth(displacement: np.ndarray, samples_per_delay: int) -> float:
    """Envelope ratio (last / first delay period) of ``|r(t) - r(t - tau)|``.

    ``displacement``: (n_samples, 3) [m]. Returns 0 when the first envelope is zero.
    """
    X = np.asarray(displacement, float)
    s = int(samples_per_delay)
    if X.shape[0] < 3 * s:
        return math.nan
    d = np.linalg.norm(X[s:] - X[:-s], axis=1)
    first = d[:s].max()
    last = d[-s:].max()
    return float(last / first) if first > 0 else 0.0


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


@dataclass(frozen=True)
class ChatterVerdict:
    """Classification of one simulated cut."""

    stable: bool
    vibration_growth: float
    nonharmonic_energy_ratio: float
    chatter_frequency_Hz: float | None
    dominant_nonharmonic_Hz: float
    roughness_Ra_m: float
    roughness_ok: bool
    tool_left_cut_fraction: float
    reasons: tuple[str, ...]

    def to_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


def classify(ds: xr.Dataset, growth_limit: float = 1.0, ra_tolerance_m: float | None = None,
             tail_fraction: float = 0.3) -> ChatterVerdict:
    """Stable / vibratory verdict from a simulation Dataset (:func:`simulate`).

    Vibratory if the run diverged (see :class:`~robobore.dynamics.timedomain.SimulationSettings`),
    the regenerative envelope grows (``vibration_growth > growth_limit``) or the
    surface roughness exceeds ``ra_tolerance_m``. The chatter frequency is reported (largest
    peak away from the tooth-passing harmonics in the last ``tail_fraction`` of the run) when
    vibratory, ``None`` when stable.
    """
    Ns = int(ds.attrs["samples_per_rev"])
    N = int(ds.attrs["n_inserts"])
    spd = Ns // N
    X = ds["displacement"].values
    g = vibration_growth(X, spd)
    fs = 1.0 / float(ds.attrs["dt_s"])
    tooth = float(ds.attrs["speed_rpm"]) / 60.0 * N
    n0 = int(X.shape[0] * (1 - tail_fraction))
    ratio, fpk = harmonic_analysis(X[n0:], fs, tooth)
    ra = float(ds.attrs.get("Ra_m", math.nan))
    r_ok = True if ra_tolerance_m is None or not math.isfinite(ra) else ra <= ra_tolerance_m
    area = ds["chip_area"].values
    left = float(np.mean(area[n0:] <= 0))
    reasons = []
    if int(ds.attrs.get("diverged", 0)):
        reasons.append(f"vibration diverged: tool-point displacement above "
                       f"{float(ds.attrs['divergence_limit_m']) * 1e3:.3g} mm at "
                       f"t = {float(ds.attrs['diverged_at_s']):.4g} s")
    if not math.isfinite(g) or g > growth_limit:
        reasons.append(f"vibration envelope grows (x{g:.3g})")
    if not r_ok:
        reasons.append(f"Ra {ra * 1e6:.3g} um above tolerance {ra_tolerance_m * 1e6:.3g} um")
    stable = not reasons
    return ChatterVerdict(stable, g, ratio, None if stable else fpk, fpk, ra, r_ok, left,
                          tuple(reasons))


__all__ = ["vibration_growth", "harmonic_analysis", "classify", "ChatterVerdict"]
