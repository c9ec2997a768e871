"""Reading ``.npz`` files that rollqp did not write itself (every byte is untrusted), and writing them in parts.

Result files, step files and candidate solutions arrive from disk, from other programs and from
other people. :func:`read_npz` opens one without trusting it: no pickles, a corrupt archive or
member (a flipped bit: bad CRC, truncated data) is an :class:`~rollqp.errors.InputError` naming
the argument, and an array header is checked before its data are read — a header that claims
more data than its zip member holds, or more than :data:`MAX_BYTES`, is refused without
allocating anything. The ``*_value`` helpers then check each key's kind, shape and finiteness:
a complex, string or NaN entry where a real number belongs is an error naming the key, never a
silent cast.

A large stored (uncompressed) member is not read into memory: :func:`read_npz` with ``map_above``
checks its CRC block by block and hands back a read-only memory map of it (a result file of a
long run can be larger than the memory). :class:`NpzStream` writes an archive one member at a
time, an array in blocks of rows (:meth:`NpzStream.rows`), so that a file larger than the memory
is written with a bounded buffer; numpy reads what it writes (the zip members of ``np.savez``).
"""
from __future__ import annotations

import io
import os
import struct
import zipfile
import zlib
from typing import Iterable

import numpy as np

from .errors import InputError

__all__ = ["MAX_BYTES", "read_npz", "real_array", "real_scalar", "text_value", "NpzStream"]

#: Largest array rollqp reads from an ``.npz`` (4 GiB): beyond the dense problems it solves
#: (a 20,000-node influence matrix is 3.2 GB), so a larger header is corrupt or hostile.
MAX_BYTES = 4 << 30
#: Longest string entry (method names, JSON scene descriptions) unless a reader allows more.
MAX_TEXT = 1 << 20
#: Bytes of a mapped member checked (CRC) per read.
CRC_BLOCK = 1 << 20
_LOCAL = struct.Struct("<4s22xHH")  # a zip local file header: signature, ..., name length, extra length


def _header(fh):
    """``(shape, dtype)`` of an ``.npy`` stream, read from its header only."""
    version = np.lib.format.read_magic(fh)
    if version == (1, 0):
        shape, _, dtype = np.lib.format.read_array_header_1_0(fh)
    elif version == (2, 0):
        shape, _, dtype = np.lib.format.read_array_header_2_0(fh)
    else:
        raise ValueError(f"unsupported .npy format version {version}")
    return shape, dtype


def _member(zf, info, arg, path, source, map_above):
    """One array of the archive, its header checked before its data are read (a large stored one mapped)."""
    name = info.filename[:-4] if info.filename.endswith(".npy") else info.filename
    with zf.open(info) as fh:
        shape, dtype = _header(fh)
        if dtype.hasobject:
            raise InputError(arg, f"{path!r}: key {name!r} holds Python objects (pickles are not read)")
        nbytes = int(np.prod(shape, dtype=np.float64)) * dtype.itemsize
        mapped = (map_above is not None and nbytes > map_above and info.compress_type == zipfile.ZIP_STORED
                  and isinstance(source, str))
        limit = info.file_size if mapped else min(MAX_BYTES, info.file_size)
        if nbytes > limit:
            raise InputError(arg, f"{path!r}: key {name!r} claims {nbytes:.3g} bytes ({shape}, {dtype}), more than "
                                  f"its {info.file_size} bytes in the archive or the limit {MAX_BYTES:.3g}: corrupt file")
        header = fh.tell()  # the .npy header's length: the data follow it
    if mapped and header + nbytes != info.file_size:
        raise InputError(arg, f"{path!r}: key {name!r} claims {nbytes} bytes of data, its member holds "
                              f"{info.file_size - header}: corrupt file")
    if mapped:
        return name, _mapped(source, info, header, shape, dtype)
    with zf.open(info) as fh:
        return name, np.lib.format.read_array(fh, allow_pickle=False)


def _mapped(path, info, header, shape, dtype):
    """A read-only memory map of a stored member's array, after one pass of reads (not through the map: its
    pages would stay resident) that checks the member's CRC and, for floats, whether every value is finite
    (the map's ``all_finite``; None for integers)."""
    with open(path, "rb") as fh:
        fh.seek(info.header_offset)
        sig, nlen, elen = _LOCAL.unpack(fh.read(_LOCAL.size))
        if sig != b"PK\x03\x04":
            raise zipfile.BadZipFile(f"bad local header of {info.filename[:80]!r}")
        start = info.header_offset + _LOCAL.size + nlen + elen
        fh.seek(start)
        crc = zlib.crc32(fh.read(header))
        left, finite, rest = info.file_size - header, True, b""
        step = max(dtype.itemsize, CRC_BLOCK - CRC_BLOCK % dtype.itemsize)
        while left:
            block = fh.read(min(step, left))
            if not block:
                raise EOFError(f"member {info.filename[:80]!r} is truncated")
            crc, left = zlib.crc32(block, crc), left - len(block)
            if dtype.kind == "f" and finite:
                data = rest + block
                cut = len(data) - len(data) % dtype.itemsize
                finite = bool(np.isfinite(np.frombuffer(data[:cut], dtype=dtype)).all())
                rest = data[cut:]
    if crc != info.CRC:
        raise zipfile.BadZipFile(f"bad CRC-32 for file {info.filename[:80]!r}")
    out = np.memmap(path, dtype=dtype, mode="r", offset=start + header, shape=tuple(shape))
    out.all_finite = finite if dtype.kind == "f" else None
    return out


def read_npz(path, arg: str, map_above: int | None = None) -> dict:
    """Every array of the ``.npz`` at ``path`` (or in the bytes ``path``), read without trusting it
    (module docstring).

    Parameters
    ----------
    path : path or bytes
    arg : str
        The command-line argument or parameter the path came from, named in every error.
    map_above : int, optional
        Stored members larger than this many bytes are memory-mapped (read-only) instead of read,
        after their CRC is checked; ``None``: every member is read (at most :data:`MAX_BYTES`).

    Raises
    ------
    InputError
        ``arg``: a missing file, not a zip archive, a corrupt member, pickled objects, or an
        oversized header.
    """
    if isinstance(path, (bytes, bytearray)):
        source, shown = io.BytesIO(path), "(embedded archive)"
        if not zipfile.is_zipfile(source):
            raise InputError(arg, f"{shown} is not a .npz archive")
    else:
        source = shown = os.fspath(path)
        if not os.path.isfile(source):
            raise InputError(arg, f"no such file: {source!r}")
        if not zipfile.is_zipfile(source):
            raise InputError(arg, f"{source!r} is not a .npz file (numpy's zip archive of arrays)")
    out = {}
    try:
        with zipfile.ZipFile(source) as zf:
            for info in zf.infolist():
                if not info.filename.endswith(".npy"):
                    raise InputError(arg, f"{shown!r}: member {info.filename[:80]!r} is not a numpy array")
                name, value = _member(zf, info, arg, shown, source, map_above)
                if name in out:  # (numpy's own reader takes the last: a forged member would win)
                    raise InputError(arg, f"{shown!r} holds the member {name[:80]!r} twice: a corrupt or forged file")
                out[name] = value
    except InputError:
        raise
    except (zipfile.BadZipFile, zipfile.LargeZipFile, zlib.error, EOFError, OSError, ValueError, MemoryError,
            NotImplementedError, RuntimeError, KeyError, TypeError, struct.error) as exc:
        # what zipfile and numpy raise on corrupt archives: bad headers, an unknown zip version or
        # compression (NotImplementedError), an "encrypted" flag (RuntimeError), bad struct fields
        first = (str(exc).splitlines() or [""])[0][:120]
        raise InputError(arg, f"{shown!r} is not a readable .npz without pickles "
                              f"({type(exc).__name__}: {first})") from exc
    return out


def _numeric(z: dict, key: str, arg: str) -> np.ndarray:
    if key not in z:
        raise InputError(arg, f"missing key {key!r}")
    v = np.asarray(z[key])
    if v.dtype.kind not in "iuf":  # bool, complex, strings, bytes, objects: not a real number
        raise InputError(arg, f"key {key!r} must hold real numbers, got dtype {v.dtype}")
    return v.astype(float)


def real_array(z: dict, key: str, shape: tuple, arg: str, finite: bool = True) -> np.ndarray:
    """``z[key]`` as a float array of ``shape`` (real, finite unless ``finite=False``)."""
    v = _numeric(z, key, arg)
    if v.shape != tuple(shape):
        raise InputError(arg, f"key {key!r} must have shape {tuple(shape)}, got {v.shape}")
    if finite and not np.all(np.isfinite(v)):
        raise InputError(arg, f"key {key!r} must be finite")
    return v


def real_scalar(z: dict, key: str, arg: str, finite: bool = True) -> float:
    """``z[key]`` as one real number (a 0-d or one-element array); NaN allowed if not ``finite``."""
    v = _numeric(z, key, arg)
    if v.size != 1 or v.ndim > 1:
        raise InputError(arg, f"key {key!r} must be one number, got shape {v.shape}")
    x = float(v.reshape(()))
    if finite and not np.isfinite(x):
        raise InputError(arg, f"key {key!r} must be finite, got {x!r}")
    return x


def text_value(z: dict, key: str, arg: str, choices=None, limit: int = MAX_TEXT) -> str:
    """``z[key]`` as a string (at most ``limit`` characters), one of ``choices`` if given."""
    if key not in z:
        raise InputError(arg, f"missing key {key!r}")
    v = np.asarray(z[key])
    if v.dtype.kind not in "US" or v.shape != ():
        raise InputError(arg, f"key {key!r} must be a string, got {v.dtype} of shape {v.shape}")
    if v.dtype.itemsize > 4 * limit:  # (a character of a 'U' array is 4 bytes)
        raise InputError(arg, f"key {key!r} is longer than {limit} characters")
    s = str(v)
    if len(s) > limit:
        raise InputError(arg, f"key {key!r} is longer than {limit} characters")
    if choices is not None and s not in choices:
        raise InputError(arg, f"key {key!r} must be one of {', '.join(map(repr, choices))}, got {s[:60]!r}")
    return s


class NpzStream:
    """An ``.npz`` written one member at a time into the open binary file ``fh`` (stored, zip64).

    :meth:`array` writes a whole array, :meth:`rows` an array of known shape from blocks of rows
    (the rows of a result field read from a run's journal): only one block is in memory. Close
    it (or use it as a context manager) to write the archive's directory.
    """

    def __init__(self, fh):
        self.zf = zipfile.ZipFile(fh, "w", compression=zipfile.ZIP_STORED, allowZip64=True)

    def array(self, name: str, value) -> None:
        """Write the array ``value`` as key ``name``."""
        value = np.asanyarray(value)
        with self.zf.open(name + ".npy", "w", force_zip64=True) as out:
            np.lib.format.write_array(out, value, allow_pickle=False)

    def rows(self, name: str, dtype, shape: tuple, blocks: Iterable) -> None:
        """Write key ``name`` of ``shape`` and ``dtype`` from ``blocks`` of rows (arrays of shape
        ``(m, *shape[1:])``, in order; their rows must add up to ``shape[0]``)."""
        dtype = np.dtype(dtype)
        header = {"descr": np.lib.format.dtype_to_descr(dtype), "fortran_order": False, "shape": tuple(shape)}
        rows = 0
        with self.zf.open(name + ".npy", "w", force_zip64=True) as out:
            np.lib.format.write_array_header_2_0(out, header)
            for block in blocks:
                block = np.ascontiguousarray(block, dtype=dtype)
                if block.shape[1:] != tuple(shape[1:]):
                    raise ValueError(f"{name}: a block of shape {block.shape} for rows of {tuple(shape[1:])}")
                out.write(block.data if block.size else b"")
                rows += block.shape[0]
        if rows != shape[0]:
            raise ValueError(f"{name}: {rows} rows written for {shape[0]}")

    def close(self) -> None:
        self.zf.close()

    def __enter__(self) -> "NpzStream":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
