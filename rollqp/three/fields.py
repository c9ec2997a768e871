"""The keys of a 3D result file (docs/results.md, "Three dimensions"): :data:`FIELDS_3D` documents every
key (shape, units, meaning) as :data:`rollqp.fields.FIELDS` does the 2D ones, and the checks of a file's
arrays (:func:`read_checked`, what :func:`rollqp.result.load_result` applies to a 3D file).
"""
from __future__ import annotations

import json

import numpy as np

from ..errors import InputError
from ..fields import Field

__all__ = ["FIELDS_3D", "GRID_FIELDS", "COLUMNS", "markdown_table", "check_arrays", "read_checked"]

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

#: The keys of the fields on the grid, ``(K+1, ny, nx)``.
GRID_FIELDS = ("pn", "px", "py", "sx", "sy", "state")
#: The per-state keys with columns, ``(K+1, columns)``.
COLUMNS = {"creepage": 3}


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
        want = {"state": (K1, ny, nx), "step": (K1,) + ((COLUMNS[key],) if key in COLUMNS else ()),
                "scalar": ()}.get(f.shape)
        if want is not None and np.shape(arrays[key]) != want:
            raise InputError(arg, f"key {key!r} must have shape {want}, got {np.shape(arrays[key])}")
    return arrays


def read_checked(z: dict, arg: str = "RESULT.npz") -> dict:
    """The arrays ``z`` of a 3D result file (read by :func:`rollqp.result.load_result`) checked key by
    key — the shapes of :data:`FIELDS_3D`, real numbers, finite where determined — with ``meta``
    decoded from JSON."""
    from ..npzfile import real_array, text_value
    check_arrays(z, arg)
    out = dict(z)
    for key, value in z.items():
        f = FIELDS_3D.get(key)
        if f is not None:
            real_array(z, key, np.shape(value), arg, finite=key not in ("approach", "creepage", "residual"))
    try:
        out["meta"] = json.loads(text_value(z, "meta", arg))
    except (json.JSONDecodeError, RecursionError) as exc:
        raise InputError(arg, f"key 'meta' must be a JSON string ({type(exc).__name__})") from exc
    if not isinstance(out["meta"], dict):
        raise InputError(arg, "key 'meta' must be a JSON object")
    return out


def markdown_table() -> str:
    """The 3D result-file reference table of docs/results.md, generated from :data:`FIELDS_3D`."""
    shapes = {"state": "(K+1, ny, nx)", "step": "(K+1,)", "scalar": "()"}
    rows = ["| key | shape | units | meaning |", "|---|---|---|---|"]
    for f in FIELDS_3D.values():
        shape = {"x": "(nx,)", "y": "(ny,)"}.get(f.name) or (f"(K+1, {COLUMNS[f.name]})" if f.name in COLUMNS
                                                            else shapes[f.shape])
        units = "–" if f.units == "1" else f.units
        note = "" if f.contract else " *(beyond the contract)*"
        rows.append(f"| `{f.name}` | {shape} | {units} | {f.description.replace('|', chr(92) + '|')}{note} |")
    rows.append("| `meta` | () | – | JSON string: the full scene with defaults, the method, package versions, "
                "`static_shift` (the braked start's rigid shift of A relative to B, x and y), `raw_distance` (a conic "
                "method's raw answers against the refined ones) and notes |")
    return "\n".join(rows)
