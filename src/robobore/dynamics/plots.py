"""Plots of the process stage (matplotlib, Agg backend, PNG files)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from robobore.io.results import save_figure


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_lobes(result, out_dir: str | Path, curves=None, title: str = "") -> Path:
    """Lobe diagram: critical depth [mm] vs spindle speed [r/min] (+ individual lobes)."""
    plt = _plt()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(8, 4.5))
    s = result.speed_rpm
    d = result.critical_depth_m * 1e3
    finite = np.isfinite(d)
    top = np.nanmax(d[finite]) * 1.2 if finite.any() else 1.0
    if np.isfinite(result.absolute_limit_m) and result.absolute_limit_m > 0:
        top = min(top, 8.0 * result.absolute_limit_m * 1e3)
    if curves:
        for n, b in curves:
            ok = (n >= s.min()) & (n <= s.max())
            ax.plot(n[ok], b[ok] * 1e3, color="0.8", lw=0.6)
    ax.fill_between(s, np.where(finite, d, top), top, color="tab:red", alpha=0.12,
                    label="unstable")
    ax.plot(s, np.where(finite, d, np.nan), color="tab:blue", lw=1.5,
            label=f"critical depth ({result.method})")
    if np.isfinite(result.absolute_limit_m):
        ax.axhline(result.absolute_limit_m * 1e3, color="k", ls="--", lw=0.8,
                   label=f"absolute limit {result.absolute_limit_m * 1e3:.4g} mm")
    ax.set_ylim(0, top)
    ax.set_xlim(s.min(), s.max())
    ax.set_xlabel("spindle speed [r/min]")
    ax.set_ylabel("depth of cut [mm]")
    ax.set_title(title or "stability lobes")
    ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    path = out / "lobes.png"
    save_figure(fig, path, dpi=120)
    plt.close(fig)
    return path


def plot_simulation(ds, out_dir: str | Path) -> list[Path]:
    """Forces, displacements, feed amplitude, surface profile and spectrum of a simulation."""
    plt = _plt()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    t = ds["time"].values
    paths = []
    fig, axs = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
    for i, a in enumerate("xyz"):
        axs[0].plot(t, ds["force"].values[:, i], lw=0.6, label=f"F{a}")
        axs[1].plot(t, ds["displacement"].values[:, i] * 1e6, lw=0.6, label=a)
    axs[0].set_ylabel("force on tool [N]")
    axs[1].set_ylabel("displacement [um]")
    axs[2].plot(t, ds["rotational_acceleration"].values[:, 0], lw=0.5, color="tab:purple")
    axs[2].set_ylabel("rotational acc. [m/s^2]")
    axs[2].set_xlabel("time [s]")
    for a in axs[:2]:
        a.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    fig.suptitle(f"n = {ds.attrs['speed_rpm']:.0f} r/min, a = {ds.attrs['depth_m'] * 1e3:.4g} mm")
    fig.tight_layout()
    p = out / "simulation_signals.png"
    save_figure(fig, p, dpi=110)
    plt.close(fig)
    paths.append(p)

    fig, axs = plt.subplots(1, 2, figsize=(10, 3.8))
    z = ds["surface_z"].values
    h = ds["surface_profile"].values
    ok = np.isfinite(h)
    if ok.sum() >= 3:  # the form (least-squares line) removed, as for Ra and Rz
        zc = z[ok] - z[ok].mean()
        res = h[ok] - np.polyval(np.polyfit(zc, h[ok], 1), zc)
        axs[0].plot((z[ok] - z[ok][0]) * 1e3, res * 1e6, lw=0.8)
    axs[0].set_xlabel("position along the feed [mm]")
    axs[0].set_ylabel("surface height, form removed [um]")
    axs[0].set_title(f"Ra = {ds.attrs['Ra_m'] * 1e6:.3g} um, Rz = {ds.attrs['Rz_m'] * 1e6:.3g} um "
                     f"(taper {ds.attrs.get('form_slope_um_per_mm', float('nan')):.3g} um/mm "
                     "removed)", fontsize=9)
    X = ds["displacement"].values
    n0 = int(0.7 * X.shape[0])
    x = X[n0:] - X[n0:].mean(axis=0)
    P = (np.abs(np.fft.rfft(x * np.hanning(x.shape[0])[:, None], axis=0)) ** 2).sum(axis=1)
    f = np.fft.rfftfreq(x.shape[0], float(ds.attrs["dt_s"]))
    axs[1].semilogy(f, P + 1e-300, lw=0.7)
    fmax = max(5 * float(ds.attrs["speed_rpm"]) / 60 * int(ds.attrs["n_inserts"]), 1.0)
    axs[1].set_xlim(0, fmax)
    axs[1].set_xlabel("frequency [Hz]")
    axs[1].set_ylabel("|FFT|^2 of displacement, Hann [m^2]")
    fig.tight_layout()
    p = out / "simulation_surface_spectrum.png"
    save_figure(fig, p, dpi=110)
    plt.close(fig)
    paths.append(p)
    return paths


__all__ = ["plot_lobes", "plot_simulation"]


def plot_band(band, out_dir: str | Path, nominal_m=None, observations=(),
              name: str = "lobes_band.png", title: str = "", truth_m=None) -> Path:
    """Lobes with their confidence band: the probability of chatter over speed x depth
    (shaded), the critical depth's 5/50/95 % and, when given, the nominal lobes, a SYNTHETIC
    truth's and the observed cuts (x chatter, o stable)."""
    plt = _plt()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(8, 4.5))
    s = band.speed_rpm
    dep = band.depth_m * 1e3
    pc = ax.pcolormesh(s, dep, band.p_chatter.T, cmap="Reds", vmin=0.0, vmax=1.0,
                       shading="nearest", alpha=0.6)
    fig.colorbar(pc, ax=ax, label="P(chatter)")
    ax.fill_between(s, band.lower_m * 1e3, band.upper_m * 1e3, color="tab:blue", alpha=0.2,
                    label="critical depth 5-95 %")
    ax.plot(s, band.median_m * 1e3, color="tab:blue", lw=1.5, label="critical depth 50 %")
    if nominal_m is not None:
        ax.plot(s, np.asarray(nominal_m) * 1e3, color="k", ls="--", lw=1.0,
                label="nominal model")
    if truth_m is not None:
        ax.plot(s, np.asarray(truth_m) * 1e3, color="tab:green", lw=1.2,
                label="SYNTHETIC truth")
    obs = list(observations)
    if obs:
        ch = [o for o in obs if o.chatter]
        st = [o for o in obs if not o.chatter]
        if ch:
            ax.plot([o.speed_rpm for o in ch], [o.depth_m * 1e3 for o in ch], "x",
                    color="darkred", ms=8, mew=2, label="observed: chatter")
        if st:
            ax.plot([o.speed_rpm for o in st], [o.depth_m * 1e3 for o in st], "o",
                    mfc="none", color="darkgreen", ms=7, mew=1.5, label="observed: stable")
    ax.set_yscale("log")
    ax.set_ylim(dep.min(), dep.max())
    ax.set_xlim(s.min(), s.max())
    ax.set_xlabel("spindle speed [r/min]")
    ax.set_ylabel("depth of cut [mm]")
    ax.set_title(title or f"stability lobes with the 90 % band ({band.source})")
    ax.legend(loc="lower right", fontsize=7)
    fig.tight_layout()
    path = out / name
    save_figure(fig, path, dpi=120)
    plt.close(fig)
    return path
