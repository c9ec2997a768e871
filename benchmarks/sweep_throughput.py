"""Throughput of ``rollqp sweep`` on a local dask cluster against the same points run in one process.

Usage::

    python benchmarks/sweep_throughput.py                 # small and large points, 3 interleaved repetitions
    python benchmarks/sweep_throughput.py --sizes small --repeats 5
    python benchmarks/sweep_throughput.py --creep         # also the docs' creep-curve command, whole,
                                                          # on a local cluster and with --workers 0
    python benchmarks/sweep_throughput.py --validate      # only: validating a sweep of 100,000 points
    python benchmarks/sweep_throughput.py --sizes small --per-chunk 4   # chunks of 4 points, not the default

Two kinds of points, both the paper's §6.1.1 scene (``cattaneo-carter``: Δq = Le/2, 6 a_H,
``newton``) over load ratio × friction:

* **small**: 40 QCE (~0.1 s a point), Q/(μP) = 0.1 … 0.85 (6 values) × μ = 0.1 … 0.45 (8
  values): 48 points;
* **large**: 80 QCE (~0.5 s a point), Q/(μP) = 0.1 … 0.85 (6) × μ = 0.1, 0.2: 12 points.

Three ways to compute the same points, alternating within each repetition
(:func:`harness.interleaved`; the ratios are of the medians):

* **runs**: the points one after another in this process (``rollqp.run``), BLAS on one thread:
  the computation alone, no store;
* **one process**: ``rollqp.sweep.sweep`` in this process (``--workers 0``): the same command and
  the same store as the sweep below, with one process doing everything;
* **sweep**: ``rollqp.sweep.sweep`` into a new zarr store on a ``LocalCluster`` of ``--workers``
  single-threaded worker processes (default 2: one per core), the whole call timed (validation,
  the store's creation, every task and every write). The cluster is started once, before the
  repetitions: its start is reported apart, and the ratio with it included too. A warm-up sweep
  first (the workers' first import of rollqp).

The scaling of ``rollqp sweep`` is **one process / sweep**: the same work (points, result
arrays, store writes) on one process against ``--workers`` processes. **runs / sweep** also
charges the sweep with what the store costs.

Overheads, measured on the way: the sweep's fixed part (validation and store), the store
writes (``StoreWriter.write`` in the one-process sweep: wall and CPU; on a local cluster the
workers write their own chunks), each point's CPU time beside its wall time (in the runs and on
the workers), and ``(workers × points' wall − Σ point times)/points``: what a point costs beyond
its own computation on a worker, its share of the writes, the scheduler and the tail included. A
**CPU-based ratio**, less sensitive to other jobs on the machine than the wall-clock one: the
one-process sweep's CPU seconds against the sweep's CPU shared by the workers (the points' CPU on
the workers, their writes included, and the client process's CPU during the sweep — validation,
store, dask's scheduler thread — divided by ``--workers``): what free cores would give if only
CPU counted (the workers' own dask CPU between points is not in it).

Points per task and chunk: each sweep's own default, as a user gets it
(``rollqp.sweep.dataset.points_per_chunk`` of its number of workers: 8 in both for the small
points; for the large ones 4 in one process and 2 on 2 workers), or ``--per-chunk B`` for both.

The store's own costs, at the end with the cluster closed: its creation written directly against
through zarr's API, and a writer made from ``.zmetadata`` against one through zarr (CPU medians).

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
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import rollqp  # noqa: E402
from rollqp.sweep import build_sweep, dataset, sweep  # noqa: E402
from rollqp.sweep.executor import InProcess, close_client, connect  # noqa: E402

SIZES = {
    "small": ({"discretization.elements": 40},
              ("load.tangential=0.1:0.85:6", "contact.friction=0.1:0.45:8")),
    "large": ({"discretization.elements": 80},
              ("load.tangential=0.1:0.85:6", "contact.friction=0.1,0.2")),
}
CREEP = ["creep-curve", "cattaneo-carter", "--friction", "0.1,0.2,0.3"]


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


CPU = {}  # case -> CPU seconds of each run in this process


def _runs(scenes, size) -> float:
    t0, c0 = time.perf_counter(), time.process_time()
    for s in scenes:
        rollqp.run(s)
    CPU.setdefault(f"runs {size}", []).append(time.process_time() - c0)
    return time.perf_counter() - t0


class _TimedWriter(dataset.StoreWriter):
    """StoreWriter that records the wall time and point count of each write in this process."""

    writes: list = []

    def write(self, points, outs):
        t0, c0 = time.perf_counter(), time.thread_time()
        super().write(points, outs)
        _TimedWriter.writes.append((time.perf_counter() - t0, len(points), time.thread_time() - c0))


def _sweep(base, vary, client, folder, summaries, per_chunk=None) -> float:
    store = os.path.join(folder, f"s{time.time_ns()}.zarr")
    t0, c0 = time.perf_counter(), time.process_time()
    summary = sweep(base, vary, store, client=client, per_chunk=per_chunk)
    wall = time.perf_counter() - t0
    assert summary.done == summary.total and not summary.failed, summary.table()
    summaries.append((wall, summary, time.process_time() - c0))
    shutil.rmtree(store)
    return wall


def _one_process(base, vary, folder, summaries, size, per_chunk=None) -> float:
    c0 = time.process_time()
    wall = _sweep(base, vary, InProcess(), folder, summaries, per_chunk)
    CPU.setdefault(f"one process {size}", []).append(time.process_time() - c0)
    return wall


def _creep_command(folder, extra=()) -> float:
    """Wall seconds of the docs' ``rollqp creep-curve`` command as a user runs it (a new process)."""
    store = os.path.join(folder, "creep.zarr")
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "rollqp.cli", *CREEP, *extra, "--out", store, "--quiet"], check=True)
    wall = time.perf_counter() - t0
    shutil.rmtree(store, ignore_errors=True)
    return wall


def _rows(size, walls, summaries, workers, startup):
    med = {k: statistics.median(walls[f"{k} {size}"]) for k in ("runs", "one process", "sweep")}
    one, par = med["one process"], med["sweep"]
    n = summaries[0][1].total
    pts = [sum(s.point_times) for _, s, _ in summaries]
    extra = [(workers * s.wall - p) / n for (_, s, _), p in zip(summaries, pts)]
    fixed = [s.prepare for _, s, _ in summaries]
    # CPU-based ratio: the one-process sweep's CPU against the sweep's CPU shared by the workers (the points'
    # CPU on the workers, their writes included, plus the client process's: validation, store, the scheduler's
    # thread), what free cores would give if nothing but CPU counted (dask's own CPU on the workers is not in it)
    sweep_cpu = statistics.median((sum(s.point_cpu) + c) / workers for _, s, c in summaries)
    listed = {k: ", ".join(f"{w:.2f}" for w in walls[f"{k} {size}"]) for k in med}
    return [
        (f"**{size}**: points", f"{n} ({summaries[0][1].per_chunk} per task and chunk)"),
        ("runs, one process, no store (median)", f"{med['runs']:.2f} s  ({listed['runs']})"),
        ("`rollqp sweep --workers 0`: one process (median)", f"{one:.2f} s  ({listed['one process']})"),
        (f"sweep, {workers} workers (median)", f"{par:.2f} s  ({listed['sweep']})"),
        ("**scaling: one process / sweep**", f"**{one / par:.2f}×**"),
        ("runs / sweep", f"{med['runs'] / par:.2f}×"),
        ("one process / (sweep + the cluster's start)", f"{one / (par + startup):.2f}×"),
        ("mean point time: runs / on the workers", f"{1e3 * med['runs'] / n:.0f} ms / {1e3 * statistics.median(pts) / n:.0f} ms"),
        ("mean point CPU time: runs / on the workers",
         f"{1e3 * statistics.median(CPU[f'runs {size}']) / n:.0f} ms / "
         f"{1e3 * statistics.median(sum(s.point_cpu) for _, s, _ in summaries) / n:.0f} ms"),
        ("CPU of the one-process sweep / of the client process during a sweep (medians)",
         f"{statistics.median(CPU[f'one process {size}']):.2f} s / {statistics.median(c for _, _, c in summaries):.2f} s"),
        ("CPU-based ratio: one-process CPU / ((Σ point CPU on the workers + client CPU) / workers)",
         f"{statistics.median(CPU[f'one process {size}']) / sweep_cpu:.2f}×"),
        ("validation and store creation (median)", f"{1e3 * statistics.median(fixed):.0f} ms"),
        ("(workers × points' wall − Σ point times)/points (median)", f"{1e3 * statistics.median(extra):.1f} ms"),
    ]


def _store_costs(base, vary, folder, repeats: int = 9) -> list:
    """CPU medians, in this process with the cluster closed, of making the store of ``vary`` over ``base``
    (the sweeps' chunking) written directly and through zarr's API (``create_store(direct=False)``), and of
    a writer made from the store's ``.zmetadata`` and through zarr (``StoreWriter`` of the opened group,
    the store's ``.zmetadata`` removed so that zarr opens every array)."""
    import zarr
    sw = build_sweep(base, vary)
    per_chunk = dataset.points_per_chunk(sw, 1)
    cpu = {k: [] for k in ("direct", "zarr", "writer at", "writer zarr")}
    for i in range(repeats):
        for how in ("direct", "zarr"):
            path = os.path.join(folder, f"c{i}-{how}.zarr")
            c0 = time.process_time()
            dataset.create_store(path, sw, per_chunk, direct=how == "direct")
            cpu[how].append(time.process_time() - c0)
        c0 = time.process_time()
        dataset.StoreWriter.at(os.path.join(folder, f"c{i}-direct.zarr"), sw)
        cpu["writer at"].append(time.process_time() - c0)
        os.remove(os.path.join(folder, f"c{i}-zarr.zarr", ".zmetadata"))
        c0 = time.process_time()
        dataset.StoreWriter(zarr.open_group(os.path.join(folder, f"c{i}-zarr.zarr"), mode="r+", zarr_format=2), sw)
        cpu["writer zarr"].append(time.process_time() - c0)
    med = {k: 1e3 * statistics.median(v) for k, v in cpu.items()}
    return [("store creation, CPU: written directly / through zarr's API (medians, this process alone)",
             f"{med['direct']:.1f} ms / {med['zarr']:.1f} ms"),
            ("a writer of the store, CPU: from .zmetadata / zarr opening every array (medians)",
             f"{med['writer at']:.1f} ms / {med['writer zarr']:.1f} ms")]


def _validate():
    """Wall and CPU seconds of validating §6.1.1 over 1,000 friction values × 100 load ratios."""
    import resource
    vary = ["contact.friction=0.1:0.5:1000", "load.tangential=0.05:0.95:100"]
    t0, c0 = time.perf_counter(), time.process_time()
    sw = build_sweep(rollqp.load_scene("cattaneo-carter"), vary)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    print(harness.table(["", "value"], [
        ("points", f"{sw.size} ({', '.join(vary)})"),
        ("validation: wall / CPU", f"{wall:.1f} s / {cpu:.1f} s ({1e3 * cpu / sw.size:.2f} ms of CPU a point)"),
        ("peak memory of the process", f"{resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB"),
        ("load average at the end", " / ".join(f"{v:.2f}" for v in os.getloadavg()))]))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--sizes", default="small,large", help="comma-separated: small, large")
    ap.add_argument("--per-chunk", type=int, default=None,
                    help="points per task and chunk in both sweeps (default: points_per_chunk's)")
    ap.add_argument("--creep", action="store_true", help="also time the docs' creep-curve command (new processes)")
    ap.add_argument("--validate", action="store_true", help="only time the validation of 100,000 points")
    args = ap.parse_args(argv)
    if args.validate:
        return _validate()
    sizes = [s.strip() for s in args.sizes.split(",") if s.strip()]
    print(harness.machine_table())
    base = rollqp.load_scene("cattaneo-carter")
    scenes = {s: base.replace(**SIZES[s][0]) for s in sizes}
    points = {s: list(build_sweep(scenes[s], SIZES[s][1]).scenes) for s in sizes}
    dataset.StoreWriter = _TimedWriter  # the executor looks it up at call time
    folder = tempfile.mkdtemp(prefix="rollqp-sweep-bench-")
    t0 = time.perf_counter()
    client = connect(workers=args.workers)
    startup = time.perf_counter() - t0
    summaries = {s: [] for s in sizes}
    try:
        sweep(base.replace(**{"discretization.distance": 0.5}), ["contact.friction=0.1,0.2"],
              os.path.join(folder, "warm.zarr"), client=client)
        _TimedWriter.writes.clear()
        cases = {}
        one = {s: [] for s in sizes}
        for s in sizes:
            cases[f"runs {s}"] = lambda s=s: _runs(points[s], s)
            cases[f"one process {s}"] = lambda s=s: _one_process(scenes[s], SIZES[s][1], folder, one[s], s, args.per_chunk)
            cases[f"sweep {s}"] = lambda s=s: _sweep(scenes[s], SIZES[s][1], client, folder, summaries[s], args.per_chunk)
        cases["control"] = lambda: _parallelism(args.workers)
        walls = harness.interleaved(args.repeats, cases, lambda f: f(),
                                    log=lambda k, i, n: print(f"  {k} {i}/{n}", flush=True))
    finally:
        close_client(client)
    creep = {"": [], " --workers 0": []}
    for _ in range(args.repeats if args.creep else 0):  # alternating, as the sweeps above
        for extra in creep:
            creep[extra].append(_creep_command(folder, extra.split()))
    store_rows = _store_costs(scenes[sizes[0]], SIZES[sizes[0]][1], folder)
    shutil.rmtree(folder, ignore_errors=True)
    rows = [(f"local cluster start ({args.workers} workers; once, not in the sweep times)", f"{startup:.2f} s")]
    for s in sizes:
        rows += _rows(s, walls, summaries[s], args.workers, startup)
    writes = _TimedWriter.writes
    per_point = sum(k for _, k, _ in writes)
    rows += [("store write of one chunk in the one-process sweep: wall / CPU (medians; CPU a point)",
              f"{1e3 * statistics.median(w for w, _, _ in writes):.1f} ms / "
              f"{1e3 * statistics.median(c for _, _, c in writes):.1f} ms "
              f"({1e3 * sum(c for _, _, c in writes) / per_point:.1f} ms a point)")]
    rows += store_rows
    rows += [(f"control: {args.workers} pure-Python loops in processes at once vs one alone (median)",
              f"{statistics.median(walls['control']):.2f}× ({', '.join(f'{w:.2f}' for w in walls['control'])}; "
              f"{args.workers}× on an idle machine)")]
    for extra, walls_ in creep.items():
        if walls_:
            rows += [(f"`rollqp {' '.join(CREEP)}{extra}` (whole command, new process; median)",
                      f"{statistics.median(walls_):.2f} s ({', '.join(f'{w:.2f}' for w in walls_)})")]
    rows += [("load average at the end", " / ".join(f"{v:.2f}" for v in os.getloadavg()))]
    print()
    print(harness.table(["", "value"], rows))


if __name__ == "__main__":
    main()
