"""The CPU engines' one step loop (robobore.cutting.fe.engine.step_loop): each engine's phases
read the state by the names of its chunk-loop state, which must follow the order of the
state's ``kernel_args()`` (the arrays the host driver hands the loop)."""

from __future__ import annotations

import types
from pathlib import Path

import numpy as np
import pytest
from conftest import strip_mesh

from robobore.cutting.fe.engine import chunk_loop as CL
from robobore.cutting.fe.engine import kernels3d as K3
from robobore.cutting.fe.engine import step_loop as SL

EX = Path(__file__).parents[3] / "examples"


def _state2():
    from robobore.cutting.fe.config.orthogonal import load_fe_config
    from robobore.cutting.fe.models.orthogonal import setup_orthogonal

    cfg = load_fe_config(EX / "fe_orthogonal.toml")
    cfg.cut.length_mm = 0.01
    return setup_orthogonal(cfg).state


def _state3():
    from robobore.cutting.fe.config.boring3d import parse_boring_config
    from robobore.cutting.fe.models.boring3d import setup_boring
    from robobore.io.config import load_toml

    d = load_toml(EX / "fe_boring_paper.toml")
    d["mesh"]["element_size_um"] = 16.6
    d["cut"]["cut_length_mm"] = 0.02
    return setup_boring(parse_boring_config(d)).state


@pytest.mark.parametrize("build, names", [(_state2, CL.CHUNK_ARGS), (_state3, K3.CHUNK_ARGS3)])
def test_the_loop_state_names_the_kernel_arguments_in_order(build, names):
    st = build()
    args = st.kernel_args()
    assert len(args) == len(names)
    for name, arr in zip(names, args, strict=True):
        assert getattr(st, name) is arr, name


def loop_code():
    """The code of the loop :func:`step_loop.make_chunk_loop` returns (a closure: one code
    object for every engine and choice)."""
    return next(c for c in SL.make_chunk_loop.__code__.co_consts
                if isinstance(c, types.CodeType) and c.co_name == "chunk_loop")


def test_both_engines_run_the_one_loop():
    loops = [CL._loop_q4r, CL._loop_q4r_heat, CL._loop_bbar, CL._loop_bbar_heat, CL._loop_ale,
             CL._loop_ale_heat, K3._loop3]
    for loop in loops:
        assert loop.py_func.__code__ is loop_code()
    # each under its own name, its phases closed over (no module global rebound)
    assert len({loop.py_func.__qualname__ for loop in loops}) == len(loops)
    assert all(loop.py_func.__closure__ for loop in loops)


def test_a_compiled_pass_without_its_interval_is_refused():
    from robobore.cutting.fe.engine.chunk_driver import advance
    from robobore.cutting.fe.engine.state2d import default_prm, make_state
    from robobore.errors import ConfigError
    from robobore.material import load_material

    nodes, conn = strip_mesh(4, 1, 4e-5, 1e-5)
    for phases, slot in ((CL.Phases(conduction=True), "P_COND_EVERY"),
                         (CL.Phases(tool_frame=True), "P_RZ_EVERY")):
        st = make_state(nodes, conn, np.zeros(nodes.shape[0], bool), load_material("TC4"),
                        prm=default_prm(), phases=phases)
        with pytest.raises(ConfigError, match=slot):
            advance(st, 1e-9)
