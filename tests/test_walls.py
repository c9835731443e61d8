"""Walls between robobore's modules, checked on the source with ``ast``.

- Only the command-line modules import the command-line layer: a module other than
  ``cli.py``, ``*/cli.py``, ``*/cli_*.py``, ``clitools.py`` and ``__main__.py`` that imports
  ``robobore.cli``, ``robobore.clitools`` or a ``cli`` module fails. Library code reports
  progress through a ``progress`` callback that the CLI builds.
- No module uses another module's private name (``from robobore.x import _y``, or ``m._y``
  where ``m`` is a robobore module bound by an import).
- No import cycle between robobore's modules, following the imports at module level and
  those inside functions (``python tests/test_walls.py`` prints both counts).
- Layer order (:data:`LAYERS`, drawn in docs/ARCHITECTURE.md, "Layers"): a module imports
  only modules of its own stage and of stages in lower layers, at module level and inside
  functions (``TYPE_CHECKING`` imports, annotations only, are left out). ``errors`` and ``io``
  import no stage; the command-line modules and ``api`` form the top layer. A module in no
  stage of the table fails, so that a new package is placed in it.
- No re-export hub: a name taken from a robobore module (``from robobore.a import name`` or
  ``a.name`` where ``a`` is a module bound by an import) is one that module defines (``def``,
  ``class``, assignment), not one it imports; a module imports no robobore name that it does
  not use itself, and its ``__all__`` lists only names it defines. :data:`PUBLIC_HUBS` names
  the package ``__init__`` files that gather names for the users of the package (``from
  robobore.material import Material``), with the reason; robobore's own modules import from
  the defining module even there. A package that loads its names on first use (an
  ``_EXPORTS`` table of name -> submodule, ``robobore.robot``, ``robobore.modal``) names the
  submodule that defines each.

Every failure names ``file:line`` of the offending import or attribute. ``EXEMPT`` lists the
packages not yet held to the private-name and cycle rules, by name, so that each can be
removed when it is brought in line.
"""

from __future__ import annotations

import ast
import sys
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"
ROOT_PACKAGE = "robobore"

#: packages (dotted prefixes) not yet held to the private-name and import-cycle rules
EXEMPT: tuple[str, ...] = ()

CLI_LAYER = ("robobore.cli", "robobore.clitools")

#: package ``__init__`` files that import names only to offer them to the package's users, with
#: the reason; they may hold names they do not use (robobore's modules do not import through
#: them)
PUBLIC_HUBS: dict[str, str] = {
    "robobore.material": "the material API of docs/api.md and the examples: Material, "
                         "load_material, bundled_materials",
    "robobore.io": "the file helpers of the package's edges: load_toml, validate_model, "
                   "atomic writes, write_json, write_netcdf",
}

#: the layers of the package, lowest first: (layer, stages), each stage (name, the dotted
#: module prefixes it holds). A module belongs to the stage of its longest matching prefix
#: (the root ``robobore`` only as itself); the command-line modules (:func:`is_cli_module`)
#: belong to the top layer wherever they sit. A module may import its own stage's modules and
#: those of the stages of lower layers, never a stage of its own layer or above.
LAYERS: tuple[tuple[str, tuple[tuple[str, tuple[str, ...]], ...]], ...] = (
    ("errors", (("errors", ("robobore.errors",)),)),
    ("foundation", (("io", ("robobore.io", "robobore")),)),
    ("models", (("robot", ("robobore.robot",)),
                ("material", ("robobore.material",)),
                ("cutting.geometry", ("robobore.cutting.geometry", "robobore.cutting.edge_kernels",
                                      "robobore.cutting")))),
    ("identification", (("modal", ("robobore.modal",)),
                        ("cutting.forces", ("robobore.cutting.forces",
                                            "robobore.cutting.coefficient_files",
                                            "robobore.cutting.coefficient_sets")))),
    ("equivalent and FE", (("equivalent", ("robobore.equivalent",)),
                           ("cutting.fe", ("robobore.cutting.fe",)))),
    ("process", (("dynamics", ("robobore.dynamics",)),
                 ("cutting.calibration", ("robobore.cutting.calibrate",
                                          "robobore.cutting.calibration_config",
                                          "robobore.cutting.calibration_runs")))),
    ("planning", (("plan", ("robobore.plan",)),)),
    ("measurement", (("measure", ("robobore.measure",)),)),
    ("study", (("study", ("robobore.study",)),)),
    ("interface", (("api", ("robobore.api",)),
                   ("cli", ("robobore.cli", "robobore.clitools", "robobore.__main__")))),
)


@dataclass(frozen=True)
class Import:
    module: str  # the importing module
    path: Path
    line: int
    target: str  # the imported module (resolved: a submodule when the name is one)
    names: tuple[str, ...]  # names taken from the target by ``from ... import``
    top_level: bool  # executed when the module is imported (not inside a function)
    type_checking: bool  # under ``if TYPE_CHECKING:``

    @property
    def where(self) -> str:
        return f"{_rel(self.path)}:{self.line}"


def _rel(path: Path) -> Path:
    """``src/robobore/...``: the path from the folder holding the package."""
    parts = path.parts
    return Path(*parts[parts.index(ROOT_PACKAGE) - 1:])


def module_files(src: Path = SRC) -> dict[str, Path]:
    """Dotted module name -> file, for every module of the package."""
    out = {}
    for p in sorted((src / ROOT_PACKAGE).rglob("*.py")):
        parts = list(p.relative_to(src).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = p
    return out


def _is_package(mod: str, files: dict[str, Path]) -> bool:
    return files[mod].name == "__init__.py"


def _resolve_from(mod: str, node: ast.ImportFrom, files: dict[str, Path]) -> str:
    if not node.level:
        return node.module or ""
    base = mod.split(".")
    if not _is_package(mod, files):
        base = base[:-1]
    base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _walk(tree: ast.AST):
    """(node, inside_function, under_type_checking) for every node."""
    stack = [(tree, False, False)]
    while stack:
        node, in_func, tc = stack.pop()
        yield node, in_func, tc
        for child in ast.iter_child_nodes(node):
            c_func = in_func or isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef
                                           | ast.Lambda)
            c_tc = tc or (isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)
                          and child in node.body)
            stack.append((child, c_func, c_tc))


def imports(files: dict[str, Path] | None = None) -> list[Import]:
    """Every import of a robobore module by a robobore module."""
    files = files if files is not None else module_files()
    out = []
    for mod, path in files.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        for node, in_func, tc in _walk(tree):
            if isinstance(node, ast.Import):
                for a in node.names:
                    if a.name.split(".")[0] == ROOT_PACKAGE:
                        out.append(Import(mod, path, node.lineno, a.name, (), not in_func, tc))
            elif isinstance(node, ast.ImportFrom):
                base = _resolve_from(mod, node, files)
                if base.split(".")[0] != ROOT_PACKAGE:
                    continue
                plain = []
                for a in node.names:
                    sub = f"{base}.{a.name}"
                    if sub in files:  # ``from package import module``
                        out.append(Import(mod, path, node.lineno, sub, (), not in_func, tc))
                    else:
                        plain.append(a.name)
                if plain or not node.names:
                    out.append(Import(mod, path, node.lineno, base, tuple(plain), not in_func,
                                      tc))
    return sorted(out, key=lambda i: (str(i.path), i.line))


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def _exempt(mod: str) -> bool:
    return any(mod == e or mod.startswith(e + ".") for e in EXEMPT)


def is_cli_module(mod: str) -> bool:
    last = mod.rsplit(".", 1)[-1]
    return (mod in CLI_LAYER or mod == f"{ROOT_PACKAGE}.__main__" or last == "cli"
            or last.startswith("cli_"))


def cli_layer_violations(files: dict[str, Path] | None = None) -> list[str]:
    """Non-CLI modules importing the CLI layer (anywhere in the module, also in functions)."""
    files = files if files is not None else module_files()
    bad = []
    for imp in imports(files):
        if is_cli_module(imp.module):
            continue
        if is_cli_module(imp.target):
            bad.append(f"{imp.where}: {imp.module} imports {imp.target} (the CLI layer)")
    return bad


def private_name_violations(files: dict[str, Path] | None = None,
                            exempt: bool = True) -> list[str]:
    """Uses of another module's private name: ``from robobore.x import _y``, ``x._y``, an
    import of a private module."""
    files = files if files is not None else module_files()
    bad = []
    for mod, path in files.items():
        if exempt and _exempt(mod):
            continue
        rel = _rel(path)
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        bound: dict[str, str] = {}  # local name -> robobore module it is bound to
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                for a in node.names:
                    if a.name.split(".")[0] != ROOT_PACKAGE:
                        continue
                    if a.asname:
                        bound[a.asname] = a.name
                    else:
                        bound[ROOT_PACKAGE] = ROOT_PACKAGE
                    if any(_private(p) for p in a.name.split(".")):
                        bad.append(f"{rel}:{node.lineno}: {mod} imports private module {a.name}")
            elif isinstance(node, ast.ImportFrom):
                base = _resolve_from(mod, node, files)
                if base.split(".")[0] != ROOT_PACKAGE or base == mod:
                    continue
                for a in node.names:
                    if f"{base}.{a.name}" in files:
                        bound[a.asname or a.name] = f"{base}.{a.name}"
                    if _private(a.name):
                        bad.append(f"{rel}:{node.lineno}: {mod} imports {base}.{a.name}")
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute) and _private(node.attr):
                target = _dotted(node.value, bound)
                if target is not None and target in files and target != mod:
                    bad.append(f"{rel}:{node.lineno}: {mod} uses {target}.{node.attr}")
    return sorted(set(bad))


def _dotted(node: ast.AST, bound: dict[str, str]) -> str | None:
    if isinstance(node, ast.Name):
        return bound.get(node.id)
    if isinstance(node, ast.Attribute):
        head = _dotted(node.value, bound)
        return f"{head}.{node.attr}" if head is not None else None
    return None


def import_graph(files: dict[str, Path] | None = None, function_level: bool = False
                 ) -> dict[str, dict[str, Import]]:
    """module -> {imported module: first import} over runtime imports (module level; with
    ``function_level`` also those inside functions). ``TYPE_CHECKING`` imports are left out."""
    files = files if files is not None else module_files()
    graph: dict[str, dict[str, Import]] = defaultdict(dict)
    for imp in imports(files):
        if imp.type_checking or (not imp.top_level and not function_level):
            continue
        if imp.target in files and imp.target != imp.module:
            graph[imp.module].setdefault(imp.target, imp)
    return graph


def cycles(graph: dict[str, dict[str, Import]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan), sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    counter = [0]
    sys.setrecursionlimit(max(10000, sys.getrecursionlimit()))

    def strong(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, {}):
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(set(graph) | {w for e in graph.values() for w in e}):
        if v not in index:
            strong(v)
    return sorted(out)


def cycle_report(graph: dict[str, dict[str, Import]], comp: list[str]) -> str:
    members = set(comp)
    edges = [f"    {imp.where}: {a} -> {b}" for a in comp
             for b, imp in sorted(graph.get(a, {}).items()) if b in members]
    return f"cycle among {', '.join(comp)}:\n" + "\n".join(edges)


def cycle_violations(files: dict[str, Path] | None = None, function_level: bool = False,
                     exempt: bool = True) -> list[str]:
    graph = import_graph(files, function_level)
    return [cycle_report(graph, c) for c in cycles(graph)
            if not (exempt and all(_exempt(m) for m in c))]


def stage_of(mod: str) -> tuple[int, str] | None:
    """(layer index, stage name) of a module by :data:`LAYERS`; None for a module in no
    stage."""
    if is_cli_module(mod):
        return len(LAYERS) - 1, "cli"
    best: tuple[int, int, str] | None = None  # (prefix length, layer, stage)
    for i, (_layer, stages) in enumerate(LAYERS):
        for name, prefixes in stages:
            for pre in prefixes:
                hit = mod == pre or (pre != ROOT_PACKAGE and mod.startswith(pre + "."))
                if hit and (best is None or len(pre) > best[0]):
                    best = (len(pre), i, name)
    return None if best is None else (best[1], best[2])


def layer_violations(files: dict[str, Path] | None = None) -> list[str]:
    """Imports against the layer order of :data:`LAYERS` (module and function level; not
    ``TYPE_CHECKING``), and modules in no stage, each naming ``file:line``."""
    files = files if files is not None else module_files()
    bad = [f"{_rel(p)}: {m} is in no stage of tests/test_walls.py LAYERS (place it there and "
           "in docs/ARCHITECTURE.md)" for m, p in files.items() if stage_of(m) is None]
    for imp in imports(files):
        if imp.type_checking:
            continue
        a, b = stage_of(imp.module), stage_of(imp.target)
        if a is None or b is None or a[1] == b[1] or b[0] < a[0]:
            continue
        where = "the same layer" if a[0] == b[0] else "a higher layer"
        bad.append(f"{imp.where}: {imp.module} ({a[1]}, layer {LAYERS[a[0]][0]}) imports "
                   f"{imp.target} ({b[1]}, {where}: {LAYERS[b[0]][0]})")
    return sorted(set(bad))


def defined_names(tree: ast.Module) -> set[str]:
    """The names a module binds at module level by ``def``, ``class`` or assignment (also
    inside module-level ``if``/``try``/``for``/``with``), not by an import."""
    out: set[str] = set()

    def bind(target: ast.AST) -> None:
        out.update(n.id for n in ast.walk(target) if isinstance(n, ast.Name))

    def visit(body: list[ast.stmt]) -> None:
        for s in body:
            if isinstance(s, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
                out.add(s.name)
            elif isinstance(s, ast.Assign):
                for t in s.targets:
                    bind(t)
            elif isinstance(s, ast.AnnAssign | ast.AugAssign):
                bind(s.target)
            elif isinstance(s, ast.For | ast.AsyncFor):
                bind(s.target)
                visit(s.body + s.orelse)
            elif isinstance(s, ast.With | ast.AsyncWith):
                for item in s.items:
                    if item.optional_vars is not None:
                        bind(item.optional_vars)
                visit(s.body)
            elif isinstance(s, ast.If):
                visit(s.body + s.orelse)
            elif isinstance(s, ast.Try):
                visit(s.body + s.orelse + s.finalbody + [x for h in s.handlers for x in h.body])

    visit(tree.body)
    return out


def reexport_violations(files: dict[str, Path] | None = None) -> list[str]:
    """Names taken from a robobore module that does not define them (``from robobore.a import
    name``, ``a.name`` on a module bound by an import), robobore names a module imports at
    module level without using them and names its ``__all__`` lists without defining them (a
    re-export), outside :data:`PUBLIC_HUBS`; each naming ``file:line``."""
    files = files if files is not None else module_files()
    trees = {m: ast.parse(p.read_text(encoding="utf-8"), filename=str(p))
             for m, p in files.items()}
    defs = {m: defined_names(t) for m, t in trees.items()}
    bad = []
    for mod, tree in trees.items():
        rel = _rel(files[mod])
        bound: dict[str, str] = {}  # local name -> robobore module it is bound to
        top_names: dict[str, tuple[int, str]] = {}  # name imported at module level -> (line, from)
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                for a in node.names:
                    if a.name.split(".")[0] == ROOT_PACKAGE:
                        bound[a.asname or ROOT_PACKAGE] = a.name if a.asname else ROOT_PACKAGE
            elif isinstance(node, ast.ImportFrom):
                base = _resolve_from(mod, node, files)
                if base.split(".")[0] != ROOT_PACKAGE or base not in files:
                    continue
                for a in node.names:
                    if f"{base}.{a.name}" in files:
                        bound[a.asname or a.name] = f"{base}.{a.name}"
                        continue
                    if a.name not in defs[base]:
                        bad.append(f"{rel}:{node.lineno}: {mod} imports {a.name} from {base}, "
                                   "which does not define it")
                    if node in tree.body:
                        top_names[a.asname or a.name] = (node.lineno, base)
        used = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute):
                target = _dotted(node.value, bound)
                if (target is not None and target in files and target != mod
                        and f"{target}.{node.attr}" not in files
                        and node.attr not in defs[target]):
                    bad.append(f"{rel}:{node.lineno}: {mod} uses {target}.{node.attr}, "
                               "which that module does not define")
        if mod not in PUBLIC_HUBS:
            for node in tree.body:
                if (isinstance(node, ast.Assign) and len(node.targets) == 1
                        and getattr(node.targets[0], "id", None) == "__all__"):
                    for elt in getattr(node.value, "elts", []):
                        name = getattr(elt, "value", None)
                        if isinstance(name, str) and name not in defs[mod] and (
                                f"{mod}.{name}" not in files):
                            bad.append(f"{rel}:{node.lineno}: {mod} lists {name} in __all__ "
                                       "without defining it")
            for name, (line, base) in sorted(top_names.items()):
                if name not in used:
                    bad.append(f"{rel}:{line}: {mod} imports {name} from {base} without using "
                               "it (a re-export)")
    return sorted(set(bad))


def lazy_export_violations(files: dict[str, Path] | None = None) -> list[str]:
    """Entries of a package's ``_EXPORTS`` table (name -> submodule, read by its
    ``__getattr__``) whose submodule does not define the name."""
    files = files if files is not None else module_files()
    bad = []
    for mod, path in files.items():
        if path.name != "__init__.py":
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        for node in tree.body:
            if (isinstance(node, ast.Assign) and len(node.targets) == 1
                    and getattr(node.targets[0], "id", None) == "_EXPORTS"
                    and isinstance(node.value, ast.Dict)):
                for k, v in zip(node.value.keys, node.value.values, strict=True):
                    name, sub = getattr(k, "value", None), f"{mod}.{getattr(v, 'value', '')}"
                    if sub not in files:
                        bad.append(f"{_rel(path)}:{k.lineno}: {mod}._EXPORTS[{name!r}] names "
                                   f"{sub}, no module of the package")
                        continue
                    sub_tree = ast.parse(files[sub].read_text(encoding="utf-8"))
                    if name not in defined_names(sub_tree):
                        bad.append(f"{_rel(path)}:{k.lineno}: {mod}._EXPORTS[{name!r}] names "
                                   f"{sub}, which does not define it")
    return bad


def module_sizes(files: dict[str, Path] | None = None) -> dict[str, int]:
    files = files if files is not None else module_files()
    return {m: len(p.read_text(encoding="utf-8").splitlines()) for m, p in files.items()}


# -- the tests ------------------------------------------------------------------------------

def test_only_cli_modules_import_the_cli_layer():
    bad = cli_layer_violations()
    assert not bad, "library code must take a progress callback, not import the CLI:\n" + \
        "\n".join(bad)


def test_no_private_name_used_across_modules():
    bad = private_name_violations()
    assert not bad, "another module's private name used (make it public or move it):\n" + \
        "\n".join(bad)


def test_no_import_cycle():
    """Neither through module-level imports nor through imports inside functions (a cycle
    hidden in a function is still two modules that need each other)."""
    bad = cycle_violations(function_level=True)
    assert not bad, "import cycles:\n" + "\n".join(bad)


def test_layer_order():
    """Each module imports only its own stage and lower layers (errors and io: no stage)."""
    bad = layer_violations()
    assert not bad, "imports against the layer order (LAYERS, docs/ARCHITECTURE.md):\n" + \
        "\n".join(bad)


def test_the_layer_table_is_the_one_the_architecture_draws():
    """docs/ARCHITECTURE.md's "Layers" table lists the stages of :data:`LAYERS` layer by
    layer, lowest first."""
    doc = (SRC.parent / "docs" / "ARCHITECTURE.md").read_text(encoding="utf-8")
    section = doc.split("## Layers", 1)[1].split("\n## ", 1)[0]
    rows = [line for line in section.splitlines() if line.startswith("| ") and "---" not in line]
    drawn = [tuple(s.strip(" `") for s in row.split("|")[2].split(",")) for row in rows[1:]]
    assert drawn == [tuple(name for name, _p in stages) for _layer, stages in LAYERS]


def test_the_layer_check_sees_a_planted_upward_import(tmp_path):
    """io importing a stage, a stage importing a higher one (in a function too), two stages of
    one layer importing each other and a package in no stage are each reported; a downward
    import, an import of the own stage, a ``TYPE_CHECKING`` import and a stage's CLI importing
    a higher stage are not."""
    pkg = tmp_path / ROOT_PACKAGE
    for sub in ("io", "robot", "material", "dynamics", "plan", "newstage"):
        (pkg / sub).mkdir(parents=True)
        (pkg / sub / "__init__.py").write_text("")
    (pkg / "__init__.py").write_text("")
    (pkg / "errors.py").write_text("")
    (pkg / "io" / "memory.py").write_text("from robobore.errors import x\n"
                                          "from robobore.robot import kin\n")
    (pkg / "robot" / "kin.py").write_text(
        "import robobore.io.memory\nfrom robobore.robot import other\n"
        "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    import robobore.plan.p\n\n\n"
        "def f():\n    from robobore.dynamics import d\n    import robobore.material.jc\n")
    (pkg / "robot" / "other.py").write_text("")
    (pkg / "robot" / "cli.py").write_text("import robobore.plan.p\n")
    (pkg / "material" / "jc.py").write_text("")
    (pkg / "dynamics" / "d.py").write_text("import robobore.robot.kin\n")
    (pkg / "plan" / "p.py").write_text("import robobore.dynamics.d\n")
    (pkg / "newstage" / "n.py").write_text("")
    bad = layer_violations(module_files(tmp_path))
    assert len(bad) == 5, bad
    text = "\n".join(bad)
    assert "io/memory.py:2: robobore.io.memory (io, layer foundation) imports robobore.robot.kin" \
        in text
    assert "robot/kin.py:9: robobore.robot.kin (robot, layer models) imports " \
        "robobore.dynamics.d (dynamics, a higher layer: process)" in text
    assert "robot/kin.py:10:" in text and "the same layer" in text
    assert sum("robobore.newstage" in b and "no stage" in b for b in bad) == 2
    assert "robot/cli.py" not in text and "plan/p.py" not in text and "kin.py:5" not in text


def test_the_scanners_see_a_planted_violation(tmp_path):
    """Each scanner finds the violation planted in a small fake package."""
    pkg = tmp_path / ROOT_PACKAGE
    (pkg / "a").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "cli.py").write_text("import robobore.a.x\n")
    (pkg / "clitools.py").write_text("def progress_bar(): pass\n")
    (pkg / "a" / "__init__.py").write_text("")
    (pkg / "a" / "x.py").write_text(
        "from robobore.a.y import _hidden\nfrom robobore.a import y\n\n\n"
        "def f():\n    from robobore.clitools import progress_bar\n    return y._other\n")
    (pkg / "a" / "y.py").write_text("import robobore.a.x\n_hidden = _other = 1\n")
    files = module_files(tmp_path)
    cli_bad = cli_layer_violations(files)
    assert len(cli_bad) == 1 and "a/x.py:6" in cli_bad[0] and "robobore.clitools" in cli_bad[0]
    priv = private_name_violations(files)
    assert len(priv) == 2 and "a/x.py:1" in priv[0] and "a/x.py:7" in priv[1]
    cyc = cycle_violations(files)
    assert len(cyc) == 1 and "a/x.py:1" in cyc[0] and "a/y.py:1" in cyc[0]


def test_no_reexport_hub():
    """Every importer takes a name from the module that defines it; no module passes on
    names it imports (:data:`PUBLIC_HUBS` aside)."""
    bad = reexport_violations() + lazy_export_violations()
    assert not bad, "import each name from the module that defines it (no re-export hubs):\n" \
        + "\n".join(bad)


def test_the_reexport_check_sees_a_planted_reexport(tmp_path):
    """A name imported from a module that only imports it (from-import and attribute) and the
    unused import that passes it on are reported; a name from its defining module, a name a
    module imports and uses, and a public hub's gathered names are not."""
    pkg = tmp_path / ROOT_PACKAGE
    (pkg / "a").mkdir(parents=True)
    (pkg / "material").mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "material" / "__init__.py").write_text("from robobore.material.lib import M\n")
    (pkg / "material" / "lib.py").write_text("class M:\n    pass\n")
    (pkg / "a" / "__init__.py").write_text("")
    (pkg / "a" / "core.py").write_text("def f():\n    pass\n\n\nX = 1\n")
    (pkg / "a" / "hub.py").write_text("from robobore.a.core import X, f\n\n\n"
                                      "def g():\n    return f()\n")
    (pkg / "a" / "user.py").write_text("from robobore.a import hub\nfrom robobore.a.core import f\n"
                                       "from robobore.a.hub import X, g\n"
                                       "from robobore.material.lib import M\n\n"
                                       "Y = hub.f, X, f, g, M\n")
    bad = reexport_violations(module_files(tmp_path))
    assert len(bad) == 3, bad
    text = "\n".join(bad)
    assert "a/hub.py:1: robobore.a.hub imports X from robobore.a.core without using it" in text
    assert "a/user.py:3: robobore.a.user imports X from robobore.a.hub, which does not define " \
        "it" in text
    assert "a/user.py:6: robobore.a.user uses robobore.a.hub.f, which that module does not " \
        "define" in text
    assert "material" not in text
    (pkg / "a" / "__init__.py").write_text('_EXPORTS = {"f": "core", "X": "hub", "Z": "gone"}\n')
    lazy = lazy_export_violations(module_files(tmp_path))
    assert len(lazy) == 2, lazy
    assert lazy[0].endswith("robobore/a/__init__.py:1: robobore.a._EXPORTS['X'] names "
                            "robobore.a.hub, which does not define it")
    assert lazy[1].endswith("robobore/a/__init__.py:1: robobore.a._EXPORTS['Z'] names "
                            "robobore.a.gone, no module of the package")


def _exempt_text() -> str:
    return ", ".join(EXEMPT) if EXEMPT else "the exempt packages (none)"


def main() -> None:
    files = module_files()
    n_cli = cli_layer_violations(files)
    priv_all = private_name_violations(files, exempt=False)
    priv = private_name_violations(files)
    print(f"modules: {len(files)}")
    print(f"CLI-layer imports by library modules: {len(n_cli)}")
    for b in n_cli:
        print("  " + b)
    print(f"private names used across modules: {len(priv_all)} in all, {len(priv)} outside "
          f"{_exempt_text()}")
    for b in priv_all:
        print("  " + b)
    for fl in (False, True):
        g = import_graph(files, function_level=fl)
        cyc = cycles(g)
        out = [c for c in cyc if not all(_exempt(m) for m in c)]
        print(f"import cycles ({'module + function level' if fl else 'module level'}): "
              f"{len(cyc)} strongly connected groups ({sum(map(len, cyc))} modules), "
              f"{len(out)} outside {_exempt_text()}")
        for c in cyc:
            print("  " + cycle_report(g, c).replace("\n", "\n  "))
    lay = layer_violations(files)
    print(f"imports against the layer order: {len(lay)}")
    for b in lay:
        print("  " + b)
    rex = reexport_violations(files) + lazy_export_violations(files)
    print(f"re-exports (names taken from a module that does not define them, imports passed "
          f"on unused): {len(rex)}")
    for b in rex:
        print("  " + b)
    sizes = module_sizes(files)
    big = sorted(((n, m) for m, n in sizes.items() if n > 600), reverse=True)
    print(f"modules over 600 lines: {len(big)}")
    for n, m in big:
        print(f"  {n:5d} {m}")


if __name__ == "__main__":
    main()
