"""`wavesph demo`: a coupled wave-SPH flume with a beach, end to end on this machine (the case:
`wavesph/cases/demo_flume.py`); ``--dambreak``: the standalone Martin & Moyce dam break (`wavesph/cases/dambreak_demo.py`).

Writes into the run directory (default ./runs/demo-<UTC time>):

    <run id>/            the server's run record: meta.json, gauges.csv (SPH-measured), sph/
                         (probes.csv, VTK snapshots every second: sph/run.pvd, sph/snapshots/)
    client_gauges.csv    the client's log: measured and theoretical elevation per window
    elevation.png        SPH-measured vs theoretical elevation at the gauges, and the flume
    summary.json         the figures printed at the end
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

from ._common import add_device_argument, device_problem, refuse_non_empty


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--t-end", type=float, default=None,
                        help="simulated time [s] (default 8: 2 ramp periods, then ~3 periods "
                             "of full waves at the flat-bed gauge; --dambreak: T = t sqrt(2g/a) "
                             "= 3.3, 0.332 s)")
    parser.add_argument("--dp", type=float, default=None,
                        help="particle spacing [m] (default 0.02: ~3300 particles, H/dp = 2, "
                             "about a minute; 0.01 resolves the wave better at ~8x the time; "
                             "--dambreak: 0.0025, 40 particles across the 0.1 m column)")
    parser.add_argument("--transport", choices=("ws", "tcp"), default="ws",
                        help="coupling socket: WebSocket (default) or plain TCP")
    parser.add_argument("-o", "--out", type=Path, default=None,
                        help="run directory (default ./runs/demo-<UTC time>); must be new or empty")
    parser.add_argument("--no-plot", action="store_true", help="skip the figure")
    parser.add_argument("--body", choices=("box", "flap"), default=None,
                        help="put a rigid body in the SPH zone at x = 1.5 m: a floating box "
                             "(heave, pitch) or a bottom-hinged flap on a spring; its motion "
                             "and loads go to <run id>/sph/bodies.csv (GET /runs/{id}/bodies)")
    parser.add_argument("--basin", action="store_true",
                        help="the coupled demo in 3D: long-crested Stokes-2 waves past a square "
                             "column in a 0.36 m wide basin with side walls, open inlet and "
                             "outlet (wavesph/cases/basin_3d.py; default dp 0.03: ~25,000 "
                             "particles, a few minutes on 2 cores)")
    parser.add_argument("--dambreak", action="store_true",
                        help="run the standalone dam break (Martin & Moyce) instead, as "
                             "`wavesph run examples/scenes/dambreak_martin_moyce.toml` does")
    add_device_argument(parser, "")
    parser.epilog = ("Coupled flume: open inlet, 1:10 beach, Stokes-2 wave H = 0.04 m, T = 1.4 s, "
                     "depth 0.24 m, coupled over a real socket to an in-process server.")


def main(args: argparse.Namespace) -> int:
    # numba's OpenMP threads spin while waiting by default: on a busy machine (more runnable
    # threads than cores) a step then costs 10-20x more. Passive waiting costs little otherwise.
    os.environ.setdefault("OMP_WAIT_POLICY", "passive")  # before numba loads: cases import lazily
    t_end = 8.0 if args.t_end is None else args.t_end
    dp = 0.02 if args.dp is None else args.dp
    if args.dambreak:
        dp = 0.0025 if args.dp is None else args.dp
    if args.basin:
        dp = 0.03 if args.dp is None else args.dp
    if not (t_end > 0 and math.isfinite(t_end)) or not 0.002 <= dp <= 0.05:
        print("wavesph demo: --t-end must be > 0 s and --dp within [0.002, 0.05] m", file=sys.stderr)
        return 2
    out = args.out or Path("runs") / f"demo-{time.strftime('%Y%m%dT%H%M%SZ', time.gmtime())}"
    if refuse_non_empty("demo", out) or device_problem("demo", args.device):
        return 2
    if args.dambreak:
        from wavesph.cases.dambreak_demo import DAMBREAK_A, run_dambreak_demo

        # the column is a = 0.1 m wide: --dp sets the particles across it, --t-end the time
        resolution = round(DAMBREAK_A / dp)
        if resolution < 4 or abs(resolution * dp - DAMBREAK_A) > 1e-9:
            print(f"wavesph demo --dambreak: --dp must divide the {DAMBREAK_A} m column into "
                  f">= 4 particles, got {dp}", file=sys.stderr)
            return 2
        T_end = 3.3 if args.t_end is None else t_end * math.sqrt(2 * 9.81 / DAMBREAK_A)
        try:
            return run_dambreak_demo(out, a=DAMBREAK_A, resolution=resolution, T_end=T_end,
                                     make_plot=not args.no_plot, device=args.device)
        except KeyboardInterrupt:
            print(f"\nwavesph demo: interrupted; partial results in {out}", file=sys.stderr)
            return 130
    if args.basin:
        return _basin(args, dp, t_end, out)
    from wavesph.cases.demo_flume import GAUGES, demo_figures, depth_for, plot_demo, run_demo
    from sph_core.progress import kernels_cached

    if not kernels_cached():  # else the first window's minutes of numba look like a hang (ux F3)
        print("wavesph demo: compiling SPH kernels (first run only, 1-5 min) ...", file=sys.stderr,
              flush=True)
    out.mkdir(parents=True, exist_ok=True)
    tic = time.perf_counter()
    try:
        info, report = run_demo(dp, t_end, args.transport, out, body=args.body,
                                device=args.device)
    except KeyboardInterrupt:
        print(f"\nwavesph demo: interrupted; partial results in {out}", file=sys.stderr)
        return 130
    depth = depth_for(dp)
    wall = time.perf_counter() - tic
    if not _finished(info, report, out):
        return 1
    figures = demo_figures(info, report, wall, depth)
    (out / "summary.json").write_text(json.dumps(figures, indent=2))
    print(f"particles {figures['particles']}, windows {figures['windows']}, SPH steps "
          f"{figures['steps']}, wall time {wall:.1f} s (SPH solve {figures['sph_solve_s']:.1f} s)\n"
          f"speed {figures['particle_steps_per_s']:.3g} particle-steps/s while solving "
          f"({figures['particle_steps_per_s_wall']:.3g} over the wall time, compilation included); "
          f"coupling overhead {100 * figures['coupling_overhead_share']:.1f} % of the coupled time\n"
          f"RMSE/H at the flat-bed gauge (x = {GAUGES['flat']} m, t >= {figures['compare_from_s']:.2f} s, "
          f"measured vs Stokes 2): "
          f"{_rmse_text(figures['rmse_over_H_flat'])}", file=sys.stderr)
    if not args.no_plot:
        plot_demo(report, info, out / "elevation.png", dp, t_end, figures["compare_from_s"],
                  figures["rmse_over_H_flat"])
    print(f"outputs in {out.resolve()}:\n"
          f"  {info['id']}/gauges.csv   SPH-measured gauges (server)\n"
          f"  {info['id']}/meta.json    run record ({info['status']})\n"
          f"  client_gauges.csv          measured and theoretical elevation per window\n"
          + ("" if args.no_plot else "  elevation.png              measured vs theory\n")
          + f"  {info['id']}/sph/run.pvd    VTK particle snapshots (sph/snapshots/) for ParaView\n"
          + (f"  {info['id']}/sph/bodies.csv the {args.body}'s motion and loads\n"
             if args.body else "")
          + "  summary.json               these figures", file=sys.stderr)
    return 0


def _basin(args: argparse.Namespace, dp: float, t_end: float, out: Path) -> int:
    """`wavesph demo --basin`: the 3D coupled basin (wavesph/cases/basin_3d.py)."""
    from wavesph.cases.basin_3d import BASIN_DEPTH, basin_figures, run_basin
    from wavesph.cases.coupled_flume import depth_for_case
    from sph_core.progress import kernels_cached

    if not kernels_cached():
        print("wavesph demo: compiling SPH kernels (first run only, 1-5 min) ...", file=sys.stderr,
              flush=True)
    out.mkdir(parents=True, exist_ok=True)
    tic = time.perf_counter()
    try:
        info, report = run_basin(dp, t_end, args.transport, out, device=args.device)
    except KeyboardInterrupt:
        print(f"\nwavesph demo: interrupted; partial results in {out}", file=sys.stderr)
        return 130
    wall = time.perf_counter() - tic
    if not _finished(info, report, out):
        return 1
    figures = basin_figures(info, report, wall, depth_for_case(BASIN_DEPTH, dp))
    (out / "summary.json").write_text(json.dumps(figures, indent=2))
    print(f"particles {figures['particles']}, windows {figures['windows']}, SPH steps "
          f"{figures['steps']}, wall time {wall:.1f} s; "
          f"{figures['particle_steps_per_s']:.3g} particle-steps/s while solving\n"
          f"RMSE/H at the centre-line gauge before the column (x = {figures['gauge_x_m']['front']} m, "
          f"t >= {figures['compare_from_s']:.2f} s, measured vs Stokes 2): "
          f"{_rmse_text(figures['rmse_over_H_front'])}\n"
          f"outputs in {out.resolve()}: {info['id']}/gauges.csv, {info['id']}/sph/probes.csv "
          f"(the column's load), {info['id']}/sph/run.pvd (ParaView), client_gauges.csv, "
          f"summary.json", file=sys.stderr)
    return 0


def _finished(info: dict, report: object, out: Path) -> bool:
    """Did the coupled run finish with a client report? Else say how it ended, where its data is."""
    if info["state"] == "finished" and report is not None:
        return True
    print(f"wavesph demo: the run ended {info['status']}; data so far in {out / info['id']}",
          file=sys.stderr)
    return False


def _rmse_text(v: float | None) -> str:
    return "n/a (the run ended before full waves reached the gauge)" if v is None else f"{v:.3f}"
