"""The interface layer (rollqp.influence.layer; docs/theory3d.md, "Interface layer"): its compliance h/G3 in the
tangential operators of both dimensions, the brush it tends to when it dominates the bodies (rollqp.closedforms.brush)
with a first-order slope as the grid doubles, and bad input in one line naming the key. CONTACT's tractcurv
series with the layer: tests/test_tractcurv.py."""
from __future__ import annotations

import numpy as np
import pytest

import layer_cases as lc
import rollqp
from rollqp.discretization.grid import Grid
from rollqp.errors import InputError
from rollqp.influence.grid import ContactOperators
from rollqp.influence.layer import Layer, LayeredOperators, grid_kernel, parse_layer
from rollqp.materials import Materials


def test_the_layer_adds_its_compliance_to_the_tangential_operators_only():
    """A_tt + c I; A_nn and the couplings unchanged; the rolling step's shifted copy takes the element the particle
    came from (half and half on a shared edge); the steady operator adds c times the upwind difference."""
    g = Grid.centred(7, 5, 1.0, 0.8)
    base = ContactOperators(g, Materials.from_young(1.0, 0.3, 3.0, 0.2))      # dissimilar: the couplings exist
    c = 0.37
    ops = LayeredOperators(base, Layer(0.37 * 2.0, 2.0))
    rng = np.random.default_rng(3)
    t, p = rng.standard_normal(2 * g.n), rng.standard_normal(g.n)
    assert ops.Ann is base.Ann and ops.Ant is base.Ant and ops.Atn is base.Atn
    assert np.allclose(ops.Att @ t, base.Att @ t + c * t, rtol=1e-13, atol=1e-14)
    assert np.allclose(ops.Att.dense(), base.Att.dense() + c * np.eye(2 * g.n), rtol=1e-13, atol=1e-14)
    # one element along -x (the upstream element of d = +1: material moving in +x came from x - dx)
    field = t.reshape(2, g.ny, g.nx)
    up = np.zeros_like(field)
    up[:, :, 1:] = field[:, :, :-1]
    assert np.allclose(ops.shifted("tt", -g.dx) @ t - base.shifted("tt", -g.dx) @ t, c * up.ravel(), atol=1e-13)
    half = ops.shifted("tt", -0.5 * g.dx) @ t - base.shifted("tt", -0.5 * g.dx) @ t
    assert np.allclose(half, 0.5 * c * (t + up.ravel()), atol=1e-13)
    st = ops.steady("tt", 1) @ t - base.steady("tt", 1) @ t
    assert np.allclose(st, c * (t - up.ravel()), atol=1e-13)
    assert ops.steady("tn", -1) is base.steady("tn", -1)
    assert np.allclose(ops.Atn @ p, base.Atn @ p)
    assert grid_kernel(g, c, (0.0, 0.0)).sum() == pytest.approx(c)


def test_a_dominating_layer_is_the_brush_in_3d():
    """F/(μFN) against eq. B.1 on 11, 22, 44 elements across: measured errors 16.8 %, 6.0 %, 3.7 % (κ = 0.3) and
    7.1 %, 4.8 %, 2.9 % (κ = 1), order 1.1 and 0.65 — first order with the staircase scatter of the rows' leading
    edges (the first stuck element of a row carries k ξ dx, the brush k ξ times its distance from the edge). The
    bodies' own elasticity (1e-4 of the layer's) moves the ratio by about 1e-4 (measured: 1e-3 at 1e-3)."""
    errs, hs = zip(*(lc.brush_3d(n) for n in (11, 22, 44)))
    errs = np.array(errs)
    assert np.all(errs > 0), errs          # the upwind first element over-counts: the discrete brush is stiffer
    assert lc.order(errs[:, 0], hs) > 0.9 and lc.order(errs[:, 1], hs) > 0.55, errs
    assert np.all(errs[-1] < 0.04), errs


def test_a_dominating_layer_is_the_brush_in_2d():
    """The same closed form on the strip (constant elements, 22, 44, 88 over ±1.1 a_H: the leading edge on a node):
    measured 4.85 %, 2.45 %, 1.21 % (κ = 0.3) and 3.88 %, 1.94 %, 0.97 % (κ = 1), order 1.0."""
    errs, hs = zip(*(lc.brush_strip(n) for n in (22, 44, 88)))
    errs = np.array(errs)
    assert np.all(errs > 0), errs
    assert lc.order(errs[:, 0], hs) > 0.9 and lc.order(errs[:, 1], hs) > 0.9, errs
    assert np.all(errs[-1] < 0.015), errs


def test_the_matrix_free_strip_takes_the_layer_as_the_dense_one():
    """mf-newton's FFT operators with the layer's diagonal (LayeredDiagonal) against the dense newton: the same
    steady creep force to the solvers' tolerance (1e-10 in p0: measured ≤ 1e-9 relative)."""
    s = rollqp.load_scene("cattaneo-carter").replace(**{
        "load.start": "rolling", "discretization.distance": 0.0, "load.tangential": None, "load.creepage": 2e-4,
        "discretization.elements": 60, "discretization.element": "constant",
        "contact.layer": {"thickness": 0.01, "shear_modulus": 8000.0}})
    dense = float(rollqp.run(s).arrays()["Q"][0])
    free = float(rollqp.run(s.replace(**{"solver.method": "mf-newton", "solver.operator": "matrix-free"})).arrays()["Q"][0])
    bare = float(rollqp.run(s.replace(**{"contact.layer": None})).arrays()["Q"][0])
    assert abs(free / dense - 1) < 1e-8
    assert abs(dense) < abs(bare)          # the layer adds compliance: less force at the same creepage


@pytest.mark.parametrize("layer, key", [
    ({"thickness": -1.0, "shear_modulus": 1.0}, "contact.layer.thickness"),
    ({"thickness": 1.0, "shear_modulus": 0.0}, "contact.layer.shear_modulus"),
    ({"thickness": 1.0}, "contact.layer.shear_modulus"),
    ({"thickness": 1.0, "shear_modulus": 1.0, "tau": 0.0}, "contact.layer.tau"),
    ({"thickness": float("nan"), "shear_modulus": 1.0}, "contact.layer.thickness"),
    ({"thickness": 1e9, "shear_modulus": 1e-3}, "contact.layer.thickness"),      # 1e5 times the bodies' compliance
    (0.5, "contact.layer"),
])
@pytest.mark.parametrize("scene", ["kalker-circular", "cattaneo-carter"])
def test_bad_layers_are_one_line_naming_the_key(scene, layer, key):
    with pytest.raises(InputError) as err:
        rollqp.load_scene(scene, {"contact.layer": layer})
    assert err.value.key == key and "\n" not in str(err.value)


def test_a_layer_reads_back_and_zero_thickness_is_no_layer():
    s = rollqp.load_scene("kalker-circular", {"contact.layer": {"thickness": 1.25, "shear_modulus": 8200.0}})
    assert rollqp.load_scene(s.to_dict()) == s
    assert parse_layer({"thickness": 0.0, "shear_modulus": 1.0}).compliance == 0.0
    s0 = rollqp.load_scene("kalker-elliptic", {"contact.layer": {"thickness": 0.0, "shear_modulus": 1.0}})
    bare = rollqp.load_scene("kalker-elliptic")
    from rollqp.march.grid import run
    assert float(run(s0).arrays()["Fx"][0]) == float(run(bare).arrays()["Fx"][0])


def test_the_transient_with_a_layer_settles_on_its_steady_state():
    """The rolling steps' layer (the element the particle came from, eq. L.2 at the offset −d·Δq): cattaneo-3d braked
    at Fx = 0.6 μFN, then rolled 6 a on 20 × 20, with a layer that more than doubles the creepage (−0.00407 against
    −0.00182 without it). The last steps' creepage is the steady state's with the same force and layer: measured
    7e-6 relative (the transient's decay after 6 a)."""
    from rollqp.march.grid import run
    s = rollqp.load_scene("cattaneo-3d").replace(**{"contact.layer": {"thickness": 0.05, "shear_modulus": 8000.0},
                                                    "discretization.elements": [20, 20], "discretization.distance": 6.0})
    marched = run(s).arrays()["creepage"][-1, 0]
    steady = s.replace(**{"load.start": "rolling", "discretization.distance": 0.0})
    direct = run(steady).arrays()["creepage"][0, 0]
    bare = run(steady.replace(**{"contact.layer": None})).arrays()["creepage"][0, 0]
    assert abs(marched / direct - 1) < 1e-4, (marched, direct)
    assert direct / bare > 2.0


def test_the_conic_route_takes_the_layer_as_newton_does():
    """A second method: kalker-elliptic (ξ, η and φ) on 18 × 36 with a layer, Newton against Clarabel's SOCP of the
    same steady step: the tractions to 1.5e-12 μp0 measured (Clarabel at rollqp's 1e-10, not its defaults)."""
    from rollqp.march.grid import run
    s = rollqp.load_scene("kalker-elliptic", {"contact.layer": {"thickness": 0.02, "shear_modulus": 8000.0},
                                              "discretization.elements": [18, 36]})
    a, b = run(s).arrays(), run(s, method="socp-clarabel").arrays()
    unit = s.mu * s.ellipse.p0
    assert max(np.max(np.abs(a[k] - b[k])) for k in ("px", "py")) / unit < 1e-9
    assert abs(a["Fx"][0]) < abs(run(s.replace(**{"contact.layer": None})).arrays()["Fx"][0])


@pytest.mark.parametrize("name, overrides", [
    ("cattaneo-carter", {"discretization.distance": 2.0}),
    ("kalker-circular", {"discretization.elements": [16, 16]}),
])
def test_a_run_names_its_layer_and_compares_no_closed_form_of_bare_bodies(tmp_path, name, overrides):
    """`rollqp run` on a scene with a layer: the summary's row of the layer; Carter's, Cattaneo's and Kalker's closed
    forms (of bodies without one) are not compared; the 2D cross-check with the QP backends agrees (a second method:
    measured 2.5e-12 μp0 on cattaneo-carter)."""
    import subprocess
    import sys
    s = rollqp.load_scene(name, {"contact.layer": {"thickness": 0.01, "shear_modulus": 8e4}, **overrides})
    (tmp_path / "s.toml").write_text(s.to_toml())
    r = subprocess.run([sys.executable, "-m", "rollqp.cli", "run", "s.toml", "--out", "s.npz"], capture_output=True,
                       text=True, timeout=600, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "interface layer   h = 0.01" in r.stdout or "interface layer  h = 0.01" in r.stdout, r.stdout
    assert "error: carter" not in r.stdout and "error: cattaneo" not in r.stdout
    if name == "kalker-circular":
        assert "error: kalker     not compared: the interface layer" in r.stdout, r.stdout
    else:
        line = next(ln for ln in r.stdout.splitlines() if ln.strip().startswith("cross-check"))
        assert "|dt|" in line and float(line.split("|dt| ")[1].split()[0]) < 1e-9, line
