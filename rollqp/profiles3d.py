r"""Body profiles over (x, y): a 3D body's undeformed surface near the contact, and the features that
roll through it (docs/scenes.md, "Three dimensions: beyond Hertz").

A body's surface is its distance ``z(x, y) ≥ 0`` from the common tangent plane, in the contact frame
(x rolling, y lateral; positive away from the other body); the undeformed distance of a step is
``h(x, y) = z_A(x, y) + z_B(x, y)`` (eq. 3D.3 for two paraboloids). A body is a **base** shape plus
**features**:

* no profile: the paraboloid of its principal radii, ``z = x²/(2R_x) + y²/(2R_y)`` (eq. 3D.3);
* ``kind = "lateral"``: a lateral profile ``z_l(y)`` added to the rolling radius, ``z = x²/(2R_x) + z_l(y)``
  (a wheel, or a rail head with ``radius = inf``); ``z_l`` is the not-a-knot cubic spline through the
  points (``interpolation = "spline"``, the default: it reproduces any quadratic to round-off) or the
  broken line through them (``"linear"``);
* ``kind = "surface"``: the whole shape as a table ``z(x, y)`` in the contact frame (rows along y),
  the tensor-product interpolating spline (cubic where a direction has four points or more) or the
  bilinear interpolant;
* features that roll through with the body's material (``frame = "material"``, the default) or sit
  in the contact frame (``frame = "contact"``): ``defect`` (a dent, ``depth > 0``, or a bump, of
  ``length`` along x and ``width`` along y: the 2D defect's shape ``φ`` over the elliptic distance
  ``r = √((2(s − x₀)/length)² + (2(y − y₀)/width)²)``) and ``flat`` (a wheel flat: the 2D chord of
  ``length`` across the whole width). A material feature at ``s`` is at ``x = s + d·q`` after a rolled
  distance ``q``, as in 2D.

The heights of the features are the 2D ones (:mod:`rollqp.profiles`: :class:`~rollqp.profiles.Defect`
and :class:`~rollqp.profiles.Flat` evaluated at a distance from the feature's centre): the physics of a
feature's height over a point is the same in both dimensions.

:func:`parse_body` reads a body's ``radius``, ``radius_y`` and ``profile`` together (which radii a
profile needs), :class:`Shape` is the undeformed distance of the two bodies, with its curvatures at the
origin (:meth:`Shape.curvatures`). Every invalid value is an :class:`~rollqp.errors.InputError` naming
its key and the allowed range. Profile coordinates and heights are in the scene's length units.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .errors import InputError
from .profiles import DEFECT_SHAPES, MAX_POINTS, Defect, Flat
from .validate import choice, finite_real, positive_real, real_sequence, suggestion

__all__ = ["Lateral", "Surface", "Defect3D", "Flat3D", "BodyShape", "Shape", "parse_body",
           "PROFILE_KINDS", "INTERPOLATIONS", "register_feature"]

INTERPOLATIONS = ("spline", "linear")
#: Largest surface table (points).
MAX_SURFACE_POINTS = 1_000_000


# =========================================================================== bases
@dataclass(frozen=True)
class Lateral:
    """A lateral profile ``z_l(y)`` through the points ``(y[i], z[i])`` (``y`` strictly increasing, ``z ≥ 0``)."""

    y: tuple
    z: tuple
    interpolation: str = "spline"
    kind = "lateral"

    def __post_init__(self):
        object.__setattr__(self, "_f", _interpolant_1d(np.asarray(self.y), np.asarray(self.z), self.interpolation))

    def height(self, x, y) -> np.ndarray:
        return self._f(np.asarray(y, dtype=float))

    def curvature_y(self) -> float:
        """``½ z_l''(0)``: the lateral curvature at the origin (0 for the broken line between its points)."""
        return 0.5 * float(self._f.second(0.0))

    def extent(self):
        return None, (self.y[0], self.y[-1])

    def to_dict(self) -> dict:
        return {"kind": "lateral", "y": list(self.y), "z": list(self.z), "interpolation": self.interpolation}


@dataclass(frozen=True)
class Surface:
    """A contact-frame table ``z(x, y)``: ``z[j][i]`` at ``(x[i], y[j])`` (rows along y), ``z ≥ 0``."""

    x: tuple
    y: tuple
    z: tuple
    interpolation: str = "spline"
    kind = "surface"

    def __post_init__(self):
        from scipy.interpolate import RectBivariateSpline
        x, y, z = np.asarray(self.x), np.asarray(self.y), np.asarray(self.z)
        kx, ky = (1, 1) if self.interpolation == "linear" else (min(3, x.size - 1), min(3, y.size - 1))
        object.__setattr__(self, "_s", RectBivariateSpline(y, x, z, kx=ky, ky=kx, s=0))

    def height(self, x, y) -> np.ndarray:
        return self._s.ev(np.asarray(y, dtype=float), np.asarray(x, dtype=float))

    def curvatures(self) -> tuple[float, float]:
        """``(½ z_xx, ½ z_yy)`` at the origin (the interpolant's)."""
        return 0.5 * float(self._s.ev(0.0, 0.0, dy=2)), 0.5 * float(self._s.ev(0.0, 0.0, dx=2))

    def extent(self):
        return (self.x[0], self.x[-1]), (self.y[0], self.y[-1])

    def to_dict(self) -> dict:
        return {"kind": "surface", "x": list(self.x), "y": list(self.y), "z": [list(r) for r in self.z],
                "interpolation": self.interpolation}


class _Interp1:
    """A 1D interpolant with its second derivative: the not-a-knot cubic spline, or the broken line."""

    def __init__(self, y, z, how):
        self.how = how
        if how == "spline" and y.size >= 3:
            from scipy.interpolate import CubicSpline
            self.s = CubicSpline(y, z, bc_type="not-a-knot")
        else:
            self.s, self.y, self.z = None, y, z

    def __call__(self, v):
        return self.s(v) if self.s is not None else np.interp(v, self.y, self.z)

    def second(self, v):
        return self.s(v, 2) if self.s is not None else 0.0


def _interpolant_1d(y, z, how):
    return _Interp1(y, z, how)


# =========================================================================== features
@dataclass(frozen=True)
class Defect3D:
    """A dent (``depth > 0``) or bump (``depth < 0``) centred at ``(x, y)``: the 2D defect's height
    ``depth·φ(r)`` over the elliptic distance ``r`` from its centre (``length`` along x, ``width`` along y)."""

    x: float
    y: float
    depth: float
    length: float
    width: float
    shape: str = "cosine"
    frame: str = "material"
    kind = "defect"

    @property
    def material(self) -> bool:
        return self.frame == "material"

    def height(self, s, y) -> np.ndarray:
        with np.errstate(over="ignore"):
            u = 2.0 * (np.asarray(s, dtype=float) - self.x) / self.length
            v = 2.0 * (np.asarray(y, dtype=float) - self.y) / self.width
            r = np.sqrt(u * u + v * v)
        return Defect(self.depth, 2.0, 0.0, self.shape).height(r)   # the 2D dent over r: its half-width is 1

    def to_dict(self) -> dict:
        return {"kind": "defect", "x": self.x, "y": self.y, "depth": self.depth, "length": self.length,
                "width": self.width, "shape": self.shape, "frame": self.frame}


@dataclass(frozen=True)
class Flat3D:
    """A wheel flat of ``length`` centred at ``x`` across the whole width: the 2D flat's chord, cut into the
    body's rolling radius ``radius``."""

    x: float
    length: float
    radius: float
    frame: str = "material"
    kind = "flat"

    @property
    def material(self) -> bool:
        return self.frame == "material"

    def height(self, s, y) -> np.ndarray:
        return Flat(self.length, self.x, self.radius).height(np.asarray(s, dtype=float)) + 0.0 * np.asarray(y)

    def to_dict(self) -> dict:
        return {"kind": "flat", "x": self.x, "length": self.length, "frame": self.frame}


PROFILE_KINDS = ("lateral", "surface", "defect", "flat")
#: Features registered from outside (:func:`register_feature`): kind → (keys, parse).
_FEATURES: dict = {}


def register_feature(kind: str, keys: tuple, parse) -> None:
    """Make ``{ kind = "<kind>", … }`` a feature of a 3D body's ``profile``: ``parse(key, item, radius)``
    returns an object with ``kind``, ``material`` (it rolls through with the body), ``height(x, y)`` (length
    units, added to the body's surface) and ``to_dict()``; ``keys``: the table's keys besides ``kind``.

    Raises
    ------
    InputError
        ``kind`` is a built-in kind or registered already.
    """
    if not isinstance(kind, str) or kind in PROFILE_KINDS or kind in _FEATURES:
        raise InputError("kind", f"must be a new profile kind (taken: {', '.join(PROFILE_KINDS + tuple(_FEATURES))}), "
                                 f"got {kind!r}")
    _FEATURES[kind] = (tuple(keys), parse)
    _KEYS[kind] = tuple(keys)
_KEYS = {"lateral": ("y", "z", "interpolation"), "surface": ("x", "y", "z", "interpolation"),
         "defect": ("x", "y", "depth", "length", "width", "shape", "frame"), "flat": ("x", "length", "frame")}


# =========================================================================== a body and the pair
@dataclass(frozen=True)
class BodyShape:
    """One body's surface: radii ``rx``, ``ry`` (``inf``: straight; None where the base replaces them), the
    base (:class:`Lateral`, :class:`Surface` or None: the paraboloid) and the features."""

    rx: float | None
    ry: float | None
    base: Any = None
    features: tuple = ()

    def height(self, x, y, shift: float = 0.0) -> np.ndarray:
        """``z(x, y)`` with the material moved by ``shift`` (= d·q) since q = 0."""
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        if isinstance(self.base, Surface):
            z = self.base.height(x, y)
        else:
            z = _para(x, self.rx)
            z = z + (self.base.height(x, y) if self.base is not None else _para(y, self.ry))
        for f in self.features:
            z = z + f.height(x - shift if f.material else x, y)
        return z

    def curvatures(self) -> tuple[float, float]:
        """``(½ z_xx, ½ z_yy)`` of the base at the origin."""
        if isinstance(self.base, Surface):
            return self.base.curvatures()
        cy = self.base.curvature_y() if self.base is not None else _half_inverse(self.ry)
        return _half_inverse(self.rx), cy

    @property
    def moves(self) -> bool:
        return any(f.material for f in self.features)

    def profile_dict(self):
        items = ([self.base.to_dict()] if self.base is not None else []) + [f.to_dict() for f in self.features]
        return None if not items else (items[0] if len(items) == 1 else items)


def _para(v, r):
    return 0.0 * v if r is None or math.isinf(r) else v * v / (2.0 * r)


def _half_inverse(r):
    return 0.0 if r is None or math.isinf(r) else 0.5 / r


@dataclass(frozen=True)
class Shape:
    """The undeformed distance ``h(x, y, shift) = z_A + z_B`` of two :class:`BodyShape`\\ s.

    Examples
    --------
    >>> a = parse_body({"radius": 30.0, "profile": {"kind": "lateral", "y": [-2.0, -1.0, 0.0, 1.0, 2.0],
    ...                 "z": [4 / 60, 1 / 60, 0.0, 1 / 60, 4 / 60]}}, "bodies.A")
    >>> b = parse_body({"radius": float("inf"), "radius_y": float("inf")}, "bodies.B")
    >>> h = Shape(a, b)
    >>> [round(c, 12) for c in h.curvatures()]        # the spline reproduces y²/60: Hertz's 1/(2R)
    [0.016666666667, 0.016666666667]
    >>> float(h(0.5, 0.5)) == 0.25 / 60 + 0.25 / 60 or abs(float(h(0.5, 0.5)) - 0.5 / 60) < 1e-15
    True
    """

    A: BodyShape
    B: BodyShape

    def __call__(self, x, y, shift: float = 0.0) -> np.ndarray:
        return self.A.height(x, y, shift) + self.B.height(x, y, shift)

    def at(self, shift: float):
        """``h(x, y)`` with the material moved by ``shift``: the callable a step's contact takes."""
        return lambda x, y: self(x, y, shift)

    def curvatures(self) -> tuple[float, float]:
        """``(A, B)`` of ``h ≈ A x² + B y²`` at the origin (eq. 3D.3 for the paraboloids)."""
        (ax, ay), (bx, by) = self.A.curvatures(), self.B.curvatures()
        return ax + bx, ay + by

    @property
    def moves(self) -> bool:
        """Whether the shape seen by the grid changes as the bodies roll (a material feature)."""
        return self.A.moves or self.B.moves

    @property
    def hertzian(self) -> bool:
        """Two paraboloids without features: eq. 3D.3 exactly."""
        return all(b.base is None and not b.features for b in (self.A, self.B))

    def check_cover(self, grid, key_of, shifts=(0.0, 0.0)) -> None:
        """Every table covers the grid (a table is not extrapolated): ``key_of(body)`` names the key."""
        gx = (grid.xl, grid.xl + grid.nx * grid.dx)
        gy = (grid.yl, grid.yl + grid.ny * grid.dy)
        for name, body in (("A", self.A), ("B", self.B)):
            if body.base is None:
                continue
            ex, ey = body.base.extent()
            for axis, have, need in (("x", ex, gx), ("y", ey, gy)):
                if have is not None and (have[0] > need[0] or have[1] < need[1]):
                    raise InputError(f"{key_of(name)}.{axis}", f"the {body.base.kind} table covers {axis} in "
                                                                f"[{have[0]:.6g}, {have[1]:.6g}] but the grid needs "
                                                                f"[{need[0]:.6g}, {need[1]:.6g}] (length units; tables "
                                                                "are not extrapolated)")


# =========================================================================== parsing
def _radius(key, v) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or math.isnan(v) or v == 0:
        raise InputError(key, f"must be a nonzero number (> 0 convex, < 0 concave, inf for a straight generator), "
                              f"got {v!r}")
    return float(v)


def parse_body(table: dict, key: str) -> BodyShape:
    """A :class:`BodyShape` from a body's ``radius``, ``radius_y`` and ``profile`` (module docstring).

    No profile: both radii are required. A ``lateral`` base replaces ``radius_y`` (give ``radius``, not
    ``radius_y``); a ``surface`` replaces both; features alone add to the paraboloid of both radii.
    """
    prof = table.get("profile")
    items = [] if prof is None else ([prof] if isinstance(prof, dict) else prof)
    if not isinstance(items, (list, tuple)) or not all(isinstance(i, dict) for i in items):
        raise InputError(f"{key}.profile", "must be an inline table such as { kind = \"lateral\", y = [...], z = [...] } "
                                           f"or an array of them (kinds: {', '.join(PROFILE_KINDS)}), got {prof!r}")
    bases, feats = [], []
    for i, item in enumerate(items):
        k = f"{key}.profile" if len(items) == 1 else f"{key}.profile[{i}]"
        kind = item.get("kind")
        kinds = PROFILE_KINDS + tuple(_FEATURES)
        if not isinstance(kind, str) or kind not in kinds:
            raise InputError(f"{k}.kind", f"must be one of {', '.join(map(repr, kinds))} in a 3D scene, got "
                                          f"{kind!r}{suggestion(kind, kinds)}")
        for name in item:
            if name != "kind" and name not in _KEYS[kind]:
                raise InputError(f"{k}.{name}", f"unknown key for a {kind} profile{suggestion(name, _KEYS[kind])} "
                                                f"(allowed: kind, {', '.join(_KEYS[kind])})")
        (bases if kind in ("lateral", "surface") else feats).append((k, kind, item))
    if len(bases) > 1:
        raise InputError(f"{key}.profile", "at most one lateral or surface table (it is the body's base shape)")
    base_kind = bases[0][1] if bases else None
    need = {None: ("radius", "radius_y"), "lateral": ("radius",), "surface": ()}[base_kind]
    for r in ("radius", "radius_y"):
        if r in need and r not in table:
            raise InputError(f"{key}.{r}", "missing required key" + (f" (a {base_kind} profile needs radius)"
                                                                      if base_kind else ""))
        if r not in need and r in table:
            raise InputError(f"{key}.{r}", f"must be absent: the {base_kind} profile gives the shape "
                                           f"{'across y' if base_kind == 'lateral' else 'in x and y'}")
    rx = _radius(f"{key}.radius", table["radius"]) if "radius" in table else None
    ry = _radius(f"{key}.radius_y", table["radius_y"]) if "radius_y" in table else None
    base = None
    if bases:
        k, kind, item = bases[0]
        base = _lateral(k, item) if kind == "lateral" else _surface(k, item)
    out = []
    for k, kind, item in feats:
        if kind == "flat" and (rx is None or math.isinf(rx) or rx < 0):
            raise InputError(f"{k}.kind", "a flat is cut into the rolling radius: the body needs a finite radius > 0")
        if kind in _FEATURES:
            out.append(_FEATURES[kind][1](k, {n: v for n, v in item.items() if n != "kind"}, rx))
            continue
        out.append(_defect(k, item) if kind == "defect" else _flat(k, item, rx))
    return BodyShape(rx, ry, base, tuple(out))


def _need(key, item, names, kind):
    for n in names:
        if n not in item:
            raise InputError(f"{key}.{n}", f"missing: a {kind} profile needs {', '.join(names)}")


def _increasing(key, v):
    bad = np.flatnonzero(~(v[1:] > v[:-1]))
    if bad.size:
        i = int(bad[0]) + 1
        raise InputError(key, f"must be strictly increasing, but [{i}] = {float(v[i])!r} follows [{i - 1}] = "
                              f"{float(v[i - 1])!r}")


def _heights(key, z):
    if not np.all(np.isfinite(z)) or np.any(z < 0) or np.any(z > 1e6):
        i = int(np.flatnonzero(~((z >= 0) & (z <= 1e6)))[0])
        raise InputError(key, f"heights must be in [0, 1e6] (the distance from the tangent plane, length units), "
                              f"but entry {i} is {float(z.flat[i])!r}")


def _lateral(key, item) -> Lateral:
    _need(key, item, ("y", "z"), "lateral")
    y = np.asarray(real_sequence(f"{key}.y", item["y"], MAX_POINTS))
    z = np.asarray(real_sequence(f"{key}.z", item["z"], MAX_POINTS))
    if not 2 <= y.size:
        raise InputError(f"{key}.y", f"needs at least 2 points, got {y.size}")
    if z.size != y.size:
        raise InputError(f"{key}.z", f"must have as many entries as {key}.y ({y.size}), got {z.size}")
    _increasing(f"{key}.y", y)
    _heights(f"{key}.z", z)
    how = choice(f"{key}.interpolation", item.get("interpolation", "spline"), INTERPOLATIONS)
    return Lateral(tuple(map(float, y)), tuple(map(float, z)), how)


def _surface(key, item) -> Surface:
    _need(key, item, ("x", "y", "z"), "surface")
    x = np.asarray(real_sequence(f"{key}.x", item["x"], 10_000))
    y = np.asarray(real_sequence(f"{key}.y", item["y"], 10_000))
    for k, v in (("x", x), ("y", y)):
        if v.size < 2:
            raise InputError(f"{key}.{k}", f"needs at least 2 points, got {v.size}")
        _increasing(f"{key}.{k}", v)
    rows = item["z"]
    if not isinstance(rows, (list, tuple)) or len(rows) != y.size or x.size * y.size > MAX_SURFACE_POINTS:
        raise InputError(f"{key}.z", f"must be {y.size} rows (one per y) of {x.size} heights (one per x), got "
                                     f"{type(rows).__name__ if not isinstance(rows, (list, tuple)) else len(rows)} rows")
    z = np.empty((y.size, x.size))
    for j, r in enumerate(rows):
        row = real_sequence(f"{key}.z[{j}]", r, x.size)
        if len(row) != x.size:
            raise InputError(f"{key}.z[{j}]", f"must hold {x.size} heights (one per x), got {len(row)}")
        z[j] = row
    _heights(f"{key}.z", z)
    how = choice(f"{key}.interpolation", item.get("interpolation", "spline"), INTERPOLATIONS)
    return Surface(tuple(map(float, x)), tuple(map(float, y)), tuple(tuple(map(float, r)) for r in z), how)


def _frame(key, item):
    return choice(f"{key}.frame", item.get("frame", "material"), ("material", "contact"))


def _defect(key, item) -> Defect3D:
    _need(key, item, ("x", "depth", "length", "width"), "defect")
    return Defect3D(finite_real(f"{key}.x", item["x"]), finite_real(f"{key}.y", item.get("y", 0.0)),
                    finite_real(f"{key}.depth", item["depth"]), positive_real(f"{key}.length", item["length"]),
                    positive_real(f"{key}.width", item["width"]),
                    choice(f"{key}.shape", item.get("shape", "cosine"), tuple(DEFECT_SHAPES)), _frame(key, item))


def _flat(key, item, radius) -> Flat3D:
    _need(key, item, ("x", "length"), "flat")
    length = positive_real(f"{key}.length", item["length"])
    if not length < radius:
        raise InputError(f"{key}.length", f"must be below the radius {radius!r}, got {length!r}")
    return Flat3D(finite_real(f"{key}.x", item["x"]), length, float(radius), _frame(key, item))
