"""Does the ISPH still-water surface corner drift because of the wall particles above the water?
One JSON object per line (docs/studies/schemes.md "## ISPH", 2026-11-23).

    PYTHONPATH=. NUMBA_NUM_THREADS=1 python bench/isph_corner.py 1.6   # walls to 1.6 d (the test's tank)
    PYTHONPATH=. NUMBA_NUM_THREADS=1 python bench/isph_corner.py 1     # walls end dp/4 above the water

Still tank d = 0.25 m, d/dp 25, the scene's ISPH defaults, to 3.2 s (~20 sqrt(d/g)); every
0.25 s: x / dp and (z - d) / dp of the three top-row particles nearest the left wall at t = 0,
and the largest fluid speed. The argument is the wall height over d (<= 1.01: d + dp/4, so no
wall particle stands above the surface).
"""

from __future__ import annotations

import json
import sys

import numpy as np

from sph_core.particles import FLUID, VX, VZ, X, Z
from sph_core.scene import make_scene
from sph_core.simulation import Simulation

TANK_DEPTH = 0.25   # still-water depth d [m]
TANK_D_OVER_DP = 25


def main() -> None:
    dp = TANK_DEPTH / TANK_D_OVER_DP
    top = float(sys.argv[1]) if len(sys.argv) > 1 else 1.6
    z1 = top * TANK_DEPTH if top > 1.01 else TANK_DEPTH + 0.25 * dp
    sim = Simulation(make_scene({
        "name": "still_corner", "dp": dp, "t_end": 3.2, "still_water_level": TANK_DEPTH,
        "tank": {"x0": 0.0, "x1": 2 * TANK_DEPTH, "z0": 0.0, "z1": z1},
        "water_blocks": [{"x0": 0.0, "x1": 2 * TANK_DEPTH, "z0": 0.0, "z1": TANK_DEPTH}],
        "scheme": {"kind": "isph"}, "output": {"probe_every": 0.05}, "probes": []}))
    ps = sim.particles
    n = ps.n
    x, z = ps.f[X, :n], ps.f[Z, :n]
    surface = np.nonzero((ps.kind[:n] == FLUID) & (z > TANK_DEPTH - dp))[0]
    track = ps.ids[surface[np.argsort(x[surface])][:3]].copy()
    for t in np.arange(0.25, 3.21, 0.25):
        try:
            sim.advance_to(float(t))
        except Exception as e:  # the corner broke down: say when
            print(json.dumps({"z1_over_d": round(z1 / TANK_DEPTH, 3), "t": float(t), "error": str(e)[:160]}))
            break
        n = ps.n
        slot = {int(i): k for k, i in enumerate(ps.ids[:n])}
        at = [slot[int(i)] for i in track]
        fluid = ps.kind[:n] == FLUID
        print(json.dumps({"z1_over_d": round(z1 / TANK_DEPTH, 3), "t": float(t),
                          "x_over_dp": [round(float(ps.f[X, k]) / dp, 2) for k in at],
                          "z_over_dp": [round(float(ps.f[Z, k] - TANK_DEPTH) / dp, 2) for k in at],
                          "v_max": float(np.hypot(ps.f[VX, :n][fluid], ps.f[VZ, :n][fluid]).max())}),
              flush=True)


if __name__ == "__main__":
    main()
