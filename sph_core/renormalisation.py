"""The renormalisation matrix and the first-order neighbour sums built with it: ONE neighbour
walk (``moments``, through pairs.gather) that both shifting laws (shifting.py), ISPH's corrected pressure gradient (isph/passes.py) and Riemann SPH's MUSCL
gradients (riemann.py) share.

For particle i and its neighbours j (fluid, wall, active buffer; j != i), r_ji = r_j - r_i,
V_j = m_j / rho_j, grad_i W_ij = F_ij r_ji (kernels.py):

    M_i     = sum_j V_j F_ij r_ji (x) r_ji         the renormalisation matrix (symmetric 2x2;
                                                 the B_i of Marrone et al. 2010, Sun et al. 2017)
    g_i     = sum_j V_j grad_i W_ij              (grad C of the shifting laws)
    a_i     = sum_j (1 + R (W_ij / W(dp))^4) V_j grad_i W_ij   (delta-plus anti-clustering, R 0.2)
    s_i     = sum_j V_j W_ij                     (Shepard sum without the self term)
    d_i[phi] = sum_j V_j (phi_j - phi_i) grad_i W_ij   for phi: the row ``phi`` over every
               neighbour, the rows ``u``, ``w`` over fluid and buffer neighbours only (walls carry
               no flow field of their own)
    Mf_i    = M_i over fluid and buffer neighbours only (renormalises d_i[u], d_i[w] in Riemann
              SPH's MUSCL gradients; the shifting laws take M_i for them)

L_i = M_i^-1 makes L_i d_i[phi] exact for a linear phi wherever M_i is invertible (Bonet & Lok
1999). lambda_i, the smallest eigenvalue of M_i, is Marrone et al.'s free-surface indicator
(~1 with a full support, where M ~ I; ~0.5 in the top row of a flat surface at h/dp 2; ~0 for
a splash).

Why one walk function and not one stored pass: no two callers evaluate M at the same state.
Riemann SPH's MUSCL gradients take it in the force pass, before the kick
changes rho; the shifting after the kick (kdk) or after the corrector (symplectic_pc: other
positions); ISPH at r^n with the solved pressure (its wall filter below), its shifting at r^{n+1}.
A pass storing M for another caller would add a neighbour walk per use (shifting's one walk
costs ~0.5x a step), so every caller inlines ``moments`` into its own pass, and what it does not
read is compiled away (inline="always", then LLVM's dead-code elimination).

Each caller keeps its own test of a near-singular M_i (they were tuned separately; unifying
them would change results): Riemann SPH det M > 0.0125 (tr M)^2, the
shifting laws det M > 1e-6 (delta-plus also lambda > 0.2), ISPH det M > 0.01.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

from numba import njit

from .kernels import f_of_q, w_of_q
from .pairs import gather, interacting
from .particles import WALL

DPLUS_R = 0.2     # anti-clustering term 1 + R (W_ij / W(dp))^n of Sun et al. 2017
DPLUS_N = 4       # (the exponent is written out as wr2 * wr2 in ``moments``)


class Moments(NamedTuple):
    """The sums of ``moments`` for one particle (module docstring)."""

    mxx: float    # M
    mxz: float
    mzz: float
    gx: float     # g = sum V grad W
    gz: float
    acx: float    # a = the same with the delta-plus anti-clustering weight
    acz: float
    shepard: float  # sum V W over the neighbours (no self term)
    phix: float   # d[phi] (every neighbour)
    phiz: float
    ux: float     # d[u] (fluid and buffer neighbours)
    uz: float
    wx: float     # d[w]
    wz: float
    mfxx: float   # Mf (fluid and buffer neighbours)
    mfxz: float
    mfzz: float


class MomentsCtx(NamedTuple):
    """What ``moments_pair`` reads besides the particles."""

    inv_h: float
    alpha_f: float
    alpha_w: float
    inv_wdp: float
    phi: Any
    u: Any
    w: Any
    phii: float
    ui: float
    wi: float
    suction_walls: bool


MOMENTS_ZERO = Moments(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
                       0.0, 0.0)


@njit(cache=True, inline="always")
def moments_pair(i, j, dx, dy, dz, r2, ps, ctx, a):
    """One neighbour's share of the sums of ``moments``; ctx as built there."""
    c = ctx
    wall = ps.kind[j] == WALL
    if wall and not c.suction_walls and ps.p[j] < 0.0:
        return a
    rx = -dx
    rz = -dz
    q = math.sqrt(r2) * c.inv_h
    vol = ps.m[j] / ps.rho[j]
    fv = vol * f_of_q(q, c.alpha_f)
    fx = fv * rx                 # V_j grad_i W_ij
    fz = fv * rz
    wk = w_of_q(q, c.alpha_w)
    wr = wk * c.inv_wdp
    wr2 = wr * wr
    wgt = 1.0 + DPLUS_R * wr2 * wr2
    d = c.phi[j] - c.phii
    mfxx = a.mfxx
    mfxz = a.mfxz
    mfzz = a.mfzz
    ux = a.ux
    uz = a.uz
    wx = a.wx
    wz = a.wz
    if not wall:
        mfxx += fx * rx
        mfxz += fx * rz
        mfzz += fz * rz
        du = c.u[j] - c.ui
        dw = c.w[j] - c.wi
        ux += du * fx
        uz += du * fz
        wx += dw * fx
        wz += dw * fz
    return Moments(a.mxx + fx * rx, a.mxz + fx * rz, a.mzz + fz * rz, a.gx + fx, a.gz + fz,
                   a.acx + wgt * fx, a.acz + wgt * fz, a.shepard + vol * wk, a.phix + d * fx,
                   a.phiz + d * fz, ux, uz, wx, wz, mfxx, mfxz, mfzz)


@njit(cache=True, inline="always")
def moments(i, ps, cells, prm, phi, u, w, suction_walls):
    """The neighbour sums of particle i (module docstring), over fluid, wall and active buffer
    neighbours within 2h; ``suction_walls`` False leaves out a wall neighbour with p < 0 (ISPH:
    the air side of a wetted wall). ``phi``, ``u``, ``w`` are particle rows (any, when unused)."""
    ctx = MomentsCtx(1.0 / prm.h, prm.alpha_f, prm.alpha_w, prm.shift_inv_wdp, phi, u, w, phi[i],
                     u[i], w[i], suction_walls)
    return gather(i, ps.x[i], ps.y[i], ps.z[i], ps.cell[i], ps, cells, 4.0 * prm.h * prm.h, interacting,
                  moments_pair, ctx, MOMENTS_ZERO)


@njit(cache=True, inline="always")
def smallest_eigenvalue(mxx, mxz, mzz):
    """lambda_min of the symmetric 2x2 matrix [[mxx, mxz], [mxz, mzz]]."""
    hd = 0.5 * (mxx - mzz)
    return 0.5 * (mxx + mzz) - math.sqrt(hd * hd + mxz * mxz)


@njit(cache=True, inline="always")
def solve(mxx, mxz, mzz, det, bx, bz):
    """M^-1 b for the symmetric M with determinant ``det`` (the caller has checked it)."""
    return (mzz * bx - mxz * bz) / det, (mxx * bz - mxz * bx) / det
