"""Slip-velocity friction laws on a 3D contact (docs/friction.md, "On the grid"; docs/validation3d.md §20): the
slip speed ``V|s|`` of each element's slip vector, Newton's pseudo-Jacobian with the ``∂μ/∂|s|`` term, the fixed
point on the bound around the conic method, the memory carried with the material, the selection of a step's
solution by the path from the frozen bound, and bad input in one line naming the key."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy import integrate

import rollqp
from rollqp.errors import InputError
from rollqp.friction import parse_friction
from rollqp.methods import BoundFixedPoint, SlipContinuation
from rollqp.methods.newton.disc import NewtonMethod
from rollqp.methods.socp import ClarabelMethod
from rollqp.march.grid import march, prepare

LAW = {"law": "exponential", "static": 0.4, "kinetic": 0.2, "velocity": 300.0, "rolling_speed": 1000.0}
# full sliding: rigid slip w = (ξ − φy, φx), |w| between 0.1 and 0.5 over the contact (V|w| = 100–500 against
# v_h = 300: μ falls from 0.34 to 0.24 across it)
XI, PHI_A = 0.3, 0.2
# a small load (a/R = 1.4e-3): the elastic slip is 0.09 % of |w| (measured), so s ≈ w
FN_SMALL = 0.1


def _sliding(per_semi_axis: int):
    """kalker-circular at ``FN_SMALL`` with ``per_semi_axis`` elements per semi-axis over the zone 1.2 a, steady
    rolling at ξ = 0.3, φ a = 0.2: every element in contact slides."""
    base = rollqp.load_scene("kalker-circular").replace(**{"load.normal": FN_SMALL})
    a, n = base.ellipse.a, round(2.4 * per_semi_axis)
    return base.replace(**{"discretization.elements": [n, n], "discretization.zone": [1.2, 1.2],
                           "discretization.distance": 0.5, "contact.friction": LAW,
                           "load.creepage": {"longitudinal": XI, "lateral": 0.0, "spin": PHI_A / a}}), a


def _exact():
    """``(Fx/FN, Mz/(FN a))`` of full sliding at the rigid slip: ``t = −μ(V|w|) p_H w/|w|`` integrated over the
    Hertz circle (scipy's quadrature; ``x, y`` in units of ``a``)."""
    law = parse_friction(LAW)

    def component(k):
        def f(y, x):
            wx, wy = XI - PHI_A * y, PHI_A * x
            w = math.hypot(wx, wy)
            p = 1.5 / math.pi * math.sqrt(max(0.0, 1 - x * x - y * y))
            return -float(law.steady(law.rolling_speed * w)[0]) * p * (wx, x * wy - y * wx)[k] / w
        return integrate.dblquad(f, -1, 1, lambda x: -math.sqrt(1 - x * x), lambda x: math.sqrt(1 - x * x),
                                 epsabs=1e-13, epsrel=1e-12)[0]
    return component(0), component(1)


def test_full_sliding_under_a_falling_law_converges_to_the_integral():
    """Fx and Mz of full sliding → the integrals of ``μ(V|w|) p_H`` as the grid doubles (10, 20, 40 per a)."""
    fx, mz = _exact()
    law = parse_friction(LAW)
    errors = []
    for n in (10, 20, 40):
        scene, a = _sliding(n)
        r = rollqp.run(scene).arrays()
        FN, p = float(r["FN"][-1]), r["pn"][-1]
        assert np.all(r["state"][-1][p > 0] == 2)   # full sliding
        # each element's traction is μ(V|s_i|) p_i against its own slip, to the solver's tolerance (1e-10 of the
        # nondimensional projection; 1e-8 p0 with margin)
        s = np.stack([r["sx"][-1], r["sy"][-1]])
        t = np.stack([r["px"][-1], r["py"][-1]])
        mu = law.steady(law.rolling_speed * np.hypot(*s))[0]
        inside = p > 0
        assert np.max(np.abs(np.hypot(*t)[inside] - mu[inside] * p[inside])) <= 1e-8 * float(r["p0"])
        errors.append((abs(float(r["Fx"][-1]) / FN - fx), abs(float(r["Mz"][-1]) / (FN * a) - mz)))
    errors = np.array(errors)
    slopes = np.log2(errors[0] / errors[2]) / 2
    print(f"|Fx/FN - exact| = {', '.join(f'{e:.3g}' for e in errors[:, 0])} (slope {slopes[0]:.2f}); "
          f"|Mz/(FN a) - exact| = {', '.join(f'{e:.3g}' for e in errors[:, 1])} (slope {slopes[1]:.2f})")
    # measured (docs/validation3d.md §20): Fx 4.26e-5, 8.80e-6, 3.30e-6 (slope 1.85); Mz 7.97e-5, 1.39e-5,
    # 4.70e-6 (slope 2.04). The midpoint rule on μ p is second order (Hertz's √ edge O(h^1.5)); the steady
    # slip's upwind difference adds a first-order part through the elastic slip, 1.4e-6 at 40 per a
    assert np.all(errors[1] < errors[0]) and np.all(errors[2] < errors[1]), errors
    assert np.all(slopes >= 1.5), (errors, slopes)


def _transient(memory=0.0, elements=(12, 12), distance=1.5, **law):
    """A braked circle rolling under the falling law with the force ramped to 0.6 μ_s FN: partial slip, the slip
    zone growing from the trailing edge (cattaneo-3d's contact)."""
    friction = {"law": "exponential", "static": 0.32, "kinetic": 0.2, "velocity": 200.0, "rolling_speed": 1e4,
                "memory": memory, **law}
    return rollqp.load_scene("cattaneo-3d").replace(**{
        "contact.friction": friction, "discretization.elements": list(elements), "discretization.distance": distance,
        "load.tangential": {"kind": "ramp", "start": 0.0, "end": 0.6, "over": 1.0}, "solver.tolerance": 1e-12})


def _run(scene, method):
    prepared = prepare(scene, method)
    return list(march(prepared[0], prepared=prepared)), prepared[2]


def _newton():
    """Newton on the law itself, no selection (each step from the previous state)."""
    return SlipContinuation(NewtonMethod(tolerance=1e-12), threshold=math.inf)


def _fixed_point():
    """The fixed point on the bound around Clarabel's SOCP (its tolerances set from 1e-12, not its defaults)."""
    return SlipContinuation(BoundFixedPoint(ClarabelMethod(tolerance=1e-12)), threshold=math.inf)


@pytest.mark.parametrize("memory", [0.0, 0.3], ids=["no-memory", "memory"])
def test_newton_agrees_with_the_fixed_point_on_the_conic_method(memory):
    """The second method: Newton with ∂μ/∂|s| in its Jacobian against the fixed point on the bound around
    Clarabel's SOCP, each solving every step of a transient (with and without memory) on its own."""
    scene = _transient(memory)
    a, contact = _run(scene, _newton())
    b, _ = _run(scene, _fixed_point())
    unit = 0.32 * contact.scales.stress
    assert any((r.state == 2).any() for r in a[1:]) and any((r.state == 1).any() for r in a[1:])
    worst = max(float(np.max(np.abs(x.t - y.t))) / unit for x, y in zip(a, b))
    mu = max(float(np.max(np.abs(x.mu - y.mu))) for x, y in zip(a, b))
    alone = sum("fixed_point" not in r.info["tangential"] for r in a[1:])
    print(f"memory {memory}: max |t_newton - t_fixed point| = {worst:.2e} mu_s p0, max |mu diff| = {mu:.2e}; "
          f"Newton alone on {alone} of {len(a) - 1} steps")
    assert alone >= (len(a) - 1) // 2      # most steps by Newton's own iteration (the rest: its safeguard)
    # both to rollqp's residual 1e-12 (Clarabel's SOCPs refined to it); the fixed point stops at its QPs'
    # residual_limit 1e-10 once it stalls: measured ≤ 3e-10 μ_s p0 apart
    assert worst <= 1e-8, worst
    assert all(x.residual <= 1e-10 and y.residual <= 1e-10 for x, y in zip(a, b))
    # the law is really in play: μ falls below μ_s on slipping elements
    assert min(float(np.min(r.mu[r.state == 2])) for r in a[1:] if (r.state == 2).any()) < 0.32 - 1e-3


def test_newton_agrees_with_the_fixed_point_on_cvxpy():
    """The fixed point on the bound around socp-cvxpy (its conic solve at tolerances set from 1e-12) against Newton on
    the transient with memory, each step on its own."""
    pytest.importorskip("cvxpy")
    from rollqp.methods.socp import CvxpyMethod
    scene = _transient(0.3, distance=1.0)
    a, contact = _run(scene, _newton())
    b, _ = _run(scene, SlipContinuation(BoundFixedPoint(CvxpyMethod(tolerance=1e-12)), threshold=math.inf))
    worst = max(float(np.max(np.abs(x.t - y.t))) for x, y in zip(a, b)) / (0.32 * contact.scales.stress)
    print(f"cvxpy: max |t_newton - t_fixed point| = {worst:.2e} mu_s p0")
    assert worst <= 1e-8, worst      # as with Clarabel: both at rollqp's residual 1e-10 or below


def test_newton_agrees_with_the_fixed_point_in_steady_rolling():
    """Steady rolling (no memory): Newton's direct steady solve against the fixed point on the conic method
    marched to the steady state."""
    scene = _transient(0.0, distance=0.5).replace(**{"load.start": "rolling", "load.tangential": 0.6})
    a, contact = _run(scene, _newton())
    b, _ = _run(scene, _fixed_point())
    unit = 0.32 * contact.scales.stress
    worst = float(np.max(np.abs(a[0].t - b[0].t))) / unit
    print(f"steady: max |t_newton - t_fixed point| = {worst:.2e} mu_s p0")
    assert (a[0].state == 2).any() and (a[0].state == 1).any()
    # the march stops when a step changes the tractions by less than the tolerance 1e-12 μ_s p0: measured
    # within 1e-9 (the march's contraction factor ~0.9 turns 1e-12 per step into 1e-11 from the fixed point)
    assert worst <= 1e-8, worst


def test_the_selected_solution_is_every_methods_and_the_path_is_reported():
    """The composed methods (the path from the frozen bound, then each method's own solve from its end) return
    the same solution, and each step says how the path went."""
    scene = _transient(0.3, distance=1.0)
    a, contact = _run(scene, "newton")
    b, _ = _run(scene, "qp-clarabel")
    unit = 0.32 * contact.scales.stress
    assert max(float(np.max(np.abs(x.t - y.t))) / unit for x, y in zip(a, b)) <= 1e-8
    assert all("points" in r.info["tangential"]["path"] for r in a[1:])


def test_a_long_memory_holds_the_static_value():
    """With the memory length far beyond the run (L = 1e6 a) the coefficient barely moves from μ_s: the run is
    Coulomb's at μ_s to the memory's weight 1 − w = Δq/(L + Δq)."""
    falling, contact = _run(_transient(1e6), "newton")
    coulomb = _run(_transient(1e6).replace(**{"contact.friction": 0.32}), "newton")[0]
    unit = 0.32 * contact.scales.stress
    for x, y in zip(falling, coulomb):
        # measured: μ within 9.6e-9 of μ_s, the tractions within 1.0e-8 μ_s p0 of Coulomb's (Δμ (1 − w) = 0.12
        # Δq/L ≈ 1e-8 per step of Δq ≈ 0.1 a, accumulated over a few steps where the material stays in slip)
        assert np.max(np.abs(x.mu - 0.32)) <= 1e-7
        assert np.max(np.abs(x.t - y.t)) <= 1e-7 * unit


def test_the_memory_is_carried_with_the_material():
    """A step's μ̄ is the last step's coefficient moved by Δq along x: with the tangential force released (Fx → 0,
    all stick, the slip 0 where the material rests) μ recovers toward μ_s from the leading edge, row by row."""
    scene = _transient(0.5)
    recs, contact = _run(scene, "newton")
    last = recs[-1]
    law = contact.slip_bound("rolling", scene.dq, scene.load.direction, last.mu)
    w = law.weight
    prev = last.mu.reshape(contact.grid.shape)
    moved = law.previous.reshape(contact.grid.shape)
    # d = −1: the material moves towards −x; what is at x_i now was at x_i + Δq: one element per step here
    step = round(scene.dq / contact.grid.dx)
    assert step == 1 and 0 < w < 1
    assert np.allclose(moved[:, :-step], prev[:, step:], rtol=0, atol=1e-15)
    assert np.all(moved[:, -step:] == 0.32)          # entering material brings the static value


BAD = [
    ({"rolling_speed": -1.0}, "contact.friction.rolling_speed:", "> 0"),
    ({"memory": -0.1}, "contact.friction.memory:", ">= 0"),
    ({"velocity": 0.0}, "contact.friction.velocity:", "> 0"),
    ({"kinetic": 0.5}, "contact.friction.static:", ">= kinetic"),
]


@pytest.mark.parametrize("change,key,range_", BAD)
def test_bad_law_on_a_grid_is_one_line_naming_the_key(change, key, range_):
    with pytest.raises(InputError) as err:
        _transient(**change)
    msg = str(err.value)
    assert msg.startswith(key) and range_ in msg and "\n" not in msg, msg


def test_a_memory_needs_a_braked_start():
    with pytest.raises(InputError) as err:
        _transient(0.3).replace(**{"load.start": "rolling", "load.tangential": 0.3})
    msg = str(err.value)
    assert msg.startswith("contact.friction.memory:") and "braked" in msg and "\n" not in msg, msg


def test_a_missing_rolling_speed_is_named():
    scene = rollqp.load_scene("cattaneo-3d")
    with pytest.raises(InputError) as err:
        scene.replace(**{"contact.friction": {"law": "rational", "static": 0.3, "kinetic": 0.2, "velocity": 1.0}})
    assert str(err.value).startswith("contact.friction.rolling_speed:")


def test_no_warning_where_the_path_is_followed():
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        _run(_transient(0.0, distance=0.5), "newton")


def test_a_run_without_memory_resumes_to_the_same_result():
    scene = _transient(0.0, distance=1.0)
    a = rollqp.run(scene).arrays()
    part = {k: (v[:4] if np.ndim(v) and k not in ("x", "y") else v) for k, v in a.items()}
    b = rollqp.run(scene, resume=part).arrays()
    assert b["q"].shape == a["q"].shape
    # the resumed state solved again from the state before it (the same computation): bit for bit
    assert np.array_equal(b["px"], a["px"]) and np.array_equal(b["state"], a["state"])


def test_a_run_with_memory_resumes_from_the_stored_coefficient():
    """The memory is the stored field ``mu``: a run with one resumes to the same result; without the field, a
    one-line refusal naming --resume."""
    scene = _transient(0.3, distance=1.0)
    a = rollqp.run(scene).arrays()
    assert "mu" in a
    part = {k: (v[:4] if np.ndim(v) and k not in ("x", "y") else v) for k, v in a.items()}
    b = rollqp.run(scene, resume=part).arrays()
    assert np.array_equal(b["px"], a["px"]) and np.array_equal(b["mu"], a["mu"])
    with pytest.raises(InputError) as err:
        rollqp.run(scene, resume={k: v for k, v in part.items() if k != "mu"})
    msg = str(err.value)
    assert msg.startswith("--resume:") and "'mu'" in msg and "\n" not in msg, msg


def test_the_uniqueness_factor_and_its_eigenvalue():
    """``κ_u`` of a step from the slip operator's largest eigenvalue (power iteration, kept with the operator)
    against the dense eigenvalue problem; below 1 Newton from rest and from the last state find one solution."""
    from rollqp.methods.continuation import uniqueness_factor
    from rollqp.problem.grid import StepSolution
    from rollqp.march.grid import normal
    scene = _transient(0.0, velocity=4000.0, distance=1.0)
    recs, contact = _run(scene, "newton")
    prev = recs[-2]
    ns = normal(contact, NewtonMethod(1e-12), scene.load.normal)
    prob = contact.tangential_step("rolling", ns.p, scene.loads_at(recs[-1].q), (prev.p, prev.t), scene.dq,
                                   scene.load.direction)
    kappa = uniqueness_factor(prob)
    dense = prob.B.dense(np.arange(prob.n), np.arange(prob.n))
    lam = float(np.max(np.linalg.eigvalsh(0.5 * (dense + dense.T))))
    exact = prob.law.steepness * float(np.max(prob.p)) * lam / prob.dq
    assert abs(kappa - exact) <= 0.02 * exact, (kappa, exact)    # 30 power iterations: measured within 1 %
    assert kappa < 1
    newton = NewtonMethod(tolerance=1e-12)
    a = newton.solve(prob, StepSolution(t=prev.t, s=prev.s, xi=prev.xi, eta=prev.eta))
    b = newton.solve(prob, None)
    assert (a.info.get("fixed_point") is None) and np.max(np.abs(a.t - b.t)) <= 1e-9 * 0.32 * contact.scales.stress


def test_a_path_that_turns_back_is_reported():
    """Where the path from the frozen bound cannot pass a λ (a fold: the step has another solution beyond it) the
    method's own solution is returned with the path's report, and a RuntimeWarning says so."""
    from rollqp.errors import SolverError
    from rollqp.methods.continuation import MIN_LAMBDA_STEP

    class FoldAtHalf(NewtonMethod):
        def solve(self, problem, warm=None):
            law = getattr(problem, "law", None)
            if law is not None and law.on_path and law.blend > 0.5:
                raise SolverError("no solution past the fold", method=self.name)
            return super().solve(problem, warm)

    scene = _transient(0.0, distance=0.5)
    method = SlipContinuation(NewtonMethod(tolerance=1e-12), path_solver=FoldAtHalf(tolerance=1e-12))
    with pytest.warns(RuntimeWarning, match="turns back near λ = 0.5"):
        recs, _ = _run(scene, method)
    path = recs[-1].info["tangential"]["path"]
    assert 0.5 - MIN_LAMBDA_STEP <= path["lam"] <= 0.5 and "fold" in path["stopped"]
    assert recs[-1].residual <= 1e-10


def test_the_newton_matrix_is_the_derivative_of_its_equations():
    """eq. 3D.26s: the dense Newton matrix of a step with a falling law (partial slip, the forces prescribed) against
    central differences of Φ_T, at a point off the solution (so that the slip rows have |s| > 0)."""
    from rollqp.methods.newton.disc import tangential_rows
    from rollqp.march.grid import normal
    scene = _transient(0.3)
    recs, contact = _run(scene, "newton")
    prev = recs[-2]
    ns = normal(contact, NewtonMethod(1e-12), scene.load.normal)
    prob = contact.tangential_step("rolling", ns.p, scene.loads_at(recs[-1].q), (prev.p, prev.t, prev.mu), scene.dq,
                                   scene.load.direction)
    phi, x, J = tangential_rows(prob, prev.t, (prev.xi, prev.eta))
    x = x + 1e-3 * np.random.default_rng(0).standard_normal(x.size)
    phi, _, J = tangential_rows(prob, _traction(prob, x), (x[-2] * prob.scales.slip, x[-1] * prob.scales.slip))
    h = 1e-7
    fd = np.column_stack([(phi(x + h * e) - phi(x - h * e)) / (2 * h) for e in np.eye(x.size)])
    # central differences to O(h²) and round-off/h ~ 1e-9 (measured 9e-10 on a like step, where the ∂μ/∂|s| term
    # itself reached 6e-2: leaving it out fails this by far)
    assert np.max(np.abs(J - fd)) <= 1e-7 * np.max(np.abs(J)), np.max(np.abs(J - fd))
    assert np.any(prob.law.dmu(recs[-1].s)) and (recs[-1].state == 2).any()


def _traction(prob, x):
    """The traction ``(2, n)`` of the scaled contact tractions at the start of ``x`` (:func:`tangential_rows`)."""
    V = np.flatnonzero(prob.bound > 0)
    t = np.zeros((2, prob.n))
    t[:, V] = x[:2 * V.size].reshape(2, V.size) * prob.scales.stress
    return t


LIMIT_LAW = {"law": "exponential", "static": 0.32, "kinetic": 0.20, "velocity": 10.0, "rolling_speed": 10000.0}
LIMIT_CREEPAGE = {"kind": "ramp", "start": 0.0, "end": -6.4e-4, "over": 1.0}   # half Carter's saturation μ a/R


def _strip(law):
    """The built-in 2D falling-friction scene (a_H = 1 mm) on 20 elements over 1.2 a_H, the creepage ramped."""
    return rollqp.load_scene("falling-friction").replace(**{
        "contact.friction": law, "load.creepage": LIMIT_CREEPAGE, "discretization.elements": 20,
        "discretization.distance": 3.0})


def _long_grid(law, radius_ratio):
    """The same contact as an ellipse elongated in y (body A's lateral radius ``radius_ratio`` × 500 mm, the load set
    for a = 1 mm): 20 elements along x as on the strip, as few along y as the aspect ratio 5 allows."""
    from rollqp.closedforms.hertz_ellipse import hertz
    from rollqp.scene import scene_from_dict
    E, nu = 209920.0, 0.28
    A, B = 2 / 1000, 1 / (1000.0 * radius_ratio)
    Estar = E / (2 * (1 - nu * nu))
    FN = 1000.0 / hertz(A, B, Estar, 1000.0).a ** 3      # a ∝ FN^(1/3): a = 1 mm
    e = hertz(A, B, Estar, FN)
    ny = max(15, int(np.ceil(e.b / e.a * 20 / 5)) + 2)
    return scene_from_dict({
        "name": "long", "units": "N-mm",
        "bodies": {"A": {"radius": 500.0, "radius_y": 500.0 * radius_ratio, "E": E, "nu": nu},
                   "B": {"radius": 500.0, "radius_y": float("inf"), "E": E, "nu": nu}},
        "contact": {"dimension": 3, "friction": law},
        "load": {"normal": FN, "start": "rolling",
                 "creepage": {"longitudinal": LIMIT_CREEPAGE, "lateral": 0.0, "spin": 0.0}},
        "discretization": {"elements": [20, ny + 1 - ny % 2], "zone": [1.2, 1.2], "step": 1.0, "distance": 3.0},
        "solver": {"method": "newton", "tolerance": 1e-10}})


def _line_force_gap(law, radius_ratio, strip):
    """max over the steps of |Q/(μ_s P)| of the grid's central row (the line through y = 0) minus the strip's."""
    r = rollqp.run(_long_grid(law, radius_ratio)).arrays()
    j = r["px"].shape[1] // 2
    line = np.sum(r["px"][:, j, :], axis=1) / np.sum(0.32 * r["pn"][-1][j])
    return float(np.max(np.abs(line - strip["Q"] / (0.32 * strip["P"]))))


@pytest.mark.slow
def test_a_long_ellipse_tends_to_the_strip_under_the_falling_law():
    """The 2D limit: the central row of an ellipse elongated in y against the 2D falling-friction scene at the same
    a, p0 (to 0.2 %), creepage ramp and elements along x. Its line force approaches the strip's as b/a grows, as
    slowly under the falling law as under Coulomb's at μ_s (the approach to plane strain is the geometry's)."""
    fall2d, coul2d = (rollqp.run(_strip(law)).arrays() for law in (LIMIT_LAW, 0.32))
    gaps = [(_line_force_gap(LIMIT_LAW, k, fall2d), _line_force_gap(0.32, k, coul2d)) for k in (32.0, 128.0)]
    print(f"line force gap to the strip at b/a = 14, 31: falling {gaps[0][0]:.4f}, {gaps[1][0]:.4f}; "
          f"Coulomb {gaps[0][1]:.4f}, {gaps[1][1]:.4f}")
    # measured (docs/validation3d.md §20): falling 0.1162, 0.0620; Coulomb 0.1198, 0.0631 (at b/a = 6: 0.180, 0.188)
    assert gaps[1][0] < 0.6 * gaps[0][0]
    for fall, coul in gaps:
        assert abs(fall - coul) <= 0.1 * coul


def test_dissimilar_bodies_under_a_falling_law():
    """The normal–tangential alternation with the falling law's tangential halves (an aluminium-like body B): every
    step's path reaches λ = 1 (no warning; before the path's floor SMOOTH a round-off move of a path that stood still
    was taken for a fold), and Newton's run agrees with the conic route's."""
    scene = _transient(0.2, distance=1.0).replace(**{"bodies.B.E": 70000.0, "bodies.B.nu": 0.33})
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        a, contact = _run(scene, "newton")
    assert all(r.info["sweeps"] > 1 for r in a[1:])          # the alternation ran
    b, _ = _run(scene, "qp-clarabel")
    assert max(float(np.max(np.abs(x.t - y.t))) for x, y in zip(a, b)) <= 1e-8 * 0.32 * contact.scales.stress
