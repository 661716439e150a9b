"""How much does the SPH flume damp a progressive wave over distance, at a given resolution?

    python bench/wave_decay.py [--H 0.04 --T 1.4 --d 0.24] [--dp 0.02] [--alpha 0.01] [--periods 4]

A flume one wavelength long with open ends driven by second-order Stokes theory (the wave of the
coupled flume, cases/coupled_flume.py, by default), gauges from 2h past the inlet to 3/4 of the
flume (cases/wave_decay.py). No coupling and no wave model but the theory: the SPH wave's own
loss, the floor under any coupled flume's error at that dp.
Prints one JSON line: H, T, d, dp, H_over_dp, alpha, x, amplitude_ratio (SPH / theory, first
harmonic), decay_per_m (least squares of the log), amplitude_at_0_8m (that fit 0.8 m past the
inlet: the coupled flume's gauge), wall_s, particles.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

os.environ.setdefault("OMP_WAIT_POLICY", "passive")  # before numba: shared, loaded cores
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from cases.wave_decay import amplitude_profile  # noqa: E402
from wave_client.theories import build_theory  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--H", type=float, default=0.04, help="wave height [m]")
    ap.add_argument("--T", type=float, default=1.4, help="period [s]")
    ap.add_argument("--d", type=float, default=0.24, help="still-water depth [m]")
    ap.add_argument("--dp", type=float, default=0.02, help="particle spacing [m]")
    ap.add_argument("--alpha", type=float, default=0.01, help="artificial viscosity coefficient")
    ap.add_argument("--periods", type=float, default=4.0, help="periods analysed")
    a = ap.parse_args(argv)
    model = build_theory("stokes", height=a.H, period=a.T, depth=a.d, ramp_time=a.T, order=2)
    prof = amplitude_profile(model, ramp=a.T, height=a.H, period=a.T, depth=a.d, dp=a.dp,
                             periods=a.periods, alpha=a.alpha)
    print(json.dumps({"H": a.H, "T": a.T, "d": a.d, "dp": a.dp, "H_over_dp": round(a.H / a.dp, 3),
                      "alpha": a.alpha, "wavelength_m": round(float(model.length), 4),
                      "x": prof.x.tolist(), "amplitude_ratio": [round(float(r), 4) for r in prof.ratio],
                      "decay_per_m": round(prof.decay_per_m, 4),
                      "amplitude_at_0_8m": round(prof.ratio_at(0.8), 4),
                      "wall_s": round(prof.wall_s, 1), "particles": prof.particles}), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
