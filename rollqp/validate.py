"""One set of small input validators, apart from the algorithms (scipy's ``_milp_iv`` pattern).

Every function checks one value and returns it normalized (a float, an int, a tuple), or raises
:class:`~rollqp.errors.InputError` naming the key or argument and the allowed range. The scene,
the load histories, the closed forms and the influence builders all validate through here, so a
value is judged the same way wherever it enters. A leaf module: it imports nothing of rollqp but
the errors, so that any module can use it.

Two families:

* **strict** (:func:`number`, :func:`integer`, :func:`finite_real`, …) for values read from
  scene files and dicts: a real number is an ``int``/``float`` (not a bool, not a string);
* **lenient** (:func:`scalar`, :func:`positive`, :func:`nonnegative`) for the Python API of the
  closed forms: anything ``float()`` accepts (numpy scalars, 0-d arrays), except a bool.
"""
from __future__ import annotations

import difflib
import math
from numbers import Real
from typing import Any, Callable

import numpy as np

from .errors import InputError

__all__ = ["is_real", "number", "integer", "choice", "string", "suggestion", "finite_real", "positive_real",
           "real_sequence", "scalar", "positive", "nonnegative"]


# --------------------------------------------------------------------------- strict
def is_real(v: Any) -> bool:
    """``v`` is a real number: an int or float (numpy's included), not a bool."""
    return isinstance(v, Real) and not isinstance(v, bool)


def number(key: str, v: Any, allowed: str, ok: Callable[[float], bool]) -> float:
    """``float(v)`` if ``v`` is a finite real number with ``ok(v)``, else an InputError."""
    if not is_real(v) or not math.isfinite(float(v)) or not ok(float(v)):
        raise InputError(key, f"must be a number {allowed}, got {v!r}")
    return float(v)


def integer(key: str, v: Any, allowed: str, ok: Callable[[int], bool]) -> int:
    """``int(v)`` if ``v`` is an integer (not a bool, not a float) with ``ok(v)``."""
    if not isinstance(v, (int, np.integer)) or isinstance(v, bool) or not ok(int(v)):
        raise InputError(key, f"must be an integer {allowed}, got {v!r}")
    return int(v)


def suggestion(word: Any, choices) -> str:
    """``"; did you mean 'x'?"`` for the closest of ``choices`` (case-insensitive), or ``""``."""
    if not isinstance(word, str):
        return ""
    lower = {c.lower(): c for c in choices}
    m = difflib.get_close_matches(word.lower(), list(lower), n=1, cutoff=0.6)
    return f"; did you mean {lower[m[0]]!r}?" if m else ""


def choice(key: str, v: Any, choices: tuple) -> str:
    """``v`` if it is one of the strings ``choices``, else an InputError with the closest one."""
    if not isinstance(v, str) or v not in choices:
        raise InputError(key, f"must be one of {', '.join(map(repr, choices))}, got {v!r}" + suggestion(v, choices))
    return v


def string(key: str, v: Any) -> str:
    """``v`` if it is a string."""
    if not isinstance(v, str):
        raise InputError(key, f"must be a string, got {v!r}")
    return v


def finite_real(key: str, v: Any, what: str = "a finite number") -> float:
    """``float(v)`` if ``v`` is a finite real number."""
    if not is_real(v) or not math.isfinite(float(v)):
        raise InputError(key, f"must be {what}, got {v!r}")
    return float(v)


def positive_real(key: str, v: Any) -> float:
    """``float(v)`` if ``v`` is a finite real number ``> 0``."""
    x = finite_real(key, v, "a finite number > 0")
    if not x > 0:
        raise InputError(key, f"must be a finite number > 0, got {v!r}")
    return x


def real_sequence(key: str, v: Any, max_length: int = 1_000_000) -> tuple[float, ...]:
    """A tuple of finite real numbers from a sequence (entries named ``key[i]``)."""
    if isinstance(v, (str, bytes)) or not hasattr(v, "__iter__"):
        raise InputError(key, f"must be an array of finite numbers, got {v!r}")
    out = []
    for i, x in enumerate(v):
        if i >= max_length:
            raise InputError(key, f"must have at most {max_length} entries")
        out.append(finite_real(f"{key}[{i}]", x))
    return tuple(out)


# --------------------------------------------------------------------------- lenient
def scalar(key: str, value) -> float:
    """``float(value)`` for anything ``float()`` accepts but a bool; finite."""
    if isinstance(value, bool):
        raise InputError(key, f"must be a real number, got {value!r}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(key, f"must be a real scalar, got {value!r}") from None
    if not math.isfinite(v):
        raise InputError(key, f"must be finite, got {value!r}")
    return v


def positive(key: str, value) -> float:
    """:func:`scalar` ``> 0``."""
    v = scalar(key, value)
    if v <= 0.0:
        raise InputError(key, f"must be > 0, got {value!r}")
    return v


def nonnegative(key: str, value) -> float:
    """:func:`scalar` ``>= 0``."""
    v = scalar(key, value)
    if v < 0.0:
        raise InputError(key, f"must be >= 0, got {value!r}")
    return v
