"""The schemes behind one stepper: what a ``Simulation`` asks of WCSPH / Riemann SPH and of ISPH.

    stepper = make_stepper(scene, capacity[, zone_targets])   # by [scheme] kind
    rho, p = stepper.initial_fluid(z, surface)     # the lattice's density (and pressure, or None)
    prm = stepper.params(scene, base, n_layers)    # the scheme's Params (base: scheme-neutral)
    dt, n = stepper.initialise(ps, ps2, cells, ends, bd, n)
    t, dt, steps, status, swapped, n_flag, v_max, n = stepper.run(ps, ps2, cells, ends, bd, n,
                                                                  t, dt, t_stop, max_steps)
    stepper.stats()                                # scheme statistics for meta.json

Each scheme owns its translation from the scene to ``Params`` (which terms are on, its time
step's Courant number) and its passes; ``Simulation`` owns the particles, outputs and what a
stopped run does (exclusion, the unstable error). The time loop's control is the same in both
kinds of stepper: stop at ``t_stop`` or after ``max_steps``, stop at the first guard that trips
with the status codes of wcsph.py (``ST_*``), hand back whether the state sits in the twin
(``swapped``). WCSPH and Riemann SPH run it jitted (``step.run``, steps of the explicit
integrators); a stepper whose step is Python around jitted passes (ISPH: the sparse solve)
runs it through ``drive`` below, which adds the rule that such steps need: no sliver step.
"""

from __future__ import annotations

import math
from typing import Any, Callable, Protocol

import numpy as np

from . import riemann, step, wcsph
from .eos import hydrostatic_density, tait_b
from .scene import Scene, Scheme
from .state import Params, ZoneTargets
from .wall_contact import face_shares


class Stepper(Protocol):
    """One scheme's translation from the scene and its time loop (module docstring)."""

    prm: Params
    passes_per_step: int   # neighbour passes per step (meta.json)

    def initial_fluid(self, z: np.ndarray, surface: np.ndarray) -> tuple[np.ndarray,
                                                                        np.ndarray | None]:
        """Density of the initial fluid lattice at heights z under ``surface``; its pressure, or
        None where the step derives it from the density."""
        ...

    def params(self, scene: Scene, base: dict[str, Any], n_layers: int) -> Params:
        """The run's Params: ``base`` (the scheme-neutral fields) plus this scheme's."""
        ...

    def initialise(self, ps: Any, ps2: Any, cells: Any, ends: Any, bd: Any,
                   n: int) -> tuple[float, int]:
        """Sort the initial state into ``ps2`` (the caller swaps), place the bodies, prepare the
        open ends; returns (first dt, n)."""
        ...

    def run(self, ps: Any, ps2: Any, cells: Any, ends: Any, bd: Any, n: int, t: float, dt: float,
            t_stop: float, max_steps: int) -> tuple[float, float, int, int, int, int, float, int]:
        """Steps until t_stop or max_steps, or a guard trips: (t, dt_next, steps, status,
        swapped, n_flagged, v_max, n), as ``step.run``."""
        ...

    def stats(self) -> dict[str, Any]:
        """The scheme's statistics since the start, for meta.json (may be empty)."""
        ...


def scheme_params(scheme: Scheme) -> dict[str, Any]:
    """The Params fields of the scene's [scheme] (riemann, limiter)."""
    if scheme.kind != "riemann":
        return {"riemann": False, "limiter": riemann.NO_RECONSTRUCTION}
    lim = riemann.VANLEER if scheme.reconstruction == "muscl" else riemann.NO_RECONSTRUCTION
    return {"riemann": True, "limiter": lim}


class WcsphStepper:
    """Weakly compressible SPH (delta-SPH and Monaghan viscosity, or the Riemann flux): the
    jitted ``step.run`` with the scene's optional parts (``step.step_parts``: only the kernels
    the scene uses are compiled)."""

    def __init__(self, scene: Scene) -> None:
        c = scene.constants
        self.integrator = c.integrator
        self.passes_per_step = wcsph.PASSES_PER_STEP[c.integrator]
        self.rho0 = c.rho0
        self.g = c.g
        self.b = tait_b(c.rho0, scene.c0)
        self.prm: Params

    def initial_fluid(self, z: np.ndarray, surface: np.ndarray) -> tuple[np.ndarray, None]:
        # the compressed hydrostatic state: with mass rho dp^2 the initial pressure is
        # hydrostatic (the equation of state) and every particle's volume exactly dp^2
        return hydrostatic_density(z, surface, self.rho0, self.g, self.b), None

    def params(self, scene: Scene, base: dict[str, Any], n_layers: int) -> Params:
        c = scene.constants
        dplus = c.shifting == "dplus"
        # shifting (shifting.py): delta-plus's CFL Ma (2h)^2 is D = 4 h max|v| dt
        shift_a = (4.0 * c.shift_dplus_scale if dplus
                   else c.shift_a if c.shifting == "fickian" else 0.0)
        self.prm = Params(**base, alpha=c.alpha, cfl=c.cfl, shift_a=shift_a, shift_dplus=dplus,
                          shift_carry=c.shift_carry,
                          # no penetration at wall faces (wall_contact.py)
                          **dict(zip(("wall_ga", "wall_g0", "wall_gb"),
                                     face_shares(scene.h, scene.dp, n_layers, base["alpha_w"],
                                                 scene.dim))),
                          **scheme_params(scene.scheme))
        return self.prm

    def _parts(self, ends: Any, bd: Any) -> tuple:
        return step.step_parts(ends, bd, self.integrator, self.prm.riemann, self.prm.shift_a > 0.0)

    def initialise(self, ps: Any, ps2: Any, cells: Any, ends: Any, bd: Any,
                   n: int) -> tuple[float, int]:
        ends, bd, _, riemann, _ = self._parts(ends, bd)
        return step.initialise(ps, ps2, cells, self.prm, ends, bd, riemann, n)

    def run(self, ps: Any, ps2: Any, cells: Any, ends: Any, bd: Any, n: int, t: float, dt: float,
            t_stop: float, max_steps: int) -> tuple[float, float, int, int, int, int, float, int]:
        return step.run(ps, ps2, cells, self.prm, *self._parts(ends, bd), n, t, dt, t_stop,
                        max_steps)

    def stats(self) -> dict[str, Any]:
        return {}


def make_stepper(scene: Scene, capacity: int, zone_targets: ZoneTargets | None = None
                 ) -> Stepper:
    """The stepper of the scene's [scheme] kind, for ``capacity`` particle slots;
    ``zone_targets``: the open ends' local targets of ISPH's relaxation zones (None: none)."""
    if scene.scheme.kind == "isph":
        from .isph import IsphStepper
        return IsphStepper(scene, capacity, zone_targets)
    return WcsphStepper(scene)


# take(t, dt) -> (status, n_flagged, max |v|^2, dt of the next step, whether the step was done)
StepFn = Callable[[float, float], tuple[int, int, float, float, bool]]


def drive(take: StepFn, t: float, dt: float, t_stop: float,
          max_steps: int) -> tuple[float, float, int, int, int, int, float]:
    """The time loop of a stepper whose step runs in Python: steps ``take`` until t reaches
    t_stop or max_steps were taken, or a step returns a status other than ST_REACHED_T.
    Returns (t, dt_next, steps, status, swapped, n_flagged, v_max), as ``step.run`` without n
    (the stepper keeps it); a step that was not done (``done`` False) leaves the state where it
    was (no swap).

    No sliver steps: a projection's pressure carries (div u^n) / dt, so a step of a tiny
    fraction of dt (window and output times meeting) gives a pressure field far from the
    flow's, which the open ends' buffers then take over (extrapolated) and the probes record.
    Measured under ISPH: a 3.7e-5 s step after 2.3e-3 s ones raised the fluid's largest pressure
    from 2.6 to 7.2 kPa; the open flume blew up within 0.015 s; in the closed dam break such
    steps before each probe record gave wall-pressure spikes of 10^5-10^7 Pa (docs/studies/schemes.md).
    So the last two steps share a remainder below 1.5 dt, and a round-off remainder (< 1e-6 dt)
    is not stepped. (The jitted ``step.run`` takes the remainder whole: the explicit steps have
    no 1/dt term.)"""
    swapped = 0
    steps = 0
    status = wcsph.ST_REACHED_T
    n_flag = 0
    v2 = 0.0
    while True:
        if t >= t_stop:
            status = wcsph.ST_REACHED_T
            break
        if steps >= max_steps:
            status = wcsph.ST_STEP_LIMIT
            break
        rem = t_stop - t
        if rem <= 1e-6 * dt:
            t = t_stop
            continue
        last = rem <= dt
        dts = rem if last else (0.5 * rem if rem < 1.5 * dt else dt)
        status, n_flag, v2, dt_next, done = take(t, dts)
        if done:
            swapped = 1 - swapped
            t = t_stop if last else t + dts
            steps += 1
        if status != wcsph.ST_REACHED_T:
            break
        dt = dt_next
    return t, dt, steps, status, swapped, n_flag, math.sqrt(v2)
