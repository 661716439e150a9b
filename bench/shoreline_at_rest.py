"""Question: where do fast particles at the still shoreline of a sloped bed come from?

Runs the demo beach flume (examples/scenes/demo_beach_flume.toml, closed at both ends, no wave)
at rest and reports, every ``--every`` s, the fastest fluid particle (speed, x, z, height above
the bed, fluid neighbours) and the lowest fluid pressure, one factor changed per variant:

    base        the scene as shipped (free-slip walls), closed inlet; the layout of
                sph_core.geometry: lattice points above a bed's polyline fluid, below it dummies
    band_half   fluid kept only at >= dp/2 from the bed polyline (the layout before the fix)
    band_dp     fluid kept only at >= dp from the bed polyline
    face        dummies only at >= dp/2 below the polyline (fluid as base)
    no_slip     wall_slip = "no_slip"
    flat        no beach: the same depth on a flat bed (the lattice meets only flat walls)
    wedge2      the wedge filled only where it holds >= 2 rows (wavesph.cases.coupled_flume.SHORE_ROWS)

    NUMBA_NUM_THREADS=1 python bench/shoreline_at_rest.py --dp 0.02 --t-end 1.5 --variants base,band_half

One JSON object per line (variant, t, v_max, x, z, above_bed, p_min).
"""

from __future__ import annotations

import argparse
import json
import tomllib
from pathlib import Path

import numpy as np

import sph_core.geometry as geometry
import sph_core.simulation as simulation
from sph_core.particles import FLUID, P, VX, VZ, X, Z
from sph_core.scene import make_scene, split_scene_file
from sph_core.simulation import Simulation

SCENE = Path(__file__).resolve().parents[1] / "examples/scenes/demo_beach_flume.toml"


def variant_scene(name: str, dp: float, t_end: float) -> dict:
    d, _ = split_scene_file(tomllib.loads(SCENE.read_text()))
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
    orig = simulation.build_layout
    band = {"band_half": 0.5 * dp, "band_dp": dp}.get(name)
    if band is not None or name == "face":
        def layout(sc):  # the shipped layout, then one band around each bed's polyline emptied
            lay = orig(sc)
            for bed in sc.beds:
                if band is not None:   # fluid only at >= band from the polyline (the old layout: dp/2)
                    d, _ = geometry._polyline_distance(bed, lay.fluid_x, lay.fluid_z)
                    k = d >= band * (1 - 1e-6)
                    lay.fluid_x, lay.fluid_z, lay.fluid_surface = lay.fluid_x[k], lay.fluid_z[k], lay.fluid_surface[k]
                else:                  # dummies only at >= dp/2 below the polyline
                    d, below = geometry._polyline_distance(bed, lay.wall_x, lay.wall_z)
                    k = ~(below & (d < 0.5 * dp))
                    lay.wall_x, lay.wall_z = lay.wall_x[k], lay.wall_z[k]
            return lay
        simulation.build_layout = layout
    try:
        sim = Simulation(scene)
    finally:
        simulation.build_layout = orig
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
    ap.add_argument("--variants", default="base,band_half,band_dp,face,flat")
    a = ap.parse_args()
    for name in a.variants.split(","):
        run_variant(name, a.dp, a.t_end, a.every)


if __name__ == "__main__":
    main()
