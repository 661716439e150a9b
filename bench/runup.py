"""Question: how far up a 1:19.85 plane beach does a solitary wave run in SPH, against
Synolakis' (1987) run-up law R/d = 2.831 sqrt(cot beta) (H/d)^(5/4)?

    NUMBA_NUM_THREADS=1 python bench/runup.py [--h-over-d 0.05,0.3] [--dp-over-d 0.1] [--depth 0.2]
                                              [--wall-slip free_slip] [--constants JSON]
                                              [--far-field boussinesq] [--toe-over-d 2]
                                              [--bed-layout along_slope] [--device cuda]

The canonical case (Synolakis 1987, J. Fluid Mech. 185): still water d on a flat bed, then a
plane beach of slope 1/19.85 whose toe is L = arccosh(sqrt(20)) / k downstream of the inlet
(the half-width at which eta = H/20, k = sqrt(3H/(4 d^3))), the beach running on above still
water. The whole flume is SPH: an open inlet (elevation imposed, no absorption) at x = 0 driven
by wave_client's `solitary` theory, whose crest passes the inlet at its default t0 (eta there
starts at 1e-3 H). With ``--far-field boussinesq`` the far field is the Boussinesq model instead
(the model's own solitary wave, timed alike, sampled at the inlet as a coupled run's messages
are) and ``--toe-over-d`` can shorten the SPH zone to a few depths before the toe: the flat
approach costs no particles. The wedge of water over the beach is filled to the still shoreline. A
`runup` probe (near_bed 2 dp) records the shoreline; R is its highest z - still water over the
run, R0 the same before the wave's front (eta > H/100) reaches the beach's toe: what the
layout itself gives at rest. The scene's constants are the defaults (override with --constants).
The run ends 1.5 L/c after the linear shallow-water travel time to the still shoreline (by then
the run-up maximum has passed). ``--bed-layout along_slope``: the beach's dummy particles in rows
parallel to the slope (a smooth bed) instead of the tank lattice's staircase (scene ``[[beds]]``
``layout``).

The law holds for non-breaking waves (Synolakis: H/d < 0.818 (cot beta)^(-10/9), 0.030 here;
breaking on run-down from about 0.044); H/d = 0.3 breaks on run-up, where Synolakis' data
follow R/d = 1.109 (H/d)^0.582 (`R_over_d_breaking_fit`; the fit as widely quoted, not yet checked against the paper). `error` is (R - R_law) / R_law
against the non-breaking law in every case.

One JSON object per H/d: H_over_d, R_over_d, R_over_d_law, R_over_d_breaking_fit, error,
R0_over_d, stopped (null, or why the run stopped early: R is then over the records before it),
far_field, bed_layout, toe_over_d (the inlet-to-toe distance / d), R_loose_over_d (the same probe counting any particle with one fluid neighbour at any
height: what the wet-film criteria leave out), H_toe_over_H (the highest SPH elevation at the toe up to the run-up peak, over H), dp, d_over_dp, H_over_dp, particles, steps, t_end, wall_s, device.

Beside the law, the same wave on the same beach in the nonlinear shallow-water equations
(wavesph.cases.shallow_runup, seconds): R_over_d_nswe (the law's own model, so within ~2 % of
it where the law holds), excess_ratio (for each section, named by its still depth / d from the
toe "1" to the still shoreline "0": the largest volume of water shoreward of it above what lay
there at rest, SPH over the NSWE; it says where along the beach the SPH swash falls behind),
and nswe_film_at_R_over_dp (the NSWE's water depth, at its own run-up instant, where the bed
stands at the SPH's R, in dp: how thin the swash is where the SPH's stops).
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

from sph_core.boundary_data import WaveModelBoundary  # noqa: E402
from sph_core.open_ends import flume_nodes  # noqa: E402
from sph_core.scene import make_scene  # noqa: E402
from sph_core.simulation import Simulation, UnstableError  # noqa: E402
from wave_client.boussinesq import solitary_approach  # noqa: E402
from wave_client.theories import G, SolitaryWave  # noqa: E402
from wavesph.cases.shallow_runup import solitary_runup, synolakis_law  # noqa: E402

COT_BETA = 19.85
# sections of the beach named by their still depth / d: the toe (1) to the still shoreline (0)
SECTIONS = (1.0, 0.5, 0.25, 0.125, 0.0625, 0.0)


def law(h_over_d: float) -> float:
    """Synolakis (1987), non-breaking run-up R/d on this beach."""
    return synolakis_law(h_over_d, COT_BETA)


def breaking_fit(h_over_d: float) -> float:
    """Synolakis (1987): the fit to his breaking-wave run-up data on the 1:19.85 beach, R/d."""
    return 1.109 * h_over_d**0.582


def runup_scene(h_over_d: float, depth: float, dp: float, wall_slip: str = "no_slip",
                constants: dict | None = None, toe_distance: float | None = None,
                bed_layout: str = "lattice") -> tuple[dict, SolitaryWave, float]:
    """(scene dict, the inlet's theory, x of the beach's toe [m]). The toe lies ``toe_distance``
    [m] downstream of the inlet (default: Synolakis' half-width L)."""
    H = h_over_d * depth
    wave = SolitaryWave(H, depth=depth)
    half = math.acosh(math.sqrt(20.0)) / wave.k
    x_toe = dp * round((half if toe_distance is None else toe_distance) / dp)
    x_shore = x_toe + COT_BETA * depth
    # beyond the shoreline: twice the expected run-up (the law's, the breaking fit's once the
    # law overshoots it), then 10 dp
    r_max = (law(h_over_d) if h_over_d <= 0.1 else breaking_fit(h_over_d)) * depth
    x1 = dp * math.ceil((x_shore + 2.0 * r_max * COT_BETA) / dp + 10)
    # shallow-water travel to the still shoreline: x_toe / c0 + 2 cot(beta) d / sqrt(g d)
    t_arrive = wave.t0 + x_toe / math.sqrt(G * depth) + 2.0 * COT_BETA * math.sqrt(depth / G)
    t_end = t_arrive + 1.5 * half / wave.c
    z_top = depth + 2.0 * r_max + 10 * dp
    scene = {
        "name": f"solitary-runup-H{h_over_d:g}", "dp": dp, "t_end": round(t_end, 4),
        "still_water_level": depth,
        "tank": {"x0": 0.0, "x1": x1, "z0": 0.0, "z1": z_top},
        "water_blocks": [{"x0": 0.0, "x1": x_shore, "z0": 0.0, "z1": depth}],
        "beds": [{"points": [[x_toe, 0.0], [x1, (x1 - x_toe) / COT_BETA]], "layout": bed_layout}],
        "open_boundaries": [{"side": "left", "elevation": "imposed"}],
        "constants": {"wall_slip": wall_slip, **(constants or {})},
        "output": {"probe_every": 0.02},
        # "loose": any fluid particle with one neighbour, at any height (spray included)
        "probes": [{"kind": "runup", "name": "shore", "near_bed": 2 * dp},
                   {"kind": "runup", "name": "loose", "min_neighbours": 1},
                   {"kind": "elevation", "name": "toe", "x": x_toe}],
    }
    return scene, wave, x_toe


def run_case(h_over_d: float, depth: float, dp_over_d: float, wall_slip: str = "no_slip",
             constants: dict | None = None, far_field: str = "theory",
             toe_over_d: float | None = None, device: str | None = None,
             bed_layout: str = "lattice") -> dict:
    """One run-up. far_field "theory": the solitary theory drives the SPH inlet; "boussinesq":
    the Boussinesq model carries the wave to it (solitary_approach; one-way: the beach's
    reflection leaves SPH through the inlet's imposed elevation, as with the theory).
    ``device``: where the SPH steps run (None: the scene's, cpu; "cuda": an NVIDIA GPU)."""
    dp = dp_over_d * depth
    data, wave, x_toe = runup_scene(h_over_d, depth, dp, wall_slip, constants,
                                    None if toe_over_d is None else toe_over_d * depth, bed_layout)
    scene = make_scene(data)
    model = (wave if far_field == "theory" else
             solitary_approach(wave.height, depth, wave.t0, scene.t_end))
    src = WaveModelBoundary(model, flume_nodes(scene)["left"], depth, 0.0)
    # the water shoreward of each section (named by its still depth / d) above what was there
    # at rest, after every record: the SPH's side of the shallow-water comparison
    x_sec = {s: x_toe + (1.0 - s) * depth * COT_BETA for s in SECTIONS}

    def shoreward_volumes(s: Simulation) -> dict[float, float]:
        st = s.fluid_state()
        vol = st["m"] / st["rho"]
        return {k: float(vol[st["x"] > xs].sum()) for k, xs in x_sec.items()}

    tic = time.perf_counter()
    sim = Simulation(scene, sources={"left": src}, device=device)
    at_rest = shoreward_volumes(sim)
    excess = dict.fromkeys(SECTIONS, 0.0)

    def record_excess(s: Simulation) -> None:
        for k, v in shoreward_volumes(s).items():
            excess[k] = max(excess[k], v - at_rest[k])

    stopped = None
    try:
        sim.advance_to(scene.t_end, progress=record_excess)
    except UnstableError as exc:  # the records up to the stop still say how far it ran up
        stopped = str(exc)
    wall = time.perf_counter() - tic
    h = sim.history
    t = np.array([r["t"] for r in h])
    rise = np.array([np.nan if r["shore_z"] is None else r["shore_z"] - depth for r in h])
    # the front (eta > H/100) reaches the toe: (t - t0) c = x_toe - arccosh(10)/k
    t_front = wave.t0 + (x_toe - math.acosh(10.0) / wave.k) / wave.c
    r0 = float(np.nanmax(rise[t < t_front]))
    r = float(np.nanmax(rise))
    r_loose = max(v for v in (h[-1]["loose_R"], -math.inf) if v is not None)
    # the wave SPH delivers: the highest elevation at the toe before the shoreline peaks
    toe = np.array([np.nan if r_["toe_eta"] is None else r_["toe_eta"] for r_ in h])
    h_toe = float(np.nanmax(toe[t <= t[int(np.nanargmax(rise))]]))
    rl = law(h_over_d)
    nswe = solitary_runup(h_over_d * depth, depth, COT_BETA, sections=SECTIONS)
    return {"bench": "runup", "H_over_d": h_over_d, "R_over_d": round(r / depth, 4),
            "R_over_d_law": round(rl, 4), "R_over_d_breaking_fit": round(breaking_fit(h_over_d), 4),
            "error": round((r / depth - rl) / rl, 3), "R0_over_d": round(r0 / depth, 4),
            "R_loose_over_d": round(r_loose / depth, 4),
            "R_over_d_nswe": round(nswe.runup / depth, 4),
            "excess_ratio": {f"{k:g}": round(excess[k] / nswe.excess[k], 3) for k in SECTIONS},
            "nswe_film_at_R_over_dp": round(nswe.film_at(r) / dp, 3),
            "H_toe_over_H": round(h_toe / (h_over_d * depth), 3),
            "t_R": round(float(t[int(np.nanargmax(rise))]), 3),
            "depth": depth, "dp": round(dp, 6), "d_over_dp": round(depth / dp, 2),
            "H_over_dp": round(h_over_d * depth / dp, 2), "wall_slip": wall_slip,
            "far_field": far_field, "bed_layout": bed_layout, "toe_over_d": round(x_toe / depth, 3),
            **({"constants": constants} if constants else {}), "particles": sim.n_particles,
            "steps": sim.steps, "t_end": scene.t_end, "stopped": stopped, "wall_s": round(wall, 1),
            "device": device or "cpu",
            "threads": int(os.environ.get("NUMBA_NUM_THREADS", "0") or 0)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--h-over-d", default="0.05", help="comma-separated H/d values")
    ap.add_argument("--depth", type=float, default=0.2, help="still-water depth d [m]")
    ap.add_argument("--dp-over-d", type=float, default=0.1,
                    help="particle spacing / depth (0.1: d/dp 10, minutes on 2 cores)")
    ap.add_argument("--wall-slip", choices=("no_slip", "free_slip"), default="no_slip",
                    help="walls and beach (the scene default no_slip holds the film back)")
    ap.add_argument("--constants", type=json.loads, default=None,
                    help='scene constants to override, JSON, e.g. \'{"h_over_dp": 1.5}\'')
    ap.add_argument("--far-field", choices=("theory", "boussinesq"), default="theory",
                    help="what drives the SPH inlet: the solitary theory, or the Boussinesq "
                         "model carrying its own solitary wave")
    ap.add_argument("--toe-over-d", type=float, default=None,
                    help="inlet-to-toe distance / d (default Synolakis' half-width L; a short "
                         "SPH zone with --far-field boussinesq)")
    ap.add_argument("--bed-layout", choices=("lattice", "along_slope"), default="lattice",
                    help="the beach's dummy particles: the tank lattice's staircase, or rows "
                         "parallel to the slope (a smooth bed)")
    ap.add_argument("--device", choices=("cpu", "cuda"), default=None,
                    help="where the SPH steps run (default: the scene's, cpu)")
    a = ap.parse_args()
    for hd in (float(v) for v in a.h_over_d.split(",")):
        print(json.dumps(run_case(hd, a.depth, a.dp_over_d, a.wall_slip, a.constants,
                                  a.far_field, a.toe_over_d, a.device, a.bed_layout)),
              flush=True)


if __name__ == "__main__":
    main()
