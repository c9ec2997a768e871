"""Falling friction: the steady creep curve ξ → Q of CONTACT's veldep_fric problem, with its branches.

Traced twice with the Newton method's direct steady solve (veldep_scene of benchmarks/friction_cases.py:
exponential law μ = 0.18 + 0.12 exp(−V|s|/100 mm/s), V = 45 m/s):

* **creepage prescribed** (each ξ solved from the braked state): one solution per ξ, rising to a
  peak and then falling towards the kinetic limit μ_k P — the whole curve, rising branch and
  falling branch;
* **force prescribed** (each Q solved from the braked state, Cattaneo at that Q): above the peak
  there is no steady state and the solve fails (SolverError); below it, between the kinetic limit
  and the peak, each force has two steady states (one on each branch), and which one Newton
  finds depends on where its start lies — docs/friction.md.

Usage::

    python examples/friction_creep.py --figure docs/figures/friction-creep-curve.png
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from rollqp.errors import InputError, SolverError
from rollqp.march import run

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))  # the reference cases (not installed)
from friction_cases import VELDEP, veldep_scene  # noqa: E402


def creep_by_creepage(xis, speed, elements):
    """``Q/(μ_s P)`` and the slip fraction of the steady state at each prescribed ``ξ`` (None: failed)."""
    out = []
    for xi in xis:
        sc = veldep_scene(elements=elements, creepage=-xi).replace(**{"contact.friction.rolling_speed": speed})
        try:
            r = run(sc, "newton").arrays()
            out.append((xi, r["Q"][-1] / (sc.contact.mu * sc.load.normal), float(np.mean(r["state"][-1][r["state"][-1] > 0] == 2))))
        except SolverError:
            out.append((xi, None, None))
    return out


def creep_by_force(ratios, speed, elements):
    """``ξ`` of the steady state at each prescribed ``Q/(μ_s P)`` (None: no solution found)."""
    out = []
    for q in ratios:
        sc = veldep_scene(elements=elements, tangential=float(q)).replace(**{"contact.friction.rolling_speed": speed})
        try:
            r = run(sc, "newton").arrays()
            out.append((q, -float(r["creepage"][-1])))
        except (SolverError, InputError):
            out.append((q, None))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--figure", help="write the figure here (PNG)")
    ap.add_argument("--speed", type=float, default=VELDEP["V"], help="rolling speed V, mm/s (default 45000)")
    ap.add_argument("--elements", type=int, default=VELDEP["MX"], help="constant elements on ±4.6 mm (default 92)")
    ap.add_argument("--points", type=int, default=30, help="points per curve (default 30)")
    args = ap.parse_args(argv)
    xis = np.linspace(0.0, 6e-3, args.points + 1)[1:]
    by_xi = creep_by_creepage(xis, args.speed, args.elements)
    ok = [(x, q) for x, q, _ in by_xi if q is not None]
    peak = max(ok, key=lambda p: p[1])
    ratios = np.linspace(0.05, 1.2 * peak[1], args.points)
    by_q = creep_by_force(ratios, args.speed, args.elements)
    print(f"creepage prescribed: {len(ok)}/{len(by_xi)} solved; peak Q/(mu_s P) = {peak[1]:.4f} at |xi| = {peak[0]:.2e}; "
          f"at |xi| = {ok[-1][0]:.1e}: {ok[-1][1]:.4f} (kinetic limit {VELDEP['FKIN'] / 0.30:.4f})")
    solved_q = [q for q, x in by_q if x is not None]
    print(f"force prescribed: solved up to Q/(mu_s P) = {max(solved_q):.4f}; "
          f"{sum(x is None for _, x in by_q)} of {len(by_q)} forces above it have no steady solution (SolverError)")
    if args.figure:
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6.4, 4.2))
        x, q = np.array(ok).T
        rising = x <= peak[0]
        ax.plot(x[rising] * 1e3, q[rising], "-o", ms=3, label="creepage prescribed: rising (stable) branch")
        ax.plot(x[~rising] * 1e3, q[~rising], "-o", ms=3, color="C3", label="creepage prescribed: falling branch")
        fq = [(xx, qq) for qq, xx in by_q if xx is not None]
        if fq:
            a, b = np.array(fq).T
            ax.plot(a * 1e3, b, "x", color="k", label="force prescribed (each from the braked state)")
        for qq, xx in by_q:
            if xx is None:
                ax.axhline(qq, color="0.8", lw=0.6, zorder=0)
        ax.axhline(VELDEP["FKIN"] / 0.30, ls="--", color="0.5", label="kinetic limit μ_k/μ_s")
        ax.set_xlabel("|ξ| [‰]")
        ax.set_ylabel("Q / (μ_s P)")
        ax.set_title(f"falling friction (exponential, V = {args.speed / 1000:g} m/s): grey lines = forces without solution",
                     fontsize=8)
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(args.figure, dpi=110)
    return {"by_creepage": by_xi, "by_force": by_q, "peak": peak}


if __name__ == "__main__":
    results = main()
