"""The friction laws' reference problems as scenes: CONTACT's falling-friction deck, a patch through Carter.

One copy of each, for the tests (tests/test_friction.py), the gallery (examples/friction_*.py) and
docs/friction.md.

* :func:`veldep_scene`: CONTACT's ``veldep_fric`` example (tests/data/contact/examples/veldep_fric.inp;
  Vollebregt & Schuttelaars, J. Sound Vib. 331 (2012) 2141): wheel R = 460 mm on a flat rail (here two
  cylinders of 920 mm: the same R), G = 82000, ν = 0.28, FN = 622216 N on DY = 200 mm (3111.08 N/mm),
  92 constant elements of DX = 0.1 mm, creepage CKSI = −0.0009999, V = 45000 mm/s, exponential law
  ``FKIN + FEXP1·exp(−ln 2·v/SABSH1)`` = 0.18 + 0.12 exp(−ln 2·v/100 mm/s); CHI = 0, i.e. rollqp's d = −1
  (docs/validation.md). CONTACT's grid has its first element *centre* at XC1 = −4.6 mm: it covers
  −4.65 … 4.55 mm, half an element off the wheel's centre; ``grid="contact"`` (the default) puts the
  wheel half an element off rollqp's symmetric strip likewise (:func:`offset_profile`).
* :func:`contact_velocity`: CONTACT's SABSH1 (the slip velocity at which the falling term is *halved*)
  as rollqp's ``velocity`` ``v_h`` of each law (docs/friction.md).
* :func:`patch_scene`: CONTACT's Carter problem (refcases.contact_scene) with a patch of low
  friction carried by the material through the contact.
"""
from __future__ import annotations

import math

import numpy as np
from refcases import E_CONTACT, NU_CONTACT, contact_scene

from rollqp.errors import InputError
from rollqp.scene import scene_from_dict

__all__ = ["VELDEP", "veldep_scene", "patch_scene", "contact_velocity", "offset_profile"]

#: CONTACT's veldep_fric case 1 (its inputs, and its steady result FX/(FSTAT FN)).
VELDEP = dict(FN=622216.0 / 200.0, R=460.0, CKSI=-0.0009999, V=45000.0, FKIN=0.18, FEXP1=0.12, SABSH1=100.0,
              MX=92, XL=4.6, ratio_case1=0.5941)


def contact_velocity(law, sabsh1):
    """rollqp's ``velocity`` ``v_h`` for CONTACT's SABSH1 of the law (L = 2, 3, 4 with one term).

    CONTACT's terms are halved at ``v = SABSH1``: linear ``max(0, 1 − v/(2 SABSH1))``, rational
    ``1/(1 + v/SABSH1)``, exponential ``exp(−ln 2 · v/SABSH1)``; rollqp's are ``max(0, 1 − v/v_h)``,
    ``1/(1 + v/v_h)``, ``exp(−v/v_h)``, so ``v_h`` = 2 SABSH1, SABSH1 and SABSH1/ln 2.

    Examples
    --------
    >>> round(contact_velocity("exponential", 100.0), 4), contact_velocity("linear", 100.0)
    (144.2695, 200.0)
    """
    factors = {"linear": 2.0, "rational": 1.0, "exponential": 1.0 / math.log(2.0)}
    if law not in factors:
        raise InputError("law", f"CONTACT's SABSH1 maps to 'linear', 'rational' or 'exponential', not {law!r}")
    return factors[law] * float(sabsh1)


def offset_profile(offset, radius=VELDEP["R"], half_width=VELDEP["XL"] + 0.1, points=9401):
    """A contact-frame table for body A that, with body B's circle of ``2 radius``, gives the gap of a wheel of
    ``radius`` on a flat rail centred at ``x = offset`` (``z(x − offset)``; circle heights of
    :func:`rollqp.profiles.circle_height`, linear between ``points`` points on ``±half_width``: 2e-9 mm at
    most from the circle, 1e-7 of the gap at the contact's edge)."""
    from rollqp.profiles import circle_height
    x = np.linspace(-half_width, half_width, points)
    h = circle_height(x - offset, radius) - circle_height(x, 2.0 * radius)
    return {"kind": "table", "x": x.tolist(), "h": h.tolist()}


def veldep_scene(elements=VELDEP["MX"], creepage=VELDEP["CKSI"], law="exponential", static=None, kinetic=None,
                 velocity=None, memory=0.0, start="rolling", distance=0.0, method="newton",
                 zone_mm=VELDEP["XL"], step=1.0, tangential=None, grid="contact"):
    """CONTACT's falling-friction problem (module docstring); ``tangential`` (Q/(μ_s P̄)) instead of the creepage.

    ``velocity``: rollqp's ``v_h`` (default CONTACT's SABSH1 = 100 mm/s mapped by :func:`contact_velocity`);
    ``grid``: ``"contact"`` (the wheel half an element off the strip's centre, as on CONTACT's grid whose
    first element centre is at XC1 = −XL) or ``"symmetric"`` (the wheel at the strip's centre)."""
    from rollqp.closedforms import hertz_half_width
    if grid not in ("contact", "symmetric"):
        raise InputError("grid", f"must be 'contact' or 'symmetric', got {grid!r}")
    if velocity is None:
        velocity = contact_velocity(law, VELDEP["SABSH1"])
    Estar = E_CONTACT / (2.0 * (1.0 - NU_CONTACT ** 2))
    a = hertz_half_width(VELDEP["FN"], VELDEP["R"], Estar)
    st = VELDEP["FKIN"] + VELDEP["FEXP1"] if static is None else static
    kin = VELDEP["FKIN"] if kinetic is None else kinetic
    fr = {"law": law, "static": st, "kinetic": kin, "velocity": velocity, "rolling_speed": VELDEP["V"]}
    if memory:
        fr["memory"] = memory
    load = {"normal": VELDEP["FN"], "start": start, "direction": -1}
    if tangential is None:
        load["creepage"] = {"kind": "constant", "value": creepage}
    else:
        load["tangential"] = tangential if isinstance(tangential, dict) else {"kind": "constant", "value": tangential}
    A = {"radius": 2 * VELDEP["R"], "E": E_CONTACT, "nu": NU_CONTACT}
    if grid == "contact":  # CONTACT's element centres at XC1 + i DX: the wheel half an element off the strip's centre
        A["profile"] = offset_profile(zone_mm / elements, half_width=zone_mm + 2.0 * zone_mm / elements)
    return scene_from_dict({
        "name": "contact-veldep",
        "description": "CONTACT's veldep_fric: falling (exponential) friction, wheel on rail, 45 m/s",
        "bodies": {"A": A, "B": {"radius": 2 * VELDEP["R"], "E": E_CONTACT, "nu": NU_CONTACT}},
        "contact": {"friction": fr},
        "load": load,
        "discretization": {"elements": elements, "element": "constant", "zone": zone_mm / a, "step": step,
                           "formulation": "material", "distance": distance},
        "solver": {"method": method, "tolerance": 1e-10}})


def patch_scene(mu=0.1, inside=0.05, start=2.0, end=2.5, elements=88, ratio=0.5, distance=8.0, method="newton",
                frame="material"):
    """CONTACT's Cattaneo → Carter problem (``refcases.contact_scene``) with a patch ``[start, end]``
    (a_H units, at q = 0) of coefficient ``inside`` carried by the material through the contact."""
    base = contact_scene(elements=elements, ratio=ratio, distance=distance, mu=mu, method=method)
    return base.replace(**{"contact.friction": {"law": "patch", "mu": mu, "inside": inside, "start": start,
                                                "end": end, "frame": frame},
                           "name": "patch-through-carter"})


#: The ramped falling-friction transient of docs/friction.md (rational law, v_h = 3 mm/s, V = 10 m/s, force
#: ramped to 0.5 μ_s P over 0.9 a_H from a braked start): the tests run its first 0.75 a_H, the velocity
#: sweep of benchmarks/friction_study.py 4.5 a_H with other laws and scales.
FALLING_RAMP = {
    "name": "falling-singular",
    "bodies": {"A": {"radius": 500.0, "E": 209920.0, "nu": 0.28}, "B": {"radius": 500.0, "E": 209920.0, "nu": 0.28}},
    "contact": {"friction": {"law": "rational", "static": 0.32, "kinetic": 0.20, "velocity": 3.0,
                             "rolling_speed": 10000.0}},
    "load": {"normal": 357.79249665883754, "tangential": {"kind": "ramp", "start": 0.0, "end": 0.5, "over": 0.9},
             "start": "braked", "direction": -1},
    "discretization": {"elements": 80, "element": "constant", "zone": 1.2, "step": 1.0, "formulation": "material",
                       "distance": 0.75},
    "solver": {"method": "newton", "tolerance": 1e-10},
}
