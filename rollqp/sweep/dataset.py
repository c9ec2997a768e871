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

import itertools
import json
import math
import os
import re

import numpy as np

from ..errors import InputError
from ..fields import FIELDS, dtype_of, fields_for

__all__ = ["open_result", "create_store", "open_store", "StoreWriter", "Layout", "chunk_tasks", "write_point", "result_fields",
           "STATUS", "points_per_chunk", "chunk_shape", "FINGERPRINT"]

#: Values of the per-point ``status`` variable.
STATUS = {"missing": 0, "done": 1, "failed": 2}
#: The global attribute that holds the sweep's fingerprint (:meth:`rollqp.sweep.Sweep.fingerprint`).
FINGERPRINT = "rollqp_sweep_fingerprint"
#: Most points in one chunk (one task): past ~16 points the per-chunk cost of a write (~30 variables,
#: one file each; measured in docs/sweeps.md) is already small beside the points' own.
MAX_POINTS_PER_CHUNK = 32
#: Most bytes of one chunk of the largest (per-state float) variable: a bound on a task's memory.
CHUNK_BYTES = 32 * 2**20
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


def result_fields(sweep) -> list:
    """The fields a sweep's points hold: the core fields and every computed field any point needs."""
    names = {f.name for f in FIELDS.values() if f.compute is None and f.derive is None} | set(sweep.facts.fields)
    return [FIELDS[n] for n in FIELDS if n in names and n not in ("q", "x")]


def points_per_chunk(sweep, workers: int = 1) -> int:
    """Points in one chunk of the store (and in one task of the sweep): ``⌈√(N/(4·workers))⌉``, raised
    to a divisor of the last axis's length when one is within twice that (:func:`_even`).

    A task costs a round trip through the scheduler and a write of ~30 files whatever its
    points, and the last tasks leave workers idle while the others finish: for N points of
    cost c each, a per-task cost o and B points a task, the wall time is about
    ``(N·c + (N/B)·o)/workers + B·c/2``, least at ``B = √(2·N·o/(workers·c))`` — the formula
    above for o/c ≈ 1/8 (a §6.1.1 point against a task's round trip and write: docs/sweeps.md).
    At most :data:`MAX_POINTS_PER_CHUNK`, and at most :data:`CHUNK_BYTES` of the largest field
    per chunk; at least one.
    """
    f = sweep.facts
    per_point = int(f.states.max()) * int(f.nodes.max()) * 8
    balance = _even(math.ceil(math.sqrt(sweep.size / (4 * max(workers, 1)))), sweep.shape[-1])
    return max(1, min(MAX_POINTS_PER_CHUNK, CHUNK_BYTES // max(per_point, 1), balance))


def _even(b: int, last: int) -> int:
    """``b`` points a chunk, raised to the nearest divisor of the last axis's length ``last`` up to 2·b,
    so that the chunks tile its rows evenly: 3 a chunk of rows of 8 would make tasks of 3, 3 and 2
    points, 4 makes two tasks of 4 (fewer tasks, the same points each)."""
    if b >= last:
        return b
    return next((d for d in range(b, min(2 * b, last) + 1) if last % d == 0), b)


def chunk_shape(shape: tuple, per_chunk: int) -> tuple:
    """A chunk of at most ``per_chunk`` points over the swept dimensions, filled from the last
    (fastest) one: rows of the last key, then whole rows of the next, …"""
    out, left = [], max(1, int(per_chunk))
    for n in reversed(shape):
        c = min(n, left)
        out.append(c)
        left = max(1, left // c) if c == n else 1
    return tuple(reversed(out))


def _coords(sweep, chunks) -> dict:
    """``name -> (dims, values, attrs, chunks)`` of the coordinates: the swept values, ``q`` and ``x``."""
    f, keys, shape = sweep.facts, sweep.keys, sweep.shape
    coords = {a.key: ((a.key,), np.array(a.values), {}, None) for a in sweep.axes}
    for name, rows, index, dim in (("q", f.q, f.q_index, "step"), ("x", f.x, f.x_index, "node")):
        if len(rows) == 1:
            coords[name] = ((dim,), np.asarray(rows[0]), _attrs(FIELDS[name]), None)
            continue
        table = np.full((len(rows), max(r.size for r in rows)), np.nan)
        for j, r in enumerate(rows):
            table[j, :r.size] = r
        coords[name] = (keys + (dim,), table[index].reshape(shape + table.shape[1:]), _attrs(FIELDS[name]),
                        chunks + table.shape[1:])
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


def _global_attrs(sweep) -> dict:
    import importlib.metadata as md

    from ..march import _versions
    from ..version import __version__
    versions = dict(_versions(), rollqp=__version__)
    for pkg in ("dask", "distributed", "xarray", "zarr"):
        try:
            versions[pkg] = md.version(pkg)
        except md.PackageNotFoundError:  # pragma: no cover
            versions[pkg] = None
    return {"title": f"rollqp sweep of {sweep.base.name}", FINGERPRINT: sweep.fingerprint(),
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


def _schema(sweep) -> dict:
    """``name -> (dims, shape, dtype)`` of every array of the store of ``sweep`` (coordinates and variables)."""
    sizes = dict(zip(sweep.keys, sweep.shape), step=int(sweep.facts.states.max()), node=int(sweep.facts.nodes.max()))
    out = {name: (dims, np.shape(values), np.asarray(values).dtype) for name, (dims, values, _, _) in
           _coords(sweep, sweep.shape).items()}
    for name, (dims, dt, _, _) in _variables(sweep, result_fields(sweep)).items():
        out[name] = (dims, tuple(sizes[d] for d in dims), dt)
    return out


def open_store(path, sweep):
    """The zarr group of an existing store of ``sweep`` and its per-point status (flat), or ``None``.

    Raises
    ------
    InputError
        ``--out``: a folder that is not a rollqp sweep store, the store of a different sweep
        (another base scene or other swept values: the fingerprints differ), or a store whose
        arrays are not those of this sweep's schema (shape, type or chunks changed since).
    """
    import zarr
    if not os.path.exists(path):
        return None
    try:
        group = zarr.open_group(path, mode="r+")
        fp = group.attrs.get(FINGERPRINT)
    except Exception as exc:  # zarr raises several types for a folder that is not a group
        raise InputError("--out", f"{path!r} exists and is not a rollqp sweep store ({type(exc).__name__})") from None
    if fp is None:
        raise InputError("--out", f"{path!r} exists and is not a rollqp sweep store (no fingerprint)")
    if not isinstance(fp, str) or not re.fullmatch(r"[0-9a-f]{64}", fp):
        raise InputError("--out", f"{path!r} is not a rollqp sweep store: its {FINGERPRINT} attribute is "
                                  f"{_short(fp)}, not a SHA-256 hex digest")
    if fp != sweep.fingerprint():
        raise InputError("--out", f"{path!r} holds a different sweep (another scene or other --vary values: "
                                  f"fingerprint {fp[:12]} != {sweep.fingerprint()[:12]}); choose another --out")
    _check_schema(path, group, sweep)
    status = np.asarray(group["status"][...]).reshape(-1)
    if not np.isin(status, tuple(STATUS.values())).all():
        raise InputError("--out", f"{path!r}: its status variable holds values other than 0, 1, 2")
    return group, status


def _short(value) -> str:
    text = repr(value)
    return f"{type(value).__name__} {text[:40]}{'…' if len(text) > 40 else ''}"


def _check_schema(path, group, sweep) -> None:
    """Every array of this sweep's store is there with its shape and type, chunked alike over the points."""
    try:
        arrays = {k: group[k] for k in group.array_keys()}
    except Exception as exc:
        raise InputError("--out", f"{path!r}: unreadable arrays ({type(exc).__name__})") from None
    chunks, d = None, len(sweep.keys)
    for name, (dims, shape, dt) in _schema(sweep).items():
        a = arrays.get(name)
        if a is None or tuple(a.shape) != tuple(shape) or np.dtype(a.dtype) != dt:
            got = "missing" if a is None else f"shape {tuple(a.shape)} of {np.dtype(a.dtype)}"
            raise InputError("--out", f"{path!r}: array {name!r} is {got}, not shape {tuple(shape)} of {dt} as this "
                                      "sweep writes it; the store was changed since: choose another --out")
        if name not in sweep.keys and tuple(dims[:d]) == sweep.keys:  # a variable over the points: every point's states and nodes in its chunk
            mine = tuple(a.chunks)
            if chunks is not None and mine[:d] != chunks or mine[d:] != tuple(shape[d:]):
                raise InputError("--out", f"{path!r}: array {name!r} is chunked {mine}, unlike the others; "
                                          "the store was changed since: choose another --out")
            chunks = mine[:d]


def create_store(path, sweep, per_chunk: int = 1):
    """Create the empty store of ``sweep`` (metadata and coordinates only) and return its zarr group.

    Written with zarr in xarray's zarr-2 layout (``_ARRAY_DIMENSIONS``, CF attributes,
    consolidated metadata), chunked ``per_chunk`` points per chunk (:func:`chunk_shape`), every
    state and node of a point in its chunk; ``xarray.open_zarr`` reads it. zarr builds the store
    in memory, whose files are then written into a new folder renamed to ``path`` at the end:
    a store is there whole or not at all, and ~70 small files cost milliseconds, not zarr's
    asynchronous round trip per file.
    """
    import zarr
    from zarr.storage import MemoryStore
    chunks = chunk_shape(sweep.shape, per_chunk)
    sizes = dict(zip(sweep.keys, sweep.shape), step=int(sweep.facts.states.max()), node=int(sweep.facts.nodes.max()))
    files = {}
    memory = MemoryStore(store_dict=files)
    group = zarr.open_group(memory, mode="w-", zarr_format=2, attributes=_global_attrs(sweep))
    point = dict(zip(sweep.keys, chunks))
    for name, (dims, values, attrs, chunk) in _coords(sweep, chunks).items():
        fill = None if values.dtype.kind == "U" else np.nan if values.dtype.kind == "f" else 0
        arr = group.create_array(name, shape=values.shape, chunks=chunk or values.shape, dtype=values.dtype,
                                 fill_value=fill, attributes=dict(attrs, _ARRAY_DIMENSIONS=list(dims)))
        arr[...] = values
    for name, (dims, dt, fill, attrs) in _variables(sweep, result_fields(sweep)).items():
        group.create_array(name, shape=tuple(sizes[d] for d in dims), chunks=tuple(point.get(d, sizes[d]) for d in dims),
                           dtype=dt, fill_value=fill, attributes=dict(attrs, _ARRAY_DIMENSIONS=list(dims)))
    zarr.consolidate_metadata(memory, zarr_format=2)
    tmp = f"{path}.creating-{os.getpid()}"
    for key, buf in files.items():
        _write_file(os.path.join(tmp, *key.split("/")), buf.to_bytes(), atomic=False)
    os.rename(tmp, path)
    return zarr.open_group(path, mode="r+", zarr_format=2)


def _write_file(target: str, data: bytes, atomic: bool = True) -> None:
    """``data`` into the file ``target`` (its folder made); ``atomic``: through a temporary file
    renamed over it, so that a reader or a kill never meets half a file."""
    folder = os.path.dirname(target)
    if not os.path.isdir(folder):
        os.makedirs(folder, exist_ok=True)
    tmp = os.path.join(folder, f".{os.path.basename(target)}.{os.getpid()}.tmp") if atomic else target
    with open(tmp, "wb") as fh:
        fh.write(data)
    if atomic:
        os.replace(tmp, target)


def _chunk_files(group, a):
    """``(folder, codec, separator, dtype)`` to write whole chunks of the zarr-2 array ``a`` as
    files, or ``None`` when zarr must write them (another format, filters, a store not on disk)."""
    from zarr.storage import LocalStore
    m = a.metadata
    if getattr(m, "zarr_format", None) != 2 or not isinstance(group.store, LocalStore) or m.filters or m.order != "C":
        return None
    folder = os.path.join(str(group.store.root), *[p for p in a.path.split("/") if p])
    return folder, m.compressor, m.dimension_separator, np.dtype(m.dtype.to_native_dtype())


def chunk_tasks(shape: tuple, chunks: tuple, status) -> list:
    """The points of a sweep of ``shape`` stored in ``chunks`` whose ``status`` is not done, grouped by
    chunk: lists of flat indices (one task each)."""
    index = np.arange(math.prod(shape)).reshape(shape)
    todo = (np.asarray(status).reshape(shape) != STATUS["done"])
    out = []
    for region in itertools.product(*(range(0, n, c) for n, c in zip(shape, chunks))):
        sel = tuple(slice(s, s + c) for s, c in zip(region, chunks))
        points = index[sel][todo[sel]]
        if points.size:
            out.append([int(i) for i in points])
    return out


class Layout:
    """The swept keys and the grid's shape: what a :class:`StoreWriter` needs of a sweep (small, sent
    to the workers that write their own chunks; a :class:`~rollqp.sweep.Sweep` serves as well)."""

    def __init__(self, keys, shape):
        self.keys, self.shape = tuple(keys), tuple(int(n) for n in shape)

    @property
    def size(self) -> int:
        return math.prod(self.shape)

    def index(self, i: int) -> tuple:
        """The multi-index of point ``i`` (row-major over the axes)."""
        return tuple(int(j) for j in np.unravel_index(i, self.shape))


class StoreWriter:
    """Writes points into a sweep's store, one chunk at a time: every variable's chunk, ``status`` last.

    A write is the points of one chunk (one task of the sweep): each variable's block of that
    chunk is filled in memory and written whole. In a zarr-2 store on disk (what
    :func:`create_store` makes) a block is encoded with the array's own compressor and written
    as its chunk file (zarr-2's key ``i.j.k``) through a temporary file renamed over it, so a
    kill never leaves half a chunk; zarr's asynchronous path costs thread hops per array, ~30
    arrays a chunk, more on a loaded machine. Otherwise zarr writes the
    blocks. Points of the chunk not in the write keep what the store holds (a re-run that
    computes only a chunk's failed points reads the chunk first). ``sweep``: the
    :class:`~rollqp.sweep.Sweep` or its :class:`Layout`.
    """

    def __init__(self, group, sweep):
        self.sweep = sweep
        self.arrays = {k: group[k] for k in group.array_keys()}
        self.chunks = tuple(self.arrays["status"].chunks)
        self.names = [k for k in self.arrays if k not in sweep.keys and (k not in ("q", "x") or self.arrays[k].ndim > 1)]
        self.files = {k: _chunk_files(group, self.arrays[k]) for k in self.names + ["status"]}
        #: Every chunk is written as a file of a store on disk (whose folder is ``root``).
        self.on_disk = all(spec is not None for spec in self.files.values())
        self.root = str(group.store.root) if self.on_disk else None

    def tasks(self, status) -> list:
        """The points to compute, grouped by chunk: lists of flat indices whose ``status`` is not done."""
        return chunk_tasks(self.sweep.shape, self.chunks, status)

    def _region(self, points) -> tuple:
        """The chunk of the first of ``points``, as slices (clipped at the arrays' ends)."""
        first = self.sweep.index(points[0])
        return tuple(slice(j - j % c, min(j - j % c + c, n)) for j, c, n in zip(first, self.chunks, self.sweep.shape))

    def points_in_chunk(self, points) -> bool:
        """``points`` all lie in one chunk (what :meth:`write` takes)."""
        region = self._region(points)
        return all(s.start <= j < s.stop for i in points for j, s in zip(self.sweep.index(i), region))

    def _blocks(self, region, points, outs) -> dict:
        """``name -> block`` of the whole chunk at ``region`` with ``outs`` (one per point) filled in."""
        clipped = tuple(s.stop - s.start for s in region)
        whole = len(points) == int(np.prod(clipped))
        blocks = {}
        for name in self.names + ["status"]:
            a = self.arrays[name]
            fill = a.fill_value if a.fill_value is not None else np.zeros((), a.dtype)[()]
            block = np.full(self.chunks + tuple(a.shape[len(region):]), fill, dtype=a.dtype)
            if not whole:  # keep the chunk's other points
                block[tuple(slice(0, n) for n in clipped)] = a[region]
            blocks[name] = block
        for i, out in zip(points, outs):
            local = tuple(j - s.start for j, s in zip(self.sweep.index(i), region))
            for name, value in _point_items(out):
                if name in blocks:
                    value = np.asarray(value)
                    blocks[name][local + tuple(slice(0, n) for n in value.shape)] = value
            blocks["status"][local] = STATUS["done" if out.get("error") is None else "failed"]
        return blocks

    def _put(self, names, region, blocks) -> None:
        """Write the chunk at ``region`` of each array in ``names``."""
        clipped = tuple(slice(0, s.stop - s.start) for s in region)
        chunk = tuple(s.start // c for s, c in zip(region, self.chunks))
        slow = []
        for name in names:
            spec = self.files[name]
            if spec is None:
                slow.append(name)
                continue
            folder, codec, sep, dt = spec
            data = np.ascontiguousarray(blocks[name], dtype=dt)
            key = sep.join(str(c) for c in chunk + (0,) * (data.ndim - len(chunk)))
            _write_file(os.path.join(folder, *key.split("/")), codec.encode(data) if codec is not None else data.tobytes())
        for name in slow:
            self.arrays[name][region] = blocks[name][clipped]

    def write(self, points, outs) -> None:
        """Store the points ``points`` (flat indices, all in one chunk) with their results ``outs``
        (:func:`rollqp.sweep.executor.compute_points`), ``status`` last."""
        region = self._region(points)
        blocks = self._blocks(region, points, outs)
        self._put(self.names, region, blocks)
        self._put(["status"], region, blocks)


def _point_items(out: dict):
    """``(name, value)`` of one point's result to store: its arrays (none if it failed), error and time."""
    yield "error", (out.get("error") or "")[:ERROR_CHARS]
    yield "point_time", out["time"]
    if out.get("error") is None:
        yield from out["arrays"].items()


def write_point(group, sweep, i: int, out: dict) -> None:
    """Write point ``i``'s result into its region (:class:`StoreWriter`, for one point)."""
    StoreWriter(group, sweep).write([i], [out])
