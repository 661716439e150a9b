"""Question: how much water does an irregular sea carry over a smooth 1:2 seawall in SPH, against
the EurOtop (2018) mean-value formula for that structure?

    NUMBA_NUM_THREADS=2 python bench/overtopping.py [--waves 500] [--hs-over-dp 4] [--rc-over-hs 1.33]
                                                    [--seed 1] [--out DIR] [--constants JSON]

The case is wavesph/cases/seawall.py (examples/scenes/seawall_overtopping.toml at Hs/dp 4): still
water d = 0.3 m, an open inlet at x = 0 driven by wave_client's `irregular` theory (JONSWAP,
gamma 3.3, Hm0 0.075 m, Tp 1.4 s: wave steepness s_m-1,0 = 0.030; 1,600 components so the record
does not repeat within the run) with the inlet's active absorption on, one peak wavelength of
flat floor, a smooth impermeable 1:2 slope up to a crest at Rc above still water (default
0.1 m, Rc/Hm0 1.33), a crest 0.10 m wide and a pit that keeps the overtopped water. An
`overtopping` probe at the crest's landward edge counts the volume that crosses it; q_mean is its
mean from t_skip (5 Tp: the ramp and the first run-up) to the end. The sea is the inlet's own: the source is sampled at each coupling window exactly as
a coupled wave model's messages are (sph_core.boundary_data.WaveModelBoundary), so this is the
coupled run without the socket.

EurOtop (2018) eq. 5.10 / 5.11, smooth slope, mean value approach, all influence factors 1
(wavesph.eurotop.smooth_slope_overtopping, its docstring has the formulas).

Hm0 and T_m-1,0 are the incident sea's at the toe, taken here from the source's discretised
spectrum (the sea the inlet makes; the SPH flume's loss on the way to the toe, about 3 % per
wavelength at Hs/dp 4, is not corrected). The formula's stated scatter: the coefficients' standard
deviations (0.003 and 0.20 on eq. 5.10; 0.0135 and 0.15 on eq. 5.11) give q_eurotop_lo and
q_eurotop_hi, the mean value with each coefficient one standard deviation towards less and more
water (q_eurotop_hi is EurOtop's design value).

One JSON object: bench, waves (the record's zero-down-crossing count at the toe gauge),
q_mean [m^2/s per metre], q_eurotop, q_eurotop_lo, q_eurotop_hi, ratio (q_mean / q_eurotop),
Hm0_toe (measured at the toe gauge: incident and reflected), Hm0, Tm_10, Rc, xi, regime (which
equation governs), dp, Hs_over_dp, particles, excluded (excluded_seaward: of them, seaward of
the crest; excluded_seaward_m2: their water, m^3 per metre), steps, t_end, t_reached, stopped (null, or why the run stopped early: the figures are
then over the records before it), wall_s, run_dir (the run's records, for `wavesph analyse`).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

os.environ.setdefault("OMP_WAIT_POLICY", "passive")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from sph_core.boundary_data import WaveModelBoundary  # noqa: E402
from sph_core.open_ends import flume_nodes  # noqa: E402
from sph_core.scene import make_scene  # noqa: E402
from sph_core.simulation import Simulation, UnstableError  # noqa: E402
from wavesph.analysis import mean_overtopping, wave_statistics  # noqa: E402
from wavesph.cases.seawall import (HS, N_COMPONENTS, RC_OVER_HS, SEAWALL_DEPTH,  # noqa: E402
                                   TAN_ALPHA, TP, sea, seawall_scene, spectral_hm0_tm10)
from wavesph.eurotop import smooth_slope_overtopping  # noqa: E402


def overtopping_run(waves: int, hs_over_dp: float, rc_over_hs: float, seed: int, out: Path,
                    constants: dict | None = None) -> dict:
    dp = HS / hs_over_dp
    rc = rc_over_hs * HS
    waves_in = sea(seed)
    hm0, tm10 = spectral_hm0_tm10(waves_in)
    # waves counted after t_skip at the toe (zero down-crossings): their mean period there was
    # 1.30 s, T_m-1,0 (1.27 s) rather than the Tp / 1.28 of a JONSWAP's T_z (the 558 s record
    # sized by that held 430 waves, not 500)
    t_skip = 5.0 * TP
    t_end = t_skip + waves * tm10 * 1.05
    if t_end > waves_in.repeat_period:
        raise SystemExit(f"the record repeats after {waves_in.repeat_period:.0f} s < t_end {t_end:.0f} s")
    raw = seawall_scene(dp, rc, t_end)
    raw["constants"].update(constants or {})
    scene = make_scene(raw)
    x_crest = next(p.x for p in scene.probes if p.name == "crest")
    src = WaveModelBoundary(waves_in, flume_nodes(scene)["left"], SEAWALL_DEPTH, 0.0)
    tic = time.perf_counter()
    # spare: the pit fills with up to ~0.4 m^3/m of inflow on top of the flume's ~0.8
    sim = Simulation(scene, run_dir=out, spare=1.0, sources={"left": src})
    last = [tic]

    def progress(s: Simulation) -> None:
        now = time.perf_counter()
        if now - last[0] > 60.0:
            last[0] = now
            print(f"# t {s.t:.1f} / {t_end:.0f} s, {s.n_particles} particles, "
                  f"{now - tic:.0f} s", file=sys.stderr, flush=True)

    stopped = None
    try:
        sim.advance_to(scene.t_end, progress=progress)
    except UnstableError as exc:   # the records up to the stop still give a mean q
        stopped = str(exc)
    wall = time.perf_counter() - tic
    # the pit behind the crest is a sink; an exclusion seaward of the crest is the flume's
    seaward = sum(1 for ex in sim.excluded if ex["x"] < x_crest)
    h = sim.history
    t = np.array([r["t"] for r in h])
    vol = np.array([r["crest_volume"] for r in h], dtype=float)
    eta = np.array([np.nan if r["toe_eta"] is None else r["toe_eta"] for r in h], dtype=float)
    q_mean = mean_overtopping(t, vol, t_skip)
    stats = wave_statistics(t, np.nan_to_num(eta), t_skip)   # toe_eta: above still water
    e = smooth_slope_overtopping(hm0, tm10, rc, TAN_ALPHA)
    q_e, q_lo, q_hi, xi, regime = e.q, e.q_lo, e.q_hi, e.xi, e.regime
    return {"bench": "overtopping", "waves": stats.n_waves, "q_mean": float(f"{q_mean:.4g}"),
            "q_eurotop": float(f"{q_e:.4g}"), "q_eurotop_lo": float(f"{q_lo:.4g}"),
            "q_eurotop_hi": float(f"{q_hi:.4g}"), "ratio": round(q_mean / q_e, 3),
            "Hm0_toe": round(stats.Hm0, 4), "Hm0": round(hm0, 4), "Tm_10": round(tm10, 3),
            "Tp": TP, "Rc": round(rc, 4), "Rc_over_Hm0": round(rc / hm0, 3),
            "xi": round(xi, 3), "regime": regime, "depth": SEAWALL_DEPTH, "tan_alpha": TAN_ALPHA,
            "dp": round(dp, 6), "Hs_over_dp": hs_over_dp, "seed": seed, "components": N_COMPONENTS,
            "dry_toe_samples": int(np.sum(~np.isfinite(eta))), "particles": sim.n_particles,
            "excluded": len(sim.excluded),
            # their water [m^3/m], against the overtopped volume q_mean (t_end - t_skip)
            "excluded_seaward": seaward, "excluded_seaward_m2": round(dp * dp * seaward, 5),
            "steps": sim.steps, "t_end": scene.t_end, "t_reached": round(sim.t, 2),
            "stopped": stopped, "constants": constants or {},
            "wall_s": round(wall, 1), "run_dir": str(out),
            "threads": int(os.environ.get("NUMBA_NUM_THREADS", "0") or 0)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--waves", type=int, default=500, help="waves in the record after the start")
    ap.add_argument("--hs-over-dp", type=float, default=4.0, help="Hm0 / particle spacing")
    ap.add_argument("--rc-over-hs", type=float, default=RC_OVER_HS, help="crest freeboard Rc / Hm0")
    ap.add_argument("--seed", type=int, default=1, help="the sea's random phases (1: the example's)")
    ap.add_argument("--out", type=Path, default=None, help="run directory (default: a temp dir)")
    ap.add_argument("--constants", type=json.loads, default={},
                    help="scene constants over the case's, JSON (e.g. '{\"exclude_limit\": 0.2}')")
    a = ap.parse_args()
    out = a.out or Path(tempfile.mkdtemp(prefix="wavesph-overtopping-"))
    print(json.dumps(overtopping_run(a.waves, a.hs_over_dp, a.rc_over_hs, a.seed, out,
                                                a.constants)), flush=True)


if __name__ == "__main__":
    main()
