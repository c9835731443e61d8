"""The SYNTHETIC measured CSV of the paper example (``data/paper_example/README.md``) and
its documented ground truth (:func:`truth_robot_model`)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from robobore.study.paper import study_conditions
from robobore.study.paper_config import PaperConfig, load_paper_config

#: Ground truth of the SYNTHETIC measured CSV (see data/paper_example/README.md): the
#: boring model with the TRUE robot (the campaign's assumed joint stiffness, the hammer
#: test's true modes) and the MEASURED TC4 coefficients (Ducobu et al. 2022 fit, not the FE
#: calibration), plus 8 % truncated Gaussian noise on every amplitude (seed 2026).
MEASURED_NOISE = 0.08
MEASURED_SEED = 2026


def truth_robot_model(cfg: PaperConfig) -> dict[str, Any]:
    """The 'real' robot of the SYNTHETIC measurements (documented ground truth)."""
    from robobore.modal.virtual import robot_boring_truth
    from robobore.robot.campaign import IRB6600_ASSUMED_JOINT_STIFFNESS_NM_PER_RAD
    from robobore.robot.description import get_robot
    from robobore.robot.stiffness import directional_stiffness_xyz

    robot = get_robot(cfg.robot.name)
    k = directional_stiffness_xyz(robot, np.radians(cfg.robot.posture_deg),
                                  np.asarray(IRB6600_ASSUMED_JOINT_STIFFNESS_NM_PER_RAD),
                                  frame="boring", tcp_m=cfg.robot.tcp_m)
    tr = robot_boring_truth()
    f = [float(v) for v in tr.frequencies_Hz]
    z = [float(v) for v in tr.damping_ratios]
    return {"system": "robot", "dynamics": {
        "equivalent": {"stiffness_N_per_m": dict(k),
                       "frequency_Hz": {"x": f[0], "y": f[1], "z": f[2]},
                       "damping_ratio": {"x": z[0], "y": z[1], "z": z[2]},
                       "pressure_foot": cfg.pressure_foot.model_dump(),
                       "note": "SYNTHETIC ground truth"},
        "insert": cfg.insert.model_dump(), "bore": cfg.bore.model_dump(),
        "coefficients": {"material": "TC4"},
        "simulation": {"revolutions": cfg.study.revolutions,
                       "ra_tolerance_um": cfg.study.ra_tolerance_um}}}


def make_synthetic_measured(config: str | Path | None, path: str | Path) -> Path:
    """Write the SYNTHETIC measured CSV of the robot conditions of ``config``.

    Conditions whose ground-truth simulation fails (a :class:`RoboboreError`, e.g. a
    non-finite integration) cannot be 'measured': they are left out and listed in a
    ``#`` comment line of the file.
    """
    from robobore.errors import RoboboreError
    from robobore.io.results import atomic_write_text
    from robobore.study.runners import boring_runner
    from robobore.study.summary import summarise
    from robobore.study.synthetic import synthetic_measured_csv

    cfg, _, _ = load_paper_config(config)
    model = truth_robot_model(cfg)
    recs, missing = [], []
    for c in study_conditions(cfg):
        try:
            ds = boring_runner(c, {"model": model,
                                   "runner_options": {"samples_per_rev_stored": 8}})
        except RoboboreError as exc:
            missing.append(f"n={c['speed_rpm']:g} f={c['feed_mm_per_rev']:g} "
                           f"ap={c['depth_of_cut_mm']:g} P={c['pressure_MPa']:g} ({exc})")
            continue
        recs.append((c, summarise(ds)))
    p = synthetic_measured_csv(recs, path, rel_noise=MEASURED_NOISE, seed=MEASURED_SEED)
    if missing:
        text = Path(p).read_text()
        head, _, rest = text.partition("\n")
        note = ("# not measured (the ground-truth simulation failed): " + "; ".join(missing))
        atomic_write_text(p, head + "\n" + note + "\n" + rest)
    return Path(p)


__all__ = ["make_synthetic_measured", "truth_robot_model", "MEASURED_NOISE", "MEASURED_SEED"]
