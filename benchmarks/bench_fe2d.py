"""Throughput of the 2D explicit FE cutting engine (element updates per second).

Runs the default, validated model -- the contract config examples/fe_orthogonal.toml: tool
frame (ALE), h = 60 um, vc = 30 m/min, 10 um elements, 2.5 um round the edge, conduction, the
calibrated friction law -- over a shortened cut (default 0.05 mm of tool travel instead of the
contract's 0.3 mm, so the whole benchmark stays within about two minutes on one thread), after
a warm-up that compiles or loads the numba cache. In the same process it runs a reference: by
default the same config with ``mesh.frame = "workpiece"`` (the Lagrangian model, same element
size, same cut length, same physics keys), and prints the default model's throughput and its
ratio to the reference's, the wall times, steps, threads and the machine load (the machine may
be shared: the ratio of two runs in one process is steadier than either figure).

    python benchmarks/bench_fe2d.py [--length-mm 0.05] [--element-um 10] [--threads N]
        [--config FILE] [--reference workpiece|none]

``--config`` measures another config; ``--length-mm`` / ``--element-um`` override its
values. Element updates per second = elements x steps / wall time of the stepping (the
``element_updates_per_s`` of the run summary; the tool frame's ALE remap passes are inside
the wall time, so the ratio shows what the ALE costs per element update).
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numba

from robobore.cutting.fe.config.orthogonal import load_fe_config
from robobore.cutting.fe.models.orthogonal import simulate_orthogonal

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "fe_orthogonal.toml"


def _run(cfg, label: str) -> dict:
    warm = cfg.model_copy(deep=True)
    warm.cut.length_mm = max(0.02, 2e-3 * cfg.mesh.element_size_um)
    t0 = time.perf_counter()
    simulate_orthogonal(warm)
    t_warm = time.perf_counter() - t0
    load0 = os.getloadavg()[0]
    s = simulate_orthogonal(cfg).to_dict()
    load1 = os.getloadavg()[0]
    print(f"{label}: frame {cfg.mesh.frame}, {cfg.cut.length_mm:g} mm, "
          f"{cfg.mesh.element_size_um:g} um elements, conduction "
          f"{cfg.solver.heat_conduction}, friction {cfg.friction_law()}")
    print(f"  warm-up {t_warm:.1f} s; elements {s['n_elements']}, steps {s['steps']}, wall "
          f"{s['wall_time_s']:.1f} s, load {load0:.2f} -> {load1:.2f}")
    print(f"  element updates per second: {s['element_updates_per_s'] / 1e6:.3f} million")
    print(f"  Fc {s['cutting_force_N_per_mm']:.1f} N/mm, Ff {s['feed_force_N_per_mm']:.1f} "
          f"N/mm, energy error {s['energy_error']:.3f} (short cut: not steady, not a result)")
    return s


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--length-mm", type=float, default=0.05,
                    help="cut length / tool travel [mm] (the contract's: 0.3)")
    ap.add_argument("--element-um", type=float, default=None, help="default: the config's "
                    "(10 for the contract)")
    ap.add_argument("--threads", type=int, default=None)
    ap.add_argument("--config", type=Path, default=EXAMPLE)
    ap.add_argument("--reference", choices=("workpiece", "none"), default="workpiece")
    args = ap.parse_args()
    if args.threads:
        numba.set_num_threads(args.threads)
    cfg = load_fe_config(args.config)
    cfg.cut.length_mm = args.length_mm
    if args.element_um is not None:
        cfg.mesh.element_size_um = args.element_um
    print(f"# 2D FE throughput, {args.config.name}, threads {numba.get_num_threads()} "
          f"({numba.threading_layer() if numba.get_num_threads() > 1 else 'serial'}), "
          f"{os.cpu_count()} CPUs")
    s = _run(cfg, "default model" if args.config == EXAMPLE else "config")
    if args.reference == "workpiece":
        # the keys the config gives (a tool-frame key has no place in the workpiece frame)
        d = cfg.model_dump(mode="json", exclude_unset=True)
        d["mesh"] = {k: v for k, v in d["mesh"].items() if k not in ("edge_element_um",)}
        d["mesh"]["frame"] = "workpiece"
        if cfg.contact._law is not None:  # the same friction law, by its name
            d["contact"] = {k: v for k, v in d["contact"].items()
                            if not k.startswith("friction_table_")}
            d["contact"]["friction"] = cfg.contact._law
        from robobore.cutting.fe.config.orthogonal import parse_config

        ref = parse_config(d, "workpiece-frame reference")
        r = _run(ref, "reference")
        print(f"ratio default / reference (element updates per second): "
              f"{s['element_updates_per_s'] / r['element_updates_per_s']:.2f}; wall time "
              f"ratio {s['wall_time_s'] / r['wall_time_s']:.2f}")


if __name__ == "__main__":
    main()
