"""The scene's checks: each part key by key, then the scene as a whole, before any work.

Per part (:func:`check_body` … :func:`check_solver`): types and ranges of every key, through the
one set of validators (:mod:`rollqp.validate`). As a whole (:func:`check_whole`,
docs/formulation.md §1, §9): the loads over the rolled distance, the contact inside the zone, the
convective-local step, the BEM geometry, the derived quantities finite (no overflow from extreme
but finite inputs) and the work a scene asks for within bounds (nodes, steps, memory) — each
failure an :class:`~rollqp.errors.InputError` naming the key, the limit and what it would need.
"""
from __future__ import annotations

import math
import os
import re
from typing import Any

import numpy as np

from ..errors import InputError
from ..histories import Constant, Harmonic, parse_history
from ..influence import get_model
from ..influence.layer import check_relative, parse_layer
from ..methods import check_name as check_method
from .schema import (AUGMENTATION_MAX, AUGMENTATION_MIN, CONVECTIVE_STEP_MAX, COUPLINGS, EDGE_ELEMENTS,
                     ELEMENT_TYPES, FORMULATION_TYPES, MAX_ELEMENTS, MAX_NODES, MAX_START_STEPS, MAX_STEPS,
                     OPERATOR_MODES, STARTS,
                     Body, Contact, Discretization, Load, SolverSettings)
from ..validate import choice, integer, number, string
from ..units import UNIT_SYSTEMS
from ..profiles import parse_profile
from ..friction import parse_friction
from ..kinematics import plan
from ..profiles import check_cover
from ..advice import fast_path
from ..matrixfree import check_scene
from ..matrixfree import memory_estimate
from ..friction.capacity import COUPLING_STRIP, estimate, limits, margin_note, near_strip, strip_shares, worst
from ..strip import Strip

#: Largest coefficient of friction (beyond any material; tractions of μ·p stay far from overflow).
MAX_FRICTION = 1e6

#: A scene's ``name``: letters and digits (any script), space, and ``._+()-``; no path separators,
#: quotes or control characters (it names output files and appears in generated scripts).
NAME_PATTERN = re.compile(r"^[^\W_][\w .+()-]{0,99}$")


# =========================================================================== names
def check_units(key: str, v: Any) -> str:
    """The declared unit system (:data:`rollqp.units.UNIT_SYSTEMS`), or ``""`` for none."""
    if isinstance(v, str) and (v == "" or v in UNIT_SYSTEMS):  # a list or table is no name (and not hashable)
        return v
    raise InputError(key, f"must be one of {', '.join(map(repr, UNIT_SYSTEMS))} (the units the scene's numbers "
                          f"are in; leave it out if none fits), got {v!r}")


def check_scene_name(key: str, v: Any) -> str:
    """A scene's name (:data:`NAME_PATTERN`)."""
    v = string(key, v)
    if not NAME_PATTERN.match(v):
        raise InputError(key, f"must be 1 to 100 letters, digits, spaces or ._+()- starting with a letter or digit "
                              f"(no path separators or quotes), got {v[:60]!r}")
    return v


def safe_name(stem: str) -> str:
    """A default name made from a file stem: characters outside :data:`NAME_PATTERN` become ``_``."""
    s = re.sub(r"[^\w .+()-]", "_", stem)[:100].lstrip(" ._+()-")
    return s or "scene"


# =========================================================================== parts
def check_body(key: str, b: Any) -> Body:
    if not isinstance(b, Body):
        raise InputError(key, f"must be a Body, got {b!r}")
    radius = number(f"{key}.radius", b.radius, "> 0", lambda x: x > 0)
    E = number(f"{key}.E", b.E, "> 0", lambda x: x > 0)
    nu = number(f"{key}.nu", b.nu, "in (-1, 0.5)", lambda x: -1.0 < x < 0.5)
    shaft = b.shaft_radius
    if shaft is not None:
        shaft = number(f"{key}.shaft_radius", shaft, f"in (0, radius = {radius!r}) or absent",
                        lambda x: 0.0 < x < radius)
    wear = b.wear
    if wear is not None:  # Archard's k/H (docs/stresses.md §6)
        wear = number(f"{key}.wear", wear, ">= 0 (k/H in 1/stress) or absent", lambda x: x >= 0)
    profile = parse_profile(b.profile, f"{key}.profile", radius)
    return Body(radius, E, nu, shaft, None if profile.is_circle else profile, wear)


def check_contact(c: Any) -> Contact:
    if not isinstance(c, Contact):
        raise InputError("contact", f"must be a Contact, got {c!r}")
    mu = parse_friction(c.friction)  # a law (Coulomb's is also its number)
    model = get_model(c.model).name
    coupling = choice("contact.coupling", c.coupling, COUPLINGS)
    d = c.reference_distance
    if d is not None:
        d = number("contact.reference_distance", d, "> 0 or absent (then R)", lambda x: x > 0)
    mesh = [None if getattr(c, k) is None else
            integer(f"contact.{k}", getattr(c, k), "in [3, 2000] or absent", lambda n: 3 <= n <= 2000)
            for k in ("bem_outer_elements", "bem_inner_elements")]
    return Contact(mu, model, coupling, d, *mesh, parse_layer(c.layer))


def check_load(ld: Any) -> Load:
    if not isinstance(ld, Load):
        raise InputError("load", f"must be a Load, got {ld!r}")
    normal = number("load.normal", ld.normal, "> 0", lambda x: x > 0)
    nh = parse_history(ld.normal_history, "load.normal_history", constant_default=1.0)
    tang = None if ld.tangential is None else parse_history(ld.tangential, "load.tangential")
    creep = None if ld.creepage is None else parse_history(ld.creepage, "load.creepage")
    if tang is not None and creep is not None:
        raise InputError("load.creepage", "give exactly one of load.tangential and "
                                          "load.creepage, not both")
    if tang is None and creep is None:
        tang = Constant(0.0)
    start = choice("load.start", ld.start, STARTS)
    direction = ld.direction
    if not isinstance(direction, (int, np.integer)) or isinstance(direction, bool) \
            or direction not in (-1, 1):
        raise InputError("load.direction", f"must be -1 or +1, got {direction!r}")
    steps = integer("load.start_steps", ld.start_steps, f">= 1 (and <= {MAX_START_STEPS})",
                    lambda n: 1 <= n <= MAX_START_STEPS)
    approach = None if ld.approach is None else parse_history(ld.approach, "load.approach")
    if approach is not None and nh != Constant(1.0):
        raise InputError("load.approach", "give at most one of load.normal_history and load.approach "
                                          "(with a prescribed approach the normal load is an unknown)")
    rolled = None if ld.rolled is None else parse_history(ld.rolled, "load.rolled")
    return Load(normal, nh, tang, creep, start, int(direction), steps, approach, rolled)


def check_discretization(d: Any) -> Discretization:
    if not isinstance(d, Discretization):
        raise InputError("discretization", f"must be a Discretization, got {d!r}")
    return Discretization(
        elements=integer("discretization.elements", d.elements,
                          f">= 2 (and <= 20000 on the dense path, {MAX_ELEMENTS} matrix-free)",
                          lambda n: 2 <= n <= MAX_ELEMENTS),
        element=choice("discretization.element", d.element, ELEMENT_TYPES),
        zone=number("discretization.zone", d.zone, "> 1", lambda x: x > 1),
        step=number("discretization.step", d.step, "in (0, 8]", lambda x: 0 < x <= 8),
        formulation=choice("discretization.formulation", d.formulation, FORMULATION_TYPES),
        distance=number("discretization.distance", d.distance, ">= 0", lambda x: x >= 0))


def check_solver(s: Any) -> SolverSettings:
    if not isinstance(s, SolverSettings):
        raise InputError("solver", f"must be a SolverSettings, got {s!r}")
    return SolverSettings(
        method=check_method(s.method, "solver.method", dimension=2),
        tolerance=number("solver.tolerance", s.tolerance, "in [1e-15, 1e-2]",
                          lambda x: 1e-15 <= x <= 1e-2),
        max_iterations=None if s.max_iterations is None else integer(
            "solver.max_iterations", s.max_iterations, ">= 1 (and <= 100000) or absent (each method's default)",
            lambda n: 1 <= n <= 100_000),
        augmentation=None if s.augmentation is None else number(
            "solver.augmentation", s.augmentation,
            f"in [{AUGMENTATION_MIN:g}, {AUGMENTATION_MAX:g}] or absent (automatic)",
            lambda x: AUGMENTATION_MIN <= x <= AUGMENTATION_MAX),
        operator=None if s.operator is None else choice("solver.operator", s.operator,
                                                                          OPERATOR_MODES))



# =========================================================================== the scene as a whole
def check_whole(scene) -> None:
    """Every whole-scene check, in the order a user should meet them (module docstring)."""
    check_derived(scene)
    check_work(scene)
    check_loads(scene)
    check_convective_step(scene)
    check_model(scene)
    check_zone(scene)
    check_tangential(scene)
    check_sampling(scene)
    check_kinematics(scene)
    check_friction(scene)


def check_kinematics(scene) -> None:
    """``load.rolled``: every step's ``|Δq|`` within the step limits (``discretization.step``'s range, the
    convective-local CFL bound), and each body's profile against the strip and the run
    (:func:`rollqp.profiles.check_cover`)."""
    pl = plan(scene)
    if pl.rolled and pl.dq.size > 1:
        disc = scene.discretization
        limit = 8.0 if disc.formulation == "material" else CONVECTIVE_STEP_MAX[disc.element]
        big = float(np.max(pl.dq)) / scene.element_length
        if big > limit * (1 + 1e-12):
            k = int(np.argmax(pl.dq))
            raise InputError("load.rolled", f"|Δq| must stay in [0, {limit:g}] Le per step with formulation = "
                                            f"{disc.formulation!r}, but step {k} (τ = {pl.tau[k] / scene.a_H:.6g} a_H) "
                                            f"rolls {big:.6g} Le: use a smaller discretization.step")
    for key, body in (("bodies.A", scene.A), ("bodies.B", scene.B)):
        if body.profile is not None:
            check_cover(body.profile, f"{key}.profile", scene.half_width, pl.shift_range(),
                        get_model(scene.contact.model))


def check_derived(scene) -> None:
    """The derived quantities are finite and positive: extreme inputs (a tiny E, a huge load or
    zone, a tiny step) must not overflow into inf, 0 or NaN and fail later with a traceback."""
    values = (("a_H", "load.normal, bodies.*.E, bodies.*.radius", lambda: scene.a_H),
              ("p0", "load.normal, bodies.*.E, bodies.*.radius", lambda: scene.p0),
              ("E*", "bodies.A.E, bodies.B.E", lambda: scene.Estar),
              ("L = zone·a_H", "discretization.zone", lambda: scene.half_width),
              ("Δq = step·Le", "discretization.step", lambda: scene.dq))
    for what, keys, value in values:
        with np.errstate(all="ignore"):
            try:
                v = float(value())
            except (OverflowError, ZeroDivisionError, ValueError):
                v = float("nan")
        if not (math.isfinite(v) and v > 0.0 and v < 1e300):
            raise InputError(keys.split(",")[0], f"the derived {what} = {v!r} is out of range: "
                                                 f"{keys} are too extreme to compute with")
    check_strip_fits(scene)
    check_wear(scene)
    check_relative(scene.contact.layer, scene.a_H, scene.Estar)
    ratio = scene.discretization.distance * scene.a_H / scene.dq
    if not math.isfinite(ratio) or ratio > MAX_STEPS:
        raise InputError("discretization.distance",
                         f"asks for {ratio:.3g} steps of {scene.discretization.step:g} Le; at most {MAX_STEPS} "
                         f"are run (distance <= {MAX_STEPS * scene.dq / scene.a_H:.6g} a_H at this step)")


def check_wear(scene) -> None:
    """An Archard coefficient ``k/H`` (``bodies.X.wear``, 1/stress) gives ``k·p0/H`` <= 1: the worn depth per unit
    slip under the peak pressure is at most the slip itself (measured ones are 1e-9 to 1e-2); beyond, the wear
    rate ``(k/H)·p·|s|`` is no wear at all, and at 1e305 it is not even a number."""
    for key, body in (("bodies.A", scene.A), ("bodies.B", scene.B)):
        if body.wear is not None and not body.wear * scene.p0 <= 1.0:
            raise InputError(f"{key}.wear", f"must be a number in [0, 1/p0 = {1.0 / scene.p0:.6g}] (k/H in 1/stress: "
                                            f"Archard's k·p0/H is at most 1), got {body.wear!r}")


def check_strip_fits(scene) -> None:
    """The potential contact zone is shorter than either radius (the half-space strip lies on the
    cylinders), and their undeformed gap over it is computable (no overflow)."""
    L = scene.half_width
    for key, body in (("bodies.A", scene.A), ("bodies.B", scene.B)):
        if not L < body.radius:
            raise InputError("discretization.zone",
                             f"the zone half-width L = {L:.6g} (zone·a_H, a_H = {scene.a_H:.6g} from load.normal, "
                             f"the moduli and radii) is not below the radius of {key} ({body.radius!r}): "
                             f"the contact would be as wide as the roller")
        with np.errstate(over="raise", invalid="raise"):  # an underflow is harmless (a tiny gap)
            try:
                radius = np.float64(body.radius)
                float(L * L / (radius * (1.0 + np.sqrt(1.0 - (L / radius) ** 2))))
            except (FloatingPointError, OverflowError):
                raise InputError(f"{key}.radius", f"{body.radius!r} is too large to compute the gap with "
                                                  f"(over a zone of {L:.6g})") from None


def memory_limits(proc: str = "/proc") -> dict:
    """What limits the memory of this process, in bytes (a limit that is not set is absent):

    * ``"physical"``: the machine's memory;
    * ``"cgroup"``: the smallest ``memory.max`` (cgroup v2) or ``memory.limit_in_bytes`` (v1) of this
      process's cgroup and its parents (a container's or a batch job's limit);
    * ``"address space"``: ``RLIMIT_AS`` (``ulimit -v``) less the address space already mapped.

    ``proc``: where ``/proc`` is (a test gives a folder with ``self/cgroup``, ``self/mountinfo`` and the
    cgroup files under the mount points it names).
    """
    out = {}
    try:
        out["physical"] = float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        pass
    cg = _cgroup_limit(proc)
    if cg is not None:
        out["cgroup"] = cg
    try:
        import resource
        soft = resource.getrlimit(resource.RLIMIT_AS)[0]
    except (ImportError, OSError, ValueError):
        soft = -1
    if soft not in (-1, getattr(__import__("resource"), "RLIM_INFINITY", -1)) and soft > 0:
        out["address space"] = float(max(soft - _mapped(proc), 0))
    return out


def _mapped(proc: str) -> int:
    """The address space this process has mapped (``VmSize``), bytes."""
    try:
        with open(os.path.join(proc, "self", "status"), encoding="ascii", errors="replace") as fh:
            for line in fh:
                if line.startswith("VmSize:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return 0


#: A cgroup limit at or above this is no limit (cgroup v1 writes 2^63 rounded down to a page).
_NO_LIMIT = float(1 << 60)


def _cgroup_limit(proc: str) -> float | None:
    """The smallest memory limit of this process's cgroup and its parents (module docs: memory_limits)."""
    try:
        with open(os.path.join(proc, "self", "cgroup"), encoding="utf-8", errors="replace") as fh:
            groups = [line.rstrip("\n").split(":", 2) for line in fh if line.count(":") >= 2]
        with open(os.path.join(proc, "self", "mountinfo"), encoding="utf-8", errors="replace") as fh:
            mounts = [line.split() for line in fh]
    except OSError:
        return None
    best = None
    for hid, controllers, path in groups:
        v2 = hid == "0" and controllers == ""
        if not v2 and "memory" not in controllers.split(","):
            continue
        name = "memory.max" if v2 else "memory.limit_in_bytes"
        for root, point in _cgroup_mounts(mounts, v2):
            rel = path[len(root):] if root != "/" and path.startswith(root) else path
            for folder in _parents(rel):
                value = _read_limit(os.path.join(point, folder.lstrip("/"), name))
                if value is not None and value < _NO_LIMIT:
                    best = value if best is None else min(best, value)
    return best


def _cgroup_mounts(mounts, v2: bool):
    """``(root, mount point)`` of the cgroup2 mounts, or of the v1 mounts with the memory controller."""
    for m in mounts:
        if "-" not in m:
            continue
        dash = m.index("-")
        fstype = m[dash + 1] if len(m) > dash + 1 else ""
        opts = m[dash + 3].split(",") if len(m) > dash + 3 else []
        if (v2 and fstype == "cgroup2") or (not v2 and fstype == "cgroup" and "memory" in opts):
            yield m[3], m[4]


def _parents(path: str):
    """``/a/b/c``, ``/a/b``, ``/a``, ``/``."""
    parts = [p for p in path.split("/") if p]
    for i in range(len(parts), -1, -1):
        yield "/" + "/".join(parts[:i])


def _read_limit(path: str) -> float | None:
    try:
        with open(path, encoding="ascii", errors="replace") as fh:
            text = fh.read(64).strip()
    except OSError:
        return None
    return float(text) if text.isdigit() else None  # "max": no limit


def available_memory() -> float:
    """The memory this process may use, bytes: the least of :func:`memory_limits` (``inf`` if none is known)."""
    return min(memory_limits().values(), default=float("inf"))


def check_work(scene) -> None:
    """The work a scene asks for fits: nodes within :data:`MAX_NODES`, and the operators (the dense influence
    matrices, or the matrix-free work space) within the memory this process may use (:func:`memory_limits`) —
    refused before any work, with what they would need. A run's states go to its result file as they come
    (:mod:`rollqp.journal`); a run that keeps them in memory is checked by :func:`check_result_memory`."""
    if fast_path(scene).note is not None:
        return  # it runs matrix-free (rollqp.advice): the scene it runs as is checked when it is built
    n, K = scene.n_nodes, scene.n_steps
    dense = check_scene(scene, MAX_NODES, scene.method_capabilities) == "dense"
    need = (scene.memory_estimate() if dense else memory_estimate(scene)) - _result_bytes(n, K + 1)
    _refuse_beyond(need, "discretization.elements", f"its operators ({n} nodes)", "use fewer elements")


def _result_bytes(n: int, states: int) -> float:
    """The result's per-state arrays in memory, as the scene's memory estimates count them."""
    return 8.0 * 6 * states * n


def check_result_memory(scene, keep_every: int = 1) -> None:
    """A run that keeps its states in memory (:func:`rollqp.run` without ``out``) can hold them: the kept states
    (every ``keep_every``-th) and the operators within the memory this process may use."""
    n, K = scene.n_nodes, scene.n_steps
    dense = check_scene(scene, MAX_NODES, scene.method_capabilities) == "dense"
    kept = -(-(K + 1) // keep_every) + 1
    need = (scene.memory_estimate() if dense else memory_estimate(scene)) - _result_bytes(n, K + 1) + \
        _result_bytes(n, kept)
    _refuse_beyond(need, "discretization.distance", f"{kept} states of {n} nodes in memory",
                   "give the run a result file (rollqp run; run(..., out=PATH)), whose states are written as they "
                   "come, or keep every k-th state")


def _refuse_beyond(need: float, key: str, what: str, remedy: str) -> None:
    limits = memory_limits()
    which, memory = min(limits.items(), key=lambda kv: kv[1], default=("physical", float("inf")))
    if need > 0.8 * memory:
        source = {"physical": "this machine's memory", "cgroup": "the memory limit of this process's cgroup",
                  "address space": "the address space left under ulimit -v (RLIMIT_AS)"}[which]
        raise InputError(key, f"{what} need about {need / 2**30:.3g} GiB, more than 80 % of {source}, "
                              f"{memory / 2**30:.3g} GiB: {remedy}")


def check_loads(scene) -> None:
    """The normal load stays >= 0 over the run (0: out of contact)."""
    q_end = scene.q_end
    nmin, _ = scene.load.normal_history.extremes(q_end)
    if not nmin >= 0:
        raise InputError("load.normal_history",
                         f"must stay >= 0 over the rolled distance [0, {q_end:.6g}] a_H (a "
                         f"pull, P < 0, is not a contact problem), but its minimum is {nmin:.6g}")


def check_zone(scene) -> None:
    """The largest Hertz half-width stays :data:`EDGE_ELEMENTS`/2 elements inside each end of the zone."""
    disc = scene.discretization
    _, nmax = scene.load.normal_history.extremes(scene.q_end)
    free = 1.0 - EDGE_ELEMENTS / disc.elements
    if not math.sqrt(nmax) < disc.zone * free:
        raise InputError(
            "discretization.zone",
            f"the contact reaches the edge of the zone (needs zone > "
            f"{math.sqrt(nmax) / free:.6g} for the largest normal load {nmax:.6g}·P̄ with "
            f"{disc.elements} elements, leaving {EDGE_ELEMENTS / 2} of an element free at each end;"
            f" got {disc.zone!r})")


def check_tangential(scene) -> None:
    """Where a tangential load is prescribed, a stick solution exists at every step: ``|Q| < μP``; with a
    friction law varying along the strip, ``|Q|`` below its own sliding limit ``∫ μ p dx`` (:func:`sliding_limits`)."""
    load, q_end = scene.load, scene.q_end
    tang = load.tangential
    if tang is None:
        return
    tmin, tmax = tang.extremes(q_end)
    if scene.contact.mu == 0.0:
        if tmin != 0.0 or tmax != 0.0:
            raise InputError("load.tangential",
                             "must be 0 when contact.friction = 0 (it is Q/(mu P̄) and "
                             f"|Q| <= mu P = 0), got values in [{tmin:.6g}, {tmax:.6g}]")
        return
    varying = scene.contact.friction.kind == "spatial"
    nmin, _ = load.normal_history.extremes(q_end)
    if not varying and nmin > 0 and max(abs(tmin), abs(tmax)) / nmin < 1.0:  # a sufficient bound
        return
    q = np.unique(np.concatenate((scene.time_steps / scene.a_H, load.normal_history.critical_points(q_end),
                                  tang.critical_points(q_end))))
    Qr, Pr = np.abs(np.asarray(tang(q), dtype=float)), np.asarray(load.normal_history(q), dtype=float)
    Qr, Pr = Qr * np.ones_like(q), Pr * np.ones_like(q)
    with np.errstate(divide="ignore", invalid="ignore"):  # P = 0 (contact lost): Q must be 0 too
        ratio = np.where(Pr > 0, Qr / np.where(Pr > 0, Pr, 1.0), np.where(Qr > 0, np.inf, 0.0))
    i = int(np.argmax(ratio))
    if np.isinf(ratio[i]):
        raise InputError("load.tangential",
                         f"must be 0 where the normal load is 0 (contact lost), but Q/(mu P̄) = "
                         f"{float(tang(q[i])):.6g} at q = {q[i]:.6g} a_H where P = 0")
    if varying:
        c, limit = sliding_limits(scene, q, Pr, ratio)
        i = worst(ratio, limit)
        if not ratio[i] < limit[i]:
            raise InputError("load.tangential",
                             f"|Q|/(mu P) = {ratio[i]:.6g} at q = {q[i]:.6g} a_H must be < {limit[i]:.6g}: with "
                             f"contact.friction varying along the strip a stick solution exists only below its "
                             f"sliding limit |Q| < ∫ mu p dx = {c[i]:.6g} mu P (mu = {scene.contact.mu:g}, the law's "
                             f"reference{margin_note(c[i], limit[i])}); gross sliding is not supported (docs/friction.md)")
        return
    if not ratio[i] < 1.0:
        raise InputError("load.tangential",
                         f"|Q|/(mu P) must stay below 1 for a stick solution (gross sliding"
                         f" is not supported), but it reaches {ratio[i]:.6g} at q = "
                         f"{q[i]:.6g} a_H")


def sliding_limits(scene, q, n, ratio) -> tuple[np.ndarray, np.ndarray]:
    """The sliding limit of a 2D scene whose friction law varies along the strip
    (:mod:`rollqp.friction.capacity`): ``(c, limit)`` at the samples ``q`` (τ/a_H) of normal loads ``n·P̄``, in
    units of ``μ_ref P`` — ``c = Σ μ_i w_i/μ_ref`` of the Hertz pressure of ``P`` (half-width ``a_H·sqrt(n)``) at
    the strip's nodes with their weights, ``μ_i`` at the nodes at the rolled distance ``q(τ)`` as the steps read
    it, and ``limit`` the force the check allows below (``c`` plus the bound on the discrete pressure's
    difference). Computed only where ``ratio > 0`` and ``n > 0`` (elsewhere 1).

    Without Hertz's pressure before the solve (a body ``profile``, ``contact.model = "bem"``, a prescribed
    ``load.approach``) the limit is the largest ``μ`` on the strip (a load beyond it has no solution). Coupled
    dissimilar bodies add the coupling's shift of the pressure (:data:`~rollqp.friction.capacity.COUPLING_STRIP`)."""
    law, d = scene.contact.friction, scene.discretization
    strip = Strip(scene.half_width, d.elements, d.element)
    aH, ref, Le = scene.a_H, float(scene.contact.mu), scene.element_length
    hertzian = (scene.A.profile is None and scene.B.profile is None and scene.load.approach is None
                and get_model(scene.contact.model).halfspace_field)      # round rollers on half-spaces
    moving = getattr(law, "frame", "fixed") == "material"
    q, n, ratio = (np.asarray(v, dtype=float) * np.ones(np.shape(q)) for v in (q, n, ratio))
    qh = scene.rolled_distance(q * aH) / aH if moving else np.zeros_like(q)

    shares = {}

    def rule(nk, qk):
        mu = np.asarray(law.coefficient(strip.x[None, :] / aH, qk, scene.load.direction), dtype=float)
        if not hertzian:
            top = float(np.max(mu)) / ref
            return top, 0.0, top, 0.0
        if nk not in shares:
            b = aH * np.sqrt(nk)                              # 2D Hertz: the half-width ∝ sqrt(P)
            shares[nk] = (strip_shares(strip.x, strip.weights, b), near_strip(strip.x, b, Le), b / Le)
        return estimate(mu, *shares[nk][:2], ref, shares[nk][2])

    coupling = 0.0 if scene.coupling_level == "off" else COUPLING_STRIP * abs(scene.beta)
    return limits(n, qh, ratio, rule, coupling)


def check_sampling(scene) -> None:
    """A harmonic history is resolved by the steps: at least two steps per wavelength (Nyquist),
    else it would be sampled silently at an aliased frequency."""
    dq = scene.dq / scene.a_H
    if scene.n_steps == 0:
        return
    for key in ("normal_history", "tangential", "creepage", "approach"):
        h = getattr(scene.load, key)
        if isinstance(h, Harmonic) and h.amplitude != 0.0 and h.wavelength < 2.0 * dq:
            raise InputError(f"load.{key}.wavelength",
                             f"must be at least two steps, 2·Δq = {2 * dq:.6g} a_H, to be resolved (got "
                             f"{h.wavelength!r}: it would be sampled at an aliased wavelength); use a "
                             f"smaller discretization.step")


def check_model(scene) -> None:
    """The influence model's own checks of the scene (:attr:`Model.check <rollqp.influence.Model.check>`)."""
    check = get_model(scene.contact.model).check
    if check is not None:
        check(scene)


def check_convective_step(scene) -> None:
    """Convective-local slip is stable only for Δq up to the node spacing h.

    Its upwind term ``d·D_up w^{k−1}`` is explicit transport of ``w`` by Δq per step: a
    CFL condition, Δq ≤ h, with h = Le for constant and linear elements and Le/2 for
    quadratic ones (a midnode). Beyond it the transient does not settle: measured on
    §6.1.1 (``docs/stability.md``) the creepage oscillates by 3–17 % of Carter's from
    step to step and ends 4–34 % off, against ≤ 1.7 % (material, same Δq) and exactly
    the steady limit for Δq ≤ h. Rejected, naming ``discretization.step``.
    """
    disc = scene.discretization
    if disc.formulation != "convective-local":
        return
    limit = CONVECTIVE_STEP_MAX[disc.element]
    if disc.step > limit:
        raise InputError("discretization.step",
                         f"must be in (0, {limit:g}] with formulation = 'convective-local' and "
                         f"{disc.element} elements (Δq at most the node spacing: the upwind "
                         f"transport is unstable beyond it, docs/stability.md), got {disc.step!r}; "
                         f"use a smaller step or formulation = 'material'")


def check_friction(scene) -> None:
    """A friction law varying along the surface meets the strip during the run (:mod:`rollqp.friction`)."""
    law = scene.contact.friction
    key = law.varies_in_y() if hasattr(law, "varies_in_y") else None
    if key is not None:
        raise InputError(f"contact.friction.{key}", "makes μ vary along y, which only a 3D scene has (a 2D "
                                                    "scene's laws vary along x only: leave it out)")
    if law.kind == "spatial":  # (rollqp.friction.FrictionLaw: a spatial law checks that it meets the strip)
        q = scene.q_end / scene.a_H
        if scene.load.rolled is not None:  # a load path: the range of q it covers (stops, reversals)
            qs = plan(scene).q / scene.a_H
            q = (float(qs.min()), float(qs.max()))
        law.check_strip(scene.half_width / scene.a_H, q, scene.load.direction)
