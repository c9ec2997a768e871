"""The result file's fields: one documented registry of every array a result file can hold.

Each :class:`Field` names an array of the result file (docs/results.md), its shape (``"state"``:
``(K+1, n)``, one row per stored state; ``"step"``: ``(K+1,)``; ``"node"``: ``(n,)``; ``"scalar"``),
its physical dimension and a one-line description, and how it is computed: from a
:class:`~rollqp.march.StepRecord` and the scene's :class:`~rollqp.operators.SceneOperators`
(``compute``, as each record arrives), from the stored fields of a block of states at once
(``derive``, when the result's arrays are made: in bulk, not step by step), or from the scene alone
(scalars). :class:`~rollqp.result.Result` fills the fields a scene needs (``needed(scene)``); the
dataset writers (xarray) read the units and descriptions from here. ``reduce`` says how a result
that keeps every k-th state combines the steps in between (docs/results.md).

Adding a result field is adding one :class:`Field` to :data:`FIELDS` (or registering one with
:func:`register` from the module that computes it): nothing else changes.

Dimensions are written in the scene's own units (``force``, ``length``; a stress is
``force/length^2`` and loads are per unit axial length): rollqp does not fix a unit system.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

__all__ = ["Field", "FIELDS", "FIELDS_3D", "registry", "register", "fields_for", "Rows", "node_shape"]

#: Shapes a field may have: per stored state and node, per stored state, per node, scalar.
SHAPES = ("state", "step", "node", "scalar")
#: How a result that keeps every k-th state combines a field over the steps since the last stored
#: state: the stored state's own value, the sum (works, times, iteration counts), the largest.
REDUCTIONS = ("last", "sum", "max")


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
    derive : callable or None
        ``derive(rows) -> array``: the field of a block of consecutive states at once, from the
        stored fields (:class:`Rows`: ``rows["pt"]``, ``rows.before("pn")``, ``rows.constants``);
        computed when the arrays are made, not per step.
    reduce : {"last", "sum", "max"}
        How a result keeping every k-th state combines the steps between stored states
        (:data:`REDUCTIONS`).
    needed : callable
        ``needed(scene) -> bool``: whether a scene's result holds the field (model only what a
        scene needs); the core fields are always there.
    contract : bool
        Part of the outer contract (docs/results.md: names and meanings never change).
    columns : int
        A ``"step"`` field with columns: ``(K+1, columns)`` (0: ``(K+1,)``).
    low, high : float or None
        The range a file's values must lie in (checked by :func:`rollqp.result.load_result`: a
        value outside is a corrupt or edited file); None: unbounded.
    finite : bool
        The values are finite numbers (False: a run may write NaN or infinity, e.g. an undetermined
        approach).
    """

    name: str
    shape: str
    units: str
    description: str
    dtype: str = "float64"
    compute: Callable | None = None
    needed: Callable = staticmethod(lambda scene: True)
    contract: bool = False
    derive: Callable | None = None
    reduce: str = "last"
    columns: int = 0
    low: float | None = None
    high: float | None = None
    finite: bool = True

    def __post_init__(self):
        if self.shape not in SHAPES:
            raise ValueError(f"field {self.name!r}: shape must be one of {SHAPES}, got {self.shape!r}")
        if self.reduce not in REDUCTIONS:
            raise ValueError(f"field {self.name!r}: reduce must be one of {REDUCTIONS}, got {self.reduce!r}")
        if self.compute is not None and self.derive is not None:
            raise ValueError(f"field {self.name!r}: computed from the record or derived from stored fields, not both")


class Rows:
    """A block of consecutive states as :attr:`Field.derive` sees it.

    ``rows[name]`` is a field of the block's states (``m`` rows: read from the store, or derived
    first if it is a derived field), ``rows.before(name)`` the same field of each state's
    predecessor (NaN rows for the starting state, which has none), ``rows.constants`` the run's
    constants (``"f"``: the nodes' weights; ``"wear_A"``, ``"wear_B"``: Archard coefficients).
    """

    def __init__(self, read, m: int, constants: dict, read_before=None, fields=None):
        self._read, self._before, self.m, self.constants = read, read_before, m, constants
        self.fields = FIELDS if fields is None else fields
        self._cache = {}

    def __getitem__(self, name: str) -> np.ndarray:
        got = self._cache.get(name)
        if got is None:
            f = self.fields.get(name)
            got = self._read(name)
            if got is None and f is not None and f.derive is not None:
                got = np.asarray(f.derive(self), dtype=dtype_of(name, self.fields))
            if got is None:
                raise KeyError(name)
            self._cache[name] = got
        return got

    def before(self, name: str) -> np.ndarray:
        """``name`` of each state's predecessor (the state before the block for the first row)."""
        return self._before(name)


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
    Field("state", "state", "1", "node state: 0 separation, 1 stick, 2 slip", dtype="int8", contract=True,
          low=0, high=2),
    Field("P", "step", FORCE, "normal load on body A", contract=True),
    Field("Q", "step", FORCE, "tangential load on body A, +x", contract=True),
    Field("creepage", "step", "1", "creepage xi = (V_A - V_B)/|V|", contract=True, finite=False),
    Field("approach", "step", LENGTH, "rigid approach delta", contract=True, finite=False),
    Field("shift", "step", LENGTH, "rigid static shift of a braked start (0 for rolling states)"),
    Field("step", "step", "1", "index k of each stored state in the run, 0..K (every k unless the run kept only "
                               "every k-th state: keep_every in meta)", dtype="int64", low=0),
    Field("iterations", "step", "1", "solver iterations of the step (outer iterations for N-T)", dtype="int64",
          contract=True, reduce="sum", low=0),
    Field("step_time", "step", "s", "wall seconds of the step", contract=True, reduce="sum", low=0),
    Field("residual", "step", "1", "the step's complementarity residual (nondimensional max norm, "
                                   "docs/formulation.md §5)", contract=True, reduce="max", finite=False),
    Field("inner_normal", "step", "1", "iterations of the normal halves (N-T: summed over outer iterations)",
          dtype="int64", reduce="sum"),
    Field("inner_tangential", "step", "1", "iterations of the tangential halves", dtype="int64", reduce="sum"),
    Field("backtracks", "step", "1", "Armijo step reductions of the Newton methods", dtype="int64", reduce="sum"),
    Field("a_H", "scalar", LENGTH, "Hertz half-width of the reference load", contract=True),
    Field("p0", "scalar", STRESS, "Hertz peak pressure of the reference load", contract=True),
    Field("R", "scalar", LENGTH, "relative radius, 1/R = 1/R_A + 1/R_B", contract=True),
    Field("Estar", "scalar", STRESS, "contact modulus E*, 1/E* = (1-nu_A^2)/E_A + (1-nu_B^2)/E_B", contract=True),
    Field("beta", "scalar", "1", "Dundurs' parameter beta (the paper's constant is 2 beta)", contract=True),
    Field("leading_edge", "scalar", "1", "+1 or -1: the sign of x where material enters", dtype="int64",
          contract=True),
)}


#: Every field of a 3D scene's result (a grid of elements: ``"state"`` fields are ``(K+1, ny, nx)``, row ``j``
#: is ``y_j``; the ``"node"`` fields ``x`` (nx,) and ``y`` (ny,) are the element centres), in file order. Forces
#: and moments are whole (not per unit axial length).
FIELDS_3D: dict[str, Field] = {f.name: f for f in (
    Field("x", "node", LENGTH, "element centres along x (nx,), the rolling direction", contract=True),
    Field("y", "node", LENGTH, "element centres along y (ny,), lateral", contract=True),
    Field("q", "step", LENGTH, "rolled distance of each stored state (0: the starting state)", contract=True),
    Field("pn", "state", STRESS, "pressure, >= 0", contract=True),
    Field("px", "state", STRESS, "tangential traction on body A along x", contract=True),
    Field("py", "state", STRESS, "tangential traction on body A along y", contract=True),
    Field("sx", "state", "1", "slip of A relative to B along x per unit rolled distance (state 0 of a braked "
                              "start: per c = sqrt(ab) of static shift)", contract=True),
    Field("sy", "state", "1", "slip of A relative to B along y, as sx", contract=True),
    Field("state", "state", "1", "element state: 0 separation, 1 stick, 2 slip", dtype="int8", contract=True,
          low=0, high=2),
    Field("FN", "step", "force", "normal force on body A", contract=True),
    Field("Fx", "step", "force", "tangential force on body A along x", contract=True),
    Field("Fy", "step", "force", "tangential force on body A along y", contract=True),
    Field("Mz", "step", "force*length", "spin moment on body A about z (about the grid's origin)", contract=True),
    Field("creepage", "step", "1", "(K+1, 3): xi, eta (rigid slip of A relative to B over |V|) and phi "
                                   "(spin, 1/length)", contract=True, columns=3, finite=False),
    Field("approach", "step", LENGTH, "rigid approach delta", contract=True, finite=False),
    Field("step", "step", "1", "index k of each stored state in the run, 0..K", dtype="int64", low=0),
    Field("iterations", "step", "1", "solver iterations of the step (N-T: sweeps times the tangential ones)",
          dtype="int64", contract=True, reduce="sum", low=0),
    Field("step_time", "step", "s", "wall seconds of the step", contract=True, reduce="sum", low=0),
    Field("residual", "step", "1", "the step's residual (rollqp's, nondimensional max norm, docs/theory3d.md "
                                   "§10)", contract=True, reduce="max", finite=False),
    Field("a", "scalar", LENGTH, "Hertz semi-axis along x", contract=True),
    Field("b", "scalar", LENGTH, "Hertz semi-axis along y", contract=True),
    Field("p0", "scalar", STRESS, "Hertz peak pressure", contract=True),
    Field("Estar", "scalar", STRESS, "contact modulus E*", contract=True),
)}

#: The registry of each dimension (``meta["dimension"]`` of a result file; 2 when absent).
REGISTRIES = {2: FIELDS, 3: FIELDS_3D}


def registry(dimension: int = 2) -> dict:
    """The fields of a result of ``dimension`` (2: the strip, :data:`FIELDS`; 3: the grid, :data:`FIELDS_3D`)."""
    return REGISTRIES[dimension]


def node_shape(fields: dict, sizes: dict) -> tuple:
    """The shape of a ``"state"`` field's row: the sizes of the ``"node"`` fields (the coordinates), the last
    coordinate first (2D: ``(n,)``; 3D: ``(ny, nx)``). ``sizes``: each coordinate's length."""
    return tuple(sizes[f.name] for f in reversed(list(fields.values())) if f.shape == "node")


def register(f: Field, dimension: int = 2) -> Field:
    """Add a field to the registry of ``dimension`` (a module that computes a new quantity registers it once)."""
    fields = registry(dimension)
    if f.name in fields and fields[f.name] != f:
        raise ValueError(f"a different result field {f.name!r} is already registered")
    fields[f.name] = f
    return f


def fields_for(scene) -> list[Field]:
    """The computed and derived fields (``compute`` or ``derive`` set) that ``scene``'s result holds."""
    fields = registry(getattr(scene, "dimension", 2))
    return [f for f in fields.values() if (f.compute is not None or f.derive is not None) and f.needed(scene)]


def dtype_of(name: str, fields: dict | None = None):
    """The numpy dtype of field ``name`` of ``fields`` (default :data:`FIELDS`; float64 for a key that is not
    registered)."""
    f = (FIELDS if fields is None else fields).get(name)
    return np.dtype(f.dtype if f is not None else "float64")


def markdown_table(dimension: int = 2) -> str:
    """The result-file reference table of docs/results.md for ``dimension``, generated from its registry."""
    fields = registry(dimension)
    coords = [f.name for f in fields.values() if f.shape == "node"]
    node = "n" if len(coords) == 1 else ", ".join(f"n{c}" for c in reversed(coords))
    shapes = {"state": f"(K+1, {node})", "step": "(K+1,)", "scalar": "()"}
    rows = ["| key | shape | units | meaning |", "|---|---|---|---|"]
    for f in fields.values():
        shape = (f"(n{f.name},)" if len(coords) > 1 else "(n,)") if f.shape == "node" else \
            f"(K+1, {f.columns})" if f.columns else shapes[f.shape]
        units = "–" if f.units == "1" else f.units
        note = "" if f.contract else " *(beyond the contract)*"
        if f.reduce != "last" and dimension == 2:
            note = f" (keeping every k-th state: the {'sum' if f.reduce == 'sum' else 'largest'} over the steps since " \
                   f"the previous stored state){note}"
        text = f.description.replace("|", "\\|")
        rows.append(f"| `{f.name}` | {shape} | {units} | {text}{note} |")
    rows.append(_META_ROW[dimension])
    return "\n".join(rows)


_META_ROW = {
    2: "| `meta` | () | – | JSON string: the full scene with defaults, the method, the model's data, "
       "package versions, `keep_every`, and notes (`failed`, `interrupted`, `resumed_from`, `gross_sliding`, "
       "`rolling_start`); a list of more than 64 numbers in it (a profile table) is stored as the array "
       "`meta.<path>` and written `{\"$array\": \"meta.<path>\"}` in its place |",
    3: "| `meta` | () | – | JSON string: the full scene with defaults, the method, package versions, `dimension` (3), "
       "`static_shift` (the braked start's rigid shift of A relative to B, x and y), `raw_distance` (a conic "
       "method's raw answers against the refined ones) and notes (`failed`, `interrupted`, `resumed_from`); long "
       "lists stored as arrays, as in 2D |"}


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


def _grid_friction_coefficient(rec, contact):
    """``μ`` at the elements of a 3D step, ``(ny, nx)``: a slip-velocity law's own (its memory, kept by the march in
    ``StepRecord.mu``; else the law at the state's slip), a patch's or a table's at the rolled distance and direction
    the step read it at (a load path's pose, else the record's ``q`` and the march's direction)."""
    g = contact.grid
    if rec.mu is not None:
        mu = rec.mu
    elif contact.law.kind == "slip":
        mu = contact.slip_bound("shift").mu(np.asarray(rec.s, dtype=float).reshape(2, -1), contact=np.asarray(rec.p) > 0)
    else:
        pose = rec.info.get("pose")
        q, d = (pose[4].q, pose[3]) if pose is not None else (rec.q, rec.info.get("direction", -1))
        mu = contact.coefficient(q, d)
    return g.field(np.broadcast_to(np.asarray(mu, dtype=float), (g.n,)))


register(Field("mu", "state", "1",
               "the friction coefficient each element had in the step (scenes with a friction law: patches, tables, "
               "slip-velocity laws; docs/friction.md)",
               compute=_grid_friction_coefficient, needed=lambda scene: scene.contact.friction.kind != "constant"), 3)
