"""CLI commands of this stage (registered by ``robobore.cli``).

* ``robobore identify modes INPUT|--example [--band-hz LO HI] [--modes N] [--max-order N]
  [--plot DIR] [--json]``: FRFs (from time records if needed) -> CMIF -> pLSCF ->
  stabilisation -> automatic modes -> LSFD.
* ``robobore identify virtual-hammer-test OUT.uff [--noise ...] [--seed ...]``: write a
  SYNTHETIC hammer test (UFF 58 time records + 164 units) with its ground truth.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import typer

from robobore.clitools import (
    JSON_OPTION,
    check_count,
    check_option,
    emit,
    handle_errors,
    parse_floats,
    progress_bar,
)


def _render_modes(res: dict[str, Any]) -> None:
    from rich.table import Table

    from robobore.clitools import fmt, stdout

    t = Table(title=f"Modes ({res['source'] or 'data'}, band {res['band_Hz'][0]:.4g}-"
              f"{res['band_Hz'][1]:.4g} Hz, orders up to {res['max_order']})",
              header_style="bold")
    # dominant input: hammer input with the largest residues; m_eff: effective modal mass
    # at that input's driving point; orders: pLSCF orders where the mode is stable
    # share: the mode's share of the rank point's modal peak compliance
    # f and zeta with the half-width of their 95 % interval (jackknife over hits; time
    # records only); 1-MPC: 0 for a real mode; the orders that support each mode and its
    # CMIF support are in the JSON
    for c in ("#", "f (Hz)", "zeta (%)", "1-MPC", "input", "m_eff kg", "share %"):
        t.add_column(c, justify="right", min_width={"f (Hz)": 15, "zeta (%)": 11}.get(c))
    for k, m in enumerate(res["modes"]):
        mass = m.get("modal_mass_kg", {}).get(m["dominant_input"])
        sh = m.get("share")
        u = m.get("uncertainty")
        fs = f"{m['frequency_Hz']:.4f}"
        zs = f"{100 * m['damping_ratio']:.3f}"
        if u:
            fs += f"±{(u['frequency_ci95_Hz'][1] - u['frequency_ci95_Hz'][0]) / 2:.4f}"
            zs += f"±{50 * (u['damping_ci95'][1] - u['damping_ci95'][0]):.3f}"
        t.add_row(str(k + 1), fs, zs, f"{1 - m['mpc']:.1e}", m["dominant_input"], fmt(mass),
                  "-" if sh is None else f"{100 * sh:.1f}")
    stdout.print(t)
    sel = res["stabilisation"].get("selection")
    if sel:
        stdout.print(f"selection: {sel['select']} (rank point: {sel['rank_point']}; physical "
                     f"modes stable over >= {sel['orders_needed']} orders)")
    st = res["stabilisation"]
    stdout.print(f"poles: {st['n_poles']} over orders {st['orders'][0]}-{st['orders'][1]}; "
                 f"status counts {st['status_counts']}; CMIF peaks (Hz): "
                 + ", ".join(f"{f:.3g}" for f in st["cmif_peaks_Hz"]))
    fit = res["fit_percent"]
    if fit:
        import numpy as np

        stdout.print(f"LSFD fit: min {np.min(fit):.2f} %, mean {np.mean(fit):.2f} % over "
                     f"{np.size(fit)} FRFs")
    for w in res.get("warnings", []):
        stdout.print(f"[yellow]warning:[/] {w}")
    for p in res.get("plots", []):
        stdout.print(f"plot: {p}")


@handle_errors
def modes_cmd(
    input_file: Path | None = typer.Argument(
        None, help="UFF file (58 time records or FRFs, 164 units) or NPZ FRF file."),
    operational: Path | None = typer.Option(
        None, "--operational",
        help="Output-only record (NPZ data/sample_rate_Hz, or UFF 58 responses): SSI-COV."),
    spindle_rpm: float | None = typer.Option(
        None, "--spindle-rpm", help="Spindle speed of a cutting record (harmonics excluded)."),
    example: bool = typer.Option(False, "--example",
                                 help="Use the bundled SYNTHETIC robot hammer test."),
    band_hz: tuple[float, float] | None = typer.Option(
        None, "--band-hz", help="Analysis band LO HI in Hz (default: all lines)."),
    modes: int | None = typer.Option(None, "--modes", help="Number of modes to keep."),
    select: str = typer.Option(
        "dominant", "--select",
        help="Which N modes --modes keeps: dominant (largest share of the driving-point "
             "compliance), lowest (lowest well-supported), stable (best-supported)."),
    point: str | None = typer.Option(
        None, "--point", help="Output whose FRFs rank the modes (default: driving points)."),
    approx_hz: str | None = typer.Option(
        None, "--approx-hz", help="Approximate mode frequencies, comma-separated, Hz."),
    max_order: int = typer.Option(40, "--max-order", help="Highest pLSCF model order."),
    uncertainty: bool = typer.Option(
        True, "--uncertainty/--no-uncertainty",
        help="95 % intervals of f, zeta and shapes by the jackknife over hits (time records)."),
    estimator: str = typer.Option("H1", "--estimator", help="FRF estimator: H1, H2, Hv."),
    exp_window_tau_s: float | None = typer.Option(
        None, "--exp-window-tau-s", help="Exponential window time constant, s (corrected)."),
    drop_flagged: bool = typer.Option(False, "--drop-flagged",
                                      help="Leave out double hits and overloads."),
    frf_type: str | None = typer.Option(
        None, "--frf-type", help="FRF type of a UFF FRF file if its records do not say."),
    plot: Path | None = typer.Option(None, "--plot", help="Write PNG plots to this folder."),
    out: Path | None = typer.Option(None, "--out", help="Write the result JSON to this file."),
    robot: str | None = typer.Option(
        None, "--robot", help="Robot of the hammer test (library name or robot TOML), "
        "recorded in the result's identity (default: the test's identity file, if any)."),
    joints_deg: str | None = typer.Option(
        None, "--joints-deg", help="Posture of the hammer test, q1,..,q6 in deg, recorded in "
        "the result's identity."),
    as_json: bool = JSON_OPTION,
) -> None:
    """Identify modes (frequency, damping, MPC, shapes) from a hammer test automatically."""
    from robobore.errors import ConfigError, IdentificationError, InputError, NumericalError
    from robobore.io.outputs import check_output_dir, check_output_file
    from robobore.io.results import write_json
    from robobore.modal.example import EXAMPLE_BAND_HZ, example_path
    from robobore.modal.frf import DoubleHitWarning, LeakageWarning, estimate_frf
    from robobore.modal.frf_data import FRF_TYPES, FRFData
    from robobore.modal.identify import identify_modes
    from robobore.modal.io import load_input

    if operational is not None:
        if example or input_file is not None:
            raise ConfigError("--operational takes the record instead of INPUT/--example",
                              field="--operational", value=operational,
                              expected="--operational FILE alone")
        return _operational(operational, band_hz, modes, spindle_rpm, max_order, uncertainty,
                            plot, out, as_json)
    if spindle_rpm is not None:
        raise ConfigError("--spindle-rpm applies to --operational records",
                          field="--spindle-rpm", value=spindle_rpm,
                          expected="--operational FILE with it")
    if example == (input_file is not None):
        raise ConfigError("give either INPUT or --example", field="INPUT", value=input_file,
                          expected="a UFF/NPZ file path or the --example flag")
    check_output_dir(plot, "--plot", "the PNG plots")
    check_output_file(out, "--out", "the result JSON")
    for v in band_hz or ():  # plausible ranges (robobore.io.ranges)
        check_option(v, "--band-hz", "band_Hz")
    check_count(modes, "--modes", 1, 100)
    from robobore.modal.identify import SELECT_MODES

    if select not in SELECT_MODES:
        raise ConfigError("unknown mode selection", field="--select", value=select,
                          expected="one of " + ", ".join(SELECT_MODES))
    if max_order > 1000:  # (below 1: identify_modes says why)
        raise ConfigError("max order too high", field="--max-order", value=max_order,
                          expected="an integer 1 .. 1000 (the stabilisation diagram's orders)")
    check_option(exp_window_tau_s, "--exp-window-tau-s")
    if frf_type is not None and frf_type.strip().lower() not in FRF_TYPES:
        raise ConfigError("unknown FRF type", field="--frf-type", value=frf_type,
                          expected="one of " + ", ".join(FRF_TYPES))
    if example:
        input_file = example_path()
        if band_hz is None:
            band_hz = EXAMPLE_BAND_HZ
    approx = parse_floats(approx_hz, None, "--approx-hz", "Hz") if approx_hz else None
    warn_list: list[str] = []
    with progress_bar("modal analysis", 3, enabled=not as_json) as advance:
        from robobore.modal.io import UFFWarning

        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", UFFWarning)
            data = load_input(input_file, frf_type)
        warn_list += [str(w.message) for w in caught if issubclass(w.category, UFFWarning)]
        advance(1)
        hits = None
        load_meta = data
        if not isinstance(data, FRFData):
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", DoubleHitWarning)
                warnings.simplefilter("always", LeakageWarning)
                est = estimate_frf(data, estimator=estimator, exp_window_tau_s=exp_window_tau_s,
                                   drop_flagged=drop_flagged)
            warn_list += [str(w.message) for w in caught]
            data, hits = est, est
        elif exp_window_tau_s is not None:
            raise ConfigError("--exp-window-tau-s applies to time records only",
                              field="--exp-window-tau-s", value=exp_window_tau_s,
                              expected="no window option for FRF input")
        try:
            an = identify_modes(data, band_Hz=band_hz, n_modes=modes, approx_Hz=approx,
                                select=select, point=point, max_order=max_order,
                                uncertainty=uncertainty)
        except (IdentificationError, NumericalError) as exc:  # say which data it was
            raise type(exc)(f"{input_file}: {exc}") from None
        except InputError as exc:  # a band the data cannot give: name the data file
            if exc.file is not None:
                raise
            raise type(exc)(exc.message, file=str(input_file), field=exc.field,
                            value=exc.value, expected=exc.expected) from None
        advance(1)
        res = an.result.to_dict()
        res["source"] = str(input_file)
        ident = _test_identity(Path(input_file), robot, joints_deg, band_hz)
        res["synthetic"] = bool(example or ident["synthetic"])
        ident["synthetic"] = res["synthetic"]
        res["identity"] = ident
        if hits is not None:
            res["hits"] = hits.to_dict()
        from robobore.plan.virtual_hammer import parse_header

        meta = getattr(load_meta, "meta", None) or {}
        res.update(parse_header(meta.get("header")))
        res["warnings"] = warn_list
        if plot is not None:
            from robobore.modal.plots import plot_all

            res["plots"] = [str(p) for p in plot_all(an, plot)]
        advance(1)
    if out is not None:
        write_json(out, res)
    emit(res, as_json, _render_modes)


def _test_identity(path: Path, robot: str | None, joints_deg: str | None,
                   band_hz: Any) -> dict[str, Any]:
    """The identity of modes identified from ``path``: the hammer test's identity file
    (``<file>.truth.json``, written by the virtual hammer test) and the options, checked
    against each other."""
    from robobore.io.identity import check_posture, check_robot, make_identity, read_identity
    from robobore.io.readers import load_json

    tp = Path(str(path) + ".truth.json")
    ident = None
    synthetic = None
    if tp.is_file():
        data = load_json(tp, "hammer-test identity file",
                         "the JSON the virtual hammer test writes next to its UFF file")
        synthetic = bool(data.get("synthetic", False))
        ident = read_identity(data, str(tp))
    out = dict(ident) if ident is not None else make_identity("modes")
    out["kind"] = "modes"
    out["source"] = str(path)
    out["synthetic"] = synthetic if synthetic is not None else out.get("synthetic")
    if robot is not None:
        from robobore.robot.description import get_robot

        rb = get_robot(robot)
        check_robot(ident, str(tp), rb.name, rb.description_hash(), "--robot",
                    verb="is a hammer test of")
        out.update(robot=rb.name, robot_hash=rb.description_hash(), robot_file=rb.file or None)
    if joints_deg is not None:
        from robobore.clitools import stderr
        from robobore.io.ranges import radians_hint

        q = parse_floats(joints_deg, None, "--joints-deg", "deg")
        hint = radians_hint(q, "--joints-deg")
        if hint is not None:
            stderr.print(f"[yellow]warning:[/] {hint}", soft_wrap=True, highlight=False)
        check_posture(ident, str(tp), q, "--joints-deg")
        out["joints_deg"] = q
    return out


def _operational(path: Path, band_hz: tuple[float, float] | None, modes: int | None,
                 spindle_rpm: float | None, max_order: int, uncertainty: bool,
                 plot: Path | None, out: Path | None, as_json: bool) -> None:
    """``identify modes --operational FILE``: SSI-COV of an output-only record."""
    from robobore.errors import ConfigError, IdentificationError, InputError
    from robobore.io.outputs import check_output_dir, check_output_file
    from robobore.io.results import write_json
    from robobore.modal.oma import identify_operational, load_operational

    check_output_dir(plot, "--plot", "the PNG plots")
    check_output_file(out, "--out", "the result JSON")
    if band_hz is None:
        raise ConfigError("an operational record needs its band", field="--band-hz",
                          expected="--band-hz LO HI in Hz (LO sets the shortest record: ten "
                                   "periods)")
    for v in band_hz:
        check_option(v, "--band-hz", "band_Hz")
    check_count(modes, "--modes", 1, 100)
    check_option(spindle_rpm, "--spindle-rpm")
    if not 1 <= max_order <= 200:
        raise ConfigError("max order out of range", field="--max-order", value=max_order,
                          expected="an integer 1 .. 200 (modes; 2x that many states)")
    with progress_bar("operational modal analysis", 2, enabled=not as_json) as advance:
        rec = load_operational(path)
        advance(1)
        try:
            r = identify_operational(rec, band_hz, n_modes=modes, spindle_rpm=spindle_rpm,
                                     max_order=max_order, uncertainty=uncertainty)
        except (IdentificationError, InputError) as exc:
            if isinstance(exc, InputError) and exc.file is None:
                raise type(exc)(exc.message, file=str(path), field=exc.field,
                                value=exc.value, expected=exc.expected) from None
            if isinstance(exc, IdentificationError):
                raise type(exc)(f"{path}: {exc}") from None
            raise
        res = r.to_dict()
        res["source"] = str(path)
        res["record"] = {"channels": len(rec.channel_names), "sample_rate_Hz":
                         rec.sample_rate_Hz, "duration_s": rec.duration_s}
        if plot is not None:
            from robobore.modal.plots import plot_operational

            res["plots"] = [str(plot_operational(r, Path(plot) / "stabilisation_oma.png"))]
        advance(1)
    if out is not None:
        write_json(out, res)
    emit(res, as_json, _render_operational)


def _render_operational(res: dict[str, Any]) -> None:
    from rich.table import Table

    from robobore.clitools import stdout

    rec = res["record"]
    t = Table(title=f"Operational modes (SSI-COV, {res['source']}, {rec['channels']} "
              f"channels, {rec['duration_s']:.4g} s, band {res['band_Hz'][0]:.4g}-"
              f"{res['band_Hz'][1]:.4g} Hz)", header_style="bold")
    for c in ("#", "f (Hz)", "zeta (%)", "orders", "share %"):
        t.add_column(c, justify="right", min_width={"f (Hz)": 15, "zeta (%)": 11}.get(c))
    for k, m in enumerate(res["modes"]):
        u = m.get("uncertainty")
        fs = f"{m['frequency_Hz']:.4f}"
        zs = f"{100 * m['damping_ratio']:.3f}"
        if u:
            fs += f"±{(u['frequency_ci95_Hz'][1] - u['frequency_ci95_Hz'][0]) / 2:.4f}"
            zs += f"±{50 * (u['damping_ci95'][1] - u['damping_ci95'][0]):.3f}"
        t.add_row(str(k + 1), fs, zs, str(m["orders_stable"]), f"{100 * m['share']:.1f}")
    stdout.print(t)
    h = res.get("harmonics_excluded") or []
    if h:
        stdout.print("rotation harmonics excluded (Hz): "
                     + ", ".join(f"{x['frequency_Hz']:.3g}" for x in h))
    for p in res.get("plots", []):
        stdout.print(f"plot: {p}")


@handle_errors
def virtual_test_cmd(
    out: Path = typer.Argument(..., help="Output UFF file (time records, UFF 58 + 164)."),
    example: bool = typer.Option(False, "--example",
                                 help="Regenerate the bundled example exactly (its settings)."),
    noise: float = typer.Option(0.01, "--noise",
                                help="Noise std as a fraction of channel RMS (force, response)."),
    hits: int = typer.Option(5, "--hits", help="Hits per hammer direction."),
    directions: str = typer.Option("x,y,z", "--directions",
                                   help="Hammer directions at the tool point (subset of x,y,z)."),
    sample_rate_hz: float | None = typer.Option(
        None, "--sample-rate-hz",
        help="Sampling rate, Hz (default 256; with --robot a power of 2 >= 5x the top mode)."),
    duration_s: float = typer.Option(6.0, "--duration-s", help="Record length, s."),
    tip: str = typer.Option("soft", "--tip", help="Hammer tip: soft, medium, hard."),
    double_hit: list[str] = typer.Option([], "--double-hit",
                                         help="Make hit I,H (1-based) a double hit."),
    seed: int = typer.Option(0, "--seed", help="Random seed."),
    robot: str | None = typer.Option(
        None, "--robot", help="Test this library robot's multibody model (with --joints-deg)."),
    robot_file: Path | None = typer.Option(
        None, "--robot-file", help="Robot TOML file (D-H and [[links]] inertias) instead."),
    joints_deg: str | None = typer.Option(None, "--joints-deg", help="Posture q1,...,qn in deg."),
    joint_stiffness_file: Path | None = typer.Option(
        None, "--joint-stiffness-file",
        help="JSON with joint_stiffness_Nm_per_rad (`robobore identify stiffness --json`)."),
    joint_stiffness: str | None = typer.Option(
        None, "--joint-stiffness-Nm-per-rad", help="k1,...,kn in N m/rad (instead of a file)."),
    tcp_m: str | None = typer.Option(None, "--tcp-m", help="Tool point in the flange frame "
                                     "'x,y,z' in m (default: flange)."),
    damping_ratio: float = typer.Option(
        0.03, "--damping-ratio", help="Modal damping ratio of every mode (ASSUMED) with --robot."),
    as_json: bool = JSON_OPTION,
) -> None:
    """Write a SYNTHETIC impact-hammer test: the bundled robot boring truth; any robot's
    pose-dependent multibody model (--robot/--robot-file, --joints-deg and a joint stiffness);
    or, without a joint stiffness, the example's five modes on that robot's compliance at that
    posture (its ground-truth joint stiffness)."""
    from robobore.clitools import kv_table, stdout
    from robobore.errors import ConfigError
    from robobore.io.outputs import check_output_file
    from robobore.io.results import write_json
    from robobore.modal.example import (
        EXAMPLE_INPUT_DOFS,
        EXAMPLE_OUTPUT_DOFS,
        EXAMPLE_SETTINGS,
        make_example,
    )
    from robobore.modal.io import write_uff_time
    from robobore.modal.virtual import robot_boring_truth, simulate_hammer_test

    check_output_file(out, "OUT", "the UFF file")
    check_output_file(Path(str(out) + ".truth.json"), "OUT", "the ground-truth JSON")
    robot_info = None
    header = None
    if robot is not None and robot_file is not None:
        raise ConfigError("the robot is given twice", field="--robot", value=robot,
                          expected=f"--robot NAME or --robot-file PATH ({robot_file}), not both")
    if joint_stiffness_file is not None or (
            joint_stiffness is not None and (robot is not None or robot_file is not None)):
        # the robot's own multibody model at the posture
        truth, robot_info = _robot_truth(robot, robot_file, joints_deg, joint_stiffness_file,
                                         joint_stiffness, tcp_m or "0,0,0", damping_ratio,
                                         example)
        from robobore.plan.virtual_hammer import header_text, sample_rate_for

        rb_ = get_robot_for_identity(robot, robot_file)
        ident = _virtual_identity(rb_, robot_info["joints_deg"],
                                  parse_floats(tcp_m or "0,0,0", 3, "--tcp-m", "m"))
        header = header_text(robot_info)
        if sample_rate_hz is None:
            sample_rate_hz = sample_rate_for(truth)
    else:
        own = [n for n, v in (("--robot", robot), ("--robot-file", robot_file),
                              ("--joint-stiffness-Nm-per-rad", joint_stiffness),
                              ("--joints-deg", joints_deg), ("--tcp-m", tcp_m))
               if v is not None]
        if example and own:
            raise ConfigError("the bundled example has its own robot and posture", field=own[0],
                              expected="--example alone, or the options without --example")
        truth, ident = _virtual_truth(robot, robot_file, joint_stiffness, joints_deg, tcp_m)
    if sample_rate_hz is None:
        sample_rate_hz = 256.0
    if example:
        make_example(out)
        settings: dict[str, Any] = dict(EXAMPLE_SETTINGS)
    else:
        dirs = [d.strip().lower() for d in directions.split(",") if d.strip()]
        if not dirs or any(d not in ("x", "y", "z") for d in dirs) or len(set(dirs)) < len(dirs):
            raise ConfigError("bad hammer directions", field="--directions", value=directions,
                              expected="distinct values among x, y, z, comma-separated")
        rows = ["xyz".index(d) for d in dirs]
        truth = truth.with_inputs(rows)
        dh = []
        for s in double_hit:
            v = parse_floats(s, 2, "--double-hit", "(input, hit) 1-based indices")
            dh.append((int(v[0]) - 1, int(v[1]) - 1))
        if not 0 <= noise < 1:
            raise ConfigError("noise must be a fraction in [0, 1)", field="--noise", value=noise,
                              expected="e.g. 0.01 for 1 % of RMS")
        _check_hammer_size(len(rows), hits, truth.phi_out.shape[0], sample_rate_hz, duration_s)
        check_option(sample_rate_hz, "--sample-rate-hz", "sample_rate_Hz")
        check_option(duration_s, "--duration-s", "record_duration_s")
        check_count(seed, "--seed", 0, 2**32 - 1)
        settings = {"n_hits": hits, "sample_rate_Hz": sample_rate_hz, "duration_s": duration_s,
                    "tip": tip, "noise_force": noise, "noise_response": noise, "seed": seed,
                    "double_hits": dh}
        rec = simulate_hammer_test(truth, **settings)
        out_dofs = (EXAMPLE_OUTPUT_DOFS if robot_info is None else
                    [(1, 1), (1, 2), (1, 3), (2, 1), (2, 2), (2, 3)])
        write_uff_time(rec, out, [EXAMPLE_INPUT_DOFS[r] for r in rows], out_dofs,
                       "SYNTHETIC robobore virtual hammer test", header=header)
    truth_path = Path(str(out) + ".truth.json")
    info = {"file": str(out), "truth_file": str(truth_path), "synthetic": True,
            "settings": settings, "truth": truth.to_dict(), "identity": ident}
    if robot_info is not None:
        from robobore.plan.virtual_hammer import static_stiffness

        info["robot"] = robot_info
        info["static_stiffness_N_per_m"] = static_stiffness(truth.with_inputs(rows))
    write_json(truth_path, info)
    if as_json:
        emit(info, True, lambda r: None)
    else:
        stdout.print(kv_table("SYNTHETIC virtual hammer test", [
            ("file", str(out)), ("ground truth", str(truth_path)),
            ("modes (Hz)", ", ".join(f"{f:g}" for f in truth.frequencies_Hz)),
            ("damping ratios", ", ".join(f"{z:g}" for z in truth.damping_ratios)),
            ("hammer inputs", ", ".join(truth.input_names)),
            ("hits per input", settings["n_hits"]), ("noise (fraction of RMS)",
                                                      settings["noise_response"])]
            + ([("robot", robot_info["robot"]),
                ("posture (deg)", ", ".join(f"{v:g}" for v in robot_info["joints_deg"])),
                ("robot directional stiffness (N/um)", ", ".join(
                    f"{a} {v / 1e6:.4g}" for a, v in
                    robot_info["directional_stiffness_N_per_m"].items())),
                ("test static stiffness (N/um)", ", ".join(
                    f"{a} {v / 1e6:.4g}" for a, v in info["static_stiffness_N_per_m"].items())),
                ("sample rate (Hz)", settings["sample_rate_Hz"])]
               if robot_info is not None else [])))


def _robot_truth(robot: str | None, robot_file: Path | None, joints_deg: str | None,
                 stiffness_file: Path | None, stiffness: str | None, tcp_m: str,
                 damping_ratio: float, example: bool) -> tuple[Any, dict[str, Any]]:
    """The modal truth of a user's robot from the CLI options (ConfigError naming the option
    when one is missing or bad)."""
    from robobore.errors import ConfigError, IdentificationError, InputError
    from robobore.plan.virtual_hammer import robot_truth
    from robobore.robot.description import get_robot

    if example:
        raise ConfigError("--example regenerates the bundled test", field="--robot",
                          value=robot or robot_file, expected="either --example or --robot")
    if (robot is None) == (robot_file is None):
        raise ConfigError("give exactly one robot", field="--robot/--robot-file",
                          value=(robot, robot_file),
                          expected="--robot NAME (robobore robot list) or --robot-file F.toml")
    if robot_file is not None and not Path(robot_file).is_file():
        raise ConfigError("robot file not found", file=str(robot_file), field="--robot-file",
                          expected="a robot TOML file")
    rb = get_robot(robot if robot is not None else str(robot_file))
    if joints_deg is None:
        raise ConfigError("no posture given", field="--joints-deg",
                          expected=f"{rb.n_joints} comma-separated joint angles in deg")
    q = parse_floats(joints_deg, rb.n_joints, "--joints-deg", "deg")
    if (stiffness_file is None) == (stiffness is None):
        raise ConfigError("give exactly one joint stiffness", field="--joint-stiffness-file",
                          expected="--joint-stiffness-file s.json or "
                                   "--joint-stiffness-Nm-per-rad k1,...,kn")
    if stiffness_file is not None:
        from robobore.io.readers import load_json
        from robobore.robot.stiffness import JointStiffness

        data = load_json(Path(stiffness_file), "joint stiffness file",
                         "a JSON object from `robobore identify stiffness --json`")
        try:
            k = list(JointStiffness.from_dict(data).as_array())
        except (InputError, IdentificationError) as exc:
            msg = getattr(exc, "message", str(exc))
            raise ConfigError(msg, file=str(stiffness_file),
                              field=getattr(exc, "field", None) or "joint_stiffness_Nm_per_rad",
                              expected=f"{rb.n_joints} joint stiffnesses in N m/rad") from None
        named = str(data.get("robot", "") or "")
        if named and named not in (rb.name, str(robot_file)):
            raise ConfigError("the joint stiffness file is of another robot",
                              file=str(stiffness_file), field="robot", value=named,
                              expected=f"the stiffness of {rb.name}")
    else:
        k = parse_floats(stiffness, rb.n_joints, "--joint-stiffness-Nm-per-rad", "N m/rad")
    if len(k) != rb.n_joints:
        raise ConfigError("one joint stiffness per joint", field="joint_stiffness_Nm_per_rad",
                          value=len(k), expected=f"{rb.n_joints} values in N m/rad")
    tcp = parse_floats(tcp_m, 3, "--tcp-m", "m")
    try:
        return robot_truth(rb, q, k, tcp_m=tcp, damping_ratio=damping_ratio)
    except InputError as exc:
        raise ConfigError(exc.message, file=exc.file or rb.file or None, field=exc.field,
                          value=exc.value, expected=exc.expected) from None


def get_robot_for_identity(robot: str | None, robot_file: Path | None) -> Any:
    """The robot named by ``--robot`` or ``--robot-file``."""
    from robobore.robot.description import get_robot, load_robot_file

    return load_robot_file(robot_file) if robot_file is not None else get_robot(
        robot or "irb6600-175-2.55", field="--robot")


def _virtual_identity(rb: Any = None, q_deg: Any = None, tcp: Any = None) -> dict[str, Any]:
    """What the virtual hammer test describes: its robot at its posture (default: the
    example robot at the example posture)."""
    from robobore.io.identity import make_identity
    from robobore.modal.virtual import EXAMPLE_POSTURE_DEG, EXAMPLE_ROBOT, EXAMPLE_TCP_M
    from robobore.robot.description import get_robot

    rb = get_robot(EXAMPLE_ROBOT) if rb is None else rb
    return make_identity("hammer test", robot=rb.name, robot_hash=rb.description_hash(),
                         robot_file=(rb.file or None) if rb.name != EXAMPLE_ROBOT else None,
                         joints_deg=EXAMPLE_POSTURE_DEG if q_deg is None else q_deg,
                         tcp_m=EXAMPLE_TCP_M if tcp is None else tcp, frame="boring",
                         synthetic=True, source="robobore virtual hammer test")


def _virtual_truth(robot: str | None, robot_file: Path | None, joint_stiffness: str | None,
                   joints_deg: str | None, tcp_m: str | None):
    """The truth model and identity of a virtual hammer test (options checked here)."""
    from robobore.modal.virtual import EXAMPLE_POSTURE_DEG, EXAMPLE_TCP_M, robot_boring_truth
    from robobore.robot.description import check_joint_limits, get_robot, load_robot_file

    if robot is None and robot_file is None and joint_stiffness is None and \
            joints_deg is None and tcp_m is None:
        return robot_boring_truth(), _virtual_identity()
    rb = (load_robot_file(robot_file) if robot_file is not None else
          get_robot(robot or "irb6600-175-2.55", field="--robot"))
    q = (list(EXAMPLE_POSTURE_DEG) if joints_deg is None
         else parse_floats(joints_deg, rb.n_joints, "--joints-deg", "deg"))
    from robobore.clitools import stderr
    from robobore.io.ranges import radians_hint

    hint = radians_hint(q, "--joints-deg")
    if hint is not None:
        stderr.print(f"[yellow]warning:[/] {hint}", soft_wrap=True, highlight=False)
    import numpy as np

    from robobore.errors import ConfigError, InputError

    try:
        check_joint_limits(rb, np.radians(q))
    except InputError as exc:
        raise ConfigError(exc.message, field=f"--joints-deg ({exc.field})", value=exc.value,
                          expected=exc.expected) from None
    k = None if joint_stiffness is None else parse_floats(
        joint_stiffness, rb.n_joints, "--joint-stiffness-Nm-per-rad", "N m/rad")
    if k is not None and any(not v > 0 for v in k):
        raise ConfigError("joint stiffnesses must be positive",
                          field="--joint-stiffness-Nm-per-rad", value=joint_stiffness,
                          expected=f"{rb.n_joints} positive values in N m/rad")
    tcp = list(EXAMPLE_TCP_M) if tcp_m is None else parse_floats(tcp_m, 3, "--tcp-m", "m")
    truth = robot_boring_truth(k, q, rb, tcp)
    return truth, _virtual_identity(rb, q, tcp)


def _check_hammer_size(n_inputs: int, hits: int, n_outputs: int, sample_rate_hz: float,
                       duration_s: float) -> None:
    """Refuse a virtual test whose records cannot fit in memory (before simulating)."""
    import math

    from robobore.errors import ConfigError
    from robobore.io.memory import check_memory, hammer_test_bytes

    for name, v in (("--sample-rate-hz", sample_rate_hz), ("--duration-s", duration_s)):
        if not (math.isfinite(v) and v > 0):
            raise ConfigError("must be a positive number", field=name, value=v,
                              expected="a finite value > 0 (Hz or s)")
    if hits < 1:
        raise ConfigError("at least one hit per direction", field="--hits", value=hits,
                          expected="an integer >= 1")
    n = sample_rate_hz * duration_s
    check_memory(hammer_test_bytes(n_inputs, hits, n_outputs, int(min(n, 1e18))),
                 f"the virtual hammer test ({n_inputs} x {hits} hits of {n:.3g} samples)",
                 "--sample-rate-hz, --duration-s or --hits", value=n)


def register(groups: dict[str, typer.Typer]) -> None:
    """Add this stage's commands to the shared command groups."""
    groups["identify"].command("modes")(modes_cmd)
    groups["identify"].command("virtual-hammer-test")(virtual_test_cmd)
