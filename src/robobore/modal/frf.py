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
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from robobore.errors import DataError, InputError

FRF_TYPES = ("accelerance", "mobility", "receptance")
RESPONSE_QUANTITIES = {"acceleration": "accelerance", "velocity": "mobility",
                       "displacement": "receptance"}
#: power of j omega that turns a receptance into each FRF type
FRF_POWER = {"receptance": 0, "mobility": 1, "accelerance": 2}
FRF_UNITS = {"receptance": "m/N", "mobility": "m/s/N", "accelerance": "m/s^2/N"}


class DoubleHitWarning(UserWarning):
    """A hit looks like a double hit or an overload; consider dropping it."""


def check_frequencies(freq: np.ndarray, *, file: str | None = None,
                      name: str = "frequency_Hz") -> np.ndarray:
    """Validate a frequency axis (1-D, finite, >= 0, strictly increasing) in Hz."""
    f = np.asarray(freq)
    if f.ndim != 1 or f.size < 2:
        raise DataError("frequency axis must be a 1-D array with at least 2 lines", file=file,
                        field=name, value=f"shape {f.shape}", expected="shape (n_f,), n_f >= 2")
    if not np.isrealobj(f):
        raise DataError("frequency axis must be real", file=file, field=name,
                        expected="real frequencies in Hz")
    f = f.astype(float)
    bad = np.flatnonzero(~np.isfinite(f))
    if bad.size:
        raise DataError("frequency axis has non-finite values", file=file, field=name,
                        row=int(bad[0]) + 1, value=float(f[bad[0]]), expected="finite Hz")
    if f[0] < 0:
        raise DataError("negative frequency", file=file, field=name, row=1, value=float(f[0]),
                        expected="frequencies >= 0 Hz")
    d = np.diff(f)
    bad = np.flatnonzero(d <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        raise DataError("frequencies are not strictly increasing", file=file, field=name,
                        row=i + 1, value=float(f[i]),
                        expected=f"a value > {f[i - 1]:g} Hz (previous line)")
    return f


def check_frf_array(frf: np.ndarray, n_f: int, *, file: str | None = None,
                    name: str = "frf") -> np.ndarray:
    """Validate an FRF array ``(n_outputs, n_inputs, n_f)``; returns complex128."""
    h = np.asarray(frf)
    if h.ndim == 1:
        h = h[None, None, :]
    elif h.ndim == 2:
        h = h[:, None, :]
    if h.ndim != 3 or h.shape[2] != n_f:
        raise DataError("FRF array has the wrong shape", file=file, field=name,
                        value=f"shape {np.asarray(frf).shape}",
                        expected=f"(n_outputs, n_inputs, {n_f}) matching frequency_Hz")
    if h.shape[0] < 1 or h.shape[1] < 1:
        raise DataError("FRF array is empty", file=file, field=name, value=f"shape {h.shape}",
                        expected="at least one output and one input")
    if not np.issubdtype(h.dtype, np.number):
        raise DataError("FRF array is not numeric", file=file, field=name,
                        value=str(h.dtype), expected="complex numbers")
    h = h.astype(complex)
    bad = np.argwhere(~np.isfinite(h))
    if bad.size:
        o, i, k = (int(v) for v in bad[0])
        raise DataError("FRF has non-finite values (NaN/inf)", file=file,
                        field=f"{name}[output {o}, input {i}]", row=k + 1,
                        value=complex(h[o, i, k]), expected="finite complex FRF values")
    if not np.any(h):
        raise DataError("every FRF value is zero", file=file, field=name,
                        expected="measured FRFs (a response to the hammer)")
    return h


def check_frf_type(frf_type: str, *, file: str | None = None) -> str:
    t = str(frf_type).strip().lower()
    if t not in FRF_TYPES:
        raise DataError("unknown FRF type", file=file, field="frf_type", value=frf_type,
                        expected="one of " + ", ".join(FRF_TYPES))
    return t


@dataclass(frozen=True)
class FRFData:
    """An FRF matrix with its frequency axis.

    Attributes
    ----------
    frequency_Hz: ``(n_f,)`` strictly increasing, Hz.
    frf: ``(n_outputs, n_inputs, n_f)`` complex, SI units of ``frf_type`` (see FRF_UNITS).
    frf_type: ``accelerance`` | ``mobility`` | ``receptance``.
    coherence: ``(n_outputs, n_inputs, n_f)`` in [0, 1] or None.
    exp_window_tau_s: time constant of the exponential window used (s), or None; the
        identified poles must be corrected by ``+1/tau`` (see module docstring).
    """

    frequency_Hz: np.ndarray
    frf: np.ndarray
    frf_type: str = "accelerance"
    coherence: np.ndarray | None = None
    output_names: tuple[str, ...] = ()
    input_names: tuple[str, ...] = ()
    exp_window_tau_s: float | None = None
    source: str | None = None
    output_dofs: tuple[tuple[int, int], ...] = ()
    input_dofs: tuple[tuple[int, int], ...] = ()

    def __post_init__(self) -> None:
        f = check_frequencies(self.frequency_Hz, file=self.source)
        h = check_frf_array(self.frf, f.size, file=self.source)
        object.__setattr__(self, "frequency_Hz", f)
        object.__setattr__(self, "frf", h)
        object.__setattr__(self, "frf_type", check_frf_type(self.frf_type, file=self.source))
        if self.coherence is not None:
            c = np.asarray(self.coherence, dtype=float)
            if c.shape != h.shape:
                raise DataError("coherence has the wrong shape", file=self.source,
                                field="coherence", value=f"shape {c.shape}",
                                expected=f"shape {h.shape} like the FRF")
            object.__setattr__(self, "coherence", c)
        no, ni = h.shape[:2]
        on = tuple(self.output_names) or tuple(f"o{k + 1}" for k in range(no))
        inn = tuple(self.input_names) or tuple(f"i{k + 1}" for k in range(ni))
        if len(on) != no or len(inn) != ni:
            raise DataError("channel names do not match the FRF shape", file=self.source,
                            field="output_names/input_names",
                            value=f"{len(on)} outputs, {len(inn)} inputs",
                            expected=f"{no} output names and {ni} input names")
        object.__setattr__(self, "output_names", on)
        object.__setattr__(self, "input_names", inn)
        for name, dofs, n in (("output_dofs", self.output_dofs, no),
                              ("input_dofs", self.input_dofs, ni)):
            t = tuple((int(a), int(b)) for a, b in dofs)
            if t and len(t) != n:
                raise DataError("DOF list does not match the FRF shape", file=self.source,
                                field=name, value=len(t), expected=f"{n} (node, direction) pairs")
            object.__setattr__(self, name, t)
        if self.exp_window_tau_s is not None and not (self.exp_window_tau_s > 0):
            raise InputError("exponential window time constant must be > 0",
                             field="exp_window_tau_s", value=self.exp_window_tau_s,
                             expected="tau > 0 s")

    @property
    def n_outputs(self) -> int:
        return self.frf.shape[0]

    @property
    def n_inputs(self) -> int:
        return self.frf.shape[1]

    def driving_points(self) -> list[tuple[int, int]]:
        """``(output_index, input_index)`` pairs measured at the same node and direction
        (from the DOFs; empty when the DOFs are unknown)."""
        if not self.output_dofs or not self.input_dofs:
            return []
        return [(self.output_dofs.index(d), j) for j, d in enumerate(self.input_dofs)
                if d in self.output_dofs]

    def band(self, lo_Hz: float | None, hi_Hz: float | None) -> FRFData:
        """The lines in ``[lo_Hz, hi_Hz]``; raises InputError when the band is outside."""
        f = self.frequency_Hz
        lo = float(f[0]) if lo_Hz is None else float(lo_Hz)
        hi = float(f[-1]) if hi_Hz is None else float(hi_Hz)
        if not (np.isfinite(lo) and np.isfinite(hi)) or hi <= lo:
            raise InputError("frequency band must have LO < HI", field="band_Hz",
                             value=(lo, hi), expected="LO < HI in Hz")
        tol = 0.5 * float(np.min(np.diff(f)))
        if lo < f[0] - tol or hi > f[-1] + tol:
            what = "is outside" if (lo >= f[-1] or hi <= f[0]) else "extends beyond"
            raise InputError(f"frequency band {what} the data", field="band_Hz",
                             value=(lo, hi),
                             expected=f"a band inside [{f[0]:g}, {f[-1]:g}] Hz")
        m = (f >= lo) & (f <= hi)
        if m.sum() < 8:
            raise InputError("frequency band holds fewer than 8 frequency lines",
                             field="band_Hz", value=(lo, hi),
                             expected=f"a wider band (line spacing {np.median(np.diff(f)):g} Hz)")
        return replace(self, frequency_Hz=f[m], frf=self.frf[:, :, m],
                       coherence=None if self.coherence is None else self.coherence[:, :, m])

    def as_type(self, frf_type: str) -> FRFData:
        """Convert between accelerance / mobility / receptance (H_acc = (jw)^2 H_rec)."""
        h = convert_frf(self.frf, self.frequency_Hz, self.frf_type, frf_type)
        return replace(self, frf=h, frf_type=frf_type)

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {
            "frequency_Hz": self.frequency_Hz.tolist(),
            "frf_re": self.frf.real.tolist(), "frf_im": self.frf.imag.tolist(),
            "frf_type": self.frf_type,
            "output_names": list(self.output_names), "input_names": list(self.input_names),
            "exp_window_tau_s": self.exp_window_tau_s,
            "output_dofs": [list(d) for d in self.output_dofs],
            "input_dofs": [list(d) for d in self.input_dofs],
        }
        if self.coherence is not None:
            d["coherence"] = self.coherence.tolist()
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> FRFData:
        return cls(np.asarray(d["frequency_Hz"], float),
                   np.asarray(d["frf_re"]) + 1j * np.asarray(d["frf_im"]),
                   d.get("frf_type", "accelerance"),
                   None if d.get("coherence") is None else np.asarray(d["coherence"]),
                   tuple(d.get("output_names", ())), tuple(d.get("input_names", ())),
                   d.get("exp_window_tau_s"), None,
                   tuple(tuple(x) for x in d.get("output_dofs", ())),
                   tuple(tuple(x) for x in d.get("input_dofs", ())))


def convert_frf(frf: np.ndarray, frequency_Hz: np.ndarray, from_type: str,
                to_type: str) -> np.ndarray:
    """Convert FRFs between types: multiply by ``(j w)^(p_to - p_from)``.

    Powers: receptance 0, mobility 1, accelerance 2. Dividing at 0 Hz gives inf, so a
    conversion that divides requires all frequencies > 0 (InputError otherwise).
    """
    a, b = check_frf_type(from_type), check_frf_type(to_type)
    k = FRF_POWER[b] - FRF_POWER[a]
    jw = 2j * np.pi * np.asarray(frequency_Hz, float)
    if k < 0 and np.any(jw == 0):
        raise InputError("cannot convert at 0 Hz (division by j*omega)", field="frequency_Hz",
                         value=0.0, expected=f"frequencies > 0 Hz to convert {a} to {b}")
    return np.asarray(frf) * jw ** k


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
    sff = np.zeros((ni, nf))
    sfa = np.zeros((no, ni, nf), complex)
    saa = np.zeros((no, ni, nf))
    checks: list[HitCheck] = []
    used = np.zeros(ni, int)
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
            sff[i] += np.abs(F) ** 2
            sfa[:, i] += np.conj(F)[None, :] * A
            saa[:, i] += np.abs(A) ** 2
            used[i] += 1
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
    freq = np.fft.rfftfreq(n, 1.0 / fs)
    # lines where the force has no energy (e.g. exactly at a zero of the pulse spectrum)
    # cannot be estimated: report them instead of returning NaN
    good = np.isfinite(h).all(axis=(0, 1)) & (sff.min(axis=0) > 0)
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
    return FRFEstimate(data, tuple(checks), used, decay)


__all__ = [
    "FRF_TYPES", "FRF_POWER", "FRF_UNITS", "FRFData", "HammerRecords", "HitCheck",
    "FRFEstimate",
    "DoubleHitWarning", "LeakageWarning", "record_decay_ratio", "estimate_frf", "convert_frf",
    "check_hit", "force_window",
    "exponential_window", "check_frequencies", "check_frf_array",
]
