r"""The friction projection: onto the ball ``|t_i| <= b_i`` of each node, for ``k`` traction components.

A step's friction law enters rollqp's residual and the Newton methods only through
``Proj_{|·| ≤ b}`` (paper eq. 56–60; docs/theory3d.md eq. 3D.19): the interval ``[−b_i, b_i]`` for one
tangential component (``k = 1``, the strip) and the disc of radius ``b_i`` for two (``k = 2``, the
grid). One function, :func:`project`, chooses by the shape of its argument: ``(n,)`` is ``k = 1``,
``(2, n)`` is ``k = 2``; :func:`residual` is ``t − Proj(t − s)``, zero iff ``t`` lies in the ball and
opposes the slip ``s``.

Examples
--------
>>> import numpy as np
>>> from rollqp.friction.projection import project
>>> project(np.array([-2.0, 0.5, 3.0]), np.array([1.0, 1.0, 1.0]))
array([-1. ,  0.5,  1. ])
>>> project(np.array([[3.0, 0.1], [4.0, 0.0]]), np.array([1.0, 1.0]))
array([[0.6, 0.1],
       [0.8, 0. ]])
"""
from __future__ import annotations

import numpy as np

__all__ = ["project", "residual"]


def project(z: np.ndarray, b: np.ndarray, minus_b: np.ndarray | None = None, out: np.ndarray | None = None) -> np.ndarray:
    """``Proj_{|·| ≤ b_i}(z_i)`` node by node, ``b >= 0``: ``z`` of shape ``(n,)`` (the interval) or
    ``(2, n)`` (the disc, ``z_i·min(1, b_i/|z_i|)``).

    For ``k = 1``, ``minus_b`` is ``−b`` if the caller keeps it and ``out`` the array to write into (the
    Newton methods evaluate it a few times an iteration). ``np.maximum``/``np.minimum`` rather than
    ``np.clip``: the same numbers, without np.clip's Python-level dispatch.
    """
    if z.ndim == 1:
        if minus_b is None:
            minus_b = -b
        if out is None:
            return np.maximum(np.minimum(z, b), minus_b)
        u = np.minimum(z, b)
        return np.maximum(u, minus_b, out=out)
    norm = np.hypot(z[0], z[1])
    k = np.divide(b, norm, out=np.ones_like(norm), where=norm > b)   # b/|z| only where it is < 1 (no overflow)
    return z * k


def residual(t: np.ndarray, s: np.ndarray, b: np.ndarray, minus_b: np.ndarray | None = None,
             out: np.ndarray | None = None) -> np.ndarray:
    """``t − Proj_{|·| ≤ b}(t − s)`` (eq. 60, eq. 3D.19): zero iff ``|t_i| <= b_i`` and ``t_i`` opposes the
    slip ``s_i``; ``t, s`` of shape ``(n,)`` or ``(2, n)``. ``minus_b``, ``out``: as in :func:`project`."""
    if t.ndim == 1:
        if minus_b is None:
            minus_b = -b
        if out is None:
            return t - np.maximum(np.minimum(t - s, b), minus_b)
        u = np.minimum(t - s, b)
        return np.subtract(t, np.maximum(u, minus_b, out=u), out=out)  # the same operations, in place
    return t - project(t - s, b)
