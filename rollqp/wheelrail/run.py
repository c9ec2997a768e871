r"""A wheel–rail scene's run: its wheels solved, the result file, the printed table, the figure and the
cross-check of every patch's tangential step (docs/wheel-rail.md).

Result keys (``.npz``, no pickled objects), per patch ``p`` of the ``P`` patches over the wheels run:
``patch_wheel`` (P,) int (0 left, 1 right); ``patch_FN``, ``patch_Fx``, ``patch_Fy``, ``patch_Mz`` (P,)
the forces and spin moment on the rail in the patch's contact frame (N, N·mm; CONTACT's FN, FX, FS,
MN); ``patch_y_rail``, ``patch_z_rail`` the contact reference on the rail profile (profile coordinates,
output side); ``patch_position`` (P, 3) the reference in the track frame; ``patch_angle`` the contact
angle δ (rad); ``patch_creepage`` (P, 3) ξ, η, φ; ``patch_approach``; ``patch_area``, ``patch_pmax``;
``wheel_force`` (2, 3) the total force on each wheel in the track frame (x forward, y right, z down;
``nan`` for a wheel not run); ``wheel_z`` (2,) the wheelset's vertical position found; each patch's
``patch<p>_x``, ``patch<p>_y`` (element centres along x and s), ``patch<p>_pn``, ``patch<p>_px``,
``patch<p>_py``, ``patch<p>_state`` ((ny, nx)); ``meta`` (JSON: the scene, method, versions).
"""
from __future__ import annotations

import json
import time

import numpy as np

from ..atomic import written
from ..crossval.grid import AGREEMENT
from ..errors import InputError
from ..march.grid import coupled_step
from ..march.loop import versions as _versions
from ..methods import CROSSVAL_METHODS_3D, available_methods, get_method
from ..operators.grid import Loads
from ..version import __version__
from .solve import solve_wheel
from .track import Track
from .wheelset import Wheelset

__all__ = ["solve_scene", "run", "WheelRailResult", "summary", "figure", "crossval"]


def _method(scene):
    return get_method(scene.solver.method, 3, tolerance=scene.solver.tolerance)


def solve_scene(scene, method=None):
    """The :class:`~rollqp.wheelrail.solve.WheelResult` of each wheel the scene runs."""
    rail, wheel = scene.profiles()
    w, tr, disc = scene.data["wheelset"], scene.data["track"], scene.data["discretization"]
    track = Track(rail, tr["gauge"], tr["gauge_height"], tr["cant"])
    ws = Wheelset(wheel, w["back_to_back"], w["flange_back"], w["nominal_radius"])
    meth = method or _method(scene)
    dx, ds = scene.element_size
    out = []
    for side in scene.sides():
        res = solve_wheel(track, ws, scene.state(), scene.materials(), scene.data["contact"]["friction"], w["load"],
                          dx, ds, meth, side=side, combine=disc["combine"], separate_angle=disc["separate_angle"])
        if not res.patches:
            raise InputError("wheelset.lateral", f"the {side} wheel does not touch its rail at this position")
        out.append(res)
    return out


class WheelRailResult:
    """The wheels' answers and their result arrays (module docstring)."""

    def __init__(self, scene, wheels, method: str, wall: float):
        self.scene, self.wheels, self.method, self.wall = scene, wheels, method, wall

    def arrays(self) -> dict:
        P = [p for w in self.wheels for p in w.patches]
        a = {"patch_wheel": np.array([0 if p.wheel == "left" else 1 for p in P], dtype=np.int64)}
        for key, attr in (("patch_FN", "FN"), ("patch_Fx", "Fx"), ("patch_Fy", "Fs"), ("patch_Mz", "Mn"),
                          ("patch_y_rail", "y_rail"), ("patch_z_rail", "z_rail"), ("patch_angle", "angle"),
                          ("patch_approach", "approach"), ("patch_area", "area"), ("patch_pmax", "pmax"),
                          ("patch_time", "time"), ("patch_residual", "residual")):
            a[key] = np.array([float(getattr(p, attr)) for p in P])
        a["patch_position"] = np.array([p.origin for p in P]).reshape(-1, 3)
        a["patch_creepage"] = np.array([p.creepage for p in P], dtype=float).reshape(-1, 3)
        a["wheel_force"] = np.full((2, 3), np.nan)
        a["wheel_z"] = np.full(2, np.nan)
        for w in self.wheels:
            i = 0 if w.side == "left" else 1
            a["wheel_force"][i] = w.force_wheel
            a["wheel_z"][i] = w.z
        for k, p in enumerate(P):
            g = p.contact.grid
            a[f"patch{k}_x"], a[f"patch{k}_y"] = np.asarray(p.x), np.asarray(p.y)
            a[f"patch{k}_pn"] = g.field(p.p)
            a[f"patch{k}_px"], a[f"patch{k}_py"] = g.field(p.t[0]), g.field(p.t[1])
            a[f"patch{k}_state"] = g.field(p.state).astype(np.int8)
        a["meta"] = np.array(json.dumps({"scene": self.scene.to_dict(), "method": self.method, "kind": "wheel-rail",
                                         "rollqp": __version__, "versions": _versions(), "wall": self.wall}))
        return a

    def save(self, out) -> None:
        with written(out) as (fh, _):
            np.savez(fh, **self.arrays())


def run(scene, progress=None, resume=None, observe=None, out=None, keep_every=None,
        start_progress=None) -> WheelRailResult:
    """Solve the scene and write its result file ``out`` (``rollqp run``'s family interface; a wheel–rail
    scene is one state: ``progress``, ``keep_every`` and ``start_progress`` have nothing to report)."""
    if resume is not None:
        raise InputError("--resume", "a wheel-rail scene is one state: there is nothing to resume")
    t0 = time.perf_counter()
    wheels = solve_scene(scene)
    result = WheelRailResult(scene, wheels, scene.solver.method, time.perf_counter() - t0)
    if observe is not None:
        observe.wheels = wheels
    if out is not None:
        result.save(out)
    return result


def summary(res: dict, scene, method: str, wall: float, stresses=None) -> str:
    """The table ``rollqp run`` prints: per wheel and patch the position, contact angle, forces,
    creepages, area and peak pressure."""
    lines = [f"  scene         {scene.name} ({scene.source}), wheel on rail",
             f"  method        {method}; {len(res['patch_FN'])} patch(es); wall time {wall:.2f} s"]
    P = len(res["patch_FN"])
    for i, side in enumerate(("left", "right")):
        if not np.all(np.isfinite(res["wheel_force"][i])):
            continue
        F = res["wheel_force"][i]
        lines.append(f"  {side} wheel    z_ws = {res['wheel_z'][i]:.4f} mm; force on the wheel (track frame, z down) "
                     f"Fx = {F[0]:.1f} N, Fy = {F[1]:.1f} N, Fz = {F[2]:.1f} N")
        for p in range(P):
            if res["patch_wheel"][p] != i:
                continue
            x, y, z = res["patch_position"][p]
            xi, eta, phi = res["patch_creepage"][p]
            lines.append(f"    patch {p}     at x = {x:.3f}, y = {y:.3f}, z = {z:.4f} mm (rail profile y = "
                         f"{res['patch_y_rail'][p]:.3f} mm), contact angle {res['patch_angle'][p]:.4f} rad")
            lines.append(f"                FN = {res['patch_FN'][p]:.1f} N, Fx = {res['patch_Fx'][p]:.1f} N, "
                         f"Fs = {res['patch_Fy'][p]:.1f} N, Mn = {res['patch_Mz'][p]:.1f} N mm (on the rail, "
                         f"contact frame)")
            lines.append(f"                xi = {xi:.4e}, eta = {eta:.4e}, phi = {phi:.4e} 1/mm; area "
                         f"{res['patch_area'][p]:.2f} mm^2, pmax {res['patch_pmax'][p]:.1f} N/mm^2")
    return "\n".join(lines)


def figure(res: dict, scene, path) -> None:
    """The profiles with the contact points (track frame) and each patch's pressure and traction."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rail, wheel = scene.profiles()
    P = len(res["patch_FN"])
    fig, axes = plt.subplots(1 + P, 2, figsize=(10, 3.2 * (1 + P)), squeeze=False)
    ax = axes[0, 0]
    ax.plot(rail.ys, rail.zs, "k-", lw=1, label="rail profile")
    for p in range(P):
        ax.plot([res["patch_y_rail"][p] * (1 if res["patch_wheel"][p] else -1)], [res["patch_z_rail"][p]], "ro")
    ax.invert_yaxis()
    ax.set_xlabel("rail profile y (right-side form), mm")
    ax.set_ylabel("z (down), mm")
    ax.set_title("rail profile and contact references")
    ax = axes[0, 1]
    ax.plot(wheel.ys, wheel.zs, "b-", lw=1)
    ax.invert_yaxis()
    ax.set_xlabel("wheel profile y (right-side form), mm")
    ax.set_title("wheel profile")
    for p in range(P):
        x, y = res[f"patch{p}_x"], res[f"patch{p}_y"]
        ext = [x[0], x[-1], y[0], y[-1]]
        a0, a1 = axes[1 + p]
        im = a0.imshow(res[f"patch{p}_pn"], origin="lower", extent=ext, aspect="equal", cmap="viridis")
        fig.colorbar(im, ax=a0, label="pressure, N/mm²")
        a0.set_title(f"patch {p} ({'left' if res['patch_wheel'][p] == 0 else 'right'}): pressure")
        a0.set_xlabel("x, mm")
        a0.set_ylabel("s, mm")
        tx, ty = res[f"patch{p}_px"], res[f"patch{p}_py"]
        im = a1.imshow(np.hypot(tx, ty), origin="lower", extent=ext, aspect="equal", cmap="magma")
        fig.colorbar(im, ax=a1, label="|traction|, N/mm²")
        step = max(1, max(tx.shape) // 20)
        X, Y = np.meshgrid(x, y)
        a1.quiver(X[::step, ::step], Y[::step, ::step], tx[::step, ::step], ty[::step, ::step], color="w")
        a1.set_title(f"patch {p}: tangential traction on the rail")
        a1.set_xlabel("x, mm")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def crossval(scene, methods=None, tolerance: float = 1e-10):
    """Every patch's tangential step solved again by ``methods`` (default: the installed conic methods, :func:`default_crossval_methods`), posed from the
    run's steady state (one rolling step of ``Δq = dx`` from it, whose answer is that state again) and
    compared with the run's: ``[(wheel, patch, method, |dp|/p0, |dt|/(μ p0), residual, seconds, raw |dt|)]``
    (raw: the conic solver's own answer before rollqp's active-set refinement, None without one)."""
    methods = list(methods or default_crossval_methods(scene))
    wheels = solve_scene(scene)
    rows = []
    for w in wheels:
        for k, p in enumerate(w.patches):
            c, rec = p.contact, p.record
            if rec is None:
                continue
            sc = c.scales
            for name in methods:
                t0 = time.perf_counter()
                m = get_method(name, 3, tolerance=tolerance)
                m.setup(c)
                loads = Loads(xi=rec.xi, eta=rec.eta, phi=rec.phi)
                nsol, tsol, _ = coupled_step(c, m, rec.FN, "rolling", loads, (rec.p, rec.t), c.grid.dx, -1)
                dp = float(np.max(np.abs(nsol.p - rec.p))) / sc.stress
                dt = float(np.max(np.abs(tsol.t - rec.t))) / (c.mu * sc.stress)
                rt = tsol.info.get("raw")
                raw = None if rt is None else float(np.max(np.abs(rt["t"] - rec.t))) / (c.mu * sc.stress)
                rows.append((w.side, k, name, dp, dt, max(nsol.residual, tsol.residual), time.perf_counter() - t0,
                             raw))
    return rows


def default_crossval_methods(scene) -> list:
    """The installed conic methods of ``rollqp crossval`` other than the scene's own."""
    installed = set(available_methods(3))
    return [m for m in CROSSVAL_METHODS_3D if m in installed and m != scene.solver.method]


def crossval_report(rows, tolerance) -> tuple[str, bool]:
    ok = all(max(r[3], r[4]) <= AGREEMENT for r in rows)
    lines = [f"wheel-rail cross-check: every patch's steady tangential step solved again (tolerance {tolerance:g})"]
    for side, k, name, dp, dt, res, sec, raw in rows:
        verdict = "agree" if max(dp, dt) <= AGREEMENT else f"DISAGREE (beyond {AGREEMENT:g})"
        rawtext = "" if raw is None else f" (the solver's own answer before the active-set refinement: |dt| {raw:.1e})"
        lines.append(f"  {side} patch {k}, {name}: {verdict}: max |dp| {dp:.1e} p0, |dt| {dt:.1e} mu p0{rawtext}; "
                     f"residual {res:.1e}; {sec:.2f} s")
    return "\n".join(lines), ok

