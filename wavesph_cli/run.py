"""`wavesph run SCENE.toml`: run an SPH scene standalone with a progress bar."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from tqdm import tqdm

from .scene import SceneError, load_scene
from .simulation import Simulation, UnstableError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", type=Path, help="scene file (TOML)")
    parser.add_argument("--out", type=Path, default=None,
                        help="run directory (default: runs/<scene name>-<UTC time>)")
    parser.add_argument("--t-end", type=float, default=None, help="override the scene's end time [s]")


def progress_bar(t_end: float, desc: str) -> tuple[tqdm, "callable"]:
    """A tqdm bar over simulated time showing steps/s; returns (bar, callback for advance_to)."""
    bar = tqdm(total=t_end, desc=desc, unit="s(sim)", bar_format=(
        "{desc}: {percentage:3.0f}%|{bar}| t={n:.3f}/{total:.3f} s [{elapsed}<{remaining}{postfix}]"))

    def update(sim: Simulation) -> None:
        bar.n = min(sim.t, t_end)
        rate = sim.steps / sim.wall_time if sim.wall_time > 0 else 0.0
        bar.set_postfix_str(f"{rate:,.0f} steps/s, step {sim.steps}", refresh=False)
        bar.refresh()

    return bar, update


def run_scene(sim: Simulation, t_end: float, desc: str) -> int:
    """Advance with a progress bar; report the outcome. Returns a process exit code."""
    bar, update = progress_bar(t_end, desc)
    try:
        sim.advance_to(t_end, progress=update)
    except UnstableError as exc:
        bar.close()
        print(f"run stopped, status unstable: {exc}", file=sys.stderr)
        return 3
    finally:
        bar.close()
        sim.close()
    return 0


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
    t_end = scene.t_end
    out = args.out or Path("runs") / f"{scene.name}-{time.strftime('%Y%m%dT%H%M%SZ', time.gmtime())}"
    print(f"building particles for '{scene.name}' (dp = {scene.dp} m) ...", file=sys.stderr)
    sim = Simulation(scene, run_dir=out)
    print(f"{sim.n_fluid} fluid + {sim.n_particles - sim.n_fluid} wall particles, c0 = {sim.c0:.2f} m/s, "
          f"h = {sim.h:.4g} m; output in {out}", file=sys.stderr)
    code = run_scene(sim, t_end, scene.name)
    if code == 0:
        print(f"done: {sim.steps} steps in {sim.wall_time:.1f} s "
              f"({sim.n_particles * sim.steps / max(sim.wall_time, 1e-9) / 1e6:.2f} M particle-steps/s); "
              f"results in {out}", file=sys.stderr)
    return code


if __name__ == "__main__":  # python -m sph_core.cli SCENE.toml
    _parser = argparse.ArgumentParser(prog="python -m sph_core.cli", description=__doc__.splitlines()[0])
    add_arguments(_parser)
    raise SystemExit(main(_parser.parse_args()))
