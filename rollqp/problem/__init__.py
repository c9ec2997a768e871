r"""Step problems and their solutions (docs/formulation.md §4–6; paper eq. 49–71).

A *step problem* is the data of one discrete step — influence matrices, weights, gap,
friction bound, loads, history vector — and nothing about how it is solved. A
*solution* carries the unknowns, the method that produced them, and residuals computed
here, by rollqp, independently of any solver's self-reported accuracy (the split of
``qpsolvers.Problem`` / ``qpsolvers.Solution``).

Sign convention (the project's, docs/formulation.md §1): ``p >= 0`` is the pressure, ``t`` the
tangential traction on body A in +x, ``g >= 0`` the deformed gap, ``s`` the slip of A
relative to B per unit rolled distance, ``δ`` the rigid approach, ``ξ`` the creepage.

Normal step (eq. 53 with the load equation eq. 67)::

    g = h + o − δ e + A p,      p >= 0, g >= 0, p·g = 0,      fᵀp = P   (or δ given)

with ``o = A_nt t̄`` the gap change due to a fixed shear (zero for similar materials).

Tangential step (eq. 61/62 with eq. 67)::

    s = ξ e + (c + A t) / Δq,   |t| <= μ p̄,  t = Proj_[−μp̄, μp̄](t − r s),   fᵀt = Q   (or ξ given)

with ``c`` the history vector (eq. 37, 48) plus ``A_tn p̄``.

Nondimensional form: lengths by ``a_H``, stresses by ``p0``. The elastic operator turns
a stress into a displacement through ``1/E*``, so gaps are measured in
``u0 = a_H p0 / E*`` and slips in ``p0 / E*``; this is the augmentation ``r = E*/p0``
(the reciprocal of the scaled influence coefficients' size) applied to ``g`` and ``s``.
The residuals (:class:`Residuals`) are the max-norms of

* Signorini:      ``min(p̂, ĝ)``                              (eq. 51–52),
* friction law:   ``t̂ − Proj_[−μp̂⁺, μp̂⁺](t̂ − ŝ)``             (eq. 60),
* load equations: ``(fᵀp − P)/(a_H p0)``, ``(fᵀt − Q)/(a_H p0)``  (eq. 67).

The package, one responsibility per module: :mod:`.scales` (the units), :mod:`.validation` (the
inputs' checks), :mod:`.normal`, :mod:`.tangential`, :mod:`.coupled` (the three step problems),
:mod:`.qp` (their convex QP, shared by the backends), :mod:`.solution` (solutions, residuals,
node states), :mod:`.state` (the state between two steps of the transient).
"""
from __future__ import annotations

from ..influence.operator import Operator, as_operator, asymmetry, split  # noqa: F401 - re-exported
from .coupled import CoupledStep
from .normal import NormalStep
from .qp import QPForm, qp_hessian, symmetrized
from .scales import Scales
from .solution import (SEPARATION, SLIP, STICK, Residuals, StepSolution, classify, compare,
                       friction_residual)
from .state import State
from .tangential import FrictionBound, TangentialStep
from .validation import MAX_MAGNITUDE, _check_sliding_limit  # noqa: F401 - used by rollqp.operators

__all__ = ["Scales", "State", "NormalStep", "TangentialStep", "FrictionBound", "CoupledStep", "QPForm", "StepSolution", "Residuals",
           "classify", "compare", "friction_residual", "qp_hessian", "symmetrized", "SEPARATION", "STICK", "SLIP",
           "MAX_MAGNITUDE"]
