r"""Three-dimensional scenes (Kalker's problem): what ``rollqp run --plot`` draws for a scene with
``[contact] dimension = 3``, designed by what the run is about (:func:`three_kind`):

==============  ================================================================  =======================
kind            the run                                                           its references
==============  ================================================================  =======================
``linear``      a steady state in which (almost) nothing slips                    Kalker's linear forces
                (``kalker-circular``: Kalker's linear theory)                     (eq. 3D.8), Hertz
``steady``      a steady state with a slip area: a point of the creep curve,      the creep curve: eq. 3D.8,
                with spin the traction turning (``kalker-elliptic``,              its saturation at μFN;
                ``ball-in-groove``)                                               ±μp, Hertz
``transient``   states that change: a braked start (a Cattaneo shift) rolled      Cattaneo–Mindlin (eq.
                to the steady state (``cattaneo-3d``), loads that change          3D.6–3D.7) at the start,
                                                                                  the steady state at the end
==============  ================================================================  =======================

Every kind draws the final state's **traction field** (vectors black where the element sticks, in
the grey stick area, red where it slips at ``t = −μp s/|s|``; the pressure's contours and the Hertz
ellipse), the **traction along the centre line** ``y = 0`` (``t_x`` and ``t_y`` between the bounds
``±μp``), the **pressure** along both axes against Hertz's (eq. 3D.4), and the **creep force**
against Kalker's linear theory: ``|F|/(μF_N)`` over the linear force ``|F_lin|/(μF_N)`` of the same
creepages (eq. 3D.8), where the linear theory is the diagonal, full sliding the level 1 and the
Shen–Hedrick–Elkins cubic (``1 − (1 − u/3)³``, an approximation, dotted) the usual saturation curve
between them. A transient adds the start's field with Cattaneo–Mindlin's stick circle, the
centre-line traction at several rolled distances between Cattaneo's (eq. 3D.6) and the steady state
(solved directly with the final loads), and the creepages against ``q/a`` with the steady state's.
Labels are mathtext, every mark is named in a legend below its panel, and the dimensional scales
(the scene's ``units``) sit beside the nondimensional ones.

A non-Hertzian contact (a profile in place of eq. 3D.3) keeps the panels; its pressure is then
compared with the Hertz ellipse of the same curvatures only as a guide.
"""
from __future__ import annotations

import numpy as np

from ..closedforms.cattaneo3d import cattaneo_stick_radius, cattaneo_traction
from ..closedforms.kalker import kalker_linear
from ..errors import RollqpError
from ..march.grid import run
from ..methods import REFERENCE_METHOD
from ..report.grid import LINEAR_SLIP_FRACTION, stick_fraction
from ..units import unit_names
from .style import REFERENCES, arrays, colors, finish, legend_below, meta, pyplot, scene_of, value_axis

__all__ = ["three_figure", "field_figure", "three_kind", "creep_force_panel", "she_saturation", "KINDS_3D"]

#: Largest number of arrows drawn along one axis (beyond, every second or third element).
ARROWS = 30
#: The kinds of 3D figure (module table).
KINDS_3D = ("linear", "steady", "transient")
#: States differ when a force, creepage or traction changes by more than this, relative to its largest
#: value (the solver's tolerance, 1e-10 of μp0, is 3e-10 of kalker-circular's small tractions; a settling
#: transient changes them by 1e-3 or more).
CHANGED = 1e-6
#: Element aspect of the field panel drawn to scale: a/b in this range (beyond, the axes are not to
#: scale and the arrows keep their true direction on the screen).
TO_SCALE = (0.4, 2.5)

#: A component below this fraction of the largest is not drawn: the solver's tolerance (1e-10 μp0) on
#: tractions of 1e-2 μp0 is 1e-8 of them; the coupling's genuine lateral traction is 5e-5 or more.
NEGLIGIBLE = 1e-6

STICK_AREA, STICK, SLIP = "0.8", "k", "#d62728"
STEADY = dict(color="#ff7f0e", ls="-.", lw=1.4)
KALKER = dict(color="#2ca02c", ls="--", lw=1.3)
SATURATION = dict(color="0.3", ls="-", lw=1.0)
SHE = dict(color="#9467bd", ls=":", lw=1.4)


# =========================================================================== what the run is about
def _changes(res) -> bool:
    """Whether the stored states differ (forces, creepages, tractions) beyond round-off."""
    if len(res["q"]) < 2:
        return False
    F = np.stack([np.asarray(res["Fx"], dtype=float), np.asarray(res["Fy"], dtype=float)], axis=1)
    for v in (F, np.asarray(res["creepage"], dtype=float)[:, :2], np.asarray(res["creepage"], dtype=float)[:, 2:]):
        if np.ptp(v, axis=0).max() > CHANGED * max(float(np.abs(v).max()), 1e-300):
            return True
    t = np.asarray(res["px"], dtype=float)
    return bool(np.abs(t - t[-1]).max() > CHANGED * max(float(np.abs(t).max()), 1e-300))


def three_kind(res, scene=None) -> str:
    """``"transient"`` if the states change, else ``"linear"`` if at most :data:`LINEAR_SLIP_FRACTION`
    of the contact slips (Kalker's linear theory applies), else ``"steady"`` (module table)."""
    res = arrays(res)
    if _changes(res):
        return "transient"
    n, _, slip = stick_fraction(res["state"][-1])
    mu = scene_of(res, scene).mu if scene_of(res, scene) is not None else 1.0
    return "linear" if mu > 0 and slip <= LINEAR_SLIP_FRACTION * max(n, 1) else "steady"


# =========================================================================== the references
def she_saturation(u):
    """Shen–Hedrick–Elkins' saturation of the linear force ``u = |F_lin|/(μF_N)``: ``|F|/(μF_N) = 1 − (1 −
    u/3)³`` for ``u ≤ 3``, else 1 (the Vermeulen–Johnson cubic with Kalker's coefficients; an
    approximation, exact in its slope 1 at 0 and its level 1 beyond ``u = 3``).

    Examples
    --------
    >>> [round(float(v), 4) for v in she_saturation([0.0, 0.3, 3.0, 5.0])]
    [0.0, 0.271, 1.0, 1.0]
    """
    u = np.minimum(np.abs(np.asarray(u, dtype=float)), 3.0)
    return 1 - (1 - u / 3) ** 3


def _linear_forces(scene, creepage):
    """Kalker's linear ``(Fx, Fy)`` of eq. 3D.8 for the creepages ``(ξ, η, φ)``, or None (no table entry:
    a/b beyond Table E.3, dissimilar bodies)."""
    e, m = scene.ellipse, scene.materials
    C = kalker_linear(e.a / e.b, m.nu)
    if C is None or m.K != 0:
        return None, C
    xi, eta, phi = (float(v) for v in creepage)
    Gc2 = m.G * e.c * e.c
    return (-Gc2 * C[0] * xi, -Gc2 * (C[1] * eta + e.c * C[2] * phi)), C


def _steady_reference(scene, res):
    """The steady state of the final loads, solved directly (the reference method, Newton), or None if it
    cannot be posed."""
    last = float(res["q"][-1]) / scene.ellipse.a
    ld = scene.load
    changes = {"load.start": "rolling", "discretization.distance": 0.0, "solver.method": REFERENCE_METHOD,
               "name": f"{scene.name}-steady"}
    for key, h in (("load.tangential", ld.tangential), ("load.lateral", ld.lateral),
                   ("load.creepage.longitudinal", ld.creepage.longitudinal),
                   ("load.creepage.lateral", ld.creepage.lateral), ("load.creepage.spin", ld.creepage.spin)):
        if h is not None:
            changes[key] = float(h(last))
    try:
        return run(scene.replace(**changes)).arrays()
    except RollqpError:          # e.g. beyond the sliding limit at the end: no steady state with stick
        return None


# =========================================================================== panels
def _unit(scene) -> str:
    """The traction unit in mathtext: ``μp0``, or ``p0`` when ``μ = 0``."""
    return r"\mu p_0" if scene.mu > 0 else "p_0"


def _centre_row(res):
    return int(np.argmin(np.abs(res["y"])))


def _row_name(res, scene) -> str:
    """``$y = 0$``, or the row of element centres nearest to it (an even number of rows has none at 0)."""
    y = float(res["y"][_centre_row(res)]) / scene.ellipse.a
    return "$y = 0$" if abs(y) < 1e-12 else f"the row nearest $y = 0$ ($y = {y:.2g}\\,a$)"


def _field_panel(ax, res, scene, k, mu_p0, title):
    """The traction vectors of state ``k`` over the grid, the stick area, the pressure contours, the
    Hertz ellipse; ``mu_p0`` the traction unit."""
    e = scene.ellipse
    to_scale = TO_SCALE[0] <= e.a / e.b <= TO_SCALE[1]
    ly = e.a if to_scale else e.b                 # not to scale: y over b, the arrows keep their screen direction
    x, y = res["x"] / e.a, res["y"] / ly
    X, Y = np.meshgrid(x, y)
    state = np.asarray(res["state"][k])
    from matplotlib.colors import ListedColormap
    ax.pcolormesh(x, y, np.where(state == 1, 1.0, np.nan), cmap=ListedColormap([STICK_AREA]), vmin=0, vmax=1,
                  shading="nearest", rasterized=True)
    levels = [0.2, 0.4, 0.6, 0.8]
    cs = ax.contour(X, Y, res["pn"][k] / e.p0, levels=levels, colors="tab:blue", linewidths=0.6)
    ax.clabel(cs, fontsize=6, fmt="%.1f")
    th = np.linspace(0, 2 * np.pi, 200)
    ax.plot(np.cos(th), e.b / ly * np.sin(th), "k-", lw=0.8)
    step = max(1, int(np.ceil(max(x.size, y.size) / ARROWS)))
    sl = (slice(step // 2, None, step), slice(step // 2, None, step))
    tx, ty, st = res["px"][k][sl] / mu_p0, res["py"][k][sl] / mu_p0, state[sl]
    big = float(np.max(np.hypot(tx, ty), initial=0.0))
    dx = step * float(x[1] - x[0]) if x.size > 1 else 1.0
    dy = step * float(y[1] - y[0]) if y.size > 1 else 1.0
    spacing = min(dx, dy) if to_scale else dx
    scale = big / (0.9 * spacing) if big > 0 else 1.0          # the longest arrow spans 0.9 of the arrows' spacing
    arrows = None
    for which, color in ((2, SLIP), (1, STICK)):
        m = st == which
        if m.any():
            arrows = ax.quiver(X[sl][m], Y[sl][m], tx[m], ty[m], color=color, angles="xy" if to_scale else "uv",
                               scale_units="xy" if to_scale else "x", scale=scale, width=0.004)
    if arrows is not None and big > 0:
        ax.quiverkey(arrows, 0.80, -0.085, big, f"{big:.3g} ${_unit(scene)}$", labelpos="E", coordinates="axes",
                     fontproperties={"size": 7})
    if to_scale:
        ax.set_aspect("equal")
    ax.set(xlabel="$x/a$", ylabel="$y/a$" if to_scale else f"$y/b$  (not to scale: $b = {e.b / e.a:.3g}\\,a$)",
           title=title)
    ax.set_xlim(x[0] - 0.5 * (x[1] - x[0]), x[-1] + 0.5 * (x[1] - x[0]))
    ax.set_ylim(y[0] - 0.5 * (y[1] - y[0]), y[-1] + 0.5 * (y[1] - y[0]))
    return _field_handles(scene)


def _hertzian(scene) -> bool:
    """Two paraboloids (eq. 3D.3); a profile's contact is not elliptic, its ellipse only a guide."""
    return bool(getattr(getattr(scene, "shape", None), "hertzian", True))


def _field_handles(scene):
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    arrow = dict(marker=r"$\rightarrow$", ls="none", ms=11)
    return ([Line2D([], [], color=STICK, **arrow), Line2D([], [], color=SLIP, **arrow),
             Patch(facecolor=STICK_AREA, edgecolor="0.6", lw=0.5),
             Line2D([], [], color="tab:blue", lw=0.6), Line2D([], [], color="k", lw=0.8)],
            ["$t$, element in stick", r"$t = -\mu p\, s/|s|$, element in slip", "stick area",
             "$p/p_0$ = 0.2, 0.4, 0.6, 0.8",
             "Hertz ellipse (3D.4)" if _hertzian(scene) else "ellipse of the equivalent curvatures (a guide)"])


def _bounds(ax, x, bound, big):
    """``±μp`` along the line; off the traction's scale (|t| far below μp0) they are named, not drawn."""
    if big > 0.2 or big == 0:
        ax.plot(x, bound, color="0.5", ls=(0, (4, 2)), lw=1, label=r"$\pm\mu p$")
        ax.plot(x, -bound, color="0.5", ls=(0, (4, 2)), lw=1)
    else:
        ax.plot([], [], color="0.5", ls=(0, (4, 2)), lw=1,
                label=rf"$\pm\mu p$ (reach $\pm 1\,\mu p_0$: off this scale, $|t| \leq {big:.2g}\,\mu p_0$)")


def _centre_panel(ax, res, scene, mu_p0, k=-1):
    """``t_x`` (stick, slip) and ``t_y`` of state ``k`` along ``y = 0`` between ``±μp``."""
    e, j0 = scene.ellipse, _centre_row(res)
    x = res["x"] / e.a
    st = res["state"][k][j0]
    tx, ty = res["px"][k][j0] / mu_p0, res["py"][k][j0] / mu_p0
    big = float(np.max(np.abs(np.concatenate([tx, ty])), initial=0.0))
    _bounds(ax, x, res["pn"][k][j0] / e.p0 * (scene.mu * e.p0 / mu_p0), big)
    ax.plot(x, tx, "-", color="0.55", lw=0.6)
    for which, color, label in ((1, STICK, "$t_x$, stick"), (2, SLIP, "$t_x$, slip")):
        m = st == which
        if m.any():
            ax.plot(x[m], tx[m], "o", ms=3.2, color=color, label=label)
    if np.abs(ty).max(initial=0.0) > NEGLIGIBLE * max(big, 1e-300):
        ax.plot(x, ty, "-s", ms=2.2, color="tab:orange", lw=1, label="$t_y$")
    ax.axhline(0, color="0.85", lw=0.6, zorder=0)
    ax.set(xlabel="$x/a$  (material enters at " + ("$x = +a$)" if scene.load.direction < 0 else "$x = -a$)"),
           ylabel=f"$t/({_unit(scene)})$", title=f"traction along {_row_name(res, scene)}, state {len(res['q']) - 1 if k == -1 else k}")


def _transient_centre_panel(ax, res, scene, mu_p0, steady):
    """``t_x`` along ``y = 0`` at several rolled distances, Cattaneo's (eq. 3D.6) at the start, the steady
    state at the end, between ``±μp``."""
    e, j0 = scene.ellipse, _centre_row(res)
    x = res["x"] / e.a
    q = np.asarray(res["q"], dtype=float) / e.a
    wanted = [w for w in (0.0, 0.5, 1.0, 2.0) if w < q[-1]] + [q[-1]]
    ks = sorted({int(np.argmin(np.abs(q - w))) for w in wanted})
    for c, k in zip(colors(len(ks)), ks):
        ax.plot(x, res["px"][k][j0] / mu_p0, "-o", ms=2.5, lw=0.9, color=c, label=f"$q = {q[k]:.2f}\\,a$")
    tmax = float(np.abs(res["px"][:, j0]).max()) / mu_p0
    _bounds(ax, x, res["pn"][-1][j0] / e.p0 * (scene.mu * e.p0 / mu_p0), tmax)
    xf = np.linspace(-1, 1, 401)
    ref = _cattaneo_ratio(res, scene)
    if ref is not None:
        ax.plot(xf, np.sign(float(res["Fx"][0])) * cattaneo_traction(np.abs(xf) * e.a, e.a, e.p0, scene.mu, ref)
                / mu_p0, **{**REFERENCES["cattaneo"], "label": "Cattaneo–Mindlin (3D.6), start"})
    if steady is not None:
        ax.plot(res["x"] / e.a, steady["px"][0][j0] / mu_p0, **STEADY, label="steady state (solved directly)")
    ax.set(xlabel="$x/a$  (material enters at " + ("$x = +a$)" if scene.load.direction < 0 else "$x = -a$)"),
           ylabel=f"$t_x/({_unit(scene)})$", title=f"traction along {_row_name(res, scene)} while rolling")


def _cattaneo_ratio(res, scene):
    """``Q/(μF_N)`` of a braked start that Cattaneo–Mindlin describes (a circle of similar bodies shifted
    along x only), else None."""
    e, m = scene.ellipse, scene.materials
    if scene.load.start != "braked" or scene.mu == 0 or abs(e.a / e.b - 1) > 1e-9 or m.K != 0:
        return None
    if abs(float(res["Fy"][0])) > 1e-12 * scene.load.normal or float(res["creepage"][0][2]) != 0:
        return None
    r = abs(float(res["Fx"][0])) / (scene.mu * float(res["FN"][0]))
    return r if 0 < r < 1 else None


def _pressure_panel(ax, res, scene):
    e = scene.ellipse
    j0, i0 = _centre_row(res), int(np.argmin(np.abs(res["x"])))
    s = np.linspace(-1, 1, 201)
    ax.plot(res["x"] / e.a, res["pn"][0][j0] / e.p0, "o", ms=3.2, color="tab:blue", label="$p/p_0$ along $x$ ($y = 0$)")
    ax.plot(res["y"] / e.b, res["pn"][0][:, i0] / e.p0, "s", ms=5, mfc="none", color="tab:green",
            label="$p/p_0$ along $y$ ($x = 0$), against $y/b$")
    hz = _hertzian(scene)
    ax.plot(s, np.sqrt(1 - s * s), **{**REFERENCES["hertz"], "label": "Hertz (3D.4)" if hz else
                                      "Hertz of the equivalent curvatures (a guide: the patch is not elliptic)"})
    ax.set(xlabel="$x/a$, $y/b$", ylabel="$p/p_0$",
           title="pressure, state 0, against Hertz" if hz else "pressure of the patch, state 0")
    u = unit_names(getattr(scene, "units", ""))
    value_axis(ax, e.p0, f"$p$ [{u.stress}]")


def creep_force_panel(ax, res, scene, k=-1):
    """The creep force of state ``k`` on Kalker's axes: ``|F|/(μF_N)`` against ``u = |F_lin|/(μF_N)``, the
    linear force of its creepages (eq. 3D.8); Kalker's linear theory is the diagonal, full sliding the
    level 1, Shen–Hedrick–Elkins' cubic (:func:`she_saturation`) between them."""
    mu, FN = scene.mu, float(res["FN"][k])
    ax.set(xlabel=r"$|F_{\rm lin}|/(\mu F_N)$, Kalker's linear force of the creepages (3D.8)",
           ylabel=r"$|F|/(\mu F_N)$", title="creep force against Kalker's linear theory")
    if mu == 0:
        ax.text(0.5, 0.5, r"$\mu = 0$: no creep force", transform=ax.transAxes, ha="center")
        return
    lin, C = _linear_forces(scene, res["creepage"][k])
    F = float(np.hypot(res["Fx"][k], res["Fy"][k])) / (mu * FN)
    if lin is None:
        why = "dissimilar bodies" if scene.materials.K != 0 else "a/b beyond Kalker's Table E.3"
        ax.axhline(1, **SATURATION, label=r"full sliding, $|F| = \mu F_N$")
        ax.axhline(F, color="k", lw=1, label=f"rollqp: $|F| = {F:.4g}\\,\\mu F_N$ (no linear theory: {why})")
        ax.set_ylim(0, 1.1)
        return
    u = float(np.hypot(*lin)) / (mu * FN)
    top = max(3.3, 1.15 * u) if u > 0.15 else 1.5 * max(u, 1e-300)
    s = np.linspace(0, top, 400)
    ax.plot(s, s, **KALKER, label=("" if _hertzian(scene) else "equivalent ellipse's ")
            + f"Kalker's linear theory (3D.8): $C_{{11}}, C_{{22}}, C_{{23}}$ = "
                                  f"{C[0]:.3g}, {C[1]:.3g}, {C[2]:.3g}")
    if top > 1:
        ax.axhline(1, **SATURATION, label=r"full sliding, $|F| = \mu F_N$")
    ax.plot(s, she_saturation(s), **SHE, label=r"Shen–Hedrick–Elkins, $1 - (1 - u/3)^3$ (approximate)")
    dev = 100 * (F / u - 1) if u > 0 else 0.0
    ax.plot([u], [F], "o", ms=7, color="k", zorder=5,
            label=f"rollqp, state {len(res['q']) - 1 if k == -1 else k}: $|F| = {F:.4g}\\,\\mu F_N$ "
                  f"({dev:+.2f} % of linear" + (": discretization, first order, validation3d.md §3)"
                                                if abs(dev) < 3 else ")"))
    ax.set_xlim(0, top)
    ax.set_ylim(0, max(1.1, 1.05 * top) if top > 1 else top)


def _creepage_panel(ax, res, scene, steady):
    """ξ, η (and φ·a) of the rolling states against q/a, with the steady state's."""
    e = scene.ellipse
    q = np.asarray(res["q"], dtype=float) / e.a
    k0 = 1 if scene.load.start == "braked" else 0         # state 0 of a braked start is a shift: no creepage
    cr = np.asarray(res["creepage"], dtype=float)
    for i, (name, color) in enumerate(((r"\xi", "tab:blue"), (r"\eta", "tab:green"))):
        if i == 0 or np.abs(cr[:, i]).max() > NEGLIGIBLE * np.abs(cr[:, :2]).max():
            ax.plot(q[k0:], cr[k0:, i] * 1e3, "-o", ms=2.2, lw=1, color=color, label=f"${name}$")
            if steady is not None:
                ax.axhline(float(steady["creepage"][0][i]) * 1e3, **{**STEADY, "color": color},
                           label=f"${name}$, steady state")
    ax.set(xlabel="$q/a$", ylabel=r"creepage $\times 10^3$",
           title="creepages while rolling" + ("\n(state 0 is a static shift: no creepage)" if k0 else ""))


# =========================================================================== the figures
def field_figure(res, scene=None, path: str | None = None, k: int = -1, title: str | None = None):
    """The traction field of state ``k`` alone (the first panel of :func:`three_figure`), with its legend.

    Examples
    --------
    >>> from rollqp import load_scene
    >>> from rollqp.march.grid import run
    >>> s = load_scene("kalker-elliptic").replace(**{"discretization.elements": [18, 36]})
    >>> fig = field_figure(run(s).arrays(), s)
    >>> [t.get_text() for t in fig.axes[0].get_legend().get_texts()][2:]
    ['stick area', '$p/p_0$ = 0.2, 0.4, 0.6, 0.8', 'Hertz ellipse (3D.4)']
    """
    plt = pyplot()
    res = arrays(res)
    scene = scene_of(res, scene)
    e, mu = scene.ellipse, scene.mu
    K = len(res["q"]) - 1 if k == -1 else k
    fig, ax = plt.subplots(figsize=(6.6, 8.2) if e.a / e.b < 0.8 else (7.5, 7.5), constrained_layout=True)
    handles = _field_panel(ax, res, scene, K, (mu if mu > 0 else 1.0) * e.p0,
                           title or f"traction $t/({_unit(scene)})$, state {K}")
    legend_below(ax, ncol=2, handles=handles[0], labels=handles[1])
    return finish(fig, path)


def three_figure(res, scene=None, path: str | None = None, title: str | None = None):
    """The 3D run's figure of its :func:`three_kind` (module docstring)."""
    plt = pyplot()
    res = arrays(res)
    scene = scene_of(res, scene)
    kind = three_kind(res, scene)
    e, mu = scene.ellipse, scene.mu
    mu_p0 = (mu if mu > 0 else 1.0) * e.p0
    tu = _unit(scene)
    K = len(res["q"]) - 1
    q_end = float(res["q"][-1]) / e.a
    if kind == "transient":
        fig, ax = plt.subplots(2, 3, figsize=(18, 11.5), constrained_layout=True)
        steady = _steady_reference(scene, res)
        handles = _field_panel(ax[0, 0], res, scene, K, mu_p0, f"traction $t/({tu})$, state {K} ($q = {q_end:.3g}\\,a$)")
        legend_below(ax[0, 0], ncol=2, handles=handles[0], labels=handles[1])
        title0 = f"traction $t/({tu})$, state 0 ($q = 0$)"
        h0 = _field_panel(ax[1, 0], res, scene, 0, mu_p0, title0)
        r = _cattaneo_ratio(res, scene)
        if r is not None:
            c = cattaneo_stick_radius(e.a, r) / e.a
            th = np.linspace(0, 2 * np.pi, 200)
            ax[1, 0].plot(c * np.cos(th), c * np.sin(th), **{**REFERENCES["cattaneo"], "lw": 1.5})
            h0 = (h0[0] + [ax[1, 0].lines[-1]], h0[1] + [f"Cattaneo–Mindlin stick circle (3D.6), $c/a = {c:.3f}$"])
        legend_below(ax[1, 0], ncol=2, handles=h0[0], labels=h0[1])
        _transient_centre_panel(ax[0, 1], res, scene, mu_p0, steady)
        legend_below(ax[0, 1], ncol=2)
        _pressure_panel(ax[0, 2], res, scene)
        legend_below(ax[0, 2], ncol=1)
        _creepage_panel(ax[1, 1], res, scene, steady)
        legend_below(ax[1, 1], ncol=2)
        creep_force_panel(ax[1, 2], res, scene)
        legend_below(ax[1, 2], ncol=1)
    else:
        fig, ax = plt.subplots(2, 2, figsize=(14, 11.5), constrained_layout=True)
        handles = _field_panel(ax[0, 0], res, scene, K, mu_p0,
                               f"traction $t/({tu})$, steady state" + (f" (state {K})" if K else ""))
        legend_below(ax[0, 0], ncol=2, handles=handles[0], labels=handles[1])
        _centre_panel(ax[0, 1], res, scene, mu_p0)
        legend_below(ax[0, 1], ncol=3)
        _pressure_panel(ax[1, 0], res, scene)
        legend_below(ax[1, 0], ncol=1)
        creep_force_panel(ax[1, 1], res, scene)
        legend_below(ax[1, 1], ncol=1)
    cr = np.asarray(res["creepage"][-1], dtype=float)
    cr[:2] = np.where(np.abs(cr[:2]) > NEGLIGIBLE * np.abs(cr[:2]).max(), cr[:2], 0.0)     # round-off shown as 0
    xi, eta, phi = (float(v) for v in cr)
    cap = mu * float(res["FN"][-1])
    forces = (f",\\ F_x = {float(res['Fx'][-1]) / cap:+.3f}\\,\\mu F_N,\\ F_y = {float(res['Fy'][-1]) / cap:+.3f}\\,"
              f"\\mu F_N" if cap > 0 else "")
    method = meta(res).get("method", "")
    about = {"linear": "Kalker's linear theory", "steady": "a point of the creep curve",
             "transient": "a transient"}[kind]
    fig.suptitle(title or (f"{scene.name}: {scene.description}  —  {about}\n"
                           f"$a/b = {e.a / e.b:.3g},\\ \\mu = {mu:g},\\ \\xi = {xi:.4g},\\ \\eta = {eta:.4g},\\ "
                           f"\\phi = {phi:.4g}$ /length{f'${forces}$' if forces else ''}"
                           + (f"   [{method}]" if method else "")), fontsize=10)
    return finish(fig, path)
