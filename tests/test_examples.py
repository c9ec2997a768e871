"""The examples are tests too (scikit-fem's tests/test_examples.py): each is run as a user runs
it (``runpy`` as ``__main__``), and what it produces is checked, not only that it ran."""
from __future__ import annotations

import runpy
from pathlib import Path

import numpy as np
import pytest

from conftest import BACKENDS, pair_tolerance

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def run_example(name, argv, monkeypatch):
    """Run ``examples/<name>`` as ``__main__`` with ``argv``; return its globals."""
    path = EXAMPLES / name
    monkeypatch.setattr("sys.argv", [str(path), *argv])
    return runpy.run_path(str(path), run_name="__main__")


def test_own_arrays(monkeypatch, capsys):
    ns = run_example("own_arrays.py", [], monkeypatch)
    out = capsys.readouterr().out
    res = ns["results"]
    normal, tangential = res["problems"]
    by_name = {b.method: b for b in BACKENDS.values()}
    assert set(res["normal"]) == set(by_name), f"every backend ran: {sorted(res['normal'])}"
    for m, b in by_name.items():
        # rollqp's residuals re-evaluated on the user's arrays, not the solution's record
        n, t = res["normal"][m], res["tangential"][m]
        rn = normal.residuals(n.p, n.delta)
        rt = tangential.residuals(t.t, t.xi)
        assert rn.max <= b.residual and rt.max <= b.residual, f"{m}: residuals {rn}, {rt}"
        assert m in out, f"{m} reported"
    ref = "qp-clarabel"
    for m, d in res["differences"].items():
        tol = pair_tolerance((by_name[m], by_name[ref]))     # constant elements: exactly symmetric
        for key in ("p", "delta", "t", "xi"):
            assert d[key] <= tol, f"{m} vs {ref}: {key} differs by {d[key]:.1e}"
        assert d["state_differs"].size == 0, f"{m}: node states differ at {d['state_differs']}"
    x = res["x"] / res["scales"].length
    state = res["states"][ref]
    assert {0, 1, 2} <= set(state.tolist()), f"separation, stick and slip all occur: {state}"
    stick = np.abs(x[state == 1])
    c = np.sqrt(1 - 0.6)                                       # Cattaneo, Q = 0.6 μP
    spacing = x[1] - x[0]
    # the discrete stick zone ends at the last node inside c (one node spacing, 0.0625 a_H)
    assert stick.max() < c < stick.max() + spacing, f"stick |x| <= {stick.max():.3f}, Cattaneo c/a = {c:.4f}"
    assert np.all(state[np.abs(x) < c - spacing] == 1), "the middle sticks"
    for word in ("separation", "stick", "slip", "differences", "signorini", "friction"):
        assert word in out, f"the printout shows {word!r}"


def test_cattaneo_carter(monkeypatch, capsys):
    ns = run_example("cattaneo_carter.py", [], monkeypatch)
    out = capsys.readouterr().out
    errors = ns["results"]["errors"]
    assert set(errors) == {"hertz", "cattaneo", "carter", "creepage"}, f"all closed forms apply: {sorted(errors)}"
    # discretization error of the paper's mesh (40 QCE, Δq = Le/2): measured 0.36 %, 0.51 %,
    # 0.64 %, 0.58 %
    assert errors["hertz"] <= 0.01, f"Hertz rms error {errors['hertz']:.4f} p0"
    assert errors["cattaneo"] <= 0.01, f"Cattaneo rms error {errors['cattaneo']:.4f} μp0"
    assert errors["carter"] <= 0.015, f"Carter rms error {errors['carter']:.4f} μp0"
    assert errors["creepage"] <= 0.015, f"creepage off Carter's by {errors['creepage']:.4f}"
    for key, value in errors.items():
        assert f"error {key}" in out and f"{value:.4f}" in out, f"{key} printed with its value"
    res = ns["results"]["result"]
    assert res["residual"].max() <= 1e-8, "every step solved to the residual limit (100 × tolerance 1e-10)"
    assert ns["results"]["scene"].name == "cattaneo-carter", "the built-in scene ran"


@pytest.mark.parametrize("name", ["own_arrays.py", "cattaneo_carter.py"])
def test_examples_are_documented(name):
    text = (EXAMPLES / name).read_text(encoding="utf-8")
    assert text.startswith('"""') and "Run it::" in text, f"{name} starts with a docstring saying how to run it"
    assert 'if __name__ == "__main__":' in text, f"{name} is a script"
