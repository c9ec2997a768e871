"""A sweep's points: the ``--vary KEY=VALUES`` grammar, the product of the values, every point validated.

A sweep is a base scene and one or more swept keys, each with its values; the points are the
Cartesian product of the values (the first key varies slowest), each point a validated
:class:`~rollqp.scene.Scene` (``scene.replace(**{key: value, ...})``). ``VALUES`` is one of

* a list ``a,b,c`` — numbers (``40``, ``0.1``, ``1e-3``) or words (``newton,qp-osqp``);
* a linear range ``start:stop:count`` — ``count`` evenly spaced values, both ends included;
* a logarithmic range ``start:stop:count:log`` — ``count`` values evenly spaced in log10,
  both ends included (``start``, ``stop`` > 0).

Any dotted scene key can be swept, ``solver.method`` and the ``discretization`` keys included;
a history key takes a number as a constant history (``load.tangential=0.1,0.5``) and its
entries are keys too (``load.tangential.value=…``). Every point is built and validated before
anything runs (:func:`build_sweep`): one bad point is an :class:`~rollqp.errors.InputError`
naming ``--vary``, the point and the scene key (docs/sweeps.md). The points are validated in
an order that meets every value of every key within the first ``max(len(values))`` points, so
a bad value stops the sweep at once however many points there are; the scenes themselves are
not kept (a sweep of 10^5 points would hold 10^5 scenes), only what the store needs of them
(:class:`Facts`), and :attr:`Sweep.scenes` builds a point's scene again when asked.
"""
from __future__ import annotations

import hashlib
import itertools
import json
import math
import re
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, RollqpError
from ..fields import fields_for
from ..methods import method_class
from ..scene import Scene, load_scene
from ..strip import Strip

__all__ = ["Axis", "Sweep", "Facts", "parse_vary", "parse_values", "build_sweep", "describe", "MAX_POINTS",
           "MAX_VALUES", "MAX_VALUE_CHARS"]

#: Most values of one swept key, and most points of a sweep (a bound on the work asked for
#: before anything runs; a sweep of 10^5 points of the §6.1.1 scene is ~3 CPU-hours).
MAX_VALUES, MAX_POINTS = 10_000, 100_000
#: Most characters of one value (a number or a word): a longer number is no parameter value
#: (and Python refuses to convert integers of more than 4,300 digits).
MAX_VALUE_CHARS = 100
_KEY = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)+$")
_INT = re.compile(r"^[+-]?\d+$")


def _clip(text, n: int = 60) -> str:
    """``text`` for an error message: at most ``n`` characters, the length said when cut."""
    try:
        text = str(text)
    except ValueError:  # an int of more than 4,300 digits has no str()
        return f"<an integer of {text.bit_length()} bits>"
    return text if len(text) <= n else f"{text[:n]}… ({len(text)} characters)"


def describe(value, n: int = 60) -> str:
    """``repr(value)`` for an error message, at most ``n`` characters (the length said when cut);
    never fails (an integer of more than 4,300 digits has no ``repr``)."""
    try:
        return _clip(repr(value), n)
    except ValueError:
        return _clip(value, n)


@dataclass(frozen=True)
class Axis:
    """One swept key and its values (numbers or strings, in the order given)."""

    key: str
    values: tuple

    @property
    def numeric(self) -> bool:
        return all(not isinstance(v, str) for v in self.values)


@dataclass(frozen=True)
class Facts:
    """What the store needs of the points, gathered while they are validated.

    ``states``/``nodes``: each point's number of states (K + 1) and nodes; ``q``/``x``: the
    distinct grids (rolled distances, node positions) and, per point, the index of its own;
    ``fields``: the computed fields (:func:`rollqp.fields.fields_for`) any point holds.
    """

    states: np.ndarray
    nodes: np.ndarray
    q: tuple
    q_index: np.ndarray
    x: tuple
    x_index: np.ndarray
    fields: frozenset


@dataclass(frozen=True)
class Sweep:
    """A base scene, its axes, and :class:`Facts` of its validated points (product order)."""

    base: object
    axes: tuple
    facts: Facts = field(default=None, compare=False, repr=False)

    @property
    def shape(self) -> tuple:
        return tuple(len(a.values) for a in self.axes)

    @property
    def size(self) -> int:
        """The number of points."""
        return math.prod(self.shape)

    @property
    def keys(self) -> tuple:
        return tuple(a.key for a in self.axes)

    @property
    def scenes(self) -> "_Scenes":
        """The points' scenes as a sequence, each built (and validated) when indexed."""
        return _Scenes(self)

    def index(self, i: int) -> tuple:
        """The multi-index of point ``i`` (row-major over the axes)."""
        return tuple(int(j) for j in np.unravel_index(i, self.shape))

    def changes(self, i: int) -> dict:
        """``{key: value}`` of point ``i``: its scene is ``base.replace(**changes(i))``."""
        return {a.key: a.values[j] for a, j in zip(self.axes, self.index(i))}

    def label(self, i: int) -> str:
        """``key=value, …`` of point ``i``."""
        return ", ".join(f"{k}={v}" for k, v in self.changes(i).items())

    def fingerprint(self) -> str:
        """SHA-256 of the base scene and the axes: the identity of the sweep's store."""
        text = json.dumps({"scene": self.base.to_dict(), "vary": [[a.key, list(a.values)] for a in self.axes]},
                          sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()


class _Scenes:
    """The scenes of a sweep's points, built on demand (``len``, indexing, iteration)."""

    def __init__(self, sweep: Sweep):
        self.sweep = sweep

    def __len__(self) -> int:
        return self.sweep.size

    def __getitem__(self, i: int):
        n = self.sweep.size
        if not -n <= i < n:
            raise IndexError(f"point {i} of a sweep of {n} points")
        return self.sweep.base.replace(**self.sweep.changes(i % n))

    def __iter__(self):
        return (self[i] for i in range(len(self)))


def _word(text: str, where: str, arg: str):
    """A number (int or float) or a word from one list entry."""
    t = text.strip()
    if not t:
        raise InputError(arg, f"{where}: empty value")
    if len(t) > MAX_VALUE_CHARS:
        raise InputError(arg, f"{where}: a value of {len(t)} characters; at most {MAX_VALUE_CHARS}")
    if _INT.match(t):
        return int(t)
    try:
        v = float(t)
    except ValueError:
        if not re.match(r"^[A-Za-z0-9_.+-]+$", t):
            raise InputError(arg, f"{where}: {t!r} is neither a number nor a word "
                                  "(letters, digits, '_', '.', '+', '-')") from None
        return t
    if not math.isfinite(v):
        raise InputError(arg, f"{where}: {t!r} is not a finite number")
    return v


def _range(parts: list, where: str, arg: str) -> tuple:
    """``start:stop:count[:log]`` as a tuple of floats, both ends included."""
    log = len(parts) == 4
    if log and parts[3].strip() != "log" or len(parts) not in (3, 4):
        raise InputError(arg, f"{where}: a range is start:stop:count or start:stop:count:log")
    if any(len(p.strip()) > MAX_VALUE_CHARS for p in parts):
        raise InputError(arg, f"{where}: a part of the range has more than {MAX_VALUE_CHARS} characters")
    try:
        start, stop = float(parts[0]), float(parts[1])
    except ValueError:
        raise InputError(arg, f"{where}: start and stop of a range must be numbers") from None
    if not _INT.match(parts[2].strip()) or not 1 <= int(parts[2]) <= MAX_VALUES:
        raise InputError(arg, f"{where}: count must be an integer in [1, {MAX_VALUES}], got {parts[2].strip()!r}")
    n = int(parts[2])
    if not (math.isfinite(start) and math.isfinite(stop)):
        raise InputError(arg, f"{where}: start and stop must be finite")
    if n > 1 and start == stop:
        raise InputError(arg, f"{where}: an empty range (start = stop with count {n})")
    if log:
        if start <= 0 or stop <= 0:
            raise InputError(arg, f"{where}: a log range needs start, stop > 0")
        values = np.logspace(math.log10(start), math.log10(stop), n)
        values[0], values[-1] = start, stop  # the ends exactly as written
    else:
        values = np.linspace(start, stop, n)
    return tuple(float(v) for v in values)


def parse_values(text: str, key: str, arg: str = "--vary") -> tuple:
    """The values of ``VALUES`` (module docstring), checked: non-empty, finite, no repeats.

    ``key`` names the values in messages (``KEY=VALUES``; ``None``: the values alone); ``arg``
    is the argument the errors name (``--vary``, or ``--ratios``/``--friction`` of the creep curve).
    """
    text = str(text)
    where = _clip(text if key is None else f"{key}={text}")
    if not text.strip():
        raise InputError(arg, f"{where}: no values (give a list a,b,c or a range start:stop:count)")
    if ":" in text:
        values = _range(text.split(":"), where, arg)
    else:
        entries = text.split(",")
        if len(entries) > MAX_VALUES:
            raise InputError(arg, f"{where}: at most {MAX_VALUES} values, got {len(entries)}")
        values = tuple(_word(t, where, arg) for t in entries)
    if len(set(values)) != len(values):
        raise InputError(arg, f"{where}: repeated values")
    kinds = {isinstance(v, str) for v in values}
    if len(kinds) > 1:
        raise InputError(arg, f"{where}: mixes numbers and words")
    return values


def parse_vary(items) -> tuple:
    """:class:`Axis` objects of the ``--vary KEY=VALUES`` arguments (each key once)."""
    if not items:
        raise InputError("--vary", "give at least one KEY=VALUES (e.g. --vary contact.friction=0.1,0.2)")
    axes, seen = [], set()
    for item in items:
        key, sep, text = str(item).partition("=")
        key = key.strip()
        if not sep or not _KEY.match(key) or len(key) > 200:
            raise InputError("--vary", f"{_clip(repr(item))} is not KEY=VALUES with a dotted scene key "
                                       "(e.g. contact.friction=0.1,0.2)")
        if key in seen:
            raise InputError("--vary", f"{key} is given twice")
        seen.add(key)
        axes.append(Axis(key, parse_values(text, key)))
    n = math.prod(len(a.values) for a in axes)
    if n > MAX_POINTS:
        raise InputError("--vary", f"{n} points; at most {MAX_POINTS}")
    return tuple(axes)


def _order(shape: tuple):
    """Every flat point index once: first the ``max(shape)`` points ``(k mod n_1, k mod n_2, …)``,
    which meet every value of every axis, then the others in product order."""
    first = []
    for k in range(max(shape, default=1)):
        first.append(int(np.ravel_multi_index(tuple(k % n for n in shape), shape)) if shape else 0)
    seen = set(first)
    yield from dict.fromkeys(first)
    yield from (i for i in range(math.prod(shape)) if i not in seen)


class _Gather:
    """Collects :class:`Facts` point by point (grids stored once per distinct grid)."""

    def __init__(self, n: int):
        self.strip = Strip
        self.states, self.nodes = np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64)
        self.q_index, self.x_index = np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64)
        self.q, self.x, self.strips, self.fields, self.methods = {}, {}, {}, set(), set()

    def add(self, i: int, scene) -> None:
        d = scene.discretization
        mesh = (scene.half_width, d.elements, d.element)
        if mesh not in self.strips:
            self.strips[mesh] = self.strip(*mesh).x
        for rows, index, grid in ((self.q, self.q_index, scene.q_steps), (self.x, self.x_index, self.strips[mesh])):
            index[i] = rows.setdefault(np.asarray(grid).tobytes(), (len(rows), grid))[0]
        self.states[i], self.nodes[i] = scene.n_steps + 1, scene.n_nodes
        self.fields.update(f.name for f in fields_for(scene))
        if scene.solver.method not in self.methods:
            method_class(scene.solver.method)  # installed? (an optional backend may be missing)
            self.methods.add(scene.solver.method)

    def facts(self) -> Facts:
        rows = lambda d: tuple(g for _, g in sorted(d.values(), key=lambda t: t[0]))  # noqa: E731
        return Facts(self.states, self.nodes, rows(self.q), self.q_index, rows(self.x), self.x_index,
                     frozenset(self.fields))


def build_sweep(base, axes, progress=None) -> Sweep:
    """Every point validated, before any work; one bad point is an InputError naming it.

    ``base`` is a :class:`~rollqp.scene.Scene` (or anything :func:`rollqp.load_scene` reads);
    ``axes`` are :class:`Axis` objects or ``--vary`` strings. ``progress(n, total)``, if given,
    is called after each validated point (the command's progress lines for large sweeps).
    """
    base = base if isinstance(base, Scene) else load_scene(base)
    if axes and isinstance(next(iter(axes)), str):
        axes = parse_vary(axes)
    axes = tuple(axes)
    sweep = Sweep(base, axes)
    gather = _Gather(sweep.size)
    for n, i in enumerate(_order(sweep.shape), 1):
        changes = sweep.changes(i)
        try:
            scene = base.replace(**changes)
            gather.add(i, scene)
        except RollqpError as err:
            label = _clip(", ".join(f"{k}={v}" for k, v in changes.items()), 200)
            raise InputError("--vary", f"point {i} ({label}): {err}") from None
        if progress is not None:
            progress(n, sweep.size)
    return Sweep(base, axes, gather.facts())
