"""Question: does the SPH far-wall pressure of the Lobovsky et al. (2014) H = 300 mm dam break
match the experiment's mean over T = t sqrt(g/H) = 3-5 (after the first impact), sensor by sensor?
And does the surge that reaches the wall have the experiment's depth (the water-level gauges)?

    NUMBA_NUM_THREADS=2 python bench/wall_pressure_means.py [--dp 0.004] [--constants JSON]
        [--scheme JSON] [--gate-speed V]

The case is wavesph/cases/wall_impact.py (the far-wall sensors 1-4 at 3, 15, 30 and 80 mm above
the bed, a `pressure_line` on the wall face), run to T = 5.2. The experiment is one realisation of
all four sensors, tests/data/lobovsky_2014_h300_sensors.csv (2 kHz block means of the 20 kHz
record). A dry probe sample counts as 0 (``dry``: its share). The water levels at the experiment's
gauges H1-H4 (tests/data/lobovsky_2014_h300_levels.csv, two records each but H1) are read in the
SPH by the vertical-line method (``elevation`` probes), and the wall pressure at more heights
(PROFILE_Z) shows where the load stops. ``--gate-speed``: the column released
by a gate lifted at that speed [m/s] (``lobovsky_scene``'s gate) instead of all at once.

One JSON object: bench, dp, constants, per sensor s1..s4 {sph, exp (mean p / rho g H), err
(sph / exp - 1), dry}, bins (the same means per T-interval of 0.25 from 2.5, "sph/exp"),
impact_T {sph, exp} (the first T at which sensor 1 exceeds IMPACT_LEVEL rho g H), levels per
gauge H1-H4 {sph, exp (mean level / H over T = 3-5, the records' mean), err, bins (per 0.5 in T
from 2, "sph/exp")}, profile {z [m]: mean p / rho g H over T = 3-5 on the wall face}, gate_speed,
particles, steps, excluded, stopped, wall_s.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from sph_core.simulation import Simulation, UnstableError  # noqa: E402
from wave_client import G  # noqa: E402
from sph_core.scene import make_scene  # noqa: E402
from wavesph.cases.wall_impact import COLUMN_HEIGHT, SENSOR_Z, lobovsky_scene  # noqa: E402

SENSORS = REPO / "tests" / "data" / "lobovsky_2014_h300_sensors.csv"
LEVELS = REPO / "tests" / "data" / "lobovsky_2014_h300_levels.csv"
IMPACT_LEVEL = 0.05  # p / rho g H at sensor 1 that marks the surge's arrival
GAUGE_X = {"H1": 0.300, "H2": 0.865, "H3": 1.114, "H4": 1.3625}  # [m], the level gauges
PROFILE_Z = (0.05, 0.12, 0.16, 0.20, 0.30)  # [m], wall points above the sensors


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dp", type=float, default=0.004)
    ap.add_argument("--constants", type=json.loads, default={}, help="scene constants, JSON")
    ap.add_argument("--scheme", type=json.loads, default=None,
                    help='the scene\'s [scheme] table, JSON (e.g. \'{"kind": "riemann"}\')')
    ap.add_argument("--gate-speed", type=float, default=None,
                    help="release the column by lifting a gate at this speed [m/s]")
    a = ap.parse_args()
    scale = math.sqrt(COLUMN_HEIGHT / G)
    scene = lobovsky_scene(dp=a.dp, t_end=5.2 * scale, probe_every=5e-4,
                           scheme=a.scheme, gate_speed=a.gate_speed, **a.constants)
    spec = scene.model_dump()
    face = next(p for p in spec["probes"] if p["name"] == "wall")
    face["points"] += [[face["points"][0][0], z] for z in PROFILE_Z]
    spec["probes"] += [{"kind": "elevation", "name": k, "x": x} for k, x in GAUGE_X.items()]
    sim = Simulation(make_scene(spec))
    tic, stopped = time.perf_counter(), None
    try:
        sim.advance_to(scene.t_end)
    except UnstableError as exc:
        stopped = str(exc)
    wall = time.perf_counter() - tic
    t = np.array([r["t"] for r in sim.history]) / scale
    exp = np.loadtxt(SENSORS, delimiter=",", skiprows=12)
    rgh = 1000.0 * G * COLUMN_HEIGHT
    out = {"bench": "wall_pressure_means", "dp": a.dp, "constants": a.constants,
           "scheme": scene.scheme.kind, "gate_speed": a.gate_speed}
    bins = {}
    sensors = []
    m, me = (t >= 3) & (t <= 5), (exp[:, 0] >= 3) & (exp[:, 0] <= 5)   # the scored window
    for k in range(len(SENSOR_Z)):
        p = _series(sim.history, f"wall_p{k}") / rgh
        sensors.append(p)
        s, e = float(np.nan_to_num(p[m]).mean()), float(exp[me, k + 1].mean())
        out[f"s{k + 1}"] = {"sph": round(s, 3), "exp": round(e, 3), "err": round(s / e - 1, 3),
                            "dry": round(float(np.isnan(p[m]).mean()), 3)}
        bins[f"s{k + 1}"] = [f"{np.nan_to_num(p[(t >= b) & (t < b + 0.25)]).mean():.2f}/"
                             f"{exp[(exp[:, 0] >= b) & (exp[:, 0] < b + 0.25), k + 1].mean():.2f}"
                             for b in np.arange(2.5, 5.0, 0.25)]
    out["impact_T"] = {"sph": _first_above(t, np.nan_to_num(sensors[0]), IMPACT_LEVEL),
                       "exp": _first_above(exp[:, 0], exp[:, 1], IMPACT_LEVEL)}
    out["levels"] = _levels(t, sim.history)
    out["profile"] = {str(z): round(float(np.nan_to_num(_series(sim.history, f"wall_p{k}")[m]).mean()
                                          / rgh), 3)
                      for k, z in enumerate(PROFILE_Z, start=len(SENSOR_Z))}
    out.update(bins=bins, particles=sim.n_particles, steps=sim.steps, excluded=len(sim.excluded),
               stopped=stopped, wall_s=round(wall, 1))
    print(json.dumps(out), flush=True)


def _series(history: list[dict], key: str) -> np.ndarray:
    """One probe column over the run, None (dry) as NaN."""
    return np.array([np.nan if r[key] is None else r[key] for r in history], dtype=float)


def _levels(t: np.ndarray, history: list[dict]) -> dict:
    """SPH against the experiment's water levels at H1-H4, level / H: the mean over T = 3-5 and
    per 0.5 in T from 2 (a dry line reads 0)."""
    lines = [ln for ln in LEVELS.read_text().splitlines() if not ln.startswith("#")]
    names = lines[0].split(",")
    exp = np.loadtxt(lines[1:], delimiter=",")
    te = exp[:, 0]
    out = {}
    for g in GAUGE_X:
        z = np.nan_to_num(_series(history, f"{g}_z_surface")) / COLUMN_HEIGHT
        e = exp[:, [k for k, n in enumerate(names) if n.startswith(g + "_")]].mean(axis=1)
        pairs = [(float(z[(t >= lo) & (t <= lo + span)].mean()),
                  float(e[(te >= lo) & (te <= lo + span)].mean()))
                 for lo, span in [(3.0, 2.0)] + [(b, 0.5) for b in np.arange(2.0, 5.0, 0.5)]]
        (s, x), bins = pairs[0], pairs[1:]
        out[g] = {"sph": round(s, 3), "exp": round(x, 3), "err": round(s / x - 1, 3),
                  "bins": ["%.3f/%.3f" % b for b in bins]}
    return out


def _first_above(t: np.ndarray, p: np.ndarray, level: float) -> float | None:
    """The first t at which p exceeds level (None if it never does), to 3 decimals."""
    k = np.flatnonzero(p > level)
    return round(float(t[k[0]]), 3) if k.size else None


if __name__ == "__main__":
    main()
