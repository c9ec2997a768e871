r"""Combined elastic constants of two half-spaces (docs/theory3d.md §3, eq. 3D.10).

The contact problem sees the two bodies only through the displacement *difference*
``u = u^A − u^B`` (A the upper body, like CONTACT's body 1). Summing the Boussinesq–Cerruti
solutions of the two half-spaces gives Kalker's combined constants (Kalker 1990, eq. 1.44)

.. math::
    \frac1G = \frac12\Big(\frac1{G_A} + \frac1{G_B}\Big),\quad
    \frac{\nu}{G} = \frac12\Big(\frac{\nu_A}{G_A} + \frac{\nu_B}{G_B}\Big),\quad
    \frac{K}{G} = \frac14\Big(\frac{1-2\nu_A}{G_A} - \frac{1-2\nu_B}{G_B}\Big)     \qquad (3D.10)

with ``G_α = E_α / (2(1 + ν_α))``. ``K`` is the difference constant that couples the normal and
tangential problems; ``K = 0`` for similar (or "quasi-identical") bodies. In terms of the 2D
project's constants: ``1/E* = (1 − ν)/G`` and Dundurs' ``β = K/(1 − ν)`` (docs/formulation.md §1).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from .errors import InputError

__all__ = ["Materials"]


def _modulus(name, v) -> float:
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise InputError(name, f"must be a real number, got {v!r}") from None
    if not (math.isfinite(x) and x > 0):
        raise InputError(name, f"must be a finite number > 0, got {v!r}")
    return x


def _poisson(name, v) -> float:
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise InputError(name, f"must be a real number, got {v!r}") from None
    if not (math.isfinite(x) and -1 < x <= 0.5):
        raise InputError(name, f"Poisson's ratio must be in (-1, 0.5], got {v!r}")
    return x


@dataclass(frozen=True)
class Materials:
    """The combined constants ``G, ν, K`` of eq. 3D.10 (A upper, B lower body).

    Build it with :meth:`from_young` (``E, ν`` of each body, the scene's keys) or
    :meth:`from_shear` (``G, ν``, CONTACT's ``GG``, ``POISS``).

    Examples
    --------
    >>> m = Materials.from_shear(200.0, 0.42, 200.0, 0.42)      # CONTACT's cattaneo example
    >>> round(m.G, 6), round(m.nu, 6), m.K, round(m.Estar, 4)
    (200.0, 0.42, 0.0, 344.8276)
    """

    G: float
    nu: float
    K: float

    @classmethod
    def from_shear(cls, G_A: float, nu_A: float, G_B: float, nu_B: float) -> "Materials":
        """From the shear moduli and Poisson's ratios of bodies A and B (eq. 3D.10)."""
        G_A, G_B = _modulus("bodies.A.G", G_A), _modulus("bodies.B.G", G_B)
        nu_A, nu_B = _poisson("bodies.A.nu", nu_A), _poisson("bodies.B.nu", nu_B)
        inv = 0.5 * (1 / G_A + 1 / G_B)
        G = 1 / inv
        nu = G * 0.5 * (nu_A / G_A + nu_B / G_B)
        K = G * 0.25 * ((1 - 2 * nu_A) / G_A - (1 - 2 * nu_B) / G_B)
        return cls(G=G, nu=nu, K=K)

    @classmethod
    def from_young(cls, E_A: float, nu_A: float, E_B: float, nu_B: float) -> "Materials":
        """From Young's moduli and Poisson's ratios (``G = E / (2(1 + ν))``)."""
        E_A, E_B = _modulus("bodies.A.E", E_A), _modulus("bodies.B.E", E_B)
        nu_A, nu_B = _poisson("bodies.A.nu", nu_A), _poisson("bodies.B.nu", nu_B)
        return cls.from_shear(E_A / (2 * (1 + nu_A)), nu_A, E_B / (2 * (1 + nu_B)), nu_B)

    @property
    def Estar(self) -> float:
        """The contact modulus ``E* = G/(1 − ν)``: ``1/E* = (1−ν_A²)/E_A + (1−ν_B²)/E_B``."""
        return self.G / (1 - self.nu)

    @property
    def beta(self) -> float:
        """Dundurs' constant ``β = K/(1 − ν)`` with body 1 = A, body 2 = B (the 2D project's β; Bentall–Johnson's
        κ = 2β; docs/theory3d.md §3): positive when A is the more compliant body in ``(1 − 2ν)/G``."""
        return self.K / (1 - self.nu)

    @property
    def similar(self) -> bool:
        """``K == 0``: the normal and tangential problems decouple."""
        return self.K == 0.0
