#!/usr/bin/env bash
# Build (once) a side virtual environment with numba-cuda and the CUDA compiler wheels, then
# compile every GPU kernel for a GPU architecture without a GPU (benchmarks/gpu_compile_check.py).
#
#   benchmarks/gpu_compile_check.sh [--cc 9.0]
#
# ROBOBORE_GPU_VENV: where the environment lives (default ~/.cache/robobore-gpu-venv, outside
# the checkout); PYTHON: the interpreter that creates it (default python3, >= 3.11).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="${ROBOBORE_GPU_VENV:-$HOME/.cache/robobore-gpu-venv}"
if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c "import numba_cuda" 2>/dev/null; then
    "${PYTHON:-python3}" -m venv "$venv"
    "$venv/bin/pip" install -e "$root" "numba-cuda" nvidia-cuda-nvcc-cu12 nvidia-cuda-nvrtc-cu12
fi
cd "$root"
exec "$venv/bin/python" benchmarks/gpu_compile_check.py "$@"
