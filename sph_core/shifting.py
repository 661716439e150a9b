"""Particle shifting with free-surface detection: two laws (scene ``constants.shifting``).

``shift_particles``: Fickian (Lind et al. 2012; Skillen et al. 2013). ``shift_particles_dplus``:
delta-plus SPH (Sun, Colagrossi, Marrone, Zhang 2017) with the free-surface detection of Marrone
et al. 2010 (its own docstring). Both carry rho and v of the shifted particle to first order
unless ``prm.shift_carry`` is off. Both take B_i, grad C_i and the gradients from the one
neighbour walk of renormalisation.py (``moments``: B_i there is M_i), shared with the kernel
gradient correction and ISPH.

Fickian: after each step every fluid particle i moves by
    dr_i = -D_i grad C_i,   D_i = A h |v_i| dt   (A = Constants.shift_a),
    grad C_i = sum_j V_j grad_i W_ij = -sum_j V_j F_ij r_ij
(j: fluid, wall and active buffer neighbours; V_j = m_j / rho_j), towards lower particle
concentration: a disordered lattice relaxes back to a regular one, which keeps the kernel sums
(and so the pressure gradient's zeroth-order error) small. Near the free surface the
concentration falls because the fluid ends, not because of disorder: a particle whose position
divergence
    div r_i = trace B_i,   B_i = sum_j V_j F_ij r_ij r_ij^T    (div r = 2 in 2D, full support)
is below ``shift_fs_div`` keeps only the component of dr_i tangent to the surface (Lind et al.
2012: no shifting normal to the surface). The normal is the renormalised
n_i = -B_i^-1 grad C_i / |B_i^-1 grad C_i| (Marrone et al. 2010; Sun et al. 2017): grad C_i itself
is parallel to dr_i and could not split it. The shifted particle's density and velocity are
carried to its new position to first order (Lind et al. 2012), rho_i += dr_i . grad rho_i,
v_i += dr_i . grad v_i, grad phi_i = sum_j V_j (phi_j - phi_i) grad_i W_ij: without it a vertical
shift would keep the hydrostatic density of its old height. |dr_i| is capped at 0.05 h.

The displacement and the carried increments are gathered into the scratch rows xn, zn, vxn,
vzn, rhon (kdk does not use them; symplectic_pc rewrites them at its next predictor) and applied
in a second loop, so no particle reads a neighbour that has already moved. Measured effect on
the wave of bench/wave_decay.py: none for the better at h/dp 2 (docs/studies/wave_decay_study.md).

delta-plus uses 11 scratch rows (xn, zn, vxn, vzn, rhon and the MUSCL gradient rows gpx..gwz,
which riemann_gradients rewrites before every use) for three passes: B, lambda, the normal, the
shift, the gradients and the surface scan; the vicinity test and the projection; the move.
Every neighbour walk here (the moments, the surface scan, the vicinity and open-end tests) is
``pairs.gather`` with a term of this module.
"""

from __future__ import annotations

import math

from numba import njit, prange

from .pairs import fluid_only, gather, interacting
from .particles import FLUID, GPX, GWZ, INLET, OUTLET, RHO, RHON, VZ, X, XN
from .renormalisation import moments, smallest_eigenvalue, solve


@njit(cache=True, inline="always")
def _surface_normal(s, det):
    """The renormalised outward normal n = -M^-1 g / |M^-1 g| of a particle with the sums ``s``
    (renormalisation.Moments; Marrone et al. 2010, Sun et al. 2017), g itself where det M <=
    1e-6; (0, 0) where it vanishes."""
    if det > 1e-6:
        lx, lz = solve(s.mxx, s.mxz, s.mzz, det, s.gx, s.gz)
    else:
        lx = s.gx
        lz = s.gz
    gn = math.sqrt(lx * lx + lz * lz)
    if gn > 0.0:
        return -lx / gn, -lz / gn
    return 0.0, 0.0


@njit(cache=True, inline="always")
def _limited(sx, sz, tangential, nx, nz, max_shift):
    """The shift (sx, sz), with its component along the normal n removed if ``tangential``,
    capped at |dr| = max_shift."""
    if tangential:
        sn = sx * nx + sz * nz
        sx -= sn * nx
        sz -= sn * nz
    ds = math.sqrt(sx * sx + sz * sz)
    if ds > max_shift:
        sx *= max_shift / ds
        sz *= max_shift / ds
    return sx, sz


# next to an open end's buffer (an active buffer particle within 2h; scene
# constants.shift_open_end): 0 "full" shift, 1 "none". The buffer is a lattice moved by the
# imposed flow, and the crossing rules count fluid in and out by where particles are: a shift
# beside it moves fluid that the imposed flux did not carry. Measured (docs/studies/wave_decay_study.md
# "flume-vs-tank gap", oscillating flow through both ends, delta-plus): "none" keeps the count
# as without shifting ("tangential", retired: docs/decisions/shift_open_end.md, gained water).
SHIFT_OPEN_END = {"full": 0, "none": 1}


@njit(cache=True, inline="always")
def _active_buffer(k):
    """Active open-end buffer particles alone."""
    return k == INLET or k == OUTLET


@njit(cache=True, inline="always")
def _any_pair(i, j, dx, dy, dz, r2, ps, ctx, a):
    """True once any neighbour has been seen."""
    return True


@njit(cache=True, inline="always")
def _near_buffer(i, ps, cells, h):
    """Is an active open-end buffer particle within 2h of particle i?"""
    return gather(i, ps.x[i], ps.y[i], ps.z[i], ps.cell[i], ps, cells, 4.0 * h * h, _active_buffer,
                  _any_pair, 0, False)


@njit(cache=True, inline="always")
def _open_end_limited(i, ps, cells, prm, sx, sz, tangential, nx, nz, max_shift):
    """_limited, or no shift at all for a particle beside a buffer under the open-end rule
    prm.shift_open "none"."""
    if prm.shift_open != 0 and _near_buffer(i, ps, cells, prm.h):
        return 0.0, 0.0
    return _limited(sx, sz, tangential, nx, nz, max_shift)


@njit(cache=True, inline="always")
def move_particle(f, i):
    """x, z, vx, vz += xn, zn, vxn, vzn (rows X..VZ and XN..VZN), rho += rhon of slot i of the
    storage ``f``: ``_move``'s body, which the CUDA step's kernel calls too. (2D: shifting is
    refused in 3D scenes.)"""
    for r in range(VZ - X + 1):
        f[X + r, i] += f[XN + r, i]
    f[RHO, i] += f[RHON, i]


@njit(parallel=True, cache=True)
def _move(ps, n):
    """Apply the gathered shifts and carries (rows xn, zn and rhon, vxn, vzn) to every fluid
    particle: a separate loop, so that no particle's sums saw a neighbour already moved."""
    # through the storage f (a local: ``ps.x[i] = ...`` inside a prange writes nothing, numba
    # 0.68.1): rows X..VZ += XN..VZN, rho += rhon
    f = ps.f
    for i in prange(n):
        if ps.kind[i] == FLUID:
            move_particle(f, i)


@njit(cache=True, inline="always")
def fickian_shift(i, ps, cells, prm, dt):
    """(dx, dz, drho, dvx, dvz) of fluid particle i: its Fickian shift and the first-order
    carries of rho and v (zero without ``prm.shift_carry``). One particle's share of
    ``shift_particles``: the CUDA step's kernel calls the same function."""
    h = prm.h
    max_shift = 0.05 * h
    # B, grad C and the (unrenormalised) gradients of rho and v for the first-order carry
    s = moments(i, ps, cells, prm, ps.rho, ps.vx, ps.vz, True)
    vxi = ps.vx[i]
    vzi = ps.vz[i]
    dcoef = prm.shift_a * h * math.sqrt(vxi * vxi + vzi * vzi) * dt
    sx = -dcoef * s.gx
    sz = -dcoef * s.gz
    nx = nz = 0.0
    tangential = s.mxx + s.mzz < prm.shift_fs_div  # div r = trace B
    if tangential:
        # renormalised normal: grad C itself is parallel to the shift and cannot split it
        nx, nz = _surface_normal(s, s.mxx * s.mzz - s.mxz * s.mxz)
    sx, sz = _open_end_limited(i, ps, cells, prm, sx, sz, tangential, nx, nz, max_shift)
    # first-order carry of rho and v to the new position
    if prm.shift_carry:
        return sx, sz, sx * s.phix + sz * s.phiz, sx * s.ux + sz * s.uz, sx * s.wx + sz * s.wz
    return sx, sz, 0.0, 0.0, 0.0


@njit(parallel=True, cache=True)
def shift_particles(ps, n, cells, prm, dt):
    """Shift every fluid particle of the sorted state ``ps`` by A = ``prm.shift_a`` (see the
    module docstring); |dr| <= 0.05 h << the cell size, so the cell lists stay valid."""
    sxr = ps.xn    # scratch rows (see the module docstring), zeroed: non-fluid slots stay put
    szr = ps.zn
    srho = ps.rhon
    svx = ps.vxn
    svz = ps.vzn
    ps.f[XN:RHON + 1, :n] = 0.0
    for i in prange(n):
        if ps.kind[i] != FLUID:
            continue
        sxr[i], szr[i], srho[i], svx[i], svz[i] = fickian_shift(i, ps, cells, prm, dt)
    _move(ps, n)


# --- delta-plus shifting (Sun, Colagrossi, Marrone, Zhang 2017; Marrone et al. 2010) -----------
# (its anti-clustering constants R, n: renormalisation.DPLUS_R, DPLUS_N, with the walk)

LAMBDA_ISOLATED = 0.2    # lambda_i (smallest eigenvalue of B_i) at or below: a splash / jet, no shift
LAMBDA_INTERIOR = 0.75   # above: full support, not a surface candidate (Marrone et al. 2010)
FS_INTERIOR = 0.0        # flags of pass 1 (stored in the scratch row ps.guz; 0: zeroed rows)
FS_SURFACE = 1.0
FS_ISOLATED = 2.0


@njit(cache=True, inline="always")
def _scan_pair(i, j, dx, dy, dz, r2, ps, ctx, occupied):
    """Marrone et al. 2010's scan: is neighbour j in the region around T = r_i + h n, the
    umbrella |e . n| + |e x n| < h (e = r_j - T) within sqrt(2) h of i, else the circle |e| < h?
    ctx = (T_x, T_z, n_x, n_z, h, 2 h^2)."""
    if occupied:
        return True
    ex = ps.x[j] - ctx[0]
    ez = ps.z[j] - ctx[1]
    h = ctx[4]
    if r2 >= ctx[5]:
        return ex * ex + ez * ez < h * h
    return (abs(ex * ctx[2] + ez * ctx[3]) + abs(ez * ctx[2] - ex * ctx[3])) < h


@njit(cache=True, inline="always")
def _surface_pair(i, j, dx, dy, dz, r2, ps, ctx, near):
    """Is neighbour j a surface particle (pass 1's flag, in row guz)?"""
    return near or ps.guz[j] == FS_SURFACE


@njit(cache=True, inline="always")
def dplus_surface(i, ps, cells, prm, coef):
    """Pass 1 of ``shift_particles_dplus`` for fluid particle i, coef = A h U dt: returns (flag,
    grad rho (x, z), grad vx (x, z), grad vz (x, z), dr (x, z), n (x, z)), zeros where not set
    (an isolated particle: its flag alone). The CUDA step's kernel calls the same function."""
    h = prm.h
    s2 = 4.0 * h * h
    scan2 = 2.0 * h * h       # |r_ji| < sqrt(2) h: the umbrella test, else the circle
    s = moments(i, ps, cells, prm, ps.rho, ps.vx, ps.vz, True)
    bxx = s.mxx
    bxz = s.mxz
    bzz = s.mzz
    lam = smallest_eigenvalue(bxx, bxz, bzz)
    det = bxx * bzz - bxz * bxz
    if lam <= LAMBDA_ISOLATED or det <= 1e-6:
        return FS_ISOLATED, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    flag = FS_INTERIOR
    # renormalised gradients (first-order consistent up to the surface)
    grx, grz = solve(bxx, bxz, bzz, det, s.phix, s.phiz)
    gux, guz = solve(bxx, bxz, bzz, det, s.ux, s.uz)
    gwx, gwz = solve(bxx, bxz, bzz, det, s.wx, s.wz)
    sx = -coef * s.acx
    sz = -coef * s.acz
    nx, nz = _surface_normal(s, det)
    if (nx != 0.0 or nz != 0.0) and lam <= LAMBDA_INTERIOR:
        # scan: is any neighbour in the region around T = r_i + h n?
        xi = ps.x[i]
        zi = ps.z[i]
        occupied = gather(i, xi, ps.y[i], zi, ps.cell[i], ps, cells, s2, interacting, _scan_pair,
                          (xi + h * nx, zi + h * nz, nx, nz, h, scan2), False)
        if not occupied:
            flag = FS_SURFACE
    return flag, grx, grz, gux, guz, gwx, gwz, sx, sz, nx, nz


@njit(cache=True, inline="always")
def dplus_tangential(i, ps, cells, prm):
    """Pass 2 of ``shift_particles_dplus`` for fluid particle i that is not isolated, from pass
    1's rows: (dx, dz, drho, dvx, dvz), the shift (tangential at the surface and within 2h of
    it) and the carries. The CUDA step's kernel calls the same function."""
    h = prm.h
    near = ps.guz[i] == FS_SURFACE
    if not near:
        near = gather(i, ps.x[i], ps.y[i], ps.z[i], ps.cell[i], ps, cells, 4.0 * h * h, fluid_only,
                      _surface_pair, 0, False)
    sx, sz = _open_end_limited(i, ps, cells, prm, ps.xn[i], ps.zn[i], near, ps.gpx[i], ps.gpz[i],
                               0.05 * h)
    crho = cu = cw = 0.0
    if prm.shift_carry:
        # gradients of rho (vxn, vzn), vx (rhon, gux), vz (gwx, gwz): pass 1's rows
        crho = sx * ps.vxn[i] + sz * ps.vzn[i]
        cu = sx * ps.rhon[i] + sz * ps.gux[i]
        cw = sx * ps.gwx[i] + sz * ps.gwz[i]
    return sx, sz, crho, cu, cw


@njit(parallel=True, cache=True)
def shift_particles_dplus(ps, n, cells, prm, dt, umax):
    """delta-plus shifting of every fluid particle of the sorted state ``ps``:
        dr_i = -A h U dt sum_j [1 + R (W_ij / W(dp))^n] grad_i W_ij V_j,
    A = ``prm.shift_a`` (4 = Sun et al. 2017's CFL Ma (2h)^2 with Ma = U / c0, CFL = c0 dt / h),
    U = ``umax`` the largest fluid speed. Free surface (Marrone et al. 2010): lambda_i, the smallest
    eigenvalue of B_i = sum_j V_j F_ij r_ij r_ij^T, <= LAMBDA_ISOLATED: no shift; a candidate
    (lambda_i <= LAMBDA_INTERIOR) whose scan region (the cone/umbrella of radius h at h along the
    renormalised normal n_i = -B_i^-1 grad C_i / |.|) holds no neighbour is a surface particle;
    surface particles and those within 2h of one keep only dr - (dr . n) n. With
    ``prm.shift_carry`` the shifted particle's rho and v are carried to the new position by
    their renormalised gradients (first-order Taylor). See the module docstring for the rows."""
    coef = prm.shift_a * prm.h * umax * dt
    # scratch rows: dr (xn, zn), n (gpx, gpz), flag (guz), the gradients of rho (vxn, vzn),
    # of vx (rhon, gux), of vz (gwx, gwz); pass 2 overwrites dr and puts the carries in
    # _move's rows rhon (rho), vxn (vx), vzn (vz)
    sxr = ps.xn
    szr = ps.zn
    snx = ps.gpx
    snz = ps.gpz
    flag = ps.guz
    grx = ps.vxn
    grz = ps.vzn
    gux = ps.rhon
    guz = ps.gux
    gwx = ps.gwx
    gwz = ps.gwz
    # every scratch row zeroed (the flag to FS_INTERIOR, 0)
    ps.f[XN:RHON + 1, :n] = 0.0
    ps.f[GPX:GWZ + 1, :n] = 0.0
    # pass 1: B, lambda, the normal, the shift, the gradients; the surface scan
    for i in prange(n):
        if ps.kind[i] == FLUID:
            (flag[i], grx[i], grz[i], gux[i], guz[i], gwx[i], gwz[i], sxr[i], szr[i], snx[i],
             snz[i]) = dplus_surface(i, ps, cells, prm, coef)
    # pass 2: the surface and its vicinity (within 2h of a surface particle) shift tangentially;
    # the carries go to _move's rows rhon, vxn, vzn (this particle's gradients are read first)
    for i in prange(n):
        if ps.kind[i] == FLUID and flag[i] != FS_ISOLATED:
            sxr[i], szr[i], gux[i], grx[i], grz[i] = dplus_tangential(i, ps, cells, prm)
    _move(ps, n)
