"""What ``rollqp run`` tells the user while it runs, on stderr: a progress bar on a terminal (tqdm, if
installed) or a line every few seconds (logs and batch jobs), the Newton iterations of a long solve, and the
estimated time of a long start or run."""
from __future__ import annotations

import os
import sys
import time

from ..progress import remaining_iterations

#: Seconds between progress lines when stderr is not a terminal (a log file, a batch job);
#: ``$ROLLQP_PROGRESS_SECONDS`` overrides it.
LOG_EVERY = 5.0
#: A run's remaining time above which ``rollqp run`` prints its estimate after the first steps (seconds).
ANNOUNCE_SECONDS = 60.0
#: Seconds of a start's steps after which its total time is estimated (:func:`start_progress`).
START_ESTIMATE_SECONDS = 3.0


def log_every() -> float:
    """Seconds between progress lines: ``$ROLLQP_PROGRESS_SECONDS``, or :data:`LOG_EVERY` when unset or
    not a number."""
    try:
        return float(os.environ.get("ROLLQP_PROGRESS_SECONDS", LOG_EVERY))
    except ValueError:
        return LOG_EVERY


def progress(quiet):
    """A progress callback and its closer: a tqdm bar on a terminal (after 2 s, if tqdm is
    installed), a line every :data:`LOG_EVERY` seconds otherwise (logs and batch jobs)."""
    if quiet:
        return None, lambda: None
    if sys.stderr.isatty():
        try:
            from tqdm import tqdm  # optional (extra "progress")
        except ImportError:
            tqdm = None
        if tqdm is not None:
            bar = {}

            def cb(k, K):
                if "b" not in bar:
                    bar["b"] = tqdm(total=K, delay=2.0, unit="step", leave=False, file=sys.stderr)
                bar["b"].update(1)

            return cb, lambda: bar.get("b") and bar["b"].close()
    t0 = time.perf_counter()
    last = [t0]
    every = log_every()

    def line(k, K):
        now = time.perf_counter()
        if now - last[0] >= every or k == K and now - t0 >= every:
            last[0] = now
            print(f"rollqp: step {k}/{K} ({100.0 * k / max(K, 1):.0f} %), {now - t0:.1f} s", file=sys.stderr,
                  flush=True)

    return line, lambda: None


def iteration_lines():
    """A :mod:`rollqp.progress` listener: a line every :data:`LOG_EVERY` seconds of a long solve inside one
    step (the Newton iterations of a large grid's steady step, with the residual), and from a minute on
    the remaining time estimated from the residual's last decrease."""
    every = log_every()
    state = {"last": 0.0, "res": []}

    def listen(what, it, res, seconds, target):
        if it == 1:  # a new solve
            state["last"], state["res"] = 0.0, []
        state["res"].append(res)
        if seconds - state["last"] < every:
            return
        state["last"] = seconds
        line = f"rollqp: {what} step: Newton iteration {it}, residual {res:.1e} (to reach {target:.0e}), {seconds:.0f} s"
        left = remaining_iterations(state["res"], target) if seconds >= 60 else None
        if left:
            line += (f"; at most about {minutes(left * seconds / it)} to go ({left} more iterations of "
                     f"{seconds / it:.0f} s at the residual's last rate of decrease; Newton's only speeds up)")
        print(line, file=sys.stderr, flush=True)

    return listen


def start_progress():
    """The report of a start's steps (a march to the steady state, the static shift steps): after the first
    :data:`START_ESTIMATE_SECONDS`, once, the estimated time of the whole start if it exceeds
    :data:`ANNOUNCE_SECONDS`; then a line every ``ROLLQP_PROGRESS_SECONDS`` (default :data:`LOG_EVERY`)."""
    t0 = time.perf_counter()
    state = {"last": t0, "said": False}
    every = log_every()

    def tick(j, expected):
        now = time.perf_counter()
        if not state["said"] and now - t0 >= START_ESTIMATE_SECONDS:
            state["said"] = True
            total = (now - t0) / j * max(expected, j)
            if total > ANNOUNCE_SECONDS:
                print(f"rollqp: the starting state: about {minutes(total)} ({expected} steps usually, "
                      f"{(now - t0) / j:.3g} s a step measured on the first {j})", file=sys.stderr, flush=True)
        if now - state["last"] >= every:
            state["last"] = now
            print(f"rollqp: the starting state: step {j} (about {expected} usually), {now - t0:.1f} s",
                  file=sys.stderr, flush=True)
    return tick


def estimate_progress(cb, steps: int):
    """``cb`` that also prints, once, the estimated remaining time when it exceeds :data:`ANNOUNCE_SECONDS`:
    measured on the first rolling steps (after at least 10 s of them, or 5 steps), the start excluded."""
    state = {"t": None, "k": 0, "said": False}

    def progress(k, K):
        now = time.perf_counter()
        if state["t"] is None:  # the first rolling step is done: the clock starts here
            state["t"], state["k"] = now, k
        elif not state["said"] and (now - state["t"] >= 10.0 or k - state["k"] >= 5):
            per = (now - state["t"]) / (k - state["k"])
            left = per * (K - k)
            state["said"] = True
            if left > ANNOUNCE_SECONDS:
                print(f"rollqp: about {minutes(left)} to go: {K - k} of {steps} steps left at {per:.3g} s a step "
                      f"(measured on steps {state['k'] + 1}..{k})", file=sys.stderr, flush=True)
        if cb is not None:
            cb(k, K)

    return progress


def minutes(seconds: float) -> str:
    """``seconds`` as a reader wants them: seconds, minutes or hours."""
    return f"{seconds:.0f} s" if seconds < 120 else f"{seconds / 60:.0f} min" if seconds < 7200 else f"{seconds / 3600:.1f} h"
