"""``mf-newton``'s warm starts give the answers of cold solves, with fewer products (docs/matrix-free.md).

A rolling step of ``mf-newton`` starts from the previous step's stick/slip sets and reduced solutions
(GMRES initial guesses), and takes the load column ``u`` (``Â_SS u = −Δq̂ e``: it depends on the stick
set alone) from the previous iteration or step when the set and the operator are the same and it was
solved at least as tightly as asked. Held here: a step solved warm in the march and the same step solved
by a fresh method from nothing agree to the solver tolerance; warm uses fewer operator products (measured
482 against 697 over five steps); a step solved again on its own settled sets solves one reduced system
an iteration (``v``), not two; the FFT products (one forward transform and one inverse for every element
type) equal the dense matrices with several columns and transposed.
"""
from __future__ import annotations

import numpy as np
import pytest

import rollqp
from rollqp.influence import toeplitz as tp
from rollqp.methods import get_method
from rollqp.strip import Strip

#: Two solves of the same step, each to rollqp's residual 1e-10 (the scene's tolerance): their tractions
#: differ by the residual times the conditioning of the stick set's system (a few). Measured ≤ 4e-13 μp0.
SAME = 1e-9


def transient(distance=1.5, elements=200):
    """§6.1.1's rollers on ``2·elements + 1`` nodes with FFT operators, Δq = 8 Le (the long steps of
    docs/matrix-free.md's 10,001-node transient): ``(scene, records)``."""
    scene = rollqp.load_scene("cattaneo-carter").replace(**{
        "solver.method": "mf-newton", "solver.operator": "matrix-free", "discretization.elements": elements,
        "discretization.step": 8, "discretization.distance": distance})
    return scene, list(rollqp.march(scene))


def test_warm_started_steps_are_the_cold_solves():
    """Every third rolling step of the march (warm: the previous sets, reduced solutions and load column)
    against a fresh ``mf-newton`` on the same step problem from nothing."""
    scene, recs = transient()
    mu_p0 = scene.contact.friction * scene.p0
    warm_products = cold_products = 0
    for rec in recs[1::3]:
        cold = get_method("mf-newton", tolerance=scene.solver.tolerance)
        sol = cold.solve(rec.problem)
        assert sol.residual <= scene.solver.tolerance and rec.solution.residual <= scene.solver.tolerance
        assert np.abs(sol.t - rec.solution.t).max() <= SAME * mu_p0
        assert abs(sol.xi / rec.solution.xi - 1) <= SAME
        warm_products += rec.solution.info["products"]
        cold_products += sol.info["products"]
    assert warm_products < cold_products, f"warm {warm_products} products, cold {cold_products}"


def test_a_settled_set_takes_its_load_column_from_the_cache():
    """The last step of the march, solved again from its own solution by the method that marched (same sets,
    same operator): one reduced system a set iteration (the load column is known), the same answer."""
    scene, _ = transient(distance=0.0)
    meth = get_method("mf-newton", tolerance=scene.solver.tolerance)
    recs = list(rollqp.march(scene.replace(**{"discretization.distance": 1.5}), meth))
    last = recs[-1]
    again = meth.solve(last.problem, warm=last.solution)
    assert again.info["solves"] == again.iterations, f"{again.info['solves']} GMRES solves, {again.iterations} iterations"
    assert np.abs(again.t - last.solution.t).max() <= SAME * scene.contact.friction * scene.p0


@pytest.mark.parametrize("element", ["constant", "linear", "quadratic"])
def test_one_transform_products_with_several_columns(element):
    """``A X`` and ``Xᵀ A`` (several columns) by one forward and one inverse transform, to round-off of the
    dense matrix (relative 1e-13), on a strip whose end nodes the elements' local nodes do not all reach."""
    strip = Strip(1.3, 17, element)
    for op in (tp.log_operator(strip, 10.0, 0.7), tp.sgn_operator(strip, 1.3)):
        M = op.dense()
        X = np.random.default_rng(4).standard_normal((strip.n, 4))
        scale = np.abs(M).max() * np.abs(X).sum(axis=0).max()
        assert np.abs(op @ X - M @ X).max() <= 1e-13 * scale
        assert np.abs(op.rmatvec(X) - M.T @ X).max() <= 1e-13 * scale
