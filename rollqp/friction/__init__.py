r"""Friction laws as objects: the registry, the scene key ``contact.friction`` and the per-step bound.

Friction enters a step only through its bound ``b = μ p⁺`` (paper eq. 57–60, 63). A law
(:mod:`.laws`) says what ``μ`` depends on; :func:`step_coefficient` turns it into what one step
problem takes in place of the old number ``mu``:

* a constant law: the ``float`` ``μ`` itself — the step problems and methods then take exactly
  the code path they took before laws existed (bitwise the same results);
* a law varying along the surface: an ``(n,)`` array ``μ_i`` at the nodes, fixed during the
  step (the bound stays independent of the unknowns: each half is still a convex QP);
* a slip-velocity law: a :class:`~.bound.SlipBound` — ``μ_i(s_i)`` depends on the unknown slip,
  and the step becomes a quasi-variational inequality (docs/theory.md, "Slip-dependent
  friction"), solved by the Newton method with ``∂b/∂s`` in its pseudo-Jacobian or by a
  fixed point on the bound around any QP backend (:class:`rollqp.methods.fixedpoint.BoundFixedPoint`).

``contact.friction`` is a number (Coulomb) or a table with ``law = "<name>"`` and the law's keys:
:data:`LAWS` maps each name to its record. Adding a law is one record in :mod:`.laws` with
``kind`` ``"constant"``, ``"spatial"`` or ``"slip"`` (and ``coefficient`` or ``steady``) and one
entry here.
"""
from __future__ import annotations

import dataclasses

from ..errors import InputError
from ..validate import suggestion
from .laws import FRAMES, MAX_FRICTION, VELOCITY_FORMS, Coulomb, Patch, SlipVelocity, Table

__all__ = ["LAWS", "parse_friction", "Coulomb", "Patch", "Table", "SlipVelocity", "MAX_FRICTION", "FRAMES",
           "VELOCITY_FORMS", "law_kind"]

#: ``law`` name → record (its fields are the table's keys).
LAWS = {"coulomb": Coulomb, "patch": Patch, "table": Table,
        **{form: SlipVelocity for form in VELOCITY_FORMS}}

KEY = "contact.friction"


def parse_friction(value):
    """The law of ``contact.friction``: a number is Coulomb's ``μ`` (returned as a ``float``, as
    before), a table (dict) or a law record is checked key by key; anything else an InputError."""
    if isinstance(value, (Coulomb, Patch, Table, SlipVelocity)):
        value = {f.name: getattr(value, f.name) for f in dataclasses.fields(value)}
    if not isinstance(value, dict):
        from ..validate import number
        return number(KEY, value, f">= 0 (and <= {MAX_FRICTION:g}), or a table [contact.friction] with law = "
                                  f"{', '.join(map(repr, LAWS))}", lambda x: 0 <= x <= MAX_FRICTION)
    name = value.get("law")
    if name not in LAWS:
        raise InputError(f"{KEY}.law", f"must be one of {', '.join(map(repr, LAWS))}, got {name!r}"
                                       + suggestion(name, LAWS))
    cls = LAWS[name]
    names = [f.name for f in dataclasses.fields(cls)]
    for k in value:
        if k not in names:
            raise InputError(f"{KEY}.{k}", f"unknown key{suggestion(k, names)} for law {name!r} (allowed: "
                                           f"{', '.join(names)})")
    required = [f.name for f in dataclasses.fields(cls)
                if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING]
    for k in required:
        if k not in value:
            raise InputError(f"{KEY}.{k}", f"missing required key of law {name!r} (it needs {', '.join(required)})")
    law = cls(**value)
    return law.mu if isinstance(law, Coulomb) else law  # Coulomb: the number, as before (the old code path)


def law_kind(friction) -> str:
    """``"constant"`` (a number or :class:`Coulomb`), ``"spatial"`` or ``"slip"``."""
    return "constant" if not hasattr(friction, "kind") else friction.kind


def reference(friction) -> float:
    """The reference ``μ`` of a law (a number is its own): ``load.tangential`` is ``Q/(μ_ref P̄)``."""
    return float(friction) if not hasattr(friction, "reference") else float(friction.reference)


def largest(friction) -> float:
    """The largest ``μ`` the law can take (0: frictionless everywhere)."""
    return float(friction) if not hasattr(friction, "largest") else float(friction.largest)
