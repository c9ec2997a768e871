"""Subsurface stresses of the computed tractions: exact Flamant integrals over the strip's elements.

Each body is a plane-strain half-space ``z > 0`` (z the depth into the body, x along the strip
as everywhere in rollqp) loaded on its surface by the pressure ``p`` and, on body A, the traction
``t`` in +x (body B receives ``−t``; docs/formulation.md §1). The stresses are the Flamant
line-load kernels (Johnson, *Contact Mechanics*, 1985, eq. 2.23 and 2.25) integrated over the
traction's shape functions (eq. 31 of the paper, :class:`rollqp.strip.Strip`) in closed form,
element by element (docs/stresses.md §1)::

    σxx = −(2/π) ∫ [p(s) X² z + t(s) X³] / r⁴ ds
    σzz = −(2/π) ∫ [p(s) z³   + t(s) X z²] / r⁴ ds        X = x − s,  r² = X² + z²
    τxz = −(2/π) ∫ [p(s) X z² + t(s) X² z] / r⁴ ds

With a polynomial traction on an element written in powers of X, every term is
``z^j ∫ X^(a+j) z^(3−a) / r⁴ dX = z^j J_(a+j)``, and the six primitives ``J_0 … J_5`` of
``u^k/(1+u²)²`` (u = X/z) are elementary (:func:`_primitives`, written without cancellation:
arctangent and logarithm differences as one ``atan2`` and one ``log``). Out of plane
``σyy = ν(σxx + σzz)`` (plane strain) with the body's own ν; the equivalents (principal stresses,
the in-plane maximum shear τ1, von Mises and Tresca) follow (:func:`invariants`).

``rollqp.stresses(result, step, grid)`` (:func:`stresses`, exported by the package) is the
post-processing step of docs/architecture.md: it rebuilds the strip from the scene stored in the
result file; the rest of this module (``rollqp.subsurface``) is the fields, their history over a run
and the figures. BEM scenes use the same half-space
field from their BEM tractions; the approximation and its size are in docs/stresses.md §4.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .errors import InputError
from .result import Result, load_result, save_npz
from .scene import load_scene
from .strip import Strip

__all__ = ["influence_matrices", "stress_components", "invariants", "StressField", "StressHistory",
           "stresses", "stress_history", "default_grid", "COMPONENTS", "QUANTITIES"]

COMPONENTS = ("sxx", "szz", "txz")
#: Every quantity of a :class:`StressField` (σyy, principal stresses s1 ≥ s2 ≥ s3 of the 3D tensor,
#: τ1 the in-plane maximum shear, von Mises and Tresca equivalents).
QUANTITIES = COMPONENTS + ("syy", "s1", "s2", "s3", "tau1", "von_mises", "tresca")
#: Smallest half-width and depth of :func:`default_grid` (units of a_H): the field is computed to
#: round-off down to depths of 1e-5 a_H per grid point; far below, its kernels (1/r⁴) lose all digits.
MIN_EXTENT = 1e-3
#: Traction values (states × nodes) of a block of states in :func:`stress_history`.
STATES_PER_BLOCK = 1 << 20
#: Points per block of the element integrals: about 30 arrays of block × elements doubles that stay
#: in the processor's cache (the costs by block size: docs/stresses.md §8).
BLOCK = 512


# =========================================================================== kernel integrals
def _primitives(X, z):
    """``[J_k(X_b/z) − J_k(X_a/z)]`` for k = 0…5 on every element, ``J_k = ∫ u^k/(1+u²)² du``.

    ``X`` (m, ne+1) holds ``x − s`` at the element ends (``X_b = X[:, :-1]``, ``X_a = X[:, 1:]``,
    the orientation of ``ds = −dX``); the transcendental parts are evaluated once per end::

        J0 = ½[u/(1+u²) + atan u]      J1 = −½/(1+u²)          J2 = ½[atan u − u/(1+u²)]
        J3 = ½[ln(1+u²) + 1/(1+u²)]    J4 = u − (3/2) atan u + ½ u/(1+u²)
        J5 = ½u² − ln(1+u²) − ½/(1+u²)
    """
    r = X * X + z * z
    th, ln, rat, odd = np.arctan2(X, z), np.log(r), z * z / r, z * X / r

    def diff(v):
        return v[:, :-1] - v[:, 1:]
    dth, dln, drat, dodd = diff(th), diff(ln), diff(rat), diff(odd)
    dX = diff(X)
    du, du2 = dX / z, dX * (X[:, :-1] + X[:, 1:]) / (z * z)
    return (0.5 * (dodd + dth), -0.5 * drat, 0.5 * (dth - dodd), 0.5 * (dln + drat),
            du - 1.5 * dth + 0.5 * dodd, 0.5 * du2 - dln - 0.5 * drat)


def _element_terms(strip: Strip, x, z):
    """Per point and element: ``T[a][m] = ∫_el ξ^m X^a z^(3−a)/r⁴ ds`` for a = 0…3, m = 0…2.

    ``ξ = (d − X)/h`` with ``d = x − s_c`` (element centre ``s_c``, half-length ``h``), so
    ``ξ^m = Σ_j C(m,j) d^(m−j) (−X)^j / h^m`` and ``∫ X^(a+j) z^(3−a)/r⁴ ds = z^j J_(a+j)``.
    """
    e0, e1 = strip.edges[:-1], strip.edges[1:]
    sc, h = 0.5 * (e0 + e1), 0.5 * (e1 - e0)
    zz = z[:, None]
    d = x[:, None] - sc[None, :]
    J = _primitives(x[:, None] - strip.edges[None, :], zz)
    nm = strip.coefficients.shape[1]
    T = [[None] * nm for _ in range(4)]
    for a in range(4):
        zj = [J[a], zz * J[a + 1], zz * zz * J[a + 2]]          # z^j J_(a+j), j = 0, 1, 2
        T[a][0] = zj[0]
        if nm > 1:
            T[a][1] = (d * zj[0] - zj[1]) / h
            T[a][2] = (d * d * zj[0] - 2.0 * d * zj[1] + zj[2]) / (h * h)
    return T


#: (component, power a of X in the kernel X^a z^(3−a)): σxx, σzz, τxz of p, then of t
_POWERS = ((2, 0, 1), (3, 1, 2))


def _element_polynomials(strip: Strip, v) -> list:
    """``V_m`` (ne, S): the traction ``Σ_m V_m ξ^m`` on each element, for each of S states ``v`` (S, n)."""
    coef, conn = strip.coefficients, strip.connectivity
    nodal = v[:, conn]                                          # (S, ne, nen)
    return [(nodal @ coef[:, m]).T for m in range(coef.shape[1])]


def _contract(strip: Strip, x, z, P, T) -> np.ndarray:
    """σxx, σzz, τxz (S, 3, m) of the states ``P`` (pressure) and ``T`` (traction), (S, n) each."""
    terms = _element_terms(strip, x, z)
    out = np.zeros((P.shape[0], 3, x.size))
    for side, v in enumerate((P, T)):
        if not np.any(v):
            continue
        V = _element_polynomials(strip, v)
        for comp, a in enumerate(_POWERS[side]):
            for m, Vm in enumerate(V):
                if terms[a][m] is not None and np.any(Vm):
                    out[:, comp] += (terms[a][m] @ Vm).T
    return -2.0 / np.pi * out


def influence_matrices(strip: Strip, x, z) -> np.ndarray:
    """``G`` of shape (6, m, n): stresses at the m points (x, z) per unit nodal traction.

    Rows: σxx, σzz, τxz due to ``p`` (compressive), then due to ``t`` (+x on the body); the
    stresses of tractions ``p``, ``t`` are ``G[:3] @ p + G[3:] @ t``. Exact for the strip's shape
    functions (module docstring). ``z`` must be > 0.
    """
    x, z = np.asarray(x, dtype=float).ravel(), np.asarray(z, dtype=float).ravel()
    n = strip.n
    G = np.empty((6, x.size, n))
    I, Z = np.eye(n), np.zeros((n, n))
    G[:3] = _contract(strip, x, z, I, Z).transpose(1, 2, 0)
    G[3:] = _contract(strip, x, z, Z, I).transpose(1, 2, 0)
    return G


def stress_components(strip: Strip, x, z, p, t) -> np.ndarray:
    """σxx, σzz, τxz of tractions ``p``, ``t`` (shape (S, n) or (n,)) at points (x, z).

    Returns shape (S, 3, m) (or (3, m) for one state), evaluated in blocks of :data:`BLOCK`
    points so that memory stays bounded on large grids.
    """
    p, t = np.asarray(p, dtype=float), np.asarray(t, dtype=float)
    one = p.ndim == 1
    P, Tt = np.atleast_2d(p), np.atleast_2d(t)
    x, z = np.asarray(x, dtype=float).ravel(), np.asarray(z, dtype=float).ravel()
    out = np.empty((P.shape[0], 3, x.size))
    for i in range(0, x.size, BLOCK):
        out[:, :, i:i + BLOCK] = _contract(strip, x[i:i + BLOCK], z[i:i + BLOCK], P, Tt)
    return out[0] if one else out


def invariants(sxx, szz, txz, nu) -> dict:
    """σyy = ν(σxx + σzz) (plane strain), principal stresses s1 ≥ s2 ≥ s3, τ1, von Mises, Tresca.

    τ1 = √(((σxx − σzz)/2)² + τxz²) is the in-plane maximum shear (Johnson's τ1); Tresca is
    s1 − s3 over all three principal stresses, von Mises √(½[(s1−s2)² + (s2−s3)² + (s3−s1)²]).
    """
    syy = nu * (sxx + szz)
    mean, tau1 = 0.5 * (sxx + szz), np.hypot(0.5 * (sxx - szz), txz)
    pr = np.sort(np.stack([mean + tau1, mean - tau1, syy]), axis=0)[::-1]
    s1, s2, s3 = pr
    vm = np.sqrt(0.5 * ((s1 - s2) ** 2 + (s2 - s3) ** 2 + (s3 - s1) ** 2))
    return dict(sxx=sxx, szz=szz, txz=txz, syy=syy, s1=s1, s2=s2, s3=s3, tau1=tau1, von_mises=vm,
                tresca=s1 - s3)


# =========================================================================== result objects
@dataclass
class StressField:
    """Stresses of one state on a grid: ``values[name]`` has shape (nz, nx) (:data:`QUANTITIES`).

    ``maxima[name] = (value, x, z)`` for τ1, von Mises, Tresca and s1 (largest tension), and
    ``minima["s3"]`` the largest compression. Lengths in the scene's units, stresses too.
    """

    x: np.ndarray
    z: np.ndarray
    values: dict
    body: str
    step: int
    q: float
    maxima: dict = field(default_factory=dict)

    def __getitem__(self, name):
        return self.values[name]


@dataclass
class StressHistory:
    """Maxima of every stored state on one grid: ``peaks[name]`` is (K+1, 3) rows (value, x, z);
    ``overall[name] = (value, x, z, step)``: where and when the material is most loaded."""

    x: np.ndarray
    z: np.ndarray
    steps: np.ndarray
    peaks: dict
    overall: dict
    body: str


PEAKS = ("tau1", "von_mises", "tresca", "s1")


def _locate(v, X, Z) -> tuple[float, float, float]:
    i = int(np.argmax(v))
    return float(v.flat[i]), float(X.flat[i]), float(Z.flat[i])


def _field(strip, X, Z, p, t, nu) -> dict:
    """Every quantity of :data:`QUANTITIES` on the grid (X, Z), each of shape X.shape."""
    s = stress_components(strip, X.ravel(), Z.ravel(), p, t)
    return {k: v.reshape(X.shape) for k, v in invariants(s[0], s[1], s[2], nu).items()}


def _maxima(values: dict, X, Z) -> dict:
    out = {k: _locate(values[k], X, Z) for k in PEAKS}
    v, x, z = _locate(-values["s3"], X, Z)
    out["s3"] = (-v, x, z)  # the largest compression
    return out


# =========================================================================== the post-processing step
def _source(result) -> tuple[dict, object]:
    """``(arrays, scene)`` of a :class:`~rollqp.result.Result`, a ``load_result`` dict or a path."""
    if isinstance(result, Result):
        arrays = dict(result.arrays())
        arrays["meta"] = result.meta
    elif isinstance(result, dict):
        arrays = result
    else:
        arrays = load_result(result, "result")
    for key in ("pn", "pt"):
        if key not in arrays:
            raise InputError("result", f"the result file holds no tractions (no key {key!r}): nothing to "
                                       "compute stresses from")
    meta = arrays.get("meta")
    if isinstance(meta, (str, np.ndarray)):  # Result.arrays() keeps meta as its JSON text
        import json
        try:
            meta = json.loads(str(meta))
        except json.JSONDecodeError:
            meta = None
    if not isinstance(meta, dict) or not isinstance(meta.get("scene"), dict):
        raise InputError("result", "the result holds no scene (meta['scene']): the strip cannot be rebuilt")
    scene = load_scene(meta["scene"])
    for key, value in (("a_H", scene.a_H), ("p0", scene.p0)):  # what the grid and the summary divide by
        got = float(np.asarray(arrays.get(key, np.nan), dtype=float).reshape(-1)[0]) if np.size(arrays.get(key, [])) == 1 \
            else float("nan")
        if not abs(got - value) <= 1e-9 * value:
            raise InputError("result", f"key {key!r} = {got!r} is not the {key} of the scene stored in the file "
                                       f"({value:.6g}): a corrupt or edited file")
    return arrays, scene


def _strip(arrays, scene) -> Strip:
    d = scene.discretization
    strip = Strip(scene.half_width, d.elements, d.element)
    x = np.asarray(arrays["x"], dtype=float)
    if x.shape != strip.x.shape or not np.allclose(x, strip.x, rtol=0, atol=1e-9 * scene.half_width):
        raise InputError("result", "the nodes 'x' are not those of the scene stored in the result file")
    return strip


def _step(step, K1: int) -> int:
    if isinstance(step, bool) or not isinstance(step, (int, np.integer)):
        raise InputError("step", f"must be an integer in [0, {K1 - 1}] (a stored state; negative counts from "
                                 f"the end), got {step!r}")
    if not -K1 <= step < K1:
        raise InputError("step", f"must be in [0, {K1 - 1}] (the result holds {K1} states), got {step}")
    return int(step) % K1


def _body(body: str, scene):
    if body not in ("A", "B"):
        raise InputError("body", f"must be 'A' or 'B', got {body!r}")
    return (scene.A if body == "A" else scene.B), (1.0 if body == "A" else -1.0)


def default_grid(scene, nx: int = 200, nz: int = 200, width: float = 1.5, depth: float = 2.0):
    """A grid under the contact: ``nx`` points on ±width·a_H, ``nz`` depths in (0, depth·a_H].

    The first depth is ``depth·a_H/nz``: the surface itself (z = 0) is not a point of the
    field (the kernels are singular there); the surface values are the tractions.
    """
    for key, v, lo in (("nx", nx, 1), ("nz", nz, 1)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not lo <= v <= 4000:
            raise InputError(key, f"must be an integer in [1, 4000], got {v!r}")
    for key, v in (("width", width), ("depth", depth)):
        if isinstance(v, bool) or not (isinstance(v, (int, float, np.integer, np.floating)) and np.isfinite(v)
                                       and MIN_EXTENT <= v <= 100):
            raise InputError(key, f"must be a number in [{MIN_EXTENT:g}, 100] (units of a_H), got {v!r}")
    a = scene.a_H
    return np.linspace(-width * a, width * a, nx), np.linspace(depth * a / nz, depth * a, nz)


def check_grid(grid) -> tuple[np.ndarray, np.ndarray]:
    """``grid = (x, z)``: 1-D arrays of finite coordinates, every depth z > 0 (below the surface)."""
    try:
        gx, gz = grid
        gx = np.asarray(gx, dtype=float)
        gz = np.asarray(gz, dtype=float)
    except (TypeError, ValueError):
        raise InputError("grid", "must be a pair (x, z) of 1-D arrays of coordinates (scene length units)") from None
    if gx.ndim != 1 or gz.ndim != 1 or gx.size < 1 or gz.size < 1:
        raise InputError("grid", f"x and z must be non-empty 1-D arrays, got shapes {gx.shape}, {gz.shape}")
    if gx.size * gz.size > 4_000_000:
        raise InputError("grid", f"at most 4e6 points, got {gx.size} x {gz.size}")
    if not (np.all(np.isfinite(gx)) and np.all(np.isfinite(gz))):
        raise InputError("grid", "coordinates must be finite")
    if np.any(gz <= 0):
        raise InputError("grid", f"every depth z must be > 0 (below the surface, z into the body); got "
                                 f"min z = {gz.min():.6g}")
    return gx, gz


def stresses(result, step: int, grid=None, body: str = "A") -> StressField:
    """Subsurface stresses of state ``step`` of ``result`` in ``body`` on ``grid = (x, z)``.

    Parameters
    ----------
    result : Result, dict (``load_result``) or path of a result file
    step : int
        A stored state, 0…K (negative: from the end).
    grid : (x, z) or None
        1-D coordinates (scene length units, z > 0 the depth into the body); None:
        :func:`default_grid` (200 × 200 on ±1.5 a_H, depth 2 a_H).
    body : {"A", "B"}
        Body A carries ``t``, body B ``−t``; ν of that body enters σyy, von Mises and Tresca.
    """
    arrays, scene = _source(result)
    strip = _strip(arrays, scene)
    k = _step(step, len(arrays["q"]))
    mat, sign = _body(body, scene)
    gx, gz = check_grid(default_grid(scene) if grid is None else grid)
    X, Z = np.meshgrid(gx, gz)
    with np.errstate(all="ignore"):  # a grid too close to the surface: not finite, said below
        values = _field(strip, X, Z, np.asarray(arrays["pn"][k], dtype=float), sign * np.asarray(arrays["pt"][k], dtype=float),
                        mat.nu)
    _finite(values.values())
    return StressField(gx, gz, values, body, k, float(arrays["q"][k]), _maxima(values, X, Z))


def _finite(arrays) -> None:
    """The stresses are finite (a point too close to the surface, or too far in scene units, overflows the
    kernels 1/r⁴): otherwise an :class:`InputError` on the grid, never NaN peaks."""
    for v in arrays:
        if not np.all(np.isfinite(v)):
            raise InputError("grid", "the stresses are not finite on this grid: its points are too close to the "
                                     "surface or too far from the contact for the kernels (use depths of at least "
                                     "1e-5 a_H and points within 1e6 a_H)")


def stress_history(result, grid=None, body: str = "A", steps=None) -> StressHistory:
    """Maxima (value, x, z) of τ1, von Mises, Tresca, s1 and s3 at every stored state (or ``steps``),
    and the overall maximum over them with its step: where and when the material is most loaded.

    The element integrals are evaluated once per block of points and applied to every state.
    """
    arrays, scene = _source(result)
    strip = _strip(arrays, scene)
    K1 = len(arrays["q"])
    ks = np.arange(K1) if steps is None else np.array([_step(s, K1) for s in steps], dtype=int)
    mat, sign = _body(body, scene)
    gx, gz = check_grid(default_grid(scene, 100, 60) if grid is None else grid)
    X, Z = np.meshgrid(gx, gz)
    x, z = X.ravel(), Z.ravel()
    best = {name: np.full((ks.size, 3), -np.inf) for name in PEAKS + ("s3",)}
    per = max(1, STATES_PER_BLOCK // max(1, np.shape(arrays["pn"])[1]))
    for j in range(0, ks.size, per):  # a block of states at a time: a long run's states need not fit in memory
        sel = ks[j:j + per]
        P, T = np.asarray(arrays["pn"][sel], dtype=float), sign * np.asarray(arrays["pt"][sel], dtype=float)
        _block_peaks(strip, x, z, P, T, mat.nu, {k: v[j:j + per] for k, v in best.items()})
    best["s3"][:, 0] *= -1
    overall = {}
    for name, rows in best.items():
        j = int(np.argmin(rows[:, 0]) if name == "s3" else np.argmax(rows[:, 0]))
        overall[name] = (float(rows[j, 0]), float(rows[j, 1]), float(rows[j, 2]), int(ks[j]))
    return StressHistory(gx, gz, ks, best, overall, body)


def _block_peaks(strip, x, z, P, T, nu, best) -> None:
    """The peaks of the states ``P``, ``T`` over the points ``x``, ``z`` into ``best`` (rows value, x, z)."""
    S = P.shape[0]
    for i in range(0, x.size, BLOCK):
        with np.errstate(all="ignore"):
            s = _contract(strip, x[i:i + BLOCK], z[i:i + BLOCK], P, T)
            inv = invariants(s[:, 0], s[:, 1], s[:, 2], nu)
        _finite(inv.values())
        inv["s3"] = -inv["s3"]
        for name, rows in best.items():
            j = np.argmax(inv[name], axis=1)
            v = inv[name][np.arange(S), j]
            better = v > rows[:, 0]
            rows[better] = np.stack([v, x[i:i + BLOCK][j], z[i:i + BLOCK][j]], axis=1)[better]


def save_field(sf: StressField, path) -> str:
    """Write a :class:`StressField` to a ``.npz`` (x, z, every quantity, the maxima), atomically."""
    arrays = {"x": sf.x, "z": sf.z, "step": np.asarray(sf.step), "q": np.asarray(sf.q),
              "body": np.asarray(sf.body)}
    arrays.update({k: np.asarray(v) for k, v in sf.values.items()})
    for name, (v, x, z) in sf.maxima.items():
        arrays[f"max_{name}"] = np.array([v, x, z])
    return save_npz(path, arrays, "stress file")


def summary_rows(sf: StressField, p0: float, a: float) -> list[tuple[str, str]]:
    """Rows of the summary table: the peaks of the state (units of p0, positions in a_H)."""
    names = {"von_mises": "peak von Mises", "tau1": "peak tau1", "tresca": "peak Tresca", "s1": "peak tension s1",
             "s3": "peak compression s3"}
    return [(label, f"{sf.maxima[k][0] / p0:.4f} p0 at x = {sf.maxima[k][1] / a:.4f} a_H, "
                    f"z = {sf.maxima[k][2] / a:.4f} a_H") for k, label in names.items()]
