r"""Restarted GMRES, its orthogonalization in blocks (the 3D Krylov steps).

Saad & Schultz's GMRES(m) (Saad, *Iterative Methods for Sparse Linear Systems*, 2nd ed., alg. 9.5): the
Krylov basis ``V`` is kept as the rows of one array and each new vector is orthogonalized against all of
them at once, twice (classical Gram–Schmidt with reorthogonalization, "CGS2": two matrix–vector products
instead of one vector operation per basis vector, as accurate as modified Gram–Schmidt); the least-squares
problem is kept triangular by Givens rotations, so that the preconditioned residual is known at every
iteration without a product. The preconditioner and the stopping rule are SciPy's ``gmres``'s (left
preconditioning; the cycle ends on the true residual ``‖b − A x‖ ≤ rtol·‖b‖``, the forcing of an inexact
Newton step), so the iterates are SciPy's up to round-off.

The operator and the preconditioner are functions of a vector; on a grid of a few thousand unknowns their
FFT products cost about as much as a Python-level Arnoldi step with one vector operation per basis
vector, which this form avoids.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["gmres"]


def gmres(A, b: np.ndarray, M=None, rtol: float = 1e-3, restart: int = 80, maxiter: int = 50):
    """``(x, info)`` with ``‖b − A(x)‖ ≤ rtol·‖b‖`` (``info = 0``), or the last iterate after ``maxiter``
    restart cycles (``info > 0``). ``A``, ``M``: functions of a vector (``M`` the preconditioner, applied on
    the left as SciPy's ``gmres`` does: the inner iteration stops on the preconditioned residual
    ``‖M(b − A x)‖ ≤ rtol·‖M b‖``, the cycle on the true one, with the inner tolerance tightened fourfold
    where the two disagree).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> A = np.eye(50) * 4 + rng.random((50, 50)) / 10
    >>> b = rng.random(50)
    >>> x, info = gmres(lambda v: A @ v, b, rtol=1e-12)
    >>> info, bool(np.linalg.norm(b - A @ x) <= 1e-12 * np.linalg.norm(b))
    (0, True)
    """
    b = np.asarray(b, dtype=float)
    n = b.size
    prec = (lambda v: v) if M is None else M
    x = np.zeros(n)
    bnorm = float(np.linalg.norm(b))
    if bnorm == 0.0:
        return x, 0
    target = rtol * bnorm
    eps = np.finfo(float).eps
    m = max(1, min(int(restart), n))
    V = np.empty((m + 1, n))
    R = np.zeros((m + 1, m))          # the Hessenberg matrix, made triangular by the rotations
    cs, sn = [0.0] * m, [0.0] * m
    factor = 1.0
    Mb = float(np.linalg.norm(prec(b)))
    r = b.copy()
    for _ in range(int(maxiter)):
        ptol = Mb * min(factor, rtol)
        v0 = prec(r)
        beta = float(np.linalg.norm(v0))
        V[0] = v0 / beta
        g = [0.0] * (m + 1)
        g[0] = beta
        k, breakdown, presid = 0, False, np.inf
        for j in range(m):
            w = prec(A(V[j]))
            h0 = float(np.linalg.norm(w))
            Vj = V[:j + 1]
            h = Vj @ w
            w -= h @ Vj
            h2 = Vj @ w                 # the second pass (CGS2)
            w -= h2 @ Vj
            h += h2
            hn = float(np.linalg.norm(w))
            breakdown = hn <= eps * h0
            col = h.tolist() + [0.0 if breakdown else hn]
            for i in range(j):          # the earlier rotations on the new column
                a, c = col[i], col[i + 1]
                col[i], col[i + 1] = cs[i] * a + sn[i] * c, -sn[i] * a + cs[i] * c
            a, c = col[j], col[j + 1]
            rho = math.hypot(a, c)
            cs[j], sn[j] = (1.0, 0.0) if rho == 0.0 else (a / rho, c / rho)
            col[j], col[j + 1] = rho, 0.0
            g[j + 1] = -sn[j] * g[j]
            g[j] = cs[j] * g[j]
            R[:j + 2, j] = col
            presid = abs(g[j + 1])
            k = j + 1
            if presid <= ptol or breakdown:
                break
            V[j + 1] = w / hn
        y = np.zeros(k)
        for i in range(k - 1, -1, -1):  # back substitution on the triangle
            y[i] = (g[i] - R[i, i + 1:k] @ y[i + 1:]) / R[i, i] if R[i, i] != 0.0 else 0.0
        x = x + y @ V[:k]
        r = b - A(x)
        if float(np.linalg.norm(r)) <= target:
            return x, 0
        if breakdown:
            break
        if presid <= ptol:
            factor = max(eps, 0.25 * factor)
    return x, int(maxiter) * m
