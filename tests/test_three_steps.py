"""The 3D steps posed two ways — convex programs on external solvers and rollqp's generalized Newton
method — agree on the same discrete step (docs/theory3d.md §5–7), with rollqp's own residuals."""
from __future__ import annotations

import numpy as np
import pytest

from rollqp.errors import InputError, SolverError
from rollqp.operators.grid import Contact, Loads
from rollqp.closedforms.hertz_ellipse import curvatures_for_ratio
from rollqp.march.grid import coupled_step, static_shift, steady, transient
from rollqp.materials import Materials
from rollqp.methods.newton.disc import NewtonMethod
from rollqp.problem.grid import SLIP, STICK, Scales, TangentialStep
from rollqp.methods import compose_3d
from rollqp.methods.socp import ClarabelMethod, CvxpyMethod, OsqpMethod, raw_solution

#: Agreement asked of two routes: both are solved to a residual of 1e-10 (Newton stops at
#: ‖Φ‖∞ ≤ 1e-10·min(1, r), the refined conic answers below it); on these grids the residual's
#: amplification to the tractions is below 10 (measured: ≤ 1e-10 differences).
AGREE = 1e-9
STEEL = Materials.from_young(210e3, 0.3, 210e3, 0.3)
FN, MU = 1000.0, 0.3


def elliptic(elements=(12, 14), materials=STEEL):
    """An a/b = 0.7 Hertz contact on a small grid (the fast suite's size)."""
    A = 1 / 60
    return Contact.hertzian(materials, (A, curvatures_for_ratio(A, 0.7)), FN, MU, elements=elements,
                            zone=(1.3, 1.3))


def units(c):
    return c.scales.stress, MU * c.scales.stress, c.scales.slip


@pytest.fixture(scope="module")
def contact():
    return elliptic()


@pytest.fixture(scope="module")
def pressure(contact):
    return NewtonMethod().solve(contact.normal_step(FN))


CONIC = [pytest.param(lambda: ClarabelMethod(), id="clarabel"),
         pytest.param(lambda: CvxpyMethod(solver="CLARABEL"), id="cvxpy-clarabel"),
         pytest.param(lambda: CvxpyMethod(solver="SCS"), id="cvxpy-scs")]


@pytest.mark.parametrize("make", CONIC + [pytest.param(lambda: OsqpMethod(), id="osqp"),
                                          pytest.param(lambda: NewtonMethod(path="krylov"), id="newton-krylov")])
def test_normal_step_two_ways(contact, pressure, make):
    """eq. 3D.14 as the QP of eq. 3D.22 (approach from the load row's multiplier) and by Newton."""
    sol = make().solve(contact.normal_step(FN))
    p0 = contact.scales.stress
    assert sol.residual <= 1e-10 and pressure.residual <= 1e-10
    assert np.max(np.abs(sol.p - pressure.p)) / p0 <= AGREE
    assert abs(sol.delta - pressure.delta) / contact.scales.displacement <= AGREE


SHIFT_LOADS = [Loads(Fx=0.5 * MU * FN, Fy=-0.3 * MU * FN, phi=0.0),
               Loads(Fx=0.2 * MU * FN, eta=2e-4, phi=0.0),
               Loads(xi=-3e-4, eta=1e-4, phi=0.0)]


@pytest.mark.parametrize("loads", SHIFT_LOADS, ids=["forces", "mixed", "creepages"])
@pytest.mark.parametrize("make", CONIC)
def test_shift_step_socp_against_newton(contact, pressure, loads, make):
    """A static shift (eq. 3D.16) as the SOCP of eq. 3D.20 and by Newton: tractions, creepages (the load
    rows' multipliers, eq. 3D.21) and the stick/slip partition agree."""
    prob = contact.tangential_step("shift", pressure.p, loads)
    ref = NewtonMethod().solve(prob)
    sol = make().solve(prob)
    _, tu, su = units(contact)
    assert sol.residual <= 1e-10 and ref.residual <= 1e-10
    assert np.max(np.abs(sol.t - ref.t)) / tu <= AGREE
    assert abs(sol.xi - ref.xi) / su <= AGREE and abs(sol.eta - ref.eta) / su <= AGREE
    assert np.array_equal(prob.states(sol.t, sol.s), prob.states(ref.t, ref.s))
    assert {STICK, SLIP} <= set(prob.states(ref.t, ref.s).tolist())


def test_rolling_step_with_spin_socp_against_newton(contact, pressure):
    """A transient rolling step (eq. 3D.16 with the previous displacements at x + dx) with spin."""
    prev = NewtonMethod().solve(contact.tangential_step("shift", pressure.p, Loads(Fx=0.4 * MU * FN, eta=0.0)))
    loads = Loads(Fx=0.4 * MU * FN, Fy=0.1 * MU * FN, phi=0.4 / contact.scales.length * 1e-3)
    prob = contact.tangential_step("rolling", pressure.p, loads, (pressure.p, prev.t), dq=contact.grid.dx)
    ref, sol = NewtonMethod().solve(prob), ClarabelMethod().solve(prob)
    _, tu, su = units(contact)
    assert np.max(np.abs(sol.t - ref.t)) / tu <= AGREE and abs(sol.xi - ref.xi) / su <= AGREE


def test_raw_clarabel_is_close_and_the_refinement_is_kept_only_when_better(contact, pressure):
    """The interior point answer alone is ~1e-8 off (complementarity ends near √gap, as in 2D); the
    active-set refinement (its KKT system on the active set it found, eq. 3D.23) takes it below 1e-10,
    and the raw answer and its residual are kept beside it."""
    prob = contact.tangential_step("shift", pressure.p, SHIFT_LOADS[0])
    raw = ClarabelMethod(refine=False, residual_limit=1e-6).solve(prob)
    ref = ClarabelMethod().solve(prob)
    assert 1e-13 < raw.residual < 1e-6
    assert ref.info["refined"] and ref.residual < raw.residual and ref.info["raw_residual"] == raw.residual
    assert np.array_equal(ref.info["raw"]["t"], raw.t)
    assert raw_solution(prob, ref).residual == raw.residual


#: The raw answers' distance from Newton's, in μp0 (tractions) and p0 (pressure): an interior point
#: method's complementary pairs end near √gap (gap 1e-13 here): measured ≤ 3e-7 on these steps
#: (docs/validation3d.md §6); SCS (first order, asked for 1e-12) ≤ 1e-9.
RAW = [pytest.param(lambda: ClarabelMethod(), 1e-6, id="clarabel"),
       pytest.param(lambda: CvxpyMethod(solver="CLARABEL"), 1e-6, id="cvxpy-clarabel"),
       pytest.param(lambda: CvxpyMethod(solver="SCS"), 1e-8, id="cvxpy-scs")]


@pytest.mark.parametrize("loads", SHIFT_LOADS, ids=["forces", "mixed", "creepages"])
@pytest.mark.parametrize("make, bound", RAW)
def test_raw_conic_answers_against_newton(contact, pressure, loads, make, bound):
    """Before any refinement: the solver's own answer (Clarabel with tightened tolerances, cvxpy's
    Clarabel and SCS) against Newton's on the same shift step, and the same on the normal step."""
    prob = contact.tangential_step("shift", pressure.p, loads)
    ref = NewtonMethod().solve(prob)
    raw = make().solve(prob).info["raw"]
    _, tu, _ = units(contact)
    assert np.max(np.abs(raw["t"] - ref.t)) / tu <= bound
    nraw = make().solve(contact.normal_step(FN)).info["raw"]
    assert np.max(np.abs(nraw["p"] - pressure.p)) / contact.scales.stress <= bound


def test_osqp_refuses_a_cone_in_one_line(contact, pressure):
    prob = contact.tangential_step("shift", pressure.p, SHIFT_LOADS[0])
    with pytest.raises(InputError) as err:
        OsqpMethod().solve(prob)
    msg = str(err.value)
    assert "\n" not in msg and msg.startswith("solver.method:") and "tangential" in msg
    with pytest.raises(InputError) as err:   # the registry refuses it before any step, naming the methods that can
        compose_3d(OsqpMethod())
    msg = str(err.value)
    assert "\n" not in msg and msg.startswith("solver.method:")
    assert all(name in msg for name in ("newton", "qp-clarabel", "socp-clarabel", "qp-cvxpy", "socp-scs"))


def test_steady_direct_against_marched():
    """Steady rolling (eq. 3D.17): Newton's direct solve against the march of SOCP steps with Δq = dx
    (Anderson-accelerated) to its fixed point. The march stops when a step changes the tractions
    by less than 1e-10 μp0; its distance to the fixed point is that divided by (1 − contraction)."""
    c = elliptic((10, 10))
    loads = Loads(Fx=0.5 * MU * FN, eta=0.0, phi=0.2 / c.scales.length * 1e-3)
    marched = steady(c, ClarabelMethod(), FN, loads, approximate_start=False)       # from zero tractions
    _, tu, su = units(c)
    assert marched.info["marched"] > 5
    started = steady(c, ClarabelMethod(), FN, loads)       # from FASTSIM's steady state: fewer steps, the same point
    assert started.info["marched"] < marched.info["marched"]
    assert np.max(np.abs(marched.t - started.t)) / tu <= 4e-8                    # both within their stopping distance
    for path in ("dense", "krylov"):
        direct = steady(c, NewtonMethod(path=path), FN, loads)
        assert direct.residual <= 1e-10
        assert np.max(np.abs(marched.t - direct.t)) / tu <= 2e-8     # the march's stopping distance (docstring)
        assert abs(marched.xi - direct.xi) / su <= 2e-8


def test_residuals_detect_a_wrong_solution(contact, pressure):
    """rollqp's residuals can fail: a wrong creepage sign, a traction outside the disc, a load row off."""
    prob = contact.tangential_step("shift", pressure.p, SHIFT_LOADS[0])
    sol = NewtonMethod().solve(prob)
    _, tu, su = units(contact)
    assert prob.residuals(sol.t, -sol.xi, sol.eta).friction > 1e-2
    assert prob.residuals(sol.t * 1.01, sol.xi, sol.eta).max > 1e-3
    nprob = contact.normal_step(FN)
    assert nprob.residuals(pressure.p * 1.001, pressure.delta).load_normal > 1e-4
    assert nprob.residuals(pressure.p, pressure.delta * 1.01).signorini > 1e-3


@pytest.mark.parametrize("kw, key", [(dict(Fx=1.0, xi=0.0), "Fx / xi"), (dict(eta=0.0), "Fx / xi"),
                                     (dict(Fx=MU * FN * 1.001, eta=0.0), "Fx"), (dict(xi=0.0, eta=np.nan), "eta"),
                                     (dict(xi=0.0, eta=0.0, dq=0.0), "dq")])
def test_tangential_step_bad_input(contact, pressure, kw, key):
    base = dict(B=contact.ops.Att, area=contact.grid.area, bound=MU * pressure.p, x=contact.x, y=contact.y,
                c=np.zeros((2, contact.grid.n)), dq=1.0)
    with pytest.raises(InputError, match="^" + key.replace(" ", r"\s")):
        TangentialStep(**{**base, **kw})


def test_cattaneo_shift_opposes_the_force(contact):
    """Convention (docs/theory3d.md §1): the rigid shift of A relative to B is opposite to the force
    on A, the slip opposite to the traction (CONTACT: FX = −3.218, SHIFT X = +8.155e-3)."""
    rec = static_shift(contact, NewtonMethod(), FN, Fx=-0.6 * MU * FN)[-1]
    assert rec.Fx == pytest.approx(-0.6 * MU * FN, rel=1e-12) and rec.info["shift"][0] > 0
    slip = rec.state == SLIP
    assert np.all(np.sum(rec.t[:, slip] * rec.s[:, slip], axis=0) < 0)


def test_dissimilar_alternation_two_ways():
    """Dissimilar bodies (K ≠ 0): each step is the N–T alternation; Newton halves and conic halves reach
    the same coupled state, and swapping the bodies flips K and the pressure's tangential traction."""
    alu_steel = Materials.from_young(70e3, 0.33, 210e3, 0.28)
    c = elliptic((10, 12), alu_steel)
    loads = Loads(Fx=0.3 * MU * FN, eta=0.0)
    n1, t1, sw1 = coupled_step(c, NewtonMethod(), FN, "shift", loads)
    n2, t2, sw2 = coupled_step(c, ClarabelMethod(), FN, "shift", loads)
    pu, tu, su = units(c)
    assert sw1 > 2 and np.max(np.abs(n1.p - n2.p)) / pu <= AGREE and np.max(np.abs(t1.t - t2.t)) / tu <= AGREE
    swapped = elliptic((10, 12), Materials.from_young(210e3, 0.28, 70e3, 0.33))
    assert swapped.materials.K == pytest.approx(-alu_steel.K)
    zero = Loads(Fx=0.0, Fy=0.0)
    _, ta, _ = coupled_step(c, NewtonMethod(), FN, "shift", zero)
    _, tb, _ = coupled_step(swapped, NewtonMethod(), FN, "shift", zero)
    assert np.max(np.abs(ta.t)) > 1e-3 * tu and np.max(np.abs(ta.t + tb.t)) / tu <= AGREE


def test_transient_records_and_similar_pressure_fixed(contact):
    start = static_shift(contact, NewtonMethod(), FN, Fx=0.5 * MU * FN)[-1]
    recs = list(transient(contact, NewtonMethod(), FN, Loads(Fx=0.5 * MU * FN, eta=0.0), contact.grid.dx, 3,
                          start=start))
    assert [r.k for r in recs] == [0, 1, 2, 3] and recs[0] is start
    assert all(np.array_equal(r.p, start.p) for r in recs)
    assert all(r.Fx == pytest.approx(0.5 * MU * FN, rel=1e-10) and r.residual <= 1e-10 for r in recs[1:])


def test_newton_reports_failure_with_the_residual(contact, pressure):
    prob = contact.tangential_step("shift", pressure.p, SHIFT_LOADS[0])
    with pytest.raises(SolverError, match="residual"):
        NewtonMethod(max_iterations=1).solve(prob)


def test_scales_are_hertz():
    c = elliptic()
    e = c.ellipse
    assert c.scales == Scales(length=np.sqrt(e.a * e.b), stress=e.p0, modulus=STEEL.Estar, dimension=3)


def test_the_2d_normal_machinery_solves_the_3d_normal_step(contact, pressure):
    """The 2D package's normal step takes the 3D operator unchanged: a flattened grid is a set of nodes
    with weights f = area/c and load FN/c (its load row (fᵀp − P)/(c p0) is then eq. 3D.29's). Its
    Newton and QP backends give the 3D step's solution: a third route."""
    import rollqp
    L = contact.scales.length
    sc = rollqp.Scales(length=L, stress=contact.scales.stress, modulus=contact.scales.modulus)
    step = rollqp.NormalStep(A=contact.ops.Ann.dense(), f=np.full(contact.grid.n, contact.grid.area / L),
                             h=contact.h, P=FN / L, scales=sc)
    for method in ("newton", "qp-clarabel", "qp-osqp"):
        sol = rollqp.solve_step(step, method)
        assert np.max(np.abs(sol.p - pressure.p)) / contact.scales.stress <= AGREE
        assert abs(sol.delta - pressure.delta) / contact.scales.displacement <= AGREE
