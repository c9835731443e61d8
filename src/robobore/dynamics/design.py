"""Adaptive test design: the next test cut(s) from the current posterior of
:mod:`robobore.dynamics.calibrate` ("which cut should I make next?").

A test cut's outcome is a verdict, chatter or stable, whose probability the calibration models
as ``P(chatter | g) = eps + (1 - 2 eps) Phi((ln a - g) / s)`` with ``g = ln a_crit(n)`` the
log critical depth at the cut's speed, ``eps`` the label-noise rate and ``s`` the verdict's
spread (:class:`~robobore.dynamics.calibrate.LikelihoodSettings`). The band
(:class:`~robobore.dynamics.band.LobeBand`) gives the posterior of ``g`` at each of its speeds
as a Gaussian ``N(g0, sd^2)`` (``ln median_m``, ``log_sd``).

Two criteria (``criterion``), both from MacKay 1992 ("Information-based objective functions
for active data selection", Neural Computation 4(4), 590-604), both cutting at the band's
median depth:

* ``"point"``: the most expected information of the verdict about ``g`` at the cut's own
  speed, the mutual information ``I(n, a) = H2(P(chatter)) - E_g[H2(P(chatter | g))]``
  (``H2`` the binary entropy in bits; the binary-outcome form of Houlsby, Huszar, Ghahramani
  & Lengyel 2011, "Bayesian active learning for classification and preference learning",
  arXiv:1112.5745), by Gauss-Hermite quadrature over ``g``. For the probit model the
  predictive probability is ``eps + (1 - 2 eps) Phi((ln a - g0) / sqrt(s^2 + sd^2))``; at
  every speed it is 0.5 (the predictive entropy's maximum: uncertainty sampling) at the
  median depth, and there ``I`` rises with ``sd / s``: the speed of the largest ``log_sd``.
* ``"mean"`` (default): the most mean marginal information over the band's speeds (MacKay
  1992, section 4.2: the information about the interpolant at the points of interest, which
  does not pile the cuts where the model alone is wide). The band's ``sensitivity`` ``S``
  gives the linearised joint covariance ``C = S S^T`` of ``g`` over the speeds; a verdict at
  speed ``m`` at the median depth is taken as a Gaussian measurement of ``g(m)`` of variance
  ``1 / F(m)``, ``F`` the Fisher information of the probit verdict about ``g`` averaged over
  ``g``'s posterior (quadrature), and updates ``C`` by the Kalman (rank-one) step. The value
  of ``m`` is the mean over the speeds ``n`` of ``0.5 log2(C(n, n) / C'(n, n))`` [bit].

Several cuts are chosen greedily: with ``"mean"`` the covariance is updated by each chosen
cut before the next is chosen (the proposals spread by themselves); with ``"point"``, each is
at least ``min_spacing_rpm`` from those already chosen (neighbouring speeds share the
parameters and would ask the same question).

Candidates are the band's speeds (``calibrate(..., speeds=...)`` sets them); they are also the
points of interest of ``"mean"``. A speed whose median lies at the bottom or at the top of
the depth scan (unstable at vanishing depth, or stable up to the scan's top) is not proposed:
a cut there does not bracket a limit. A band without ``sensitivity`` takes ``"point"``. The
truth is never used: the proposal depends on the band alone.

A proposed depth is never deeper than the cut can be: the depth-of-cut range of
:mod:`robobore.io.ranges` (``depth_mm``, the one definition of a plausible depth) and, when
given, the config's ``[calibration] max_depth_mm`` (what the insert, the machine and the part
allow), whichever is smaller (:func:`depth_cap`). Where the band's median is deeper, the cut is
at the cap; its ``p_chatter`` and ``information_bits`` are those of the capped depth, its
``why`` and ``depth_capped_by`` say which limit bound. The choice of the speed stays that of
the median depth.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.stats import norm

from robobore.dynamics.band import DEPTH_FLOOR_M, LobeBand
from robobore.dynamics.semidiscretization import DEPTH_SCAN_HI_M
from robobore.errors import ConfigError
from robobore.io.ranges import RANGES

#: Default smallest distance between two cuts proposed together, as a share of the
#: candidates' speed span.
MIN_SPACING_SHARE = 0.1
#: The design criteria of :func:`propose_cuts`.
CRITERIA = ("mean", "point")
#: Gauss-Hermite nodes of the expectation over the log critical depth.
QUADRATURE_NODES = 40


@dataclass(frozen=True)
class ProposedCut:
    """A proposed test cut: speed [r/min], depth [m], the predicted probability of chatter,
    the band's ``log_sd`` there, the expected information of its verdict about the critical
    depth at its speed [bit], why, the criterion that chose it and, for ``"mean"``, its mean
    information over the band's speeds [bit]. ``depth_capped_by``: the limit that set the depth
    below the band's median (:func:`depth_cap`), None where the depth is the median;
    ``median_depth_m``: the band's median there."""

    speed_rpm: float
    depth_m: float
    p_chatter: float
    log_sd: float
    information_bits: float
    why: str
    criterion: str = "point"
    mean_information_bits: float = float("nan")
    depth_capped_by: str | None = None
    median_depth_m: float = float("nan")

    def to_dict(self) -> dict[str, Any]:
        return {"speed_rpm": self.speed_rpm, "depth_mm": self.depth_m * 1e3,
                "depth_capped_by": self.depth_capped_by,
                "band_median_depth_mm": self.median_depth_m * 1e3,
                "p_chatter": self.p_chatter, "critical_depth_log_sd": self.log_sd,
                "expected_information_bits": self.information_bits,
                "mean_information_bits": None if math.isnan(self.mean_information_bits)
                else self.mean_information_bits, "criterion": self.criterion,
                "why": self.why}


def _h2(p: np.ndarray) -> np.ndarray:
    p = np.clip(p, 1e-300, 1.0 - 1e-16)
    return -(p * np.log2(p) + (1.0 - p) * np.log2(1.0 - p))


def predictive_p_chatter(log_sd: np.ndarray | float, depth_offset_ln: np.ndarray | float,
                         label_noise: float, verdict_spread: float) -> np.ndarray:
    """P(chatter) of a cut ``depth_offset_ln`` (``ln a - g0``) from the band's median when the
    log critical depth is ``N(g0, log_sd^2)`` (the probit verdict integrated over it)."""
    sd = np.asarray(log_sd, float)
    z = np.asarray(depth_offset_ln, float) / np.sqrt(verdict_spread ** 2 + sd ** 2)
    return label_noise + (1.0 - 2.0 * label_noise) * norm.cdf(z)


def expected_information(log_sd: np.ndarray | float, depth_offset_ln: np.ndarray | float,
                         label_noise: float, verdict_spread: float) -> np.ndarray:
    """Mutual information [bit] between a cut's verdict and the log critical depth
    ``N(g0, log_sd^2)`` for a cut ``depth_offset_ln`` from the median (module docstring)."""
    sd = np.atleast_1d(np.asarray(log_sd, float))
    off = np.broadcast_to(np.asarray(depth_offset_ln, float), sd.shape)
    x, w = np.polynomial.hermite_e.hermegauss(QUADRATURE_NODES)
    w = w / w.sum()
    g = sd[:, None] * x[None, :]  # g - g0
    p = label_noise + (1.0 - 2.0 * label_noise) * norm.cdf((off[:, None] - g) / verdict_spread)
    cond = (_h2(p) * w[None, :]).sum(axis=1)
    out = _h2(predictive_p_chatter(sd, off, label_noise, verdict_spread)) - cond
    return np.maximum(out, 0.0)


def verdict_fisher(log_sd: np.ndarray | float, label_noise: float,
                   verdict_spread: float) -> np.ndarray:
    """Fisher information [1 / (ln depth)^2] of a verdict at the band's median depth about
    ``g``, averaged over ``g ~ N(g0, log_sd^2)``: ``E[(dP/dg)^2 / (P (1 - P))]``."""
    sd = np.atleast_1d(np.asarray(log_sd, float))
    x, w = np.polynomial.hermite_e.hermegauss(QUADRATURE_NODES)
    w = w / w.sum()
    z = -(sd[:, None] * x[None, :]) / verdict_spread
    p = label_noise + (1.0 - 2.0 * label_noise) * norm.cdf(z)
    dp = (1.0 - 2.0 * label_noise) * norm.pdf(z) / verdict_spread
    return ((dp ** 2 / np.clip(p * (1.0 - p), 1e-300, None)) * w[None, :]).sum(axis=1)


def mean_information(cov: np.ndarray, fisher: np.ndarray) -> np.ndarray:
    """Mean marginal information [bit] over the speeds of a Gaussian measurement of ``g`` at
    each speed ``m`` of variance ``1 / fisher[m]``, for the joint covariance ``cov`` of ``g``
    (module docstring)."""
    var = np.diag(cov).copy()
    ok = var > 0
    r = 1.0 / np.maximum(fisher, 1e-300)
    new = var[:, None] - cov ** 2 / (var[None, :] + r[None, :])  # [n, m]
    with np.errstate(divide="ignore", invalid="ignore"):
        gain = 0.5 * np.log2(var[:, None] / np.maximum(new, 1e-300 * np.maximum(var[:, None],
                                                                                1e-300)))
    gain = np.where(ok[:, None], gain, 0.0)
    return gain.mean(axis=0) if var.size else np.zeros(0)


def depth_cap(max_depth_m: float | None = None) -> tuple[float, str]:
    """The deepest cut [m] a proposal may have and the limit that sets it, in words: the top
    of the depth-of-cut range of :mod:`robobore.io.ranges` or ``max_depth_m`` (the config's
    ``[calibration] max_depth_mm``), whichever is smaller."""
    r = RANGES["depth_mm"]
    cap = (r.hi * 1e-3, f"the depth-of-cut range of robobore.io.ranges ({r.bounds()})")
    if max_depth_m is None:
        return cap
    m = float(max_depth_m)
    if not (math.isfinite(m) and m > 0.0):
        raise ConfigError("largest depth of a proposed cut must be positive",
                          field="calibration.max_depth_mm", value=m * 1e3,
                          expected=f"{r.bounds()}")
    if m < cap[0]:
        return m, f"[calibration] max_depth_mm = {m * 1e3:g} mm"
    return cap


def propose_cuts(source: LobeBand | Any, n: int = 1, label_noise: float | None = None,
                 verdict_spread: float | None = None, min_spacing_rpm: float | None = None,
                 criterion: str = "mean", max_depth_m: float | None = None
                 ) -> list[ProposedCut]:
    """The ``n`` next test cuts (module docstring) from a
    :class:`~robobore.dynamics.calibrate.Calibration` (its band and likelihood settings) or a
    :class:`~robobore.dynamics.band.LobeBand` (with ``label_noise`` and ``verdict_spread``,
    default 0.1 each). Candidates: the band's speeds. ``criterion``: ``"mean"`` or
    ``"point"``. ``min_spacing_rpm`` (``"point"``): the smallest distance between two
    proposed cuts (default :data:`MIN_SPACING_SHARE` of the candidates' span).
    ``max_depth_m``: the config's largest depth of a test cut (:func:`depth_cap`; the range's
    top always applies). Fewer than ``n`` cuts come back when no candidate is left."""
    band = source if isinstance(source, LobeBand) else source.band
    settings = getattr(source, "settings", None)
    eps = label_noise if label_noise is not None else (
        settings.label_noise if settings is not None else 0.1)
    s = verdict_spread if verdict_spread is not None else (
        settings.verdict_spread if settings is not None else 0.1)
    if not 1 <= n <= 100:
        raise ConfigError("number of proposed cuts out of range", field="n", value=n,
                          expected="1 .. 100 cuts")
    if criterion not in CRITERIA:
        raise ConfigError("unknown design criterion", field="criterion", value=criterion,
                          expected=" or ".join(CRITERIA))
    if band.sensitivity is None:
        criterion = "point"
    speeds = np.asarray(band.speed_rpm, float)
    span = float(speeds.max() - speeds.min()) if speeds.size else 0.0
    spacing = MIN_SPACING_SHARE * span if min_spacing_rpm is None else float(min_spacing_rpm)
    if spacing < 0:
        raise ConfigError("proposal spacing must not be negative", field="min_spacing_rpm",
                          value=spacing, expected=">= 0 r/min")
    cap_m, cap_by = depth_cap(max_depth_m)
    med = np.asarray(band.median_m, float)
    inside = (med > DEPTH_FLOOR_M * (1 + 1e-9)) & (med < DEPTH_SCAN_HI_M * (1 - 1e-9))
    sd = np.asarray(band.log_sd, float).copy()
    info = expected_information(sd, 0.0, eps, s)
    p50 = predictive_p_chatter(sd, 0.0, eps, s)
    cov = None
    if criterion == "mean":
        S = np.asarray(band.sensitivity, float)
        cov = S @ S.T
    free = inside.copy()
    out: list[ProposedCut] = []
    while len(out) < n and free.any():
        if cov is not None:
            sd_now = np.sqrt(np.maximum(np.diag(cov), 0.0))
            fisher = verdict_fisher(sd_now, eps, s)
            value = mean_information(cov, fisher)
            i = int(np.argmax(np.where(free, value, -np.inf)))
            why = (f"most mean information over the band's {speeds.size} speeds"
                   f"{' after the cuts proposed before it' if out else ''}: "
                   f"{value[i]:.3f} bit per speed; verdict's information at the cut "
                   f"{info[i]:.3f} bit (critical depth log sd {sd[i]:.3f}, 90 % band "
                   f"{band.lower_m[i] * 1e3:.3g}-{band.upper_m[i] * 1e3:.3g} mm); depth at "
                   f"the band's median, where P(chatter) = {p50[i]:.2f}")
            mean_bits = float(value[i])
            c = cov[:, i].copy()
            cov = cov - np.outer(c, c) / (cov[i, i] + 1.0 / max(float(fisher[i]), 1e-300))
        else:
            i = int(np.argmax(np.where(free, info, -np.inf)))
            apart = f" at least {spacing:.0f} r/min from the cuts proposed before it" if out else ""
            why = (f"largest expected information of a verdict among the candidate speeds"
                   f"{apart}: {info[i]:.3f} bit (critical depth log sd {sd[i]:.3f}, 90 % band "
                   f"{band.lower_m[i] * 1e3:.3g}-{band.upper_m[i] * 1e3:.3g} mm); depth at the "
                   f"band's median, where P(chatter) = {p50[i]:.2f}")
            mean_bits = float("nan")
        depth, p_ch, bits, capped = float(med[i]), float(p50[i]), float(info[i]), None
        if depth > cap_m:
            off = math.log(cap_m / depth)
            depth, capped = cap_m, cap_by
            p_ch = float(predictive_p_chatter(sd[i], off, eps, s))
            bits = float(expected_information(sd[i], off, eps, s)[0])
            why += (f"; the median {med[i] * 1e3:.3g} mm is deeper than the cut can be: depth "
                    f"capped at {cap_m * 1e3:.3g} mm by {cap_by}, where P(chatter) = "
                    f"{p_ch:.2f} and the verdict's information is {bits:.3f} bit")
        out.append(ProposedCut(float(speeds[i]), depth, p_ch, float(sd[i]), bits, why,
                               criterion, mean_bits, capped, float(med[i])))
        if cov is not None:
            free[i] = False
        else:
            free &= np.abs(speeds - speeds[i]) >= max(spacing, 1e-9 * max(span, 1.0))
    return out


__all__ = ["ProposedCut", "propose_cuts", "depth_cap", "expected_information", "predictive_p_chatter",
           "verdict_fisher", "mean_information", "CRITERIA",
           "MIN_SPACING_SHARE", "QUADRATURE_NODES"]
