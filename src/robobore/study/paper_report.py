"""The self-contained HTML report of ``robobore paper``; its figures are
:mod:`robobore.study.paper_figures`.

:func:`build_report` returns a :class:`robobore.study.report.Report` with: inputs (SYNTHETIC
labels), the stiffness and mode tables, the equivalent model (with / without the foot, and
what the paper's c = 23.7 N s/m implies), the coefficient set of the boring model (its
calibrated domain and the warnings where the study leaves it), the FE calibration (points,
fit, coefficients; the opt-in set unless the config chooses it),
figures like the paper's (force over half a revolution; feed amplitude over time; force and
feed amplitude against speed, feed and depth for robot and machine tool with each point
marked by its verdict; force and rotational acceleration as chatter develops; machined
surface, form removed; lobes with the swept conditions), the stabilisation diagram and an
FRF fit of the hammer test, the comparison with the measured CSV, and the qualitative checks
against the paper, each made with the chatter verdict and, separately, with the paper's
roughness criterion (disagreements stated).

Point marks: :data:`robobore.study.paper_figures.MARKS` (every figure and the tables).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from robobore.study.paper_figures import (
    fig_feed_amplitude_time,
    fig_force_half_rev,
    fig_lobes,
    fig_surface,
    fig_trends,
    fig_vibration_develops,
    pyplot,
    system_label,
)
from robobore.study.plots import verdict_class
from robobore.study.report import Report


def _verdict_text(summary: dict[str, Any] | None) -> str:
    if not summary:
        return "FAILED"
    return {"chatter": "CHATTER", "rough": "rough", "ok": "ok", None: "n/a"}[
        verdict_class(summary)]


def _cond(r: dict[str, Any]) -> str:
    return (f"n = {r['speed_rpm']:g} r/min, f = {r['feed_mm_per_rev']:g} mm/r, "
            f"ap = {r['depth_of_cut_mm']:g} mm")


def _base_key(rows: list[dict[str, Any]], base: dict[str, float], system: str,
              p: float) -> dict[str, Any] | None:
    for r in rows:
        if (r["system"] == system and r["pressure_MPa"] == p and r.get("summary")
                and all(math.isclose(r[k], base[k]) for k in base)):
            return r
    return None


def _mode_rows(modes: list[dict[str, Any]]) -> list[dict[str, Any]]:
    out = []
    for i, m in enumerate(modes):
        d = m.get("direction")
        key = f"hammer_{d}" if d else None
        mass = (m.get("modal_mass_kg") or {}).get(key) if key else None
        k = (m.get("modal_stiffness_N_per_m") or {}).get(key) if key else None
        mpc = m.get("mpc")
        out.append({"mode": i + 1, "f [Hz]": m["frequency_Hz"],
                    "zeta [%]": 100 * m["damping_ratio"],
                    "MPC": None if mpc is None else f"{mpc:.7f}",
                    "1 - MPC": None if mpc is None else f"{1.0 - mpc:.2e}",
                    "direction": d,
                    "modal mass [kg]": mass,
                    "modal stiffness [N/um]": None if k is None else k * 1e-6})
    return out


def modal_figure_pngs(an: Any) -> list[tuple[bytes, str]]:
    """(PNG, caption) of the stabilisation diagram and of the FRF fit of each hammer input's
    driving point: the report's modal figures (drawn by the study while its pool computes)."""
    import tempfile

    from robobore.modal.plots import plot_frf_fit, plot_stabilisation

    out = []
    with tempfile.TemporaryDirectory() as tmp:
        p = plot_stabilisation(an, Path(tmp) / "stab.png")
        out.append((p.read_bytes(), "Stabilisation diagram of the hammer test (pLSCF model "
                    "order against frequency, symbols by stability status) over the CMIF; "
                    "dashed lines: the selected modes."))
        d = an.data
        for j in range(d.n_inputs):
            o = j if j < d.n_outputs else 0
            p = plot_frf_fit(an, Path(tmp) / f"frf{j}.png", o, j)
            out.append((p.read_bytes(), f"Measured FRF {d.output_names[o]} / "
                        f"{d.input_names[j]} and the identified modal model (LSFD "
                        "synthesis)."))
    return out


def _eq_rows(eq: dict[str, Any]) -> list[dict[str, Any]]:
    out = []
    for label, key in (("without foot", "without_foot"),
                       (f"with foot ({eq['pressure_MPa']:g} MPa)", "with_foot"),
                       ("paper's c = 23.7 N s/m", "paper_c")):
        for r in eq[key].table():
            out.append({"model": label, "axis": r["axis"].upper(),
                        "k [N/um]": r["stiffness_N_per_m"] * 1e-6,
                        "f_n [Hz]": r["frequency_Hz"], "m [kg]": r["mass_kg"],
                        "c [N s/m]": r["damping_N_s_per_m"], "zeta": r["damping_ratio"]})
    return out


def _pct(v: float | None) -> float | None:
    return None if v is None else round(100.0 * v, 1) + 0.0  # no -0


def force_model_fe_text(rep: Report, coeffs: dict[str, Any]) -> None:
    """The FE model the coefficients were calibrated from (the coefficients file's
    ``fe_model``, written by ``robobore calibrate forces``) and, as a list, how its virtual
    tests depart from the validated configuration."""
    m = coeffs.get("fe_model")
    if not isinstance(m, dict):
        rep.add_note("The coefficients file does not name the FE model it was calibrated "
                     "from (no fe_model record): recalibrate with robobore calibrate forces.")
        return
    src = m.get("source")
    src = "the calibration's inline fe_config table" if src == "inline" else src
    rep.add_text(f"FE model of the virtual tests: {m.get('summary')} (FE config: {src}). "
                 f"Validation status: {m.get('validation')}.")
    out = m.get("outside_validation") or []
    if out:
        import html

        rep.add_text("The calibration's FE tests depart from the validated configuration "
                     "(the validation table below) in:")
        rep.add_html("<ul>" + "".join(f"<li>{html.escape(str(x))}</li>" for x in out)
                     + "</ul>")


def force_model_validation(rep: Report, coeffs: dict[str, Any],
                           record: str | Path | None = None) -> None:
    """The validation table of the FE model the coefficients come from: the bundled record
    of the default model (``robobore/data/fe_validation``) when the calibration ran the
    validated physics on its material; otherwise a note that no validation applies."""
    from robobore.cutting.calibration_config import VALIDATION_DOMAIN
    from robobore.cutting.fe.models.validation_record import (
        bundled_validation_path,
        load_validation_record,
    )

    m = coeffs.get("fe_model") if isinstance(coeffs.get("fe_model"), dict) else {}
    mat = coeffs.get("material")
    if not m.get("validated_physics") or mat != VALIDATION_DOMAIN["material"]:
        rep.add_note("The FE model of these coefficients is not the engine's validated model "
                     f"on its validated material ({VALIDATION_DOMAIN['material']}): no "
                     "validation against measured forces applies to them (docs/fe.md, "
                     "'Model choice').")
        return
    path = Path(record) if record is not None else bundled_validation_path()
    if not path.is_file():
        rep.add_note(f"The validation record of the default FE model ({path}) is missing "
                     "from this installation: no validation table.")
        return
    val = load_validation_record(path)
    rows = []
    for pt in val.points:
        ms, er = pt.measured, pt.relative_error
        rows.append({"h [um]": pt.uncut_chip_thickness_um,
                     "vc [m/min]": pt.cutting_speed_m_per_min,
                     "Fc meas [N/mm]": ms.cutting_force_N_per_mm,
                     "Fc sim [N/mm]": pt.cutting_force_N_per_mm,
                     "Fc err [%]": _pct(er.cutting_force),
                     "Ff meas [N/mm]": ms.feed_force_N_per_mm,
                     "Ff sim [N/mm]": pt.feed_force_N_per_mm,
                     "Ff err [%]": _pct(er.feed_force),
                     "chip ratio meas": ms.chip_ratio,
                     "chip ratio sim": pt.chip_ratio,
                     "chip ratio err [%]": _pct(er.chip_ratio)})
    rep.add_table(rows, caption="Validation of the FE model against measured orthogonal "
                  "forces (err = simulated / measured - 1)", float_fmt="{:.4g}")
    mx_, mn_ = val.summary.max_abs_error, val.summary.mean_abs_error
    parts = []
    for label, mx, mn in (("Fc", mx_.cutting_force, mn_.cutting_force),
                          ("Ff", mx_.feed_force, mn_.feed_force),
                          ("chip ratio", mx_.chip_ratio, mn_.chip_ratio)):
        if mx is not None and mn is not None:
            parts.append(f"{label} {100 * mx:.1f} / {100 * mn:.1f} %")
    rep.add_text("Max / mean |error| over the points: " + ", ".join(parts) + ".")
    rep.add_text(f"Source: {path.name} (robobore/data/fe_validation), the --json output of "
                 f"robobore fe validate {val.config} --measured "
                 f"{Path(str(val.measured_file)).name} (the engine's default model at "
                 "its validated configuration). Its two CALIBRATED choices (friction law "
                 "rech2013_calibrated, the hardening hold) were chosen on these same points, "
                 "so the table shows how far the calibration reaches, not an independent "
                 "validation.")


def _set_label(cset: dict[str, Any] | None) -> str:
    if not cset:
        return "n/a"
    d = cset.get("domain") or {}
    v, h = d.get("cutting_speed_m_per_min"), d.get("uncut_chip_thickness_um")
    return (f"{cset.get('name')} (calibrated: "
            + ("speeds n/a" if not v else f"{v[0]:g}-{v[1]:g} m/min") + ", "
            + ("chip thicknesses n/a" if not h else f"h {h[0]:g}-{h[1]:g} um") + ")")


def coefficient_set_section(rep: Report, cset: dict[str, Any], warnings: list[str]) -> None:
    """The section naming the coefficient set of the boring model (sweep, lobes, posture
    plan): its description, calibrated domain, values at the base speed, and the warnings
    where the study uses it outside its calibrated speeds or chip thicknesses (the same list
    as ``warnings`` in ``paper_summary.json``)."""
    rep.add_section("Force model used by the simulations")
    if not cset:
        rep.add_note("The coefficient set is not known.")
        return
    d = cset["domain"]
    rep.add_text(f"Coefficient set {cset['name']}: {cset['description']}.")
    c = cset["coefficients"]
    rep.add_key_values({
        "set": cset["name"],
        "calibrated cutting speeds [m/min]": "n/a" if not d["cutting_speed_m_per_min"] else
        "{:g}-{:g}".format(*d["cutting_speed_m_per_min"]),
        "calibrated uncut chip thicknesses [um]": "n/a" if not d["uncut_chip_thickness_um"]
        else "{:g}-{:g}".format(*d["uncut_chip_thickness_um"]),
        "base condition's cutting speed [m/min]": f"{cset['base_cutting_speed_m_per_min']:.3g}",
        **{f"{k} at the base speed": c[k] for k in ("Ktc_N_per_m2", "Kte_N_per_m",
                                                     "Kfc_N_per_m2", "Kfe_N_per_m")},
        "provenance": c.get("provenance", ""),
    }, caption="Coefficient set of the boring model")
    if warnings:
        rep.add_note(f"{len(warnings)} coefficient warning(s): the set is used outside its "
                     "calibrated domain (table below; 'warnings' in paper_summary.json).")
        rep.add_table([{"warning": w} for w in warnings], caption="Coefficient warnings")


def build_report(cfg: Any, cfg_path: Path, *, stiff: dict[str, Any], modes: dict[str, Any],
                 eq: dict[str, Any], coeffs: dict[str, Any], rows: list[dict[str, Any]],
                 store: Any, lobes: dict[str, Any], cmp: Any, checks: list[dict[str, Any]],
                 summary: dict[str, Any],
                 modal_pngs: list[tuple[bytes, str]] | None = None) -> Report:
    """The paper report (see module doc); ``modal_pngs``: the modal figures of
    :func:`modal_figure_pngs` when already drawn (drawn here otherwise)."""
    plt = pyplot()
    base = {k: float(v) for k, v in cfg.study.base.items()}
    syn = stiff.get("synthetic") or modes.get("synthetic")
    rep = Report(cfg.study.title, subtitle=("SYNTHETIC example data: every measurement in "
                                            "this report is a virtual experiment"
                                            if syn else f"config {cfg_path}"))
    rep.add_section("Summary")
    rep.add_key_values({
        "config": str(cfg_path),
        "conditions simulated": f"{summary['computed']} of {summary['conditions']}",
        "chatter (vibration grows)": summary.get("chatter"),
        "rough (Ra after form removal > tolerance)": summary.get("rough"),
        "tool leaves the cut": summary.get("tool_leaves_cut"),
        "stable / vibratory by the paper's criterion (Ra > "
        f"{cfg.study.ra_tolerance_um:g} um)": f"{summary['stable']} / {summary['vibratory']}",
        "force coefficients (boring model)": _set_label(summary.get("coefficient_set")),
        "coefficient warnings": len(summary.get("warnings") or []),
        "robobore version": summary.get("robobore_version"),
    }, caption="Run")
    if summary["failed"]:
        rep.add_note(f"{len(summary['failed'])} condition(s) FAILED in the simulation and are "
                     "missing from the figures and checks (see the table below).")
        rep.add_table([{"system": f["system"], **f["condition"], "error": (f["error"] or "")[:160]}
                       for f in summary["failed"]], caption="Failed conditions")
    dis = [c for c in checks if c["agrees"] is False]
    if dis:
        rep.add_note("Our model DISAGREES with the paper on: "
                     + "; ".join(f"{c['finding']} [by {c.get('verdict', '')}]" for c in dis)
                     + " (details in 'Paper's findings').")
    rep.add_text("Verdicts: 'chatter' = the vibration grows over the revolutions (regenerative "
                 "envelope and per-revolution feed/radial amplitude, docs/process.md); "
                 "'rough' = Ra of the machined profile after removing its form (least-squares "
                 f"line) above {cfg.study.ra_tolerance_um:g} um; the paper's criterion calls "
                 "a cut 'vibratory' when it is rough (feed marks alone can make it so). "
                 "Figures mark chatter with red diamonds, rough-only cuts with orange open "
                 "squares, the rest with black dots.")

    # ---------------------------------------------------------------- robot
    rep.add_section("Robot stiffness")
    ide = stiff["identification"]
    rep.add_text(f"Joint stiffness identified from the laser-tracker campaign {stiff['campaign']}"
                 + (" (SYNTHETIC)" if stiff["synthetic"] else "") + f" for {stiff['robot']}; "
                 "directional stiffness at the paper's posture "
                 f"{', '.join(f'{v:g}' for v in stiff['posture_deg'])} deg in the boring frame "
                 "(X horizontal, Y vertical, Z feed).")
    rep.add_table([{"joint": i + 1, "k [N m/rad]": k,
                    "std": ide["joint_stiffness_std_Nm_per_rad"][i],
                    "95 % low": ide["joint_stiffness_ci95_low_Nm_per_rad"][i],
                    "95 % high": ide["joint_stiffness_ci95_high_Nm_per_rad"][i],
                    "status": ide["joint_status"][i]}
                   for i, k in enumerate(ide["joint_stiffness_Nm_per_rad"])],
                  caption="Identified joint stiffness")
    ku = stiff["directional_stiffness_N_per_m"]
    rep.add_table([{"direction": a.upper(), "k [N/um]": ku[a] * 1e-6} for a in "xyz"],
                  caption="Directional stiffness at the boring posture (boring frame)")

    rep.add_section("Modes")
    rep.add_text(f"The {len(modes['modes'])} best-supported modes of the hammer test "
                 f"{modes['source']}" + (" (SYNTHETIC)" if modes["synthetic"] else "")
                 + " (pLSCF + LSFD, automatic selection).")
    rep.add_table(_mode_rows(modes["modes"]), caption="Identified modes (MPC as estimated by "
                  "LSFD; 1 - MPC shows how far from a real mode; modal mass and stiffness at "
                  "the driving point of the mode's direction)")
    an = modes.get("analysis")
    if an is not None:
        for png, caption in (modal_pngs if modal_pngs is not None else modal_figure_pngs(an)):
            rep.add_image_png(png, caption)

    rep.add_section("Equivalent model")
    rep.add_text("Paper eq. 1-3: per direction k from the robot stiffness, f_n and zeta from the "
                 "mode assigned to that direction (by its direction), m = k / w_n^2, "
                 "c = 2 zeta sqrt(k m). The pressure foot is an ASSUMED contact model "
                 "(docs/process.md). The last block uses the paper's c = 23.7 N s/m instead of "
                 "the identified damping.")
    rep.add_table(_eq_rows(eq), caption="Equivalent model per direction")
    zp = eq["paper_c"].damping_ratio
    rep.add_note("With c = 23.7 N s/m the implied damping ratios are "
                 + ", ".join(f"{a.upper()}: {zp[a]:.2e}" for a in "xyz")
                 + ", i.e. practically undamped, far below the identified modal damping "
                 + ", ".join(f"{100 * eq['without_foot'].damping_ratio[a]:.1f} %" for a in "xyz")
                 + ". The simulations use the identified damping.")

    # ---------------------------------------------------------------- forces
    cset = summary.get("coefficient_set") or {}
    fe_used = cset.get("name") == "TC4-FE"
    coefficient_set_section(rep, cset, summary.get("warnings") or [])
    rep.add_section("Force model (FE-calibrated)" if fe_used else
                    "Force model: the FE calibration (opt-in set TC4-FE, not used above)")
    c = coeffs["coefficients"]
    if not fe_used:
        rep.add_text("The FE engine's own result for the paper's insert and chip: the set "
                     "the boring model uses with [coefficients] material = \"TC4-FE\". The "
                     "simulations of this report use the coefficient set of the section "
                     "above.")
    rep.add_text(f"Coefficients: {coeffs.get('mode')}. {c.get('provenance', '')}")
    force_model_fe_text(rep, coeffs)
    se = coeffs.get("standard_errors", {})
    rep.add_table([{"coefficient": k, "value": c[k], "standard error": se.get(k)}
                   for k in ("Ktc_N_per_m2", "Kte_N_per_m", "Kfc_N_per_m2", "Kfe_N_per_m",
                             "Krc_N_per_m2", "Kre_N_per_m")],
                  caption="Mechanistic coefficients used by the boring model" if fe_used
                  else "Mechanistic coefficients of the FE calibration (opt-in)")
    if coeffs.get("fe_points"):
        from robobore.cutting.calibrate import predicted_forces

        rep.add_table([{"h [um]": p["h_um"], "vc [m/min]": p["vc_m_per_min"],
                        "Fc FE [N/mm]": p["Fc_fe"] * 1e-3, "Fc fit [N/mm]": p["Fc_fit"] * 1e-3,
                        "Fc err [%]": 100 * p["Fc_rel_error"],
                        "Ff FE [N/mm]": p["Ff_fe"] * 1e-3, "Ff fit [N/mm]": p["Ff_fit"] * 1e-3,
                        "Ff err [%]": 100 * p["Ff_rel_error"]}
                       for p in predicted_forces(coeffs)],
                      caption="Virtual orthogonal cutting tests (2D FE) and the fit")
        for w in coeffs.get("warnings", []):
            rep.add_note("Calibration warning: " + w + ".")

    force_model_validation(rep, coeffs)

    # ---------------------------------------------------------------- figures
    rep.add_section("Simulated boring: forces and vibration")
    rb = _base_key(rows, base, "robot", 0.0)
    if rb is not None:
        ds = store.load(rb["key"])
        fig = fig_force_half_rev(ds, f"robot, no foot, {_cond(rb)}")
        rep.add_figure(fig, "Force components over half a revolution at the base condition "
                       "(paper Fig. 7 kind): X and Y rotate with the bar, Z (feed) is nearly "
                       "constant.")
        plt.close(fig)
    items = []
    for g in sorted({(r["system"], r["pressure_MPa"]) for r in rows}):
        r = _base_key(rows, base, *g)
        if r is not None:
            items.append((f"{system_label(*g)[0]}, base condition {_cond(r)} "
                          f"[{_verdict_text(r['summary'])}]", store.load(r["key"])))
    robot0 = [r for r in rows if r["system"] == "robot" and r["pressure_MPa"] == 0.0
              and r.get("summary")]
    vib = [r for r in robot0 if verdict_class(r["summary"]) == "chatter"]
    if not vib:
        vib = [r for r in robot0 if verdict_class(r["summary"]) == "rough"]
    worst = max(vib, key=lambda r: r["summary"]["feed_amplitude_um"]) if vib else None
    if worst is not None:
        items.append((f"robot, no foot, {_cond(worst)} [{_verdict_text(worst['summary'])}]",
                      store.load(worst["key"])))
    if items:
        fig = fig_feed_amplitude_time(items)
        rep.add_figure(fig, "Feed-direction (Z) displacement of the tool over time (paper Fig. "
                       "8 kind).")
        plt.close(fig)
    fig = fig_trends(rows, base)
    rep.add_figure(fig, "Average force amplitude (mean of X and Y) and feed amplitude against "
                   "speed, feed and depth of cut, one factor at a time around the base "
                   "condition (paper Figs. 9-10 kind); red diamonds chatter, orange squares "
                   "rough only (the paper's 'vibratory' without chatter), black dots neither.")
    plt.close(fig)
    if worst is not None:
        ds = store.load(worst["key"])
        fig = fig_vibration_develops(ds, f"robot, no foot, {_cond(worst)} "
                                         f"[{_verdict_text(worst['summary'])}]")
        rep.add_figure(fig, "Force and rotational acceleration as the vibration develops "
                       f"(paper Fig. 11 kind). Classification: {ds.attrs.get('reasons', '')}.")
        plt.close(fig)
    st = [r for r in robot0 if verdict_class(r["summary"]) == "ok"]
    rough = [r for r in robot0 if verdict_class(r["summary"]) == "rough"]
    surf = []
    if rb is not None and verdict_class(rb["summary"]) == "ok":
        surf.append((f"ok, base {_cond(rb)}", store.load(rb["key"])))
    elif st:
        surf.append((f"ok, {_cond(st[0])}", store.load(st[0]["key"])))
    if rough:
        r1 = max(rough, key=lambda r: r["feed_mm_per_rev"])
        surf.append((f"rough only, {_cond(r1)}", store.load(r1["key"])))
    if worst is not None and worst not in rough:
        surf.append((f"{_verdict_text(worst['summary'])}, {_cond(worst)}",
                     store.load(worst["key"])))
    if surf:
        fig = fig_surface(surf)
        rep.add_figure(fig, "Machined surface along the bore axis after removing its form "
                       "(least-squares line), as Ra is computed (paper Fig. 12 kind): a cut "
                       "without vibration, one made rough by its feed marks alone, and the "
                       "strongest chatter.")
        plt.close(fig)
    if lobes:
        fig = fig_lobes(lobes, rows, base)
        cons = summary.get("lobe_consistency") or {}
        rep.add_figure(fig, "Stability lobe diagram of the robot at the base feed "
                       "(semi-discretisation on the chip at each depth, the model the time "
                       "domain integrates), with the swept conditions (speed and depth series) "
                       "marked by their verdict; rough-only points can lie below the lobes. "
                       f"Checked condition by condition ({cons.get('rule', '')}): "
                       f"{cons.get('consistent', 0)} of {cons.get('checked', 0)} consistent, "
                       f"{cons.get('nonlinear', 0)} with the tool leaving the cut.")
        plt.close(fig)
        cal = summary.get("calibration")
        if cal:  # [measured] observations: the lobes corrected by the observed cuts
            rep.add_image_png(Path(cal["plot"]).read_bytes(), "Lobes corrected by "
                              f"{cal['cuts']} observed cuts (calibrate dynamics): critical "
                              "depth 5/50/95 % and P(chatter), the cuts marked.")
            lo, med, hi = cal["lowest_critical_depth_mm"]
            rep.add_key_values({"corrected lowest critical depth (mm), 90 %":
                                f"{med:.3g} [{lo:.3g} .. {hi:.3g}] at "
                                f"{cal['at_speed_rpm']:.0f} r/min; " + ", ".join(
                                    f"{k} {v:.3g}" for k, v in cal["factors"].items())})
        for x in cons.get("inconsistent", []):
            rep.add_text(f"Lobes and verdict disagree at n {x['speed_rpm']:g} r/min, "
                         f"P {x['pressure_MPa']:g} MPa, ap {x['depth_mm']:g} mm: {x['side']} "
                         f"the limit {x['critical_depth_mm']} mm, chatter {x['chatter']}.")

    # ---------------------------------------------------------------- comparison
    rep.add_section("Comparison with the measurements")
    if cmp is None:
        rep.add_text("No measured CSV configured.")
    else:
        rep.add_text("Measured: " + str(cfg.measured.file) + (" (SYNTHETIC: " +
                     cfg.measured.truth_note + ")" if cfg.measured.truth_note else "")
                     + ". The paper reports 3.22-15.54 % (stable) and 5.61-22.56 % "
                     "(vibratory) relative errors.")
        g = []
        for name, s in cmp.groups.items():
            g.append({"group": name, "conditions": s.get("n_conditions"), "values": s.get("n"),
                      "min [%]": None if s.get("min_rel_error") is None
                      else 100 * s["min_rel_error"],
                      "max [%]": None if s.get("max_rel_error") is None
                      else 100 * s["max_rel_error"],
                      "mean [%]": None if s.get("mean_rel_error") is None
                      else 100 * s["mean_rel_error"]})
        rep.add_table(g, caption=f"Relative error per group (groups from the "
                      f"{cmp.group_source} stable flag: the paper's criterion)")
        a = cmp.agreement
        rep.add_key_values({"conditions with both flags": a.get("n"),
                            "agree": a.get("agree"),
                            "agreement rate": None if a.get("rate") is None
                            else f"{100 * a['rate']:.1f} %",
                            "measured stable, simulated vibratory":
                                a.get("measured_stable_simulated_vibratory"),
                            "measured vibratory, simulated stable":
                                a.get("measured_vibratory_simulated_stable")},
                           caption="Stable / vibratory agreement")
        from robobore.study.plots import parity_figure

        fig = parity_figure(cmp)
        rep.add_figure(fig, "Simulated against measured (SYNTHETIC) amplitudes.")
        plt.close(fig)
        rep.add_table(cmp.table_rows(), caption="Per condition and quantity", max_rows=400)

    if summary.get("posture_plan") is not None:  # robobore plan: the paper's bore
        from robobore.plan.paper import add_posture_section

        add_posture_section(rep, summary["posture_plan"])

    # ---------------------------------------------------------------- checks
    rep.add_section("Paper's findings")
    rep.add_text("Each qualitative finding of the paper is checked on our results (computed "
                 "from the sweep, not written by hand), with the coefficient set "
                 f"{_set_label(cset)}; a finding marked NO is one where our model, with this "
                 "set, differs from the paper.")
    rep.add_text("Findings about vibrating or not are checked twice: with the chatter "
                 "verdict (does the vibration grow) and, separately, with the paper's own "
                 "criterion (Ra above the tolerance); the 'checked by' column says which.")
    rep.add_table([{"paper's finding": c["finding"], "checked by": c.get("verdict", ""),
                    "our result": c["ours"],
                    "agrees": {True: "yes", False: "NO", None: "n/a"}[c["agrees"]]}
                   for c in checks], caption="Qualitative checks")
    for c in checks:
        if c["agrees"] is False:
            rep.add_note(f"Disagreement ({c.get('verdict', '')}): the paper finds "
                         f"'{c['finding']}'; our model gives {c['ours']}.")

    rep.add_section("All conditions")
    rep.add_table([{"system": r["system"], "n [r/min]": r["speed_rpm"],
                    "f [mm/r]": r["feed_mm_per_rev"], "ap [mm]": r["depth_of_cut_mm"],
                    "P [MPa]": r["pressure_MPa"],
                    "Fx amp [N]": (r["summary"] or {}).get("force_amplitude_x_N"),
                    "Fy amp [N]": (r["summary"] or {}).get("force_amplitude_y_N"),
                    "Fz amp [N]": (r["summary"] or {}).get("force_amplitude_z_N"),
                    "feed amp [um]": (r["summary"] or {}).get("feed_amplitude_um"),
                    "feed amp growth": (r["summary"] or {}).get("feed_amplitude_growth"),
                    "Ra, form removed [um]": (r["summary"] or {}).get("roughness_Ra_um"),
                    "verdict": _verdict_text(r["summary"]),
                    "chatter": (r["summary"] or {}).get("chatter"),
                    "leaves cut": (r["summary"] or {}).get("tool_leaves_cut"),
                    "paper's criterion": (None if not r["summary"]
                                          or r["summary"].get("stable") is None
                                          else ("stable" if r["summary"]["stable"]
                                                else "vibratory"))}
                   for r in rows], caption="Summary per condition (verdict: CHATTER = the "
                  "vibration grows; rough = Ra above the tolerance without chatter; the "
                  "paper's criterion is Ra alone)")
    rep.add_text("Files: results.nc (all conditions), sweep/results/<key>.nc (one condition "
                 "each, time histories decimated), paper_summary.json, equivalent_model.json, "
                 "coefficients.json.")
    return rep


__all__ = ["build_report", "modal_figure_pngs", "coefficient_set_section", "force_model_fe_text", "force_model_validation"]
