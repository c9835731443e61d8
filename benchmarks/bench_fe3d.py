"""3D FE engine: throughput and the boring validation at the paper's condition.

Usage::

    python benchmarks/bench_fe3d.py speed [--elements 30000] [--steps 200]
        [--frame workpiece|tool]
    python benchmarks/bench_fe3d.py paper [--sizes 16.7 12.5] [--cut-mm 0.15]
        [--mass-scaling 400] [--coefficients FILE] [--friction LAW|table|0.3]
        [--separation erosion_layer|node_split] [--frame workpiece|tool] [--no-support]
        [--out results.json]

``speed`` prints element-updates per second of the full time step (nodes, contact, elements,
tool, heat conduction every 10 steps; in the tool frame the ALE pass every 10 steps too) on a
mesh of the paper's condition of about ``--elements`` hexahedra (the default tool-frame mesh,
or the workpiece frame's wall block with ``--frame workpiece``), on one numba thread and on
all of them, each with the adiabatic model as the reference run in
the same process (the ratio is the cost of conduction), with the load average (the machine is
shared: figures are noisy). ``paper`` runs
``examples/fe_boring_paper.toml`` (ap = 0.05 mm, f = 0.15 mm/r, n = 300 r/min, TC4; insert
and bore diameter are documented assumptions) at each element size, compares the rotating-
frame forces with the mechanistic model (default TC4 coefficients, or ``--coefficients``,
e.g. the bundled FE-calibrated ``src/robobore/data/paper_example/tc4_fe_coefficients.json``),
reports the mesh-refinement change between successive meshes, then (unless
``--no-support``) runs the finest mesh with the tool on a quasi-static 3-axis support
(natural frequency 100 kHz, zeta 0.5) and compares the mean Z deflection with feed force /
kZ. The physics is the example's, i.e. the engine's defaults (docs/fe3d.md, "Physics and
validation"), unless ``--friction`` names another friction law, "table" or a constant;
``--frame workpiece`` runs the workpiece-frame model instead of the default tool-frame ALE
mesh (docs/fe3d.md, "Tool-frame 3D model").
Results go to ``--out`` (atomic JSON) when given.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numba
import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def _load() -> str:
    return f"load average {os.getloadavg()[0]:.2f} (1 min) on {os.cpu_count()} cpus"


def speed(n_elements: int, steps: int, frame: str | None = None) -> dict:
    from robobore.cutting.fe.config.boring3d import parse_boring_config
    from robobore.cutting.fe.engine import kernels3d as K3
    from robobore.cutting.fe.models.boring3d import setup_boring
    from robobore.io.config import load_toml

    d = load_toml(ROOT / "examples" / "fe_boring_paper.toml")
    if frame is not None:
        d["mesh"]["frame"] = frame
    # the element size giving about n_elements: the workpiece block has 8,120 hexahedra at
    # 12.5 um (cubic in 1 / size), the tool-frame mesh 25,548 (slices and sections: a power
    # 2.17, from its 13,947 / 25,548 / 41,450 at 16.6 / 12.5 / 10 um)
    frame = parse_boring_config(d).mesh.frame  # the example's where not given
    if frame == "tool":
        le = 12.5 * (25548 / n_elements) ** (1 / 2.17)
    else:
        d["cut"]["cut_length_mm"] = 0.3  # the block of 8,120 hexahedra at 12.5 um
        le = 12.5 * (8120 / n_elements) ** (1 / 3)
    d["mesh"]["element_size_um"] = min(le, 16.6)
    out: dict = {"frame": frame}
    n_max = numba.get_num_threads()
    for par in (False, True):
        numba.set_num_threads(n_max if par else 1)
        for cond in (True, False):
            d["solver"]["heat_conduction"] = cond
            s = setup_boring(parse_boring_config(d))
            st = s.state
            run = K3.run_chunk3_for(s.spec)  # the loop of the model choice (heat pass or not)
            run(5, *st.kernel_args())  # compile / warm up
            t0 = time.perf_counter()
            c0 = time.process_time()
            taken = run(steps, *st.kernel_args())
            wall = time.perf_counter() - t0
            cpu = time.process_time() - c0
            rate = st.n_elements * taken / wall
            per_cpu = st.n_elements * taken / cpu
            key = (f"{n_max}_threads" if par else "1_thread") + ("" if cond else "_adiabatic")
            out[key] = {"elements": st.n_elements, "steps": int(taken), "wall_s": wall,
                        "cpu_s": cpu, "element_updates_per_s": rate,
                        "element_updates_per_cpu_s": per_cpu, "load": _load()}
            # per CPU-second: what one core delivers when it actually runs (the shared
            # machine gives this process only part of a core); x 2 estimates an unloaded
            # 2-core machine
            print(f"{key:19s}: {st.n_elements} elements x {taken} steps in {wall:.2f} s wall, "
                  f"{cpu:.2f} s CPU -> {rate / 1e6:.2f} M element-updates/s wall, "
                  f"{per_cpu / 1e6:.2f} M per CPU-second ({_load()})", flush=True)
        base = f"{n_max}_threads" if par else "1_thread"
        ratio = (out[base]["element_updates_per_cpu_s"]
                 / out[base + "_adiabatic"]["element_updates_per_cpu_s"])
        out[base]["ratio_to_adiabatic"] = ratio
        print(f"{base}: heat conduction (default) / adiabatic, per CPU-second: {ratio:.3f}",
              flush=True)
    return out


def paper(sizes: list[float], cut_mm: float, ms: float, coefficients: str | None,
          friction: str | None = None, separation: str | None = None,
          support: bool = True, frame: str | None = None) -> dict:
    from robobore.cutting.fe.config.boring3d import parse_boring_config
    from robobore.cutting.fe.models.boring3d import compare_with_mechanistic, simulate_boring
    from robobore.io.config import load_toml

    base = load_toml(ROOT / "examples" / "fe_boring_paper.toml")
    if friction is not None:
        try:
            value: str | float = float(friction)
        except ValueError:
            value = friction  # a friction law's name or "table"
        base.setdefault("contact", {})["friction"] = value
    if separation is not None:
        base["mesh"]["separation"] = separation
    if frame is not None:
        base["mesh"]["frame"] = frame
    res: dict = {"runs": [], "cut_length_mm": cut_mm, "mass_scaling": ms,
                 "frame": parse_boring_config(base).mesh.frame}
    for le in sizes:
        d = json.loads(json.dumps(base))
        d["mesh"]["element_size_um"] = le
        d["cut"]["cut_length_mm"] = cut_mm
        d["solver"]["mass_scaling"] = ms
        r = simulate_boring(parse_boring_config(d))
        cmp_ = compare_with_mechanistic(r, coefficients).to_dict()
        s = r.to_dict()
        row = {"element_size_um": le, "force_rotating_N": s["force_rotating_N"],
               "force_rotating_std_N": s["force_rotating_std_N"],
               "force_amplitude_N": s["force_amplitude_N"], "energy_error": s["energy_error"],
               "hourglass_fraction": s["hourglass_fraction"],
               "kinetic_fraction": s["energy_J"]["kinetic"] / s["energy_J"]["external"],
               "n_elements": s["n_elements"], "steps": s["steps"],
               "wall_time_s": s["wall_time_s"],
               "element_updates_per_s": s["element_updates_per_s"],
               "eroded_damage": s["eroded_damage"], "eroded_distortion": s["eroded_distortion"],
               "comparison": cmp_, "load": _load()}
        res["runs"].append(row)
        print(json.dumps(row, indent=1), flush=True)
    for prev, row in zip(res["runs"], res["runs"][1:], strict=False):
        a, b = prev["force_rotating_N"], row["force_rotating_N"]
        row["change_from_previous_mesh"] = {k: (b[k] - a[k]) / abs(b[k]) for k in a}
    if len(res["runs"]) >= 2:
        res["refinement_change"] = res["runs"][-1]["change_from_previous_mesh"]
        print("refinement change:", res["refinement_change"], flush=True)
    _print_table(res["runs"])
    if not support:
        return res
    # tool on the quasi-static equivalent support (finest mesh)
    d = json.loads(json.dumps(base))
    d["mesh"]["element_size_um"] = sizes[-1]
    d["cut"]["cut_length_mm"] = cut_mm
    d["solver"]["mass_scaling"] = ms
    d["tool_support"] = {"stiffness_N_per_m": 4.0e8, "damping_N_s_per_m": 632.0,
                         "mass_kg": 1.0e-3}
    r = simulate_boring(parse_boring_config(d))
    s = r.to_dict()
    res["support"] = {k: s[k] for k in ("tool_dz_mean_um", "tool_dz_static_um",
                                        "feed_amplitude_um", "force_rotating_N",
                                        "energy_error")}
    res["support"]["relative_difference"] = (s["tool_dz_mean_um"] / s["tool_dz_static_um"]
                                             - 1.0)
    print("support:", json.dumps(res["support"]), flush=True)
    return res


def _print_table(runs: list[dict]) -> None:
    """The validation table: per mesh, FE forces, difference from the model, change from the
    previous mesh, energy error, wall time."""
    comps = ("tangential", "radial", "feed")
    print("element_um  hexahedra  steps  FE t/r/f [N]  vs model t/r/f [%]  "
          "change t/r/f [%]  energy_err  wall_s")
    for r in runs:
        fe = "/".join(f"{r['force_rotating_N'][c]:.1f}" for c in comps)
        vs = "/".join(f"{100 * r['comparison'][c]['relative_difference']:+.1f}" for c in comps)
        ch = r.get("change_from_previous_mesh")
        chs = "/".join(f"{100 * ch[c]:+.1f}" for c in comps) if ch else "-"
        print(f"{r['element_size_um']:10.3g}  {r['n_elements']:9d}  {r['steps']:5d}  {fe}  "
              f"{vs}  {chs}  {r['energy_error']:.3f}  {r['wall_time_s']:.0f}", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mode", choices=["speed", "paper"])
    ap.add_argument("--elements", type=int, default=30000)
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--sizes", type=float, nargs="+", default=[16.6, 12.5])
    ap.add_argument("--cut-mm", type=float, default=0.15)
    ap.add_argument("--mass-scaling", type=float, default=400.0)
    ap.add_argument("--coefficients", default=None)
    ap.add_argument("--friction", default=None,
                    help='a friction law, "table" or a Coulomb coefficient (default: the '
                         "example's, i.e. the engine's default law)")
    ap.add_argument("--separation", choices=["erosion_layer", "node_split"], default=None)
    ap.add_argument("--frame", choices=["workpiece", "tool"], default=None,
                    help="the mesh frame (default: the example's, the tool frame)")
    ap.add_argument("--no-support", action="store_true",
                    help="skip the run of the finest mesh on the quasi-static support")
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    if a.mode == "speed":
        out = speed(a.elements, a.steps, a.frame)
    else:
        out = paper(a.sizes, a.cut_mm, a.mass_scaling, a.coefficients, a.friction,
                    a.separation, support=not a.no_support, frame=a.frame)
    if a.out:
        from robobore.io.results import write_json

        write_json(a.out, out)
    _ = np


if __name__ == "__main__":
    main()
