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
from rollqp.closedforms.hertz_ellipse import curvatures_for_ratio, hertz
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


# ------------------------------------------------------------------------------ the tractcurv deck
#: The names of a deck line's values where its label does not list one name per value.
_LABELS = {"POISS 1,2, GG 1,2": ("POISS1", "POISS2", "GG1", "GG2"),
           "FKIN, FEXP1,SABSH1, FE2,SH2": ("FKIN", "FEXP1", "SABSH1", "FEXP2", "SABSH2")}


def deck(name: str = "tractcurv") -> list:
    """CONTACT's input deck ``name.inp`` as one dict per case (module 3): every value by its name, as CONTACT keeps
    them from case to case (a case's lines set only what its control digits ask for; the rest carries over), the
    control digits (``P``, ``B``, ``T``, ``N``, ``F``, ``S``; ``L``, ``D``, ``C``, ``M``, ``Z``, ``E``; ``H``, ``G``, …)
    by letter, and ``series`` (1, 2, …: a case whose ``D`` digit sets a new grid starts one). The deck's lines carry
    their names (``106700. 0.0004 0.000 0.000  FN, CKSI, CETA, CPHI``), so the parser reads names, not positions."""
    cases, state, series = [], {}, 0
    current = None
    for raw in (DATA / f"{name}.inp").read_text().splitlines():
        line = raw.split("%", 1)[0].strip()
        if not line:
            continue
        if line.endswith("MODULE"):
            if current is not None:
                cases.append(current)
            if int(line.split()[0]) == 0:
                current = None
                break
            current = {}
            continue
        fields = line.split()
        digits = re.fullmatch(r"\d+", fields[0]) and re.fullmatch(r"[A-Z](-[A-Z])+", fields[1] if len(fields) > 1 else "")
        if digits:
            letters = fields[1].split("-")
            code = fields[0].rjust(len(letters), "0")
            for letter, digit in zip(letters, code):
                current[letter] = int(digit)
            if letters[:2] == ["L", "D"] and current["D"] != 0:
                series += 1
            continue
        numbers = []
        for f in fields:
            try:
                numbers.append(float(f))
            except ValueError:
                break
        label = " ".join(fields[len(numbers):])
        names = _LABELS.get(label) or tuple(n for n in re.split(r"[,\s]+", label) if n)
        if len(names) < len(numbers):
            raise ValueError(f"{name}.inp: line {raw!r}: {len(numbers)} values for the names {names}")
        state.update(zip(names, numbers))
        current.update(zip(names, numbers))
        current["series"] = series
    if current is not None:
        cases.append(current)
    out = []
    for c in cases:     # each case: the state as CONTACT holds it then (its own lines over the carried values)
        state_c = {**(out[-1] if out else {}), **c}
        out.append(state_c)
    return out


def reference_forces(name: str = "tractcurv") -> list:
    """``[(CKSI, FX, adhesion count, slip count)]`` of every case of CONTACT's ``name.ref_out``."""
    ref = []
    for blk in blocks(name):
        kin = re.search(r"CKSI\s+CETA\s+CPHI\n\s*\S+\s+\S+\s+\S+\s+(\S+)", blk)
        tot = re.search(r"FRIC.POWER\n\s*\S+\s+(\S+)", blk)
        cnt = re.search(r"NSLIP\s+INORM\s+ITANG\n\s*(\d+)\s+(\d+)\s+(\d+)\s+(\d+)", blk)
        ref.append((float(kin.group(1)), float(tot.group(1)), int(cnt.group(3)), int(cnt.group(4))))
    return ref


def tractcurv_contact(case: dict, mu: float, layer: bool):
    """The contact of a tractcurv case on CONTACT's grid: ``IPOTCN = −2`` (A1 and a/b), ``MX × MY`` elements over
    ``SCALE·(a, b)``, ``G``, ``ν`` of ``GG1``, ``POISS1`` (both bodies alike), with the case's interface layer
    (``GG3``, ``LAYTHK``: ``M = 4``) if ``layer``."""
    m = Materials.from_shear(case["GG1"], case["POISS1"], case["GG2"], case["POISS2"])
    A = case["A1"]
    B = curvatures_for_ratio(A, case["AOB"])
    e = hertz(A, B, m.Estar, case["FN"])
    nx, ny, s = int(case["MX"]), int(case["MY"]), case["SCALE"]
    grid = Grid(nx, ny, 2 * s * e.a / nx, 2 * s * e.b / ny, -s * e.a, -s * e.b)
    lay = {"thickness": case["LAYTHK"], "shear_modulus": case["GG3"]} if layer else None
    return Contact(grid, m, (A, B), case["FN"], mu, layer=lay)


def exponential_mu(case: dict, speed):
    """CONTACT's ``L = 4`` law at the absolute slip velocities ``speed`` (its user guide, eq. "exponential_law"):
    ``μ = FKIN + FEXP1·exp(−ln 2·s/SABSH1) + FEXP2·exp(−ln 2·s/SABSH2)``."""
    out = case["FKIN"] + case["FEXP1"] * np.exp(-np.log(2.0) * speed / case["SABSH1"])
    if case.get("FEXP2", 0.0):
        out = out + case["FEXP2"] * np.exp(-np.log(2.0) * speed / case["SABSH2"])
    return out


def remembered_mu(case: dict, grid, speed, direction: int = -1):
    """CONTACT's friction memory in the steady state (its user guide, "Friction memory"): along each row from the
    leading edge, ``μ_i = (μ_up + r_i μ_s(s_i))/(1 + r_i)`` with ``r_i = DX·max(s_i, S0)/(V·MEMDST)`` (the relaxation
    ``μ̇ = −max(s, s0)/d_c (μ − μ_s(s))`` by implicit Euler over one element's passage ``DX/V``), fresh material
    entering at ``μ_s(0)``; ``MEMDST = 0``: the instantaneous law."""
    target = exponential_mu(case, speed).reshape(grid.ny, grid.nx)
    if case["MEMDST"] == 0:
        return target.ravel()
    r = grid.dx * np.maximum(speed, case["MEM_S0"]).reshape(grid.ny, grid.nx) / (case["VELOC"] * case["MEMDST"])
    mu = np.empty_like(target)
    up = np.full(grid.ny, float(exponential_mu(case, 0.0)))
    cols = range(grid.nx - 1, -1, -1) if direction == -1 else range(grid.nx)   # d = −1: material enters at +x
    for i in cols:
        mu[:, i] = (up + r[:, i] * target[:, i]) / (1.0 + r[:, i])
        up = mu[:, i]
    return mu.ravel()


#: CONTACT's stopping rule of its velocity-dependent iteration: the slip changes by at most 1e-3 of its size.
RTOL = 1e-3


class _GivenMu:
    """A friction 'law' of kind "spatial" whose μ at the elements is given (the harness's fixed point)."""
    kind, law = "spatial", "given"

    def __init__(self, mu):
        self.mu_e = np.asarray(mu, dtype=float)
        self.reference = float(np.max(self.mu_e))

    def coefficient(self, points, q, direction):
        return self.mu_e


def falling_steady(contact, case, xi, newton, pressure, warm=None, rtol=RTOL, max_outer=50):
    """The steady state with CONTACT's velocity-dependent friction by CONTACT's own outer iteration (its output's
    "Vel-dep: |Sk − Sk−1|, .001 |Sk|" lines): slip → μ (:func:`remembered_mu`) → the steady solve with the bound μp
    → slip, until the slip changes by at most ``rtol`` of its size. Returns ``(record, outer iterations)``."""
    g = contact.grid
    mu = np.full(g.n, float(exponential_mu(case, 0.0)))
    s_old = None
    for k in range(1, max_outer + 1):
        contact.law = _GivenMu(mu)
        warm = steady(contact, newton, case["FN"], Loads(xi=xi, eta=0.0), -1, start=warm, pressure=pressure)
        s = np.asarray(warm.s, dtype=float).reshape(2, -1)
        speed = case["VELOC"] * np.hypot(s[0], s[1])
        if s_old is not None and np.max(np.abs(s - s_old)) <= rtol * np.max(np.abs(s)):
            return warm, k
        s_old = s
        mu = remembered_mu(case, g, speed)
    raise RuntimeError(f"tractcurv: the velocity-dependent outer iteration did not settle in {max_outer} (CKSI {xi})")


def tractcurv_falling(cases: int | None = None, memory: bool = True):
    """CONTACT's tractcurv series 2 (falling friction ``L = 4`` with memory, the interface layer ``M = 4``, 48 × 44):
    CONTACT's ``[(CKSI, FX, adhesion, slip)]`` and rollqp's ``[(Fx, adhesion, slip, outer iterations)]``, rollqp's
    steady solves under CONTACT's velocity-dependent iteration (:func:`falling_steady`); ``memory=False``: the
    instantaneous law (``MEMDST = 0``)."""
    all_cases = deck("tractcurv")
    two = [c for c in all_cases if c["series"] == 2][:cases]
    refs = reference_forces("tractcurv")
    first = all_cases.index(two[0])
    ref = refs[first:first + len(two)]
    case0 = dict(two[0]) if memory else {**two[0], "MEMDST": 0.0}
    c = tractcurv_contact(case0, float(exponential_mu(case0, 0.0)), layer=True)
    newton = NewtonMethod()
    p = newton.solve(c.normal_step(case0["FN"]))
    ours, warm = [], None
    for case in two:
        case = {**case, "MEMDST": case0["MEMDST"]}
        rec, k = falling_steady(c, case, case["CKSI"], newton, p, warm)
        warm = rec
        ours.append((rec.Fx, int(np.sum(rec.state == 1)), int(np.sum(rec.state == 2)), k))
    return ref, ours
