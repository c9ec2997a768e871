"""The sliding limit of prescribed tangential forces with a friction law varying over the contact
(rollqp.friction.capacity; docs/friction.md, "The sliding limit of prescribed forces").

A stick solution exists only below ``|F| < Σ μ_i p_i A_i`` (``∫ μ p dA``). The scene checks estimate it before any
solve with the Hertz pressure on the scene's own grid (3D) or strip (2D): a patch above the reference ``μ`` carries
more than ``μ_ref FN`` (such loads are accepted and solve), a patch below it less (such loads are refused before a
step fails), and the estimate plus its margin is never below the capacity of the discrete pressure (no load with a
solution refused). A uniform coefficient keeps the plain ``μ FN`` check and its messages, to the letter."""
from __future__ import annotations

import numpy as np
import pytest

import rollqp
from rollqp import cli
from rollqp.errors import InputError
from rollqp.friction.capacity import MARGIN
from rollqp.loads import sliding_limits
from rollqp.march import run
from rollqp.methods import scene_method_3d
from rollqp.methods.newton import NewtonMethod
from rollqp.operators import SceneOperators
from rollqp.patch import computed_patch
from rollqp.scene import checks
from rollqp.scene.grid import Solver3D

SMALL3 = {"discretization.elements": [12, 12], "discretization.distance": 0.5, "load.start": "braked",
          "load.creepage": {"spin": 0.0}}
ABOVE = {"law": "patch", "mu": 0.3, "inside": 0.6, "start": 0.0, "end": 5.0}   # μ = 0.6 on x >= 0: capacity 1.5
BELOW = {"law": "patch", "mu": 0.3, "inside": 0.1, "start": 0.0, "end": 5.0}   # μ = 0.1 on x >= 0: capacity 2/3


def scene3(friction, **changes):
    return rollqp.load_scene("kalker-circular", {**SMALL3, "contact.friction": friction, **changes})


def scene2(friction, **changes):
    return rollqp.load_scene("cattaneo-carter", {"discretization.distance": 1.0, "contact.friction": {
        "law": "patch", "mu": 0.1, "start": 0.0, "end": 5.0, **friction}, **changes})


def discrete_capacity_3d(sc, q=0.0):
    """``Σ μ_i p_i A_i/(μ_ref FN)`` of the frictionless normal step's pressure on the scene's grid."""
    e, g = sc.ellipse, sc.grid
    p = computed_patch(sc.shape.at(0.0), g, sc.materials, sc.load.normal, scene_method_3d(Solver3D("newton", 1e-12)),
                       (e.A, e.B)).p.ravel()
    X, Y = g.centres()
    mu = sc.contact.friction.coefficient(np.stack([X, Y]) / e.a, q / e.a, sc.load.direction)
    return float(mu @ p) * g.area / (sc.mu * sc.load.normal)


def discrete_capacity_2d(sc, n=1.0):
    """``f·(μ p)/(μ_ref P)`` of the 2D normal step's pressure at ``P = n P̄``."""
    ops = SceneOperators.build(sc, symmetrized=False)
    P = n * sc.load.normal
    p = NewtonMethod().solve(ops.normal_step(P)).p
    mu = sc.contact.friction.coefficient(ops.strip.x[None, :] / sc.a_H, 0.0, sc.load.direction)
    return float(ops.f @ (mu * p)) / (sc.contact.mu * P)


# =========================================================================== 3D
def test_3d_patch_above_the_reference_carries_more_and_solves():
    """1.2 μ_ref FN is beyond the reference limit but below the patch's 1.5: accepted, and every step (Newton,
    12 × 12) carries exactly the prescribed force."""
    sc = scene3(ABOVE, **{"load.tangential": 0.9, "load.lateral": 0.7})           # |F| = 1.14 μ_ref FN
    c, limit = sliding_limits(sc, np.zeros(1), 1.0, np.ones(1))
    assert c[0] == pytest.approx(1.5, abs=1e-12)                                  # half the force at 0.6, by symmetry
    recs = list(rollqp.march(sc, method="newton"))
    assert len(recs) == sc.n_steps + 1 >= 3
    cap = sc.mu * sc.load.normal
    for rec in recs:                                                             # the solver's own residual: 1e-10
        assert np.hypot(rec.Fx, rec.Fy) == pytest.approx(np.hypot(0.9, 0.7) * cap, rel=1e-9)


def test_3d_patch_above_the_reference_refuses_beyond_its_capacity():
    with pytest.raises(InputError) as err:
        scene3(ABOVE, **{"load.tangential": 1.7})
    msg = str(err.value)
    assert err.value.key == "load.tangential" and "\n" not in msg
    assert "∫ mu p dA = 1.5 mu FN" in msg and "must be < 1.60417" in msg, msg     # + 0.5/4.8 (12 × 12)


def test_3d_patch_below_the_reference_refuses_before_any_solve():
    """0.8 μ_ref FN is below the reference limit but above the patch's 2/3 (and above the discrete pressure's
    capacity, so no step could solve it): refused by the scene, naming the key and the allowed range."""
    sc = scene3(BELOW)
    assert discrete_capacity_3d(sc) < 0.8
    with pytest.raises(InputError) as err:
        scene3(BELOW, **{"load.tangential": 0.8})
    assert err.value.key == "load.tangential" and "\n" not in str(err.value)
    assert "∫ mu p dA = 0.666667 mu FN" in str(err.value), str(err.value)
    with pytest.raises(InputError, match="must be < 0.736111"):                  # the direction does not matter
        scene3(BELOW, **{"load.lateral": -0.8})
    scene3(BELOW, **{"load.tangential": 0.6})                                     # below: accepted


def test_3d_a_material_patch_is_checked_at_every_step():
    """A patch below the reference carried by the material reaches the contact at q ≈ 2 a (x + q >= 3 with
    d = −1): a run that stops before is accepted, one that rolls it in is refused at a step where it covers the
    contact."""
    law = {**BELOW, "start": 3.0, "end": 50.0, "frame": "material"}
    scene3(law, **{"load.tangential": 0.6, "discretization.distance": 1.0})
    with pytest.raises(InputError, match=r"load.tangential: .* at q = (\d|\.)+ a must be < ") as err:
        scene3(law, **{"load.tangential": 0.6, "discretization.distance": 5.0})
    q = float(str(err.value).split(" at q = ")[1].split(" a ")[0])
    assert 2.0 <= q <= 5.0, str(err.value)


def test_3d_normal_history_scales_the_limit():
    """With a normal history the limit is c·FN(τ): 0.6 of μ_ref FN_ref is below 2/3 FN at FN = FN_ref and beyond
    it at FN = 0.8 FN_ref (the end of the ramp, a breakpoint), on the load-path check."""
    hist = {"kind": "ramp", "start": 1.0, "end": 0.8, "over": 0.5}
    with pytest.raises(InputError, match=r"load.tangential: .* at τ = 0.5 a \(FN the current normal load 0.8·"):
        scene3(BELOW, **{"load.tangential": 0.6, "load.normal_history": hist})
    scene3(BELOW, **{"load.tangential": 0.5, "load.normal_history": hist})       # 0.625 < 2/3 at the end


@pytest.mark.parametrize("n", [12, 20, 40])
@pytest.mark.parametrize("law", [
    BELOW, ABOVE, {**ABOVE, "start": -0.37, "end": 0.21, "y_start": -0.4},
    {"law": "table", "x": [-1.0, 1.0], "y": [-1.0, 1.0], "values": [[0.1, 0.5], [0.4, 0.2]]}],
    ids=["below", "above", "box", "table"])
def test_3d_the_limit_is_never_below_the_discrete_capacity(law, n):
    """The check's limit is at least the capacity of the discrete pressure (no load with a solution refused), and
    the Hertz estimate is within the margin of it (measured: 3e-3 on 12 × 12)."""
    sc = scene3(law, **{"discretization.elements": [n, n]})
    c, limit = (float(v[0]) for v in sliding_limits(sc, np.zeros(1), 1.0, np.ones(1)))
    exact = discrete_capacity_3d(sc)
    assert limit >= exact, (c, limit, exact)
    assert abs(c - exact) <= limit - c + 1e-15


# =========================================================================== 2D
def test_2d_patch_above_the_reference_carries_more_and_solves():
    sc = scene2({"inside": 0.2}, **{"load.tangential": 1.3})
    c, limit = checks.sliding_limits(sc, np.zeros(1), 1.0, np.ones(1))
    assert 1.3 < c[0] < 1.55 and discrete_capacity_2d(sc) > 1.3
    Q = run(sc, "newton").arrays()["Q"]
    assert np.allclose(Q, 1.3 * sc.contact.mu * sc.load.normal, rtol=1e-9, atol=0)
    with pytest.raises(InputError) as err:
        scene2({"inside": 0.2}, **{"load.tangential": 1.6})
    assert err.value.key == "load.tangential" and "∫ mu p dx = 1.50664 mu P" in str(err.value), str(err.value)


def test_2d_patch_below_the_reference_refuses_before_any_solve():
    sc = scene2({"inside": 0.05})
    assert discrete_capacity_2d(sc) < 0.8
    with pytest.raises(InputError) as err:
        scene2({"inside": 0.05}, **{"load.tangential": 0.8})
    assert err.value.key == "load.tangential" and "\n" not in str(err.value)
    assert "must be < 0.76" in str(err.value), str(err.value)
    # with a normal history: 0.6 of μ P̄ is beyond 0.75 P at P = 0.7 P̄ (the ramp's end)
    with pytest.raises(InputError, match=r"at q = 0.5 a_H must be <"):
        scene2({"inside": 0.05}, **{"load.tangential": 0.6,
                                    "load.normal_history": {"kind": "ramp", "start": 1.0, "end": 0.7, "over": 0.5}})


@pytest.mark.parametrize("element, elements, n", [("quadratic", 40, 1.0), ("linear", 10, 1.0), ("constant", 20, 0.3),
                                                 ("quadratic", 12, 0.3)])
@pytest.mark.parametrize("law", [{"inside": 0.05}, {"inside": 0.3, "start": -0.41, "end": 0.13},
                                 {"law": "table", "x": [-1.0, 0.0, 1.0], "values": [0.02, 0.2, 0.1]}],
                         ids=["below", "above", "table"])
def test_2d_the_limit_is_never_below_the_discrete_capacity(law, element, elements, n):
    friction = ({"law": "patch", "mu": 0.1, "start": 0.0, "end": 5.0, **law} if law.get("law") != "table" else law)
    sc = rollqp.load_scene("cattaneo-carter", {"discretization.element": element, "discretization.elements": elements,
                                               "contact.friction": friction, "load.tangential": 0.0})
    c, limit = (float(v[0]) for v in checks.sliding_limits(sc, np.zeros(1), n, np.ones(1)))
    exact = discrete_capacity_2d(sc, n)
    assert limit >= exact, (c, limit, exact)


# =========================================================================== uniform: unchanged
def test_uniform_friction_keeps_the_plain_check_and_its_messages():
    for law in (0.3, {"law": "exponential", "static": 0.3, "kinetic": 0.2, "velocity": 1.0, "rolling_speed": 10.0}):
        sc = scene3(law)
        assert sliding_limits(sc, np.zeros(1), 1.0, np.ones(1)) is None       # static = reference: μ FN itself
    with pytest.raises(InputError) as err:
        scene3(0.3, **{"load.tangential": 0.8, "load.lateral": 0.7})
    assert str(err.value) == ("load.tangential: |(Fx, Fy)|/(mu FN) = 1.06301 at q = 0 a must be < 1: a stick "
                              "solution exists only below the sliding limit (prescribe creepages for gross sliding)")
    with pytest.raises(InputError) as err:
        scene3(0.3, **{"load.tangential": 0.9, "load.normal_history": {"kind": "ramp", "start": 1.0, "end": 0.8,
                                                                        "over": 0.5}})
    assert str(err.value) == ("load.tangential: |(Fx, Fy)|/(mu FN) = 1.125 at τ = 0.5 a (FN the current normal load "
                              "0.8·load.normal) must be < 1: a stick solution exists only below the sliding limit "
                              "(prescribe creepages for gross sliding)")
    with pytest.raises(InputError) as err:
        rollqp.load_scene("cattaneo-carter", {"load.tangential": 1.1})
    assert str(err.value) == ("load.tangential: |Q|/(mu P) must stay below 1 for a stick solution (gross sliding is "
                              "not supported), but it reaches 1.1 at q = 0 a_H")


# =========================================================================== the command line
@pytest.mark.parametrize("dimension", [3, 2])
def test_the_command_line_refuses_in_one_line(dimension, tmp_path, capsys, monkeypatch):
    """``rollqp run`` on a scene file whose force is beyond a patch's limit (below the reference one): exit 2,
    one line naming the key, no traceback, no result."""
    import tomli_w
    monkeypatch.chdir(tmp_path)
    d = (scene3(BELOW) if dimension == 3 else scene2({"inside": 0.05})).to_dict()
    d["load"]["tangential"] = 0.8
    f = tmp_path / "bad.toml"
    f.write_bytes(tomli_w.dumps(_toml_safe(d)).encode())
    code = cli.main(["run", str(f), "--quiet", "--out", str(tmp_path / "r.npz")])
    err = capsys.readouterr().err
    assert code == 2, (code, err)
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert err.startswith("rollqp: error: load.tangential: ") and "∫ mu p d" in err, err
    assert not (tmp_path / "r.npz").exists()


def _toml_safe(v):
    if isinstance(v, dict):
        return {k: _toml_safe(x) for k, x in v.items() if x is not None}
    if isinstance(v, (list, tuple)):
        return [_toml_safe(x) for x in v]
    return v


def test_3d_dissimilar_bodies_the_limit_covers_the_coupled_pressure():
    """Kalker's K = 0.48 moves the pressure under the tangential tractions (the capacity by up to 0.11·|K|·|F| μ
    spread, measured): the check's limit stays above the capacity of every step's own pressure."""
    law = {**ABOVE, "start": 0.8}
    sc = scene3(law, **{"bodies.B.E": 1e7, "bodies.B.nu": 0.49, "bodies.A.nu": 0.0, "discretization.elements": [16, 16],
                        "discretization.distance": 0.1, "load.tangential": 1.0})
    assert sc.materials.K > 0.45
    c, limit = (float(v[0]) for v in sliding_limits(sc, np.zeros(1), 1.0, np.ones(1)))
    X, Y = sc.grid.centres()
    mu = sc.contact.friction.coefficient(np.stack([X, Y]) / sc.ellipse.a, 0.0, -1)
    caps = [float(mu @ np.ravel(rec.p)) * sc.grid.area / (sc.mu * sc.load.normal)
            for rec in rollqp.march(sc, method="qp-clarabel")]
    assert len(caps) >= 2 and min(caps) < discrete_capacity_3d(sc) - 0.01        # the coupling moved it
    assert limit >= max(caps), (c, limit, caps)


# =========================================================================== without Hertz's pressure
def test_3d_profile_uses_the_computed_contact_and_else_the_largest_mu():
    """A body profile: at load.normal the computed contact's own pressure (the frictionless normal step the scene
    checks the grid with: its capacity exactly, no mesh margin), at another load only the largest μ bounds it."""
    law = {"law": "patch", "mu": 0.3, "inside": 0.6, "start": 0.0, "end": 50.0, "y_start": 0.0}
    sc = rollqp.load_scene("quartic-roller", {"contact.friction": law})
    assert not sc.shape.hertzian
    c, limit = sliding_limits(sc, np.zeros(2), np.array([1.0, 0.5]), np.ones(2))
    X, Y = sc.grid.centres()
    mu = sc.contact.friction.coefficient(np.stack([X, Y]) / sc.ellipse.a, 0.0, -1)
    exact = float(mu @ sc.patch.p.ravel()) / (sc.mu * float(np.sum(sc.patch.p)))
    assert 1.0 < c[0] == pytest.approx(exact, rel=1e-12) and limit[0] == c[0]
    assert c[1] == limit[1] == 2.0
    with pytest.raises(InputError, match=r"load.tangential: .* must be < 2: "):
        rollqp.load_scene("quartic-roller", {"contact.friction": law, "load.creepage": {"spin": 0.0},
                                             "load.start": "braked", "load.tangential": 0.5,
                                             "discretization.distance": 1.0,
                                             "load.normal_history": {"kind": "ramp", "start": 1.0, "end": 0.2,
                                                                     "over": 1.0}})


def test_2d_profile_bounds_by_the_largest_mu():
    sc = rollqp.load_scene("dent", {"contact.friction": {"law": "patch", "mu": 0.1, "inside": 0.05, "start": 0.0,
                                                         "end": 5.0}})
    c, limit = checks.sliding_limits(sc, np.zeros(1), 1.0, np.ones(1))
    assert c[0] == limit[0] == 1.0                                            # the reference is the largest here
    with pytest.raises(InputError, match=r"load.tangential: \|Q\|/\(mu P\) = 1.05 .* must be < 1: "):
        rollqp.load_scene("dent", {"contact.friction": {"law": "patch", "mu": 0.1, "inside": 0.05, "start": 0.0,
                                                        "end": 5.0}, "load.tangential": 1.05})
