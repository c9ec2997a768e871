r"""One 3D contact, built once: geometry, materials, grid, operators, scales (docs/theory3d.md §2–4).

:class:`Contact` is what every step of a 3D problem shares — the analog of the 2D project's
scene operators: the grid and its :class:`~rollqp.influence.grid.ContactOperators`, the
undeformed distance on the grid, the Hertz ellipse of the nominal load and the scales of the
residuals — and it makes the step problems of :mod:`rollqp.problem.grid`:

* :meth:`Contact.normal_step` (eq. 3D.14), with the shear's gap ``A_nt t`` for dissimilar bodies;
* :meth:`Contact.tangential_step` of a *shift* (eq. 3D.16 with no offset, ``Δq`` the length unit
  ``c``: ``ξ·c`` is the rigid shift), a *rolling* step (eq. 3D.16: the previous displacements at
  ``x − d·Δq``) or the *steady* state (eq. 3D.17).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..friction import as_law
from ..friction.bound import grid_coefficient
from ..profiles.surface import QuadraticProfile
from ..discretization.grid import Grid
from ..closedforms.hertz_ellipse import hertz
from ..influence import DEFAULT_MODEL, get_model
from ..influence.layer import parse_layer, with_layer
from ..problem.grid import NormalStep, Residuals, Scales, StepSolution, TangentialStep

__all__ = ["Contact", "Loads"]


@dataclass(frozen=True)
class Loads:
    """The tangential loading of a step: ``Fx`` or ``xi``, ``Fy`` or ``eta`` (exactly one of each
    pair), and the spin ``phi`` (1/length). Forces on body A, creepages of A relative to B; ``q`` the
    rolled distance of the step (length units: where a friction law along the surface is read)."""

    Fx: float | None = None
    xi: float | None = None
    Fy: float | None = None
    eta: float | None = None
    phi: float = 0.0
    q: float = 0.0


#: Below this coefficient of friction the tangential steps measure tractions in (mu / MU_REFERENCE) p0 instead of
#: p0 (:attr:`Contact.tangential_scales`): a method's tolerance then bounds the tractions' error by at most
#: MU_REFERENCE⁻¹ = 100 times the tolerance in mu p0, whatever mu. At and above it (every built-in scene) nothing
#: changes.
MU_REFERENCE = 0.01


class Contact:
    """The shared data of a 3D contact (module docstring).

    Parameters
    ----------
    grid : rollqp.discretization.grid.Grid
    materials : rollqp.materials.Materials
    curvatures : (float, float)
        ``(A, B)`` of eq. 3D.3 (for the Hertz ellipse and the default profile).
    FN : float
        The nominal normal force: the Hertz ellipse and the scales.
    mu : float or FrictionLaw
        Coulomb's coefficient of friction (``>= 0``), or a friction law along the surface
        (:class:`rollqp.friction.FrictionLaw` of kind ``"constant"`` or ``"spatial"``: ``μ`` at the grid's
        points, read at each step's rolled distance, :meth:`coefficient`). ``mu`` is then its reference.
    profile : callable, optional
        ``h(x, y)``, the undeformed distance; default ``A x² + B y²`` (the seam for
        non-Hertzian profiles).
    model : str
        The influence model (``contact.model``) of 3D scenes that builds the operators from the grid and
        the materials (:func:`rollqp.influence.get_model`; default the Boussinesq–Cerruti half-space).
    layer : rollqp.influence.layer.Layer or dict, optional
        An interface layer between the bodies (``contact.layer``): its compliance ``h/G₃`` joins the tangential
        operators (:mod:`rollqp.influence.layer`).

    Examples
    --------
    >>> from rollqp.materials import Materials
    >>> c = Contact.hertzian(Materials.from_young(210e3, 0.25, 210e3, 0.25), (1 / 60, 1 / 60), 1000.0, 0.3,
    ...                      elements=(20, 20))
    >>> round(c.ellipse.a, 4), c.grid.nx, c.ops.coupled
    (0.5857, 20, False)
    """

    def __init__(self, grid: Grid, materials, curvatures, FN: float, mu: float, profile=None,
                 model: str = DEFAULT_MODEL, layer=None):
        # a scene's law as it is, a number checked once here (as_law)
        law = as_law(mu)
        if law.kind not in ("constant", "spatial", "slip"):
            raise InputError("contact.friction", f"a 3D contact takes a law of kind 'constant', 'spatial' or 'slip'; "
                                                 f"law {law.law!r} is of kind {law.kind!r}")
        self.law = law
        self.grid, self.materials, self.mu = grid, materials, law.mu if law.kind == "constant" else float(law.reference)
        self.ellipse = hertz(curvatures[0], curvatures[1], materials.Estar, FN)
        self.profile = profile if profile is not None else QuadraticProfile(*curvatures)
        self.scales = Scales.ellipse(self.ellipse)
        # the tangential steps' units: tractions in p0, and in (mu / MU_REFERENCE) p0 where friction is smaller, so
        # that a method's tolerance stays a fraction of mu p0 (at mu = 1e-6 a tolerance in p0 would allow tractions
        # beyond mu p by 1e-4 mu p0)
        f = min(1.0, self.mu / MU_REFERENCE) if self.mu > 0 else 1.0
        self.tangential_scales = self.scales if f == 1.0 else Scales(self.scales.length, self.scales.stress * f,
                                                                     self.scales.modulus, dimension=3)
        self.layer = parse_layer(layer)
        self.ops = with_layer(get_model(model, "contact.model", dimension=3).build(grid, materials), self.layer)
        self.x, self.y = grid.centres()
        self.record = grid.record()   # the points, weights and components a law or a field reads
        h = np.asarray(self.profile(self.x, self.y), dtype=float)
        if h.shape != (grid.n,) or not np.all(np.isfinite(h)):
            raise InputError("profile", f"h(x, y) must give finite values of shape ({grid.n},)")
        self.h = h

    @classmethod
    def hertzian(cls, materials, curvatures, FN: float, mu: float, elements=(40, 40), zone=(1.25, 1.25)):
        """The grid of ``elements`` on ``zone·(a, b)`` around the Hertz ellipse of ``FN`` (SPEC's
        ``discretization.elements`` and ``zone``); the ellipse must lie inside its outer rows of elements."""
        e = hertz(curvatures[0], curvatures[1], materials.Estar, FN)
        grid = Grid.for_ellipse(e.a, e.b, elements, zone)
        if not grid.covers(e.a, e.b):
            raise InputError("discretization.zone", f"the grid must cover the Hertz ellipse with its outer rows of "
                                                    f"elements to spare: zone {tuple(zone)} on {tuple(elements)} elements does not")
        return cls(grid, materials, curvatures, FN, mu)

    # ------------------------------------------------------------------ step problems
    def normal_step(self, FN: float, t=None) -> NormalStep:
        """The normal step of eq. 3D.14; ``t`` (``(2, n)``) the shear whose gap ``A_nt t`` it sees."""
        offset = None
        if self.ops.coupled and t is not None:
            offset = self.ops.Ant @ np.asarray(t, dtype=float).ravel()
        return NormalStep(self.ops.Ann, self.grid.area, self.h, FN=FN, offset=offset, scales=self.scales)

    def tangential_step(self, kind: str, p, loads: Loads, previous=None, dq=None, direction: int = -1):
        """The tangential step of eq. 3D.15 with the pressure ``p`` (bound ``μ p⁺``).

        ``kind``: ``"shift"`` (``Δq = c``, history ``−u'(x)``), ``"rolling"`` (history
        ``−u'(x − d Δq)``, eq. 3D.16) or ``"steady"`` (eq. 3D.17, ``Δq = dx``); ``previous`` is
        ``(p', t')`` of the last step (zero tractions if ``None``), or ``(p', t', μ')`` with the coefficient
        ``μ'`` the last step left at the elements (a slip-velocity law's memory, :meth:`slip_bound`).
        """
        p = np.asarray(p, dtype=float)
        ops, g = self.ops, self.grid
        if kind == "steady":
            B, dq = ops.steady("tt", direction), g.dx
            c = np.zeros(2 * g.n) if not ops.coupled else ops.steady("tn", direction) @ p
        elif kind in ("shift", "rolling"):
            B = ops.Att
            if kind == "shift":
                dq, off = self.scales.length, 0.0
            else:
                if dq is None or not dq > 0:
                    raise InputError("discretization.step", f"a rolling step needs Δq > 0, got {dq!r}")
                off = -direction * float(dq)
            c = np.zeros(2 * g.n) if not ops.coupled else ops.Atn @ p
            if previous is not None:
                pp, tp = (np.asarray(v, dtype=float) for v in previous[:2])
                c = c - (ops.Att if off == 0 else ops.shifted("tt", off)) @ tp.ravel()
                if ops.coupled:
                    c = c - (ops.Atn if off == 0 else ops.shifted("tn", off)) @ pp
        else:
            raise InputError("kind", f"must be 'shift', 'rolling' or 'steady', got {kind!r}")
        if self.law.kind == "slip":
            memory = previous[2] if previous is not None and len(previous) > 2 else None
            law = self.slip_bound(kind, dq, direction, memory)
            return TangentialStep(B, g.area, law.mu(np.zeros((2, g.n))) * np.maximum(p, 0.0), self.x, self.y,
                                  c.reshape(2, g.n), dq, Fx=loads.Fx, xi=loads.xi, Fy=loads.Fy, eta=loads.eta,
                                  phi=loads.phi, scales=self.tangential_scales, p=p, law=law)
        bound = self.bound(p, loads.q, direction)
        return TangentialStep(B, g.area, bound, self.x, self.y, c.reshape(2, g.n), dq, Fx=loads.Fx, xi=loads.xi,
                              Fy=loads.Fy, eta=loads.eta, phi=loads.phi, scales=self.tangential_scales)

    def slip_bound(self, kind: str, dq=None, direction: int = -1, memory=None):
        """The :class:`~rollqp.friction.bound.SlipBound` of a slip-velocity law for a step of ``kind``: ``μ(V|s_i|)``
        with the memory ``memory`` (the coefficient the last step left at the elements, ``(n,)``; ``None``: the
        static value) carried with the material by a rolling step's ``Δq`` (in units of ``a``, the Hertz
        semi-axis along x, the unit of the law's ``memory``); a shift step moves nothing (its memory relaxes in
        place), a steady solve cannot carry a memory (InputError) (:func:`rollqp.friction.bound.grid_coefficient`)."""
        a = self.ellipse.a
        dq_hat = float(dq) / a if kind == "rolling" else None
        if memory is not None and np.shape(memory) != (self.grid.n,):
            memory = None      # a state without the law's memory (a start, a resumed state): the static value
        _, law = grid_coefficient(self.law, self.grid.x / a, self.grid.shape, dq_hat=dq_hat, direction=direction,
                                  previous=memory, steady=kind == "steady")
        return law

    def coefficient(self, q: float = 0.0, direction: int = -1):
        """``μ`` at the grid's points at the rolled distance ``q``: the number ``mu`` for a constant law, else
        the law's ``coefficient`` at the element centres ``(x, y)/a`` (``a`` the Hertz semi-axis along x,
        the unit of the scene's distances) and ``q/a`` (:class:`rollqp.friction.FrictionLaw`)."""
        if self.law.kind == "constant":
            return self.mu
        if self.law.kind == "slip":   # at rest (the static value); a step's own: its law at its slip
            return float(self.law.steady(0.0)[0])
        a = self.ellipse.a
        mu = np.asarray(self.law.coefficient(self.record.points / a, float(q) / a, direction), dtype=float)
        if mu.shape != (self.grid.n,) or not np.all(np.isfinite(mu) & (mu >= 0)):
            raise InputError("contact.friction", f"law {self.law.law!r} must give a finite μ >= 0 at each of the "
                                                 f"{self.grid.n} elements, got shape {mu.shape}")
        return mu

    def bound(self, p, q: float = 0.0, direction: int = -1) -> np.ndarray:
        """The traction bound ``μ p⁺`` of the pressure ``p`` at the rolled distance ``q`` (eq. 3D.18)."""
        return self.coefficient(q, direction) * np.maximum(p, 0.0)

    def hertz_start(self, FN: float):
        """The Hertz pressure and approach of ``FN`` as a start for an iterative normal solve: the
        contact set is then nearly the discrete one (measured: Newton's normal step on a 100 × 100 grid
        in 2 iterations from it, 51 from a few elements in contact)."""
        e = hertz(self.ellipse.A, self.ellipse.B, self.materials.Estar, FN)
        return StepSolution(residuals=Residuals(), p=e.pressure(self.x, self.y), delta=e.delta)

    def moments(self, t) -> tuple[float, float, float]:
        """``(Fx, Fy, Mz)`` on body A of the tractions ``t`` (eq. 3D.2): ``Mz = Σ (x t_y − y t_x)·area``."""
        t = np.asarray(t, dtype=float).reshape(2, -1)
        a = self.grid.area
        return a * float(t[0].sum()), a * float(t[1].sum()), a * float(np.sum(self.x * t[1] - self.y * t[0]))
