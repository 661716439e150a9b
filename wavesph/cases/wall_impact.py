"""A violent dam break against a wall: Lobovsky et al. (2014), H = 300 mm.

Geometry (their Fig. 1, 2D section): a tank 1.61 m long and 0.6 m high; the water column
0.6 m long and H = 0.3 m high at the left wall, released at t = 0; the surge hits the far (right)
wall at x = 1.61 m. Pressure sensors on that wall at z = 3, 15, 30 and 80 mm above the bed
(sensor 1 = 3 mm). The tank length is 402.5 dp at dp = 0.004 m: not a whole
number of spacings, the case that exposed the corner leak (docs/studies/wall_pressure.md).

Experiment: L. Lobovsky, E. Botia-Vera, F. Castellana, J. Mas-Soler, A. Souto-Iglesias,
"Experimental investigation of dynamic pressure loads during dam break", J. Fluids Struct. 48
(2014) 407-434, doi:10.1016/j.jfluidstructs.2014.03.009. The sensor-1 trace in
tests/data/lobovsky_2014_h300_sensor1.csv is one realisation sampled at 20 kHz (TNL-SPH: "peak event 5"
of their Fig. 18), as distributed with TNL-SPH (MIT licence), in their units t sqrt(g/H) and
p / (rho g H).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from sph_core.scene import Scene, make_scene

from .dambreak import DAMBREAK_ALPHA

LOBOVSKY_TANK_LENGTH = 1.61    # [m]
TANK_HEIGHT = 0.6     # [m], the experiment's
# the model's walls rise higher: in 2D the run-up jet on the far wall passes 0.6 m from t = 0.64 s
# (dp 0.008, no wall viscosity) and particles over the top would be excluded, as in
# wavesph.cases.dambreak (walls 5a high); only the later sloshing sees the difference
WALL_HEIGHT = 1.2     # [m]
COLUMN_LENGTH = 0.6   # [m]
COLUMN_HEIGHT = 0.3   # [m] = H, the scale of the experiment's units
SENSOR_Z = (0.003, 0.015, 0.030, 0.080)  # [m] above the bed, on the far wall
# the gate (``gate_speed``): a plate GATE_THICKNESS_DP spacings thick at the column's face, from
# the bed to GATE_TOP, lifted GATE_LIFT at constant speed from t = 0 (the experiment's gate is
# pulled up; its speed is not reported, and its impact time says it was fast:
# docs/studies/wall_pressure.md, "Friction: what it moves and what it does not"). Thicker than
# the kernel support 2h at any h/dp <= 2, so the water beyond it does not feel the column through it
GATE_THICKNESS_DP = 5
GATE_TOP = 0.4        # [m]
GATE_LIFT = 0.45      # [m]: the plate's bottom clears the column's top by 0.15 m
LOBOVSKY_SENSOR1 = (Path(__file__).resolve().parents[2] / "tests" / "data"
                    / "lobovsky_2014_h300_sensor1.csv")


def lobovsky_scene(dp: float = 0.004, t_end: float = 2.0, probe_every: float = 2.5e-4,
                   snapshot_every: float = 0.0, tank_length: float = LOBOVSKY_TANK_LENGTH,
                   wall_height: float = WALL_HEIGHT, scheme: dict | None = None,
                   gate_speed: float | None = None, **constants) -> Scene:
    """The H = 300 mm dam break with the far-wall sensors as a ``pressure_line`` named ``wall``
    (points on the wall face x = tank_length) and the wall's horizontal force (``force`` probe
    ``wall_force``, the dummy particles of the right wall below 0.1 m).

    The walls rise to ``wall_height`` (WALL_HEIGHT; the experiment's tank is TANK_HEIGHT high).
    ``constants`` override the scene constants; alpha defaults to DAMBREAK_ALPHA. ``scheme``:
    the scene's [scheme] table (default wcsph). ``gate_speed`` [m/s]: release the column by
    lifting a gate at that speed (a prescribed body named ``gate``) instead of all at once."""
    constants.setdefault("alpha", DAMBREAK_ALPHA)
    L = tank_length
    bodies = []
    if gate_speed is not None:
        if not gate_speed > 0:
            raise ValueError(f"gate_speed: must be > 0 m/s, got {gate_speed}")
        bodies = [{"name": "gate", "shape": "box", "x0": COLUMN_LENGTH,
                   "x1": COLUMN_LENGTH + GATE_THICKNESS_DP * dp, "z0": 0.0, "z1": GATE_TOP,
                   "motion": "prescribed",
                   "series": [(0.0, 0.0, 0.0, 0.0), (GATE_LIFT / gate_speed, 0.0, GATE_LIFT, 0.0)]}]
    return make_scene({
        "name": "lobovsky_2014_h300",
        "dp": dp, "t_end": t_end,
        "tank": {"x0": 0.0, "x1": L, "z0": 0.0, "z1": wall_height},
        "water_blocks": [{"x0": 0.0, "x1": COLUMN_LENGTH, "z0": 0.0, "z1": COLUMN_HEIGHT}],
        "constants": constants,
        **({"scheme": scheme} if scheme else {}),
        **({"bodies": bodies} if bodies else {}),
        "output": {"probe_every": probe_every, "snapshot_every": snapshot_every},
        "probes": [
            {"kind": "pressure_line", "name": "wall", "points": [[L, z] for z in SENSOR_Z]},
            {"kind": "force", "name": "wall_force", "x0": L, "x1": L + 0.05, "z0": -0.05,
             "z1": 0.1},
        ],
    })


def lobovsky_sensor1(path: str | Path | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(t [s], p [Pa]) of the experiment's sensor 1 (z = 3 mm), H = 0.3 m, g = 9.81, rho = 1000."""
    data = _read_csv(path or LOBOVSKY_SENSOR1)
    t_star, p_star = data[:, 0], data[:, 1]
    H, g, rho = COLUMN_HEIGHT, 9.81, 1000.0
    return t_star * math.sqrt(H / g), p_star * rho * g * H


def _read_csv(path: str | Path) -> np.ndarray:
    rows = [ln for ln in Path(path).read_text().splitlines() if ln and not ln.startswith("#")]
    return np.array([[float(v) for v in r.split(",")] for r in rows[1:]])


def first_peak(t: np.ndarray, p: np.ndarray, t_max: float) -> tuple[float, float]:
    """(t, p) of the largest pressure before ``t_max`` [s] (the first impact's peak)."""
    sel = np.nonzero(t <= t_max)[0]
    k = sel[np.nanargmax(p[sel])]
    return float(t[k]), float(p[k])
