"""Body profiles: each body's undeformed surface near the contact, and the features that roll with it.

A body's profile gives the height ``z(x)`` of its undeformed surface above the common tangent
line, at the Eulerian coordinate ``x`` of the strip (positive away from the other body); the
undeformed gap of eq. 10 is ``h(x) = z_A(x) + z_B(x)`` (docs/formulation.md §1, docs/kinematics.md).
A profile is the body's **base** shape plus **features**:

* base ``circle`` (the default): ``z = x²/(R(1 + √(1 − (x/R)²)))``, the round roller of
  :func:`rollqp.influence.halfspace.undeformed_gap`, bit for bit;
* base ``table`` with ``frame = "contact"``: the whole shape ``z(x)`` as points (inline or a
  CSV/npz file of ``x, h``), fixed in the contact frame (a punch, a crowned or worn shape that
  does not rotate with the body), piecewise-linear between the points;
* features attached to the body's **material** (they move through the contact as it rolls):
  ``flat`` (a chord of given length cut into the circle: a wheel flat), ``defect`` (a dent,
  ``depth > 0``, or a bump, ``depth < 0``, of given width and shape) and ``table`` with
  ``frame = "material"`` (a deviation from the circle as a function of the material coordinate:
  out-of-roundness, roughness). A feature at material coordinate ``s`` is at
  ``x = s + d·q`` after a rolled distance ``q`` (``d`` = ``load.direction``), so its deviation
  at ``x`` is ``dz(x − d·q)``.

:class:`Profile` is the public object (``Profile.gap(x, shift)``, ``Profile.moves``);
:func:`parse_profile` builds one from a scene's ``bodies.<A|B>.profile`` (one inline table or an
array of them), every invalid value an :class:`~rollqp.errors.InputError` naming the key.
Kinds are registered in :data:`FEATURE_KINDS` (:func:`register`). Files are read only from the
scene file's folder, never outside the working folder, never executed.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from ..errors import InputError
from ..validate import choice, finite_real, positive_real, real_sequence, suggestion
from ..npzfile import read_npz
from ..npzfile import real_array

__all__ = ["Profile", "Feature", "Table", "Flat", "Defect", "FEATURE_KINDS", "register", "parse_profile",
           "circle_height", "DEFECT_SHAPES"]

#: Largest profile table (points): a rough surface sampled at 10^6 points fits.
MAX_POINTS = 1_000_000
#: Largest profile file read (bytes).
MAX_FILE_BYTES = 64 << 20
#: Shapes of a ``defect``, ``φ(u)`` on ``|u| < 1`` (``u`` = distance from the centre over half the width).
DEFECT_SHAPES = {
    "cosine": lambda u: 0.5 * (1.0 + np.cos(np.pi * u)),   # smooth bell, zero slope at the rim
    "parabolic": lambda u: 1.0 - u * u,                     # a spherical-cap dent: slope jumps at the rim
    "flat": lambda u: np.ones_like(u),                      # a step: a pit or a plateau
}


def circle_height(x, radius: float) -> np.ndarray:
    """``z = x²/(R(1 + √(1 − (x/R)²)))``: a circle of radius R touching the tangent line at x = 0.

    The same expression, term for term, as the half-space model's undeformed gap, so that circle
    profiles reproduce it bitwise.
    """
    x = np.asarray(x, dtype=float)
    u = x / radius
    return x * x / (radius * (1.0 + np.sqrt(1.0 - u * u)))


# =========================================================================== features
class Feature:
    """One part of a profile: a base shape (``frame = "contact"``) or a material feature.

    Subclasses are frozen dataclasses with ``kind``, ``to_dict()``, ``height(s)`` and ``extent()``; material
    features (``material = True``) are evaluated at the material coordinate ``s = x − d·q``. The scene
    checks a feature through :meth:`extent` only (:func:`check_cover`): a feature that is zero outside its
    extent (``covers = False``, the default) must be narrower than the potential contact zone; one that is
    defined only on its extent (``covers = True``, a table) must cover what the strip sees.
    """

    kind: ClassVar[str] = ""
    material: ClassVar[bool] = True
    #: ``True``: defined on :meth:`extent` only, which must cover the strip; ``False``: zero outside it.
    covers: ClassVar[bool] = False
    #: The key named when the extent is too wide (``"width"``, ``"length"``, …).
    extent_key: ClassVar[str] = "width"

    def height(self, s) -> np.ndarray:  # pragma: no cover - abstract
        """Height (base) or deviation from the circle (material feature) at ``s``, length units."""
        raise NotImplementedError

    def extent(self) -> tuple[float, float]:  # pragma: no cover - abstract
        """The interval of ``s`` outside which the feature is zero (a base: where it is defined)."""
        raise NotImplementedError

    def to_dict(self) -> dict:
        return {"kind": self.kind, **{k: (list(v) if isinstance(v, tuple) else v)
                                      for k, v in self.__dict__.items() if v is not None}}


@dataclass(frozen=True)
class Table(Feature):
    """A piecewise-linear profile through the points ``(x[i], h[i])`` (``x`` strictly increasing).

    ``frame = "contact"``: the body's whole shape in the contact frame (replaces the circle);
    ``frame = "material"``: a deviation from the circle at the material coordinate (rolls through).
    Evaluated only inside ``[x[0], x[-1]]``: the scene checks that the points cover what the
    strip sees (:func:`check_cover`).
    """

    x: tuple
    h: tuple
    frame: str = "contact"
    kind: ClassVar[str] = "table"
    covers: ClassVar[bool] = True
    extent_key: ClassVar[str] = "x"

    @property
    def material(self):  # type: ignore[override]
        return self.frame == "material"

    def height(self, s):
        return np.interp(np.asarray(s, dtype=float), self.x, self.h)

    def extent(self):
        return self.x[0], self.x[-1]

    def to_dict(self):
        return {"kind": "table", "x": list(self.x), "h": list(self.h), "frame": self.frame}


@dataclass(frozen=True)
class Flat(Feature):
    """A wheel flat: the chord of ``length`` centred at material coordinate ``position``.

    Deviation from the circle of radius R (small angles): ``((l/2)² − (s − s0)²)/(2R)`` on the
    chord, zero outside; on the contact centre the surface is then straight, ``z = l²/(8R)``.
    """

    length: float
    position: float
    radius: float
    kind: ClassVar[str] = "flat"
    extent_key: ClassVar[str] = "length"

    def __post_init__(self):
        if not self.length < self.radius:
            raise InputError("length", f"a flat must be shorter than the radius {self.radius!r}, got {self.length!r}")

    def height(self, s):
        u = np.asarray(s, dtype=float) - self.position
        half = 0.5 * self.length
        inside = np.abs(u) < half
        u = np.where(inside, u, 0.0)  # far from the flat (a position of 1e308): no u² to overflow
        return np.where(inside, (half * half - u * u) / (2.0 * self.radius), 0.0)

    def extent(self):
        return self.position - 0.5 * self.length, self.position + 0.5 * self.length

    def to_dict(self):
        return {"kind": "flat", "length": self.length, "position": self.position}


@dataclass(frozen=True)
class Defect(Feature):
    """A dent (``depth > 0``: material removed, the gap opens) or bump (``depth < 0``) at ``position``.

    Deviation ``depth·φ(2(s − s0)/width)`` with ``φ`` one of :data:`DEFECT_SHAPES`, zero for
    ``|s − s0| ≥ width/2``. ``depth = 0`` is the circle exactly.
    """

    depth: float
    width: float
    position: float
    shape: str = "cosine"
    kind: ClassVar[str] = "defect"

    def height(self, s):
        with np.errstate(over="ignore"):  # far from the defect u overflows to ±inf: outside, as it should be
            u = 2.0 * (np.asarray(s, dtype=float) - self.position) / self.width
        inside = np.abs(u) < 1.0
        return np.where(inside, self.depth * DEFECT_SHAPES[self.shape](np.where(inside, u, 0.0)), 0.0)

    def extent(self):
        return self.position - 0.5 * self.width, self.position + 0.5 * self.width

    def to_dict(self):
        return {"kind": "defect", "depth": self.depth, "width": self.width, "position": self.position,
                "shape": self.shape}


# =========================================================================== the profile
@dataclass(frozen=True)
class Profile:
    """A body's undeformed shape: a base (the circle of ``radius``, or a contact-frame table) and features.

    Parameters
    ----------
    radius : float
        The body's radius (the circle, and the curvature a flat is cut into).
    features : tuple of Feature
        At most one contact-frame :class:`Table` (it replaces the circle) and any number of
        material features.

    Examples
    --------
    >>> from rollqp.profiles import Profile, Table
    >>> rough = Profile(150.0, (Table((-2.0, 0.0, 2.0), (0.0, 1e-4, 0.0), frame="material"),))
    >>> z = rough.gap([-0.5, 0.0, 0.5], shift=0.1)   # circle + deviation at s = x − shift
    """

    radius: float
    features: tuple = ()

    @property
    def base(self) -> Table | None:
        """The contact-frame table replacing the circle, or None (a circle)."""
        for f in self.features:
            if not f.material:
                return f
        return None

    @property
    def moves(self) -> bool:
        """Whether the shape seen by the strip changes as the body rolls (a material feature)."""
        return any(f.material for f in self.features)

    @property
    def is_circle(self) -> bool:
        return not self.features

    def gap(self, x, shift: float = 0.0) -> np.ndarray:
        """Height ``z(x)`` of the undeformed surface when the material has moved by ``shift`` (= d·q).

        Parameters
        ----------
        x : array_like
            Contact-frame coordinates (length units).
        shift : float
            Displacement of the body's material along +x since q = 0, ``d·q``: a material
            feature at ``s`` is then at ``x = s + shift``.
        """
        x = np.asarray(x, dtype=float)
        base = self.base
        z = circle_height(x, self.radius) if base is None else base.height(x)
        for f in self.features:
            if f.material:
                z = z + f.height(x - shift)
        return z

    def to_dict(self) -> list | None:
        """The scene's ``profile`` value (None: a circle)."""
        return [f.to_dict() for f in self.features] if self.features else None


# =========================================================================== parsing
FEATURE_KINDS: dict[str, type] = {"circle": None, "table": Table, "flat": Flat, "defect": Defect}
_KEYS = {"circle": (), "table": ("x", "h", "file", "frame"), "flat": ("length", "position"),
         "defect": ("depth", "width", "position", "shape")}


def register(kind: str, cls: type, keys: tuple, parse) -> None:
    """Add a feature kind: ``parse(key, values, radius, folder) -> Feature`` builds it from its table."""
    FEATURE_KINDS[kind] = cls
    _KEYS[kind] = tuple(keys)
    _PARSERS[kind] = parse


def parse_profile(obj: Any, key: str, radius: float, folder: str | os.PathLike | None = None) -> Profile:
    """A :class:`Profile` from a scene's ``bodies.<X>.profile``: one inline table, an array of them, or None.

    Parameters
    ----------
    obj : None, dict, list of dict or Profile
    key : str
        The scene key (``"bodies.A.profile"``), named in every error.
    radius : float
        The body's radius.
    folder : path, optional
        The scene file's folder: a table's ``file`` is read from there only (default: the working
        folder).
    """
    if isinstance(obj, Profile):
        return obj
    if obj is None:
        return Profile(radius)
    items = [obj] if isinstance(obj, dict) else obj
    if not isinstance(items, (list, tuple)) or not all(isinstance(i, dict) for i in items):
        raise InputError(key, "must be an inline table such as { kind = \"defect\", depth = 1e-3, width = 0.5, "
                              f"position = 2.0 }} or an array of them (kinds: {', '.join(FEATURE_KINDS)}), got {obj!r}")
    feats = []
    for i, item in enumerate(items):
        k = key if len(items) == 1 else f"{key}[{i}]"
        f = _parse_one(item, k, radius, folder)
        if f is not None:
            feats.append(f)
    if sum(not f.material for f in feats) > 1:
        raise InputError(key, "at most one table with frame = 'contact' (it is the body's whole shape)")
    return Profile(float(radius), tuple(feats))


def _parse_one(item: dict, key: str, radius: float, folder):
    kind = item.get("kind")
    if not isinstance(kind, str) or kind not in FEATURE_KINDS:  # a list or a table is no kind (nor hashable)
        raise InputError(f"{key}.kind", f"must be one of {', '.join(map(repr, FEATURE_KINDS))}, got {kind!r}"
                         + suggestion(kind, FEATURE_KINDS))
    for k in item:
        if k != "kind" and k not in _KEYS[kind]:
            raise InputError(f"{key}.{k}", f"unknown key for a {kind} profile{suggestion(k, _KEYS[kind])} "
                                           f"(allowed: kind, {', '.join(_KEYS[kind]) or 'nothing else'})")
    values = {k: v for k, v in item.items() if k != "kind"}
    return _PARSERS[kind](key, values, radius, folder)


def _need(key, values, names, kind):
    for n in names:
        if n not in values:
            raise InputError(f"{key}.{n}", f"missing: a {kind} profile needs {', '.join(names)}")


def _parse_table(key, values, radius, folder):
    frame = choice(f"{key}.frame", values.get("frame", "contact"), ("contact", "material"))
    if "file" in values:
        if "x" in values or "h" in values:
            raise InputError(f"{key}.file", "give either file or the points x and h, not both")
        x, h = read_profile_file(values["file"], f"{key}.file", folder)
    else:
        _need(key, values, ("x", "h"), "table")
        x = np.asarray(real_sequence(f"{key}.x", values["x"], MAX_POINTS))
        h = np.asarray(real_sequence(f"{key}.h", values["h"], MAX_POINTS))
    xkey, hkey = (f"{key}.file", f"{key}.file") if "file" in values else (f"{key}.x", f"{key}.h")
    if not 2 <= x.size <= MAX_POINTS:
        raise InputError(xkey, f"needs 2 to {MAX_POINTS} points, got {x.size}")
    if h.size != x.size:
        raise InputError(hkey, f"must have as many entries as {key}.x ({x.size}), got {h.size}")
    bad = np.flatnonzero(~(x[1:] > x[:-1]))  # compared, not subtracted: no overflow at ±1e308
    if bad.size:
        i = int(bad[0]) + 1
        raise InputError(xkey, f"x must be strictly increasing, but x[{i}] = {float(x[i])!r} follows "
                               f"x[{i - 1}] = {float(x[i - 1])!r}")
    big = np.flatnonzero(~(np.abs(h) <= radius))
    if big.size:  # a height beyond the radius is no roller's surface (and 1e308 overflows the gap)
        i = int(big[0])
        raise InputError(hkey, f"heights must be within ±radius = ±{radius:.6g} (length units), but h[{i}] = "
                               f"{float(h[i])!r}")
    return Table(tuple(map(float, x)), tuple(map(float, h)), frame)


def _parse_flat(key, values, radius, folder):
    _need(key, values, ("length", "position"), "flat")
    length = positive_real(f"{key}.length", values["length"])
    if not length < radius:
        raise InputError(f"{key}.length", f"must be below the radius {radius!r}, got {length!r}")
    return Flat(length, finite_real(f"{key}.position", values["position"]), float(radius))


def _parse_defect(key, values, radius, folder):
    _need(key, values, ("depth", "width", "position"), "defect")
    return Defect(finite_real(f"{key}.depth", values["depth"]), positive_real(f"{key}.width", values["width"]),
                  finite_real(f"{key}.position", values["position"]),
                  choice(f"{key}.shape", values.get("shape", "cosine"), tuple(DEFECT_SHAPES)))


_PARSERS = {"circle": lambda key, values, radius, folder: None, "table": _parse_table, "flat": _parse_flat,
            "defect": _parse_defect}


def read_profile_file(name: Any, key: str, folder=None) -> tuple[np.ndarray, np.ndarray]:
    """``(x, h)`` from a CSV (two columns ``x, h``, ``#`` comments) or ``.npz`` (arrays ``x`` and ``h``) file.

    ``name`` is relative to ``folder`` (the scene file's folder; default the working folder) and
    must stay inside it and inside the working folder: no absolute paths, no ``..`` out of it, no
    links leading out.
    """
    if not isinstance(name, str) or not name or len(name) > 4096 or "\0" in name:
        shown = repr(name)[:80] if isinstance(name, str) else type(name).__name__
        raise InputError(key, f"must be a file name (a .csv or .npz file beside the scene file, no NUL character), "
                              f"got {shown}")
    try:
        base = Path(folder if folder is not None else os.getcwd()).resolve()
        cwd = Path(os.getcwd()).resolve()
        path = (base / name).resolve()
    except (OSError, RuntimeError, ValueError) as exc:  # a symbolic link loop (RuntimeError before 3.13)
        raise InputError(key, f"{name[:80]!r} cannot be resolved to a file ({type(exc).__name__}: "
                              f"{str(exc)[:80]})") from None
    if Path(name).is_absolute() or not (path.is_relative_to(base) and path.is_relative_to(cwd)):
        raise InputError(key, f"{name!r} must be a file inside the scene file's folder ({base}) and the working "
                              f"folder ({cwd})")
    if path.suffix.lower() not in (".csv", ".npz"):
        raise InputError(key, f"{name!r} must be a .csv or .npz file")
    try:
        if not path.is_file():
            raise InputError(key, f"no such file: {name!r} (looked in {base})")
        size = path.stat().st_size
    except OSError as exc:
        raise InputError(key, f"cannot read {name!r} ({exc.strerror or exc})") from None
    if size > MAX_FILE_BYTES:
        raise InputError(key, f"{name!r} is larger than {MAX_FILE_BYTES >> 20} MiB")
    if path.suffix.lower() == ".npz":
        z = read_npz(path, key)
        n = np.asarray(z.get("x", np.zeros(0))).size
        return real_array(z, "x", (n,), key), real_array(z, "h", (n,), key)
    return _read_csv(path, name, key)


def _read_csv(path, name, key) -> tuple[np.ndarray, np.ndarray]:
    """``(x, h)`` of a CSV of two numeric columns (``#`` comments); an empty file or one without a row of
    numbers is an error, not numpy's warning."""
    import warnings
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # numpy warns on a file without data rows: an error here
            data = np.loadtxt(path, delimiter=",", comments="#", dtype=float, ndmin=2)
    except UserWarning:
        raise InputError(key, f"{name!r} holds no rows of numbers x, h (an empty CSV file)") from None
    except (ValueError, OSError, UnicodeDecodeError) as exc:
        raise InputError(key, f"{name!r} is not a CSV of two numeric columns x, h ({str(exc)[:100]})") from None
    if data.shape[0] == 0:
        raise InputError(key, f"{name!r} holds no rows of numbers x, h (an empty CSV file)")
    if data.shape[1] != 2 or not np.all(np.isfinite(data)):
        raise InputError(key, f"{name!r} must have exactly two finite numeric columns x, h (got {data.shape[1]})")
    return data[:, 0].copy(), data[:, 1].copy()


# =========================================================================== scene checks
def check_cover(profile: Profile, key: str, strip_half: float, shifts: tuple[float, float], model) -> None:
    """A profile against its scene: only on a model that takes profiles; a feature defined on its extent
    (a table) covers what the strip sees; one that is zero outside its extent (a flat, a defect) is narrower
    than the zone (``2L``) — every feature asked through :meth:`Feature.extent` only.

    ``shifts`` is the range of ``d·q`` over the run: a material coordinate ``s = x − d·q`` with
    ``|x| ≤ L`` then lies in ``[−L − max, L − min]``. ``model``: the scene's influence model
    (:class:`rollqp.influence.Model`).
    """
    if profile.is_circle:
        return
    if not model.profiles:
        raise InputError(key, f"must be a circle (absent) with contact.model = {model.name!r}: its mesh is the "
                              "round roller's; profiles need a model that takes them (the half-space)")
    L = strip_half
    for i, f in enumerate(profile.features):
        k = key if len(profile.features) == 1 else f"{key}[{i}]"
        lo, hi = f.extent()
        if f.covers:
            need = (-L, L) if not f.material else (-L - shifts[1], L - shifts[0])
            if lo > need[0] or hi < need[1]:
                what = "the strip" if not f.material else "the material that passes through the strip"
                raise InputError(f"{k}.{f.extent_key}", f"the {f.kind} covers [{lo:.6g}, {hi:.6g}] but {what} needs "
                                                        f"[{need[0]:.6g}, {need[1]:.6g}] (length units)")
        elif not hi - lo < 2 * L:
            raise InputError(f"{k}.{f.extent_key}", f"must be in (0, {2 * L:.6g}) (narrower than the potential "
                                                    f"contact zone 2L = 2·zone·a_H), got {hi - lo!r}")
