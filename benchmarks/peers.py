"""rollqp's matrix-free normal solve against the FFT contact codes Tamaas and ContactMechanics (docs/matrix-free.md).

The 2D Hertz normal problem (line load P on a cylinder of radius R against a half-space,
E* = 1; rms pressure error against Hertz over the contact |x| < a, relative to p0):

* **rollqp** ``mf-newton`` on FFT operators, quadratic elements, ``n`` nodes on the strip
  ±1.25 a (the measurement of ``benchmarks/matrix_free.py``: a fresh process, cold solve,
  rollqp residual 1e-10);
* **Tamaas** (``PolonskyKeerRey``, ``basic_1d`` model, tolerance 1e-10) and **ContactMechanics**
  (``constrained_conjugate_gradients`` on a ``PeriodicFFTElasticHalfSpace``, penetration
  tolerance 1e-10 a²/R): periodic codes, which emulate an isolated contact by a periodic cell
  ``M`` times the strip, on a grid of rollqp's node spacing (``M (n − 1)`` points). Their error
  has a periodic-image part that falls only with ``M`` (about ``M⁻²``), so each is run at
  ``M = 8`` and at the smallest ``M`` of 8, 16, 32, … whose error is at most rollqp's at that
  ``n`` ("equal achieved accuracy"; given up above ``--max-grid`` points, or when the error stops
  falling: the peer's discretization error on that spacing is above rollqp's).

Medians of ``--repeats`` solves (one above 2^18 grid points), BLAS/OpenMP pinned to one
thread; a peer that is not installed is skipped (``pip install rollqp[bench]``)::

    python benchmarks/peers.py --nodes 321 1281 2561 10001 40001 131073
"""
from __future__ import annotations

import argparse
import importlib.util
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from harness import machine_table, pin_threads, table  # noqa: E402

P, R, ESTAR = 1e-3, 100.0, 1.0
A_H = np.sqrt(4 * P * R / (np.pi * ESTAR))
P0 = 2 * P / (np.pi * A_H)
ZONE = 1.25
TOL = 1e-10
#: Iteration limit of the peers' solvers (Tamaas's default of 1000 stopped the 1.28 M-point grid of
#: 10,001 nodes at M = 128 at 4.9e-5, above the error of M = 64; ContactMechanics' default is 100,000).
MAX_ITER = 100_000


def grid(n, M):
    """``(x, dx)``: the periodic cell of ``M`` strips on rollqp's node spacing, centred on the contact."""
    dx = 2 * ZONE * A_H / (n - 1)
    N = M * (n - 1)
    return (np.arange(N) - N // 2) * dx, dx


def hertz_error(x, p):
    """rms of ``(p − p_Hertz)/p0`` over ``|x| < a``."""
    inside = np.abs(x) < A_H
    exact = P0 * np.sqrt(1 - (x[inside] / A_H) ** 2)
    return float(np.sqrt(np.mean(((p[inside] - exact) / P0) ** 2)))


def tamaas_solve(n, M):
    import tamaas as tm
    tm.set_log_level(tm.LogLevel.error)
    x, dx = grid(n, M)
    model = tm.ModelFactory.createModel(tm.model_type.basic_1d, [x.size * dx], [x.size])
    model.E, model.nu = ESTAR, 0.0                        # E/(1 − ν²) = E* of rollqp's A_nn = (2/(πE*)) K
    solver = tm.PolonskyKeerRey(model, -(x ** 2) / (2 * R), TOL)
    solver.max_iter = MAX_ITER                            # its default 1000 stops short on 10^6-point grids
    t0 = time.perf_counter()
    solver.solve(P / (x.size * dx))                       # the mean pressure over the cell
    seconds = time.perf_counter() - t0
    return seconds, hertz_error(x, np.array(model.traction).ravel())


def contactmechanics_solve(n, M):
    from ContactMechanics import PeriodicFFTElasticHalfSpace
    from ContactMechanics.Optimization.ConstrainedConjugateGradients import constrained_conjugate_gradients
    from SurfaceTopography import UniformLineScan
    x, dx = grid(n, M)
    substrate = PeriodicFFTElasticHalfSpace((x.size,), ESTAR, physical_sizes=(x.size * dx,))
    topography = UniformLineScan(-(x ** 2) / (2 * R), x.size * dx, periodic=True)
    t0 = time.perf_counter()
    res = constrained_conjugate_gradients(substrate, topography, external_force=P, pentol=TOL * A_H ** 2 / R)
    seconds = time.perf_counter() - t0
    if not res.success:
        raise RuntimeError(f"ContactMechanics did not converge: {res.message}")
    return seconds, hertz_error(x, np.asarray(res.jac).ravel() / dx)   # pixel forces / dx


PEERS = {"Tamaas": ("tamaas", tamaas_solve), "ContactMechanics": ("ContactMechanics", contactmechanics_solve)}


def median_solve(solve, n, M, repeats):
    runs = [solve(n, M) for _ in range(repeats if M * (n - 1) <= 2 ** 18 else 1)]
    return float(np.median([r[0] for r in runs])), runs[-1][1]


def matched(solve, n, target, repeats, max_grid):
    """``(M, seconds, error, why)`` at the smallest M = 8, 16, … with error <= target; else ``M = None``
    with the last error and why the search stopped: the grid would exceed ``max_grid`` points, or
    the error no longer falls (less than 20 % from M to 2M: the peer's own discretization error at
    this spacing is reached, above rollqp's)."""
    M, last = 8, None
    while M * (n - 1) <= max_grid:
        t, e = median_solve(solve, n, M, 1)
        if e <= target:
            t, e = median_solve(solve, n, M, repeats)
            return M, t, e, ""
        if last is not None and e > 0.8 * last[2]:
            return None, t, e, f"plateau from M = {last[0]}"
        last = (M, t, e)
        M *= 2
    return None, *(last[1:] if last else (float("nan"), float("nan"))), "grid limit"


def _fmt(s):
    return "–" if s is None or s != s else (f"{s * 1e3:.0f} ms" if s < 1 else f"{s:.2f} s")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=int, nargs="+", default=[321, 1281, 2561, 10001])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--max-grid", type=int, default=2 ** 21, help="largest peer grid tried (points)")
    args = ap.parse_args(argv)
    pin_threads()
    from matrix_free import measure                        # rollqp's own measurement (a fresh process)
    cmd = "python benchmarks/peers.py " + " ".join(sys.argv[1:] if argv is None else argv)
    print(machine_table(cmd), "\n", flush=True)
    peers = {}
    for name, (module, solve) in PEERS.items():
        if importlib.util.find_spec(module) is None:
            print(f"{name}: not installed (pip install rollqp[bench]); skipped", flush=True)
        else:
            peers[name] = solve
    header = ["nodes", "rollqp mf-newton", "rms error"]
    for name in peers:
        header += [f"{name} M = 8", "rms error", f"{name} at rollqp's error", "M", "ratio"]
    rows = []
    for n in args.nodes:
        r = measure(n, "fft", args.repeats if n <= 40001 else 1, what="normal")
        row = [n, _fmt(r.get("normal")), f"{r['err']:.1e}" if "err" in r else r.get("error", "")]
        for name, solve in peers.items():
            t8, e8 = median_solve(solve, n, 8, args.repeats) if 8 * (n - 1) <= args.max_grid else (None, None)
            M, tm_, em, why = matched(solve, n, r.get("err", 0.0), args.repeats, args.max_grid)
            row += [_fmt(t8), "–" if e8 is None else f"{e8:.1e}",
                    f"{_fmt(tm_)} ({em:.1e})" if M else f"not reached: {em:.1e}, {why}",
                    M or "–",
                    f"{tm_ / r['normal']:.1f}×" if M and "normal" in r else "–"]
        rows.append(row)
        print(table(header, rows[-1:]), flush=True)
    print()
    print(table(header, rows))


if __name__ == "__main__":
    main()
