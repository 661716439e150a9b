"""An SPH flume with open ends, driven window by window by boundary-data sources.

    flume = OpenFlume(scene, sources={"left": src_in, "right": src_out}, window=T / 50)
    flume.advance_to(t_end)                      # samples each source at every window end
    # or, driven from outside (the coupling server), one window at a time:
    flume.advance_window(t1, left=sample_in, right=sample_out)   # BoundarySample at t1
    flume.boundary_gauges()   # {"left": eta, "right": eta} measured at the boundary gauges
    flume.probe_values()      # the scene's probes (elevation gauges mid-flume, points)

The scene's ``open_boundaries`` say which tank walls are open (see ``scene.OpenBoundary``);
``flume.nodes[side]`` (``BoundaryNodes``) are the z levels where a source gives u and w.
Inside a window [t0, t1] the jitted loop interpolates the two end samples linearly in time
(seed 001, Algorithm 2), so no Python runs between sub-steps. Bad boundary data raise
``BoundaryDataError`` before any step is taken: the state and the run directory stay as they were.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Mapping

import numpy as np

from . import open_boundary as ob
from . import wcsph
from .boundary_data import (BoundaryData, BoundaryDataError, BoundaryNodes, BoundarySample,
                            still_sample, validate_sample)
from .eos import GAMMA, hydrostatic_density
from .particles import INLET, M, P, RHO, WALL, X, Z, Checkpoint
from .scene import OUTLET_PRESSURE, OpenBoundary, Scene
from .simulation import STEPS_PER_CALL, Simulation, UnstableError

SIDES = ("left", "right")


@dataclass
class FlumeCheckpoint:
    """An exact copy of a flume: particles and clock, boundary state, last window samples."""

    particles: Checkpoint
    eta_meas: np.ndarray
    counters: np.ndarray
    samples: dict[str, BoundarySample]


class OpenFlume(Simulation):
    """A Simulation whose scene has open ends (inlet/outlet buffers); see the module docstring."""

    def __init__(self, scene: Scene, sources: Mapping[str, BoundaryData] | None = None,
                 run_dir: str | Path | None = None, window: float = 0.02,
                 spare: float = 0.3) -> None:
        if not scene.open_boundaries:
            raise ValueError("open_boundaries: the scene has none (use Simulation)")
        if scene.constants.integrator != "kdk":
            raise ValueError("constants.integrator: open boundaries run with 'kdk' only, "
                             f"got {scene.constants.integrator!r}")
        if not (math.isfinite(window) and window > 0):
            raise ValueError(f"window: must be a positive number of seconds, got {window}")
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
        super().__init__(scene, run_dir=run_dir, spare=spare)
        self.window = float(window)
        self.open_sides = tuple(o.side for o in scene.open_boundaries)
        sources = dict(sources or {})
        unknown = set(sources) - set(self.open_sides)
        if unknown:
            raise ValueError(f"sources: no open boundary on side(s) {sorted(unknown)}")
        self.sources = sources
        self._build_buffers()
        for side, src in sources.items():
            if src.nodes.size != self.nodes[side].size or not np.allclose(src.nodes.z,
                                                                           self.nodes[side].z):
                raise BoundaryDataError(f"sources.{side}.nodes: not the flume's nodes "
                                        f"(use flume_nodes(scene)['{side}'])")
        # the samples at the window start; the first from the sources, else rest
        self._samples = {s: (validate_sample(sources[s].sample(self.t), self.nodes[s],
                                             self.swl, where=s) if s in sources
                             else still_sample(self.nodes[s], self.t))
                         for s in self.open_sides}
        self._load_window(self.t, self._samples, self._samples)
        self.n_fluid0 = self.n_fluid
        self.fluid_mass0 = self.fluid_mass()
        if self.writer:
            self.writer.update_meta(**self._meta_fields())

    # ---------------------------------------------------------------- construction
    def _build_buffers(self) -> None:
        """Turn the tank wall columns of the open sides into buffer particles."""
        sc, ps = self.scene, self.particles
        tank, dp, c = sc.tank, sc.dp, sc.constants
        self.swl = float(sc.still_water_level)
        self.buffer_length = self.n_layers * dp
        self.nodes = flume_nodes(sc)
        nn = next(iter(self.nodes.values())).size
        self.obp = np.zeros((2, ob.N_OBP))
        self.zn = np.zeros((2, nn))
        self.win_t = np.zeros(2)
        self.win_u = np.zeros((2, 2, nn))
        self.win_w = np.zeros((2, 2, nn))
        self.win_eta = np.zeros((2, 2))
        self.win_etag = np.zeros((2, 2))
        self.eta_meas = np.full(2, np.nan)
        self.counters = np.zeros((2, ob.N_COUNTERS), dtype=np.int64)
        self._next_id = np.zeros(1, dtype=np.int64)
        n = ps.n
        x, z, kind = ps.f[X, :n], ps.f[Z, :n], ps.kind[:n]
        depth = self.swl - tank.z0
        for o in sc.open_boundaries:
            b = SIDES.index(o.side)
            nd = self.nodes[o.side]
            nx = -1.0 if b == 0 else 1.0
            p = self.obp[b]
            p[ob.OB_ON] = 1.0
            p[ob.OB_XF] = nd.x_face
            p[ob.OB_NX] = nx
            p[ob.OB_LEN] = self.buffer_length
            p[ob.OB_SWL] = self.swl
            p[ob.OB_SQGD] = math.sqrt(c.g / depth)
            p[ob.OB_ABSORB] = 1.0 if o.absorb else 0.0
            p[ob.OB_IMPOSED] = 1.0 if o.elevation == "imposed" else 0.0
            p[ob.OB_GHOST] = 1.0 if buffer_pressure(o) == "extrapolated" else 0.0
            p[ob.OB_XG] = nd.x_gauge
            p[ob.OB_ZBED] = nd.z_bed
            p[ob.OB_ZTOP] = nd.z_top
            p[ob.OB_DZG] = 0.25 * dp
            p[ob.OB_DP] = dp
            self.zn[b] = nd.z
            # the wall columns outside this face (above the floor) become the buffer lattice
            sel = np.nonzero((kind == WALL) & ((x - nd.x_face) * nx > 0) & (z > tank.z0))[0]
            wet = z[sel] < self.swl
            kind[sel] = np.where(wet, INLET + b, ob.INLET_IDLE + b)
            rho = np.where(wet, hydrostatic_density(z[sel], self.swl, c.rho0, c.g, self.b), c.rho0)
            ps.f[RHO, sel] = rho
            ps.f[P, sel] = self.b * ((rho / c.rho0) ** GAMMA - 1.0)
            ps.f[M, sel] = rho * dp * dp
            # fluid may enter the buffer before it is converted: widen the domain check
            if b == 0:
                self.prm[wcsph.PR_FX0] = nd.x_face - self.buffer_length - dp
            else:
                self.prm[wcsph.PR_FX1] = nd.x_face + self.buffer_length + dp
        for b in range(2):  # an end without boundary keeps valid (unused) node levels
            if self.obp[b, ob.OB_ON] == 0.0:
                self.zn[b] = self.zn[1 - b]
        self._next_id[0] = ps.next_id
        self.dt = float(wcsph.initialise(*self._arrays(), ps.n, self.prm, self.grid.ncx,
                                         self.grid.ncz))
        self._swap()
        ob.measure_boundaries(ps.f, ps.kind, self.cell_start, self.obp, self.eta_meas, self.prm,
                              self.grid.ncx, self.grid.ncz)

    def _load_window(self, t1: float, start: Mapping[str, BoundarySample],
                     end: Mapping[str, BoundarySample]) -> None:
        self.win_t[:] = (self.t, t1)
        for side in self.open_sides:
            b = SIDES.index(side)
            for lv, s in enumerate((start[side], end[side])):
                self.win_u[b, lv] = s.u
                self.win_w[b, lv] = s.w
                self.win_eta[b, lv] = s.eta
                self.win_etag[b, lv] = s.gauge_eta

    # ---------------------------------------------------------------- driving
    def advance_to(self, t_end: float,
                   progress: Callable[[Simulation], None] | None = None) -> None:
        """Advance to ``t_end`` [s] in windows of ``self.window``, sampling every source at each
        window end (sides without a source keep the data of the last window)."""
        if not math.isfinite(t_end):
            raise ValueError(f"t_end: must be finite, got {t_end}")
        eps = 1e-9 * self.window
        while self.t < t_end - eps:
            t1 = min(self.t + self.window, t_end)
            if t_end - t1 < eps:
                t1 = t_end
            self.advance_window(t1, progress=progress)

    def advance_window(self, t1: float, left: BoundarySample | None = None,
                       right: BoundarySample | None = None,
                       progress: Callable[[Simulation], None] | None = None) -> None:
        """Advance one coupling window to ``t1`` with the data at t1 of each open end (given, or
        sampled from that side's source); raises BoundaryDataError (state untouched) or
        UnstableError."""
        if not (math.isfinite(t1) and t1 > self.t):
            raise ValueError(f"t1: must be finite and after t = {self.t}, got {t1}")
        if self.status == "unstable":
            raise RuntimeError("advance_window: the run is unstable; restore a checkpoint first")
        given = {"left": left, "right": right}
        end: dict[str, BoundarySample] = {}
        try:
            for side in SIDES:
                s = given[side]
                if side not in self.open_sides:
                    if s is not None:
                        raise BoundaryDataError(f"{side}: the flume has no open boundary there")
                    continue
                if s is None:  # the side's source, else the data of the last window held
                    last = self._samples[side]
                    s = (self.sources[side].sample(t1) if side in self.sources
                         else BoundarySample(t1, last.u, last.w, last.eta, last.eta_gauge))
                end[side] = validate_sample(s, self.nodes[side], self.swl, where=side)
                if abs(end[side].t - t1) > 1e-9 * max(1.0, abs(t1)):
                    raise BoundaryDataError(f"{side}.t: sample at t = {end[side].t} for a window "
                                            f"ending at {t1}")
        except BoundaryDataError as exc:
            self.status = "failed"
            if self.writer:
                self.writer.update_meta(**self._meta_fields(), cause=f"boundary data: {exc}")
            raise
        self._load_window(t1, self._samples, end)
        self._advance_recording(t1, progress)
        self._samples = end

    def _run_until(self, t_stop: float) -> None:
        ps = self.particles
        tic = time.perf_counter()
        t, dt, steps, status, swapped, n_flag, vmax, n = ob.advance_open(
            *self._arrays(), ps.n, ps.capacity, self.prm, self.grid.ncx, self.grid.ncz,
            self.t, self.dt, t_stop, STEPS_PER_CALL, self.obp, self.zn, self.win_t, self.win_u,
            self.win_w, self.win_eta, self.win_etag, self.eta_meas, self.counters, self._next_id)
        self.wall_time += time.perf_counter() - tic
        if swapped:
            self._swap()
        ps.n = int(n)
        ps.next_id = int(self._next_id[0])
        self.t, self.dt, self.steps, self.v_max = float(t), float(dt), self.steps + steps, vmax
        if status == ob.ST_CAPACITY:
            self.status = "unstable"
            cause = (f"{ob.STATUS_TEXT[status]}: {ps.capacity} slots; more fluid entered than "
                     "left (build the flume with a larger spare)")
            if self.writer:
                self.writer.update_meta(**self._meta_fields(), cause=cause,
                                        unstable_step=self.steps, unstable_t=self.t)
            raise UnstableError(self.steps, self.t, cause)
        if status not in (wcsph.ST_REACHED_T, wcsph.ST_STEP_LIMIT):
            self._stopped(status, n_flag)

    # ---------------------------------------------------------------- readings
    def boundary_gauges(self) -> dict[str, float | None]:
        """Elevation [m above still water] at each open end's gauge, from the last step; None if
        dry or not measured yet."""
        out: dict[str, float | None] = {}
        for side in self.open_sides:
            v = self.eta_meas[SIDES.index(side)]
            out[side] = float(v) if math.isfinite(v) else None
        return out

    def boundary_counts(self) -> dict[str, dict[str, int]]:
        """Per open end: particles that became fluid (``in``), fluid that left (``out``), buffer
        particles created and removed, since the start."""
        return {side: dict(zip(("in", "out", "created", "removed"),
                               (int(v) for v in self.counters[SIDES.index(side)])))
                for side in self.open_sides}

    def _meta_fields(self) -> dict[str, Any]:
        meta = super()._meta_fields()
        if hasattr(self, "counters"):
            meta["open_boundaries"] = self.boundary_counts()
        return meta

    # ---------------------------------------------------------------- checkpoints
    def checkpoint(self) -> FlumeCheckpoint:  # type: ignore[override]
        return FlumeCheckpoint(super().checkpoint(), self.eta_meas.copy(), self.counters.copy(),
                               dict(self._samples))

    def restore(self, c: FlumeCheckpoint) -> None:  # type: ignore[override]
        super().restore(c.particles)
        self._next_id[0] = self.particles.next_id
        self.eta_meas[:] = c.eta_meas
        self.counters[:] = c.counters
        self._samples = dict(c.samples)


def buffer_pressure(o: OpenBoundary) -> str:
    """How the buffer of open end ``o`` gets its pressure: ``hydrostatic`` or ``extrapolated``."""
    if o.pressure is not None:
        return o.pressure
    return OUTLET_PRESSURE if o.elevation == "extrapolated" else "hydrostatic"


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
