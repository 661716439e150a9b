"""wavesph for scripts and notebooks: scenes in, gauge tables out.

    import wavesph
    scene = wavesph.load_scene("examples/scenes/dambreak.toml")
    sim = wavesph.run_scene(scene, "runs/dambreak")        # as `wavesph run`
    df = wavesph.read_gauges("runs/dambreak/probes.csv")    # any wavesph gauge CSV
    res = wavesph.analyse("runs/flume", t_from=3.0)        # Hm0, Tp, H1/3, Hmax; q; load peaks

Subpackages: ``wavesph.cli`` (the `wavesph` command), ``wavesph.cases`` (named scenes and their
references), ``wavesph.studies`` (sweeps over many runs on dask: accuracy, stability, `wavesph
plan`), ``wavesph.analysis`` (gauge post-processing), ``wavesph.local_server`` (the server in a
thread of this process). This module imports nothing heavy: the solver (and numba) loads on the
first call that needs it, so `wavesph couple` never loads it.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import pandas

    from sph_core.scene import Scene
    from sph_core.simulation import Simulation

__all__ = ["analyse", "load_scene", "read_gauges", "run_scene"]


def load_scene(path: str | Path) -> "Scene":
    """A TOML scene file as a validated Scene (``sph_core.scene.SceneError`` names the field)."""
    from sph_core.scene import load_scene as _load_scene

    return _load_scene(path)


def run_scene(scene: "Scene", out_dir: str | Path, progress: bool = True) -> "Simulation":
    """Run ``scene`` from t_start to t_end standalone, outputs (probes.csv, snapshots, meta.json)
    in ``out_dir``, as `wavesph run` does; the closed Simulation comes back, its ``status``
    "completed" or "unstable" (the cause on stderr). ``progress``: a bar or lines on stderr."""
    from sph_core.progress import advance_with_progress
    from sph_core.simulation import Simulation

    sim = Simulation(scene, run_dir=out_dir)
    advance_with_progress(sim, scene.t_end, scene.name, show=progress)
    return sim


def read_gauges(path: str | Path) -> "pandas.DataFrame":
    """Any wavesph gauge CSV (probes.csv, the server's gauges.csv, a coupling client's log,
    `wavesph waves` output) as a pandas DataFrame: one column per CSV column (units in the
    README's Outputs table), a dry gauge NaN."""
    import pandas

    from sph_core.output import load_gauges

    return pandas.DataFrame(load_gauges(path))


def analyse(run_dir: str | Path, t_from: float | None = None,
            period: float | None = None) -> dict:
    """A run directory's gauges analysed (as `wavesph analyse`): per elevation gauge Hm0, Tp,
    H1/3, Hmax, Tm; per overtopping probe the mean discharge q [m^2/s]; per force and
    pressure-line column the peaks (per wave ``period`` too). ``wavesph.analysis.analyse_run``;
    the single-record functions are there too (wave_statistics, mean_overtopping, peaks)."""
    from .analysis import analyse_run

    return analyse_run(run_dir, t_from, period)
