"""Figures of the measure stage (matplotlib, Agg backend, PNG files)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from robobore.io.results import save_figure


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_spectrogram(det: Any, out_dir: str | Path, modes_Hz: tuple[float, ...] = (),
                     name: str = "chatter_spectrogram.png") -> Path:
    """Spectrogram (normalised power, dB) of the analysed channel with the spindle
    harmonics, the fixed lines, the modes and the chatter frequency marked; below it the
    chatter peak's energy share per window against the limit."""
    plt = _plt()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    sp = det.spectrogram
    f, t, P = sp["f"], sp["t"], sp["P"]
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(9, 7), sharex=True,
                                  gridspec_kw={"height_ratios": [3, 1]})
    db = 10 * np.log10(P.T + 1e-30)
    vmax = float(np.max(db))
    ax.pcolormesh(t, f, db, shading="nearest", vmin=vmax - 70, vmax=vmax, cmap="viridis")
    f0 = det.spindle_frequency_Hz
    if f0:
        for k in range(1, int(f[-1] / f0) + 1):
            if k > 60:
                break
            ax.axhline(k * f0, color="w", lw=0.3, alpha=0.5)
    for ln in det.fixed_lines_Hz:
        ax.axhline(ln, color="orange", lw=0.6, ls=":")
    for m in modes_Hz:
        ax.axhline(m, color="tab:red", lw=1.0, ls="--", label=f"mode {m:.4g} Hz")
    if det.chatter_frequency_Hz:
        ax.axhline(det.chatter_frequency_Hz, color="magenta", lw=1.0,
                   label=f"chatter {det.chatter_frequency_Hz:.5g} Hz")
    if det.onset_s is not None:
        ax.axvline(det.onset_s, color="magenta", lw=0.8, ls="--")
    ax.set_ylabel("frequency (Hz)")
    ax.set_title(f"{det.record.get('source')}: {'CHATTER' if det.chatter else 'stable'}"
                 f" (channel {det.channel}; white: spindle harmonics, orange: fixed lines)")
    if modes_Hz or det.chatter_frequency_Hz:
        ax.legend(loc="upper right", fontsize=8)
    sh = [w["peak_share"] for w in det.windows]
    ax2.plot(t, sh, "o-", ms=3)
    ax2.axhline(det.settings["share_limit"], color="tab:red", lw=0.8, ls="--")
    ax2.set_ylabel("peak energy share")
    ax2.set_xlabel("time (s)")
    ax2.set_ylim(0, 1)
    fig.tight_layout()
    path = save_figure(fig, out / name, dpi=110)
    plt.close(fig)
    return path


def plot_cut(record: Any, q: dict[str, Any], out_dir: str | Path, name: str) -> Path:
    """Force (and displacement) channels over time with the cutting part shaded, and the
    per-revolution force amplitudes."""
    plt = _plt()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(9, 6))
    t = record.t0_s + np.arange(record.n_samples) / record.sample_rate_Hz
    for i, c in enumerate(record.channels):
        if c.startswith("F"):
            ax.plot(t, record.signals[i], lw=0.5, label=c)
    a, b = q["cutting_time_s"]
    ax.axvspan(a, b, color="0.9", zorder=-1, label="cutting part")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("force (N)")
    ax.legend(fontsize=8)
    revs = q["per_revolution"]
    for ax_name in "xyz":
        key = f"force_amplitude_{ax_name}_N"
        if revs and key in revs[0]:
            ax2.plot([r["revolution"] for r in revs], [r[key] for r in revs], ".-",
                     label=f"F{ax_name} amplitude")
    ax2.set_xlabel("revolution")
    ax2.set_ylabel("half peak-to-peak (N)")
    ax2.legend(fontsize=8)
    fig.tight_layout()
    path = save_figure(fig, out / name, dpi=110)
    plt.close(fig)
    return path


__all__ = ["plot_spectrogram", "plot_cut"]
