r"""The contact patch of a non-Hertzian 3D scene, found by the normal step (docs/scenes.md, "Three
dimensions: beyond Hertz"; docs/validation3d.md, "Non-Hertzian geometry").

With a body ``profile`` (:mod:`rollqp.profiles3d`) the contact area is not the Hertz ellipse: it is what
the frictionless normal step (eq. 3D.14) on the grid finds for the undeformed distance ``h(x, y)``.
:func:`computed_patch` solves that step once, at the reference load and ``q = 0``, and returns the
:class:`Patch`: the pressure, the elements in contact, their area, the half-lengths through the origin
(from the element edges of the contact run on the row and the column through the origin) and the
**equivalent curvatures** ``(A, B)``, those whose Hertz ellipse of the same force has exactly these
half-lengths — so that ``p0 = 3FN/(2πab)`` and the scales of the residuals follow the computed contact
(:func:`equivalent_curvatures`).

:func:`check_patch` is the scene's check that the grid covers the computed contact with a row of
elements to spare (no pressure on the outermost rows and columns), naming the grid's key.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .closedforms.hertz_ellipse import curvatures_for_ratio, hertz
from .discretization.grid import ASPECT_RANGE, MAX_ELEMENTS, Grid
from .errors import InputError, SolverError
from .operators.grid import Contact

__all__ = ["Patch", "computed_patch", "equivalent_curvatures", "check_patch", "guess_curvatures"]


@dataclass(frozen=True)
class Patch:
    """The computed contact: ``p`` (``(ny, nx)``), ``contact`` (bool, ``(ny, nx)``), ``area``, the
    half-lengths ``a``, ``b`` through the origin, the centre ``(xc, yc)`` of those runs, and the
    approach ``delta``."""

    p: np.ndarray
    contact: np.ndarray
    area: float
    a: float
    b: float
    xc: float
    yc: float
    delta: float


def guess_curvatures(h, grid) -> tuple[float, float]:
    """Secant curvatures of ``h`` at half the grid's reach from the origin along each axis: a start (the
    warm pressure and the scales of the solve), not an answer. An :class:`InputError` if ``h`` does not
    rise away from the origin (no concentrated contact)."""
    out = []
    for axis, lo, n, d in (("x", grid.xl, grid.nx, grid.dx), ("y", grid.yl, grid.ny, grid.dy)):
        reach = 0.5 * max(abs(lo), abs(lo + n * d))
        pts = np.array([-reach, reach])
        v = h(pts, 0.0 * pts) if axis == "x" else h(0.0 * pts, pts)
        v = np.asarray(v, dtype=float) - float(np.asarray(h(np.zeros(1), np.zeros(1)))[0])
        c = float(np.min(v)) / reach ** 2
        if not c > 0:
            raise InputError("profile", f"the undeformed distance does not rise away from the origin along {axis} "
                                        "within the grid: no concentrated contact")
        out.append(c)
    return out[0], out[1]


def equivalent_curvatures(a: float, b: float, Estar: float, FN: float) -> tuple[float, float]:
    """``(A, B)`` whose Hertz ellipse of ``FN`` has the semi-axes ``a``, ``b`` (Hertz's semi-axes scale as
    ``(A, B)^(-1/3)`` at a fixed ratio ``B/A``).

    Examples
    --------
    >>> A, B = equivalent_curvatures(0.5, 0.8, 230769.0, 500.0)
    >>> e = hertz(A, B, 230769.0, 500.0)
    >>> round(e.a, 12), round(e.b, 12)
    (0.5, 0.8)
    """
    B1 = curvatures_for_ratio(1.0, a / b)
    e = hertz(1.0, B1, Estar, FN)
    lam = (e.a / a) ** 3
    return lam, lam * B1


def _run(contact_row, edges):
    """The half-length and centre of the contact run on a row (``contact_row`` bool, element ``edges``)."""
    idx = np.flatnonzero(contact_row)
    if idx.size == 0:
        return 0.0, 0.0
    lo, hi = edges[idx[0]], edges[idx[-1] + 1]
    return 0.5 * (hi - lo), 0.5 * (hi + lo)


def computed_patch(h, grid, materials, FN: float, method, guess=None) -> Patch:
    """The frictionless normal step of ``h`` on ``grid`` pressed by ``FN``, solved by ``method`` (module
    docstring); ``guess``: curvatures for its start and scales (default :func:`guess_curvatures`)."""
    guess = guess or guess_curvatures(h, grid)
    contact = Contact(grid, materials, guess, FN, 0.0, profile=h)
    method.setup(contact)
    try:
        sol = method.solve(contact.normal_step(FN), contact.hertz_start(FN))
    except SolverError as err:
        raise SolverError(f"the normal step of the profile did not converge ({err})", method=method.name) from err
    p = grid.field(sol.p)
    on = p > 1e-12 * float(np.max(p))        # the solution's zeros are exact up to round-off of p0
    xe = grid.xl + np.arange(grid.nx + 1) * grid.dx
    ye = grid.yl + np.arange(grid.ny + 1) * grid.dy
    rows = [j for j in range(grid.ny) if ye[j] <= 0.0 <= ye[j + 1]]
    cols = [i for i in range(grid.nx) if xe[i] <= 0.0 <= xe[i + 1]]
    if not rows or not cols:
        raise InputError("discretization.extent", "the grid must contain the origin (the first point of contact)")
    ax = [_run(on[j], xe) for j in rows]
    by = [_run(on[:, i], ye) for i in cols]
    a, xc = (float(np.mean([v[k] for v in ax])) for k in (0, 1))
    b, yc = (float(np.mean([v[k] for v in by])) for k in (0, 1))
    if not (a > 0 and b > 0):
        raise InputError("load.normal", f"the computed contact does not pass through the origin (half-lengths "
                                        f"{a:.3g}, {b:.3g}): the profile's lowest point must be at x = y = 0")
    return Patch(p=p, contact=on, area=float(on.sum()) * grid.area, a=a, b=b, xc=xc, yc=yc, delta=float(sol.delta))


def check_patch(patch: Patch, key: str) -> None:
    """The computed contact keeps off the grid's outermost rows and columns (a row of elements to spare)."""
    on = patch.contact
    edge = {"x": bool(on[:, 0].any() or on[:, -1].any()), "y": bool(on[0].any() or on[-1].any())}
    for axis, hit in edge.items():
        if hit:
            raise InputError(key, f"the computed contact reaches the grid's outer {'columns' if axis == 'x' else 'rows'} "
                                  f"(along {axis}): the grid must cover it with a row of elements to spare; widen it "
                                  f"(computed half-lengths through the origin: a = {patch.a:.4g}, b = {patch.b:.4g})")



# =========================================================================== the grid in length units
def _pair_of(key, v, what):
    if isinstance(v, (str, bytes, dict)) or not hasattr(v, "__len__") or len(v) != 2:
        raise InputError(key, f"must be a pair [along x, along y] of {what}, got {v!r}")
    return tuple(v)


def _real(key, v) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)) or not np.isfinite(v):
        raise InputError(key, f"must be a finite number, got {v!r}")
    return float(v)


def grid_extent(extent, zone, element_size, elements):
    """The checked ``discretization.extent`` (``((x0, x1), (y0, y1))``, length units, around the origin) and
    ``element_size`` (``(dx, dy) > 0``), or None each: the grid is given by ``zone`` or by ``extent``, its
    elements by ``elements`` or ``element_size`` (one of each pair), and its elements are within
    :data:`~rollqp.discretization.grid.ASPECT_RANGE` and :data:`~rollqp.discretization.grid.MAX_ELEMENTS`."""
    if extent is None:
        if element_size is not None:
            raise InputError("discretization.element_size", "needs discretization.extent (the grid in length units); "
                                                            "with discretization.zone give elements")
        return None, None
    if zone is not None:
        raise InputError("discretization.zone", "give the grid as zone (half-widths / (a, b)) or as "
                                                "discretization.extent (length units), not both")
    if element_size is not None and elements is not None:
        raise InputError("discretization.element_size", "give discretization.elements or element_size, not both")
    rows = _pair_of("discretization.extent", extent, "[lower, upper] bounds, [[x0, x1], [y0, y1]]")
    out = []
    for axis, r in zip("xy", rows):
        k = f"discretization.extent[{'01'[axis == 'y']}]"
        lo, hi = (_real(f"{k}[{i}]", v) for i, v in enumerate(_pair_of(k, r, f"bounds along {axis}")))
        if not lo < 0 < hi:
            raise InputError(k, f"must hold the origin (the first point of contact): x0 < 0 < x1, got [{lo!r}, {hi!r}]")
        out.append((lo, hi))
    size = None
    if element_size is not None:
        size = tuple(_real(f"discretization.element_size[{i}]", v)
                     for i, v in enumerate(_pair_of("discretization.element_size", element_size, "sizes > 0")))
        if not all(v > 0 for v in size):
            raise InputError("discretization.element_size", f"must be sizes > 0 (length units), got {list(size)!r}")
        key = "discretization.element_size"
        counts = [round((hi - lo) / d) for (lo, hi), d in zip(out, size)]
    else:
        key = "discretization.elements"
        counts = list(_pair_of(key, elements, "element counts along x and y")) if elements is not None else [40, 40]
    for i, n in enumerate(counts):
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 4 <= n <= 10_000:
            raise InputError(key, f"gives {n!r} elements along {'xy'[i]}: must be 4 to 10000")
    if counts[0] * counts[1] > MAX_ELEMENTS:
        raise InputError(key, f"nx·ny = {counts[0] * counts[1]} exceeds {MAX_ELEMENTS} elements")
    dx, dy = ((hi - lo) / n for (lo, hi), n in zip(out, counts))
    lo_r, hi_r = ASPECT_RANGE
    if not lo_r <= dx / dy <= hi_r:
        raise InputError(key, f"element aspect ratio dx/dy = {dx / dy:.4g} must be in [{lo_r:g}, {hi_r:g}]: the "
                              "tractions are resolved only to O(max(dx, dy)) (docs/validation3d.md §8)")
    return tuple(out), size


def extent_grid(extent, elements, element_size):
    """The :class:`~rollqp.discretization.grid.Grid` of ``extent`` with ``elements`` (or ``round(width/element_size)``
    elements of the width exactly)."""
    (x0, x1), (y0, y1) = extent
    if element_size is not None:
        nx, ny = (round((hi - lo) / d) for (lo, hi), d in zip(extent, element_size))
    else:
        nx, ny = elements if elements is not None else (40, 40)
    return Grid(int(nx), int(ny), (x1 - x0) / nx, (y1 - y0) / ny, x0, y0)


# =========================================================================== a profile that rolls through
def moving_profile(contact, shape, direction: int, key: str = "discretization.zone"):
    """``move(q)``: sets ``contact.h`` to the undeformed distance after the rolled distance ``q`` (a material
    feature at ``s`` is then at ``x = s + d·q``, ``d = direction``), the hook the march calls before each
    rolling step of a scene whose profile moves (:attr:`rollqp.profiles3d.Shape.moves`); ``move.check(p, k)``
    after the step: the contact keeps off the grid's outermost rows and columns, else an
    :class:`InputError` naming ``key`` and the step (the scene's check, :func:`check_patch`, at every step)."""
    g = contact.grid

    def move(q: float) -> None:
        h = np.asarray(shape(contact.x, contact.y, direction * float(q)), dtype=float)
        if not np.all(np.isfinite(h)):
            raise InputError("profile", f"the undeformed distance at q = {q!r} is not finite")
        contact.h = h

    def check(p, k: int) -> None:
        on = g.field(np.asarray(p) > 0)
        if on[:, 0].any() or on[:, -1].any() or on[0].any() or on[-1].any():
            raise InputError(key, f"at rolling step {k} the contact reaches the grid's outer rows or columns (a "
                                  "profile feature rolling through widened it): the grid must cover it with a row "
                                  "of elements to spare; widen it")

    move.check = check
    return move
