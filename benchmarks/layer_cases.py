"""The interface layer's reference cases, shared by ``tests/test_interface_layer.py``, ``tests/test_tractcurv.py``
(tolerances) and ``benchmarks/three_validation.py --section layer|tractcurv`` (the tables of docs/validation3d.md):
a layer that dominates the bodies against the brush's closed form (:mod:`rollqp.closedforms.brush`) in 3D and on the
strip, and CONTACT's tractcurv series 3 (FASTSIM) beside rollqp's ``fastsim``."""
from __future__ import annotations

import numpy as np

import contact3d_cases as cc
import rollqp
from rollqp.closedforms import brush_creep_ratio
from rollqp.discretization.grid import Grid
from rollqp.materials import Materials
from rollqp.methods.fastsim import FastsimMethod
from rollqp.methods.newton.disc import NewtonMethod
from rollqp.operators.grid import Contact, Loads
from rollqp.closedforms.hertz_ellipse import hertz
from rollqp.march.grid import steady

#: The brush's κ = k|ξ|a/(μp0) of the checks: mostly stick, and stick and slip alike.
KAPPAS = (0.3, 1.0)


def brush_3d(n: int, eps: float = 1e-4):
    """A circle (E = 210 GPa, ν = 0.25, FN = 1 kN, R = 30 mm on a plane, μ = 0.3) under a layer 1/eps times as
    compliant as the bodies' a/G, on n × n elements over 1.1·(a, b) (the leading edge on an element edge on the
    axis): ``(F/(μFN)/brush − 1 at each κ of KAPPAS, dx)``."""
    m = Materials.from_young(210e3, 0.25, 210e3, 0.25)
    A, FN, mu = 1 / 60, 1000.0, 0.3
    e = hertz(A, A, m.Estar, FN)
    comp = e.a / m.G / eps
    c = Contact(Grid.for_ellipse(e.a, e.b, (n, n), (1.1, 1.1)), m, (A, A), FN, mu,
                layer={"thickness": comp, "shear_modulus": 1.0})
    newton = NewtonMethod()
    p = newton.solve(c.normal_step(FN))
    errs = []
    for kappa in KAPPAS:
        xi = kappa * mu * e.p0 * comp / e.a
        r = steady(c, newton, FN, Loads(xi=xi, eta=0.0), -1, pressure=p)
        errs.append(r.Fx / (mu * FN) / brush_creep_ratio(xi, e.a, e.p0, mu, 1 / comp) - 1)
    return np.array(errs), c.grid.dx


def brush_strip(n: int, eps: float = 1e-4):
    """The same on the strip: the built-in ``cattaneo-carter`` rolling steadily with a creepage, constant elements
    over ±1.1 a_H (the leading edge on a node), a layer 1/eps times as compliant as a_H/E*: ``(errors, element)``."""
    base = rollqp.load_scene("cattaneo-carter").replace(**{
        "load.start": "rolling", "discretization.distance": 0.0, "load.tangential": None, "load.creepage": 1e-6,
        "discretization.elements": n, "discretization.element": "constant", "discretization.zone": 1.1})
    comp = base.a_H / base.Estar / eps
    mu = base.contact.mu
    errs = []
    for kappa in KAPPAS:
        xi = kappa * mu * base.p0 * comp / base.a_H
        s = base.replace(**{"contact.layer": {"thickness": comp, "shear_modulus": 1.0}, "load.creepage": xi})
        Q = float(rollqp.run(s).arrays()["Q"][0])
        errs.append(Q / (mu * base.load.normal) / brush_creep_ratio(xi, base.a_H, base.p0, mu, 1 / comp) - 1)
    return np.array(errs), 2 * 1.1 * base.a_H / n


def order(errors, hs) -> float:
    """The exponent of ``err ∝ h^k`` from the first grid to the last."""
    return float(np.log(abs(errors[0] / errors[-1])) / np.log(hs[0] / hs[-1]))


def tractcurv_fastsim():
    """CONTACT's tractcurv series 3 (original FASTSIM, μ = 0.33) beside rollqp's ``fastsim`` on CONTACT's grid:
    ``[(CKSI, CONTACT's FX, rollqp's Fx)]``."""
    d, ref = cc.deck(), cc.reference_forces()
    idx = [i for i, c in enumerate(d) if c["series"] == 3]
    c0 = d[idx[0]]
    c = cc.tractcurv_contact(c0, c0["FKIN"], layer=False)
    fs = FastsimMethod()
    fs.setup(c)
    p = NewtonMethod().solve(c.normal_step(c0["FN"]))
    return [(d[i]["CKSI"], ref[i][1], steady(c, fs, c0["FN"], Loads(xi=d[i]["CKSI"], eta=0.0), -1, pressure=p).Fx)
            for i in idx]
