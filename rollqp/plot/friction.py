"""A friction law (docs/friction.md): what ``rollqp run --plot`` draws for a scene whose μ is not one number.

:func:`friction_figure`: the traction against x at several rolled distances within its own bound
±μ(x)p (dotted, not the reference μ's), the coefficient μ(x) the law gives at the nodes of those
states (result field ``friction_coefficient``) with the law's levels, the slip, and the creepage
with the load. The traction is scaled by the law's reference coefficient μ_ref (``load.tangential``
is ``Q/(μ_ref P̄)``: docs/scenes.md).
"""
from __future__ import annotations

import numpy as np

from .style import LABELS, Info, arrays, colors, finish, legend_below, length_axis, pyplot, stress_axis
from .transient import _creepage_panel, snapshot_indices

#: Attributes of a law drawn as levels in the μ(x) panel, with their labels.
LEVELS = {"static": r"$\mu_s$ (static)", "kinetic": r"$\mu_k$ (kinetic)", "mu": r"$\mu$ outside the patch",
          "inside": r"$\mu$ inside the patch"}


def friction_figure(res, scene, path=None, title: str | None = None):
    """Traction within ±μ(x)p, the local μ(x), slip and creepage of a scene with a friction law."""
    plt = pyplot()
    res = arrays(res)
    info = Info(res, scene)
    a, p0, mu = info.a, info.p0, info.mu_scale
    x = res["x"] / a
    tq = np.asarray(res["q"], dtype=float) / a
    idx = snapshot_indices(res["q"], a)
    local = np.asarray(res["friction_coefficient"], dtype=float) if "friction_coefficient" in res else None
    fig, ax = plt.subplots(2, 2, figsize=(14, 10), constrained_layout=True)
    for c, k in zip(colors(len(idx)), idx):
        lab = f"$q = {tq[k]:.2f}\\,a_H$"
        on = res["state"][k] > 0
        ax[0, 0].plot(x, res["pt"][k] / (mu * p0), "-", color=c, lw=1.4, label=lab)
        if local is not None:
            bound = np.where(on, local[k] * res["pn"][k] / (mu * p0), np.nan)
            ax[0, 0].plot(x, bound, ":", color=c, lw=0.9)
            ax[0, 0].plot(x, -bound, ":", color=c, lw=0.9)
            ax[0, 1].plot(x, np.where(on, local[k], np.nan), "-", color=c, lw=1.4, label=lab)
        if not (k == 0 and info.static_start):
            ax[1, 0].plot(x, np.where(on, res["slip"][k], np.nan) * info.R / a, "-", color=c, lw=1.2, label=lab)
    _levels(ax[0, 1], scene)
    ax[0, 0].set(xlabel=LABELS["x"], ylabel=r"$t/(\mu_{ref}\, p_0)$",
                 title=r"tangential traction on body A (dotted: its bound $\pm\mu(x)\,p$)")
    ax[0, 1].set(xlabel=LABELS["x"], ylabel=r"$\mu(x)$", title="the coefficient the law gives at the nodes in contact")
    ax[1, 0].set(xlabel=LABELS["x"], ylabel=LABELS["s"], title="slip per unit rolled distance")
    for axis in (ax[0, 0], ax[0, 1], ax[1, 0]):
        axis.grid(alpha=0.3)
        length_axis(axis, info)
        legend_below(axis)
    stress_axis(ax[0, 0], info, per_mu=True)
    _creepage_panel(ax[1, 1], res, info, tq, "q")
    ax[1, 1].grid(alpha=0.3)
    law = getattr(scene.contact.friction, "law", type(scene.contact.friction).__name__)
    fig.suptitle(info.title(title, extra=f"  [friction law {law!s}, μ_ref = {mu:g}]"), fontsize=9)
    return finish(fig, path)


def _levels(ax, scene):
    """The law's own levels (static, kinetic, patch values) as horizontal lines, where it has them."""
    law = scene.contact.friction
    for (attr, label), color in zip(LEVELS.items(), ("#d62728", "#ff7f0e", "#8c564b", "#e377c2")):
        v = getattr(law, attr, None)
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            ax.axhline(float(v), color=color, ls="--", lw=1.0, label=label)
