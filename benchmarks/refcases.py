"""Reference cases of CONTACT (Vollebregt & Kalker) and the paper's §6.1.1 convergence problem, as scenes.

Two problems for which CONTACT (Vollebregt & Kalker), the field's reference code, has results
(``tests/data/contact/README.md`` in the source repository; docs/validation.md):

* :func:`contact_scene`: CONTACT's 2D Cattaneo → Carter problem of similar cylinders
  (G = 82000, ν = 0.28, R = 500 mm as two cylinders of radius 1000 mm, FN' = 178.896248 N/mm
  so that a_H = 1 mm, μ = 0.1), by default on CONTACT's grid: 88 constant elements on
  ±1.1 a_H, Δq = one element, material form.
* :func:`bentall_scene`: CONTACT's ``bentall`` case (examples/bentall.inp): R_A = R_B = 50 mm,
  aluminium body 1 = rollqp's A (G = 23000, ν = 0.31) on steel (G = 82000, ν = 0.28),
  FN = 16201.9 N on a DY = 1000 mm strip (16.2019 N/mm, a_H = 0.1 mm), free rolling in the
  steady state, Δq = Le; :func:`bentall_contact_grid` puts it on CONTACT's grid (216 constant
  elements of DX = 0.001 mm from XL = −0.108 mm, CHI = 180°, i.e. rollqp's d = +1).

:func:`convergence_errors` is the paper's §6.1.1 problem on a refined mesh against Hertz,
Cattaneo and Carter (docs/validation.md, "Convergence").

One copy of each, so that the tests (tests/test_contact.py, tests/test_bentall.py) and the
benchmarks that print docs/validation.md (benchmarks/validation.py, benchmarks/bentall.py)
always describe the same problem.
"""
from __future__ import annotations

import os
from pathlib import Path

from rollqp import closedforms as cf
from rollqp.report import rms_in_contact
from rollqp.scene import Scene, load_scene, scene_from_dict

#: CONTACT's result files, shipped with the source repository in ``tests/data/contact`` (numbers
#: computed with CONTACT, Apache-2.0; README and LICENSE there); ``$ROLLQP_CONTACT_REFDATA``
#: points elsewhere.
REFDATA = Path(os.environ.get("ROLLQP_CONTACT_REFDATA",
                              Path(__file__).resolve().parents[1] / "tests" / "data" / "contact"))

# ---------------------------------------------------------------- Cattaneo → Carter (similar)
G_CONTACT, NU_CONTACT = 82000.0, 0.28
E_CONTACT = 2.0 * G_CONTACT * (1.0 + NU_CONTACT)  # 209920
FN_CONTACT = 178.896248   # N/mm: a_H = 1 mm on R = 500 mm
MU_CONTACT = 0.1
RATIO_CONTACT = 0.75      # Q/(μP)


def contact_scene(elements=88, ratio=RATIO_CONTACT, start="braked", distance=4.0, mu=MU_CONTACT,
                  method="qp-osqp", zone=1.1, step=1.0, element="constant") -> Scene:
    """CONTACT's Cattaneo → Carter problem as a rollqp scene (default: CONTACT's 88-element grid)."""
    return scene_from_dict({
        "name": "contact-reference",
        "description": "CONTACT's 2D Cattaneo-Carter problem on CONTACT's grid",
        "bodies": {"A": {"radius": 1000.0, "E": E_CONTACT, "nu": NU_CONTACT},
                   "B": {"radius": 1000.0, "E": E_CONTACT, "nu": NU_CONTACT}},
        "contact": {"friction": mu},
        "load": {"normal": FN_CONTACT, "tangential": {"kind": "constant", "value": ratio},
                 "start": start, "direction": -1},
        "discretization": {"elements": elements, "element": element, "zone": zone, "step": step,
                           "formulation": "material", "distance": distance},
        "solver": {"method": method, "tolerance": 1e-10}})


# ---------------------------------------------------------------- Bentall–Johnson (dissimilar)
G_AL, NU_AL = 23000.0, 0.31   # aluminium, CONTACT's body 1
G_ST, NU_ST = 82000.0, 0.28   # steel, CONTACT's body 2
ALUMINIUM = {"radius": 50.0, "E": 2.0 * G_AL * (1.0 + NU_AL), "nu": NU_AL}
STEEL = {"radius": 50.0, "E": 2.0 * G_ST * (1.0 + NU_ST), "nu": NU_ST}
FN_BENTALL = 16.2019          # N/mm: CONTACT's 16201.9 N over DY = 1000 mm
CONTACT_XL, CONTACT_DX, CONTACT_MX = -0.108, 0.001, 216   # mm: CONTACT's bentall grid


def bentall_scene(mu, elements=80, element="constant", coupling="goodman", direction=-1, zone=1.1,
                  swap=False, method="newton", P=FN_BENTALL) -> Scene:
    """Aluminium (A) on steel (B), free rolling, steady (rolling start), Δq = Le."""
    A, B = (STEEL, ALUMINIUM) if swap else (ALUMINIUM, STEEL)
    return scene_from_dict({
        "name": "bentall", "description": "aluminium on steel, free rolling (Bentall-Johnson)",
        "bodies": {"A": A, "B": B},
        "contact": {"friction": mu, "coupling": coupling},
        "load": {"normal": P, "tangential": {"kind": "constant", "value": 0.0}, "start": "rolling",
                 "direction": direction},
        "discretization": {"elements": elements, "element": element, "zone": zone, "step": 1.0,
                           "formulation": "material", "distance": 0.0},
        "solver": {"method": method, "tolerance": 1e-10}})


def bentall_contact_grid(mu, coupling, dx=CONTACT_DX, method="newton") -> Scene:
    """The bentall case on CONTACT's strip ±0.108 mm with elements of ``dx`` mm, d = +1 (CHI = 180°)."""
    n = int(round(-2 * CONTACT_XL / dx))
    s = bentall_scene(mu, elements=n, coupling=coupling, direction=+1, method=method)
    return s.replace(**{"discretization.zone": -CONTACT_XL / s.a_H})


# ---------------------------------------------------------------- convergence (§6.1.1)
def convergence_errors(element, n, method="qp-osqp") -> dict:
    """Errors on ``n`` elements of §6.1.1 (zone ±1.25 a_H, so a_H is an element edge for every
    ``n`` used; Δq = Le/2): Hertz and Cattaneo at q = 0 of a braked start with no rolling
    (distance 0), Carter and its creepage in steady rolling (``start = "rolling"``); rms over
    ``|x| <= a_H``, in p0 and μp0, and ``|ξ/ξ_Carter − 1|``."""
    base = load_scene("cattaneo-carter")
    s = base.replace(**{"discretization.elements": n, "discretization.element": element,
                        "discretization.distance": 0.0, "solver.method": method})
    from rollqp.march import run
    r = run(s).arrays()
    if len(r["q"]) != 1:
        raise AssertionError("distance 0: the starting state only")
    x, a, p0, mu, R = r["x"], s.a_H, s.p0, s.contact.friction, s.R
    ratio = float(r["Q"][0]) / (mu * float(r["P"][0]))  # the scene's Q/(μP), 0.75
    out = {"hertz": rms_in_contact(x, a, r["pn"][0] - cf.hertz_pressure(x, a, p0)) / p0,
           "cattaneo": rms_in_contact(x, a, r["pt"][0] - cf.cattaneo_traction(x, a, p0, mu, ratio)) / (mu * p0)}
    r = run(s.replace(**{"load.start": "rolling"})).arrays()
    out["carter"] = rms_in_contact(x, a, r["pt"][0] - cf.carter_traction(x, a, p0, mu, ratio, -1)) / (mu * p0)
    out["creepage"] = abs(float(r["creepage"][0]) / cf.carter_creepage(a, R, mu, ratio) - 1)
    return out
