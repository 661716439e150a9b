"""Question: what do open ends add to an SPH step?

    NUMBA_NUM_THREADS=2 python bench/open_end_cost.py [--dps 0.02 0.01] [--seconds 1.0]

The flume of `wavesph demo` (wavesph/cases/demo_flume.py: open inlet, 2 m of flat bed, a 1:10
beach; linear wave H 0.04 m, T 1.4 s driven in process, windows T/50) stepped for ``--seconds``
simulated seconds after a warm-up second, against the same scene with the inlet closed by a wall
(still water: the same particles and the same dt within a few per cent). The open ends' own work
per step is the buffers' update and face crossings, the ghost-node pressure of the buffers and
the boundary gauge (sph_core/open_boundary.py), plus the windows' boundary data from Python.

One JSON object per dp: bench, dp, particles, closed_ms, open_ms (per step, the jitted loop's
time plus the windows' Python), open_over_closed, open_particle_steps_per_s, threads.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_WAIT_POLICY", "passive")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from sph_core.boundary_data import WaveModelBoundary  # noqa: E402
from sph_core.open_ends import flume_nodes  # noqa: E402
from sph_core.scene import make_scene  # noqa: E402
from sph_core.simulation import Simulation  # noqa: E402
from wave_client.theories import build_theory  # noqa: E402
from wavesph.cases.demo_flume import HEIGHT, PERIOD, demo_scene  # noqa: E402


def per_step_ms(sim: Simulation, seconds: float) -> float:
    """Wall ms per step over ``seconds`` simulated after the first (the numba cache's load)."""
    sim.advance_to(1.0)
    s0, tic = sim.steps, time.perf_counter()
    sim.advance_to(1.0 + seconds)
    return 1e3 * (time.perf_counter() - tic) / (sim.steps - s0)


def step_costs(dp: float, seconds: float) -> dict:
    data = demo_scene(dp, t_end=1.0 + seconds)
    closed = make_scene({k: v for k, v in data.items() if k != "open_boundaries"})
    ms_closed = per_step_ms(Simulation(closed), seconds)
    scene = make_scene(data)
    wave = build_theory("linear", height=HEIGHT, period=PERIOD, depth=scene.still_water_level)
    src = WaveModelBoundary(wave, flume_nodes(scene)["left"], scene.still_water_level, 0.0)
    sim = Simulation(scene, sources={"left": src}, window=PERIOD / 50)
    ms_open = per_step_ms(sim, seconds)
    return {"bench": "open_end_cost", "dp": dp, "particles": sim.n_particles,
            "closed_ms": round(ms_closed, 3), "open_ms": round(ms_open, 3),
            "open_over_closed": round(ms_open / ms_closed, 3),
            "open_particle_steps_per_s": round(sim.n_particles / (1e-3 * ms_open)),
            "threads": int(os.environ.get("NUMBA_NUM_THREADS", "0") or 0)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dps", type=float, nargs="+", default=[0.02, 0.01])
    ap.add_argument("--seconds", type=float, default=1.0, help="simulated seconds timed")
    a = ap.parse_args()
    for dp in a.dps:
        print(json.dumps(step_costs(dp, a.seconds)), flush=True)


if __name__ == "__main__":
    main()
