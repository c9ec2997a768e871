"""The paper's §6.1.1 example through the Python API: from Cattaneo to Carter.

Similar steel rollers braked at Q/(μP) = 0.75 (Cattaneo's traction), then rolling 6 a_H to
Carter's steady state. The built-in scene ``cattaneo-carter`` is run with :func:`rollqp.run`
and the result is held against the closed forms (rollqp.report.closed_form_errors): Hertz and
Cattaneo at q = 0, Carter's traction and creepage at the end. Between the two closed forms
the creepage overshoots its steady value and settles (the transient, measured here: its peak,
where it occurs, and from where it stays within 1 % of the steady creepage).

Run it::

    python examples/cattaneo_carter.py [METHOD] [--figure PATH] [--out RESULT.npz]

METHOD defaults to the scene's (qp-clarabel); ``--figure PATH`` draws the tractions, the slip
and the creepage over the transient (in the manner of the paper's Fig. 4).
"""
from __future__ import annotations

import argparse
import time

import numpy as np

import rollqp
from rollqp import closedforms as cf
from rollqp.report import closed_form_errors

#: Rolled distances (q/a_H) drawn in the figure.
SNAPSHOTS = (0.0, 0.25, 0.5, 1.0, 2.0, 6.0)


def transient(res, scene):
    """The creepage transient after the brake is released, relative to the last (steady) state."""
    a = float(res["a_H"])
    q, xi = res["q"][1:] / a, res["creepage"][1:]          # rolling states (state 0 is the braked one)
    rel = xi / xi[-1]
    k = int(np.argmax(rel))
    off = np.flatnonzero(np.abs(rel - 1) > 0.01)
    return {"peak": float(rel[k] - 1), "q_peak": float(q[k]),
            "q_within_1pc": float(q[off[-1] + 1]) if off.size else float(q[0])}


def figure(res, scene, path, title):
    """Tractions (with Cattaneo and Carter), slip and creepage over the transient."""
    from rollqp.plot import LABELS, REFERENCES, pyplot
    from rollqp.plot.style import legend_below, reference
    plt = pyplot()
    x, a, p0, R = res["x"], float(res["a_H"]), float(res["p0"]), float(res["R"])
    mu, d = scene.contact.friction, scene.load.direction
    ratio = float(res["Q"][-1]) / (mu * float(res["P"][-1]))
    q = res["q"] / a
    idx = [int(np.argmin(np.abs(q - w))) for w in SNAPSHOTS if w <= q[-1] + 1e-9]
    fig, ax = plt.subplots(1, 3, figsize=(16, 5.2), constrained_layout=True)
    colors = plt.cm.viridis(np.linspace(0.78, 0.0, len(idx)))
    xs = np.linspace(-1.25, 1.25, 1001)
    for color, k in zip(colors, idx):
        label = f"$q = {q[k]:.2f}\\,a_H$"
        ax[0].plot(x / a, res["pt"][k] / (mu * p0), "o-", ms=2.5, lw=0.8, color=color, label=label)
        if k > 0:  # state 0 carries the static shift's increment, not a rolling slip
            slip = np.where(res["state"][k] == 0, np.nan, res["slip"][k])
            ax[1].plot(x / a, slip * R / (mu * a), "-", lw=1.0, color=color, label=label)
    reference(ax[0], xs, cf.cattaneo_traction(xs, 1.0, 1.0, 1.0, ratio), "cattaneo")
    reference(ax[0], xs, cf.carter_traction(xs, 1.0, 1.0, 1.0, ratio, d), "carter")
    ax[0].set(xlabel=LABELS["x"], ylabel=LABELS["t"], title="traction on body A")
    ax[1].set(xlabel=LABELS["x"], ylabel=r"$s\,R/(\mu a_H)$", title="slip per unit rolled distance")
    xi_c = cf.carter_creepage(a, R, mu, ratio)
    ax[2].plot(q[1:], res["creepage"][1:] / xi_c, "-", lw=1.2, color="C0", label="rollqp")
    ax[2].axhline(1.0, **{**REFERENCES["carter"], "label": "Carter (steady)"})
    m = transient(res, scene)
    ax[2].annotate(f"peak {m['peak']:+.1%} at q = {m['q_peak']:.2f} a_H",
                   xy=(m["q_peak"], 1 + m["peak"] * res["creepage"][-1] / xi_c), xytext=(2.0, 1.1),
                   arrowprops={"arrowstyle": "->", "lw": 0.6}, fontsize=8)
    ax[2].set(xlabel=LABELS["q"], ylabel=r"$\xi/\xi_{Carter}$", title="creepage after the brake is released")
    for axis in ax:
        axis.grid(alpha=0.3)
        legend_below(axis)
    fig.suptitle(title)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(method=None, out=None, figure_path=None):
    scene = rollqp.load_scene("cattaneo-carter")
    t0 = time.perf_counter()
    result = rollqp.run(scene, method=method)
    wall = time.perf_counter() - t0
    res = result.arrays()
    name = method or scene.solver.method
    print(f"{scene.name}: {scene.description}")
    print(f"  {name}, {len(res['q']) - 1} rolling steps + starting state in {wall:.2f} s, "
          f"max residual {res['residual'].max():.1e}")
    errors = {}
    for key, value, what in closed_form_errors(res, scene):
        errors[key] = value
        print(f"  error {key:<10} {value:.4f}   {what}")
    trans = transient(res, scene)
    print(f"  transient: creepage peak {trans['peak']:+.2%} of the steady value at q = {trans['q_peak']:.3f} a_H, "
          f"within 1 % of it from q = {trans['q_within_1pc']:.3f} a_H")
    if out:
        result.save(out)
        print(f"  result written to {out}")
    if figure_path:
        title = f"§6.1.1: from Cattaneo to Carter, Q/(mu P) = 0.75, mu = 0.1, 40 QCE, {name}"
        print(f"  figure {figure(res, scene, figure_path, title)}")
    return {"errors": errors, "transient": trans, "result": res, "scene": scene, "method": name}


def _args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("method", nargs="?", default=None, help="step method (default: the scene's, qp-clarabel)")
    ap.add_argument("--figure", metavar="PATH", help="write the figure (PNG) here")
    ap.add_argument("--out", metavar="RESULT", help="write the result file (.npz) here")
    return ap.parse_args(argv)


if __name__ == "__main__":
    _a = _args()
    results = main(_a.method, out=_a.out, figure_path=_a.figure)
