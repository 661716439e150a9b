"""`wavesph demo --dambreak`: a standalone dam break (Martin & Moyce geometry) with a progress bar
and a plot. It runs the dam break, writes the usual run directory (probes.csv, meta.json, VTK snapshots) and a figure comparing the surge front
with Martin & Moyce (1952) and a snapshot of the particles.
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

from sph_core.particles import FLUID, VX, VZ, X, Z
from sph_core.progress import advance_with_progress
from sph_core.simulation import DeviceError, Simulation

from .dambreak import dambreak_scene, front_errors, martin_moyce_table


DAMBREAK_A = 0.1  # column width [m] of the demo (height 2a)


def run_dambreak_demo(out: Path | None = None, a: float = DAMBREAK_A, resolution: int = 40,
                      T_end: float = 3.3, make_plot: bool = True, device: str | None = None) -> int:
    """Run the dam break of column width ``a`` [m] (height 2a) at ``resolution`` particles
    across it to ``T_end`` in Martin & Moyce units T = t sqrt(2g/a); outputs in ``out`` (default
    runs/demo-<UTC time>), with the figure dambreak.png, the steps on ``device`` ("cpu" or
    "cuda"; default cpu). Returns a process exit code."""
    if a <= 0 or resolution < 4 or T_end <= 0:
        raise ValueError("dam-break demo: a must be > 0, resolution >= 4, T_end > 0")
    t_end = T_end / math.sqrt(2 * 9.81 / a)
    scene = dambreak_scene(a=a, dp=a / resolution, t_end=t_end, tank_length=5 * a,
                           snapshot_every=t_end / 10)
    out = out or Path("runs") / f"demo-{time.strftime('%Y%m%dT%H%M%SZ', time.gmtime())}"
    try:
        sim = Simulation(scene, run_dir=out, device=device)
    except DeviceError as exc:   # one line, before the run directory is written
        print(f"wavesph demo: {exc}", file=sys.stderr)
        return 2
    print(f"dam break: column {a:g} m x {2 * a:g} m, {sim.n_fluid} fluid particles, "
          f"c0 = {sim.c0:.1f} m/s; output in {out}", file=sys.stderr)
    code = advance_with_progress(sim, t_end, "dam break")
    t = np.array([r["t"] for r in sim.history])
    xf = np.array([np.nan if r["front_x"] is None else r["front_x"] for r in sim.history])
    ok = np.isfinite(xf)
    if ok.sum() >= 2 and t[ok].max() * math.sqrt(2 * 9.81 / a) > 0.41:
        err = front_errors(t[ok], xf[ok], a)
        print(f"front vs Martin & Moyce (T <= 3): max error {100 * err['max_rel_error']:.1f} %, "
              f"rms {100 * err['rms_rel_error']:.1f} %", file=sys.stderr)
    if make_plot and ok.any():
        path = plot_dambreak(sim, t[ok], xf[ok], a, out / "dambreak.png")
        print(f"figure: {path}", file=sys.stderr)
    return code


def plot_dambreak(sim: Simulation, t: np.ndarray, xf: np.ndarray, a: float, path: Path) -> Path:
    """Front Z(T) against Martin & Moyce, and the particles at the last time coloured by speed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    T_ref, Z_ref = martin_moyce_table()
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.5), gridspec_kw={"width_ratios": [1, 1.6]})
    ax1.plot(t * math.sqrt(2 * 9.81 / a), xf / a, "-", label=f"wavesph, a/dp = {a / sim.scene.dp:.0f}")
    ax1.plot(T_ref, Z_ref, "ko", mfc="none", label="Martin & Moyce (1952)")
    ax1.set(xlabel="T = t sqrt(2g/a)", ylabel="Z = x_front / a", title="surge front")
    ax1.legend()
    ax1.grid(alpha=0.3)
    ps = sim.particles
    kind = ps.kind[: ps.n]
    x, z = ps.field(X), ps.field(Z)
    speed = np.hypot(ps.field(VX), ps.field(VZ))
    fl = kind == FLUID
    ax2.scatter(x[~fl & (kind >= 0)], z[~fl & (kind >= 0)], s=1, c="0.6")
    sc = ax2.scatter(x[fl], z[fl], s=2, c=speed[fl], cmap="viridis")
    fig.colorbar(sc, ax=ax2, label="speed [m/s]")
    ax2.set(xlabel="x [m]", ylabel="z [m]", title=f"t = {sim.t:.3f} s", aspect="equal")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path

