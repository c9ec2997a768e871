r"""Creep forces extrapolated to the fine-grid limit from three grids (Richardson, the order measured).

The steady state of a rolling start is solved on three grids of ``n₁ < n₂ < n₃`` elements along the shorter
axis in a constant ratio ``r = n₂/n₁ = n₃/n₂`` (the zone kept, so that the ellipse's edge falls at the same
place within its elements on each: default ``n/2, n, 2n`` from the scene's ``n``). With ``F_k`` a force on
grid ``k``, the differences ``d₁ = F₂ − F₁`` and ``d₂ = F₃ − F₂`` give the observed order and the
extrapolated value

.. math::
    p = \frac{\ln(d_1/d_2)}{\ln r},\qquad F_* = F_3 + \frac{d_2}{r^p − 1},

and the error estimate printed with it is the extrapolation's own correction ``|F_* − F_3|`` (Richardson's
estimate of the finest grid's error; ``F_*`` itself is in error by less where the three grids are in the
asymptotic range). Where they are not — ``d₁`` and ``d₂`` of opposite signs, or ``p`` outside
``[0.3, 5]`` — no order is claimed: ``F_*`` is the finest grid's value and the estimate is the larger of
``|d₁|, |d₂|`` (said in the table). The contact edge cuts the elements differently as the grid changes, so
the convergence of a discrete force is not a clean power of ``h``: the measured orders and how close the
estimates come are in docs/performance.md ("Speed against error").

Examples
--------
>>> from rollqp import load_scene
>>> x = extrapolate(load_scene("kalker-circular"), grids=(10, 20, 40))
>>> x.grids, x.forces["Fy"], len(x.forces["Fx"].values)      # Fy = 0 by symmetry
((10, 20, 40), None, 3)
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

from .errors import InputError
from .march.grid import run

__all__ = ["extrapolate", "Extrapolation", "Extrapolated", "richardson", "ORDER_RANGE"]

#: Observed orders accepted as asymptotic (outside it the grids are not in the asymptotic range).
ORDER_RANGE = (0.3, 5.0)
#: Forces below this fraction of μFN (and the moment below it times μFN·c) are zero by symmetry: not extrapolated.
NEGLIGIBLE = 1e-9


@dataclass(frozen=True)
class Extrapolated:
    """One quantity: its values on the grids, the observed order (None: not asymptotic), the extrapolated
    value and its error estimate."""

    values: tuple
    order: float | None
    value: float
    error: float


def richardson(values, ratio: float) -> Extrapolated:
    """Richardson's extrapolation of three values on grids refined by ``ratio`` (module docstring).

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


@dataclass
class Extrapolation:
    """The three grids' forces (``Fx``, ``Fy`` in force units, ``Mz``), their extrapolation, and each grid's
    wall time; ``str()`` is the table ``rollqp extrapolate`` prints."""

    scene: str
    grids: tuple
    ratio: float
    forces: dict = field(default_factory=dict)
    seconds: tuple = ()
    cap: float = 1.0

    def __str__(self) -> str:
        g = " / ".join(f"{n}" for n in self.grids)
        lines = [f"{self.scene}: the steady state on grids of {g} elements along the shorter axis (ratio "
                 f"{self.ratio:g}), {' + '.join(f'{t:.2f}' for t in self.seconds)} = {sum(self.seconds):.2f} s",
                 f"  {'':<4} {'grid ' + str(self.grids[0]):>14} {'grid ' + str(self.grids[1]):>14} "
                 f"{'grid ' + str(self.grids[2]):>14} {'order':>6} {'extrapolated':>14} {'error estimate':>22}"]
        for k, e in self.forces.items():
            if e is None:
                lines.append(f"  {k:<4} zero by symmetry on every grid (below {NEGLIGIBLE:g} of mu FN)")
                continue
            order = f"{e.order:6.2f}" if e.order is not None else f"{'-':>6}"
            rel = e.error / abs(e.value) if e.value else math.inf
            lines.append(f"  {k:<4} {e.values[0]:14.6g} {e.values[1]:14.6g} {e.values[2]:14.6g} {order} "
                         f"{e.value:14.7g} {e.error:11.3g} ({100 * rel:.3f} %)")
        if any(e is not None and e.order is None for e in self.forces.values()):
            lines.append("  (-: the three grids are not in the asymptotic range for it; the finest grid's value and "
                         "the largest difference are shown)")
        return "\n".join(lines)


def extrapolate(scene, grids=None, quantities=("Fx", "Fy", "Mz")) -> Extrapolation:
    """The forces of ``scene``'s steady state extrapolated from three grids (module docstring).

    ``grids``: three element counts along the shorter axis in a constant ratio (default ``n/2, n, 2n`` of
    the scene's ``n``); the other axis keeps the scene's proportion, the zone is the scene's.

    Raises
    ------
    InputError
        A scene that is not a rolling start (no steady state), or grids not three increasing counts in a
        constant ratio.
    """
    if scene.dimension != 3 or scene.load.start != "rolling":
        raise InputError("SCENE", f"extrapolate works on the steady state of a 3D rolling start "
                                  f"(load.start = 'rolling'); {scene.name!r} is not one")
    nx, ny = scene.discretization.elements
    base = min(nx, ny)
    if grids is None:
        grids = (max(base // 2, 1), base, 2 * base)
    grids = tuple(int(g) for g in grids)
    if len(grids) != 3 or not 0 < grids[0] < grids[1] < grids[2]:
        raise InputError("--grids", f"must be three increasing element counts, got {grids!r}")
    r1, r2 = grids[1] / grids[0], grids[2] / grids[1]
    if abs(r1 / r2 - 1) > 1e-9:
        raise InputError("--grids", f"must be in a constant ratio (n2/n1 = n3/n2), got {grids!r} "
                                    f"(ratios {r1:.4g} and {r2:.4g})")
    values, seconds = {q: [] for q in quantities}, []
    for n in grids:
        k = n / base
        s = scene.replace(**{"discretization.elements": [round(nx * k), round(ny * k)],
                             "discretization.distance": 0.0})
        t0 = time.perf_counter()
        res = run(s).arrays()
        seconds.append(time.perf_counter() - t0)
        for q in quantities:
            values[q].append(float(res[q][0]))
    cap = scene.mu * scene.load.normal
    out = Extrapolation(scene.name, grids, r1, seconds=tuple(seconds), cap=cap)
    for q in quantities:
        unit = cap * (scene.ellipse.c if q == "Mz" else 1.0)
        if max(abs(v) for v in values[q]) <= NEGLIGIBLE * unit:
            out.forces[q] = None
        else:
            out.forces[q] = richardson(values[q], r1)
    return out
