"""GPU vs CPU for the explicit FE engines: agreement and throughput (needs an NVIDIA GPU
and numba-cuda for the GPU parts; the CPU parts run anywhere).

Usage::

    python benchmarks/bench_gpu.py env
    python benchmarks/bench_gpu.py check3d [--steps 60 2000]
    python benchmarks/bench_gpu.py speed3d [--sizes 10 5 3.3] [--gpu-steps 2000]
        [--cpu-steps 40] [--cpu-threads 2] [--no-gpu] [--profile]
    python benchmarks/bench_gpu.py paper3d [--sizes 10] [--devices cpu gpu] [--cut-mm 0.15]
        [--mass-scaling 400] [--coefficients FILE]
    python benchmarks/bench_gpu.py speed2d [--sizes 10 2.5] [--gpu-steps 4000] [--cpu-steps 200]
    python benchmarks/bench_gpu.py ortho2d [--devices cpu gpu] [--length-mm 1.0]
        [--element-um 10] [--config FILE]

Every mode prints its figures and, with ``--out FILE``, writes them as JSON (atomic).

``check3d``: the small cut of :func:`small3d` (insert on springs, contact, plasticity,
erosion; also the state of ``tests/cutting/fe3d/test_fe3d_gpu.py``) on the real GPU against
the CPU engine: relative state differences after each step count (the simulator test gets
1e-9; on hardware the GPU's own math library and fused multiply-adds differ in the last
bits, and an explicit cut amplifies them over many steps).

``speed3d`` / ``speed2d``: the boring example (3D) / the contract config (2D) meshed at each
element size; the same initial state is advanced ``--gpu-steps`` on the GPU and
``--cpu-steps`` on the CPU with ``--cpu-threads`` numba threads:
element-updates per second of each, their ratio, and the state difference after the CPU's
steps (the GPU runs the same steps first). ``--profile`` adds a per-kernel breakdown (a
synchronised rerun).

The GPU runs use the persistent kernel (one cooperative launch per chunk of steps, the
default); ``gpu_launch_per_kernel`` is the same state advanced with one launch per kernel and
step (the fallback path), whose host-side launch cost dominates small meshes.

``paper3d`` / ``ortho2d``: whole runs (the 3D paper condition of ``bench_fe3d.py paper``,
the 2D contract config or, with ``--config``, any 2D config, the tool-frame ALE model's
included; ``--length-mm`` /
``--element-um`` override the config's when given) on each device: forces, energy error,
wall time and the relative force differences between the devices.
"""

from __future__ import annotations

import argparse
import copy
import json
import os
import platform
import time
from pathlib import Path

import numba
import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def _rel(u, v) -> float:
    u = np.nan_to_num(np.asarray(u, float))
    v = np.nan_to_num(np.asarray(v, float))
    return float(np.max(np.abs(u - v)) / max(float(np.max(np.abs(u))), 1e-300))


def env() -> dict:
    out = {"python": platform.python_version(), "numba": numba.__version__,
           "numpy": np.__version__, "cpus": os.cpu_count(),
           "numba_threads": numba.get_num_threads()}
    try:
        import numba_cuda  # noqa: F401

        out["numba_cuda"] = getattr(numba_cuda, "__version__", "?")
    except Exception as e:  # pragma: no cover - depends on the machine
        out["numba_cuda"] = f"not importable: {e}"
    from robobore.cutting.fe.engine.gpu.shared import cuda_available

    out["cuda_available"] = cuda_available()
    if out["cuda_available"]:
        from numba import cuda

        try:
            dev = cuda.get_current_device()
            out["gpu"] = dev.name.decode() if isinstance(dev.name, bytes) else str(dev.name)
            out["compute_capability"] = list(dev.compute_capability)
            out["multiprocessors"] = int(dev.MULTIPROCESSOR_COUNT)
        except AttributeError:  # numba's CUDA simulator
            out["gpu"] = "numba CUDA simulator"
    print(json.dumps(out, indent=1), flush=True)
    return out


# ----------------------------------------------------------------------------------- 3D
def small3d(n_samples: int = 4000):
    """The small 3D cut of ``check3d`` and of tests/cutting/fe3d/test_fe3d_gpu.py (which loads
    it from this file): a 24-element TC4 block, the insert on springs entering it, erosion,
    histories every 2 ns."""
    import math

    from robobore.cutting.fe.engine.state3d import box_mesh, default_prm3, make_state3
    from robobore.cutting.fe.hex import layout3d
    from robobore.material import load_material

    le = 20e-6
    nodes, conn, idx = box_mesh(4, 2, 3, 4 * le, 2 * le, 3 * le, origin=(0.0, -2 * le, -1.5 * le))
    fixed = np.zeros(len(nodes), np.int64)
    fixed[idx[:, 0, :].ravel()] = 7
    fixed[idx[-1, :, :].ravel()] = 7
    p = default_prm3()
    p[layout3d.P_TOOL] = 1.0
    p[layout3d.P_RN], p[layout3d.P_KAPPA], p[layout3d.P_KEND] = 0.4e-3, math.pi / 2, math.radians(5)
    p[layout3d.P_RAKE], p[layout3d.P_CLR] = math.radians(7), math.radians(7)
    p[layout3d.P_RE] = 10e-6
    p[layout3d.P_MU], p[layout3d.P_TAU] = 0.3, 576e6
    p[layout3d.P_MS] = 100.0
    p[layout3d.P_VC], p[layout3d.P_VF], p[layout3d.P_RADIUS] = 5.0, 1e-3, 0.02
    p[layout3d.P_SUPPORT] = 1.0
    p[layout3d.P_KX] = p[layout3d.P_KY] = p[layout3d.P_KZ] = 1e7
    p[layout3d.P_CX] = p[layout3d.P_CY] = p[layout3d.P_CZ] = 50.0
    p[layout3d.P_MX] = p[layout3d.P_MY] = p[layout3d.P_MZ] = 1e-3
    p[layout3d.P_EROSION] = layout3d.ERODE_LAYER
    p[layout3d.P_SAMPLE_DT] = 2e-9
    # every element in the erosion layer: damage erodes anywhere in the box
    return make_state3(nodes, conn, fixed, load_material("TC4"), prm=p, n_samples=n_samples,
                       layer=np.ones(len(conn), np.bool_), tool_tip=(-12e-6, -1.2 * le, 0.0))


def _diff3(a, b) -> dict:
    from robobore.cutting.fe.hex import scalar3d

    out = {k: _rel(getattr(a, k), getattr(b, k))
           for k in ("x", "vx", "vy", "vz", "sd", "pres", "eps_p", "temp", "tool")}
    fx, fz = scalar3d.T_FX, scalar3d.T_FZ
    out["forces"] = _rel(a.tool[fx:fz + 1], b.tool[fx:fz + 1])
    out["same_alive"] = bool(np.array_equal(a.alive, b.alive))
    return out


def check3d(steps: list[int]) -> dict:
    from robobore.cutting.fe.engine.gpu.backend3d import advance3_gpu
    from robobore.cutting.fe.engine.state3d import advance3

    res = {}
    for n in steps:
        a = small3d()
        t_end = n * a.clock[1]
        na = advance3(a, t_end, chunk_steps=max(n, 10))
        for persistent in (True, False):
            b = small3d()
            nb = advance3_gpu(b, t_end, chunk_steps=max(n, 10), persistent=persistent)
            d = _diff3(a, b)
            d["steps"] = [na, nb]
            d["contact_force_N"] = float(np.abs(a.cf).sum())
            key = f"{n} steps, {'persistent' if persistent else 'launch per kernel'}"
            res[key] = d
            print(f"check3d {key}: " + json.dumps(d), flush=True)
    return res


def _boring_dict(le: float, ms: float, cut_mm: float):
    from robobore.io.config import load_toml

    d = load_toml(ROOT / "examples" / "fe_boring_paper.toml")
    d["mesh"]["frame"] = "workpiece"  # the GPU engine's frame (the tool frame is CPU only)
    d["mesh"]["element_size_um"] = le
    d["cut"]["cut_length_mm"] = cut_mm
    d["solver"]["mass_scaling"] = ms
    d.setdefault("contact", {})["friction"] = "table"
    return d


def _timed(fn, *args, **kwargs) -> tuple[float, int]:
    """(wall time [s], return value) of ``fn(*args, **kwargs)``."""
    t0 = time.perf_counter()
    n = fn(*args, **kwargs)
    return time.perf_counter() - t0, n


def _speed_row(st0, n_elements: int, advance, advance_gpu, diff, gpu_steps: int,
               cpu_steps: int, use_gpu: bool, profile: bool) -> dict:
    """Throughput of one engine from the initial state ``st0`` on the CPU (``advance``) and
    on the GPU (``advance_gpu``: persistent kernel, then one launch per kernel), and the
    state difference ``diff(cpu, gpu)`` after the same steps."""
    dt = float(st0.clock[1])

    def t_after(steps: int) -> float:
        return st0.time + (steps - 0.5) * dt

    def rate(wall: float, n: int) -> dict:
        return {"steps": n, "wall_s": wall, "element_updates_per_s": n_elements * n / wall}

    row = {"elements": n_elements, "nodes": int(st0.x.shape[0]), "time_step_s": dt}
    advance(copy.deepcopy(st0), t_after(3), chunk_steps=10)  # compile / load the cache
    c = copy.deepcopy(st0)
    row["cpu"] = rate(*_timed(advance, c, t_after(cpu_steps), chunk_steps=cpu_steps))
    if not use_gpu:
        return row
    advance_gpu(copy.deepcopy(st0), t_after(3), chunk_steps=10)  # compile, first launches
    g = copy.deepcopy(st0)
    advance_gpu(g, t_after(cpu_steps), chunk_steps=cpu_steps)
    row["same_steps_difference"] = diff(c, g)
    row["gpu"] = rate(*_timed(advance_gpu, copy.deepcopy(st0), t_after(gpu_steps),
                              chunk_steps=gpu_steps))
    row["gpu"]["includes"] = "host-device copies of the whole state, in and out"
    row["speedup"] = row["gpu"]["element_updates_per_s"] / row["cpu"]["element_updates_per_s"]
    m = min(gpu_steps, 1000)
    row["gpu_launch_per_kernel"] = rate(*_timed(advance_gpu, copy.deepcopy(st0), t_after(m),
                                                chunk_steps=m, persistent=False))
    if profile:
        prof: dict[str, float] = {}
        m = min(gpu_steps, 500)
        advance_gpu(copy.deepcopy(st0), t_after(m), chunk_steps=m, profile=prof)
        row["gpu_profile_us_per_step"] = {k: 1e6 * v / m for k, v in prof.items()}
    return row


def speed3d(sizes: list[float], gpu_steps: int, cpu_steps: int, cpu_threads: int,
            use_gpu: bool, profile: bool) -> dict:
    from robobore.cutting.fe.config.boring3d import parse_boring_config
    from robobore.cutting.fe.engine.state3d import advance3
    from robobore.cutting.fe.models.boring3d import setup_boring

    advance3_gpu = None
    if use_gpu:
        from robobore.cutting.fe.engine.gpu.backend3d import advance3_gpu
    numba.set_num_threads(min(cpu_threads, numba.config.NUMBA_NUM_THREADS))
    res = {"cpu_threads": cpu_threads, "runs": []}
    for le in sizes:
        st0 = setup_boring(parse_boring_config(_boring_dict(le, 400.0, 0.15))).state
        row = {"element_size_um": le, **_speed_row(st0, st0.n_elements, advance3,
                                                    advance3_gpu, _diff3, gpu_steps,
                                                    cpu_steps, use_gpu, profile)}
        res["runs"].append(row)
        print(json.dumps(row), flush=True)
    return res


def paper3d(sizes: list[float], devices: list[str], cut_mm: float, ms: float,
            coefficients: str | None) -> dict:
    from robobore.cutting.fe.config.boring3d import parse_boring_config
    from robobore.cutting.fe.models.boring3d import compare_with_mechanistic, simulate_boring

    res = {"runs": []}
    for le in sizes:
        by = {}
        for dev in devices:
            cfg = parse_boring_config(_boring_dict(le, ms, cut_mm))
            r = simulate_boring(cfg, device=dev)
            s = r.to_dict()
            by[dev] = {k: s[k] for k in ("force_rotating_N", "force_mean_N",
                                         "force_amplitude_N", "energy_error",
                                         "hourglass_fraction", "n_elements", "steps",
                                         "wall_time_s", "element_updates_per_s",
                                         "eroded_damage", "eroded_distortion")}
            by[dev]["comparison"] = compare_with_mechanistic(r, coefficients).to_dict()
            print(f"paper3d {le} um {dev}: " + json.dumps(by[dev]), flush=True)
        row = {"element_size_um": le, "by_device": by}
        if "cpu" in by and "gpu" in by:
            a, b = by["cpu"]["force_rotating_N"], by["gpu"]["force_rotating_N"]
            row["gpu_vs_cpu"] = {k: (b[k] - a[k]) / abs(a[k]) for k in a}
            print(f"paper3d {le} um gpu vs cpu: " + json.dumps(row["gpu_vs_cpu"]), flush=True)
        res["runs"].append(row)
    return res


# ----------------------------------------------------------------------------------- 2D
def _ortho_cfg(le: float | None, length_mm: float | None, config: str | None = None):
    from robobore.cutting.fe.config.orthogonal import load_fe_config

    cfg = load_fe_config(config or ROOT / "examples" / "fe_orthogonal.toml")
    if le is not None:
        cfg.mesh.element_size_um = le
    if length_mm is not None:
        cfg.cut.length_mm = length_mm
    return cfg


def _diff2(a, b) -> dict:
    from robobore.cutting.fe.engine import layout

    out = {k: _rel(getattr(a, k), getattr(b, k))
           for k in ("x", "y", "vx", "vy", "sdx", "pres", "eps_p", "temp", "tool")}
    out["forces"] = _rel(a.tool[layout.T_FX:layout.T_FY + 1], b.tool[layout.T_FX:layout.T_FY + 1])
    out["same_alive"] = bool(np.array_equal(a.alive, b.alive))
    return out


def speed2d(sizes: list[float], gpu_steps: int, cpu_steps: int, cpu_threads: int,
            use_gpu: bool, profile: bool) -> dict:
    from robobore.cutting.fe.engine.chunk_driver import advance
    from robobore.cutting.fe.models.orthogonal import setup_orthogonal

    advance_gpu = None
    if use_gpu:
        from robobore.cutting.fe.engine.gpu.backend2d import advance_gpu
    numba.set_num_threads(min(cpu_threads, numba.config.NUMBA_NUM_THREADS))
    res = {"cpu_threads": cpu_threads, "runs": []}
    for le in sizes:
        st0 = setup_orthogonal(_ortho_cfg(le, 1.0)).state
        row = {"element_size_um": le, **_speed_row(st0, int(st0.conn.shape[0]), advance,
                                                    advance_gpu, _diff2, gpu_steps,
                                                    cpu_steps, use_gpu, profile)}
        res["runs"].append(row)
        print(json.dumps(row), flush=True)
    return res


def ortho2d(devices: list[str], length_mm: float | None, le: float | None,
            config: str | None = None) -> dict:
    from robobore.cutting.fe.models.orthogonal import simulate_orthogonal

    cfg = _ortho_cfg(le, length_mm, config)
    by = {}
    for dev in devices:
        r = simulate_orthogonal(cfg.model_copy(deep=True), device=dev)
        s = r.to_dict()
        by[dev] = {k: s.get(k) for k in ("cutting_force_N_per_mm", "feed_force_N_per_mm",
                                         "chip_ratio", "peak_temperature_K", "energy_error",
                                         "n_elements", "steps", "wall_time_s",
                                         "element_updates_per_s")}
        print(f"ortho2d {dev}: " + json.dumps(by[dev]), flush=True)
    res = {"config": str(config or "examples/fe_orthogonal.toml"),
           "element_size_um": cfg.mesh.element_size_um, "length_mm": cfg.cut.length_mm,
           "by_device": by}
    if "cpu" in by and "gpu" in by:
        res["gpu_vs_cpu"] = {k: (by["gpu"][k] - by["cpu"][k]) / abs(by["cpu"][k])
                             for k in ("cutting_force_N_per_mm", "feed_force_N_per_mm",
                                       "chip_ratio")}
        print("ortho2d gpu vs cpu: " + json.dumps(res["gpu_vs_cpu"]), flush=True)
    return res


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mode", choices=["env", "check3d", "speed3d", "paper3d", "speed2d",
                                     "ortho2d"])
    ap.add_argument("--steps", type=int, nargs="+", default=[60, 2000])
    ap.add_argument("--sizes", type=float, nargs="+", default=None)
    ap.add_argument("--gpu-steps", type=int, default=2000)
    ap.add_argument("--cpu-steps", type=int, default=40)
    ap.add_argument("--cpu-threads", type=int, default=2)
    ap.add_argument("--no-gpu", action="store_true")
    ap.add_argument("--profile", action="store_true")
    ap.add_argument("--devices", nargs="+", default=["cpu", "gpu"])
    ap.add_argument("--cut-mm", type=float, default=0.15)
    ap.add_argument("--mass-scaling", type=float, default=400.0)
    ap.add_argument("--coefficients", default=None)
    ap.add_argument("--length-mm", type=float, default=None)
    ap.add_argument("--element-um", type=float, default=None)
    ap.add_argument("--config", default=None)
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    if a.mode == "env":
        out = env()
    elif a.mode == "check3d":
        out = check3d(a.steps)
    elif a.mode == "speed3d":
        out = speed3d(a.sizes or [10.0, 5.0, 3.3], a.gpu_steps, a.cpu_steps, a.cpu_threads,
                      not a.no_gpu, a.profile)
    elif a.mode == "paper3d":
        out = paper3d(a.sizes or [10.0], a.devices, a.cut_mm, a.mass_scaling, a.coefficients)
    elif a.mode == "speed2d":
        out = speed2d(a.sizes or [10.0, 2.5], a.gpu_steps, a.cpu_steps, a.cpu_threads,
                      not a.no_gpu, a.profile)
    else:
        out = ortho2d(a.devices, a.length_mm, a.element_um, a.config)
    out["load_average"] = os.getloadavg()[0]
    if a.out:
        from robobore.io.results import write_json

        write_json(a.out, out)


if __name__ == "__main__":
    main()
