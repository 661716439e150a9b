"""The state the jitted kernels read and write, in four typed containers (numba named tuples).

    Particles  one particle buffer: the float rows (named views of one 2D array), kind, ids, cell
    Cells      the cell lists of the current order and the grid they index
    Params     the run's constants (kernel, EOS, viscosity, time step, the tank's domain box)
    OpenEnds   the open inlet/outlet ends: settings per end, the window's boundary data, and the
               measured state (gauges, counters); ``active`` False makes every open-end hook a no-op

A kernel takes the containers it needs, so its signature says what it touches: e.g.
``fluid_pass(ps, n, cells, prm)``. Arrays inside are shared (writes go to the run's storage);
the scalars are values. Every container's numba type is the same for every scene (a closed tank
carries an inactive ``OpenEnds`` of the same shapes), so each kernel compiles once and caches.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .absorption import N_FILTER
from .particles import (AX, AY, AZ, DRHO, DVNX, DVNY, DVNZ, GPX, GPZ, GUX, GUZ, GWX, GWZ, M, P,
                        PW, RHO, RHON, VWX, VWY, VWZ, VX, VXN, VY, VYN, VZ, VZN, XN, YN, ZN, X, Y,
                        Z)


class Particles(NamedTuple):
    """One particle buffer (the run keeps two and swaps them at every sort).

    ``f[row, slot]`` is the storage (copied whole by the sort and by buffer cloning); the named
    arrays are views of its rows. Rows x..m are carried through a sort, xn..rhon (the symplectic
    predictor's state at t^n) too for that integrator, drho/vwx/vwz are recomputed after it."""

    f: np.ndarray
    x: np.ndarray
    y: np.ndarray        # zero in a 2D scene (the x-z plane)
    z: np.ndarray
    vx: np.ndarray
    vy: np.ndarray
    vz: np.ndarray
    ax: np.ndarray
    ay: np.ndarray
    az: np.ndarray
    rho: np.ndarray
    p: np.ndarray
    m: np.ndarray
    xn: np.ndarray
    yn: np.ndarray
    zn: np.ndarray
    vxn: np.ndarray
    vyn: np.ndarray
    vzn: np.ndarray
    rhon: np.ndarray
    drho: np.ndarray
    vwx: np.ndarray      # wall particles: velocity for the viscous term (Adami no-slip)
    vwy: np.ndarray
    vwz: np.ndarray
    gpx: np.ndarray      # Riemann SPH + MUSCL (2D): grad p, grad vx = (gux, guz), grad vz = (gwx, gwz)
    gpz: np.ndarray
    gux: np.ndarray
    guz: np.ndarray
    gwx: np.ndarray
    gwz: np.ndarray
    dvnx: np.ndarray     # fluid: no-penetration velocity correction at a wall face (wall_contact.py)
    dvny: np.ndarray
    dvnz: np.ndarray
    pw: np.ndarray       # fluid: the pressure its walls feel from it, p or max(p, 0) (wcsph.fluid_pass)
    kind: np.ndarray     # int8: particles.FLUID, WALL, INLET, ...
    ids: np.ndarray      # int64 identity, kept through sorts
    cell: np.ndarray     # int64 cell index of the slot (set by the sort)


def particles_view(f: np.ndarray, kind: np.ndarray, ids: np.ndarray, cell: np.ndarray) -> Particles:
    """Named views of the storage ``f`` (no copy)."""
    return Particles(f, f[X], f[Y], f[Z], f[VX], f[VY], f[VZ], f[AX], f[AY], f[AZ], f[RHO], f[P],
                     f[M], f[XN], f[YN], f[ZN], f[VXN], f[VYN], f[VZN], f[RHON], f[DRHO], f[VWX],
                     f[VWY], f[VWZ], f[GPX], f[GPZ], f[GUX], f[GUZ], f[GWX], f[GWZ], f[DVNX],
                     f[DVNY], f[DVNZ], f[PW], kind, ids, cell)


class Cells(NamedTuple):
    """Cell lists: the particles of cell c = (cz * ncy + cy) * ncx + cx are slots
    start[c]:start[c + 1] (the bin ncx * ncy * ncz holds inactive slots); cursor and order are
    the sort's scratch. A particle's neighbours are in the block neighbours.block_of(cell). A 2D
    scene has one layer of cells in y (ncy = 1: c = cz * ncx + cx)."""

    start: np.ndarray
    cursor: np.ndarray
    order: np.ndarray
    ncx: int
    ncz: int
    xmin: float
    zmin: float
    inv_cs: float
    reach: int           # cells per support radius 2h: the search block is (2 reach + 1)^dim
    ncy: int = 1         # cells across y (1: a 2D scene)
    ymin: float = 0.0
    three: bool | None = None   # True: a 3D grid; None: 2D, decided when compiled (Params.three)


class Params(NamedTuple):
    """Constants of a run [SI]."""

    h: float
    alpha_w: float       # Wendland C2: W = alpha_w (...), F = alpha_f (...)
    alpha_f: float
    rho0: float
    c0: float
    b: float             # Tait B
    gamma: float
    gx: float
    gz: float            # (gy: at the end, 0 unless a 3D scene tilts gravity)
    alpha: float         # artificial viscosity
    nu: float            # laminar viscosity
    delta: float         # delta-SPH
    cfl: float
    rho_lo: float        # density band (fraction of rho0); outside: the run stops
    rho_hi: float
    noslip: bool
    fx0: float           # box a fluid particle must stay in (else ST_LEFT_DOMAIN)
    fx1: float
    fz0: float
    fz1: float
    alpha_wall: float    # artificial viscosity against walls = alpha_wall * alpha
    shift_a: float       # particle shifting coefficient A (0: off; shifting.py)
    shift_fs_div: float  # position divergence below which shifting is tangential only
    # scheme (scene [scheme]; riemann.py): Riemann SPH instead of delta-SPH + Monaghan AV
    riemann: bool = False
    limiter: int = 0     # MUSCL reconstruction (riemann.VANLEER) or none (0)
    # particle shifting law (shifting.py): Fickian (D = shift_a h |v_i| dt) or delta-plus
    # (D = shift_a h max|v| dt, anti-clustering weight 1 + R (W / W(dp))^4 with shift_inv_wdp
    # = 1 / W(dp), Marrone's surface detection); shift_carry: Taylor-carry rho, v over the shift
    shift_dplus: bool = False
    shift_carry: bool = True
    shift_inv_wdp: float = 0.0
    # no-penetration correction at wall faces (wall_contact.py): the wall's kernel share
    # sum_s V_s W_is of a fluid particle dp/4 in front of a flat wall face, at it, dp/4 behind
    # it (wall_g0 = 0: off)
    wall_ga: float = 0.0
    wall_g0: float = 0.0
    wall_gb: float = 0.0
    # shifting next to an open end's buffer (shifting.SHIFT_OPEN_END): 0 full, 1 none
    shift_open: int = 0
    # ISPH (isph.stepper): each buffer particle keeps its imposed acceleration in ax, az (the
    # change of its imposed velocity over the step, open_boundary.buffer_update) for its
    # pressure row, and a particle entering a buffer takes its imposed velocity at once
    buffer_acceleration: bool = False
    # three dimensions: gravity's y component and the y range of the box of fx0..fz1
    gy: float = 0.0
    fy0: float = -1e300
    fy1: float = 1e300
    # True: a 3D scene; None: 2D. Its *type* differs (bool / none), so every kernel compiles
    # once per dimension, and in 2D the y components a term would add (exact zeros) are left
    # out at compile time: ``if prm.three is None`` (terms.py), as the step's None-able parts
    three: bool | None = None


class OpenEnds(NamedTuple):
    """Open ends b = 0 (left, kinds INLET/INLET_IDLE) and b = 1 (right, OUTLET/OUTLET_IDLE).

    Per-end settings are arrays of 2; the window [win_t[0], win_t[1]] holds the boundary data at
    its two ends (level 0, 1) on the nodes zn[b]; eta_meas, counters and next_id are written by
    the step. See open_boundary.py for the physics."""

    active: bool          # any end open; False: every open-end hook returns at once
    capacity: int         # slots of the particle buffers (inflow may append up to it)
    on: np.ndarray        # bool[2]
    x_face: np.ndarray    # face x [m]
    nx: np.ndarray        # outward normal (-1 left, +1 right)
    length: np.ndarray    # buffer width [m]
    swl: np.ndarray       # still-water level [m]
    sqgd: np.ndarray      # direct gain D of the absorption filter [1/s] (sph_core.absorption)
    absorb: np.ndarray    # bool[2]: absorption correction on
    imposed: np.ndarray   # bool[2]: surface imposed (else measured)
    ghost: np.ndarray     # bool[2]: buffer pressure extrapolated from ghost nodes
    x_gauge: np.ndarray   # boundary gauge x [m]
    z_bed: np.ndarray
    z_top: np.ndarray
    dz_gauge: float       # spacing of the gauge's line points [m]
    dp: float
    zn: np.ndarray        # [2, nodes] node heights
    win_t: np.ndarray     # [2]
    win_u: np.ndarray     # [2 ends, 2 levels, nodes]
    win_w: np.ndarray
    win_eta: np.ndarray   # [2 ends, 2 levels] target elevation
    win_etag: np.ndarray  # [2 ends, 2 levels] source's elevation at the gauge
    eta_meas: np.ndarray  # [2] measured elevation at the gauges (NaN: dry / not measured)
    zs: np.ndarray        # [2] surface z_s of each buffer at its last update [m]
    counters: np.ndarray  # int64[2, 4]: C_IN, C_OUT, C_CREATED, C_REMOVED
    next_id: np.ndarray   # int64[1]: id of the next created particle
    filt_tau: np.ndarray  # [2, N_FILTER] time constants of the absorption filter [s]
    filt_c: np.ndarray    # [2, N_FILTER] its gains [1/s] (sph_core.absorption)
    filt_x: np.ndarray    # [2, N_FILTER] its state: the mismatch low-passed with each tau [m]
    # [2, nodes]: the absorption correction's vertical profile on zn (depth mean 1 below the
    # still-water level; all ones: a depth-uniform piston; sph_core.absorption.correction_profile)
    corr_prof: np.ndarray
    # y of the boundary gauges' lines [m]: mid-width in a 3D scene (long-crested waves), 0 in 2D
    y_gauge: float = 0.0


class ZoneTargets(NamedTuple):
    """What ISPH's relaxation zones pull towards where the source knows the wave inside the SPH
    domain (a wave model evaluated there: open_ends.OpenBoundaries): the velocity profiles at
    stations s_k = k ds into the fluid from each face, k = 0..K-1, at the window's two times.
    ``local[b]`` False: end b's zone pulls towards the face's profile (the window's data; ends
    fed from outside, whose data stop at the face). open_boundary.relax_to_source reads it."""

    local: np.ndarray     # bool[2]
    ds: float             # station spacing [m]
    u: np.ndarray         # [2 ends, K stations, 2 levels, nodes]
    w: np.ndarray


def no_zone_targets(n_nodes: int = 2) -> ZoneTargets:
    """ZoneTargets of no local data (every zone pulls towards its face's profile)."""
    return ZoneTargets(np.zeros(2, dtype=np.bool_), 1.0, np.zeros((2, 2, 2, n_nodes)),
                       np.zeros((2, 2, 2, n_nodes)))


def closed_ends(capacity: int, n_nodes: int = 2) -> OpenEnds:
    """An inactive OpenEnds (a closed tank): same types as an open one, hooks do nothing."""
    z2 = lambda: np.zeros(2)  # noqa: E731
    b2 = lambda: np.zeros(2, dtype=np.bool_)  # noqa: E731
    return OpenEnds(False, int(capacity), b2(), z2(), np.array([-1.0, 1.0]), z2(), z2(), z2(),
                    b2(), b2(), b2(), z2(), z2(), np.ones(2), 0.0, 0.0,
                    np.tile(np.linspace(0.0, 1.0, n_nodes), (2, 1)), z2(),
                    np.zeros((2, 2, n_nodes)), np.zeros((2, 2, n_nodes)), np.zeros((2, 2)),
                    np.zeros((2, 2)), np.full(2, np.nan), z2(), np.zeros((2, 4), dtype=np.int64),
                    np.zeros(1, dtype=np.int64), np.ones((2, N_FILTER)),
                    np.zeros((2, N_FILTER)), np.zeros((2, N_FILTER)), np.ones((2, n_nodes)))
