"""Throughput of ``rollqp sweep`` on a local dask cluster against the same points run serially.

Usage::

    python benchmarks/sweep_throughput.py                  # 24 §6.1.1 points, newton, 3 interleaved repetitions
    python benchmarks/sweep_throughput.py --method qp-osqp --repeats 1
    python benchmarks/sweep_throughput.py --elements 80    # heavier points

The 24 points are the paper's §6.1.1 scene (``cattaneo-carter``: 40 QCE, Δq = Le/2, 6 a_H)
over Q/(μP) = 0.1 … 0.85 (6 values) × μ = 0.1, 0.15, 0.2, 0.3. **Serial**: the points one after
another in this process (``rollqp.run``), BLAS on one thread. **Sweep**: ``rollqp.sweep.sweep``
into a new zarr store on a ``LocalCluster`` of ``--workers`` single-threaded worker processes
(default 2: one per core), store creation and every write included; the cluster is started
once, before the repetitions (its start-up is reported apart), and warmed up with one small
sweep (the workers' first import of rollqp). The two alternate within each repetition
(:func:`harness.interleaved`); the ratio is of the medians.

Per-point overhead of the executor, three ways: a no-op task's round trip through the
scheduler (200 tasks), the client's write of one point into the store (``StoreWriter.write``),
and ``(workers × sweep wall − Σ point times)/points`` — what a point costs beyond its own
computation on a worker, start-up and tail included.

Control: the machine's parallelism at the moment (``workers`` pure-Python loops in processes at
once against one alone; 2× on an idle 2-core machine), measured between the repetitions: on a
shared machine it bounds what any parallel run can gain.
"""
from __future__ import annotations

import harness  # noqa: F401  (pins BLAS first)

import argparse  # noqa: E402
import os  # noqa: E402
import shutil  # noqa: E402
import statistics  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import rollqp  # noqa: E402
from rollqp.sweep import build_sweep, sweep  # noqa: E402
from rollqp.sweep import dataset  # noqa: E402
from rollqp.sweep.executor import close_client, connect  # noqa: E402

VARY = ("load.tangential=0.1:0.85:6", "contact.friction=0.1,0.15,0.2,0.3")


def _noop(i):
    return i


def _spin(_=None) -> float:
    """A fixed pure-Python loop; its wall time."""
    t0 = time.perf_counter()
    s = 0
    for i in range(2_000_000):
        s += i * i
    return time.perf_counter() - t0


def _parallelism(workers: int) -> float:
    """The machine's parallelism at the moment: ``workers`` × (one loop alone) / (``workers``
    loops at once, in processes): ``workers`` on an idle machine, less when it is shared."""
    import multiprocessing as mp
    with mp.get_context("spawn").Pool(workers) as pool:
        pool.map(_noop, range(workers))  # the processes started and their imports done
        alone = _spin()
        together = max(pool.map(_spin, range(workers)))  # each loop's own wall time
    return workers * alone / together


def _serial(scenes) -> float:
    t0 = time.perf_counter()
    for s in scenes:
        rollqp.run(s)
    return time.perf_counter() - t0


class _TimedWriter(dataset.StoreWriter):
    """StoreWriter that records the wall time of each point's write (client side)."""

    times: list = []

    def write(self, i, out):
        t0 = time.perf_counter()
        super().write(i, out)
        _TimedWriter.times.append(time.perf_counter() - t0)


def _sweep(base, client, folder, summaries) -> float:
    store = os.path.join(folder, f"s{len(summaries)}.zarr")
    t0 = time.perf_counter()
    summary = sweep(base, VARY, store, client=client)
    wall = time.perf_counter() - t0
    assert summary.done == 24 and not summary.failed, summary.table()
    summaries.append((wall, summary))
    shutil.rmtree(store)
    return wall


def _roundtrip(client, n=200) -> float:
    t0 = time.perf_counter()
    client.gather([client.submit(_noop, i, pure=False) for i in range(n)])
    return (time.perf_counter() - t0) / n


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--method", default="newton")
    ap.add_argument("--elements", type=int, default=40)
    args = ap.parse_args(argv)
    print(harness.machine_table())
    base = rollqp.load_scene("cattaneo-carter").replace(**{"solver.method": args.method,
                                                           "discretization.elements": args.elements})
    sw = build_sweep(base, VARY)
    dataset.StoreWriter = _TimedWriter  # the executor looks it up at call time
    folder = tempfile.mkdtemp(prefix="rollqp-sweep-bench-")
    t0 = time.perf_counter()
    client = connect(workers=args.workers)
    startup = time.perf_counter() - t0
    try:
        sweep(base.replace(**{"discretization.distance": 0.5}), ["contact.friction=0.1,0.2"],
              os.path.join(folder, "warm.zarr"), client=client)
        summaries = []
        cases = {"serial": lambda: _serial(sw.scenes), "sweep": lambda: _sweep(base, client, folder, summaries),
                 "control": lambda: _parallelism(args.workers)}
        walls = harness.interleaved(args.repeats, cases, lambda f: f(),
                                    log=lambda k, i, n: print(f"  {k} {i}/{n}", flush=True))
        rt = _roundtrip(client)
    finally:
        close_client(client)
        shutil.rmtree(folder, ignore_errors=True)
    ser, par = statistics.median(walls["serial"]), statistics.median(walls["sweep"])
    pts = [sum(s.point_times) for _, s in summaries]
    extra = [(args.workers * w - p) / 24 for (w, _), p in zip(summaries, pts)]
    writes = _TimedWriter.times[2:]  # after the warm-up's two points
    print()
    print(harness.table(["", "value"], [
        ("points", f"24 ({', '.join(VARY)}; {args.elements} {base.discretization.element} elements, {args.method})"),
        ("serial, one process (median of runs)", f"{ser:.2f} s  ({', '.join(f'{w:.2f}' for w in walls['serial'])})"),
        (f"sweep, {args.workers} workers (median of runs)", f"{par:.2f} s  ({', '.join(f'{w:.2f}' for w in walls['sweep'])})"),
        ("**throughput ratio serial/sweep**", f"**{ser / par:.2f}×**"),
        (f"control: {args.workers} pure-Python loops in processes at once vs one alone (median)",
         f"{statistics.median(walls['control']):.2f}× ({', '.join(f'{w:.2f}' for w in walls['control'])}; "
         f"{args.workers}× on an idle machine)"),
        ("Σ point times on the workers (median)", f"{statistics.median(pts):.2f} s"),
        ("cluster start-up (once, not in the sweep times)", f"{startup:.2f} s"),
        ("overhead: no-op task round trip", f"{1e3 * rt:.1f} ms per task"),
        ("overhead: client write of one point (median)", f"{1e3 * statistics.median(writes):.1f} ms"),
        ("overhead: (workers × wall − Σ point times)/points (median)", f"{1e3 * statistics.median(extra):.1f} ms"),
        ("load average at the end", " / ".join(f"{v:.2f}" for v in os.getloadavg())),
    ]))


if __name__ == "__main__":
    main()
