"""The 3D figure of ``rollqp run --plot``, by what the run is about (rollqp.plot.three): Kalker's
linear theory, a point of the creep curve, a transient from a Cattaneo shift; each with the
references a reader checks against, both bounds ±μp, and a legend naming every mark. Coarse grids."""
from __future__ import annotations

import numpy as np
import pytest

from rollqp import load_scene
from rollqp.plot.three import she_saturation, three_figure, three_kind
from rollqp.march.grid import run

pytest.importorskip("matplotlib")


def coarse(name: str, **changes):
    s = load_scene(name)
    nx, ny = s.discretization.elements
    k = 12 / min(nx, ny)
    return s.replace(**{"discretization.elements": [round(nx * k), round(ny * k)], "discretization.zone": [1.3, 1.3],
                        **changes})


def _labels(fig):
    out = []
    for ax in fig.axes:
        leg = ax.get_legend()
        if leg is not None:
            out += [t.get_text() for t in leg.get_texts()]
    return out


@pytest.fixture(scope="module")
def runs():
    scenes = {"linear": coarse("kalker-circular", **{"discretization.distance": 0.5}),
              "steady": coarse("kalker-elliptic"),
              "transient": coarse("cattaneo-3d", **{"discretization.distance": 1.5})}
    return {k: (s, run(s).arrays()) for k, s in scenes.items()}


@pytest.mark.parametrize("kind", ["linear", "steady", "transient"])
def test_the_kind_is_what_the_run_is_about(runs, kind):
    scene, res = runs[kind]
    assert three_kind(res, scene) == kind


@pytest.mark.parametrize("kind", ["linear", "steady", "transient"])
def test_every_figure_names_its_references_and_marks(runs, kind, tmp_path):
    import matplotlib.pyplot as plt
    scene, res = runs[kind]
    fig = three_figure(res, scene)
    labels = " | ".join(_labels(fig))
    for needed in ("element in stick", "element in slip", "stick area", "p/p_0$ = 0.2", "Hertz ellipse",
                   "Hertz (3D.4)", "Kalker's linear theory (3D.8)", "rollqp, state"):
        assert needed in labels, (needed, labels)
    assert r"\pm\mu p" in labels
    if kind == "transient":
        assert "Cattaneo–Mindlin (3D.6), start" in labels and "steady state (solved directly)" in labels
        assert "stick circle (3D.6)" in labels
    if kind != "linear":
        assert "full sliding" in labels and "Shen–Hedrick–Elkins" in labels
    # the stick area's swatch is the grey of the area, not black
    from matplotlib.colors import to_rgba
    field = fig.axes[0].get_legend()
    swatch = field.legend_handles[field.get_texts().index(next(t for t in field.get_texts() if t.get_text() == "stick area"))]
    assert swatch.get_facecolor()[:3] == pytest.approx(to_rgba("0.8")[:3])
    # no twin axis with the creepages on the force panel: every axes of the figure is a panel or a scale
    assert not any(ax.get_ylabel().startswith("creepage /") for ax in fig.axes)
    fig.savefig(tmp_path / "f.png")
    plt.close(fig)


def test_the_steady_panel_draws_both_bounds(runs):
    """t_x lies between −μp and +μp along y = 0, and both are drawn (a braking case slips on −μp)."""
    import matplotlib.pyplot as plt
    scene, res = runs["steady"]
    fig = three_figure(res, scene)
    ax = fig.axes[1]
    j0 = int(np.argmin(np.abs(res["y"])))
    bound = res["pn"][-1][j0] / scene.ellipse.p0
    ys = [np.asarray(line.get_ydata(), dtype=float) for line in ax.get_lines()]
    assert any(y.shape == bound.shape and np.allclose(y, bound) for y in ys)
    assert any(y.shape == bound.shape and np.allclose(y, -bound) for y in ys)
    plt.close(fig)


def test_braking_slips_on_the_lower_bound(runs):
    """The same ellipse braking (ξ > 0): the slipping elements sit on −μp, the curve drawn."""
    scene = runs["steady"][0].replace(**{"load.creepage.longitudinal": 1.4e-3, "load.creepage.spin": 0.0,
                                        "load.creepage.lateral": 0.0})
    res = run(scene).arrays()
    j0 = int(np.argmin(np.abs(res["y"])))
    slip = res["state"][-1][j0] == 2
    assert slip.any()
    bound = scene.mu * res["pn"][-1][j0][slip]
    # |t| = μp on the slip elements (to the Newton tolerance), along −x up to the small lateral part the
    # νXY/ρ³ coupling turns it by (5e-5 here, validation3d.md §4)
    np.testing.assert_allclose(np.hypot(res["px"][-1][j0][slip], res["py"][-1][j0][slip]), bound, rtol=1e-8)
    assert np.all(res["px"][-1][j0][slip] <= -0.999 * bound)


def test_she_saturation_has_the_linear_slope_and_saturates():
    u = np.array([1e-6, 3.0, 10.0])
    assert she_saturation(u)[0] == pytest.approx(1e-6, rel=1e-5) and she_saturation(u)[1:] == pytest.approx(1.0)


def test_a_non_hertzian_patch_calls_its_ellipse_a_guide():
    """A profile's contact is not elliptic: the ellipse of its equivalent curvatures, Hertz's pressure and
    Kalker's coefficients of that ellipse are named as guides, not as its references."""
    import matplotlib.pyplot as plt
    scene = load_scene("quartic-roller").replace(**{"discretization.elements": [12, 24]})
    fig = three_figure(run(scene).arrays(), scene)
    labels = " | ".join(_labels(fig))
    assert "ellipse of the equivalent curvatures (a guide)" in labels and "Hertz ellipse (3D.4)" not in labels
    assert "equivalent ellipse's Kalker's linear theory" in labels and "a guide: the patch is not elliptic" in labels
    plt.close(fig)
