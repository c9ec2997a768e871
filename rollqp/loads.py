r"""The load-path keys of a 3D scene, ``load.normal_history`` and ``load.rolled``: their checks and the normal
force they set (docs/scenes.md, "Three dimensions"). The steps they make are :mod:`rollqp.march.grid`'s.

The same history objects as in 2D (:mod:`rollqp.histories`), functions of the time-like parameter τ in
units of ``a`` (the rolled distance itself without ``load.rolled``). :func:`check_load_path` holds the
scene's checks, each a one-line :class:`~rollqp.errors.InputError` naming the key.

>>> from rollqp import load_scene
>>> s = load_scene("kalker-circular").replace(**{"load.normal_history": {"kind": "ramp", "start": 1.0, "end": 0.0,
...                                                                      "over": 2.0}})
>>> has_load_path(s), float(normal_force(s, 0.5 * s.ellipse.a)) / s.load.normal
(True, 0.75)
"""
from __future__ import annotations

import dataclasses
import functools

import numpy as np

from .errors import InputError
from .histories import Constant, Harmonic
from .kinematics import plan
from .methods import REFERENCE_METHOD, scene_method_3d
from .closedforms.hertz_ellipse import hertz
from .friction.capacity import COUPLING_GRID, estimate, grid_shares, limits, margin_note, near_grid, worst
from .patch import check_patch, computed_patch

__all__ = ["has_load_path", "normal_force", "start_force", "start_ellipse", "check_load_path", "sliding_limits",
           "MAX_STEP_RATIO"]

#: Largest ``|Δq_k|`` of a step of a load path, in elements ``dx``: the range of ``discretization.step``.
MAX_STEP_RATIO = 8.0


def has_load_path(scene) -> bool:
    """Whether ``scene`` has a normal load history (other than the constant 1) or a ``load.rolled``."""
    ld = scene.load
    return ld.rolled is not None or ld.normal_history != Constant(1.0)


def normal_force(scene, tau):
    """``FN(τ) = load.normal·normal_history(τ/a)`` (``tau`` in length units, a float or an array)."""
    return scene.load.normal * scene.load.normal_history(np.asarray(tau, dtype=float) / scene.ellipse.a)


# =========================================================================== checks
def check_load_path(scene) -> None:
    """The load path's checks: the normal load ``>= 0`` (0: out of contact), the grid covering the contact
    of the largest load, every step's ``|Δq|`` at most :data:`MAX_STEP_RATIO` elements, a harmonic history
    resolved by two steps per wavelength, and the prescribed forces below the sliding limit of the
    current load, ``|(Fx, Fy)| < μ·FN(τ)`` (zero where ``FN(τ) = 0``; a law varying over the contact:
    :func:`sliding_limits`)."""
    ld, a = scene.load, scene.ellipse.a
    tau = scene.time_steps
    s_end = float(tau[-1]) / a
    nmin, nmax = ld.normal_history.extremes(s_end)
    if not nmin >= 0:
        raise InputError("load.normal_history", f"must stay >= 0 over [0, {s_end:.6g}] a (a pull, FN < 0, is not "
                                                f"a contact problem; 0 is out of contact), but its minimum is "
                                                f"{nmin:.6g}")
    ds = scene.dq / a
    for key in ("normal_history", "rolled"):
        h = getattr(ld, key)
        if isinstance(h, Harmonic) and h.amplitude != 0.0 and scene.n_steps > 0 and h.wavelength < 2.0 * ds:
            raise InputError(f"load.{key}.wavelength", f"must be at least two steps, 2·Δq = {2 * ds:.6g} a, to be "
                                                       f"resolved (got {h.wavelength!r}: it would be sampled at an "
                                                       "aliased wavelength); use a smaller discretization.step")
    if nmax > 1.0:
        _check_cover(scene, nmax)
    pl = plan(scene)
    if pl.rolled and pl.dq.size > 1:
        big = float(np.max(pl.dq)) / scene.grid.dx
        if big > MAX_STEP_RATIO * (1 + 1e-12):
            k = int(np.argmax(pl.dq))
            raise InputError("load.rolled", f"|Δq| must stay in [0, {MAX_STEP_RATIO:g}] dx per step, but step {k} "
                                            f"(τ = {pl.tau[k] / a:.6g} a) rolls {big:.6g} dx: use a smaller "
                                            "discretization.step")
    _check_sliding_limit(scene, s_end)


def _check_cover(scene, nmax: float) -> None:
    """The grid covers the contact of the largest load ``nmax·FN_ref`` (its Hertz ellipse, or with a profile
    the contact the normal step finds) with a row of elements to spare."""
    key = "discretization.extent" if scene.discretization.extent is not None else "discretization.zone"
    if scene.shape.hertzian:
        e, f = scene.ellipse, nmax ** (1.0 / 3.0)      # Hertz: a, b ∝ FN^(1/3)
        if not scene.grid.covers(e.a * f, e.b * f):
            raise InputError(key, f"the grid must cover the Hertz ellipse of the largest normal load "
                                  f"{nmax:.6g}·load.normal (a = {e.a * f:.4g}, b = {e.b * f:.4g}) with a row of "
                                  "elements to spare on each side; widen it")
        return
    A, B = scene.shape.curvatures()
    solver = dataclasses.replace(scene.solver, method=REFERENCE_METHOD, tolerance=1e-12, max_iterations=None,
                                 augmentation=None)
    patch = computed_patch(scene.shape.at(0.0), scene.grid, scene.materials, nmax * scene.load.normal,
                           scene_method_3d(solver), (A, B) if A > 0 and B > 0 else None)
    check_patch(patch, key)


def _check_sliding_limit(scene, s_end: float) -> None:
    ld = scene.load
    if ld.tangential is None and ld.lateral is None:
        return
    s = scene.time_steps / scene.ellipse.a
    for h in (ld.tangential, ld.lateral, ld.normal_history):
        if h is not None:
            s = np.union1d(s, h.critical_points(s_end))
    fx = ld.tangential(s) if ld.tangential is not None else 0.0
    fy = ld.lateral(s) if ld.lateral is not None else 0.0
    r = np.hypot(fx, fy) * np.ones_like(s)
    n = np.asarray(ld.normal_history(s), dtype=float) * np.ones_like(s)
    key = "load.tangential" if ld.tangential is not None else "load.lateral"
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(n > 0, r / np.where(n > 0, n, 1.0), np.where(r > 0, np.inf, 0.0))
    k = int(np.argmax(ratio))
    if scene.mu == 0 and r[k] != 0:
        raise InputError(key, f"must be 0 when contact.friction = 0 (a force over mu FN, and |(Fx, Fy)| <= mu FN = 0), "
                              f"got |(Fx, Fy)|/(mu FN) = {r[k]:.6g} at τ = {s[k]:.6g} a; prescribe creepages instead")
    if np.isinf(ratio[k]):
        raise InputError(key, f"must be 0 where the normal load is 0 (out of contact), but |(Fx, Fy)|/(mu FN_ref) = "
                              f"{r[k]:.6g} at τ = {s[k]:.6g} a where load.normal_history is 0")
    lim = sliding_limits(scene, s, n, ratio)
    if lim is not None:
        c, limit = lim
        k = worst(ratio, limit)
        if not ratio[k] < limit[k]:
            raise InputError(key, f"|(Fx, Fy)|/(mu FN) = {ratio[k]:.6g} at τ = {s[k]:.6g} a (FN the current normal "
                                  f"load {n[k]:.6g}·load.normal) " + limit_message(scene, c[k], limit[k]))
        return
    if not ratio[k] < 1:
        raise InputError(key, f"|(Fx, Fy)|/(mu FN) = {ratio[k]:.6g} at τ = {s[k]:.6g} a (FN the current normal load "
                              f"{n[k]:.6g}·load.normal) must be < 1: a stick solution exists only below the sliding "
                              "limit (prescribe creepages for gross sliding)")


def sliding_limits(scene, s, n, ratio):
    """The sliding limit of a 3D scene's prescribed forces where its friction law varies over the contact
    (:mod:`rollqp.friction.capacity`): ``(c, limit)`` at the samples ``s`` (τ/a) of normal loads ``n·load.normal``,
    in units of ``μ_ref FN`` — ``c = Σ μ_i w_i/μ_ref`` of the Hertz pressure of ``FN`` on the scene's grid, with
    ``μ_i`` at the element centres at the rolled distance ``q(τ)`` as the steps read it, and ``limit`` the force the
    check allows below (``c`` plus the bound on the discrete pressure's difference). Computed only where
    ``ratio > 0`` and ``n > 0`` (elsewhere 1). None where ``μ`` is the same at every element: Coulomb, and a
    slip-velocity law (its largest value, the static one, is its reference), whose limit is ``μ FN`` itself.

    Without a Hertzian shape (a body ``profile``) the pressure is that of the scene's computed contact
    (:attr:`Scene3D.patch <rollqp.scene.grid.Scene3D.patch>`, the discrete frictionless pressure at
    ``load.normal``) where the load is ``load.normal`` and the shape does not move; elsewhere nothing before
    the solve gives it, and the limit is the largest ``μ`` on the grid (a load beyond it has no solution).
    Dissimilar bodies add the coupling's shift of the pressure (:data:`~rollqp.friction.capacity.COUPLING_GRID`)."""
    law = scene.contact.friction
    if law.kind != "spatial":
        return None
    s, n, ratio = (np.asarray(v, dtype=float) * np.ones(np.shape(s)) for v in (s, n, ratio))
    e, g, ref, d = scene.ellipse, scene.grid, scene.mu, int(scene.load.direction)
    X, Y = g.centres()
    points = np.stack([X, Y]) / e.a
    moving = getattr(law, "frame", "fixed") == "material"
    q = scene.rolled_distance(s * e.a) / e.a if moving else np.zeros_like(s)

    @functools.lru_cache(maxsize=64)
    def mu_at(qh):
        return np.asarray(law.coefficient(points, qh, d), dtype=float)

    @functools.lru_cache(maxsize=64)
    def hertz_at(nk):
        f = nk ** (1.0 / 3.0)                             # Hertz: a, b ∝ FN^(1/3)
        a, b = e.a * f, e.b * f
        return grid_shares(X, Y, g.dx, g.dy, a, b), near_grid(X, Y, g.dx, g.dy, a, b), min(a / g.dx, b / g.dy)

    def rule(nk, qh):
        mu = mu_at(qh)
        if scene.shape.hertzian:
            w, near, m = hertz_at(nk)
            return estimate(mu, w, near, ref, m)
        if nk == 1.0 and not scene.shape.moves:          # the computed contact's own pressure: no mesh margin
            w = scene.patch.p.ravel() / float(np.sum(scene.patch.p))
            return estimate(mu, w, w > 0, ref, np.inf)
        top = float(np.max(mu)) / ref
        return top, 0.0, top, 0.0

    return limits(n, q, ratio, rule, COUPLING_GRID * abs(scene.materials.K))


def limit_message(scene, c: float, limit: float) -> str:
    """The end of the sliding-limit refusal of a friction law varying over the contact (:func:`sliding_limits`)."""
    return (f"must be < {limit:.6g}: with contact.friction varying over the contact a stick solution exists only "
            f"below its sliding limit |(Fx, Fy)| < ∫ mu p dA = {c:.6g} mu FN (mu = {scene.mu:g}, the law's "
            f"reference{margin_note(c, limit)}); prescribe creepages for gross sliding (docs/friction.md)")


def start_force(scene) -> float:
    """The normal force of the starting state, ``FN(τ = 0)`` (``load.normal`` without a normal history)."""
    return float(normal_force(scene, 0.0)) if has_load_path(scene) else float(scene.load.normal)


def start_ellipse(scene):
    """The Hertz ellipse of the starting state's load ``FN(0)`` (the scene's own without a normal history;
    None at ``FN(0) = 0``, out of contact): what the starting state is compared with."""
    FN = start_force(scene)
    if FN == scene.load.normal:
        return scene.ellipse
    return None if FN <= 0 else hertz(*scene.curvatures, scene.materials.Estar, FN)
