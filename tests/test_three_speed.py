"""What a 3D run costs and what it says about it: the conic cost model, the refusal before any work, the
cross-check's time budget and its reuse of identical steps (rollqp.advice.grid, rollqp.crossval.grid).
No test times anything: the budget tests use a budget of zero or a deadline already past."""
from __future__ import annotations

import numpy as np
import pytest

from rollqp import cli, load_scene
from rollqp.errors import InputError
from rollqp.advice import grid as advice
from rollqp.crossval.grid import SpotObserver, cross_check, crossval
from rollqp.march.grid import run


def coarse(name, **changes):
    s = load_scene(name)
    nx, ny = s.discretization.elements
    k = 12 / min(nx, ny)
    base = {"discretization.elements": [round(nx * k), round(ny * k)], "discretization.zone": [1.3, 1.3]}
    return s.replace(**{**base, **changes})


def test_the_cost_model_grows_with_the_contact_and_follows_the_yardstick():
    y = 0.003
    t = [advice.conic_step_seconds(m, y) for m in (100, 300, 812, 5000)]
    assert all(b > a for a, b in zip(t, t[1:]))
    assert advice.conic_step_seconds(812, 2 * y) == pytest.approx(2 * t[2])
    # between the quadratic (assembly) and the cubic (factorizations) law
    assert (812 / 300) ** 2 < t[2] / t[1] < (812 / 300) ** 3
    assert advice.yardstick() > 0


def test_the_conic_estimate_counts_the_sweeps_of_dissimilar_bodies():
    """A conic run of dissimilar bodies alternates normal and tangential solves in every step: the estimate
    counts the sweeps the run takes (measured here on a small grid, by count, not time: the model's 4 %
    on the 76-element grid it was fitted on, 25 % allowed on another grid and start)."""
    from rollqp.march.grid import march
    scene = load_scene("cattaneo-3d", {"bodies.B.E": 70000.0, "bodies.B.nu": 0.33, "discretization.elements": [10, 10],
                                       "discretization.distance": 1.0, "solver.method": "socp-clarabel"})
    sweeps = [rec.info["sweeps"] for rec in march(scene)]
    measured = sum(sweeps) / len(sweeps)
    assert measured > 2                                    # the alternation is there to count
    assert advice.coupled_sweeps(scene.materials.K, scene.solver.tolerance) == pytest.approx(measured, rel=0.25)
    similar = scene.replace(**{"bodies.B.E": 210000.0, "bodies.B.nu": 0.25})
    ratio = advice.conic_run(scene)[2] / advice.conic_run(similar)[2]
    assert ratio == pytest.approx(advice.SWEEP_COST * advice.coupled_sweeps(scene.materials.K, 1e-10))
    assert advice.step_factor(0.0, 1e-10) == 1.0


def test_a_conic_run_whose_dense_matrix_does_not_fit_is_refused_before_any_work():
    scene = load_scene("kalker-circular", {"solver.method": "socp-clarabel", "discretization.elements": [200, 200]})
    with pytest.raises(InputError, match=r"^solver.method: .*--method newton.*coarser grid") as err:
        advice.refusal(scene, allow_long=True)          # memory: not even --allow-long
    assert "\n" not in str(err.value) and "Ann" not in str(err.value) and "use the FFT product" not in str(err.value)


def test_a_conic_run_estimated_above_an_hour_is_refused_unless_allowed(monkeypatch):
    scene = load_scene("kalker-circular", {"solver.method": "socp-clarabel"})
    monkeypatch.setattr(advice, "_YARDSTICK", [1.0])    # a machine where a 600-order Cholesky takes 1 s
    steps, per, total = advice.conic_run(scene)
    assert total > advice.REFUSE_SECONDS and steps > scene.n_steps  # the march to the steady state counted
    with pytest.raises(InputError, match=r"would take about .* h .*--method newton.*--allow-long"):
        advice.refusal(scene)
    advice.refusal(scene, allow_long=True)
    assert advice.notes(scene) and "about" in advice.notes(scene)[0]
    monkeypatch.setattr(advice, "_YARDSTICK", [1e-6])   # a fast machine: no note, no refusal
    advice.refusal(scene)
    assert advice.notes(scene) == []
    assert advice.notes(load_scene("kalker-circular")) == []   # Newton: nothing to say


def test_the_command_refuses_in_one_line(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "big.toml"
    path.write_text(load_scene("kalker-circular", {"discretization.elements": [200, 200]}).to_toml(), encoding="utf-8")
    code = cli.main(["run", str(path), "--method", "socp-clarabel", "--quiet"])
    err = capsys.readouterr().err
    assert code == cli.EXIT_INPUT and err.count("\n") == 1 and "--method newton" in err, err
    assert not (tmp_path / "big.npz").exists() and not list(tmp_path.glob("*.journal"))


@pytest.fixture(scope="module")
def kept():
    scene = coarse("kalker-circular", **{"discretization.distance": 1.0})
    obs = SpotObserver(range(scene.n_steps + 1))
    run(scene, observe=obs)
    return scene, obs


def test_a_budget_of_zero_solves_nothing_and_says_so(kept):
    scene, obs = kept
    check = cross_check(scene, obs, "newton", budget=0.0)
    assert check.rows == {} and sorted(check.skipped["socp-clarabel"]) == sorted(obs.kept)
    text = str(check)
    assert text.startswith("skipped: one socp-clarabel step takes about") and "--cross-check" in text


def test_identical_steps_are_solved_once_and_compared_each(kept):
    scene, obs = kept
    check = cross_check(scene, obs, "newton", methods=["socp-clarabel"])
    K = scene.n_steps
    assert check.agrees() and check.steps == list(range(K + 1))
    # the rolling steps from the second on start from the same state, bit for bit (steady state reproduced)
    arrays = [obs.kept[k][0] for k in range(1, K + 1)]
    assert all(np.array_equal(a.t, arrays[0].t) for a in arrays)
    same = {k for (_, k) in check.same}
    # step 1 (Δq = dx from the steady state 0) is the steady check of step 0; steps 3…K start from states
    # 2…K-1, which are state 1 bit for bit, as step 2 does
    assert scene.dq == pytest.approx(obs.contact.grid.dx) and same == {1, *range(3, K + 1)}, same
    for k in same:                                       # each compared with the run's own solution of it
        assert ("socp-clarabel", k) in check.per_step
    assert "solved once" in str(check)


def test_crossval_step_choice_still_checks(kept):
    scene, _ = kept
    check = crossval(scene, step=1, methods=["socp-clarabel"])
    assert check.agrees() and check.steps == [1]


# ------------------------------------------------------------------------------- extrapolation
def test_richardson_recovers_a_power_law_and_its_order():
    from rollqp.extrapolate import richardson
    for p in (0.7, 1.0, 2.0):
        e = richardson([3.0 + 0.4 * h ** p for h in (0.2, 0.1, 0.05)], 2.0)
        assert e.order == pytest.approx(p, rel=1e-9) and e.value == pytest.approx(3.0, rel=1e-12)
        assert e.error == pytest.approx(0.4 * 0.05 ** p, rel=1e-9)      # the finest grid's error
    e = richardson([1.0, 1.1, 1.05], 2.0)                                # not monotone: no order claimed
    assert e.order is None and e.value == 1.05 and e.error == pytest.approx(0.1)


def test_the_first_order_fit_recovers_the_limit_and_its_estimate_covers_scatter_and_order():
    from rollqp.extrapolate import fit_first_order
    h = np.array([0.1, 0.075, 0.05])
    e = fit_first_order(h, 3.0 + 0.4 * h, [1e-6] * 3)                   # exactly first order
    assert e.value == pytest.approx(3.0, rel=1e-12) and e.order == pytest.approx(1.0, rel=1e-6)
    assert e.error == pytest.approx(2 * np.sqrt(np.linalg.inv(np.array([[3, h.sum()], [h.sum(), (h * h).sum()]]))[0, 0])
                                    * 1e-6, rel=1e-6)                 # twice F0's standard error, no order term
    rng = np.random.default_rng(3)
    misses = 0
    for _ in range(200):       # scatter alone: the estimate (2 sigma) covers the true error about 95 % of the time
        e = fit_first_order(h, 3.0 + 0.4 * h + rng.normal(0, 1e-3, 3), [1e-3] * 3)
        misses += abs(e.value - 3.0) > e.error
    assert misses <= 20
    for p in (0.6, 1.6):       # the order strays from 1: the estimate covers the first-order fit's error
        F = 3.0 + 0.4 * h ** p
        e = fit_first_order(h, F, [1e-9] * 3)
        assert e.order == pytest.approx(p, rel=1e-4) and abs(e.value - 3.0) <= e.error
    e = fit_first_order(h, [3.04, 3.02, 3.03], [1e-4] * 3)                # not monotone: no order, whole correction
    assert e.order is None and e.error >= abs(e.value - 3.03)


def test_the_positions_are_spread_over_the_element_for_every_count():
    from rollqp.extrapolate import positions
    assert positions(5, first=3) == positions(8)[3:]                                       # a sequence: extensible
    assert (0.0, 0.0) not in positions(256)                       # not the centred grid: a special position
    for k in (4, 16, 64, 256):
        p = np.array(positions(k))
        assert np.all(np.abs(p) <= 0.5) and len({tuple(np.round(q, 12)) for q in p}) == k
        for axis in (0, 1):     # evenly spread: each quarter of the element holds k/4 positions, to within 2
            counts = np.histogram(p[:, axis], bins=4, range=(-0.5, 0.5))[0]
            assert np.all(np.abs(counts - k / 4) <= 2), (k, axis, counts)


def test_extrapolate_command(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert cli.main(["extrapolate", "kalker-circular", "--grids", "10,15,20", "--shifts", "3"]) == 0
    out = capsys.readouterr().out
    assert "grid 20" in out and "3 position(s)" in out and "error estimate" in out and "Fy   negligible" in out
    for bad in ("10", "a,b,c", "40,20,10", "10,10,20", "0,10"):
        assert cli.main(["extrapolate", "kalker-circular", "--grids", bad]) == cli.EXIT_INPUT
        assert "--grids" in capsys.readouterr().err
    for bad in ("1", "x", "513"):
        assert cli.main(["extrapolate", "kalker-circular", "--shifts", bad]) == cli.EXIT_INPUT
        assert "--shifts" in capsys.readouterr().err
    assert cli.main(["extrapolate", "kalker-circular", "--grids", "10,15,20", "--target", "5%", "--workers", "1"]) == 0
    assert "target 5 % of the creep forces" in capsys.readouterr().out
    for key, bad in (("--target", "0"), ("--target", "100"), ("--target", "%"), ("--target", "nan"), ("--target", "x"),
                     ("--budget", "0"), ("--budget", "-1"), ("--budget", "inf"), ("--workers", "0"),
                     ("--workers", "1.5"), ("--workers", "300")):
        assert cli.main(["extrapolate", "kalker-circular", key, bad]) == cli.EXIT_INPUT
        err = capsys.readouterr().err
        assert key in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err, (key, bad, err)
    assert cli.main(["extrapolate", "kalker-circular", "--grids", "40,80,2000"]) == cli.EXIT_INPUT   # too large:
    err = capsys.readouterr().err                                                  # refused before any solve
    assert "--grids: the grid of 2000 elements: discretization.elements" in err and len(err.splitlines()) == 1
    assert cli.main(["extrapolate", "cattaneo-3d"]) == cli.EXIT_INPUT        # a braked start: no steady state
    assert "rolling start" in capsys.readouterr().err
