"""What every figure of :mod:`rollqp.plot` shares: matplotlib, labels, colours, scales, legends, the scene.

* Labels are mathtext (``$t/(\\mu p_0)$``), the same symbols as docs/formulation.md.
* Snapshots (states at several rolled distances) run from light to dark viridis; closed-form
  references each have a colour of their own (:data:`REFERENCES`) outside viridis, so Cattaneo,
  Carter, Mindlin and Bentall–Johnson never look alike, nor like a state.
* Nondimensional axes (x/a_H, p/p0, …) carry a second, dimensional scale (mm, MPa, …) in the
  units the scene declares (:mod:`rollqp.units`; "length units" when it declares none).
* Legends sit below their panel, never over the data.
"""
from __future__ import annotations

import json

import numpy as np

from ..errors import MissingBackendError
from ..scene import scene_from_dict
from ..units import unit_names


def pyplot():
    """``matplotlib.pyplot`` with the non-interactive Agg backend; a one-line error naming the extra if absent."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise MissingBackendError("--plot needs matplotlib: pip install 'rollqp[plot]'") from exc
    return plt


#: Axis labels (mathtext), by quantity.
LABELS = {"x": r"$x/a_H$", "q": r"$q/a_H$", "tau": r"$\tau/a_H$", "p": r"$p/p_0$", "t": r"$t/(\mu p_0)$",
          "s": r"$s\,R/a_H$", "xi": r"$\xi\,R/a_H$", "Q": r"$Q/(\mu P)$", "P": r"$P/\bar P$"}

#: Closed-form references: one colour and line style each (none of them in viridis).
REFERENCES = {
    "hertz": dict(color="0.45", ls="--", lw=1.0, label="Hertz"),
    "cattaneo": dict(color="#d62728", ls="--", lw=1.2, label="Cattaneo (start)"),
    "carter": dict(color="#ff7f0e", ls="-.", lw=1.4, label="Carter (steady)"),
    "carter_back": dict(color="#e377c2", ls="-.", lw=1.4, label="Carter, rolling back"),
    "mindlin": dict(color="#d62728", ls="-", lw=1.0, label="Mindlin–Deresiewicz"),
    "bentall": dict(color="#8c564b", ls="--", lw=1.2, label=r"Bentall–Johnson, $\mu\to 0$"),
}

#: Node states (``Result`` key ``state``) and how they are drawn.
STATE_NAMES = {0: "separation", 1: "stick", 2: "slip"}
STATE_COLORS = {0: "#d9d9d9", 1: "#2c7bb6", 2: "#d7191c"}


def symbol(name: str) -> str:
    """The mathtext symbol of a clock or quantity name (``"tau"`` → ``\\tau``)."""
    return {"tau": r"\tau", "q": "q", "xi": r"\xi", "mu": r"\mu"}.get(name, name)


def colors(m):
    """Snapshot colours from light (first state) to dark (last): the final state, usually the
    one read, gets viridis' darkest end rather than its near-invisible yellow."""
    return pyplot().cm.viridis(np.linspace(0.78, 0.0, max(m, 1)))


def reference(ax, x, y, key, **kw):
    """Draw the closed form ``key`` of :data:`REFERENCES` (``kw`` overrides its style)."""
    return ax.plot(x, y, **{**REFERENCES[key], **kw})


def legend_below(ax, ncol: int | None = None, fontsize: float = 7, **kw):
    """The panel's legend under its x-axis label, outside the data (nothing if there is nothing to name)."""
    handles, labels = kw.pop("handles", None), kw.pop("labels", None)
    if handles is None:
        handles, labels = ax.get_legend_handles_labels()
    if not handles:
        return None
    ncol = ncol or min(len(handles), 3)
    return ax.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=ncol, fontsize=fontsize,
                     frameon=False, handlelength=2.2, columnspacing=1.2, **kw)


def finish(fig, path):
    """Save and close (returning ``path``), or return the figure when ``path`` is None."""
    if path is None:
        return fig
    fig.savefig(path, dpi=120)
    pyplot().close(fig)
    return path


# --------------------------------------------------------------------------- the scene behind a result
def arrays(res) -> dict:
    """The result's arrays from ``Result``, ``Result.arrays()`` or :func:`load_result`."""
    return res.arrays() if hasattr(res, "arrays") and callable(res.arrays) else res


def meta(res) -> dict:
    m = res.get("meta", {})
    if isinstance(m, dict):
        return m
    try:
        return json.loads(str(m))
    except ValueError:  # pragma: no cover - a result file always has JSON meta
        return {}


def scene_of(res, scene=None):
    """The scene of a result: the one given, or the one stored in its ``meta`` (None if it has none)."""
    if scene is not None:
        return scene
    sd = meta(res).get("scene")
    if not sd:
        return None
    try:
        return scene_from_dict(sd)
    except Exception:  # noqa: BLE001 - a result of an older or foreign scene: figures from meta alone
        return None


class Info:
    """What the figures need of the scene: from the scene if given, else from ``meta``."""

    def __init__(self, res: dict, scene=None):
        m = meta(res)
        sd = m.get("scene", {})
        if scene is not None:
            self.mu = float(scene.contact.mu)
            self.name, self.description = scene.name, scene.description
            self.start, self.direction = scene.load.start, int(scene.load.direction)
            self.normal = float(scene.load.normal)
            self.coupling = scene.coupling_level
            self.units = getattr(scene, "units", "")
        else:
            fr = sd.get("contact", {}).get("friction", 1.0)
            self.mu = float(fr) if not isinstance(fr, dict) else float(fr.get("mu", fr.get("static", max(fr.get("values", [1.0])))))
            self.name, self.description = sd.get("name", "result"), sd.get("description", "")
            self.start = sd.get("load", {}).get("start", "braked")
            self.direction = int(sd.get("load", {}).get("direction", -int(res.get("leading_edge", 1))))
            self.normal = float(sd.get("load", {}).get("normal", res["P"][0]))
            self.coupling = m.get("coupling", "?")
            self.units = sd.get("units", "")
        self.method = m.get("method", "")
        self.a = float(res["a_H"])
        self.p0 = float(res["p0"])
        self.R = float(res["R"])
        self.beta = float(res["beta"])
        self.kappa = 2.0 * self.beta
        self.mu_scale = self.mu if self.mu > 0 else 1.0
        self.u = unit_names(self.units)
        # step 0 of a braked start carries static-shift slip, not rolling slip
        self.static_start = self.start == "braked"

    def title(self, title=None, extra=""):
        """The figure's title: the scene's name and description, its parameters and the method."""
        if title:
            return title
        import textwrap
        tail = (f"  [2β = {self.kappa:.4g}, μ = {self.mu:g}, a_H = {self.a:.4g} {self.u.length}, "
                f"p0 = {self.p0:.4g} {self.u.stress}" + (f", {self.method}" if self.method else "") + "]")
        return "\n".join(textwrap.wrap(f"{self.name}: {self.description}{extra}{tail}", 160))


# --------------------------------------------------------------------------- dimensional scales
def length_axis(ax, info, where="top", label="x"):
    """A second x-scale in the scene's length unit (``where="top"``) beside x/a_H (or q/a_H)."""
    a = info.a
    sec = ax.secondary_xaxis(where, functions=(lambda v: v * a, lambda v: v / a))
    sec.set_xlabel(f"${label}$ [{info.u.length}]", fontsize=8)
    sec.tick_params(labelsize=7)
    return sec


def value_axis(ax, factor: float, label: str):
    """A second y-scale on the right: the panel's nondimensional value times ``factor`` (e.g. p0 in MPa)."""
    sec = ax.secondary_yaxis("right", functions=(lambda v: v * factor, lambda v: v / factor))
    sec.set_ylabel(label, fontsize=8)
    sec.tick_params(labelsize=7)
    return sec


def stress_axis(ax, info, per_mu: bool = False):
    """Right scale of a p/p0 (or t/(μp0), ``per_mu``) panel in the scene's stress unit."""
    f = info.p0 * (info.mu_scale if per_mu else 1.0)
    return value_axis(ax, f, f"${'t' if per_mu else 'p'}$ [{info.u.stress}]")


def clock(res, a):
    """``(values/a_H, name)``: the time-like τ of a load path (``time``), else the rolled distance q."""
    if "time" in res:
        return np.asarray(res["time"], dtype=float) / a, "tau"
    return np.asarray(res["q"], dtype=float) / a, "q"


def rolling_mask(res, steady_start: bool = False) -> np.ndarray:
    """Which stored states were reached by rolling: not a stop's or a load change's static steps, and not
    the starting state unless it is a steady rolling state (``steady_start``, ``load.start = "rolling"``)."""
    K = len(res["q"])
    m = np.asarray(res["direction"]) != 0 if "direction" in res else np.ones(K, dtype=bool)
    m[0] = steady_start
    return m
