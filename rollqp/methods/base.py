r"""The step-method protocol: what a method declares, how it is made, set up and called.

Every step method — the QP backends, the generalized Newton method, the N–T alternation —
follows one life cycle (osqp-python's ``setup`` / ``update`` / ``solve``)::

    method = Cls.from_settings(settings, **options)   # validated; unknown options are an error
    method.setup(operators)                           # once per scene (rollqp.operators.SceneOperators)
    sol = method.solve(problem, warm)                 # every step: only vectors change

and declares what it can do in one frozen record, :attr:`Method.capabilities` (a :class:`Capabilities`):
what it solves (a subset of :data:`KINDS`), whether it needs the influence matrix or works with
products only, whether it poses slip-dependent friction bounds, and the switches the transient may
turn on. rollqp reads the record; it never probes a method for attributes. The kinds it solves:

``"normal"``, ``"tangential"``, ``"coupled"``
    the step problems of :mod:`rollqp.problem` (their ``kind``);
``"steady"``
    the non-symmetric steady-rolling tangential/coupled problem (slip ``s = ξ e + T w``, ``T`` the
    transient step's fixed point, docs/formulation.md §9), posed directly for a rolling start.

The registry (:mod:`rollqp.methods`) composes methods from these declarations only — a QP
backend on a coupled scene runs inside the N–T alternation (:class:`~rollqp.methods.alternation.Alternation`);
a method that solves ``"steady"`` gets a direct rolling start, the others march to it
(:func:`rollqp.march`); the scene's operators are built as the record asks (dense or matrix-free,
exact or symmetrized, :meth:`rollqp.operators.SceneOperators.build`) — so method names are compared
nowhere else.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable, Protocol, runtime_checkable

from ..errors import InputError

#: What a method may declare in :attr:`Capabilities.solves`.
KINDS = ("normal", "tangential", "coupled", "steady")
#: The kinds of friction law (:attr:`rollqp.friction.FrictionLaw.kind`).
FRICTION_KINDS = frozenset({"constant", "spatial", "slip"})


@dataclass(frozen=True)
class Capabilities:
    """What a step method declares it can do (the module docstring); read, never probed.

    The class attribute ``capabilities`` of a method class is its declaration (the registry reads it
    without making the method, e.g. to build a scene's operators); a method object may refine it with
    its settings (a tolerance-dependent limit, an option switched off) in its own ``capabilities``.

    Examples
    --------
    >>> from rollqp.methods import Capabilities, capabilities
    >>> capabilities("newton").solves == frozenset({"normal", "tangential", "coupled", "steady"})
    True
    >>> capabilities("mf-newton").matrix_free, capabilities("qp-osqp").matrix_free
    (True, False)
    >>> sorted(Capabilities(solves=frozenset({"normal", "tangential"})).dimensions)
    [2]
    """

    #: The problem kinds it solves (:data:`KINDS`).
    solves: frozenset = frozenset()
    #: ``"exact"``: the collocation problem with the influence operator as it is; ``"symmetrized"``: with
    #: ``F⁻¹ sym(F A)`` instead, and the scene's operators are built so for the whole transient
    #: (docs/formulation.md §7).
    operator: str = "exact"
    #: It works with operator products only (``A @ x``, ``x @ A``, ``diagonal()``, ``column(j)``), so that a
    #: scene may give it FFT operators (:mod:`rollqp.matrixfree`); False: it needs the n × n matrix.
    matrix_free: bool = False
    #: It solves steps whose friction bound depends on the slip itself; else the registry runs it inside the
    #: fixed point on the bound (:class:`rollqp.methods.fixedpoint.BoundFixedPoint`).
    slip_dependent: bool = False
    #: The kinds of friction law (:data:`FRICTION_KINDS`) its coupled step takes (when it solves ``"coupled"``).
    coupled_friction: frozenset = FRICTION_KINDS
    #: The coupled residual at which the N–T alternation around it stops (None: its tolerance).
    coupled_limit: float | None = None
    #: The largest rollqp residual of a solution it accepts (None: its tolerance).
    residual_limit: float | None = None
    #: ``method.single_sweeps(on)`` switches one N–T sweep per step on (the march to a steady state).
    single_sweeps: bool = False
    #: ``method.predicting(on)`` switches the active-set prediction of its QPs on (the same march).
    predicting: bool = False
    #: The accelerated rolling start of :mod:`rollqp.methods.steady_start` takes it (its QPs' sensitivity).
    accelerated_start: bool = False
    #: That start's quasi-Newton phase is used (False: Anderson alone).
    quasi_newton: bool = False
    #: The problems' dimensions it solves: 2 (a strip of nodes along x), 3 (a grid of surface elements).
    dimensions: frozenset = frozenset({2})
    #: Tangential traction components per node: 1 in 2D, 2 in 3D.
    traction_components: int = 1
    #: It keeps factorizations from one step to the next that a journaled march records and a resumed march
    #: rebuilds (:mod:`rollqp.solverstate`): ``method.carrier()`` is the object that keeps them.
    carries_state: bool = False
    #: The friction set ``|t| <= μ p`` of a node: ``"interval"`` (2D), ``"disc"`` (3D, a second-order cone).
    friction_set: str = "interval"

    def __post_init__(self):
        unknown = set(self.solves) - set(KINDS)
        if unknown:
            raise InputError("capabilities.solves", f"must be a subset of {KINDS}, got {sorted(unknown)}")
        if self.operator not in ("exact", "symmetrized"):
            raise InputError("capabilities.operator", f"must be 'exact' or 'symmetrized', got {self.operator!r}")
        object.__setattr__(self, "solves", frozenset(self.solves))
        object.__setattr__(self, "dimensions", frozenset(self.dimensions))
        if not self.dimensions or not self.dimensions <= {2, 3}:
            raise InputError("capabilities.dimensions", f"must be a non-empty subset of {{2, 3}}, got {sorted(self.dimensions)}")
        object.__setattr__(self, "coupled_friction", frozenset(self.coupled_friction))


@runtime_checkable
class Method(Protocol):
    """A step method (module docstring).

    Attributes
    ----------
    name : str
        The registry name (``"qp-clarabel"``, ``"newton"``, …).
    capabilities : Capabilities
        What it solves and how (:class:`Capabilities`).
    tolerance : float
        rollqp's nondimensional residual the method is asked to reach.
    """

    name: str
    capabilities: Capabilities
    tolerance: float

    @classmethod
    def from_settings(cls, settings, **options) -> "Method":
        """A method configured from a scene's :class:`~rollqp.scene.SolverSettings`.

        ``options`` are method-specific settings; an unknown one is an
        :class:`~rollqp.errors.InputError` naming it (:func:`check_options`).
        """

    def setup(self, operators) -> None:
        """Start a scene: forget the previous scene's solver objects; precompute on ``operators``."""

    def solve(self, problem, warm=None):
        """Solve one step problem, warm-started from ``warm``; a :class:`~rollqp.problem.StepSolution`.

        Raises :class:`~rollqp.errors.SolverError` short of rollqp's residual tolerance.
        """


def check_options(method: str, given: dict, allowed: Iterable[str]) -> None:
    """Reject settings a method does not know (osqp-python's ``Unrecognized settings``).

    Raises
    ------
    InputError
        Naming the first unknown option, the method and the options it accepts.
    """
    allowed = sorted(set(allowed))
    unknown = [k for k in given if k not in allowed]
    if unknown:
        import difflib
        close = difflib.get_close_matches(unknown[0], allowed, n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise InputError(unknown[0], f"unrecognized setting for method {method!r}{hint} "
                                     f"(allowed: {', '.join(allowed) or 'none'})")


def check_kind(method: "Method", problem) -> None:
    """Refuse, up front, a problem of a kind ``method`` does not declare in ``solves``."""
    solves = method.capabilities.solves
    if problem.kind not in solves:
        raise InputError("problem", f"method {method.name!r} does not solve {problem.kind} steps "
                                    f"(it solves: {', '.join(k for k in KINDS if k in solves)})")
