"""SPH throughput on the standard 2D dam break (DualSPHysics / PySPH reference case), or in 3D.

Question: how many particle-steps per second does the WCSPH core sustain on this machine, and
where does the time go (neighbour search vs interactions vs integration)?

Case: water column 1 m x 2 m at the left wall of a 4 m tank, dp = 0.01 m (20,000 fluid particles)
and the 4x larger dp = 0.005 m variant. Each size runs a fixed number of steps after a short
warm-up; particles counts all active particles (fluid + wall), as the DualSPHysics and PySPH
anchors do. Also measures the one-off numba compile time, cold (empty cache) and cached.

Output: one JSON object per line.
    python bench/sph_throughput.py [--steps 400] [--dps 0.01 0.005] [--integrator kdk]
        [--cells-per-support 2] [--diagnostics] [--threads 1 2 4 8 16]

``--dim 3``: the 3D dam break of the MARIN tank without its box (wavesph.cases.marin_dambreak:
a 1.228 x 1 x 0.55 m column in a 3.22 x 1 x 1 m tank, the case of PySPH's dam_break_3d), h/dp
1.5, at dp 0.04 and 0.02 m by default; the same fields plus ``dim``.
    python bench/sph_throughput.py --dim 3 [--dps 0.04 0.02]

``--device cuda``: the same case stepped on the GPU through ``Simulation(device="cuda")``
(sph_core/cuda), timed with plain kernel launches and/or two-step CUDA graph replays
(``--graphs``), each for about ``--budget`` seconds: one line per size and mode with device,
gpu, particles, particle_steps_per_s, wall_s_per_sim_s, ms_per_step, launches_per_step (host
calls per step) and the per-kernel milliseconds of one step (CUDA events). dp 0.01 / 0.0025 /
0.00125 m give ~25.6k / ~340k / ~1.4M particles.
    python bench/sph_throughput.py --device cuda --dps 0.01 0.0025 0.00125 [--graphs both]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

COMPILE_PROBE = """
import time
t0 = time.perf_counter()
from wavesph.cases.dambreak import dambreak_scene
from sph_core.simulation import Simulation
sim = Simulation(dambreak_scene(a=0.05, dp=0.005, t_end=0.01, integrator="{integrator}"))
sim.advance_to(0.002)
sim.probe_values()
print(time.perf_counter() - t0)
"""


def compile_times(integrator: str) -> dict:
    """Import + build + first steps in a fresh interpreter, with an empty and a warm numba cache."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        out = []
        for _ in range(2):
            res = subprocess.run([sys.executable, "-c", COMPILE_PROBE.format(integrator=integrator)],
                                 env=env, capture_output=True, text=True, check=True)
            out.append(float(res.stdout.strip().splitlines()[-1]))
    return {"bench": "numba_compile", "integrator": integrator, "compile_cold_s": round(out[0], 2),
            "compile_cached_s": round(out[1], 2)}


def time_components(sim, repeats: int) -> dict:
    """Seconds per call of each phase of a step, timed on the current state."""
    from sph_core import wcsph
    from sph_core.neighbours import sort_by_cell
    from sph_core.particles import N_SORTED_KDK

    ps, cells, prm = sim.particles, sim.cells, sim.prm

    def clock(fn) -> float:
        fn()
        t0 = time.perf_counter()
        for _ in range(repeats):
            fn()
        return (time.perf_counter() - t0) / repeats

    # sorting an already sorted set costs the same as a real step's sort (O(N) counting sort);
    # the twin receives the copy and the live state stays as it is
    t_sort = clock(lambda: sort_by_cell(ps.view, ps.view2, N_SORTED_KDK, ps.n, cells))
    t_wall = clock(lambda: wcsph.wall_pass(ps.view, ps.n, cells, prm))
    t_fluid = clock(lambda: wcsph.fluid_pass(ps.view, ps.n, cells, prm, None))
    t_kick = clock(lambda: wcsph.kdk_kick(ps.view, ps.n, 0.0, prm))
    return {"sort": t_sort, "wall": t_wall, "fluid": t_fluid, "kick": t_kick}


def run_size(dp: float, steps: int, integrator: str, diagnostics: bool,
             cells_per_support: int | None, dim: int = 2) -> dict:
    import numba

    from wavesph.cases.dambreak import dambreak_scene
    from wavesph.cases.marin_dambreak import marin_scene
    from sph_core.simulation import Simulation

    if dim == 3:
        scene = marin_scene(dp=dp, t_end=1.0, box=False, integrator=integrator)
    else:
        scene = dambreak_scene(a=1.0, dp=dp, t_end=1.0, integrator=integrator)
    sim = Simulation(scene, **({"cells_per_support": cells_per_support} if cells_per_support else {}))
    sim.advance_steps(20)                     # warm-up (compiled already, touches memory)
    sim.wall_time = 0.0
    s0 = sim.steps
    t0, c0 = time.perf_counter(), time.process_time()
    sim.advance_steps(steps)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    n = sim.n_particles
    parts = time_components(sim, repeats=20)
    kick_calls = 2 if integrator == "kdk" else 2   # kdk: drift+kick; pc: predict+correct
    per_step = {
        "neighbour_search": parts["sort"] * (1 if integrator == "kdk" else 1),
        "interactions": (parts["wall"] + parts["fluid"]) * sim.passes_per_step,
        "integration": parts["kick"] * kick_calls,
    }
    total = sum(per_step.values())
    out = {
        "bench": "sph_throughput", "dim": dim,
        "case": "dambreak_3d_marin_tank" if dim == 3 else "dambreak_2d_1x2m_tank4m", "dp": dp,
        "h_over_dp": round(sim.h / dp, 3),
        "integrator": integrator, "neighbours": "cell_lists",
        "cell_side_over_h": round(sim.grid.cs / sim.h, 3), "particles": n, "fluid_particles": sim.n_fluid,
        "steps": sim.steps - s0, "passes_per_step": sim.passes_per_step,
        "wall_s": round(wall, 3), "cpu_s": round(cpu, 3),
        "particle_steps_per_s": round(n * (sim.steps - s0) / wall),
        "particle_passes_per_s": round(n * (sim.steps - s0) * sim.passes_per_step / wall),
        "threads": numba.get_num_threads(), "threading_layer": numba.threading_layer(),
        "share_neighbour_search": round(per_step["neighbour_search"] / total, 3),
        "share_interactions": round(per_step["interactions"] / total, 3),
        "share_integration": round(per_step["integration"] / total, 3),
        "ms_per_call": {k: round(1e3 * v, 3) for k, v in parts.items()},
        "simulated_t_s": round(sim.t, 5), "dt_s": sim.dt,
    }
    if diagnostics:
        from sph_core import wcsph
        wcsph.fluid_pass.parallel_diagnostics(level=1)
    return out


def _steps_for(n: int, budget: float, rate: float) -> int:
    """Steps that take about ``budget`` seconds at ``rate`` particle-steps/s (20..5000)."""
    return int(min(5000, max(20, budget * rate / n)))


def run_size_cuda(dp: float, budget: float, modes: list[bool]) -> list[dict]:
    """One Simulation on the GPU per size, timed with plain launches and/or graphs (``modes``:
    False plain, True graphs, in that order)."""
    import numba

    from sph_core.cuda.cuda_stepper import LAUNCHES_PER_STEP
    from sph_core.simulation import Simulation
    from wavesph.cases.dambreak import dambreak_scene

    t0 = time.perf_counter()
    sim = Simulation(dambreak_scene(a=1.0, dp=dp, t_end=1.0), device="cuda")
    t_build = time.perf_counter() - t0
    st = sim._gpu
    sim._gpu_graphs = False               # plain launches first; graphs when asked
    t0 = time.perf_counter()
    sim.advance_steps(10)                 # compiles on first use; touches every buffer
    t_warm = time.perf_counter() - t0
    n = sim.n_particles
    kt = st.kernel_times(5)               # 5 steps (the next call's copy-back follows them)
    out = []
    for graphs in modes:
        if graphs:
            sim._gpu_graphs = True
            sim.advance_steps(2)          # captures the graphs after this call
            if st._graph is None:
                out.append({"bench": "sph_throughput", "device": "cuda", "dp": dp,
                            "graphs": True, "error": st.graph_error})
                continue
        t0 = time.perf_counter()
        sim.advance_steps(20)             # a short timed run, then one sized to the budget
        steps = _steps_for(n, budget, n * 20 / (time.perf_counter() - t0))
        ts, s0 = sim.t, sim.steps
        t0 = time.perf_counter()
        sim.advance_steps(steps)          # ends with one copy of the state to the host
        wall = time.perf_counter() - t0
        done = sim.steps - s0
        out.append({
            "bench": "sph_throughput", "case": "dambreak_2d_1x2m_tank4m", "device": "cuda",
            "gpu": sim._gpu_name, "graphs": graphs, "batch": st.batch, "dp": dp,
            "particles": n, "fluid_particles": sim.n_fluid, "steps": done,
            "wall_s": round(wall, 4), "particle_steps_per_s": round(n * done / wall),
            "wall_s_per_sim_s": round(wall / (sim.t - ts), 3) if sim.t > ts else None,
            "ms_per_step": round(1e3 * wall / done, 4),
            # host calls per step: the kernels' launches, or one graph replay per two steps
            "launches_per_step": 0.5 if graphs else LAUNCHES_PER_STEP,
            "kernels_per_step": LAUNCHES_PER_STEP,
            "kernel_ms": kt, "kernel_ms_sum": round(sum(kt.values()), 4),
            "build_s": round(t_build, 2), "compile_and_warm_s": round(t_warm, 2),
            "simulated_t_s": round(sim.t, 5), "dt_s": sim.dt, "numba": numba.__version__,
            "host_threads": numba.get_num_threads()})
    return out


def run_threads(threads: list[int], argv: list[str]) -> None:
    """This bench at each thread count in a fresh process (NUMBA_NUM_THREADS is read at import),
    its lines printed as they come with ``efficiency_vs_2`` = (rate / rate at 2 threads) / (T / 2)
    (and ``efficiency_vs_1``); the 2-thread run goes first."""
    order = sorted(set(threads), key=lambda t: (t != 2, t))
    base: dict[tuple, dict] = {}
    for t in order:
        env = dict(os.environ, NUMBA_NUM_THREADS=str(t))
        res = subprocess.run([sys.executable, __file__, *argv, "--no-compile"], env=env,
                             capture_output=True, text=True)
        rows = [json.loads(line) for line in res.stdout.splitlines() if line.startswith("{")]
        if res.returncode != 0 or not rows:
            print(json.dumps({"bench": "sph_throughput", "threads": t, "error":
                              res.stderr.strip().splitlines()[-1:]}), flush=True)
            continue
        for row in rows:
            key = (row["dp"], row["integrator"])
            base.setdefault(key, {})[t] = row["particle_steps_per_s"]
            for ref in (1, 2):
                r = base[key].get(ref)
                row[f"efficiency_vs_{ref}"] = (round(row["particle_steps_per_s"] / r / (t / ref), 3)
                                               if r else None)
            print(json.dumps(row), flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=400)
    ap.add_argument("--dps", type=float, nargs="+", default=None,
                    help="particle spacings [m] (default 0.01 0.005; --dim 3: 0.04 0.02)")
    ap.add_argument("--dim", type=int, choices=[2, 3], default=2,
                    help="3: the 3D dam break (module docstring); cpu only")
    ap.add_argument("--integrator", choices=["kdk", "symplectic_pc"], default="kdk")
    ap.add_argument("--cells-per-support", type=int, default=None,
                    help="neighbour cells of side 2h / this (default: the Simulation's)")
    ap.add_argument("--diagnostics", action="store_true", help="print numba parallel diagnostics")
    ap.add_argument("--no-compile", action="store_true", help="skip the compile-time measurement")
    ap.add_argument("--device", choices=["cpu", "cuda"], default="cpu",
                    help="where the steps run (cuda: module docstring)")
    ap.add_argument("--budget", type=float, default=8.0,
                    help="cuda: seconds of timed stepping per size and mode")
    ap.add_argument("--graphs", choices=["off", "on", "both"], default="both",
                    help="cuda: plain launches (off), two-step CUDA graph replays (on), or both")
    ap.add_argument("--threads", type=int, nargs="+", default=None,
                    help="run at each of these numba thread counts, each in a fresh process")
    args = ap.parse_args()
    if args.dps is None:
        args.dps = [0.04, 0.02] if args.dim == 3 else [0.01, 0.005]
    if args.dim == 3 and (args.device == "cuda" or args.threads):
        ap.error("--dim 3 runs on the cpu, in this process (no --device cuda, no --threads)")
    if args.device == "cuda":
        modes = {"off": [False], "on": [True], "both": [False, True]}[args.graphs]
        for dp in args.dps:
            for res in run_size_cuda(dp, args.budget, modes):
                print(json.dumps(res), flush=True)
        return
    if args.threads:
        argv = ["--steps", str(args.steps), "--dps", *map(str, args.dps),
                "--integrator", args.integrator]
        if args.cells_per_support:
            argv += ["--cells-per-support", str(args.cells_per_support)]
        run_threads(args.threads, argv)
        return
    if not args.no_compile:
        print(json.dumps(compile_times(args.integrator)), flush=True)
    for dp in args.dps:
        print(json.dumps(run_size(dp, args.steps, args.integrator, args.diagnostics,
                                  args.cells_per_support, args.dim)), flush=True)


if __name__ == "__main__":
    main()
