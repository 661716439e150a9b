"""The MARIN dam break with a box (Kleefsman et al. 2005; SPHERIC validation test 2): the second
3D reference, and the 3D dam break of the throughput bench.

Kleefsman, Fekken, Veldman, Iwanowski & Buchner (2005), J. Comput. Phys. 206:363-393: a tank
3.22 x 1.0 x 1.0 m (x = 0 at the downstream wall), a water column x 1.992..3.22 m across the whole
width, 0.55 m high, released at t = 0, and a box 0.161 x 0.403 x 0.161 m on the bed at
x 0.6635..0.8245, centred across the width. Measured (data/marin_dambreak.csv, every 0.01 s from
the SPHERIC test 2 file; its header has the source and the probe positions): water heights H2
(x 0.992) and H4 (x 2.638, in the reservoir) on the centreline, pressures P1 and P3 on the box's
face the flow hits (x 0.8245, z 0.021 and 0.101; taken on the centreline here, the sensors being
0.0255 m off it).
"""

from __future__ import annotations

from importlib import resources

import numpy as np

from sph_core.scene import Scene, make_scene

MARIN_TANK = (3.22, 1.0, 1.0)
WATER_X0, WATER_H = 1.992, 0.55
MARIN_BOX = (0.6635, 0.8245, 0.2985, 0.7015, 0.161)   # x0, x1, y0, y1, height
MARIN_GAUGES = {"H2": 0.992, "H4": 2.638}             # x of the water-height gauges (y 0.5)
MARIN_SENSORS = {"P1": 0.021, "P3": 0.101}            # z of the pressure sensors on the face x1


def measured() -> dict[str, np.ndarray]:
    """The measured record: t [s], H1..H4 [m], P1, P3, P5, P7 [Pa] (module docstring)."""
    text = resources.files("wavesph.cases").joinpath("data/marin_dambreak.csv").read_text()
    lines = [ln for ln in text.splitlines() if ln and not ln.startswith("#")]
    names = [c.split("_")[0] for c in lines[0].split(",")]
    data = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]])
    return dict(zip(names, data.T))


def marin_scene(dp: float = 0.02, t_end: float = 2.0, probe_every: float = 0.01,
                box: bool = True, **constants) -> Scene:
    """The MARIN case at spacing ``dp`` with the gauges H2, H4 (elevation) and the sensors P1,
    P3 (a pressure line on the box face); ``box`` False: the plain 3D dam break."""
    from .dambreak import DAMBREAK_ALPHA
    from .tall_structure import TALL_ALPHA_WALL_FACTOR, TALL_H_OVER_DP

    # the 3D dam break's settings (wavesph.cases.tall_structure: measured there)
    constants.setdefault("alpha", DAMBREAK_ALPHA)
    constants.setdefault("alpha_wall_factor", TALL_ALPHA_WALL_FACTOR)
    constants.setdefault("h_over_dp", TALL_H_OVER_DP)
    length, width, height = MARIN_TANK
    x0, x1, y0, y1, bh = MARIN_BOX
    probes = [{"kind": "elevation", "name": k, "x": x, "y": 0.5 * width} for k, x in MARIN_GAUGES.items()]
    if box:
        probes.append({"kind": "pressure_line", "name": "box", "y": 0.5 * width,
                       "points": [(x1, z) for z in MARIN_SENSORS.values()]})
    return make_scene({
        "name": "marin_dambreak_3d" if box else "dambreak_3d", "dim": 3, "dp": dp,
        "t_end": t_end,
        "tank": {"x0": 0.0, "x1": length, "y0": 0.0, "y1": width, "z0": 0.0, "z1": height},
        "water_blocks": [{"x0": WATER_X0, "x1": length, "z0": 0.0, "z1": WATER_H}],
        "structures": [{"x0": x0, "x1": x1, "y0": y0, "y1": y1, "z0": 0.0, "z1": bh}] if box else [],
        "constants": constants,
        "output": {"probe_every": probe_every},
        "probes": probes,
    })


def marin_errors(history: list[dict]) -> dict[str, float]:
    """RMS differences of the simulated H2, H4 [m] and P1, P3 [Pa] from the measurement at the
    simulation's record times (linear interpolation of the measurement; dry gauges count as
    zero height, dry sensors as zero pressure), and each over its measured range."""
    m = measured()
    t = np.array([r["t"] for r in history])
    t_max = min(t.max(), m["t"].max())
    sel = t <= t_max
    out: dict[str, float] = {}
    for name, col in [("H2", "H2_z_surface"), ("H4", "H4_z_surface"),
                      ("P1", "box_p0"), ("P3", "box_p1")]:
        sim = np.array([r.get(col) if r.get(col) is not None else 0.0 for r in history])[sel]
        ref = np.interp(t[sel], m["t"], m[name])
        rms = float(np.sqrt(np.mean((sim - ref) ** 2)))
        out[f"{name}_rms"] = rms
        out[f"{name}_rms_rel"] = rms / float(np.ptp(ref)) if np.ptp(ref) > 0 else float("nan")
    return out
