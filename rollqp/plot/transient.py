"""Similar bodies rolling (paper Figs 4–5): traction, slip and creepage, Cattaneo and Carter overlaid.

:func:`transient_figure` is what ``rollqp run --plot`` draws for a scene without coupling,
profile or load path (``cattaneo-carter``, ``ramp``): the tangential traction and the slip
against x at several rolled distances, and the creepage against q with Carter's steady value
(and the tangential load, where it varies).
"""
from __future__ import annotations

import numpy as np

from .. import closedforms as cf
from .style import (LABELS, REFERENCES, Info, arrays, clock, colors, finish, legend_below, length_axis, pyplot,
                    reference, rolling_mask, stress_axis, symbol)


def snapshot_indices(q, a, wanted=(0.0, 0.25, 0.5, 1.0, 2.0)):
    """Indices of the stored states nearest to ``wanted`` (in a_H), plus the last one."""
    qa = np.asarray(q) / a
    idx = sorted({int(np.argmin(np.abs(qa - w))) for w in wanted if w <= qa[-1]} | {len(qa) - 1})
    return idx


def coulomb(scene):
    """The scene's constant friction coefficient, or None (frictionless, or a law μ(x, s): no closed form applies)."""
    return float(scene.contact.mu) if scene.contact.friction.kind == "constant" and scene.contact.mu > 0 else None


def transient_figure(res: dict, scene, path: str | None = None, title: str | None = None):
    """Three panels: t/(μp0) and sR/a_H against x/a_H at several q, and ξR/a_H against q.

    Closed forms in their own colours: Cattaneo at the braked start, Carter's traction, slip and
    creepage for the final load. The braked starting state (a static shift, not a rolling state)
    is left off the slip panel and out of the creepage curve (its value named in a note). Each
    panel has its dimensional scale (x in the scene's length unit, t in its stress unit).
    """
    plt = pyplot()
    res = arrays(res)
    info = Info(res, scene)
    a, p0, mu = info.a, info.p0, info.mu_scale
    x = res["x"] / a
    fig, ax = plt.subplots(1, 3, figsize=(15, 5.4), constrained_layout=True)
    tq, tname = clock(res, a)
    idx = snapshot_indices(tq * a, a)
    for c, k in zip(colors(len(idx)), idx):
        lab = f"${symbol(tname)} = {tq[k]:.2f}\\,a_H$"
        ax[0].plot(x, res["pt"][k] / (mu * p0), "-", color=c, lw=1.4, label=lab)
        if not (k == 0 and info.static_start):
            slip = np.where(res["state"][k] == 0, np.nan, res["slip"][k])  # no slip where separated
            ax[1].plot(x, slip * info.R / a, "-", color=c, lw=1.2, label=lab)
    ax[0].plot(x, res["pn"][0] / p0, ":", color="0.6", lw=1, label=r"$p/p_0$ (bound $\mu p$)")
    _closed_forms(ax, res, scene, info)
    _creepage_panel(ax[2], res, info, tq, tname)
    ax[0].set(xlabel=LABELS["x"], ylabel=LABELS["t"], title="tangential traction on body A")
    note = " (the braked start has no rolling slip)" if info.static_start else ""
    ax[1].set(xlabel=LABELS["x"], ylabel=LABELS["s"], title="slip per unit rolled distance" + note)
    for axis in ax[:2]:
        length_axis(axis, info)
    stress_axis(ax[0], info, per_mu=True)
    for axis in ax:
        axis.grid(alpha=0.3)
    legend_below(ax[0])
    legend_below(ax[1])
    fig.suptitle(info.title(title), fontsize=9)
    return finish(fig, path)


def _closed_forms(ax, res, scene, info):
    """Cattaneo (braked start) and Carter (final load: traction, slip, creepage) where they apply."""
    mu = coulomb(scene)
    if scene.coupling_level != "off" or scene.load.tangential is None or mu is None:
        return
    a, p0 = info.a, info.p0
    xf = np.linspace(-1, 1, 801) * a
    P0, Q0 = float(res["P"][0]), float(res["Q"][0])
    if info.static_start and 0 < abs(Q0) < mu * P0:
        reference(ax[0], xf / a, cf.cattaneo_traction(xf, a, p0, mu, Q0 / (mu * P0)) / (mu * p0), "cattaneo")
    r1 = float(res["Q"][-1]) / (mu * float(res["P"][-1]))
    d = res["direction"][res["direction"] != 0] if "direction" in res else np.zeros(0)
    direction = int(d[-1]) if d.size else info.direction
    if abs(r1) < 1:
        reference(ax[0], xf / a, cf.carter_traction(xf, a, p0, mu, r1, direction) / (mu * p0), "carter")
        reference(ax[1], xf / a, cf.carter_slip(xf, a, info.R, mu, r1, direction) * info.R / a, "carter")
        xi = cf.carter_creepage(a, info.R, mu, r1) * info.R / a
        ax[2].axhline(xi, **REFERENCES["carter"])


def _creepage_panel(ax, res, info, tq, tname):
    """ξR/a_H of the rolling states (a braked start and a stop are not rolling: no creepage drawn),
    with the tangential load on a second scale where it varies."""
    xi = np.asarray(res["creepage"], dtype=float) * info.R / info.a
    roll = rolling_mask(res, steady_start=info.start == "rolling")
    ax.plot(tq, np.where(roll, xi, np.nan), "-", color="C0", lw=1.3, label=r"rollqp, $\xi R/a_H$")
    if not roll[0] and xi[0] != 0:
        ax.text(0.01, 0.02, f"state 0 (static shift per $a_H$): {xi[0]:.3g}, not drawn",
                transform=ax.transAxes, fontsize=7, color="0.35", va="bottom")
    ax.set(xlabel=LABELS[tname], ylabel=LABELS["xi"], title="creepage")
    handles, labels = ax.get_legend_handles_labels()
    Qr = np.asarray(res["Q"], dtype=float) / (info.mu_scale * np.maximum(np.asarray(res["P"], dtype=float), 1e-300))
    if np.ptp(Qr) > 1e-9:
        tw = ax.twinx()
        handles += tw.plot(tq, Qr, "-", color="0.55", lw=1.0)
        labels.append(LABELS["Q"] + " (right scale)")
        tw.set_ylabel(LABELS["Q"], color="0.4")
    legend_below(ax, handles=handles, labels=labels)
