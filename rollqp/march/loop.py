"""What the run of either discretization does the same way (docs/results.md): the loop of the step records into
the result (:func:`drive`), the states a resumed run keeps (:func:`keep_every`), and the checks of an earlier
part of a run before it is continued (:func:`check_last`, :func:`check_earlier`).

A discretization's march (:mod:`rollqp.march.strip`, :mod:`rollqp.march.grid`) hands these its own pieces — how
a stored state is read, how its step is solved again, what its fields are measured in — and gets the same
guarantees, messages and exit codes in both dimensions.
"""
from __future__ import annotations

import functools

import numpy as np

from ..errors import InputError, SolverError
from ..result import ResumeSource, _meta_of

__all__ = ["RESUME_TOL", "drive", "keep_every", "last_index", "stored_steps", "check_last", "check_earlier",
           "versions"]

#: A resumed state must equal its step solved again from the state before it to this fraction of p0
#: (pressures) and μp0 (tractions): ten thousand times the methods' tolerance (1e-10: two solutions
#: of a step from different warm starts agree to ~1e-10), far below any change to a state that matters.
RESUME_TOL = 1e-6


def drive(result, records, *, source=None, resumed_from=None, operators=None, observe=None, progress=None,
          steps: int = 0):
    """The run's loop, in either dimension: the ``records`` (an iterator of step records, started lazily) into
    ``result``, after the states of ``source`` (a resumed run's, :meth:`Result.resume
    <rollqp.result.Result.resume>`; ``resumed_from``: the index of its last one). ``observe(record,
    operators)`` with every record, ``progress(k, steps)`` after each rolling step. On a failure or a signal
    the result is finished with a note (``failed``, ``interrupted``: its completed states are written) and the
    error raised with ``err.partial``; call it inside :func:`rollqp.atomic.stop_once`, so that a second
    Ctrl-C never interrupts the writing of what the first one saves."""
    try:
        if source is not None:
            result.resume(source)
            result.meta["resumed_from"] = resumed_from
        for rec in records:
            result.add(rec, operators)
            if observe is not None:
                observe(rec, operators)
            if progress is not None and rec.k > 0:
                progress(rec.k, steps)
    except (SolverError, InputError, KeyboardInterrupt, MemoryError) as err:
        note = {"interrupted": "interrupted"} if isinstance(err, KeyboardInterrupt) else \
            {"failed": str(err) or type(err).__name__}
        try:
            result.finish(note)
        except KeyboardInterrupt:  # a signal held during the write: the file is written, the first one goes on
            pass
        err.partial = result
        raise
    try:
        return result.finish()
    except KeyboardInterrupt as err:  # a signal while the file was written: it is complete
        err.partial = result
        raise


def keep_every(asked, source) -> int:
    """``keep_every`` of a run: the resumed file's, which an explicit value must not contradict."""
    had = source.keep_every if isinstance(source, ResumeSource) else \
        _meta_of(source).get("keep_every", 1) if isinstance(source, dict) else None
    if had is not None and (isinstance(had, bool) or not isinstance(had, int) or had < 1):
        raise InputError("--resume", f"meta['keep_every'] must be a whole number >= 1, got {str(had)[:40]}")
    if asked is None:
        return had or 1
    if had is not None and asked != had:
        raise InputError("--keep-every", f"the resumed run keeps every {had}-th state; resume it with that "
                                         f"(or without --keep-every), got {asked!r}")
    return asked


def last_index(arrays) -> int:
    """The index k of the last stored state (``step`` if the file keeps only some states)."""
    return int(arrays["step"][-1]) if "step" in arrays else len(arrays["q"]) - 1


def stored_steps(arrays) -> np.ndarray:
    """The index of every stored state (``step``, or 0, 1, … when the file keeps every state)."""
    return np.asarray(arrays["step"]) if "step" in arrays else np.arange(len(arrays["q"]))


def check_last(arrays, *, stored, start, step, identical, differences, consistent=None, n_steps=None):
    """The state a resumed run continues from: the last stored state of ``arrays``, checked to solve its own step.

    The step is solved again from the state before it — ``start()`` for state 0, ``step(k)`` for a rolling
    step ``k`` from the stored state ``k − 1`` — as the uninterrupted run solved it. Equal to the stored state
    ``stored(-1)`` bit for bit (``identical(again, stored)``), it is the state the run continues from. Otherwise
    every ``(what, again, stored, scale, unit)`` of ``differences(again, stored)`` must agree to
    :data:`RESUME_TOL` of its scale, and ``consistent(stored)`` (``None``, or what is wrong with the state in
    itself) must find nothing; then the run continues from the stored state. Else the file was changed or is
    corrupt: a one-line :class:`InputError` on ``--resume``, nothing run. ``n_steps``: the scene's rolling steps
    (a file with more is another scene's).
    """
    k = last_index(arrays)
    if n_steps is not None and k > n_steps:
        raise InputError("--resume", f"the result file has {k} rolling steps, the scene {n_steps}")
    steps = stored_steps(arrays)
    last = stored(-1)
    try:
        if k == 0:
            again = start()
        elif steps.size >= 2 and int(steps[-2]) == k - 1:
            again = step(k)
        else:
            raise InputError("--resume", f"the result file does not hold the state before its last one ({k}), "
                                         "which it needs to be continued")
    except SolverError as err:
        raise InputError("--resume", f"the last state ({k}) cannot be checked: its step, solved again, failed "
                                     f"({str(err)[:120]})") from None
    if identical(again, last):
        return again
    for what, a, b, scale, unit in differences(again, last):
        if a is None or b is None:
            continue
        d = np.abs(np.asarray(a, dtype=float) - np.asarray(b, dtype=float)) / scale
        worst = float(np.max(d)) if np.all(np.isfinite(d)) else np.inf
        if not worst <= RESUME_TOL:
            raise InputError("--resume", f"the last state ({k}) does not solve its own step: solved again from the "
                                         f"state before it, its {what} differs by {worst:.3g} {unit} (more than "
                                         f"{RESUME_TOL:g}): the file was changed or is corrupt")
    bad = None if consistent is None else consistent(last)
    if bad:
        raise InputError("--resume", f"the last state ({k}): {bad}: the file was changed or is corrupt")
    return last


def check_earlier(source, names, inconsistent, rows: int = 256) -> None:
    """Every stored state of ``source`` (a :class:`~rollqp.result.ResumeSource`, or a result file's arrays)
    consistent in itself, a block of states at a time (the arrays ``names``; a journal's blocks are read from
    disk one after the other, never all at once): ``inconsistent(block, k)`` (``k``: the blocks' state indices)
    gives ``None`` or what is wrong, ``"state 12: …"`` or a description of the block. A state that is not is a
    changed or corrupt file: a one-line :class:`InputError` on ``--resume``, before anything is run or written."""
    blocks = source.blocks(names) if isinstance(source, ResumeSource) else _array_blocks(source, names, rows)
    seen = 0
    for b in blocks:
        m = len(b[names[0]])
        k = np.asarray(b["step"]) if "step" in b else np.arange(seen, seen + m)
        bad = inconsistent(b, k)
        if bad:
            where = bad if bad.startswith("state") else f"a state of the file: {bad}"
            raise InputError("--resume", f"{where}: the file was changed or is corrupt")
        seen += m


def _array_blocks(arrays, names, rows: int):
    K1 = len(arrays["q"])
    for i in range(0, K1, rows):
        yield {k: np.asarray(arrays[k][i:i + rows]) for k in names if k in arrays}


@functools.lru_cache(maxsize=1)
def _installed_versions() -> tuple:
    """The versions recorded in every result's meta, read once per process (importlib.metadata
    scans sys.path: ~5 ms, more than the stepping of a small scene)."""
    import importlib.metadata as md
    out = {}
    for pkg in ("numpy", "scipy", "clarabel", "osqp", "cvxpy"):
        try:
            out[pkg] = md.version(pkg)
        except md.PackageNotFoundError:
            out[pkg] = None
    return tuple(out.items())


def versions() -> dict:
    """The package versions recorded in a result's meta (``meta["versions"]``)."""
    return dict(_installed_versions())
