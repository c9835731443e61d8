"""Confidence band of the stability lobes: the critical depth's 5/50/95 % over speed and the
probability of chatter over a speed x depth grid, for a robot model whose parameters are
known up to a Gaussian distribution (in log space).

One implementation serves both sources of uncertainty: the posterior of the model corrected by
observed cuts (:mod:`robobore.dynamics.calibrate`) and the modes' intervals carried by the
equivalent model (:attr:`robobore.equivalent.EquivalentModel.uncertainty`,
:func:`modal_band`).

Method: linearised sensitivity of ``g(n) = ln a_crit(n)`` along the principal axes of the
parameter covariance. With ``Sigma = sum_j lambda_j u_j u_j^T``, the lobes are computed at
``theta0 +- sqrt(lambda_j) u_j`` and ``var g(n) = sum_j ((g_j+ - g_j-) / 2)^2`` (central
secants one standard deviation wide: the first-order propagation of uncertainty,
JCGM 100:2008 section 5.1, with a secant on the scale of the spread rather than a tangent).
``g(n)`` is then taken as Gaussian: the critical depth's quantiles are
``exp(g0 +- 1.645 sd)`` and the probability of chatter at depth ``a`` is
``Phi((ln a - g0) / sd)``. A zero covariance gives the nominal lobes and a step at them.
Critical depths are the lobes' chatter limit,
:func:`~robobore.dynamics.semidiscretization.chatter_limit` (the linear limit, above the
interruption where the steady cut is interrupted at vanishing depth; a speed stable up to the
top of the depth scan counts as the top, one unstable at the bottom as the bottom).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.stats import norm

from robobore.dynamics.process import CuttingProcess
from robobore.dynamics.semidiscretization import (
    DEPTH_SCAN_DECADES,
    DEPTH_SCAN_HI_M,
    chatter_limit,
)
from robobore.dynamics.structure import ToolPointStructure

#: Two-sided 90 % band: the 5 % and 95 % quantiles of a Gaussian are mean -+ Z90 sd.
Z90 = float(norm.ppf(0.95))
#: Lowest depth a critical depth is reported as [m] (the bottom of the depth scan).
DEPTH_FLOOR_M = DEPTH_SCAN_HI_M * 10.0 ** (-DEPTH_SCAN_DECADES)


def clipped(a: np.ndarray | float) -> np.ndarray:
    """Critical depths [m] clipped to the scan range (inf -> its top, 0 -> its bottom)."""
    return np.clip(np.nan_to_num(np.asarray(a, float), posinf=DEPTH_SCAN_HI_M),
                   DEPTH_FLOOR_M, DEPTH_SCAN_HI_M)


def critical_depths(structure: ToolPointStructure, process: CuttingProcess,
                    speeds: np.ndarray, guess: np.ndarray | None = None) -> np.ndarray:
    """Chatter limit [m] (:func:`~robobore.dynamics.semidiscretization.chatter_limit`) at each
    speed (clipped, :func:`clipped`). ``guess`` (m, one a
    speed, e.g. the nominal model's): each search continues from it; without it, from the
    previous speed's limit."""
    speeds = np.asarray(speeds, float)
    out = np.empty(speeds.size)
    prev = None
    for i, n in enumerate(speeds):
        g = prev if guess is None else float(guess[i])
        g = g if g is not None and DEPTH_FLOOR_M < g < DEPTH_SCAN_HI_M else None
        out[i] = float(clipped(chatter_limit(structure, process, float(n), guess_m=g)))
        prev = out[i]
    return out


@dataclass(frozen=True)
class LobeBand:
    """The band: ``speed_rpm`` (n,); ``median_m``, ``lower_m`` (5 %), ``upper_m`` (95 %) and
    ``log_sd`` (n,) of the critical depth; ``depth_m`` (d,) and ``p_chatter`` (n, d);
    ``source`` (what the uncertainty is: "observations" or "modal intervals");
    ``parameters`` (names of the uncertain parameters); ``evaluations`` (lobe curves
    computed); ``sensitivity`` (n, k): the secant ``(g_j+ - g_j-) / 2`` of ``ln a_crit``
    along each of the covariance's ``k`` principal axes one standard deviation wide, so that
    ``sensitivity @ sensitivity.T`` is the linearised covariance of ``ln a_crit`` between the
    speeds (``log_sd`` the root of its diagonal); None where not known."""

    speed_rpm: np.ndarray
    median_m: np.ndarray
    lower_m: np.ndarray
    upper_m: np.ndarray
    log_sd: np.ndarray
    depth_m: np.ndarray
    p_chatter: np.ndarray
    source: str
    parameters: tuple[str, ...]
    evaluations: int
    method: str = ("linearised sensitivity along the covariance's principal axes "
                   "(central secants at +-1 sd), Gaussian in ln a_crit")
    sensitivity: np.ndarray | None = None

    def to_dict(self) -> dict[str, Any]:
        return {"source": self.source, "method": self.method,
                "parameters": list(self.parameters), "lobe_evaluations": self.evaluations,
                "speed_rpm": self.speed_rpm.tolist(),
                "critical_depth_p50_mm": (self.median_m * 1e3).tolist(),
                "critical_depth_p05_mm": (self.lower_m * 1e3).tolist(),
                "critical_depth_p95_mm": (self.upper_m * 1e3).tolist(),
                "critical_depth_log_sd": self.log_sd.tolist(),
                "depth_mm": (self.depth_m * 1e3).tolist(),
                "p_chatter": self.p_chatter.tolist()}

    def to_dataset(self):
        """The band as an ``xarray.Dataset`` (units in attributes)."""
        import xarray as xr

        return xr.Dataset(
            {"critical_depth_p50": ("speed", self.median_m * 1e3, {"units": "mm"}),
             "critical_depth_p05": ("speed", self.lower_m * 1e3, {"units": "mm"}),
             "critical_depth_p95": ("speed", self.upper_m * 1e3, {"units": "mm"}),
             "critical_depth_log_sd": ("speed", self.log_sd, {
                 "units": "1", "long_name": "standard deviation of ln(critical depth)"}),
             "p_chatter": (("speed", "depth"), self.p_chatter, {
                 "units": "1", "long_name": "probability that the cut chatters"})},
            coords={"speed": ("speed", self.speed_rpm, {"units": "r/min"}),
                    "depth": ("depth", self.depth_m * 1e3, {"units": "mm"})},
            attrs={"band_source": self.source, "band_method": self.method,
                   "band_parameters": ", ".join(self.parameters)})


def depth_grid(median_m: np.ndarray, count: int = 60) -> np.ndarray:
    """Geometric depth grid [m] for the probability map: a fifth of the smallest median
    critical depth to three times the largest one (within the depth scan)."""
    lo = max(float(np.min(median_m)) / 5.0, DEPTH_FLOOR_M)
    hi = min(float(np.max(median_m)) * 3.0, DEPTH_SCAN_HI_M)
    return np.geomspace(lo, max(hi, lo * 1.01), count)


def lobe_band(curve: Callable[[np.ndarray, np.ndarray | None], np.ndarray],
              theta0: np.ndarray, cov: np.ndarray, speeds: np.ndarray,
              names: tuple[str, ...], source: str, depth_count: int = 60,
              progress: Callable[[int], None] | None = None,
              nominal: np.ndarray | None = None) -> LobeBand:
    """The band of ``curve(theta, guess)`` (critical depths [m] at ``speeds``, continued from
    ``guess`` when given) over ``theta ~ N(theta0, cov)``. ``nominal``: the curve at
    ``theta0`` when already known. ``progress(1)`` after each curve."""
    theta0 = np.asarray(theta0, float)
    cov = np.asarray(cov, float)
    g0c = clipped(curve(theta0, None)) if nominal is None else clipped(nominal)
    if progress is not None:
        progress(1)
    g0 = np.log(g0c)
    lam, U = np.linalg.eigh(0.5 * (cov + cov.T))
    var = np.zeros_like(g0)
    n_eval = 1
    cols = []
    scale = max(float(lam.max(initial=0.0)), 0.0)
    for j in range(lam.size):
        if not (lam[j] > 1e-12 * max(scale, 1e-300) and lam[j] > 1e-18):
            continue
        step = math.sqrt(lam[j]) * U[:, j]
        gp = np.log(clipped(curve(theta0 + step, g0c)))
        gm = np.log(clipped(curve(theta0 - step, g0c)))
        var += (0.5 * (gp - gm)) ** 2
        cols.append(0.5 * (gp - gm))
        n_eval += 2
        if progress is not None:
            progress(2)
    sd = np.sqrt(var)
    depth = depth_grid(g0c, depth_count)
    la = np.log(depth)[None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        z = (la - g0[:, None]) / sd[:, None]
    step_map = (la >= g0[:, None]).astype(float)
    p = np.where(sd[:, None] > 0, norm.cdf(np.nan_to_num(z)), step_map)
    return LobeBand(np.asarray(speeds, float), g0c, np.exp(g0 - Z90 * sd),
                    np.exp(g0 + Z90 * sd), sd, depth, p, source, tuple(names), n_eval,
                    sensitivity=np.column_stack(cols) if cols else np.zeros((g0.size, 0)))


# --------------------------------------------------------------------------- modal intervals
#: 95 % intervals are mean +- this many standard deviations (Gaussian in log space).
Z95 = float(norm.ppf(0.975))


def modal_covariance(uncertainty: dict[str, dict[str, list[float]]],
                     axes: tuple[str, ...] = ("x", "y", "z")
                     ) -> tuple[np.ndarray, tuple[str, ...]]:
    """Diagonal covariance of the log frequency, log damping ratio and log stiffness of each
    unit from the equivalent model's 95 % ranges (``uncertainty[axis][key] = [lo, hi]``;
    ``sd = ln(hi / lo) / (2 x 1.96)``, 0 where a key is missing). Order: for each axis,
    frequency, damping, stiffness; returns ``(cov, names)``."""
    names, sd = [], []
    for a in axes:
        u = uncertainty.get(a, {}) if uncertainty else {}
        for key in ("frequency_Hz", "damping_ratio", "stiffness_N_per_m"):
            names.append(f"{key}.{a}")
            rng = u.get(key)
            if rng is None:
                sd.append(0.0)
                continue
            lo, hi = float(rng[0]), float(rng[1])
            sd.append(math.log(hi / lo) / (2.0 * Z95) if lo > 0 and hi > lo else 0.0)
    return np.diag(np.square(sd)), tuple(names)


def scaled_structure(base: ToolPointStructure, log_f: np.ndarray, log_zeta: np.ndarray,
                     log_k: np.ndarray) -> ToolPointStructure:
    """``base`` with its first ``len(log_f)`` modes' frequency, damping ratio and stiffness
    multiplied by ``exp`` of the given logs (the others unchanged; damping kept below 0.95)."""
    f = base.frequency_Hz.copy()
    z = base.damping_ratio.copy()
    k = base.stiffness_N_per_m.copy()
    n = len(log_f)
    f[:n] *= np.exp(log_f)
    z[:n] = np.minimum(z[:n] * np.exp(log_zeta), 0.95)
    k[:n] *= np.exp(log_k)
    return ToolPointStructure(f, z, k, base.directions.copy())


def modal_band(structure: ToolPointStructure, process: CuttingProcess, speeds: np.ndarray,
               uncertainty: dict[str, dict[str, list[float]]], depth_count: int = 60,
               progress: Callable[[int], None] | None = None) -> LobeBand:
    """The lobes' band from the equivalent model's 95 % ranges (:func:`modal_covariance`;
    the equivalent units are the structure's first three modes)."""
    cov, names = modal_covariance(uncertainty)

    def curve(theta: np.ndarray, guess: np.ndarray | None) -> np.ndarray:
        t = theta.reshape(3, 3)  # axis x (f, zeta, k)
        st = scaled_structure(structure, t[:, 0], t[:, 1], t[:, 2])
        return critical_depths(st, process, speeds, guess)

    return lobe_band(curve, np.zeros(9), cov, speeds, names, "modal intervals",
                     depth_count=depth_count, progress=progress)


def band_evaluations(cov: np.ndarray) -> int:
    """Lobe curves :func:`lobe_band` computes for ``cov`` (1 + 2 per positive eigenvalue)."""
    lam = np.linalg.eigvalsh(0.5 * (np.asarray(cov) + np.asarray(cov).T))
    scale = max(float(lam.max(initial=0.0)), 0.0)
    return 1 + 2 * int(np.sum((lam > 1e-12 * max(scale, 1e-300)) & (lam > 1e-18)))


__all__ = ["LobeBand", "lobe_band", "modal_band", "modal_covariance", "scaled_structure",
           "critical_depths", "clipped", "depth_grid", "band_evaluations", "Z90", "Z95",
           "DEPTH_FLOOR_M"]
