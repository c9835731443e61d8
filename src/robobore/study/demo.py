"""DEMO runner: a single-degree-of-freedom regenerative boring toy (NOT the boring model).

This runner exists so the sweep machinery can be used and tested before the real boring
simulation (``robobore.dynamics``) is wired in. Everything it returns is labelled
``model = "DEMO ..."``. Do not read physics into its numbers beyond what is written here.

Model (Tlusty's regenerative chatter model, single DOF; Altintas, *Manufacturing
Automation*, 2nd ed., Sec. 3.2, Eqs. 3.20-3.30). The tool is flexible in the feed direction
Z only, with modal mass ``m``, stiffness ``k`` and damping ratio ``zeta``; ``z`` > 0 moves
the tool away from the material. The chip thickness is the feed per revolution ``h0``
corrected by the current and previous-revolution vibration, and the tool leaves the cut
when it would be negative (the only nonlinearity)::

    m z'' + c z' + k z = F_z(t),   F_z = K_z b h(t)
    h(t) = max(0, h0 - z(t) + r(t - T))     T = 60 / n  (one revolution)
    r(t) = z(t) while cutting,  r(t - T) + h0 while out of the cut (surface not renewed)

with ``b`` the depth of cut (chip width) and ``K_z`` the feed-direction cutting-force
coefficient. The tangential and radial forces ``F_t = K_t b h``, ``F_r = K_r b h`` rotate
with the boring bar, so their components in the fixed horizontal/vertical axes are
``F_x = F_t cos(phi) - F_r sin(phi)``, ``F_y = F_t sin(phi) + F_r cos(phi)``, with
``phi = 2 pi n t / 60``. The pressure foot is modelled as a stiffening
``k(P) = k0 (1 + P / P_ref)`` and a damping ratio ``zeta(P) = zeta0 + dzeta_per_MPa * P``
(a toy assumption, stated, not identified).

Linear stability (for tests): the characteristic equation is
``1 + K_z b (1 - exp(-i w T)) G(i w) = 0`` with ``G = 1 / (k - m w^2 + i c w)``, so the
critical depth at speed ``n`` is the smallest ``b = -1 / (K_z (1 - exp(-i w T)) G)`` over
the frequencies where that is real and positive (:func:`critical_depth_m`); its minimum over
all speeds is ``2 k zeta (1 + zeta) / K_z`` (Altintas Eq. 3.29).

Integration: exact zero-order-hold discretisation of the linear SDOF (matrix exponential)
with the force held over each step and an integer number of steps per revolution, so the
delay is exact. Summary (see :mod:`robobore.study.summary`), over the last
``analysed_revolutions``: ``force_amplitude_{x,y,z}_N`` = the mean over revolutions of the
peak |force component| in each revolution; ``feed_amplitude_um`` = the mean over revolutions
of half the peak-to-peak ``z`` in each revolution; ``stable`` = the tool never left the cut in those
revolutions and that vibration amplitude is not larger than over the revolutions just
before them (a decaying transient; a growing or saturated vibration is chatter).
"""

from __future__ import annotations

import math
import os
import time
import uuid
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from robobore.errors import ConfigError


class DemoParams(BaseModel):
    """Parameters of the demo runner (the ``[model]`` table of a sweep config)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    stiffness_N_per_m: float = Field(6.0e5, gt=0, description="k0, feed direction, no foot")
    natural_frequency_Hz: float = Field(10.0, gt=0)
    damping_ratio: float = Field(0.04, gt=0, lt=1)
    K_feed_N_per_m2: float = Field(5.0e8, gt=0, description="K_z, feed force coefficient")
    K_tangential_N_per_m2: float = Field(1.8e9, gt=0, description="K_t")
    K_radial_N_per_m2: float = Field(7.0e8, gt=0, description="K_r")
    pressure_ref_MPa: float = Field(0.3, gt=0, description="P_ref: k doubles at this P")
    damping_ratio_per_MPa: float = Field(0.02, ge=0)
    duration_s: float = Field(4.0, gt=0, le=600)
    min_revolutions: int = Field(12, ge=4)
    steps_per_period: int = Field(40, ge=10, description="steps per natural period, at least")
    min_steps_per_revolution: int = Field(64, ge=8)
    analysed_revolutions: int = Field(3, ge=1, description="revolutions in the summary")
    output_points: int = Field(2000, ge=10, description="max stored samples of the time series")


class DemoOptions(BaseModel):
    """Options that do not change the result (the ``[runner_options]`` table)."""

    model_config = ConfigDict(extra="forbid")

    marker_dir: str | None = Field(None, description="write one file per invocation here")
    sleep_s: float = Field(0.0, ge=0, description="sleep this long per condition (tests)")
    fail_speeds_rpm: list[float] = Field(default_factory=list,
                                         description="raise for these speeds (tests)")


def _modal(p: DemoParams, pressure_MPa: float) -> tuple[float, float, float]:
    """(m, c, k) at foot pressure ``pressure_MPa``; m is fixed by k0 and f_n at P = 0."""
    wn0 = 2.0 * math.pi * p.natural_frequency_Hz
    m = p.stiffness_N_per_m / wn0**2
    k = p.stiffness_N_per_m * (1.0 + pressure_MPa / p.pressure_ref_MPa)
    zeta = p.damping_ratio + p.damping_ratio_per_MPa * pressure_MPa
    c = 2.0 * zeta * math.sqrt(k * m)
    return m, c, k


def critical_depth_m(params: DemoParams, speed_rpm: float, pressure_MPa: float,
                     n_freq: int = 200_000) -> float:
    """Critical (stability-limit) depth of cut in m of the linear demo model at a speed.

    Solves ``1 + K_z b (1 - e^{-i w T}) G(i w) = 0`` for real ``b > 0`` on a dense grid of
    chatter frequencies (0.05 .. 20 f_n), taking the smallest root.
    """
    m, c, k = _modal(params, pressure_MPa)
    wn = math.sqrt(k / m)
    w = np.linspace(0.05 * wn, 20.0 * wn, n_freq)
    T = 60.0 / speed_rpm
    g = 1.0 / (k - m * w**2 + 1j * c * w)
    q = (1.0 - np.exp(-1j * w * T)) * g
    im = q.imag
    idx = np.nonzero(np.sign(im[:-1]) * np.sign(im[1:]) < 0)[0]
    best = math.inf
    for i in idx:
        t = im[i] / (im[i] - im[i + 1])
        re = q.real[i] + t * (q.real[i + 1] - q.real[i])
        if re < 0:
            best = min(best, -1.0 / (params.K_feed_N_per_m2 * re))
    return best


def simulate(params: DemoParams, speed_rpm: float, feed_mm_per_rev: float,
             depth_of_cut_mm: float, pressure_MPa: float) -> dict[str, Any]:
    """Time-domain demo simulation; returns time series (SI) and the summary quantities."""
    from scipy.linalg import expm

    m, c, k = _modal(params, pressure_MPa)
    T = 60.0 / speed_rpm
    h0 = feed_mm_per_rev * 1e-3
    b = depth_of_cut_mm * 1e-3
    wn = math.sqrt(k / m)
    n_rev_steps = max(params.min_steps_per_revolution,
                      math.ceil(T * wn / (2 * math.pi) * params.steps_per_period))
    dt = T / n_rev_steps
    n_revs = max(params.min_revolutions, math.ceil(params.duration_s / T))
    n = n_revs * n_rev_steps

    # exact ZOH discretisation of x' = A x + B F, x = (z, z')
    A = np.array([[0.0, 1.0], [-k / m, -c / m]])
    Ad = expm(A * dt)
    Bd = np.linalg.solve(A, (Ad - np.eye(2)) @ np.array([0.0, 1.0 / m]))
    a00, a01, a10, a11 = (float(v) for v in Ad.ravel())
    b0, b1 = float(Bd[0]), float(Bd[1])

    Kz_b = params.K_feed_N_per_m2 * b
    z_hist = np.empty(n)
    h_hist = np.empty(n)
    r = [0.0] * n_rev_steps  # surface of the previous revolution (ring buffer), m
    z = 0.0
    v = 0.0
    for i in range(n):
        j = i % n_rev_steps
        h = h0 - z + r[j]
        if h > 0.0:
            r[j] = z
        else:
            h = 0.0
            r[j] = r[j] + h0
        f = Kz_b * h
        z_hist[i] = z
        h_hist[i] = h
        z, v = a00 * z + a01 * v + b0 * f, a10 * z + a11 * v + b1 * f

    t = np.arange(n) * dt
    phi = 2.0 * math.pi * t / T
    Ft = params.K_tangential_N_per_m2 * b * h_hist
    Fr = params.K_radial_N_per_m2 * b * h_hist
    Fx = Ft * np.cos(phi) - Fr * np.sin(phi)
    Fy = Ft * np.sin(phi) + Fr * np.cos(phi)
    Fz = Kz_b * h_hist

    na = min(params.analysed_revolutions, n_revs // 2)
    last = slice(n - na * n_rev_steps, n)
    before = slice(n - 2 * na * n_rev_steps, n - na * n_rev_steps)

    def per_rev(x: np.ndarray, sl: slice = last) -> np.ndarray:
        return x[sl].reshape(na, n_rev_steps)

    def half_ptp(x: np.ndarray) -> float:
        return float(np.mean(0.5 * (x.max(axis=1) - x.min(axis=1))))

    feed_amp = half_ptp(per_rev(z_hist))
    feed_amp_before = half_ptp(per_rev(z_hist, before))
    left_cut = bool(np.any(h_hist[last] <= 0.0))
    static = Kz_b * h0 / k
    return {
        "time_s": t, "z_m": z_hist, "h_m": h_hist, "Fx_N": Fx, "Fy_N": Fy, "Fz_N": Fz,
        "force_amplitude_x_N": float(np.mean(np.abs(per_rev(Fx)).max(axis=1))),
        "force_amplitude_y_N": float(np.mean(np.abs(per_rev(Fy)).max(axis=1))),
        "force_amplitude_z_N": float(np.mean(np.abs(per_rev(Fz)).max(axis=1))),
        "feed_amplitude_m": feed_amp,
        "static_deflection_m": static,
        "stable": bool(not left_cut and feed_amp <= feed_amp_before),
        "left_cut": left_cut,
        "dt_s": dt, "revolutions": n_revs, "m_kg": m, "c_N_s_per_m": c, "k_N_per_m": k,
    }


def demo_runner(condition: dict[str, Any], context: dict[str, Any]) -> Any:
    """Sweep runner (``runner = "demo"``): DEMO single-DOF regenerative toy.

    ``condition``: a :class:`robobore.study.conditions.Condition` as a dict.
    ``context``: ``{"model": {...DemoParams...}, "runner_options": {...DemoOptions...},
    "seed": int, "key": str, ...}``. Returns an ``xarray.Dataset`` with time series
    ``z_um``, ``Fx_N``, ``Fy_N``, ``Fz_N`` over ``time_s`` (decimated to at most
    ``output_points`` samples) and the summary quantities as scalar variables.
    """
    import xarray as xr

    try:
        params = DemoParams.model_validate(context.get("model") or {})
    except Exception as exc:
        raise ConfigError(f"bad demo model parameters: {exc}", field="model") from None
    opts = DemoOptions.model_validate(context.get("runner_options") or {})
    if opts.marker_dir:
        d = Path(opts.marker_dir)
        d.mkdir(parents=True, exist_ok=True)
        (d / f"{context.get('key', 'nokey')}.{os.getpid()}.{uuid.uuid4().hex}.run").write_text(
            "started\n")
    if opts.sleep_s:
        time.sleep(opts.sleep_s)
    speed = float(condition["speed_rpm"])
    if any(abs(speed - s) < 1e-9 for s in opts.fail_speeds_rpm):
        raise RuntimeError(f"demo runner asked to fail at {speed:g} r/min (runner_options)")

    res = simulate(params, speed, float(condition["feed_mm_per_rev"]),
                   float(condition["depth_of_cut_mm"]), float(condition.get("pressure_MPa", 0.0)))
    n = res["time_s"].size
    step = max(1, math.ceil(n / params.output_points))
    sl = slice(0, n, step)
    b_crit = critical_depth_m(params, speed, float(condition.get("pressure_MPa", 0.0)),
                              n_freq=20_000)
    ds = xr.Dataset(
        {
            "z_um": ("time_s", res["z_m"][sl] * 1e6,
                     {"units": "um", "long_name": "tool feed-direction displacement"}),
            "Fx_N": ("time_s", res["Fx_N"][sl], {"units": "N"}),
            "Fy_N": ("time_s", res["Fy_N"][sl], {"units": "N"}),
            "Fz_N": ("time_s", res["Fz_N"][sl], {"units": "N"}),
            "force_amplitude_x_N": ((), res["force_amplitude_x_N"], {"units": "N"}),
            "force_amplitude_y_N": ((), res["force_amplitude_y_N"], {"units": "N"}),
            "force_amplitude_z_N": ((), res["force_amplitude_z_N"], {"units": "N"}),
            "feed_amplitude_um": ((), res["feed_amplitude_m"] * 1e6, {"units": "um"}),
            "stable": ((), res["stable"]),
        },
        coords={"time_s": ("time_s", res["time_s"][sl], {"units": "s"})},
        attrs={
            "model": "DEMO single-DOF regenerative toy (robobore.study.demo), not the boring model",
            "static_deflection_um": res["static_deflection_m"] * 1e6,
            "critical_depth_of_cut_mm": b_crit * 1e3 if math.isfinite(b_crit) else -1.0,
            "dt_s": res["dt_s"],
            "revolutions": int(res["revolutions"]),
        },
    )
    return ds


__all__ = ["DemoParams", "DemoOptions", "critical_depth_m", "simulate", "demo_runner"]
