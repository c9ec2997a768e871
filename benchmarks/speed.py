"""The speed targets (docs/performance.md, "Targets") in one run: each target, what it requires, what this machine measures.

One command writes the table into docs/performance.md (between ``<!-- bench:speed -->`` markers)::

    python benchmarks/speed.py                # print the table (about 3 minutes on 2 idle cores)
    python benchmarks/speed.py --docs         # and write it into docs/performance.md
    python benchmarks/speed.py --full         # also the 2,561-node cattaneo-carter run (minutes)

Every figure is a median over repeated runs in this one process or in fresh child processes
(where the target is a whole process: ``import rollqp``, a CLI run, an assembly's peak memory),
BLAS pinned to one thread; ratios compare numbers of this run only. No test times anything:
this script is where speed is measured.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from harness import fit_exponent, machine_table, pin_threads, table, write_sections  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent


def _env() -> dict:
    """A child's environment: this source tree, BLAS pinned, and bytecode caching as on a user's machine
    (``PYTHONDONTWRITEBYTECODE`` unset: else every process compiles rollqp's modules again, ~0.05 s)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
               MPLBACKEND="Agg")
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def _child(code: str, *args, repeats=1) -> list:
    """The last stdout line of ``python -c code args`` as JSON, ``repeats`` fresh processes (after one
    unrecorded run that writes the bytecode caches)."""
    env = _env()
    subprocess.run([sys.executable, "-c", code, *map(str, args)], env=env, cwd=ROOT, capture_output=True)
    out = []
    for _ in range(repeats):
        r = subprocess.run([sys.executable, "-c", code, *map(str, args)], env=env, cwd=ROOT,
                           capture_output=True, text=True, check=True)
        out.append(json.loads(r.stdout.strip().splitlines()[-1]))
    return out


def import_time(repeats=7) -> float:
    """Median seconds of ``import rollqp`` in a fresh interpreter (the interpreter's own start excluded)."""
    code = "import json, time; t = time.perf_counter(); import rollqp; print(json.dumps(time.perf_counter() - t))"
    return float(np.median(_child(code, repeats=repeats)))


#: The ``rollqp`` command of this interpreter's environment (its console script), else the same entry point.
_SCRIPT = Path(sys.executable).with_name("rollqp")
_ROLLQP = ([str(_SCRIPT)] if _SCRIPT.exists()
           else [sys.executable, "-c", "import sys; from rollqp.cli import main; sys.exit(main())"])


def cli_time(repeats=5, scene="cattaneo-carter", method="newton") -> float:
    """Median wall seconds of the whole process ``rollqp run SCENE --method M --out F`` (interpreter start,
    imports, the run, the summary and the result file)."""
    times = []
    with tempfile.TemporaryDirectory() as tmp:
        env = _env()
        for i in range(repeats + 1):  # the first, unrecorded, writes the bytecode caches
            t0 = time.perf_counter()
            subprocess.run([*_ROLLQP, "run", scene, "--method", method, "--out", os.path.join(tmp, "r.npz")],
                           env=env, cwd=tmp, check=True, capture_output=True)
            if i:
                times.append(time.perf_counter() - t0)
    return float(np.median(times))


def newton_step_ratio(repeats=5) -> dict:
    """§6.1.1 (81 nodes): the Newton rolling step against three dense ``n × n`` products ``A @ x``.

    The products are timed in the march itself: right after each rolling step of ``repeats`` runs, three
    products in one timed block (``time.perf_counter``, as the step's own ``step_time``), so that the step and
    its yardstick are taken in the same state of the machine and of its caches; ``ratio`` is the median over
    the steps of ``step_time`` / (the three products after it). On this 2-core virtual machine one and the
    same step, repeated, takes 46 µs or 70 µs by turns for stretches of a few hundred microseconds, and a
    product 1.2 or 1.7 µs: a ratio of two times taken apart (a run's median step against the best of 7
    batches of 20,000 products, ``ratio_batch``; or each step's best over the runs against the same,
    ``ratio_best``) moves by a fifth between runs, the ratio taken step by step by 2 %.

    Returns ``step`` (the median ``step_time``), ``product`` (the median of the three products after a step,
    over three), ``ratio``, and ``batch`` (the product's best of 7 batches), ``ratio_batch`` (the median step
    over three of it), ``best`` (the median over the steps of each step's best over the runs),
    ``ratio_best``.
    """
    import timeit

    import rollqp
    scene = rollqp.load_scene("cattaneo-carter")
    rng = np.random.default_rng(0)
    n = None
    steps, products = [], []
    for _ in range(repeats):
        run_steps = []
        for rec in rollqp.march(scene, "newton"):
            if n is None:
                n = int(rec.state.p.size)
                A, x = rng.standard_normal((n, n)), rng.standard_normal(n)
            if rec.k == 0:
                continue
            t0 = time.perf_counter()
            A @ x
            A @ x
            A @ x
            products.append(time.perf_counter() - t0)
            run_steps.append(rec.step_time)
        steps.append(run_steps)
    steps, products = np.array(steps), np.array(products)
    number = 20000
    batch = min(timeit.repeat(lambda: A @ x, number=number, repeat=7)) / number
    step, best = float(np.median(steps)), float(np.median(steps.min(axis=0)))
    return {"n": n, "step": step, "product": float(np.median(products)) / 3.0,
            "ratio": float(np.median(steps.ravel() / products)),
            "batch": batch, "ratio_batch": step / (3.0 * batch), "best": best, "ratio_best": best / (3.0 * batch),
            "runs": repeats}


def assembly(nodes=5121, repeats=3) -> dict:
    """Half-space assembly of ``nodes`` quadratic nodes, a fresh process each (``benchmarks/assembly.py``):
    median seconds and peak RSS in matrices."""
    from assembly import measure
    runs = [measure(nodes) for _ in range(repeats)]
    return {"seconds": float(np.median([r["seconds"] for r in runs])),
            "peak": float(np.median([r["peak_bytes"] / r["matrix_bytes"] for r in runs]))}


def cattaneo_carter_fine(elements=1280) -> dict:
    """The §6.1.1 transient on ``elements`` quadratic elements with the dense ``newton`` (``solver.operator =
    "dense"``: else the fast path runs this size as ``mf-newton``): the whole ``rollqp.run`` call, wall and
    CPU, and the method the result says ran."""
    import rollqp
    scene = rollqp.load_scene("cattaneo-carter").replace(**{"discretization.elements": elements,
                                                            "solver.operator": "dense"})
    t0, c0 = time.perf_counter(), time.process_time()
    r = rollqp.run(scene, method="newton")
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    a = r.arrays()
    return {"nodes": int(a["x"].size), "steps": len(a["q"]) - 1, "seconds": wall, "cpu": cpu,
            "stepping": float(a["step_time"].sum()), "method": r.meta.get("method", "newton")}


def matrix_free_sizes(sizes=(2561, 10001, 40001, 131073)) -> dict:
    """``benchmarks/matrix_free.py``'s normal Hertz problem (cold) and rolling step (tangential half) with
    ``mf-newton`` on FFT products, one fresh process per size (medians of 3 solves; 1 at 131,073)."""
    from matrix_free import measure
    return {n: measure(n, "fft", 3 if n < 100000 else 1) for n in sizes}


def rows_matrix_free(add) -> None:
    r = matrix_free_sizes()
    n1, nb = r[10001], r[131073]
    add("normal problem, 10,001 nodes, `mf-newton` (rms error vs Hertz)", "≤ 0.5 s",
        f"{n1['normal']:.3f} s ({n1['err']:.1e})", n1["normal"] <= 0.5)
    add("normal problem, 131,073 nodes (peak memory)", "≤ 30 s, ≤ 1 GB",
        f"{nb['normal']:.1f} s, {nb['peak_bytes'] / 2 ** 20:.0f} MiB", nb["normal"] <= 30 and nb["peak_bytes"] <= 2 ** 30)
    ns = sorted(r)
    e = fit_exponent(ns, [r[n]["normal"] for n in ns], n_min=2561)
    each = ", ".join(f"{r[n]['normal']:.3g} s" for n in ns)
    add(f"normal problem cost exponent, {ns[0]:,}–{ns[-1]:,} nodes ({each})",
        "≤ 1.3", f"{e:.2f}", e <= 1.3)
    add("rolling step (Carter state, tangential half), 10,001 nodes", "≤ 1 s", f"{n1['roll']:.3f} s",
        n1["roll"] <= 1.0)
    t = transient_10001()
    add(f"§6.1.1 transient, 10,001 nodes, `mf-newton`, Δq = 8 Le, 6 a_H ({t['steps']} steps): wall a step "
        "(CPU a step; median wall step; set iterations, products a step)", "≤ 50 ms",
        f"{1e3 * t['wall'] / t['steps']:.0f} ms ({1e3 * t['cpu'] / t['steps']:.0f} ms; {1e3 * t['median']:.0f} ms; "
        f"{t['sets']:.2f}, {t['products']:.1f})", t["wall"] / t["steps"] <= 0.05)


def transient_10001() -> dict:
    """``python benchmarks/matrix_free.py --transient --nodes 10001``: the §6.1.1 transient with ``mf-newton``
    on 10,001 nodes at Δq = 8 Le over the full 6 a_H, in a fresh process (wall and CPU of the march,
    the braked start included; the start's cold normal solve is the first record)."""
    from matrix_free import transient
    return transient(10001, 6.0)


def qp_overhead(repeats=5) -> dict:
    """``benchmarks/qp_overhead.py``: the median §6.1.1 step's share outside the QP solver's solve calls
    (wall time), per backend, the backends alternating over ``repeats`` marches."""
    from qp_overhead import measure
    runs = {"qp-osqp": [], "qp-clarabel": []}
    for _ in range(repeats):
        for name in runs:
            runs[name].append(measure(name)["outside"])
    return {name: float(np.median(v)) for name, v in runs.items()}


def bentall_start(repeats=3) -> dict:
    """CONTACT's Bentall–Johnson grid (216 constant elements, μ = 0.05, full coupling), rolling start:
    the whole ``rollqp.run`` in CPU seconds with ``newton`` and ``qp-osqp`` (medians, alternating) and
    the QP answer's distance from Newton's (max of |Δp|/p0, |Δt|/(μp0), state 0)."""
    import bentall
    s = bentall.contact_grid(0.05, "full")
    cpu = {"newton": [], "qp-osqp": []}
    res = {}
    for _ in range(repeats):
        for name in cpu:
            r, c, _ = bentall.timed_cpu_run(s, name)
            cpu[name].append(c)
            res[name] = r
    dist, _ = bentall.start_distance(res["qp-osqp"], res["newton"], s)
    return {k: float(np.median(v)) for k, v in cpu.items()} | {"distance": dist}


def coupled_rolling_scenes() -> list:
    """The built-in scenes with full coupling (dissimilar bodies), each with ``load.start = "rolling"``."""
    import rollqp
    out = []
    for name in sorted(rollqp.builtin_scenes()):
        sc = rollqp.load_scene(name)
        if getattr(sc, "coupling_level", None) == "full":   # (3D scenes have none)
            out.append(sc.replace(**{"load.start": "rolling"}))
    return out


def held(sc):
    """``sc`` with its load histories held at their values at ``q = 0`` (the loads of the rolling start)."""
    from rollqp.histories import Constant
    key = "creepage" if sc.load.creepage is not None else "tangential"
    return sc.replace(**{"load.normal_history": Constant(float(sc.load.normal_history(0.0))),
                         f"load.{key}": Constant(float(getattr(sc.load, key)(0.0)))})


def rolling_starts(repeats=5, methods=("newton", "qp-osqp", "qp-clarabel")) -> dict:
    """Every built-in coupled scene with a rolling start: the whole ``rollqp.run`` of the start alone
    (``distance = 0``) in CPU seconds per method (medians, the methods alternating), the QP starts'
    distance from ``newton``'s (max of |Δp|/p0, |Δt|/(μp0)), and how far a ``newton`` march of 1 a_H from
    the start at the start's loads (:func:`held`) moves (max over its states, μp0)."""
    import rollqp
    out = {}
    for sc in coupled_rolling_scenes():
        start = sc.replace(**{"discretization.distance": 0.0})
        cpu = {m: [] for m in methods}
        res = {}
        for _ in range(repeats):
            for m in methods:
                c0 = time.process_time()
                res[m] = rollqp.run(start, method=m).arrays()
                cpu[m].append(time.process_time() - c0)
        mu_p0, ref = sc.contact.friction * sc.p0, res["newton"]
        dist = {m: max(float(np.abs(res[m]["pt"][0] - ref["pt"][0]).max()) / mu_p0,
                       float(np.abs(res[m]["pn"][0] - ref["pn"][0]).max()) / sc.p0) for m in methods}
        a = rollqp.run(held(sc).replace(**{"discretization.distance": 1.0}), method="newton").arrays()
        drift = max(float(np.abs(a["pt"] - a["pt"][0]).max()) / mu_p0, float(np.abs(a["pn"] - a["pn"][0]).max()) / sc.p0)
        out[sc.name] = {"cpu": {m: float(np.median(v)) for m, v in cpu.items()}, "distance": dist, "drift": drift}
    return out


def rows_rolling_starts(add) -> None:
    from rollqp.march.strip import STEADY_TOL
    for name, r in rolling_starts().items():
        c, d = r["cpu"], r["distance"]
        add(f"`{name}`, rolling start: a `newton` march of 1 a_H from it moves it by (μp0)",
            f"< {STEADY_TOL:.0e} (the march's tolerance)", f"{r['drift']:.1e}", r["drift"] < STEADY_TOL)
        for m in ("qp-osqp", "qp-clarabel"):
            ratio = c[m] / c["newton"]
            add(f"`{name}`, rolling start: `{m}` / `newton` CPU (distance of the states)", "≤ 10, ≤ 1e-8",
                f"{ratio:.1f} ({1e3 * c[m]:.0f} ms / {1e3 * c['newton']:.1f} ms; {d[m]:.0e})",
                ratio <= 10 and d[m] <= 1e-8)


def rows(full: bool, log) -> list:
    out = []

    def add(target, required, measured, met):
        out.append((target, required, measured, "met" if met else "**not met**"))
        log(f"{target}: {measured}")

    t = import_time()
    add("`import rollqp` (fresh interpreter)", "≤ 0.3 s", f"{t:.2f} s", t <= 0.3)
    t = cli_time()
    add("`rollqp run cattaneo-carter --method newton`, whole process", "≤ 0.6 s", f"{t:.2f} s", t <= 0.6)
    r = newton_step_ratio()
    add(f"§6.1.1 Newton rolling step / three dense products (n = {r['n']})", "≤ 15",
        f"{r['ratio']:.1f} ({1e3 * r['step']:.3f} ms / 3 × {1e6 * r['product']:.2f} µs, step by step; against "
        f"the best batch of products ({1e6 * r['batch']:.2f} µs): {r['ratio_batch']:.1f}, each step's best "
        f"{r['ratio_best']:.1f})", r["ratio"] <= 15)
    r = assembly()
    add("half-space assembly, 5,121 nodes (peak memory in matrices)", "≤ 1 s, ≤ 2 matrices",
        f"{r['seconds']:.2f} s, {r['peak']:.2f}", r["seconds"] <= 1.0 and r["peak"] <= 2.0)
    o = qp_overhead()
    for name, share in o.items():
        add(f"§6.1.1 `{name}`: median step's time outside the solver's solve calls", "≤ 15 %",
            f"{100 * share:.1f} %", share <= 0.15)
    b = bentall_start()
    ratio = b["qp-osqp"] / b["newton"]
    add("Bentall–Johnson coupled rolling start (216 elements): `qp-osqp` / `newton` CPU "
              "(distance of the answers)", "≤ 10",
        f"{ratio:.0f} ({b['qp-osqp']:.2f} s / {b['newton']:.2f} s; {b['distance']:.0e})", ratio <= 10)
    rows_rolling_starts(add)
    rows_matrix_free(add)
    if full:
        r = cattaneo_carter_fine()
        add(f"cattaneo-carter, {r['nodes']} nodes, {r['steps']} steps, `{r['method']}`, dense", "≤ 60 s",
            f"{r['seconds']:.1f} s (CPU {r['cpu']:.1f} s; Σ step_time {r['stepping']:.1f} s)", r["seconds"] <= 60)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--docs", action="store_true", help="write the table into docs/performance.md")
    ap.add_argument("--full", action="store_true", help="also the 2,561-node cattaneo-carter run")
    args = ap.parse_args(argv)
    pin_threads()
    command = "python benchmarks/speed.py" + (" --full" if args.full else "") + (" --docs" if args.docs else "")
    machine = machine_table(command)  # the load average at the start, as its row says
    print(machine + "\n", flush=True)
    res = rows(args.full, lambda m: print(f"  {m}", file=sys.stderr, flush=True))
    body = table(["target", "required", "measured", ""], res)
    print(body)
    if args.docs:
        doc = ROOT / "docs" / "performance.md"
        write_sections(doc, {"speed": machine + "\n\n" + body})
    return 0


if __name__ == "__main__":
    sys.exit(main())
