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

from ..errors import InputError, RollqpError
from .dataset import open_result
from .spec import Axis, Sweep, build_sweep, parse_vary

__all__ = ["sweep", "prepare", "Axis", "Sweep", "build_sweep", "parse_vary", "open_result"]


def prepare(scene, vary, out):
    """``(sweep, store path)``: every point and the store checked before any work.

    The store is refused if it holds another sweep; the point's method must be installed.
    """
    from ..methods import method_class
    from .dataset import check_store_path, open_store
    sw = build_sweep(scene, vary)
    for i, s in enumerate(sw.scenes):
        try:
            method_class(s.solver.method)
        except RollqpError as err:
            raise InputError("--vary", f"point {i} ({sw.label(i)}): {err}") from None
    path = check_store_path(out)
    open_store(path, sw)  # refuses a store of another sweep, before the cluster starts
    return sw, path


def sweep(scene, vary, out, *, scheduler=None, workers=None, client=None, quiet=True, on_point=None):
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
    """
    from ..result import OutputLock
    from .dataset import create_store, open_store
    from .executor import close_client, connect, run_sweep
    sw, path = prepare(scene, vary, out)
    with OutputLock(path):
        own = client is None
        client = client or connect(scheduler, workers)  # an unreachable scheduler: nothing written
        try:
            opened = open_store(path, sw)
            if opened is None:
                group, status = create_store(path, sw), np.zeros(len(sw.scenes), dtype="int8")
            else:
                group, status = opened
            return run_sweep(sw, group, status, client, quiet=quiet, on_point=on_point)
        finally:
            if own:
                close_client(client)
