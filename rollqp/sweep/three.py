r"""Sweeps and creep-force curves of 3D scenes (docs/sweeps.md, "Three dimensions").

``rollqp sweep`` over any key of a 3D scene runs every point of the product of the ``--vary`` axes (each
point validated before any work, one bad point an error naming it) on the same dask cluster as 2D
(:func:`rollqp.sweep.executor.map_jobs`) and writes one labelled xarray Dataset into a zarr store: the
swept keys are dimensions (their values the coordinates), ``step`` (the state index), ``y`` and ``x``
(the element centres, coordinates) the others; every array of the 3D result file is a variable
(``creepage`` has the extra dimension ``component`` = longitudinal, lateral, spin), with the per-point
``status`` (1 done, 2 failed), ``error`` and ``point_time``. Points with fewer states or another grid are
padded with NaN (their own ``q``, ``x``, ``y`` then per point).

The store is resumable as a 2D one is: while the sweep runs, each point is saved as it finishes
(``POINTS/<i>.npz`` inside the store folder, written atomically, with ``MANIFEST`` naming the sweep by its
fingerprint: the base scene and the swept values); the labelled Dataset replaces them when every point is
done. A sweep that was killed (SIGKILL, Ctrl-C, SIGTERM) and is run again with the same scene and ``--vary``
computes only the points not saved and writes the same Dataset (but for the points' wall times); a store
of another sweep, or a folder that is no 3D sweep store, is refused naming ``--out``; a finished store of
the same sweep is opened and nothing is computed. A sweep with failed points keeps its saved points and
manifest beside the Dataset: the same command again tries the failed points only, as a 2D sweep does.

``rollqp creep-curve SCENE --creepage longitudinal|lateral|spin --values V`` is the preset of the steady
creep-force curve: the scene in steady rolling (``load.start = "rolling"``, ``distance = 0``) at each
prescribed creepage (the others as the scene gives them; a force along the swept axis is replaced by
the creepage), the forces ``Fx``, ``Fy`` and the spin moment ``Mz`` against it, with the closed forms
(:class:`CreepCurve3D`):

* **Kalker's linear theory** at the origin (docs/theory3d.md): ``Fx = −G c² C11 ξ``,
  ``Fy = −G c² (C22 η + c C23 φ)`` (:func:`rollqp.closedforms.kalker.kalker_linear`, ``c = √(ab)``);
* **saturation**: ``|F| → μ FN`` at large creepage;
* ``dF/dξ`` of the computed curve by finite differences (second order on the values,
  :func:`numpy.gradient`), beside Kalker's slope.
"""
from __future__ import annotations

import hashlib
import itertools
import json
import math
import os
import re
import shutil
import time
from dataclasses import dataclass, field

import numpy as np

from ..atomic import OutputLock, written
from ..closedforms.kalker import kalker_linear
from ..errors import InputError, RollqpError
from ..fields import registry
from ..march.grid import run
from ..plot import pyplot
from ..scene import load_scene, scene_from_dict
from ..threads import limited
from .executor import close_client, connect, iter_jobs
from .spec import Axis, MAX_POINTS, parse_values, parse_vary

__all__ = ["sweep_3d", "run_point_3d", "creep_curve_3d", "CreepCurve3D", "CREEPAGES", "Summary3D"]

#: ``--creepage`` names and the scene keys they sweep (and the force key they replace).
CREEPAGES = {"longitudinal": ("load.creepage.longitudinal", "load.tangential", "Fx"),
             "lateral": ("load.creepage.lateral", "load.lateral", "Fy"),
             "spin": ("load.creepage.spin", None, "Fy")}
COMPONENTS = ("longitudinal", "lateral", "spin")
#: Inside a 3D store being computed: the sweep's fingerprint (JSON) and the folder of the points done.
MANIFEST, POINTS = "rollqp-sweep3d.json", "points"
#: The Dataset's global attribute holding the sweep's fingerprint (the 2D stores' name).
FINGERPRINT = "rollqp_sweep_fingerprint"


def run_point_3d(scene: dict) -> dict:
    """One 3D point on a worker: ``{"arrays", "time"}`` or ``{"error", "time"}`` (its one-line error)."""
    t0 = time.perf_counter()
    try:
        with limited(1):
            arrays = run(scene_from_dict(scene)).arrays()
    except Exception as err:  # noqa: BLE001  (an input the method cannot run: one line, the sweep goes on)
        return {"error": f"{type(err).__name__}: {err}".splitlines()[0][:200], "time": time.perf_counter() - t0}
    arrays.pop("meta", None)
    return {"arrays": arrays, "time": time.perf_counter() - t0}


@dataclass
class Summary3D:
    """What a 3D sweep did: points, failures (index, error), wall time, the points' own times."""

    total: int
    done: int = 0
    failed: list = field(default_factory=list)
    wall: float = 0.0
    point_times: list = field(default_factory=list)
    interrupted: bool = False
    kept: int = 0

    def table(self) -> str:
        busy = sum(self.point_times)
        rows = [f"  points        {self.done} done, {len(self.failed)} failed of {self.total}"
                + (f" ({self.kept} kept from the store, not recomputed)" if self.kept else "")
                + (" (interrupted: run the same command again to compute the rest)" if self.interrupted else ""),
                f"  wall time     {self.wall:.2f} s (points' own {busy:.2f} s: {busy / max(self.wall, 1e-9):.2f}x)"]
        rows += [f"  failed        point {i}: {e}" for i, e in self.failed[:5]]
        return "\n".join(rows)


def _points(base, axes):
    """Every point's scene dict, validated (one bad point: an InputError naming it)."""
    out = []
    for i, values in enumerate(itertools.product(*(a.values for a in axes))):
        changes = dict(zip((a.key for a in axes), values))
        try:
            out.append(base.replace(**changes).to_dict())
        except RollqpError as err:
            label = ", ".join(f"{k}={v}" for k, v in changes.items())[:200]
            raise InputError("--vary", f"point {i} ({label}): {err}") from None
    return out


def fingerprint_3d(base, axes) -> str:
    """SHA-256 of the base scene and the swept keys and values: what a store is the store of."""
    text = json.dumps({"dimension": 3, "scene": base.to_dict(), "vary": [[a.key, list(a.values)] for a in axes]},
                      sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def _check_out(out) -> str:
    path = os.fspath(out).rstrip("/")
    if not path.endswith(".zarr"):
        raise InputError("--out", f"a sweep store is a zarr folder ending in .zarr, got {path!r}")
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder) or not os.access(folder, os.W_OK):
        raise InputError("--out", f"cannot write in folder {folder!r}")
    if os.path.exists(path) and not os.path.isdir(path):
        raise InputError("--out", f"{path!r} exists and is not a zarr folder")
    return path


def _open_out(path, fp):
    """``(finished dataset or None, {index: saved point})`` of the store ``path`` of the sweep ``fp`` (module
    docstring); a new store is made (its manifest written). Refuses another sweep's store naming ``--out``."""
    manifest = os.path.join(path, MANIFEST)
    if os.path.isdir(path) and not os.path.exists(manifest):
        import xarray as xr
        try:
            ds = xr.open_zarr(path, chunks=None)
            theirs = ds.attrs.get(FINGERPRINT)
        except Exception as exc:  # noqa: BLE001  (zarr raises several types for a folder that is no store)
            raise InputError("--out", f"{path!r} exists and is not a rollqp sweep store ({type(exc).__name__})") from None
        if theirs != fp:
            raise InputError("--out", f"{path!r} holds a different sweep (another scene, dimension or other --vary "
                                      f"values: fingerprint {str(theirs)[:12]} != {fp[:12]}); choose another --out")
        return ds.load(), {}
    if os.path.exists(manifest):
        try:
            with open(manifest, encoding="utf-8") as fh:
                theirs = json.load(fh).get("fingerprint")
        except (OSError, ValueError, AttributeError):
            theirs = None
        if theirs != fp:
            raise InputError("--out", f"{path!r} holds a different 3D sweep being computed (fingerprint "
                                      f"{str(theirs)[:12]} != {fp[:12]}); choose another --out")
    else:
        os.makedirs(os.path.join(path, POINTS), exist_ok=True)
        with written(manifest, ".json") as (fh, _):
            fh.write(json.dumps({"fingerprint": fp, "format": "rollqp 3D sweep points"}).encode())
    os.makedirs(os.path.join(path, POINTS), exist_ok=True)
    saved = {}
    for name in os.listdir(os.path.join(path, POINTS)):
        m = re.fullmatch(r"(\d{1,7})\.npz", name)
        if m is None:
            continue
        try:
            with np.load(os.path.join(path, POINTS, name), allow_pickle=False) as z:
                arrays = {k: z[k] for k in z.files}
        except (OSError, ValueError, EOFError):   # unreadable: computed again
            continue
        t = float(arrays.pop("_point_time", np.nan))
        saved[int(m.group(1))] = {"arrays": arrays, "time": t}
    return None, saved


def _save_point(path, i, r) -> None:
    """Save point ``i``'s arrays in the store being computed (atomic: a killed writer leaves no half file)."""
    import io
    buf = io.BytesIO()
    np.savez(buf, _point_time=np.float64(r["time"]), **r["arrays"])
    with written(os.path.join(path, POINTS, f"{i}.npz")) as (fh, _):
        fh.write(buf.getvalue())


def sweep_3d(scene, vary, out, *, scheduler=None, workers=None, client=None, quiet=True, on_point=None):
    """Run a sweep of a 3D scene into the zarr store ``out`` (new, or the store of this sweep, continued);
    return ``(dataset, Summary3D)`` (module docstring; ``dataset`` is None when interrupted).
    ``vary``: ``"KEY=VALUES"`` strings or :class:`~rollqp.sweep.spec.Axis` objects; ``on_point(i, out)``
    after point ``i`` is saved."""
    base = scene if hasattr(scene, "replace") else load_scene(scene)
    axes = parse_vary(vary) if vary and isinstance(next(iter(vary)), str) else tuple(vary)
    if not axes:
        raise InputError("--vary", "give at least one KEY=VALUES")
    size = math.prod(len(a.values) for a in axes)
    if size > MAX_POINTS:
        raise InputError("--vary", f"{size} points; at most {MAX_POINTS}")
    path = _check_out(out)
    points = _points(base, axes)
    fp = fingerprint_3d(base, axes)
    with OutputLock(path):
        finished, saved = _open_out(path, fp)
        if finished is not None:
            done = int((finished["status"].values == 1).sum())
            return finished, Summary3D(len(points), kept=done)
        summary = Summary3D(len(points), kept=len(saved))
        todo = [i for i in range(len(points)) if i not in saved]
        results = dict(saved)
        t0 = time.perf_counter()
        own = client is None and todo
        client = (client or connect(scheduler, workers)) if todo else None
        try:
            for i, r in zip(todo, iter_jobs(run_point_3d, [(points[i],) for i in todo], client) if todo else ()):
                results[i] = r
                summary.point_times.append(r["time"])
                if "error" in r:
                    summary.failed.append((i, r["error"]))
                else:
                    summary.done += 1
                    _save_point(path, i, r)
                if on_point is not None:
                    on_point(i, r)
        except KeyboardInterrupt:
            summary.interrupted = True
            summary.wall = time.perf_counter() - t0
            return None, summary
        finally:
            if own:
                close_client(client)
        summary.wall = time.perf_counter() - t0
        ds = dataset_3d(base, axes, [results[i] for i in range(len(points))])
        ds.attrs[FINGERPRINT] = fp
        ds.to_zarr(path, mode="w", zarr_format=2, consolidated=True)   # as the 2D stores (docs/sweeps.md)
        failed = [i for i in range(len(points)) if "error" in results[i]]
        if failed:      # as a 2D store: the same command again tries the failed points, the others kept
            _keep_points(path, fp, {i: r for i, r in results.items() if "error" not in r})
        else:
            for leftover in (os.path.join(path, POINTS), os.path.join(path, MANIFEST)):   # only if zarr kept them
                if os.path.isdir(leftover):
                    shutil.rmtree(leftover)
                elif os.path.exists(leftover):
                    os.unlink(leftover)
    return ds, summary


def _keep_points(path, fp, done) -> None:
    """Beside the Dataset of a sweep with failed points: its manifest and the points done, so that running the
    same sweep again computes the failed points only and rewrites the Dataset."""
    os.makedirs(os.path.join(path, POINTS), exist_ok=True)
    for i, r in done.items():
        if not os.path.exists(os.path.join(path, POINTS, f"{i}.npz")):
            _save_point(path, i, r)
    with written(os.path.join(path, MANIFEST), ".json") as (fh, _):
        fh.write(json.dumps({"fingerprint": fp, "format": "rollqp 3D sweep points"}).encode())


def dataset_3d(base, axes, results):
    """The labelled Dataset of a 3D sweep's results (module docstring)."""
    import json

    import xarray as xr

    fields = registry(3)
    keys = tuple(a.key for a in axes)
    shape = tuple(len(a.values) for a in axes)
    ok = [r.get("arrays") for r in results]
    have = [a for a in ok if a is not None]
    K = max((a["q"].size for a in have), default=1)
    ny = max((a["y"].size for a in have), default=1)
    nx = max((a["x"].size for a in have), default=1)
    same = all(np.array_equal(a["x"], have[0]["x"]) and np.array_equal(a["y"], have[0]["y"])
               and np.array_equal(a["q"], have[0]["q"]) for a in have) if have else True
    names = [n for n in (have[0] if have else {}) if n not in ("x", "y", "q")]
    data = {}
    for name in names:
        sample = np.asarray(have[0][name])
        f = fields.get(name)
        if sample.ndim == 3:
            dims, pad = ("step", "y", "x"), (K, ny, nx)
        elif name == "creepage":
            dims, pad = ("step", "component"), (K, 3)
        elif sample.ndim == 1:
            dims, pad = ("step",), (K,)
        else:
            dims, pad = (), ()
        kind = "f" if sample.dtype.kind in "fiu" else sample.dtype.kind
        arr = np.full(shape + pad, np.nan if kind == "f" else "", dtype=float if kind == "f" else sample.dtype)
        for idx, a in zip(np.ndindex(*shape), ok):
            if a is None:
                continue
            v = np.asarray(a[name], dtype=arr.dtype)
            arr[idx + tuple(slice(0, s) for s in v.shape)] = v
        attrs = {"units": f.units, "long_name": f.description} if f is not None else {}
        data[name] = (keys + dims, arr, attrs)
    status = np.array([1 if a is not None else 2 for a in ok], dtype="int8").reshape(shape)
    error = np.array([r.get("error", "") for r in results], dtype="<U200").reshape(shape)
    data["status"] = (keys, status, {"long_name": "1 done, 2 failed", "units": "1"})
    data["error"] = (keys, error, {"long_name": "one-line error of a failed point"})
    data["point_time"] = (keys, np.array([r["time"] for r in results]).reshape(shape), {"units": "s"})
    coords = {a.key: ((a.key,), np.array(a.values)) for a in axes}
    coords["component"] = (("component",), np.array(COMPONENTS))
    for name, n in (("q", K), ("y", ny), ("x", nx)):
        dim = "step" if name == "q" else name
        if same and have:
            coords[name] = ((dim,), np.asarray(have[0][name], dtype=float))
        else:
            table = np.full(shape + (n,), np.nan)
            for idx, a in zip(np.ndindex(*shape), ok):
                if a is not None:
                    table[idx + (slice(0, a[name].size),)] = a[name]
            coords[f"{name}_of_point"] = (keys + (dim,), table)
    attrs = {"title": f"rollqp sweep of {base.name}", "dimension": 3,
             "scene": json.dumps(base.to_dict(), sort_keys=True, default=str),
             "vary": json.dumps([[a.key, list(a.values)] for a in axes], default=str),
             "conventions": "status: 1 done, 2 failed; padded states and elements are NaN; docs/sweeps.md"}
    return xr.Dataset(data, coords=coords, attrs=attrs)


# =========================================================================== the creep-force curve
def _values(text) -> tuple:
    values = parse_values(text, None, "--values") if isinstance(text, str) else tuple(text)
    try:
        out = tuple(float(v) for v in values if not isinstance(v, (str, bool)))
    except (TypeError, ValueError, OverflowError):
        out = ()
    if not out or len(out) != len(values) or not all(np.isfinite(v) and abs(v) <= 10.0 for v in out):
        raise InputError("--values", f"creepages must be finite numbers with |v| <= 10, got {text!r}"[:200])
    return out


def creep_sweep_3d(scene, creepage: str, values):
    """``(steady base scene, axis)`` of the 3D creep-curve sweep."""
    scene = scene if hasattr(scene, "replace") else load_scene(scene)
    if creepage not in CREEPAGES:
        raise InputError("--creepage", f"must be one of {', '.join(CREEPAGES)}, got {creepage!r}")
    key, force, _ = CREEPAGES[creepage]
    v = _values(values)
    changes = {"load.start": "rolling", "discretization.distance": 0.0, key: v[0]}
    if force is not None:
        changes[force] = None
    base = scene.replace(**changes)
    return base, Axis(key, v)


@dataclass
class CreepCurve3D:
    """Forces against one creepage (state 0 of each steady point) with Kalker's linear theory and μFN."""

    scene: object
    creepage: str
    values: np.ndarray
    FN: np.ndarray
    Fx: np.ndarray
    Fy: np.ndarray
    Mz: np.ndarray
    summary: object = None

    @property
    def force(self) -> np.ndarray:
        """The force along the swept creepage (``Fy`` for the spin)."""
        return self.Fx if CREEPAGES[self.creepage][2] == "Fx" else self.Fy

    def kalker_slope(self) -> float | None:
        """Kalker's ``dF/dξ`` at the origin (None outside his table or for dissimilar bodies). With an interface layer
        (``contact.layer``) the bodies' slope in series with the layer's brush, ``1/k = 1/k_Kalker + 1/k_brush``,
        ``k_brush = (8/3) a² b G₃/h`` (docs/theory3d.md §13): an estimate, not a theory (None for the spin)."""
        s = self.scene
        e, m = s.ellipse, s.materials
        if m.K != 0 or not 0 <= m.nu <= 0.5:
            return None
        C = kalker_linear(e.a / e.b, m.nu)
        if C is None:
            return None
        c2 = m.G * e.c * e.c
        k = {"longitudinal": -c2 * C[0], "lateral": -c2 * C[1], "spin": -c2 * e.c * C[2]}[self.creepage]
        layer = getattr(s.contact, "layer", None)
        if layer is not None and layer.compliance > 0:
            if self.creepage == "spin":
                return None
            brush = -8.0 / 3.0 * e.a * e.a * e.b / layer.compliance
            k = 1.0 / (1.0 / k + 1.0 / brush)
        return k

    def _layered(self) -> bool:
        layer = getattr(self.scene.contact, "layer", None)
        return layer is not None and layer.compliance > 0

    def sliding(self, values) -> np.ndarray | None:
        """``μ(V|creepage|)/μ`` of a slip-velocity law (the coefficient at the rigid slip velocity over the scene's
        reference μ): the level full sliding tends to at large creepage; None for other laws and the spin."""
        law = self.scene.contact.friction
        if getattr(law, "kind", None) != "slip" or self.creepage == "spin":
            return None
        v = np.abs(np.asarray(values, dtype=float)) * law.rolling_speed
        return np.asarray(law.steady(v)[0], dtype=float) / self.scene.mu

    def slope(self) -> np.ndarray:
        """``dF/dξ`` of the computed curve by finite differences (NaN beside a failed point)."""
        F, v = self.force, self.values
        out = np.full(F.shape, np.nan)
        ok = np.isfinite(F)
        if ok.sum() > 1:
            out[ok] = np.gradient(F[ok], v[ok])
        return out

    def origin_slope(self) -> float:
        """The computed slope at the origin: the secant through the two values of least absolute creepage
        (NaN with fewer than two computed points)."""
        F, v = self.force, self.values
        ok = np.isfinite(F)
        F, v = F[ok], v[ok]
        if v.size < 2:
            return float("nan")
        a, b = np.argsort(np.abs(v))[:2]
        return float((F[b] - F[a]) / (v[b] - v[a]))

    def table(self) -> str:
        s = self.scene
        k = self.kalker_slope()
        sl = self.slope()
        name = {"longitudinal": "ξ", "lateral": "η", "spin": "φ"}[self.creepage]
        comp = CREEPAGES[self.creepage][2]
        rows = [f"| {name} | FN | Fx | Fy | Mz | {comp}/(μFN) | d{comp}/d{name} | Kalker (linear) |",
                "|---|---|---|---|---|---|---|---|"]
        for j, v in enumerate(self.values):
            if not np.isfinite(self.force[j]):
                rows.append(f"| {v:g} | failed | | | | | | |")
                continue
            lin = "—" if k is None else f"{k * v:.5g}"
            rows.append(f"| {v:g} | {self.FN[j]:.6g} | {self.Fx[j]:.6g} | {self.Fy[j]:.6g} | {self.Mz[j]:.6g} | "
                        f"{self.force[j] / (s.mu * self.FN[j]):+.5f} | {sl[j]:.5g} | {lin} |")
        o = self.origin_slope()
        rows.append("")
        if k and self._layered():
            rows.append(f"slope at the origin d{comp}/d{name} = {o:.6g}; Kalker's linear theory of the bodies in series "
                        f"with the interface layer's brush {k:.6g} ({100 * (o / k - 1):+.2f} %: an estimate, "
                        "docs/theory3d.md §13)")
        else:
            rows.append(f"slope at the origin d{comp}/d{name} = {o:.6g}" + (
                f"; Kalker's linear theory {k:.6g} ({100 * (o / k - 1):+.2f} %: discretization, first order in dx, "
                f"docs/validation3d.md)" if k else " (no linear theory for this scene)"))
        slide = self.sliding(self.values)
        if slide is not None:
            j = int(np.argmax(np.abs(self.values)))
            rows.append(f"full sliding: |({comp})| -> mu(V |{name}|) FN, the law at the rigid slip velocity: "
                        f"{s.mu * slide[j] * float(self.FN[j]):.6g} at {name} = {self.values[j]:g}")
        else:
            rows.append(f"saturation: |({comp})| -> mu FN = {s.mu * float(np.nanmax(self.FN)):.6g}")
        return "\n".join(rows)

    def plot(self, path) -> str:
        plt = pyplot()
        s = self.scene
        k = self.kalker_slope()
        cap = s.mu * s.load.normal
        comp = CREEPAGES[self.creepage][2]
        fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 4.2))
        ax.plot(self.values, self.force / cap, "o-", ms=4, label=f"rollqp: {comp}/(μFN)")
        if k is not None:
            v = np.linspace(min(self.values.min(), 0.0), max(self.values.max(), 0.0), 200)
            lin = k * v / cap
            lin[np.abs(lin) > 1.2] = np.nan       # the line only where it is near the curve's range
            ax.plot(v, lin, "k:", lw=1, label=("Kalker's linear theory in series with the layer (estimate)"
                                               if self._layered() else "Kalker's linear theory"))
        for y in (-1.0, 1.0):
            ax.axhline(y, color="0.5", lw=0.8, ls="--")
        slide = self.sliding(self.values)
        ax.plot([], [], color="0.5", ls="--", label="±μFN (saturation)" if slide is None else "±μ_s FN (static μ)")
        if slide is not None:
            v = np.linspace(min(self.values.min(), 0.0), max(self.values.max(), 0.0), 200)
            ax.plot(v, -np.sign(v) * self.sliding(v), color="tab:red", ls="--", lw=1,
                    label="μ(V|creepage|) FN: full sliding")
        ax.set_xlabel({"longitudinal": "ξ", "lateral": "η", "spin": "φ (1/length)"}[self.creepage])
        ax.set_ylabel(f"{comp}/(μFN)")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
        bx.plot(self.values, self.slope(), "o-", ms=4, label=f"d{comp}/d(creepage), rollqp")
        if k is not None:
            bx.axhline(k, color="k", ls=":", lw=1, label=("Kalker's linear theory in series with the layer (estimate)"
                                                           if self._layered() else "Kalker's linear theory"))
        bx.set_xlabel(ax.get_xlabel())
        bx.set_ylabel("slope")
        bx.legend(fontsize=8)
        bx.grid(alpha=0.3)
        fig.suptitle(f"Steady creep-force curve of {s.name} ({s.grid.nx} x {s.grid.ny} elements, μ = {s.mu:g})")
        fig.tight_layout()
        fig.savefig(path, dpi=110)
        plt.close(fig)
        return path


def creep_curve_3d(scene, creepage: str = "longitudinal", values="1e-4:2e-3:12", out="creep.zarr",
                   **run) -> CreepCurve3D:
    """Run the 3D creep-curve sweep into ``out`` (``run``: :func:`sweep_3d`'s ``scheduler``, ``workers``,
    ``client``, ``quiet``) and return the curve."""
    base, axis = creep_sweep_3d(scene, creepage, values)
    ds, summary = sweep_3d(base, (axis,), out, **run)
    if ds is None:   # interrupted: the points done are saved in the store, run again for the rest
        return CreepCurve3D(base, creepage, np.asarray(axis.values, dtype=float), None, None, None, None, summary)
    get = lambda k: np.asarray(ds[k].values[:, 0], dtype=float)  # noqa: E731  (state 0 of each point)
    return CreepCurve3D(base, creepage, np.asarray(axis.values, dtype=float), get("FN"), get("Fx"), get("Fy"),
                        get("Mz"), summary)
