"""Rating of candidate postures: stiffness, modes, chatter limit, forced feed amplitude, and
the recommended candidate by a criterion (see :mod:`robobore.plan.posture`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robobore.plan.candidates import Candidates
from robobore.plan.config import PlanConfig, PlanInputs

CRITERIA = ("critical_depth", "stiffness_x", "stiffness_y", "stiffness_z", "stiffness_min")


def steady_feed_amplitude(structure: Any, process: Any, depth_m: float, speed_rpm: float
                          ) -> float:
    """Half peak-to-peak feed-direction (Z) displacement [m] of the steady cut: the periodic
    orbit the time-domain simulation starts on and settles to when the cut is stable
    (:func:`robobore.dynamics.timedomain.nominal_cut_deflection`, depth-modulation stiffness
    included; the process built at ``depth_m``), so the planner and ``simulate boring``
    report the same amplitude."""
    from robobore.dynamics.timedomain import forced_response

    z = forced_response(structure, process.at_depth(depth_m), speed_rpm, depth_m)[:, 2]
    return float(0.5 * (z.max() - z.min()))


def build_process(inp: PlanInputs) -> Any:
    """The boring-bar process at ``[cutting]`` from ``[insert]`` and ``[coefficients]``."""
    from robobore.dynamics.config import DynamicsConfig
    from robobore.dynamics.config import build_process as _bp

    c = inp.cfg
    dc = DynamicsConfig.model_validate({
        "structure": {"modes": [{"frequency_Hz": 10.0, "damping_ratio": 0.05,
                                 "stiffness_N_per_m": 1e6, "direction": [1, 0, 0]}]},
        "insert": c.insert.model_dump(), "bore": {"diameter_mm": c.bore.diameter_mm},
        "cutting": {"speed_rpm": c.cutting.speed_rpm,
                    "feed_mm_per_rev": c.cutting.feed_mm_per_rev,
                    "depth_mm": c.cutting.depth_mm},
        **({"coefficients": c.coefficients.model_dump(exclude_none=True)}
           if c.coefficients is not None else {})})
    return _bp(dc, source=str(inp.path))


def criterion_values(name: str, stiffness: np.ndarray, critical_depth_m: np.ndarray
                     ) -> np.ndarray:
    if name == "critical_depth":
        return critical_depth_m * 1e3
    if name == "stiffness_min":
        return stiffness.min(axis=1)
    return stiffness[:, "xyz".index(name[-1])]


CRITERION_UNITS = {"critical_depth": "mm", "stiffness_x": "N/m", "stiffness_y": "N/m",
                   "stiffness_z": "N/m", "stiffness_min": "N/m"}


def evaluate(model: Any, robot: Any, cand: Candidates, process: Any, A0: np.ndarray,
             cfg: PlanConfig, progress: Any = None, mode_share: float = 1e-3,
             criterion_only: bool = False) -> dict[str, np.ndarray]:
    """Stiffness, modes, critical depth (frequency-domain screen) and the steady feed
    amplitude per candidate (chunks of 512); ``mode_share``: the feed amplitude's structure
    leaves out modes below that share of the tool-point flexibility.

    ``critical_depth_m`` is the limit at the ``[cutting]`` speed (the speed the cut runs at:
    the value candidates are ranked by); ``critical_depth_range_min_m`` the lowest point of
    the envelope over the ``[lobes]`` speed range, at ``critical_speed_rpm``.

    ``criterion_only``: only what :func:`criterion_values` needs (modes, stiffness, and for
    the ``critical_depth`` criterion ``critical_depth_m`` and ``chatter_frequency_Hz``); the
    range minimum, its speed and the feed amplitude are NaN."""
    from robobore.plan.chatter import critical_depth_ranges

    n = cand.q_rad.shape[0]
    nj = model.n_dof
    out = {"frequency_Hz": np.empty((n, nj)), "damping_ratio": np.empty((n, nj)),
           "stiffness_N_per_m": np.empty((n, 3)), "critical_depth_m": np.empty(n),
           "chatter_frequency_Hz": np.empty(n), "critical_speed_rpm": np.empty(n),
           "critical_depth_range_min_m": np.empty(n), "feed_amplitude_m": np.empty(n)}
    n_cut = float(cfg.cutting.speed_rpm)
    need_depth = not criterion_only or cfg.plan.criterion == "critical_depth"
    if criterion_only:
        for name in ("critical_depth_m", "chatter_frequency_Hz", "critical_speed_rpm",
                     "critical_depth_range_min_m", "feed_amplitude_m"):
            out[name].fill(np.nan)
    for s in range(0, n, 512):
        e = min(n, s + 512)
        pm = model.modes(cand.q_rad[s:e])
        out["frequency_Hz"][s:e] = pm.frequency_Hz
        out["damping_ratio"][s:e] = pm.damping_ratio
        out["stiffness_N_per_m"][s:e] = pm.directional_stiffness
        # the limit at the cut's speed and (not criterion_only) the range's lowest point, in
        # one pass over the frequency grid
        ranges = [(n_cut, n_cut)] * need_depth + [
            (cfg.lobes.speed_min_rpm, cfg.lobes.speed_max_rpm)] * (not criterion_only)
        if ranges:
            b, fch, nch = critical_depth_ranges(pm.frequency_Hz, pm.damping_ratio, pm.u, A0,
                                                ranges, process.n_inserts)
        if need_depth:
            out["critical_depth_m"][s:e] = b[:, 0]
            out["chatter_frequency_Hz"][s:e] = fch[:, 0]
        if not criterion_only:
            out["critical_depth_range_min_m"][s:e] = b[:, -1]
            out["critical_speed_rpm"][s:e] = nch[:, -1]
        for k in range(e - s if not criterion_only else 0):
            out["feed_amplitude_m"][s + k] = steady_feed_amplitude(
                pm.structure(k, mode_share), process, cfg.cutting.depth_mm * 1e-3,
                cfg.cutting.speed_rpm)
        if progress is not None:
            progress(e - s)
    return out


def recommend(crit: np.ndarray, Q: np.ndarray, q_ref: np.ndarray, rel_tol: float = 1e-6
              ) -> int:
    """Index of the best candidate: the largest criterion (an infinite critical depth counts
    as the largest); among candidates within ``rel_tol`` of the best (for a tool point on
    the flange axis, the tool-axis rotation only turns axis 6 and leaves stiffness and modes
    unchanged), the one nearest the measured posture (smallest largest joint move)."""
    c = np.where(np.isnan(crit), -np.inf, crit)
    top = np.max(c)
    if np.isinf(top) and top > 0:
        near = np.flatnonzero(np.isinf(c) & (c > 0))
    else:
        near = np.flatnonzero(c >= top - rel_tol * abs(top))
    move = np.max(np.abs(np.angle(np.exp(1j * (Q[near] - q_ref[None, :])))), axis=1)
    return int(near[int(np.argmin(move))])


__all__ = ["CRITERIA", "CRITERION_UNITS", "steady_feed_amplitude",
           "build_process", "criterion_values", "evaluate", "recommend"]
