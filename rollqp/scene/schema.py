"""The scene's schema: plain, frozen records of one rolling-contact problem and the allowed values.

No validation happens here (:mod:`.checks` does it, with the dotted keys); these are the parts of
a :class:`~rollqp.scene.Scene` — two bodies, the contact law, the loads, the discretization, the
solver — with their documented keys, units and defaults (docs/scenes.md).
"""
from __future__ import annotations

from dataclasses import dataclass

from ..histories import Constant, History
from ..influence import DEFAULT_MODEL, model_names
from ..methods import DEFAULT_METHOD, METHOD_NAMES

METHODS = METHOD_NAMES  # the method registry's built-in names (rollqp.methods; names are checked there)
MODELS = model_names()  # the built-in influence models (rollqp.influence; names are checked there)
COUPLINGS = ("auto", "full", "goodman", "off")
STARTS = ("braked", "rolling")
ELEMENT_TYPES = ("constant", "linear", "quadratic")
FORMULATION_TYPES = ("material", "convective-local")

#: ``|β|`` above which ``coupling = "auto"`` means full coupling
BETA_ZERO = 1e-12
#: free elements required between the largest contact and each end of the zone
EDGE_ELEMENTS = 1.5
#: largest ``discretization.step`` (Δq/Le) of the convective-local formulation: the node
#: spacing h/Le (:meth:`Scene._check_convective_step`)
CONVECTIVE_STEP_MAX = {"constant": 1.0, "linear": 1.0, "quadratic": 0.5}
#: allowed ``solver.augmentation`` (nondimensional r): the band in which newton converged on
#: every hard case (docs/stability.md, ``python benchmarks/hard_cases.py --only "r="``)
AUGMENTATION_MIN, AUGMENTATION_MAX = 1e-6, 10.0


#: largest number of nodes of a dense strip (its n × n influence matrices: 3.2 GB each at the limit)
MAX_NODES = 20001
#: largest number of elements (the dense path stops at MAX_NODES nodes; the matrix-free one here)
MAX_ELEMENTS = 1_000_000
OPERATOR_MODES = ("auto", "dense", "matrix-free")
#: largest number of rolling steps of a scene (a result of 10^6 states of 81 nodes is 3 GB)
MAX_STEPS = 1_000_000
#: largest number of increments of a braked start
MAX_START_STEPS = 100_000

# =========================================================================== parts
@dataclass(frozen=True)
class Body:
    """One elastic cylinder.

    Parameters
    ----------
    radius : float
        Outer radius R_A or R_B, ``> 0``.
    E : float
        Young's modulus, ``> 0``.
    nu : float
        Poisson's ratio, in (−1, 0.5).
    shaft_radius : float or None
        Inner (shaft) radius of the annular cylinder, in (0, radius); used by
        ``contact.model = "bem"`` only. None: not given.
    profile : Profile or None
        The body's undeformed shape (:mod:`rollqp.profiles`: a contact-frame table, flats,
        defects, material tables); None: the circle of ``radius``.
    wear : float or None
        Archard's wear coefficient over hardness, k/H (1/stress, ``>= 0``): the worn depth rate is
        ``(k/H)·p·|s|`` per unit rolled distance (docs/stresses.md §6). None: no wear modelled.
    """

    radius: float
    E: float
    nu: float
    shaft_radius: float | None = None
    profile: object = None
    wear: float | None = None

    @property
    def G(self) -> float:
        """Shear modulus G = E / (2(1 + ν))."""
        return self.E / (2.0 * (1.0 + self.nu))


@dataclass(frozen=True)
class Contact:
    """Contact law and elastic model.

    Parameters
    ----------
    friction : float or FrictionLaw
        Coulomb coefficient μ, finite and ``>= 0``; or a law of :mod:`rollqp.friction`
        (``[contact.friction]`` table: a patch, a table μ(x), a slip-velocity law). A validated scene holds
        a :class:`~rollqp.friction.FrictionLaw` (Coulomb's law is also its number).
    model : str
        A registered influence model (:func:`rollqp.influence.model_names`): ``"halfspace"``, half-space
        influence (docs/formulation.md §3), or ``"bem"``, true geometry by BEM (docs/bem.md).
    coupling : {"auto", "full", "goodman", "off"}
        Normal–tangential coupling level (§3); "auto" is "full" iff β ≠ 0, else "off".
    reference_distance : float or None
        d_ref of the 2D half-space kernel ``−ln(|x − s|/d_ref)``, ``> 0``; None: the relative
        radius R (see :attr:`Scene.reference_distance_value`).
    bem_outer_elements, bem_inner_elements : int or None
        ``model = "bem"``: elements on each roller's outer circle outside the strip and on its
        shaft, in [3, 2000]; None: the paper's 19 and 16 (docs/bem.md).
    layer : Layer or None
        An interface layer between the bodies, ``{ thickness = h, shear_modulus = G3 }``: its compliance
        ``h/G3`` joins the tangential influence (:mod:`rollqp.influence.layer`); None: none.
    """

    friction: float
    model: str = DEFAULT_MODEL
    coupling: str = "auto"
    reference_distance: float | None = None
    bem_outer_elements: int | None = None
    bem_inner_elements: int | None = None
    layer: object = None

    @property
    def mu(self) -> float:
        """The reference coefficient (the number itself for Coulomb; :func:`rollqp.friction.reference`):
        ``load.tangential`` is ``Q/(μ P̄)`` with it."""
        return float(self.friction.reference)


@dataclass(frozen=True)
class Load:
    """Loads and start, as histories of the rolled distance q/a_H.

    Parameters
    ----------
    normal : float
        Reference normal load P̄ per unit length, ``> 0``; defines a_H and p0.
    normal_history : History
        P(q) = P̄·normal_history(q/a_H); must stay >= 0 (0: out of contact).
    tangential : History or None
        Q(q) = μ·P̄·tangential(q/a_H) on body A (Q/(μP̄), P̄ the reference load).
    creepage : History or None
        Prescribed creepage ξ(q) = creepage(q/a_H) instead of Q. Exactly one of
        ``tangential`` and ``creepage`` is set in a validated scene (neither given:
        tangential constant 0).
    start : {"braked", "rolling"}
        Braked start (Hertz then Cattaneo, docs/formulation.md §9) or steady rolling.
    direction : {-1, +1}
        d = sgn(V), the direction of the material through the contact (paper: −1).
    start_steps : int
        Quasi-static steps applying the normal load of a braked start, ``>= 1``.
    approach : History or None
        Prescribed approach of the shaft centres δ(q) = approach(q/a_H) (length units) instead
        of the normal load (the normal-side analogue of ``creepage``); ``normal`` stays the
        reference load P̄ of a_H, p0 and the zone. Meaningful with ``contact.model = "bem"``
        (rigid shafts); on the half-space δ depends on ``reference_distance`` (docs/bem.md).
    rolled : History or None
        Kinematics as a history (:mod:`rollqp.kinematics`): the rolled distance
        q(τ) = a_H·rolled(τ/a_H) of the time-like parameter τ, which then steps by Δτ = step·Le
        up to ``distance`` and is the argument of every load history. Increasing q rolls in
        ``direction``, decreasing q reverses, a constant q stops (static shift steps). None: τ = q.
    """

    normal: float                                # P̄, the reference load
    normal_history: History = Constant(1.0)      # P(q)/P̄
    tangential: History | None = None            # Q(q)/(μP̄) …
    creepage: History | None = None              # … or ξ(q)
    start: str = "braked"
    direction: int = -1                          # d = sgn(V)
    start_steps: int = 1
    approach: History | None = None              # δ(q) instead of P(q)
    rolled: History | None = None                # q(τ)/a_H (None: τ = q)


@dataclass(frozen=True)
class Discretization:
    """Discretization of the strip and of the rolled distance (docs/formulation.md §2).

    Parameters
    ----------
    elements : int
        Elements on the potential contact zone [−L, L], in [2, 20000].
    element : {"constant", "linear", "quadratic"}
        Traction shape functions (the paper's QCE: "quadratic").
    zone : float
        L / a_H, ``> 1``.
    step : float
        Δq / Le, in (0, 8].
    formulation : {"material", "convective-local"}
        Time discretization of the slip (§4).
    distance : float
        Rolled distance / a_H, ``>= 0``.
    """

    elements: int = 40
    element: str = "quadratic"
    zone: float = 1.25
    step: float = 0.5
    formulation: str = "material"
    distance: float = 6.0


@dataclass(frozen=True)
class SolverSettings:
    """The step solver.

    Parameters
    ----------
    method : str
        One of :data:`METHODS`.
    tolerance : float
        Nondimensional residual tolerance, in [1e-15, 1e-2].
    max_iterations : int or None
        Iteration limit per step, ``>= 1``: Newton iterations (``newton``; each half of
        ``nt-newton``), outer N–T iterations (``nt-newton``, and the QP methods on a coupled
        scene), and the QP solver's own iterations per QP (the ``qp-*`` and ``qps-*`` methods).
        None (default): each method's own limit (Newton 200, N–T 200 outer iterations, the QP
        solvers' defaults).
    augmentation : float or None
        The Newton methods' nondimensional augmentation ``r`` of ``min(p, r g)`` and
        ``Proj(t − r s)`` (docs/formulation.md §4), the same for the normal and the tangential rows,
        in [:data:`AUGMENTATION_MIN`, :data:`AUGMENTATION_MAX`] (the band in which ``newton``
        converges on every hard case, docs/stability.md). None (default): automatic,
        ``1/mean(diag Â)`` (normal) and ``Δq̂/mean(diag Â)`` (tangential), see
        :mod:`rollqp.methods.newton`. Ignored by the QP methods. The solution does not depend
        on ``r``, only the Newton path does.
    operator : {"auto", "dense", "matrix-free"} or None
        Influence operators as dense matrices or as FFT products on the uniform half-space strip
        (docs/matrix-free.md); "auto" (or None, the default): matrix-free for the methods that
        work with products only (``mf-newton``) from :data:`rollqp.matrixfree.THRESHOLD` nodes.
    """

    method: str = DEFAULT_METHOD
    tolerance: float = 1e-10
    max_iterations: int | None = None
    augmentation: float | None = None
    operator: str | None = None

