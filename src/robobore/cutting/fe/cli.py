"""CLI commands of the FE stage (registered by ``robobore.cli``): ``robobore fe orthogonal``
(``--device cpu|gpu``), ``robobore fe validate`` (:mod:`robobore.cutting.fe.models.validate`) and,
from :mod:`robobore.cutting.fe.cli_boring`, ``robobore fe boring``."""

from __future__ import annotations

from pathlib import Path

import typer

from robobore.clitools import JSON_OPTION, emit, fraction_progress, handle_errors, kv_table, stdout

_KEYS = [
    ("cutting_force_N_per_mm", "cutting force Fc [N/mm]"),
    ("feed_force_N_per_mm", "feed force Ff [N/mm]"),
    ("averaging_window_mm", "averaging window [mm of cut]"),
    ("chip_ratio", "chip thickness ratio"),
    ("shear_angle_deg", "shear angle [deg]"),
    ("peak_temperature_K", "peak temperature [K]"),
    ("tool_dx_mean_um", "tool deflection x [um]"),
    ("tool_dy_mean_um", "tool deflection y [um]"),
    ("tool_dx_static_um", "Fc * width / kx [um]"),
    ("tool_dy_static_um", "Ff * width / ky [um]"),
    ("energy_error", "energy balance error"),
    ("hourglass_fraction", "hourglass / internal energy"),
    ("eroded_damage", "elements eroded (damage)"),
    ("eroded_distortion", "elements eroded (distortion/time step)"),
    ("friction_coefficient", "Coulomb friction used"),
    ("friction_law", "friction law"),
    ("n_elements", "elements"),
    ("device", "device"),
    ("steps", "time steps"),
    ("wall_time_s", "wall time [s]"),
    ("element_updates_per_s", "element updates per second"),
]


def validation_warnings(cfg) -> list[str]:
    """What in an FE orthogonal config leaves the validated model or its checked domain
    (docs/fe.md, "Validation against the measured forces"), in words: printed with every run
    so that a result is never read as validated where it is not."""
    from robobore.cutting.calibration_config import domain_departures
    from robobore.cutting.fe.models.choose import choose_orthogonal
    from robobore.material.friction import friction_law

    out = []
    if not choose_orthogonal(cfg).tool_frame:
        out.append("workpiece-frame model: not the validated model; its feed force is far "
                   "below the tool-frame model's and the measured forces (17.8 against 47.9 "
                   "N/mm at h 30 um, docs/fe.md, \"Tool-frame ALE model\")")
    if cfg.parameters == "a_priori":
        out.append("a-priori parameters: feed force 19-54 % below the measured forces at the "
                   "nine validation points, outside 25 % at eight (docs/fe.md)")
    law = friction_law("rech2013_calibrated")
    c = cfg.contact
    same_friction = (c.friction == "table" and c.friction_velocity == law.read_at
                     and tuple(c.friction_table_velocity_m_per_min) == law.velocity_m_per_min
                     and tuple(c.friction_table_mu) == law.mu
                     and c.shear_limit_MPa == law.shear_limit_MPa)
    if cfg.parameters != "a_priori" and not same_friction:
        out.append(f"friction: {cfg.friction_law()}; the validated model reads the law "
                   "rech2013_calibrated at each node's sliding speed")
    off = domain_departures(
        [cfg.cut.uncut_chip_thickness_um], [cfg.cut.cutting_speed_m_per_min],
        rake_deg=cfg.tool.rake_deg, edge_radius_um=cfg.tool.edge_radius_um,
        element_size_um=cfg.mesh.element_size_um, length_mm=cfg.cut.length_mm,
        material=cfg.material.name)
    if off:
        out.append("outside the domain checked against measured forces: " + "; ".join(off))
    return out


def orthogonal_cmd(
    config: Path = typer.Argument(..., help="FE orthogonal-cutting config (TOML)."),
    as_json: bool = JSON_OPTION,
    plot: Path | None = typer.Option(None, "--plot", help="Write chip pictures (PNG) here."),
    vtk: Path | None = typer.Option(None, "--vtk", help="Write the final mesh (VTU) here."),
    out: Path | None = typer.Option(None, "--out", help="Write histories to this netCDF file."),
    device: str = typer.Option("cpu", "--device", help="cpu (default) or gpu (numba-cuda)."),
) -> None:
    """Explicit plane-strain FE simulation of orthogonal cutting (Johnson-Cook material,
    rigid tool on optional springs/dampers)."""
    run_orthogonal_cli(config, as_json, plot, vtk, out, device)


@handle_errors
def run_orthogonal_cli(config, as_json, plot, vtk, out, device="cpu") -> None:
    from robobore.cutting.fe.config.orthogonal import load_fe_config
    from robobore.cutting.fe.models.orthogonal import check_device, simulate_orthogonal
    from robobore.cutting.fe.models.output import plot_chip, to_dataset, write_vtk
    from robobore.io.outputs import check_output_dir, check_output_file
    from robobore.io.results import write_netcdf

    check_output_file(out, "--out", "the netCDF histories")
    check_output_dir(vtk, "--vtk", "the VTU mesh")
    check_output_dir(plot, "--plot", "the PNG pictures")
    cfg = load_fe_config(config)
    check_device(device, cfg, str(config))
    with fraction_progress("FE cutting", enabled=not as_json) as prog:
        res = simulate_orthogonal(cfg, source=str(config), progress=prog, device=device)
    files = {}
    if out is not None:
        files["netcdf"] = str(write_netcdf(to_dataset(res), out, config=res.config))
    if vtk is not None:
        files["vtk"] = str(write_vtk(res, Path(vtk) / "fe_orthogonal_final.vtu"))
    if plot is not None:
        for f in ("temperature_K", "eps_p", "von_mises_Pa"):
            files[f"png_{f}"] = str(plot_chip(res, Path(plot) / f"fe_chip_{f}.png", f))
        files["png_forces"] = str(_plot_forces(res, Path(plot) / "fe_forces.png"))
    result = res.to_dict()
    result["warnings"] = validation_warnings(cfg)
    from robobore.io.identity import fe_identity

    result["identity"] = fe_identity("fe orthogonal", cfg, str(config))
    if files:
        result["files"] = files

    def render(r: dict) -> None:
        rows = [(label, r.get(k)) for k, label in _KEYS if k in r]
        for face, f in r.get("force_by_face_N_per_mm", {}).items():
            rows.append((f"{face} Fc / Ff [N/mm]", f"{f['cutting']:.2f} / {f['feed']:.2f}"))
        stdout.print(kv_table("FE orthogonal cutting", rows))
        for w in r.get("warnings", []):
            stdout.print(f"[yellow]warning:[/] {w}")
        for k, v in r.get("files", {}).items():
            stdout.print(f"{k}: {v}")

    emit(result, as_json, render)


def _plot_forces(res, path: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    h = res.history
    fig, ax = plt.subplots(figsize=(7, 4), dpi=120)
    ax.plot(h["cut_length_mm"], h["cutting_force_N_per_mm"], label="Fc")
    ax.plot(h["cut_length_mm"], h["feed_force_N_per_mm"], label="Ff")
    from robobore.cutting.fe.engine.layout import FACES

    for face, style in zip(FACES, (":", "--", "-."), strict=True):
        if f"{face}_cutting_force_N_per_mm" in h:  # CPU runs: the split by tool face
            ax.plot(h["cut_length_mm"], h[f"{face}_cutting_force_N_per_mm"], style,
                    color="C0", lw=0.8, label=f"Fc {face}")
            ax.plot(h["cut_length_mm"], h[f"{face}_feed_force_N_per_mm"], style,
                    color="C1", lw=0.8, label=f"Ff {face}")
    a, b = res.summary.averaging_window_mm
    ax.axvspan(a, b, color="0.9", label="averaging window")
    ax.set_xlabel("length of cut [mm]")
    ax.set_ylabel("force on the tool [N/mm]")
    ax.legend(fontsize=7, ncol=2)
    from robobore.io.results import save_figure

    path.parent.mkdir(parents=True, exist_ok=True)
    save_figure(fig, path)
    plt.close(fig)
    return path


def validate_cmd(
    config: Path = typer.Argument(..., help="FE orthogonal-cutting config (TOML)."),
    measured: Path = typer.Option(..., "--measured", help="Measured-forces file (JSON; format "
                                  "in docs/fe.md, robobore fe validate)."),
    as_json: bool = JSON_OPTION,
    points: str | None = typer.Option(None, "--points", help="Only these conditions, "
                                      "h_um:vc_m_per_min pairs, e.g. 60:30,40:5 (a condition "
                                      "the file does not hold is a prediction)."),
    out: Path | None = typer.Option(None, "--out", help="Folder of the per-point results "
                                    "(reused on a rerun: an interrupted validation resumes); "
                                    "default ./fe_validate_<config name>."),
    plot: Path | None = typer.Option(None, "--plot", help="Write a simulated-vs-measured "
                                     "picture (PNG) here."),
    device: str = typer.Option("cpu", "--device", help="cpu (default) or gpu (numba-cuda)."),
) -> None:
    """Run the config at every measured condition (uncut chip thickness and cutting speed
    replaced per point) and compare Fc, Ff and chip ratio with the measurement."""
    run_validate_cli(config, measured, as_json, points, out, plot, device)


@handle_errors
def run_validate_cli(config, measured, as_json, points, out, plot, device="cpu") -> None:
    from robobore.cutting.fe.config.orthogonal import parse_config
    from robobore.cutting.fe.models.validate import parse_points, read_measured, run_validation
    from robobore.io.config import load_toml

    base = load_toml(config)
    base_cfg = parse_config(base, str(config))  # the base config's own errors first
    meas = read_measured(measured)
    pts = None if points is None else parse_points(points)
    default_out = out is None
    out = Path(f"fe_validate_{Path(config).stem}") if out is None else out
    from robobore.io.outputs import check_output_dir

    check_output_dir(out, "--out", "the per-point results (resumable store)")
    check_output_dir(plot, "--plot", "the validation picture")
    if default_out:  # said before the work: the store lands in the working folder
        from robobore.clitools import stderr

        stderr.print(f"[yellow]note:[/] per-point results (resumable) go to "
                     f"{out.resolve()} (no --out given)", soft_wrap=True, highlight=False)
    with fraction_progress("FE validation", enabled=not as_json) as prog:
        result = run_validation(base, meas, source=str(config), points=pts, out_dir=out,
                                device=device, progress=prog).to_dict()
    result["measured_file"] = str(measured)
    from robobore.io.identity import fe_identity

    result["identity"] = fe_identity("fe validate", base_cfg, str(config))
    if plot is not None:
        result.setdefault("files", {})["png_validation"] = str(
            _plot_validation(result, Path(plot) / "fe_validation.png"))

    def render(r: dict) -> None:
        from rich.table import Table

        t = Table(title="FE validation (err % = simulated / measured - 1)")
        for c in ("h um", "vc m/min", "Fc meas", "Fc sim", "err %", "Ff meas", "Ff sim",
                  "err %", "r meas", "r sim", "err %"):
            t.add_column(c, justify="right")

        def f(v, fm=".1f"):
            return "-" if v is None else format(v, fm)

        def e(v):
            return "-" if v is None else f"{100 * v:+.1f}"

        for p in r["points"]:
            m, re_ = p["measured"], p["relative_error"]
            t.add_row(f(p["uncut_chip_thickness_um"], "g"), f(p["cutting_speed_m_per_min"], "g"),
                      f(m["cutting_force_N_per_mm"]), f(p["cutting_force_N_per_mm"]),
                      e(re_["cutting_force"]), f(m["feed_force_N_per_mm"]),
                      f(p["feed_force_N_per_mm"]), e(re_["feed_force"]),
                      f(m["chip_ratio"], ".2f"), f(p["chip_ratio"], ".2f"), e(re_["chip_ratio"]))
        stdout.print(t)
        s = r["summary"]
        rows = []
        for key, label in (("cutting_force", "Fc"), ("feed_force", "Ff"),
                           ("chip_ratio", "chip ratio")):
            mx, mn = s["max_abs_error"][key], s["mean_abs_error"][key]
            rows.append((f"{label}: mean / max |error| [%] ({s['n_measured'][key]} points)",
                         "-" if mx is None else f"{100 * mn:.1f} / {100 * mx:.1f}"))
        rows.append(("points reused from the results folder",
                     sum(1 for p in r["points"] if p["reused"])))
        rows.append(("config", r["config"]))
        rows.append(("measured file", r["measured_file"]))
        rows.append(("results folder", r["out_dir"]))
        stdout.print(kv_table("Summary", rows))
        for k, v in r.get("files", {}).items():
            stdout.print(f"{k}: {v}")

    emit(result, as_json, render)


def _plot_validation(result: dict, path: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(9, 4), dpi=120)
    for ax, key, label, band in ((axes[0], "cutting_force_N_per_mm", "Fc [N/mm]", 0.10),
                                 (axes[1], "feed_force_N_per_mm", "Ff [N/mm]", 0.25)):
        pts = [(p["measured"][key], p[key], p) for p in result["points"]
               if p["measured"][key] is not None and p[key] is not None]
        if pts:
            xs = [a for a, _, _ in pts]
            lo, hi = 0.0, 1.15 * max(max(xs), max(b for _, b, _ in pts))
            ax.plot([lo, hi], [lo, hi], "k-", lw=0.8)
            ax.fill_between([lo, hi], [lo * (1 - band), hi * (1 - band)],
                            [lo * (1 + band), hi * (1 + band)], color="0.9",
                            label=f"+-{100 * band:.0f} %")
            for a, b, p in pts:
                ax.plot(a, b, "o", color="C0")
                ax.annotate(f"{p['uncut_chip_thickness_um']:g}/{p['cutting_speed_m_per_min']:g}",
                            (a, b), fontsize=6, xytext=(3, 3), textcoords="offset points")
            ax.set_xlim(lo, hi)
            ax.set_ylim(lo, hi)
            ax.legend(fontsize=7)
        ax.set_xlabel(f"measured {label}")
        ax.set_ylabel(f"simulated {label}")
    fig.suptitle("FE validation (labels: h um / vc m/min)", fontsize=9)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.stem + ".tmp.png")
    fig.savefig(tmp)
    plt.close(fig)
    tmp.replace(path)
    return path


def register(groups: dict[str, typer.Typer]) -> None:
    """Add this stage's commands to the shared command groups."""
    from robobore.cutting.fe.cli_boring import register_boring

    groups["fe"].command("orthogonal")(orthogonal_cmd)
    groups["fe"].command("validate")(validate_cmd)
    register_boring(groups)
