"""The kernels' element integrals on the reference element, and the offsets of a strip's nodes from its elements.

What the dense half-space matrices (:mod:`.halfspace`) and the Toeplitz operators (:mod:`.toeplitz`)
share: the moments ``I_m(ξ_i) = ∫_{-1}^{1} ξ^m k(ξ − ξ_i) dξ`` (m = 0, 1, 2) of the log and sgn
kernels, the offsets ``ξ[i, e] = (x_i − c_e)/hl_e`` of every node from every element (only the
``O(n)`` distinct ones on a uniform lattice), and the element-by-element assembly. The method of
the integrals (closed form near, Gauss–Legendre far) is in :mod:`.halfspace`'s docstring,
"Element integrals".
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError

__all__ = ["FAR_FIELD", "GAUSS_POINTS", "log_moments", "sgn_moments", "lattice_offsets", "element_offsets",
           "assemble_elements"]

#: ``|ξ_i|`` above which the log moments use Gauss–Legendre quadrature (see module docstring).
FAR_FIELD = 4.0
#: Number of Gauss–Legendre points of the far field.
GAUSS_POINTS = 20
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(GAUSS_POINTS)
# Largest deviation (in ξ) of actual offsets from the ideal lattice that is treated as round-off.
_LATTICE_TOL = 1e-10
_CHUNK = 1 << 18


def log_moments(xi: np.ndarray) -> np.ndarray:
    """``I_m(ξ_i) = ∫_{-1}^{1} ξ^m ln|ξ - ξ_i| dξ`` for m = 0, 1, 2; shape ``xi.shape + (3,)``.

    Closed form for ``|ξ_i| <= FAR_FIELD``, Gauss–Legendre beyond (module docstring).
    """
    xi = np.asarray(xi, dtype=float)
    flat = xi.ravel()
    out = np.empty((flat.size, 3))
    near = np.abs(flat) <= FAR_FIELD
    if near.any():
        z = flat[near]

        def prim(v):
            # G_k(v) = v^{k+1}/(k+1) (ln|v| - 1/(k+1)), k = 0, 1, 2; G_k(0) = 0.
            av = np.abs(v)
            lv = np.log(np.where(av > 0, av, 1.0))
            return [v ** (k + 1) / (k + 1) * (lv - 1.0 / (k + 1)) for k in range(3)]

        gp, gm = prim(1.0 - z), prim(-1.0 - z)
        d0, d1, d2 = (gp[k] - gm[k] for k in range(3))
        out[near, 0] = d0
        out[near, 1] = d1 + z * d0
        out[near, 2] = d2 + 2.0 * z * d1 + z * z * d0
    # Far field: ln|ξ - ξ_i| = ln|ξ_i| - ξ/ξ_i + [log1p(-ξ/ξ_i) + ξ/ξ_i]. The first two terms
    # are integrated exactly (moments ∫ξ^m = 2, 0, 2/3 and ∫ξ^{m+1} = 0, 2/3, 0); only the
    # O((ξ/ξ_i)²) remainder (|ξ/ξ_i| < 1/4) goes to Gauss–Legendre, so the result is accurate to
    # round-off relative to itself, also for the small odd moment.
    far = np.flatnonzero(~near)
    moments = _GAUSS_W[:, None] * _GAUSS_X[:, None] ** np.arange(3)[None, :]  # (ng, 3)
    m0 = np.array([2.0, 0.0, 2.0 / 3.0])
    m1 = np.array([0.0, 2.0 / 3.0, 0.0])
    block = _CHUNK // GAUSS_POINTS + 1
    for start in range(0, far.size, block):
        idx = far[start:start + block]
        z = flat[idx]
        u = _GAUSS_X[None, :] / z[:, None]
        rest = np.log1p(-u) + u
        out[idx] = (np.log(np.abs(z))[:, None] * m0[None, :] - (1.0 / z)[:, None] * m1[None, :]
                    + rest @ moments)
    return out.reshape(xi.shape + (3,))


def sgn_moments(xi: np.ndarray) -> np.ndarray:
    """``∫_{-1}^{1} ξ^m sgn(ξ_i - ξ) dξ`` for m = 0, 1, 2 (exact); shape ``xi.shape + (3,)``.

    With ``t = clip(ξ_i, -1, 1)``: ``∫_{-1}^{t} ξ^m - ∫_{t}^{1} ξ^m = (2 t^{m+1} - 1 - (-1)^{m+1})/(m+1)``.
    """
    t = np.clip(np.asarray(xi, dtype=float), -1.0, 1.0)
    return np.stack([2.0 * t, t * t - 1.0, (2.0 * t ** 3) / 3.0], axis=-1)


def _snap(value: float) -> float:
    """``value`` rounded to a dyadic rational with a 2^-20 step (exact small lattice numbers)."""
    return float(np.round(value * 2.0 ** 20) / 2.0 ** 20)


def lattice_offsets(strip):
    """``(values, r, hl0)`` of a uniform lattice strip, ``None`` for any other node layout.

    On a uniform lattice (nodes ``x_0 + i·Δx``, equal elements of length ``r·Δx`` with integer
    ``r``) the offsets are ``ξ[i, e] = ξ_00 + (Δx/hl)(i - r e)``: ``values[k - k_min]`` holds the
    value at ``k = i - r e``, ``k_min = -r (n_e - 1)``, computed from the ideal lattice: the
    nodes and edges of :class:`~rollqp.strip.Strip` (``linspace``) deviate from it by round-off
    only, checked to ``_LATTICE_TOL`` half-lengths. ``O(n)`` memory.
    """
    x = np.asarray(strip.x, dtype=float)
    edges = np.asarray(strip.edges, dtype=float)
    n, ne = x.size, edges.size - 1
    if n < 2:
        return None
    hl0 = 0.5 * (edges[-1] - edges[0]) / ne
    dx = (x[-1] - x[0]) / (n - 1)
    step = _snap(dx / hl0)                    # Δx / hl: 2 (constant, linear), 1 (quadratic)
    r = int(round(2.0 / step)) if step > 0 else 0
    xi00 = _snap((x[0] - 0.5 * (edges[0] + edges[1])) / hl0)
    tol = _LATTICE_TOL * hl0
    if (r >= 1 and abs(r * step - 2.0) < 1e-12
            and abs(x[0] - 0.5 * (edges[0] + edges[1]) - xi00 * hl0) <= tol
            and np.max(np.abs(x - x[0] - step * hl0 * np.arange(n))) <= tol
            and np.max(np.abs(edges - edges[0] - 2.0 * hl0 * np.arange(ne + 1))) <= tol):
        kmin = -r * (ne - 1)
        return xi00 + step * np.arange(kmin, n), r, hl0
    return None


def element_offsets(strip, lattice: bool | None = None):
    """Reference offsets ``ξ[i, e] = (x_i - c_e) / hl_e`` as ``(values, index, hl)``.

    ``values[index]`` is the (n, n_elements) offset matrix. On a uniform lattice
    (:func:`lattice_offsets`) only the distinct values are evaluated.
    ``lattice=None`` detects the lattice, ``False`` forces the general path, ``True`` requires it.
    """
    x = np.asarray(strip.x, dtype=float)
    edges = np.asarray(strip.edges, dtype=float)
    n, ne = x.size, edges.size - 1
    hl = 0.5 * np.diff(edges)
    if np.any(hl <= 0):
        raise InputError("strip", "element edges must be strictly increasing")
    if lattice is not False:
        lat = lattice_offsets(strip)
        if lat is not None:
            values, r, hl0 = lat
            index = np.arange(n)[:, None] - r * np.arange(ne)[None, :] + r * (ne - 1)
            return values, index, np.full(ne, hl0)
        if lattice:
            raise InputError("strip", "nodes are not a uniform lattice")
    centre = 0.5 * (edges[:-1] + edges[1:])
    xi = (x[:, None] - centre[None, :]) / hl[None, :]
    return xi.ravel(), np.arange(n * ne).reshape(n, ne), hl


def assemble_elements(strip, moments, offsets) -> np.ndarray:
    """``M[i, j] = Σ_e hl_e ∫_{-1}^{1} N_a(ξ) k(ξ, ξ_ie) dξ`` over the ``(e, a)`` with node ``j``.

    ``moments(values)`` returns the reference moments ``∫ ξ^m k dξ`` (m = 0, 1, 2);
    ``offsets`` is the result of :func:`element_offsets`.
    """
    values, index, hl = offsets
    coef = np.asarray(strip.coefficients, dtype=float)          # (nen, 3)
    local = moments(values) @ coef.T                            # (n_values, nen)
    conn = np.asarray(strip.connectivity)
    n = np.asarray(strip.x).size
    M = np.zeros((n, n))
    for a in range(conn.shape[1]):
        # Within one local index a, every node appears at most once: plain fancy-index add.
        M[:, conn[:, a]] += local[index, a] * hl[None, :]
    return M
