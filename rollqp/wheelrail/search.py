r"""The contact search: from a wheel on its rail to contact patches on planar grids (docs/wheel-rail.md).

For a right-side wheel–rail pair at a given position (:mod:`rollqp.wheelrail.wheelset`):

1. **Locus and gap.** Along the contact locus (WR.2) the vertical gap ``g = z_rail(y) − z_wheel`` is
   computed at every sample of the wheel profile; ``g < 0`` is interpenetration of the undeformed
   surfaces.
2. **Regions.** The runs of the locus with ``g < 0`` are interpenetration regions; two regions less than
   ``combine`` mm apart (laterally) whose contact angles differ by less than ``separate_angle`` are one
   patch (CONTACT's ``D_COMB``, ``A_SEP``); others are separate patches (tread and flange).
3. **Contact reference** of each patch: the centre of its interpenetration area weighted by the
   squared overlap, ``y_c = ∬ y g² dx dy / ∬ g² dx dy`` (and ``x_c`` likewise; :func:`_weights`), on the
   rail surface ``z_c = z_rail(y_c)``; the **contact angle** ``δ`` the same weighted mean of the rail
   surface's inclination ``atan(dz/dy)`` (CONTACT's weighted centre and weighted angle). The contact frame is
   ``e_x = (1, 0, 0)``, ``e_s = (0, cos δ, sin δ)``, ``e_n = (0, −sin δ, cos δ)`` (into the rail).
4. **Planar contact approach.** On the plane through the reference spanned by ``e_x, e_s``, the
   undeformed distance ``h(x, s)`` is the distance along ``e_n`` from the wheel surface to the rail
   surface (negative where they overlap): the rail from its profile turned into the plane's
   coordinates, the wheel by Newton's method on the line through each grid point
   (:meth:`~rollqp.wheelrail.wheelset.Wheelset.surface_along`).
5. **Grid.** Elements ``dx × ds`` covering the region's extent in ``s`` and its extent in ``x``
   (``±√(2 ρ_x g_n)``, ``ρ_x = ρ/cos δ`` the wheel's radius in the rolling direction, ``g_n`` the
   normal overlap) with :data:`MARGIN` to spare: the interpenetration region of the undeformed surfaces
   holds the contact area at this approach (Hertz: 1/√2 of it).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..discretization.grid import Grid, MAX_ELEMENTS

__all__ = ["Patch", "search", "touch", "MARGIN"]

#: Relative margin of a patch's grid beyond its interpenetration region, plus 2 elements a side.
MARGIN = 0.15


@dataclass
class Patch:
    """One contact patch of a right-side pair: reference ``origin`` (track frame), ``angle`` δ, its axes,
    ``grid`` (x along e_x, y along e_s) and ``gap`` on it (``(n,)``, mm), the wheel's surface point
    ``wheel_point`` along ``e_n`` from the origin, and the rigid overlap ``overlap`` (max −gap)."""

    origin: np.ndarray
    angle: float
    grid: Grid
    gap: np.ndarray
    wheel_point: np.ndarray
    overlap: float
    radius_x: float
    curvature_s: float
    region: tuple = field(default=())

    @property
    def axes(self):
        c, s = math.cos(self.angle), math.sin(self.angle)
        return np.array([1.0, 0, 0]), np.array([0.0, c, s]), np.array([0.0, -s, c])


def touch(track, wheelset, state):
    """The vertical gap along the locus: ``(points, y_w, g)`` with ``g`` nan where the locus is invalid."""
    p, yw, ok = wheelset.locus(state)
    g = track.z_at(p[:, 1]) - p[:, 2]
    g = np.where(ok, g, np.nan)
    return p, yw, g


def _runs(mask):
    """``[(i0, i1)]`` of the runs of True in ``mask`` (i1 exclusive)."""
    m = np.concatenate([[False], mask, [False]]).astype(int)
    d = np.diff(m)
    return list(zip(np.nonzero(d == 1)[0], np.nonzero(d == -1)[0]))


def search(track, wheelset, state, dx: float, ds: float, combine: float = 4.0, separate_angle: float = math.pi / 2,
           key: str = "wheelset", grow: float = 1.0):
    """The patches of the pair at ``state`` (module docstring); ``[]`` if the surfaces do not overlap."""
    p, yw, g = touch(track, wheelset, state)
    pen = np.where(np.isfinite(g) & (g < 0), -g, 0.0)
    runs = _runs(pen > 0)
    if not runs:
        return []
    yt = p[:, 1]
    slope = track.slope_at(yt)
    ang = np.arctan(np.nan_to_num(slope))
    # merge close runs of similar angle
    groups = [list(runs[0])]
    for i0, i1 in runs[1:]:
        j0, j1 = groups[-1]
        a_prev = float(np.average(ang[j0:j1], weights=pen[j0:j1]))
        a_new = float(np.average(ang[i0:i1], weights=pen[i0:i1]))
        if abs(yt[i0] - yt[j1 - 1]) <= combine and abs(a_new - a_prev) <= separate_angle:
            groups[-1][1] = i1
        else:
            groups.append([i0, i1])
    patches = []
    for i0, i1 in groups:
        sl = slice(i0, i1)
        w = _weights(pen[sl], yt[sl], wheelset.radius_at(yw[sl]), ang[sl])
        yc = float(np.sum(w * yt[sl]) / np.sum(w))
        xc = float(np.sum(w * p[sl, 0]) / np.sum(w))
        delta = float(np.sum(w * ang[sl]) / np.sum(w))
        origin = np.array([xc, yc, float(track.z_at(yc))])
        patches.append(_planar(track, wheelset, state, origin, delta, p[i0:i1], pen[i0:i1], yw[i0:i1], dx, ds, key, grow))
    return patches


def _weights(pen, y, rho, ang):
    """The weights of the contact reference (step 3): the squared overlap integrated over the
    interpenetration area, ``∬ g² dx dy``; along ``x`` the overlap of a slice is ``g(1 − x²/L²)`` with
    ``L = √(2 ρ_x g)``, whose squared integral is ``(16/15) g² L`` — so a locus point weighs
    ``g^{5/2} √(ρ_x) |dy|``."""
    rx = rho / np.maximum(np.cos(ang), 0.05)
    dy = np.abs(np.gradient(y)) if y.size > 1 else np.ones(1)
    w = pen ** 2.5 * np.sqrt(rx) * dy
    return w if np.sum(w) > 0 else np.ones_like(pen)


def _planar(track, wheelset, state, origin, delta, pts, pen, yw, dx, ds, key, grow: float = 1.0):
    """The patch's grid and gap (steps 4–5 of the module docstring)."""
    c, s = math.cos(delta), math.sin(delta)
    ex, es, en = np.array([1.0, 0, 0]), np.array([0.0, c, s]), np.array([0.0, -s, c])
    rel = pts - origin
    sj = rel @ es
    pn = pen * c                                    # vertical overlap → along the normal
    rho = wheelset.radius_at(yw)
    rx = float(np.nanmax(rho)) / max(c, 0.05)
    half = np.sqrt(2.0 * rx * np.maximum(pn, 0.0))
    xj = rel @ ex
    x0, x1 = float(np.min(xj - half)), float(np.max(xj + half))
    s0, s1 = float(np.min(sj)) - ds, float(np.max(sj)) + ds
    mx, ms = grow * MARGIN * (x1 - x0) + 2 * dx, grow * MARGIN * (s1 - s0) + 2 * ds
    x0, x1, s0, s1 = x0 - mx, x1 + mx, s0 - ms, s1 + ms
    nx, ny = max(int(math.ceil((x1 - x0) / dx)), 4), max(int(math.ceil((s1 - s0) / ds)), 4)
    if nx * ny > MAX_ELEMENTS:
        raise InputError("discretization.element_size", f"a patch of {x1 - x0:.3g} × {s1 - s0:.3g} mm needs "
                                                         f"{nx} × {ny} elements, more than {MAX_ELEMENTS}: "
                                                         f"take larger elements")
    xm, sm = 0.5 * (x0 + x1), 0.5 * (s0 + s1)
    grid = Grid(nx, ny, dx, ds, xm - nx * dx / 2, sm - ny * ds / 2)
    gap = planar_gap(track, wheelset, state, origin, delta, grid, key)
    W = origin + wheelset.surface_along(state, origin[None, :], en, key)[0] * en
    # curvature of the gap across (along s) at the origin: for the scales of the patch's solve only
    h0 = planar_gap_line(track, wheelset, state, origin, delta, np.array([-ds, 0.0, ds]), key)
    curv_s = max((h0[0] - 2 * h0[1] + h0[2]) / (2 * ds * ds), 1e-3 / (2 * rx))
    return Patch(origin, delta, grid, gap, W, float(-np.min(gap)), rx, float(curv_s), (float(s0), float(s1)))


def rail_normal_coordinate(track, origin, delta, s):
    """The rail surface's coordinate along ``e_n`` above the plane points at ``s`` (the rail profile turned
    into the plane's coordinates, interpolated in ``s``)."""
    c, sn = math.cos(delta), math.sin(delta)
    ys, zs = track.points
    sk = (ys - origin[1]) * c + (zs - origin[2]) * sn
    nk = -(ys - origin[1]) * sn + (zs - origin[2]) * c
    lo, hi = float(np.min(s)) - 1.0, float(np.max(s)) + 1.0
    sel = (sk >= lo) & (sk <= hi)
    if np.count_nonzero(sel) < 2 or np.any(np.diff(sk[sel]) <= 0):
        raise InputError("rail profile", f"the rail surface is not a height field over the contact plane at "
                                         f"y = {origin[1]:.3f} (contact angle {delta:.3f} rad)")
    return np.interp(s, sk[sel], nk[sel], left=np.nan, right=np.nan)


def planar_gap(track, wheelset, state, origin, delta, grid, key="wheelset"):
    """``h(x, s)`` at the grid's element centres (flattened, module docstring step 4)."""
    x, y = grid.centres()
    return _gap(track, wheelset, state, origin, delta, x, y, key)


def planar_gap_line(track, wheelset, state, origin, delta, s, key="wheelset"):
    return _gap(track, wheelset, state, origin, delta, np.zeros_like(s), s, key)


def _gap(track, wheelset, state, origin, delta, x, s, key):
    c, sn = math.cos(delta), math.sin(delta)
    es, en = np.array([0.0, c, sn]), np.array([0.0, -sn, c])
    P = origin + np.outer(x, [1.0, 0, 0]) + np.outer(s, es)
    tw = wheelset.surface_along(state, P, en, key)
    nr = rail_normal_coordinate(track, origin, delta, s)
    if np.any(~np.isfinite(nr)):
        raise InputError("rail profile", "a patch reaches beyond the rail profile's ends")
    return nr - tw
