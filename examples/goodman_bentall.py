"""The paper's §6.2.1 example through the Python API: from Goodman to Bentall.

Dissimilar cylinders (2β = 1, μ = 0.3; the built-in scene ``goodman-bentall`` documents the
materials) are pressed together at Q = 0 in 40 normal-load steps, then released to roll
freely (Q = 0) for 6 a_H. Run twice, as the paper does:

* ``coupling = "goodman"`` (Fig. 6, the paper's "uncoupled" case): the shear does not change
  the pressure (A_nt = 0) but the pressure still displaces the surfaces tangentially
  (A_tn ≠ 0). The starting state is Goodman's: Hertz pressure with an antisymmetric shear.
* ``coupling = "full"`` (Fig. 7): both coupling terms. The starting pressure has a peak that
  rolls out through the trailing edge; the steady state is close to the Goodman one.

Both end in Bentall's steady free rolling; the creepage is held against Bentall & Johnson's
μ → 0 value |ξ| = 0.457·κ·a/R (``rollqp.closedforms.bentall_johnson_creepage``; for finite μ
the magnitude is smaller, and its sign is d·sgn(κ), docs/formulation.md §1, §12).

Run it::

    python examples/goodman_bentall.py [METHOD] [--figures DIR]

METHOD defaults to the scene's (newton); ``--figures DIR`` writes goodman-bentall-goodman.png
(Fig. 6), goodman-bentall-full.png (Fig. 7), goodman-bentall-zones.png and
goodman-bentall-compare.png there.
"""
from __future__ import annotations

import argparse
import itertools
import os
import time

import numpy as np

import rollqp
from rollqp import closedforms as cf

#: Rolled distances (q/a_H) drawn in the snapshot figures: the start, the paper's 0.6 contact
#: widths (1.2 a_H) at which the pressure peak has left, 1.8 widths (3.6 a_H) after which the
#: transient is gone, and the end.
SNAPSHOTS = (0.0, 0.3, 0.6, 1.2, 3.6, 6.0)
STATE_NAMES = {0: "separation", 1: "stick", 2: "slip"}


def zones(x, state):
    """Runs of equal node states from left to right: ``[(name, x_first, x_last), ...]``."""
    out, i = [], 0
    for code, run in itertools.groupby(state.tolist()):
        n = len(list(run))
        out.append((STATE_NAMES[code], float(x[i]), float(x[i + n - 1])))
        i += n
    return out


def _peak_at(q, where, excess, qa):
    """x/a_H of the pressure excess over the final state at q ≈ qa, None if there is none."""
    k = int(np.argmin(np.abs(q - qa)))
    return float(where[k]) if excess[k] > 0.005 else None


def measure(res, scene, wall):
    """The numbers the example prints and its test checks."""
    from rollqp.plot import settled_q
    a, p0, mu, R = float(res["a_H"]), float(res["p0"]), scene.contact.friction, float(res["R"])
    x, q = res["x"], res["q"] / a
    p, t = res["pn"], res["pt"]
    hertz = cf.hertz_pressure(x, a, p0)
    inside = np.abs(x) <= a
    bj = cf.bentall_johnson_creepage(scene.kappa, a, R)
    pmax = p.max(axis=1) / p0
    excess = (p - p[-1]).max(axis=1) / p0                       # pressure above the final state's
    after = np.nonzero(excess > 0.02)[0]
    where = x[np.argmax(p - p[-1], axis=1)] / a                 # where the excess is largest
    return {
        "steps": len(q) - 1,
        "iterations": int(res["iterations"].sum()),
        "iterations_start": int(res["iterations"][0]),
        "iterations_per_step": float(res["iterations"][1:].mean()),
        "wall": wall,
        "residual": float(res["residual"].max()),
        # the braked starting state (q = 0)
        "start_hertz_rms": float(np.sqrt(np.mean((p[0] - hertz)[inside] ** 2)) / p0),
        "start_pmax": float(pmax[0]),
        "start_tmax": float(np.abs(t[0]).max() / (mu * p0)),
        "start_antisymmetry": float(np.abs(t[0] + t[0][::-1]).max() / (mu * p0)),
        "start_pressure_asymmetry": float(np.abs(p[0] - p[0][::-1]).max() / p0),
        "start_Q": float(res["Q"][0] / (mu * res["P"][0])),
        "start_zones": zones(x / a, res["state"][0]),
        # friction law over every state: |t| <= mu p
        "friction_excess": float(np.max(np.abs(t) - mu * p) / (mu * p0)),
        "start_excess": float(excess[0]),
        "peak_gone": float(q[after[-1] + 1]) if after.size else 0.0,
        "peak_x_half": _peak_at(q, where, excess, 0.5),
        "peak_x_one": _peak_at(q, where, excess, 1.0),
        "settled": settled_q(res, mu),
        "xi_end": float(res["creepage"][-1]),
        "xi_bj": bj,
        "xi_ratio": float(res["creepage"][-1]) / bj,
        "xi_change_last_2aH": float(np.ptp(res["creepage"][q >= q[-1] - 2.0]) / abs(res["creepage"][-1])),
        "end_pmax": float(pmax[-1]),
        "end_zones": zones(x / a, res["state"][-1]),
    }


def main(method=None, figures=None, distance=None):
    base = rollqp.load_scene("goodman-bentall")
    if distance is not None:
        base = base.replace(**{"discretization.distance": float(distance)})
    runs = {}
    for coupling in ("goodman", "full"):
        scene = base.replace(**{"contact.coupling": coupling})
        t0 = time.perf_counter()
        result = rollqp.run(scene, method=method)
        wall = time.perf_counter() - t0
        res = result.arrays()
        runs[coupling] = {"scene": scene, "result": res, "stats": measure(res, scene, wall)}

    name = method or base.solver.method
    print(f"{base.name}: {base.description}")
    print(f"  beta = {base.beta:.10f} (2beta = {base.kappa:.6g}), mu = {base.contact.friction}, "
          f"a_H = {base.a_H:.4f}, a_H/R = {base.a_H / base.R:.4f}, p0 = {base.p0:.2f}; method {name}")
    rows = [("rolling steps (+ start)", "steps", "{:d}"),
            ("iterations: start (40 P-steps)", "iterations_start", "{:d}"),
            ("iterations per rolling step", "iterations_per_step", "{:.2f}"),
            ("wall time [s]", "wall", "{:.2f}"),
            ("max residual", "residual", "{:.1e}"),
            ("q=0: rms(p - Hertz)/p0", "start_hertz_rms", "{:.4f}"),
            ("q=0: max p/p0", "start_pmax", "{:.4f}"),
            ("q=0: max |t|/(mu p0)", "start_tmax", "{:.4f}"),
            ("q=0: max |t(x)+t(-x)|/(mu p0)", "start_antisymmetry", "{:.1e}"),
            ("max (|t| - mu p)/(mu p0), all q", "friction_excess", "{:.1e}"),
            ("q=0: max (p - p_end)/p0", "start_excess", "{:.4f}"),
            ("p - p_end <= 0.02 p0 from q/a_H", "peak_gone", "{:.3f}"),
            ("x/a_H of max (p - p_end) at q = 0.5 a_H", "peak_x_half", "{:+.3f}"),
            ("x/a_H of max (p - p_end) at q = 1.0 a_H", "peak_x_one", "{:+.3f}"),
            ("tractions settled from q/a_H", "settled", "{:.3f}"),
            ("final creepage xi", "xi_end", "{:.5e}"),
            ("xi / xi_BJ (mu -> 0: 0.457 kappa a/R)", "xi_ratio", "{:.4f}"),
            ("xi change over the last 2 a_H", "xi_change_last_2aH", "{:.1e}"),
            ("steady max p/p0", "end_pmax", "{:.4f}")]
    print(f"  {'':<40} {'goodman':>12} {'full':>12}")
    for label, key, fmt in rows:
        vals = [runs[c]["stats"][key] for c in ("goodman", "full")]
        print(f"  {label:<40} " + " ".join(f"{'-' if v is None else fmt.format(v):>12}" for v in vals))
    for c in ("goodman", "full"):
        for when, key in (("q = 0", "start_zones"), ("end", "end_zones")):
            z = runs[c]["stats"][key]
            print(f"  {c:<8} {when:<6} " + " | ".join(f"{k} {x0:+.3f}..{x1:+.3f}" for k, x0, x1 in z
                                                     if k != "separation"))

    g, f = runs["goodman"]["result"], runs["full"]["result"]
    p0, mu = base.p0, base.contact.friction
    comparison = {
        "start_dp": float(np.abs(f["pn"][0] - g["pn"][0]).max() / p0),
        "start_dt": float(np.abs(f["pt"][0] - g["pt"][0]).max() / (mu * p0)),
        "transient_dt": float(np.abs(f["pt"] - g["pt"]).max() / (mu * p0)),
        "end_dp": float(np.abs(f["pn"][-1] - g["pn"][-1]).max() / p0),
        "end_dt_rms": float(np.sqrt(np.mean((f["pt"][-1] - g["pt"][-1]) ** 2)) / (mu * p0)),
        "end_xi_ratio": float(f["creepage"][-1] / g["creepage"][-1]),
    }
    print("  full vs goodman: "
          f"q=0 max|dp| {comparison['start_dp']:.3f} p0, max|dt| {comparison['start_dt']:.3f} mu p0; "
          f"over the transient max|dt| {comparison['transient_dt']:.3f} mu p0; "
          f"end max|dp| {comparison['end_dp']:.3f} p0, rms dt {comparison['end_dt_rms']:.3f} mu p0, "
          f"xi_full/xi_goodman {comparison['end_xi_ratio']:.4f}")

    written = []
    if figures:
        from rollqp import plot
        os.makedirs(figures, exist_ok=True)
        for c, fig in (("goodman", "Fig. 6"), ("full", "Fig. 7")):
            path = os.path.join(figures, f"goodman-bentall-{c}.png")
            plot.snapshot_figure(runs[c]["result"], runs[c]["scene"], path, at=SNAPSHOTS,
                                 title=f"§6.2.1 ({fig}): Goodman to Bentall, 2beta = 1, mu = 0.3, "
                                       f"coupling {c}, {name}")
            written.append(path)
        path = os.path.join(figures, "goodman-bentall-zones.png")
        plot.zone_map_figure(runs["full"]["result"], runs["full"]["scene"], path,
                             title=f"§6.2.1: stick/slip zones and creepage, full coupling, {name}")
        written.append(path)
        path = os.path.join(figures, "goodman-bentall-compare.png")
        plot.comparison_figure({"goodman": g, "full": f}, runs["full"]["scene"], path, at=(0.0, 0.6, 1.2, 6.0),
                               title=f"§6.2.1: coupling goodman (solid) vs full (dashed), {name}")
        written.append(path)
        for path in written:
            print(f"  figure {path}")
    return {"runs": runs, "comparison": comparison, "figures": written, "method": name}


def _args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("method", nargs="?", default=None, help="step method (default: the scene's, newton)")
    ap.add_argument("--figures", metavar="DIR", help="write the figures to this folder")
    ap.add_argument("--distance", type=float, help="rolled distance / a_H (default: the scene's, 6)")
    return ap.parse_args(argv)


if __name__ == "__main__":
    _a = _args()
    results = main(_a.method, figures=_a.figures, distance=_a.distance)
