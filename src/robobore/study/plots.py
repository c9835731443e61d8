"""Figures and report sections of the study stage (matplotlib, Agg backend).

:func:`parity_figure` plots simulated against measured amplitudes, stable conditions as
small black dots and vibratory ones as larger red markers (the paper's Fig. 10 convention);
:func:`comparison_report` builds the HTML report of ``robobore compare --report``.
"""

from __future__ import annotations

from typing import Any

from robobore.study.compare import Comparison
from robobore.study.report import Report
from robobore.study.summary import AMPLITUDE_QUANTITIES

_LABEL = {
    "force_amplitude_x_N": "force amplitude X [N]",
    "force_amplitude_y_N": "force amplitude Y [N]",
    "force_amplitude_z_N": "force amplitude Z (feed) [N]",
    "feed_amplitude_um": "feed-direction amplitude [µm]",
}


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def parity_figure(cmp: Comparison) -> Any:
    """Simulated vs measured, one panel per amplitude quantity present; ±20 % band."""
    plt = _pyplot()
    qs = [q for q in AMPLITUDE_QUANTITIES
          if any(q in r["quantities"] and r["quantities"][q]["simulated"] is not None
                 for r in cmp.rows)]
    n = max(1, len(qs))
    fig, axes = plt.subplots(1, n, figsize=(4.0 * n, 3.8), squeeze=False)
    for ax, q in zip(axes[0], qs, strict=False):
        pts = {"stable": ([], []), "vibratory": ([], []), "unknown": ([], [])}
        for r in cmp.rows:
            e = r["quantities"].get(q)
            if e is None or e["simulated"] is None:
                continue
            pts[r["group"]][0].append(e["measured"])
            pts[r["group"]][1].append(e["simulated"])
        allv = [v for xs, ys in pts.values() for v in (*xs, *ys)]
        hi = max(allv) * 1.1 if allv else 1.0
        ax.plot([0, hi], [0, hi], color="0.4", lw=1, label="simulated = measured")
        ax.fill_between([0, hi], [0, 0.8 * hi], [0, 1.2 * hi], color="0.9", label="±20 %")
        if pts["stable"][0]:
            ax.scatter(*pts["stable"], s=14, c="k", label="stable", zorder=3)
        if pts["vibratory"][0]:
            ax.scatter(*pts["vibratory"], s=46, c="tab:red", marker="D", label="vibratory",
                       zorder=3)
        if pts["unknown"][0]:
            ax.scatter(*pts["unknown"], s=20, c="tab:blue", marker="s", label="not classified",
                       zorder=3)
        ax.set_xlim(0, hi)
        ax.set_ylim(0, hi)
        ax.set_xlabel(f"measured {_LABEL[q]}")
        ax.set_ylabel("simulated")
        ax.set_aspect("equal")
        ax.legend(fontsize=7, loc="upper left")
    if not qs:
        axes[0][0].text(0.5, 0.5, "no amplitude to compare", ha="center", va="center")
    fig.tight_layout()
    return fig


def _pct(v: float | None) -> float | None:
    return None if v is None else 100.0 * v


def comparison_report(cmp: Comparison, title: str = "Comparison with measurements") -> Report:
    """An HTML report of a comparison: group statistics, agreement, parity plot, table."""
    plt = _pyplot()
    rep = Report(title, subtitle="Relative error = |simulated - measured| / |measured|.")
    rep.add_section("Relative error per group")
    rep.add_text(f"Conditions are grouped by the {cmp.group_source} stable/vibratory flag. "
                 "For reference, the paper reports 3.22-15.54 % (stable) and 5.61-22.56 % "
                 "(vibratory) for its FE model against its experiments.")
    rep.add_table([
        {"group": g, "conditions": s["n_conditions"], "values": s["n"],
         "min [%]": _pct(s["min_rel_error"]), "max [%]": _pct(s["max_rel_error"]),
         "mean [%]": _pct(s["mean_rel_error"])}
        for g, s in cmp.groups.items()
    ], caption="Minimum, maximum and mean relative error", float_fmt="{:.2f}")
    a = cmp.agreement
    rep.add_section("Stable / vibratory agreement")
    rep.add_key_values({
        "conditions with both flags": a["n"], "agree": a["agree"],
        "agreement rate [%]": None if a["rate"] is None else 100.0 * a["rate"],
        "measured stable, simulated vibratory": a["measured_stable_simulated_vibratory"],
        "measured vibratory, simulated stable": a["measured_vibratory_simulated_stable"],
    }, caption="Agreement of the stability classification")
    rep.add_section("Simulated against measured")
    fig = parity_figure(cmp)
    rep.add_figure(fig, "Simulated against measured amplitudes; small black dots: stable, "
                   "red diamonds: vibratory.")
    plt.close(fig)
    rep.add_section("Per condition")
    rep.add_table(cmp.table_rows(), caption="Measured, simulated and relative error [%]")
    if cmp.unmatched_measured or cmp.undefined:
        rep.add_section("Not compared")
        for u in cmp.unmatched_measured:
            rep.add_note(f"Measured row {u['row']} has no simulated condition.")
        for u in cmp.undefined:
            rep.add_note(f"Row {u['row']}, {u['quantity']}: {u['reason']}.")
    return rep


__all__ = ["parity_figure", "comparison_report"]
