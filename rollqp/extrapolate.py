r"""Creep forces extrapolated to the fine-grid limit from a few grids, each averaged over grid positions.

**Why one grid position is not enough.** The discrete contact area is the set of elements whose centres
the normal step finds in contact, and the stick/slip boundary is a set of elements too: how the contact edge
and the slip boundary cut the elements depends on where the grid lies relative to the ellipse, and that
changes irregularly from one element count to the next (the lattice-point count of an ellipse). A force on
one grid position is therefore a smooth first-order term plus an irregular one of 0.1–0.3 % at 16–32
elements per semi-axis, whose sign changes from grid to grid: three centred grids do not converge as a power
of ``h``, their measured order is spurious, and Richardson's estimate can miss the error by ten times
(docs/performance.md, "Speed against error").

**The remedy.** Each grid is solved at ``shifts`` positions relative to the ellipse, the grid moved by
fractions ``(u_j, v_j)`` of an element (``u_j = (j + ½)/K − ½`` stratified along x, ``v_j`` the golden-ratio
sequence along y: a rank-1 lattice on the unit cell), and the forces averaged. The average is a smooth
function of ``h``: measured on the circle at ξ = 1e-5 and 1e-3 it follows ``F₀ + C h`` to within its
scatter from 16 to 48 elements per semi-axis, and at ξ = 1e-3 its order-1 extrapolation agrees with a single
160-per-semi-axis grid corrected by the same ``C h`` to 0.03 % (docs/performance.md).

**The extrapolation and its estimate.** With ``F̄_k`` the average on grid ``k`` and ``s_k`` its standard
error (the scatter of the positions over ``√K``), the first-order model is fitted by weighted least squares

.. math::
    \bar F_k \approx F_0 + C\,h_k,\qquad \text{estimate} = 2\,\sigma(F_0) + |F_0^{(p)} - F_0|,

where ``σ(F₀)`` is the fit's standard error of ``F₀`` from the ``s_k``, scaled up by the fit's residual where
the residual exceeds what the scatter explains (reduced χ² above 1), and ``F₀⁽ᵖ⁾`` the extrapolation with the
order ``p`` measured from the three finest grids: the estimate grows where the measured order strays from 1
by more than the scatter explains (``|F₀⁽ᵖ⁾ − F₀|`` less twice its own standard error from the ``s_k``, at
least 0); where no order can be measured — the differences of opposite signs — the whole correction
``|F₀ − F̄_finest|`` is added instead. The positions are not independent draws but a stratified set: their average is closer to
the smooth value than ``s_k`` says (measured: the estimate 1.7–35 times the error), so it is conservative.

Examples
--------
>>> from rollqp import load_scene
>>> x = extrapolate(load_scene("kalker-circular"), grids=(10, 15, 20), shifts=3)
>>> x.grids, x.forces["Fy"], len(x.forces["Fx"].values), x.runs
((10, 15, 20), None, 3, 9)
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from .errors import InputError
from .march.grid import run

__all__ = ["extrapolate", "Extrapolation", "Extrapolated", "richardson", "positions", "fit_first_order",
           "ORDER_RANGE", "SHIFTS", "THEORETICAL_ORDER"]

#: Observed orders accepted as asymptotic (outside it the grids are not in the asymptotic range).
ORDER_RANGE = (0.3, 5.0)
#: Forces whose averages are below this fraction of μFN on every grid (and no single position above ten times
#: it; the moment: times μFN·c) are negligible — zero by symmetry where the scene is symmetric, the positions
#: breaking it by less: not extrapolated.
NEGLIGIBLE = 1e-4
#: Grid positions per grid by default (module docstring): the scatter of 8 positions' average is below
#: 0.03 % of the force at 32 elements per semi-axis on the circle (measured, docs/performance.md).
SHIFTS = 8
#: Order of the discretization error of the position-averaged force (piecewise-constant elements; measured
#: 0.89–1.42 from the command's default grids on the cases of docs/performance.md, the spread the scatter's).
THEORETICAL_ORDER = 1.0
#: Golden ratio's conjugate: the y-fractions of the positions (``{j·g}``), evenly spread for any count.
_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


@dataclass(frozen=True)
class Extrapolated:
    """One quantity: its averages on the grids and their standard errors, the observed order (None: not
    measurable), the extrapolated value and its error estimate."""

    values: tuple
    order: float | None
    value: float
    error: float
    scatter: tuple = ()


def positions(count: int) -> list:
    """The grid's shifts ``(u, v)`` in elements (module docstring); one position is the centred grid.

    >>> positions(1), [tuple(round(c, 3) for c in p) for p in positions(2)]
    ([(0.0, 0.0)], [(-0.25, 0.0), (0.25, -0.382)])
    """
    if count == 1:
        return [(0.0, 0.0)]
    return [((j + 0.5) / count - 0.5, (0.5 + j * _GOLDEN) % 1.0 - 0.5) for j in range(count)]


def richardson(values, ratio: float) -> Extrapolated:
    """Richardson's extrapolation of three values on grids refined by ``ratio``, the order measured (the
    single-position estimate: its error is the extrapolation's own correction ``|F_* − F_3|``; no order is
    claimed where the differences change sign or the order is outside :data:`ORDER_RANGE`).

    >>> e = richardson([1 + 0.1, 1 + 0.05, 1 + 0.025], 2.0)     # F = 1 + h: order 1, limit 1
    >>> round(e.order, 6), round(e.value, 12), round(e.error, 6)
    (1.0, 1.0, 0.025)
    """
    F1, F2, F3 = (float(v) for v in values)
    d1, d2 = F2 - F1, F3 - F2
    if d2 == 0.0:
        return Extrapolated((F1, F2, F3), None, F3, abs(d1))
    if d1 * d2 > 0:
        p = math.log(d1 / d2) / math.log(ratio)
        if ORDER_RANGE[0] <= p <= ORDER_RANGE[1]:
            value = F3 + d2 / (ratio ** p - 1.0)
            return Extrapolated((F1, F2, F3), p, value, abs(value - F3))
    return Extrapolated((F1, F2, F3), None, F3, max(abs(d1), abs(d2)))


def _measured_order(h, F):
    """The order ``p`` of ``F = F₀ + C h^p`` through three points (any ratios), or None (no such ``p`` in
    :data:`ORDER_RANGE`)."""
    (h1, h2, h3), (F1, F2, F3) = h, F
    if (F2 - F3) == 0.0 or (F1 - F2) * (F2 - F3) <= 0.0:
        return None
    target = (F1 - F2) / (F2 - F3)

    def g(p):
        return (h1 ** p - h2 ** p) / (h2 ** p - h3 ** p) - target
    lo, hi = ORDER_RANGE
    if g(lo) * g(hi) > 0:
        return None
    for _ in range(80):         # bisection: g rises monotonically with p for h1 > h2 > h3
        mid = 0.5 * (lo + hi)
        if g(lo) * g(mid) <= 0:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def fit_first_order(h, means, errors) -> Extrapolated:
    """``F₀ + C h`` fitted to the grids' averages ``means`` (standard errors ``errors``) and the estimate of
    the module docstring.

    >>> e = fit_first_order([0.1, 0.05, 0.025], [1.1, 1.05, 1.025], [1e-4, 1e-4, 1e-4])   # exactly 1 + h
    >>> round(e.value, 12), round(e.order, 6), bool(e.error < 5e-4)
    (1.0, 1.0, True)
    """
    h, F, s = (np.asarray(v, dtype=float) for v in (h, means, errors))
    if h.size < 2 or np.any(np.diff(h) >= 0):
        raise InputError("grids", f"need two or more grids, coarse to fine, got h = {h.tolist()!r}")
    w = 1.0 / np.maximum(s, 1e-15 * np.max(np.abs(F)) + 1e-300) ** 2 if np.all(s > 0) else np.ones_like(h)
    M = np.column_stack([np.ones_like(h), h ** THEORETICAL_ORDER])
    cov = np.linalg.inv(M.T @ (w[:, None] * M))
    coef = cov @ (M.T @ (w * F))
    F0 = float(coef[0])
    var = float(cov[0, 0]) if np.all(s > 0) else 0.0
    dof = h.size - 2
    if dof > 0:
        r = F - M @ coef
        chi2 = float(np.sum(w * r * r)) / dof if np.all(s > 0) else math.inf
        if not np.all(s > 0):        # no scatter measured: the residual alone
            var = float(np.sum(r * r)) / dof * float(np.linalg.inv(M.T @ M)[0, 0])
        elif chi2 > 1.0:             # the residual exceeds the scatter: scale up (reduced chi-square)
            var *= chi2
    order = _measured_order(h[-3:], F[-3:]) if h.size >= 3 else None
    if order is None:
        model = abs(F0 - F[-1])
    else:
        # the change of F0 with the measured order, beyond what the averages' scatter alone moves it by
        def change(values):
            p = _measured_order(h[-3:], values[-3:])
            if p is None:
                return abs(F0 - values[-1])
            Fp = values[-1] - (values[-2] - values[-1]) * h[-1] ** p / (h[-2] ** p - h[-1] ** p)
            return Fp - _first_order_value(h, values, w)
        g = change(F)
        if np.all(s > 0):
            J = [(change(F + e * si) - change(F - e * si)) / 2.0 for e, si in zip(np.eye(h.size), s)]
            model = max(0.0, abs(g) - 2.0 * math.sqrt(float(np.sum(np.square(J)))))
        else:
            model = abs(g)
    return Extrapolated(tuple(float(v) for v in F), order, F0, 2.0 * math.sqrt(var) + model,
                        tuple(float(v) for v in s))


def _first_order_value(h, F, w) -> float:
    M = np.column_stack([np.ones_like(h), h ** THEORETICAL_ORDER])
    return float(np.linalg.solve(M.T @ (w[:, None] * M), M.T @ (w * F))[0])


@dataclass
class Extrapolation:
    """The grids' averaged forces (``Fx``, ``Fy`` in force units, ``Mz``), their extrapolation, and each
    grid's wall time; ``str()`` is the table ``rollqp extrapolate`` prints."""

    scene: str
    grids: tuple
    shifts: int
    forces: dict = field(default_factory=dict)
    seconds: tuple = ()
    cap: float = 1.0

    @property
    def runs(self) -> int:
        """Steady solves made (grids × positions)."""
        return len(self.grids) * self.shifts

    def __str__(self) -> str:
        g = " / ".join(f"{n}" for n in self.grids)
        lines = [f"{self.scene}: the steady state on grids of {g} elements along the shorter axis, each at "
                 f"{self.shifts} position(s), {' + '.join(f'{t:.2f}' for t in self.seconds)} = "
                 f"{sum(self.seconds):.2f} s",
                 "  " + f"{'':<4} " + " ".join(f"{'grid ' + str(n):>22}" for n in self.grids)
                 + f" {'order':>6} {'extrapolated':>14} {'error estimate':>22}"]
        for k, e in self.forces.items():
            if e is None:
                lines.append(f"  {k:<4} negligible on every grid (below {NEGLIGIBLE:g} of mu FN: zero by symmetry)")
                continue
            order = f"{e.order:6.2f}" if e.order is not None else f"{'-':>6}"
            rel = e.error / abs(e.value) if e.value else math.inf
            cells = " ".join(f"{v:12.6g} ± {s:<7.2g}" for v, s in zip(e.values, e.scatter or [0.0] * len(e.values)))
            lines.append(f"  {k:<4} {cells} {order} {e.value:14.7g} {e.error:11.3g} ({100 * rel:.3f} %)")
        lines.append("  (each grid: the average over its positions ± its standard error; extrapolated: F0 of "
                     "F0 + C h; estimate: twice F0's standard error + its change with the measured order)")
        if any(e is not None and e.order is None for e in self.forces.values()):
            lines.append("  (-: no order measurable from the grids for it; the whole correction is in the estimate)")
        return "\n".join(lines)


def _grid_of(scene):
    """``(nx, ny, (x0, x1), (y0, y1))`` of the scene's grid."""
    g = scene.grid
    return g.nx, g.ny, (g.xl, g.xl + g.nx * g.dx), (g.yl, g.yl + g.ny * g.dy)


def extrapolate(scene, grids=None, shifts: int = SHIFTS, quantities=("Fx", "Fy", "Mz")) -> Extrapolation:
    """The forces of ``scene``'s steady state extrapolated from grids averaged over positions (module docstring).

    ``grids``: two or more increasing element counts along the shorter axis (default ``n, 2n, 3n`` of the
    scene's ``n``: the averages' scatter falls fast with ``h``, and a wide range of ``h`` measures the order
    well); the other axis keeps the scene's proportion, the grid's extent is the scene's (moved by
    less than an element for each position). ``shifts``: positions per grid (at least 2: the scatter is
    part of the estimate). Each position's grid has one element more on each side than the scene's, so
    that the moved grid keeps the scene's margin around the contact (they are out of contact).

    Raises
    ------
    InputError
        A scene that is not a rolling start (no steady state), grids that are not two or more increasing
        counts, or fewer than 2 positions.
    """
    if scene.dimension != 3 or scene.load.start != "rolling":
        raise InputError("SCENE", f"extrapolate works on the steady state of a 3D rolling start "
                                  f"(load.start = 'rolling'); {scene.name!r} is not one")
    nx, ny, (x0, x1), (y0, y1) = _grid_of(scene)
    base = min(nx, ny)
    if grids is None:
        grids = (base, 2 * base, 3 * base)
    grids = tuple(int(g) for g in grids)
    if len(grids) < 2 or grids[0] < 1 or any(not a < b for a, b in zip(grids, grids[1:])):
        raise InputError("--grids", f"must be two or more increasing element counts, got {grids!r}")
    if isinstance(shifts, bool) or not isinstance(shifts, (int, np.integer)) or not 2 <= shifts <= 64:
        raise InputError("--shifts", f"must be an integer in [2, 64] (grid positions per grid), got {shifts!r}")
    values, seconds, hs = {q: [] for q in quantities}, [], []
    for n in grids:
        k = n / base
        NX, NY = max(round(nx * k), 1), max(round(ny * k), 1)
        dx, dy = (x1 - x0) / NX, (y1 - y0) / NY
        hs.append(math.sqrt(dx * dy))
        t0, got = time.perf_counter(), {q: [] for q in quantities}
        for u, v in positions(int(shifts)):
            # one element more on each side: the moved grid keeps the scene's margin around the contact
            s = scene.replace(**{"discretization.elements": [NX + 2, NY + 2], "discretization.zone": None,
                                 "discretization.element_size": None,
                                 "discretization.extent": [[x0 + (u - 1) * dx, x1 + (u + 1) * dx],
                                                           [y0 + (v - 1) * dy, y1 + (v + 1) * dy]],
                                 "discretization.distance": 0.0})
            res = run(s).arrays()
            for q in quantities:
                got[q].append(float(res[q][0]))
        seconds.append(time.perf_counter() - t0)
        for q in quantities:
            values[q].append(got[q])
    cap = scene.mu * scene.load.normal
    out = Extrapolation(scene.name, grids, int(shifts), seconds=tuple(seconds), cap=cap)
    for q in quantities:
        unit = cap * (scene.ellipse.c if q == "Mz" else 1.0)
        vals = np.asarray(values[q])
        if np.max(np.abs(vals.mean(axis=1))) <= NEGLIGIBLE * unit and np.max(np.abs(vals)) <= 10 * NEGLIGIBLE * unit:
            out.forces[q] = None
            continue
        means = vals.mean(axis=1)
        errors = vals.std(axis=1, ddof=1) / math.sqrt(vals.shape[1])
        out.forces[q] = fit_first_order(hs, means, errors)
    return out
