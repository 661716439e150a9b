"""SPH step throughput on the GPU (sph_core/cuda) and the CPU, on the standard 2D dam break.

Case: as bench/sph_throughput.py: water column 1 m x 2 m at the left wall of a 4 m tank, h/dp 2,
kdk; particles counts all active particles (fluid + wall). dp 0.01 / 0.0025 / 0.00125 m give
~25.6k / ~340k / ~1.4M particles.

Output: one JSON object per line (also appended to --out if given):
    device, particles, particle_steps_per_s, wall_s_per_sim_s, ms_per_step, launches_per_step
and for the GPU the per-kernel milliseconds of one step (CUDA events) and the build times.

    python bench/gpu_throughput.py --device cuda --dps 0.01 0.0025 0.00125
    NUMBA_NUM_THREADS=16 python bench/gpu_throughput.py --device cpu --dps 0.005
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # the repo, run from anywhere


def _scene(dp: float):
    from wavesph.cases.dambreak import dambreak_scene
    return dambreak_scene(a=1.0, dp=dp, t_end=1.0)


def _steps_for(n: int, budget: float, guess: float) -> int:
    """Steps that take about ``budget`` seconds at ``guess`` particle-steps/s (20..5000)."""
    return int(min(5000, max(20, budget * guess / n)))


def run_cuda(dp: float, budget: float, modes: list[bool]) -> list[dict]:
    """One Simulation and CudaStepper per size, timed with plain launches and/or graphs."""
    import numba

    from sph_core.cuda.cuda_stepper import LAUNCHES_PER_STEP, CudaStepper
    from sph_core.simulation import Simulation

    t0 = time.perf_counter()
    sim = Simulation(_scene(dp))
    t_build = time.perf_counter() - t0
    t0 = time.perf_counter()
    st = CudaStepper(sim)
    st.advance_steps(10)                  # compiles on first use; touches every buffer
    st.synchronize()
    t_warm = time.perf_counter() - t0
    n = sim.n_particles
    kt = st.kernel_times(5)
    out = []
    for graphs in modes:
        if graphs and not st.enable_graphs():
            out.append({"bench": "gpu_throughput", "dp": dp, "graphs": True,
                        "error": st.graph_error})
            continue
        # a short timed run, then one sized to the budget from its rate
        t0 = time.perf_counter()
        st.advance_steps(20)
        st.synchronize()
        rate = n * 20 / (time.perf_counter() - t0)
        steps = _steps_for(n, budget, rate)
        ts, s0 = st.t, st.steps
        t0 = time.perf_counter()
        st.advance_steps(steps)
        st.synchronize()
        wall = time.perf_counter() - t0
        done = st.steps - s0
        out.append({
            "bench": "gpu_throughput", "case": "dambreak_2d_1x2m_tank4m", "device": _gpu_name(),
            "graphs": graphs, "batch": st.batch, "dp": dp, "particles": n,
            "fluid_particles": sim.n_fluid, "steps": done, "wall_s": round(wall, 4),
            "particle_steps_per_s": round(n * done / wall),
            "wall_s_per_sim_s": round(wall / (st.t - ts), 3) if st.t > ts else None,
            "ms_per_step": round(1e3 * wall / done, 4),
            # host calls per step: the kernels' launches, or one graph replay per two steps
            "launches_per_step": 0.5 if graphs else LAUNCHES_PER_STEP,
            "kernels_per_step": LAUNCHES_PER_STEP,
            "kernel_ms": kt, "kernel_ms_sum": round(sum(kt.values()), 4),
            "build_s": round(t_build, 2), "compile_and_warm_s": round(t_warm, 2),
            "simulated_t_s": round(st.t, 5), "dt_s": st.dt, "numba": numba.__version__,
            "host_threads": numba.get_num_threads()})
    return out


def run_cpu(dp: float, budget: float) -> dict:
    import platform

    import numba

    from sph_core.simulation import Simulation

    sim = Simulation(_scene(dp))
    sim.advance_steps(10)                 # compiled already (cache) or now; touches memory
    n = sim.n_particles
    t0 = time.perf_counter()
    sim.advance_steps(10)
    rate = n * 10 / (time.perf_counter() - t0)
    steps = _steps_for(n, budget, rate)
    ts, s0 = sim.t, sim.steps
    t0 = time.perf_counter()
    sim.advance_steps(steps)
    wall = time.perf_counter() - t0
    done = sim.steps - s0
    return {"bench": "gpu_throughput", "case": "dambreak_2d_1x2m_tank4m",
            "device": f"cpu {platform.machine()} x{numba.get_num_threads()}",
            "threads": numba.get_num_threads(), "threading_layer": numba.threading_layer(),
            "dp": dp, "particles": n, "fluid_particles": sim.n_fluid, "steps": done,
            "wall_s": round(wall, 4), "particle_steps_per_s": round(n * done / wall),
            "wall_s_per_sim_s": round(wall / (sim.t - ts), 3) if sim.t > ts else None,
            "ms_per_step": round(1e3 * wall / done, 4), "launches_per_step": None,
            "cpu_count": os.cpu_count()}


def _gpu_name() -> str:
    from sph_core.cuda import simulated
    if simulated():
        return "cuda simulator"
    from numba import cuda
    name = cuda.get_current_device().name
    return "cuda " + (name.decode() if isinstance(name, bytes) else str(name))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--device", choices=["cuda", "cpu"], default="cuda")
    ap.add_argument("--dps", type=float, nargs="+", default=[0.01, 0.0025, 0.00125])
    ap.add_argument("--budget", type=float, default=8.0, help="seconds of timed stepping per size")
    ap.add_argument("--graphs", choices=["off", "on", "both"], default="both",
                    help="cuda: replay two-step CUDA graphs (on), plain launches (off) or both")
    ap.add_argument("--out", type=Path, default=None, help="append the JSON lines here too")
    args = ap.parse_args()
    modes = {"off": [False], "on": [True], "both": [False, True]}[args.graphs]
    for dp in args.dps:
        print(f"# {args.device} dp={dp} ...", file=sys.stderr, flush=True)
        for res in (run_cuda(dp, args.budget, modes) if args.device == "cuda"
                    else [run_cpu(dp, args.budget)]):
            line = json.dumps(res)
            print(line, flush=True)
            if args.out:
                with open(args.out, "a") as fh:
                    fh.write(line + "\n")


if __name__ == "__main__":
    main()
