"""What the closed forms share: the checks of their arguments and the semi-ellipses they are made of.

The lenient validators of :mod:`rollqp.validate` (numpy scalars accepted), the checks of a load
ratio ``Q/(μP)`` (``|ratio| < 1``, partial slip), a rolling direction and coordinates, and the
semi-ellipses ``√(1 − u²)`` written without cancellation at their ends.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..validate import nonnegative, positive, scalar

#: The textbook the closed forms are quoted from.
_JOHNSON = "K. L. Johnson, Contact Mechanics, Cambridge University Press, 1985"

# the project's one set of validators (rollqp.validate), lenient: numpy scalars accepted
_scalar, _positive, _nonnegative = scalar, positive, nonnegative


def _ratio(value) -> float:
    v = _scalar("ratio", value)
    if not abs(v) < 1.0:
        raise InputError("ratio", f"Q/(mu P) must satisfy |ratio| < 1 (partial slip), got {value!r}")
    return v


def _ratio_array(value) -> np.ndarray:
    try:
        r = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError("ratio", f"must be real, got {value!r}") from None
    if not np.all(np.isfinite(r)) or not np.all(np.abs(r) < 1.0):
        raise InputError("ratio", "Q/(mu P) must be finite with |ratio| < 1 (partial slip)")
    return r


def _direction(value) -> int:
    if isinstance(value, bool):
        raise InputError("direction", f"must be -1 or +1, got {value!r}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError("direction", f"must be -1 or +1, got {value!r}") from None
    if v not in (-1.0, 1.0):
        raise InputError("direction", f"must be -1 or +1, got {value!r}")
    return int(v)


def _coords(x) -> np.ndarray:
    try:
        return np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise InputError("x", f"must be real, got {x!r}") from None


def _out(values: np.ndarray):
    return float(values) if values.ndim == 0 else values


def _semi_ellipse(x: np.ndarray, centre: float, half_width: float) -> np.ndarray:
    """√(1 − (x − centre)²/half_width²) inside the interval, 0 outside.

    Written as √((1 − u)(1 + u)), which is exactly 0 at u = ±1 and accurate near the ends.
    """
    if half_width <= 0.0:
        return np.zeros_like(x)
    u = (x - centre) / half_width
    return np.sqrt(np.clip((1.0 - u) * (1.0 + u), 0.0, None))


def _leading_semi_ellipse(x: np.ndarray, a: float, c: float, d: int) -> np.ndarray:
    """√(1 − (x − x_c)²/c²) on Carter's stick zone, x_c = −d(a − c), 0 outside.

    Evaluated through the distance from the leading edge, e = d·x + a, as
    √((e/c)(2 − e/c)): exactly 0 at the leading edge (no rounding of x_c ± c), and
    mirror-exact (x, d) ↔ (−x, −d).
    """
    if c <= 0.0:
        return np.zeros_like(x)
    v = (d * x + a) / c
    return np.sqrt(np.clip(v * (2.0 - v), 0.0, None))
