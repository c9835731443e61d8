"""Posture-plan figures: criterion vs tool-axis rotation per branch, lobes, workspace map."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from robobore.plan.results import PostureResult

CRITERION_LABEL = {"critical_depth": "critical depth at the cutting speed [mm]",
                   "stiffness_x": "stiffness along X (horizontal) [N/µm]",
                   "stiffness_y": "stiffness along Y [N/µm]",
                   "stiffness_z": "stiffness along Z (feed) [N/µm]",
                   "stiffness_min": "smallest of the X, Y, Z stiffnesses [N/µm]"}


def _scale(name: str) -> float:
    return 1.0 if name == "critical_depth" else 1e-6


def plot_rotation_map(result: PostureResult, ax: Any) -> None:
    """Criterion vs tool-axis rotation, one line per IK branch; recommended (star) and
    measured (diamond) postures marked."""
    from robobore.plan.ik import branch_label

    A = result.arrays
    cand, crit = A.cand, A.criterion * _scale(result.criterion)
    for b in np.unique(cand.branch):
        m = cand.branch == b
        o = np.argsort(cand.rotation_deg[m])
        ax.plot(cand.rotation_deg[m][o], crit[m][o], ".", ms=2.5,
                label=f"branch {b} ({branch_label(int(b))})")
    i = A.best
    ax.plot(cand.rotation_deg[i], crit[i], "*", ms=14, color="k", mfc="gold",
            label="recommended")
    if A.measured is not None:
        j = A.measured
        ax.plot(cand.rotation_deg[j], crit[j], "D", ms=8, color="k", mfc="none", mew=1.5,
                label="measured posture")
    ax.set_xlabel("tool-axis rotation ψ [deg] (flange x from boring X)")
    ax.set_ylabel(CRITERION_LABEL[result.criterion])
    ax.ticklabel_format(axis="y", useOffset=False)
    fin = crit[np.isfinite(crit)]
    if fin.size and np.ptp(fin) <= 1e-6 * max(abs(float(fin.max())), 1e-300):
        ax.text(0.5, 0.5, "the criterion does not vary over the candidates\n"
                f"({fin.max():.4g} everywhere: e.g. a tool axis along the flange axis, where "
                "the rotation only turns joint 6)", transform=ax.transAxes, ha="center",
                va="center", fontsize=8, bbox=dict(fc="white", ec="0.6"))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="best")


def plot_posture_plan(result: PostureResult, out_dir: str | Path,
                      workspace: dict[str, Any] | None = None) -> list[Path]:
    """Write the posture-plan PNGs into ``out_dir``; returns the paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    syn = " (SYNTHETIC identification inputs)" if result.synthetic_inputs else ""
    fig, ax = plt.subplots(figsize=(8, 4.5))
    plot_rotation_map(result, ax)
    ax.set_title("posture map: " + result.criterion + syn, fontsize=9)
    fig.tight_layout()
    p = out / "posture_map.png"
    fig.savefig(p, dpi=130)
    plt.close(fig)
    paths.append(p)
    # stiffness per axis and first frequency vs rotation
    A = result.arrays
    cand, ev = A.cand, A.ev
    fig, axs = plt.subplots(1, 2, figsize=(10, 4))
    for b in np.unique(cand.branch):
        m = cand.branch == b
        o = np.argsort(cand.rotation_deg[m])
        for k, a in enumerate("xyz"):
            axs[0].plot(cand.rotation_deg[m][o], ev["stiffness_N_per_m"][m][o, k] * 1e-6,
                        ["-", "--", ":"][k], label=f"k_{a}, branch {b}")
        axs[1].plot(cand.rotation_deg[m][o], ev["frequency_Hz"][m][o, 0], label=f"f1, branch {b}")
    axs[0].set_ylabel("directional stiffness [N/µm] (boring frame)")
    axs[1].set_ylabel("first natural frequency [Hz]")
    for a in axs:
        a.set_xlabel("tool-axis rotation ψ [deg]")
        a.grid(alpha=0.3)
        a.legend(fontsize=6)
    fig.suptitle("stiffness and first mode vs rotation" + syn, fontsize=9)
    fig.tight_layout()
    p = out / "posture_stiffness_modes.png"
    fig.savefig(p, dpi=130)
    plt.close(fig)
    paths.append(p)
    if result.lobes:
        fig, ax = plt.subplots(figsize=(7, 4))
        for name, L in result.lobes.items():
            d = np.asarray(L.critical_depth_mm, float)
            pos = d[np.isfinite(d) & (d > 0)]
            floor = 0.5 * float(pos.min()) if pos.size else 1e-3
            ax.plot(L.speed_rpm, np.where(d > 0, d, floor), label=f"{name} posture")
        ax.axhline(result.cutting["depth_mm"], color="k", lw=0.8, ls="--",
                   label="depth of cut")
        ax.set_xlabel("spindle speed [r/min]")
        ax.set_ylabel("critical depth of cut [mm]")
        ax.set_yscale("log")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
        ax.set_title("stability lobes (semi-discretisation; 0: no chatter-free depth, drawn "
                     "at the axis floor)" + syn, fontsize=9)
        fig.tight_layout()
        p = out / "posture_lobes.png"
        fig.savefig(p, dpi=130)
        plt.close(fig)
        paths.append(p)
    if workspace is not None:
        fig, ax = plt.subplots(figsize=(6, 5))
        B = np.array([[np.nan if v is None else v for v in row]
                      for row in workspace["best_criterion"]], float) * _scale(result.criterion)
        dx, dy = np.asarray(workspace["dx_m"]), np.asarray(workspace["dy_m"])
        im = ax.pcolormesh(dx, dy, np.ma.masked_invalid(B), shading="nearest")
        fig.colorbar(im, ax=ax, label="best " + CRITERION_LABEL[result.criterion])
        ax.plot(0, 0, "D", mfc="none", color="k", label="configured part placement")
        ax.set_xlabel("part shift dx [m] (base frame)")
        ax.set_ylabel("part shift dy [m] (base frame)")
        ax.legend(fontsize=7)
        ax.set_title("workspace map (blank: no posture reaches)" + syn, fontsize=9)
        fig.tight_layout()
        p = out / "posture_workspace.png"
        fig.savefig(p, dpi=130)
        plt.close(fig)
        paths.append(p)
    return paths


__all__ = ["plot_posture_plan", "plot_rotation_map"]
