"""A short run of the 3D boring model on the tool-frame mesh (``mesh.frame = "tool"``).

Usage::

    python benchmarks/fe3d_toolframe_short.py [--config examples/fe_boring_paper.toml]
        [--steps 3000] [--mass-scaling 400] [--element-um 12.5] [--t-min-um 5]
        [--setup-only] [--no-inertia-factors] [--normal-damping Z] [--out results.json]

``--setup-only``: no run; the mesh facts, the initial time step and the steps the config's
whole cut would take at it. Otherwise runs the config with ``[mesh] frame = "tool"`` for
about ``--steps`` explicit steps (the cut length set to the insert travel those steps take
at the initial time step, which may be below the config's one-element minimum: set after
the config is validated) and prints the step size, the steps per second (ALE passes
included), the mesh facts and the forces over the last half of the travel
(``simulate_boring``'s window), with the history of the rotating-frame forces against the
travel (the run's samples). A few thousand steps are a micrometre or so of travel at the
paper's condition: the forces are those of the start of the cut from the pre-shaped chip,
not steady values. Results go to ``--out`` (JSON) when given.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--config", default=str(ROOT / "examples" / "fe_boring_paper.toml"))
    ap.add_argument("--steps", type=int, default=3000)
    ap.add_argument("--mass-scaling", type=float, default=400.0)
    ap.add_argument("--element-um", type=float, default=None)
    ap.add_argument("--t-min-um", type=float, default=None)
    ap.add_argument("--setup-only", action="store_true")
    ap.add_argument("--no-inertia-factors", action="store_true",
                    help="solver.thin_element_mass_scaling = false")
    ap.add_argument("--normal-damping", type=float, default=None,
                    help="contact.normal_damping (default: the config's, 1 in the tool frame)")
    ap.add_argument("--out", default=None)
    a = ap.parse_args()

    from robobore.cutting.fe.config.boring3d import parse_boring_config
    from robobore.cutting.fe.models.boring3d import setup_boring, simulate_boring
    from robobore.io.config import load_toml

    d = load_toml(a.config)
    d["mesh"]["frame"] = "tool"
    if a.element_um is not None:
        d["mesh"]["element_size_um"] = a.element_um
    if a.t_min_um is not None:
        d["mesh"]["t_min_um"] = a.t_min_um
    d.setdefault("solver", {})["mass_scaling"] = a.mass_scaling
    if a.no_inertia_factors:
        d["solver"]["thin_element_mass_scaling"] = False
    if a.normal_damping is not None:
        d.setdefault("contact", {})["normal_damping"] = a.normal_damping
    cfg = parse_boring_config(d, source=a.config)
    setup = setup_boring(cfg, a.config)
    dt = float(setup.state.clock[1])
    vc = math.pi * cfg.cut.bore_diameter_mm * 1e-3 * cfg.cut.speed_rpm / 60.0
    if a.setup_only:
        from robobore.cutting.fe.models.toolframe3d import toolframe_mesh_summary

        out = {"element_size_um": cfg.mesh.element_size_um, "mass_scaling": a.mass_scaling,
               "toolframe_mesh": toolframe_mesh_summary(setup.mesh).to_dict(), "time_step_s": dt,
               "cut_length_mm": cfg.cut.cut_length_mm,
               "steps_for_the_cut": cfg.cut.cut_length_mm * 1e-3 / (vc * dt)}
        print(json.dumps(out, indent=1))
        return
    cfg.cut.cut_length_mm = a.steps * dt * vc * 1e3
    res = simulate_boring(cfg, source=a.config)
    r = res.to_dict()
    keys = ("force_rotating_N", "force_rotating_std_N", "averaging_window_mm", "energy_error",
            "hourglass_fraction", "steps", "time_step_s", "wall_time_s",
            "element_updates_per_s", "n_elements", "n_nodes", "toolframe_mesh",
            "eroded_distortion", "peak_temperature_K", "cutting_speed_m_per_min")
    out = {k: r[k] for k in keys}
    out["steps_per_s"] = r["steps"] / r["wall_time_s"]
    out["mass_scaling"] = a.mass_scaling
    out["travel_um"] = cfg.cut.cut_length_mm * 1e3
    out["config"] = a.config
    h = res.history
    out["history"] = {k: [float(v) for v in h[k]] for k in (
        "cut_length_mm", "force_tangential_N", "force_radial_N", "force_feed_N")}
    text = json.dumps(out, indent=1)
    print(text)
    if a.out:
        Path(a.out).write_text(text + "\n")


if __name__ == "__main__":
    main()
