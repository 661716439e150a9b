"""A Simulation owns the particles, the clock, the open ends, the probes and the run directory.

    sim = Simulation(scene, run_dir=None)   # run_dir: CSV probes, VTK snapshots, meta.json
    sim = Simulation(scene, sources={"left": src}, window=0.02)   # a scene with open ends
    sim.advance_to(t_end, progress=None)    # raises UnstableError(step, t, cause)
    sim.advance_window(t1, left=sample, right=sample)   # open ends driven from outside
    sim = Simulation(scene, device="cuda")  # the step on a GPU (default: the scene's [run] device)
    sim.checkpoint() -> Checkpoint; sim.restore(c)   # exact state copy (protocol `goback`)
    sim.probe_values() -> dict[str, float | None]    # configured probes at the current state
    sim.boundary_gauges(); sim.boundary_counts()     # open ends (empty for a closed tank)

Every scene runs the same loop: the open inlet/outlet ends are a value (``self.open``, an
``open_ends.OpenBoundaries``: named constructors ``from_scene`` / ``closed``), and the time loop
is one call of the scheme's stepper (``self.stepper``, steppers.py: ``WcsphStepper`` runs the
jitted ``step.run``; ``isph.IsphStepper`` a Python loop over jitted passes around a sparse
pressure solve, with the same returns and the same open-end hooks) up to the next output time
(and, with open ends, the next window end); the stepper also makes the run's Params and initial
state. Python only handles boundary data, probes, snapshots, metadata and the progress callback.

With ``device = "cuda"`` the time loop is ``sph_core.cuda.cuda_stepper.CudaStepper``'s instead:
the particles stay on the GPU while it steps and come back to the host (``to_host``: the live
buffer, the cell starts, the clock) after every call of the loop, i.e. at each output time and
before control returns to the caller, so the probes, writers, guards and checkpoints below run
unchanged on host arrays; what the host changes (particles excluded after a guard, a restored
checkpoint, new gravity) goes back with ``from_host``. A device that cannot take the run (no
GPU, a feature the GPU step lacks: ``cuda_stepper.unsupported``) raises ``DeviceError`` (one
line) before the run directory is written.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any, Callable, Mapping

import numba
import numpy as np

from . import wcsph
from .bodies import BodyLog, BodySet
from .boundary_data import BoundaryData, BoundaryDataError, BoundarySample
from .eos import tait_b
from .geometry import buffer_layers, build_layout
from .geometry3d import build_layout_3d
from .kernels import w_of_q, wendland_alpha
from .neighbours import CellGrid, compute_cells, counting_sort
from .load_probes import LoadProbes
from .open_boundary import INLET_IDLE
from .open_ends import OpenBoundaries, buffer_widths
from .output import RunWriter
from .particles import (FLUID, INACTIVE, M, P, RHO, VX, VY, VZ, WALL, X, Y, Z, Checkpoint,
                        ParticleSet)
from .probes import (fluid_neighbour_counts, interpolate_points, line_mass_density,
                     shoreline, surface_from_line)
from .shifting import SHIFT_OPEN_END
from .scene import DEVICES, ElevationProbe, FrontProbe, PointProbe, RunupProbe, Scene
from .state import Params
from .steppers import Stepper, WcsphStepper, make_stepper

STEPS_PER_CALL = 200  # steps per jitted call between progress callbacks
# cells per kernel support radius 2h (neighbours.py): 2 = cells of side h, a 5 x 5 search block
CELLS_PER_SUPPORT = 2


__all__ = ["DeviceError", "Simulation", "UnstableError"]


class DeviceError(ValueError):
    """The chosen device cannot run this scene here (no GPU, or a feature its step lacks); the
    message is one line that names the reason."""


class UnstableError(RuntimeError):
    """The run became unstable; ``step``, ``t`` and ``cause`` say when and why."""

    def __init__(self, step: int, t: float, cause: str) -> None:
        super().__init__(f"unstable at step {step}, t = {t:.6g} s: {cause}")
        self.step = step
        self.t = t
        self.cause = cause


class Simulation:
    """SPH run of one scene (WCSPH, or ISPH with ``[scheme] kind = "isph"``); see the module
    docstring for the contract.

    ``sources`` (side -> BoundaryData) and ``window`` [s] apply to scenes with open ends;
    ``spare`` is the spare particle capacity (default 0.1, 0.3 with open ends: inflow);
    ``cells_per_support`` sets the neighbour cells' side, 2h / cells_per_support;
    ``device`` ("cpu" or "cuda", default the scene's ``[run] device``) where the steps run."""

    def __init__(self, scene: Scene, run_dir: str | Path | None = None,
                 spare: float | None = None, sources: Mapping[str, BoundaryData] | None = None,
                 window: float = 0.02, cells_per_support: int = CELLS_PER_SUPPORT,
                 device: str | None = None) -> None:
        if device is not None and device != scene.run.device:
            if device not in DEVICES:
                raise DeviceError(f"device: {device!r} is not one of {', '.join(DEVICES)}")
            # the scene records the device the run used (meta.json)
            run = scene.run.model_copy(update={"device": device})
            scene = scene.model_copy(update={"run": run})
        self.device = scene.run.device
        if self.device == "cuda":   # before anything is built: the cheap refusal first
            from .cuda import unavailable_reason
            reason = unavailable_reason()
            if reason is not None:
                raise DeviceError(f"device cuda: {reason}")
        self.scene = scene
        c = scene.constants
        # an open end's buffer: the scene's width, at least the walls' layers
        buffers = {side: buffer_layers(scene, w) for side, w in buffer_widths(scene).items()}
        layout = (build_layout(scene, buffers) if scene.dim == 2
                  else build_layout_3d(scene, buffers))
        dp, h = scene.dp, scene.h
        self.h = h
        self.c0 = scene.c0
        self.b = tait_b(c.rho0, self.c0)
        self.open = OpenBoundaries.from_scene(scene, sources, window)
        if spare is None:
            spare = 0.3 if self.open.active else 0.1
        # rigid bodies: their particles replace the fluid inside them
        self.bodies = BodySet(scene, layout.n_layers * dp)
        if self.bodies.active:
            keep = self.bodies.fluid_outside(layout.fluid_x, layout.fluid_z, dp)
            layout.fluid_x, layout.fluid_z = layout.fluid_x[keep], layout.fluid_z[keep]
            layout.fluid_surface = layout.fluid_surface[keep]
        n = layout.wall_x.size + layout.fluid_x.size + self.bodies.x.size
        self.particles = ps = ParticleSet(max(int(n * (1.0 + spare)), n + 1),
                                          np.float32 if c.precision == "float32" else np.float64)
        # the scheme: its Params, initial state and time loop (steppers.py)
        self.stepper: Stepper = make_stepper(scene, ps.capacity, self.open.zone)
        self.dim = scene.dim
        vol = dp ** scene.dim
        flat = scene.dim == 2
        ps.add(layout.wall_x, layout.wall_z, WALL, np.full(layout.wall_x.size, c.rho0),
               np.full(layout.wall_x.size, c.rho0 * vol), y=0.0 if flat else layout.wall_y)
        # mass = rho * dp^dim: the particle volume is exactly dp^2 (3D: dp^3)
        rho_f, p_f = self.stepper.initial_fluid(layout.fluid_z, layout.fluid_surface)
        ps.add(layout.fluid_x, layout.fluid_z, FLUID, rho_f, rho_f * vol,
               y=0.0 if flat else layout.fluid_y)
        if p_f is not None:
            ps.f[P, ps.n - rho_f.size: ps.n] = p_f
        self.bodies.attach(ps, c.rho0, dp)
        self.n_layers = layout.n_layers
        self.open.attach(ps, scene, self.b, {side: k * dp for side, k in buffers.items()})
        t = scene.tank
        wall = layout.n_layers * dp
        yr = {} if flat else dict(y0=t.y0 - wall, y1=t.y1 + wall)
        wx0 = buffers.get("left", layout.n_layers) * dp
        wx1 = buffers.get("right", layout.n_layers) * dp
        self.grid = CellGrid.covering(t.x0 - wx0, t.x1 + wx1, t.z0 - wall, t.z1, 2.0 * h,
                                      reach=cells_per_support, **yr)
        self.cells = self.grid.lists(ps.capacity)
        aw = wendland_alpha(h, scene.dim)
        # a fluid particle whose centre passes the first dummy layer (dp/2 behind the wall face)
        # has gone through the wall; the top z1 is open
        fx0, fx1 = self.open.fluid_box(t.x0 - 0.5 * dp, t.x1 + 0.5 * dp, dp)
        lo, hi = c.density_band
        # the scheme-neutral Params; the stepper adds its scheme's (viscosity, Courant number,
        # shifting law, wall shares, flux)
        base = dict(h=h, alpha_w=aw, alpha_f=5.0 * aw / (h * h), rho0=c.rho0, c0=self.c0,
                    b=self.b, gamma=7.0, gx=0.0, gz=-c.g, nu=c.nu, delta=c.delta,
                    rho_lo=lo, rho_hi=hi, noslip=c.wall_slip == "no_slip", fx0=fx0, fx1=fx1,
                    fz0=t.z0 - 0.5 * dp, fz1=t.z1, alpha_wall=c.alpha_wall_factor,
                    shift_fs_div=c.shift_fs_div, shift_inv_wdp=1.0 / w_of_q(dp / h, aw),
                    shift_open=SHIFT_OPEN_END[c.shift_open_end])
        if not flat:   # the y walls' first layers, as fx0, fx1 for the x walls
            base.update(fy0=t.y0 - 0.5 * dp, fy1=t.y1 + 0.5 * dp, three=True)
        self.stepper.params(scene, base, layout.n_layers)
        self.passes_per_step = self.stepper.passes_per_step
        self._counts = np.zeros(ps.capacity, dtype=np.int64)
        dt, n_new = self.stepper.initialise(ps.view, ps.view2, self.cells, self.open.ends,
                                            self.bodies.state, ps.n)
        self.dt = float(dt)
        ps.swap()
        ps.n = int(n_new)
        self.t = scene.t_start
        self.open.start(self.t)
        self.steps = 0
        self.wall_time = 0.0
        self.v_max = 0.0
        self.fluid_mass0 = self.fluid_mass()
        self.n_fluid0 = self.n_fluid
        self.excluded: list[dict[str, Any]] = []  # particles removed: density band, left the tank
        self._gpu: Any = None   # the CudaStepper of device "cuda"
        if self.device == "cuda":
            self._gpu = self._cuda_stepper()
        # probes
        self._points = [p for p in scene.probes if isinstance(p, PointProbe)]
        self._elev = [p for p in scene.probes if isinstance(p, ElevationProbe)]
        self._fronts = [p for p in scene.probes if isinstance(p, FrontProbe)]
        self._runups = [p for p in scene.probes if isinstance(p, RunupProbe)]
        self._runup_max: dict[str, float | None] = {p.name: None for p in self._runups}
        self._beds = [list(b.points) for b in scene.beds]
        self._px = np.array([p.x for p in self._points], dtype=float)
        self._pz = np.array([p.z for p in self._points], dtype=float)
        self._px0, self._pz0 = self._px.copy(), self._pz.copy()   # at t_start (follow)
        self._py = np.array([p.y for p in self._points], dtype=float)
        self._pout = np.zeros((len(self._points), 5))
        self.loads = LoadProbes(scene)  # force, pressure_line, overtopping
        nz = int(math.floor((t.z1 - t.z0) / (0.5 * dp)))
        self._line_z = t.z0 + (np.arange(nz) + 0.5) * 0.5 * dp
        self._line_rho = np.zeros(self._line_z.size)
        self.history: list[dict[str, float | None]] = []
        self.body_history: list[dict[str, float]] = []  # on the probe cadence (bodies.csv)
        self._k_probe = 0
        self._k_snap = 0
        self.status = "created"
        self.writer: RunWriter | None = None
        if run_dir is not None:
            self.writer = RunWriter(run_dir, self.probe_columns(), scene.model_dump(mode="json"))
            self.writer.update_meta(**self._meta_fields())
            if self.bodies.active:
                self.bodies.log = BodyLog(run_dir, self.bodies.columns())
                self.writer.update_meta(bodies=self.bodies.properties)
        self._record_outputs()

    def _cuda_stepper(self) -> Any:
        """The GPU step for this run, or DeviceError naming what stops it."""
        from .cuda import device_name, simulated
        from .cuda.cuda_stepper import CudaStepper, unsupported

        missing = unsupported(self)
        if missing:
            raise DeviceError("device cuda: not supported yet: " + ", ".join(missing)
                              + " (run it with device cpu)")
        try:
            gpu = CudaStepper(self)
        except Exception as exc:   # device memory, a driver error: one line, no run directory
            first = str(exc).splitlines()[0] if str(exc) else repr(exc)
            raise DeviceError(f"device cuda: {first}") from exc
        self._gpu_name = device_name()
        # two-step CUDA graphs, captured after the first call compiled the kernels (a GPU only)
        self._gpu_graphs = not simulated()
        return gpu

    def _pull(self) -> None:
        """The device's state into the host arrays (after each call of the GPU's loop)."""
        if self._gpu is not None:
            self._gpu.to_host()

    def _push(self) -> None:
        """The host's state onto the device (after the host changed it)."""
        if self._gpu is not None:
            self._gpu.from_host()

    # ---------------------------------------------------------------- state access
    @property
    def prm(self) -> Params:
        """The run's Params (the stepper's)."""
        return self.stepper.prm

    @prm.setter
    def prm(self, value: Params) -> None:
        self.stepper.prm = value

    @property
    def nodes(self) -> dict:
        """BoundaryNodes of each open end (where a source gives u, w)."""
        return self.open.nodes

    @property
    def open_sides(self) -> tuple[str, ...]:
        return self.open.sides

    @property
    def zone_columns(self) -> dict[str, np.ndarray]:
        """side -> x [m] of the columns inside ISPH's relaxation zones where ``advance_window``
        takes local targets (the face's nodes' heights); empty without zones."""
        return self.open.zone_columns()

    @property
    def window(self) -> float:
        """Coupling window [s] of the open ends (advance_to samples the sources at its ends)."""
        return self.open.window

    @property
    def n_particles(self) -> int:
        """Particles in use (fluid + wall + buffers)."""
        return int(np.count_nonzero(self.particles.kind[: self.particles.n] >= 0))

    @property
    def n_fluid(self) -> int:
        return self.particles.count(FLUID)

    def fluid_mass(self) -> float:
        ps = self.particles
        return float(ps.field(M)[ps.mask(FLUID)].sum())

    def fluid_state(self) -> dict[str, np.ndarray]:
        """Copies of the fluid particles' fields, ordered by particle id (y, vy: zero in 2D)."""
        ps = self.particles
        sel = ps.mask(FLUID)
        order = np.argsort(ps.ids[: ps.n][sel])
        out = {name: ps.field(row)[sel][order].copy() for name, row in
               (("x", X), ("y", Y), ("z", Z), ("vx", VX), ("vy", VY), ("vz", VZ), ("rho", RHO),
                ("p", P), ("m", M))}
        out["id"] = ps.ids[: ps.n][sel][order].copy()
        return out

    # ---------------------------------------------------------------- probes
    def probe_columns(self) -> list[str]:
        cols: list[str] = []
        for p in self._points:
            cols += [f"{p.name}_u", f"{p.name}_w", f"{p.name}_p"]
            if self.dim == 3:
                cols.append(f"{p.name}_v")
        for p in self._elev:
            cols.append(f"{p.name}_z_surface")
            if self.scene.still_water_level is not None:
                cols.append(f"{p.name}_eta")
        for p in self._fronts:
            cols.append(f"{p.name}_x")
        for p in self._runups:
            cols += [f"{p.name}_x", f"{p.name}_z", f"{p.name}_R"]
        return cols + self.loads.columns()

    def probe_values(self) -> dict[str, float | None]:
        """Configured probes at the current state [SI]; None marks a dry probe."""
        ps = self.particles
        aw = self.prm.alpha_w
        out: dict[str, float | None] = {}
        if self._points:
            for k, p in enumerate(self._points):
                if p.follow:
                    x, z = self.bodies.follow(p.follow, self._px0[k:k + 1], self._pz0[k:k + 1])
                    self._px[k], self._pz[k] = x[0], z[0]
            interpolate_points(ps.view, self.cells, self._px, self._py, self._pz, self.h, aw,
                               self._pout)
            for k, p in enumerate(self._points):
                wet = self._pout[k, 3] > 0.05
                # interpolate_points' columns: u, w, p, (sum V W), v
                for suffix, j in (("u", 0), ("w", 1), ("p", 2), ("v", 4))[: 4 if self.dim == 3 else 3]:
                    out[f"{p.name}_{suffix}"] = float(self._pout[k, j]) if wet else None
        rho0 = self.scene.constants.rho0
        for p in self._elev:
            line_mass_density(ps.view, self.cells, float(p.x), float(p.y), self._line_z, self.h, aw,
                              self._line_rho)
            zs = surface_from_line(self._line_z, self._line_rho, p.threshold * rho0)
            out[f"{p.name}_z_surface"] = zs
            swl = self.scene.still_water_level
            if swl is not None:
                out[f"{p.name}_eta"] = None if zs is None else zs - swl
        if self._fronts or self._runups:
            fluid_neighbour_counts(ps.view, ps.n, self.cells, self.h, self._counts)
            counts = self._counts[: ps.n]
            x = ps.field(X)
            for p in self._fronts:
                sel = counts >= p.min_neighbours
                out[f"{p.name}_x"] = float(x[sel].max()) if sel.any() else None
            for p in self._runups:
                s = shoreline(x, ps.field(Z), counts, p.min_neighbours, self._beds,
                              self.scene.tank.z0, p.near_bed)
                r = self._runup_max[p.name]
                if s is not None:
                    rise = s[1] - float(self.scene.still_water_level)
                    r = rise if r is None else max(r, rise)
                    self._runup_max[p.name] = r
                out[f"{p.name}_x"] = None if s is None else s[0]
                out[f"{p.name}_z"] = None if s is None else s[1]
                out[f"{p.name}_R"] = r
        if self.loads:
            out.update(self.loads.values(self.particles, self.cells, self.prm, self.t,
                                         self.bodies))
        return out

    # ---------------------------------------------------------------- outputs
    def _meta_fields(self) -> dict[str, Any]:
        return {"status": self.status, "t": self.t, "steps": self.steps,
                "wall_time_s": round(self.wall_time, 3), "dt": self.dt,
                "n_particles": self.n_particles, "n_fluid": self.n_fluid,
                "excluded": len(self.excluded), "excluded_particles": self.excluded[-20:],
                "c0": self.c0, "h": self.h, "integrator": self.scene.constants.integrator,
                "scheme": self.scene.scheme.kind,
                **self.stepper.stats(),
                "passes_per_step": self.passes_per_step, "threads": numba.get_num_threads(),
                "device": self.device,
                **({"gpu": self._gpu_name, "cuda_graphs": self._gpu._graph is not None}
                   if self._gpu is not None else {}),
                "particle_steps_per_s": (self.n_particles * self.steps / self.wall_time
                                         if self.wall_time > 0 else None),
                **({"open_boundaries": self.boundary_counts()} if self.open.active else {})}

    def _record_outputs(self) -> None:
        """Probes and snapshots whose time has come (t = k * cadence)."""
        o = self.scene.output
        eps = 1e-9 * max(self.dt, 1e-12)
        if o.probe_every > 0 and self.t >= self._k_probe * o.probe_every - eps:
            values = self.probe_values()
            self.history.append({"t": self.t, **values})
            if self.writer:
                self.writer.probe_row(self.t, self.steps, values)
            if self.bodies.active:
                rows = self.bodies.rows()
                self.body_history.append({"t": self.t, **rows})
                if self.bodies.log:
                    self.bodies.log.row(self.t, self.steps, rows)
            self._k_probe = int(math.floor(self.t / o.probe_every + 1e-6)) + 1
        if self.writer and o.snapshot_every > 0 and self.t >= self._k_snap * o.snapshot_every - eps:
            self.write_snapshot()
            self._k_snap = int(math.floor(self.t / o.snapshot_every + 1e-6)) + 1

    def write_snapshot(self) -> None:
        if self.writer is None:
            raise RuntimeError("write_snapshot: this simulation has no run_dir")
        ps = self.particles
        # idle open-end buffer particles (kinds INLET_IDLE, OUTLET_IDLE: above the end's surface,
        # held in place, in no pass) are left out: in ParaView and the page they hung in the air
        sel = (ps.kind[: ps.n] >= 0) & (ps.kind[: ps.n] < INLET_IDLE)
        fld = {name: ps.field(row)[sel] for name, row in
               (("rho", RHO), ("pressure", P), ("vx", VX), ("vy", VY), ("vz", VZ))}
        if self.dim == 2:
            del fld["vy"]
        fld["kind"] = ps.kind[: ps.n][sel].astype(np.int32)
        fld["id"] = ps.ids[: ps.n][sel].astype(np.int64)
        vy = ps.field(VY)[sel]
        fld["speed"] = np.sqrt(fld["vx"] ** 2 + vy ** 2 + fld["vz"] ** 2)
        fld["velocity"] = (fld["vx"], vy, fld["vz"])  # a vector for glyphs
        fld["mass"] = ps.field(M)[sel]
        fld["h"] = np.full(fld["mass"].size, self.h)
        fld["body"] = self.bodies.particle_body(fld["id"])  # -1: not a body particle
        self.writer.snapshot(self.t, ps.field(X)[sel], ps.field(Z)[sel], fld, y=ps.field(Y)[sel])

    def _next_output_time(self, t_target: float) -> float:
        o = self.scene.output
        t_next = t_target
        if o.probe_every > 0:
            t_next = min(t_next, self._k_probe * o.probe_every)
        if self.writer and o.snapshot_every > 0:
            t_next = min(t_next, self._k_snap * o.snapshot_every)
        return t_next

    # ---------------------------------------------------------------- time loop
    def advance_to(self, t_end: float, progress: Callable[["Simulation"], None] | None = None) -> None:
        """Advance to time ``t_end`` [s], recording outputs on their cadence; with open ends in
        windows of ``self.window``, sampling every source at each window end (sides without a
        source keep the data of the last window).

        Raises UnstableError (status ``unstable`` in meta.json) if the guard trips; the outputs
        written so far stay on disk."""
        if not math.isfinite(t_end):
            raise ValueError(f"t_end: must be finite, got {t_end}")
        if self.status == "unstable":
            raise RuntimeError("advance_to: the run is unstable; restore a checkpoint first")
        if not self.open.active:
            self._advance_recording(t_end, progress)
            return
        eps = 1e-9 * self.window
        while self.t < t_end - eps:
            t1 = min(self.t + self.window, t_end)
            if t_end - t1 < eps:
                t1 = t_end
            self.advance_window(t1, progress=progress)

    def advance_window(self, t1: float, left: BoundarySample | None = None,
                       right: BoundarySample | None = None,
                       progress: Callable[["Simulation"], None] | None = None,
                       zone: Mapping[str, tuple[np.ndarray, np.ndarray]] | None = None) -> None:
        """Advance one coupling window to ``t1`` with the data at t1 of each open end (given, or
        sampled from that side's source); ``zone``: side -> (u, w)[column, node] at t1 at the
        columns ``zone_columns`` of ISPH's relaxation zones (their local targets; omitted, a
        zone pulls towards its face's profile). Raises BoundaryDataError (state untouched) or
        UnstableError."""
        if not (math.isfinite(t1) and t1 > self.t):
            raise ValueError(f"t1: must be finite and after t = {self.t}, got {t1}")
        if self.status == "unstable":
            raise RuntimeError("advance_window: the run is unstable; restore a checkpoint first")
        try:
            end = self.open.end_samples(t1, {"left": left, "right": right})
            zone_end = self.open.check_zone_data(end, zone or {})
        except BoundaryDataError as exc:
            self.status = "failed"
            if self.writer:
                self.writer.update_meta(**self._meta_fields(), cause=f"boundary data: {exc}")
            raise
        self.open.load_window(self.t, t1, end, zone_end)
        if self._gpu is not None:
            self._gpu.load_window()     # the window's boundary data to the device
        self._advance_recording(t1, progress)
        self.open.samples = end

    def _advance_recording(self, t_end: float,
                           progress: Callable[["Simulation"], None] | None) -> None:
        """Step to each output time, record, report, and keep meta.json honest on any way out
        (UnstableError, Ctrl-C, a bug)."""
        self.status = "running"
        try:
            while self.t < t_end:
                self._run(self._next_output_time(t_end), STEPS_PER_CALL)
                self._record_outputs()
                if progress is not None:
                    progress(self)
            self.status = "completed" if self.t >= self.scene.t_end else "paused"
        except UnstableError:
            raise
        except BaseException as exc:  # keep the record honest on Ctrl-C or a bug
            self.status = "interrupted" if isinstance(exc, KeyboardInterrupt) else "failed"
            if self.writer:
                self.writer.update_meta(**self._meta_fields(), cause=repr(exc))
            raise
        if self.writer:
            self.writer.update_meta(**self._meta_fields())

    def advance_steps(self, n_steps: int) -> None:
        """Take exactly ``n_steps`` steps without recording outputs (benchmarks, tests)."""
        self._run(math.inf, int(n_steps))

    def _run(self, t_stop: float, max_steps: int) -> None:
        """One call of the stepper's loop up to ``t_stop`` or ``max_steps`` steps."""
        if self._gpu is not None:
            self._run_gpu(t_stop, max_steps)
            return
        ps = self.particles
        ends = self.open.ends
        ends.next_id[0] = ps.next_id
        tic = time.perf_counter()
        t, dt, steps, status, swapped, n_flag, vmax, n = self.stepper.run(
            ps.view, ps.view2, self.cells, ends, self.bodies.state, ps.n, self.t, self.dt,
            t_stop, max_steps)
        self.wall_time += time.perf_counter() - tic
        if swapped:
            ps.swap()
        ps.n = int(n)
        if self.open.active:
            ps.next_id = int(ends.next_id[0])
        self.t, self.dt, self.steps, self.v_max = float(t), float(dt), self.steps + steps, vmax
        self._verdict(status, n_flag)

    def _verdict(self, status: int, n_flag: int) -> None:
        """After a call of either device's loop: fail on a full particle store, exclude or fail
        on a guard (``_stopped``), else carry on."""
        ps = self.particles
        if status == wcsph.ST_CAPACITY:
            self.status = "unstable"
            cause = (f"{wcsph.STATUS_TEXT[status]}: {ps.capacity} slots; more fluid entered than "
                     "left (build the run with a larger spare)")
            if self.writer:
                self.writer.update_meta(**self._meta_fields(), cause=cause,
                                        unstable_step=self.steps, unstable_t=self.t)
            raise UnstableError(self.steps, self.t, cause)
        if status not in (wcsph.ST_REACHED_T, wcsph.ST_STEP_LIMIT):
            self._stopped(status, n_flag)

    def _run_gpu(self, t_stop: float, max_steps: int) -> None:
        """``_run`` on the GPU: the device steps, then its state comes back to the host (with
        open ends: the live count, next id, gauges and counters too)."""
        gpu = self._gpu
        tic = time.perf_counter()
        t, dt, steps, status, n_flag, vmax = gpu.run(t_stop, max_steps)
        self.wall_time += time.perf_counter() - tic
        self._pull()
        self.t, self.dt, self.v_max = float(t), float(dt), float(vmax)
        if self._gpu_graphs and steps > 0 and gpu._graph is None and gpu.graph_error is None:
            gpu.enable_graphs()   # False (reason in graph_error): the plain launches stay
        self._verdict(status, n_flag)

    # ---------------------------------------------------------------- open ends
    def boundary_gauges(self) -> dict[str, float | None]:
        """Elevation [m above still water] at each open end's gauge, from the last step; None if
        dry or not measured yet."""
        return self.open.gauges()

    def boundary_counts(self) -> dict[str, dict[str, int]]:
        """Per open end: particles that became fluid (``in``), fluid that left (``out``), buffer
        particles created and removed, since the start."""
        return self.open.counts()

    def _exclude(self, bad: np.ndarray, ids: np.ndarray, x: np.ndarray, z: np.ndarray,
                 rho: np.ndarray, reason: str) -> bool:
        """Remove the fluid particles ``bad`` (indices into the fluid selection) from the run
        and log them with ``reason``, if the scene's exclude_limit allows; False if it does not."""
        limit = self.scene.constants.exclude_limit * self.n_fluid0
        if bad.size == 0 or len(self.excluded) + bad.size > limit:
            return False
        slots = np.nonzero(self.particles.mask(FLUID))[0][bad]
        self.particles.kind[slots] = INACTIVE  # skipped by every pass, sorted to the end
        self._push()
        self.excluded += [{"id": int(ids[k]), "t": self.t, "step": self.steps, "x": float(x[k]),
                           "z": float(z[k]), "rho": float(rho[k]), "reason": reason} for k in bad]
        if self.writer:
            self.writer.update_meta(**self._meta_fields())
        return True

    def _stopped(self, status: int, n_flag: int) -> None:
        """The jitted loop stopped early: exclude out-of-band particles if the scene allows (the
        caller's loop then goes on), else fail the run as unstable with its cause."""
        ps = self.particles
        sel = ps.mask(FLUID)
        x, z, rho = ps.field(X)[sel], ps.field(Z)[sel], ps.field(RHO)[sel]
        ids = ps.ids[: ps.n][sel]
        cause = wcsph.STATUS_TEXT[status]
        if status == wcsph.ST_DENSITY:
            lo, hi = self.scene.constants.density_band
            rho0 = self.scene.constants.rho0
            bad = np.nonzero((rho < lo * rho0) | (rho > hi * rho0))[0]
            if self._exclude(bad, ids, x, z, rho, "density out of band"):
                return
            cause += f" [{lo}, {hi}] rho0 (after {len(self.excluded)} excluded)"
        elif status == wcsph.ST_LEFT_DOMAIN:
            # a particle thrown over the top or through a wall is removed like one whose density
            # left the band (same log, same exclude_limit): one splash must not end the run
            q = self.prm
            y = ps.field(Y)[sel]
            bad = np.nonzero(~((x >= q.fx0) & (x <= q.fx1) & (z >= q.fz0) & (z <= q.fz1)
                               & (y >= q.fy0) & (y <= q.fy1)))[0]
            if self._exclude(bad, ids, x, z, rho, "left the tank"):
                return
            cause += f" (after {len(self.excluded)} excluded)"
        else:
            v = np.hypot(ps.field(VX)[sel], ps.field(VZ)[sel])
            bad = np.nonzero(~(np.isfinite(v) & np.isfinite(rho)))[0]
        cause += f": {n_flag} particle(s)"
        if bad.size:
            k = bad[0]
            cause += f", e.g. id {ids[k]} at x={x[k]:.4g} z={z[k]:.4g} rho={rho[k]:.6g}"
        self.status = "unstable"
        if self.writer:
            self.writer.update_meta(**self._meta_fields(), cause=cause, unstable_step=self.steps,
                                    unstable_t=self.t)
        raise UnstableError(self.steps, self.t, cause)

    # ---------------------------------------------------------------- checkpoints
    def checkpoint(self) -> Checkpoint:
        """An exact copy of the state (particles, clock, dt, open-end state)."""
        c = self.particles.snapshot(self.t, self.dt, self.steps)
        c.cell = self.particles.cell[: c.n].copy()
        c.cell_start = self.cells.start.copy()
        c.open_state = self.open.state()
        c.body_state = self.bodies.get_state()
        return c

    def restore(self, c: Checkpoint) -> None:
        """Return exactly to a checkpoint; the cell lists are rebuilt for its particle order."""
        ps = self.particles
        ps.restore(c)
        self.t, self.dt, self.steps = c.t, c.dt, c.steps
        self.excluded = [e for e in self.excluded if e["step"] <= c.steps]
        if (c.cell is not None and c.cell_start is not None
                and c.cell_start.size == self.cells.start.size):
            ps.cell[: c.n] = c.cell
            self.cells.start[:] = c.cell_start
        else:
            self._rebuild_cells()
        self.open.set_state(c.open_state)
        self.loads.reset_sides()
        self.bodies.set_state(c.body_state)
        self._push()
        self.status = "paused"
        o = self.scene.output
        self._k_probe = int(math.floor(self.t / o.probe_every + 1e-9)) + 1 if o.probe_every else 0
        self._k_snap = (int(math.floor(self.t / o.snapshot_every + 1e-9)) + 1
                        if o.snapshot_every else 0)

    def _rebuild_cells(self) -> None:
        """Cell lists for the current order without moving particles (for probes after restore)."""
        ps = self.particles
        compute_cells(ps.view, ps.n, self.cells)
        counting_sort(ps.cell, ps.n, self.cells)
        if not np.array_equal(self.cells.order[: ps.n], np.arange(ps.n)):
            # the checkpoint was not taken in cell order (cannot happen for our own checkpoints)
            raise RuntimeError("restore: checkpoint particles are not sorted by cell")

    def close(self) -> None:
        if self.writer:
            self.writer.update_meta(**self._meta_fields())
            self.writer.close()
        if self.bodies.log:
            self.bodies.log.close()

    def set_gravity(self, gx: float, gz: float) -> None:
        """Replace gravity [m/s^2] (z up: the scene's own is (0, -g)) and re-evaluate the rates
        at the current state, as at the start of a run. The particles are kept as they are: a
        caller changing gravity sets the matching density field first. WCSPH only (the ISPH
        stepper holds its own copy of the parameters)."""
        if not isinstance(self.stepper, WcsphStepper):
            raise ValueError("set_gravity: WCSPH runs only (the ISPH stepper keeps its own gravity)")
        ps = self.particles
        self.prm = self.prm._replace(gx=float(gx), gz=float(gz))
        dt, n = self.stepper.initialise(ps.view, ps.view2, self.cells, self.open.ends,
                                        self.bodies.state, ps.n)
        ps.swap()
        ps.n = int(n)
        self.dt = float(dt)
        self._push()
