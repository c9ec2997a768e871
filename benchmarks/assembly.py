"""Half-space assembly time and peak memory on uniform strips (docs/matrix-free.md).

One fresh process per size (peak RSS is per process): ``halfspace_influence`` on ``N`` quadratic
elements (``2N + 1`` nodes), similar materials. Run from a source tree; ``--source`` times
another checkout (e.g. main) with the same script, for a table of the two trees.

    python benchmarks/assembly.py --nodes 2561 5121 [--source /path/to/other/checkout]
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

_CHILD = r"""
import json, resource, sys, time
import numpy as np
from rollqp.strip import Strip
from rollqp.influence import halfspace_influence
import scipy.fft, scipy.linalg, scipy.sparse.linalg  # imported before timing: a process's one-time cost
n = int(sys.argv[1]); el = sys.argv[2]
ne = {"quadratic": (n - 1) // 2, "linear": n - 1, "constant": n}[el]
s = Strip(1.25, ne, el)
t0 = time.perf_counter()
inf = halfspace_influence(s, Estar=1.0, beta=0.0, R_A=20.0, R_B=40.0)
dt = time.perf_counter() - t0
rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
print(json.dumps({"nodes": s.n, "seconds": dt, "peak_bytes": rss, "matrix_bytes": 8 * s.n * s.n,
                  "min_eig_rel": inf.info["min_eig_rel"]}))
"""


def measure(n: int, element: str = "quadratic", source: str | None = None) -> dict:
    """One assembly of ``n`` nodes in a fresh process (of ``source``'s rollqp, default this checkout):
    ``nodes``, ``seconds``, ``peak_bytes`` (the process's peak RSS), ``matrix_bytes``, ``min_eig_rel``."""
    src = os.path.abspath(source or os.path.join(os.path.dirname(__file__), ".."))
    env = dict(os.environ, PYTHONPATH=src)
    out = subprocess.run([sys.executable, "-c", _CHILD, str(n), element], env=env, cwd=src,
                         capture_output=True, text=True, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=int, nargs="+", default=[2561, 5121])
    ap.add_argument("--element", default="quadratic", choices=("constant", "linear", "quadratic"))
    ap.add_argument("--source", default=None, help="checkout whose rollqp is timed (default: this one)")
    args = ap.parse_args(argv)
    print("| nodes | assembly (s) | peak RSS (GB) | peak / matrix | min_eig_rel |")
    print("|---|---|---|---|---|")
    for n in args.nodes:
        r = measure(n, args.element, args.source)
        print(f"| {r['nodes']} | {r['seconds']:.2f} | {r['peak_bytes'] / 1e9:.2f} | "
              f"{r['peak_bytes'] / r['matrix_bytes']:.2f} | {r['min_eig_rel']:.6g} |", flush=True)


if __name__ == "__main__":
    main()
