"""GPU backend of the 2D engine: imports and fails cleanly without a GPU; the CUDA kernels
(built from the same scalar functions as the CPU engine) agree with the CPU engine in numba's
CUDA simulator.

Measured on an NVIDIA H100 on 2026-11-22 (benchmarks/bench_gpu.py; docs/fe.md, "GPU path");
CI has no GPU, so these simulator tests are what CI checks.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from typer.testing import CliRunner

from robobore.cli import app
from robobore.cutting.fe.engine.gpu import backend2d as gpu2d
from robobore.cutting.fe.engine.gpu.runstate2d import N_RED, RunState
from robobore.cutting.fe.engine.gpu.shared import cuda_available
from robobore.errors import ConfigError

EXAMPLE = Path(__file__).parents[3] / "examples" / "fe_orthogonal.toml"

#: shared by the simulator scripts: histories every 5 steps over the compared steps
PRELUDE = textwrap.dedent("""
    import numpy as np
    from robobore.cutting.fe.engine import layout as L

    def sample_every_5_steps(st, rows):
        dt = float(st.clock[1])
        st.prm[L.P_SAMPLE_DT] = 5 * dt
        k0 = int(st.clock[0] / st.prm[L.P_SAMPLE_DT])
        st.ist[L.I_SAMPLE] = k0
        st.hist = np.full((k0 + rows, L.N_HIST), np.nan)
        st.hacc[:] = 0.0
        st.clock[2] = 0.0
        return dt, k0
""")

SCRIPT = PRELUDE + textwrap.dedent("""
    import copy, json, sys
    import numpy as np
    from numba import cuda
    assert cuda.simulator_is_being_used() if hasattr(cuda, "simulator_is_being_used") else True
    from robobore.cutting.fe.engine import layout as L
    from robobore.cutting.fe.config.orthogonal import parse_config
    from robobore.cutting.fe.engine.gpu.backend2d import advance_gpu
    from robobore.cutting.fe.engine.chunk_driver import advance
    from robobore.cutting.fe.models.orthogonal import setup_orthogonal

    cfg = parse_config({
        "tool": {"rake_deg": 15.0, "clearance_deg": 2.0, "edge_radius_um": 20.0},
        "cut": {"uncut_chip_thickness_um": 60.0, "cutting_speed_m_per_min": 30.0,
                "length_mm": 0.06, "width_mm": 1.0},
        "contact": {"friction": "table", "friction_velocity": "sliding"},
        "parameters": "a_priori",
        "mesh": {"frame": "workpiece", "element_size_um": 15.0, "separation": "node_split",
                 "separation_height_um": 5.0},
        "solver": {"mass_scaling": 100.0, "heat_conduction": True,
                   "conduction_interval": 4},
        "tool_support": {"stiffness_N_per_m": [2e7, 2e7], "damping_N_s_per_m": [200.0, 200.0],
                         "mass_kg": [0.05, 0.05]},
    })
    s = setup_orthogonal(cfg)
    st = s.state
    # into the cut on the CPU: contact, plastic chip, released and still tied pairs
    t_mid = s.t_contact + 0.5 * (s.t_end - s.t_contact)
    advance(st, t_mid)
    dt, k0 = sample_every_5_steps(st, 20)
    a = copy.deepcopy(st)
    b = copy.deepcopy(st)
    t_end = float(st.clock[0]) + 40.5 * dt
    na = advance(a, t_end, chunk_steps=15)
    nb = advance_gpu(b, t_end, chunk_steps=15, persistent=sys.argv[1] == 'persistent')

    def rel(u, v):
        u = np.nan_to_num(np.asarray(u, float))
        v = np.nan_to_num(np.asarray(v, float))
        return float(np.max(np.abs(u - v)) / max(np.max(np.abs(u)), 1e-300))

    pairs = np.where(b.twin >= 0)[0]
    tied = pairs[b.tied[pairs] == 1]
    out = {"steps": [na, nb], "n_elements": int(st.conn.shape[0]),
           "contact_nodes": int(np.sum((a.cfx != 0) | (a.cfy != 0))),
           "plastic_growth": float(np.max(a.eps_p - st.eps_p)),
           "released": int(np.sum(st.tied[pairs] == 0)), "tied": int(tied.size),
           "support_um": float(abs(a.tool[L.T_UX]) * 1e6),
           "temp_cond": rel(a.temp, st.temp),
           "tied_bitwise": bool(np.array_equal(b.x[tied], b.x[b.twin[tied]])
                                and np.array_equal(b.y[tied], b.y[b.twin[tied]])),
           "same_tied": bool(np.array_equal(a.tied, b.tied)),
           "same_alive": bool(np.array_equal(a.alive, b.alive)),
           "samples": int(a.ist[L.I_SAMPLE] - k0),
           "friction_heat_J_per_m": float(np.sum(a.fheat - st.fheat)),
           "parting_edges": int(st.ppair.shape[0])}
    for k in ("x", "y", "vx", "vy", "sdx", "sdy", "sdxy", "pres", "eps_p", "temp", "dmg",
              "qhx", "ie", "hge", "fex", "cfx", "cfy", "fric", "nwork", "tool",
              "fheat"):
        out[k] = rel(getattr(a, k), getattr(b, k))
    out["hist"] = rel(a.hist, b.hist)  # with the force split by tool face (H_FX_RAKE ...)
    out["split_rake"] = float(np.nanmax(np.abs(a.hist[k0:, L.H_FX_RAKE])))
    out["en"] = rel(a.en, b.en)
    out["clock"] = rel(a.clock, b.clock)
    print("RESULT" + json.dumps(out))
""")


#: the tool-frame ALE model (examples/fe_orthogonal_toolframe.toml, coarsened), 23 steps from
#: the middle of a cut: the CPU engine, then the persistent kernel and one launch per kernel
SCRIPT_TF = PRELUDE + textwrap.dedent("""
    import copy, json, sys, tomllib
    import numpy as np
    from robobore.cutting.fe.engine import layout as L
    from robobore.cutting.fe.config.orthogonal import parse_config
    from robobore.cutting.fe.engine.gpu.backend2d import advance_gpu
    from robobore.cutting.fe.engine.chunk_driver import advance
    from robobore.cutting.fe.models.orthogonal import setup_orthogonal

    d = tomllib.load(open(sys.argv[1], "rb"))
    d["cut"]["length_mm"] = 0.02  # one element: the shortest cut the config accepts
    d["mesh"]["element_size_um"] = 20.0
    d["mesh"]["edge_element_um"] = 10.0
    d.setdefault("solver", {}).update(heat_conduction=True, conduction_interval=4)
    d.setdefault("contact", {})["friction_velocity"] = "sliding"
    d["tool_support"] = {"stiffness_N_per_m": [2e7, 2e7],
                         "damping_N_s_per_m": [200.0, 200.0], "mass_kg": [0.05, 0.05]}
    s = setup_orthogonal(parse_config(d))
    st = s.state
    advance(st, 0.5 * s.t_end)
    dt, k0 = sample_every_5_steps(st, 10)
    t_end = float(st.clock[0]) + 23.5 * dt
    a = copy.deepcopy(st)
    na = advance(a, t_end, chunk_steps=15)

    def rel(u, v):
        u = np.nan_to_num(np.asarray(u, float))
        v = np.nan_to_num(np.asarray(v, float))
        return float(np.max(np.abs(u - v)) / max(np.max(np.abs(u)), 1e-300))

    out = {"n_elements": int(st.conn.shape[0]),
           "ale_passes": sum(1 for i in range(int(st.ist[L.I_STEP]), int(a.ist[L.I_STEP]))
                             if i % int(st.prm[L.P_RZ_EVERY]) == 0),
           "mesh_moved_m": float(np.max(np.abs(a.aflt[:, 4:6] - st.aflt[:, 4:6]))),
           "area0_changed": float(np.max(np.abs(a.area0 - st.area0))),
           "mass_changed": float(np.max(np.abs(a.mass - st.mass))),
           "split_rake": float(np.nanmax(np.abs(a.hist[k0:, L.H_FX_RAKE]))),
           "temp_changed": float(np.max(np.abs(a.temp - st.temp)))}
    for path in ("persistent", "launch_per_kernel"):
        b = copy.deepcopy(st)
        nb = advance_gpu(b, t_end, chunk_steps=15, persistent=path == "persistent")
        r = {"steps": [na, nb]}
        for k in ("x", "y", "vx", "vy", "mass", "sdx", "sdy", "sdxy", "pres", "eps_p", "temp",
                  "area0", "aflt", "xn", "cfx", "cfy", "fric", "tool", "fheat", "vslip",
                  "hist", "en", "clock"):
            r[k] = rel(getattr(a, k), getattr(b, k))
        out[path] = r
    print("RESULT" + json.dumps(out))
""")


def test_gpu2d_module_imports_and_reports_cleanly():
    assert callable(gpu2d.advance_gpu)
    if not cuda_available():
        from robobore.cutting.fe.config.orthogonal import load_fe_config
        from robobore.cutting.fe.models.orthogonal import simulate_orthogonal

        with pytest.raises(ConfigError, match="no usable NVIDIA GPU"):
            simulate_orthogonal(load_fe_config(EXAMPLE), device="gpu")


def test_bbar_is_refused_on_the_gpu():
    with pytest.raises(ConfigError, match="solver.element"):
        gpu2d.check_gpu_supported("q4_bbar")
    gpu2d.check_gpu_supported("q4r")


def test_cli_device_gpu_fails_cleanly_without_gpu(tmp_path):
    if cuda_available():
        pytest.skip("a GPU is usable here")
    r = CliRunner().invoke(app, ["fe", "orthogonal", str(EXAMPLE), "--json", "--device", "gpu"])
    assert r.exit_code == 2
    assert "no usable NVIDIA GPU" in r.output and "--device" in r.output
    assert "Traceback" not in r.output


def test_cli_rejects_unknown_device_and_bbar_on_gpu(tmp_path):
    r = CliRunner().invoke(app, ["fe", "orthogonal", str(EXAMPLE), "--json", "--device", "tpu"])
    assert r.exit_code == 2
    assert "unknown device" in r.output and "tpu" in r.output
    f = tmp_path / "bbar.toml"
    f.write_text(EXAMPLE.read_text() + '[solver]\nelement = "q4_bbar"\n')
    r = CliRunner().invoke(app, ["fe", "orthogonal", str(f), "--json", "--device", "gpu"])
    assert r.exit_code == 2
    assert "solver.element" in r.output


def _simulator_usable() -> bool:
    try:
        import numba.cuda  # noqa: F401
    except Exception:
        return False
    return True


@pytest.mark.skipif(not _simulator_usable(), reason="numba has no CUDA target/simulator")
@pytest.mark.parametrize("path", ["persistent", "launch_per_kernel"])
def test_cuda_kernels_match_cpu_engine_in_simulator(tmp_path, path):
    """40 steps of a node-split cut in progress (tool on springs, contact, plastic chip,
    released and tied pairs, conduction every 4 steps with the thermal contact and the tied
    parting-line edges, histories every 5 steps, friction from the Rech table at each
    contact node's sliding speed): the CUDA
    kernels run in numba's simulator give the same bits as the CPU engine: both devices
    run the same scalar functions, sum the contact force in the same fixed order
    (``quad.node_contact.contact_total``), and use atomics only for exact operations (a count,
    a min, a max) -- both the persistent kernel (the default) and one launch per kernel and step.

    The CPU engine is compiled afresh in the subprocess (its own NUMBA_CACHE_DIR): the
    machine code numba makes for ``quad.element.element_update`` depends on what else the process
    compiled before it (with a cache filled by other tests the same element can give a result
    2e-13 apart after 40 steps; swapping that function's cache files flips the comparison),
    so bit-identity holds for a given compilation, not across them."""
    env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1", NUMBA_NUM_THREADS="1",
               NUMBA_CACHE_DIR=str(tmp_path / "numba_cache"))
    p = subprocess.run([sys.executable, "-c", SCRIPT, path], env=env, capture_output=True,
                       text=True, timeout=600, cwd=tmp_path)
    assert p.returncode == 0, p.stderr[-3000:]
    line = [s for s in p.stdout.splitlines() if s.startswith("RESULT")][-1]
    r = json.loads(line[len("RESULT"):])
    print(r)
    assert r["steps"][0] == r["steps"][1] >= 30
    # the compared steps exercise what they claim to
    assert r["contact_nodes"] > 0, r
    assert r["plastic_growth"] > 0, r
    assert r["released"] > 0 and r["tied"] > 0, r
    assert r["support_um"] > 0, r
    assert r["temp_cond"] > 0, r
    assert r["samples"] >= 7, r
    # the thermal contact (frictional heat, tool conductance) and the tied parting-line
    # conduction run in the compared steps
    assert r["friction_heat_J_per_m"] > 0 and r["parting_edges"] > 0, r
    assert r["tied_bitwise"] and r["same_tied"] and r["same_alive"], r
    for k in ("x", "y", "vx", "vy", "sdx", "sdy", "sdxy", "pres", "eps_p", "temp", "dmg",
              "qhx", "ie", "hge", "fex", "cfx", "cfy", "fric", "nwork", "tool", "hist", "en",
              "clock", "fheat"):
        assert r[k] == 0.0, (k, r)


@pytest.mark.skipif(not _simulator_usable(), reason="numba has no CUDA target/simulator")
def test_toolframe_ale_on_the_gpu_matches_cpu_engine_in_simulator(tmp_path):
    """The tool-frame ALE model (``mesh.frame = "tool"``) on the GPU: 23 steps from the
    middle of a coarse cut (tool on springs, conduction every 4 steps with the thermal
    contact, friction read at the sliding speed) with the ALE pass at every 10th step --
    node placement, Jacobi sweeps, donor-cell remap with inflow of virgin material, velocity
    remap and nodal masses, all run by the GPU kernels from the scalar functions of rezone.py
    and remap.py -- give the same bits as the CPU engine in numba's simulator, with the
    persistent kernel and with one launch per kernel; the force split by tool face too. (Own
    numba cache: see the test above.)"""
    env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1", NUMBA_NUM_THREADS="1",
               NUMBA_CACHE_DIR=str(tmp_path / "numba_cache"))
    tf = Path(__file__).parents[3] / "examples" / "fe_orthogonal_toolframe.toml"
    p = subprocess.run([sys.executable, "-c", SCRIPT_TF, str(tf)], env=env,
                       capture_output=True, text=True, timeout=900, cwd=tmp_path)
    assert p.returncode == 0, p.stderr[-3000:]
    line = [s for s in p.stdout.splitlines() if s.startswith("RESULT")][-1]
    r = json.loads(line[len("RESULT"):])
    print(r)
    # the compared steps exercise what they claim to: ALE passes that move the mesh and
    # remap the masses, heat, contact on the rake
    assert r["ale_passes"] >= 2, r
    assert r["mesh_moved_m"] > 0 and r["area0_changed"] > 0 and r["mass_changed"] > 0, r
    assert r["split_rake"] > 0 and r["temp_changed"] > 0, r
    for path in ("persistent", "launch_per_kernel"):
        q = r[path]
        assert q["steps"][0] == q["steps"][1] == 23, (path, q)
        for k, v in q.items():
            if k != "steps":
                assert v == 0.0, (path, k, q)


def test_persistent_kernel_parameters_fit_in_cuda_limit():
    """CUDA's classic limit on a kernel's parameters is 4096 bytes (larger only from CUDA
    12.1 on recent GPUs and toolkits); numba passes each array as its data model's flattened
    fields (56 bytes for a 1D array, 72 for 2D). The 2D persistent kernel takes the whole
    state, so a new state array could push it over: count the bytes with numba's own data
    model for the tool-frame state (the largest argument list)."""
    import tomllib

    import llvmlite.ir as ir
    import numpy as np
    from numba import typeof
    from numba.core.datamodel import default_manager

    from robobore.cutting.fe.config.orthogonal import parse_config
    from robobore.cutting.fe.models.orthogonal import setup_orthogonal

    def nbytes(t) -> int:
        if isinstance(t, tuple):
            return sum(nbytes(x) for x in t)
        if isinstance(t, ir.IntType):
            return t.width // 8
        if isinstance(t, (ir.PointerType, ir.DoubleType)):
            return 8
        if isinstance(t, ir.ArrayType):
            return t.count * nbytes(t.element)
        if isinstance(t, ir.LiteralStructType):
            return sum(nbytes(e) for e in t.elements)
        raise TypeError(t)

    def arg(v) -> int:
        return nbytes(default_manager.lookup(typeof(v)).get_argument_type())

    tf = Path(__file__).parents[3] / "examples" / "fe_orthogonal_toolframe.toml"
    d = tomllib.loads(tf.read_text())
    d["cut"]["length_mm"] = 0.02  # one element: the shortest cut the config accepts
    d["mesh"]["element_size_um"] = 20.0
    d["mesh"]["edge_element_um"] = 10.0
    st = setup_orthogonal(parse_config(d)).state
    # k_run(n_steps, state (the arrays, then erosion, cond_every, theat, rz_every), red, cflag,
    # clist); the state, a namedtuple, passes as its elements' fields
    state = RunState(*[getattr(st, k) for k in gpu2d._ARRAYS], 0, 0, 0, 0)
    total = (arg(0) + arg(state) + arg(np.zeros(N_RED)) + arg(np.zeros(1, np.int32))
             + arg(np.zeros(1, np.int64)))
    assert arg(state) == sum(arg(v) for v in state)
    assert arg(np.zeros(3)) == 56 and arg(np.zeros((3, 2))) == 72  # the model counted
    assert total <= 4096, total
