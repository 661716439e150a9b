"""Rigid bodies in the GPU kdk step: the kernels and their device state.

The bodies' state (``bodies.Bodies``: q, qd, acc, loads, per-particle loads) lives on the device
with the particles; ``BodiesDevice.read`` copies it back into the Simulation's (a few small
arrays). Every kernel calls the CPU's own functions of ``sph_core/bodies.py``:
``body_particle`` (``place_bodies``' body), ``particle_load`` (``_particle_loads``' body),
``body_accelerations`` (the per-body sum, in particle order as on the CPU, and the equations of
motion; one thread) and ``bodies_advance`` / ``bodies_v2max`` (one thread; their inlined twins
below, the same source).

In the step (``gpu_step_plan.py``), after the fluid's kick + drift: ``k_stage(KICK_DRIFT)``,
``k_place``; after the forces: ``k_particle_loads``, ``k_accelerations``; after the kick:
``k_stage(KICK)``, ``k_place``, ``k_v2`` (the time step's speed bound takes the bodies' too).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import cuda, njit

from ..bodies import (bodies_advance, bodies_v2max, body_accelerations, body_particle,
                      particle_load)
from ..particles import WALL
from . import gpu_kernels as K
from .gpu_kernels import _fluid_consts, _view

# the stage functions are plain @njit on the CPU (inlined into step.run they miscount, numba
# 0.68.1; step.py); a kernel's callees must be inlined: twins of the same source
_bodies_advance = njit(inline="always")(bodies_advance.py_func)
_bodies_v2max = njit(inline="always")(bodies_v2max.py_func)

# the state read back (the rest are settings)
BODY_FIELDS_READ = ("q", "qd", "acc", "qn", "qdn", "load", "fk_x", "fk_z", "fk_m")


@K.kernel
def k_stage(bd, stage, clk, ctl):
    """bodies_advance (one thread): one integrator stage of every body at this step's t, dt."""
    if cuda.grid(1) != 0 or ctl[K.STOP] != 0:
        return
    _bodies_advance(bd, clk[K.T], clk[K.DTS], stage)


@K.kernel
def k_place(buf, n, bd, ctl):
    """place_bodies: x, v, a of every body particle from its body's state."""
    if ctl[K.STOP] != 0:
        return
    i = cuda.grid(1)
    if i < n:
        ps = _view(buf)
        ok, x, z, vx, vz, ax, az = body_particle(i, ps, bd)
        if ok:
            ps.x[i] = x
            ps.z[i] = z
            ps.vx[i] = vx
            ps.vz[i] = vz
            ps.ax[i] = ax
            ps.az[i] = az


@K.kernel
def k_particle_loads(buf, n, cells, prm, bd, ctl):
    """_particle_loads: each body particle's reaction on its fluid neighbours and moment."""
    if ctl[K.STOP] != 0:
        return
    j = cuda.grid(1)
    if j < n and buf[1][j] == WALL:
        ps = _view(buf)
        kb = ps.ids[j] - bd.id0
        if kb >= 0 and kb < bd.npart:
            bd.fk_x[kb], bd.fk_z[kb], bd.fk_m[kb] = particle_load(j, kb, ps, cells, bd,
                                                                  _fluid_consts(prm))


@K.kernel
def k_accelerations(bd, prm, ctl):
    """body_loads' second half (one thread): loads summed per body, accelerations."""
    if cuda.grid(1) != 0 or ctl[K.STOP] != 0:
        return
    body_accelerations(bd, prm)


@K.kernel
def k_v2(bd, clk, ctl):
    """The step's max |v|^2 takes the body particles' (step.run: max(v2, bodies_v2max))."""
    if cuda.grid(1) != 0 or ctl[K.STOP] != 0:
        return
    clk[K.V2] = max(clk[K.V2], _bodies_v2max(bd))


class BodiesDevice:
    """The bodies' state on the device for a CudaStepper."""

    def __init__(self, st: Any, bd: Any) -> None:
        self.st = st
        self.host = bd
        self.bd = bd._replace(**{k: st._to_device(v) for k, v in bd._asdict().items()
                                 if isinstance(v, np.ndarray)})

    def read(self) -> None:
        """Copy the bodies' state (q, qd, acc, loads) into the Simulation's ``Bodies``."""
        for k in BODY_FIELDS_READ:
            getattr(self.host, k)[:] = self.st._to_host(getattr(self.bd, k))
