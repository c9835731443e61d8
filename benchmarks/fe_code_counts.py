"""Counts of the FE engine's readability measures, read from the source with ``ast``.

``python benchmarks/fe_code_counts.py [--json]`` prints, for ``src/robobore/cutting``:

* ``functions_over_12_params``: functions (def, lambda excluded) with more than 12 parameters
  (positional, keyword-only, ``*args``/``**kwargs`` each count one); the generated blocks of
  ``P_*`` constants hold no functions, so every function counts;
* ``globals_update_rebind``: calls of ``globals().update`` and of a function named ``rebind``;
* ``frame_device_string_sites``: comparisons (``==``, ``!=``) of ``<...>.frame``, ``frame``,
  ``device`` or ``getattr(..., "frame")`` (the ``grep -rn "frame ==\\|device =="`` sites and
  their ``!=`` and ``getattr`` forms), outside the chooser module
  :mod:`robobore.cutting.fe.models.choose`;
* ``modules_over_500_lines``;
* ``dict_any_returns_fe``: functions of ``cutting/fe`` whose return annotation is
  ``dict[str, Any]`` and whose name is public (no leading underscore; ``to_dict``, the JSON of
  a typed result, aside).

``tests/cutting/fe/test_code_counts.py`` holds the first count to a ceiling.
"""

from __future__ import annotations

import ast
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1] / "src" / "robobore" / "cutting"
#: the one module that may compare frame/device strings: it chooses the model
CHOOSER = ROOT / "fe" / "models" / "choose.py"
LIMIT = 12


def n_params(fn: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    a = fn.args
    return (len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs) + (a.vararg is not None)
            + (a.kwarg is not None))


def _is_frame_device_cmp(node: ast.Compare) -> bool:
    if not any(isinstance(op, ast.Eq | ast.NotEq) for op in node.ops):
        return False
    for side in (node.left, *node.comparators):
        name = (side.attr if isinstance(side, ast.Attribute)
                else side.id if isinstance(side, ast.Name) else None)
        if (isinstance(side, ast.Call) and getattr(side.func, "id", None) == "getattr"
                and len(side.args) >= 2 and isinstance(side.args[1], ast.Constant)):
            name = side.args[1].value  # getattr(cfg.mesh, "frame", ...) == ...
        if name in ("frame", "device"):
            return True
    return False


def count(root: Path = ROOT) -> dict:
    wide: list[str] = []
    rebind: list[str] = []
    sites: list[str] = []
    long_mod: list[str] = []
    dict_any: list[str] = []
    for path in sorted(root.rglob("*.py")):
        src = path.read_text()
        rel = str(path.relative_to(root.parents[1]))
        n_lines = src.count("\n")
        if n_lines > 500:
            long_mod.append(f"{rel} ({n_lines})")
        tree = ast.parse(src)
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                n = n_params(node)
                if n > LIMIT:
                    wide.append(f"{rel}:{node.lineno} {node.name} ({n})")
                ret = node.returns
                if (ret is not None and "/fe/" in str(path) and not node.name.startswith("_")
                        and node.name != "to_dict"
                        and ast.unparse(ret).replace(" ", "") == "dict[str,Any]"):
                    dict_any.append(f"{rel}:{node.lineno} {node.name}")
            elif isinstance(node, ast.Call):
                f = node.func
                if isinstance(f, ast.Attribute) and f.attr == "update" and isinstance(
                        f.value, ast.Call) and getattr(f.value.func, "id", None) == "globals":
                    rebind.append(f"{rel}:{node.lineno} globals().update")
                elif getattr(f, "id", None) == "rebind" or getattr(f, "attr", None) == "rebind":
                    rebind.append(f"{rel}:{node.lineno} rebind")
            elif isinstance(node, ast.Compare) and path != CHOOSER and _is_frame_device_cmp(
                    node):
                sites.append(f"{rel}:{node.lineno}")
    return {"functions_over_12_params": wide, "globals_update_rebind": rebind,
            "frame_device_string_sites": sites, "modules_over_500_lines": long_mod,
            "dict_any_returns_fe": dict_any}


def main(argv: list[str]) -> None:
    c = count()
    if "--json" in argv:
        print(json.dumps(c, indent=1))
        return
    for k, v in c.items():
        print(f"{k}: {len(v)}")
        for item in v:
            print(f"    {item}")


if __name__ == "__main__":
    main(sys.argv[1:])
