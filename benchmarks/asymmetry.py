"""Newton against the QP backends beside the measured asymmetry of F·A.

On piecewise-constant elements on a uniform grid F·A is exactly symmetric and the
collocation step problem *is* a convex QP: Newton and the QP backends must agree to solver
tolerance. On linear and quadratic elements F·A is not symmetric. rollqp's QP backends then
solve the collocation problem itself by symmetric–skew splitting (``operator="exact"``), so
they still agree with Newton to solver tolerance; the single symmetrized QP
(``operator="symmetrized"``) solves another discrete problem, and its difference from
Newton is what the asymmetry costs. This script prints both, per element type and mesh,
for the §6.1.1 transient (similar bodies) and a §6.2.1-like coupled transient (β ≈ 0.5,
N–T alternation with OSQP halves)::

    python benchmarks/asymmetry.py
"""
from __future__ import annotations

import numpy as np
import harness  # noqa: F401  (pins BLAS first)

import rollqp
from rollqp.operators import SceneOperators
from rollqp.histories import Constant
from rollqp.methods import get_method
from rollqp.influence.operator import asymmetry


def similar(element, elements):
    return rollqp.load_scene("cattaneo-carter").replace(**{
        "discretization.element": element, "discretization.elements": elements,
        "discretization.distance": 3.0})


def coupled(element, elements):
    return rollqp.load_scene("cattaneo-carter").replace(**{
        "bodies.A.E": 1000.0, "bodies.A.nu": 0.0, "bodies.B.E": 1e9, "bodies.B.nu": 0.3,
        "contact.friction": 0.3, "load.tangential": Constant(0.0), "load.start_steps": 10,
        "discretization.step": 0.25, "discretization.element": element,
        "discretization.elements": elements, "discretization.distance": 2.0})


def run_with(scene, operator):
    """Run ``scene`` with OSQP (alternation if coupled) and the given QP operator."""
    return rollqp.run(scene, method=get_method("qp-osqp", tolerance=scene.solver.tolerance, operator=operator))


def print_table(make, label):
    print(f"\n### {label}\n")
    print("| element | n elem | asym(F·A_nn) | max |Δp| exact QP (p0) | max |Δt| exact QP (μp0) "
          "| max |Δp| symmetrized QP (p0) | max |Δt| symmetrized QP (μp0) |")
    print("|---|---|---|---|---|---|---|")
    for element in ("constant", "linear", "quadratic"):
        for elements in (20, 40, 80):
            scene = make(element, elements)
            mu, p0 = scene.contact.friction, scene.p0
            model = SceneOperators.build(scene)
            asym = asymmetry(model.Ann, model.f)
            ref = rollqp.run(scene, method="newton")
            ex = run_with(scene, "exact")
            try:
                sy = run_with(scene, "symmetrized")
                dps = np.max(np.abs(sy["pn"] - ref["pn"])) / p0
                dts = np.max(np.abs(sy["pt"] - ref["pt"])) / (mu * p0)
                sym = f"{dps:.1e} | {dts:.1e}"
            except rollqp.RollqpError as err:  # e.g. the checkerboard leaves the zone
                sym = f"fails: {str(err)[:40]} | –"
            dp = np.max(np.abs(ex["pn"] - ref["pn"])) / p0
            dt = np.max(np.abs(ex["pt"] - ref["pt"])) / (mu * p0)
            print(f"| {element} | {elements} | {asym:.2e} | {dp:.1e} | {dt:.1e} | {sym} |")


def main():
    print_table(similar, "Similar bodies (§6.1.1, 3 a_H, every step)")
    print_table(coupled, "Dissimilar, full coupling (β ≈ 0.5, μ = 0.3, 2 a_H, every step)")


if __name__ == "__main__":
    main()
