"""Figures of a transient, designed per kind of scene. Needs the ``plot`` extra (matplotlib).

What a scene is about decides the panels (:func:`figure_kind`, :func:`plot_result`: what
``rollqp run --plot`` draws):

=============  =====================================================  ==========================
kind           the scene                                              figure
=============  =====================================================  ==========================
``coupled``    dissimilar bodies with normal–tangential coupling      :func:`coupled_figure`
``profile``    a profile feature rolls through (a dent, a flat)       :func:`profile_figure`
``rest``       tangential loads that change at rest (fretting)        :func:`rest_figure`
``path``       a stop or a reversal of the rolling (``load.rolled``)  :func:`path_figure`
``friction``   a friction law: μ that varies with x or slip velocity  :func:`friction_figure`
``transient``  similar bodies rolling (Cattaneo to Carter, a ramp)    :func:`transient_figure`
``three``      a 3D scene (Kalker's problem): its linear theory, a     :func:`three_figure`
               point of the creep curve, or a transient
               (:func:`~rollqp.plot.three.three_kind`)
=============  =====================================================  ==========================

Every figure labels its axes in mathtext, gives each closed form a colour of its own
(:data:`REFERENCES`), puts its legends below the panels, and has dimensional scales (the
scene's ``units``) beside the nondimensional ones (:mod:`rollqp.plot.style`). The parts are
public too: :func:`snapshot_figure`, :func:`zone_map_figure`, :func:`dissimilar_figure` (all
on one page, with the solver's iterations), :func:`comparison_figure` (several results
overlaid), and the ``draw_*`` functions that draw one panel.

Every function takes the result's arrays (``Result.arrays()``, :func:`rollqp.load_result`,
or a :class:`~rollqp.result.Result`) and, optionally, the scene; without the scene it is read
from the result's ``meta``. With ``path`` the figure is saved and closed and the path
returned; without it the matplotlib figure is returned.
"""
from __future__ import annotations

import numpy as np

from ..scene import BETA_ZERO
from .dissimilar import (FREE_ROLLING_RATIO, SETTLED_RATE, comparison_figure, coupled_figure, dissimilar_figure,
                         draw_history, draw_pressure, draw_snapshots, draw_traction, draw_zone_map, select_states,
                         settled_q, snapshot_figure, zone_map_figure)
from .friction import friction_figure
from .paths import path_figure, profile_figure, rest_figure
from .stresses import plot_field, plot_field3d
from .style import LABELS, REFERENCES, STATE_COLORS, STATE_NAMES, arrays, pyplot, scene_of
from .three import three_figure
from .transient import snapshot_indices, transient_figure

__all__ = ["pyplot", "plot_result", "figure_kind", "FIGURES", "transient_figure", "three_figure", "coupled_figure", "profile_figure",
           "rest_figure", "path_figure", "friction_figure", "snapshot_figure", "zone_map_figure", "dissimilar_figure",
           "comparison_figure", "draw_snapshots", "draw_zone_map", "draw_history", "draw_pressure", "draw_traction",
           "select_states", "settled_q", "snapshot_indices", "LABELS", "REFERENCES", "STATE_COLORS", "STATE_NAMES",
           "FREE_ROLLING_RATIO", "SETTLED_RATE", "plot_field", "plot_field3d"]

#: The figure of each kind (:func:`figure_kind`).
FIGURES = {"coupled": coupled_figure, "profile": profile_figure, "rest": rest_figure, "path": path_figure,
           "friction": friction_figure, "transient": transient_figure, "three": three_figure}
#: The kind of every scene of a dimension that has one figure (the scene's ``dimension``).
DIMENSION_KINDS = {3: "three"}


def figure_kind(res, scene=None) -> str:
    """What a run is about, which decides its figure (module table).

    A 3D scene has its own kind (:data:`DIMENSION_KINDS`). Else, in this order: normal–tangential
    coupling (β ≠ 0, coupling not "off"); a body profile with a feature that rolls through the
    contact; tangential loads that change while the rollers stand still (static steps with a varying
    Q); a stop or a reversal of the rolling; a friction law (μ not one number); else a transient of
    similar bodies.
    """
    res = arrays(res)
    scene = scene_of(res, scene)
    if scene is None:
        return "transient"
    if scene.dimension in DIMENSION_KINDS:
        return DIMENSION_KINDS[scene.dimension]
    if scene.coupling_level != "off" and abs(scene.beta) > BETA_ZERO:
        return "coupled"
    if any(b.profile is not None and b.profile.moves for b in (scene.A, scene.B)):
        return "profile"
    law = scene.contact.friction.kind != "constant"
    d = np.asarray(res["direction"]) if "direction" in res else None
    if d is None:
        return "friction" if law else "transient"
    rest = d == 0
    rest[0] = scene.load.start == "braked"
    Q = np.asarray(res["Q"], dtype=float)
    if rest.sum() > 2 and np.ptp(Q[rest]) > 1e-9 * max(float(np.abs(res["P"]).max()), 1e-300):
        return "rest"
    moving = d[1:][d[1:] != 0]
    if rest[1:].any() or (moving.size and np.ptp(moving) > 0):
        return "path"
    return "friction" if law else "transient"


def plot_result(res, scene, path, **kw) -> str:
    """The figure ``rollqp run --plot`` draws: the one of the run's :func:`figure_kind`."""
    res = arrays(res)
    scene = scene_of(res, scene)
    return FIGURES[figure_kind(res, scene)](res, scene, path, **kw)
