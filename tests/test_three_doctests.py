"""The ``Examples`` of rollqp.three's public docstrings run as written."""
from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = ["grid", "materials", "influence", "operator", "operators", "geometry", "hertz", "closedforms", "gnm",
           "contact", "loads"]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    module = importlib.import_module(f"rollqp.three.{name}")
    result = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0 and result.attempted > 0, f"rollqp.three.{name}: {result}"
