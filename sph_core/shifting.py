"""Particle shifting with free-surface detection: two laws (scene ``constants.shifting``).

``shift_particles``: Fickian (Lind et al. 2012; Skillen et al. 2013). ``shift_particles_dplus``:
delta-plus SPH (Sun, Colagrossi, Marrone, Zhang 2017) with the free-surface detection of Marrone
et al. 2010 (its own docstring). Both carry rho and v of the shifted particle to first order
unless ``prm.shift_carry`` is off. The renormalisation matrix B_i below is computed here, in the
shifting pass (a kernel-gradient-correction pass computes the same matrix; share it when both run).

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
the wave of bench/wave_decay.py: none for the better at h/dp 2 (docs/wave_decay_study.md).

delta-plus uses 11 scratch rows (xn, zn, vxn, vzn, rhon and the MUSCL gradient rows gpx..gwz,
which riemann_gradients rewrites before every use) for three passes: B, lambda, the normal, the
shift, the gradients and the surface scan; the vicinity test and the projection; the move.
"""

from __future__ import annotations

import math

from numba import njit, prange

from .kernels import f_of_q, w_of_q
from .neighbours import block_of
from .particles import FLUID, INLET, OUTLET, WALL

# next to an open end's buffer (an active buffer particle within 2h; scene
# constants.shift_open_end): 0 "full" shift, 1 "tangential" (no component along the face
# normal, x), 2 "none". The buffer is a lattice moved by the imposed flow, and the crossing rules
# count fluid in and out by where particles are: a shift beside it moves fluid that the imposed
# flux did not carry. Measured (docs/wave_decay_study.md, 2026-11-23 "flume-vs-tank gap",
# oscillating flow through both ends, delta-plus): "tangential" gains water fast (the vertical
# shift alone beside the buffer's fixed rows), "none" keeps the count as without shifting.
SHIFT_OPEN_END = {"full": 0, "tangential": 1, "none": 2}


@njit(cache=True, inline="always")
def _open_end_rule(sx, sz, rule):
    if rule == 1:
        return 0.0, sz
    if rule == 2:
        return 0.0, 0.0
    return sx, sz


@njit(parallel=True, cache=True)
def shift_particles(ps, n, cells, prm, dt):
    """Shift every fluid particle of the sorted state ``ps`` by A = ``prm.shift_a`` (see the
    module docstring); |dr| <= 0.05 h << the cell size, so the cell lists stay valid."""
    x = ps.x
    z = ps.z
    vx = ps.vx
    vz = ps.vz
    rho = ps.rho
    m = ps.m
    kind = ps.kind
    cell = ps.cell
    cell_start = cells.start
    ncx = cells.ncx
    h = prm.h
    alpha_f = prm.alpha_f
    coef = prm.shift_a
    fs_div = prm.shift_fs_div
    shift_open = prm.shift_open
    max_shift = 0.05 * h
    s2 = 4.0 * h * h
    inv_h = 1.0 / h
    sxr = ps.xn    # scratch rows (see the module docstring)
    szr = ps.zn
    srho = ps.rhon
    svx = ps.vxn
    svz = ps.vzn
    for i in prange(n):
        sxr[i] = 0.0
        szr[i] = 0.0
        srho[i] = 0.0
        svx[i] = 0.0
        svz[i] = 0.0
        if kind[i] != FLUID:
            continue
        xi = x[i]
        zi = z[i]
        gcx = 0.0
        gcz = 0.0
        bxx = bxz = bzz = 0.0
        # velocity and density gradients (for the first-order carry of v and rho)
        gux = guz = gwx = gwz = grx = grz = 0.0
        near_buf = False   # an active open-end buffer particle within 2h
        cxl, cxh, czl, czh = block_of(cell[i], cells)
        for zz in range(czl, czh + 1):
            row = zz * ncx
            for j in range(cell_start[row + cxl], cell_start[row + cxh + 1]):
                kj = kind[j]
                if j == i or kj < FLUID or kj > OUTLET:
                    continue
                dx = xi - x[j]
                dz = zi - z[j]
                r2 = dx * dx + dz * dz
                if r2 >= s2:
                    continue
                if kj == INLET or kj == OUTLET:
                    near_buf = True
                fv = f_of_q(math.sqrt(r2) * inv_h, alpha_f) * m[j] / rho[j]
                # grad_i W_ij = -F r_ij
                gcx -= fv * dx
                gcz -= fv * dz
                bxx += fv * dx * dx
                bxz += fv * dx * dz
                bzz += fv * dz * dz
                if kj != WALL:  # walls carry no flow field of their own
                    du = vx[j] - vx[i]
                    dw = vz[j] - vz[i]
                    gux -= fv * du * dx
                    guz -= fv * du * dz
                    gwx -= fv * dw * dx
                    gwz -= fv * dw * dz
                dr = rho[j] - rho[i]
                grx -= fv * dr * dx
                grz -= fv * dr * dz
        dcoef = coef * h * math.sqrt(vx[i] * vx[i] + vz[i] * vz[i]) * dt
        sx = -dcoef * gcx
        sz = -dcoef * gcz
        if bxx + bzz < fs_div:  # div r = trace B
            # renormalised normal n = -B^-1 grad C / |.| (Marrone et al. 2010; Sun et al. 2017):
            # grad C itself is parallel to the shift and cannot split it
            det = bxx * bzz - bxz * bxz
            if det > 1e-6:
                lx = (bzz * gcx - bxz * gcz) / det
                lz = (bxx * gcz - bxz * gcx) / det
            else:
                lx = gcx
                lz = gcz
            gn = math.sqrt(lx * lx + lz * lz)
            if gn > 0.0:
                nx = -lx / gn
                nz = -lz / gn
                sn = sx * nx + sz * nz
                sx -= sn * nx
                sz -= sn * nz
        if near_buf:
            sx, sz = _open_end_rule(sx, sz, shift_open)
        s = math.sqrt(sx * sx + sz * sz)
        if s > max_shift:
            sx *= max_shift / s
            sz *= max_shift / s
        sxr[i] = sx
        szr[i] = sz
        # first-order carry of rho and v to the new position
        if prm.shift_carry:
            srho[i] = sx * grx + sz * grz
            svx[i] = sx * gux + sz * guz
            svz[i] = sx * gwx + sz * gwz
    for i in prange(n):
        if kind[i] == FLUID:
            x[i] += sxr[i]
            z[i] += szr[i]
            rho[i] += srho[i]
            vx[i] += svx[i]
            vz[i] += svz[i]


# --- delta-plus shifting (Sun, Colagrossi, Marrone, Zhang 2017; Marrone et al. 2010) -----------

DPLUS_R = 0.2            # anti-clustering term 1 + R (W_ij / W(dp))^n of Sun et al. 2017
DPLUS_N = 4
LAMBDA_ISOLATED = 0.2    # lambda_i (smallest eigenvalue of B_i) at or below: a splash / jet, no shift
LAMBDA_INTERIOR = 0.75   # above: full support, not a surface candidate (Marrone et al. 2010)
FS_INTERIOR = 0.0        # flags of pass 1 (stored in the scratch row ps.guz)
FS_SURFACE = 1.0
FS_ISOLATED = 2.0
FS_NEAR_BUFFER = 4.0     # added to the flag: an active open-end buffer particle within 2h


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
    x = ps.x
    z = ps.z
    vx = ps.vx
    vz = ps.vz
    rho = ps.rho
    m = ps.m
    kind = ps.kind
    cell = ps.cell
    cell_start = cells.start
    ncx = cells.ncx
    h = prm.h
    alpha_f = prm.alpha_f
    alpha_w = prm.alpha_w
    inv_wdp = prm.shift_inv_wdp
    coef = prm.shift_a * h * umax * dt
    carry = prm.shift_carry
    shift_open = prm.shift_open
    max_shift = 0.05 * h
    s2 = 4.0 * h * h
    inv_h = 1.0 / h
    scan2 = 2.0 * h * h       # |r_ji| < sqrt(2) h: the umbrella test, else the circle
    # scratch rows: dr (xn, zn), n (gpx, gpz), flag (guz), the gradients of rho (vxn, vzn),
    # of vx (rhon, gux), of vz (gwx, gwz); pass 2 overwrites dr and puts the carries in
    # vxn (rho), vzn (vx), rhon (vz)
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
    # pass 1: B, lambda, the normal, the shift, the gradients; the surface scan
    for i in prange(n):
        sxr[i] = 0.0
        szr[i] = 0.0
        snx[i] = 0.0
        snz[i] = 0.0
        flag[i] = FS_INTERIOR
        grx[i] = grz[i] = gux[i] = guz[i] = gwx[i] = gwz[i] = 0.0
        if kind[i] == FLUID:
            xi = x[i]
            zi = z[i]
            gcx = gcz = 0.0       # sum V grad W (the normal)
            wcx = wcz = 0.0       # the same with the anti-clustering weight (the shift)
            bxx = bxz = bzz = 0.0
            ax_ = az_ = ux = uz = wx = wz = 0.0
            near_buf = False   # an active open-end buffer particle within 2h
            cxl, cxh, czl, czh = block_of(cell[i], cells)
            for zz in range(czl, czh + 1):
                row = zz * ncx
                for j in range(cell_start[row + cxl], cell_start[row + cxh + 1]):
                    kj = kind[j]
                    if j == i or kj < FLUID or kj > OUTLET:
                        continue
                    dx = xi - x[j]
                    dz = zi - z[j]
                    r2 = dx * dx + dz * dz
                    if r2 >= s2:
                        continue
                    if kj == INLET or kj == OUTLET:
                        near_buf = True
                    q = math.sqrt(r2) * inv_h
                    fv = f_of_q(q, alpha_f) * m[j] / rho[j]
                    wr = w_of_q(q, alpha_w) * inv_wdp
                    wr2 = wr * wr
                    wgt = 1.0 + DPLUS_R * wr2 * wr2
                    gcx -= fv * dx            # grad_i W_ij = -F r_ij
                    gcz -= fv * dz
                    wcx -= wgt * fv * dx
                    wcz -= wgt * fv * dz
                    bxx += fv * dx * dx
                    bxz += fv * dx * dz
                    bzz += fv * dz * dz
                    dr = rho[j] - rho[i]
                    ax_ -= fv * dr * dx
                    az_ -= fv * dr * dz
                    if kj != WALL:  # walls carry no flow field of their own
                        du = vx[j] - vx[i]
                        dw = vz[j] - vz[i]
                        ux -= fv * du * dx
                        uz -= fv * du * dz
                        wx -= fv * dw * dx
                        wz -= fv * dw * dz
            half_tr = 0.5 * (bxx + bzz)
            hd = 0.5 * (bxx - bzz)
            lam = half_tr - math.sqrt(hd * hd + bxz * bxz)
            det = bxx * bzz - bxz * bxz
            if lam <= LAMBDA_ISOLATED or det <= 1e-6:
                flag[i] = FS_ISOLATED
            else:
                # renormalised gradients (first-order consistent up to the surface)
                lx = (bzz * gcx - bxz * gcz) / det
                lz = (bxx * gcz - bxz * gcx) / det
                grx[i] = (bzz * ax_ - bxz * az_) / det
                grz[i] = (bxx * az_ - bxz * ax_) / det
                gux[i] = (bzz * ux - bxz * uz) / det
                guz[i] = (bxx * uz - bxz * ux) / det
                gwx[i] = (bzz * wx - bxz * wz) / det
                gwz[i] = (bxx * wz - bxz * wx) / det
                sxr[i] = -coef * wcx
                szr[i] = -coef * wcz
                gn = math.sqrt(lx * lx + lz * lz)
                if gn > 0.0:
                    nx = -lx / gn
                    nz = -lz / gn
                    snx[i] = nx
                    snz[i] = nz
                    if lam <= LAMBDA_INTERIOR:
                        # scan: is any neighbour in the region around T = r_i + h n?
                        tx = xi + h * nx
                        tz = zi + h * nz
                        occupied = False
                        for zz in range(czl, czh + 1):
                            row = zz * ncx
                            for j in range(cell_start[row + cxl], cell_start[row + cxh + 1]):
                                kj = kind[j]
                                if occupied or j == i or kj < FLUID or kj > OUTLET:
                                    continue
                                dx = x[j] - xi
                                dz = z[j] - zi
                                r2 = dx * dx + dz * dz
                                if r2 >= s2:
                                    continue
                                ex = x[j] - tx
                                ez = z[j] - tz
                                if r2 >= scan2:
                                    occupied = ex * ex + ez * ez < h * h
                                else:
                                    occupied = (abs(ex * nx + ez * nz)
                                                + abs(ez * nx - ex * nz)) < h
                        if not occupied:
                            flag[i] = FS_SURFACE
            if near_buf:
                flag[i] += FS_NEAR_BUFFER
    # pass 2: the surface and its vicinity (within 2h of a surface particle) shift tangentially
    for i in prange(n):
        fl = flag[i]
        near_buf = fl >= FS_NEAR_BUFFER
        if near_buf:
            fl -= FS_NEAR_BUFFER
        if kind[i] == FLUID and fl != FS_ISOLATED:
            near = fl == FS_SURFACE
            if not near:
                xi = x[i]
                zi = z[i]
                cxl, cxh, czl, czh = block_of(cell[i], cells)
                for zz in range(czl, czh + 1):
                    row = zz * ncx
                    for j in range(cell_start[row + cxl], cell_start[row + cxh + 1]):
                        if near or kind[j] != FLUID or (flag[j] != FS_SURFACE and flag[j]
                                                        != FS_SURFACE + FS_NEAR_BUFFER):
                            continue
                        dx = xi - x[j]
                        dz = zi - z[j]
                        near = dx * dx + dz * dz < s2
            sx = sxr[i]
            sz = szr[i]
            if near:
                sn = sx * snx[i] + sz * snz[i]
                sx -= sn * snx[i]
                sz -= sn * snz[i]
            if near_buf:
                sx, sz = _open_end_rule(sx, sz, shift_open)
            s = math.sqrt(sx * sx + sz * sz)
            if s > max_shift:
                sx *= max_shift / s
                sz *= max_shift / s
            sxr[i] = sx
            szr[i] = sz
            if carry:
                crho = sx * grx[i] + sz * grz[i]
                cu = sx * gux[i] + sz * guz[i]
                cw = sx * gwx[i] + sz * gwz[i]
            else:
                crho = cu = cw = 0.0
            grx[i] = crho
            grz[i] = cu
            gux[i] = cw
    for i in prange(n):
        fl = flag[i]
        if kind[i] == FLUID and fl != FS_ISOLATED and fl != FS_ISOLATED + FS_NEAR_BUFFER:
            x[i] += sxr[i]
            z[i] += szr[i]
            rho[i] += grx[i]
            vx[i] += grz[i]
            vz[i] += gux[i]
