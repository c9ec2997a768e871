"""The product of a slip operator with a vector: its dense copy (one BLAS call) against the row gather.

``rollqp.strip.RowSparse`` stores the history operator ``M`` (eq. 37, 48) as at most three non-zeros a
row; up to ``RowSparse.DENSE_MAX`` entries its product with a vector goes through a dense copy. This
script times both products (CPU time, medians of interleaved repetitions) on the history operator of
uniform quadratic strips (docs/performance.md, "Measured settings of the methods"):

    python benchmarks/row_sparse.py [--nodes 41 81 129 161 321] [--repeats 7]
"""
from __future__ import annotations

import argparse
import time
import timeit

import numpy as np

from harness import interleaved, machine_table, pin_threads, table

pin_threads()

from rollqp.strip import RowSparse, Strip  # noqa: E402


def gather(op: RowSparse, w: np.ndarray) -> np.ndarray:
    """The row-gather product ``RowSparse @ w`` uses above ``DENSE_MAX`` (its public ``cols``, ``vals``)."""
    out = op.vals[:, 0] * w[op.cols[:, 0]]
    for j in range(1, op.cols.shape[1]):
        out += op.vals[:, j] * w[op.cols[:, j]]
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=int, nargs="+", default=[41, 81, 129, 161, 321])
    ap.add_argument("--repeats", type=int, default=7)
    args = ap.parse_args(argv)
    print(machine_table("python benchmarks/row_sparse.py --nodes " + " ".join(map(str, args.nodes))))
    rows = []
    for n in args.nodes:
        strip = Strip(1.25, (n - 1) // 2, "quadratic")
        M = strip.history_operator("material", strip.element_length / 2, -1)
        op = RowSparse.from_dense(M)
        dense = np.array(M)
        w = np.random.default_rng(0).standard_normal(strip.n)
        assert np.allclose(gather(op, w), dense @ w, rtol=0, atol=1e-12 * np.abs(dense @ w).max())
        number = 20000

        def measure(case):
            f = (lambda: dense @ w) if case == "dense" else (lambda: gather(op, w))
            return timeit.Timer(f, timer=time.process_time).timeit(number) / number  # CPU: less load-dependent

        t = {k: float(np.median(v)) for k, v in interleaved(args.repeats, {"dense": "dense", "gather": "gather"}, measure).items()}
        rows.append([strip.n, strip.n ** 2, f"{1e6 * t['dense']:.2f}", f"{1e6 * t['gather']:.2f}",
                     f"{t['gather'] / t['dense']:.2f}", "dense" if strip.n ** 2 <= RowSparse.DENSE_MAX else "gather"])
    print()
    print(table(["nodes", "entries", "dense µs (CPU)", "gather µs (CPU)", "gather / dense", "RowSparse uses"], rows))


if __name__ == "__main__":
    main()
