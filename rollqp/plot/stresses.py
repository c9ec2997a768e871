"""Figures of the subsurface stresses (docs/stresses.md): contour maps under the contact with the surface tractions
above them, of a strip's state (:func:`plot_field`, :mod:`rollqp.subsurface`) and of a grid's section or line
(:func:`plot_field3d`, :mod:`rollqp.subsurface3d`)."""
from __future__ import annotations

import numpy as np

from ..subsurface3d import COMPONENTS
from .style import pyplot

__all__ = ["plot_field", "plot_field3d"]


def plot_field(sf, arrays: dict, path, p0: float, a: float) -> str:
    """Contour maps of von Mises and τ1 (units of p0, lengths in a_H) under the contact, with the
    surface tractions and the stick/slip zones of the state above them (Johnson's Fig. 7.5 style); ``sf`` a
    :class:`~rollqp.subsurface.StressField`."""
    plt = pyplot()
    x, k = np.asarray(arrays["x"]) / a, sf.step
    fig, axes = plt.subplots(2, 2, figsize=(11, 6.5), sharex="col",
                             gridspec_kw=dict(height_ratios=(1, 3)), constrained_layout=True)
    colors = {0: "0.8", 1: "tab:blue", 2: "tab:red"}
    for col, name in enumerate(("von_mises", "tau1")):
        top, ax = axes[0, col], axes[1, col]
        top.plot(x, arrays["pn"][k] / p0, "k-", lw=1, label="p/p0")
        top.plot(x, arrays["pt"][k] / p0, "k--", lw=1, label="t/p0")
        for state, label in ((1, "stick"), (2, "slip")):
            m = np.asarray(arrays["state"][k]) == state
            top.plot(x[m], np.zeros(m.sum()), "s", ms=3, color=colors[state], label=label)
        top.legend(fontsize=7, ncol=4, loc="upper left")
        top.set_ylabel("surface")
        cs = ax.contourf(sf.x / a, sf.z / a, sf.values[name] / p0, levels=20, cmap="viridis")
        ax.contour(sf.x / a, sf.z / a, sf.values[name] / p0, levels=10, colors="w", linewidths=0.4)
        v, xm, zm = sf.maxima[name]
        ax.plot([xm / a], [zm / a], "r+", ms=10, mew=2)
        ax.set_title(f"{'von Mises' if name == 'von_mises' else 'τ1'} / p0 (body {sf.body}, state {k}): "
                     f"max {v / p0:.3f} at x = {xm / a:.3f} a_H, z = {zm / a:.3f} a_H", fontsize=9)
        ax.invert_yaxis()
        ax.set_xlabel("x / a_H")
        ax.set_ylabel("depth z / a_H")
        fig.colorbar(cs, ax=ax)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return str(path)


def plot_field3d(sf, arrays: dict, path, p0: float) -> str:
    """Contour maps of von Mises and Tresca (in p0) on the section's plane, with the surface tractions of
    the grid row (or column) under it above; on a line, every component against depth; ``sf`` a
    :class:`~rollqp.subsurface3d.StressField3D`."""
    plt = pyplot()
    sec, k = sf.section, sf.step
    if sec.kind == "line":
        fig, ax = plt.subplots(figsize=(6.5, 5), constrained_layout=True)
        for name in COMPONENTS + ("von_mises",):
            ax.plot(sf.values[name][:, 0] / p0, sec.z, "-" if name != "von_mises" else "k-", lw=1.2, label=name)
        ax.invert_yaxis()
        ax.set_xlabel("stress / p0 (tension positive)")
        ax.set_ylabel("depth z")
        ax.set_title(f"body {sf.body}, state {k}: {sec.label}", fontsize=9)
        ax.legend(fontsize=8)
        fig.savefig(path, dpi=110)
        plt.close(fig)
        return str(path)
    x, y = (np.asarray(arrays[c], dtype=float) for c in ("x", "y"))
    if sec.kind == "y":
        row = int(np.argmin(np.abs(y - sec.value[0])))
        h, cut = x, (lambda f: np.asarray(f)[k][row, :])
    else:
        col = int(np.argmin(np.abs(x - sec.value[0])))
        h, cut = y, (lambda f: np.asarray(f)[k][:, col])
    fig, axes = plt.subplots(2, 2, figsize=(11, 6.5), sharex="col", gridspec_kw=dict(height_ratios=(1, 3)),
                             constrained_layout=True)
    for col, name in enumerate(("von_mises", "tresca")):
        top, ax = axes[0, col], axes[1, col]
        for key, style in (("pn", "k-"), ("px", "k--"), ("py", "k:")):
            top.step(h, cut(arrays[key]) / p0, style, where="mid", lw=1, label=f"{key}/p0")
        top.legend(fontsize=7, ncol=3, loc="upper left")
        top.set_ylabel("surface")
        v = sf.values[name] / p0
        cs = ax.contourf(sec.along, sec.z, v, levels=20, cmap="viridis")
        ax.contour(sec.along, sec.z, v, levels=10, colors="w", linewidths=0.4)
        m = sf.maxima[name]
        ax.plot([m[1] if sec.kind == "y" else m[2]], [m[3]], "r+", ms=10, mew=2)
        ax.set_title(f"{'von Mises' if name == 'von_mises' else 'Tresca'} / p0 (body {sf.body}, state {k}, "
                     f"{sec.label}): max {m[0] / p0:.3f} at depth {m[3]:.4g}", fontsize=9)
        ax.invert_yaxis()
        ax.set_xlabel("x" if sec.kind == "y" else "y")
        ax.set_ylabel("depth z")
        fig.colorbar(cs, ax=ax)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return str(path)


# =========================================================================== generated kernels
# Written by benchmarks/derive_subsurface3d.py (sympy): regenerate, do not edit. Arguments X = x − ξ,
# Y = y − η at a corner (ξ, η), the depth z > 0 and ν; returns the 18 kernels, for p, q_x, q_y in turn the
# six components of COMPONENTS (tension positive, per unit load).
