r"""Subsurface stresses in three dimensions: exact Boussinesq–Cerruti integrals over the grid's rectangles.

Body A is the half-space ``z > 0`` (z into A, as everywhere in rollqp's 3D), loaded on its surface by
the pressure ``p ≥ 0`` and the tangential tractions ``(p_x, p_y)`` on A, constant on each rectangular
element of the grid (:mod:`rollqp.discretization.grid`, eq. 3D.9). The stresses are Love's potentials
(Love 1929; Johnson, *Contact Mechanics*, 1985, §3.1, eq. 3.2–3.7) of those loads: every component is a
sum of third and fourth derivatives of ``W = ∫∫ Ω dξ dη``, ``Ω = z ln(ρ + z) − ρ``, and over a rectangle
each such derivative is the corner sum (docs/stresses.md §9)

.. math::
    \int_{x_l}^{x_r}\!\!\int_{y_l}^{y_r} k(x-ξ, y-η, z)\,dξ\,dη
      = K(X_+, Y_+) - K(X_-, Y_+) - K(X_+, Y_-) + K(X_-, Y_-),\qquad X_± = x - x_{l,r}  \qquad (3D.S1)

of a closed form ``K`` (``∂²K/∂X∂Y = k``; the primitives of ``Ω``, ``ln(ρ + z)`` and ``1/ρ`` in
``benchmarks/derive_subsurface3d.py``, which derives :func:`_corner_kernels` and :func:`_point_kernels`
below with sympy: regenerate them with it, never edit them by hand). The same derivatives of ``Ω``
itself are the point-load stresses of Boussinesq and Cerruti (:func:`point_load`, for checking).

On the grid the corner sums are one product: with the corner weights
``w_ij = L_ij − L_i−1,j − L_i,j−1 + L_i−1,j−1`` of an element field ``L`` (zero outside the grid), the
stress at a point is ``Σ_corners K(x − x_i, y − y_j, z) w_ij`` (:func:`stress_components`), in blocks of
points so that memory stays bounded, over the corners of the loaded elements only.

Signs: tension positive; z > 0 into the body; ``σzz → −p`` and ``σxz → −p_x``, ``σyz → −p_y`` at the
surface under a load. Body B is the half-space below (z into B), loaded by ``p`` and ``−(p_x, p_y)``:
its stresses are given in its own frame (x, y as A's, z into B), as in 2D (docs/stresses.md §1).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy import arcsinh, arctan, log, pi, sqrt  # noqa: F401  (the generated kernels' functions)

from .discretization.grid import Grid
from .errors import InputError
from .result import load_result, save_npz
from .scene import load_scene
from .subsurface import _step

__all__ = ["COMPONENTS", "QUANTITIES", "stress_components", "point_load", "invariants", "Section", "section",
           "StressField3D", "stresses3d", "stress_history3d", "save_field3d", "summary_rows3d",
           "parse_plane", "parse_line", "parse_depths"]

#: The six components, in the order of every array of this module (tension positive).
COMPONENTS = ("sxx", "syy", "szz", "sxy", "sxz", "syz")
#: Every quantity of a :class:`StressField3D`: the components, the principal stresses s1 ≥ s2 ≥ s3, von
#: Mises, Tresca (s1 − s3) and the mean (hydrostatic) stress.
QUANTITIES = COMPONENTS + ("s1", "s2", "s3", "von_mises", "tresca", "hydrostatic")
#: The peaks a :class:`StressField3D` locates (largest value; ``s3``: the largest compression).
PEAKS = ("von_mises", "tresca", "s1", "s3")
#: Point × corner evaluations per block (about 200 temporaries of this many doubles live at once: 64 MB).
BLOCK = 1 << 15
#: Largest number of points of one call (a plane of 2000 × 2000).
MAX_POINTS = 4_000_000


# =========================================================================== kernels on the grid
def _loads(v, shape) -> np.ndarray:
    """An element field as (S, ny, nx) floats: ``shape`` (ny, nx) fields, flattened or not, one or S states."""
    a = np.asarray(v, dtype=float)
    ny, nx = shape
    if a.shape[-1:] == (ny * nx,):
        a = a.reshape(a.shape[:-1] + (ny, nx))
    if a.shape[-2:] != (ny, nx) or a.ndim > 3:
        raise InputError("tractions", f"must have the grid's shape ({ny}, {nx}) (or one such field per state), "
                                      f"got {np.shape(v)}")
    return a.reshape((-1, ny, nx))


def _corner_weights(L) -> np.ndarray:
    """``w_ij = L_ij − L_i−1,j − L_i,j−1 + L_i−1,j−1`` on the (ny+1, nx+1) corners, flattened: (S, corners)."""
    Lp = np.pad(L, ((0, 0), (1, 1), (1, 1)))
    W = Lp[:, 1:, 1:] - Lp[:, 1:, :-1] - Lp[:, :-1, 1:] + Lp[:, :-1, :-1]
    return W.reshape(L.shape[0], -1)


def _check_points(x, y, z):
    try:
        x, y, z = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (x, y, z)))
    except ValueError:
        raise InputError("points", "x, y and z must broadcast to one shape") from None
    x, y, z = (v.ravel() for v in (x, y, z))
    if x.size > MAX_POINTS:
        raise InputError("points", f"at most {MAX_POINTS} points, got {x.size}")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y)) and np.all(np.isfinite(z))):
        raise InputError("points", "coordinates must be finite")
    if x.size and np.any(z <= 0):
        raise InputError("depths", f"every depth z must be > 0 (below the surface, z into the body; the surface "
                                   f"values are the tractions), got min z = {z.min():.6g}")
    return x, y, z


def stress_components(grid, x, y, z, pn, px, py, nu: float) -> np.ndarray:
    """σxx, σyy, σzz, σxy, σxz, σyz at the points ``(x, y, z)`` of element tractions on ``grid``.

    Parameters
    ----------
    grid : rollqp.discretization.grid.Grid
    x, y, z : array_like
        Points (broadcast together; z > 0, the depth into the body).
    pn, px, py : array_like
        Pressure (≥ 0 compressive) and tangential tractions on the body, constant on each element:
        shape (ny, nx) or (ny·nx,), or one such field per state (S, ny, nx).
    nu : float
        The body's Poisson's ratio.

    Returns
    -------
    ndarray
        Shape (6, m) for one state, (S, 6, m) for S states (:data:`COMPONENTS`), tension positive; exact
        for uniform tractions on the rectangles (eq. 3D.S1).

    Examples
    --------
    >>> from rollqp.discretization.grid import Grid
    >>> g = Grid.centred(1, 1, 0.5, 0.5)                     # a unit square under unit pressure
    >>> s = stress_components(g, 0.0, 0.0, 1e-6, [[1.0]], [[0.0]], [[0.0]], 0.3)
    >>> bool(abs(s[2, 0] + 1.0) < 1e-5)                      # σzz = −p just below the surface
    True
    """
    x, y, z = _check_points(x, y, z)
    if not (isinstance(nu, (int, float, np.integer, np.floating)) and -1 < nu < 0.5):
        raise InputError("nu", f"must be in (-1, 0.5), got {nu!r}")
    shape = (grid.ny, grid.nx)
    P, Tx, Ty = (_loads(v, shape) for v in (pn, px, py))
    S = max(P.shape[0], Tx.shape[0], Ty.shape[0])
    P, Tx, Ty = (np.broadcast_to(v, (S,) + shape) for v in (P, Tx, Ty))
    one = all(np.ndim(v) < 3 and np.size(v) == grid.n for v in (pn, px, py))
    out = np.zeros((S, 6, x.size))
    loaded = np.flatnonzero(np.any((P != 0) | (Tx != 0) | (Ty != 0), axis=0).ravel())
    if loaded.size and x.size:
        j, i = np.divmod(loaded, grid.nx)
        j0, j1, i0, i1 = j.min(), j.max() + 1, i.min(), i.max() + 1   # the loaded elements' bounding box
        cx = grid.xl + grid.dx * np.arange(i0, i1 + 1)
        cy = grid.yl + grid.dy * np.arange(j0, j1 + 1)
        CX, CY = (v.ravel() for v in np.meshgrid(cx, cy))
        weights = [(k, _corner_weights(np.ascontiguousarray(L[:, j0:j1, i0:i1])))
                   for k, L in enumerate((P, Tx, Ty))]
        weights = [(k, w) for k, w in weights if np.any(w)]
        per = max(1, BLOCK // CX.size)
        for b in range(0, x.size, per):
            sl = slice(b, b + per)
            X = x[sl, None] - CX[None, :]
            Y = y[sl, None] - CY[None, :]
            Z = np.broadcast_to(z[sl, None], X.shape)
            X = np.where((X == 0) & (Y == 0), 1e-30 * Z, X)   # above a corner: the closed forms' limit
            with np.errstate(all="ignore"):
                K = _corner_kernels(X, Y, Z, float(nu))
            for k, w in weights:
                for c in range(6):
                    Kc = np.broadcast_to(K[6 * k + c], X.shape)
                    out[:, c, sl] += w @ Kc.T
    return out[0] if one else out


def point_load(X, Y, z, nu: float) -> np.ndarray:
    """The stresses of unit point loads at the origin (Boussinesq: p; Cerruti: q_x, q_y), (3, 6, m).

    Row ``k`` of the first axis is the load (pressure, traction along x, along y on the body), the second
    the component (:data:`COMPONENTS`). The integrand of :func:`stress_components`, for checking it.

    Examples
    --------
    >>> s = point_load(0.0, 0.0, 2.0, 0.3)                   # σzz = −3P z³/(2π ρ⁵) on the axis
    >>> bool(abs(s[0, 2, 0] + 3 / (2 * np.pi * 4.0)) < 1e-15)
    True
    """
    X, Y, z = _check_points(X, Y, z)
    with np.errstate(all="ignore"):
        K = _point_kernels(X, Y, z, float(nu))
    return np.stack([np.broadcast_to(k, X.shape) for k in K]).reshape(3, 6, X.size)


def invariants(s) -> dict:
    """The quantities of :data:`QUANTITIES` from the components ``s`` (6, …) (:data:`COMPONENTS` order).

    Principal stresses by the symmetric eigenvalue solver (s1 ≥ s2 ≥ s3); von Mises
    ``√(½[(σxx−σyy)² + (σyy−σzz)² + (σzz−σxx)²] + 3(σxy² + σxz² + σyz²))``; Tresca ``s1 − s3``; the mean
    stress ``(σxx + σyy + σzz)/3`` (CONTACT's SIGHYD).
    """
    s = np.asarray(s, dtype=float)
    sxx, syy, szz, sxy, sxz, syz = s
    T = np.stack([np.stack([sxx, sxy, sxz], -1), np.stack([sxy, syy, syz], -1), np.stack([sxz, syz, szz], -1)], -1)
    ev = np.linalg.eigvalsh(T)
    s3, s2, s1 = ev[..., 0], ev[..., 1], ev[..., 2]
    vm = np.sqrt(0.5 * ((sxx - syy) ** 2 + (syy - szz) ** 2 + (szz - sxx) ** 2) + 3 * (sxy ** 2 + sxz ** 2 + syz ** 2))
    out = dict(zip(COMPONENTS, s))
    out.update(s1=s1, s2=s2, s3=s3, von_mises=vm, tresca=s1 - s3, hydrostatic=(sxx + syy + szz) / 3)
    return out


# =========================================================================== sections the user chooses
@dataclass(frozen=True)
class Section:
    """Points below the surface: a plane ``y = value`` (points along x), a plane ``x = value`` (along y) or a
    line ``x = value[0], y = value[1]`` (depths only). ``along`` holds the horizontal coordinates (one
    entry, NaN, for a line), ``z`` the depths; the points form a (nz, n_along) grid."""

    kind: str                     # "y" (plane y = const), "x" (plane x = const), "line"
    value: tuple
    along: np.ndarray
    z: np.ndarray

    def points(self):
        """``(x, y, z)`` of the (nz, n_along) points."""
        A, Z = np.meshgrid(self.along, self.z)
        if self.kind == "y":
            return A, np.full_like(A, self.value[0]), Z
        if self.kind == "x":
            return np.full_like(A, self.value[0]), A, Z
        return np.full_like(Z, self.value[0]), np.full_like(Z, self.value[1]), Z

    @property
    def label(self) -> str:
        if self.kind == "line":
            return f"line x = {self.value[0]:.6g}, y = {self.value[1]:.6g}"
        return f"plane {self.kind} = {self.value[0]:.6g}"


def _number(text: str, arg: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise InputError(arg, f"{text!r} is not a number") from None
    if not np.isfinite(v):
        raise InputError(arg, f"must be finite, got {text!r}")
    return v


def parse_plane(text: str) -> tuple[str, float]:
    """``"y=0"`` → ``("y", 0.0)``; ``"x=X"`` → ``("x", X)`` (scene length units)."""
    key, sep, val = str(text).replace(" ", "").partition("=")
    if not sep or key not in ("x", "y"):
        raise InputError("--plane", f"must be y=VALUE or x=VALUE (scene length units), got {text!r}")
    return key, _number(val, "--plane")


def parse_line(text: str) -> tuple[float, float]:
    """``"x=X,y=Y"`` → ``(X, Y)``."""
    got = {}
    for part in str(text).replace(" ", "").split(","):
        key, sep, val = part.partition("=")
        if not sep or key not in ("x", "y") or key in got:
            raise InputError("--line", f"must be x=X,y=Y (scene length units), got {text!r}")
        got[key] = _number(val, "--line")
    if set(got) != {"x", "y"}:
        raise InputError("--line", f"must be x=X,y=Y (scene length units), got {text!r}")
    return got["x"], got["y"]


def parse_depths(text: str) -> np.ndarray:
    """``"Z1,Z2,…"`` → the depths (> 0, scene length units, at most 4000)."""
    vals = [_number(v, "--depths") for v in str(text).replace(" ", "").split(",") if v]
    if not vals or len(vals) > 4000:
        raise InputError("--depths", f"must be 1 to 4000 numbers Z1,Z2,… (> 0, scene length units), got {text!r}")
    z = np.array(vals)
    if np.any(z <= 0):
        raise InputError("--depths", f"every depth must be > 0 (z into the body; the surface values are the "
                                     f"tractions), got {z.min():.6g}")
    return z


def section(grid, scale: float, plane=None, line=None, depths=None, along=None) -> Section:
    """The points of a plane (``plane = ("y", Y)`` or ``("x", X)``) or a ``line = (X, Y)`` below ``grid``.

    Defaults: the plane ``y = 0``; along it the element centres of the grid (CONTACT's recommendation for
    piecewise constant loads: between centres and edges the field of the discrete tractions is rougher
    than the contact's, near the surface); ``depths``: 40 depths up to ``2·scale`` (``scale``: the
    Hertz semi-axis ``a``).
    """
    if plane is not None and line is not None:
        raise InputError("--line", "give a plane or a line, not both")
    z = np.linspace(2 * scale / 40, 2 * scale, 40) if depths is None else np.asarray(depths, dtype=float)
    if line is not None:
        return Section("line", (float(line[0]), float(line[1])), np.array([np.nan]), z)
    kind, value = ("y", 0.0) if plane is None else plane
    if along is None:
        along = (grid.xl + grid.dx * (np.arange(grid.nx) + 0.5)) if kind == "y" else \
            (grid.yl + grid.dy * (np.arange(grid.ny) + 0.5))
    return Section(kind, (float(value),), np.asarray(along, dtype=float), z)


# =========================================================================== a result's state
@dataclass
class StressField3D:
    """Stresses of one state on a :class:`Section`: ``values[name]`` of shape (nz, n_along)
    (:data:`QUANTITIES`); ``maxima[name] = (value, x, y, z)`` for :data:`PEAKS` (``s3``: the largest
    compression, its most negative value)."""

    section: Section
    values: dict
    body: str
    step: int
    q: float
    maxima: dict = field(default_factory=dict)

    def __getitem__(self, name):
        return self.values[name]


def _maxima(values: dict, pts) -> dict:
    out = {}
    for name in PEAKS:
        v = -values[name] if name == "s3" else values[name]
        i = int(np.argmax(v))
        out[name] = (float(values[name].flat[i]),) + tuple(float(c.flat[i]) for c in pts)
    return out


def _state(arrays, step: int):
    return _step(step, len(arrays["q"]))


def result_grid(arrays, scene=None):
    """The :class:`~rollqp.discretization.grid.Grid` of a 3D result's element centres ``x``, ``y`` (uniform)."""
    x, y = (np.asarray(arrays[k], dtype=float) for k in ("x", "y"))
    sizes = []
    for key, c in (("x", x), ("y", y)):
        if c.size > 1:
            d = np.diff(c)
            if not (np.all(d > 0) and np.ptp(d) <= 1e-9 * max(abs(d[0]), 1e-300) + 1e-12 * np.max(np.abs(c))):
                raise InputError("RESULT.npz", f"key {key!r} must hold the uniformly spaced element centres of a grid")
            sizes.append(float(np.mean(d)))
        elif scene is not None:  # one element along this axis: its size is the scene's, if its grid is this one
            sg = scene.grid
            mine = getattr(sg, key)
            if mine.size != 1 or not abs(float(mine[0]) - float(c[0])) <= 1e-9 * (abs(float(c[0])) + getattr(sg, "d" + key)):
                raise InputError("RESULT.npz", f"key {key!r} is not the grid of the scene stored in the file "
                                               f"({mine.size} elements along {key}): a corrupt or edited file")
            sizes.append(float(getattr(sg, "d" + key)))
        else:
            raise InputError("RESULT.npz", f"one element along {key}: its size comes from the scene")
    dx, dy = sizes
    return Grid(x.size, y.size, dx, dy, float(x[0] - dx / 2), float(y[0] - dy / 2))


def source3d(result) -> tuple[dict, object]:
    """``(arrays, scene)`` of a 3D result (a ``load_result`` dict, a path, or an object with ``arrays()``)."""
    if isinstance(result, dict):
        arrays = result
    elif hasattr(result, "arrays"):
        arrays = dict(result.arrays())
    else:
        arrays = load_result(result, "result")
    for key in ("pn", "px", "py", "x", "y", "q"):
        if key not in arrays:
            raise InputError("result", f"not a 3D result with tractions (no key {key!r})")
    meta = arrays.get("meta")
    if isinstance(meta, (str, np.ndarray)):
        import json
        try:
            meta = json.loads(str(meta))
        except json.JSONDecodeError:
            meta = None
    if not isinstance(meta, dict) or not isinstance(meta.get("scene"), dict):
        raise InputError("result", "the result holds no scene (meta['scene']): the bodies' ν are unknown")
    return arrays, load_scene(meta["scene"])


def _scale(arrays) -> float:
    """The Hertz semi-axis ``a`` of the result (the default depths' scale), checked."""
    a = float(np.asarray(arrays.get("a", np.nan), dtype=float).reshape(-1)[0]) if np.size(arrays.get("a", [])) == 1 \
        else float("nan")
    if not (np.isfinite(a) and a > 0):
        raise InputError("result", f"key 'a' must be a number > 0 (the Hertz semi-axis), got {a!r}")
    return a


def _finite(s) -> None:
    """The stresses (and so their invariants, whose squares are within the range then) are finite: else the
    tractions are beyond the floating-point range, a one-line error, never NaN peaks."""
    s = np.asarray(s)
    if not (np.all(np.isfinite(s)) and np.max(np.abs(s), initial=0.0) < 1e150):
        raise InputError("result", "the stresses of these tractions are not finite (or beyond 1e150): the file's "
                                   "tractions are out of range")


def _body_nu(scene, body: str):
    if body not in ("A", "B"):
        raise InputError("body", f"must be 'A' or 'B', got {body!r}")
    return float(getattr(scene, body).nu), (1.0 if body == "A" else -1.0)


def stresses3d(result, step: int, plane=None, line=None, depths=None, body: str = "A", along=None) -> StressField3D:
    """Subsurface stresses of state ``step`` of a 3D ``result`` in ``body`` on a plane or a line.

    Parameters
    ----------
    result : a 3D result (``load_result`` dict, path, or :class:`~rollqp.result.Result`)
    step : int
        A stored state, 0…K (negative: from the end).
    plane : ("y", Y) or ("x", X), optional
        The plane ``y = Y`` (points along x) or ``x = X``; default ``y = 0``.
    line : (X, Y), optional
        The vertical line through ``(X, Y)`` instead of a plane.
    depths : array_like, optional
        Depths z > 0 (scene length units); default 40 depths up to 2a.
    body : {"A", "B"}
        Body A carries ``(p_x, p_y)``, body B ``−(p_x, p_y)``; its ν enters every component.
    along : array_like, optional
        The horizontal coordinates on a plane (default: the element centres).
    """
    arrays, scene = source3d(result)
    grid = result_grid(arrays, scene)
    k = _state(arrays, step)
    nu, sign = _body_nu(scene, body)
    sec = section(grid, _scale(arrays), plane, line, depths, along)
    pts = sec.points()
    with np.errstate(all="ignore"):
        s = stress_components(grid, *pts, arrays["pn"][k], sign * np.asarray(arrays["px"][k]),
                              sign * np.asarray(arrays["py"][k]), nu)
        _finite(s)
        values = {n: v.reshape(pts[0].shape) for n, v in invariants(s).items()}
    return StressField3D(sec, values, body, k, float(arrays["q"][k]), _maxima(values, pts))


@dataclass
class StressHistory3D:
    """Peaks of every state on one section: ``peaks[name]`` (K+1, 4) rows (value, x, y, z); ``overall[name]``
    ``(value, x, y, z, step)``."""

    section: Section
    steps: np.ndarray
    peaks: dict
    overall: dict
    body: str


def stress_history3d(result, plane=None, line=None, depths=None, body: str = "A", steps=None) -> StressHistory3D:
    """The peaks of :data:`PEAKS` of every stored state (or ``steps``) on a section, and over the run."""
    arrays, scene = source3d(result)
    grid = result_grid(arrays, scene)
    K1 = len(arrays["q"])
    ks = np.arange(K1) if steps is None else np.array([_state(arrays, s) for s in steps], dtype=int)
    nu, sign = _body_nu(scene, body)
    sec = section(grid, _scale(arrays), plane, line, depths)
    pts = sec.points()
    peaks = {n: np.zeros((ks.size, 4)) for n in PEAKS}
    per = max(1, (1 << 22) // max(1, pts[0].size * 6))
    for b in range(0, ks.size, per):
        sel = ks[b:b + per]
        with np.errstate(all="ignore"):
            s = stress_components(grid, *pts, np.asarray(arrays["pn"])[sel], sign * np.asarray(arrays["px"])[sel],
                                  sign * np.asarray(arrays["py"])[sel], nu)
        _finite(s)
        for r in range(sel.size):
            with np.errstate(all="ignore"):
                inv = invariants(s[r])
            for name, (v, x, y, z) in _maxima({n: inv[n] for n in PEAKS}, [c.ravel() for c in pts]).items():
                peaks[name][b + r] = (v, x, y, z)
    overall = {}
    for name, rows in peaks.items():
        j = int(np.argmin(rows[:, 0]) if name == "s3" else np.argmax(rows[:, 0]))
        overall[name] = tuple(float(v) for v in rows[j]) + (int(ks[j]),)
    return StressHistory3D(sec, ks, peaks, overall, body)


# =========================================================================== writing and drawing
def save_field3d(sf: StressField3D, path) -> str:
    """Write a :class:`StressField3D` to a ``.npz``: the points ``x, y, z`` (nz, n_along), every quantity, the
    maxima ``max_<name> = [value, x, y, z]``, ``step``, ``q``, ``body``, ``section``; atomically."""
    x, y, z = sf.section.points()
    arrays = {"x": x, "y": y, "z": z, "step": np.asarray(sf.step), "q": np.asarray(sf.q), "body": np.asarray(sf.body),
              "section": np.asarray(sf.section.label)}
    arrays.update({k: np.asarray(v) for k, v in sf.values.items()})
    for name, row in sf.maxima.items():
        arrays[f"max_{name}"] = np.array(row)
    return save_npz(path, arrays, "stress file")


def summary_rows3d(sf: StressField3D, p0: float) -> list[tuple[str, str]]:
    """Rows of the summary table: the peaks of the state (units of p0, positions in length units)."""
    names = {"von_mises": "peak von Mises", "tresca": "peak Tresca", "s1": "peak tension s1",
             "s3": "peak compression s3"}
    return [(label, f"{sf.maxima[k][0] / p0:.4f} p0 at x = {sf.maxima[k][1]:.5g}, y = {sf.maxima[k][2]:.5g}, "
                    f"z = {sf.maxima[k][3]:.5g}") for k, label in names.items()]


def _corner_kernels_0(X, Y, z, nu, x):
    x[0] = pi**(-1.0)
    x[1] = Y**2
    x[2] = x[1]*z
    x[3] = X**2
    x[4] = z**2
    x[5] = x[1] + x[3]
    x[6] = x[4] + x[5]
    x[7] = sqrt(x[6])
    x[8] = x[2] + x[3]*x[7]
    x[9] = x[8]**(-1.0)
    x[10] = x[5]*x[9]
    x[11] = x[7] + z
    x[12] = x[11]**(-1.0)
    x[13] = X*Y
    x[14] = x[12]*x[13]
    x[15] = arctan(x[10]*x[14])
    x[16] = x[7]**(-1.0)
    x[17] = Y*x[16]
    x[18] = X*x[17]
    x[19] = x[12]*x[18]
    x[20] = x[3] + x[4]
    x[21] = x[20]**(-3/2)
    x[22] = x[1]/x[20] + 1
    x[23] = 1/sqrt(x[22])
    x[24] = x[21]*x[23]
    x[25] = x[24]*z
    x[26] = x[13]*x[25]
    x[27] = x[16]*x[3]
    x[28] = x[12]*x[5]
    x[29] = 2*x[7]
    x[30] = x[27] + x[29]
    x[31] = x[3]*x[30]
    x[32] = -x[1] + x[10]*x[31] + x[27]*x[28] - 3*x[3]
    x[33] = x[8]**(-2.0)
    x[34] = x[11]**(-2.0)
    x[35] = x[1]*x[3]
    x[36] = x[34]*x[35]*x[5]**2
    x[37] = x[33]*x[36] + 1
    x[38] = x[9]/x[37]
    x[39] = -x[14]*x[32]*x[38]
    x[40] = x[15] + x[19] - x[26] + x[39]
    x[41] = x[1] + x[4]
    x[42] = x[41]**(-3/2)
    x[43] = x[3]/x[41] + 1
    x[44] = x[43]**(-3/2)
    x[45] = 3*x[3]
    x[46] = x[20]**(-5/2)
    x[47] = x[23]*x[46]
    x[48] = x[45]*x[47]
    x[49] = x[22]**(-3/2)
    x[50] = x[49]/x[20]**(7/2)
    x[51] = x[4]**(-1.0)
    x[52] = x[6]**(-1.0)
    x[53] = x[3]*x[52]
    x[54] = x[51]*x[53]
    x[55] = x[1]*x[54] + 1
    x[56] = x[55]**(-1.0)
    x[57] = x[53] - 1
    x[58] = x[56]*x[57]
    x[59] = x[6]**(-3/2)


def _corner_kernels_1(X, Y, z, nu, x):
    x[60] = 3*x[59]
    x[61] = 2*x[59]/x[55]**2
    x[62] = x[51]*x[61]
    x[63] = -x[1]*x[57]**2*x[62] + 3*x[24] + x[35]*x[50] + x[42]*x[44] - x[48] + x[58]*x[60]
    x[64] = Y*x[24]
    x[65] = (1/2)*z
    x[66] = X*x[65]
    x[67] = x[64]*x[66]
    x[68] = 1/sqrt(x[43])
    x[69] = x[42]*x[68]
    x[70] = x[69]*z
    x[71] = x[13]*x[70]
    x[72] = x[3]*z
    x[73] = x[1]*x[7] + x[72]
    x[74] = x[73]**(-1.0)
    x[75] = x[5]*x[74]
    x[76] = arctan(x[14]*x[75])
    x[77] = 3*x[1]
    x[78] = x[1]*x[16]
    x[79] = x[29] + x[78]
    x[80] = x[1]*x[79]
    x[81] = -x[28]*x[78] + x[3] - x[75]*x[80] + x[77]
    x[82] = x[73]**(-2.0)
    x[83] = x[36]*x[82] + 1
    x[84] = x[74]/x[83]
    x[85] = x[14]*x[81]*x[84]
    x[86] = x[19] - x[71] + x[76] + x[85]
    x[87] = (2*nu - 1)**(-1.0)
    x[88] = nu**2*x[87]
    x[89] = z**(-1.0)
    x[90] = arctan(x[18]*x[89])
    x[91] = x[16]*z
    x[92] = x[51] + x[52]
    x[93] = x[56]*x[92]
    x[94] = -x[13]*x[91]*x[93] + x[26] + x[71] + x[90]
    x[95] = Y*x[65]
    x[96] = X*x[95]
    x[97] = nu*x[87]
    x[98] = x[41]**(-5/2)
    x[99] = x[68]*x[98]
    x[100] = x[44]/x[41]**(7/2)
    x[101] = x[1]*x[52]
    x[102] = x[101] - 1
    x[103] = x[102]*x[56]
    x[104] = x[100]*x[35] - x[102]**2*x[3]*x[62] + x[103]*x[60] + x[21]*x[49] + 3*x[69] - x[77]*x[99]
    x[105] = 3*x[4]
    x[106] = x[100]*x[3]
    x[107] = x[35]*x[61]
    x[108] = x[6]**(-2.0)
    x[109] = x[56]*x[91]
    x[110] = x[1]*x[4]*x[50] - x[105]*x[47] - x[105]*x[99] + x[106]*x[4] - x[107]*x[92]**2 + x[109]*(3*x[108]*z + x[52]*x[89] + 2/z**3) - 2*x[16]*x[93] + x[24] + x[69]
    x[111] = -1/2*nu*x[40]*x[87] - 1/2*nu*x[86]*x[87] - 1/2*nu*x[87]*x[94] + x[104]*x[96]*x[97] + x[110]*x[96]*x[97] + x[40]*x[88] + x[63]*x[96]*x[97] + x[86]*x[88] + x[88]*x[94]
    x[112] = x[111] + (1/2)*x[19]
    x[113] = X*x[69]
    x[114] = x[113]*x[95]
    x[115] = (1/2)*x[91]
    x[116] = log(x[11])
    x[117] = x[91] + 1
    x[118] = x[12]*z
    x[119] = x[117]*x[118]


def _corner_kernels_2(X, Y, z, nu, x):
    x[120] = 2*x[12]
    x[121] = x[34]*z
    x[122] = x[4]*x[52]
    x[123] = x[12]*x[91]
    x[124] = x[65]*(x[117]**2*x[121] - x[117]*x[120] + x[123]*(x[122] - 1) + x[16] - x[4]*x[59])
    x[125] = -x[51] - x[52]
    x[126] = x[16]*x[89]
    x[127] = x[107]*x[89]*x[92]
    x[128] = x[25] + x[70]
    x[129] = x[2]*x[3]*x[50] - x[48]*z
    x[130] = x[109]*(x[108]*x[45] + x[125] + x[54]) - x[126]*x[58] - x[127]*x[57] + x[128] + x[129] - x[44]*x[72]*x[98]
    x[131] = x[130]*x[95]
    x[132] = x[106]*x[2] - 3*x[2]*x[99]
    x[133] = -x[102]*x[127] - x[103]*x[126] + x[109]*(x[101]*x[51] + x[108]*x[77] + x[125]) + x[128] + x[132] - x[2]*x[46]*x[49]
    x[134] = x[133]*x[66]
    x[135] = 1/sqrt(x[20])
    x[136] = arcsinh(Y*x[135])
    x[137] = 1/sqrt(x[41])
    x[138] = Y*x[137]*x[68]
    x[139] = x[3]*x[64]
    x[140] = x[17]*x[58]
    x[141] = -Y*x[123] + Y*x[16] - x[136] - x[138] + x[139] - x[140]
    x[142] = x[12]*x[16]
    x[143] = -x[142]
    x[144] = x[12]*x[59]
    x[145] = x[144]*x[3]
    x[146] = x[34]*x[53]
    x[147] = 4*x[12]
    x[148] = x[10]*x[30]
    x[149] = 2*x[5]
    x[150] = -3*x[142]*x[5] + 6
    x[151] = x[149]*x[35]/x[11]**3
    x[152] = -x[12]*x[3]*x[38]*(-x[10]*(-X**4*x[59] + 5*x[27] + x[29]) + x[120]*x[148]*x[27] + x[145]*x[5] + x[146]*x[149] - x[147]*x[27] - 2*x[148] + x[149]*x[3]*x[30]**2*x[33] + x[150] - 4*x[31]*x[9]) + x[120]*x[32]*x[38] + x[129] + x[143] + x[145] + x[146] + x[151]*x[32]**2/(x[37]**2*x[8]**3) + x[25]
    x[153] = -x[136] - x[138] + x[139] - x[17]*x[56]*x[57]
    x[154] = x[118] - 1
    x[155] = x[154]*x[88]
    x[156] = x[117]*x[121] + x[12]*x[122] - x[12] - x[52]*z
    x[157] = x[115]*x[156]
    x[158] = Y*x[157]
    x[159] = -nu*x[153]*x[87] + x[131]*x[97] + x[141]*x[88] + x[152]*x[95]*x[97] + x[153]*x[88] + x[155]*x[17] + x[158]*x[97]
    x[160] = arcsinh(X*x[137])
    x[161] = X*x[135]*x[23]
    x[162] = x[1]*x[113]
    x[163] = X*x[16]
    x[164] = nu*x[154]
    x[165] = x[103]*x[163]
    x[166] = X*x[157]
    x[167] = (1/2)*x[0]
    x[168] = x[0]*x[124]
    x[169] = -x[102]*x[163]*x[56] - x[160] - x[161] + x[162]
    x[170] = -X*x[123] + X*x[16] - x[160] - x[161] + x[162] - x[165]
    x[171] = x[1]*x[144]
    x[172] = x[101]*x[34]
    x[173] = -x[81]
    x[174] = x[75]*x[79]
    x[175] = -x[1]*x[12]*x[84]*(x[1]*x[149]*x[79]**2*x[82] + x[120]*x[174]*x[78] - x[147]*x[78] + x[149]*x[172] + x[150] + x[171]*x[5] - 2*x[174] - 4*x[74]*x[80] - x[75]*(-Y**4*x[59] + x[29] + 5*x[78])) + x[120]*x[173]*x[84] + x[132] + x[143] + x[151]*x[173]**2/(x[73]**3*x[83]**2) + x[171] + x[172] + x[70]
    x[176] = -nu*x[169]*x[87] + x[134]*x[97] + x[155]*x[163] + x[166]*x[97] + x[169]*x[88] + x[170]*x[88] + x[175]*x[66]*x[97]


def _corner_kernels(X, Y, z, nu):
    x = [None] * 177
    _corner_kernels_0(X, Y, z, nu, x)
    _corner_kernels_1(X, Y, z, nu, x)
    _corner_kernels_2(X, Y, z, nu, x)
    return (x[0]*((1/2)*X*Y*x[63]*z + nu*x[40] - x[112] - 1/2*x[15] - 1/2*x[39] + x[67]),
            x[0]*((1/2)*X*Y*x[104]*z + nu*x[86] - x[112] + x[114] - 1/2*x[76] - 1/2*x[85]),
            x[0]*((1/2)*X*Y*x[110]*z + (1/2)*X*Y*x[16]*x[56]*x[92]*z + nu*x[94] - x[111] - x[114] - x[67] - 1/2*x[90]),
            x[0]*(nu*(x[116] + x[119] - x[91]) + x[115] - 1/2*x[116] - 1/2*x[119] + x[124]),
            x[0]*x[131],
            x[0]*x[134],
            x[0]*((1/2)*Y*x[152]*z + nu*x[141] - x[153] - x[159]),
            x[0]*(Y*nu*x[154]*x[16] + (1/2)*Y*x[156]*x[16]*z - x[159]),
            x[0]*((1/2)*Y*x[130]*z + nu*x[153] - x[159]),
            x[0]*((1/2)*x[160] + (1/2)*x[161] - 1/2*x[162] + x[163]*x[164] + (1/2)*x[165] + x[166]),
            x[167]*(X*Y*x[63]*z - x[94]),
            x[168],
            x[0]*(X*nu*x[154]*x[16] + (1/2)*X*x[156]*x[16]*z - x[176]),
            x[0]*((1/2)*X*x[175]*z + nu*x[170] - x[169] - x[176]),
            x[0]*((1/2)*X*x[133]*z + nu*x[169] - x[176]),
            x[0]*((1/2)*x[136] + (1/2)*x[138] - 1/2*x[139] + (1/2)*x[140] + x[158] + x[164]*x[17]),
            x[168],
            x[167]*(X*Y*x[104]*z - x[94]))


def _point_kernels_0(X, Y, z, nu, x):
    x[0] = pi**(-1.0)
    x[1] = X**2
    x[2] = Y**2
    x[3] = z**2
    x[4] = x[1] + x[2] + x[3]
    x[5] = x[4]**(-3/2)
    x[6] = sqrt(x[4])
    x[7] = x[6] + z
    x[8] = x[7]**(-1.0)
    x[9] = x[5]*x[8]
    x[10] = x[4]**(-1.0)
    x[11] = x[7]**(-2.0)
    x[12] = x[10]*x[11]
    x[13] = x[4]**(-5/2)
    x[14] = 3*x[13]
    x[15] = x[1]*x[14]
    x[16] = x[15]*z
    x[17] = x[4]**(-2.0)
    x[18] = x[11]*x[17]
    x[19] = x[18]*x[3]
    x[20] = x[1]*x[19]
    x[21] = x[15]*x[8]
    x[22] = x[5]*z
    x[23] = x[6]**(-1.0)
    x[24] = x[23]*z
    x[25] = x[24] + 1
    x[26] = x[11]*x[25]
    x[27] = x[22]*x[26]
    x[28] = x[7]**(-3.0)
    x[29] = x[25]*x[28]
    x[30] = x[10]*x[29]
    x[31] = x[30]*z
    x[32] = x[1]*x[31]
    x[33] = x[23]*x[8]
    x[34] = x[24]*x[26]
    x[35] = x[22] - x[3]*x[9] + x[33] - x[34]
    x[36] = -x[1]*x[12] + x[1]*x[27] - x[1]*x[9] - x[16] + 2*x[20] + x[21]*x[3] + 2*x[32] + x[35]
    x[37] = x[4]**(-7/2)
    x[38] = 15*x[37]
    x[39] = x[3]*x[38]
    x[40] = x[1]*x[39]
    x[41] = 9*x[13]*z
    x[42] = x[41]*x[8]
    x[43] = 6*z
    x[44] = x[18]*x[43]
    x[45] = 4*x[30]
    x[46] = 2*x[5]
    x[47] = x[26]*x[46]
    x[48] = z**3
    x[49] = x[11]/x[4]**3
    x[50] = 8*x[48]*x[49]
    x[51] = x[38]*x[48]*x[8]
    x[52] = x[10]*x[3]
    x[53] = x[52] - 1
    x[54] = x[18]*z
    x[55] = x[53]*x[54]
    x[56] = x[25]**2
    x[57] = x[28]*x[56]
    x[58] = 2*x[57]
    x[59] = x[22]*x[58]


def _point_kernels_1(X, Y, z, nu, x):
    x[60] = 2*x[22]*x[28]
    x[61] = x[53]*x[60]
    x[62] = x[7]**(-4.0)
    x[63] = x[43]*x[62]
    x[64] = x[10]*x[56]*x[63]
    x[65] = x[13]*x[3]
    x[66] = 6*x[65]
    x[67] = x[26]*x[66]
    x[68] = x[17]*x[29]
    x[69] = 8*x[3]*x[68]
    x[70] = x[14]*x[3]
    x[71] = x[14]*x[48]
    x[72] = x[71]*x[8]
    x[73] = x[23]*x[26]
    x[74] = 2*x[73]
    x[75] = 3*x[22]
    x[76] = x[75]*x[8]
    x[77] = x[12]*x[53]
    x[78] = x[77]*z
    x[79] = x[24]*x[58]
    x[80] = x[3]*x[47]
    x[81] = -x[5] + x[70] - x[72] + x[74] + x[76] - x[78] - x[79] - x[80]
    x[82] = -x[1]*x[42] - x[1]*x[44] - x[1]*x[45] - x[1]*x[47] + x[1]*x[50] + x[1]*x[51] + x[1]*x[55] + x[1]*x[59] + x[1]*x[61] + x[1]*x[64] + x[1]*x[67] + x[1]*x[69] + x[15] - x[40] + x[81]
    x[83] = (3/2)*x[65]
    x[84] = x[8]*x[83]
    x[85] = (1/2)*x[22]
    x[86] = x[26]*x[85]
    x[87] = nu**2
    x[88] = (2*nu - 1)**(-1.0)
    x[89] = x[87]*x[88]
    x[90] = x[14]*x[2]
    x[91] = x[90]*z
    x[92] = x[19]*x[2]
    x[93] = x[70]*x[8]
    x[94] = x[2]*x[31]
    x[95] = -x[12]*x[2] + x[2]*x[27] - x[2]*x[9] + x[2]*x[93] + x[35] - x[91] + 2*x[92] + 2*x[94]
    x[96] = x[11]*x[56]
    x[97] = x[25]**3
    x[98] = x[28]*x[97]
    x[99] = x[33]*x[53]
    x[100] = 3*x[5]
    x[101] = x[100]*x[8]
    x[102] = x[101]*x[3]*x[53] + 3*x[34]*x[53] - x[71] + x[75] - 3*x[96] + 2*x[98]*z - 3*x[99]
    x[103] = nu*x[102]
    x[104] = z**4
    x[105] = x[22]*x[8]
    x[106] = 12*x[53]
    x[107] = 3*x[12]
    x[108] = x[107]*z
    x[109] = 5*x[104]
    x[110] = x[24]*x[57]
    x[111] = x[26]*x[3]*x[5]
    x[112] = -x[100] - x[104]*x[38] - x[105]*x[106] + x[106]*x[110] + x[106]*x[111] - x[106]*x[73] + x[108]*x[53]**2 + x[25]**4*x[63] + 18*x[65] + x[76]*(x[109]*x[17] - 6*x[52] + 1) - 8*x[98]
    x[113] = (1/2)*z
    x[114] = nu*x[88]
    x[115] = x[82]*z
    x[116] = x[2]*x[39]
    x[117] = -x[116] - x[2]*x[42] - x[2]*x[44] - x[2]*x[45] - x[2]*x[47] + x[2]*x[50] + x[2]*x[51] + x[2]*x[55] + x[2]*x[59] + x[2]*x[61] + x[2]*x[64] + x[2]*x[67] + x[2]*x[69] + x[81] + x[90]
    x[118] = x[117]*z
    x[119] = -1/2*nu*x[36]*x[88] - 1/2*nu*x[88]*x[95] - x[102]*x[87]*x[88] + (1/2)*x[103]*x[88] + x[112]*x[113]*x[114] + (1/2)*x[114]*x[115] + (1/2)*x[114]*x[118] + x[36]*x[89] + x[89]*x[95]


def _point_kernels_2(X, Y, z, nu, x):
    x[120] = -1/2*x[11]*x[23]*x[25]*z + x[119] - 1/2*x[3]*x[5]*x[8] + (1/2)*x[33] + x[85]
    x[121] = (3/2)*x[13]
    x[122] = x[121]*x[48]
    x[123] = x[14]*z
    x[124] = 2*x[19]
    x[125] = 2*x[31]
    x[126] = x[113]*(x[14] - x[39] - x[42] - x[44] - x[45] - x[47] + x[50] + x[51] + x[55] + x[59] + x[61] + x[64] + x[67] + x[69])
    x[127] = X*x[0]
    x[128] = Y*x[127]
    x[129] = x[65]*x[8]
    x[130] = -x[26]*x[75]
    x[131] = x[123] + x[9]
    x[132] = x[109]*x[37]*x[8] + x[124]*x[53] + x[125]*x[53] - 6*x[129] + x[130] + x[131] - x[23]*x[58] + 2*x[24]*x[62]*x[97] + x[26]*x[71] + x[3]*x[46]*x[57] - 5*x[37]*x[48] - x[77]
    x[133] = (3/2)*x[132]*z
    x[134] = Y*x[0]
    x[135] = -x[76]
    x[136] = x[100] - x[108] + x[135]
    x[137] = 3*x[54]
    x[138] = x[1]*x[137] + x[1]*x[60] - x[15] + x[16]*x[8]
    x[139] = x[136] + x[138]
    x[140] = x[101] + x[107] - 9*x[129] + x[130] - 6*x[19] - x[30]*x[43] + x[41]
    x[141] = x[38]*z
    x[142] = 3*x[18]
    x[143] = x[28]*x[46]
    x[144] = x[28]*x[66]
    x[145] = 12*x[3]*x[49]
    x[146] = 6*x[22]*x[25]*x[62]
    x[147] = x[43]*x[68]
    x[148] = -x[1]*x[141] - x[1]*x[142] - x[1]*x[143] + x[1]*x[144] + x[1]*x[145] + x[1]*x[146] + x[1]*x[147] + x[16]*x[26] - x[21] + x[40]*x[8]
    x[149] = x[140] + x[148]
    x[150] = -x[105] - x[12]*z + x[5]
    x[151] = x[137]*x[2] + x[2]*x[60] + x[8]*x[91] - x[90]
    x[152] = x[150] + x[151]
    x[153] = x[12] - x[124] - x[125] + x[131] - x[27] - x[93]
    x[154] = x[116]*x[8] - x[141]*x[2] - x[142]*x[2] - x[143]*x[2] + x[144]*x[2] + x[145]*x[2] + x[146]*x[2] + x[147]*x[2] + x[26]*x[91] - x[8]*x[90]
    x[155] = x[153] + x[154]
    x[156] = x[113]*x[155]
    x[157] = x[135] + x[5] - x[70] + x[72] - x[74] + x[78] + x[79] + x[80]
    x[158] = nu*x[157]
    x[159] = x[114]*x[133] - x[157]*x[87]*x[88] + x[158]*x[88]
    x[160] = x[113]*x[114]*x[149] + x[114]*x[156] + x[139]*x[89] + x[152]*x[89] + x[159]
    x[161] = -3/2*x[132]*z + x[158]
    x[162] = x[138] + x[150]
    x[163] = x[148] + x[153]
    x[164] = x[113]*x[163]
    x[165] = x[110] + x[111] + x[113]*x[77] + x[122]*x[8] - 3/2*x[22]*x[8] + (1/2)*x[5] - x[73] - x[83]
    x[166] = (1/2)*x[0]
    x[167] = x[126]*x[128]
    x[168] = x[136] + x[151]
    x[169] = x[140] + x[154]
    x[170] = x[113]*x[114]*x[169] + x[114]*x[164] + x[159] + x[162]*x[89] + x[168]*x[89]


def _point_kernels(X, Y, z, nu):
    x = [None] * 171
    _point_kernels_0(X, Y, z, nu, x)
    _point_kernels_1(X, Y, z, nu, x)
    _point_kernels_2(X, Y, z, nu, x)
    return (x[0]*(nu*x[36] + (1/2)*x[1]*x[10]*x[11] + (3/2)*x[1]*x[13]*z + (1/2)*x[1]*x[5]*x[8] - x[1]*x[84] - x[1]*x[86] - x[120] - x[20] - x[32] + (1/2)*x[82]*z),
            x[0]*(nu*x[95] + (1/2)*x[10]*x[11]*x[2] + (1/2)*x[117]*z - x[120] + (3/2)*x[13]*x[2]*z + (1/2)*x[2]*x[5]*x[8] - x[2]*x[84] - x[2]*x[86] - x[92] - x[94]),
            x[0]*(-x[103] + (3/2)*x[11]*x[23]*x[25]*x[53]*z + (1/2)*x[112]*z - x[119] - x[122] + x[28]*x[97]*z + (3/2)*x[3]*x[5]*x[53]*x[8] + (3/2)*x[5]*z - 3/2*x[96] - 3/2*x[99]),
            x[128]*(nu*(-x[12] - x[123] + x[124] + x[125] + x[27] - x[9] + x[93]) + (1/2)*x[12] + x[121]*z + x[126] - x[19] - x[31] - x[84] - x[86] + (1/2)*x[9]),
            x[127]*x[133],
            x[133]*x[134],
            x[127]*(nu*x[139] + (1/2)*x[149]*z - x[160] - x[81]),
            x[127]*(nu*x[152] + (1/2)*x[155]*z - x[160]),
            x[127]*(-x[160] - x[161]),
            x[134]*(nu*x[162] + x[164] + x[165]),
            x[166]*(x[102] + x[115]),
            x[167],
            x[134]*(nu*x[162] + (1/2)*x[163]*z - x[170]),
            x[134]*(nu*x[168] + (1/2)*x[169]*z - x[170] - x[81]),
            x[134]*(-x[161] - x[170]),
            x[127]*(nu*x[152] + x[156] + x[165]),
            x[167],
            x[166]*(x[102] + x[118]))
