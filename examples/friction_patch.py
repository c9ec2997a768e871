"""A patch of low friction rolling through a Carter contact: the creepage transient and the zones.

CONTACT's Cattaneo → Carter problem (contact_scene of benchmarks/refcases.py: μ = 0.1, Q = 0.5 μP
prescribed, braked start) with a patch of μ = 0.05 on [2, 2.5] a_H of body A's material at q = 0
(patch_scene of benchmarks/friction_cases.py); the material moves with d = −1, so the patch enters the
contact at the leading edge x = +a_H at q ≈ 1 a_H and leaves at x = −a_H at q ≈ 3.5 a_H.
Compared with the same run without the patch (constant μ = 0.1).

Usage::

    python examples/friction_patch.py --figure docs/figures/friction-patch.png
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from rollqp.march import run

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))  # the reference cases (not installed)
from friction_cases import patch_scene  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--figure", help="write the figure here (PNG)")
    ap.add_argument("--elements", type=int, default=88, help="constant elements on ±1.1 a_H (default 88)")
    ap.add_argument("--method", default="newton", help="step method (default newton)")
    args = ap.parse_args(argv)
    sc = patch_scene(elements=args.elements, method=args.method)
    base = sc.replace(**{"contact.friction": sc.contact.mu})
    with_patch, without = run(sc).arrays(), run(base).arrays()
    a = sc.a_H
    q = with_patch["q"] / a
    xi, xi0 = with_patch["creepage"], without["creepage"]
    carter = xi0[-1]
    i = 1 + int(np.argmax(np.abs(xi[1:])))  # state 0 is the static shift (creepage per a_H of shift)
    print(f"steady creepage without the patch: {carter:.6e}; with it the creepage peaks at {xi[i]:.6e} "
          f"({xi[i] / carter:.3f} x) at q = {q[i]:.2f} a_H and returns to {xi[-1]:.6e} "
          f"(|Δ|/|ξ| = {abs(xi[-1] / carter - 1):.1e}) at q = {q[-1]:.1f} a_H")
    if args.figure:
        import matplotlib.pyplot as plt
        fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(6.4, 6.0), sharex=True)
        ax1.plot(q[1:], xi[1:] / carter, label="patch μ = 0.05 on [2, 2.5] a_H of the material")
        ax1.plot(q[1:], xi0[1:] / carter, "--", label="constant μ = 0.1")
        ax1.set_ylabel("ξ / ξ_Carter")
        ax1.legend(fontsize=7)
        st = with_patch["state"]
        x = with_patch["x"] / a
        ax2.pcolormesh(q, x, st.T, cmap="viridis", shading="nearest", vmin=0, vmax=2)
        ax2.plot(q, 2.0 - q, "w--", lw=0.8)
        ax2.plot(q, 2.5 - q, "w--", lw=0.8)
        ax2.set_ylim(x[0], x[-1])
        ax2.set_xlabel("q / a_H")
        ax2.set_ylabel("x / a_H (dark: separation, teal: stick, yellow: slip)")
        ax2.yaxis.label.set_size(7)
        fig.tight_layout()
        fig.savefig(args.figure, dpi=110)
    return {"q": q, "xi": xi, "xi_constant": xi0, "state": with_patch["state"], "x": with_patch["x"] / a,
            "scene": sc}


if __name__ == "__main__":
    results = main()
