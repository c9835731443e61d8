"""GPU backend: imports and fails cleanly without a GPU; the CUDA kernels (built from the same
scalar functions as the CPU engine) agree with the CPU engine in numba's CUDA simulator.

Measured on an NVIDIA H100 on 2026-11-22 (benchmarks/bench_gpu.py; docs/fe3d.md, "GPU"); CI
has no GPU, so these simulator tests are what CI checks.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from robobore.cutting.fe.engine.gpu import backend3d as gpu
from robobore.cutting.fe.engine.gpu.shared import cuda_available, require_gpu
from robobore.errors import ConfigError

#: the GPU benchmark script; its ``small3d`` builds the simulator test's state
BENCH = Path(__file__).parents[3] / "benchmarks" / "bench_gpu.py"

SCRIPT = textwrap.dedent("""
    import importlib.util, json, sys
    import numpy as np
    from numba import cuda
    assert cuda.simulator_is_being_used() if hasattr(cuda, "simulator_is_being_used") else True
    from robobore.cutting.fe.engine import layout as L2
    from robobore.cutting.fe.hex import layout3d as L3
    from robobore.cutting.fe.hex import scalar3d as S3
    from robobore.cutting.fe.engine.gpu.backend3d import advance3_gpu
    from robobore.cutting.fe.engine.state3d import advance3

    # the state builder of benchmarks/bench_gpu.py (its check3d runs the same cut on a GPU)
    spec = importlib.util.spec_from_file_location("bench_gpu", sys.argv[2])
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)

    def build():
        # the default friction law (rech2013_calibrated: the table read at each contact
        # node's filtered sliding speed) at the block's cutting speed prm[P_VC] = 5 m/s, and
        # heat conduction with the thermal contact every 3 steps (20 passes)
        from robobore.cutting.fe.config.contact import ContactSection
        from robobore.cutting.fe.config.engine_settings import (
            apply_friction_settings,
            apply_thermal_settings,
        )
        from robobore.cutting.fe.config.orthogonal import SolverSection
        from robobore.material import load_material
        s = bench.small3d(n_samples=40)
        apply_friction_settings(s.prm, ContactSection(), s.prm[L3.P_VC] * 60.0, L3)
        apply_thermal_settings(s.prm, SolverSection(conduction_interval=3), ContactSection(),
                               load_material("TC4"), L3)
        return s

    a = build()
    b = build()
    t_end = 60 * a.clock[1]
    na = advance3(a, t_end, chunk_steps=25)
    prof = None if sys.argv[1] == 'persistent' else {}
    nb = advance3_gpu(b, t_end, chunk_steps=25, persistent=sys.argv[1] == 'persistent',
                      profile=prof)
    def rel(u, v):
        return float(np.max(np.abs(u - v)) / max(np.max(np.abs(u)), 1e-300))
    out = {"steps": [na, nb], "contact": float(np.abs(a.cf[:, :3]).sum()),
           "table": float(a.prm[L3.P_MUTAB_N]), "slide": float(np.max(a.cf[:, 3])),
           "vslip": rel(a.cf[:, 3], b.cf[:, 3]),
           "x": rel(a.x, b.x), "vx": rel(a.vx, b.vx), "vy": rel(a.vy, b.vy),
           "sd": rel(a.sd, b.sd), "pres": rel(a.pres, b.pres), "eps_p": rel(a.eps_p, b.eps_p),
           # temperature rise above room temperature (mat[TROOM])
           "temp": rel(a.temp - a.mat[6], b.temp - b.mat[6]),
           "heated": float(np.max(a.temp) - a.mat[6]),
           "cond_t": [float(a.prm[L3.P_COND_T]), float(b.prm[L3.P_COND_T])],
           "theat": rel(a.theat, b.theat),
           "tool": rel(a.tool, b.tool), "ext": rel(a.en[L2.E_EXT:L2.E_EXT + 1],
                                                  b.en[L2.E_EXT:L2.E_EXT + 1]),
           "hist_f": rel(np.nan_to_num(a.hist[:, S3.H_FX:S3.H_FZ + 1]),
                         np.nan_to_num(b.hist[:, S3.H_FX:S3.H_FZ + 1])),
           "profile": sorted(prof) if prof is not None else None}
    print("RESULT" + json.dumps(out))
""")


def test_gpu_module_imports_and_reports_cleanly():
    assert isinstance(cuda_available(), bool)
    if not cuda_available():
        with pytest.raises(ConfigError, match="no usable NVIDIA GPU"):
            require_gpu()


def _simulator_usable() -> bool:
    try:
        import numba.cuda  # noqa: F401
    except Exception:
        return False
    return True


@pytest.mark.skipif(not _simulator_usable(), reason="numba has no CUDA target/simulator")
@pytest.mark.parametrize("path", ["persistent", "launch_per_kernel"])
def test_cuda_kernels_match_cpu_engine_in_simulator(tmp_path, path):
    """60 steps of a 24-element block cut by the insert on springs (contact with the
    default friction law read at the filtered sliding speed, plasticity, support,
    histories): the CUDA kernels run in numba's simulator agree with the CPU
    engine to 1e-9 relative (the CPU element is compiled with FMA/reassociation, so not
    bit-identical), both the persistent kernel (one cooperative launch per chunk, the
    default) and the fallback of one launch per kernel and step."""
    env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1")
    p = subprocess.run([sys.executable, "-c", SCRIPT, path, str(BENCH)], env=env,
                       capture_output=True,
                       text=True, timeout=600, cwd=tmp_path)
    assert p.returncode == 0, p.stderr[-3000:]
    line = [s for s in p.stdout.splitlines() if s.startswith("RESULT")][-1]
    r = json.loads(line[len("RESULT"):])
    assert r["steps"][0] == r["steps"][1]
    assert r["contact"] > 0, "the insert never touched the block"
    assert r["table"] == 6 and r["slide"] > 0, "friction not read at the sliding speed"
    assert r["heated"] > 0.05, "no heat in the block"
    assert r["cond_t"][0] > 0 and r["cond_t"][0] == r["cond_t"][1], "conduction passes differ"
    for k in ("x", "vx", "vy", "sd", "pres", "eps_p", "tool", "ext", "hist_f", "vslip", "temp",
              "theat"):
        assert r[k] < 1e-9, (k, r)
    if path == "launch_per_kernel":  # run with a per-kernel profile (benchmarks use it)
        assert r["profile"] == ["conduction", "contact_sum", "elements", "finish", "nodes",
                                "tool"], r


class _NoCooperative:
    """Stands for a kernel that numba-cuda cannot specialise (no cudadevrt, say)."""

    def specialize(self, *args):
        raise RuntimeError("cudadevrt not found")


def test_persistent_kernel_falls_back_or_fails_clearly(monkeypatch):
    monkeypatch.delenv("NUMBA_ENABLE_CUDASIM", raising=False)
    with pytest.warns(RuntimeWarning, match="one kernel per phase"):
        assert gpu._cooperative(_NoCooperative(), [1], 128, fallback=True) is None
    with pytest.raises(ConfigError, match="persistent GPU kernel is not usable"):
        gpu._cooperative(_NoCooperative(), [1], 128, fallback=False)


def test_gpu_benchmark_script_runs_its_cpu_part(tmp_path):
    """benchmarks/bench_gpu.py (the script that measured the H100 figures of docs/fe3d.md)
    keeps running where there is no GPU: its environment report and the CPU half of the 3D
    throughput comparison, with the JSON it writes."""
    script = BENCH
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_ENABLE_CUDASIM"}
    out = tmp_path / "speed.json"
    p = subprocess.run([sys.executable, "-W", "ignore", str(script), "speed3d", "--no-gpu",
                        "--sizes", "16.6", "--cpu-steps", "3", "--out", str(out)],
                       env=env, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr[-3000:]
    r = json.loads(out.read_text())
    row = r["runs"][0]
    assert row["elements"] > 1000 and row["cpu"]["steps"] == 3, row
    assert row["cpu"]["element_updates_per_s"] > 0
    p = subprocess.run([sys.executable, str(script), "env"], env=env, capture_output=True,
                       text=True, timeout=300)
    assert p.returncode == 0, p.stderr[-3000:]
    assert '"cuda_available"' in p.stdout
