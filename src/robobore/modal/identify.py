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

import dataclasses
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from robobore.errors import IdentificationError, InputError
from robobore.modal.cmif import CMIF, cmif
from robobore.modal.frf import FRFEstimate, HammerRecords
from robobore.modal.frf_data import FRFData
from robobore.modal.lsfd import LSFDResult, lsfd, modal_peak_compliance, mpc, normalise_shape
from robobore.modal.plscf import PLSCFResult, plscf
from robobore.modal.stabilization import (
    SelectedPole,
    StabilisationDiagram,
    pole_clusters,
    select_poles,
    stabilisation,
    support_needed,
)


def _cplx(v: Any) -> np.ndarray:
    a = np.asarray(v)
    if a.dtype == object or (a.size and isinstance(a.flat[0], dict)):
        return np.vectorize(lambda d: complex(d["re"], d["im"]), otypes=[complex])(a)
    return a.astype(complex)


def _cplx_list(a: np.ndarray) -> Any:
    return np.vectorize(lambda z: {"re": float(z.real), "im": float(z.imag)},
                        otypes=[object])(np.asarray(a)).tolist()


def _uncertainty_of(d: Any) -> Any:
    if not d:
        return None
    from robobore.modal.uncertainty import ModeUncertainty

    return ModeUncertainty.from_dict(d)


def _opt_float(v: Any) -> float | None:
    return None if v is None else float(v)


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
    or out-of-phase residues give no entry). share: the mode's share of the rank point's
    modal peak compliance (see :func:`identify_modes`), share_point: that FRF
    (``output/input``), peak_compliance_m_per_N: the mode's own receptance peak there.
    uncertainty: standard deviations and 95 % intervals of frequency, damping (and, from
    hits, shape) (:class:`~robobore.modal.uncertainty.ModeUncertainty`).
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
    share: float | None = None
    share_point: str | None = None
    peak_compliance_m_per_N: float | None = None
    uncertainty: Any = None  # ModeUncertainty (robobore.modal.uncertainty) or None

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
                "share": self.share, "share_point": self.share_point,
                "peak_compliance_m_per_N": self.peak_compliance_m_per_N,
                "uncertainty": (None if self.uncertainty is None
                                else self.uncertainty.to_dict()),
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
                    if v is not None},
                   _opt_float(d.get("share")), d.get("share_point"),
                   _opt_float(d.get("peak_compliance_m_per_N")),
                   _uncertainty_of(d.get("uncertainty")))


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


SELECT_MODES = ("dominant", "lowest", "stable")
#: the clustering's frequency width (stabilization.pole_clusters' cluster_freq_tol)
DEDUPE_FREQ_TOL = 0.005


def rank_pairs(data: FRFData, point: str | None = None
               ) -> tuple[list[tuple[int, int]], bool, str]:
    """The FRFs ``(output, input)`` a mode's share is measured at, whether a mode's share is
    its largest over them (always, here) and how they were chosen: ``point`` (an output name:
    its FRFs to every input), else the driving points from the DOFs (same node and
    direction, or the same node and opposite direction sign), else the most compliant output
    (largest mean |H| over the band and the inputs: under a hammer at the tool, the tool
    point)."""
    if point is not None:
        if point not in data.output_names:
            raise InputError("unknown rank point", field="point", value=point,
                             expected="one of the outputs: " + ", ".join(data.output_names))
        o = data.output_names.index(point)
        return [(o, j) for j in range(data.n_inputs)], True, point
    dp = data.driving_points()
    if dp:
        return dp, True, "driving points"
    if data.output_dofs and data.input_dofs:
        ab = [(n, abs(d)) for n, d in data.output_dofs]
        dp = [(ab.index((n, abs(d))), j) for j, (n, d) in enumerate(data.input_dofs)
              if (n, abs(d)) in ab]
        if dp:
            return dp, True, "driving points (direction sign ignored)"
    o = int(np.argmax(np.mean(np.abs(data.frf), axis=(1, 2))))
    return ([(o, j) for j in range(data.n_inputs)], True,
            f"most compliant output ({data.output_names[o]})")


def mode_shares(fit: LSFDResult, poles: np.ndarray, pairs: list[tuple[int, int]],
                best: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each mode's share of the modal peak compliance at the rank FRFs -> ``(share,
    peak m/N, index of the pair)`` per mode.

    At one FRF the share of mode ``m`` is ``P_m / sum_k P_k`` with ``P`` the modes' own
    receptance peaks (:func:`~robobore.modal.lsfd.modal_peak_compliance`); with
    ``best`` a mode's share is its largest over the pairs, else the share of the peaks
    summed over all pairs (pair index -1)."""
    P = modal_peak_compliance(fit.residues, poles)  # (no, ni, nm)
    Pp = np.array([P[o, j] for o, j in pairs])  # (n_pairs, nm)
    if best:
        tot = Pp.sum(axis=1, keepdims=True)
        sh = Pp / np.where(tot > 0, tot, 1.0)
        k = np.argmax(sh, axis=0)
        nm = Pp.shape[1]
        return sh[k, np.arange(nm)], Pp[k, np.arange(nm)], k
    tot = Pp.sum(axis=0)
    return tot / (tot.sum() or 1.0), Pp.max(axis=0), np.full(Pp.shape[1], -1)


def identify_modes(data: FRFData, *, band_Hz: tuple[float, float] | None = None,
                   n_modes: int | None = None, approx_Hz: list[float] | None = None,
                   select: str = "dominant", point: str | None = None,
                   uncertainty: bool = True,
                   max_order: int = 40, min_order: int = 1, freq_tol: float = 0.01,
                   damp_tol: float = 0.05, mac_tol: float = 0.98,
                   min_fraction: float = 0.3) -> ModalAnalysis:
    """Identify modes from FRFs automatically.

    Parameters
    ----------
    data: FRFs ``(n_outputs, n_inputs, n_f)``: an :class:`FRFData` or the FRF stage's
        result (:class:`~robobore.modal.frf.FRFEstimate` of ``estimate_frf``; its ``frf``).
    band_Hz: analysis band ``(lo, hi)`` in Hz; default all lines > 0 Hz.
    n_modes: keep ``n_modes`` modes, chosen by ``select`` among the physical modes (pole
        clusters stable over ``min_fraction`` of the orders; when fewer, the next
        best-supported clusters fill up): ``"dominant"`` the modes with the largest share of
        the rank point's compliance (:func:`mode_shares`), ``"lowest"`` the lowest in
        frequency, ``"stable"`` the best-supported in the diagram. approx_Hz: or one mode
        near each of these frequencies (Hz); neither: every physical mode.
    point: output name whose FRFs rank the modes (default: the driving points from the
        DOFs, else all FRFs).
    uncertainty: 95 % intervals of every mode (:mod:`robobore.modal.uncertainty`): with an
        FRFEstimate (time records) by the jackknife over hits, with FRFs alone by a wild
        bootstrap of the residuals of the fit with every physical mode.
    max_order: highest pLSCF order (``max_order * n_inputs`` poles).
    freq_tol, damp_tol, mac_tol: stabilisation criteria.
    """
    est = data if isinstance(data, FRFEstimate) and data.per_hit is not None else None
    data = _frf_arg(data)
    if approx_Hz is not None and n_modes is not None:
        raise InputError("give either a number of modes or approximate frequencies",
                         field="modes/approx_Hz", value=(n_modes, approx_Hz),
                         expected="one of the two")
    if select not in SELECT_MODES:
        raise InputError("unknown mode selection", field="select", value=select,
                         expected="one of " + ", ".join(SELECT_MODES))
    if n_modes is not None and n_modes < 1:
        raise InputError("number of modes must be >= 1", field="modes", value=n_modes,
                         expected="an integer >= 1")
    t0 = time.perf_counter()
    lo, hi = band_Hz if band_Hz is not None else (None, None)
    d = data.band(lo, hi)
    if d.frequency_Hz[0] == 0:
        d = d.band(float(d.frequency_Hz[1]), None)
    pairs, best, rank_label = rank_pairs(d, point)
    cm = cmif(d)
    t1 = time.perf_counter()
    res = plscf(d, None, max_order=max_order, min_order=min_order)
    t2 = time.perf_counter()
    diag = stabilisation(res, freq_tol, damp_tol, mac_tol)
    need = support_needed(diag, min_fraction)
    clusters = pole_clusters(diag)
    physical = [c for c in clusters if c.cluster_size >= need]
    if n_modes is None:
        sel = select_poles(diag, approx_Hz=approx_Hz, min_fraction=min_fraction)
        pool = physical + [c for c in sel if all(c.pole != p.pole for p in physical)]
    else:
        # one cluster per mode: a mode whose damping scatters over the orders can leave two
        # clusters at one frequency, whose LSFD columns are nearly collinear (large residues
        # of opposite sign); within 2 cluster widths in frequency the better-supported stays
        uniq: list[SelectedPole] = []
        for c in physical:  # best-supported first
            if all(abs(c.frequency_Hz / u.frequency_Hz - 1) >= 2 * DEDUPE_FREQ_TOL
                   for u in uniq):
                uniq.append(c)
        physical = uniq
        pool = physical + [c for c in clusters if c.cluster_size < need][
            : max(0, n_modes - len(physical))]
        if len(pool) < n_modes:
            raise IdentificationError(
                f"asked for {n_modes} modes but the diagram has only {len(pool)} stable "
                "pole clusters: raise --max-order or check the band")
        sel = []
    pool.sort(key=lambda c: c.frequency_Hz)

    def fit_of(ps: list[SelectedPole]) -> LSFDResult:
        return lsfd(d, np.array([p.pole for p in ps]),
                    np.array([p.participation for p in ps]).reshape(len(ps), d.n_inputs))

    pool_fit = fit_of(pool)
    pool_poles = np.array([p.pole for p in pool])
    share, peak, where = mode_shares(pool_fit, pool_poles, pairs, best)
    if n_modes is not None:
        if select == "dominant":
            order = np.argsort(-share, kind="stable")
        elif select == "lowest":
            order = np.arange(len(pool))
        else:
            order = np.argsort([-c.cluster_size for c in pool], kind="stable")
        sel = sorted((pool[i] for i in order[:n_modes]), key=lambda c: c.frequency_Hz)
    t3 = time.perf_counter()
    # shapes and residues of the selected modes from the fit with every physical mode: the
    # modes left out of the selection are still in the data (lower/upper residuals do not
    # take in-band modes)
    fit = pool_fit
    t4 = time.perf_counter()
    c1 = cm.values[0]
    modes = []
    for s in sel:
        i = next(i for i, c in enumerate(pool) if c.pole == s.pole)
        o_j = pairs[where[i]] if where[i] >= 0 else None
        R = fit.residues[:, :, i]
        w_in = np.linalg.norm(R, axis=0)
        w_in = w_in / (w_in.sum() or 1.0)
        dom = d.input_names[int(np.argmax(w_in))]
        mode = Mode(s.frequency_Hz, s.damping_ratio, 0.0, np.zeros(0), s.participation, R, dom)
        masses = {d.input_names[j]: mode.driving_point_mass_kg(o, j)
                  for o, j in d.driving_points()}
        modes.append(Mode(s.frequency_Hz, s.damping_ratio, mpc(fit.mode_shapes[:, i]),
                          normalise_shape(fit.mode_shapes[:, i]), s.participation, R,
                          dom, _axis_of(dom), tuple(float(v) for v in w_in), s.cluster_size,
                          float(cm.at(s.frequency_Hz)[0] / c1.max()),
                          {k: v for k, v in masses.items() if np.isfinite(v)},
                          float(share[i]),
                          (f"{d.output_names[o_j[0]]}/{d.input_names[o_j[1]]}" if o_j
                           else "all"), float(peak[i])))
    summary = diag.summary()
    summary["selected"] = [{"frequency_Hz": s.frequency_Hz, "damping_ratio": s.damping_ratio,
                            "orders_stable": s.cluster_size,
                            "frequency_spread": s.frequency_spread,
                            "damping_spread": s.damping_spread,
                            "orders": list(s.orders)} for s in sel]
    summary["physical_modes"] = [
        {"frequency_Hz": c.frequency_Hz, "damping_ratio": c.damping_ratio,
         "orders_stable": c.cluster_size, "share": float(share[i]),
         "selected": any(c.pole == s.pole for s in sel)} for i, c in enumerate(pool)]
    summary["selection"] = {"select": select if n_modes is not None else
                            ("approx_Hz" if approx_Hz else "all"),
                            "orders_needed": need,
                            "rank_point": rank_label}
    summary["cmif_peaks_Hz"] = cm.peaks_Hz.tolist()
    timings = {"cmif": t1 - t0, "plscf": t2 - t1, "stabilisation_selection": t3 - t2,
               "lsfd": t4 - t3}
    result = ModalResult(tuple(modes), d.output_names, d.input_names, d.frf_type,
                         res.band_Hz, max_order, summary, fit.fit_percent,
                         data.exp_window_tau_s, data.source, timings)
    an = ModalAnalysis(result, d, cm, res, diag, fit)
    if uncertainty and est is not None:
        from robobore.modal.uncertainty import jackknife_over_hits

        unc, info = jackknife_over_hits(est, an)
        summary["uncertainty"] = info
        timings["uncertainty"] = info["time_s"]
        result = dataclasses.replace(result, modes=tuple(
            dataclasses.replace(m, uncertainty=u) for m, u in zip(modes, unc, strict=True)))
        an = dataclasses.replace(an, result=result)
    elif uncertainty:
        from robobore.modal.uncertainty import bootstrap_residuals

        unc, info = bootstrap_residuals(d, pool_fit.synthesised, an)
        summary["uncertainty"] = info
        timings["uncertainty"] = info["time_s"]
        result = dataclasses.replace(result, modes=tuple(
            dataclasses.replace(m, uncertainty=u) for m, u in zip(modes, unc, strict=True)))
        an = dataclasses.replace(an, result=result)
    return an


__all__ = ["Mode", "ModalResult", "ModalAnalysis", "identify_modes", "mode_shares", "rank_pairs",
           "SELECT_MODES"]
