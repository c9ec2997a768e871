"""examples/rough.py (docs/matrix-free.md, docs/examples.md): a small version of the rough-cylinder
transient, run as its command runs it, and the same scene on the dense path."""
from __future__ import annotations

import runpy
from pathlib import Path

import numpy as np

from rollqp.matrixfree import mode

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
#: The small version: 500 quadratic elements on ±2 a_H (1,001 nodes: matrix-free by the auto
#: threshold), 0.2 a_H rolled at Δq = 8 Le = 0.064 a_H (4 rolling steps).
SMALL = ["--elements", "500", "--distance", "0.2"]


def _run(argv, monkeypatch):
    path = EXAMPLES / "rough.py"
    monkeypatch.setattr("sys.argv", [str(path), *argv])
    return runpy.run_path(str(path), run_name="__main__")["results"]


def test_rough_example_small(monkeypatch, capsys, tmp_path):
    fig = tmp_path / "rough.png"
    mf = _run(SMALL + ["--figure", str(fig)], monkeypatch)
    out = capsys.readouterr().out
    m, a = mf["measures"], mf["arrays"]
    assert mode(mf["scene"]) == "matrix-free", "1,001 nodes with mf-newton: FFT operators"
    assert m["nodes"] == 1001 and m["states"] == 5
    # several contact patches in every state (measured 13 to 17 at this seed), both zones present
    assert m["patches_min"] >= 5, m["patches"]
    assert m["stick_nodes"] > 0 and m["slip_nodes"] > 0
    # the loads are rows of the system: met to round-off; every step to rollqp's residual (tolerance 1e-10)
    assert m["load_error"] < 1e-12 and m["shear_error"] < 1e-12
    assert m["residual"] <= 1e-10
    assert fig.stat().st_size > 10_000
    assert "contact patches per state" in out and "1,001 nodes" in out
    # the same scene on the dense path (newton): both solve every step to rollqp's residual 1e-10,
    # so the states agree to a few times that (measured 1e-13 p0, μp0)
    dense = _run(SMALL + ["--method", "newton"], monkeypatch)["arrays"]
    p0, mu = float(a["p0"]), mf["scene"].contact.friction
    assert np.max(np.abs(dense["pn"] - a["pn"])) / p0 < 1e-10
    assert np.max(np.abs(dense["pt"] - a["pt"])) / (mu * p0) < 1e-10
    assert np.array_equal(dense["state"], a["state"])


def test_rough_example_is_documented():
    text = (EXAMPLES / "rough.py").read_text(encoding="utf-8")
    assert text.startswith('"""') and "Run it::" in text and 'if __name__ == "__main__":' in text
    docs = Path(__file__).resolve().parent.parent / "docs"
    for page in ("examples.md", "matrix-free.md"):
        assert "figures/rough.png" in (docs / page).read_text(encoding="utf-8"), page
