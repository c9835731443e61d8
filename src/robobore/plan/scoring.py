"""Rating of candidate postures: stiffness, modes, chatter limit, forced feed amplitude, and
the recommended candidate by a criterion (see :mod:`robobore.plan.posture`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robobore.plan.candidates import Candidates
from robobore.plan.config import PlanConfig, PlanInputs

CRITERIA = ("critical_depth", "stiffness_x", "stiffness_y", "stiffness_z", "stiffness_min")


def feed_amplitude(frequency_Hz: np.ndarray, damping_ratio: np.ndarray, u: np.ndarray,
                   force_basis_N: np.ndarray, speed_rpm: float, n_inserts: int) -> np.ndarray:
    """Half peak-to-peak feed-direction (Z) tool displacement of the steady forced response
    [m], (n,), for a rotating bar whose per-insert force is ``(f_t, f_r, f_z)`` in the insert
    basis. Only the first spindle harmonic reaches X/Y (the bar force is a rotating vector),
    and only through the cross receptances ``G_zx``, ``G_zy``; ``n_inserts`` equally spaced
    inserts cancel it (factor ``|sum_p exp(2 pi i p / N)|``)."""
    ft, fr, _ = force_basis_N
    W = 2 * np.pi * speed_rpm / 60.0
    w = 2 * np.pi * frequency_Hz
    h = 1.0 / (w ** 2 - W ** 2 + 2j * damping_ratio * w * W)  # (n, m)
    Gzx = np.einsum("nm,nm,nm->n", h, u[:, :, 2], u[:, :, 0])
    Gzy = np.einsum("nm,nm,nm->n", h, u[:, :, 2], u[:, :, 1])
    S = abs(np.sum(np.exp(2j * np.pi * np.arange(n_inserts) / n_inserts)))
    return np.abs(Gzx * (fr + 1j * ft) + Gzy * (ft - 1j * fr)) * S


def nominal_force_basis(process: Any, depth_m: float) -> np.ndarray:
    """Per-insert nominal force (t, r, z) [N] of a boring process at depth ``depth_m``."""
    return (np.einsum("e,e,ei->i", process.width_per_depth * depth_m, process.h0, process.shear)
            + np.einsum("e,ei->i", process.edge_per_depth * depth_m + process.edge_fixed_m,
                        process.edge))


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
             cfg: PlanConfig, progress: Any = None) -> dict[str, np.ndarray]:
    """Stiffness, modes, critical depth and feed amplitude per candidate (chunks of 512)."""
    from robobore.plan.chatter import critical_depth_range

    n = cand.q_rad.shape[0]
    nj = model.n_dof
    out = {"frequency_Hz": np.empty((n, nj)), "damping_ratio": np.empty((n, nj)),
           "stiffness_N_per_m": np.empty((n, 3)), "critical_depth_m": np.empty(n),
           "chatter_frequency_Hz": np.empty(n), "critical_speed_rpm": np.empty(n),
           "feed_amplitude_m": np.empty(n)}
    fb = nominal_force_basis(process, cfg.cutting.depth_mm * 1e-3)
    for s in range(0, n, 512):
        e = min(n, s + 512)
        pm = model.modes(cand.q_rad[s:e])
        out["frequency_Hz"][s:e] = pm.frequency_Hz
        out["damping_ratio"][s:e] = pm.damping_ratio
        out["stiffness_N_per_m"][s:e] = pm.directional_stiffness
        b, fch, nch = critical_depth_range(pm.frequency_Hz, pm.damping_ratio, pm.u, A0,
                                           cfg.lobes.speed_min_rpm, cfg.lobes.speed_max_rpm,
                                           process.n_inserts)
        out["critical_depth_m"][s:e] = b
        out["chatter_frequency_Hz"][s:e] = fch
        out["critical_speed_rpm"][s:e] = nch
        out["feed_amplitude_m"][s:e] = feed_amplitude(pm.frequency_Hz, pm.damping_ratio, pm.u,
                                                      fb, cfg.cutting.speed_rpm,
                                                      process.n_inserts)
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


__all__ = ["CRITERIA", "CRITERION_UNITS", "feed_amplitude", "nominal_force_basis",
           "build_process", "criterion_values", "evaluate", "recommend"]
