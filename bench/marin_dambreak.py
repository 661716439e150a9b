"""Question: how close is the 3D step to the MARIN dam break with a box (Kleefsman et al. 2005,
SPHERIC test 2): water heights in the tank and pressures on the box, and at what cost?

    python bench/marin_dambreak.py [--dps 0.04] [--t-end 2.0] [--h-over-dp 1.5]

The case is wavesph.cases.marin_dambreak (tank 3.22 x 1 x 1 m, a 1.228 x 1 x 0.55 m water column,
a 0.161 x 0.403 x 0.161 m box), compared at the simulation's records (every 0.01 s) with the
measured record (wavesph/cases/data/marin_dambreak.csv, its header has the source): H2 (x 0.992,
between the gate and the box), H4 (x 2.638, in the reservoir), P1 and P3 on the box's face
(z 0.021, 0.101 m). Errors are RMS differences over 0..t_end, also divided by each measured
range; arrival times are when H2 first exceeds 2 cm and P1 first exceeds 1 kPa.

One JSON object per dp: dp, h_over_dp, particles, steps, wall_s, wall_s_per_sim_s, H2_rms,
H2_rms_rel, H4_rms, H4_rms_rel, P1_rms, P1_rms_rel, P3_rms, P3_rms_rel, P1_peak_sim, P1_peak_exp,
H2_arrival_sim, H2_arrival_exp, P1_arrival_sim, P1_arrival_exp, excluded, threads.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

os.environ.setdefault("OMP_WAIT_POLICY", "passive")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from sph_core.simulation import Simulation  # noqa: E402
from wavesph.cases.marin_dambreak import marin_errors, marin_scene, measured  # noqa: E402


def _first(t: np.ndarray, v: np.ndarray, level: float) -> float | None:
    k = np.nonzero(v > level)[0]
    return float(t[k[0]]) if k.size else None


def measure_marin(dp: float, t_end: float, h_over_dp: float) -> dict:
    import numba

    sim = Simulation(marin_scene(dp=dp, t_end=t_end, h_over_dp=h_over_dp))
    t0 = time.perf_counter()
    sim.advance_to(t_end, progress=None)
    wall = time.perf_counter() - t0
    h = sim.history
    t = np.array([r["t"] for r in h])
    h2 = np.array([r["H2_z_surface"] or 0.0 for r in h])
    p1 = np.array([r["box_p0"] or 0.0 for r in h])
    m = measured()
    sel = m["t"] <= t_end
    err = marin_errors(h)
    return {"bench": "marin_dambreak", "dp": dp, "h_over_dp": h_over_dp,
            "particles": int(sim.n_particles), "steps": sim.steps, "wall_s": round(wall, 1),
            "wall_s_per_sim_s": round(wall / t_end, 1),
            **{k: round(v, 4) for k, v in err.items()},
            "P1_peak_sim": round(float(p1.max()), 1), "P1_peak_exp": round(float(m["P1"][sel].max()), 1),
            "H2_arrival_sim": _first(t, h2, 0.02), "H2_arrival_exp": _first(m["t"], m["H2"], 0.02),
            "P1_arrival_sim": _first(t, p1, 1000.0), "P1_arrival_exp": _first(m["t"], m["P1"], 1000.0),
            "excluded": len(sim.excluded), "t_end": t_end, "threads": numba.get_num_threads()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dps", type=float, nargs="+", default=[0.04])
    ap.add_argument("--t-end", type=float, default=2.0)
    ap.add_argument("--h-over-dp", type=float, default=1.5)
    args = ap.parse_args()
    for dp in args.dps:
        print(json.dumps(measure_marin(dp, args.t_end, args.h_over_dp)), flush=True)


if __name__ == "__main__":
    main()
