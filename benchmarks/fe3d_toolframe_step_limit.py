"""Which elements set the time step of the 3D tool-frame model as the chip forms.

Usage::

    python benchmarks/fe3d_toolframe_step_limit.py [--config examples/fe_boring_paper.toml]
        [--element-um 16.6] [--mass-scaling 400] [--travel-um 60] [--checkpoints 6]
        [--top 5] [--json OUT]

Runs the config with ``[mesh] frame = "tool"`` (no tool support) for ``--travel-um`` of
insert travel and, at ``--checkpoints`` evenly spaced points, prints the time step, the
median element step (with the inertia factors, ``FEState3.msf``) and the ``--top`` elements
with the smallest step: their slice (``ToolFrameMesh3D.elem_slice``), whether they are chip
elements, their step, inertia factor, centroid relative to the insert tip [um] and plastic
strain. A falling step with the same elements at the top names the part of the mesh that
limits the run (for example the chip's thin elements at the first and last engaged slices).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--config", default=str(ROOT / "examples" / "fe_boring_paper.toml"))
    ap.add_argument("--element-um", type=float, default=16.6)
    ap.add_argument("--mass-scaling", type=float, default=400.0)
    ap.add_argument("--travel-um", type=float, default=60.0)
    ap.add_argument("--checkpoints", type=int, default=6)
    ap.add_argument("--top", type=int, default=5)
    ap.add_argument("--json", default=None)
    a = ap.parse_args()

    from robobore.cutting.fe.config.boring3d import parse_boring_config
    from robobore.cutting.fe.engine import kernels3d as K3
    from robobore.cutting.fe.engine import layout
    from robobore.cutting.fe.engine.state3d import advance3
    from robobore.cutting.fe.hex import scalar3d
    from robobore.cutting.fe.models.boring3d import setup_boring
    from robobore.io.config import load_toml

    d = load_toml(a.config)
    d["mesh"]["frame"] = "tool"
    d["mesh"]["element_size_um"] = a.element_um
    d.setdefault("solver", {})["mass_scaling"] = a.mass_scaling
    # the run stops at the checkpoints; the config's cut must reach the last of them
    d["cut"]["cut_length_mm"] = max(float(d["cut"]["cut_length_mm"]), 1e-3 * a.travel_um)
    d.pop("tool_support", None)
    cfg = parse_boring_config(d, source=a.config)
    setup = setup_boring(cfg, a.config)
    st, mesh = setup.state, setup.mesh
    ne = st.conn.shape[0]
    print(f"{ne} hexahedra, {mesh.z_slices.shape[0]} slices, initial step {st.clock[1]:.3e} s",
          flush=True)
    t_start = st.time
    t0 = time.perf_counter()
    rows = []
    for k in range(1, a.checkpoints + 1):
        travel = k * a.travel_um / a.checkpoints
        advance3(st, t_start + travel * 1e-6 / setup.vc, chunk_steps=cfg.solver.chunk_steps,
                 step=K3.run_chunk3_for(setup.spec))
        msf = st.msf if st.msf.shape[0] else np.ones(ne)
        de = st.dte * np.sqrt(msf)
        cx, cy, cz, *_ = scalar3d.tool_kinematics(st.tool, st.prm)
        xyz = np.stack([st.x, st.y, st.z], 1)
        row = {"travel_um": travel, "steps": int(st.ist[layout.I_STEP]), "dt_s": float(st.clock[1]),
               "median_element_step_s": float(np.median(de)), "wall_s": time.perf_counter() - t0,
               "limiting": []}
        print(f"{row['wall_s']:7.1f} s  travel {travel:6.2f} um  step {row['steps']}  "
              f"dt {row['dt_s']:.3e} s  median element step {row['median_element_step_s']:.3e} s",
              flush=True)
        for e in np.argsort(de)[:a.top]:
            c = 1e6 * (xyz[st.conn[e]].mean(0) - (cx, cy, cz))
            el = {"element": int(e), "slice": int(mesh.elem_slice[e]), "chip": bool(mesh.chip[e]),
                  "step_s": float(de[e]), "inertia_factor": float(msf[e]),
                  "centroid_from_tip_um": [float(v) for v in c], "eps_p": float(st.eps_p[e])}
            row["limiting"].append(el)
            print(f"    element {e:6d}  slice {el['slice']:3d}  chip {el['chip']!s:5s}  step "
                  f"{el['step_s']:.3e} s  factor {el['inertia_factor']:6.2f}  centroid - tip "
                  f"({c[0]:6.1f}, {c[1]:6.1f}, {c[2]:7.1f}) um  eps_p {el['eps_p']:.2f}",
                  flush=True)
        rows.append(row)
    if a.json:
        Path(a.json).write_text(json.dumps({"element_size_um": a.element_um,
                                            "mass_scaling": a.mass_scaling,
                                            "checkpoints": rows}, indent=1))


if __name__ == "__main__":
    main()
