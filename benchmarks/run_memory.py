"""Peak memory of a long run: ``rollqp run`` of ``cattaneo-carter`` refined, in a fresh process.

Usage, from the repository root::

    python benchmarks/run_memory.py                         # 1,280 elements (2,561 nodes, 6,144 steps), dense path
    python benchmarks/run_memory.py --operator auto         # the same, the operator rollqp picks (matrix-free here)
    python benchmarks/run_memory.py --elements 320 --keep-every 8   # 641 nodes, every 8th state kept

What is measured: the whole command ::

    rollqp run SCENE.toml --method newton --out r.npz --quiet [--keep-every K]

in a child process (interpreter, imports, the run with its journal, the result file written from
the journal, the summary), its **peak resident memory** read from the kernel when it ends
(``os.wait4``'s ``ru_maxrss``: what ``/usr/bin/time -v`` prints as "Maximum resident set size"),
its wall and CPU time. ``SCENE.toml`` is the built-in scene (``rollqp show cattaneo-carter``) with
``discretization.elements`` set and, unless ``--operator auto``, ``solver.operator = "dense"`` (at
2,561 nodes ``auto`` runs ``newton``'s matrix-free form, ``mf-newton``). With ``--in-memory`` the
same scene also runs through the Python API without a file (``rollqp.run(scene)``: every state held
in memory), for comparison.

The states go to the run's journal as they are computed (docs/results.md, "Memory"), so the peak
is the solver's working set: the influence matrix, Newton's scaled copy with its factorizations,
the interpreter and its libraries; it does not grow with the number of steps.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from harness import machine_table, table  # noqa: E402

IN_MEMORY = """
import sys, rollqp
scene = rollqp.load_scene(sys.argv[1])
res = rollqp.run(scene, method="newton")
print(res["pn"].shape)
"""


def scene_file(folder: Path, elements: int, operator: str) -> Path:
    """``cattaneo-carter`` with ``elements`` quadratic elements (and ``solver.operator``) as a scene file."""
    import rollqp
    over = {"discretization.elements": elements}
    if operator != "auto":
        over["solver.operator"] = operator
    path = folder / f"cc{2 * elements + 1}.toml"
    path.write_text(rollqp.load_scene("cattaneo-carter").replace(**over).to_toml(), encoding="utf-8")
    return path


def measure(argv: list[str], cwd: Path) -> dict:
    """Run ``argv`` in ``cwd``: ``{"rss": bytes at peak, "wall": s, "cpu": s, "rc": exit code, "err": stderr}``."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv, cwd=cwd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    err = proc.stderr.read().decode(errors="replace")
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    return {"rss": usage.ru_maxrss * 1024, "wall": time.perf_counter() - t0,
            "cpu": usage.ru_utime + usage.ru_stime, "rc": proc.returncode, "err": err.strip()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, default=1280, help="quadratic elements (default 1280: 2,561 nodes)")
    ap.add_argument("--operator", choices=("dense", "auto"), default="dense",
                    help="solver.operator of the scene (default dense: newton's dense path)")
    ap.add_argument("--keep-every", type=int, default=None, help="rollqp run --keep-every K")
    ap.add_argument("--in-memory", action="store_true", help="also the Python API without a file (every state "
                                                             "in memory; at 2,561 nodes about 2 GB)")
    args = ap.parse_args(argv)
    command = "python benchmarks/run_memory.py " + " ".join(sys.argv[1:] if argv is None else argv)
    print(machine_table(command) + "\n", flush=True)
    rows = []
    with tempfile.TemporaryDirectory(prefix="rollqp-memory-") as tmp:
        folder = Path(tmp)
        scene = scene_file(folder, args.elements, args.operator)
        cli = [sys.executable, "-m", "rollqp.cli", "run", scene.name, "--method", "newton", "--out", "r.npz",
               "--quiet"] + (["--keep-every", str(args.keep_every)] if args.keep_every else [])
        runs = [("`rollqp run … --out r.npz` (journal)", cli)]
        if args.in_memory:
            runs.append(("`rollqp.run(scene)` (in memory)", [sys.executable, "-c", IN_MEMORY, scene.name]))
        for label, cmd in runs:
            r = measure(cmd, folder)
            if r["rc"] != 0:
                print(f"{label}: exit {r['rc']}: {r['err'][-500:]}", file=sys.stderr)
                return 1
            size = (folder / "r.npz").stat().st_size if "--out" in cmd else 0
            rows.append((label, f"{2 * args.elements + 1}", args.operator, f"{r['rss'] / 1e6:.0f} MB",
                         f"{r['wall']:.0f} s", f"{r['cpu']:.0f} s", f"{size / 1e6:.0f} MB" if size else "–"))
    print(table(["run", "nodes", "solver.operator", "peak RSS", "wall", "CPU", "result file"], rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
