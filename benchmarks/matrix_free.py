"""The matrix-free path against the dense one: normal Hertz problem, a rolling step, memory (docs/matrix-free.md).

Each size runs in a fresh process (its peak RSS is the memory of that size alone), BLAS pinned
to one thread, medians over ``--repeats`` cold solves. The normal problem is the 2D Hertz
contact on quadratic elements (``n = 2·N + 1`` nodes, zone 1.25 a_H), solved from scratch; the
rolling step is the tangential half of the first rolling step after a braked (Cattaneo)
start at Q = 0.75 μP, μ = 0.3, material formulation, Δq = 0.5 Le, warm-started from the braked
state as in a transient. ``--dense`` adds the dense ``newton`` (matrix assembly included) up to
that many nodes. ``--threshold`` times ``mf-newton`` with dense and with FFT products on the
same problems (the crossover of :data:`rollqp.matrixfree.THRESHOLD`), ``--preconditioner``
compares the circulant preconditioner with none (GMRES products per step).

    python benchmarks/matrix_free.py --nodes 321 1281 2561 10001 40001 131073 --dense 2561
    python benchmarks/matrix_free.py --threshold --nodes 161 321 641 1281 2561
    python benchmarks/matrix_free.py --preconditioner --nodes 321 2561 10001
    python benchmarks/matrix_free.py --transient --nodes 10001 [--distance 6] [--source /other/checkout]

``--transient``: the §6.1.1 transient (``cattaneo-carter``, ``mf-newton``, Δq = 8 Le, the longest step
allowed) on each ``--nodes``, in a fresh process: wall and CPU seconds, per step (mean, median and by
eighths of the run), set iterations and operator products per step. ``--source`` adds the same run on
another source tree's rollqp (another checkout), the two alternating, for the ratio of the two trees.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from harness import fit_exponent, machine_table, pin_threads, table  # noqa: E402

_CHILD = r"""
import json, resource, sys, time
import numpy as np
from rollqp.closedforms import hertz_half_width, hertz_peak_pressure
from rollqp.influence import halfspace as hs, halfspace_influence
from rollqp.influence.toeplitz import log_operator
from rollqp.matrixfree import sparse_history
from rollqp.methods import get_method
from rollqp.problem import NormalStep, Scales, TangentialStep
from rollqp.strip import Strip
from rollqp.influence.operator import Operator

n, kind, repeats, opts = int(sys.argv[1]), sys.argv[2], int(sys.argv[3]), json.loads(sys.argv[4])
what = opts.pop("_what", "normal,roll")
P, R, mu = 1e-3, 100.0, 0.3
a = hertz_half_width(P, R, 1.0); sc = Scales(a, hertz_peak_pressure(P, a), 1.0)
strip = Strip(1.25 * a, (n - 1) // 2, "quadratic")
h = hs.undeformed_gap(strip.x, R)
t0 = time.perf_counter()
if kind == "dense":
    A = halfspace_influence(strip, Estar=1.0, beta=0.0, R_A=R, R_B=np.inf).Ann
    method = "newton"
elif kind == "mf-dense":
    A = Operator(halfspace_influence(strip, Estar=1.0, beta=0.0, R_A=R, R_B=np.inf).Ann)
    method = "mf-newton"
else:
    A = log_operator(strip, R, 2.0 / np.pi)
    method = "mf-newton"
build = time.perf_counter() - t0
normal = NormalStep(A=A, f=strip.weights, h=h, P=P, scales=sc)
times, sol = [], None
for _ in range(repeats):
    m = get_method(method, **opts)
    t0 = time.perf_counter(); sol = m.solve(normal); times.append(time.perf_counter() - t0)
inside = np.abs(strip.x) < a
err = float(np.sqrt(np.mean(((sol.p[inside] - sc.stress * np.sqrt(1 - (strip.x[inside] / a) ** 2)) / sc.stress) ** 2)))
out = {"nodes": strip.n, "kind": kind, "build": build, "normal": float(np.median(times)), "err": err,
       "normal_iterations": sol.iterations, "normal_products": sol.info.get("products")}
if "roll" in what:
    Q, dq = 0.75 * mu * P, 0.5 * strip.element_length
    m = get_method(method, **opts)
    braked = m.solve(TangentialStep(A=A, f=strip.weights, p=sol.p, mu=mu, c=np.zeros(strip.n), dq=a, Q=Q, scales=sc))
    M = sparse_history(strip, "material", dq, -1)
    w = A @ braked.t
    step = TangentialStep(A=A, f=strip.weights, p=sol.p, mu=mu, c=-(M @ w), dq=dq, Q=Q, scales=sc)
    times = []
    for _ in range(repeats):
        m2 = get_method(method, **opts)
        if method == "mf-newton":
            m2._warm = m._warm  # the transient's warm start: the braked state's reduced solutions
        t0 = time.perf_counter(); rs = m2.solve(step, warm=braked); times.append(time.perf_counter() - t0)
    out.update(roll=float(np.median(times)), roll_iterations=rs.iterations, roll_products=rs.info.get("products"),
               roll_residual=rs.residual)
out["peak_bytes"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
print(json.dumps(out))
"""


_TRANSIENT = r"""
import json, sys, time
import numpy as np
import rollqp
n, distance = int(sys.argv[1]), float(sys.argv[2])
sc = rollqp.load_scene("cattaneo-carter").replace(**{"solver.method": "mf-newton", "discretization.elements": (n - 1) // 2,
    "discretization.step": 8, "discretization.distance": distance})
rows = []
t0, c0 = time.perf_counter(), time.process_time()
for rec in rollqp.march(sc):
    sol = rec.solution
    rows.append((rec.step_time, rec.counters.iterations, (sol.info.get("products") or 0) if sol is not None else 0))
wall, cpu = time.perf_counter() - t0, time.process_time() - c0
a = np.array(rows[1:], dtype=float)
parts = [[float(np.median(b[:, 0])), float(b[:, 1].mean()), float(b[:, 2].mean())] for b in np.array_split(a, min(8, len(a)))]
print(json.dumps({"nodes": sc.n_nodes, "steps": len(a), "wall": wall, "cpu": cpu, "start": rows[0][0],
                  "mean": float(a[:, 0].mean()), "median": float(np.median(a[:, 0])), "sets": float(a[:, 1].mean()),
                  "products": float(a[:, 2].mean()), "parts": parts}))
"""


def transient(n, distance, source=None):
    """The §6.1.1 transient on ``n`` nodes with ``mf-newton`` (module docstring), in a fresh process (on the
    rollqp of the source tree ``source``, default this one)."""
    src = str(Path(source).resolve()) if source else str(Path(__file__).resolve().parent.parent)
    res = subprocess.run([sys.executable, "-c", _TRANSIENT, str(n), str(distance)], env=dict(os.environ, PYTHONPATH=src),
                         cwd=src, capture_output=True, text=True, check=True)
    return json.loads(res.stdout.strip().splitlines()[-1]) | {"load": os.getloadavg()[0]}


def measure(n, kind, repeats, opts=None, what="normal,roll"):
    src = str(Path(__file__).resolve().parent.parent)
    env = dict(os.environ, PYTHONPATH=src)
    o = dict(opts or {}, _what=what)
    res = subprocess.run([sys.executable, "-c", _CHILD, str(n), kind, str(repeats), json.dumps(o)],
                         env=env, cwd=src, capture_output=True, text=True)
    if res.returncode != 0:
        return {"nodes": n, "kind": kind, "error": res.stderr.strip().splitlines()[-1]}
    return json.loads(res.stdout.strip().splitlines()[-1])


def _fmt(x, unit="s"):
    return "–" if x is None else (f"{x * 1e3:.0f} ms" if x < 1 else f"{x:.2f} s")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=int, nargs="+", default=[321, 1281, 2561, 10001])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--dense", type=int, default=0, help="also the dense newton up to this many nodes")
    ap.add_argument("--threshold", action="store_true", help="mf-newton with dense vs FFT products")
    ap.add_argument("--preconditioner", action="store_true", help="circulant vs no preconditioner")
    ap.add_argument("--transient", action="store_true", help="the §6.1.1 transient with mf-newton, Δq = 8 Le")
    ap.add_argument("--distance", type=float, default=6.0, help="rolled distance of --transient, in a_H")
    ap.add_argument("--source", help="--transient also on this source tree's rollqp (the two trees compared)")
    args = ap.parse_args(argv)
    pin_threads()
    cmd = "python benchmarks/matrix_free.py " + " ".join(sys.argv[1:] if argv is None else argv)
    print(machine_table(cmd), "\n", flush=True)
    if args.transient:
        for n in args.nodes:
            runs = [(args.source, transient(n, args.distance, args.source))] if args.source else []
            r = transient(n, args.distance)
            runs.append((None, r))
            print(table(["source", "load (1 min, after)", "nodes", "steps", "wall", "CPU", "step: mean", "median",
                         "CPU a step", "sets a step", "products a step"],
                        [[src or "this tree", f"{x['load']:.1f}", x["nodes"], x["steps"], f"{x['wall']:.1f} s",
                          f"{x['cpu']:.1f} s", _fmt(x["mean"]), _fmt(x["median"]), _fmt(x["cpu"] / x["steps"]),
                          f"{x['sets']:.2f}", f"{x['products']:.1f}"] for src, x in runs]))
            print()
            print(table(["steps (eighths of the run)", "median step", "sets a step", "products a step"],
                        [[f"{k + 1}/{len(r['parts'])}", _fmt(m), f"{s_:.2f}", f"{p:.1f}"] for k, (m, s_, p) in enumerate(r["parts"])]))
        return
    if args.threshold:
        rows = []
        for n in args.nodes:
            d, f = (measure(n, k, args.repeats, what="normal") for k in ("mf-dense", "fft"))
            rows.append([n, _fmt(d.get("normal")), _fmt(f.get("normal")),
                         f"{d['normal'] / f['normal']:.2f}" if "normal" in d and "normal" in f else "–"])
            print(table(["nodes", "mf-newton, dense products", "mf-newton, FFT products", "dense / FFT"], rows[-1:]),
                  flush=True)
        print(table(["nodes", "mf-newton, dense products", "mf-newton, FFT products", "dense / FFT"], rows))
        return
    if args.preconditioner:
        rows = []
        for n in args.nodes:
            c, z = (measure(n, "fft", 1, {"preconditioner": p}) for p in ("circulant", "none"))
            rows.append([n, c.get("normal_products"), z.get("normal_products"), _fmt(c.get("normal")), _fmt(z.get("normal")),
                         c.get("roll_products"), z.get("roll_products"), _fmt(c.get("roll")), _fmt(z.get("roll"))])
            print(rows[-1], flush=True)
        print(table(["nodes", "normal products (circulant)", "(none)", "normal time (circulant)", "(none)",
                     "rolling products (circulant)", "(none)", "rolling time (circulant)", "(none)"], rows))
        return
    rows, ns, ts = [], [], []
    for n in args.nodes:
        kinds = ["fft"] + (["dense"] if n <= args.dense else [])
        for kind in kinds:
            r = measure(n, kind, args.repeats if n <= 40001 else 1)
            if "error" in r:
                rows.append([n, kind, r["error"], "", "", "", "", ""])
            else:
                rows.append([r["nodes"], "mf-newton (FFT)" if kind == "fft" else "newton (dense)", _fmt(r["normal"]),
                             f"{r['normal_iterations']} / {r['normal_products'] or '–'}", f"{r['err']:.1e}",
                             _fmt(r.get("roll")), f"{r.get('roll_iterations')} / {r.get('roll_products') or '–'}",
                             f"{r['peak_bytes'] / 2**20:.0f} MiB"])
                if kind == "fft":
                    ns.append(r["nodes"]); ts.append(r["normal"])
            print(table(["nodes", "method", "normal (cold)", "sets / products", "rms error vs Hertz",
                         "rolling step (tangential half)", "sets / products", "peak RSS"], rows[-1:]), flush=True)
    print()
    print(table(["nodes", "method", "normal (cold)", "sets / products", "rms error vs Hertz",
                 "rolling step (tangential half)", "sets / products", "peak RSS"], rows))
    big = [n for n in ns if n >= 2561]
    if len(big) >= 2:
        print(f"\nfitted exponent of the normal solve over {min(big)}–{max(big)} nodes: "
              f"{fit_exponent(ns, ts, n_min=2561):.2f}")


if __name__ == "__main__":
    main()
