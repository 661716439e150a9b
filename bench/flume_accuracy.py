"""How close does the open-boundary SPH flume come to wave theory, and at what cost?

    python bench/flume_accuracy.py --case III [--dp 0.01] [--periods 5] [--no-absorb]
    python bench/flume_accuracy.py --theory stokes --H 0.08 --T 2.0 --d 1.0 --dp 0.01
    python bench/flume_accuracy.py --theory stream_function --H 0.02 --d 0.2 --dp 0.005 \
        --kd 1.2 2.0 --h-over-dp 2 --alpha-wall 0   # one line each

Runs one case of the seed 002 validation table (tests/data/wave_cases_seed002.csv, cases I-VI)
or any regular wave through a flume one wavelength long (standing wave: half a wavelength, faces
at the nodes of eta) with open ends driven by the theory (the table's names and orders:
wavesph/cases/seed002_waves.py; the standing wave is second order). Prints one JSON line:
case, theory, order (of a stokes or standing wave; --order overrides the table's), H, T, d, dp,
H_over_dp, periods, rmse_over_H (mid-flume gauge vs theory over the
periods after the ramp), reflection (first harmonic, least squares over nine gauges within L/4
of mid-flume with a fitted spatial decay of both waves: the coarse flume damps its waves, and a
fit without decay reads that as reflection), reflection_3g (the plain fit over mid-flume and L/8
either side), reflection_steady (with --steady: nine gauges, decay, over the periods after the
outlet's start-up emission has passed them; the standard window above holds it at large kd),
reflection_harmonics (Mansard & Funke per harmonic, first and bound second, nine
gauges with decay), none for the standing wave; kd; wall_s, particles, steps, particle_steps_per_s,
boundary counts, the mean water level at mid-flume (mean_level_m), the change of the flume's
water volume per length since the start (level_drift_m), the gauges' mean level over the
last period (level_last_period_m) and the fastest fluid particle near each face and mid-flume
(speed_max_m_s: an end many times faster than mid-flume is disordered).

One run is one realisation: the step is deterministic, but a flume whose open end blows up
near the surface (case III at H/dp 6) scores 2.7-8.6 % RMSE/H from round-off-sized
differences (docs/studies/absorption.md, "Case III at H/dp 6"). An end's IN - OUT boundary
count is its net inflow in particles, to compare with the wave's mass transport g H^2 / (8 c).
"""

from __future__ import annotations

import argparse
import json
import math
import sys

from wavesph.cases.seed002_waves import case_theory, read_cases
from wavesph.cases.wave_flume import flume_case
from wave_client.theories import wavenumber


def run_flume_case(theory: str, height: float, period: float, depth: float, dp: float, periods: float,
                   ramp_periods: float = 1.0, absorb: bool = True, case: str | None = None,
                   steady: bool = False, device: str | None = None, order: int | None = None,
                   **constants) -> dict:
    ramp = ramp_periods * period
    model = case_theory(theory, height=height, period=period, depth=depth, ramp_time=ramp,
                        **({} if order is None else {"order": order}))
    if theory == "irregular":  # flume length and gauges from the peak wave
        wavelength = 2 * math.pi / float(wavenumber(2 * math.pi / period, depth))
    else:
        wavelength = float(model.length)
    out = flume_case(model, height=height, period=period, depth=depth, wavelength=wavelength,
                     dp=dp, periods=periods, ramp=ramp, standing=theory == "standing",
                     absorb=(absorb, absorb), regular=theory != "irregular",
                     name=f"flume_{case or theory}", steady=steady, device=device, **constants)
    return {"case": case, "theory": theory, "order": getattr(model, "order", None),
            "device": device or "cpu", **constants, **out}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--case", choices=["I", "II", "III", "IV", "V", "VI"])
    ap.add_argument("--theory", help="regular wave instead of a case: linear, stokes2..5, "
                                     "stream_function, standing")
    ap.add_argument("--H", type=float)
    ap.add_argument("--T", type=float)
    ap.add_argument("--d", type=float)
    ap.add_argument("--kd", type=float, nargs="+", help="instead of --T: the period of linear "
                    "waves of this kd in depth --d (several: one run and line each)")
    ap.add_argument("--dp", type=float, help="particle spacing [m] (default: H/10)")
    ap.add_argument("--periods", type=float, default=5.0, help="periods measured after the ramp")
    ap.add_argument("--ramp-periods", type=float, default=1.0)
    ap.add_argument("--no-absorb", action="store_true", help="switch the seed 002 correction off")
    ap.add_argument("--steady", action="store_true",
                    help="also run until the outlet's start-up emission has passed the gauges "
                         "and print reflection_steady over --periods periods after it")
    ap.add_argument("--h-over-dp", type=float, help="smoothing length / dp (default: the scene's)")
    ap.add_argument("--alpha-wall", type=float, help="wall viscosity factor (scene default)")
    ap.add_argument("--order", type=int, help="the theory's order instead of the table's "
                                               "(stokes 2-5, standing 1-2)")
    ap.add_argument("--device", choices=["cpu", "cuda"], default=None,
                    help="where the SPH steps run (default: the scene's, cpu)")
    a = ap.parse_args(argv)
    constants = {k: v for k, v in (("h_over_dp", a.h_over_dp), ("alpha_wall_factor", a.alpha_wall))
                 if v is not None}
    if a.case:
        row = read_cases()[a.case]
        theory = row["theory"]
        height, depth = float(row["H"]), float(row["d"])
        periods_s = [float(row["T"])]
    elif a.theory and a.H and a.d and (a.T or a.kd):
        theory, height, depth = a.theory, a.H, a.d
        periods_s = [a.T] if a.T else [2 * math.pi / math.sqrt(9.81 * kd / a.d * math.tanh(kd))
                                       for kd in a.kd]
    else:
        ap.error("give --case, or --theory with --H --d and --T or --kd")
    dp = a.dp if a.dp else height / 10.0
    for period in periods_s:
        out = run_flume_case(theory, height, period, depth, dp, a.periods, a.ramp_periods,
                             not a.no_absorb, a.case, a.steady, device=a.device, order=a.order,
                             **constants)
        print(json.dumps(out), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
