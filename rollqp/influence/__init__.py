"""Influence matrices of the two bodies at the strip nodes (paper eq. 23–30; docs/formulation.md §3).

Each model is a declared record, a :class:`Model` (:mod:`.model`): its builder from a scene, the scene
keys it reads, its checks, whether it has matrix-free operators and takes body profiles, its rows in a
run's summary. :func:`register_model` adds one — ``contact.model`` then accepts its name everywhere;
:func:`get_model` finds one. The built-in ``halfspace`` and ``bem`` are in :mod:`.builtin`.

``MODELS`` maps a model's name to its array builder ``f(strip, **kw) -> Influence`` and
:func:`build_influence` dispatches on it (the builders with their own keyword arguments, without a scene).
"""
from __future__ import annotations

from . import builtin
from ..errors import InputError
from .halfspace import Influence, halfspace_influence, min_eigenvalue
from .memo import Memo
from .model import DEFAULT as DEFAULT_MODEL
from .model import Model
from .model import get as get_model
from .model import names as model_names
from .model import register as register_model

__all__ = ["Influence", "halfspace_influence", "bem_influence", "min_eigenvalue", "MODELS", "build_influence", "Model",
           "register_model", "get_model", "model_names", "DEFAULT_MODEL", "Memo"]

def bem_influence(strip, **kw) -> Influence:
    """The BEM influence (:func:`rollqp.influence.bem.bem_influence`), imported when a scene asks for it."""
    from .bem import bem_influence as build  # the BEM module: numpy.polynomial at its import, scipy.linalg on its solve (import rollqp stays light)
    return build(strip, **kw)


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


register_model(builtin.HALFSPACE)
register_model(builtin.BEM)
register_model(builtin.HALFSPACE_3D)
