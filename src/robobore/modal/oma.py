"""Operational (output-only) modal analysis: covariance-driven stochastic subspace
identification (SSI-COV) of response records under unmeasured excitation (cutting vibration,
ambient excitation).

Method (Peeters & De Roeck 1999, *Reference-based stochastic subspace identification for
output-only modal analysis*; Brincker & Ventura 2015, *Introduction to Operational Modal
Analysis*, ch. 9; written from the references, no code copied):

1. the records are band-limited and decimated by an integer factor so that the band's upper
   edge is at most 0.4 of the new sample rate (``scipy.signal.decimate``, zero-phase FIR);
2. output correlations ``R_i = 1/(N-i) sum_k y_(k+i) y_k^T`` (``i = 0..2s``; by FFT);
3. the block Toeplitz matrix ``T = [R_(s+i-j)]`` (``s`` block rows and columns, lags 1..2s-1)
   is factorised ``T = U S V^T``; for a model of ``n`` states the observability matrix is
   ``O = U_n S_n^(1/2)``, ``C`` its first block row, ``A = O_up^+ O_down`` (shift
   invariance);
4. the poles ``lambda = fs ln(mu)`` of ``A``'s eigenvalues ``mu`` and the mode shapes
   ``C psi`` for ``n = 2, 4, ..., 2 max_order`` form the stabilisation diagram (the shapes
   take the place of the participation vectors in the MAC criterion); clustering and the
   support gate are those of the hammer-test identification
   (:func:`robobore.modal.stabilization.pole_clusters`).

Rotation harmonics of a cutting record are forced responses, not modes. With the spindle
speed given they are first subtracted from the records by least squares
(:func:`remove_harmonics`: a cosine and a sine per harmonic and channel, the rotation
frequency refined within +-0.5 %); what is left of them has (numerically) zero damping. A
cluster within 1 % of a multiple of the rotation frequency
(``spindle_rpm / 60``) with damping below 0.5 %, and without a spindle speed any cluster
below 0.1 % damping, is reported as a harmonic and excluded.

Share of a mode (``--modes N`` keeps the largest): with ``A = Psi diag(mu) Psi^-1`` and
``G`` the first block column of ``S_n^(1/2) V_n^T`` (``R_i = C A^(i-1) G``), mode ``m``
contributes ``c_m mu_m^(i-1) g_m^T`` to every correlation; its share is
``||c_m|| ||g_m|| / (1 - |mu_m|)`` (its correlations summed over lags, ~ its spectral peak)
over the sum for all physical modes.

Uncertainty: the stratified jackknife of :mod:`robobore.modal.uncertainty`, here over ``J``
consecutive segments of the record (default 6): each segment left out in turn, the poles
re-estimated at the orders of each mode's cluster (nearest pole within the clustering metric),
``v = (J-1)/J sum (theta_j - mean)^2``, 95 % interval with t(0.975, J-1).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from robobore.errors import DataError, IdentificationError, InputError
from robobore.modal.plscf import PLSCFResult, PoleSet
from robobore.modal.stabilization import (
    pole_clusters,
    stabilisation,
    support_needed,
)

HARMONIC_TOL = 0.01
HARMONIC_MAX_DAMPING = 0.005
NO_SPEED_MAX_DAMPING = 0.001
MIN_PERIODS = 10


@dataclass(frozen=True)
class OperationalRecord:
    """Output-only response records ``data (n_channels, n_samples)`` at ``sample_rate_Hz``."""

    data: np.ndarray
    sample_rate_Hz: float
    channel_names: tuple[str, ...] = ()
    source: str | None = None
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        a = np.atleast_2d(np.asarray(self.data, float))
        if a.ndim != 2 or a.shape[1] < 64:
            raise DataError("operational records must be (channels, samples)", file=self.source,
                            field="data", value=f"shape {a.shape}",
                            expected="a 2-D array with at least 64 samples per channel")
        if not np.all(np.isfinite(a)):
            i = np.argwhere(~np.isfinite(a))[0]
            raise DataError("non-finite sample", file=self.source,
                            field=f"channel {i[0] + 1}", row=int(i[1]) + 1,
                            expected="finite numbers")
        if not (np.isfinite(self.sample_rate_Hz) and self.sample_rate_Hz > 0):
            raise DataError("sample rate must be > 0", file=self.source,
                            field="sample_rate_Hz", value=self.sample_rate_Hz,
                            expected="a rate in Hz")
        names = tuple(self.channel_names) or tuple(f"ch{k + 1}" for k in range(a.shape[0]))
        if len(names) != a.shape[0]:
            raise DataError("channel names do not match the records", file=self.source,
                            field="channel_names", value=len(names),
                            expected=f"{a.shape[0]} names")
        object.__setattr__(self, "data", a)
        object.__setattr__(self, "channel_names", names)

    @property
    def duration_s(self) -> float:
        return self.data.shape[1] / self.sample_rate_Hz


def load_operational(path: str | Path) -> OperationalRecord:
    """An output-only record: NPZ (``data (n_channels, n_samples)``, ``sample_rate_Hz``,
    optional ``channel_names``) or UFF 58 time records (function type 1; force records, if
    any, are left out; one record per channel, the first record of each channel's DOF)."""
    p = Path(path)
    if p.suffix.lower() == ".npz":
        if not p.is_file():
            raise DataError("file not found", file=str(p), expected="an NPZ file")
        try:
            z = np.load(p, allow_pickle=False)
        except ValueError:
            raise DataError("NPZ holds pickled objects (not read)", file=str(p),
                            expected="plain numeric arrays") from None
        except OSError as exc:
            raise DataError(f"not a readable NPZ file ({exc})", file=str(p)) from None
        for key in ("data", "sample_rate_Hz"):
            if key not in z:
                raise DataError("missing array", file=str(p), field=key,
                                expected="data (n_channels, n_samples) and sample_rate_Hz")
        names = tuple(str(v) for v in z["channel_names"]) if "channel_names" in z else ()
        return OperationalRecord(np.asarray(z["data"], float), float(z["sample_rate_Hz"]),
                                 names, str(p))
    from robobore.modal.io import read_uff_records

    recs = [r for r in read_uff_records(p) if int(r.get("func_type", 0)) == 1
            and int(r.get("ordinate_spec_data_type", 0)) != 13]
    if not recs:
        raise DataError("no response time records", file=str(p), field="func_type",
                        expected="dataset 58 function type 1 records of responses")
    seen: dict[tuple[int, int], dict[str, Any]] = {}
    for r in recs:
        seen.setdefault((int(r["rsp_node"]), int(r["rsp_dir"])), r)
    rs = list(seen.values())
    n = min(len(r["data"]) for r in rs)
    dt = float(rs[0]["abscissa_inc"])
    names = tuple(str(r.get("id2", "")).strip() or f"n{k[0]}d{k[1]}"
                  for k, r in seen.items())
    return OperationalRecord(np.array([np.asarray(r["data"], float)[:n] for r in rs]), 1.0 / dt,
                             names, str(p))


def remove_harmonics(y: np.ndarray, fs: float, spindle_rpm: float, f_max: float,
                     refine: bool = True) -> tuple[np.ndarray, float]:
    """Subtract the rotation harmonics ``h f_rot`` (``h f_rot <= f_max``) from records
    ``y (l, N)`` by least squares (a cosine and a sine per harmonic and channel), with
    ``f_rot`` refined within +-0.5 % of ``spindle_rpm / 60`` (largest summed power of the
    first harmonics on a 201-point grid) -> ``(y - harmonics, f_rot)``."""
    N = y.shape[1]
    t = np.arange(N) / fs
    f0 = spindle_rpm / 60.0
    nh = int(np.floor(f_max / f0))
    if nh < 1:
        return y, f0
    hs = np.arange(1, min(nh, 3) + 1)
    fr, half = f0, 0.005 * f0
    for _ in range(2 if refine else 0):
        grid = fr + np.linspace(-half, half, 21)
        power = [np.sum(np.abs(y @ np.exp(-2j * np.pi * np.outer(t, hs * g))) ** 2)
                 for g in grid]
        fr = float(grid[int(np.argmax(power))])
        half /= 10
    B = np.empty((N, 2 * nh))
    for h in range(1, nh + 1):
        B[:, 2 * h - 2] = np.cos(2 * np.pi * h * fr * t)
        B[:, 2 * h - 1] = np.sin(2 * np.pi * h * fr * t)
    coef, *_ = np.linalg.lstsq(B, y.T, rcond=None)
    return y - (B @ coef).T, fr


def _prepare(rec: OperationalRecord, band_Hz: tuple[float, float],
             spindle_rpm: float | None = None, refine: bool = True
             ) -> tuple[np.ndarray, float, float | None]:
    """Zero-mean records (rotation harmonics subtracted when the speed is given) decimated
    so that the band's top is <= 0.4 of the new rate."""
    from scipy.signal import decimate

    lo, hi = band_Hz
    fs = rec.sample_rate_Hz
    if not (0 < lo < hi <= 0.5 * fs):
        raise InputError("band outside the record", field="band_Hz", value=(lo, hi),
                         expected=f"0 < LO < HI <= {0.5 * fs:g} Hz (the Nyquist frequency)")
    need = MIN_PERIODS / lo
    if rec.duration_s < need:
        raise InputError(f"record too short: {rec.duration_s:g} s is fewer than ten periods "
                         f"of the lowest frequency {lo:g} Hz", field="duration_s",
                         value=rec.duration_s,
                         expected=f">= {need:g} s (ten periods of {lo:g} Hz), or a higher LO")
    y = rec.data - rec.data.mean(axis=1, keepdims=True)
    for step in _decimation_steps(int(max(1, np.floor(0.4 * fs / hi)))):
        y = decimate(y, step, ftype="fir", axis=1, zero_phase=True)
        fs /= step
    f_rot = None
    if spindle_rpm:  # after decimation: the harmonics above the band are filtered out
        y, f_rot = remove_harmonics(y, fs, spindle_rpm, min(1.2 * hi, 0.45 * fs), refine)
    return y, fs, f_rot


def _decimation_steps(q_max: int) -> list[int]:
    """Stages (each <= 10, as scipy's FIR decimation wants) of the largest factor
    ``<= q_max`` that splits into such stages."""
    for q in range(q_max, 0, -1):
        steps, r = [], q
        for p in range(10, 1, -1):
            while r % p == 0:
                steps.append(p)
                r //= p
        if r == 1:
            return steps
    return []


def correlations(y: np.ndarray, n_lags: int) -> np.ndarray:
    """``R (n_lags + 1, l, l)``: ``R_i = 1/(N-i) sum_k y_(k+i) y_k^T`` (unbiased, by FFT)."""
    l, N = y.shape
    nfft = 1 << int(np.ceil(np.log2(2 * N)))
    Y = np.fft.rfft(y, nfft, axis=1)
    S = Y[:, None, :] * np.conj(Y[None, :, :])
    r = np.fft.irfft(S, nfft, axis=2)[:, :, : n_lags + 1]  # r[a, b, i] = sum y_a(k+i) y_b(k)
    return np.transpose(r, (2, 0, 1)) / (N - np.arange(n_lags + 1))[:, None, None]


@dataclass(frozen=True)
class SSIModel:
    """The factorised Toeplitz matrix of one record (all orders come from it)."""

    U: np.ndarray
    s: np.ndarray
    Vt: np.ndarray
    n_channels: int
    sample_rate_Hz: float  # after decimation


def ssi_factor(y: np.ndarray, fs: float, block_rows: int) -> SSIModel:
    l = y.shape[0]
    R = correlations(y, 2 * block_rows)
    s = block_rows
    T = np.zeros((s * l, s * l))
    for i in range(s):
        for j in range(s):
            T[i * l:(i + 1) * l, j * l:(j + 1) * l] = R[s + i - j]
    U, sv, Vt = np.linalg.svd(T)
    return SSIModel(U, sv, Vt, l, fs)


def ssi_poles(m: SSIModel, n: int, with_share: bool = False):
    """Poles (rad/s, positive frequency), shapes ``(n_poles, l)`` (unit norm) and, with
    ``with_share``, each pole's correlation weight (module docstring) for ``n`` states."""
    l = m.n_channels
    sq = np.sqrt(m.s[:n])
    O = m.U[:, :n] * sq[None, :]
    C = O[:l]
    A = np.linalg.lstsq(O[:-l], O[l:], rcond=None)[0]
    mu, Psi = np.linalg.eig(A)
    with np.errstate(divide="ignore", invalid="ignore"):
        lam = np.log(mu.astype(complex)) * m.sample_rate_Hz
    keep = np.isfinite(lam) & (lam.imag > 0)
    phi = (C @ Psi)[:, keep].T
    nrm = np.linalg.norm(phi, axis=1, keepdims=True)
    phi = phi / np.where(nrm > 0, nrm, 1.0)
    w = None
    if with_share:
        G = (sq[:, None] * m.Vt[:n])[:, :l]  # first block column of S^(1/2) V^T
        g = np.linalg.solve(Psi, G)  # (n, l)
        cm = np.linalg.norm(C @ Psi, axis=0)
        gm = np.linalg.norm(g, axis=1)
        with np.errstate(divide="ignore"):
            w = (cm * gm / np.maximum(1 - np.abs(mu), 1e-12))[keep]
    o = np.argsort(lam[keep].imag)
    return lam[keep][o], phi[o], (None if w is None else w[o])


@dataclass(frozen=True)
class OperationalMode:
    frequency_Hz: float
    damping_ratio: float
    mode_shape: np.ndarray  # (n_channels,) complex, largest entry 1
    share: float
    orders_stable: int
    uncertainty: Any = None

    def to_dict(self) -> dict[str, Any]:
        return {"frequency_Hz": self.frequency_Hz, "damping_ratio": self.damping_ratio,
                "share": self.share, "orders_stable": self.orders_stable,
                "mode_shape": [{"re": float(z.real), "im": float(z.imag)}
                               for z in self.mode_shape],
                "uncertainty": None if self.uncertainty is None else self.uncertainty.to_dict()}


@dataclass(frozen=True)
class OperationalResult:
    modes: tuple[OperationalMode, ...]
    channel_names: tuple[str, ...]
    band_Hz: tuple[float, float]
    max_order: int
    harmonics: tuple[dict[str, float], ...]
    stabilisation: dict[str, Any]
    sample_rate_Hz: float
    timings_s: dict[str, float]
    source: str | None = None
    diagram: Any = field(default=None, repr=False, compare=False)

    @property
    def frequencies_Hz(self) -> np.ndarray:
        return np.array([m.frequency_Hz for m in self.modes])

    @property
    def damping_ratios(self) -> np.ndarray:
        return np.array([m.damping_ratio for m in self.modes])

    def to_dict(self) -> dict[str, Any]:
        return {"method": "SSI-COV (output-only)", "modes": [m.to_dict() for m in self.modes],
                "channel_names": list(self.channel_names), "band_Hz": list(self.band_Hz),
                "max_order": self.max_order, "harmonics_excluded": list(self.harmonics),
                "stabilisation": self.stabilisation,
                "analysis_sample_rate_Hz": self.sample_rate_Hz,
                "timings_s": dict(self.timings_s), "source": self.source}


def _poles_result(m: SSIModel, orders: list[int], band: tuple[float, float]) -> PLSCFResult:
    sets = []
    for o in orders:
        lam, phi, _ = ssi_poles(m, 2 * o)
        sets.append(PoleSet(o, lam, phi))
    return PLSCFResult(tuple(sets), band, m.n_channels, 1.0 / m.sample_rate_Hz, 0.0)


def _is_harmonic(f: float, z: float, f_rot: float | None) -> bool:
    if f_rot:
        h = max(1, round(f / f_rot))
        if abs(f - h * f_rot) <= HARMONIC_TOL * f and z < HARMONIC_MAX_DAMPING:
            return True
    return z < NO_SPEED_MAX_DAMPING


def identify_operational(rec: OperationalRecord, band_Hz: tuple[float, float], *,
                         n_modes: int | None = None, spindle_rpm: float | None = None,
                         max_order: int = 30, block_rows: int | None = None,
                         min_fraction: float = 0.3, uncertainty: bool = True,
                         segments: int = 6) -> OperationalResult:
    """Output-only identification of ``rec`` in ``band_Hz`` (module docstring; BLAS on one
    thread: many small problems).

    n_modes: keep the N modes with the largest shares (default: every physical mode).
    spindle_rpm: rotation speed of a cutting record (its harmonics are excluded).
    max_order: highest model order in modes (``2 max_order`` states).
    """
    from robobore.modal.plscf import single_thread_blas

    with single_thread_blas():
        return _identify_operational(rec, band_Hz, n_modes, spindle_rpm, max_order,
                                     block_rows, min_fraction, uncertainty, segments)


def _identify_operational(rec: OperationalRecord, band_Hz: tuple[float, float],
                          n_modes: int | None, spindle_rpm: float | None, max_order: int,
                          block_rows: int | None, min_fraction: float, uncertainty: bool,
                          segments: int) -> OperationalResult:
    t0 = time.perf_counter()
    if n_modes is not None and n_modes < 1:
        raise InputError("number of modes must be >= 1", field="modes", value=n_modes,
                         expected="an integer >= 1")
    if spindle_rpm is not None and not spindle_rpm > 0:
        raise InputError("spindle speed must be > 0", field="spindle_rpm", value=spindle_rpm,
                         expected="a speed in r/min")
    band = (float(band_Hz[0]), float(band_Hz[1]))
    y, fs, f_rot_fit = _prepare(rec, band, spindle_rpm)
    l = y.shape[0]
    # block rows: the model's states, and lags over at least one period of the band's low edge
    s = block_rows or min(max(int(np.ceil(2 * max_order / l)) + 2, 20,
                              int(np.ceil(fs / band[0]))), 400)
    model = ssi_factor(y, fs, s)
    if 2 * max_order > s * l:
        raise InputError("model order too high for the block rows", field="max_order",
                         value=max_order, expected=f"<= {s * l // 2}")
    t1 = time.perf_counter()
    orders = list(range(1, max_order + 1))
    res = _poles_result(model, orders, band)
    diag = stabilisation(res)
    clusters = pole_clusters(diag)
    need = support_needed(diag, min_fraction)
    f_rot = None if spindle_rpm is None else spindle_rpm / 60.0
    harm: dict[float, dict[str, float]] = {}
    for c in clusters:  # one entry per harmonic frequency (its clusters may split)
        if _is_harmonic(c.frequency_Hz, c.damping_ratio, f_rot):
            harm.setdefault(round(c.frequency_Hz, 1), {"frequency_Hz": c.frequency_Hz,
                                                       "damping_ratio": c.damping_ratio})
    harmonics = tuple(harm[k] for k in sorted(harm))
    phys = [c for c in clusters if c.cluster_size >= need
            and not _is_harmonic(c.frequency_Hz, c.damping_ratio, f_rot)]
    if not phys:
        raise IdentificationError(
            f"no pole is stable over {need} of the model orders 1-{max_order} in "
            f"{band[0]:g}-{band[1]:g} Hz (besides rotation harmonics), from {l} response "
            f"channel{'s' if l != 1 else ''} of {y.shape[1] / fs:.3g} s; expected at least one "
            "physical pole: raise --max-order, lengthen the record"
            + (", record more channels (one channel separates few modes)" if l == 1 else "")
            + " or check the band")
    phys.sort(key=lambda c: c.frequency_Hz)
    # shares and shapes at the highest order, nearest pole per mode
    lam, phi, wgt = ssi_poles(model, 2 * max_order, with_share=True)
    share = np.zeros(len(phys))
    shapes = []
    for k, c in enumerate(phys):
        j = int(np.argmin(np.abs(lam - c.pole)))
        share[k] = wgt[j]
        v = phi[j]
        shapes.append(v / v[int(np.argmax(np.abs(v)))])
    share = share / (share.sum() or 1.0)
    idx = list(range(len(phys)))
    if n_modes is not None:
        if len(phys) < n_modes:
            raise IdentificationError(f"asked for {n_modes} modes but only {len(phys)} "
                                      "physical modes are in the band")
        idx = sorted(np.argsort(-share, kind="stable")[:n_modes].tolist())
    t2 = time.perf_counter()
    unc: list[Any] = [None] * len(idx)
    info: dict[str, Any] = {}
    if uncertainty:
        unc, info = _jackknife_segments(rec, band, [phys[i] for i in idx], s, segments,
                                        None if f_rot_fit is None else 60.0 * f_rot_fit)
    t3 = time.perf_counter()
    modes = tuple(OperationalMode(phys[i].frequency_Hz, phys[i].damping_ratio, shapes[i],
                                  float(share[i]), phys[i].cluster_size, u)
                  for i, u in zip(idx, unc, strict=True))
    summary = diag.summary()
    summary["orders_needed"] = need
    summary["physical_modes"] = [{"frequency_Hz": c.frequency_Hz,
                                  "damping_ratio": c.damping_ratio,
                                  "orders_stable": c.cluster_size, "share": float(share[k]),
                                  "selected": k in idx} for k, c in enumerate(phys)]
    summary["uncertainty"] = info or {"method": None}
    if f_rot_fit is not None:
        summary["rotation_frequency_Hz"] = f_rot_fit
    return OperationalResult(modes, rec.channel_names, band, max_order, harmonics, summary, fs,
                             {"ssi_factor": t1 - t0, "poles_selection": t2 - t1,
                              "uncertainty": t3 - t2}, rec.source, diag)


def _jackknife_segments(rec: OperationalRecord, band: tuple[float, float], sel: list[Any],
                        s: int, J: int, spindle_rpm: float | None = None
                        ) -> tuple[list[Any], dict[str, Any]]:
    """Jackknife over ``J`` record segments (module docstring)."""
    from scipy.stats import t as student_t

    from robobore.modal.uncertainty import ModeUncertainty

    t0 = time.perf_counter()
    n = rec.data.shape[1]
    edges = np.linspace(0, n, J + 1).astype(int)
    f0 = np.array([c.frequency_Hz for c in sel])
    z0 = np.array([c.damping_ratio for c in sel])
    ords = [tuple(o for o in c.orders if o >= np.median(c.orders))[-6:] for c in sel]
    reps = []
    for j in range(J):
        keep = np.concatenate([np.arange(edges[i], edges[i + 1]) for i in range(J) if i != j])
        sub = OperationalRecord(rec.data[:, keep], rec.sample_rate_Hz, rec.channel_names)
        y, fs, _ = _prepare(sub, band, spindle_rpm, refine=False)
        m = ssi_factor(y, fs, s)
        cache: dict[int, np.ndarray] = {}
        fr = np.full(len(sel), np.nan)
        zr = np.full(len(sel), np.nan)
        for k in range(len(sel)):
            got = []
            for o in ords[k]:
                if o not in cache:
                    cache[o] = ssi_poles(m, 2 * o)[0]
                lam = cache[o]
                if lam.size == 0:
                    continue
                f = np.abs(lam) / (2 * np.pi)
                z = -lam.real / np.abs(lam)
                with np.errstate(divide="ignore", invalid="ignore"):
                    d = np.abs(np.log(f / f0[k])) / 0.005 + np.abs(
                        np.log(np.where(z > 0, z, 1e-12) / z0[k])) / 0.3
                i = int(np.argmin(d))
                if d[i] <= 3.0:
                    got.append((f[i], z[i]))
            if got:
                fr[k] = np.mean([g[0] for g in got])
                zr[k] = np.mean([g[1] for g in got])
        reps.append((fr, zr))
    F = np.array([r[0] for r in reps])
    Z = np.array([r[1] for r in reps])
    out = []
    for k in range(len(sel)):
        ok = np.isfinite(F[:, k])
        nj = int(ok.sum())
        if nj < 2:
            out.append(None)
            continue
        fac = (nj - 1) / nj
        sf = float(np.sqrt(fac * np.sum((F[ok, k] - F[ok, k].mean()) ** 2)))
        sz = float(np.sqrt(fac * np.sum((Z[ok, k] - Z[ok, k].mean()) ** 2)))
        t = float(student_t.ppf(0.975, nj - 1))
        out.append(ModeUncertainty(sf, sz, (f0[k] - t * sf, f0[k] + t * sf),
                                   (z0[k] - t * sz, z0[k] + t * sz), float(nj - 1),
                                   None, (), nj, "jackknife over record segments"))
    return out, {"method": "jackknife over record segments", "segments": J,
                 "time_s": time.perf_counter() - t0}


def simulate_operational(truth: Any, duration_s: float, sample_rate_Hz: float, *,
                         spindle_rpm: float | None = None, harmonic_ratio: float = 1.0,
                         n_harmonics: int = 12, direction_ratios: Any = (1.0, 0.6, 0.3),
                         noise: float = 0.02, seed: int = 0) -> OperationalRecord:
    """SYNTHETIC output-only accelerations of a modal truth (``robobore.modal.virtual``)
    under unmeasured forces at its inputs: white random forces (independent per input, RMS
    in ``direction_ratios``), plus for a cutting record ``n_harmonics`` rotation harmonics
    ``h * spindle_rpm / 60`` (amplitude ``1/h``, random phases, the same direction ratios;
    their total RMS ``harmonic_ratio`` x the random part's). Response by exact filtering in
    the frequency domain over the record (periodic extension); white measurement noise of
    ``noise`` x each channel's RMS."""
    rng = np.random.default_rng(seed)
    n = int(round(duration_s * sample_rate_Hz))
    f = np.fft.rfftfreq(n, 1.0 / sample_rate_Hz)
    ni = truth.phi_in.shape[0]
    ratio = np.resize(np.asarray(direction_ratios, float), ni)
    force = rng.standard_normal((ni, n)) * ratio[:, None]
    if spindle_rpm:
        t = np.arange(n) / sample_rate_Hz
        fr = spindle_rpm / 60.0
        per = np.zeros((ni, n))
        for h in range(1, n_harmonics + 1):
            if h * fr >= 0.45 * sample_rate_Hz:
                break
            per += (ratio[:, None] / h) * np.cos(2 * np.pi * h * fr * t
                                                 + rng.uniform(0, 2 * np.pi, (ni, 1)))
        rms_r = np.sqrt(np.mean(force**2))
        rms_h = np.sqrt(np.mean(per**2))
        force = force + harmonic_ratio * rms_r / rms_h * per
    H = truth.frf(f, "accelerance")
    y = np.fft.irfft(np.einsum("ojk,jk->ok", H, np.fft.rfft(force, axis=1)), n, axis=1)
    y = y + noise * y.std(axis=1, keepdims=True) * rng.standard_normal(y.shape)
    return OperationalRecord(y, sample_rate_Hz, tuple(truth.output_names), None,
                             {"synthetic": True, "spindle_rpm": spindle_rpm,
                              "harmonic_ratio": harmonic_ratio, "noise": noise, "seed": seed})


__all__ = ["OperationalRecord", "simulate_operational", "remove_harmonics", "OperationalResult", "OperationalMode", "load_operational",
           "identify_operational", "correlations", "ssi_factor", "ssi_poles", "SSIModel",
           "MIN_PERIODS"]
