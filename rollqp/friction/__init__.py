r"""Friction laws as objects: the registry, the scene key ``contact.friction`` and the per-step bound.

Friction enters a step only through its bound ``b = μ p⁺`` (paper eq. 57–60, 63). A law
(:mod:`.laws`) says what ``μ`` depends on; :func:`step_coefficient` turns it into what one step
problem takes for its coefficient ``mu``:

* a constant law: the ``float`` ``μ`` itself — the step problems and methods then take their
  constant-coefficient code path, with no law in it;
* a law varying along the surface: an ``(n,)`` array ``μ_i`` at the nodes, fixed during the
  step (the bound stays independent of the unknowns: each half is still a convex QP);
* a slip-velocity law: a :class:`~.bound.SlipBound` — ``μ_i(s_i)`` depends on the unknown slip,
  and the step becomes a quasi-variational inequality (docs/theory.md, "Slip-dependent
  friction"), solved by the Newton method with ``∂b/∂s`` in its pseudo-Jacobian or by a
  fixed point on the bound around any QP backend (:class:`rollqp.methods.fixedpoint.BoundFixedPoint`).

``contact.friction`` is a number (Coulomb) or a table with ``law = "<name>"`` and the law's keys:
:data:`LAWS` maps each name to its record. Every law follows one protocol, :class:`FrictionLaw`,
and its declared ``kind`` says which of the three paths above a step takes; the scene, the march,
the methods and the reports ask the law (its ``kind``, ``reference``, ``largest``), never its type.
Adding a law is one class with ``kind`` ``"constant"``, ``"spatial"`` or ``"slip"`` (and
``coefficient`` or ``steady``) and one call of :func:`register` — from any module, inside rollqp or
out (docs/architecture.md, "How to add …").

Examples
--------
>>> from rollqp.friction import parse_friction
>>> law = parse_friction(0.3)                      # a number is Coulomb's law
>>> law.kind, law.reference
('constant', 0.3)
>>> patch = parse_friction({"law": "patch", "mu": 0.3, "inside": 0.1, "start": -0.5, "end": 0.5})
>>> patch.kind, patch.largest
('spatial', 0.3)
"""
from __future__ import annotations

import dataclasses
from typing import Protocol, runtime_checkable

from ..errors import InputError
from ..validate import suggestion
from .laws import FRAMES, MAX_FRICTION, VELOCITY_FORMS, Coulomb, Patch, SlipVelocity, Table
from ..validate import number

__all__ = ["LAWS", "FrictionLaw", "register", "parse_friction", "as_law", "Coulomb", "Patch", "Table",
           "SlipVelocity", "MAX_FRICTION", "FRAMES", "VELOCITY_FORMS", "law_kind", "reference", "largest"]

#: The kinds of law: what a step problem takes from it (module docstring).
KINDS = ("constant", "spatial", "slip")


@runtime_checkable
class FrictionLaw(Protocol):
    """A friction law: what ``μ`` of the bound ``|t| <= μ p`` depends on (module docstring).

    Attributes
    ----------
    law : str
        Its name, the table's ``law`` key.
    kind : {"constant", "spatial", "slip"}
        ``"constant"``: ``mu``, one number (the step problems' fast path). ``"spatial"``: also
        ``coefficient(points, q_hat, direction) -> (n,) array`` (``μ`` at the ``points`` of the
        discretization, shape ``(d, n)``: ``x̂`` on a strip, ``(x̂, ŷ)`` on a grid, in the contact's length
        unit — ``a_H`` on a strip, the Hertz semi-axis ``a`` along x on a grid) and
        ``check_strip(half_width_hat, q_end_hat, direction)`` (the scene's check that it meets the
        strip). ``"slip"``: also ``steady(v) -> (μ, dμ/dv)`` of the slip velocity, ``rolling_speed``,
        ``memory`` and ``weight(dq_hat)`` (:class:`~.bound.SlipBound`), and for the selection of a step's
        solution on steep laws (:mod:`rollqp.methods.continuation`) ``steepest`` (the largest ``|dμ/dv|``),
        ``kinks`` (the velocities where ``μ(v)`` has a kink) and ``branch(v, k) -> (μ, dμ/dv)`` (the ``k``-th
        smooth piece's formula, continued beyond it).
    reference : float
        The ``μ`` of ``load.tangential = Q/(μ P̄)`` and of the reports.
    largest : float
        The largest ``μ`` it takes (0: frictionless everywhere).
    """

    law: str
    kind: str

    @property
    def reference(self) -> float: ...

    @property
    def largest(self) -> float: ...


#: ``law`` name → record (its fields are the table's keys).
LAWS = {"coulomb": Coulomb, "patch": Patch, "table": Table,
        **{form: SlipVelocity for form in VELOCITY_FORMS}}

KEY = "contact.friction"


def register(name: str, cls: type) -> None:
    """Make ``[contact.friction]`` with ``law = name`` the law ``cls`` (a frozen dataclass whose fields are
    the table's keys, following :class:`FrictionLaw`, with ``kind`` one of :data:`KINDS`).

    Raises
    ------
    InputError
        ``name`` is taken, or ``cls`` declares no valid ``kind``.
    """
    if not isinstance(name, str) or not name or name in LAWS:
        raise InputError("name", f"must be a new law name (registered: {', '.join(LAWS)}), got {name!r}")
    try:
        kind = cls.kind
    except AttributeError:
        kind = None
    if kind not in KINDS:
        raise InputError("cls", f"a friction law declares its kind, one of {', '.join(KINDS)}")
    LAWS[name] = cls


def _keys(cls) -> tuple[list, list]:
    """The table keys of law class ``cls`` and the required ones."""
    if cls is Coulomb:
        return list(Coulomb.keys), ["mu"]
    fields = dataclasses.fields(cls)
    return ([f.name for f in fields], [f.name for f in fields
                                        if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING])


def parse_friction(value) -> FrictionLaw:
    """The law of ``contact.friction``: a number is Coulomb's ``μ`` (a :class:`Coulomb`, itself the number),
    a table (dict) or a law record is checked key by key; anything else an InputError."""
    if isinstance(value, Coulomb):
        return value
    if isinstance(value, FrictionLaw) and dataclasses.is_dataclass(value):
        value = {f.name: getattr(value, f.name) for f in dataclasses.fields(value)}
    if not isinstance(value, dict):
        return Coulomb(number(KEY, value, f">= 0 (and <= {MAX_FRICTION:g}), or a table [contact.friction] with law = "
                                          f"{', '.join(map(repr, LAWS))}", lambda x: 0 <= x <= MAX_FRICTION))
    name = value.get("law")
    if not isinstance(name, str) or name not in LAWS:  # a list or table is no name (and not hashable)
        raise InputError(f"{KEY}.law", f"must be one of {', '.join(map(repr, LAWS))}, got {name!r}"
                                       + suggestion(name, LAWS))
    cls = LAWS[name]
    names, required = _keys(cls)
    for k in value:
        if k not in names:
            raise InputError(f"{KEY}.{k}", f"unknown key{suggestion(k, names)} for law {name!r} (allowed: "
                                           f"{', '.join(names)})")
    for k in required:
        if k not in value:
            raise InputError(f"{KEY}.{k}", f"missing required key of law {name!r} (it needs {', '.join(required)})")
    return cls(**value)


def as_law(friction) -> FrictionLaw:
    """``friction`` as a law: a law as it is, a number as Coulomb's (:func:`parse_friction`)."""
    return friction if isinstance(friction, FrictionLaw) else parse_friction(friction)


def law_kind(friction) -> str:
    """``"constant"`` (a number or :class:`Coulomb`), ``"spatial"`` or ``"slip"``."""
    return as_law(friction).kind


def reference(friction) -> float:
    """The reference ``μ`` of a law (a number is its own): ``load.tangential`` is ``Q/(μ_ref P̄)``."""
    return float(as_law(friction).reference)


def largest(friction) -> float:
    """The largest ``μ`` the law can take (0: frictionless everywhere)."""
    return float(as_law(friction).largest)
