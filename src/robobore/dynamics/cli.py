"""CLI commands of the process stage: ``robobore lobes``, ``robobore simulate boring``,
``robobore model equivalent`` (registered by ``robobore.cli``)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import typer

from robobore.clitools import (
    JSON_OPTION,
    check_option,
    emit,
    fmt,
    handle_errors,
    kv_table,
    parse_floats,
    progress_bar,
    stdout,
)
from robobore.errors import ConfigError


def _read_json(path: Path, what: str) -> dict[str, Any]:
    from robobore.io.readers import load_json

    return load_json(path, f"{what} file", "a JSON object (as written by robobore --json)")


# ----------------------------------------------------------------------------- model files
STIFFNESS_FILE_OPTION = typer.Option(
    None, "--stiffness-file",
    help="Joint-stiffness JSON of `robobore identify stiffness --json` (with --modes-file); "
         "the robot model, instead of [structure]/[equivalent] in the TOML.")
MODES_FILE_OPTION = typer.Option(
    None, "--modes-file", help="Modes JSON of `robobore identify modes --json` (with "
                               "--stiffness-file).")
EQUIVALENT_FILE_OPTION = typer.Option(
    None, "--equivalent-file", help="Equivalent-model JSON of `robobore model equivalent "
                                    "--json` (instead of the two files above).")


# ----------------------------------------------------------------------------- lobes
@handle_errors
def lobes_cmd(
    config: Path = typer.Argument(..., help="TOML config ([structure]/[equivalent] or [model] "
                                            "files or the file options, + [process] or "
                                            "boring sections, [speed_rpm])."),
    method: str = typer.Option("semidiscretization", "--method",
                               help="semidiscretization (default; periodic directions and "
                                    "depth modulation of the rotating bar) or frequency "
                                    "(zero-order, fast)."),
    stiffness_file: Path | None = STIFFNESS_FILE_OPTION,
    modes_file: Path | None = MODES_FILE_OPTION,
    equivalent_file: Path | None = EQUIVALENT_FILE_OPTION,
    plot: Path | None = typer.Option(None, "--plot", help="Write lobes.png into this folder."),
    band: bool = typer.Option(False, "--band", help="Add the 90 % band from the equivalent "
                              "model's uncertainty (modes' intervals or calibrate dynamics)."),
    band_speeds: int = typer.Option(40, "--band-speeds", help="Speeds of the band."),
    as_json: bool = JSON_OPTION,
) -> None:
    """Stability lobes: critical depth of cut vs spindle speed."""
    import numpy as np

    from robobore.dynamics import stability
    from robobore.dynamics.config import (
        build_coefficients,
        build_process,
        build_structure,
        load_dynamics_config,
        speed_range,
    )
    from robobore.io.outputs import check_output_dir

    check_output_dir(plot, "--plot", "lobes.png")
    cfg, _ = load_dynamics_config(config, stiffness_file, modes_file, equivalent_file)
    src = str(config)
    st = build_structure(cfg, src)
    coef = build_coefficients(cfg, src) if cfg.is_boring else None
    pr = build_process(cfg, src, coefficients=coef)
    sp, default_note = speed_range(cfg)
    speeds = np.linspace(sp.min, sp.max, sp.count)
    if band:
        from robobore.dynamics.cli_calibrate import band_uncertainty

        band_uncertainty(cfg, src, band_speeds)
    if method not in ("frequency", "semidiscretization"):
        raise ConfigError("unknown method", field="--method", value=method,
                          expected="frequency or semidiscretization")
    notes = [] if default_note is None else [default_note]
    if coef is not None:
        from robobore.dynamics.config import lobe_coefficient_note

        cnote = lobe_coefficient_note(cfg, coef)
        if cnote is not None:
            notes.append(cnote)
    if method == "frequency":
        res = stability.lobes_frequency_domain(st, pr, speeds)
        if pr.rotating:
            notes.append("rotating boring bar: zero-order (revolution-averaged) directions; "
                         "the depth-modulation stiffness is not in the frequency-domain "
                         "solution -- cross-check with --method semidiscretization")
    else:
        with progress_bar("semi-discretisation", speeds.size, not as_json) as adv:
            res = stability.lobes_semidiscretization(st, pr, speeds, progress=adv)
        n_stable = int(np.sum(~np.isfinite(res.critical_depth_m)))
        top = res.depth_scan_max_m * 1e3
        if res.unconditionally_stable:
            notes.append(f"unconditionally stable up to {top:g} mm at every speed (the top of "
                         "the depth scan)")
        elif n_stable:
            notes.append(f"stable up to {top:g} mm (the top of the depth scan) at {n_stable} "
                         f"of {speeds.size} speeds")
        below = (res.interrupted_below_m if res.interrupted_below_m is not None
                 else np.zeros(speeds.size))
        cut0 = res.critical_depth_m == 0.0
        zero = speeds[cut0 & (below == 0.0)]
        if zero.size:
            notes.append(f"unstable at vanishing depth at {zero.size} speed(s) "
                         f"({zero.min():.0f}-{zero.max():.0f} r/min): an instability that does "
                         "not need the regenerative cut (the rotating bar's depth-modulation "
                         "stiffness, parametric); critical depth 0")
        inter = speeds[cut0 & (below > 0.0)]
        if inter.size:
            notes.append(f"no chatter-free depth at {inter.size} speed(s) "
                         f"({inter.min():.0f}-{inter.max():.0f} r/min): the steady forced "
                         "vibration takes the tool out of the material up to the linear limit "
                         "(interrupted cut, outside the linear model); critical depth 0, the "
                         "linear limit in interrupted_below_mm")
        part = speeds[(~cut0) & (below > 0.0)]
        if part.size:
            notes.append(f"at {part.size} speed(s) the steady forced vibration takes the tool "
                         "out of the material below interrupted_below_mm: chatter-free "
                         "between that depth and the critical depth")
    mc = stability.mode_coupling_limit(st, pr)
    out = res.to_dict()
    out["mode_coupling_limit_mm"] = mc * 1e3 if math.isfinite(mc) else None
    out["process"] = pr.label
    if pr.depth_dependent:
        notes.append("boring process built from its chip geometry at every trial depth (the "
                     "chip the time domain integrates at that depth)")
    out["notes"] = notes
    out["warnings"] = [] if coef is None else coef.domain_warnings(pr.h0)
    if plot is not None:
        curves = stability.lobe_curves(st, pr, 12) if method == "frequency" else None
        out["plot"] = str(stability_plot(res, plot, curves, pr.label))
    if band:
        from robobore.dynamics.cli_calibrate import lobes_band

        out["band"] = lobes_band(cfg, st, pr, np.linspace(sp.min, sp.max, band_speeds), plot,
                                 src, not as_json)

    def render(r: dict[str, Any]) -> None:
        d = np.asarray(res.critical_depth_m) * 1e3
        i = int(np.nanargmin(np.where(np.isfinite(d), d, np.nan))) if np.isfinite(d).any() else 0
        j = int(np.nanargmax(np.where(np.isfinite(d), d, np.nan))) if np.isfinite(d).any() else 0
        rows = [("method", res.method), ("process", pr.label),
                ("speeds (r/min)", f"{speeds[0]:g} .. {speeds[-1]:g} ({speeds.size})"),
                ("absolute limit (mm)", r["absolute_limit_mm"] if math.isfinite(
                    r["absolute_limit_mm"]) else f"none up to {r.get('depth_scan_max_mm')} mm"),
                ("lowest critical depth (mm) at r/min", f"{fmt(d[i])} at {speeds[i]:.0f}"
                 if np.isfinite(d).any() else "none (stable at every speed)"),
                ("best pocket (mm) at r/min", f"{fmt(d[j])} at {speeds[j]:.0f}"
                 if np.isfinite(d).any() else "none (stable at every speed)"),
                ("mode-coupling limit (mm)", r["mode_coupling_limit_mm"])]
        if "plot" in r:
            rows.append(("plot", r["plot"]))
        for w in r["warnings"]:
            rows.append(("warning (coefficients)", w))
        stdout.print(kv_table("stability lobes", rows))
        for n in notes:
            stdout.print(f"[dim]note: {n}[/]")

    emit(out, as_json, render)


def stability_plot(res, plot_dir: Path, curves, label: str) -> Path:
    from robobore.dynamics.plots import plot_lobes

    return plot_lobes(res, plot_dir, curves, title=f"stability lobes -- {label}")


# ----------------------------------------------------------------------------- simulate
@handle_errors
def simulate_boring_cmd(
    config: Path = typer.Argument(..., help="TOML config (as for `robobore lobes`)."),
    stiffness_file: Path | None = STIFFNESS_FILE_OPTION,
    modes_file: Path | None = MODES_FILE_OPTION,
    equivalent_file: Path | None = EQUIVALENT_FILE_OPTION,
    speed_rpm: float | None = typer.Option(None, "--speed-rpm",
                                           help="Spindle speed [r/min] (default [cutting])."),
    depth_mm: float | None = typer.Option(None, "--depth-mm",
                                          help="Depth of cut [mm] (default [cutting])."),
    feed_mm_per_rev: float | None = typer.Option(
        None, "--feed-mm-per-rev", help="Feed [mm/r] (default [cutting] or [process])."),
    pressure_MPa: float | None = typer.Option(
        None, "--pressure-MPa",
        help="Pressure-foot pressure [MPa] (boring configs with [equivalent]; 0 = no foot)."),
    revolutions: int | None = typer.Option(None, "--revolutions",
                                           help="Revolutions (default [simulation], 150)."),
    samples_per_rev: int | None = typer.Option(None, "--samples-per-rev",
                                               help="Samples per revolution (default auto)."),
    out: Path | None = typer.Option(None, "--out", help="Write the Dataset to this .nc file."),
    plot: Path | None = typer.Option(None, "--plot", help="Write PNG plots into this folder."),
    as_json: bool = JSON_OPTION,
) -> None:
    """Time-domain boring simulation with regeneration; chatter, surface-finish,
    tool-leaves-cut and paper's-criterion verdicts."""
    from dataclasses import replace

    from robobore.dynamics.api import run_boring
    from robobore.dynamics.config import load_dynamics_config
    from robobore.io.results import write_netcdf

    cfg, raw = load_dynamics_config(config, stiffness_file, modes_file, equivalent_file)
    if speed_rpm is None and cfg.cutting is None:
        raise ConfigError("no spindle speed", field="--speed-rpm",
                          expected="--speed-rpm N (r/min) or a [cutting] section")
    if depth_mm is None and cfg.cutting is None:
        raise ConfigError("no depth of cut", field="--depth-mm",
                          expected="--depth-mm A (mm) or a [cutting] section")
    if pressure_MPa is not None and not (math.isfinite(pressure_MPa) and 0.0 <= pressure_MPa
                                         <= 10.0):
        raise ConfigError("pressure out of range", field="--pressure-MPa", value=pressure_MPa,
                          expected="0 .. 10 MPa")
    from robobore.io.ranges import check_positive, check_value

    for opt, v, name in (("--speed-rpm", speed_rpm, "speed_rpm"), ("--depth-mm", depth_mm,
                         "depth_mm"), ("--feed-mm-per-rev", feed_mm_per_rev, "feed_mm_per_rev")):
        if v is not None:  # the one range of each quantity (robobore.io.ranges)
            check_positive(v, name, field=opt)
    if pressure_MPa is not None:
        check_value(pressure_MPa, "pressure_MPa", field="--pressure-MPa", kind=ConfigError)
    if out is not None and out.suffix != ".nc":
        raise ConfigError("output must be a netCDF file", field="--out", value=str(out),
                          expected="a path ending in .nc")
    from robobore.io.outputs import check_output_dir, check_output_file

    check_output_file(out, "--out", "the netCDF Dataset")
    check_output_dir(plot, "--plot", "the PNG plots")
    with progress_bar("simulating", None, not as_json):
        res = run_boring(cfg, speed_rpm, depth_mm, feed_mm_per_rev=feed_mm_per_rev,
                         pressure_MPa=pressure_MPa, revolutions=revolutions,
                         samples_per_rev=samples_per_rev, return_dataset=True,
                         source=str(config))
    ds = res.dataset
    result = replace(res, dataset=None, config=None).to_dict()
    speed_rpm, depth_mm = res.speed_rpm, res.depth_mm
    if out is not None:
        write_netcdf(ds, out, config=raw)
        result["out"] = str(out)
    if plot is not None:
        from robobore.dynamics.plots import plot_simulation

        result["plots"] = [str(p) for p in plot_simulation(ds, plot)]

    def render(r: dict[str, Any]) -> None:
        fin = {None: "no tolerance", "ok": "ok", "rough": "ROUGH"}[r["surface_finish"]]
        ch = "CHATTER" if r["chatter"] else "no"
        if r["chatter_cause"] not in (None, "regenerative"):
            ch += f" ({r['chatter_cause']})"
        sc = r.get("sampling_check")
        if not r["chatter_decided"]:
            ch += (" (undecided: changes with the sampling, see reasons)"
                   if sc is not None and not sc["agrees"] else
                   " (undecided: at the stability limit)")
        paper = {None: "not judged (no Ra tolerance)", True: "stable",
                 False: "VIBRATORY"}[r["stable"]]
        res_um = r["amplitude_resolution_um"]
        feed = (r["feed_amplitude_um"] if r["feed_amplitude_resolved"]
                else f"below {res_um * 1e3:g} nm (resolution)")
        rows = [("chatter (vibration grows)", ch),
                ("surface finish (Ra, form removed)", fin),
                ("tool leaves the cut", f"YES ({r.get('tool_leaves_cut_cause')})"
                 if r["tool_leaves_cut"] else "no"),
                ("paper's criterion (Ra > tolerance or chatter)", paper),
                ("chatter frequency (Hz)", r["chatter_frequency_Hz"]
                 if r["chatter_frequency_Hz"] is not None else "-"),
                ("growth per insert pitch (Floquet multiplier)",
                 f"{fmt(r['floquet_multiplier'])} +- {fmt(r['floquet_multiplier_se'])} (ln)"),
                ("vibration growth (envelope, feed, radial)",
                 f"{fmt(r['vibration_growth'])} / {fmt(r['feed_amplitude_growth'])} / "
                 f"{fmt(r['radial_amplitude_growth'])}"),
                *[(f"mean force {a} (N)", r["force_mean_N"][a]) for a in "xyz"],
                *[(f"force amplitude {a} (N)", r["force_amplitude_N"][a]) for a in "xyz"],
                ("feed amplitude (um)", feed),
                ("Ra / Rz, form removed (um)",
                 f"{fmt(r['roughness_Ra_um'])} / {fmt(r['roughness_Rz_um'])}"),
                ("Ra with form (um), taper (um/mm)",
                 f"{fmt(r['roughness_Ra_with_form_um'])}, {fmt(r['form_slope_um_per_mm'])}"),
                ("samples per revolution", r["samples_per_rev"]),
                ("revolutions simulated", r["revolutions_simulated"])]
        for why in r["reasons"]:
            rows.append(("reason", why))
        for w in r["coefficient_warnings"]:
            rows.append(("warning (coefficients)", w))
        stdout.print(kv_table(f"boring simulation, n = {speed_rpm:g} r/min, "
                              f"a = {depth_mm:g} mm", rows))

    emit(result, as_json, render)


# ----------------------------------------------------------------------------- equivalent
@handle_errors
def equivalent_cmd(
    stiffness_N_per_m: str | None = typer.Option(
        None, "--stiffness-N-per-m", help="Directional stiffness x,y,z [N/m]."),
    stiffness_file: Path | None = typer.Option(
        None, "--stiffness-file", help='JSON {"directional_stiffness_N_per_m": {x,y,z}}.'),
    modes_file: Path | None = typer.Option(
        None, "--modes-file", help='JSON {"modes": [{"frequency_Hz", "damping_ratio", ...}]}.'),
    frequencies_Hz: str | None = typer.Option(
        None, "--frequencies-Hz", help="Natural frequencies x,y,z [Hz] (instead of a file)."),
    damping_ratios: str | None = typer.Option(
        None, "--damping-ratios", help="Damping ratios x,y,z (with --frequencies-Hz)."),
    assign: str | None = typer.Option(
        None, "--assign", help="Mode indices for x,y,z, e.g. 0,2,1 (0-based)."),
    damping_N_s_per_m: float | None = typer.Option(
        None, "--damping-N-s-per-m", help="Given damping coefficient (the paper: 23.7)."),
    foot_pressure_MPa: float | None = typer.Option(
        None, "--foot-pressure-MPa", help="Add the pressure foot at this pressure [MPa]."),
    foot_piston_diameter_mm: float = typer.Option(
        50.0, "--foot-piston-diameter-mm", help="Piston diameter [mm] (assumed default 50)."),
    foot_normal_stiffness_N_per_m: float | None = typer.Option(
        None, "--foot-normal-stiffness-N-per-m", help="Contact stiffness (default Hertz)."),
    as_json: bool = JSON_OPTION,
) -> None:
    """Equivalent per-direction mass-spring-damper model (m = k / wn^2; c or zeta)."""
    from robobore.equivalent import EquivalentModel, PressureFoot

    if (stiffness_N_per_m is None) == (stiffness_file is None):
        raise ConfigError("give exactly one stiffness source", field="--stiffness-N-per-m",
                          expected="--stiffness-N-per-m x,y,z or --stiffness-file FILE.json")
    if stiffness_file is not None:
        stiff = _read_json(stiffness_file, "stiffness")
    else:
        k = parse_floats(stiffness_N_per_m, 3, "--stiffness-N-per-m", "N/m")
        stiff = {"directional_stiffness_N_per_m": dict(zip("xyz", k, strict=True))}
    if modes_file is not None:
        modes = _read_json(modes_file, "modes")
    elif frequencies_Hz is not None:
        f = parse_floats(frequencies_Hz, 3, "--frequencies-Hz", "Hz")
        z = (parse_floats(damping_ratios, 3, "--damping-ratios", "(ratio)")
             if damping_ratios is not None else [0.0] * 3)
        if damping_ratios is None and damping_N_s_per_m is None:
            raise ConfigError("no damping given", field="--damping-ratios",
                              expected="--damping-ratios x,y,z or --damping-N-s-per-m C")
        modes = {"modes": [{"frequency_Hz": a, "damping_ratio": b}
                           for a, b in zip(f, z, strict=True)]}
    else:
        raise ConfigError("no modes given", field="--modes-file",
                          expected="--modes-file FILE.json or --frequencies-Hz x,y,z")
    check_option(damping_N_s_per_m, "--damping-N-s-per-m")  # plausible ranges (io.ranges)
    check_option(foot_pressure_MPa, "--foot-pressure-MPa")
    check_option(foot_piston_diameter_mm, "--foot-piston-diameter-mm")
    check_option(foot_normal_stiffness_N_per_m, "--foot-normal-stiffness-N-per-m")
    if foot_pressure_MPa is not None and not foot_piston_diameter_mm > 0:
        raise ConfigError("no piston", field="--foot-piston-diameter-mm",
                          value=foot_piston_diameter_mm, expected="a diameter > 0 mm")
    assignment = None
    if assign is not None:
        idx = parse_floats(assign, 3, "--assign", "0-based mode indices")
        assignment = {a: int(i) for a, i in zip("xyz", idx, strict=True)}
    foot = None
    if foot_pressure_MPa is not None:
        if not 0 <= foot_pressure_MPa <= 10:
            raise ConfigError("out of range", field="--foot-pressure-MPa",
                              value=foot_pressure_MPa, expected="0 .. 10 MPa")
        foot = PressureFoot(pressure_Pa=foot_pressure_MPa * 1e6,
                            piston_area_m2=math.pi * (foot_piston_diameter_mm * 1e-3 / 2) ** 2,
                            normal_stiffness_N_per_m=foot_normal_stiffness_N_per_m)
    try:
        em = EquivalentModel.from_stiffness_and_modes(
            stiff, modes, assignment, damping_N_s_per_m=damping_N_s_per_m, foot=foot,
            names=(str(stiffness_file or "--stiffness-N-per-m"),
                   str(modes_file or "--frequencies-Hz")))
    except ConfigError as exc:  # name the JSON file the bad key came from
        src = modes_file if (exc.field or "").startswith("modes") else stiffness_file
        if exc.file is not None or src is None:
            raise
        raise ConfigError(exc.message, file=str(src), field=exc.field, value=exc.value,
                          expected=exc.expected) from None
    result = em.to_dict()
    result["table"] = em.table()
    result["tool_point_modes"] = em.tool_point_modes()

    def render(r: dict[str, Any]) -> None:
        from rich.table import Table

        t = Table(title="equivalent model (boring frame)", header_style="bold")
        for h in ("axis", "k (N/m)", "f_n (Hz)", "m (kg)", "c (N s/m)", "zeta"):
            t.add_column(h, justify="right")
        for row in r["table"]:
            t.add_row(row["axis"], fmt(row["stiffness_N_per_m"]), fmt(row["frequency_Hz"]),
                      fmt(row["mass_kg"]), fmt(row["damping_N_s_per_m"]),
                      fmt(row["damping_ratio"]))
        stdout.print(t)
        for n in r["notes"]:
            stdout.print(f"[dim]note: {n}[/]")

    emit(result, as_json, render)


def register(groups: dict[str, typer.Typer]) -> None:
    """Add this stage's commands to the shared command groups."""
    groups["root"].command("lobes")(lobes_cmd)
    groups["simulate"].command("boring")(simulate_boring_cmd)
    groups["model"].command("equivalent")(equivalent_cmd)
