"""3D load paths (rollqp.loads, rollqp.march.grid): the normal load as a history (zero: out of contact),
the rolled distance as a history (stops, reversals, variable Δq, fretting at rest), against Hertz at the current
load, the steady state at the current load, Mindlin–Deresiewicz at rest, the 2D code on the same history and a
second method."""
from __future__ import annotations

import numpy as np
import pytest

import rollqp
from rollqp.errors import InputError
from rollqp.kinematics import plan
from rollqp.closedforms.hertz_ellipse import hertz
from rollqp.march.grid import steady, static_shift
from rollqp.march.grid import prepare, run

#: the reversal path of the 2D built-in scene stop-reverse: roll 3 a, stop for 1 a, roll back 6 a
REVERSE = {"kind": "table", "q": [0, 3, 4, 10], "value": [0, 3, 3, -3]}


def circle(n=16, **changes):
    """Kalker's circular contact on n × n elements, zone 1.4 (room for a load 1.3 times the reference)."""
    return rollqp.load_scene("kalker-circular").replace(**{"discretization.elements": [n, n],
                                                           "discretization.zone": [1.4, 1.4], **changes})


def braked(n=16, **changes):
    """The circle braked by Fx = 0.75 μFN (a braked start, then rolling), as the 2D stop-reverse scene."""
    return circle(n, **{"load.start": "braked", "load.creepage": None, "load.tangential": 0.75, **changes})


def harmonic(n, lam=16.0, xi=1e-4):
    return circle(n, **{"load.creepage": {"longitudinal": xi}, "discretization.distance": lam / 4,
                        "load.normal_history": {"kind": "harmonic", "mean": 1.0, "amplitude": 0.3,
                                                "wavelength": lam}})


# =========================================================================== (a) the normal load as a history
def _hertz_errors(n):
    s = harmonic(n)
    a = run(s).arrays()
    _, _, contact = prepare(s)
    A, B = s.curvatures
    out = []
    for k in range(a["FN"].size):
        ph = hertz(A, B, s.materials.Estar, float(a["FN"][k])).pressure(contact.x, contact.y)
        out.append(np.linalg.norm(a["pn"][k].ravel() - ph) / np.linalg.norm(ph))
    return s, a, np.array(out)


def test_normal_history_gives_hertz_at_the_current_load():
    """Every step's pressure is Hertz's at the step's load to the discretization error, which falls as the
    grid is refined (relative L2 error, max over the steps: measured 0.0335 on 16², 0.0222 on 24², 0.0202 on 32²,
    as irregular as the normal step's own error at constant loads in [1, 1.3] FN_ref, 0.034, 0.024, 0.014 at
    most: the elements the ellipse's edge cuts change with the load; benchmarks/three_loads.py)."""
    s16, a16, e16 = _hertz_errors(16)
    _, _, e24 = _hertz_errors(24)
    fn = s16.load.normal * s16.load.normal_history(s16.time_steps / s16.ellipse.a)
    # the load is the history's (the normal step's force equation, solved to 1e-10)
    assert np.allclose(a16["FN"], fn, rtol=1e-9, atol=0) and fn.max() > 1.25 * s16.load.normal
    assert e16.max() < 0.036 and e24.max() < 0.024 and e24.max() < 0.75 * e16.max()   # first order: 0.67
    # not Hertz at the reference load: at the largest load that error is 7 times the discretization error
    _, _, contact = prepare(s16)
    k = int(np.argmax(a16["FN"]))
    ref = s16.ellipse.pressure(contact.x, contact.y)
    assert np.linalg.norm(a16["pn"][k].ravel() - ref) / np.linalg.norm(ref) > 5 * e16.max()


def test_creep_force_tracks_the_steady_value_at_the_current_load():
    """A creepage with a slowly varying load (λ = 16 a): each step's Fx against the steady state at that
    step's load on the same grid. Measured max |ΔFx|/(μFN) = 1.36e-3 on 16², 1.96e-3 on 24², 1.93e-3 on
    32², while Fx itself changes by 7 % over the run: the deviation comes when the discrete contact grows by a
    ring of elements (the new rim enters without traction memory and relaxes over a contact length); between
    those steps the lag is below 1e-4."""
    s = harmonic(16)
    a = run(s).arrays()
    _, meth, contact = prepare(s)
    dev = np.array([abs(a["Fx"][k] - steady(contact, meth, float(a["FN"][k]), s.loads_at(float(s.time_steps[k])),
                                            direction=-1).Fx) / (s.mu * a["FN"][k]) for k in range(a["FN"].size)])
    assert dev[0] < 1e-9                            # the rolling start is the steady state itself
    assert dev.max() < 1.5e-3
    grows = np.flatnonzero(np.diff((a["pn"] > 0).sum(axis=(1, 2))) > 0) + 1
    assert grows.size >= 1 and dev[1:grows[0]].max() < 1e-4          # before the contact first grows: the lag
    assert (a["Fx"].max() - a["Fx"].min()) / abs(a["Fx"][0]) > 0.05     # measured 7 %: tracking is not constancy


def test_zero_load_is_out_of_contact():
    """A normal load that drops to 0 and comes back: zero fields (every element separated), then contact again
    with Hertz's pressure; a creepage prescribed throughout."""
    s = circle(**{"load.creepage": {"longitudinal": 1e-4}, "discretization.distance": 3.0,
                  "load.normal_history": {"kind": "table", "q": [0, 0.5, 1.0, 1.5, 2.0], "value": [1, 0, 0, 1, 1]}})
    a = run(s).arrays()
    tau = s.time_steps / s.ellipse.a
    off = (tau >= 0.5) & (tau <= 1.0)
    assert off.sum() >= 3
    for f in ("pn", "px", "py", "state"):
        assert np.all(a[f][off] == 0), f
    assert np.all(a["FN"][off] == 0) and np.all(a["Fx"][off] == 0)
    assert np.all(a["creepage"][off][:, 0] == 1e-4)
    back = tau >= 1.5
    assert np.allclose(a["FN"][back], s.load.normal, rtol=1e-9)
    assert np.abs(a["Fx"][-1]) > 0.5 * np.abs(a["Fx"][0])      # rolling again builds the creep force up


# =========================================================================== (b) stops and reversals
def test_a_stop_under_held_loads_changes_nothing():
    """Rolling, then a stop (the rolled distance constant) with Fx held: static shift steps whose tractions and
    pressure stay those of the last rolling step (measured 3e-15 μp0), with no rigid shift."""
    s = braked(**{"load.rolled": REVERSE, "discretization.distance": 4.0})
    a = run(s).arrays()
    pl = plan(s)
    stops = np.flatnonzero(pl.d == 0)[1:] if pl.d[0] == 0 else np.flatnonzero(pl.d == 0)
    assert stops.size >= 4
    k0 = stops[0] - 1
    mu_p0 = s.mu * s.ellipse.p0
    for k in stops:
        assert np.max(np.abs(a["px"][k] - a["px"][k0])) / mu_p0 < 1e-10     # solver tolerance 1e-10
        assert np.max(np.abs(a["py"][k] - a["py"][k0])) / mu_p0 < 1e-10
        assert np.max(np.abs(a["pn"][k] - a["pn"][k0])) / s.ellipse.p0 < 1e-12
        assert abs(a["creepage"][k][0]) * s.materials.Estar / s.ellipse.p0 < 1e-10   # no rigid shift
    assert np.allclose(a["q"][stops], 3 * s.ellipse.a)


def _stick_centroid(x, state):
    """The mean x of the sticking elements of each state (nan where none sticks)."""
    out = []
    for st in state:
        m = st == 1
        out.append(np.broadcast_to(x, m.shape)[m].mean() if m.any() else np.nan)
    return np.array(out)


def test_reversal_moves_the_stick_zone_to_the_new_leading_edge_as_in_2d():
    """Roll 3 a, stop, roll back 6 a with Fx = 0.75 μFN held (the 2D scene stop-reverse's path): the stick
    zone is at the leading edge (x > 0 rolling forward with direction −1, x < 0 rolling back) at every rolling
    step, from the first step after the reversal on (its Δq is 0.025 a), in 3D as in 2D on the same history; the
    end state is the forward run's mirrored (measured 1.8e-7 μp0: the transient left after 6 a, as 2D's 7.5e-7)."""
    s = braked(**{"load.rolled": REVERSE, "discretization.distance": 10.0})
    a = run(s).arrays()
    c3 = _stick_centroid(a["x"], a["state"]) / s.ellipse.a
    s2 = rollqp.load_scene("stop-reverse")
    a2 = rollqp.run(s2).arrays()
    c2 = _stick_centroid(a2["x"], a2["state"]) / s2.a_H
    d3, d2 = plan(s).d, a2["direction"]
    tau3, tau2 = s.time_steps / s.ellipse.a, a2["time"] / s2.a_H
    compared = 0
    for k in range(1, tau3.size):
        if d3[k] == 0:
            continue
        k2 = int(np.argmin(np.abs(tau2 - tau3[k])))
        if d2[k2] != d3[k]:         # a step at the path's corners (2D steps by Le, 3D by dx)
            continue
        compared += 1
        assert np.sign(c3[k]) == np.sign(c2[k2]) == -d3[k], (k, c3[k], c2[k2])
    assert compared >= 0.8 * np.count_nonzero(d3[1:])
    fwd = run(braked(**{"discretization.distance": 6.0})).arrays()
    assert a["q"][-1] == pytest.approx(-3 * s.ellipse.a)
    # the last full step (the run's last one rolls the 0.14 dx left to q = −3 a)
    assert plan(s).dq[-2] == pytest.approx(s.grid.dx, rel=1e-9)
    assert np.max(np.abs(a["px"][-2][:, ::-1] - fwd["px"][-1])) / (s.mu * s.ellipse.p0) < 1e-5
    assert np.max(np.abs(a["px"][-2] - fwd["px"][-1])) / (s.mu * s.ellipse.p0) > 0.3


def test_fretting_at_rest_follows_mindlin_deresiewicz():
    """At rest (rolled = 0 throughout) Fx cycles 0.6 → −0.6 → 0.6 μFN from the Cattaneo state: the state at −0.6
    is the first one negated and the state back at 0.6 the first one (Mindlin–Deresiewicz's loop closes; measured
    4.8e-4 and 3.5e-4 μp0, below); and unloading to 0 gives t(0.6) − 2·t(0.3), Cattaneo's states superposed
    (measured 1.1e-4 μp0 on 16²: the same discrete path dependence)."""
    L = 8 * braked().grid.dx / braked().ellipse.a          # 8 steps per quarter cycle: the turns are steps
    s = braked(**{"load.rolled": {"kind": "constant", "value": 0.0}, "discretization.distance": 4 * L,
                  "load.tangential": {"kind": "table", "q": [0, L, 2 * L, 3 * L, 4 * L],
                                      "value": [0.6, 0.0, -0.6, 0.0, 0.6]}})
    a = run(s).arrays()
    assert np.all(plan(s).d[1:] == 0)
    k1, k2, k4 = 8, 16, 32
    assert a["Fx"][k2] == pytest.approx(-0.6 * s.mu * s.load.normal, rel=1e-9)
    mu_p0 = s.mu * s.ellipse.p0
    # 1e-3: the discrete path dependence of the incremental shift steps in 3D (the slip turns out of x with
    # ν ≠ 0; Cattaneo's start in one step, the cycle in steps of 0.075): measured 4.8e-4 and 3.5e-4
    assert np.max(np.abs(a["px"][k2] + a["px"][0])) / mu_p0 < 1e-3
    assert np.max(np.abs(a["px"][k4] - a["px"][0])) / mu_p0 < 1e-3
    assert np.max(np.abs(a["px"][k2] - a["px"][0])) / mu_p0 > 0.5
    _, meth, contact = prepare(s)
    cat = {F: static_shift(contact, meth, s.load.normal, F * s.mu * s.load.normal)[-1].t[0] for F in (0.6, 0.3)}
    md = contact.grid.field(cat[0.6] - 2 * cat[0.3])
    assert np.max(np.abs(a["px"][k1] - md)) / mu_p0 < 1e-3


# =========================================================================== variable Δq and a second method
def test_variable_steps_stop_reversal_and_load_agree_between_methods():
    """Variable Δq (three slopes), a stop, a reversal and a varying normal load: Newton against the conic
    method (Clarabel, refined by the active set) to the tolerance 1e-10 (measured 5e-11 μp0, 5e-15 p0)."""
    pytest.importorskip("clarabel")
    s = braked(12, **{"load.rolled": {"kind": "table", "q": [0, 1, 1.5, 2.5, 4], "value": [0, 0.5, 0.5, 1.5, 0.75]},
                      "load.normal_history": {"kind": "table", "q": [0, 1.2, 4], "value": [1.0, 1.2, 0.9]},
                      "load.tangential": {"kind": "table", "q": [0, 1.2, 1.4], "value": [0.5, -0.3, 0.4]},
                      "discretization.distance": 4.0})
    dq = np.unique(np.round(plan(s).dq / s.grid.dx, 9))
    assert dq.size >= 4 and 0.0 in dq                # stops and three step sizes
    a = run(s).arrays()
    b = run(s, method="socp-clarabel").arrays()
    scale = s.mu * s.ellipse.p0
    assert np.max(np.abs(a["px"] - b["px"])) / scale < 1e-9
    assert np.max(np.abs(a["pn"] - b["pn"])) / s.ellipse.p0 < 1e-9


# =========================================================================== (c) errors naming the key
@pytest.mark.parametrize("changes, key", [
    ({"load.normal_history": {"kind": "harmonic", "mean": 0.5, "amplitude": 0.8, "wavelength": 4.0}},
     "load.normal_history"),
    ({"load.normal_history": {"kind": "table", "q": [0, 2, 1], "value": [1, 1, 1]}}, "load.normal_history.q"),
    ({"load.rolled": {"kind": "table", "q": [0, 2, 1], "value": [0, 1, 2]}}, "load.rolled.q"),
    ({"load.rolled": {"kind": "sine", "q": [0, 1]}}, "load.rolled.kind"),
    ({"load.normal_history": {"kind": "ramp", "start": 1.0}}, "load.normal_history.end"),
    ({"load.normal_history": "big"}, "load.normal_history"),
    ({"load.rolled": {"kind": "table", "q": [0, 1], "value": [0, 40]}}, "load.rolled"),
    ({"load.normal_history": {"kind": "harmonic", "mean": 1, "amplitude": 0.1, "wavelength": 0.1}},
     "load.normal_history.wavelength"),
    ({"load.normal_history": {"kind": "constant", "value": 2.0}}, "discretization.zone"),
    ({"load.start": "braked", "load.creepage": None, "load.tangential": 0.5,
      "load.normal_history": {"kind": "table", "q": [0, 1, 2], "value": [1, 0, 1]}}, "load.tangential"),
    ({"load.start": "braked", "load.creepage": None, "load.tangential": 0.5,
      "load.normal_history": {"kind": "table", "q": [0, 2], "value": [1, 0.4]}}, "load.tangential"),
])
def test_bad_load_paths_are_one_line_errors_naming_the_key(changes, key):
    with pytest.raises(InputError) as err:
        circle(**changes)
    assert err.value.key == key and "\n" not in str(err.value), str(err.value)


def test_a_load_path_round_trips_and_plain_scenes_are_unchanged():
    """The keys survive to_dict / replace; a scene without them marches as before (the same records)."""
    s = braked(**{"load.rolled": REVERSE, "load.normal_history": {"kind": "ramp", "start": 1.0, "end": 1.2,
                                                                    "over": 2.0}})
    again = rollqp.scene.grid.scene_from_dict(s.to_dict())
    assert again == s and again.load.rolled.to_dict() == REVERSE | {"q": [0.0, 3.0, 4.0, 10.0],
                                                                     "value": [0.0, 3.0, 3.0, -3.0]}
    plain = braked(12, **{"discretization.distance": 1.0})
    assert plain.to_dict()["load"].keys().isdisjoint({"normal_history", "rolled"})
    same = braked(12, **{"discretization.distance": 1.0, "load.normal_history": {"kind": "constant", "value": 1.0},
                         "load.rolled": {"kind": "ramp", "start": 0.0, "end": 10.0, "over": 10.0}})
    a, b = run(plain).arrays(), run(same).arrays()
    assert np.allclose(a["px"], b["px"], rtol=0, atol=1e-12 * plain.ellipse.p0)


def test_a_load_path_resumes_where_it_stopped():
    """Roll, stop while the load (and Fx with it: the same history scaled) drops to 0 and comes back, roll back:
    a run resumed from any stored state (rolling, shift, out of contact) continues as the run that never stopped
    (to the resume check's tolerance; measured 2.4e-12 μp0)."""
    nh = {"kind": "table", "q": [0, 1, 1.2, 1.9, 2.2, 4], "value": [1, 1, 0, 0, 1, 1.2]}
    s = braked(12, **{"load.tangential": nh | {"value": [0.5 * v for v in nh["value"]]},
                      "load.rolled": {"kind": "table", "q": [0, 1, 2.5, 4], "value": [0, 1, 1, -0.5]},
                      "load.normal_history": nh, "discretization.distance": 4.0})
    full = run(s).arrays()
    K = full["q"].size
    phases = {"rolling": np.flatnonzero(plan(s).d != 0)[3], "unloaded": int(np.flatnonzero(full["FN"] == 0)[0]),
              "shift": int(np.flatnonzero(plan(s).d == 0)[-1])}
    assert full["FN"][phases["unloaded"]] == 0 and plan(s).d[phases["unloaded"]] == 0
    for what, k in phases.items():
        part = {n: (v[:k + 1] if isinstance(v, np.ndarray) and v.ndim >= 1 and v.shape[0] == K else v)
                for n, v in full.items()}
        again = run(s, resume=part).arrays()
        assert again["q"].size == K, what
        assert np.max(np.abs(again["px"] - full["px"])) / (s.mu * s.ellipse.p0) < 1e-10, what
        assert np.max(np.abs(again["pn"] - full["pn"])) / s.ellipse.p0 < 1e-10, what


def test_export_step_and_cross_check_pose_a_load_paths_steps():
    """export-step and the run's cross-check pose each step as the run did (its load, Δq, direction and loads):
    the run's own solution solves the exported step (rollqp's residuals at the solver tolerance) and the
    conic method agrees on the kept steps; an out-of-contact step is refused naming --step."""
    from rollqp.stepfile.three import export_step_3d
    from rollqp.crossval.grid import SpotObserver, cross_check
    nh = {"kind": "table", "q": [0, 1, 1.2, 1.9, 2.2, 4], "value": [1.2, 1, 0, 0, 1, 1.2]}
    s = braked(12, **{"load.tangential": nh | {"value": [0.5 * v for v in nh["value"]]},
                      "load.rolled": {"kind": "table", "q": [0, 1, 2.5, 4], "value": [0, 1, 1, -0.5]},
                      "load.normal_history": nh, "discretization.distance": 4.0})
    pl, fn = plan(s), s.load.normal_history(s.time_steps / s.ellipse.a)
    picks = {"start": 0, "rolling": 2, "stop with a changing load": int(np.flatnonzero((pl.d == 0) & (fn > 0))[-1]),
             "rolling back": int(np.flatnonzero(pl.d == 1)[1])}
    for what, k in picks.items():
        step = export_step_3d(s, k)
        assert step.FN == pytest.approx(s.load.normal * fn[k], rel=1e-12), what
        assert step.ref_residual < 1e-9, (what, step.ref_residual)
    with pytest.raises(InputError) as err:
        export_step_3d(s, int(np.flatnonzero(fn == 0)[0]))
    assert err.value.key == "--step" and "out of contact" in str(err.value)
    pytest.importorskip("clarabel")
    observer = SpotObserver(list(picks.values()))
    run(s, observe=observer)
    check = cross_check(s, observer, "newton", methods=["socp-clarabel"])
    assert len(check.per_step) == len(picks) and check.agrees, check.table()
