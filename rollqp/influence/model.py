"""Influence models as declared records: what ``contact.model = "<name>"`` builds, reads, checks and supports.

A :class:`Model` says everything the rest of rollqp asks about a model — the scene validation (its
checks, whether it takes body profiles), the operators (its dense builder, its matrix-free operators
if it has them), the summary of a run (its rows) and the stresses command (whether its tractions sit
on a half-space) — so that no module outside :mod:`rollqp.influence` compares a model's name.
:func:`register` adds one (the built-in ``halfspace`` and ``bem`` are registered by
:mod:`rollqp.influence`); :func:`get` finds one by name, with the error a scene gets for an unknown one.

Examples
--------
>>> from rollqp.influence import get_model, model_names
>>> model_names()[:2]
('halfspace', 'bem')
>>> get_model("halfspace").matrix_free, get_model("bem").profiles
(True, False)
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from ..errors import InputError
from ..validate import suggestion

__all__ = ["Model", "register", "get", "names", "DEFAULT"]

#: The model of a scene without ``contact.model``.
DEFAULT = "halfspace"


@dataclass(frozen=True)
class Model:
    """One influence model (module docstring).

    Parameters
    ----------
    name : str
        ``contact.model``.
    build : callable
        ``build(scene, strip) -> Influence``: the dense influence matrices of the scene's bodies at the
        strip's nodes, the undeformed gap and an ``info`` dict (:class:`~rollqp.influence.Influence`).
    description : str
        One line, for listings.
    keys : tuple of str
        The scene keys it reads besides the bodies' ``radius``, ``E`` and ``nu`` (documentation, and the
        summary of a run).
    check : callable or None
        ``check(scene)``: its checks of a whole scene, an :class:`~rollqp.errors.InputError` naming the key
        (run with the scene's own, before any work).
    operators : callable or None
        ``operators(scene, strip) -> (A_nn, A_tt, A_tn, A_nt, h, info)`` as FFT operators without stored
        matrices (:mod:`rollqp.matrixfree`); None: dense only.
    profiles : bool
        It takes body profiles (:mod:`rollqp.profiles`: any undeformed gap); False: the round rollers only.
    halfspace_field : bool
        Its tractions act on a half-space, so the subsurface stresses of :mod:`rollqp.subsurface` are its
        own; False: the stresses are a half-space field below its tractions (an approximation, noted).
    report : callable or None
        ``report(meta) -> [(label, text), …]``: rows of a run's summary from the result's ``meta["model"]``.
    memo : bool
        ``build`` takes the keyword ``memo``: the :class:`~rollqp.influence.memo.Memo` of the scene's
        operators, where it keeps what depends on the geometry alone (the BEM's roller compliances).
    dimensions : frozenset of int
        The scenes it models: 2 (a strip: ``build(scene, strip)``) and/or 3 (a grid of rectangles:
        ``build(grid, materials)`` returns the contact's operators, ``A_nn``, ``A_tt`` and for dissimilar
        bodies ``A_nt``, ``A_tn``, with their ``shifted`` and ``steady`` copies, as
        :class:`~rollqp.influence.grid.ContactOperators` does). One name may hold one model per dimension.
    """

    name: str
    build: Callable
    description: str = ""
    keys: tuple = ()
    check: Callable | None = None
    operators: Callable | None = None
    profiles: bool = True
    halfspace_field: bool = True
    report: Callable | None = None
    memo: bool = False
    dimensions: frozenset = frozenset({2})

    def __post_init__(self):
        dims = frozenset(self.dimensions)
        if not dims or not dims <= {2, 3}:
            raise InputError("model.dimensions", f"must be a non-empty subset of {{2, 3}}, got {sorted(dims)}")
        object.__setattr__(self, "dimensions", dims)

    @property
    def matrix_free(self) -> bool:
        """It has FFT operators (:attr:`operators`)."""
        return self.operators is not None


#: (name, dimension) → :class:`Model`, in the order registered.
_MODELS: dict[tuple, Model] = {}


def register(model: Model) -> Model:
    """Make ``contact.model = model.name`` build ``model``; returns it.

    Raises
    ------
    InputError
        ``model`` is not a :class:`Model`, or its name is taken.
    """
    if not isinstance(model, Model):
        raise InputError("model", f"must be a rollqp.influence.Model, got {type(model).__name__}")
    taken = [d for d in sorted(model.dimensions) if (model.name, d) in _MODELS]
    if taken:
        raise InputError("model.name", f"{model.name!r} is registered already for {taken[0]}D scenes "
                                       f"(models: {', '.join(names(taken[0]))})")
    for d in sorted(model.dimensions):
        _MODELS[(model.name, d)] = model
    return model


def names(dimension: int = 2) -> tuple[str, ...]:
    """The names of the registered models of ``dimension``'s scenes."""
    return tuple(n for n, d in _MODELS if d == dimension)


def get(name, key: str = "contact.model", dimension: int = 2) -> Model:
    """The model ``name`` of ``dimension``'s scenes; an :class:`InputError` on ``key`` naming the registered
    ones if there is none."""
    model = _MODELS.get((name, dimension)) if isinstance(name, str) else None
    if model is None:
        known = names(dimension)
        raise InputError(key, f"must be one of {', '.join(map(repr, known))}, got {name!r}"
                              + suggestion(name, known))
    return model
