r"""The track: where a rail profile lies in the track frame (docs/wheel-rail.md, "Frames").

The **track frame** is CONTACT's: ``x`` forward along the track, ``y`` to the right, ``z`` down, the
origin on the track centre line in the plane on top of the rails. Every computation is made for a
*right-side* wheel–rail pair; a left pair is its mirror image in ``y`` (:mod:`rollqp.wheelrail.solve`).

A rail profile (canonical form, :mod:`rollqp.wheelrail.profiles`) is rotated by the installation angle
``−cant`` (right rail; cant > 0 tilts the rail towards the track centre) about its origin, shifted up so
that its highest point touches the track plane ``z = 0``, and shifted laterally so that its gauge face —
the first point of the profile, from the track centre side, at ``gauge_height`` below the track plane —
lies at ``y = gauge/2`` (the gauge point computation of CONTACT's module 1).

Examples
--------
>>> import numpy as np
>>> from rollqp.wheelrail.profiles import Profile
>>> y = np.linspace(-36.0, 36.0, 145)
>>> head = Profile.from_points(y, 300.0 - np.sqrt(300.0 ** 2 - y ** 2) + 20 * (np.abs(y) > 35.9), "rail")
>>> t = Track(head, gauge=1435.0, gauge_height=1.0)      # the gauge face: 1 mm below the top
>>> round(t.rail_y0, 3), round(float(t.z_at(1435.0 / 2)), 6)
(741.974, 1.0)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError

__all__ = ["Track"]


def _finite(key, v, positive=False):
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or (positive and v <= 0):
        raise InputError(key, f"must be a finite number{' > 0' if positive else ''}, got {v!r}")
    return float(v)


@dataclass(frozen=True)
class Track:
    """A rail profile placed in the track frame of a right-side pair (module docstring).

    Parameters
    ----------
    rail : Profile
        The rail profile (canonical, right side).
    gauge : float
        Distance between the gauge faces of the two rails (``track.gauge``, mm).
    gauge_height : float
        Depth below the track plane at which the gauge is measured (``track.gauge_height``, default 14 mm).
    cant : float
        Rail inclination (rad) applied here; 0 when the profile is already inclined (as the benchmark's).
    """

    rail: object
    gauge: float = 1435.0
    gauge_height: float = 14.0
    cant: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "gauge", _finite("track.gauge", self.gauge, positive=True))
        object.__setattr__(self, "gauge_height", _finite("track.gauge_height", self.gauge_height, positive=True))
        cant = _finite("track.cant", self.cant)
        if abs(cant) > 0.2:
            raise InputError("track.cant", f"must be within ±0.2 rad (a rail inclination), got {cant!r}")
        object.__setattr__(self, "cant", cant)
        c, s = math.cos(-cant), math.sin(-cant)
        ys, zs = self.rail.ys, self.rail.zs
        yr, zr = c * ys - s * zs, s * ys + c * zs             # rotation about x (y → z positive)
        z0 = -float(np.min(zr))
        below = np.nonzero(zr + z0 <= self.gauge_height)[0]
        if below.size == 0 or below[0] == 0:
            raise InputError("track.gauge_height", f"the rail profile {self.rail.name!r} does not reach "
                                                   f"{self.gauge_height:g} mm below its top on the track-centre side "
                                                   f"(its gauge face must go deeper than the gauge height)")
        i = int(below[0])
        f = (self.gauge_height - (zr[i - 1] + z0)) / ((zr[i] + z0) - (zr[i - 1] + z0))
        yg = yr[i - 1] + f * (yr[i] - yr[i - 1])
        object.__setattr__(self, "rail_y0", 0.5 * self.gauge - float(yg))
        object.__setattr__(self, "rail_z0", z0)
        object.__setattr__(self, "_ys", yr + self.rail_y0)
        object.__setattr__(self, "_zs", zr + z0)
        if np.any(np.diff(self._ys) <= 0):
            raise InputError("track.cant", "the inclined rail profile is no longer monotone in y")
        object.__setattr__(self, "_dzs", np.gradient(self._zs, self._ys))

    # ------------------------------------------------------------------ the rail in track coordinates
    @property
    def points(self) -> tuple[np.ndarray, np.ndarray]:
        """The sampled rail surface ``(y, z)`` in the track frame."""
        return self._ys, self._zs

    def z_at(self, y) -> np.ndarray:
        """The rail surface's ``z`` at track ``y`` (nan beyond the profile)."""
        return np.interp(np.asarray(y, dtype=float), self._ys, self._zs, left=np.nan, right=np.nan)

    def slope_at(self, y) -> np.ndarray:
        """``dz/dy`` of the rail surface at track ``y``."""
        return np.interp(np.asarray(y, dtype=float), self._ys, self._dzs, left=np.nan, right=np.nan)

    def to_rail(self, y, z):
        """Track ``(y, z)`` → rail profile coordinates (before inclination: the profile file's frame)."""
        c, s = math.cos(-self.cant), math.sin(-self.cant)
        yy, zz = np.asarray(y) - self.rail_y0, np.asarray(z) - self.rail_z0
        return c * yy + s * zz, -s * yy + c * zz
