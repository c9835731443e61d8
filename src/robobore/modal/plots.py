"""Plots of a modal analysis (matplotlib, Agg backend): FRF + fit + coherence, CMIF,
stabilisation diagram over the CMIF. Each function writes one PNG and returns its path."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from robobore.modal.frf_data import FRF_UNITS
from robobore.modal.identify import ModalAnalysis

_MARKERS = {0: ("o", "0.7", "new"), 1: ("x", "tab:orange", "f"), 2: ("d", "tab:blue", "f+d"),
            3: ("v", "tab:purple", "f+v"), 4: ("+", "tab:green", "stable")}


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, path: Path) -> Path:
    from robobore.io.results import save_figure

    path.parent.mkdir(parents=True, exist_ok=True)
    return save_figure(fig, path, dpi=110, bbox_inches="tight")


def plot_frf_fit(an: ModalAnalysis, path: str | Path, output: int = 0,
                 input: int = 0) -> Path:  # noqa: A002
    """Magnitude and phase of one FRF with the LSFD synthesis, and its coherence."""
    plt = _plt()
    d, fit = an.data, an.lsfd
    f = d.frequency_Hz
    keep = f > 0
    h = d.frf[output, input, keep]
    hs = fit.synthesised[output, input]
    nrow = 3 if d.coherence is not None else 2
    fig, ax = plt.subplots(nrow, 1, sharex=True, figsize=(8, 2.4 * nrow))
    ax[0].semilogy(f[keep], np.abs(h), "k", lw=1, label="measured")
    ax[0].semilogy(fit.frequency_Hz, np.abs(hs), "r--", lw=1,
                   label=f"synthesised (fit {fit.fit_percent[output, input]:.3f} %)")
    for m in an.result.modes:
        for a in ax:
            a.axvline(m.frequency_Hz, color="0.8", lw=0.6, zorder=0)
    ax[0].set_ylabel(f"|H| ({FRF_UNITS[d.frf_type]})")
    ax[0].legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    ax[0].set_title(f"FRF {d.output_names[output]} / {d.input_names[input]}")
    ax[1].plot(f[keep], np.degrees(np.angle(h)), "k", lw=1)
    ax[1].plot(fit.frequency_Hz, np.degrees(np.angle(hs)), "r--", lw=1)
    ax[1].set_ylabel("phase (deg)")
    if d.coherence is not None:
        ax[2].plot(f, d.coherence[output, input], "b", lw=1)
        ax[2].set_ylim(0, 1.05)
        ax[2].set_ylabel("coherence (-)")
    ax[-1].set_xlabel("frequency (Hz)")
    out = _save(fig, Path(path))
    plt.close(fig)
    return out


def plot_cmif(an: ModalAnalysis, path: str | Path) -> Path:
    """All CMIF curves with the identified modes marked."""
    plt = _plt()
    c = an.cmif
    fig, ax = plt.subplots(figsize=(8, 3.5))
    for k, v in enumerate(c.values):
        ax.semilogy(c.frequency_Hz, v, lw=1, label=f"CMIF {k + 1}")
    for m in an.result.modes:
        ax.axvline(m.frequency_Hz, color="r", lw=0.6, ls=":")
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel(f"singular value ({FRF_UNITS[an.data.frf_type]})")
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    ax.set_title("Complex mode indicator function")
    out = _save(fig, Path(path))
    plt.close(fig)
    return out


def plot_stabilisation(an: ModalAnalysis, path: str | Path) -> Path:
    """Stabilisation diagram (order vs frequency, symbols by status) over the CMIF."""
    plt = _plt()
    dg = an.diagram
    lo, hi = dg.band_Hz
    fig, ax = plt.subplots(figsize=(9, 5))
    m = (dg.frequency_Hz >= lo) & (dg.frequency_Hz <= hi) & (dg.damping_ratio > 0)
    for st, (mk, col, lab) in _MARKERS.items():
        s = m & (dg.status == st)
        ax.scatter(dg.frequency_Hz[s], dg.order[s], marker=mk, s=14 if st == 4 else 8,
                   c=col, label=lab, linewidths=0.8)
    for md in an.result.modes:
        ax.axvline(md.frequency_Hz, color="r", lw=0.8, ls="--")
    ax.set_xlim(lo, hi)
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("model order")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), fontsize=8, ncol=5)
    ax2 = ax.twinx()
    ax2.semilogy(an.cmif.frequency_Hz, an.cmif.values[0], "k", lw=0.8, alpha=0.6)
    if an.cmif.values.shape[0] > 1:
        ax2.semilogy(an.cmif.frequency_Hz, an.cmif.values[1], "0.5", lw=0.6, alpha=0.5)
    ax2.set_ylabel(f"CMIF, singular value ({FRF_UNITS[an.data.frf_type]})")
    ax.set_title("Stabilisation diagram (pLSCF) over the CMIF")
    out = _save(fig, Path(path))
    plt.close(fig)
    return out


def plot_all(an: ModalAnalysis, folder: str | Path) -> list[Path]:
    """Stabilisation diagram, CMIF and the driving-point (or first) FRFs with their fit."""
    folder = Path(folder)
    paths = [plot_stabilisation(an, folder / "stabilisation.png"),
             plot_cmif(an, folder / "cmif.png")]
    d = an.data
    for j in range(d.n_inputs):
        o = j if j < d.n_outputs else 0
        paths.append(plot_frf_fit(an, folder / f"frf_{d.output_names[o]}_{d.input_names[j]}.png",
                                  o, j))
    return paths


__all__ = ["plot_frf_fit", "plot_cmif", "plot_stabilisation", "plot_all"]


def plot_operational(result, path: str | Path) -> Path:
    """Stabilisation diagram of an output-only (SSI-COV) identification: every pole by
    order and status, the selected modes and the excluded rotation harmonics."""
    plt = _plt()
    dg = result.diagram
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for k, (mk, col, lab) in _MARKERS.items():
        m = dg.status == k
        if np.any(m):
            ax.scatter(dg.frequency_Hz[m], dg.order[m], marker=mk, s=14, c=col, label=lab,
                       linewidths=0.8)
    for i, md in enumerate(result.modes):
        ax.axvline(md.frequency_Hz, color="tab:red", lw=0.8,
                   label="selected" if i == 0 else None)
    for i, h in enumerate(result.harmonics):
        ax.axvline(h["frequency_Hz"], color="0.4", lw=0.8, ls=":",
                   label="rotation harmonic (excluded)" if i == 0 else None)
    ax.set_xlim(*result.band_Hz)
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("model order (modes)")
    ax.set_title("SSI-COV stabilisation diagram (output-only)")
    ax.legend(fontsize=7, loc="upper right")
    return _save(fig, Path(path))

