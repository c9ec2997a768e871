"""Half-space influence matrices of two elastic cylinders (paper eq. 23–30; docs/formulation.md §3).

For both bodies together, at the strip nodes (collocation at ``x_i``),

.. math::

    g = h - \\delta e + A_{nn} p + A_{nt} t \\qquad \\text{(eq. 25, 30)}

    w = A_{tn} p + A_{tt} t \\qquad \\text{(eq. 28)}

with ``w = u_x^A - u_x^B``, ``p`` the pressure (≥ 0 in compression) and ``t`` the traction on
body A in +x (sign convention of docs/formulation.md §1). In the half-space approximation
(plane strain) the combined compliances are (the paper's eq. 26 and 29 with ``S^α`` of eq. 24
replaced by the half-space Green's functions):

.. math::

    A_{nn}[i,j] = A_{tt}[i,j] = \\frac{2}{\\pi E^*} K[i,j], \\quad
    K[i,j] = \\int N_j(s)\\,\\bigl(-\\ln(|x_i - s| / d_{ref})\\bigr)\\,ds

    A_{nt} = \\frac{\\beta}{E^*} S, \\quad A_{tn} = -\\frac{\\beta}{E^*} S, \\quad
    S[i,j] = \\int N_j(s)\\,\\operatorname{sgn}(x_i - s)\\,ds

``1/E* = (1-ν_A²)/E_A + (1-ν_B²)/E_B``; ``β`` is Dundurs' parameter (the paper's constant of
eq. 92 is ``2β``, Bentall–Johnson's ``κ``). The kernels are reciprocal,
``A_tn(x, s) = A_nt(s, x)``; in the discrete form this reads ``F A_tn = (F A_nt)ᵀ`` with
``F = diag(f)``, ``f_j = ∫ N_j dx``.

The reference distance ``d_ref``
--------------------------------
In 2D the surface displacements of a half-space are defined only up to a rigid constant: the
log kernel carries an arbitrary length ``d_ref``. Changing ``d → d'`` adds
``c e fᵀ`` with ``c = (2/(πE*)) ln(d'/d)`` to ``A_nn`` and ``A_tt`` (``S`` has no such constant):
a rigid normal displacement ``c P e`` and a rigid tangential one ``c Q e``.

* With ``P`` and ``Q`` prescribed the constants cancel: ``c P`` is absorbed by the approach
  ``δ`` (a multiplier), and ``c Q`` (which reaches the slip only as ``c (Q^k - Q^{k-1})/Δq``, and
  not at all in steady rolling, where ``D_up e = 0``) by the creepage ``ξ``. The tractions do
  not depend on ``d_ref``; ``δ`` and ``ξ`` do, by these rigid amounts.
* With ``δ`` or ``ξ`` prescribed they do not cancel: the tractions then depend on ``d_ref``.
  The 2D half-space approach is **undetermined** (it grows like ``ln(d_ref)``); only a
  finite-body model (BEM, docs/bem.md) fixes it. Results with prescribed ``δ`` hold for
  the chosen ``d_ref`` only.

The QP of each step needs a positive definite Hessian ``sym(F A)``. The operator with kernel
``-ln(|x - s| / d)`` is positive definite on an interval only if the interval is shorter than
``4 d`` (its logarithmic capacity is a quarter of its length), i.e. ``d_ref > L/2`` on
``[-L, L]``. The default ``d_ref = R`` (the relative radius) satisfies this with a wide margin
(``L ≪ R`` in the half-space approximation), is fixed by the geometry rather than by the mesh,
and is the natural length of the cylinder problem: it makes ``δ`` the textbook-like
``(a²/2R)(ln(2R/a) + 1/2)`` for a Hertz pressure. :func:`halfspace_influence` checks the
smallest eigenvalue and reports the smallest admissible ``d_ref`` of the discretization
(:func:`minimum_reference_distance`) when the choice is too small.

Element integrals
-----------------
On element ``e`` with centre ``c`` and half-length ``hl``, ``s = c + hl ξ`` and
``ξ_i = (x_i - c)/hl``; the moments ``I_m(ξ_i) = ∫_{-1}^{1} ξ^m ln|ξ - ξ_i| dξ`` (m = 0, 1, 2)
are evaluated in closed form with ``v = ξ - ξ_i`` and
``∫ v^k ln|v| dv = v^{k+1}/(k+1) (ln|v| - 1/(k+1))`` (limit 0 at ``v = 0``). The closed form
subtracts terms of size ``ξ_i² ln|ξ_i|`` to obtain a result of size ``ln|ξ_i|``, so it loses
digits when ``|ξ_i|`` is large; for ``|ξ_i| > 4`` (the singularity at least three half-lengths
outside the element) the moments are computed with 20-point Gauss–Legendre quadrature instead.
There the integrand is analytic in a Bernstein ellipse of parameter
``ρ = |ξ_i| + sqrt(ξ_i² - 1) > 7.8``, so the quadrature error ``~ρ^{-40} < 1e-35`` is far below
round-off. (The quadrature is applied to ``log1p(-ξ/ξ_i) + ξ/ξ_i`` only, the terms
``ln|ξ_i| - ξ/ξ_i`` being integrated exactly, so that the slightly inexact Gauss weights do not
limit the accuracy: the moments are correct to a few ulps.) The sgn kernel is piecewise
polynomial and is integrated exactly.

The strip of :class:`rollqp.strip.Strip` is a uniform lattice; the offsets ``ξ_i`` then take only
``O(n)`` distinct values (small integers), which are evaluated once and gathered. This makes the
matrices translation invariant to the last bit (exactly symmetric ``F K`` for constant elements)
and fast (a 2601-node strip in well under a second). Other node layouts (any object with ``x``,
``edges``, ``connectivity``, ``coefficients`` and ``weights``) use the general path, evaluating
every node–element pair.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..validate import positive_real
from .kernels import (FAR_FIELD, GAUSS_POINTS, assemble_elements, element_offsets,  # noqa: F401 - re-exported
                      lattice_offsets, log_moments, sgn_moments)
from . import toeplitz
from .operator import asymmetry
from .toeplitz import positive_definite_threshold

__all__ = [
    "Influence",
    "halfspace_influence",
    "log_kernel_matrix",
    "sgn_kernel_matrix",
    "undeformed_gap",
    "element_offsets",
    "min_eigenvalue",
    "minimum_reference_distance",
]

COUPLINGS = ("auto", "full", "goodman", "off")

def _kernel_matrix(strip, moments, lattice) -> np.ndarray:
    """The collocation matrix of a kernel: from its ``O(n)`` distinct entries on a uniform lattice
    (:func:`rollqp.influence.toeplitz.assemble`, bitwise the general assembly's values without
    its ``n × n_e`` index and gather temporaries), element by element otherwise."""
    if lattice is not False:
        lat = lattice_offsets(strip)
        if lat is not None and np.all(np.diff(np.asarray(strip.edges, dtype=float)) > 0):
            P, r = toeplitz.generators(strip, moments, lat)
            return toeplitz.assemble(P, r, np.asarray(strip.x).size, np.asarray(strip.connectivity).shape[0])
    return assemble_elements(strip, moments, element_offsets(strip, lattice))


def log_kernel_matrix(strip, d_ref: float, lattice: bool | None = None) -> np.ndarray:
    """Collocation matrix of the 2D log kernel (the shape of ``A_nn``, eq. 25–26).

    .. math::

        K[i, j] = \\int N_j(s)\\,\\bigl(-\\ln(|x_i - s| / d_{ref})\\bigr)\\,ds

    integrated over every element where ``N_j`` is nonzero, in closed form near the node and by
    20-point Gauss–Legendre quadrature where ``|ξ_i| > 4`` (module docstring).

    Parameters
    ----------
    strip : rollqp.strip.Strip
        Nodes ``x``, ``edges``, ``connectivity``, reference ``coefficients``, ``weights``.
    d_ref : float
        Reference distance of the logarithm (> 0, same length unit as ``x``).
    lattice : bool, optional
        The assembly path (:func:`element_offsets`): ``None`` detects a uniform lattice and
        evaluates each distinct offset once, ``False`` forces the general path.

    Returns
    -------
    K : ndarray, shape (n, n)
        Not symmetric in general; ``F K`` (``F = diag(weights)``) is symmetric up to the
        discretization error, exactly for constant elements on a uniform grid.

    Notes
    -----
    On element ``e`` (``s = c + hl ξ``)
    ``∫_e N_a (-ln(|x_i - s|/d)) ds = -hl ∫ N_a ln|ξ - ξ_i| dξ + hl ln(d/hl) ∫ N_a dξ``,
    so ``K(d') = K(d) + ln(d'/d) e fᵀ``.
    """
    d_ref = positive_real("contact.reference_distance", float(d_ref))
    K = _kernel_matrix(strip, log_moments, lattice)
    np.negative(K, out=K)
    lat = None if lattice is False else lattice_offsets(strip)
    hl = 0.5 * np.diff(np.asarray(strip.edges, dtype=float))
    if lat is not None:
        hl = np.full(hl.size, lat[2])                            # the lattice's half-length
    coef = np.asarray(strip.coefficients, dtype=float)
    w_ref = 2.0 * coef[:, 0] + 2.0 * coef[:, 2] / 3.0            # ∫_{-1}^{1} N_a dξ
    conn = np.asarray(strip.connectivity)
    shift = np.zeros(K.shape[1])
    np.add.at(shift, conn, (hl * np.log(d_ref / hl))[:, None] * w_ref[None, :])
    K += shift[None, :]
    return K


def sgn_kernel_matrix(strip, lattice: bool | None = None) -> np.ndarray:
    """Collocation matrix of the sign kernel (the shape of ``A_nt``, ``A_tn``; eq. 26, 29).

    .. math::

        S[i, j] = \\int N_j(s)\\,\\operatorname{sgn}(x_i - s)\\,ds

    exact (piecewise polynomial; ``x_i`` may be an element end or interior node).

    Parameters
    ----------
    strip : rollqp.strip.Strip
    lattice : bool, optional
        The assembly path, as for :func:`log_kernel_matrix`.

    Returns
    -------
    S : ndarray, shape (n, n)
        ``Σ_j S[i, j] = (x_i + L) - (L - x_i) = 2 x_i``; ``F S`` is antisymmetric up to the
        discretization error, exactly for constant elements on a uniform grid.
    """
    return _kernel_matrix(strip, sgn_moments, lattice)


def undeformed_gap(x, R_A: float, R_B: float = np.inf) -> np.ndarray:
    """Undeformed separation of two cylinders (eq. 10).

    .. math::

        h(x) = R_A\\bigl(1 - \\sqrt{1 - (x/R_A)^2}\\bigr) + R_B\\bigl(1 - \\sqrt{1 - (x/R_B)^2}\\bigr)

    evaluated as ``x² / (R (1 + sqrt(1 - (x/R)²)))`` per body (no cancellation; ``R = inf``, a
    plane, contributes 0). ``h ≈ x²/(2R)`` with ``1/R = 1/R_A + 1/R_B``.
    """
    x = np.asarray(x, dtype=float)
    h = np.zeros_like(x)
    for key, radius in (("R_A", R_A), ("R_B", R_B)):
        radius = float(radius)
        if not (radius > 0):
            raise InputError(key, f"the radius must be > 0 (or inf for a plane), got {radius!r}")
        if np.isinf(radius):
            continue
        u = x / radius
        if np.any(np.abs(u) > 1):
            raise InputError(key, f"the radius {radius:g} is smaller than the zone half-width "
                                  f"{np.max(np.abs(x)):g}")
        h = h + x * x / (radius * (1.0 + np.sqrt(1.0 - u * u)))
    return h


# ---------------------------------------------------------------------------------------------
# Diagnostics
# ---------------------------------------------------------------------------------------------
def _weights(F) -> np.ndarray:
    F = np.asarray(F, dtype=float)
    return np.diag(F).copy() if F.ndim == 2 else F


def min_eigenvalue(F, A) -> float:
    """Smallest eigenvalue of ``sym(F A)`` relative to the largest in magnitude.

    ``sym(F A) = (F A + (F A)ᵀ)/2`` is the Hessian the QPs use (docs/formulation.md §7).

    Parameters
    ----------
    F : ndarray, shape (n,) or (n, n)
        The weights ``f`` or ``diag(f)``.
    A : ndarray, shape (n, n)

    Returns
    -------
    float
        ``λ_min / max|λ|`` (scale-free; ``> 0`` iff positive definite).
    """
    FA = _weights(F)[:, None] * np.asarray(A, dtype=float)
    ev = np.linalg.eigvalsh(0.5 * (FA + FA.T))
    top = np.max(np.abs(ev))
    return float(ev[0] / top) if top > 0 else 0.0


def _threshold(f, K, d_ref):
    """Smallest ``d`` with ``sym(F K(d))`` positive definite, from ``K = K(d_ref)``.

    ``sym(F K(d)) = B + τ f fᵀ`` with ``B = sym(F K(d_ref))``, ``τ = ln(d/d_ref)``. If ``B`` is
    positive definite on ``f^⊥`` (true for the log kernel), ``det(B + τ f fᵀ) =
    det(B)(1 + τ fᵀB⁻¹f)`` vanishes only at ``τ* = -1/(fᵀB⁻¹f)``, and the matrix is positive
    definite exactly for ``τ > τ*``. Returns ``nan`` when ``B`` is singular.
    """
    import scipy.linalg  # here, not at import: `import rollqp` stays free of scipy.linalg
    FK = f[:, None] * K
    B = 0.5 * (FK + FK.T)
    try:
        y = scipy.linalg.cho_solve(scipy.linalg.cho_factor(B), f)     # B positive definite
    except np.linalg.LinAlgError:
        try:
            y = scipy.linalg.solve(B, f, assume_a="sym")
        except np.linalg.LinAlgError:
            return float("nan")
    q = float(f @ y)
    return float(d_ref * np.exp(-1.0 / q)) if q != 0 else float("nan")


def minimum_reference_distance(strip) -> float:
    """Smallest ``d_ref`` for which ``sym(F K)`` of this discretization is positive definite.

    The continuous bound is ``L/2``, the logarithmic capacity of ``[-L, L]`` (a quarter of its
    length); the discrete threshold converges to it under refinement (0.6277 for 40 QCE on
    ``L = 1.25``, bound 0.625). Any admissible ``d_ref`` must exceed it. Computed from
    ``K(4L)`` with the rank-one formula of ``_threshold`` (one symmetric solve, ``O(n³)``).
    """
    L = 0.5 * float(np.asarray(strip.edges)[-1] - np.asarray(strip.edges)[0])
    d0 = 4.0 * L
    return _threshold(np.asarray(strip.weights, dtype=float), log_kernel_matrix(strip, d0), d0)


# ---------------------------------------------------------------------------------------------
# The combined influence
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Influence:
    """Combined influence of both bodies at the strip nodes (eq. 25, 28, 30).

    .. math::

        g = h - \\delta e + A_{nn} p + A_{nt} t, \\qquad w = A_{tn} p + A_{tt} t

    with ``w = u_x^A - u_x^B``, ``p ≥ 0`` in compression, ``t`` on body A in +x.

    Attributes
    ----------
    Ann, Att : ndarray, shape (n, n)
        Normal–normal and tangential–tangential compliances.
    Ant : ndarray, shape (n, n) or None
        Normal displacement due to ``t``; ``None`` for coupling ``"goodman"`` and ``"off"``.
    Atn : ndarray, shape (n, n) or None
        Tangential displacement due to ``p``; ``None`` for coupling ``"off"``.
    h : ndarray, shape (n,)
        Undeformed gap at the nodes (eq. 10).
    model : str
        ``"halfspace"`` (or ``"bem"``).
    info : dict
        Model data and diagnostics (``d_ref``, ``coupling``, ``beta``, ``kappa = 2β``,
        ``Estar``, ``R``, ``asymmetry_FA``, ``min_eig_rel``, ...).
    """

    Ann: np.ndarray
    Att: np.ndarray
    Ant: np.ndarray | None
    Atn: np.ndarray | None
    h: np.ndarray
    model: str
    info: dict = field(default_factory=dict)

    @property
    def coupled(self) -> bool:
        """True when the normal problem sees ``t`` (``A_nt`` present: full coupling)."""
        return self.Ant is not None

    @property
    def has_Atn(self) -> bool:
        """True when the pressure displaces the surfaces tangentially (full or goodman)."""
        return self.Atn is not None

    @property
    def n(self) -> int:
        """Number of nodes."""
        return int(self.h.size)


def _coupling(strip, f, beta, Estar, coupling):
    """``(A_tn, A_nt or None, reciprocity defect)``: ``∓(β/E*) S`` (eq. 26, 29); ``A_nt`` with full coupling only.

    Reciprocity ``F A_tn = (F A_nt)ᵀ`` holds iff ``F S`` is antisymmetric; its defect is
    ``‖FS + (FS)ᵀ‖/‖FS‖``.
    """
    S = sgn_kernel_matrix(strip)
    defect = asymmetry(S, f, sign=-1.0)
    S *= -beta / Estar                          # A_tn in place; A_nt = -A_tn exactly (rounding is odd)
    return S, (np.negative(S) if coupling == "full" else None), defect


#: Below this many nodes the reported ``min_eig_rel`` is a full eigenvalue computation (cheap);
#: above it a Lanczos estimate on the Cholesky factor (``_lanczos_rel``).
_EIG_DENSE_MAX = 400


def _weighted_sym_upper(f, K) -> np.ndarray:
    """A new array whose upper triangle is ``sym(F K)`` (the lower one is not needed by Cholesky):
    row blocks, so the only ``n × n`` array made is the result (two copies of a matrix at the peak)."""
    n = K.shape[0]
    B = f[:, None] * K
    for i0 in range(0, n, 256):
        i1 = min(n, i0 + 256)
        B[i0:i1, i0:] = 0.5 * (B[i0:i1, i0:] + B[i0:, i0:i1].T)
    return B


def _lanczos_rel(Lf) -> float:
    """``λ_min/λ_max`` of ``B = L Lᵀ`` (``Lf`` the Fortran-ordered lower factor) by Lanczos (ARPACK,
    to round-off): ``λ_max`` from products ``L(Lᵀx)``, ``λ_min = 1/λ_max(B⁻¹)`` from triangular
    solves: ``O(n²)`` per iteration, no copy of the factor."""
    import scipy.sparse.linalg as spla
    n = Lf.shape[0]
    import scipy.linalg  # here, not at import: `import rollqp` stays free of scipy.linalg
    trmv, trsv = scipy.linalg.blas.dtrmv, scipy.linalg.blas.dtrsv

    def mul(x):
        return trmv(Lf, trmv(Lf, np.ravel(x), trans=1, lower=1), lower=1)

    def inv(x):
        return trsv(Lf, trsv(Lf, np.ravel(x), lower=1), trans=1, lower=1)

    top = spla.eigsh(spla.LinearOperator((n, n), matvec=mul, dtype=float), k=1, which="LA",
                     tol=0, return_eigenvectors=False)[0]
    low = 1.0 / spla.eigsh(spla.LinearOperator((n, n), matvec=inv, dtype=float), k=1, which="LA",
                           tol=0, return_eigenvectors=False)[0]
    return float(low / top)


#: Nodes above which a uniform strip's definiteness is decided matrix-free (:func:`_check_by_threshold`)
#: instead of by an attempted Cholesky factorization (``O(n³/3)``; the costs by size: docs/matrix-free.md).
CHOLESKY_MAX = 4096


def _indefinite(d_ref, L, lam, d_min):
    """The :class:`InputError` of a ``d_ref`` that makes ``sym(F A_nn)`` indefinite."""
    hint = (f"the smallest admissible value for this mesh is {d_min:.6g}"
            if np.isfinite(d_min) else "no admissible value could be determined")
    what = f"relative min eigenvalue {lam:.3e}" if np.isfinite(lam) else f"d_ref <= {d_min:.6g}"
    return InputError(
        "contact.reference_distance",
        f"d_ref = {d_ref:.6g} makes the normal influence matrix indefinite "
        f"({what}); it must exceed L/2 = {L / 2:.6g} "
        f"(continuous bound), {hint}; the default is the relative radius R")


def _check_by_threshold(strip, d_ref, L):
    """``(nan, d_min)`` for a uniform strip above :data:`CHOLESKY_MAX` nodes, without factorizing.

    ``sym(F K(d)) = B + τ f fᵀ`` (``B = sym(F K(4L))``, ``τ = ln(d/4L)``) is positive definite
    exactly for ``d > d_min = 4L exp(−1/(fᵀB⁻¹f))`` when ``B`` is (:func:`_threshold`);
    ``fᵀB⁻¹f`` by conjugate gradients on FFT products
    (:func:`~rollqp.influence.toeplitz.positive_definite_threshold`, the matrix-free path's check,
    docs/matrix-free.md). That ``B`` is positive definite is verified by Cholesky on every uniform
    mesh up to :data:`CHOLESKY_MAX` nodes (this module) and on each element type at the largest of
    them in the tests; ``λ_min/λ_max`` is not computed (``nan``)."""
    d_min = positive_definite_threshold(strip)
    if not (np.isfinite(d_min) and d_ref > d_min):
        raise _indefinite(d_ref, L, float("nan"), d_min)
    return float("nan"), d_min


def _check_definite(f, K, d_ref, L, strip=None):
    """``(λ_min/max|λ|, d_min)`` of ``sym(F K)`` by an attempted Cholesky factorization (``O(n³/3)``,
    no eigendecomposition); an :class:`InputError` on ``contact.reference_distance`` if it fails,
    with the smallest admissible ``d_ref`` (:func:`_threshold`). ``d_min`` from the same factor:
    ``d_ref exp(-1/(fᵀB⁻¹f))``; ``λ_min/λ_max`` exact below :data:`_EIG_DENSE_MAX` nodes, a Lanczos
    estimate on the factor above. A uniform ``strip`` above :data:`CHOLESKY_MAX` nodes is decided
    matrix-free (:func:`_check_by_threshold`)."""
    if strip is not None and K.shape[0] > CHOLESKY_MAX and lattice_offsets(strip) is not None:
        return _check_by_threshold(strip, d_ref, L)
    import scipy.linalg  # here, not at import: `import rollqp` stays free of scipy.linalg
    try:
        # the transpose of the C-ordered upper triangle is a Fortran-ordered lower one: factorized
        # in place (no third copy)
        Lf = scipy.linalg.cholesky(_weighted_sym_upper(f, K).T, lower=True, overwrite_a=True,
                                   check_finite=False)
    except np.linalg.LinAlgError:
        Lf = None
    if Lf is not None and np.all(np.diag(Lf) > 0):
        y = scipy.linalg.cho_solve((Lf, True), f, check_finite=False)
        q = float(f @ y)
        d_min = float(d_ref * np.exp(-1.0 / q)) if q != 0 else float("nan")
        lam = min_eigenvalue(f, K) if K.shape[0] <= _EIG_DENSE_MAX else _lanczos_rel(Lf)
        return lam, d_min
    del Lf
    raise _indefinite(d_ref, L, min_eigenvalue(f, K), _threshold(f, K, d_ref))


def halfspace_influence(strip, *, Estar: float, beta: float, R_A: float, R_B: float = np.inf,
                        coupling: str = "off", d_ref: float | None = None) -> Influence:
    """Half-space influence of two cylinders (eq. 25–30; docs/formulation.md §3).

    ``A_nn = A_tt = (2/(πE*)) K``, ``A_nt = (β/E*) S``, ``A_tn = -(β/E*) S`` with ``K`` of
    :func:`log_kernel_matrix` and ``S`` of :func:`sgn_kernel_matrix`; ``h`` from eq. 10.

    Parameters
    ----------
    strip : rollqp.strip.Strip
    Estar : float
        Combined modulus, ``1/E* = (1-ν_A²)/E_A + (1-ν_B²)/E_B``.
    beta : float
        Dundurs' ``β`` (``|β| ≤ 1/2``); the paper's constant (eq. 92) and Bentall–Johnson's
        ``κ`` are ``2β``.
    R_A, R_B : float
        Cylinder radii; ``R_B = inf`` for a plane. ``1/R = 1/R_A + 1/R_B``.
    coupling : {"off", "goodman", "full", "auto"}
        ``"full"`` keeps ``A_nt`` and ``A_tn``; ``"goodman"`` only ``A_tn`` (shear does not change
        the pressure); ``"off"`` neither; ``"auto"`` is ``"full"`` if ``β ≠ 0`` else ``"off"``.
        ``β = 0`` with ``"full"``/``"goodman"`` gives zero matrices.
    d_ref : float, optional
        Reference distance of the log kernel; default ``R`` (module docstring).

    Returns
    -------
    Influence

    Raises
    ------
    InputError
        ``contact.reference_distance`` when ``sym(F A_nn)`` is not positive definite (the message
        gives the smallest admissible value), and for invalid arguments.

    Notes
    -----
    On a uniform strip the matrices are filled from their ``O(n)`` Toeplitz generators. The
    positive-definiteness check is an attempted Cholesky factorization (``O(n³/3)``) up to
    :data:`CHOLESKY_MAX` nodes and, above it on a uniform strip, the rank-one threshold by FFT
    products (:func:`_check_by_threshold`); the assembly's time and memory by size are in
    docs/matrix-free.md.
    """
    Estar = positive_real("Estar", float(Estar))
    beta = float(beta)
    if not (np.isfinite(beta) and abs(beta) <= 0.5):
        raise InputError("beta", f"Dundurs' beta must lie in [-0.5, 0.5], got {beta!r}")
    if coupling not in COUPLINGS:
        raise InputError("contact.coupling", f"must be one of {', '.join(COUPLINGS)}, got {coupling!r}")
    if coupling == "auto":
        coupling = "full" if beta != 0 else "off"
    x = np.asarray(strip.x, dtype=float)
    h = undeformed_gap(x, R_A, R_B)
    R = 1.0 / (1.0 / float(R_A) + 1.0 / float(R_B))
    if d_ref is None:
        d_ref = R
    d_ref = positive_real("contact.reference_distance", float(d_ref))
    f = np.asarray(strip.weights, dtype=float)
    L = 0.5 * float(np.asarray(strip.edges)[-1] - np.asarray(strip.edges)[0])

    K = log_kernel_matrix(strip, d_ref)
    lam, d_min = _check_definite(f, K, d_ref, L, strip)

    info = {
        "d_ref": d_ref, "d_ref_min": d_min, "d_ref_min_continuous": 0.5 * L,
        "coupling": coupling, "beta": beta, "kappa": 2.0 * beta, "Estar": Estar,
        "R": R, "R_A": float(R_A), "R_B": float(R_B),
        "asymmetry_FA": asymmetry(K, f),
        "asymmetry_A": asymmetry(K, np.ones(K.shape[0])),
        "min_eig_rel": lam,
        "gauss_points": GAUSS_POINTS, "far_field": FAR_FIELD,
    }
    K *= 2.0 / (np.pi * Estar)                  # A_nn in place: the same products as (2/(πE*)) K
    Ann = Att = K                               # one read-only array for both (A_tt = A_nn)
    Ant = Atn = None
    if coupling in ("full", "goodman"):
        Atn, Ant, info["reciprocity_defect"] = _coupling(strip, f, beta, Estar, coupling)
    for M in (Ann, Ant, Atn, h):
        if M is not None:
            M.setflags(write=False)
    return Influence(Ann=Ann, Att=Att, Ant=Ant, Atn=Atn, h=h, model="halfspace", info=info)
