"""How much does the SPH flume damp a progressive wave over distance, at a given resolution?

    python bench/wave_decay.py [--H 0.04 --T 1.4 --d 0.24] [--dp 0.02 0.01 0.005] [--periods 4 (--long: 12)]
        [--settle-periods 0] [--ramp-periods 1] [--inlet-pressure hydrostatic|extrapolated]
        [--no-outlet-absorb]
        [--h-over-dp 2.0] [--alpha 0.01] [--slip no_slip|free_slip] [--c0-factor 10] [--delta 0.1]
        [--cfl 0.25] [--integrator kdk|symplectic_pc] [--nu 1e-6] [--alpha-wall 1.0]
        [--shifting none|fickian|dplus] [--shift-a 2.0]
        [--shift-fs-div 1.8] [--shift-open-end full|none] [--flume-wavelengths 1]
        [--gauge-wavelengths 0.75] [--n-gauges 12]
        [--long] [--noise] [--records DIR] [--velocity-z Z [Z ...]]
        [--scheme wcsph|riemann|isph] [--reconstruction muscl|none] [--ppe-solver bicgstab|amg]
        [--isph-density-relaxation 0.01] [--isph-wall-stop 1] [--isph-relaxation-zone 0]

--long: a flume 3 wavelengths long, 36 gauges over 2.25 wavelengths, 12 periods from the time
the outlet's reflection has come back to the inlet: resolves the decay to ~0.1 %/m (dp 0.02: fitted
2.56, separated 2.58 %/m; a fit over the default 0.75 L span moves by ~1 %/m with the outlet's
reflection pattern; docs/studies/absorption.md). 12 periods, not 4: the inlet's amplitude falls
2.5 % as the outlet's reflection returns, and until that envelope has run past the gauges the
fit at one time reads less loss (at H/dp 4: 0.3 %/m in the window's first period, 1.0 from the
fourth on, 0.92 along the wave groups; modulated_decay_per_period; docs/studies/
wave_decay_study.md, "The long flume's 4-period window read the inlet's envelope"). ~9x the
particle-steps of the default flume.

ISPH carries this wave through its open ends with relaxation zones and its wave settings,
`--scheme isph --h-over-dp 1.2 --isph-density-relaxation 0.05 --isph-wall-stop 100
--isph-relaxation-zone 0.4` (docs/physics/isph.md; the first gauge then sits at the zone's end);
with the scheme's defaults its flume breaks down at ~5 s, before the window. At H/dp 4 add
`--ramp-periods 2`: a wave started over one period breaks the inlet's face inside the window
(docs/studies/schemes.md, "The start-up ramp: ISPH's flume at H/dp 4").

A flume one wavelength long with open ends driven by second-order Stokes theory (the wave of the
coupled flume, wavesph/cases/coupled_flume.py, by default), gauges from 2h past the inlet to 3/4 of the
flume (wavesph/cases/wave_decay.py). No coupling and no wave model but the theory: the SPH wave's own
loss, the floor under any coupled flume's error at that dp. Every option left out keeps the
scene's default (sph_core.scene.Constants); c0 = c0_factor sqrt(g d) (the flume's default 10).

Prints one JSON line per dp: H, T, d, dp, H_over_dp, the options, x, amplitude_ratio (SPH /
theory, first harmonic), decay_per_m (least squares of the log), loss_per_wavelength
(1 - exp(-decay L)), amplitude_at_0_8m (that fit 0.8 m past the inlet: the coupled flume's
gauge), wall_s, particles, steps, particle_steps_per_s; then, given several dp, one line with the
convergence order of the decay between successive dp, log(decay_1/decay_2)/log(dp_1/dp_2).
modulated_decay_per_m, modulated_loss_per_wavelength, reflection_ripple, beat_modulation: the
decay fitted with the outlet's reflection ripple (period L/2) and the free second harmonic's beat
(period 2 pi / (k(2 omega) - 2k), ~3 m here; null where the gauges span less) beside it (wavesph.cases.wave_decay.modulated_decay:
the plain fit hangs on where its span cuts the beat); modulated_decay_per_period, that fit over
each period of the window in turn (a loss that changes with the run's time);
group_decay_per_period, group_decay_per_m, group_loss_per_wavelength: the same fit following each
period down the flume, each gauge x / c_g later (wavesph.cases.wave_decay.group_decays; the
periods whose last gauge the record reaches): an inlet amplitude that changes over time does
not read as decay there. The figure to quote.
--velocity-z Z...: velocity probes at every gauge's x, Z m above the floor; prints
velocity_group_decay_per_m (per Z, the horizontal velocity's first harmonic fitted along the
groups as the elevation is) and velocity_group_decay_per_period: a loss that the velocity field
shows too is the wave's own, not the gauge's (with --records, its records in
wave_decay_dp<dp>_velocity.npz: velocity_z, u, u_theory at the gauges' x and times).
--records DIR keeps the gauge records (an npz per dp) to fit again without re-running, e.g.
group_decays(**npz) with an earlier t0 (a long run's groups before the window start).
separated_decay_per_m, separated_k_over_k_theory (SPH's wavenumber: phase-speed error),
separated_reflection: an incident and a reflected wave with one decay rate and wavenumber
fitted to the complex amplitudes (wavesph.cases.wave_decay.separated_decay).
ratio_first_half / ratio_second_half: the ratio over each half of the window (a loss that
grows in time rather than along x shows here); mean_eta_error_mm: time-mean SPH minus theory
elevation per gauge; level_drift_mm: change of the flume's mean level from its fluid count.
boundary_counts: per end, fluid particles in / out and buffer particles created / removed.
second_harmonic_ratio: |2 omega amplitude| of SPH over the theory's per gauge (a free second
harmonic from the inlet beats along x). --noise (wavesph.cases.particle_noise): noise_x_m, bin centres
(0.25 m); noise_fraction, the particle-noise kinetic energy (velocity minus a local quadratic
fit) per bin over the wave's energy 0.5 rho0 g a^2 per bin, mean over the window; noise_t_s,
noise_fraction_t: the same over the gauged span at each sample (every T/5 from the start).
A run that goes unstable prints its line with state "unstable", t_stop, steps and status (the
other dp go on; exit status 1), as a marginal scheme's flume (ISPH at dp 0.01) does.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from pathlib import Path

import numpy as np

os.environ.setdefault("OMP_WAIT_POLICY", "passive")  # before numba: shared, loaded cores
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from wavesph.cases.wave_decay import amplitude_profile, convergence_record, separated_decay  # noqa: E402
from wavesph.cases.schemes import (add_constant_arguments, add_scheme_arguments,  # noqa: E402
                                   constants_from_args, scheme_from_args)
from sph_core.simulation import UnstableError  # noqa: E402
from wave_client.theories import build_theory  # noqa: E402


def _finite(v: float) -> float | None:
    """``v`` to 4 decimals, None for nan (JSON has no nan)."""
    return None if math.isnan(v) else round(v, 4)


def _along_groups(decays: np.ndarray, length: float) -> dict:
    """The fit along the wave groups: per period, their mean and its loss per wavelength."""
    mean = float(decays.mean()) if decays.size else math.nan
    return {"group_decay_per_period": [round(float(v), 4) for v in decays],
            "group_decay_per_m": _finite(mean),
            "group_loss_per_wavelength": _finite(1.0 - math.exp(-mean * length))}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--H", type=float, default=0.04, help="wave height [m]")
    ap.add_argument("--T", type=float, default=1.4, help="period [s]")
    ap.add_argument("--d", type=float, default=0.24, help="still-water depth [m]")
    ap.add_argument("--dp", type=float, nargs="+", default=[0.02], help="particle spacing(s) [m]")
    ap.add_argument("--periods", type=float, default=None,
                    help="periods analysed (default 4; --long 12: the inlet's envelope passes "
                         "the gauges over the first 4)")
    ap.add_argument("--ramp-periods", type=float, default=1.0,
                    help="the theory's start-up ramp in periods (ISPH at H/dp 4 needs 2: with 1 "
                         "its inlet's face breaks during the window; docs/studies/schemes.md)")
    ap.add_argument("--settle-periods", type=float, default=0.0,
                    help="extra periods between the front's passage and the analysed window")
    ap.add_argument("--flume-wavelengths", type=float, default=1.0,
                    help="flume length in wavelengths")
    ap.add_argument("--gauge-wavelengths", type=float, default=0.75,
                    help="gauges from 2h past the inlet to this many wavelengths")
    ap.add_argument("--long", action="store_true",
                    help="the long flume: 3 wavelengths, 36 gauges over 2.25, a window of 12 "
                         "periods after the outlet's reflection has come back to the inlet (its "
                         "pattern, period L/2, averages out of the fitted decay)")
    ap.add_argument("--noise", action="store_true",
                    help="sample the particle-noise energy along x and in time (diagnostic)")
    ap.add_argument("--n-gauges", type=int, default=12, help="number of elevation gauges")
    ap.add_argument("--records", type=Path, default=None, metavar="DIR",
                    help="keep each dp's gauge records in DIR/wave_decay_dp<dp>.npz (t, x, eta, "
                         "theory, t0, period, cg, k, k_beat: group_decays' arguments)")
    ap.add_argument("--velocity-z", type=float, nargs="+", default=[], metavar="Z",
                    help="velocity probes at every gauge's x, Z m above the floor")
    add_constant_arguments(ap, open_ends=True)
    ap.add_argument("--c0-factor", type=float, default=10.0, help="c0 = factor * sqrt(g d)")
    ap.add_argument("--no-outlet-absorb", action="store_true",
                    help="outlet without the absorption correction (diagnostic: its reflection)")
    ap.add_argument("--inlet-pressure", choices=["hydrostatic", "extrapolated"],
                    help="inlet buffer pressure (scene default if unset)")
    ap.add_argument("--device", choices=["cpu", "cuda"], default=None,
                    help="where the SPH steps run (default: the scene's, cpu)")
    add_scheme_arguments(ap)
    a = ap.parse_args(argv)
    cst = constants_from_args(a)
    scheme = scheme_from_args(a)
    if a.long:
        a.flume_wavelengths, a.gauge_wavelengths, a.n_gauges = 3.0, 2.25, 36
    if a.periods is None:
        a.periods = 12.0 if a.long else 4.0
    c0 = a.c0_factor * math.sqrt(9.81 * a.d)
    decays, failed = [], False
    for dp in a.dp:
        ramp = a.ramp_periods * a.T
        model = build_theory("stokes", height=a.H, period=a.T, depth=a.d, ramp_time=ramp, order=2)
        try:
            prof = amplitude_profile(model, ramp=ramp, height=a.H, period=a.T, depth=a.d, dp=dp,
                                     periods=a.periods, flume_wavelengths=a.flume_wavelengths,
                                     inlet_pressure=a.inlet_pressure,
                                     settle_periods=a.settle_periods,
                                     outlet_absorb=not a.no_outlet_absorb,
                                     gauge_wavelengths=a.gauge_wavelengths, n_gauges=a.n_gauges,
                                     wait_reflection=a.long, noise=a.noise,
                                     velocity_z=tuple(a.velocity_z),
                                     c0=c0, scheme=scheme, device=a.device, **cst)
        except UnstableError as exc:
            failed = True
            print(json.dumps({"H": a.H, "T": a.T, "d": a.d, "dp": dp,
                              "H_over_dp": round(a.H / dp, 3), "device": a.device or "cpu",
                              "constants": cst, "scheme": scheme, "long": a.long,
                              "state": "unstable", "t_stop": round(exc.t, 4), "steps": exc.step,
                              "status": str(exc)}), flush=True)
            continue
        length = float(model.length)
        decays.append(prof.decay_per_m)
        if a.records is not None:
            a.records.mkdir(parents=True, exist_ok=True)
            np.savez(a.records / f"wave_decay_dp{dp:g}.npz", **prof.records)
            if prof.velocity_records is not None:
                np.savez(a.records / f"wave_decay_dp{dp:g}_velocity.npz", **prof.velocity_records)
        sep_decay, sep_k, sep_kr = separated_decay(prof.x, prof.amp, prof.k)
        print(json.dumps({"H": a.H, "T": a.T, "d": a.d, "dp": dp, "H_over_dp": round(a.H / dp, 3),
                          "device": a.device or "cpu", "state": "finished",
                          "constants": cst, "scheme": scheme, "c0_factor": a.c0_factor,
                          "inlet_pressure": a.inlet_pressure, "settle_periods": a.settle_periods,
                          "ramp_periods": a.ramp_periods,
                          "outlet_absorb": not a.no_outlet_absorb,
                          "flume_wavelengths": a.flume_wavelengths,
                          "gauge_wavelengths": a.gauge_wavelengths, "long": a.long,
                          "wavelength_m": round(length, 4),
                          "x": prof.x.tolist(),
                          "amplitude_ratio": [round(float(r), 4) for r in prof.ratio],
                          "decay_per_m": round(prof.decay_per_m, 4),
                          "modulated_decay_per_m": round(prof.modulated_decay_per_m, 4),
                          "modulated_loss_per_wavelength": round(
                              1.0 - math.exp(-prof.modulated_decay_per_m * length), 4),
                          "reflection_ripple": _finite(prof.reflection_ripple),
                          "beat_modulation": _finite(prof.beat_modulation),
                          "modulated_decay_per_period": [round(float(v), 4)
                                                         for v in prof.decay_per_period],
                          **_along_groups(prof.group_decay_per_period, length),
                          **({} if prof.velocity_group_decay_per_period is None else {
                              "velocity_group_decay_per_m": {
                                  f"{z:g}": _finite(float(v.mean()) if v.size else math.nan)
                                  for z, v in prof.velocity_group_decay_per_period.items()},
                              "velocity_group_decay_per_period": {
                                  f"{z:g}": [round(float(x), 4) for x in v]
                                  for z, v in prof.velocity_group_decay_per_period.items()}}),
                          "loss_per_wavelength": round(1.0 - math.exp(-prof.decay_per_m * length), 4),
                          "separated_decay_per_m": round(sep_decay, 4),
                          "separated_k_over_k_theory": round(sep_k / prof.k, 4),
                          "separated_reflection": round(sep_kr, 4),
                          "ratio_first_half": [round(float(r), 4) for r in prof.ratio_first_half],
                          "ratio_second_half": [round(float(r), 4) for r in prof.ratio_second_half],
                          "mean_eta_error_mm": [round(1e3 * float(e), 2) for e in prof.mean_eta_error],
                          "level_drift_mm": round(1e3 * prof.level_drift_m, 2),
                          "boundary_counts": prof.counts,
                          "second_harmonic_ratio": [round(float(r), 4) for r in prof.ratio_2nd],
                          **({} if prof.noise_x is None else {
                              "noise_x_m": [round(float(v), 3) for v in prof.noise_x],
                              "noise_fraction": [float(f"{v:.4g}") for v in prof.noise_fraction],
                              "noise_t_s": [round(float(v), 3) for v in prof.noise_t],
                              "noise_fraction_t": [float(f"{v:.4g}")
                                                   for v in prof.noise_fraction_t]}),
                          "amplitude_at_0_8m": round(prof.ratio_at(0.8), 4),
                          "wall_s": round(prof.wall_s, 1), "particles": prof.particles,
                          "steps": prof.steps,
                          "particle_steps_per_s": round(prof.particles * prof.steps
                                                        / max(prof.wall_s, 1e-9))}), flush=True)
    if len(a.dp) > 1 and not failed:
        print(json.dumps(convergence_record(a.dp, decays, "decay_per_m")), flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
