"""The result of a run (docs/results.md): its states as they are computed, and the result file.

:class:`Result` receives one :class:`~rollqp.march.StepRecord` per state (:meth:`Result.add`)
and keeps what the result file needs of it: the core fields, the fields computed from the record
(``Field.compute``) and the step's length and phase. The fields derived from stored ones
(``Field.derive``: the frictional power and work, the load work, the wear rates) are computed in
bulk, a block of states at a time, when the arrays are made (:meth:`Result.arrays`, the result
file), never per step. Where the states go:

* in memory (the default of :func:`rollqp.run`): :meth:`Result.arrays` returns them;
* to a journal (``run(..., out=PATH)`` and ``rollqp run``): each state is appended to
  ``PATH.journal`` as it is completed (:mod:`rollqp.journal`), nothing is kept in memory, and
  :meth:`Result.finish` writes the result file from the journal a block of rows at a time and
  removes the journal. A run killed at any moment (SIGKILL) loses at most the state in flight;
  ``rollqp run --resume PATH`` continues from the journal (:func:`resume_source`).

With ``keep_every = k`` a result keeps the states ``0, k, 2k, …`` and the last two; a step field
of a kept state combines the steps since the previous kept one (``Field.reduce``: works, times
and iteration counts are summed, the residual is the largest, the rest is the state's own), so
that sums over the run stay right.
"""
from __future__ import annotations

import json
import os
import weakref
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .atomic import (META_ARRAY_MIN, MAX_META_ARRAY, TEMP_PREFIX, OutputLock, alive, decode_meta,  # noqa: F401
                     encode_meta, held_signals, remove_stale_temporaries, replace, save_npz, temporary, written)
from .errors import InputError
from .fields import FIELDS, Rows, dtype_of, node_shape, registry
from .journal import Journal, SUFFIX, journal_path, json_default as _json_default, layout_of
from .npzfile import NpzStream, read_npz, real_scalar, text_value

__all__ = ["Result", "Layout", "STRIP", "load_result", "save_npz", "check_output", "resume_source", "OutputLock", "TEMP_PREFIX",
           "remove_stale_temporaries", "encode_meta", "decode_meta"]

#: The core fields read off each record (:mod:`rollqp.fields` documents them).
_PER_STATE = ("pn", "pt", "slip", "gap", "state")
_PER_STEP = ("q", "P", "Q", "creepage", "approach", "shift", "iterations", "step_time", "residual",
             "inner_normal", "inner_tangential", "backtracks", "step")
#: What the derived fields read besides stored fields: the step's length (``_dq``, 0 for the
#: starting state) and whether it rolled (``_rolling``). Kept in the journal, not in the file.
_HIDDEN = ("_dq", "_rolling")
_HIDDEN_DTYPES = {"_dq": "<f8", "_rolling": "|i1"}
#: Stored members of a result file larger than this are memory-mapped, not read (bytes): a long run's
#: file is read without its states filling the memory (the pages a reader touches are read in).
MAP_ABOVE = 1 << 20
#: Bytes of rows the result file is written in, and read in to be checked.
BLOCK_BYTES = 2 << 20


#: Longest ``meta`` text read: a valid scene file (16 MiB of TOML: ``rollqp.scene.io.MAX_FILE_BYTES``, its long
#: lists stored as arrays) and 1 MiB for the model's data, versions and notes (a test holds them equal).
META_LIMIT = (16 << 20) + (1 << 20)




@dataclass(frozen=True)
class Layout:
    """What a result of one discretization keeps of each state: its field registry
    (:func:`rollqp.fields.registry`), the core fields read off each record (``core``), the fields kept in the
    journal only for the derived ones (``hidden``, with their dtypes) and ``read(record, operators) ->
    (values, notes)``: the core fields' values of a record and its notes for ``meta``."""

    dimension: int
    core: tuple
    read: Callable
    hidden: tuple = ()

    @property
    def fields(self) -> dict:
        return registry(self.dimension)


#: The notes of an earlier part of a run that a resumed run keeps in ``meta``.
_CARRIED = ("gross_sliding", "rolling_start", "start_note", "static_shift", "raw_distance")


class Result:
    """States of a transient: index 0 is the starting state, then the rolling steps (every
    ``keep_every``-th one and the last two if ``keep_every > 1``).

    The arrays are the result file's (docs/results.md; every key is a :class:`rollqp.fields.Field`):
    the core fields read off each :class:`~rollqp.march.StepRecord` (:meth:`add`), the computed and
    derived fields the scene needs (``extra``: :func:`rollqp.fields.fields_for`), ``scalars``
    (``a_H``, ``p0``, ``R``, ``Estar``, ``beta``, ``leading_edge``) and ``meta`` (JSON-able).
    ``constants`` are what derived fields read besides the states (``"f"``, the nodes' weights;
    ``"wear_A"``, ``"wear_B"``). With ``out`` the states go to ``out``'s journal, and
    :meth:`finish` writes the result file ``out`` (module docstring).
    """

    def __init__(self, x, scalars: dict, meta: dict, extra=(), *, constants=None, keep_every: int = 1,
                 out=None, operators=None, layout: Layout | None = None, coords: dict | None = None):
        if isinstance(keep_every, bool) or not isinstance(keep_every, (int, np.integer)) or not 1 <= keep_every <= 10**9:
            raise InputError("keep_every", f"must be a whole number >= 1, got {keep_every!r}")
        self.layout = STRIP if layout is None else layout
        self.fields = self.layout.fields
        self.coords = {k: np.asarray(v, dtype=float) for k, v in (coords or {"x": x}).items()}
        self.x = self.coords["x"]
        self.node_shape = node_shape(self.fields, {k: v.size for k, v in self.coords.items()})
        self.scalars, self.meta, self.extra = dict(scalars), meta, list(extra)
        self.keep_every = int(keep_every)
        self.meta["keep_every"] = self.keep_every
        self.meta["dimension"] = self.layout.dimension
        self.constants = {k: np.asarray(v) for k, v in (constants or {}).items()}
        self.out = None if out is None else os.fspath(out)
        self._ops = None if operators is None else weakref.ref(operators)
        self.names = list(self.layout.core) + [f.name for f in self.extra]
        self.stored = [n for n in self.names if self.fields[n].derive is None] + list(self.layout.hidden)
        self._store = _Memory(self) if out is None else _Journaled(self)
        self._cache = None

    # ------------------------------------------------------------------ adding states
    def add(self, rec, operators=None) -> None:
        """Append the state of a :class:`~rollqp.march.StepRecord` (``rec.k`` must be the next index);
        the fields computed from records use the scene's ``operators``."""
        ops = operators if operators is not None else (self._ops() if self._ops is not None else None)
        if rec.k != self.steps:
            raise ValueError(f"record {rec.k} appended as state {self.steps}")
        values, notes = self.layout.read(rec, ops)
        for f in self.extra:
            if f.compute is not None:
                values[f.name] = f.compute(rec, ops)
        values["step"] = rec.k
        solver = notes.pop("solver", None)
        _apply_notes(self.meta, rec.k, notes)
        if solver is not None:  # what the method carries to the next step (journal only: rollqp.solverstate)
            notes["solver"] = solver
        self._store.append(values, notes)
        self._cache = None

    def extend(self, arrays: dict) -> None:
        """Append every state of a result file's ``arrays`` (an earlier part of the same run, checked by
        :func:`load_result`); its notes (``gross_sliding``, ``rolling_start``, ``start_note``) are kept."""
        meta = _meta_of(arrays)
        for k in _CARRIED:
            if k in meta:
                self.meta[k] = meta[k]
        missing = [k for k in self.names if k not in arrays and k != "step"]
        if missing:
            raise InputError("--resume", f"the result file lacks {', '.join(missing)}: not written by this "
                                         "version of rollqp for this scene")
        steps = np.asarray(arrays["step"]) if "step" in arrays else np.arange(len(arrays["q"]))
        for i in range(len(arrays["q"])):
            self._store.import_row({k: (arrays[k][i] if k != "step" else steps[i]) for k in self.names})
        self._cache = None

    def resume(self, source) -> None:
        """Start from the states of an earlier part of this run: a :class:`ResumeSource` (its journal is
        continued, or its result file's states imported) or the arrays of a result file."""
        if isinstance(source, dict):
            return self.extend(source)
        for k in _CARRIED:
            if k in source.meta:
                self.meta[k] = source.meta[k]
        store = self._store
        if source.journal is not None and isinstance(store, _Journaled):
            store.continue_journal(source.journal)
        elif source.journal is not None:
            self.extend(_assemble(source.journal, self, None) | {"meta": {}})
        else:
            for row in source.rows(self.names):
                store.import_row(row)
        self._cache = None

    @property
    def steps(self) -> int:
        """The states computed so far (the index of the next one)."""
        return self._store.steps

    def __len__(self) -> int:
        """The states the result holds (all computed ones unless ``keep_every > 1``)."""
        return self._store.stored

    # ------------------------------------------------------------------ the arrays
    def arrays(self) -> dict:
        """All arrays of the result file, keyed as in docs/results.md (``meta`` as its JSON text)."""
        if self._cache is None:
            self._cache = self._store.arrays()
        return self._cache

    def __getitem__(self, key):
        return self.arrays()[key]

    @property
    def rows(self) -> dict:
        """The per-state and per-step arrays by name (``arrays()`` without ``x``, scalars and ``meta``)."""
        a = self.arrays()
        return {k: a[k] for k in self.names if k in a}

    def save(self, path) -> str:
        """Write the result file ``path`` atomically (signals held back while it is written)."""
        return self._store.save(path)

    def finish(self, notes: dict | None = None) -> "Result":
        """The run is over: ``notes`` (``failed``, ``interrupted``) go into ``meta``; with a journal, the
        result file is written from it and the journal removed, and the result reads from the file
        from now on. A SIGINT or SIGTERM that arrived during the write is raised again after it."""
        self.meta.update(notes or {})
        self._store.finish()
        self._cache = None
        return self


def _read_strip(rec, ops) -> tuple[dict, dict]:
    """The core fields and notes of a 2D :class:`~rollqp.march.StepRecord` (:data:`STRIP`)."""
    st, c, tsol = rec.state, rec.counters, rec.state.tsol
    values = dict(pn=st.p, pt=st.t, slip=tsol.s, gap=st.nsol.g, state=rec.nodes, q=rec.q, P=rec.P, Q=rec.Q,
                  creepage=tsol.xi, approach=st.nsol.delta, shift=rec.shift, iterations=c.iterations,
                  step_time=rec.step_time, residual=c.residual, inner_normal=c.inner_normal,
                  inner_tangential=c.inner_tangential, backtracks=c.backtracks, step=rec.k)
    values["_dq"] = _step_length(rec)
    values["_rolling"] = rec.phase == "rolling" and st.p is not None
    notes = {}
    if rec.gross_sliding:  # possible with a prescribed creepage beyond the sliding creepage
        notes["gross_sliding"] = True
    if rec.k == 0 and rec.phase in ("steady", "rolling"):
        notes["rolling_start"] = "direct steady solve" if rec.phase == "steady" else "marching to steady state"
    if rec.note is not None:
        notes["start_note"] = rec.note
    if rec.solver is not None:
        notes["solver"] = rec.solver
    return values, notes


#: The strip's result (a 2D scene): :data:`rollqp.fields.FIELDS`.
STRIP = Layout(2, _PER_STATE + _PER_STEP, _read_strip, _HIDDEN)


def _meta_of(arrays: dict) -> dict:
    """The ``meta`` of a result's arrays as a dict (``arrays()`` holds its JSON text, :func:`load_result` the dict)."""
    meta = arrays.get("meta", {})
    if isinstance(meta, dict):
        return meta
    try:
        meta = json.loads(str(meta))
    except (json.JSONDecodeError, RecursionError):
        raise InputError("--resume", "key 'meta' must be a JSON object") from None
    if not isinstance(meta, dict):
        raise InputError("--resume", "key 'meta' must be a JSON object")
    return meta


def _step_length(rec) -> float:
    """The length the step's slip is per (``Δq_k``, ``Δ = a_H`` for a step at rest, 0 for the start;
    :func:`rollqp.energy.friction_work`)."""
    if rec.k == 0 or rec.problem is None or rec.phase not in ("rolling", "static-shift"):
        return 0.0
    return float(rec.problem.dq)


def _apply_notes(meta: dict, k: int, notes: dict) -> None:
    for key, value in notes.items():
        if key == "solver":  # the method's record, for a resumed march (rollqp.solverstate), not the file's
            continue
        if key == "gross_sliding":
            meta.setdefault("gross_sliding", []).append(int(k))
        else:
            meta[key] = value


# =========================================================================== combining states
class _Thinning:
    """Which states a result keeps (``k % keep == 0`` and the last two) and the step fields of the kept
    ones, combined over the steps in between (``Field.reduce``), fed in order a block at a time."""

    def __init__(self, names, keep: int, fields=FIELDS):
        self.names, self.keep, self.fields = list(names), keep, fields
        self.pending = {}  # the combined values of steps fed since the last kept one

    def feed(self, steps: np.ndarray, values: dict, last_two: bool) -> tuple[np.ndarray, dict]:
        """``(kept, combined)``: the block's kept rows (indices) and their step fields; ``last_two``:
        the block ends the run (its last two rows are kept)."""
        keep = steps % self.keep == 0
        if last_two:
            keep[-2:] = True
        kept = np.flatnonzero(keep)
        out = {}
        for name in self.names:
            v, how = np.asarray(values[name]), self.fields[name].reduce
            if how == "last":
                out[name] = v[kept]
                continue
            if kept.size:
                starts = np.concatenate(([0], kept[:-1] + 1))
                seg = (np.add if how == "sum" else np.maximum).reduceat(v[:kept[-1] + 1], starts)
                if name in self.pending:
                    seg[0] = _combine(how, self.pending.pop(name), seg[0])
                out[name] = seg
                rest = v[kept[-1] + 1:]
            else:
                out[name], rest = v[:0], v
            if rest.size:
                r = rest.sum() if how == "sum" else np.maximum.reduce(rest)
                self.pending[name] = _combine(how, self.pending[name], r) if name in self.pending else r
        return kept, out


def _combine(how, a, b):
    return a + b if how == "sum" else np.maximum(a, b)


def _step_names(names, fields=FIELDS) -> list:
    return [n for n in names if fields[n].shape == "step"]


def _state_names(names, fields=FIELDS) -> list:
    return [n for n in names if fields[n].shape == "state"]


def _block_rows(rows: Rows, names) -> dict:
    return {n: rows[n] for n in names}


# =========================================================================== in memory
class _Memory:
    """States kept in memory: the rows of the stored fields, grown by doubling. With ``keep_every > 1``
    the oldest rows are combined into the kept ones a block at a time (:class:`_Thinning`), so that only
    the kept states stay. The rows of an earlier part (:meth:`Result.extend`) come first, combined already."""

    BLOCK = 256

    def __init__(self, result: Result):
        self.r = result
        self.cols, self.n, self.base = {}, 0, 0   # raw rows: states base .. base + n - 1
        self.before = {}                           # the last row combined, for Rows.before
        self.out = {name: [] for name in result.names}
        self.committed = 0                         # kept rows in self.out
        self.thin = _Thinning(_step_names(result.names, result.fields), result.keep_every, result.fields)
        self.imported = []                         # rows of an earlier part (every field, combined)
        self.next_step = 0

    @property
    def steps(self) -> int:
        return self.next_step

    @property
    def stored(self) -> int:
        if self.r.keep_every == 1:
            return self.committed + len(self.imported) + self.n
        idx = np.concatenate([np.array([int(r["step"]) for r in self.imported], dtype=np.int64),
                              self.cols["step"][:self.n] if self.cols else np.zeros(0, np.int64)])
        keep = idx % self.r.keep_every == 0
        keep[-2:] = True
        return self.committed + int(keep.sum())

    def import_row(self, row: dict) -> None:
        if self.n or self.base:
            raise ValueError("an earlier part is imported before any state is added")
        self.imported.append({k: np.array(v, copy=True) for k, v in row.items()})
        self.next_step = int(row["step"]) + 1

    def append(self, values: dict, notes: dict) -> None:
        if self.imported:
            self._commit(self._imported_block(), last_two=False)
        if not self.cols:
            for name in self.r.stored:
                v = np.asarray(values[name])
                self.cols[name] = np.empty((16,) + v.shape, dtype=_HIDDEN_DTYPES.get(name) or dtype_of(name, self.r.fields))
        if self.n == next(iter(self.cols.values())).shape[0]:
            for name, a in self.cols.items():
                self.cols[name] = np.concatenate([a, np.empty_like(a)])
        for name, a in self.cols.items():
            a[self.n] = values[name]
        self.n += 1
        self.next_step = int(values["step"]) + 1
        if self.r.keep_every > 1 and self.n >= 2 * self.BLOCK:
            self._commit(self._raw_block(self.BLOCK), last_two=False)

    # ------------------------------------------------------------------ blocks
    def _imported_block(self):
        """``(rows, steps, m, drop)`` of the imported rows (every field stored, nothing derived)."""
        rows = self.imported
        cols = {k: np.stack([np.asarray(r[k]) for r in rows]) for k in self.r.names}

        def drop():
            self.before = {k: v[-1] for k, v in cols.items()}
            self.imported = []
        return Rows(cols.get, len(rows), self.r.constants, None, self.r.fields), cols["step"], len(rows), drop

    def _raw_block(self, m: int):
        """``(rows, steps, m, drop)`` of the oldest ``m`` raw rows, their predecessor from ``self.before``."""
        cols, before = self.cols, self.before

        def read(name):
            return cols[name][:m] if name in cols else None

        def read_before(name):
            first = before.get(name)
            first = np.full(cols[name].shape[1:], np.nan) if first is None else np.asarray(first, dtype=float)
            return np.concatenate([first[None], cols[name][:m - 1]])

        def drop():
            self.before = {k: v[m - 1].copy() for k, v in cols.items()}
            for name, a in cols.items():
                cols[name] = a[m:].copy()
            self.base += m
            self.n -= m
        return Rows(read, m, self.r.constants, read_before, self.r.fields), cols["step"][:m], m, drop

    def _combine(self, block, last_two: bool, thin: _Thinning) -> dict:
        rows, steps, m, _ = block
        names, fields = self.r.names, self.r.fields
        kept, out = thin.feed(np.asarray(steps), _block_rows(rows, _step_names(names, fields)), last_two)
        out.update({n: rows[n][kept] for n in _state_names(names, fields)})
        return out

    def _commit(self, block, last_two: bool) -> None:
        if block[0].m == 0:
            return
        out = self._combine(block, last_two, self.thin)
        for name in self.r.names:
            self.out[name].append(out[name])
        self.committed += len(out["step"])
        block[3]()

    # ------------------------------------------------------------------ the arrays
    def arrays(self) -> dict:
        r = self.r
        parts = {name: list(v) for name, v in self.out.items()}
        thin = _copy_thinning(self.thin)
        if self.imported:
            tail = self._combine(self._imported_block(), last_two=True, thin=thin)
        elif self.n:
            tail = self._combine(self._raw_block(self.n), last_two=True, thin=thin)
        else:
            tail = {}
        for n, v in tail.items():
            parts[n].append(v)
        out = dict(r.coords)
        for name in r.names:
            f = r.fields[name]
            chunks = [np.asarray(c, dtype=dtype_of(name, r.fields)) for c in parts[name]]
            shape = (0,) + (r.node_shape if f.shape == "state" else (f.columns,) if f.columns else ())
            out[name] = np.concatenate(chunks) if chunks else np.empty(shape, dtype=dtype_of(name, r.fields))
        out.update({k: np.asarray(v) for k, v in r.scalars.items()})
        out["meta"] = np.asarray(json.dumps(r.meta, sort_keys=True, default=_json_default))
        return out

    def save(self, path) -> str:
        return save_npz(path, self.arrays(), "result file")

    def finish(self) -> None:
        pass


def _copy_thinning(t: _Thinning) -> _Thinning:
    c = _Thinning(t.names, t.keep, t.fields)
    c.pending = dict(t.pending)
    return c


# =========================================================================== in a journal
class _Journaled:
    """States appended to ``out``'s journal as they come (:mod:`rollqp.journal`); the result file is written
    from it by :meth:`finish`, a block of rows at a time, and read from the file after that."""

    def __init__(self, result: Result):
        self.r = result
        self.path = journal_path(result.out)
        self.journal = None    # created with the first state (its layout is that state's)
        self.file = None       # after finish: the result file's arrays (load_result)

    @property
    def steps(self) -> int:
        j = self.journal
        return int(j.frames.index[len(j) - 1]) + 1 if j is not None and len(j) else 0

    @property
    def stored(self) -> int:
        if self.file is not None:
            return len(self.file["q"])
        if self.journal is None or not len(self.journal):
            return 0
        idx = self.journal.frames.index[:len(self.journal)]
        keep = idx % self.r.keep_every == 0
        keep[-2:] = True
        return int(keep.sum())

    def _create(self, sample: dict) -> None:
        r = self.r
        text, marrays = encode_meta(r.meta)
        arrays = {**r.coords, **{k: np.asarray(v) for k, v in r.scalars.items()},
                  **{f"constant.{k}": v for k, v in r.constants.items()}, **marrays}
        info = {"layout": _layouts(r, sample, layout_of), "keep_every": r.keep_every, "names": r.names, "version": 1,
                "dimension": r.layout.dimension}
        self.journal = Journal.create(self.path, arrays, text, info)

    def continue_journal(self, source) -> None:
        """Continue the journal ``source`` (read-only, of this scene): reopened for appending if it is this
        result's journal, else copied to it first."""
        import shutil
        source.close()
        if os.path.abspath(source.path) != os.path.abspath(self.path):
            with written(self.path, suffix=".journal") as (fh, _):
                with open(source.path, "rb") as src:
                    shutil.copyfileobj(src, fh)
        self.adopt(Journal.open(self.path, "--resume", writable=True))

    def adopt(self, journal) -> None:
        """Continue ``journal`` (the same scene's, opened for appending; its notes are in :class:`ResumeSource`'s
        ``meta``, which :meth:`Result.resume` copies)."""
        info = journal.header["info"]
        if (info.get("keep_every") != self.r.keep_every or info.get("names") != self.r.names
                or info.get("dimension", 2) != self.r.layout.dimension):
            raise InputError("--resume", f"the journal {journal.path!r} was written by another version of rollqp "
                                         "or with another keep_every: resume it with that one")
        self.journal = journal

    def append(self, values: dict, notes: dict) -> None:
        if self.journal is None:
            self._create(values)
        rec = np.zeros((), dtype=self.journal.layouts["S"])
        for name in self.r.stored:
            rec[name] = values[name]
        self.journal.append("S", int(values["step"]), rec, notes)

    def import_row(self, row: dict) -> None:
        if self.journal is None:
            self._create(row)
        rec = np.zeros((), dtype=self.journal.layouts["R"])
        for name in self.r.names:
            rec[name] = row[name]
        self.journal.append("R", int(row["step"]), rec)

    def arrays(self) -> dict:
        if self.file is not None:
            return self.file
        if self.journal is None or not len(self.journal):
            return _Memory(self.r).arrays()
        return _assemble(self.journal, self.r, None)

    def save(self, path) -> str:
        if self.file is not None and os.path.abspath(path) == os.path.abspath(self.r.out):
            return self.r.out
        if self.file is not None:
            return save_npz(path, {k: v for k, v in self.file.items()}, "result file")
        with held_signals():
            return _assemble(self.journal, self.r, os.fspath(path))

    def finish(self) -> None:
        if self.journal is None or not len(self.journal):
            if self.journal is not None:
                self.journal.remove()
            return
        with held_signals() as got:
            _assemble(self.journal, self.r, self.r.out)
            self.journal.remove()
        self.file = load_result(self.r.out, "result file")
        self.file["meta"] = np.asarray(json.dumps(self.file["meta"], sort_keys=True, default=_json_default))
        if got:
            import signal
            signal.raise_signal(got[0])


def _layouts(r: Result, sample: dict, layout_of) -> dict:
    """The journal's layouts: ``S`` (the stored fields of a computed state) and ``R`` (every field of an
    imported one), from one state's values; a derived state field has the shape of ``pn``."""
    node = list(np.shape(sample["pn"]))

    def shape(name):
        if name in sample:
            return list(np.shape(sample[name]))
        return node if name in r.fields and r.fields[name].shape == "state" else []

    def dt(name):
        return _HIDDEN_DTYPES[name] if name in _HIDDEN_DTYPES else dtype_of(name, r.fields).str
    S = [[n, dt(n), shape(n)] for n in r.stored]
    R = [[n, dt(n), shape(n)] for n in r.names]
    return {"S": S, "R": R}


def _journal_blocks(journal, ids):
    """The frames ``ids`` (increasing) in blocks of one kind and at most :data:`BLOCK_BYTES`."""
    ids = np.asarray(ids, dtype=np.int64)
    i = 0
    while i < ids.size:
        kind = journal.frames.kind[ids[i]]
        size = journal.layouts["SR"[kind]].itemsize
        m = max(1, BLOCK_BYTES // max(size, 1))
        j = i + 1
        while j < ids.size and j - i < m and journal.frames.kind[ids[j]] == kind:
            j += 1
        yield ids[i:j]
        i = j


def _journal_rows(journal, ids, constants, fields=FIELDS) -> Rows:
    """:class:`~rollqp.fields.Rows` of the journal's frames ``ids`` (one kind; predecessors read as needed)."""
    recs = journal.records(ids)
    consecutive = ids.size < 2 or int(ids[-1] - ids[0]) == ids.size - 1

    def read(name):
        return recs[name] if name in recs.dtype.names else None

    def predecessor(i, name):
        if i < 0:
            return np.full(recs[name].shape[1:], np.nan)
        return journal.records([i])[name][0]

    def read_before(name):
        if consecutive:  # the block's own rows, shifted by one, and the frame before it
            return np.concatenate([np.asarray(predecessor(int(ids[0]) - 1, name), dtype=float)[None],
                                   recs[name][:-1]])
        return np.stack([np.asarray(predecessor(int(i) - 1, name), dtype=float) for i in ids])
    return Rows(read, len(ids), constants, read_before, fields)


def _assemble(journal, r: Result, path):
    """The result file at ``path`` (or, ``path=None``, the arrays in memory) from the journal: the step
    fields of every state first (combined over the states that are not kept), then each state field
    of the kept states, a block of rows at a time."""
    n = len(journal)
    steps = _step_names(r.names, r.fields)
    thin = _Thinning(steps, r.keep_every, r.fields)
    kept_ids, parts = [], {k: [] for k in steps}
    all_ids = np.arange(n)
    for ids in _journal_blocks(journal, all_ids):
        rows = _journal_rows(journal, ids, r.constants, r.fields)
        kept, values = thin.feed(journal.frames.index[ids], _block_rows(rows, steps), last_two=ids[-1] == n - 1)
        kept_ids.append(ids[kept])
        for k in steps:
            parts[k].append(np.asarray(values[k], dtype=dtype_of(k, r.fields)))
    kept_ids = np.concatenate(kept_ids)
    columns = {k: np.concatenate(v) for k, v in parts.items()}

    def state_blocks(name):
        for ids in _journal_blocks(journal, kept_ids):
            yield _journal_rows(journal, ids, r.constants, r.fields)[name]
    meta_text, marrays = encode_meta(r.meta)
    if path is None:
        out = dict(r.coords)
        for name in r.names:
            out[name] = columns[name] if name in columns else np.concatenate(list(state_blocks(name)))
        out.update({k: np.asarray(v) for k, v in r.scalars.items()})
        out["meta"] = np.asarray(json.dumps(r.meta, sort_keys=True, default=_json_default))
        return out
    return _write_result(path, r, columns, state_blocks, kept_ids.size, meta_text, marrays)


def _write_result(path, r: Result, columns, state_blocks, K1, meta_text, marrays) -> str:
    """Write the result file atomically: a temporary file beside ``path``, then a rename."""
    with written(path) as (fh, _), NpzStream(fh) as z:
        for k, v in r.coords.items():
            z.array(k, v)
        for name in r.names:
            if name in columns:
                z.array(name, columns[name])
                continue
            blocks = state_blocks(name)
            first = next(blocks)
            z.rows(name, dtype_of(name, r.fields), (K1,) + first.shape[1:], _chain(first, blocks))
        for k, v in r.scalars.items():
            z.array(k, np.asarray(v))
        z.array("meta", np.asarray(meta_text))
        for k, v in marrays.items():
            z.array(k, v)
    return os.fspath(path)


def _chain(first, rest):
    yield first
    yield from rest


# =========================================================================== files
#: The longest suffix of a file written beside a result file (its journal; its lock is ``.lock``).
_LONGEST_SUFFIX = ".journal"


def check_output(path, what: str = "result file", key: str = "--out") -> str:
    """``path`` as a string if a ``.npz`` can be written there: checked before any work.

    Raises
    ------
    InputError
        ``key``: not ending in ``.npz``, a missing or unwritable folder, or a folder in its place.
    """
    try:
        path = os.fspath(path)
    except TypeError:
        raise InputError(key, f"the {what} must be a path, got {type(path).__name__}") from None
    if not isinstance(path, str) or "\x00" in path:
        raise InputError(key, f"the {what} must be a path without NUL characters, got {str(path)[:80]!r}")
    if not path.endswith(".npz"):
        raise InputError(key, f"the {what} must end in .npz, got {path!r}")
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise InputError(key, f"folder {folder!r} does not exist")
    try:
        longest = os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError, AttributeError):
        longest = 255
    name = os.path.basename(path)
    if len(os.fsencode(name)) + len(_LONGEST_SUFFIX) > longest:   # its journal and lock sit beside it
        raise InputError(key, f"the {what}'s name is too long: {len(os.fsencode(name))} bytes, at most "
                              f"{longest - len(_LONGEST_SUFFIX)} (its journal {name[:20]}…{_LONGEST_SUFFIX} must fit "
                              f"in {longest})")
    if os.path.isdir(path):
        raise InputError(key, f"{path!r} is a folder, not a file")
    try:
        fd, probe = temporary(path)
    except OSError as exc:
        raise InputError(key, f"cannot write in folder {folder!r} ({exc.strerror or exc})") from None
    os.close(fd)
    os.unlink(probe)
    return path


# =========================================================================== reading
def load_result(path, arg: str = "RESULT.npz", map_above: int | None = MAP_ABOVE) -> dict:
    """Read a result file into a dict of arrays (``meta`` decoded from JSON), every key checked.

    The file is read without trusting it (:func:`rollqp.npzfile.read_npz`); each key that
    :mod:`rollqp.fields` documents must have its shape (``(K+1, n)``, ``(K+1,)``, ``(n,)`` or
    ``()``) and hold real numbers; every key of the outer contract (``Field.contract``) must be
    there; ``step`` (if there) must increase from 0 or more; other keys are kept as they are. Members
    larger than ``map_above`` bytes are memory-mapped, read-only (a long run's file can be larger
    than the memory); ``meta``'s arrays (:func:`encode_meta`) are put back in it.

    Raises
    ------
    InputError
        ``arg``: a missing or corrupt file, a file that is not a result file, a bad key.
    """
    z = read_npz(path, arg, map_above=map_above)
    for key in ("x", "q", "meta"):
        if key not in z:
            raise InputError(arg, f"{os.fspath(path)!r} is not a rollqp result file (no key {key!r})")
    try:
        meta = json.loads(text_value(z, "meta", arg, limit=META_LIMIT))
    except (json.JSONDecodeError, RecursionError) as exc:
        raise InputError(arg, f"key 'meta' must be a JSON string ({type(exc).__name__})") from exc
    if not isinstance(meta, dict):
        raise InputError(arg, "key 'meta' must be a JSON object")
    dim = meta.get("dimension", 2)
    if isinstance(dim, bool) or dim not in (2, 3):
        raise InputError(arg, f"meta['dimension'] must be 2 or 3, got {str(dim)[:40]}")
    check_arrays(z, registry(dim), arg, what=os.fspath(path))
    out = {k: v for k, v in z.items() if not k.startswith("meta.")}
    out["meta"] = decode_meta(meta, z, arg)
    return out


def check_arrays(z: dict, fields: dict, arg: str, what: str = "the result") -> None:
    """The arrays ``z`` of a result of the registry ``fields`` checked: the coordinates non-empty and 1-D, every
    key of the contract there, each registered key of its shape (``"state"``: ``(K+1,)`` and the coordinates'
    sizes, last first), dtype kind, finiteness and range (``Field.low``, ``Field.high``), the scalars in
    their ranges, ``step`` increasing."""
    coords = [f.name for f in fields.values() if f.shape == "node"]
    for key in coords + ["q"]:
        if key not in z or np.ndim(z[key]) != 1 or np.shape(z[key])[0] < 1:
            raise InputError(arg, f"key {key!r} must be a non-empty 1-D array, got shape "
                                  f"{np.shape(z[key]) if key in z else None}")
    missing = [key for key, f in fields.items() if f.contract and key not in z]
    if missing:  # the contract's keys are in every result file rollqp writes
        raise InputError(arg, f"{what!r} is not a complete rollqp result file (no key {missing[0]!r}"
                              + (f" and {len(missing) - 1} more)" if len(missing) > 1 else ")"))
    K1 = np.shape(z["q"])[0]
    node = node_shape(fields, {c: np.shape(z[c])[0] for c in coords})
    for key in z:
        f = fields.get(key)
        if f is None or key == "meta":
            continue
        shape = {"state": (K1,) + node, "step": (K1,) + ((f.columns,) if f.columns else ()),
                 "node": (np.shape(z[key])[0] if np.ndim(z[key]) == 1 else -1,), "scalar": ()}[f.shape]
        _check_array(z, key, shape, arg, finite=f.finite, field=f)
    _check_scalars(z, arg)
    if "step" in z:
        st = np.asarray(z["step"])
        if st.dtype.kind not in "iu" or (K1 and st[0] < 0) or np.any(np.diff(st) <= 0):
            raise InputError(arg, "key 'step' must hold increasing whole numbers >= 0 (the stored states' indices)")


def _check_array(z: dict, key: str, shape: tuple, arg: str, finite: bool = True, field=None) -> None:
    """``z[key]`` holds real numbers of ``shape`` (finite unless ``finite=False``; of ``field``'s dtype kind and
    range), checked a block of rows at a time (no converted copy of a memory-mapped member)."""
    v = z[key]
    if not isinstance(v, np.ndarray) or v.dtype.kind not in "iuf":  # bool, complex, strings, objects
        raise InputError(arg, f"key {key!r} must hold real numbers, got dtype {np.asarray(v).dtype}")
    if field is not None and (np.dtype(field.dtype).kind == "f") != (v.dtype.kind == "f"):
        raise InputError(arg, f"key {key!r} must hold {'floating-point' if field.dtype.startswith('float') else 'whole'}"
                              f" numbers ({field.dtype}), got dtype {v.dtype}")
    if v.shape != tuple(shape):
        raise InputError(arg, f"key {key!r} must have shape {tuple(shape)}, got {v.shape}")
    if field is not None and (field.low is not None or field.high is not None):
        _check_range(v, key, field, arg)
    if not finite or v.dtype.kind != "f":
        return
    known = getattr(v, "all_finite", None)  # a mapped member, checked as it was read (rollqp.npzfile)
    if known is not None:
        if not known:
            raise InputError(arg, f"key {key!r} must be finite")
        return
    rows = max(1, BLOCK_BYTES // max(v[0].nbytes if v.ndim else v.nbytes, 1)) if v.ndim else 1
    for i in range(0, max(len(v) if v.ndim else 1, 1), rows):
        if not np.isfinite(v[i:i + rows] if v.ndim else v).all():
            raise InputError(arg, f"key {key!r} must be finite")


def _check_range(v, key, field, arg) -> None:
    """``field.low <= v <= field.high`` (NaN allowed where the field is not finite), a block of rows at a time."""
    lo = -np.inf if field.low is None else field.low
    hi = np.inf if field.high is None else field.high
    rows = max(1, BLOCK_BYTES // max(v[0].nbytes if v.ndim else v.nbytes, 1)) if v.ndim else 1
    for i in range(0, max(len(v) if v.ndim else 1, 1), rows):
        b = np.asarray(v[i:i + rows] if v.ndim else v)
        bad = (b < lo) | (b > hi)
        if np.any(bad):
            raise InputError(arg, f"key {key!r} must lie in [{lo:g}, {hi:g}], got {b[bad].flat[0]!r}")


#: The scalars every reader divides by or builds a grid from: their allowed ranges.
_SCALAR_RANGES = {"a": ("> 0", lambda v: v > 0), "b": ("> 0", lambda v: v > 0), "a_H": ("> 0", lambda v: v > 0), "p0": ("> 0", lambda v: v > 0), "R": ("> 0", lambda v: v > 0),
                  "Estar": ("> 0", lambda v: v > 0), "beta": ("in [-0.5, 0.5]", lambda v: -0.5 <= v <= 0.5),
                  "leading_edge": ("+1 or -1", lambda v: v in (1, -1))}


def _check_scalars(z: dict, arg: str) -> None:
    """The result's scalars are single finite numbers in their ranges (a_H, p0, R, E* > 0; |β| <= 1/2; the
    leading edge ±1): readers divide by them (a zero a_H, a negative p0 are a corrupt or edited file)."""
    for key, (allowed, ok) in _SCALAR_RANGES.items():
        if key in z:
            v = real_scalar(z, key, arg)
            if not ok(v):
                raise InputError(arg, f"key {key!r} must be a number {allowed}, got {v!r}")


class ResumeSource:
    """What a run continues from (``rollqp run --resume PATH``): the journal beside the result file ``PATH``
    if it holds more (the states of a run that was killed), else the result file itself.

    ``meta`` (with the journal's notes), ``keep_every``, ``last`` (the index of the last state),
    :meth:`tail` (what the march needs) and :meth:`rows` (every stored state, to import).
    """

    def __init__(self, path: str, arg: str, journal=None, arrays=None):
        self.path, self.arg, self.journal, self.arrays = path, arg, journal, arrays
        if journal is not None:
            head = journal.header["arrays"]
            meta = decode_meta(json.loads(text_value(head, "meta", arg, limit=META_LIMIT)), head, arg)
            for k, notes in journal.notes:
                _apply_notes(meta, k, notes)
            self.meta, self.keep_every = meta, int(journal.header["info"].get("keep_every", 1))
            self.steps = journal.frames.index[:len(journal)].copy()
        else:
            self.meta = arrays["meta"]
            self.keep_every = int(self.meta.get("keep_every", 1)) if isinstance(self.meta.get("keep_every", 1), int) else 1
            self.steps = np.asarray(arrays["step"]) if "step" in arrays else np.arange(len(arrays["q"]))
        self.last = int(self.steps[-1]) if self.steps.size else -1

    def tail(self) -> dict:
        """``x``, every stored state's ``q`` and ``step``, and the last two stored states (all fields)."""
        if self.journal is None:
            a = self.arrays
            fields = registry(a["meta"].get("dimension", 2))
            out = {k: np.asarray(v[-2:]) for k, v in a.items() if k in fields and fields[k].shape in ("state", "step")}
            out.update({k: np.asarray(a[k]) for k, f in fields.items() if f.shape == "node"})
            out.update(q=np.asarray(a["q"]), step=self.steps)
            return out
        j = self.journal
        n = len(j)
        last = [j.records([i])[0] for i in range(max(n - 2, 0), n)]
        out = {}
        for name in set(last[0].dtype.names).intersection(last[-1].dtype.names):
            out[name] = np.stack([np.asarray(r[name]) for r in last])
        qs = [j.records(ids)["q"] for ids in _journal_blocks(j, np.arange(n))]
        head = j.header["arrays"]
        out.update({k: np.asarray(head[k]) for k in ("x", "y") if k in head})
        out.update(q=np.concatenate(qs) if qs else np.zeros(0), step=self.steps)
        out["_notes"] = j.notes  # the method's records (rollqp.solverstate) and a stored state's p and t
        out["_state_at"] = self._state_at
        return out

    def _state_at(self, k: int) -> dict:
        """``{"p": pn, "t": pt}`` of the stored state ``k`` (a journal's)."""
        i = int(np.searchsorted(self.steps, k))
        if i >= self.steps.size or self.steps[i] != k:
            raise KeyError(k)
        rec = self.journal.records([i])[0]
        return {"p": np.array(rec["pn"], dtype=float), "t": np.array(rec["pt"], dtype=float)}

    def blocks(self, names):
        """Every stored state's ``names`` (those it holds), a block of states at a time: dicts of arrays whose first
        axis is the block's states (the states an earlier part hands on, to be checked before they are imported)."""
        if self.journal is None:
            a = self.arrays
            K1 = len(a["q"])
            size = sum(np.asarray(a[k][:1]).nbytes for k in names if k in a) or 1
            m = max(1, BLOCK_BYTES // size)
            for i in range(0, K1, m):
                yield {k: np.asarray(a[k][i:i + m]) for k in names if k in a}
            return
        j = self.journal
        for ids in _journal_blocks(j, np.arange(len(j))):
            recs = j.records(ids)
            yield {k: np.asarray(recs[k]) for k in names if k in recs.dtype.names}

    def rows(self, names):
        """Every stored state as ``{name: value}`` of ``names`` (an earlier part to import)."""
        a = self.arrays
        missing = [k for k in names if k not in a and k != "step"]
        if missing:
            raise InputError(self.arg, f"the result file lacks {', '.join(missing)}: not written by this version "
                                       "of rollqp for this scene")
        for i in range(len(a["q"])):
            yield {k: (a[k][i] if k != "step" else self.steps[i]) for k in names}

    def close(self) -> None:
        if self.journal is not None:
            self.journal.close()


def resume_source(path, arg: str = "--resume") -> ResumeSource:
    """The states to continue from: ``path`` is a result file (``RESULT.npz``) or its journal
    (``RESULT.npz.journal``); the journal is taken when it holds at least as many states as the
    file (a run killed after the file was last written), each read without trusting it."""
    path = os.fspath(path)
    npz = path[:-len(SUFFIX)] if path.endswith(SUFFIX) else path
    jpath = npz + SUFFIX
    arrays = load_result(npz, arg) if os.path.isfile(npz) else None
    journal = None
    if os.path.isfile(jpath):
        journal = Journal.open(jpath, arg)
        if not len(journal) or (arrays is not None and
                                int(journal.frames.index[len(journal) - 1]) < _last_step(arrays)):
            journal.close()   # the file holds more: the journal of an older part
            journal = None
    if journal is None and arrays is None:
        if os.path.isfile(jpath):
            raise InputError(arg, f"the journal {jpath!r} holds no completed state (the run was stopped before its "
                                  f"first state was complete): run the scene again")
        raise InputError(arg, f"no such file: {npz!r} (nor a journal {jpath!r} of a killed run)")
    return ResumeSource(npz, arg, journal=journal, arrays=None if journal is not None else arrays)


def _last_step(arrays) -> int:
    return int(arrays["step"][-1]) if "step" in arrays else len(arrays["q"]) - 1
