"""Figures in the manner of the paper's Figs 4–5: tangential traction and slip against x
at several rolled distances, closed forms overlaid. Needs the ``plot`` extra (matplotlib)."""
from __future__ import annotations

import numpy as np

from . import closedforms as cf
from .errors import MissingBackendError


def _plt():
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
    """Save a three-panel figure: t/(μp0), slip, and creepage against q."""
    plt = _plt()
    x, a, p0 = res["x"], float(res["a_H"]), float(res["p0"])
    mu = scene.contact.friction or 1.0
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.6), constrained_layout=True)
    idx = snapshot_indices(res["q"], a)
    colors = plt.cm.viridis(np.linspace(0, 0.9, len(idx)))
    for c, k in zip(colors, idx):
        lab = f"q = {res['q'][k] / a:.2f} a_H"
        ax[0].plot(x / a, res["pt"][k] / (mu * p0), "-", color=c, lw=1.4, label=lab)
        slip = np.where(res["state"][k] == 0, np.nan, res["slip"][k])  # no slip where separated
        ax[1].plot(x / a, slip * scene.R / (mu * a), "-", color=c, lw=1.2, label=lab)
    ax[0].plot(x / a, res["pn"][0] / p0, ":", color="0.5", lw=1, label="p/p0 (q = 0)")
    xf = np.linspace(-1, 1, 801) * a
    if scene.coupling_level == "off" and scene.load.tangential is not None and scene.contact.friction > 0:
        P0, Q0 = float(res["P"][0]), float(res["Q"][0])
        if scene.load.start == "braked" and abs(Q0) < mu * P0:
            ax[0].plot(xf / a, cf.cattaneo_traction(xf, a, p0, mu, Q0 / (mu * P0)) / (mu * p0), "k--", lw=0.9,
                       label="Cattaneo")
        r1 = float(res["Q"][-1]) / (mu * float(res["P"][-1]))
        if abs(r1) < 1:
            ax[0].plot(xf / a, cf.carter_traction(xf, a, p0, mu, r1, scene.load.direction) / (mu * p0), "k-.",
                       lw=0.9, label="Carter")
    ax[0].set(xlabel="x / a_H", ylabel="t / (mu p0)", title="tangential traction on body A")
    ax[1].set(xlabel="x / a_H", ylabel="s R / (mu a_H)", title="slip (per unit rolled distance)")
    ax[2].plot(res["q"] / a, res["creepage"] * scene.R / (mu * a), "-", lw=1.2, label="rollqp")
    if scene.coupling_level == "off" and scene.load.tangential is not None and scene.contact.friction > 0:
        r1 = float(res["Q"][-1]) / (mu * float(res["P"][-1]))
        if abs(r1) < 1:
            ax[2].axhline(cf.carter_creepage(a, scene.R, mu, r1) * scene.R / (mu * a), color="k", ls="-.", lw=0.9,
                          label="Carter (steady)")
    ax[2].set(xlabel="q / a_H", ylabel="xi R / (mu a_H)", title="creepage")
    for axis in ax:
        axis.grid(alpha=0.3)
        axis.legend(fontsize=7)
    fig.suptitle(title or f"{scene.name}: {scene.description}", fontsize=10)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
