"""The grid's report: the summary ``rollqp run`` prints for a 3D scene, and its errors against closed forms and tables
(docs/validation3d.md).

:func:`summary` has the 2D summary's signature (:func:`rollqp.report.summary`) and rows: the scene,
the method, the grid, the Hertz ellipse, steps, iterations, wall time, the largest residual, then the
final forces and moment on body A, the creepages, the stick area, and the errors that apply:

* **Hertz** (state 0): the semi-axes and peak pressure of the computed pressure against the Hertz
  ellipse (:func:`hertz_field_errors`);
* **Kalker's linear theory** (a steady state, state 0 of a rolling start, where no more than
  :data:`LINEAR_SLIP_FRACTION` of the contact slips): the forces of the prescribed creepages against
  ``Fx = −G c² C11 ξ``, ``Fy = −G c² (C22 η + c C23 φ)`` (eq. 3D.8; Table E.3, interpolated by
  :func:`rollqp.closedforms.kalker.kalker_linear`), or the creepages of the prescribed forces against
  the same relations solved for them. On the grid the difference is the discretization error, first
  order in the element size (docs/validation3d.md §3 extrapolates it to within 1 %).

Post-processing of 3D solutions (the errors above, and Kalker's creep coefficients):

* **semi-axes of a computed pressure.** For the Hertz pressure ``∫x²p/∫p = a²/5`` (and ``b²/5``
  for y), so ``a_h = √(5 Σx²p/Σp)`` measures the contact's extent from the whole field, not from
  its staircase edge (:func:`semi_axes`, :func:`hertz_field_errors`);
* **creep coefficients** (:func:`creep_matrix`). Three steady solves at creepages small enough that every
  contact element sticks give the columns of ``∂(Fx, Fy, Mz)/∂(ξ, η, φ)``, nondimensionalized as in
  eq. 3D.8. ``area_normalized=True`` divides by powers of the computed contact area over the
  Hertz area instead of ``πab``: the staircase of the discrete contact area is the leading,
  irregular part of the discretization error, and this removes it (docs/validation3d.md).
"""
from __future__ import annotations

import json

import numpy as np

from . import time_row
from ..units import unit_names
from ..closedforms.cattaneo3d import cattaneo_shift, cattaneo_traction
from ..closedforms.kalker import kalker_linear
from ..influence.layer import compliance_of
from ..influence.layer import summary_rows as layer_rows
from ..loads import start_ellipse
from ..operators.grid import Loads
from ..march.grid import normal, steady

__all__ = ["summary", "closed_form_errors", "stick_fraction", "LINEAR_SLIP_FRACTION", "semi_axes", "hertz_errors",
           "hertz_field_errors", "creep_matrix", "cattaneo_errors"]

#: Largest fraction of the contact elements that may slip for the linear theory to be compared: it is
#: the limit of vanishing creepage, where nothing slips; a few slipping elements at the trailing edge
#: change the force by the square of their share (measured: 1e-4 at 1 % slipping).
LINEAR_SLIP_FRACTION = 0.02


def _meta(res) -> dict:
    meta = res.get("meta") if isinstance(res, dict) else None
    return json.loads(str(meta)) if meta is not None and not isinstance(meta, dict) else (meta or {})


def _force_units(u):
    force = u.load.rsplit("/", 1)[0]
    return force, f"{force}·{u.length}"


def stick_fraction(state) -> tuple[int, int, int]:
    """``(contact, stick, slip)`` element counts of a state field (0 separation, 1 stick, 2 slip)."""
    s = np.asarray(state)
    stick, slip = int(np.sum(s == 1)), int(np.sum(s == 2))
    return stick + slip, stick, slip


def closed_form_errors(res: dict, scene) -> list[tuple[str, str]]:
    """``(name, text)`` for every comparison that applies (module docstring)."""
    e = start_ellipse(scene)            # Hertz at the starting state's load (a normal history's FN(0))
    if e is None:
        return [("contact (start)", "out of contact (FN(0) = 0): no closed form for state 0")]
    if not scene.shape.hertzian:       # a profile: no closed form; a, b, p0 are the scales (docs/scenes.md)
        on = np.asarray(res["pn"][0]) > 0
        area = float(on.sum()) * float(np.diff(res["x"][:2])[0]) * float(np.diff(res["y"][:2])[0])
        return [("contact (start)", f"area {area:.5g} (the normal step's; the Hertz ellipse of a, b would be "
                                    f"{np.pi * e.a * e.b:.5g}); no closed form for a non-Hertzian profile")]
    dx, dy = float(np.diff(res["x"][:2])[0]), float(np.diff(res["y"][:2])[0])
    if e.a < 2 * dx or e.b < 2 * dy:    # a few elements in contact: their moments are not the ellipse's
        return [("contact (start)", f"the Hertz ellipse at FN(0) (a = {e.a:.4g}, b = {e.b:.4g}) spans fewer than "
                                    f"two elements each way (dx = {dx:.4g}, dy = {dy:.4g}): not compared")]
    X, Y = np.meshgrid(res["x"], res["y"])
    h = hertz_field_errors(X, Y, res["pn"][0], float(res["approach"][0]), e)
    rows = [("error: hertz", f"a {100 * h['a']:+.3f} %, b {100 * h['b']:+.3f} %, p0 {100 * h['p0']:+.3f} %, "
                             f"approach {100 * h['delta']:+.3f} % (state 0; discretization, docs/validation3d.md §1)")]
    if scene.load.start == "rolling":
        rows += _kalker_rows(res, scene)
    else:
        rows += _cattaneo_rows(res, scene, X, Y)
    return rows


def _cattaneo_rows(res, scene, X, Y) -> list[tuple[str, str]]:
    """The braked start of a circle pressed, then shifted along x (Cattaneo–Mindlin, eq. 3D.6–3D.7)."""
    e, m, mu = start_ellipse(scene), scene.materials, scene.mu
    FN, Fx = float(res["FN"][0]), float(res["Fx"][0])
    if mu == 0:
        return []
    r = abs(Fx) / (mu * FN)
    loads = scene.loads_at(0.0)
    if abs(e.a / e.b - 1) > 1e-9 or m.K != 0 or loads.Fy != 0 or loads.phi != 0 or not 0 < r < 1:
        return []
    ref = np.sign(Fx) * cattaneo_traction(np.hypot(X, Y), e.a, e.p0, mu, r)
    rms = float(np.sqrt(np.mean((res["px"][0] - ref) ** 2))) / (mu * e.p0)
    shift = -np.sign(Fx) * cattaneo_shift(FN, e.a, mu, r, m.G, m.nu)
    got = float(_meta(res).get("static_shift", [float("nan")])[0])
    exact = "exact for nu = 0; for nu > 0 it neglects the lateral traction of the nu XY/rho³ kernel"
    return [("error: cattaneo", f"rms(px - Cattaneo)/(mu p0) = {rms:.3g}, shift {100 * (got / shift - 1):+.3f} % of "
                                f"Mindlin's {shift:.5g} (state 0; Cattaneo–Mindlin is {exact}: docs/validation3d.md §2)")]


def _kalker_rows(res, scene) -> list[tuple[str, str]]:
    e, m = start_ellipse(scene), scene.materials
    if scene.mu == 0:
        return [("error: kalker", "not compared (mu = 0: no stick, no creep force)")]
    if compliance_of(scene.contact.layer) > 0:
        return [("error: kalker", "not compared: the interface layer's compliance joins the bodies' (Kalker's theory "
                                  "is of the bodies alone; the layer against the brush: docs/validation3d.md §19)")]
    C = kalker_linear(e.a / e.b, m.nu)
    n, _, slip = stick_fraction(res["state"][0])
    if C is None or m.K != 0:
        why = "dissimilar bodies" if m.K != 0 else "a/b outside Table E.3"
        return [("error: kalker", f"not compared ({why})")]
    if slip > LINEAR_SLIP_FRACTION * n:
        return [("error: kalker", f"not compared: {slip} of {n} contact elements slip (the linear theory is the "
                                  f"limit of no slip; at most {100 * LINEAR_SLIP_FRACTION:g} % compared)")]
    c, G = e.c, m.G
    xi, eta, phi = (float(v) for v in res["creepage"][0])
    ld = scene.load
    out = []
    if ld.creepage.longitudinal is not None and xi != 0:
        ref = -G * c * c * C[0] * xi
        out.append(f"Fx {100 * (float(res['Fx'][0]) / ref - 1):+.2f} % against -G c² C11 xi = {ref:.5g}")
    elif ld.creepage.longitudinal is None and float(res["Fx"][0]) != 0:
        ref = -float(res["Fx"][0]) / (G * c * c * C[0])
        out.append(f"xi {100 * (xi / ref - 1):+.2f} % against -Fx/(G c² C11) = {ref:.5g}")
    if ld.creepage.lateral is not None and (eta != 0 or phi != 0):
        ref = -G * c * c * (C[1] * eta + c * C[2] * phi)
        out.append(f"Fy {100 * (float(res['Fy'][0]) / ref - 1):+.2f} % against -G c² (C22 eta + c C23 phi) = {ref:.5g}")
    elif ld.creepage.lateral is None and float(res["Fy"][0]) != 0:
        ref = (-float(res["Fy"][0]) / (G * c * c) - c * C[2] * phi) / C[1]
        out.append(f"eta {100 * (eta / ref - 1):+.2f} % against (-Fy/(G c²) - c C23 phi)/C22 = {ref:.5g}")
    if not out:
        return []
    note = (f"(C11, C22, C23 = {C[0]:.4g}, {C[1]:.4g}, {C[2]:.4g}: Kalker 1990 Table E.3 at a/b = {e.a / e.b:.4g}, "
            f"nu = {m.nu:.4g}; {slip} of {n} elements slip; first order in dx, docs/validation3d.md §3)")
    return [("error: kalker", "; ".join(out) + " " + note)]


def _of_cap(F: float, cap: float) -> str:
    """`` (+0.30000 mu FN)``, or nothing when ``μ = 0``."""
    return f" ({F / cap:+.5f} mu FN)" if cap > 0 else ""


def _grid_row(res, scene, u) -> str:
    nx, ny = res["x"].size, res["y"].size
    dx, dy = float(np.diff(res["x"][:2])[0]), float(np.diff(res["y"][:2])[0])
    d = scene.discretization
    where = (f"zone ±{d.zone[0]:g} a × ±{d.zone[1]:g} b" if d.zone is not None else
             f"extent [{d.extent[0][0]:g}, {d.extent[0][1]:g}] × [{d.extent[1][0]:g}, {d.extent[1][1]:g}] {u.length}")
    return f"{nx} x {ny} elements ({nx * ny}), dx = {dx:.4g}, dy = {dy:.4g} {u.length}, {where}"


def _steps_row(res, scene, u) -> str:
    K = len(res["q"]) - 1
    start = {"rolling": "steady state (rolling start)", "braked": "braked start (static shift)"}[scene.load.start]
    rolled = int(np.count_nonzero(np.diff(np.asarray(res["q"], dtype=float))))   # a held load.rolled: at rest
    if rolled == K:
        return f"{start} + {K} rolling steps of {scene.discretization.step:g} dx ({scene.dq:.4g} {u.length})"
    return (f"{start} + {K} steps: {rolled} rolling, {K - rolled} at rest (static steps: load.rolled held, the "
            "loads changing in place)")


def summary(res: dict, scene, method: str, wall: float, stresses=None) -> str:
    """The table ``rollqp run`` prints for a 3D scene (module docstring); the arguments as
    :func:`rollqp.report.summary` (``stresses``: a :class:`rollqp.subsurface3d.StressHistory3D` of the run, from
    ``rollqp run --stresses``: its peak von Mises and Tresca stresses over the stored states, with place and state)."""
    u = unit_names(getattr(scene, "units", ""))
    force, moment = _force_units(u)
    e, mu = scene.ellipse, scene.mu
    ran = _meta(res).get("method") or method
    it = np.asarray(res["iterations"])
    n, stick, slip = stick_fraction(res["state"][-1])
    xi, eta, phi = (float(v) for v in res["creepage"][-1])
    FN, Fx, Fy, Mz = (float(res[k][-1]) for k in ("FN", "Fx", "Fy", "Mz"))
    rows = [("scene", f"{scene.name} ({scene.source}), three-dimensional"),
            ("method", ran),
            ("grid", _grid_row(res, scene, u)),
            ("Hertz", f"a = {e.a:.5g} {u.length}, b = {e.b:.5g} {u.length} (a/b = {e.a / e.b:.4g}), p0 = {e.p0:.5g} "
                      f"{u.stress}, E* = {e.Estar:.5g} {u.stress}, FN = {scene.load.normal:.6g} {force}"),
            *layer_rows(scene.contact.layer, u.length, u.stress),
            ("steps", _steps_row(res, scene, u)),
            ("iterations", f"{int(it.sum())} in all ({int(it[0])} for the starting state)"),
            ("wall time", time_row(res, wall)),
            ("max residual", f"{float(np.max(res['residual'])):.2e} (nondimensional, docs/theory3d.md §10)"),
            ("forces (end)", f"FN = {FN:.6g} {force}, Fx = {Fx:.6g} {force}{_of_cap(Fx, mu * FN)}, "
                             f"Fy = {Fy:.6g} {force}{_of_cap(Fy, mu * FN)}, Mz = {Mz:.6g} {moment}"),
            ("creepages (end)", f"xi = {xi:.6g}, eta = {eta:.6g}, phi = {phi:.6g} 1/{u.length}"),
            ("stick area (end)", f"{100 * stick / max(n, 1):.1f} % of the {n} contact elements ({stick} stick, "
                                 f"{slip} slip)" + (": frictionless (mu = 0): t = 0, the creepages as prescribed (else "
                                                    "0), an element slips wherever they move it" if mu == 0 else ""))]
    note = _meta(res).get("rolling_start")
    if note:
        rows.append(("starting state", note))
    raw = _meta(res).get("raw_distance")
    if raw:
        rows.append(("raw conic", f"the solver's own answers (before the active-set refinement) differ from the "
                                  f"refined ones kept by max |dp| {raw['dp']:.1e} p0, |dt| {raw['dt']:.1e} mu p0 "
                                  f"over {raw['steps']} steps (interior point: about sqrt(gap); docs/theory3d.md §5)"))
    rows += closed_form_errors(res, scene)
    if stresses is not None:
        for key, label in (("von_mises", "peak von Mises"), ("tresca", "peak Tresca")):
            v, x, y, z, k = stresses.overall[key]
            rows.append((label, f"{v / e.p0:.4f} p0 at x = {x:.5g}, y = {y:.5g}, z = {z:.5g} {u.length}, state {k} "
                                f"(body {stresses.body}, plane y = 0 below the grid, {stresses.section.z.size} depths "
                                "to 2a; rollqp stresses for other sections)"))
    w = max(len(r[0]) for r in rows)
    return "\n".join(f"  {k:<{w}}  {v}" for k, v in rows)



def semi_axes(contact, p) -> tuple[float, float]:
    """``(a_h, b_h)``: the semi-axes of an ellipsoidal pressure with the moments of ``p``."""
    p = np.asarray(p, dtype=float)
    P = float(p.sum())
    return float(np.sqrt(5 * np.sum(contact.x ** 2 * p) / P)), float(np.sqrt(5 * np.sum(contact.y ** 2 * p) / P))


def hertz_errors(contact, solution) -> dict:
    """Errors of a normal solution against the Hertz ellipse of the contact (:func:`hertz_field_errors`)."""
    return hertz_field_errors(contact.x, contact.y, solution.p, solution.delta, contact.ellipse)


def hertz_field_errors(x, y, p, delta, ellipse) -> dict:
    """Errors of a pressure field ``p`` at the element centres ``(x, y)`` (flattened) and its approach
    against the Hertz ``ellipse`` (relative to ``a, b, p0, δ``): ``a``, ``b`` (the semi-axes of the
    ellipsoidal pressure with ``p``'s second moments, exact for Hertz's: ``∫x²p/∫p = a²/5``), ``p0``
    (the pressure interpolated to the centre by the quadric through the nine central elements'
    ``p²``), ``delta``, ``rms`` (``p − p_Hertz`` over the grid, in ``p0``), ``max`` (in ``p0``)."""
    e = ellipse
    x, y, p = (np.asarray(v, dtype=float).ravel() for v in (x, y, p))
    P = float(p.sum())
    ah, bh = float(np.sqrt(5 * np.sum(x ** 2 * p) / P)), float(np.sqrt(5 * np.sum(y ** 2 * p) / P))
    ph = e.pressure(x, y)
    # p² is the quadric p0²(1 − x²/a² − y²/b²) for Hertz: fit it on the elements nearest the centre
    near = np.argsort(np.hypot(x / e.a, y / e.b))[:9]
    M = np.column_stack([np.ones(near.size), x[near] ** 2, y[near] ** 2])
    coef = np.linalg.lstsq(M, p[near] ** 2, rcond=None)[0]
    return {"a": ah / e.a - 1, "b": bh / e.b - 1, "p0": float(np.sqrt(coef[0])) / e.p0 - 1,
            "delta": delta / e.delta - 1, "rms": float(np.sqrt(np.mean((p - ph) ** 2))) / e.p0,
            "max": float(np.max(np.abs(p - ph))) / e.p0}


def cattaneo_errors(contact, record, ratio: float, traction) -> dict:
    """``rms`` and ``max`` of ``t_x − t_Cattaneo`` over the grid (in ``μp0``) and the relative error of
    the rigid shift, for a shift along x (``traction(r)``: the closed form's magnitude)."""
    sign = np.sign(record.Fx)
    ref = sign * traction(np.hypot(contact.x, contact.y))
    mp0 = contact.mu * contact.scales.stress
    d = record.t[0] - ref
    return {"rms": float(np.sqrt(np.mean(d ** 2))) / mp0, "max": float(np.max(np.abs(d))) / mp0,
            "ty": float(np.max(np.abs(record.t[1]))) / mp0}


def creep_matrix(contact, method, FN: float, creepage: float = 1e-8, direction: int = -1,
                 area_normalized: bool = False) -> tuple[np.ndarray, dict]:
    """``C`` with ``(Fx/(Gc²), Fy/(Gc²), Mz/(Gc³)) = −C (ξ, η, cφ)`` (eq. 3D.8) from three steady solves.

    Returns ``(C, info)``; ``info["slipping"]`` counts slipping elements (0 for the linear theory:
    lower ``creepage`` if not), ``info["area_ratio"]`` is the computed contact area over ``πab``.
    """
    e, G = contact.ellipse, contact.materials.G
    c = e.c
    C = np.zeros((3, 3))
    slipping = 0
    pressure = None if contact.ops.coupled else normal(contact, method, FN)
    for k, (xi, eta, phi) in enumerate([(creepage, 0.0, 0.0), (0.0, creepage, 0.0), (0.0, 0.0, creepage / c)]):
        rec = steady(contact, method, FN, Loads(xi=xi, eta=eta, phi=phi), direction=direction, pressure=pressure)
        slipping += int(np.sum(rec.state == 2))
        C[:, k] = -np.array([rec.Fx / (G * c * c), rec.Fy / (G * c * c), rec.Mz / (G * c ** 3)]) / creepage
    ratio = float(np.sum(rec.p > 0)) * contact.grid.area / (np.pi * e.a * e.b)
    if area_normalized:
        powers = np.array([[1.0, 1.0, 1.5], [1.0, 1.0, 1.5], [1.5, 1.5, 2.0]])
        C = C / ratio ** powers
    return C, {"slipping": slipping, "area_ratio": ratio}
