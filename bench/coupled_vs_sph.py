"""Is the coupled Boussinesq-SPH flume as accurate as, and 10x cheaper than, SPH alone?

    python bench/coupled_vs_sph.py [--dp 0.01] [--wavelengths 12] [--sph-only-seconds 3]
                                   [--modes two_way,absorption_only] [--out DIR]   (~30 min)
                                   [--scheme isph --isph-... (wavesph.cases.schemes)]
    python bench/coupled_vs_sph.py --end outlet --x-flat 2.4 --wavelengths 2 --dp 0.02 \
        --no-sph-only [--scheme isph ...]              (the zone open at both ends, ~1 min)

The flume of wavesph/cases/coupled_flume.py: regular waves (H = 0.04 m, T = 1.4 s, d = 0.24 m) from a
Boussinesq source --wavelengths wavelengths (12: 23.6 m) up-flume of an SPH zone (open inlet,
1.2 m flat bed, 1:10 beach). Runs, at one particle spacing dp:
  reference        Boussinesq alone over the whole flume (beach to depth d/3, then a sponge)
  coupled          the SPH zone driven by `wavesph couple --model boussinesq` over WebSocket,
                   two-way (the model's boundary lets SPH's reflection out) and absorption-only
                   (`[coupling] two_way = false`, `--absorb`: the client absorbs it). The SPH
                   zone starts at rest at FlumeCase.t_sph_start, two periods before the first
                   long wave could reach it; the Boussinesq model runs alone until then.
  sph_only         SPH over the whole length from t = 0, inlet at the source driven by Stokes-2
                   theory (server standalone run). A full run at dp = 0.01 takes hours on 2 cores,
                   so by default only the first --sph-only-seconds are run and the wall time is
                   extrapolated linearly in simulated time (build excluded from the scaling);
                   `extrapolated` says so, and its rmse_over_H is then null (the wave has not
                   reached the gauge). --sph-only-seconds 0 runs it to the end.
rmse_over_H: elevation at the flat-bed gauge inside the SPH zone (0.8 m past the inlet) against
the reference, over t >= compare_from (ramp + front travel + 1 period) to t_end (4 periods).
What bounds it (measured at dp 0.01, 5.08 % absorption-only): the beach. SPH's breaking beach
reflects 7.6 %, as Battjes' 0.1 xi^2 for this slope, the reference's 0.6 % (`beach_reflection`),
and that reflection builds up across the scored window (the error's non-periodic half); the
incident wave is the reference's within 0.2 % and 0.02 rad. Smaller parts: the mean level the
closed beach holds after the ramped front, the Boussinesq model's own bound second harmonic
(3.6 mm against Stokes' 3.1 mm here); docs/studies/absorption.md, "The coupled flume's window".
--scheme and its options set both SPH scenes' [scheme] (each line carries it): ISPH does not
run this flume, its 1:10 beach loses still water within seconds (docs/studies/schemes.md,
"The coupled flume's beach under ISPH"); the line then says state "unstable".
--end outlet: the SPH zone is --x-flat of flat bed ending in an open outlet that the model feeds
too (absorption-only, the client absorbing at both ends; FlumeCase.end), against the model alone
over the same flat flume: the coupling and the zone's own travel without a beach, for any scheme
(ISPH with its wave options: --h-over-dp 1.2 --isph-density-relaxation 0.05 --isph-wall-stop 100
--isph-relaxation-zone 0.4). The reflection split then reads the outlet's: outlet_reflection
and outlet_reflection_reference (flat and mid gauges). ISPH's relaxation zones pull towards the
model's wave at each x inside them, which the client sends (protocol 1.2 ZONE_NODES; the line's
zone_targets "local"); --face-zone-targets sends the faces only (zone_targets "face": the zones
pull towards the face's profile).
Speed figures want a quiet machine and OpenMP's default (active) wait policy: on a shared,
loaded machine set OMP_WAIT_POLICY=passive, which costs the small SPH zone ~27 % of its
throughput (its parallel regions are short; a sleeping worker takes ~0.1 ms to wake).
Beside rmse_over_H, each coupled run prints the first harmonic split at the flat and toe gauges
(flat and mid with --end outlet, its keys named outlet_ as above):
beach_reflection (SPH), beach_reflection_reference, battjes_reflection (0.1 xi^2),
incident_ratio and incident_phase_rad (SPH's incident wave against the reference's) and
rmse_over_H_incident: rmse_over_H with each record's reflected first harmonic taken out (a
stationary fit: a reflection still building up over the window comes out only in part).
Prints one JSON object per line: one per run, then the summary with `speedup` = SPH-only wall
time / coupled wall time (two-way if it finished, else absorption-only) and, when the SPH-only
run went to the end, rmse_over_H_coupled_vs_sph_only: each coupled run against it at the flat
gauge (a reference whose beach is the SPH zone's; `--wavelengths 2 --sph-only-seconds 0` makes
it affordable: 291 + 621 s at dp 0.01 on 2 cores; SPH's own 2-wavelength travel
then dominates, 10.9 % against the Boussinesq reference).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from wave_client import G  # noqa: E402
from wave_client.theories.linear import wavenumber  # noqa: E402
from wavesph.analysis import (reflected_wave, rmse_over_height,  # noqa: E402
                              separate_harmonics)
from wavesph.cases.coupled_flume import (FlumeCase, correlation, reference_run,  # noqa: E402
                                         rmse_over_h, run_coupled, run_sph_only)
from wavesph.cases.schemes import add_scheme_arguments, scheme_from_args  # noqa: E402


def _accuracy(c: FlumeCase, res: dict, gauge: str = "flat") -> dict:
    if "t" not in res or res["state"] != "finished":
        return {"rmse_over_H": None, "correlation": None}
    t, eta = res["t"], res["eta"][gauge]
    refs = reference_run(c, t)          # every SPH-zone gauge: one Boussinesq run
    ref = refs[gauge]
    rmse = rmse_over_h(t, eta, ref, c)
    if rmse is None:
        return {"rmse_over_H": None, "correlation": None}
    sel = t >= c.compare_from - 1e-9
    # the mean level against the reference's and the wave's size (std ratio) over the same span
    out = {"rmse_over_H": round(rmse, 4),
           "correlation": round(correlation(t, eta, ref, c.compare_from), 4),
           "mean_level_m": round(float(np.mean(eta[sel]) - np.mean(ref[sel])), 5),
           "amplitude_ratio": round(float(np.std(eta[sel]) / np.std(ref[sel])), 4)}
    return {**out, **_far_end_reflection(c, t[sel], {n: e[sel] for n, e in res["eta"].items()},
                                         {n: r[sel] for n, r in refs.items()})}


def _far_end_reflection(c: FlumeCase, t: np.ndarray, eta: dict, ref: dict) -> dict:
    """The first harmonic split into the incident wave and the far end's reflection (the
    beach's, or the outlet's) at two gauges 0.4 m apart on the flat bed (c.reflection_pair),
    for SPH and the reference: the compared gauge stands in their partial standing wave, so an
    end that reflects more moves its phase and size though the incident wave is the same.
    ``battjes_reflection`` (beach): Battjes (1974) 0.1 xi^2 for the 1:10 slope (xi = tan beta /
    sqrt(H / L0)). ``rmse_over_H_incident``: rmse_over_H with each record's reflected first
    harmonic at the flat gauge taken out, i.e. what the coupling delivers (the incident wave,
    and any reflection the inlet failed to absorb, which comes back as incident) without the
    far end's own reflection, which the reference's does not make."""
    a, b = c.reflection_pair
    xs = np.array([c.gauges[a], c.gauges[b]])
    k = float(wavenumber(c.omega, c.depth))   # Airy: the SPH wave's
    s, s_ref = (separate_harmonics(t, np.array([e[a], e[b]]), xs, c.period, [k])[0]
                for e in (eta, ref))
    incident, incident_ref = (e[a] - reflected_wave(sep, t, c.period, k, xs[0])
                              for e, sep in ((eta, s), (ref, s_ref)))
    end = {"reflection": round(s.kr, 4), "reflection_reference": round(s_ref.kr, 4)}
    if c.end == "beach":
        xi = c.slope / math.sqrt(c.height / (G * c.period ** 2 / (2.0 * math.pi)))
        end["battjes_reflection"] = round(0.1 * xi * xi, 4)
    return {**{(f"{c.end}_{key}" if key.startswith("refl") else key): v
               for key, v in end.items()},
            "incident_ratio": round(s.a_incident / s_ref.a_incident, 4),
            "incident_phase_rad": round(float(np.angle(np.exp(
                1j * (s.phase_incident - s_ref.phase_incident)))), 4),
            "rmse_over_H_incident": round(rmse_over_height(incident, incident_ref, c.height), 4)}


def _against_sph_only(c: FlumeCase, res: dict, sph: dict) -> float | None:
    """RMSE/H of a coupled run against the full SPH-only run at the flat gauge, over the same
    window: a reference with the same beach (the SPH-only inlet is driven by Stokes-2 theory
    and its wave crosses the whole flume in SPH, so its own loss and harmonics are in it)."""
    if "t" not in res or "t" not in sph or res["state"] != "finished" or \
            sph["state"] != "finished":
        return None
    ref = np.interp(res["t"], sph["t"], sph["eta"]["flat"])
    rmse = rmse_over_h(res["t"], res["eta"]["flat"], ref, c)
    return None if rmse is None else round(rmse, 4)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--dp", type=float, default=0.01, help="particle spacing [m] (both runs)")
    ap.add_argument("--wavelengths", type=float, default=12.0,
                    help="Boussinesq source to SPH inlet, in wavelengths")
    ap.add_argument("--sph-only-seconds", type=float, default=3.0,
                    help="simulated seconds of the SPH-only run, extrapolated to t_end (0: full run)")
    ap.add_argument("--modes", default=None,
                    help="coupled runs (default: two_way,absorption_only; absorption_only with "
                         "--end outlet)")
    ap.add_argument("--end", choices=("beach", "outlet"), default="beach",
                    help="the SPH zone's far end: the 1:10 beach, or an open outlet fed by the "
                         "model (flat bed, absorption-only)")
    ap.add_argument("--x-flat", type=float, default=None,
                    help="flat bed inside SPH, inlet -> beach toe or outlet [m] (default 1.2)")
    ap.add_argument("--no-sph-only", action="store_true",
                    help="coupled runs only (no SPH-only run, no speed-up summary)")
    ap.add_argument("--absorb", choices=("none", "client", "incident", "sph"), default=None,
                    help="who absorbs at the SPH inlet (default: the two-way boundary with the "
                         "client's incident-wave correction in two-way mode, the client in "
                         "absorption-only; wavesph.cases.coupled_flume.run_coupled)")
    ap.add_argument("--h-over-dp", type=float, help="SPH smoothing length / dp (scene default)")
    ap.add_argument("--alpha-wall", type=float, help="SPH wall viscosity factor (scene default)")
    add_scheme_arguments(ap)
    ap.add_argument("--out", type=Path, default=None, help="run directories (default: a temp dir)")
    ap.add_argument("--face-zone-targets", action="store_true",
                    help="ISPH: the client sends the wave at the faces only, so the relaxation "
                         "zones pull towards the face's profile (default: the wave inside them)")
    args = ap.parse_args(argv)
    scheme = scheme_from_args(args)
    out = args.out or Path(tempfile.mkdtemp(prefix="coupled_vs_sph-"))
    constants = {k: v for k, v in (("h_over_dp", args.h_over_dp),
                                   ("alpha_wall_factor", args.alpha_wall)) if v is not None}
    case = {"wavelengths": args.wavelengths, "end": args.end,
            **({} if args.x_flat is None else {"x_flat": args.x_flat})}
    c = FlumeCase(**case).at(args.dp)
    modes = (args.modes or ("absorption_only" if args.end == "outlet"
                            else "two_way,absorption_only")).split(",")
    if args.end == "outlet" and (modes != ["absorption_only"] or args.absorb == "sph"):
        ap.error("--end outlet runs absorption_only with the client absorbing (the model hears "
                 "SPH at one boundary; wavesph.cases.coupled_flume.run_coupled)")
    common = {"dp": args.dp, "scheme": scheme, "H": c.height, "T": c.period, "depth": c.depth,
              "H_over_dp": round(c.height / args.dp, 3), "wavelengths": c.wavelengths,
              "wavelength_m": round(c.wavelength, 4), "t_end": round(c.t_end, 3),
              "compare_from": round(c.compare_from, 3), "gauge_x_from_inlet": c.gauge,
              "t_sph_start": round(c.t_sph_start, 3), "end": c.end, "x_flat": c.x_flat,
              **({"zone_targets": "face" if args.face_zone_targets else "local"}
                 if (scheme or {}).get("isph_relaxation_zone") else {})}
    coupled, records = {}, {}
    for mode in modes:
        res = run_coupled(c, args.dp, out / f"coupled_{mode}", two_way=mode == "two_way",
                          absorb=args.absorb, constants=constants, scheme=scheme,
                          zone_nodes=not args.face_zone_targets)
        records[mode] = res
        line = {"run": "coupled", "mode": res["mode"], "absorb": res["absorb"], **common,
                "state": res["state"],
                "particles": res["particles"], "steps": res["steps"], "windows": res["windows"],
                "wall_s": round(res["wall_s"], 2),
                "coupling_overhead_share": res["coupling_overhead_share"], **_accuracy(c, res)}
        coupled[mode] = line
        print(json.dumps(line), flush=True)
    if args.no_sph_only:
        return 0
    full = args.sph_only_seconds <= 0 or args.sph_only_seconds >= c.t_end
    res = run_sph_only(c, args.dp, out / "sph_only", t_end=None if full else args.sph_only_seconds,
                       scheme=scheme)
    build, run_wall = res["build_s"], res["wall_s"] - res["build_s"]
    wall = res["wall_s"] if full else build + run_wall * c.t_end / res["t_end"]
    sph = {"run": "sph_only", **common, "state": res["state"], "particles": res["particles"],
           "steps": res["steps"], "simulated_s": round(res["t_end"], 3),
           "measured_wall_s": round(res["wall_s"], 2), "build_s": round(build, 2),
           "extrapolated": not full, "wall_s": round(wall, 2),
           **(_accuracy(c, res) if full else {"rmse_over_H": None, "correlation": None})}
    print(json.dumps(sph), flush=True)
    # the speed-up against a coupled run that reached t_end (two-way preferred)
    done = [v for v in coupled.values() if v["state"] == "finished"] or list(coupled.values())
    base = next((v for v in done if v["mode"] == "two_way"), done[0])
    summary = {"summary": "coupled_vs_sph", "dp": args.dp, "H_over_dp": common["H_over_dp"],
               "speedup": round(wall / base["wall_s"], 2), "speedup_mode": base["mode"],
               "speedup_by_mode": {m: round(wall / v["wall_s"], 2) for m, v in coupled.items()
                                   if v["state"] == "finished"},
               "coupled_states": {m: v["state"] for m, v in coupled.items()},
               "sph_only_extrapolated": not full,
               "particles_ratio": round(sph["particles"] / base["particles"], 2),
               "rmse_over_H_coupled": {m: v["rmse_over_H"] for m, v in coupled.items()},
               "rmse_over_H_sph_only": sph["rmse_over_H"],
               "rmse_over_H_coupled_vs_sph_only": {
                   m: _against_sph_only(c, r, res) for m, r in records.items()},
               "out": str(out)}
    print(json.dumps(summary), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
