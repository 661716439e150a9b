"""The 3D dam break against a tall square structure (seed 004's 3D case): scene and comparison.

Yeh & Petroff's experiment (University of Washington), as Gomez-Gesteira & Dalrymple (2004, J.
Waterway Port Coastal Ocean Eng. 130(2):63-69) and Raad & Bidoae (2005, J. Comput. Phys.
203:668-699) model it: a tank 1.6 x 0.61 x 0.75 m, a water column 0.4 m long and 0.3 m high across
the whole width at the upstream wall (x = 0), the gate at x = 0.4 m, and a 0.12 x 0.12 m column
from the bed to the top with its upstream face at x = 0.9 m and y 0.25..0.37 m. The bed
downstream of the gate was wet (1 cm of water). The measured force on the column, F_x(t), is a
digitisation of Raad & Bidoae's Fig. 18 (data/tall_structure_force.csv, its header has the source;
a second digitisation, tests/data/tall_structure_force_anuga.csv, agrees within ~1 N in 0.1 s bins).

The comparison works on 0.05 s bin means (the digitised trace is a noisy point cloud): the peak
force error is (max F_sim - max F_exp) / max F_exp, the RMS error the RMS of the bin means'
difference over [t_from, t_to] divided by the measured peak.
"""

from __future__ import annotations

from importlib import resources

import numpy as np

from sph_core.scene import Scene, make_scene

TALL_TANK = (1.6, 0.61, 0.75)           # length, width, height [m]
TALL_COLUMN = (0.9, 1.02, 0.25, 0.37)   # x0, x1, y0, y1 of the column [m]
WATER = (0.4, 0.3)                 # length, height of the water column [m]
WET_BED = 0.01                     # water on the bed downstream of the gate [m]
BIN = 0.05                         # bin of the force comparison [s]
# 3D support: h/dp 1.5 (~110 neighbours; 2 gives ~270 at 2.4x the cost, and at dp 0.04 a lower
# peak force, 7.7 against 12.3 N: docs/developer/three_dimensions.md)
TALL_H_OVER_DP = 1.5
# artificial viscosity against the walls off (the 2D dam break keeps it at 1): with three walls
# around the surge (bed and both sides) it held the front back, the force's peak 11.6 N against
# 17.4 N without it at dp 0.02 (measured 28.5 N; docs/developer/three_dimensions.md)
TALL_ALPHA_WALL_FACTOR = 0.0


def measured_force() -> tuple[np.ndarray, np.ndarray]:
    """(t [s], F_x [N]) of the digitised measurement (module docstring)."""
    text = resources.files("wavesph.cases").joinpath("data/tall_structure_force.csv").read_text()
    rows = [ln for ln in text.splitlines() if ln and not ln.startswith("#")][1:]
    data = np.array([[float(v) for v in r.split(",")] for r in rows])
    return data[:, 0], data[:, 1]


def tall_structure_scene(dp: float = 0.02, t_end: float = 1.0, probe_every: float = 0.005,
                         snapshot_every: float = 0.0, wet_bed: bool | None = None,
                         scheme: dict | None = None, **constants) -> Scene:
    """The 3D case at spacing ``dp`` with a force probe ``column`` on the structure's particles.

    ``wet_bed``: the 1 cm layer downstream of the gate; default on when it holds a particle row
    (dp <= 1 cm), off at a coarser dp (a dry bed, as Proteus' model of the case). ``scheme``:
    the scene's [scheme] table (default wcsph).
    ``constants`` override the scene constants: alpha defaults to the dam break's 0.1
    (wavesph.cases.dambreak), h/dp to TALL_H_OVER_DP, the wall viscosity factor to
    TALL_ALPHA_WALL_FACTOR."""
    from .dambreak import DAMBREAK_ALPHA

    constants.setdefault("alpha", DAMBREAK_ALPHA)
    constants.setdefault("alpha_wall_factor", TALL_ALPHA_WALL_FACTOR)
    constants.setdefault("h_over_dp", TALL_H_OVER_DP)
    # c0 from the column's height (c0_factor sqrt(2 g H)), not the scene's tallest block
    constants.setdefault("c0", 10.0 * (2.0 * 9.81 * WATER[1]) ** 0.5)
    length, width, height = TALL_TANK
    x0, x1, y0, y1 = TALL_COLUMN
    wet = (dp <= WET_BED + 1e-12) if wet_bed is None else wet_bed
    blocks = [{"x0": 0.0, "x1": WATER[0], "z0": 0.0, "z1": WATER[1]}]
    if wet:
        blocks.append({"x0": WATER[0], "x1": length, "z0": 0.0, "z1": max(WET_BED, dp)})
    return make_scene({
        "name": "tall_structure_3d", "dim": 3, "dp": dp, "t_end": t_end,
        "tank": {"x0": 0.0, "x1": length, "y0": 0.0, "y1": width, "z0": 0.0, "z1": height},
        "water_blocks": blocks,
        "structures": [{"x0": x0, "x1": x1, "y0": y0, "y1": y1, "z0": 0.0, "z1": height}],
        "constants": constants, "scheme": scheme or {},
        "output": {"probe_every": probe_every, "snapshot_every": snapshot_every},
        "probes": [{"kind": "force", "name": "column", "x0": x0 - 0.5 * dp, "x1": x1 + 0.5 * dp,
                    "y0": y0 - 0.5 * dp, "y1": y1 + 0.5 * dp, "z0": 0.0, "z1": height}],
    })


def _bins(t: np.ndarray, f: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Mean of f in each bin [edges[k], edges[k + 1]) (NaN where empty)."""
    k = np.digitize(t, edges) - 1
    out = np.full(edges.size - 1, np.nan)
    for b in range(edges.size - 1):
        sel = k == b
        if sel.any():
            out[b] = f[sel].mean()
    return out


def force_errors(t: np.ndarray, fx: np.ndarray, t_from: float = 0.0,
                 t_to: float | None = None) -> dict[str, float]:
    """Peak and RMS errors of a simulated F_x(t) [N] against the measurement, on BIN-second bin
    means over [t_from, t_to] (default: to the end of the simulated record); the peak error is
    signed (positive: the simulation's peak is higher)."""
    te, fe = measured_force()
    t_to = float(np.max(t)) if t_to is None else t_to
    edges = np.arange(t_from, t_to + 1e-9, BIN)
    sim = _bins(np.asarray(t), np.asarray(fx), edges)
    exp = _bins(te, fe, edges)
    ok = np.isfinite(sim) & np.isfinite(exp)
    peak_exp = float(np.nanmax(exp))
    return {"peak_force_sim": float(np.nanmax(sim[ok])), "peak_force_exp": peak_exp,
            "peak_force_error": float((np.nanmax(sim[ok]) - peak_exp) / peak_exp),
            "rms_force_error": float(np.sqrt(np.mean((sim[ok] - exp[ok]) ** 2)) / peak_exp),
            "bins": int(ok.sum())}
