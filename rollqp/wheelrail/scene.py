r"""The wheel–rail scene: ``[contact] kind = "wheel-rail"`` (docs/wheel-rail.md, "Scene").

::

    name = "mbench-a22"
    units = "N-mm"
    [contact]
    dimension = 3
    kind = "wheel-rail"
    friction = 0.3
    [wheelset]
    wheel_profile = "MBench_S1002_v3.prw"   # .prw/.prr (SIMPACK) or a two-column y, z table
    rail_profile = "MBench_UIC60_v3.prr"
    nominal_radius = 460.0
    back_to_back = 1360.0
    flange_back = -70.0      # the flange back's lateral position in the wheel profile (optional)
    lateral = 2.0
    yaw = 0.0048
    roll = -1.128e-4         # optional, default 0
    pitch_rate = -4.3459197  # optional: free rolling at nominal_radius
    load = 10000.0           # vertical load per wheel (or vertical = z_ws, mm down, prescribed)
    speed = 2000.0
    side = "left"            # "left" | "right" | "both"
    E = 209920.0
    nu = 0.28                # or wheel_E, wheel_nu, rail_E, rail_nu
    [track]
    gauge = 1435.0
    [discretization]
    element_size = 0.2       # or [dx, ds]

Further optional keys: ``[wheelset]`` ``wheel_mirror_y``, ``rail_mirror_y``, ``wheel_scale``,
``rail_scale``, ``wheel_smooth``, ``rail_smooth`` (mm, the smoothing spline's wavelength), ``vy``,
``vz``, ``roll_rate``, ``yaw_rate``; ``[track]`` ``gauge_height`` (14 mm), ``cant`` (rad, 0: the profile
is already inclined); ``[discretization]`` ``combine`` (mm, 4), ``separate_angle`` (rad, π/2);
``[solver]`` ``method`` (``newton``), ``tolerance`` (1e-10). Profile files are read from the scene
file's folder only (a built-in scene: the package's own data), never outside it.
"""
from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any, ClassVar

from ..errors import InputError
from ..materials import Materials
from ..methods import DEFAULT_METHOD, require_3d
from ..scene.core import SceneBase
from ..validate import suggestion
from .profiles import read_profile, resolve_file
from .wheelset import State

__all__ = ["WheelRailScene", "scene_from_dict", "KEYS"]

#: Every key of each table, with its default (``REQUIRED``: must be given).
REQUIRED = object()
KEYS = {
    "contact": {"dimension": 3, "kind": "wheel-rail", "friction": REQUIRED},
    "wheelset": {"wheel_profile": REQUIRED, "rail_profile": REQUIRED, "wheel_mirror_y": False, "rail_mirror_y": False,
                 "wheel_scale": 1.0, "rail_scale": 1.0, "wheel_smooth": 0.0, "rail_smooth": 0.0,
                 "nominal_radius": REQUIRED, "back_to_back": REQUIRED, "flange_back": -70.0, "lateral": 0.0,
                 "yaw": 0.0, "roll": 0.0, "vertical": None, "load": None, "pitch_rate": None, "speed": 2000.0,
                 "vy": 0.0, "vz": 0.0, "roll_rate": 0.0, "yaw_rate": 0.0, "side": "both", "E": None, "nu": None,
                 "wheel_E": None, "wheel_nu": None, "rail_E": None, "rail_nu": None},
    "track": {"gauge": 1435.0, "gauge_height": 14.0, "cant": 0.0},
    "discretization": {"element_size": REQUIRED, "combine": 4.0, "separate_angle": math.pi / 2},
    "solver": {"method": DEFAULT_METHOD, "tolerance": 1e-10},
}
TOP = {"name": None, "description": "", "units": "N-mm"}
SIDES = ("left", "right", "both")


def _real(key, v, lo=None, hi=None, positive=False):
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise InputError(key, f"must be a finite number, got {v!r}")
    v = float(v)
    if positive and not v > 0:
        raise InputError(key, f"must be > 0, got {v!r}")
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        raise InputError(key, f"must be in [{lo:g}, {hi:g}], got {v!r}")
    return v


def _data_folder():
    return resources.files("rollqp.wheelrail").joinpath("data")


@dataclass(frozen=True)
class WheelRailScene(SceneBase):
    """A validated wheel–rail scene (module docstring): ``data`` the nested dict with defaults filled in."""

    data: dict
    source: str = field(default="<dict>", compare=False)
    dimension: ClassVar[int] = 3
    family: ClassVar[str] = "wheel-rail"
    n_steps: ClassVar[int] = 0

    @property
    def name(self) -> str:
        return self.data["name"]

    @property
    def solver(self):
        from types import SimpleNamespace
        return SimpleNamespace(**self.data["solver"])

    @property
    def folder(self) -> Path:
        """Where the profile files are read: the scene file's folder (built-ins: the package's data)."""
        if self.source.startswith("builtin:"):
            return Path(str(_data_folder()))
        if self.source.startswith("<"):
            return Path.cwd()
        return Path(self.source).resolve().parent

    def to_dict(self) -> dict:
        return {k: v for k, v in copy.deepcopy(self.data).items() if v is not None}

    def to_toml(self) -> str:
        import tomli_w
        d = self.to_dict()
        for t in KEYS:
            d[t] = {k: v for k, v in d[t].items() if v is not None}
        return tomli_w.dumps(d)

    def replace(self, **changes: Any) -> "WheelRailScene":
        d = copy.deepcopy(self.data)
        for key, value in changes.items():
            table, _, name = key.partition(".")
            if not name:
                d[table] = value
            else:
                d.setdefault(table, {})[name] = value
        return scene_from_dict(d, source=self.source)

    # ------------------------------------------------------------------ the parts
    def sides(self) -> tuple:
        s = self.data["wheelset"]["side"]
        return ("left", "right") if s == "both" else (s,)

    def profiles(self):
        """``(rail, wheel)`` read from their files (module docstring)."""
        w = self.data["wheelset"]
        out = []
        for kind in ("rail", "wheel"):
            key = f"wheelset.{kind}_profile"
            path = resolve_file(w[f"{kind}_profile"], key, self.folder)
            out.append(read_profile(path, kind, mirror_y=w[f"{kind}_mirror_y"], scale=w[f"{kind}_scale"],
                                    smooth=w[f"{kind}_smooth"], name=f"{key} {w[kind + '_profile']!r}"))
        return tuple(out)

    def materials(self):
        w = self.data["wheelset"]
        E = {b: w.get(f"{b}_E") if w.get(f"{b}_E") is not None else w.get("E") for b in ("wheel", "rail")}
        nu = {b: w.get(f"{b}_nu") if w.get(f"{b}_nu") is not None else w.get("nu") for b in ("wheel", "rail")}
        for b in ("wheel", "rail"):
            if E[b] is None or nu[b] is None:
                raise InputError(f"wheelset.{b}_E", "give E and nu (both bodies) or wheel_E, wheel_nu, rail_E, "
                                                   "rail_nu")
        return Materials.from_young(E["rail"], nu["rail"], E["wheel"], nu["wheel"])

    def state(self):
        w = self.data["wheelset"]
        return State(lateral=w["lateral"], vertical=w["vertical"] or 0.0, roll=w["roll"], yaw=w["yaw"],
                     speed=w["speed"], pitch_rate=w["pitch_rate"], vy=w["vy"], vz=w["vz"], roll_rate=w["roll_rate"],
                     yaw_rate=w["yaw_rate"])

    @property
    def element_size(self) -> tuple:
        e = self.data["discretization"]["element_size"]
        return (e, e) if isinstance(e, float) else tuple(e)


def _check_contact(c):
    if c["dimension"] != 3 or c["kind"] != "wheel-rail":
        raise InputError("contact.kind", "a wheel-rail scene has dimension = 3 and kind = \"wheel-rail\"")
    c["friction"] = _real("contact.friction", c["friction"], lo=0.0, hi=10.0)


def _check_wheelset(w):
    for k in ("wheel_profile", "rail_profile"):
        if not isinstance(w[k], str) or not w[k]:
            raise InputError(f"wheelset.{k}", f"must be a file name, got {w[k]!r}")
    for k in ("wheel_mirror_y", "rail_mirror_y"):
        if not isinstance(w[k], bool):
            raise InputError(f"wheelset.{k}", f"must be true or false, got {w[k]!r}")
    for k in ("wheel_scale", "rail_scale", "nominal_radius", "back_to_back", "speed"):
        w[k] = _real(f"wheelset.{k}", w[k], positive=True)
    for k in ("wheel_smooth", "rail_smooth"):
        w[k] = _real(f"wheelset.{k}", w[k], lo=0.0, hi=100.0)
    for k in ("flange_back", "lateral", "vy", "vz", "roll_rate", "yaw_rate"):
        w[k] = _real(f"wheelset.{k}", w[k])
    for k in ("yaw", "roll"):
        w[k] = _real(f"wheelset.{k}", w[k], lo=-0.2, hi=0.2)
    if (w["load"] is None) == (w["vertical"] is None):
        raise InputError("wheelset.load", "give exactly one of load (the vertical force per wheel) and vertical "
                                          "(the wheelset's vertical position)")
    if w["load"] is not None:
        w["load"] = _real("wheelset.load", w["load"], positive=True)
    if w["vertical"] is not None:
        w["vertical"] = _real("wheelset.vertical", w["vertical"], lo=-50.0, hi=50.0)
    if w["pitch_rate"] is not None:
        w["pitch_rate"] = _real("wheelset.pitch_rate", w["pitch_rate"])
    if w["side"] not in SIDES:
        raise InputError("wheelset.side", f"must be one of {', '.join(SIDES)}, got {w['side']!r}")
    for k in ("E", "wheel_E", "rail_E"):
        if w[k] is not None:
            w[k] = _real(f"wheelset.{k}", w[k], positive=True)
    for k in ("nu", "wheel_nu", "rail_nu"):
        if w[k] is not None:
            w[k] = _real(f"wheelset.{k}", w[k], lo=-0.99, hi=0.5)


def _check_rest(out):
    t = out["track"]
    t["gauge"] = _real("track.gauge", t["gauge"], positive=True)
    t["gauge_height"] = _real("track.gauge_height", t["gauge_height"], positive=True)
    t["cant"] = _real("track.cant", t["cant"], lo=-0.2, hi=0.2)
    disc = out["discretization"]
    e = disc["element_size"]
    if isinstance(e, (list, tuple)):
        if len(e) != 2:
            raise InputError("discretization.element_size", f"must be one size or [dx, ds], got {e!r}")
        disc["element_size"] = [_real("discretization.element_size", v, lo=1e-3, hi=10.0) for v in e]
    else:
        disc["element_size"] = _real("discretization.element_size", e, lo=1e-3, hi=10.0)
    disc["combine"] = _real("discretization.combine", disc["combine"], lo=0.0, hi=100.0)
    disc["separate_angle"] = _real("discretization.separate_angle", disc["separate_angle"], lo=0.0, hi=math.pi)
    s = out["solver"]
    s["tolerance"] = _real("solver.tolerance", s["tolerance"], lo=1e-14, hi=1e-3)
    if not isinstance(s["method"], str):
        raise InputError("solver.method", f"must be a method name, got {s['method']!r}")
    require_3d(s["method"], "solver.method")


def scene_from_dict(d: Any, source: str = "<dict>", default_name: str = "scene") -> WheelRailScene:
    """Validate a wheel–rail scene's nested dict (module docstring); every error names its key."""
    if not isinstance(d, dict):
        raise InputError("scene", "must be a table")
    out = {}
    for k, v in d.items():
        if k not in TOP and k not in KEYS:
            raise InputError(k, f"unknown key of a wheel-rail scene{suggestion(k, [*TOP, *KEYS])}; tables: "
                                f"{', '.join(KEYS)}")
    for k, default in TOP.items():
        out[k] = d.get(k, default)
    out["name"] = str(out["name"] or default_name)
    for k in ("name", "description", "units"):
        if not isinstance(out[k], str):
            raise InputError(k, f"must be a string, got {out[k]!r}")
    for table, keys in KEYS.items():
        given = d.get(table, {})
        if not isinstance(given, dict):
            raise InputError(table, "must be a table")
        for k in given:
            if k not in keys:
                raise InputError(f"{table}.{k}", f"unknown key{suggestion(k, keys)}; keys of [{table}]: "
                                                 f"{', '.join(keys)}")
        t = {}
        for k, default in keys.items():
            if k not in given and default is REQUIRED:
                raise InputError(f"{table}.{k}", "is required in a wheel-rail scene")
            t[k] = given.get(k, default)
        out[table] = t
    _check_contact(out["contact"])
    _check_wheelset(out["wheelset"])
    _check_rest(out)
    scene = WheelRailScene(out, source=str(source))
    scene.materials()           # E and nu given
    return scene
