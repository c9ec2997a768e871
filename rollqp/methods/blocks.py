"""Products by blocks: ``(K @ v)[rows]`` when the node sets are a few runs of consecutive nodes (the stick zone,
the slip zones, the contact of a step), at ``|rows|·|cols|`` instead of ``n²``: the Newton iterations'
(:mod:`rollqp.methods.newton.linear`) and the products a resumed run rebuilds (:mod:`rollqp.solverstate`).
numpy only (no scipy: :mod:`rollqp.solverstate` is imported with the march).

>>> import numpy as np
>>> runs(np.array([0, 1, 2, 50, 51]))
[(0, 3), (50, 52)]
"""
from __future__ import annotations

import numpy as np

__all__ = ["runs", "partial_product", "RUN_GAP", "MAX_BLOCKS"]

#: Indices closer than this are one run (a block with a few needless zeros costs less than
#: another BLAS call).
RUN_GAP = 32
#: More blocks than this: one dense product instead.
MAX_BLOCKS = 12


def runs(idx: np.ndarray, gap: int = RUN_GAP) -> list:
    """The sorted indices ``idx`` as ``(start, stop)`` runs, gaps up to ``gap`` bridged."""
    if idx.size == 0:
        return []
    brk = np.flatnonzero(np.diff(idx) > gap)
    starts = idx[np.concatenate(([0], brk + 1))]
    stops = idx[np.concatenate((brk, [idx.size - 1]))] + 1
    return list(zip(starts.tolist(), stops.tolist()))


def partial_product(K: np.ndarray, rows: np.ndarray, v: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """``(K @ v)[rows]`` for ``v`` zero outside the sorted indices ``cols``, by blocks of ``K`` (views, no copies).

    The node sets of a contact step (the stick zone, the slip zones, the contact) are a few runs
    of consecutive nodes, so the product costs ``|rows|·|cols|`` instead of ``n²``; a set in more
    than :data:`MAX_BLOCKS` blocks takes the dense product.
    """
    out = np.zeros(rows.size)
    if rows.size == 0 or cols.size == 0:
        return out
    rr, cr = runs(rows), runs(cols)
    if len(rr) * len(cr) > MAX_BLOCKS:
        return (K @ v)[rows]
    i0 = 0
    for a, b in rr:
        acc = K[a:b, cr[0][0]:cr[0][1]] @ v[cr[0][0]:cr[0][1]]
        for c0, c1 in cr[1:]:
            acc += K[a:b, c0:c1] @ v[c0:c1]
        i1 = i0 + int(np.searchsorted(rows[i0:], b))
        out[i0:i1] = acc[rows[i0:i1] - a]
        i0 = i1
    return out
