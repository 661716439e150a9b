"""`wavesph couple`: drive a wave model against a running SPH server.

    wavesph couple --url ws://127.0.0.1:8000/runs/r1/couple --model stokes --H 0.08 --T 2
    wavesph couple --url tcp://127.0.0.1:8766 --run-id r1 --model irregular --H 0.15 --T 2 \
                   --out gauges.csv
    wavesph couple --url ws://127.0.0.1:8000/runs/r1/couple --model solitary --H 0.01 --t0 3
    wavesph couple --scene examples/scenes/demo_beach_flume.toml --model stokes --H 0.04 --T 1.4
        (creates the coupled run from the scene file on the server at --url, default
        http://127.0.0.1:8765, then couples to it)

The still-water depth defaults to the scene's (sent by the server in WELCOME); --d is checked
against it. Exit status: 0 done, 1 the coupled run failed (reason on stderr), 2 bad arguments.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from protocol import Welcome

THEORY_MODELS = ("linear", "stokes", "stream", "standing", "irregular", "solitary")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    p = parser
    p.add_argument("--url", default=None,
                   help="ws://HOST:PORT/runs/ID/couple or tcp://HOST:PORT (then give --run-id); "
                        "with --scene: the server, http://HOST:PORT (default http://127.0.0.1:8765)")
    p.add_argument("--scene", type=Path, default=None,
                   help="scene file (TOML) to create the coupled run from first (its [coupling] "
                        "table: window_max, z_ref; its mode and [source] are left out: --model "
                        "drives the run)")
    p.add_argument("--token", default=None,
                   help="API token for --scene (default: WAVESPH_TOKEN)")
    p.add_argument("--model", required=True, choices=THEORY_MODELS + ("boussinesq",),
                   help="wave model driving the SPH inlet")
    p.add_argument("--H", type=float, help="wave height [m] (irregular: significant height Hs)")
    p.add_argument("--T", type=float, help="wave period [s] (irregular: peak period Tp)")
    p.add_argument("--d", type=float, default=None,
                   help="still-water depth [m]; default: the scene's depth at the inlet")
    p.add_argument("--ramp-periods", type=float, default=2.0,
                   help="half-cosine start-up ramp, in wave periods (the flume starts at rest)")
    p.add_argument("--t0", type=float, default=None,
                   help="time [s] the crest passes the SPH inlet (--model solitary; default: "
                        "when the elevation there starts at 1e-3 H)")
    p.add_argument("--order", type=int, default=None,
                   help="--model stokes: order 2-5 (default 5); --model standing: 1 or 2 "
                        "(default 1)")
    p.add_argument("--n-fourier", type=int, default=10, help="Fourier modes (--model stream)")
    p.add_argument("--gamma", type=float, default=3.3, help="JONSWAP peak enhancement (irregular)")
    p.add_argument("--components", type=int, default=200, help="wave components (irregular)")
    p.add_argument("--seed", type=int, default=0, help="random phases seed (irregular)")
    p.add_argument("--config", default=None,
                   help="`wavesph waves` TOML scene of the Boussinesq model (--model boussinesq); "
                        "its [coupling] x is where the SPH inlet sits")
    p.add_argument("--window", type=float, default=None,
                   help="coupling window [s]; default min(server window_max, T/50)")
    p.add_argument("--t-end", type=float, default=None, help="stop at this time [s]")
    p.add_argument("--absorb", action="store_true",
                   help="apply the active-absorption correction of Verbrugghe et al. 2019 "
                        "(seed 002) on the client side; only for a server whose open boundaries "
                        "do not absorb themselves")
    p.add_argument("--absorb-wave", choices=("total", "incident"), default="total",
                   help="what the client's correction compares: the total elevation "
                        "(Verbrugghe et al. 2019, seed 002), or the incident (right-going) "
                        "characteristic, for two-way models whose boundary already lets SPH's "
                        "reflection out (CouplingOptions.absorb_wave)")
    p.add_argument("--absorb-cutoff", type=float, default=None,
                   help="low-pass cutoff [Hz] of the absorption's measured mismatch (default 3/T)")
    p.add_argument("--x-offset", type=float, default=None,
                   help="model x = SPH x + offset [m]; default: the Boussinesq [coupling] x at "
                        "the SPH inlet, 0 for the theories")
    p.add_argument("--inlet-gauge", type=int, default=None,
                   help="gauge index measuring the inlet (default: nearest to the inlet)")
    p.add_argument("--outlet-gauge", type=int, default=None,
                   help="gauge index measuring the outlet (default: nearest to the outlet)")
    p.add_argument("--no-zone-nodes", action="store_true",
                   help="send the wave at the open ends' faces only, not inside the run's "
                        "relaxation zones (ISPH; protocol 1.2 ZONE_NODES): the zones then pull "
                        "towards the face's profile")
    p.add_argument("--run-id", default=None, help="run to couple to (required with tcp://)")
    p.add_argument("--scene-hash", default=None,
                   help="SHA-256 (hex) of the scene the model was set up for; refused if it differs")
    p.add_argument("--timeout", type=float, default=120.0,
                   help="longest wait for a server reply [s] (one SPH window)")
    p.add_argument("--queue-timeout", type=float, default=3600.0,
                   help="longest wait for the run to start [s] (it may be queued on the server; "
                        "it is reserved for this client meanwhile)")
    p.add_argument("-o", "--out", dest="output", default=None,
                   help="CSV file for the gauge series (must not exist)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")


def model_factory(args: argparse.Namespace) -> tuple[Callable[[Welcome], Any], float | None]:
    """(callable(Welcome) -> WaveModel, wave period [s] or None) for the chosen --model.

    Theories take the depth from WELCOME unless --d is given; everything that can be checked
    before connecting is checked here, so a bad argument never reaches the server.
    """
    if args.model == "boussinesq":
        return _boussinesq_factory(args)
    from wave_client.theories import build_theory

    if args.model == "solitary":
        if args.H is None or args.T is not None:
            raise ValueError("--model solitary needs --H and takes no --T (no period)")
        options: dict[str, Any] = {"t0": args.t0}
    elif args.H is None or args.T is None:
        raise ValueError(f"--model {args.model} needs --H and --T")
    else:
        if args.t0 is not None:
            raise ValueError("--t0 is for --model solitary")
        options = {"ramp_time": args.ramp_periods * args.T}
    if args.order is not None:
        if args.model not in ("stokes", "standing"):
            raise ValueError(f"--order is for --model stokes or standing, not {args.model}")
        options["order"] = args.order
    elif args.model == "stream":
        options["n_fourier"] = args.n_fourier
    elif args.model == "irregular":
        options.update(gamma=args.gamma, n_components=args.components, seed=args.seed)
    if args.ramp_periods < 0:
        raise ValueError(f"--ramp-periods must be >= 0, got {args.ramp_periods}")

    def make(welcome: Welcome):
        depth = welcome.depth if args.d is None else args.d
        return build_theory(args.model, height=args.H, period=args.T, depth=depth, **options)

    if args.d is not None:  # validate the theory now, before connecting
        make(None)  # type: ignore[arg-type]
    return make, args.T


def _boussinesq_factory(args: argparse.Namespace) -> tuple[Callable[[Welcome], Any], float | None]:
    try:  # imported lazily: the theories never need numba
        from wave_client.boussinesq.wave_scene import build_model, load_wave_scene
    except ImportError as exc:
        raise ValueError(f"--model boussinesq is not available in this build ({exc})") from exc
    if args.config is None:
        raise ValueError("--model boussinesq needs --config SCENE.toml (a `wavesph waves` scene)")
    config = Path(args.config)
    scene = load_wave_scene(config)  # WaveSceneError is a ValueError naming the field
    return (lambda welcome: build_model(scene, base_dir=config.parent)), getattr(scene.wave, "period", None)


def _create_run(args: argparse.Namespace) -> str:
    """POST the scene file as a coupled run; the WebSocket url to couple to."""
    import os

    from wave_client.coupling.server_runs import (DEFAULT_SERVER, SubmitError, coupled_run_body,
                                                  http_base, submit_scene_file)

    server = args.url or DEFAULT_SERVER
    if server.startswith("tcp://") or "/runs/" in server:
        raise ValueError("with --scene, --url is the server (http://HOST:PORT), not a run")
    body, dropped = coupled_run_body(args.scene)
    if dropped:
        print(f"wavesph couple: the file's {' and '.join(dropped)} left out: this client's "
              f"--model drives the run ({args.scene} as it is: `wavesph submit`)", file=sys.stderr)
    try:
        info = submit_scene_file(server, args.scene, body=body,
                                 token=args.token or os.environ.get("WAVESPH_TOKEN"))
    except SubmitError as exc:
        raise CoupleSetupError(str(exc)) from None
    base = http_base(server)
    print(f"wavesph couple: created run {info['id']} from {args.scene} ({base}/runs/{info['id']})",
          file=sys.stderr)
    return base.replace("http", "ws", 1) + f"/runs/{info['id']}/couple"


class CoupleSetupError(Exception):
    """The server refused to create the run (exit 1, like a failed coupling)."""


def main(args: argparse.Namespace) -> int:
    from wave_client.coupling import CouplingError, CouplingOptions, couple

    try:
        factory, period = model_factory(args)
        window = args.window
        if window is None and args.model == "boussinesq" and period is not None:
            window = period / 50  # the theories give the core their period themselves
        scene_hash = None
        if args.scene_hash is not None:
            try:
                scene_hash = bytes.fromhex(args.scene_hash)
            except ValueError:
                scene_hash = b""
            if len(scene_hash) != 32:
                raise ValueError("--scene-hash must be 64 hex digits (SHA-256)")
        options = CouplingOptions(window=window, t_end=args.t_end, absorb=args.absorb,
                                  absorb_cutoff=args.absorb_cutoff, absorb_wave=args.absorb_wave,
                                  x_offset=args.x_offset, inlet_gauge=args.inlet_gauge,
                                  outlet_gauge=args.outlet_gauge,
                                  zone_nodes=not args.no_zone_nodes)
        url = args.url
        if args.scene is not None:
            url = _create_run(args)
        elif url is None:
            raise ValueError("give --url (a run on a server) or --scene (create the run first)")
        if url.startswith("tcp://") and not args.run_id:
            raise ValueError("--run-id is required with a tcp:// url (the HELLO names the run)")
        report = couple(url, factory, options, run_id=args.run_id, scene_hash=scene_hash,
                        timeout=args.timeout, queue_timeout=args.queue_timeout,
                        log_path=args.output, progress=not args.no_progress)
    except ValueError as exc:
        print(f"wavesph couple: {exc}", file=sys.stderr)
        return 2
    except (CouplingError, CoupleSetupError) as exc:
        print(f"wavesph couple: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("wavesph couple: interrupted (the server was told; the gauge log keeps every "
              "window received)", file=sys.stderr)
        return 130
    n = len(report.records)
    t = report.records[-1].t1 if n else float("nan")
    overhead = report.model_time / report.wall_time if report.wall_time > 0 else 0.0
    print(f"coupled {n} windows to t = {t:.6g} s in {report.wall_time:.2f} s "
          f"(wave model {overhead:.1%} of wall time); correction gauges: "
          + (", ".join(f"{side} {name}" for side, name in report.gauge_names.items()) or "none")
          + (f"; series in {args.output}" if args.output else ""))
    return 0
