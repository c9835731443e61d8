"""The paper-like figures of the ``robobore paper`` report (:mod:`robobore.study.paper_report`).

Force over half a revolution; feed amplitude over time; force and feed amplitude against
speed, feed and depth for robot and machine tool; force and rotational acceleration as chatter
develops; machined surface, form removed; lobes with the swept conditions.

Point marks (:data:`MARKS`, every figure and the tables): red diamond = chatter (the
vibration grows); orange open square = rough only (Ra after form removal above the
tolerance without chatter: the paper's criterion calls it "vibratory"); black dot = neither.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from robobore.study.plots import MARKS as _ALL_MARKS
from robobore.study.plots import verdict_class

#: Marks of the paper report (every result there carries the verdicts by cause).
MARKS = {k: _ALL_MARKS[k] for k in ("ok", "rough", "chatter")}

_SYS_STYLE = {("robot", 0.0): ("robot, no foot", "tab:blue"),
              ("machine_tool", 0.0): ("machine tool (stiff, assumed)", "tab:green")}
_FACTORS = (("speed_rpm", "spindle speed n [r/min]"), ("feed_mm_per_rev", "feed f [mm/r]"),
            ("depth_of_cut_mm", "depth of cut ap [mm]"))


def pyplot() -> Any:
    """matplotlib.pyplot on the non-interactive Agg backend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def system_label(system: str, p: float) -> tuple[str, str]:
    """Legend label and colour of a simulated system at foot pressure ``p`` [MPa]."""
    if (system, p) in _SYS_STYLE:
        return _SYS_STYLE[(system, p)]
    return f"robot, foot {p:g} MPa", "tab:orange"


def fig_force_half_rev(ds: Any, title: str) -> Any:
    """Force components over the last half revolution (paper Fig. 7 kind)."""
    plt = pyplot()
    ns = int(ds.attrs["samples_per_rev"]) // int(ds.attrs.get("stored_time_stride", 1))
    F = np.asarray(ds["force"].values, float)
    n = F.shape[0]
    half = max(2, ns // 2)
    seg = F[n - half:]
    ang = np.linspace(0.0, 180.0, seg.shape[0], endpoint=False)
    fig, ax = plt.subplots(figsize=(7.4, 3.4))
    for i, (lab, c) in enumerate((("X horizontal", "tab:blue"), ("Y vertical", "tab:orange"),
                                  ("Z feed", "tab:green"))):
        ax.plot(ang, seg[:, i], color=c, label=lab)
    ax.set_xlabel("bar rotation over the last half revolution [deg]")
    ax.set_ylabel("force on the tool [N]")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    fig.tight_layout()
    return fig


def fig_feed_amplitude_time(items: list[tuple[str, Any]]) -> Any:
    """Feed-direction (Z) displacement over time (paper Fig. 8 kind)."""
    plt = pyplot()
    fig, axes = plt.subplots(len(items), 1, figsize=(6.4, 1.9 * len(items) + 0.6),
                             squeeze=False, sharex=False)
    for ax, (lab, ds) in zip(axes[:, 0], items, strict=True):
        z = np.asarray(ds["displacement"].values, float)[:, 2] * 1e6
        t = np.asarray(ds["time"].values, float)
        ax.plot(t, z, lw=0.6, color="tab:blue")
        ax.set_ylabel("feed-direction\ndisplacement Z [um]", fontsize=8)
        ax.set_title(lab, fontsize=8)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("time [s]")
    fig.tight_layout()
    return fig


def fig_trends(rows: list[dict[str, Any]], base: dict[str, float]) -> Any:
    """Average force amplitude and feed amplitude vs speed, feed, depth (paper Figs. 9-10).

    The feed amplitude spans many decades (a stiff machine tool's is 1e-7 um): it is drawn on
    a log axis; a value of exactly zero cannot be, and is drawn as a hollow triangle on the
    bottom edge (labelled "= 0")."""
    plt = pyplot()
    fig, axes = plt.subplots(2, 3, figsize=(13.0, 6.6))
    groups = sorted({(r["system"], r["pressure_MPa"]) for r in rows})
    zero_drawn = False
    for j, (f, flab) in enumerate(_FACTORS):
        others = [k for k, _ in _FACTORS if k != f]
        for i, (q, qlab) in enumerate((("force", "mean XY force amplitude [N]"),
                                       ("feed_amplitude_um", "feed amplitude [um] (log)"))):
            ax = axes[i, j]
            for g in groups:
                lab, col = system_label(*g)
                sel = sorted([r for r in rows if (r["system"], r["pressure_MPa"]) == g
                              and r.get("summary")
                              and all(math.isclose(r[o], base[o]) for o in others)],
                             key=lambda r: r[f])
                if not sel:
                    continue
                x = [r[f] for r in sel]
                if q == "force":
                    y = [0.5 * (r["summary"]["force_amplitude_x_N"]
                                + r["summary"]["force_amplitude_y_N"]) for r in sel]
                else:
                    y = [r["summary"]["feed_amplitude_um"] for r in sel]
                pos = [(a, b) for a, b in zip(x, y, strict=True) if q == "force" or b > 0]
                if pos:
                    ax.plot(*zip(*pos, strict=True), "-", color=col, lw=1.2,
                            label=lab if (i, j) == (0, 0) else None)
                for cls, (kw, _) in MARKS.items():
                    pts = [(a, b) for a, b, r in zip(x, y, sel, strict=True)
                           if verdict_class(r["summary"]) == cls and (q == "force" or b > 0)]
                    if pts:
                        ax.scatter(*zip(*pts, strict=True), zorder=3, **kw)
                zeros = [a for a, b in zip(x, y, strict=True) if q != "force" and b <= 0]
                if zeros:
                    zero_drawn = True
                    ax.scatter(zeros, [0.0] * len(zeros), marker="v", s=30, facecolors="none",
                               edgecolors=col, zorder=4, clip_on=False,
                               transform=ax.get_xaxis_transform())
            ax.set_xlabel(flab)
            ax.set_ylabel(qlab)
            if q == "feed_amplitude_um":
                ax.set_yscale("log")
            ax.grid(alpha=0.3, which="both" if q == "force" else "major")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    for kw, lab in MARKS.values():
        handles.append(axes[0, 0].scatter([], [], **kw))
        labels.append(lab)
    if zero_drawn:
        handles.append(axes[0, 0].scatter([], [], marker="v", s=30, facecolors="none",
                                          edgecolors="k"))
        labels.append("feed amplitude = 0 (bottom edge)")
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=8, frameon=False,
               bbox_to_anchor=(0.5, -0.01))
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    return fig


def fig_vibration_develops(ds: Any, title: str) -> Any:
    """Force and rotational acceleration over time for a vibratory cut (paper Fig. 11)."""
    plt = pyplot()
    t = np.asarray(ds["time"].values, float)
    F = np.asarray(ds["force"].values, float)
    fig, axes = plt.subplots(2, 1, figsize=(7.8, 4.6), sharex=True)
    for i, lab in enumerate(("X", "Y", "Z")):
        axes[0].plot(t, F[:, i], lw=0.6, label=lab)
    axes[0].set_ylabel("force on the tool [N]")
    axes[0].legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    axes[0].set_title(title, fontsize=9)
    if "rotational_acceleration" in ds:
        A = np.asarray(ds["rotational_acceleration"].values, float)
        names = [str(v) for v in ds["rot_axis"].values] if "rot_axis" in ds.coords else \
            ["radial", "tangential"]
        for i in range(A.shape[1]):
            axes[1].plot(t, A[:, i], lw=0.6, label=names[i])
        axes[1].legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0),
                       frameon=False)
    axes[1].set_ylabel("rotational acceleration [m/s^2]")
    axes[1].set_xlabel("time [s]")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def fig_surface(items: list[tuple[str, Any]]) -> Any:
    """Machined-surface profile along the bore axis after removing its form (least-squares
    line: offset and taper), as Ra is computed (paper Fig. 12 kind)."""
    from robobore.dynamics.timedomain import roughness

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.6, 3.4))
    for lab, ds in items:
        z = np.asarray(ds["surface_z"].values, float)
        r = np.asarray(ds["surface_profile"].values, float)
        ok = np.isfinite(r)
        if ok.sum() < 3:
            continue
        zc = z[ok] - z[ok].mean()
        coef = np.polyfit(zc, r[ok], 1)
        res = (r[ok] - np.polyval(coef, zc)) * 1e6
        ra = roughness(z, r)["Ra_m"] * 1e6
        ax.plot((z[ok] - z[ok][0]) * 1e3, res, lw=0.8,
                label=f"{lab}: Ra {ra:.3g} um (taper {coef[0] * 1e3:.3g} um/mm removed)")
    ax.set_xlabel("position along the bore axis [mm]")
    ax.set_ylabel("surface height, form removed [um]")
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.2), frameon=False)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def fig_lobes(lobes: dict[str, Any], rows: list[dict[str, Any]], base: dict[str, float]) -> Any:
    """Stability lobes (critical depth vs speed) with the swept conditions at the base feed."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(9.6, 4.0))
    cols = ["tab:blue", "tab:orange"]
    ymax = 0.0
    for (lab, d), c in zip(lobes.items(), cols, strict=False):
        n = np.asarray(d["speed_rpm"], float)
        a = np.asarray(d["critical_depth_mm"], float)
        ax.plot(n, a, color=c, lw=1.2, label=f"lobes, robot {lab} ({d.get('method', '')})")
        fin = a[np.isfinite(a)]
        if fin.size:
            ymax = max(ymax, float(np.percentile(fin, 90)))
    pts = [r for r in rows if r["system"] == "robot" and r.get("summary")
           and math.isclose(r["feed_mm_per_rev"], base["feed_mm_per_rev"])]
    sel = [r for r in pts if r["pressure_MPa"] == 0.0]
    for cls, (kw, lab) in MARKS.items():
        pc = [r for r in sel if verdict_class(r["summary"]) == cls]
        if pc:
            ax.scatter([r["speed_rpm"] for r in pc], [r["depth_of_cut_mm"] for r in pc],
                       zorder=3, label=f"swept, no foot: {lab}", **kw)
    dmax = max([r["depth_of_cut_mm"] for r in pts] + [0.0])
    ax.set_ylim(0, max(ymax, 1.3 * dmax, 1e-3))
    ax.set_xlabel("spindle speed n [r/min]")
    ax.set_ylabel("critical depth of cut [mm]")
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


__all__ = ["MARKS", "pyplot", "system_label", "fig_force_half_rev", "fig_feed_amplitude_time",
           "fig_trends", "fig_vibration_develops", "fig_surface", "fig_lobes"]
