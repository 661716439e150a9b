"""Rigid bodies in the CUDA step (sph_core/cuda/gpu_bodies.py) against the CPU's bodies.py, kernel
by kernel and over a short run.

On a GPU when one is present, else under numba-cuda's simulator (set by
cuda_support, imported before numba.cuda); skipped without numba-cuda. The state is a tiny tank (dp 0.02 m, depth 0.1 m,
0.3 m long) with a free box (surge, heave, pitch) released 1 cm below its equilibrium and
offset from the middle, warmed up on the CPU, so that it moves and turns.
"""

from __future__ import annotations

import numpy as np
import pytest
from cuda_support import (CUDA_TESTS, close, device_session, fluid_agrees, set_clock, short_run,
                          skip_without_device, stepper)

pytestmark = CUDA_TESTS

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
    with device_session():
        from sph_core.simulation import Simulation

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
    st = stepper(gsim)
    ps, n, bd = cpu.particles, cpu.particles.n, cpu.bodies.state
    assert np.abs(bd.qd).max() > 0.0   # the box moves
    body_loads(ps.view, n, cpu.cells, cpu.prm, bd)
    bodies_advance(bd, cpu.t, cpu.dt, KICK_DRIFT)
    place_bodies(ps.view, n, bd)
    set_clock(st, gsim.dt, t=gsim.t)
    # the loads read the sorted state in buffer 0: an odd step's plan has it as its ps2
    _run(st, ("body_loads", "body_acc"), parity=1)
    _run(st, ("body_stage", "body_place"), parity=0)
    st.bodies.read()
    g = gsim.bodies.state
    assert np.all(bd.load[0] != 0.0)
    for k in ("fk_x", "fk_z", "fk_m", "load", "acc"):
        close(getattr(g, k), getattr(bd, k), rel=1e-11)
    for k in ("q", "qd"):
        close(getattr(g, k), getattr(bd, k), rel=1e-13)
    f = st._to_host(st.bufs[0][0])
    body = (ps.ids[:n] >= bd.id0) & (ps.ids[:n] < bd.id0 + bd.npart)
    assert body.sum() == bd.npart
    for row in (X, Z, VX, VZ, AX, AZ):
        close(f[row, :n][body], ps.f[row, :n][body], rel=1e-11)


def test_short_run_matches_cpu(body_factory):
    from sph_core.cuda import simulated

    steps = 6 if simulated() else 100
    cpu, gsim = body_factory(), body_factory()
    short_run(cpu, gsim, steps)
    for k in ("q", "qd", "acc"):
        close(getattr(gsim.bodies.state, k), getattr(cpu.bodies.state, k), rel=1e-9)
    fluid_agrees(cpu, gsim)


def test_prescribed_and_hinged_stages_match_cpu():
    """bodies_advance's prescribed (series interpolation) and hinged branches and the
    placement on the device and on the CPU: a prescribed plate and a hinged flap."""
    from sph_core.bodies import KICK, KICK_DRIFT, bodies_advance, place_bodies
    from sph_core.particles import AX, AZ, VX, VZ, X, Z
    from sph_core.scene import make_scene
    from sph_core.simulation import Simulation

    skip_without_device()

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
    st = stepper(gsim)
    bd = cpu.bodies.state
    t, dt = 0.004, 1e-3   # the kick-drift stage interpolates the series' first span
    for stage in (KICK_DRIFT, KICK):
        bodies_advance(bd, t, dt, stage)
    place_bodies(cpu.particles.view, cpu.particles.n, bd)
    set_clock(st, dt, t=t)
    _run(st, ("body_stage", "body_stage2", "body_place"))
    st.bodies.read()
    g = gsim.bodies.state
    assert bd.q[0, 0] != 0.0 and bd.qd[0, 2] != 0.0 and bd.q[1, 2] != 0.0
    for k in ("q", "qd", "acc"):
        close(getattr(g, k), getattr(bd, k), rel=1e-14)
    n = cpu.particles.n
    f = st._to_host(st.bufs[0][0])
    for row in (X, Z, VX, VZ, AX, AZ):
        close(f[row, :n], cpu.particles.f[row, :n], rel=1e-13)
