"""Speed of the 3D steps (docs/validation3d.md §10): wall times and ratios within one run.

    python benchmarks/three_speed.py            # about 10 minutes here (the 300 × 300 steady step dominates)
    python benchmarks/three_speed.py --quick    # without the 300 × 300 grid

1. A steady rolling step (the normal step, then the steady tangential step, Newton) on the 30 × 30
   grid of Kalker's circle and on CONTACT's 48 × 44 tractcurv grid — CONTACT's reference outputs
   print no times, so there is no CONTACT time to set it against (said in the table);
2. the same on 100 × 100 and 300 × 300 grids: the FFT path (no matrix is formed). The normal step
   starts from the Hertz pressure (``march.normal``), the steady step from zero traction;
3. Clarabel's SOCP against Newton on the same tangential step, both to rollqp's residual ≤ 1e-10
   (Clarabel refined on its active set; its raw residual beside it), on 16 × 16, 24 × 24 and 30 × 30 grids;
4. the built-in 3D scenes run as ``rollqp run`` runs them (``rollqp.march.grid.run``, Newton, without the
   cross-check), and one conic step of each (Clarabel, the cost of the cross-check per step);
5. the conic route to a steady state on 24 × 24: Newton's method on the march map (``accelerate="chord"``)
   against the Anderson-accelerated march, at a small creepage (all stick) and a large one (partial slip).

    python benchmarks/three_speed.py --only builtins chord     # sections 4 and 5 alone (about 5 minutes)
    python benchmarks/three_speed.py --only contact startup    # CONTACT's problems (22 × 22 … 82 × 82), start-up
    git worktree add /tmp/rollqp-1bdc107 1bdc107              # the rollqp CONTACT's ratios were measured against:
    python benchmarks/three_speed.py --only contact --old /tmp/rollqp-1bdc107   # CONTACT's times on this machine
    python benchmarks/three_speed.py --only precision --figure docs/figures/perf-3d-work-precision.png
                                                               # Newton, FASTSIM, extrapolation against a reference
                                                               # from 75/150/300 elements (about 10 min at load 12)

The machine is shared (2 cores, other jobs running): the load average is printed with the tables,
and only ratios within one run are meaningful.
"""
from __future__ import annotations

import argparse
import os
import time

import numpy as np
from harness import pin_threads, table

from rollqp.operators.grid import Contact, Loads
from rollqp.discretization.grid import Grid
from rollqp.closedforms.hertz_ellipse import curvatures_for_ratio, hertz
from rollqp.march.grid import normal, steady
from rollqp.materials import Materials
from rollqp.methods.newton.disc import NewtonMethod
from rollqp.methods.socp import ClarabelMethod

FN, MU = 1000.0, 0.3
STEEL = Materials.from_young(210e3, 0.28, 210e3, 0.28)


def best_of(fn, repeats):
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def steady_step(c, FN_, loads, path, repeats):
    """(normal time, steady tangential time, record) for one steady rolling step by Newton."""
    m = NewtonMethod(path=path)
    tn, p = best_of(lambda: normal(c, m, FN_), repeats)
    tt, rec = best_of(lambda: steady(c, m, FN_, loads, pressure=p), repeats)
    return tn, tt, rec


def section_steady(quick):
    rows = []
    cases = [("circle 30 × 30", Contact.hertzian(STEEL, (1 / 60, 1 / 60), FN, MU, elements=(30, 30), zone=(1.1, 1.1)),
              FN, "auto", 3)]
    m = Materials.from_shear(82000.0, 0.28, 82000.0, 0.28)
    B = curvatures_for_ratio(0.0008, 0.5)
    e = hertz(0.0008, B, m.Estar, 106700.0)
    g = Grid(48, 44, 2.2 * e.a / 48, 2.2 * e.b / 44, -1.1 * e.a, -1.1 * e.b)
    cases.append(("tractcurv 48 × 44", Contact(g, m, (0.0008, B), 106700.0, 0.33), 106700.0, "auto", 3))
    for n in (100,) if quick else (100, 300):
        cases.append((f"circle {n} × {n}", Contact.hertzian(STEEL, (1 / 60, 1 / 60), FN, MU, elements=(n, n),
                                                              zone=(1.1, 1.1)), FN, "krylov", 1))
    for label, c, F, path, rep in cases:
        loads = Loads(xi=-0.5 * c.scales.slip, eta=0.0)
        tn, tt, rec = steady_step(c, F, loads, path, rep)
        rows.append([label, c.grid.n, int(np.sum(rec.p > 0)), path, f"{tn:.3f}", f"{tt:.3f}",
                     f"{rec.residual:.1e}", "not printed in its ref_out" if "tractcurv" in label else "–"])
    return table(["grid", "elements", "in contact", "path", "normal [s]", "steady tangential [s]", "residual",
                  "CONTACT's time"], rows)


def section_socp(quick):
    rows = []
    for n in (16, 24) if quick else (16, 24, 30):
        c = Contact.hertzian(STEEL, (1 / 60, 1 / 60), FN, MU, elements=(n, n), zone=(1.15, 1.15))
        p = normal(c, NewtonMethod(), FN)
        prob = c.tangential_step("rolling", p.p, Loads(Fx=0.5 * MU * FN, eta=0.0), (p.p, 0.3 * MU * np.stack([p.p, 0 * p.p])),
                                 dq=c.grid.dx)
        tn, ref = best_of(lambda: NewtonMethod().solve(prob), 3)
        tk, refk = best_of(lambda: NewtonMethod(path="krylov").solve(prob), 3)
        clar = ClarabelMethod()
        tc, sol = best_of(lambda: clar.solve(prob), 2)
        d = np.max(np.abs(sol.t - ref.t)) / (MU * c.scales.stress)
        rows.append([f"{n} × {n}", int(np.sum(p.p > 0)), f"{tn:.3f}", f"{tk:.3f}", f"{tc:.3f}", f"{tc / min(tn, tk):.0f}",
                     f"{sol.residual:.0e} ({sol.info['raw_residual']:.0e})", f"{max(ref.residual, refk.residual):.0e}",
                     f"{d:.1e}"])
    return table(["grid", "in contact", "Newton dense [s]", "Newton Krylov [s]", "Clarabel + refinement [s]",
                  "Clarabel / best Newton", "Clarabel residual (raw)", "Newton residual",
                  "max\\|Δt\\|/μp0"], rows)


def section_builtins(quick):
    """The built-in scenes: the run as ``rollqp run`` makes it (Newton), and one Clarabel step of its end."""
    from rollqp import load_scene
    from rollqp.methods import get_method
    from rollqp.march.grid import coupled_step
    from rollqp.march.grid import prepare, run
    rows = []
    for name in ("kalker-circular", "kalker-elliptic", "cattaneo-3d"):
        scene = load_scene(name)
        t0 = time.perf_counter()
        res = run(scene).arrays()
        wall = time.perf_counter() - t0
        _, _, contact = prepare(scene)
        clar = get_method("socp-clarabel", 3)
        clar.setup(contact)
        k = len(res["q"]) - 1
        prev = (res["pn"][k - 1].ravel(), np.stack([res["px"][k - 1].ravel(), res["py"][k - 1].ravel()])) if k else \
            (res["pn"][0].ravel(), np.stack([res["px"][0].ravel(), res["py"][0].ravel()]))
        t1 = time.perf_counter()
        coupled_step(contact, clar, scene.load.normal, "rolling", scene.loads_at(float(res["q"][k])), prev,
                     scene.dq if k else contact.grid.dx, scene.load.direction)
        tc = time.perf_counter() - t1
        n = int(np.sum(res["state"][-1] > 0))
        rows.append([name, f"{scene.grid.nx} × {scene.grid.ny}", n, k, f"{wall:.2f}", f"{float(np.sum(res['step_time'])):.2f}",
                     f"{float(np.median(res['step_time'][1:])) * 1e3:.0f}" if k else "–", f"{tc:.2f}"])
    return table(["scene", "grid", "in contact", "rolling steps", "run [s]", "stepping [s]", "median step [ms]",
                  "one Clarabel step [s]"], rows)


def section_chord(quick):
    """The conic route to a steady state: Newton on the march map against Anderson's march (Clarabel)."""
    c = Contact.hertzian(Materials.from_young(210e3, 0.25, 210e3, 0.25), (1 / 60, 1 / 60), FN, MU,
                         elements=(16, 16) if quick else (24, 24), zone=(1.25, 1.25))
    rows = []
    for xi in (1e-5, 1e-3):
        out = {}
        for acc in ("chord", "anderson"):
            m = ClarabelMethod()
            t0 = time.perf_counter()
            rec = steady(c, m, FN, Loads(xi=-xi, eta=0.0, phi=0.0), accelerate=acc)
            out[acc] = (rec, time.perf_counter() - t0)
        (a, ta), (b, tb) = out["chord"], out["anderson"]
        slip = int(np.sum(a.state == 2))
        rows.append([f"{c.grid.nx} × {c.grid.ny}", f"{xi:g}", f"{slip}/{int(np.sum(a.state > 0))}", a.info["marched"],
                     f"{ta:.1f}", b.info["marched"], f"{tb:.1f}", f"{tb / ta:.1f}",
                     f"{np.max(np.abs(a.t - b.t)) / (MU * c.scales.stress):.0e}"])
    return table(["grid", "ξ", "slip/contact", "chord steps", "chord [s]", "Anderson steps", "Anderson [s]",
                  "Anderson / chord", "max\\|Δt\\|/μp0"], rows)


#: CONTACT's figures on the same problems (circle, partial slip; single-threaded, whole-process CPU time),
#: measured on another machine with CONTACT (not installed here) against the rollqp of that day (commit
#: 1bdc107): the ratio rollqp / CONTACT of the steady run's whole process, and the transient rolling step of
#: both codes (rollqp's, CONTACT's low and high, ms).
CONTACT_RATIO_STEADY = {10: (38.0, "SteadyGS"), 20: (3.5, "SteadyGS"), 40: (0.29, "SteadyGS")}
CONTACT_RATIO_GD = {20: 4.9, 40: 1.0}
CONTACT_TRANSIENT_MS = {10: (42.0, 3.0, 5.0), 20: (140.0, 21.0, 21.0)}
#: The older checkout timed beside this one (``--old DIR``): the rollqp CONTACT's ratios were measured against.
OLD = [None]

_SCENE = """name = "circle"
units = "N-mm"
[bodies.A]
radius = 30.0
radius_y = 30.0
E = 210000.0
nu = 0.25
[bodies.B]
radius = inf
radius_y = inf
E = 210000.0
nu = 0.25
[contact]
dimension = 3
friction = 0.3
[load]
normal = 1000.0
start = "rolling"
creepage = {{ longitudinal = 1e-3, lateral = 0.0, spin = 0.0 }}
[discretization]
elements = [{n}, {n}]
zone = [{z!r}, {z!r}]
step = 1.0
distance = 0.0
"""


def _tree_env(tree):
    """The environment of a process on the checkout ``tree``: single-threaded BLAS (as CONTACT was timed; the
    older checkout does not pin its pools itself), and bytecode caches allowed, as an installed package has
    them (an environment with ``PYTHONDONTWRITEBYTECODE`` compiles every module of every process again)."""
    env = dict(os.environ)
    env["PYTHONPATH"] = str(tree)
    for key in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        env[key] = "1"
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def _worker(tree, pers):
    """The lines of benchmarks/contact_problems.py run on the checkout ``tree`` (a fresh process)."""
    import json
    import subprocess
    import sys
    script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "contact_problems.py")
    out = subprocess.run([sys.executable, script, *map(str, pers)], check=True, capture_output=True, text=True,
                         env=_tree_env(tree), cwd=tree)
    return {(d["per"], d["case"]): d for d in map(json.loads, out.stdout.splitlines())}


def _whole(tree, per, folder, repeats=3):
    """Best CPU seconds (user + system) of ``rollqp run`` on the circle's steady state as a fresh process."""
    import resource
    import subprocess
    import sys
    n, z = 2 * per + 2, (per + 1) / per * (1 + 1e-9)
    path = os.path.join(folder, f"c{n}.toml")
    with open(path, "w", encoding="utf-8") as f:
        f.write(_SCENE.format(n=n, z=z))
    best = np.inf
    for _ in range(repeats):
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([sys.executable, "-m", "rollqp.cli", "run", path, "--quiet", "--no-cross-check", "--out",
                        os.path.join(folder, f"c{n}.npz")], check=True, capture_output=True, cwd=folder,
                       env=_tree_env(tree))
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        best = min(best, r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime)
    return best


def section_contact(quick):
    """The problems CONTACT was timed on (benchmarks/contact_problems.py: the steady rolling step — normal +
    steady tangential, ξ alone and ξ, η, φ together, partial slip — and a transient rolling step on circles of
    10, 20 and 40 elements per semi-axis), and the whole ``rollqp run`` of the steady state, CPU of this
    checkout; with ``--old DIR`` the same on the older checkout CONTACT's ratios were measured against, and
    from it CONTACT's time on this machine: the older rollqp's time here divided by its ratio to CONTACT."""
    import tempfile
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    pers = (10, 20) if quick else (10, 20, 40)
    trees = [("this", here)] + ([("old", OLD[0])] if OLD[0] else [])
    folder = tempfile.mkdtemp()
    res, whole = {}, {}
    for name, tree in trees:   # one tree after the other, each grid's whole process right after its steps
        res[name] = _worker(tree, pers)
        for per in pers:
            whole[name, per] = _whole(tree, per, folder)
    rows = []
    for per in pers:
        for case in ("ξ", "ξ, η, φ"):
            d = res["this"][per, case]
            row = [f"{per} ({d['grid']})", case, f"{d['slip']}/{d['contact']}", f"{d['steady'] * 1e3:.1f}",
                   f"{whole['this', per]:.2f}" if case == "ξ" else "″",
                   f"{d['step'] * 1e3:.2f} ({d['first'] * 1e3:.0f}; {d['mean'] * 1e3:.1f})"]
            if "old" in res:
                o = res["old"][per, case]
                ratio, solver = CONTACT_RATIO_STEADY[per]
                cw = whole["old", per] / ratio
                gd = f", GDsteady {whole['old', per] / CONTACT_RATIO_GD[per]:.2f}" if per in CONTACT_RATIO_GD else ""
                row += [f"{o['steady'] * 1e3:.1f}", f"{whole['old', per]:.2f}" if case == "ξ" else "″",
                        f"{cw:.3f} ({solver}{gd})", f"{d['steady'] / cw:.2f}× / {whole['this', per] / cw:.1f}×"]
                if per in CONTACT_TRANSIENT_MS:
                    then, lo, hi = CONTACT_TRANSIENT_MS[per]
                    clo, chi = o["step"] * lo / then, o["step"] * hi / then
                    row += [f"{o['step'] * 1e3:.2f}", f"{clo * 1e3:.1f}–{chi * 1e3:.1f}",
                            f"{d['step'] / chi:.1f}–{d['step'] / clo:.1f}× ({d['mean'] / chi:.1f}–{d['mean'] / clo:.1f}×)"]
                else:
                    row += ["", "", ""]
            rows.append(row)
    head = ["elements per semi-axis (grid)", "creepages", "slip/contact", "steady step [ms CPU]",
            "whole run [s CPU]", "transient step, median [ms CPU] (first; mean of 12)"]
    if "old" in res:
        head += ["old: steady step [ms]", "old: whole run [s]", "CONTACT here: whole run [s]",
                 "steady step / CONTACT; whole run / CONTACT", "old: transient step [ms]",
                 "CONTACT here: transient step [ms]", "transient step / CONTACT (mean of 12)"]
    return table(head, rows)


def section_startup(quick):
    """The start-up of a small 3D run, each in a fresh process (best of 3, CPU and wall): the import, the import and
    the influence coefficients of a 22 × 22 contact (kernels and their FFTs), and the whole command on a 22 × 22
    steady state (kalker-circular's circle, ξ = 1e-3, no rolling steps, no cross-check)."""
    import subprocess
    import sys
    import tempfile
    from rollqp import load_scene
    folder = tempfile.mkdtemp()
    scene = load_scene("kalker-circular", {"discretization.elements": [22, 22], "discretization.zone": [1.1, 1.1],
                                           "discretization.distance": 0.0, "load.creepage.longitudinal": 1e-3})
    path = os.path.join(folder, "c22.toml")
    with open(path, "w", encoding="utf-8") as f:
        f.write(scene.to_toml())
    contact = ("import numpy as np, rollqp\nfrom rollqp.operators.grid import Contact\n"
               "from rollqp.materials import Materials\n"
               "c = Contact.hertzian(Materials.from_young(210e3, .28, 210e3, .28), (1/60, 1/60), 1e3, .3, "
               "elements=(22, 22), zone=(1.1, 1.1))\nc.ops.Att @ np.ones(2 * c.grid.n); c.ops.Ann @ np.ones(c.grid.n)")
    cases = (("import rollqp", [sys.executable, "-c", "import rollqp"]),
             ("import + a 22 × 22 contact's influence coefficients", [sys.executable, "-c", contact]),
             ("the command on a 22 × 22 steady state (kalker-circular's circle, ξ = 1e-3, no rolling steps; quiet, "
              "no cross-check)",
              [sys.executable, "-m", "rollqp.cli", "run", path, "--quiet", "--no-cross-check", "--out",
               os.path.join(folder, "c22.npz")]))
    import resource
    rows = []
    for label, cmd in cases:
        best, wall = np.inf, np.inf
        for _ in range(3):
            r0, t0 = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter()
            subprocess.run(cmd, check=True, capture_output=True, cwd=folder,
                           env=_tree_env(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
            r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            best = min(best, r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime)
            wall = min(wall, time.perf_counter() - t0)
        rows.append([label, f"{best:.2f}", f"{wall:.2f}"])
    return table(["what (a fresh process)", "CPU [s] (user + system), best of 3", "wall [s], best of 3"], rows)


def _steady_run(n, method="newton", xi=1e-3):
    """kalker-circular's circle (zone 1.25: the edge on element boundaries for n a multiple of 5) at ξ alone, its
    steady state on n × n elements by ``method``: (Fx, CPU seconds of the run, wall seconds)."""
    from rollqp import load_scene
    from rollqp.march.grid import run
    scene = load_scene("kalker-circular", {"discretization.elements": [n, n], "discretization.distance": 0.0,
                                           "load.creepage.longitudinal": xi, "solver.method": method})
    c0, w0 = time.process_time(), time.perf_counter()
    r = run(scene).arrays()
    return float(r["Fx"][0]), time.process_time() - c0, time.perf_counter() - w0


#: CONTACT's point on the work–precision figure: 1 % error in Fx at 30 elements per semi-axis in 1–2 s of CPU
#: (CONTACT's default solvers, single-threaded, measured on another machine: CONTACT is not installed here).
CONTACT_POINT = (1.5, 1e-2)


def section_precision(quick):
    """Force error against CPU time on the circle at ξ = 1e-3 (partial slip): Newton on 20 … 160 elements,
    FASTSIM on the same grids, and ``rollqp extrapolate``'s defaults at targets of 1 %, 0.3 % and 0.1 % (one
    process: its CPU time is the whole work); the reference is the one recorded in
    tests/data/extrapolation/references.json (the same extrapolation on grids twice as fine). Draws
    docs/figures/perf-3d-work-precision.png."""
    import json
    from pathlib import Path

    from rollqp import load_scene
    from rollqp.extrapolate import extrapolate
    data = json.loads((Path(__file__).resolve().parent.parent / "tests" / "data" / "extrapolation"
                       / "references.json").read_text(encoding="utf-8"))
    ref = next(c for c in data["cases"] if c["case"] == "circle-1e-3" and c["q"] == "Fx")
    F = ref["reference"]
    rows, pts = [], {"newton": [], "fastsim": [], "extrapolated": []}
    grids = (20, 40, 80) if quick else (20, 40, 80, 160)
    runs = {n: _steady_run(n) for n in grids}
    for n in grids:
        Fx, cpu, wall = runs[n]
        pts["newton"].append((cpu, abs(Fx / F - 1)))
        rows.append([f"newton {n} × {n}", f"{Fx:.5f}", f"{abs(Fx / F - 1):.2e}", f"{cpu:.2f}", f"{wall:.2f}", ""])
    for n in grids:
        Fx, cpu, wall = _steady_run(n, "fastsim")
        pts["fastsim"].append((cpu, abs(Fx / F - 1)))
        rows.append([f"fastsim {n} × {n}", f"{Fx:.5f}", f"{abs(Fx / F - 1):.2e}", f"{cpu:.2f}", f"{wall:.2f}", ""])
    scene = load_scene("kalker-circular", {"load.creepage.longitudinal": 1e-3})
    for target in ((1e-2, 3e-3) if quick else (1e-2, 3e-3, 1e-3)):
        c0, w0 = time.process_time(), time.perf_counter()
        x = extrapolate(scene, target=target, workers=1)
        cpu, wall = time.process_time() - c0, time.perf_counter() - w0
        e = x.forces["Fx"]
        pts["extrapolated"].append((cpu, abs(e.value / F - 1), e.error / abs(e.value)))
        rows.append([f"extrapolated to {100 * target:g} % ({'/'.join(map(str, x.grids))}, "
                     f"{'/'.join(map(str, x.shifts))} positions)", f"{e.value:.5f}", f"{abs(e.value / F - 1):.2e}",
                     f"{cpu:.2f}", f"{wall:.2f}", f"{e.error / abs(e.value):.2e}"])
    _figure(pts, F, FIGURE[0])
    head = (f"reference Fx = {F:.5f} N ± {100 * ref['reference_estimate'] / abs(F):.2f} % (tests/data/extrapolation/"
            f"references.json: grids {ref['reference_grids']}, 6 positions each)\n\n")
    return head + table(["method and grid", "Fx [N]", "error against the reference", "CPU [s]", "wall [s]",
                         "its own error estimate"], rows)


#: Where section_precision draws its figure (``--figure``).
FIGURE = ["docs/figures/perf-3d-work-precision.png"]


def _figure(pts, F, path):
    from pathlib import Path
    from harness import pyplot
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for key, marker in (("newton", "o-"), ("fastsim", "s-")):
        xs, ys = zip(*pts[key])
        ax.loglog(xs, ys, marker, label={"newton": "Newton, 20 … 160 elements across",
                                         "fastsim": "FASTSIM (Kalker's simplified theory), same grids"}[key])
    if pts["extrapolated"]:
        xs, ys, es = zip(*pts["extrapolated"])
        ax.errorbar(xs, ys, yerr=[[0] * len(es), es], fmt="D", capsize=3,
                    label="rollqp extrapolate, targets 1, 0.3, 0.1 % (bar: its printed estimate)")
    ax.loglog(*CONTACT_POINT, "k*", markersize=11, label="CONTACT, 30 per semi-axis (another machine)")
    ax.axhline(1e-3, color="0.6", lw=0.8, ls=":")
    ax.set_xlabel("CPU time [s] (this machine, one thread)")
    ax.set_ylabel("|Fx / Fx,ref − 1|")
    ax.set_title("Circle, ξ = 1e-3 (partial slip): creep force error against time", fontsize=10)
    ax.legend(fontsize=7)
    out = Path(path)
    if not out.is_absolute():
        out = Path(__file__).resolve().parent.parent / out
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


SECTIONS = {"contact": ("CONTACT's problems: steady and transient steps", section_contact),
            "precision": ("work–precision: Newton, FASTSIM, extrapolation", section_precision),
            "startup": ("start-up of a small 3D run", section_startup),
            "steady": ("steady rolling step, Newton", section_steady), "socp": ("SOCP against Newton", section_socp),
            "builtins": ("the built-in 3D scenes", section_builtins),
            "chord": ("the conic route to a steady state", section_chord)}


def main(argv=None):
    ap = argparse.ArgumentParser(description="Speed of the 3D steps (ratios within one run).")
    ap.add_argument("--quick", action="store_true", help="without the 300 × 300 grid and the 30 × 30 SOCP")
    ap.add_argument("--only", nargs="+", choices=sorted(SECTIONS), help="these sections only")
    ap.add_argument("--old", help="section contact: also time this older checkout (the rollqp CONTACT's ratios "
                    "were measured against, commit 1bdc107) and derive CONTACT's times on this machine from it")
    ap.add_argument("--figure", default=FIGURE[0], help="the work–precision figure (section precision; "
                    "relative to the repository)")
    args = ap.parse_args(argv)
    FIGURE[0] = args.figure
    OLD[0] = os.path.abspath(args.old) if args.old else None
    pin_threads()
    print(f"load average at start: {', '.join(f'{x:.2f}' for x in os.getloadavg())} (2 cores, shared)\n")
    for key in args.only or SECTIONS:
        name, fn = SECTIONS[key]
        t0 = time.perf_counter()
        text = fn(args.quick)
        print(f"### {name} ({time.perf_counter() - t0:.0f} s)\n\n{text}\n", flush=True)
    print(f"load average at end: {', '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
