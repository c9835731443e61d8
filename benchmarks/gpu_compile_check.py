"""Compile the GPU engines' persistent kernels for a GPU architecture WITHOUT a GPU, and print
their resource use (registers, spills) from ``ptxas``.

A device call costs minutes; this catches compile errors (a non-constant shared-array shape,
an untyped closure) and register growth on any machine. Needs, in the environment that runs
it (a side virtual environment is fine)::

    pip install -e . "numba-cuda" nvidia-cuda-nvcc-cu12 nvidia-cuda-nvrtc-cu12

No environment variable is needed: numba-cuda finds libnvvm in the nvidia-cuda-nvcc wheel,
and this script runs that wheel's ``ptxas``. ``benchmarks/gpu_compile_check.sh`` builds such an
environment once (outside the checkout) and runs this script.

Usage::

    python benchmarks/gpu_compile_check.py [--cc 9.0]

numba-cuda asks the current device for its compute capability when it compiles device
functions; with no device there, this script answers with ``--cc`` (a development aid, not
something the engines do).

The CPU functions this script compiles on the way go to a temporary numba cache: with
numba-cuda loaded, numba's CPU code differs in the last bits, and those cache files would
otherwise be picked up by later CPU runs of the engines in this checkout (the stored digits of
tests/cutting/fe/test_fe_digits.py would then not be reproduced).
"""

from __future__ import annotations

import argparse
import atexit
import glob
import inspect
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import types
from pathlib import Path

os.environ["NUMBA_CACHE_DIR"] = tempfile.mkdtemp(prefix="robobore_gpu_compile_check_numba_")
atexit.register(shutil.rmtree, os.environ["NUMBA_CACHE_DIR"], ignore_errors=True)

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def _ptxas() -> str | None:
    """The ``ptxas`` of the nvidia-cuda-nvcc wheel, or None."""
    try:
        import nvidia
    except ImportError:
        return None
    for base in nvidia.__path__:
        hits = glob.glob(os.path.join(base, "cuda_nvcc", "bin", "ptxas"))
        if hits:
            return hits[0]
    return None


def main() -> int:
    ap = argparse.ArgumentParser(description=" ".join(__doc__.split("\n\n")[0].split()))
    ap.add_argument("--cc", default="9.0", help="compute capability, e.g. 9.0 (H100)")
    a = ap.parse_args()
    cc = tuple(int(v) for v in a.cc.split("."))
    try:
        import numba.cuda.dispatcher as disp
        import numba_cuda  # noqa: F401  (numba's built-in CUDA target cannot do this)
        from numba import cuda, typeof
    except Exception as e:  # pragma: no cover - depends on the environment
        print(f"needs numba-cuda ({type(e).__name__}: {e}): pip install numba-cuda "
              "nvidia-cuda-nvcc-cu12 nvidia-cuda-nvrtc-cu12 (see the module docstring)")
        return 2
    disp.get_current_device = lambda: types.SimpleNamespace(compute_capability=cc)

    from robobore.cutting.fe.config.boring3d import parse_boring_config
    from robobore.cutting.fe.config.orthogonal import load_fe_config
    from robobore.cutting.fe.engine import layout
    from robobore.cutting.fe.engine.chunk_loop import Phases
    from robobore.cutting.fe.engine.gpu import backend2d as gpu2d
    from robobore.cutting.fe.engine.gpu import backend3d as gpu
    from robobore.cutting.fe.engine.gpu import kernels3d as gpu_k3
    from robobore.cutting.fe.engine.gpu import runstate2d
    from robobore.cutting.fe.hex import layout3d
    from robobore.cutting.fe.models.boring3d import setup_boring
    from robobore.cutting.fe.models.orthogonal import setup_orthogonal
    from robobore.cutting.fe.quad import node_contact
    from robobore.io.config import load_toml

    d = load_toml(ROOT / "examples" / "fe_boring_paper.toml")
    d["mesh"]["element_size_um"] = 16.6
    d["mesh"]["frame"] = "workpiece"  # the GPU engine's frame (the tool frame is CPU only)
    st3 = setup_boring(parse_boring_config(d)).state
    # the tool-frame model's state (conduction on): the same argument types as the workpiece
    # frame's, with the ALE arrays filled; the kernels of its phases (ALE and heat: the
    # largest persistent kernel)
    cfg = load_fe_config(ROOT / "examples" / "fe_orthogonal_toolframe.toml")
    cfg.cut.length_mm = 0.01
    st2 = setup_orthogonal(cfg).state
    k2 = gpu2d._kernels(st2.phases)

    def chunk_arrays(nn: int) -> list:
        n = (nn + node_contact.N_SUM_LANES - 1) // node_contact.N_SUM_LANES
        return [np.zeros(n, np.int32), np.zeros(n, np.int64)]

    # k_run(n_steps, state (the arrays, then the scalar settings), red, cflag, clist)
    cases = {
    }
    # the 3D persistent kernel with and without the heat phase
    run3 = [1, gpu_k3.RunState3(*[np.ascontiguousarray(getattr(st3, n)) for n in gpu._RUN_ARGS],
                             int(st3.prm[layout3d.P_EROSION])),
            np.zeros(gpu_k3.N_RED)] + chunk_arrays(st3.x.shape[0])
    for conduction in (True, False):
        name = f"3D k_run ({'conduction' if conduction else 'adiabatic'})"
        cases[name] = (gpu._kernels(conduction)[-1], run3)
    # the 3D launch-per-kernel path's kernels (with conduction: all of them), each on the state
    # ``a`` and, where it takes them, the reductions ``red``
    k3 = gpu._kernels(True)
    for kern in tuple(k3[:5]) + tuple(k3[5]):
        names = inspect.signature(kern.py_func).parameters
        args = [np.zeros(gpu_k3.N_RED) if n == "red" else run3[1] for n in names]
        cases[f"3D {kern.py_func.__name__}"] = (kern, args)
    # the 2D persistent kernel of each GPU model choice (the tool frame and conduction, each
    # on or off), compiled for the tool-frame state's argument types
    run2 = [1, runstate2d.RunState(*[np.ascontiguousarray(getattr(st2, n)) for n in gpu2d._ARRAYS],
                              int(st2.prm[layout.P_EROSION]), 1, 1,
                              int(st2.prm[layout.P_RZ_EVERY])),
            np.zeros(runstate2d.N_RED)] + chunk_arrays(st2.x.shape[0])
    for tool_frame in (True, False):
        for conduction in (True, False):
            ph = Phases("q4r", tool_frame, conduction)
            name = (f"2D k_run ({'tool' if tool_frame else 'workpiece'} frame, "
                    f"{'conduction' if conduction else 'adiabatic'})")
            cases[name] = (gpu2d._kernels(ph)[-2], run2)
    # the launch-per-kernel path's kernels (the tool frame with conduction: all of them), each
    # on the state ``a`` and, where it takes them, the reductions ``red``
    for kern in tuple(k2[:-2]) + tuple(k2[-1]):
        names = inspect.signature(kern.py_func).parameters
        args = [np.zeros(runstate2d.N_RED) if n == "red" else run2[1] for n in names]
        cases[f"2D {kern.py_func.__name__}"] = (kern, args)
    ptxas = _ptxas()
    rc = 0
    for name, (kernel, args) in cases.items():
        t0 = time.perf_counter()
        try:
            ptx, _ = cuda.compile_ptx(kernel.py_func, tuple(typeof(v) for v in args), cc=cc)
        except Exception as e:
            print(f"{name}: DOES NOT COMPILE: {type(e).__name__}: {str(e)[:2000]}")
            rc = 1
            continue
        line = f"{name}: PTX {len(ptx)} characters in {time.perf_counter() - t0:.1f} s"
        if ptxas is not None:
            with tempfile.TemporaryDirectory() as tmp:
                f = Path(tmp) / "k.ptx"
                f.write_text(ptx)
                p = subprocess.run([ptxas, f"-arch=sm_{cc[0]}{cc[1]}", "-c", "-v", str(f),
                                    "-o", str(Path(tmp) / "k.o")],
                                   capture_output=True, text=True)
            regs = re.findall(r"Used (\d+) registers", p.stderr)
            spill = re.findall(r"(\d+) bytes spill stores, (\d+) bytes spill loads", p.stderr)
            if p.returncode != 0:
                line += f"; ptxas failed: {p.stderr[-500:]}"
                rc = 1
            else:
                line += (f"; {regs[-1] if regs else '?'} registers a thread, spills "
                         f"(stores/loads bytes) {spill[-1] if spill else '?'}")
        print(line, flush=True)
    return rc


if __name__ == "__main__":
    sys.exit(main())
