r"""Subsurface stresses in three dimensions: exact Boussinesq–Cerruti integrals over the grid's rectangles.

Body A is the half-space ``z > 0`` (z into A, as everywhere in rollqp's 3D), loaded on its surface by
the pressure ``p ≥ 0`` and the tangential tractions ``(p_x, p_y)`` on A, constant on each rectangular
element of the grid (:mod:`rollqp.three.grid`, eq. 3D.9). The stresses are Love's potentials
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

from .errors import InputError

__all__ = ["COMPONENTS", "QUANTITIES", "stress_components", "point_load", "invariants", "Section", "section",
           "StressField3D", "stresses3d", "stress_history3d", "save_field3d", "plot_field3d", "summary_rows3d",
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
    grid : rollqp.three.grid.Grid
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
    >>> from rollqp.three.grid import Grid
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
    from .subsurface import _step
    return _step(step, len(arrays["q"]))


def result_grid(arrays, scene=None):
    """The :class:`~rollqp.three.grid.Grid` of a 3D result's element centres ``x``, ``y`` (uniform)."""
    from .three.grid import Grid
    x, y = (np.asarray(arrays[k], dtype=float) for k in ("x", "y"))
    sizes = []
    for key, c in (("x", x), ("y", y)):
        if c.size > 1:
            d = np.diff(c)
            if not (np.all(d > 0) and np.ptp(d) <= 1e-9 * max(abs(d[0]), 1e-300) + 1e-12 * np.max(np.abs(c))):
                raise InputError("RESULT.npz", f"key {key!r} must hold the uniformly spaced element centres of a grid")
            sizes.append(float(np.mean(d)))
        elif scene is not None:
            sizes.append(float(getattr(scene.grid, "d" + key)))
        else:
            raise InputError("RESULT.npz", f"one element along {key}: its size comes from the scene")
    dx, dy = sizes
    return Grid(x.size, y.size, dx, dy, float(x[0] - dx / 2), float(y[0] - dy / 2))


def source3d(result) -> tuple[dict, object]:
    """``(arrays, scene)`` of a 3D result (a ``load_result`` dict, a path, or an object with ``arrays()``)."""
    from .result import load_result
    from .scene import load_scene
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


def _body_nu(scene, body: str):
    if body not in ("A", "B"):
        raise InputError("body", f"must be 'A' or 'B', got {body!r}")
    return float(getattr(scene, body).nu), (1.0 if body == "A" else -1.0)


def stresses3d(result, step: int, plane=None, line=None, depths=None, body: str = "A", along=None) -> StressField3D:
    """Subsurface stresses of state ``step`` of a 3D ``result`` in ``body`` on a plane or a line.

    Parameters
    ----------
    result : a 3D result (``load_result`` dict, path, or :class:`~rollqp.three.result.Result3D`)
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
    s = stress_components(grid, *pts, arrays["pn"][k], sign * np.asarray(arrays["px"][k]),
                          sign * np.asarray(arrays["py"][k]), nu)
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
        s = stress_components(grid, *pts, np.asarray(arrays["pn"])[sel], sign * np.asarray(arrays["px"])[sel],
                              sign * np.asarray(arrays["py"])[sel], nu)
        for r in range(sel.size):
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
    from .result import save_npz
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


def plot_field3d(sf: StressField3D, arrays: dict, path, p0: float) -> str:
    """Contour maps of von Mises and Tresca (in p0) on the section's plane, with the surface tractions of
    the grid row (or column) under it above; on a line, every component against depth."""
    from .plot import pyplot
    plt = pyplot()
    sec, k = sf.section, sf.step
    if sec.kind == "line":
        fig, ax = plt.subplots(figsize=(6.5, 5), constrained_layout=True)
        for name in COMPONENTS + ("von_mises",):
            ax.plot(sf.values[name][:, 0] / p0, sec.z, "-" if name != "von_mises" else "k-", lw=1.2, label=name)
        ax.invert_yaxis()
        ax.set_xlabel("stress / p0 (tension positive)")
        ax.set_ylabel("depth z")
        ax.set_title(f"body {sf.body}, state {k}: {sec.label}", fontsize=9)
        ax.legend(fontsize=8)
        fig.savefig(path, dpi=110)
        plt.close(fig)
        return str(path)
    x, y = (np.asarray(arrays[c], dtype=float) for c in ("x", "y"))
    if sec.kind == "y":
        row = int(np.argmin(np.abs(y - sec.value[0])))
        h, cut = x, (lambda f: np.asarray(f)[k][row, :])
    else:
        col = int(np.argmin(np.abs(x - sec.value[0])))
        h, cut = y, (lambda f: np.asarray(f)[k][:, col])
    fig, axes = plt.subplots(2, 2, figsize=(11, 6.5), sharex="col", gridspec_kw=dict(height_ratios=(1, 3)),
                             constrained_layout=True)
    for col, name in enumerate(("von_mises", "tresca")):
        top, ax = axes[0, col], axes[1, col]
        for key, style in (("pn", "k-"), ("px", "k--"), ("py", "k:")):
            top.step(h, cut(arrays[key]) / p0, style, where="mid", lw=1, label=f"{key}/p0")
        top.legend(fontsize=7, ncol=3, loc="upper left")
        top.set_ylabel("surface")
        v = sf.values[name] / p0
        cs = ax.contourf(sec.along, sec.z, v, levels=20, cmap="viridis")
        ax.contour(sec.along, sec.z, v, levels=10, colors="w", linewidths=0.4)
        m = sf.maxima[name]
        ax.plot([m[1] if sec.kind == "y" else m[2]], [m[3]], "r+", ms=10, mew=2)
        ax.set_title(f"{'von Mises' if name == 'von_mises' else 'Tresca'} / p0 (body {sf.body}, state {k}, "
                     f"{sec.label}): max {m[0] / p0:.3f} at depth {m[3]:.4g}", fontsize=9)
        ax.invert_yaxis()
        ax.set_xlabel("x" if sec.kind == "y" else "y")
        ax.set_ylabel("depth z")
        fig.colorbar(cs, ax=ax)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return str(path)


# =========================================================================== generated kernels
# Written by benchmarks/derive_subsurface3d.py (sympy): regenerate, do not edit. Arguments X = x − ξ,
# Y = y − η at a corner (ξ, η), the depth z > 0 and ν; returns the 18 kernels, for p, q_x, q_y in turn the
# six components of COMPONENTS (tension positive, per unit load).
def _corner_kernels(X, Y, z, nu):  # noqa: C901 (generated)
    x0 = pi**(-1.0)
    x1 = Y**2
    x2 = x1*z
    x3 = X**2
    x4 = z**2
    x5 = x1 + x3
    x6 = x4 + x5
    x7 = sqrt(x6)
    x8 = x2 + x3*x7
    x9 = x8**(-1.0)
    x10 = x5*x9
    x11 = x7 + z
    x12 = x11**(-1.0)
    x13 = X*Y
    x14 = x12*x13
    x15 = arctan(x10*x14)
    x16 = x7**(-1.0)
    x17 = Y*x16
    x18 = X*x17
    x19 = x12*x18
    x20 = x3 + x4
    x21 = x20**(-3/2)
    x22 = x1/x20 + 1
    x23 = 1/sqrt(x22)
    x24 = x21*x23
    x25 = x24*z
    x26 = x13*x25
    x27 = x16*x3
    x28 = x12*x5
    x29 = 2*x7
    x30 = x27 + x29
    x31 = x3*x30
    x32 = -x1 + x10*x31 + x27*x28 - 3*x3
    x33 = x8**(-2.0)
    x34 = x11**(-2.0)
    x35 = x1*x3
    x36 = x34*x35*x5**2
    x37 = x33*x36 + 1
    x38 = x9/x37
    x39 = -x14*x32*x38
    x40 = x15 + x19 - x26 + x39
    x41 = x1 + x4
    x42 = x41**(-3/2)
    x43 = x3/x41 + 1
    x44 = x43**(-3/2)
    x45 = 3*x3
    x46 = x20**(-5/2)
    x47 = x23*x46
    x48 = x45*x47
    x49 = x22**(-3/2)
    x50 = x49/x20**(7/2)
    x51 = x4**(-1.0)
    x52 = x6**(-1.0)
    x53 = x3*x52
    x54 = x51*x53
    x55 = x1*x54 + 1
    x56 = x55**(-1.0)
    x57 = x53 - 1
    x58 = x56*x57
    x59 = x6**(-3/2)
    x60 = 3*x59
    x61 = 2*x59/x55**2
    x62 = x51*x61
    x63 = -x1*x57**2*x62 + 3*x24 + x35*x50 + x42*x44 - x48 + x58*x60
    x64 = Y*x24
    x65 = (1/2)*z
    x66 = X*x65
    x67 = x64*x66
    x68 = 1/sqrt(x43)
    x69 = x42*x68
    x70 = x69*z
    x71 = x13*x70
    x72 = x3*z
    x73 = x1*x7 + x72
    x74 = x73**(-1.0)
    x75 = x5*x74
    x76 = arctan(x14*x75)
    x77 = 3*x1
    x78 = x1*x16
    x79 = x29 + x78
    x80 = x1*x79
    x81 = -x28*x78 + x3 - x75*x80 + x77
    x82 = x73**(-2.0)
    x83 = x36*x82 + 1
    x84 = x74/x83
    x85 = x14*x81*x84
    x86 = x19 - x71 + x76 + x85
    x87 = (2*nu - 1)**(-1.0)
    x88 = nu**2*x87
    x89 = z**(-1.0)
    x90 = arctan(x18*x89)
    x91 = x16*z
    x92 = x51 + x52
    x93 = x56*x92
    x94 = -x13*x91*x93 + x26 + x71 + x90
    x95 = Y*x65
    x96 = X*x95
    x97 = nu*x87
    x98 = x41**(-5/2)
    x99 = x68*x98
    x100 = x44/x41**(7/2)
    x101 = x1*x52
    x102 = x101 - 1
    x103 = x102*x56
    x104 = x100*x35 - x102**2*x3*x62 + x103*x60 + x21*x49 + 3*x69 - x77*x99
    x105 = 3*x4
    x106 = x100*x3
    x107 = x35*x61
    x108 = x6**(-2.0)
    x109 = x56*x91
    x110 = x1*x4*x50 - x105*x47 - x105*x99 + x106*x4 - x107*x92**2 + x109*(3*x108*z + x52*x89 + 2/z**3) - 2*x16*x93 + x24 + x69
    x111 = -1/2*nu*x40*x87 - 1/2*nu*x86*x87 - 1/2*nu*x87*x94 + x104*x96*x97 + x110*x96*x97 + x40*x88 + x63*x96*x97 + x86*x88 + x88*x94
    x112 = x111 + (1/2)*x19
    x113 = X*x69
    x114 = x113*x95
    x115 = (1/2)*x91
    x116 = log(x11)
    x117 = x91 + 1
    x118 = x12*z
    x119 = x117*x118
    x120 = 2*x12
    x121 = x34*z
    x122 = x4*x52
    x123 = x12*x91
    x124 = x65*(x117**2*x121 - x117*x120 + x123*(x122 - 1) + x16 - x4*x59)
    x125 = -x51 - x52
    x126 = x16*x89
    x127 = x107*x89*x92
    x128 = x25 + x70
    x129 = x2*x3*x50 - x48*z
    x130 = x109*(x108*x45 + x125 + x54) - x126*x58 - x127*x57 + x128 + x129 - x44*x72*x98
    x131 = x130*x95
    x132 = x106*x2 - 3*x2*x99
    x133 = -x102*x127 - x103*x126 + x109*(x101*x51 + x108*x77 + x125) + x128 + x132 - x2*x46*x49
    x134 = x133*x66
    x135 = 1/sqrt(x20)
    x136 = arcsinh(Y*x135)
    x137 = 1/sqrt(x41)
    x138 = Y*x137*x68
    x139 = x3*x64
    x140 = x17*x58
    x141 = -Y*x123 + Y*x16 - x136 - x138 + x139 - x140
    x142 = x12*x16
    x143 = -x142
    x144 = x12*x59
    x145 = x144*x3
    x146 = x34*x53
    x147 = 4*x12
    x148 = x10*x30
    x149 = 2*x5
    x150 = -3*x142*x5 + 6
    x151 = x149*x35/x11**3
    x152 = -x12*x3*x38*(-x10*(-X**4*x59 + 5*x27 + x29) + x120*x148*x27 + x145*x5 + x146*x149 - x147*x27 - 2*x148 + x149*x3*x30**2*x33 + x150 - 4*x31*x9) + x120*x32*x38 + x129 + x143 + x145 + x146 + x151*x32**2/(x37**2*x8**3) + x25
    x153 = -x136 - x138 + x139 - x17*x56*x57
    x154 = x118 - 1
    x155 = x154*x88
    x156 = x117*x121 + x12*x122 - x12 - x52*z
    x157 = x115*x156
    x158 = Y*x157
    x159 = -nu*x153*x87 + x131*x97 + x141*x88 + x152*x95*x97 + x153*x88 + x155*x17 + x158*x97
    x160 = arcsinh(X*x137)
    x161 = X*x135*x23
    x162 = x1*x113
    x163 = X*x16
    x164 = nu*x154
    x165 = x103*x163
    x166 = X*x157
    x167 = (1/2)*x0
    x168 = x0*x124
    x169 = -x102*x163*x56 - x160 - x161 + x162
    x170 = -X*x123 + X*x16 - x160 - x161 + x162 - x165
    x171 = x1*x144
    x172 = x101*x34
    x173 = -x81
    x174 = x75*x79
    x175 = -x1*x12*x84*(x1*x149*x79**2*x82 + x120*x174*x78 - x147*x78 + x149*x172 + x150 + x171*x5 - 2*x174 - 4*x74*x80 - x75*(-Y**4*x59 + x29 + 5*x78)) + x120*x173*x84 + x132 + x143 + x151*x173**2/(x73**3*x83**2) + x171 + x172 + x70
    x176 = -nu*x169*x87 + x134*x97 + x155*x163 + x166*x97 + x169*x88 + x170*x88 + x175*x66*x97
    return (x0*((1/2)*X*Y*x63*z + nu*x40 - x112 - 1/2*x15 - 1/2*x39 + x67),
            x0*((1/2)*X*Y*x104*z + nu*x86 - x112 + x114 - 1/2*x76 - 1/2*x85),
            x0*((1/2)*X*Y*x110*z + (1/2)*X*Y*x16*x56*x92*z + nu*x94 - x111 - x114 - x67 - 1/2*x90),
            x0*(nu*(x116 + x119 - x91) + x115 - 1/2*x116 - 1/2*x119 + x124),
            x0*x131,
            x0*x134,
            x0*((1/2)*Y*x152*z + nu*x141 - x153 - x159),
            x0*(Y*nu*x154*x16 + (1/2)*Y*x156*x16*z - x159),
            x0*((1/2)*Y*x130*z + nu*x153 - x159),
            x0*((1/2)*x160 + (1/2)*x161 - 1/2*x162 + x163*x164 + (1/2)*x165 + x166),
            x167*(X*Y*x63*z - x94),
            x168,
            x0*(X*nu*x154*x16 + (1/2)*X*x156*x16*z - x176),
            x0*((1/2)*X*x175*z + nu*x170 - x169 - x176),
            x0*((1/2)*X*x133*z + nu*x169 - x176),
            x0*((1/2)*x136 + (1/2)*x138 - 1/2*x139 + (1/2)*x140 + x158 + x164*x17),
            x168,
            x167*(X*Y*x104*z - x94))

def _point_kernels(X, Y, z, nu):
    x0 = pi**(-1.0)
    x1 = X**2
    x2 = Y**2
    x3 = z**2
    x4 = x1 + x2 + x3
    x5 = x4**(-3/2)
    x6 = sqrt(x4)
    x7 = x6 + z
    x8 = x7**(-1.0)
    x9 = x5*x8
    x10 = x4**(-1.0)
    x11 = x7**(-2.0)
    x12 = x10*x11
    x13 = x4**(-5/2)
    x14 = 3*x13
    x15 = x1*x14
    x16 = x15*z
    x17 = x4**(-2.0)
    x18 = x11*x17
    x19 = x18*x3
    x20 = x1*x19
    x21 = x15*x8
    x22 = x5*z
    x23 = x6**(-1.0)
    x24 = x23*z
    x25 = x24 + 1
    x26 = x11*x25
    x27 = x22*x26
    x28 = x7**(-3.0)
    x29 = x25*x28
    x30 = x10*x29
    x31 = x30*z
    x32 = x1*x31
    x33 = x23*x8
    x34 = x24*x26
    x35 = x22 - x3*x9 + x33 - x34
    x36 = -x1*x12 + x1*x27 - x1*x9 - x16 + 2*x20 + x21*x3 + 2*x32 + x35
    x37 = x4**(-7/2)
    x38 = 15*x37
    x39 = x3*x38
    x40 = x1*x39
    x41 = 9*x13*z
    x42 = x41*x8
    x43 = 6*z
    x44 = x18*x43
    x45 = 4*x30
    x46 = 2*x5
    x47 = x26*x46
    x48 = z**3
    x49 = x11/x4**3
    x50 = 8*x48*x49
    x51 = x38*x48*x8
    x52 = x10*x3
    x53 = x52 - 1
    x54 = x18*z
    x55 = x53*x54
    x56 = x25**2
    x57 = x28*x56
    x58 = 2*x57
    x59 = x22*x58
    x60 = 2*x22*x28
    x61 = x53*x60
    x62 = x7**(-4.0)
    x63 = x43*x62
    x64 = x10*x56*x63
    x65 = x13*x3
    x66 = 6*x65
    x67 = x26*x66
    x68 = x17*x29
    x69 = 8*x3*x68
    x70 = x14*x3
    x71 = x14*x48
    x72 = x71*x8
    x73 = x23*x26
    x74 = 2*x73
    x75 = 3*x22
    x76 = x75*x8
    x77 = x12*x53
    x78 = x77*z
    x79 = x24*x58
    x80 = x3*x47
    x81 = -x5 + x70 - x72 + x74 + x76 - x78 - x79 - x80
    x82 = -x1*x42 - x1*x44 - x1*x45 - x1*x47 + x1*x50 + x1*x51 + x1*x55 + x1*x59 + x1*x61 + x1*x64 + x1*x67 + x1*x69 + x15 - x40 + x81
    x83 = (3/2)*x65
    x84 = x8*x83
    x85 = (1/2)*x22
    x86 = x26*x85
    x87 = nu**2
    x88 = (2*nu - 1)**(-1.0)
    x89 = x87*x88
    x90 = x14*x2
    x91 = x90*z
    x92 = x19*x2
    x93 = x70*x8
    x94 = x2*x31
    x95 = -x12*x2 + x2*x27 - x2*x9 + x2*x93 + x35 - x91 + 2*x92 + 2*x94
    x96 = x11*x56
    x97 = x25**3
    x98 = x28*x97
    x99 = x33*x53
    x100 = 3*x5
    x101 = x100*x8
    x102 = x101*x3*x53 + 3*x34*x53 - x71 + x75 - 3*x96 + 2*x98*z - 3*x99
    x103 = nu*x102
    x104 = z**4
    x105 = x22*x8
    x106 = 12*x53
    x107 = 3*x12
    x108 = x107*z
    x109 = 5*x104
    x110 = x24*x57
    x111 = x26*x3*x5
    x112 = -x100 - x104*x38 - x105*x106 + x106*x110 + x106*x111 - x106*x73 + x108*x53**2 + x25**4*x63 + 18*x65 + x76*(x109*x17 - 6*x52 + 1) - 8*x98
    x113 = (1/2)*z
    x114 = nu*x88
    x115 = x82*z
    x116 = x2*x39
    x117 = -x116 - x2*x42 - x2*x44 - x2*x45 - x2*x47 + x2*x50 + x2*x51 + x2*x55 + x2*x59 + x2*x61 + x2*x64 + x2*x67 + x2*x69 + x81 + x90
    x118 = x117*z
    x119 = -1/2*nu*x36*x88 - 1/2*nu*x88*x95 - x102*x87*x88 + (1/2)*x103*x88 + x112*x113*x114 + (1/2)*x114*x115 + (1/2)*x114*x118 + x36*x89 + x89*x95
    x120 = -1/2*x11*x23*x25*z + x119 - 1/2*x3*x5*x8 + (1/2)*x33 + x85
    x121 = (3/2)*x13
    x122 = x121*x48
    x123 = x14*z
    x124 = 2*x19
    x125 = 2*x31
    x126 = x113*(x14 - x39 - x42 - x44 - x45 - x47 + x50 + x51 + x55 + x59 + x61 + x64 + x67 + x69)
    x127 = X*x0
    x128 = Y*x127
    x129 = x65*x8
    x130 = -x26*x75
    x131 = x123 + x9
    x132 = x109*x37*x8 + x124*x53 + x125*x53 - 6*x129 + x130 + x131 - x23*x58 + 2*x24*x62*x97 + x26*x71 + x3*x46*x57 - 5*x37*x48 - x77
    x133 = (3/2)*x132*z
    x134 = Y*x0
    x135 = -x76
    x136 = x100 - x108 + x135
    x137 = 3*x54
    x138 = x1*x137 + x1*x60 - x15 + x16*x8
    x139 = x136 + x138
    x140 = x101 + x107 - 9*x129 + x130 - 6*x19 - x30*x43 + x41
    x141 = x38*z
    x142 = 3*x18
    x143 = x28*x46
    x144 = x28*x66
    x145 = 12*x3*x49
    x146 = 6*x22*x25*x62
    x147 = x43*x68
    x148 = -x1*x141 - x1*x142 - x1*x143 + x1*x144 + x1*x145 + x1*x146 + x1*x147 + x16*x26 - x21 + x40*x8
    x149 = x140 + x148
    x150 = -x105 - x12*z + x5
    x151 = x137*x2 + x2*x60 + x8*x91 - x90
    x152 = x150 + x151
    x153 = x12 - x124 - x125 + x131 - x27 - x93
    x154 = x116*x8 - x141*x2 - x142*x2 - x143*x2 + x144*x2 + x145*x2 + x146*x2 + x147*x2 + x26*x91 - x8*x90
    x155 = x153 + x154
    x156 = x113*x155
    x157 = x135 + x5 - x70 + x72 - x74 + x78 + x79 + x80
    x158 = nu*x157
    x159 = x114*x133 - x157*x87*x88 + x158*x88
    x160 = x113*x114*x149 + x114*x156 + x139*x89 + x152*x89 + x159
    x161 = -3/2*x132*z + x158
    x162 = x138 + x150
    x163 = x148 + x153
    x164 = x113*x163
    x165 = x110 + x111 + x113*x77 + x122*x8 - 3/2*x22*x8 + (1/2)*x5 - x73 - x83
    x166 = (1/2)*x0
    x167 = x126*x128
    x168 = x136 + x151
    x169 = x140 + x154
    x170 = x113*x114*x169 + x114*x164 + x159 + x162*x89 + x168*x89
    return (x0*(nu*x36 + (1/2)*x1*x10*x11 + (3/2)*x1*x13*z + (1/2)*x1*x5*x8 - x1*x84 - x1*x86 - x120 - x20 - x32 + (1/2)*x82*z),
            x0*(nu*x95 + (1/2)*x10*x11*x2 + (1/2)*x117*z - x120 + (3/2)*x13*x2*z + (1/2)*x2*x5*x8 - x2*x84 - x2*x86 - x92 - x94),
            x0*(-x103 + (3/2)*x11*x23*x25*x53*z + (1/2)*x112*z - x119 - x122 + x28*x97*z + (3/2)*x3*x5*x53*x8 + (3/2)*x5*z - 3/2*x96 - 3/2*x99),
            x128*(nu*(-x12 - x123 + x124 + x125 + x27 - x9 + x93) + (1/2)*x12 + x121*z + x126 - x19 - x31 - x84 - x86 + (1/2)*x9),
            x127*x133,
            x133*x134,
            x127*(nu*x139 + (1/2)*x149*z - x160 - x81),
            x127*(nu*x152 + (1/2)*x155*z - x160),
            x127*(-x160 - x161),
            x134*(nu*x162 + x164 + x165),
            x166*(x102 + x115),
            x167,
            x134*(nu*x162 + (1/2)*x163*z - x170),
            x134*(nu*x168 + (1/2)*x169*z - x170 - x81),
            x134*(-x161 - x170),
            x127*(nu*x152 + x156 + x165),
            x167,
            x166*(x102 + x118))

