"""Derive the kernels of :mod:`rollqp.subsurface3d` with sympy and print them as Python source.

    python benchmarks/derive_subsurface3d.py > /tmp/kernels.py    # then compare with the module

The stresses of surface loads on a half-space z > 0 follow from Love's potentials (Love 1929; Johnson,
*Contact Mechanics*, 1985, §3.1, eq. 3.2-3.7): with ``F1 = ∫∫ q_x Ω``, ``G1 = ∫∫ q_y Ω``, ``H1 = ∫∫ p Ω``,
``Ω = z ln(ρ + z) − ρ``, ``F = ∂F1/∂z`` …, ``ψ1 = ∂F1/∂x + ∂G1/∂y + ∂H1/∂z``, ``ψ = ∂ψ1/∂z``::

    4πG u_x = 2 ∂F/∂z − ∂H/∂x + 2ν ∂ψ1/∂x − z ∂ψ/∂x        (and y)
    4πG u_z = ∂H/∂z + (1 − 2ν) ψ − z ∂ψ/∂z

Hooke's law turns every stress component into a sum of third and fourth derivatives of the potential
``W = ∫∫ Ω`` (times the uniform load of an element). Over a rectangle every such derivative is a corner
sum ``K(X₊, Y₊) − K(X₋, Y₊) − K(X₊, Y₋) + K(X₋, Y₋)`` of a closed form ``K`` (``X = x − ξ``):

* ``∂x^a ∂y^b ∂z^c W`` with a, b ≥ 1: ``K = ∂X^(a−1) ∂Y^(b−1) ∂z^c Ω`` (since ``∂X∂Y`` of the
  rectangle's primitive is the integrand);
* c ≥ 2: ``∂z² Ω = 1/ρ``, whose primitive is ``P = X asinh(Y/√(X²+z²)) + Y asinh(X/√(Y²+z²)) −
  z atan(XY/(zρ))``; ``K = ∂X^a ∂Y^b ∂z^(c−2) P``;
* c = 1 and b = 0: ``∂z Ω = ln(ρ + z)``, ``K = ∂X^(a−1) L_Y`` with ``L_Y = ∫ ln(ρ + z) dY = Y ln(ρ + z) − Y
  + z asinh(Y/√(X²+z²)) + X atan(XY(X²+Y²)/((ρ+z)(X²ρ + zY²)))`` (a = 0 likewise with X, Y exchanged);
* c = 0 and b = 0 (or a = 0): Ω is harmonic, ``∂x² W = −∂y² W − ∂z² W``.

The logarithms are written as ``asinh`` (no cancellation where X or Y is large and negative). The point
load's kernels are the same derivatives of Ω itself (:func:`rollqp.subsurface3d.point_load`). The output
is one function of (X, Y, z, ν) returning the 18 kernels, for p, q_x, q_y in turn, the six components
σxx, σyy, σzz, σxy, σxz, σyz each (tension positive, per unit load), common subexpressions shared.
"""
import sympy as sp
from sympy.printing.numpy import NumPyPrinter

COMPONENTS = ("sxx", "syy", "szz", "sxy", "sxz", "syz")


def stresses_of_potential():
    """Each stress component as a linear form in the derivatives of W, per load (p, q_x, q_y)."""
    x, y, z = sp.symbols("x y z", real=True)
    nu, G = sp.symbols("nu G", positive=True)
    p, qx, qy = sp.symbols("p q_x q_y")
    W = sp.Function("W")(x, y, z)
    F1, G1, H1 = qx * W, qy * W, p * W
    F, Gf, H = (sp.diff(f, z) for f in (F1, G1, H1))
    psi1 = sp.diff(F1, x) + sp.diff(G1, y) + sp.diff(H1, z)
    psi = sp.diff(psi1, z)
    c = 1 / (4 * sp.pi * G)
    u = [c * (2 * sp.diff(F, z) - sp.diff(H, x) + 2 * nu * sp.diff(psi1, x) - z * sp.diff(psi, x)),
         c * (2 * sp.diff(Gf, z) - sp.diff(H, y) + 2 * nu * sp.diff(psi1, y) - z * sp.diff(psi, y)),
         c * (sp.diff(H, z) + (1 - 2 * nu) * psi - z * sp.diff(psi, z))]
    X = (x, y, z)
    eps = [[(sp.diff(u[i], X[j]) + sp.diff(u[j], X[i])) / 2 for j in range(3)] for i in range(3)]
    tr = eps[0][0] + eps[1][1] + eps[2][2]
    pairs = dict(sxx=(0, 0), syy=(1, 1), szz=(2, 2), sxy=(0, 1), sxz=(0, 2), syz=(1, 2))
    out = {}
    for name, (i, j) in pairs.items():
        s = sp.expand(2 * G * (eps[i][j] + (nu / (1 - 2 * nu) * tr if i == j else 0)))
        for load in (p, qx, qy):
            out[name, str(load)] = s.coeff(load)
    return out, (x, y, z, nu, G)


def kernels(rectangle: bool):
    x, y, z, nu, G = stresses_of_potential()[1]
    forms = stresses_of_potential()[0]
    X, Y = sp.symbols("X Y", real=True)
    Z = sp.symbols("z", positive=True)
    rho = sp.sqrt(X ** 2 + Y ** 2 + Z ** 2)
    Om = Z * sp.log(rho + Z) - rho
    P = X * sp.asinh(Y / sp.sqrt(X ** 2 + Z ** 2)) + Y * sp.asinh(X / sp.sqrt(Y ** 2 + Z ** 2)) \
        - Z * sp.atan(X * Y / (Z * rho))
    LY = Y * sp.log(rho + Z) - Y + Z * sp.asinh(Y / sp.sqrt(X ** 2 + Z ** 2)) \
        + X * sp.atan(X * Y * (X ** 2 + Y ** 2) / ((rho + Z) * (X ** 2 * rho + Z * Y ** 2)))
    LX = LY.subs({X: Y, Y: X}, simultaneous=True)

    def D(a, b, c):
        if not rectangle:
            return sp.diff(Om, *([X] * a + [Y] * b + [Z] * c))
        if a >= 1 and b >= 1:
            return sp.diff(Om, *([X] * (a - 1) + [Y] * (b - 1) + [Z] * c))
        if c >= 2:
            return sp.diff(P, *([X] * a + [Y] * b + [Z] * (c - 2))) if a + b + c > 2 else P
        if c == 1:
            return sp.diff(LY, *([X] * (a - 1))) if a >= 1 else sp.diff(LX, *([Y] * (b - 1)))
        if a >= 2:
            return -D(a - 2, 2, 0) - D(a - 2, 0, 2)
        return -D(2, b - 2, 0) - D(0, b - 2, 2)

    exprs = []
    for load in ("p", "q_x", "q_y"):
        for comp in COMPONENTS:
            s = forms[comp, load]
            reps = {d: D(*(d.variables.count(v) for v in (x, y, z))) for d in s.atoms(sp.Derivative)}
            exprs.append(s.subs(reps).subs({x: X, y: Y, z: Z, G: 1}))
    return exprs, (X, Y, Z, nu)


def source(name: str, rectangle: bool, per: int = 60) -> str:
    """The kernels as Python source: the common subexpressions ``x[i]`` computed by functions of ``per`` lines
    each (one screen), then ``name(X, Y, z, nu)`` returning the 18 kernels."""
    import re
    exprs, _ = kernels(rectangle)
    reps, red = sp.cse(exprs, optimizations="basic")
    pr = NumPyPrinter({"fully_qualified_modules": False})

    def code(e):
        return re.sub(r"\bx(\d+)\b", r"x[\1]", pr.doprint(e))
    lines = [f"    x[{str(s)[1:]}] = {code(e)}" for s, e in reps]
    parts = []
    for k in range(0, len(lines), per):
        parts.append(f"def {name}_{k // per}(X, Y, z, nu, x):\n" + "\n".join(lines[k:k + per]) + "\n")
    body = [f"def {name}(X, Y, z, nu):", f"    x = [None] * {len(reps)}"]
    body += [f"    {name}_{k}(X, Y, z, nu, x)" for k in range(len(parts))]
    body.append("    return (" + ",\n            ".join(code(e) for e in red) + ")")
    return "\n\n".join(parts) + "\n\n" + "\n".join(body) + "\n"


if __name__ == "__main__":
    print(source("_corner_kernels", True))
    print()
    print(source("_point_kernels", False))
