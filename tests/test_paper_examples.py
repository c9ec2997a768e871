"""The paper's dissimilar examples (§6.2): built-in scenes, worked examples, figures.

* §6.2.1 ``goodman-bentall`` (examples/goodman_bentall.py): 2β = 1, μ = 0.3, pressed at Q = 0
  in 40 normal-load steps, then free rolling; coupling "goodman" (Fig. 6) and "full" (Fig. 7).
* §6.2.2 ``harmonic`` (examples/harmonic.py): 2β = 0.288, μ = 0.1, steady free rolling, then
  P = P̄(1 + 0.2 sin(2πq/λ)).

The examples run as a user runs them (``runpy`` as ``__main__``, as in test_examples.py) and
what they measure is held to physics: symmetry of the Goodman state, the friction bound, the
pressure peak convected out through the trailing edge, the free-rolling creepage against
Bentall & Johnson's μ → 0 value (sign and magnitude, and its approach as μ → 0), the contact
width following the load, the first load cycle transient and the later ones periodic, and the
agreement of the coupled Newton method with the N–T alternation. No closed form exists for
the coupled transients, so the bounds are physical limits or the paper's observations, with
the measured values beside them (rollqp 0.1.0, half-space model).
"""
from __future__ import annotations

import contextlib
import io
import runpy
from pathlib import Path

import numpy as np
import pytest

import rollqp
from rollqp import cli
from rollqp import closedforms as cf
from rollqp.histories import Harmonic

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def run_example(name, argv):
    """Run ``examples/<name>`` as ``__main__`` with ``argv``; return (globals, stdout)."""
    path = EXAMPLES / name
    out = io.StringIO()
    with pytest.MonkeyPatch.context() as mp, contextlib.redirect_stdout(out):
        mp.setattr("sys.argv", [str(path), *argv])
        ns = runpy.run_path(str(path), run_name="__main__")
    return ns, out.getvalue()


@pytest.fixture(scope="module")
def goodman_bentall():
    """examples/goodman_bentall.py with the scene's method (newton): both couplings, 6 a_H."""
    ns, out = run_example("goodman_bentall.py", [])
    return ns["results"], out


@pytest.fixture(scope="module")
def harmonic():
    """examples/harmonic.py as the scene has it: λ = 2 a_H, 6 a_H (three cycles), newton."""
    ns, out = run_example("harmonic.py", [])
    return ns["results"], out


# ------------------------------------------------------------------------------- scenes
def test_builtin_scenes_follow_the_paper():
    names = rollqp.builtin_scenes()
    assert "§6.2.1" in names["goodman-bentall"] and "§6.2.2" in names["harmonic"], "descriptions cite the paper"

    gb = rollqp.load_scene("goodman-bentall")
    # "Dundurs' constant = 1" is 2β (docs/formulation.md §3): β = 0.5, asked to at least 5 digits
    assert abs(gb.beta - 0.5) <= 5e-6 and abs(gb.kappa - 1.0) <= 1e-5, f"beta = {gb.beta!r}"
    assert gb.contact.friction == 0.3 and gb.contact.coupling == "full", "mu = 0.3, full coupling (Fig. 7)"
    assert gb.load.tangential == rollqp.histories.Constant(0.0), "free rolling, Q = 0"
    assert gb.load.start == "braked" and gb.load.start_steps == 40, "40 normal-load steps"
    d = gb.discretization
    assert (d.elements, d.element, d.step, d.formulation) == (40, "quadratic", 0.25, "material"), \
        "40 QCE, Δq = Le/4, material formulation"
    assert d.distance >= 3.6, "beyond the paper's 1.8 contact widths of transient"
    assert gb.solver.method == "newton"
    # a realistic small contact: the half-space model needs a_H << R (paper's rollers: 0.0105)
    assert 0.005 <= gb.a_H / gb.R <= 0.02, f"a_H/R = {gb.a_H / gb.R:.4f}"

    h = rollqp.load_scene("harmonic")
    assert abs(h.beta - 0.144) <= 5e-7, f"2beta = 0.288: beta = {h.beta!r}"
    assert h.contact.friction == 0.1 and h.coupling_level == "full"
    d = h.discretization
    assert (d.elements, d.element, d.step, d.formulation) == (21, "quadratic", 0.3185, "convective-local"), \
        "21 QCE, Δq = 0.637 Le/2, convective-local"
    assert h.load.start == "rolling" and h.load.tangential == rollqp.histories.Constant(0.0)
    assert h.load.normal_history == Harmonic(1.0, 0.2, 2.0), "P = P̄(1 + 0.2 sin(2πq/λ)), λ = 2 a_H"
    # the largest load 1.2 P̄ widens the contact by √1.2; the zone must hold it (the scene
    # check: 3/4 of an element free at each end)
    assert np.sqrt(1.2) < d.zone * (1 - 1.5 / d.elements), f"zone {d.zone}"
    assert d.distance >= 2 * h.load.normal_history.wavelength, "at least two load cycles"
    assert 0.005 <= h.a_H / h.R <= 0.02, f"a_H/R = {h.a_H / h.R:.4f}"


def test_cli_lists_the_scenes(capsys):
    assert cli.main(["scenes"]) == 0
    out = capsys.readouterr().out
    for name in ("goodman-bentall", "harmonic"):
        assert any(line.split()[0] == name for line in out.splitlines()), f"{name} listed"


@pytest.mark.parametrize("name", ["goodman-bentall", "harmonic"])
def test_cli_runs_and_plots(name, tmp_path, capsys):
    pytest.importorskip("matplotlib")
    out, fig = tmp_path / "r.npz", tmp_path / "f.png"
    assert cli.main(["run", name, "--out", str(out), "--plot", str(fig)]) == 0
    text = capsys.readouterr().out
    assert "coupling full" in text and "final creepage" in text, text
    assert fig.stat().st_size > 50_000, "the dissimilar figure (six panels) was drawn"
    res = rollqp.load_result(out)
    assert res["residual"].max() <= 1e-8, "every step to the residual limit"


# ------------------------------------------------------------------------------- §6.2.1
def test_goodman_starting_state(goodman_bentall):
    """Coupling "goodman" after the braked normal loading: Hertz pressure, antisymmetric shear."""
    results, _ = goodman_bentall
    run = results["runs"]["goodman"]
    st, res, scene = run["stats"], run["result"], run["scene"]
    # A_nt = 0: the pressure is Hertz's; 0.50 % is the 40-QCE discretization error (the
    # similar-body Hertz start of cattaneo-carter measures 0.36 %, same bound)
    assert st["start_hertz_rms"] <= 0.01, f"rms(p − Hertz) = {st['start_hertz_rms']:.4f} p0"
    # A_tn ≠ 0: the pressure displaces the surfaces tangentially and friction resists:
    # large slip zones at ±μp (measured max |t| = 0.957 μp0)
    assert st["start_tmax"] >= 0.5, f"max |t| = {st['start_tmax']:.3f} μp0"
    # symmetric problem on a symmetric mesh: t odd to solver accuracy (measured 6e-14)
    assert st["start_antisymmetry"] <= 1e-9, f"max |t(x) + t(−x)| = {st['start_antisymmetry']:.1e} μp0"
    assert abs(st["start_Q"]) <= 1e-9, "no net tangential force"
    zones = [z for z in st["start_zones"] if z[0] != "separation"]
    assert [z[0] for z in zones] == ["slip", "stick", "slip"], f"central stick zone: {zones}"
    stick = zones[1]
    assert abs(stick[1] + stick[2]) <= 1e-9 and stick[2] > 0, f"stick zone centred on x = 0: {stick}"
    # friction opposes the relative displacement the pressure alone produces (A_tn p)
    p, t, state = res["pn"][0], res["pt"][0], res["state"][0]
    model = rollqp.SceneOperators.build(scene, symmetrized=False)
    wp = model.Atn @ p
    slip = state == 2
    assert np.all(np.sign(t[slip]) == -np.sign(wp[slip])), "t opposes A_tn p in the slip zones"


def test_friction_bound_and_free_rolling(goodman_bentall):
    results, _ = goodman_bentall
    for c in ("goodman", "full"):
        res, st = results["runs"][c]["result"], results["runs"][c]["stats"]
        # |t| ≤ μp at every node of every state, to round-off (measured ≤ 4e-16)
        assert st["friction_excess"] <= 1e-12, f"{c}: (|t| − μp) up to {st['friction_excess']:.1e} μp0"
        Q = res["Q"] / (0.3 * res["P"])
        assert np.abs(Q).max() <= 1e-9, f"{c}: free rolling, max |Q|/(μP) = {np.abs(Q).max():.1e}"
        assert st["residual"] <= 1e-8, f"{c}: residual {st['residual']:.1e}"


def test_full_coupling_differs_from_goodman(goodman_bentall):
    """The coupled start has a pressure peak (Fig. 7) that Goodman's approximation lacks."""
    results, out = goodman_bentall
    g, f = results["runs"]["goodman"]["stats"], results["runs"]["full"]["stats"]
    cmp = results["comparison"]
    assert f["start_pmax"] >= 1.2 and g["start_pmax"] <= 1.001, \
        f"peak {f['start_pmax']:.3f} p0 (full) vs {g['start_pmax']:.4f} (goodman); measured 1.306"
    # by symmetry the coupled start is still p even, t odd (measured 5e-14, 2e-13)
    assert f["start_pressure_asymmetry"] <= 1e-9 and f["start_antisymmetry"] <= 1e-9
    assert cmp["start_dp"] >= 0.2 and cmp["start_dt"] >= 0.2, f"the starts differ: {cmp}"
    assert cmp["transient_dt"] >= 0.3, f"and so do the transients: {cmp}"
    assert "full vs goodman" in out


def test_pressure_peak_rolls_out_through_the_trailing_edge(goodman_bentall):
    """Paper: the peak 'disappears through the trailing edge' after 0.6 contact widths."""
    results, _ = goodman_bentall
    f = results["runs"]["full"]["stats"]
    scene = results["runs"]["full"]["scene"]
    trailing = scene.load.direction          # the trailing edge is at x = +d·a (docs/formulation.md §1)
    # the excess pressure is carried with the material (speed 1 in q): at q = 0.5 and 1.0 a_H
    # it has moved towards the trailing edge by 0.375 and 0.75 a_H (measured)
    assert trailing * f["peak_x_half"] >= 0.25, f"at q = 0.5 a_H the peak is at x = {f['peak_x_half']:+.3f} a_H"
    assert trailing * f["peak_x_one"] >= 0.6, f"at q = 1.0 a_H the peak is at x = {f['peak_x_one']:+.3f} a_H"
    # gone (≤ 0.02 p0 above the steady pressure) by 0.75 contact widths; paper 0.6, measured
    # 1.39 a_H = 0.70 widths (the bound allows for the excess 'rule' chosen here)
    assert f["peak_gone"] <= 1.5, f"pressure excess gone from q = {f['peak_gone']:.3f} a_H"


def test_bentall_steady_state(goodman_bentall):
    """Both couplings end in steady free rolling with a Bentall–Johnson creepage."""
    results, _ = goodman_bentall
    g, f = results["runs"]["goodman"]["stats"], results["runs"]["full"]["stats"]
    scene = results["runs"]["full"]["scene"]
    for c, st in (("goodman", g), ("full", f)):
        # paper: the transient is gone after 1.8 contact widths (3.6 a_H); the tractions here
        # settle by 3.1 (full) and 4.06 a_H (goodman: a stick/slip boundary node flips late)
        assert st["settled"] is not None and st["settled"] <= 4.5, f"{c}: settled from {st['settled']}"
        assert st["xi_change_last_2aH"] <= 1e-3, f"{c}: creepage still changes {st['xi_change_last_2aH']:.1e}"
        # sign: sgn(ξ) = d·sgn(κ) (closedforms.bentall_johnson_creepage); magnitude below the
        # μ → 0 value: finite friction sticks part of the contact (κ/μ = 3.3; measured 0.750
        # goodman, 0.786 full)
        assert np.sign(st["xi_end"]) == scene.load.direction * np.sign(scene.kappa), f"{c}: sign of ξ"
        assert 0.6 <= abs(st["xi_ratio"]) <= 1.0, f"{c}: |ξ|/ξ_BJ = {abs(st['xi_ratio']):.4f}"
    # paper: 'the steady state solution is very close to that obtained by neglecting coupling'
    ratio = results["comparison"]["end_xi_ratio"]
    assert abs(ratio - 1) <= 0.1, f"ξ_full/ξ_goodman = {ratio:.4f} (measured 1.048)"


def test_creepage_approaches_bentall_johnson_as_friction_vanishes():
    """Goodman coupling (Bentall–Johnson's assumption), direct steady free-rolling solves:
    |ξ|/ξ_BJ rises towards 1 as μ → 0 (measured 0.751, 0.876, 0.963, 0.990)."""
    scene = rollqp.load_scene("goodman-bentall").replace(
        **{"contact.coupling": "goodman", "load.start": "rolling", "discretization.distance": 0.0})
    bj = cf.bentall_johnson_creepage(scene.kappa, scene.a_H, scene.R)
    ratios = []
    for mu in (0.3, 0.1, 0.03, 0.01):
        res = rollqp.run(scene.replace(**{"contact.friction": mu})).arrays()
        xi = float(res["creepage"][0])
        assert np.sign(xi) == scene.load.direction * np.sign(scene.kappa), f"mu = {mu}: sign of ξ"
        ratios.append(abs(xi) / bj)
    assert np.all(np.diff(ratios) > 0), f"|ξ|/ξ_BJ increases as μ decreases: {np.round(ratios, 4)}"
    # 40 QCE: the ratio changes by ≤ 1.3e-3 from 40 to 80 elements (measured), hence 0.5 %
    assert 0.97 <= ratios[-1] <= 1.005, f"μ = 0.01: |ξ|/ξ_BJ = {ratios[-1]:.4f}"


def test_nt_newton_matches_coupled_newton(goodman_bentall):
    """Paper §6.3: the N–T alternation gives 'exactly the same results' as the coupled scheme."""
    results, _ = goodman_bentall
    ref, scene = results["runs"]["full"]["result"], results["runs"]["full"]["scene"]
    res = rollqp.run(scene, method="nt-newton").arrays()
    p0, mu = scene.p0, scene.contact.friction
    # both stop at the coupled residual 1e-10; the solutions then differ by that times the
    # step's conditioning (measured 1.2e-9 p0, 3.0e-9 μp0)
    assert np.abs(res["pn"] - ref["pn"]).max() / p0 <= 1e-7
    assert np.abs(res["pt"] - ref["pt"]).max() / (mu * p0) <= 1e-7
    assert np.array_equal(res["state"], ref["state"]), "same stick/slip/separation nodes"
    # paper: ≈ 6 outer iterations per step for this problem; measured mean 9.8
    assert res["iterations"][1:].mean() <= 20, f"outer iterations {res['iterations'][1:].mean():.1f}"


# ------------------------------------------------------------------------------- §6.2.2
def test_rolling_start_is_the_steady_state():
    """At constant load the convective-local transient keeps the directly solved steady state."""
    scene = rollqp.load_scene("harmonic").replace(
        **{"load.normal_history": {"kind": "constant", "value": 1.0}, "discretization.distance": 1.0})
    res = rollqp.run(scene).arrays()
    p0, mu = scene.p0, scene.contact.friction
    # fixed point up to the residual limit (measured exactly 0: Newton accepts the warm start)
    assert np.abs(res["pt"] - res["pt"][0]).max() / (mu * p0) <= 1e-8
    assert np.abs(res["pn"] - res["pn"][0]).max() / p0 <= 1e-8
    assert np.abs(res["creepage"] - res["creepage"][0]).max() <= 1e-8 * abs(res["creepage"][0])


def test_harmonic_load(harmonic):
    results, out = harmonic
    st, res, scene = results["stats"], results["result"], results["scene"]
    # steady free-rolling start: Bentall–Johnson sign, magnitude below the μ → 0 value
    # (κ/μ = 2.88; measured 0.740)
    assert np.sign(st["xi_start"]) == scene.load.direction * np.sign(scene.kappa)
    assert 0.6 <= abs(st["xi_start_ratio"]) <= 1.0, f"|ξ0|/ξ_BJ = {abs(st['xi_start_ratio']):.4f}"
    # paper: 'the contact area length varies in phase with the normal load'. The discrete
    # half-width moves in node steps: within one node spacing of a_H·√(P/P̄) (measured 0.043
    # a_H, spacing 0.064), and correlated with P (measured 0.957)
    assert st["half_width_error"] <= st["node_spacing"], st["half_width_error"]
    assert st["width_load_correlation"] >= 0.9, st["width_load_correlation"]
    # paper: 'two-one-two adhesion zones appear in an alternating sequence'
    counts = st["stick_zone_counts"]
    assert set(counts) == {1, 2}, f"one or two stick zones: {counts}"
    assert min(counts.values()) >= 0.1 * (st["steps"] + 1), f"both occur often: {counts}"
    assert st["friction_excess"] <= 1e-12 and st["Q_max"] <= 1e-9, "|t| ≤ μp, Q = 0"
    assert st["residual"] <= 1e-8
    P = res["P"] / scene.load.normal
    assert abs(P.max() - 1.2) <= 0.01 and abs(P.min() - 0.8) <= 0.01, "P between 0.8 and 1.2 P̄"
    assert "stick zones" in out and "cycle 1->2" in out


def test_first_cycle_transient_then_periodic():
    """Paper: 'this first cycle is completely transient, giving place to a periodic
    quasi-steady state'. With λ a whole number of steps (49 Δq ≈ 2.0066 a_H) states one cycle
    apart are compared at the same phase."""
    scene = rollqp.load_scene("harmonic")
    lam = 49 * scene.dq / scene.a_H
    ns, _ = run_example("harmonic.py", ["--wavelength", repr(lam), "--cycles", "4"])
    st = ns["results"]["stats"]
    assert st["steps_per_cycle"] == 49 and abs(st["phase_mismatch"]) <= 1e-12
    d = [c["dt"] for c in st["cycles"]]
    # cycle 1 → 2 changes by 0.305 μp0, 2 → 3 by 0.055, 3 → 4 by 9e-4 (measured)
    assert d[0] >= 0.1, f"the first cycle is transient: {d}"
    assert d[-1] <= 1e-2 and d[-1] < 0.1 * d[0], f"then periodic: {d}"
    assert st["cycles"][-1]["flips"] == 0, "same stick/slip nodes one cycle apart"


# ------------------------------------------------------------------------------- figures
def test_figures(goodman_bentall, harmonic, tmp_path):
    pytest.importorskip("matplotlib")
    from rollqp import plot
    gres = goodman_bentall[0]["runs"]["full"]["result"]
    hres, hscene = harmonic[0]["result"], harmonic[0]["scene"]
    # the default snapshots: evenly spaced over the transient when the run settles, else over the run
    qs = plot.settled_q(gres)
    assert qs is not None and qs <= 4.5 and plot.settled_q(hres) is None
    idx = plot.select_states(gres["q"], float(gres["a_H"]), settled=qs)
    assert idx[0] == 0 and idx[-1] == len(gres["q"]) - 1 and len(idx) == 5
    assert gres["q"][idx[-2]] / float(gres["a_H"]) <= qs + 0.02
    assert plot.select_states(hres["q"], float(hres["a_H"]), at=(0.0, 1.0, 1.0, 99.0)) == \
        [0, int(np.argmin(np.abs(hres["q"] / float(hres["a_H"]) - 1.0)))], "nearest, unique, in range"
    fig = plot.snapshot_figure(hres, hscene, at=(0.0, 0.5, 1.5))
    assert len(fig.axes) == 4
    import matplotlib.pyplot as plt
    plt.close(fig)
    for name, func in (("s.png", plot.snapshot_figure), ("z.png", plot.zone_map_figure),
                       ("d.png", plot.dissimilar_figure)):
        path = tmp_path / name
        assert func(hres, None, str(path)) == str(path), "meta stands in for the scene"
        assert path.stat().st_size > 20_000, name
    path = tmp_path / "c.png"
    plot.comparison_figure({"goodman": goodman_bentall[0]["runs"]["goodman"]["result"], "full": gres},
                           path=str(path))
    assert path.stat().st_size > 20_000


def test_examples_write_their_figures(tmp_path):
    pytest.importorskip("matplotlib")
    ns, out = run_example("harmonic.py", ["--cycles", "1", "--figures", str(tmp_path)])
    names = sorted(Path(p).name for p in ns["results"]["figures"])
    assert names == ["harmonic-first-cycle.png", "harmonic-periodic.png", "harmonic-zones.png"]
    assert all((tmp_path / n).stat().st_size > 20_000 for n in names)


@pytest.mark.parametrize("name", ["goodman_bentall.py", "harmonic.py"])
def test_examples_are_documented(name):
    text = (EXAMPLES / name).read_text(encoding="utf-8")
    assert text.startswith('"""') and "Run it::" in text, f"{name} starts with a docstring saying how to run it"
    assert 'if __name__ == "__main__":' in text, f"{name} is a script"


# ------------------------------------------------------------------------------- slow
@pytest.mark.slow
@pytest.mark.parametrize("name", ["goodman-bentall", "harmonic"])
def test_qp_alternation_matches_newton(name):
    """qp-osqp alternates normal and tangential QPs (≈ 45 s for goodman-bentall, 5 s for harmonic)."""
    from threadpoolctl import threadpool_limits
    scene = rollqp.load_scene(name)
    with threadpool_limits(limits=1):       # as the CLI: competing BLAS pools slow OSQP's steps
        ref = rollqp.run(scene).arrays()
        res = rollqp.run(scene, method="qp-osqp").arrays()
    p0, mu = scene.p0, scene.contact.friction
    # the QP halves are trusted to residual 1e-8 (conftest BACKENDS); times the step's
    # conditioning. Measured 1.3e-9 p0 and 3.0e-9 μp0 (goodman-bentall), 9.3e-10 p0 and
    # 8.6e-8 μp0 (harmonic)
    assert np.abs(res["pn"] - ref["pn"]).max() / p0 <= 1e-6
    assert np.abs(res["pt"] - ref["pt"]).max() / (mu * p0) <= 1e-6
    assert np.array_equal(res["state"], ref["state"]), "same node states"
    assert abs(res["creepage"][-1] / ref["creepage"][-1] - 1) <= 1e-6


@pytest.mark.slow
def test_harmonic_nt_newton_matches_newton(harmonic):
    ref, scene = harmonic[0]["result"], harmonic[0]["scene"]
    res = rollqp.run(scene, method="nt-newton").arrays()
    p0, mu = scene.p0, scene.contact.friction
    assert np.abs(res["pn"] - ref["pn"]).max() / p0 <= 1e-7          # measured 3.2e-10
    assert np.abs(res["pt"] - ref["pt"]).max() / (mu * p0) <= 1e-7   # measured 3.7e-10
    assert np.array_equal(res["state"], ref["state"])
