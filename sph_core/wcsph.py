"""Weakly-compressible SPH: the physical terms of a step, each a jitted pass over the particles.

The step that calls them is ``step.run`` (one skeleton for every integrator and scene).

Equations (i fluid, j neighbour, r_ij = r_i - r_j, grad_i W_ij = -F_ij r_ij, V_j = m_j / rho_j):

continuity + delta-SPH (Fourtakas et al. 2019 dynamic form, fluid-fluid and fluid-wall pairs):
    drho_i/dt = -rho_i sum_j V_j F_ij (v_ij . r_ij)
                + 2 delta h c0 sum_j (rho_j - rho_i - rho^H_ji) F_ij V_j,
    rho^H_ji = rho_H(z_j) - rho_H(z_i) = (rho_i g / c_i^2)(z_i - z_j),  c_i^2 = c0^2 (rho_i/rho0)^(gamma-1)
momentum:
    dv_i/dt = sum_j m_j [(p_i + p_j)/(rho_i rho_j) + Pi_ij] F_ij r_ij                 (pressure, Monaghan AV)
              (with a kernel gradient correction, kernel_correction.py, the pressure part's
               F_ij r_ij is (L_i + L_j)/2 F_ij r_ij)
              - sum_j m_j 4 nu F_ij r^2 / ((rho_i + rho_j)(r^2 + 0.01 h^2)) v_ij + g   (Lo & Shao 2002)
    Pi_ij = -alpha c0 h (v_ij.r_ij) / (rho_bar (r^2 + 0.01 h^2)) if v_ij.r_ij < 0 else 0   (Monaghan 1992)
walls (Adami, Hu & Adams 2012, eq. 22 of seed 004), from fluid neighbours f of wall particle s:
    p_s = max(0, [sum_f p_f W_sf + (g - a_s) . sum_f rho_f r_sf W_sf] / sum_f W_sf),  rho_s = EOS^-1(p_s),
    no-slip: v_s(viscous) = 2 v_s - sum_f v_f W_sf / sum_f W_sf;  no fluid neighbour: p_s = 0.
    A fluid particle within dp/4 of a wall face loses its velocity towards the wall (the
    no-penetration correction of wall_contact.py: dvnx, dvnz from fluid_pass, added by the kick).
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
from .neighbours import block_of
from .particles import FLUID, INLET, OUTLET, WALL
from .riemann import NO_RECONSTRUCTION, interface_state, limited
from .wall_contact import approach_speed, no_penetration

# status codes returned by the time loop (step.run)
ST_REACHED_T = 0
ST_STEP_LIMIT = 1
ST_NONFINITE = 2
ST_DENSITY = 3
ST_LEFT_DOMAIN = 4
ST_CAPACITY = 5
STATUS_TEXT = {
    ST_NONFINITE: "non-finite velocity or density (NaN/inf)",
    # the loop stops; Simulation excludes the particles if within Constants.exclude_limit
    ST_DENSITY: "density outside the sane band",
    ST_LEFT_DOMAIN: "fluid particle left the tank (through a wall or over its top)",
    ST_CAPACITY: "particle capacity exhausted by open-boundary inflow",
}

INTEGRATORS = {"kdk": 0, "symplectic_pc": 1}
KDK = 0
SYMPLECTIC_PC = 1

# fast-math for the interaction passes, without the no-NaN/no-inf assumptions: the stability
# guard must still see a NaN produced there
FASTMATH = {"nsz", "arcp", "contract", "afn", "reassoc"}
PASSES_PER_STEP = {"kdk": 1, "symplectic_pc": 2}


@njit(parallel=True, cache=True, fastmath=FASTMATH)
def wall_pass(ps, n, cells, prm):
    """Adami et al. (2012) pressure, density and no-slip velocity of every wall particle."""
    x = ps.x
    z = ps.z
    vx = ps.vx
    vz = ps.vz
    ax = ps.ax
    az = ps.az
    rho = ps.rho
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
    gx = prm.gx
    gz = prm.gz
    rho0 = prm.rho0
    b = prm.b
    gam = prm.gamma
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
            cxl, cxh, czl, czh = block_of(cell[i], cells)
            for zz in range(czl, czh + 1):
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
def fluid_pass(ps, n, cells, prm):
    """The fused gather over fluid particles: continuity, delta-SPH, pressure, viscosity, gravity.

    With ``prm.riemann`` the pair's continuity, delta-SPH, pressure and artificial viscosity are
    the Riemann SPH flux instead (riemann.py; MUSCL gradients from riemann_gradients).
    Writes ax, az, drho and the no-penetration velocity change dvnx, dvnz (wall_contact.py) of
    each fluid particle; returns nothing (reductions are in the kicks)."""
    x = ps.x
    z = ps.z
    vx = ps.vx
    vz = ps.vz
    ax = ps.ax
    az = ps.az
    rho = ps.rho
    p = ps.p
    m = ps.m
    drho = ps.drho
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
    rho0 = prm.rho0
    c0 = prm.c0
    gam = prm.gamma
    gx = prm.gx
    gz = prm.gz
    g = math.sqrt(gx * gx + gz * gz)
    gdir_z = gz / g if g > 0 else 0.0
    gdir_x = gx / g if g > 0 else 0.0
    av = prm.alpha * c0 * h
    # artificial viscosity against walls (DualSPHysics' ViscoBoundFactor): the bed's boundary
    # layer is far thinner than dp, and alpha c0 h over a shear across dp dissipates the same
    # wave energy at every dp (docs/wave_decay_study.md)
    av_wall = prm.alpha_wall * av
    nu4 = 4.0 * prm.nu
    ddiff = 2.0 * prm.delta * h * c0
    noslip = prm.noslip
    rs = prm.riemann
    lim = prm.limiter
    muscl = lim != NO_RECONSTRUCTION
    eta = prm.rs_eta
    inv_c0 = 1.0 / c0
    wall_rs = prm.alpha_wall
    gpx = ps.gpx
    gpz = ps.gpz
    gux = ps.gux
    guz = ps.guz
    gwx = ps.gwx
    gwz = ps.gwz
    # kernel gradient correction (kernel_correction.py): the pressure term's grad_i W_ij becomes
    # (L_i + L_j)/2 grad_i W_ij (L_i for a wall neighbour): antisymmetric, so momentum is kept
    kgc = prm.kgc != 0
    lxx = ps.lxx
    lxz = ps.lxz
    lzz = ps.lzz
    # no penetration at wall faces (wall_contact.py): g0 = 0 turns it off
    ga = prm.wall_ga
    g0 = prm.wall_g0
    gb = prm.wall_gb
    nopen = g0 > 0.0
    aw = prm.alpha_w
    inv_rho0 = 1.0 / rho0
    dvnx = ps.dvnx
    dvnz = ps.dvnz
    pw = ps.pw
    for i in prange(n):
        if kind[i] == FLUID:
            xi = x[i]
            zi = z[i]
            lxxi = lxx[i]
            lxzi = lxz[i]
            lzzi = lzz[i]
            vxi = vx[i]
            vzi = vz[i]
            rhoi = rho[i]
            pi = p[i]
            inv_rhoi = 1.0 / rhoi
            # hydrostatic density gradient factor rho_i g / c_i^2 (Fourtakas et al. 2019)
            khyd = rhoi * g / (c0 * c0 * (rhoi / rho0) ** (gam - 1.0))
            fx = 0.0
            fz = 0.0
            cont = 0.0
            diff = 0.0
            gw = 0.0     # wall share, normal and velocity sums (wall_contact.py)
            gnx = 0.0
            gnz = 0.0
            gvx = 0.0
            gvz = 0.0
            tx = 0.0     # the walls' push that a particle in tension (p_i < 0) would not feel
            tz = 0.0
            cxl, cxh, czl, czh = block_of(cell[i], cells)
            for zz in range(czl, czh + 1):
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
                    visc = kj != WALL or noslip
                    if rs:
                        # Riemann problem along e = r_ji / |r_ji| (riemann.py), r_ji = -(dx, dz)
                        r = max(math.sqrt(r2), 1e-9 * h)   # coincident particles: no NaN
                        ex = -dx / r
                        ez = -dz / r
                        ul = vxi * ex + vzi * ez
                        ur = vx[j] * ex + vz[j] * ez
                        ui = ul
                        pl = pi
                        pr = p[j]
                        if muscl:
                            dpj = pr - pl
                            si = -(gpx[i] * dx + gpz[i] * dz)
                            sj = si if kj == WALL else -(gpx[j] * dx + gpz[j] * dz)
                            pl += 0.5 * limited(si, dpj, lim)
                            pr -= 0.5 * limited(sj, dpj, lim)
                            if kj != WALL:
                                duj = ur - ul
                                si = -((gux[i] * dx + guz[i] * dz) * ex
                                       + (gwx[i] * dx + gwz[i] * dz) * ez)
                                sj = -((gux[j] * dx + guz[j] * dz) * ex
                                       + (gwx[j] * dx + gwz[j] * dz) * ez)
                                ul += 0.5 * limited(si, duj, lim)
                                ur -= 0.5 * limited(sj, duj, lim)
                        ustar, pstar = interface_state(ul, ur, pl, pr, 0.5 * (rhoi + rhoj) * c0,
                                                       inv_c0, eta,
                                                       wall_rs if kj == WALL else 1.0)
                        cont += 2.0 * vol * fij * r * (ui - ustar)
                        pf = 2.0 * vol * pstar * inv_rhoi
                    else:
                        cont -= vol * fij * (dvx * dx + dvz * dz)
                        # m_j (p_i + p_j) / (rho_i rho_j), with the divisions shared per pair
                        pf = vol * (pi + p[j]) * inv_rhoi
                        # height of i above j along gravity (z_i - z_j for g = (0, -g)); wall
                        # densities come from the Adami extrapolation, so they carry the
                        # hydrostatic part as the fluid's do and take part in the diffusion
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
                        if pi < 0.0 and not rs:
                            pt = -vol * pi * inv_rhoi
                            if kgc:
                                tx += pt * fij * (lxxi * dx + lxzi * dz)
                                tz += pt * fij * (lxzi * dx + lzzi * dz)
                            else:
                                tx += pt * fij * dx
                                tz += pt * fij * dz
                    if kgc:
                        # the pressure part alone goes through L; viscosity keeps grad W
                        if kj == WALL:
                            cxx = lxxi
                            cxz = lxzi
                            czz = lzzi
                        else:
                            cxx = 0.5 * (lxxi + lxx[j])
                            cxz = 0.5 * (lxzi + lxz[j])
                            czz = 0.5 * (lzzi + lzz[j])
                        fx += pf * fij * (cxx * dx + cxz * dz)
                        fz += pf * fij * (cxz * dx + czz * dz)
                        pf = 0.0
                    if visc:
                        vr = dvx * dx + dvz * dz
                        mden = mj / ((rhoi + rhoj) * (r2 + eta2))
                        if vr < 0.0 and not rs:
                            pf -= 2.0 * (av_wall if kj == WALL else av) * vr * mden
                        lam = nu4 * r2 * mden
                        fx -= lam * fij * dvx
                        fz -= lam * fij * dvz
                    fx += pf * fij * dx
                    fz += pf * fij * dz
            # no tension across a wall while the particle approaches it (p_i -> max(p_i, 0)): a
            # particle in tension is otherwise pulled into the wall (a dry-bed front sinks
            # through the bed); one that moves away keeps the pull, so a thin swash film stays
            # on its beach (docs/wall_pressure.md, session 7)
            # (the Riemann flux has no such pair term: tx = 0, and its bodies keep max(p_i, 0))
            pwi = pi
            if pi < 0.0 and (rs or approach_speed(gw, gnx, gnz, gvx, gvz, vxi, vzi) < 0.0):
                fx += tx
                fz += tz
                pwi = 0.0
            pw[i] = pwi
            ax[i] = fx + gx
            az[i] = fz + gz
            drho[i] = rhoi * cont + ddiff * diff
            if nopen:
                dvnx[i], dvnz[i] = no_penetration(gw, gnx, gnz, gvx, gvz, vxi, vzi, ga, g0, gb)


@njit(parallel=True, cache=True)
def kdk_kick_drift(ps, n, dt, prm):
    """First half-kick and drift of the leapfrog; returns the number of fluid particles outside the tank."""
    x = ps.x
    z = ps.z
    vx = ps.vx
    vz = ps.vz
    ax = ps.ax
    az = ps.az
    rho = ps.rho
    p = ps.p
    drho = ps.drho
    kind = ps.kind
    rho0 = prm.rho0
    b = prm.b
    gam = prm.gamma
    fx0 = prm.fx0
    fx1 = prm.fx1
    fz0 = prm.fz0
    fz1 = prm.fz1
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
def kdk_kick(ps, n, dt, prm):
    """Second half-kick; returns (#non-finite, #outside density band, max |v|^2, max |a|^2, max rho)."""
    vx = ps.vx
    vz = ps.vz
    ax = ps.ax
    az = ps.az
    rho = ps.rho
    drho = ps.drho
    kind = ps.kind
    rho0 = prm.rho0
    lo = prm.rho_lo * rho0
    hi = prm.rho_hi * rho0
    hdt = 0.5 * dt
    n_bad = 0
    n_band = 0
    v2max = 0.0
    a2max = 0.0
    rmax = 0.0
    dvnx = ps.dvnx
    dvnz = ps.dvnz
    for i in prange(n):
        if kind[i] == FLUID:
            # dvn: the no-penetration correction of the force pass (wall_contact.py)
            u = vx[i] + hdt * ax[i] + dvnx[i]
            w = vz[i] + hdt * az[i] + dvnz[i]
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
def pc_predict(ps, n, dt, prm):
    """Symplectic predictor: save state n, half-step x, v, rho with a^n; p from rho^{n+1/2}."""
    x = ps.x
    z = ps.z
    vx = ps.vx
    vz = ps.vz
    ax = ps.ax
    az = ps.az
    rho = ps.rho
    p = ps.p
    drho = ps.drho
    xn = ps.xn
    zn = ps.zn
    vxn = ps.vxn
    vzn = ps.vzn
    rhon = ps.rhon
    kind = ps.kind
    hdt = 0.5 * dt
    rho0 = prm.rho0
    b = prm.b
    gam = prm.gamma
    for i in prange(n):
        if kind[i] == FLUID:
            xn[i] = x[i]
            zn[i] = z[i]
            vxn[i] = vx[i]
            vzn[i] = vz[i]
            rhon[i] = rho[i]
            x[i] += hdt * vx[i]
            z[i] += hdt * vz[i]
            vx[i] += hdt * ax[i]
            vz[i] += hdt * az[i]
            r = rho[i] + hdt * drho[i]
            rho[i] = r
            p[i] = pressure(r, rho0, b, gam)


@njit(parallel=True, cache=True)
def pc_correct(ps, n, dt, prm):
    """Symplectic corrector from the half-step rates; returns the same tuple as ``kdk_kick``
    plus the count of fluid particles outside the tank."""
    x = ps.x
    z = ps.z
    vx = ps.vx
    vz = ps.vz
    ax = ps.ax
    az = ps.az
    rho = ps.rho
    p = ps.p
    drho = ps.drho
    xn = ps.xn
    zn = ps.zn
    vxn = ps.vxn
    vzn = ps.vzn
    rhon = ps.rhon
    kind = ps.kind
    rho0 = prm.rho0
    b = prm.b
    gam = prm.gamma
    lo = prm.rho_lo * rho0
    hi = prm.rho_hi * rho0
    fx0 = prm.fx0
    fx1 = prm.fx1
    fz0 = prm.fz0
    fz1 = prm.fz1
    n_bad = 0
    n_band = 0
    n_out = 0
    v2max = 0.0
    a2max = 0.0
    rmax = 0.0
    for i in prange(n):
        if kind[i] == FLUID:
            eps = -drho[i] / rho[i] * dt
            r = rhon[i] * (2.0 - eps) / (2.0 + eps)
            u0 = vxn[i]
            w0 = vzn[i]
            # dvn: the no-penetration correction of the half-step force pass (wall_contact.py)
            u = u0 + dt * ax[i] + ps.dvnx[i]
            w = w0 + dt * az[i] + ps.dvnz[i]
            xi = xn[i] + 0.5 * dt * (u + u0)
            zi = zn[i] + 0.5 * dt * (w + w0)
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
def update_pressure(ps, n, prm):
    """p = EOS(rho) for every fluid particle."""
    rho = ps.rho
    p = ps.p
    kind = ps.kind
    rho0 = prm.rho0
    b = prm.b
    gam = prm.gamma
    for i in prange(n):
        if kind[i] == FLUID:
            p[i] = pressure(rho[i], rho0, b, gam)


@njit(cache=True)
def stable_dt(v2max, a2max, rmax, prm):
    """dt = min(CFL h/(c_max + v_max), CFL sqrt(h/a_max), 0.125 h^2/nu)."""
    h = prm.h
    cfl = prm.cfl
    cmax = prm.c0 * max(rmax / prm.rho0, 1.0) ** (0.5 * (prm.gamma - 1.0))
    dt = cfl * h / (cmax + math.sqrt(v2max))
    if a2max > 0.0:
        dt = min(dt, cfl * math.sqrt(h / math.sqrt(a2max)))
    if prm.nu > 0.0:
        dt = min(dt, 0.125 * h * h / prm.nu)
    return dt
