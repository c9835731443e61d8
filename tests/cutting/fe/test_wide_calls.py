"""The FE functions that still take more than 12 parameters (the per-element and per-node
updates of the hot loops, ``benchmarks/fe_code_counts.py``) are called, on the CPU and on
the GPU, with arguments named as their parameters, in the parameters' order: the CPU loop,
the GPU kernels and the definition cannot disagree on an order without this test failing.

An argument's name is its variable (``x``), the attribute it reads (``a.x``, a GPU run
state's field) or the variable a cast wraps (``np.int64(n)``).
"""

from __future__ import annotations

import ast
import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[3]
FE = ROOT / "src" / "robobore" / "cutting" / "fe"
_SCRIPT = ROOT / "benchmarks" / "fe_code_counts.py"

#: every call site of a wide function: (module under cutting/fe, name called there, the
#: wide function's definition)
WIDE_CALLS = [
    ("quad/element.py", "quad_element", "quad_element_py"),
    ("engine/gpu/kernels2d.py", "elem", "quad_element_py"),
    ("quad/bbar.py", "quad_bbar", "quad_bbar_py"),
    ("quad/node_contact.py", "quad_node", "quad_node_py"),
    ("engine/gpu/kernels2d.py", "node", "quad_node_py"),
    ("engine/kernels3d.py", "hex_element", "hex_element_py"),
    ("engine/gpu/kernels3d.py", "elem", "hex_element_py"),
    ("engine/kernels3d.py", "hex_node", "hex_node_py"),
    ("engine/gpu/kernels3d.py", "node", "hex_node_py"),
]


def _wide_functions() -> dict[str, list[str]]:
    """name -> parameter names of each function over the counter's limit."""
    spec = importlib.util.spec_from_file_location("fe_code_counts", _SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    out = {}
    for path in sorted(FE.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef) and mod.n_params(node) > mod.LIMIT:
                out[node.name] = [a.arg for a in node.args.posonlyargs + node.args.args]
    return out


def _arg_name(a: ast.expr) -> str | None:
    if isinstance(a, ast.Name):
        return a.id
    if isinstance(a, ast.Attribute):
        return a.attr
    if isinstance(a, ast.Call) and len(a.args) == 1:  # np.int64(n)
        return _arg_name(a.args[0])
    return None


def mismatches(source: str, callee: str, params: list[str]) -> list[tuple]:
    """``(line, position, parameter, argument)`` where a call of ``callee`` in ``source``
    does not pass an argument named as the parameter; a call with keywords or another
    number of arguments is one entry with position -1. Raises when there is no call."""
    calls = [n for n in ast.walk(ast.parse(source)) if isinstance(n, ast.Call)
             and isinstance(n.func, ast.Name) and n.func.id == callee]
    if not calls:
        raise AssertionError(f"no call of {callee}")
    bad = []
    for call in calls:
        names = [_arg_name(a) for a in call.args]
        if call.keywords or len(names) != len(params):
            bad.append((call.lineno, -1, len(params), len(names)))
            continue
        bad += [(call.lineno, i, p, n) for i, (p, n) in enumerate(zip(params, names))
                if p != n]
    return bad


def test_every_wide_function_has_its_call_sites_checked():
    wide = _wide_functions()
    assert set(wide) == {w for _, _, w in WIDE_CALLS}, (
        "a function over 12 parameters is not (or no longer) in WIDE_CALLS", sorted(wide))


@pytest.mark.parametrize("module, callee, wide", WIDE_CALLS,
                         ids=[f"{m}:{c}" for m, c, _ in WIDE_CALLS])
def test_wide_call_names_its_arguments_as_the_parameters(module, callee, wide):
    bad = mismatches((FE / module).read_text(), callee, _wide_functions()[wide])
    assert not bad, f"{module} {callee}: (line, position, parameter, argument) {bad}"


def test_a_swapped_argument_is_caught():
    # the check is not blind: the CPU element pass with two arguments in the other order
    src = (FE / "quad/element.py").read_text()
    swapped = src.replace("quad_element(e, conn, layer, area0, x, y,",
                          "quad_element(e, conn, layer, area0, y, x,")
    assert swapped != src
    params = _wide_functions()["quad_element_py"]
    assert mismatches(src, "quad_element", params) == []
    assert [b[1:] for b in mismatches(swapped, "quad_element", params)] == [
        (4, "x", "y"), (5, "y", "x")]
