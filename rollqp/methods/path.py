r"""The path of a slip-dependent step's solutions from the frozen bound (docs/friction.md, "Which solution of a step").

A step whose friction coefficient falls with the slip velocity can have several solutions. The one a
method returns is the end, at ``λ = 1``, of the curve of solutions of

.. math::
    H(\hat t, \hat\xi, \lambda) = \Phi_\lambda(\hat t, \hat\xi) = 0, \qquad
    \mu_\lambda(s) = (1 - \lambda)\,\mu_f + \lambda\,\mu(s),

through the solution at ``λ = 0`` (``Φ_λ``: the step's NCP form, eq. 60 with the bound ``μ_λ(s) p̂⁺``;
``μ_f`` the coefficients of the previous state). At ``λ = 0`` the bound does not depend on the unknowns and
the step is a convex QP: its solution is unique, so the curve is one curve, and it is followed by arclength
wherever it goes — back in ``λ`` past a fold and forward again — until it reaches ``λ = 1``.

**The pieces.** ``Φ_λ`` is smooth on each *piece*: every contact node either sticks (row ``ŝ_i = 0``, eq.
86/87) or slips in a direction ``σ_i`` (row ``t̂_i − σ_i μ_λ(s_i) p̂_i = 0``, eq. 88s) on one smooth piece of
the law (:attr:`~rollqp.friction.laws.SlipVelocity.kinks`); nodes outside the contact carry ``t̂_i = 0``
(eq. 85). A piece holds while its inequalities do (:meth:`FrozenBoundPath.margins`): a sticking node's traction
within its static bound, ``|t̂_i| <= μ_λ(0) p̂_i``; a slipping node's slip opposite to its traction, ``σ_i ŝ_i <=
0``, and its slip velocity on its piece of the law. The curve is followed one piece at a time (Allgower &
Georg, *Numerical Continuation Methods*, 1990, ch. 2 and 12): a predictor along the tangent, a Newton corrector
on the piece's smooth equations in the hyperplane normal to it, and where a margin of the new point is
negative, the point where it is zero (regula falsi on the step length); there the node changes piece and the
curve goes on along the new piece's tangent in the direction that enters it (the node's new margin grows).
A fold inside a piece is passed by the arclength parametrization; a fold at a change of piece by the direction
rule (a falling law's steepest steps turn back in ``λ`` at many such points).

Unknowns ``u = (t̂, ξ̂, λ)`` (``ξ̂`` when ``Q`` is prescribed) in the units of docs/formulation.md §5
(``t̂ = t/p0``, ``ŝ = s E*/p0``); the matrices are dense ``(N + 1)²`` with ``N = n + 1`` (the slip-dependent
Newton method's size, :mod:`rollqp.methods.newton.slip`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import SolverError

__all__ = ["FrozenBoundPath", "Piece", "follow", "PathStop"]

ZERO, STICK, SLIP = 0, 1, 2
#: Corrector: Newton iterations from the predictor before the step is halved, and its tolerance on ``|H|∞``
#: (``t̂`` and ``ŝ`` units; raised to 64 ε times the largest stick row's terms where round-off is larger).
CORRECTOR_ITERATIONS, CORRECTOR_TOLERANCE = 8, 1e-13
#: Step control (in the ``u`` norm, ``t̂`` ~ μ, ``λ`` in [0, 1]): first and largest step, the corrector's
#: largest distance from the predictor and the smallest cosine between successive tangents (a smaller angle
#: keeps the corrector on the branch it follows: with 0.5 and 0.9 the path jumped onto another branch of the
#: same step on docs/friction.md's ramped transient at v_h = 1 mm/s; so did a largest step of 1 with the
#: corrector's distance capped at 0.04, on the exponential law at v_h = 1 mm/s), and the step below which the
#: path stops.
FIRST_STEP, LARGEST_STEP, DISTANCE, COSINE, SMALLEST_STEP = 0.1, 0.2, 0.2, 0.95, 1e-10
#: Points (predictor–corrector steps and changes of piece) before the path is given up: about five times the
#: steepest steps of docs/friction.md's sweep (column "path points"); a step with no solution (a force above
#: the creep curve's peak) crawls at a small λ instead of ending, and is given up here.
MAX_POINTS = 3000
#: The edge of a piece is located to a margin in ``[0, EDGE]`` inside it (``t̂``/``ŝ`` units: ten times
#: the corrector's tolerance, so that a point that close is told from the edge); the search aims at the middle
#: of that window, ``EDGE_AIM``, so that its secant estimates land inside the piece, where it stops.
EDGE, EDGE_AIM = 1e-12, 0.5e-12
#: ``|ξ̂|`` beyond which the path runs into gross sliding (a creepage of 1e6 p0/E*: no stick zone is near).
XI_LIMIT = 1e6


class PathStop(SolverError):
    """The path from the frozen bound cannot be followed to ``λ = 1``; ``lam`` is the ``λ`` it reached."""

    def __init__(self, message, *, lam, residual=None, points=None):
        self.lam = float(lam)
        super().__init__(message, status="path stops", residual=residual, iterations=points)


@dataclass(frozen=True)
class Piece:
    """Which smooth piece of ``H`` holds: per node the case (0 outside the contact, 1 stick, 2 slip), the slip
    direction ``σ`` (the traction's sign; 0 unless slipping) and the piece of the law it slips on."""

    case: np.ndarray
    sign: np.ndarray
    segment: np.ndarray


class FrozenBoundPath:
    """``H`` of one step on its pieces (module docstring): residual, Jacobian, margins, tangents, corrector.

    Parameters
    ----------
    problem : TangentialStep
        A slip-dependent step (``problem.law`` a :class:`~rollqp.friction.bound.SlipBound`).
    frozen : (n,) array
        ``μ_f``, the coefficients of the bound at ``λ = 0``.
    """

    def __init__(self, problem, frozen):
        sc, n = problem.scales, problem.n
        self.problem, self.law, self.n = problem, problem.law, n
        self.frozen = np.asarray(frozen, dtype=float)
        self.load = problem.Q is not None
        self.N = n + int(self.load)
        self.slip_unit, self.V = sc.slip, self.law.law.rolling_speed
        self.p = np.maximum(problem.p, 0.0) / sc.stress
        self.G = np.asarray(problem.A.dense()) * (sc.stress / (problem.dq * sc.slip))  # ∂ŝ/∂t̂
        self.s0 = problem.c / (problem.dq * sc.slip) + (0.0 if self.load else problem.xi / sc.slip)
        self.f = problem.f * (sc.stress / sc.force)
        self.Q = problem.Q / sc.force if self.load else None
        self.static = self.law.mu(np.zeros(n))  # the coefficient at rest (memory included)
        kinks = np.asarray(self.law.law.kinks, dtype=float)
        self.kinks = np.concatenate(([-np.inf], kinks, [np.inf])) / (self.V * self.slip_unit)  # in ŝ
        # the rows' round-off: a stick row sums n products of Ĝ with tractions up to μ_s p̂
        big = float(np.max(np.abs(self.G).sum(axis=1), initial=0.0)) * float(np.max(self.static * self.p, initial=0.0))
        self.tolerance = max(CORRECTOR_TOLERANCE, 64 * np.finfo(float).eps * big)

    # ------------------------------------------------------------ evaluation
    def slip(self, u):
        """``ŝ`` at ``u``."""
        s = self.G @ u[:self.n] + self.s0
        return s + u[self.n] if self.load else s

    def _law(self, sh, pc):
        """``(μ, ∂μ/∂ŝ)`` of the law (no blend) at the slipping nodes' own branch: ``v = V σ-signed slip``,
        continued smoothly past ``v = 0`` (``v = −σ V s``)."""
        slip = pc.case == SLIP
        sign = np.where(slip, pc.sign, -1.0)
        with np.errstate(over="ignore", invalid="ignore"):  # a corrector iterate far off: caught by its test
            m, d = self.law.branch(np.where(slip, -sign * sh * (self.V * self.slip_unit), 0.0), pc.segment)
        return m, -sign * d * (self.V * self.slip_unit)

    def residual(self, u, pc):
        """``H`` of the piece ``pc`` at ``u`` (N values)."""
        n, lam = self.n, u[-1]
        t, sh = u[:n], self.slip(u)
        m, _ = self._law(sh, pc)
        mu = (1.0 - lam) * self.frozen + lam * m
        r = np.where(pc.case == STICK, sh, np.where(pc.case == SLIP, t - pc.sign * mu * self.p, t))
        return np.append(r, self.f @ t - self.Q) if self.load else r

    def jacobian(self, u, pc):
        """``[∂H/∂(t̂, ξ̂), ∂H/∂λ]`` of the piece ``pc`` at ``u`` (``N × (N + 1)``)."""
        n, N, lam = self.n, self.N, u[-1]
        sh = self.slip(u)
        m, dm = self._law(sh, pc)
        ds = np.zeros((n, N))  # ∂ŝ/∂(t̂, ξ̂)
        ds[:, :n] = self.G
        if self.load:
            ds[:, n] = 1.0
        st, sl = pc.case == STICK, pc.case == SLIP
        M = np.zeros((N, N + 1))
        M[:n, :N] = np.where(st[:, None], ds, np.eye(n, N))
        M[:n, :N] -= (sl * pc.sign * lam * dm * self.p)[:, None] * ds
        M[:n, N] = np.where(sl, -pc.sign * (m - self.frozen) * self.p, 0.0)
        if self.load:
            M[n, :n] = self.f
        return M

    def margins(self, u, pc):
        """Per node the distance from the edge of its piece (``>= 0`` inside; ``inf`` outside the contact) and
        what lies there: ``0`` the other case (stick ↔ slip), ``±1`` the next piece of the law."""
        n, lam = self.n, u[-1]
        t, sh = u[:n], self.slip(u)
        out, where = np.full(n, np.inf), np.zeros(n, dtype=int)
        st, sl = pc.case == STICK, pc.case == SLIP
        out[st] = (((1.0 - lam) * self.frozen + lam * self.static) * self.p - np.abs(t))[st]
        v = -pc.sign * sh  # slip speed in ŝ units, signed: < 0 past the kink at rest
        floor = np.maximum(self.kinks[pc.segment], 0.0)  # the piece's lower edge: rest (stick) or a kink
        lo, hi = v - floor, self.kinks[pc.segment + 1] - v
        out[sl] = np.minimum(lo, hi)[sl]
        where[sl] = np.where(hi < lo, 1, np.where(floor <= 0.0, 0, -1))[sl]
        return out, where

    def piece_at(self, u):
        """The piece the NCP form reads at ``u`` (the node cases of eq. 85–88: stick where ``|t̂ − ŝ| <= b``)."""
        n, lam = self.n, u[-1]
        t, sh = u[:n], self.slip(u)
        b = self.law.homotopy(self.frozen, lam).mu(sh * self.slip_unit) * self.p
        stick = (np.abs(t - sh) <= b) & (b > 0.0)
        case = np.where(b > 0.0, np.where(stick, STICK, SLIP), ZERO)
        sign = np.where(case == SLIP, np.sign(t - sh), 0.0)
        seg = np.where(case == SLIP, self.law.segment(np.abs(sh) * self.V * self.slip_unit), 0)
        return Piece(case, sign, seg)

    def switched(self, pc, j, kind, u):
        """``pc`` with node ``j`` across the edge ``kind`` of :meth:`margins`."""
        case, sign, seg = pc.case.copy(), pc.sign.copy(), pc.segment.copy()
        if case[j] == STICK:
            case[j], sign[j], seg[j] = SLIP, np.sign(u[j]), int(self.law.segment(0.0))
        elif kind == 0:
            case[j], sign[j], seg[j] = STICK, 0.0, 0
        else:
            seg[j] += kind
        return Piece(case, sign, seg)

    def solution(self, u):
        """The step's solution at the traction and creepage of ``u`` (rollqp's residuals of the law's step)."""
        sc, n = self.problem.scales, self.n
        xi = u[n] * sc.slip if self.load else self.problem.xi
        return self.problem.solution(u[:n] * sc.stress, xi)

    # ------------------------------------------------------------ geometry
    def tangent(self, u, pc, border):
        """The unit tangent of the piece's curve at ``u`` with ``border · τ > 0`` (None: singular)."""
        M = np.vstack([self.jacobian(u, pc), border])
        rhs = np.zeros(self.N + 1)
        rhs[-1] = 1.0
        try:
            tau = np.linalg.solve(M, rhs)
        except np.linalg.LinAlgError:
            return None
        nrm = float(np.linalg.norm(tau))
        return tau / nrm if np.isfinite(nrm) and nrm > 0 else None

    def correct(self, guess, normal, pc, lam=None):
        """Newton on the piece's equations from ``guess`` in the hyperplane ``normal · (u − guess) = 0`` (or at
        ``λ = lam``). Returns ``(u, iterations)``, ``u`` None if it does not converge (quadratically: each
        correction at most half the last) within :data:`CORRECTOR_ITERATIONS`."""
        u, last = guess.copy(), np.inf
        row = normal if lam is None else np.eye(self.N + 1)[-1]
        for it in range(CORRECTOR_ITERATIONS + 1):
            F = self.residual(u, pc)
            c = float(row @ (u - guess)) if lam is None else u[-1] - lam
            if max(float(np.max(np.abs(F))), abs(c)) <= self.tolerance:
                return u, it
            if it == CORRECTOR_ITERATIONS:
                break
            try:
                d = np.linalg.solve(np.vstack([self.jacobian(u, pc), row]), -np.append(F, c))
            except np.linalg.LinAlgError:
                break
            size = float(np.max(np.abs(d)))
            if not np.isfinite(size) or (size > 0.5 * last and size > 1e-12):
                break
            u, last = u + d, size
        return None, it


def follow(path, start):
    """The end at ``λ = 1`` of the curve of solutions through ``start`` (``(t̂, ξ̂)`` at ``λ = 0``), followed
    piece by piece (module docstring). Returns ``(u, stats)``; :class:`PathStop` where it cannot go on."""
    u = np.append(np.asarray(start, dtype=float), 0.0)
    pc = path.piece_at(u)
    tau = path.tangent(u, pc, np.eye(path.N + 1)[-1])  # increasing λ
    if tau is None:
        raise PathStop("the step at the frozen bound is singular", lam=0.0, residual=_residual(path, u))
    st = dict(points=0, switches=0, turns=0, lam_max=0.0)
    h = FIRST_STEP
    while st["points"] < MAX_POINTS:
        if h < SMALLEST_STEP:
            raise PathStop(f"the path stops at λ = {u[-1]:.6g} (no step of the corrector converges)", lam=u[-1],
                           residual=_residual(path, u), points=st["points"])
        new = _advance(path, u, pc, tau, h)
        if new is None:
            h /= 2.0
            continue
        uc, tc, its = new
        end = _finish(path, u, uc, pc, tau)
        if end is not None:
            return end, st
        margin, _ = path.margins(uc, pc)
        if np.min(margin) < 0.0:
            shrink = _overshoot(path, u, uc, pc)
            if shrink < 0.5 and h > 1e3 * SMALLEST_STEP:  # the first edge lies early in the step: land beyond it
                h *= max(1.5 * shrink, 1e-3)
                continue
            u, pc, tau = _turn(path, u, uc, pc, tau, h, st)
            h = min(max(h, 1e-6), LARGEST_STEP)
        else:
            st["turns"] += int(tc[-1] * tau[-1] < 0.0)
            u, tau = uc, tc
            h = min(LARGEST_STEP, h * (2.0 if its <= 2 else 1.0 if its <= 4 else 0.5))
        st["points"] += 1
        st["lam_max"] = max(st["lam_max"], float(u[-1]))
        _check_bounded(path, u, st)
    raise PathStop(f"the path did not reach λ = 1 within {MAX_POINTS} points (λ = {u[-1]:.6g})", lam=u[-1],
                   residual=_residual(path, u), points=st["points"])


def _advance(path, u, pc, tau, h):
    """One predictor–corrector step of length ``h`` on the piece: ``(u, tangent, iterations)``, or None if the
    corrector fails or the step leaves the branch (distance from the predictor, angle of the tangents)."""
    guess = u + h * tau
    uc, its = path.correct(guess, tau, pc)
    if uc is None or np.linalg.norm(uc - guess) > DISTANCE * h:
        return None
    tc = path.tangent(uc, pc, tau)
    chord = uc - u
    size = float(np.linalg.norm(chord))
    if tc is None or size == 0.0 or tc @ tau < COSINE or chord @ tau < COSINE * size:
        return None
    return uc, tc, its


def _finish(path, u, uc, pc, tau):
    """The point at ``λ = 1`` if the step from ``u`` to ``uc`` crosses it inside the piece, else None."""
    if not uc[-1] >= 1.0 > u[-1]:
        return None
    a = (1.0 - u[-1]) / (uc[-1] - u[-1])
    end, _ = path.correct(u + a * (uc - u), tau, pc, lam=1.0)
    if end is None or np.min(path.margins(end, pc)[0]) < 0.0:
        return None
    return end


def _overshoot(path, u, uc, pc) -> float:
    """Where along the step from ``u`` to ``uc`` the first margin turns negative, linearly interpolated (0…1)."""
    m0, m1 = path.margins(u, pc)[0], path.margins(uc, pc)[0]
    bad = m1 < 0.0
    return float(np.min(np.maximum(m0[bad], 0.0) / (np.maximum(m0[bad], 0.0) - m1[bad])))


def _turn(path, u, uc, pc, tau, h, st):
    """Locate the edge of the piece between ``u`` and ``uc`` (:func:`_edge`; where one of its trial points
    is not put back on the curve, its halving trials), move the node across it, and the new piece's
    tangent that enters it."""
    found = _edge(path, u, uc, pc, tau, h)
    found = found if found is not None else _edge(path, u, uc, pc, tau, h, halving=True)
    if found is None:
        raise PathStop(f"the path's edge of a piece is not found near λ = {u[-1]:.6g}", lam=u[-1],
                       residual=_residual(path, u), points=st["points"])
    ulo, j = found
    kind = int(path.margins(ulo, pc)[1][j])
    new = path.switched(pc, j, kind, ulo)
    tn = path.tangent(ulo, new, tau)
    if tn is None:
        raise PathStop(f"the path's next piece is singular at λ = {ulo[-1]:.6g}", lam=ulo[-1],
                       residual=_residual(path, ulo), points=st["points"])
    if path.margins(ulo + 1e-7 * tn, new)[0][j] < path.margins(ulo, new)[0][j]:
        tn = -tn  # the direction that enters the new piece
    st["switches"] += 1
    st["turns"] += int(tn[-1] * tau[-1] < 0.0)
    return ulo, new, tn


def _edge(path, u, uc, pc, tau, h, halving=False):
    """``(point, node)`` of the edge between ``u`` and ``uc``: regula falsi on the step length along ``tau``,
    every trial point put back on the curve by the corrector; None where the corrector fails at a trial point.

    The trial: with the Illinois weights (the weight of an end kept twice in a row is halved), aimed at the
    margin :data:`EDGE_AIM` inside the piece; ``halving``: the secant's trial moved halfway towards the end
    just replaced, aimed at the edge itself (slower: about 25 corrector solves an edge at 45 m/s; its trial
    points differ, so it passes where a trial of the first is not put back on the curve)."""
    aim, clamp = (0.0, 1e-3) if halving else (EDGE_AIM, 1e-9)
    lo, hi, ulo, j = 0.0, h, u, None
    m_lo, m_hi = path.margins(u, pc)[0], path.margins(uc, pc)[0]
    w_lo, w_hi, last = 1.0, 1.0, 0  # last: the end replaced last (1 the low end, −1 the high one)
    for _ in range(200):
        bad = np.flatnonzero(m_hi < 0.0)
        f_lo = w_lo * np.maximum(m_lo[bad] - aim, 0.0)
        frac = f_lo / (f_lo - w_hi * (m_hi[bad] - aim))
        j, a = int(bad[np.argmin(frac)]), float(np.min(frac))
        if halving:
            a = 0.5 * a if last == 1 else 0.5 * (1.0 + a) if last == -1 else a
        hm = lo + min(max(a, clamp), 1.0 - clamp) * (hi - lo)
        um, _ = path.correct(u + hm * tau, tau, pc)
        if um is None:
            return None
        margin = path.margins(um, pc)[0]
        if np.min(margin) < 0.0:
            hi, m_hi = hm, margin
            if not halving:
                w_hi, w_lo = 1.0, (0.5 * w_lo if last == -1 else w_lo)
            last = -1
        else:
            lo, ulo, m_lo = hm, um, margin
            if not halving:
                w_lo, w_hi = 1.0, (0.5 * w_hi if last == 1 else w_hi)
            last = 1
            if margin[j] <= EDGE or hi - lo <= 1e-15 * h:
                break
    return ulo, j


def _check_bounded(path, u, st):
    """The path runs off: below ``λ = −1`` (it cannot come back to the unique solution at ``λ = 0``) or into
    gross sliding (``|ξ̂|`` beyond :data:`XI_LIMIT`)."""
    if u[-1] < -1.0:
        raise PathStop(f"the path runs back below λ = 0 (λ = {u[-1]:.6g})", lam=u[-1], residual=_residual(path, u),
                       points=st["points"])
    if path.load and abs(u[path.n]) > XI_LIMIT:
        raise PathStop(f"the path runs into gross sliding (creepage {u[path.n] * path.slip_unit:.3g}) at "
                       f"λ = {u[-1]:.6g}: no state with stick is continuous with the frozen bound", lam=u[-1],
                       residual=_residual(path, u), points=st["points"])


def _residual(path, u):
    """rollqp's residual of the law's step (``λ = 1``) at the traction and creepage of ``u``."""
    return float(path.solution(u).residual)

