"""ISPH's stepper: one projection step (``IsphStepper.step``: the passes of passes.py, the
pressure solve of ppe.py, the open-end and body hooks) and the time loop around it."""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from ..bodies import KICK, KICK_DRIFT, bodies_advance, bodies_v2max, body_loads, place_bodies
from ..neighbours import sort_by_cell
from ..open_boundary import (extrapolate_buffers, measure_boundaries, relax_to_source,
                             update_buffers)
from ..particles import FLUID, N_SORTED_KDK, WALL
from ..riemann import NO_RECONSTRUCTION
from ..scene import Scene
from ..shifting import shift_particles
from ..state import Params, ZoneTargets, no_zone_targets
from ..steppers import drive
from ..wcsph import ST_CAPACITY, ST_LEFT_DOMAIN, ST_NONFINITE, ST_REACHED_T
from .passes import correct, free_surface_flags, predict, scatter_pressure, wall_state
from .ppe import MAX_ROW, PPE_SOLVERS, compact_rows, ppe_assemble, ppe_unknowns, solve_ppe


def isph_dt(v2max: float, a2max: float, prm: Any, v_ref: float = 0.0) -> float:
    """dt = min(cfl h / max(|v|_max, v_ref), 0.25 sqrt(h / max|a*|), 0.125 h^2 / nu): no sound
    speed; v_ref is the scene's own speed scale sqrt(2 g H) (Lind et al. 2012 take the step
    from such an a-priori speed)."""
    h = prm.h
    dt = math.inf
    v = max(math.sqrt(v2max), v_ref)
    if v > 0.0:
        dt = prm.cfl * h / v
    if a2max > 0.0:
        dt = min(dt, 0.25 * math.sqrt(h / math.sqrt(a2max)))
    if prm.nu > 0.0:
        dt = min(dt, 0.125 * h * h / prm.nu)
    return dt


class IsphStepper:
    """The ISPH scheme of one Simulation (steppers.Stepper): its Params, its initial state, one
    projection step (``step``) and the loop around it (steppers.drive), plus the PPE
    statistics (``ppe_iterations``, ``ppe_solves``, ``ppe_unknowns``, ``solve_time``)."""

    passes_per_step = 1   # one pressure solve per step, whatever constants.integrator says

    def __init__(self, scene: Scene, capacity: int,
                 zone_targets: ZoneTargets | None = None) -> None:
        sc = scene.scheme
        c = scene.constants
        if sc.ppe_solver not in PPE_SOLVERS:
            raise ValueError(f"ppe_solver: one of {PPE_SOLVERS}, got {sc.ppe_solver!r}")
        self.solver = sc.ppe_solver
        self.tol = float(sc.ppe_tolerance)
        self.max_iter = int(sc.ppe_max_iter)
        self.fs_threshold = float(sc.free_surface_threshold)
        self.isph_shifting = bool(sc.isph_shifting)
        self.v_ref = float(sc.isph_vref_factor * math.sqrt(2.0 * c.g * scene.water_height))
        self.wall_stop = float(sc.isph_wall_stop)
        self.relax = float(sc.isph_density_relaxation)
        self.zone = float(sc.isph_relaxation_zone)
        self.zone_tau = float(sc.isph_relaxation_time)
        # the zones' local targets, filled per window by open_ends.OpenBoundaries
        self.zone_targets = no_zone_targets() if zone_targets is None else zone_targets
        self.rho0 = c.rho0
        self.g = c.g
        self.vol = scene.dp * scene.dp
        self.prm: Any = None
        cap = int(capacity)
        self.flag = np.zeros(cap, dtype=np.int8)
        self.rho_k = np.zeros(cap)
        self.rho_ref = 0.0   # set by initialise
        self.wsum = np.zeros(cap)
        self.dwall = np.zeros(cap)
        self.idx = np.zeros(cap, dtype=np.int64)
        self.slot = np.zeros(cap, dtype=np.int64)
        self.indptr = np.arange(cap + 1, dtype=np.int64) * MAX_ROW
        self.ptr = np.zeros(cap + 1, dtype=np.int64)
        self.indices = np.zeros(cap * MAX_ROW, dtype=np.int64)
        self.data = np.zeros(cap * MAX_ROW)
        self.b = np.zeros(cap)
        self.x0 = np.zeros(cap)
        self.x2 = np.zeros(8 * cap)  # BiCGSTAB's eight vectors
        self.ppe_iterations = 0
        self.ppe_solves = 0
        self.ppe_unknowns = 0
        self.ppe_max_residual = 0.0
        self.solve_time = 0.0

    # --------------------------------------------------------------- set-up
    def initial_fluid(self, z: np.ndarray, surface: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Incompressible: density rho0; the hydrostatic pressure is the warm start of the first
        pressure solve."""
        return np.full(z.size, self.rho0), self.rho0 * self.g * (surface - z)

    def params(self, scene: Scene, base: dict[str, Any], n_layers: int) -> Params:
        """Params of ISPH: no artificial viscosity (the bodies' load pass reads alpha), the flow
        speed's Courant number, Fickian shifting only (its figures in docs/studies/schemes.md were
        measured without the carry), no wall-face no-penetration shares (the PPE has its own
        no-penetration pressure, isph_wall_stop), the buffers' imposed acceleration kept for
        their pressure rows (passes.buffer_rows)."""
        c = scene.constants
        shifting = c.shifting == "fickian" or self.isph_shifting
        prm = Params(**base, alpha=0.0, cfl=scene.scheme.isph_cfl,
                     shift_a=c.shift_a if shifting else 0.0, shift_dplus=False,
                     shift_carry=False, wall_ga=0.0, wall_g0=0.0, wall_gb=0.0, riemann=False,
                     limiter=NO_RECONSTRUCTION, buffer_acceleration=True)
        self.prm = prm
        self.shifting = self.isph_shifting and prm.shift_a > 0.0
        # a typical fluid diagonal sum_j B_ij ~ (2 / rho0) sum_j V_j F_ij = 7 / (rho0 h^2): the
        # scale of the wall rows
        self.wscale = 7.0 / (prm.rho0 * prm.h * prm.h)
        # the relaxation's time scale: the nominal step cfl h / v_ref, not the actual dt (with
        # 1/dt^2 a shrinking step strengthened it, which shrank the step further: the dam break
        # blew up within 0.005 s)
        self.dt_ref = prm.cfl * prm.h / self.v_ref if self.v_ref > 0.0 else 0.25 * math.sqrt(
            prm.h / math.hypot(prm.gx, prm.gz))
        return prm

    def initialise(self, ps: Any, ps2: Any, cells: Any, ends: Any, bd: Any,
                   n: int) -> tuple[float, int]:
        """Incompressible buffers of the open ``ends`` (density rho0, mass rho0 dp^2: open_ends
        made them WCSPH's), place the rigid bodies ``bd`` (bodies.Bodies), sort the initial
        state into ``ps2`` (the caller swaps), buffer pressures and boundary gauges; returns
        (dt, n)."""
        if ends.active:
            kind = ps.kind[:n]
            buf = (kind != FLUID) & (kind != WALL) & (kind >= 0)
            ps.rho[:n][buf] = self.rho0
            ps.m[:n][buf] = self.rho0 * self.vol
        place_bodies(ps, n, bd)
        n = sort_by_cell(ps, ps2, N_SORTED_KDK, n, cells)
        self._open_ends_sorted(ps2, n, cells, ends)
        # the initial lattice's interior kernel density (~1.006 rho0), the PPE's density
        # reference: taken here, from the scene's own start, so that a run restored from a
        # checkpoint into a new Simulation steps on with the same reference
        free_surface_flags(ps2, n, cells, self.prm, self.fs_threshold, self.flag, self.rho_k)
        inner = self.flag[:n] == 0
        self.rho_ref = float(np.median(self.rho_k[:n][inner])) if inner.any() else self.prm.rho0
        g2 = self.prm.gx ** 2 + self.prm.gz ** 2
        return isph_dt(0.0, g2, self.prm, self.v_ref), int(n)

    # --------------------------------------------------------------- one step
    def _solve(self, ps: Any, n: int, cells: Any, dt: float) -> None:
        prm = self.prm
        m = ppe_unknowns(ps, n, self.flag, self.wsum, self.idx)
        longest = ppe_assemble(ps, n, cells, prm, dt, self.idx, self.wsum, self.dwall,
                               self.wscale, self.indptr, self.indices, self.data, self.b, self.x0,
                               self.slot, self.rho_k, self.rho_ref,
                               self.relax / (self.dt_ref * self.dt_ref))
        if longest >= MAX_ROW:  # a row lost terms: the particles are far denser than the lattice
            raise RuntimeError(f"ISPH: a PPE row has more than {MAX_ROW - 1} neighbours")
        compact_rows(m, self.indptr, self.indices, self.data, self.ptr)
        tic = time.perf_counter()
        # pyamg's set-up estimates spectral radii from np.random start vectors: with a fixed
        # seed a run repeats bit for bit (checkpoint / restore, pushed vs pulled open-end data;
        # unseeded they differed by ~1e-9 m after 0.2 s); the caller's random state is kept.
        # The other solvers draw no random numbers.
        rng = np.random.get_state() if self.solver == "amg" else None
        if rng is not None:
            np.random.seed(0)
        try:
            sol, it, rel = solve_ppe(self.solver, m, self.ptr, self.indices, self.data,
                                     self.b[:m], self.x0[:m], self.tol, self.max_iter, self.x2)
        finally:
            if rng is not None:
                np.random.set_state(rng)
        self.solve_time += time.perf_counter() - tic
        self.ppe_iterations += int(it)
        self.ppe_solves += 1
        self.ppe_unknowns = int(m)
        self.ppe_max_residual = max(self.ppe_max_residual, float(rel))
        scatter_pressure(ps, m, self.slot, np.ascontiguousarray(sol), self.flag[:n])

    def _open_ends_sorted(self, ps: Any, n: int, cells: Any, ends: Any) -> None:
        """Open-end hooks on the sorted state: buffer pressures, boundary gauges; constant
        density (the hooks write WCSPH's Tait density into the buffers)."""
        if ends.active:
            extrapolate_buffers(ps, n, cells, ends, self.prm)
            ps.rho[:n] = self.prm.rho0
            measure_boundaries(ps, cells, ends, self.prm)

    def step(self, ps: Any, ps2: Any, cells: Any, n: int, t: float, dt: float,
             ends: Any, bd: Any) -> tuple[int, int, int, float, float]:
        """One projection step from the sorted state ``ps`` at time t with the open ``ends``;
        the state ends sorted in ``ps2``. Returns (n, n_bad, n_out, max |v|^2, max |a*|^2); n < 0:
        the open ends ran out of particle capacity (state in ``ps``, not sorted)."""
        prm = self.prm
        free_surface_flags(ps, n, cells, prm, self.fs_threshold, self.flag, self.rho_k)
        wall_state(ps, n, cells, prm, dt, self.wall_stop, self.wsum, self.dwall)
        a2 = predict(ps, n, cells, prm, dt)
        self._solve(ps, n, cells, dt)
        if bd.active:
            # rigid bodies are moving walls of the PPE (their particles are WALL rows, with the
            # body's velocity and acceleration in the no-penetration and Adami terms); their
            # loads come from this step's pressure at r^n (bodies._particle_loads: pressure and
            # laminar pair terms; ISPH's Params carry alpha 0, so no artificial viscosity), and
            # they advance over the step with that acceleration (the kdk stages back to back)
            np.maximum(ps.p[:n], 0.0, out=ps.pw[:n])   # no tension across a body's face
            body_loads(ps, n, cells, prm, bd)
            bodies_advance(bd, t, dt, KICK_DRIFT)
            bodies_advance(bd, t, dt, KICK)
        n_bad, n_out, v2 = correct(ps, n, cells, prm, dt)
        place_bodies(ps, n, bd)
        v2 = max(v2, bodies_v2max(bd))   # a fast body bounds dt as fluid does
        if ends.active:  # after the drift, as step.py's kdk step: buffers moved, crossings
            n = update_buffers(ps, n, t + dt, dt, ends, prm)
            if n < 0:
                return -1, int(n_bad), int(n_out), float(v2), float(a2)
            if self.zone > 0.0:
                relax_to_source(ps, n, t + dt, dt, ends, self.zone, self.zone_tau,
                                self.zone_targets)
        n = sort_by_cell(ps, ps2, N_SORTED_KDK, n, cells)
        if self.shifting:
            shift_particles(ps2, n, cells, prm, dt)
        self._open_ends_sorted(ps2, n, cells, ends)
        return int(n), int(n_bad), int(n_out), float(v2), float(a2)

    def run(self, ps: Any, ps2: Any, cells: Any, ends: Any, bd: Any, n: int, t: float, dt: float,
            t_stop: float, max_steps: int) -> tuple[float, float, int, int, int, int, float, int]:
        """Steps (``step``) until t reaches t_stop or max_steps were taken, or a guard trips, in
        steppers.drive's loop; returns as ``step.run``: (t, dt_next, steps, status, swapped,
        n_flagged, v_max, n)."""
        cur = [ps, ps2, n]   # the current state, its twin, the slots in use

        def take(t: float, dt: float) -> tuple[int, int, float, float, bool]:
            n_new, n_bad, n_out, v2, a2 = self.step(cur[0], cur[1], cells, cur[2], t, dt, ends,
                                                    bd)
            if n_new < 0:  # out of capacity: the state stays in ps, as step.run's
                return ST_CAPACITY, cur[2], v2, dt, False
            cur[0], cur[1], cur[2] = cur[1], cur[0], n_new
            status, n_flag = ((ST_NONFINITE, n_bad) if n_bad else
                              (ST_LEFT_DOMAIN, n_out) if n_out else (ST_REACHED_T, 0))
            return status, n_flag, v2, isph_dt(v2, a2, self.prm, self.v_ref), True

        t, dt, steps, status, swapped, n_flag, v_max = drive(take, t, dt, t_stop, max_steps)
        return t, dt, steps, status, swapped, n_flag, v_max, cur[2]

    def stats(self) -> dict[str, Any]:
        """PPE statistics since the start (for meta.json and the benches)."""
        s = max(self.ppe_solves, 1)
        return {"ppe_solver": self.solver, "ppe_solves": self.ppe_solves,
                "ppe_iterations_per_step": self.ppe_iterations / s,
                "ppe_unknowns": self.ppe_unknowns, "ppe_max_residual": self.ppe_max_residual,
                "ppe_solve_time_s": round(self.solve_time, 3)}
