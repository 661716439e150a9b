"""Where a kdk step's time goes, stage by stage, on the standard 2D dam break (CPU).

Question: which stages of the CPU step are serial or poorly parallel? Runs the stages of
``step._step_kdk`` (closed tank, WCSPH, no shifting: the dam break's step) one by one from
Python on a live Simulation, timing each, for ``--steps`` steps after the jitted run's warm-up;
compares their sum with the jitted ``step.run`` over as many steps (``step_ms``: the gap is the
per-call dispatch of the Python loop, ~10-20 us a stage). Also the load balance of each parallel
stage at ``--model-threads`` threads, as numba's static schedule splits its loop (the slots, or
the kind-balanced ranges of neighbours.kind_ranges): the work of the busiest thread over the
mean, counted in particles of the kind the stage works on; ``model_efficiency`` = Amdahl with
the serial stages and that imbalance (vs 1 thread), the best the step can scale to there
(memory bandwidth and the parallel loops' launches not counted).

Output: one JSON object per line: one per stage (``stage``, ``ms``, ``share``, ``split``: serial,
even or ranges, ``imbalance_T``), then a summary (``threads``, ``particles``, ``stage_sum_ms``,
``step_ms``, ``serial_share``, ``model_efficiency``).

    NUMBA_NUM_THREADS=1 python bench/step_stages.py [--dp 0.005] [--steps 30]
        [--model-threads 16] [--precision float64|float32]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # the repo, run from anywhere

# stage -> (how its loop is split: "serial", "even" (numba's static schedule over the slots),
# "ranges" (over neighbours.kind_ranges of the kind), the kind of particle whose count measures
# its work (None: every slot)
STAGES = {
    "kick_drift": ("even", "fluid"),
    "compute_cells": ("even", None),
    "counting_sort": ("even", None),      # serial below neighbours' size for the chunked sort
    "permute": ("even", None),
    "wall_pass": ("ranges", "wall"),
    "fluid_pass": ("ranges", "fluid"),
    "kick": ("even", "fluid"),
    "stable_dt": ("serial", None),
}


def _static(iters: int, threads: int) -> np.ndarray:
    """First iteration of each thread under numba's static schedule (equal shares)."""
    return np.linspace(0, iters, threads + 1).round().astype(int)


def _imbalance(kind: np.ndarray, how: str, which: str | None, threads: int) -> float:
    """Work of the busiest of ``threads`` threads over the mean, in particles of kind ``which``."""
    from sph_core.neighbours import PASS_RANGES, kind_ranges
    from sph_core.particles import FLUID, WALL
    if threads <= 1 or how == "serial":
        return 1.0
    k = FLUID if which == "fluid" else WALL
    w = np.ones(kind.size) if which is None else (kind == k).astype(float)
    if how == "ranges":
        edges = kind_ranges(kind, kind.size, k, PASS_RANGES)[_static(PASS_RANGES, threads)]
    else:
        edges = _static(kind.size, threads)
    per = np.array([w[a:b].sum() for a, b in zip(edges[:-1], edges[1:])])
    return float(per.max() / per.mean()) if per.mean() > 0 else 1.0


def profile(dp: float, steps: int, model_threads: int, precision: str = "float64") -> list[dict]:
    import numba

    from sph_core import neighbours, step, wcsph
    from sph_core.particles import N_SORTED_KDK
    from sph_core.simulation import Simulation
    from wavesph.cases.dambreak import dambreak_scene

    sim = Simulation(dambreak_scene(a=1.0, dp=dp, t_end=1.0, precision=precision))
    sim.advance_steps(20)                 # compiled, memory touched
    t0 = time.perf_counter()
    sim.advance_steps(steps)
    step_ms = 1e3 * (time.perf_counter() - t0) / steps

    pset, cells, prm = sim.particles, sim.cells, sim.prm
    ps, ps2 = pset.view, pset.view2
    n, dt = pset.n, sim.dt
    tot = dict.fromkeys(STAGES, 0.0)

    def clock(name: str, fn, *args):
        t = time.perf_counter()
        r = fn(*args)
        tot[name] += time.perf_counter() - t
        return r

    for it in range(steps + 1):
        if it == 1:                       # the first loop step warms the Python calls
            tot = dict.fromkeys(STAGES, 0.0)
        clock("kick_drift", wcsph.kdk_kick_drift, ps, n, dt, prm)
        clock("compute_cells", neighbours.compute_cells, ps, n, cells)
        clock("counting_sort", neighbours.counting_sort, ps.cell, n, cells)
        clock("permute", neighbours.permute, ps, ps2, N_SORTED_KDK, cells.order, n)
        n = int(cells.start[cells.ncx * cells.ncy * cells.ncz])
        ps, ps2 = ps2, ps
        clock("wall_pass", wcsph.wall_pass, ps, n, cells, prm)
        clock("fluid_pass", wcsph.fluid_pass, ps, n, cells, prm, None)
        _, _, v2, a2, rmax = clock("kick", wcsph.kdk_kick, ps, n, dt, prm)
        dt = clock("stable_dt", step.stable_dt, v2, a2, rmax, prm)
    kind = np.asarray(ps.kind[:n])
    total = sum(tot.values())
    from sph_core.neighbours import SORT_CHUNKS
    stages = dict(STAGES)
    if n < 512 * SORT_CHUNKS:
        stages["counting_sort"] = ("serial", None)
    out, serial, model = [], 0.0, 0.0
    for name, (how, which) in stages.items():
        share = tot[name] / total
        imb = _imbalance(kind, how, which, model_threads)
        serial += share if how == "serial" else 0.0
        # a serial stage takes its whole time at any thread count; a prange one 1/T of it,
        # times the busiest thread's excess
        model += share if how == "serial" else share * imb / model_threads
        out.append({"bench": "step_stages", "stage": name, "ms": round(1e3 * tot[name] / steps, 3),
                    "share": round(share, 4), "split": how,
                    f"imbalance_{model_threads}": round(imb, 3)})
    out.append({"bench": "step_stages", "dp": dp, "precision": precision, "particles": n,
                "steps": steps,
                "threads": numba.get_num_threads(), "threading_layer": numba.threading_layer(),
                "stage_sum_ms": round(1e3 * total / steps, 3), "step_ms": round(step_ms, 3),
                "serial_share": round(serial, 4), "model_threads": model_threads,
                "model_efficiency": round(1.0 / (model_threads * model), 3)})
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dp", type=float, default=0.005)
    ap.add_argument("--steps", type=int, default=30)
    ap.add_argument("--model-threads", type=int, default=16)
    ap.add_argument("--precision", choices=["float64", "float32"], default="float64",
                    help="storage of the particle fields")
    args = ap.parse_args()
    for row in profile(args.dp, args.steps, args.model_threads, args.precision):
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
