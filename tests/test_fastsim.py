"""FASTSIM (rollqp.methods.fastsim): Kalker's simplified theory as one more 3D method.

Validated as the method's docstring says: its linear limit is Kalker's linear theory by construction (the
flexibilities are made from C11, C22, C23), so the only error left there is the grid's quadrature of the
contact ellipse, which must fall as the grid is refined; it saturates to μFN; and against the exact
solution of the same discrete problem (Newton) its error is that of the simplified theory (a few per cent
in partial slip), stated here as a bound measured on two scenes.
"""
from __future__ import annotations

import numpy as np
import pytest

from rollqp import cli, load_scene
from rollqp.errors import InputError
from rollqp.methods import available_methods
from rollqp.methods.fastsim import fastsim_traction, flexibilities
from rollqp.closedforms.kalker import kalker_linear
from rollqp.march.grid import run


def steady(name="kalker-circular", method="fastsim", n=None, **changes):
    base = {"solver.method": method, "discretization.distance": 0.0}
    if n is not None:
        s = load_scene(name)
        nx, ny = s.discretization.elements
        base["discretization.elements"] = [n * nx // min(nx, ny), n * ny // min(nx, ny)]
    scene = load_scene(name, {**base, **changes})
    return scene, run(scene).arrays()


def kalker_forces(scene, xi, eta, phi):
    e, m = scene.ellipse, scene.materials
    C11, C22, C23 = kalker_linear(e.a / e.b, m.nu)
    c, G = e.c, m.G
    return -G * c * c * C11 * xi, -G * c * c * (C22 * eta + c * C23 * phi)


def test_registered_for_3d():
    assert "fastsim" in available_methods(3)


@pytest.mark.parametrize("creep", [dict(xi=1e-6, eta=0.0, phi=0.0), dict(xi=0.0, eta=1e-6, phi=0.0),
                                   dict(xi=0.0, eta=0.0, phi=1e-7)])
def test_the_linear_limit_is_kalkers_theory_up_to_the_grids_quadrature(creep):
    """a/b = 0.5 (kalker-elliptic's ellipse): each creepage alone, tiny (nothing slips); the error against
    -G c² C ξ falls as the grid doubles (quadrature of the ellipse by the elements in contact)."""
    errs = []
    for n in (16, 32, 64):
        changes = {"load.creepage.longitudinal": creep["xi"], "load.creepage.lateral": creep["eta"],
                   "load.creepage.spin": creep["phi"]}
        scene, r = steady("kalker-elliptic", n=n, **changes)
        assert np.all(r["state"][0][r["pn"][0] > 0] == 1), "everything sticks"
        Fx, Fy = kalker_forces(scene, creep["xi"], creep["eta"], creep["phi"])
        got, ref = (float(r["Fx"][0]), Fx) if creep["xi"] else (float(r["Fy"][0]), Fy)
        errs.append(abs(got / ref - 1))
    assert errs[2] < errs[0] and errs[2] < 0.02, errs     # measured below


def test_it_saturates_to_mu_fn():
    scene, r = steady(**{"load.creepage.longitudinal": 0.1})
    cap = scene.mu * scene.load.normal
    assert abs(abs(float(r["Fx"][0])) / cap - 1) < 1e-9     # every element slips at μp: Σ μ p area = μ FN
    assert np.all(r["state"][0][r["pn"][0] > 0] == 2)


def test_prescribed_forces_are_met():
    scene, r = steady(**{"load.creepage.longitudinal": None, "load.tangential": 0.5})
    assert float(r["Fx"][0]) == pytest.approx(0.5 * scene.mu * scene.load.normal, rel=1e-8)


def test_its_error_against_the_exact_solution_of_the_same_problem():
    """kalker-elliptic (ξ, η, φ together, partial slip) and a circle at ξ = 1e-3 (half the contact slips):
    FASTSIM against Newton on the same grid and pressure. Measured: 13 % in Fx and 1 % in Fy on
    kalker-elliptic, 4.4 % on the circle (docs/performance.md); the bounds below leave room for the grid."""
    for name, changes, bound in (("kalker-elliptic", {}, 0.2),
                                 ("kalker-circular", {"load.creepage.longitudinal": 1e-3}, 0.06)):
        _, f = steady(name, **changes)
        _, x = steady(name, method="newton", **changes)
        F, X = np.hypot(f["Fx"][0], f["Fy"][0]), np.hypot(x["Fx"][0], x["Fy"][0])
        assert abs(F / X - 1) < bound, (name, F, X)
        assert abs(F / X - 1) > 1e-3, "an approximation: not the exact answer"


def test_flexibilities_give_the_coefficients_back():
    L1, L2, L3 = flexibilities(2.0, 1.0, 3.0, 0.25)
    C11, C22, C23 = kalker_linear(2.0, 0.25)
    assert 8 * 2.0 / (3 * L1 * 3.0) == pytest.approx(C11) and 8 * 2.0 / (3 * L2 * 3.0) == pytest.approx(C22)
    assert np.pi * 2.0 * np.sqrt(2.0) / (4 * L3 * 3.0) == pytest.approx(C23)


def test_stick_grows_linearly_from_the_leading_edge_either_way():
    x = np.arange(-0.95, 1.0, 0.1)
    y = np.zeros_like(x)
    for e in (1, -1):
        t = fastsim_traction(x, y, np.full(x.size, 1e9), 0.1, (1.0, 1.0, 1.0), 1.0, 1.0, 1e-3, 0.0, 0.0, e)
        assert np.allclose(t[0], 1e-3 * e * (x - e))


def test_rolling_steps_and_dissimilar_bodies_are_refused_in_one_line(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert cli.main(["run", "kalker-circular", "--method", "fastsim", "--quiet"]) == cli.EXIT_INPUT
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "steady state" in err and "--method newton" in err
    assert not list(tmp_path.iterdir())
    with pytest.raises(InputError, match="similar bodies"):
        steady(**{"bodies.B.E": 70000.0})
