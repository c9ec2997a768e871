"""The scene's derived quantities: E*, R, β, the Hertz scales, the strip and the steps, the loads at q.

:class:`Derived` is the part of :class:`~rollqp.scene.Scene` computed from its keys (a mixin: the
scene's fields are read as ``self.A``, ``self.load``, …). One formula each: the Hertz half-width
and peak pressure are :func:`rollqp.closedforms.hertz_half_width` and
:func:`~rollqp.closedforms.hertz_peak_pressure`, as everywhere in rollqp.
"""
from __future__ import annotations

import functools
import math

import numpy as np

from ..errors import InputError
from ..methods import record
from .schema import BETA_ZERO
from ..closedforms import hertz_half_width
from ..closedforms import hertz_peak_pressure

__all__ = ["Derived"]


class Derived:
    """Derived quantities of a scene (module docstring); the scene's units throughout.

    The scalars a step reads (E*, R, β, a_H, p0, L, Le, Δq) are computed once per scene and kept
    (``functools.cached_property``: a Scene is immutable, and its checks read them only after
    every field is normalized); a small run reads them thousands of times.
    """

    @property
    def q_end(self) -> float:
        """Last rolled distance the loads are evaluated at, in units of a_H.

        ``max(distance, n_steps·Δq/a_H)``: the last step may overshoot ``distance`` by less
        than one step when ``distance`` is not a whole number of steps.
        """
        return max(self.discretization.distance, self.n_steps * self.dq / self.a_H)

    @property
    def method_capabilities(self):
        """What the scene's ``solver.method`` declares (:class:`~rollqp.methods.base.Capabilities`, asked of the
        method registry by name): whether it needs the influence matrix, what it solves."""
        return record(self.solver.method).capabilities

    @property
    def bem_mesh(self) -> tuple[int, int]:
        """``(outer, inner)`` BEM element counts per roller (defaults 19, 16; docs/bem.md)."""
        # one place for the paper's counts, in the BEM module (numpy.polynomial and scipy.linalg behind it: import
        # rollqp stays light)
        from ..influence.bem import DEFAULT_INNER, DEFAULT_OUTER
        c = self.contact
        return (DEFAULT_OUTER if c.bem_outer_elements is None else c.bem_outer_elements,
                DEFAULT_INNER if c.bem_inner_elements is None else c.bem_inner_elements)

    # ------------------------------------------------------------------ derived quantities
    @functools.cached_property
    def Estar(self) -> float:
        """Contact modulus E*, 1/E* = (1 − ν_A²)/E_A + (1 − ν_B²)/E_B (plane strain)."""
        A, B = self.A, self.B
        return 1.0 / ((1.0 - A.nu ** 2) / A.E + (1.0 - B.nu ** 2) / B.E)

    @functools.cached_property
    def R(self) -> float:
        """Relative radius R, 1/R = 1/R_A + 1/R_B."""
        return 1.0 / (1.0 / self.A.radius + 1.0 / self.B.radius)

    @functools.cached_property
    def beta(self) -> float:
        """Dundurs' parameter (docs/formulation.md §3).

        β = ½[(1 − 2ν_A)/G_A − (1 − 2ν_B)/G_B] / [(1 − ν_A)/G_A + (1 − ν_B)/G_B];
        zero for similar materials, and it changes sign when A and B are swapped.
        """
        A, B = self.A, self.B
        num = (1.0 - 2.0 * A.nu) / A.G - (1.0 - 2.0 * B.nu) / B.G
        den = (1.0 - A.nu) / A.G + (1.0 - B.nu) / B.G
        return 0.5 * num / den

    @property
    def kappa(self) -> float:
        """κ = 2β: the paper's "constant" (eq. 92), Bentall–Johnson's κ."""
        return 2.0 * self.beta

    @functools.cached_property
    def a_H(self) -> float:
        """Hertz half-width for the reference load P̄: a_H = sqrt(4 P̄ R / (π E*))."""
        return hertz_half_width(self.load.normal, self.R, self.Estar)

    @functools.cached_property
    def p0(self) -> float:
        """Hertz peak pressure for P̄: p0 = 2 P̄ / (π a_H) = a_H E* / (2R)."""
        return hertz_peak_pressure(self.load.normal, self.a_H)

    @property
    def coupling_level(self) -> str:
        """Coupling level used: "full", "goodman" or "off" ("auto": "full" iff ``|β| > 1e-12``)."""
        c = self.contact.coupling
        if c == "auto":
            return "full" if abs(self.beta) > BETA_ZERO else "off"
        return c

    @property
    def leading_edge(self) -> int:
        """Sign of x where material enters the contact, −d (docs/formulation.md §1)."""
        return -self.load.direction

    @functools.cached_property
    def half_width(self) -> float:
        """Half-width of the potential contact zone, L = zone·a_H."""
        return self.discretization.zone * self.a_H

    @functools.cached_property
    def element_length(self) -> float:
        """Element length Le = 2L / elements."""
        return 2.0 * self.half_width / self.discretization.elements

    @functools.cached_property
    def dq(self) -> float:
        """Rolled distance per step, Δq = step·Le (length units)."""
        return self.discretization.step * self.element_length

    @property
    def n_steps(self) -> int:
        """Number of rolling steps K: distance·a_H/Δq, rounded if within 1e-9 of an integer
        (relative), else rounded up."""
        ratio = self.discretization.distance * self.a_H / self.dq
        r = round(ratio)
        return int(r) if abs(r - ratio) <= 1e-9 * ratio else int(math.ceil(ratio))

    @property
    def time_steps(self) -> np.ndarray:
        """The time-like parameter τ_k = k·Δq, k = 0 … K, shape (K + 1,), length units: the argument of
        the load histories (the rolled distance itself without ``load.rolled``)."""
        return np.arange(self.n_steps + 1) * self.dq

    @property
    def q_steps(self) -> np.ndarray:
        """Rolled distances q_k, k = 0 … K, shape (K + 1,), length units: k·Δq, or q(τ_k) with
        ``load.rolled`` (:mod:`rollqp.kinematics`)."""
        tau = self.time_steps
        return tau if self.load.rolled is None else self.rolled_distance(tau)

    def rolled_distance(self, tau):
        """q(τ) = a_H·rolled(τ/a_H) (length units); τ itself without ``load.rolled``."""
        if self.load.rolled is None:
            return np.asarray(tau, dtype=float)
        return self.a_H * np.asarray(self.load.rolled(np.asarray(tau, dtype=float) / self.a_H), dtype=float)

    @property
    def n_nodes(self) -> int:
        """Nodes of the strip: elements + 1 (linear), 2·elements + 1 (quadratic), elements (constant)."""
        d = self.discretization
        return {"constant": d.elements, "linear": d.elements + 1, "quadratic": 2 * d.elements + 1}[d.element]

    def memory_estimate(self) -> float:
        """Bytes a run needs at its peak: the dense n × n influence matrices with their working copies
        (six, measured at most five at assembly) and the result's five per-state arrays."""
        n, states = self.n_nodes, self.n_steps + 1
        return 8.0 * (6 * n * n + 6 * states * n)

    @property
    def reference_distance_value(self) -> float:
        """d_ref of the half-space kernel: ``contact.reference_distance``, or R if absent."""
        d = self.contact.reference_distance
        return self.R if d is None else d

    def normal_load(self, q):
        """Normal load P(q) = P̄·normal_history(q/a_H).

        Parameters
        ----------
        q : float or ndarray
            Rolled distance, length units.
        """
        return self.load.normal * self.load.normal_history(np.asarray(q, dtype=float) / self.a_H)

    def tangential_load(self, q):
        """Tangential load on body A, Q(q) = μ·P̄·tangential(q/a_H), at the rolled distance ``q``
        (length units); an :class:`~rollqp.errors.InputError` if the scene prescribes the creepage."""
        return self.contact.mu * self.load.normal * self._history("tangential", "creepage", q)

    def prescribed_creepage(self, q):
        """Prescribed creepage ξ(q) = creepage(q/a_H) at the rolled distance ``q`` (length units);
        an :class:`~rollqp.errors.InputError` if the scene prescribes the tangential load."""
        return self._history("creepage", "tangential", q)

    def _history(self, key: str, other: str, q):
        """``load.<key>`` at ``q/a_H``; an InputError if the scene prescribes ``load.<other>`` instead."""
        history = getattr(self.load, key)
        if history is None:
            raise InputError(f"load.{key}", f"not prescribed: this scene prescribes load.{other} instead")
        return history(np.asarray(q, dtype=float) / self.a_H)

    def prescribed_approach(self, q):
        """Prescribed approach δ(q) = approach(q/a_H) of the shaft centres, or None if P is given.

        Parameters
        ----------
        q : float or ndarray
            Rolled distance, length units.
        """
        if self.load.approach is None:
            return None
        return self.load.approach(np.asarray(q, dtype=float) / self.a_H)

