r"""The Manchester contact benchmark, case A-2.2, as one table (docs/validation-wheel-rail.md).

An S1002 wheelset on UIC60 rails (inclined 1:40 in the profile file), gauge 1435 mm, back-to-back
1360 mm, nominal radius 460 mm, 10 kN vertical load per wheel, μ = 0.3, forward speed 2 m/s; lateral
displacement 0 → 10 mm with yaw 0 → 24 mrad in 21 positions. The wheelset's roll and angular velocity
per position are those of CONTACT's input files for the case (found there by balancing the two wheels'
vertical positions and rolling moments). :data:`POSITIONS` holds them; :func:`table` runs every position
for one or both wheels; :func:`read_reference` reads CONTACT's reference output (``.ref_out``) to
compare with.

Examples
--------
>>> len(POSITIONS), POSITIONS[12]
(21, (6.0, 0.0144, -0.0006272, -4.3293718))
"""
from __future__ import annotations

import math
import re
import time
from dataclasses import dataclass

from ..errors import InputError
from .run import solve_scene

__all__ = ["POSITIONS", "table", "read_reference", "Row"]

#: ``(lateral y_ws mm, yaw rad, roll rad, angular velocity about the axle rad/s)`` of the 21 positions
#: (CONTACT's mbench_a22 inputs; the same for both wheels).
POSITIONS = (
    (0.0, 0.0, 0.0, -4.34811810), (0.5, 0.0012, -0.00002304, -4.34741340), (1.0, 0.0024, -0.00005049, -4.34657520),
    (1.5, 0.0036, -0.00008103, -4.34624400), (2.0, 0.0048, -0.00011280, -4.34591970),
    (2.5, 0.0060, -0.00014570, -4.34556270), (3.0, 0.0072, -0.00018030, -4.34515030),
    (3.5, 0.0084, -0.00021680, -4.34466880), (4.0, 0.0096, -0.00025570, -4.34409300),
    (4.5, 0.0108, -0.00029770, -4.34337150), (5.0, 0.0120, -0.00035540, -4.33536370),
    (5.5, 0.0132, -0.00047770, -4.33188640), (6.0, 0.0144, -0.0006272, -4.3293718),
    (6.5, 0.0156, -0.00437600, -4.27488340), (7.0, 0.0168, -0.00639300, -4.26356290),
    (7.5, 0.0180, -0.00764200, -4.25757470), (8.0, 0.0192, -0.00860600, -4.25348570),
    (8.5, 0.0204, -0.00940800, -4.25032450), (9.0, 0.0216, -0.01010113, -4.24775610),
    (9.5, 0.0228, -0.01071386, -4.24556650), (10.0, 0.0240, -0.01126431, -4.24363750),
)


@dataclass
class Row:
    """One patch of one position: case number, wheel, and the quantities compared."""

    case: int
    wheel: str
    patch: int
    values: dict
    time: float


def table(scene, cases=None, sides=("left", "right"), progress=None):
    """Run the benchmark positions ``cases`` (1-based; default all 21) of the wheel–rail ``scene`` (its
    profiles, materials, friction, load and grid) for ``sides``: a list of :class:`Row` (``progress``: called
    with the rows of each position and wheel as they are done)."""
    cases = list(range(1, len(POSITIONS) + 1)) if cases is None else list(cases)
    for c in cases:
        if not (isinstance(c, int) and 1 <= c <= len(POSITIONS)):
            raise InputError("--cases", f"must be integers in [1, {len(POSITIONS)}], got {c!r}")
    rows = []
    for c in cases:
        y, yaw, roll, pitch = POSITIONS[c - 1]
        for side in sides:
            s = scene.replace(**{"wheelset.lateral": y, "wheelset.yaw": yaw, "wheelset.roll": roll,
                                 "wheelset.pitch_rate": pitch, "wheelset.side": side})
            t0 = time.perf_counter()
            wheels = solve_scene(s)
            elapsed = time.perf_counter() - t0
            for w in wheels:
                for k, p in enumerate(w.patches):
                    F = w.force_rail
                    rows.append(Row(c, side, k + 1, {
                        "z_ws": w.z, "FX_TR": F[0], "FY_TR": F[1], "FZ_TR": F[2], "XCP_TR": p.origin[0],
                        "YCP_TR": p.origin[1], "ZCP_TR": p.origin[2], "DELTCP": p.angle, "YCP_R": p.y_rail,
                        "ZCP_R": p.z_rail, "CKSI": p.creepage[0], "CETA": p.creepage[1], "CPHI": p.creepage[2],
                        "FN": p.FN, "FX": p.Fx, "FS": p.Fs, "MN": p.Mn, "APPROACH": p.approach, "PMAX": p.pmax,
                        "AREA": p.area}, elapsed))
            if progress is not None:
                progress([r for r in rows if r.case == c and r.wheel == side])
    return rows


_BLOCKS = {
    "WHEEL-SET POSITION": (("S_WS", "Y_WS", "Z_WS", "ROLL_WS", "YAW_WS", "PITCH_WS"), 1),
    "TOTAL FORCES ON RAIL": (("FX_TR", "FY_TR", "FZ_TR", "FX_WS", "FY_WS", "FZ_WS"), 1),
    "CONTACT REFERENCE LOCATION": (("XCP_TR", "YCP_TR", "ZCP_TR", "DELTCP", "YCP_R", "ZCP_R"), 1),
    "KINEMATIC CONSTANTS": (("CHI", "DQ", "VELOC", "CKSI", "CETA", "CPHI"), 1),
    "TOTAL FORCES, TORSIONAL": (("FN", "FX", "FS", "MN", "ELAST_EN", "FRIC_POWER"), 1),
}


def read_reference(path) -> list[dict]:
    """CONTACT's reference output of a module-1 run: per case a dict with ``case``, ``wheel`` and its
    patches (each a dict of the printed quantities: ``XCP_TR … ZCP_R``, ``CKSI``, ``CETA``, ``CPHI``,
    ``FN``, ``FX``, ``FS``, ``MN``, ``APPROACH``, ``PMAX``) and the wheel's ``Z_WS``, ``FX_TR``, ``FY_TR``,
    ``FZ_TR``. Only numbers are read."""
    try:
        lines = open(path, encoding="utf-8", errors="replace").read().splitlines()
    except OSError as exc:
        raise InputError("--reference", f"cannot read {path} ({exc.strerror or exc})") from None
    cases, cur, patch = [], None, None
    num = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
    for i, line in enumerate(lines):
        m = re.match(r"\s*Case\s+(\d+)", line)
        if m:
            cur = {"case": int(m.group(1)), "patches": []}
            cases.append(cur)
            continue
        if cur is None:
            continue
        if "WHEEL-RAIL CONTACT," in line:
            cur["wheel"] = "left" if "LEFT" in line else "right"
        if "DATA FOR CONTACT PATCH" in line:
            patch = {}
            cur["patches"].append(patch)
        for head, (names, skip) in _BLOCKS.items():
            if line.strip().startswith(head) and i + 2 < len(lines):
                vals = [float(v) for v in num.findall(lines[i + 1 + skip])]
                target = patch if head in ("CONTACT REFERENCE LOCATION", "KINEMATIC CONSTANTS",
                                           "TOTAL FORCES, TORSIONAL") else cur
                if target is not None and len(vals) == len(names):
                    target.update(dict(zip(names, vals)))
                if head == "TOTAL FORCES, TORSIONAL" and patch is not None and i + 4 < len(lines):
                    more = [float(v) for v in num.findall(lines[i + 4])]
                    if len(more) == 5:
                        patch["APPROACH"], patch["PMAX"] = more[3], more[4]
    for c in cases:
        if not math.isfinite(c.get("FZ_TR", math.nan)):
            raise InputError("--reference", f"{path}: case {c['case']} has no TOTAL FORCES ON RAIL block")
    return cases
