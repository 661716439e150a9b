"""CUDA kernels of the GPU step's schemes beyond the kdk WCSPH of ``gpu_kernels.py``: the
symplectic predictor-corrector, particle shifting (both laws) and Riemann SPH.

Each kernel is a thin shell around the per-particle function that its CPU pass's prange loop
calls too (one source for both devices):

    kernel                   per-particle function               CPU pass
    (k_bin is gpu_kernels.k_bin)
    k_permute_pc             per_particle.permute_slot           neighbours.permute (14 rows)
    k_predict                wcsph.pc_predict_particle           wcsph.pc_predict
    k_correct                wcsph.pc_correct_particle           wcsph.pc_correct
    k_shift_fickian          shifting.fickian_shift              shifting.shift_particles
    k_dplus_surface          shifting.dplus_surface              shift_particles_dplus, pass 1
    k_dplus_tangential       shifting.dplus_tangential           shift_particles_dplus, pass 2
    k_shift_move             shifting.move_particle              shifting._move
    k_muscl_gradients        riemann.muscl_gradients             riemann.riemann_gradients
    k_fluid_riemann          wcsph.fluid_rates (riemann True)    wcsph.fluid_pass

Every kernel returns at once when the device's stop flag is set (gpu_kernels.py). Passes that
read a neighbour's result of an earlier pass (the shift's move, delta-plus's surface flags,
the MUSCL gradients) are separate launches: a launch boundary is the only grid-wide barrier.
"""

from __future__ import annotations

import math

from numba import cuda

from ..particles import FLUID, GPX, GPZ, GUX, GUZ, GWX, GWZ, N_SORTED_PC, RHON, XN
from ..riemann import muscl_gradients
from ..shifting import FS_ISOLATED, dplus_surface, dplus_tangential, fickian_shift, move_particle
from ..wcsph import pc_correct_particle, pc_predict_particle
from .gpu_kernels import (DTS, N_BAD, N_BAND, N_OUT, STOP, V2, _block_max, _view, fluid_kernel,
                          kernel, permute_kernel)
from .per_particle import clear_rows

k_permute_pc = permute_kernel(
    "k_permute_pc", N_SORTED_PC,
    """neighbours.permute with the symplectic step's rows (N_SORTED_PC: x..m and xn..rhon).""")


@kernel
def k_predict(buf, n, prm, clk, ctl):
    """wcsph.pc_predict: state n saved, half step of x, v, rho with the rates at x^n."""
    if ctl[STOP] != 0:
        return
    i = cuda.grid(1)
    if i < n and buf[1][i] == FLUID:
        pc_predict_particle(buf[0], i, clk[DTS], prm)


@kernel
def k_correct(buf, n, prm, clk, ctl):
    """wcsph.pc_correct: the corrector, guard counts, block-reduced max |v|^2, |a|^2, rho."""
    if ctl[STOP] != 0:
        return
    i = cuda.grid(1)
    v2 = 0.0
    a2 = 0.0
    r = 0.0
    if i < n and buf[1][i] == FLUID:
        bad, band, out, v2, a2, r = pc_correct_particle(buf[0], i, clk[DTS], prm)
        if bad != 0:
            cuda.atomic.add(ctl, N_BAD, 1)
        if band != 0:
            cuda.atomic.add(ctl, N_BAND, 1)
        if out != 0:
            cuda.atomic.add(ctl, N_OUT, 1)
    _block_max(clk, v2, a2, r)


@kernel
def k_shift_fickian(buf, n, cells, prm, clk, ctl):
    """shifting.shift_particles' first loop: the Fickian shift and carries of every fluid
    particle into the scratch rows xn, zn, rhon, vxn, vzn (zero for the other slots)."""
    if ctl[STOP] != 0:
        return
    i = cuda.grid(1)
    if i < n:
        clear_rows(buf[0], i, XN, RHON)
        if buf[1][i] == FLUID:
            ps = _view(buf)
            ps.xn[i], ps.zn[i], ps.rhon[i], ps.vxn[i], ps.vzn[i] = fickian_shift(
                i, ps, cells, prm, clk[DTS])


@kernel
def k_dplus_surface(buf, n, cells, prm, clk, ctl):
    """shift_particles_dplus' pass 1 (scratch rows zeroed first): B, lambda, the normal, the
    shift, the renormalised gradients and the surface flag; U = max |v| of this step (clk[V2],
    reduced by the kick or the corrector)."""
    if ctl[STOP] != 0:
        return
    i = cuda.grid(1)
    if i < n:
        clear_rows(buf[0], i, XN, RHON)
        clear_rows(buf[0], i, GPX, GWZ)
        if buf[1][i] == FLUID:
            ps = _view(buf)
            coef = prm.shift_a * prm.h * math.sqrt(clk[V2]) * clk[DTS]
            # rows as shift_particles_dplus names them: flag guz, grad rho (vxn, vzn), grad vx
            # (rhon, gux), grad vz (gwx, gwz), dr (xn, zn), n (gpx, gpz)
            (ps.guz[i], ps.vxn[i], ps.vzn[i], ps.rhon[i], ps.gux[i], ps.gwx[i], ps.gwz[i],
             ps.xn[i], ps.zn[i], ps.gpx[i], ps.gpz[i]) = dplus_surface(i, ps, cells, prm, coef)


@kernel
def k_dplus_tangential(buf, n, cells, prm, ctl):
    """shift_particles_dplus' pass 2: surface particles and their vicinity shift tangentially;
    the carries into _move's rows."""
    if ctl[STOP] != 0:
        return
    i = cuda.grid(1)
    if i < n and buf[1][i] == FLUID:
        ps = _view(buf)
        if ps.guz[i] != FS_ISOLATED:
            ps.xn[i], ps.zn[i], ps.rhon[i], ps.vxn[i], ps.vzn[i] = dplus_tangential(
                i, ps, cells, prm)


@kernel
def k_shift_move(buf, n, ctl):
    """shifting._move: apply the gathered shifts and carries (after every particle's sums)."""
    if ctl[STOP] != 0:
        return
    i = cuda.grid(1)
    if i < n and buf[1][i] == FLUID:
        move_particle(buf[0], i)


@kernel
def k_muscl_gradients(buf, n, cells, prm, ctl):
    """riemann.riemann_gradients: the MUSCL gradients of p, vx, vz (rows gpx..gwz)."""
    if ctl[STOP] != 0:
        return
    i = cuda.grid(1)
    if i < n:
        f = buf[0]
        (f[GPX, i], f[GPZ, i], f[GUX, i], f[GUZ, i], f[GWX, i],
         f[GWZ, i]) = muscl_gradients(i, _view(buf), cells, prm)


k_fluid_riemann = fluid_kernel(
    "k_fluid_riemann", True,
    """wcsph.fluid_pass with Riemann SPH's flux (terms.riemann_pair).""")
