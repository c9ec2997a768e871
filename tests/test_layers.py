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
