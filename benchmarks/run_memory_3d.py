"""Peak memory of a 3D run at two lengths: ``rollqp run`` of ``cattaneo-3d`` on a finer grid, in a fresh process.

Usage, from the repository root::

    python benchmarks/run_memory_3d.py                          # 40 x 40 elements, 160 and 960 rolling steps
    python benchmarks/run_memory_3d.py --steps 160 960 --elements 40
    python benchmarks/run_memory_3d.py --source /path/to/other/checkout   # the same with another tree's rollqp

What is measured: the whole command ::

    rollqp run SCENE.toml --out r.npz --quiet

in a child process (interpreter, imports, the run with its journal, the result file written from
the journal, the summary), its **peak resident memory** read from the kernel when it ends
(``os.wait4``'s ``ru_maxrss``), its wall time. ``SCENE.toml`` is the built-in ``cattaneo-3d`` (Newton)
with ``discretization.elements = [N, N]`` and ``discretization.distance`` set for the number of
rolling steps. The states go to the run's journal as they are computed (docs/results.md, "Memory"),
so the peak should not grow with the number of steps: the table gives the peak at each length and
their difference, against the size of the states (what holding them in memory would add).
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


def scene_file(folder: Path, elements: int, steps: int) -> Path:
    """``cattaneo-3d`` on ``elements`` x ``elements`` with ``steps`` rolling steps, as a scene file."""
    import rollqp
    base = rollqp.load_scene("cattaneo-3d").replace(**{"discretization.elements": [elements, elements]})
    per_step = base.dq / base.ellipse.a
    scene = base.replace(**{"discretization.distance": steps * per_step, "name": f"c3d-{elements}-{steps}"})
    path = folder / f"c3d-{elements}-{steps}.toml"
    path.write_text(scene.to_toml(), encoding="utf-8")
    return path


def measure(argv: list[str], cwd: Path, source: str | None) -> dict:
    """Run ``argv`` in ``cwd``: ``{"rss": bytes at peak, "wall": s, "rc": exit code, "err": stderr}``."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    if source:
        env["PYTHONPATH"] = source
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv, cwd=cwd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    err = proc.stderr.read().decode(errors="replace")
    _, status, usage = os.wait4(proc.pid, 0)
    return {"rss": usage.ru_maxrss * 1024, "wall": time.perf_counter() - t0,
            "rc": os.waitstatus_to_exitcode(status), "err": err.strip()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, default=40, help="elements along x and y (default 40)")
    ap.add_argument("--steps", type=int, nargs="+", default=[160, 960], help="rolling steps (default 160 960)")
    ap.add_argument("--source", default=None, help="the rollqp tree to run (PYTHONPATH; default: this one)")
    args = ap.parse_args(argv)
    command = "python benchmarks/run_memory_3d.py " + " ".join(sys.argv[1:] if argv is None else argv)
    print(machine_table(command) + "\n", flush=True)
    rows, peaks = [], []
    with tempfile.TemporaryDirectory(prefix="rollqp-memory3d-") as tmp:
        folder = Path(tmp)
        for steps in args.steps:
            scene = scene_file(folder, args.elements, steps)
            r = measure([sys.executable, "-m", "rollqp.cli", "run", scene.name, "--out", "r.npz", "--quiet"],
                        folder, args.source)
            if r["rc"] != 0:
                print(f"{steps} steps: exit {r['rc']}: {r['err'][-500:]}", file=sys.stderr)
                return 1
            size = (folder / "r.npz").stat().st_size
            peaks.append(r["rss"])
            rows.append((f"{steps + 1}", f"{args.elements} x {args.elements}", f"{r['rss'] / 1e6:.0f} MB",
                         f"{(r['rss'] - peaks[0]) / 1e6:+.0f} MB", f"{size / 1e6:.0f} MB", f"{r['wall']:.0f} s"))
    print(table(["states", "grid", "peak RSS", "against the first", "result file", "wall"], rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
