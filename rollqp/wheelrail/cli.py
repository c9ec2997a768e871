r"""The command line of wheel–rail scenes: the parts of their record for ``rollqp run`` and ``rollqp crossval``
(:data:`rollqp.cli.common.FAMILIES` names them), and ``rollqp wheelrail-table`` (the Manchester benchmark's positions in one command; docs/wheel-rail.md)."""
from __future__ import annotations

import json

from ..atomic import written
from ..errors import InputError
from ..scene import load_scene
from .benchmark import read_reference, table
from .run import crossval, crossval_report

__all__ = ["advise", "spot", "check", "crossval_command", "add_arguments", "main"]


def advise(scene) -> None:
    """Nothing to advise before a wheel–rail run."""


def spot(args, scene):
    """No steps are kept for a cross-check after the run (``rollqp crossval`` compares the methods)."""
    return {}, None


def check(kept, scene, budget=None) -> str:  # pragma: no cover - no steps are kept
    return ""


def crossval_command(scene, step, methods) -> int:
    """``rollqp crossval`` of a wheel–rail scene: its one state by every method; exit 1 if they disagree."""
    if step not in (None, 0):
        raise InputError("--step", f"a wheel-rail scene is one state (step 0), got {step!r}")
    rows = crossval(scene, methods, tolerance=scene.solver.tolerance)
    text, ok = crossval_report(rows, scene.solver.tolerance)
    print(text)
    return 0 if ok else 1


def add_arguments(t) -> None:
    t.add_argument("scene", help="a wheel-rail scene (its profiles, materials, load, friction, grid)")
    t.add_argument("--cases", default="1:21", help="positions: a,b,c or first:last (default 1:21)")
    t.add_argument("--sides", default="left,right", help="left, right or left,right (default)")
    t.add_argument("--reference", action="append", metavar="REF_OUT",
                   help="CONTACT's reference output(s) to compare with (its .ref_out of the left and/or right wheel)")
    t.add_argument("--element-size", type=float, help="the elements' size dx = ds (mm; default the scene's)")
    t.add_argument("--out", help="write the rows as JSON to this file")


def _cases(text):
    try:
        if ":" in text:
            a, b = (int(v) for v in text.split(":"))
            return list(range(a, b + 1))
        return [int(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise InputError("--cases", f"must be a,b,c or first:last (integers), got {text!r}") from None


def main(args) -> int:
    """``rollqp wheelrail-table``: the table of the benchmark's positions (0), its rows as JSON with ``--out``."""
    scene = load_scene(args.scene)
    if getattr(scene, "family", None) != "wheel-rail":
        raise InputError("SCENE", f"{scene.name!r} is not a wheel-rail scene ([contact] kind = \"wheel-rail\")")
    if args.element_size is not None:
        try:
            scene = scene.replace(**{"discretization.element_size": args.element_size})
        except InputError as err:
            raise InputError("--element-size", str(err).split(": ", 1)[-1]) from None
    sides = tuple(s.strip() for s in args.sides.split(",") if s.strip())
    if not sides or any(s not in ("left", "right") for s in sides):
        raise InputError("--sides", f"must be left, right or left,right, got {args.sides!r}")
    refs = {}
    for path in args.reference or []:
        for case in read_reference(path):
            refs[case.get("wheel"), case["case"]] = case
    load = scene.data["wheelset"]["load"] or 1.0
    print(f"{'case':>4} {'wheel':>5} {'p':>1} {'y_rail':>8} {'delta':>8} {'FN':>8} {'Fx':>8} {'Fs':>8} "
          f"{'xi':>10} {'eta':>10} {'phi':>10} {'s':>6}" + ("   d_y_rail  dFN/Fz  dFx/Fz  dFs/Fz" if refs else ""))
    out = []

    def show(rows):
        for r in rows:
            v = r.values
            line = (f"{r.case:>4} {r.wheel:>5} {r.patch:>1} {v['YCP_R']:8.3f} {v['DELTCP']:8.4f} {v['FN']:8.1f} "
                    f"{v['FX']:8.1f} {v['FS']:8.1f} {v['CKSI']:10.3e} {v['CETA']:10.3e} {v['CPHI']:10.3e} {r.time:6.2f}")
            ref = refs.get((r.wheel, r.case))
            if ref and len(ref["patches"]) >= r.patch:
                p = ref["patches"][r.patch - 1]
                line += (f"   {v['YCP_R'] - p['YCP_R']:+8.3f}  {(v['FN'] - p['FN']) / load:+6.2%}  "
                         f"{(v['FX'] - p['FX']) / load:+6.2%}  {(v['FS'] - p['FS']) / load:+6.2%}")
            print(line, flush=True)
            out.append({"case": r.case, "wheel": r.wheel, "patch": r.patch, "time": r.time,
                        **{k: float(x) for k, x in v.items()}})

    table(scene, _cases(args.cases), sides, progress=show)
    if args.out:
        with written(args.out, suffix=".json") as (fh, _):
            fh.write(json.dumps(out, indent=1).encode())
        print(f"  rows          {args.out}")
    return 0
