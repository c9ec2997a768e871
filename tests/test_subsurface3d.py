"""Subsurface stresses in 3D (docs/stresses.md §9, docs/validation3d.md §11): the point-load kernels against
Boussinesq's and Cerruti's solution (equilibrium, free surface, resultants), the rectangle integrals against
quadrature, Huber's and Hamilton's closed forms with their convergence as the grid doubles, CONTACT's
``subsurf`` example on its grid, and the command."""
from __future__ import annotations

import numpy as np
import pytest

from rollqp.closedforms.hertz3d import hamilton_normal, huber_axis, sliding_axis_shear
from rollqp.errors import InputError
from rollqp.subsurface3d import (COMPONENTS, invariants, parse_depths, parse_line, parse_plane, point_load,
                                 stress_components)
from rollqp.operators.grid import Contact
from rollqp.methods.newton.disc import NewtonMethod
from rollqp.discretization.grid import Grid
from rollqp.materials import Materials

from pathlib import Path

DATA = Path(__file__).parent / "data" / "contact3d"
NU = 0.28


# ------------------------------------------------------------------------------ the point loads
def test_point_load_is_boussinesq_and_cerruti():
    """σ_iz = −3 z x_i (F·x)/(2πρ⁵) for both point loads (Johnson eq. 3.20, 3.22), Boussinesq's trace
    −(1+ν)P z/(πρ³); equilibrium by central differences; a free surface away from the load."""
    x, y, z = np.array([0.37, -1.2, 0.05]), np.array([-0.52, 0.3, 0.8]), np.array([0.61, 0.2, 1.5])
    s = point_load(x, y, z, NU)
    rho = np.sqrt(x * x + y * y + z * z)
    for k, F in enumerate((z, x, y)):             # F·x of a unit p (into the body), q_x, q_y
        for c, xi in ((2, z), (4, x), (5, y)):    # σzz, σxz, σyz
            np.testing.assert_allclose(s[k, c], -3 * z * xi * F / (2 * np.pi * rho ** 5), rtol=1e-13, atol=1e-16)
    np.testing.assert_allclose(s[0, 0] + s[0, 1] + s[0, 2], -(1 + NU) * z / (np.pi * rho ** 3), rtol=1e-13)
    h = 1e-4                                      # div σ = 0: central differences, error O(h²) ~ 1e-8 here
    for k in range(3):
        def comp(dx, dy, dz, c):
            return point_load(x + dx, y + dy, z + dz, NU)[k, c]
        T = {(0, 0): 0, (1, 1): 1, (2, 2): 2, (0, 1): 3, (1, 0): 3, (0, 2): 4, (2, 0): 4, (1, 2): 5, (2, 1): 5}
        for i in range(3):
            div = sum((comp(*(h * np.eye(3)[j]), T[i, j]) - comp(*(-h * np.eye(3)[j]), T[i, j])) / (2 * h)
                      for j in range(3))
            assert np.max(np.abs(div)) < 1e-6, (k, i, div)
    free = point_load(np.array([0.7, -0.4]), np.array([0.2, 0.9]), 1e-9, NU)
    assert np.max(np.abs(free[:, [2, 4, 5]])) < 1e-8


def _composite_gauss(lo, hi, width, order=12):
    """Nodes and weights of a composite Gauss–Legendre rule on [lo, hi] with panels of at most ``width``."""
    k = max(1, int(np.ceil((hi - lo) / width)))
    t, w = np.polynomial.legendre.leggauss(order)
    edges = np.linspace(lo, hi, k + 1)
    h = np.diff(edges)[:, None] / 2
    return ((edges[:-1, None] + h * (t + 1)).ravel(), (h * w).ravel())


def test_rectangle_integrals_match_quadrature():
    """Every one of the 18 kernels integrated over a rectangle (eq. 3D.S1) against quadrature of the point
    loads (composite Gauss rules with panels of z/3: agree to 1e-14 of the largest, the rule's own error measured
    below 2e-15 by halving the panels; the closed forms to 6e-15)."""
    g = Grid(1, 1, 1.0, 0.6, -0.5, -0.3)
    for pt in [(0.1, 0.2, 0.3), (0.7, -0.4, 0.05), (-2.0, 1.5, 0.5), (0.5, 0.3, 0.2)]:   # the last above a corner
        got = np.stack([stress_components(g, *pt, *(np.eye(3)[k].reshape(3, 1, 1)), NU)[:, 0] for k in range(3)])
        s, ws = _composite_gauss(-0.5, 0.5, pt[2] / 3)
        e, we = _composite_gauss(-0.3, 0.3, pt[2] / 3)
        S, E = np.meshgrid(s, e)
        ref = point_load(pt[0] - S, pt[1] - E, pt[2], NU) @ np.outer(we, ws).ravel()
        assert np.max(np.abs(got - ref)) < 1e-13 * np.max(np.abs(ref)), (pt, got - ref)


def test_corner_weights_sum_the_elements():
    """On a grid, the corner sums of all elements equal the sum of their one-element fields."""
    g = Grid(3, 2, 0.5, 0.4, -0.75, -0.4)
    rng = np.random.default_rng(1)
    L = rng.normal(size=(3, 2, 3))
    pts = (np.array([0.1, -0.6, 0.9]), np.array([0.0, 0.3, -0.5]), np.array([0.2, 0.1, 0.6]))
    whole = stress_components(g, *pts, *L, NU)
    parts = 0
    for j in range(2):
        for i in range(3):
            one = np.zeros_like(L)
            one[:, j, i] = L[:, j, i]
            parts = parts + stress_components(g, *pts, *one, NU)
    np.testing.assert_allclose(whole, parts, rtol=1e-12, atol=1e-14)


# ------------------------------------------------------------------------------ closed forms
def _gauss_disk(x, y, z, a, p0, nu, load, n=160, b=None):
    """∫∫ p0√(1 − x²/a² − y²/b²) · point load over the ellipse (b = a: the circle), product Gauss rule in
    (u, θ), (x, y) = sin u (a cos θ, b sin θ): smooth; 160 × 320 points agree with 320 × 640 to 6e-14."""
    b = a if b is None else b
    u, wu = np.polynomial.legendre.leggauss(n)
    u, wu = (u + 1) * np.pi / 4, wu * np.pi / 4
    t, wt = np.polynomial.legendre.leggauss(2 * n)
    t, wt = (t + 1) * np.pi, wt * np.pi
    U, T = np.meshgrid(u, t)
    W = np.outer(wt, wu) * a * b * np.sin(U) * np.cos(U) * p0 * np.cos(U)
    r = np.sin(U)
    k = point_load(x - a * r * np.cos(T), y - b * r * np.sin(T), z, nu)[load]
    return (k * W.ravel()).sum(axis=1)


def test_hamilton_and_axis_shear_against_quadrature():
    """The closed forms themselves: Hamilton's normal field and the sliding traction's σxz on the axis against
    Gauss quadrature of the point loads (to 1e-9 p0)."""
    a, p0, nu = 1.0, 1.0, 0.3
    for pt in [(0.3, 0.2, 0.4), (1.2, -0.5, 0.6)]:
        np.testing.assert_allclose(hamilton_normal(*pt, a, p0, nu), _gauss_disk(*pt, a, p0, nu, 0), atol=1e-9)
    for z in (0.3, 0.8):
        assert abs(sliding_axis_shear(z, a, p0, 1.0) - _gauss_disk(0.0, 0.0, z, a, p0, nu, 1)[4]) < 1e-9
    sxx, szz = huber_axis(np.array([0.5]), a, p0, nu)
    ref = _gauss_disk(1e-12, 0.0, 0.5, a, p0, nu, 0)
    assert abs(sxx[0] - ref[0]) < 1e-9 and abs(szz[0] - ref[2]) < 1e-9


def _hertz_errors(n, nu=0.3, mu=0.3):
    m = Materials.from_young(210e3, nu, 210e3, nu)
    c = Contact.hertzian(m, (1 / 60, 1 / 60), 1000.0, mu, elements=(n, n), zone=(1.3, 1.3))
    p = c.grid.field(NewtonMethod().solve(c.normal_step(1000.0)).p)
    e = c.ellipse
    z = np.linspace(0.1, 2, 20) * e.a
    s = stress_components(c.grid, 0 * z, 0 * z, z, p, mu * p, 0 * p, nu)      # sliding: q_x = μp
    sxx, szz = huber_axis(z, e.a, e.p0, nu)
    huber = max(np.abs(s[0] - sxx).max(), np.abs(s[1] - sxx).max(), np.abs(s[2] - szz).max()) / e.p0
    shear = np.abs(s[4] - sliding_axis_shear(z, e.a, e.p0, mu)).max() / e.p0
    X, Y, Z = np.array([0.5, 0.3, -0.7]) * e.a, np.array([0.2, -0.6, 0.1]) * e.a, np.array([0.4, 0.5, 0.3]) * e.a
    off = stress_components(c.grid, X, Y, Z, p, mu * p, 0 * p, nu)
    ref = hamilton_normal(X, Y, Z, e.a, e.p0, nu) + mu * np.stack([_gauss_disk(X[i], Y[i], Z[i], e.a, e.p0, nu, 1)
                                                                    for i in range(3)], axis=1)
    return c.grid.dx / e.a, huber, shear, np.abs(off - ref).max() / e.p0


@pytest.mark.parametrize("ns", [(11, 21), pytest.param((21, 41, 81), marks=pytest.mark.slow)])
def test_hertz_and_sliding_sphere_converge(ns):
    """Huber (axis), Hamilton (normal field off the axis) and the sliding traction μp: the stresses of the
    computed Hertz pressure converge at order ≈ 2 as the grid doubles (docs/validation3d.md §11: measured
    slopes 1.7-2.4; the staircase of the discrete contact area makes single ratios irregular)."""
    rows = [_hertz_errors(n) for n in ns]
    h = np.array([r[0] for r in rows])
    for col in (1, 2, 3):
        e = np.array([r[col] for r in rows])
        slope = np.log(e[0] / e[-1]) / np.log(h[0] / h[-1])
        assert slope > 1.5, (col, e, slope)
    assert rows[-1][1] < 3e-3 and rows[-1][2] < 1e-3 and rows[-1][3] < 1e-2   # the 21 × 21 grid: measured 5.6e-4, 1.5e-4, 1.2e-3


@pytest.mark.parametrize("ns", [(11, 21), pytest.param((11, 21, 41), marks=pytest.mark.slow)])
def test_elliptic_hertz_with_sliding_traction_converges(ns):
    """An ellipse a/b = 0.5 with q_x = 0.3p: the six components on the axis (8 depths 0.1a-2a) against the exact
    Hertz pressure's and traction's stresses by Gauss quadrature of the point loads; measured 1.7e-3, 3.6e-4,
    9.0e-5 p0 on 11, 21, 41 elements along x (slopes 2.42, 2.08)."""
    from rollqp.closedforms.hertz_ellipse import curvatures_for_ratio
    m = Materials.from_young(210e3, 0.3, 210e3, 0.3)
    errs, hs = [], []
    for n in ns:
        c = Contact.hertzian(m, (1 / 60, curvatures_for_ratio(1 / 60, 0.5)), 1000.0, 0.3, elements=(n, 2 * n),
                             zone=(1.3, 1.3))
        p = c.grid.field(NewtonMethod().solve(c.normal_step(1000.0)).p)
        e = c.ellipse
        z = np.linspace(0.1, 2, 8) * e.a
        s = stress_components(c.grid, 0 * z, 0 * z, z, p, 0.3 * p, 0 * p, 0.3)
        ref = np.stack([_gauss_disk(0.0, 0.0, zz, e.a, e.p0, 0.3, 0, b=e.b)
                        + 0.3 * _gauss_disk(0.0, 0.0, zz, e.a, e.p0, 0.3, 1, b=e.b) for zz in z], axis=1)
        errs.append(np.abs(s - ref).max() / e.p0)
        hs.append(c.grid.dx / e.a)
    assert np.log(errs[0] / errs[-1]) / np.log(hs[0] / hs[-1]) > 1.7, errs
    assert errs[-1] < 5e-4, errs


# ------------------------------------------------------------------------------ CONTACT's subsurf
def _contact_subsurf():
    rows = [line.split() for line in open(DATA / "subsurf.ref_subs") if not line.startswith("%")]
    data = np.array([[float(v) for v in r] for r in rows if len(r) == 14])
    return data[np.any(data[:, 3:] != 0, axis=1) & (data[:, 2] > 0)]   # the points, not the blocks' headers


def test_contact_subsurf_example():
    """CONTACT's ``subsurf`` case 2 (one element [−0.4999, 0.5001] × [−0.4998, 0.5002], pn = 1, px = 0.999,
    ν = 0.28): every point below the surface (6188) agrees to the digits CONTACT prints (6 significant:
    |d| ≤ 5e-6 |ref| + 5e-7); z = 0 is not a point of rollqp's field (the surface values are the tractions)."""
    d = _contact_subsurf()
    assert len(d) == 6188
    g = Grid(1, 1, 1.0, 1.0, -0.4999, -0.4998)
    inv = invariants(stress_components(g, d[:, 0], d[:, 1], d[:, 2], [[1.0]], [[0.999]], [[0.0]], 0.28))
    cols = dict(hydrostatic=6, von_mises=7, sxx=8, sxy=9, sxz=10, syy=11, syz=12, szz=13)
    for name, c in cols.items():
        assert np.all(np.abs(inv[name] - d[:, c]) <= 5e-6 * np.abs(d[:, c]) + 5e-7), name


# ------------------------------------------------------------------------------ input
def test_bad_input_names_the_argument():
    g = Grid(1, 1, 1.0, 1.0, -0.5, -0.5)
    for call, key in ((lambda: stress_components(g, 0, 0, 0.0, [[1.0]], [[0.0]], [[0.0]], 0.3), "depths"),
                      (lambda: stress_components(g, 0, 0, 1.0, [[1.0]], [[0.0]], [[0.0]], 0.7), "nu"),
                      (lambda: stress_components(g, 0, 0, 1.0, [1.0, 2.0], [[0.0]], [[0.0]], 0.3), "tractions"),
                      (lambda: stress_components(g, np.nan, 0, 1.0, [[1.0]], [[0.0]], [[0.0]], 0.3), "points"),
                      (lambda: parse_plane("z=1"), "--plane"), (lambda: parse_plane("y=abc"), "--plane"),
                      (lambda: parse_line("x=1"), "--line"), (lambda: parse_depths("0.1,-2"), "--depths"),
                      (lambda: parse_depths("inf"), "--depths")):
        with pytest.raises(InputError) as err:
            call()
        assert err.value.key == key
    assert parse_plane(" x = 2.5") == ("x", 2.5) and parse_line("y=1,x=-2") == (-2.0, 1.0)
    assert COMPONENTS == ("sxx", "syy", "szz", "sxy", "sxz", "syz")


# ------------------------------------------------------------------------------ the command
@pytest.fixture(scope="module")
def result3d(tmp_path_factory):
    from rollqp import load_scene
    from rollqp.march.grid import run
    scene = load_scene("cattaneo-3d").replace(**{"discretization.elements": [12, 12], "discretization.distance": 1.0,
                                                 "name": "cattaneo-3d-coarse"})
    path = tmp_path_factory.mktemp("s3") / "r.npz"
    run(scene).save(path)
    return path


def test_command_on_a_3d_result(result3d, tmp_path, capsys):
    """``rollqp stresses R.npz --step K`` with a plane, a line and depths: the stress file holds the section's
    points and every quantity, equal to the API's; the figure is written; the peaks are printed."""
    from rollqp import cli
    from rollqp.result import load_result
    from rollqp.subsurface3d import stresses3d
    out, fig = tmp_path / "s.npz", tmp_path / "s.png"
    assert cli.main(["stresses", str(result3d), "--step", "-1", "--plane", "x=0.02", "--depths", "0.05,0.1,0.3",
                     "--out", str(out), "--plot", str(fig)]) == 0
    text = capsys.readouterr().out
    assert "peak von Mises" in text and "plane x = 0.02" in text
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with np.load(out, allow_pickle=False) as f:
        got = {k: f[k] for k in f.files}
    sf = stresses3d(load_result(result3d), -1, plane=("x", 0.02), depths=[0.05, 0.1, 0.3])
    assert got["x"].shape == got["sxx"].shape == (3, 12) and np.all(got["x"] == 0.02)
    for k in COMPONENTS + ("von_mises", "s1", "s3"):
        np.testing.assert_array_equal(got[k], sf[k])
    assert got["max_von_mises"][0] == sf.values["von_mises"].max()
    assert cli.main(["stresses", str(result3d), "--step", "0", "--line", "x=0,y=0", "--plot", str(fig)]) == 0


@pytest.mark.parametrize("args, key", [(["--grid", "3,4"], "--grid"), (["--plane", "z=1"], "--plane"),
                                       (["--line", "x=1"], "--line"), (["--depths", "0.1,0"], "--depths"),
                                       (["--step", "99"], "--step"),
                                       (["--plane", "y=0", "--line", "x=0,y=0"], "--line")])
def test_command_refuses_bad_3d_input_in_one_line(result3d, args, key, capsys):
    from rollqp import cli
    argv = ["stresses", str(result3d)] + (["--step", "1"] if "--step" not in args else []) + args
    assert cli.main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"rollqp: error: {key}:"), err


def test_history_and_body_b(result3d):
    """The peaks of every state on a line (``stress_history3d``) are those of each state's field; body B is loaded
    by p and −(p_x, p_y): just below a slipping element its σxz is +p_x where A's is −p_x."""
    from rollqp.result import load_result
    from rollqp.subsurface3d import stress_history3d, stresses3d
    a = load_result(result3d)
    z = [0.01, 0.05, 0.2]
    h = stress_history3d(a, line=(0.0, 0.0), depths=z)
    for k in range(len(a["q"])):
        sf = stresses3d(a, k, line=(0.0, 0.0), depths=z)
        # the same sums, states in one matrix product or one at a time: equal to round-off
        assert abs(h.peaks["von_mises"][k, 0] - sf.values["von_mises"].max()) <= 1e-13 * float(a["p0"])
        assert abs(h.peaks["s3"][k, 0] - sf.values["s3"].min()) <= 1e-13 * float(a["p0"])
    k = int(np.argmax(h.peaks["von_mises"][:, 0]))
    assert h.overall["von_mises"][4] == k
    j, i = np.unravel_index(np.argmax(np.abs(a["px"][-1])), a["px"][-1].shape)
    x0, y0, dz = float(a["x"][i]), float(a["y"][j]), 1e-6 * float(a["a"])
    A = stresses3d(a, -1, line=(x0, y0), depths=[dz])
    B = stresses3d(a, -1, line=(x0, y0), depths=[dz], body="B")
    px = float(a["px"][-1][j, i])
    # the surface limit σxz → ∓p_x, to O(dz/dx) ≈ 1e-5 of p_x (the field of the neighbours' tractions)
    assert abs(A["sxz"][0, 0] + px) < 1e-4 * abs(px) and abs(B["sxz"][0, 0] - px) < 1e-4 * abs(px)
    assert abs(A["szz"][0, 0] - B["szz"][0, 0]) < 1e-4 * float(a["p0"])


@pytest.mark.parametrize("change, words", [("pn", "not finite"), ("x", "uniformly spaced"), ("y", "not the grid"),
                                           ("a", "'a'")])
def test_command_refuses_a_changed_3d_file_in_one_line(result3d, tmp_path, capsys, change, words):
    """A file whose tractions overflow the kernels, whose centres are not a uniform grid, whose one row is not
    the scene's grid, or whose semi-axis is not positive: one line naming RESULT.npz, exit 2 (never NaN peaks)."""
    from rollqp import cli
    with np.load(result3d, allow_pickle=False) as f:
        z = {k: f[k] for k in f.files}
    if change == "pn":
        z["pn"] = z["pn"].copy()
        z["pn"][1, 5, 5] = 1e300
    elif change == "x":
        z["x"] = z["x"].copy()
        z["x"][3] += 0.1 * (z["x"][1] - z["x"][0])
    elif change == "y":
        for k in [k for k, v in z.items() if np.ndim(v) == 3]:   # every field on the grid
            z[k] = z[k][:, :1]
        z["y"] = z["y"][:1]
    else:
        z["a"] = np.asarray(-1.0)
    np.savez(tmp_path / "bad.npz", **z)
    assert cli.main(["stresses", str(tmp_path / "bad.npz"), "--step", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("rollqp: error: RESULT.npz:") and words in err[0], err
