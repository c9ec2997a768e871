"""``rollqp stresses RESULT.npz --step K [--plot F.png] [--out S.npz] [--body A|B] [--grid NX,NZ]`` (3D: ``--plane``,
``--line``, ``--depths``): the subsurface stresses of one state of a result file (docs/stresses.md)."""
from __future__ import annotations

from ..errors import InputError
from ..influence import get_model
from ..plot.stresses import plot_field, plot_field3d
from ..result import check_output, load_result
from ..subsurface import _source, default_grid, save_field, stresses, summary_rows
from ..subsurface3d import parse_depths, parse_line, parse_plane, save_field3d, stresses3d, summary_rows3d
from .common import check_plot


def add_arguments(t) -> None:
    t.add_argument("result", metavar="RESULT.npz")
    t.add_argument("--step", type=int, required=True, help="the stored state K (0 = the starting state; "
                   "negative counts from the end)")
    t.add_argument("--plot", help="contour maps of von Mises and tau1 (3D: Tresca) with the surface tractions (PNG)")
    t.add_argument("--out", help="stress file (.npz): the points, every stress quantity, the maxima")
    t.add_argument("--body", default="A", choices=("A", "B"), help="body A (traction t) or B (-t)")
    t.add_argument("--grid", default=None, help="2D: NX,NZ points on ±WIDTH a_H and depths (0, DEPTH a_H] "
                   "(default 200,200)")
    t.add_argument("--width", type=float, default=None, help="2D: half-width of the grid in a_H (default 1.5)")
    t.add_argument("--depth", type=float, default=None, help="2D: depth of the grid in a_H (default 2)")
    t.add_argument("--plane", help="3D: the plane y=Y (points along x at the element centres) or x=X "
                   "(scene length units; default y=0)")
    t.add_argument("--line", help="3D: the vertical line x=X,y=Y instead of a plane")
    t.add_argument("--depths", help="3D: depths Z1,Z2,... (> 0, scene length units; default 40 down to 2a)")


def _stresses_3d(args, arrays) -> int:
    """``rollqp stresses`` on a 3D result: the section the user chose, its peaks, the stress file, the figure."""
    for opt in ("grid", "width", "depth"):
        if getattr(args, opt) is not None:
            raise InputError(f"--{opt}", "is for 2D results; on a 3D result choose the points with --plane y=Y | "
                                         "--plane x=X | --line x=X,y=Y and --depths Z1,Z2,...")
    plane = parse_plane(args.plane) if args.plane is not None else None
    line = parse_line(args.line) if args.line is not None else None
    depths = parse_depths(args.depths) if args.depths is not None else None
    names = {"step": "--step", "result": "RESULT.npz", "depths": "--depths", "points": "--depths"}
    try:
        sf = stresses3d(arrays, args.step, plane, line, depths, body=args.body)
    except InputError as err:
        raise InputError(names.get(err.key, err.key), str(err).split(": ", 1)[-1]) from None
    p0 = float(arrays["p0"])
    nz, nh = sf.values["sxx"].shape
    print(f"  state         {sf.step} (q = {sf.q:.6g}), body {sf.body}, {sf.section.label}, "
          f"{nh} x {nz} points" if nh > 1 else f"  state         {sf.step} (q = {sf.q:.6g}), body {sf.body}, "
          f"{sf.section.label}, {nz} depths")
    for k, v in summary_rows3d(sf, p0):
        print(f"  {k:<20}  {v}")
    if args.out:
        print(f"  stress file   {save_field3d(sf, args.out)}")
    if args.plot:
        print(f"  figure        {plot_field3d(sf, arrays, args.plot, p0)}")
    return 0


def main(args) -> int:
    if args.out:
        check_output(args.out, "stress file", "--out")
    check_plot(args.plot)
    loaded = load_result(args.result, "RESULT.npz")
    if loaded["meta"].get("dimension", 2) == 3:  # the result file's dimension (meta; 2 when absent)
        return _stresses_3d(args, loaded)
    for opt in ("plane", "line", "depths"):
        if getattr(args, opt) is not None:
            raise InputError(f"--{opt}", "is for 3D results; on a 2D result choose the points with --grid NX,NZ, "
                                         "--width and --depth")
    grid = "200,200" if args.grid is None else args.grid
    width, depth = (1.5 if args.width is None else args.width), (2.0 if args.depth is None else args.depth)
    try:
        nx, nz = (int(v) for v in grid.split(","))
    except ValueError:
        raise InputError("--grid", f"must be NX,NZ (two integers), got {grid!r}") from None
    names = {"nx": "--grid", "nz": "--grid", "width": "--width", "depth": "--depth", "step": "--step",
             "result": "RESULT.npz"}
    try:
        arrays, scene = _source(loaded)
        sf = stresses(arrays, args.step, default_grid(scene, nx, nz, width, depth), body=args.body)
    except InputError as err:
        raise InputError(names.get(err.key, err.key), str(err).split(": ", 1)[-1]) from None
    a, p0 = float(arrays["a_H"]), float(arrays["p0"])
    print(f"  state         {sf.step} (q = {sf.q / a:.4f} a_H), body {sf.body}, grid {nx} x {nz}")
    if not get_model(scene.contact.model).halfspace_field:
        print(f"  note          half-space field below the model's tractions: error about a/(2R) p0 = "
              f"{a / (2 * scene.R):.2g} p0 (docs/stresses.md §4)")
    for k, v in summary_rows(sf, p0, a):
        print(f"  {k:<20}  {v}")
    if args.out:
        print(f"  stress file   {save_field(sf, args.out)}")
    if args.plot:
        print(f"  figure        {plot_field(sf, arrays, args.plot, p0, a)}")
    return 0
