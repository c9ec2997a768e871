"""The result file's fields: one documented registry of every array a result file can hold.

Each :class:`Field` names an array of the result file (docs/results.md), its shape (``"state"``:
``(K+1, n)``, one row per stored state; ``"step"``: ``(K+1,)``; ``"node"``: ``(n,)``; ``"scalar"``),
its physical dimension and a one-line description, and how it is computed: from a
:class:`~rollqp.march.StepRecord` and the scene's :class:`~rollqp.operators.SceneOperators`
(``compute``), or from the scene alone (scalars). :class:`~rollqp.result.Result` fills the fields
a scene needs (``needed(scene)``) as the records arrive; the dataset writers
(xarray) read the units and descriptions from here.

Adding a result field is adding one :class:`Field` to :data:`FIELDS` (or registering one with
:func:`register` from the module that computes it): nothing else changes.

Dimensions are written in the scene's own units (``force``, ``length``; a stress is
``force/length^2`` and loads are per unit axial length): rollqp does not fix a unit system.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

__all__ = ["Field", "FIELDS", "register", "fields_for"]

#: Shapes a field may have: per stored state and node, per stored state, per node, scalar.
SHAPES = ("state", "step", "node", "scalar")


@dataclass(frozen=True)
class Field:
    """One array of the result file.

    Attributes
    ----------
    name : str
        The key in the ``.npz``.
    shape : {"state", "step", "node", "scalar"}
        ``(K+1, n)``, ``(K+1,)``, ``(n,)`` or ``()``.
    units : str
        Physical dimension in the scene's units (``"force/length^2"``, ``"1"`` for a pure number).
    description : str
        One line: what the array holds, with its sign convention.
    dtype : str
        ``"float64"``, ``"int64"`` or ``"int8"``.
    compute : callable or None
        ``compute(record, operators) -> value`` for a ``"state"``/``"step"`` field; ``None`` for
        the core fields that :class:`~rollqp.result.Result` reads off the record itself.
    needed : callable
        ``needed(scene) -> bool``: whether a scene's result holds the field (model only what a
        scene needs); the core fields are always there.
    contract : bool
        Part of the outer contract (docs/results.md: names and meanings never change).
    """

    name: str
    shape: str
    units: str
    description: str
    dtype: str = "float64"
    compute: Callable | None = None
    needed: Callable = staticmethod(lambda scene: True)
    contract: bool = False

    def __post_init__(self):
        if self.shape not in SHAPES:
            raise ValueError(f"field {self.name!r}: shape must be one of {SHAPES}, got {self.shape!r}")


STRESS, LENGTH, FORCE = "force/length^2", "length", "force/length"

#: Every field, in the order the result file lists them.
FIELDS: dict[str, Field] = {f.name: f for f in (
    Field("x", "node", LENGTH, "node coordinates along the strip (Eulerian, fixed to the contact)", contract=True),
    Field("q", "step", LENGTH, "rolled distance of each stored state (0: the starting state)", contract=True),
    Field("pn", "state", STRESS, "contact pressure, >= 0 in compression", contract=True),
    Field("pt", "state", STRESS, "tangential traction on body A, +x", contract=True),
    Field("slip", "state", "1", "slip s of A relative to B per unit rolled distance (step 0 of a braked start: "
                                "per a_H of static shift)", contract=True),
    Field("gap", "state", LENGTH, "deformed normal gap", contract=True),
    Field("state", "state", "1", "node state: 0 separation, 1 stick, 2 slip", dtype="int8", contract=True),
    Field("P", "step", FORCE, "normal load on body A", contract=True),
    Field("Q", "step", FORCE, "tangential load on body A, +x", contract=True),
    Field("creepage", "step", "1", "creepage xi = (V_A - V_B)/|V|", contract=True),
    Field("approach", "step", LENGTH, "rigid approach delta", contract=True),
    Field("shift", "step", LENGTH, "rigid static shift of a braked start (0 for rolling states)"),
    Field("iterations", "step", "1", "solver iterations of the step (outer iterations for N-T)", dtype="int64",
          contract=True),
    Field("step_time", "step", "s", "wall seconds of the step", contract=True),
    Field("residual", "step", "1", "the step's complementarity residual (nondimensional max norm, "
                                   "docs/formulation.md §5)", contract=True),
    Field("inner_normal", "step", "1", "iterations of the normal halves (N-T: summed over outer iterations)",
          dtype="int64"),
    Field("inner_tangential", "step", "1", "iterations of the tangential halves", dtype="int64"),
    Field("backtracks", "step", "1", "Armijo step reductions of the Newton methods", dtype="int64"),
    Field("a_H", "scalar", LENGTH, "Hertz half-width of the reference load", contract=True),
    Field("p0", "scalar", STRESS, "Hertz peak pressure of the reference load", contract=True),
    Field("R", "scalar", LENGTH, "relative radius, 1/R = 1/R_A + 1/R_B", contract=True),
    Field("Estar", "scalar", STRESS, "contact modulus E*, 1/E* = (1-nu_A^2)/E_A + (1-nu_B^2)/E_B", contract=True),
    Field("beta", "scalar", "1", "Dundurs' parameter beta (the paper's constant is 2 beta)", contract=True),
    Field("leading_edge", "scalar", "1", "+1 or -1: the sign of x where material enters", dtype="int64",
          contract=True),
)}


def register(f: Field) -> Field:
    """Add a field to :data:`FIELDS` (a module that computes a new quantity registers it once)."""
    if f.name in FIELDS and FIELDS[f.name] != f:
        raise ValueError(f"a different result field {f.name!r} is already registered")
    FIELDS[f.name] = f
    return f


def fields_for(scene) -> list[Field]:
    """The computed fields (``compute`` set) that ``scene``'s result holds."""
    return [f for f in FIELDS.values() if f.compute is not None and f.needed(scene)]


def dtype_of(name: str):
    """The numpy dtype of field ``name`` (float64 for a key that is not registered)."""
    f = FIELDS.get(name)
    return np.dtype(f.dtype if f is not None else "float64")


def markdown_table() -> str:
    """The result-file reference table of docs/results.md, generated from :data:`FIELDS`."""
    shapes = {"state": "(K+1, n)", "step": "(K+1,)", "node": "(n,)", "scalar": "()"}
    rows = ["| key | shape | units | meaning |", "|---|---|---|---|"]
    for f in FIELDS.values():
        units = "–" if f.units == "1" else f.units
        note = "" if f.contract else " *(beyond the contract)*"
        text = f.description.replace("|", "\\|")
        rows.append(f"| `{f.name}` | {shapes[f.shape]} | {units} | {text}{note} |")
    rows.append("| `meta` | () | – | JSON string: the full scene with defaults, the method, the model's data, "
                "package versions, and notes (`failed`, `interrupted`, `resumed_from`, `gross_sliding`, "
                "`rolling_start`) |")
    return "\n".join(rows)


# ------------------------------------------------------------------------- kinematics
def _with_rolled(scene) -> bool:
    return scene.load.rolled is not None


register(Field("time", "step", LENGTH, "time-like parameter tau of each state (load.rolled: q = q(tau) and the "
                                       "loads are histories of tau; 0: the starting state)",
               compute=lambda rec, ops: 0.0 if rec.tau is None else rec.tau, needed=_with_rolled))
register(Field("direction", "step", "1", "direction of the material in the step (load.rolled): +1 or -1, "
                                         "0 for a stop (a static shift step)", dtype="int64",
               compute=lambda rec, ops: rec.direction if rec.k > 0 else int(ops.scene.load.direction),
               needed=_with_rolled))


def _friction_coefficient(rec, operators):
    """``μ`` at the nodes of a step with a friction law (kept by the march in ``StepSolution.mu``)."""
    sol = rec.solution
    mu = None if sol is None else sol.mu
    return np.full(operators.n, float(operators.mu)) if mu is None else np.asarray(mu, dtype=float)


register(Field("friction_coefficient", "state", "1",
               "coefficient of friction mu at each node in the step (scenes with a friction law, docs/friction.md)",
               compute=_friction_coefficient, needed=lambda scene: scene.contact.friction.kind != "constant"))
