"""Weakly-compressible SPH: the passes of a step over the particles, and the integrators.

Every vector has three components (x, y, z); a 2D scene (the x-z plane) keeps y, vy, ay zero and
its sums are the 2D ones (pairs.py). The equations below hold in either dimension.

The per-pair terms the passes fold over their neighbours (pairs.gather) are in terms.py; the
step that calls the passes is ``step.run`` (one skeleton for every integrator and scene).

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

from numba import njit, prange

from .eos import density, pressure
from .neighbours import PASS_RANGES, kind_ranges
from .pairs import fluidlike, gather, interacting
from .particles import (AX, AY, AZ, DRHO, DVNX, DVNY, DVNZ, FLUID, P, PW, RHO, RHON, VWX, VWY,
                        VWZ, VX, VXN, VY, VYN, VZ, VZN, WALL, XN, YN, ZN, X, Y, Z)
from .terms import (FLUID_SUMS_ZERO, WALL_SUMS_ZERO, adami_pair, fluid_consts, fluid_i,
                    riemann_pair, wcsph_pair)
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


# fast-math for the interaction passes, without the no-NaN/no-inf assumptions: the stability
# guard must still see a NaN produced there
FASTMATH = {"nsz", "arcp", "contract", "afn", "reassoc"}
PASSES_PER_STEP = {"kdk": 1, "symplectic_pc": 2}


@njit(cache=True, inline="always")
def adami_state(i, ps, cells, prm):
    """(p, rho, vwx, vwy, vwz) of wall particle i: Adami et al. (2012) pressure, density and
    no-slip velocity from its fluid neighbours (terms.adami_pair). One particle's share of
    ``wall_pass``: the CUDA step's kernel calls the same function."""
    h = prm.h
    by = 0.0 if prm.three is None else prm.gy - ps.ay[i]   # 2D: a constant (no y lever)
    ctx = (1.0 / h, prm.alpha_w, prm.gx - ps.ax[i], by, prm.gz - ps.az[i])
    s = gather(i, ps.x[i], ps.y[i], ps.z[i], ps.cell[i], ps, cells, 4.0 * h * h, fluidlike,
               adami_pair, ctx, WALL_SUMS_ZERO)
    if s.sw > 0.0:
        # no suction: a negative extrapolated pressure (free surface near the wall) would pull
        # fluid into the wall
        pi = max(s.sp / s.sw, 0.0)
        # 2D (prm.three None, when compiled): no y sum, so none is gathered
        vwy = 0.0 if prm.three is None else 2.0 * ps.vy[i] - s.svy / s.sw
        return (pi, density(pi, prm.rho0, prm.b, prm.gamma), 2.0 * ps.vx[i] - s.svx / s.sw,
                vwy, 2.0 * ps.vz[i] - s.svz / s.sw)
    return 0.0, prm.rho0, ps.vx[i], ps.vy[i], ps.vz[i]


@njit(parallel=True, cache=True, fastmath=FASTMATH)
def wall_pass(ps, n, cells, prm):
    """Adami et al. (2012) pressure, density and no-slip velocity of every wall particle."""
    f = ps.f   # writes go through the storage (module note on prange stores)
    kind = ps.kind
    b = kind_ranges(kind, n, WALL, PASS_RANGES)   # equal shares of the walls per thread
    for r in prange(b.size - 1):
        for i in range(b[r], b[r + 1]):
            if kind[i] == WALL:
                p, rho, vwx, vwy, vwz = adami_state(i, ps, cells, prm)
                f[P, i] = p
                f[RHO, i] = rho
                f[VWX, i] = vwx
                f[VWZ, i] = vwz
                if prm.three is not None:   # 2D: the y rows stay zero, untouched
                    f[VWY, i] = vwy


@njit(cache=True, inline="always")
def fluid_rates(i, ps, cells, prm, riemann, k, fi):
    """(ax, ay, az, drho, pw, dvnx, dvny, dvnz) of fluid particle i: continuity, delta-SPH, pressure,
    viscosity, gravity (terms.wcsph_pair), or with ``riemann`` True (not None) the Riemann SPH
    flux (terms.riemann_pair; MUSCL gradients from riemann_gradients); pw is the pressure its
    walls feel, dvn the no-penetration velocity change (wall_contact.py; zero when off). One
    particle's share of ``fluid_pass``: the CUDA step's kernel calls the same function. ``k``,
    ``fi``: terms.fluid_consts(prm) and terms.fluid_i(i, ps, k), built by the caller (inlined
    into a prange loop, the NamedTuple they build fails numba's parfor array analysis; a CUDA
    kernel needs them inlined)."""
    if riemann is None:
        a = gather(i, fi.x, fi.y, fi.z, ps.cell[i], ps, cells, k.s2, interacting, wcsph_pair,
                   (k, fi), FLUID_SUMS_ZERO)
    else:
        a = gather(i, fi.x, fi.y, fi.z, ps.cell[i], ps, cells, k.s2, interacting, riemann_pair,
                   (k, fi), FLUID_SUMS_ZERO)
    fx = a.fx
    fz = a.fz
    # 2D (prm.three None, decided when compiled): the y sums are left out, so the compiler
    # drops their accumulation from the walk
    if prm.three is None:
        fy = gny = gvy = ty = vyi = 0.0
    else:
        fy = a.fy
        gny = a.gny
        gvy = a.gvy
        ty = a.ty
        vyi = fi.vy
    # no tension across a wall while the particle approaches it (p_i -> max(p_i, 0)): a
    # particle in tension is otherwise pulled into the wall (a dry-bed front sinks through the
    # bed); one that moves away keeps the pull, so a thin swash film stays on its beach
    # (docs/studies/wall_pressure.md). The Riemann flux has no such pair term (tx = 0): its
    # walls always feel max(p_i, 0)
    pwi = fi.p
    if fi.p < 0.0 and (riemann is not None
                       or approach_speed(a.gw, a.gnx, gny, a.gnz, a.gvx, gvy, a.gvz, fi.vx,
                                         vyi, fi.vz) < 0.0):
        fx += a.tx
        fy += ty
        fz += a.tz
        pwi = 0.0
    dvx = 0.0
    dvy = 0.0
    dvz = 0.0
    if prm.wall_g0 > 0.0:   # no penetration at wall faces (wall_contact.py): g0 = 0 turns it off
        dvx, dvy, dvz = no_penetration(a.gw, a.gnx, gny, a.gnz, a.gvx, gvy, a.gvz, fi.vx,
                                       vyi, fi.vz, prm.wall_ga, prm.wall_g0, prm.wall_gb)
    if prm.three is None:
        dvy = 0.0
    return (fx + prm.gx, fy + prm.gy, fz + prm.gz, fi.rho * a.cont + k.ddiff * a.diff, pwi, dvx,
            dvy, dvz)


@njit(parallel=True, cache=True, fastmath=FASTMATH)
def fluid_pass(ps, n, cells, prm, riemann):
    """Rates of every fluid particle (``fluid_rates``): writes a, drho, pw, dvn;
    returns nothing (reductions are in the kicks). A None ``riemann`` compiles the WCSPH pair
    alone (step.py)."""
    f = ps.f
    kind = ps.kind
    b = kind_ranges(kind, n, FLUID, PASS_RANGES)  # equal shares of the fluid per thread
    for r in prange(b.size - 1):
        for i in range(b[r], b[r + 1]):
            if kind[i] == FLUID:
                k = fluid_consts(prm)
                fi = fluid_i(i, ps, k)
                ax, ay, az, drho, pw, dvx, dvy, dvz = fluid_rates(i, ps, cells, prm, riemann, k,
                                                                  fi)
                f[AX, i] = ax
                f[AZ, i] = az
                f[DRHO, i] = drho
                f[PW, i] = pw
                f[DVNX, i] = dvx
                f[DVNZ, i] = dvz
                if prm.three is not None:   # 2D: the y rows stay zero, untouched
                    f[AY, i] = ay
                    f[DVNY, i] = dvy


# Numba drops stores made inside a prange loop through ``ps.row[i] = ...``: the passes write
# through the storage array ``f = ps.f`` (rows named by particles.py), and read through either.

@njit(cache=True, inline="always")
def _outside(xi, yi, zi, prm):
    """1 if (xi, yi, zi) is outside the box a fluid particle must stay in, else 0."""
    return 0 if (xi >= prm.fx0 and xi <= prm.fx1 and zi >= prm.fz0 and zi <= prm.fz1
                 and yi >= prm.fy0 and yi <= prm.fy1) else 1


@njit(cache=True, inline="always")
def _guard(u, v, w, r, axi, ayi, azi, lo, hi):
    """(non-finite, outside the density band, |v|^2, |a|^2) of a particle after its update."""
    v2 = u * u + v * v + w * w
    a2 = axi * axi + ayi * ayi + azi * azi
    if not (math.isfinite(v2) and math.isfinite(r) and math.isfinite(a2)):   # (CUDA has math's)
        return 1, 0, v2, a2
    return 0, 1 if (r < lo or r > hi) else 0, v2, a2


@njit(cache=True, inline="always")
def kdk_pressure(rho_half, drho, dt, prm):
    """The pressure the leapfrog's force pass reads: the half-kicked density rho^{n+1/2} carried a
    full step on, not half. That density lags the velocity by half a step (its last rate came from
    v^{n-1/2}); read only half a step on, sound grows by (k c dt)^2/4 a step, an anti-diffusion
    c0^2 dt/4 that delta 0.1 does not outweigh in water a few particles deep
    (bench/leapfrog_acoustics.py, docs/physics/wcsph.md "Time step and integrators")."""
    return pressure(rho_half + dt * drho, prm.rho0, prm.b, prm.gamma)


@njit(parallel=True, cache=True)
def kdk_kick_drift(ps, n, dt, prm):
    """First half-kick and drift of the leapfrog; returns the number of fluid particles outside the tank."""
    f = ps.f
    kind = ps.kind
    hdt = 0.5 * dt
    n_out = 0
    for i in prange(n):
        if kind[i] == FLUID:
            f[VX, i] += hdt * f[AX, i]
            f[VZ, i] += hdt * f[AZ, i]
            r = f[RHO, i] + hdt * f[DRHO, i]
            f[RHO, i] = r
            f[P, i] = kdk_pressure(r, f[DRHO, i], dt, prm)
            xi = f[X, i] + dt * f[VX, i]
            zi = f[Z, i] + dt * f[VZ, i]
            f[X, i] = xi
            f[Z, i] = zi
            yi = 0.0
            if prm.three is not None:   # 2D (when compiled): the y rows stay zero
                f[VY, i] += hdt * f[AY, i]
                yi = f[Y, i] + dt * f[VY, i]
                f[Y, i] = yi
            n_out += _outside(xi, yi, zi, prm)
    return n_out


@njit(parallel=True, cache=True)
def kdk_kick(ps, n, dt, prm):
    """Second half-kick; returns (#non-finite, #outside density band, max |v|^2, max |a|^2, max rho)."""
    f = ps.f
    kind = ps.kind
    lo = prm.rho_lo * prm.rho0
    hi = prm.rho_hi * prm.rho0
    hdt = 0.5 * dt
    n_bad = 0
    n_band = 0
    v2max = 0.0
    a2max = 0.0
    rmax = 0.0
    for i in prange(n):
        if kind[i] == FLUID:
            # dvn: the no-penetration correction of the force pass (wall_contact.py)
            u = f[VX, i] + hdt * f[AX, i] + f[DVNX, i]
            w = f[VZ, i] + hdt * f[AZ, i] + f[DVNZ, i]
            r = f[RHO, i] + hdt * f[DRHO, i]
            f[VX, i] = u
            f[VZ, i] = w
            f[RHO, i] = r
            v = ay = 0.0
            if prm.three is not None:   # 2D (when compiled): the y rows stay zero
                ay = f[AY, i]
                v = f[VY, i] + hdt * ay + f[DVNY, i]
                f[VY, i] = v
            bad, band, v2, a2 = _guard(u, v, w, r, f[AX, i], ay, f[AZ, i], lo, hi)
            n_bad += bad
            n_band += band
            v2max = max(v2max, v2)
            a2max = max(a2max, a2)
            rmax = max(rmax, r)
    return n_bad, n_band, v2max, a2max, rmax


@njit(cache=True, inline="always")
def pc_predict_particle(f, i, dt, prm):
    """Symplectic predictor of fluid slot i of the storage ``f``: state n saved, x, v, rho
    half-stepped with a^n, p from rho^{n+1/2}. One particle's share of ``pc_predict``: the CUDA
    step's kernel calls the same function."""
    hdt = 0.5 * dt
    f[XN, i] = f[X, i]
    f[ZN, i] = f[Z, i]
    f[VXN, i] = f[VX, i]
    f[VZN, i] = f[VZ, i]
    f[RHON, i] = f[RHO, i]
    f[X, i] += hdt * f[VX, i]
    f[Z, i] += hdt * f[VZ, i]
    f[VX, i] += hdt * f[AX, i]
    f[VZ, i] += hdt * f[AZ, i]
    if prm.three is not None:   # 2D (when compiled): the y rows stay zero
        f[YN, i] = f[Y, i]
        f[VYN, i] = f[VY, i]
        f[Y, i] += hdt * f[VY, i]
        f[VY, i] += hdt * f[AY, i]
    r = f[RHO, i] + hdt * f[DRHO, i]
    f[RHO, i] = r
    f[P, i] = pressure(r, prm.rho0, prm.b, prm.gamma)


@njit(parallel=True, cache=True)
def pc_predict(ps, n, dt, prm):
    """Symplectic predictor: save state n, half-step x, v, rho with a^n; p from rho^{n+1/2}."""
    f = ps.f
    kind = ps.kind
    for i in prange(n):
        if kind[i] == FLUID:
            pc_predict_particle(f, i, dt, prm)


@njit(cache=True, inline="always")
def pc_correct_particle(f, i, dt, prm):
    """Symplectic corrector of fluid slot i of the storage ``f`` from the half-step rates;
    returns (non-finite, outside the density band, outside the tank, |v|^2, |a|^2, rho). One
    particle's share of ``pc_correct``: the CUDA step's kernel calls the same function."""
    eps = -f[DRHO, i] / f[RHO, i] * dt
    r = f[RHON, i] * (2.0 - eps) / (2.0 + eps)
    u0 = f[VXN, i]
    w0 = f[VZN, i]
    # dvn: the no-penetration correction of the half-step force pass (wall_contact.py)
    u = u0 + dt * f[AX, i] + f[DVNX, i]
    w = w0 + dt * f[AZ, i] + f[DVNZ, i]
    xi = f[XN, i] + 0.5 * dt * (u + u0)
    zi = f[ZN, i] + 0.5 * dt * (w + w0)
    f[VX, i] = u
    f[VZ, i] = w
    f[RHO, i] = r
    f[P, i] = pressure(r, prm.rho0, prm.b, prm.gamma)
    f[X, i] = xi
    f[Z, i] = zi
    v = ay = yi = 0.0
    if prm.three is not None:   # 2D (when compiled): the y rows stay zero
        v0 = f[VYN, i]
        ay = f[AY, i]
        v = v0 + dt * ay + f[DVNY, i]
        yi = f[YN, i] + 0.5 * dt * (v + v0)
        f[VY, i] = v
        f[Y, i] = yi
    bad, band, v2, a2 = _guard(u, v, w, r, f[AX, i], ay, f[AZ, i], prm.rho_lo * prm.rho0,
                               prm.rho_hi * prm.rho0)
    return bad, band, _outside(xi, yi, zi, prm), v2, a2, r


@njit(parallel=True, cache=True)
def pc_correct(ps, n, dt, prm):
    """Symplectic corrector from the half-step rates; returns the same tuple as ``kdk_kick``
    plus the count of fluid particles outside the tank."""
    f = ps.f
    kind = ps.kind
    n_bad = 0
    n_band = 0
    n_out = 0
    v2max = 0.0
    a2max = 0.0
    rmax = 0.0
    for i in prange(n):
        if kind[i] == FLUID:
            bad, band, out, v2, a2, r = pc_correct_particle(f, i, dt, prm)
            n_bad += bad
            n_band += band
            n_out += out
            v2max = max(v2max, v2)
            a2max = max(a2max, a2)
            rmax = max(rmax, r)
    return n_bad, n_band, n_out, v2max, a2max, rmax


@njit(parallel=True, cache=True)
def update_pressure(ps, n, prm):
    """p = EOS(rho) for every fluid particle."""
    f = ps.f
    kind = ps.kind
    for i in prange(n):
        if kind[i] == FLUID:
            f[P, i] = pressure(f[RHO, i], prm.rho0, prm.b, prm.gamma)


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
