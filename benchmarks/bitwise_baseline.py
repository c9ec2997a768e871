"""Every built-in scene with every method it allows: save each result's arrays, or compare two saves.

A refactoring that claims "the same numbers as before" runs this script on the tree before and on the
tree after, and compares:

    python benchmarks/bitwise_baseline.py run /tmp/baseline-main        # on the old tree
    python benchmarks/bitwise_baseline.py run /tmp/baseline-new         # on the new tree
    python benchmarks/bitwise_baseline.py compare /tmp/baseline-main /tmp/baseline-new

``run`` loads every built-in scene (``rollqp scenes``), tries each registered method name of its
dimension (``scene.replace(**{"solver.method": name})``; a name the scene refuses is listed as
refused with the message, a method whose package is missing as missing) and writes
``<folder>/<scene>/<method>.npz`` with every array of the result (``Result.arrays()``), or
``<method>.error.txt`` with the error a run ended with (an error is a result too: the same error
must come back).

To keep the run to minutes on a shared machine the scenes are shortened (``SHORTEN`` below: the
rolled distance, the steps of a cycle) and the slow first-order solvers get fewer scenes; the
shortened scenes still pass every phase (static start, transient, rolling) of their originals. The
overrides are the same on both trees, so the comparison is bitwise all the same.

``compare`` prints, per scene and method, each array whose values differ with the largest absolute
difference (NaNs at the same places count as equal); arrays that hold wall-clock times
(``VOLATILE``) are left out of the verdict, and ``meta`` is compared without its timing and version
entries. The exit code is 1 when anything but a volatile array differs.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
import traceback
from pathlib import Path

import numpy as np

import rollqp
from rollqp.errors import MissingBackendError, RollqpError
from rollqp.methods import SCENE_METHOD_NAMES

#: Dotted overrides per scene (shorter runs; the same on either tree).
SHORTEN = {
    "cattaneo-carter": {"discretization.distance": 3.0},
    "dent": {"discretization.distance": 3.0},
    "falling-friction": {},
    "fretting": {},
    "goodman-bentall": {"discretization.distance": 3.0},
    "harmonic": {},
    "ramp": {"discretization.distance": 3.0},
    "stop-reverse": {},
    "cattaneo-3d": {"discretization.elements": [16, 16], "discretization.distance": 2.0},
    "kalker-circular": {"discretization.elements": [20, 20]},
    "kalker-elliptic": {"discretization.elements": [18, 36]},
    "ball-in-groove": {"discretization.elements": [14, 42]},
    "quartic-roller": {"discretization.elements": [12, 24]},
}
#: Slow methods run on these scenes only (first-order solvers and the optional QP backends on
#: every 2D scene would take tens of minutes; one scene each still checks their path).
SLOW = {"socp-scs": ("kalker-circular",)}
#: Arrays holding wall-clock times: reported, never part of the verdict.
VOLATILE = ("step_time", "time", "wall_time", "setup_time", "solve_time")
#: meta entries that hold times or versions.
META_VOLATILE = ("time", "elapsed", "seconds", "version", "versions", "created", "started", "finished", "host", "wall")


def _scene(name: str):
    scene = rollqp.load_scene(name)
    over = SHORTEN.get(name, {})
    return scene.replace(**over) if over else scene


def run(folder: Path, only: list[str] | None = None, methods: list[str] | None = None) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    log = {}
    t_all = time.perf_counter()
    for name in sorted(rollqp.builtin_scenes()):
        if only and name not in only:
            continue
        try:
            base = _scene(name)
        except RollqpError as exc:   # an override this tree's scene refuses: say so, go on
            log[name] = f"scene refused: {exc}"
            print(f"{name}: scene refused: {exc}", flush=True)
            continue
        out = folder / name
        out.mkdir(exist_ok=True)
        for method in SCENE_METHOD_NAMES:
            if method in SLOW and name not in SLOW[method] or methods and method not in methods:
                continue
            key = f"{name}/{method}"
            try:
                scene = base.replace(**{"solver.method": method})
            except RollqpError as exc:
                log[key] = f"refused: {exc}"
                continue
            t0 = time.perf_counter()
            try:
                result = rollqp.run(scene)
            except MissingBackendError as exc:
                log[key] = f"missing: {exc}"
                continue
            except RollqpError as exc:
                (out / f"{method}.error.txt").write_text(f"{type(exc).__name__}: {exc}\n")
                log[key] = f"error ({time.perf_counter() - t0:.1f} s): {type(exc).__name__}: {exc}"
                continue
            except Exception:  # a bug: keep it, it is a result of the tree too
                (out / f"{method}.error.txt").write_text(traceback.format_exc())
                log[key] = "crash (see the .error.txt)"
                continue
            arrays = {k: np.asarray(v) for k, v in result.arrays().items()}
            np.savez(out / f"{method}.npz", **arrays)
            log[key] = f"ok ({time.perf_counter() - t0:.1f} s, {len(arrays)} arrays)"
            print(f"{key:40s} {log[key]}", flush=True)
    log["_total_seconds"] = round(time.perf_counter() - t_all, 1)
    (folder / "log.json").write_text(json.dumps(log, indent=1))
    print(f"total {log['_total_seconds']} s; log: {folder / 'log.json'}")


def _meta(text: str):
    try:
        meta = json.loads(text)
    except (TypeError, ValueError):
        return text

    def clean(obj):
        if isinstance(obj, dict):
            return {k: clean(v) for k, v in obj.items() if not any(w in k.lower() for w in META_VOLATILE)}
        if isinstance(obj, list):
            return [clean(v) for v in obj]
        return obj
    return clean(meta)


def _diff(a: np.ndarray, b: np.ndarray):
    """None if equal bit for bit (NaNs at the same places), else a description."""
    if a.shape != b.shape:
        return f"shape {a.shape} != {b.shape}"
    if a.dtype.kind in "US" or b.dtype.kind in "US":
        if a.dtype.kind in "US" and b.dtype.kind in "US" and a.shape == ():
            ma, mb = _meta(str(a)), _meta(str(b))
            return None if ma == mb else "text differs"
        return None if np.array_equal(a, b) else "text differs"
    if a.dtype.kind in "fc" or b.dtype.kind in "fc":
        a64, b64 = a.astype(np.complex128 if "c" in (a.dtype.kind, b.dtype.kind) else np.float64), b.astype(
            np.complex128 if "c" in (a.dtype.kind, b.dtype.kind) else np.float64)
        same = (a64 == b64) | (np.isnan(a64) & np.isnan(b64))
        if same.all():
            return None
        d = np.abs(a64 - b64)
        d = np.where(same, 0.0, d)
        scale = float(np.nanmax(np.abs(a64))) if a64.size else 0.0
        big = float(np.nanmax(d)) if np.isfinite(d).any() else float("nan")
        return f"max |diff| {big:.3e} (max |old| {scale:.3e}, {int((~same).sum())} of {same.size} differ)"
    return None if np.array_equal(a, b) else f"max |diff| {np.max(np.abs(a.astype(np.int64) - b.astype(np.int64)))}"


def compare(old: Path, new: Path) -> int:
    bad = 0
    rows = 0
    for scene_dir in sorted(p for p in old.iterdir() if p.is_dir()):
        for f in sorted(scene_dir.iterdir()):
            key = f"{scene_dir.name}/{f.name}"
            g = new / scene_dir.name / f.name
            if not (new / scene_dir.name).exists():
                continue   # a scene the new run left out (--scene)
            if not g.exists():
                print(f"{key}: missing in {new}")
                bad += 1
                continue
            rows += 1
            if f.suffix == ".txt":
                if f.read_text() != g.read_text():
                    print(f"{key}: the error differs:\n  old {f.read_text().strip()[:300]}\n  new {g.read_text().strip()[:300]}")
                    bad += 1
                continue
            a, b = np.load(f), np.load(g)
            for k in sorted(set(a.files) | set(b.files)):
                if k not in a.files or k not in b.files:
                    print(f"{key} {k}: only in {'old' if k in a.files else 'new'}")
                    bad += 1
                    continue
                d = _diff(a[k], b[k])
                if d is None:
                    continue
                if k in VOLATILE:
                    continue
                print(f"{key} {k}: {d}")
                bad += 1
    for scene_dir in sorted(p for p in new.iterdir() if p.is_dir()):
        for g in scene_dir.iterdir():
            if (old / scene_dir.name).exists() and not (old / scene_dir.name / g.name).exists():
                print(f"{scene_dir.name}/{g.name}: only in {new}")
                bad += 1
    print(f"{rows} results compared; {bad} differences outside the wall-clock arrays {VOLATILE}")
    return 1 if bad else 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run every built-in scene with every method; save the arrays")
    r.add_argument("folder", type=Path)
    r.add_argument("--scene", action="append", help="only these scenes (repeatable)")
    r.add_argument("--method", action="append", help="only these methods (repeatable)")
    c = sub.add_parser("compare", help="the largest difference per array between two saves")
    c.add_argument("old", type=Path)
    c.add_argument("new", type=Path)
    args = ap.parse_args(argv)
    if args.cmd == "run":
        run(args.folder, args.scene, args.method)
        return 0
    return compare(args.old, args.new)


if __name__ == "__main__":
    sys.exit(main())
