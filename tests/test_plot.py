"""Figures per kind of scene (rollqp.plot): which figure a run gets, and what its panels hold."""
from __future__ import annotations

import numpy as np
import pytest

import rollqp
from rollqp import closedforms as cf

pytest.importorskip("matplotlib")
from rollqp import plot  # noqa: E402  (needs matplotlib)

#: Built-in scenes, shortened where the point of the scene survives, and the figure each gets.
KINDS = {
    "cattaneo-carter": ({"discretization.distance": 1.0}, "transient"),
    "ramp": ({"discretization.distance": 1.0}, "transient"),
    "goodman-bentall": ({"discretization.distance": 0.25, "discretization.elements": 20}, "coupled"),
    "harmonic": ({"discretization.distance": 0.5}, "coupled"),
    "dent": ({}, "profile"),
    "fretting": ({}, "rest"),
    "stop-reverse": ({}, "path"),
    "falling-friction": ({"discretization.distance": 1.5}, "friction"),
}


@pytest.fixture(scope="module")
def runs():
    out = {}
    for name, (changes, _) in KINDS.items():
        s = rollqp.load_scene(name).replace(**changes) if changes else rollqp.load_scene(name)
        out[name] = (s, rollqp.run(s).arrays())
    return out


@pytest.mark.parametrize("name", list(KINDS))
def test_each_builtin_scene_gets_its_figure(name, runs, tmp_path):
    """The scene's content decides the figure (the same from the result file alone: its meta holds the scene)."""
    s, res = runs[name]
    assert plot.figure_kind(res, s) == KINDS[name][1]
    assert plot.figure_kind(res) == KINDS[name][1]
    path = plot.plot_result(res, s, str(tmp_path / "f.png"))
    assert (tmp_path / "f.png").stat().st_size > 20_000, path


def _line(ax, label_part):
    return next(line for line in ax.get_lines() if label_part in str(line.get_label()))


def test_a_stop_has_no_creepage_drawn(runs):
    """stop-reverse: the creepage is drawn for the rolling states only — the stop's static steps are gaps,
    not creepage 0 — and the traction panel has states after the reversal and Carter both ways."""
    s, res = runs["stop-reverse"]
    fig = plot.path_figure(res, s)
    ax = fig.axes
    y = _line(ax[3], "rolling states").get_ydata()
    stop = np.asarray(res["direction"]) == 0
    assert np.all(np.isnan(y[stop])) and np.all(np.isfinite(y[~stop][1:]))
    labels = [str(line.get_label()) for line in ax[0].get_lines()]
    assert "Carter (steady)" in labels and "Carter, rolling the other way" in labels
    idx, turn = plot.paths.turn_states(res, plot.style.Info(res, s))
    assert turn is not None and sum(k >= turn for k in idx) >= 4, "states while the contact turns round"
    plot.pyplot().close(fig)


def test_fretting_loop_against_mindlin(runs):
    """fretting: the Q–u loop at rest (a shift, not a creepage) beside the Mindlin–Deresiewicz loop; the energies
    per cycle agree to the discretization (40 QCE: measured 0.02 %; 1 % allowed)."""
    s, res = runs["fretting"]
    fig = plot.rest_figure(res, s)
    loop = fig.axes[1]
    rq, mind = _line(loop, "rollqp: $W$"), _line(loop, "Mindlin")
    W = [float(str(line.get_label()).split("= ")[1].split()[0]) for line in (rq, mind)]
    assert abs(W[0] / W[1] - 1) < 0.01, W
    assert "not a creepage" in loop.get_title()
    plot.pyplot().close(fig)


def test_dent_states_span_its_passage(runs):
    """dent: the states drawn are one before the dent reaches the contact, four while it crosses, and after."""
    s, res = runs["dent"]
    on, dz = plot.paths.passage(res, s, s.a_H)
    idx = plot.paths.profile_states(res, s, s.a_H)
    inside = [k for k in idx if on[0] <= k <= on[-1]]
    assert len(inside) >= 4 and min(idx) < on[0] and max(idx) > on[-1]
    assert dz.max() == pytest.approx(s.A.profile.features[0].depth, rel=0.05)  # the 3 µm dent, sampled on the nodes


def test_mindlin_displacement_loop_area_is_the_dissipation():
    """The closed-form loop (Masing superposition of the 2D Cattaneo compliance) encloses W of
    mindlin_dissipation; the trapezoidal area converges at second order as the path is sampled finer."""
    W = cf.mindlin_dissipation(0.6, 0.1, 1000.0, 115384.6)
    errs = []
    for n in (50, 100, 200):
        r = np.concatenate([np.linspace(0, 0.6, n), np.linspace(0.6, -0.6, 4 * n)[1:], np.linspace(-0.6, 0.6, 4 * n)[1:]])
        u = cf.mindlin_displacement(r, 0.1, 1000.0, 115384.6)
        Q = 100.0 * r
        loop = slice(n - 1, None)
        errs.append(abs(np.sum(0.5 * (Q[loop][1:] + Q[loop][:-1]) * np.diff(u[loop])) / W - 1))
        assert u[n - 1] == pytest.approx(u[-1], abs=1e-15)  # the loop closes
    slopes = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(slopes > 1.9), (errs, slopes)
