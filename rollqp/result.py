"""The result file (docs/results.md): one ``.npz`` without pickled objects, written atomically."""
from __future__ import annotations

import json
import os
import tempfile
from dataclasses import dataclass, field

import numpy as np

from .errors import InputError
from .fields import FIELDS, dtype_of

#: The core per-state and per-step fields, read off each record (:mod:`rollqp.fields` documents them).
_PER_STATE = ("pn", "pt", "slip", "gap", "state")
_PER_STEP = ("q", "P", "Q", "creepage", "approach", "shift", "iterations", "step_time", "residual",
             "inner_normal", "inner_tangential", "backtracks")


@dataclass
class Result:
    """States of a transient: index 0 is the starting state, 1..K the rolling steps.

    The arrays are the result file's (docs/results.md; every key is a :class:`rollqp.fields.Field`):
    the core fields read off each :class:`~rollqp.march.StepRecord` (:meth:`add`), the computed
    fields the scene needs (``extra``: :func:`rollqp.fields.fields_for`), and ``scalars``
    (``a_H``, ``p0``, ``R``, ``Estar``, ``beta``, ``leading_edge``). ``meta`` is JSON-able.
    """

    x: np.ndarray
    scalars: dict
    meta: dict
    extra: list = field(default_factory=list)
    rows: dict = field(default_factory=dict)

    def __post_init__(self):
        for k in _PER_STATE + _PER_STEP + tuple(f.name for f in self.extra):
            self.rows.setdefault(k, [])

    def append(self, **values):
        """Append one state: every core field (and every ``extra`` one) by name."""
        missing = [k for k in self.rows if k not in values]
        if missing:
            raise TypeError(f"Result.append: missing field(s) {', '.join(missing)}")
        new = [(rows, np.array(values[k], copy=True)) for k, rows in self.rows.items()]
        for rows, v in new:  # an interrupt (Ctrl-C, SIGTERM) in here leaves a partial state: len() ignores it
            rows.append(v)

    def extend(self, arrays: dict) -> None:
        """Append every state of a result file's ``arrays`` (an earlier part of the same run);
        its ``gross_sliding`` and ``rolling_start`` notes are kept."""
        meta = arrays.get("meta", {})
        for k in ("gross_sliding", "rolling_start"):
            if k in meta:
                self.meta[k] = meta[k]
        missing = [k for k in self.rows if k not in arrays]
        if missing:
            raise InputError("--resume", f"the result file lacks {', '.join(missing)}: not written by this "
                                         "version of rollqp for this scene")
        for i in range(len(arrays["q"])):
            self.append(**{k: arrays[k][i] for k in self.rows})

    def add(self, rec, operators=None) -> None:
        """Append the state of a :class:`~rollqp.march.StepRecord` (``rec.k`` must be ``len(self)``);
        the ``extra`` fields are computed from the record and the scene's ``operators``."""
        if rec.k != len(self):
            raise ValueError(f"record {rec.k} appended as state {len(self)}")
        st, c, tsol = rec.state, rec.counters, rec.state.tsol
        if rec.gross_sliding:  # possible with a prescribed creepage beyond the sliding creepage
            self.meta.setdefault("gross_sliding", []).append(rec.k)
        if rec.k == 0 and rec.phase == "steady":
            self.meta["rolling_start"] = "direct steady solve"
        elif rec.k == 0 and rec.phase == "rolling":
            self.meta["rolling_start"] = "marching to steady state"
        values = dict(q=rec.q, pn=st.p, pt=st.t, slip=tsol.s, gap=st.nsol.g, state=rec.nodes, P=rec.P, Q=rec.Q,
                      creepage=tsol.xi, approach=st.nsol.delta, shift=rec.shift, iterations=c.iterations,
                      step_time=rec.step_time, residual=c.residual, inner_normal=c.inner_normal,
                      inner_tangential=c.inner_tangential, backtracks=c.backtracks)
        for f in self.extra:
            values[f.name] = f.compute(rec, operators)
        self.append(**values)

    def __len__(self):
        """The complete states (every field appended; one cut short by an interrupt is not counted)."""
        return min(len(v) for v in self.rows.values())

    def arrays(self) -> dict:
        """All arrays of the result file, keyed as in docs/results.md (the complete states)."""
        n = self.x.size
        K1 = len(self)
        out = {"x": np.asarray(self.x, dtype=float)}
        for k, v in self.rows.items():
            v = v[:K1]
            per_state = k in _PER_STATE or (k in FIELDS and FIELDS[k].shape == "state")
            shape = (K1, n) if per_state else (K1,)
            out[k] = np.asarray(v, dtype=dtype_of(k)).reshape(shape)
        for k, v in self.scalars.items():
            out[k] = np.asarray(v)
        out["meta"] = np.asarray(json.dumps(self.meta, sort_keys=True, default=_json_default))
        return out

    def __getitem__(self, key):
        return self.arrays()[key]

    def save(self, path) -> str:
        """Write the result file atomically (temporary file in the same folder, then rename)."""
        return save_npz(path, self.arrays(), "result file")


#: Temporary files of an atomic write: ``.rollqp-<pid>-<random>.npz`` beside the target, so
#: that one left behind by a killed process (SIGKILL during the write) is recognized and removed
#: by the next write into the same folder (:func:`remove_stale_temporaries`).
TEMP_PREFIX = ".rollqp-"


def _alive(pid: int) -> bool:
    """Whether process ``pid`` exists (on this machine)."""
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    return True


def remove_stale_temporaries(folder) -> list[str]:
    """Delete the temporary files of writes whose process no longer runs; return their names."""
    removed = []
    try:
        names = os.listdir(folder)
    except OSError:
        return removed
    for name in names:
        if not (name.startswith(TEMP_PREFIX) and name.endswith(".npz")):
            continue
        pid = name[len(TEMP_PREFIX):].split("-", 1)[0]
        if pid.isdigit() and not _alive(int(pid)):
            try:
                os.unlink(os.path.join(folder, name))
                removed.append(name)
            except OSError:
                pass
    return removed


def check_output(path, what: str = "result file", key: str = "--out") -> str:
    """``path`` as a string if a ``.npz`` can be written there: checked before any work.

    Raises
    ------
    InputError
        ``key``: not ending in ``.npz``, a missing or unwritable folder, or a folder in its place.
    """
    path = os.fspath(path)
    if not path.endswith(".npz"):
        raise InputError(key, f"the {what} must end in .npz, got {path!r}")
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise InputError(key, f"folder {folder!r} does not exist")
    if os.path.isdir(path):
        raise InputError(key, f"{path!r} is a folder, not a file")
    try:
        fd, probe = tempfile.mkstemp(suffix=".npz", dir=folder, prefix=f"{TEMP_PREFIX}{os.getpid()}-")
    except OSError as exc:
        raise InputError(key, f"cannot write in folder {folder!r} ({exc.strerror or exc})") from None
    os.close(fd)
    os.unlink(probe)
    return path


def save_npz(path, arrays: dict, what: str = "result file") -> str:
    """Write ``arrays`` to the ``.npz`` ``path`` atomically (temporary file, then rename).

    A path not ending in ``.npz`` or in a missing folder is an :class:`InputError` on ``--out``.
    Temporary files left in the folder by killed writers are removed first
    (:func:`remove_stale_temporaries`); an interrupted write removes its own.
    """
    path = os.fspath(path)
    if not path.endswith(".npz"):
        raise InputError("--out", f"the {what} must end in .npz, got {path!r}")
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise InputError("--out", f"folder {folder!r} does not exist")
    remove_stale_temporaries(folder)
    fd, tmp = tempfile.mkstemp(suffix=".npz", dir=folder, prefix=f"{TEMP_PREFIX}{os.getpid()}-")
    try:
        with os.fdopen(fd, "wb") as fh:
            np.savez(fh, **arrays)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp creates 0600; give the usual file mode
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path


class OutputLock:
    """Exclusive right to write one result file for the length of a run (``with OutputLock(path):``).

    A lock file ``PATH.lock`` holding the writer's process id, created atomically (``O_EXCL``).
    A second run writing the same ``--out`` while the first is alive is refused at once, before
    any work (:class:`InputError` naming ``--out`` and the other process), instead of racing it
    (the last rename would win). A lock left by a process that no longer runs is taken over.
    """

    def __init__(self, path, key: str = "--out"):
        self.lock = os.fspath(path) + ".lock"
        self.key = key
        self.held = False

    def __enter__(self) -> "OutputLock":
        for _ in range(2):
            try:
                fd = os.open(self.lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
            except FileExistsError:
                owner = self._owner()
                if owner is not None and _alive(owner):
                    raise InputError(self.key, f"another rollqp process (pid {owner}) is writing "
                                               f"{self.lock[:-5]!r}; wait for it or choose another --out") from None
                try:
                    os.unlink(self.lock)  # stale: its process is gone
                except FileNotFoundError:
                    pass
                continue
            with os.fdopen(fd, "w") as fh:
                fh.write(str(os.getpid()))
            self.held = True
            return self
        raise InputError(self.key, f"cannot lock {self.lock!r}")

    def _owner(self):
        try:
            with open(self.lock, encoding="ascii") as fh:
                text = fh.read(32).strip()
        except (OSError, UnicodeDecodeError):
            return None
        return int(text) if text.isdigit() else None

    def __exit__(self, *exc) -> None:
        if self.held:
            try:
                os.unlink(self.lock)
            except FileNotFoundError:
                pass
            self.held = False


def load_result(path, arg: str = "RESULT.npz") -> dict:
    """Read a result file into a dict of arrays (``meta`` decoded from JSON), every key checked.

    The file is read without trusting it (:func:`rollqp.npzfile.read_npz`); each key that
    :mod:`rollqp.fields` documents must have its shape (``(K+1, n)``, ``(K+1,)``, ``(n,)`` or
    ``()``) and hold real numbers; every key of the outer contract (``Field.contract``) must be
    there; other keys are kept as they are.

    Raises
    ------
    InputError
        ``arg``: a missing or corrupt file, a file that is not a result file, a bad key.
    """
    from .npzfile import read_npz, real_array, text_value
    z = read_npz(path, arg)
    for key in ("x", "q", "meta"):
        if key not in z:
            raise InputError(arg, f"{os.fspath(path)!r} is not a rollqp result file (no key {key!r})")
    if "y" in z:  # a grid of elements: a 3D scene's result file (docs/results.md, "Three dimensions")
        from .three.fields import read_checked
        return read_checked(z, arg)
    n, K1 = np.shape(z["x"])[0] if np.ndim(z["x"]) == 1 else -1, np.shape(z["q"])[0] if np.ndim(z["q"]) == 1 else -1
    if n < 1 or K1 < 1:
        raise InputError(arg, f"keys 'x' and 'q' must be non-empty 1-D arrays, got shapes {np.shape(z['x'])}, "
                              f"{np.shape(z['q'])}")
    missing = [key for key, f in FIELDS.items() if f.contract and key not in z]
    if missing:  # the contract's keys are in every result file rollqp writes
        raise InputError(arg, f"{os.fspath(path)!r} is not a complete rollqp result file (no key {missing[0]!r}"
                              + (f" and {len(missing) - 1} more)" if len(missing) > 1 else ")"))
    shapes = {"state": (K1, n), "step": (K1,), "node": (n,), "scalar": ()}
    out = {}
    for key, value in z.items():
        f = FIELDS.get(key)
        if f is None or key == "meta":
            out[key] = value
            continue
        finite = key not in ("approach", "creepage", "residual")  # NaN where undetermined
        real_array(z, key, shapes[f.shape], arg, finite=finite)  # checks kind, shape, finiteness
        out[key] = value
    try:
        out["meta"] = json.loads(text_value(z, "meta", arg))
    except (json.JSONDecodeError, RecursionError) as exc:
        raise InputError(arg, f"key 'meta' must be a JSON string ({type(exc).__name__})") from exc
    if not isinstance(out["meta"], dict):
        raise InputError(arg, "key 'meta' must be a JSON object")
    return out


def _json_default(o):
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)
