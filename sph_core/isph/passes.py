"""ISPH's passes over the particles (the package docstring has the step): free-surface flags,
the wall state, the predictor, the pressure scatter and the corrector. Each walks its
neighbours through ``pairs.gather`` with a term of terms.py."""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..pairs import fluid_only, fluidlike, gather, interacting
from ..particles import FLUID, INLET, OUTLET, WALL
from ..renormalisation import moments, solve
from ..terms import fluid_consts, fluid_i
from ..wcsph import FASTMATH
from .isph_terms import (WALL_ROW_SUMS_ZERO, surface_pair, symmetric_pressure_pair, viscous_pair,
                    wall_pair, wall_stop_pair)


# a film or drop against a wall: walls fill its divergence's support, so it can read as
# interior, and a cluster of interior particles whose only other neighbours are walls has no
# p = 0 link in the PPE (wall rows copy the fluid's pressure): the system is singular and
# BiCGSTAB returned NaN for every particle (a particle pushed into a 1:10 staircase beach).
# A lattice particle in a tank's corner has 7 fluid neighbours in 2D at h/dp 1.2.
MIN_INTERIOR_NEIGHBOURS = 3


@njit(parallel=True, cache=True, fastmath=FASTMATH)
def free_surface_flags(ps, n, cells, prm, threshold, flag, rho_k):
    """flag[i] = 1 for a free-surface fluid particle (position divergence <= ``threshold``, or
    fewer than MIN_INTERIOR_NEIGHBOURS fluid and buffer neighbours), 0 for an interior one, -1
    for the rest; rho_k[i] = sum_j m_j W_ij (fluid, wall, buffer, self included) of every fluid
    particle."""
    kind = ps.kind
    h = prm.h
    s2 = 4.0 * h * h
    ctx = (1.0 / h, prm.alpha_w, prm.alpha_f, prm.rho0)
    for i in prange(n):
        flag[i] = -1
        if kind[i] == FLUID:
            # walked around the point (slot -1): the self term m_i W(0) counts in rho_k
            sr, sdiv, carried = gather(-1, ps.x[i], ps.y[i], ps.z[i], ps.cell[i], ps, cells, s2,
                                       interacting, surface_pair, ctx, (0.0, 0.0, 0))
            rho_k[i] = sr
            flag[i] = 1 if sdiv <= threshold or carried < MIN_INTERIOR_NEIGHBOURS else 0


@njit(parallel=True, cache=True, fastmath=FASTMATH)
def wall_state(ps, n, cells, prm, dt, stop, wsum, dwall):
    """Adami et al. (2012) for every wall particle s from its fluid neighbours f:
    wsum[s] = sum_f W_sf, dwall[s] = sum_f W_sf rho_f (g - a_s) . r_sf / wsum (the hydrostatic
    part of p_s) plus the no-penetration part (package docstring; ``stop`` = isph_wall_stop),
    and the no-slip velocity vw_s = 2 v_s - sum_f v_f W_sf / wsum. Active buffer
    particles of open ends count as f, with their known pressure moved into dwall (their sum
    W_sf p_f / wsum): the wall row then has unknowns for the fluid only."""
    vx = ps.vx
    vz = ps.vz
    # locals of the rows written: numba drops prange stores made through ps.p[i]
    p = ps.p
    vwx = ps.vwx
    vwz = ps.vwz
    kind = ps.kind
    h = prm.h
    inv_h = 1.0 / h
    s2 = 4.0 * h * h
    aw = prm.alpha_w
    tau = stop * dt
    buffer_rows(ps, n, cells, prm, wsum, dwall)   # first: the wall rows read a buffer's wsum
    for i in prange(n):
        if kind[i] != INLET and kind[i] != OUTLET:
            wsum[i] = 0.0
            dwall[i] = 0.0
        if kind[i] == WALL:
            xi = ps.x[i]
            zi = ps.z[i]
            ctx = (inv_h, aw, prm.gx - ps.ax[i], prm.gz - ps.az[i], wsum)
            s = gather(i, xi, ps.y[i], zi, ps.cell[i], ps, cells, s2, fluidlike, wall_pair, ctx,
                       WALL_ROW_SUMS_ZERO)
            sd = s.sp
            # the no-penetration part: fluid approaching the wall (relative normal velocity
            # u_n < 0, n from the wall into the fluid) must stop within tau, so the ghost
            # pressure rises by rho |u_n| d / tau over each neighbour f, d = n . r_fs, with
            # tau = stop dt (stop = isph_wall_stop steps, 1: within the step)
            nn = math.sqrt(s.nx * s.nx + s.nz * s.nz)
            if nn > 0.0:
                sd = gather(i, xi, ps.y[i], zi, ps.cell[i], ps, cells, s2, fluid_only, wall_stop_pair,
                            (inv_h, aw, s.nx / nn, s.nz / nn, vx[i], vz[i], tau), sd)
            wsum[i] = s.sw
            if s.sw > 0.0:
                dwall[i] = sd / s.sw
                vwx[i] = 2.0 * vx[i] - s.svx / s.sw
                vwz[i] = 2.0 * vz[i] - s.svz / s.sw
            else:
                p[i] = 0.0
                vwx[i] = vx[i]
                vwz[i] = vz[i]


@njit(parallel=True, cache=True, fastmath=FASTMATH)
def buffer_rows(ps, n, cells, prm, wsum, dwall):
    """wsum[b], dwall[b] of every active buffer particle b of an open end: the Adami sums over
    its fluid neighbours, p_b - sum_f w_bf p_f = sum_f w_bf rho_f (g - a_b) . r_bf, a row of the PPE
    (with wsum > 0) solved with the fluid rows: the buffer's pressure follows the fluid's within
    the step, as a wall's does. (Taken from the last step's fluid, the open-end hook's ghost
    extrapolation, it lagged the solve by a step, and the still open flume broke down.) a_b is
    the buffer's imposed acceleration (ax, az: Params.buffer_acceleration): with g alone the
    buffer's pressure had no wave in it beyond the hydrostatic, the fluid beside the face did not
    follow the buffer near the bed, and the wave flume broke down there 2 s sooner
    (docs/studies/schemes.md, "The buffer's pressure with its acceleration")."""
    kind = ps.kind
    inv_h = 1.0 / prm.h
    s2 = 4.0 * prm.h * prm.h
    for i in prange(n):
        if kind[i] == INLET or kind[i] == OUTLET:
            wsum[i] = 0.0
            dwall[i] = 0.0
            s = gather(i, ps.x[i], ps.y[i], ps.z[i], ps.cell[i], ps, cells, s2, fluid_only,
                       wall_pair, (inv_h, prm.alpha_w, prm.gx - ps.ax[i], prm.gz - ps.az[i],
                                   wsum), WALL_ROW_SUMS_ZERO)
            wsum[i] = s.sw
            if s.sw > 0.0:
                dwall[i] = s.sp / s.sw


@njit(parallel=True, cache=True, fastmath=FASTMATH)
def predict(ps, n, cells, prm, dt):
    """u* = u^n + dt (g + nu lap u) for the fluid (eq. 7); u^n kept in vxn, vzn. Returns
    max |g + nu lap u|^2 (the force limit of the time step)."""
    ax = ps.ax
    az = ps.az
    kind = ps.kind
    for i in prange(n):
        if kind[i] == FLUID:
            # built per particle: a NamedTuple live into a prange loop fails parfor lowering
            k = fluid_consts(prm)
            fi = fluid_i(i, ps, k)
            fx, fz = gather(i, fi.x, ps.y[i], fi.z, ps.cell[i], ps, cells, k.s2, interacting,
                            viscous_pair, (k, fi), (0.0, 0.0))
            ax[i] = fx + prm.gx
            az[i] = fz + prm.gz
    return _predict_update(ps, n, dt)


@njit(parallel=True, cache=True, fastmath=FASTMATH)
def _predict_update(ps, n, dt):
    """predict's update, a function of its own: as a second loop of predict, numba's parfor
    fusion merged it into the first, whose neighbour reads through ps.vx[j] it does not see
    as the same array, so a particle read neighbours already updated."""
    vx = ps.vx
    vz = ps.vz
    ax = ps.ax
    az = ps.az
    vxn = ps.vxn
    vzn = ps.vzn
    kind = ps.kind
    a2max = 0.0
    for i in prange(n):
        if kind[i] == FLUID:
            vxn[i] = vx[i]
            vzn[i] = vz[i]
            vx[i] += dt * ax[i]
            vz[i] += dt * az[i]
            a2max = max(a2max, ax[i] * ax[i] + az[i] * az[i])
    return a2max


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
    them the surface corners of still water crept away from the wall. Returns (#non-finite,
    #outside the tank box, max |v|^2)."""
    x = ps.x
    z = ps.z
    vx = ps.vx
    vz = ps.vz
    ax = ps.ax
    az = ps.az
    p = ps.p
    rho = ps.rho
    kind = ps.kind
    h = prm.h
    inv_h = 1.0 / h
    s2 = 4.0 * h * h
    af = prm.alpha_f
    for i in prange(n):
        if kind[i] == FLUID:
            # grad p = M^-1 sum_j V_j (p_j - p_i) grad_i W_ij over the neighbours below
            s = moments(i, ps, cells, prm, p, vx, vz, False)
            det = s.mxx * s.mzz - s.mxz * s.mxz
            if det > 0.01:  # 1 on a full 2D lattice support
                gpx, gpz = solve(s.mxx, s.mxz, s.mzz, det, s.phix, s.phiz)
                fx = -gpx / rho[i]
                fz = -gpz / rho[i]
            else:
                fx, fz = gather(i, x[i], ps.y[i], z[i], ps.cell[i], ps, cells, s2, interacting,
                                symmetric_pressure_pair, (inv_h, af, p[i] / (rho[i] * rho[i])),
                                (0.0, 0.0))
            # the pressure acceleration; with the predictor's, (u^{n+1} - u^n) / dt
            ax[i] = fx
            az[i] = fz
    return _correct_update(ps, n, prm, dt)


@njit(parallel=True, cache=True, fastmath=FASTMATH)
def _correct_update(ps, n, prm, dt):
    """correct's update, a function of its own for the reason of ``_predict_update``."""
    x = ps.x
    z = ps.z
    vx = ps.vx
    vz = ps.vz
    ax = ps.ax
    az = ps.az
    vxn = ps.vxn
    vzn = ps.vzn
    kind = ps.kind
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
