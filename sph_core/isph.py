"""Incompressible SPH (ISPH): the projection method of Cummins & Rudman (1999) as in seed 004.

Selected by a scene's ``[scheme] kind = "isph"``; ``Simulation`` then steps with an
``IsphStepper`` (a Python loop over jitted passes: the sparse pressure solve runs in scipy /
pyamg) instead of ``step.run``. Density is constant (rho0, every particle's mass rho0 dp^2); the
pressure comes from a Poisson equation each step, not from an equation of state, so there is no
sound speed and the time step follows the flow speed.

One step (i fluid, j neighbour, r_ij = r_i - r_j, grad_i W_ij = -F_ij r_ij, V_j = m_j / rho0),
on the sorted state at t^n (docs/schemes.md "## ISPH" has the measurements behind each choice):

1. free surface (Dirichlet p = 0): the position divergence sum_j V_j F_ij r_ij^2 <= 1.5
   (``free_surface_threshold``; 2 inside the fluid in 2D, Lind et al. 2012; seed 004's density
   criterion is retired: docs/decisions/free_surface.md);
2. predictor (eq. 7): u*_i = u^n_i + dt (g + nu lap u_i), the Lo & Shao (2002) laminar term of
   wcsph.fluid_pass; walls: Adami et al. (2012) no-slip velocity;
3. pressure Poisson equation (eq. 9-12), one sparse system over the interior fluid particles
   and the wall particles that have fluid neighbours:
     fluid i:  sum_j B_ij (p_i - p_j) = -div u*_i / dt + relax (rho_k,i - rho_ref) / (rho_ref dt_ref^2)
               B_ij = 8 m_j / (rho_i + rho_j)^2 F_ij r_ij^2 / (r_ij^2 + eta^2),  eta = 0.1 h   (Shao & Lo 2003)
               div u*_i = sum_f V_f (u*_f - u*_i) . grad_i W_if   over fluid f    (Khayyer et al. 2009)
               the last term (Asai et al. 2012, ``isph_density_relaxation``) with dt_ref the
               nominal step cfl h / v_ref in place of dt: rho_k = sum m W, rho_ref the initial
               interior lattice's value (~1.006 rho0);
     wall s:   p_s - sum_f w_sf p_f = sum_f w_sf rho_f [(g - a_s) . r_sf + max(0, -u_n,f / dt) (n_s . r_fs)]
               w_sf = W_sf / sum_f W_sf (Adami et al. 2012, seed 004 eq. 22, linear in the fluid
               pressures) plus a no-penetration part: u_n,f = (u_f - v_s) . n_s the fluid's
               approach speed, n_s the unit vector from the wall into its fluid neighbours.
   The walls enter the fluid rows through their pressure only (a ghost-pressure Neumann
   condition): with the wall velocity also in div u* the hydrostatic column came out 1.45x too
   heavy, and with the plain Adami rows fluid driven at the bed went through it (the wall pressure
   rises with the fluid's). Free-surface particles enter with p = 0. Solved by ``ppe_solver``:
   ``bicgstab`` (the default) = BiCGSTAB preconditioned by the diagonal, jitted, ``amg`` =
   BiCGSTAB preconditioned by smoothed-aggregation AMG (pyamg), both warm-started from the last
   pressure (the seed's Jacobi iteration, ILU and SuperLU are retired:
   docs/decisions/ppe_solver.md). The no-penetration part
   stops the approach within ``isph_wall_stop`` steps (rho |u_n| d / (stop dt)); it and the
   source scale as 1/dt, so ``IsphStepper.run`` never ends a run on a sliver step;
4. corrector (eq. 16-17): u^{n+1} = u* - dt grad p_i / rho0, r^{n+1} = r^n + dt (u^n + u^{n+1}) / 2,
   grad p by the renormalised difference B_i^-1 sum_j V_j (p_j - p_i) grad_i W_ij (Bonet & Lok
   1999), seed eq. 5 only where B_i is near-singular (seed eq. 5 everywhere is retired: the
   surface layer, its kernel cut, fell at ~g/3; docs/decisions/isph_gradient.md); wall
   particles with p < 0 (the air side of a wetted wall) are left out like air
   (docs/decisions/isph_dry_walls.md);
5. open ends (the hooks of step.py's kdk step, same places): update_buffers after the drift
   (buffers imposed and moved, crossings), extrapolate_buffers after the sort, measure_boundaries
   at the end; then every particle's density is reset to rho0 (the buffers' Tait density of
   open_boundary.py is WCSPH's); sort by cell, then Fickian particle shifting (Lind et al. 2012,
   sph_core.shifting).

Open ends: active buffer particles are Dirichlet neighbours of the PPE: their pressure is known
(open_boundary.py's rules; ISPH inlets extrapolate by default, scene.ISPH_INLET_PRESSURE) and
moves to the right-hand side of the fluid and wall rows; they count in div u* (with their imposed
velocity), the viscous term and the free-surface criterion as fluid neighbours (docs/schemes.md
"ISPH with open ends and bodies"). Rigid bodies (fixed, prescribed) are WALL rows moving with
the body; their loads come from the step's pressure after the solve (free and hinged bodies are
refused by the scene: that explicit coupling is unstable for a body lighter than its added mass).

The PPE is solved at r^n rather than at seed 004's intermediate r* = r^n + dt u* (eq. 8): one
neighbour search per step instead of two. The time step (no sound speed):
    dt = min(isph_cfl h / max(|v|_max, v_ref), 0.25 sqrt(h / max|g + nu lap u|), 0.125 h^2 / nu),
v_ref = isph_vref_factor sqrt(2 g H) (H the water height), the a-priori speed of Lind et al.
(2012): without it a tank at rest steps at the force limit 0.25 sqrt(h/g), 7x larger (tried only
before the wall rows above were settled, where it did not help; not re-measured since).
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit, prange

from .bodies import bodies_kick, bodies_kick_drift, bodies_v2max, body_loads, place_bodies
from .kernels import f_of_q, w_of_q
from .neighbours import block_of, sort_by_cell
from .open_boundary import extrapolate_buffers, measure_boundaries, update_buffers
from .particles import FLUID, INLET, N_SORTED_KDK, OUTLET, WALL
from .renormalisation import moments, solve
from .shifting import shift_particles
from .wcsph import (FASTMATH, ST_CAPACITY, ST_LEFT_DOMAIN, ST_NONFINITE, ST_REACHED_T,
                    ST_STEP_LIMIT)

PPE_SOLVERS = ("bicgstab", "amg")
MAX_ROW = 64   # non-zeros per PPE row, generous: a full 2D support at h/dp 2 has ~50 neighbours


@njit(parallel=True, cache=True, fastmath=FASTMATH)
def free_surface_flags(ps, n, cells, prm, threshold, flag, rho_k):
    """flag[i] = 1 for a free-surface fluid particle, 0 for an interior one, -1 for the rest;
    rho_k[i] = sum_j m_j W_ij (fluid and wall, self included) of every fluid particle."""
    x = ps.x
    z = ps.z
    m = ps.m
    kind = ps.kind
    cell = ps.cell
    cell_start = cells.start
    ncx = cells.ncx
    h = prm.h
    inv_h = 1.0 / h
    s2 = 4.0 * h * h
    aw = prm.alpha_w
    af = prm.alpha_f
    rho0 = prm.rho0
    for i in prange(n):
        flag[i] = -1
        if kind[i] == FLUID:
            sr = 0.0
            sdiv = 0.0
            cxl, cxh, czl, czh = block_of(cell[i], cells)
            for zz in range(czl, czh + 1):
                row = zz * ncx
                for j in range(cell_start[row + cxl], cell_start[row + cxh + 1]):
                    if 0 <= kind[j] <= OUTLET:   # fluid, wall, active buffer (open ends)
                        dx = x[i] - x[j]
                        dz = z[i] - z[j]
                        r2 = dx * dx + dz * dz
                        if r2 < s2:
                            q = math.sqrt(r2) * inv_h
                            sr += m[j] * w_of_q(q, aw)
                            sdiv += m[j] / rho0 * f_of_q(q, af) * r2
            rho_k[i] = sr
            flag[i] = 1 if sdiv <= threshold else 0


@njit(parallel=True, cache=True, fastmath=FASTMATH)
def wall_state(ps, n, cells, prm, dt, stop, wsum, dwall):
    """Adami et al. (2012) for every wall particle s from its fluid neighbours f:
    wsum[s] = sum_f W_sf, dwall[s] = sum_f W_sf rho_f (g - a_s) . r_sf / wsum (the hydrostatic
    part of p_s) plus the no-penetration part (module docstring; ``stop`` = isph_wall_stop),
    and the no-slip velocity vw_s = 2 v_s - sum_f v_f W_sf / wsum. Active buffer
    particles of open ends count as f, with their known pressure moved into dwall (their sum
    W_sf p_f / wsum): the wall row then has unknowns for the fluid only."""
    x = ps.x
    z = ps.z
    vx = ps.vx
    vz = ps.vz
    ax = ps.ax
    az = ps.az
    rho = ps.rho
    # a local binding: numba 0.68 drops prange stores made through ps.p[i]
    p = ps.p
    vwx = ps.vwx
    vwz = ps.vwz
    kind = ps.kind
    cell = ps.cell
    cell_start = cells.start
    ncx = cells.ncx
    h = prm.h
    inv_h = 1.0 / h
    s2 = 4.0 * h * h
    aw = prm.alpha_w
    for i in prange(n):
        wsum[i] = 0.0
        dwall[i] = 0.0
        if kind[i] == WALL:
            bx = prm.gx - ax[i]
            bz = prm.gz - az[i]
            sw = 0.0
            sd = 0.0
            svx = 0.0
            svz = 0.0
            nx = 0.0
            nz = 0.0
            cxl, cxh, czl, czh = block_of(cell[i], cells)
            for zz in range(czl, czh + 1):
                row = zz * ncx
                for j in range(cell_start[row + cxl], cell_start[row + cxh + 1]):
                    kj = kind[j]
                    if kj == FLUID or kj == INLET or kj == OUTLET:
                        dx = x[i] - x[j]
                        dz = z[i] - z[j]
                        r2 = dx * dx + dz * dz
                        if r2 < s2:
                            w = w_of_q(math.sqrt(r2) * inv_h, aw)
                            sw += w
                            sd += rho[j] * (bx * dx + bz * dz) * w
                            if kj != FLUID:  # an open end's buffer: its pressure is known
                                sd += p[j] * w
                            svx += vx[j] * w
                            svz += vz[j] * w
                            nx -= dx * w
                            nz -= dz * w
            # the no-penetration part: fluid approaching the wall (relative normal velocity
            # u_n < 0, n from the wall into the fluid) must stop within tau, so the ghost
            # pressure rises by rho |u_n| d / tau over each neighbour f, d = n . r_fs, with
            # tau = stop dt (stop = isph_wall_stop steps, 1: within the step)
            nn = math.sqrt(nx * nx + nz * nz)
            if nn > 0.0:
                nx /= nn
                nz /= nn
                for zz in range(czl, czh + 1):
                    row = zz * ncx
                    for j in range(cell_start[row + cxl], cell_start[row + cxh + 1]):
                        if kind[j] == FLUID:
                            dx = x[i] - x[j]
                            dz = z[i] - z[j]
                            r2 = dx * dx + dz * dz
                            if r2 < s2:
                                un = (vx[j] - vx[i]) * nx + (vz[j] - vz[i]) * nz
                                if un < 0.0:
                                    w = w_of_q(math.sqrt(r2) * inv_h, aw)
                                    d = -(dx * nx + dz * nz)
                                    sd += rho[j] * (-un) * d / (stop * dt) * w
            wsum[i] = sw
            if sw > 0.0:
                dwall[i] = sd / sw
                vwx[i] = 2.0 * vx[i] - svx / sw
                vwz[i] = 2.0 * vz[i] - svz / sw
            else:
                p[i] = 0.0
                vwx[i] = vx[i]
                vwz[i] = vz[i]


@njit(parallel=True, cache=True, fastmath=FASTMATH)
def predict(ps, n, cells, prm, dt):
    """u* = u^n + dt (g + nu lap u) for the fluid (eq. 7); u^n kept in vxn, vzn. Returns
    max |g + nu lap u|^2 (the force limit of the time step)."""
    x = ps.x
    z = ps.z
    vx = ps.vx
    vz = ps.vz
    ax = ps.ax
    az = ps.az
    rho = ps.rho
    m = ps.m
    vxn = ps.vxn
    vzn = ps.vzn
    vwx = ps.vwx
    vwz = ps.vwz
    kind = ps.kind
    cell = ps.cell
    cell_start = cells.start
    ncx = cells.ncx
    h = prm.h
    inv_h = 1.0 / h
    s2 = 4.0 * h * h
    eta2 = 0.01 * h * h
    af = prm.alpha_f
    nu4 = 4.0 * prm.nu
    noslip = prm.noslip
    for i in prange(n):
        if kind[i] == FLUID:
            fx = 0.0
            fz = 0.0
            cxl, cxh, czl, czh = block_of(cell[i], cells)
            for zz in range(czl, czh + 1):
                row = zz * ncx
                for j in range(cell_start[row + cxl], cell_start[row + cxh + 1]):
                    kj = kind[j]
                    if j != i and (kj == FLUID or kj == INLET or kj == OUTLET
                                   or (kj == WALL and noslip)):
                        dx = x[i] - x[j]
                        dz = z[i] - z[j]
                        r2 = dx * dx + dz * dz
                        if r2 < s2:
                            if kj == WALL:
                                dvx = vx[i] - vwx[j]
                                dvz = vz[i] - vwz[j]
                            else:
                                dvx = vx[i] - vx[j]
                                dvz = vz[i] - vz[j]
                            lam = (nu4 * r2 * m[j] / ((rho[i] + rho[j]) * (r2 + eta2))
                                   * f_of_q(math.sqrt(r2) * inv_h, af))
                            fx -= lam * dvx
                            fz -= lam * dvz
            ax[i] = fx + prm.gx
            az[i] = fz + prm.gz
    a2max = 0.0
    for i in prange(n):
        if kind[i] == FLUID:
            vxn[i] = vx[i]
            vzn[i] = vz[i]
            vx[i] += dt * ax[i]
            vz[i] += dt * az[i]
            a2max = max(a2max, ax[i] * ax[i] + az[i] * az[i])
    return a2max


@njit(cache=True)
def ppe_unknowns(ps, n, flag, wsum, idx):
    """idx[i] = the unknown of slot i (interior fluid, wetted wall), -1 if none; returns the count."""
    k = 0
    for i in range(n):
        if flag[i] == 0 or (ps.kind[i] == WALL and wsum[i] > 0.0):
            idx[i] = k
            k += 1
        else:
            idx[i] = -1
    return k


@njit(parallel=True, cache=True, fastmath=FASTMATH)
def ppe_assemble(ps, n, cells, prm, dt, idx, wsum, dwall, wscale, indptr, indices, data, b,
                 x0, slot, rho_k, rho_ref, relax):
    """Fill the PPE rows (module docstring, step 3) in CSR with MAX_ROW slots per row (the
    unused tail of a row is padding the caller compacts); b the right-hand side, x0 the warm
    start (the last pressure), slot[k] the particle of unknown k. Returns the largest row length.
    Wall rows are scaled by ``wscale`` (a typical fluid diagonal) for a balanced system."""
    inv_dt = 1.0 / dt
    longest = 0
    for i in prange(n):
        k = idx[i]
        if k >= 0:
            longest = max(longest, _assemble_row(ps, i, k, cells, prm, inv_dt, idx, wsum, dwall,
                                                 wscale, indptr, indices, data, b, x0, slot,
                                                 rho_k, rho_ref, relax))
    return longest


@njit(cache=True, fastmath=FASTMATH)
def _assemble_row(ps, i, k, cells, prm, inv_dt, idx, wsum, dwall, wscale, indptr, indices, data,
                  b, x0, slot, rho_k, rho_ref, relax):
    """Row k (particle i) of the PPE; returns its length."""
    x = ps.x
    z = ps.z
    vx = ps.vx
    vz = ps.vz
    p = ps.p
    m = ps.m
    rho = ps.rho
    kind = ps.kind
    cell = ps.cell
    cell_start = cells.start
    ncx = cells.ncx
    h = prm.h
    inv_h = 1.0 / h
    s2 = 4.0 * h * h
    eta2 = 0.01 * h * h
    af = prm.alpha_f
    aw = prm.alpha_w
    slot[k] = i
    x0[k] = p[i]
    base = indptr[k]
    cnt = 1          # position 0 of the row: the diagonal
    indices[base] = k
    if kind[i] == FLUID:
        diag = 0.0
        div = 0.0
        known = 0.0
        cxl, cxh, czl, czh = block_of(cell[i], cells)
        for zz in range(czl, czh + 1):
            row = zz * ncx
            for j in range(cell_start[row + cxl], cell_start[row + cxh + 1]):
                kj = kind[j]
                if j == i or not (0 <= kj <= OUTLET):   # fluid, wall, active buffer
                    continue
                dx = x[i] - x[j]
                dz = z[i] - z[j]
                r2 = dx * dx + dz * dz
                if r2 >= s2:
                    continue
                fij = f_of_q(math.sqrt(r2) * inv_h, af)
                # div u*_i = sum_j V_j (u*_j - u*_i) . grad_i W_ij, grad_i W_ij = -F r_ij, over
                # the fluid: the walls' part is their ghost pressure (the Neumann condition)
                # fluid, or an open end's buffer with its imposed velocity (with an outlet's
                # buffer in through its pressure only, the outlet's bottom corner drained:
                # 1.4 m/s there at 0.7 s; docs/schemes.md "ISPH with open ends and bodies")
                if kj != WALL:
                    div -= m[j] / rho[j] * fij * ((vx[j] - vx[i]) * dx + (vz[j] - vz[i]) * dz)
                rs = rho[i] + rho[j]
                bij = 8.0 * m[j] / (rs * rs) * fij * r2 / (r2 + eta2)
                diag += bij
                kk = idx[j]
                if kk >= 0 and cnt < MAX_ROW:
                    indices[base + cnt] = kk
                    data[base + cnt] = -bij
                    cnt += 1
                elif kj >= INLET:  # a buffer particle: Dirichlet, its pressure is known
                    known += bij * p[j]
        data[base] = diag
        # density-invariance relaxation (Asai et al. 2012): a kernel density above the lattice's
        # pushes apart, below pulls together, so volume errors do not accumulate
        b[k] = -div * inv_dt + relax * (rho_k[i] - rho_ref) / rho_ref + known
    else:  # wall: p_s - sum_f w_sf p_f = dwall_s, scaled
        inv_sw = wscale / wsum[i]
        data[base] = wscale
        b[k] = wscale * dwall[i]
        cxl, cxh, czl, czh = block_of(cell[i], cells)
        for zz in range(czl, czh + 1):
            row = zz * ncx
            for j in range(cell_start[row + cxl], cell_start[row + cxh + 1]):
                kk = idx[j]
                if kind[j] == FLUID and kk >= 0:
                    dx = x[i] - x[j]
                    dz = z[i] - z[j]
                    r2 = dx * dx + dz * dz
                    if r2 < s2 and cnt < MAX_ROW:
                        indices[base + cnt] = kk
                        data[base + cnt] = -w_of_q(math.sqrt(r2) * inv_h, aw) * inv_sw
                        cnt += 1
    for c in range(cnt, MAX_ROW):
        indices[base + c] = -1
    return cnt


@njit(cache=True)
def compact_rows(m, indptr, indices, data, out_ptr):
    """Drop the padding (-1 columns) of the m rows in place; out_ptr receives the CSR pointers."""
    w = 0
    out_ptr[0] = 0
    for k in range(m):
        for c in range(indptr[k], indptr[k + 1]):
            if indices[c] >= 0:
                indices[w] = indices[c]
                data[w] = data[c]
                w += 1
        out_ptr[k + 1] = w
    return w


@njit(parallel=True, cache=True)
def scatter_pressure(ps, m, slot, sol, flag):
    """p of every unknown from the solution; free-surface fluid p = 0. Walls keep a negative
    solution (unlike wcsph.wall_pass's no-suction clamp): the corrector must see the pressures
    the solve balanced, or the divergence it removed comes back at the surface corners."""
    p = ps.p
    for k in prange(m):
        p[slot[k]] = sol[k]
    for i in prange(flag.size):
        if flag[i] == 1:
            p[i] = 0.0


@njit(parallel=True, cache=True, fastmath=FASTMATH)
def correct(ps, n, cells, prm, dt):
    """u^{n+1} = u* - dt (grad p / rho)_i (eq. 16), r^{n+1} = r^n + dt (u^n + u^{n+1}) / 2
    (eq. 17); grad p by the renormalised difference B_i^-1 sum_j V_j (p_j - p_i) grad_i W_ij
    (Bonet & Lok 1999), exact for a linear field on a truncated support (B_i, the sum:
    renormalisation.moments), seed eq. 5 (symmetric) where det B_i <= 0.01. Wall particles with
    p < 0 (the air side of a wetted wall, above the free surface) are left out like air: with
    them the surface corners of still water crept away from the wall.
    Returns (#non-finite, #outside the tank box, max |v|^2)."""
    x = ps.x
    z = ps.z
    vx = ps.vx
    vz = ps.vz
    ax = ps.ax
    az = ps.az
    p = ps.p
    m = ps.m
    rho = ps.rho
    vxn = ps.vxn
    vzn = ps.vzn
    kind = ps.kind
    cell = ps.cell
    cell_start = cells.start
    ncx = cells.ncx
    h = prm.h
    inv_h = 1.0 / h
    s2 = 4.0 * h * h
    af = prm.alpha_f
    for i in prange(n):
        if kind[i] == FLUID:
            fx = 0.0
            fz = 0.0
            symmetric = True
            # grad p = M^-1 sum_j V_j (p_j - p_i) grad_i W_ij over the neighbours below
            s = moments(i, ps, cells, prm, p, vx, vz, False)
            det = s.mxx * s.mzz - s.mxz * s.mxz
            if det > 0.01:  # 1 on a full 2D lattice support
                gpx, gpz = solve(s.mxx, s.mxz, s.mzz, det, s.phix, s.phiz)
                fx = -gpx / rho[i]
                fz = -gpz / rho[i]
                symmetric = False
            if symmetric:
                # -(1/rho) grad p = sum_j m_j (p_i/rho_i^2 + p_j/rho_j^2) F r_ij
                cxl, cxh, czl, czh = block_of(cell[i], cells)
                for zz in range(czl, czh + 1):
                    row = zz * ncx
                    for j in range(cell_start[row + cxl], cell_start[row + cxh + 1]):
                        kj = kind[j]
                        if j != i and 0 <= kj <= OUTLET and (kj != WALL or p[j] >= 0.0):
                            dx = x[i] - x[j]
                            dz = z[i] - z[j]
                            r2 = dx * dx + dz * dz
                            if r2 < s2:
                                fij = f_of_q(math.sqrt(r2) * inv_h, af)
                                pf = m[j] * (p[i] / (rho[i] * rho[i]) + p[j] / (rho[j] * rho[j]))
                                fx += pf * fij * dx
                                fz += pf * fij * dz
            # the pressure acceleration; with the predictor's, (u^{n+1} - u^n) / dt
            ax[i] = fx
            az[i] = fz
    n_bad = 0
    n_out = 0
    v2max = 0.0
    for i in prange(n):
        if kind[i] == FLUID:
            u = vx[i] + dt * ax[i]
            w = vz[i] + dt * az[i]
            ax[i] = (u - vxn[i]) / dt
            az[i] = (w - vzn[i]) / dt
            xi = x[i] + 0.5 * dt * (u + vxn[i])
            zi = z[i] + 0.5 * dt * (w + vzn[i])
            vx[i] = u
            vz[i] = w
            x[i] = xi
            z[i] = zi
            v2 = u * u + w * w
            if not np.isfinite(v2):
                n_bad += 1
            elif not (xi >= prm.fx0 and xi <= prm.fx1 and zi >= prm.fz0 and zi <= prm.fz1):
                n_out += 1
            v2max = max(v2max, v2)
    return n_bad, n_out, v2max


@njit(cache=True, fastmath=FASTMATH)
def _spmv(indptr, indices, data, x, y, m):
    for k in range(m):
        s = 0.0
        for c in range(indptr[k], indptr[k + 1]):
            s += data[c] * x[indices[c]]
        y[k] = s


@njit(cache=True, fastmath=FASTMATH)
def bicgstab_jacobi(indptr, indices, data, b, x, m, tol, max_iter, w):
    """BiCGSTAB (van der Vorst 1992) preconditioned by the diagonal (first in each row), in
    place on the warm start x; w is (8, >= m) scratch. No set-up and no Python per iteration:
    on these small systems (10^3-10^4 unknowns, warm-started) that beats building an AMG
    hierarchy every step. Returns (iterations, relative residual)."""
    r = w[0]
    rh = w[1]
    p = w[2]
    v = w[3]
    ph = w[4]
    sv = w[5]
    sh = w[6]
    t = w[7]
    _spmv(indptr, indices, data, x, t, m)
    bn = 0.0
    rn = 0.0
    for k in range(m):
        r[k] = b[k] - t[k]
        rh[k] = r[k]
        p[k] = 0.0
        v[k] = 0.0
        bn += b[k] * b[k]
        rn += r[k] * r[k]
    bn = math.sqrt(bn)
    if bn == 0.0:
        bn = 1.0
    rel = math.sqrt(rn) / bn
    rho = 1.0
    alpha = 1.0
    omega = 1.0
    it = 0
    while rel > tol and it < max_iter:
        rho1 = 0.0
        for k in range(m):
            rho1 += rh[k] * r[k]
        if rho1 == 0.0 or omega == 0.0:  # breakdown: restart from the current residual
            for k in range(m):
                rh[k] = r[k]
                p[k] = 0.0
                v[k] = 0.0
            rho = alpha = omega = 1.0
            rho1 = 0.0
            for k in range(m):
                rho1 += r[k] * r[k]
        beta = (rho1 / rho) * (alpha / omega)
        rho = rho1
        for k in range(m):
            p[k] = r[k] + beta * (p[k] - omega * v[k])
            ph[k] = p[k] / data[indptr[k]]
        _spmv(indptr, indices, data, ph, v, m)
        rv = 0.0
        for k in range(m):
            rv += rh[k] * v[k]
        if rv == 0.0:  # breakdown with nothing left to gain: return the current iterate
            break
        alpha = rho / rv
        sn = 0.0
        for k in range(m):
            sv[k] = r[k] - alpha * v[k]
            sn += sv[k] * sv[k]
        it += 1
        if math.sqrt(sn) / bn <= tol:
            for k in range(m):
                x[k] += alpha * ph[k]
            rel = math.sqrt(sn) / bn
            break
        for k in range(m):
            sh[k] = sv[k] / data[indptr[k]]
        _spmv(indptr, indices, data, sh, t, m)
        ts = 0.0
        tt = 0.0
        for k in range(m):
            ts += t[k] * sv[k]
            tt += t[k] * t[k]
        omega = ts / tt if tt > 0.0 else 0.0
        rn = 0.0
        for k in range(m):
            x[k] += alpha * ph[k] + omega * sh[k]
            r[k] = sv[k] - omega * t[k]
            rn += r[k] * r[k]
        rel = math.sqrt(rn) / bn
    return it, rel


def solve_ppe(solver: str, m: int, ptr: np.ndarray, indices: np.ndarray, data: np.ndarray,
              b: np.ndarray, x0: np.ndarray, tol: float, max_iter: int,
              scratch: np.ndarray) -> tuple[np.ndarray, int, float]:
    """Solve the m x m CSR system (diagonal first in each row) by ``solver`` (PPE_SOLVERS) from
    the warm start ``x0`` (overwritten by ``bicgstab``); returns (solution, iterations,
    relative residual |b - A x| / |b|)."""
    if solver == "bicgstab":
        work = scratch.reshape(-1)[: 8 * m].reshape(8, m) if scratch.size >= 8 * m else np.empty((8, m))
        it, rel = bicgstab_jacobi(ptr, indices, data, b, x0, m, tol, max_iter, work)
        return x0, int(it), float(rel)
    if solver != "amg":
        raise ValueError(f"ppe_solver: one of {PPE_SOLVERS}, got {solver!r}")
    import pyamg  # only this solver needs it
    nnz = int(ptr[m])
    a = sp.csr_matrix((data[:nnz], indices[:nnz], ptr[: m + 1]), shape=(m, m))
    pre = pyamg.smoothed_aggregation_solver(a, symmetry="nonsymmetric",
                                            max_coarse=200).aspreconditioner()
    count = [0]

    def _count(_xk: np.ndarray) -> None:
        count[0] += 1

    sol, _info = spla.bicgstab(a, b, x0=x0, rtol=tol, atol=0.0, maxiter=max_iter, M=pre,
                               callback=_count)
    bn = float(np.linalg.norm(b)) or 1.0
    return sol, int(count[0]), float(np.linalg.norm(b - a @ sol)) / bn


def isph_dt(v2max: float, a2max: float, prm: Any, v_ref: float = 0.0) -> float:
    """dt = min(cfl h / max(|v|_max, v_ref), 0.25 sqrt(h / max|a*|), 0.125 h^2 / nu): no sound
    speed; v_ref is the scene's own speed scale sqrt(2 g H) (Lind et al. 2012 take the step
    from such an a-priori speed)."""
    h = prm.h
    dt = math.inf
    v = max(math.sqrt(v2max), v_ref)
    if v > 0.0:
        dt = prm.cfl * h / v
    if a2max > 0.0:
        dt = min(dt, 0.25 * math.sqrt(h / math.sqrt(a2max)))
    if prm.nu > 0.0:
        dt = min(dt, 0.125 * h * h / prm.nu)
    return dt


class IsphStepper:
    """The ISPH time loop of one Simulation: same call and returns as ``step.run``, plus the PPE
    statistics (``ppe_iterations``, ``ppe_solves``, ``ppe_unknowns``, ``solve_time``)."""

    def __init__(self, capacity: int, prm: Any, dp: float, solver: str = "bicgstab",
                 tolerance: float = 1e-5, max_iter: int = 20000, fs_threshold: float = 1.5,
                 shifting: bool = True, v_ref: float = 0.0,
                 density_relaxation: float = 0.0, wall_stop: float = 1.0) -> None:
        if solver not in PPE_SOLVERS:
            raise ValueError(f"ppe_solver: one of {PPE_SOLVERS}, got {solver!r}")
        self.prm = prm
        self.solver = solver
        self.tol = float(tolerance)
        self.max_iter = int(max_iter)
        self.fs_threshold = float(fs_threshold)
        self.shifting = bool(shifting) and prm.shift_a > 0.0
        self.v_ref = float(v_ref)
        self.wall_stop = float(wall_stop)
        # a typical fluid diagonal sum_j B_ij ~ (2 / rho0) sum_j V_j F_ij = 7 / (rho0 h^2): the
        # scale of the wall rows
        self.wscale = 7.0 / (prm.rho0 * prm.h * prm.h)
        cap = int(capacity)
        self.flag = np.zeros(cap, dtype=np.int8)
        self.rho_k = np.zeros(cap)
        self.rho_ref = 0.0
        self.relax = float(density_relaxation)
        # the relaxation's time scale: the nominal step cfl h / v_ref, not the actual dt (with
        # 1/dt^2 a shrinking step strengthened it, which shrank the step further: the dam break
        # blew up within 0.005 s)
        self.dt_ref = prm.cfl * prm.h / v_ref if v_ref > 0.0 else 0.25 * math.sqrt(
            prm.h / math.hypot(prm.gx, prm.gz))
        self.wsum = np.zeros(cap)
        self.dwall = np.zeros(cap)
        self.idx = np.zeros(cap, dtype=np.int64)
        self.slot = np.zeros(cap, dtype=np.int64)
        self.indptr = np.arange(cap + 1, dtype=np.int64) * MAX_ROW
        self.ptr = np.zeros(cap + 1, dtype=np.int64)
        self.indices = np.zeros(cap * MAX_ROW, dtype=np.int64)
        self.data = np.zeros(cap * MAX_ROW)
        self.b = np.zeros(cap)
        self.x0 = np.zeros(cap)
        self.x2 = np.zeros(8 * cap)  # BiCGSTAB's eight vectors
        self.ppe_iterations = 0
        self.ppe_solves = 0
        self.ppe_unknowns = 0
        self.ppe_max_residual = 0.0
        self.solve_time = 0.0

    # --------------------------------------------------------------- set-up
    def initialise(self, ps: Any, ps2: Any, cells: Any, n: int, ends: Any,
                   bd: Any) -> tuple[float, int]:
        """Place the rigid bodies ``bd`` (bodies.Bodies), sort the initial state into ``ps2``
        (the caller swaps), buffer pressures and boundary gauges of the open ``ends``
        (state.OpenEnds); returns (dt, n)."""
        place_bodies(ps, n, bd)
        n = sort_by_cell(ps, ps2, N_SORTED_KDK, n, cells)
        self._open_ends_sorted(ps2, n, cells, ends)
        g2 = self.prm.gx ** 2 + self.prm.gz ** 2
        return isph_dt(0.0, g2, self.prm, self.v_ref), int(n)

    # --------------------------------------------------------------- one step
    def _solve(self, ps: Any, n: int, cells: Any, dt: float) -> None:
        prm = self.prm
        m = ppe_unknowns(ps, n, self.flag, self.wsum, self.idx)
        longest = ppe_assemble(ps, n, cells, prm, dt, self.idx, self.wsum, self.dwall,
                               self.wscale, self.indptr, self.indices, self.data, self.b, self.x0,
                               self.slot, self.rho_k, self.rho_ref,
                               self.relax / (self.dt_ref * self.dt_ref))
        if longest >= MAX_ROW:  # a row lost terms: the particles are far denser than the lattice
            raise RuntimeError(f"ISPH: a PPE row has more than {MAX_ROW - 1} neighbours")
        compact_rows(m, self.indptr, self.indices, self.data, self.ptr)
        tic = time.perf_counter()
        # pyamg's set-up estimates spectral radii from np.random start vectors: with a fixed
        # seed a run repeats bit for bit (checkpoint / restore, pushed vs pulled open-end data;
        # unseeded they differed by ~1e-9 m after 0.2 s); the caller's random state is kept.
        # The other solvers draw no random numbers.
        rng = np.random.get_state() if self.solver == "amg" else None
        if rng is not None:
            np.random.seed(0)
        try:
            sol, it, rel = solve_ppe(self.solver, m, self.ptr, self.indices, self.data,
                                     self.b[:m], self.x0[:m], self.tol, self.max_iter, self.x2)
        finally:
            if rng is not None:
                np.random.set_state(rng)
        self.solve_time += time.perf_counter() - tic
        self.ppe_iterations += int(it)
        self.ppe_solves += 1
        self.ppe_unknowns = int(m)
        self.ppe_max_residual = max(self.ppe_max_residual, float(rel))
        scatter_pressure(ps, m, self.slot, np.ascontiguousarray(sol), self.flag[:n])

    def _open_ends_sorted(self, ps: Any, n: int, cells: Any, ends: Any) -> None:
        """Open-end hooks on the sorted state: buffer pressures, boundary gauges; constant
        density (the hooks write WCSPH's Tait density into the buffers)."""
        if ends.active:
            extrapolate_buffers(ps, n, cells, ends, self.prm)
            ps.rho[:n] = self.prm.rho0
            measure_boundaries(ps, cells, ends, self.prm)

    def step(self, ps: Any, ps2: Any, cells: Any, n: int, t: float, dt: float,
             ends: Any, bd: Any) -> tuple[int, int, int, float, float]:
        """One projection step from the sorted state ``ps`` at time t with the open ``ends``;
        the state ends sorted in ``ps2``. Returns (n, n_bad, n_out, max |v|^2, max |a*|^2); n < 0:
        the open ends ran out of particle capacity (state in ``ps``, not sorted)."""
        prm = self.prm
        free_surface_flags(ps, n, cells, prm, self.fs_threshold, self.flag, self.rho_k)
        if self.rho_ref == 0.0:  # the initial lattice's interior kernel density (~1.006 rho0)
            inner = self.flag[:n] == 0
            self.rho_ref = float(np.median(self.rho_k[:n][inner])) if inner.any() else prm.rho0
        wall_state(ps, n, cells, prm, dt, self.wall_stop, self.wsum, self.dwall)
        a2 = predict(ps, n, cells, prm, dt)
        self._solve(ps, n, cells, dt)
        if bd.active:
            # rigid bodies are moving walls of the PPE (their particles are WALL rows, with the
            # body's velocity and acceleration in the no-penetration and Adami terms); their
            # loads come from this step's pressure at r^n (bodies._particle_loads: pressure and
            # laminar pair terms; ISPH's Params carry alpha 0, so no artificial viscosity), and
            # they advance over the step with that acceleration (the kdk stages back to back)
            np.maximum(ps.p[:n], 0.0, out=ps.pw[:n])   # no tension across a body's face
            body_loads(ps, n, cells, prm, bd)
            bodies_kick_drift(bd, t, dt)
            bodies_kick(bd, t, dt)
        n_bad, n_out, v2 = correct(ps, n, cells, prm, dt)
        place_bodies(ps, n, bd)
        v2 = max(v2, bodies_v2max(bd))   # a fast body bounds dt as fluid does
        if ends.active:  # after the drift, as step.py's kdk step: buffers moved, crossings
            n = update_buffers(ps, n, t + dt, dt, ends, prm)
            if n < 0:
                return -1, int(n_bad), int(n_out), float(v2), float(a2)
        n = sort_by_cell(ps, ps2, N_SORTED_KDK, n, cells)
        if self.shifting:
            shift_particles(ps2, n, cells, prm, dt)
        self._open_ends_sorted(ps2, n, cells, ends)
        return int(n), int(n_bad), int(n_out), float(v2), float(a2)

    def run(self, ps: Any, ps2: Any, cells: Any, ends: Any, bd: Any, n: int, t: float, dt: float,
            t_stop: float, max_steps: int) -> tuple[float, float, int, int, int, int, float, int]:
        """Steps until t reaches t_stop or max_steps were taken, or a guard trips; returns as
        ``step.run``: (t, dt_next, steps, status, swapped, n_flagged, v_max, n)."""
        swapped = 0
        steps = 0
        status = ST_REACHED_T
        n_flag = 0
        v2 = 0.0
        while True:
            if t >= t_stop:
                status = ST_REACHED_T
                break
            if steps >= max_steps:
                status = ST_STEP_LIMIT
                break
            # no sliver steps: a projection's pressure carries (div u^n) / dt, so a step of a
            # tiny fraction of dt (window and output times meeting) gives a pressure field far
            # from the flow's, which the open ends' buffers then take over (extrapolated) and
            # the probes record. Measured: a 3.7e-5 s step after 2.3e-3 s ones raised the
            # fluid's largest pressure from 2.6 to 7.2 kPa; the open flume blew up within
            # 0.015 s; in the closed dam break such steps before each probe record gave
            # wall-pressure spikes of 10^5-10^7 Pa (docs/schemes.md). So the last two steps
            # share a remainder below 1.5 dt, and a round-off remainder (< 1e-6 dt) is not
            # stepped.
            rem = t_stop - t
            if rem <= 1e-6 * dt:
                t = t_stop
                continue
            last = rem <= dt
            dts = rem if last else (0.5 * rem if rem < 1.5 * dt else dt)
            n_new, n_bad, n_out, v2, a2 = self.step(ps, ps2, cells, n, t, dts, ends, bd)
            if n_new < 0:  # the state stays in ps, as step.run's
                status, n_flag = ST_CAPACITY, n
                break
            n = n_new
            ps, ps2 = ps2, ps
            swapped = 1 - swapped
            t = t_stop if last else t + dts
            steps += 1
            if n_bad:
                status, n_flag = ST_NONFINITE, n_bad
                break
            if n_out:
                status, n_flag = ST_LEFT_DOMAIN, n_out
                break
            dt = isph_dt(v2, a2, self.prm, self.v_ref)
        return t, dt, steps, status, swapped, n_flag, math.sqrt(v2), n

    def stats(self) -> dict[str, Any]:
        """PPE statistics since the start (for meta.json and the benches)."""
        s = max(self.ppe_solves, 1)
        return {"ppe_solver": self.solver, "ppe_solves": self.ppe_solves,
                "ppe_iterations_per_step": self.ppe_iterations / s,
                "ppe_unknowns": self.ppe_unknowns, "ppe_max_residual": self.ppe_max_residual,
                "ppe_solve_time_s": round(self.solve_time, 3)}
