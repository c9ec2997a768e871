"""BLAS threads: one pool size for every entry point, set before numpy or scipy load.

numpy's and scipy's wheels each bundle their own OpenBLAS, and each starts a pool of as many
threads as the machine has cores. On rollqp's steps (dense solves of a few hundred to a few
thousand unknowns, FFT products) the two pools compete for the same cores: measured on the
project's 2-core machine, ``rollqp run cattaneo-3d`` took 15.6 s with scipy's pool at 2 threads
and 4.7 s with both pools at one (docs/performance.md, "BLAS threads").

So rollqp runs with ``ROLLQP_THREADS`` BLAS threads (default 1):

* :func:`pin_environment` (called by ``import rollqp``, before numpy is imported) sets
  ``OPENBLAS_NUM_THREADS``, ``OMP_NUM_THREADS``, ``MKL_NUM_THREADS``, … to that number where the
  user has not set them, so every pool loaded afterwards starts at that size;
* :func:`limited` (the command line, :func:`rollqp.run`, the sweep workers) loads scipy's BLAS and
  then limits every loaded pool to that number for the duration of the call (threadpoolctl), and
  gives the previous sizes back afterwards — also in a process that loaded numpy before rollqp.

This module imports nothing but the standard library and :mod:`rollqp.errors` (which imports nothing): it runs
before numpy loads.

Examples
--------
>>> import os
>>> threads({"ROLLQP_THREADS": "2"})
2
>>> threads({})
1
"""
from __future__ import annotations

import os

from .errors import InputError

__all__ = ["VARIABLE", "VARIABLES", "threads", "pin_environment", "limited", "pool_sizes"]

#: The environment variable that sets rollqp's BLAS threads (a whole number >= 1; default 1).
VARIABLE = "ROLLQP_THREADS"
#: The variables the BLAS/OpenMP libraries read when they load.
VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS",
             "VECLIB_MAXIMUM_THREADS")
#: Largest value accepted (a typo such as 10000 would start that many threads per pool).
MAX_THREADS = 1024


def threads(environ=None) -> int:
    """The BLAS threads rollqp runs with: ``$ROLLQP_THREADS`` (a whole number in ``1 …`` :data:`MAX_THREADS`),
    default 1; anything else is an :class:`~rollqp.errors.InputError` naming the variable."""
    env = os.environ if environ is None else environ
    text = str(env.get(VARIABLE, "1")).strip()
    if not text.isdigit() or not 1 <= int(text) <= MAX_THREADS:
        shown = text if len(text) <= 20 else f"{text[:20]}…"
        raise InputError(VARIABLE, f"must be a whole number of BLAS threads in [1, {MAX_THREADS}], got {shown!r}")
    return int(text)


def pin_environment() -> None:
    """Set the thread variables of :data:`VARIABLES` to :func:`threads` where they are unset, so that the
    pools of numpy and scipy start at that size (a bad ``ROLLQP_THREADS`` is left to :func:`limited`
    to report; the variables then stay as they are)."""
    try:
        n = threads()
    except ValueError:
        return
    for var in VARIABLES:
        os.environ.setdefault(var, str(n))


class limited:
    """``with limited():`` every loaded BLAS pool at :func:`threads` threads for the block (scipy's BLAS is
    loaded first, so that its pool is limited too); the previous sizes are restored on exit."""

    def __init__(self, n: int | None = None):
        self.n = threads() if n is None else int(n)
        self._limiter = None

    def __enter__(self):
        import scipy.linalg  # noqa: F401  (loads scipy's own OpenBLAS before the limit is applied)
        try:
            from threadpoolctl import threadpool_limits
        except ImportError:  # pragma: no cover - threadpoolctl is a core dependency
            return self
        self._limiter = threadpool_limits(limits=self.n)
        return self

    def __exit__(self, *exc):
        if self._limiter is not None:
            self._limiter.restore_original_limits()
            self._limiter = None
        return False


def pool_sizes() -> list:
    """``[(library file, API, threads), …]`` of the BLAS/OpenMP pools loaded in this process (threadpoolctl)."""
    from threadpoolctl import threadpool_info
    return [(os.path.basename(i["filepath"]), i.get("internal_api"), i["num_threads"]) for i in threadpool_info()]
