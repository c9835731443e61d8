"""Figures and report sections of the study stage (matplotlib, Agg backend).

Each condition is marked by its verdict (:func:`verdict_class`, :data:`MARKS`): red diamond =
chatter (the vibration grows), orange open square = rough only (the paper's criterion says
"vibratory": Ra above the tolerance, without chatter), black dot = neither. Results without the
verdicts by cause (other runners, measured data) are marked by their ``stable`` flag alone:
red diamond = vibratory.

* :func:`parity_figure`: simulated against measured amplitudes;
* :func:`trend_figure`: a summary quantity against one factor (speed, feed, depth of cut),
  one line per foot pressure (the paper's Figs. 9 and 10);
* :func:`stability_map_figure`: depth of cut against speed, stable/vibratory marked (the
  swept conditions to overlay on a stability lobe diagram);
* :func:`comparison_report` and :func:`sweep_report`: the HTML reports of
  ``robobore compare --report`` and ``robobore sweep --report``.

``records`` are ``(condition, summary)`` pairs, e.g. from ``ResultsStore.records()``.
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


#: Marker per verdict class: scatter keyword arguments and legend label.
MARKS: dict[str, tuple[dict[str, Any], str]] = {
    "ok": (dict(s=14, c="k", marker="o"), "no chatter, Ra within tolerance"),
    "rough": (dict(s=40, facecolors="none", edgecolors="tab:orange", marker="s",
                   linewidths=1.4), "rough only (Ra > tol., no chatter; paper: vibratory)"),
    "chatter": (dict(s=44, c="tab:red", marker="D"), "chatter (vibration grows)"),
    "vibratory": (dict(s=44, c="tab:red", marker="D"), "vibratory (stable flag)"),
    "stable": (dict(s=14, c="k", marker="o"), "stable (stable flag)"),
}


def verdict_class(summary: dict[str, Any] | None) -> str | None:
    """``"chatter"``, ``"rough"`` (the paper's criterion vibratory without chatter) or
    ``"ok"`` for a summary with the verdicts by cause; ``"vibratory"`` / ``"stable"`` for
    one with the ``stable`` flag only; None without either."""
    if not summary:
        return None
    if "chatter" in summary:
        if summary["chatter"] is True:
            return "chatter"
        if summary.get("stable") is False or summary.get("surface_finish_ok") is False:
            return "rough"
        return "ok"
    st = summary.get("stable")
    return None if st is None else ("stable" if st else "vibratory")


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
            ax.scatter(*pts["stable"], s=14, c="k", label="stable (paper's criterion)",
                       zorder=3)
        if pts["vibratory"][0]:
            ax.scatter(*pts["vibratory"], s=46, c="tab:red", marker="D",
                       label="vibratory (paper's criterion)", zorder=3)
        if pts["unknown"][0]:
            ax.scatter(*pts["unknown"], s=20, c="tab:blue", marker="s", label="not classified",
                       zorder=3)
        ax.set_xlim(0, hi)
        ax.set_ylim(0, hi)
        ax.set_xlabel(f"measured {_LABEL[q]}", fontsize=8)
        ax.set_ylabel(f"simulated {_LABEL[q]}", fontsize=8)
        ax.set_aspect("equal")
    if not qs:
        axes[0][0].text(0.5, 0.5, "no amplitude to compare", ha="center", va="center")
    # one legend for all panels, below them: it never hides a point
    handles, labels = axes[0][0].get_legend_handles_labels()
    for ax in axes[0][1:]:
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    if handles:
        fig.legend(handles, labels, loc="lower center", ncol=min(5, len(labels)), fontsize=8,
                   frameon=False, bbox_to_anchor=(0.5, -0.02))
        fig.tight_layout(rect=(0, 0.08, 1, 1))
    else:
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


FACTOR_LABEL = {
    "speed_rpm": "rotational speed n [r/min]",
    "feed_mm_per_rev": "feed f [mm/r]",
    "depth_of_cut_mm": "depth of cut ap [mm]",
    "pressure_MPa": "foot pressure P [MPa]",
}


SERIES_LABEL = {
    "speed_rpm": "n = {:g} r/min",
    "feed_mm_per_rev": "f = {:g} mm/r",
    "depth_of_cut_mm": "ap = {:g} mm",
    "pressure_MPa": "P = {:g} MPa",
}


def _matches(cond: dict[str, Any], fixed: dict[str, Any] | None) -> bool:
    return not fixed or all(abs(float(cond[k]) - float(v)) <= 1e-9 * max(1.0, abs(float(v)))
                            for k, v in fixed.items())


def trend_figure(records: list[tuple[dict[str, Any], dict[str, Any]]], x: str,
                 quantity: str, series: str = "pressure_MPa",
                 fixed: dict[str, Any] | None = None, ax: Any = None) -> Any:
    """``quantity`` against factor ``x``, one line per value of ``series``.

    ``fixed`` keeps only the conditions with those factor values (a one-factor-at-a-time
    cut through a grid); otherwise each line goes through the mean over the other factors
    at each ``x`` (a main-effect plot) and every condition is drawn as a marker.
    Returns the figure.
    """
    plt = _pyplot()
    if ax is None:
        fig, ax = plt.subplots(figsize=(5.2, 3.6))
    else:
        fig = ax.figure
    rows = [(c, s) for c, s in records if _matches(c, fixed) and s.get(quantity) is not None]
    levels = sorted({float(c[series]) for c, _ in rows})
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, lv in enumerate(levels):
        pts = [(float(c[x]), float(s[quantity]), verdict_class(s))
               for c, s in rows if float(c[series]) == lv]
        xs = sorted({p[0] for p in pts})
        means = [sum(p[1] for p in pts if p[0] == xv) / sum(1 for p in pts if p[0] == xv)
                 for xv in xs]
        ax.plot(xs, means, "-", color=colours[i % len(colours)], lw=1.3,
                label=SERIES_LABEL.get(series, series + " = {:g}").format(lv))
        for cls, (kw, _) in MARKS.items():
            pc = [p for p in pts if p[2] == cls]
            if pc:
                ax.scatter([p[0] for p in pc], [p[1] for p in pc], zorder=3, **kw)
    present = {verdict_class(s) for _, s in rows}
    for cls, (kw, lab) in MARKS.items():
        if cls in present:
            ax.scatter([], [], label=lab, **kw)
    ax.set_xlabel(FACTOR_LABEL.get(x, x))
    ax.set_ylabel(_LABEL.get(quantity, quantity))
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def stability_map_figure(records: list[tuple[dict[str, Any], dict[str, Any]]],
                         pressure_MPa: float | None = None, ax: Any = None) -> Any:
    """Depth of cut against speed for the swept conditions, each marked by its verdict
    (conditions with the given foot pressure, or all). Returns the figure; overlay a
    stability lobe diagram on ``fig.axes[0]``."""
    plt = _pyplot()
    if ax is None:
        fig, ax = plt.subplots(figsize=(5.6, 3.6))
    else:
        fig = ax.figure
    fixed = None if pressure_MPa is None else {"pressure_MPa": pressure_MPa}
    rows = [(c, s) for c, s in records if _matches(c, fixed)]
    groups = {cls: ([c for c, s in rows if verdict_class(s) == cls], kw, lab)
              for cls, (kw, lab) in MARKS.items()}
    groups["not classified"] = ([c for c, s in rows if verdict_class(s) is None],
                                dict(s=20, c="tab:blue", marker="s"), "not classified")
    for cs, style, lab in groups.values():
        if cs:
            ax.scatter([c["speed_rpm"] for c in cs], [c["depth_of_cut_mm"] for c in cs],
                       label=lab, zorder=3, **style)
    ax.set_xlabel(FACTOR_LABEL["speed_rpm"])
    ax.set_ylabel(FACTOR_LABEL["depth_of_cut_mm"])
    if pressure_MPa is not None:
        ax.set_title(f"foot pressure P = {pressure_MPa:g} MPa", fontsize=9)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def sweep_report(store: Any, keys: list[str] | None = None, title: str = "Sweep results",
                 max_rows: int = 300) -> Report:
    """An HTML report of a sweep: counts, failures, stability maps, trends, summary table.

    ``store``: a :class:`robobore.study.store.ResultsStore`; ``keys``: the sweep's
    conditions (default: every finished condition in the store).
    """
    from robobore.study.conditions import CONDITION_FIELDS

    plt = _pyplot()
    recs = list(store.records(keys))
    records = [(r.condition, r.summary) for r in recs]
    rep = Report(title, subtitle=f"Results store: {store.root}")
    rep.add_section("Overview")
    n_keys = len(keys) if keys is not None else len(recs)
    failed = [k for k in (keys or []) if store.status(k) == "failed"]
    runners = sorted({r.runner or "?" for r in recs})
    rep.add_key_values({"conditions": n_keys, "finished": len(recs), "failed": len(failed),
                        "runner": ", ".join(runners),
                        "chatter (vibration grows)": sum(1 for _, s in records
                                                         if s.get("chatter") is True),
                        "stable, stable flag (paper's criterion)":
                            sum(1 for _, s in records if s.get("stable") is True),
                        "vibratory, stable flag (paper's criterion)":
                            sum(1 for _, s in records if s.get("stable") is False)},
                       caption="Sweep status")
    if any("demo" == r for r in runners):
        rep.add_note("These results come from the DEMO runner (single-DOF regenerative toy), "
                     "not from the boring model.")
    if failed:
        rows = []
        for k in failed:
            f = store.failure(k) or {}
            rows.append({"key": k, **{c: f.get("condition", {}).get(c)
                                      for c in CONDITION_FIELDS},
                         "error": f.get("error", "")[:200]})
        rep.add_table(rows, caption="Failed conditions")
    if not records:
        rep.add_text("No finished condition.")
        return rep
    pressures = sorted({float(c["pressure_MPa"]) for c, _ in records})
    if any(s.get("stable") is not None for _, s in records):
        rep.add_section("Stable and vibratory conditions")
        for p in pressures:
            fig = stability_map_figure(records, p)
            rep.add_figure(fig, f"Swept conditions at foot pressure P = {p:g} MPa, each "
                           "marked by its verdict (red diamonds chatter or, without the "
                           "verdicts by cause, vibratory; orange squares rough only).")
            plt.close(fig)
    quantities = [q for q in AMPLITUDE_QUANTITIES
                  if any(s.get(q) is not None for _, s in records)]
    factors = [f for f in ("speed_rpm", "feed_mm_per_rev", "depth_of_cut_mm")
               if len({float(c[f]) for c, _ in records}) > 1]
    if quantities and factors:
        rep.add_section("Trends")
        rep.add_text("Each line is the mean over the other factors at each level (main "
                     "effect); every condition is drawn as a marker.")
        for q in quantities:
            fig, axes = plt.subplots(1, len(factors), figsize=(4.6 * len(factors), 3.5),
                                     squeeze=False)
            for ax, f in zip(axes[0], factors, strict=True):
                trend_figure(records, f, q, ax=ax)
            fig.tight_layout()
            rep.add_figure(fig, f"{_LABEL.get(q, q)} against the cutting conditions.")
            plt.close(fig)
    rep.add_section("All conditions")
    rep.add_table([{**{f: c[f] for f in CONDITION_FIELDS}, "posture": c.get("posture"),
                    **{q: s.get(q) for q in (*AMPLITUDE_QUANTITIES, "stable", "chatter",
                                             "roughness_Ra_um")}}
                   for c, s in records], caption="Summary per condition", max_rows=max_rows)
    return rep


__all__ = [
    "parity_figure", "trend_figure", "stability_map_figure", "comparison_report",
    "sweep_report", "verdict_class", "MARKS",
]
