"""Open-boundary buffers (Tafuni et al. 2018; seed 002): the jitted open-end terms of a step.

The step (step.run) calls three hooks, each a no-op when ``ends.active`` is False (closed tank):
    update_buffers      after the drift: impose and move buffers, then the crossings (appends)
    extrapolate_buffers after the sort: ghost-node pressure of extrapolating ends
    measure_boundaries  after the forces: the boundary gauges (eta_meas)
and ISPH's stepper a fourth after update_buffers where its scheme asks for relaxation zones:
    relax_to_source     the fluid's velocity pulled towards the wave's near each face
The Python side (settings, sources, windows, validation) is open_ends.OpenBoundaries.

A flume has at most two open ends, index b = 0 (left, particle kinds INLET / INLET_IDLE) and
b = 1 (right, OUTLET / OUTLET_IDLE). Each end is a buffer of width L >= 2h outside the tank face
x_f (the wave's surface orbit wide: open_ends.buffer_widths), outward normal n_x (-1 left, +1
right); d = (x - x_f) n_x is the depth into the buffer.

Every step, for buffer particle i of end b (the window [t0, t1] holds the source's samples,
interpolated linearly in time and linearly in z between the nodes):
    u_i = u(z_i, t) + du_b P_b(z_i) - (x_i - x_f) dw/dz(z_i, t),  w_i = w(z_i, t),
    x_i += dt u_i,  z_i += dt w_i
    (each particle follows the orbit whose velocity it carries, u carried off the face by
    continuity; kept between bed and tank top)
    du_b = n_x G[eta_meas,b - eta_gauge,b(t)]  if absorbing   (seed 002 correction; G a causal
           filter of the mismatch following Biesel's piston gain per frequency, its direct
           gain in the ends' sqgd, see sph_core.absorption); P_b the correction's vertical
           profile (ends.corr_prof on the nodes: linear theory's cosh k(z + d) at the wave
           period, 1 when no period is known)
    surface z_s,b = swl + eta_b(t)  (elevation imposed)  or, extrapolated,
    swl + eta_b(t) + (eta_meas,b - eta_gauge,b(t)) (the source's elevation at the face plus the
    gauge's mismatch)
    active (interacts as fluid) iff z_i < z_s,b;  rho_i = rho0 (1 + rho0 g (z_s,b - z_i)/B)^(1/7)
    (hydrostatic below the imposed or measured surface; Tait EOS, same form as the initial state),
    or, at an end with ghost extrapolation (OpenEnds.ghost; seed 002's outlet), and at a
    hydrostatic end within SURFACE_BAND_H h of its surface, after the sort:
    p_i = p_g + (x_i - x_g) dp/dx_g from the fluid at the ghost node x_g = 2 x_f - x_i mirrored
    into the fluid (first-order consistent interpolation, Tafuni et al. 2018), rho_i = EOS^-1(p_i).
    The outlet extrapolates by default (scene.OUTLET_PRESSURE, with the measured reflection: half
    the hydrostatic buffer's): the hydrostatic buffer takes the pressure of the surface measured
    2h inside the face, out of phase with the face and without the wave's non-hydrostatic
    pressure; the ghost nodes carry the fluid's own pressure field into the buffer. The inlet
    is hydrostatic (seed 002) below a band near its surface: the continuum hydrostatic profile
    is not the SPH fluid's discrete equilibrium near its free surface, and the difference pulled
    the fluid's surface corner into the buffer (SURFACE_BAND_H).
Crossings (d: depth into the buffer, counted per end so that mass balance is exact):
    fluid with d >= 0 where the imposed flow leaves (u n_x > 0), or with d >= dp
                                 -> buffer                         (counter OUT)
    active buffer with d < 0     -> fluid, new buffer particle at x + n_x L, same z (IN, CREATED)
    idle buffer with d < 0       -> removed (it is above the surface), replaced as above (REMOVED)
    buffer with d >= L           -> removed (slot INACTIVE, dropped at the next sort) (REMOVED)
The condition on fluid entering against an inflow stops a particle at the face from bouncing
between fluid and buffer: every bounce would clone it at the far end (a net particle created
each time), and the clones pile up into clumps that blow the inflow up.
The measured elevation comes from a gauge a short distance inside the face: the vertical-line
method (seed 004, second method), surface where sum_j m_j W falls below rho0/2, fluid and
active buffer particles counted; NaN when dry (then no correction, imposed surface used).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .eos import density, pressure
from .kernels import f_of_q, w_of_q
from .neighbours import cell_at
from .pairs import fluid_only, fluidlike, gather
from .terms import mass_pair  # the boundary gauge is an elevation probe's line
from .particles import FLUID, INACTIVE, INLET, OUTLET

# idle buffer particles: above the boundary's surface, kept in place but not interacting.
# End b has active kind INLET + b and idle kind INLET_IDLE + b.
INLET_IDLE = 4
OUTLET_IDLE = 5

# smallest determinant of the (h-scaled) first-order correction matrix at a ghost node; below it
# the node has too few fluid neighbours on too few sides (free surface, corner) for a gradient,
# and the Shepard (zeroth-order) value is used. DualSPHysics' default limit (Tafuni et al. 2018).
GHOST_DET_MIN = 1e-3
# depth below a hydrostatic buffer's surface, in h, within which its pressure is extrapolated from
# the fluid as at a ghost end: the SPH fluid's equilibrium near its free surface is not the
# continuum rho0 g (z_s - z) (kernel truncation: at h/dp 2 and rest the top fluid row, dp/2 below
# the surface, carries ~195 Pa against 98 at dp 0.02, the next row +11 %, deeper rows within a
# few %), and a buffer holding the continuum profile there pulls the fluid's surface corner into
# it (4 cm/s in still water; tests/test_sph_core/test_open_boundary.py). Below the band the imposed
# hydrostatic pressure stands (seed 002's inlet). The band is h: the top two rows at h/dp 2.
SURFACE_BAND_H = 1.0
# per-end counters[b, :]
C_IN, C_OUT, C_CREATED, C_REMOVED = range(4)
N_COUNTERS = 4


# The helpers below are inline="always": the CPU loops and the CUDA kernels
# (sph_core/cuda/gpu_open_ends.py) call the same per-particle functions, and numba-cuda compiles
# only inlined callees without a device (docs/developer/gpu.md).
@njit(cache=True, inline="always")
def node_index(zn, z):
    """np.searchsorted(zn, z) (side left) for finite z, by bisection (numba-cuda has no
    searchsorted)."""
    lo = 0
    hi = zn.size
    while lo < hi:
        mid = (lo + hi) // 2
        if zn[mid] < z:
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit(cache=True, inline="always")
def _blend(a, k, r):
    """(1 - r) a[lv=0, k] + r a[lv=1, k] for a window array a[level, node]."""
    return (1.0 - r) * a[0, k] + r * a[1, k]


@njit(cache=True, inline="always")
def profile_value(zn, a, r, z):
    """Profile a[level, node] at height z: linear in z between nodes zn (clamped at the ends),
    linear in time with weight r of level 1."""
    nn = zn.size
    k = node_index(zn, z)
    if k <= 0:
        return _blend(a, 0, r)
    if k >= nn:
        return _blend(a, nn - 1, r)
    s = (z - zn[k - 1]) / (zn[k] - zn[k - 1])
    return (1.0 - s) * _blend(a, k - 1, r) + s * _blend(a, k, r)


@njit(cache=True, inline="always")
def profile_slope(zn, a, r, z):
    """d/dz of profile_value at height z (0 outside the nodes, where the profile is clamped)."""
    k = node_index(zn, z)
    if k <= 0 or k >= zn.size:
        return 0.0
    return (_blend(a, k, r) - _blend(a, k - 1, r)) / (zn[k] - zn[k - 1])


@njit(cache=True, inline="always")
def node_value(zn, a, z):
    """Profile a[node] at height z: linear in z between nodes zn (clamped at the ends)."""
    nn = zn.size
    k = node_index(zn, z)
    if k <= 0:
        return a[0]
    if k >= nn:
        return a[nn - 1]
    s = (z - zn[k - 1]) / (zn[k] - zn[k - 1])
    return (1.0 - s) * a[k - 1] + s * a[k]


@njit(cache=True, inline="always")
def window_weight(t, win_t):
    """Weight r of the window end in the linear time interpolation, clamped to [0, 1]."""
    span = win_t[1] - win_t[0]
    if span <= 0.0:
        return 1.0
    return min(max((t - win_t[0]) / span, 0.0), 1.0)


@njit(cache=True, inline="always")
def boundary_state(b, r, dt, ends):
    """(z_s, du) of end b: the surface the buffer uses and the absorption velocity correction
    du = n_x [D e + sum_j c_j x_j], e = eta_meas - eta_gauge, each x_j the mismatch low-passed
    with time constant tau_j (advanced by dt here, exactly for e constant over the step;
    sph_core.absorption). A dry gauge counts as no mismatch."""
    eta_th = (1.0 - r) * ends.win_eta[b, 0] + r * ends.win_eta[b, 1]
    etag_th = (1.0 - r) * ends.win_etag[b, 0] + r * ends.win_etag[b, 1]
    em = ends.eta_meas[b]
    du = 0.0
    if ends.absorb[b]:
        e = em - etag_th if math.isfinite(em) else 0.0
        du = ends.sqgd[b] * e
        for j in range(ends.filt_c.shape[1]):
            xj = ends.filt_x[b, j]
            xj += (e - xj) * (1.0 - math.exp(-dt / ends.filt_tau[b, j]))
            ends.filt_x[b, j] = xj
            du += ends.filt_c[b, j] * xj
        du *= ends.nx[b]
    eta = eta_th
    if not ends.imposed[b] and math.isfinite(em):
        # measured surface carried to the face by the source (the target wave's own phase over
        # the gauge offset; only the mismatch is read at the gauge)
        eta = eta_th + (em - etag_th)
    zs = ends.swl[b] + eta
    # the surface never leaves the tank (validated data; a measured one could overshoot)
    zs = min(max(zs, ends.z_bed[b]), ends.z_top[b])
    return zs, du


@njit(cache=True, inline="always")
def _end_of(k):
    if k == INLET or k == INLET_IDLE:
        return 0
    if k == OUTLET or k == OUTLET_IDLE:
        return 1
    return -1


@njit(cache=True, inline="always")
def buffer_particle(i, ps, dt, r, zs0, du0, zs1, du1, ends, prm):
    """Buffer slot i imposed and moved (``buffer_update``'s body): returns (b, u, w, x, z,
    kind, rho, p) with b = -1 (nothing to write) when slot i is not a buffer particle. The
    particle moves with the source's (u, w): moved in x only, it would sit off the orbit whose
    velocity it carries by the orbit's vertical excursion (2-4 dp at H/dp 4-8), a divergence its
    fluid neighbours' continuity sees and the flow has not."""
    b = _end_of(ps.kind[i])
    if b < 0:
        return -1, 0.0, 0.0, 0.0, 0.0, 0, 0.0, 0.0
    zi = ps.z[i]
    zs = zs0 if b == 0 else zs1
    du = du0 if b == 0 else du1
    zn = ends.zn[b]
    # u carried off the face by continuity, du/dx = -dw/dz: an x-uniform u with the vertical
    # strain of w would make the buffer's particle density breathe with the wave, a spurious
    # second-order flux through the face
    u = (profile_value(zn, ends.win_u[b], r, zi) + du * node_value(zn, ends.corr_prof[b], zi)
         - (ps.x[i] - ends.x_face[b]) * profile_slope(zn, ends.win_w[b], r, zi))
    w = profile_value(zn, ends.win_w[b], r, zi)
    xi = ps.x[i] + dt * u
    zi = min(max(zi + dt * w, ends.z_bed[b]), ends.z_top[b])
    if zi < zs:
        rho0 = prm.rho0
        rho = rho0 * (1.0 + rho0 * (-prm.gz) * (zs - zi) / prm.b) ** (1.0 / prm.gamma)
        return b, u, w, xi, zi, INLET + b, rho, pressure(rho, rho0, prm.b, prm.gamma)
    return b, u, w, xi, zi, INLET_IDLE + b, prm.rho0, 0.0


@njit(parallel=True, cache=True)
def buffer_update(ps, n, dt, r, zs0, du0, zs1, du1, ends, prm):
    """Impose velocity, move, (de)activate and set hydrostatic density of every buffer particle."""
    # the rows written as locals (``ps.x[i] = ...`` inside a prange writes nothing, numba 0.68.1)
    x = ps.x
    z = ps.z
    vx = ps.vx
    vy = ps.vy
    vz = ps.vz
    rho_ = ps.rho
    p = ps.p
    drho = ps.drho
    ax = ps.ax
    ay = ps.ay
    az = ps.az
    kind = ps.kind
    acc = prm.buffer_acceleration
    for i in prange(n):
        b, u, w, xi, zi, k, rho, pi = buffer_particle(i, ps, dt, r, zs0, du0, zs1, du1, ends,
                                                      prm)
        if b < 0:
            continue
        # the imposed velocity's change along the particle's path, absorption correction
        # included (ISPH's buffer rows: the pressure that gives the buffer its motion)
        ax[i] = (u - vx[i]) / dt if acc else 0.0
        az[i] = (w - vz[i]) / dt if acc else 0.0
        vx[i] = u
        vz[i] = w
        x[i] = xi
        z[i] = zi
        kind[i] = k
        rho_[i] = rho
        p[i] = pi
        drho[i] = 0.0
        if prm.three is not None:   # long-crested: the boundary data has no y component
            vy[i] = 0.0
            ay[i] = 0.0


@njit(parallel=True, cache=True)
def relax_to_source(ps, n, t1, dt, ends, length, tau, zt):
    """ISPH's relaxation zones (Scheme.isph_relaxation_zone): every fluid particle within
    ``length`` of an open end's face has its velocity pulled towards the wave's velocity there
    at t1 by a = 1 - exp(-dt q^2 / tau), q = 1 - s / length, s the distance from the face: the
    pull is strongest at the face and vanishes with its slope at the zone's end. The target is
    the wave's local value where the source knows it inside the domain (``zt``, a
    state.ZoneTargets: the profiles at stations ds apart, linear between them; a theory's value
    above its surface is its surface value), else the end's source profile at the face (u, w)(z,
    t1) (the buffer's imposed profile without the absorption correction; above the face's surface
    z_s the value at z_s): a pull towards the face's phase across a zone a good fraction of a
    wavelength long, which reflects (docs/studies/schemes.md, "A zone that pulls towards the
    local wave"). Wave codes generate and absorb with such zones (Altomare et al. 2018 in
    DualSPHysics). Why ISPH needs one: at outflow through the inlet the fluid's surface beside
    the face fell below the buffer's and then rose at twice its speed, and the flume broke down
    there within ~3 periods (docs/studies/schemes.md, "The wave flume's open ends with
    relaxation zones")."""
    if not ends.active:
        return
    r = window_weight(t1, ends.win_t)
    vx = ps.vx
    vz = ps.vz
    kind = ps.kind
    last = zt.u.shape[1] - 2
    for i in prange(n):
        if kind[i] != FLUID:
            continue
        for b in range(2):
            if not ends.on[b]:
                continue
            s = (ps.x[i] - ends.x_face[b]) * (-ends.nx[b])
            if s < 0.0 or s >= length:
                continue
            q = 1.0 - s / length
            a = 1.0 - math.exp(-dt * q * q / tau)
            if zt.local[b]:
                f = s / zt.ds
                k = min(int(f), last)
                f -= k
                zi = ps.z[i]
                ut = ((1.0 - f) * profile_value(ends.zn[b], zt.u[b, k], r, zi)
                      + f * profile_value(ends.zn[b], zt.u[b, k + 1], r, zi))
                wt = ((1.0 - f) * profile_value(ends.zn[b], zt.w[b, k], r, zi)
                      + f * profile_value(ends.zn[b], zt.w[b, k + 1], r, zi))
            else:
                zi = min(ps.z[i], ends.zs[b])
                ut = profile_value(ends.zn[b], ends.win_u[b], r, zi)
                wt = profile_value(ends.zn[b], ends.win_w[b], r, zi)
            vx[i] += a * (ut - vx[i])
            vz[i] += a * (wt - vz[i])


# what a slot does at the face crossings (transition_of)
T_NONE, T_TO_BUFFER, T_TO_FLUID, T_IDLE_OUT, T_FAR_OUT = range(5)


@njit(cache=True, inline="always")
def transition_of(i, ps, ends, r, zs0, du0, zs1, du1):
    """The crossing of slot i (``buffer_transitions``' body, after buffer_update): returns
    (action, b, kind): T_TO_BUFFER fluid becomes a buffer particle of end b with that kind
    (counter OUT); T_TO_FLUID an active buffer particle becomes fluid and T_IDLE_OUT an idle
    one is removed, both cloned at x + n_x L with their old kind (IN or REMOVED, CREATED);
    T_FAR_OUT removed past the buffer's far side (REMOVED); T_NONE nothing."""
    k = int(ps.kind[i])
    x = ps.x
    z = ps.z
    if k == FLUID:
        for b in range(2):
            nx = ends.nx[b]
            d = (x[i] - ends.x_face[b]) * nx
            if ends.on[b] and d >= 0.0:
                u = (profile_value(ends.zn[b], ends.win_u[b], r, z[i])
                     + (du0 if b == 0 else du1) * node_value(ends.zn[b], ends.corr_prof[b], z[i]))
                if u * nx > 0.0 or d >= ends.dp:
                    zs = zs0 if b == 0 else zs1
                    return T_TO_BUFFER, b, INLET + b if z[i] < zs else INLET_IDLE + b
                return T_NONE, b, k
        return T_NONE, -1, k
    b = _end_of(k)
    if b < 0:
        return T_NONE, b, k
    d = (x[i] - ends.x_face[b]) * ends.nx[b]
    if d < 0.0:
        if k == INLET + b:
            return T_TO_FLUID, b, FLUID
        return T_IDLE_OUT, b, INACTIVE
    if d >= ends.length[b]:
        return T_FAR_OUT, b, INACTIVE
    return T_NONE, b, k


@njit(cache=True)
def buffer_transitions(ps, n, ends, r, zs0, du0, zs1, du1, prm):
    """Convert particles crossing a face, spawn and remove buffer particles (serial: appends in
    slot order; the GPU's prefix sum over the clones gives the same slots). With
    ``prm.buffer_acceleration`` a particle entering a buffer takes its imposed velocity (its
    next acceleration is then the imposed flow's, not its step from the fluid's velocity).

    Returns the new slot count, or -1 if the capacity is exhausted."""
    f = ps.f
    x = ps.x
    kind = ps.kind
    ids = ps.ids
    counters = ends.counters
    n0 = n
    nrows = f.shape[0]
    # the faces as locals: a fluid particle inside both faces (nearly all of them) is skipped
    # without calling transition_of, whose reads of ``ends`` cost ~0.6 us a particle in this
    # serial loop (the demo flume at dp 0.01: 8.4 ms a step with open ends, 4.1 without the
    # calls; closed 3.3; bench/open_end_cost.py)
    # likewise a buffer particle inside its buffer (0 <= d < L: most of a buffer the wave's
    # orbit wide)
    on0, on1 = ends.on[0], ends.on[1]
    xf0, xf1 = ends.x_face[0], ends.x_face[1]
    nx0, nx1 = ends.nx[0], ends.nx[1]
    len0, len1 = ends.length[0], ends.length[1]
    for i in range(n0):
        k = kind[i]
        if k == FLUID:
            if not ((on0 and (x[i] - xf0) * nx0 >= 0.0) or (on1 and (x[i] - xf1) * nx1 >= 0.0)):
                continue
        else:
            b = _end_of(k)
            if b < 0:
                continue
            d = (x[i] - xf0) * nx0 if b == 0 else (x[i] - xf1) * nx1
            if d >= 0.0 and d < (len0 if b == 0 else len1):
                continue
        act, b, knew = transition_of(i, ps, ends, r, zs0, du0, zs1, du1)
        if act == T_NONE:
            continue
        if act == T_TO_BUFFER:
            counters[b, C_OUT] += 1
            if prm.buffer_acceleration:
                kind[i] = knew   # now, not below: buffer_particle reads it (dt 0: no move)
                _, u, w, _, _, _, _, _ = buffer_particle(i, ps, 0.0, r, zs0, du0, zs1, du1,
                                                         ends, prm)
                ps.vx[i] = u
                ps.vz[i] = w
        elif act == T_FAR_OUT:
            counters[b, C_REMOVED] += 1
        else:
            if n >= ends.capacity:
                return -1
            for row in range(nrows):
                f[row, n] = f[row, i]
            x[n] = x[i] + ends.nx[b] * ends.length[b]
            kind[n] = k
            ids[n] = ends.next_id[0]
            ends.next_id[0] += 1
            n += 1
            counters[b, C_CREATED] += 1
            counters[b, C_IN if act == T_TO_FLUID else C_REMOVED] += 1
        kind[i] = knew
    return n


@njit(cache=True)
def update_buffers(ps, n, t1, dt, ends, prm):
    """Open-end hook after the drift (data at t1 = t + dt): buffers imposed and moved, then the
    crossings. Returns the new slot count (-1: capacity exhausted); n unchanged if no open end."""
    if not ends.active:
        return n
    r = window_weight(t1, ends.win_t)
    zs0, du0 = boundary_state(0, r, dt, ends)
    zs1, du1 = boundary_state(1, r, dt, ends)
    ends.zs[0] = zs0
    ends.zs[1] = zs1
    buffer_update(ps, n, dt, r, zs0, du0, zs1, du1, ends, prm)
    return buffer_transitions(ps, n, ends, r, zs0, du0, zs1, du1, prm)


@njit(cache=True, inline="always")
def _ghost_pair(i, j, dx, dy, dz, r2, ps, ctx, a):
    """The moment sums of ghost_pressure (in its order a00 a01 a02 a10 a11 a12 a20 a21 a22 b0 b1
    b2) for fluid neighbour j of the node; ctx = (h, alpha_w, alpha_f)."""
    h = ctx[0]
    rx = -dx  # r_j = x_j - x_g
    rz = -dz
    q = math.sqrt(r2) / h
    v = ps.m[j] / ps.rho[j]
    w = v * w_of_q(q, ctx[1])
    fv = v * f_of_q(q, ctx[2]) * h  # h-scaled gradient weight: F r_j h, with r_j / h below
    sx = rx / h
    sz = rz / h
    pj = ps.p[j]
    return (a[0] + w, a[1] + w * sx, a[2] + w * sz,
            a[3] + fv * rx, a[4] + fv * rx * sx, a[5] + fv * rx * sz,
            a[6] + fv * rz, a[7] + fv * rz * sx, a[8] + fv * rz * sz,
            a[9] + w * pj, a[10] + fv * rx * pj, a[11] + fv * rz * pj)


@njit(cache=True, inline="always")
def ghost_pressure(ps, cells, xg, yg, zg, prm):
    """First-order consistent SPH interpolation of the fluid pressure at a ghost node (xg, yg, zg)
    (Liu & Liu 2006; Tafuni et al. 2018, eq. 13): with r_j = (x_j - xg, z_j - zg), V_j = m_j/rho_j,
    the Taylor series p_j = p_g + r_j . grad p_g tested with W_gj and grad W_gj = F_gj r_j gives
        sum_j V_j [W, F x_j, F z_j]^T [1, x_j, z_j] (p_g, p_x, p_z)^T
            = sum_j V_j [W, F x_j, F z_j]^T p_j
    over fluid particles j; a linear field is reproduced exactly. Solved in h-scaled form (the
    matrix is the identity for a full, regular support). Returns (p_g, p_x, p_z, order): order 1
    if the determinant exceeds GHOST_DET_MIN, 0 for the Shepard value sum V W p / sum V W with no
    gradient, -1 if the node has no fluid neighbour. In 3D (long-crested boundary data) the
    same fit in x and z over the node's 3D support: the pressure does not vary across y."""
    h = prm.h
    s = gather(-1, xg, yg, zg, cell_at(xg, yg, zg, cells), ps, cells, 4.0 * h * h, fluid_only,
               _ghost_pair, (h, prm.alpha_w, prm.alpha_f),
               (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    a00, a01, a02, a10, a11, a12, a20, a21, a22, b0, b1, b2 = s
    if a00 <= 0.0:
        return 0.0, 0.0, 0.0, -1
    det = (a00 * (a11 * a22 - a12 * a21) - a01 * (a10 * a22 - a12 * a20)
           + a02 * (a10 * a21 - a11 * a20))
    if abs(det) < GHOST_DET_MIN:
        return b0 / a00, 0.0, 0.0, 0
    pg = (b0 * (a11 * a22 - a12 * a21) - a01 * (b1 * a22 - a12 * b2)
          + a02 * (b1 * a21 - a11 * b2)) / det
    px = (a00 * (b1 * a22 - a12 * b2) - b0 * (a10 * a22 - a12 * a20)
          + a02 * (a10 * b2 - b1 * a20)) / det
    pz = (a00 * (a11 * b2 - b1 * a21) - a01 * (a10 * b2 - b1 * a20)
          + b0 * (a10 * a21 - a11 * a20)) / det
    return pg, px / h, pz / h, 1


@njit(parallel=True, cache=True)
def buffer_extrapolate(ps, n, cells, ends, prm):
    """Pressure and density of the active buffer particles of ends with ghost extrapolation
    (seed 002 outlet; Tafuni et al. 2018): buffer particle i at depth d past the face x_f gets the
    fluid's pressure at its ghost node x_g = 2 x_f - x_i (same z, d inside the fluid), carried to
    x_i by the interpolated gradient,
        p_i = max(p_g + (x_i - x_g) dp/dx, 0),   rho_i = rho0 (1 + p_i/B)^(1/gamma)
    (not below zero: buffer particles have no free surface of their own to hold a suction, as the
    hydrostatic option). A ghost node without fluid keeps the hydrostatic value of buffer_update.
    A hydrostatic end extrapolates too, but only within SURFACE_BAND_H h below its surface z_s:
    there the SPH fluid's equilibrium is not the continuum rho0 g (z_s - z) (module docstring)."""
    p_ = ps.p  # the rows written as locals (see buffer_update)
    rho = ps.rho
    for i in prange(n):
        ok, p, r = extrapolated_state(i, ps, cells, ends, prm)
        if ok:
            p_[i] = p
            rho[i] = r


@njit(cache=True, inline="always")
def extrapolated_state(i, ps, cells, ends, prm):
    """(written, p, rho) of slot i (``buffer_extrapolate``'s body): written False where slot i
    keeps its pressure (not an active buffer particle, below a hydrostatic end's band, out of
    every fluid particle's reach, or a ghost node without fluid)."""
    k = ps.kind[i]
    if k != INLET and k != OUTLET:
        return False, 0.0, 0.0
    b = 0 if k == INLET else 1
    zi = ps.z[i]
    if not ends.ghost[b] and zi < ends.zs[b] - SURFACE_BAND_H * prm.h:
        return False, 0.0, 0.0
    xi = ps.x[i]
    # fluid stands at most dp past the face (transition_of), so a buffer particle 4h beyond
    # that is neither a fluid particle's neighbour nor a neighbour of a wall particle whose
    # extrapolated state a fluid particle reads: its pressure would serve nothing
    if (xi - ends.x_face[b]) * ends.nx[b] >= 4.0 * prm.h + ends.dp:
        return False, 0.0, 0.0
    xg = 2.0 * ends.x_face[b] - xi
    pg, px, pz, order = ghost_pressure(ps, cells, xg, ps.y[i], zi, prm)
    if order < 0:
        return False, 0.0, 0.0
    p = max(pg + (xi - xg) * px, 0.0)
    return True, p, density(p, prm.rho0, prm.b, prm.gamma)


@njit(cache=True)
def extrapolate_buffers(ps, n, cells, ends, prm):
    """Open-end hook after the sort: ghost-node pressure of the extrapolating ends' buffers and
    of the hydrostatic ends' surface band."""
    if ends.active:
        buffer_extrapolate(ps, n, cells, ends, prm)


@njit(cache=True, inline="always")
def line_density(ps, cells, xp, yp, zk, prm):
    """sum_j m_j W(x - x_j) at (xp, yp, zk) over fluid and active buffer particles (a gauge
    point)."""
    h = prm.h
    return gather(-1, xp, yp, zk, cell_at(xp, yp, zk, cells), ps, cells, 4.0 * h * h, fluidlike,
                  mass_pair, (h, prm.alpha_w), 0.0)


@njit(cache=True, inline="always")
def gauge_points(ends, b):
    """Points of end b's gauge line (``surface_z``'s): z_bed + k dz_gauge, k < this count."""
    return int((ends.z_top[b] - ends.z_bed[b]) / ends.dz_gauge) + 1


@njit(cache=True, inline="always")
def crossing(k, nz, zk, s, prev, dz, level):
    """Surface height where the line density falls through ``level`` between point k (density
    s >= level, height zk) and the point above (density prev)."""
    if k == nz - 1:
        return zk
    return zk + (s - level) / (s - prev) * dz


@njit(cache=True)
def surface_z(ps, cells, xp, yp, z_lo, z_hi, dz, prm):
    """Free-surface height at (xp, yp) by the vertical-line method (seed 004, eq. 23):
    rho_f(z) = sum_j m_j W(x - x_j) over fluid and active buffer particles on points z_lo + k dz;
    the surface is the highest z where rho_f falls through rho0/2 (linear between points).
    Returns NaN when no point reaches rho0/2 (dry)."""
    level = 0.5 * prm.rho0
    nz = int((z_hi - z_lo) / dz) + 1
    prev = 0.0
    for k in range(nz - 1, -1, -1):
        zk = z_lo + k * dz
        s = line_density(ps, cells, xp, yp, zk, prm)
        if s >= level:
            return crossing(k, nz, zk, s, prev, dz, level)
        prev = s
    return np.nan


@njit(cache=True)
def measure_boundaries(ps, cells, ends, prm):
    """Open-end hook after the forces: eta_meas[b] = surface at the boundary gauge of end b minus
    the still-water level."""
    if not ends.active:
        return
    for b in range(2):
        if ends.on[b]:
            zsurf = surface_z(ps, cells, ends.x_gauge[b], ends.y_gauge, ends.z_bed[b],
                              ends.z_top[b], ends.dz_gauge, prm)
            ends.eta_meas[b] = zsurf - ends.swl[b]
