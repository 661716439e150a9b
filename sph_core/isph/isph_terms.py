"""ISPH's per-pair terms: the folds of ``pairs.gather`` that its passes compose (passes.py,
ppe.py), with the physical pieces they share with WCSPH (sph_core.terms: the Adami wall sums,
the laminar viscosity).

Same signature as every term, ``acc = term(i, j, dx, dy, dz, r2, ps, ctx, acc)`` (dx = x_i - x_j; 2D: dy = 0);
``ctx`` is a tuple read by index (numba's parfor analysis rejects unpacking it inside a term).
Equations: the package docstring (r_ij = r_i - r_j, grad_i W_ij = -F_ij r_ij, V_j = m_j / rho0).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from numba import njit

from ..kernels import f_of_q, w_of_q
from ..pairs import fluidlike
from ..particles import FLUID, INLET, WALL
from ..terms import WallSums, adami_sum, kernel_f, viscous_momentum

MAX_ROW = 64   # non-zeros per PPE row, generous: a full 2D support at h/dp 2 has ~50 neighbours


@njit(cache=True, inline="always")
def surface_pair(i, j, dx, dy, dz, r2, ps, ctx, a):
    """(kernel density sum_j m_j W_ij, position divergence sum_j V_j F_ij r_ij^2, count of
    fluid and active buffer neighbours besides itself) of a fluid particle.
    ctx = (inv_h, alpha_w, alpha_f, rho0)."""
    q = math.sqrt(r2) * ctx[0]
    mj = ps.m[j]
    carried = 1 if r2 > 0.0 and fluidlike(ps.kind[j]) else 0
    return (a[0] + mj * w_of_q(q, ctx[1]), a[1] + mj / ctx[3] * f_of_q(q, ctx[2]) * r2,
            a[2] + carried)


class WallRowSums(NamedTuple):
    """What a wall particle gathers: the Adami sums (terms.WallSums, sp without the fluid's
    pressure) and the unnormalised wall normal -sum_j W_ij r_ij."""

    sw: float
    sp: float
    svx: float
    svz: float
    nx: float
    nz: float


WALL_ROW_SUMS_ZERO = WallRowSums(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@njit(cache=True, inline="always")
def wall_pair(i, j, dx, dy, dz, r2, ps, ctx, a):
    """Wall particle i and a fluid or buffer neighbour j: the Adami sums (terms.adami_sum) with
    the fluid's pressure left out (an unknown of the row, as is the pressure of a buffer particle
    with a row of its own, wsum_j > 0; another buffer's is known), and the wall normal.
    ctx = (inv_h, alpha_w, bx, bz, wsum), b = g - a_i."""
    w = w_of_q(math.sqrt(r2) * ctx[0], ctx[1])
    kj = ps.kind[j]
    pj = 0.0 if kj == FLUID or (kj != WALL and ctx[4][j] > 0.0) else ps.p[j]
    s = adami_sum(WallSums(a.sw, a.sp, a.svx, 0.0, a.svz), w, pj, ps.rho[j],
                  ctx[2] * dx + ctx[3] * dz, ps.vx[j], 0.0, ps.vz[j])   # ISPH is 2D (x-z)
    return WallRowSums(s.sw, s.sp, s.svx, s.svz, a.nx - dx * w, a.nz - dz * w)


@njit(cache=True, inline="always")
def wall_stop_pair(i, j, dx, dy, dz, r2, ps, ctx, a):
    """Wall particle i and fluid neighbour j approaching it (u_n = (u_j - v_i) . n < 0, n the
    wall's unit normal into the fluid): the ghost-pressure rise rho_j |u_n| d / tau W_ij that
    stops it within tau, d = n . r_ji. ctx = (inv_h, alpha_w, nx, nz, vx_i, vz_i, tau)."""
    un = (ps.vx[j] - ctx[4]) * ctx[2] + (ps.vz[j] - ctx[5]) * ctx[3]
    if un >= 0.0:
        return a
    w = w_of_q(math.sqrt(r2) * ctx[0], ctx[1])
    d = -(dx * ctx[2] + dz * ctx[3])
    return a + ps.rho[j] * (-un) * d / ctx[6] * w


@njit(cache=True, inline="always")
def viscous_pair(i, j, dx, dy, dz, r2, ps, ctx, a):
    """Fluid particle i and a fluid, buffer or (no-slip) wall neighbour j: Lo & Shao's laminar
    viscosity, terms.viscous_momentum without pressure or artificial viscosity; against a wall
    its Adami no-slip velocity. ctx = (terms.FluidConsts, terms.FluidI); a = (fx, fz)."""
    k = ctx[0]
    fi = ctx[1]
    if ps.kind[j] == WALL:
        if not k.noslip:
            return a
        dvx = fi.vx - ps.vwx[j]
        dvz = fi.vz - ps.vwz[j]
    else:
        dvx = fi.vx - ps.vx[j]
        dvz = fi.vz - ps.vz[j]
    fx, _, fz = viscous_momentum(a[0], 0.0, a[1], 0.0, dvx, 0.0, dvz, dx, dy, dz, r2,
                                 kernel_f(r2, k), fi.rho, ps.rho[j], ps.m[j], 0.0, k)
    return fx, fz


@njit(cache=True, inline="always")
def fluid_row_pair(i, j, dx, dy, dz, r2, ps, ctx, a):
    """Fluid particle i's PPE row and neighbour j (fluid, wall, buffer): the Shao & Lo (2003)
    Laplacian coefficient B_ij into the diagonal and, for an unknown j, the row's column
    (written into ``indices``, ``data`` at base + count: fluid, wall and buffer particles with a
    row); the known pressure of a buffer particle without one goes to the right-hand side; the
    Khayyer et al. (2009) divergence of u* over fluid and buffer neighbours (the walls' part is
    their ghost pressure: the Neumann condition).
    ctx = (inv_h, alpha_f, eta2, vx_i, vz_i, rho_i, idx, indices, data, base, dt gx, dt gz);
    a = (diag, div, known, count)."""
    fij = f_of_q(math.sqrt(r2) * ctx[0], ctx[1])
    kj = ps.kind[j]
    mj = ps.m[j]
    rhoj = ps.rho[j]
    div = a[1]
    if kj == FLUID:
        div -= mj / rhoj * fij * ((ps.vx[j] - ctx[3]) * dx + (ps.vz[j] - ctx[4]) * dz)
    elif kj != WALL:
        # an open end's buffer with its imposed velocity as a u*: u_b + dt g, the velocity the
        # projection's hydrostatic gradient takes back to u_b, as the fluid's u* carries the
        # step's gravity (compared with u_b itself, a buffer at rest was a source of divergence
        # wherever its support is one-sided, the surface rows and the bed, and the still open
        # flume broke down at 2.8 s; left out, the inlet cannot drive a wave;
        # docs/studies/schemes.md "ISPH open ends: the buffers in the projection")
        div -= mj / rhoj * fij * ((ps.vx[j] + ctx[10] - ctx[3]) * dx
                                  + (ps.vz[j] + ctx[11] - ctx[4]) * dz)
    rs = ctx[5] + rhoj
    bij = 8.0 * mj / (rs * rs) * fij * r2 / (r2 + ctx[2])
    known = a[2]
    cnt = a[3]
    kk = ctx[6][j]
    if kk >= 0 and cnt < MAX_ROW:
        ctx[7][ctx[9] + cnt] = kk
        ctx[8][ctx[9] + cnt] = -bij
        cnt += 1
    elif kj >= INLET:  # a buffer particle: Dirichlet, its pressure is known
        known += bij * ps.p[j]
    return (a[0] + bij, div, known, cnt)


@njit(cache=True, inline="always")
def wall_row_pair(i, j, dx, dy, dz, r2, ps, ctx, a):
    """Wall particle i's PPE row and fluid neighbour j: the Adami weight -W_ij / sum W (scaled)
    of j's unknown. ctx = (inv_h, alpha_w, wscale / sum W, idx, indices, data, base);
    a = the row's count."""
    kk = ctx[3][j]
    if kk < 0 or a >= MAX_ROW:
        return a
    ctx[4][ctx[6] + a] = kk
    ctx[5][ctx[6] + a] = -w_of_q(math.sqrt(r2) * ctx[0], ctx[1]) * ctx[2]
    return a + 1


@njit(cache=True, inline="always")
def symmetric_pressure_pair(i, j, dx, dy, dz, r2, ps, ctx, a):
    """-(1/rho) grad p of seed 004 eq. 5, sum_j m_j (p_i/rho_i^2 + p_j/rho_j^2) F_ij r_ij, over
    fluid, buffer and wet wall neighbours (a wall with p < 0, the air side of a wetted wall,
    is left out like air). ctx = (inv_h, alpha_f, p_i / rho_i^2); a = (fx, fz)."""
    rhoj = ps.rho[j]
    pj = ps.p[j]
    if ps.kind[j] == WALL and pj < 0.0:
        return a
    fij = f_of_q(math.sqrt(r2) * ctx[0], ctx[1])
    pf = ps.m[j] * (ctx[2] + pj / (rhoj * rhoj))
    return a[0] + pf * fij * dx, a[1] + pf * fij * dz
