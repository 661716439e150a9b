"""`wavesph run SCENE.toml`: run an SPH scene standalone with a progress bar."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from sph_core.progress import advance_with_progress
from sph_core.scene import SceneError, load_scene
from sph_core.simulation import Simulation


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", type=Path, help="scene file (TOML)")
    parser.add_argument("--out", type=Path, default=None,
                        help="run directory (default: runs/<scene name>-<UTC time>)")
    parser.add_argument("--t-end", type=float, default=None, help="override the scene's end time [s]")
    parser.add_argument("--wave", type=float, nargs=2, metavar=("H", "T"), default=None,
                        help="the waves the scene is for (height [m], period [s]): warn if the "
                             "scene costs far more than `wavesph plan`'s for the same accuracy")


def main(args: argparse.Namespace) -> int:
    try:
        scene = load_scene(args.scene)
    except SceneError as exc:
        print(f"wavesph run: {exc}", file=sys.stderr)
        return 2
    if args.t_end is not None:
        if not args.t_end > 0:
            print("wavesph run: --t-end must be > 0", file=sys.stderr)
            return 2
        scene = scene.model_copy(update={"t_end": args.t_end})   # meta.json records the real end
    if args.wave is not None:
        _warn_if_expensive(scene, *args.wave)
    t_end = scene.t_end
    out = args.out or Path("runs") / f"{scene.name}-{time.strftime('%Y%m%dT%H%M%SZ', time.gmtime())}"
    print(f"building particles for '{scene.name}' (dp = {scene.dp} m) ...", file=sys.stderr)
    sim = Simulation(scene, run_dir=out)
    print(f"{sim.n_fluid} fluid + {sim.n_particles - sim.n_fluid} wall particles, c0 = {sim.c0:.2f} m/s, "
          f"h = {sim.h:.4g} m; output in {out}", file=sys.stderr)
    code = advance_with_progress(sim, t_end, scene.name)
    if code == 0:
        print(f"done: {sim.steps} steps in {sim.wall_time:.1f} s "
              f"({sim.n_particles * sim.steps / max(sim.wall_time, 1e-9) / 1e6:.2f} M particle-steps/s); "
              f"results in {out}", file=sys.stderr)
    return code



def _warn_if_expensive(scene, height: float, period: float) -> None:
    """The plan's warning (cases.planning.expense_warning) on stderr; the run goes on."""
    from cases.planning import expense_warning

    try:
        msg = expense_warning(scene, height, period)
    except ValueError as exc:   # no still-water level, no sweep data: nothing to compare
        msg = None
        print(f"wavesph run: no plan comparison ({exc})", file=sys.stderr)
    if msg:
        print(f"wavesph run: warning: {msg}", file=sys.stderr)
