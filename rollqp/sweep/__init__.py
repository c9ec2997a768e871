"""Parameter studies on dask.distributed, results as labelled xarray datasets in a zarr store.

``rollqp sweep SCENE --vary KEY=VALUES ... [--out STORE] [--scheduler ADDRESS] [--workers N]``
and ``rollqp creep-curve``; docs/sweeps.md. The package needs the ``sweep`` extra (dask
[distributed], xarray, zarr), imported only here: ``import rollqp`` stays light.

Modules: :mod:`.spec` (the ``--vary`` grammar and the validated points), :mod:`.dataset` (the
dataset schema, the zarr store, :func:`open_result`), :mod:`.executor` (the cluster, the task,
the sweep loop), :mod:`.creep` (the creep-curve preset).
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..result import OutputLock
from .dataset import check_store_path, open_result, open_store, points_per_chunk
from .executor import Progress, close_client, connect, run_sweep
from .spec import MAX_POINTS, Axis, Sweep, build_sweep, parse_vary

__all__ = ["sweep", "prepare", "Axis", "Sweep", "build_sweep", "parse_vary", "open_result", "VALIDATION_PROGRESS_AFTER"]


def prepare(scene, vary, out, quiet=True):
    """``(sweep, store path)``: every point and the store checked before any work.

    The store is refused if it holds another sweep; the points' methods must be installed.
    Unless ``quiet``, a sweep whose validation takes more than a second shows its progress.
    """
    bar = Progress(0, "validated point", quiet, after=VALIDATION_PROGRESS_AFTER)
    try:
        sw = build_sweep(scene, vary, progress=bar)
    finally:
        bar.close()
    path = check_store_path(out)
    open_store(path, sw)  # refuses a store of another sweep, before the cluster starts
    return sw, path


#: Seconds of validation after which a large sweep shows its progress (unless quiet).
VALIDATION_PROGRESS_AFTER = 1.0


def sweep(scene, vary, out, *, scheduler=None, workers=None, client=None, quiet=True, on_point=None,
          per_chunk=None):
    """Run a sweep into the zarr store ``out``; return the :class:`~.executor.Summary`.

    Parameters
    ----------
    scene : Scene, str or path
        The base scene.
    vary : sequence of str or Axis
        ``"KEY=VALUES"`` strings (:mod:`.spec`) or :class:`Axis` objects.
    out : str or path
        The store (``*.zarr``): created, or continued if it holds this sweep (only the points
        not yet done are computed; nothing stored is overwritten).
    scheduler, workers, client
        Where to run: an existing ``distributed.Client``, a scheduler address, or a new
        ``LocalCluster`` of ``workers`` processes (default one per core).
    quiet : bool
        No progress lines (validation of a large sweep, points computed).
    on_point : callable, optional
        ``on_point(i, out)`` after point ``i`` is stored.
    per_chunk : int, optional
        Points per chunk of a new store, and so per task (default
        :func:`~.dataset.points_per_chunk`: ⌈√(N/workers)⌉ of N points, raised to a divisor of the last axis's length within twice that, at most 32); a
        store that exists keeps its own.
    """
    import time

    if per_chunk is not None and (not isinstance(per_chunk, int) or isinstance(per_chunk, bool)
                                  or not 1 <= per_chunk <= MAX_POINTS):
        raise InputError("per_chunk", f"must be an integer in [1, {MAX_POINTS}], got {per_chunk!r}")
    t0 = time.perf_counter()
    sw, path = prepare(scene, vary, out, quiet=quiet)
    prepared = time.perf_counter() - t0
    with OutputLock(path):
        own = client is None
        t1 = time.perf_counter()
        client = client or connect(scheduler, workers)  # an unreachable scheduler: nothing written
        startup = time.perf_counter() - t1 if own else 0.0
        try:
            t2 = time.perf_counter()
            opened, create = open_store(path, sw), None
            if opened is None:  # made by run_sweep, on a local cluster while the first points compute
                n = per_chunk or points_per_chunk(sw, max(len(client.scheduler_info()["workers"]), 1))
                group, status = None, np.zeros(sw.size, dtype="int8")
                create = (path, n)
            else:
                group, status = opened
            prepared += time.perf_counter() - t2
            summary = run_sweep(sw, group, status, client, quiet=quiet, on_point=on_point, create=create)
            summary.startup, summary.prepare = startup, summary.prepare + prepared
            return summary
        finally:
            if own:
                close_client(client)
