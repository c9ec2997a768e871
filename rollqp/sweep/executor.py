"""Running independent rollqp jobs on dask.distributed: the cluster, the per-point task, the sweep loop.

* :func:`connect` gives a ``Client``: a ``LocalCluster`` with one single-threaded worker
  process per core by default, or an existing cluster's scheduler (``--scheduler ADDRESS``),
  reached within a short timeout or refused with a one-line :class:`~rollqp.errors.InputError`.
* :func:`compute_point` is the task: a scene (as its plain dict) run by :func:`rollqp.run`
  with BLAS pinned to one thread inside the task (``threadpoolctl``; a worker started by hand
  gets the same pinning as the local ones), returning its result arrays and wall time, or its
  one-line error.
* :func:`run_sweep` submits the points not yet in the store, writes each result into its
  region as it arrives (:class:`rollqp.sweep.dataset.StoreWriter`, in the client process: the
  store needs no shared file system), shows progress, and returns a :class:`Summary`.
* :func:`map_jobs` runs any picklable function over independent cases (the benchmark harness
  and the hard-case suite): one task per worker at a time, so a timed case never shares its
  core with another case of the same run.
"""
from __future__ import annotations

import os
import socket
import sys
import time
from dataclasses import dataclass, field

from ..errors import InputError

__all__ = ["connect", "close_client", "compute_point", "run_sweep", "iter_jobs", "map_jobs", "Summary", "CONNECT_TIMEOUT"]

#: Seconds to reach a scheduler given by ``--scheduler`` before giving up.
CONNECT_TIMEOUT = 5.0
#: Most local worker processes per core (each is a Python process of ~100 MB; more than one per
#: core only shares the cores, it never adds throughput).
MAX_WORKERS_PER_CORE = 4
#: BLAS/OpenMP thread variables set to 1 in the local workers' environment.
_THREAD_ENV = {k: "1" for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}


def _dask():
    try:
        import distributed
    except ImportError as exc:  # pragma: no cover - the extra is missing
        from ..errors import MissingBackendError
        raise MissingBackendError("sweeps need dask.distributed: pip install 'rollqp[sweep]'") from exc
    return distributed


def connect(scheduler: str | None = None, workers: int | None = None, timeout: float = CONNECT_TIMEOUT):
    """A ``distributed.Client``: to ``scheduler`` (an address such as ``tcp://host:8786``), or to a
    new ``LocalCluster`` of ``workers`` single-threaded worker processes (default: one per core).

    Raises
    ------
    InputError
        ``--scheduler``: not reachable within ``timeout`` seconds; ``--workers``: not in
        [1, :data:`MAX_WORKERS_PER_CORE` × cores], or given with ``--scheduler``.
    """
    distributed = _dask()
    if scheduler is not None:
        if workers is not None:
            raise InputError("--workers", "applies to the local cluster only; the cluster at --scheduler has its own")
        try:
            return distributed.Client(scheduler, timeout=timeout)
        except (OSError, TimeoutError, ValueError) as exc:
            reason = str(exc).splitlines()[0][:160] if str(exc) else type(exc).__name__
            raise InputError("--scheduler", f"cannot reach a dask scheduler at {scheduler!r} within "
                                            f"{timeout:g} s ({reason})") from None
    cores = os.cpu_count() or 1
    n = cores if workers is None else workers
    if not isinstance(n, int) or isinstance(n, bool) or not 1 <= n <= MAX_WORKERS_PER_CORE * cores:
        raise InputError("--workers", f"must be an integer in [1, {MAX_WORKERS_PER_CORE * cores}] "
                                      f"({MAX_WORKERS_PER_CORE} per core of this machine), got {workers!r}")
    import dask
    # the workers' statistical profiler samples the task thread's stack every 10 ms: time
    # taken from the points (the GIL), for a profile nobody reads here
    with dask.config.set({"distributed.worker.profile.enabled": False}):
        cluster = distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                           dashboard_address=None, env=dict(_THREAD_ENV), silence_logs=50)
    return distributed.Client(cluster)


def compute_point(scene_dict: dict) -> dict:
    """Run one scene on a worker: ``{"arrays", "time", "worker"}``, or ``{"error", "time"}`` with its one-line error."""
    from threadpoolctl import threadpool_limits

    from ..errors import RollqpError
    from ..march import run
    from ..scene import scene_from_dict
    t0 = time.perf_counter()
    with threadpool_limits(limits=1):
        try:
            result = run(scene_from_dict(scene_dict))
        except RollqpError as err:
            return {"error": f"{type(err).__name__}: {err}".splitlines()[0], "time": time.perf_counter() - t0}
        except Exception as err:  # a bug, not an input: still one line, the sweep goes on
            return {"error": f"{type(err).__name__}: {err}".splitlines()[0], "time": time.perf_counter() - t0}
    arrays = result.arrays()
    arrays.pop("meta")
    return {"arrays": arrays, "time": time.perf_counter() - t0, "worker": f"{socket.gethostname()}:{os.getpid()}"}


@dataclass
class Summary:
    """What a sweep did: the points computed now, those kept from the store, the failures."""

    total: int
    kept: int = 0
    done: int = 0
    failed: list = field(default_factory=list)
    wall: float = 0.0
    point_times: list = field(default_factory=list)
    interrupted: bool = False

    @property
    def speedup(self) -> float:
        """Sum of the points' own times over the wall time of the sweep."""
        return sum(self.point_times) / self.wall if self.wall > 0 else float("nan")

    def table(self) -> str:
        """The summary table printed at the end of ``rollqp sweep``."""
        rows = [("points", str(self.total)), ("kept from the store", str(self.kept)),
                ("computed now", str(self.done)), ("failed", str(len(self.failed))),
                ("missing", str(self.total - self.kept - self.done - len(self.failed))),
                ("wall time", f"{self.wall:.2f} s"),
                ("sum of point times", f"{sum(self.point_times):.2f} s"),
                ("speed-up", f"{self.speedup:.2f}x" if self.point_times else "-")]
        w = max(len(k) for k, _ in rows)
        lines = [f"  {k:<{w}}  {v}" for k, v in rows]
        lines += [f"  failed: {label}: {msg}" for label, msg in self.failed]
        if self.interrupted:
            lines.append("  interrupted: the points above are stored; run the same command again for the rest")
        return "\n".join(lines)


def _bar(total: int, quiet: bool):
    """``update(n_done)`` and ``close()``: tqdm on a terminal, otherwise a line every few seconds."""
    if quiet:
        return (lambda n: None), (lambda: None)
    if sys.stderr.isatty():
        try:
            from tqdm import tqdm
            bar = tqdm(total=total, unit="point", leave=False, file=sys.stderr)
            return (lambda n: bar.update(1)), bar.close
        except ImportError:
            pass
    t0, last = time.perf_counter(), [0.0]
    every = float(os.environ.get("ROLLQP_PROGRESS_SECONDS", "5") or 5)

    def line(n):
        now = time.perf_counter()
        if now - last[0] >= every or n == total:
            last[0] = now
            print(f"rollqp: point {n}/{total} ({100.0 * n / max(total, 1):.0f} %), {now - t0:.1f} s",
                  file=sys.stderr, flush=True)

    return line, (lambda: None)


def run_sweep(sweep, group, status, client, quiet: bool = False, on_point=None) -> Summary:
    """Compute the points of ``sweep`` whose ``status`` is not done, writing each into ``group``.

    ``on_point(i, out)`` is called after each point is stored (tests, observers). Ctrl-C or
    SIGTERM cancels the points in flight and returns the summary with ``interrupted`` set:
    the stored points stay, and running the sweep again computes only the rest.
    """
    from .dataset import STATUS, StoreWriter
    distributed = _dask()
    todo = [i for i in range(len(sweep.scenes)) if status[i] != STATUS["done"]]
    summary = Summary(total=len(sweep.scenes), kept=len(sweep.scenes) - len(todo))
    update, close = _bar(len(todo), quiet)
    writer = StoreWriter(group, sweep)
    prefix = f"rollqp-point-{sweep.fingerprint()[:10]}-{time.time_ns()}"
    t0 = time.perf_counter()
    futures = {}
    try:
        for i in todo:
            fut = client.submit(compute_point, sweep.scenes[i].to_dict(), pure=False,
                                key=f"{prefix}-{i}")
            futures[fut] = i
        for n, fut in enumerate(distributed.as_completed(futures), 1):
            i = futures.pop(fut)
            out = fut.result()
            writer.write(i, out)
            if out.get("error") is None:
                summary.done += 1
            else:
                summary.failed.append((sweep.label(i), out["error"]))
            summary.point_times.append(out["time"])
            update(n)
            if on_point is not None:
                on_point(i, out)
    except KeyboardInterrupt:
        summary.interrupted = True
        client.cancel(list(futures))
    finally:
        close()
        summary.wall = time.perf_counter() - t0
    return summary


def iter_jobs(fn, jobs, client):
    """``fn(*job)`` for each job on ``client``'s cluster, yielded in the order of ``jobs`` as they finish."""
    futures = [client.submit(fn, *job, pure=False) for job in jobs]
    try:
        for fut in futures:
            yield fut.result()
    finally:
        client.cancel([f for f in futures if not f.done()])


def map_jobs(fn, jobs, workers: int | None = None, scheduler: str | None = None, client=None):
    """``[fn(*job) for job in jobs]`` on a dask cluster, in order; one job per worker at a time.

    Every worker is single-threaded (``threads_per_worker=1``), so a worker runs one job at a
    time and, with no more workers than cores, each timed job has a core of its own. ``fn``
    must be importable by the workers (a module-level function). Exceptions are re-raised here.
    """
    own = client is None
    client = client or connect(scheduler, workers)
    try:
        return list(iter_jobs(fn, jobs, client))
    finally:
        if own:
            close_client(client)


def close_client(client) -> None:
    """Close a client and, if it made one, its local cluster."""
    cluster = getattr(client, "cluster", None)
    client.close()
    if cluster is not None:
        cluster.close()
