r"""The command line of wheel–rail scenes: their record for ``rollqp run`` and ``rollqp crossval``, and
``rollqp wheelrail-table`` (the Manchester benchmark's positions in one command; docs/wheel-rail.md)."""
from __future__ import annotations

import json

from ..errors import InputError
from .run import crossval, crossval_report, figure, run, summary

__all__ = ["family_record", "add_parser", "cmd_table"]


def _advise(scene) -> None:
    """Nothing to advise before a wheel–rail run."""


def _spot(args, scene):
    return {}, None


def _check(kept, scene) -> str:  # pragma: no cover - no steps are kept
    return ""


def _crossval(scene, step, methods) -> int:
    if step not in (None, 0):
        raise InputError("--step", f"a wheel-rail scene is one state (step 0), got {step!r}")
    rows = crossval(scene, methods, tolerance=scene.solver.tolerance)
    text, ok = crossval_report(rows, scene.solver.tolerance)
    print(text)
    return 0 if ok else 1


def family_record(Family):
    """The :class:`rollqp.cli.Family` of wheel–rail scenes."""
    return Family(run, summary, figure, _advise, _spot, _check, None, frozenset({"crossval"}), _crossval)


def add_parser(sub) -> None:
    t = sub.add_parser("wheelrail-table", help="the Manchester benchmark A-2.2: its 21 positions of a wheel-rail "
                       "scene, left and right wheels, as one table (docs/validation-wheel-rail.md)")
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


def cmd_table(args) -> int:
    from ..scene import load_scene
    from .benchmark import read_reference, table
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
        from ..atomic import written
        with written(args.out, suffix=".json") as (fh, _):
            fh.write(json.dumps(out, indent=1).encode())
        print(f"  rows          {args.out}")
    return 0
