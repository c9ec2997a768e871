r"""The step-method protocol: what a method declares, how it is made, set up and called.

Every step method — the QP backends, the generalized Newton method, the N–T alternation —
follows one life cycle (osqp-python's ``setup`` / ``update`` / ``solve``)::

    method = Cls.from_settings(settings, **options)   # validated; unknown options are an error
    method.setup(operators)                           # once per scene (rollqp.operators.SceneOperators)
    sol = method.solve(problem, warm)                 # every step: only vectors change

and declares what it can solve in :attr:`Method.solves`, a subset of :data:`KINDS`:

``"normal"``, ``"tangential"``, ``"coupled"``
    the step problems of :mod:`rollqp.problem` (their ``kind``);
``"steady"``
    the non-symmetric steady-rolling tangential/coupled problem (slip ``s = ξ e + T w``, ``T`` the
    transient step's fixed point, docs/formulation.md §9), posed directly for a rolling start.

The registry (:mod:`rollqp.methods`) composes methods from these declarations only — a QP
backend on a coupled scene runs inside the N–T alternation (:class:`~rollqp.methods.alternation.Alternation`);
a method that solves ``"steady"`` gets a direct rolling start, the others march to it
(:func:`rollqp.march`) — so method names are compared nowhere else.
"""
from __future__ import annotations

from typing import Iterable, Protocol, runtime_checkable

from ..errors import InputError

#: What a method may declare in :attr:`Method.solves`.
KINDS = ("normal", "tangential", "coupled", "steady")


@runtime_checkable
class Method(Protocol):
    """A step method (module docstring).

    Attributes
    ----------
    name : str
        The registry name (``"qp-clarabel"``, ``"newton"``, …).
    solves : frozenset of str
        The problem kinds it solves (:data:`KINDS`).
    operator : {"exact", "symmetrized"}
        ``"exact"``: it solves the collocation problem with the influence operator as it is.
        ``"symmetrized"``: it solves the problem with ``F⁻¹ sym(F A)`` instead, and the scene's
        operators are built that way for the whole transient (docs/formulation.md §7).
    tolerance : float
        rollqp's nondimensional residual the method is asked to reach.
    """

    name: str
    solves: frozenset
    operator: str
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
    if problem.kind not in method.solves:
        raise InputError("problem", f"method {method.name!r} does not solve {problem.kind} steps "
                                    f"(it solves: {', '.join(k for k in KINDS if k in method.solves)})")
