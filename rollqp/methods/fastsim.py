r"""FASTSIM: Kalker's simplified theory of steady rolling (Kalker 1982), the fast approximate method.

Kalker's simplified theory replaces the half-space by a bed of independent springs: the surface
displacement of an element is its own traction times a flexibility, ``u = L t``. In steady rolling the
slip is then ``s = w − e ∂(L t)/∂x`` (``e = −d``, ``d`` the rolling direction of ``load.direction``),
with the rigid slip ``w = (ξ − φ y, η + φ x)``. Where the contact sticks (``s = 0``) the traction grows
linearly from the leading edge ``x_ℓ(y)``, where it is zero; where the trial traction exceeds the bound
``μp`` it slips at the bound, along the trial traction (FASTSIM's saturation). Per row of elements, from
the leading edge along ``−e``:

.. math::
    t^{\rm trial}_x(x) = t_x(x') + e\,(ξ/L_1 − φ y/L_3)(x − x'),\quad
    t^{\rm trial}_y(x) = t_y(x') + e\,\big(η/L_2\,(x − x') + φ/(2L_3)\,(x^2 − x'^2)\big),

``t = t^{\rm trial}`` if ``|t^{\rm trial}| ≤ μp``, else ``μp\, t^{\rm trial}/|t^{\rm trial}|``
(``x'`` the previous element of the row, the leading edge ``x_ℓ = a\sqrt{1 − y²/b²}`` of the Hertz
ellipse at the first).

**The flexibilities** come from Kalker's linear creep coefficients ``C_ij`` of the scene's ellipse
(:func:`rollqp.closedforms.kalker.kalker_linear`, Table E.3, at its ``a/b`` and ``ν``):

.. math::
    L_1 = \frac{8a}{3\,C_{11}\,G},\qquad L_2 = \frac{8a}{3\,C_{22}\,G},\qquad
    L_3 = \frac{\pi a\sqrt{a/b}}{4\,C_{23}\,G},

so that, with nothing slipping, the forces are Kalker's linear theory **by construction**: over the
ellipse ``∫∫(x_ℓ − x) = 8a²b/3`` gives ``F_x = −G ab C_{11} ξ`` and ``∫∫ x(x_ℓ − x)`` the spin term
``−G (ab)^{3/2} C_{23} φ`` of ``F_y`` (the discrete sums on the grid reproduce them to the grid's
quadrature error). At large creepage every element slips and the force is ``μ F_N`` (saturation).
Between, it is an approximation: its error against the exact solution of the same discrete problem
(:mod:`rollqp.methods.newton.disc`) is measured in docs/performance.md ("FASTSIM").

**The pressure** is the scene's own (the normal step, solved exactly by Newton's method,
:mod:`rollqp.methods.newton.disc`: Kalker's FASTSIM takes the parabolic pressure of his simplified normal theory;
here the saturation uses the same pressure as the exact method it is compared with). Prescribed forces
(``Fx``, ``Fy``) are met by solving for the creepages (``scipy.optimize.root`` from the linear theory).

FASTSIM solves the steady state only (a rolling start with ``discretization.distance = 0``); a transient or
shift step, dissimilar bodies (``K ≠ 0``: the simplified theory has no coupling) and an ``a/b`` outside Kalker's
table are one-line :class:`~rollqp.errors.InputError`\ s. Its residual is rollqp's on the exact step
problem: it is *not* small (the simplified theory is another problem), and is reported, not enforced.

References: J. J. Kalker, A fast algorithm for the simplified theory of rolling contact, Vehicle System
Dynamics 11 (1982) 1–13; Kalker (1990) Table E.3.

Examples
--------
>>> from rollqp import load_scene
>>> from rollqp.march.grid import run
>>> scene = load_scene("kalker-circular", {"solver.method": "fastsim", "discretization.distance": 0.0})
>>> r = run(scene).arrays()
>>> round(float(r["Fx"][0]) / (-0.00402 * 300.0), 1)   # the linear limit: Kalker's -G c² C11 ξ (-1.19 N)
1.0
"""
from __future__ import annotations

import time

import numpy as np

from ..errors import InputError, SolverError
from ..closedforms.kalker import kalker_linear
from .newton.disc import NewtonMethod
from .base import Capabilities, check_options

__all__ = ["FastsimMethod", "flexibilities", "fastsim_traction"]


def flexibilities(a: float, b: float, G: float, nu: float) -> tuple:
    """``(L1, L2, L3)`` of Kalker's simplified theory from ``C11, C22, C23`` of Table E.3 (module docstring).

    >>> L1, L2, L3 = flexibilities(1.0, 1.0, 1.0, 0.25)
    >>> round(8 / (3 * L1), 2), round(8 / (3 * L2), 2)     # C11, C22 at a/b = 1, ν = 0.25
    (4.12, 3.67)
    """
    C = kalker_linear(a / b, nu)
    if C is None:
        raise InputError("solver.method", f"fastsim needs Kalker's creep coefficients, tabulated for "
                                          f"0.1 <= a/b <= 10; the contact has a/b = {a / b:.4g}")
    C11, C22, C23 = C
    return 8 * a / (3 * C11 * G), 8 * a / (3 * C22 * G), np.pi * a * np.sqrt(a / b) / (4 * C23 * G)


def fastsim_traction(x, y, bound, dx, L, a, b, xi, eta, phi, e=1):
    """FASTSIM's tractions ``(2, n)`` on a uniform grid (rows of constant ``y``), the contact where
    ``bound > 0`` (module docstring; ``e = +1``: the leading edge at ``+x``).

    >>> import numpy as np
    >>> x = np.arange(-0.95, 1.0, 0.1); y = np.zeros_like(x)
    >>> t = fastsim_traction(x, y, np.full(x.size, 1e9), 0.1, (1.0, 1.0, 1.0), 1.0, 1.0, 1e-3, 0.0, 0.0)
    >>> bool(np.allclose(t[0], 1e-3 * (x - 1.0)))             # stick: linear from the leading edge
    True
    """
    L1, L2, L3 = L
    x, y, bound = (np.asarray(v, dtype=float) for v in (x, y, bound))
    out = np.zeros((2, x.size))
    inside = np.flatnonzero(bound > 0)
    if inside.size == 0:
        return out
    # the elements in contact by row (equal y), each row from its leading edge; a gap starts a new segment
    order = inside[np.lexsort((-e * x[inside], y[inside]))]     # a row's centres share one y exactly
    xs, ys, bs = x[order], y[order], bound[order]
    start = np.r_[True, (ys[1:] != ys[:-1]) | (np.abs(xs[1:] - xs[:-1]) > 1.5 * dx)]
    # the leading edge of a segment: the ellipse's where it lies within the first element's reach, else
    # half an element ahead of it
    lead = e * a * np.sqrt(np.clip(1.0 - (ys / b) ** 2, 0.0, None))
    ahead = e * (lead - xs)
    lead = np.where((ahead > 1e-9 * dx) & (ahead <= dx), lead, xs + e * 0.5 * dx)
    prev = np.where(start, lead, np.r_[0.0, xs[:-1]])
    first = np.flatnonzero(start)
    rank = np.arange(xs.size) - first[np.cumsum(start) - 1]
    tx, ty = np.zeros(xs.size), np.zeros(xs.size)
    for k in range(int(rank.max()) + 1):      # the k-th element of every segment at once
        idx = np.flatnonzero(rank == k)
        x1, x0, yk = xs[idx], prev[idx], ys[idx]
        px = tx[idx - 1] if k else 0.0
        py = ty[idx - 1] if k else 0.0
        trial_x = px + e * (xi / L1 - phi * yk / L3) * (x1 - x0)
        trial_y = py + e * (eta / L2 * (x1 - x0) + phi / (2 * L3) * (x1 ** 2 - x0 ** 2))
        norm = np.hypot(trial_x, trial_y)
        cap = bs[idx]
        with np.errstate(divide="ignore", invalid="ignore"):
            f = np.where(norm > cap, cap / norm, 1.0)
        tx[idx], ty[idx] = trial_x * f, trial_y * f
    out[0, order], out[1, order] = tx, ty
    return out


class FastsimMethod:
    """FASTSIM (Kalker's simplified theory) for 3D steady rolling (module docstring).

    Parameters
    ----------
    tolerance : float
        The tolerance of the exact normal step (Newton) and of the creepages that meet prescribed forces.
    """

    name = "fastsim"
    #: It solves the steady state only: a run with rolling steps after it is refused before any work
    #: (:func:`rollqp.advice.grid.refusal`).
    steady_only = True
    capabilities = Capabilities(solves=frozenset({"normal", "tangential", "steady"}), matrix_free=True,
                                dimensions=frozenset({3}), traction_components=2, friction_set="disc")

    def __init__(self, tolerance: float = 1e-10, max_iterations: int | None = None):
        self.tolerance = float(tolerance)
        self._normal = NewtonMethod(tolerance=tolerance, max_iterations=max_iterations or 100)
        self.contact = None

    @classmethod
    def from_settings(cls, settings, **options):
        """From a scene's solver settings: ``tolerance``, ``max_iterations`` (of the normal step)."""
        check_options(cls.name, options, ())
        return cls(tolerance=settings.tolerance, max_iterations=settings.max_iterations)

    def setup(self, contact=None) -> None:
        """The contact whose ellipse and materials give the flexibilities."""
        self.contact = contact

    def solve(self, problem, warm=None):
        if problem.kind == "normal":
            return self._normal.solve(problem, warm)
        t0 = time.perf_counter()
        c = self.contact
        if c is None:
            raise InputError("solver.method", "fastsim needs its contact (method.setup(contact)) for the flexibilities")
        direction = next((d for d in (-1, 1) if problem.B is c.ops.steady("tt", d)), None)
        if direction is None:
            raise InputError("solver.method", "fastsim solves the steady state only (a rolling start with "
                                              "discretization.distance = 0); use --method newton for rolling steps")
        m = c.materials
        if m.K != 0:
            raise InputError("solver.method", "fastsim: Kalker's simplified theory is for similar bodies (K = 0); "
                                              "use --method newton")
        e = c.ellipse
        L = flexibilities(e.a, e.b, m.G, m.nu)
        g = c.grid

        def traction(xi, eta):
            return fastsim_traction(problem.x, problem.y, problem.bound, g.dx, L, e.a, e.b, xi, eta, problem.phi,
                                    -direction)

        xi, eta = problem.xi, problem.eta
        if problem.Fx is not None or problem.Fy is not None:
            xi, eta = self._creepages(problem, traction, e, m)
        t = traction(xi, eta)
        sol = problem.solution(t, None if problem.xi is not None else xi, None if problem.eta is not None else eta,
                               method=self.name, iterations=1, extras={"time": time.perf_counter() - t0,
                                                                      "flexibilities": L})
        return sol

    def _creepages(self, problem, traction, e, m):
        """The creepages whose FASTSIM forces are the prescribed ones (the others as given)."""
        from scipy.optimize import root
        area = problem.area
        C = kalker_linear(e.a / e.b, m.nu)
        ab, G = e.a * e.b, m.G
        free = [j for j, F in enumerate((problem.Fx, problem.Fy)) if F is not None]
        target = np.array([(problem.Fx, problem.Fy)[j] for j in free])
        guess = np.array([-target[i] / (G * ab * C[j]) for i, j in enumerate(free)])
        scale = max(float(np.max(np.abs(target))), 1e-300)

        def creep(z):
            v = [problem.xi, problem.eta]
            for i, j in enumerate(free):
                v[j] = z[i]
            return v

        def f(z):
            t = traction(*creep(z))
            return (np.array([area * t[j].sum() for j in free]) - target) / scale

        out = root(f, guess, method="hybr", tol=self.tolerance)
        if not np.max(np.abs(f(out.x))) <= 1e-8:
            raise SolverError("fastsim: no creepages give the prescribed forces (at the friction limit?)",
                              method=self.name, residual=float(np.max(np.abs(f(out.x)))))
        return creep(out.x)
