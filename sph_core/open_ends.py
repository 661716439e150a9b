"""Open inlet/outlet ends of a run, as a value the Simulation carries (no subclass, no own loop).

    ends = OpenBoundaries.from_scene(scene, sources={"left": src_in, "right": src_out}, window=T/50)
    ends = OpenBoundaries.closed()        # a closed tank: every open-end hook of the step is a no-op
    sim = Simulation(scene, sources=..., window=...)   # builds one of them from scene.open_boundaries
    sim.advance_to(t_end)                  # windows of `window`, each source sampled at its end
    sim.advance_window(t1, left=sample_in, right=sample_out)   # driven from outside (the server)
    sim.boundary_gauges(); sim.boundary_counts()

The scene's ``open_boundaries`` say which tank walls are open (see ``scene.OpenBoundary``);
``nodes[side]`` (``BoundaryNodes``) are the z levels where a source gives u and w. Inside a window
[t0, t1] the jitted loop interpolates the two end samples linearly in time (seed 001,
Algorithm 2), so no Python runs between sub-steps. Bad boundary data raise ``BoundaryDataError``
before any step is taken. The jitted physics is open_boundary.py; the kernels see this value as
``state.OpenEnds`` (``self.ends``), whose window arrays ``load_window`` fills in place, and
ISPH's relaxation zones the wave inside the domain as ``state.ZoneTargets`` (``self.zone``, filled
by the same call: from the side's source where a wave model drives the run in-process, or from
the zone's columns given with the window, ``zone_end``, where a coupling client sends them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from .absorption import (absorption_filter, correction_profile, linear_wavenumber,
                         profile_wavenumber, source_period)
from .boundary_data import (BoundaryData, BoundaryDataError, BoundaryNodes, BoundarySample,
                            still_sample, validate_sample)
from .eos import GAMMA, hydrostatic_density
from .open_boundary import INLET_IDLE
from .particles import INLET, M, P, RHO, WALL, X, Y, Z, ParticleSet
from .scene import (INLET_PRESSURE, ISPH_INLET_PRESSURE, OUTLET_PRESSURE, OpenBoundary,
                    Scene)
from .state import OpenEnds, ZoneTargets, closed_ends, no_zone_targets

SIDES = ("left", "right")


@dataclass
class OpenState:
    """What a checkpoint keeps of the open ends beyond the particles: gauges, counters, the
    samples at the window start, the absorption filter's state."""

    eta_meas: np.ndarray
    counters: np.ndarray
    samples: dict[str, BoundarySample]
    filt_x: np.ndarray
    zs: np.ndarray | None = None   # the buffers' surfaces (None in checkpoints made before it)
    # ISPH's relaxation zones: which ends pull towards local targets, those targets at the
    # window start ([2, K, nodes] u and w) and their time (None: no local targets, or a
    # checkpoint made before them)
    zone_local: np.ndarray | None = None
    zone_u: np.ndarray | None = None
    zone_w: np.ndarray | None = None
    zone_t: float | None = None


def check_open_end_layout(scene: Scene) -> None:
    """ValueError naming the scene field whose geometry open ends cannot stand in (checked
    cheaply, before any particle: a server refuses such a run before it accepts it)."""
    cells = (scene.tank.x1 - scene.tank.x0) / scene.dp
    if "right" in {o.side for o in scene.open_boundaries} and abs(cells - round(cells)) > 1e-6:
        # the right buffer continues the fluid lattice laid out from x0: a partial spacing
        # would leave a gap (or an overlap) of particles at the face
        raise ValueError(f"tank.x1: x1 - x0 = {scene.tank.x1 - scene.tank.x0} m must be a "
                         f"whole number of particle spacings dp = {scene.dp} m with a right "
                         "open end")
    reach = 4.0 * scene.h  # the buffer (2h) and the support of its outermost fluid
    for i, bed in enumerate(scene.beds):
        xs = [pt[0] for pt in bed.points]
        for o in scene.open_boundaries:
            xf = scene.tank.x0 if o.side == "left" else scene.tank.x1
            if min(xs) - reach < xf < max(xs) + reach:
                # buffers stand on the tank floor: a bed there would cut through them
                raise ValueError(f"beds.{i}: comes within {reach:.3g} m of the {o.side} open "
                                 "end; open ends need the flat tank floor there")


def orbit_diameter(height: float, period: float, depth: float, g: float = 9.81) -> float:
    """Horizontal diameter [m] of a wave's surface orbit, H / tanh kd (linear theory): how far
    the water at the face travels in and out over a period."""
    kd = linear_wavenumber(2.0 * math.pi / period, depth, g) * depth
    return height / math.tanh(kd)


def buffer_widths(scene: Scene) -> dict[str, float]:
    """Each open end's buffer width [m] (before rounding up to whole columns): the scene's
    ``buffer_width``, else the kernel support 2h. A wave flume wants the wave's orbit diameter
    plus 2h (``orbit_diameter``; wavesph.cases.wave_flume.buffer_width_for): a buffer
    narrower than the orbit is emptied and refilled from the fluid every period, and its
    particles then stand where fluid crossed the face; at H/dp 8 (case V) the flume lost its
    reflection goal that way (docs/studies/absorption.md, 'The buffer's width'). The width is
    the scene's alone, so a standalone run and a coupled one of the same scene step alike."""
    return {o.side: o.buffer_width if o.buffer_width is not None else 2.0 * scene.h
            for o in scene.open_boundaries}


class OpenBoundaries:
    """The open ends of a run: their settings, data sources and window (module docstring)."""

    def __init__(self, sides: tuple[str, ...], nodes: Mapping[str, BoundaryNodes],
                 sources: Mapping[str, BoundaryData], window: float, ends: OpenEnds,
                 still_water_level: float, zone: ZoneTargets | None = None) -> None:
        self.sides = sides
        self.nodes = dict(nodes)
        self.sources = dict(sources)
        self.window = float(window)
        self.ends = ends
        self.swl = still_water_level
        # samples at the window start: at rest until the first window is loaded
        self.samples = {s: still_sample(self.nodes[s], 0.0) for s in sides}
        # ISPH's relaxation zones: local targets of the ends whose source knows the wave inside
        # the domain, at stations k ds from the face into the fluid; _zone_t: the time of their
        # level-1 data (NaN: none loaded yet)
        self.zone = no_zone_targets() if zone is None else zone
        self.has_zone = zone is not None   # ISPH's relaxation zones: local targets may be given
        self._zone_t = math.nan

    # ---------------------------------------------------------------- named constructors
    @classmethod
    def closed(cls, capacity: int = 1) -> "OpenBoundaries":
        """No open end: the step's open-end hooks do nothing."""
        return cls((), {}, {}, math.inf, closed_ends(capacity), math.nan)

    @classmethod
    def from_scene(cls, scene: Scene, sources: Mapping[str, BoundaryData] | None = None,
                   window: float = 0.02, capacity: int = 1) -> "OpenBoundaries":
        """The scene's open ends with their data sources (sides without a source hold their last
        data, at first rest). Raises ValueError naming the scene field that rules them out."""
        if not scene.open_boundaries:
            if sources:
                raise ValueError(f"sources: no open boundary on side(s) {sorted(sources)}")
            return cls.closed(capacity)
        if not (math.isfinite(window) and window > 0):
            raise ValueError(f"window: must be a positive number of seconds, got {window}")
        check_open_end_layout(scene)
        sides = tuple(o.side for o in scene.open_boundaries)
        sources = dict(sources or {})
        unknown = set(sources) - set(sides)
        if unknown:
            raise ValueError(f"sources: no open boundary on side(s) {sorted(unknown)}")
        nodes = flume_nodes(scene)
        for side, src in sources.items():
            if src.nodes.size != nodes[side].size or not np.allclose(src.nodes.z, nodes[side].z):
                raise BoundaryDataError(f"sources.{side}.nodes: not the flume's nodes "
                                        f"(use flume_nodes(scene)['{side}'])")
        swl = float(scene.still_water_level)
        nn = next(iter(nodes.values())).size
        e = closed_ends(capacity, nn)
        dp, c = scene.dp, scene.constants
        depth = swl - scene.tank.z0
        for o in scene.open_boundaries:
            b = SIDES.index(o.side)
            nd = nodes[o.side]
            e.on[b] = True
            e.x_face[b] = nd.x_face
            e.nx[b] = -1.0 if b == 0 else 1.0
            e.swl[b] = swl
            e.zs[b] = swl   # at rest until the first update
            period = o.absorption_period or source_period(sources.get(o.side))
            q = profile_wavenumber(c.g, depth, period)
            e.sqgd[b], e.filt_tau[b], e.filt_c[b] = absorption_filter(
                c.g, depth, abs(nd.x_gauge - nd.x_face), period, q)
            # the profile above the still-water level continues linear theory's cosh (crests)
            e.corr_prof[b] = correction_profile((nd.z - nd.z_bed) / depth, q)
            e.absorb[b] = o.absorb
            e.imposed[b] = o.elevation == "imposed"
            e.ghost[b] = buffer_pressure(o, scene.scheme.kind) == "extrapolated"
            e.x_gauge[b] = nd.x_gauge
            e.z_bed[b] = nd.z_bed
            e.z_top[b] = nd.z_top
            e.zn[b] = nd.z
        for b in range(2):  # an end without boundary keeps valid (unused) node levels
            if not e.on[b]:
                e.zn[b] = e.zn[1 - b]
        # 3D: long-crested boundary data, the gauges' lines at mid-width
        y_gauge = 0.5 * (scene.tank.y0 + scene.tank.y1) if scene.dim == 3 else 0.0
        e = e._replace(active=True, dz_gauge=0.25 * dp, dp=dp, y_gauge=y_gauge)
        return cls(sides, nodes, sources, window, e, swl,
                   zone_targets(scene, sources, nn))

    # ---------------------------------------------------------------- setup
    @property
    def active(self) -> bool:
        return bool(self.ends.active)

    def attach(self, ps: ParticleSet, scene: Scene, b_tait: float,
               buffer_length: Mapping[str, float]) -> None:
        """Turn the tank wall columns of the open sides into buffer particles of ``ps`` and size
        the jitted state for its capacity; ``buffer_length``: side -> the buffer's width [m]
        (its columns times dp)."""
        self.ends = self.ends._replace(capacity=ps.capacity)
        if not self.active:
            return
        tank, dp, c = scene.tank, scene.dp, scene.constants
        for side in self.sides:
            self.ends.length[SIDES.index(side)] = buffer_length[side]
        n = ps.n
        x, y, z, kind = ps.f[X, :n], ps.f[Y, :n], ps.f[Z, :n], ps.kind[:n]
        # 3D: only the columns across the tank's width; those beyond it (the edges of the x
        # walls) stay walls, the side walls of the buffer
        across = (y > tank.y0) & (y < tank.y1) if scene.dim == 3 else np.ones(n, dtype=bool)
        for side in self.sides:
            b = SIDES.index(side)
            xf, nx = self.ends.x_face[b], self.ends.nx[b]
            # the wall columns outside this face (above the floor) become the buffer lattice
            sel = np.nonzero((kind == WALL) & ((x - xf) * nx > 0) & (z > tank.z0) & across)[0]
            wet = z[sel] < self.swl
            kind[sel] = np.where(wet, INLET + b, INLET_IDLE + b)
            rho = np.where(wet, hydrostatic_density(z[sel], self.swl, c.rho0, c.g, b_tait),
                           c.rho0)
            ps.f[RHO, sel] = rho
            ps.f[P, sel] = b_tait * ((rho / c.rho0) ** GAMMA - 1.0)
            ps.f[M, sel] = rho * dp ** scene.dim

    def fluid_box(self, x0: float, x1: float, dp: float) -> tuple[float, float]:
        """x range a fluid particle may reach: fluid may enter a buffer before it is converted."""
        e = self.ends
        if e.on[0]:
            x0 = e.x_face[0] - e.length[0] - dp
        if e.on[1]:
            x1 = e.x_face[1] + e.length[1] + dp
        return x0, x1

    # ---------------------------------------------------------------- windows
    def start(self, t: float) -> None:
        """Window start data at time t: the sources' samples there, else rest."""
        self.samples = {s: (validate_sample(self.sources[s].sample(t), self.nodes[s], self.swl,
                                            where=s) if s in self.sources
                            else still_sample(self.nodes[s], t))
                        for s in self.sides}
        self.load_window(t, t, self.samples)

    def end_samples(self, t1: float, given: Mapping[str, BoundarySample | None]
                    ) -> dict[str, BoundarySample]:
        """Validated data at t1 for every open end: given, else the side's source, else the last
        window's data held. Raises BoundaryDataError naming the side and field."""
        end: dict[str, BoundarySample] = {}
        for side in SIDES:
            s = given.get(side)
            if side not in self.sides:
                if s is not None:
                    raise BoundaryDataError(f"{side}: the flume has no open boundary there")
                continue
            if s is None:
                last = self.samples[side]
                s = (self.sources[side].sample(t1) if side in self.sources
                     else BoundarySample(t1, last.u, last.w, last.eta, last.eta_gauge))
            end[side] = validate_sample(s, self.nodes[side], self.swl, where=side)
            if abs(end[side].t - t1) > 1e-9 * max(1.0, abs(t1)):
                raise BoundaryDataError(f"{side}.t: sample at t = {end[side].t} for a window "
                                        f"ending at {t1}")
        return end

    def load_window(self, t0: float, t1: float, end: Mapping[str, BoundarySample],
                    zone_end: Mapping[str, tuple[np.ndarray, np.ndarray]] | None = None) -> None:
        """The jitted window: data of the current start samples at t0, of ``end`` at t1 (and
        the relaxation zones' local targets at both). ``zone_end``: side -> (u, w)[station,
        node] at t1 of that end's zone, given from outside (``check_zone_data``); the ends it
        names pull towards them, the others towards their source's wave (in-process) or the
        face's profile."""
        e = self.ends
        e.win_t[:] = (t0, t1)
        for side in self.sides:
            b = SIDES.index(side)
            for lv, s in enumerate((self.samples[side], end[side])):
                e.win_u[b, lv] = s.u
                e.win_w[b, lv] = s.w
                e.win_eta[b, lv] = s.eta
                e.win_etag[b, lv] = s.gauge_eta
        if self.has_zone:
            self._load_zone(t0, t1, zone_end or {})

    def _load_zone(self, t0: float, t1: float,
                   given: Mapping[str, tuple[np.ndarray, np.ndarray]]) -> None:
        """The zones' local targets at t0 and t1: at t0 the last window's t1 data (else, after a
        restore without them, the source sampled at t0, or the given data held over the
        window); at t1 the given data, else each in-process source's (``velocity_along``). An
        end with neither pulls towards its face's profile (``local`` False)."""
        z = self.zone
        k = np.arange(z.u.shape[1])
        go_on = abs(self._zone_t - t0) <= 1e-9 * max(1.0, abs(t0))
        for b, side in enumerate(SIDES):
            src = self.sources.get(side)
            dx = -self.ends.nx[b] * z.ds * k   # the stations' offsets from the face
            if side in given:
                u1, w1 = given[side]
            elif side in self.sides and hasattr(src, "velocity_along"):
                u1, w1 = src.velocity_along(t1, dx)
            else:
                z.local[b] = False
                continue
            if go_on and z.local[b]:
                z.u[b, :, 0] = z.u[b, :, 1]
                z.w[b, :, 0] = z.w[b, :, 1]
            elif side not in given:
                z.u[b, :, 0], z.w[b, :, 0] = src.velocity_along(t0, dx)
            else:
                z.u[b, :, 0], z.w[b, :, 0] = u1, w1
            z.u[b, :, 1], z.w[b, :, 1] = u1, w1
            z.local[b] = True
        self._zone_t = t1

    def zone_columns(self) -> dict[str, np.ndarray]:
        """side -> the x [m] of the zone's stations inside the fluid (station 0, the face,
        excluded: its data is the window's face sample) where local targets may be given from
        outside (``load_window``'s ``zone_end``); empty without ISPH relaxation zones."""
        z = self.zone
        if not self.has_zone:
            return {}
        k = np.arange(1, z.u.shape[1])
        return {side: self.ends.x_face[SIDES.index(side)]
                - self.ends.nx[SIDES.index(side)] * z.ds * k for side in self.sides}

    def check_zone_data(self, end: Mapping[str, BoundarySample],
                        given: Mapping[str, tuple[np.ndarray, np.ndarray]]
                        ) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """The zones' data at t1 given from outside as ``load_window`` takes it: (u, w)[station,
        node], station 0 the face's sample in ``end`` (``end_samples``). ``given``: side -> (u,
        w)[column, node] over ``zone_columns()[side]``. Raises BoundaryDataError naming the side
        and field."""
        cols = self.zone_columns()
        out: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        for side, (u, w) in given.items():
            if side not in cols:
                raise BoundaryDataError(f"{side}.zone: this run has no relaxation zone there")
            shape = (cols[side].size, self.nodes[side].size)
            u, w = np.asarray(u, dtype=float), np.asarray(w, dtype=float)
            for name, a in (("u", u), ("w", w)):
                if a.shape != shape:
                    raise BoundaryDataError(f"{side}.zone.{name}: shape {a.shape}, expected "
                                            f"{shape} (columns, nodes)")
                if not np.all(np.isfinite(a)):
                    raise BoundaryDataError(f"{side}.zone.{name}: not finite at t = "
                                            f"{end[side].t}")
            out[side] = (np.vstack([end[side].u[None, :], u]), np.vstack([end[side].w[None, :], w]))
        return out

    # ---------------------------------------------------------------- readings and state
    def gauges(self) -> dict[str, float | None]:
        out: dict[str, float | None] = {}
        for side in self.sides:
            v = self.ends.eta_meas[SIDES.index(side)]
            out[side] = float(v) if math.isfinite(v) else None
        return out

    def counts(self) -> dict[str, dict[str, int]]:
        return {side: dict(zip(("in", "out", "created", "removed"),
                               (int(v) for v in self.ends.counters[SIDES.index(side)])))
                for side in self.sides}

    def state(self) -> OpenState | None:
        if not self.active:
            return None
        z = self.zone
        zone = ((z.local.copy(), z.u[:, :, 1].copy(), z.w[:, :, 1].copy(), float(self._zone_t))
                if z.local.any() and math.isfinite(self._zone_t) else (None,) * 4)
        return OpenState(self.ends.eta_meas.copy(), self.ends.counters.copy(), dict(self.samples),
                         self.ends.filt_x.copy(), self.ends.zs.copy(), *zone)

    def set_state(self, s: OpenState | None) -> None:
        if s is None:
            return
        self.ends.eta_meas[:] = s.eta_meas
        self.ends.counters[:] = s.counters
        if s.zs is not None:
            self.ends.zs[:] = s.zs
        self.samples = dict(s.samples)
        self.ends.filt_x[:] = s.filt_x
        self._zone_t = math.nan   # a local zone re-samples its source, or holds its given data
        if s.zone_u is not None and s.zone_w is not None and s.zone_t is not None \
                and s.zone_local is not None and s.zone_u.shape == self.zone.u[:, :, 1].shape:
            self.zone.local[:] = s.zone_local
            self.zone.u[:, :, 1] = s.zone_u
            self.zone.w[:, :, 1] = s.zone_w
            self._zone_t = float(s.zone_t)


def zone_targets(scene: Scene, sources: Mapping[str, BoundaryData], n_nodes: int
                 ) -> ZoneTargets | None:
    """The ZoneTargets of an ISPH scene with relaxation zones: stations at most dp apart over
    the zone, local at each end whose source can say the wave inside the domain
    (``velocity_along``, a wave model's boundary; ends fed from outside turn local when a
    window gives their data); None without zones."""
    length = scene.scheme.isph_relaxation_zone if scene.scheme.kind == "isph" else 0.0
    local = np.array([length > 0 and hasattr(sources.get(side), "velocity_along")
                      for side in SIDES], dtype=np.bool_)
    if not (length > 0 and scene.open_boundaries):
        return None
    k = max(2, math.ceil(length / scene.dp) + 1)
    return ZoneTargets(local, length / (k - 1), np.zeros((2, k, 2, n_nodes)),
                       np.zeros((2, k, 2, n_nodes)))


def buffer_pressure(o: OpenBoundary, scheme: str = "wcsph") -> str:
    """How the buffer of open end ``o`` gets its pressure under the scene's scheme kind:
    ``hydrostatic`` or ``extrapolated``."""
    if o.pressure is not None:
        return o.pressure
    if o.elevation == "extrapolated":
        return OUTLET_PRESSURE
    return ISPH_INLET_PRESSURE if scheme == "isph" else INLET_PRESSURE


def flume_nodes(scene: Scene) -> dict[str, BoundaryNodes]:
    """The boundary nodes of each open end of ``scene``: z levels from the floor to the top of
    the tank at spacing <= dp/2, the face x, the boundary gauge ``gauge_offset`` (default 2h)
    inside the face."""
    t, dp = scene.tank, scene.dp
    nz = int(math.ceil((t.z1 - t.z0) / (0.5 * dp))) + 1
    z = np.linspace(t.z0, t.z1, nz)
    out = {}
    for o in scene.open_boundaries:
        xf = t.x0 if o.side == "left" else t.x1
        off = o.gauge_offset if o.gauge_offset is not None else 2.0 * scene.h
        xg = xf + off if o.side == "left" else xf - off
        out[o.side] = BoundaryNodes(o.side, xf, z, t.z0, t.z1, xg)
    return out
