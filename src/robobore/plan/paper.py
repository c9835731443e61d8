"""The posture map of the paper's bore, for the report of ``robobore paper``.

The paper's bore is where its boring posture puts the tool point (``[robot] posture_deg`` and
``tcp_m`` of paper.toml, forward kinematics) with the tool axis along the flange z axis. The
plan uses the study's own identification results (joint stiffness, modes), insert, force
coefficients, base condition and lobe speed range; the end effector is the ASSUMED one of
``examples/plan_paper_bore.toml`` (:data:`PAPER_END_EFFECTOR`).
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any

import numpy as np

from robobore.errors import RoboboreError
from robobore.plan.inertia import ToolBody

#: ASSUMED end effector for the paper's cell: electro-spindle + boring bar, 60 kg, centre of
#: mass 0.15 m along the flange z axis (solid cylinder 0.2 m diameter, 0.4 m long).
PAPER_END_EFFECTOR = ToolBody(60.0, (0.0, 0.0, 0.15), (0.95, 0.95, 0.30, 0.0, 0.0, 0.0))
#: workspace map of the report: part shifts (base frame) and rotation step
WORKSPACE_SHIFTS_M = (-0.3, -0.15, 0.0, 0.15, 0.3)
WORKSPACE_ROTATION_STEP_DEG = 10.0


def paper_posture_plan(cfg: Any, cfg_path: Path, stiff: dict[str, Any], modes: dict[str, Any],
                       coeffs: dict[str, Any], coefficients: dict[str, Any] | None = None
                       ) -> dict[str, Any]:
    """Plan for the paper's bore (compact, JSON-ready); ``{"error": msg}`` when it cannot be
    made (for instance a robot without inertial data), so the report says why. The plan's
    ``[coefficients]`` table is ``coefficients`` (the study's set), or the coefficients-file
    content ``coeffs`` inline when it is None."""
    from robobore.cutting.coefficient_files import inline_coefficients
    from robobore.plan.config import PlanConfig, PlanInputs
    from robobore.plan.posture import run_plan, workspace_map
    from robobore.robot.description import get_robot
    from robobore.robot.kinematics import fk

    t0 = time.perf_counter()
    try:
        robot = get_robot(cfg.robot.name)
        q = np.radians(np.asarray(cfg.robot.posture_deg, float))
        tcp = np.asarray(cfg.robot.tcp_m, float)
        T = fk(robot, q, tcp)
        k = stiff["identification"]["joint_stiffness_Nm_per_rad"]
        if any(v is None for v in k):
            return {"error": "joint stiffness not identified for every joint"}
        base = cfg.study.base
        pc = PlanConfig.model_validate({
            "robot": {"name": cfg.robot.name},
            "identification": {"joint_stiffness": "(paper study)", "modes": "(paper study)",
                               "posture_deg": list(cfg.robot.posture_deg)},
            "tool": {"tcp_m": list(cfg.robot.tcp_m), "mass_kg": PAPER_END_EFFECTOR.mass_kg,
                     "com_m": list(PAPER_END_EFFECTOR.com_m),
                     "inertia_kg_m2": list(PAPER_END_EFFECTOR.inertia_kg_m2)},
            "bore": {"point_m": T[:3, 3].tolist(), "axis": T[:3, 2].tolist(),
                     "diameter_mm": cfg.bore.diameter_mm},
            "insert": cfg.insert.model_dump(),
            "cutting": {"speed_rpm": float(base["speed_rpm"]),
                        "feed_mm_per_rev": float(base["feed_mm_per_rev"]),
                        "depth_mm": float(base["depth_of_cut_mm"])},
            "coefficients": (inline_coefficients(coeffs, cfg.coefficients.speed_dependent)
                             if coefficients is None else coefficients),
            "lobes": {"speed_min_rpm": cfg.lobes.speed_min_rpm,
                      "speed_max_rpm": cfg.lobes.speed_max_rpm},
            "workspace": {"dx_m": list(WORKSPACE_SHIFTS_M), "dy_m": list(WORKSPACE_SHIFTS_M),
                          "rotation_step_deg": WORKSPACE_ROTATION_STEP_DEG},
        })
        fz = np.array([[m["frequency_Hz"], m.get("damping_ratio", 0.0)]
                       for m in modes["modes"]], float)
        inp = PlanInputs(pc, {}, Path(cfg_path), robot, np.asarray(k, float), fz[:, 0],
                         fz[:, 1], q, tcp, T[:3, 3].copy(), T[:3, 2].copy(), None, None,
                         bool(stiff.get("synthetic") or modes.get("synthetic")))
        res = run_plan(inp)
        ws = workspace_map(res)
    except RoboboreError as exc:
        return {"error": str(exc)}
    A = res.arrays
    cand = A.cand
    keep = ("joints_deg", "tool_axis_rotation_deg", "branch", "branch_label",
            "directional_stiffness_N_per_m", "critical_depth_mm", "critical_depth_range_min_mm",
            "critical_depth_method", "feed_amplitude_um", "criterion_value")
    short = {}
    d = res.to_dict()
    for name in ("recommended", "measured"):
        e = d[name]
        short[name] = None if e is None else {kk: e[kk] for kk in keep} | {
            "first_frequency_Hz": e["modes"][0]["frequency_Hz"]}
    return {
        "criterion": d["criterion"], "criterion_unit": d["criterion_unit"],
        "counts": d["counts"], "calibration": d["calibration"],
        "warnings": d["warnings"],
        "recommended": short["recommended"], "measured": short["measured"],
        "synthetic_inputs": d["synthetic_inputs"],
        "end_effector": "ASSUMED 60 kg spindle + bar, centre of mass 0.15 m along flange z",
        "map": {"rotation_deg": cand.rotation_deg.tolist(), "branch": cand.branch.tolist(),
                "criterion": A.criterion.tolist()},
        "workspace": ws,
        "wall_time_s": time.perf_counter() - t0,
    }


def add_posture_section(rep: Any, plan: dict[str, Any]) -> None:
    """The report section "Posture map" (figure, table, notes) from :func:`paper_posture_plan`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from robobore.plan.ik import branch_label

    rep.add_section("Posture map for the paper's bore")
    if "error" in plan:
        rep.add_note(f"No posture map: {plan['error']}")
        return
    rep.add_text(
        "Every posture that holds the paper's bore (tool-axis rotation in 1 deg steps x every "
        "inverse-kinematics branch, inside the joint limits, away from singularities) rated "
        "with the pose-dependent elastic multibody model (robobore plan; docs/plan.md), "
        "calibrated to the identified modes at the paper's posture. Criterion: the "
        "critical depth of cut at the cutting speed (semi-discretisation; the lowest over the "
        "lobe speed range beside it). End effector: "
        f"{plan['end_effector']}." + (" Identification inputs are SYNTHETIC."
                                      if plan["synthetic_inputs"] else ""))
    m = plan["map"]
    rot, br, cr = (np.asarray(m[k], float) for k in ("rotation_deg", "branch", "criterion"))
    fig, axs = plt.subplots(1, 2 if plan.get("workspace") else 1,
                            figsize=(11 if plan.get("workspace") else 6.8, 4.0), squeeze=False)
    ax = axs[0, 0]
    for b in np.unique(br):
        s = br == b
        o = np.argsort(rot[s])
        ax.plot(rot[s][o], cr[s][o], ".", ms=3, label=f"branch {int(b)} "
                f"({branch_label(int(b))})")
    rec, mea = plan["recommended"], plan["measured"]
    ax.plot(rec["tool_axis_rotation_deg"], rec["criterion_value"], "*", ms=14, color="k",
            mfc="gold", label="recommended")
    if mea is not None:
        ax.plot(mea["tool_axis_rotation_deg"], mea["criterion_value"], "D", ms=8, mfc="none",
                color="k", mew=1.5, label="paper's posture")
    ax.set_xlabel("tool-axis rotation [deg]")
    ax.set_ylabel("critical depth at the cutting speed [mm]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    ws = plan.get("workspace")
    if ws:
        ax2 = axs[0, 1]
        B = np.array([[np.nan if v is None else v for v in row] for row in ws["best_criterion"]],
                     float)
        im = ax2.pcolormesh(ws["dx_m"], ws["dy_m"], np.ma.masked_invalid(B), shading="nearest")
        fig.colorbar(im, ax=ax2, label="best critical depth [mm]")
        ax2.plot(0, 0, "D", mfc="none", color="k", label="paper's part placement")
        ax2.set_xlabel("part shift dx [m]")
        ax2.set_ylabel("part shift dy [m]")
        ax2.legend(fontsize=7)
    fig.tight_layout()
    rep.add_figure(fig, "Posture map of the paper's bore: criterion vs tool-axis rotation per "
                   "IK branch with the recommended (star) and the paper's (diamond) posture"
                   + ("; right: best value over rotations and branches when the part is "
                      "shifted in the base frame (blank: unreachable)" if ws else "") + ".")
    plt.close(fig)
    rows = []
    for name, e in (("recommended", rec), ("paper's posture", mea)):
        if e is None:
            continue
        k = e["directional_stiffness_N_per_m"]
        rows.append({"posture": name, "joints [deg]": ", ".join(f"{v:.1f}"
                                                               for v in e["joints_deg"]),
                     "rotation [deg]": e["tool_axis_rotation_deg"], "branch": e["branch"],
                     "k x/y/z [N/um]": "/".join(f"{k[a] * 1e-6:.3g}" for a in "xyz"),
                     "f1 [Hz]": e["first_frequency_Hz"],
                     "critical depth at the cutting speed [mm]": e["critical_depth_mm"],
                     "lowest over the speed range [mm]": e["critical_depth_range_min_mm"],
                     "feed amplitude [um]": e["feed_amplitude_um"]})
    rep.add_table(rows, caption="Recommended posture and the paper's posture")
    c = plan["calibration"]
    rep.add_note(
        f"{plan['counts']['candidates']} candidate postures; model calibrated to "
        f"{c['matched_modes']} identified modes, rms frequency residual "
        f"{c['rms_frequency_residual_percent']:.1f} % (link scale factors "
        + ", ".join(f"{v:.2f}" for v in c["link_scale"]) + "). With the tool point on the "
        "flange axis the tool-axis rotation only turns axis 6 (spherical wrist): stiffness and "
        "modes do not change with it, so the choice is between branches and part placements.")
    if mea is not None and rec is not None and not math.isclose(
            rec["criterion_value"], mea["criterion_value"], rel_tol=1e-6):
        rep.add_note(f"The recommended posture raises the criterion from "
                     f"{mea['criterion_value']:.4g} to {rec['criterion_value']:.4g} "
                     f"{plan['criterion_unit']}.")


__all__ = ["paper_posture_plan", "add_posture_section", "PAPER_END_EFFECTOR"]
