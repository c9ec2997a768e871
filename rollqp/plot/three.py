"""Three-dimensional scenes (Kalker's problem): the traction field over the contact ellipse.

:func:`three_figure` is what ``rollqp run --plot`` draws for a scene with ``[contact] dimension = 3``
(``kalker-circular``, ``kalker-elliptic``, ``cattaneo-3d``), the classic Kalker/CONTACT picture of
the final state beside its pressure and, for a run with rolling steps, its creep force:

1. the tangential traction vectors over the grid (every element, or every second one on large grids),
   black where the element sticks (the grey area) and red where it slips (``t = −μp s/|s|``), with
   the Hertz ellipse and contours of ``p/p0``;
2. the pressure ``p/p0`` along the two axes of the ellipse against Hertz's;
3. a run with rolling steps: the creep forces ``Fx/(μFN)``, ``Fy/(μFN)`` and the creepages against
   the rolled distance ``q/a``; a steady state alone: the traction along the centre line ``y = 0``
   with the traction bound ``μp``.
"""
from __future__ import annotations

import numpy as np

from .style import REFERENCES, arrays, finish, legend_below, meta, pyplot, scene_of

__all__ = ["three_figure"]

#: Largest number of arrows drawn along one axis (beyond, every second or third element).
ARROWS = 32


def _field_panel(ax, res, e, mu, k):
    x, y = res["x"] / e.a, res["y"] / e.a
    X, Y = np.meshgrid(x, y)
    state = res["state"][k]
    ax.pcolormesh(x, y, np.where(state == 1, 1.0, np.nan), cmap="Greys", vmin=0, vmax=2.5, shading="nearest")
    cs = ax.contour(X, Y, res["pn"][k] / e.p0, levels=[0.2, 0.4, 0.6, 0.8], colors="tab:blue", linewidths=0.6)
    ax.clabel(cs, fontsize=7, fmt="%.1f")
    th = np.linspace(0, 2 * np.pi, 200)
    ax.plot(np.cos(th), e.b / e.a * np.sin(th), "k-", lw=0.8)
    step = max(1, int(np.ceil(max(x.size, y.size) / ARROWS)))
    sl = (slice(None, None, step), slice(None, None, step))
    q = (mu or 1.0) * e.p0
    tx, ty, st = res["px"][k][sl] / q, res["py"][k][sl] / q, state[sl]
    big = float(np.max(np.hypot(tx, ty), initial=0.0))
    spacing = step * float(min(np.diff(x[:2])[0] if x.size > 1 else 1, np.diff(y[:2])[0] if y.size > 1 else 1))
    scale = big / (0.9 * spacing) if big > 0 else 1.0      # the longest arrow spans 0.9 of the arrows' spacing
    arrows = None
    for which, color, label in ((2, "tab:red", "slip: $t = -\\mu p\\, s/|s|$"), (1, "k", "stick (grey area)")):
        m = st == which
        if m.any():
            arrows = ax.quiver(X[sl][m], Y[sl][m], tx[m], ty[m], color=color, angles="xy", scale_units="xy",
                               scale=scale, width=0.004, label=label)
    if arrows is not None and big > 0:
        ax.quiverkey(arrows, 0.72, 0.04, big, f"{big:.3g} $\\mu p_0$", labelpos="E", coordinates="axes",
                     fontproperties={"size": 7})
    ax.set_aspect("equal")
    ax.set(xlabel="$x/a$", ylabel="$y/a$", title="tangential traction $t/(\\mu p_0)$, state "
                                                  f"{k} (q = {float(res['q'][k]) / e.a:.3g} a)")
    legend_below(ax, ncol=2)


def _pressure_panel(ax, res, e):
    j0, i0 = int(np.argmin(np.abs(res["y"]))), int(np.argmin(np.abs(res["x"])))
    s = np.linspace(-1, 1, 201)
    ax.plot(res["x"] / e.a, res["pn"][0][j0] / e.p0, "o", ms=3.5, color="tab:blue", label="$p/p_0$ along x (y = 0)")
    ax.plot(res["y"] / e.b, res["pn"][0][:, i0] / e.p0, "s", ms=6, mfc="none", color="tab:green",
            label="$p/p_0$ along y (x = 0), against $y/b$")
    ax.plot(s, np.sqrt(1 - s * s), **REFERENCES["hertz"])
    ax.set(xlabel="$x/a$, $y/b$", ylabel="$p/p_0$", title="pressure, state 0, against Hertz")
    legend_below(ax, ncol=1)


def _history_panel(ax, res, e, mu, FN, braked):
    q = np.asarray(res["q"], dtype=float) / e.a
    ax.plot(q, res["Fx"] / (mu * FN), "-o", ms=2.5, color="tab:blue", label="$F_x/(\\mu F_N)$")
    ax.plot(q, res["Fy"] / (mu * FN), "-s", ms=2.5, color="tab:orange", label="$F_y/(\\mu F_N)$")
    ax.set(xlabel="$q/a$", ylabel="creep force $/(\\mu F_N)$", title="creep forces on body A"
           + ("\n(creepages from the first rolling step: state 0 is a static shift)" if braked else ""))
    ax2 = ax.twinx()
    su = e.p0 / e.Estar
    k = 1 if braked else 0
    ax2.plot(q[k:], res["creepage"][k:, 0] / su, ":", color="tab:blue", label="$\\xi E^*/p_0$")
    ax2.plot(q[k:], res["creepage"][k:, 1] / su, ":", color="tab:orange", label="$\\eta E^*/p_0$")
    ax2.set_ylabel("creepage $/(p_0/E^*)$", fontsize=8)
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    legend_below(ax, ncol=2, handles=h1 + h2, labels=l1 + l2)


def _centre_line_panel(ax, res, e, mu):
    j0 = int(np.argmin(np.abs(res["y"])))
    x = res["x"] / e.a
    q = (mu or 1.0) * e.p0
    st = res["state"][-1][j0]
    tx, ty = res["px"][-1][j0] / q, res["py"][-1][j0] / q
    big = float(np.max(np.abs(np.concatenate([tx, ty])), initial=0.0))
    bound = res["pn"][-1][j0] / e.p0
    if big > 0.2:   # the bound μp on the traction's scale; far below it, the bound would flatten the traction
        ax.plot(x, bound, "--", color="0.5", lw=1, label="bound $\\mu p/(\\mu p_0)$")
    else:
        ax.text(0.02, 0.95, f"the bound $\\mu p$ reaches 1 $\\mu p_0$: off this scale (|t| <= {big:.2g} $\\mu p_0$)",
                transform=ax.transAxes, fontsize=7, va="top")
    for which, color, label in ((1, "k", "$t_x$, stick"), (2, "tab:red", "$t_x$, slip")):
        m = st == which
        ax.plot(x[m], tx[m], "o", ms=3, color=color, label=label)
    ax.plot(x, ty, "-", color="tab:orange", lw=1, label="$t_y$")
    ax.set(xlabel="$x/a$", ylabel="$t/(\\mu p_0)$", title="traction along y = 0 (final state)")
    legend_below(ax, ncol=2)


def three_figure(res, scene=None, path: str | None = None, title: str | None = None):
    """The 3D run's figure (module docstring): the final state's traction field, the pressure, and the
    creep forces (a run with rolling steps) or the centre-line traction (a steady state alone)."""
    plt = pyplot()
    res = arrays(res)
    scene = scene_of(res, scene)
    e, mu, FN = scene.ellipse, scene.mu, scene.load.normal
    K = len(res["q"]) - 1
    fig, ax = plt.subplots(1, 3, figsize=(16, 5.8), constrained_layout=True,
                           gridspec_kw={"width_ratios": [1.25, 1, 1]})
    _field_panel(ax[0], res, e, mu, K)
    _pressure_panel(ax[1], res, e)
    if K > 0:
        _history_panel(ax[2], res, e, mu, FN, scene.load.start == "braked")
    else:
        _centre_line_panel(ax[2], res, e, mu)
    xi, eta, phi = (float(v) for v in res["creepage"][-1])
    method = meta(res).get("method", "")
    fig.suptitle(title or (f"{scene.name}: {scene.description}\n[a/b = {e.a / e.b:.3g}, mu = {mu:g}, "
                           f"xi = {xi:.3g}, eta = {eta:.3g}, phi = {phi:.3g}, Fx = {float(res['Fx'][-1]) / ((mu or 1.0) * FN):.3f} "
                           f"mu FN, Fy = {float(res['Fy'][-1]) / ((mu or 1.0) * FN):.3f} mu FN" + (f", {method}]" if method else "]")),
                 fontsize=9)
    return finish(fig, path)
