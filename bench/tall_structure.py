"""Question: how close is the 3D step's force on a tall structure hit by a dam break to Yeh &
Petroff's measurement, and what does it cost on this machine?

    python bench/tall_structure.py [--dps 0.02] [--h-over-dp 1.5] [--t-end 1.5] [--wet-bed auto]

The case is seed 004's 3D validation (wavesph.cases.tall_structure: tank 1.6 x 0.61 x 0.75 m, a
0.4 x 0.61 x 0.3 m water column, a 0.12 x 0.12 m column 0.5 m past the gate), compared with the
digitised measured force F_x(t) (wavesph/cases/data/tall_structure_force.csv; Raad & Bidoae 2005
Fig. 18) on 0.05 s bin means from 0 to t_end: the peak error is (max F_sim - max F_exp) / max F_exp
(signed), the RMS error the RMS of the bin means' difference over the measured peak.

One JSON object per dp: dp, h_over_dp, particles, fluid_particles, steps, wall_s,
wall_s_per_sim_s, peak_force_error, rms_force_error, peak_force_sim, peak_force_exp, t_peak_sim,
t_peak_exp, onset_sim (first time F_x > 2 N), onset_exp, excluded, wet_bed, threads.
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
from wavesph.cases.tall_structure import (BIN, force_errors, measured_force,  # noqa: E402
                                          tall_structure_scene)

ONSET_N = 2.0   # [N] the force's arrival: first record (or bin) above this


def _onset(t: np.ndarray, f: np.ndarray) -> float | None:
    above = np.nonzero(f > ONSET_N)[0]
    return float(t[above[0]]) if above.size else None


def measure(dp: float, h_over_dp: float, t_end: float, wet_bed: bool | None) -> dict:
    import numba

    scene = tall_structure_scene(dp=dp, t_end=t_end, h_over_dp=h_over_dp, wet_bed=wet_bed)
    sim = Simulation(scene)
    t0 = time.perf_counter()
    sim.advance_to(t_end, progress=None)
    wall = time.perf_counter() - t0
    t = np.array([r["t"] for r in sim.history])
    fx = np.array([r["column_fx"] for r in sim.history])
    te, fe = measured_force()
    err = force_errors(t, fx, 0.0, t_end)
    # times of the peaks of the bin means (the digitised record is a point cloud)
    edges = np.arange(0.0, t_end + 1e-9, BIN)
    mid = 0.5 * (edges[:-1] + edges[1:])

    def peak_t(tt, ff):
        k = np.digitize(tt, edges) - 1
        means = np.array([ff[k == b].mean() if np.any(k == b) else -np.inf
                          for b in range(mid.size)])
        return float(mid[int(np.argmax(means))])

    return {"bench": "tall_structure", "dp": dp, "h_over_dp": h_over_dp,
            "particles": int(sim.n_particles), "fluid_particles": int(sim.n_fluid0),
            "steps": sim.steps, "wall_s": round(wall, 1),
            "wall_s_per_sim_s": round(wall / t_end, 1),
            "peak_force_error": round(err["peak_force_error"], 4),
            "rms_force_error": round(err["rms_force_error"], 4),
            "peak_force_sim": round(err["peak_force_sim"], 2),
            "peak_force_exp": round(err["peak_force_exp"], 2),
            "t_peak_sim": peak_t(t, fx), "t_peak_exp": peak_t(te[te <= t_end], fe[te <= t_end]),
            "onset_sim": _onset(t, fx), "onset_exp": _onset(np.sort(te), fe[np.argsort(te)]),
            "excluded": len(sim.excluded), "wet_bed": len(scene.water_blocks) > 1,
            "t_end": t_end, "threads": numba.get_num_threads()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dps", type=float, nargs="+", default=[0.02])
    ap.add_argument("--h-over-dp", type=float, default=1.5)
    ap.add_argument("--t-end", type=float, default=1.5)
    ap.add_argument("--wet-bed", choices=["auto", "on", "off"], default="auto",
                    help="the 1 cm layer downstream of the gate (auto: when dp <= 1 cm)")
    args = ap.parse_args()
    wet = {"auto": None, "on": True, "off": False}[args.wet_bed]
    for dp in args.dps:
        print(json.dumps(measure(dp, args.h_over_dp, args.t_end, wet)), flush=True)


if __name__ == "__main__":
    main()
