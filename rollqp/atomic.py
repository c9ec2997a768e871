"""Writing output files safely: atomic replacement, the temporaries of killed writers, one writer per
file, and signals held back while a file is being written (docs/results.md, "Writing").

* A file is written to a temporary file in its own folder (``.rollqp-<pid>.<start>-<random>``),
  then renamed over the target: a reader sees the old file or the new one, never half of one.
  Temporaries left by a writer that was killed (SIGKILL during the write) are removed by the next
  write into the same folder (:func:`remove_stale_temporaries`); a process is recognized by its
  id *and* its start time, so a temporary whose id now belongs to another process is still stale.
* :class:`OutputLock` gives one process the right to write a result file for the length of a
  run: an advisory ``flock`` on ``PATH.lock``, which the kernel releases when its holder dies,
  however it dies (a lock file left behind, or whose process id now belongs to another process,
  is taken over at once).
* :func:`held_signals`: SIGINT and SIGTERM are held back while a file is written, so that a second
  Ctrl-C 0–40 ms after the first never interrupts the write of what the first one saves.
* :func:`save_npz` writes a ``.npz`` this way (a 2D or 3D result file, a step file's arrays), with a
  result's ``meta`` encoded by :func:`encode_meta` (its long lists as arrays; :func:`decode_meta` puts
  them back).
"""
from __future__ import annotations

import contextlib
import json
import os
import re
import signal
import tempfile
import threading

import numpy as np

from .errors import InputError
from .journal import json_default as _json_default
from .npzfile import NpzStream

#: A list of more than this many numbers in a result's ``meta`` is stored as an array of its own.
META_ARRAY_MIN = 64
#: Longest array referenced from ``meta`` (a profile table of a million points, a list of a million steps).
MAX_META_ARRAY = 2_000_001

__all__ = ["TEMP_PREFIX", "process_start", "alive", "remove_stale_temporaries", "temporary", "written", "replace",
           "OutputLock", "held_signals", "stop_once", "save_npz", "encode_meta", "decode_meta"]

#: Temporary files of an atomic write start with this (module docstring).
TEMP_PREFIX = ".rollqp-"


def process_start(pid: int) -> str | None:
    """The start time of process ``pid`` (clock ticks after boot, ``/proc/PID/stat`` field 22), or None."""
    try:
        with open(f"/proc/{int(pid)}/stat", "rb") as fh:
            text = fh.read(4096).decode("ascii", "replace")
    except (OSError, ValueError):
        return None
    fields = text[text.rfind(")") + 2:].split()  # after the command name, which may hold spaces
    return fields[19] if len(fields) > 19 else None


def alive(pid: int, start: str | None = None) -> bool:
    """Whether process ``pid`` exists on this machine (and, if ``start`` is given and readable, started then)."""
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        pass
    except OverflowError:
        return False
    if start is None:
        return True
    now = process_start(pid)
    return now is None or now == start


def _own_tag() -> str:
    start = process_start(os.getpid())
    return f"{os.getpid()}" + (f".{start}" if start else "")


def remove_stale_temporaries(folder) -> list[str]:
    """Delete the temporary files of writes whose process no longer runs; return their names."""
    removed = []
    try:
        names = os.listdir(folder)
    except OSError:
        return removed
    for name in names:
        if not name.startswith(TEMP_PREFIX):
            continue
        tag = name[len(TEMP_PREFIX):].split("-", 1)[0]
        pid, _, start = tag.partition(".")
        if pid.isdigit() and not alive(int(pid), start or None):
            try:
                os.unlink(os.path.join(folder, name))
                removed.append(name)
            except OSError:
                pass
    return removed


def temporary(path, suffix: str = ".npz") -> tuple[int, str]:
    """``(fd, name)`` of a new temporary file beside ``path`` (stale ones of killed writers removed first)."""
    folder = os.path.dirname(os.path.abspath(path))
    remove_stale_temporaries(folder)
    return tempfile.mkstemp(suffix=suffix, dir=folder, prefix=f"{TEMP_PREFIX}{_own_tag()}-")


@contextlib.contextmanager
def written(path, suffix: str = ".npz"):
    """``with written(path) as (fh, tmp):`` write a temporary file beside ``path`` (binary ``fh``, its name
    ``tmp``); renamed over ``path`` (:func:`replace`) when the block ends, removed if it raises."""
    fd, tmp = temporary(path, suffix)
    try:
        with os.fdopen(fd, "wb") as fh:
            yield fh, tmp
        replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def replace(tmp: str, path) -> None:
    """Give the temporary ``tmp`` the usual file mode and rename it over ``path``."""
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)  # mkstemp creates 0600
    os.replace(tmp, path)


class OutputLock:
    """Exclusive right to write one output for the length of a run (``with OutputLock(path):``).

    An advisory lock (``flock``) on ``PATH.lock``, which holds the writer's process id for the
    message. A second run writing the same ``--out`` while the first is alive is refused at once,
    before any work (:class:`InputError` naming ``--out`` and the other process), instead of racing
    it. The kernel drops the lock with its process, so a lock file left by a killed run, or one whose
    process id now belongs to another process, is taken over. On a file system without ``flock``, the
    process id and start time written in the file decide whether its writer still runs.
    """

    def __init__(self, path, key: str = "--out"):
        self.lock = os.fspath(path) + ".lock"
        self.key = key
        self.fd = -1

    def __enter__(self) -> "OutputLock":
        import fcntl
        for _ in range(5):
            fd = os.open(self.lock, os.O_CREAT | os.O_RDWR, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                owner = self._owner(fd)
                os.close(fd)
                raise InputError(self.key, f"another rollqp process{f' (pid {owner})' if owner else ''} is writing "
                                           f"{self.lock[:-5]!r}; wait for it or choose another --out") from None
            except OSError:  # no flock here: the id and start time in the file
                os.close(fd)
                return self._without_flock()
            try:
                same = os.path.samestat(os.fstat(fd), os.stat(self.lock))
            except FileNotFoundError:
                same = False
            if not same:  # its holder removed it as we opened it: lock the new one
                os.close(fd)
                continue
            os.ftruncate(fd, 0)
            os.write(fd, _own_tag().replace(".", " ").encode())
            self.fd = fd
            return self
        raise InputError(self.key, f"cannot lock {self.lock!r}")

    def _without_flock(self) -> "OutputLock":
        for _ in range(2):
            try:
                fd = os.open(self.lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
            except FileExistsError:
                with open(self.lock, "rb") as fh:
                    parts = fh.read(64).decode("ascii", "replace").split()
                if parts and parts[0].isdigit() and alive(int(parts[0]), parts[1] if len(parts) > 1 else None):
                    raise InputError(self.key, f"another rollqp process (pid {parts[0]}) is writing "
                                               f"{self.lock[:-5]!r}; wait for it or choose another --out") from None
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(self.lock)  # stale: its process is gone
                continue
            os.write(fd, _own_tag().replace(".", " ").encode())
            self.fd = fd
            return self
        raise InputError(self.key, f"cannot lock {self.lock!r}")

    @staticmethod
    def _owner(fd) -> int | None:
        try:
            text = os.pread(fd, 64, 0).decode("ascii", "replace").split()
        except OSError:
            return None
        return int(text[0]) if text and text[0].isdigit() else None

    def __exit__(self, *exc) -> None:
        if self.fd >= 0:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(self.lock)  # first, while it is held (a waiter then finds a new file)
            os.close(self.fd)
            self.fd = -1


@contextlib.contextmanager
def held_signals():
    """SIGINT and SIGTERM held back for the block (the main thread only; elsewhere nothing changes).

    Yields the list of the signals that arrived; the caller decides what they mean once the file is
    written (:meth:`rollqp.result.Result.finish` raises the first one again).
    """
    got: list[int] = []
    if threading.current_thread() is not threading.main_thread():
        yield got
        return
    old = {}
    try:
        for s in (signal.SIGINT, signal.SIGTERM):
            old[s] = signal.signal(s, lambda signum, frame: got.append(signum))
        yield got
    finally:
        for s, h in old.items():
            signal.signal(s, h)


@contextlib.contextmanager
def stop_once():
    """For the block (a run): the first SIGINT (and SIGTERM, where a handler is set, as the command line does) acts
    as before — Python's KeyboardInterrupt, the command line's ``Terminated`` — and every later one is held back:
    a second Ctrl-C 0–40 ms after the first, while the first one's states are being written, changes nothing.
    The main thread only; elsewhere nothing changes."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    stopping, old = [], {}

    def handler(signum, frame):
        if stopping:
            return
        stopping.append(signum)
        old[signum](signum, frame)

    try:
        for s in (signal.SIGINT, signal.SIGTERM):
            prev = signal.getsignal(s)
            if callable(prev):
                old[s] = prev
                signal.signal(s, handler)
        yield
    finally:
        for s, h in old.items():
            signal.signal(s, h)


# =========================================================================== .npz files and their meta
def save_npz(path, arrays: dict, what: str = "result file") -> str:
    """Write ``arrays`` to the ``.npz`` ``path`` atomically (temporary file, then rename), SIGINT and SIGTERM
    held back until it is written (:func:`rollqp.atomic.held_signals`).

    A path not ending in ``.npz`` or in a missing folder is an :class:`InputError` on ``--out``.
    Temporary files left in the folder by killed writers are removed first; an interrupted write
    removes its own. A result's ``meta`` (a dict or its JSON text) is written with its long lists as
    arrays (:func:`encode_meta`).
    """
    path = os.fspath(path)
    if not path.endswith(".npz"):
        raise InputError("--out", f"the {what} must end in .npz, got {path!r}")
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise InputError("--out", f"folder {folder!r} does not exist")
    arrays = dict(arrays)
    if "meta" in arrays and what == "result file":
        meta = arrays["meta"]
        meta = json.loads(str(meta)) if not isinstance(meta, dict) else meta
        text, marrays = encode_meta(meta)
        arrays["meta"] = np.asarray(text)
        arrays.update(marrays)
    with held_signals(), written(path) as (fh, _), NpzStream(fh) as z:
        for k, v in arrays.items():
            z.array(k, v)
    return path


def encode_meta(meta: dict) -> tuple[str, dict]:
    """``(JSON text, arrays)``: every list of more than :data:`META_ARRAY_MIN` numbers in ``meta`` (a profile
    table, a long list of steps) becomes an array ``meta.<path>`` and ``{"$array": "meta.<path>"}`` in the
    text, so that the text stays the size of a scene file whatever the tables (:func:`decode_meta`)."""
    arrays = {}

    def walk(v, path):
        if isinstance(v, np.ndarray):
            v = v.tolist()
        if isinstance(v, dict):
            return {k: walk(x, path + (str(k),)) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            if len(v) > META_ARRAY_MIN and all(_is_number(e) for e in v):
                key = "meta." + re.sub(r"[^A-Za-z0-9_.-]", "_", ".".join(path))[:200]
                while key in arrays:
                    key += "_"
                ints = all(isinstance(e, (int, np.integer)) for e in v)
                arrays[key] = np.asarray(v, dtype=np.int64 if ints else np.float64)
                return {"$array": key}
            return [walk(x, path + (str(i),)) for i, x in enumerate(v)]
        return v
    tree = walk(meta, ())
    return json.dumps(tree, sort_keys=True, default=_json_default), arrays


def _is_number(e) -> bool:
    return isinstance(e, (int, float, np.integer, np.floating)) and not isinstance(e, (bool, np.bool_))


def decode_meta(tree, arrays: dict, arg: str):
    """``meta`` with its ``{"$array": key}`` entries replaced by the lists in ``arrays`` (each checked: a key
    ``meta.*`` of the file, a 1-D array of at most :data:`MAX_META_ARRAY` real numbers)."""
    def walk(v):
        if isinstance(v, dict):
            if set(v) == {"$array"}:
                return _meta_array(v["$array"], arrays, arg)
            return {k: walk(x) for k, x in v.items()}
        if isinstance(v, list):
            return [walk(x) for x in v]
        return v
    return walk(tree)


def _meta_array(key, arrays, arg):
    if not (isinstance(key, str) and key.startswith("meta.") and key in arrays):
        raise InputError(arg, f"key 'meta' refers to an array {str(key)[:80]!r} that the file does not hold")
    a = np.asarray(arrays[key])
    if a.ndim != 1 or a.dtype.kind not in "iuf" or a.size > MAX_META_ARRAY:
        raise InputError(arg, f"key {key!r} must be a 1-D array of at most {MAX_META_ARRAY} numbers, got "
                              f"{a.dtype} of shape {a.shape}")
    return a.tolist()
