"""FRF data: measured frequency response functions, their types, units and checks.

:class:`FRFData` holds FRFs ``(n_outputs, n_inputs, n_frequencies)`` (complex, response per
force) of one type (``receptance`` m/N, ``mobility`` m/s/N, ``accelerance`` m/s^2/N) on a
frequency axis in Hz, with optional coherence and (node, direction) DOFs; :func:`convert_frf`
changes the type. The estimation from hammer time records is :mod:`robobore.modal.frf`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from robobore.errors import DataError, InputError

FRF_TYPES = ("accelerance", "mobility", "receptance")
RESPONSE_QUANTITIES = {"acceleration": "accelerance", "velocity": "mobility",
                       "displacement": "receptance"}
#: power of j*omega in each FRF type (receptance 0, mobility 1, accelerance 2)
FRF_POWER = {"receptance": 0, "mobility": 1, "accelerance": 2}
FRF_UNITS = {"receptance": "m/N", "mobility": "m/s/N", "accelerance": "m/s^2/N"}


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


__all__ = [
    "FRF_TYPES", "FRF_UNITS", "FRF_POWER", "RESPONSE_QUANTITIES", "FRFData", "convert_frf",
    "check_frequencies", "check_frf_array", "check_frf_type",
]
