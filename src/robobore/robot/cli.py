"""CLI commands of the robot stage (registered by ``robobore.cli``).

``robobore robot list|fk|stiffness|campaign`` and ``robobore identify stiffness``.
Heavy imports (numba kernels, scipy) happen inside the commands.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import typer

from robobore.clitools import (
    JSON_OPTION,
    check_count,
    check_option,
    emit,
    fmt,
    handle_errors,
    kv_table,
    parse_floats,
    stderr,
    stdout,
)

DEFAULT_ROBOT = "irb6600-175-2.55"
EXAMPLE_CAMPAIGN = ("data", "campaign_irb6600", "campaign.csv")

ROBOT_OPT = typer.Option(
    None, "--robot", help="Robot library name (see `robobore robot list`) or a robot TOML path."
)
ROBOT_FILE_OPT = typer.Option(
    None, "--robot-file", help="A robot TOML file (D-H data); overrides --robot."
)
TCP_OPT = typer.Option(
    None, "--tcp-m", help="Tool point in the flange frame, 'x,y,z' in m (default: flange)."
)
FRAME_OPT = typer.Option(
    "boring", "--frame",
    help="Process frame for k_xx, k_yy, k_zz: boring (the paper's frame: Z = tool z = feed, "
    "X horizontal, Y = Z x X, vertical), tool (flange axes), or base.",
)


def _robot(robot: str | None, robot_file: Path | None, default: str | None = DEFAULT_ROBOT):
    from robobore.errors import ConfigError
    from robobore.robot.description import get_robot, load_robot_file

    if robot_file is not None:
        return load_robot_file(robot_file)
    if robot is None:
        if default is None:
            raise ConfigError("no robot given", field="--robot",
                              expected="a robot library name or --robot-file PATH")
        robot = default
    return get_robot(robot, field="--robot")


def _tcp(tcp: str | None) -> list[float] | None:
    return None if tcp is None else parse_floats(tcp, 3, "--tcp-m", "m")


def _frame(frame: str, frame_rotation: str | None) -> Any:
    import numpy as np

    from robobore.errors import ConfigError
    from robobore.robot.stiffness import FRAMES

    if frame_rotation is not None:
        return np.asarray(parse_floats(frame_rotation, 9, "--frame-rotation", "-"),
                          float).reshape(3, 3)
    if frame not in FRAMES:
        raise ConfigError("unknown frame", field="--frame", value=frame,
                          expected=f"one of {list(FRAMES)}")
    return frame


def _q(robot, joints_deg: str, warn: list[str] | None = None):
    import numpy as np

    from robobore.io.ranges import radians_hint
    from robobore.robot.description import check_joint_limits

    vals = parse_floats(joints_deg, robot.n_joints, "--joints-deg", "deg")
    hint = radians_hint(vals, "--joints-deg")
    if hint is not None:
        stderr.print(f"[yellow]warning:[/] {hint}", soft_wrap=True, highlight=False)
        if warn is not None:
            warn.append(hint)
    q = np.radians(vals)
    try:
        check_joint_limits(robot, q)
    except Exception as exc:  # re-label with the CLI option
        from robobore.errors import ConfigError, InputError

        if isinstance(exc, InputError):
            raise ConfigError(exc.message, field=f"--joints-deg ({exc.field})", value=exc.value,
                              expected=exc.expected) from None
        raise
    return q


def _matrix_table(title: str, M, row_labels, col_labels):
    from rich.table import Table

    t = Table(title=title, header_style="bold")
    t.add_column("")
    for c in col_labels:
        t.add_column(c, justify="right")
    for lab, row in zip(row_labels, M, strict=True):
        t.add_row(lab, *[f"{float(v):.3g}" for v in row])
    return t


# --- robot list -----------------------------------------------------------------------------


@handle_errors
def list_cmd(as_json: bool = JSON_OPTION) -> None:
    """List the robots in the library (built-in and ROBOBORE_ROBOT_PATH folders)."""
    from robobore.robot.description import available_robots, load_robot_file

    out = {}
    for name, path in available_robots().items():
        r = load_robot_file(path)
        out[name] = {"file": str(path), "joints": r.n_joints, "description": r.description}

    def render(res: dict[str, Any]) -> None:
        stdout.print(kv_table("robot library", [(k, v["description"]) for k, v in res.items()]))

    emit({"robots": out}, as_json, lambda r: render(r["robots"]))


# --- robot fk -------------------------------------------------------------------------------


@handle_errors
def fk_cmd(
    joints_deg: str = typer.Option(..., "--joints-deg", help="q1,...,q6 in deg."),
    robot: str = ROBOT_OPT,
    robot_file: Path = ROBOT_FILE_OPT,
    tcp_m: str = TCP_OPT,
    as_json: bool = JSON_OPTION,
) -> None:
    """Forward kinematics and geometric Jacobian at one posture."""
    import numpy as np

    from robobore.robot.kinematics import fk_jacobian
    from robobore.robot.stiffness import process_frame

    rb = _robot(robot, robot_file)
    notes: list[str] = []
    q = _q(rb, joints_deg, notes)
    T, J = fk_jacobian(rb, q, _tcp(tcp_m))
    res = {
        "robot": rb.name,
        "joints_deg": np.degrees(q).tolist(),
        "tcp_m": _tcp(tcp_m) or [0.0, 0.0, 0.0],
        "position_m": T[:3, 3].tolist(),
        "rotation": T[:3, :3].tolist(),
        "jacobian": J.tolist(),
        "jacobian_condition": float(np.linalg.cond(J)),
        "notes": notes,
    }
    try:
        res["R_world_boring"] = process_frame(T[:3, :3], "boring").tolist()
    except Exception:  # vertical feed axis: no boring frame
        res["R_world_boring"] = None

    def render(r: dict[str, Any]) -> None:
        p = r["position_m"]
        stdout.print(kv_table(f"forward kinematics — {r['robot']}", [
            ("x (m)", p[0]), ("y (m)", p[1]), ("z (m)", p[2]),
            ("tool z-axis (feed)", ", ".join(f"{v[2]:.4f}" for v in r["rotation"])),
            ("cond(J)", r["jacobian_condition"]),
        ]))
        stdout.print(_matrix_table("rotation (world <- tool)", r["rotation"], "xyz",
                                   ["x_tool", "y_tool", "z_tool"]))
        stdout.print(_matrix_table("geometric Jacobian (m/rad; rad/rad)", r["jacobian"],
                                   ["vx", "vy", "vz", "wx", "wy", "wz"],
                                   [f"q{i + 1}" for i in range(len(r["joints_deg"]))]))

    emit(res, as_json, render)


# --- robot stiffness ------------------------------------------------------------------------


def _stiffness_file_robot(file: Path | None, robot: str | None, robot_file: Path | None,
                          notes: list[str]):
    """The robot of ``robot stiffness``: the options' robot, checked against the joint
    stiffness file's identity, or (no robot option) the file's own robot, said in a note."""
    from robobore.io.identity import check_robot, read_identity, unchecked_note
    from robobore.io.readers import load_json
    from robobore.robot.description import robot_of_identity

    if file is None:
        return _robot(robot, robot_file)
    data = load_json(Path(file), "joint stiffness file",
                     "a JSON object from `robobore identify stiffness --json`")
    ident = read_identity(data, str(file))
    if ident is None:
        notes.append(unchecked_note(str(file)))
        if data.get("robot") and robot is None and robot_file is None:
            ident = {"robot": str(data["robot"])}
    if robot is not None or robot_file is not None:
        rb = _robot(robot, robot_file)
        check_robot(ident, str(file), rb.name, rb.description_hash(),
                    "--robot-file" if robot_file is not None else "--robot")
        return rb
    if ident is not None and ident.get("robot"):
        rb = robot_of_identity(ident, str(file))
        notes.append(f"robot {rb.name} taken from {file} (no --robot given)")
        return rb
    return _robot(None, None)


def _joint_stiffness(text: str | None, file: Path | None, n: int):
    from robobore.errors import ConfigError, InputError
    from robobore.robot.stiffness import JointStiffness

    if file is not None:
        from robobore.io.readers import load_json

        p = Path(file)
        data = load_json(p, "joint stiffness file",
                         "a JSON object from `robobore identify stiffness --json`")
        try:
            js = JointStiffness.from_dict(data)
        except InputError as exc:
            raise ConfigError(exc.message, file=str(p), field=exc.field, value=exc.value,
                              expected=exc.expected) from None
        if len(js.k_Nm_per_rad) != n:
            raise ConfigError(f"got {len(js.k_Nm_per_rad)} joint stiffnesses", file=str(p),
                              field="joint_stiffness_Nm_per_rad",
                              value=list(js.k_Nm_per_rad),
                              expected=f"{n} values in N m/rad (one per joint of the robot)")
        return js
    if text is None:
        raise ConfigError("no joint stiffness given", field="--joint-stiffness-Nm-per-rad",
                          expected=f"{n} comma-separated values in N m/rad, or "
                          "--joint-stiffness-file")
    vals = parse_floats(text, n, "--joint-stiffness-Nm-per-rad", "N m/rad")
    if any(not (v > 0 and math.isfinite(v)) for v in vals):
        raise ConfigError("joint stiffnesses must be positive",
                          field="--joint-stiffness-Nm-per-rad", value=text,
                          expected=f"{n} positive values in N m/rad")
    return vals


@handle_errors
def stiffness_cmd(
    joints_deg: str = typer.Option(..., "--joints-deg", help="q1,...,q6 in deg."),
    joint_stiffness: str = typer.Option(
        None, "--joint-stiffness-Nm-per-rad", help="k1,...,k6 in N m/rad."),
    joint_stiffness_file: Path = typer.Option(
        None, "--joint-stiffness-file",
        help="JSON from `robobore identify stiffness --json` (instead of the list)."),
    robot: str = ROBOT_OPT,
    robot_file: Path = ROBOT_FILE_OPT,
    tcp_m: str = TCP_OPT,
    frame: str = FRAME_OPT,
    frame_rotation: str = typer.Option(
        None, "--frame-rotation",
        help="User process frame: R_world_process as 9 numbers, row-major (columns = axes)."),
    wrench: str = typer.Option(
        None, "--wrench-N-Nm",
        help="External wrench on the tool 'Fx,Fy,Fz,Mx,My,Mz' (N, N m about the tool point, "
        "world frame): adds the complementary stiffness under load (CCT, Chen & Kao 2000)."),
    plot: Path = typer.Option(None, "--plot", help="Write a polar plot of the directional "
                              "stiffness in the process planes (PNG) to this folder."),
    as_json: bool = JSON_OPTION,
) -> None:
    """Cartesian, directional and principal stiffness of the robot at one posture."""
    import numpy as np

    from robobore.io.outputs import check_output_dir
    from robobore.robot.stiffness import stiffness_at

    check_output_dir(plot, "--plot", "the PNG plots")
    notes: list[str] = []
    rb = _stiffness_file_robot(joint_stiffness_file, robot, robot_file, notes)
    for n_ in notes:
        stderr.print(f"[yellow]note:[/] {n_}", soft_wrap=True, highlight=False)
    q = _q(rb, joints_deg, notes)
    k = _joint_stiffness(joint_stiffness, joint_stiffness_file, rb.n_joints)
    W = None if wrench is None else parse_floats(wrench, 6, "--wrench-N-Nm", "N and N m")
    res = stiffness_at(rb, q, k, frame=_frame(frame, frame_rotation), tcp_m=_tcp(tcp_m),
                       wrench=W).to_dict()
    res = {"robot": rb.name, "joints_deg": np.degrees(q).tolist(), **res, "notes": notes}
    if plot is not None:
        res["plots"] = _plot_stiffness(res, Path(plot))

    def render(r: dict[str, Any]) -> None:
        d, b = r["directional_stiffness_N_per_m"], r["directional_stiffness_base_N_per_m"]
        rows = [(f"k_{a}{a} ({r['frame']} frame) N/m", d[a]) for a in "xyz"]
        rows += [(f"k_{a}{a} (base frame) N/m", b[a]) for a in "xyz"]
        rows += [(f"principal k{i + 1} N/m", v)
                 for i, v in enumerate(r["principal_stiffness_N_per_m"])]
        rows += [("cond(J)", r["jacobian_condition"])]
        stdout.print(kv_table(f"stiffness — {r['robot']} at "
                              f"{', '.join(f'{v:g}' for v in r['joints_deg'])} deg", rows))
        lab = ["x", "y", "z", "rx", "ry", "rz"]
        stdout.print(_matrix_table("Cartesian stiffness K (N/m, N/rad; N m/m, N m/rad)",
                                   r["cartesian_stiffness"], lab, lab))
        if r.get("complementary_stiffness") is not None:
            stdout.print(_matrix_table("complementary stiffness under load K_C (CCT)",
                                       r["complementary_stiffness"], lab, lab))

    emit(res, as_json, render)


def _plot_stiffness(r: dict[str, Any], folder: Path) -> list[str]:
    """Polar plots of k_u = 1/(u^T C_tt u) for u in the process XY, XZ and YZ planes."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    C = np.asarray(r["compliance"])[:3, :3]
    R = np.asarray(r["R_world_process"])
    phi = np.linspace(0, 2 * np.pi, 361)
    fig, axs = plt.subplots(1, 3, subplot_kw={"projection": "polar"}, figsize=(13, 4.4))
    for ax, (a, b) in zip(axs, ((0, 1), (0, 2), (1, 2)), strict=True):
        U = np.outer(np.cos(phi), R[:, a]) + np.outer(np.sin(phi), R[:, b])
        k = 1.0 / np.einsum("ni,ij,nj->n", U, C, U)
        ax.plot(phi, k / 1e6)
        ax.set_title(f"{'XYZ'[a]}{'XYZ'[b]} plane ({r['frame']} frame), k in N/um",
                     fontsize=9)
    fig.suptitle(f"directional stiffness, {r['robot']} at "
                 f"{', '.join(f'{v:g}' for v in r['joints_deg'])} deg")
    fig.tight_layout()
    from robobore.io.results import save_figure

    folder.mkdir(parents=True, exist_ok=True)
    p = folder / "directional_stiffness.png"
    save_figure(fig, p, dpi=110)
    plt.close(fig)
    return [str(p)]


# --- robot campaign -------------------------------------------------------------------------


@handle_errors
def campaign_cmd(
    out: Path = typer.Argument(..., help="Campaign CSV to write (contract layout)."),
    robot: str = ROBOT_OPT,
    robot_file: Path = ROBOT_FILE_OPT,
    joint_stiffness: str = typer.Option(
        None, "--joint-stiffness-Nm-per-rad",
        help="TRUE k1..k6 (N m/rad); default: the documented IRB 6600 assumption."),
    postures_deg: str = typer.Option(
        None, "--postures-deg", help="'q1,..,q6; q1,..,q6; ...' deg (default: paper posture "
        "+ 5 spread postures)."),
    force_directions: str = typer.Option(
        None, "--force-directions", help="'x,y,z; ...' one world-frame direction per posture."),
    load_levels_N: str = typer.Option(
        "0,250,500,750,1000", "--load-levels-N", help="Force per load step, N (step 0 = 0)."),
    pressures_MPa: str = typer.Option(
        None, "--pressures-MPa",
        help="Pressure-foot mode (paper): e.g. '0,0.3,0.4,0.5,0.6'; force = P x piston area "
        "along -tool z at the foot (joints 4-6 then NOT identifiable)."),
    piston_area_m2: float = typer.Option(1.0e-3 / 0.6, "--piston-area-m2",
                                         help="Pressure-foot piston area, m^2."),
    load_point_m: str = typer.Option(
        None, "--load-point-m", help="Load point in the flange frame 'x,y,z', m (lever arm; "
        "default 0.25,0,0.30; pressure foot 0,0,0.35)."),
    reflectors_m: str = typer.Option(
        None, "--reflectors-m", help="Reflectors in the flange frame 'x,y,z; ...' m (>= 3)."),
    sigma_um: float = typer.Option(
        None, "--sigma-um", help="Tracker noise, 1-sigma per coordinate, um (default: AT901 "
        "model, half of MPE = 15 um + 6 um/m)."),
    tracker_position_m: str = typer.Option(
        "3.5,-3.0,1.0", "--tracker-position-m", help="Tracker position (world), m."),
    seed: int = typer.Option(0, "--seed", help="Random seed."),
    as_json: bool = JSON_OPTION,
) -> None:
    """Generate a SYNTHETIC laser-tracker stiffness campaign (virtual experiment)."""
    from robobore.io.outputs import check_output_file
    from robobore.robot import campaign as cm
    from robobore.robot.campaign_io import write_campaign

    check_output_file(out, "OUT", "the campaign CSV")
    check_option(piston_area_m2, "--piston-area-m2")  # plausible ranges (robobore.io.ranges)
    check_option(sigma_um, "--sigma-um")
    check_count(seed, "--seed", 0, 2**32 - 1)
    rb = _robot(robot, robot_file)
    kw: dict[str, Any] = {"robot": str(robot_file) if robot_file else rb.name, "seed": seed}
    if joint_stiffness is not None:
        kw["joint_stiffness_Nm_per_rad"] = tuple(_joint_stiffness(joint_stiffness, None,
                                                                  rb.n_joints))
    if postures_deg is not None:
        kw["postures_deg"] = tuple(tuple(parse_floats(p, rb.n_joints, "--postures-deg", "deg"))
                                   for p in postures_deg.split(";") if p.strip())
    if force_directions is not None:
        kw["force_directions"] = cm.parse_vectors(force_directions, "--force-directions", "-")
    if load_point_m is not None:
        kw["load_point_flange_m"] = tuple(parse_floats(load_point_m, 3, "--load-point-m", "m"))
    if reflectors_m is not None:
        kw["reflectors_flange_m"] = cm.parse_vectors(reflectors_m, "--reflectors-m", "m")
    kw["noise"] = cm.TrackerNoise(
        sigma_m=None if sigma_um is None else sigma_um * 1e-6,
        tracker_position_m=tuple(parse_floats(tracker_position_m, 3, "--tracker-position-m",
                                              "m")))
    if pressures_MPa is not None:
        kw["pressures_MPa"] = tuple(parse_floats(pressures_MPa, None, "--pressures-MPa", "MPa"))
        kw["piston_area_m2"] = piston_area_m2
        spec = cm.pressure_foot_spec(**kw)
    else:
        kw["load_levels_N"] = tuple(parse_floats(load_levels_N, None, "--load-levels-N", "N"))
        spec = cm.CampaignSpec(**kw)
    camp = cm.simulate_campaign(spec)
    from robobore.robot.campaign_io import truth_path

    check_output_file(truth_path(out), "OUT", "the campaign's identity file")
    write_campaign(camp, out, identity={
        "file": str(out), "synthetic": True, "robot": rb.name,
        "robot_hash": rb.description_hash(), "robot_file": rb.file or None,
        "true_joint_stiffness_Nm_per_rad": list(spec.joint_stiffness_Nm_per_rad),
        "spec": spec.to_dict()})
    res = {
        "file": str(out),
        "identity_file": str(truth_path(out)),
        "synthetic": True,
        "rows": camp.n_rows,
        "postures": len(camp.postures()),
        "load_steps": int(camp.load_step.max()) + 1,
        "true_joint_stiffness_Nm_per_rad": list(spec.joint_stiffness_Nm_per_rad),
        "spec": spec.to_dict(),
    }

    def render(r: dict[str, Any]) -> None:
        stdout.print(kv_table("virtual campaign (SYNTHETIC)", [
            ("file", r["file"]), ("rows", r["rows"]), ("postures", r["postures"]),
            ("load steps per posture", r["load_steps"]),
            ("true k (N m/rad)",
             ", ".join(f"{v:.3g}" for v in r["true_joint_stiffness_Nm_per_rad"])),
            ("seed", r["spec"]["seed"]),
        ]))

    emit(res, as_json, render)


# --- identify stiffness ---------------------------------------------------------------------


def example_campaign_path() -> Path:
    """Path of the bundled SYNTHETIC example campaign CSV."""
    from importlib import resources

    return Path(str(resources.files("robobore").joinpath(*EXAMPLE_CAMPAIGN)))


@handle_errors
def identify_stiffness_cmd(
    campaign: Path = typer.Argument(None, help="Campaign CSV (contract layout)."),
    example: bool = typer.Option(False, "--example",
                                 help="Use the bundled SYNTHETIC IRB 6600 campaign."),
    robot: str = ROBOT_OPT,
    robot_file: Path = ROBOT_FILE_OPT,
    sigma_um: float = typer.Option(
        None, "--sigma-um", help="Known tracker noise (1-sigma per coordinate, um); default: "
        "estimated from the weighted residuals."),
    cond_limit: float = typer.Option(1e6, "--cond-limit",
                                     help="Largest accepted scaled condition number."),
    tcp_m: str = TCP_OPT,
    frame: str = FRAME_OPT,
    plot: Path = typer.Option(None, "--plot", help="Write PNG plots to this folder."),
    as_json: bool = JSON_OPTION,
) -> None:
    """Identify joint stiffnesses from a laser-tracker campaign (weighted NNLS)."""
    from robobore.errors import ConfigError
    from robobore.io.outputs import check_output_dir
    from robobore.robot.campaign_io import read_campaign
    from robobore.robot.identify import identify_joint_stiffness

    check_output_dir(plot, "--plot", "the PNG plots")
    if example:
        if campaign is not None:
            raise ConfigError("give either a campaign file or --example, not both",
                              field="--example")
        path = example_campaign_path()
        rb = _robot(robot, robot_file, default=DEFAULT_ROBOT)
    else:
        if campaign is None:
            raise ConfigError("no campaign file given", field="CAMPAIGN",
                              expected="a campaign CSV path, or --example")
        path = campaign
        rb = _robot(robot, robot_file, default=None)
    if sigma_um is not None and not (math.isfinite(sigma_um) and 0.0 < sigma_um <= 1e4):
        raise ConfigError("tracker noise out of range", field="--sigma-um", value=sigma_um,
                          expected="0 < sigma <= 10000 um (1-sigma per coordinate)")
    check_option(cond_limit, "--cond-limit", "cond_limit")
    camp = read_campaign(path, robot=rb)
    res = identify_joint_stiffness(camp, rb, sigma_m=None if sigma_um is None else
                                   sigma_um * 1e-6, cond_limit=cond_limit,
                                   frame=_frame(frame, None), tcp_m=_tcp(tcp_m))
    d = res.to_dict()
    d["synthetic"] = bool(example or res.synthetic)
    d["identity"]["synthetic"] = d["synthetic"]
    if example:
        d["example"] = "bundled SYNTHETIC campaign (virtual experiment, documented ground truth)"
    if plot is not None:
        d["plots"] = _plot_identification(d, Path(plot))
    emit(d, as_json, _render_identification)


def _render_identification(r: dict[str, Any]) -> None:
    from rich.table import Table

    title = "joint stiffness identification"
    if r.get("synthetic"):
        title += " — SYNTHETIC data"
    t = Table(title=title, header_style="bold")
    for c in ("joint", "k (N m/rad)", "std", "95 % low", "95 % high", "status"):
        t.add_column(c, justify="right" if c not in ("status",) else "left")
    for i, k in enumerate(r["joint_stiffness_Nm_per_rad"]):
        t.add_row(str(i + 1), fmt(k), fmt(r["joint_stiffness_std_Nm_per_rad"][i]),
                  fmt(r["joint_stiffness_ci95_low_Nm_per_rad"][i]),
                  fmt(r["joint_stiffness_ci95_high_Nm_per_rad"][i]), r["joint_status"][i])
    stdout.print(t)
    obs = r["observability"]
    stdout.print(kv_table("fit and observability", [
        ("equations / dof", f"{r['n_equations']} / {r['dof']}"),
        ("cond (column-scaled regressor)", obs["condition_number_scaled"]),
        ("residual rms translation (um)", r["residual_rms_translation_m"] * 1e6),
        ("residual rms rotation (urad)", r["residual_rms_rotation_rad"] * 1e6),
        ("tracker sigma estimated from residuals (um)",
         None if r["noise_sigma_estimated_m"] is None else r["noise_sigma_estimated_m"] * 1e6),
        ("chi2/dof with the given sigma", r["chi2_per_dof"]),
    ]))
    d = r["directional_stiffness_N_per_m"]
    lo, hi = (r["directional_stiffness_ci95_low_N_per_m"],
              r["directional_stiffness_ci95_high_N_per_m"])
    q = ", ".join(f"{v:g}" for v in r["directional_posture_deg"])
    stdout.print(kv_table(
        f"directional stiffness at the first (boring) posture ({q} deg), "
        f"{r['directional_frame']} frame, TCP {r['directional_tcp_m']} m",
        [(f"k_{a}{a} N/m [95 %]",
          "—" if d[a] is None else f"{fmt(d[a])}  [{fmt(lo[a])}, {fmt(hi[a])}]")
         for a in "xyz"]))
    for note in r.get("notes", []):
        stdout.print(f"[yellow]note:[/] {note}")
    sus = [e for e in r.get("residuals", []) if e.get("suspect")]
    for e in sus:
        stdout.print(f"[yellow]suspect measurement:[/] posture {e['posture']}, load step "
                     f"{e['load_step']} (row {e['first_row']}): normalised residual "
                     f"{e['normalised_residual']:.2f}, reflector fit rms "
                     f"{e['rigid_fit_rms_m'] * 1e6:.1f} um")
    byf = r.get("directional_stiffness_by_frame_N_per_m") or {}
    if byf.get("boring") is not None and r["directional_frame"] != "boring":
        b = byf["boring"]
        stdout.print("boring frame (X horizontal, Y vertical, Z feed = tool z): "
                     f"k_XX {fmt(b['x'])}, k_YY {fmt(b['y'])}, k_ZZ {fmt(b['z'])} N/m")


def _plot_identification(r: dict[str, Any], folder: Path) -> list[str]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    folder.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(1, 2, figsize=(11, 4))
    k = [np.nan if v is None else v for v in r["joint_stiffness_Nm_per_rad"]]
    lo = [np.nan if v is None else v for v in r["joint_stiffness_ci95_low_Nm_per_rad"]]
    hi = [np.nan if v is None else v for v in r["joint_stiffness_ci95_high_Nm_per_rad"]]
    x = np.arange(1, len(k) + 1)
    k, lo, hi = map(np.asarray, (k, lo, hi))
    ax[0].errorbar(x, k, yerr=[k - lo, hi - k], fmt="o", capsize=4)
    ax[0].set_yscale("log")
    ax[0].set_xlabel("joint")
    ax[0].set_ylabel("k (N m/rad), 95 % interval")
    ax[0].set_title("identified joint stiffness" + (" (SYNTHETIC)" if r.get("synthetic") else ""))
    res = r["residuals"]
    ax[1].bar(np.arange(len(res)), [e["translation_residual_m"] * 1e6 for e in res])
    ax[1].set_xlabel("measurement (posture, load step)")
    ax[1].set_ylabel("translation residual (um)")
    ax[1].set_title("per-measurement residuals")
    fig.tight_layout()
    from robobore.io.results import save_figure

    p = folder / "identify_stiffness.png"
    save_figure(fig, p, dpi=110)
    plt.close(fig)
    return [str(p)]


def register(groups: dict[str, typer.Typer]) -> None:
    """Add this stage's commands to the shared command groups."""
    groups["robot"].command("list")(list_cmd)
    groups["robot"].command("fk")(fk_cmd)
    groups["robot"].command("stiffness")(stiffness_cmd)
    groups["robot"].command("campaign")(campaign_cmd)
    groups["identify"].command("stiffness")(identify_stiffness_cmd)
