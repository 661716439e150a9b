"""Rigid bodies of boundary particles in the SPH zone: fixed, prescribed, free, hinged.

    bodies = BodySet.from_scene(scene)         # shapes -> particles, mass, inertia, motion
    keep = bodies.fluid_outside(x, z, dp)      # fluid lattice points not inside a body
    bodies.attach(ps)                          # appends the body particles (kind WALL)
    bd = bodies.state                          # the kernels' typed container (``Bodies``)
    bodies.rows() -> dict                      # motions and loads for bodies.csv

Particles. A body is a set of dummy particles on the tank's lattice inside its shape, a shell
``n_layers * dp`` thick (as a fixed Structure), of kind WALL: the Adami wall treatment of the
tank applies unchanged (wcsph.wall_pass, fluid_pass). Body particles have the consecutive ids
``id0 .. id0 + npart - 1`` (kept through every sort), which index their offsets (rx, rz) from the
body's reference point at theta = 0. The kinematics set each particle's position, velocity
v = V + omega x r (continuity and no-slip terms) and acceleration a = A + alpha x r - omega^2 r
(the Adami pressure extrapolation uses g - a).

Reference point: the centre of mass for fixed, prescribed and free bodies; the pivot of a hinged
one. State per body q = (x_ref, z_ref, theta), qd its rate, acc its second derivative; theta is
counter-clockwise with x right and z up, so v = omega (-r_z, r_x) and the moment about the
reference point is M = r_x F_z - r_z F_x.

Loads (``body_loads``): the force on body particle k is minus the sum of the pair forces it
exerts on its fluid neighbours, -sum_i m_i a_ik with a_ik the very pair term of fluid_pass
(pressure + Monaghan AV + Lo & Shao laminar, with the Adami wall state of k), computed as a gather
over body particles (no scatter, no race), then summed per body. Fluid + body momentum is thus
conserved to round-off (tests/test_sph_core/test_bodies.py).

Dynamics (per metre of span):
    free:    m dU/dt = F_x - k_x (x - x0) - c_x U,   m dW/dt = F_z + m g_z - k_z (z - z0) - c_z W,
             I_c domega/dt = M_c - k_t (theta - theta0) - c_t omega;  DOFs not listed stay at rest
    hinged:  I_p domega/dt = M_p + (c x m g) - k (theta - theta0) - c omega,  I_p = I_c + m |c|^2,
             c the centre of mass relative to the pivot
    prescribed: q(t) = q(t_start) + series(t) (linear in t), qd its slope, acc = 0.
The bodies are integrated by the fluid's integrator stages (kdk: half-kick, drift, forces,
half-kick; symplectic_pc: predictor, forces at the half step, corrector), in the same jitted step.

Contact (stated limitation): there is none. Body particles interact with fluid only; a body may
pass through the tank walls, beds, structures or another body, and a body particle leaving the
tank's grid is clamped into its edge cells. Scenes must keep bodies clear of the walls.
"""

from __future__ import annotations

import csv
import math
import warnings
from pathlib import Path
from typing import NamedTuple

import numpy as np
from numba import njit, prange

from .pairs import fluid_only, gather
from .particles import AX, AZ, VX, VZ, WALL, X, Z, ParticleSet
from .scene import Body, Scene
from .terms import body_reaction, fluid_consts

FIXED = 0
PRESCRIBED = 1
FREE = 2
HINGED = 3
MOTIONS = {"fixed": FIXED, "prescribed": PRESCRIBED, "free": FREE, "hinged": HINGED}
DOF_INDEX = {"surge": 0, "heave": 1, "pitch": 2}


class Bodies(NamedTuple):
    """The bodies of a run, as the kernels see them (arrays shared with ``BodySet``).

    Per body b: settings and the state q, qd, acc [b, 3] = (x_ref, z_ref, theta) and rates;
    qn, qdn the symplectic predictor's state at t^n; load [b, 3] = fluid (F_x, F_z, M about the
    reference point). Per body particle k (id - id0): owner, offsets rx, rz at theta = 0, and the
    gather's per-particle load (fk_x, fk_z, fk_m)."""

    active: bool           # False: every body hook returns at once (no body in the scene)
    nb: int
    id0: int
    npart: int
    motion: np.ndarray     # int64[nb]
    dof: np.ndarray        # [nb, 3] 1.0 free, 0.0 held (free bodies)
    mass: np.ndarray       # [nb] kg/m
    inertia: np.ndarray    # [nb] kg m^2/m about the reference point (pivot for hinged)
    com0: np.ndarray       # [nb, 2] centre of mass - reference point at theta = 0
    spring: np.ndarray     # [nb, 3]
    damper: np.ndarray     # [nb, 3]
    q0: np.ndarray         # [nb, 3] state at t_start (spring rest, prescribed origin)
    q: np.ndarray
    qd: np.ndarray
    acc: np.ndarray
    qn: np.ndarray
    qdn: np.ndarray
    load: np.ndarray
    series_t: np.ndarray   # [nb, m] prescribed: times (absolute) ...
    series_q: np.ndarray   # [nb, m, 3] ... and displacements
    series_n: np.ndarray   # int64[nb] rows used
    owner: np.ndarray      # int64[npart]
    rx: np.ndarray
    rz: np.ndarray
    fk_x: np.ndarray
    fk_z: np.ndarray
    fk_m: np.ndarray


def no_bodies() -> Bodies:
    """An inactive container of the same numba type (a scene without bodies)."""
    z = lambda *s: np.zeros(s)  # noqa: E731
    return Bodies(False, 0, 0, 0, np.zeros(1, dtype=np.int64), z(1, 3), z(1), z(1), z(1, 2),
                  z(1, 3), z(1, 3), z(1, 3), z(1, 3), z(1, 3), z(1, 3), z(1, 3), z(1, 3), z(1, 3),
                  z(1, 2), z(1, 2, 3), np.zeros(1, dtype=np.int64), np.zeros(1, dtype=np.int64),
                  z(1), z(1), z(1), z(1), z(1))


# ------------------------------------------------------------------------------ kernels
# _prescribed and _set_prescribed are inline="always" and allocate nothing, so that the GPU
# step's one-thread kernel compiles bodies_advance (sph_core/cuda/gpu_bodies.py)
@njit(cache=True, inline="always")
def _prescribed(bd, b, t):
    """Displacement (3) and its slope (3) at time t of prescribed body b (linear between rows),
    as six scalars."""
    m = bd.series_n[b]
    ts = bd.series_t[b]
    sq = bd.series_q[b]
    if t <= ts[0]:
        return sq[0, 0], sq[0, 1], sq[0, 2], 0.0, 0.0, 0.0
    if t >= ts[m - 1]:
        return sq[m - 1, 0], sq[m - 1, 1], sq[m - 1, 2], 0.0, 0.0, 0.0
    lo = 0   # np.searchsorted(ts[:m], t, side="right") by bisection
    hi = m
    while lo < hi:
        mid = (lo + hi) // 2
        if ts[mid] <= t:
            lo = mid + 1
        else:
            hi = mid
    k = lo - 1
    span = ts[k + 1] - ts[k]
    s = (t - ts[k]) / span
    return (sq[k, 0] + s * (sq[k + 1, 0] - sq[k, 0]), sq[k, 1] + s * (sq[k + 1, 1] - sq[k, 1]),
            sq[k, 2] + s * (sq[k + 1, 2] - sq[k, 2]), (sq[k + 1, 0] - sq[k, 0]) / span,
            (sq[k + 1, 1] - sq[k, 1]) / span, (sq[k + 1, 2] - sq[k, 2]) / span)


@njit(cache=True, inline="always")
def _set_prescribed(bd, b, t_pos, t_vel):
    d0, d1, d2, _, _, _ = _prescribed(bd, b, t_pos)
    _, _, _, v0, v1, v2 = _prescribed(bd, b, t_vel)
    bd.q[b, 0] = bd.q0[b, 0] + d0
    bd.q[b, 1] = bd.q0[b, 1] + d1
    bd.q[b, 2] = bd.q0[b, 2] + d2
    bd.qd[b, 0] = v0
    bd.qd[b, 1] = v1
    bd.qd[b, 2] = v2
    for c in range(3):
        bd.acc[b, c] = 0.0


# the stages of the integrators a body follows (``bodies_advance``): kdk's first half (qd +=
# dt/2 acc, q += dt qd) and second half (qd += dt/2 acc); the symplectic predictor (save q, qd;
# q += dt/2 qd, qd += dt/2 acc) and corrector (qd = qdn + dt acc, q = qn + dt/2 (qd + qdn))
KICK_DRIFT, KICK, PREDICT, CORRECT = range(4)


@njit(cache=True)
def bodies_advance(bd, t, dt, stage):
    """One integrator stage of every body (t: the step's start); prescribed bodies take their
    motion at the stage's time instead (kick-drift: q(t + dt), qd(t + dt/2))."""
    if not bd.active:
        return
    hdt = 0.5 * dt
    for b in range(bd.nb):
        if stage == PREDICT:
            for c in range(3):
                bd.qn[b, c] = bd.q[b, c]
                bd.qdn[b, c] = bd.qd[b, c]
        mo = bd.motion[b]
        if mo == FREE or mo == HINGED:
            for c in range(3):
                if stage == KICK_DRIFT:
                    bd.qd[b, c] += hdt * bd.acc[b, c]
                    bd.q[b, c] += dt * bd.qd[b, c]
                elif stage == KICK:
                    bd.qd[b, c] += 0.5 * dt * bd.acc[b, c]
                elif stage == PREDICT:
                    bd.q[b, c] += hdt * bd.qd[b, c]
                    bd.qd[b, c] += hdt * bd.acc[b, c]
                else:
                    u = bd.qdn[b, c] + dt * bd.acc[b, c]
                    bd.q[b, c] = bd.qn[b, c] + 0.5 * dt * (u + bd.qdn[b, c])
                    bd.qd[b, c] = u
        elif mo == PRESCRIBED:
            if stage == KICK_DRIFT:
                _set_prescribed(bd, b, t + dt, t + hdt)
            elif stage == PREDICT:
                _set_prescribed(bd, b, t + hdt, t + hdt)
            else:
                _set_prescribed(bd, b, t + dt, t + dt)


@njit(cache=True, inline="always")
def body_arm(bd, k):
    """(body b, rx, rz) of body particle k: its offset from body b's reference point (rx, rz in
    the body's frame) turned by the body's angle q[b, 2]."""
    b = bd.owner[k]
    th = bd.q[b, 2]
    c = math.cos(th)
    s = math.sin(th)
    return b, c * bd.rx[k] - s * bd.rz[k], s * bd.rx[k] + c * bd.rz[k]


@njit(cache=True)
def bodies_v2max(bd):
    """Largest squared body-particle speed |V + omega x r|^2 (for the time step's CFL bound)."""
    v2max = 0.0
    if not bd.active:
        return v2max
    for k in range(bd.npart):
        b, rx, rz = body_arm(bd, k)
        om = bd.qd[b, 2]
        u = bd.qd[b, 0] - om * rz
        w = bd.qd[b, 1] + om * rx
        v2max = max(v2max, u * u + w * w)
    return v2max


@njit(cache=True, inline="always")
def body_particle(i, ps, bd):
    """(is a body particle, x, z, vx, vz, ax, az) of slot i from its body's q, qd, acc
    (``place_bodies``' body)."""
    k = ps.ids[i] - bd.id0
    if k < 0 or k >= bd.npart:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    b, rx, rz = body_arm(bd, k)
    om = bd.qd[b, 2]
    al = bd.acc[b, 2]
    return (True, bd.q[b, 0] + rx, bd.q[b, 1] + rz, bd.qd[b, 0] - om * rz, bd.qd[b, 1] + om * rx,
            bd.acc[b, 0] - al * rz - om * om * rx, bd.acc[b, 1] + al * rx - om * om * rz)


@njit(parallel=True, cache=True)
def place_bodies(ps, n, bd):
    """Position, velocity (V + omega x r) and acceleration of every body particle from q, qd, acc."""
    if not bd.active:
        return
    f = ps.f   # writes through the storage: numba drops prange stores made through ps.row[i]
    for i in prange(n):
        ok, x, z, vx, vz, ax, az = body_particle(i, ps, bd)
        if ok:
            f[X, i] = x
            f[Z, i] = z
            f[VX, i] = vx
            f[VZ, i] = vz
            f[AX, i] = ax
            f[AZ, i] = az


@njit(parallel=True, cache=True)
def _particle_loads(ps, n, cells, prm, bd):
    """Per body particle k: minus the pair forces it exerts on its fluid neighbours (the
    fluid-wall pair of the fluid pass, terms.body_reaction), and its moment about the body's
    reference point."""
    ids = ps.ids
    fk_x = bd.fk_x
    fk_z = bd.fk_z
    fk_m = bd.fk_m
    for j in prange(n):
        kb = ids[j] - bd.id0
        if kb >= 0 and kb < bd.npart and ps.kind[j] == WALL:
            # fluid_consts per particle: see wcsph.fluid_pass
            fk_x[kb], fk_z[kb], fk_m[kb] = particle_load(j, kb, ps, cells, bd, fluid_consts(prm))


@njit(cache=True, inline="always")
def particle_load(j, kb, ps, cells, bd, k):
    """(F_x, F_z, M) of body particle kb in slot j (``_particle_loads``' body); k the fluid
    pass's constants (terms.fluid_consts)."""
    xj = ps.x[j]
    zj = ps.z[j]
    fx, _, fz = gather(j, xj, ps.y[j], zj, ps.cell[j], ps, cells, k.s2, fluid_only,
                       body_reaction, k, (0.0, 0.0, 0.0))   # bodies move in the x-z plane (2D)
    b = bd.owner[kb]
    rx = xj - bd.q[b, 0]
    rz = zj - bd.q[b, 1]
    return fx, fz, rx * fz - rz * fx


@njit(cache=True)
def body_loads(ps, n, cells, prm, bd):
    """Fluid loads on every body (gather, then a per-body sum) and the resulting accelerations."""
    if not bd.active:
        return
    _particle_loads(ps, n, cells, prm, bd)
    body_accelerations(bd, prm)


@njit(cache=True, inline="always")
def body_accelerations(bd, prm):
    """Sum the per-particle loads per body (in particle order) and set each body's
    accelerations (``body_loads``' second half; one thread on the GPU)."""
    for b in range(bd.nb):
        for c in range(3):
            bd.load[b, c] = 0.0
    for k in range(bd.npart):
        b = bd.owner[k]
        bd.load[b, 0] += bd.fk_x[k]
        bd.load[b, 1] += bd.fk_z[k]
        bd.load[b, 2] += bd.fk_m[k]
    gx = prm.gx
    gz = prm.gz
    for b in range(bd.nb):
        mo = bd.motion[b]
        ma = bd.mass[b]
        if mo == FREE:
            fx = (bd.load[b, 0] + ma * gx - bd.spring[b, 0] * (bd.q[b, 0] - bd.q0[b, 0])
                  - bd.damper[b, 0] * bd.qd[b, 0])
            fz = (bd.load[b, 1] + ma * gz - bd.spring[b, 1] * (bd.q[b, 1] - bd.q0[b, 1])
                  - bd.damper[b, 1] * bd.qd[b, 1])
            mt = (bd.load[b, 2] - bd.spring[b, 2] * (bd.q[b, 2] - bd.q0[b, 2])
                  - bd.damper[b, 2] * bd.qd[b, 2])
            bd.acc[b, 0] = bd.dof[b, 0] * fx / ma
            bd.acc[b, 1] = bd.dof[b, 1] * fz / ma
            bd.acc[b, 2] = bd.dof[b, 2] * mt / bd.inertia[b]
        elif mo == HINGED:
            th = bd.q[b, 2]
            co = math.cos(th)
            si = math.sin(th)
            cxr = co * bd.com0[b, 0] - si * bd.com0[b, 1]
            czr = si * bd.com0[b, 0] + co * bd.com0[b, 1]
            mg = cxr * ma * gz - czr * ma * gx
            f = (bd.load[b, 2] + mg - bd.spring[b, 2] * (th - bd.q0[b, 2])
                 - bd.damper[b, 2] * bd.qd[b, 2])
            bd.acc[b, 0] = 0.0
            bd.acc[b, 1] = 0.0
            bd.acc[b, 2] = f / bd.inertia[b]


# ------------------------------------------------------------------------------ geometry
def shape_polygon(body: Body) -> np.ndarray:
    """The body's outline [k, 2] (counter-clockwise) in scene coordinates at t_start."""
    if body.shape in ("box", "flap"):
        pts = [(body.x0, body.z0), (body.x1, body.z0), (body.x1, body.z1), (body.x0, body.z1)]
    elif body.shape == "wedge":
        ax_, az_ = body.apex
        half = 0.5 * body.breadth
        top = az_ + half * math.tan(math.radians(body.deadrise_deg))
        pts = [(ax_, az_), (ax_ + half, top), (ax_ - half, top)]
    else:
        pts = list(body.points)
    poly = np.asarray(pts, dtype=float)
    if _signed_area(poly) < 0:
        poly = poly[::-1].copy()
    return poly


def _signed_area(poly: np.ndarray) -> float:
    x, z = poly[:, 0], poly[:, 1]
    return 0.5 * float(np.sum(x * np.roll(z, -1) - np.roll(x, -1) * z))


def polygon_properties(poly: np.ndarray) -> tuple[float, np.ndarray, float]:
    """Area, centroid and polar second moment of area about the centroid (per unit density)."""
    x, z = poly[:, 0], poly[:, 1]
    xn, zn = np.roll(x, -1), np.roll(z, -1)
    cr = x * zn - xn * z
    area = 0.5 * cr.sum()
    cx = ((x + xn) * cr).sum() / (6.0 * area)
    cz = ((z + zn) * cr).sum() / (6.0 * area)
    ixx = ((z * z + z * zn + zn * zn) * cr).sum() / 12.0   # about the origin
    izz = ((x * x + x * xn + xn * xn) * cr).sum() / 12.0
    j0 = ixx + izz
    jc = j0 - area * (cx * cx + cz * cz)
    return float(area), np.array([cx, cz]), float(jc)


def _inside(poly: np.ndarray, x: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Even-odd point-in-polygon test."""
    inside = np.zeros(x.shape, dtype=bool)
    n = len(poly)
    for a in range(n):
        (xa, za), (xb, zb) = poly[a], poly[(a + 1) % n]
        crosses = (za > z) != (zb > z)
        with np.errstate(divide="ignore", invalid="ignore"):
            xc = xa + (z - za) * (xb - xa) / (zb - za)
        inside ^= crosses & (x < xc)
    return inside


def _distance(poly: np.ndarray, x: np.ndarray, z: np.ndarray) -> np.ndarray:
    d = np.full(x.shape, np.inf)
    n = len(poly)
    for a in range(n):
        (xa, za), (xb, zb) = poly[a], poly[(a + 1) % n]
        ex, ez = xb - xa, zb - za
        s = np.clip(((x - xa) * ex + (z - za) * ez) / (ex * ex + ez * ez), 0.0, 1.0)
        d = np.minimum(d, np.hypot(x - (xa + s * ex), z - (za + s * ez)))
    return d


def _lattice_in(scene: Scene, poly: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points of the tank lattice (x0 + (i + 1/2) dp, z0 + (j + 1/2) dp) inside the polygon."""
    dp, t = scene.dp, scene.tank
    i0 = math.floor((poly[:, 0].min() - t.x0) / dp) - 1
    i1 = math.ceil((poly[:, 0].max() - t.x0) / dp) + 1
    j0 = math.floor((poly[:, 1].min() - t.z0) / dp) - 1
    j1 = math.ceil((poly[:, 1].max() - t.z0) / dp) + 1
    gx, gz = np.meshgrid(t.x0 + (np.arange(i0, i1) + 0.5) * dp,
                         t.z0 + (np.arange(j0, j1) + 0.5) * dp, indexing="ij")
    gx, gz = gx.ravel(), gz.ravel()
    keep = _inside(poly, gx, gz)
    return gx[keep], gz[keep]


# ------------------------------------------------------------------------------ the run's bodies
class BodySet:
    """The bodies of a scene: their particles, settings and state (``state``, the kernels' view)."""

    def __init__(self, scene: Scene, thickness: float) -> None:
        self.scene = scene
        self.names = [b.name for b in scene.bodies]
        self.polygons = [shape_polygon(b) for b in scene.bodies]
        nb = len(scene.bodies)
        px, pz, owner = [], [], []
        self.thin: list[str] = []
        for b, poly in enumerate(self.polygons):
            x, z = _lattice_in(scene, poly)
            dist = _distance(poly, x, z)
            # a body thinner than the kernel support 2h lets fluid on its two sides interact
            # through it and its particles' Adami pressure mix both sides' pressures (measured:
            # a 0.04 m flap at dp 0.02, h/dp 2 oscillated 11 % slower than at dp 0.01)
            if x.size and 2.0 * (float(dist.max()) + 0.5 * scene.dp) < 2.0 * scene.h:
                self.thin.append(self.names[b])
                warnings.warn(f"bodies.{self.names[b]}: thinner than the kernel support 2h = "
                              f"{2.0 * scene.h:.4g} m: the fluid on its two sides interacts "
                              f"through it; thicken it or refine dp", stacklevel=2)
            shell = dist < thickness
            x, z = x[shell], z[shell]
            if x.size == 0:
                raise ValueError(f"bodies.{b}: no particle fits inside the shape at dp = {scene.dp}")
            px.append(x)
            pz.append(z)
            owner.append(np.full(x.size, b, dtype=np.int64))
        self.x = np.concatenate(px) if nb else np.zeros(0)
        self.z = np.concatenate(pz) if nb else np.zeros(0)
        self.owner = np.concatenate(owner) if nb else np.zeros(0, dtype=np.int64)
        self.state = no_bodies()
        self.log: BodyLog | None = None

    @property
    def active(self) -> bool:
        return bool(self.scene.bodies)

    def fluid_outside(self, x: np.ndarray, z: np.ndarray, dp: float) -> np.ndarray:
        """Mask of fluid lattice points outside every body (and not closer than dp/2 to it)."""
        keep = np.ones(x.shape, dtype=bool)
        half = 0.5 * dp * (1.0 - 1e-6)
        for poly in self.polygons:
            keep &= ~(_inside(poly, x, z) | (_distance(poly, x, z) < half))
        return keep

    def attach(self, ps: ParticleSet, rho0: float, dp: float) -> None:
        """Append the body particles (kind WALL, mass rho0 dp^2) and build ``state``."""
        if not self.active:
            return
        ids = ps.add(self.x, self.z, WALL, np.full(self.x.size, rho0),
                     np.full(self.x.size, rho0 * dp * dp))
        nb = len(self.scene.bodies)
        motion = np.zeros(nb, dtype=np.int64)
        dof = np.zeros((nb, 3))
        mass = np.zeros(nb)
        inertia = np.zeros(nb)
        com0 = np.zeros((nb, 2))
        spring = np.zeros((nb, 3))
        damper = np.zeros((nb, 3))
        q = np.zeros((nb, 3))
        qd = np.zeros((nb, 3))
        rows = max([len(b.series) for b in self.scene.bodies] + [2])
        series_t = np.zeros((nb, rows))
        series_q = np.zeros((nb, rows, 3))
        series_n = np.zeros(nb, dtype=np.int64)
        rx = np.zeros(self.x.size)
        rz = np.zeros(self.x.size)
        self.properties = []
        for b, (body, poly) in enumerate(zip(self.scene.bodies, self.polygons)):
            area, centroid, j_c = polygon_properties(poly)
            m = body.mass if body.mass is not None else (body.density or self.scene.constants.rho0) * area
            com = np.array(body.com, dtype=float) if body.com is not None else centroid
            i_c = body.inertia if body.inertia is not None else m * j_c / area
            motion[b] = MOTIONS[body.motion]
            if body.motion == "hinged":
                ref = np.array(body.pivot if body.pivot is not None
                               else (0.5 * (body.x0 + body.x1), body.z0), dtype=float)
                i_ref = i_c + m * float(np.sum((com - ref) ** 2))
                dof[b] = (0.0, 0.0, 1.0)
                qd[b, 2] = body.velocity[2]
            else:
                ref = com
                i_ref = i_c
                dof[b] = [1.0 if name in body.dofs else 0.0 for name in DOF_INDEX]
                if body.motion == "free":
                    qd[b] = np.asarray(body.velocity) * dof[b]
            mass[b], inertia[b], com0[b] = m, i_ref, com - ref
            k = np.broadcast_to(np.asarray(body.spring, dtype=float), (3,))
            c = np.broadcast_to(np.asarray(body.damper, dtype=float), (3,))
            if body.motion == "hinged":
                spring[b, 2], damper[b, 2] = k[-1], c[-1]
            else:
                spring[b], damper[b] = k, c
            q[b, :2] = ref
            if body.series:
                s = np.asarray(body.series, dtype=float)
                series_n[b] = len(s)
                series_t[b, : len(s)] = s[:, 0]
                series_q[b, : len(s)] = s[:, 1:]
            sel = self.owner == b
            rx[sel] = self.x[sel] - ref[0]
            rz[sel] = self.z[sel] - ref[1]
            self.properties.append({"name": body.name, "mass": m, "inertia_ref": i_ref,
                                    "inertia_com": i_c, "area": area, "com": com.tolist(),
                                    "reference": ref.tolist(), "particles": int(sel.sum())})
        npart = self.x.size
        z = lambda *s: np.zeros(s)  # noqa: E731
        self.state = Bodies(True, nb, int(ids[0]), int(npart), motion, dof, mass, inertia, com0,
                            spring, damper, q.copy(), q, qd, z(nb, 3), z(nb, 3), z(nb, 3),
                            z(nb, 3), series_t, series_q, series_n, self.owner.copy(), rx, rz,
                            z(npart), z(npart), z(npart))
        # prescribed motion is at its t_start displacement from the first step on
        for b in range(nb):
            if motion[b] == PRESCRIBED:
                _set_prescribed(self.state, b, self.scene.t_start, self.scene.t_start)

    # ---------------------------------------------------------------- reading and checkpoints
    def rows(self) -> dict[str, float]:
        """Motions and loads of every body: name_x, _z, _theta (reference point), _u, _w, _omega,
        _fx, _fz, _my (fluid force [N/m] and moment about the reference point [N m/m])."""
        bd = self.state
        out: dict[str, float] = {}
        for b, name in enumerate(self.names):
            for c, key in enumerate(("x", "z", "theta")):
                out[f"{name}_{key}"] = float(bd.q[b, c])
            for c, key in enumerate(("u", "w", "omega")):
                out[f"{name}_{key}"] = float(bd.qd[b, c])
            for c, key in enumerate(("fx", "fz", "my")):
                out[f"{name}_{key}"] = float(bd.load[b, c])
        return out

    def columns(self) -> list[str]:
        return [f"{n}_{k}" for n in self.names
                for k in ("x", "z", "theta", "u", "w", "omega", "fx", "fz", "my")]

    def follow(self, name: str, x0: np.ndarray, z0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Where points given at t_start (scene coordinates x0, z0) are now, carried rigidly by
        body ``name`` (probes with ``follow``)."""
        b = self.names.index(name)
        bd = self.state
        dth = float(bd.q[b, 2] - bd.q0[b, 2])
        c, s = math.cos(dth), math.sin(dth)
        rx = np.asarray(x0, dtype=float) - bd.q0[b, 0]
        rz = np.asarray(z0, dtype=float) - bd.q0[b, 1]
        return bd.q[b, 0] + c * rx - s * rz, bd.q[b, 1] + s * rx + c * rz

    def particle_body(self, ids: np.ndarray) -> np.ndarray:
        """Body index of each particle id (-1: not a body particle), for snapshots."""
        out = np.full(ids.shape, -1, dtype=np.int32)
        if self.active:
            k = ids - self.state.id0
            sel = (k >= 0) & (k < self.state.npart)
            out[sel] = self.state.owner[k[sel]]
        return out

    def get_state(self) -> tuple[np.ndarray, ...] | None:
        bd = self.state
        return None if not self.active else tuple(a.copy() for a in (bd.q, bd.qd, bd.acc, bd.load))

    def set_state(self, s: tuple[np.ndarray, ...] | None) -> None:
        if s is None or not self.active:
            return
        bd = self.state
        for dst, src in zip((bd.q, bd.qd, bd.acc, bd.load), s):
            dst[:] = src


class BodyLog:
    """bodies.csv beside probes.csv: t, step, then BodySet.columns(); flushed per row."""

    def __init__(self, run_dir: str | Path, columns: list[str]) -> None:
        self.columns = ["t", "step"] + columns
        self._file = open(Path(run_dir) / "bodies.csv", "w", newline="")
        self._csv = csv.writer(self._file)
        self._csv.writerow(self.columns)
        self._file.flush()

    def row(self, t: float, step: int, values: dict[str, float]) -> None:
        self._csv.writerow([repr(float(t)), step] + [repr(values[c]) for c in self.columns[2:]])
        self._file.flush()

    def close(self) -> None:
        if not self._file.closed:
            self._file.close()
