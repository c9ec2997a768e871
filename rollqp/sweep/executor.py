"""Running independent rollqp jobs on dask.distributed: the cluster, the tasks, the sweep loop.

* :func:`connect` gives a ``Client``: a ``LocalCluster`` with one single-threaded worker
  process per core by default (its dashboard off, its HTTP port chosen by the system, so a
  busy port 8787 changes nothing), or an existing cluster's scheduler (``--scheduler
  ADDRESS``), checked first by :func:`check_scheduler`.
* :func:`check_scheduler` accepts ``tcp://``, ``tls://`` (with a dask TLS configuration) and
  ``inproc://`` addresses, and before dask opens a connection it reads the peer's first
  message itself, at most :data:`HANDSHAKE_BYTES` within the timeout: a dask scheduler sends
  its handshake (a small msgpack table) as soon as it accepts, while any other service (an SSH
  server's banner, an HTTP server, silence) fails the check with a one-line
  :class:`~rollqp.errors.InputError`. Only then is the address given to dask, whose reader
  allocates whatever length a peer announces (``distributed.comm.tcp.TCP.read``): a peer that
  has answered as a dask scheduler is trusted as dask trusts it (it could as well send pickles).
* :func:`compute_points` is the task: some points of one chunk of the store, each scene
  (the base scene's dict and the point's changes) run by :func:`rollqp.run` with BLAS pinned
  to one thread for the task (``threadpoolctl``; a worker started by hand gets the same
  pinning as the local ones), each returning its result arrays and wall time, or its one-line error.
* :func:`run_sweep` submits one task per chunk of the store holding points not yet done
  (:meth:`rollqp.sweep.dataset.StoreWriter.tasks`), all in one message to the scheduler; each
  task's points are written as one write per variable for the whole chunk, ``status`` last. On
  a local cluster (whose workers share the client's disk) the worker that computed a chunk
  writes it (its writer made from the store's metadata file, no zarr array opened) and sends
  back only each point's status and times; the client's process, which also runs dask's
  scheduler, then spends its share of the two cores on little else. A cluster at ``--scheduler`` needs no shared file
  system: its workers send the arrays, and the client writes them as they arrive. The loop
  shows progress and returns a :class:`Summary`.
* :func:`map_jobs` runs any picklable function over independent cases (the benchmark harness
  and the hard-case suite): one task per worker at a time, so a timed case never shares its
  core with another case of the same run.
"""
from __future__ import annotations

import os
import socket
import struct
import sys
import time
from dataclasses import dataclass, field

from ..errors import InputError, MissingBackendError
from ..influence import Memo
from ..march import run
from ..scene import scene_from_dict
from ..threads import limited
from .dataset import Layout, StoreWriter, chunk_shape, chunk_tasks, create_store
from .spec import describe

__all__ = ["connect", "check_scheduler", "close_client", "InProcess", "compute_point", "compute_points", "run_sweep", "iter_jobs",
           "map_jobs", "Summary", "Progress", "CONNECT_TIMEOUT", "HANDSHAKE_BYTES"]

#: Seconds to reach a scheduler given by ``--scheduler`` (and read its handshake) before giving up.
CONNECT_TIMEOUT = 5.0
#: Most bytes of a scheduler's first message that :func:`check_scheduler` reads (dask's
#: handshake is ~60 bytes: its compression, Python version and pickle protocol).
HANDSHAKE_BYTES = 64 * 1024
#: Most local worker processes per core (each is a Python process of ~100 MB; more than one per
#: core only shares the cores, it never adds throughput).
MAX_WORKERS_PER_CORE = 4
#: Base scenes whose dict pickles to more bytes are sent to the workers once (scattered), not with every task.
SCATTER_BYTES = 64 * 1024
#: BLAS/OpenMP thread variables set to 1 in the local workers' environment.
_THREAD_ENV = {k: "1" for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}
_SCHEMES = ("tcp", "tls", "inproc")
#: dask settings of the local cluster (its processes read them when they start). The workers'
#: statistical profiler samples the task thread's stack every 10 ms: time taken from the points
#: (the GIL), for a profile nobody reads here. dask's own monitors (the event loops' tick, the
#: system monitor, the memory monitor) run less often than dask's defaults: an idle cluster's CPU
#: (docs/sweeps.md), which a machine shared by session (Linux's autogroup) takes from the points.
_LOCAL_CONFIG = {"distributed.worker.profile.enabled": False,
                 "distributed.admin.tick.interval": "200ms",
                 "distributed.admin.system-monitor.interval": "2s",
                 "distributed.worker.memory.monitor-interval": "1s"}


def _dask():
    try:
        import distributed
    except ImportError as exc:  # pragma: no cover - the extra is missing
        raise MissingBackendError("sweeps need dask.distributed: pip install 'rollqp[sweep]'") from exc
    return distributed


def _scheduler_error(address, reason: str) -> InputError:
    return InputError("--scheduler", f"{_short(address)}: {reason}")


def _tls_context():
    """The client's SSL context of dask's TLS configuration, or ``None`` when there is none."""
    from distributed.security import Security
    return Security().get_connection_args("client").get("ssl_context")


class _NotDask(ValueError):
    """The peer answered, but not as a dask scheduler."""


def _read_exactly(sock, n: int, deadline: float) -> bytes:
    data = b""
    while len(data) < n:
        left = deadline - time.monotonic()
        if left <= 0:
            raise _NotDask(f"it sent no complete dask handshake within the timeout ({len(data)} of {n} bytes)")
        sock.settimeout(left)
        try:
            part = sock.recv(min(n - len(data), 65536))
        except (socket.timeout, TimeoutError):
            part = None
        if part == b"":
            raise _NotDask(f"it closed the connection after {len(data)} bytes of a dask handshake")
        data += part or b""
    return data


def _handshake(sock, deadline: float) -> dict:
    """The peer's first dask message, read within ``deadline`` and :data:`HANDSHAKE_BYTES`."""
    from distributed.protocol import loads
    from distributed.protocol.utils import unpack_frames
    (n,) = struct.unpack("<Q", _read_exactly(sock, 8, deadline))
    if not 8 <= n <= HANDSHAKE_BYTES:
        raise _NotDask(f"its first message announces {n} bytes (a dask handshake has at most {HANDSHAKE_BYTES})")
    try:
        frames, rest = unpack_frames(_read_exactly(sock, n, deadline), partial=True)
        msg = loads(frames, deserialize=False) if frames and not rest else None
    except _NotDask:
        raise
    except Exception:  # any decoding error: the bytes are not dask's framing or msgpack
        msg = None
    if not isinstance(msg, dict) or "pickle-protocol" not in msg:
        raise _NotDask("its first message is not a dask handshake")
    return msg


def check_scheduler(address, timeout: float = CONNECT_TIMEOUT) -> str:
    """``address`` if it names a dask scheduler that answers as one within ``timeout`` seconds.

    Raises
    ------
    InputError
        ``--scheduler``: a scheme other than ``tcp://``, ``tls://`` (the latter only with a dask
        TLS configuration: ``distributed.comm.tls.*``) or ``inproc://``; a malformed host or
        port; nothing listening; or a peer whose first message is not a dask handshake (read
        here, at most :data:`HANDSHAKE_BYTES`, within the timeout).
    """
    if not isinstance(address, str) or not address.strip() or len(address) > 1000 or any(c.isspace() for c in address):
        raise _scheduler_error(str(address), "not an address such as tcp://HOST:8786")
    _dask()
    from distributed.comm.addressing import parse_address, parse_host_port
    scheme, loc = parse_address(address)
    scheme = scheme.lower()
    if scheme not in _SCHEMES:
        raise _scheduler_error(address, f"the scheme {scheme[:20]}:// is not supported (give tcp://HOST:PORT, "
                                        "or tls://HOST:PORT with a dask TLS configuration)")
    if scheme == "inproc":  # a scheduler in this very process: no socket, no peer
        from distributed.comm.inproc import global_manager
        try:
            found = global_manager.get_listener_for(loc)
        except (ValueError, TypeError):
            found = None
        if found is None:
            raise _scheduler_error(address, "no scheduler of this process listens there (inproc:// addresses "
                                            "reach only this very process)")
        return address
    context = _tls_context() if scheme == "tls" else None
    if scheme == "tls" and context is None:
        raise _scheduler_error(address, "tls:// needs a dask TLS configuration (distributed.comm.tls: ca-file, "
                                        "client cert and key); none is set")
    try:
        host, port = parse_host_port(loc)
        port = int(port)
    except (ValueError, TypeError) as exc:
        raise _scheduler_error(address, f"not HOST:PORT ({str(exc)[:80]})") from None
    if not host or not 0 < port < 65536:
        raise _scheduler_error(address, "needs a host and a port in [1, 65535]")
    deadline = time.monotonic() + timeout
    try:
        raw = socket.create_connection((host, port), timeout=timeout)
    except OSError as exc:  # refused, unreachable, unknown host, connect timeout
        reason = (str(exc).splitlines() or [""])[0][:120] or type(exc).__name__
        raise InputError("--scheduler", f"cannot reach a dask scheduler at {_short(address)} within {timeout:g} s "
                                        f"({reason})") from None
    try:
        with raw:
            sock = context.wrap_socket(raw) if context is not None else raw
            _handshake(sock, deadline)
    except _NotDask as exc:
        raise _scheduler_error(address, f"not a dask scheduler: {exc}") from None
    except OSError as exc:  # reset, TLS refused
        raise _scheduler_error(address, f"not a dask scheduler: {type(exc).__name__} while reading its "
                                        "handshake") from None
    return address


class InProcess:
    """What :func:`run_sweep` and :func:`iter_jobs` ask of a dask ``Client``, done in this process
    (``--workers 0``): each task runs when its result is asked for, one after another. No
    cluster to start and no dask imported: a sweep of a few seconds of points, or one on a
    machine whose cores are busy, is done sooner so (docs/sweeps.md)."""

    def scheduler_info(self) -> dict:
        return {"workers": {}}

    def submit(self, fn, *args, key=None, pure=None):
        return _Deferred(fn, args)

    def map(self, fn, *iterables, key=None, pure=None) -> list:
        return [_Deferred(fn, args) for args in zip(*iterables)]

    def scatter(self, data, **kwargs):
        return data

    def cancel(self, futures) -> None:
        pass

    def close(self) -> None:
        pass


class _Deferred:
    """A task of :class:`InProcess`: run once, when its result is first asked for."""

    def __init__(self, fn, args):
        self.fn, self.args, self.out = fn, args, None

    def result(self):
        if self.fn is not None:
            self.out, self.fn, self.args = self.fn(*self.args), None, None
        return self.out

    def done(self) -> bool:
        return self.fn is None


def connect(scheduler: str | None = None, workers: int | None = None, timeout: float = CONNECT_TIMEOUT):
    """A ``distributed.Client``: to ``scheduler`` (an address such as ``tcp://host:8786``, checked by
    :func:`check_scheduler`), or to a new ``LocalCluster`` of ``workers`` single-threaded
    worker processes (default: one per core); ``workers = 0``: an :class:`InProcess` client
    (the points run in this process, no cluster).

    Raises
    ------
    InputError
        ``--scheduler``: see :func:`check_scheduler`, or not reachable within ``timeout``
        seconds; ``--workers``: not in [1, :data:`MAX_WORKERS_PER_CORE` × cores], or given
        with ``--scheduler``.
    """
    if scheduler is None and workers == 0 and not isinstance(workers, bool):
        return InProcess()
    distributed = _dask()
    if scheduler is not None:
        if workers is not None:
            raise InputError("--workers", "applies to the local cluster only; the cluster at --scheduler has its own")
        address = check_scheduler(scheduler, timeout)
        try:
            return distributed.Client(address, timeout=timeout)
        except (OSError, TimeoutError, ValueError) as exc:
            reason = str(exc).splitlines()[0][:160] if str(exc) else type(exc).__name__
            raise InputError("--scheduler", f"cannot reach a dask scheduler at {_short(address)} within {timeout:g} s "
                                            f"({reason})") from None
    cores = os.cpu_count() or 1
    n = cores if workers is None else workers
    if not isinstance(n, int) or isinstance(n, bool) or not 1 <= n <= MAX_WORKERS_PER_CORE * cores:
        raise InputError("--workers", f"must be an integer in [0, {MAX_WORKERS_PER_CORE * cores}] "
                                      f"(0: in this process, no cluster; at most {MAX_WORKERS_PER_CORE} per core of "
                                      f"this machine), got {_short(workers)}")
    import dask
    with dask.config.set(_LOCAL_CONFIG):
        # no dashboard; the scheduler's HTTP server (which it always starts) on a port the
        # system picks, so that another cluster on 8787 makes no warning
        cluster = distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                           dashboard_address="127.0.0.1:0", scheduler_kwargs={"dashboard": False},
                                           env=dict(_THREAD_ENV), silence_logs=50)
        return distributed.Client(cluster)


def _short(value, n: int = 80) -> str:
    return describe(value, n)


#: What a worker process keeps of the bodies between the points it runs (the BEM's rollers: seconds
#: each, the same for every point that does not vary them), handed to each run; at most 8 kept.
_GEOMETRY = None


def _geometry():
    global _GEOMETRY
    if _GEOMETRY is None:
        _GEOMETRY = Memo(size=8)
    return _GEOMETRY


def compute_point(scene) -> dict:
    """Run one scene (a :class:`~rollqp.scene.Scene` or its dict) on a worker: ``{"arrays", "time",
    "cpu", "worker"}`` (wall and CPU seconds of the worker's process), or ``{"error", "time", "cpu",
    "worker"}`` with its one-line error."""
    with limited(1):  # scipy's BLAS loaded first, so that its pool is limited too (rollqp.threads)
        return _run_point(scene)


def _run_point(scene) -> dict:
    """:func:`compute_point` with BLAS already pinned (by the caller, once for a task's points)."""
    t0, c0 = time.perf_counter(), time.process_time()
    worker = f"{socket.gethostname()}:{os.getpid()}"
    try:
        result = run(scene_from_dict(scene) if isinstance(scene, dict) else scene, geometry=_geometry())
    except Exception as err:  # an input the method cannot run, or a bug: one line, the sweep goes on
        return {"error": f"{type(err).__name__}: {err}".splitlines()[0], "time": time.perf_counter() - t0,
                "cpu": time.process_time() - c0, "worker": worker}
    arrays = result.arrays()
    arrays.pop("meta")
    return {"arrays": arrays, "time": time.perf_counter() - t0, "cpu": time.process_time() - c0, "worker": worker}


#: The stores a worker writes into (path, fingerprint, its metadata file's inode and time) -> StoreWriter:
#: made once per sweep.
_WRITERS: dict = {}


def _writer(store):
    """The :class:`~rollqp.sweep.dataset.StoreWriter` of ``store = (path, fingerprint, keys, shape)``,
    made from the store's files (:meth:`~rollqp.sweep.dataset.StoreWriter.at`)."""
    path, fingerprint, keys, shape = store
    meta = os.stat(os.path.join(path, ".zmetadata"))  # a store made again at the same path is another store
    key = (path, fingerprint, meta.st_ino, meta.st_mtime_ns)
    if key not in _WRITERS:
        if len(_WRITERS) >= 4:
            _WRITERS.pop(next(iter(_WRITERS)))
        _WRITERS[key] = StoreWriter.at(path, Layout(keys, shape))
    return _WRITERS[key]


def compute_points(base, points, store=None) -> list:
    """The task: ``[compute_point(base.replace(**changes)) for _, changes in points]``.

    ``base`` is the sweep's base scene as its dict, ``points`` ``(index, changes)`` pairs; the
    scene of each point is built as the client validated it (``Scene.replace``). With ``store``
    (``(path, fingerprint, keys, shape)``: a worker that shares the client's disk), the points
    are written into their chunk of the store here, and each result is returned without its
    arrays, marked ``"written"``.
    """
    out = _compute_points(base, points)
    if store is not None:
        try:
            _writer(store).write([i for i, _ in points], out)
        except Exception:  # noqa: BLE001  (the store unreachable here: the client writes, or says why)
            return out
        for o in out:
            o.pop("arrays", None)
            o["written"] = True
    return out


def _compute_points(base, points) -> list:
    t0 = time.perf_counter()
    try:
        scene = scene_from_dict(base)
    except Exception as err:  # validated on the client: a worker of another rollqp version?
        msg = f"{type(err).__name__}: {err}".splitlines()[0]
        return [{"error": msg, "time": time.perf_counter() - t0} for _ in points]
    out = []
    with limited(1):  # once for the task, scipy's BLAS loaded first (rollqp.threads) (a few hundred microseconds each time)
        for _, changes in points:
            t1 = time.perf_counter()
            try:
                point = scene.replace(**changes)
            except Exception as err:
                out.append({"error": f"{type(err).__name__}: {err}".splitlines()[0], "time": time.perf_counter() - t1})
                continue
            out.append(_run_point(point))
    return out


@dataclass
class Summary:
    """What a sweep did: the points computed now, those kept from the store, the failures, the times.

    ``wall`` is the time of the points' phase (submission to the last write); ``startup`` the
    cluster's start (or the connection to ``--scheduler``), ``prepare`` the validation of the
    points and the store's creation (on a local cluster a new store is made while the first
    points compute: its time is then in ``wall``): their sum is the sweep's whole time.
    """

    total: int
    kept: int = 0
    done: int = 0
    failed: list = field(default_factory=list)
    wall: float = 0.0
    point_times: list = field(default_factory=list)
    point_cpu: list = field(default_factory=list)
    interrupted: bool = False
    startup: float = 0.0
    prepare: float = 0.0
    workers: int = 0
    per_chunk: int = 1

    @property
    def speedup(self) -> float:
        """Sum of the points' own times over the wall time of the points' phase."""
        return sum(self.point_times) / self.wall if self.wall > 0 else float("nan")

    def table(self) -> str:
        """The summary table printed at the end of ``rollqp sweep``."""
        rows = [("points", str(self.total)), ("kept from the store", str(self.kept)),
                ("computed now", str(self.done)), ("failed", str(len(self.failed))),
                ("missing", str(self.total - self.kept - self.done - len(self.failed))),
                ("workers", f"{self.workers or 'none, this process'} ({self.per_chunk} point{'s' if self.per_chunk > 1 else ''} "
                            "per task)"),
                ("validation and store", f"{self.prepare:.2f} s"),
                ("cluster start", f"{self.startup:.2f} s"),
                ("wall time of the points", f"{self.wall:.2f} s"),
                ("total", f"{self.prepare + self.startup + self.wall:.2f} s"),
                ("sum of point times", f"{sum(self.point_times):.2f} s"),
                ("speed-up", f"{self.speedup:.2f}x" if self.point_times else "-")]
        w = max(len(k) for k, _ in rows)
        lines = [f"  {k:<{w}}  {v}" for k, v in rows]
        lines += [f"  failed: {label}: {msg}" for label, msg in self.failed]
        if self.interrupted:
            lines.append("  interrupted: the points above are stored; run the same command again for the rest")
        return "\n".join(lines)


class Progress:
    """Counts ``what`` (points validated, points computed) on stderr: a tqdm bar on a terminal,
    else a line every ``$ROLLQP_PROGRESS_SECONDS`` (default 5) seconds and a last one; nothing
    when ``quiet``. A count that ends within ``after`` seconds shows nothing."""

    def __init__(self, total: int, what: str, quiet: bool = False, after: float = 0.0):
        self.total, self.what, self.quiet, self.after = total, what, quiet, after
        self.t0 = self.last = time.perf_counter()
        self.every = float(os.environ.get("ROLLQP_PROGRESS_SECONDS", "5") or 5)
        self.bar, self.shown = None, False

    def _tqdm(self):
        if self.bar is None and sys.stderr.isatty():
            try:
                from tqdm import tqdm
                self.bar = tqdm(total=self.total, unit="point", desc=self.what, leave=False, file=sys.stderr)
            except ImportError:
                self.bar = False
        return self.bar

    def __call__(self, n: int, total: int | None = None) -> None:
        if total is not None:
            self.total = total
        if self.quiet:
            return
        now = time.perf_counter()
        if now - self.t0 < self.after:
            return
        bar = self._tqdm()
        if bar:
            bar.n = n
            if now - self.last >= 0.1 or n == self.total:
                bar.refresh()
                self.last = now
            return
        if now - self.last >= self.every or n == self.total or not self.shown:
            self.last, self.shown = now, True
            print(f"rollqp: {self.what} {n}/{self.total} ({100.0 * n / max(self.total, 1):.0f} %), "
                  f"{now - self.t0:.1f} s", file=sys.stderr, flush=True)

    def close(self) -> None:
        if self.bar:
            self.bar.close()


def _shares_disk(client) -> bool:
    """The workers of ``client`` write on the client's disk: a ``LocalCluster``'s."""
    cluster = getattr(client, "cluster", None)
    return cluster is not None and isinstance(cluster, _dask().LocalCluster)


def _submit(client, sweep, tasks, store=None):
    """One future per task (chunk) -> its point indices; ``store``: where the workers write."""
    import pickle
    base = sweep.base.to_dict()
    if len(pickle.dumps(base)) > SCATTER_BYTES:  # a large table in the scene: sent once to every worker
        base = client.scatter(base, broadcast=True, hash=False)
    fingerprint = sweep.fingerprint()
    where = None if store is None else (str(store), fingerprint, sweep.keys, sweep.shape)
    prefix = f"rollqp-points-{fingerprint[:10]}-{time.time_ns()}"
    n = len(tasks)
    # one message to the scheduler for all the tasks (one graph), not one per task
    futures = client.map(compute_points, [base] * n, [[(i, sweep.changes(i)) for i in points] for points in tasks],
                         [where] * n, key=[f"{prefix}-{points[0]}" for points in tasks], pure=False)
    return dict(zip(futures, tasks))


def run_sweep(sweep, group, status, client, quiet: bool = False, on_point=None, create=None) -> Summary:
    """Compute the points of ``sweep`` whose ``status`` is not done, writing them into ``group``.

    One task per chunk of the store that holds points to do; each task's points are written
    together as the task finishes, by the worker when it shares the client's disk (a local
    cluster), else here. ``on_point(i, out)`` is called after each point is stored
    (tests, observers). Ctrl-C or SIGTERM cancels the tasks in flight and returns the summary
    with ``interrupted`` set: the stored points stay, and running the sweep again computes only
    the rest.

    A new store: ``group`` is None and ``create = (path, per_chunk)`` (:func:`~.dataset.create_store`).
    On a local cluster the tasks go out first and the store is made while the first points
    compute (a task that ends before the store exists sends its arrays, written here by a writer
    made then); else the store is made first.
    """
    as_completed = iter if isinstance(client, InProcess) else _dask().as_completed
    early = group is None and not isinstance(client, InProcess) and _shares_disk(client)
    made = time.perf_counter()
    if group is None and not early:
        create_store(create[0], sweep, create[1])
    made = time.perf_counter() - made
    if early:  # a store made by create_store is zarr-2 files on disk: the workers can write it
        writer, store = None, os.path.abspath(create[0])
        tasks = chunk_tasks(sweep.shape, chunk_shape(sweep.shape, create[1]), status)
    else:
        writer = StoreWriter(group, sweep) if group is not None else StoreWriter.at(create[0], sweep)
        tasks = writer.tasks(status)
        local = not isinstance(client, InProcess) and writer.on_disk and _shares_disk(client)
        store = writer.root if local else None
    todo = sum(len(t) for t in tasks)
    summary = Summary(total=sweep.size, kept=sweep.size - todo, workers=len(client.scheduler_info()["workers"]),
                      per_chunk=max((len(t) for t in tasks), default=1), prepare=made)
    bar = Progress(todo, "point", quiet)
    t0 = time.perf_counter()
    futures, n = {}, 0
    try:
        futures = _submit(client, sweep, tasks, store)
        if early:  # made while the first points compute; the workers write into it, the client only
            try:   # what a task sends back unwritten (its writer opened then)
                create_store(create[0], sweep, create[1])
            except BaseException:
                client.cancel(list(futures))
                raise
        for fut in as_completed(list(futures)):
            points = futures.pop(fut)
            outs = fut.result()
            if not all(o.get("written") for o in outs):
                writer = writer or StoreWriter.at(create[0], sweep)
                writer.write(points, outs)
            for i, out in zip(points, outs):
                if out.get("error") is None:
                    summary.done += 1
                else:
                    summary.failed.append((sweep.label(i), out["error"]))
                summary.point_times.append(out["time"])
                summary.point_cpu.append(out.get("cpu", float("nan")))
                if on_point is not None:
                    on_point(i, out)
            n += len(points)
            bar(n)
    except KeyboardInterrupt:
        summary.interrupted = True
        client.cancel(list(futures))
    finally:
        bar.close()
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
