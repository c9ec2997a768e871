"""3D half-space influence coefficients (docs/theory3d.md §3): closed forms against quadrature and
the point-load solutions, Betti's reciprocity, positive definiteness, FFT against dense products."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from rollqp.errors import InputError
from rollqp.discretization.grid import Grid
from rollqp.influence.cerruti import kernels, point_load, rectangle_integrals
from rollqp.materials import Materials
from rollqp.influence.blocktoeplitz import BlockToeplitz
from rollqp.influence.grid import ContactOperators

STEEL_ALU = Materials.from_young(210e3, 0.28, 70e3, 0.33)   # dissimilar: K ≠ 0
INTEGRANDS = {"r": lambda x, y: 1 / math.hypot(x, y), "xx": lambda x, y: x * x / math.hypot(x, y) ** 3,
              "yy": lambda x, y: y * y / math.hypot(x, y) ** 3, "xy": lambda x, y: x * y / math.hypot(x, y) ** 3,
              "x": lambda x, y: x / (x * x + y * y), "y": lambda x, y: y / (x * x + y * y)}


@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")   # quadpack on the 1/ρ singularity
@pytest.mark.parametrize("X, Y, dx, dy", [(2.0, 1.5, 1.0, 0.5), (-3.0, 0.7, 0.8, 1.3), (0.0, 2.0, 1.0, 1.0),
                                          (0.4, 0.2, 1.0, 1.0), (0.3, 0.0, 1.0, 0.5)])
def test_rectangle_integrals_match_quadrature(X, Y, dx, dy):
    """eq. 3D.12 against adaptive quadrature, including rectangles that contain the observation
    point (the last two: integrable 1/ρ singularities inside)."""
    values = rectangle_integrals(X, Y, dx, dy)
    for key, f in INTEGRANDS.items():
        ref, err = integrate.dblquad(lambda y, x: f(x, y), X - dx / 2, X + dx / 2, Y - dy / 2, Y + dy / 2,
                                     epsabs=1e-12, epsrel=1e-12)
        # quadrature's own error bound (1e-12 asked; the singular cases stop near 1e-10) decides
        assert abs(float(values[key]) - ref) <= 1e-9 * max(1.0, abs(ref)), key


def test_self_coefficient_of_a_square():
    """The classical ∫∫ dA/ρ over a square of side 2s from its centre: 8 s asinh(1) (Love)."""
    assert rectangle_integrals(0.0, 0.0, 2.0, 2.0)["r"] == pytest.approx(8 * math.asinh(1.0), rel=1e-15)


def test_far_field_is_the_point_load():
    """Far from the element the coefficient is the point-load kernel (eq. 3D.11) times the
    area, to O((d/ρ)²): the error must fall by 4 when the distance doubles."""
    g = Grid.centred(81, 81, 8.1, 8.1)          # unit elements, offsets up to 80
    k = kernels(g, STEEL_ALU)
    errors = []
    for dist in (10, 20, 40):
        a, b = 80 + dist, 80 + dist // 2        # the offset (dist, dist/2) elements
        pl = point_load(float(dist) * g.dx, float(dist // 2) * g.dy, STEEL_ALU)
        errors.append(max(abs(k[c][b, a] / (pl[c] * g.area) - 1) for c in ("nn", "xx", "yy", "xy", "nx", "xn")))
    assert errors[0] < 2e-3   # O((1/10)²) with a small constant
    assert 3.5 < errors[0] / errors[1] < 4.5 and 3.5 < errors[1] / errors[2] < 4.5, errors


def test_full_operator_is_symmetric_and_positive_definite():
    """Betti: the 3n × 3n influence matrix of the displacement difference is exactly symmetric on the
    uniform grid (A_xn(X) = A_nx(−X), the coupling blocks antisymmetric in X) and positive definite
    (the elastic energy of the two bodies)."""
    g = Grid(7, 6, 0.3, 0.45, -1.0, -1.3)
    k = kernels(g, STEEL_ALU)
    full = BlockToeplitz(g, [[k["nn"], k["nx"], k["ny"]], [k["xn"], k["xx"], k["xy"]], [k["yn"], k["yx"], k["yy"]]])
    D = full.dense()
    assert np.array_equal(D, D.T)
    assert np.linalg.eigvalsh(D).min() > 0
    assert np.array_equal(k["xn"], -k["nx"]) and np.array_equal(k["nx"][:, ::-1], -k["nx"])


def test_pressure_draws_the_softer_surface_towards_the_load():
    """Sign of the coupling (eq. 3D.11): with body A the more compliant in (1 − 2ν)/G (K > 0), a
    pressure at the origin moves A's surface relative to B towards it: u_x < 0 ahead (x > 0)."""
    soft_top = Materials.from_young(70e3, 0.25, 210e3, 0.25)
    assert soft_top.K > 0
    g = Grid.centred(9, 9, 4.5, 4.5)
    k = kernels(g, soft_top)                    # entry [8 + j, 8 + i]: i elements along x, j along y
    assert k["xn"][8, 10] < 0 < k["xn"][8, 6]


@pytest.mark.parametrize("offset", [(0.0, 0.0), (0.3, 0.0), (-0.25, 0.1)])
def test_fft_product_equals_dense_product(offset):
    """eq. 3D.13: the FFT product is the exact linear convolution (no wrap-around), with offsets too."""
    g = Grid(11, 7, 0.25, 0.3, -1.4, -1.0)
    k = kernels(g, STEEL_ALU, offset=offset)
    op = BlockToeplitz(g, [[k["xx"], k["xy"]], [k["yx"], k["yy"]]], "Att")
    x = np.random.default_rng(3).standard_normal(2 * g.n)
    D = op.dense()
    assert np.max(np.abs(op @ x - D @ x)) <= 1e-13 * np.max(np.abs(D @ x))
    rows, cols = np.array([3, 10, 40]), np.array([0, 5, 6, 70])
    sub = op.dense(rows, cols)
    assert np.array_equal(sub[:3, :4], D[np.ix_(rows, cols)])
    assert np.array_equal(sub[3:, 4:], D[np.ix_(g.n + rows, g.n + cols)])


def test_shifted_kernel_is_the_kernel_one_element_over():
    """An offset of one element width along x is the same Toeplitz kernel moved by one index (the
    transient's previous displacements when Δq = dx, eq. 3D.16)."""
    g = Grid(10, 8, 0.2, 0.25, -1.0, -1.0)
    k0 = kernels(g, STEEL_ALU)["xx"]
    k1 = kernels(g, STEEL_ALU, offset=(g.dx, 0.0))["xx"]
    assert np.allclose(k1[:, :-1], k0[:, 1:], rtol=1e-13, atol=0)


def test_steady_operator_is_the_upwind_difference_of_displacements():
    """eq. 3D.17: (A − A(· − d dx)) t is the displacement minus the displacement one element upstream."""
    g = Grid(12, 9, 0.2, 0.3, -1.2, -1.35)
    ops = ContactOperators(g, Materials.from_young(210e3, 0.3, 210e3, 0.3))
    wide = Grid(13, 9, 0.2, 0.3, -1.2, -1.35)         # one more column downstream of the material flow
    wops = ContactOperators(wide, ops.materials)
    t = np.zeros((2, 9, 13))
    t[:, :, :12] = np.random.default_rng(0).standard_normal((2, 9, 12))
    u = (wops.Att @ t.ravel()).reshape(2, 9, 13)
    expected = u[:, :, :12] - u[:, :, 1:]               # d = −1: the particle at x came from x + dx
    got = (ops.steady("tt", -1) @ t[:, :, :12].ravel()).reshape(2, 9, 12)
    assert np.allclose(got, expected, rtol=0, atol=1e-13 * np.abs(u).max())


def test_materials_combine_like_kalker_and_the_2d_project():
    m = STEEL_ALU
    GA, GB = 210e3 / 2.56, 70e3 / 2.66
    assert 1 / m.G == pytest.approx(0.5 * (1 / GA + 1 / GB), rel=1e-14)
    assert 1 / m.Estar == pytest.approx((1 - 0.28 ** 2) / 210e3 + (1 - 0.33 ** 2) / 70e3, rel=1e-14)
    dundurs = 0.5 * ((1 - 2 * 0.28) / GA - (1 - 2 * 0.33) / GB) / ((1 - 0.28) / GA + (1 - 0.33) / GB)
    assert m.beta == pytest.approx(dundurs, rel=1e-13)


@pytest.mark.parametrize("kw, key", [(dict(G_A=-1.0, nu_A=0.3, G_B=1.0, nu_B=0.3), "bodies.A.G"),
                                     (dict(G_A=1.0, nu_A=0.6, G_B=1.0, nu_B=0.3), "bodies.A.nu"),
                                     (dict(G_A=1.0, nu_A=0.3, G_B=float("nan"), nu_B=0.3), "bodies.B.G")])
def test_bad_materials_name_the_key(kw, key):
    with pytest.raises(InputError, match=key.replace(".", r"\.")):
        Materials.from_shear(**kw)


def test_operator_refuses_a_dense_block_beyond_its_budget(monkeypatch):
    g = Grid.centred(30, 30, 1.0, 1.0)
    op = ContactOperators(g, Materials.from_young(1.0, 0.3, 1.0, 0.3)).Att
    monkeypatch.setattr("rollqp.influence.blocktoeplitz.DENSE_MAX", 1000)
    with pytest.raises(InputError, match="FFT products"):
        op.dense()
