"""The one jitted time loop: every scene, every integrator, with or without open ends.

    t, dt, steps, status, swapped, n_flag, v_max, n = run(ps, ps2, cells, prm, ends, bd, pc,
                                                          riemann, shift, n, t, dt, t_stop,
                                                          max_steps)

State lives in the typed containers of ``state.py`` (Particles ``ps`` and its twin ``ps2``,
Cells, Params, OpenEnds) and of ``bodies.py`` (Bodies ``bd``); ``swapped`` = 1 means the current state is in the twin (the caller swaps its
references), ``n`` the slots in use after the call (a sort drops inactive slots, open ends
append).

Only the kernels a scene uses are compiled: each optional part of the step is an argument that
is None when the scene has none of it, and numba prunes an ``if x is None`` branch on an
argument before it types the rest, so a closed WCSPH tank never compiles the open-end, body,
Riemann, shifting or predictor-corrector kernels (``step_parts`` builds them from a Simulation;
each combination compiles once and is cached; the stages are not ``inline="always"``: inlined
into ``run`` they returned a wrong particle count, numba 0.68.1):
    ends     OpenEnds, or None (closed tank)
    bd       Bodies, or None (no rigid bodies)
    pc       True: the symplectic predictor-corrector; None: kdk leapfrog
    riemann  True: Riemann SPH's flux (riemann.py); None: WCSPH (delta-SPH, Monaghan AV)
    shift    True: particle shifting after each step (shifting.py); None: none

One step, as the two integrators order the same stages (wcsph.py has the equations):

    kdk (one force evaluation)               symplectic_pc (two)
    ------------------------------------     ------------------------------------
    kick + drift (fluid)                     sort                          [S]
    update_buffers                  [D]      extrapolate_buffers           [S']
    sort                            [S]      forces at x^n                 [F]
    extrapolate_buffers             [S']     measure_boundaries            [G]
    forces                          [F]      predict (half step)
    kick (guards, max |v|, |a|, rho)         forces at x^{n+1/2}           [F]
    measure_boundaries              [G]      correct (guards)
                                             update_buffers                [D]

[F] forces = ``wall_pass`` (Adami wall state) then, for Riemann SPH with MUSCL,
``riemann_gradients``, then ``fluid_pass`` (continuity, delta-SPH, pressure, viscosity, gravity;
or the Riemann flux, riemann.py) then ``body_loads`` (fluid loads on the rigid bodies, their
accelerations): ``_forces`` below. Bodies follow the fluid's stages: kdk half-kick + drift with
the fluid's, half-kick after the fluid's; symplectic predictor / corrector likewise; each stage
then places the body particles (``place_bodies``: x, v = V + omega x r, a). The open-end hooks
([D] after the drift: buffers imposed and moved, crossings; [S'] after the sort: ghost-node
pressure; [G] after the forces: boundary gauges) run when ``ends`` is given. Buffer particles
are not FLUID: the integrators never move them; update_buffers does, once per step, with the
window's data at t + dt.

Where a new physical term goes (docs/developer/adding_a_term.md):
- a new pair contribution to the rates (a force or density term between neighbours): its
  physical function in terms.py, called from the pair term of the scheme it belongs to
  (terms.wcsph_pair / riemann_pair): it shares fluid_pass's one neighbour walk (pairs.gather);
- a pass that needs neighbours before the forces (as Riemann SPH's MUSCL gradients): a
  pass over ``pairs.gather`` with its own term, called in ``_forces`` before ``fluid_pass``;
- a position correction after the update (particle shifting): a pass after ``kdk_kick`` /
  ``pc_correct`` in ``_step_kdk`` / ``_step_pc``, on the sorted state (cells valid for kdk; for
  symplectic_pc the cells are those of x^n);
- damping / absorption of the velocity (e.g. a sponge layer): after the kick / corrector, same
  place as shifting.
Rows added to Particles go after ``rhon`` and before ``drho`` if a sort must carry them (and
N_SORTED_* grow), else at the end (particles.py).
"""

from __future__ import annotations

import math

from numba import njit

from .bodies import (CORRECT, KICK, KICK_DRIFT, PREDICT, bodies_advance,
                     bodies_v2max, body_loads, place_bodies)
from .neighbours import sort_by_cell
from .open_boundary import extrapolate_buffers, measure_boundaries, update_buffers
from .particles import N_SORTED_KDK, N_SORTED_PC
from .riemann import NO_RECONSTRUCTION, riemann_gradients
from .shifting import shift_particles, shift_particles_dplus
from .wcsph import (ST_CAPACITY, ST_DENSITY, ST_LEFT_DOMAIN, ST_NONFINITE, ST_REACHED_T,
                    ST_STEP_LIMIT, fluid_pass, kdk_kick, kdk_kick_drift, pc_correct, pc_predict,
                    stable_dt, update_pressure, wall_pass)


def step_parts(ends, bd, integrator: str, riemann: bool, shifting: bool) -> tuple:
    """(ends, bd, pc, riemann, shift): the optional parts of ``run``'s step, None where the scene
    has none (module docstring)."""
    return (ends if ends.active else None, bd if bd.active else None,
            True if integrator == "symplectic_pc" else None, True if riemann else None,
            True if shifting else None)


@njit(cache=True)
def _forces(ps, n, cells, prm, bd, riemann):
    """Rates of every fluid particle (ax, az, drho) and body (acc) at the current, sorted state."""
    wall_pass(ps, n, cells, prm)
    if riemann is not None:
        if prm.limiter != NO_RECONSTRUCTION:
            riemann_gradients(ps, n, cells, prm)   # MUSCL: gradients of p and v (riemann.py)
    fluid_pass(ps, n, cells, prm, riemann)
    if bd is not None:
        body_loads(ps, n, cells, prm, bd)


@njit(cache=True)
def _shift(ps, n, cells, prm, dt, v2max, shift):
    """Particle shifting after the update (shifting.py), if on: Fickian or delta-plus."""
    if shift is not None:
        if prm.shift_dplus:
            shift_particles_dplus(ps, n, cells, prm, dt, math.sqrt(v2max))
        else:
            shift_particles(ps, n, cells, prm, dt)


@njit(cache=True)
def _place(ps, n, bd):
    if bd is not None:
        place_bodies(ps, n, bd)


@njit(cache=True)
def _body_v2max(bd):
    if bd is None:
        return 0.0
    return bodies_v2max(bd)


@njit(cache=True)
def initialise(ps, ps2, cells, prm, ends, bd, riemann, n):
    """Sort, evaluate rates at the initial state, measure the boundary gauges; returns (dt, n).
    The sorted state ends in ``ps2`` (the caller swaps)."""
    update_pressure(ps, n, prm)
    _place(ps, n, bd)
    n = sort_by_cell(ps, ps2, N_SORTED_PC, n, cells)
    if ends is not None:
        extrapolate_buffers(ps2, n, cells, ends, prm)
    _forces(ps2, n, cells, prm, bd, riemann)
    n_bad, n_band, v2max, a2max, rmax = kdk_kick(ps2, n, 0.0, prm)
    if ends is not None:
        measure_boundaries(ps2, cells, ends, prm)
    return stable_dt(max(v2max, _body_v2max(bd)), a2max, rmax, prm), n


@njit(cache=True)
def _step_kdk(ps, ps2, cells, prm, ends, bd, riemann, shift, n, t, dt):
    """One leapfrog step; the state ends in ps2. Returns (n, status, n_flag, v2max, a2max, rmax)."""
    # a particle that left the tank box finishes the step like the others (the sort clamps it
    # to the grid); the verdict then reports it and the Simulation excludes it
    n_out = kdk_kick_drift(ps, n, dt, prm)
    if bd is not None:
        bodies_advance(bd, t, dt, KICK_DRIFT)
    _place(ps, n, bd)
    n_new = n
    if ends is not None:
        n_new = update_buffers(ps, n, t + dt, dt, ends, prm)
        if n_new < 0:
            return n, ST_CAPACITY, n, 0.0, 0.0, 0.0, False
    n = sort_by_cell(ps, ps2, N_SORTED_KDK, n_new, cells)
    if ends is not None:
        extrapolate_buffers(ps2, n, cells, ends, prm)
    _forces(ps2, n, cells, prm, bd, riemann)
    n_bad, n_band, v2max, a2max, rmax = kdk_kick(ps2, n, dt, prm)
    if bd is not None:
        bodies_advance(bd, t, dt, KICK)
    _place(ps2, n, bd)
    _shift(ps2, n, cells, prm, dt, v2max, shift)
    if ends is not None:
        measure_boundaries(ps2, cells, ends, prm)
    return _verdict(n, n_bad, n_band, n_out, v2max, a2max, rmax)


@njit(cache=True)
def _step_pc(ps, ps2, cells, prm, ends, bd, riemann, shift, n, t, dt):
    """One symplectic predictor-corrector step; the state ends in ps2. Same returns as _step_kdk."""
    n = sort_by_cell(ps, ps2, N_SORTED_PC, n, cells)
    if ends is not None:
        extrapolate_buffers(ps2, n, cells, ends, prm)
    _forces(ps2, n, cells, prm, bd, riemann)
    if ends is not None:
        measure_boundaries(ps2, cells, ends, prm)
    pc_predict(ps2, n, dt, prm)
    if bd is not None:
        bodies_advance(bd, t, dt, PREDICT)
    _place(ps2, n, bd)
    _forces(ps2, n, cells, prm, bd, riemann)
    n_bad, n_band, n_out, v2max, a2max, rmax = pc_correct(ps2, n, dt, prm)
    if bd is not None:
        bodies_advance(bd, t, dt, CORRECT)
    _place(ps2, n, bd)
    _shift(ps2, n, cells, prm, dt, v2max, shift)
    if ends is not None and n_bad == 0 and n_out == 0:
        n_new = update_buffers(ps2, n, t + dt, dt, ends, prm)
        if n_new < 0:
            return n, ST_CAPACITY, n, v2max, a2max, rmax, True
        n = n_new
    return _verdict(n, n_bad, n_band, n_out, v2max, a2max, rmax)


@njit(cache=True)
def _verdict(n, n_bad, n_band, n_out, v2max, a2max, rmax):
    """Status after a completed step (the guards in the order they are reported)."""
    if n_bad > 0:
        return n, ST_NONFINITE, n_bad, v2max, a2max, rmax, True
    if n_out > 0:
        return n, ST_LEFT_DOMAIN, n_out, v2max, a2max, rmax, True
    if n_band > 0:
        return n, ST_DENSITY, n_band, v2max, a2max, rmax, True
    return n, ST_REACHED_T, 0, v2max, a2max, rmax, True


@njit(cache=True)
def run(ps, ps2, cells, prm, ends, bd, pc, riemann, shift, n, t, dt, t_stop, max_steps):
    """Run steps until t reaches t_stop or max_steps were taken, or a guard trips.

    Returns (t, dt_next, steps, status, swapped, n_flagged, v_max, n)."""
    swapped = 0
    steps = 0
    status = ST_REACHED_T
    n_flag = 0
    v2max = 0.0
    while True:
        if t >= t_stop:
            status = ST_REACHED_T
            break
        if steps >= max_steps:
            status = ST_STEP_LIMIT
            break
        dts = dt
        last = False
        if t + dts >= t_stop:
            dts = t_stop - t
            last = True
        if pc is None:
            n, status, n_flag, v2, a2max, rmax, done = _step_kdk(ps, ps2, cells, prm, ends, bd,
                                                                  riemann, shift, n, t, dts)
        else:
            n, status, n_flag, v2, a2max, rmax, done = _step_pc(ps, ps2, cells, prm, ends, bd,
                                                                 riemann, shift, n, t, dts)
        if done:  # the step got to its sort: the state is in the twin
            ps, ps2 = ps2, ps
            swapped = 1 - swapped
            t = t_stop if last else t + dts
            steps += 1
            v2max = max(v2, _body_v2max(bd))   # a fast body bounds dt as fluid does
        if status != ST_REACHED_T:
            break
        dt = stable_dt(v2max, a2max, rmax, prm)
    return t, dt, steps, status, swapped, n_flag, math.sqrt(v2max), n
