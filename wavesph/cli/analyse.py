"""`wavesph analyse RUN_DIR`: what an engineer reads off a run, from its gauge files.

    wavesph analyse runs/seawall --from 3.0 --period 1.5

Per elevation gauge Hm0, Tp, H1/3, Hmax, Tm and the number of waves; per overtopping probe the
mean discharge q; per run-up probe Ru2% and the highest run-up above still water (Ru2% ranked
among the first elevation gauge's incident waves); per force or pressure-line column the peaks
(with --period, the mean of the per-period maxima and of their highest tenth). The functions
are wavesph.analysis's (wave_statistics, mean_overtopping, runup_statistics, peaks,
analyse_run). Exit status: 0, 2 no gauge files.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from wavesph.analysis import analyse_run


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("run_dir", type=Path,
                        help="a run directory (`wavesph run` -o, or a server run's directory)")
    parser.add_argument("--from", dest="t_from", type=float, default=None,
                        help="analyse from this time [s] on, e.g. after the start-up ramp "
                             "(default: the whole record)")
    parser.add_argument("--period", type=float, default=None,
                        help="wave period [s]: load peaks per period too")
    parser.add_argument("--json", action="store_true", help="print one JSON object only")


def main(args: argparse.Namespace) -> int:
    try:
        res = analyse_run(args.run_dir, args.t_from, args.period)
    except (ValueError, OSError) as exc:
        print(f"wavesph analyse: {exc}", file=sys.stderr)
        return 2
    if args.json:
        print(json.dumps(res))
        return 0
    span = f"from t = {args.t_from:g} s" if args.t_from is not None else "whole records"
    print(f"{args.run_dir}: {', '.join(res['files'])} ({span})")
    if res["waves"]:
        print(f"\n{'gauge':<16} {'Hm0 [m]':>9} {'Tp [s]':>8} {'H1/3 [m]':>9} {'Hmax [m]':>9} "
              f"{'Tm [s]':>8} {'waves':>6}")
        for g, w in res["waves"].items():
            print(f"{g:<16} {w['Hm0']:>9.4g} {w['Tp']:>8.4g} {_f(w['H1_3']):>9} "
                  f"{_f(w['Hmax']):>9} {_f(w['Tm']):>8} {w['n_waves']:>6}")
    if res["overtopping"]:
        print(f"\n{'overtopping':<16} {'mean q [m^2/s]':>15}")
        for name, o in res["overtopping"].items():
            print(f"{name:<16} {o['q_m2_s']:>15.4g}")
    if res["runup"]:
        print(f"\n{'run-up':<16} {'Ru2% [m]':>9} {'Rmax [m]':>9} {'events':>7} {'waves':>6}")
        for name, r in res["runup"].items():
            print(f"{name:<16} {r['Ru2']:>9.4g} {r['Rmax']:>9.4g} {r['n_events']:>7} {r['n_waves']:>6}")
    if res["loads"]:
        print(f"\n{'load [N/m, N m/m, Pa]':<22} {'max':>10} {'at t [s]':>9} {'min':>10} "
              f"{'mean':>10} {'mean/period':>12} {'top 1/10':>10}")
        for name, p in res["loads"].items():
            print(f"{name:<22} {p['max']:>10.4g} {p['t_max']:>9.4g} {p['min']:>10.4g} "
                  f"{p['mean']:>10.4g} {_f(p['mean_of_period_maxima']):>12} "
                  f"{_f(p['highest_tenth_mean']):>10}")
    for name, why in res["skipped"].items():
        print(f"skipped {name}: {why}", file=sys.stderr)
    return 0


def _f(v: float | None) -> str:
    return "-" if v is None else f"{v:.4g}"
