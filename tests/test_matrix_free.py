"""The matrix-free path (docs/matrix-free.md): FFT operators, sparse slip operators, mf-newton, scene checks."""
from __future__ import annotations

import numpy as np
import pytest

import rollqp

from rollqp.closedforms import hertz_half_width, hertz_peak_pressure
from rollqp.errors import InputError
from rollqp.influence import halfspace as hs
from rollqp.influence import halfspace_influence
from rollqp.influence import toeplitz as tp
from rollqp.march import march
from rollqp.matrixfree import sparse_history, sparse_steady
from rollqp.methods import get_method
from rollqp.operators import SceneOperators
from rollqp.problem import NormalStep, Scales, TangentialStep
from rollqp.scene import load_scene
from rollqp.strip import Strip

ELEMENTS = (("constant", 41), ("linear", 40), ("quadratic", 20))
# Products by FFT and by BLAS sum the same terms in another order: round-off, relative to the
# largest entry of the result (n ≤ 81 terms of one sign and size): 1e-13 leaves a margin of 100.
ROUNDOFF = 1e-13


def _rel(a, b):
    """Largest difference relative to the largest entry (absolute for an all-zero ``b``)."""
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1.0))


@pytest.mark.parametrize("element,ne", ELEMENTS)
def test_fft_products_equal_dense_matrices(element, ne):
    strip = Strip(1.25, ne, element)
    inf = halfspace_influence(strip, Estar=2.0, beta=0.3, R_A=10.0, R_B=30.0, coupling="full")
    Ann, Att, Atn, Ant = tp.halfspace_operators(strip, Estar=2.0, beta=0.3, d_ref=inf.info["d_ref"],
                                                coupling="full")
    X = np.random.default_rng(1).standard_normal((strip.n, 3))
    for op, M in ((Ann, inf.Ann), (Att, inf.Att), (Atn, inf.Atn), (Ant, inf.Ant)):
        for x in X.T:
            assert _rel(op @ x, M @ x) < ROUNDOFF, f"{element}: A x by FFT"
            assert _rel(x @ op, x @ M) < ROUNDOFF, f"{element}: xᵀ A by FFT"
        assert _rel(op @ X, M @ X) < ROUNDOFF, f"{element}: A X (several columns)"
        assert _rel(op.diagonal(), np.diagonal(M)) < ROUNDOFF, f"{element}: diagonal"
        assert _rel(op.column(strip.n // 2), M[:, strip.n // 2]) < ROUNDOFF, f"{element}: column"
        assert _rel(op.dense(), M) < ROUNDOFF, f"{element}: dense() from the generators"


@pytest.mark.parametrize("element,ne", ELEMENTS)
def test_steady_operator_products_equal_dense(element, ne):
    """Δ·d·D_up·A (eq. 48) as sparse times FFT products: products, diagonal and column as the dense
    operator's to round-off (the sparse factor adds at most three terms)."""
    from rollqp.matrixfree import SteadyOperator
    strip = Strip(1.25, ne, element)
    inf = halfspace_influence(strip, Estar=2.0, beta=0.3, R_A=10.0, R_B=30.0, coupling="full")
    _, Att, Atn, _ = tp.halfspace_operators(strip, Estar=2.0, beta=0.3, d_ref=inf.info["d_ref"], coupling="full")
    x = np.random.default_rng(2).standard_normal(strip.n)
    for d in (-1, 1):
        for op, M in ((Att, inf.Att), (Atn, inf.Atn)):
            S = SteadyOperator(sparse_steady(strip, d), op, 0.7)
            D = 0.7 * (strip.steady_operator(d) @ M)
            assert _rel(S @ x, D @ x) < ROUNDOFF and _rel(x @ S, x @ D) < ROUNDOFF
            assert _rel(S.diagonal(), np.diagonal(D)) < ROUNDOFF and _rel(S.column(5), D[:, 5]) < ROUNDOFF
            assert _rel(S.dense(), D) < ROUNDOFF


@pytest.mark.parametrize("element,ne", ELEMENTS)
def test_lattice_assembly_is_the_element_by_element_gather(element, ne):
    """The dense assembly from O(n) generators adds the same products in the same order as the
    general gather over (node, element) pairs on the same offsets: bitwise equal."""
    strip = Strip(1.25, ne, element)
    for kernel in ("log", "sgn"):
        moments = tp.kernel_moments(kernel)
        P, r = tp.generators(strip, moments)
        assert np.array_equal(tp.assemble(P, r, strip.n, ne), tp.elementwise(strip, moments))
    # and the general (non-lattice) path agrees to round-off of the offsets
    assert _rel(hs.log_kernel_matrix(strip, 3.0), hs.log_kernel_matrix(strip, 3.0, lattice=False)) < 1e-12


def test_fft_operator_needs_a_uniform_lattice():
    class Bent:
        x = np.array([-1.0, -0.2, 0.5, 1.0])
        edges = np.array([-1.2, -0.6, 0.1, 0.7, 1.2])
        connectivity = np.arange(4)[:, None]
        coefficients = np.array([[1.0, 0.0, 0.0]])
        weights = np.diff(edges)
    with pytest.raises(InputError) as exc:
        tp.generators(Bent(), tp.kernel_moments("log"))
    assert exc.value.key == "strip"


@pytest.mark.parametrize("element,ne", ELEMENTS)
def test_threshold_without_matrix_equals_dense_threshold(element, ne):
    """d_ref's admissible minimum from one CG solve (rtol 1e-10) matches the Cholesky one."""
    strip = Strip(1.25, ne, element)
    assert tp.positive_definite_threshold(strip) == pytest.approx(hs.minimum_reference_distance(strip), rel=1e-8)


@pytest.mark.parametrize("element,ne", ELEMENTS)
@pytest.mark.parametrize("formulation", ("material", "convective-local", "static"))
@pytest.mark.parametrize("direction", (-1, 1))
def test_sparse_slip_operators_equal_dense(element, ne, formulation, direction):
    strip = Strip(1.25, ne, element)
    dq = 0.3 * strip.spacing
    S = sparse_history(strip, formulation, dq, direction).toarray()
    assert np.allclose(S, strip.history_operator(formulation, dq, direction), rtol=0, atol=1e-14)
    assert np.array_equal(sparse_steady(strip, direction).toarray(), strip.steady_operator(direction))


def _hertz(element, ne, P=1e-3, R=100.0):
    a = hertz_half_width(P, R, 1.0)
    strip = Strip(1.25 * a, ne, element)
    return strip, Scales(a, hertz_peak_pressure(P, a), 1.0), hs.undeformed_gap(strip.x, R), R, P


@pytest.mark.parametrize("element,ne", ELEMENTS)
def test_mf_newton_equals_newton_on_one_step(element, ne):
    """Normal (load and approach given) and tangential (load and creepage given) steps; the two
    methods reach rollqp's residual 1e-10: the tractions agree to a few times that."""
    strip, sc, h, R, P = _hertz(element, 2 * ne)
    inf = halfspace_influence(strip, Estar=1.0, beta=0.0, R_A=R, R_B=np.inf)
    op = tp.log_operator(strip, R, 2 / np.pi)
    newton, mf = get_method("newton"), get_method("mf-newton")
    for kw in ({"P": P}, {"delta": 0.9 * newton.solve(NormalStep(A=inf.Ann, f=strip.weights, h=h, P=P,
                                                                  scales=sc)).delta}):
        a = newton.solve(NormalStep(A=inf.Ann, f=strip.weights, h=h, scales=sc, **kw))
        b = mf.solve(NormalStep(A=op, f=strip.weights, h=h, scales=sc, **kw))
        assert b.residual <= 1e-10 and np.max(np.abs(a.p - b.p)) / sc.stress < 1e-9, kw
    c = 1e-3 * sc.displacement * np.sin(strip.x / sc.length)
    for kw in ({"Q": 0.4 * 0.3 * P}, {"xi": -2e-4 * sc.slip}):
        args = dict(f=strip.weights, p=a.p, mu=0.3, c=c, dq=0.1 * sc.length, scales=sc, **kw)
        ta = newton.solve(TangentialStep(A=inf.Att, **args))
        tb = mf.solve(TangentialStep(A=op, **args))
        assert tb.residual <= 1e-10 and np.max(np.abs(ta.t - tb.t)) / (0.3 * sc.stress) < 1e-9, kw


def test_mf_newton_hertz_convergence_slope():
    """Hertz pressure (docs/formulation.md §12) by mf-newton on FFT operators: the rms error in the
    contact falls at least like h^0.9 as the mesh doubles (measured slope 1.0–1.1: 2.9e-4, 1.4e-4,
    7.4e-5 at 321, 641, 1281 nodes)."""
    errs = []
    for ne in (160, 320, 640):
        strip, sc, h, R, P = _hertz("quadratic", ne)
        op = tp.log_operator(strip, R, 2 / np.pi)
        sol = get_method("mf-newton").solve(NormalStep(A=op, f=strip.weights, h=h, P=P, scales=sc))
        inside = np.abs(strip.x) < sc.length
        exact = sc.stress * np.sqrt(1 - (strip.x[inside] / sc.length) ** 2)
        errs.append(np.sqrt(np.mean(((sol.p[inside] - exact) / sc.stress) ** 2)))
    slopes = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(slopes > 0.9), (errs, slopes)


@pytest.mark.parametrize("reference,kw", [
    ("newton", {}),                                                   # quadratic, material, similar
    pytest.param("newton", {"discretization.element": "constant", "discretization.elements": 60,
                            "discretization.formulation": "convective-local", "discretization.distance": 2.0},
                 marks=pytest.mark.slow),
    # dissimilar (full coupling): mf-newton runs the N–T alternation, stopped at 0.01 times the
    # tolerance (krylov.COUPLED_FACTOR): measured 1.1e-12 p0, 1.4e-12 μp0 from the coupled newton
    ("newton", {"discretization.element": "linear", "discretization.distance": 0.25,
                "bodies.B.E": 70000.0, "bodies.B.nu": 0.33}),
    # rolling start: mf-newton solves the steady problem directly (eq. 48, products by
    # SteadyOperator), as newton does; measured 1.1e-13 p0, 9.3e-14 μp0
    ("newton", {"load.start": "rolling", "discretization.distance": 1.0}),
    # a dissimilar rolling start (coupled steady start and coupled steps: the built-in harmonic);
    # measured 3.8e-12 p0, 4.0e-12 μp0
    pytest.param("newton", {"scene": "harmonic", "discretization.distance": 1.0}, marks=pytest.mark.slow),
])
def test_transient_matrix_free_equals_dense(reference, kw):
    """Every state of a transient (braked start, rolling steps): the dense path and the
    matrix-free one agree to 1e-10 of p0 and μ p0 (both solve to rollqp's residual 1e-10)."""
    kw = dict(kw)
    scene = load_scene(kw.pop("scene", "cattaneo-carter")).replace(**{"discretization.distance": 3.0, **kw})
    dense = list(march(scene, reference))
    mf = list(march(scene.replace(**{"solver.method": "mf-newton", "solver.operator": "matrix-free"})))
    assert len(dense) == len(mf)
    assert mf[0].phase == dense[0].phase, "a rolling start is solved directly by both (phase 'steady')"
    p0, mu = scene.p0, scene.contact.friction
    for a, b in zip(dense, mf):
        assert np.max(np.abs(a.state.p - b.state.p)) / p0 < 1e-10
        assert np.max(np.abs(a.state.t - b.state.t)) / (mu * p0) < 1e-10


def test_scene_operator_choice_and_refusals():
    base = load_scene("cattaneo-carter")
    ops = SceneOperators.build(base.replace(**{"solver.method": "mf-newton", "discretization.elements": 150}))
    assert ops.matrix_free and isinstance(ops.Ann, tp.ToeplitzOperator), "auto: FFT from the threshold"
    ops = SceneOperators.build(base.replace(**{"solver.method": "mf-newton"}))
    assert not ops.matrix_free, "auto: dense below the threshold"
    with pytest.raises(InputError) as exc:
        base.replace(**{"solver.operator": "matrix-free"})
    assert exc.value.key == "solver.operator" and "mf-newton" in str(exc.value)
    with pytest.raises(InputError) as exc:
        base.replace(**{"discretization.elements": 20001, "solver.method": "qp-osqp"})
    assert exc.value.key == "discretization.elements" and "mf-newton" in str(exc.value)
    with pytest.raises(InputError) as exc:
        base.replace(**{"solver.operator": "sparse"})
    assert exc.value.key == "solver.operator"
    huge = base.replace(**{"solver.method": "mf-newton", "discretization.elements": 1_000_000,
                           "discretization.distance": 1.0})  # its operators fit; its states go to a file as they come
    with pytest.raises(InputError) as exc:                # 10^6 elements × 10^6 states in memory: refused, sized
        rollqp.run(huge)
    assert exc.value.key == "discretization.distance" and "GiB" in str(exc.value)
    big = base.replace(**{"solver.method": "mf-newton", "discretization.elements": 50_000,
                          "discretization.distance": 0.0})
    assert big.n_nodes == 100_001, "beyond the dense limit with a matrix-free method"


@pytest.mark.parametrize("name,operator", [("stop-reverse", "matrix-free"), ("fretting", "matrix-free"),
                                           ("stop-reverse", "auto")])
def test_load_paths_matrix_free_equal_dense(name, operator):
    """load.rolled (stops, reversals, a cycle at rest) with mf-newton: every state as dense newton's.

    The static-shift steps of a stop keep the state: every node is at zero slip, those at the
    bound also at the friction limit. Loose Krylov solves flip them at random (without the stall rule and
    the dead band no set repeats: 100 set iterations and a residual of 2.4e-5 at step 97 of stop-reverse
    on the dense operator, "auto" at 81 nodes); the stall rule and the dead band prevent it. Both methods solve to
    rollqp's residual 1e-10; measured 1.2e-13 p0 and 7.7e-13 μp0."""
    scene = rollqp.load_scene(name)
    dense = list(march(scene, "newton"))
    mf = list(march(scene.replace(**{"solver.method": "mf-newton", "solver.operator": operator})))
    assert len(dense) == len(mf) == scene.n_steps + 1
    p0, mu = scene.p0, scene.contact.friction
    for a, b in zip(dense, mf):
        assert np.max(np.abs(a.state.p - b.state.p)) / p0 < 1e-10
        assert np.max(np.abs(a.state.t - b.state.t)) / (mu * p0) < 1e-10
    stops = [r.solution.iterations for r in mf if r.phase == "static-shift" and r.k > 0]
    assert stops and max(stops) <= 10, f"set iterations on the stop's steps: {stops}"


def test_load_path_history_operators_are_sparse_on_the_matrix_free_path():
    """A load path's variable steps build their history operators as the scene's own are built: sparse,
    never an n × n matrix, on the matrix-free path (O(n) memory), and equal to the dense path's."""
    import scipy.sparse

    from rollqp.kinematics import HistoryCache
    from rollqp.march import prepare
    s = rollqp.load_scene("stop-reverse").replace(**{"solver.method": "mf-newton", "solver.operator": "matrix-free"})
    _, _, ops = prepare(s)
    M = HistoryCache(ops).get(0.5 * s.dq, +1)
    assert scipy.sparse.issparse(M) and M.nnz <= 3 * ops.n
    _, _, dense_ops = prepare(s.replace(**{"solver.method": "newton", "solver.operator": "dense"}))
    Md = HistoryCache(dense_ops).get(0.5 * s.dq, +1)
    np.testing.assert_allclose(M.toarray(), Md.dense(), rtol=0, atol=1e-15)   # the same shift weights
