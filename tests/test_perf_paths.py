"""The fast linear-algebra paths give the answers of the plain ones (correctness, never timing).

* Newton's reduced system (rollqp.methods.newton._System.direction): the identity rows of
  the separated/slipping nodes eliminated, the LU factors reused through a Schur complement
  while the active set moves by a few nodes, against ``numpy.linalg.solve`` on the full
  pseudo-Jacobian ``J`` — direction by direction, and over a whole transient (same iteration
  counts, same tractions).
* The QP backends' solver cache keyed by a Hessian fingerprint: a changed Hessian builds a
  new solver object, the same Hessian reuses it.
"""
from __future__ import annotations

import numpy as np
import pytest

import rollqp
from rollqp.driver import Model
from rollqp.methods import newton as newton_module
from rollqp.methods.newton import NewtonMethod

# Tolerances, each with its reason.
TOL = {
    # two LU-based solves of the same system: both backward stable, so they differ by
    # round-off times the condition number of J (≤ 1e4 here: the log kernel on 161 nodes, r
    # scaled to O(1) rows), relative to ‖d‖.
    "direction": 1e-10,
    # a whole transient by both paths: each step ends at round-off (Φ piecewise linear, the
    # last full step exact), so the tractions agree to a few hundred ulps of μp0 per step,
    # carried by the history vector over the steps.
    "transient": 1e-11,
}


def _tangential_system(elements=80, element="quadratic"):
    scene = rollqp.load_scene("cattaneo-carter").replace(
        **{"discretization.elements": elements, "discretization.element": element})
    model = Model.build(scene, symmetric=False)
    nsol = NewtonMethod().solve(model.normal_step(scene.load.normal))
    pb = model.tangential_step(nsol.p, np.zeros(model.strip.n), scene.dq, Q=0.5 * 0.1 * scene.load.normal)
    meth = NewtonMethod()
    sys_ = meth._system(pb, pb.dq / pb.scales.length)
    return model, sys_


def _masks(n, rng):
    """A base active set, then small moves of its ends (Schur path), then a large change (refactor)."""
    lo, hi = n // 5, 4 * n // 5
    base = np.zeros(n, dtype=bool)
    base[lo:hi] = True
    out = [base]
    for dlo, dhi in [(1, 0), (1, -1), (0, -2), (-1, 1), (2, 2), (3, -3)]:
        m = np.zeros(n, dtype=bool)
        m[lo + dlo:hi + dhi] = True
        out.append(m)
    m = base.copy()
    m[rng.choice(np.flatnonzero(base), size=3, replace=False)] = False  # holes inside: released nodes
    out.append(m)
    m = np.zeros(n, dtype=bool)
    m[n // 3: 2 * n // 3] = True  # a large change: refactor
    out.append(m)
    out.append(base)  # back again: a large change the other way
    return out


@pytest.mark.parametrize("with_load", [True, False], ids=["load-row", "prescribed"])
def test_reduced_direction_matches_full_jacobian(with_load):
    """Every direction of the reduced/updated solve equals the full solve J d = −Φ."""
    _, sys_ = _tangential_system()
    n = sys_.fhat.size
    rng = np.random.default_rng(5)
    before = (sys_.factorizations, sys_.updates)
    for m in _masks(n, rng):
        mask = np.append(m, True) if with_load else m
        phi = rng.standard_normal(n + with_load)
        d = sys_.direction(mask, phi, with_load)
        J = sys_.jacobian(mask, with_load)
        ref = np.linalg.solve(J, -phi)
        assert np.max(np.abs(d - ref)) <= TOL["direction"] * np.max(np.abs(ref))
        # the pinned nodes' entries are exactly −Φ (identity rows)
        assert np.array_equal(d[:n][~m], -phi[:n][~m])
    # both paths were taken: new factorizations and Schur-complement updates
    assert sys_.factorizations - before[0] >= 2
    assert sys_.updates - before[1] >= 5


def test_direction_singular_is_none():
    """A reduced system that is singular (load row with every node pinned) is reported, not solved."""
    _, sys_ = _tangential_system(elements=20)
    n = sys_.fhat.size
    mask = np.append(np.zeros(n, dtype=bool), True)
    assert sys_.direction(mask, np.ones(n + 1), True) is None


def _full_direction(self, mask, phi, with_load):
    """The plain path: the full pseudo-Jacobian, dense LU."""
    J = self.jacobian(mask, with_load)
    try:
        return np.linalg.solve(J, -phi)
    except np.linalg.LinAlgError:
        return None


@pytest.mark.parametrize("element", ["quadratic", "linear"])
def test_transient_same_iterates_as_full_solve(monkeypatch, element):
    """A transient (braked start, then the rolling steps to 1.5 a_H on 161/81 nodes) by the reduced
    solve and by the full one: the same Newton iteration counts and backtracks at every step,
    tractions equal to round-off."""
    scene = rollqp.load_scene("cattaneo-carter").replace(
        **{"discretization.elements": 80, "discretization.element": element, "discretization.distance": 1.5,
           "solver.method": "newton"})
    fast = rollqp.run(scene).arrays()
    with monkeypatch.context() as mp:
        mp.setattr(newton_module._System, "direction", _full_direction)
        plain = rollqp.run(scene).arrays()
    assert np.array_equal(fast["iterations"], plain["iterations"])
    assert np.array_equal(fast["backtracks"], plain["backtracks"])
    mu, p0 = scene.contact.friction, scene.p0
    assert np.max(np.abs(fast["pt"] - plain["pt"])) <= TOL["transient"] * mu * p0
    assert np.max(np.abs(fast["creepage"] - plain["creepage"])) <= TOL["transient"] * abs(plain["creepage"]).max()


@pytest.mark.parametrize("backend", ["qp-osqp", "qp-clarabel"])
def test_qp_solver_cache_follows_the_hessian(backend):
    """The solver object is reused while the operator is the same arrays, rebuilt for another
    operator of the same structure, and the answers equal those of fresh method objects."""
    from rollqp.methods import get_method

    model, _ = _tangential_system(elements=20, element="constant")  # symmetric F·A: one QP per solve
    scene = model.scene
    nsol = NewtonMethod().solve(model.normal_step(scene.load.normal))
    Q = 0.5 * 0.1 * scene.load.normal
    pb1 = model.tangential_step(nsol.p, np.zeros(model.strip.n), scene.dq, Q=Q)
    pb2 = pb1.replace(A=pb1.A + 0.5 * np.diag(np.diag(pb1.A)))  # same structure, another Hessian (not a
    # multiple: the QP form normalizes H by its largest diagonal entry)
    meth = get_method(backend)
    builds = []
    orig = meth._build
    meth._build = lambda form: builds.append(1) or orig(form)
    s1 = meth.solve(pb1)
    s1b = meth.solve(pb1.replace(c=pb1.c + 1e-3 * scene.a_H * scene.p0 / scene.Estar))  # same operator: reused
    assert len(builds) == 1
    s2 = meth.solve(pb2)
    assert len(builds) == 2
    # each equals a fresh object's answer (to the backends' tolerance: 1e-10 requested, rollqp's
    # residual limit 1e-8 in μp0 units)
    for pb, s in ((pb1, s1), (pb2, s2)):
        fresh = get_method(backend).solve(pb)
        assert np.max(np.abs(s.t - fresh.t)) <= 1e-8 * 0.1 * scene.p0
    assert not np.allclose(s1.t, s2.t)  # the operators really differ
    assert np.max(np.abs(s1b.t - s1.t)) > 0


def _full_coupled_direction(S, contact, stick, slip_sign, mu, phi):
    """The plain path for the coupled step: the full pseudo-Jacobian, dense LU."""
    J = NewtonMethod._coupled_jacobian(S, contact, stick, slip_sign, mu)
    try:
        return np.linalg.solve(J, -phi)
    except np.linalg.LinAlgError:
        return None


def test_coupled_transient_same_iterates_as_full_solve(monkeypatch):
    """The coupled Newton method (goodman-bentall shortened: 20 QCE, the Goodman start in 10
    normal-load steps, 1 a_H of rolling) with the reduced system and with the full one: the same
    iterations and backtracks at every rolling step, tractions equal to round-off. (In the braked
    start, with its many Armijo backtracks onto kinks, round-off may send the two paths through a
    kink differently — measured 59 against 57 iterations over the 10 load steps — to the same
    solution.)"""
    scene = rollqp.load_scene("goodman-bentall").replace(
        **{"discretization.elements": 20, "discretization.step": 0.5, "discretization.distance": 1.0,
           "load.start_steps": 10})
    fast = rollqp.run(scene, method="newton").arrays()
    with monkeypatch.context() as mp:
        mp.setattr(NewtonMethod, "_coupled_direction", staticmethod(_full_coupled_direction))
        plain = rollqp.run(scene, method="newton").arrays()
    assert np.array_equal(fast["iterations"][1:], plain["iterations"][1:])
    assert np.array_equal(fast["backtracks"][1:], plain["backtracks"][1:])
    mu, p0 = scene.contact.friction, scene.p0
    assert np.max(np.abs(fast["pt"] - plain["pt"])) <= TOL["transient"] * mu * p0
    assert np.max(np.abs(fast["pn"] - plain["pn"])) <= TOL["transient"] * p0
