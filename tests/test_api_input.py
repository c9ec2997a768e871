"""The one-step API on bad matrices and arguments: a one-line rollqp error naming the argument,
never a solver's own exception, a C-level message on the console, or a NaN result."""
from __future__ import annotations

import numpy as np
import pytest

import rollqp
from rollqp.errors import RollqpError

N = 5
F, H = np.ones(N), np.linspace(0.0, 1.0, N) ** 2

BAD = {
    "indefinite": -np.eye(N),
    "zero": np.zeros((N, N)),
    "singular": np.ones((N, N)),
}


@pytest.mark.parametrize("method", ["qp-osqp", "qp-clarabel", "qp-cvxpy", "newton"])
@pytest.mark.parametrize("name", list(BAD))
def test_bad_matrices_are_rollqp_errors(name, method, capfd):
    pb = rollqp.NormalStep(A=BAD[name], f=F, h=H, P=1.0)
    with pytest.raises(RollqpError) as info:
        rollqp.solve_step(pb, method)
    out = capfd.readouterr()
    assert out.out == "" and out.err == "", f"nothing printed by the solver: {out}"
    msg = str(info.value)
    if method.startswith("qp-"):
        assert msg.startswith("A: the QP methods need sym(F·A) positive definite"), msg


def test_nonsymmetric_but_definite_is_solved_by_every_method():
    """F·A not symmetric but its symmetric part definite: the QP backends' splitting and Newton agree."""
    A = np.triu(np.ones((N, N))) + np.eye(N)
    pb = rollqp.NormalStep(A=A, f=F, h=H, P=1.0)
    ref = rollqp.solve_step(pb, "newton")
    for m in ("qp-osqp", "qp-clarabel", "qp-cvxpy"):
        sol = rollqp.solve_step(pb, m)
        # both stop at rollqp's residual 1e-10; the splitting contracts to the QP's accuracy (1e-8 limit)
        assert np.max(np.abs(sol.p - ref.p)) <= 1e-8 and sol.residual <= 1e-8, m


@pytest.mark.parametrize("kw, key", [
    (dict(scales=None), "scales"),
    (dict(f=-F), "f"),
    (dict(A=np.full((N, N), np.nan)), "A"),
    (dict(A=np.eye(N + 1)), "A"),
    (dict(P=np.inf), "P"),
])
def test_bad_arguments_name_the_argument(kw, key):
    args = dict(A=np.eye(N), f=F, h=H, P=1.0)
    args.update(kw)
    with pytest.raises(rollqp.InputError) as info:
        rollqp.NormalStep(**args)
    assert info.value.key == key, str(info.value)


def test_unknown_method_options_are_named():
    with pytest.raises(rollqp.InputError, match="eps_abz: unrecognized setting for method 'qp-osqp'; did you mean 'eps_abs'"):
        rollqp.get_method("qp-osqp", eps_abz=1e-9)
    with pytest.raises(rollqp.InputError, match="newton"):
        rollqp.get_method("newton", tol=1e-9)
