"""``rollqp bench ARGS``: the benchmark suite of the source repository (``benchmarks/suite.py``: work–precision
and scaling; docs/performance.md), which parses its own options."""
from __future__ import annotations

import argparse
import runpy
import sys
from pathlib import Path

from ..errors import InputError


def add_arguments(b) -> None:
    b.add_argument("bench_args", nargs=argparse.REMAINDER)


def benchmarks_folder():
    """The source repository's ``benchmarks/`` folder beside the package, or ``None`` (installed from a wheel)."""
    folder = Path(__file__).resolve().parents[2] / "benchmarks"
    return folder if (folder / "suite.py").is_file() else None


def main(args) -> int:
    folder = benchmarks_folder()
    if folder is None:
        raise InputError("bench", "the benchmarks ship with the source repository (benchmarks/suite.py), which this "
                                  "installation does not have; clone it and run rollqp bench there")
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))
    suite = runpy.run_path(str(folder / "suite.py"), run_name="rollqp_bench_suite")
    return suite["main"](args.bench_args)
