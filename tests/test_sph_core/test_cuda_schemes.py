"""The GPU step's schemes beyond kdk WCSPH (sph_core/cuda/gpu_schemes.py) against their CPU
twins: the symplectic predictor-corrector, Fickian and delta-plus shifting, Riemann SPH with and
without MUSCL gradients, kernel by kernel on the same state and over a short run.

As test_cuda_step.py: on a GPU when one is present, else under numba-cuda's simulator; skipped
without numba-cuda; the tiny dam break (322 particles, 50 fluid) after a few CPU steps of the
scene itself (moving fluid, the scene's own scratch rows).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from cuda_support import (CUDA_TESTS, close, device_session, fluid_agrees, set_clock, short_run,
                          stepper)

pytestmark = CUDA_TESTS

A, DP, WARM_STEPS = 0.05, 0.01, 15

SCENES = {
    "pc": dict(integrator="symplectic_pc"),
    "fickian": dict(shifting="fickian"),
    "pc_dplus": dict(integrator="symplectic_pc", shifting="dplus"),
    "riemann_muscl": dict(scheme={"kind": "riemann"}),
    "riemann_first": dict(scheme={"kind": "riemann", "reconstruction": "none"}),
}


def _scene(name):
    from wavesph.cases.dambreak import dambreak_scene
    return dambreak_scene(a=A, dp=DP, t_end=1.0, tank_length=2.0 * A, **SCENES[name])


@pytest.fixture(scope="module")
def make():
    """make(name): a fresh Simulation of scene ``name`` after WARM_STEPS CPU steps."""
    with device_session():
        from sph_core.simulation import Simulation

        checkpoints = {}

        def factory(name):
            if name not in checkpoints:
                base = Simulation(_scene(name))
                base.advance_steps(WARM_STEPS)
                checkpoints[name] = base.checkpoint()
            s = Simulation(_scene(name))
            s.restore(checkpoints[name])
            return s
        yield factory


def _launch(st, kernel, *args):
    from sph_core.cuda import gpu_kernels as K
    kernel[st._grid_n, K.TPB](*args)


def test_step_plan(make):
    """The step plan carries each scheme's kernels in step.run's order."""
    names = {k: [p[0] for p in stepper(make(k))._plan[0]] for k in SCENES}
    assert names["pc"][0] == "bin" and names["pc"].count("fluid") == 2
    assert names["pc"][-2:] == ["correct", "finish"]
    assert names["fickian"][-4:] == ["kick", "shift_fickian", "shift_move", "finish"]
    assert names["pc_dplus"][-5:] == ["correct", "dplus_surface", "dplus_tangential",
                                      "shift_move", "finish"]
    assert names["riemann_muscl"].count("muscl_gradients") == 1
    assert "muscl_gradients" not in names["riemann_first"]


def test_pc_sort_predict_correct_match_cpu(make):
    """symplectic_pc's sort (14 rows carried), predictor and corrector against the CPU's."""
    from sph_core import wcsph
    from sph_core.cuda import gpu_kernels as K
    from sph_core.cuda import gpu_schemes as S
    from sph_core.neighbours import sort_by_cell
    from sph_core.particles import N_SORTED_PC, P, RHO, RHON, VX, VZ, X, XN, Z

    cpu = make("pc")
    st = stepper(make("pc"))
    ps, n, dt, prm = cpu.particles, cpu.particles.n, cpu.dt, cpu.prm
    # sort: the same order, the carried rows copied exactly
    n_sorted = sort_by_cell(ps.view, ps.view2, N_SORTED_PC, n, cpu.cells)
    set_clock(st, dt)
    a, b = st.bufs[0], st.bufs[1]
    _launch(st, K.k_bin, a, n, st.cells, st.count, st.ctl)
    K.k_scan_blocks[st.nb, K.SCAN_B](st.count, st.start, st.bsum, st.m, st.ctl)
    K.k_scan_sums[1, K.SCAN_B](st.bsum, st.nb, st.ctl)
    K.k_scan_add[st.nb, K.SCAN_B](st.start, st.bsum, st.cursor, st.count, st.m, st.ctl)
    _launch(st, K.k_scatter, a, n, st.cursor, st.order, st.ctl)
    K.k_cell_order[st._grid_c, K.TPB](st.start, st.order, st.ncell + 1, st.ctl)
    _launch(st, S.k_permute_pc, a, b, st.order, n, st.ctl)
    start = st._to_host(st.start)
    np.testing.assert_array_equal(start, cpu.cells.start)
    assert start[st.ncell] == n_sorted
    f2 = st._to_host(b[0])
    np.testing.assert_array_equal(f2[:N_SORTED_PC, :n], ps.f2[:N_SORTED_PC, :n])
    np.testing.assert_array_equal(st._to_host(b[1])[:n], ps.kind2[:n])
    np.testing.assert_array_equal(st._to_host(b[2])[:n], ps.ids2[:n])
    # predictor then corrector (same dt, the stored rates) on each side's sorted buffer
    pre = ps.f2[:, :n].copy()
    wcsph.pc_predict(ps.view2, n, dt, prm)
    _launch(st, S.k_predict, b, n, prm, st.clk, st.ctl)
    f2 = st._to_host(b[0])
    for r in (X, Z, VX, VZ, RHO, P) + tuple(range(XN, RHON + 1)):
        close(f2[r, :n], ps.f2[r, :n], rel=1e-13)
    res = wcsph.pc_correct(ps.view2, n, dt, prm)
    _launch(st, S.k_correct, b, n, prm, st.clk, st.ctl)
    n_bad, n_band, n_out, v2, a2, rmax = res
    assert (n_bad, n_band, n_out) == (0, 0, 0) and v2 > 0.0
    clk, ctl = st._to_host(st.clk), st._to_host(st.ctl)
    assert (ctl[K.N_BAD], ctl[K.N_BAND], ctl[K.N_OUT]) == (0, 0, 0)
    np.testing.assert_allclose(clk[[K.V2, K.A2, K.RMAX]], [v2, a2, rmax], rtol=1e-13)
    f2 = st._to_host(b[0])
    for r in (X, Z, VX, VZ, RHO, P):
        close(f2[r, :n], ps.f2[r, :n], rel=1e-13)
    # the step moved the fluid (a kernel that did nothing would not match)
    assert np.abs(ps.f2[X, :n] - pre[X]).max() > 0.0
    assert np.abs(ps.f2[VZ, :n] - pre[VZ]).max() > 0.0


def test_fickian_shift_matches_cpu(make):
    from sph_core import shifting
    from sph_core.cuda import gpu_schemes as S
    from sph_core.particles import FLUID, RHO, RHON, VX, VZ, X, XN, Z

    cpu = make("fickian")
    st = stepper(make("fickian"))
    ps, n, dt = cpu.particles, cpu.particles.n, cpu.dt
    shifting.shift_particles(ps.view, n, cpu.cells, cpu.prm, dt)
    set_clock(st, dt)
    a = st.bufs[0]
    _launch(st, S.k_shift_fickian, a, n, st.cells, st.prm, st.clk, st.ctl)
    _launch(st, S.k_shift_move, a, n, st.ctl)
    f = st._to_host(a[0])
    fluid = ps.kind[:n] == FLUID
    assert np.abs(ps.f[XN, :n][fluid]).max() > 0.0     # the particles shifted
    for r in tuple(range(XN, RHON + 1)):
        close(f[r, :n], ps.f[r, :n])
    for r in (X, Z, VX, VZ, RHO):
        close(f[r, :n], ps.f[r, :n], rel=1e-14)


def test_dplus_shift_matches_cpu(make):
    from sph_core import shifting
    from sph_core.cuda import gpu_schemes as S
    from sph_core.particles import FLUID, GPX, GPZ, GUZ, RHO, RHON, VX, VZ, X, XN, Z

    cpu = make("pc_dplus")
    st = stepper(make("pc_dplus"))
    ps, n, dt = cpu.particles, cpu.particles.n, cpu.dt
    v2 = float((ps.f[VX, :n] ** 2 + ps.f[VZ, :n] ** 2)[ps.kind[:n] == FLUID].max())
    shifting.shift_particles_dplus(ps.view, n, cpu.cells, cpu.prm, dt, math.sqrt(v2))
    set_clock(st, dt, v2=v2)
    a = st.bufs[0]
    _launch(st, S.k_dplus_surface, a, n, st.cells, st.prm, st.clk, st.ctl)
    _launch(st, S.k_dplus_tangential, a, n, st.cells, st.prm, st.ctl)
    _launch(st, S.k_shift_move, a, n, st.ctl)
    f = st._to_host(a[0])
    fluid = ps.kind[:n] == FLUID
    flags = ps.f[GUZ, :n][fluid]
    # the scene has surface particles and interior ones, and the shift is not zero
    assert np.any(flags == shifting.FS_SURFACE) and np.any(flags == shifting.FS_INTERIOR)
    assert np.abs(ps.f[XN, :n][fluid]).max() > 0.0
    np.testing.assert_array_equal(f[GUZ, :n], ps.f[GUZ, :n])   # the surface flags
    for r in tuple(range(XN, RHON + 1)) + (GPX, GPZ):
        close(f[r, :n], ps.f[r, :n])
    for r in (X, Z, VX, VZ, RHO):
        close(f[r, :n], ps.f[r, :n], rel=1e-14)


@pytest.mark.parametrize("name", ["riemann_muscl", "riemann_first"])
def test_riemann_forces_match_cpu(make, name):
    """The wall pass, the MUSCL gradients (when on) and the Riemann flux's fluid pass."""
    from sph_core import wcsph
    from sph_core.cuda import gpu_kernels as K
    from sph_core.cuda import gpu_schemes as S
    from sph_core.particles import AX, AZ, DRHO, DVNX, DVNZ, FLUID, GPX, GWZ, PW
    from sph_core.riemann import NO_RECONSTRUCTION, riemann_gradients

    cpu = make(name)
    st = stepper(make(name))
    ps, n, prm = cpu.particles, cpu.particles.n, cpu.prm
    assert prm.riemann and (prm.limiter != NO_RECONSTRUCTION) == (name == "riemann_muscl")
    wcsph.wall_pass(ps.view, n, cpu.cells, prm)
    set_clock(st)
    a = st.bufs[0]
    _launch(st, K.k_wall, a, n, st.cells, prm, st.ctl)
    fluid = ps.kind[:n] == FLUID
    if prm.limiter != NO_RECONSTRUCTION:
        riemann_gradients(ps.view, n, cpu.cells, prm)
        _launch(st, S.k_muscl_gradients, a, n, st.cells, prm, st.ctl)
        f = st._to_host(a[0])
        assert np.abs(ps.f[GPX, :n][fluid]).max() > 0.0
        for r in range(GPX, GWZ + 1):
            close(f[r, :n][fluid], ps.f[r, :n][fluid])
    wcsph.fluid_pass(ps.view, n, cpu.cells, prm, True)
    _launch(st, S.k_fluid_riemann, a, n, st.cells, prm, st.ctl)
    f = st._to_host(a[0])
    for r in (AX, AZ, DRHO, PW, DVNX, DVNZ):
        close(f[r, :n][fluid], ps.f[r, :n][fluid])


@pytest.mark.parametrize("name", list(SCENES))
def test_short_run_matches_cpu(make, name):
    """A few steps of each scheme on the device and on the CPU agree to round-off growth
    (test_cuda_step.py's whole-run bound and why)."""
    from sph_core.cuda import simulated

    steps = 5 if simulated() else 100
    cpu = make(name)
    gpu = make(name)
    short_run(cpu, gpu, steps)
    a = fluid_agrees(cpu, gpu, 1e-10, f"{name}, {steps} steps, max |gpu - cpu| / max |cpu|:")
    assert np.abs(a["vz"]).max() > 0.01   # the column is falling: the comparison has content
