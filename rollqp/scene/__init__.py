"""Scenes: the validated description of one transient rolling-contact problem.

A scene is read from a TOML file (every key: docs/scenes.md), from the name of a
built-in scene (the files in ``rollqp/scenes/``) or from a plain dict of the same nesting::

    name, description
    [bodies.A] [bodies.B]   radius, E, nu, shaft_radius
    [contact]               friction, model, coupling, reference_distance, bem_outer_elements,
                            bem_inner_elements
    [load]                  normal, normal_history, tangential | creepage, start, direction,
                            start_steps, approach
    [discretization]        elements, element, zone, step, formulation, distance
    [solver]                method, tolerance, max_iterations, augmentation

Units are the user's, as long as they are consistent (the paper: N and mm). Loads are per unit
axial length. Load histories are functions of the rolled distance q in units of a_H
(:mod:`rollqp.histories`).

Every invalid input is an :class:`~rollqp.errors.InputError` naming the dotted key
(``bodies.A.nu``) and the allowed range or values; unknown keys get the closest valid name.
Besides the per-key ranges, a scene is checked as a whole (docs/formulation.md §1, §9;
:mod:`rollqp.scene.checks`):

* the normal load stays >= 0 over the rolled distance; where it is 0 the bodies are out of
  contact (the driver records an unloaded state, :func:`rollqp.run`) and Q must be 0;
* the largest Hertz half-width, a_H·sqrt(max P/P̄), stays clear of the zone's edges by at
  least three quarters of an element: a_H·sqrt(max P/P̄) < L·(1 − 1.5/elements), L = zone·a_H
  (the element length is 2L/elements);
* with ``formulation = "convective-local"``, Δq is at most the node spacing
  (``discretization.step`` <= 1 for constant and linear, <= 0.5 for quadratic elements):
  the upwind transport is unstable beyond it (docs/stability.md);
* where a tangential load is prescribed, a stick solution exists: ``|Q| < μP``, i.e.
  ``|Q/(μP̄)| / (P/P̄) < 1``, at every step (and at the histories' breakpoints and peaks);
* the derived quantities (a_H, p0, E*, L, Δq) are finite: extreme inputs are refused, not
  overflowed; the work is bounded: at most ``MAX_NODES`` nodes and ``MAX_STEPS`` steps, and the
  dense matrices and the result within this machine's memory (the estimate is in the message);
* a harmonic history is resolved by the steps (at least two per wavelength).

The package, one responsibility per module: :mod:`.schema` (the plain records and allowed
values), :mod:`.checks` (each part, then the whole), :mod:`.derived` (E*, R,
β, the Hertz scales, Δq, the loads at q), :mod:`.core` (the :class:`Scene`), :mod:`.io` (TOML,
dicts and the built-in scenes in and out).

Sign convention (docs/formulation.md §1): material moves through the contact with direction
d = ``load.direction`` (the paper's examples: d = −1) and enters at the leading edge x = −d·L.
"""
from __future__ import annotations

import importlib

#: Public name -> submodule. Loaded on first use (PEP 562), so that ``import rollqp`` stays light.
_EXPORTS = {
    **{k: ".core" for k in ("Scene",)},
    **{k: ".io" for k in ("builtin_scenes", "load_scene", "scene_from_dict", "scene_from_toml", "scene_to_dict",
                          "scene_to_toml")},
    **{k: ".schema" for k in ("AUGMENTATION_MAX", "AUGMENTATION_MIN", "BETA_ZERO", "CONVECTIVE_STEP_MAX", "COUPLINGS",
                              "EDGE_ELEMENTS", "ELEMENT_TYPES", "FORMULATION_TYPES", "MAX_NODES", "MAX_START_STEPS",
                              "MAX_STEPS", "METHODS", "MODELS", "STARTS", "Body", "Contact", "Discretization", "Load",
                              "SolverSettings")},
}

__all__ = ["METHODS", "MODELS", "COUPLINGS", "STARTS", "ELEMENT_TYPES", "FORMULATION_TYPES",
           "Body", "Contact", "Load", "Discretization", "SolverSettings", "Scene",
           "load_scene", "scene_from_dict", "scene_from_toml", "builtin_scenes", "scene_to_dict", "scene_to_toml"]


def __getattr__(name):
    if name in _EXPORTS:
        value = getattr(importlib.import_module(_EXPORTS[name], __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))
