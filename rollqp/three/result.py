"""The result of a 3D run and its file (docs/results.md, "Three dimensions").

The same file format as a 2D result — one ``.npz`` without pickled objects, written atomically
(:func:`rollqp.result.save_npz`) — with the keys of a grid of elements: fields on the grid have the
shape ``(K+1, ny, nx)`` (row ``j`` is ``y_j``), the creepage three columns ``(ξ, η, φ)``.
:data:`FIELDS_3D` documents every key (shape, units, meaning) as :data:`rollqp.fields.FIELDS` does
the 2D ones.
"""
from __future__ import annotations

import json

import numpy as np

from ..errors import InputError
from ..fields import Field
from ..result import save_npz

__all__ = ["FIELDS_3D", "Result3D", "markdown_table", "check_arrays"]

STRESS, LENGTH, FORCE = "force/length^2", "length", "force"

#: Every key of a 3D result file, in order (``"state"``: ``(K+1, ny, nx)``, ``"step"``: ``(K+1,)`` or
#: ``(K+1, columns)``, ``"node"``: the coordinates, ``"scalar"``: ``()``).
FIELDS_3D: dict[str, Field] = {f.name: f for f in (
    Field("x", "node", LENGTH, "element centres along x (nx,), the rolling direction", contract=True),
    Field("y", "node", LENGTH, "element centres along y (ny,), lateral", contract=True),
    Field("q", "step", LENGTH, "rolled distance of each stored state (0: the starting state)", contract=True),
    Field("pn", "state", STRESS, "pressure, >= 0", contract=True),
    Field("px", "state", STRESS, "tangential traction on body A along x", contract=True),
    Field("py", "state", STRESS, "tangential traction on body A along y", contract=True),
    Field("sx", "state", "1", "slip of A relative to B along x per unit rolled distance (state 0 of a braked "
                              "start: per c = sqrt(ab) of static shift)", contract=True),
    Field("sy", "state", "1", "slip of A relative to B along y, as sx", contract=True),
    Field("state", "state", "1", "element state: 0 separation, 1 stick, 2 slip", dtype="int8", contract=True),
    Field("FN", "step", FORCE, "normal force on body A", contract=True),
    Field("Fx", "step", FORCE, "tangential force on body A along x", contract=True),
    Field("Fy", "step", FORCE, "tangential force on body A along y", contract=True),
    Field("Mz", "step", "force*length", "spin moment on body A about z (about the grid's origin)", contract=True),
    Field("creepage", "step", "1", "(K+1, 3): xi, eta (rigid slip of A relative to B over |V|) and phi "
                                   "(spin, 1/length)", contract=True),
    Field("approach", "step", LENGTH, "rigid approach delta", contract=True),
    Field("iterations", "step", "1", "solver iterations of the step (N-T: sweeps times the tangential ones)",
          dtype="int64", contract=True),
    Field("step_time", "step", "s", "wall seconds of the step", contract=True),
    Field("residual", "step", "1", "the step's residual (rollqp's, nondimensional max norm, docs/theory3d.md "
                                   "§10)", contract=True),
    Field("a", "scalar", LENGTH, "Hertz semi-axis along x", contract=True),
    Field("b", "scalar", LENGTH, "Hertz semi-axis along y", contract=True),
    Field("p0", "scalar", STRESS, "Hertz peak pressure", contract=True),
    Field("Estar", "scalar", STRESS, "contact modulus E*", contract=True),
)}

_GRID = ("pn", "px", "py", "sx", "sy", "state")
_COLUMNS = {"creepage": 3}


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
            shape = (K1,) + (g.shape if k in _GRID else ((_COLUMNS[k],) if k in _COLUMNS else ()))
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


def check_arrays(arrays: dict, arg: str = "RESULT.npz") -> dict:
    """Check the keys and shapes of a 3D result's arrays (:data:`FIELDS_3D`); returns them."""
    for key in ("x", "y", "q"):
        if key not in arrays or np.ndim(arrays[key]) != 1 or np.size(arrays[key]) < 1:
            raise InputError(arg, f"a 3D result file needs a non-empty 1-D key {key!r}")
    nx, ny, K1 = (np.size(arrays[k]) for k in ("x", "y", "q"))
    for key, f in FIELDS_3D.items():
        if key not in arrays:
            if f.contract:
                raise InputError(arg, f"not a complete 3D rollqp result file (no key {key!r})")
            continue
        want = {"state": (K1, ny, nx), "step": (K1,) + ((_COLUMNS[key],) if key in _COLUMNS else ()),
                "scalar": ()}.get(f.shape)
        if want is not None and np.shape(arrays[key]) != want:
            raise InputError(arg, f"key {key!r} must have shape {want}, got {np.shape(arrays[key])}")
    return arrays


def markdown_table() -> str:
    """The 3D result-file reference table of docs/results.md, generated from :data:`FIELDS_3D`."""
    shapes = {"state": "(K+1, ny, nx)", "step": "(K+1,)", "scalar": "()"}
    rows = ["| key | shape | units | meaning |", "|---|---|---|---|"]
    for f in FIELDS_3D.values():
        shape = {"x": "(nx,)", "y": "(ny,)"}.get(f.name) or (f"(K+1, {_COLUMNS[f.name]})" if f.name in _COLUMNS
                                                            else shapes[f.shape])
        units = "–" if f.units == "1" else f.units
        note = "" if f.contract else " *(beyond the contract)*"
        rows.append(f"| `{f.name}` | {shape} | {units} | {f.description.replace('|', chr(92) + '|')}{note} |")
    rows.append("| `meta` | () | – | JSON string: the full scene with defaults, the method, package versions, "
                "`static_shift` (the braked start's rigid shift of A relative to B, x and y), `raw_distance` (a conic "
                "method's raw answers against the refined ones) and notes |")
    return "\n".join(rows)


def _json_default(o):
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)
