"""`wavesph bench accuracy|stability`: the speed-accuracy chart and the stability suite.

Each point (case or scenario, method, dp) is an independent run on dask.distributed: a
LocalCluster of processes (one thread each) unless ``--scheduler ADDRESS`` names an existing
scheduler (its workers need this package importable). Records land in DIR/points/*.json: run the
same command again and finished points are not rerun (``--retry-failed`` reruns the failed).
"""

from __future__ import annotations

import argparse
import json
import shlex
import sys
from pathlib import Path

from wavesph.studies import stability, sweeps


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="what", required=True)
    for name, help_text, default in (
            ("accuracy", "error against wall time for every case x method x dp: accuracy.csv/png",
             "runs/accuracy"),
            ("stability", "method x scenario -> stable/noisy/unstable: stability.csv/png",
             "runs/stability")):
        p = sub.add_parser(name, help=help_text, description=help_text)
        p.add_argument("--quick", action="store_true", help="the small preset (<= 10 min on 2 cores)")
        p.add_argument("--out", type=Path, default=Path(default), help=f"run directory ({default})")
        p.add_argument("--scheduler", default=None, help="address of an existing dask scheduler")
        p.add_argument("--workers", type=int, default=None, help="LocalCluster workers (default: cores)")
        p.add_argument("--methods", default=None,
                       help=f"comma-separated subset of {','.join(sweeps.METHODS)}")
        p.add_argument("--retry-failed", action="store_true", help="rerun points that failed")
        if name == "accuracy":
            p.add_argument("--cases", default=None,
                           help="comma-separated subset of flume_I..flume_V, dambreak, coupled")
            p.add_argument("--repeats", type=int, default=1,
                           help="realisations of every point (a flume's ramp 0.1 %% longer per "
                                "repeat); the chart draws their run-to-run scatter")


def main(args: argparse.Namespace) -> int:
    methods = args.methods.split(",") if args.methods else None
    command = "wavesph " + " ".join(shlex.quote(a) for a in sys.argv[1:])
    kw = {"scheduler": args.scheduler, "n_workers": args.workers, "retry_failed": args.retry_failed}
    try:
        if args.what == "accuracy":
            points = sweeps.accuracy_points(args.quick, methods, args.repeats,
                                            args.cases.split(",") if args.cases else None)
        else:
            points = stability.stability_points(args.quick, methods)
    except ValueError as exc:
        print(f"wavesph bench: {exc}", file=sys.stderr)
        return 2
    out: Path = args.out
    if args.what == "accuracy":
        records = sweeps.run_sweep(points, out, desc="accuracy", **kw)
        sweeps.write_csv(records, out / "accuracy.csv", command)
        meta = json.loads((out / "accuracy.meta.json").read_text())
        sweeps.plot_accuracy(records, out / "accuracy.png", title=sweeps.chart_title(meta))
        files = [out / "accuracy.csv", out / "accuracy.png"]
    else:
        records = stability.run_stability(points, out, **kw)
        stability.write_stability_csv(records, out / "stability.csv", command)
        stability.plot_stability(records, out / "stability.png")
        files = [out / "stability.csv", out / "stability.png"]
    print(f"{len(records)} points: {sweeps.records_summary(records)}; wrote "
          + ", ".join(str(f) for f in files), file=sys.stderr)
    return 0
