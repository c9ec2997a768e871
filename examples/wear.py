"""The paper's §6.2.2 claim, measured: a harmonic normal load wears the rollers more than a constant one.

The paper ends §6.2.2 with "bigger slip zones and higher slip velocities; both will increase
roller wear". This example runs the built-in scene ``harmonic`` (aluminium on steel, 2β = 0.288,
μ = 0.1, free rolling, P = P̄(1 + 0.2 sin(2π q/λ)), λ = 2 a_H, 21 QCE) and the same scene with a
constant load P̄, over the same rolled distance, with Archard's law on both rollers
(``bodies.X.wear`` = k/H; the depth scales with it, the ratios do not), and compares:

* the slip zone (the share of contact nodes that slip, averaged over the rolling steps) and the
  slip velocity (max |s| per step, averaged);
* the dissipated frictional work (``friction_work``, accumulated);
* the worn profile along each roller's surface (:func:`rollqp.wear.profile`): its mean over the
  surface that passed through the whole run and its peak.

Run it::

    python examples/wear.py [--distance D] [--wear K_OVER_H] [--figure FILE]

``--distance`` is the rolled distance in a_H (default 6: three load cycles); ``--figure`` draws
the two worn profiles of each roller (docs/figures/wear-harmonic.png).
"""
from __future__ import annotations

import argparse

import numpy as np

import rollqp
from rollqp.wear import profile

#: k/H in 1/MPa: a mild-wear coefficient k = 1e-7 over a hardness of about 1 GPa (order of magnitude only).
WEAR = 1e-10


def scenes(distance=6.0, wear=WEAR):
    """``{"constant": scene, "harmonic": scene}``: §6.2.2 with and without the load cycle."""
    h = rollqp.load_scene("harmonic").replace(**{"discretization.distance": distance, "bodies.A.wear": wear,
                                                 "bodies.B.wear": wear})
    c = h.replace(**{"load.normal_history": {"kind": "constant", "value": 1.0}})
    return {"constant": c, "harmonic": h}


def measure(res, scene) -> dict:
    """Slip share, slip velocity, frictional work and worn depth of one run (arrays of a result)."""
    a, mu = scene.a_H, scene.contact.friction
    st, s = np.asarray(res["state"][1:]), np.abs(res["slip"][1:])
    contact = (st > 0).sum(axis=1)
    out = {"slip share": float(np.mean((st == 2).sum(axis=1) / contact)),
           "max |s| (mean over steps)": float(np.mean(s.max(axis=1))),
           "friction work": float(np.sum(res["friction_work"]))}
    L, q = scene.half_width, float(res["q"][-1])
    for body in ("A", "B"):
        sig, depth = profile(res, body)
        # material that passed through the whole zone [−L, L]: upstream of it at q = 0, downstream at the end
        u = -scene.load.direction * sig
        passed = (u >= L) & (u <= q - L)
        out[f"mean depth {body}"] = float(depth[passed].mean()) if passed.any() else float("nan")
        out[f"peak depth {body}"] = float(depth.max())
        out[f"profile {body}"] = (sig / a, depth)
    out["a_H"], out["mu"] = a, mu
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--distance", type=float, default=6.0, help="rolled distance in a_H (default 6)")
    ap.add_argument("--wear", type=float, default=WEAR, help="k/H of both rollers, 1/MPa (default 1e-10)")
    ap.add_argument("--figure", help="PNG: the worn profiles")
    args = ap.parse_args(argv)
    results = {}
    for name, sc in scenes(args.distance, args.wear).items():
        results[name] = measure(rollqp.run(sc).arrays(), sc)
    keys = ["slip share", "max |s| (mean over steps)", "friction work", "mean depth A", "peak depth A",
            "mean depth B", "peak depth B"]
    print(f"{'':28s} {'constant':>12s} {'harmonic':>12s} {'ratio':>7s}")
    for k in keys:
        c, h = results["constant"][k], results["harmonic"][k]
        print(f"{k:28s} {c:12.4e} {h:12.4e} {h / c:7.3f}")
    if args.figure:
        from rollqp.plot import pyplot
        plt = pyplot()
        fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), constrained_layout=True)
        sc = scenes(args.distance, args.wear)["constant"]
        unit = args.wear * sc.p0 * sc.a_H
        for ax, body in zip(axes, ("A", "B")):
            for name, style in (("constant", "k-"), ("harmonic", "r-")):
                sig, d = results[name][f"profile {body}"]
                ax.plot(sig, d / unit, style, lw=1, label=f"{name} load")
            ax.set_xlabel("surface coordinate σ / a_H (material position at q = 0)")
            ax.set_ylabel("worn depth / ((k/H) p0 a_H)")
            ax.set_title(f"roller {body}: {args.distance:g} a_H rolled; mean depth harmonic/constant = "
                         f"{results['harmonic'][f'mean depth {body}'] / results['constant'][f'mean depth {body}']:.2f}",
                         fontsize=9)
            ax.legend(fontsize=8)
        fig.savefig(args.figure, dpi=110)
        print(f"figure {args.figure}")
    return results


if __name__ == "__main__":
    main()
