r"""Creep forces extrapolated to the fine-grid limit from a few grids, each averaged over grid positions, with
as many positions as a target error needs.

**Why one grid position is not enough.** The discrete contact area is the set of elements whose centres
the normal step finds in contact, and the stick/slip boundary is a set of elements too: how the contact edge
and the slip boundary cut the elements depends on where the grid lies relative to the ellipse, and that
changes irregularly from one element count to the next (the lattice-point count of an ellipse). A force on
one grid position is therefore a smooth first-order term plus an irregular one of 0.1–0.3 % at 16–48
elements per semi-axis: three centred grids do not converge as a power of ``h``, their measured order is
spurious, and Richardson's estimate can miss the error by ten times (docs/performance.md, "Speed against
error"). The irregular part is the elastic staircase of the contact edge, not the pressure: it is the same
with the cell-averaged Hertz pressure, and with no slip at all (measured, docs/performance.md).

**The remedy.** Each grid is solved at ``K`` positions relative to the ellipse, the grid moved by fractions
``(u_j, v_j)`` of an element (:func:`positions`: the R₂ low-discrepancy sequence, every prefix of which is
evenly spread, so that positions can be added to a grid), and the forces averaged. The average is a smooth
function of ``h``: measured on the circle at ξ = 1e-5 and 1e-3 with 16 positions on seven grids from 16 to 48
elements per semi-axis, ``F₀ + C h`` fits the averages within their scatter (reduced χ² 0.03–0.11).

**The extrapolation and its estimate.** With ``F̄_k`` the average on grid ``k`` and ``s_k = σ_k/√K_k`` its
standard error, the first-order model is fitted by weighted least squares

.. math::
    \bar F_k \approx F_0 + C\,h_k,\qquad \text{estimate} = t_{95}(\nu)\,\sigma(F_0) + |F_0^{(p)} - F_0|,

where ``σ(F₀)`` is the fit's standard error of ``F₀`` from the ``s_k``, scaled up by the fit's residual where
the residual exceeds what the scatter explains (reduced χ² above 1); ``t₉₅(ν)`` Student's two-sided 95 %
quantile (:func:`t95`, at least 2) with ``ν`` the Welch–Satterthwaite degrees of freedom of ``F₀`` from the
grids' positions (:func:`welch_dof`: a grid of ``K`` positions gives its scatter ``K − 1``), so that an
estimate from few positions is as wide as their few degrees of freedom make it; and ``F₀⁽ᵖ⁾`` the extrapolation with the
order ``p`` measured from the three finest grids (where none is measurable — the differences of opposite
signs — ``F̄_finest`` in its place: the whole correction): the estimate grows where the measured order
strays from 1 by more than the scatter explains, ``|F₀⁽ᵖ⁾ − F₀|`` less the 95 % band of that change over
:data:`MODEL_DRAWS` draws of the averages within their standard errors, at least 0 (with two grids the whole
correction). A grid's scatter ``σ_k`` is the larger of its positions' standard
deviation and a floor from the other grids (:func:`scatter`): a grid with few positions cannot make the
estimate small by a lucky draw. The positions are evenly spread, not independent
draws: their average is closer to the smooth value than ``s_k`` says, so the estimate is conservative.

**Positions where they pay (:func:`allocate`).** ``F₀ = Σ w_k F̄_k`` (the fit's weights), so its variance is
``Σ w_k² σ_k²/K_k``; for a solve costing ``c_k`` on grid ``k`` the variance a given time buys is least with
``K_k ∝ |w_k| σ_k / √c_k`` (a Lagrange multiplier). The scatter falls faster than ``h`` while the cost rises
as about ``N^1.2`` (:data:`COST_EXPONENT`), so the coarse grid, whose scatter sets the slope ``C``, takes most
positions and the finest few. :func:`extrapolate` starts with :data:`START_SHIFTS` positions a grid (the finest
:data:`FINEST_START`) and adds
positions in rounds, at most doubling a grid's count in a round, until every creep force's estimate is
within ``target`` or the time ``budget`` is spent.

Examples
--------
>>> from rollqp import load_scene
>>> x = extrapolate(load_scene("kalker-circular"), grids=(10, 15, 20), shifts=3)
>>> x.grids, x.forces["Fy"], len(x.forces["Fx"].values), x.runs, x.shifts
((10, 15, 20), None, 3, 9, (3, 3, 3))
"""
from __future__ import annotations

import math
import os
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from .errors import InputError, SolverError
from .march.grid import run
from .threads import limited

__all__ = ["extrapolate", "Extrapolation", "Extrapolated", "richardson", "positions", "fit_first_order", "t95", "welch_dof",
           "scatter", "allocate", "sensitivities", "solve_position", "PositionedGrid", "ORDER_RANGE", "START_SHIFTS", "FINEST_START", "CONFIRM", "MAX_SHIFTS",
           "TARGET", "BUDGET", "NEGLIGIBLE", "SMALL", "TARGETED", "THEORETICAL_ORDER", "MODEL_DRAWS", "COST_EXPONENT", "COST_OVERHEAD"]

#: Observed orders accepted as asymptotic (outside it the grids are not in the asymptotic range).
ORDER_RANGE = (0.3, 5.0)
#: A quantity is negligible — zero by symmetry where the scene is symmetric, the positions breaking it by
#: less — where on every grid its average is within the larger of this fraction of μFN (the moment: of μFN·c)
#: and twice its standard error, and below :data:`SMALL` of it: it is not extrapolated (nor targeted).
NEGLIGIBLE = 1e-4
#: Above this fraction of μFN (μFN·c) on some grid a quantity is extrapolated however large its scatter.
SMALL = 1e-2
#: Positions a grid starts with before positions are allocated: four give each grid's scatter three degrees of
#: freedom, and the pooled power law (:func:`scatter`) guards the grids that keep few.
START_SHIFTS = 4
#: Positions the finest grid starts with: its solves cost most, and the pooled power law (:func:`scatter`)
#: bounds its scatter from below until it has four.
FINEST_START = 2
#: Positions every grid has before the order's part of the estimate (which positions do not shrink) may end
#: the rounds as out of the asymptotic range: with fewer, the order measured from the averages is mostly their
#: scatter (measured: 4.9 from 4/4/2 positions on the circle at 5–10 elements per semi-axis, 1.1 from 16 on each).
CONFIRM = 8
#: Most positions on one grid (the allocation stops there; a target that needs more needs finer grids).
MAX_SHIFTS = 512
#: Default target of the creep forces' estimate, relative (0.1 %).
TARGET = 1e-3
#: Default time budget of the positions' rounds, wall-clock seconds: the rounds stop there with the estimate
#: they reached (a run cut by the budget depends on the machine's speed; one that reaches its target does not).
BUDGET = 120.0
#: The quantities the target applies to (the creep forces); the spin moment is extrapolated and reported.
TARGETED = ("Fx", "Fy")
#: Order of the discretization error of the position-averaged force (piecewise-constant elements; measured
#: 0.89–1.42 from the command's default grids on the cases of docs/performance.md, the spread the scatter's).
THEORETICAL_ORDER = 1.0
#: Draws of the grids' averages within their standard errors that measure how far the scatter alone moves the
#: order's change of ``F₀`` (:func:`fit_first_order`; seeded: the same data give the same estimate).
MODEL_DRAWS = 400
#: A steady solve's cost grows as ``N^COST_EXPONENT`` of the grid's ``N`` elements (measured on the circle,
#: 40 → 120 elements across: 0.11 s → 1.56 s of CPU at 9 times the elements, N^1.2). The allocation uses this
#: model, not measured times, so that the positions (and the result) do not depend on the machine's load.
COST_EXPONENT = 1.2
#: The fixed part of a solve's cost in the same unit (the scene, the operators and the start of a steady solve:
#: about 40 ms, measured on 12 × 12 elements, against 1.56 s for ``N^1.2`` = 9.7e4 on 122 × 122).
COST_OVERHEAD = 2500.0
#: Bounds on the order ``q`` of the scatter's fall ``σ ∝ h^q`` (:func:`scatter`): measured 1.5–1.7 on the circle
#: from 16 to 48 elements per semi-axis (the irregular part of one position falls faster than the grid); the
#: floor takes it to fall no faster than ``h³`` and not to rise as the grid refines.
SCATTER_ORDERS = (0.0, 3.0)
#: The plastic number's inverse powers: the R₂ sequence's steps along x and y (Roberts, "The unreasonable
#: effectiveness of quasirandom sequences", 2018): every prefix is evenly spread over the unit cell.
_PLASTIC = 1.324717957244746
_R2 = (1.0 / _PLASTIC, 1.0 / _PLASTIC ** 2)


@dataclass(frozen=True)
class Extrapolated:
    """One quantity: its averages on the grids and their standard errors, the observed order (None: not
    measurable), the extrapolated value and its error estimate; ``model``: the estimate's part from the order
    (more positions do not shrink it: finer grids do)."""

    values: tuple
    order: float | None
    value: float
    error: float
    scatter: tuple = ()
    model: float = 0.0


def positions(count: int, first: int = 0) -> list:
    """Positions ``first … first + count − 1`` of the grid's shifts ``(u, v)`` in elements: the R₂ sequence
    (module docstring), every prefix evenly spread over the element. It starts one step after the centred grid:
    the centred grid is symmetric about the ellipse's axes on every grid, a special position rather than a
    typical one (on the circle at ξ = 1e-5 and 16 elements per semi-axis its force is 1.4 scatters off the
    average).

    >>> [tuple(round(c, 3) for c in p) for p in positions(3)]
    [(-0.245, -0.43), (-0.49, 0.14), (0.265, -0.29)]
    >>> positions(2, first=1) == positions(3)[1:]
    True
    """
    return [((0.5 + j * _R2[0]) % 1.0 - 0.5, (0.5 + j * _R2[1]) % 1.0 - 0.5)
            for j in range(first + 1, first + count + 1)]


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


def t95(dof: float) -> float:
    """The two-sided 95 % quantile of Student's t with ``dof`` degrees of freedom, at least 2 (the normal's
    1.96 rounded up, where ``dof`` is infinite).

    >>> round(t95(3), 3), round(t95(30), 3), t95(math.inf)
    (3.182, 2.042, 2.0)
    """
    if not math.isfinite(dof):
        return 2.0
    from scipy.special import stdtrit    # (scipy: only where an estimate is made; import rollqp stays light)
    return max(2.0, float(stdtrit(max(dof, 1.0), 0.975)))


def welch_dof(weights, errors, dof) -> float:
    """Welch–Satterthwaite's degrees of freedom of ``Σ w_k F̄_k`` with standard errors ``errors`` each from
    ``dof`` degrees of freedom (infinite where none is given).

    >>> round(welch_dof([1.0, 1.0], [1.0, 1.0], [3, 3]), 6), welch_dof([1.0], [1.0], [math.inf])
    (6.0, inf)
    """
    a = np.square(np.asarray(weights, dtype=float) * np.asarray(errors, dtype=float))
    d = np.asarray(dof, dtype=float)
    den = float(np.sum(np.where(np.isfinite(d), a * a / np.maximum(d, 1.0), 0.0)))
    return math.inf if den == 0.0 else float(np.sum(a)) ** 2 / den


def fit_first_order(h, means, errors, dof=None) -> Extrapolated:
    """``F₀ + C h`` fitted to the grids' averages ``means`` (standard errors ``errors``, each from ``dof``
    degrees of freedom: the grid's positions less one; None: known exactly) and the estimate of the module
    docstring.

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
    free = h.size - 2                # the fit's residual degrees of freedom
    if free > 0:
        r = F - M @ coef
        chi2 = float(np.sum(w * r * r)) / free if np.all(s > 0) else math.inf
        if not np.all(s > 0):        # no scatter measured: the residual alone
            var = float(np.sum(r * r)) / free * float(np.linalg.inv(M.T @ M)[0, 0])
        elif chi2 > 1.0:             # the residual exceeds the scatter: scale up (reduced chi-square)
            var *= chi2
    order = float(_orders(h[-3:], F[None, -3:])[0]) if h.size >= 3 else math.nan
    order = None if math.isnan(order) else order
    if h.size < 3:                   # no order can be measured: the whole correction
        model = abs(F0 - F[-1])
    else:
        g = float(_changes(h, F[None, :], w)[0])
        if np.all(s > 0):
            # beyond what the averages' scatter alone moves it by: the 95 % band of the change over draws of
            # the averages within their standard errors (the change is far from linear in them where the
            # order is poorly measured)
            draws = F + np.random.default_rng(0).standard_normal((MODEL_DRAWS, h.size)) * s
            band = float(np.quantile(np.abs(_changes(h, draws, w) - g), 0.95))
            model = max(0.0, abs(g) - band)
        else:
            model = abs(g)
    t = 2.0 if dof is None or not np.all(s > 0) else t95(welch_dof(sensitivities(h, s), s, dof))
    return Extrapolated(tuple(float(v) for v in F), order, F0, t * math.sqrt(var) + model,
                        tuple(float(v) for v in s), model)


def _orders(h, F) -> np.ndarray:
    """The order ``p`` of ``F = F₀ + C h^p`` through each row of ``F`` (three grids' values, ``h`` coarse to fine,
    any ratios), NaN where no ``p`` in :data:`ORDER_RANGE` fits (differences of opposite signs): a bisection on
    every row at once."""
    (h1, h2, h3), F = h, np.asarray(F, dtype=float)
    d1, d2 = F[:, 0] - F[:, 1], F[:, 1] - F[:, 2]
    ok = (d2 != 0.0) & (d1 * d2 > 0.0)
    target = np.where(ok, d1 / np.where(d2 == 0.0, 1.0, d2), 0.0)

    def g(p):
        return (h1 ** p - h2 ** p) / (h2 ** p - h3 ** p) - target
    lo, hi = np.full(len(F), ORDER_RANGE[0]), np.full(len(F), ORDER_RANGE[1])
    ok &= g(lo) * g(hi) <= 0
    for _ in range(80):          # bisection: g rises monotonically with p for h1 > h2 > h3
        mid = 0.5 * (lo + hi)
        left = g(lo) * g(mid) <= 0
        hi, lo = np.where(left, mid, hi), np.where(left, lo, mid)
    return np.where(ok, 0.5 * (lo + hi), np.nan)


def _changes(h, F, w) -> np.ndarray:
    """For each row of ``F`` (the grids' averages): F₀ with the order measured from the three finest grids less
    the first-order F₀ (weights ``w``); where no order is measurable, the whole correction ``F̄_finest − F₀``."""
    F = np.asarray(F, dtype=float)
    base = F @ sensitivities(h, 1.0 / np.sqrt(w))
    p = _orders(h[-3:], F[:, -3:])
    q = np.where(np.isnan(p), 1.0, p)
    ext = F[:, -1] - (F[:, -2] - F[:, -1]) * h[-1] ** q / (h[-2] ** q - h[-1] ** q)
    return np.where(np.isnan(p), F[:, -1], ext) - base


def sensitivities(h, errors) -> np.ndarray:
    """``w`` with ``F₀ = Σ w_k F̄_k`` in the weighted fit of ``F₀ + C h`` (weights ``1/errors²``).

    >>> [round(float(w), 6) for w in sensitivities([0.1, 0.05], [1.0, 1.0])]    # two grids: F₀ = 2 F̄₂ − F̄₁
    [-1.0, 2.0]
    """
    h, s = np.asarray(h, dtype=float), np.asarray(errors, dtype=float)
    W = 1.0 / s ** 2
    M = np.column_stack([np.ones_like(h), h ** THEORETICAL_ORDER])
    return (np.linalg.inv(M.T @ (W[:, None] * M)) @ (M.T * W))[0]


def scatter(h, samples) -> np.ndarray:
    """Each grid's scatter of one position's value: the larger of its positions' standard deviation and a floor
    from the other grids with four positions or more, through the bounds of :data:`SCATTER_ORDERS` on how the
    scatter falls with ``h``: no faster than ``h³`` from a coarser grid, and not at all rising from a finer one.
    A grid cannot lower its own scatter by a lucky draw (two positions that happen to agree), and the floor,
    a bound rather than a fit, does not raise a grid above what the bounds allow.

    >>> [round(float(s), 4) for s in scatter([0.2, 0.1], [[1.0, 1.2, 1.4, 1.0], [2.0, 2.0]])]   # a lucky draw
    [0.1915, 0.0239]
    """
    h = np.asarray(h, dtype=float)
    own = np.array([float(np.std(v, ddof=1)) if len(v) > 1 else 0.0 for v in samples])
    ok = (own > 0) & (np.array([len(v) for v in samples]) >= 4)
    floor = np.zeros_like(h)
    for k in range(h.size):
        for j in np.flatnonzero(ok):
            if j != k:
                q = SCATTER_ORDERS[1] if h[j] > h[k] else SCATTER_ORDERS[0]
                floor[k] = max(floor[k], own[j] * (h[k] / h[j]) ** q)
    return np.maximum(own, floor)


def allocate(h, sigma, cost, counts, variance: float, most: int = MAX_SHIFTS) -> tuple:
    """Positions per grid that bring ``F₀``'s variance ``Σ w_k² σ_k²/K_k`` to ``variance`` at least cost
    ``Σ K_k c_k``: ``K_k = λ |w_k| σ_k / √c_k`` (module docstring; the weights ``w`` from the resulting errors,
    three passes), never fewer than ``counts``, nor more than twice them (a round re-measures the scatter), nor
    ``most``.

    >>> allocate([1/40, 1/80, 1/120], [3.4e-3, 1.2e-3, 5e-4], [1.0, 5.3, 14.0], [4, 4, 4], (4e-4) ** 2)
    (8, 4, 6)
    """
    h, sigma, cost = (np.asarray(v, dtype=float) for v in (h, sigma, cost))
    low = np.asarray(counts, dtype=float)
    K = low.copy()
    for _ in range(3):
        w = np.abs(sensitivities(h, sigma / np.sqrt(K)))
        lam = float(np.sum(w * sigma * np.sqrt(cost))) / variance
        K = np.maximum(lam * w * sigma / np.sqrt(cost), low)
    return tuple(int(k) for k in np.clip(np.ceil(K - 1e-9), low, np.minimum(2 * low, most)))


@dataclass
class Extrapolation:
    """The grids' averaged forces (``Fx``, ``Fy`` in force units, ``Mz``), their extrapolation, the positions
    solved on each grid (``shifts``) and each grid's wall time; ``str()`` is the table ``rollqp extrapolate``
    prints. ``reached``: whether every creep force's estimate is within ``target`` (None: no target);
    ``stopped``: why the rounds ended."""

    scene: str
    grids: tuple
    shifts: tuple
    forces: dict = field(default_factory=dict)
    seconds: tuple = ()
    cap: float = 1.0
    target: float | None = None
    reached: bool | None = None
    stopped: str = ""
    workers: int = 1

    @property
    def runs(self) -> int:
        """Steady solves made (the positions of every grid)."""
        return int(sum(self.shifts))

    def __str__(self) -> str:
        g = " / ".join(f"{n}" for n in self.grids)
        k = " / ".join(f"{n}" for n in self.shifts)
        lines = [f"{self.scene}: the steady state on grids of {g} elements along the shorter axis, at {k} "
                 f"position(s), {sum(self.seconds):.2f} s"
                 + (f" on {self.workers} workers" if self.workers > 1 else ""),
                 "  " + f"{'':<4} " + " ".join(f"{'grid ' + str(n):>22}" for n in self.grids)
                 + f" {'order':>6} {'extrapolated':>14} {'error estimate':>22}"]
        for key, e in self.forces.items():
            if e is None:
                lines.append(f"  {key:<4} negligible: on every grid below {SMALL:g} of mu FN and within the larger of "
                             f"{NEGLIGIBLE:g} of it and twice its standard error (zero by symmetry)")
                continue
            order = f"{e.order:6.2f}" if e.order is not None else f"{'-':>6}"
            rel = e.error / abs(e.value) if e.value else math.inf
            cells = " ".join(f"{v:12.6g} ± {s:<7.2g}" for v, s in zip(e.values, e.scatter or [0.0] * len(e.values)))
            lines.append(f"  {key:<4} {cells} {order} {e.value:14.7g} {e.error:11.3g} ({100 * rel:.3f} %)")
        lines.append("  (each grid: the average over its positions ± its standard error; extrapolated: F0 of "
                     "F0 + C h; estimate: t (Student's 95 %, the positions' degrees of freedom) times F0's standard error "
                     "+ its change with the measured order)")
        if any(e is not None and e.order is None for e in self.forces.values()):
            lines.append("  (-: no order measurable from the grids for it; the whole correction, beyond what the "
                         "scatter explains, is in the estimate)")
        if self.target is not None:
            if self.reached:
                lines.append(f"  target {100 * self.target:g} % of the creep forces reached")
            else:
                lines.append(f"  target {100 * self.target:g} % of the creep forces NOT reached: {self.stopped}")
        return "\n".join(lines)


def _grid_of(scene):
    """``(nx, ny, (x0, x1), (y0, y1))`` of the scene's grid."""
    g = scene.grid
    return g.nx, g.ny, (g.xl, g.xl + g.nx * g.dx), (g.yl, g.yl + g.ny * g.dy)


def solve_position(scene) -> tuple:
    """One position's steady state: its ``(Fx, Fy, Mz)`` (a top-level function: a worker process runs it), with
    the BLAS pools at ``$ROLLQP_THREADS``."""
    with limited():
        res = run(scene).arrays()
    return tuple(float(res[q][0]) for q in ("Fx", "Fy", "Mz"))


class PositionedGrid:
    """One grid of the extrapolation: ``n`` elements along the scene's shorter axis (``base`` the scene's own
    count), its element size ``h``, the scene of its position ``j`` (:meth:`at`), and the forces of the
    positions solved so far."""

    def __init__(self, scene, n: int, base: int):
        nx, ny, (self.x0, self.x1), (self.y0, self.y1) = _grid_of(scene)
        k = n / base
        self.scene, self.n = scene, n
        self.NX, self.NY = max(round(nx * k), 1), max(round(ny * k), 1)
        self.dx, self.dy = (self.x1 - self.x0) / self.NX, (self.y1 - self.y0) / self.NY
        self.h = math.sqrt(self.dx * self.dy)
        self.forces: list = []
        self.seconds = 0.0

    def at(self, j: int):
        """The scene on this grid at position ``j`` of :func:`positions`: moved by ``(u, v)`` elements, with one
        element more on each side (the moved grid keeps the scene's margin around the contact)."""
        (u, v), = positions(1, first=j)
        return self.scene.replace(**{"discretization.elements": [self.NX + 2, self.NY + 2],
                                     "discretization.zone": None, "discretization.element_size": None,
                                     "discretization.extent": [[self.x0 + (u - 1) * self.dx, self.x1 + (u + 1) * self.dx],
                                                               [self.y0 + (v - 1) * self.dy, self.y1 + (v + 1) * self.dy]],
                                     "discretization.distance": 0.0})

    @property
    def cost(self) -> float:
        """The cost model of one solve (:data:`COST_EXPONENT`, :data:`COST_OVERHEAD`), relative."""
        return float((self.NX + 2) * (self.NY + 2)) ** COST_EXPONENT + COST_OVERHEAD


def _check(grids, shifts, target, budget, workers):
    if len(grids) < 2 or grids[0] < 1 or any(not a < b for a, b in zip(grids, grids[1:])):
        raise InputError("--grids", f"must be two or more increasing element counts, got {grids!r}")
    if shifts is not None and (isinstance(shifts, bool) or not isinstance(shifts, (int, np.integer))
                               or not 2 <= shifts <= MAX_SHIFTS):
        raise InputError("--shifts", f"must be an integer in [2, {MAX_SHIFTS}] (grid positions per grid), got {shifts!r}")
    if target is not None and (isinstance(target, bool) or not isinstance(target, (int, float))
                               or not 0 < target < 1):
        raise InputError("--target", f"must be a relative error in (0, 1) (0.001: 0.1 %), got {target!r}")
    if isinstance(budget, bool) or not isinstance(budget, (int, float)) or not 0 < budget <= 1e6:
        raise InputError("--budget", f"must be a number of seconds in (0, 1e6], got {budget!r}")
    if isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or not 1 <= workers <= 256:
        raise InputError("--workers", f"must be an integer in [1, 256] (processes), got {workers!r}")


def _solve_positions(parts, counts, pool) -> None:
    """Solve the positions each grid lacks up to ``counts``, on ``pool`` (None: here). The finest grid's first:
    the workers' last solves are then the short ones; each grid's positions stay in their order, so the
    averages do not depend on the workers. A failed solve is reported with its grid and position."""
    jobs = [(g, j) for g, k in reversed(list(zip(parts, counts))) for j in range(len(g.forces), k)]
    w0 = time.perf_counter()
    got = (pool.map(solve_position, [g.at(j) for g, j in jobs]) if pool is not None
           else (solve_position(g.at(j)) for g, j in jobs))
    it = iter(got)
    for g, j in jobs:
        try:
            f = next(it)
        except SolverError as err:      # name the grid and position, keep the solver's residual
            (u, v), = positions(1, first=j)
            raise SolverError(f"grid {g.n} at position {j} (u, v) = ({u:.3f}, {v:.3f}) elements: {err.message}",
                              method=err.method, status=err.status, residual=err.residual,
                              iterations=err.iterations) from None
        w1 = time.perf_counter()
        g.forces.append(f)
        g.seconds += w1 - w0
        w0 = w1


def _fits(scene, parts, quantities) -> dict:
    """``{q: (Extrapolated, one position's scatter per grid)}``, None for a negligible quantity."""
    cap = scene.mu * scene.load.normal
    hs = np.array([g.h for g in parts])
    out = {}
    for i, q in enumerate(("Fx", "Fy", "Mz")):
        if q not in quantities:
            continue
        unit = cap * (scene.ellipse.c if q == "Mz" else 1.0)
        vals = [np.array([f[i] for f in g.forces]) for g in parts]
        means = np.array([v.mean() for v in vals])
        sig = scatter(hs, vals)
        counts = np.array([len(v) for v in vals], dtype=float)
        if (np.max(np.abs(means)) <= SMALL * unit
                and np.all(np.abs(means) <= np.maximum(NEGLIGIBLE * unit, 2.0 * sig / np.sqrt(counts)))):
            out[q] = None
            continue
        out[q] = (fit_first_order(hs, means, sig / np.sqrt(counts), dof=counts - 1), sig)
    return out


def _next_counts(parts, counts, short, target) -> tuple:
    """The positions of the next round for the forces ``short`` of their target, or why there is none:
    ``(counts, "")`` or ``(None, why)`` (module docstring)."""
    hs = np.array([g.h for g in parts])
    cost = np.array([g.cost for g in parts])
    new = np.array(counts)
    for q, (e, sig) in short.items():
        se, goal = np.asarray(e.scatter), target * abs(e.value)
        room = goal - e.model
        if room <= 0.25 * goal and min(counts) < CONFIRM:
            # the order's part is most of the target, from too few positions to judge the order: measure
            # it on every grid first
            room = 0.25 * goal
            new = np.maximum(new, np.minimum(CONFIRM, 2 * np.array(counts)))
        elif room <= 0.25 * goal:      # the order's part (beyond the scatter) is most of the target
            why = (f"the order measured from the grids ({e.order:.2f})" if e.order is not None else
                   "the averages, not monotone in h beyond their scatter,")
            return None, (f"{q}: {why} alone add(s) {100 * e.model / abs(e.value):.3f} % to the estimate: the grids "
                          "are not in the asymptotic range (finer --grids)")
        t = t95(welch_dof(sensitivities(hs, se), se, np.asarray(counts) - 1.0))
        new = np.maximum(new, allocate(hs, sig, cost, counts, (room / t) ** 2))
        # no order measurable, the averages' differences within their scatter: the order is measured from the
        # differences of neighbouring averages, so an inner grid's standard error no larger than the smaller
        # of its neighbours' (where the order is measured, an inner grid's scatter only widens its allowance)
        for k in range(1, len(parts) - 1) if e.order is None else ():
            want = math.ceil(counts[k] * (se[k] / min(se[k - 1], se[k + 1])) ** 2 - 1e-9)
            new[k] = max(new[k], min(want, 2 * counts[k], MAX_SHIFTS))
    if np.all(new == counts):   # the variance suffices by the model, the estimate not (the fit's residual above
        #                         the scatter): more positions where they reduce the variance most per cost
        e, sig = next(iter(short.values()))
        w = sensitivities(hs, sig / np.sqrt(counts))
        gain = np.where(np.array(counts) < MAX_SHIFTS, w ** 2 * sig ** 2 / (np.square(counts) * cost), -1.0)
        if gain.max() < 0:
            return None, f"every grid has {MAX_SHIFTS} positions (finer --grids)"
        k = int(np.argmax(gain))
        new[k] = min(2 * counts[k], MAX_SHIFTS)
    return tuple(int(k) for k in new), ""


def _within_budget(parts, counts, new, elapsed, budget) -> tuple:
    """``new`` cut to what the budget's remaining time allows (from each grid's measured time a position), or
    ``(None, why)``."""
    per = np.array([g.seconds / max(len(g.forces), 1) for g in parts])
    more = np.array(new) - np.array(counts)
    ahead = float(np.sum(more * per))
    if elapsed + ahead <= budget:
        return new, ""
    more = np.floor(more * max(budget - elapsed, 0.0) / ahead).astype(int)
    if not more.any():
        return None, (f"the next positions would take about {ahead:.0f} s, beyond the budget of {budget:g} s "
                      "(--budget, or finer --grids)")
    return tuple(int(k) for k in np.array(counts) + more), ""


def _short(fits, target) -> dict:
    """The creep forces (:data:`TARGETED`) whose estimate is beyond ``target`` (relative)."""
    return {q: f for q, f in fits.items()
            if f is not None and q in TARGETED and not f[0].error <= target * abs(f[0].value)}


def extrapolate(scene, grids=None, shifts: int | None = None, *, target: float | None = TARGET,
                budget: float = BUDGET, workers: int = 1, quantities=("Fx", "Fy", "Mz"),
                progress=None) -> Extrapolation:
    """The forces of ``scene``'s steady state extrapolated from grids averaged over positions (module docstring).

    ``grids``: two or more increasing element counts along the shorter axis (default ``n, 2n, 3n`` of the
    scene's ``n``); the other axis keeps the scene's proportion, the grid's extent is the scene's (moved by
    less than an element for each position, one element more on each side to keep the scene's margin around
    the contact). ``shifts``: a fixed number of positions on every grid (then ``target`` is only reported);
    ``None``: :data:`START_SHIFTS` a grid (the finest :data:`FINEST_START`), then positions added where they pay
    (:func:`allocate`) until every creep force (:data:`TARGETED`) has its estimate within ``target``
    (relative) or ``budget`` seconds (wall clock) are spent. ``workers``: processes solving the positions side
    by side (each at ``$ROLLQP_THREADS`` BLAS threads; the numbers do not depend on them). ``progress(text)``:
    told of each round.

    Raises
    ------
    InputError
        A scene that is not a rolling start (no steady state), grids that are not two or more increasing
        counts, positions, a target, a budget or workers out of range.
    SolverError
        A position's solve failed: the message names its grid and position.
    """
    if scene.dimension != 3 or scene.load.start != "rolling":
        raise InputError("SCENE", f"extrapolate works on the steady state of a 3D rolling start "
                                  f"(load.start = 'rolling'); {scene.name!r} is not one")
    base = min(scene.grid.nx, scene.grid.ny)
    grids = (base, 2 * base, 3 * base) if grids is None else tuple(int(g) for g in grids)
    _check(grids, shifts, target, budget, workers)
    t0 = time.perf_counter()
    parts = [PositionedGrid(scene, n, base) for n in grids]
    for g in parts:                  # every grid's scene checked before any solve
        try:
            g.at(0)
        except InputError as err:
            raise InputError("--grids", f"the grid of {g.n} elements: {err}") from None
    counts = ((int(shifts),) * len(parts) if shifts is not None
              else (START_SHIFTS,) * (len(parts) - 1) + (FINEST_START,))
    stopped = ""
    pool = ProcessPoolExecutor(max_workers=int(workers)) if workers > 1 else None
    try:
        _solve_positions(parts, counts, pool)
        while shifts is None and target is not None:
            short = _short(_fits(scene, parts, quantities), target)
            if not short:
                break
            elapsed = time.perf_counter() - t0
            new, stopped = ((None, f"the budget of {budget:g} s is spent (--budget, or finer --grids)")
                            if elapsed >= budget else _next_counts(parts, counts, short, target))
            if new is not None:
                new, stopped = _within_budget(parts, counts, new, elapsed, budget)
            if new is None:
                break
            if progress is not None:
                q = max(short, key=lambda k: short[k][0].error / abs(short[k][0].value))
                e = short[q][0]
                progress(f"positions {'/'.join(map(str, counts))} -> {'/'.join(map(str, new))}: {q} estimate "
                         f"{100 * e.error / abs(e.value):.3f} % > target {100 * target:g} % "
                         f"({time.perf_counter() - t0:.1f} s)")
            counts = new
            _solve_positions(parts, counts, pool)
    finally:
        if pool is not None:
            pool.shutdown()
    fits = _fits(scene, parts, quantities)
    out = Extrapolation(scene.name, grids, tuple(len(g.forces) for g in parts), seconds=tuple(g.seconds for g in parts),
                        cap=scene.mu * scene.load.normal, target=target,
                        reached=None if target is None else not _short(fits, target), stopped=stopped,
                        workers=int(workers))
    out.forces = {q: None if f is None else f[0] for q, f in fits.items()}
    return out
