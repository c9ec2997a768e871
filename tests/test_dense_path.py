"""The dense path's shortcuts give the answers of the plain products (correctness, never timing; issue 18).

* :class:`rollqp.strip.RowSparse` (the history operators, at most three non-zeros a row) holds the
  dense operator's values and multiplies like it;
* :func:`rollqp.methods.newton.linear.partial_product` is ``(K @ v)[rows]``, by blocks or by the
  dense fallback;
* Newton with the partial products and the carried ``y`` (``n >= PARTIAL_MIN``) reaches the
  tractions of the plain dense products, step by step over a transient;
* the march's ``w`` reuses the solution's product ``A_tt t`` and equals ``A_tt t``;
* the elastic energy read from the state's gap and ``w`` equals the quadratic form.
"""
from __future__ import annotations

import numpy as np
import pytest

import rollqp
from rollqp.energy import elastic_energy
from rollqp.march import prepare
from rollqp.methods.newton import linear
from rollqp.strip import RowSparse, Strip

# Tolerances, each with its reason.
TOL = {
    # a sum of at most three products in another order: a few ulps of the largest term
    "rowsparse": 1e-15,
    # blocks of a product summed in another order: round-off of n terms, relative to ‖K‖‖v‖
    "product": 1e-13,
    # two transients whose products differ by round-off: the step problem's conditioning turns
    # an ulp of its data into ~1e-12 of μp0 (measured 6.6e-13 on 81 nodes for a 1-ulp change
    # of the load, on the plain path alone), carried by the history vector over the steps
    "transient": 1e-10,
    # U from g − h + δ instead of A p: round-off of the gap's terms (h, δ ~ u0) against U
    "energy": 1e-12,
}


@pytest.mark.parametrize("element", ["constant", "linear", "quadratic"])
@pytest.mark.parametrize("formulation", ["material", "convective-local", "static"])
def test_rowsparse_history_is_the_dense_operator(element, formulation):
    s = Strip(1.25, 24, element)
    for d in (-1, 1):
        M = s.history_operator(formulation, 0.3 * s.element_length, d)
        R = RowSparse.from_dense(M)
        assert R.cols.shape[1] <= 3
        assert np.array_equal(R.dense(), M)
        w = np.random.default_rng(1).standard_normal((s.n, 2))
        ref = M @ w
        scale = np.max(np.abs(M)) * np.max(np.abs(w)) * 3
        assert np.max(np.abs(R @ w[:, 0] - ref[:, 0])) <= TOL["rowsparse"] * scale
        assert np.max(np.abs(R @ w - ref)) <= TOL["rowsparse"] * scale


def test_scene_history_is_row_sparse(builtin_scene):
    scene = builtin_scene("cattaneo-carter")
    ops = rollqp.operators.SceneOperators.build(scene)
    M = ops.history()
    assert isinstance(M, RowSparse)
    assert np.array_equal(np.asarray(M), ops.strip.history_operator(
        scene.discretization.formulation, scene.dq, scene.load.direction))


@pytest.mark.parametrize("pattern", ["runs", "scattered", "empty"])
def test_partial_product_is_the_product(pattern):
    rng = np.random.default_rng(2)
    n = 400
    K = rng.standard_normal((n, n + 1))
    v = np.zeros(n + 1)
    if pattern == "runs":  # the node sets of a contact step: a few runs, and the load column
        cols = np.r_[40:180, 260:300, n]
        rows = np.r_[0:30, 100:220, 390:400]
    elif pattern == "scattered":  # more blocks than MAX_BLOCKS: the dense fallback
        cols = np.sort(rng.choice(n + 1, 150, replace=False))
        rows = np.sort(rng.choice(n, 120, replace=False))
    else:
        cols, rows = np.empty(0, dtype=int), np.arange(10)
    v[cols] = rng.standard_normal(cols.size)
    got = linear.partial_product(K, rows, v, cols)
    ref = (K @ v)[rows]
    assert got.shape == ref.shape
    assert np.max(np.abs(got - ref), initial=0.0) <= TOL["product"] * np.abs(K).max() * np.abs(v).sum()


def test_runs_bridge_small_gaps():
    assert linear.runs(np.array([1, 2, 3, 7, 8, 100]), gap=4) == [(1, 9), (100, 101)]
    assert linear.runs(np.array([], dtype=int)) == []


def test_partial_newton_reaches_the_plain_tractions(builtin_scene, monkeypatch):
    """321 nodes over the Carter transient: partial products and carried y against plain dense products."""
    scene = builtin_scene("cattaneo-carter", **{"discretization.elements": 160, "discretization.distance": 1.5})
    fast = rollqp.run(scene, method="newton").arrays()
    monkeypatch.setattr(linear, "PARTIAL_MIN", 10 ** 9)  # every ReducedSystem built after this: plain products
    plain = rollqp.run(scene, method="newton").arrays()
    mu_p0 = scene.contact.friction * scene.p0
    assert np.max(np.abs(fast["pt"] - plain["pt"])) <= TOL["transient"] * mu_p0
    assert np.max(np.abs(fast["pn"] - plain["pn"])) <= TOL["transient"] * scene.p0
    assert np.array_equal(fast["iterations"], plain["iterations"])
    assert fast["residual"].max() <= scene.solver.tolerance


@pytest.mark.parametrize("name", ["cattaneo-carter", "goodman-bentall"])
def test_march_w_and_energy_from_the_state(builtin_scene, name):
    scene = builtin_scene(name, **{"discretization.distance": 0.5})
    scene, meth, ops = prepare(scene, "newton")
    f = ops.f
    for rec in rollqp.march(scene, prepared=(scene, meth, ops)):
        st = rec.state
        assert np.max(np.abs(st.w - ops.w(st.p, st.t))) <= TOL["product"] * max(np.abs(st.w).max(), 1e-300)
        U = 0.5 * (f * st.p) @ (ops.Ann @ st.p) + 0.5 * (f * st.t) @ (ops.Att @ st.t)
        if ops.Ant is not None:
            U += (f * st.p) @ (ops.Ant @ st.t)
        assert abs(elastic_energy(rec, ops) - U) <= TOL["energy"] * abs(U)


def test_result_ignores_a_state_cut_short_by_an_interrupt(builtin_scene):
    """A signal between two fields of Result.append (Ctrl-C, SIGTERM: the partial file is then written)
    leaves some fields one state longer; the result holds the complete states only."""
    scene = builtin_scene("cattaneo-carter", **{"discretization.distance": 0.25})
    res = rollqp.run(scene, method="newton")
    K1 = len(res)
    first = next(iter(res.rows))
    res.rows[first].append(res.rows[first][-1])  # one field of state K1 appended, the others not
    assert len(res) == K1
    a = res.arrays()
    assert a["q"].shape == (K1,) and a[first].shape[0] == K1
