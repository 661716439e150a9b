"""How much does the SPH flume damp a progressive wave over distance, at a given resolution?

    python bench/wave_decay.py [--H 0.04 --T 1.4 --d 0.24] [--dp 0.02] [--alpha 0.01] [--periods 4]

A flume one wavelength long with open ends driven by second-order Stokes theory (the wave of
the coupled flume, server/coupled_flume.py, by default): elevation gauges from 2h past the inlet
to 3/4 of the flume. For each gauge the first-harmonic amplitude of SPH over the first-harmonic
amplitude of the theory, over ``--periods`` periods once the ramped wave has passed the last
gauge. No coupling and no wave model but the theory: this is the SPH wave's own loss, the floor
under any coupled flume's error at that dp. decay_per_m: slope of log(amplitude ratio) over x
(least squares; the outlet's small reflection makes the profile ripple about it).
Prints one JSON line: H, T, d, dp, H_over_dp, alpha, x, amplitude_ratio, decay_per_m,
amplitude_at_0_8m, wall_s, particles.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from pathlib import Path

os.environ.setdefault("OMP_WAIT_POLICY", "passive")  # before numba: shared, loaded cores
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

from sph_core.scene import ElevationProbe  # noqa: E402
from sph_core.wave_analysis import harmonic_amplitude  # noqa: E402
from sph_core.wave_flume import run_wave_flume, wave_flume_scene  # noqa: E402
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
    ramp = a.T
    model = build_theory("stokes", height=a.H, period=a.T, depth=a.d, ramp_time=ramp, order=2)
    length = float(model.length)
    k = 2.0 * math.pi / length
    kd = k * a.d
    c_g = 0.5 * (length / a.T) * (1.0 + 2.0 * kd / math.sinh(2.0 * kd))
    xs = np.round(np.linspace(2.0 * math.sqrt(2.0) * a.dp, 0.75 * length, 12), 4)
    t0 = ramp + xs[-1] / c_g + a.T  # the ramped front and one period past the last gauge
    scene = wave_flume_scene(depth=a.d, wavelength=length, height=a.H, dp=a.dp,
                             t_end=t0 + a.periods * a.T, length=length, absorb=(True, True),
                             right_elevation="extrapolated", probe_every=a.T / 40,
                             name="wave_decay", alpha=a.alpha)
    probes = [ElevationProbe(kind="elevation", name=f"g{i}", x=float(x)) for i, x in enumerate(xs)]
    scene = scene.model_copy(update={"probes": probes})
    res = run_wave_flume(scene, model, window=a.T / 50)
    sel = np.nonzero(res.t >= t0 - 1e-9)[0]
    sel = sel[: int(round(a.periods * a.T / (res.t[1] - res.t[0])))]
    omega = 2.0 * math.pi / a.T
    ratio = np.array([abs(harmonic_amplitude(res.t[sel], res.eta[p.name][sel], omega))
                      / abs(harmonic_amplitude(res.t[sel], res.theory[p.name][sel], omega))
                      for p in probes])
    slope, icpt = np.polyfit(xs, np.log(ratio), 1)
    print(json.dumps({"H": a.H, "T": a.T, "d": a.d, "dp": a.dp, "H_over_dp": round(a.H / a.dp, 3),
                      "alpha": a.alpha, "wavelength_m": round(length, 4), "x": xs.tolist(),
                      "amplitude_ratio": [round(float(r), 4) for r in ratio],
                      "decay_per_m": round(float(-slope), 4),
                      "amplitude_at_0_8m": round(float(math.exp(icpt + 0.8 * slope)), 4),
                      "wall_s": round(res.wall_s, 1), "particles": res.particles}), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
