"""Uncertainty of identified modes: the stratified jackknife over the hammer hits.

Every hit of a roving-hammer test is an independent repetition of the same experiment, so
the spread of the identified values when one hit is left out measures how well the data fix
them (Quenouille-Tukey jackknife; Efron & Tibshirani, *An Introduction to the Bootstrap*,
ch. 11; stratified over the hammer inputs, whose hits are independent samples of different
experiments). For each input ``s`` with ``n_s`` used hits and each hit ``i`` left out, the FRFs
are re-averaged from the per-hit spectra (:func:`robobore.modal.frf.combine_hits`) and the
poles re-estimated; the variance of a value ``theta`` is

    v = sum_s (n_s - 1) / n_s * sum_i (theta_(s,i) - mean_i theta_(s,i))^2

and the 95 % interval ``theta +- t_(0.975, nu) sqrt(v)`` with Satterthwaite's effective
degrees of freedom ``nu = (sum_s v_s)^2 / sum_s (v_s^2 / (n_s - 1))`` (the input that carries
a mode sets its degrees of freedom: 5 hits of one direction give ``nu = 4``, ``t = 2.78``).

Re-estimation per replicate, at the cost of a few denominators instead of the whole
stabilisation diagram: the pLSCF denominators at (up to) six orders spread over the upper
half of each selected mode's cluster (the orders its identified value comes from), at each
the root of ``det D(z)`` nearest the identified pole by Newton iteration
(:func:`robobore.modal.plscf.poles_near`; accepted within 3 units of the clustering metric
``|ln f ratio| / 0.005 + |ln zeta ratio| / 0.3``), their mean (a smooth statistic, as the
jackknife needs); LSFD with the replicate's poles gives its mode shapes, compared with the
identified ones by MAC.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from robobore.errors import InputError
from robobore.modal.frf import FRFEstimate, combine_hits
from robobore.modal.lsfd import lsfd, normalise_shape
from robobore.modal.plscf import poles_near, single_thread_blas
from robobore.modal.stabilization import mac

#: the clustering metric's scales (robobore.modal.stabilization.pole_clusters) and the
#: largest distance at which a replicate pole is taken for an identified one
FREQ_SCALE, DAMP_SCALE, MATCH_DISTANCE = 0.005, 0.3, 3.0
ORDERS_PER_MODE = 6


@dataclass(frozen=True)
class ModeUncertainty:
    """Standard deviations and 95 % intervals of one mode (jackknife over hits).

    frequency_std_Hz, damping_std; frequency_ci_Hz, damping_ci: ``(lo, hi)``; dof: effective
    degrees of freedom; shape_mac_min: the smallest MAC between a replicate's shape and the
    identified one; shape_std: jackknife standard deviation of each entry of the normalised
    shape (largest entry 1); n_replicates: replicates where the mode was found.
    """

    frequency_std_Hz: float
    damping_std: float
    frequency_ci_Hz: tuple[float, float]
    damping_ci: tuple[float, float]
    dof: float
    shape_mac_min: float | None
    shape_std: tuple[float, ...]
    n_replicates: int
    method: str = "jackknife over hits"

    def to_dict(self) -> dict[str, Any]:
        return {"frequency_std_Hz": self.frequency_std_Hz, "damping_std": self.damping_std,
                "frequency_ci95_Hz": list(self.frequency_ci_Hz),
                "damping_ci95": list(self.damping_ci), "dof": self.dof,
                "shape_mac_min": self.shape_mac_min, "shape_std": list(self.shape_std),
                "n_replicates": self.n_replicates, "method": self.method}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> ModeUncertainty:
        return cls(float(d["frequency_std_Hz"]), float(d["damping_std"]),
                   tuple(d["frequency_ci95_Hz"]), tuple(d["damping_ci95"]), float(d["dof"]),
                   None if d.get("shape_mac_min") is None else float(d["shape_mac_min"]),
                   tuple(float(v) for v in d["shape_std"]),
                   int(d["n_replicates"]), str(d.get("method", "jackknife over hits")))


def _upper_orders(orders: tuple[int, ...]) -> tuple[int, ...]:
    """The orders of the upper half of a cluster (as the identified value), at most
    :data:`ORDERS_PER_MODE` of them spread evenly."""
    up = [o for o in orders if o >= np.median(orders)] if orders else []
    if len(up) <= ORDERS_PER_MODE:
        return tuple(up)
    k = np.unique(np.round(np.linspace(0, len(up) - 1, ORDERS_PER_MODE)).astype(int))
    return tuple(up[i] for i in k)


def _near(lam: complex, f0: float, z0: float) -> bool:
    """A pole within :data:`MATCH_DISTANCE` of ``(f0, z0)`` in the clustering metric."""
    f = abs(lam) / (2 * np.pi)
    z = -lam.real / abs(lam)
    if not z > 0:
        return False
    return bool(abs(np.log(f / f0)) / FREQ_SCALE + abs(np.log(z / z0)) / DAMP_SCALE
                <= MATCH_DISTANCE)


def _replicate(data, band: tuple[float, float], orders: list[tuple[int, ...]],
               f0: np.ndarray, z0: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                        np.ndarray]:
    """Poles of one replicate's FRFs: ``(f, zeta, participation, found)`` per mode."""
    d = _band_of(data, band)
    todo = sorted({o for os_ in orders for o in os_})
    wn = 2 * np.pi * f0
    lam0 = -z0 * wn + 1j * wn * np.sqrt(1 - z0**2)
    P, Lp = poles_near(d, lam0, todo, single_thread=False)
    row = {o: i for i, o in enumerate(todo)}
    nm = f0.size
    f = np.full(nm, np.nan)
    z = np.full(nm, np.nan)
    L = np.zeros((nm, d.n_inputs), complex)
    for m in range(nm):
        got = []
        for o in orders[m]:
            lam = P[row[o], m]
            if np.isfinite(lam) and _near(lam, f0[m], z0[m]):
                got.append((lam, Lp[row[o], m]))
        if got:
            lam = np.array([g[0] for g in got])
            f[m] = float(np.mean(np.abs(lam))) / (2 * np.pi)
            z[m] = float(np.mean(-lam.real / np.abs(lam)))
            L[m] = got[len(got) // 2][1]
    return f, z, L, np.isfinite(f)


def jackknife_over_hits(est: FRFEstimate, analysis: Any) -> tuple[list[ModeUncertainty | None],
                                                                  dict[str, Any]]:
    """Jackknife uncertainty of every mode of ``analysis`` (a ModalAnalysis from
    ``est.frf``) -> one :class:`ModeUncertainty` (None when fewer than two hits of an input
    are left to resample) per mode, and a summary (replicates, time)."""
    if est.per_hit is None:
        raise InputError("the FRF estimate holds no per-hit spectra", field="per_hit",
                         expected="an FRFEstimate of estimate_frf")
    t0 = time.perf_counter()
    with single_thread_blas():  # many small problems: threads only cost here
        return _jackknife(est, analysis, t0)


def _jackknife(est: FRFEstimate, analysis: Any, t0: float
               ) -> tuple[list[ModeUncertainty | None], dict[str, Any]]:
    from scipy.stats import t as student_t

    res = analysis.result
    sel = res.stabilisation.get("selected", [])
    nm = len(res.modes)
    f0 = res.frequencies_Hz
    z0 = res.damping_ratios
    orders = [_upper_orders(tuple(s.get("orders", ()))) or (res.max_order,) for s in sel]
    band = tuple(res.band_Hz)
    used = est.per_hit["used"]
    shapes0 = np.array([m.mode_shape for m in res.modes]).T  # (no, nm)
    # the replicate estimator on all hits (the jackknife's reference for the bias)
    f_all, z_all, _, found_all = _replicate(combine_hits(est, np.ones(used.shape)), band,
                                            orders, f0, z0)
    f_all = np.where(found_all, f_all, f0)
    z_all = np.where(found_all, z_all, z0)
    # per stratum (input) the leave-one-out replicates
    strata: list[list[tuple[np.ndarray, np.ndarray, np.ndarray]]] = []
    n_rep = 0
    for s in range(used.shape[0]):
        reps = []
        hits = np.flatnonzero(used[s])
        if hits.size >= 2:
            for h in hits:
                w = np.ones(used.shape)
                w[s, h] = 0.0
                d = combine_hits(est, w)
                f, z, L, found = _replicate(d, band, orders, f0, z0)
                shp = np.full((shapes0.shape[0], nm), np.nan, complex)
                if np.any(found):
                    lam = (-z * 2 * np.pi * f + 1j * 2 * np.pi * f * np.sqrt(1 - z**2))[found]
                    fit = lsfd(_band_of(d, band), lam, L[found])
                    shp[:, found] = fit.mode_shapes
                reps.append((f, z, shp))
                n_rep += 1
        strata.append(reps)
    out: list[ModeUncertainty | None] = []
    for m in range(nm):
        vf, vz, vs_shape, bf, bz = [], [], [], [], []
        ns_list = []
        macs = []
        count = 0
        for reps in strata:
            fs_ = np.array([r[0][m] for r in reps])
            zs_ = np.array([r[1][m] for r in reps])
            ok = np.isfinite(fs_)
            n_s = ok.sum()
            if n_s < 2:
                continue
            count += int(n_s)
            fac = (n_s - 1) / n_s
            vf.append(fac * np.sum((fs_[ok] - fs_[ok].mean()) ** 2))
            vz.append(fac * np.sum((zs_[ok] - zs_[ok].mean()) ** 2))
            bf.append((n_s - 1) * (fs_[ok].mean() - f_all[m]))
            bz.append((n_s - 1) * (zs_[ok].mean() - z_all[m]))
            ns_list.append(n_s)
            shp = np.array([normalise_shape(r[2][:, m]) for r, o in zip(reps, ok, strict=True)
                            if o])
            vs_shape.append(fac * np.sum(np.abs(shp - shp.mean(axis=0)) ** 2, axis=0))
            macs += [mac(v, shapes0[:, m]) for v in shp]
        if not ns_list:
            out.append(None)
            continue
        ns = np.array(ns_list, float)

        def dof(v: list[float]) -> float:
            va = np.array(v)
            den = np.sum(va**2 / (ns - 1))
            return float(va.sum() ** 2 / den) if den > 0 else float(np.sum(ns - 1))

        sf, sz = float(np.sqrt(np.sum(vf))), float(np.sqrt(np.sum(vz)))
        nu_f, nu_z = dof(vf), dof(vz)
        tf = float(student_t.ppf(0.975, max(nu_f, 1.0)))
        tz = float(student_t.ppf(0.975, max(nu_z, 1.0)))
        # intervals about the bias-corrected value (the jackknife bias estimate)
        fc, zc = float(f0[m]), float(z0[m])
        out.append(ModeUncertainty(
            sf, sz, (fc - tf * sf, fc + tf * sf), (zc - tz * sz, zc + tz * sz),
            float(min(nu_f, nu_z)),
            float(min(macs)) if macs else float("nan"),
            tuple(float(v) for v in np.sqrt(np.sum(vs_shape, axis=0))), count))
    return out, {"method": "stratified jackknife over hits", "replicates": n_rep,
                 "orders": [list(o) for o in orders], "time_s": time.perf_counter() - t0}


def _band_of(d: Any, band: tuple[float, float]) -> Any:
    b = d.band(*band)
    return b.band(float(b.frequency_Hz[1]), None) if b.frequency_Hz[0] == 0 else b


def bootstrap_residuals(data: Any, synthesised: np.ndarray, analysis: Any,
                        n_boot: int = 12, seed: int = 0
                        ) -> tuple[list[ModeUncertainty | None], dict[str, Any]]:
    """Uncertainty of the modes of ``analysis`` from FRFs alone: a wild bootstrap of the fit
    residuals. ``data``: the band-limited FRFs the modes come from; ``synthesised``: their
    fit with every physical mode (same shape). Replicate ``b``:
    ``H_b = H_fit + r e^(j theta)`` with the residual ``r = H - H_fit`` of every line and
    FRF and independent uniform phases ``theta`` (noise of the measured size at every line,
    no assumption on its distribution); the poles are re-estimated as in
    :func:`jackknife_over_hits`; standard deviation over the replicates, 95 % interval
    ``theta +- t(0.975, B-1) s``."""
    import dataclasses

    from scipy.stats import t as student_t

    t0 = time.perf_counter()
    rng = np.random.default_rng(seed)
    res = analysis.result
    sel = res.stabilisation.get("selected", [])
    f0 = res.frequencies_Hz
    z0 = res.damping_ratios
    orders = [_upper_orders(tuple(s.get("orders", ()))) or (res.max_order,) for s in sel]
    band = tuple(res.band_Hz)
    r = data.frf - synthesised
    F, Z = [], []
    with single_thread_blas():
        for _ in range(n_boot):
            ph = np.exp(2j * np.pi * rng.uniform(size=r.shape))
            d = dataclasses.replace(data, frf=synthesised + r * ph)
            f, z, _, _ = _replicate(d, band, orders, f0, z0)
            F.append(f)
            Z.append(z)
    F, Z = np.array(F), np.array(Z)
    out: list[ModeUncertainty | None] = []
    for m in range(f0.size):
        ok = np.isfinite(F[:, m])
        nb = int(ok.sum())
        if nb < max(5, n_boot // 2):
            out.append(None)
            continue
        sf, sz = float(np.std(F[ok, m], ddof=1)), float(np.std(Z[ok, m], ddof=1))
        tq = float(student_t.ppf(0.975, nb - 1))
        out.append(ModeUncertainty(sf, sz, (f0[m] - tq * sf, f0[m] + tq * sf),
                                   (z0[m] - tq * sz, z0[m] + tq * sz), float(nb - 1), None,
                                   (), nb, "bootstrap of the fit residuals"))
    return out, {"method": "wild bootstrap of the FRF fit residuals", "replicates": n_boot,
                 "orders": [list(o) for o in orders], "time_s": time.perf_counter() - t0}


__all__ = ["ModeUncertainty", "jackknife_over_hits", "bootstrap_residuals"]
