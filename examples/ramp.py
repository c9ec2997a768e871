"""The paper's §6.1.2 example: the tangential load ramped while rolling.

The rollers of §6.1.1 (similar steel, μ = 0.1, 40 QCE, Δq = Le/2) start stopped with Q = 0;
Q/(μP) is then ramped linearly from 0 to 0.75 while they roll q/a_H = 8/3, and held there to
q = 6 a_H (built-in scene ``ramp``). The final loads are those of §6.1.1, so the final state must
be the same Carter state although the history is different (the paper: "logically, the final
steady state coincides with that obtained in the previous example"). The example runs both
scenes and measures

* the end state against Carter's closed forms (traction and creepage) and against the end
  state of §6.1.1 (``cattaneo-carter``);
* what the creepage means *during* the ramp. With P and Q prescribed, the 2D half-space
  displacements carry an arbitrary rigid constant (the reference distance d_ref of the log
  kernel, docs/formulation.md §3): changing d_ref → d' adds c·Q, c = (2/(πE*))·ln(d'/d), to the
  rigid tangential displacement, which a growing Q turns into an extra rigid slip that the
  creepage absorbs, Δξ = −c·dQ/dq. The tractions do not change. The example runs the ramp
  again with d_ref = 10 R and checks both statements; so, while the load changes, the 2D
  creepage is not a model-independent number, and only the end state is compared with Carter.

Run it::

    python examples/ramp.py [METHOD] [--figure PATH]

METHOD defaults to newton; ``--figure PATH`` draws the tractions (the paper's Fig. 5) and the
creepage of both histories.
"""
from __future__ import annotations

import argparse

import numpy as np

import rollqp
from rollqp import closedforms as cf
from rollqp.problem import STICK
from rollqp.report import closed_form_errors

#: Rolled distances (q/a_H) drawn: the first step (the paper's first curve is at q/a_H = 1/30;
#: here Δq = a_H/32), during the ramp, its end (8/3), and the end of the run.
SNAPSHOTS = (1 / 32, 0.5, 1.0, 2.0, 8 / 3, 6.0)


#: The second reference distance, in units of the default d_ref = R.
DREF_FACTOR = 10.0


def rigid_creepage_shift(scene, factor=DREF_FACTOR):
    """Δξ = −c·dQ/dq during the ramp when d_ref is multiplied by ``factor`` (module docstring)."""
    c = 2.0 / (np.pi * scene.Estar) * np.log(factor)
    hist = scene.load.tangential
    rate = (hist.end - hist.start) * scene.contact.friction * scene.load.normal / (hist.over * scene.a_H)
    return -c * rate


def measure(ramp, ramp_scene, ref, ref_scene, other):
    """End state against Carter and §6.1.1; the d_ref dependence of the creepage during the ramp."""
    a, p0, mu = float(ramp["a_H"]), float(ramp["p0"]), ramp_scene.contact.friction
    q = ramp["q"] / a
    errors = dict((k, v) for k, v, _ in closed_form_errors(ramp, ramp_scene))
    over = ramp_scene.load.tangential.over
    dq = ramp_scene.dq / ramp_scene.a_H
    # steps wholly inside the ramp, and wholly after it (the step across q = 8/3 is neither)
    during, after = (q > 0) & (q <= over + 1e-9), q - dq >= over - 1e-9
    dxi = other["creepage"] - ramp["creepage"]
    return {
        "carter": errors["carter"],
        "creepage": errors["creepage"],
        "start_t": float(np.abs(ramp["pt"][0]).max() / (mu * p0)),
        "end_dt": float(np.abs(ramp["pt"][-1] - ref["pt"][-1]).max() / (mu * p0)),
        "end_dxi": float(ramp["creepage"][-1] / ref["creepage"][-1] - 1),
        "stick_nodes": (int(np.sum(ramp["state"][-1] == STICK)), int(np.sum(ref["state"][-1] == STICK))),
        "dref_dt": float(np.abs(other["pt"] - ramp["pt"]).max() / (mu * p0)),
        "dref_dxi_during": (float(dxi[during].min()), float(dxi[during].max())),
        "dref_dxi_after": float(np.abs(dxi[after]).max()),
        "dref_predicted": rigid_creepage_shift(ramp_scene),
        "residual": float(max(ramp["residual"].max(), ref["residual"].max(), other["residual"].max())),
    }


def figure(ramp, ramp_scene, ref, other, path, title):
    """Tractions of the ramp (paper Fig. 5) and the creepage of both histories."""
    from rollqp.plot import LABELS, REFERENCES, pyplot
    from rollqp.plot.style import legend_below, reference
    plt = pyplot()
    x, a, p0, R = ramp["x"], float(ramp["a_H"]), float(ramp["p0"]), float(ramp["R"])
    mu, d = ramp_scene.contact.friction, ramp_scene.load.direction
    q = ramp["q"] / a
    fig, ax = plt.subplots(1, 2, figsize=(13, 5.4), constrained_layout=True)
    idx = [int(np.argmin(np.abs(q - w))) for w in SNAPSHOTS if w <= q[-1] + 1e-9]
    colors = plt.cm.viridis(np.linspace(0.78, 0.0, len(idx)))
    for color, k in zip(colors, idx):
        r = ramp["Q"][k] / (mu * ramp["P"][k])
        ax[0].plot(x / a, ramp["pt"][k] / (mu * p0), "o-", ms=2.5, lw=0.8, color=color,
                   label=f"$q = {q[k]:.3g}\\,a_H$, $Q/(\\mu P) = {r:.3f}$")
    xs = np.linspace(-1.25, 1.25, 1001)
    reference(ax[0], xs, cf.carter_traction(xs, 1.0, 1.0, 1.0, 0.75, d), "carter", label="Carter, 0.75")
    ax[0].plot(xs, cf.hertz_pressure(xs, 1.0, 1.0), ":", color="0.5", lw=0.8, label=r"bound $\mu p$")
    ax[0].set(xlabel=LABELS["x"], ylabel=LABELS["t"], title="traction on body A during and after the ramp")
    scale = R / (mu * a)
    ax[1].plot(q[1:], -ramp["creepage"][1:] * scale, "-", lw=1.2, label="ramp (§6.1.2), d_ref = R")
    ax[1].plot(q[1:], -other["creepage"][1:] * scale, "--", lw=1.0,
               label=f"ramp, d_ref = {DREF_FACTOR:g} R (same tractions)")
    xi_c = cf.carter_creepage(a, R, mu, 0.75)
    ax[1].axhline(-xi_c * scale, **{**REFERENCES["carter"], "label": r"Carter, $Q/(\mu P) = 0.75$"})
    qr = ref["q"] / a
    ax[1].plot(qr[1:], -ref["creepage"][1:] * scale, "-", lw=1.0, alpha=0.7, label="braked start (§6.1.1)")
    ax[1].axvline(8 / 3, color="0.6", lw=0.8, ls=":")
    ax[1].set(xlabel=LABELS["q"], ylabel=r"$-\xi R/(\mu a_H)$", title="creepage")
    for axis in ax:
        axis.grid(alpha=0.3)
        legend_below(axis, ncol=2)
    fig.suptitle(title)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(method="newton", figure_path=None):
    ramp_scene, ref_scene = rollqp.load_scene("ramp"), rollqp.load_scene("cattaneo-carter")
    other_scene = ramp_scene.replace(**{"contact.reference_distance": DREF_FACTOR * ramp_scene.R})
    ramp = rollqp.run(ramp_scene, method=method).arrays()
    ref = rollqp.run(ref_scene, method=method).arrays()
    other = rollqp.run(other_scene, method=method).arrays()
    m = measure(ramp, ramp_scene, ref, ref_scene, other)
    print(f"{ramp_scene.name}: {ramp_scene.description}; method {method}")
    print(f"  q = 0: max |t|/(mu p0) = {m['start_t']:.1e} (stopped at Q = 0)")
    print(f"  end (q = 6 a_H) against Carter: rms(t - Carter)/(mu p0) = {m['carter']:.4f}, "
          f"|xi/xi_Carter - 1| = {m['creepage']:.4f}")
    print(f"  end against §6.1.1's end: max |dt|/(mu p0) = {m['end_dt']:.1e}, xi_ramp/xi_6.1.1 - 1 = "
          f"{m['end_dxi']:+.1e}, stick nodes {m['stick_nodes'][0]} / {m['stick_nodes'][1]}")
    lo, hi = m["dref_dxi_during"]
    print(f"  d_ref = {DREF_FACTOR:g} R instead of R: max |dt|/(mu p0) = {m['dref_dt']:.1e}; creepage change "
          f"during the ramp {lo:.6e} .. {hi:.6e} (predicted -c dQ/dq = {m['dref_predicted']:.6e}), "
          f"after it {m['dref_dxi_after']:.1e}")
    print(f"  max residual {m['residual']:.1e}")
    if figure_path:
        title = f"§6.1.2: Q/(mu P) ramped 0 -> 0.75 over q = 8/3 a_H while rolling, mu = 0.1, 40 QCE, {method}"
        print(f"  figure {figure(ramp, ramp_scene, ref, other, figure_path, title)}")
    return {"measures": m, "ramp": ramp, "reference": ref, "other": other, "scene": ramp_scene, "method": method}


def _args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("method", nargs="?", default="newton", help="step method (default newton)")
    ap.add_argument("--figure", metavar="PATH", help="write the figure (PNG) here")
    return ap.parse_args(argv)


if __name__ == "__main__":
    _a = _args()
    results = main(_a.method, figure_path=_a.figure)
