"""Influence matrices of the two bodies at the strip nodes (paper eq. 23–30; docs/formulation.md §3).

``MODELS`` maps a scene's ``contact.model`` to a builder ``f(strip, **kw) -> Influence``;
:func:`build_influence` dispatches on it.
"""
from __future__ import annotations

from ..errors import InputError
from .halfspace import Influence, halfspace_influence, min_eigenvalue


def bem_influence(strip, **kw) -> Influence:
    """The BEM influence (:func:`rollqp.influence.bem.bem_influence`), imported when a scene asks for
    it: the BEM module and scipy.linalg stay out of ``import rollqp`` (half-space scenes never
    load them)."""
    from .bem import bem_influence as build
    return build(strip, **kw)

__all__ = ["Influence", "halfspace_influence", "bem_influence", "min_eigenvalue", "MODELS", "build_influence"]

#: Available influence models (``contact.model``).
MODELS = {"halfspace": halfspace_influence, "bem": bem_influence}


def build_influence(model: str, strip, **kw) -> Influence:
    """Build the influence of ``model`` on ``strip``; keyword arguments go to the builder.

    Raises
    ------
    InputError
        ``contact.model`` for an unknown model.
    """
    try:
        builder = MODELS[model]
    except (KeyError, TypeError):
        raise InputError("contact.model",
                         f"must be one of {', '.join(sorted(MODELS))}, got {model!r}") from None
    return builder(strip, **kw)
