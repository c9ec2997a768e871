r"""The largest tangential force a contact can carry before any solve: the sliding limit of a friction law
that varies over the contact (docs/friction.md, "The sliding limit of prescribed forces").

A stick solution of a step with prescribed forces exists only below ``|(Fx, Fy)| < Σ_i μ_i p_i A_i`` (the
discrete form of ``∫ μ p dA``): every element at its bound is full sliding. With a uniform ``μ`` that is
``μ FN`` whatever the pressure; with a law varying over the contact (a patch, a table) it depends on where
the pressure is, and a scene's check runs before the discrete pressure exists. It is estimated here with the
Hertz pressure of the scene's ellipse (3D) or strip (2D), at the current normal load, on the scene's own
discretization: ``μ_i`` at the element centres (3D) or nodes (2D) exactly as the steps read it, the pressure's
share ``w_i`` of each element (Hertz's force on the element, integrated on :data:`SUB` × :data:`SUB` points,
3D) or node (``f_i p_Hertz(x_i)``, 2D), normalised to ``Σ w_i = 1``:

.. math::  c = \frac{\sum_i \mu_i w_i}{\mu_\mathrm{ref}},\qquad
           \text{capacity} = c\,\mu_\mathrm{ref} F_N .

The discrete pressure ``p_i A_i/FN = w'_i`` differs from ``w_i`` (its edge elements, its contact set), and
since both sum to 1, ``|Σ μ_i (w_i − w'_i)| <= ½ (μ_max − μ_min) Σ|w_i − w'_i|`` over the elements either
pressure reaches. The checks refuse a force only beyond ``c + min(1, MARGIN/m)·(μ_max − μ_min)/μ_ref``
(:data:`MARGIN`, measured; ``m`` the elements per semi-axis), plus the coupling's shift of the pressure for
dissimilar bodies (:data:`COUPLING_GRID`, :data:`COUPLING_STRIP`), so a load with a stick solution is never refused
for this estimate; a load between ``c`` and that bound may still be refused by the step (its own sliding limit).
A uniform ``μ`` gives ``c = 1`` and no margin (the checks then keep their plain ``μFN`` path).

Examples
--------
>>> import numpy as np
>>> w = strip_shares(np.linspace(-1.0, 1.0, 201), np.full(201, 0.01), 1.0)
>>> mu = np.where(np.linspace(-1.0, 1.0, 201) >= 0.0, 0.6, 0.3)   # a patch on the trailing half
>>> round(float(mu @ w / 0.3), 2)                                  # half the force at 0.6, half at 0.3
1.5
"""
from __future__ import annotations

import numpy as np

__all__ = ["SUB", "MARGIN", "COUPLING_GRID", "COUPLING_STRIP", "grid_shares", "strip_shares", "near_grid",
           "near_strip", "estimate", "allowed", "per_sample", "limits", "worst", "margin_note"]

#: Sub-samples per direction of a grid element for its share of the Hertz force (midpoint rule on SUB × SUB
#: points). Measured against 40 × 40 sub-samples on grids of 2 to 30 elements per semi-axis: ``Σ|Δw| <= 5.3e-3``
#: (2 elements), 3.7e-4 (16); the estimate's difference from the discrete pressure is larger (:data:`MARGIN`),
#: so finer sampling buys nothing.
SUB = 4


def grid_shares(x, y, dx: float, dy: float, a: float, b: float, sub: int = SUB) -> np.ndarray:
    """Each element's share of the Hertz force of the ellipse ``(a, b)`` centred at the origin (``x``, ``y``: the
    element centres, ``(n,)``; ``dx``, ``dy`` their sizes): ``∫ sqrt(1 − x²/a² − y²/b²)`` over the element on
    ``sub × sub`` midpoints, normalised to sum 1."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    w = np.zeros(x.shape)
    hit = (np.abs(x) < a + dx) & (np.abs(y) < b + dy)      # elements that can meet the ellipse
    off = (np.arange(sub) + 0.5) / sub - 0.5
    xs = x[hit][:, None, None] + dx * off[None, :, None]
    ys = y[hit][:, None, None] + dy * off[None, None, :]
    w[hit] = np.sqrt(np.maximum(0.0, 1.0 - (xs / a) ** 2 - (ys / b) ** 2)).sum(axis=(1, 2))
    return w / w.sum()


def strip_shares(x, f, b: float) -> np.ndarray:
    """Each node's share ``f_i sqrt(1 − x_i²/b²)`` of the Hertz force of half-width ``b`` (``x``: the nodes,
    ``f``: their weights ``∫ N_i dx``), normalised to sum 1."""
    x = np.asarray(x, dtype=float)
    w = np.asarray(f, dtype=float) * np.sqrt(np.maximum(0.0, 1.0 - (x / b) ** 2))
    return w / w.sum()


def near_grid(x, y, dx: float, dy: float, a: float, b: float) -> np.ndarray:
    """The elements the Hertz or the discrete pressure of the ellipse ``(a, b)`` can reach (the ellipse grown
    by an element each way: the discrete contact set differs from Hertz's by its edge elements)."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    return (x / (a + dx)) ** 2 + (y / (b + dy)) ** 2 <= 1.0


def near_strip(x, b: float, h: float) -> np.ndarray:
    """The nodes the Hertz or the discrete pressure of half-width ``b`` can reach (grown by ``h``, an element)."""
    return np.abs(np.asarray(x, dtype=float)) <= b + h


#: ``min(1, MARGIN/m)`` is the bound on ``½ Σ|w_i − w'_i|`` the checks take, ``m`` the elements (3D:
#: ``min(a/dx, b/dy)``) or element lengths (2D: ``b/Le``) per semi-axis of the current contact. Measured
#: (``½ Σ|Δw|·m``, the Hertz shares against the frictionless normal step's pressure): 3D at most 0.215 over
#: m = 0.6 to 20, element aspect 0.7 to 1.4, grids centred and shifted by 0.37 dx, a/b = 1 and 0.24 to 4.8;
#: 2D at most 0.229 over constant, linear and quadratic elements, 4 to 400 elements, zones 1.1 to 3, loads
#: P̄ and 0.3 P̄ (m = 0.37 to 182). Taken as 0.5, twice the largest (the bound is never above 1: both sum to 1).
MARGIN = 0.5

#: The normal–tangential coupling of dissimilar bodies moves the pressure under the tangential tractions, and the
#: capacity with it: ``|Σ μ_i Δw_i| <= COUPLING·|K|·(|F|/(μ_ref FN))·(μ_max − μ_min)/μ_ref`` (Kalker's ``K``, 3D;
#: Dundurs' ``β``, 2D). Measured at 0.97 of the capacity of patches at four places, ``|K|`` from 0.003 to 0.48
#: (20 × 20, ``qp-clarabel``, four steps): at most 0.227 (3D); ``|β|`` from 0.006 to 0.49 (40 quadratic elements):
#: at most 0.059 (2D). Taken as twice the largest.
COUPLING_GRID = 0.5
COUPLING_STRIP = 0.12


def estimate(mu, w, near, reference: float, m: float) -> tuple[float, float, float, float]:
    """``(c, spread, top, mesh)`` in units of ``μ_ref`` (module docstring): ``c = Σ μ_i w_i/μ_ref``, ``spread =
    (μ_max − μ_min)/μ_ref`` and ``top = μ_max/μ_ref`` over the ``near`` elements, and ``mesh = min(1, MARGIN/m)``,
    the bound on ``½ Σ|w_i − w'_i|`` (:func:`allowed` combines them)."""
    mu = np.broadcast_to(np.asarray(mu, dtype=float), np.shape(w))
    c = float(mu @ w) / reference
    hi, lo = float(np.max(mu[near])) / reference, float(np.min(mu[near])) / reference
    return c, hi - lo, hi, min(1.0, MARGIN / m)


def allowed(parts, ratio, coupling: float) -> np.ndarray:
    """The force (in ``μ_ref FN``) a check allows below at each sample: ``c + (mesh + coupling·ratio)·spread``, at
    most ``top`` (no pressure carries more than the largest ``μ`` times ``FN``); ``parts`` the columns of
    :func:`estimate` per sample, ``coupling`` the coupling constant times ``|K|`` (or ``|β|``), 0 for similar bodies."""
    c, spread, top, mesh = parts
    return np.minimum(c + (mesh + coupling * np.asarray(ratio, dtype=float)) * spread, top)


def per_sample(n, q, rule) -> np.ndarray:
    """``rule(n_k, q_k) -> (c, spread, top, mesh)`` at each sample (shape ``(4, samples)``), evaluated once per
    distinct pair."""
    keys = np.stack([np.asarray(n, dtype=float), np.asarray(q, dtype=float)], axis=1)
    if keys.shape[0] == 0:
        return np.zeros((4, 0))
    uniq, inv = np.unique(keys, axis=0, return_inverse=True)
    vals = np.array([rule(float(a), float(b)) for a, b in uniq]).reshape(-1, 4)
    return vals[np.ravel(inv)].T


def limits(n, q, ratio, rule, coupling: float) -> tuple[np.ndarray, np.ndarray]:
    """``(c, limit)`` at each sample of normal loads ``n`` (relative) and rolled distances ``q``: ``rule(n_k,
    q_k)`` (:func:`estimate`'s columns) where ``ratio > 0`` and ``n > 0`` (elsewhere 1), combined by
    :func:`allowed`. The skeleton of both dimensions' ``sliding_limits`` (:func:`rollqp.loads.sliding_limits`,
    :func:`rollqp.scene.checks.sliding_limits`), which give the ``rule``."""
    n, q, ratio = (np.asarray(v, dtype=float) for v in (n, q, ratio))
    need = (ratio > 0) & (n > 0)
    parts = np.ones((4, ratio.size))
    parts[:, need] = per_sample(n[need], q[need], rule)
    return parts[0], allowed(parts, ratio, coupling)


def worst(ratio, limit) -> int:
    """The sample whose force is nearest (or beyond) its limit: ``argmax ratio/limit`` over the loaded samples
    (a limit of 0, ``μ = 0`` on the contact, makes any force there the worst)."""
    ratio = np.asarray(ratio, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return int(np.argmax(np.where(ratio > 0, ratio / limit, 0.0)))


def margin_note(c: float, limit: float) -> str:
    """The refusals' note of the margin :func:`allowed` adds to the estimate ``c`` (empty without one)."""
    return f"; +{limit - c:.3g} allowed for the discrete pressure's difference from this estimate" if limit > c else ""
