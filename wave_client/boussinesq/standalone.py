"""Run a `wavesph waves` scene alone and write the gauge elevation series to CSV.

The CSV is the README's dialect: one header row `t,<gauge columns>` (t [s], each gauge's
elevation eta [m] above still water), one row per sample, no comment lines; rows are flushed as
the run goes, so an interrupted run keeps what it computed. What the run was (model, gauges,
grid, how it ended) is in `<stem>.meta.json` beside it.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
from tqdm import tqdm

from wave_client.progress_bars import TQDM_INTERVAL

from .wave_scene import WaveScene, build_model
from .solver import BoussinesqUnstableError


def run_wave_scene(scene: WaveScene, csv_path: Path, base_dir: Path | None = None,
              progress: bool = True) -> dict[str, float]:
    """Run the scene to grid.t_end; returns a summary (steps, wall time, corrector statistics).

    Raises BoussinesqUnstableError (after the rows so far are written) if the run blows up.
    """
    model = build_model(scene, base_dir)
    xs = np.asarray(scene.gauges.x, float)
    every = scene.output.every or model.dt
    stride = max(1, int(round(every / model.dt)))
    n_total = int(round(scene.grid.t_end / model.dt))
    csv_path.parent.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    meta = {"model": "wavesph waves: Nwogu extended Boussinesq (z_alpha = -0.531 h), 1D",
            "columns": {"t": "time [s]", **{c: f"surface elevation eta [m] above still water at x = {x:g} m"
                                            for c, x in zip(scene.gauges.columns(), xs)}},
            "grid": {"x0": model.x0, "x1": model.x1, "dx": model.dx, "dt": model.dt,
                     "nodes": model.n_nodes},
            "status": "running"}
    meta_path = csv_path.with_suffix(".meta.json")
    meta_path.write_text(json.dumps(meta, indent=1))
    with open(csv_path, "w", encoding="utf-8") as out, \
            tqdm(total=n_total, disable=not progress, unit="step", desc="waves",
                 mininterval=TQDM_INTERVAL) as bar:
        out.write("t," + ",".join(scene.gauges.columns()) + "\n")

        def write_row() -> None:
            out.write(f"{model.t:.12g}," + ",".join(f"{v:.8e}" for v in model.elevation(xs)) + "\n")

        write_row()
        done = 0
        try:
            while done < n_total:
                block = min(stride * max(1, 1000 // stride), n_total - done)
                for _ in range(block // stride):
                    model.advance_steps(stride)
                    write_row()
                rest = block % stride
                model.advance_steps(rest)
                done += block
                bar.update(block)
                out.flush()
        except BoussinesqUnstableError:
            meta["status"] = f"unstable at t = {model.t:.6g} s"
            meta_path.write_text(json.dumps(meta, indent=1))
            raise
    meta["status"] = "completed"
    meta_path.write_text(json.dumps(meta, indent=1))
    wall = time.perf_counter() - t0
    stats = model.corrector_stats
    return {"steps": float(n_total), "nodes": float(model.n_nodes), "dt": model.dt, "wall_s": wall,
            "point_updates_per_s": model.n_nodes * n_total / max(wall, 1e-12), **stats}
