"""What the benchmark scripts share: thread pinning, the machine table, markdown tables, timing, fits.

Every script in ``benchmarks/`` imports this module first (``from harness import ...``; the
scripts run from the repository root as ``python benchmarks/NAME.py``, which puts this folder on
the path). Importing it pins every BLAS/OpenMP pool to one thread (:func:`pin_threads`): the
numpy and scipy wheels each bundle OpenBLAS, and two pools fighting over 2 cores can make a
dense solve 100× slower. Timings are medians over repetitions; ratios compare numbers of one
run only (:func:`interleaved` alternates the cases so that a change of the machine's load hits
all of them alike).
"""
from __future__ import annotations

import datetime
import importlib.metadata as md
import os
import platform
import re
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

# ------------------------------------------------------------------------------- machine
#: Thread-count variables read by BLAS/OpenMP libraries when they load.
THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS",
                    "VECLIB_MAXIMUM_THREADS", "NUMEXPR_NUM_THREADS")


def pin_threads():
    """Limit every BLAS/OpenMP pool to one thread for the rest of the process; the limiter.

    The pools already loaded (numpy's and scipy's OpenBLAS, each wheel bundles its own) are
    limited by threadpoolctl; libraries loaded later start single-threaded through the
    environment variables (set unless the user set them). Every benchmark calls this once.
    """
    for var in THREAD_VARIABLES:
        os.environ.setdefault(var, "1")
    from threadpoolctl import threadpool_limits
    import scipy.linalg  # noqa: F401  (load scipy's BLAS before the limit is applied)
    return threadpool_limits(limits=1)


def cpu_model() -> str:
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def source_line() -> str:
    """The rollqp source measured: git commit and whether the package's files differ from it."""
    root = Path(__file__).resolve().parent.parent  # the repository
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=root, capture_output=True, text=True,
                              timeout=10).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--", "rollqp"], cwd=root, capture_output=True,
                               text=True, timeout=10).stdout.split("\n")
    except (OSError, subprocess.SubprocessError):
        return "unknown (no git)"
    changed = [ln[3:] for ln in dirty if ln.strip()]
    return (f"commit {head or 'unknown'}"
            + (f", with uncommitted changes in {', '.join(changed)}" if changed else ", no uncommitted changes in rollqp/"))


def machine_rows(command: str | None = None) -> list[tuple[str, str]]:
    """(key, value) rows: date, platform, CPU, Python, packages, thread pools, load, command, source."""
    from threadpoolctl import threadpool_info
    try:
        usable = len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        usable = os.cpu_count()
    versions = []
    for p in ("rollqp", "numpy", "scipy", "clarabel", "osqp", "cvxpy", "threadpoolctl"):
        try:
            versions.append(f"{p} {md.version(p)}")
        except md.PackageNotFoundError:
            versions.append(f"{p} (not installed)")
    pools = "; ".join(f"{d.get('internal_api')} {d.get('version') or ''} "
                      f"({d.get('num_threads')} thread{'s' if d.get('num_threads') != 1 else ''})".replace("  ", " ")
                      for d in threadpool_info()) or "none found"
    return [("date", datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")),
            ("platform", platform.platform()),
            ("cpu", f"{cpu_model()}; os.cpu_count() = {os.cpu_count()}, usable = {usable}"),
            ("python", f"{platform.python_implementation()} {platform.python_version()}"),
            ("packages", ", ".join(versions)),
            ("thread pools", pools),
            ("load average", " / ".join(f"{v:.2f}" for v in os.getloadavg()) + " (1, 5, 15 min, at start)"),
            ("command", command or "python " + " ".join([os.path.relpath(sys.argv[0])] + sys.argv[1:])),
            ("rollqp source", source_line())]


def machine_table(command: str | None = None) -> str:
    return table(["", ""], machine_rows(command))


def table(header, rows) -> str:
    """A markdown table; bars and lone stars (E*) in cells are escaped."""
    def cell(c):
        return re.sub(r"(?<!\*)\*(?!\*)", r"\\*", str(c).replace("|", "\\|"))

    out = ["| " + " | ".join(cell(h) for h in header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(cell(c) for c in r) + " |" for r in rows]
    return "\n".join(out)


def fmt_err(e) -> str:
    return "–" if e is None or not np.isfinite(e) else f"{e:.1e}"


# ------------------------------------------------------------------------------- runs


@dataclass
class Run:
    """One scene run by one method: times, errors, or the failure."""

    method: str
    label: str
    n: int = 0
    steps: int = 0
    stepping: float = float("nan")   # Σ step_time [s], median over repeats
    step: float = float("nan")       # median rolling step_time [s], median over repeats
    wall: float = float("nan")       # the whole rollqp.run call [s], median over repeats
    repeats: int = 0
    residual: float = float("nan")
    errors: dict = field(default_factory=dict)
    failed: str | None = None
    skipped: str | None = None
    arrays: dict | None = field(default=None, repr=False)

    @property
    def ok(self) -> bool:
        return self.failed is None and self.skipped is None


def short_error(exc) -> str:
    """One line: the exception's type and the first line of its message, whole (rollqp's errors
    are one line by design; a cut message loses the step, the residual or the limit at its end)."""
    msg = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
    return f"{type(exc).__name__}: {msg}"


def timed_run(scene, method, label="", repeats=3, budget=2.0, keep=True) -> Run:
    """Run ``scene`` with ``method`` up to ``repeats`` times (stopping once ``budget`` seconds
    are spent, at least once); medians of the times. Never raises: failures are recorded."""
    from rollqp import RollqpError, run as drive
    from rollqp.report import closed_form_errors

    out = Run(method=method, label=label)
    stepping, steps, walls = [], [], []
    spent = 0.0
    res = None
    for _ in range(max(1, repeats)):
        t0 = time.perf_counter()
        try:
            res = drive(scene, method=method)
        except (RollqpError, ValueError, ArithmeticError, np.linalg.LinAlgError, MemoryError) as exc:
            out.failed = short_error(exc)
            part = getattr(exc, "partial", None)
            if part is not None and len(part):
                out.steps = len(part) - 1
            return out
        except Exception as exc:  # a backend's own exception: recorded, the study goes on
            out.failed = short_error(exc)
            return out
        w = time.perf_counter() - t0
        a = res.arrays()
        walls.append(w)
        stepping.append(float(a["step_time"].sum()))
        steps.append(float(np.median(a["step_time"][2:] if len(a["step_time"]) > 3 else a["step_time"][1:])))
        spent += w
        if spent > budget:
            break
    a = res.arrays()
    out.n, out.steps, out.repeats = int(a["x"].size), len(a["q"]) - 1, len(walls)
    out.stepping, out.step, out.wall = map(lambda v: float(np.median(v)), (stepping, steps, walls))
    out.residual = float(a["residual"].max())
    out.errors = {k: v for k, v, _ in closed_form_errors(a, scene)}
    if keep:
        out.arrays = {k: a[k] for k in ("x", "q", "pn", "pt", "creepage", "a_H", "p0")}
    return out


def diff_to(run: Run, ref: Run, mu: float) -> float | None:
    """Largest ``|t − t_ref|/(μp0)`` and ``|p − p_ref|/p0`` over all states (same discretization)."""
    if not (run.ok and ref.ok) or run.arrays["pt"].shape != ref.arrays["pt"].shape:
        return None
    p0 = float(ref.arrays["p0"])
    dt = float(np.max(np.abs(run.arrays["pt"] - ref.arrays["pt"]))) / (max(mu, 1e-300) * p0)
    dp = float(np.max(np.abs(run.arrays["pn"] - ref.arrays["pn"]))) / p0
    return max(dt, dp)



def ms(seconds) -> str:
    """Seconds as milliseconds with two decimals."""
    return f"{1e3 * seconds:.2f}"


def interleaved(repeats, cases: dict, measure, log=None) -> dict:
    """``{key: [measure(case) for each repetition]}``: the cases alternate within each repetition,
    so that a change of the machine's load hits all of them alike. ``repeats`` is a number, or a
    ``{key: number}`` (a case stops after its own count); ``log(key, i, n)`` after each run."""
    counts = repeats if isinstance(repeats, dict) else {k: repeats for k in cases}
    out = {k: [] for k in cases}
    for rep in range(max(1, max(counts.values()))):
        for key, case in cases.items():
            if rep < max(1, counts[key]):
                out[key].append(measure(case))
                if log is not None:
                    log(key, rep + 1, counts[key])
    return out


def fit_exponent(ns, ts, n_min=161):
    """Least-squares slope of log t against log n over the sizes ``n >= n_min`` (NaN if fewer than two)."""
    ns, ts = np.asarray(ns, dtype=float), np.asarray(ts, dtype=float)
    m = (ns >= n_min) & np.isfinite(ts) & (ts > 0)
    if m.sum() < 2:
        return float("nan")
    return float(np.polyfit(np.log(ns[m]), np.log(ts[m]), 1)[0])


def cholesky_time(n, repeats=5) -> float:
    """Median time of ``scipy.linalg.cho_factor`` of an SPD matrix of size ``n``: the dense floor."""
    import scipy.linalg
    rng = np.random.default_rng(0)
    M = rng.standard_normal((n, n))
    A = M @ M.T + n * np.eye(n)
    times = []
    for _ in range(repeats):
        B = A.copy(order="F")
        t0 = time.perf_counter()
        scipy.linalg.cho_factor(B, overwrite_a=True, check_finite=False)
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def write_sections(doc: Path, sections: dict) -> list[str]:
    """Replace ``<!-- bench:NAME -->`` … ``<!-- /bench:NAME -->`` blocks of ``doc``; names written."""
    text = doc.read_text()
    done = []
    for name, body in sections.items():
        pat = re.compile(rf"(<!-- bench:{re.escape(name)} -->\n).*?(<!-- /bench:{re.escape(name)} -->)", re.S)
        if pat.search(text):
            text = pat.sub(lambda mt: mt.group(1) + body.rstrip() + "\n" + mt.group(2), text)
            done.append(name)
    doc.write_text(text)
    return done


def step_records(scene, method, stop=None, keep=None):
    """``(record, wall seconds, CPU seconds)`` per rolling step of ``rollqp.march(scene, method)``.

    The times cover the whole step as the march makes it (loads, history vector, the step
    problems, the solves, ``w``). ``stop``: the last step marched (default: all); ``keep(k)``
    selects the steps returned. The starting state's record comes first, with its own times.
    """
    import rollqp
    out = []
    records = rollqp.march(scene, method=method)
    while True:
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            rec = next(records)
        except StopIteration:
            return out
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        if rec.k == 0 or keep is None or keep(rec.k):
            out.append((rec, wall, cpu))
        if stop is not None and rec.k >= stop:
            records.close()
            return out


def run_once(scene, method):
    """One ``rollqp.run``: wall and CPU time, stepping time and its parts, iterations, the largest
    residual, Carter's error (``rollqp.report.closed_form_errors``) and the number of steps."""
    import rollqp
    from rollqp.report import closed_form_errors
    t0, c0 = time.perf_counter(), time.process_time()
    res = rollqp.run(scene, method=method)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    arr = res.arrays()
    errs = {n: v for n, v, _ in closed_form_errors(arr, scene)}
    st = arr["step_time"]
    return dict(wall=wall, cpu=cpu, influence=float(res.meta["model"].get("influence_seconds", np.nan)),
                stepping=float(st.sum()), start=float(st[0]), rolling=float(st[1:].sum()),
                median=float(np.median(st[1:])), max=float(st[1:].max()), residual=float(arr["residual"].max()),
                iters=int(arr["iterations"].sum()), carter=errs.get("carter", float("nan")), K=len(st) - 1)


def medians(runs: list) -> dict:
    """The median of every numeric key over a list of result dicts (NaN ignored); other keys from the first."""
    out = {}
    for key, v in runs[0].items():
        if isinstance(v, (int, float, np.floating, np.integer)) and not isinstance(v, bool):
            vals = [r[key] for r in runs if not np.isnan(r[key])]
            out[key] = float(np.median(vals)) if vals else float("nan")
        else:
            out[key] = v
    return out


def goodman_bentall_scene():
    """``(scene, label)``: the built-in ``goodman-bentall`` (the paper's §6.2.1: 2β = 1, μ = 0.3,
    free rolling from the Goodman state, full coupling), shared by the coupled benchmarks."""
    import rollqp
    return rollqp.load_scene("goodman-bentall"), "built-in scene `goodman-bentall`"


def pyplot():
    """``matplotlib.pyplot`` (Agg), or a one-line error naming the ``plot`` extra."""
    from rollqp.plot import pyplot as _pyplot
    return _pyplot()


#: Pinned for the whole process at import (the limiter is kept alive here).
THREAD_LIMIT = pin_threads()
