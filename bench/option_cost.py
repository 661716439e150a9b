"""What does each accuracy option cost per particle-step, under the same load?

    python bench/option_cost.py [--dp 0.01] [--steps 2000] [--repeats 3] [--only WORD ...]

The closed tank of cases.standing_wave (1.0 x 0.24 m of water, moving) stepped a fixed number
of steps per variant; variants are interleaved and repeated so that a change of machine load hits
them alike. Each variant is the scene defaults with one option changed. Prints one JSON line per
variant: particles, particle_steps_per_s (best of the repeats), ratio to the baseline, and
steps_per_simulated_s (h/dp changes dt); the cost per simulated second is the product.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_WAIT_POLICY", "passive")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

from sph_core.particles import FLUID, VX, VZ, X, Z  # noqa: E402
from sph_core.scene import make_scene  # noqa: E402
from sph_core.simulation import Simulation  # noqa: E402

BASELINE = "baseline (defaults: h/dp 2, alpha_wall_factor 0)"
VARIANTS = {
    BASELINE: {},
    "h/dp sqrt(2)": {"h_over_dp": 1.4142},
    "alpha_wall_factor 1": {"alpha_wall_factor": 1.0},
    "shifting fickian": {"shifting": "fickian"},
    "shifting dplus": {"shifting": "dplus"},
}


def build(dp: float, constants: dict) -> Simulation:
    d, length, k = 0.24, 1.0, math.pi
    scene = make_scene({
        "name": "cost", "dp": dp, "t_end": 100.0, "still_water_level": d,
        "tank": {"x0": 0.0, "x1": length, "z0": 0.0, "z1": d + 0.1},
        "water_blocks": [{"x0": 0.0, "x1": length, "z0": 0.0, "z1": d}],
        "constants": {"c0": 10.0 * math.sqrt(9.81 * d), **constants},
        "output": {"probe_every": 0.0}})
    sim = Simulation(scene)
    ps = sim.particles
    fl = ps.kind[: ps.n] == FLUID
    x, z = ps.f[X, : ps.n][fl], ps.f[Z, : ps.n][fl]
    # a sloshing motion, so that velocity-dependent terms (shifting) do their work
    ps.f[VX, : ps.n][fl] = -0.05 * (z / d) * np.sin(k * x)
    ps.f[VZ, : ps.n][fl] = 0.05 * (z / d) * np.cos(k * x)
    return sim


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--dp", type=float, default=0.01)
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--only", nargs="+", default=None,
                    help="run the baseline and the variants whose name contains one of these words")
    a = ap.parse_args(argv)
    sims = {name: build(a.dp, cst) for name, cst in VARIANTS.items()
            if a.only is None or name == BASELINE or any(w in name for w in a.only)}
    for sim in sims.values():  # compile and settle
        sim.advance_steps(50)
    best = {name: 0.0 for name in sims}
    dt_step = {name: 0.0 for name in sims}
    for _ in range(a.repeats):
        for name, sim in sims.items():
            s0, tic = sim.steps, time.perf_counter()
            t0 = sim.t
            sim.advance_steps(a.steps)
            wall = time.perf_counter() - tic
            rate = sim.n_particles * (sim.steps - s0) / wall
            best[name] = max(best[name], rate)
            dt_step[name] = (sim.t - t0) / (sim.steps - s0)
    base = best[BASELINE]
    for name, sim in sims.items():
        print(json.dumps({"variant": name, "particles": sim.n_particles,
                          "particle_steps_per_s": round(best[name]),
                          "ratio_to_baseline": round(best[name] / base, 3),
                          "steps_per_simulated_s": round(1.0 / dt_step[name])}), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
