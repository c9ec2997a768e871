"""Reading ``.npz`` files that rollqp did not write itself: every byte is untrusted.

Result files, step files and candidate solutions arrive from disk, from other programs and from
other people. :func:`read_npz` opens one without trusting it: no pickles, a corrupt archive or
member (a flipped bit: bad CRC, truncated data) is an :class:`~rollqp.errors.InputError` naming
the argument, and an array header is checked before its data are read — a header that claims
more data than its zip member holds, or more than :data:`MAX_BYTES`, is refused without
allocating anything. The ``*_value`` helpers then check each key's kind, shape and finiteness:
a complex, string or NaN entry where a real number belongs is an error naming the key, never a
silent cast.
"""
from __future__ import annotations

import os
import struct
import zipfile
import zlib

import numpy as np

from .errors import InputError

__all__ = ["MAX_BYTES", "read_npz", "real_array", "real_scalar", "text_value"]

#: Largest array rollqp reads from an ``.npz`` (4 GiB): beyond the dense problems it solves
#: (a 20,000-node influence matrix is 3.2 GB), so a larger header is corrupt or hostile.
MAX_BYTES = 4 << 30
#: Longest string entry (method names, JSON scene descriptions).
MAX_TEXT = 1 << 20


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


def _member(zf, info, arg, path):
    """One array of the archive, its header checked before its data are read."""
    name = info.filename[:-4] if info.filename.endswith(".npy") else info.filename
    with zf.open(info) as fh:
        shape, dtype = _header(fh)
        if dtype.hasobject:
            raise InputError(arg, f"{path!r}: key {name!r} holds Python objects (pickles are not read)")
        nbytes = int(np.prod(shape, dtype=np.float64)) * dtype.itemsize
        if nbytes > min(MAX_BYTES, info.file_size):
            raise InputError(arg, f"{path!r}: key {name!r} claims {nbytes:.3g} bytes ({shape}, {dtype}), more than "
                                  f"its {info.file_size} bytes in the archive or the limit {MAX_BYTES:.3g}: corrupt file")
    with zf.open(info) as fh:
        return name, np.lib.format.read_array(fh, allow_pickle=False)


def read_npz(path, arg: str) -> dict:
    """Every array of the ``.npz`` at ``path``, read without trusting it (module docstring).

    Raises
    ------
    InputError
        ``arg`` (the command-line argument or parameter the path came from): a missing file,
        not a zip archive, a corrupt member, pickled objects, or an oversized header.
    """
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise InputError(arg, f"no such file: {path!r}")
    if not zipfile.is_zipfile(path):
        raise InputError(arg, f"{path!r} is not a .npz file (numpy's zip archive of arrays)")
    out = {}
    try:
        with zipfile.ZipFile(path) as zf:
            for info in zf.infolist():
                if not info.filename.endswith(".npy"):
                    raise InputError(arg, f"{path!r}: member {info.filename[:80]!r} is not a numpy array")
                name, value = _member(zf, info, arg, path)
                out[name] = value
    except InputError:
        raise
    except (zipfile.BadZipFile, zipfile.LargeZipFile, zlib.error, EOFError, OSError, ValueError, MemoryError,
            NotImplementedError, RuntimeError, KeyError, TypeError, struct.error) as exc:
        # what zipfile and numpy raise on corrupt archives: bad headers, an unknown zip version or
        # compression (NotImplementedError), an "encrypted" flag (RuntimeError), bad struct fields
        first = (str(exc).splitlines() or [""])[0][:120]
        raise InputError(arg, f"{path!r} is not a readable .npz without pickles "
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


def text_value(z: dict, key: str, arg: str, choices=None) -> str:
    """``z[key]`` as a string (at most :data:`MAX_TEXT` characters), one of ``choices`` if given."""
    if key not in z:
        raise InputError(arg, f"missing key {key!r}")
    v = np.asarray(z[key])
    if v.dtype.kind not in "US" or v.shape != ():
        raise InputError(arg, f"key {key!r} must be a string, got {v.dtype} of shape {v.shape}")
    s = str(v)
    if len(s) > MAX_TEXT:
        raise InputError(arg, f"key {key!r} is longer than {MAX_TEXT} characters")
    if choices is not None and s not in choices:
        raise InputError(arg, f"key {key!r} must be one of {', '.join(map(repr, choices))}, got {s[:60]!r}")
    return s
