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

from ..errors import InputError, MissingBackendError
from ..fields import FIELDS, dtype_of, fields_for
from ..march.loop import versions as _versions
from ..result import load_result
from ..version import __version__

__all__ = ["open_result", "create_store", "open_store", "StoreWriter", "Layout", "chunk_tasks", "write_point", "result_fields",
           "STATUS", "points_per_chunk", "chunk_shape", "FINGERPRINT", "COMPRESSOR"]

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
    """Points in one chunk of the store (and in one task of the sweep): ``⌈√(N/workers)⌉``, raised
    to a divisor of the last axis's length when one is within twice that (:func:`_even`).

    A task costs a round trip through the scheduler and a write of ~30 files whatever its
    points, and the last tasks leave workers idle while the others finish: for N points of
    cost c each, a per-task cost o and B points a task, the wall time is about
    ``(N·c + (N/B)·o)/workers + B·c/2``, least at ``B = √(2·N·o/(workers·c))`` — the formula
    above for o/c ≈ 1/2. Measured (docs/sweeps.md): a task's fixed cost is 10–20 ms (the write
    of its chunk, most of it ~30 file creations, and dask's handling), against ~25 ms for a §6.1.1
    point at 40 QCE (o/c ≈ 0.5–0.8), ~100 ms at 80 QCE (≈ 0.15) and ~5 ms for a steady point of
    the creep curve (≈ 2). At most :data:`MAX_POINTS_PER_CHUNK`, and at most :data:`CHUNK_BYTES`
    of the largest field per chunk; at least one.
    """
    f = sweep.facts
    per_point = int(f.states.max()) * int(f.nodes.max()) * 8
    balance = _even(math.ceil(math.sqrt(sweep.size / max(workers, 1))), sweep.shape[-1])
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


#: The compressor of every array of a store: zarr's default for zarr-2 arrays, named here so that both
#: ways of writing a store (:func:`create_store`) give the same files.
COMPRESSOR = {"id": "blosc", "cname": "lz4", "clevel": 5, "shuffle": 1, "blocksize": 0}
#: dtype kinds whose metadata and chunks :func:`create_store` writes itself (others go through zarr).
_DIRECT_KINDS = "fiU"


def create_store(path, sweep, per_chunk: int = 1, *, direct: bool = True) -> None:
    """Create the empty store of ``sweep`` (metadata and coordinates only) at ``path``.

    xarray's zarr-2 layout (``_ARRAY_DIMENSIONS``, CF attributes, consolidated metadata ``.zmetadata``),
    chunked ``per_chunk`` points per chunk (:func:`chunk_shape`), every state and node of a point in
    its chunk, every array compressed with :data:`COMPRESSOR`; ``xarray.open_zarr`` reads it. The
    files are written into a new folder renamed to ``path`` at the end: a store is there whole or not
    at all.

    ``direct``: the metadata files (``.zgroup``, ``.zattrs``, each array's ``.zarray`` and
    ``.zattrs``, ``.zmetadata``) are written here as the JSON zarr writes, and the coordinates'
    chunks encoded with the arrays' compressor, as zarr does (no chunk that holds only the fill
    value); ``False`` (or a coordinate of another type than numbers and words): zarr builds them in
    memory. The two give the same files (tests/test_sweep_hardening.py); the direct way costs a fifth
    to a half of the CPU of zarr's asynchronous API, most of it the file creations themselves (docs/sweeps.md).
    """
    files = _direct_files(sweep, per_chunk) if direct else None
    if files is None:
        files = _zarr_files(sweep, per_chunk)
    tmp = f"{path}.creating-{os.getpid()}"
    if os.path.lexists(tmp):  # left by a killed process of the same id
        import shutil
        shutil.rmtree(tmp)
    _write_tree(tmp, files)
    os.rename(tmp, path)


def _arrays(sweep, per_chunk: int):
    """``(name, dims, shape, chunks, dtype, fill, attrs, values)`` of every array of the store (``values``:
    a coordinate's, else ``None``)."""
    chunks = chunk_shape(sweep.shape, per_chunk)
    sizes = dict(zip(sweep.keys, sweep.shape), step=int(sweep.facts.states.max()), node=int(sweep.facts.nodes.max()))
    point = dict(zip(sweep.keys, chunks))
    for name, (dims, values, attrs, chunk) in _coords(sweep, chunks).items():
        fill = None if values.dtype.kind == "U" else np.nan if values.dtype.kind == "f" else 0
        yield (name, dims, values.shape, tuple(chunk or values.shape), values.dtype, fill,
               dict(attrs, _ARRAY_DIMENSIONS=list(dims)), values)
    for name, (dims, dt, fill, attrs) in _variables(sweep, result_fields(sweep)).items():
        yield (name, dims, tuple(sizes[d] for d in dims), tuple(point.get(d, sizes[d]) for d in dims), dt, fill,
               dict(attrs, _ARRAY_DIMENSIONS=list(dims)), None)


def _zarr_files(sweep, per_chunk: int) -> dict:
    """``key -> bytes`` of the store, built by zarr in memory."""
    import zarr
    from numcodecs import get_codec
    from zarr.storage import MemoryStore
    files = {}
    memory = MemoryStore(store_dict=files)
    group = zarr.open_group(memory, mode="w-", zarr_format=2, attributes=_global_attrs(sweep))
    for name, _, shape, chunks, dt, fill, attrs, values in _arrays(sweep, per_chunk):
        arr = group.create_array(name, shape=shape, chunks=chunks, dtype=dt, fill_value=fill, attributes=attrs,
                                 compressors=get_codec(dict(COMPRESSOR)))
        if values is not None:
            arr[...] = values
    zarr.consolidate_metadata(memory, zarr_format=2)
    return {key: buf.to_bytes() for key, buf in files.items()}


def _direct_files(sweep, per_chunk: int):
    """``key -> bytes`` of the store, the JSON written here (zarr's own layout and encoding: its
    ``ArrayV2Metadata.to_buffer_dict``); ``None`` for a coordinate of a type not in :data:`_DIRECT_KINDS`."""
    from numcodecs import get_codec
    codec = get_codec(dict(COMPRESSOR))
    attrs = _global_attrs(sweep)
    meta = {".zgroup": {"zarr_format": 2}, ".zattrs": attrs}
    files = {}
    # zarr's order of the consolidated metadata (casefolded names): the same bytes, not only the same JSON
    for name, _, shape, chunks, dt, fill, array_attrs, values in sorted(_arrays(sweep, per_chunk),
                                                                         key=lambda a: (a[0].casefold(), a[0])):
        if dt.kind not in _DIRECT_KINDS:
            return None
        zarray = {"shape": list(shape), "chunks": list(chunks), "dtype": dt.str, "fill_value": _json_fill(fill),
                  "order": "C", "filters": None, "dimension_separator": ".", "compressor": dict(COMPRESSOR),
                  "zarr_format": 2}
        meta[f"{name}/.zattrs"], meta[f"{name}/.zarray"] = array_attrs, zarray
        if values is not None:
            files.update(_coordinate_chunks(name, values, chunks, dt, fill, codec))
    for key, doc in meta.items():
        files[key] = json.dumps(doc, indent=2, allow_nan=True).encode()
    files[".zmetadata"] = json.dumps({"metadata": meta, "zarr_consolidated_format": 1}, allow_nan=True).encode()
    return files


def _json_fill(fill):
    """A fill value as zarr-2 metadata spells it (``"NaN"`` for a float NaN, ``null`` for none)."""
    if fill is None:
        return None
    if isinstance(fill, float):
        return "NaN" if math.isnan(fill) else "Infinity" if fill == math.inf else "-Infinity" if fill == -math.inf \
            else fill
    return int(fill)


def _coordinate_chunks(name, values, chunks, dt, fill, codec) -> dict:
    """``key -> bytes`` of the chunks of a coordinate: each padded with the fill value to the whole chunk
    and encoded with ``codec``; a chunk that holds only the fill value is not written (as zarr does)."""
    out = {}
    fill_value = np.zeros((), dt)[()] if fill is None else fill
    for index in itertools.product(*(range(-(-n // c)) for n, c in zip(values.shape, chunks))):
        sel = tuple(slice(i * c, min(i * c + c, n)) for i, c, n in zip(index, chunks, values.shape))
        part = values[sel]
        if dt.kind == "f" and np.isnan(fill_value) and np.isnan(part).all() or np.all(part == fill_value):
            continue
        block = np.full(chunks, fill_value, dtype=dt)
        block[tuple(slice(0, s.stop - s.start) for s in sel)] = part
        out[f"{name}/{'.'.join(map(str, index))}"] = codec.encode(block)
    return out


def _write_tree(root: str, files: dict) -> None:
    """``files`` (``key -> bytes``, keys ``/``-separated) as new files under the new folder ``root``."""
    folders = {os.path.dirname(key) for key in files} - {""}
    os.mkdir(root)
    for folder in sorted(folders):
        os.makedirs(os.path.join(root, *folder.split("/")), exist_ok=True)
    for key, data in files.items():
        fd = os.open(os.path.join(root, *key.split("/")), os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        try:
            view = memoryview(data)
            while view:
                view = view[os.write(fd, view):]
        finally:
            os.close(fd)


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


class _Array:
    """One array of a store as :class:`StoreWriter` sees it: shape, dtype, fill value, chunks, and how
    its chunks are written: as files (``folder``, ``codec``, ``separator``: zarr-2 on disk) or by
    zarr (``zarr``: the opened array)."""

    __slots__ = ("shape", "dtype", "fill", "chunks", "folder", "codec", "separator", "zarr")

    def __init__(self, shape, dtype, fill, chunks, folder=None, codec=None, separator=".", zarr=None):
        self.shape, self.dtype, self.chunks = tuple(shape), np.dtype(dtype), tuple(chunks)
        self.fill = np.zeros((), self.dtype)[()] if fill is None else fill
        self.folder, self.codec, self.separator, self.zarr = folder, codec, separator, zarr

    @property
    def ndim(self) -> int:
        return len(self.shape)

    def key(self, chunk: tuple) -> str:
        """The file of the chunk at ``chunk`` (indices over the swept dimensions; 0 over the others)."""
        name = self.separator.join(str(c) for c in chunk + (0,) * (self.ndim - len(chunk)))
        return os.path.join(self.folder, *name.split("/"))

    def read(self, chunk: tuple) -> np.ndarray:
        """The whole chunk at ``chunk`` as stored (the fill value where no file is)."""
        try:
            with open(self.key(chunk), "rb") as fh:
                data = fh.read()
        except FileNotFoundError:
            return np.full(self.chunks, self.fill, dtype=self.dtype)
        raw = self.codec.decode(data) if self.codec is not None else data
        return np.frombuffer(raw, dtype=self.dtype).reshape(self.chunks).copy()


def _fill_from_json(value, dtype):
    """A zarr-2 ``fill_value`` as a number (``"NaN"``, ``"Infinity"``, ``"-Infinity"`` for floats)."""
    if value is None:
        return None
    if isinstance(value, str):
        return float(value.replace("Infinity", "inf"))
    return np.asarray(value, dtype=dtype)[()]


def _arrays_from_metadata(root: str):
    """``name -> _Array`` of the zarr-2 store at ``root`` read from its consolidated metadata, every chunk
    a file; ``None`` when the store is not plain zarr-2 files (no ``.zmetadata``, filters, another
    order, a dtype zarr must convert): zarr then writes."""
    from numcodecs import get_codec
    try:
        with open(os.path.join(root, ".zmetadata"), "rb") as fh:
            meta = json.loads(fh.read())["metadata"]
        out = {}
        for key, m in meta.items():
            if not key.endswith("/.zarray"):
                continue
            name, dt, sep = key[:-len("/.zarray")], np.dtype(m["dtype"]), m.get("dimension_separator", ".")
            if "/" in name or m.get("zarr_format") != 2 or m.get("filters") or m.get("order", "C") != "C" \
                    or dt.kind not in "biufU" or sep not in (".", "/"):
                return None
            codec = get_codec(dict(m["compressor"])) if m.get("compressor") else None
            out[name] = _Array(m["shape"], dt, _fill_from_json(m.get("fill_value"), dt), m["chunks"],
                               os.path.join(root, name), codec, sep)
        return out if "status" in out else None
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None


def _arrays_from_zarr(group) -> dict:
    """``name -> _Array`` of every array of ``group``, opened by zarr (each written by zarr)."""
    out = {}
    for k in group.array_keys():
        a = group[k]
        out[k] = _Array(a.shape, a.dtype, a.fill_value, a.chunks, zarr=a)
    return out


class StoreWriter:
    """Writes points into a sweep's store, one chunk at a time: every variable's chunk, ``status`` last.

    A write is the points of one chunk (one task of the sweep): each variable's block of that
    chunk is filled in memory and written whole. In a zarr-2 store on disk (what
    :func:`create_store` makes) the arrays are known from the store's consolidated metadata
    (``.zmetadata``, one file read: no zarr array is opened) and a block is encoded with the
    array's own compressor and written as its chunk file (zarr-2's key ``i.j.k``) through a
    temporary file renamed over it, so a kill never leaves half a chunk; zarr's asynchronous path
    costs thread hops per array, ~30 arrays a chunk, more on a loaded machine. Otherwise (a store
    in memory, another layout) zarr opens the arrays and writes the blocks. Points of the chunk not
    in the write keep what the store holds (a re-run that computes only a chunk's failed points
    reads the chunk first). ``sweep``: the :class:`~rollqp.sweep.Sweep` or its :class:`Layout`.
    """

    def __init__(self, group, sweep):
        from zarr.storage import LocalStore
        local = isinstance(group.store, LocalStore) and getattr(group.metadata, "zarr_format", None) == 2
        root = os.path.join(str(group.store.root), *[p for p in group.path.split("/") if p]) if local else None
        arrays = _arrays_from_metadata(root) if local else None
        self._setup(sweep, arrays or _arrays_from_zarr(group), root)

    @classmethod
    def at(cls, path, sweep) -> "StoreWriter":
        """The writer of the store at ``path`` from its files alone; zarr opens it only when they are
        not plain zarr-2 files with consolidated metadata."""
        path = os.fspath(path)
        arrays = _arrays_from_metadata(path)
        if arrays is None:
            import zarr
            return cls(zarr.open_group(path, mode="r+", zarr_format=2), sweep)
        self = cls.__new__(cls)
        self._setup(sweep, arrays, path)
        return self

    def _setup(self, sweep, arrays: dict, root) -> None:
        self.sweep, self.arrays = sweep, arrays
        self.chunks = tuple(arrays["status"].chunks)
        self.names = [k for k in arrays if k not in sweep.keys and (k not in ("q", "x") or arrays[k].ndim > 1)]
        #: Every chunk is written as a file of a store on disk (whose folder is ``root``).
        self.on_disk = all(arrays[k].folder is not None for k in self.names + ["status"])
        self.root = root if self.on_disk else None

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

    def _block(self, name, region, whole: bool) -> np.ndarray:
        """The whole chunk at ``region`` of array ``name``: the fill value, or (not ``whole``) as stored."""
        a = self.arrays[name]
        if not whole and a.zarr is None:
            return a.read(tuple(s.start // c for s, c in zip(region, self.chunks)))
        block = np.full(self.chunks + a.shape[len(region):], a.fill, dtype=a.dtype)
        if not whole:  # keep the chunk's other points
            block[tuple(slice(0, s.stop - s.start) for s in region)] = a.zarr[region]
        return block

    def _blocks(self, region, points, outs) -> dict:
        """``name -> block`` of the whole chunk at ``region`` with ``outs`` (one per point) filled in."""
        whole = len(points) == math.prod(s.stop - s.start for s in region)
        blocks = {name: self._block(name, region, whole) for name in self.names + ["status"]}
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
        for name in names:
            a = self.arrays[name]
            if a.zarr is not None:
                a.zarr[region] = blocks[name][clipped]
                continue
            data = np.ascontiguousarray(blocks[name], dtype=a.dtype)
            _write_file(a.key(chunk), a.codec.encode(data) if a.codec is not None else data.tobytes())

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
