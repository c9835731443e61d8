"""CLI commands of the study stage (registered by ``robobore.cli``).

``robobore sweep CONFIG.toml`` and ``robobore compare MEASURED.csv RESULTS_DIR``.
Dask, xarray and matplotlib are imported inside the commands.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import typer
from rich.markup import escape

from robobore.clitools import (
    JSON_OPTION,
    emit,
    fmt,
    handle_errors,
    kv_table,
    stage_progress,
    stderr,
    stdout,
)

ALLOW_FAILURES_OPTION = typer.Option(
    False, "--allow-failures", help="Exit 0 even when some conditions failed (they are still "
    "listed and recorded).")


def _render_sweep(res: dict[str, Any]) -> None:
    from rich.table import Table

    stdout.print(kv_table(f"sweep {res['name']}", [
        ("results store", res["store"]),
        ("mode", res["mode"]),
        ("conditions", res["total"]),
        ("already done (skipped)", res["skipped"]),
        ("computed now", res["computed"]),
        ("failed now", res["failed"]),
        ("not done (failed or pending)", res["pending"]),
        ("wall time, s", res["wall_time_s"]),
        ("conditions/s", res["conditions_per_s"]),
    ]))
    if res["failures"]:
        t = Table(title="failed conditions (see failed/<key>.json for tracebacks)",
                  header_style="bold red")
        for c in ("key", "condition", "error"):
            t.add_column(c)
        for f in res["failures"][:30]:
            c = f["condition"]
            t.add_row(f["key"], f"n={fmt(c['speed_rpm'])} f={fmt(c['feed_mm_per_rev'])} "
                      f"ap={fmt(c['depth_of_cut_mm'])} P={fmt(c['pressure_MPa'])}",
                      f["error"][:120])
        stdout.print(t)


def sweep_cmd(
    config: Path = typer.Argument(..., help="Sweep config TOML (see docs/study.md)."),
    scheduler: str | None = typer.Option(
        None, "--scheduler", help="Address of a running Dask scheduler (tcp://host:port); "
        "default: start a local cluster."),
    workers: int | None = typer.Option(
        None, "--workers", min=0, help="Local cluster workers (default: CPU count; "
        "0 = run in this process without Dask)."),
    threads: bool = typer.Option(
        False, "--threads", help="Local workers as threads of this process, not processes."),
    out: Path | None = typer.Option(
        None, "--out", help="Results store folder (default: ./sweep-<name>)."),
    report: Path | None = typer.Option(
        None, "--report", help="Also write a self-contained HTML report of the sweep here."),
    status: bool = typer.Option(
        False, "--status", help="Only show what is done / failed / pending; compute nothing."),
    allow_failures: bool = ALLOW_FAILURES_OPTION,
    as_json: bool = JSON_OPTION,
) -> None:
    """Run a sweep of cutting conditions (resumable: finished conditions are skipped).

    Exit code 0 when every condition is done, 1 when some failed or are not done (they are
    listed, and recorded with their traceback in the store, and the store's index and the
    report say which and why; run the command again to retry them); --allow-failures
    exits 0 all the same.
    """
    import warnings

    from robobore.io.outputs import check_output_dir, check_output_file
    from robobore.study.store import StoreWarning
    from robobore.study.sweep import plan_from_file, run_sweep

    plan = plan_from_file(config)
    if scheduler is not None and workers is not None:
        from robobore.errors import ConfigError

        raise ConfigError("give either --scheduler or --workers", field="--workers",
                          value=workers, expected="no --workers with an external scheduler")
    store = out if out is not None else Path(f"sweep-{plan.name}")
    if status:
        _status(plan, store, as_json)
        return
    check_output_dir(store, "--out", "the results store")
    check_output_file(report, "--report", "the HTML report")
    with warnings.catch_warnings(), stage_progress(sys.stderr.isatty()) as progress:
        warnings.simplefilter("ignore", StoreWarning)  # printed below, one line each
        outcome = run_sweep(plan, store, scheduler=scheduler, workers=workers,
                            processes=not threads, progress=progress)
    for w in outcome.warnings:
        stderr.print(f"[yellow]warning:[/] {escape(w)}", soft_wrap=True)
    res = {"name": plan.name, "runner": plan.runner, **outcome.to_dict()}
    if report is not None:
        from robobore.study.plots import sweep_report
        from robobore.study.store import ResultsStore

        sweep_report(ResultsStore(store), [i.key for i in plan.items],
                     title=f"Sweep {plan.name}").write(report)
        res["report"] = str(report)
    emit(res, as_json, _render_sweep)
    if outcome.pending and not allow_failures:
        raise typer.Exit(code=1)


def _status(plan: Any, store_dir: Path, as_json: bool) -> None:
    from robobore.study.store import ResultsStore

    if not (store_dir / "store.json").is_file():
        counts = {"done": 0, "failed": 0, "pending": len(plan.items)}
        failures: list[dict[str, Any]] = []
    else:
        st = ResultsStore(store_dir)
        counts = {"done": 0, "failed": 0, "pending": 0}
        failures = []
        for i in plan.items:
            s = st.status(i.key)
            counts[s] += 1
            if s == "failed":
                rec = st.failure(i.key) or {}
                failures.append({"key": i.key, "condition": i.condition,
                                 "error": rec.get("error", ""),
                                 "attempts": rec.get("attempts", 0)})
    res = {"name": plan.name, "store": str(store_dir), "total": len(plan.items), **counts,
           "failures": failures}

    def render(r: dict[str, Any]) -> None:
        stdout.print(kv_table(f"sweep {r['name']} (status only)", [
            ("results store", r["store"]), ("conditions", r["total"]), ("done", r["done"]),
            ("failed", r["failed"]), ("pending", r["pending"])]))
        for f in r["failures"][:30]:
            stdout.print(f"[red]failed[/] {f['key']} ({f['attempts']}x): {f['error'][:120]}")

    emit(res, as_json, render)


def _pct(v: float | None) -> str:
    return "—" if v is None else f"{100.0 * v:.2f} %"


def _render_compare(res: dict[str, Any]) -> None:
    from rich.table import Table

    t = Table(title="measured vs simulated (relative error)", header_style="bold")
    for c in ("row", "n [r/min]", "f [mm/r]", "ap [mm]", "P [MPa]", "group", "quantity",
              "measured", "simulated", "rel. error"):
        t.add_column(c, justify="right")
    for r in res["conditions"]:
        c = r["condition"]
        for q, e in r["quantities"].items():
            t.add_row(str(r["row"]), fmt(c["speed_rpm"]), fmt(c["feed_mm_per_rev"]),
                      fmt(c["depth_of_cut_mm"]), fmt(c["pressure_MPa"]), r["group"], q,
                      fmt(e["measured"]), fmt(e["simulated"]), _pct(e["rel_error"]))
    stdout.print(t)
    g = Table(title=f"relative error per group (groups from the {res['group_source']} "
              "stable flag)", header_style="bold")
    for c in ("group", "conditions", "values", "min", "max", "mean"):
        g.add_column(c, justify="right")
    for name, s in res["groups"].items():
        g.add_row(name, str(s["n_conditions"]), str(s["n"]), _pct(s["min_rel_error"]),
                  _pct(s["max_rel_error"]), _pct(s["mean_rel_error"]))
    stdout.print(g)
    a = res["agreement"]
    for w in res.get("warnings", []):
        stdout.print(f"[yellow]warning:[/] {w}")
    if len(res.get("systems_in_store", [])) > 1:
        stdout.print(f"[dim]note: compared the {res['system']} results; the store also holds "
                     + ", ".join(x for x in res["systems_in_store"] if x != res["system"])
                     + " (--system NAME)[/]")
    stdout.print(kv_table("stable / vibratory agreement", [
        ("conditions with both flags", a["n"]), ("agree", a["agree"]),
        ("agreement rate", None if a["rate"] is None else f"{100 * a['rate']:.1f} %"),
        ("measured stable, simulated vibratory", a["measured_stable_simulated_vibratory"]),
        ("measured vibratory, simulated stable", a["measured_vibratory_simulated_stable"]),
    ]))
    if res["unmatched_measured"]:
        rows = ", ".join(str(u["row"]) for u in res["unmatched_measured"])
        stdout.print(f"[yellow]measured rows without a simulated condition:[/] {rows}")
    for u in res["undefined"]:
        stdout.print(f"[yellow]row {u['row']} {u['quantity']}:[/] {u['reason']}")


def compare_cmd(
    measured: Path = typer.Argument(..., help="Measured CSV, or a manifest of record files "
                                              "(force_file, displacement_file columns) measured "
                                              "as by 'measure cut' (docs/study.md)."),
    results: Path = typer.Argument(..., help="Results store folder written by 'robobore sweep',"
                                             " or the output folder of 'robobore paper'."),
    report: Path | None = typer.Option(None, "--report", help="Also write an HTML report here."),
    system: str | None = typer.Option(
        None, "--system", help="Simulated system to compare when the results hold several "
                               "(robobore paper: robot, machine_tool; default robot)."),
    as_json: bool = JSON_OPTION,
) -> None:
    """Compare measurements with a sweep's results: relative errors, groups, agreement."""
    from robobore.io.outputs import check_output_file
    from robobore.study.compare import compare_results

    check_output_file(report, "--report", "the HTML report")
    from robobore.clitools import stage_progress

    with stage_progress(not as_json) as progress:
        cmp = compare_results(measured, results, system, progress=progress)
    res = cmp.to_dict()
    res["measured"] = str(measured)
    res["results"] = str(results)
    if report is not None:
        from robobore.study.plots import comparison_report

        comparison_report(cmp, title=f"Comparison: {measured.name} vs {results.name}").write(report)
        res["report"] = str(report)
    emit(res, as_json, _render_compare)


def register(groups: dict[str, typer.Typer]) -> None:
    """Add this stage's commands to the shared command groups."""
    root = groups["root"]
    root.command("sweep")(handle_errors(sweep_cmd))
    root.command("compare")(handle_errors(compare_cmd))
    register_main(groups)


# --- robobore paper / robobore calibrate forces (issue 6 main job) ------------------------


def _render_paper(res: dict[str, Any]) -> None:
    from rich.table import Table

    stdout.print(kv_table("robobore paper" + (" (SYNTHETIC example data)"
                                              if res.get("synthetic_inputs") else ""), [
        ("report", res["report"]),
        ("conditions", res["conditions"]),
        ("computed", res["computed"]),
        ("chatter (vibration grows)", res.get("chatter")),
        ("rough (Ra, form removed, > tolerance)", res.get("rough")),
        ("tool leaves the cut", res.get("tool_leaves_cut")),
        ("stable, paper's criterion", res["stable"]),
        ("vibratory, paper's criterion", res["vibratory"]),
        ("failed", len(res["failed"])),
        ("force coefficients (boring model)", (res.get("coefficient_set") or {}).get("name")),
        ("force calibration (report's FE section)", res.get("coefficients_mode")),
        ("wall time, s", res["wall_time_s"]),
    ]))
    sweep_w = set((res.get("sweep") or {}).get("warnings", []))  # printed on stderr
    for w in res.get("warnings", []):
        if w not in sweep_w:
            stdout.print(f"[yellow]warning:[/] {escape(w)}", soft_wrap=True)
    if res["failed"]:
        t = Table(title="failed conditions", header_style="bold red")
        for c in ("system", "condition", "error"):
            t.add_column(c)
        for f in res["failed"][:30]:
            c = f["condition"]
            t.add_row(f["system"], f"n={fmt(c['speed_rpm'])} f={fmt(c['feed_mm_per_rev'])} "
                      f"ap={fmt(c['depth_of_cut_mm'])} P={fmt(c['pressure_MPa'])}",
                      escape(str(f.get("error"))[:160]))
        stdout.print(t)
    cmp = res.get("comparison")
    if cmp:
        t = Table(title="relative error vs measured (SYNTHETIC)", header_style="bold")
        for c in ("group", "conditions", "min", "max", "mean"):
            t.add_column(c, justify="right")
        for name, s in cmp["groups"].items():
            t.add_row(name, str(s.get("n_conditions")), _pct(s.get("min_rel_error")),
                      _pct(s.get("max_rel_error")), _pct(s.get("mean_rel_error")))
        stdout.print(t)
    t = Table(title="the paper's findings, checked on our results", header_style="bold")
    for c in ("paper's finding", "checked by", "our result", "agrees"):
        t.add_column(c)
    for c in res["qualitative_checks"]:
        t.add_row(c["finding"], c.get("verdict", ""), c["ours"],
                  {True: "yes", False: "[red]NO[/]", None: "n/a"}[c["agrees"]])
    stdout.print(t)


def paper_cmd(
    config: Path | None = typer.Argument(
        None, help="Paper study config TOML (default: the bundled SYNTHETIC example)."),
    out: Path = typer.Option(Path("paper-results"), "--out", help="Output folder."),
    fast: bool = typer.Option(False, "--fast", help="Use the stored force calibration "
                              "([coefficients] file) instead of running the FE calibration."),
    workers: int = typer.Option(2, "--workers", min=0, help="Worker processes for the "
                                "sweep (a forked process pool) and FE processes (0 = serial)."),
    allow_failures: bool = ALLOW_FAILURES_OPTION,
    as_json: bool = JSON_OPTION,
) -> None:
    """The paper's whole study: identify, model, calibrate, sweep, compare, report.

    Exit code 1 when any condition failed (the report and the results are written all the
    same and list the failed conditions with their errors); --allow-failures exits 0.
    """
    import warnings

    from robobore.io.outputs import check_output_dir
    from robobore.study.paper import run_paper
    from robobore.study.store import StoreWarning

    check_output_dir(out, "--out", "the study's results")
    with warnings.catch_warnings(), \
            stage_progress(sys.stderr.isatty() and not as_json) as progress:
        warnings.simplefilter("ignore", StoreWarning)  # printed below, one line each
        res = run_paper(config, out, fast=fast, workers=workers, progress=progress).to_dict()
    for w in res.get("sweep", {}).get("warnings", []):
        stderr.print(f"[yellow]warning:[/] {escape(w)}", soft_wrap=True)
    emit(res, as_json, _render_paper)
    if res["failed"] and not allow_failures:
        stderr.print(f"[bold red]error:[/] {len(res['failed'])} of {res['conditions']} "
                     "conditions failed (listed in the report and paper_summary.json); "
                     "--allow-failures exits 0 all the same", soft_wrap=True)
        raise typer.Exit(code=1)


def _render_calibration(res: dict[str, Any]) -> None:
    from rich.table import Table

    from robobore.cutting.calibrate import predicted_forces

    t = Table(title=f"virtual orthogonal tests ({res['material']}, FE 2D)", header_style="bold")
    for c in ("h [um]", "vc [m/min]", "Fc FE [N/mm]", "Fc fit", "err", "Ff FE [N/mm]",
              "Ff fit", "err"):
        t.add_column(c, justify="right")
    for p in predicted_forces(res):
        t.add_row(fmt(p["h_um"]), fmt(p["vc_m_per_min"]), fmt(p["Fc_fe"] * 1e-3),
                  fmt(p["Fc_fit"] * 1e-3), _pct(p["Fc_rel_error"]), fmt(p["Ff_fe"] * 1e-3),
                  fmt(p["Ff_fit"] * 1e-3), _pct(p["Ff_rel_error"]))
    stdout.print(t)
    per = res.get("per_speed_fits") or {}
    if len(per) >= 2:  # what the boring model uses: these, interpolated at its cutting speed
        t = Table(title="per-speed fits (used at the cutting speed: linear in ln(vc), held "
                  "outside; speed_dependent = false: the pooled set below)",
                  header_style="bold")
        for col in ("vc [m/min]", "Ktc_N_per_m2", "Kte_N_per_m", "Kfc_N_per_m2",
                    "Kfe_N_per_m"):
            t.add_column(col, justify="right")
        for v, k in per.items():
            t.add_row(v, fmt(k["Ktc_N_per_m2"]), fmt(k["Kte_N_per_m"]),
                      fmt(k["Kfc_N_per_m2"]), fmt(k["Kfe_N_per_m"]))
        stdout.print(t)
    c, se = res["coefficients"], res["standard_errors"]
    stdout.print(kv_table("fitted coefficients (± standard error)", [
        (k, f"{fmt(c[k])} ± {fmt(se.get(k))}" if se.get(k) is not None else fmt(c[k]))
        for k in ("Ktc_N_per_m2", "Kte_N_per_m", "Kfc_N_per_m2", "Kfe_N_per_m",
                  "Krc_N_per_m2", "Kre_N_per_m")] + [
        ("FE points from cache", res.get("fe_cached_points")),
        ("file", res.get("file", "(not written; use --out)")),
        ("wall time, s", res.get("wall_time_s"))]))
    for w in res.get("warnings", []):
        stdout.print(f"[yellow]warning:[/] {w}")


def calibrate_forces_cmd(
    config: Path | None = typer.Argument(
        None, help="TOML with a [calibration] table (+ [insert], [material]); default: the "
        "bundled paper example."),
    out: Path | None = typer.Option(None, "--out", help="Write the coefficients file (JSON)."),
    workers: int = typer.Option(2, "--workers", min=1, help="FE runs in parallel (processes)."),
    as_json: bool = JSON_OPTION,
) -> None:
    """FE-calibrated mechanistic coefficients: 2D FE over h x vc, least-squares fit."""
    from robobore.clitools import progress_bar
    from robobore.cutting.calibrate import calibrate_forces
    from robobore.cutting.calibration_config import load_calibration_config
    from robobore.io.outputs import check_output_file
    from robobore.study.paper_config import PaperConfig, example_config_path

    check_output_file(out, "--out", "the coefficients JSON")
    path = config if config is not None else example_config_path()
    # a paper config holds a calibration: its other sections are accepted
    cfg = load_calibration_config(path, other_sections=PaperConfig.model_fields)
    n = len(cfg.uncut_chip_thickness_um) * len(cfg.cutting_speed_m_per_min)
    with progress_bar("FE virtual cutting tests", total=n,
                      enabled=sys.stderr.isatty() and not as_json) as advance:
        res = calibrate_forces(cfg, out=out, workers=workers, progress=advance)
    res["config"] = str(path)
    emit(res, as_json, _render_calibration)


def register_main(groups: dict[str, typer.Typer]) -> None:
    groups["root"].command("paper")(handle_errors(paper_cmd))
    groups["calibrate"].command("forces")(handle_errors(calibrate_forces_cmd))
