"""The steady creep curve as a sweep preset: Q/(μP) against the creepage ξ, with its closed forms.

Each point is the scene in steady rolling at a prescribed load ratio Q/(μP̄) (``load.start =
"rolling"``, ``discretization.distance = 0``: the starting state alone). A method that solves
``"steady"`` (``newton``, ``nt-newton``) solves the steady problem directly; the QP methods
reach it by marching at constant loads (:mod:`rollqp.march`). The creepage ξ is the result's
``creepage`` of state 0. Overlays (docs/formulation.md §12):

* similar bodies (β = 0): Carter's law, ``ξ_C = −sgn(r)(μa/R)(1 − √(1 − |r|))``
  (:func:`rollqp.closedforms.carter_creepage`), and its inverse, the creep-force law
  ``Q/(μP) = −sgn(ξ)[1 − (1 − |ξ|R/(μa))²]`` (:func:`~rollqp.closedforms.creep_force_ratio`),
  whose slope is ``dQ/dξ = −2PR(1 − |ξ|R/(μa))/a`` (``−πaE*/2`` at ξ = 0);
* dissimilar bodies (β ≠ 0): the free-rolling creepage of Bentall and Johnson's μ → 0 limit,
  ``|ξ| = 0.457·|2β|·a/R`` at Q = 0 (:func:`~rollqp.closedforms.bentall_johnson_creepage`).

``dQ/dξ`` of the computed curve is its finite-difference slope (second order on the given
ratios, :func:`numpy.gradient`), reported beside Carter's.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import sweep
from .. import closedforms as cf
from ..errors import InputError
from ..plot import pyplot
from ..scene import load_scene
from .spec import Axis, describe, parse_values

__all__ = ["CreepCurve", "creep_curve", "creep_sweep"]


def _numbers(values, arg: str, what: str, ok) -> tuple:
    """``values`` (a ``VALUES`` string or a sequence of numbers) as floats with ``ok(v)``, else an
    InputError naming ``arg`` and the allowed range ``what``."""
    values = parse_values(values, None, arg) if isinstance(values, str) else tuple(values)
    try:
        out = tuple(float(v) for v in values if not isinstance(v, (str, bool)))
    except (TypeError, ValueError, OverflowError):
        out = ()
    if not out or len(out) != len(values) or not all(ok(v) for v in out):
        shown = ", ".join(describe(v, 20) for v in values[:6])
        raise InputError(arg, f"{what}, got {shown}{', …' if len(values) > 6 else ''}")
    return out


def _ratios(text) -> tuple:
    return _numbers(text, "--ratios", "load ratios Q/(mu P) must be numbers in (-1, 1)", lambda v: -1.0 < v < 1.0)


def _frictions(text, scene) -> tuple:
    if text is None:
        return (scene.contact.friction,)
    return _numbers(text, "--friction", "friction coefficients must be finite numbers > 0",
                    lambda v: 0.0 < v < float("inf"))


def creep_sweep(scene, ratios="0.05:0.95:19", friction=None):
    """``(steady base scene, axes)`` of the creep-curve sweep (validated by :func:`~.spec.build_sweep`)."""
    scene = load_scene(scene) if not hasattr(scene, "replace") else scene
    r, mu = _ratios(ratios), _frictions(friction, scene)
    base = scene.replace(**{"load.start": "rolling", "discretization.distance": 0.0, "load.tangential": r[0],
                            "contact.friction": mu[0]})
    return base, (Axis("contact.friction", mu), Axis("load.tangential", r))


def _fmt(value, spec: str, defined: bool) -> str:
    """``value`` formatted, or ``—`` where it is undefined or not finite."""
    return format(value, spec) if defined and np.isfinite(value) else "—"


@dataclass
class CreepCurve:
    """The computed curve (arrays over ``(friction, ratio)``) and its closed-form overlays."""

    scene: object
    mu: np.ndarray
    ratio: np.ndarray          # Q/(μP) of the solution (the prescribed ratio, to round-off)
    xi: np.ndarray             # computed creepage (NaN where a point failed)
    P: np.ndarray
    summary: object = None
    prescribed: tuple = None   # the ratios asked for (--ratios)

    @property
    def similar(self) -> bool:
        return self.scene.beta == 0.0

    def carter_xi(self) -> np.ndarray:
        """Carter's creepage at each computed ratio (similar bodies)."""
        s = self.scene
        return np.array([[cf.carter_creepage(s.a_H, s.R, m, r) if np.isfinite(r) else np.nan for r in row]
                         for m, row in zip(self.mu, self.ratio)])

    def slope(self) -> np.ndarray:
        """dQ/dξ of the computed curve (force/length per unit creepage), by finite differences.

        NaN where it is undefined: a curve of one computed point, a failed neighbour, or two
        neighbours at the same creepage.
        """
        Q = self.ratio * self.mu[:, None] * self.P
        out = np.full(Q.shape, np.nan)
        for i, (q, x) in enumerate(zip(Q, self.xi)):
            ok = np.isfinite(q) & np.isfinite(x)
            if ok.sum() > 1:
                with np.errstate(all="ignore"):
                    out[i, ok] = np.gradient(q[ok], x[ok])
        return np.where(np.isfinite(out), out, np.nan)

    def carter_slope(self) -> np.ndarray:
        """Carter's ``dQ/dξ = −2PR(1 − |ξ|R/(μa))/a`` at the computed creepages."""
        s = self.scene
        u = np.abs(self.xi) * s.R / (self.mu[:, None] * s.a_H)
        return -2.0 * self.P * s.R * (1.0 - np.minimum(u, 1.0)) / s.a_H

    def bentall_johnson_xi(self) -> float:
        """The signed μ → 0 free-rolling creepage, ``sgn ξ = d·sgn κ`` (dissimilar bodies)."""
        s = self.scene
        return s.load.direction * np.sign(s.beta) * cf.bentall_johnson_creepage(2.0 * s.beta, s.a_H, s.R)

    def table(self) -> str:
        """Markdown table: ratio, ξ, the closed form, relative error, dQ/dξ and Carter's.

        A value that is undefined is shown as ``—`` (never ``nan``): the relative error where
        Carter's ξ is 0 (Q = 0), the slope of a curve of one point or beside a failed point;
        a failed point's row says ``failed``. A note under the table says which.
        """
        rows, notes = [], set()
        slope = self.slope()
        with np.errstate(all="ignore"):
            xc = self.carter_xi() if self.similar else None
            rel = self.xi / xc - 1.0 if self.similar else None
        if self.similar:
            sc = self.carter_slope()
            rows += ["| μ | Q/(μP) | ξ | ξ_Carter | ξ/ξ_Carter − 1 | dQ/dξ | dQ/dξ Carter |", "|---|---|---|---|---|---|---|"]
        else:
            rows += [f"Bentall–Johnson limit (μ → 0, Q = 0): ξ = {self.bentall_johnson_xi():.5e}\n",
                     "| μ | Q/(μP) | ξ | dQ/dξ |", "|---|---|---|---|"]
        for i, m in enumerate(self.mu):
            for j, r in enumerate(self._prescribed()):
                if not np.isfinite(self.xi[i, j]):
                    rows.append(f"| {m:g} | {r:.4f} | failed |" + " |" * (4 if self.similar else 1))
                    notes.add("failed: the point's error is in the summary below and in the store")
                    continue
                cells = [f"{m:g}", f"{self.ratio[i, j]:.4f}", f"{self.xi[i, j]:.5e}"]
                if self.similar:
                    cells += [f"{xc[i, j] + 0.0:.5e}", _fmt(rel[i, j], "+.3e", xc[i, j] != 0.0)]
                    notes.update(["—: undefined where Carter's ξ is 0 (Q = 0)"] if xc[i, j] == 0.0 else [])
                cells.append(_fmt(slope[i, j], ".4e", True))
                notes.update(["—: no slope (one point, a failed neighbour or equal creepages)"]
                             if not np.isfinite(slope[i, j]) else [])
                cells += [f"{sc[i, j]:.4e}"] if self.similar else []
                rows.append("| " + " | ".join(cells) + " |")
        return "\n".join(rows + ([""] if notes else []) + sorted(notes))

    def _prescribed(self) -> np.ndarray:
        return self.ratio[0] if self.prescribed is None else np.asarray(self.prescribed)

    def plot(self, path) -> str:
        """The classic creep-force figure: Q/(μP) against ξ (left) and against ξR/(μa) (right)."""
        plt = pyplot()
        s = self.scene
        fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 4.2))
        for i, m in enumerate(self.mu):
            line, = ax.plot(-self.xi[i], self.ratio[i], "o", ms=4, label=f"rollqp, μ = {m:g}")
            bx.plot(-self.xi[i] * s.R / (m * s.a_H), self.ratio[i], "o", ms=4, color=line.get_color())
            if self.similar:
                u = np.linspace(0.0, 1.2, 200)
                ax.plot(u * m * s.a_H / s.R, cf.creep_force_ratio(-u * m * s.a_H / s.R, s.a_H, s.R, m), "-",
                        color=line.get_color(), lw=1)
        if self.similar:
            u = np.linspace(0.0, 1.2, 200)
            bx.plot(u, cf.creep_force_ratio(-u, 1.0, 1.0, 1.0), "k-", lw=1, label="Carter")
            bx.plot(u[u < 0.5], 2 * u[u < 0.5], "k:", lw=1, label="linear: dQ/dξ = −πaE*/2")
            ax.plot([], [], "k-", lw=1, label="Carter")
        else:
            xb = -self.bentall_johnson_xi()
            ax.axvline(xb, color="k", ls="--", lw=1, label="Bentall–Johnson, μ → 0, Q = 0")
            bx.axhline(0.0, color="k", lw=0.5)
        ax.ticklabel_format(axis="x", style="sci", scilimits=(0, 0))
        ax.set_xlabel("−ξ (creepage of A, sign of Q opposite)")
        ax.set_ylabel("Q/(μP)")
        bx.set_xlabel("−ξR/(μa)")
        bx.set_ylabel("Q/(μP)")
        for a in (ax, bx):
            a.axhline(1.0, color="0.6", lw=0.5)
            if a.get_legend_handles_labels()[0]:
                a.legend(fontsize=8, loc="lower right")
            a.grid(alpha=0.3)
        fig.suptitle(f"Steady creep curve of {s.name} ({s.discretization.elements} {s.discretization.element} elements)")
        fig.tight_layout()
        fig.savefig(path, dpi=110)
        plt.close(fig)
        return path


def creep_curve(scene, ratios="0.05:0.95:19", friction=None, out="creep.zarr", **run) -> CreepCurve:
    """Run the creep-curve sweep into the store ``out`` (``run``: :func:`rollqp.sweep.sweep`'s
    ``scheduler``, ``workers``, ``client``, ``quiet``) and read the curve back.

    The store is read with zarr (the four arrays the curve needs, state 0): xarray and pandas
    are not imported by the command.
    """
    import zarr

    base, axes = creep_sweep(scene, ratios, friction)
    summary = sweep(base, axes, out, **run)
    group = zarr.open_group(str(out), mode="r")
    done = np.asarray(group["status"][...]) == 1
    P, Q, xi = (np.where(done, np.asarray(group[name][..., 0], dtype=float), np.nan) for name in ("P", "Q", "creepage"))
    mu = np.asarray(group["contact.friction"][...], dtype=float)
    with np.errstate(all="ignore"):  # a failed point's NaN stays NaN
        ratio = Q / (mu[:, None] * P)
    return CreepCurve(base, mu, ratio, xi, P, summary, axes[1].values)
