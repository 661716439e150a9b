"""Per-particle bodies of the CUDA step's kernels, one ``@njit(inline="always")`` function per pass.

Each is the loop body of its CPU twin in ``sph_core/wcsph.py`` / ``neighbours.py`` for one
particle slot ``i`` (the same equations, line for line; Riemann SPH and the kernel gradient
correction are not carried: the GPU step refuses scenes that use them). numba compiles them
for whichever target calls them: as device functions inside the CUDA kernels of ``kernels.py``
and as ordinary CPU code under the CUDA simulator, where they run at compiled speed.

The pair loops are here, one function per pass (``wall_particle``, ``fluid_particle``), so
they can be replaced as a whole by the solver's shared per-pair terms (``sph_core/pairs.py``).
"""

from __future__ import annotations

import math

from numba import njit

from ..eos import density, pressure
from ..kernels import f_of_q, w_of_q
from ..neighbours import block_of, cell_at
from ..particles import FLUID, INLET, OUTLET, WALL
from ..wall_contact import approach_speed, no_penetration


@njit(cache=True, inline="always")
def cell_of(i, ps, cells):
    """ps.cell of slot i as ``neighbours.compute_cells`` sets it: clamped to the grid, inactive
    slots in the extra bin ncx * ncz."""
    if ps.kind[i] < 0:
        return cells.ncx * cells.ncz
    return cell_at(ps.x[i], ps.z[i], cells)


@njit(cache=True, inline="always")
def wall_particle(i, ps, cells, prm):
    """``wcsph.wall_pass`` for wall slot i: Adami pressure, density and no-slip velocity."""
    x = ps.x
    z = ps.z
    vx = ps.vx
    vz = ps.vz
    rho = ps.rho
    p = ps.p
    kind = ps.kind
    cell_start = cells.start
    ncx = cells.ncx
    inv_h = 1.0 / prm.h
    s2 = 4.0 * prm.h * prm.h
    aw = prm.alpha_w
    xi = x[i]
    zi = z[i]
    bx = prm.gx - ps.ax[i]
    bz = prm.gz - ps.az[i]
    sw = 0.0
    sp = 0.0
    svx = 0.0
    svz = 0.0
    cxl, cxh, czl, czh = block_of(ps.cell[i], cells)
    for zz in range(czl, czh + 1):
        row = zz * ncx
        for j in range(cell_start[row + cxl], cell_start[row + cxh + 1]):
            if kind[j] == FLUID or kind[j] == INLET or kind[j] == OUTLET:
                dx = xi - x[j]
                dz = zi - z[j]
                r2 = dx * dx + dz * dz
                if r2 < s2:
                    w = w_of_q(math.sqrt(r2) * inv_h, aw)
                    sw += w
                    sp += (p[j] + rho[j] * (bx * dx + bz * dz)) * w
                    svx += vx[j] * w
                    svz += vz[j] * w
    if sw > 0.0:
        pi = max(sp / sw, 0.0)   # no suction (wcsph.wall_pass)
        p[i] = pi
        rho[i] = density(pi, prm.rho0, prm.b, prm.gamma)
        ps.vwx[i] = 2.0 * vx[i] - svx / sw
        ps.vwz[i] = 2.0 * vz[i] - svz / sw
    else:
        p[i] = 0.0
        rho[i] = prm.rho0
        ps.vwx[i] = vx[i]
        ps.vwz[i] = vz[i]


@njit(cache=True, inline="always")
def fluid_particle(i, ps, cells, prm):
    """``wcsph.fluid_pass`` for fluid slot i (delta-SPH, no kernel correction): writes ax, az,
    drho, pw and, with the no-penetration correction on, dvnx, dvnz."""
    x = ps.x
    z = ps.z
    vx = ps.vx
    vz = ps.vz
    rho = ps.rho
    p = ps.p
    m = ps.m
    vwx = ps.vwx
    vwz = ps.vwz
    kind = ps.kind
    cell_start = cells.start
    ncx = cells.ncx
    h = prm.h
    inv_h = 1.0 / h
    s2 = 4.0 * h * h
    eta2 = 0.01 * h * h
    af = prm.alpha_f
    rho0 = prm.rho0
    c0 = prm.c0
    gam = prm.gamma
    gx = prm.gx
    gz = prm.gz
    g = math.sqrt(gx * gx + gz * gz)
    gdir_z = gz / g if g > 0 else 0.0
    gdir_x = gx / g if g > 0 else 0.0
    av = prm.alpha * c0 * h
    av_wall = prm.alpha_wall * av
    nu4 = 4.0 * prm.nu
    ddiff = 2.0 * prm.delta * h * c0
    noslip = prm.noslip
    ga = prm.wall_ga
    g0 = prm.wall_g0
    gb = prm.wall_gb
    aw = prm.alpha_w
    inv_rho0 = 1.0 / rho0
    xi = x[i]
    zi = z[i]
    vxi = vx[i]
    vzi = vz[i]
    rhoi = rho[i]
    pi = p[i]
    inv_rhoi = 1.0 / rhoi
    khyd = rhoi * g / (c0 * c0 * (rhoi / rho0) ** (gam - 1.0))
    fx = 0.0
    fz = 0.0
    cont = 0.0
    diff = 0.0
    gw = 0.0
    gnx = 0.0
    gnz = 0.0
    gvx = 0.0
    gvz = 0.0
    tx = 0.0
    tz = 0.0
    cxl, cxh, czl, czh = block_of(ps.cell[i], cells)
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
            fij = f_of_q(math.sqrt(r2) * inv_h, af)
            rhoj = rho[j]
            mj = m[j]
            vol = mj / rhoj
            dvx = vxi - vx[j]
            dvz = vzi - vz[j]
            visc = kj != WALL or noslip
            cont -= vol * fij * (dvx * dx + dvz * dz)
            pf = vol * (pi + p[j]) * inv_rhoi
            up = -(gdir_x * dx + gdir_z * dz)
            diff += (rhoj - rhoi - khyd * up) * fij * vol
            if kj == WALL:
                dvx = vxi - vwx[j]
                dvz = vzi - vwz[j]
                vg = mj * inv_rho0
                wg = vg * w_of_q(math.sqrt(r2) * inv_h, aw)
                gw += wg
                gnx += vg * fij * dx
                gnz += vg * fij * dz
                gvx += wg * vx[j]
                gvz += wg * vz[j]
                if pi < 0.0:
                    pt = -vol * pi * inv_rhoi
                    tx += pt * fij * dx
                    tz += pt * fij * dz
            if visc:
                vr = dvx * dx + dvz * dz
                mden = mj / ((rhoi + rhoj) * (r2 + eta2))
                if vr < 0.0:
                    pf -= 2.0 * (av_wall if kj == WALL else av) * vr * mden
                lam = nu4 * r2 * mden
                fx -= lam * fij * dvx
                fz -= lam * fij * dvz
            fx += pf * fij * dx
            fz += pf * fij * dz
    # the approach-gated wall tension (wcsph.fluid_pass)
    pwi = pi
    if pi < 0.0 and approach_speed(gw, gnx, gnz, gvx, gvz, vxi, vzi) < 0.0:
        fx += tx
        fz += tz
        pwi = 0.0
    ps.pw[i] = pwi
    ps.ax[i] = fx + gx
    ps.az[i] = fz + gz
    ps.drho[i] = rhoi * cont + ddiff * diff
    if g0 > 0.0:
        ps.dvnx[i], ps.dvnz[i] = no_penetration(gw, gnx, gnz, gvx, gvz, vxi, vzi, ga, g0, gb)


@njit(cache=True, inline="always")
def kick_drift_particle(i, ps, dt, prm):
    """``wcsph.kdk_kick_drift`` for fluid slot i; True if it ends outside the fluid box."""
    hdt = 0.5 * dt
    ps.vx[i] += hdt * ps.ax[i]
    ps.vz[i] += hdt * ps.az[i]
    r = ps.rho[i] + hdt * ps.drho[i]
    ps.rho[i] = r
    ps.p[i] = pressure(r + hdt * ps.drho[i], prm.rho0, prm.b, prm.gamma)
    xi = ps.x[i] + dt * ps.vx[i]
    zi = ps.z[i] + dt * ps.vz[i]
    ps.x[i] = xi
    ps.z[i] = zi
    return not (xi >= prm.fx0 and xi <= prm.fx1 and zi >= prm.fz0 and zi <= prm.fz1)


@njit(cache=True, inline="always")
def kick_particle(i, ps, dt, prm):
    """``wcsph.kdk_kick`` for fluid slot i; returns (v^2, a^2, rho, guard) with guard 0 ok,
    1 non-finite, 2 outside the density band."""
    hdt = 0.5 * dt
    ax = ps.ax[i]
    az = ps.az[i]
    u = ps.vx[i] + hdt * ax + ps.dvnx[i]
    w = ps.vz[i] + hdt * az + ps.dvnz[i]
    r = ps.rho[i] + hdt * ps.drho[i]
    ps.vx[i] = u
    ps.vz[i] = w
    ps.rho[i] = r
    v2 = u * u + w * w
    a2 = ax * ax + az * az
    guard = 0
    if not (math.isfinite(v2) and math.isfinite(r) and math.isfinite(a2)):
        guard = 1
    elif r < prm.rho_lo * prm.rho0 or r > prm.rho_hi * prm.rho0:
        guard = 2
    return v2, a2, r, guard
