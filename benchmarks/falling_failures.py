"""The falling-friction scenes of docs/stability.md ("Slip-dependent friction"): each run's outcome, measured.

    python benchmarks/falling_failures.py     # about 5 min on a shared 2-core machine

CONTACT's veldep_fric problem (friction_cases.veldep_scene: its grid and its law mapped) at several speeds,
with the creepage or the force prescribed, from a rolling or a braked start; each row the method, how far
the run got and, if it stopped, the SolverError's message (step, residual).
"""
from __future__ import annotations

import time

from harness import table  # (pins BLAS first)

from friction_cases import VELDEP, veldep_scene
from rollqp.errors import SolverError
from rollqp.march import march

CASES = [  # (label, method, scene keywords, rolling speed)
    ("V = 45 m/s, ξ prescribed, rolling start", "newton", {}, 45000.0),
    ("V = 45 m/s, ξ prescribed, rolling start", "qp-osqp", {}, 45000.0),
    ("V = 45 m/s, ξ prescribed, braked, 12 a_H", "newton", dict(start="braked", distance=12.0), 45000.0),
    ("V = 45 m/s, Q = 0.5 μ_s P, braked, 1 a_H", "qp-osqp", dict(start="braked", distance=1.0, tangential=0.5), 45000.0),
    ("V = 45 m/s, Q = 0.5 μ_s P, braked, 1 a_H", "newton", dict(start="braked", distance=1.0, tangential=0.5), 45000.0),
    ("V = 45 m/s, Q = 0.85 μ_s P (above the creep curve's peak, 0.8067), rolling start", "newton", dict(tangential=0.85), 45000.0),
    ("V = 45 m/s, Q = 0.5 μ_s P, braked, 6 a_H, 184 elements", "newton",
     dict(start="braked", distance=6.0, tangential=0.5, elements=184), 45000.0),
    ("V = 4.5 m/s, Q = 0.5 μ_s P, braked, 6 a_H, 184 elements", "newton",
     dict(start="braked", distance=6.0, tangential=0.5, elements=184), 4500.0),
]


def outcome(label, method, kw, speed):
    sc = veldep_scene(**kw).replace(**{"contact.friction.rolling_speed": speed})
    t0, k, restarts = time.perf_counter(), None, 0
    try:
        for rec in march(sc, method):
            k = rec.k
            restarts += int(rec.solution is not None and rec.solution.info.get("restarts", 0))
        out, msg = f"converged, {k} steps" + (f" ({restarts} warm starts lost, re-solved)" if restarts else ""), "—"
    except SolverError as err:
        out, msg = f"SolverError, step {err.step}", f"{err.message.split(';')[0]} ({err.residual:.3g})"
    return [label, method, out, msg, f"{time.perf_counter() - t0:.1f}"]


def main():
    print(f"CONTACT's veldep_fric: {VELDEP['MX']} elements unless said, law 0.18 + 0.12 exp(−ln 2 v/100 mm/s)\n")
    print(table(["scene", "method", "outcome", "message (residual)", "s"], [outcome(*c) for c in CASES]))


if __name__ == "__main__":
    main()
