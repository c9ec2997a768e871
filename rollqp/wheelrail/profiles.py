r"""Wheel and rail profiles: CONTACT's profile files read, checked and brought into one canonical form.

A profile is the lateral cross-section of a rail or of a wheel (its generating curve), a list of points
``(y, z)``. Two file forms are read (docs/wheel-rail.md):

* SIMPACK's ``.prr`` (rail) and ``.prw`` (wheel) files, the form of the Manchester benchmark's profiles:
  ``header.begin … header.end`` (``type`` 0 rail, 1 wheel), ``spline.begin … spline.end`` with the
  processing options ``shift.y``, ``shift.z``, ``rotate``, ``bound.y.min/max``, ``bound.z.min/max``,
  ``mirror.y``, ``mirror.z``, ``units.len.f`` and the points between ``point.begin`` and ``point.end``
  (two or three numbers a row, the third a weight that is ignored); ``!`` starts a comment. The file's
  options are applied first, in SIMPACK's order (shift, rotation, clipping, mirroring, units), then the
  scene's own mirroring and scaling — as CONTACT does. Every other key (``file``, ``comment``, …) is
  read as text and never used: nothing from a file is executed or opened;
* a plain table of two numeric columns ``y z`` (spaces, tabs or commas; ``%``, ``!`` and ``#`` start
  comments), for any other file extension.

The **canonical form** is CONTACT's: lengths in mm, ``z`` pointing *down* (out of the wheel, into the
rail), a *right-side* profile with ``y`` increasing towards the field side; points are stored with ``y``
ascending. A rail's head is then its lowest ``z`` and a wheel's flange is on the low-``y`` side.

Checks, each a one-line :class:`~rollqp.errors.InputError` naming the file and, where one row is at
fault, its line: a row that is not two or three finite numbers; fewer than 4 points; a lateral
coordinate that is not strictly monotone (which also excludes loops: a curve whose ``y`` is monotone
cannot cross itself); a total length outside 5–500 mm (a unit error: CONTACT's bounds); a wheel whose
flange is on the field side (mirroring forgotten).

The surface between the points is a cubic spline in the summed chord length ``s`` (``z(s)`` a cubic
spline, ``y(s)`` monotone piecewise-cubic, so that the lateral coordinate stays monotone), or, with
``smooth = L > 0`` (mm), the weighted smoothing spline that halves fluctuations of wavelength ``L``
(CONTACT's ``ismooth = 1``: penalty ``λ = (L/2π)⁴`` on ``∫ f''² ds``, weights the chord lengths),
sampled every :data:`SAMPLE` mm for the contact search.

Examples
--------
>>> import numpy as np
>>> y = np.linspace(-30.0, 30.0, 61)
>>> p = Profile.from_points(y, y ** 2 / 600.0, kind="rail", name="crown")
>>> round(float(p.z_at(np.array([6.0]))[0]), 6), round(float(p.slope_at(np.array([6.0]))[0]), 6)
(0.06, 0.02)
"""
from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError

__all__ = ["Profile", "read_profile", "resolve_file", "SAMPLE", "MAX_FILE_BYTES"]

#: Arc-length spacing (mm) of the sampled spline used by the contact search: the chord error of a
#: curve of radius R between samples is SAMPLE²/(8R), 5e-8 mm on a 60 mm flange root — far below the
#: approaches (~0.01 mm) the patches see.
SAMPLE = 0.02
#: Largest profile file read (bytes): measured profiles have a few thousand rows.
MAX_FILE_BYTES = 4 << 20
#: Summed chord length allowed (mm), CONTACT's check of the units.
LENGTH_RANGE = (5.0, 500.0)
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?"


@dataclass(frozen=True)
class Profile:
    """A profile in canonical form (module docstring): points ``y`` (ascending), ``z`` (mm, down), and
    the sampled spline ``ys``, ``zs``, ``dzs`` (``dz/dy``) used for evaluation.

    ``kind`` is ``"rail"`` or ``"wheel"``; ``name`` the file it came from (for messages).
    """

    y: np.ndarray
    z: np.ndarray
    kind: str
    name: str
    smooth: float = 0.0
    ys: np.ndarray = field(repr=False, default=None)
    zs: np.ndarray = field(repr=False, default=None)
    dzs: np.ndarray = field(repr=False, default=None)

    @classmethod
    def from_points(cls, y, z, kind: str, name: str = "<points>", smooth: float = 0.0, rows=None) -> "Profile":
        """The profile through points ``(y, z)`` already in canonical orientation (any order of ``y``),
        checked (module docstring); ``rows``: the file line of each point, for messages."""
        if kind not in ("rail", "wheel"):
            raise InputError("kind", f"must be 'rail' or 'wheel', got {kind!r}")
        y = np.asarray(y, dtype=float).ravel()
        z = np.asarray(z, dtype=float).ravel()
        rows = np.arange(1, y.size + 1) if rows is None else np.asarray(rows)
        if y.size != z.size:
            raise InputError(name, f"y and z must have the same length, got {y.size} and {z.size}")
        if y.size < 4:
            raise InputError(name, f"a profile needs at least 4 points, got {y.size}")
        bad = ~(np.isfinite(y) & np.isfinite(z))
        if bad.any():
            raise InputError(name, f"row {int(rows[np.argmax(bad)])}: not a finite number")
        if y[-1] < y[0]:
            y, z, rows = y[::-1], z[::-1], rows[::-1]
        dy = np.diff(y)
        if np.any(dy <= 0):
            i = int(np.argmax(dy <= 0)) + 1
            raise InputError(name, f"row {int(rows[i])}: the lateral coordinate y = {y[i]:.6g} must be strictly "
                                   f"monotone along the profile (the row before has y = {y[i - 1]:.6g}); loops and "
                                   f"overhangs are not supported")
        length = float(np.sum(np.hypot(dy, np.diff(z))))
        if not LENGTH_RANGE[0] <= length <= LENGTH_RANGE[1]:
            raise InputError(name, f"the profile is {length:.6g} long; a rail or wheel profile in mm is between "
                                   f"{LENGTH_RANGE[0]:g} and {LENGTH_RANGE[1]:g} mm (wrong units? set the scale)")
        smooth = float(smooth)
        if not (math.isfinite(smooth) and smooth >= 0):
            raise InputError("smooth", f"must be a finite number >= 0 (mm), got {smooth!r}")
        if kind == "wheel":
            _check_flange_side(y, z, name)
        ys, zs, dzs = _sample(y, z, smooth, name)
        return cls(y, z, kind, name, smooth, ys, zs, dzs)

    # ------------------------------------------------------------------ evaluation
    @property
    def span(self) -> tuple[float, float]:
        """``(y_min, y_max)`` of the profile."""
        return float(self.ys[0]), float(self.ys[-1])

    def z_at(self, y) -> np.ndarray:
        """``z(y)`` of the spline (nan outside the profile)."""
        y = np.asarray(y, dtype=float)
        return np.interp(y, self.ys, self.zs, left=np.nan, right=np.nan)

    def slope_at(self, y) -> np.ndarray:
        """``dz/dy`` of the spline (nan outside the profile)."""
        y = np.asarray(y, dtype=float)
        return np.interp(y, self.ys, self.dzs, left=np.nan, right=np.nan)

    def mirrored(self) -> "Profile":
        """The profile mirrored in ``y`` (a left-side profile of a right-side one)."""
        return Profile(-self.y[::-1], self.z[::-1], self.kind, self.name, self.smooth, -self.ys[::-1],
                       self.zs[::-1], -self.dzs[::-1])


def _check_flange_side(y, z, name):
    """A wheel's flange (its deepest point, if it reaches 10 mm below the tread's median height) lies on
    the track-centre side: the low-``y`` side of a right wheel."""
    top = float(np.max(z))
    if top - float(np.median(z)) > 10.0 and y[int(np.argmax(z))] > 0.5 * (y[0] + y[-1]):
        raise InputError(name, "the wheel's flange is on the field side (y increasing towards it): a right-side "
                               "wheel profile has its flange at low y; mirror it (mirror_y = true)")


def _sample(y, z, smooth, name):
    """The spline (module docstring) sampled every :data:`SAMPLE` mm of arc length: ``(ys, zs, dz/dy)``."""
    from scipy.interpolate import CubicSpline, PchipInterpolator, make_smoothing_spline
    s = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(y), np.diff(z)))])
    if smooth > 0:
        w = np.gradient(s)            # the chord lengths δs_i = (s_{i+1} − s_{i−1})/2 as weights
        lam = (smooth / (2 * math.pi)) ** 4
        fy, fz = make_smoothing_spline(s, y, w=w, lam=lam), make_smoothing_spline(s, z, w=w, lam=lam)
    else:
        fy, fz = PchipInterpolator(s, y), CubicSpline(s, z)
    ss = np.linspace(0.0, s[-1], max(int(math.ceil(s[-1] / SAMPLE)) + 1, 2 * y.size))
    ys, zs = fy(ss), fz(ss)
    dys, dzs = fy(ss, 1), fz(ss, 1)
    if np.any(np.diff(ys) <= 0):
        i = int(np.argmax(np.diff(ys) <= 0))
        raise InputError(name, f"the smoothed profile is not monotone in y near y = {ys[i]:.4g} (smooth = "
                               f"{smooth:g} mm is too strong for its steep faces)")
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = np.where(dys > 0, dzs / np.where(dys > 0, dys, 1.0), np.sign(dzs) * 1e6)
    return ys, zs, np.clip(slope, -1e6, 1e6)


# ---------------------------------------------------------------------- files
def resolve_file(name, key: str, folder=None) -> Path:
    """The path of the file ``name`` relative to ``folder`` (the scene file's folder; default the working
    folder), refused if it is absolute, leads outside that folder, or is not a readable file."""
    if not isinstance(name, str) or not name or len(name) > 4096 or "\0" in name:
        shown = repr(name)[:80] if isinstance(name, str) else type(name).__name__
        raise InputError(key, f"must be a file name beside the scene file, got {shown}")
    try:
        base = Path(folder if folder is not None else os.getcwd()).resolve()
        path = (base / name).resolve()
    except (OSError, RuntimeError, ValueError) as exc:
        raise InputError(key, f"{name[:80]!r} cannot be resolved to a file ({type(exc).__name__})") from None
    if Path(name).is_absolute() or not path.is_relative_to(base):
        raise InputError(key, f"{name!r} must be a file inside the scene file's folder ({base})")
    try:
        if not path.is_file():
            raise InputError(key, f"no such file: {name!r} (looked in {base})")
        if path.stat().st_size > MAX_FILE_BYTES:
            raise InputError(key, f"{name!r} is larger than {MAX_FILE_BYTES >> 20} MiB")
    except OSError as exc:
        raise InputError(key, f"cannot read {name!r} ({exc.strerror or exc})") from None
    return path


def read_profile(path, kind: str, mirror_y: bool = False, mirror_z: bool = False, scale: float = 1.0,
                 smooth: float = 0.0, name: str | None = None) -> Profile:
    """Read a profile file (module docstring) into canonical form.

    Parameters
    ----------
    path : path
        The file (already resolved: :func:`resolve_file`).
    kind : {"rail", "wheel"}
    mirror_y, mirror_z : bool
        Mirror the lateral / vertical coordinate after the file's own options.
    scale : float
        Multiplies both coordinates (e.g. 1000 for a table in metres).
    smooth : float
        Wavelength (mm) of the smoothing spline; 0: the interpolating spline.
    """
    path = Path(path)
    name = name or path.name
    for key, v in (("mirror_y", mirror_y), ("mirror_z", mirror_z)):
        if not isinstance(v, bool):
            raise InputError(key, f"must be true or false, got {v!r}")
    if isinstance(scale, bool) or not isinstance(scale, (int, float)) or not (math.isfinite(scale) and scale > 0):
        raise InputError("scale", f"must be a finite number > 0, got {scale!r}")
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise InputError(name, f"cannot read ({exc.strerror or exc})") from None
    if len(raw) > MAX_FILE_BYTES:
        raise InputError(name, f"larger than {MAX_FILE_BYTES >> 20} MiB")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")
    if "\0" in text:
        raise InputError(name, "a binary file, not a profile")
    lines = text.splitlines()
    if path.suffix.lower() in (".prr", ".prw"):
        y, z, rows = _read_simpack(lines, name, kind, path.suffix.lower())
    else:
        y, z, rows = _read_table(lines, name)
    if mirror_y:
        y = -y
    if mirror_z:
        z = -z
    return Profile.from_points(y * scale, z * scale, kind, name=name, smooth=smooth, rows=rows)


def _numbers(line: str, name: str, row: int, counts=(2,)) -> list[float]:
    parts = [p for p in re.split(r"[\s,;]+", line.strip()) if p]
    if len(parts) not in counts or not all(re.fullmatch(_NUMBER, p) for p in parts):
        want = " or ".join(str(c) for c in counts)
        raise InputError(name, f"row {row}: expected {want} numbers, got {line.strip()[:60]!r}")
    vals = [float(p.replace("d", "e").replace("D", "e")) for p in parts]
    if not all(math.isfinite(v) for v in vals):
        raise InputError(name, f"row {row}: not a finite number: {line.strip()[:60]!r}")
    return vals


def _strip(line: str, marks: str) -> str:
    cut = min((i for i in (line.find(m) for m in marks) if i >= 0), default=-1)
    return line if cut < 0 else line[:cut]


def _read_table(lines, name):
    ys, zs, rows = [], [], []
    for i, line in enumerate(lines, start=1):
        body = _strip(line, "%!#").strip()
        if not body:
            continue
        y, z = _numbers(body, name, i)
        ys.append(y)
        zs.append(z)
        rows.append(i)
    if not ys:
        raise InputError(name, "holds no rows of two numbers y, z")
    return np.array(ys), np.array(zs), np.array(rows)


#: The SIMPACK options used (and their defaults); every other key is ignored.
_SIMPACK_OPTIONS = {"type": None, "shift.y": 0.0, "shift.z": 0.0, "rotate": 0.0, "bound.y.min": 1.0,
                    "bound.y.max": 0.0, "bound.z.min": 1.0, "bound.z.max": 0.0, "mirror.y": 0.0, "mirror.z": 0.0,
                    "units.len.f": 1000.0, "units.ang.f": 1.0}


def _read_simpack(lines, name, kind, suffix):
    opts = dict(_SIMPACK_OPTIONS)
    ys, zs, rows = [], [], []
    inside = done = header = False
    for i, line in enumerate(lines, start=1):
        body = _strip(line, "!").strip()
        if not body:
            continue
        low = body.lower()
        if low in ("header.begin", "header.end"):
            header = low == "header.begin"
            continue
        if low == "point.begin":
            inside = True
            continue
        if low == "point.end":
            inside, done = False, True
            continue
        if inside:
            y, z = _numbers(body, name, i, counts=(2, 3))[:2]
            ys.append(y)
            zs.append(z)
            rows.append(i)
            continue
        m = re.fullmatch(r"([A-Za-z][\w.]*)\s*=\s*(.*)", body)
        if m and m.group(1).lower() in opts and (m.group(1).lower() == "type") == header:
            key = m.group(1).lower()
            value = m.group(2).strip()
            if not re.fullmatch(_NUMBER, value):
                raise InputError(name, f"row {i}: {key} must be a number, got {value[:40]!r}")
            opts[key] = float(value.replace("d", "e").replace("D", "e"))
    if inside and not done:
        raise InputError(name, "point.begin without point.end")
    if not ys:
        raise InputError(name, "no points (a SIMPACK profile lists them between point.begin and point.end)")
    expect = 0 if suffix == ".prr" else 1
    if opts["type"] is not None and int(opts["type"]) != expect:
        raise InputError(name, f"header type = {int(opts['type'])} but a {suffix} file is a "
                               f"{'rail (0)' if expect == 0 else 'wheel (1)'} profile")
    if (kind == "rail") != (suffix == ".prr"):
        raise InputError(name, f"a {suffix} file holds a {'rail' if suffix == '.prr' else 'wheel'} profile, "
                               f"used here as the {kind} profile")
    y, z, rows = np.array(ys), np.array(zs), np.array(rows)
    y, z = y + opts["shift.y"], z + opts["shift.z"]
    if opts["rotate"]:
        a = opts["rotate"] / opts["units.ang.f"]
        y, z = math.cos(a) * y - math.sin(a) * z, math.sin(a) * y + math.cos(a) * z
    keep = np.ones(y.size, dtype=bool)
    if opts["bound.y.min"] < opts["bound.y.max"]:
        keep &= (y >= opts["bound.y.min"]) & (y <= opts["bound.y.max"])
    if opts["bound.z.min"] < opts["bound.z.max"]:
        keep &= (z >= opts["bound.z.min"]) & (z <= opts["bound.z.max"])
    y, z, rows = y[keep], z[keep], rows[keep]
    if opts["mirror.y"] == 1:
        y = -y
    if opts["mirror.z"] == 1:
        z = -z
    unit = opts["units.len.f"]
    if not unit > 0:
        raise InputError(name, f"units.len.f must be > 0, got {unit!r}")
    f = 1000.0 / unit                      # file lengths in 1/units.len.f m; canonical mm
    return y * f, z * f, rows
