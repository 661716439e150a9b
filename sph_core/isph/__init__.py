"""Incompressible SPH (ISPH): the projection method of Cummins & Rudman (1999) as in seed 004.

Selected by a scene's ``[scheme] kind = "isph"``; ``Simulation`` then steps with an
``IsphStepper`` (a Python loop over jitted passes around the sparse pressure solve) instead of
``step.run``. Density is constant (rho0, every particle's mass rho0 dp^2); the
pressure comes from a Poisson equation each step, not from an equation of state, so there is no
sound speed and the time step follows the flow speed.

One step (i fluid, j neighbour, r_ij = r_i - r_j, grad_i W_ij = -F_ij r_ij, V_j = m_j / rho0),
on the sorted state at t^n (docs/studies/schemes.md "## ISPH" has the measurements behind each choice):

1. free surface (Dirichlet p = 0): the position divergence sum_j V_j F_ij r_ij^2 <= 1.5
   (``free_surface_threshold``; 2 inside the fluid in 2D, Lind et al. 2012; seed 004's density
   criterion is retired: docs/decisions/free_surface.md), or fewer than 3 fluid and buffer
   neighbours (a film or drop walled in by walls: without a p = 0 link its rows are singular);
2. predictor (eq. 7): u*_i = u^n_i + dt (g + nu lap u_i), the Lo & Shao (2002) laminar term of
   wcsph.fluid_pass; walls: Adami et al. (2012) no-slip velocity;
3. pressure Poisson equation (eq. 9-12), one sparse system over the interior fluid particles
   and the wall and open-end buffer particles that have fluid neighbours:
     fluid i:  sum_j B_ij (p_i - p_j) = -div u*_i / dt + relax (rho_k,i - rho_ref) / (rho_ref dt_ref^2)
               B_ij = 8 m_j / (rho_i + rho_j)^2 F_ij r_ij^2 / (r_ij^2 + eta^2),  eta = 0.1 h   (Shao & Lo 2003)
               div u*_i = sum_f V_f (u*_f - u*_i) . grad_i W_if   over fluid f    (Khayyer et al. 2009)
               the last term (Asai et al. 2012, ``isph_density_relaxation``) with dt_ref the
               nominal step cfl h / v_ref in place of dt: rho_k = sum m W, rho_ref the initial
               interior lattice's value (~1.006 rho0);
     wall s:   p_s - sum_f w_sf p_f = sum_f w_sf rho_f [(g - a_s) . r_sf + max(0, -u_n,f / dt) (n_s . r_fs)]
               w_sf = W_sf / sum_f W_sf (Adami et al. 2012, seed 004 eq. 22, linear in the fluid
               pressures) plus a no-penetration part: u_n,f = (u_f - v_s) . n_s the fluid's
               approach speed, n_s the unit vector from the wall into its fluid neighbours.
   The walls enter the fluid rows through their pressure only (a ghost-pressure Neumann
   condition): with the wall velocity also in div u* the hydrostatic column came out 1.45x too
   heavy, and with the plain Adami rows fluid driven at the bed went through it (the wall pressure
   rises with the fluid's). Free-surface particles enter with p = 0. Solved by ``ppe_solver``:
   ``bicgstab`` (the default) = BiCGSTAB preconditioned by the diagonal, jitted, ``amg`` =
   BiCGSTAB preconditioned by smoothed-aggregation AMG (pyamg), both warm-started from the last
   pressure (the seed's Jacobi iteration, ILU and SuperLU are retired:
   docs/decisions/ppe_solver.md). The no-penetration part
   stops the approach within ``isph_wall_stop`` steps (rho |u_n| d / (stop dt)); it and the
   source scale as 1/dt, so its loop (steppers.drive) never ends a run on a sliver step;
4. corrector (eq. 16-17): u^{n+1} = u* - dt grad p_i / rho0, r^{n+1} = r^n + dt (u^n + u^{n+1}) / 2,
   grad p by the renormalised difference B_i^-1 sum_j V_j (p_j - p_i) grad_i W_ij (Bonet & Lok
   1999), seed eq. 5 only where B_i is near-singular (seed eq. 5 everywhere is retired: the
   surface layer, its kernel cut, fell at ~g/3; docs/decisions/isph_gradient.md); wall
   particles with p < 0 (the air side of a wetted wall) are left out like air
   (docs/decisions/isph_dry_walls.md);
5. open ends (the hooks of step.py's kdk step, same places): update_buffers after the drift
   (buffers imposed and moved, crossings), extrapolate_buffers after the sort, measure_boundaries
   at the end; then every particle's density is reset to rho0 (the buffers' Tait density of
   open_boundary.py is WCSPH's); sort by cell, then Fickian particle shifting (Lind et al. 2012,
   sph_core.shifting).

Open ends: an active buffer particle with fluid neighbours has a row of the PPE, as a wall
particle does (passes.buffer_rows: p_b - sum_f w_bf p_f = sum_f w_bf rho_f g . r_bf, the Adami
sums over its fluid neighbours), so its pressure follows the fluid's within the step; one without
fluid neighbours keeps the open-end hook's pressure (open_boundary.py's rules) as a known
value. Buffers count in div u* with u*_b = u_b + dt g (their imposed velocity plus the step's
gravity, as the fluid's u* carries it), in the viscous term and in the free-surface criterion as
fluid neighbours (docs/studies/schemes.md "ISPH with open ends and bodies" and "ISPH open ends:
the buffers in the projection").

Rigid bodies (fixed, prescribed) are WALL rows moving with the body; their loads come from the
step's pressure after the solve (free and hinged bodies are refused by the scene: that explicit
coupling is unstable for a body lighter than its added mass).

The PPE is solved at r^n rather than at seed 004's intermediate r* = r^n + dt u* (eq. 8): one
neighbour search per step instead of two. The time step (no sound speed):
    dt = min(isph_cfl h / max(|v|_max, v_ref), 0.25 sqrt(h / max|g + nu lap u|), 0.125 h^2 / nu),
v_ref = isph_vref_factor sqrt(2 g H) (H the water height), the a-priori speed of Lind et al.
(2012): without it a tank at rest steps at the force limit 0.25 sqrt(h/g), 7x larger (tried only
before the wall rows above were settled, where it did not help; not re-measured since).

The package: ``terms`` (the per-pair terms, folds of pairs.gather), ``passes`` (free surface,
wall state, predictor, corrector), ``ppe`` (unknowns, rows, solvers), ``stepper``
(``IsphStepper``: one step and the loop).
"""

from .passes import correct, free_surface_flags, predict, scatter_pressure, wall_state
from .ppe import (MAX_ROW, PPE_SOLVERS, bicgstab_jacobi, compact_rows, ppe_assemble,
                  ppe_unknowns, solve_ppe)
from .stepper import IsphStepper, isph_dt

__all__ = ["MAX_ROW", "PPE_SOLVERS", "IsphStepper", "bicgstab_jacobi", "compact_rows", "correct",
           "free_surface_flags", "isph_dt", "ppe_assemble", "ppe_unknowns", "predict",
           "scatter_pressure", "solve_ppe", "wall_state"]
