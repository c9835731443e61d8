"""Modal identification pipeline and its result contract.

``identify_modes(frf_data, ...)``: band -> CMIF -> pLSCF (all orders) -> stabilisation
diagram -> automatic pole selection -> LSFD (shapes, residues, residuals, fit) ->
:class:`ModalResult`.

:class:`ModalResult` is what the equivalent-model stage consumes: modes sorted by frequency
with natural frequency (Hz, undamped), damping ratio, MPC, complex mode shape (normalised),
participation vector, receptance residues ``(n_outputs, n_inputs)`` in m/N/s (physically
scaled), and a ``direction`` hint (the input whose residues dominate). For a driving point
(output ``o`` measured at the same point and direction as input ``j``) and a lightly damped
real mode, the effective modal mass is ``m = 1 / (2 w_d (-Im R_oj))`` (kg) and the modal
stiffness ``k = m w_n^2`` (N/m): see :meth:`Mode.driving_point_mass_kg`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from robobore.errors import InputError
from robobore.modal.cmif import CMIF, cmif
from robobore.modal.frf import FRFData, FRFEstimate, HammerRecords
from robobore.modal.lsfd import LSFDResult, lsfd, mpc, normalise_shape
from robobore.modal.plscf import PLSCFResult, plscf
from robobore.modal.stabilization import StabilisationDiagram, select_poles, stabilisation


def _cplx(v: Any) -> np.ndarray:
    a = np.asarray(v)
    if a.dtype == object or (a.size and isinstance(a.flat[0], dict)):
        return np.vectorize(lambda d: complex(d["re"], d["im"]), otypes=[complex])(a)
    return a.astype(complex)


def _cplx_list(a: np.ndarray) -> Any:
    return np.vectorize(lambda z: {"re": float(z.real), "im": float(z.imag)},
                        otypes=[object])(np.asarray(a)).tolist()


def _axis_of(name: str) -> str | None:
    """``x``/``y``/``z`` when an input name is, or ends in, one of them."""
    n = name.strip().lower()
    if n in ("x", "y", "z"):
        return n
    if len(n) >= 2 and n[-1] in "xyz" and n[-2] in "_-+ .":
        return n[-1]
    return None


@dataclass(frozen=True)
class Mode:
    """One identified mode.

    frequency_Hz: undamped natural frequency ``|lambda| / 2 pi``; damping_ratio:
    ``-Re(lambda)/|lambda|``; mpc in [0, 1]; mode_shape ``(n_outputs,)`` complex, largest
    entry 1; participation ``(n_inputs,)`` complex unit vector; residues ``(n_outputs,
    n_inputs)`` complex receptance residues (m/N/s); dominant_input: name of the input whose
    residues are largest; direction: its axis letter ``x``/``y``/``z`` when the input name
    ends in one (``hammer_x`` -> ``x``; the equivalent-model stage assigns modes to axes by
    it), else None; input_weights: the share of each input in the residue norm (sums to 1);
    modal_mass_kg: effective modal mass per input name at its driving point (when the DOFs
    tell which output is measured at the hammer point and direction; mass-line not reached
    or out-of-phase residues give no entry).
    """

    frequency_Hz: float
    damping_ratio: float
    mpc: float
    mode_shape: np.ndarray
    participation: np.ndarray
    residues: np.ndarray
    dominant_input: str
    direction: str | None = None
    input_weights: tuple[float, ...] = ()
    cluster_size: int = 0
    cmif_support: float = 0.0
    modal_mass_kg: dict[str, float] = field(default_factory=dict)

    @property
    def pole(self) -> complex:
        wn = 2 * np.pi * self.frequency_Hz
        return complex(-self.damping_ratio * wn, wn * np.sqrt(1 - self.damping_ratio**2))

    @property
    def damped_frequency_Hz(self) -> float:
        return self.frequency_Hz * float(np.sqrt(1 - self.damping_ratio**2))

    def driving_point_mass_kg(self, output_index: int, input_index: int) -> float:
        """Effective modal mass (kg) at a driving point (see module docstring)."""
        r = self.residues[output_index, input_index]
        wd = 2 * np.pi * self.damped_frequency_Hz
        v = -float(np.imag(r))
        return float("inf") if v <= 0 else 1.0 / (2 * wd * v)

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {"frequency_Hz": self.frequency_Hz,
                             "damping_ratio": self.damping_ratio, "mpc": self.mpc}
        if self.direction is not None:
            d["direction"] = self.direction
        return d | {"damped_frequency_Hz": self.damped_frequency_Hz,
                "dominant_input": self.dominant_input,
                "input_weights": list(self.input_weights), "cluster_size": self.cluster_size,
                "cmif_support": self.cmif_support,
                "modal_mass_kg": dict(self.modal_mass_kg),
                "modal_stiffness_N_per_m": {k: v * (2 * np.pi * self.frequency_Hz) ** 2
                                            for k, v in self.modal_mass_kg.items()},
                "mode_shape": _cplx_list(self.mode_shape),
                "participation": _cplx_list(self.participation),
                "residues": _cplx_list(self.residues)}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Mode:
        return cls(float(d["frequency_Hz"]), float(d["damping_ratio"]), float(d["mpc"]),
                   _cplx(d["mode_shape"]), _cplx(d["participation"]), _cplx(d["residues"]),
                   str(d.get("dominant_input", "")), d.get("direction"),
                   tuple(float(v) for v in d.get("input_weights", ())),
                   int(d.get("cluster_size", 0)),
                   float(d.get("cmif_support", 0.0)),
                   {str(k): float(v) for k, v in (d.get("modal_mass_kg") or {}).items()
                    if v is not None})


@dataclass(frozen=True)
class ModalResult:
    """Identified modes (sorted by frequency) and how they were obtained."""

    modes: tuple[Mode, ...]
    output_names: tuple[str, ...]
    input_names: tuple[str, ...]
    frf_type: str
    band_Hz: tuple[float, float]
    max_order: int
    stabilisation: dict[str, Any]
    fit_percent: np.ndarray  # (n_outputs, n_inputs)
    exp_window_tau_s: float | None = None
    source: str | None = None
    timings_s: dict[str, float] = field(default_factory=dict)

    @property
    def frequencies_Hz(self) -> np.ndarray:
        return np.array([m.frequency_Hz for m in self.modes])

    @property
    def damping_ratios(self) -> np.ndarray:
        return np.array([m.damping_ratio for m in self.modes])

    def to_dict(self) -> dict[str, Any]:
        return {"modes": [m.to_dict() for m in self.modes],
                "output_names": list(self.output_names), "input_names": list(self.input_names),
                "frf_type": self.frf_type, "band_Hz": list(self.band_Hz),
                "max_order": self.max_order, "stabilisation": self.stabilisation,
                "fit_percent": np.asarray(self.fit_percent).tolist(),
                "exp_window_tau_s": self.exp_window_tau_s, "source": self.source,
                "timings_s": dict(self.timings_s)}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> ModalResult:
        return cls(tuple(Mode.from_dict(m) for m in d["modes"]),
                   tuple(d.get("output_names", ())), tuple(d.get("input_names", ())),
                   d.get("frf_type", "accelerance"), tuple(d.get("band_Hz", (0.0, 0.0))),
                   int(d.get("max_order", 0)), dict(d.get("stabilisation", {})),
                   np.asarray(d.get("fit_percent", []), float), d.get("exp_window_tau_s"),
                   d.get("source"), dict(d.get("timings_s", {})))


@dataclass(frozen=True)
class ModalAnalysis:
    """Everything computed on the way (for plots and diagnostics) plus the result."""

    result: ModalResult
    data: FRFData  # band-limited FRFs
    cmif: CMIF
    plscf: PLSCFResult
    diagram: StabilisationDiagram
    lsfd: LSFDResult


def _frf_arg(data: Any) -> FRFData:
    """The FRFs of ``data``: an FRFData, or an FRFEstimate's ``frf``; else InputError."""
    if isinstance(data, FRFData):
        return data
    if isinstance(data, FRFEstimate):
        return data.frf
    hint = (" (time records: estimate the FRFs first, robobore.modal.estimate_frf)"
            if isinstance(data, HammerRecords) else "")
    raise InputError(f"not FRFs{hint}", field="data", value=type(data).__name__,
                     expected="an FRFData or the FRFEstimate of estimate_frf")


def identify_modes(data: FRFData, *, band_Hz: tuple[float, float] | None = None,
                   n_modes: int | None = None, approx_Hz: list[float] | None = None,
                   max_order: int = 40, min_order: int = 1, freq_tol: float = 0.01,
                   damp_tol: float = 0.05, mac_tol: float = 0.98,
                   min_fraction: float = 0.3) -> ModalAnalysis:
    """Identify modes from FRFs automatically.

    Parameters
    ----------
    data: FRFs ``(n_outputs, n_inputs, n_f)``: an :class:`FRFData` or the FRF stage's
        result (:class:`~robobore.modal.frf.FRFEstimate` of ``estimate_frf``; its ``frf``).
    band_Hz: analysis band ``(lo, hi)`` in Hz; default all lines > 0 Hz.
    n_modes: keep the ``n_modes`` best-supported modes; approx_Hz: or one mode near each
        of these frequencies (Hz); neither: every mode stable over ``min_fraction`` of the
        orders.
    max_order: highest pLSCF order (``max_order * n_inputs`` poles).
    freq_tol, damp_tol, mac_tol: stabilisation criteria.
    """
    data = _frf_arg(data)
    if approx_Hz is not None and n_modes is not None:
        raise InputError("give either a number of modes or approximate frequencies",
                         field="modes/approx_Hz", value=(n_modes, approx_Hz),
                         expected="one of the two")
    t0 = time.perf_counter()
    lo, hi = band_Hz if band_Hz is not None else (None, None)
    d = data.band(lo, hi)
    if d.frequency_Hz[0] == 0:
        d = d.band(float(d.frequency_Hz[1]), None)
    cm = cmif(d)
    t1 = time.perf_counter()
    res = plscf(d, None, max_order=max_order, min_order=min_order)
    t2 = time.perf_counter()
    diag = stabilisation(res, freq_tol, damp_tol, mac_tol)
    sel = select_poles(diag, n_modes=n_modes, approx_Hz=approx_Hz, min_fraction=min_fraction)
    t3 = time.perf_counter()
    poles = np.array([s.pole for s in sel])
    L = np.array([s.participation for s in sel]).reshape(len(sel), d.n_inputs)
    fit = lsfd(d, poles, L)
    t4 = time.perf_counter()
    c1 = cm.values[0]
    modes = []
    for k, s in enumerate(sel):
        R = fit.residues[:, :, k]
        share = np.linalg.norm(R, axis=0)
        share = share / (share.sum() or 1.0)
        dom = d.input_names[int(np.argmax(share))]
        mode = Mode(s.frequency_Hz, s.damping_ratio, 0.0, np.zeros(0), s.participation, R, dom)
        masses = {d.input_names[j]: mode.driving_point_mass_kg(o, j)
                  for o, j in d.driving_points()}
        modes.append(Mode(s.frequency_Hz, s.damping_ratio, mpc(fit.mode_shapes[:, k]),
                          normalise_shape(fit.mode_shapes[:, k]), s.participation, R,
                          dom, _axis_of(dom), tuple(float(v) for v in share), s.cluster_size,
                          float(cm.at(s.frequency_Hz)[0] / c1.max()),
                          {k: v for k, v in masses.items() if np.isfinite(v)}))
    summary = diag.summary()
    summary["selected"] = [{"frequency_Hz": s.frequency_Hz, "damping_ratio": s.damping_ratio,
                            "orders_stable": s.cluster_size,
                            "frequency_spread": s.frequency_spread,
                            "damping_spread": s.damping_spread} for s in sel]
    summary["cmif_peaks_Hz"] = cm.peaks_Hz.tolist()
    result = ModalResult(tuple(modes), d.output_names, d.input_names, d.frf_type,
                         res.band_Hz, max_order, summary, fit.fit_percent,
                         data.exp_window_tau_s, data.source,
                         {"cmif": t1 - t0, "plscf": t2 - t1, "stabilisation_selection": t3 - t2,
                          "lsfd": t4 - t3})
    return ModalAnalysis(result, d, cm, res, diag, fit)


__all__ = ["Mode", "ModalResult", "ModalAnalysis", "identify_modes"]
