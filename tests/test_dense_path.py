"""The dense path's shortcuts give the answers of the plain products (correctness, never timing).

* :class:`rollqp.strip.RowSparse` (the history operators, at most three non-zeros a row) holds the
  dense operator's values and multiplies like it;
* :func:`rollqp.methods.newton.linear.partial_product` is ``(K @ v)[rows]``, by blocks or by the
  dense fallback;
* Newton with the partial products and the carried ``y`` (``n >= PARTIAL_MIN``) reaches the
  tractions of the plain dense products, step by step over a transient;
* the march's ``w`` reuses the solution's product ``A_tt t`` and equals ``A_tt t``;
* the elastic energy read from the state's gap and ``w`` equals the quadratic form;
* the small-``n`` path: the direction on kept factors (the block ``[K_FP; f̂_Pᵀ]``, a free set met
  again) solves the pseudo-Jacobian; the march's step problems (``validate=False``) are the
  validated ones and keep the sliding-limit check; the loads of the plan, evaluated once, are the
  loads at each step.
"""
from __future__ import annotations

import numpy as np
import pytest

import rollqp
from conftest import Delegate
from rollqp.energy import elastic_energy
from rollqp.march import prepare
from rollqp.methods.newton import linear
from rollqp.scene import builtin_scenes
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
    # the reduced system's LU against a dense solve of the whole pseudo-Jacobian: round-off times
    # the reduced matrix's condition (~1e3 on 81 nodes), relative to |d|
    "direction": 1e-11,
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


def test_rowsparse_vector_product_in_both_forms():
    """Up to RowSparse.DENSE_MAX entries a vector goes through the dense copy, beyond through the rows."""
    for elements in (24, 100):  # 49 and 201 quadratic nodes: either side of DENSE_MAX
        s = Strip(1.25, elements, "quadratic")
        M = s.history_operator("material", 0.3 * s.element_length, 1)
        assert (s.n * s.n <= RowSparse.DENSE_MAX) == (elements == 24)
        w = np.random.default_rng(3).standard_normal(s.n)
        got = RowSparse.from_dense(M) @ w
        assert np.max(np.abs(got - M @ w)) <= TOL["rowsparse"] * np.max(np.abs(M)) * np.max(np.abs(w)) * 3


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


def _rolling_step(builtin_scene, k=100):
    """A rolling step of §6.1.1 (81 nodes) with newton set up on it, and the record that solved it."""
    scene, meth, ops = prepare(builtin_scene("cattaneo-carter"), "newton")
    for rec in rollqp.march(scene, prepared=(scene, meth, ops)):
        if rec.k == k:
            return scene, meth, ops, rec
    raise AssertionError("the march ended early")


def test_direction_on_kept_factors_solves_the_jacobian(builtin_scene):
    """The direction of a free set (factored, then found again among the kept factors, after another set)
    solves J d = −Φ of the whole pseudo-Jacobian (eq. 80), and a set met again is not refactored."""
    scene, meth, ops, rec = _rolling_step(builtin_scene)
    pb, sc = rec.problem, rec.problem.scales
    sys_ = meth.system(pb, pb.dq / sc.length)
    rng = np.random.default_rng(4)
    z = np.append(rec.state.t / sc.stress, rec.solution.xi / sc.slip)
    found = []
    for scale in (0.0, 0.05, 0.0):  # the solution's set, a perturbed iterate's set, the first set again
        zz = z + scale * rng.standard_normal(z.size) * np.abs(z).max()
        phi, J, cases = meth.residual_and_jacobian(pb, zz)
        mask = np.append(np.isin(cases, ["eq86", "eq87"]), True)  # stick rows, and the load row
        before = sys_.factorizations
        d = sys_.direction(mask, phi, True)
        ref = np.linalg.solve(J, -phi)
        assert np.max(np.abs(d - ref)) <= TOL["direction"] * np.abs(ref).max()
        found.append((mask.copy(), d, sys_.factorizations - before))
    assert not np.array_equal(found[0][0], found[1][0]), "the perturbation must change the free set"
    assert found[2][2] == 0, "a free set met again is solved on its kept factors"
    assert np.array_equal(found[0][1], found[2][1])  # the same factors and right-hand side: the same numbers


def test_march_step_problems_are_the_validated_ones(builtin_scene):
    """``validate=False`` (the march) builds the problem ``validate=True`` would, and still refuses a load
    beyond the sliding limit, which depends on the step's pressure."""
    scene, meth, ops, rec = _rolling_step(builtin_scene)
    pb = rec.problem
    for Q in (pb.Q, 0.5 * pb.Q):
        a = ops.tangential_step(pb.p, pb.c, pb.dq, Q=Q, validate=False)
        b = ops.tangential_step(pb.p, pb.c, pb.dq, Q=Q)
        for name in ("A", "f", "p", "mu", "c", "dq", "Q", "xi", "scales", "law"):
            x, y = getattr(a, name), getattr(b, name)
            assert x is y or np.array_equal(x, y) or x == y, name
        assert np.array_equal(a.bound, b.bound)
    cap = float(ops.f @ pb.bound)
    for validate in (True, False):
        with pytest.raises(rollqp.InputError, match="sliding limit"):
            ops.tangential_step(pb.p, pb.c, pb.dq, Q=1.01 * cap, validate=validate)
    n1, n2 = ops.normal_step(scene.load.normal, validate=False), ops.normal_step(scene.load.normal)
    assert n1.P == n2.P and n1.h is n2.h and n1.A is n2.A and n1.offset is None and n2.offset is None


@pytest.mark.parametrize("name", sorted(n for n in builtin_scenes() if rollqp.load_scene(n).dimension == 2))
def test_plan_loads_are_the_loads_at_each_step(builtin_scene, name):
    """The loads the march reads from the plan (each history evaluated once over all steps) are the
    scene's loads at each step's τ, to the bit."""
    scene = builtin_scene(name)
    plan = rollqp.kinematics.plan(scene)
    for rec in rollqp.march(scene, method="newton"):
        if rec.k == 0 or rec.problem is None:
            continue
        tau = plan.tau[rec.k]
        if scene.load.approach is None:
            assert rec.P == float(scene.normal_load(tau))
        if scene.load.creepage is None and rec.problem.kind == "tangential":
            assert rec.problem.Q == float(scene.tangential_load(tau))
        elif scene.load.creepage is not None:
            assert rec.solution.xi == float(scene.prescribed_creepage(tau))


@pytest.mark.parametrize("field, key", [("p", "p"), ("t", "c")])
def test_a_non_finite_solution_stops_the_march_as_a_validated_step_would(builtin_scene, field, key):
    """A method whose solution holds a NaN (here a wrapper breaking newton's after a few solves): the next
    march-built step refuses it with the one-line InputError naming the array (``p`` the pressure under the
    bound, ``c`` the history from the shear), and the completed states are kept (``err.partial``)."""
    class Broken(Delegate):
        calls = 0

        def solve(self, problem, warm=None):
            sol = self.inner.solve(problem, warm=warm)
            self.calls += 1
            value = getattr(sol, field)
            if self.calls > 6 and value is not None:
                value = value.copy()
                value[value.size // 2] = np.nan
                setattr(sol, field, value)
            return sol

    scene = builtin_scene("dent", **{"discretization.distance": 0.5})  # a moving profile: a new pressure every step
    with pytest.raises(rollqp.InputError, match=rf"^{key}: must be finite") as err:
        rollqp.run(scene, method=Broken(rollqp.get_method("newton", tolerance=scene.solver.tolerance)))
    assert 0 < len(err.value.partial) < scene.n_steps + 1
