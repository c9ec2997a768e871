#!/usr/bin/env python3
r"""rollqp's 3D steps as a test set for conic and friction-contact solvers (docs/conic-test-set.md).

::

    python benchmarks/conic_test_set.py [--out DIR] [--small] [--only CASES] [--run [--solver S] [--settings S]]
    python benchmarks/conic_test_set.py --out DIR --summarize
    python benchmarks/conic_test_set.py --out DIR --epigraph NAME   # Clarabel: CBF's epigraph against H itself

writes the set to ``DIR`` (default ``conic-test-set``)::

    DIR/cbf/NAME.cbf          each tangential SOCP and normal QP in the Conic Benchmark Format (version 3)
    DIR/data/NAME.npz         the same program's arrays (H, q, a, b, bound; rollqp.conicset.forms)
    DIR/fclib/NAME.hdf5       each coupled static step as an FCLib local problem, its solution in /solution
    DIR/solutions/NAME.npz    the certified solution and the map back to tractions
    DIR/problems.json, problems.md   the catalogue

and with ``--run`` runs every installed conic solver (Clarabel, SCS, ECOS, CVXOPT; natively on the CBF
file and through cvxpy) at default and high-accuracy settings, and the FCLib problems by the SOCP fixed
point (``socp-fp-clarabel``, ``socp-fp-scs``: rollqp.conicset.fcsocp): ``DIR/results/report.md``
(qpbenchmark's style: success rate, shifted geometric mean of time, accuracy against the certified
solutions), ``DIR/results/answers.jsonl`` and ``answers-fclib.jsonl`` (every solve). Needs the extra
``conicbench``.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from harness import machine_rows, pin_threads, table

pin_threads()

from rollqp.conicset import generate, report  # noqa: E402  (after the thread limit)
from rollqp.conicset import run as runner  # noqa: E402
from rollqp.conicset import cbf  # noqa: E402
from rollqp.conicset.forms import ProgramData  # noqa: E402


def _epigraph_study(out: Path, name: str) -> None:
    """Clarabel on one program two ways, tolerances 1e-8 … 1e-12: the CBF file (the quadratic objective
    as the rotated-cone epigraph) and the quadratic objective handed over as ``P = H``."""
    import clarabel
    import numpy as np
    import scipy.sparse as sp
    with np.load(out / "data" / f"{name}.npz") as z:
        d = ProgramData.from_arrays(z)
    x_star = np.load(out / "solutions" / f"{name}.npz")["x"]
    c, G, h, dims, Aeq, beq = cbf.standard_form(cbf.read(out / "cbf" / f"{name}.cbf"))
    cones = [clarabel.ZeroConeT(Aeq.shape[0])] * bool(Aeq.shape[0]) + \
        [clarabel.NonnegativeConeT(dims["l"])] * bool(dims["l"]) + [clarabel.SecondOrderConeT(q) for q in dims["q"]]
    nv = d.m // 2
    if d.kind == "normal":
        A2, b2, k2 = -sp.identity(d.m, format="csr"), np.zeros(d.m), [clarabel.NonnegativeConeT(d.m)]
    else:
        i = np.arange(nv)
        A2 = sp.csr_matrix((-np.ones(2 * nv), (np.r_[3 * i + 1, 3 * i + 2], np.r_[i, nv + i])), shape=(3 * nv, d.m))
        b2 = np.zeros(3 * nv)
        b2[3 * i] = d.bound
        k2 = [clarabel.SecondOrderConeT(3)] * nv
    A2 = sp.vstack([sp.csr_matrix(d.a), A2], format="csc")
    rows = []
    for tol in (1e-8, 1e-9, 1e-10, 1e-11, 1e-12):
        out_row = [f"{tol:.0e}"]
        for P, q, A, b, K in ((sp.csc_matrix((c.size, c.size)), c, sp.vstack([Aeq, G], format="csc"),
                               np.concatenate([beq, h]), cones),
                              (sp.triu(sp.csc_matrix(d.H), format="csc"), d.q, A2, np.concatenate([d.b, b2]),
                               [clarabel.ZeroConeT(d.k)] * bool(d.k) + k2)):
            st = clarabel.DefaultSettings()
            st.verbose = False
            st.tol_gap_abs = st.tol_gap_rel = st.tol_feas = tol
            sol = clarabel.DefaultSolver(P, q, A, b, K, st).solve()
            out_row += [f"{sol.status} ({sol.iterations})", f"{np.max(np.abs(np.asarray(sol.x)[:d.m] - x_star)):.1e}"]
        rows.append(out_row)
    print(f"{name}: Clarabel, max|x − x*| [p0] on the CBF epigraph and with P = H")
    print(table(["tolerance", "epigraph: status (iterations)", "max|x − x*|", "P = H: status (iterations)",
                 "max|x − x*|"], rows))


def _generate(args) -> dict:
    t0 = time.perf_counter()

    def said(name, probs):
        for p in probs:
            print(f"  {p.name:34s} {p.kind:10s} n = {p.meta['n']:5d}  residual {p.meta['residual']:.1e} "
                  f"(file {p.meta['residual_from_arrays']:.1e})  [{time.perf_counter() - t0:.0f} s]", flush=True)
    only = args.only.split(",") if args.only else None
    problems = generate.build(small=args.small, only=only, progress=said)
    generate.write_set(problems, args.out)
    catalogue = json.loads((Path(args.out) / "problems.json").read_text(encoding="utf-8"))
    (Path(args.out) / "problems.md").write_text(report.catalogue_table(catalogue) + "\n", encoding="utf-8")
    print(f"{len(problems)} problems written to {args.out} in {time.perf_counter() - t0:.0f} s")
    return catalogue


def _report(out: Path, answers, catalogue) -> None:
    machine = table(["", ""], machine_rows())
    text = report.report(answers, catalogue, machine)
    (out / "results" / "report.md").write_text(text + "\n", encoding="utf-8")
    print(text)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="conic-test-set")
    ap.add_argument("--small", action="store_true", help="the small set of the tests (seconds)")
    ap.add_argument("--only", help="comma-separated case names (" + ", ".join(generate.CASES) + ")")
    ap.add_argument("--run", action="store_true", help="run the solvers and write the report")
    ap.add_argument("--solver",
                    help="comma-separated solver routes (" + ", ".join(runner.SOLVERS + runner.FC_SOLVERS) + ")")
    ap.add_argument("--settings", help="comma-separated: default, high")
    ap.add_argument("--summarize", action="store_true", help="the report of the last run, again")
    ap.add_argument("--epigraph", metavar="NAME", help="Clarabel on one written program: epigraph against P = H")
    args = ap.parse_args(argv)
    out = Path(args.out)
    if args.epigraph:
        _epigraph_study(out, args.epigraph)
        return 0
    if args.summarize:
        catalogue = json.loads((out / "problems.json").read_text(encoding="utf-8"))
        lines = []
        for log in ("answers.jsonl", "answers-fclib.jsonl"):
            if (out / "results" / log).exists():
                lines += (out / "results" / log).read_text(encoding="utf-8").splitlines()
        _report(out, [runner.Answer(**json.loads(s)) for s in lines if s.strip()], catalogue)
        return 0
    catalogue = _generate(args)
    if args.run:
        wanted = args.solver.split(",") if args.solver else list(runner.SOLVERS + runner.FC_SOLVERS)
        unknown = [s for s in wanted if s not in runner.SOLVERS + runner.FC_SOLVERS]
        if unknown:
            print(f"unknown solver route(s) {', '.join(unknown)}; known: "
                  f"{', '.join(runner.SOLVERS + runner.FC_SOLVERS)}")
            return 2
        settings = tuple(args.settings.split(",")) if args.settings else runner.SETTINGS
        missing = [s for s in wanted if not runner.available(s)]
        if missing:
            print(f"not installed, skipped: {', '.join(missing)} (pip install -e '.[conicbench]')")

        def said(a):
            print(f"  {a.problem:30s} {a.solver:16s} {a.settings:8s} {'ok' if a.ok else a.status[:24]:24s} "
                  f"|x − x*| {a.dx:.1e}  residual {a.residual:.1e}  {a.time:.3f} s", flush=True)
        conic = [s for s in wanted if s in runner.SOLVERS and runner.available(s)]
        fc = [s for s in wanted if s in runner.FC_SOLVERS and runner.available(s)]
        answers = runner.run_set(out, conic, settings, progress=said) if conic else []
        answers += runner.run_fclib(out, fc, progress=said) if fc else []
        _report(out, answers, catalogue)
    return 0


if __name__ == "__main__":
    sys.exit(main())
