r"""A wheel on its rail solved: the vertical load met, every patch's normal and tangential problem
(docs/wheel-rail.md, "Solving").

For one wheel (:func:`solve_wheel`):

1. **Passes.** The contact search (:func:`rollqp.wheelrail.search.search`) at the wheelset's vertical
   position ``z`` gives the patches, each with its grid and undeformed distance ``h_p`` (negative
   where the surfaces overlap). Lowering the wheelset by ``Δz`` brings patch ``p``'s surfaces closer by
   ``Δz cos δ_p`` along its normal: its normal problem (eq. 3D.14) is solved with the prescribed
   approach ``Δz cos δ_p`` on ``h_p`` — one ``Δz`` for all patches of the wheel. ``Δz`` is found by the
   secant method on ``(F_z/F)^{2/3}`` (nearly linear in the approach for Hertz-like patches) until the
   vertical force ``F_z = Σ_p (F_{N,p} cos δ_p + F_{s,p} sin δ_p)`` on the rail equals the load ``F``
   to :data:`LOAD_TOLERANCE`. The search is repeated at ``z + Δz`` until ``|Δz|`` is below
   :data:`Z_TOLERANCE` of the overlap (or the grid is enlarged when a patch's pressure reaches its
   outer elements).
2. **Tangential problems.** Each patch's steady rolling problem (eq. 3D.17) is solved with the
   creepages of the wheelset's motion at the patch (WR.3) by the scene's method (Newton by default).
   The tangential forces' vertical part ``F_s sin δ`` enters the load balance: step 1's force balance
   is solved again with it until it changes by less than :data:`LOAD_TOLERANCE`.

Forces are those on the rail (body A, CONTACT's body 1): per patch ``(F_x, F_s, F_N, M_n)`` in its
contact frame, per wheel their sum in the track frame. A left wheel is computed as the mirror image of
a right one and mirrored back (``y``, ``δ``, ``F_s``, ``M_n``, ``η``, ``φ`` change sign).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import InputError, SolverError
from ..march.grid import steady
from ..operators.grid import Contact, Loads
from ..problem.grid import NormalStep
from .search import search, touch

__all__ = ["PatchResult", "WheelResult", "solve_wheel", "LOAD_TOLERANCE", "Z_TOLERANCE"]

#: Relative tolerance of the vertical force balance (the normal solves are exact to the method's tolerance).
LOAD_TOLERANCE = 1e-8
#: A pass is the last when its vertical correction is below this fraction of the patches' overlap: the
#: reference then moves by far less than an element (the load is met exactly on the last pass's geometry).
Z_TOLERANCE = 0.02
MAX_PASSES = 8
#: The first pass (finding the vertical position roughly) runs on elements this many times larger.
COARSE = 2.0


class _Gap:
    """``h(x, y)`` of a patch on its own grid (the seam :class:`~rollqp.operators.grid.Contact` takes)."""

    def __init__(self, grid, gap):
        self.grid, self.gap = grid, np.asarray(gap, dtype=float)

    def __call__(self, x, y):
        if np.shape(x) != self.gap.shape:
            raise InputError("profile", "the patch's undeformed distance is defined on its own grid only")
        return self.gap


@dataclass
class PatchResult:
    """One patch's answer (module docstring; lengths mm, forces N, on the rail, output side)."""

    wheel: str
    origin: np.ndarray            # contact reference, track frame
    angle: float                  # δ
    y_rail: float                 # reference on the rail profile (profile coordinates, output side)
    z_rail: float
    wheel_point: np.ndarray       # the wheel profile coordinates (y_w, z_w) of the reference
    creepage: tuple               # ξ, η, φ
    FN: float
    Fx: float
    Fs: float
    Mn: float
    approach: float               # the rigid approach: the largest overlap of the undeformed surfaces along e_n
    area: float
    pmax: float
    x: np.ndarray
    y: np.ndarray
    p: np.ndarray
    t: np.ndarray
    state: np.ndarray
    residual: float
    iterations: int
    time: float
    contact: object = field(repr=False, default=None)
    record: object = field(repr=False, default=None)

    @property
    def force_track(self) -> np.ndarray:
        """``(F_x, F_y, F_z)`` of the patch on the rail in the track frame."""
        c, s = math.cos(self.angle), math.sin(self.angle)
        return np.array([self.Fx, self.Fs * c - self.FN * s, self.Fs * s + self.FN * c])


@dataclass
class WheelResult:
    """A wheel's answer: ``side``, the wheelset's vertical position ``z``, ``patches`` and totals."""

    side: str
    z: float
    patches: list
    passes: int
    time: float

    @property
    def force_rail(self) -> np.ndarray:
        """Total force on the rail, track frame (CONTACT's FX(TR), FY(TR), FZ(TR))."""
        return np.sum([p.force_track for p in self.patches], axis=0) if self.patches else np.zeros(3)

    @property
    def force_wheel(self) -> np.ndarray:
        """Total force on the wheel, track frame: ``−force_rail``."""
        return -self.force_rail


def _normal(method, contact, approach, warm):
    prob = NormalStep(contact.ops.Ann, contact.grid.area, contact.h, delta=float(approach), scales=contact.scales)
    if not approach > float(np.min(contact.h)):
        return None
    return method.solve(prob, warm)


def _normal_force(method, contact, FN, warm):
    prob = NormalStep(contact.ops.Ann, contact.grid.area, contact.h, FN=float(FN), scales=contact.scales)
    return method.solve(prob, warm)


def _balance(method, contacts, patches, target, warm, key):
    """``(Δz, normal solutions)`` with ``Σ F_N,p(Δz cos δ_p) cos δ_p = target`` (module docstring); one
    patch: its normal force ``target / cos δ`` prescribed, ``Δz`` from its approach."""
    cosd = np.array([math.cos(p.angle) for p in patches])
    if not target > 0:
        raise InputError("wheelset.load", f"the vertical load left for the normal forces must be > 0, got {target:g}")
    if len(patches) == 1:
        s = _normal_force(method, contacts[0], target / cosd[0], warm[0])
        return s.delta / cosd[0], [s]
    sols = list(warm)

    def force(dz):
        tot = 0.0
        for i, (c, p) in enumerate(zip(contacts, patches)):
            s = _normal(method, c, dz * cosd[i], sols[i])
            if s is not None:
                sols[i] = s
                tot += c.grid.area * float(np.sum(s.p)) * cosd[i]
            else:
                sols[i] = None
        return tot

    def f(dz):
        return (max(force(dz), 0.0) / target) ** (2.0 / 3.0) - 1.0

    scale = max(max(p.overlap for p in patches), 1e-6)
    a, fa = 0.0, f(0.0)
    b = 0.5 * scale if fa < 0 else -0.3 * scale
    fb = f(b)
    for _ in range(60):
        if abs(fb) <= LOAD_TOLERANCE:
            return b, sols
        if fb == fa:
            break
        c = b - fb * (b - a) / (fb - fa)
        if not math.isfinite(c):
            break
        if fb <= -1.0 + 1e-12 and fa <= -1.0 + 1e-12:   # both without contact: lower further
            c = b + scale
        a, fa, b = b, fb, c
        fb = f(b)
    raise SolverError(f"{key}: the vertical load was not met (secant method on the wheelset's vertical position)",
                      residual=abs(fb))


def _touches_edge(grid, p) -> bool:
    P = grid.field(p)
    return bool(np.any(P[0] > 0) or np.any(P[-1] > 0) or np.any(P[:, 0] > 0) or np.any(P[:, -1] > 0))


def _curvatures(patch):
    return (1.0 / (2.0 * patch.radius_x), max(patch.curvature_s, 1e-3 / (2.0 * patch.radius_x)))


def solve_wheel(track, wheelset, state, materials, mu: float, load: float | None, dx: float, ds: float, method,
                side: str = "right", combine: float = 4.0, separate_angle: float = math.pi / 2) -> WheelResult:
    """Solve one wheel on its rail (module docstring).

    ``state`` is the wheelset's (track frame, as given: a left wheel is mirrored here); ``load`` the
    vertical force per wheel (``None``: ``state.vertical`` prescribed); ``dx``, ``ds`` the element size;
    ``method`` a 3D method (:func:`rollqp.methods.get_method`).
    """
    if side not in ("left", "right"):
        raise InputError("wheelset.side", f"must be 'left' or 'right', got {side!r}")
    t0 = time.perf_counter()
    st = state.mirrored() if side == "left" else state
    key = f"wheelset ({side} wheel)"
    if load is not None:
        _, _, g = touch(track, wheelset, replace(st, vertical=0.0))
        if not np.any(np.isfinite(g)):
            raise InputError("wheelset.lateral", f"the {side} wheel and its rail have no point in common laterally")
        z = float(np.nanmin(g)) + 0.02
    else:
        z = st.vertical
    grow, correction, passes = 1.0, 0.0, 0
    warm, contacts, patches, nsols = None, [], [], []
    for passes in range(1, MAX_PASSES + 1):
        coarse = COARSE if passes == 1 and load is not None else 1.0
        patches = search(track, wheelset, replace(st, vertical=z), coarse * dx, coarse * ds, combine, separate_angle,
                         key, grow=grow)
        if not patches:
            if load is None:
                raise InputError("wheelset.vertical", f"the {side} wheel does not touch its rail at this position")
            z += 0.05
            continue
        contacts = [Contact(p.grid, materials, _curvatures(p), load or 1e4, mu, profile=_Gap(p.grid, p.gap))
                    for p in patches]
        if load is None:
            dz = 0.0
            nsols = [_normal(method, c, 0.0, None) for c in contacts]
        else:
            dz, nsols = _balance(method, contacts, patches, load - correction, [None] * len(patches), key)
        edge = any(s is not None and _touches_edge(c.grid, s.p) for c, s in zip(contacts, nsols))
        overlap = max(p.overlap for p in patches)
        if edge:
            grow *= 1.6
            z += dz
            continue
        if load is None or (coarse == 1.0 and abs(dz) <= Z_TOLERANCE * max(overlap + dz, 1e-9)):
            z += dz
            break
        z += dz
    else:
        raise SolverError(f"{key}: the contact search did not settle in {MAX_PASSES} passes (a patch keeps growing "
                          f"beyond its grid or the vertical position keeps moving)")
    # tangential problems, with their vertical force in the balance
    z_pass = z - dz
    results = []
    for _ in range(20):
        results = []
        new_corr = 0.0
        for patch, contact, nsol in zip(patches, contacts, nsols):
            results.append(_tangential(wheelset, replace(st, vertical=z), patch, contact, nsol, method, side,
                                       track, dz))
            if nsol is not None:
                new_corr += results[-1].Fs * math.sin(patch.angle)
        if load is None or abs(new_corr - correction) <= LOAD_TOLERANCE * load * 10:
            break
        correction = new_corr
        dz, nsols = _balance(method, contacts, patches, load - correction, nsols, key)
        z = z_pass + dz
    out = [r for r in results if r.FN > 0]
    if side == "left":
        out = [_mirror(r) for r in out]
    return WheelResult(side, z, out, passes, time.perf_counter() - t0)


def _tangential(wheelset, st, patch, contact, nsol, method, side, track, dz):
    ex, es, en = patch.axes
    t0 = time.perf_counter()
    # the wheel's surface point along the normal from the reference, moved with the wheelset by dz
    W = patch.wheel_point + np.array([0.0, 0.0, dz])
    xi, eta, phi = wheelset.creepages(st, W, ex, es, en)
    yr, zr = track.to_rail(patch.origin[1], patch.origin[2])
    q = (W - wheelset.centre(st)) @ wheelset.rotation(st)
    wp = np.array([q[1] - wheelset.offset, math.hypot(q[0], q[2]) - wheelset.nominal_radius])
    g = contact.grid
    if nsol is None:
        zero = np.zeros(g.n)
        return PatchResult(side, patch.origin.copy(), patch.angle, float(yr), float(zr), wp, (xi, eta, phi), 0.0, 0.0,
                           0.0, 0.0, 0.0, 0.0, 0.0, g.x, g.y, zero, np.zeros((2, g.n)), zero.astype(np.int8), 0.0, 0,
                           0.0, contact)
    FN = g.area * float(np.sum(nsol.p))
    rec = steady(contact, method, FN, Loads(xi=xi, eta=eta, phi=phi), direction=-1, pressure=nsol)
    Fx, Fs, Mn = contact.moments(rec.t)
    elapsed = time.perf_counter() - t0
    return PatchResult(side, patch.origin.copy(), patch.angle, float(yr), float(zr), wp, (xi, eta, phi), FN, Fx, Fs,
                       Mn, patch.overlap + float(nsol.delta), g.area * float(np.count_nonzero(nsol.p > 0)), float(np.max(nsol.p)),
                       g.x, g.y, nsol.p, rec.t, rec.state, float(rec.residual), int(rec.iterations), elapsed, contact,
                       rec)


def _mirror(r: PatchResult) -> PatchResult:
    """A right-side answer seen in the mirror ``y → −y`` (module docstring)."""
    g = r.contact.grid
    flip = lambda v: g.field(v)[..., ::-1, :].reshape(np.shape(v))   # noqa: E731  rows y → −y
    t = np.stack([flip(r.t[0]), -flip(r.t[1])])
    xi, eta, phi = r.creepage
    return replace(r, origin=r.origin * np.array([1.0, -1.0, 1.0]), angle=-r.angle, y_rail=-r.y_rail,
                   wheel_point=r.wheel_point * np.array([-1.0, 1.0]), creepage=(xi, -eta, -phi), Fs=-r.Fs, Mn=-r.Mn,
                   y=-r.y[::-1], p=flip(r.p), t=t, state=flip(r.state))
