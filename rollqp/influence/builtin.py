"""The built-in influence models, as :class:`~rollqp.influence.model.Model` records: the half-space and the BEM.

Each adapter reads from a scene what its builder needs (the scene is not imported: its attributes are
read); the BEM module is imported only when a BEM scene is built.
"""
from __future__ import annotations

import math
import time

from ..errors import InputError
from .grid import ContactOperators
from .halfspace import halfspace_influence
from .halfspace import undeformed_gap
from .model import Model
from .toeplitz import halfspace_operators
from .toeplitz import positive_definite_threshold

__all__ = ["HALFSPACE", "BEM", "MIN_BEM_ELEMENT_RATIO"]


def halfspace_of(scene, strip):
    """The half-space influence of ``scene``'s cylinders on ``strip`` (:func:`~.halfspace.halfspace_influence`)."""
    return halfspace_influence(strip, Estar=scene.Estar, beta=scene.beta, R_A=scene.A.radius, R_B=scene.B.radius,
                               coupling=scene.coupling_level, d_ref=scene.reference_distance_value)


def halfspace_operators_of(scene, strip):
    """``(A_nn, A_tt, A_tn, A_nt, h, info)`` of a half-space scene as FFT operators (eq. 25–30; :mod:`rollqp.matrixfree`).

    ``d_ref`` must exceed the discretization's threshold
    (:func:`~rollqp.influence.toeplitz.positive_definite_threshold`), else an
    :class:`InputError` on ``contact.reference_distance`` as on the dense path.
    """
    t0 = time.perf_counter()
    coupling = scene.coupling_level
    d_ref = scene.reference_distance_value
    L = float(strip.half_width)
    d_min = positive_definite_threshold(strip)
    if not d_ref > d_min:
        raise InputError("contact.reference_distance",
                         f"d_ref = {d_ref:.6g} makes the normal influence operator indefinite; it must exceed "
                         f"L/2 = {L / 2:.6g} (continuous bound), the smallest admissible value for this mesh "
                         f"is {d_min:.6g}; the default is the relative radius R")
    Ann, Att, Atn, Ant = halfspace_operators(strip, Estar=scene.Estar, beta=scene.beta, d_ref=d_ref,
                                             coupling=coupling)
    h = undeformed_gap(strip.x, scene.A.radius, scene.B.radius)
    h.setflags(write=False)
    info = {"d_ref": d_ref, "d_ref_min": d_min, "d_ref_min_continuous": 0.5 * L, "coupling": coupling,
            "beta": scene.beta, "kappa": 2.0 * scene.beta, "Estar": scene.Estar, "R": scene.R,
            "R_A": float(scene.A.radius), "R_B": float(scene.B.radius), "operator_mode": "matrix-free",
            "operator_seconds": time.perf_counter() - t0}
    return Ann, Att, Atn, Ant, h, info


def bem_of(scene, strip, memo=None):
    """The true-geometry influence of ``scene``'s rollers on rigid shafts (:func:`rollqp.influence.bem.bem_influence`;
    ``memo``: where the rollers' compliances are kept, the scene operators' :class:`~rollqp.influence.memo.Memo`)."""
    # the BEM module: numpy.polynomial at its import, scipy.linalg on its solve (import rollqp stays light)
    from .bem import bem_influence
    return bem_influence(strip, Estar=scene.Estar, beta=scene.beta, R_A=scene.A.radius, R_B=scene.B.radius,
                         coupling=scene.coupling_level, d_ref=scene.reference_distance_value, A=scene.A, B=scene.B,
                         n_outer=scene.bem_mesh[0], n_inner=scene.bem_mesh[1], memo=memo)


#: Smallest strip element length over the smaller radius for ``model = "bem"``: the BEM nodes are
#: points ``R (cos θ, sin θ)`` and its collocation integrals need their separations resolved far
#: above round-off (1e-7 R is 1e9 ulps of R). Contacts this small are half-space contacts: the
#: BEM's departure from the half-space is of order a/R (docs/bem.md).
MIN_BEM_ELEMENT_RATIO = 1e-7


def check_bem_scene(scene) -> None:
    """``model = "bem"``: both shafts given, the strip shorter than half a circumference, its
    elements resolvable on the circles."""
    if scene.contact.model != "bem":
        return
    smaller = min(scene.A.radius, scene.B.radius)
    if not scene.element_length >= MIN_BEM_ELEMENT_RATIO * smaller:
        raise InputError("contact.model", f"'bem' needs strip elements of at least {MIN_BEM_ELEMENT_RATIO:g} × the "
                                          f"smaller radius, got {scene.element_length:.3g} on radius {smaller:g} "
                                          f"(a_H/R = {scene.a_H / scene.R:.3g}); a contact this small is a half-space "
                                          f"contact: use model = 'halfspace'")
    for key, body in (("bodies.A", scene.A), ("bodies.B", scene.B)):
        if body.shaft_radius is None:
            raise InputError(f"{key}.shaft_radius", "is required when contact.model = 'bem' (the "
                                                    f"rigid shaft's radius, in (0, {body.radius!r}))")
        if not 2.0 * scene.half_width < math.pi * body.radius:
            raise InputError("discretization.zone",
                             f"the strip (2L = {2 * scene.half_width:.6g}) must be shorter than half the "
                             f"circumference of {key} (radius {body.radius!r}) for model = 'bem'")


def bem_rows(m: dict) -> list[tuple[str, str]]:
    """A BEM run's summary rows from its ``meta["model"]``: assembly cost, geometric coupling, asymmetry of F·A
    (docs/bem.md)."""
    cost = ("cached (the same rollers built before with this memo)" if m.get("bem_cached") else
            f"{m.get('bem_seconds', float('nan')):.3f} s assembly + condensation")
    return [("BEM", f"{cost}, {m.get('bem_memory_bytes', 0) / 2 ** 20:.1f} MiB per body system; "
                    f"{m.get('bem_outer_elements')} outer + {m.get('bem_inner_elements')} shaft elements"),
            ("BEM coupling", f"geometric A_nt/A_tn {m.get('geometric_coupling')} "
                             f"(|F A_nt|/|F A_nn| = {m.get('coupling_size', float('nan')):.2e})"),
            ("BEM asymmetry", f"|FA - (FA)^T|/|FA| = {m.get('asymmetry_FA', float('nan')):.2e} (A_nn), "
                              f"{m.get('asymmetry_FAtt', float('nan')):.2e} (A_tt); operator {m.get('operator')}")]


HALFSPACE = Model("halfspace", halfspace_of, "elastic half-spaces (docs/formulation.md §3)",
                  keys=("contact.reference_distance", "contact.coupling"), operators=halfspace_operators_of)
#: Boussinesq–Cerruti on the rectangles of a grid (three dimensions, docs/theory3d.md §3–4).
HALFSPACE_3D = Model("halfspace", ContactOperators, "elastic half-spaces, Boussinesq–Cerruti on rectangles "
                     "(docs/theory3d.md §3)", dimensions=frozenset({3}))
BEM = Model("bem", bem_of, "true roller geometry on rigid shafts by BEM (docs/bem.md)",
            keys=("contact.bem_outer_elements", "contact.bem_inner_elements", "contact.coupling",
                  "bodies.A.shaft_radius", "bodies.B.shaft_radius"),
            check=check_bem_scene, profiles=False, halfspace_field=False, report=bem_rows, memo=True)
