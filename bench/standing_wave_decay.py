"""Where does the SPH wave's energy go? A standing wave in a closed tank, no open boundaries.

    python bench/standing_wave_decay.py [--dp 0.02 0.01] [--h-over-dp 2] [--alpha 0.01]
        [--alpha-wall 1] [--slip no_slip|free_slip] [--delta 0.1] [--c0-factor 10] [--periods 6]
        [--cfl 0.25] [--nu 1e-6] [--shifting none|fickian|dplus]
        [--shift-a 2] [--shift-fs-div 1.8]
        [--scheme wcsph|riemann|isph] [--reconstruction muscl|none]

The first sloshing mode of a tank half a wavelength long, the wave of bench/wave_decay.py
(wavesph.cases.standing_wave). Its amplitude decay rate in time over the group velocity is the decay
over distance a progressive wave would have from the same losses: comparable with
bench/wave_decay.py's decay_per_m, without inlet, outlet or gauge.
Prints one JSON line per dp: omega_error, beta_per_s, equiv_decay_per_m,
equiv_loss_per_wavelength, beta_gauge_per_s, gauge_over_velocity_amplitude (the gauge's bias),
ke_noise_over_ke0 (kinetic energy outside the first three modes over the initial, mean over the
second half, and max), local_noise_over_ke0 (wavesph.cases.particle_noise: velocity minus a local
quadratic fit, the measure bench/wave_decay.py --noise uses along the open flume; KE_0 is the
standing wave's energy, rho0 g a^2 / 4 per metre), particles, steps, wall_s (jitted loop),
particle_steps_per_s; then, given several dp, the convergence order of equiv_decay_per_m.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

os.environ.setdefault("OMP_WAIT_POLICY", "passive")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from wavesph.cases.standing_wave import standing_wave_decay  # noqa: E402
from wavesph.cases.schemes import (add_constant_arguments, add_scheme_arguments,  # noqa: E402
                                   constants_from_args, scheme_from_args)
from wavesph.cases.wave_decay import convergence_record  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--dp", type=float, nargs="+", default=[0.02])
    ap.add_argument("--d", type=float, default=0.24, help="still-water depth [m]")
    ap.add_argument("--length", type=float, default=1.0, help="tank length = half wavelength [m]")
    ap.add_argument("--a", type=float, default=0.02, help="standing-wave amplitude [m]")
    ap.add_argument("--periods", type=float, default=6.0)
    ap.add_argument("--c0-factor", type=float, default=10.0, help="c0 = factor * sqrt(g d)")
    add_constant_arguments(ap)
    add_scheme_arguments(ap)
    a = ap.parse_args(argv)
    cst = constants_from_args(a)
    scheme = scheme_from_args(a)
    decays = []
    for dp in a.dp:
        r = standing_wave_decay(dp=dp, depth=a.d, length=a.length, amplitude=a.a,
                                periods=a.periods, c0_factor=a.c0_factor, scheme=scheme,
                                **cst)
        decays.append(r.equiv_decay_per_m)
        print(json.dumps({
            "dp": dp, "a_over_dp": round(a.a / dp, 3), "constants": cst, "scheme": scheme, "c0_factor": a.c0_factor,
            "omega_error": round(r.omega_error, 5), "beta_per_s": round(r.beta_per_s, 5),
            "equiv_decay_per_m": round(r.equiv_decay_per_m, 4),
            "equiv_loss_per_wavelength": round(r.loss_per_wavelength(2.0 * a.length), 4),
            "beta_gauge_per_s": round(r.beta_gauge_per_s, 5),
            "gauge_over_velocity_amplitude": round(r.gauge_over_velocity, 4),
            "ke_noise_over_ke0_mean_2nd_half": round(r.noise_ke_fraction, 5),
            "ke_noise_over_ke0_max": round(r.noise_ke_fraction_max, 5),
            "local_noise_over_ke0_mean_2nd_half": round(r.local_noise_fraction, 6),
            "particles": r.particles, "steps": r.steps, "wall_s": round(r.wall_s, 1),
            "particle_steps_per_s": round(r.particles * r.steps / max(r.wall_s, 1e-9))}),
            flush=True)
    if len(a.dp) > 1:
        print(json.dumps(convergence_record(a.dp, decays, "equiv_decay_per_m")), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
