"""Posture-planning benchmark: a full map of 360 tool-axis rotations x every IK branch, with
modes and the critical depth over the speed range for every candidate.

Prints figures; no assertions. Run (set the thread count; the machine is shared, so note the
load printed with the figures)::

    NUMBA_NUM_THREADS=1 python benchmarks/bench_plan.py
    NUMBA_NUM_THREADS=2 python benchmarks/bench_plan.py

Inputs: examples/plan_paper_bore.toml (the paper's bore, tool point on the flange axis:
360 x 8 = 2880 IK solutions tried, those inside the joint limits rated) and the same bore
with a spindle 0.2 m off the flange axis (more distinct postures). The identification JSON
files of the example are used as they are (SYNTHETIC). A third line rates 2880 postures
(every IK solution of the full map, whether inside the limits or not) to time the worst case
of the rating itself.
"""

from __future__ import annotations

import os
import re
import tempfile
import time
from pathlib import Path

import numpy as np

from robobore.plan.chatter import critical_depth_range
from robobore.plan.posture import plan_posture
from robobore.robot.description import get_robot
from robobore.robot.kinematics import fk

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "plan_paper_bore.toml"
PAPER_Q_DEG = [-48.38, 54.82, 6.86, -54.16, 107.43, -21.95]


def _load() -> str:
    try:
        return " ".join(f"{v:.2f}" for v in os.getloadavg())
    except OSError:
        return "n/a"


def _config(tcp: list[float] | None) -> Path:
    text = EXAMPLE.read_text()
    text = re.sub(r"\[workspace\].*", "", text, flags=re.S)
    if tcp is not None:
        T = fk(get_robot("irb6600-175-2.55"), np.radians(PAPER_Q_DEG), tcp)
        text = re.sub(r"(?m)^tcp_m =.*$", f"tcp_m = {tcp}", text)
        text = re.sub(r"(?m)^point_m =.*$", f"point_m = {T[:3, 3].tolist()}", text)
        text = re.sub(r"(?m)^axis =.*$", f"axis = {T[:3, 2].tolist()}", text)
    d = Path(tempfile.mkdtemp(prefix="bench_plan_"))
    p = d / "plan.toml"
    p.write_text(text.replace('"plan_paper_bore/', f'"{EXAMPLE.parent}/plan_paper_bore/')
                 .replace('"../src/', f'"{ROOT}/src/'))
    return p


def _rate(model, Q, process) -> tuple[float, float]:
    """Wall times [s] of the modes and of the critical depth (150-1100 r/min) at postures Q."""
    t0 = time.perf_counter()
    pm = model.modes(Q)
    t1 = time.perf_counter()
    critical_depth_range(pm.frequency_Hz, pm.damping_ratio, pm.u,
                         process.mean_directional_matrix(), 150.0, 1100.0, 1)
    return t1 - t0, time.perf_counter() - t1


def main() -> None:
    threads = os.environ.get("NUMBA_NUM_THREADS", "default")
    print(f"NUMBA_NUM_THREADS={threads}, cores {os.cpu_count()}, load average {_load()}")
    plan_posture(_config(None))  # warm-up: numba kernels from the cache, imports
    for label, tcp in (("paper bore, tcp on the flange axis", None),
                       ("paper bore, spindle 0.2 m off the flange axis", [0.2, 0.0, 0.3])):
        cfg = _config(tcp)
        t0 = time.perf_counter()
        res = plan_posture(cfg)
        dt = time.perf_counter() - t0
        r = res.to_dict()
        c = r["counts"]
        print(f"{label}: {c['rotations']} rotations x 8 branches = {c['ik_solutions_tried']} IK "
              f"solutions, {c['reaching']} reach, {c['candidates']} candidates rated "
              f"(modes + critical depth {r['speed_range_rpm'][0]:g}-"
              f"{r['speed_range_rpm'][1]:g} r/min): {dt:.2f} s "
              f"({c['candidates'] / dt:.0f} candidates/s, including calibration and config)")
    # worst case of the rating: 2880 postures
    A = res.arrays
    model, process = A.model, A.process
    rng = np.random.default_rng(0)
    Q = A.cand.q_rad[rng.integers(0, A.cand.q_rad.shape[0], 2880)]
    t_modes, t_depth = _rate(model, Q, process)
    print(f"2880 postures: modes {t_modes:.2f} s, critical depth {t_depth:.2f} s, "
          f"total {t_modes + t_depth:.2f} s ({2880 / (t_modes + t_depth):.0f} postures/s)")
    # the same with link bending (lower arm and forearm as beams: 12 coordinates)
    from dataclasses import replace

    from robobore.plan.bending import LinkBending

    mb = replace(model, link_bending=(LinkBending(2, (1 / 5.7e7, 1 / 7.2e7)),
                                      LinkBending(4, (1 / 1.6e7, 1 / 1.6e7))))
    t_modes, t_depth = _rate(mb, Q, process)
    print(f"2880 postures with link bending ({mb.n_dof} coordinates): modes {t_modes:.2f} s, "
          f"critical depth {t_depth:.2f} s, total {t_modes + t_depth:.2f} s "
          f"({2880 / (t_modes + t_depth):.0f} postures/s)")
    print(f"load average after: {_load()}")


if __name__ == "__main__":
    main()
