"""Riemann SPH (seed 003, SPH-flow style): the interface state and limiter of the pair term
``terms.riemann_pair`` (``wcsph.fluid_pass`` with ``prm.riemann``), and the MUSCL gradient pass
that runs before it.

Each pair (i, j) solves a one-dimensional Riemann problem along e = (r_j - r_i)/|r_j - r_i| at
its mid-point (Vila 1999; Zhang, Hu & Adams 2017, J. Comput. Phys. 335, 605-620):
left state (U_L, P_L) from i, right state (U_R, P_R) from j, U = v . e. The linearised (acoustic)
solver, with rho_bar = (rho_i + rho_j)/2, Z = rho_bar c0:

    U* = (U_L + U_R)/2 + (P_L - P_R) / (2 Z)
    P* = (P_L + P_R)/2 + beta Z (U_L - U_R) / 2

beta = 1: the plain Godunov flux (Vila); low-dissipation (Zhang et al. 2017, eq. 19):
beta = min(eta max(U_L - U_R, 0) / c0, 1), eta = 3: no dissipation in expansion, and in
compression a dissipation quadratic in the velocity jump. The rates replace continuity,
delta-SPH, pressure and Monaghan viscosity of WCSPH (laminar viscosity stays):

    drho_i/dt = 2 rho_i sum_j V_j (U_i - U*) F_ij |r_ij|         (= (v_i - v*) . grad_i W_ij)
    dv_i/dt   = 2 sum_j V_j P* / rho_i F_ij r_ij                  (= -2 sum m_j P*/(rho_i rho_j) grad_i W_ij)

Reconstruction (MUSCL, van Leer 1979): without it U_L, P_L = U_i, p_i, and the pressure jump
of the hydrostatic state itself drives density diffusion. With it each side is extrapolated to
the mid-point with its particle's gradient, limited against the pair's own difference
d = phi_j - phi_i:  phi_L = phi_i + lim(grad phi_i . r_ji, d)/2,  phi_R = phi_j - lim(grad phi_j . r_ji, d)/2.
A linear field gives phi_L = phi_R exactly (no dissipation); at an extremum the limiter returns 0
(first order, full dissipation). Both limiters keep |lim| <= |d|, so each side stops at the
mid-point at most: van Leer's harmonic mean 2ad/(a + d) is used for |a| < |d| only (above, d, as
minmod). Unbounded, van Leer's slope reaches 2d where a particle's gradient is poor (near the
surface, corners): the two extrapolations then cross, the flux turns anti-dissipative, and the
still-water tank blew up (bed pressure 80-90 % off, 0.35 m/s; with the crossed states merely
reset to their mean it still did). Gradients are kernel-corrected (exact for linear fields wherever
the neighbour moment matrix is invertible): grad phi_i = L_i^-1 sum_j V_j (phi_j - phi_i) F_ij r_ji,
L_i = sum_j V_j F_ij r_ji (x) r_ji; pressure over fluid, buffer and wall neighbours (the Adami
wall pressure continues the fluid's), velocity over fluid and buffer neighbours only (the walls'
no-slip ghost velocity is not a smooth continuation of the flow).

Walls: the Adami dummy state of wcsph.wall_pass (pressure); the wall side takes the wall
particle's own velocity and, with MUSCL, the fluid particle's pressure gradient (wall particles
have none), so a hydrostatic wall state has no pressure jump. The velocity dissipation against
walls is scaled by ``prm.alpha_wall`` as WCSPH's artificial viscosity against walls is.
"""

from __future__ import annotations

from numba import njit, prange

from .particles import FLUID, GPX, GPZ, GUX, GUZ, GWX, GWZ, OUTLET
from .renormalisation import moments, solve

# Params.limiter: 0 no reconstruction, 1 MUSCL with van Leer's limiter (the minmod limiter and
# Zhang et al.'s low-dissipation beta were measured and retired: docs/decisions/)
NO_RECONSTRUCTION = 0
VANLEER = 1
_FASTMATH = {"nsz", "arcp", "contract", "afn", "reassoc"}


@njit(cache=True, inline="always")
def limited(a, d):
    """Van Leer's limited slope from the gradient's estimate ``a`` and the pair difference
    ``d``, capped at |d|; 0 when they disagree in sign; d when a == d."""
    if a * d <= 0.0:
        return 0.0
    if abs(a) >= abs(d):
        return d
    # van Leer's harmonic mean, used only below |d|: beyond it the extrapolation passes the
    # mid-point (see the module docstring)
    return 2.0 * a * d / (a + d)


@njit(cache=True, inline="always")
def interface_state(ul, ur, pl, pr, zc, wall_factor):
    """(U*, P*) of the linearised Riemann problem (module docstring), beta = 1."""
    du = ul - ur
    ustar = 0.5 * (ul + ur) + 0.5 * (pl - pr) / zc
    return ustar, 0.5 * (pl + pr) + 0.5 * wall_factor * zc * du


@njit(cache=True, inline="always")
def muscl_gradients(i, ps, cells, prm):
    """(gpx, gpz, gux, guz, gwx, gwz): the kernel-corrected gradients of p, vx, vz of slot i
    (zero outside the fluid..buffer kinds, and where the moment matrix is near singular); one
    particle's share of ``riemann_gradients``: the CUDA step's kernel calls the same function."""
    ki = ps.kind[i]
    gpx = gpz = gux = guz = gwx = gwz = 0.0
    if ki >= FLUID and ki <= OUTLET:
        # moment matrices: all neighbours M (pressure), fluid and buffers Mf (velocity)
        s = moments(i, ps, cells, prm, ps.p, ps.vx, ps.vz, True)
        # invert where well conditioned: det relative to the isotropic (tr/2)^2 above 5 %
        det = s.mxx * s.mzz - s.mxz * s.mxz
        tr = s.mxx + s.mzz
        if tr > 0.0 and det > 0.0125 * tr * tr:
            gpx, gpz = solve(s.mxx, s.mxz, s.mzz, det, s.phix, s.phiz)
        det = s.mfxx * s.mfzz - s.mfxz * s.mfxz
        tr = s.mfxx + s.mfzz
        if tr > 0.0 and det > 0.0125 * tr * tr:
            gux, guz = solve(s.mfxx, s.mfxz, s.mfzz, det, s.ux, s.uz)
            gwx, gwz = solve(s.mfxx, s.mfxz, s.mfzz, det, s.wx, s.wz)
    return gpx, gpz, gux, guz, gwx, gwz


@njit(parallel=True, cache=True, fastmath=_FASTMATH)
def riemann_gradients(ps, n, cells, prm):
    """Kernel-corrected gradients of p, vx, vz of every fluid and buffer particle (rows gpx..gwz;
    zero elsewhere, and where the neighbour moment matrix is near singular: first order there),
    from the shared walk renormalisation.moments (``muscl_gradients``). (Wall particles, inside
    the kind range, get gradients too; nothing reads them.)"""
    f = ps.f   # writes through the storage: numba drops prange stores made through ps.row[i]
    for i in prange(n):
        (f[GPX, i], f[GPZ, i], f[GUX, i], f[GUZ, i], f[GWX, i],
         f[GWZ, i]) = muscl_gradients(i, ps, cells, prm)
