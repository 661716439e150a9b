"""Question: where do fast particles at the still shoreline of a sloped bed come from?

Runs the demo beach flume (examples/scenes/demo_beach_flume.toml, closed at both ends, no wave)
at rest and reports, every ``--every`` s, the fastest fluid particle (speed, x, z, height above
the bed, fluid neighbours) and the lowest fluid pressure, one factor changed per variant:

    base        the scene as shipped (free-slip walls), closed inlet
    no_slip     wall_slip = "no_slip"
    gap_dp      fluid kept only at >= dp (not dp/2) from the bed polyline
    flat        no beach: the same depth on a flat bed (the lattice meets only flat walls)
    wedge2      the wedge filled only where it holds >= 2 rows (cases/coupled_flume.SHORE_ROWS)

    NUMBA_NUM_THREADS=1 python bench/shoreline_at_rest.py --dp 0.02 --t-end 1.5

One JSON object per line (variant, t, v_max, x, z, above_bed, p_min).
"""

from __future__ import annotations

import argparse
import json
import tomllib
from pathlib import Path

import numpy as np

import sph_core.geometry as geometry
from sph_core.particles import FLUID, P, VX, VZ, X, Z
from sph_core.scene import make_scene
from sph_core.simulation import Simulation

SCENE = Path(__file__).resolve().parents[1] / "examples/scenes/demo_beach_flume.toml"


def variant_scene(name: str, dp: float, t_end: float) -> dict:
    d = tomllib.loads(SCENE.read_text())
    d.pop("open_boundaries")
    d.update(dp=dp, t_end=t_end, probes=[])
    if name == "no_slip":
        d["constants"]["wall_slip"] = "no_slip"
    if name == "wedge2":
        d["water_blocks"][0]["x1"] = 2.0 + (d["still_water_level"] - 2 * dp) / 0.1
    if name == "flat":
        d.pop("beds")
        d["water_blocks"][0]["x1"] = d["tank"]["x1"]
    return d


def run_variant(name: str, dp: float, t_end: float, every: float) -> None:
    scene = make_scene(variant_scene(name, dp, t_end))
    orig = geometry._polyline_distance
    if name == "gap_dp":  # shift the kept fluid: distance to the polyline >= dp instead of dp/2
        def shifted(bed, x, z):
            dist, below = orig(bed, x, z)
            return dist + 0.5 * dp * (dist < dp), below
        geometry._polyline_distance = shifted
    try:
        sim = Simulation(scene)
    finally:
        geometry._polyline_distance = orig
    bed = scene.beds[0].points if scene.beds else [(0.0, 0.0), (scene.tank.x1, 0.0)]
    bx, bz = np.array(bed).T
    t = 0.0
    while t < t_end - 1e-9:
        t = min(t + every, t_end)
        sim.advance_to(t)
        ps = sim.particles
        sel = ps.mask(FLUID)
        x, z = ps.field(X)[sel], ps.field(Z)[sel]
        v = np.hypot(ps.field(VX)[sel], ps.field(VZ)[sel])
        p = ps.field(P)[sel]
        k = int(np.argmax(v))
        print(json.dumps({"variant": name, "dp": dp, "t": round(sim.t, 4), "v_max": round(float(v[k]), 4),
                          "x": round(float(x[k]), 4), "z": round(float(z[k]), 4),
                          "above_bed": round(float(z[k] - np.interp(x[k], bx, bz)), 4),
                          "n_fast": int((v > 0.1).sum()),
                          "p_min": round(float(p.min()), 1), "x_p_min": round(float(x[np.argmin(p)]), 4),
                          "excluded": len(sim.excluded)}), flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dp", type=float, default=0.02)
    ap.add_argument("--t-end", type=float, default=1.5)
    ap.add_argument("--every", type=float, default=0.25)
    ap.add_argument("--variants", default="base,no_slip,gap_dp,flat")
    a = ap.parse_args()
    for name in a.variants.split(","):
        run_variant(name, a.dp, a.t_end, a.every)


if __name__ == "__main__":
    main()
