"""FRF estimation from impact-hammer time records.

Conventions
-----------
* Time records: ``force`` ``(n_inputs, n_hits, n_samples)`` in N and ``response``
  ``(n_inputs, n_hits, n_outputs, n_samples)`` in m/s^2 (or m/s, m), sampled at
  ``sample_rate_Hz``. Input ``j`` is one hammer point/direction; every hit excites one input
  (single-input-multiple-output per hit, as in a roving-accelerometer-free hammer test).
* FRF matrices: ``(n_outputs, n_inputs, n_frequencies)`` complex, response per force.
* Estimators (Bendat & Piersol; Allemang, *Vibrations: Experimental Modal Analysis*, UC-SDRL
  course notes ch. 5; Fladung 1994): with ``F`` and ``A`` the DFTs of the windowed force and
  response of each hit, summed over hits::

      H1 = sum(conj(F) A) / sum(|F|^2)             (noise on the response)
      H2 = sum(|A|^2) / sum(conj(A) F)             (noise on the force)
      Hv = sqrt(|H1| |H2|) exp(j angle(H1))        (geometric mean, SIMO case)
      coherence = |sum(conj(F) A)|^2 / (sum(|F|^2) sum(|A|^2))

* Exponential window ``w(t) = exp(-(t - t0)/tau)`` (``t0`` = trigger): it multiplies every
  decaying exponential ``exp(lambda t)`` of the response by ``exp(-t/tau)``, so every
  identified pole is shifted by exactly ``-1/tau`` along the real axis::

      lambda_est = lambda_true - 1/tau
      => lambda_true = lambda_est + 1/tau        (applied exactly by correct_poles_for_window)

  In damping ratios, with ``lambda = -zeta w_n + j w_n sqrt(1 - zeta^2)`` and a small shift,
  ``zeta_true ~= zeta_est - 1/(tau w_n)`` (first order in ``1/(tau w_n)``). The force is
  windowed with the same exponential (the pulse sits at ``t0``, where ``w = 1``), so the
  ratio ``A/F`` is the FRF of the damped-more system.

The FRF container (:class:`FRFData`, types, units, checks) is :mod:`robobore.modal.frf_data`;
its public names are importable from here too.
"""

from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from robobore.errors import DataError, InputError
from robobore.modal.frf_data import (
    RESPONSE_QUANTITIES,
    FRFData,
)


class DoubleHitWarning(UserWarning):
    """A hit looks like a double hit or an overload; consider dropping it."""


@dataclass(frozen=True)
class HammerRecords:
    """Impact-hammer time records.

    Attributes
    ----------
    sample_rate_Hz: sampling rate, Hz.
    force: ``(n_inputs, n_hits, n_samples)`` hammer force, N.
    response: ``(n_inputs, n_hits, n_outputs, n_samples)``, SI unit of ``response_quantity``.
    response_quantity: ``acceleration`` | ``velocity`` | ``displacement``.
    valid: ``(n_inputs, n_hits)`` bool; hits marked False are left out of the average.
    force_range_N, response_range: ADC full-scale ranges (for overload detection) or None.
    """

    sample_rate_Hz: float
    force: np.ndarray
    response: np.ndarray
    response_quantity: str = "acceleration"
    output_names: tuple[str, ...] = ()
    input_names: tuple[str, ...] = ()
    valid: np.ndarray | None = None
    force_range_N: float | None = None
    response_range: float | None = None
    pretrigger_s: float = 0.0
    source: str | None = None
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        src = self.source
        if not (np.isfinite(self.sample_rate_Hz) and self.sample_rate_Hz > 0):
            raise DataError("sample rate must be > 0", file=src, field="sample_rate_Hz",
                            value=self.sample_rate_Hz, expected="a rate > 0 Hz")
        f = np.asarray(self.force, dtype=float)
        r = np.asarray(self.response, dtype=float)
        if f.ndim != 3:
            raise DataError("force records have the wrong shape", file=src, field="force",
                            value=f"shape {f.shape}", expected="(n_inputs, n_hits, n_samples)")
        if r.ndim != 4 or r.shape[:2] != f.shape[:2] or r.shape[3] != f.shape[2]:
            raise DataError("response records have the wrong shape", file=src,
                            field="response", value=f"shape {r.shape}",
                            expected=f"({f.shape[0]}, {f.shape[1]}, n_outputs, {f.shape[2]})")
        if f.shape[2] < 16:
            raise DataError("records are too short", file=src, field="n_samples",
                            value=f.shape[2], expected=">= 16 samples")
        for name, arr in (("force", f), ("response", r)):
            bad = np.argwhere(~np.isfinite(arr))
            if bad.size:
                raise DataError("time record has non-finite values", file=src,
                                field=f"{name}[{', '.join(str(int(v)) for v in bad[0][:-1])}]",
                                row=int(bad[0][-1]) + 1, expected="finite samples")
        rq = str(self.response_quantity).lower()
        if rq not in RESPONSE_QUANTITIES:
            raise DataError("unknown response quantity", file=src, field="response_quantity",
                            value=self.response_quantity,
                            expected="acceleration, velocity or displacement")
        object.__setattr__(self, "force", f)
        object.__setattr__(self, "response", r)
        object.__setattr__(self, "response_quantity", rq)
        v = (np.ones(f.shape[:2], bool) if self.valid is None
             else np.asarray(self.valid, bool))
        if v.shape != f.shape[:2]:
            raise DataError("valid mask has the wrong shape", file=src, field="valid",
                            value=f"shape {v.shape}", expected=f"shape {f.shape[:2]}")
        object.__setattr__(self, "valid", v)
        ni, no = f.shape[0], r.shape[2]
        on = tuple(self.output_names) or tuple(f"o{k + 1}" for k in range(no))
        inn = tuple(self.input_names) or tuple(f"i{k + 1}" for k in range(ni))
        if len(on) != no or len(inn) != ni:
            raise DataError("channel names do not match the records", file=src,
                            field="output_names/input_names",
                            expected=f"{no} output and {ni} input names")
        object.__setattr__(self, "output_names", on)
        object.__setattr__(self, "input_names", inn)

    @property
    def n_inputs(self) -> int:
        return self.force.shape[0]

    @property
    def n_hits(self) -> int:
        return self.force.shape[1]

    @property
    def n_outputs(self) -> int:
        return self.response.shape[2]

    @property
    def n_samples(self) -> int:
        return self.force.shape[2]

    def drop_hits(self, hits: list[tuple[int, int]]) -> HammerRecords:
        """Mark hits ``(input_index, hit_index)`` (0-based) as invalid."""
        v = self.valid.copy()
        for i, h in hits:
            if not (0 <= i < self.n_inputs and 0 <= h < self.n_hits):
                raise InputError("no such hit", field="drop_hits", value=(i, h),
                                 expected=f"input < {self.n_inputs}, hit < {self.n_hits}")
            v[i, h] = False
        return _replace(self, valid=v)


def _replace(rec: HammerRecords, **kw: Any) -> HammerRecords:
    d = {k: getattr(rec, k) for k in rec.__dataclass_fields__}
    d.update(kw)
    return HammerRecords(**d)


@dataclass(frozen=True)
class HitCheck:
    """Quality checks of one hit."""

    input_index: int
    hit_index: int
    peak_force_N: float
    pulse_width_s: float
    double_hit: bool
    force_overload: bool
    response_overload: bool

    @property
    def flagged(self) -> bool:
        return self.double_hit or self.force_overload or self.response_overload

    def to_dict(self) -> dict[str, Any]:
        return {"input": self.input_index, "hit": self.hit_index,
                "peak_force_N": self.peak_force_N, "pulse_width_s": self.pulse_width_s,
                "double_hit": self.double_hit, "force_overload": self.force_overload,
                "response_overload": self.response_overload}


def _segments(mask: np.ndarray) -> list[tuple[int, int]]:
    """Contiguous True runs as (start, stop) index pairs."""
    m = np.concatenate(([False], mask, [False])).astype(np.int8)
    d = np.diff(m)
    starts = np.flatnonzero(d == 1)
    stops = np.flatnonzero(d == -1)
    return list(zip(starts.tolist(), stops.tolist(), strict=True))


def _clipped(x: np.ndarray, full_scale: float | None, min_run: int = 3) -> bool:
    """Overload: samples at the ADC range, or a flat top of >= min_run equal extreme samples."""
    a = np.abs(x)
    peak = float(a.max())
    if peak == 0:
        return False
    if full_scale is not None and peak >= 0.999 * full_scale:
        return True
    at_top = a >= peak * (1 - 1e-9)
    return any(b - s >= min_run for s, b in _segments(at_top))


def check_hit(force: np.ndarray, response: np.ndarray, fs: float,
              force_range: float | None = None, response_range: float | None = None,
              threshold: float = 0.1) -> tuple[float, float, bool, bool, bool]:
    """Peak force, pulse width, double-hit and overload flags of one hit.

    A double hit is a second force pulse above ``threshold`` x peak separated from the
    first one by the force returning below the threshold for longer than one pulse width.
    """
    f = np.asarray(force, float)
    peak = float(np.max(np.abs(f)))
    segs = _segments(np.abs(f) > threshold * peak) if peak > 0 else []
    if not segs:
        return peak, 0.0, False, False, False
    main = max(segs, key=lambda s: np.abs(f[s[0]:s[1]]).max())
    width = (main[1] - main[0]) / fs
    double = False
    for s in segs:
        if s is main:
            continue
        gap = (s[0] - main[1]) if s[0] >= main[1] else (main[0] - s[1])
        if gap > max(1, main[1] - main[0]):
            double = True
    f_ovl = _clipped(f, force_range)
    r_ovl = any(_clipped(r, response_range) for r in np.atleast_2d(response))
    return peak, width, double, f_ovl, r_ovl


def exponential_window(n: int, fs: float, tau_s: float, t0_s: float = 0.0) -> np.ndarray:
    """``w(t) = exp(-(t - t0)/tau)`` for ``t >= t0``, 1 before; ``(n,)``."""
    t = np.arange(n) / fs
    return np.exp(-np.clip(t - t0_s, 0.0, None) / tau_s)


def force_window(force: np.ndarray, fs: float, length_s: float | None = None,
                 taper_s: float | None = None) -> np.ndarray:
    """Force window ``(n,)``: 1 around the pulse, cosine taper, 0 elsewhere.

    The window opens a little before the pulse starts (2 % of peak) and closes
    ``length_s`` after the peak (default: 4 pulse widths, at least 10 samples), so that the
    noise in the force channel outside the pulse does not enter the spectrum.
    """
    f = np.asarray(force, float)
    n = f.size
    a = np.abs(f)
    ip = int(np.argmax(a))
    peak = a[ip]
    above = np.flatnonzero(a > 0.02 * peak)
    start = int(above[0]) if above.size else ip
    width = max(1, ip - start) * 2
    if length_s is None:
        stop = min(n, ip + max(10, 4 * width))
    else:
        stop = min(n, ip + max(1, int(round(length_s * fs))))
    start = max(0, start - max(2, width // 2))
    w = np.zeros(n)
    w[start:stop] = 1.0
    nt = max(2, int(round((taper_s or 0.0) * fs))) if taper_s is not None else max(2, width)
    nt = min(nt, n - stop)
    if nt > 0:
        w[stop:stop + nt] = 0.5 * (1 + np.cos(np.pi * (np.arange(nt) + 1) / (nt + 1)))
    return w


@dataclass(frozen=True)
class FRFEstimate:
    """Result of :func:`estimate_frf`: the FRF data and the per-hit checks."""

    frf: FRFData
    hits: tuple[HitCheck, ...]
    n_averages: np.ndarray  # (n_inputs,) hits used per input
    decay_ratio: np.ndarray | None = None  # (n_inputs,) median over hits, record_decay_ratio
    #: per-hit spectra for resampling the hits (:func:`combine_hits`): ``sff (ni, nh, nf)``,
    #: ``sfa (no, ni, nh, nf)``, ``saa (no, ni, nh, nf)`` on all DFT lines, ``used (ni, nh)``
    per_hit: dict[str, Any] | None = field(default=None, repr=False, compare=False)
    estimator: str = "H1"

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {"hits": [h.to_dict() for h in self.hits],
                             "n_averages": self.n_averages.tolist()}
        if self.decay_ratio is not None:
            d["decay_ratio"] = self.decay_ratio.tolist()
        return d


class LeakageWarning(UserWarning):
    """The response has not decayed by the end of the record (leakage)."""


def record_decay_ratio(response: np.ndarray, t_peak: int) -> float:
    """RMS of the last 10 % of a record over the RMS of the 10 % after the hammer peak,
    worst channel; ``response`` ``(n_outputs, n_samples)``. The noise floor, estimated from
    the pre-trigger samples (when there are >= 8), is removed in power from the tail, so the
    ratio is ~0 when the response has died out and large when the free decay was truncated
    (leakage)."""
    n = response.shape[-1]
    m = max(4, n // 10)
    head = response[:, t_peak: t_peak + m]
    tail = response[:, n - m:]
    h2 = np.mean(head**2, axis=-1)
    t2 = np.mean(tail**2, axis=-1)
    pre = t_peak - 4  # leave out the samples next to the pulse
    if pre >= 8:
        t2 = np.maximum(t2 - np.mean(response[:, :pre] ** 2, axis=-1), 0.0)
    return float(np.max(np.sqrt(t2 / np.where(h2 > 0, h2, np.inf))))


def estimate_frf(records: HammerRecords, *, estimator: str = "H1",
                 exp_window_tau_s: float | None = None, use_force_window: bool = True,
                 force_window_s: float | None = None, drop_flagged: bool = False,
                 double_hit_threshold: float = 0.1,
                 leakage_threshold: float = 0.1) -> FRFEstimate:
    """Average FRFs and coherence over the hits of every input.

    Parameters
    ----------
    records: the time records.
    estimator: ``H1`` | ``H2`` | ``Hv``.
    exp_window_tau_s: exponential window time constant (s) applied to force and response,
        starting at the pulse peak; None for no window. Carried on the result so that the
        poles can be corrected (``+1/tau``).
    use_force_window, force_window_s: force window (see :func:`force_window`).
    drop_flagged: leave out hits flagged as double hits/overloads (a warning is issued
        either way).
    leakage_threshold: warn (LeakageWarning) when, without exponential window, the median
        over the hits of :func:`record_decay_ratio` exceeds this value.

    Returns
    -------
    FRFEstimate with ``frf.frf`` ``(n_outputs, n_inputs, n_samples//2 + 1)``.
    """
    est = estimator.strip().upper()
    if est not in ("H1", "H2", "HV"):
        raise InputError("unknown FRF estimator", field="estimator", value=estimator,
                         expected="H1, H2 or Hv")
    if exp_window_tau_s is not None and not exp_window_tau_s > 0:
        raise InputError("exponential window time constant must be > 0",
                         field="exp_window_tau_s", value=exp_window_tau_s, expected="tau > 0 s")
    fs = records.sample_rate_Hz
    ni, nh, no, n = records.n_inputs, records.n_hits, records.n_outputs, records.n_samples
    nf = n // 2 + 1
    sff = np.zeros((ni, nh, nf))
    sfa = np.zeros((no, ni, nh, nf), complex)
    saa = np.zeros((no, ni, nh, nf))
    checks: list[HitCheck] = []
    used = np.zeros(ni, int)
    use = np.zeros((ni, nh), bool)
    decay = np.zeros(ni)
    ratios: list[float] = []
    for i in range(ni):
        for h in range(nh):
            f = records.force[i, h]
            r = records.response[i, h]
            peak, width, dbl, fo, ro = check_hit(f, r, fs, records.force_range_N,
                                                 records.response_range, double_hit_threshold)
            chk = HitCheck(i, h, peak, width, dbl, fo, ro)
            checks.append(chk)
            if chk.flagged:
                what = ", ".join(k for k, v in (("double hit", dbl), ("force overload", fo),
                                                ("response overload", ro)) if v)
                warnings.warn(f"input {records.input_names[i]} hit {h + 1}: {what}"
                              + (" (dropped)" if drop_flagged else
                                 " (kept; use drop_flagged / --drop-flagged to leave it out)"),
                              DoubleHitWarning, stacklevel=2)
            if not records.valid[i, h] or (drop_flagged and chk.flagged):
                continue
            if peak == 0:
                raise DataError("force record is all zeros", file=records.source,
                                field=f"force[input {records.input_names[i]}, hit {h + 1}]",
                                expected="a hammer pulse in N")
            wf = force_window(f, fs, force_window_s) if use_force_window else np.ones(n)
            we = np.ones(n)
            if exp_window_tau_s is not None:
                we = exponential_window(n, fs, exp_window_tau_s, np.argmax(np.abs(f)) / fs)
            F = np.fft.rfft(f * wf * we)
            A = np.fft.rfft(r * we[None, :], axis=-1)
            sff[i, h] = np.abs(F) ** 2
            sfa[:, i, h] = np.conj(F)[None, :] * A
            saa[:, i, h] = np.abs(A) ** 2
            used[i] += 1
            use[i, h] = True
            ratios.append(record_decay_ratio(r, int(np.argmax(np.abs(f)))))
        decay[i] = float(np.median(ratios)) if ratios else 0.0
        ratios.clear()
        if exp_window_tau_s is None and decay[i] > leakage_threshold:
            warnings.warn(
                f"input {records.input_names[i]}: the response has not decayed by the end of "
                f"the record (end/start RMS {decay[i]:.2f}): leakage biases damping; use an "
                f"exponential window, e.g. tau = {n / fs / 4:.3g} s (--exp-window-tau-s)",
                LeakageWarning, stacklevel=2)
        if used[i] == 0:
            raise DataError("no valid hit left for an input", file=records.source,
                            field=f"input {records.input_names[i]}",
                            expected="at least one hit that is not dropped")
    h, coh = _combine(sff.sum(axis=1), sfa.sum(axis=2), saa.sum(axis=2), est)
    sff_all = sff.sum(axis=1)
    freq = np.fft.rfftfreq(n, 1.0 / fs)
    # lines where the force has no energy (e.g. exactly at a zero of the pulse spectrum)
    # cannot be estimated: report them instead of returning NaN
    good = np.isfinite(h).all(axis=(0, 1)) & (sff_all.min(axis=0) > 0)
    if not good.all():
        k = int(np.flatnonzero(~good)[0])
        if good.sum() < 8:
            raise DataError("force spectrum is zero: FRF cannot be estimated",
                            file=records.source, field="force", row=k + 1,
                            expected="hammer pulses with energy in the band")
        freq, h, coh = freq[good], h[:, :, good], coh[:, :, good]
    coh = np.nan_to_num(np.clip(coh, 0.0, 1.0), nan=0.0)
    ftype = RESPONSE_QUANTITIES[records.response_quantity]
    data = FRFData(freq, h, ftype, coh, records.output_names, records.input_names,
                   exp_window_tau_s, records.source,
                   tuple(records.meta.get("output_dofs", ())),
                   tuple(records.meta.get("input_dofs", ())))
    per_hit = {"sff": sff[:, :, good], "sfa": sfa[:, :, :, good], "saa": saa[:, :, :, good],
               "used": use}
    return FRFEstimate(data, tuple(checks), used, decay, per_hit, est)


def _combine(sff: np.ndarray, sfa: np.ndarray, saa: np.ndarray, est: str
             ) -> tuple[np.ndarray, np.ndarray]:
    """FRF (H1/H2/HV) and coherence from summed spectra ``(ni, nf)``, ``(no, ni, nf)``."""
    with np.errstate(divide="ignore", invalid="ignore"):
        h1 = sfa / sff[None]
        h2 = saa / np.conj(sfa)
        coh = np.abs(sfa) ** 2 / (sff[None] * saa)
    if est == "H1":
        h = h1
    elif est == "H2":
        h = h2
    else:
        h = np.sqrt(np.abs(h1) * np.abs(h2)) * np.exp(1j * np.angle(h1))
    return h, coh


def combine_hits(est: FRFEstimate, weights: np.ndarray) -> FRFData:
    """The FRFs of ``est`` re-averaged with per-hit ``weights (n_inputs, n_hits)`` (0 leaves a
    hit out, 2 counts it twice): the resampling step of the bootstrap/jackknife over hits."""
    ph = est.per_hit
    if ph is None:
        raise InputError("the FRF estimate holds no per-hit spectra", field="per_hit",
                         expected="an FRFEstimate of estimate_frf")
    w = np.asarray(weights, float) * ph["used"]
    if np.any(w.sum(axis=1) <= 0):
        raise InputError("every input needs a hit", field="weights", value=w.sum(axis=1),
                         expected="a positive weight for at least one used hit per input")
    sff = np.einsum("ih,ihf->if", w, ph["sff"])
    sfa = np.einsum("ih,oihf->oif", w, ph["sfa"])
    saa = np.einsum("ih,oihf->oif", w, ph["saa"])
    h, coh = _combine(sff, sfa, saa, est.estimator)
    coh = np.nan_to_num(np.clip(coh, 0.0, 1.0), nan=0.0)
    return dataclasses.replace(est.frf, frf=h, coherence=coh)


__all__ = [
    "HammerRecords",
    "HitCheck",
    "FRFEstimate",
    "DoubleHitWarning",
    "LeakageWarning",
    "record_decay_ratio",
    "estimate_frf",
    "combine_hits",
    "check_hit",
    "force_window",
    "exponential_window",
]
