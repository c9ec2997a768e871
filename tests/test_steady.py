"""The direct steady rolling solve (``load.start = "rolling"`` with ``newton``/``nt-newton``).

``rollqp.march`` (``_March.steady_direct``) solves the steady problem ``s = ξ e + d·D_up w`` at once
(docs/formulation.md §9). Held here against:

* the long-run limit of the transient at constant loads: the QP methods' rolling start (which
  marches until the tractions change by less than ``rollqp.march.strip.STEADY_TOL`` a step), and the Newton
  transient from a braked start rolled 12 a_H;
* Carter's closed forms (similar bodies), with the discretization error of the mesh;
* each other: ``newton`` (coupled GNMls) and ``nt-newton`` (N–T alternation) on a dissimilar,
  fully coupled scene;
* the two transient formulations, material and convective-local, whose steady limits coincide
  exactly for linear interpolation and differ by less than the discretization error for QCE.

When the transient's limit is the direct steady state exactly (docs/formulation.md §9):

* convective-local, any Δq: ``s = ξ e + d·D_up w^{k−1} + (w^k − w^{k−1})/Δq`` has the fixed point
  ``s = ξ e + d·D_up w``, the steady slip itself;
* material, ``s = ξ e* + (w^k − R w^{k−1})/Δq``: the fixed point has ``(I − R) w/Δq``. With a
  piecewise-linear displacement interpolation (constant elements: between element centres;
  linear elements) and ``Δq`` at most one node spacing ``h``, ``(R w)_i = w_i + (Δq/h)(w_up −
  w_i)``, so ``(I − R)/Δq = d·D_up`` exactly. With QCE this holds when ``Δq = h = Le/2`` (the
  paper's ``step = 0.5``: R moves nodal values by exactly one node), not for other steps.
  Only the leading-edge node differs, and it is out of contact.

Dissimilar scene: the paper's §6.1.1 rollers with body A aluminium (G = 23000, ν = 0.31; B steel
E = 210000, ν = 0.3), β = 0.150, full coupling. Tolerances are in μp0 (tractions), p0
(pressures), relative for the creepage. Measured values are quoted in each docstring.
"""
from __future__ import annotations

import numpy as np
import pytest

import rollqp
from rollqp import closedforms as cf
from rollqp.report import rms_in_contact
from rollqp.march.strip import STEADY_TOL
from rollqp.histories import Constant

RATIO = 0.75
#: Aluminium, as in CONTACT's bentall example (G = 23000, ν = 0.31; E = 2G(1 + ν)).
ALUMINIUM = {"radius": 150.0, "E": 2 * 23000.0 * 1.31, "nu": 0.31}

#: Distance to the steady state of a constant-load march stopped when a step changes t by less
#: than STEADY_TOL (μp0): at most STEADY_TOL/(1 − ρ), ρ the per-step contraction of the
#: transient. The Carter transient loses 99 % in ~1.7 a_H (CONTACT's reference), i.e. ρ ≈ 0.92
#: per step of Le/2 on 40 QCE; 1e-6 allows ρ up to 0.99. Measured: 7e-8 … 4e-7.
MARCH_TOL = 100 * STEADY_TOL
#: Two exact solvers of the same collocation equations, each stopped at a nondimensional residual
#: of 1e-10: their solutions differ by the residual times the condition of the active-set
#: system (a few), as for the QP backends in conftest.py (5e-9 each). Measured: ≤ 1.5e-10.
SOLVER_TOL = 1e-8
#: The Newton transient rolled 12 a_H at constant loads: the transient decays by ~10× per a_H
#: (CONTACT: within 1 % from 1.65 a_H, 0.1 % from 2.6 a_H), so what is left after 12 a_H is the
#: per-step solver tolerance (1e-10). Measured: ≤ 3.3e-9 μp0 over the tests below.
TRANSIENT_TOL = 1e-7




def similar(**changes):
    """The paper's §6.1.1 scene (40 QCE, Δq = Le/2, Q/(μP) = 0.75) with changes."""
    return rollqp.load_scene("cattaneo-carter").replace(**changes) if changes else \
        rollqp.load_scene("cattaneo-carter")


def dissimilar(ratio=0.5, **changes):
    """§6.1.1's rollers with A aluminium (β = 0.150, coupling "auto" → "full")."""
    return similar(**{"bodies.A": ALUMINIUM, "load.tangential": Constant(ratio), **changes})


def steady(scene, method="newton"):
    """State 0 of a rolling start: (p, t, ξ) as arrays/float."""
    r = rollqp.run(scene.replace(**{"load.start": "rolling", "discretization.distance": 0.0}), method=method)
    assert r.meta["rolling_start"] == ("direct steady solve" if method in ("newton", "nt-newton")
                                       else "marching to steady state")
    return _state(r, 0)


def long_transient(scene, method="newton", distance=12.0):
    """The last state of a braked start rolled ``distance`` a_H at constant loads."""
    r = rollqp.run(scene.replace(**{"load.start": "braked", "discretization.distance": distance}), method=method)
    last, before = _state(r, -1), _state(r, -2)
    return last, before


def _state(r, k):
    return {"p": np.asarray(r["pn"][k]), "t": np.asarray(r["pt"][k]), "xi": float(r["creepage"][k]),
            "x": np.asarray(r["x"])}


def differences(a, b, scene):
    """max |Δt|/μp0, max |Δp|/p0, |ξ_a/ξ_b − 1|."""
    mu, p0 = scene.contact.friction, scene.p0
    return (float(np.max(np.abs(a["t"] - b["t"]))) / (mu * p0),
            float(np.max(np.abs(a["p"] - b["p"]))) / p0,
            abs(a["xi"] / b["xi"] - 1.0))


# =========================================================================== transient limits
def test_direct_steady_is_the_qp_marched_limit():
    """Paper's mesh (40 QCE, Δq = Le/2 = h, material): newton's direct steady state against
    qp-osqp's rolling start, which marches the transient at constant loads.

    The two limits are the same discrete problem (module docstring), so they differ only by
    the march's stopping distance (MARCH_TOL). Measured: 7.3e-8 μp0, ξ 1.0e-8, p 1.6e-13 p0 with the
    plain march; 1.9e-11 μp0, ξ 2.9e-12, p 2.3e-13 p0 with the Anderson-accelerated start.
    """
    scene = similar()
    direct, marched = steady(scene, "newton"), steady(scene, "qp-osqp")
    dt, dp, dxi = differences(direct, marched, scene)
    assert dt <= MARCH_TOL, f"tractions differ by {dt:.2e} μp0"
    assert dxi <= MARCH_TOL, f"creepages differ by {dxi:.2e}"
    assert dp <= SOLVER_TOL, f"pressures differ by {dp:.2e} p0 (same normal problem)"


@pytest.mark.parametrize("case, method", [
    ("similar", "newton"),
    ("dissimilar", "newton"),
    ("dissimilar", "nt-newton"),
])
def test_direct_steady_is_the_long_transients_limit(case, method):
    """Braked start rolled 12 a_H with the Newton method against the direct steady solve.

    Similar: the paper's §6.1.1 (Q/(μP) = 0.75). Dissimilar: aluminium on steel, full coupling,
    Q/(μP) = 0.5 (the direct solve by ``newton``, i.e. coupled GNMls, and by ``nt-newton``).
    Measured: 4.3e-10 μp0 (similar), 1.7e-9 μp0 and ξ 3.6e-12 (dissimilar).
    """
    scene = similar() if case == "similar" else dissimilar()
    direct = steady(scene, method)
    last, before = long_transient(scene, "newton")
    settle = float(np.max(np.abs(last["t"] - before["t"]))) / (scene.contact.friction * scene.p0)
    assert settle <= TRANSIENT_TOL, f"the transient still changes by {settle:.2e} μp0 a step after 12 a_H"
    dt, dp, dxi = differences(direct, last, scene)
    assert dt <= TRANSIENT_TOL, f"tractions differ by {dt:.2e} μp0"
    assert dp <= TRANSIENT_TOL, f"pressures differ by {dp:.2e} p0"
    assert dxi <= TRANSIENT_TOL, f"creepages differ by {dxi:.2e}"


def test_convective_local_limit_is_the_steady_state_for_any_step():
    """Convective-local with Δq = 0.3 Le (not a node spacing), dissimilar, 40 QCE: its fixed
    point is the steady slip for every Δq (module docstring). Measured: 3.3e-9 μp0, ξ 1.6e-10."""
    scene = dissimilar(**{"discretization.formulation": "convective-local", "discretization.step": 0.3})
    direct = steady(scene, "newton")
    last, _ = long_transient(scene, "newton")
    dt, dp, dxi = differences(direct, last, scene)
    assert max(dt, dp, dxi) <= TRANSIENT_TOL, f"Δt {dt:.2e} μp0, Δp {dp:.2e} p0, Δξ {dxi:.2e}"


@pytest.mark.slow
def test_coupled_direct_steady_is_the_qp_marched_limit():
    """Dissimilar, full coupling: nt-newton's direct steady state against qp-osqp's rolling start
    (N–T alternation of QPs, marched at constant loads). Measured: 3.6e-7 μp0, ξ 1.6e-8 with the plain
    march (≈ 10 s); 1.3e-10 μp0 and p0, ξ 4.7e-12 with the Anderson-accelerated start (≈ 1 s)."""
    scene = dissimilar()
    direct, marched = steady(scene, "nt-newton"), steady(scene, "qp-osqp")
    dt, dp, dxi = differences(direct, marched, scene)
    assert dt <= MARCH_TOL and dxi <= MARCH_TOL and dp <= MARCH_TOL, \
        f"Δt {dt:.2e} μp0, Δp {dp:.2e} p0, Δξ {dxi:.2e}"


# =========================================================================== formulations
@pytest.mark.parametrize("element, step", [("constant", 0.3), ("constant", 1.0), ("linear", 0.5)])
def test_material_and_convective_local_limits_coincide_for_linear_interpolation(element, step):
    """Constant and linear elements interpolate w piecewise linearly: for Δq ≤ h the material
    fixed point is the steady slip exactly (module docstring), so both transients end in the
    direct steady state. Dissimilar scene, 40 elements, 12 a_H. Measured: ≤ 1.7e-9 μp0."""
    scene = dissimilar(**{"discretization.element": element, "discretization.step": step})
    direct = steady(scene, "newton")
    for form in ("material", "convective-local"):
        last, _ = long_transient(scene.replace(**{"discretization.formulation": form}), "newton")
        dt, dp, dxi = differences(direct, last, scene)
        assert max(dt, dp, dxi) <= TRANSIENT_TOL, f"{form}: Δt {dt:.2e} μp0, Δp {dp:.2e} p0, Δξ {dxi:.2e}"


def test_material_and_convective_local_limits_agree_within_discretization_error():
    """QCE with Δq = 0.3 Le: the material shift interpolates w quadratically, so its fixed point is
    a different (equally consistent) difference of w and the two limits differ by a
    discretization error. Dissimilar scene, 40 QCE, 12 a_H.

    Bounds: the traction difference must be below the traction's own discretization error on
    this mesh, estimated as the rms difference between the 40- and 80-QCE steady states at the
    shared nodes (measured 5.3e-3 μp0; formulation difference 3.6e-4 μp0). The creepage of this
    scene scatters from mesh to mesh by ~1e-4 (|ξ_n/ξ_2n − 1| = 4e-5, 3e-6, 9e-5 for n = 20, 40,
    80) instead of converging smoothly, so its bound is the 0.1 % order of the creepage error of
    40 QCE on Carter's problem (0.58 %, docs/validation.md §5) divided by five; measured 1.6e-4,
    falling with refinement (2.5e-4, 1.6e-4, 1.0e-4, 1.1e-5 on 20, 40, 80, 160 QCE).
    """
    scene = dissimilar(**{"discretization.step": 0.3})
    mat, _ = long_transient(scene.replace(**{"discretization.formulation": "material"}), "newton")
    conv, _ = long_transient(scene.replace(**{"discretization.formulation": "convective-local"}), "newton")
    s40 = steady(scene, "newton")
    s80 = steady(scene.replace(**{"discretization.elements": 80}), "newton")
    np.testing.assert_allclose(s80["x"][::2], s40["x"], rtol=0, atol=1e-12 * scene.a_H)
    mu_p0, a = scene.contact.friction * scene.p0, scene.a_H
    mesh_error = rms_in_contact(s40["x"], a, s40["t"] - s80["t"][::2]) / mu_p0
    form_diff = rms_in_contact(mat["x"], a, mat["t"] - conv["t"]) / mu_p0
    assert 0 < form_diff <= mesh_error, \
        f"material − convective-local: rms {form_diff:.2e} μp0; mesh error 40 → 80 QCE {mesh_error:.2e} μp0"
    assert abs(mat["xi"] / conv["xi"] - 1) <= 1e-3, f"creepages differ by {abs(mat['xi'] / conv['xi'] - 1):.2e}"


@pytest.mark.slow
def test_material_and_convective_local_difference_shrinks_with_the_mesh():
    """The same on 20, 40, 80 QCE (≈ 6 s): the difference of the two limits falls with every
    refinement. Measured: ξ 2.5e-4, 1.6e-4, 1.0e-4; rms t 1.9e-2, 3.6e-4, 2.4e-4 μp0."""
    dxi, dt = [], []
    for n in (20, 40, 80):
        scene = dissimilar(**{"discretization.step": 0.3, "discretization.elements": n})
        mat, _ = long_transient(scene.replace(**{"discretization.formulation": "material"}), "newton")
        conv, _ = long_transient(scene.replace(**{"discretization.formulation": "convective-local"}), "newton")
        dxi.append(abs(mat["xi"] / conv["xi"] - 1))
        dt.append(rms_in_contact(mat["x"], scene.a_H, mat["t"] - conv["t"]) / (scene.contact.friction * scene.p0))
    assert dxi[0] > dxi[1] > dxi[2], f"creepage differences {dxi}"
    assert dt[0] > dt[1] > dt[2], f"traction differences {dt}"


# =========================================================================== Carter
def test_direct_steady_matches_carter():
    """Similar bodies, Q/(μP) = 0.75: the direct steady state against Carter's traction and
    creepage on 40 and 80 QCE (the paper's mesh and one refinement).

    The errors are the mesh's discretization error, first order (docs/validation.md §5; the
    steady state on 40 QCE is the same discrete state as the 6 a_H transient there): measured
    rms 0.636 % μp0 and ξ −0.581 % on 40 QCE, 0.322 % and −0.289 % on 80. Bounds: ≤ 1 % on 40 QCE
    (the "~0.6 %" error with room), and the 80-QCE errors at most 0.6 × the 40-QCE ones (first
    order gives 0.5; an error that does not shrink, e.g. a wrong upwind direction, fails).
    """
    errors = {}
    for n in (40, 80):
        scene = similar(**{"discretization.elements": n})
        s = steady(scene, "newton")
        x, a, p0, mu, R = s["x"], scene.a_H, scene.p0, scene.contact.friction, scene.R
        rms = rms_in_contact(x, a, s["t"] - cf.carter_traction(x, a, p0, mu, RATIO, scene.load.direction)) / (mu * p0)
        xi_c = cf.carter_creepage(a, R, mu, RATIO)
        assert np.sign(s["xi"]) == np.sign(xi_c) == -1, "ξ and Q of opposite signs"
        errors[n] = (rms, abs(s["xi"] / xi_c - 1))
    rms40, xi40 = errors[40]
    assert rms40 <= 0.01, f"Carter traction rms error {rms40:.4f} μp0 on 40 QCE"
    assert xi40 <= 0.01, f"creepage {xi40:.4%} from Carter's on 40 QCE"
    for k, name in enumerate(("traction rms", "creepage")):
        assert errors[80][k] <= 0.6 * errors[40][k], \
            f"{name} error {errors[40][k]:.2e} → {errors[80][k]:.2e} (40 → 80 QCE): not first order"


# =========================================================================== newton vs nt-newton
@pytest.mark.parametrize("ratio, mu", [(0.0, 0.1), (0.5, 0.1), (0.0, 0.3)])
def test_newton_and_nt_newton_steady_agree(ratio, mu):
    """Dissimilar, full coupling: the coupled GNMls (``newton``) and the N–T alternation
    (``nt-newton``) solve the same steady collocation equations, so they agree to solver
    tolerance. Measured: ≤ 1.5e-10 μp0 and p0, ξ ≤ 3.1e-11."""
    scene = dissimilar(ratio, **{"contact.friction": mu})
    assert scene.coupling_level == "full" and scene.beta == pytest.approx(0.1496, abs=1e-4)
    a, b = steady(scene, "newton"), steady(scene, "nt-newton")
    dt, dp, dxi = differences(a, b, scene)
    assert max(dt, dp, dxi) <= SOLVER_TOL, f"Δt {dt:.2e} μp0, Δp {dp:.2e} p0, Δξ {dxi:.2e}"


def test_rolling_start_failure_is_step_0():
    """A failure while reaching the rolling start is reported at state 0, not step 1."""
    import rollqp as _r
    scene = _r.load_scene("cattaneo-carter").replace(
        **{"load.start": "rolling", "solver.method": "newton", "solver.max_iterations": 2})
    with pytest.raises(_r.SolverError) as info:
        _r.run(scene)
    assert info.value.step == 0, f"labelled state 0: {info.value}"


def test_direct_steady_slip_matches_carter_slip():
    """The steady slip against Carter's (``closedforms.carter_slip``) on 40, 80, 160 QCE.

    Measured rms error over the contact, in units of μa/R (the slip's scale: the edge value is
    1.38 μa/R at Q/(μP) = 0.75): 1.91e-2, 9.96e-3, 5.16e-3 — first order (0.94, 0.95), as the
    tractions (docs/validation.md §5: square-root kink at the stick–slip boundary). The maximum
    error sits at that boundary and falls as √Le (7.5e-2, 5.2e-2, 3.7e-2). Bounds: ≤ 2.5e-2 on
    40 QCE (the measured error with room for solver tolerance), and each refinement at most
    0.6 × the previous (first order gives 0.5; a slip of the wrong sign or zone fails at once).
    """
    errors = []
    for n in (40, 80, 160):
        scene = similar(**{"discretization.elements": n, "load.start": "rolling", "discretization.distance": 0.0})
        r = rollqp.run(scene, method="newton")
        x, a, R, mu = np.asarray(r["x"]), scene.a_H, scene.R, scene.contact.friction
        exact = cf.carter_slip(x, a, R, mu, RATIO, scene.load.direction)
        diff = np.nan_to_num(np.asarray(r["slip"][0]) - exact)  # NaN outside the contact
        errors.append(rms_in_contact(x, a, diff) / (mu * a / R))
    assert errors[0] <= 2.5e-2, f"steady slip rms error {errors[0]:.3e} μa/R on 40 QCE"
    for coarse, fine in zip(errors, errors[1:]):
        assert fine <= 0.6 * coarse, f"slip error {coarse:.2e} → {fine:.2e}: not first order"


def test_a_failed_direct_steady_solve_falls_back_to_marching():
    """A method that declares "steady" but fails on the steady problem (as mf-newton's GMRES can at
    10,001 nodes, docs/matrix-free.md) marches to the steady state instead; the result says so in
    ``meta["start_note"]`` and reaches the direct solution to the march's tolerance (MARCH_TOL)."""
    from conftest import Delegate
    from rollqp.errors import SolverError
    from rollqp.methods import get_method

    class NoSteady(Delegate):
        def solve(self, problem, warm=None):
            if str(getattr(problem.A, "name", "")).startswith("steady"):
                raise SolverError("refused the steady problem (test double)", method=self.name, residual=1.0)
            return super().solve(problem, warm=warm)

    s = rollqp.load_scene("cattaneo-carter").replace(**{"load.start": "rolling", "discretization.distance": 0.5})
    direct = rollqp.run(s, method="newton")
    marched = rollqp.run(s, method=NoSteady(get_method("newton", tolerance=s.solver.tolerance)))
    assert "start_note" not in direct.meta
    assert "direct steady solve failed" in marched.meta["start_note"]
    assert "refused the steady problem" in marched.meta["start_note"]
    a, b = direct.arrays(), marched.arrays()
    mu = s.contact.friction
    assert np.max(np.abs(a["pt"] - b["pt"])) / (mu * s.p0) < MARCH_TOL
    from rollqp.report import summary
    assert "direct steady solve failed" in summary(b, s, "newton", 0.0)   # the run's summary table says it
