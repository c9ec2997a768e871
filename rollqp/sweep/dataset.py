"""Results as labelled xarray Datasets: one result file (:func:`open_result`) or a sweep's zarr store.

The schema (docs/sweeps.md): the swept keys are dimensions (their values the coordinates),
``step`` (the state index k = 0 … K of the result file) and ``node`` the two others, with the coordinates ``q`` (rolled
distance) and ``x`` (node positions): 1-D when every point shares them, else one row per point
(a swept mesh, step or load changes them). Every field of the result file
(:data:`rollqp.fields.FIELDS`) is a variable with ``units`` and ``long_name`` attributes; the
scene, the swept values, the versions and the sweep's fingerprint are global attributes.
Points with fewer states or nodes than the largest are padded (NaN; integer fields are stored
with ``_FillValue = -1`` and read back as floats with NaN where nothing was computed).

Why zarr (format 2, consolidated metadata) and not netCDF: a zarr store is a folder with one
file per chunk, and every variable is chunked one point per chunk, so the result of a point is
written into its own chunk files (a *region*) as soon as it arrives, without rewriting anything
else; a sweep killed at any moment loses only the points in flight and never corrupts the
points already written, whereas a netCDF4/HDF5 file is one file whose internal metadata a kill
during a write can leave unreadable. The per-point ``status`` variable (0 not computed, 1 done,
2 failed) is written last, so a point counts as done only once all its data are on disk.
"""
from __future__ import annotations

import json
import os

import numpy as np

from ..errors import InputError
from ..fields import FIELDS, dtype_of, fields_for

__all__ = ["open_result", "create_store", "open_store", "StoreWriter", "write_point", "result_fields", "STATUS"]

#: Values of the per-point ``status`` variable.
STATUS = {"missing": 0, "done": 1, "failed": 2}
#: Characters kept of a failed point's one-line error.
ERROR_CHARS = 200
_SCALAR_NAMES = ("a_H", "p0", "R", "Estar", "beta", "leading_edge")


def _xr():
    try:
        import xarray as xr
    except ImportError as exc:  # pragma: no cover - the extra is missing
        from ..errors import MissingBackendError
        raise MissingBackendError("labelled datasets need xarray: pip install 'rollqp[sweep]'") from exc
    return xr


def _attrs(f) -> dict:
    units = "1" if f.units == "1" else f.units
    return {"units": units, "long_name": f.description}


def _dims(f, keys: tuple) -> tuple:
    return keys + {"state": ("step", "node"), "step": ("step",), "node": ("node",), "scalar": ()}[f.shape]


def open_result(path):
    """A result file (``.npz``, docs/results.md) as an :class:`xarray.Dataset`.

    Dimensions ``step`` (k = 0 … K) and ``node`` with the coordinates ``q`` and ``x``; every array of the
    file a variable with its ``units`` and ``long_name``; the scene, method and versions of
    ``meta`` as global attributes (the scene as JSON in ``scene``). The ``.npz`` stays the
    contract format; this is a view of it. Raises :class:`~rollqp.errors.InputError` as
    :func:`rollqp.load_result` does.
    """
    from ..result import load_result
    xr = _xr()
    z = load_result(path, "RESULT.npz")
    meta = z.pop("meta")
    data = {}
    for key, value in z.items():
        f = FIELDS.get(key)
        if key in ("q", "x"):
            continue
        if f is None:
            data[key] = xr.Variable(tuple(f"{key}_dim{i}" for i in range(np.ndim(value))), value)
            continue
        data[key] = xr.Variable(_dims(f, ()), np.asarray(value, dtype=f.dtype), _attrs(f))
    coords = {"q": ("step", z["q"], _attrs(FIELDS["q"])), "x": ("node", z["x"], _attrs(FIELDS["x"]))}
    attrs = {k: (v if isinstance(v, (str, int, float)) else json.dumps(v, sort_keys=True))
             for k, v in meta.items() if v is not None}
    attrs["source"] = os.fspath(path)
    return xr.Dataset(data, coords=coords, attrs=attrs)


def result_fields(scenes) -> list:
    """The fields a sweep's points hold: the core fields and every computed field any point needs."""
    names = [f.name for f in FIELDS.values() if f.compute is None]
    for scene in scenes:
        names += [f.name for f in fields_for(scene) if f.name not in names]
    return [FIELDS[n] for n in FIELDS if n in names and n not in ("q", "x")]


def _grids(sweep):
    """``(q rows, x rows)`` of every point, from the scenes (no solve)."""
    from ..strip import Strip
    qs, xs = [], []
    for s in sweep.scenes:
        d = s.discretization
        qs.append(s.q_steps)
        xs.append(Strip(s.half_width, d.elements, d.element).x)
    return qs, xs


def _shared(rows) -> bool:
    return all(r.shape == rows[0].shape and np.array_equal(r, rows[0]) for r in rows)


def _padded(rows, shape, keys_shape):
    out = np.full(keys_shape + (max(r.size for r in rows),), np.nan)
    flat = out.reshape(-1, out.shape[-1])
    for i, r in enumerate(rows):
        flat[i, :r.size] = r
    return out


def _coords(sweep) -> dict:
    """``name -> (dims, values, attrs)`` of the coordinates: the swept values, ``q`` and ``x``."""
    keys, shape = sweep.keys, sweep.shape
    coords = {a.key: ((a.key,), np.array(a.values), {}) for a in sweep.axes}
    qs, xs = _grids(sweep)
    for name, rows, dim in (("q", qs, "step"), ("x", xs, "node")):
        if _shared(rows):
            coords[name] = ((dim,), rows[0], _attrs(FIELDS[name]))
        else:
            coords[name] = (keys + (dim,), _padded(rows, None, shape), _attrs(FIELDS[name]))
    return coords


def _variables(sweep, fields) -> dict:
    """``name -> (dims, dtype, fill, attrs)`` of the data variables."""
    keys = sweep.keys
    out = {}
    for f in fields:
        dt = dtype_of(f.name)
        dims = _dims(f, keys)
        out[f.name] = (dims, dt, np.nan if dt.kind == "f" else -1, dict(_attrs(f), coordinates=_coord_names(dims)))
    out["status"] = (keys, np.dtype("int8"), None, {"long_name": "0 not computed, 1 done, 2 failed", "units": "1"})
    out["error"] = (keys, np.dtype(f"<U{ERROR_CHARS}"), None, {"long_name": "one-line error of a failed point"})
    out["point_time"] = (keys, np.dtype("float64"), np.nan,
                         {"units": "s", "long_name": "wall seconds of the point on its worker"})
    return out


def _coord_names(dims) -> str:
    return " ".join(n for n, d in (("q", "step"), ("x", "node")) if d in dims)


def _global_attrs(sweep, fields) -> dict:
    from ..march import _versions
    from ..version import __version__
    versions = dict(_versions(), rollqp=__version__)
    for pkg in ("dask", "distributed", "xarray", "zarr"):
        try:
            versions[pkg] = __import__(pkg).__version__
        except ImportError:  # pragma: no cover
            versions[pkg] = None
    return {"title": f"rollqp sweep of {sweep.base.name}", "rollqp_sweep_fingerprint": sweep.fingerprint(),
            "scene": json.dumps(sweep.base.to_dict(), sort_keys=True),
            "vary": json.dumps([[a.key, list(a.values)] for a in sweep.axes]),
            "versions": json.dumps(versions, sort_keys=True),
            "conventions": "status: 0 not computed, 1 done, 2 failed; padded states/nodes are NaN "
                           "(integer fields: _FillValue -1); docs/sweeps.md"}


def check_store_path(path) -> str:
    """``path`` as a string if it can be a sweep store (``*.zarr`` in an existing folder)."""
    path = os.fspath(path)
    if not path.rstrip("/").endswith(".zarr"):
        raise InputError("--out", f"a sweep store is a zarr folder ending in .zarr, got {path!r}")
    folder = os.path.dirname(os.path.abspath(path.rstrip("/")))
    if not os.path.isdir(folder) or not os.access(folder, os.W_OK):
        raise InputError("--out", f"cannot write in folder {folder!r}")
    if os.path.exists(path) and not os.path.isdir(path):
        raise InputError("--out", f"{path!r} exists and is not a zarr folder")
    return path.rstrip("/")


def open_store(path, sweep):
    """The zarr group of an existing store of ``sweep`` and its per-point status (flat), or ``None``.

    Raises
    ------
    InputError
        ``--out``: a folder that is not a rollqp sweep store, or the store of a different sweep
        (another base scene or other swept values: the fingerprints differ).
    """
    import zarr
    if not os.path.exists(path):
        return None
    try:
        group = zarr.open_group(path, mode="r+")
        fp = group.attrs.get("rollqp_sweep_fingerprint")
    except Exception as exc:  # zarr raises several types for a folder that is not a group
        raise InputError("--out", f"{path!r} exists and is not a rollqp sweep store ({type(exc).__name__})") from None
    if fp is None:
        raise InputError("--out", f"{path!r} exists and is not a rollqp sweep store (no fingerprint)")
    if fp != sweep.fingerprint():
        raise InputError("--out", f"{path!r} holds a different sweep (another scene or other --vary values: "
                                  f"fingerprint {fp[:12]} != {sweep.fingerprint()[:12]}); choose another --out")
    return group, np.asarray(group["status"][...]).reshape(-1)


def create_store(path, sweep):
    """Create the empty store of ``sweep`` (metadata and coordinates only) and return its zarr group.

    Written with zarr directly in xarray's zarr-2 layout (``_ARRAY_DIMENSIONS``, CF attributes,
    consolidated metadata), chunked one point per chunk; ``xarray.open_zarr`` reads it.
    """
    import zarr
    fields = result_fields(sweep.scenes)
    sizes = dict(zip(sweep.keys, sweep.shape), step=max(s.n_steps + 1 for s in sweep.scenes),
                 node=max(s.n_nodes for s in sweep.scenes))
    group = zarr.open_group(path, mode="w-", zarr_format=2)
    group.attrs.update(_global_attrs(sweep, fields))
    for name, (dims, values, attrs) in _coords(sweep).items():
        fill = None if values.dtype.kind == "U" else np.nan if values.dtype.kind == "f" else 0
        arr = group.create_array(name, shape=values.shape, chunks=values.shape, dtype=values.dtype, fill_value=fill,
                                 attributes=dict(attrs, _ARRAY_DIMENSIONS=list(dims)))
        arr[...] = values
    point = dict(zip(sweep.keys, (1,) * len(sweep.keys)))
    for name, (dims, dt, fill, attrs) in _variables(sweep, fields).items():
        group.create_array(name, shape=tuple(sizes[d] for d in dims), chunks=tuple(point.get(d, sizes[d]) for d in dims),
                           dtype=dt, fill_value=fill, attributes=dict(attrs, _ARRAY_DIMENSIONS=list(dims)))
    zarr.consolidate_metadata(path, zarr_format=2)
    return zarr.open_group(path, mode="r+", zarr_format=2)


class StoreWriter:
    """Writes points into a sweep's store: each point's region of every variable, ``status`` last.

    The arrays are opened once; the variables of one point are written concurrently (zarr's
    asynchronous API: one file per chunk, so the writes are independent), then ``status``.
    """

    def __init__(self, group, sweep):
        self.sweep = sweep
        self.arrays = {k: group[k] for k in group.array_keys()}
        self.per_point_grid = {k for k in ("q", "x") if self.arrays[k].ndim > 1}

    def _items(self, idx, out: dict) -> list:
        if out.get("error") is not None:
            return [("error", idx, out["error"][:ERROR_CHARS]), ("point_time", idx, out["time"])]
        items = [("error", idx, ""), ("point_time", idx, out["time"])]
        for name, value in out["arrays"].items():
            if name not in self.arrays or name in ("q", "x") and name not in self.per_point_grid:
                continue
            value = np.asarray(value)
            items.append((name, idx + tuple(slice(0, s) for s in value.shape), value))
        return items

    def write(self, i: int, out: dict) -> None:
        """Store point ``i``'s result (``out`` of :func:`rollqp.sweep.executor.compute_point`)."""
        idx = self.sweep.index(i)
        items = [(self.arrays[name], sel, value) for name, sel, value in self._items(idx, out)]
        try:
            import asyncio

            from zarr.core.sync import sync

            async def _all():
                await asyncio.gather(*(a._async_array.setitem(sel, v) for a, sel, v in items))
            sync(_all())
        except (ImportError, AttributeError):  # pragma: no cover - another zarr: one array at a time
            for a, sel, v in items:
                a[sel] = v
        self.arrays["status"][idx] = STATUS["done" if out.get("error") is None else "failed"]


def write_point(group, sweep, i: int, out: dict) -> None:
    """Write point ``i``'s result into its region (:class:`StoreWriter`, for one point)."""
    StoreWriter(group, sweep).write(i, out)
