"""Does particle shifting beside an open end move water through it? Fluid count under a
zero-mean oscillating flow.

    python bench/open_end_mass.py [--periods 5] [--dp 0.02] [--variants JSON]

A flume 0.6 m long, still water 0.3 m deep (the test flume of tests/test_sph_core/test_open_boundary.py),
left end imposed, right end extrapolated; both ends impose a uniform horizontal flow
u = U sin(2 pi t / T) (U 0.2 m/s, T 1 s) with a still surface: the imposed net flux is zero over
each period, so the fluid count at whole periods should stay put. ``--variants``: a JSON list of
scene-constant overrides, one run each in this process (default: no shifting; delta-plus with
shift_open_end full, none). Prints one JSON line per variant: the fluid count change
at each whole period, the level change it makes (count dp^2 / length), the per-end crossing
counts, the largest fluid speed at the end, wall_s.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

os.environ.setdefault("OMP_WAIT_POLICY", "passive")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from sph_core.boundary_data import BoundarySample  # noqa: E402
from sph_core.open_ends import flume_nodes  # noqa: E402
from sph_core.scene import make_scene  # noqa: E402
from sph_core.simulation import Simulation  # noqa: E402

DEPTH, LENGTH, U, PERIOD, G = 0.3, 0.6, 0.2, 1.0, 9.81
DEFAULT_VARIANTS = [{}, {"shifting": "dplus"}, {"shifting": "dplus", "shift_open_end": "none"}]


class _Oscillating:
    """Uniform horizontal flow u = U sin(2 pi t / T) at the nodes of one end, still surface."""

    def __init__(self, nodes) -> None:
        self.n = nodes.size

    def sample(self, t: float) -> BoundarySample:
        u = U * math.sin(2.0 * math.pi * t / PERIOD)
        return BoundarySample(t, np.full(self.n, u), np.zeros(self.n), 0.0)


def _run_variant(dp: float, periods: int, constants: dict) -> dict:
    scene = make_scene({
        "dp": dp, "t_end": float(periods) * PERIOD, "still_water_level": DEPTH,
        "tank": {"x0": 0.0, "x1": LENGTH, "z0": 0.0, "z1": DEPTH + 0.12},
        "water_blocks": [{"x0": 0.0, "x1": LENGTH, "z0": 0.0, "z1": DEPTH}],
        "constants": {"c0": 10.0 * math.sqrt(G * DEPTH), **constants},
        "open_boundaries": [{"side": "left", "elevation": "imposed"},
                            {"side": "right", "elevation": "extrapolated"}]})
    sim = Simulation(scene, sources={s: _Oscillating(nd) for s, nd in flume_nodes(scene).items()},
                     window=0.02)
    tic = time.perf_counter()
    change = []
    for k in range(1, periods + 1):
        sim.advance_to(k * PERIOD)
        change.append(sim.n_fluid - sim.n_fluid0)
    st = sim.fluid_state()
    return {"constants": constants, "dp": dp, "periods": periods,
            "fluid_change_per_period": change,
            "level_change_mm": round(1e3 * change[-1] * dp * dp / scene.tank.x1, 2),
            "boundary_counts": sim.boundary_counts(),
            "max_speed": round(float(np.hypot(st["vx"], st["vz"]).max()), 4),
            "wall_s": round(time.perf_counter() - tic, 1)}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--periods", type=int, default=5)
    ap.add_argument("--dp", type=float, default=0.02)
    ap.add_argument("--variants", type=json.loads, default=DEFAULT_VARIANTS,
                    help="JSON list of scene-constant overrides")
    a = ap.parse_args(argv)
    for cst in a.variants:
        print(json.dumps(_run_variant(a.dp, a.periods, {"h_over_dp": 2.0, **cst})), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
