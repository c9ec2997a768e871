"""True-geometry influence by a 2D plane-strain elastostatic BEM (paper §2.3, eq. 23–30).

Each roller α is an annulus, outer radius ``R`` and inner radius ``r`` (the shaft), whose
inner boundary is welded to a rigid shaft (``u = 0``) and whose outer boundary is
traction-free except the contact strip. The boundary integral equation (Kelvin's plane-strain
fundamental solution, collocation at the nodes)

.. math::

    c(y)\\,u(y) + \\int_\\Gamma T(x, y)\\,u(x)\\,d\\Gamma_x = \\int_\\Gamma U(x, y)\\,t(x)\\,d\\Gamma_x

discretized with quadratic elements gives ``H u = G t`` (eq. 23). Condensing every variable
that is not a contact-node displacement (eq. 24) gives the body's contact compliance
``S^α``: column ``j`` is the displacement of the strip nodes due to a unit nodal traction of
shape ``N_j`` (the strip's own shape function). Both bodies are combined into the matrices of
:class:`~rollqp.influence.halfspace.Influence` (eq. 25–30) in the project's sign convention
(docs/formulation.md §1, §3).

Discretization
--------------
* **Elements**: quadratic elements (nodes at ``ξ = -1, 0, 1``, shape functions of
  :class:`~rollqp.strip.Strip`) on the *exact* circular arcs, ``θ(ξ) = θ_c + φ ξ``: the fields
  (displacements, tractions) are quadratic in the arc parameter, the geometry is the circle
  itself (constant Jacobian ``R|φ|``, exact normals). Quadratic isoparametric geometry would
  add a radial error ``≈ φ⁴/10`` per element, 1e-3 of the radius on the large elements of the
  graded outer mesh; the exact arc removes that error at no cost.
* **Meshes**: the outer boundary is the scene's strip (``[-L, L]`` mapped onto the circle by
  arc length, the strip elements *are* BEM elements, so every strip node is a BEM node) plus
  ``n_outer`` elements (default 19, the paper's) graded geometrically away from the strip:
  sizes ``min(Le·q^m, cap)``, ``m = 1, 2, …`` from each end of the strip towards the point
  opposite the contact, with ``cap = MAX_ANGLE_FACTOR·2πR/n_outer`` (1.36 times the uniform
  size) and ``q`` such that the elements close the circle. The inner boundary has
  ``n_inner`` equal elements (default 16). Without a strip (``strip_edges=None``, the ring
  alone) the outer elements are equal.
* **Displacements** are continuous (global nodes); **tractions** are element-wise
  (discontinuous at element ends): they are known on the outer boundary, so a strip traction
  ``N_j`` of constant, linear or quadratic strip elements is represented exactly, and on the
  inner boundary they are the unknowns (continuous there, the boundary being smooth).
* **Integration** (``n_gauss = 10`` Gauss–Legendre points per (sub-)element):

  - *regular and near-singular* pairs (collocation node ``y`` not on the element): the
    element is cut into ``m = 2^k`` equal parts with part length ``<= dist(y, element)``.
    The integrand is then analytic in a Bernstein ellipse of parameter ``ρ >= 4.2`` around
    every part, so the relative quadrature error is ``< ρ^{-20} ≈ 3e-13`` (verified in
    ``tests/test_bem.py`` against a 4× finer subdivision). This handles the adjacent
    elements of very different size (strip elements are ~1e-3 of the outer ones).
  - *singular* pairs (``y`` a node of the element, at ``ξ_0``): the element is split at
    ``ξ_0``. In ``U``, ``ln r = ln|ξ - ξ_0| + ln(r/|ξ - ξ_0|)``: the first term is integrated
    exactly against the quadratic shape functions (the closed-form log moments of
    :mod:`~rollqp.influence.halfspace`), the second is analytic. In ``T`` only the columns of
    the other two nodes are needed (``N_a(ξ_0) = 0`` makes them bounded and analytic on each
    side of ``ξ_0``).
  - *strongly singular* diagonal blocks, free term included, from the rigid-body condition
    ``H e_x = H e_y = 0`` over the whole annulus boundary (outer + inner).
* **Solution**: with ``u = 0`` on the inner boundary the unknowns are the outer
  displacements and the inner tractions; the square system is LU-factored once per body
  and solved for all ``2n`` strip load cases at once.

Geometry, frames and the rigid reference
----------------------------------------
Each body is computed in its own frame: centre at the origin, contact point at the bottom
``(0, -R)``, arc coordinate ``s`` from it in the ``+x`` direction, so the surface point is
``(R sin(s/R), -R cos(s/R))``. Body A lies above the contact (centre ``(0, R_A)`` in the
contact frame); body B's frame is rotated by 180° (centre ``(0, -R_B)``), so its arc
coordinate is ``-s`` and the node order is reversed. As in the paper's eq. 24, tractions and
displacements are taken in the **local** components at each surface point: normal (``n``,
along the inward normal ``-n̂``: the push of a pressure, and a displacement that opens the
gap) and tangential (``t``, along the tangent ``t̂`` of increasing ``s``; ``+x`` at the
contact point). With ``p`` pushing both bodies apart and ``t`` on A along ``+t̂`` (on B the
opposite, which is B's own ``+t̂'``), both bodies see the load ``(t, p)`` in their own frames
and (``J`` reverses the node order)

.. math::

    A_{nn} = C^A_{nn} + J C^B_{nn} J, \\quad A_{nt} = C^A_{nt} + J C^B_{nt} J, \\quad
    A_{tn} = C^A_{tn} + J C^B_{tn} J, \\quad A_{tt} = C^A_{tt} + J C^B_{tt} J

(eq. 26, 29; ``C^α_{ab}[i, j]``: displacement component ``a`` at node ``i`` due to the unit
load case ``N_j`` in component ``b`` of body α). Local components make a rigid rotation of a
rim (the wind-up of a roller on a thin shaft) a constant ``u_t`` and no ``u_n``: it neither
slips nor opens the gap, as it must. (Cartesian components would turn it into a spurious
tangential strain ``∝ x/R``; its size on Carter's creepage is in docs/bem.md.) Nodes of A and B are paired by arc length (material is
convected along each surface by arc length), and the undeformed gap is the separation of
the paired points along the line of centres,
``h(s) = R_A(1 - cos(s/R_A)) + R_B(1 - cos(s/R_B))`` (``= s²/2R`` to leading order).

Displacements are relative to the rigid shafts, so ``δ`` is the approach of the shaft
centres: the half-space's undetermined constant ``d_ref`` does not exist here, and a
prescribed approach or creepage is meaningful. Linearized kinematics, as in the paper: the
approach enters every gap as ``-δ`` (its normal component is ``δ cos θ``), the loads are
``P = fᵀp``, ``Q = fᵀt`` (the shaft forces are ``∫ p cos θ ± t sin θ``), and the slip is
``∂w/∂s`` without the curvature term ``u_n/R`` of the surface strain: all exact to
``O(θ²)``, ``θ = L/R_α``, i.e. ``1e-4`` for ``a/R = 0.01`` and a few per cent for the largest
contacts of the geometry study (docs/bem.md).
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from ..errors import InputError
from .halfspace import COUPLINGS, Influence, min_eigenvalue
from .kernels import log_moments as _log_moments
from .memo import Memo
from .operator import asymmetry

__all__ = ["AnnulusMesh", "annulus_mesh", "BEMBody", "body_matrices", "contact_compliance",
           "bem_influence", "contact_gap", "lame_ring", "DEFAULT_OUTER", "DEFAULT_INNER"]

#: Default element counts outside the strip and on the shaft (the paper's, §2.3).
DEFAULT_OUTER, DEFAULT_INNER = 19, 16
#: Gauss–Legendre points per (sub-)element.
N_GAUSS = 10
#: Largest number of equal parts of a near-singular element.
MAX_PARTS = 4096
#: Largest graded outer element, as a multiple of the uniform angle ``2π/n_outer`` (0.45 rad for
#: the default 19): a compromise between grading next to the strip and the size of the far
#: elements (docs/bem.md, "Meshes").
MAX_ANGLE_FACTOR = 1.36
_GX, _GW = np.polynomial.legendre.leggauss(N_GAUSS)
_COEF = np.array([[0.0, -0.5, 0.5], [1.0, 0.0, -1.0], [0.0, 0.5, 0.5]])   # N_a = c0 + c1 ξ + c2 ξ²
_XI_NODE = np.array([-1.0, 0.0, 1.0])


def _shape(xi):
    """Quadratic shape functions at ``xi``: shape ``xi.shape + (3,)``."""
    xi = np.asarray(xi, dtype=float)[..., None]
    return _COEF[:, 0] + _COEF[:, 1] * xi + _COEF[:, 2] * xi * xi


# ---------------------------------------------------------------------------------- mesh
@dataclass(frozen=True)
class AnnulusMesh:
    """Quadratic arc elements on the two circles of an annulus.

    Attributes
    ----------
    radius, shaft_radius : float
        Outer ``R`` and inner ``r``.
    theta_c, phi : ndarray, shape (E,)
        Element ``e`` is ``θ = θ_c + φ ξ``, ``ξ ∈ [-1, 1]``; ``φ > 0`` on the outer circle
        (counter-clockwise), ``φ < 0`` on the inner one (clockwise), so the domain is on the
        left and ``n = sign(φ)·(cos θ, sin θ)`` is the outward normal.
    rad : ndarray, shape (E,)
        Circle radius of each element.
    conn : ndarray, shape (E, 3)
        Global node numbers (outer nodes first).
    nodes : ndarray, shape (N, 2)
        Node coordinates.
    n_outer_nodes : int
        Nodes ``0 … n_outer_nodes-1`` are on the outer circle.
    n_outer_elements : int
        Elements ``0 … n_outer_elements-1`` are on the outer circle; the first ``n_strip`` are
        the strip's.
    n_strip : int
        Strip elements; strip BEM nodes are ``0 … 2 n_strip``.
    """

    radius: float
    shaft_radius: float
    theta_c: np.ndarray
    phi: np.ndarray
    rad: np.ndarray
    conn: np.ndarray
    nodes: np.ndarray
    n_outer_nodes: int
    n_outer_elements: int
    n_strip: int

    @property
    def n_nodes(self) -> int:
        return int(self.nodes.shape[0])

    @property
    def n_elements(self) -> int:
        return int(self.phi.size)

    @property
    def lengths(self) -> np.ndarray:
        """Arc length of each element."""
        return 2.0 * self.rad * np.abs(self.phi)

    def points(self, e, xi):
        """Positions, outward normals and Jacobians at ``xi`` on elements ``e`` (broadcast)."""
        th = self.theta_c[e] + self.phi[e] * xi
        c, s = np.cos(th), np.sin(th)
        rad = self.rad[e] * np.ones_like(th)
        sg = np.sign(self.phi[e]) * np.ones_like(th)
        return (np.stack([rad * c, rad * s], -1), np.stack([sg * c, sg * s], -1),
                self.rad[e] * np.abs(self.phi[e]) * np.ones_like(th))


def _graded_sizes(first: float, n: int, total: float, cap: float) -> np.ndarray:
    """Sizes ``min(first·q^{m_k}, cap)``, ``m_k = min(k+1, n-k)``, summing to ``total``.

    ``q >= 1`` by bisection; ``cap`` is raised to ``total/n`` if it cannot be met.
    """
    k = np.arange(n)
    m = np.minimum(k + 1, n - k)
    cap = max(cap, total / n)
    sizes = lambda q: np.minimum(first * q ** m.astype(float), cap)  # noqa: E731
    if sizes(1.0).sum() >= total:
        return sizes(1.0) * total / sizes(1.0).sum()
    lo, hi = 1.0, 2.0
    while sizes(hi).sum() < total:
        hi *= 2.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if sizes(mid).sum() < total else (lo, mid)
    out = sizes(hi)
    return out * total / out.sum()


def annulus_mesh(radius: float, shaft_radius: float, strip_edges, n_outer: int = DEFAULT_OUTER,
                 n_inner: int = DEFAULT_INNER) -> AnnulusMesh:
    """The mesh of one roller: the strip, ``n_outer`` graded elements, ``n_inner`` on the shaft.

    Parameters
    ----------
    radius, shaft_radius : float
        ``R > r > 0``.
    strip_edges : array_like or None
        Element edges of the strip in arc length from the contact point (the scene strip's
        ``edges``, increasing, ``2L < π R``); None: no strip, ``n_outer`` equal elements.
    n_outer, n_inner : int
        Elements on the rest of the outer circle (graded, see the module docstring) and on
        the inner circle (equal), each ``>= 3``.
    """
    R, r = float(radius), float(shaft_radius)
    if not (0 < r < R):
        raise InputError("shaft_radius", f"must lie in (0, radius = {R:g}), got {r!r}")
    for key, n in (("contact.bem_outer_elements", n_outer), ("contact.bem_inner_elements", n_inner)):
        if not (isinstance(n, (int, np.integer)) and not isinstance(n, bool) and 3 <= n <= 2000):
            raise InputError(key, f"must be an integer in [3, 2000], got {n!r}")
    if strip_edges is None:   # no contact strip: n_outer equal elements (the ring alone)
        h = np.pi * R / n_outer
        strip_edges, n_outer = [-h, h], n_outer - 1
    edges = np.asarray(strip_edges, dtype=float)
    ns = edges.size - 1
    span = edges[-1] - edges[0]
    if not (ns >= 1 and np.all(np.diff(edges) > 0)):
        raise InputError("strip", "element edges must be strictly increasing")
    if not span < np.pi * R:
        raise InputError("discretization.zone", f"the strip ({span:g} long) must cover less than half "
                                                f"the circumference of the roller (radius {R:g})")
    le = float(np.min(np.diff(edges)))
    free = 2.0 * np.pi * R - span
    sizes = _graded_sizes(le, int(n_outer), free, MAX_ANGLE_FACTOR * 2.0 * np.pi * R / n_outer)
    s_edges = np.concatenate([edges, edges[-1] + np.cumsum(sizes)])
    s_edges[-1] = edges[0] + 2.0 * np.pi * R                     # the circle closes on node 0
    ne_o = s_edges.size - 1
    th_o = -0.5 * np.pi + s_edges / R
    tc_o, ph_o = 0.5 * (th_o[1:] + th_o[:-1]), 0.5 * (th_o[1:] - th_o[:-1])
    n_on = 2 * ne_o
    eo = np.arange(ne_o)
    conn_o = np.stack([2 * eo, 2 * eo + 1, (2 * eo + 2) % n_on], 1)
    th_i = -0.5 * np.pi - 2.0 * np.pi * np.arange(n_inner + 1) / n_inner   # clockwise
    tc_i, ph_i = 0.5 * (th_i[1:] + th_i[:-1]), 0.5 * (th_i[1:] - th_i[:-1])
    ei = np.arange(n_inner)
    conn_i = n_on + np.stack([2 * ei, 2 * ei + 1, (2 * ei + 2) % (2 * n_inner)], 1)
    theta_c, phi = np.concatenate([tc_o, tc_i]), np.concatenate([ph_o, ph_i])
    rad = np.concatenate([np.full(ne_o, R), np.full(n_inner, r)])
    conn = np.concatenate([conn_o, conn_i])
    nodes = np.zeros((n_on + 2 * n_inner, 2))
    for a in range(3):
        th = theta_c + phi * _XI_NODE[a]
        nodes[conn[:, a]] = np.stack([rad * np.cos(th), rad * np.sin(th)], 1)
    return AnnulusMesh(R, r, theta_c, phi, rad, conn, nodes, n_on, ne_o, ns)


# ---------------------------------------------------------------------------------- kernels
def _kernels(rvec, normal, nu):
    """Kelvin plane-strain kernels for unit shear modulus: ``U`` and ``T``, shape ``(..., 2, 2)``.

    ``r = x - y`` (field minus source point), ``n`` the outward normal at ``x``:

    ``U_ij = [(3-4ν)(-ln r) δ_ij + r_,i r_,j] / (8π(1-ν))``,
    ``T_ij = -[∂r/∂n ((1-2ν) δ_ij + 2 r_,i r_,j) - (1-2ν)(r_,i n_j - r_,j n_i)] / (4π(1-ν) r)``.
    ``U`` is returned without its ``-ln r`` part, which is given separately as ``lnr`` (so
    that the singular elements can treat it analytically).
    """
    r = np.sqrt(np.sum(rvec * rvec, -1))
    d = rvec / r[..., None]
    eye = np.eye(2)
    dd = d[..., :, None] * d[..., None, :]
    U_rest = dd / (8.0 * np.pi * (1.0 - nu))
    drdn = np.sum(d * normal, -1)[..., None, None]
    skew = d[..., :, None] * normal[..., None, :] - normal[..., :, None] * d[..., None, :]
    T = -(drdn * ((1.0 - 2.0 * nu) * eye + 2.0 * dd) - (1.0 - 2.0 * nu) * skew) \
        / (4.0 * np.pi * (1.0 - nu) * r[..., None, None])
    return U_rest, np.log(r), T


def _integrate(mesh, nu, y, e, xi, w):
    """``Σ_g w_g J N_a [U, T](x(ξ_g), y)`` for pairs (``y``: (P, 2), ``e``: (P,), ``xi, w``: (P, G)).

    Returns ``Gc, Hc`` of shape (P, 3, 2, 2) (local node ``a``, load direction ``i``,
    component ``j``). ``U`` includes its log part.
    """
    x, n, J = mesh.points(e[:, None], xi)
    U_rest, lnr, T = _kernels(x - y[:, None, :], n, nu)
    cU = (3.0 - 4.0 * nu) / (8.0 * np.pi * (1.0 - nu))
    U = U_rest - cU * lnr[..., None, None] * np.eye(2)
    wN = (w * J)[..., None] * _shape(xi)                       # (P, G, 3)
    Gc = np.einsum("pga,pgij->paij", wN, U)
    Hc = np.einsum("pga,pgij->paij", wN, T)
    return Gc, Hc


def _parts(m):
    """Gauss points and weights of ``m`` equal parts of [-1, 1]: shape (m·N_GAUSS,)."""
    k = np.arange(m)[:, None]
    xi = -1.0 + (2.0 * k + 1.0 + _GX[None, :]) / m
    return xi.ravel(), np.broadcast_to(_GW[None, :] / m, (m, N_GAUSS)).ravel()


def _distances(mesh) -> np.ndarray:
    """Exact distance of every node to every arc element, shape (N, E)."""
    y = mesh.nodes
    rho = np.linalg.norm(y, axis=1)[:, None]
    ang = np.arctan2(y[:, 1], y[:, 0])[:, None]
    delta = np.angle(np.exp(1j * (ang - mesh.theta_c[None, :])))       # wrapped to (-π, π]
    inside = np.abs(delta) <= np.abs(mesh.phi)[None, :]
    ends = [np.stack([mesh.rad * np.cos(mesh.theta_c + sg * mesh.phi),
                      mesh.rad * np.sin(mesh.theta_c + sg * mesh.phi)], 1) for sg in (-1.0, 1.0)]
    dend = np.minimum(*(np.linalg.norm(y[:, None, :] - p[None], axis=-1) for p in ends))
    return np.where(inside, np.abs(rho - mesh.rad[None, :]), dend)


# ---------------------------------------------------------------------------------- assembly
@dataclass
class BEMBody:
    """The assembled BEM system of one roller (unit shear modulus).

    ``H`` (2N, 2N) acts on nodal displacements, ``G`` (2N, 6E) on element-wise tractions
    (column ``2(3e + a) + j``: element ``e``, local node ``a``, component ``j``).
    """

    mesh: AnnulusMesh
    nu: float
    H: np.ndarray
    G: np.ndarray
    seconds: float


def body_matrices(mesh: AnnulusMesh, nu: float) -> BEMBody:
    """Assemble ``H`` and ``G`` of eq. 23 (module docstring, "Integration")."""
    t0 = time.perf_counter()
    N, E = mesh.n_nodes, mesh.n_elements
    H = np.zeros((N, 2, N, 2))
    G = np.zeros((N, 2, E, 3, 2))
    # -------- classification: singular (node of the element) or subdivision level by distance
    dist = _distances(mesh)
    own = np.zeros((N, E), dtype=bool)
    own[mesh.conn, np.arange(E)[:, None]] = True
    ratio = mesh.lengths[None, :] / np.where(own, 1.0, dist)
    level = np.ceil(np.log2(np.maximum(ratio, 1.0))).astype(int)
    if np.any(level[~own] > np.log2(MAX_PARTS)):
        raise InputError("mesh", "a node lies too close to an element it does not belong to")
    # -------- regular and near-singular pairs, grouped by subdivision level
    for lev in np.unique(level[~own]):
        ii, ee = np.nonzero((level == lev) & ~own)
        xi, w = _parts(2 ** int(lev))
        P = ii.size
        for start in range(0, P, max(1, 200000 // xi.size)):
            sl = slice(start, start + max(1, 200000 // xi.size))
            i, e = ii[sl], ee[sl]
            Gc, Hc = _integrate(mesh, nu, mesh.nodes[i], e, np.broadcast_to(xi, (i.size, xi.size)),
                                np.broadcast_to(w, (i.size, w.size)))
            G[i, :, e] += Gc.transpose(0, 2, 1, 3)
            for a in range(3):
                np.add.at(H, (i, slice(None), mesh.conn[e, a]), Hc[:, a])
    # -------- singular pairs: split at the node; analytic log part
    i_s, e_s = np.nonzero(own)
    a0 = np.argmax(mesh.conn[e_s] == i_s[:, None], axis=1)
    xi0 = _XI_NODE[a0]
    gx, gw = np.polynomial.legendre.leggauss(2 * N_GAUSS)
    # left part [-1, ξ0] and right part [ξ0, 1] (zero length when ξ0 is that end)
    lo_len, hi_len = (xi0 + 1.0) / 2.0, (1.0 - xi0) / 2.0
    # (an empty part gets harmless points, ξ = 0, with zero weights)
    xi = np.concatenate([np.where(lo_len[:, None] > 0, -1.0 + lo_len[:, None] * (gx + 1.0), 0.0),
                         np.where(hi_len[:, None] > 0, xi0[:, None] + hi_len[:, None] * (gx + 1.0), 0.0)], 1)
    w = np.concatenate([lo_len[:, None] * gw, hi_len[:, None] * gw], 1)
    y = mesh.nodes[i_s]
    x, n, J = mesh.points(e_s[:, None], xi)
    U_rest, lnr, T = _kernels(x - y[:, None, :], n, nu)
    cU = (3.0 - 4.0 * nu) / (8.0 * np.pi * (1.0 - nu))
    # ln r = ln|ξ - ξ0| + ln(r/|ξ - ξ0|): the second (analytic) part by quadrature ...
    smooth = lnr - np.log(np.abs(xi - xi0[:, None]))
    U = U_rest - cU * smooth[..., None, None] * np.eye(2)
    wN = (w * J)[..., None] * _shape(xi)
    Gc = np.einsum("pga,pgij->paij", wN, U)
    # ... and the first exactly: ∫ N_a ln|ξ - ξ0| dξ from the log moments
    mom = _log_moments(xi0) @ _COEF.T                                      # (P, 3)
    Jc = mesh.rad[e_s] * np.abs(mesh.phi[e_s])
    Gc -= cU * (Jc[:, None] * mom)[..., None, None] * np.eye(2)
    G[i_s, :, e_s] += Gc.transpose(0, 2, 1, 3)
    Hc = np.einsum("pga,pgij->paij", wN, T)
    for a in range(3):
        off = a != a0                      # the node's own column comes from the rigid-body condition
        np.add.at(H, (i_s[off], slice(None), mesh.conn[e_s[off], a]), Hc[off, a])
    # -------- rigid-body condition: H e_x = H e_y = 0 (free term included)
    idx = np.arange(N)
    H[idx, :, idx, :] = 0.0
    H[idx, :, idx, :] = -H.sum(axis=2)
    return BEMBody(mesh, float(nu), H.reshape(2 * N, 2 * N), G.reshape(2 * N, 6 * E),
                   time.perf_counter() - t0)


def _solve_system(body: BEMBody, rhs_tractions: np.ndarray) -> np.ndarray:
    """Outer displacements for element-wise outer tractions (columns), ``u = 0`` on the shaft.

    ``rhs_tractions``: (6 E_outer, k). Returns (2 N_outer, k) for unit shear modulus.
    """
    mesh = body.mesh
    No, Eo = mesh.n_outer_nodes, mesh.n_outer_elements
    N, E = mesh.n_nodes, mesh.n_elements
    Gi = body.G[:, 6 * Eo:].reshape(2 * N, E - Eo, 3, 2)
    Gin = np.zeros((2 * N, N - No, 2))
    for a in range(3):
        np.add.at(Gin.transpose(1, 0, 2), mesh.conn[Eo:, a] - No, Gi[:, :, a, :].transpose(1, 0, 2))
    M = np.concatenate([body.H[:, :2 * No], -Gin.reshape(2 * N, -1)], 1)
    rhs = body.G[:, :6 * Eo] @ rhs_tractions
    X = scipy.linalg.lu_solve(scipy.linalg.lu_factor(M, check_finite=False), rhs, check_finite=False)
    return X[:2 * No]


def _strip_map(strip) -> tuple[np.ndarray, np.ndarray]:
    """BEM node of each strip node, and the element-wise nodal values of each ``N_j``.

    Returns ``nodes`` (n,) and ``values`` (n_elements, 3, n): ``N_j`` at ``ξ = -1, 0, 1`` of each
    strip element (quadratic: nodes; linear: ends; constant: mid-points).
    """
    ne = int(np.asarray(strip.edges).size - 1)
    conn = np.asarray(strip.connectivity)
    coef = np.asarray(strip.coefficients, dtype=float)
    nen = conn.shape[1]
    bem_local = {3: np.array([0, 1, 2]), 2: np.array([0, 2]), 1: np.array([1])}[nen]
    nodes = np.zeros(strip.n if hasattr(strip, "n") else np.asarray(strip.x).size, dtype=int)
    nodes[conn] = 2 * np.arange(ne)[:, None] + bem_local[None, :]
    vals_local = coef[:, 0][None, :] + coef[:, 1][None, :] * _XI_NODE[:, None] \
        + coef[:, 2][None, :] * _XI_NODE[:, None] ** 2                    # (3 ξ, nen)
    values = np.zeros((ne, 3, nodes.size))
    for b in range(nen):
        values[np.arange(ne), :, conn[:, b]] = vals_local[:, b][None, :]
    return nodes, values


def contact_compliance(strip, radius, shaft_radius, E, nu, n_outer=DEFAULT_OUTER, n_inner=DEFAULT_INNER):
    """The body's contact compliance ``S^α`` (eq. 24) in its own frame (module docstring).

    Parameters
    ----------
    strip : rollqp.strip.Strip
        The strip in arc length from the contact point.
    radius, shaft_radius, E, nu : float
        The roller.
    n_outer, n_inner : int
        Elements outside the strip and on the shaft.

    Returns
    -------
    C : ndarray, shape (2, 2, n, n)
        ``C[a, b, i, j]``: displacement component ``a`` (0: x, 1: y) at strip node ``i`` due to
        a unit traction ``N_j`` in component ``b``, relative to the rigid shaft.
    info : dict
        Mesh data, timings and the grading ratio.
    """
    t0 = time.perf_counter()
    mesh = annulus_mesh(radius, shaft_radius, strip.edges, n_outer, n_inner)
    body = body_matrices(mesh, nu)
    t1 = time.perf_counter()
    nodes, values = _strip_map(strip)
    ns, n = mesh.n_strip, nodes.size
    Eo = mesh.n_outer_elements
    # local directions, b = 0 the tangent t̂ = (-n_y, n_x) (increasing s) and b = 1 the inward
    # normal -n̂ (the push of a pressure, and a displacement that opens the gap), at the strip
    # elements' nodes (for the loads) and at the strip nodes (for the displacements)
    _, nrm, _ = mesh.points(np.arange(ns)[:, None], _XI_NODE[None, :])            # (ns, 3, 2)
    dirs = np.stack([np.stack([-nrm[..., 1], nrm[..., 0]], -1), -nrm], 2)          # (ns, 3, b, comp)
    loads = np.zeros((Eo, 3, 2, 2, n))            # (element, local node, component; case b, j)
    loads[:ns] = dirs.transpose(0, 1, 3, 2)[..., None] * values[:, :, None, None, :]
    u = _solve_system(body, loads.reshape(6 * Eo, 2 * n)).reshape(-1, 2, 2, n)[nodes]   # (i, comp, b, j)
    n_hat = mesh.nodes[nodes] / np.linalg.norm(mesh.nodes[nodes], axis=1)[:, None]
    node_dirs = np.stack([np.stack([-n_hat[:, 1], n_hat[:, 0]], -1), -n_hat], 1)    # (i, a, comp)
    Gmod = E / (2.0 * (1.0 + nu))
    C = np.einsum("iac,icbj->abij", node_dirs, u) / Gmod                            # (a, b, i, j)
    sizes = mesh.lengths[ns:Eo]
    info = {"assembly_seconds": body.seconds, "solve_seconds": time.perf_counter() - t1,
            "seconds": time.perf_counter() - t0, "nodes": mesh.n_nodes, "elements": mesh.n_elements,
            "grading_ratio": float(sizes[1] / sizes[0]) if sizes.size > 1 else 1.0,
            "largest_element_angle": float(2 * np.max(np.abs(mesh.phi))),
            "memory_bytes": int(body.H.nbytes + body.G.nbytes + 8 * (2 * mesh.n_nodes) ** 2)}
    return C, info


# ---------------------------------------------------------------------------------- closed form check
def lame_ring(mesh: AnnulusMesh, nu: float, pressure: float = 1.0, E: float = 1.0):
    """BEM radial displacement of the outer nodes under uniform outer pressure, ``u = 0`` inside.

    Returns the radial displacement ``u · n`` at every outer node (the Lamé check of
    :func:`rollqp.closedforms.lame_ring_displacement`).
    """
    body = body_matrices(mesh, nu)
    Eo = mesh.n_outer_elements
    _, n, _ = mesh.points(np.arange(Eo)[:, None], _XI_NODE[None, :])     # (Eo, 3, 2)
    t = -pressure * n
    u = _solve_system(body, t.reshape(6 * Eo, 1))[:, 0].reshape(-1, 2) / (E / (2.0 * (1.0 + nu)))
    xo = mesh.nodes[:mesh.n_outer_nodes]
    return np.sum(u * xo, 1) / np.linalg.norm(xo, axis=1)


# ---------------------------------------------------------------------------------- the influence
#: How many roller compliances a :class:`~rollqp.influence.memo.Memo` made by :func:`geometry_memo` keeps.
GEOMETRY_MEMO_SIZE = 8


def geometry_memo() -> Memo:
    """A memo for :func:`body_compliance` (at most :data:`GEOMETRY_MEMO_SIZE` rollers): what a caller that builds
    several scenes on the same rollers hands to each (:class:`~rollqp.influence.memo.Memo`)."""
    return Memo(size=GEOMETRY_MEMO_SIZE)


def body_compliance(strip, radius, shaft, E, nu, n_outer, n_inner, memo: Memo | None = None):
    """``(S, info)`` of one roller (:func:`contact_compliance`), kept in ``memo``.

    The key is the geometry itself (strip half-width, elements and element type; radius, shaft radius,
    E, ν; the outer and inner element counts): the roller's BEM assembly and condensation (``O(N³)``,
    seconds) depend on nothing else, so the two bodies of a symmetric pair, or two scenes given the same
    memo, assemble each roller once. ``S`` is read-only; ``info["cached"]`` says whether it came from
    ``memo`` (None: a memo of this call only).
    """
    memo = Memo() if memo is None else memo
    key = ("bem-body", float(strip.half_width), int(strip.n_elements), strip.element, float(radius), float(shaft),
           float(E), float(nu), int(n_outer), int(n_inner))
    cached = key in memo

    def build():
        C, info = contact_compliance(strip, radius, shaft, E, nu, n_outer, n_inner)
        C.setflags(write=False)
        return C, info

    C, info = memo.get(key, build)
    return C, dict(info, cached=cached)


def contact_gap(s, R_A, R_B):
    """Undeformed gap along the line of centres between points paired by arc length ``s``.

    ``h = R_A(1 - cos(s/R_A)) + R_B(1 - cos(s/R_B))``, evaluated as ``2R sin²(s/2R)``.
    """
    s = np.asarray(s, dtype=float)
    return sum(2.0 * R * np.sin(0.5 * s / R) ** 2 for R in (float(R_A), float(R_B)))


def bem_influence(strip, *, A=None, B=None, Estar: float = 1.0, beta: float = 0.0, coupling: str = "off",
                  n_outer: int = DEFAULT_OUTER, n_inner: int = DEFAULT_INNER, memo: Memo | None = None,
                  **_ignored) -> Influence:
    """True-geometry influence of two rollers on rigid shafts (eq. 23–30; module docstring).

    Parameters
    ----------
    strip : rollqp.strip.Strip
        The scene's strip (arc length from the contact point).
    A, B : rollqp.scene.Body
        The rollers: ``radius``, ``E``, ``nu``, ``shaft_radius`` (required).
    Estar, beta : float
        Combined modulus and Dundurs' β (for the coupling level and the report only).
    coupling : {"off", "goodman", "full", "auto"}
        As for the half-space (``"auto"``: full iff ``β ≠ 0``). For similar materials the
        BEM still has a small geometric ``A_nt``/``A_tn`` (the half-space's is zero): kept with
        ``"full"``, dropped with ``"off"``; its size is ``info["coupling_size"]``.
    n_outer, n_inner : int
        Elements outside the strip and on each shaft (defaults: the paper's 19 and 16).
    memo : Memo, optional
        Where the rollers' compliances are kept (:func:`body_compliance`; the scene's operators hand
        theirs). Default: a memo of this call, so a symmetric pair assembles one roller.
    **_ignored
        The half-space builder's ``R_A``, ``R_B`` and ``d_ref`` (``build_influence`` passes the
        same keywords to every model): the radii come from ``A`` and ``B``, and with rigid
        shafts there is no reference distance.

    Returns
    -------
    Influence
        ``model = "bem"``; ``info`` has the timings (``bem_seconds``), the memory of the
        assembled systems (``bem_memory_bytes``), ``coupling_size`` ``= ‖F A_nt‖/‖F A_nn‖``,
        the asymmetries of ``F·A`` and whether the geometric coupling was kept.
    """
    if coupling not in COUPLINGS:
        raise InputError("contact.coupling", f"must be one of {', '.join(COUPLINGS)}, got {coupling!r}")
    if coupling == "auto":
        coupling = "full" if beta != 0 else "off"
    for key, body in (("bodies.A", A), ("bodies.B", B)):
        if getattr(body, "shaft_radius", None) is None:
            raise InputError(f"{key}.shaft_radius", "is required when contact.model = 'bem' "
                                                    "(the inner radius of the roller, in (0, radius))")
    t0 = time.perf_counter()
    memo = Memo() if memo is None else memo
    CA, infoA = body_compliance(strip, A.radius, A.shaft_radius, A.E, A.nu, n_outer, n_inner, memo)
    CB, infoB = body_compliance(strip, B.radius, B.shaft_radius, B.E, B.nu, n_outer, n_inner, memo)
    J = np.arange(strip.n)[::-1]
    comb = lambda a, b: CA[a, b] + CB[a, b][np.ix_(J, J)]  # noqa: E731
    Ann, Att, Ant, Atn = comb(1, 1), comb(0, 0), comb(1, 0), comb(0, 1)
    f = np.asarray(strip.weights, dtype=float)
    FAnn = f[:, None] * Ann
    info = {"coupling": coupling, "beta": float(beta), "kappa": 2.0 * float(beta), "Estar": float(Estar),
            "R_A": float(A.radius), "R_B": float(B.radius), "R": 1.0 / (1.0 / A.radius + 1.0 / B.radius),
            "shaft_A": float(A.shaft_radius), "shaft_B": float(B.shaft_radius),
            "bem_outer_elements": int(n_outer), "bem_inner_elements": int(n_inner),
            "bem_seconds": time.perf_counter() - t0,
            "bem_assembly_seconds": infoA["assembly_seconds"] * (not infoA["cached"])
            + infoB["assembly_seconds"] * (not infoB["cached"]),
            "bem_cached": bool(infoA["cached"] and infoB["cached"]),
            "bem_assembled": int(not infoA["cached"]) + int(not infoB["cached"]),
            "bem_memory_bytes": max(infoA["memory_bytes"], infoB["memory_bytes"]),
            "bem_grading_ratio": [infoA["grading_ratio"], infoB["grading_ratio"]],
            "asymmetry_FA": asymmetry(Ann, f), "asymmetry_FAtt": asymmetry(Att, f),
            "min_eig_rel": min_eigenvalue(f, Ann),
            "coupling_size": float(np.linalg.norm(f[:, None] * Ant) / np.linalg.norm(FAnn)),
            "reciprocity_defect": float(np.linalg.norm(f[:, None] * Atn - (f[:, None] * Ant).T)
                                        / np.linalg.norm(f[:, None] * Ant)),
            "geometric_coupling": {"full": "kept (A_nt, A_tn)", "goodman": "A_tn kept, A_nt dropped",
                                   "off": "dropped"}[coupling],
            "reference": "rigid shafts (delta = approach of the shaft centres)"}
    h = contact_gap(strip.x, A.radius, B.radius)
    Ant_out = Ant if coupling == "full" else None
    Atn_out = Atn if coupling in ("full", "goodman") else None
    for M in (Ann, Att, Ant_out, Atn_out, h):
        if M is not None:
            M.setflags(write=False)
    return Influence(Ann=Ann, Att=Att, Ant=Ant_out, Atn=Atn_out, h=h, model="bem", info=info)
