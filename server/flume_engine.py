"""The coupled engine over an sph_core Simulation with open ends: what a coupling client actually drives.

Protocol view of the flume (PROTOCOL.md):
- nodes: every open end's z levels, the left end first; x = the end's face, z up from the
  still-water level, side 0 = left end (the inlet), 1 = right end (the outlet).
- SET u, w at the nodes become the end's velocity profile at t1; eta (equal at the nodes of one
  end, which share their x) becomes the end's target elevation. The flume interpolates linearly
  in time inside the window, from the values in force at t0 (seed 001, Algorithm 2).
- zone nodes (protocol 1.2, ZONE_NODES; an ISPH scene with relaxation zones): the nodes, then
  per open end its zone's columns (the face's z levels at each x, side 2 + end): u, w there
  become the zone's local targets (sph_core.open_ends, ``advance_window(zone=...)``); eta there
  is not used. A SET of the face nodes alone leaves the zones pulling towards the face's profile.
- gauges: each open end's boundary gauge (`left_boundary`, `right_boundary`, measured by the
  flume at x_gauge) then the scene's elevation probes; u_ref, w_ref at z_ref below still water
  at each gauge's x come from point probes the engine adds to its copy of the scene.
"""

from __future__ import annotations

import math
import threading
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from protocol import NO_GAUGE, ErrorCode, GaugeKind, ProtocolError
from sph_core.boundary_data import BoundaryDataError, BoundarySample
from sph_core.checkpoint_file import load_checkpoint, save_checkpoint
from sph_core.open_ends import SIDES
from sph_core.scene import PointProbe, Scene
from sph_core.simulation import Simulation

from .engine import EngineNodes, Measurement, SceneSummary, SolveCancelled
from .schemas import RunRequest
from .store import fresh_path  # sph/, then sph.1/ ... for resumed sessions

REF = "_ref"  # suffix of the point probes the engine adds at z_ref
CANCEL_GRACE_S = 2.0  # [s] of solving before a cancelled run's window is cut


def ref_scene(scene: Scene, z_ref: float) -> tuple[Scene, list[str], list[float]]:
    """The scene with a point probe at (gauge x, still water + z_ref) per gauge; gauge names, x."""
    swl = float(scene.still_water_level)
    t = scene.tank
    names, xs = [], []
    for o in scene.open_boundaries:
        off = o.gauge_offset if o.gauge_offset is not None else 2.0 * scene.h
        names.append(f"{o.side}_boundary")
        xs.append(t.x0 + off if o.side == "left" else t.x1 - off)
    for p in scene.probes:
        if p.kind == "elevation":
            names.append(p.name)
            xs.append(p.x)
    extra = [PointProbe(kind="point", name=f"{n}{REF}", x=x, z=swl + z_ref) for n, x in zip(names, xs)]
    return scene.model_copy(update={"probes": [*scene.probes, *extra]}), names, xs


class FlumeEngine:
    """CouplingEngine (server/engine.py) of a scene with open boundaries."""

    def __init__(self, request: RunRequest, run_dir: Path | None) -> None:
        scene = request.scene
        if not scene.open_boundaries:
            raise ValueError("scene.open_boundaries: a coupled run needs at least one open end")
        swl = float(scene.still_water_level)
        depth = swl - scene.tank.z0
        z_ref = request.coupling.z_ref if request.coupling.z_ref is not None else -0.5 * depth
        if not -depth < z_ref <= 0:
            raise ValueError(f"coupling.z_ref: {z_ref} m is not in the water column (-{depth}, 0]")
        sim_scene, self.gauge_names, gauge_x = ref_scene(scene, z_ref)
        self.flume = Simulation(sim_scene, run_dir=None if run_dir is None else fresh_path(Path(run_dir), "sph"),
                                window=request.coupling.window_max)
        f = self.flume
        self.sides = [s for s in SIDES if s in f.open_sides]
        self._slices: dict[str, slice] = {}
        xs, zs, side_ids, k = [], [], [], 0
        for s in self.sides:
            nd = f.nodes[s]
            self._slices[s] = slice(k, k + nd.size)
            k += nd.size
            xs.append(np.full(nd.size, nd.x_face))
            zs.append(nd.z - swl)
            side_ids.append(np.full(nd.size, SIDES.index(s), dtype=np.uint32))
        boundary = [n.endswith("_boundary") for n in self.gauge_names]
        absorbs = {o.side: o.absorb for o in scene.open_boundaries}
        eta_gauge = tuple(self.gauge_names.index(f"{s}_boundary") if absorbs.get(s) else NO_GAUGE
                          for s in SIDES)
        self._nodes = EngineNodes(np.concatenate(xs), np.concatenate(zs), np.concatenate(side_ids),
                                  np.array(gauge_x), list(self.gauge_names),
                                  np.where(boundary, GaugeKind.BOUNDARY, GaugeKind.PROBE).astype(np.uint32),
                                  eta_gauge)
        self._zone_nodes: EngineNodes | None = None
        self._zone_slices: dict[str, tuple[slice, int]] = {}   # side -> (slice, columns)
        cols = f.zone_columns
        if cols:
            zx, zz, zside = [self._nodes.x], [self._nodes.z], [self._nodes.side]
            for s in self.sides:
                nd, c = f.nodes[s], cols[s]
                self._zone_slices[s] = (slice(k, k + c.size * nd.size), c.size)
                k += c.size * nd.size
                zx.append(np.repeat(c, nd.size))
                zz.append(np.tile(nd.z - swl, c.size))
                zside.append(np.full(c.size * nd.size, 2 + SIDES.index(s), dtype=np.uint32))
            self._zone_nodes = replace(self._nodes, x=np.concatenate(zx), z=np.concatenate(zz),
                                       side=np.concatenate(zside))
        self.summary = SceneSummary(g=scene.constants.g, depth=depth, still_water_level=swl,
                                    z_ref=z_ref, t_start=f.t, t_end=scene.t_end, dt_sph=f.dt)
        # t0, t1, each end's sample at t1, each zone's (u, w)[column, node] at t1
        self._window: tuple[float, float, dict[str, BoundarySample],
                            dict[str, tuple[np.ndarray, np.ndarray]]] | None = None
        self._saved = None
        self._window_steps = 0
        self.cancel: threading.Event | None = None  # the run's cancel flag (server/engine.py)
        self.cancel_grace = CANCEL_GRACE_S
        self._solve_started = 0.0

    # -- clock and size --------------------------------------------------------------------
    @property
    def t(self) -> float:
        return self.flume.t

    @property
    def steps(self) -> int:
        return self.flume.steps

    @property
    def n_particles(self) -> int:
        return self.flume.n_particles

    # -- contract --------------------------------------------------------------------------
    def nodes(self) -> EngineNodes:
        return self._nodes

    def zone_nodes(self) -> EngineNodes | None:
        """The nodes followed by the relaxation zones' columns (None: the scene has no zones)."""
        return self._zone_nodes

    def set_window(self, t0: float, t1: float, u: np.ndarray, w: np.ndarray, eta: np.ndarray) -> None:
        samples: dict[str, BoundarySample] = {}
        for s in self.sides:
            sl = self._slices[s]
            samples[s] = BoundarySample(t1, np.asarray(u[sl]), np.asarray(w[sl]),
                                        float(np.mean(eta[sl])))
        zone: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        if self._zone_nodes is not None and u.size == self._zone_nodes.x.size:
            for s, (sl, n_cols) in self._zone_slices.items():
                zone[s] = (np.asarray(u[sl]).reshape(n_cols, -1), np.asarray(w[sl]).reshape(n_cols, -1))
        self._window = (t0, t1, samples, zone)

    def solve_window(self) -> Measurement:
        if self._window is None:
            raise RuntimeError("solve_window before set_window")
        _, t1, samples, zone = self._window
        before = self.flume.steps
        self._solve_started = time.perf_counter()
        try:
            self.flume.advance_window(t1, **samples, progress=self._check_cancel, zone=zone)
        except BoundaryDataError as exc:  # the client's data, not our failure
            raise ProtocolError(ErrorCode.BAD_VALUE, f"SET: {exc}") from None
        finally:
            self._window = None
        m = self.measure()
        return Measurement(m.eta, m.wet, m.u_ref, m.w_ref, steps=self.flume.steps - before)

    def _check_cancel(self, _: Simulation) -> None:
        """Called between chunks of steps (sph_core STEPS_PER_CALL) and at each output: a
        cancelled run's window is cut once it has solved ``cancel_grace`` s (a window that ends
        soon ends on its boundary, whose state is saved for resuming)."""
        if (self.cancel is not None and self.cancel.is_set()
                and time.perf_counter() - self._solve_started >= self.cancel_grace):
            raise SolveCancelled()

    def measure(self) -> Measurement:
        values = self.flume.probe_values()
        boundary = self.flume.boundary_gauges()
        n = len(self.gauge_names)
        eta, u, w = np.zeros(n), np.zeros(n), np.zeros(n)
        wet = np.zeros(n, dtype=bool)
        for j, name in enumerate(self.gauge_names):
            side = name.removesuffix("_boundary")
            e = boundary.get(side) if name.endswith("_boundary") else values.get(f"{name}_eta")
            uu, ww = values.get(f"{name}{REF}_u"), values.get(f"{name}{REF}_w")
            if e is not None and math.isfinite(e):
                wet[j], eta[j] = True, e
                u[j] = uu if uu is not None else 0.0
                w[j] = ww if ww is not None else 0.0
        return Measurement(eta, wet, u, w)

    def checkpoint(self) -> None:
        self._saved = self.flume.checkpoint()

    def goback(self) -> None:
        if self._saved is None:
            raise RuntimeError("goback without a checkpoint")
        self.flume.restore(self._saved)
        self._window = None

    def stability(self) -> dict[str, float]:
        f = self.flume
        mass0 = f.fluid_mass0
        return {"dt": f.dt, "v_max": f.v_max, "c0": f.c0, "mach": f.v_max / f.c0 if f.c0 else 0.0,
                "fluid_mass_ratio": f.fluid_mass() / mass0 if mass0 else 1.0}

    def save_state(self, path: Path) -> None:
        # a portable npz (arrays + a JSON tree), never a pickle: sph_core.checkpoint_file
        save_checkpoint(path, self.flume.checkpoint())

    def load_state(self, path: Path) -> None:
        self.flume.restore(load_checkpoint(path))
        self.summary = replace(self.summary, t_start=self.flume.t)

    def close(self) -> None:
        self.flume.close()


def flume_engine(request: RunRequest, run_dir: Path) -> FlumeEngine:
    """The server's default engine factory for coupled runs."""
    return FlumeEngine(request, run_dir)
