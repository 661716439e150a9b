"""ISPH's stepper: one projection step (``IsphStepper.step``: the passes of passes.py, the
pressure solve of ppe.py, the open-end and body hooks) and the time loop around it."""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from ..bodies import bodies_kick, bodies_kick_drift, bodies_v2max, body_loads, place_bodies
from ..neighbours import sort_by_cell
from ..open_boundary import extrapolate_buffers, measure_boundaries, update_buffers
from ..particles import N_SORTED_KDK
from ..shifting import shift_particles
from ..wcsph import ST_CAPACITY, ST_LEFT_DOMAIN, ST_NONFINITE, ST_REACHED_T, ST_STEP_LIMIT
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
    """The ISPH time loop of one Simulation: same call and returns as ``step.run``, plus the PPE
    statistics (``ppe_iterations``, ``ppe_solves``, ``ppe_unknowns``, ``solve_time``)."""

    def __init__(self, capacity: int, prm: Any, dp: float, solver: str = "bicgstab",
                 tolerance: float = 1e-5, max_iter: int = 20000, fs_threshold: float = 1.5,
                 shifting: bool = True, v_ref: float = 0.0,
                 density_relaxation: float = 0.0, wall_stop: float = 1.0) -> None:
        if solver not in PPE_SOLVERS:
            raise ValueError(f"ppe_solver: one of {PPE_SOLVERS}, got {solver!r}")
        self.prm = prm
        self.solver = solver
        self.tol = float(tolerance)
        self.max_iter = int(max_iter)
        self.fs_threshold = float(fs_threshold)
        self.shifting = bool(shifting) and prm.shift_a > 0.0
        self.v_ref = float(v_ref)
        self.wall_stop = float(wall_stop)
        # a typical fluid diagonal sum_j B_ij ~ (2 / rho0) sum_j V_j F_ij = 7 / (rho0 h^2): the
        # scale of the wall rows
        self.wscale = 7.0 / (prm.rho0 * prm.h * prm.h)
        cap = int(capacity)
        self.flag = np.zeros(cap, dtype=np.int8)
        self.rho_k = np.zeros(cap)
        self.rho_ref = 0.0
        self.relax = float(density_relaxation)
        # the relaxation's time scale: the nominal step cfl h / v_ref, not the actual dt (with
        # 1/dt^2 a shrinking step strengthened it, which shrank the step further: the dam break
        # blew up within 0.005 s)
        self.dt_ref = prm.cfl * prm.h / v_ref if v_ref > 0.0 else 0.25 * math.sqrt(
            prm.h / math.hypot(prm.gx, prm.gz))
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
    def initialise(self, ps: Any, ps2: Any, cells: Any, n: int, ends: Any,
                   bd: Any) -> tuple[float, int]:
        """Place the rigid bodies ``bd`` (bodies.Bodies), sort the initial state into ``ps2``
        (the caller swaps), buffer pressures and boundary gauges of the open ``ends``
        (state.OpenEnds); returns (dt, n)."""
        place_bodies(ps, n, bd)
        n = sort_by_cell(ps, ps2, N_SORTED_KDK, n, cells)
        self._open_ends_sorted(ps2, n, cells, ends)
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
        if self.rho_ref == 0.0:  # the initial lattice's interior kernel density (~1.006 rho0)
            inner = self.flag[:n] == 0
            self.rho_ref = float(np.median(self.rho_k[:n][inner])) if inner.any() else prm.rho0
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
            bodies_kick_drift(bd, t, dt)
            bodies_kick(bd, t, dt)
        n_bad, n_out, v2 = correct(ps, n, cells, prm, dt)
        place_bodies(ps, n, bd)
        v2 = max(v2, bodies_v2max(bd))   # a fast body bounds dt as fluid does
        if ends.active:  # after the drift, as step.py's kdk step: buffers moved, crossings
            n = update_buffers(ps, n, t + dt, dt, ends, prm)
            if n < 0:
                return -1, int(n_bad), int(n_out), float(v2), float(a2)
        n = sort_by_cell(ps, ps2, N_SORTED_KDK, n, cells)
        if self.shifting:
            shift_particles(ps2, n, cells, prm, dt)
        self._open_ends_sorted(ps2, n, cells, ends)
        return int(n), int(n_bad), int(n_out), float(v2), float(a2)

    def run(self, ps: Any, ps2: Any, cells: Any, ends: Any, bd: Any, n: int, t: float, dt: float,
            t_stop: float, max_steps: int) -> tuple[float, float, int, int, int, int, float, int]:
        """Steps until t reaches t_stop or max_steps were taken, or a guard trips; returns as
        ``step.run``: (t, dt_next, steps, status, swapped, n_flagged, v_max, n)."""
        swapped = 0
        steps = 0
        status = ST_REACHED_T
        n_flag = 0
        v2 = 0.0
        while True:
            if t >= t_stop:
                status = ST_REACHED_T
                break
            if steps >= max_steps:
                status = ST_STEP_LIMIT
                break
            # no sliver steps: a projection's pressure carries (div u^n) / dt, so a step of a
            # tiny fraction of dt (window and output times meeting) gives a pressure field far
            # from the flow's, which the open ends' buffers then take over (extrapolated) and
            # the probes record. Measured: a 3.7e-5 s step after 2.3e-3 s ones raised the
            # fluid's largest pressure from 2.6 to 7.2 kPa; the open flume blew up within
            # 0.015 s; in the closed dam break such steps before each probe record gave
            # wall-pressure spikes of 10^5-10^7 Pa (docs/schemes.md). So the last two steps
            # share a remainder below 1.5 dt, and a round-off remainder (< 1e-6 dt) is not
            # stepped.
            rem = t_stop - t
            if rem <= 1e-6 * dt:
                t = t_stop
                continue
            last = rem <= dt
            dts = rem if last else (0.5 * rem if rem < 1.5 * dt else dt)
            n_new, n_bad, n_out, v2, a2 = self.step(ps, ps2, cells, n, t, dts, ends, bd)
            if n_new < 0:  # the state stays in ps, as step.run's
                status, n_flag = ST_CAPACITY, n
                break
            n = n_new
            ps, ps2 = ps2, ps
            swapped = 1 - swapped
            t = t_stop if last else t + dts
            steps += 1
            if n_bad:
                status, n_flag = ST_NONFINITE, n_bad
                break
            if n_out:
                status, n_flag = ST_LEFT_DOMAIN, n_out
                break
            dt = isph_dt(v2, a2, self.prm, self.v_ref)
        return t, dt, steps, status, swapped, n_flag, math.sqrt(v2), n

    def stats(self) -> dict[str, Any]:
        """PPE statistics since the start (for meta.json and the benches)."""
        s = max(self.ppe_solves, 1)
        return {"ppe_solver": self.solver, "ppe_solves": self.ppe_solves,
                "ppe_iterations_per_step": self.ppe_iterations / s,
                "ppe_unknowns": self.ppe_unknowns, "ppe_max_residual": self.ppe_max_residual,
                "ppe_solve_time_s": round(self.solve_time, 3)}
