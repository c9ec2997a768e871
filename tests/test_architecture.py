"""The architecture's rules, checked on the source tree (docs/architecture.md).

* Tests, examples and benchmarks use public names only: no ``rollqp`` module or attribute
  whose name starts with ``_`` is imported or reached into.
* No function in ``rollqp/`` is longer than 80 lines (one screen: a reader sees all of it).
* Method names are looked at only by the registry: the transient, the step files and the
  scenes never compare them.
* No cache in ``rollqp/`` is keyed on ``id()`` (set-up happens once per scene instead).
"""
from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "rollqp"
MAX_LINES = 80


def _sources(*folders):
    for folder in folders:
        yield from sorted((ROOT / folder).rglob("*.py"))


def _private_uses(path: Path) -> list[str]:
    """``from rollqp.x import _y``, ``import rollqp._x``, ``rollqp.x._y`` attribute chains."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found = []
    bound = {"rollqp"}  # names bound to rollqp modules or objects by the file's imports
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] == "rollqp":
            bound |= {a.asname or a.name for a in node.names}
        elif isinstance(node, ast.Import):
            bound |= {(a.asname or a.name).split(".")[0] for a in node.names if a.name.split(".")[0] == "rollqp"}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] == "rollqp":
            parts = node.module.split(".") + [a.name for a in node.names]
            found += [f"line {node.lineno}: from {node.module} import {a.name}" for a in node.names
                      if any(p.startswith("_") and not p.startswith("__") for p in parts)]
        elif isinstance(node, ast.Import):
            found += [f"line {node.lineno}: import {a.name}" for a in node.names
                      if a.name.split(".")[0] == "rollqp"
                      and any(p.startswith("_") for p in a.name.split("."))]
        elif isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__"):
            chain, base = [node.attr], node.value
            while isinstance(base, ast.Attribute):
                chain.append(base.attr)
                base = base.value
            if isinstance(base, ast.Name) and base.id in bound:
                found.append(f"line {node.lineno}: {base.id}.{'.'.join(reversed(chain))}")
    return found


@pytest.mark.parametrize("folder", ["tests", "examples", "benchmarks"])
def test_public_names_only(folder):
    bad = {str(p.relative_to(ROOT)): u for p in _sources(folder) if (u := _private_uses(p))}
    assert not bad, f"private rollqp names used in {folder}/: {bad}"


def test_functions_fit_one_screen():
    long = []
    for path in _sources("rollqp"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > MAX_LINES:
                    long.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.name} ({n} lines)")
    assert not long, f"functions longer than {MAX_LINES} lines: {long}"


@pytest.mark.parametrize("module", ["march.py", "stepfile.py", "crossval.py", "operators.py", "scene"])
def test_method_names_only_in_the_registry(module):
    pattern = re.compile(r"QP_METHODS|DIRECT_STEADY|[\"']nt-newton[\"']|[\"']qp-[a-z]+[\"']\s*(?:in|==)|"
                         r"(?:==|!=|in)\s*\(?[\"'](?:newton|nt-newton|qp-[a-z]+)[\"']")
    paths = [PACKAGE / module] if module.endswith(".py") else sorted((PACKAGE / module).rglob("*.py"))
    hits = [f"{p.relative_to(ROOT)}:{i}: {line.strip()}" for p in paths if p.exists()
            for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1) if pattern.search(line)]
    assert not hits, f"method names compared outside the registry: {hits}"


def test_no_id_keyed_caches():
    hits = [f"{p.relative_to(ROOT)}:{i}: {line.strip()}" for p in _sources("rollqp")
            for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
            if re.search(r"\bid\(", line) and not line.lstrip().startswith("#")]
    assert not hits, f"id()-keyed lookups in rollqp/: {hits}"


@pytest.mark.integration
def test_import_rollqp_loads_no_optional_or_heavy_module():
    """``import rollqp`` (and so ``rollqp --help``) loads neither scipy nor the BEM module nor
    any optional extra: each is imported when a scene or command first needs it (issue 18:
    the import went from 0.56 s to ~0.25 s here). A fresh interpreter, so nothing is cached."""
    import subprocess
    import sys
    code = ("import sys, rollqp; heavy = ('scipy', 'rollqp.influence.bem', 'cvxpy', 'matplotlib', 'dask', "
            "'xarray', 'zarr'); print(','.join(m for m in heavy if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "", f"imported by `import rollqp`: {out.stdout.strip()}"
