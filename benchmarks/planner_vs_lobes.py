"""The posture planner against the lobes and the time domain at the same posture and model.

Runs the plan of a config (default ``examples/plan_paper_bore.toml``, SYNTHETIC identification
inputs), takes the tool-point structure it rated at the measured and the recommended posture
(``lobes[...]["tool_point_modes"]`` of the plan's JSON), writes it as the ``[structure]`` of a
dynamics config with the plan's insert, bore, cutting condition and coefficients, and runs on
it what a user would run:

* ``robobore.dynamics.api.critical_depth_at`` (the semi-discretisation answer of ``robobore
  lobes`` at one speed) at the ``[cutting]`` speed, against the planner's ``critical_depth_mm``;
* ``robobore.dynamics.api.lobes`` over the plan's 30 speeds of ``[lobes]``, its lowest limit
  against the planner's ``critical_depth_range_min_mm``;
* ``robobore.dynamics.api.run_boring`` (``simulate boring``) at the ``[cutting]`` condition, its
  feed amplitude against the planner's ``feed_amplitude_um``.

    python benchmarks/planner_vs_lobes.py [config.toml]
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from robobore.dynamics.api import critical_depth_at, lobes, run_boring
from robobore.plan.posture import SD_SPEEDS, plan_posture


def dynamics_config(result, modes: list[dict]) -> dict:
    """A dynamics config dict of the plan's process on the structure ``modes``."""
    inp = result.arrays.inputs
    c = inp.cfg
    cfg = {"structure": {"modes": modes}, "insert": c.insert.model_dump(),
           "bore": {"diameter_mm": c.bore.diameter_mm},
           "cutting": {"speed_rpm": c.cutting.speed_rpm,
                       "feed_mm_per_rev": c.cutting.feed_mm_per_rev,
                       "depth_mm": c.cutting.depth_mm},
           "speed_rpm": {"min": c.lobes.speed_min_rpm, "max": c.lobes.speed_max_rpm,
                         "count": SD_SPEEDS}}
    if c.coefficients is not None:
        co = c.coefficients.model_dump(exclude_none=True)
        if "file" in co:
            co["file"] = str((Path(inp.path).parent / co["file"]).resolve())
        cfg["coefficients"] = co
    return cfg


def main() -> None:
    path = Path(sys.argv[1]) if len(sys.argv) > 1 else (
        Path(__file__).resolve().parents[1] / "examples" / "plan_paper_bore.toml")
    t0 = time.perf_counter()
    plan = plan_posture(path)
    res = plan.to_dict()
    t_plan = time.perf_counter() - t0
    print(f"plan of {path.name}: {res['counts']['candidates']} candidates in {t_plan:.1f} s; "
          f"cutting {res['cutting']}")
    worst_b = worst_a = 0.0
    for name in ("measured", "recommended"):
        e, L = res[name], res["lobes"].get(name)
        if e is None or L is None:
            continue
        cfg = dynamics_config(plan, L["tool_point_modes"])
        n = float(res["cutting"]["speed_rpm"])
        at = critical_depth_at(cfg, n)
        lb = lobes(cfg)
        sim = run_boring(cfg)
        b_plan, b_lob = e["critical_depth_mm"], at.critical_depth_mm
        m_plan, m_lob = e["critical_depth_range_min_mm"], float(np.min(lb.critical_depth_mm))
        a_plan, a_sim = e["feed_amplitude_um"], sim.feed_amplitude_um
        db = abs(b_plan / b_lob - 1.0) if b_lob else abs(b_plan - b_lob)
        da = abs(a_plan / a_sim - 1.0)
        worst_b, worst_a = max(worst_b, db), max(worst_a, da)
        print(f"{name}: critical depth at {n:g} r/min: planner {b_plan:.6g} mm, lobes "
              f"{b_lob:.6g} mm ({100 * db:.3g} %); lowest over the range: planner "
              f"{m_plan:.6g} mm, lobes {m_lob:.6g} mm; feed amplitude: planner {a_plan:.5g} "
              f"um, simulate boring {a_sim:.5g} um ({100 * da:.3g} %; chatter "
              f"{sim.chatter}, {sim.revolutions} revolutions, "
              f"{sim.samples_per_rev} samples/rev)")
    print(f"largest deviation: critical depth {100 * worst_b:.3g} % (target 1 %), feed "
          f"amplitude {100 * worst_a:.3g} % (target 10 %); {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()
