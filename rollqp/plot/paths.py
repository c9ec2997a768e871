"""Scenes about a profile or a load path: what ``rollqp run --plot`` draws for them (docs/kinematics.md).

* :func:`profile_figure` — a feature of a body's profile (a dent, a flat, roughness) rolls
  through the contact: pressure and the profile at states before, during and after its passage,
  the traction, the node states over the run with the feature's track, and the creepage.
* :func:`rest_figure` — tangential loads that change at rest (fretting, ``load.rolled`` constant):
  tractions at the turning points against Mindlin–Deresiewicz, the Q–u loop (the rigid shift,
  not a creepage) against the closed form with the energy per cycle, the load path, and the
  creepage once it rolls.
* :func:`path_figure` — a stop and a reversal (``load.rolled``): tractions and slip before the
  stop and while the contact turns round, against Carter in both directions, the node states
  over τ, and the creepage of the rolling steps only (a stop has none).
"""
from __future__ import annotations

import numpy as np

from .. import closedforms as cf
from .dissimilar import contact_span, draw_pressure, draw_zone_map
from .style import (LABELS, REFERENCES, Info, arrays, clock, colors, finish, legend_below, length_axis, pyplot,
                    reference, rolling_mask, stress_axis, symbol)
from ..kinematics import hysteresis
from .transient import coulomb


def _label(tname, tq, k, res, a):
    """``τ = …, q = …`` of state k (``res`` None: τ or q alone)."""
    lab = f"${symbol(tname)} = {tq[k]:.2f}\\,a_H$"
    if tname == "tau" and res is not None:
        lab += f", $q = {res['q'][k] / a:.2f}\\,a_H$"
    return lab


def _nearest(values, wanted, pool):
    """The index in ``pool`` (an index array) whose ``values`` is nearest to each of ``wanted``, in order, unique."""
    out = []
    for w in wanted:
        k = int(pool[np.argmin(np.abs(values[pool] - w))])
        if k not in out:
            out.append(k)
    return sorted(out)


# =========================================================================== a profile rolling through
def deviation(scene, x, q) -> np.ndarray:
    """The moving part of the undeformed gap at rolled distance ``q``: the material features of both
    bodies' profiles at ``x − d·q`` (length units; :mod:`rollqp.profiles`)."""
    shift = scene.load.direction * float(q)
    dz = np.zeros_like(np.asarray(x, dtype=float))
    for body in (scene.A, scene.B):
        if body.profile is not None:
            for f in body.profile.features:
                if f.material:
                    dz = dz + f.height(np.asarray(x, dtype=float) - shift)
    return dz


def passage(res, scene, a):
    """``(states, dz)``: the states whose contact (``abs(x) <= a_H``) the profile's features touch, and the
    deviation of every state (``(K+1, n)``)."""
    x = np.asarray(res["x"], dtype=float)
    dz = np.array([deviation(scene, x, q) for q in res["q"]])
    inside = np.abs(x) <= a
    amp = np.max(np.abs(dz[:, inside]), axis=1) if inside.any() else np.zeros(len(dz))
    on = np.flatnonzero(amp > 1e-3 * max(float(amp.max()), 1e-300))
    return on, dz


def profile_states(res, scene, a, n_during: int = 4) -> list[int]:
    """The states to draw: the last before the passage, ``n_during`` evenly through it, the first after
    it and the last of the run (fewer where they coincide)."""
    on, _ = passage(res, scene, a)
    K = len(res["q"]) - 1
    q = np.asarray(res["q"], dtype=float)
    if on.size == 0:  # the features never reach the contact: evenly over the run
        return sorted(set(np.linspace(0, K, 5).round().astype(int).tolist()))
    during = np.linspace(q[on[0]], q[on[-1]], n_during + 2)[1:-1]
    pick = [max(on[0] - 1, 0)] + _nearest(q, during, on) + [min(on[-1] + 1, K), K]
    return sorted(set(int(k) for k in pick))


def profile_figure(res, scene, path=None, title: str | None = None):
    """A profile feature rolling through: pressure and profile, traction, zones with its track, creepage."""
    plt = pyplot()
    res = arrays(res)
    info = Info(res, scene)
    a = info.a
    idx = profile_states(res, scene, a)
    on, dz = passage(res, scene, a)
    fig = plt.figure(figsize=(15, 10.5), constrained_layout=True)
    gs = fig.add_gridspec(3, 2, height_ratios=[2.2, 1.0, 2.2])
    axp = fig.add_subplot(gs[0, 0])
    axd = fig.add_subplot(gs[1, 0], sharex=axp)
    axt = fig.add_subplot(gs[0:2, 1])
    draw_pressure(axp, res, info, idx, hertz=False)
    xf = np.linspace(-1, 1, 401) * a
    reference(axp, xf / a, cf.hertz_pressure(xf, a, info.p0) / info.p0, "hertz", label="Hertz (round rollers)")
    x = res["x"] / a
    small, unit = _small_length(info)
    for c, k in zip(colors(len(idx)), idx):
        axd.plot(x, dz[k] * small, "-", color=c, lw=1.3)
        axt.plot(x, res["pt"][k] / (info.mu_scale * info.p0), "-", color=c, lw=1.4, label=_label("q", res["q"] / a, k,
                                                                                               res, a))
    axd.set(xlabel=LABELS["x"], ylabel=f"$\\Delta z$ [{unit}]", title="the profile's deviation from the circles "
            "(> 0: material removed)")
    axp.set_xlabel("")
    axt.set(xlabel=LABELS["x"], ylabel=LABELS["t"], title="tangential traction on body A")
    _reference_bounds(axt, res, scene, info)
    x0, x1 = contact_span(res, a)
    for axis in (axp, axd, axt):
        axis.set_xlim(x0, x1)
        axis.grid(alpha=0.3)
    length_axis(axp, info)
    stress_axis(axt, info, per_mu=True)
    legend_below(axp, ncol=4, fontsize=7)
    legend_below(axt, ncol=3)
    axz = fig.add_subplot(gs[2, 0])
    draw_zone_map(axz, res, scene, legend="below")
    if on.size:
        _mark_span(axz, res["q"][on[0]] / a, res["q"][on[-1]] / a, "the feature in the contact")
    axc = fig.add_subplot(gs[2, 1], sharex=axz)
    _creepage(axc, res, scene, info, res["q"] / a, "q")
    fig.suptitle(info.title(title), fontsize=9)
    return finish(fig, path)


def _mark_span(ax, t0, t1, text):
    """Two dashed verticals around an interval of the horizontal axis and its name between them (not a
    shading: the zone map's colours stay as they are)."""
    for t in (t0, t1):
        ax.axvline(t, color="k", ls=(0, (4, 3)), lw=0.9)
    ax.text(0.5 * (t0 + t1), 0.5, text, transform=ax.get_xaxis_transform(), ha="center", va="center", fontsize=7,
            rotation=90, color="k", bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="none", alpha=0.8))


def _small_length(info):
    """``(factor, name)`` for profile depths and displacements: µm when the scene is in mm or m."""
    return {"mm": (1e3, "µm"), "m": (1e6, "µm")}.get(info.u.length, (1.0, info.u.length))


def _reference_bounds(ax, res, scene, info):
    """Carter's steady traction for the final loads (the circles' state the contact returns to)."""
    mu = coulomb(scene)
    P, Q = float(res["P"][-1]), float(res["Q"][-1])
    if mu is None or scene.coupling_level != "off" or not abs(Q) < mu * P:
        return
    xf = np.linspace(-1, 1, 801) * info.a
    d = _final_direction(res, info)
    reference(ax, xf / info.a, cf.carter_traction(xf, info.a, info.p0, mu, Q / (mu * P), d) / (mu * info.p0),
              "carter" if d == info.direction else "carter_back")


def _final_direction(res, info):
    d = np.asarray(res["direction"]) if "direction" in res else np.zeros(0)
    d = d[d != 0]
    return int(d[-1]) if d.size else info.direction


def _creepage(ax, res, scene, info, tq, tname, rolled=True):
    """ξR/a_H of the rolling states only (stops and load changes at rest have none: gaps), Carter's steady
    value of the final loads, and the rolled distance q(τ) on a second scale for a load path."""
    xi = np.asarray(res["creepage"], dtype=float) * info.R / info.a
    roll = rolling_mask(res, steady_start=info.start == "rolling")
    ax.plot(tq, np.where(roll, xi, np.nan), "-", color="C0", lw=1.3, label=r"rollqp, $\xi R/a_H$ (rolling states)")
    mu = coulomb(scene)
    P, Q = float(res["P"][-1]), float(res["Q"][-1])
    if mu is not None and scene.coupling_level == "off" and 0 < abs(Q) < mu * P:
        ax.axhline(cf.carter_creepage(info.a, info.R, mu, Q / (mu * P)) * info.R / info.a, **REFERENCES["carter"])
    ax.set(xlabel=LABELS[tname], ylabel=LABELS["xi"], title="creepage of the rolling steps")
    ax.grid(alpha=0.3)
    handles, labels = ax.get_legend_handles_labels()
    if tname == "tau" and rolled:
        tw = ax.twinx()
        handles += tw.plot(tq, res["q"] / info.a, "-", color="0.6", lw=1.0)
        labels.append(r"rolled distance $q/a_H$ (right scale)")
        tw.set_ylabel(LABELS["q"], color="0.45")
    legend_below(ax, handles=handles, labels=labels)


# =========================================================================== loads changing at rest
def rest_states(res, info) -> list[int]:
    """At-rest states at the tangential load's turning points and zero crossings (first cycle and a half)."""
    rest = np.flatnonzero(~rolling_mask(res, steady_start=info.start == "rolling"))
    r = np.asarray(res["Q"], dtype=float)[rest] / (info.mu_scale * np.asarray(res["P"], dtype=float)[rest])
    picks = [0]
    for j in range(1, r.size - 1):
        if (r[j] - r[j - 1]) * (r[j + 1] - r[j]) < 0 or (r[j] != r[j - 1] and r[j + 1] == r[j]):
            picks.append(j)  # a turning point (or the end of a ramp)
    picks.append(r.size - 1)
    out = []
    for j0, j1 in zip(picks[:-1], picks[1:]):
        out.append(j0)
        seg = np.arange(j0, j1 + 1)
        if np.sign(r[j0]) * np.sign(r[j1]) < 0:
            out.append(int(seg[np.argmin(np.abs(r[seg]))]))  # the zero crossing between two turning points
    out.append(picks[-1])
    return sorted(set(int(rest[j]) for j in out))[:6]


def mindlin_paths(res, info, states):
    """``{k: path of Q/(μP)}`` for the states whose history is at rest under constant P (Mindlin applies)."""
    rest = ~rolling_mask(res, steady_start=info.start == "rolling")
    P = np.asarray(res["P"], dtype=float)
    r = np.asarray(res["Q"], dtype=float) / (info.mu_scale * P)
    out = {}
    for k in states:
        if rest[:k + 1].all() and np.ptp(P[:k + 1]) == 0 and np.all(np.abs(r[:k + 1]) < 1):
            out[k] = list(r[:k + 1])
    return out


def rest_figure(res, scene, path=None, title: str | None = None):
    """Loads changing at rest: tractions against Mindlin, the Q–u loop against the closed form, the path."""
    plt = pyplot()
    res = arrays(res)
    info = Info(res, scene)
    a, p0, mu = info.a, info.p0, info.mu_scale
    tq, tname = clock(res, a)
    idx = rest_states(res, info)
    mind = mindlin_paths(res, info, idx) if coulomb(scene) is not None and scene.coupling_level == "off" else {}
    fig, ax = plt.subplots(2, 2, figsize=(14, 10), constrained_layout=True)
    x = res["x"] / a
    xf = np.linspace(-1, 1, 801) * a
    for c, k in zip(colors(len(idx)), idx):
        r = round(float(res["Q"][k]) / (mu * float(res["P"][k])), 2) + 0.0  # no "-0.00"
        ax[0, 0].plot(x, res["pt"][k] / (mu * p0), "o", ms=3, color=c,
                      label=_label(tname, tq, k, None, a) + f", $Q/(\\mu P) = {r:+.2f}$")
        if k in mind:
            ax[0, 0].plot(xf / a, cf.mindlin_traction(xf, a, p0, mu, mind[k]) / (mu * p0), "-", color=c, lw=0.9)
    ax[0, 0].plot([], [], "k-", lw=0.9, label="Mindlin–Deresiewicz (lines, each state's colour)")
    ax[0, 0].set(xlabel=LABELS["x"], ylabel=LABELS["t"], title="traction at rest: turning points and zero crossings "
                 "(dots: rollqp)", xlim=contact_span(res, a))
    length_axis(ax[0, 0], info)
    stress_axis(ax[0, 0], info, per_mu=True)
    legend_below(ax[0, 0], ncol=2)
    _loop(ax[0, 1], res, scene, info)
    _load_path(ax[1, 0], res, info, tq, tname)
    _creepage(ax[1, 1], res, scene, info, tq, tname, rolled=False)
    for axis in ax.ravel():
        axis.grid(alpha=0.3)
    fig.suptitle(info.title(title), fontsize=9)
    return finish(fig, path)


def _loop(ax, res, scene, info):
    """Q against the rigid displacement u at rest (u = −Σ shift: :func:`rollqp.kinematics.hysteresis`), its
    part linear in Q removed (it depends on the half-space's reference distance and does no work), and the
    Mindlin–Deresiewicz loop of the same path; the energy of the last closed cycle of each."""
    rest = ~rolling_mask(res, steady_start=info.start == "rolling")
    h = hysteresis(res)
    Q, u = h["Q"][rest], h["u"][rest]
    muP = info.mu_scale * float(res["P"][0])
    r = Q / muP
    i, j = _last_cycle(r)
    if i is None:
        ax.text(0.5, 0.5, "no closed load cycle at rest", ha="center", transform=ax.transAxes)
        return
    k = (u[i] - u[j]) / (Q[i] - Q[j])  # the secant compliance through the loop's tips
    scale = np.pi * float(res["Estar"]) / muP  # u in units of μP/(πE*), the closed form's
    lo, hi = sorted((i, j))
    seg = slice(min(lo, hi), None)
    ax.plot((u[seg] - u[i] - k * (Q[seg] - Q[i])) * scale, r[seg], "o-", ms=2.5, lw=0.9, color="C0",
            label=f"rollqp: $W$ = {_cycle_energy(Q, u, lo, hi):.4g} {info.u.energy} per cycle")
    if coulomb(scene) is not None and scene.coupling_level == "off" and np.all(np.abs(r) < 1):
        uc = cf.mindlin_displacement(r, info.mu_scale, float(res["P"][0]), float(res["Estar"]))
        kc = (uc[i] - uc[j]) / (Q[i] - Q[j])
        amp = 0.5 * (r[i] - r[j])
        W = cf.mindlin_dissipation(abs(amp), info.mu_scale, float(res["P"][0]), float(res["Estar"]))
        reference(ax, (uc[seg] - uc[i] - kc * (Q[seg] - Q[i])) * scale, r[seg], "mindlin", lw=1.4,
                  label=f"Mindlin–Deresiewicz 2D: $W$ = {W:.4g} {info.u.energy}")
    ax.set(xlabel=r"$(u - k\,Q)\;\pi E^*/(\mu P)$, $k$: secant compliance of the loop", ylabel=LABELS["Q"],
           title="tangential load against rigid shift at rest (not a creepage)")
    small, unit = _small_length(info)
    sec = ax.secondary_xaxis("top", functions=(lambda v: v * small / scale, lambda v: v * scale / small))
    sec.set_xlabel(f"$u - k\\,Q$ [{unit}]", fontsize=8)
    sec.tick_params(labelsize=7)
    legend_below(ax, ncol=1)


def _last_cycle(r):
    """``(i, j)``: the last maximum and the minimum before it that close a cycle (equal |r|), or ``(None, None)``."""
    if r.size < 3 or np.ptp(r) == 0:
        return None, None
    top, bottom = r.max(), r.min()
    tops = np.flatnonzero(np.isclose(r, top, atol=1e-9))
    bots = np.flatnonzero(np.isclose(r, bottom, atol=1e-9))
    for i in tops[::-1]:
        before = bots[bots < i]
        if before.size:
            return int(i), int(before[-1])
    return None, None


def _cycle_energy(Q, u, lo, hi):
    """``∮ Q du`` from state ``lo`` to ``hi`` and back along the states after ``hi`` to the next return to Q[lo]."""
    after = np.flatnonzero(np.isclose(Q[hi:], Q[lo], atol=1e-9 * abs(Q).max()))
    end = hi + int(after[0]) if after.size else Q.size - 1
    m = slice(lo, end + 1)
    return float(np.sum(0.5 * (Q[m][1:] + Q[m][:-1]) * np.diff(u[m])))


def _load_path(ax, res, info, tq, tname):
    """Q/(μP) against τ, the rolling phases shaded, and the rolled distance q(τ)."""
    r = np.asarray(res["Q"], dtype=float) / (info.mu_scale * np.asarray(res["P"], dtype=float))
    ax.plot(tq, r, "-", color="#9467bd", lw=1.3, label=LABELS["Q"])
    roll = rolling_mask(res)
    for s, e in _runs(roll):
        ax.axvspan(tq[s - 1] if s else tq[s], tq[e], color="C0", alpha=0.08, lw=0)
    ax.plot([], [], "s", color="C0", alpha=0.25, label="rolling")
    ax.set(xlabel=LABELS[tname], ylabel=LABELS["Q"], title="the load path")
    handles, labels = ax.get_legend_handles_labels()
    tw = ax.twinx()
    handles += tw.plot(tq, res["q"] / info.a, "-", color="0.55", lw=1.0)
    labels.append(r"rolled distance $q/a_H$ (right scale)")
    tw.set_ylabel(LABELS["q"], color="0.45")
    legend_below(ax, handles=handles, labels=labels)


def _runs(mask):
    """``[(start, end), ...]``: the index runs where ``mask`` is True (inclusive ends)."""
    m = np.concatenate(([False], np.asarray(mask, dtype=bool), [False]))
    d = np.diff(m.astype(int))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1))


# =========================================================================== stops and reversals
def turn_states(res, info) -> tuple[list[int], int | None]:
    """``(states, k_turn)``: the last state before the first stop or reversal, the states 0.25, 0.5, 1 and 2 a_H
    of rolling after it turns, and the last; ``k_turn`` the first rolling state of the new direction."""
    d = np.asarray(res["direction"])
    q = np.asarray(res["q"], dtype=float) / info.a
    K = d.size - 1
    moving = np.flatnonzero(d[1:] != 0) + 1
    turn = next((int(k) for k, prev in zip(moving[1:], moving[:-1]) if d[k] != d[prev]), None)
    stop = next((int(k) for k in range(1, K + 1) if d[k] == 0 and d[k - 1] != 0), None)
    before = (stop or turn or K) - 1
    out = [max(before, 0)]
    if stop is not None and turn is not None and turn > stop:
        out.append(turn - 1)  # the end of the stop
    if turn is not None:
        rolled = np.concatenate(([0.0], np.cumsum(np.abs(np.diff(q)))))  # distance rolled, either way
        since = rolled - rolled[turn - 1]
        after = np.arange(turn, K + 1)
        out += _nearest(since, (0.25, 0.5, 1.0, 2.0), after)
    out.append(K)
    return sorted(set(out)), turn


def path_figure(res, scene, path=None, title: str | None = None):
    """A stop and a reversal: traction and slip around the turn against Carter both ways, zones, creepage."""
    plt = pyplot()
    res = arrays(res)
    info = Info(res, scene)
    a, p0, mu = info.a, info.p0, info.mu_scale
    tq, tname = clock(res, a)
    idx, _ = turn_states(res, info)
    fig, ax = plt.subplots(2, 2, figsize=(14, 10), constrained_layout=True)
    x = res["x"] / a
    for c, k in zip(colors(len(idx)), idx):
        lab = _label(tname, tq, k, res, a)
        ax[0, 0].plot(x, res["pt"][k] / (mu * p0), "-", color=c, lw=1.4, label=lab)
        if not (k == 0 and info.static_start) and res["direction"][k] != 0:
            ax[0, 1].plot(x, np.where(res["state"][k] == 0, np.nan, res["slip"][k]) * info.R / a, "-", color=c,
                          lw=1.2, label=lab)
    _carter_both_ways(ax[0], res, scene, info)
    for axis, (yl, t) in zip(ax[0], ((LABELS["t"], "tangential traction on body A, around the turn"),
                                      (LABELS["s"], "slip of the rolling states shown"))):
        axis.set(xlabel=LABELS["x"], ylabel=yl, title=t, xlim=contact_span(res, a))
        axis.grid(alpha=0.3)
        length_axis(axis, info)
        legend_below(axis, ncol=2)
    stress_axis(ax[0, 0], info, per_mu=True)
    draw_zone_map(ax[1, 0], res, scene, clock=(tq, tname), legend="below")
    for s, e in _runs(~rolling_mask(res)[1:]):
        _mark_span(ax[1, 0], tq[s], tq[e + 1], "at rest")
    _creepage(ax[1, 1], res, scene, info, tq, tname)
    fig.suptitle(info.title(title), fontsize=9)
    return finish(fig, path)


def _carter_both_ways(axes, res, scene, info):
    """Carter's traction and slip for the final loads in both rolling directions (each its own colour)."""
    mu = coulomb(scene)
    P, Q = float(res["P"][-1]), float(res["Q"][-1])
    if mu is None or scene.coupling_level != "off" or not abs(Q) < mu * P:
        return
    a, xf = info.a, np.linspace(-1, 1, 801) * info.a
    for d, key in ((info.direction, "carter"), (-info.direction, "carter_back")):
        style = {"label": REFERENCES[key]["label"] if d == info.direction else "Carter, rolling the other way"}
        reference(axes[0], xf / a, cf.carter_traction(xf, a, info.p0, mu, Q / (mu * P), d) / (mu * info.p0), key,
                  **style)
        reference(axes[1], xf / a, cf.carter_slip(xf, a, info.R, mu, Q / (mu * P), d) * info.R / a, key, **style)


__all__ = ["profile_figure", "rest_figure", "path_figure", "deviation", "profile_states", "rest_states",
           "turn_states"]
