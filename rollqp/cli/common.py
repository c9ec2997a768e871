"""What the commands of ``rollqp`` share: the exit codes, the default output names, the ``--plot`` check and the
options of the commands on dask."""
from __future__ import annotations

import argparse
import os
import re
import signal

from ..errors import InputError, MissingBackendError

EXIT_INPUT, EXIT_SOLVER = 2, 3
#: The journal or the result file could not be written (a full disk, a file size limit).
EXIT_WRITE = 4
#: Interrupted by Ctrl-C (SIGINT) or SIGTERM: the shell's 128 + signal number.
EXIT_INTERRUPTED, EXIT_TERMINATED = 130, 143


class Terminated(KeyboardInterrupt):
    """SIGTERM, handled as Ctrl-C: the completed states are written before rollqp exits."""


def on_sigterm(signum, frame):
    raise Terminated()


def default_output(name: str, suffix: str = ".npz") -> str:
    """``<name><suffix>`` in the current folder, the scene name reduced to a safe file name.

    A scene's name never steers the path: every character outside ``[A-Za-z0-9._-]`` becomes
    ``_`` and leading dots are dropped (``"../x"`` → ``"_x"``), so the default output stays in
    the working folder.
    """
    safe = re.sub(r"[^A-Za-z0-9._-]", "_", name).lstrip(".")[:100] or "result"
    return safe + suffix


def check_plot(path):
    """Check ``--plot`` before the run: a known image format and a writable folder."""
    if path is None:
        return
    try:  # matplotlib (extra "plot") itself: rollqp.plot's figures are imported only when one is drawn
        from matplotlib.backends.backend_agg import FigureCanvasAgg
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise MissingBackendError("--plot needs matplotlib: pip install 'rollqp[plot]'") from exc
    ext = os.path.splitext(path)[1].lstrip(".").lower()
    formats = FigureCanvasAgg.get_supported_filetypes()
    if ext not in formats:
        raise InputError("--plot", f"unknown figure format {ext or '(none)'!r}; use one of "
                                   f"{', '.join(sorted(formats))}")
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder) or not os.access(folder, os.W_OK):
        raise InputError("--plot", f"cannot write in folder {folder!r}")


# --------------------------------------------------------------------------- the commands on dask (docs/sweeps.md)
def workers_count(text):
    """``--workers N``: an integer of a few digits (its range is checked when the cluster starts)."""
    t = str(text).strip()
    if not t.isdigit() or len(t) > 6:
        shown = t if len(t) <= 20 else f"{t[:20]}… ({len(t)} characters)"
        raise argparse.ArgumentTypeError(f"must be a whole number of worker processes, got {shown!r}")
    return int(t)


def cluster_options(p):
    p.add_argument("--scheduler", metavar="ADDRESS", help="an existing dask scheduler (tcp://host:8786, or "
                   "tls://host:8786 with a dask TLS configuration); default: a local cluster")
    p.add_argument("--workers", type=workers_count, help="worker processes of the local cluster (default: one per core; 0: the points run in this "
                   "process, no cluster)")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")


def sweep_signals(fn):
    """Run ``fn()`` with SIGTERM handled as Ctrl-C (the stored points stay)."""
    previous = signal.signal(signal.SIGTERM, on_sigterm)
    try:
        return fn()
    finally:
        signal.signal(signal.SIGTERM, previous)


def sweep_exit(summary) -> int:
    if summary.interrupted:
        return EXIT_INTERRUPTED
    return EXIT_SOLVER if summary.failed else 0
