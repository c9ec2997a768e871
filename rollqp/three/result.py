"""The result of a 3D run and its file (docs/results.md, "Three dimensions").

The same file format as a 2D result — one ``.npz`` without pickled objects, written atomically
(:func:`rollqp.result.save_npz`) — with the keys of a grid of elements: fields on the grid have the
shape ``(K+1, ny, nx)`` (row ``j`` is ``y_j``), the creepage three columns ``(ξ, η, φ)``.
:data:`FIELDS_3D` (:mod:`rollqp.three.fields`) documents every key (shape, units, meaning) as
:data:`rollqp.fields.FIELDS` does the 2D ones.
"""
from __future__ import annotations

import json

import numpy as np

from ..errors import InputError
from ..result import save_npz
from ..journal import json_default as _json_default
from .fields import COLUMNS, FIELDS_3D, GRID_FIELDS, check_arrays, markdown_table, read_checked  # noqa: F401

__all__ = ["FIELDS_3D", "Result3D", "markdown_table", "check_arrays", "read_checked", "journal_arrays"]


class Result3D:
    """States of a 3D run: index 0 the starting state, then the rolling steps (:data:`FIELDS_3D`).

    ``add(record)`` appends a :class:`~rollqp.three.march.StepRecord`; ``arrays()`` gives the result
    file's arrays, ``save(path)`` writes it atomically; ``meta`` is JSON-able.

    With ``out`` (a result file's path) every state is also appended, as it is completed, to the
    journal ``out.journal`` (:mod:`rollqp.journal`: one frame per state, kept by the kernel when the
    process is killed, SIGKILL included); :meth:`finish` writes the result file and removes the
    journal, and ``rollqp run --resume out`` continues a killed run from it (:func:`journal_arrays`).
    """

    def __init__(self, grid, scalars: dict, meta: dict, out=None):
        self.grid, self.scalars, self.meta, self.out = grid, dict(scalars), meta, out
        self.rows = {k: [] for k, f in FIELDS_3D.items() if f.shape in ("state", "step")}
        self.journal = None

    def add(self, rec) -> None:
        """Append the state of a record (``rec.k`` must be ``len(self)``)."""
        if rec.k != len(self):
            raise ValueError(f"record {rec.k} appended as state {len(self)}")
        g = self.grid
        t, s = np.asarray(rec.t).reshape(2, -1), np.asarray(rec.s).reshape(2, -1)
        values = dict(q=rec.q, pn=g.field(rec.p), px=g.field(t[0]), py=g.field(t[1]), sx=g.field(s[0]),
                      sy=g.field(s[1]), state=g.field(rec.state), FN=rec.FN, Fx=rec.Fx, Fy=rec.Fy, Mz=rec.Mz,
                      creepage=(rec.xi, rec.eta, rec.phi), approach=rec.delta,
                      iterations=rec.iterations, step_time=rec.time,
                      residual=rec.residual)
        self.append(values)

    def append(self, values: dict) -> None:
        """Append one state given every field by name (an interrupted append is not counted), and to the
        journal if the result has one."""
        new = [(rows, np.array(values[k], copy=True).astype(FIELDS_3D[k].dtype)) for k, rows in self.rows.items()]
        if self.out is not None:
            self._journal({k: v for (k, _), (_, v) in zip(self.rows.items(), new)})
        for rows, v in new:
            rows.append(v)

    def _journal(self, values: dict) -> None:
        from ..journal import Journal, journal_path, layout_dtype, layout_of
        if self.journal is None:
            layout = layout_of(values)
            head = {"x": self.grid.x, "y": self.grid.y, **{k: np.asarray(v, dtype=float) for k, v in self.scalars.items()}}
            info = {"layout": {"S": layout, "R": layout}, "dimension": 3, "keep_every": 1}
            self.journal = Journal.create(journal_path(self.out), head, json.dumps(self.meta, sort_keys=True,
                                                                                  default=_json_default), info)
        rec = np.zeros((), dtype=layout_dtype(self.journal.header["info"]["layout"]["S"]))
        for k, v in values.items():
            rec[k] = v
        self.journal.append("S", len(self), rec)

    def finish(self, notes: dict | None = None) -> str | None:
        """The run is over: ``notes`` into ``meta``; with ``out``, the result file written (atomically) and
        the journal removed. Returns the file's path (None without ``out``)."""
        self.meta.update(notes or {})
        if self.out is None:
            return None
        path = self.save(self.out)
        if self.journal is not None:
            self.journal.remove()
            self.journal = None
        return path

    def extend(self, arrays: dict) -> None:
        """Append every state of a 3D result file's ``arrays`` (an earlier part of the same run)."""
        check_arrays(arrays, "--resume")
        for i in range(len(arrays["q"])):
            self.append({k: arrays[k][i] for k in self.rows})

    def __len__(self) -> int:
        return min(len(v) for v in self.rows.values())

    def arrays(self) -> dict:
        """Every array of the result file (``meta`` as its JSON text), the complete states only."""
        K1, g = len(self), self.grid
        out = {"x": g.x.copy(), "y": g.y.copy()}
        for k, rows in self.rows.items():
            f = FIELDS_3D[k]
            shape = (K1,) + (g.shape if k in GRID_FIELDS else ((COLUMNS[k],) if k in COLUMNS else ()))
            out[k] = np.asarray(rows[:K1], dtype=f.dtype).reshape(shape)
        for k, v in self.scalars.items():
            out[k] = np.asarray(v, dtype=float)
        out["meta"] = np.asarray(json.dumps(self.meta, sort_keys=True, default=_json_default))
        return out

    def __getitem__(self, key):
        return self.arrays()[key]

    def save(self, path) -> str:
        """Write the result file atomically."""
        return save_npz(path, self.arrays(), "result file")


def journal_arrays(journal) -> dict:
    """The arrays of a 3D run's journal (a killed run's states, :class:`rollqp.journal.Journal` opened by
    :func:`rollqp.result.resume_source`), as :func:`rollqp.result.load_result` gives a result file's: each
    frame's CRC checked, the keys and shapes of :data:`FIELDS_3D`."""
    from ..npzfile import text_value
    head = journal.header["arrays"]
    if int(journal.header["info"].get("dimension", 2)) != 3:
        raise InputError(journal.arg, f"{journal.path!r} is the journal of a 2D run")
    n = len(journal)
    recs = journal.records(np.arange(n)) if n else None
    out = {k: np.asarray(head[k]) for k in ("x", "y", "a", "b", "p0", "Estar") if k in head}
    for name in (recs.dtype.names if recs is not None else ()):
        out[name] = np.asarray(recs[name])
    out["meta"] = text_value(head, "meta", journal.arg)
    return read_checked(out, journal.arg)


