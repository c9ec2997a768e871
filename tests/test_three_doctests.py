"""The ``Examples`` of the three-dimensional modules' public docstrings run as written."""
from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = ["discretization", "discretization.grid", "materials", "influence.cerruti", "influence.blocktoeplitz", "influence.grid",
           "profiles.surface", "closedforms.hertz_ellipse", "closedforms.kalker", "methods.newton.disc", "operators.grid",
           "loads", "methods.newton.capacitance", "methods.newton.gmres"]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    module = importlib.import_module(f"rollqp.{name}")
    result = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0 and result.attempted > 0, f"rollqp.{name}: {result}"
