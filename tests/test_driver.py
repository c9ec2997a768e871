"""The transient (rollqp.march; paper §4.1, §4.4; docs/formulation.md §9) on the built-in scenes.

Tier 1 (closed forms, discretization error of the paper's 40 QCE, Δq = Le/2): Cattaneo at
the braked start, Carter after rolling, from a braked start, a ramp or a rolling start.
Tier 2 (exact discrete symmetries, solver tolerance): mirror x → −x with the rolling
direction, Q → −Q. And the driver's contract: the normal QP solved once when nothing can
change it, a failing step reported with its number and the completed states, result arrays
as SPEC.md, atomic result files.

The driver tests run ``qp-osqp`` (the fastest backend on these problems, ~3 ms per step);
backend agreement is test_qp's business.
"""
from __future__ import annotations

import importlib

import json
import os

import numpy as np
import pytest

import rollqp
from rollqp import SolverError, closedforms as cf, load_result
from rollqp.operators import SceneOperators
from conftest import Delegate
from rollqp.result import Result

METHOD = "qp-osqp"


def rms_in_contact(res, err, a):
    """rms of ``err`` over the nodes with |x| <= a."""
    m = np.abs(res["x"]) <= a
    return float(np.sqrt(np.mean(err[m] ** 2)))


@pytest.fixture(scope="module")
def short(builtin_scene):
    """cattaneo-carter rolled 1 a_H (33 rolling steps), memoized by changes."""
    cache = {}

    def run(**changes):
        key = tuple(sorted((k, json.dumps(v, sort_keys=True)) for k, v in changes.items()))
        if key not in cache:
            scene = builtin_scene("cattaneo-carter", **{"discretization.distance": 1.0, **changes})
            cache[key] = (scene, rollqp.run(scene, method=METHOD).arrays())
        return cache[key]
    return run


@pytest.fixture(scope="module")
def full_runs():
    """cattaneo-carter and ramp over the paper's 6 a_H (192 rolling steps each)."""
    return {name: rollqp.run(name, method=METHOD).arrays() for name in ("cattaneo-carter", "ramp")}


# ------------------------------------------------------------------------------- closed forms
@pytest.mark.parametrize("method", ["qp-clarabel", "qp-osqp", "qp-cvxpy"],
                         ids=["clarabel", "osqp", "cvxpy"])
def test_braked_start_is_hertz_then_cattaneo(builtin_scene, method):
    scene = builtin_scene("cattaneo-carter", **{"discretization.distance": 0.0})
    res = rollqp.run(scene, method=method).arrays()
    assert res["q"].tolist() == [0.0], "distance 0: the starting state only"
    a, p0, mu = scene.a_H, scene.p0, scene.contact.friction
    x = res["x"]
    # discretization error of 40 QCE on ±1.25 a_H: measured 0.36 % (Hertz), 0.51 % (Cattaneo)
    e_h = rms_in_contact(res, res["pn"][0] - cf.hertz_pressure(x, a, p0), a) / p0
    assert e_h <= 0.01, f"{method}: rms(p − Hertz) = {e_h:.4f} p0"
    e_c = rms_in_contact(res, res["pt"][0] - cf.cattaneo_traction(x, a, p0, mu, 0.75), a) / (mu * p0)
    assert e_c <= 0.01, f"{method}: rms(t − Cattaneo) = {e_c:.4f} μp0"
    assert res["Q"][0] == pytest.approx(0.75 * mu * scene.load.normal, rel=1e-8), \
        "the braked start carries Q = 0.75 μP (load equation, solver tolerance)"


def test_cattaneo_carter_ends_in_carter(full_runs, builtin_scene):
    scene = builtin_scene("cattaneo-carter")
    res = full_runs["cattaneo-carter"]
    a, p0, mu = scene.a_H, scene.p0, scene.contact.friction
    e = rms_in_contact(res, res["pt"][-1] - cf.carter_traction(res["x"], a, p0, mu, 0.75, -1), a) / (mu * p0)
    # discretization error (measured 0.64 %); Carter's transient has died out by 6 a_H
    assert e <= 0.015, f"rms(t − Carter) = {e:.4f} μp0 at q = 6 a_H"
    xi = cf.carter_creepage(a, scene.R, mu, 0.75)
    assert res["creepage"][-1] == pytest.approx(xi, rel=0.015), "creepage → Carter's (measured 0.6 % off)"


def test_ramp_ends_in_the_same_carter_state(full_runs, builtin_scene):
    scene = builtin_scene("ramp")
    cc, rp = full_runs["cattaneo-carter"], full_runs["ramp"]
    a, p0, mu = scene.a_H, scene.p0, scene.contact.friction
    assert np.max(np.abs(rp["pt"][0])) == 0.0, "the ramp starts stopped at Q = 0"
    # load equations solved to the residual limit 1e-8 (in a_H p0, i.e. ~1e-8 relative to μP)
    assert rp["Q"][-1] == pytest.approx(cc["Q"][-1], rel=1e-8), "both end at Q = 0.75 μP"
    d = rms_in_contact(rp, rp["pt"][-1] - cc["pt"][-1], a) / (mu * p0)
    # the history is forgotten within ~3 a_H (measured 2e-5 after 3.3 a_H at the final load)
    assert d <= 0.015, f"rms(t_ramp − t_cattaneo-carter) = {d:.2e} μp0 at 6 a_H"
    e = rms_in_contact(rp, rp["pt"][-1] - cf.carter_traction(rp["x"], a, p0, mu, 0.75, -1), a) / (mu * p0)
    assert e <= 0.015, f"the ramp ends in Carter's state: rms = {e:.4f} μp0"


def test_rolling_start_is_carter(builtin_scene):
    scene = builtin_scene("cattaneo-carter", **{"load.start": "rolling", "discretization.distance": 0.5})
    res = rollqp.run(scene, method=METHOD).arrays()
    a, p0, mu = scene.a_H, scene.p0, scene.contact.friction
    assert res["q"][0] == 0.0 and len(res["q"]) == scene.n_steps + 1, "state 0 is the steady state at q = 0"
    e = rms_in_contact(res, res["pt"][0] - cf.carter_traction(res["x"], a, p0, mu, 0.75, -1), a) / (mu * p0)
    assert e <= 0.015, f"rms(t − Carter) = {e:.4f} μp0 at q = 0 (discretization error, measured 0.64 %)"
    assert res["creepage"][0] == pytest.approx(cf.carter_creepage(a, scene.R, mu, 0.75), rel=0.015), \
        "Carter's creepage at q = 0"
    # steady: rolling on changes nothing. The start stops when a step changes t by < 1e-10 μp0;
    # the remaining distance to the fixed point is that over (1 − contraction): measured 9e-8.
    drift = np.max(np.abs(res["pt"] - res["pt"][0])) / (mu * p0)
    assert drift <= 1e-6, f"the rolling start is steady: t drifts by {drift:.1e} μp0"


# ------------------------------------------------------------------------------- symmetries
def test_direction_mirrors_the_solution(short):
    scene, minus = short()
    _, plus = short(**{"load.direction": 1})
    mu, p0, slip = scene.contact.friction, scene.p0, scene.p0 / scene.Estar
    # linspace(−L, L): symmetric to the last bit or two of L = 1.3 a_H
    assert np.allclose(minus["x"], -minus["x"][::-1], rtol=0, atol=1e-15 * scene.a_H), "symmetric nodes"
    # the two discrete problems are exact mirrors; each is solved to rollqp's residual 1e-8
    # (measured difference 5e-13)
    assert np.max(np.abs(plus["pn"] - minus["pn"][:, ::-1])) <= 1e-8 * p0, "p(x) ↔ p(−x)"
    assert np.max(np.abs(plus["pt"] - minus["pt"][:, ::-1])) <= 1e-8 * mu * p0, "t(x) ↔ t(−x)"
    # slip = (c + A t)/Δq: a traction difference of 1e-8 μp0 over Δq = Le/2 gives ~1e-8·μ·(a/Δq) p0/E*
    assert np.max(np.abs(plus["slip"] - minus["slip"][:, ::-1])) <= 1e-7 * slip, "s(x) ↔ s(−x)"
    assert np.max(np.abs(plus["creepage"] - minus["creepage"])) <= 1e-8 * slip, "the same creepage"
    assert int(plus["leading_edge"]) == -int(minus["leading_edge"]) == -1, "material enters at x = −d·L"
    # Carter's stick zone sits at the leading edge: x > 0 for d = −1, x < 0 for d = +1
    x_stick = lambda r: float(np.mean(r["x"][r["state"][-1] == 1]))   # noqa: E731
    assert x_stick(minus) > 0 > x_stick(plus), "stick zone at the leading edge"


def test_reversed_load_flips_traction_and_creepage(short):
    scene, pos = short()
    _, neg = short(**{"load.tangential": {"kind": "constant", "value": -0.75}})
    mu, p0, slip = scene.contact.friction, scene.p0, scene.p0 / scene.Estar
    # Q → −Q is an exact antisymmetry of the discrete problem; solver tolerance 1e-8
    assert np.max(np.abs(neg["pt"] + pos["pt"])) <= 1e-8 * mu * p0, "t → −t"
    assert np.max(np.abs(neg["creepage"] + pos["creepage"])) <= 1e-8 * slip, "ξ → −ξ"
    assert np.max(np.abs(neg["pn"] - pos["pn"])) == 0.0, "the pressure does not see Q (β = 0)"
    assert np.array_equal(neg["state"], pos["state"]), "the same stick/slip zones"
    assert np.all(pos["creepage"][1:] * pos["Q"][1:] < 0), "creepage opposes the load (Carter)"


# ------------------------------------------------------------------------------- solves
class Counting(Delegate):
    """A method that counts its normal and tangential solves, and can fail at one of them."""

    def __init__(self, inner, fail_at_tangential=None):
        super().__init__(inner)
        self.fail_at = fail_at_tangential
        self.counts = {"normal": 0, "tangential": 0}

    def solve(self, problem, warm=None):
        self.counts[problem.kind] += 1
        if problem.kind == "tangential" and self.counts["tangential"] == self.fail_at:
            raise SolverError("injected failure", method=self.inner.name, status="test", residual=1.0)
        return self.inner.solve(problem, warm=warm)


@pytest.fixture
def counting(monkeypatch):
    """Make scenes run with a :class:`Counting` method; returns the created instances."""
    import rollqp.methods
    made = []

    def install(fail_at_tangential=None):
        real = rollqp.methods.scene_method

        def make(settings, coupled=False, **kw):
            m = Counting(real(settings, coupled, **kw), fail_at_tangential)
            made.append(m)
            return m
        monkeypatch.setattr(importlib.import_module("rollqp.march.strip"), "scene_method", make)  # where the march makes it
        return made
    return install


def test_constant_normal_load_solved_once(builtin_scene, counting):
    made = counting()
    scene = builtin_scene("cattaneo-carter", **{"discretization.distance": 0.5})
    res = rollqp.run(scene, method=METHOD)
    (m,) = made
    K = scene.n_steps
    assert m.counts == {"normal": 1, "tangential": K + 1}, \
        f"β = 0, constant P: one normal solve, one tangential per state ({m.counts}, K = {K})"
    assert len(res) == K + 1, "every state recorded"


def test_varying_normal_load_solved_every_step(builtin_scene, counting):
    made = counting()
    scene = builtin_scene("cattaneo-carter", **{
        "discretization.distance": 0.5,
        "load.normal_history": {"kind": "harmonic", "mean": 1.0, "amplitude": 0.05, "wavelength": 2.0}})
    res = rollqp.run(scene, method=METHOD).arrays()
    (m,) = made
    K = scene.n_steps
    assert m.counts["normal"] == K + 1, f"P changes: a normal solve per state ({m.counts}, K = {K})"
    expected = scene.normal_load(res["q"])
    # recorded from the same history evaluation: round-off only
    assert np.allclose(res["P"], expected, rtol=1e-12), "P(q) recorded as prescribed"
    f = SceneOperators.build(scene).f
    assert np.allclose(res["pn"] @ f, res["P"], rtol=1e-8), "fᵀp = P(q) at every state (solver tolerance)"


def test_failing_step_reports_step_and_partial(builtin_scene, counting):
    # braked start: tangential solve 1 is step 0; solve k + 1 is rolling step k
    counting(fail_at_tangential=6)
    scene = builtin_scene("cattaneo-carter", **{"discretization.distance": 1.0})
    with pytest.raises(SolverError) as info:
        rollqp.run(scene, method=METHOD)
    err = info.value
    assert err.step == 5, f"the failing step is 5: {err.step}"
    assert err.method == METHOD and err.status == "test", f"method and status kept: {err}"
    assert "step 5" in str(err), f"the message names the step: {err}"
    partial = err.partial
    assert isinstance(partial, Result) and len(partial) == 5, f"states 0..4 completed: {len(partial)}"
    arr = partial.arrays()
    # q_k = k Δq computed the same way: round-off only
    assert np.allclose(arr["q"], np.arange(5) * scene.dq, rtol=1e-14), f"q of states 0..4: {arr['q']}"
    assert arr["pt"].shape == (5, arr["x"].size), "partial arrays have the partial length"
    assert isinstance(err.__cause__, SolverError), "the original error is chained"


# ------------------------------------------------------------------------------- result
SPEC_STATE = ("pn", "pt", "slip", "gap", "state")
SPEC_STEP = ("q", "P", "Q", "creepage", "approach", "iterations", "step_time", "residual")
SPEC_SCALAR = ("a_H", "p0", "R", "Estar", "beta", "leading_edge", "meta")


def test_result_arrays_follow_spec(short):
    scene, res = short()
    n, K = res["x"].shape[0], scene.n_steps
    assert res["x"].shape == (n,) and res["x"].dtype == np.float64, f"x: {res['x'].shape}"
    assert n == 2 * scene.discretization.elements + 1, "quadratic elements: 2·elements + 1 nodes"
    for k in SPEC_STATE:
        assert res[k].shape == (K + 1, n), f"{k}: shape {res[k].shape}, expected {(K + 1, n)}"
        assert res[k].dtype == (np.int8 if k == "state" else np.float64), f"{k}: dtype {res[k].dtype}"
    for k in SPEC_STEP:
        assert res[k].shape == (K + 1,), f"{k}: shape {res[k].shape}, expected {(K + 1,)}"
        assert np.issubdtype(res[k].dtype, np.integer if k == "iterations" else np.floating), f"{k}: {res[k].dtype}"
    for k in SPEC_SCALAR:
        assert res[k].shape == (), f"{k} is a scalar: {res[k].shape}"
    assert set(np.unique(res["state"])) <= {0, 1, 2}, "states are 0, 1, 2"
    assert np.allclose(res["q"], np.arange(K + 1) * scene.dq, rtol=1e-14), "q_k = k Δq (round-off only)"
    # OSQP returns separated nodes at ~−1e-19 (the normal QP's x is not clipped to x >= 0, unlike
    # the tangential one): nonnegative to the solver's tolerance
    assert np.all(res["pn"] >= -1e-12 * scene.p0), f"pressure ≥ 0: min {res['pn'].min():.1e}"
    assert np.all(res["iterations"] > 0) and np.all(res["step_time"] > 0), "every step did work"
    # QPMethod's residual_limit = 100 × tolerance 1e-10
    assert res["residual"].max() <= 1e-8, f"residuals within the solver's limit: {res['residual'].max():.1e}"
    assert float(res["a_H"]) == scene.a_H and float(res["p0"]) == scene.p0, "Hertz scales of P̄"
    assert int(res["leading_edge"]) == 1, "d = −1: material enters at x = +L"
    meta = json.loads(str(res["meta"]))
    ran = scene.replace(**{"solver.method": METHOD})       # run(..., method=) overrides [solver].method
    assert meta["method"] == METHOD and meta["scene"] == ran.to_dict(), "meta: method and the full scene run"


def test_result_save_is_atomic_and_round_trips(builtin_scene, tmp_path):
    scene = builtin_scene("cattaneo-carter", **{"discretization.distance": 0.25})
    result = rollqp.run(scene, method=METHOD)
    path = tmp_path / "out.npz"
    assert result.save(path) == os.fspath(path), "save returns the path"
    assert sorted(os.listdir(tmp_path)) == ["out.npz"], f"no temporary files left: {os.listdir(tmp_path)}"
    back = load_result(path)
    arrays = result.arrays()
    assert set(back) == set(arrays), f"the same keys: {set(back) ^ set(arrays)}"
    for k, v in arrays.items():
        if k == "meta":
            continue
        assert back[k].dtype == v.dtype and np.array_equal(back[k], v), f"{k} round-trips bit for bit"
    assert back["meta"] == json.loads(json.dumps(result.meta)), "meta round-trips as JSON"
    with np.load(path, allow_pickle=False) as z:                 # no pickled objects
        assert "meta" in z.files and z["meta"].dtype.kind == "U", "meta is a JSON string"


def test_result_save_failure_keeps_old_file(short, tmp_path, monkeypatch):
    _, arrays = short()
    path = tmp_path / "out.npz"
    path.write_bytes(b"previous result")

    def broken(fh, array, **kw):  # the disk fills while an array is written
        fh.write(b"half an array")
        raise OSError("disk full")
    result = Result(x=arrays["x"], scalars={}, meta={})
    monkeypatch.setattr(np.lib.format, "write_array", broken)
    with pytest.raises(OSError):
        result.save(path)
    assert path.read_bytes() == b"previous result", "a failed save leaves the old file intact"
    assert sorted(os.listdir(tmp_path)) == ["out.npz"], f"and no temporary file: {os.listdir(tmp_path)}"


def test_result_save_rejects_bad_paths(tmp_path):
    result = Result(x=np.zeros(3), scalars={}, meta={})
    with pytest.raises(rollqp.InputError) as info:
        result.save(tmp_path / "out.txt")
    assert info.value.key == "--out", f"names --out: {info.value}"
    with pytest.raises(rollqp.InputError) as info:
        result.save(tmp_path / "missing" / "out.npz")
    assert info.value.key == "--out" and "does not exist" in str(info.value), f"missing folder: {info.value}"


def test_result_file_has_default_permissions(tmp_path):
    result = Result(x=np.zeros(3), scalars={}, meta={})
    path = tmp_path / "out.npz"
    result.save(path)
    plain = tmp_path / "plain.npz"
    with open(plain, "wb") as fh:
        np.savez(fh, x=np.zeros(3))
    assert oct(path.stat().st_mode & 0o777) == oct(plain.stat().st_mode & 0o777), \
        "a result file is created with the same permissions as any other file (umask)"


def test_scene_iteration_limit_reaches_qp_methods(builtin_scene):
    """``solver.max_iterations`` is the QP solver's own limit per QP (methods.base: from_settings):
    one interior-point iteration cannot solve the braked start's QPs, so the start fails, naming
    the step and the method; without the key Clarabel keeps its own limit and solves it."""
    scene = builtin_scene("cattaneo-carter", **{"discretization.distance": 0.0, "solver.max_iterations": 1,
                                                 "solver.method": "qp-clarabel"})
    with pytest.raises(SolverError) as info:
        rollqp.run(scene)
    assert info.value.step == 0 and info.value.method == "qp-clarabel", str(info.value)
    res = rollqp.run(scene.replace(**{"solver.max_iterations": None})).arrays()
    assert res["iterations"][0] > 1 and res["residual"][0] <= 1e-8
