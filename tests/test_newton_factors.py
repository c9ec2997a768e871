"""The dense Newton method's reduced systems reuse the nearest kept factorization (rollqp.methods.newton.linear).

A Newton iterate's free set can swing far from the set factored last and back within a step (the
dense ``cattaneo-carter`` at 2,561 nodes: the second iterate of each step in a stretch of the
transient sticks ~200 nodes that the third releases again). Such a set is solved bordered on the kept
factorization nearest to it, when one is near, instead of a new factorization; the direction is the one
of the pseudo-Jacobian itself either way. Held here on a random diagonally dominant system (no scene: the
linear algebra alone), with the direction against a dense solve of ``J d = −Φ``.
"""
from __future__ import annotations

import numpy as np

from rollqp.methods.newton.linear import ReducedSystem

#: Directions of a well-conditioned system (condition ~10) solved two ways: round-off of the
#: factorizations and the bordered Schur complement (measured 1e-15 relative).
ROUNDOFF = 1e-12


def system(n=200, seed=0):
    rng = np.random.default_rng(seed)
    Ahat = rng.standard_normal((n, n)) / np.sqrt(n) + 4.0 * np.eye(n)
    fhat = rng.uniform(0.5, 1.0, n)
    return ReducedSystem(None, None, Ahat, fhat, 0.7, np.ones(n), 1.0), rng


def free(n, k):
    m = np.zeros(n + 1, dtype=bool)
    m[:k] = True
    m[n] = True  # the load row
    return m


def check(sys_, mask, phi):
    d = sys_.direction(mask, phi, True)
    exact = np.linalg.solve(sys_.jacobian(mask, True), -phi)
    assert np.abs(d - exact).max() <= ROUNDOFF * np.abs(exact).max()


def test_a_set_far_from_the_last_factorization_borders_on_the_nearest_kept_one():
    n = 200
    sys_, rng = system(n)
    phi = rng.standard_normal(n + 1)
    check(sys_, free(n, 150), phi)          # factored
    check(sys_, free(n, 100), phi)          # 50 nodes away (more than 1/8 of 150): factored anew
    assert (sys_.factorizations, sys_.updates) == (2, 0)
    check(sys_, free(n, 147), phi)          # 47 from the last, 3 from the first: bordered on the first
    assert (sys_.factorizations, sys_.updates) == (2, 1)
    check(sys_, free(n, 60), phi)           # near neither (40 and 87 away): factored
    assert (sys_.factorizations, sys_.updates) == (3, 1)
