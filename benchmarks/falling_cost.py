"""What a falling friction law costs: three runs timed against another checkout's rollqp, in one run.

Prints the Markdown table of docs/friction.md ("Which solution of a step", cost)::

    git archive COMMIT | tar -x -C /tmp/before        # the rollqp to compare with (any commit)
    python benchmarks/falling_cost.py --before /tmp/before

Cases: the built-in ``falling-friction`` scene (``newton``); docs/friction.md's 45 m/s snippet
(``cattaneo-carter``, ``load.tangential`` 0.5, exponential law 0.30 / 0.18, ``velocity`` 100 mm/s,
``rolling_speed`` 45000 mm/s, ``newton``); ``tests/test_friction.py::test_examples_run`` (pytest).
Each case runs in a fresh process, once with ``--before``'s package first on ``PYTHONPATH`` and
once with this repository's, alternating (:func:`harness.interleaved`: a change of the machine's
load hits both alike); the time is the child's CPU time (user + system), the median of the repeats.
"""
from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
from pathlib import Path

import numpy as np
from harness import interleaved, table  # (pins BLAS first)

ROOT = Path(__file__).resolve().parent.parent
SNIPPET = """
import rollqp
sc = rollqp.load_scene('cattaneo-carter').replace(**{'load.tangential': 0.5,
  'contact.friction': {'law': 'exponential', 'static': 0.30, 'kinetic': 0.18, 'velocity': 100.0,
  'rolling_speed': 45000.0}})
assert len(rollqp.run(sc, 'newton').arrays()['q']) == 193
"""
CASES = {
    "built-in falling-friction (newton)": [sys.executable, "-c",
                                           "import rollqp; rollqp.run(rollqp.load_scene('falling-friction'), 'newton')"],
    "45 m/s snippet (newton)": [sys.executable, "-c", SNIPPET],
    "test_friction.py::test_examples_run": [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                                            str(ROOT / "tests" / "test_friction.py") + "::test_examples_run"],
}


def cpu_seconds(command, source) -> float:
    """The CPU time of ``command`` run in a child process with ``source``'s rollqp first on the path."""
    env = dict(os.environ, PYTHONPATH=str(source))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(command, env=env, cwd=source, check=True, stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", required=True, type=Path, help="a source tree of rollqp to compare with")
    ap.add_argument("--repeats", type=int, default=1)
    args = ap.parse_args(argv)
    jobs = {(name, side): (cmd, src) for name, cmd in CASES.items()
            for side, src in (("before", args.before.resolve()), ("now", ROOT))}
    times = {k: float(np.median(v)) for k, v in interleaved(args.repeats, jobs, lambda job: cpu_seconds(*job)).items()}
    rows = [[name, f"{times[(name, 'before')]:.2f}", f"{times[(name, 'now')]:.2f}",
             f"{times[(name, 'before')] / times[(name, 'now')]:.1f}×"] for name in CASES]
    print(f"load average at the end: {os.getloadavg()[0]:.1f}")
    print(table(["case", "--before tree: CPU s", "this tree: CPU s", "ratio"], rows))


if __name__ == "__main__":
    main()
