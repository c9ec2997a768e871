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
entries are keys too (``load.tangential.value=…``). Every point is built before anything runs:
one bad point is an :class:`~rollqp.errors.InputError` naming ``--vary``, the point and the
scene key (docs/sweeps.md).
"""
from __future__ import annotations

import hashlib
import itertools
import json
import math
import re
from dataclasses import dataclass

import numpy as np

from ..errors import InputError

__all__ = ["Axis", "Sweep", "parse_vary", "parse_values", "build_sweep", "MAX_POINTS", "MAX_VALUES"]

#: Most values of one swept key, and most points of a sweep (a bound on the work asked for
#: before anything runs; a sweep of 10^5 points of the §6.1.1 scene is ~3 CPU-hours).
MAX_VALUES, MAX_POINTS = 10_000, 100_000
_KEY = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)+$")
_INT = re.compile(r"^[+-]?\d+$")


@dataclass(frozen=True)
class Axis:
    """One swept key and its values (numbers or strings, in the order given)."""

    key: str
    values: tuple

    @property
    def numeric(self) -> bool:
        return all(not isinstance(v, str) for v in self.values)


@dataclass(frozen=True)
class Sweep:
    """A base scene, its axes, and the validated scene of every point (product order)."""

    base: object
    axes: tuple
    scenes: tuple

    @property
    def shape(self) -> tuple:
        return tuple(len(a.values) for a in self.axes)

    @property
    def keys(self) -> tuple:
        return tuple(a.key for a in self.axes)

    def index(self, i: int) -> tuple:
        """The multi-index of point ``i`` (row-major over the axes)."""
        return tuple(int(j) for j in np.unravel_index(i, self.shape))

    def label(self, i: int) -> str:
        """``key=value, …`` of point ``i``."""
        return ", ".join(f"{a.key}={a.values[j]}" for a, j in zip(self.axes, self.index(i)))

    def fingerprint(self) -> str:
        """SHA-256 of the base scene and the axes: the identity of the sweep's store."""
        text = json.dumps({"scene": self.base.to_dict(), "vary": [[a.key, list(a.values)] for a in self.axes]},
                          sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()


def _word(text: str, where: str):
    """A number (int or float) or a word from one list entry."""
    t = text.strip()
    if not t:
        raise InputError("--vary", f"{where}: empty value")
    if _INT.match(t):
        return int(t)
    try:
        v = float(t)
    except ValueError:
        if not re.match(r"^[A-Za-z0-9_.+-]+$", t):
            raise InputError("--vary", f"{where}: {t!r} is neither a number nor a word "
                                       "(letters, digits, '_', '.', '+', '-')") from None
        return t
    if not math.isfinite(v):
        raise InputError("--vary", f"{where}: {t!r} is not a finite number")
    return v


def _range(parts: list, where: str) -> tuple:
    """``start:stop:count[:log]`` as a tuple of floats, both ends included."""
    log = len(parts) == 4
    if log and parts[3].strip() != "log" or len(parts) not in (3, 4):
        raise InputError("--vary", f"{where}: a range is start:stop:count or start:stop:count:log")
    try:
        start, stop = float(parts[0]), float(parts[1])
    except ValueError:
        raise InputError("--vary", f"{where}: start and stop of a range must be numbers") from None
    if not _INT.match(parts[2].strip()) or not 1 <= int(parts[2]) <= MAX_VALUES:
        raise InputError("--vary", f"{where}: count must be an integer in [1, {MAX_VALUES}], got {parts[2]!r}")
    n = int(parts[2])
    if not (math.isfinite(start) and math.isfinite(stop)):
        raise InputError("--vary", f"{where}: start and stop must be finite")
    if n > 1 and start == stop:
        raise InputError("--vary", f"{where}: an empty range (start = stop with count {n})")
    if log:
        if start <= 0 or stop <= 0:
            raise InputError("--vary", f"{where}: a log range needs start, stop > 0")
        values = np.logspace(math.log10(start), math.log10(stop), n)
        values[0], values[-1] = start, stop  # the ends exactly as written
    else:
        values = np.linspace(start, stop, n)
    return tuple(float(v) for v in values)


def parse_values(text: str, key: str) -> tuple:
    """The values of ``VALUES`` (module docstring), checked: non-empty, finite, no repeats."""
    where = f"{key}={text}"
    if not text.strip():
        raise InputError("--vary", f"{where}: no values (give a list a,b,c or a range start:stop:count)")
    if ":" in text:
        values = _range(text.split(":"), where)
    else:
        values = tuple(_word(t, where) for t in text.split(","))
    if len(values) > MAX_VALUES:
        raise InputError("--vary", f"{where}: at most {MAX_VALUES} values, got {len(values)}")
    if len(set(values)) != len(values):
        raise InputError("--vary", f"{where}: repeated values")
    kinds = {isinstance(v, str) for v in values}
    if len(kinds) > 1:
        raise InputError("--vary", f"{where}: mixes numbers and words")
    return values


def parse_vary(items) -> tuple:
    """:class:`Axis` objects of the ``--vary KEY=VALUES`` arguments (each key once)."""
    if not items:
        raise InputError("--vary", "give at least one KEY=VALUES (e.g. --vary contact.friction=0.1,0.2)")
    axes, seen = [], set()
    for item in items:
        key, sep, text = str(item).partition("=")
        key = key.strip()
        if not sep or not _KEY.match(key):
            raise InputError("--vary", f"{item!r} is not KEY=VALUES with a dotted scene key (e.g. contact.friction=0.1,0.2)")
        if key in seen:
            raise InputError("--vary", f"{key} is given twice")
        seen.add(key)
        axes.append(Axis(key, parse_values(text, key)))
    n = math.prod(len(a.values) for a in axes)
    if n > MAX_POINTS:
        raise InputError("--vary", f"{n} points; at most {MAX_POINTS}")
    return tuple(axes)


def build_sweep(base, axes) -> Sweep:
    """Every point's validated scene, before any work; one bad point is an InputError naming it.

    ``base`` is a :class:`~rollqp.scene.Scene` (or anything :func:`rollqp.load_scene` reads);
    ``axes`` are :class:`Axis` objects or ``--vary`` strings.
    """
    from ..scene import Scene, load_scene
    base = base if isinstance(base, Scene) else load_scene(base)
    if axes and isinstance(next(iter(axes)), str):
        axes = parse_vary(axes)
    axes = tuple(axes)
    scenes = []
    for n, combo in enumerate(itertools.product(*(a.values for a in axes))):
        changes = {a.key: v for a, v in zip(axes, combo)}
        try:
            scenes.append(base.replace(**changes))
        except InputError as err:
            label = ", ".join(f"{k}={v}" for k, v in changes.items())
            raise InputError("--vary", f"point {n} ({label}): {err}") from None
    return Sweep(base, axes, tuple(scenes))
