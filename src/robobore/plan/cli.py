"""``robobore plan posture``: where and how the robot should hold the boring tool."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer

from robobore.clitools import JSON_OPTION, emit, fmt, handle_errors, kv_table, progress_bar, stdout
from robobore.errors import ConfigError
from robobore.plan.posture import SD_TOP


@handle_errors
def posture_cmd(
    config: Path = typer.Argument(..., help="Plan config (TOML; see docs/plan.md)."),
    out: Path | None = typer.Option(None, "--out",
                                    help="Folder for posture_plan.nc and posture_plan.json."),
    plot: Path | None = typer.Option(None, "--plot", help="Write PNG plots into this folder."),
    top: int = typer.Option(10, "--top", help="Rows of the candidate table (best first)."),
    x_hint: str | None = typer.Option(
        None, "--x-hint", help="x,y,z: the boring frame's X is this direction projected onto "
        "the plane normal to the bore axis (overrides bore.x_hint; default: horizontal, for a "
        "vertical bore the base x axis projected)."),
    as_json: bool = JSON_OPTION,
) -> None:
    """Rate every posture that reaches a bore (tool-axis rotation x IK branch) by stiffness,
    modes and critical depth with the calibrated pose-dependent model; recommend the best."""
    from dataclasses import replace

    import numpy as np

    from robobore.io.results import write_json, write_netcdf
    from robobore.plan.posture import plan_posture, results_dataset, workspace_map

    if out is not None and out.exists() and not out.is_dir():
        raise ConfigError("--out must be a folder", field="--out", value=str(out),
                          expected="a folder (created if missing)")
    if top < 0:
        raise ConfigError("negative row count", field="--top", value=top, expected=">= 0")

    def factory(desc: str, total: int):
        return progress_bar(desc, total, not as_json)

    hint = None
    if x_hint is not None:
        from robobore.clitools import parse_floats

        hint = parse_floats(x_hint, 3, "--x-hint", "(a direction, base frame)")
    result = plan_posture(config, progress_factory=factory, x_hint=hint)
    ws = None
    inp = result.arrays.inputs
    if inp.cfg.workspace is not None:
        n = len(inp.cfg.workspace.dx_m) * len(inp.cfg.workspace.dy_m)
        with progress_bar("workspace map", n, not as_json) as adv:
            ws = workspace_map(result, adv)
        result = replace(result, workspace=ws)
    pub = result.to_dict()
    for w in pub.get("warnings", []):
        from robobore.clitools import stderr

        stderr.print(f"[yellow]warning:[/] {w}", soft_wrap=True, highlight=False)
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        write_netcdf(results_dataset(result), out / "posture_plan.nc", config=inp.raw)
        write_json(out / "posture_plan.json", pub)
        pub["out"] = [str(out / "posture_plan.nc"), str(out / "posture_plan.json")]
    if plot is not None:
        from robobore.plan.plots import plot_posture_plan

        pub["plots"] = [str(p) for p in plot_posture_plan(result, plot, ws)]

    def render(r: dict[str, Any]) -> None:
        from rich.table import Table

        rec = r["recommended"]
        rows = [("criterion", f"{r['criterion']} [{r['criterion_unit']}]"),
                ("candidates (rotations x branches)",
                 f"{r['counts']['candidates']} of {r['counts']['ik_solutions_tried']} "
                 f"({r['counts']['rotations']} rotations)"),
                ("largest tool-point / axis error", f"{fmt(r['max_position_error_mm'])} mm / "
                                                     f"{fmt(r['max_axis_error_deg'])} deg"),
                ("calibration rms frequency residual (%)",
                 r["calibration"]["rms_frequency_residual_percent"]),
                ("recommended joints (deg)", ", ".join(f"{v:.2f}" for v in rec["joints_deg"])),
                ("recommended rotation (deg) / branch",
                 f"{rec['tool_axis_rotation_deg']:.2f} / {rec['branch']} ({rec['branch_label']})"),
                ("recommended criterion", rec["criterion_value"])]
        m = r["measured"]
        if m is not None:
            rows.append(("measured posture criterion", m["criterion_value"]))
        else:
            rows.append(("measured posture", "not a candidate (does not hold this bore)"))
        if r.get("synthetic_inputs"):
            rows.append(("inputs", "SYNTHETIC identification results"))
        rows.append(("critical depth method",
                     f"semi-discretization at {fmt(r['cutting']['speed_rpm'])} r/min (the "
                     f"cutting speed) for the best {SD_TOP} of a frequency-domain screen and "
                     "the measured posture (critical_depth_method per candidate); b_min: the "
                     "lowest over the speed range"))
        for w in r.get("warnings", []):
            rows.append(("warning", w))
        for n in r.get("notes", []):
            rows.append(("note", n))
        rows.append(("wall time (s)", r["wall_time_s"]))
        stdout.print(kv_table("posture plan", rows))
        t = Table(title=f"best {top} candidates", header_style="bold")
        for c in ("rot (deg)", "branch", "k_x", "k_y", "k_z (N/um)", "f1 (Hz)",
                  "b_crit (mm)", "b_min range (mm)", "feed amp (um)"):
            t.add_column(c, justify="right")
        crit = np.array([c.get("critical_depth_mm") or np.inf if r["criterion"] ==
                         "critical_depth" else 0.0 for c in r["candidates"]])
        if r["criterion"] != "critical_depth":
            key = {"stiffness_min": None}.get(r["criterion"], r["criterion"][-1])
            crit = np.array([min(c["directional_stiffness_N_per_m"].values()) if key is None
                             else c["directional_stiffness_N_per_m"][key]
                             for c in r["candidates"]])
        rec_key = (rec["tool_axis_rotation_deg"], rec["branch"])
        first = np.array([(c["tool_axis_rotation_deg"], c["branch"]) == rec_key
                          for c in r["candidates"]])
        for i in np.lexsort((~first, -crit))[:top]:
            c = r["candidates"][int(i)]
            k = c["directional_stiffness_N_per_m"]
            t.add_row(f"{c['tool_axis_rotation_deg']:.1f}", str(c["branch"]),
                      fmt(k["x"] * 1e-6), fmt(k["y"] * 1e-6), fmt(k["z"] * 1e-6),
                      fmt(c["modes"][0]["frequency_Hz"]),
                      fmt(c["critical_depth_mm"]) + (
                          "" if c["critical_depth_method"] == "semi-discretization" else " (FD)"),
                      fmt(c["critical_depth_range_min_mm"]),
                      fmt(c["feed_amplitude_um"]))
        stdout.print(t)

    emit(pub, as_json, render)


def register(groups: dict[str, typer.Typer]) -> None:
    """Add this stage's commands to the shared command groups."""
    groups["plan"].command("posture")(posture_cmd)
