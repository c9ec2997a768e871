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

from ..result import save_npz
from .fields import COLUMNS, FIELDS_3D, GRID_FIELDS, check_arrays, markdown_table, read_checked  # noqa: F401

__all__ = ["FIELDS_3D", "Result3D", "markdown_table", "check_arrays", "read_checked"]


class Result3D:
    """States of a 3D run: index 0 the starting state, then the rolling steps (:data:`FIELDS_3D`).

    ``add(record)`` appends a :class:`~rollqp.three.march.StepRecord`; ``arrays()`` gives the result
    file's arrays, ``save(path)`` writes it atomically; ``meta`` is JSON-able.
    """

    def __init__(self, grid, scalars: dict, meta: dict):
        self.grid, self.scalars, self.meta = grid, dict(scalars), meta
        self.rows = {k: [] for k, f in FIELDS_3D.items() if f.shape in ("state", "step")}

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
        """Append one state given every field by name (an interrupted append is not counted)."""
        new = [(rows, np.array(values[k], copy=True)) for k, rows in self.rows.items()]
        for rows, v in new:
            rows.append(v)

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


def _json_default(o):
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)
