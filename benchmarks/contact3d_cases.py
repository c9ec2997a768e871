"""CONTACT's own 3D examples (``cattaneo``, ``catt_to_cart``, ``tractcurv``) set up on CONTACT's grids
and solved by rollqp's 3D Newton method: each function returns CONTACT's printed figures beside
rollqp's. Shared by ``tests/test_three_validation.py`` (tolerances) and
``benchmarks/three_validation.py --section contact`` (the tables of docs/validation3d.md).

The decks' parameters are CONTACT's own (its user guide's definitions): shear moduli G and
Poisson's ratios, the curvatures A and B of the undeformed distance, the normal force FN, the
friction coefficient FSTAT, the grid's DX, DY and its lower-left corner, creepages CKSI and the
rolling step DQ. CONTACT's output prints four digits.
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from rollqp.operators.grid import Contact, Loads
from rollqp.methods.newton.disc import NewtonMethod
from rollqp.discretization.grid import Grid
from rollqp.three.hertz import curvatures_for_ratio, hertz
from rollqp.march.grid import static_shift, steady, transient
from rollqp.materials import Materials

DATA = Path(__file__).resolve().parent.parent / "tests" / "data" / "contact3d"


def blocks(name: str) -> list:
    """The cases of CONTACT's reference output ``name.ref_out``, one text block each."""
    return (DATA / f"{name}.ref_out").read_text().split("\n Case ")[1:]


def cattaneo():
    """CONTACT's cattaneo case 2 (19 × 19, G = 200, ν = 0.42, μ = 0.4, Fx = −0.875 μFN): shift,
    approach, peak pressure and the contact/adhesion/slip counts, CONTACT's and rollqp's."""
    blk = blocks("cattaneo")[1]
    vals = re.search(r"FN/G\s+SHIFT X\s+SHIFT Y\s+APPROACH\s+PMAX\s*\n\s*(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)", blk)
    cnt = re.search(r"NSLIP\s+INORM\s+ITANG\n\s*(\d+)\s+(\d+)\s+(\d+)\s+(\d+)", blk)
    ref = dict(shift=float(vals.group(2)), delta=float(vals.group(4)), pmax=float(vals.group(5)),
               ncon=int(cnt.group(2)), nadh=int(cnt.group(3)), nslip=int(cnt.group(4)))
    m = Materials.from_shear(200.0, 0.42, 200.0, 0.42)
    c = Contact(Grid(19, 19, 0.13333, 0.13333, -1.26667, -1.26667), m, (0.01, 0.01), 9.1954, 0.4)
    rec = static_shift(c, NewtonMethod(), 9.1954, Fx=-0.875 * 0.4 * 9.1954)[-1]
    ours = dict(shift=rec.info["shift"][0], delta=rec.delta, pmax=float(rec.p.max()), ncon=int(np.sum(rec.p > 0)),
                nadh=int(np.sum(rec.state == 1)), nslip=int(np.sum(rec.state == 2)))
    return ref, ours


def catt_to_cart(steps: int):
    """CONTACT's catt_to_cart, first sequence (34 × 33, braked at Fx = −0.657 μFN, then ``steps``
    rolling steps with DQ = DX): ``[(shift or creepage, adhesion count, slip count)]`` per case."""
    ref = []
    for blk in blocks("catt_to_cart")[:steps + 1]:
        v = re.search(r"(?:SHIFT|CREEP) X.*\n\s*(\S+)\s+(\S+)", blk)
        cnt = re.search(r"Tang: final element division: A, S=\s+(\d+)\s+(\d+)", blk)
        ref.append((float(v.group(2)), int(cnt.group(1)), int(cnt.group(2))))
    m = Materials.from_shear(1.0, 0.28, 1.0, 0.28)
    c = Contact(Grid(34, 33, 0.25, 0.25, -4.125, -4.125), m, (0.002963, 0.002963), 0.4705, 0.4013)
    Fx = -0.657 * 0.4013 * 0.4705
    start = static_shift(c, NewtonMethod(), 0.4705, Fx=Fx)[-1]
    ours = [(start.info["shift"][0], int(np.sum(start.state == 1)), int(np.sum(start.state == 2)))]
    for rec in transient(c, NewtonMethod(), 0.4705, Loads(Fx=Fx, eta=0.0), 0.25, steps, -1, start=start):
        if rec.k > 0:
            ours.append((rec.xi, int(np.sum(rec.state == 1)), int(np.sum(rec.state == 2))))
    return ref, ours


def tractcurv(cases: int):
    """CONTACT's tractcurv series 1 (48 × 44, a/b = 0.5, μ = 0.33, steady, CKSI prescribed): CONTACT's
    ``[(CKSI, FX, adhesion count, slip count)]`` and rollqp's ``[(Fx, adhesion count, slip count)]``."""
    ref = []
    for blk in blocks("tractcurv")[:cases]:
        kin = re.search(r"CKSI\s+CETA\s+CPHI\n\s*\S+\s+\S+\s+\S+\s+(\S+)", blk)
        tot = re.search(r"FRIC.POWER\n\s*\S+\s+(\S+)", blk)
        cnt = re.search(r"NSLIP\s+INORM\s+ITANG\n\s*(\d+)\s+(\d+)\s+(\d+)\s+(\d+)", blk)
        ref.append((float(kin.group(1)), float(tot.group(1)), int(cnt.group(3)), int(cnt.group(4))))
    m = Materials.from_shear(82000.0, 0.28, 82000.0, 0.28)
    A = 0.0008
    B = curvatures_for_ratio(A, 0.5)
    e = hertz(A, B, m.Estar, 106700.0)
    c = Contact(Grid(48, 44, 2.2 * e.a / 48, 2.2 * e.b / 44, -1.1 * e.a, -1.1 * e.b), m, (A, B), 106700.0, 0.33)
    newton = NewtonMethod()
    p = newton.solve(c.normal_step(106700.0))
    ours, warm = [], None
    for xi, *_ in ref:
        warm = steady(c, newton, 106700.0, Loads(xi=xi, eta=0.0), -1, start=warm, pressure=p)
        ours.append((warm.Fx, int(np.sum(warm.state == 1)), int(np.sum(warm.state == 2))))
    return ref, ours
