"""`wavesph waves SCENE.toml`: run the Boussinesq far-field model alone, write gauge series to CSV."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", type=Path, help="TOML scene (grid, bathymetry, wave, sponge, gauges)")
    parser.add_argument("-o", "--out", dest="output", type=Path, default=None,
                        help="gauge CSV path, must not exist; its metadata goes to <stem>.meta.json "
                             "(default: output.csv of the scene)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def main(args: argparse.Namespace) -> int:
    from wave_client.boussinesq.standalone import run_wave_scene
    from wave_client.boussinesq.wave_scene import WaveSceneError, load_wave_scene
    from wave_client.boussinesq.solver import BoussinesqUnstableError

    try:
        scene = load_wave_scene(args.scene)
        csv_path = args.output or Path(scene.output.csv)
        for p in (csv_path, csv_path.with_suffix(".meta.json")):
            if p.exists():
                print(f"wavesph waves: {p} exists: choose a new --out (a run never overwrites "
                      "another's data)", file=sys.stderr)
                return 2
        summary = run_wave_scene(scene, csv_path, base_dir=args.scene.parent, progress=not args.no_progress)
    except (WaveSceneError, ValueError) as exc:
        print(f"wavesph waves: {exc}", file=sys.stderr)
        return 2
    except BoussinesqUnstableError as exc:
        print(f"wavesph waves: {exc}; rows so far are in the CSV", file=sys.stderr)
        return 1
    print(f"wrote {csv_path}: {int(summary['steps'])} steps of {summary['dt']:.4g} s on "
          f"{int(summary['nodes'])} nodes in {summary['wall_s']:.2f} s "
          f"({summary['point_updates_per_s']:.3g} point-updates/s, "
          f"{summary['mean_iterations']:.2f} corrector iterations/step)")
    return 0
