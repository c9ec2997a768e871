"""The built-in scenes of the 3D gallery beyond Hertz (docs/examples.md, "Three dimensions"): `aluminium-on-steel`
(a dissimilar transient from rest) and `rolling-stresses` (the stresses below a rolling contact) run, by Newton and
by the conic route, to the same answer, and show what the gallery says of them."""
from __future__ import annotations

import numpy as np
import pytest

import rollqp
from rollqp.subsurface3d import stresses3d


def _small(name, **changes):
    return rollqp.load_scene(name).replace(**{"discretization.elements": [12, 12], **changes})


@pytest.mark.parametrize("name, changes", [("aluminium-on-steel", {"discretization.distance": 0.5}),
                                           ("rolling-stresses", {})])
def test_newton_and_the_conic_route_agree(name, changes):
    """Both routes on a 12 × 12 version: tractions and pressure to 1e-7 of μp0 and p0 (each solved to 1e-10; the
    conic solver's answer polished by rollqp's residual, measured differences below 1e-8)."""
    out = {}
    for method in ("newton", "socp-clarabel"):
        a = rollqp.run(_small(name, **changes).replace(**{"solver.method": method})).arrays()
        out[method] = a
    n, c = out["newton"], out["socp-clarabel"]
    mu_p0 = float(n["p0"]) * _small(name).mu
    assert np.abs(n["pn"] - c["pn"]).max() < 1e-7 * float(n["p0"])
    assert max(np.abs(n[k] - c[k]).max() for k in ("px", "py")) < 1e-7 * mu_p0


def test_the_dissimilar_braked_state_moves_its_stick_area():
    """K ≠ 0: the braked state's stick area has its centroid at x = −0.21 a on the gallery's 20 × 20 grid (and the
    pressure's at −0.009 a); with a second aluminium body (K = 0) both are at 0 to round-off."""
    s = rollqp.load_scene("aluminium-on-steel").replace(**{"discretization.distance": 0.0})
    centroids = []
    for scene in (s, s.replace(**{"bodies.B.E": 70000.0, "bodies.B.nu": 0.33})):
        a = rollqp.run(scene).arrays()
        X = np.broadcast_to(a["x"], a["state"][0].shape)
        centroids.append(X[a["state"][0] == 1].mean() / float(a["a"]))
    assert centroids[0] < -0.15 and abs(centroids[1]) < 1e-12, centroids


def test_the_traction_raises_the_stress_peak_and_lifts_it():
    """rolling-stresses at Fx = 0.8 μFN against the same contact without traction, on the plane y = 0: von Mises'
    peak 0.671 p0 at z = 1.58 mm against 0.617 p0 at 1.89 mm (the gallery's numbers)."""
    peaks = []
    for fx in (0.8, 0.0):
        res = rollqp.run(rollqp.load_scene("rolling-stresses").replace(**{"load.tangential": fx}))
        sf = stresses3d(res, -1, plane=("y", 0.0))
        v, *where = sf.maxima["von_mises"]
        peaks.append((v / float(res.arrays()["p0"]), where[-1]))
    (v1, z1), (v0, z0) = peaks
    assert v1 == pytest.approx(0.671, abs=2e-3) and v0 == pytest.approx(0.617, abs=2e-3)
    assert z1 < z0


def test_rollqp_run_stresses_reports_the_3d_peaks_of_the_run(tmp_path, capsys, monkeypatch):
    """`rollqp run SCENE3D --stresses` prints the peak von Mises and Tresca stresses over the stored states on the
    plane y = 0: the same numbers as `rollqp stresses` of that state (rollqp.subsurface3d.stresses3d)."""
    import re

    from rollqp import cli
    monkeypatch.chdir(tmp_path)
    scene = tmp_path / "c.toml"
    scene.write_text(rollqp.load_scene("cattaneo-3d").replace(**{"discretization.elements": [12, 12],
                                                                 "discretization.distance": 1.0}).to_toml())
    assert cli.main(["run", str(scene), "--stresses", "--no-cross-check", "--out", "c.npz"]) == 0
    out = capsys.readouterr().out
    m = re.search(r"peak von Mises\s+(\S+) p0 at x = (\S+), y = (\S+), z = (\S+) mm, state (\d+)", out)
    assert m, out
    res = rollqp.load_result(tmp_path / "c.npz")
    sf = stresses3d(res, int(m.group(5)), plane=("y", 0.0))
    v, x, y, z = sf.maxima["von_mises"]
    assert float(m.group(1)) == pytest.approx(v / float(res["p0"]), abs=1e-4)
    assert float(m.group(4)) == pytest.approx(z, rel=1e-4)
    for k in range(res["q"].size):        # no state has a larger peak
        assert stresses3d(res, k, plane=("y", 0.0)).maxima["von_mises"][0] <= v * (1 + 1e-12)
