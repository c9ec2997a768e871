"""What a scene's transient needs that cannot change during it, built once: :class:`SceneOperators`.

The strip (docs/formulation.md §2), the influence operators (§3) as read-only
:class:`~rollqp.influence.operator.Operator`\\ s validated once, the undeformed gap, the scales of
the nondimensional form (§5), the history operators of the slip (§4) and the steady-rolling slip
operators (§9). Methods receive it once per scene (:meth:`Method.setup
<rollqp.methods.base.Method.setup>`); :func:`rollqp.march` asks it for each step's problem.

Only what the scene needs is built: coupling operators for the coupling level asked for, the
steady operators only for a direct steady rolling start, each history operator on first use.
"""
from __future__ import annotations

import functools
import math
import time
from dataclasses import dataclass, field

import numpy as np

from .. import matrixfree
from ..errors import InputError
from ..influence import Memo, get_model
from ..influence.operator import Operator, asymmetry
from ..influence.layer import strip_tangential
from ..problem import CoupledStep, FrictionBound, NormalStep, Scales, TangentialStep, _check_sliding_limit
from ..strip import RowSparse, Strip
from ..profiles import Profile
from ..friction import largest
from ..friction.bound import step_coefficient

__all__ = ["SceneOperators"]


@dataclass
class SceneOperators:
    """The fixed part of a scene's transient (module docstring); build with :meth:`build`.

    Attributes
    ----------
    scene : Scene
    strip : Strip
    Ann, Att : Operator
        Normal and tangential influence (eq. 25, 28); ``F⁻¹ sym(F A)`` of them when
        ``symmetrized``.
    Atn, Ant : Operator or None
        Coupling (``None``: absent at the scene's coupling level, docs/formulation.md §3).
    h : ndarray
        Undeformed gap at the nodes (eq. 10).
    scales : Scales
        ``a_H``, ``p0``, ``E*`` of the reference load.
    symmetrized : bool
        The QP operator ``F⁻¹ sym(F A)`` replaces ``A`` for the whole transient (history
        vectors included), so that every step's residual refers to one discrete model.
    info : dict
        The influence model's data and diagnostics, the measured asymmetries of ``F·A``,
        ``influence_seconds``, ``operator``.
    memo : Memo
        What is built once and kept for the scene (:class:`~rollqp.influence.memo.Memo`): the history and
        steady operators, and what the influence model keeps of the geometry (the BEM's roller compliances).
    """

    scene: object
    strip: Strip
    Ann: Operator
    Att: Operator
    Atn: Operator | None
    Ant: Operator | None
    h: np.ndarray
    scales: Scales
    symmetrized: bool = False
    info: dict = field(default_factory=dict)
    memo: Memo = field(default_factory=Memo, repr=False)

    def __post_init__(self):
        # the bound of the last step the march made, with the pressure and μ objects it is of (tangential_step)
        self._last_bound: tuple | None = None

    @classmethod
    def build(cls, scene, symmetrized: bool = False, capabilities=None, memo: Memo | None = None,
              geometry: Memo | None = None) -> "SceneOperators":
        """Discretize ``scene``; ``symmetrized`` selects the QP operator ``F⁻¹ sym(F A)``.

        ``capabilities``: the :class:`~rollqp.methods.base.Capabilities` of the method object that runs the
        scene (:func:`rollqp.march.prepare` passes them; default: those the scene's ``solver.method``
        declares): dense matrices, or FFT operators for a method that works with products only on a
        large half-space strip (:func:`rollqp.matrixfree.mode`). ``memo``: the scene's :attr:`memo` (default
        a new one; it keeps this scene's history and steady operators, so it is never shared between
        scenes). ``geometry``: where the influence model keeps what depends on the bodies alone (the
        BEM's rollers; default ``memo``); a caller that builds several scenes on the same bodies (a
        sweep's worker) may hand them one, so that it is built once."""
        d = scene.discretization
        memo = Memo() if memo is None else memo
        strip = Strip(scene.half_width, d.elements, d.element)
        if matrixfree.mode(scene, capabilities) == "matrix-free":
            return cls._build_matrix_free(scene, strip, memo).with_profiles()
        t0 = time.perf_counter()
        model = get_model(scene.contact.model)  # (rollqp.influence.Model)
        infl = model.build(scene, strip, memo=memo if geometry is None else geometry) if model.memo else model.build(scene, strip)
        f = strip.weights
        info = dict(infl.info)
        info["asymmetry_Ann"] = asymmetry(infl.Ann, f)
        info["asymmetry_Att"] = asymmetry(infl.Att, f)
        Ann = Operator(infl.Ann, "influence")
        layer = scene.contact.layer    # an interface layer's compliance h/G3 on A_tt's diagonal (eq. L.2)
        same = layer is None and (infl.Att is infl.Ann or np.array_equal(infl.Att, infl.Ann))
        Att = Ann if same else strip_tangential(Operator(infl.Att, "influence"), layer)
        if symmetrized:
            Ann = Ann.split(f).sym
            Att = Ann if same else Att.split(f).sym
        info["influence_seconds"] = time.perf_counter() - t0
        info["operator"] = "symmetrized" if symmetrized else "collocation"
        Atn, Ant = (None if M is None else Operator(M, "influence") for M in (infl.Atn, infl.Ant))
        ops = cls(scene=scene, strip=strip, Ann=Ann, Att=Att, Atn=Atn, Ant=Ant, h=infl.h,
                  scales=Scales(scene.a_H, scene.p0, scene.Estar), symmetrized=symmetrized, info=info, memo=memo)
        return ops.with_profiles()

    def with_profiles(self) -> "SceneOperators":
        """This object with :attr:`h` the profiles' gap at q(0) (:mod:`rollqp.profiles`; dense or matrix-free)."""
        if self.scene.A.profile is not None or self.scene.B.profile is not None:
            self.h = self.gap(float(self.scene.rolled_distance(0.0)))
        return self

    # ------------------------------------------------------------ geometry
    @property
    def profiles_move(self) -> bool:
        """A body's profile has a feature attached to its material: the gap changes as it rolls."""
        return any(b.profile is not None and b.profile.moves for b in (self.scene.A, self.scene.B))

    def gap(self, q: float) -> np.ndarray:
        """Undeformed gap ``h = z_A(x) + z_B(x)`` after the rolled distance ``q`` (eq. 10; :mod:`rollqp.profiles`).

        The material of both bodies has moved by ``d·q`` (``d`` = ``load.direction``); a scene of
        two circles has the influence model's own gap (:attr:`h`), whatever ``q``.
        """
        sc = self.scene
        if sc.A.profile is None and sc.B.profile is None:
            return self.h
        x, shift = self.strip.x, sc.load.direction * float(q)
        h = 0.0
        for body in (sc.A, sc.B):
            prof = body.profile if body.profile is not None else Profile(body.radius)
            h = h + prof.gap(x, shift)
        h = np.asarray(h, dtype=float)
        h.setflags(write=False)
        return h

    @classmethod
    def _build_matrix_free(cls, scene, strip, memo) -> "SceneOperators":
        """FFT operators on the uniform strip (:mod:`rollqp.matrixfree`; docs/matrix-free.md)."""
        t0 = time.perf_counter()
        Ann, Att, Atn, Ant, h, info = matrixfree.build(scene, strip)
        Att = strip_tangential(Att, scene.contact.layer)
        info["influence_seconds"] = time.perf_counter() - t0
        info["operator"] = "collocation"
        return cls(scene=scene, strip=strip, Ann=Ann, Att=Att, Atn=Atn, Ant=Ant, h=h,
                   scales=Scales(scene.a_H, scene.p0, scene.Estar), info=info, memo=memo)

    @property
    def matrix_free(self) -> bool:
        """The influence operators are FFT products (no stored matrices; sparse slip operators)."""
        return self.info.get("operator_mode") == "matrix-free"

    @property
    def f(self) -> np.ndarray:
        """Integration weights ``f_j = ∫ N_j`` (eq. 65–67)."""
        return self.strip.weights

    @property
    def n(self) -> int:
        return self.strip.n

    @property
    def coupled(self) -> bool:
        """Full coupling (``A_nt`` present): each step is one :class:`CoupledStep`."""
        return self.Ant is not None

    @functools.cached_property
    def mu(self) -> float:
        """The reference coefficient (Coulomb's ``μ`` itself; :attr:`Contact.mu <rollqp.scene.Contact.mu>`), one
        float object for the whole scene (a step problem's bound is kept while its ``p`` and ``μ`` are the same
        objects: :meth:`tangential_step`)."""
        return self.scene.contact.mu

    @property
    def friction(self):
        """The scene's friction law (:class:`rollqp.friction.FrictionLaw`)."""
        return self.scene.contact.friction

    @property
    def frictionless(self) -> bool:
        """``μ = 0`` everywhere, whatever the slip (the law's largest value is 0)."""
        return largest(self.friction) == 0.0

    def step_friction(self, q=0.0, dq=None, previous=None, steady=False):
        """``(mu, law)`` of a step at the rolled distance ``q`` (:func:`rollqp.friction.bound.step_coefficient`):
        the number ``μ`` and ``None`` for Coulomb (the constant bound's path)."""
        sc, a = self.scene, self.scales.length
        return step_coefficient(self.friction, self.strip.x / a, q / a, sc.load.direction,
                                dq_hat=None if dq is None else dq / a, previous=previous, steady=steady)

    # ------------------------------------------------------------ slip operators
    def history(self, formulation: str | None = None, dq: float | None = None,
                direction: int | None = None):
        """``M`` with the history vector ``c^{k−1} = −M w^{k−1}`` (eq. 37, 48), built once per argument set.

        At most three non-zeros a row, stored so (:class:`~rollqp.strip.RowSparse`; ``scipy.sparse``
        on the matrix-free path): a product costs ``O(n)``, not the dense ``O(n²)``.

        The defaults are the scene's own: ``discretization.formulation``, ``Δq`` and ``load.direction``.
        """
        sc = self.scene
        formulation = sc.discretization.formulation if formulation is None else formulation
        dq = sc.dq if dq is None else dq
        direction = sc.load.direction if direction is None else direction
        key = ("history", formulation, float(dq), int(direction))
        return self.memo.get(key, lambda: self.build_history(formulation, dq, direction))

    def build_history(self, formulation: str, dq: float, direction: int):
        """A new history operator ``M`` (eq. 37, 48), not kept: sparse rows on either path (scipy.sparse,
        built without a matrix, on the matrix-free path; :class:`~rollqp.strip.RowSparse` on the dense one).
        :meth:`history` keeps the scene's; a load path's variable steps keep theirs in a bounded cache
        (:class:`rollqp.kinematics.HistoryCache`)."""
        if self.matrix_free:
            return matrixfree.sparse_history(self.strip, formulation, dq, direction)
        return RowSparse.from_dense(self.strip.history_operator(formulation, dq, direction))

    def steady(self) -> tuple[Operator | None, Operator]:
        """``(Δ·T·A_tn, Δ·T·A_tt)`` with ``Δ = a_H``: the steady slip operators, built once.

        ``T`` (:meth:`Strip.steady_operator <rollqp.strip.Strip.steady_operator>`) is the fixed point of
        the scene's own transient step, ``(I − M)/Δq`` with the history operator ``M`` of its
        formulation, ``Δq`` and direction: ``d·D_up`` for ``convective-local``, ``(I − R)/Δq`` for
        ``material``. With ``dq = Δ`` and ``c = 0`` the step problems' slip ``ξ e + (c + A_tn p + A_tt
        t)/dq`` is then the steady slip ``ξ e + T w`` (docs/formulation.md §4, §9), and a march from the
        steady state stays there.
        """
        return self.memo.get("steady", self._build_steady)

    def _build_steady(self) -> tuple[Operator | None, Operator]:
        if self.matrix_free:   # products, no matrix (rollqp.matrixfree)
            return matrixfree.steady_operators(self)
        sc = self.scene
        T = self.scales.length * self.strip.steady_operator(sc.load.direction, sc.discretization.formulation, sc.dq)
        Atn = None if self.Atn is None else Operator(T @ self.Atn.dense(), "steady A_tn")
        return Atn, Operator(T @ self.Att.dense(), "steady A_tt")

    # ------------------------------------------------------------ step problems
    def normal_step(self, P, t=None, delta=None, h=None, validate=True) -> NormalStep:
        """The normal step (eq. 53): load ``P`` (or approach ``delta``), shear ``t`` fixed; ``h``: the
        undeformed gap of the step (default :attr:`h`; a moving profile's :meth:`gap`).

        ``validate=False`` (rollqp.march): the values are the scene's validated data and the method's
        checked solutions, and the step is made with ``trusted=True`` (not checked again)."""
        offset = None if (self.Ant is None or t is None) else self.Ant @ t
        h = self.h if h is None else h
        if not validate:
            if offset is not None:
                _finite("t", offset)
            return NormalStep(A=self.Ann, f=self.f, h=h, P=_float(P), delta=_float(delta), offset=offset,
                              scales=self.scales, trusted=True)
        return NormalStep(A=self.Ann, f=self.f, h=h, P=P, delta=delta, offset=offset, scales=self.scales)

    def tangential_step(self, p, c, dq, Q=None, xi=None, steady=False, friction=None, validate=True) -> TangentialStep:
        """The tangential step (eq. 61/62) at the pressure ``p``; ``steady``: the steady slip operators;
        ``friction``: ``(mu, law)`` of the step (:meth:`step_friction`; default the scene's Coulomb ``μ``);
        ``validate`` as for :meth:`normal_step` (the sliding limit, which depends on ``p``, is checked
        either way)."""
        Atn, Att = self.steady() if steady else (self.Atn, self.Att)
        if Atn is not None:
            c = c + Atn @ p
        mu, law = (self.mu, None) if friction is None else friction
        if validate:
            return TangentialStep(A=Att, f=self.f, p=p, mu=mu, c=c, dq=dq, Q=Q, xi=xi, scales=self.scales, law=law)
        _finite("c", c)
        last = self._last_bound  # (p, μ, FrictionBound, sliding limit) of the last march-built step
        if last is not None and last[0] is p and last[1] is mu and law is None:
            # the same pressure (a fixed normal half) and μ: the same bound, handed to the step (the fields in
            # their order: keywords cost as much as the construction)
            pb = TangentialStep(Att, self.f, p, mu, c, float(dq), _float(Q), _float(xi), self.scales, None, True, last[2])
            _check_sliding_limit(pb, last[3])
        else:
            pb = TangentialStep(A=Att, f=self.f, p=p, mu=mu, c=c, dq=float(dq), Q=_float(Q), xi=_float(xi),
                                scales=self.scales, law=law, trusted=True)
            _finite("p", pb.bound)
            if law is None:
                self._last_bound = (p, mu, FrictionBound(pb.bound, pb.bound_hat), _check_sliding_limit(pb))
            else:
                _check_sliding_limit(pb)
        return pb

    def coupled_step(self, P, c, dq, Q=None, xi=None, steady=False, delta=None, h=None,
                     friction=None) -> CoupledStep:
        """The coupled step (docs/formulation.md §10); ``steady``: the steady slip ``s = ξ e + T w`` (:meth:`steady`); ``h`` as
        for :meth:`normal_step`; ``friction`` as for :meth:`tangential_step`."""
        Atn, Att = self.steady() if steady else (self.Atn, self.Att)
        mu, law = (self.mu, None) if friction is None else friction
        return CoupledStep(Ann=self.Ann, Att=Att, Ant=self.Ant, Atn=Atn, f=self.f, h=self.h if h is None else h,
                           mu=mu, c=c, dq=dq, P=P, Q=Q, xi=xi, delta=delta, scales=self.scales, law=law)

    def w(self, p, t, At=None) -> np.ndarray:
        """Relative tangential displacement ``w = A_tn p + A_tt t`` (eq. 28); ``At``: ``A_tt t`` if known."""
        out = self.Att @ t if At is None else At
        return out if self.Atn is None else out + self.Atn @ p

    def check_inside(self, p, step: int):
        """The contact must not reach the ends of the potential contact zone (docs/formulation.md §1)."""
        ends = (p[0], p[-1])
        if max(ends) > 1e-8 * self.scales.stress:
            raise InputError("discretization.zone",
                             f"the contact reaches the edge of the zone at step {step} "
                             f"(p/p0 = {max(ends) / self.scales.stress:.2e} at an end node): increase zone "
                             f"(now {self.scene.discretization.zone})")


def _finite(name, v) -> None:
    """The one check a march-built step keeps on the arrays it takes from the last step's solution:
    finite (one sum: a NaN or an infinity makes it non-finite), else the InputError a validated step
    would raise."""
    if not math.isfinite(float(np.add.reduce(v))):  # (the ufunc: np.sum's dispatch costs more)
        raise InputError(name, "must be finite (the last step's solution was not)")


def _float(v):
    """A load, approach or creepage of a march-built step as a float (``None`` kept): what
    ``__post_init__`` would store."""
    return None if v is None else float(v)
