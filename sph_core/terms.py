"""Per-pair terms of the WCSPH and Riemann SPH rates, each written once.

A *term* has the signature of ``pairs.gather``'s fold, ``acc = term(i, j, dx, dy, dz, r2, ps,
ctx, acc)`` (dx = x_i - x_j, i the particle whose sums these are; dy = 0 in a 2D scene), and is composed of the small
physical functions below; the passes (wcsph.py) and the body loads (bodies.py) call them, so a
fluid particle, a body and a probe feel the same pair. Everything here is a plain scalar
``@njit(inline="always")`` function of numbers and particle rows: the same source is what a
GPU kernel calls (numba compiles an ``njit`` function for the CUDA target too).

Equations (r_ij = r_i - r_j, grad_i W_ij = -F_ij r_ij, V_j = m_j / rho_j; wcsph.py has the
whole step):
    continuity        -rho_i sum_j V_j F_ij (v_ij . r_ij)
    delta-SPH         2 delta h c0 sum_j (rho_j - rho_i - rho^H_ji) F_ij V_j  (Fourtakas 2019)
    pressure          sum_j V_j (p_i + p_j) / rho_i F_ij r_ij
    Monaghan AV       -sum_j 2 alpha c0 h (v_ij . r_ij) m_j / ((rho_i + rho_j)(r^2 + 0.01 h^2)) F_ij r_ij
    laminar (Lo & Shao 2002)  -sum_j 4 nu m_j r^2 / ((rho_i + rho_j)(r^2 + 0.01 h^2)) F_ij v_ij
    Riemann flux      riemann.py (continuity 2 rho_i V_j (U_i - U*) F_ij |r|, pressure 2 V_j P*/rho_i F_ij r)
    wall contact sums wall_contact.py (share, normal, velocity of the walls around i)

Adding a term: write its pair function here (or its physical piece, called from the pair
function that already walks the same neighbours), then one line where the pass composes it
(docs/developer/adding_a_term.md).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from numba import njit

from .kernels import f_of_q, w_of_q
from .particles import WALL
from .riemann import interface_state, limited


class FluidConsts(NamedTuple):
    """The fluid pass's constants, from Params once per pass (``fluid_consts``)."""

    h: float
    inv_h: float
    s2: float            # (2h)^2, the support
    eta2: float          # 0.01 h^2, the viscous terms' regulariser
    alpha_f: float
    alpha_w: float
    rho0: float
    inv_rho0: float
    c0: float
    inv_c0: float
    gamma: float
    g: float
    gdir_x: float        # unit vector along gravity (0 without gravity)
    gdir_y: float
    gdir_z: float
    av: float            # alpha c0 h
    av_wall: float       # alpha_wall alpha c0 h: artificial viscosity against walls
    nu4: float           # 4 nu
    ddiff: float         # 2 delta h c0
    noslip: bool
    muscl: bool          # Riemann: MUSCL reconstruction
    wall_rs: float       # Riemann: velocity dissipation factor against walls
    three: bool | None   # Params.three: None in 2D (the y components are left out when compiled)


@njit(cache=True)
def fluid_consts(prm):
    """FluidConsts of the run's Params."""
    h = prm.h
    c0 = prm.c0
    g = math.sqrt(prm.gx * prm.gx + prm.gy * prm.gy + prm.gz * prm.gz)
    av = prm.alpha * c0 * h
    return FluidConsts(h, 1.0 / h, 4.0 * h * h, 0.01 * h * h, prm.alpha_f, prm.alpha_w,
                       prm.rho0, 1.0 / prm.rho0, c0, 1.0 / c0, prm.gamma, g,
                       prm.gx / g if g > 0 else 0.0, prm.gy / g if g > 0 else 0.0,
                       prm.gz / g if g > 0 else 0.0,
                       av, prm.alpha_wall * av, 4.0 * prm.nu, 2.0 * prm.delta * h * c0,
                       prm.noslip, prm.limiter != 0, prm.alpha_wall, prm.three)


class FluidI(NamedTuple):
    """The walking fluid particle i's own values, read once per particle."""

    x: float
    y: float
    z: float
    vx: float
    vy: float
    vz: float
    rho: float
    p: float
    inv_rho: float
    khyd: float          # rho_i g / c_i^2: the hydrostatic density gradient (Fourtakas 2019)


@njit(cache=True)
def fluid_i(i, ps, k):
    """FluidI of particle i (k: FluidConsts)."""
    rhoi = ps.rho[i]
    return FluidI(ps.x[i], ps.y[i], ps.z[i], ps.vx[i], ps.vy[i], ps.vz[i], rhoi, ps.p[i], 1.0 / rhoi,
                  rhoi * k.g / (k.c0 * k.c0 * (rhoi / k.rho0) ** (k.gamma - 1.0)))


class FluidSums(NamedTuple):
    """What a fluid particle gathers: acceleration (without gravity), continuity and
    delta-SPH sums, the wall contact sums (wall_contact.py) and the walls' push that a particle
    in tension would not feel (tx, ty, tz)."""

    fx: float
    fy: float
    fz: float
    cont: float
    diff: float
    gw: float
    gnx: float
    gny: float
    gnz: float
    gvx: float
    gvy: float
    gvz: float
    tx: float
    ty: float
    tz: float


FLUID_SUMS_ZERO = FluidSums(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
                            0.0)


# --- physical pieces ---------------------------------------------------------------------------

@njit(cache=True, inline="always")
def kernel_f(r2, k):
    """F_ij = -(dW/dr)/r at the pair's distance."""
    return f_of_q(math.sqrt(r2) * k.inv_h, k.alpha_f)


@njit(cache=True, inline="always")
def pressure_factor(vol, pi, pj, inv_rhoi):
    """V_j (p_i + p_j) / rho_i: the pair's pressure acceleration is this x F_ij r_ij."""
    return vol * (pi + pj) * inv_rhoi


@njit(cache=True, inline="always")
def density_diffusion(rhoi, rhoj, khyd, dx, dy, dz, fij, vol, k):
    """delta-SPH pair sum (Fourtakas et al. 2019) without its 2 delta h c0: the dynamic
    density difference less the hydrostatic one over the pair's height along gravity. Wall
    densities come from the Adami extrapolation, so they carry the hydrostatic part too."""
    up = -(k.gdir_x * dx + k.gdir_y * dy + k.gdir_z * dz)
    return (rhoj - rhoi - khyd * up) * fij * vol


@njit(cache=True, inline="always")
def viscous_momentum(fx, fy, fz, pf, dvx, dvy, dvz, dx, dy, dz, r2, fij, rhoi, rhoj, mj, av, k):
    """Adds the pair's momentum to (fx, fy, fz): Monaghan's artificial viscosity (coefficient
    ``av``, 0: none) folded into the pressure factor ``pf``, Lo & Shao's laminar viscosity,
    then pf F_ij r_ij."""
    vr = dvx * dx + dvy * dy + dvz * dz
    mden = mj / ((rhoi + rhoj) * (r2 + k.eta2))
    if vr < 0.0 and av > 0.0:
        pf -= 2.0 * av * vr * mden
    lam = k.nu4 * r2 * mden
    fx -= lam * fij * dvx
    fy -= lam * fij * dvy
    fz -= lam * fij * dvz
    return fx + pf * fij * dx, fy + pf * fij * dy, fz + pf * fij * dz


@njit(cache=True, inline="always")
def wall_momentum(fx, fy, fz, pwi, vxi, vyi, vzi, rhoi, inv_rhoi, j, dx, dy, dz, r2, fij, ps,
                  av, k):
    """The fluid-wall pair's momentum on fluid particle i from wall particle j, added to
    (fx, fy, fz), with ``pwi`` the pressure of i the wall feels: pressure, artificial viscosity
    against walls (``av``) and laminar viscosity against the wall's no-slip velocity."""
    rhoj = ps.rho[j]
    mj = ps.m[j]
    pf = pressure_factor(mj / rhoj, pwi, ps.p[j], inv_rhoi)
    if not k.noslip:
        return fx + pf * fij * dx, fy + pf * fij * dy, fz + pf * fij * dz
    return viscous_momentum(fx, fy, fz, pf, vxi - ps.vwx[j], vyi - ps.vwy[j], vzi - ps.vwz[j],
                            dx, dy, dz, r2, fij, rhoi, rhoj, mj, av, k)


@njit(cache=True, inline="always")
def wall_contact(a, j, dx, dy, dz, r2, fij, ps, k):
    """(gw, gnx, gny, gnz, gvx, gvy, gvz) of ``a`` plus wall particle j's share, normal and
    velocity (wall_contact.py)."""
    vg = ps.m[j] * k.inv_rho0
    wg = vg * w_of_q(math.sqrt(r2) * k.inv_h, k.alpha_w)
    return (a.gw + wg, a.gnx + vg * fij * dx, a.gny + vg * fij * dy, a.gnz + vg * fij * dz,
            a.gvx + wg * ps.vx[j], a.gvy + wg * ps.vy[j], a.gvz + wg * ps.vz[j])


# --- pair terms (the folds of pairs.gather) ------------------------------------------------------

@njit(cache=True, inline="always")
def wcsph_pair(i, j, dx, dy, dz, r2, ps, ctx, a):
    """Fluid particle i and a fluid, buffer or wall neighbour j: continuity, delta-SPH,
    pressure, artificial and laminar viscosity; for a wall, the contact sums and the tension
    push. ctx = (FluidConsts, FluidI)."""
    k = ctx[0]
    fi = ctx[1]
    fij = kernel_f(r2, k)
    rhoj = ps.rho[j]
    mj = ps.m[j]
    vol = mj / rhoj
    # continuity uses the neighbour's own (for walls: prescribed) velocity
    dvx = fi.vx - ps.vx[j]
    dvz = fi.vz - ps.vz[j]
    if k.three is None:   # 2D, decided when compiled: the y terms are constant zeros
        dy = 0.0
        dvy = 0.0
    else:
        dvy = fi.vy - ps.vy[j]
    cont = a.cont - vol * fij * (dvx * dx + dvy * dy + dvz * dz)
    diff = a.diff + density_diffusion(fi.rho, rhoj, fi.khyd, dx, dy, dz, fij, vol, k)
    if ps.kind[j] == WALL:
        gw, gnx, gny, gnz, gvx, gvy, gvz = wall_contact(a, j, dx, dy, dz, r2, fij, ps, k)
        tx = a.tx
        ty = a.ty
        tz = a.tz
        if fi.p < 0.0:
            pt = -vol * fi.p * fi.inv_rho
            tx += pt * fij * dx
            ty += pt * fij * dy
            tz += pt * fij * dz
        fx, fy, fz = wall_momentum(a.fx, a.fy, a.fz, fi.p, fi.vx, fi.vy, fi.vz, fi.rho, fi.inv_rho,
                                   j, dx, dy, dz, r2, fij, ps, k.av_wall, k)
        return FluidSums(fx, fy, fz, cont, diff, gw, gnx, gny, gnz, gvx, gvy, gvz, tx, ty, tz)
    pf = pressure_factor(vol, fi.p, ps.p[j], fi.inv_rho)
    fx, fy, fz = viscous_momentum(a.fx, a.fy, a.fz, pf, dvx, dvy, dvz, dx, dy, dz, r2, fij, fi.rho,
                                  rhoj, mj, k.av, k)
    return FluidSums(fx, fy, fz, cont, diff, a.gw, a.gnx, a.gny, a.gnz, a.gvx, a.gvy, a.gvz, a.tx,
                     a.ty, a.tz)


@njit(cache=True, inline="always")
def riemann_flux(i, j, dx, dz, r2, ps, fi, k):
    """(continuity sum, pressure factor) of the pair's linearised Riemann problem along
    e = r_ji / |r_ji| (riemann.py), MUSCL-reconstructed when k.muscl. 2D (x-z): a 3D scene
    refuses Riemann SPH (its MUSCL gradients are 2D rows)."""
    r = max(math.sqrt(r2), 1e-9 * k.h)   # coincident particles: no NaN
    ex = -dx / r
    ez = -dz / r
    ul = fi.vx * ex + fi.vz * ez
    ur = ps.vx[j] * ex + ps.vz[j] * ez
    ui = ul
    pl = fi.p
    pr = ps.p[j]
    wall = ps.kind[j] == WALL
    if k.muscl:
        dpj = pr - pl
        si = -(ps.gpx[i] * dx + ps.gpz[i] * dz)
        sj = si if wall else -(ps.gpx[j] * dx + ps.gpz[j] * dz)
        pl += 0.5 * limited(si, dpj)
        pr -= 0.5 * limited(sj, dpj)
        if not wall:
            duj = ur - ul
            si = -((ps.gux[i] * dx + ps.guz[i] * dz) * ex + (ps.gwx[i] * dx + ps.gwz[i] * dz) * ez)
            sj = -((ps.gux[j] * dx + ps.guz[j] * dz) * ex + (ps.gwx[j] * dx + ps.gwz[j] * dz) * ez)
            ul += 0.5 * limited(si, duj)
            ur -= 0.5 * limited(sj, duj)
    rhoj = ps.rho[j]
    ustar, pstar = interface_state(ul, ur, pl, pr, 0.5 * (fi.rho + rhoj) * k.c0,
                                   k.wall_rs if wall else 1.0)
    vol = ps.m[j] / rhoj
    fij = kernel_f(r2, k)
    return 2.0 * vol * fij * r * (ui - ustar), 2.0 * vol * pstar * fi.inv_rho


@njit(cache=True, inline="always")
def riemann_pair(i, j, dx, dy, dz, r2, ps, ctx, a):
    """Fluid particle i and a fluid, buffer or wall neighbour j in Riemann SPH (2D): the flux's
    continuity and pressure, laminar viscosity; for a wall, the contact sums (no tension
    push: the flux has none). ctx = (FluidConsts, FluidI)."""
    k = ctx[0]
    fi = ctx[1]
    if k.three is None:   # 2D, decided when compiled (wcsph_pair)
        dy = 0.0
    fij = kernel_f(r2, k)
    rhoj = ps.rho[j]
    mj = ps.m[j]
    dc, pf = riemann_flux(i, j, dx, dz, r2, ps, fi, k)
    cont = a.cont + dc
    if ps.kind[j] == WALL:
        gw, gnx, gny, gnz, gvx, gvy, gvz = wall_contact(a, j, dx, dy, dz, r2, fij, ps, k)
        if k.noslip:
            fx, fy, fz = viscous_momentum(a.fx, a.fy, a.fz, pf, fi.vx - ps.vwx[j], 0.0,
                                          fi.vz - ps.vwz[j], dx, dy, dz, r2, fij, fi.rho, rhoj,
                                          mj, 0.0, k)
        else:
            fx = a.fx + pf * fij * dx
            fy = a.fy
            fz = a.fz + pf * fij * dz
        return FluidSums(fx, fy, fz, cont, a.diff, gw, gnx, gny, gnz, gvx, gvy, gvz, a.tx, a.ty,
                         a.tz)
    fx, fy, fz = viscous_momentum(a.fx, a.fy, a.fz, pf, fi.vx - ps.vx[j], 0.0, fi.vz - ps.vz[j],
                                  dx, dy, dz, r2, fij, fi.rho, rhoj, mj, 0.0, k)
    return FluidSums(fx, fy, fz, cont, a.diff, a.gw, a.gnx, a.gny, a.gnz, a.gvx, a.gvy, a.gvz,
                     a.tx, a.ty, a.tz)


class WallSums(NamedTuple):
    """The Adami sums of a wall particle over its fluid neighbours."""

    sw: float     # sum W
    sp: float     # sum (p_f + rho_f (g - a_s) . r_sf) W
    svx: float    # sum v_f W
    svy: float
    svz: float


WALL_SUMS_ZERO = WallSums(0.0, 0.0, 0.0, 0.0, 0.0)


@njit(cache=True, inline="always")
def adami_sum(a, w, pj, rhoj, br, vxj, vyj, vzj):
    """WallSums ``a`` plus one fluid neighbour's share: kernel weight w, pressure pj, density
    rhoj, br = (g - a_s) . r_sf the hydrostatic lever, velocity (vxj, vyj, vzj)."""
    return WallSums(a.sw + w, a.sp + (pj + rhoj * br) * w, a.svx + vxj * w, a.svy + vyj * w,
                    a.svz + vzj * w)


@njit(cache=True, inline="always")
def adami_pair(i, j, dx, dy, dz, r2, ps, ctx, a):
    """Wall particle i and fluid neighbour j (Adami, Hu & Adams 2012): the kernel-weighted
    pressure with the hydrostatic correction and velocity. ctx = (inv_h, alpha_w, bx, by, bz),
    b = g - a_i the wall's apparent gravity. (ISPH's wall rows sum the same, without the fluid's
    pressure: isph.isph_terms.wall_pair.)"""
    w = w_of_q(math.sqrt(r2) * ctx[0], ctx[1])
    return adami_sum(a, w, ps.p[j], ps.rho[j], ctx[2] * dx + ctx[3] * dy + ctx[4] * dz, ps.vx[j],
                     ps.vy[j], ps.vz[j])


@njit(cache=True, inline="always")
def body_reaction(i, j, dx, dy, dz, r2, ps, k, a):
    """Body particle i (a wall) and fluid neighbour j: minus m_j times the fluid-wall pair's
    momentum on j (``wall_momentum``, with the p_j the walls felt, row pw). a = (fx, fy, fz)."""
    fij = kernel_f(r2, k)
    rhoj = ps.rho[j]
    pax, pay, paz = wall_momentum(0.0, 0.0, 0.0, ps.pw[j], ps.vx[j], ps.vy[j], ps.vz[j], rhoj,
                                  1.0 / rhoj, i, -dx, -dy, -dz, r2, fij, ps, k.av_wall, k)
    mj = ps.m[j]
    return a[0] - mj * pax, a[1] - mj * pay, a[2] - mj * paz


@njit(cache=True, inline="always")
def mass_pair(i, j, dx, dy, dz, r2, ps, ctx, a):
    """sum m W at a point (seed 004's kernel mass density: the elevation probes' and the open
    ends' boundary gauges' line); ctx = (h, alpha_w)."""
    return a + ps.m[j] * w_of_q(math.sqrt(r2) / ctx[0], ctx[1])
