"""Weakly-compressible SPH: one fused interaction pass per force evaluation, jitted time loop.

Equations (i fluid, j neighbour, r_ij = r_i - r_j, grad_i W_ij = -F_ij r_ij, V_j = m_j / rho_j):

continuity + delta-SPH (Fourtakas et al. 2019 dynamic form, fluid-fluid and fluid-wall pairs):
    drho_i/dt = -rho_i sum_j V_j F_ij (v_ij . r_ij)
                + 2 delta h c0 sum_j (rho_j - rho_i - rho^H_ji) F_ij V_j,
    rho^H_ji = rho_H(z_j) - rho_H(z_i) = (rho_i g / c_i^2)(z_i - z_j),  c_i^2 = c0^2 (rho_i/rho0)^(gamma-1)
momentum:
    dv_i/dt = sum_j m_j [(p_i + p_j)/(rho_i rho_j) + Pi_ij] F_ij r_ij                 (pressure, Monaghan AV)
              - sum_j m_j 4 nu F_ij r^2 / ((rho_i + rho_j)(r^2 + 0.01 h^2)) v_ij + g   (Lo & Shao 2002)
    Pi_ij = -alpha c0 h (v_ij.r_ij) / (rho_bar (r^2 + 0.01 h^2)) if v_ij.r_ij < 0 else 0   (Monaghan 1992)
walls (Adami, Hu & Adams 2012, eq. 22 of seed 004), from fluid neighbours f of wall particle s:
    p_s = max(0, [sum_f p_f W_sf + (g - a_s) . sum_f rho_f r_sf W_sf] / sum_f W_sf),  rho_s = EOS^-1(p_s),
    no-slip: v_s(viscous) = 2 v_s - sum_f v_f W_sf / sum_f W_sf;  no fluid neighbour: p_s = 0.
time step (Monaghan 1989; DualSPHysics):
    dt = min(CFL h / (c_max + |v|_max), CFL sqrt(h / |a|_max), 0.125 h^2 / nu).

Integrators
- ``kdk`` (default): leapfrog kick-drift-kick, ONE interaction pass per step:
    v^{n+1/2} = v^n + dt/2 a^n, rho^{n+1/2} = rho^n + dt/2 D^n, x^{n+1} = x^n + dt v^{n+1/2},
    a^{n+1}, D^{n+1} from (x^{n+1}, v^{n+1/2}, rho^{n+1/2}; p from rho^n + dt D^n),
    v^{n+1} = v^{n+1/2} + dt/2 a^{n+1}, rho^{n+1} = rho^{n+1/2} + dt/2 D^{n+1}.
- ``symplectic_pc``: the DualSPHysics symplectic predictor-corrector, TWO passes per step
  (forces at x^n and at x^{n+1/2}; rho^{n+1} = rho^n (2 - eps)/(2 + eps), eps = -D^{n+1/2} dt / rho^{n+1/2}).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .eos import density, pressure
from .kernels import f_of_q, w_of_q
from .neighbours import sort_by_cell
from .particles import (AX, AZ, DRHO, FLUID, INLET, M, N_SORTED_KDK, N_SORTED_PC, OUTLET, P, RHO,
                        RHON, VWX, VWZ, VX, VXN, VZ, VZN, WALL, XN, ZN, X, Z)

# indices into the float parameter vector ``prm``
(PR_H, PR_ALPHA_W, PR_ALPHA_F, PR_RHO0, PR_C0, PR_B, PR_GAMMA, PR_GX, PR_GZ, PR_ALPHA, PR_NU,
 PR_DELTA, PR_CFL, PR_RHO_LO, PR_RHO_HI, PR_NOSLIP, PR_FX0, PR_FX1, PR_FZ0, PR_FZ1, PR_XMIN,
 PR_ZMIN, PR_INV_CS) = range(23)
N_PRM = 23

# status codes returned by the time loop
ST_REACHED_T = 0
ST_STEP_LIMIT = 1
ST_NONFINITE = 2
ST_DENSITY = 3
ST_LEFT_DOMAIN = 4
STATUS_TEXT = {
    ST_NONFINITE: "non-finite velocity or density (NaN/inf)",
    # the loop stops; Simulation excludes the particles if within Constants.exclude_limit
    ST_DENSITY: "density outside the sane band",
    ST_LEFT_DOMAIN: "fluid particle left the tank (through a wall or over its top)",
}

INTEGRATORS = {"kdk": 0, "symplectic_pc": 1}

# fast-math for the interaction passes, without the no-NaN/no-inf assumptions: the stability
# guard must still see a NaN produced there
FASTMATH = {"nsz", "arcp", "contract", "afn", "reassoc"}
PASSES_PER_STEP = {"kdk": 1, "symplectic_pc": 2}


@njit(parallel=True, cache=True, fastmath=FASTMATH)
def wall_pass(f, kind, cell, cell_start, n, ncx, ncz, prm):
    """Adami et al. (2012) pressure, density and no-slip velocity of every wall particle."""
    x = f[X]
    z = f[Z]
    vx = f[VX]
    vz = f[VZ]
    ax = f[AX]
    az = f[AZ]
    rho = f[RHO]
    p = f[P]
    vwx = f[VWX]
    vwz = f[VWZ]
    h = prm[PR_H]
    inv_h = 1.0 / h
    s2 = 4.0 * h * h
    aw = prm[PR_ALPHA_W]
    gx = prm[PR_GX]
    gz = prm[PR_GZ]
    rho0 = prm[PR_RHO0]
    b = prm[PR_B]
    gam = prm[PR_GAMMA]
    for i in prange(n):
        if kind[i] == WALL:
            xi = x[i]
            zi = z[i]
            bx = gx - ax[i]
            bz = gz - az[i]
            sw = 0.0
            sp = 0.0
            svx = 0.0
            svz = 0.0
            c = cell[i]
            cz = c // ncx
            cx = c - cz * ncx
            cxl = cx - 1 if cx > 0 else 0
            cxh = cx + 1 if cx < ncx - 1 else ncx - 1
            for zz in range(max(cz - 1, 0), min(cz + 2, ncz)):
                row = zz * ncx
                for j in range(cell_start[row + cxl], cell_start[row + cxh + 1]):
                    # fluid and active open-boundary buffer particles (kinds 0, 2, 3)
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
                # no suction: a negative extrapolated pressure (free surface near the wall)
                # would pull fluid into the wall
                pi = max(sp / sw, 0.0)
                p[i] = pi
                rho[i] = density(pi, rho0, b, gam)
                vwx[i] = 2.0 * vx[i] - svx / sw
                vwz[i] = 2.0 * vz[i] - svz / sw
            else:
                p[i] = 0.0
                rho[i] = rho0
                vwx[i] = vx[i]
                vwz[i] = vz[i]


@njit(parallel=True, cache=True, fastmath=FASTMATH)
def fluid_pass(f, kind, cell, cell_start, n, ncx, ncz, prm):
    """The fused gather over fluid particles: continuity, delta-SPH, pressure, viscosity, gravity.

    Writes AX, AZ, DRHO of each fluid particle; returns nothing (reductions are in the kicks)."""
    x = f[X]
    z = f[Z]
    vx = f[VX]
    vz = f[VZ]
    ax = f[AX]
    az = f[AZ]
    rho = f[RHO]
    p = f[P]
    m = f[M]
    drho = f[DRHO]
    vwx = f[VWX]
    vwz = f[VWZ]
    h = prm[PR_H]
    inv_h = 1.0 / h
    s2 = 4.0 * h * h
    eta2 = 0.01 * h * h
    af = prm[PR_ALPHA_F]
    rho0 = prm[PR_RHO0]
    c0 = prm[PR_C0]
    gam = prm[PR_GAMMA]
    gx = prm[PR_GX]
    gz = prm[PR_GZ]
    g = math.sqrt(gx * gx + gz * gz)
    gdir_z = gz / g if g > 0 else 0.0
    gdir_x = gx / g if g > 0 else 0.0
    av = prm[PR_ALPHA] * c0 * h
    nu4 = 4.0 * prm[PR_NU]
    ddiff = 2.0 * prm[PR_DELTA] * h * c0
    noslip = prm[PR_NOSLIP] > 0.5
    for i in prange(n):
        if kind[i] == FLUID:
            xi = x[i]
            zi = z[i]
            vxi = vx[i]
            vzi = vz[i]
            rhoi = rho[i]
            pi = p[i]
            # hydrostatic density gradient factor rho_i g / c_i^2 (Fourtakas et al. 2019)
            khyd = rhoi * g / (c0 * c0 * (rhoi / rho0) ** (gam - 1.0))
            fx = 0.0
            fz = 0.0
            cont = 0.0
            diff = 0.0
            c = cell[i]
            cz = c // ncx
            cx = c - cz * ncx
            cxl = cx - 1 if cx > 0 else 0
            cxh = cx + 1 if cx < ncx - 1 else ncx - 1
            for zz in range(max(cz - 1, 0), min(cz + 2, ncz)):
                row = zz * ncx
                for j in range(cell_start[row + cxl], cell_start[row + cxh + 1]):
                    kj = kind[j]
                    # INACTIVE (-1) and idle buffer slots (> OUTLET) do not interact; active
                    # buffer particles (INLET, OUTLET) act as fluid with imposed velocity
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
                    # continuity uses the particle's own (for walls: prescribed) velocity
                    dvx = vxi - vx[j]
                    dvz = vzi - vz[j]
                    cont -= vol * fij * (dvx * dx + dvz * dz)
                    pf = mj * (pi + p[j]) / (rhoi * rhoj)
                    visc = kj != WALL or noslip
                    # height of i above j along gravity (z_i - z_j for g = (0, -g)); wall
                    # densities come from the Adami extrapolation, so they carry the hydrostatic
                    # part as the fluid's do and take part in the diffusion
                    up = -(gdir_x * dx + gdir_z * dz)
                    diff += (rhoj - rhoi - khyd * up) * fij * vol
                    if kj == WALL:
                        dvx = vxi - vwx[j]
                        dvz = vzi - vwz[j]
                    if visc:
                        vr = dvx * dx + dvz * dz
                        if vr < 0.0:
                            pf -= mj * av * vr / (0.5 * (rhoi + rhoj) * (r2 + eta2))
                        lam = mj * nu4 * r2 / ((rhoi + rhoj) * (r2 + eta2))
                        fx -= lam * fij * dvx
                        fz -= lam * fij * dvz
                    fx += pf * fij * dx
                    fz += pf * fij * dz
            ax[i] = fx + gx
            az[i] = fz + gz
            drho[i] = rhoi * cont + ddiff * diff


@njit(parallel=True, cache=True)
def kdk_kick_drift(f, kind, n, dt, prm):
    """First half-kick and drift of the leapfrog; returns the number of fluid particles outside the tank."""
    x = f[X]
    z = f[Z]
    vx = f[VX]
    vz = f[VZ]
    ax = f[AX]
    az = f[AZ]
    rho = f[RHO]
    p = f[P]
    drho = f[DRHO]
    rho0 = prm[PR_RHO0]
    b = prm[PR_B]
    gam = prm[PR_GAMMA]
    fx0 = prm[PR_FX0]
    fx1 = prm[PR_FX1]
    fz0 = prm[PR_FZ0]
    fz1 = prm[PR_FZ1]
    hdt = 0.5 * dt
    n_out = 0
    for i in prange(n):
        if kind[i] == FLUID:
            vx[i] += hdt * ax[i]
            vz[i] += hdt * az[i]
            r = rho[i] + hdt * drho[i]
            rho[i] = r
            p[i] = pressure(r + hdt * drho[i], rho0, b, gam)
            xi = x[i] + dt * vx[i]
            zi = z[i] + dt * vz[i]
            x[i] = xi
            z[i] = zi
            if not (xi >= fx0 and xi <= fx1 and zi >= fz0 and zi <= fz1):
                n_out += 1
    return n_out


@njit(parallel=True, cache=True)
def kdk_kick(f, kind, n, dt, prm):
    """Second half-kick; returns (#non-finite, #outside density band, max |v|^2, max |a|^2, max rho)."""
    vx = f[VX]
    vz = f[VZ]
    ax = f[AX]
    az = f[AZ]
    rho = f[RHO]
    drho = f[DRHO]
    rho0 = prm[PR_RHO0]
    lo = prm[PR_RHO_LO] * rho0
    hi = prm[PR_RHO_HI] * rho0
    hdt = 0.5 * dt
    n_bad = 0
    n_band = 0
    v2max = 0.0
    a2max = 0.0
    rmax = 0.0
    for i in prange(n):
        if kind[i] == FLUID:
            u = vx[i] + hdt * ax[i]
            w = vz[i] + hdt * az[i]
            r = rho[i] + hdt * drho[i]
            vx[i] = u
            vz[i] = w
            rho[i] = r
            v2 = u * u + w * w
            a2 = ax[i] * ax[i] + az[i] * az[i]
            if not (np.isfinite(v2) and np.isfinite(r) and np.isfinite(a2)):
                n_bad += 1
            elif r < lo or r > hi:
                n_band += 1
            v2max = max(v2max, v2)
            a2max = max(a2max, a2)
            rmax = max(rmax, r)
    return n_bad, n_band, v2max, a2max, rmax


@njit(parallel=True, cache=True)
def pc_predict(f, kind, n, dt, prm):
    """Symplectic predictor: save state n, half-step x, v, rho with a^n; p from rho^{n+1/2}."""
    x = f[X]
    z = f[Z]
    vx = f[VX]
    vz = f[VZ]
    rho = f[RHO]
    p = f[P]
    hdt = 0.5 * dt
    rho0 = prm[PR_RHO0]
    b = prm[PR_B]
    gam = prm[PR_GAMMA]
    for i in prange(n):
        if kind[i] == FLUID:
            f[XN, i] = x[i]
            f[ZN, i] = z[i]
            f[VXN, i] = vx[i]
            f[VZN, i] = vz[i]
            f[RHON, i] = rho[i]
            x[i] += hdt * vx[i]
            z[i] += hdt * vz[i]
            vx[i] += hdt * f[AX, i]
            vz[i] += hdt * f[AZ, i]
            r = rho[i] + hdt * f[DRHO, i]
            rho[i] = r
            p[i] = pressure(r, rho0, b, gam)


@njit(parallel=True, cache=True)
def pc_correct(f, kind, n, dt, prm):
    """Symplectic corrector from the half-step rates; returns the same tuple as ``kdk_kick``
    plus the count of fluid particles outside the tank."""
    x = f[X]
    z = f[Z]
    vx = f[VX]
    vz = f[VZ]
    ax = f[AX]
    az = f[AZ]
    rho = f[RHO]
    p = f[P]
    rho0 = prm[PR_RHO0]
    b = prm[PR_B]
    gam = prm[PR_GAMMA]
    lo = prm[PR_RHO_LO] * rho0
    hi = prm[PR_RHO_HI] * rho0
    fx0 = prm[PR_FX0]
    fx1 = prm[PR_FX1]
    fz0 = prm[PR_FZ0]
    fz1 = prm[PR_FZ1]
    n_bad = 0
    n_band = 0
    n_out = 0
    v2max = 0.0
    a2max = 0.0
    rmax = 0.0
    for i in prange(n):
        if kind[i] == FLUID:
            eps = -f[DRHO, i] / rho[i] * dt
            r = f[RHON, i] * (2.0 - eps) / (2.0 + eps)
            u0 = f[VXN, i]
            w0 = f[VZN, i]
            u = u0 + dt * ax[i]
            w = w0 + dt * az[i]
            xi = f[XN, i] + 0.5 * dt * (u + u0)
            zi = f[ZN, i] + 0.5 * dt * (w + w0)
            vx[i] = u
            vz[i] = w
            rho[i] = r
            p[i] = pressure(r, rho0, b, gam)
            x[i] = xi
            z[i] = zi
            v2 = u * u + w * w
            a2 = ax[i] * ax[i] + az[i] * az[i]
            if not (np.isfinite(v2) and np.isfinite(r) and np.isfinite(a2)):
                n_bad += 1
            elif r < lo or r > hi:
                n_band += 1
            if not (xi >= fx0 and xi <= fx1 and zi >= fz0 and zi <= fz1):
                n_out += 1
            v2max = max(v2max, v2)
            a2max = max(a2max, a2)
            rmax = max(rmax, r)
    return n_bad, n_band, n_out, v2max, a2max, rmax


@njit(parallel=True, cache=True)
def update_pressure(f, kind, n, prm):
    """p = EOS(rho) for every fluid particle."""
    rho0 = prm[PR_RHO0]
    b = prm[PR_B]
    gam = prm[PR_GAMMA]
    for i in prange(n):
        if kind[i] == FLUID:
            f[P, i] = pressure(f[RHO, i], rho0, b, gam)


@njit(cache=True)
def stable_dt(v2max, a2max, rmax, prm):
    """dt = min(CFL h/(c_max + v_max), CFL sqrt(h/a_max), 0.125 h^2/nu)."""
    h = prm[PR_H]
    cfl = prm[PR_CFL]
    rho0 = prm[PR_RHO0]
    cmax = prm[PR_C0] * max(rmax / rho0, 1.0) ** (0.5 * (prm[PR_GAMMA] - 1.0))
    dt = cfl * h / (cmax + math.sqrt(v2max))
    if a2max > 0.0:
        dt = min(dt, cfl * math.sqrt(h / math.sqrt(a2max)))
    if prm[PR_NU] > 0.0:
        dt = min(dt, 0.125 * h * h / prm[PR_NU])
    return dt


@njit(cache=True)
def _sort(f, f2, nrows, kind, kind2, ids, ids2, cell, cell2, order, cell_start, cursor, n,
          prm, ncx, ncz):
    sort_by_cell(f, f2, nrows, kind, kind2, ids, ids2, cell, cell2, order, cell_start, cursor,
                 n, prm[PR_XMIN], prm[PR_ZMIN], prm[PR_INV_CS], ncx, ncz)


@njit(cache=True)
def initialise(f, f2, kind, kind2, ids, ids2, cell, cell2, order, cell_start, cursor, n, prm,
               ncx, ncz):
    """Sort, evaluate rates at the initial state and return the first dt (state ends in f2 twins)."""
    update_pressure(f, kind, n, prm)
    _sort(f, f2, N_SORTED_PC, kind, kind2, ids, ids2, cell, cell2, order, cell_start, cursor,
          n, prm, ncx, ncz)
    wall_pass(f2, kind2, cell2, cell_start, n, ncx, ncz, prm)
    fluid_pass(f2, kind2, cell2, cell_start, n, ncx, ncz, prm)
    n_bad, n_band, v2max, a2max, rmax = kdk_kick(f2, kind2, n, 0.0, prm)
    return stable_dt(v2max, a2max, rmax, prm)


@njit(cache=True)
def advance(f, f2, kind, kind2, ids, ids2, cell, cell2, order, cell_start, cursor, n, prm,
            ncx, ncz, integrator, t, dt, t_stop, max_steps):
    """Run steps until t reaches t_stop or max_steps were taken, or the state turns unstable.

    Returns (t, dt_next, steps, status, swapped, n_flagged, v_max). ``swapped`` = 1 means the
    current state is in the twin buffers (the caller swaps its references)."""
    swapped = 0
    steps = 0
    status = ST_REACHED_T
    n_flag = 0
    v2max = 0.0
    while True:
        if t >= t_stop:
            status = ST_REACHED_T
            break
        if steps >= max_steps:
            status = ST_STEP_LIMIT
            break
        dts = dt
        last = False
        if t + dts >= t_stop:
            dts = t_stop - t
            last = True
        if integrator == 0:
            n_out = kdk_kick_drift(f, kind, n, dts, prm)
            if n_out > 0:
                status = ST_LEFT_DOMAIN
                n_flag = n_out
                break
            _sort(f, f2, N_SORTED_KDK, kind, kind2, ids, ids2, cell, cell2, order, cell_start,
                  cursor, n, prm, ncx, ncz)
            f, f2 = f2, f
            kind, kind2 = kind2, kind
            ids, ids2 = ids2, ids
            cell, cell2 = cell2, cell
            swapped = 1 - swapped
            wall_pass(f, kind, cell, cell_start, n, ncx, ncz, prm)
            fluid_pass(f, kind, cell, cell_start, n, ncx, ncz, prm)
            n_bad, n_band, v2max, a2max, rmax = kdk_kick(f, kind, n, dts, prm)
            n_out = 0
        else:
            # rates at x^n (the sort happens here, at the start of the step)
            _sort(f, f2, N_SORTED_PC, kind, kind2, ids, ids2, cell, cell2, order, cell_start,
                  cursor, n, prm, ncx, ncz)
            f, f2 = f2, f
            kind, kind2 = kind2, kind
            ids, ids2 = ids2, ids
            cell, cell2 = cell2, cell
            swapped = 1 - swapped
            wall_pass(f, kind, cell, cell_start, n, ncx, ncz, prm)
            fluid_pass(f, kind, cell, cell_start, n, ncx, ncz, prm)
            pc_predict(f, kind, n, dts, prm)
            wall_pass(f, kind, cell, cell_start, n, ncx, ncz, prm)
            fluid_pass(f, kind, cell, cell_start, n, ncx, ncz, prm)
            n_bad, n_band, n_out, v2max, a2max, rmax = pc_correct(f, kind, n, dts, prm)
        t = t_stop if last else t + dts
        steps += 1
        if n_bad > 0:
            status = ST_NONFINITE
            n_flag = n_bad
            break
        if n_out > 0:
            status = ST_LEFT_DOMAIN
            n_flag = n_out
            break
        if n_band > 0:
            status = ST_DENSITY
            n_flag = n_band
            break
        dt = stable_dt(v2max, a2max, rmax, prm)
    return t, dt, steps, status, swapped, n_flag, math.sqrt(v2max)
