"""The checks of a step problem's inputs: real, finite, of the right shape, within range (one-line errors).

Each step problem's ``__post_init__`` runs them on its fields, unless it is made with ``trusted=True``:
the march builds its steps from the scene's validated operators and the methods' checked solutions so,
and a checked step's halves and copies are made so (:func:`_copy`).
"""
from __future__ import annotations

import dataclasses
import functools

import numpy as np

from ..errors import InputError
from ..influence.operator import Operator, as_operator
from .scales import Scales


#: Largest magnitude of any number given to a step problem. rollqp forms products of up to four
#: of them (the QP objective pᵀ F A p, fᵀp, A·p): with every factor ≤ 1e60 these stay below
#: 1e240 · n, far from float64's 1.8e308, while any physical input in any units is far below
#: it (stresses ~1e11 Pa, compliances ~1e-12).
MAX_MAGNITUDE = 1e60


def _real(name, v) -> np.ndarray:
    """``v`` as a float array; an InputError naming ``name`` unless it holds real, finite numbers
    within ±:data:`MAX_MAGNITUDE` (booleans, complex numbers, strings, objects and ragged lists
    are refused, never cast)."""
    if type(v) is np.ndarray and v.dtype == np.float64:  # the common case: no copy, two numpy calls
        a = v
    else:
        try:
            a = np.asarray(v)
        except (ValueError, TypeError) as exc:
            raise InputError(name, f"must hold real numbers ({exc})") from None
        if a.dtype.kind not in "iuf":
            raise InputError(name, f"must hold real numbers, got {type(v).__name__} of dtype {a.dtype}")
        a = a.astype(float)
    if a.size:
        big = np.abs(a).max()  # (the method: np.max's dispatch costs more on step-sized vectors)
        if not big <= MAX_MAGNITUDE:  # NaN compares false: one test for both
            if not np.all(np.isfinite(a)):
                raise InputError(name, "must be finite")
            raise InputError(name, f"values must be within ±{MAX_MAGNITUDE:g} (beyond, the products of the step "
                                   f"problem overflow; rescale, e.g. with Scales), got {big:.3g}")
    return a


def _scalar(name, v):
    """``v`` as a float, or ``None``; an InputError naming ``name`` unless it is one real number."""
    if v is None:
        return None
    if isinstance(v, (float, int)) and not isinstance(v, bool):  # the common case, without numpy
        x = float(v)
        if abs(x) <= MAX_MAGNITUDE:
            return x
    a = _real(name, v)
    if a.ndim != 0:
        raise InputError(name, f"must be a real number, got an array of shape {a.shape}")
    return float(a)


def _set_scalars(step, names) -> None:
    for name in names:
        setattr(step, name, _scalar(name, getattr(step, name)))


def _vec(name, v, n):
    a = _real(name, v)  # real and finite
    if a.shape != (n,):
        raise InputError(name, f"must have shape ({n},), got {a.shape}")
    return a


def _set_weights(step) -> int:
    """Validate a step's weights ``f`` (1-D, finite, all > 0) and its scales, store them, return ``n``."""
    if not isinstance(step.scales, Scales):
        raise InputError("scales", f"must be a rollqp.Scales (e.g. Scales.hertz(P, R, Estar), or Scales() for the "
                                   f"problem's own units), got {type(step.scales).__name__}")
    f = step.f
    n = np.shape(f)[0] if (f.ndim if type(f) is np.ndarray else np.ndim(f)) == 1 else -1
    if n < 1:
        raise InputError("f", "must be a 1-D array of weights")
    f = _vec("f", f, n)
    if (f <= 0).any():
        raise InputError("f", "weights must all be > 0")
    step.f = f
    return n


def _check_arrays(step, operators=(), vectors=(), optional=()) -> int:
    """Validate a step's weights, its operators (``n × n``) and vectors (``n``; ``optional`` may be
    ``None``) in place; return ``n``."""
    n = _set_weights(step)
    for name in operators:
        value = getattr(step, name)
        if value is not None or name in ("A", "Ann", "Att"):
            if not isinstance(value, Operator):
                value = _real(name, value)
            setattr(step, name, as_operator(value, name, n))
    for name in vectors + optional:
        if getattr(step, name) is not None or name in vectors:
            setattr(step, name, _vec(name, getattr(step, name), n))
    return n


def _per_node(mu) -> bool:
    """``mu`` is given per node (a sequence or an array of dimension >= 1), not one number."""
    return isinstance(mu, (list, tuple, np.ndarray)) and not (isinstance(mu, np.ndarray) and mu.ndim == 0)


def _check_friction(step) -> None:
    """``μ`` finite and ``>= 0`` (a number, or one per node: :mod:`rollqp.friction`), ``Δq`` finite and ``> 0``."""
    if not _per_node(step.mu):
        if step.mu is None or not (np.isfinite(step.mu) and step.mu >= 0):
            raise InputError("mu", f"the coefficient of friction must be finite and >= 0, got {step.mu!r}")
    else:
        mu = _vec("mu", step.mu, step.f.size)
        if np.any(mu < 0):
            raise InputError("mu", f"the coefficients of friction must all be >= 0, got min {float(mu.min())!r}")
        step.mu = mu
    law = getattr(step, "law", None)
    if law is not None and not (callable(getattr(law, "mu", None)) and callable(getattr(law, "dmu", None))):
        raise InputError("law", f"must be a slip-dependent bound with mu(s) and dmu(s) (rollqp.friction.SlipBound), "
                                f"got {type(law).__name__}")
    if step.dq is None or not (np.isfinite(step.dq) and step.dq > 0):
        raise InputError("dq", f"the step must be a finite number > 0, got {step.dq!r}")


def _exactly_one(names, values):
    given = [n for n, v in zip(names, values) if v is not None]
    if len(given) != 1:
        raise InputError(" / ".join(names), f"give exactly one of {' or '.join(names)} (got {len(given)})")


def _check_sliding_limit(step, cap=None) -> float | None:
    """A tangential step with ``Q`` prescribed needs ``|Q| < μ fᵀp`` (a solution with stick), else an InputError.
    ``cap``: ``fᵀ(μ p⁺)`` if the caller has it. Returns the cap (None without ``Q``)."""
    if step.Q is not None:
        cap = float(step.f @ step.bound) if cap is None else cap
        if not abs(step.Q) < cap:
            raise InputError("Q", f"|Q| = {abs(step.Q):.6g} must be below the sliding limit "
                                  f"mu fᵀp = {cap:.6g} for a solution with stick")
    return cap


def _copy(step, **changes):
    """``step`` with ``changes``, made by its class with ``trusted=True``: the caller vouches that the values
    are valid (a checked step's own, and products of them with checked or solver-computed arrays), so the
    checks of ``__post_init__``, which would only repeat, are skipped."""
    values = {name: getattr(step, name) for name in _field_names(type(step))}
    values.update(changes)
    return type(step)(**values, trusted=True)


@functools.cache
def _field_names(cls) -> tuple:
    """The names of ``cls``'s fields (a step problem's data, the constructor's arguments but ``trusted``)."""
    return tuple(f.name for f in dataclasses.fields(cls))
