"""What the method's records cost a journaled run, and what a resumed run differs by.

Usage, from the repository root::

    python benchmarks/resume_records.py                     # 81 nodes (193 steps) and 2,561 nodes (1,024 steps)
    python benchmarks/resume_records.py --elements 40 --reps 5

A run with a result file journals each state with the method's record (rollqp.solverstate: Newton's
factorizations made and bordered, which ones are kept, the march's history operators), so that a
resumed march repeats the uninterrupted one bit for bit (docs/results.md, "Resuming"). For
``cattaneo-carter`` with ``discretization.elements`` set (``solver.operator = "dense"``, 1 a_H
rolled at 2,561 nodes), ``method = "newton"``:

* **bytes a step**: the journal's size over its states, and the records' share of it (their JSON);
* **time a step**: the run with its result file, with the records and with a recorder that records
  nothing, alternated ``--reps`` times in one process (the median of each; the machine's load is
  printed: speed as a ratio within one run);
* **resumed**: the run stopped after a third of its states (what a SIGKILL leaves: the journal),
  resumed, and compared with the uninterrupted run: the largest difference of any array.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))


class _Stop(BaseException):
    pass


class _Silent:
    """A recorder that records nothing (the run without the records)."""

    def __init__(self, meth, ops):
        self.newton, self.tags, self.lasts, self.summary, self.hist = None, 0, {}, None, None

    def note(self, k, state, cache=None):
        return None


def scene_of(elements: int):
    import rollqp
    over = {"discretization.elements": elements, "solver.operator": "dense", "solver.method": "newton"}
    if elements > 100:
        over["discretization.distance"] = 1.0
    return rollqp.load_scene("cattaneo-carter").replace(**over)


def timed(scene, folder, silent: bool) -> tuple[float, int, int]:
    """``(seconds, journal bytes, record bytes)`` of a run with a result file (the journal read before it is
    removed: the run is stopped at its last state and its journal measured)."""
    import rollqp
    from rollqp import solverstate
    from rollqp.journal import Journal, journal_path
    out = Path(folder) / ("s.npz" if silent else "r.npz")
    for p in (out, Path(journal_path(out))):
        if p.exists():
            p.unlink()
    last = scene.n_steps

    def observe(rec, ops):
        if rec.k == last:
            raise _Stop
    real = solverstate.Recorder
    if silent:
        solverstate.Recorder = _Silent
    t0 = time.perf_counter()
    try:
        rollqp.run(scene, out=out, observe=observe)
    except _Stop:
        pass
    finally:
        solverstate.Recorder = real
    wall = time.perf_counter() - t0
    j = Journal.open(journal_path(out), "journal")
    size = os.path.getsize(journal_path(out))
    records = sum(len(json.dumps(n["solver"], sort_keys=True)) for _, n in j.notes if "solver" in n)
    j.close()
    return wall, size, records


def resumed_difference(scene, folder) -> dict:
    import rollqp
    full = rollqp.run(scene).arrays()
    out = Path(folder) / "k.npz"
    stop = scene.n_steps // 3

    def observe(rec, ops):
        if rec.k == stop:
            raise _Stop
    try:
        rollqp.run(scene, out=out, observe=observe)
    except _Stop:
        pass
    res = rollqp.run(scene, resume=out, out=out).arrays()
    worst = {}
    for key, value in full.items():
        if key in ("meta", "step_time") or np.asarray(value).dtype.kind not in "fiub":
            continue
        a, b = np.asarray(value, dtype=float), np.asarray(res[key], dtype=float)
        worst[key] = 0.0 if np.array_equal(a, b, equal_nan=True) else float(np.nanmax(np.abs(a - b)))
    return {"resumed_from": stop, "largest": max(worst.values()), "different": [k for k, v in worst.items() if v]}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--elements", type=int, nargs="*", default=[40, 1280])
    ap.add_argument("--reps", type=int, default=3)
    args = ap.parse_args(argv)
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    print(f"load average at start: {os.getloadavg()[0]:.2f}")
    for el in args.elements:
        scene = scene_of(el)
        with tempfile.TemporaryDirectory() as folder:
            on, off, sizes = [], [], None
            for _ in range(args.reps):
                w, size, rec = timed(scene, folder, silent=False)
                on.append(w)
                sizes = (size, rec)
                off.append(timed(scene, folder, silent=True)[0])
            states = scene.n_steps + 1
            size, rec = sizes
            print(f"{2 * el + 1} nodes, {states} states: journal {size / states:,.0f} bytes a state, of which "
                  f"the records {rec / states:,.0f}; time a step {statistics.median(on) / states * 1e3:.3f} ms "
                  f"with the records, {statistics.median(off) / states * 1e3:.3f} ms without "
                  f"(ratio {statistics.median(on) / statistics.median(off):.3f}, medians of {args.reps})")
            print("  resumed:", resumed_difference(scene, folder))
    print(f"load average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
