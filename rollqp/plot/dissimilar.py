"""Dissimilar bodies (paper Figs 6–9): snapshots, the zone map, the creepage and load history.

* :func:`draw_snapshots` — pressure p/p0, traction t/(μp0) between its bounds ±μp/(μp0) = ±p/p0,
  slip and the node state (stick/slip/separation) against x/a_H at several rolled distances.
* :func:`draw_zone_map` — the node states of every stored state over (q/a_H, x/a_H), with the
  Hertz half-width of the current load.
* :func:`draw_history` — the creepage against q/a_H with Bentall–Johnson's μ → 0 value, and the
  loads where they vary.
* :func:`coupled_figure` — what ``rollqp run --plot`` draws for a scene with normal–tangential
  coupling: the coupling shown in four panels (pressure against Hertz, traction within its
  bounds, zone map, creepage and load).
* :func:`snapshot_figure`, :func:`zone_map_figure`, :func:`dissimilar_figure` (everything on one
  page, with the solver's iterations), :func:`comparison_figure` (several results overlaid).
"""
from __future__ import annotations

import numpy as np

from .. import closedforms as cf
from .style import (LABELS, REFERENCES, STATE_COLORS, STATE_NAMES, Info, arrays, colors, finish, legend_below,
                    length_axis, pyplot, reference, stress_axis)

#: ``|Q|/P`` below which a state counts as free rolling: the load condition ∫t = Q is met to the
#: solver tolerance (nondimensional residual 1e-10), so a prescribed Q = 0 is stored as ~1e-15 P;
#: 1e-8 leaves room and is far below any applied traction.
FREE_ROLLING_RATIO = 1e-8

#: :func:`select_states` default: a run has settled once no node's p/p0 or t/(μp0) changes
#: faster than this per a_H of rolling (node states flipping at a zone boundary of a coarse
#: mesh still move single values by ~0.1 per a_H; a transient by ~1–20).
SETTLED_RATE = 0.03


def _free_rolling(res) -> bool:
    """True if no tangential load acts at any step (the Bentall–Johnson μ → 0 limit applies)."""
    scale = np.maximum(np.abs(np.asarray(res["P"], dtype=float)), 1e-300)
    return bool(np.all(np.abs(np.asarray(res["Q"], dtype=float)) <= FREE_ROLLING_RATIO * scale))


def settled_q(res, mu: float | None = None, rate: float = SETTLED_RATE) -> float | None:
    """The rolled distance q/a_H after which the tractions stop changing, or None.

    None if they still change at the end (e.g. a varying load) or the run is too short to
    tell (the last quarter of the run must be quiet).
    """
    res = arrays(res)
    mu = Info(res).mu_scale if mu is None else (mu if mu > 0 else 1.0)
    a, p0 = float(res["a_H"]), float(res["p0"])
    q = np.asarray(res["q"], dtype=float) / a
    if q.size < 3:
        return None
    dq = np.diff(q)
    d = np.maximum(np.abs(np.diff(res["pn"], axis=0)).max(axis=1) / p0,
                   np.abs(np.diff(res["pt"], axis=0)).max(axis=1) / (mu * p0)) / np.where(dq > 0, dq, np.inf)
    big = np.nonzero(d > rate)[0]
    qs = float(q[big[-1] + 1]) if big.size else float(q[1])
    return qs if qs <= q[0] + 0.75 * (q[-1] - q[0]) else None


def select_states(q, a, at=None, n: int = 5, settled: float | None = None) -> list[int]:
    """Indices of the stored states to draw.

    Parameters
    ----------
    q : ndarray
        Rolled distances of the stored states (length units).
    a : float
        a_H.
    at : sequence of float, optional
        Wanted rolled distances q/a_H; each gives the nearest stored state (duplicates and
        values beyond the last state dropped).
    n : int
        Without ``at``: ``n`` states evenly spaced in q from the first to the last (both
        included) …
    settled : float, optional
        … or, if given (q/a_H where the run reached its steady state, :func:`settled_q`),
        ``n − 1`` evenly spaced over the transient ``[0, settled]`` and the last state.
    """
    qa = np.asarray(q, dtype=float) / a
    if at is None:
        n = max(int(n), 1)
        if settled is not None and n > 2 and settled < qa[-1]:
            at = list(np.linspace(qa[0], settled, n - 1)) + [qa[-1]]
        else:
            at = np.linspace(qa[0], qa[-1], n) if n > 1 else [qa[-1]]
    idx = []
    tol = 0.5 * (qa[1] - qa[0]) if qa.size > 1 else 0.0
    for w in at:
        if w > qa[-1] + tol:
            continue
        k = int(np.argmin(np.abs(qa - w)))
        if k not in idx:
            idx.append(k)
    return sorted(idx)


def contact_span(res, a, pad=0.15):
    """x/a_H limits around every node ever in contact."""
    x = res["x"] / a
    on = np.any(res["state"] > 0, axis=0)
    if not on.any():
        return x[0], x[-1]
    lo, hi = x[on].min(), x[on].max()
    return max(x[0], lo - pad), min(x[-1], hi + pad)


def _states(res, info, at, n):
    return select_states(res["q"], info.a, at, n, settled=None if at is not None else settled_q(res, info.mu))


def draw_pressure(ax, res, info, idx, hertz: bool = True):
    """p/p0 of the states ``idx`` (light to dark), Hertz's of each state's load dashed (``hertz``)."""
    x, a = res["x"] / info.a, info.a
    for c, k in zip(colors(len(idx)), idx):
        ax.plot(x, res["pn"][k] / info.p0, "-", color=c, lw=1.4, label=f"$q = {res['q'][k] / a:.2f}\\,a_H$")
    if hertz:
        xf = np.linspace(x[0], x[-1], 801) * a
        for j, k in enumerate(idx):
            P = float(res["P"][k])
            if P > 0:
                ah = cf.hertz_half_width(P, info.R, _estar(res))
                reference(ax, xf / a, cf.hertz_pressure(xf, ah, cf.hertz_peak_pressure(P, ah)) / info.p0, "hertz",
                          label="Hertz of each state's load" if j == 0 else None, lw=0.8)
    ax.set(xlabel=LABELS["x"], ylabel=LABELS["p"], title="contact pressure")
    stress_axis(ax, info)


def _estar(res):
    return float(res["Estar"])


def draw_traction(ax, res, info, idx):
    """t/(μp0) of the states ``idx`` with their bounds ±μp/(μp0) dotted."""
    x, a, p0, mu = res["x"] / info.a, info.a, info.p0, info.mu_scale
    for c, k in zip(colors(len(idx)), idx):
        ax.plot(x, res["pt"][k] / (mu * p0), "-", color=c, lw=1.4, label=f"$q = {res['q'][k] / a:.2f}\\,a_H$")
        bound = np.where(res["state"][k] > 0, res["pn"][k] / p0, np.nan)
        ax.plot(x, bound, ":", color=c, lw=0.9)
        ax.plot(x, -bound, ":", color=c, lw=0.9)
    ax.set(xlabel=LABELS["x"], ylabel=LABELS["t"], title=r"tangential traction on body A (dotted: $\pm\mu p$)")
    stress_axis(ax, info, per_mu=True)


def draw_snapshots(axes, res, scene=None, at=None, n: int = 5) -> list[int]:
    """Draw p/p0, t/(μp0) with ±μp/(μp0), slip and node states on four axes.

    Parameters
    ----------
    axes : sequence of 4 matplotlib axes
        Pressure, traction, slip, node state.
    res : dict or Result
    scene : Scene, optional
    at, n :
        Which states: the rolled distances ``at`` (q/a_H), or by default ``n`` states evenly
        spaced over the run, or, if the run settles (:func:`settled_q`), ``n − 1`` over the
        transient and the last one (:func:`select_states`).

    Returns
    -------
    list of int
        The state indices drawn.
    """
    res = arrays(res)
    info = Info(res, scene)
    idx = _states(res, info, at, n)
    axp, axt, axs, axz = axes
    draw_pressure(axp, res, info, idx, hertz=False)
    draw_traction(axt, res, info, idx)
    x, a = res["x"] / info.a, info.a
    for row, (c, k) in enumerate(zip(colors(len(idx)), idx)):
        lab = f"$q = {res['q'][k] / a:.2f}\\,a_H$"
        st = res["state"][k]
        if not (k == 0 and info.static_start):
            axs.plot(x, np.where(st == 0, np.nan, res["slip"][k]) * info.R / a, "-", color=c, lw=1.2, label=lab)
        for code in (0, 1, 2):
            m = st == code
            if m.any():
                axz.scatter(x[m], np.full(m.sum(), row), s=14, marker="s", color=STATE_COLORS[code], edgecolors="none")
        axz.text(1.01, row, f"q = {res['q'][k] / a:.2f}", transform=axz.get_yaxis_transform(), fontsize=7,
                 va="center", color=c)
    x0, x1 = contact_span(res, a)
    for axis in axes:
        axis.set_xlim(x0, x1)
        axis.grid(alpha=0.3)
    note = " (q = 0 braked: no rolling slip)" if (0 in idx and info.static_start) else ""
    axs.set(xlabel=LABELS["x"], ylabel=LABELS["s"], title="slip of A relative to B" + note)
    axz.set(xlabel=LABELS["x"], title="node state", ylim=(-0.6, len(idx) - 0.4))
    axz.set_yticks([])
    axz.invert_yaxis()
    from matplotlib.patches import Patch
    legend_below(axz, handles=[Patch(color=STATE_COLORS[c], label=STATE_NAMES[c]) for c in (1, 2, 0)],
                 labels=[STATE_NAMES[c] for c in (1, 2, 0)])
    for axis in (axp, axt, axs):
        legend_below(axis)
    return idx


def draw_zone_map(ax, res, scene=None, clock=None, legend: str = "right"):
    """Draw the node states of every stored state over (q/a_H, x/a_H), Hertz edges overlaid.

    ``clock``: ``(values/a_H, name)`` of the horizontal axis (default the rolled distance q; a
    load path draws its states against τ).
    """
    pyplot()
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch
    res = arrays(res)
    info = Info(res, scene)
    a = info.a
    q, name = clock if clock is not None else (res["q"] / a, "q")
    x = res["x"] / a
    qe = _edges(q)
    xe = _edges(x)
    cmap = ListedColormap([STATE_COLORS[0], STATE_COLORS[1], STATE_COLORS[2]])
    norm = BoundaryNorm([-0.5, 0.5, 1.5, 2.5], 3)
    ax.pcolormesh(qe, xe, np.asarray(res["state"], dtype=float).T, cmap=cmap, norm=norm, shading="flat",
                  rasterized=True)
    half = np.sqrt(np.maximum(res["P"], 0.0) / info.normal)  # Hertz half-width a(P)/a_H
    ax.plot(q, half, "k--", lw=0.8)
    ax.plot(q, -half, "k--", lw=0.8)
    x0, x1 = contact_span(res, a)
    ax.set(xlabel=LABELS[name], ylabel=LABELS["x"], ylim=(x0, x1), xlim=(qe[0], qe[-1]),
           title="node states (dashed: Hertz half-width of the load)")
    lead = -info.direction
    ax.text(0.995, 0.985 if lead > 0 else 0.015, "leading edge", transform=ax.transAxes, ha="right",
            va="top" if lead > 0 else "bottom", fontsize=7, color="0.15")
    handles = [Patch(color=STATE_COLORS[c], label=STATE_NAMES[c]) for c in (1, 2, 0)]
    if legend == "right":  # outside the axes: the image fills them, any legend inside would hide states
        ax.legend(handles=handles, fontsize=7, loc="upper left", bbox_to_anchor=(1.005, 1.0), borderaxespad=0.0)
    else:
        legend_below(ax, handles=handles, labels=[h.get_label() for h in handles])


def _edges(v):
    """Cell edges around the values ``v`` (midpoints, half a spacing beyond the ends)."""
    v = np.asarray(v, dtype=float)
    if v.size == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    return np.concatenate(([v[0] - 0.5 * (v[1] - v[0])], 0.5 * (v[1:] + v[:-1]), [v[-1] + 0.5 * (v[-1] - v[-2])]))


def draw_history(ax, res, scene=None):
    """Creepage ξR/a_H against q/a_H, the Bentall–Johnson μ → 0 value, and the loads if they vary."""
    res = arrays(res)
    info = Info(res, scene)
    a, R = info.a, info.R
    q = res["q"] / a
    xi = np.asarray(res["creepage"], dtype=float) * R / a
    if info.static_start:
        xi = np.where(np.arange(xi.size) == 0, np.nan, xi)  # the braked start: a static shift, no creepage
    ax.plot(q, xi, "-", color="C0", lw=1.3, label=r"creepage $\xi R/a_H$")
    if info.kappa != 0 and abs(info.kappa) <= 1 and _free_rolling(res):
        bj = cf.bentall_johnson_creepage(info.kappa, a, R) * np.sign(info.kappa) * info.direction
        ax.axhline(bj * R / a, **REFERENCES["bentall"])
    elif info.kappa != 0:
        ax.text(0.01, 0.98, "Bentall–Johnson (free rolling) not drawn: Q ≠ 0", transform=ax.transAxes,
                fontsize=7, color="0.3", va="top")
    ax.set(xlabel=LABELS["q"], ylabel=LABELS["xi"], title="creepage and loads")
    ax.grid(alpha=0.3)
    P = res["P"] / info.normal
    Qr = res["Q"] / (info.mu_scale * info.normal)
    lines, labels = ax.get_legend_handles_labels()
    if np.ptp(P) > 1e-12 or np.ptp(Qr) > 1e-9:
        tw = ax.twinx()
        if np.ptp(P) > 1e-12:
            lines += tw.plot(q, P, "-", color="0.5", lw=1.0)
            labels.append(LABELS["P"] + " (right scale)")
        if np.ptp(Qr) > 1e-9:
            lines += tw.plot(q, Qr, "-", color="#9467bd", lw=1.0)
            labels.append(r"$Q/(\mu \bar P)$ (right scale)")
        tw.set_ylabel("load")
    legend_below(ax, handles=lines, labels=labels)


def coupled_figure(res, scene=None, path=None, at=None, n: int = 5, title: str | None = None):
    """The coupling of a dissimilar pair in four panels: what ``rollqp run --plot`` draws for it.

    Pressure p/p0 at several q against Hertz's of each state's load (the coupling moves it off
    Hertz); traction t/(μp0) within its bounds ±μp; the node states over the whole run; the
    creepage with Bentall–Johnson's μ → 0 value and the load where it varies. States as
    :func:`select_states` (``at`` or ``n``); both scales (a_H, p0 and the scene's units).
    """
    plt = pyplot()
    res = arrays(res)
    info = Info(res, scene)
    idx = _states(res, info, at, n)
    fig, ax = plt.subplots(2, 2, figsize=(14, 9.6), constrained_layout=True)
    draw_pressure(ax[0, 0], res, info, idx)
    draw_traction(ax[0, 1], res, info, idx)
    x0, x1 = contact_span(res, info.a)
    for axis in ax[0]:
        axis.set_xlim(x0, x1)
        axis.grid(alpha=0.3)
        length_axis(axis, info)
        legend_below(axis)
    draw_zone_map(ax[1, 0], res, scene, legend="below")
    draw_history(ax[1, 1], res, scene)
    fig.suptitle(info.title(title), fontsize=9)
    return finish(fig, path)


def snapshot_figure(res, scene=None, path=None, at=None, n: int = 5, title: str | None = None):
    """Pressure, traction with ±μp, slip and node states against x/a_H at several q.

    Parameters
    ----------
    res : dict or Result
    scene : Scene, optional
    path : str, optional
        Save to this file (and return it); else return the figure.
    at : sequence of float, optional
        Rolled distances q/a_H to draw (nearest stored states).
    n : int
        Without ``at``: ``n`` states evenly spaced over the run, or, if it settles to a
        steady state (:func:`settled_q`), ``n − 1`` evenly spaced over the transient and the
        last one.
    """
    plt = pyplot()
    res = arrays(res)
    fig, ax = plt.subplots(2, 2, figsize=(13, 9.2), constrained_layout=True)
    draw_snapshots(ax.ravel(), res, scene, at=at, n=n)
    fig.suptitle(Info(res, scene).title(title), fontsize=9)
    return finish(fig, path)


def zone_map_figure(res, scene=None, path=None, title: str | None = None):
    """Node states over (q/a_H, x/a_H), and the creepage and loads against q/a_H."""
    plt = pyplot()
    res = arrays(res)
    fig, ax = plt.subplots(2, 1, figsize=(11, 8.2), sharex=True, constrained_layout=True,
                           gridspec_kw={"height_ratios": [2.2, 1]})
    draw_zone_map(ax[0], res, scene)
    ax[0].set_xlabel("")
    draw_history(ax[1], res, scene)
    fig.suptitle(Info(res, scene).title(title), fontsize=9)
    return finish(fig, path)


def dissimilar_figure(res, scene=None, path=None, at=None, n: int = 5, title: str | None = None):
    """One page: the four snapshot panels, the zone map, the creepage/load history and the iterations."""
    plt = pyplot()
    res = arrays(res)
    fig = plt.figure(figsize=(16, 11.5), constrained_layout=True)
    gs = fig.add_gridspec(3, 3, height_ratios=[1, 1, 1])
    axes = [fig.add_subplot(gs[0, 0]), fig.add_subplot(gs[0, 1]), fig.add_subplot(gs[0, 2]),
            fig.add_subplot(gs[1, 0])]
    draw_snapshots(axes, res, scene, at=at, n=n)
    zm = fig.add_subplot(gs[1, 1:])
    draw_zone_map(zm, res, scene)
    hist = fig.add_subplot(gs[2, 1:], sharex=zm)
    draw_history(hist, res, scene)
    _iterations_panel(fig.add_subplot(gs[2, 0]), res)
    fig.suptitle(Info(res, scene).title(title), fontsize=9)
    return finish(fig, path)


def _iterations_panel(ax, res):
    q = res["q"] / float(res["a_H"])
    it = np.asarray(res["iterations"])
    ax.step(q[1:], it[1:], where="mid", lw=1.0, color="0.2", label="iterations (outer for N–T)")
    if np.any(res["inner_normal"][1:]) or np.any(res["inner_tangential"][1:]):
        ax.step(q[1:], res["inner_normal"][1:], where="mid", lw=0.8, color="C1", label="inner: normal")
        ax.step(q[1:], res["inner_tangential"][1:], where="mid", lw=0.8, color="C2", label="inner: tangential")
    ax.set(xlabel=LABELS["q"], ylabel="per step", title=f"solver iterations (step 0: {int(it[0])})")
    ax.grid(alpha=0.3)
    legend_below(ax)


def comparison_figure(results: dict, scene=None, path=None, at=None, n: int = 4, title: str | None = None):
    """Several results of one problem overlaid: p/p0 and t/(μp0) at several q, and the creepage.

    Parameters
    ----------
    results : dict
        Label → result arrays (same strip and steps, e.g. coupling "goodman" and "full").
    at, n :
        States to draw (:func:`select_states`, from the first result's q).
    """
    plt = pyplot()
    items = [(k, arrays(v)) for k, v in results.items()]
    first = items[0][1]
    info = Info(first, scene)
    a, p0, mu = info.a, info.p0, info.mu_scale
    idx = select_states(first["q"], a, at, n)
    styles = ["-", "--", "-.", ":"]
    fig, ax = plt.subplots(1, 3, figsize=(16, 5.8), constrained_layout=True)
    for j, (label, r) in enumerate(items):
        ls = styles[j % len(styles)]
        x = r["x"] / a
        for c, k in zip(colors(len(idx)), idx):
            if k >= len(r["q"]):
                continue
            lab = f"{label}, $q = {r['q'][k] / a:.2f}\\,a_H$"
            ax[0].plot(x, r["pn"][k] / p0, ls, color=c, lw=1.3, label=lab)
            ax[1].plot(x, r["pt"][k] / (mu * p0), ls, color=c, lw=1.3, label=lab)
        xi = np.asarray(r["creepage"], dtype=float) * info.R / a
        ax[2].plot(r["q"][1:] / a, xi[1:], ls, color="C0", lw=1.3, label=label)
    if info.kappa != 0 and abs(info.kappa) <= 1 and all(_free_rolling(r) for _, r in items):
        bj = cf.bentall_johnson_creepage(info.kappa, a, info.R) * np.sign(info.kappa) * info.direction
        ax[2].axhline(bj * info.R / a, **REFERENCES["bentall"])
    x0, x1 = contact_span(first, a)
    ax[0].set(xlabel=LABELS["x"], ylabel=LABELS["p"], title="contact pressure", xlim=(x0, x1))
    ax[1].set(xlabel=LABELS["x"], ylabel=LABELS["t"], title="tangential traction on body A", xlim=(x0, x1))
    ax[2].set(xlabel=LABELS["q"], ylabel=LABELS["xi"], title="creepage")
    for axis in ax:
        axis.grid(alpha=0.3)
        legend_below(axis, ncol=2, fontsize=6)
    fig.suptitle(title or f"{info.name}: " + " vs ".join(k for k, _ in items), fontsize=9)
    return finish(fig, path)
