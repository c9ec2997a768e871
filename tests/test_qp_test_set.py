"""The qpbenchmark test set of rollqp's step QPs (``benchmarks/qp_test_set.py``, docs/qp-test-set.md).

A small version of the set (four QPs of 40–81 variables: a symmetric constant-element normal step,
the last and the first QP of the splitting of a rolling tangential step, the normal half of a coupled
step) is generated once per module, written to disk and read back through the generated
``rolling_contact.py`` exactly as qpbenchmark reads it. Then:

* every reference solution passes qpbenchmark's own checks — ``Problem.check_constraints``, a positive
  definite ``P``, and qpsolvers' ``Solution.is_optimal`` (primal and dual residuals and duality gap) at
  the test set's *high_accuracy* tolerance (1e-9);
* mapped back to rollqp's tractions and multipliers (the stored ``x_scale`` and ``y_scale``), each
  satisfies rollqp's own residuals to 1e-12 on the QP's step problem, and the last QP's on the
  collocation step itself (Newton reaches round-off, measured ≤ 1e-14 here);
* the exported QP is the one rollqp solves: the same arrays as the step file's QP with the skew part
  frozen (``rollqp.stepfile``), and rollqp's own qpsolvers backend on the step gives the certified solution;
* qpbenchmark runs on the set (quadprog, high accuracy) and writes its report;
* the checks can fail: a reference moved by 1e-6 at one node, or with the wrong multiplier sign, fails them.
"""
from __future__ import annotations

import ast
import functools
import sys
from pathlib import Path

import numpy as np
import pytest

import rollqp

try:
    import qpbenchmark
    import qpsolvers
except ImportError:  # the extra is not installed: every test skips, each by name (CI reruns them by name)
    qpbenchmark = qpsolvers = None

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import qp_test_set as qts  # noqa: E402  (imports qpbenchmark only where it runs it)

pytestmark = pytest.mark.skipif(qpbenchmark is None, reason="qpbenchmark is not installed "
                                                            "(pip install -e '.[qpbenchmark]', or '.[test,all]')")

#: rollqp's residual of a reference solution: Newton terminates finitely on these piecewise-linear
#: equations (measured ≤ 1e-14 on these steps); the test set's certificate.
CERTIFIED = 1e-12


@pytest.fixture(scope="module")
def small_set(tmp_path_factory):
    """``(folder, exported, test set)``: the small set written to disk and read back by its own TestSet."""
    out = tmp_path_factory.mktemp("qp-test-set")
    selected = qts.cases(small=True)
    exported = qts.generate(selected)
    scenes = {c.name: "{}" for c in selected}
    qts.write_set(out, exported, scenes)
    return out, exported, qts.load_test_set(out)


def _problems(test_set):
    return {p.name: p for p in test_set}


def test_the_set_holds_every_case_and_qpbenchmark_reads_it(small_set):
    out, exported, test_set = small_set
    names = sorted(e.case.name for e in exported)
    assert sorted(_problems(test_set)) == names
    assert test_set.count_problems() == len(names) == 4
    assert set(test_set.tolerances) == set(test_set.solver_settings) >= {"high_accuracy", "default"}
    assert (out / "problems.md").read_text(encoding="utf-8").count("\n| `") == len(names)


def test_references_pass_qpbenchmarks_own_checks(small_set):
    _, _, test_set = small_set
    tol = test_set.tolerances["high_accuracy"]
    for name, problem in _problems(test_set).items():
        problem.check_constraints()
        assert np.array_equal(problem.P, problem.P.T), name
        assert np.linalg.eigvalsh(problem.P)[0] > 0, name
        ref = test_set.reference(problem)
        assert ref.is_optimal(min(tol.primal, tol.dual, tol.gap)), (name, ref.primal_residual(), ref.dual_residual(),
                                                                     ref.duality_gap())


@functools.lru_cache(maxsize=None)
def _record(name):
    """``(scene, record)`` of the small set's case ``name``: its scene marched with Newton at 1e-12 (once)."""
    case = next(c for c in qts.cases(small=True) if c.name == name)
    scene = case.scene().replace(**{"solver.tolerance": 1e-12})
    return scene, qts.march_states(scene, [case.k])[case.k]


def _step_problems(case):
    """``(half, qp problem)`` of a case, rebuilt from its scene: the collocation half-step and the
    (shifted, symmetrized) step whose KKT system the exported QP is."""
    rec = _record(case.name)[1]
    half, sol, prev = qts.halves(rec)[case.half]
    frozen = qts.traction(half, sol) if case.stage == "step" else prev
    return half, qts.qp_problem(half, frozen)[0]


def _unscaled(problem, stored):
    """rollqp's solution of ``problem`` from the stored ``x``, ``y``: traction ``x·x_scale``, ``δ`` or ``ξ`` ``= y₀·y_scale``."""
    with np.load(stored, allow_pickle=False) as z:
        x, y, xs, ys, load_row = z["x"], z["y"], float(z["x_scale"]), float(z["y_scale"]), bool(z["load_row"])
    if not load_row:  # δ or ξ prescribed: the step's own
        mult = problem.delta if problem.kind == "normal" else problem.xi
    else:
        mult = float(y[0]) * ys
    return problem.solution(x * xs, mult)


def test_references_satisfy_rollqps_residuals(small_set):
    out, exported, _ = small_set
    for e in exported:
        half, target = _step_problems(e.case)
        sol = _unscaled(target, out / "solutions" / f"{e.case.name}.npz")
        assert sol.residual <= CERTIFIED, (e.case.name, sol.residuals)
        if e.case.stage == "step":  # the last QP's solution is the collocation step's
            assert half.evaluate(sol).residual <= CERTIFIED, (e.case.name, half.evaluate(sol).residuals)


def test_the_exported_qp_is_the_one_rollqp_solves(small_set):
    """The step file's QP with the skew part frozen at the solution (``rollqp.stepfile``, its own route
    through ``CoupledStep`` and the scaled ``F A``) has the same arrays; rollqp's qpsolvers backend on the
    collocation step (the whole splitting) lands on the certified solution."""
    from rollqp.march import prepare
    from rollqp.stepfile import from_record
    out, exported, test_set = small_set
    problems = _problems(test_set)
    for e in (e for e in exported if e.case.stage == "step"):
        scene, rec = _record(e.case.name)
        _, _, ops = prepare(scene, "newton")
        form = from_record(scene, ops, "newton", rec).qp_forms()[e.case.half]
        pb = problems[e.case.name]
        scale = np.abs(pb.P).max()
        # the same numbers by two routes: round-off of an n-term product, ≤ 1e-10 of the largest entry
        # (the step file's own check_forms tolerance)
        assert np.abs(pb.P - form["P"]).max() <= 1e-10 * scale, e.case.name
        assert np.abs(pb.q - form["q_frozen"]).max() <= 1e-10 * max(1.0, np.abs(pb.q).max()), e.case.name
        lb, ub = np.full(pb.q.size, -np.inf), np.full(pb.q.size, np.inf)
        arr = e.arrays
        ub[arr["up"]], lb[arr["lo"]] = pb.h[:arr["up"].size], -pb.h[arr["up"].size:]
        lb[arr["fixed"]] = ub[arr["fixed"]] = pb.b[int(arr["load_row"]):]
        assert np.allclose(lb, form["lb"], rtol=1e-12, atol=1e-14) and np.allclose(ub, form["ub"], rtol=1e-12,
                                                                                     atol=1e-14), e.case.name
        assert np.allclose(pb.A[:1], form["A"], rtol=1e-12, atol=0) and np.allclose(pb.b[:1], form["b"]), e.case.name
        half = qts.halves(rec)[e.case.half][0]
        got = rollqp.solve_step(half, "qps-quadprog", tolerance=1e-12)
        # quadprog solves the final active set's KKT system directly and the splitting stops at a change
        # of 1e-12 p0: the answer is the certified one to ~1e-12 (measured ≤ 2e-14); bound 1e-10
        assert np.abs(qts.traction(half, got) / half.scales.stress - e.x).max() <= 1e-10, e.case.name


def test_qpbenchmark_runs_the_set_and_writes_its_report(small_set):
    out, exported, test_set = small_set
    if "quadprog" not in test_set.solvers:
        pytest.skip("quadprog is not installed (pip install -e '.[qpbenchmark]')")
    _, df, distances = qts.run_benchmark(out, settings="high_accuracy", solver="quadprog", log=lambda m: None)
    ok = qts.passed(df, test_set)
    assert len(ok) == len(exported) and all(ok.values()), ok
    # a dual active-set method ends on the exact active set: round-off of its KKT solve (measured ≤ 1e-13)
    assert max(distances.values()) <= 1e-10, distances
    report = (out / "results" / f"{qts.SET_NAME}.md").read_text(encoding="utf-8")
    assert f"| Number of problems | {len(exported)} |" in report and "quadprog" in report
    summary = "\n".join(qts.certified_report(test_set, df, distances))
    assert f"| quadprog | {len(exported)} · {len(exported)} |" in summary


def test_the_checks_fail_on_a_wrong_solution(small_set):
    """A reference moved by 1e-6 at one free node, or a load multiplier with the wrong sign, fails
    qpbenchmark's check at high accuracy and rollqp's residual: the checks above can fail."""
    out, exported, test_set = small_set
    e = next(e for e in exported if e.case.name == "cc-qce40-k48-tangential")
    problem = _problems(test_set)[e.case.name]
    act = qts.active_set(e.arrays, e.x, e.y_load)
    i = int(np.flatnonzero(act["free"])[0])
    moved = e.x.copy()
    moved[i] += 1e-6
    y, z = qts.duals(e.arrays, moved, e.y_load)
    bad = qpsolvers.Solution(problem, found=True, x=moved, y=y, z=z)
    assert not bad.is_optimal(1e-9)
    flipped = qts.duals(e.arrays, e.x, -e.y_load)
    assert not qpsolvers.Solution(problem, found=True, x=e.x, y=flipped[0], z=flipped[1]).is_optimal(1e-9)
    assert qts.projection_residual(e.arrays, moved, e.y_load) > 1e-9
    _, target = _step_problems(e.case)
    assert target.solution(moved * e.meta["x_scale"], e.y_load * e.meta["y_scale"]).residual > CERTIFIED


def test_the_generated_test_set_needs_no_rollqp(small_set):
    out, _, _ = small_set
    tree = ast.parse((out / f"{qts.SET_NAME}.py").read_text(encoding="utf-8"))
    imported = {a.name.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
    imported |= {n.module.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
    assert imported <= {"os", "typing", "numpy", "qpbenchmark", "qpsolvers"}, imported


def test_catalogue_names_are_unique_and_say_what_they_are():
    full = qts.cases()
    names = [c.name for c in full]
    assert len(set(names)) == len(names)
    for c in full:
        assert c.half in c.name and c.half in ("normal", "tangential") and c.stage in ("step", "split1")
        assert c.name.endswith("-split1") == (c.stage == "split1") and c.what and c.group


def test_command_line(tmp_path, capsys):
    assert qts.main(["--small", "--only", "const40", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "data" / "cc-const40-s0-normal.npz").exists()
    assert "`cc-const40-s0-normal`" in capsys.readouterr().out
    with pytest.raises(SystemExit) as err:
        qts.main(["--small", "--only", "nothing-like-this", "--out", str(tmp_path)])
    assert err.value.code == 2
    assert "--only 'nothing-like-this' matches no problem name" in capsys.readouterr().err
