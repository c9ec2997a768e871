r"""The friction laws: what the coefficient ``μ`` of the bound ``|t| <= μ p`` depends on (docs/friction.md).

Three families, each a small frozen record whose fields are the keys of ``[contact.friction]``:

* :class:`Coulomb` — one constant ``μ`` (``contact.friction = 0.3`` is this law; the law object is
  also the number ``μ``, a ``float``, so that a scene's ``contact.friction`` reads as that number);
* :class:`Patch`, :class:`Table` — ``μ(x)`` varying along the surface, fixed in the contact
  frame (``frame = "fixed"``) or carried by a body's material through the contact
  (``frame = "material"``: the material point at ``x`` at rolled distance ``q`` was at
  ``x − d q`` at ``q = 0``, ``d = load.direction``);
* :class:`SlipVelocity` — ``μ(v)`` of the slip velocity ``v = V |s|`` (``V`` the rolling speed,
  ``s`` the slip per unit rolled distance), CONTACT's forms with ``Δμ = static − kinetic`` and a
  characteristic velocity ``v_h``:

  ===============  ============================================================
  ``linear``       ``μ = μ_k + Δμ max(0, 1 − v/v_h)``
  ``rational``     ``μ = μ_k + Δμ / (1 + v/v_h)``
  ``exponential``  ``μ = μ_k + Δμ exp(−v/v_h)``
  ``plateau``      ``μ = μ_k + Δμ exp(−max(0, v − v_p)/v_h)`` (flat up to ``v_p``)
  ===============  ============================================================

  with an optional memory length ``L``: the coefficient of a material point relaxes towards
  ``μ(v)`` over the rolled distance ``L`` (implicit Euler per step, :mod:`.bound`).

Positions and lengths are in units of ``a_H`` (like the histories' ``q/a_H``); velocities in the
scene's own length/time units. Every law validates its keys (an :class:`~rollqp.errors.InputError`
naming ``contact.friction.<key>`` and the range) at construction.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..validate import choice, number, real_sequence

__all__ = ["MAX_FRICTION", "Coulomb", "Patch", "Table", "SlipVelocity", "VELOCITY_FORMS", "FRAMES"]

#: Largest coefficient of friction (beyond any material; tractions of μ·p stay far from overflow).
MAX_FRICTION = 1e6
FRAMES = ("fixed", "material")
VELOCITY_FORMS = ("linear", "rational", "exponential", "plateau")
KEY = "contact.friction"


def _mu(name, v):
    return number(f"{KEY}.{name}", v, f">= 0 (and <= {MAX_FRICTION:g})", lambda x: 0 <= x <= MAX_FRICTION)


class Coulomb(float):
    """Constant Coulomb coefficient ``μ`` (paper eq. 57–60): a law object that is also the number ``μ``.

    A ``float`` subclass: arithmetic, comparisons, ``repr``, JSON and TOML see the number itself (a scene
    written out says ``friction = 0.3``), while rollqp reads it as a law (``kind``, ``reference``,
    ``largest``); each step takes the plain ``float`` ``μ`` (:attr:`mu`), the step problems' fast path.

    Examples
    --------
    >>> from rollqp.friction import Coulomb
    >>> law = Coulomb(0.3)
    >>> law.kind, law.mu, 2 * law
    ('constant', 0.3, 0.6)
    >>> law
    0.3
    """

    law = "coulomb"
    kind = "constant"
    #: The table's keys (``[contact.friction]`` with ``law = "coulomb"``).
    keys = ("mu", "law")
    __slots__ = ()
    __repr__ = float.__repr__

    def __new__(cls, mu, law: str = "coulomb"):
        if law != "coulomb":
            raise InputError(f"{KEY}.law", f"must be 'coulomb' for a Coulomb law, got {law!r}")
        return super().__new__(cls, _mu("mu", mu))

    def __reduce__(self):
        return Coulomb, (float(self),)

    @property
    def mu(self) -> float:
        """``μ`` as a plain ``float`` (what a step problem takes)."""
        return float(self)

    @property
    def reference(self) -> float:
        """The ``μ`` of ``load.tangential = Q/(μ P̄)`` and of the reports."""
        return float(self)

    @property
    def largest(self) -> float:
        return float(self)


class _Spatial:
    """Shared part of the laws varying along the surface: the frame and ``μ`` at the nodes."""

    kind = "spatial"

    def _check_frame(self):
        object.__setattr__(self, "frame", choice(f"{KEY}.frame", self.frame, FRAMES))

    def positions(self, x_hat, q_hat, direction):
        """Where the nodes ``x̂`` are in the law's own coordinate (``a_H`` units) at ``q̂``."""
        return x_hat - direction * q_hat if self.frame == "material" else x_hat

    #: The keys that make a law vary along y (a grid's second coordinate; a strip has none).
    y_keys = ()

    def varies_in_y(self) -> str | None:
        """The first key set that makes ``μ`` depend on ``ŷ`` (only a 3D contact has it), else None."""
        return next((k for k in self.y_keys if getattr(self, k) is not None), None)

    def coefficient(self, points, q_hat, direction) -> np.ndarray:
        """``μ`` at the ``points`` (shape ``(d, n)``: the rolling coordinate ``x̂`` first, then ``ŷ`` on a
        grid; length units of the contact) at the rolled distance ``q̂``. The material frame moves ``x̂``
        only; a law without y keys is the same on every line of a grid."""
        pts = np.asarray(points, dtype=float)
        xs = self.positions(pts[0], q_hat, direction)
        key = self.varies_in_y()
        if key is None:
            return self.profile(xs)
        if pts.ndim != 2 or pts.shape[0] < 2:
            raise InputError(f"{KEY}.{key}", "makes μ vary along y, which only a 3D contact has (a 2D strip's "
                                             "laws vary along x only)")
        return self.surface(xs, pts[1])

    def span(self):
        """``(lo, hi)``: the part of the law's coordinate where μ differs from the outside value."""
        raise NotImplementedError

    def check_strip(self, half_width_hat, q_end_hat, direction):
        """The varying part meets the strip ``[−L̂, L̂]`` at some rolled distance of the run, else an InputError.

        ``q_end_hat``: the last rolled distance (the run covers ``[0, q̂_end]``), or ``(q̂_lo, q̂_hi)``,
        the range a load path (``load.rolled``: stops and reversals) covers."""
        lo, hi = self.span()
        q_lo, q_hi = (0.0, q_end_hat) if np.ndim(q_end_hat) == 0 else (min(q_end_hat), max(q_end_hat))
        if self.frame == "material":  # the strip in the law's coordinate sweeps x − d q
            a, b = sorted((-direction * q_lo, -direction * q_hi))
            a, b = min(a, 0.0), max(b, 0.0)
            slo, shi = -half_width_hat + a, half_width_hat + b
        else:
            slo, shi = -half_width_hat, half_width_hat
        if not (hi > slo and lo < shi):
            name = "start" if isinstance(self, Patch) else "x"
            raise InputError(f"{KEY}.{name}", f"the {self.law} [{lo:.6g}, {hi:.6g}] a_H lies outside the strip "
                                              f"(it must meet [{slo:.6g}, {shi:.6g}] a_H, the potential contact zone "
                                              f"{'swept by the material over the run' if self.frame == 'material' else ''})")


@dataclass(frozen=True)
class Patch(_Spatial):
    """``μ = inside`` on ``[start, end]`` (``a_H`` units), ``mu`` elsewhere; on a 3D contact also bounded in
    y by ``[y_start, y_end]`` (``a_H`` units; either omitted: unbounded on that side, both: every y)."""

    mu: float
    inside: float
    start: float
    end: float
    frame: str = "fixed"
    law: str = "patch"
    y_start: float | None = None
    y_end: float | None = None
    y_keys = ("y_start", "y_end")

    def __post_init__(self):
        object.__setattr__(self, "mu", _mu("mu", self.mu))
        object.__setattr__(self, "inside", _mu("inside", self.inside))
        s = number(f"{KEY}.start", self.start, "finite (a_H units)", lambda x: True)
        e = number(f"{KEY}.end", self.end, f"> start = {s!r} (a_H units)", lambda x: x > s)
        object.__setattr__(self, "start", s)
        object.__setattr__(self, "end", e)
        if self.y_start is not None:
            object.__setattr__(self, "y_start", number(f"{KEY}.y_start", self.y_start, "finite (a_H units)",
                                                       lambda x: True))
        if self.y_end is not None:
            lo = self.y_start
            object.__setattr__(self, "y_end", number(
                f"{KEY}.y_end", self.y_end, "finite (a_H units)" if lo is None else f"> y_start = {lo!r} (a_H units)",
                lambda x: lo is None or x > lo))
        self._check_frame()

    reference = property(lambda self: self.mu, doc="The outside value (``load.tangential = Q/(μ P̄)``).")
    largest = property(lambda self: max(self.mu, self.inside))

    def profile(self, xi):
        return np.where((xi >= self.start) & (xi <= self.end), self.inside, self.mu)

    def surface(self, xi, yi):
        """``μ(x̂, ŷ)``: ``inside`` on the rectangle ``[start, end] × [y_start, y_end]``."""
        inside = (xi >= self.start) & (xi <= self.end)
        if self.y_start is not None:
            inside &= yi >= self.y_start
        if self.y_end is not None:
            inside &= yi <= self.y_end
        return np.where(inside, self.inside, self.mu)

    def span(self):
        return self.start, self.end


@dataclass(frozen=True)
class Table(_Spatial):
    """``μ(x)`` interpolated linearly in the table ``(x, values)`` (``a_H`` units), constant beyond its ends.

    On a 3D contact, ``y`` (``a_H`` units, increasing) makes ``values`` a table of rows along y (``len(y)``
    rows of ``len(x)`` entries): ``μ(x, y)`` bilinear in it, constant beyond its ends. Without ``y`` a
    table is ``μ(x)``, the same at every y.

    Examples
    --------
    >>> import numpy as np
    >>> t = Table(x=(-1.0, 1.0), values=((0.1, 0.3), (0.2, 0.4)), y=(0.0, 1.0))
    >>> t.coefficient(np.array([[0.0, 0.0, 5.0], [0.5, -3.0, 2.0]]), 0.0, -1)
    array([0.25, 0.2 , 0.4 ])
    """

    x: tuple
    values: tuple
    frame: str = "fixed"
    law: str = "table"
    y: tuple | None = None
    y_keys = ("y",)

    def __post_init__(self):
        x = real_sequence(f"{KEY}.x", self.x, 100_000)
        if len(x) < 2:
            raise InputError(f"{KEY}.x", f"must have at least 2 entries, got {len(x)}")
        if any(b <= a for a, b in zip(x, x[1:])):
            raise InputError(f"{KEY}.x", "must be strictly increasing")
        if self.y is None:
            v = real_sequence(f"{KEY}.values", self.values, 100_000)
            if len(v) != len(x):
                raise InputError(f"{KEY}.values", f"must have as many entries as {KEY}.x (at least 2), got {len(v)} "
                                                  f"and {len(x)}")
            for i, m in enumerate(v):
                _mu(f"values[{i}]", m)
        else:
            y = real_sequence(f"{KEY}.y", self.y, 100_000)
            if len(y) < 2 or any(b <= a for a, b in zip(y, y[1:])):
                raise InputError(f"{KEY}.y", f"must be strictly increasing with at least 2 entries, got {list(y)!r}")
            rows = self.values
            if isinstance(rows, (str, bytes)) or not hasattr(rows, "__len__") or len(rows) != len(y):
                n = len(rows) if hasattr(rows, "__len__") else rows
                raise InputError(f"{KEY}.values", f"with {KEY}.y must be {len(y)} rows (one per y), got {n!r}")
            v = []
            for j, row in enumerate(rows):
                r = real_sequence(f"{KEY}.values[{j}]", row, 100_000)
                if len(r) != len(x):
                    raise InputError(f"{KEY}.values[{j}]", f"must have {len(x)} entries (one per x), got {len(r)}")
                for i, m in enumerate(r):
                    _mu(f"values[{j}][{i}]", m)
                v.append(r)
            v = tuple(v)
            object.__setattr__(self, "y", y)
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "values", v)
        self._check_frame()

    def _all(self):
        return self.values if self.y is None else tuple(m for row in self.values for m in row)

    reference = property(lambda self: max(self._all()), doc="The largest tabulated value.")
    largest = property(lambda self: max(self._all()))

    def profile(self, xi):
        return np.interp(xi, self.x, self.values)

    def surface(self, xi, yi):
        """``μ(x̂, ŷ)`` bilinear in the table: linear along x on each row, then along y between rows
        (``lo + w (hi − lo)``: equal rows give the row's ``μ(x)`` exactly)."""
        rows = np.array([np.interp(xi, self.x, r) for r in self.values])
        y = np.asarray(self.y)
        yc = np.clip(yi, y[0], y[-1])
        j = np.clip(np.searchsorted(y, yc, side="right") - 1, 0, len(y) - 2)
        w = (yc - y[j]) / (y[j + 1] - y[j])
        k = np.arange(np.size(xi))
        lo, hi = rows[j, k], rows[j + 1, k]
        return lo + w * (hi - lo)

    def span(self):
        return self.x[0], self.x[-1]


@dataclass(frozen=True)
class SlipVelocity:
    """``μ(v)``, ``v = V |s|`` (module docstring): ``static``, ``kinetic``, ``velocity`` ``v_h``, ``plateau``
    ``v_p`` (form ``plateau`` only), ``rolling_speed`` ``V`` (required), ``memory`` ``L`` (``a_H`` units, 0: none)."""

    law: str
    static: float
    kinetic: float
    velocity: float
    rolling_speed: float | None = None
    plateau: float | None = None
    memory: float = 0.0
    kind = "slip"

    def __post_init__(self):
        choice(f"{KEY}.law", self.law, VELOCITY_FORMS)
        st, kin = _mu("static", self.static), _mu("kinetic", self.kinetic)
        if not st >= kin:
            raise InputError(f"{KEY}.static", f"must be >= kinetic = {kin!r} (a falling law), got {st!r}")
        put = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731 - frozen dataclass
        put("static", st)
        put("kinetic", kin)
        put("velocity", number(f"{KEY}.velocity", self.velocity, "> 0 (slip velocity, length/time)", lambda x: x > 0))
        if self.rolling_speed is None:
            raise InputError(f"{KEY}.rolling_speed", f"is required by the slip-velocity law {self.law!r} "
                                                     "(the rolling speed V > 0, length/time: v_slip = V |s|)")
        put("rolling_speed", number(f"{KEY}.rolling_speed", self.rolling_speed, "> 0 (length/time)", lambda x: x > 0))
        if self.law == "plateau":
            if self.plateau is None:
                raise InputError(f"{KEY}.plateau", "is required by law 'plateau' (the velocity up to which μ = static, >= 0)")
            put("plateau", number(f"{KEY}.plateau", self.plateau, ">= 0 (length/time)", lambda x: x >= 0))
        elif self.plateau is not None:
            raise InputError(f"{KEY}.plateau", f"belongs to law 'plateau' only, not {self.law!r}")
        put("memory", number(f"{KEY}.memory", self.memory, ">= 0 (a_H units; 0: no memory)", lambda x: x >= 0))

    reference = property(lambda self: self.static, doc="The static value (``load.tangential = Q/(μ_s P̄)``).")
    largest = property(lambda self: self.static)

    def steady(self, v):
        """``(μ(v), dμ/dv)`` for slip velocities ``v >= 0`` (module docstring's forms)."""
        v = np.asarray(v, dtype=float)
        dm, vh = self.static - self.kinetic, self.velocity
        if self.law == "linear":
            inside = v < vh
            return self.kinetic + dm * np.where(inside, 1.0 - v / vh, 0.0), np.where(inside, -dm / vh, 0.0)
        if self.law == "rational":
            u = 1.0 + v / vh
            return self.kinetic + dm / u, -(dm / vh) / u / u  # not vh·u·u: it overflows for u > 1e154
        if self.law == "exponential":
            e = np.exp(-v / vh)
            return self.kinetic + dm * e, -dm * e / vh
        over = v > self.plateau
        e = np.exp(-np.maximum(0.0, v - self.plateau) / vh)
        return self.kinetic + dm * e, np.where(over, -dm * e / vh, 0.0)

    @property
    def steepest(self) -> float:
        """The largest ``|dμ/dv|`` over ``v >= 0``: ``Δμ/v_h`` for every form (at ``v = 0``, or just above ``v_p``)."""
        return (self.static - self.kinetic) / self.velocity

    @property
    def kinks(self) -> tuple:
        """The slip velocities where ``μ(v)`` has a kink (its slope jumps): ``v_h`` (linear: μ reaches μ_k),
        ``v_p`` (plateau: the fall starts); none for the rational and exponential forms."""
        if self.law == "linear":
            return (self.velocity,)
        if self.law == "plateau":
            return (self.plateau,)
        return ()

    def branch(self, v, k):
        """``(μ, dμ/dv)`` of the ``k``-th smooth piece of ``μ(v)`` (between :attr:`kinks` ``k − 1`` and ``k``),
        evaluated at any ``v`` — also beyond the piece and at ``v < 0``, the piece's own formula continued: the
        path of solutions (:mod:`rollqp.methods.path`) follows one smooth piece at a time and needs its equations
        a little past the piece's ends to find where it leaves it. ``k`` an int or an int array like ``v``."""
        v = np.asarray(v, dtype=float)
        dm, vh = self.static - self.kinetic, self.velocity
        if self.law == "linear":  # piece 0: the falling line; piece 1: μ_k
            return (np.where(k == 0, self.kinetic + dm * (1.0 - v / vh), self.kinetic),
                    np.where(k == 0, -dm / vh + 0.0 * v, 0.0 * v))
        if self.law == "plateau":  # piece 0: μ_s; piece 1: the exponential fall from v_p
            e = np.exp(-(v - self.plateau) / vh)
            return (np.where(k == 0, self.static, self.kinetic + dm * e), np.where(k == 0, 0.0, -dm * e / vh))
        return self.steady(v)

    def weight(self, dq_hat) -> float:
        """The memory's weight ``w = L/(L + |Δq|)`` of the previous coefficient (0 without memory)."""
        return 0.0 if self.memory == 0.0 else self.memory / (self.memory + abs(dq_hat))

