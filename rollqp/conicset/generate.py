r"""The conic test set: 3D steps of the built-in scenes, marched by Newton, certified, written out.

Each problem is one step of a built-in scene (``cattaneo-3d``: a circle braked and rolled;
``kalker-elliptic``: an a/b = 0.5 ellipse with ξ, η and spin; ``kalker-circular`` with pure spin;
dissimilar bodies: aluminium on steel, docs/validation3d.md §7), marched with rollqp's Newton method
(:class:`~rollqp.methods.newton.disc.NewtonMethod`, tolerance :data:`NEWTON_TOLERANCE`) and posed as

* a **tangential SOCP** (eq. 3D.20, the pressure fixed) or a **normal QP** (eq. 3D.22, the shear
  fixed) — :mod:`~rollqp.conicset.forms`, written as CBF (:mod:`~rollqp.conicset.cbf`) and as
  arrays; a dissimilar step's halves at the coupled solution, each a convex program whose
  solution is the coupled one;
* a **coupled static step** as an FCLib local problem (:mod:`~rollqp.conicset.fclib`).

**Certificates.** The Newton solution's rollqp residual on the step problem (eq. 3D.29) must be at
most :data:`CERTIFIED`, and the same residual computed from the exported arrays alone
(:func:`~rollqp.conicset.forms.residual`, :func:`~rollqp.conicset.fclib.residual`) must agree with
it: a problem that fails either is an error, never written.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..scene import load_scene
from ..operators.grid import Contact, Loads
from ..problem.conic import normal_form, tangential_form
from ..methods.newton.disc import NewtonMethod
from ..march.grid import coupled_step, normal, static_shift
from . import cbf, fclib
from .forms import ProgramData, from_form, objective, residual

__all__ = ["Exported", "CASES", "SMALL", "build", "write_set", "NEWTON_TOLERANCE", "CERTIFIED"]

#: Newton's stopping tolerance on ‖Φ‖∞ (docs/theory3d.md §7): it terminates on these piecewise-smooth
#: equations in a few iterations from the previous state, at round-off.
NEWTON_TOLERANCE = 1e-12
#: rollqp's residual every certified solution must meet (measured: at most 5.6e-13 on this set, the
#: largest grids' round-off times their condition).
CERTIFIED = 1e-11
#: Aluminium on steel (docs/validation3d.md §7): K = +0.0753.
ALU_STEEL = (70e3, 0.33, 210e3, 0.28)
STEEL_ALU = (210e3, 0.28, 70e3, 0.33)
#: A soft body on steel (K = +0.0448).
SOFT_STEEL = (5e3, 0.45, 210e3, 0.3)


@dataclass
class Exported:
    """One problem: ``kind`` ``"normal"``, ``"tangential"`` (``data``: :class:`ProgramData`) or ``"fc"``
    (``data``: ``{"W", "q", "mu"}``); ``x``, ``y`` the certified solution in the exported variables
    (``fc``: ``r``; ``y`` empty), ``meta`` the catalogue entry and the map back to tractions."""

    name: str
    kind: str
    what: str
    data: object
    x: np.ndarray
    y: np.ndarray
    meta: dict = field(default_factory=dict)


def _contact(scene_name, elements, materials=None, **changes):
    """The built-in scene on ``elements`` (zone widened where the grid is too coarse to leave a row
    of elements around the ellipse), and its :class:`Contact`."""
    scene = load_scene(scene_name)
    zone = [max(z, 1.02 / (1 - 2 / e)) for z, e in zip(scene.discretization.zone, elements)]
    if materials is not None:   # the bodies' own: the grid is laid over their Hertz ellipse
        changes.update(zip(("bodies.A.E", "bodies.A.nu", "bodies.B.E", "bodies.B.nu"), materials))
    scene = scene.replace(**{"discretization.elements": list(elements), "discretization.zone": zone}, **changes)
    return scene, Contact(scene.grid, scene.materials, scene.curvatures, scene.load.normal, scene.mu)


def _newton():
    return NewtonMethod(tolerance=NEWTON_TOLERANCE, max_iterations=200)


def _certify(name, problem, sol, form_data, x, y):
    """The two residuals agree and are at most :data:`CERTIFIED`; returns rollqp's."""
    r_step = float(sol.residual)
    r_form = residual(form_data, x, y)
    if not (r_step <= CERTIFIED and r_form <= CERTIFIED):
        raise InputError(name, f"not certified: rollqp residual {r_step:.2e} on the step, {r_form:.2e} from the arrays")
    return r_step, r_form


def _states(problem, sol):
    """``(stick, slip)`` fractions of the elements in contact (tangential), or the contact fraction."""
    if problem.kind == "normal":
        return {"contact": float(np.mean(sol.p > 0))}
    st = problem.states(sol.t, sol.s)
    inside = st > 0
    return {"stick": float(np.mean(st[inside] == 1)), "slip": float(np.mean(st[inside] == 2)),
            "contact_elements": int(inside.sum())}


def _program(name, what, problem, sol, contact, extra=None) -> Exported:
    """Export a normal or tangential step solved by Newton: its form, certified solution, catalogue."""
    sc = contact.scales
    ah = problem.area / sc.length ** 2
    if problem.kind == "normal":
        form = normal_form(problem)
        x = sol.p[form.elements] / sc.stress
        unknowns = [-sol.delta / sc.displacement] if form.rows else []
    else:
        form = tangential_form(problem)
        x = (sol.t[:, form.elements] / sc.stress).ravel()
        crp = {"Fx": sol.xi / sc.slip, "Fy": sol.eta / sc.slip}
        unknowns = [crp[r] for r in form.rows]
    y = np.asarray(unknowns, dtype=float) * form.eq_scale / form.obj_scale
    data = from_form(form, ah)
    r_step, r_form = _certify(name, problem, sol, data, x, y)
    ev = np.linalg.eigvalsh(data.H)
    meta = {"what": what, "grid": [contact.grid.nx, contact.grid.ny], "n": data.m, "load_rows": data.k,
            "cones": data.m // 2 if data.kind == "tangential" else 0, "cond_H": float(ev[-1] / ev[0]),
            "residual": r_step, "residual_from_arrays": r_form, "objective": objective(data, x),
            "elements": form.elements.tolist(), "p0": sc.stress, "Estar": sc.modulus, "c": sc.length,
            "rows": list(form.rows), "multiplier_to_unknown": form.obj_scale / form.eq_scale, **_states(problem, sol),
            **(extra or {})}
    return Exported(name, problem.kind, what, data, np.asarray(x), y, meta)


# ------------------------------------------------------------------------------------------ cases
def hertz(name, scene_name, elements):
    """The normal QP of the scene's Hertz contact."""
    scene, c = _contact(scene_name, elements)
    prob = c.normal_step(scene.load.normal)
    sol = _newton().solve(prob, c.hertz_start(scene.load.normal))
    return [_program(name, "Hertz: the normal step (QP, eq. 3D.22)", prob, sol, c)]


def shift(name, elements, ratio=0.6):
    """Cattaneo–Mindlin: ``cattaneo-3d``'s static shift to Fx = ratio·μFN (SOCP, two load rows)."""
    scene, c = _contact("cattaneo-3d", elements)
    FN = scene.load.normal
    rec = static_shift(c, _newton(), FN, ratio * c.mu * FN, 0.0)[-1]
    prob = c.tangential_step("shift", rec.p, rec.info["loads"], rec.info["before"])
    sol = _newton().solve(prob)
    return [_program(name, f"Cattaneo–Mindlin: static shift to Fx = {ratio:g} μFN", prob, sol, c)]


def rolling(name, scene_name, elements, steps, loads=None, braked=True):
    """Transient rolling steps of ``Δq = dx`` from the braked state (``braked``) or from rest; the steps
    ``steps`` exported (SOCP; creepages prescribed: no load rows)."""
    scene, c = _contact(scene_name, elements)
    FN, meth = scene.load.normal, _newton()
    ld = loads if loads is not None else scene.loads_at(0.0)
    nsol = normal(c, meth, FN)
    if braked:
        prev = static_shift(c, meth, FN, ld.Fx, ld.Fy or 0.0, ld.phi)[-1]
        prev_pt = (prev.p, prev.t)
    else:
        prev_pt = (nsol.p, np.zeros((2, c.grid.n)))
    out, warm = [], None
    for k in range(1, max(steps) + 1):
        prob = c.tangential_step("rolling", nsol.p, ld, prev_pt, c.grid.dx, scene.load.direction)
        sol = meth.solve(prob, warm)
        if k in steps:
            what = f"{scene_name}: rolling step {k} (Δq = dx) from {'the braked state' if braked else 'rest'}"
            out.append(_program(f"{name}-k{k}", what, prob, sol, c, {"step": k}))
        prev_pt, warm = (nsol.p, sol.t), sol
    return out


def coupled(name, elements, materials, ratio=0.5, fc=True, halves=True):
    """Dissimilar bodies' static shift to Fx = ratio·μFN: the N–T alternation by Newton; its two halves
    at the coupled solution (QP and SOCP) and the coupled step as an FCLib problem."""
    scene, c = _contact("cattaneo-3d", elements, materials)
    FN = scene.load.normal
    loads = Loads(Fx=ratio * c.mu * FN, Fy=0.0)
    ns, ts, sweeps = coupled_step(c, _newton(), FN, "shift", loads)
    K = float(c.materials.K)
    tag = f"E {materials[0] / 1e3:g}/{materials[1]:g} on {materials[2] / 1e3:g}/{materials[3]:g} (K = {K:+.4f})"
    out = []
    if halves:
        nprob = c.normal_step(FN, ts.t)
        nsol = _newton().solve(nprob, ns)
        out.append(_program(f"{name}-normal", f"dissimilar bodies, {tag}: normal half at the coupled shift "
                                              f"(gap with A_nt t)", nprob, nsol, c, {"sweeps": sweeps, "K": K}))
        tprob = c.tangential_step("shift", ns.p, loads)
        tsol = _newton().solve(tprob, ts)
        out.append(_program(f"{name}-tangential", f"dissimilar bodies, {tag}: tangential half at the coupled "
                                                  f"shift (bound μp, history A_tn p)", tprob, tsol, c,
                            {"sweeps": sweeps, "K": K}))
    if fc:
        out.append(_fc(f"{name}-fc", f"dissimilar bodies, {tag}: the coupled static shift", c, ns, ts, loads, K))
    return out


def fc_similar(name, elements, ratio=0.6):
    """Similar bodies' static shift as an FCLib problem (W without the normal–tangential blocks)."""
    scene, c = _contact("cattaneo-3d", elements)
    FN = scene.load.normal
    loads = Loads(Fx=ratio * c.mu * FN, Fy=0.0)
    ns, ts, _ = coupled_step(c, _newton(), FN, "shift", loads)
    return [_fc(f"{name}-fc", f"Cattaneo–Mindlin (similar bodies), Fx = {ratio:g} μFN", c, ns, ts, loads, 0.0)]


def _influence(c):
    """``E*/c·[[A_nn, A_nt], [A_tn, A_tt]]`` interleaved per element ``(N, T1, T2)``."""
    ops, n = c.ops, c.grid.n
    A = np.zeros((3 * n, 3 * n))
    A[:n, :n] = ops.Ann.dense()
    A[n:, n:] = ops.Att.dense()
    if ops.coupled:
        A[:n, n:] = ops.Ant.dense()
        A[n:, :n] = ops.Atn.dense()
    order = np.arange(3 * n).reshape(3, n).T.ravel()
    return A[np.ix_(order, order)] * c.scales.modulus / c.scales.length


def _fc(name, what, c, ns, ts, loads, K) -> Exported:
    """The coupled static step at the certified approach and shift as ``FC(W, q, μ)`` (module docstring of
    :mod:`~rollqp.conicset.fclib`)."""
    sc, n = c.scales, c.grid.n
    W = _influence(c)
    zero = Loads(xi=ts.xi, eta=ts.eta, phi=loads.phi)
    s_rigid = c.tangential_step("shift", np.zeros(n), zero).slip(np.zeros((2, n)))
    q = np.vstack([(c.h - ns.delta) / sc.displacement, s_rigid / sc.slip]).T.ravel()
    r = np.vstack([ns.p / sc.stress, ts.t / sc.stress]).T.ravel()
    u = W @ r + q
    mu = np.full(n, c.mu)
    r_fc = fclib.residual(W, q, mu, r)
    r_step = max(ns.residual, ts.residual)
    # the step's own gap and slip against W r + q: the same numbers up to the products' round-off
    consistency = float(np.max(np.abs(u - np.vstack([ns.g / sc.displacement, ts.s / sc.slip]).T.ravel())))
    if not (r_fc <= CERTIFIED and r_step <= CERTIFIED and consistency <= CERTIFIED):
        raise InputError(name, f"not certified: residual {r_fc:.2e} (file), {r_step:.2e} (step), W r + q off by "
                               f"{consistency:.2e}")
    ev = np.linalg.eigvalsh(0.5 * (W + W.T))
    st = ts.info.get("contact", 0)
    bound = c.mu * np.maximum(ns.p, 0)
    states = c.tangential_step("shift", ns.p, zero).states(ts.t, ts.s)
    inside = states > 0
    meta = {"what": what, "grid": [c.grid.nx, c.grid.ny], "contacts": n, "n": 3 * n, "K": K,
            "cond_W": float(ev[-1] / ev[0]), "asymmetry_W": float(np.max(np.abs(W - W.T)) / np.max(np.abs(W))),
            "residual": r_step, "residual_from_arrays": r_fc, "w_consistency": consistency,
            "delta_hat": ns.delta / sc.displacement, "xi_hat": ts.xi / sc.slip, "eta_hat": ts.eta / sc.slip,
            "p0": sc.stress, "Estar": sc.modulus, "c": sc.length, "mu": c.mu, "contact_elements": int(inside.sum()),
            "stick": float(np.mean(states[inside] == 1)), "slip": float(np.mean(states[inside] == 2)),
            "bound_max": float(bound.max() / sc.stress), "newton_contact": st}
    return Exported(name, "fc", what, {"W": W, "q": q, "mu": mu, "u": u}, r, np.zeros(0), meta)


# ---------------------------------------------------------------------------------------- the set
def _cases(small: bool):
    """``(name, builder)`` pairs: the small set of the tests, or the full set."""
    if small:
        return [("hertz-circle-12", lambda: hertz("hertz-circle-12", "cattaneo-3d", (12, 12))),
                ("catt-12-shift", lambda: shift("catt-12-shift", (12, 12))),
                ("alusteel-10", lambda: coupled("alusteel-10", (10, 10), ALU_STEEL))]
    out = []
    for e in (8, 16, 24, 32):
        out.append((f"hertz-circle-{e}", lambda e=e: hertz(f"hertz-circle-{e}", "cattaneo-3d", (e, e))))
        out.append((f"catt-{e}-shift", lambda e=e: shift(f"catt-{e}-shift", (e, e))))
    out += [("catt-16-shift-q0.98", lambda: shift("catt-16-shift-q0.98", (16, 16), ratio=0.98)),
            ("catt-24-rolling", lambda: rolling("catt-24-rolling", "cattaneo-3d", (24, 24), (2, 12))),
            ("hertz-ellipse-16x32", lambda: hertz("hertz-ellipse-16x32", "kalker-elliptic", (16, 32))),
            ("ellipse-16x32-rolling", lambda: rolling("ellipse-16x32-rolling", "kalker-elliptic", (16, 32), (3, 30),
                                                      braked=False)),
            ("spin-20-rolling", lambda: rolling("spin-20-rolling", "kalker-circular", (20, 20), (4,),
                                                loads=Loads(Fx=0.0, Fy=0.0, phi=4e-3), braked=False)),
            ("alusteel-16", lambda: coupled("alusteel-16", (16, 16), ALU_STEEL)),
            ("steelalu-16", lambda: coupled("steelalu-16", (16, 16), STEEL_ALU)),
            ("softsteel-16", lambda: coupled("softsteel-16", (16, 16), SOFT_STEEL, halves=False)),
            ("alusteel-24", lambda: coupled("alusteel-24", (24, 24), ALU_STEEL, halves=False)),
            ("catt-16", lambda: fc_similar("catt-16", (16, 16)))]
    return out


#: The case names of the full set and of the small set (the tests'), in order.
CASES = [name for name, _ in _cases(False)]
SMALL = [name for name, _ in _cases(True)]


def build(small: bool = False, only=None, progress=None) -> list[Exported]:
    """Generate and certify the problems (``only``: case names, see :data:`CASES`)."""
    cases = _cases(small)
    if only:
        known = {n for n, _ in cases}
        bad = [n for n in only if n not in known]
        if bad:
            raise InputError("--only", f"unknown case(s) {', '.join(bad)}; known: {', '.join(sorted(known))}")
        cases = [(n, f) for n, f in cases if n in only]
    out = []
    for name, make in cases:
        probs = make()
        if progress:
            progress(name, probs)
        out += probs
    return out


def write_set(problems, out) -> None:
    """Write ``problems`` under ``out``: ``cbf/NAME.cbf`` and ``data/NAME.npz`` (the program's arrays) for
    the conic programs, ``fclib/NAME.hdf5`` for the FCLib problems, ``solutions/NAME.npz`` (certified
    solution and the map back to tractions) and ``problems.json`` (the catalogue)."""
    out = Path(out)
    for sub in ("cbf", "data", "fclib", "solutions"):
        (out / sub).mkdir(parents=True, exist_ok=True)
    catalogue = {}
    for p in problems:
        meta = {k: v for k, v in p.meta.items() if k != "elements"}
        if p.kind == "fc":
            fclib.write(out / "fclib" / f"{p.name}.hdf5", p.data["W"], p.data["q"], p.data["mu"], r=p.x, u=p.data["u"],
                        title=p.name, description=p.what,
                        math_info="W symmetric positive definite (E*/c times the half-spaces' influence matrix); "
                                  f"certified solution by rollqp's Newton method, residual {p.meta['residual']:.1e}")
            np.savez(out / "solutions" / f"{p.name}.npz", r=p.x, u=p.data["u"], grid=np.array(p.meta["grid"]),
                     meta=np.array(json.dumps(meta)))
        else:
            comment = (f"rollqp conic test set: {p.name}\n{p.what}\nmin 1/2 x'Hx + q'x through the epigraph "
                       f"(tau, 1, L'x) in QR; certified solution in solutions/{p.name}.npz")
            cbf.write(out / "cbf" / f"{p.name}.cbf", p.data, comment)
            np.savez(out / "data" / f"{p.name}.npz", **p.data.arrays())
            np.savez(out / "solutions" / f"{p.name}.npz", x=p.x, y=p.y, z=cbf.epigraph_point(p.data, p.x),
                     elements=np.array(p.meta["elements"]), meta=np.array(json.dumps(meta)))
        catalogue[p.name] = {"kind": p.kind, **meta}
    (out / "problems.json").write_text(json.dumps(catalogue, indent=1), encoding="utf-8")
