"""The architecture's rules, checked on the source tree (docs/architecture.md).

* Tests, examples and benchmarks use public names only: no ``rollqp`` module or attribute
  whose name starts with ``_`` is imported or reached into.
* No function in ``rollqp/`` is longer than 80 lines (one screen: a reader sees all of it).
* Method names are looked at only by the registry: the transient, the step files and the
  scenes never compare them; no method name, influence model name or ``isinstance(…, float)``
  friction test appears as code outside the registry or record that owns it.
* No cache in ``rollqp/`` is keyed on ``id()`` (set-up happens once per scene instead).
* No object is made or changed by writing its internals: no ``object.__new__``, no writes into an
  instance's ``__dict__`` (a step problem made without its checks is made by its constructor with
  ``trusted=True``; what is computed once is kept in a memo its owner holds).
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


def _code_strings(path: Path) -> list[tuple[int, str]]:
    """``(line, value)`` of the string constants of a module that are code, not docstrings."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docs = {id(n.body[0].value) for n in ast.walk(tree)
            if isinstance(n, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and n.body
            and isinstance(n.body[0], ast.Expr) and isinstance(n.body[0].value, ast.Constant)}
    return [(n.lineno, n.value) for n in ast.walk(tree)
            if isinstance(n, ast.Constant) and isinstance(n.value, str) and id(n) not in docs]


def _owned(names, owner: str) -> list[str]:
    """String constants equal to one of ``names`` in rollqp's code outside the package ``owner``."""
    return [f"{p.relative_to(ROOT)}:{line}: {value!r}" for p in _sources("rollqp")
            if not str(p.relative_to(PACKAGE)).startswith(owner) for line, value in _code_strings(p) if value in names]


def test_method_names_only_in_the_method_registry():
    from rollqp.methods import METHOD_NAMES
    hits = _owned(set(METHOD_NAMES), "methods")
    assert not hits, f"method names in code outside rollqp.methods: {hits}"


def test_model_names_only_in_the_influence_records():
    from rollqp.influence import model_names
    hits = _owned(set(model_names()), "influence")
    assert not hits, f"influence model names in code outside rollqp.influence: {hits}"


def test_no_float_test_of_friction_outside_the_friction_package():
    pattern = re.compile(r"isinstance\([^()]*(?:friction|\bmu\b|law)[^()]*,\s*\(?[^)]*\bfloat\b")
    hits = [f"{p.relative_to(ROOT)}:{i}: {line.strip()}" for p in _sources("rollqp")
            if not str(p.relative_to(PACKAGE)).startswith("friction")
            for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1) if pattern.search(line)]
    assert not hits, f"friction tested for a float outside rollqp.friction (ask the law's kind): {hits}"


def test_the_name_checks_find_what_they_look_for(tmp_path):
    """The checks above on a module that breaks each rule: they are not blind."""
    bad = tmp_path / "bad.py"
    bad.write_text('"""doc: \'newton\' in a docstring is prose."""\n'
                   'def f(scene, ops):\n'
                   '    if scene.solver.method == "newton" or scene.contact.model == "bem":\n'
                   '        return isinstance(ops.friction, float)\n', encoding="utf-8")
    assert [v for _, v in _code_strings(bad)] == ["newton", "bem"]
    assert re.search(r"isinstance\([^()]*(?:friction|\bmu\b|law)[^()]*,\s*\(?[^)]*\bfloat\b", bad.read_text())


def test_no_id_keyed_caches():
    hits = [f"{p.relative_to(ROOT)}:{i}: {line.strip()}" for p in _sources("rollqp")
            for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
            if re.search(r"\bid\(", line) and not line.lstrip().startswith("#")]
    assert not hits, f"id()-keyed lookups in rollqp/: {hits}"


INTERNALS = re.compile(r"object\.__new__\(|__dict__\s*\[[^\]]*\]\s*=|__dict__\.(?:update|pop|setdefault|clear)\(")


def test_no_writes_into_object_internals():
    hits = [f"{p.relative_to(ROOT)}:{i}: {line.strip()}" for p in _sources("rollqp")
            for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
            if INTERNALS.search(line) and not line.lstrip().startswith("#")]
    assert not hits, f"objects made or changed through their internals in rollqp/: {hits}"
    for line in ("obj = object.__new__(cls)", "pb.__dict__[\"bound\"] = b", "new.__dict__.update(old.__dict__)"):
        assert INTERNALS.search(line), line  # the check is not blind
    assert not INTERNALS.search("values = {**ref.__dict__}")  # reading is not writing


@pytest.mark.integration
def test_import_rollqp_loads_no_optional_or_heavy_module():
    """``import rollqp`` (and so ``rollqp --help``) loads neither scipy nor the BEM module nor
    any optional extra: each is imported when a scene or command first needs it (
    the import went from 0.56 s to ~0.25 s here). A fresh interpreter, so nothing is cached."""
    import subprocess
    import sys
    code = ("import sys, rollqp; heavy = ('scipy', 'rollqp.influence.bem', 'cvxpy', 'matplotlib', 'dask', "
            "'xarray', 'zarr'); print(','.join(m for m in heavy if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "", f"imported by `import rollqp`: {out.stdout.strip()}"


def test_the_method_table_declares_the_dimensions_of_every_class_it_imports_on_first_use():
    """The table names the classes that need scipy or a solver package by module, with their dimensions
    declared (``import rollqp`` then loads neither): each declaration must be the class's own record."""
    from rollqp.methods import available_methods, record
    checked = 0
    for dimension in (2, 3):
        for name in available_methods(dimension):
            rec = record(name, dimension)
            declared = getattr(rec.entry, "dimensions", None)   # None: a class held by the table itself
            if declared is not None:
                assert rec.cls.capabilities.dimensions == declared, (name, dimension, rec.entry)
                checked += 1
    assert checked >= 12, checked   # the core entries at least: the check is not blind
