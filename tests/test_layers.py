"""rollqp's layers, checked on the source tree (docs/architecture.md, "Layers").

* The import-layer contract of ``pyproject.toml`` (``[tool.importlinter]``) holds: ``lint-imports``
  (import-linter, a test dependency) finds every import — at the top of a module or inside a
  function — and fails on one that runs from a layer to a higher one.
* The contract can fail: the same check on a copy of the package with one import added from the
  base layer to the march reports it broken (a contract that cannot fail checks nothing).
* No import cycle between rollqp's modules (read from the source with :mod:`ast`, imports inside
  functions included, ``if TYPE_CHECKING:`` blocks excluded): every module can be read, tested and
  replaced after the ones it imports.
"""
from __future__ import annotations

import ast
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "rollqp"


def _lint(root: Path) -> subprocess.CompletedProcess:
    """``lint-imports`` on the package under ``root`` with the contract of this checkout's pyproject.toml."""
    pytest.importorskip("importlinter", reason="import-linter is in the test extra: pip install -e '.[test]'")
    code = ("import sys; from importlinter.cli import lint_imports_command; "
            "sys.exit(lint_imports_command(['--no-cache', '--no-logo', sys.argv[1]]))")
    return subprocess.run([sys.executable, "-c", code, str(ROOT / "pyproject.toml")], cwd=root,
                          capture_output=True, text=True, timeout=300, env={**os.environ, "PYTHONPATH": str(root)})


def test_the_layer_contract_holds():
    out = _lint(ROOT)
    assert out.returncode == 0, f"the import-layer contract is broken:\n{out.stdout[-3000:]}{out.stderr[-2000:]}"
    assert "1 kept, 0 broken" in out.stdout, out.stdout[-2000:]


def test_the_layer_contract_fails_on_an_upward_import(tmp_path):
    """A deliberate violation: the strip (base layer) importing the march (three floors up)."""
    copy = tmp_path / "rollqp"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    strip = copy / "strip.py"
    strip.write_text(strip.read_text(encoding="utf-8") + "\n\ndef _upward():\n    from .march import run\n    return run\n",
                     encoding="utf-8")
    out = _lint(tmp_path)
    assert out.returncode != 0, out.stdout[-2000:]
    assert "rollqp.strip is not allowed to import rollqp.march" in out.stdout, out.stdout[-3000:]


def _modules() -> dict[str, Path]:
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(ROOT).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def _imports(name: str, path: Path, modules: dict) -> set[str]:
    """The rollqp modules ``name`` imports (anywhere but under ``if TYPE_CHECKING:``)."""
    found = set()

    def target(node):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
                base = base[:len(base) - (node.level - 1)]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            return [f"{mod}.{a.name}" if f"{mod}.{a.name}" in modules else mod for a in node.names]
        return [a.name for a in node.names]

    def visit(node):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and "TYPE_CHECKING" in ast.unparse(child.test):
                continue
            if isinstance(child, (ast.Import, ast.ImportFrom)):
                for t in target(child):
                    while t not in modules and "." in t:
                        t = t.rsplit(".", 1)[0]
                    if t in modules and t != name and t.startswith("rollqp"):
                        found.add(t)
            visit(child)

    visit(ast.parse(path.read_text(encoding="utf-8")))
    return found


def _cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan's algorithm)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def connect(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges[v]:
            if w not in index:
                connect(w)
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

    for v in edges:
        if v not in index:
            connect(v)
    return out


def test_no_import_cycle():
    modules = _modules()
    edges = {name: _imports(name, path, modules) for name, path in modules.items()}
    # the package itself (rollqp/__init__.py) re-exports the public names of every layer: it is the
    # top of the graph, and no module of rollqp may import it (that would close a cycle through it)
    assert not [m for m, e in edges.items() if "rollqp" in e and m != "rollqp"], "modules importing rollqp itself"
    assert _cycles(edges) == []


def test_the_cycle_check_finds_a_cycle():
    """The same check on a small graph with a cycle and a self-contained part."""
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []


def _units():
    """The contract's floors (lists of its entries) and each module's entry (the longest that holds it)."""
    import tomllib
    layers = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"][0]["layers"]
    floors = [[e.strip() for e in floor.replace("|", ":").split(":")] for floor in layers]
    entries = sorted((e for f in floors for e in f), key=len, reverse=True)

    def unit(module):
        rest = module[len("rollqp."):]
        return next((e for e in entries if rest == e or rest.startswith(e + ".")), None)
    return floors, unit


def test_no_sibling_on_a_floor_hides_a_mutual_import():
    """``:`` lets the modules of one floor import each other; none does both ways (a loop between two
    packages would hide behind the floor), and every rollqp module sits on a floor."""
    modules = _modules()
    floors, unit = _units()
    arrows = set()
    for name, path in modules.items():
        for target in _imports(name, path, modules):
            a, b = unit(name), unit(target)
            if a is not None and b is not None and a != b:
                arrows.add((a, b))
    mutual = [(a, b) for f in floors for i, a in enumerate(f) for b in f[i + 1:] if (a, b) in arrows and (b, a) in arrows]
    assert mutual == [], f"siblings importing each other: {mutual}"
    entries = [e for f in floors for e in f]
    containers = {m for m in modules if any(e.startswith(m[len("rollqp."):] + ".") for e in entries)}  # rollqp.three
    unplaced = sorted({m for m in modules if m != "rollqp" and m not in containers and unit(m) is None})
    assert unplaced == [], f"modules on no floor of the contract: {unplaced}"


def test_at_most_two_arrows_back_up():
    """The contract's ignored imports are the only arrows running up a floor: at most two, each named."""
    import tomllib
    contract = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"][0]
    assert len(contract.get("ignore_imports", [])) <= 2


# ----------------------------------------------------------------------------- imports inside functions
#: At most this many imports of rollqp's own modules inside functions. rollqp's modules import each other at their
#: top (a module's dependencies are read in one place, and the cycle and layer checks above see the real graph);
#: an import inside a function is left only where an optional or heavy dependency stands behind the imported module
#: (xarray for rollqp.open_result, scipy.sparse and clarabel for a step file's Clarabel JSON, scipy for the grid's
#: chord start and the BEM: ``import rollqp`` and the start of ``rollqp run`` load none of them,
#: tests/test_architecture.py) or where a real cycle cannot be broken (the wheel-rail scene, built on
#: the scene package, read by it: the contract's one arrow back up). 20 leaves room for a few such cases; each one
#: says why in a comment on its line or the line above (checked below).
MAX_INNER_IMPORTS = 20


def _inner_imports(root: Path = PACKAGE) -> list[tuple[str, int, str]]:
    """``(file, line, statement)`` of each import of rollqp's own modules inside a function, counted as
    ``count_inner_imports.py`` counts them: every ``import``/``from … import`` under a ``def`` whose module is
    relative or starts with ``rollqp`` (a function nested in another is walked once per enclosing function, as
    there)."""
    found = []
    for path in sorted(root.rglob("*.py")):
        source = path.read_text(encoding="utf-8")
        for node in ast.walk(ast.parse(source)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                for sub in ast.walk(node):
                    own = (isinstance(sub, ast.ImportFrom) and (sub.level > 0 or (sub.module or "").startswith("rollqp"))
                           or isinstance(sub, ast.Import) and any(a.name.startswith("rollqp") for a in sub.names))
                    if own:
                        found.append((str(path.relative_to(root.parent)), sub.lineno, ast.get_source_segment(source, sub)))
    return found


def test_at_most_twenty_imports_of_rollqp_inside_functions():
    inner = _inner_imports()
    listing = "\n".join(f"  {f}:{line}: {text}" for f, line, text in inner)
    assert len(inner) <= MAX_INNER_IMPORTS, f"{len(inner)} imports of rollqp's modules inside functions:\n{listing}"


def test_each_import_inside_a_function_says_why():
    """The reason of each import left inside a function: a comment on its line or on the line above."""
    silent = []
    for f, line, text in _inner_imports():
        lines = (PACKAGE.parent / f).read_text(encoding="utf-8").splitlines()
        if "#" not in lines[line - 1] and "#" not in lines[line - 2]:
            silent.append(f"{f}:{line}: {text}")
    assert silent == [], "imports inside functions without their reason:\n" + "\n".join(silent)


def test_the_inner_import_count_can_fail(tmp_path):
    """The count on a small package: a module-top import is not counted, a function's (nested ones too) is."""
    pkg = tmp_path / "rollqp"
    pkg.mkdir()
    (pkg / "a.py").write_text("from . import b\nimport numpy\n\ndef f():\n    from .b import x  # why\n    import rollqp.b\n"
                              "    def g():\n        from rollqp import c\n    import numpy\n", encoding="utf-8")
    found = [(f, line) for f, line, _ in _inner_imports(pkg)]
    assert sorted(found) == [("rollqp/a.py", 5), ("rollqp/a.py", 6), ("rollqp/a.py", 8), ("rollqp/a.py", 8)]
