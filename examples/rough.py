"""A rough cylinder rolling through a transient on the matrix-free path (docs/matrix-free.md).

The rollers of §6.1.1 (similar steel, R_A = 150 mm, R_B = 300 mm, P = 1000 N/mm, μ = 0.1), but
roller A carries a seeded random roughness on its circle: a ``table`` profile with
``frame = "material"`` (docs/kinematics.md), a self-affine (fractal-like) surface with Hurst
exponent 0.8 and wavelengths from a_H/64 to a_H/2, 0.5 µm rms (a_H = 1.05 mm, the smooth
deformed gap at 1.25 a_H is 1.35 µm, so the zone is ±2 a_H). The roughness rolls through the contact, so every step re-solves the normal half
with the gap of that instant: the contact breaks into several patches that move, merge and
split. The braked start (Q = 0.5 μP, Cattaneo on a rough surface) is followed by rolling under
constant loads; ``mf-newton`` solves each step with FFT products on the uniform strip (``O(n)``
memory, no n × n matrix), here 10,001 nodes by default.

The roughness is generated in the example from a fixed seed (:func:`roughness`), sampled at
a_H/1024, and passed inline as the body's profile (``bodies.A.profile``).

Run it::

    python examples/rough.py [--elements N] [--distance Q] [--method M] [--figure PATH]

``--elements`` (quadratic elements on the zone ±2 a_H; 5000: 10,001 nodes), ``--distance``
(rolled distance after the start, in a_H; 1.0), ``--method`` (``mf-newton``; ``newton`` runs
the same scene on the dense path, at most 20,001 nodes), ``--figure`` draws the pressure and
shear at the end, the zone map against q, and the number of contact patches and the creepage
against q (docs/figures/rough.png).
"""
from __future__ import annotations

import argparse
import time

import numpy as np

import rollqp
from rollqp.problem import SEPARATION, SLIP, STICK

#: The roughness: seed, rms height (mm), Hurst exponent, shortest and longest wavelength (a_H).
SEED, RMS, HURST, SHORTEST, LONGEST = 16, 0.5e-3, 0.8, 1 / 64, 1 / 2
#: Zone half-width L/a_H: a rough contact spreads beyond a_H (the smooth deformed gap at 1.25 a_H
#: is only 1.35 µm), so the zone is wider than the smooth scenes' 1.25.
ZONE = 2.0
#: Table sampling, per shortest wavelength.
SAMPLES = 16
#: Q/(μP) held from the start.
LOAD = 0.5


def roughness(a_H, span, seed=SEED, rms=RMS, hurst=HURST, shortest=SHORTEST, longest=LONGEST):
    """``(s, z)``: a seeded self-affine height profile on ``[-span, span]`` (mm).

    Random phases, amplitudes ``∝ k^{-(1+H)}`` (power spectrum ``∝ k^{-2(1+H)}``) between the
    wavenumbers of ``longest`` and ``shortest`` (in a_H), scaled to ``rms``, zero mean.
    """
    dx = shortest * a_H / SAMPLES
    s = np.arange(-span, span + dx, dx)
    k = np.fft.rfftfreq(s.size, dx)
    band = (k >= 1 / (longest * a_H)) & (k <= 1 / (shortest * a_H))
    amp = np.where(band, np.where(k > 0, k, 1.0) ** -(1 + hurst), 0.0)
    phase = np.random.default_rng(seed).uniform(0, 2 * np.pi, k.size)
    z = np.fft.irfft(amp * np.exp(1j * phase), n=s.size)
    z -= z.mean()
    return s, z * (rms / np.sqrt(np.mean(z * z)))


def rough_scene(elements=5000, distance=1.0, method="mf-newton"):
    """The built-in ``cattaneo-carter`` with roughness on roller A, Q = :data:`LOAD` μP, ``elements``
    quadratic elements and ``distance`` a_H rolled at Δq = 8 Le (the longest step allowed)."""
    base = rollqp.load_scene("cattaneo-carter")
    a = base.a_H
    span = (ZONE + distance + 0.25) * a       # the material that passes the strip
    s, z = roughness(a, span)
    return base.replace(**{
        "name": "rough", "description": "a rough roller rolling through a braked contact (examples/rough.py)",
        "bodies.A.profile": {"kind": "table", "x": s.tolist(), "h": z.tolist(), "frame": "material"},
        "load.tangential": {"kind": "constant", "value": LOAD},
        "discretization.elements": int(elements), "discretization.step": 8.0, "discretization.zone": ZONE,
        "discretization.distance": float(distance), "solver.method": method})


def patches(state) -> int:
    """Contact patches of one state: runs of nodes in contact (stick or slip)."""
    c = np.concatenate([[0], (np.asarray(state) != SEPARATION).astype(int), [0]])
    return int(np.sum(np.diff(c) == 1))


def measure(arrays, scene):
    """Patches per state, contact fraction, equilibrium, residuals and the rolling step's time."""
    a, st = float(arrays["a_H"]), arrays["state"]
    f = rollqp.Strip(scene.half_width, scene.discretization.elements, scene.discretization.element).weights
    npatch = np.array([patches(row) for row in st])
    P = arrays["pn"] @ f
    Q = arrays["pt"] @ f
    mu = scene.contact.friction
    return {
        "nodes": int(st.shape[1]), "states": int(st.shape[0]),
        "patches": npatch, "patches_max": int(npatch.max()), "patches_min": int(npatch.min()),
        "contact_width": float((np.ptp(arrays["x"][st[-1] != SEPARATION])) / a),
        "peak": float(arrays["pn"].max() / arrays["p0"]),
        "load_error": float(np.max(np.abs(P / scene.load.normal - 1))),
        "shear_error": float(np.max(np.abs(Q / (LOAD * mu * scene.load.normal) - 1))),
        "stick_nodes": int(np.sum(st[-1] == STICK)), "slip_nodes": int(np.sum(st[-1] == SLIP)),
        "residual": float(arrays["residual"].max()),
        "step_time": float(np.median(arrays["step_time"][1:])) if st.shape[0] > 1 else float("nan"),
    }


def figure(arrays, scene, m, path):
    import matplotlib.pyplot as plt
    from rollqp import closedforms as cf
    a, p0, mu = float(arrays["a_H"]), float(arrays["p0"]), scene.contact.friction
    x, q = arrays["x"] / a, arrays["q"] / a
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.2))
    ax[0].plot(x, arrays["pn"][-1] / p0, lw=0.7, label="p/p0 (rough)")
    ax[0].plot(x, arrays["pt"][-1] / (mu * p0), lw=0.7, label="t/(μp0) (rough)")
    xa = arrays["x"]
    ax[0].plot(x, cf.hertz_pressure(xa, a, p0) / p0, "k--", lw=0.8, label="Hertz (smooth)")
    ax[0].plot(x, cf.carter_traction(xa, a, p0, mu, LOAD, scene.load.direction) / (mu * p0), "k:", lw=0.8,
               label="Carter (smooth)")
    ax[0].set(xlabel="x/a_H", title=f"end state, q = {q[-1]:.2f} a_H ({m['nodes']:,} nodes)", xlim=(-1.3, 1.3))
    ax[0].legend(fontsize=8)
    ax[1].pcolormesh(x, q, arrays["state"], cmap="viridis", shading="nearest", vmin=0, vmax=2)
    ax[1].set(xlabel="x/a_H", ylabel="q/a_H", title="zones: separation, stick, slip (dark to light)",
              xlim=(-1.3, 1.3))
    ax[2].plot(q, m["patches"], "C0", drawstyle="steps-mid")
    ax[2].set(xlabel="q/a_H", ylabel="contact patches", title="patches and creepage")
    tw = ax[2].twinx()
    tw.plot(q[1:], arrays["creepage"][1:] * 1e3, "C1")
    tw.axhline(cf.carter_creepage(a, scene.R, mu, LOAD) * 1e3, color="C1", ls=":")
    tw.set_ylabel("creepage ×1e3 (dotted: smooth Carter)", color="C1")
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, default=5000)
    ap.add_argument("--distance", type=float, default=1.0)
    ap.add_argument("--method", default="mf-newton")
    ap.add_argument("--figure")
    args = ap.parse_args(argv)
    scene = rough_scene(args.elements, args.distance, args.method)
    t0 = time.perf_counter()
    arrays = rollqp.run(scene).arrays()
    wall = time.perf_counter() - t0
    m = measure(arrays, scene)
    print(f"rough roller, {args.method}: {m['nodes']:,} nodes, {m['states']} states, {wall:.1f} s "
          f"(median rolling step {m['step_time'] * 1e3:.0f} ms)")
    print(f"contact patches per state: {m['patches_min']} to {m['patches_max']}; end: {m['patches'][-1]} patches "
          f"over {m['contact_width']:.2f} a_H, {m['stick_nodes']} stick and {m['slip_nodes']} slip nodes")
    print(f"peak pressure {m['peak']:.2f} p0; load |P/P̄ - 1| <= {m['load_error']:.1e}, "
          f"|Q/(0.5 μP̄) - 1| <= {m['shear_error']:.1e}; largest residual {m['residual']:.1e}")
    if args.figure:
        figure(arrays, scene, m, args.figure)
        print(f"figure: {args.figure}")
    return {"scene": scene, "arrays": arrays, "measures": m, "seconds": wall}


if __name__ == "__main__":
    results = main()
