"""Rigid bodies in the CUDA step (sph_core/cuda/gpu_bodies.py) against the CPU's bodies.py, kernel
by kernel and over a short run.

On a GPU when one is present, else under numba-cuda's simulator (set here, before numba.cuda is
first imported); skipped without numba-cuda. The state is a tiny tank (dp 0.02 m, depth 0.1 m,
0.3 m long) with a free box (surge, heave, pitch) released 1 cm below its equilibrium and
offset from the middle, warmed up on the CPU, so that it moves and turns.
"""

from __future__ import annotations

import importlib.util
import os
import shutil
import sys

import numpy as np
import pytest

if "NUMBA_ENABLE_CUDASIM" not in os.environ and not (
        os.path.exists("/dev/nvidia0") or shutil.which("nvidia-smi")):
    os.environ["NUMBA_ENABLE_CUDASIM"] = "1"

pytestmark = [
    pytest.mark.cuda,
    pytest.mark.skipif(importlib.util.find_spec("numba_cuda") is None,
                       reason="numba-cuda is not installed (pip install numba-cuda)"),
]

WARM_STEPS = 30


def _scene():
    from sph_core.scene import make_scene

    return make_scene({
        "dp": 0.02, "t_end": 1.0, "still_water_level": 0.1,
        "tank": {"x0": 0.0, "x1": 0.3, "z0": 0.0, "z1": 0.2},
        "water_blocks": [{"x0": 0.0, "x1": 0.3, "z0": 0.0, "z1": 0.1}],
        "bodies": [{"name": "box", "shape": "box", "x0": 0.1, "x1": 0.18, "z0": 0.06,
                    "z1": 0.12, "density": 500.0, "motion": "free",
                    "dofs": ["surge", "heave", "pitch"]}]})


@pytest.fixture(scope="module")
def body_factory():
    from sph_core.cuda import unavailable_reason
    reason = unavailable_reason()
    if reason:
        pytest.skip(reason)
    from sph_core.simulation import Simulation

    old = sys.getswitchinterval()
    sys.setswitchinterval(1e-4)
    base = Simulation(_scene())
    base.advance_steps(WARM_STEPS)
    ck = base.checkpoint()
    bd = base.bodies.state

    def make():
        s = Simulation(_scene())
        s.restore(ck)
        for k in ("q", "qd", "acc", "qn", "qdn", "load"):
            getattr(s.bodies.state, k)[:] = getattr(bd, k)
        return s
    yield make
    sys.setswitchinterval(old)


def _stepper(sim):
    from sph_core.cuda.cuda_stepper import CudaStepper
    return CudaStepper(sim)


def _clock(st, t, dts):
    from sph_core.cuda import gpu_kernels as K
    clk = np.zeros(K.N_CLK)
    clk[K.T], clk[K.DTS], clk[K.T_STOP] = t, dts, np.inf
    st._put(st.clk, clk)
    st._put(st.ctl, np.zeros(K.N_CTL, dtype=np.int64))


def _close(gpu, cpu, rel=1e-12):
    scale = max(float(np.abs(cpu).max()), 1e-300)
    np.testing.assert_allclose(gpu, cpu, rtol=0.0, atol=rel * scale)


def _run(st, names, parity=0):
    plan = st._plan[parity]
    index = [p[0] for p in plan]
    for name in names:
        _, kernel, args = plan[index.index(name)]
        kernel(*args)


def test_loads_stage_and_placement_match_cpu(body_factory):
    """body_loads (per-particle reactions, the per-body sum, the equations of motion), one
    kick-drift stage and place_bodies on the device and on the CPU from the same state."""
    from sph_core.bodies import KICK_DRIFT, bodies_advance, body_loads, place_bodies
    from sph_core.particles import AX, AZ, VX, VZ, X, Z

    cpu, gsim = body_factory(), body_factory()
    st = _stepper(gsim)
    ps, n, bd = cpu.particles, cpu.particles.n, cpu.bodies.state
    assert np.abs(bd.qd).max() > 0.0   # the box moves
    body_loads(ps.view, n, cpu.cells, cpu.prm, bd)
    bodies_advance(bd, cpu.t, cpu.dt, KICK_DRIFT)
    place_bodies(ps.view, n, bd)
    _clock(st, gsim.t, gsim.dt)
    # the loads read the sorted state in buffer 0: an odd step's plan has it as its ps2
    _run(st, ("body_loads", "body_acc"), parity=1)
    _run(st, ("body_stage", "body_place"), parity=0)
    st.bodies.read()
    g = gsim.bodies.state
    assert np.all(bd.load[0] != 0.0)
    for k in ("fk_x", "fk_z", "fk_m", "load", "acc"):
        _close(getattr(g, k), getattr(bd, k), rel=1e-11)
    for k in ("q", "qd"):
        _close(getattr(g, k), getattr(bd, k), rel=1e-13)
    f = st._to_host(st.bufs[0][0])
    body = (ps.ids[:n] >= bd.id0) & (ps.ids[:n] < bd.id0 + bd.npart)
    assert body.sum() == bd.npart
    for row in (X, Z, VX, VZ, AX, AZ):
        _close(f[row, :n][body], ps.f[row, :n][body], rel=1e-11)


def test_short_run_matches_cpu(body_factory):
    from sph_core.cuda import simulated
    from sph_core.wcsph import ST_STEP_LIMIT

    steps = 6 if simulated() else 100
    cpu, gsim = body_factory(), body_factory()
    st = _stepper(gsim)
    assert st.advance_steps(steps) == ST_STEP_LIMIT
    st.to_host()
    cpu.advance_steps(steps)
    assert gsim.steps == cpu.steps
    assert gsim.t == pytest.approx(cpu.t, rel=1e-12)
    assert gsim.dt == pytest.approx(cpu.dt, rel=1e-10)
    for k in ("q", "qd", "acc"):
        _close(getattr(gsim.bodies.state, k), getattr(cpu.bodies.state, k), rel=1e-9)
    a, b = cpu.fluid_state(), gsim.fluid_state()
    np.testing.assert_array_equal(a["id"], b["id"])
    print({k: float(np.abs(b[k] - a[k]).max() / np.abs(a[k]).max()) for k in a if k != "id"})
    for key in ("x", "z", "vx", "vz", "rho", "p"):
        _close(b[key], a[key], rel=1e-10)


def test_prescribed_and_hinged_stages_match_cpu():
    """bodies_advance's prescribed (series interpolation) and hinged branches and the
    placement on the device and on the CPU: a prescribed plate and a hinged flap."""
    from sph_core.bodies import KICK, KICK_DRIFT, bodies_advance, place_bodies
    from sph_core.cuda import unavailable_reason
    from sph_core.particles import AX, AZ, VX, VZ, X, Z
    from sph_core.scene import make_scene
    from sph_core.simulation import Simulation

    if unavailable_reason():
        pytest.skip(unavailable_reason())

    def scene():
        return make_scene({
            "dp": 0.02, "t_end": 1.0, "still_water_level": 0.1,
            "tank": {"x0": 0.0, "x1": 0.4, "z0": 0.0, "z1": 0.2},
            "water_blocks": [{"x0": 0.0, "x1": 0.4, "z0": 0.0, "z1": 0.1}],
            "bodies": [
                {"name": "plate", "shape": "box", "x0": 0.06, "x1": 0.14, "z0": 0.07, "z1": 0.15,
                 "motion": "prescribed",
                 "series": [(0.0, 0.0, 0.0, 0.0), (0.01, 0.002, -0.001, 0.05),
                            (1.0, 0.05, -0.02, 0.3)]},
                {"name": "flap", "shape": "box", "x0": 0.22, "x1": 0.30, "z0": 0.02, "z1": 0.14,
                 "density": 600.0, "motion": "hinged", "pivot": (0.26, 0.02)}]})

    cpu, gsim = Simulation(scene()), Simulation(scene())
    for s in (cpu, gsim):   # a turning flap: omega and alpha in the placement
        s.bodies.state.qd[1, 2] = 0.4
        s.bodies.state.acc[1, 2] = -2.0
    st = _stepper(gsim)
    bd = cpu.bodies.state
    t, dt = 0.004, 1e-3   # the kick-drift stage interpolates the series' first span
    for stage in (KICK_DRIFT, KICK):
        bodies_advance(bd, t, dt, stage)
    place_bodies(cpu.particles.view, cpu.particles.n, bd)
    _clock(st, t, dt)
    _run(st, ("body_stage", "body_stage2", "body_place"))
    st.bodies.read()
    g = gsim.bodies.state
    assert bd.q[0, 0] != 0.0 and bd.qd[0, 2] != 0.0 and bd.q[1, 2] != 0.0
    for k in ("q", "qd", "acc"):
        _close(getattr(g, k), getattr(bd, k), rel=1e-14)
    n = cpu.particles.n
    f = st._to_host(st.bufs[0][0])
    for row in (X, Z, VX, VZ, AX, AZ):
        _close(f[row, :n], cpu.particles.f[row, :n], rel=1e-13)
