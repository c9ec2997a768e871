"""The ``Examples`` of rollqp's docstrings are run (scipy's style: every ``>>>`` line is a test).

Every module of ``rollqp/`` whose source holds a ``>>>`` example is run by :mod:`doctest` (``ELLIPSIS``
for the tails of long messages, ``NORMALIZE_WHITESPACE`` for wrapped output); a module that holds
examples must run at least one, and none may fail.
"""
from __future__ import annotations

import doctest
import importlib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _modules_with_examples() -> list[str]:
    out = []
    for path in sorted((ROOT / "rollqp").rglob("*.py")):
        if ">>> " in path.read_text(encoding="utf-8"):
            parts = list(path.relative_to(ROOT).with_suffix("").parts)
            out.append(".".join(parts[:-1] if parts[-1] == "__init__" else parts))
    return out


MODULES = _modules_with_examples()


def test_the_public_api_has_examples():
    assert len(MODULES) >= 10, MODULES


@pytest.mark.parametrize("name", MODULES)
def test_examples(name):
    module = importlib.import_module(name)
    flags = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
    result = doctest.testmod(module, optionflags=flags, verbose=False, report=True)
    assert result.attempted > 0, f"{name}: its examples were not found by doctest"
    assert result.failed == 0, f"{name}: {result.failed} of {result.attempted} examples failed (see the output above)"
