"""The fast linear-algebra paths give the answers of the plain ones (correctness, never timing).

* Newton's reduced system (rollqp.methods.newton.linear.ReducedSystem.direction): the identity rows of
  the separated/slipping nodes eliminated, the LU factors reused through a Schur complement
  while the active set moves by a few nodes, against ``numpy.linalg.solve`` on the full
  pseudo-Jacobian ``J`` — direction by direction, and over a whole transient (same iteration
  counts, same tractions).
* The coupled Newton step's reused LU (rollqp.methods.newton.linear.CoupledFactors: Woodbury updates
  of the changed rows on the factored J) against the direct reduced solve
  (rollqp.methods.newton.linear.direct_coupled_direction): direction by direction on random case patterns, the
  fallbacks (singular, ill-conditioned, inaccurate updates), and whole coupled runs.
* Newton's two iteration loops: the one written out for small systems
  (rollqp.methods.newton.uncoupled._iterate_dense, below ``linear.PARTIAL_MIN`` nodes) against the
  general one (``_Iterate``, with products over the contact columns) on the same small scenes: the same
  iterations at every step, tractions equal to round-off.
* The march's tangential-only rolling step (``rollqp.march.strip.FAST_ROLLING_STEP``) against the general
  step and record: every array of whole runs bitwise equal.
* The QP backends' solver cache keyed by a Hessian fingerprint: a changed Hessian builds a
  new solver object, the same Hessian reuses it.
"""
from __future__ import annotations

import importlib

import numpy as np
import pytest

import rollqp
from rollqp.operators import SceneOperators
from rollqp.methods.newton import linear, ncp
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
    model = SceneOperators.build(scene, symmetrized=False)
    nsol = NewtonMethod().solve(model.normal_step(scene.load.normal))
    pb = model.tangential_step(nsol.p, np.zeros(model.strip.n), scene.dq, Q=0.5 * 0.1 * scene.load.normal)
    meth = NewtonMethod()
    sys_ = meth.system(pb, pb.dq / pb.scales.length)
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
        mp.setattr(linear.ReducedSystem, "direction", _full_direction)
        plain = rollqp.run(scene).arrays()
    assert np.array_equal(fast["iterations"], plain["iterations"])
    assert np.array_equal(fast["backtracks"], plain["backtracks"])
    mu, p0 = scene.contact.friction, scene.p0
    assert np.max(np.abs(fast["pt"] - plain["pt"])) <= TOL["transient"] * mu * p0
    assert np.max(np.abs(fast["creepage"] - plain["creepage"])) <= TOL["transient"] * abs(plain["creepage"]).max()


@pytest.mark.parametrize("name, changes", [
    ("cattaneo-carter", {}), ("harmonic", {}),
    ("cattaneo-carter", {"discretization.element": "linear", "discretization.elements": 60,
                         "discretization.distance": 3.0})])
def test_small_system_loop_is_the_general_iteration(monkeypatch, name, changes):
    """Below ``PARTIAL_MIN`` nodes the Newton iteration runs in its written-out loop; the general loop
    (``PARTIAL_MIN = 0``: products over the contact columns, ``y`` carried along between them) solves the
    same steps in the same numbers of iterations and backtracks, to tractions equal to round-off (the
    partial products sum in another order: measured 7.5e-14 μp0 on cattaneo-carter)."""
    scene = rollqp.load_scene(name).replace(**{"solver.method": "newton", **changes})
    small = rollqp.run(scene).arrays()
    assert small["x"].size < linear.PARTIAL_MIN
    with monkeypatch.context() as mp:
        mp.setattr(linear, "PARTIAL_MIN", 0)
        general = rollqp.run(scene).arrays()
    assert np.array_equal(small["iterations"], general["iterations"])
    assert np.array_equal(small["backtracks"], general["backtracks"])
    mu, p0 = scene.contact.friction, scene.p0
    assert np.max(np.abs(small["pt"] - general["pt"])) <= TOL["transient"] * mu * p0
    assert np.max(np.abs(small["pn"] - general["pn"])) <= TOL["transient"] * p0


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
    J = ncp.coupled_jacobian(S, contact, stick, slip_sign, mu)
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
        mp.setattr(linear, "direct_coupled_direction", _full_coupled_direction)
        plain = rollqp.run(scene, method="newton").arrays()
    assert np.array_equal(fast["iterations"][1:], plain["iterations"][1:])
    assert np.array_equal(fast["backtracks"][1:], plain["backtracks"][1:])
    mu, p0 = scene.contact.friction, scene.p0
    assert np.max(np.abs(fast["pt"] - plain["pt"])) <= TOL["transient"] * mu * p0
    assert np.max(np.abs(fast["pn"] - plain["pn"])) <= TOL["transient"] * p0


# ------------------------------------------------------------------- coupled factorization reuse
def _coupled_problem(elements=80):
    """A coupled rolling step of goodman-bentall (161 nodes: above the direct-solve size)."""
    scene = rollqp.load_scene("goodman-bentall").replace(**{"discretization.elements": elements})
    model = SceneOperators.build(scene, symmetrized=False)
    n = model.strip.n
    P = scene.load.normal
    return model.coupled_step(P, np.zeros(n), scene.dq, Q=0.0)


def _coupled_patterns(n, rng):
    """Random node cases: a base pattern, small random changes of it (Woodbury updates, the
    changes accumulating against the factored pattern), then a large change (refactor)."""
    def random_cases(contact_frac, stick_frac):
        contact = rng.random(n) < contact_frac
        u = rng.random(n)
        stick = u < stick_frac
        slip_sign = np.where(stick, 0.0, np.where(u < stick_frac + (1 - stick_frac) / 2, 1.0, -1.0))
        zero = ~stick & (rng.random(n) < 0.3)  # zero bound: identity t row
        slip_sign[zero] = 0.0
        return contact, stick, slip_sign

    base = random_cases(0.6, 0.5)
    out = [base]
    cur = [a.copy() for a in base]
    for k in (1, 2, 3, 4, 5):  # each flips k more nodes' cases
        contact, stick, slip_sign = [a.copy() for a in cur]
        for i in rng.choice(n, size=k, replace=False):
            case = rng.integers(5)
            contact[i] = case != 0 or not contact[i]
            stick[i] = case == 1
            slip_sign[i] = {2: 1.0, 3: -1.0}.get(int(case), 0.0)
        cur = [contact, stick, slip_sign]
        out.append(tuple(cur))
    out.append(random_cases(0.4, 0.7))  # large change: refactor
    out.append(base)  # and back
    return out


@pytest.mark.parametrize("loads", ["P,Q", "none"])
def test_coupled_updated_direction_matches_direct(loads):
    """Every direction of the reused/updated factorization (Woodbury on the factored J) equals
    the direct reduced solve (rollqp.methods.newton.linear.direct_coupled_direction) on random case patterns."""
    pb = _coupled_problem()
    if loads == "none":  # δ and ξ prescribed: no load rows
        pb = pb.replace(P=None, Q=None, delta=0.0, xi=0.0)
    meth = NewtonMethod()
    S, _ = meth.coupled_system(pb)
    fac = linear.CoupledFactors(S)
    assert S.N >= fac.DIRECT_BELOW  # the reuse path, not the direct fallback
    n, mu = pb.n, pb.mu
    rng = np.random.default_rng(7)
    for contact, stick, slip_sign in _coupled_patterns(n, rng):
        phi = rng.standard_normal(S.N)
        d, dN, dT = fac.direction(contact, stick, slip_sign, mu, phi)
        ref = linear.direct_coupled_direction(S, contact, stick, slip_sign, mu, phi)
        assert np.max(np.abs(d - ref)) <= TOL["direction"] * np.max(np.abs(ref))
        # the returned K_N d, K_T d are those products (recomputed here in another order of
        # summation: round-off of a 324-term dot product, ≲ 1e-13 relative)
        assert np.allclose(dN, S.KN @ d, rtol=0, atol=1e-12 * np.max(np.abs(dN)))
        assert np.allclose(dT, S.KT @ d, rtol=0, atol=1e-12 * np.max(np.abs(dT)))
    assert fac.factorizations >= 2 and fac.updates >= 4 and fac.rejected == 0


def test_coupled_update_falls_back_when_singular_or_inaccurate(monkeypatch):
    """An update that makes J singular returns None, as the direct solve does; an update whose
    capacitance matrix is too ill-conditioned, or whose residual is not at round-off, is
    replaced by a new factorization — the direct path's direction, bit for bit."""
    pb = _coupled_problem()
    meth = NewtonMethod()
    S, _ = meth.coupled_system(pb)
    n, mu = pb.n, pb.mu
    rng = np.random.default_rng(3)
    # contact at 4 nodes only, every node sticking: J regular
    contact = np.zeros(n, dtype=bool)
    contact[n // 2 - 2:n // 2 + 2] = True
    stick = np.ones(n, dtype=bool)
    sign = np.zeros(n)
    fac = linear.CoupledFactors(S)
    phi = rng.standard_normal(S.N)
    assert fac.direction(contact, stick, sign, mu, phi) is not None
    # separating those 4 nodes (4 changed rows: an update) leaves no row with a δ̂ entry
    none = np.zeros(n, dtype=bool)
    assert linear.direct_coupled_direction(S, none, stick, sign, mu, phi) is None
    assert fac.direction(none, stick, sign, mu, phi) is None
    assert fac.updates == 0
    # the checks reject every update: refactor, the direct path's direction exactly
    for attr, value in (("MAX_CONDITION", 0.0), ("MAX_RESIDUAL", 0.0)):
        fac = linear.CoupledFactors(S)
        with monkeypatch.context() as mp:
            mp.setattr(linear.CoupledFactors, attr, value)
            patterns = _coupled_patterns(n, rng)[:3]
            for c, s, g in patterns:
                phi = rng.standard_normal(S.N)
                d = fac.direction(c, s, g, mu, phi)[0]
                assert np.array_equal(d, linear.direct_coupled_direction(S, c, s, g, mu, phi))
        assert fac.rejected == 2 and fac.updates == 0


@pytest.mark.parametrize("scene_changes, direct_below", [
    ({"discretization.distance": 1.0}, 0),  # goodman-bentall shortened, 81 nodes: reuse forced on
    ({"discretization.elements": 80, "discretization.step": 0.5, "discretization.distance": 1.0,
      "load.start_steps": 10, "contact.friction": 0.6}, None),  # 161 nodes, μ = 0.6
], ids=["goodman-bentall", "mu-0.6"])
def test_coupled_reuse_same_run_as_direct(monkeypatch, scene_changes, direct_below):
    """Whole coupled runs with the factorization reused and with the direct solve every
    iteration: the same iterations and backtracks at every rolling step, tractions equal to
    round-off, and the reuse really taken (Woodbury updates counted)."""
    scene = rollqp.load_scene("goodman-bentall").replace(**scene_changes)
    made = []
    init = linear.CoupledFactors.__init__
    with monkeypatch.context() as mp:
        mp.setattr(linear.CoupledFactors, "__init__", lambda self, S: init(self, S) or made.append(self))
        if direct_below is not None:
            mp.setattr(linear.CoupledFactors, "DIRECT_BELOW", direct_below)
        fast = rollqp.run(scene, method="newton").arrays()
    with monkeypatch.context() as mp:
        mp.setattr(NewtonMethod, "coupled_reuse", False)
        plain = rollqp.run(scene, method="newton").arrays()
    roll = made[-1]  # the rolling steps' operator (the start's is another: its own Δq)
    assert roll.updates > 10 * roll.factorizations
    # the start (braked, many backtracks onto kinks) may take another path through a kink
    # by round-off (see test_coupled_transient_same_iterates_as_full_solve); the rolling steps not
    assert np.array_equal(fast["iterations"][1:], plain["iterations"][1:])
    assert np.array_equal(fast["backtracks"][1:], plain["backtracks"][1:])
    mu, p0 = scene.contact.friction, scene.p0
    assert np.max(np.abs(fast["pt"] - plain["pt"])) <= TOL["transient"] * mu * p0
    assert np.max(np.abs(fast["pn"] - plain["pn"])) <= TOL["transient"] * p0


@pytest.mark.parametrize("name, method, changes", [
    ("cattaneo-carter", "newton", {}), ("cattaneo-carter", "nt-newton", {}), ("cattaneo-carter", "qp-osqp", {}),
    ("cattaneo-carter", "qp-clarabel", {}), ("ramp", "newton", {}),
    ("cattaneo-carter", "newton", {"discretization.element": "linear", "discretization.elements": 60})])
def test_tangential_only_rolling_step_is_the_general_step(monkeypatch, name, method, changes):
    """The written-out rolling step of a scene whose rolling steps are their tangential half alone (these
    scenes' are: a fixed normal half, one μ, uncoupled, a fixed profile) gives, bit for bit, every array
    the general step and record give (the same calls on the same numbers)."""
    march_module = importlib.import_module("rollqp.march.strip")
    scene = rollqp.load_scene(name).replace(**{"solver.method": method, **changes})
    if scene.discretization.distance > 3.0:
        scene = scene.replace(**{"discretization.distance": 3.0})
    fast = rollqp.run(scene).arrays()
    with monkeypatch.context() as mp:
        mp.setattr(march_module, "FAST_ROLLING_STEP", False)
        plain = rollqp.run(scene).arrays()
    compared = 0
    for key, value in fast.items():
        if key in ("meta", "step_time"):   # the wall times differ between any two runs
            continue
        np.testing.assert_array_equal(value, plain[key], err_msg=f"{name}, {method}: {key}")
        compared += 1
    assert compared >= 20
