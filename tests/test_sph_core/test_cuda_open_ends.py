"""Open ends in the CUDA step (sph_core/cuda/gpu_open_ends.py) against the CPU's open_boundary.py,
kernel by kernel and over a few coupling windows.

On a GPU when one is present, else under numba-cuda's simulator (set by
cuda_support, imported before numba.cuda); skipped without numba-cuda. The state is a tiny flume (dp 0.02 m, depth 0.1 m,
0.24 m long, both ends open: imposed inlet, extrapolated outlet, absorbing) with an oscillating
through-flow, warmed up on the CPU, so that the simulator (every CUDA thread a Python thread)
stays within a minute.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from cuda_support import (CUDA_TESTS, close, device_session, fluid_agrees, set_clock,
                          skip_without_device, stepper)

pytestmark = CUDA_TESTS

# WARM_T: the simulator's three windows of three steps (~0.0085 s) then span t = 0.30, a probe
# time of the default cadence (0.01 s), so a probe cadence back in _flume fails there too
D, DP, LENGTH, WARM_T = 0.1, 0.02, 0.24, 0.295


class Oscillating:
    """Uniform horizontal flow u = U sin(2 pi t / T) through both ends, a small swell at the
    gauges (so the absorbing correction acts)."""

    def __init__(self, nodes, amplitude: float = 0.3, period: float = 1.0) -> None:
        self.nodes = nodes
        self.amplitude = amplitude
        self.period = period

    def sample(self, t: float):
        from sph_core.boundary_data import BoundarySample
        s = math.sin(2 * math.pi * t / self.period)
        n = self.nodes.size
        return BoundarySample(t, np.full(n, self.amplitude * s), np.zeros(n), 0.0, 0.002 * s)


def _flume():
    from sph_core.open_ends import flume_nodes
    from sph_core.scene import make_scene

    sc = make_scene({
        "dp": DP, "t_end": 10.0, "still_water_level": D,
        "tank": {"x0": 0.0, "x1": LENGTH, "z0": 0.0, "z1": D + 0.06},
        "water_blocks": [{"x0": 0.0, "x1": LENGTH, "z0": 0.0, "z1": D}],
        "constants": {"c0": 10.0 * math.sqrt(9.81 * D)},
        # no output times: Simulation.advance_window (the CPU reference of test_windows_match_cpu)
        # would otherwise stop at each probe time with a step shortened to land on it, where
        # CudaStepper.advance_to runs straight to the window's end (the product path,
        # Simulation._run_gpu, stops at them too: test_cuda_simulation.py)
        "output": {"probe_every": 0.0, "snapshot_every": 0.0},
        "open_boundaries": [{"side": "left", "elevation": "imposed"},
                            {"side": "right", "elevation": "extrapolated"}]})
    return sc, {s: Oscillating(n) for s, n in flume_nodes(sc).items()}


@pytest.fixture(scope="module")
def flume_factory():
    """Fresh Simulations of the tiny flume after WARM_T s on the CPU (flow through both ends)."""
    with device_session():
        from sph_core.simulation import Simulation

        sc, src = _flume()
        base = Simulation(sc, sources=src, window=0.02)
        base.advance_to(WARM_T)
        ck = base.checkpoint()

        def make():
            sc, src = _flume()
            s = Simulation(sc, sources=src, window=0.02)
            s.restore(ck)
            return s
        yield make


def _window(sim, t1, t0=None):
    """The next window's data into the host OpenEnds (what Simulation.advance_window does);
    t0: the window's start (the stepper's clock: ``sim.t`` moves only on ``to_host``)."""
    end = sim.open.end_samples(t1, {})
    sim.open.load_window(sim.t if t0 is None else t0, t1, end)
    return end


def _crossings(sim):
    """Move a few particles so that every kind of crossing happens in the next update_buffers:
    an active and an idle left buffer particle into the fluid (both cloned), a right buffer
    particle past its far side, a fluid particle dp into the right buffer."""
    from sph_core.open_boundary import INLET_IDLE
    from sph_core.particles import FLUID, INLET, OUTLET, X

    ps, e = sim.particles, sim.open.ends
    kind, x = ps.kind[: ps.n], ps.f[X, : ps.n]
    pick = {}
    for k in (INLET, INLET_IDLE, OUTLET, FLUID):
        sel = np.nonzero(kind == k)[0]
        assert sel.size, k
        pick[k] = sel[sel.size // 2]
    x[pick[INLET]] = e.x_face[0] + 0.004
    x[pick[INLET_IDLE]] = e.x_face[0] + 0.004
    x[pick[OUTLET]] = e.x_face[1] + e.length[1] + 0.004
    x[pick[FLUID]] = e.x_face[1] + DP + 0.004


def test_buffer_update_and_crossings_match_cpu(flume_factory):
    """update_buffers (boundary state with the absorbing filter, buffers moved, crossings with
    clones appended in slot order) on the device and on the CPU from the same state."""
    from sph_core.cuda import gpu_kernels as K
    from sph_core.cuda import gpu_open_ends as G
    from sph_core.open_boundary import update_buffers

    cpu, gsim = flume_factory(), flume_factory()
    for s in (cpu, gsim):
        s.open.ends.eta_meas[:] = (0.003, -0.002)   # a mismatch: the correction acts
        _crossings(s)
        _window(s, s.t + 0.01)
    st = stepper(gsim)
    st.open.load_window()
    dt = cpu.dt
    ps, n, e = cpu.particles, cpu.particles.n, cpu.open.ends
    counters0 = e.counters.copy()
    filt0 = e.filt_x.copy()
    e.next_id[0] = ps.next_id   # as Simulation._run sets it before a CPU run
    n_new = update_buffers(ps.view, n, cpu.t + dt, dt, e, cpu.prm)
    assert n_new == n + 2   # the two clones
    set_clock(st, dt, t=gsim.t)
    for name, kernel, args in st._plan[0][1:8]:   # boundary .. apply (no kick, no sort)
        assert name in ("boundary", "buffers", "mark", "clone_scan_blocks", "clone_scan_sums",
                        "clone_scan_add", "apply"), name
        kernel(*args)
    assert st._to_host(st.ctl)[K.STOP] == 0
    got = st.open.read()
    assert not np.array_equal(e.filt_x, filt0) and np.any(e.counters != counters0)
    np.testing.assert_array_equal(got["counters"], e.counters)
    assert got["next_id"][0] == e.next_id[0]
    close(got["zs"], e.zs)
    close(got["filt_x"], e.filt_x)
    buf = st.bufs[0]
    np.testing.assert_array_equal(st._to_host(buf[1])[:n_new], ps.kind[:n_new])
    np.testing.assert_array_equal(st._to_host(buf[2])[:n_new], ps.ids[:n_new])
    from sph_core.particles import INACTIVE
    assert np.all(st._to_host(buf[1])[n_new:] == INACTIVE)
    f = st._to_host(buf[0])
    for r in range(f.shape[0]):
        close(f[r, :n_new], ps.f[r, :n_new])
    assert st._to_host(st.open.oe[G.OFF])[st.n] == 2


def test_capacity_overflow_stops_the_device(flume_factory):
    from sph_core.cuda import gpu_kernels as K
    from sph_core.cuda import gpu_open_ends as G
    from sph_core.wcsph import ST_CAPACITY

    sim = flume_factory()
    _crossings(sim)
    st = stepper(sim)
    oei = st._to_host(st.open.oe[G.I])
    oei[G.N_LIVE] = st.n - 1          # one free slot left, two clones due
    st._put(st.open.oe[G.I], oei)
    set_clock(st, sim.dt, t=sim.t)
    for _, kernel, args in st._plan[0][1:8]:
        kernel(*args)
    ctl = st._to_host(st.ctl)
    assert (ctl[K.STOP], ctl[K.STATUS], ctl[K.N_FLAG]) == (1, ST_CAPACITY, st.n - 1)


def test_extrapolation_and_gauges_match_cpu(flume_factory):
    """extrapolate_buffers (ghost nodes) and measure_boundaries on the sorted state."""
    from sph_core.open_boundary import extrapolate_buffers, measure_boundaries
    from sph_core.particles import INLET, OUTLET, P, RHO

    cpu, gsim = flume_factory(), flume_factory()
    st = stepper(gsim)
    ps, n, e = cpu.particles, cpu.particles.n, cpu.open.ends
    e.eta_meas[:] = np.nan
    extrapolate_buffers(ps.view, n, cpu.cells, e, cpu.prm)
    measure_boundaries(ps.view, cpu.cells, e, cpu.prm)
    set_clock(st, gsim.dt, t=gsim.t)
    plan = st._plan[1]   # an odd step's sorted state is buffer 0, where the state is
    names = [p[0] for p in plan]
    for name in ("extrapolate", "gauge_line", "gauge"):
        _, kernel, args = plan[names.index(name)]
        kernel(*args)
    got = st.open.read()
    assert np.all(np.isfinite(e.eta_meas))
    close(got["eta_meas"], e.eta_meas, rel=1e-13)
    f = st._to_host(st.bufs[0][0])
    buf = (ps.kind[:n] == INLET) | (ps.kind[:n] == OUTLET)
    assert buf.sum() > 0
    for row in (P, RHO):
        close(f[row, :n][buf], ps.f[row, :n][buf])
    assert st.open.n_live() == n


def test_windows_match_cpu(flume_factory):
    """A few coupling windows on the device (data in per window, gauges and counters out)
    and on the CPU agree: step count and clock after every window, particle count, ids,
    positions, velocities, gauges, counters. The CPU's advance_window takes one run to t1 here
    (the flume has no output times: _flume)."""
    from sph_core.cuda import simulated
    from sph_core.wcsph import ST_REACHED_T

    cpu, gsim = flume_factory(), flume_factory()
    for s in (cpu, gsim):
        _crossings(s)   # every kind of crossing in the first step
    counts0 = cpu.boundary_counts()
    st = stepper(gsim)
    windows, span = (3, 3) if simulated() else (10, 40)   # windows, steps per window
    t1 = cpu.t
    gauges = []
    for _ in range(windows):
        t1 = t1 + span * cpu.dt
        end = _window(gsim, t1, st.t)
        st.load_window()
        assert st.advance_to(t1) == ST_REACHED_T
        gsim.open.samples = end
        st.read_boundaries()
        cpu.advance_window(t1)
        assert (st.steps0 + st.steps, st.t) == (cpu.steps, cpu.t), len(gauges)
        gauges.append((gsim.boundary_gauges(), cpu.boundary_gauges()))
    st.to_host()
    assert gsim.steps == cpu.steps and gsim.t == cpu.t
    assert gsim.particles.n == cpu.particles.n
    assert gsim.particles.next_id == cpu.particles.next_id
    assert gsim.boundary_counts() == cpu.boundary_counts()
    counts = cpu.boundary_counts()
    assert all(counts[side][k] > counts0[side][k]
               for side, k in (("left", "in"), ("left", "created"), ("left", "removed"),
                               ("right", "out"), ("right", "removed")))
    for g, c in gauges:
        for side in ("left", "right"):
            assert g[side] == pytest.approx(c[side], abs=1e-12)   # m
    fluid_agrees(cpu, gsim, 1e-10, "max |gpu - cpu| / max |cpu|:", cpu.boundary_counts())


def test_open_ends_with_a_floating_body_match_cpu():
    """Open ends and a rigid body in one step (the launch list of gpu_step_plan with both):
    a few steps from rest with a box released 1 cm below its equilibrium."""
    from sph_core.cuda import simulated
    from sph_core.open_ends import flume_nodes
    from sph_core.scene import make_scene
    from sph_core.simulation import Simulation
    from sph_core.wcsph import ST_STEP_LIMIT

    skip_without_device()

    def make():
        sc = make_scene({
            "dp": DP, "t_end": 10.0, "still_water_level": D,
            "tank": {"x0": 0.0, "x1": 0.32, "z0": 0.0, "z1": D + 0.06},
            "water_blocks": [{"x0": 0.0, "x1": 0.32, "z0": 0.0, "z1": D}],
            "constants": {"c0": 10.0 * math.sqrt(9.81 * D)},
            "open_boundaries": [{"side": "left", "elevation": "imposed"},
                                {"side": "right", "elevation": "extrapolated"}],
            "bodies": [{"name": "box", "shape": "box", "x0": 0.12, "x1": 0.20, "z0": 0.05,
                        "z1": 0.13, "density": 500.0, "motion": "free", "dofs": ["heave"]}]})
        return Simulation(sc, sources={s: Oscillating(n) for s, n in flume_nodes(sc).items()},
                          window=0.02)

    steps = 4 if simulated() else 100
    cpu, gsim = make(), make()
    st = stepper(gsim)
    assert st.open is not None and st.bodies is not None
    assert st.advance_steps(steps) == ST_STEP_LIMIT
    st.to_host()
    st.read_boundaries()
    cpu.advance_steps(steps)
    assert gsim.steps == cpu.steps and gsim.particles.n == cpu.particles.n
    assert gsim.boundary_counts() == cpu.boundary_counts()
    for side in ("left", "right"):
        assert gsim.boundary_gauges()[side] == pytest.approx(cpu.boundary_gauges()[side],
                                                             abs=1e-12)
    close(gsim.bodies.state.q, cpu.bodies.state.q, rel=1e-12)
    close(gsim.bodies.state.qd, cpu.bodies.state.qd, rel=1e-9)
    assert abs(cpu.bodies.state.qd[0, 1]) > 0.0
    fluid_agrees(cpu, gsim)
