"""The CUDA step (sph_core/cuda) against its CPU twins, kernel by kernel and over a short run.

Runs on a GPU when one is present, else under numba-cuda's simulator (set by cuda_support,
imported before numba.cuda: the CPU tests in the same session never import it). Skipped without
numba-cuda. The state is a tiny dam break (a = 0.05 m, dp = 0.01 m, a 0.1 m tank: 322 particles,
50 of them fluid) so that the simulator, which runs every CUDA thread as a Python thread (~2 s
per step here), stays within seconds.
"""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest
from cuda_support import (CUDA_TESTS, close, device_session, fluid_agrees, set_clock, short_run,
                          skip_without_device, stepper)

pytestmark = CUDA_TESTS

A, DP, WARM_STEPS = 0.05, 0.01, 15


def _dambreak(**kw):
    from wavesph.cases.dambreak import dambreak_scene
    return dambreak_scene(a=A, dp=DP, t_end=1.0, tank_length=2.0 * A, **kw)


@pytest.fixture(scope="module")
def sim_factory():
    """Fresh Simulations of the tiny dam break after WARM_STEPS CPU steps (moving fluid)."""
    with device_session():
        from sph_core.simulation import Simulation

        base = Simulation(_dambreak())
        base.advance_steps(WARM_STEPS)
        ck = base.checkpoint()

        def make():
            s = Simulation(_dambreak())
            s.restore(ck)
            return s
        yield make


def _host(st, a):
    return st._to_host(a)


def test_kick_drift_and_cell_sort_match_cpu(sim_factory):
    from sph_core import wcsph
    from sph_core.cuda import gpu_kernels as K
    from sph_core.neighbours import sort_by_cell
    from sph_core.particles import N_SORTED_KDK

    cpu = sim_factory()
    st = stepper(sim_factory())
    dt = cpu.dt
    ps, n = cpu.particles, cpu.particles.n
    n_out = wcsph.kdk_kick_drift(ps.view, n, dt, cpu.prm)
    n_sorted = sort_by_cell(ps.view, ps.view2, N_SORTED_KDK, n, cpu.cells)
    set_clock(st, dt)
    a, b = st.bufs[0], st.bufs[1]
    gn, tpb = st._grid_n, K.TPB
    K.k_kick_drift_bin[gn, tpb](a, n, st.prm, st.cells, st.count, st.clk, st.ctl)
    K.k_scan_blocks[st.nb, K.SCAN_B](st.count, st.start, st.bsum, st.m, st.ctl)
    K.k_scan_sums[1, K.SCAN_B](st.bsum, st.nb, st.ctl)
    K.k_scan_add[st.nb, K.SCAN_B](st.start, st.bsum, st.cursor, st.count, st.m, st.ctl)
    K.k_scatter[gn, tpb](a, n, st.cursor, st.order, st.ctl)
    K.k_cell_order[st._grid_c, tpb](st.start, st.order, st.ncell + 1, st.ctl)
    K.k_permute[gn, tpb](a, b, st.order, n, st.ctl)
    assert _host(st, st.ctl)[K.N_OUT] == n_out
    start = _host(st, st.start)
    np.testing.assert_array_equal(start, cpu.cells.start)
    assert start[st.ncell] == n_sorted
    np.testing.assert_array_equal(_host(st, st.order)[:n], cpu.cells.order[:n])
    np.testing.assert_array_equal(_host(st, st.count), 0)   # cleared for the next step
    np.testing.assert_array_equal(_host(st, b[1])[:n], ps.kind2[:n])
    np.testing.assert_array_equal(_host(st, b[2])[:n], ps.ids2[:n])
    np.testing.assert_array_equal(_host(st, b[3])[:n], ps.cell2[:n])
    f2 = _host(st, b[0])
    for r in range(N_SORTED_KDK):
        # a few ulp: the GPU fuses x + dt v into one rounding, and its pow differs from libm's
        # by an ulp, which p = B((rho/rho0)^7 - 1) amplifies near p = 0 to ~1e-14 of max |p|
        close(f2[r, :n], ps.f2[r, :n], rel=1e-13)


def test_wall_and_fluid_pass_match_cpu(sim_factory):
    from sph_core import wcsph
    from sph_core.cuda import gpu_kernels as K
    from sph_core.particles import AX, AZ, DRHO, DVNX, DVNZ, FLUID, P, PW, RHO, VWX, VWZ, WALL

    cpu = sim_factory()
    st = stepper(sim_factory())
    ps, n = cpu.particles, cpu.particles.n
    assert cpu.prm.wall_g0 > 0.0   # the no-penetration correction is exercised
    wcsph.wall_pass(ps.view, n, cpu.cells, cpu.prm)
    wcsph.fluid_pass(ps.view, n, cpu.cells, cpu.prm, None)   # None: the delta-SPH form
    set_clock(st)
    a = st.bufs[0]
    K.k_wall[st._grid_n, K.TPB](a, n, st.cells, st.prm, st.ctl)
    K.k_fluid[st._grid_n, K.TPB](a, n, st.cells, st.prm, st.ctl)
    f = _host(st, a[0])
    wall = ps.kind[:n] == WALL
    fluid = ps.kind[:n] == FLUID
    assert np.abs(ps.f[P, :n][wall]).max() > 0.0   # the walls carry pressure
    for row in (P, RHO, VWX, VWZ):
        close(f[row, :n][wall], ps.f[row, :n][wall])
    for row in (AX, AZ, DRHO, PW, DVNX, DVNZ):
        close(f[row, :n][fluid], ps.f[row, :n][fluid])


def test_kick_and_next_dt_match_cpu(sim_factory):
    from sph_core import wcsph
    from sph_core.cuda import gpu_kernels as K
    from sph_core.particles import RHO, VX, VZ

    cpu = sim_factory()
    st = stepper(sim_factory())
    ps, n, dt = cpu.particles, cpu.particles.n, cpu.dt
    n_bad, n_band, v2, a2, rmax = wcsph.kdk_kick(ps.view, n, dt, cpu.prm)
    dt_next = wcsph.stable_dt(v2, a2, rmax, cpu.prm)
    set_clock(st, dt)
    ctl = np.zeros(K.N_CTL, dtype=np.int64)
    ctl[K.MAX_STEPS] = 10
    st._put(st.ctl, ctl)
    a = st.bufs[0]
    K.k_kick[st._grid_n, K.TPB](a, n, st.prm, st.clk, st.ctl)
    clk, ctl = _host(st, st.clk), _host(st, st.ctl)
    assert (ctl[K.N_BAD], ctl[K.N_BAND]) == (n_bad, n_band) == (0, 0)
    assert v2 > 0.0
    np.testing.assert_allclose(clk[[K.V2, K.A2, K.RMAX]], [v2, a2, rmax], rtol=1e-14)
    f = _host(st, a[0])
    for row in (VX, VZ, RHO):
        close(f[row, :n], ps.f[row, :n], rel=1e-13)
    K.k_finish[1, 1](st.prm, st.clk, st.ctl)
    clk, ctl = _host(st, st.clk), _host(st, st.ctl)
    np.testing.assert_allclose(clk[K.DT], dt_next, rtol=1e-14)
    assert clk[K.T] == dt and ctl[K.STEPS] == 1 and ctl[K.STOP] == 0


def test_guard_stops_the_device_at_the_tripping_step(sim_factory):
    """A non-finite velocity trips the guard in the kick: the device stops after that step and
    the queued steps do nothing."""
    from sph_core.particles import FLUID, VX
    from sph_core.wcsph import ST_NONFINITE

    sim = sim_factory()
    ps = sim.particles
    k = int(np.nonzero(ps.kind[: ps.n] == FLUID)[0][0])
    ps.f[VX, k] = np.nan
    st = stepper(sim)
    t, dt, steps, status, n_flag, vmax = st.run(np.inf, 4)
    assert (status, steps) == (ST_NONFINITE, 1)
    assert n_flag >= 1


def test_short_run_matches_cpu(sim_factory):
    """kdk steps on the device and on the CPU agree to round-off growth (10 steps under the
    simulator, 100 on a GPU): both start from the same sorted state and sort identically (the
    device's per-cell ordering makes its sort the CPU's stable counting sort), so they differ
    only by the last bits of reassociated sums and fused multiply-adds, which the dynamics
    amplify. How much: on the CPU alone, moving every fluid x by one ulp grows to a difference
    of <= 2e-13 of each field's scale after 200 steps (p; x 9e-16, v 6e-15; docs/developer/gpu.md).
    The bound, 1e-10 of each field's scale, leaves room for an ulp per operation per step; a
    missing term or a wrong dt is off by many orders more."""
    from sph_core.cuda import simulated

    steps = 10 if simulated() else 100
    cpu = sim_factory()
    gpu = sim_factory()
    short_run(cpu, gpu, steps)
    # the measured differences (pytest -rP shows them; docs/developer/gpu.md)
    a = fluid_agrees(cpu, gpu, 1e-10, f"{steps} steps, max |gpu - cpu| / max |cpu|:")
    assert np.abs(a["vz"]).max() > 0.01   # the column is falling: the comparison has content


def test_run_lands_on_t_stop(sim_factory):
    from sph_core.wcsph import ST_REACHED_T

    sim = sim_factory()
    st = stepper(sim)
    t_stop = sim.t + 1.5 * sim.dt   # the second step is shortened to land on it
    t, dt, steps, status, _, _ = st.run(t_stop, 100)
    assert status == ST_REACHED_T and t == t_stop and steps == 2


def test_unsupported_scene_is_refused():
    if importlib.util.find_spec("numba_cuda") is None:
        pytest.skip("numba-cuda is not installed")
    skip_without_device()
    from sph_core.cuda.cuda_stepper import CudaStepper
    from sph_core.simulation import Simulation

    sim = Simulation(_dambreak(scheme={"kind": "isph"}))
    with pytest.raises(ValueError, match="ISPH"):
        CudaStepper(sim)


def test_graph_replay_matches_plain_launches(sim_factory):
    """The two-step CUDA graphs replay exactly the plain launches: the same state, bit for bit
    (GPU only: the simulator has no graphs)."""
    from sph_core.cuda import simulated
    from sph_core.particles import N_SORTED_KDK
    from sph_core.wcsph import ST_STEP_LIMIT

    if simulated():
        pytest.skip("CUDA graphs need a GPU")
    plain = stepper(sim_factory())
    graph = stepper(sim_factory())
    assert plain.advance_steps(1) == graph.advance_steps(1) == ST_STEP_LIMIT   # compiles
    assert graph.enable_graphs(), graph.graph_error
    print("graph launches:", graph.launches, "plain:", plain.launches)
    for st in (plain, graph):
        st.batch = 16
        assert st.advance_steps(33) == ST_STEP_LIMIT   # 16 pairs + one plain step
    assert plain.steps == graph.steps == 34 and plain.cur == graph.cur
    assert plain.t == graph.t and plain.dt == graph.dt
    a = plain._to_host(plain.bufs[plain.cur][0])
    b = graph._to_host(graph.bufs[graph.cur][0])
    np.testing.assert_array_equal(a[:N_SORTED_KDK, : plain.n], b[:N_SORTED_KDK, : graph.n])


def test_simulator_shared_arrays_are_one_per_line_under_contention():
    """sph_core.cuda.lock_simulator_shared_arrays: 32 threads (a simulated block) asking at once
    for the shared array of one line all get the same array. The simulator's own lookup is not
    locked: with threads switching every microsecond, 32 of 300 such rounds handed out more than
    one array (measured), which made the CUDA tests fail now and then."""
    import sys
    import threading

    from sph_core.cuda import lock_simulator_shared_arrays, simulated
    if not simulated():
        pytest.skip("the simulator's shared memory only")
    from numba.cuda.simulator import kernelapi

    lock_simulator_shared_arrays()
    old = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)
    try:
        split = 0
        for _ in range(200):
            shared = kernelapi.FakeCUDAShared(0)
            got = [None] * 32
            go = threading.Barrier(32)

            def take(k):
                go.wait()
                got[k] = shared.array(16, np.int64)

            threads = [threading.Thread(target=take, args=(k,)) for k in range(32)]
            for t in threads:
                t.start()
            for t in threads:
                t.join()
            split += len({id(a) for a in got}) > 1
    finally:
        sys.setswitchinterval(old)
    assert split == 0


_MARSHAL_CHECK = """
import pickle, sys
import sph_core.cuda   # numpy's row_stack for numba-cuda, before numba.cuda
from numba import typeof
from numba.cuda.dispatcher import CUDADispatcher, _Kernel
from sph_core.cuda import gpu_bodies, gpu_kernels, gpu_open_ends, gpu_schemes

class Launch:   # numba-cuda's own marshalling of one launch's arguments, the kernels' extensions
    extensions = [gpu_kernels._NoneArgs()]
    _prepare_args = _Kernel._prepare_args

for tup in pickle.load(open(sys.argv[1], "rb")):
    out = []
    Launch()._prepare_args(typeof(tup), tup, 0, [], out)
    assert len(out) >= len(tup) and 0 in out, (type(tup).__name__, out)
plain = [f"{m.__name__}.{k}" for m in (gpu_kernels, gpu_open_ends, gpu_schemes, gpu_bodies)
         for k, v in vars(m).items() if isinstance(v, CUDADispatcher)
         and not v.targetoptions.get("device")
         and not any(isinstance(e, gpu_kernels._NoneArgs)
                     for e in v.targetoptions.get("extensions") or [])]
assert not plain, plain
print("ok")
"""


def test_launch_arguments_marshal_on_a_gpu(sim_factory, tmp_path):
    """Every launch's arguments are what numba-cuda's launch can marshal on a GPU (the simulator
    takes anything, so a None in Params went unseen until the H200 refused it): the plan's leaves
    are arrays, numbers, booleans or None; the tuples holding None (a 2D step's Params.three,
    Cells.three) go through numba-cuda's own marshalling with the kernels' extension, and every
    kernel carries it (a process without the simulator: scalars and tuples need no GPU)."""
    import os
    import pickle
    import subprocess
    import sys
    from pathlib import Path

    st = stepper(sim_factory())
    bad, with_none = [], []

    def check(v, where):
        """Record a leaf numba-cuda cannot marshal, and every all-scalar tuple holding None."""
        if isinstance(v, tuple):
            for i, x in enumerate(v):
                check(x, f"{where}.{i}")
            if any(x is None for x in v) and not any(
                    hasattr(x, "shape") or isinstance(x, tuple) for x in v):
                with_none.append(v)
        elif v is not None and not (hasattr(v, "shape") or isinstance(
                v, (bool, int, float, np.bool_, np.integer, np.floating))):
            bad.append(f"{where}: {type(v).__name__}")

    for parity in (0, 1):
        for name, _, args in st._plan[parity]:
            check(tuple(args), name)
    assert not bad, bad
    assert with_none, "the 2D step's Params.three is None: a tuple with None was expected"
    data = tmp_path / "tuples.pkl"
    data.write_bytes(pickle.dumps(list({type(t).__name__: t for t in with_none}.values())))
    root = Path(__file__).resolve().parents[2]
    env = {**os.environ, "NUMBA_ENABLE_CUDASIM": "0"}
    res = subprocess.run([sys.executable, "-c", _MARSHAL_CHECK, str(data)], cwd=root, env=env,
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 0 and res.stdout.strip() == "ok", res.stderr[-3000:]
