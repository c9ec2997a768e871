"""Load histories: functions of the rolled distance q (in units of a_H).

A scene prescribes its loads as histories (docs/scenes.md, "Histories"): the normal load as a
multiplier of the reference load P̄, the tangential load as the ratio Q/(μP̄), or the creepage
ξ directly. Each history is a small frozen dataclass that

* evaluates vectorized, ``h(q)`` with ``q`` a float or an ndarray (q ≥ 0 in units of a_H);
* gives back the TOML inline table it was read from, ``h.to_dict()`` (with ``kind``);
* knows its exact extremes over ``[0, q_end]``, ``h.extremes(q_end)``, and the points where
  they can occur, ``h.critical_points(q_end)`` (ends, breakpoints, peaks), which the scene
  validation uses to check that the normal load stays positive and the tangential load stays
  below the friction limit.

The TOML forms are::

    { kind = "constant", value = v }
    { kind = "ramp", start = v0, end = v1, over = q1 }      # linear on [0, q1], then held
    { kind = "harmonic", mean = m, amplitude = A, wavelength = lam, phase = phi }
    { kind = "table", q = [...], value = [...] }           # piecewise linear, held outside

:func:`parse_history` turns such a table into a history; every invalid value is an
:class:`~rollqp.errors.InputError` naming the full key (``load.normal_history.wavelength``).
Strings are never evaluated.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any, ClassVar

import numpy as np

from .errors import InputError
from .validate import finite_real, is_real, positive_real, real_sequence, suggestion

__all__ = ["History", "Constant", "Ramp", "Harmonic", "Table", "HISTORY_KINDS",
           "parse_history"]

#: Harmonic histories with more peaks than this in ``[0, q_end]`` report only the first ones
#: from :meth:`Harmonic.critical_points` (their :meth:`~Harmonic.extremes` stay exact).
MAX_HARMONIC_PEAKS = 100_000


# --------------------------------------------------------------------------- value checks
# (the project's one set of validators: rollqp.validate)
def _q_end(q_end: Any) -> float:
    x = finite_real("q_end", q_end, "a finite number >= 0")
    if x < 0:
        raise InputError("q_end", f"must be a finite number >= 0, got {q_end!r}")
    return x


def _out(q: Any, values: np.ndarray):
    """Return a float for scalar input and an ndarray otherwise."""
    return float(values) if np.ndim(q) == 0 else values


# --------------------------------------------------------------------------- base class
class History:
    """Base class of the load histories (q in units of a_H).

    Subclasses are frozen dataclasses; their fields are the keys of the TOML inline table
    (besides ``kind``). Construction validates and normalizes the fields (numbers become
    floats, arrays tuples of floats) and raises :class:`~rollqp.errors.InputError` naming
    ``ClassName.field``; :func:`parse_history` names the full scene key instead.
    """

    kind: ClassVar[str] = ""
    #: fields that must be given in the TOML table (the others have defaults)
    required: ClassVar[tuple[str, ...]] = ()

    def __call__(self, q):  # pragma: no cover - abstract
        """Value at the rolled distance ``q`` (float or ndarray, units of a_H)."""
        raise NotImplementedError

    def critical_points(self, q_end: float) -> np.ndarray:  # pragma: no cover - abstract
        """Sorted points of ``[0, q_end]`` where the extremes over any subinterval can occur.

        Always contains 0 and ``q_end``; adds the breakpoints (ramp end, table nodes) and the
        peaks and troughs of a harmonic inside the interval.
        """
        raise NotImplementedError

    def extremes(self, q_end: float) -> tuple[float, float]:
        """Exact ``(min, max)`` of the history over ``[0, q_end]``.

        Parameters
        ----------
        q_end : float
            End of the interval, ``>= 0``, units of a_H.

        Returns
        -------
        (float, float)
            The smallest and largest value taken on ``[0, q_end]``.
        """
        v = np.asarray(self(self.critical_points(q_end)), dtype=float)
        return float(v.min()), float(v.max())

    def to_dict(self) -> dict:
        """The TOML inline table of this history: ``{"kind": ..., field: value, ...}``."""
        d: dict[str, Any] = {"kind": self.kind}
        for f in fields(self):  # type: ignore[arg-type]
            v = getattr(self, f.name)
            d[f.name] = list(v) if isinstance(v, tuple) else v
        return d

    #: each field's validator (rollqp.validate), named ``key.field`` in its errors
    checks: ClassVar[dict] = {}

    # normalization shared by __post_init__ and parse_history
    @classmethod
    def _normalize(cls, key: str, values: dict) -> dict:
        """Every field through its validator (:attr:`checks`); an absent optional one at its default."""
        defaults = {f.name: f.default for f in fields(cls)}
        return {name: check(f"{key}.{name}", values.get(name, defaults.get(name)))
                for name, check in cls.checks.items()}

    def __post_init__(self):
        values = {f.name: getattr(self, f.name) for f in fields(self)}  # type: ignore[arg-type]
        for name, v in type(self)._normalize(type(self).__name__, values).items():
            object.__setattr__(self, name, v)


# --------------------------------------------------------------------------- kinds
@dataclass(frozen=True)
class Constant(History):
    """A constant history, ``h(q) = value``.

    Parameters
    ----------
    value : float
        The value, finite.
    """

    value: float = 1.0

    kind: ClassVar[str] = "constant"
    required: ClassVar[tuple[str, ...]] = ("value",)
    checks: ClassVar[dict] = {"value": finite_real}

    def __call__(self, q):
        return _out(q, np.full(np.shape(q), self.value, dtype=float))

    def critical_points(self, q_end):
        return np.array([0.0, _q_end(q_end)])

    def extremes(self, q_end):
        _q_end(q_end)
        return self.value, self.value


@dataclass(frozen=True)
class Ramp(History):
    """A linear ramp from ``start`` at q = 0 to ``end`` at q = ``over``, held after.

    .. math:: h(q) = v_0 + (v_1 - v_0)\\,\\min(\\max(q/q_1, 0), 1)

    Parameters
    ----------
    start, end : float
        Values at q = 0 and from q = ``over`` on, finite.
    over : float
        Length of the ramp in units of a_H, ``> 0``.
    """

    start: float
    end: float
    over: float

    kind: ClassVar[str] = "ramp"
    required: ClassVar[tuple[str, ...]] = ("start", "end", "over")
    checks: ClassVar[dict] = {"start": finite_real, "end": finite_real, "over": positive_real}

    def __call__(self, q):
        s = np.clip(np.asarray(q, dtype=float) / self.over, 0.0, 1.0)
        return _out(q, self.start + (self.end - self.start) * s)

    def critical_points(self, q_end):
        q_end = _q_end(q_end)
        pts = [0.0, q_end] + ([self.over] if self.over < q_end else [])
        return np.array(sorted(pts))

    def extremes(self, q_end):
        v0, v1 = self.start, float(self(_q_end(q_end)))
        return min(v0, v1), max(v0, v1)


@dataclass(frozen=True)
class Harmonic(History):
    """A harmonic history, ``h(q) = mean + amplitude·sin(2π q / wavelength + phase)``.

    Parameters
    ----------
    mean, amplitude : float
        Finite; the amplitude may be negative (a phase shift of π).
    wavelength : float
        Period in q, units of a_H, ``> 0``.
    phase : float, optional
        Phase in radians at q = 0 (default 0).
    """

    mean: float
    amplitude: float
    wavelength: float
    phase: float = 0.0

    kind: ClassVar[str] = "harmonic"
    required: ClassVar[tuple[str, ...]] = ("mean", "amplitude", "wavelength")
    checks: ClassVar[dict] = {"mean": finite_real, "amplitude": finite_real, "wavelength": positive_real,
                              "phase": finite_real}

    def __call__(self, q):
        theta = 2.0 * np.pi * np.asarray(q, dtype=float) / self.wavelength + self.phase
        return _out(q, self.mean + self.amplitude * np.sin(theta))

    def _peak_range(self, q_end: float, offset: float, period: float) -> tuple[int, int]:
        """Integers k with θ = offset + k·period inside [θ(0), θ(q_end)]."""
        t0 = self.phase
        t1 = self.phase + 2.0 * math.pi * q_end / self.wavelength
        return math.ceil((t0 - offset) / period), math.floor((t1 - offset) / period)

    def critical_points(self, q_end):
        q_end = _q_end(q_end)
        k0, k1 = self._peak_range(q_end, math.pi / 2, math.pi)
        k1 = min(k1, k0 + MAX_HARMONIC_PEAKS - 1)
        k = np.arange(k0, k1 + 1, dtype=float)
        qk = (math.pi / 2 + math.pi * k - self.phase) * self.wavelength / (2.0 * math.pi)
        qk = qk[(qk > 0.0) & (qk < q_end)]
        return np.concatenate(([0.0], qk, [q_end]))

    def extremes(self, q_end):
        q_end = _q_end(q_end)
        ends = [float(self(0.0)), float(self(q_end))]
        lo, hi = min(ends), max(ends)
        if self.amplitude != 0.0:
            # sin = +1 at θ = π/2 + 2πk, sin = −1 at θ = −π/2 + 2πk
            up0, up1 = self._peak_range(q_end, math.pi / 2, 2.0 * math.pi)
            dn0, dn1 = self._peak_range(q_end, -math.pi / 2, 2.0 * math.pi)
            top, bottom = self.mean + self.amplitude, self.mean - self.amplitude
            if up0 <= up1:
                lo, hi = min(lo, top), max(hi, top)
            if dn0 <= dn1:
                lo, hi = min(lo, bottom), max(hi, bottom)
        return lo, hi


@dataclass(frozen=True)
class Table(History):
    """A piecewise linear history through the points ``(q[i], value[i])``, held outside.

    Parameters
    ----------
    q : sequence of float
        Breakpoints in units of a_H, finite and strictly increasing, at least one.
    value : sequence of float
        Values at the breakpoints, finite, as many as ``q``.
    """

    q: tuple[float, ...]
    value: tuple[float, ...]

    kind: ClassVar[str] = "table"
    required: ClassVar[tuple[str, ...]] = ("q", "value")

    @classmethod
    def _normalize(cls, key, values):
        q = real_sequence(f"{key}.q", values["q"])
        v = real_sequence(f"{key}.value", values["value"])
        if len(q) < 1:
            raise InputError(f"{key}.q", "must have at least one point, got []")
        if len(v) != len(q):
            raise InputError(f"{key}.value",
                             f"must have as many entries as {key}.q ({len(q)}), got {len(v)}")
        for i in range(1, len(q)):
            if not q[i] > q[i - 1]:
                raise InputError(f"{key}.q", f"must be strictly increasing, but q[{i}] = {q[i]!r}"
                                             f" follows q[{i - 1}] = {q[i - 1]!r}")
        return {"q": q, "value": v}

    def __call__(self, q):
        return _out(q, np.interp(np.asarray(q, dtype=float), self.q, self.value))

    def critical_points(self, q_end):
        q_end = _q_end(q_end)
        inner = [x for x in self.q if 0.0 < x < q_end]
        return np.array([0.0, *inner, q_end])


HISTORY_KINDS: dict[str, type[History]] = {
    c.kind: c for c in (Constant, Ramp, Harmonic, Table)}


# --------------------------------------------------------------------------- parsing
def parse_history(obj: Any, key: str, *, constant_default: float | None = None) -> History:
    """Build a history from its TOML inline table.

    Parameters
    ----------
    obj : dict or History or float
        The inline table (``{"kind": "ramp", "start": 0.0, ...}``). A :class:`History` is
        returned as is; a plain number is shorthand for ``{kind = "constant", value = x}``.
    key : str
        The full scene key of the table, used in error messages (``"load.tangential"``).
    constant_default : float, optional
        Value of a ``constant`` history that omits ``value`` (the scene passes 1 for
        ``load.normal_history``); if None, ``value`` is required.

    Returns
    -------
    History

    Raises
    ------
    InputError
        Unknown ``kind`` or keys (with the closest valid name), missing keys, values of the
        wrong type or out of range; the key named is the full one, e.g.
        ``load.normal_history.wavelength``.
    """
    if isinstance(obj, History):
        return obj
    if is_real(obj):
        return Constant(finite_real(key, obj))
    if not isinstance(obj, dict):
        raise InputError(key, "must be an inline table such as { kind = \"constant\", "
                              f"value = 0.5 }} (kinds: {', '.join(HISTORY_KINDS)}), got {obj!r}")
    if "kind" not in obj:
        raise InputError(f"{key}.kind", f"missing; one of {', '.join(map(repr, HISTORY_KINDS))}")
    kind = obj["kind"]
    if not isinstance(kind, str) or kind not in HISTORY_KINDS:
        raise InputError(f"{key}.kind", f"must be one of {', '.join(map(repr, HISTORY_KINDS))},"
                                        f" got {kind!r}" + (suggestion(kind, HISTORY_KINDS)
                                                            if isinstance(kind, str) else ""))
    cls = HISTORY_KINDS[kind]
    names = [f.name for f in fields(cls)]  # type: ignore[arg-type]
    for k in obj:
        if k != "kind" and k not in names:
            raise InputError(f"{key}.{k}", f"unknown key for a {kind} history"
                                           f"{suggestion(k, names)} (allowed: kind, "
                                           f"{', '.join(names)})")
    values = {k: v for k, v in obj.items() if k != "kind"}
    if cls is Constant and "value" not in values and constant_default is not None:
        values["value"] = constant_default
    for k in cls.required:
        if k not in values:
            raise InputError(f"{key}.{k}", f"missing: a {kind} history needs "
                                           f"{', '.join(cls.required)}")
    return cls(**cls._normalize(key, values))
