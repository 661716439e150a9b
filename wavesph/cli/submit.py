"""`wavesph submit SCENE.toml`: create a run on a server from a scene file.

    wavesph submit examples/scenes/demo_beach_flume.toml --source stokes --H 0.04 --T 1.4 --order 2
    wavesph submit tank.toml --url http://host:8765 --token $WAVESPH_TOKEN

The file goes to the server as it is (its `mode`, `[coupling]` and `[source]` tables beside the
scene); `--source` and `--mode` override them. Prints the run's id and where to follow it.
Exit status: 0 created, 1 the server refused it or is unreachable (its reason on stderr), 2 bad
arguments.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

SOURCES = ("linear", "stokes", "stream", "irregular", "solitary")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from wave_client.coupling.server_runs import DEFAULT_SERVER

    p = parser
    p.add_argument("scene", type=Path, help="scene file (TOML; may hold mode, [coupling], [source])")
    p.add_argument("--url", default=DEFAULT_SERVER,
                   help=f"the server, wavesph serve (default {DEFAULT_SERVER})")
    p.add_argument("--mode", choices=("coupled", "standalone"), default=None,
                   help="coupled: wait for a client (wavesph couple); standalone: run as it is, "
                        "open ends driven by the source (default: the file's mode, else "
                        "standalone with a source or without open ends, coupled otherwise)")
    p.add_argument("--source", choices=SOURCES, default=None,
                   help="a built-in wave theory driving the open ends (replaces a [source] table)")
    p.add_argument("--H", type=float, default=None, help="--source wave height [m] (irregular: Hs)")
    p.add_argument("--T", type=float, default=None, help="--source wave period [s] (irregular: Tp)")
    p.add_argument("--ramp-periods", type=float, default=None,
                   help="--source start-up ramp in periods (default: the server's, 2)")
    p.add_argument("--order", type=int, default=None, help="--source stokes: order 2-5 (default 5)")
    p.add_argument("--t0", type=float, default=None,
                   help="--source solitary: time [s] the crest passes the inlet (default: the "
                        "elevation there starts at 1e-3 H)")
    p.add_argument("--n-fourier", type=int, default=None,
                   help="--source stream: Fourier terms (default 10)")
    p.add_argument("--token", default=os.environ.get("WAVESPH_TOKEN"),
                   help="API token (default: WAVESPH_TOKEN); needed off loopback")


def source_table(args: argparse.Namespace) -> dict | None:
    """The [source] table the options give, or None; ValueError if incomplete."""
    extra = {"ramp_periods": args.ramp_periods, "order": args.order, "n_fourier": args.n_fourier,
             "t0": args.t0}
    if args.source is None:
        given = [k for k in ("H", "T") if getattr(args, k) is not None]
        given += [k for k, v in extra.items() if v is not None]
        if given:
            raise ValueError(f"--{given[0].replace('_', '-')} needs --source THEORY")
        return None
    if args.source == "solitary":  # one wave, no period: the server refuses a T
        if args.H is None or args.T is not None:
            raise ValueError("--source solitary needs --H and takes no --T")
        return {"theory": "solitary", "H": args.H,
                **{k: v for k, v in extra.items() if v is not None}}
    if args.H is None or args.T is None:
        raise ValueError(f"--source {args.source} needs --H and --T")
    return {"theory": args.source, "H": args.H, "T": args.T,
            **{k: v for k, v in extra.items() if v is not None}}


def main(args: argparse.Namespace) -> int:
    from wave_client.coupling.server_runs import SubmitError, http_base, submit_scene_file

    try:
        info = submit_scene_file(args.url, args.scene, mode=args.mode, source=source_table(args),
                                 token=args.token)
    except SubmitError as exc:          # the server's answer (or none)
        print(f"wavesph submit: {exc}", file=sys.stderr)
        return 1
    except (ValueError, OSError) as exc:  # the arguments or the file
        print(f"wavesph submit: {exc}", file=sys.stderr)
        return 2
    base = http_base(args.url)
    print(f"run {info['id']} ({info['mode']}, {info['status']}); follow it at {base}/ "
          f"or {base}/runs/{info['id']}")
    if info["mode"] == "coupled":
        ws = base.replace("http", "ws", 1)
        print(f"couple a wave model: wavesph couple --url {ws}/runs/{info['id']}/couple --model ...")
    return 0
