r"""A 3D step's conic program as plain arrays, and rollqp's residual computed from them.

:class:`ProgramData` is :class:`rollqp.problem.conic.ConicForm` (eq. 3D.22/3D.20) written out:
``min ½xᵀHx + qᵀx`` s.t. ``a x = b`` and ``x ∈ K`` — ``x ≥ 0`` (normal) or one cone
``(bound_i, x_i, x_{nv+i}) ∈ Q³`` per element (tangential). With ``slip_scale = obj/â`` the
gradient of the Lagrangian is the step's own gap or slip (docs/theory3d.md §5):

.. math::
    \hat g = \texttt{slip\_scale}\,(Hx + q + a^Ty)\ \text{(normal)},\qquad
    \hat s = \texttt{slip\_scale}\,(Hx + q + a^Ty)\ \text{(tangential)}

so rollqp's residual (eq. 3D.29) of an answer ``(x, y)`` — ``‖min(p̂, ĝ)‖∞`` or
``max_i |t̂_i − Proj_{b̂_i}(t̂_i − ŝ_i)|``, and the load rows ``eq·|a x − b|`` — needs these arrays
only, not rollqp's operators: a test set reader can evaluate it.

Examples
--------
>>> import numpy as np
>>> d = ProgramData("normal", np.eye(2), np.array([-1.0, 0.5]), np.ones((1, 2)), np.array([1.0]),
...                 None, 1.0, 1.0)
>>> float(residual(d, np.array([1.0, 0.0]), np.array([0.0])))
0.0
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["ProgramData", "from_form", "residual", "objective", "kkt_gradient", "disc_projection", "ascii_text"]


@dataclass(frozen=True)
class ProgramData:
    """The arrays of one conic program (module docstring); ``bound`` is None for the normal QP."""

    kind: str
    H: np.ndarray
    q: np.ndarray
    a: np.ndarray
    b: np.ndarray
    bound: np.ndarray | None
    slip_scale: float
    eq_scale: float

    @property
    def m(self) -> int:
        return int(self.q.size)

    @property
    def k(self) -> int:
        return int(self.a.shape[0])

    def arrays(self) -> dict:
        """The arrays as an ``npz`` payload (:func:`from_arrays` reads it back)."""
        out = {"kind": np.array(self.kind), "H": self.H, "q": self.q, "a": self.a, "b": self.b,
               "slip_scale": np.array(self.slip_scale), "eq_scale": np.array(self.eq_scale)}
        if self.bound is not None:
            out["bound"] = self.bound
        return out

    @classmethod
    def from_arrays(cls, z) -> "ProgramData":
        """From :meth:`arrays` (a dict or an open ``npz``)."""
        bound = np.asarray(z["bound"], dtype=float) if "bound" in z else None
        return cls(str(z["kind"]), np.asarray(z["H"], dtype=float), np.asarray(z["q"], dtype=float),
                   np.asarray(z["a"], dtype=float).reshape(-1, np.asarray(z["q"]).size),
                   np.asarray(z["b"], dtype=float).ravel(), bound, float(z["slip_scale"]), float(z["eq_scale"]))


def from_form(form, area_hat: float) -> ProgramData:
    """From a :class:`~rollqp.problem.conic.ConicForm` with a symmetric operator (no skew part) and the
    element area ``â`` in units of ``c²``."""
    if form.skew is not None:
        raise ValueError("a form with a skew part is a sequence of programs, not one (docs/theory3d.md §6)")
    H = 0.5 * (form.H + form.H.T)
    return ProgramData(form.kind, np.array(H), np.array(form.q), np.array(form.a), np.array(form.b),
                       None if form.bound is None else np.array(form.bound),
                       float(form.obj_scale) / float(area_hat), float(form.eq_scale))


def disc_projection(z: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``Proj_{|·| ≤ b_i}(z_i)`` for ``z`` of shape ``(2, n)`` (eq. 3D.19)."""
    norm = np.hypot(z[0], z[1])
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.where(norm > b, b / np.where(norm > 0, norm, 1.0), 1.0)
    return z * k


def kkt_gradient(d: ProgramData, x, y) -> np.ndarray:
    """``Hx + q + aᵀy``: times ``slip_scale`` the gap (normal) or the slip (tangential)."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float).ravel()
    g = d.H @ x + d.q
    return g + d.a.T @ y if d.k else g


def residual(d: ProgramData, x, y) -> float:
    """rollqp's residual (eq. 3D.29) of the answer ``(x, y)`` (module docstring); NaN if not finite."""
    x = np.asarray(x, dtype=float)
    if x.shape != (d.m,) or not np.all(np.isfinite(x)) or not np.all(np.isfinite(y)):
        return float("nan")
    grad = d.slip_scale * kkt_gradient(d, x, y)
    if d.kind == "normal":
        comp = float(np.max(np.abs(np.minimum(x, grad)), initial=0.0))
    else:
        nv = d.m // 2
        t, s = x.reshape(2, nv), grad.reshape(2, nv)
        r = t - disc_projection(t - s, d.bound)
        comp = float(np.max(np.hypot(r[0], r[1]), initial=0.0))
    load = float(np.max(np.abs(d.a @ x - d.b), initial=0.0)) * d.eq_scale if d.k else 0.0
    return max(comp, load)


def objective(d: ProgramData, x) -> float:
    """``½xᵀHx + qᵀx``."""
    x = np.asarray(x, dtype=float)
    return float(0.5 * x @ (d.H @ x) + d.q @ x)


def ascii_text(text: str) -> str:
    """``text`` in ASCII (CBF comments, FCLib's info strings): Greek letters spelled, marks dropped."""
    import unicodedata
    for a, b in (("μ", "mu"), ("–", "-"), ("—", "-"), ("·", "*"), ("½", "1/2"), ("ᵀ", "'"), ("Δ", "d"),
                 ("δ", "delta"), ("ξ", "xi"), ("η", "eta"), ("φ", "phi"), ("≥", ">="), ("≤", "<=")):
        text = text.replace(a, b)
    return unicodedata.normalize("NFKD", text).encode("ascii", "ignore").decode("ascii")
