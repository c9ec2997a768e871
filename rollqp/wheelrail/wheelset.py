r"""The wheelset: its geometry, position and velocities, and the rigid slip they give (docs/wheel-rail.md).

Frames (all right-handed, ``z`` down, lengths in mm): the **wheelset frame** has its origin at the
wheelset centre and its ``y`` axis along the axle; the wheel profile's origin (its taping line) lies at
``(0, d/2 − y_fb, r_nom)`` in it (``d`` the back-to-back distance between the flange backs, ``y_fb`` the
flange back's position in the profile, ``r_nom`` the nominal radius). A wheel point at profile
coordinate ``y_w`` and angle ``θ`` about the axle is

.. math::
    q(θ, y_w) = (−ρ \sin θ,\; d/2 − y_{fb} + y_w,\; ρ \cos θ),\qquad ρ(y_w) = r_{nom} + z_w(y_w)   \qquad (WR.1)

The wheelset is rolled by ``φ`` about ``x``, then yawed by ``ψ`` about its own ``z`` (CONTACT's
roll–yaw–pitch order; pitch does not move a round wheel) and put at ``C = (0, y_ws, z_ws − r_nom)``:
``p = R q + C`` with ``R = R_x(φ) R_z(ψ)``.

The **contact locus** is where the wheel's surface normal ``∝ R (sin θ, ρ', −cos θ)`` has no ``x``
component (for a rail that is straight along ``x`` these are the lowest wheel points of each track
``y``): ``sin θ = tan ψ · ρ'(y_w)`` (WR.2), the leading shift of a yawed flange.

The velocity of a wheel material point ``p`` relative to the frame moving with the wheelset at the
forward speed ``V``: ``v = (0, v_y, v_z) + ω × (p − C)``, with ``ω = φ̇ e_x + ψ̇ R_x(φ) e_z + Ω R e_y``
(``Ω`` the angular velocity about the axle, negative when rolling forward). The rail's material moves
at ``(−V, 0, 0)``. The creepages of a patch with axes ``(e_x, e_s, e_n)`` are the rigid slip of the
rail (body A, CONTACT's body 1) relative to the wheel over the rolling speed ``V_r = |½(v_A + v_B)|``
in the contact plane (the mean speed of the two surfaces through the contact, CONTACT's VELOC) (WR.3):

.. math::
    ξ = (v_A − v_B)·e_x / V_r,\quad η = (v_A − v_B)·e_s / V_r,\quad φ = −ω·e_n / V_r .
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..errors import InputError, SolverError

__all__ = ["Wheelset", "State"]


def _num(key, v, positive=False, lo=None, hi=None):
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or (positive and v <= 0):
        raise InputError(key, f"must be a finite number{' > 0' if positive else ''}, got {v!r}")
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        raise InputError(key, f"must be in [{lo:g}, {hi:g}], got {v!r}")
    return float(v)


@dataclass(frozen=True)
class State:
    """A wheelset's position and velocities in the track frame (module docstring).

    ``lateral`` y_ws (mm), ``vertical`` z_ws (mm, down; found from the load when solving), ``roll`` φ,
    ``yaw`` ψ (rad), ``speed`` V (> 0, mm/time), ``pitch_rate`` Ω (rad/time; ``None``: free rolling
    ``−V/r_nom``), ``vy``, ``vz`` (mm/time), ``roll_rate``, ``yaw_rate`` (rad/time).
    """

    lateral: float = 0.0
    vertical: float = 0.0
    roll: float = 0.0
    yaw: float = 0.0
    speed: float = 2000.0
    pitch_rate: float | None = None
    vy: float = 0.0
    vz: float = 0.0
    roll_rate: float = 0.0
    yaw_rate: float = 0.0

    def __post_init__(self):
        for k in ("lateral", "vertical", "vy", "vz", "roll_rate", "yaw_rate"):
            object.__setattr__(self, k, _num(f"wheelset.{k}", getattr(self, k)))
        object.__setattr__(self, "roll", _num("wheelset.roll", self.roll, lo=-0.2, hi=0.2))
        object.__setattr__(self, "yaw", _num("wheelset.yaw", self.yaw, lo=-0.2, hi=0.2))
        object.__setattr__(self, "speed", _num("wheelset.speed", self.speed, positive=True))
        if self.pitch_rate is not None:
            object.__setattr__(self, "pitch_rate", _num("wheelset.pitch_rate", self.pitch_rate))

    def mirrored(self) -> "State":
        """The state seen in the mirror ``y → −y`` (a left wheel computed as a right one)."""
        return replace(self, lateral=-self.lateral, roll=-self.roll, yaw=-self.yaw, vy=-self.vy,
                       roll_rate=-self.roll_rate, yaw_rate=-self.yaw_rate)


@dataclass(frozen=True)
class Wheelset:
    """A (right) wheel of a wheelset: ``wheel`` profile (canonical), ``back_to_back`` d, ``flange_back``
    y_fb (the flange back's lateral position in the profile, CONTACT's FBPOS), ``nominal_radius`` r_nom."""

    wheel: object
    back_to_back: float = 1360.0
    flange_back: float = -70.0
    nominal_radius: float = 460.0

    def __post_init__(self):
        object.__setattr__(self, "back_to_back", _num("wheelset.back_to_back", self.back_to_back, positive=True))
        object.__setattr__(self, "flange_back", _num("wheelset.flange_back", self.flange_back))
        object.__setattr__(self, "nominal_radius", _num("wheelset.nominal_radius", self.nominal_radius,
                                                        positive=True))
        if self.nominal_radius < 5 * (self.wheel.span[1] - self.wheel.span[0]) / 2:
            pass    # small rollers are allowed: only ρ > 0 matters (checked below)
        if np.any(self.nominal_radius + self.wheel.zs <= 0):
            raise InputError("wheelset.nominal_radius", "is smaller than the wheel profile's depth")

    @property
    def offset(self) -> float:
        """Lateral position of the wheel profile's origin in the wheelset frame, ``d/2 − y_fb``."""
        return 0.5 * self.back_to_back - self.flange_back

    # ------------------------------------------------------------------ placement
    @staticmethod
    def rotation(state: State) -> np.ndarray:
        """``R = R_x(φ) R_z(ψ)`` (module docstring)."""
        cf, sf, cp, sp = math.cos(state.roll), math.sin(state.roll), math.cos(state.yaw), math.sin(state.yaw)
        Rx = np.array([[1.0, 0, 0], [0, cf, -sf], [0, sf, cf]])
        Rz = np.array([[cp, -sp, 0], [sp, cp, 0], [0, 0, 1.0]])
        return Rx @ Rz

    def centre(self, state: State) -> np.ndarray:
        return np.array([0.0, state.lateral, state.vertical - self.nominal_radius])

    def radius_at(self, yw) -> np.ndarray:
        """``ρ(y_w) = r_nom + z_w(y_w)`` (WR.1; nan beyond the profile)."""
        return self.nominal_radius + self.wheel.z_at(yw)

    def locus(self, state: State):
        """The contact locus (WR.2) at the wheel profile's samples: track points ``(n, 3)``, the profile
        coordinate ``y_w`` and the valid mask (where the surface is not too steep for the yaw)."""
        yw = self.wheel.ys
        rho = self.nominal_radius + self.wheel.zs
        drho = self.wheel.dzs
        st = math.tan(state.yaw) * drho
        ok = np.abs(st) < 0.99
        th = np.arcsin(np.clip(st, -0.99, 0.99))
        q = np.stack([-rho * np.sin(th), self.offset + yw, rho * np.cos(th)])
        p = (self.rotation(state) @ q).T + self.centre(state)
        return p, yw, ok

    def surface_along(self, state: State, P, d, key: str = "wheel surface"):
        """``t`` with ``P + t d`` on the wheel surface, for points ``P`` ``(m, 3)`` and one direction ``d``
        (track frame): Newton's method on ``|q_xz| − ρ(q_y − offset)``, ``q = Rᵀ(P + t d − C)``."""
        R, C = self.rotation(state), self.centre(state)
        q0 = (np.asarray(P, dtype=float) - C) @ R            # rows: Rᵀ (P − C)
        dq = R.T @ np.asarray(d, dtype=float)
        t = np.zeros(q0.shape[0])
        lo, hi = self.wheel.span
        for _ in range(60):
            q = q0 + t[:, None] * dq
            yw = q[:, 1] - self.offset
            if np.any((yw < lo) | (yw > hi)):
                raise InputError(key, "a patch reaches beyond the wheel profile's ends (a contact at its edge: "
                                      "the profile must extend past the contact)")
            rr = np.hypot(q[:, 0], q[:, 2])
            f = rr - (self.nominal_radius + self.wheel.z_at(yw))
            if np.max(np.abs(f)) < 1e-11 * self.nominal_radius:
                return t
            df = (q[:, 0] * dq[0] + q[:, 2] * dq[2]) / rr - self.wheel.slope_at(yw) * dq[1]
            step = -f / np.where(np.abs(df) > 1e-12, df, 1e-12)
            t = t + np.clip(step, -2.0, 2.0)
        raise SolverError(f"{key}: the wheel surface along the contact normal was not found (Newton's method, "
                          f"60 iterations)", residual=float(np.max(np.abs(f))))

    # ------------------------------------------------------------------ kinematics
    def angular_velocity(self, state: State) -> np.ndarray:
        R = self.rotation(state)
        cf, sf = math.cos(state.roll), math.sin(state.roll)
        pitch = -state.speed / self.nominal_radius if state.pitch_rate is None else state.pitch_rate
        return (state.roll_rate * np.array([1.0, 0, 0]) + state.yaw_rate * np.array([0.0, -sf, cf])
                + pitch * R[:, 1])

    def creepages(self, state: State, W, ex, es, en) -> tuple[float, float, float]:
        """``(ξ, η, φ)`` of the rail relative to the wheel at the wheel point ``W`` (WR.3)."""
        om = self.angular_velocity(state)
        vB = np.array([0.0, state.vy, state.vz]) + np.cross(om, np.asarray(W) - self.centre(state))
        vA = np.array([-state.speed, 0.0, 0.0])
        rel = vA - vB
        mean = 0.5 * (vA + vB)
        V = math.hypot(float(mean @ ex), float(mean @ es))        # the rolling speed in the contact plane
        return float(rel @ ex) / V, float(rel @ es) / V, float(-(om @ en)) / V

    def rolling_speed(self, state: State, W, ex, es) -> float:
        """``|½(v_A + v_B)|`` in the contact plane: the speed the creepages are relative to (WR.3)."""
        om = self.angular_velocity(state)
        vB = np.array([0.0, state.vy, state.vz]) + np.cross(om, np.asarray(W) - self.centre(state))
        mean = 0.5 * (np.array([-state.speed, 0.0, 0.0]) + vB)
        return math.hypot(float(mean @ ex), float(mean @ es))
