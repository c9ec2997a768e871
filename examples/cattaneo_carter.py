"""The paper's §6.1.1 example through the Python API: from Cattaneo to Carter.

Similar steel rollers braked at Q/(μP) = 0.75 (Cattaneo's traction), then rolling 6 a_H to
Carter's steady state. The built-in scene ``cattaneo-carter`` is run with :func:`rollqp.run`
and the result is held against the closed forms (rollqp.report.closed_form_errors): Hertz and
Cattaneo at q = 0, Carter's traction and creepage at the end.

Run it::

    python examples/cattaneo_carter.py [METHOD]
"""
from __future__ import annotations

import sys
import time

import rollqp
from rollqp.report import closed_form_errors


def main(method=None, out=None):
    scene = rollqp.load_scene("cattaneo-carter")
    t0 = time.perf_counter()
    result = rollqp.run(scene, method=method)
    wall = time.perf_counter() - t0
    res = result.arrays()
    name = method or scene.solver.method
    print(f"{scene.name}: {scene.description}")
    print(f"  {name}, {len(res['q']) - 1} rolling steps + starting state in {wall:.2f} s, "
          f"max residual {res['residual'].max():.1e}")
    errors = {}
    for key, value, what in closed_form_errors(res, scene):
        errors[key] = value
        print(f"  error {key:<10} {value:.4f}   {what}")
    if out:
        result.save(out)
        print(f"  result written to {out}")
    return {"errors": errors, "result": res, "scene": scene}


if __name__ == "__main__":
    results = main(sys.argv[1] if len(sys.argv) > 1 else None)
