"""Figures of a transient. Needs the ``plot`` extra (matplotlib).

* :func:`transient_figure` — in the manner of the paper's Figs 4–5 (similar bodies):
  tangential traction and slip against x at several rolled distances, closed forms overlaid,
  and the creepage against q.
* :func:`snapshot_figure` — in the manner of the paper's Figs 6–9 (dissimilar bodies):
  pressure p/p0, traction t/(μp0) between its bounds ±μp/(μp0) = ±p/p0, slip and the node
  state (stick/slip/separation) against x/a_H at several rolled distances.
* :func:`zone_map_figure` — the node states of every stored step as an image over
  (q/a_H, x/a_H), with the Hertz half-width of the current load, and the creepage (and the
  load, where it varies) against q/a_H.
* :func:`dissimilar_figure` — both on one page: what ``rollqp run --plot`` draws for a
  scene with normal–tangential coupling (β ≠ 0 and coupling not "off").
* :func:`comparison_figure` — several results of one problem overlaid (e.g. coupling
  "goodman" against "full").
* :func:`plot_result` — the ``--plot`` dispatcher.

Every function takes the result's arrays (``Result.arrays()``, :func:`rollqp.load_result`,
or a :class:`~rollqp.result.Result`) and, optionally, the scene; without the scene, μ, κ,
the start and the direction are read from the result's ``meta``. With ``path`` the figure
is saved and closed and the path returned; without it the matplotlib figure is returned.
"""
from __future__ import annotations

import json

import numpy as np

from . import closedforms as cf
from .errors import MissingBackendError
from .scene import BETA_ZERO


def pyplot():
    """``matplotlib.pyplot`` with the non-interactive Agg backend; a one-line error naming the extra if absent."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise MissingBackendError("--plot needs matplotlib: pip install 'rollqp[plot]'") from exc
    return plt


def snapshot_indices(q, a, wanted=(0.0, 0.25, 0.5, 1.0, 2.0)):
    """Indices of the stored states nearest to ``wanted`` (in a_H), plus the last one."""
    qa = np.asarray(q) / a
    idx = sorted({int(np.argmin(np.abs(qa - w))) for w in wanted if w <= qa[-1]} | {len(qa) - 1})
    return idx


def transient_figure(res: dict, scene, path: str, title: str | None = None) -> str:
    """Save a three-panel figure: t/(μp0), slip and creepage against q, closed forms overlaid.

    Slip and creepage are drawn as ``s·R/a_H`` and ``ξ·R/a_H`` in every figure of this module
    (geometric scaling, the same for any μ). The braked starting state (a static shift, not a
    rolling state) is left off the slip panel and out of the creepage panel's y-range.
    """
    plt = pyplot()
    x, a, p0 = res["x"], float(res["a_H"]), float(res["p0"])
    mu = scene.contact.mu or 1.0
    braked = scene.load.start == "braked"
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.6), constrained_layout=True)
    # a load path (load.rolled, rollqp.kinematics): states against the time-like τ, Carter in the last direction
    clock, tname = (res["time"], "tau") if "time" in res else (res["q"], "q")
    d = res["direction"][res["direction"] != 0] if "direction" in res else np.zeros(0)
    direction = int(d[-1]) if d.size else scene.load.direction
    idx = snapshot_indices(clock, a)
    for c, k in zip(_colors(plt, len(idx)), idx):
        lab = f"{tname} = {clock[k] / a:.2f} a_H"
        ax[0].plot(x / a, res["pt"][k] / (mu * p0), "-", color=c, lw=1.4, label=lab)
        if not (k == 0 and braked):
            slip = np.where(res["state"][k] == 0, np.nan, res["slip"][k])  # no slip where separated
            ax[1].plot(x / a, slip * scene.R / a, "-", color=c, lw=1.2, label=lab)
    ax[0].plot(x / a, res["pn"][0] / p0, ":", color="0.5", lw=1, label="p/p0 (q = 0)")
    ax[2].plot(clock / a, res["creepage"] * scene.R / a, "-", lw=1.2, label="rollqp")
    xf = np.linspace(-1, 1, 801) * a
    closed = scene.coupling_level == "off" and scene.load.tangential is not None and scene.contact.friction.kind == "constant" and scene.contact.mu > 0
    marks = []
    if closed:
        P0, Q0 = float(res["P"][0]), float(res["Q"][0])
        if braked and abs(Q0) < mu * P0:
            ax[0].plot(xf / a, cf.cattaneo_traction(xf, a, p0, mu, Q0 / (mu * P0)) / (mu * p0), "k--", lw=0.9,
                       label="Cattaneo")
        r1 = float(res["Q"][-1]) / (mu * float(res["P"][-1]))
        if abs(r1) < 1:
            ax[0].plot(xf / a, cf.carter_traction(xf, a, p0, mu, r1, direction) / (mu * p0), "k-.", lw=0.9,
                       label="Carter")
            ax[1].plot(xf / a, cf.carter_slip(xf, a, scene.R, mu, r1, direction) * scene.R / a, "k-.", lw=0.9,
                       label="Carter (steady)")
            marks.append(cf.carter_creepage(a, scene.R, mu, r1) * scene.R / a)
            ax[2].axhline(marks[-1], color="k", ls="-.", lw=0.9, label="Carter (steady)")
    _creepage_limits(ax[2], res["creepage"] * scene.R / a, skip_first=braked, marks=marks)
    ax[0].set(xlabel="x / a_H", ylabel="t / (mu p0)", title="tangential traction on body A")
    note = " (q = 0 braked: no rolling slip)" if braked else ""
    ax[1].set(xlabel="x / a_H", ylabel="s R / a_H", title="slip per unit rolled distance" + note)
    ax[2].set(xlabel=f"{tname} / a_H", ylabel="xi R / a_H", title="creepage")
    for axis in ax:
        axis.grid(alpha=0.3)
        axis.legend(fontsize=7, loc="best")
    fig.suptitle(title or f"{scene.name}: {scene.description}", fontsize=10)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _creepage_limits(ax, values, skip_first: bool, marks=()) -> None:
    """y-range of a creepage panel from the rolling states (and the lines already drawn).

    A braked start's state 0 is a static shift whose "creepage" is the rigid shift per unit
    length, often far outside the rolling range: it is left off the range and, when off scale,
    named in a note in the panel. ``marks``: the closed-form levels drawn, kept in range.
    """
    v = np.asarray(values, dtype=float)
    rolling = v[1:] if skip_first and v.size > 1 else v
    pool = np.concatenate([rolling[np.isfinite(rolling)], np.asarray(marks, dtype=float).ravel()])
    if pool.size == 0:
        return
    lo, hi = float(pool.min()), float(pool.max())
    pad = 0.08 * (hi - lo) if hi > lo else 0.1 * max(abs(hi), 1e-12)
    ax.set_ylim(lo - pad, hi + pad)
    if skip_first and v.size > 1 and not (lo - pad <= v[0] <= hi + pad):
        ax.text(0.01, 0.02, f"q = 0 (braked, static shift): {v[0]:.3g}, off scale", transform=ax.transAxes,
                fontsize=7, color="0.3", va="bottom")


#: ``|Q|/P`` below which a state counts as free rolling: the load condition ∫t = Q is met to the
#: solver tolerance (nondimensional residual 1e-10), so a prescribed Q = 0 is stored as ~1e-15 P;
#: 1e-8 leaves room and is far below any applied traction.
FREE_ROLLING_RATIO = 1e-8


def _free_rolling(res) -> bool:
    """True if no tangential load acts at any step (the Bentall–Johnson μ → 0 limit applies)."""
    scale = np.maximum(np.abs(np.asarray(res["P"], dtype=float)), 1e-300)
    return bool(np.all(np.abs(np.asarray(res["Q"], dtype=float)) <= FREE_ROLLING_RATIO * scale))


# =========================================================================== dissimilar bodies
#: Node states (``Result`` key ``state``) and how they are drawn.
STATE_NAMES = {0: "separation", 1: "stick", 2: "slip"}
STATE_COLORS = {0: "#d9d9d9", 1: "#2c7bb6", 2: "#d7191c"}


def _arrays(res) -> dict:
    """The result's arrays from ``Result``, ``Result.arrays()`` or :func:`load_result`."""
    return res.arrays() if hasattr(res, "arrays") and callable(res.arrays) else res


def _meta(res) -> dict:
    meta = res.get("meta", {})
    if isinstance(meta, dict):
        return meta
    try:
        return json.loads(str(meta))
    except ValueError:  # pragma: no cover - a result file always has JSON meta
        return {}


class _Info:
    """What the figures need of the scene: from the scene if given, else from ``meta``."""

    def __init__(self, res: dict, scene=None):
        meta = _meta(res)
        sd = meta.get("scene", {})
        if scene is not None:
            self.mu = float(scene.contact.mu)
            self.name, self.description = scene.name, scene.description
            self.start, self.direction = scene.load.start, int(scene.load.direction)
            self.normal = float(scene.load.normal)
            self.coupling = scene.coupling_level
        else:
            fr = sd.get("contact", {}).get("friction", 1.0)
            self.mu = float(fr) if not isinstance(fr, dict) else float(fr.get("mu", fr.get("static", max(fr.get("values", [1.0])))))
            self.name, self.description = sd.get("name", "result"), sd.get("description", "")
            self.start = sd.get("load", {}).get("start", "braked")
            self.direction = int(sd.get("load", {}).get("direction", -int(res.get("leading_edge", 1))))
            self.normal = float(sd.get("load", {}).get("normal", res["P"][0]))
            self.coupling = meta.get("coupling", "?")
        self.method = meta.get("method", "")
        self.a = float(res["a_H"])
        self.p0 = float(res["p0"])
        self.R = float(res["R"])
        self.beta = float(res["beta"])
        self.kappa = 2.0 * self.beta
        self.mu_scale = self.mu if self.mu > 0 else 1.0
        # step 0 of a braked start carries static-shift slip, not rolling slip
        self.static_start = self.start == "braked"


#: :func:`select_states` default: a run has settled once no node's p/p0 or t/(μp0) changes
#: faster than this per a_H of rolling (node states flipping at a zone boundary of a coarse
#: mesh still move single values by ~0.1 per a_H; a transient by ~1–20).
SETTLED_RATE = 0.03


def settled_q(res, mu: float | None = None, rate: float = SETTLED_RATE) -> float | None:
    """The rolled distance q/a_H after which the tractions stop changing, or None.

    None if they still change at the end (e.g. a varying load) or the run is too short to
    tell (the last quarter of the run must be quiet).
    """
    res = _arrays(res)
    mu = _Info(res).mu_scale if mu is None else (mu if mu > 0 else 1.0)
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


def _colors(plt, m):
    """Snapshot colours from light (first state) to dark (last): the final state, usually the
    one read, gets viridis' darkest end rather than its near-invisible yellow."""
    return plt.cm.viridis(np.linspace(0.8, 0.0, max(m, 1)))


def _contact_span(res, a, pad=0.15):
    """x/a_H limits around every node ever in contact."""
    x = res["x"] / a
    on = np.any(res["state"] > 0, axis=0)
    if not on.any():
        return x[0], x[-1]
    lo, hi = x[on].min(), x[on].max()
    return max(x[0], lo - pad), min(x[-1], hi + pad)


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
    plt = pyplot()
    res = _arrays(res)
    info = _Info(res, scene)
    a, p0, mu = info.a, info.p0, info.mu_scale
    x = res["x"] / a
    idx = select_states(res["q"], a, at, n, settled=None if at is not None else settled_q(res, info.mu))
    colors = _colors(plt, len(idx))
    axp, axt, axs, axz = axes
    for row, (c, k) in enumerate(zip(colors, idx)):
        lab = f"q = {res['q'][k] / a:.2f} a_H"
        st = res["state"][k]
        p = res["pn"][k] / p0
        axp.plot(x, p, "-", color=c, lw=1.4, label=lab)
        axt.plot(x, res["pt"][k] / (mu * p0), "-", color=c, lw=1.4, label=lab)
        bound = np.where(st > 0, p, np.nan)
        axt.plot(x, bound, ":", color=c, lw=0.9)
        axt.plot(x, -bound, ":", color=c, lw=0.9)
        if not (k == 0 and info.static_start):
            slip = np.where(st == 0, np.nan, res["slip"][k])  # no slip where separated
            axs.plot(x, slip * info.R / a, "-", color=c, lw=1.2, label=lab)
        for code in (0, 1, 2):
            m = st == code
            if m.any():
                axz.scatter(x[m], np.full(m.sum(), row), s=14, marker="s", color=STATE_COLORS[code],
                            edgecolors="none")
        axz.text(1.01, row, lab.replace(" a_H", ""), transform=axz.get_yaxis_transform(), fontsize=7,
                 va="center", color=c)
    x0, x1 = _contact_span(res, a)
    for axis in axes:
        axis.set_xlim(x0, x1)
        axis.grid(alpha=0.3)
    axp.set(xlabel="x / a_H", ylabel="p / p0", title="contact pressure")
    axt.set(xlabel="x / a_H", ylabel="t / (mu p0)", title="tangential traction on body A (dotted: ±mu p)")
    note = " (q = 0 braked: no rolling slip)" if (0 in idx and info.static_start) else ""
    axs.set(xlabel="x / a_H", ylabel="s R / a_H", title="slip of A relative to B" + note)
    axz.set(xlabel="x / a_H", title="node state", ylim=(-0.6, len(idx) - 0.4))
    axz.set_yticks([])
    axz.invert_yaxis()
    from matplotlib.patches import Patch
    axz.legend(handles=[Patch(color=STATE_COLORS[c], label=STATE_NAMES[c]) for c in (1, 2, 0)],
               fontsize=7, loc="lower center", ncol=3, bbox_to_anchor=(0.5, -0.02))
    lead = -info.direction
    axz.annotate("material enters", xy=(x1 if lead > 0 else x0, len(idx) - 0.4), fontsize=7,
                 ha="right" if lead > 0 else "left", va="bottom", color="0.3")
    for axis in (axp, axt, axs):
        if axis.get_legend_handles_labels()[0]:
            axis.legend(fontsize=7, loc="best", framealpha=0.85)
    return idx


def draw_zone_map(ax, res, scene=None):
    """Draw the node states of every stored state over (q/a_H, x/a_H), Hertz edges overlaid."""
    pyplot()
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch
    res = _arrays(res)
    info = _Info(res, scene)
    a = info.a
    q, x = res["q"] / a, res["x"] / a
    qe = np.concatenate(([q[0] - 0.5 * (q[1] - q[0])] if q.size > 1 else [q[0] - 0.5],
                         0.5 * (q[1:] + q[:-1]),
                         [q[-1] + 0.5 * (q[-1] - q[-2])] if q.size > 1 else [q[0] + 0.5]))
    xe = np.concatenate(([x[0] - 0.5 * (x[1] - x[0])], 0.5 * (x[1:] + x[:-1]), [x[-1] + 0.5 * (x[-1] - x[-2])]))
    cmap = ListedColormap([STATE_COLORS[0], STATE_COLORS[1], STATE_COLORS[2]])
    norm = BoundaryNorm([-0.5, 0.5, 1.5, 2.5], 3)
    ax.pcolormesh(qe, xe, np.asarray(res["state"], dtype=float).T, cmap=cmap, norm=norm, shading="flat",
                  rasterized=True)
    half = np.sqrt(np.maximum(res["P"], 0.0) / info.normal)  # Hertz half-width a(P)/a_H
    ax.plot(q, half, "k--", lw=0.8)
    ax.plot(q, -half, "k--", lw=0.8)
    x0, x1 = _contact_span(res, a)
    ax.set(xlabel="q / a_H", ylabel="x / a_H", ylim=(x0, x1), xlim=(qe[0], qe[-1]),
           title="node states (dashed: Hertz half-width of P(q))")
    lead = -info.direction
    ax.text(0.99, 0.98 if lead > 0 else 0.02, "leading edge", transform=ax.transAxes, ha="right",
            va="top" if lead > 0 else "bottom", fontsize=7, color="0.2")
    # outside the axes: the image fills them, any legend inside would hide states
    ax.legend(handles=[Patch(color=STATE_COLORS[c], label=STATE_NAMES[c]) for c in (1, 2, 0)],
              fontsize=7, loc="upper left", bbox_to_anchor=(1.005, 1.0), borderaxespad=0.0)


def draw_history(ax, res, scene=None):
    """Creepage ξR/a_H against q/a_H, the Bentall–Johnson μ → 0 value, and the loads if they vary."""
    from . import closedforms as _cf
    res = _arrays(res)
    info = _Info(res, scene)
    a, R = info.a, info.R
    q = res["q"] / a
    ax.plot(q, res["creepage"] * R / a, "-", color="C0", lw=1.3, label="creepage xi R/a_H")
    marks = []
    if info.kappa != 0 and abs(info.kappa) <= 1 and _free_rolling(res):
        bj = _cf.bentall_johnson_creepage(info.kappa, a, R) * np.sign(info.kappa) * info.direction
        ax.axhline(bj * R / a, color="C0", ls="--", lw=0.9, label="Bentall-Johnson, mu -> 0")
        marks = [bj * R / a]
    elif info.kappa != 0:
        ax.text(0.01, 0.98, "Bentall-Johnson (free rolling) not drawn: Q != 0", transform=ax.transAxes,
                fontsize=7, color="0.3", va="top")
    _creepage_limits(ax, res["creepage"] * R / a, skip_first=info.static_start, marks=marks)
    ax.set(xlabel="q / a_H", ylabel="xi R / a_H", title="creepage and loads")
    ax.grid(alpha=0.3)
    P = res["P"] / info.normal
    Qr = res["Q"] / (info.mu_scale * info.normal)
    lines, labels = ax.get_legend_handles_labels()
    if np.ptp(P) > 1e-12 or np.ptp(Qr) > 1e-9:
        tw = ax.twinx()
        if np.ptp(P) > 1e-12:
            tw.plot(q, P, "-", color="C1", lw=1.0, label="P / P̄")
        if np.ptp(Qr) > 1e-9:
            tw.plot(q, Qr, "-", color="C2", lw=1.0, label="Q / (mu P̄)")
        tw.set_ylabel("load")
        l2, b2 = tw.get_legend_handles_labels()
        lines, labels = lines + l2, labels + b2
    ax.legend(lines, labels, fontsize=7, loc="best")


def _finish(fig, plt, path):
    if path is None:
        return fig
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _title(info, title):
    if title:
        return title
    extra = f"  [2beta = {info.kappa:.4g}, mu = {info.mu:g}, coupling {info.coupling}" + \
            (f", {info.method}]" if info.method else "]")
    import textwrap
    return "\n".join(textwrap.wrap(f"{info.name}: {info.description}{extra}", 170))


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
    res = _arrays(res)
    fig, ax = plt.subplots(2, 2, figsize=(13, 8.4), constrained_layout=True)
    draw_snapshots(ax.ravel(), res, scene, at=at, n=n)
    fig.suptitle(_title(_Info(res, scene), title), fontsize=9)
    return _finish(fig, plt, path)


def zone_map_figure(res, scene=None, path=None, title: str | None = None):
    """Node states over (q/a_H, x/a_H), and the creepage and loads against q/a_H."""
    plt = pyplot()
    res = _arrays(res)
    fig, ax = plt.subplots(2, 1, figsize=(11, 7.6), sharex=True, constrained_layout=True,
                           gridspec_kw={"height_ratios": [2.2, 1]})
    draw_zone_map(ax[0], res, scene)
    ax[0].set_xlabel("")
    draw_history(ax[1], res, scene)
    fig.suptitle(_title(_Info(res, scene), title), fontsize=9)
    return _finish(fig, plt, path)


def dissimilar_figure(res, scene=None, path=None, at=None, n: int = 5, title: str | None = None):
    """One page: the four snapshot panels, the zone map and the creepage/load history."""
    plt = pyplot()
    res = _arrays(res)
    fig = plt.figure(figsize=(16, 10.5), constrained_layout=True)
    gs = fig.add_gridspec(3, 3, height_ratios=[1, 1, 1])
    axes = [fig.add_subplot(gs[0, 0]), fig.add_subplot(gs[0, 1]), fig.add_subplot(gs[0, 2]),
            fig.add_subplot(gs[1, 0])]
    draw_snapshots(axes, res, scene, at=at, n=n)
    zm = fig.add_subplot(gs[1, 1:])
    draw_zone_map(zm, res, scene)
    hist = fig.add_subplot(gs[2, 1:], sharex=zm)
    draw_history(hist, res, scene)
    _iterations_panel(fig.add_subplot(gs[2, 0]), res)
    fig.suptitle(_title(_Info(res, scene), title), fontsize=9)
    return _finish(fig, plt, path)


def _iterations_panel(ax, res):
    q = res["q"] / float(res["a_H"])
    it = np.asarray(res["iterations"])
    ax.step(q[1:], it[1:], where="mid", lw=1.0, color="0.2", label="iterations (outer for N-T)")
    if np.any(res["inner_normal"][1:]) or np.any(res["inner_tangential"][1:]):
        ax.step(q[1:], res["inner_normal"][1:], where="mid", lw=0.8, color="C1", label="inner: normal")
        ax.step(q[1:], res["inner_tangential"][1:], where="mid", lw=0.8, color="C2", label="inner: tangential")
    ax.set(xlabel="q / a_H", ylabel="per step", title=f"solver iterations (step 0: {int(it[0])})")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)


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
    items = [(k, _arrays(v)) for k, v in results.items()]
    first = items[0][1]
    info = _Info(first, scene)
    a, p0, mu = info.a, info.p0, info.mu_scale
    idx = select_states(first["q"], a, at, n)
    colors = _colors(plt, len(idx))
    styles = ["-", "--", "-.", ":"]
    fig, ax = plt.subplots(1, 3, figsize=(16, 4.8), constrained_layout=True)
    for j, (label, r) in enumerate(items):
        ls = styles[j % len(styles)]
        x = r["x"] / a
        for c, k in zip(colors, idx):
            if k >= len(r["q"]):
                continue
            lab = f"{label}, q = {r['q'][k] / a:.2f} a_H"
            ax[0].plot(x, r["pn"][k] / p0, ls, color=c, lw=1.3, label=lab)
            ax[1].plot(x, r["pt"][k] / (mu * p0), ls, color=c, lw=1.3, label=lab)
        ax[2].plot(r["q"] / a, r["creepage"] * info.R / a, ls, color="C0", lw=1.3, label=label)
    marks = []
    if info.kappa != 0 and abs(info.kappa) <= 1 and all(_free_rolling(r) for _, r in items):
        bj = cf.bentall_johnson_creepage(info.kappa, a, info.R) * np.sign(info.kappa) * info.direction
        marks.append(bj * info.R / a)
        ax[2].axhline(marks[-1], color="k", ls=":", lw=0.9, label="Bentall-Johnson, mu -> 0")
    elif info.kappa != 0:
        ax[2].text(0.01, 0.98, "Bentall-Johnson (free rolling) not drawn: Q != 0", transform=ax[2].transAxes,
                   fontsize=7, color="0.3", va="top")
    _creepage_limits(ax[2], np.concatenate([r["creepage"][1:] for _, r in items]) * info.R / a, skip_first=False,
                     marks=marks)
    x0, x1 = _contact_span(first, a)
    ax[0].set(xlabel="x / a_H", ylabel="p / p0", title="contact pressure", xlim=(x0, x1))
    ax[1].set(xlabel="x / a_H", ylabel="t / (mu p0)", title="tangential traction on body A", xlim=(x0, x1))
    ax[2].set(xlabel="q / a_H", ylabel="xi R / a_H", title="creepage")
    for axis in ax:
        axis.grid(alpha=0.3)
        axis.legend(fontsize=6, loc="best")
    fig.suptitle(title or f"{info.name}: " + " vs ".join(k for k, _ in items), fontsize=9)
    return _finish(fig, plt, path)


def plot_result(res, scene, path, **kw) -> str:
    """The figure ``rollqp run --plot`` draws: :func:`dissimilar_figure` when the scene has
    normal–tangential coupling (β ≠ 0 and coupling not "off"), else :func:`transient_figure`."""
    res = _arrays(res)
    if scene.coupling_level != "off" and abs(scene.beta) > BETA_ZERO:
        return dissimilar_figure(res, scene, path, **kw)
    return transient_figure(res, scene, path, **kw)
