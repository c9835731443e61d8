"""``robobore fe boring CONFIG.toml [--json] [--vtk DIR] [--device cpu|gpu] [--coefficients F]``.

Registered by :func:`register_boring` (called from the FE stage's ``register``).
"""

from __future__ import annotations

from pathlib import Path

import typer

from robobore.clitools import JSON_OPTION, emit, fraction_progress, handle_errors, kv_table, stdout

_ROWS = [
    ("force_rotating_N", "force on the tool, rotating frame (tangential, radial, feed) [N]"),
    ("force_mean_N", "boring frame X, Y, Z: mean over a revolution [N]"),
    ("force_amplitude_N", "boring frame X, Y, Z: amplitude over a revolution [N]"),
    ("force_at_run_angle_N", "boring frame X, Y, Z at the simulated bar angle [N]"),
    ("feed_amplitude_um", "feed-direction (Z) tool amplitude [um]"),
    ("tool_dz_mean_um", "tool Z deflection, mean [um]"),
    ("tool_dz_static_um", "feed force / kZ [um]"),
    ("averaging_window_mm", "averaging window [mm of cut]"),
    ("chip_area_mm2", "chip area (ap f - scallop) [mm^2]"),
    ("chip_max_height_um", "chip height above the pre-bore surface [um]"),
    ("peak_temperature_K", "peak temperature [K]"),
    ("energy_error", "energy balance error"),
    ("hourglass_fraction", "hourglass / internal energy"),
    ("eroded_damage", "elements eroded (damage)"),
    ("eroded_distortion", "elements eroded (distortion/time step)"),
    ("frame", "mesh frame (workpiece / tool)"),
    ("separation", "chip separation"),
    ("pairs_parted", "node pairs parted (node splitting)"),
    ("friction_law", "friction law"),
    ("friction_coefficient", "Coulomb friction (nominal: at the cutting speed)"),
    ("sliding_speed_mean_m_per_s", "sliding speed of the contact nodes, mean [m/s]"),
    ("n_elements", "elements"),
    ("time_step_s", "initial time step [s]"),
    ("steps", "time steps"),
    ("wall_time_s", "wall time [s]"),
    ("element_updates_per_s", "element updates per second"),
    ("device", "device"),
]

#: the tool-frame model's status, printed with every tool-frame run (docs/fe3d.md,
#: "Tool-frame 3D model")
TOOL_FRAME_STATUS = (
    'the 3D tool-frame ALE model (mesh.frame = "tool", the default) is checked against the '
    "mechanistic model calibrated from the validated 2D model at three boring conditions of "
    "the paper's insert (ap 0.05 mm at f 0.15 and 0.10 mm/r, ap 0.07 mm at 0.15 mm/r with "
    "mesh.t_min_um = 10; each force component within 15 %; mass scaling 400, 0.15 mm of "
    'travel), not against measured boring forces (docs/fe3d.md, "Tool-frame 3D model").')

#: the workpiece-frame model's status, printed with every workpiece-frame run (docs/fe3d.md,
#: "Limits of the workpiece frame")
THRUST_LIMIT = (
    'the workpiece-frame model (mesh.frame = "workpiece") gives radial and feed forces 22-38 % '
    "below the mechanistic model calibrated from the validated 2D model at the paper's "
    "condition on every mesh from 12.5 to 6.25 um (its chip separation deletes material the "
    "edge radius should plough; the tangential force is within 12 %). Take the radial and feed "
    'forces from the default tool-frame model (within 15 % there) or the mechanistic model '
    '(docs/fe3d.md, "Limits of the workpiece frame").')


#: the largest radial deflection of the insert, as a fraction of the edge element, that the
#: tool-frame mesh's placement (which does not follow it) is trusted with
RADIAL_DEFLECTION_LIMIT = 0.1


def boring_warnings(cfg, summary=None) -> list[str]:
    """What a 3D boring run's numbers rest on, in words, printed with every run: the frame's
    validation status and, in the tool frame on a support, a radial deflection of the insert
    the mesh does not follow (docs/fe3d.md, "Tool-frame 3D model", "Limits")."""
    from robobore.cutting.fe.models.choose import choose_boring

    out = [TOOL_FRAME_STATUS if choose_boring(cfg).tool_frame else THRUST_LIMIT]
    tf = None if summary is None else summary.toolframe_mesh
    d, edge = (None, None) if tf is None else (tf.radial_deflection_max_um, tf.edge_element_um)
    if d is not None and edge and d > RADIAL_DEFLECTION_LIMIT * edge:
        out.append(f"the insert's radial deflection on its support reached {d:.3g} um, "
                   f"{100 * d / edge:.0f} % of the edge element ({edge:.3g} um); the tool-frame "
                   "mesh does not follow a radial deflection of the insert, and its forces are "
                   f"not checked with one above {100 * RADIAL_DEFLECTION_LIMIT:.0f} % of the edge "
                   'element (docs/fe3d.md, "Tool-frame 3D model")')
    return out


def boring_cmd(
    config: Path = typer.Argument(..., help="3D FE boring config (TOML)."),
    as_json: bool = JSON_OPTION,
    vtk: Path | None = typer.Option(None, "--vtk", help="Write initial/final meshes (VTU) here."),
    device: str = typer.Option("cpu", "--device", help="cpu (default) or gpu (numba-cuda)."),
    coefficients: Path | None = typer.Option(
        None, "--coefficients",
        help="Compare with the mechanistic model using this coefficients file "
             "(default: the bundled TC4 coefficients)."),
) -> None:
    """Explicit 3D FE simulation of boring: insert with nose radius on the bore wall with the
    previous revolution's feed marks, held by the 3-direction equivalent model."""
    run_boring_cli(config, as_json, vtk, device, coefficients)


@handle_errors
def run_boring_cli(config, as_json, vtk, device, coefficients) -> None:
    from robobore.cutting.fe.config.boring3d import load_boring_config
    from robobore.cutting.fe.models.boring3d import (
        compare_with_mechanistic,
        simulate_boring,
        write_vtk,
    )
    from robobore.cutting.fe.models.choose import check_device, choose_boring

    check_device(device)
    cfg = load_boring_config(config)
    choose_boring(cfg, device, str(config))  # the device's checks, before anything is built
    from robobore.io.outputs import check_output_dir

    check_output_dir(vtk, "--vtk", "the VTU meshes")
    from robobore.io.identity import check_cut_file, fe_identity

    notes = [] if coefficients is None else [n for n in [check_cut_file(
        coefficients, material=cfg.material.name, insert=cfg.insert,
        material_by=f"[material] name of {config}", insert_by=f"[insert] of {config}")] if n]
    with fraction_progress("FE boring (3D)", enabled=not as_json) as prog:
        res = simulate_boring(cfg, source=str(config), progress=prog, device=device)
    result = res.to_dict()
    result["mechanistic_comparison"] = compare_with_mechanistic(res, coefficients).to_dict()
    result["warnings"] = boring_warnings(cfg, res.summary) + notes
    result["identity"] = fe_identity("fe boring", cfg, str(config))
    if vtk is not None:
        result["files"] = {"vtk": [str(p) for p in write_vtk(res, vtk)]}

    def render(r: dict) -> None:
        rows = []
        for k, label in _ROWS:
            v = r.get(k)
            if isinstance(v, dict):
                v = ", ".join(f"{x:.4g}" if isinstance(x, float) else str(x) for x in v.values())
            rows.append((label, v))
        tf = r.get("toolframe_mesh")
        if tf is not None:
            rows.append(("tool-frame mesh: nodes, hexahedra, slices",
                         f"{tf['nodes']}, {tf['hexahedra']}, {tf['slices']}"))
            rows.append(("tool-frame mesh: t_min [um], clamp's chip area / chip area",
                         f"{tf['t_min_um']:.3g}, {100 * tf['clamp_area_fraction']:.2f} %"))
        stdout.print(kv_table("FE boring (3D)", rows))
        mc = r["mechanistic_comparison"]
        stdout.print(kv_table("FE vs mechanistic model", [
            (f"{c}: FE / model [N], difference",
             f"{mc[c]['fe_N']:.3g} / {mc[c]['model_N']:.3g}, "
             f"{100 * mc[c]['relative_difference']:+.1f} %")
            for c in ("tangential", "radial", "feed")]))
        for w in r.get("warnings", []):
            stdout.print(f"[yellow]warning:[/] {w}")

    emit(result, as_json, render)


def register_boring(groups: dict[str, typer.Typer]) -> None:
    """Add ``robobore fe boring`` to the "fe" group."""
    groups["fe"].command("boring")(boring_cmd)
