"""Posture planning for a bore: candidates, their stiffness, modes and chatter limit, best one.

A six-axis robot holding a boring spindle keeps three freedoms once the bore is fixed: the
rotation of the flange about the tool axis (the spindle turns anyway), the inverse-kinematics
branch, and where the part sits. :func:`plan_posture` enumerates the first two (and, with a
``[workspace]`` section, a grid of part placements) and rates every candidate with the
calibrated pose-dependent model (:mod:`robobore.plan.model`):

1. tool-axis rotation ``psi`` on a grid of ``[plan] rotation_step_deg`` (angle of the flange x
   axis about the bore axis from the boring-frame X; the grid is anchored at the measured
   posture's angle so that the measured posture is a candidate when it reaches the bore);
2. every closed-form IK branch (:mod:`robobore.plan.ik`); each solution is verified by forward
   kinematics (tool point within 0.1 mm, tool axis within 0.05 deg of the bore axis) and kept
   when inside the joint limits and at least ``singularity_margin`` from a singularity
   (smallest singular value of the Jacobian with its translational rows divided by the
   robot's reach ``L = sum |a_i| + |d_i|``: dimensionless, 0 at a singularity);
3. per candidate: directional stiffness in the boring frame, modes, the critical depth at the
   ``[cutting]`` speed (the speed the cut runs at; the lowest critical depth over the
   ``[lobes]`` speed range is reported beside it, ``critical_depth_range_min_mm``: on a robot
   it is often 0 at every candidate, some speed of the range having no chatter-free depth,
   and would rank nothing), and the feed-direction amplitude of the steady cut at
   ``[cutting]`` (half peak-to-peak of Z of the periodic orbit the time-domain simulation
   starts on and settles to, :func:`robobore.plan.scoring.steady_feed_amplitude`: the same
   computation, so the same number as ``simulate boring`` on the same structure). The
   critical depth of every candidate is first screened by the zero-order frequency domain
   (:mod:`robobore.plan.chatter`); the best :data:`SD_TOP` of the screen and the measured
   posture are then rated by the semi-discretisation of the stability module (the method of
   ``robobore lobes``: :func:`~robobore.dynamics.semidiscretization.chatter_free_window` at
   the cutting speed, the lobes over the range for the range minimum;
   ``critical_depth_method`` says which a value comes from);
4. recommendation: the candidate with the largest value of the criterion
   (``critical_depth`` by default, among the semi-discretisation-rated candidates, or
   ``stiffness_x``/``stiffness_y``/``stiffness_z``/``stiffness_min``).

Config: see ``examples/plan_paper_bore.toml`` and docs/plan.md.

The modules behind it: :mod:`robobore.plan.config` (the config), :mod:`robobore.plan.candidates`
(steps 1-2), :mod:`robobore.plan.scoring` (steps 3-4); this module runs them and writes the
result (JSON contract, netCDF dataset, workspace map).
"""

from __future__ import annotations

import math
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from robobore.dynamics.results import Vector3
from robobore.errors import InputError
from robobore.plan.candidates import (
    AXIS_TOL_DEG,
    POSITION_TOL_M,
    Candidates,
    boring_frame,
    enumerate_candidates,
    reach_length,
    rotation_grid,
    rotation_of,
)
from robobore.plan.config import PlanInputs, load_plan_config
from robobore.plan.results import (
    BoreFrame,
    Candidate,
    PlanArrays,
    PlanCounts,
    PlanMode,
    PostureError,
    PostureLobes,
    PostureResult,
)
from robobore.plan.scoring import (
    CRITERION_UNITS,
    build_process,
    criterion_values,
    evaluate,
    recommend,
)

#: an rms frequency residual of the calibration above this (%) is reported: the stiffness,
#: the modes and the posture do not describe one robot (the bundled example: 29 %; mode
#: frequencies in rad/s given as Hz: 64 %; joint stiffnesses x 1000: about 2,240 %)
CALIBRATION_WARN_PERCENT = 50.0


#: Semi-discretisation rating of the plan: the best SD_TOP candidates of the frequency-domain
#: screen (and the measured posture) over SD_SPEEDS speeds of the [lobes] range.
SD_TOP = 3
SD_SPEEDS = 30
#: Modes whose tool-point flexibility is below this share of the largest are left out of the
#: structures the plan rates (:meth:`robobore.plan.model.PostureModes.structure`): they do not move
#: the tool point, but a stiff local mode would set the semi-discretisation step.
PLAN_MODE_SHARE = 1e-3


def _flat_map_warning(crit: np.ndarray, name: str) -> list[str]:
    """A sentence when the criterion does not vary over the candidates (the map is flat)."""
    fin = crit[np.isfinite(crit)]
    if fin.size > 1 and np.ptp(fin) <= 1e-6 * max(abs(float(fin.max())), 1e-300):
        return [f"the {name} criterion does not vary over the {fin.size} candidates "
                f"({float(fin.max()):.4g}): the posture choice does not matter for it here "
                "(e.g. a tool axis along the flange axis, where the rotation only turns "
                "joint 6)"]
    return []


def _coefficient_warnings(process: Any) -> list[str]:
    """The cutting coefficients' domain warnings at the plan's cut (a cutting speed or chip
    thickness outside the set's calibrated range), each prefixed ``coefficients:``."""
    g = getattr(process, "geometry", None)
    if g is None:
        return []
    return [f"coefficients: {w}" for w in g.coefficients.domain_warnings(process.h0)]


def _same_posture(q1: np.ndarray, q2: np.ndarray, tol: float = 1e-6) -> bool:
    d = np.angle(np.exp(1j * (np.asarray(q1) - np.asarray(q2))))
    return bool(np.max(np.abs(d)) < tol)


def plan_posture(config: str | Path, *, progress_factory: Any = None,
                 x_hint: Any = None) -> PostureResult:
    """Run the posture plan of a config file; returns the :class:`PostureResult` (its
    ``to_dict()`` the JSON contract, its ``arrays`` the in-memory candidates and model).
    ``x_hint`` overrides the config's ``bore.x_hint`` (the boring frame's X direction).

    ``progress_factory(description, total)`` -> context manager yielding ``advance(n)``
    (optional; :func:`robobore.clitools.progress_bar`).
    """
    t0 = time.perf_counter()
    return run_plan(load_plan_config(config, x_hint), progress_factory=progress_factory, t0=t0)


def run_plan(inp: PlanInputs, *, progress_factory: Any = None,
             t0: float | None = None) -> PostureResult:
    """The posture plan for validated inputs (see :func:`plan_posture`)."""
    from contextlib import nullcontext

    from robobore.dynamics.semidiscretization import chatter_free_window
    from robobore.dynamics.stability import lobes_semidiscretization
    from robobore.plan.inertia import ToolBody
    from robobore.plan.model import PoseModel, calibrate
    from robobore.robot.kinematics import fk

    t0 = time.perf_counter() if t0 is None else t0
    cfg, robot, f = inp.cfg, inp.robot, str(inp.path)
    tool = ToolBody(cfg.tool.mass_kg, tuple(cfg.tool.com_m), tuple(cfg.tool.inertia_kg_m2))
    model0 = PoseModel(robot, inp.k_Nm_per_rad, np.zeros(robot.n_joints), tool=tool,
                       link_bending=inp.link_bending,
                       tcp_m=tuple(inp.tcp_m), robot_file=robot.file or None,
                       x_hint=None if inp.x_hint is None else tuple(inp.x_hint))
    cal = calibrate(model0, inp.q_meas_rad, inp.modes_f_Hz, inp.modes_zeta)
    model = cal.model
    from robobore.io.ranges import radians_hint

    hint = radians_hint(np.degrees(inp.q_meas_rad).tolist(),
                        f"{f}: the measured posture (identification.posture_deg)")
    warn = [] if hint is None else [hint]
    rms_cal = float(np.sqrt(np.mean(cal.frequency_error_percent ** 2)))
    if not rms_cal <= CALIBRATION_WARN_PERCENT:
        warn.append(
            f"the model calibrated at the measured posture misses the identified modes by "
            f"{rms_cal:.4g} % rms (more than {CALIBRATION_WARN_PERCENT:g} %): the joint "
            f"stiffnesses ({inp.stiffness_file}), the modes ({inp.modes_file}) and the posture "
            "may not belong together (another robot, a unit slip such as N m/rad x 1000, "
            "rad/s as Hz); the plan's figures are not reliable")
    process = build_process(inp)
    A0 = process.mean_directional_matrix()
    from robobore.io.identity import make_identity

    Rb = boring_frame(inp.bore_axis, inp.x_hint)
    # measured posture: does it hold this bore? anchor the rotation grid at its angle
    Tm = fk(robot, inp.q_meas_rad, inp.tcp_m)
    meas_pos_err = float(np.linalg.norm(Tm[:3, 3] - inp.bore_point_m))
    meas_ax_err = float(np.degrees(np.arccos(np.clip(Tm[:3, 2] @ inp.bore_axis, -1, 1))))
    meas_reaches = meas_pos_err <= POSITION_TOL_M and meas_ax_err <= AXIS_TOL_DEG
    anchor = rotation_of(Rb, Tm[:3, :3]) if meas_reaches else 0.0
    rot = rotation_grid(cfg.plan.rotation_step_deg, anchor)
    cand = enumerate_candidates(robot, inp.bore_point_m, inp.bore_axis, inp.tcp_m, rot,
                                cfg.plan.singularity_margin, inp.x_hint)
    if cand.n_reached == 0:
        raise InputError(
            "the bore is out of the robot's reach at every tool-axis rotation and IK branch",
            file=f, field="bore.point_m", value=[round(float(v), 6) for v in inp.bore_point_m],
            expected=f"a point the tool (tcp {inp.tcp_m.tolist()} m) can reach with its axis "
                     f"along bore.axis; robot '{robot.name}' reach about "
                     f"{reach_length(robot):.2f} m (base frame, m)")
    if cand.q_rad.shape[0] == 0:
        raise InputError(
            f"no posture reaches the bore inside the joint limits with singularity margin "
            f"{cfg.plan.singularity_margin} ({cand.n_reached} IK solutions reach it, "
            f"{cand.n_in_limits} inside the limits)", file=f, field="bore.point_m",
            value=[round(float(v), 6) for v in inp.bore_point_m],
            expected="a bore position/axis the robot reaches inside its limits, or a smaller "
                     "plan.singularity_margin")
    pf = progress_factory or (lambda d, t: nullcontext(lambda n=1: None))
    with pf("posture candidates", cand.q_rad.shape[0]) as adv:
        ev = evaluate(model, robot, cand, process, A0, cfg, adv)
    meas_idx = None
    for i in np.flatnonzero(np.abs(((cand.rotation_deg - anchor) + 180) % 360 - 180) < 1e-9):
        if _same_posture(cand.q_rad[i], inp.q_meas_rad):
            meas_idx = int(i)
    # the chatter limit of the lobes' method: the frequency-domain limit screens every
    # candidate; the best SD_TOP of the screen and the measured posture are rated by the
    # semi-discretisation lobes (the default of `robobore lobes`) on the same structure and
    # process, and the recommendation is the best of those
    speeds = np.linspace(cfg.lobes.speed_min_rpm, cfg.lobes.speed_max_rpm, SD_SPEEDS)
    method = np.array(["frequency (screening)"] * cand.q_rad.shape[0], dtype=object)
    crit0 = criterion_values(cfg.plan.criterion, ev["stiffness_N_per_m"],
                             ev["critical_depth_m"])
    order = [int(i) for i in np.argsort(-np.where(np.isnan(crit0), -np.inf, crit0),
                                        kind="stable")[:SD_TOP]]
    rated = sorted(set(order) | ({meas_idx} if meas_idx is not None else set()))
    sd_lobes = {}
    at_speed: dict[int, tuple[float, float]] = {}
    structures: dict[int, Any] = {}
    by_structure: dict[tuple, Any] = {}
    n_cut = float(cfg.cutting.speed_rpm)

    def sd(idx: int):
        # candidates with the same structure (a tool-axis rotation about the flange axis)
        # share their lobes: (lobes over the range, (interrupted below, limit) at the speed)
        st = model.modes(cand.q_rad[idx]).structure(0, PLAN_MODE_SHARE)
        key = (tuple(np.round(st.frequency_Hz, 6)), tuple(np.round(st.damping_ratio, 8)),
               tuple(np.round(st.stiffness_N_per_m, 0)), tuple(np.round(st.directions, 6).ravel()))
        if key not in by_structure:
            by_structure[key] = (lobes_semidiscretization(st, process, speeds),
                                 chatter_free_window(st, process, n_cut), st)
        return by_structure[key]

    def rate(idx: int) -> None:
        L, win, st = sd(idx)
        sd_lobes[idx], at_speed[idx] = L, win
        structures[idx] = st
        ev["critical_depth_m"][idx] = float(win[1])
        ev["critical_depth_range_min_m"][idx] = float(np.min(L.critical_depth_m))
        ev["critical_speed_rpm"][idx] = float(speeds[int(np.argmin(L.critical_depth_m))])
        ev["chatter_frequency_Hz"][idx] = math.nan
        method[idx] = "semi-discretization"

    with pf("semi-discretisation lobes", len(rated)) as adv:
        for idx in rated:
            rate(idx)
            adv(1)
    ev["critical_depth_method"] = method
    crit = criterion_values(cfg.plan.criterion, ev["stiffness_N_per_m"], ev["critical_depth_m"])
    pick = np.array([c if method[i] == "semi-discretization" else -np.inf
                     for i, c in enumerate(crit)]) if cfg.plan.criterion == "critical_depth" \
        else crit
    best = recommend(pick, cand.q_rad, inp.q_meas_rad)
    if best not in sd_lobes:
        rate(best)
        crit = criterion_values(cfg.plan.criterion, ev["stiffness_N_per_m"],
                                ev["critical_depth_m"])
    entries = [_entry(i, cand, ev) for i in range(cand.q_rad.shape[0])]
    # the semi-discretisation lobes at the recommended and measured postures
    lobes = {}
    for name, idx in (("recommended", best), ("measured", meas_idx)):
        if idx is None:
            continue
        L = sd_lobes[idx]
        below, lim = at_speed[idx]
        lobes[name] = PostureLobes(
            method=L.method, speed_rpm=tuple(speeds.tolist()),
            critical_depth_mm=tuple((L.critical_depth_m * 1e3).tolist()),
            interrupted_below_mm=tuple((L.interrupted_below_m * 1e3).tolist()),
            cutting_speed_rpm=n_cut,
            critical_depth_at_speed_mm=float(lim * 1e3),
            interrupted_below_at_speed_mm=float(below * 1e3),
            # the structure these lobes are of ([structure] modes of a
            # `robobore lobes` / `simulate boring` config)
            tool_point_modes=tuple(m.to_dict() for m in structures[idx].modes()))
    equivalent = {}
    for name, idx in (("recommended", best), ("measured", meas_idx)):
        if idx is not None:
            equivalent[name] = model.equivalent(cand.q_rad[idx]).table()
    wall = time.perf_counter() - t0
    return PostureResult(
        config=f,
        robot=robot.name,
        criterion=cfg.plan.criterion,
        criterion_unit=CRITERION_UNITS[cfg.plan.criterion],
        recommended=replace(entries[best], criterion_value=float(crit[best])),
        measured=None if meas_idx is None else replace(
            entries[meas_idx], criterion_value=float(crit[meas_idx])),
        measured_posture_deg=tuple(np.degrees(inp.q_meas_rad).tolist()),
        measured_posture_reaches_bore=meas_reaches,
        measured_posture_error=PostureError(position_mm=meas_pos_err * 1e3,
                                            axis_deg=meas_ax_err),
        calibration=cal.to_dict(),
        bore=BoreFrame(point_m=tuple(inp.bore_point_m.tolist()),
                       axis=tuple(inp.bore_axis.tolist()),
                       x_hint=None if inp.x_hint is None else tuple(inp.x_hint.tolist()),
                       boring_frame_columns=tuple(tuple(c) for c in Rb.T.tolist())),
        tcp_m=tuple(inp.tcp_m.tolist()),
        counts=PlanCounts(rotations=int(rot.size), ik_solutions_tried=cand.n_tried,
                          reaching=cand.n_reached, inside_limits=cand.n_in_limits,
                          candidates=int(cand.q_rad.shape[0])),
        max_position_error_mm=float(cand.position_error_m.max() * 1e3),
        max_axis_error_deg=float(cand.axis_error_deg.max()),
        speed_range_rpm=(cfg.lobes.speed_min_rpm, cfg.lobes.speed_max_rpm),
        cutting=cfg.cutting.model_dump(),
        candidates=tuple(entries),
        lobes=lobes,
        equivalent_model=equivalent,
        synthetic_inputs=bool(inp.synthetic),
        notes=tuple(inp.notes),
        warnings=tuple(warn + cal.warnings() + _flat_map_warning(crit0, cfg.plan.criterion)
                       + _coefficient_warnings(process)),
        identity=make_identity(
            "plan", robot=robot.name, robot_hash=robot.description_hash(),
            robot_file=robot.file or None, joints_deg=list(entries[best].joints_deg),
            tcp_m=inp.tcp_m.tolist(), frame="boring", synthetic=bool(inp.synthetic),
            source=f),
        wall_time_s=wall,
        arrays=PlanArrays(cand=cand, ev=ev, criterion=crit, best=best, measured=meas_idx,
                          rotations=rot, model=model, inputs=inp, process=process),
    )


def _entry(i: int, cand: Candidates, ev: dict[str, np.ndarray]) -> Candidate:
    from robobore.plan.ik import branch_label

    k = ev["stiffness_N_per_m"][i]
    b = ev["critical_depth_m"][i]
    bm = ev["critical_depth_range_min_m"][i]
    return Candidate(
        joints_deg=tuple(np.degrees(cand.q_rad[i]).tolist()),
        tool_axis_rotation_deg=float(cand.rotation_deg[i]),
        branch=int(cand.branch[i]),
        branch_label=branch_label(int(cand.branch[i])),
        directional_stiffness_N_per_m=Vector3(x=float(k[0]), y=float(k[1]), z=float(k[2])),
        modes=tuple(PlanMode(frequency_Hz=float(fr), damping_ratio=float(z))
                    for fr, z in zip(ev["frequency_Hz"][i], ev["damping_ratio"][i],
                                     strict=True)),
        critical_depth_mm=None if not math.isfinite(b) else float(b * 1e3),
        critical_depth_range_min_mm=None if not math.isfinite(bm) else float(bm * 1e3),
        critical_speed_rpm=float(ev["critical_speed_rpm"][i]),
        critical_depth_method=str(ev["critical_depth_method"][i]),
        chatter_frequency_Hz=float(ev["chatter_frequency_Hz"][i]),
        feed_amplitude_um=float(ev["feed_amplitude_m"][i] * 1e6),
        singularity_measure=float(cand.singularity[i]),
        position_error_mm=float(cand.position_error_m[i] * 1e3),
        axis_error_deg=float(cand.axis_error_deg[i]),
    )


def results_dataset(result: PostureResult) -> Any:
    """The candidates as an xarray Dataset (dims candidate, joint, mode, axis)."""
    import xarray as xr

    A = result.arrays
    cand, ev = A.cand, A.ev
    n, nj = cand.q_rad.shape
    nm = ev["frequency_Hz"].shape[1]
    ds = xr.Dataset(
        {
            "joints": (("candidate", "joint"), np.degrees(cand.q_rad), {"units": "deg"}),
            "tool_axis_rotation": (("candidate",), cand.rotation_deg, {"units": "deg"}),
            "branch": (("candidate",), cand.branch.astype(np.int16)),
            "directional_stiffness": (("candidate", "axis"), ev["stiffness_N_per_m"],
                                      {"units": "N/m", "frame": "boring (Z bore axis)"}),
            "frequency": (("candidate", "mode"), ev["frequency_Hz"], {"units": "Hz"}),
            "damping_ratio": (("candidate", "mode"), ev["damping_ratio"]),
            "critical_depth": (("candidate",), ev["critical_depth_m"] * 1e3,
                               {"units": "mm", "long_name": "critical depth at the cutting "
                                "speed"}),
            "critical_depth_range_min": (("candidate",), ev["critical_depth_range_min_m"] * 1e3,
                                         {"units": "mm", "long_name": "lowest critical depth "
                                          "over the speed range"}),
            "chatter_frequency": (("candidate",), ev["chatter_frequency_Hz"], {"units": "Hz"}),
            "feed_amplitude": (("candidate",), ev["feed_amplitude_m"] * 1e6, {"units": "um"}),
            "singularity_measure": (("candidate",), cand.singularity),
            "criterion": (("candidate",), A.criterion,
                          {"name": result.criterion, "units": result.criterion_unit}),
        },
        coords={"candidate": np.arange(n), "joint": np.arange(1, nj + 1),
                "mode": np.arange(1, nm + 1), "axis": ["x", "y", "z"]},
        attrs={"recommended_candidate": A.best,
               "measured_candidate": -1 if A.measured is None else A.measured,
               "criterion": result.criterion, "robot": result.robot,
               "synthetic_inputs": int(result.synthetic_inputs)},
    )
    return ds


def workspace_map(result: PostureResult, progress: Any = None) -> dict[str, Any] | None:
    """Best criterion value over rotations x branches at each part placement of
    ``[workspace]`` (the bore point shifted by (dx, dy) in the base frame)."""
    inp: PlanInputs = result.arrays.inputs
    ws = inp.cfg.workspace
    if ws is None:
        return None
    model = result.arrays.model
    process = result.arrays.process
    A0 = process.mean_directional_matrix()
    rot = rotation_grid(ws.rotation_step_deg)
    best = np.full((len(ws.dy_m), len(ws.dx_m)), np.nan)
    for iy, dy in enumerate(ws.dy_m):
        for ix, dx in enumerate(ws.dx_m):
            pt = inp.bore_point_m + np.array([dx, dy, 0.0])
            cand = enumerate_candidates(inp.robot, pt, inp.bore_axis, inp.tcp_m, rot,
                                        inp.cfg.plan.singularity_margin, inp.x_hint)
            if cand.q_rad.shape[0]:
                ev = evaluate(model, inp.robot, cand, process, A0, inp.cfg,
                              criterion_only=True)
                c = criterion_values(inp.cfg.plan.criterion, ev["stiffness_N_per_m"],
                                     ev["critical_depth_m"])
                best[iy, ix] = float(np.max(c))
            if progress is not None:
                progress(1)
    return {"dx_m": list(ws.dx_m), "dy_m": list(ws.dy_m),
            "best_criterion": [[None if not np.isfinite(v) else float(v) for v in row]
                               for row in best],
            "criterion": inp.cfg.plan.criterion, "rotation_step_deg": ws.rotation_step_deg}


__all__ = ["plan_posture", "run_plan", "results_dataset", "workspace_map"]
