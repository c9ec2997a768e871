r"""The step programs in the Conic Benchmark Format (CBF, version 3, as CBLIB publishes it).

CBF states ``min cᵀz + c₀`` subject to ``z_j ∈ K_j`` (``VAR``, cones over consecutive variables)
and ``g = A z + b ∈ K_i`` (``CON``, cones over consecutive rows), with ``OBJACOORD`` (``c``),
``ACOORD`` (``A``, ``row col value``) and ``BCOORD`` (``b``). Its objective is linear, so the
quadratic objective of eq. 3D.22/3D.20 goes through an epigraph with a **rotated** second-order
cone ``QR = {u : 2u₁u₂ ≥ ‖u_{3:}‖², u₁, u₂ ≥ 0}``: with ``H = LLᵀ`` (Cholesky),

.. math::
    \min\ q^Tx + \tau \quad\text{s.t.}\quad (\tau,\ 1,\ L^Tx) \in \mathrm{QR}^{m+2}
    \ \Leftrightarrow\ \tau \ge \tfrac12 x^THx,

and the variables ``z = (x, τ)``. The rows, in this order:

* ``L=`` — the load rows ``a x − b`` (none where the step prescribes the creepages or the approach);
* tangential: one ``Q 3`` per element, ``(b̂_i, x_i, x_{nv+i})`` — the friction disc ``|t̂_i| ≤ b̂_i``;
* ``QR m+2`` — the epigraph.

The normal QP's ``x ≥ 0`` is the variables' cone (``VAR``: ``L+ m`` then ``F 1``); the tangential
variables are free. The optimum's ``τ`` is ``½x*ᵀHx*``, its objective the QP's. A load row's
multiplier ``y`` (eq. 3D.21, rollqp's sign: Lagrangian ``+y(ax − b)``) is minus the CBF dual of
its ``L=`` row (``c = Aᵀλ + …``, ``λ`` in the dual cone).

:func:`read` parses a CBF file into :class:`Conic` (a minimal reader: the keywords written here and
comments); :func:`standard_form` turns it into the ``Gz + s = h, s ∈ K`` form that Clarabel, SCS,
ECOS and CVXOPT take.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..errors import InputError
from .forms import ascii_text

__all__ = ["write", "read", "Conic", "standard_form", "epigraph_point", "VERSION"]

#: The CBF version written (CBLIB's: version 3 has every keyword used here; 4 adds power cones).
VERSION = 3


def _cholesky_upper(H):
    """``Lᵀ`` of ``H = LLᵀ``; a Hessian that is not positive definite is an error (the elastic energy is)."""
    try:
        return np.linalg.cholesky(H).T
    except np.linalg.LinAlgError:
        raise InputError("H", "the Hessian must be positive definite (the elastic energy)") from None


def _rows(d):
    """``(A triplets, b entries, con cones)`` of the program ``d`` (:class:`~rollqp.conicset.forms.ProgramData`)."""
    m, k = d.m, d.k
    rows, cols, vals, brow, bval, cones = [], [], [], [], [], []
    if k:
        r, c = np.nonzero(d.a)
        rows.append(r), cols.append(c), vals.append(d.a[r, c])
        brow.append(np.arange(k)), bval.append(-d.b)
        cones.append(("L=", k))
    r0 = k
    if d.kind == "tangential":
        nv = m // 2
        i = np.arange(nv)
        rows += [r0 + 3 * i + 1, r0 + 3 * i + 2]
        cols += [i, nv + i]
        vals += [np.ones(nv), np.ones(nv)]
        brow.append(r0 + 3 * i), bval.append(d.bound)
        cones += [("Q", 3)] * nv
        r0 += 3 * nv
    U = _cholesky_upper(d.H)                      # rows of Lᵀx
    ur, uc = np.nonzero(U)
    rows += [np.array([r0]), r0 + 2 + ur]
    cols += [np.array([m]), uc]
    vals += [np.ones(1), U[ur, uc]]
    brow.append(np.array([r0 + 1])), bval.append(np.ones(1))
    cones.append(("QR", m + 2))
    cat = np.concatenate
    return (cat(rows), cat(cols), cat(vals)), (cat(brow), cat(bval)), cones, r0 + m + 2


def write(path, d, comment: str = "") -> None:
    """Write the program ``d`` (:class:`~rollqp.conicset.forms.ProgramData`) as a CBF file at ``path``."""
    (ar, ac, av), (br, bv), cones, nrows = _rows(d)
    keep = bv != 0
    br, bv = br[keep], bv[keep]
    var = [("L+", d.m), ("F", 1)] if d.kind == "normal" else [("F", d.m + 1)]
    out = [f"# {ascii_text(line)}" for line in comment.splitlines()]
    out += ["VER", str(VERSION), "", "OBJSENSE", "MIN", "", "VAR", f"{d.m + 1} {len(var)}"]
    out += [f"{name} {size}" for name, size in var] + [""]
    out += ["CON", f"{nrows} {len(cones)}"] + [f"{name} {size}" for name, size in cones] + [""]
    nz = np.flatnonzero(d.q)
    out += ["OBJACOORD", str(nz.size + 1)] + [f"{j} {v!r}" for j, v in zip(nz, d.q[nz].tolist())] + [f"{d.m} 1.0", ""]
    out += ["ACOORD", str(av.size)] + [f"{r} {c} {v!r}" for r, c, v in zip(ar, ac, av.tolist())] + [""]
    out += ["BCOORD", str(bv.size)] + [f"{r} {v!r}" for r, v in zip(br, bv.tolist())] + [""]
    with open(path, "w", encoding="ascii") as f:
        f.write("\n".join(out))


def epigraph_point(d, x) -> np.ndarray:
    """The CBF variables ``z = (x, τ = ½xᵀHx)`` of a program's point ``x``."""
    x = np.asarray(x, dtype=float)
    return np.append(x, 0.5 * float(x @ (d.H @ x)))


@dataclass(frozen=True)
class Conic:
    """A CBF problem: ``min cᵀz + c0`` s.t. ``z ∈ var_cones``, ``A z + b ∈ con_cones`` (cones as
    ``(name, size)`` over consecutive entries)."""

    c: np.ndarray
    c0: float
    A: sp.csr_matrix
    b: np.ndarray
    var_cones: list
    con_cones: list
    sense: str = "MIN"


def _tokens(path):
    with open(path, encoding="ascii") as f:
        for line in f:
            line = line.strip()
            if line and not line.startswith("#"):
                yield line


def read(path) -> Conic:
    """Parse the CBF file at ``path`` (the keywords :func:`write` uses; others are an InputError)."""
    it = _tokens(path)
    n = m = 0
    c0, sense, var, con = 0.0, "MIN", [], []
    c, A, b = None, None, None
    for key in it:
        if key == "VER":
            next(it)
        elif key == "OBJSENSE":
            sense = next(it)
        elif key in ("VAR", "CON"):
            size, count = (int(v) for v in next(it).split())
            cones = [(name, int(s)) for name, s in (next(it).split() for _ in range(count))]
            if key == "VAR":
                n, var = size, cones
            else:
                m, con = size, cones
        elif key == "OBJACOORD":
            c = np.zeros(n)
            for _ in range(int(next(it))):
                j, v = next(it).split()
                c[int(j)] += float(v)
        elif key == "OBJBCOORD":
            c0 = float(next(it))
        elif key == "ACOORD":
            t = np.array([next(it).split() for _ in range(int(next(it)))], dtype=float).reshape(-1, 3)
            A = sp.csr_matrix((t[:, 2], (t[:, 0].astype(int), t[:, 1].astype(int))), shape=(m, n))
        elif key == "BCOORD":
            b = np.zeros(m)
            for _ in range(int(next(it))):
                i, v = next(it).split()
                b[int(i)] += float(v)
        else:
            raise InputError(str(path), f"CBF keyword {key!r} is not read by this reader")
    A = A if A is not None else sp.csr_matrix((m, n))
    return Conic(c if c is not None else np.zeros(n), c0, A, b if b is not None else np.zeros(m), var, con, sense)


def standard_form(p: Conic):
    """``(c, G, h, dims, Aeq, beq)``: ``min cᵀz`` s.t. ``Gz + s = h``, ``s`` in ``dims`` — first
    ``dims["l"]`` nonnegative entries, then second-order cones of sizes ``dims["q"]`` — and
    ``Aeq z = beq``. A ``QR`` cone becomes ``Q`` by ``(u₁ + u₂, u₁ − u₂)/√2``; ``L-`` rows are negated.
    A ``Q``/``QR`` block's dual is the dual of its rows in this order."""
    if p.sense != "MIN":
        raise InputError("OBJSENSE", "only MIN problems are read")
    n = p.c.size
    eq, lin, soc = [], [], []
    blocks = [("var", name, s) for name, s in p.var_cones] + [("con", name, s) for name, s in p.con_cones]
    pos = {"var": 0, "con": 0}
    for where, name, s in blocks:
        i0 = pos[where]
        pos[where] += s
        if where == "var":
            M, g = sp.identity(n, format="csr")[i0:i0 + s], np.zeros(s)
        else:
            M, g = p.A[i0:i0 + s], p.b[i0:i0 + s]
        if name == "F":
            continue
        if name == "L=":
            eq.append((M, -g))
        elif name in ("L+", "L-"):
            sign = 1.0 if name == "L+" else -1.0
            lin.append((-sign * M, sign * g))
        elif name in ("Q", "QR"):
            T = sp.identity(s, format="csr")
            if name == "QR":
                T = sp.lil_matrix((s, s))
                T[0, 0] = T[0, 1] = T[1, 0] = 1 / np.sqrt(2)
                T[1, 1] = -1 / np.sqrt(2)
                for j in range(2, s):
                    T[j, j] = 1.0
                T = T.tocsr()
            soc.append((-(T @ M), T @ g, s))
        else:
            raise InputError("cone", f"cone {name!r} is not read by this reader")
    G = sp.vstack([M for M, _ in lin] + [M for M, _, _ in soc], format="csc") if lin or soc else sp.csc_matrix((0, n))
    h = np.concatenate([g for _, g in lin] + [g for _, g, _ in soc]) if lin or soc else np.zeros(0)
    Aeq = sp.vstack([M for M, _ in eq], format="csc") if eq else sp.csc_matrix((0, n))
    beq = np.concatenate([g for _, g in eq]) if eq else np.zeros(0)
    dims = {"l": int(sum(M.shape[0] for M, _ in lin)), "q": [s for _, _, s in soc]}
    return p.c, G, h, dims, Aeq, beq
