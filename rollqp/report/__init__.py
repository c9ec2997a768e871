"""Errors against the closed forms (docs/formulation.md §12) and the run summary table."""
from __future__ import annotations

import numpy as np

from .. import closedforms as cf
from ..units import unit_names
from ..influence import get_model
from ..influence.layer import compliance_of
from ..influence.layer import summary_rows as layer_rows
from ..kinematics import plan


def rms_in_contact(x, a, err):
    """Root mean square of ``err`` over the nodes with ``|x| <= a``: the error measure of every
    closed-form comparison (the run summary, docs/validation.md, the tests and examples)."""
    m = np.abs(x) <= a
    return float(np.sqrt(np.mean(err[m] ** 2)))


def closed_form_errors(res: dict, scene) -> list[tuple[str, float, str]]:
    """``(name, value, what)`` for every closed form the scene has.

    Applicable only to similar materials (β = 0 or coupling off) on the half-space model:
    Hertz at the start (constant normal load), Cattaneo at the start of a braked scene,
    Carter and the creep law at the end when the loads have been constant for the last
    3 a_H (Carter's transient has died out by then: CONTACT's reference creepage stays
    within 0.1 % of steady from 2.6 a_H).
    """
    out = []
    if scene.coupling_level != "off" or not get_model(scene.contact.model).halfspace_field:
        return out
    x, a, p0, R = res["x"], float(res["a_H"]), float(res["p0"]), float(res["R"])
    mu = scene.contact.mu
    if scene.contact.friction.kind != "constant":  # a friction law: no closed form to compare with
        mu = 0.0
    P0 = float(res["P"][0])
    a0 = cf.hertz_half_width(P0, R, scene.Estar)
    p00 = cf.hertz_peak_pressure(P0, a0)
    out.append(("hertz", rms_in_contact(x, a0, res["pn"][0] - cf.hertz_pressure(x, a0, p00)) / p0,
                "rms(pn - Hertz)/p0 at q = 0"))
    if mu <= 0 or scene.load.tangential is None or compliance_of(scene.contact.layer) > 0:
        return out   # (an interface layer: Cattaneo's and Carter's bodies have none)
    if scene.load.start == "braked":
        r0 = float(res["Q"][0]) / (mu * P0)
        if 0 < abs(r0) < 1:
            e = res["pt"][0] - cf.cattaneo_traction(x, a0, p00, mu, r0)
            out.append(("cattaneo", rms_in_contact(x, a0, e) / (mu * p0), "rms(pt - Cattaneo)/(mu p0) at q = 0"))
    q = res["q"]
    qa = q[-1] / a
    tail = q >= q[-1] - 3 * a
    direction = scene.load.direction
    if scene.load.rolled is not None:  # a load path (rollqp.kinematics): the last 3 a_H rolled one way
        rolled, tail, direction = _rolled_tail(scene, 3 * a)
    else:
        rolled = q[-1]
    if rolled / a >= 3 * (1 - 1e-12) and np.ptp(res["P"][tail]) == 0 and np.ptp(res["Q"][tail]) <= 1e-12 * abs(res["Q"][-1]) + 1e-300:
        P1 = float(res["P"][-1])
        a1 = cf.hertz_half_width(P1, R, scene.Estar)
        p01 = cf.hertz_peak_pressure(P1, a1)
        r1 = float(res["Q"][-1]) / (mu * P1)
        e = res["pt"][-1] - cf.carter_traction(x, a1, p01, mu, r1, direction)
        out.append(("carter", rms_in_contact(x, a1, e) / (mu * p0), f"rms(pt - Carter)/(mu p0) at q = {qa:.2f} a_H"))
        xi = cf.carter_creepage(a1, R, mu, r1)
        if xi != 0:
            out.append(("creepage", abs(float(res["creepage"][-1]) / xi - 1),
                        f"|xi/xi_Carter - 1| at q = {qa:.2f} a_H ({float(res['creepage'][-1]):.4e} vs {xi:.4e})"))
    return out


def _rolled_tail(scene, need: float):
    """``(distance, mask, direction)``: how far the last steps of a load path rolled without stopping or
    reversing (up to ``need``), which states they are, and their direction (:mod:`rollqp.kinematics`)."""
    pl = plan(scene)
    d, k, dist = pl.final_direction, pl.d.size - 1, 0.0
    mask = np.zeros(pl.d.size, dtype=bool)
    mask[-1] = True
    while k > 0 and pl.d[k] == d and dist < need:
        dist += float(pl.dq[k])
        k -= 1
        mask[k] = True
    return dist, mask, d


def summary(res: dict, scene, method: str, wall: float, stresses=None) -> str:
    """The table ``rollqp run`` prints; ``stresses`` (a :class:`rollqp.subsurface.StressHistory`, from
    ``rollqp run --stresses``) adds the peak von Mises and τ1 over the run with their place and state.

    Dimensional values carry the units the scene declares (``units``, :mod:`rollqp.units`), beside
    the nondimensional ones; ``wall`` is the wall time of this call of the run (a resumed run: of
    the steps computed since it resumed, which the ``wall time`` row compares with their stepping).
    """
    u = unit_names(getattr(scene, "units", ""))
    a, p0 = float(res["a_H"]), float(res["p0"])
    ran = _meta(res).get("method") or method
    rows = [("scene", f"{scene.name} ({scene.source})"),
            ("method", ran if ran == method else f"{ran} (the scene names {method}: see fast path below)"),
            ("nodes", f"{res['x'].size} ({scene.discretization.elements} {scene.discretization.element} elements, "
                      f"zone ±{scene.discretization.zone} a_H = ±{scene.discretization.zone * a:.4g} {u.length})"),
            ("steps", steps_row(res, scene, u)),
            ("a_H, p0", f"{a:.6g} {u.length}, {p0:.6g} {u.stress} (Hertz at P̄ = {scene.load.normal:.6g} {u.load}, "
                        f"E* = {scene.Estar:.6g} {u.stress}, R = {scene.R:.6g} {u.length})"),
            ("beta (2beta)", f"{float(res['beta']):.6g} ({2 * float(res['beta']):.6g}), coupling {scene.coupling_level}"),
            *layer_rows(scene.contact.layer, u.length, u.stress),
            ("iterations", iterations_row(res)),
            ("wall time", time_row(res, wall)),
            ("max residual", f"{float(res['residual'].max()):.2e} (nondimensional, docs/formulation.md §5)"),
            ("final creepage", f"{float(res['creepage'][-1]):.6e}")]
    rows += _model_rows(res, scene)
    if _meta(res).get("method_note"):
        rows.append(("fast path", _meta(res)["method_note"]))
    rows += _start_rows(res)
    rows += _gross_rows(res)
    rows += energy_rows(res, scene, stresses)
    for name, val, what in closed_form_errors(res, scene):
        rows.append((f"error: {name}", f"{val:.3g}  {what}"))
    w = max(len(r[0]) for r in rows)
    return "\n".join(f"  {k:<{w}}  {v}" for k, v in rows)


def _rolling(res: dict) -> np.ndarray:
    """Which states ``1..K`` were rolling steps (a load path's stops are static steps: ``direction`` 0)."""
    d = np.asarray(res["direction"])[1:] if "direction" in res else None
    return np.ones(len(res["q"]) - 1, dtype=bool) if d is None else d != 0


def steps_row(res: dict, scene, u=None) -> str:
    """``K rolling steps of Δq …`` — or, with stops (``load.rolled``), how many rolled and how many stood still."""
    u = u or unit_names("")
    K = len(res["q"]) - 1
    roll = _rolling(res)
    a = float(res["a_H"])
    dq = np.abs(np.diff(np.asarray(res["q"], dtype=float)))[roll]
    if dq.size and np.ptp(dq) > 1e-9 * dq.max():  # a load path whose speed varies
        size = f"{dq.min() / a:.4g}…{dq.max() / a:.4g} a_H ({dq.min():.4g}…{dq.max():.4g} {u.length})"
    else:
        size = f"{scene.dq / a:.5g} a_H ({scene.dq:.4g} {u.length})"
    if roll.all():
        return f"{K} rolling steps of {size} + starting state"
    n = int(roll.sum())
    return (f"{K} steps + starting state: {n} rolling of {size}, {K - n} at rest (static steps: a stop, or loads "
            "that change without rolling)")


def iterations_row(res: dict) -> str:
    """Iterations in all, and the median per rolling step (the start and a load path's stops counted apart)."""
    it = np.asarray(res["iterations"])
    roll = _rolling(res)
    per = it[1:][roll] if roll.any() else it
    return (f"{int(it.sum())} in all ({int(it[0])} for the starting state), median {np.median(per):.0f} per "
            "rolling step")


def time_row(res: dict, wall: float) -> str:
    """Wall time against the stepping time of the same steps: a resumed run counts only its own steps."""
    st = np.asarray(res["step_time"], dtype=float)
    first = _meta(res).get("resumed_from")
    if first is None:
        return (f"{wall:.3f} s ({float(st.sum()):.3f} s stepping, median {1e3 * float(np.median(st)):.2f} ms "
                "per step)")
    mine = st[int(first) + 1:]
    med = 1e3 * float(np.median(mine)) if mine.size else float("nan")
    return (f"{wall:.3f} s for steps {int(first) + 1}..{st.size - 1} resumed here ({float(mine.sum()):.3f} s "
            f"stepping, median {med:.2f} ms per step); all {st.size - 1} steps with the earlier run: "
            f"{float(st.sum()):.3f} s stepping")


def _meta(res: dict) -> dict:
    """The result's ``meta`` (a dict, or its JSON as stored in a result file)."""
    import json
    meta = res.get("meta") or {}
    return json.loads(str(meta)) if not isinstance(meta, dict) else meta


def _start_rows(res: dict) -> list[tuple[str, str]]:
    """A rolling start that marched because the direct steady solve failed says so (rollqp.march)."""
    note = _meta(res).get("start_note")
    return [] if note is None else [("starting state", str(note))]


def _model_rows(res: dict, scene) -> list[tuple[str, str]]:
    """The influence model's own rows (:attr:`Model.report <rollqp.influence.Model.report>`; the BEM's: assembly
    cost, the geometric coupling and the asymmetry of F·A, docs/bem.md)."""
    rows = get_model(scene.contact.model).report
    return [] if rows is None else rows(_meta(res).get("model", {}))


def _gross_rows(res: dict) -> list[tuple[str, str]]:
    """States where every contact node slips (``meta["gross_sliding"]``, rollqp.result): said in words."""
    ks = _meta(res).get("gross_sliding") or []
    return [] if not ks else [("gross sliding", f"every contact node slips at {len(ks)} state(s) (first: state {ks[0]})")]


def energy_rows(res: dict, scene, stresses=None) -> list[tuple[str, str]]:
    """Dissipation (docs/stresses.md §5) and, if computed, the peak subsurface stresses (§3)."""
    rows = []
    if "dissipation" in res:
        u = unit_names(getattr(scene, "units", ""))
        unit = float(res["a_H"]) * float(res["p0"])  # force/length, the load unit
        Wf = float(np.sum(res["friction_work"]))
        rows.append(("dissipation", f"{float(res['dissipation'][-1]):.4g} {u.rate} per unit rolled distance at the "
                                    f"end ({float(res['dissipation'][-1]) / unit:.4g} a_H p0); friction work "
                                    f"{Wf:.4g} {u.energy} accumulated over the run ({Wf / (unit * float(res['a_H'])):.4g}"
                                    " a_H² p0)"))
    if stresses is not None:
        a, p0 = float(res["a_H"]), float(res["p0"])
        for key, label in (("von_mises", "peak von Mises"), ("tau1", "peak tau1")):
            v, x, z, k = stresses.overall[key]
            rows.append((label, f"{v / p0:.4f} p0 at x = {x / a:.4f} a_H, z = {z / a:.4f} a_H, state {k} "
                                f"(body {stresses.body}, grid {stresses.x.size} x {stresses.z.size})"))
    return rows
