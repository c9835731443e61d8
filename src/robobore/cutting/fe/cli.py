"""CLI commands of the FE stage (registered by ``robobore.cli``): ``robobore fe orthogonal``
(``--device cpu|gpu``) and, from :mod:`robobore.cutting.fe.cli_boring`, ``robobore fe boring``."""

from __future__ import annotations

from pathlib import Path

import typer

from robobore.clitools import JSON_OPTION, emit, handle_errors, kv_table, progress_bar, stdout

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
    from robobore.cutting.fe.config import load_fe_config
    from robobore.cutting.fe.output import plot_chip, to_dataset, write_vtk
    from robobore.cutting.fe.solver import check_device, simulate_orthogonal
    from robobore.io.outputs import check_output_dir, check_output_file
    from robobore.io.results import write_netcdf

    check_output_file(out, "--out", "the netCDF histories")
    check_output_dir(vtk, "--vtk", "the VTU mesh")
    check_output_dir(plot, "--plot", "the PNG pictures")
    cfg = load_fe_config(config)
    check_device(device, cfg, str(config))
    total = 1000
    with progress_bar("FE cutting", total, enabled=not as_json) as advance:
        done = [0]

        def prog(frac: float) -> None:
            n = int(frac * total)
            if n > done[0]:
                advance(n - done[0])
                done[0] = n

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
    result = dict(res.summary)
    if files:
        result["files"] = files

    def render(r: dict) -> None:
        rows = [(label, r.get(k)) for k, label in _KEYS if k in r]
        for face, f in r.get("force_by_face_N_per_mm", {}).items():
            rows.append((f"{face} Fc / Ff [N/mm]", f"{f['cutting']:.2f} / {f['feed']:.2f}"))
        stdout.print(kv_table("FE orthogonal cutting", rows))
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
    from robobore.cutting.fe.kernels import FACES

    for face, style in zip(FACES, (":", "--", "-."), strict=True):
        if f"{face}_cutting_force_N_per_mm" in h:  # CPU runs: the split by tool face
            ax.plot(h["cut_length_mm"], h[f"{face}_cutting_force_N_per_mm"], style,
                    color="C0", lw=0.8, label=f"Fc {face}")
            ax.plot(h["cut_length_mm"], h[f"{face}_feed_force_N_per_mm"], style,
                    color="C1", lw=0.8, label=f"Ff {face}")
    a, b = res.summary["averaging_window_mm"]
    ax.axvspan(a, b, color="0.9", label="averaging window")
    ax.set_xlabel("length of cut [mm]")
    ax.set_ylabel("force on the tool [N/mm]")
    ax.legend(fontsize=7, ncol=2)
    from robobore.io.results import save_figure

    path.parent.mkdir(parents=True, exist_ok=True)
    save_figure(fig, path)
    plt.close(fig)
    return path


def register(groups: dict[str, typer.Typer]) -> None:
    """Add this stage's commands to the shared command groups."""
    from robobore.cutting.fe.cli_boring import register_boring

    groups["fe"].command("orthogonal")(orthogonal_cmd)
    register_boring(groups)
