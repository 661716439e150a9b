"""Scene description: a validated tank configuration, from TOML or Python objects.

Coordinates are absolute (SPH datum): x to the right, z up, the tank floor usually at z = 0.
Rectangles are given by their corners (x0, x1, z0, z1) in metres. A 2D scene (``dim = 2``, the
default) is the vertical plane x-z; a 3D scene (``dim = 3``) adds y across the tank, and its
tank, water blocks, structures and force probes are boxes (x0, x1, y0, y1, z0, z1; a block,
structure or probe without y0, y1 spans the tank's width). Unknown keys are errors
(``extra="forbid"``), and every error names its field path, e.g.
``water_blocks.0.z1: must be greater than z0``.
"""

from __future__ import annotations

import math
import tomllib
from collections import Counter
from pathlib import Path
from typing import Annotated, Any, Literal, Union

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator


class SceneError(ValueError):
    """A scene configuration is invalid; the message names each offending field."""


# Options measured and retired (docs/decisions/KEY.md: what, the figure, why not): a scene that
# still sets one gets a one-line error naming that page. (table model, key) -> the values still
# accepted (the retired option's surviving default, or the values a kept field still has).
RETIRED: dict[tuple[str, str], tuple[Any, ...]] = {
    ("Constants", "kernel_correction"): ("off",),
    ("Scheme", "limiter"): ("vanleer",),
    ("Scheme", "low_dissipation"): (False,),
    ("Scheme", "low_dissipation_eta"): (),
    ("Constants", "shift_open_end"): ("full", "none"),
    ("OpenBoundary", "absorption"): ("filter",),
    ("OpenBoundary", "absorption_transfer"): ("piston",),
    ("OpenBoundary", "absorption_profile"): ("mode",),
    ("OpenBoundary", "surface"): ("face",),
    # ISPH (docs/studies/schemes.md "## ISPH" has the measurements)
    ("Scheme", "isph_gradient"): ("corrected",),
    ("Scheme", "ppe_solver"): ("bicgstab", "amg"),   # still a field: the accepted values pass
    ("Scheme", "free_surface"): ("divergence",),
    ("Scheme", "isph_dry_walls"): (False,),
}


def retired_page(key: str) -> str:
    """The decision page of a retired option."""
    return f"docs/decisions/{key}.md"


class _Model(BaseModel):
    # allow_inf_nan: t_end = inf or dp = nan in a file is named at once as not finite
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    @model_validator(mode="before")
    @classmethod
    def _retired(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            return data
        kept = {}
        for key, value in data.items():
            accepted = RETIRED.get((cls.__name__, key))
            if accepted is not None and value not in accepted:
                raise ValueError(f"{key}: {value!r} was measured and retired "
                                 f"(see {retired_page(key)})")
            if accepted is None or key in cls.model_fields:
                kept[key] = value  # a field keeping some values validates them itself
        return kept


class Rect(_Model):
    """Axis-aligned rectangle [x0, x1] x [z0, z1] [m]; in a 3D scene the box [x0, x1] x
    [y0, y1] x [z0, z1] (y0, y1 None: across the whole tank)."""

    x0: float
    x1: float
    z0: float
    z1: float
    y0: float | None = Field(None, description="3D scenes: the box's y range [m] (None: the tank's)")
    y1: float | None = None

    @model_validator(mode="after")
    def _ordered(self) -> "Rect":
        if not self.x1 > self.x0:
            raise ValueError("x1: must be greater than x0")
        if not self.z1 > self.z0:
            raise ValueError("z1: must be greater than z0")
        if (self.y0 is None) != (self.y1 is None):
            raise ValueError("y1: give both y0 and y1, or neither")
        if self.y0 is not None and not self.y1 > self.y0:
            raise ValueError("y1: must be greater than y0")
        return self


class Tank(Rect):
    """The fluid domain: walls of dummy particles left (x0), right (x1) and below (z0).

    The walls reach up to z1, which is also the top of the computational domain: a particle above
    z1 has left the domain and is excluded (Constants.exclude_limit), as one whose density left
    the band."""


class WaterBlock(Rect):
    """A rectangle filled with fluid particles at rest, hydrostatic below its top z1."""


class Bed(_Model):
    """A sloping bed: a polyline (x increasing) with dummy particles in layers below it (in 3D
    extruded across the width)."""

    points: list[tuple[float, float]] = Field(min_length=2)
    layout: Literal["lattice", "along_slope"] = Field(
        "lattice", description="the dummy particles: `lattice` the tank's lattice points below "
        "the line (a staircase along a slope); `along_slope` rows parallel to each segment, dp "
        "apart along and across it (a smooth bed; docs/studies/runup.md)")

    @model_validator(mode="after")
    def _increasing(self) -> "Bed":
        xs = [p[0] for p in self.points]
        if any(b <= a for a, b in zip(xs, xs[1:])):
            raise ValueError("points: x must increase strictly along the polyline")
        return self


class Structure(Rect):
    """A fixed structure: a shell of dummy particles one kernel support thick. ``box`` (default):
    the rectangle (3D: the box) of its corners; ``cylinder`` (3D scenes): a vertical circular
    cylinder inscribed in its corners, its axis at the centre of [x0, x1] x [y0, y1] (which
    must be a square: the diameter), from z0 to z1."""

    shape: Literal["box", "cylinder"] = "box"

    @model_validator(mode="after")
    def _round(self) -> "Structure":
        if self.shape == "cylinder" and self.y0 is not None:
            d, e = self.x1 - self.x0, self.y1 - self.y0
            if abs(d - e) > 1e-9 * max(d, e):
                raise ValueError(f"y1: a cylinder's x and y extents are its diameter; got "
                                 f"{d:g} m and {e:g} m")
        return self


class Body(_Model):
    """A rigid body of boundary particles (physics in ``sph_core.bodies``).

    Shape (scene coordinates at t_start): ``box`` and ``flap`` by their corners x0, x1, z0, z1
    (a flap is a box hinged by default at the centre of its bottom edge); ``wedge`` by its
    ``apex`` (x, z), top ``breadth`` and ``deadrise_deg`` (apex down); ``polygon`` by ``points``.
    Mass per metre of span: ``mass`` [kg/m] or ``density`` [kg/m^3] (times the shape's area);
    ``inertia`` [kg m^2/m] about the centre of mass (default: the uniform shape's).

    Motion: ``fixed``; ``prescribed`` (``series`` rows (t, dx, dz, dtheta): displacement from
    the initial position, linear in time between rows, held after the last); ``free`` in the
    ``dofs`` named (surge x, heave z, pitch theta; theta counter-clockwise with x right, z up);
    ``hinged`` about ``pivot``. ``spring`` / ``damper``: per DOF (surge, heave, pitch) for a
    free body [N/m, N s/m, N m/rad, N m s/rad], one value (pitch) for a hinged one; springs pull
    towards the initial position. ``velocity`` (u, w, omega): initial velocity of a free or
    hinged body (only omega counts for a hinged one)."""

    name: str = Field(min_length=1)
    shape: Literal["box", "wedge", "flap", "polygon"]
    x0: float | None = None
    x1: float | None = None
    z0: float | None = None
    z1: float | None = None
    apex: tuple[float, float] | None = None
    breadth: float | None = Field(None, gt=0)
    deadrise_deg: float | None = Field(None, gt=0, lt=90)
    points: list[tuple[float, float]] | None = None
    mass: float | None = Field(None, gt=0)
    density: float | None = Field(None, gt=0)
    inertia: float | None = Field(None, gt=0)
    com: tuple[float, float] | None = None
    motion: Literal["fixed", "prescribed", "free", "hinged"] = "free"
    dofs: list[Literal["surge", "heave", "pitch"]] = ["surge", "heave", "pitch"]
    pivot: tuple[float, float] | None = None
    spring: float | tuple[float, float, float] = 0.0
    damper: float | tuple[float, float, float] = 0.0
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    series: list[tuple[float, float, float, float]] = []

    @model_validator(mode="after")
    def _complete(self) -> "Body":
        if self.shape in ("box", "flap"):
            if None in (self.x0, self.x1, self.z0, self.z1):
                raise ValueError(f"x0: a {self.shape} needs x0, x1, z0, z1")
            if not (self.x1 > self.x0 and self.z1 > self.z0):
                raise ValueError("x1: must exceed x0, and z1 z0")
        elif self.shape == "wedge":
            if self.apex is None or self.breadth is None or self.deadrise_deg is None:
                raise ValueError("apex: a wedge needs apex, breadth and deadrise_deg")
        elif self.points is None or len(self.points) < 3:
            raise ValueError("points: a polygon needs at least 3 points")
        if (self.mass is None) == (self.density is None) and self.motion in ("free", "hinged"):
            raise ValueError("mass: give exactly one of mass and density")
        if self.motion == "hinged" and self.pivot is None and self.shape != "flap":
            raise ValueError("pivot: a hinged body other than a flap needs a pivot")
        if self.motion == "prescribed" and len(self.series) < 2:
            raise ValueError("series: a prescribed motion needs at least 2 rows (t, dx, dz, dtheta)")
        ts = [r[0] for r in self.series]
        if any(b <= a for a, b in zip(ts, ts[1:])):
            raise ValueError("series: t must increase strictly")
        for name in ("spring", "damper"):
            v = getattr(self, name)
            if self.motion == "hinged" and not isinstance(v, (int, float)):
                raise ValueError(f"{name}: one value (pitch) for a hinged body")
            vals = (v,) if isinstance(v, (int, float)) else v
            if any(x < 0 for x in vals):
                raise ValueError(f"{name}: must be >= 0")
        return self


class Constants(_Model):
    """Physical and numerical constants (SI)."""

    rho0: float = Field(1000.0, gt=0, description="reference density [kg/m^3]")
    g: float = Field(9.81, gt=0, description="gravity [m/s^2], acting in -z")
    c0: float | None = Field(None, gt=0, description="speed of sound [m/s]; default c0_factor*sqrt(2 g H)")
    c0_factor: float = Field(10.0, gt=0, description="c0 = c0_factor * sqrt(2 g H), H = water height")
    # h/dp 2 (~50 neighbours): the wave keeps far more of itself than at sqrt(2) (flume 14 ->
    # 6.2 %/m at H/dp 2, 25x less particle noise, phase speed -3.6 -> -0.3 %; one step costs
    # ~2x, 0.7x the steps: ~1.25x per simulated second; docs/studies/wave_decay_study.md).
    # Up to 4: at a fixed h/dp the particles' discretisation error is a floor under a closed
    # tank's wave loss, which more neighbours lower (the description's figures); above 4 nothing
    # was measured (the study's "At one smoothing length, more neighbours")
    h_over_dp: float = Field(2.0, ge=1.0, le=4.0, description=(
        "smoothing length h / dp; 2 (default), sqrt(2) is cheaper (~0.8x per simulated second) "
        "and noisier; 3 halves a closed tank's wave loss at H/dp 8 (~1.3x the cost) but not an "
        "open flume's at H/dp 4"))
    cfl: float = Field(0.25, gt=0, le=0.5, description="Courant number of the adaptive time step")
    alpha: float = Field(0.01, ge=0, description="Monaghan artificial viscosity coefficient")
    nu: float = Field(1.0e-6, ge=0, description="laminar kinematic viscosity [m^2/s]")
    delta: float = Field(0.1, ge=0, description="delta-SPH density diffusion coefficient")
    # the wave's loss to artificial viscosity against the bed does not converge with dp (the
    # boundary layer is far thinner than dp): 6.1 -> 1.8 %/m (closed tank, dp 0.02) without it.
    # A violent surge over a bed wants it back (dam break: wavesph/cases/dambreak.py sets 1).
    alpha_wall_factor: float = Field(0.0, ge=0, description=(
        "artificial viscosity against walls = this x alpha (DualSPHysics' ViscoBoundFactor); "
        "0 (default) for waves, 1 for violent flows on a bed (the dam-break case); applies "
        "with no_slip walls only"))
    shifting: Literal["none", "fickian", "dplus"] = Field("none", description=(
        "particle shifting after each step: fickian = Lind et al. 2012, tangential only below "
        "shift_fs_div; dplus = Sun et al. 2017 (delta-plus SPH), tangential only at the free "
        "surface found by Marrone et al. 2010 and within 2h of it, none for isolated particles "
        "(sph_core.shifting)"))
    shift_a: float = Field(2.0, gt=0, description="fickian: shifting coefficient A: D = A h |v| dt")
    shift_dplus_scale: float = Field(1.0, gt=0, description=(
        "dplus: multiplier on Sun et al. 2017's CFL Ma (2h)^2 (D = 4 scale h max|v| dt)"))
    shift_carry: bool = Field(True, description=(
        "carry the shifted particle's density and velocity to its new position (first-order "
        "Taylor); without it the shift diffuses the velocity field"))
    shift_open_end: Literal["full", "none"] = Field("full", description=(
        "shifting of a fluid particle with an open end's active buffer particle within 2h: "
        "full or none (sph_core.shifting)"))
    shift_fs_div: float = Field(1.8, gt=0, lt=2, description=(
        "position divergence below which a particle counts as near the free surface (2D: 2 "
        "inside the fluid) and shifts only tangentially"))
    wall_slip: Literal["no_slip", "free_slip"] = "no_slip"
    density_band: tuple[float, float] = Field((0.7, 1.3), description="sane rho/rho0 band")
    # A drop thrown off the surface (splash, run-up on a staircase bed) keeps few neighbours: its
    # density leaves the band by continuity and, landing, it can be crushed against the wall
    # particles. Such particles are removed and logged, as DualSPHysics excludes particles
    # leaving [700, 1300] kg/m^3 or the domain; more than this share means a real blow-up:
    # the run stops.
    exclude_limit: float = Field(0.01, ge=0, le=1, description=(
        "share of the initial fluid particles that may be excluded (density out of the band, or "
        "left the tank over its top or through a wall) before the run stops as unstable"))
    integrator: Literal["kdk", "symplectic_pc"] = Field(
        "kdk", description="kdk: leapfrog, 1 force pass/step; symplectic_pc: DualSPHysics-style, 2 passes")
    precision: Literal["float64", "float32"] = Field("float64", description=(
        "storage of the particle fields: float64 (default), or float32 (half the memory; the "
        "arithmetic stays float64 where a float64 operand enters; docs/studies/float32_storage.md)"))

    @model_validator(mode="after")
    def _band(self) -> "Constants":
        lo, hi = self.density_band
        if not (0 < lo < 1 < hi):
            raise ValueError("density_band: must satisfy 0 < low < 1 < high")
        return self


ISPH_H_OVER_DP = 1.4142   # h/dp of an ISPH scene that sets none (Scene._scheme_h)


class Scheme(_Model):
    """Which SPH scheme solves the fluid.

    ``riemann`` (sph_core.riemann, seed 003): weakly compressible as wcsph (same EOS, walls, time
    step, integrators), but each pair's continuity and pressure terms come from a linearised
    Riemann problem at the pair's mid-point instead of delta-SPH and Monaghan viscosity
    (constants.alpha and constants.delta are not used; constants.alpha_wall_factor scales the
    velocity dissipation against walls).

    The ``ppe_*``, ``free_surface_threshold``, ``isph_*`` options apply to ``kind = "isph"`` only
    (sph_core.isph: projection method, a pressure Poisson equation per step)."""

    kind: Literal["wcsph", "riemann", "isph"] = Field("wcsph", description=(
        "wcsph: weakly compressible, delta-SPH density diffusion, Monaghan viscosity; "
        "riemann: weakly compressible, pairwise Riemann flux; "
        "isph: incompressible SPH (projection method, seed 004)"))
    reconstruction: Literal["muscl", "none"] = Field("muscl", description=(
        "riemann: left/right states extrapolated to the pair's mid-point with limited "
        "gradients (muscl), or the particles' own values (none, first order)"))
    # van Leer's limiter and beta = 1 were measured best (docs/studies/schemes.md); the minmod limiter
    # and the low-dissipation beta are retired (docs/decisions/limiter.md, low_dissipation.md)
    # retired (RETIRED above): the Jacobi, ILU and direct solvers, seed 004's density criterion of
    # the free surface and symmetric pressure gradient, and the dry walls in the corrector
    ppe_solver: Literal["bicgstab", "amg"] = Field("bicgstab", description=(
        "ISPH pressure Poisson solver: bicgstab = BiCGSTAB preconditioned by the diagonal, "
        "jitted (no set-up); amg = BiCGSTAB preconditioned by smoothed-aggregation AMG (pyamg)"))
    ppe_tolerance: float = Field(1e-5, gt=0, lt=1, description=(
        "ISPH: relative residual |b - A p| / |b| at which the pressure solve stops"))
    ppe_max_iter: int = Field(20000, ge=1, description="ISPH: iteration cap of the pressure solve")
    free_surface_threshold: float = Field(1.5, gt=0, description=(
        "ISPH: a fluid particle is on the free surface (Dirichlet p = 0) where its position "
        "divergence sum_j V_j F_ij r_ij^2 is at most this (2 inside the fluid in 2D; Lind et al. "
        "2012)"))
    isph_cfl: float = Field(0.2, gt=0, le=0.5, description=(
        "ISPH Courant number on the flow speed: dt <= isph_cfl h / max|v| (no sound speed)"))
    isph_vref_factor: float = Field(1.0, ge=0, description=(
        "ISPH: the time step's speed is at least this x sqrt(2 g H), H the water height "
        "(0: the flow's max|v| alone)"))
    isph_density_relaxation: float = Field(0.01, ge=0, le=1, description=(
        "ISPH: weight of the density-invariance term (rho_k - rho_ref)/(rho_ref dt^2) added to "
        "the divergence source (Asai et al. 2012); 0: the seed's divergence-free source alone "
        "(measured: the still-water surface then rises ~4 mm/s at d/dp 25; 0.01 holds it)"))
    isph_wall_stop: float = Field(1.0, ge=1, description=(
        "ISPH: fluid approaching a wall is stopped by a ghost-pressure rise rho |u_n| d / tau "
        "over this many steps, tau = isph_wall_stop dt (d the fluid's distance from the wall "
        "particle along the wall normal); 1: within one step"))
    isph_shifting: bool = Field(True, description=(
        "ISPH: Fickian particle shifting (Lind et al. 2012) with Constants.shift_a after each step"))
    isph_relaxation_zone: float = Field(0.0, ge=0, description=(
        "ISPH: length [m] of a relaxation zone inside each open end's face, where the fluid's "
        "velocity is pulled towards the wave's at the rate q^2 / isph_relaxation_time, q = 1 - "
        "s / length, s the distance from the face: the wave model at the particle when a model "
        "drives the run in-process (the benches' theory flumes) or a coupling client sends the "
        "wave inside the zone (protocol 1.2 ZONE_NODES: wave_client and a scene's [source] do), "
        "else the face's profile; 0: none (the wave flume's inlet then breaks down within a few "
        "periods: docs/studies/schemes.md)"))
    isph_relaxation_time: float = Field(0.2, gt=0, description=(
        "ISPH: time scale [s] of the relaxation zone's pull at the face"))


class PointProbe(_Model):
    """Kernel-interpolated velocity (u, w; in 3D also v, column <name>_v) and pressure p at a
    point."""

    kind: Literal["point"]
    name: str = Field(min_length=1)
    x: float
    z: float
    y: float = Field(0.0, description="3D scenes: y of the point [m]")
    follow: str | None = Field(None, description=(
        "name of a body: the point(s) move rigidly with it (given at t_start, in scene "
        "coordinates; e.g. a pressure line on a moving hull)"))


class ElevationProbe(_Model):
    """Free-surface z at a given x by the vertical-line method (seed 004, second method)."""

    kind: Literal["elevation"]
    name: str = Field(min_length=1)
    x: float
    y: float = Field(0.0, description="3D scenes: y of the vertical line [m]")
    threshold: float = Field(0.5, gt=0, lt=1, description="surface where sum(m W) < threshold*rho0")


class FrontProbe(_Model):
    """Largest x of fluid particles that have at least ``min_neighbours`` fluid neighbours."""

    kind: Literal["front"]
    name: str = Field(min_length=1)
    min_neighbours: int = Field(3, ge=0)


class RunupProbe(_Model):
    """Shoreline and run-up on a bed: the shoreline is the most landward wet point, the largest
    x of the fluid particles that have at least ``min_neighbours`` fluid neighbours (isolated
    drops do not count) and, with ``near_bed``, lie at most that height above the bed (the
    highest bed polyline at x, else the tank floor); its elevation is that particle's centre z,
    within about dp/2 of the water line (still water: dp/2 below it; a one-particle film: dp/2
    above the bed). Columns: <name>_x, <name>_z [m], <name>_R [m], the highest
    z - still_water_level of the records so far (taken every output.probe_every, so a peak
    between two records is missed; restarted with each Simulation, so a resumed run's R counts
    from the resume). Put the beach at the tank's +x end: the probe takes the wet point of
    largest x anywhere in the tank."""

    kind: Literal["runup"]
    name: str = Field(min_length=1)
    min_neighbours: int = Field(3, ge=0)
    near_bed: float | None = Field(None, gt=0, description=(
        "only particles at most this height [m] above the bed count (e.g. 2 dp: the wet film, "
        "not spray over it); default: all"))


class ForceProbe(Rect):
    """Force and moment per metre of width (3D: force [N] and moment [N m], with the extra
    columns <name>_fy, <name>_mx, <name>_mz, in a box [x0, x1] x [y0, y1] x [z0, z1]) that the
    fluid exerts on the wall, bed or structure particles whose centres lie in the rectangle
    [x0, x1] x [z0, z1]: the reaction of the
    pressure pair forces those particles exert on the fluid (wcsph.fluid_pass),
    F = -sum_s sum_f m_f m_s (p_f + p_s)/(rho_f rho_s) F_fs (r_f - r_s), and the moment
    M = sum_s (z_s - z_m) F_x,s - (x_s - x_m) F_z,s about ``moment_about`` (x_m, z_m) [N m/m],
    positive when F_x above the point tips the wall towards +x. Columns: <name>_fx, <name>_fz
    [N/m], <name>_my [N m/m]. Viscous and artificial-viscosity forces are not included (wall
    shear; small against pressure on a structure)."""

    kind: Literal["force"]
    name: str = Field(min_length=1)
    moment_about: tuple[float, float] | tuple[float, float, float] | None = Field(
        None, description="(x, z) of the moment's axis [m] (3D: (x, y, z), the point the "
                          "moments are taken about); default the box's bottom centre")

    def axis(self) -> tuple[float, float, float]:
        """(x, y, z) the moments are taken about [m]."""
        m = self.moment_about
        if m is None:
            yc = 0.0 if self.y0 is None else 0.5 * (self.y0 + self.y1)
            return 0.5 * (self.x0 + self.x1), yc, self.z0
        if len(m) == 2:
            return m[0], 0.0, m[1]
        return m[0], m[1], m[2]


class PressureLineProbe(_Model):
    """Pressure at points along a wall (DualSPHysics' MeasureTool): the Shepard kernel
    interpolation of the fluid's pressure at each point, as a point probe's p. Put the points on
    the wall face or up to dp inside the fluid. Columns <name>_p<k> [Pa] for points[k]; a point
    with no fluid near it is dry (empty)."""

    kind: Literal["pressure_line"]
    name: str = Field(min_length=1)
    points: list[tuple[float, float]] = Field(min_length=1, description="(x, z) of each point [m]")
    y: float = Field(0.0, description="3D scenes: y of the line's points [m]")
    follow: str | None = Field(None, description=(
        "name of a body: the point(s) move rigidly with it (given at t_start, in scene "
        "coordinates; e.g. a pressure line on a moving hull)"))


class OvertoppingProbe(_Model):
    """Volume of fluid that has crossed the vertical section at ``x`` towards +x (net, per metre
    of width), counted by particle (volume m/rho) between records, so it is exact in the
    particles' own terms: <name>_volume [m^3/m] since the start, <name>_q [m^2/s] the mean flux
    over the interval since the previous record."""

    kind: Literal["overtopping"]
    name: str = Field(min_length=1)
    x: float


Probe = Annotated[Union[PointProbe, ElevationProbe, FrontProbe, RunupProbe, ForceProbe,
                        PressureLineProbe, OvertoppingProbe], Field(discriminator="kind")]


# buffer pressure of an outlet (elevation "extrapolated") that does not name one. Extrapolated
# (seed 002's outlet) halves the reflection of case V (2 periods, 1-wavelength flume; decay-aware
# K_R / three-gauge K_R / RMSE/H): H/dp = 6: 1.7 % / 3.9 % / 4.4 % against hydrostatic
# 4.0 % / 7.0 % / 4.2 %; H/dp = 3: 1.8 % / 4.0 % against 4.0 % / 6.5 %; same cost.
OUTLET_PRESSURE = "extrapolated"
# buffer pressure of an inlet (elevation "imposed") that does not name one: seed 002's table.
# Within h of its surface a hydrostatic buffer takes the fluid's own pressure through the ghost
# nodes (open_boundary.SURFACE_BAND_H). Extrapolated everywhere, the inlet let a fluid particle
# through the floor at its bottom corner (case V, dp 0.02) and generated 5 % less amplitude
# within 0.3 m of the face (docs/studies/wave_decay_study.md).
INLET_PRESSURE = "hydrostatic"
# ... of an ISPH inlet: extrapolated. ISPH puts p = 0 on its surface particles' centres, dp/2 below
# the surface, so its pressure is ~rho0 g dp/2 below the continuum hydrostatic one a hydrostatic
# buffer holds; in the still open flume (d 0.3 m, dp 0.02, tests/test_sph_core/test_open_boundary.py)
# that pushed the inlet's surface corner at 0.10 m/s within 0.1 s and the run blew up at 0.87 s;
# extrapolated, the flume stays still (docs/studies/schemes.md "ISPH with open ends and bodies").
# Since ISPH solves the pressure of every buffer particle with fluid neighbours with the fluid
# (isph.passes.buffer_rows), this value only reaches the buffer particles beyond the fluid's
# support and the warm start of the solve.
ISPH_INLET_PRESSURE = "extrapolated"


class OpenBoundary(_Model):
    """An open end of the tank (seed 002): the tank wall on ``side`` is replaced by a
    buffer of particles outside the tank face (x0 or x1), at least one kernel support wide and
    wide enough that the wave's orbits do not carry its particles through it (``buffer_width``).

    Buffer particles take the velocity of a boundary-data source (see ``sph_core.boundary_data``).
    ``elevation``: ``imposed`` takes the source's elevation (inlet of seed 002); ``extrapolated``
    takes the source's elevation at the face plus the mismatch measured by the boundary gauge
    inside the fluid (outlet). ``absorb`` applies the seed 002 correction
    u = u_theory + n_x G (eta_measured - eta_theory), n_x the outward normal (-1 left, +1 right),
    with the gauge ``gauge_offset`` [m] inside the face (default 2h). The gain G is a causal
    filter following Biesel's piston transfer function frequency by frequency, delayed by the
    gauge's offset and exact at the wave period (``absorption_period``, else the source
    theory's); the correction's vertical profile is linear theory's cosh k(z + d) at that period
    (uniform when no period is known); ``sph_core.absorption``, docs/studies/absorption.md. The plain
    gains (``absorption`` shallow/linear), the flux transfer, the uniform profile and the
    gauge's own reading as the outlet's surface were measured and retired (docs/decisions/)."""

    side: Literal["left", "right"]
    elevation: Literal["imposed", "extrapolated"] = "imposed"
    absorb: bool = True
    absorption_period: float | None = Field(None, gt=0, description=(
        "wave period [s] where the absorption filter is exact and whose mode profiles the "
        "correction (None: the source's)"))
    gauge_offset: float | None = Field(None, gt=0, description="boundary gauge distance inside the face [m]")
    buffer_width: float | None = Field(None, gt=0, description=(
        "buffer width outside the face [m], in whole particle columns, at least one kernel "
        "support (2h, also the default); a wave flume wants the wave's surface orbit diameter "
        "H / tanh(kd) plus 2h, so the orbits do not carry the buffer's particles through it "
        "(docs/physics/open_boundaries.md, 'Buffer width')"))
    pressure: Literal["hydrostatic", "extrapolated"] | None = Field(
        None, description="buffer pressure: hydrostatic below the buffer's surface, or "
                          "extrapolated from the fluid through mirrored ghost nodes; None: "
                          "OUTLET_PRESSURE (extrapolated) for an extrapolated elevation, else "
                          "INLET_PRESSURE (hydrostatic; ISPH: ISPH_INLET_PRESSURE, extrapolated); "
                          "hydrostatic buffers extrapolate within h of their surface; ISPH "
                          "solves the pressure of buffer particles next to the fluid with it")


MAX_OUTPUTS = 10_000_000  # probe rows or snapshots of one run (beyond: an interval below dt)


class Output(_Model):
    """Output cadence in simulated seconds (0 = never)."""

    probe_every: float = Field(0.01, ge=0)
    snapshot_every: float = Field(0.0, ge=0)


DEVICES = ("cpu", "cuda")   # RunSettings.device's values


class RunSettings(_Model):
    """How the scene is run (not what is simulated): the device that takes the SPH steps."""

    device: Literal["cpu", "cuda"] = Field(
        "cpu", description="cpu: the numba step on the CPU cores; cuda: the step on an NVIDIA GPU "
                           "(numba-cuda: WCSPH and Riemann SPH with either integrator and "
                           "shifting; open ends and bodies with kdk delta-SPH; not ISPH or "
                           "float32 storage: docs/developer/gpu.md); `wavesph run --device` "
                           "overrides it")


class Scene(_Model):
    """A complete SPH tank scene."""

    name: str = "scene"
    dim: Literal[2, 3] = Field(2, description=(
        "2: the vertical plane x-z (per metre of width); 3: x, y, z (the tank a box, y across it)"))
    dp: float = Field(gt=0, description="initial particle spacing [m]")
    t_end: float = Field(gt=0, description="end time [s]")
    # A coupled zone that stays at rest until the far-field waves arrive need not be solved
    # before then: its clock starts at t_start (the wave model runs alone up to it).
    t_start: float = Field(0.0, ge=0, description="start time [s]: the water is at rest then")
    still_water_level: float | None = Field(None, description="z of the still-water level [m]")
    tank: Tank
    water_blocks: list[WaterBlock] = Field(min_length=1)
    beds: list[Bed] = []
    structures: list[Structure] = []
    constants: Constants = Constants()
    scheme: Scheme = Scheme()
    output: Output = Output()
    run: RunSettings = RunSettings()
    probes: list[Probe] = []
    open_boundaries: list[OpenBoundary] = []
    bodies: list[Body] = []

    @model_validator(mode="before")
    @classmethod
    def _across_tank(cls, data: Any) -> Any:
        # a 3D scene's water block, box structure or force probe without y0, y1 spans the tank's
        # width: given so here, as a new value (the models are frozen, and a caller's object
        # may serve other scenes)
        if not (isinstance(data, dict) and data.get("dim") == 3):
            return data
        tank = data.get("tank")
        get = tank.get if isinstance(tank, dict) else (lambda k: getattr(tank, k, None))
        y0, y1 = get("y0"), get("y1")
        if y0 is None or y1 is None:
            return data

        def across(v: Any) -> Any:
            if isinstance(v, dict):
                box = v.get("kind", "force") == "force" and v.get("shape") != "cylinder"
                return {**v, "y0": y0, "y1": y1} if box and v.get("y0") is None and v.get("y1") is None else v
            if isinstance(v, Rect) and v.y0 is None and getattr(v, "shape", "box") != "cylinder":
                return v.model_copy(update={"y0": y0, "y1": y1})
            return v

        return {**data, **{key: [across(v) for v in data[key]]
                           for key in ("water_blocks", "structures", "probes")
                           if isinstance(data.get(key), list)}}

    @model_validator(mode="before")
    @classmethod
    def _scheme_h(cls, data: Any) -> Any:
        # ISPH was built and measured at h/dp sqrt 2; at the WCSPH default h/dp 2 its still tank
        # (d/dp 10) reaches 0.045 m/s in 0.2 s against 0.009 (corner particles creep inward), so an
        # ISPH scene without its own h_over_dp gets sqrt 2
        if isinstance(data, dict):
            scheme, cst = data.get("scheme") or {}, data.get("constants") or {}
            kind = scheme.get("kind") if isinstance(scheme, dict) else getattr(scheme, "kind", None)
            if kind == "isph" and isinstance(cst, dict) and "h_over_dp" not in cst:
                data = {**data, "constants": {**cst, "h_over_dp": ISPH_H_OVER_DP}}
        return data

    @model_validator(mode="after")
    def _consistent(self) -> "Scene":
        t = self.tank
        if self.dim == 3:
            self._consistent_3d()
        else:
            self._flat()
        if not self.t_end > self.t_start:
            raise ValueError(f"t_end: must be after t_start = {self.t_start} s")
        sides = [o.side for o in self.open_boundaries]
        if len(set(sides)) != len(sides):
            raise ValueError(f"open_boundaries: one boundary per side, got sides {sides}")
        if self.open_boundaries and self.still_water_level is None:
            raise ValueError("still_water_level: required when the scene has open_boundaries")
        for i, b in enumerate(self.water_blocks):
            if b.x0 < t.x0 - 1e-12 or b.x1 > t.x1 + 1e-12 or b.z0 < t.z0 - 1e-12 or b.z1 > t.z1:
                raise ValueError(f"water_blocks.{i}: must lie inside the tank")
            if min(b.x1 - b.x0, b.z1 - b.z0) < self.dp:
                raise ValueError(f"water_blocks.{i}: must be at least dp wide and high")
        swl = self.still_water_level
        if swl is not None:
            if not t.z0 < swl < t.z1:
                raise ValueError(f"still_water_level: {swl} m must lie between the tank's floor "
                                 f"z0 = {t.z0} m and top z1 = {t.z1} m (with freeboard for the waves)")
            tops = [b.z1 for b in self.water_blocks]
            if tops and abs(max(tops) - swl) > 0.5 * self.dp:
                raise ValueError(f"still_water_level: {swl} m, but the highest water block's top "
                                 f"is {max(tops)} m: the blocks hold the still water, so they "
                                 "should meet it (within dp/2)")
            msg = datum_mismatch(swl, max(tops), t.z0, self.dp)
            if msg:
                raise ValueError(f"still_water_level: {msg}")
        for i, p in enumerate(self.probes):
            if p.kind == "runup" and swl is None:
                raise ValueError(f"probes.{i}: a runup probe measures from still_water_level; "
                                 "give it")
        dup = {n for n, k in Counter(p.name for p in self.probes).items() if k > 1}  # O(n)
        if dup:
            raise ValueError(f"probes: duplicate names {sorted(dup)}")
        for i, p in enumerate(self.probes):
            x = getattr(p, "x", None)
            if x is not None and not (t.x0 <= x <= t.x1):
                raise ValueError(f"probes.{i}.x: must lie inside the tank [{t.x0}, {t.x1}]")
        if self.scheme.kind == "isph":
            # the ISPH step moves bodies with loads from the step's own pressure (explicit
            # coupling): a free or hinged body lighter than its added mass is unstable so
            # (measured: a floating box's heave load went 0.9, 1.3, 0.07, 5.1, -8.9 x its
            # weight in the first five steps; a hinged flap left the tank at 0.15 s).
            # Fixed and prescribed bodies are moving walls of the pressure equation.
            for i, b in enumerate(self.bodies):
                if b.motion in ("free", "hinged"):
                    raise ValueError(f"bodies.{i}.motion: isph supports fixed and prescribed "
                                     f"bodies only, got {b.motion!r} (use scheme kind "
                                     "\"wcsph\" for free or hinged bodies)")
        bnames = [b.name for b in self.bodies]
        if len(set(bnames)) != len(bnames):
            raise ValueError(f"bodies: duplicate names {bnames}")
        for i, p in enumerate(self.probes):
            follow = getattr(p, "follow", None)
            if follow is not None and follow not in bnames:
                raise ValueError(f"probes.{i}.follow: no body named {follow!r} (bodies: {bnames})")
        if self.output.snapshot_every and self.output.snapshot_every > self.t_end - self.t_start:
            raise ValueError("output.snapshot_every: must not exceed the run's length t_end - t_start")
        for name in ("probe_every", "snapshot_every"):  # 1e-300 s: a run that only writes rows
            every = getattr(self.output, name)
            if every and (self.t_end - self.t_start) / every > MAX_OUTPUTS:
                raise ValueError(f"output.{name}: {every:g} s makes more than {MAX_OUTPUTS:,} "
                                 f"outputs of the run's {self.t_end - self.t_start:g} s")
        return self

    def _flat(self) -> None:
        """A 2D scene names no y."""
        boxes = ([("tank", self.tank)] + [(f"water_blocks.{i}", b) for i, b in enumerate(self.water_blocks)]
                 + [(f"structures.{i}", b) for i, b in enumerate(self.structures)]
                 + [(f"probes.{i}", p) for i, p in enumerate(self.probes) if isinstance(p, Rect)])
        for where, r in boxes:
            if r.y0 is not None:
                raise ValueError(f"{where}.y0: a y range needs a 3D scene (dim = 3)")
        for i, p in enumerate(self.probes):
            if getattr(p, "y", 0.0) != 0.0 or len(getattr(p, "moment_about", None) or ()) == 3:
                raise ValueError(f"probes.{i}: y needs a 3D scene (dim = 3)")
        for i, s in enumerate(self.structures):
            if s.shape != "box":
                raise ValueError(f"structures.{i}.shape: a {s.shape} needs a 3D scene (dim = 3)")

    def _consistent_3d(self) -> None:
        """A 3D scene: the tank has a y range, every box lies across it, and only the features
        the 3D step has are asked for (each refusal one line)."""
        t = self.tank
        if t.y0 is None:
            raise ValueError("tank.y0: a 3D scene's tank needs y0 and y1 (its width) [m]")
        if (t.y1 - t.y0) < 2.0 * self.dp:
            raise ValueError("tank.y1: the tank must be at least 2 dp wide")
        named = ([(f"water_blocks.{i}", b) for i, b in enumerate(self.water_blocks)]
                 + [(f"structures.{i}", b) for i, b in enumerate(self.structures)]
                 + [(f"probes.{i}", p) for i, p in enumerate(self.probes) if isinstance(p, Rect)])
        for where, r in named:
            if r.y0 is None:   # the others were given the tank's width (_across_tank)
                raise ValueError(f"{where}.y0: a cylinder needs its y0, y1 (its diameter)")
            if where.startswith("water_blocks") and (r.y0 < t.y0 - 1e-12 or r.y1 > t.y1 + 1e-12):
                raise ValueError(f"{where}: must lie inside the tank (y {t.y0}..{t.y1})")
        for i, p in enumerate(self.probes):
            y = getattr(p, "y", None)
            if y is not None and not (t.y0 <= y <= t.y1):
                raise ValueError(f"probes.{i}.y: must lie inside the tank [{t.y0}, {t.y1}]")
        refused = {
            "bodies": bool(self.bodies),
            "scheme.kind": self.scheme.kind != "wcsph",
            "constants.shifting": self.constants.shifting != "none",
            "run.device": self.run.device != "cpu",
        }
        for key, asked in refused.items():
            if asked:
                raise ValueError(f"{key}: not available in 3D yet (dim = 3 runs WCSPH with "
                                 "delta-SPH on the CPU: walls, beds, box and cylinder "
                                 "structures, open ends with long-crested waves; "
                                 "docs/developer/three_dimensions.md)")

    # derived quantities -------------------------------------------------------------------
    @property
    def h(self) -> float:
        """Smoothing length h = h_over_dp * dp [m]; the kernel support is 2h."""
        return self.constants.h_over_dp * self.dp

    @property
    def water_height(self) -> float:
        """Highest water surface above the lowest water bottom [m] (for c0)."""
        return max(b.z1 for b in self.water_blocks) - min(b.z0 for b in self.water_blocks)

    @property
    def c0(self) -> float:
        """Speed of sound [m/s]: explicit, or c0_factor * sqrt(2 g H)."""
        c = self.constants
        return c.c0 if c.c0 is not None else c.c0_factor * math.sqrt(2.0 * c.g * self.water_height)


def filled_surface(block_top: float, z0: float, dp: float) -> float:
    """z [m] of the water surface the particles make in a block reaching ``block_top``: rows sit
    at z0 + (j + 1/2) dp below the top (sph_core.geometry's lattice, anchored at the tank
    floor ``z0``), each holding a layer dp thick."""
    return z0 + dp * math.ceil((block_top - z0) / dp - 0.5 - 1e-9)


def datum_mismatch(swl: float, block_top: float, z0: float, dp: float) -> str | None:
    """Why the particles' surface would miss the still-water level, or None (with the highest
    block's top within dp/2 of the level, it misses only if dp does not divide the depth
    ``swl - z0``). Elevation gauges read eta = z_surface - still_water_level, so a surface dp/2
    low reads -dp/2 in still water (a third of H at H/dp 1.5), and the open ends' depth
    disagrees with the water's."""
    if not math.isfinite((block_top - z0) / dp):   # dp 5e-324: the particle cap refuses it
        return None
    surface = filled_surface(block_top, z0, dp)
    if _on_level(surface, swl, dp):
        return None
    depth = swl - z0
    rows = depth / dp
    fine, coarse = depth / math.ceil(rows), depth / max(1, math.floor(rows))
    return (f"{swl:g} m is {rows:.4g} dp above the tank floor z0 = {z0:g} m (dp = {dp:g} m): "
            f"the particles would fill to {surface:.4g} m and every elevation gauge would read "
            f"{surface - swl:+.3g} m in still water; pick a dp that divides the depth {depth:g} m, "
            f"e.g. {divisor_text(depth, fine)} or {divisor_text(depth, coarse)} m")


def divisor_text(depth: float, dp: float) -> str:
    """The shortest decimal of ``dp``, a divisor of ``depth``, that a scene accepts as one (its
    rows still fill to the depth, datum_mismatch): what to write in a scene file. Four digits are
    not always enough (0.3 m / 17 = 0.01765 fills to 0.30005 m)."""
    rows = round(depth / dp)
    for digits in range(1, 18):
        text = f"{dp:.{digits}g}"
        d = float(text)
        if round(depth / d) == rows and _on_level(filled_surface(depth, 0.0, d), depth, d):
            return text
    return repr(dp)


def _on_level(surface: float, swl: float, dp: float) -> bool:
    return abs(surface - swl) <= 1e-3 * dp   # round-off of dp values such as H/3


def _format_errors(exc: ValidationError) -> str:
    lines = []
    for err in exc.errors():
        loc = [str(p) for p in err["loc"] if p not in ("function-after",)]
        # discriminated unions add the tag name to the path: drop it
        loc = [p for p in loc if p not in ("point", "elevation", "front", "force",
                                           "pressure_line", "overtopping")]
        msg = err["msg"].removeprefix("Value error, ")
        if ": " in msg and not msg.startswith(("Input", "Field")):
            head, tail = msg.split(": ", 1)
            if head.split(".")[0] in {"x0", "x1", "z0", "z1", "points", "density_band",
                                      *(key for _, key in RETIRED)}:
                loc.append(head)
                msg = tail
            elif loc == [] or "." in head or head in {"probes", "output.snapshot_every"}:
                loc = head.split(".") if not loc else loc + head.split(".")
                msg = tail
        lines.append(f"{'.'.join(loc) or '<scene>'}: {msg}")
    return "; ".join(lines)


# A scene file may also say how a server runs it (`wavesph submit`, `wavesph couple --scene`,
# POST /runs with a TOML body): `mode`, `[coupling]` (window_max, z_ref), `[source]` (a built-in
# theory). They are not part of the Scene; `wavesph run` ignores them. (The scene's own `[run]`
# table, RunSettings, is part of it: the device its steps take.)
RUN_TABLES = ("mode", "coupling", "source")


def split_scene_file(data: dict) -> tuple[dict, dict]:
    """A parsed scene file as (scene fields, run settings: the RUN_TABLES it has)."""
    return ({k: v for k, v in data.items() if k not in RUN_TABLES},
            {k: data[k] for k in RUN_TABLES if k in data})


def make_scene(data: dict) -> Scene:
    """Validate a plain dict (e.g. parsed TOML) into a Scene; raise SceneError naming the fields."""
    try:
        return Scene.model_validate(data)
    except ValidationError as exc:
        raise SceneError(f"invalid scene: {_format_errors(exc)}") from None


def load_scene(path: str | Path) -> Scene:
    """Read a TOML scene file into a validated Scene."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise SceneError(f"scene file not found: {path}") from None
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path}: not valid TOML ({exc})") from None
    except UnicodeDecodeError as exc:
        raise SceneError(f"{path}: not UTF-8 text (byte {exc.start}): a scene file is TOML") from None
    except OSError as exc:  # a directory, no permission
        raise SceneError(f"{path}: cannot be read ({exc.strerror or exc})") from None
    try:
        return make_scene(split_scene_file(data)[0])
    except SceneError as exc:
        raise SceneError(f"{path}: {exc}") from None
