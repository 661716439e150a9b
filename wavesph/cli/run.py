"""`wavesph run SCENE.toml`: run an SPH scene standalone with a progress bar."""

from __future__ import annotations

import argparse
import sys
import time
import tomllib
from pathlib import Path

from sph_core.progress import advance_with_progress
from sph_core.scene import Scene, SceneError, load_scene, make_scene, split_scene_file
from sph_core.simulation import DeviceError, Simulation

from ._common import add_device_argument, positive_float, refuse_non_empty

MAX_PARTICLES = 2e7  # ten times the server's cap: a typo in dp, not a big study


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", type=Path, help="scene file (TOML)")
    parser.add_argument("-o", "--out", type=Path, default=None,
                        help="run directory, new or empty (default: runs/<scene name>-<UTC time>)")
    parser.add_argument("--t-end", type=positive_float, default=None,
                        help="end time [s] (default: the scene's t_end)")
    parser.add_argument("--dp", type=positive_float, default=None,
                        help="particle spacing [m] (default: the scene's dp)")
    parser.add_argument("--snapshot-every", type=float, default=None,
                        help="VTK snapshot interval [s], 0 = none (default: the scene's "
                             "output.snapshot_every)")
    parser.add_argument("--threads", type=int, default=None,
                        help="numba threads (default: NUMBA_NUM_THREADS or all cores)")
    add_device_argument(parser, "")
    parser.add_argument("--max-particles", type=positive_float, default=MAX_PARTICLES,
                        help=f"refuse a scene estimated above this many particles (default "
                             f"{MAX_PARTICLES:.0e}: a dp typed wrong would fill the memory)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar or lines")
    parser.add_argument("--preview", action="store_true",
                        help="write the initial particles (snapshots/particles_00000.vtu) and the "
                             "geometry (geometry.vtu) and stop, without solving (as GenCase)")
    parser.add_argument("--wave", type=float, nargs=2, metavar=("H", "T"), default=None,
                        help="the waves the scene is for (height [m], period [s]): warn if the "
                             "scene costs far more than `wavesph plan`'s for the same accuracy")


def main(args: argparse.Namespace) -> int:
    try:
        scene = load_scene(args.scene)
        refusal = None if args.preview else open_end_refusal(args.scene, scene)  # no step: no waves
        if refusal:
            print(f"wavesph run: {refusal}", file=sys.stderr)
            return 2
        if scene.open_boundaries and not args.preview:
            print("wavesph run: nothing drives the open boundaries here: they hold still water "
                  "(for waves: `wavesph submit` with a [source], or `wavesph couple --scene`)",
                  file=sys.stderr)
        data = scene.model_dump(mode="json")
        if args.t_end is not None:
            data["t_end"] = args.t_end      # meta.json records the real end
        if args.dp is not None:
            data["dp"] = args.dp
        if args.device is not None:
            data["run"] = {**data["run"], "device": args.device}
        length = data["t_end"] - data["t_start"]
        if args.snapshot_every is not None:
            data["output"] = {**data["output"], "snapshot_every": args.snapshot_every}
        elif args.t_end is not None and data["output"]["snapshot_every"] > length:
            # a shortened run keeps its first and last snapshot, and says so
            data["output"] = {**data["output"], "snapshot_every": length}
            print(f"wavesph run: snapshots every {length:g} s (the run is shorter than the "
                  "scene's output.snapshot_every)", file=sys.stderr)
        scene = make_scene(data)             # the overrides are validated like the file
    except SceneError as exc:
        print(f"wavesph run: {exc}", file=sys.stderr)
        return 2
    from server.schemas import estimate_particles

    n = estimate_particles(scene)
    if n > args.max_particles:
        print(f"wavesph run: the scene needs about {n:.3g} particles, above --max-particles "
              f"{args.max_particles:.3g}: increase dp (now {scene.dp:g} m) or raise the cap",
              file=sys.stderr)
        return 2
    if args.threads is not None:
        import numba

        if not 1 <= args.threads <= numba.config.NUMBA_NUM_THREADS:
            print(f"wavesph run: --threads must be within [1, {numba.config.NUMBA_NUM_THREADS}]",
                  file=sys.stderr)
            return 2
        numba.set_num_threads(args.threads)
    if args.wave is not None:
        _warn_if_expensive(scene, *args.wave)
    out = args.out or Path("runs") / f"{scene.name}-{time.strftime('%Y%m%dT%H%M%SZ', time.gmtime())}"
    if refuse_non_empty("run", out):
        return 2
    print(f"building particles for '{scene.name}' (dp = {scene.dp} m) ...", file=sys.stderr)
    try:
        sim = Simulation(scene, run_dir=out)
    except DeviceError as exc:   # raised before the run directory is written
        print(f"wavesph run: {exc}", file=sys.stderr)
        return 2
    print(f"{sim.n_fluid} fluid + {sim.n_particles - sim.n_fluid} wall particles, c0 = {sim.c0:.2f} m/s, "
          f"h = {sim.h:.4g} m, device {sim.device}; output in {out}", file=sys.stderr)
    if args.preview:
        return _preview(sim, out)
    try:
        code = advance_with_progress(sim, scene.t_end, scene.name, show=not args.no_progress)
    except KeyboardInterrupt:
        print(f"\nwavesph run: interrupted at t = {sim.t:.4g} s; partial results in {out}",
              file=sys.stderr)
        return 130
    if code == 0:
        print(f"done: {sim.steps} steps in {sim.wall_time:.1f} s "
              f"({sim.n_particles * sim.steps / max(sim.wall_time, 1e-9) / 1e6:.2f} M particle-steps/s); "
              f"results in {out}", file=sys.stderr)
    return code


def open_end_refusal(path: Path, scene: Scene) -> str | None:
    """Why `wavesph run` refuses ``scene`` (read from ``path``), or None. `run` steps the SPH
    alone: nothing drives its open ends, so they hold still water. A scene whose file drives them
    (a `[source]` or `mode = "coupled"`) would silently simulate still water here, while the
    same file makes waves on a server (the driving code is the server's, through its coupling
    door: server/theory_client.py)."""
    if not scene.open_boundaries:
        return None
    run = split_scene_file(tomllib.loads(path.read_text()))[1]
    if "source" in run:
        return (f"{path} drives its open boundaries with a [source], which `wavesph run` does not "
                f"do (it would simulate still water): start `wavesph serve`, then `wavesph submit "
                f"{path}`")
    if run.get("mode") == "coupled":
        return (f"{path} is a coupled scene (mode = \"coupled\"): its open boundaries wait for a "
                f"wave model, which `wavesph run` has not: start `wavesph serve`, then `wavesph "
                f"couple --scene {path} --model ...`")
    return None


def _preview(sim: Simulation, out: Path) -> int:
    """Initial particles and geometry as VTK, no time step (meta.json status "preview")."""
    from sph_core.output import write_geometry_vtk

    sim.write_snapshot()
    geometry = write_geometry_vtk(sim.scene, out / "geometry")
    sim.close()
    sim.writer.update_meta(status="preview")   # after close, which writes the run's own status
    print(f"preview (no time step taken): particles in {out / 'snapshots'}, outlines in "
          f"{geometry}; open {out / 'run.pvd'} and {geometry.name} in ParaView", file=sys.stderr)
    return 0


def _warn_if_expensive(scene, height: float, period: float) -> None:
    """The plan's warning (wavesph.studies.planning.expense_warning) on stderr; the run goes on."""
    from wavesph.studies.planning import expense_warning

    try:
        msg = expense_warning(scene, height, period)
    except ValueError as exc:   # no still-water level, no sweep data: nothing to compare
        msg = None
        print(f"wavesph run: no plan comparison ({exc})", file=sys.stderr)
    if msg:
        print(f"wavesph run: warning: {msg}", file=sys.stderr)
