"""The friction laws' reference problems as scenes: CONTACT's falling-friction deck, a patch through Carter.

One copy of each, for the tests (tests/test_friction.py), the gallery (examples/friction_*.py) and
docs/friction.md.

* :func:`veldep_scene`: CONTACT's ``veldep_fric`` example (tests/data/contact/examples/veldep_fric.inp;
  Vollebregt & Schuttelaars, J. Sound Vib. 331 (2012) 2141): wheel R = 460 mm on a flat rail (here two
  cylinders of 920 mm: the same R), G = 82000, ν = 0.28, FN = 622216 N on DY = 200 mm (3111.08 N/mm),
  92 constant elements of DX = 0.1 mm on ±4.6 mm, creepage CKSI = −0.0009999, V = 45000 mm/s,
  exponential law μ = 0.18 + 0.12 exp(−v/100 mm/s); CHI = 0, i.e. rollqp's d = −1 (docs/validation.md).
* :func:`patch_scene`: CONTACT's Carter problem (refcases.contact_scene) with a patch of low
  friction carried by the material through the contact.
"""
from __future__ import annotations

from refcases import E_CONTACT, NU_CONTACT, contact_scene
from rollqp.scene import scene_from_dict

__all__ = ["VELDEP", "veldep_scene", "patch_scene"]

#: CONTACT's veldep_fric case 1 (its inputs, and its steady result FX/(FSTAT FN)).
VELDEP = dict(FN=622216.0 / 200.0, R=460.0, CKSI=-0.0009999, V=45000.0, FKIN=0.18, FEXP1=0.12, SABSH1=100.0,
              MX=92, XL=4.6, ratio_case1=0.5941)


def veldep_scene(elements=VELDEP["MX"], creepage=VELDEP["CKSI"], law="exponential", static=None, kinetic=None,
                 velocity=VELDEP["SABSH1"], memory=0.0, start="rolling", distance=0.0, method="newton",
                 zone_mm=VELDEP["XL"], step=1.0, tangential=None):
    """CONTACT's falling-friction problem (module docstring); ``tangential`` (Q/(μ_s P̄)) instead of the creepage."""
    from rollqp.closedforms import hertz_half_width
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
    return scene_from_dict({
        "name": "contact-veldep",
        "description": "CONTACT's veldep_fric: falling (exponential) friction, wheel on rail, 45 m/s",
        "bodies": {"A": {"radius": 2 * VELDEP["R"], "E": E_CONTACT, "nu": NU_CONTACT},
                   "B": {"radius": 2 * VELDEP["R"], "E": E_CONTACT, "nu": NU_CONTACT}},
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
