r"""The coupled static steps as FCLib local problems (HDF5 in FCLib's layout, written by h5py).

FCLib's local frictional contact problem ``FC(W, q, μ)``: find the contact velocities (here:
displacements) ``u`` and reactions (here: tractions) ``r``, three per contact ``(N, T1, T2)``, with

.. math::
    u = Wr + q,\qquad \hat u = u + (\mu\|u_T\|, 0, 0),\qquad
    C^*_\mu \ni \hat u \perp r \in C_\mu,\quad C_\mu = \{\|r_T\| \le \mu r_N\}.

A rollqp static shift step of two bodies in contact (docs/theory3d.md §4, §8) is this problem on the
``n`` grid elements once the approach ``δ`` and the shift ``(ξ, η)·c`` are prescribed at their
certified values (a load-controlled step fixes them by its solution): with ``r = (p̂, t̂_x, t̂_y)``
(in ``p0``) and ``u = (ĝ, ŝ_x, ŝ_y)`` (gap in ``u0 = c p0/E*``, slip per unit shift in ``p0/E*``;
the shift's ``Δq = c`` makes them the same unit), ``W`` is ``E*/c`` times the influence matrix
``[[A_nn, A_nt], [A_tn, A_tt]]`` interleaved per element (symmetric positive definite, Betti),
``q = (ĥ − δ̂, ŝ_rigid + history)`` and ``μ`` the coefficient of friction of every element.
De Saxcé's ``û`` makes FCLib's complementarity Coulomb's law with a gap: ``u_N ≥ 0``,
``r_N u_N = 0``, slip opposite the tangential reaction.

Layout written (FCLib's ``fclib_write_local`` and ``fclib_write_solution``, ``src/fclib.h``)::

    /fclib_local/spacedim             int[1] = 3
    /fclib_local/W/{nzmax,m,n,nz}     int[1]; nz = -1: compressed columns
    /fclib_local/W/{p,i,x}            column pointers (n+1), row indices, values (nzmax)
    /fclib_local/vectors/{q,mu}       q (m = 3·contacts), mu (contacts)
    /fclib_local/info/{title,description,math_info}   strings
    /solution/{u,r}                   the certified solution

``numberOfContacts`` (Siconos' name) is ``m/3``. rollqp's residual of ``(u, r)`` (eq. 3D.29 of the
coupled step: ``‖min(r_N, u_N)‖∞`` and ``|r_T − Proj_{μ r_N⁺}(r_T − u_T)|``) needs the file only:
:func:`residual`.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..errors import MissingBackendError
from .forms import ascii_text, disc_projection

__all__ = ["write", "read", "residual", "SPACEDIM"]

#: Three components per contact: normal, then the two tangential directions (x, y of the grid).
SPACEDIM = 3


def _h5py():
    try:
        import h5py
    except ImportError:
        raise MissingBackendError("FCLib files need h5py: pip install 'rollqp[conicbench]'") from None
    return h5py


def write(path, W, q, mu, r=None, u=None, title="", description="", math_info="") -> None:
    """Write ``FC(W, q, μ)`` (``W`` dense or sparse ``(m, m)``, ``m = 3·contacts``) and, if given, its
    solution ``(u, r)`` in FCLib's layout (module docstring)."""
    h5py = _h5py()
    Wc = sp.csc_matrix(W)
    Wc.sort_indices()
    m = Wc.shape[0]
    with h5py.File(path, "w") as f:
        loc = f.create_group("fclib_local")
        loc.create_dataset("spacedim", data=np.array([SPACEDIM], dtype=np.int32))
        g = loc.create_group("W")
        for key, v in (("nzmax", Wc.nnz), ("m", m), ("n", Wc.shape[1]), ("nz", -1)):
            g.create_dataset(key, data=np.array([v], dtype=np.int32))
        g.create_dataset("p", data=Wc.indptr.astype(np.int32))
        g.create_dataset("i", data=Wc.indices.astype(np.int32))
        g.create_dataset("x", data=Wc.data.astype(float))
        vec = loc.create_group("vectors")
        vec.create_dataset("q", data=np.asarray(q, dtype=float))
        vec.create_dataset("mu", data=np.asarray(mu, dtype=float))
        info = loc.create_group("info")
        for key, text in (("title", title), ("description", description), ("math_info", math_info)):
            if text:   # a fixed-length, null-terminated ASCII string, as H5LTmake_dataset_string writes
                raw = ascii_text(text).encode("ascii") + b"\0"
                info.create_dataset(key, data=np.array(raw, dtype=f"S{len(raw)}"))
        if r is not None:
            sol = f.create_group("solution")
            sol.create_dataset("u", data=np.asarray(u, dtype=float))
            sol.create_dataset("r", data=np.asarray(r, dtype=float))


def read(path, solution: bool = True) -> dict:
    """``{"W": csc, "q", "mu", "spacedim", "u", "r" (or None), "title"}`` of an FCLib local problem
    (``solution=False``: the problem only, ``/solution`` not read)."""
    h5py = _h5py()
    with h5py.File(path, "r") as f:
        loc = f["fclib_local"]
        g = loc["W"]
        m, n, nz = (int(g[k][0]) for k in ("m", "n", "nz"))
        if nz != -1:
            raise ValueError(f"{path}: only compressed-column W is read (nz = -1), got nz = {nz}")
        W = sp.csc_matrix((g["x"][:], g["i"][:], g["p"][:]), shape=(m, n))
        out = {"W": W, "q": loc["vectors/q"][:], "mu": loc["vectors/mu"][:], "spacedim": int(loc["spacedim"][0]),
               "u": None, "r": None, "title": loc["info/title"][()].decode() if "info/title" in loc else ""}
        if solution and "solution" in f:
            out["u"], out["r"] = f["solution/u"][:], f["solution/r"][:]
    return out


def residual(W, q, mu, r) -> float:
    """rollqp's residual of the reactions ``r`` (module docstring), with ``u = Wr + q``."""
    r = np.asarray(r, dtype=float)
    u = (W @ r + q).reshape(-1, SPACEDIM).T
    rr = r.reshape(-1, SPACEDIM).T
    sig = float(np.max(np.abs(np.minimum(rr[0], u[0]))))
    res = rr[1:] - disc_projection(rr[1:] - u[1:], np.asarray(mu) * np.maximum(rr[0], 0.0))
    return max(sig, float(np.max(np.hypot(res[0], res[1]))))
