"""Particles as structure-of-arrays with spare capacity.

All real-valued fields live in one array ``f[field, slot]`` (each field row contiguous), float64
or, with the scene's ``constants.precision = "float32"``, float32;
``kind`` (int8), ``ids`` (int64) and ``cell`` (int64) are separate. Slots ``[0, n)`` are in use;
``n <= capacity`` leaves room for open boundaries to create particles. Every array has a twin
buffer: reordering by cell gathers into the twin and the two are swapped, so nothing is
allocated per step. ``view`` / ``view2`` are the kernels' typed views (``state.Particles``).

Row layout. The first ``N_SORTED_*`` rows are carried through a reorder, and in a 3D scene the
first ``N_SORTED_Y_*`` of the y rows from ``Y`` on too; the others are recomputed after it. Every
particle has three components (x, y, z): a 2D scene (the vertical plane x-z) keeps its y rows
zero, never sorts or reads them, and every term it adds is exactly zero. The y rows come last,
so a 2D particle's rows 0..25 are those of the 2D-only layout (and its checkpoints). Kernels
name rows, never positions.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

# particle kinds
FLUID = 0
WALL = 1
INLET = 2      # active open-boundary buffer particle of the left end (open_boundary.py)
OUTLET = 3     # ... of the right end
INACTIVE = -1  # a free slot inside [0, n): skipped by every pass, sorted to the end

# float rows, carried through reordering
X, Z, VX, VZ, AX, AZ, RHO, P, M = range(9)
# state at the start of a step, used by the two-pass symplectic predictor-corrector only
XN, ZN, VXN, VZN, RHON = range(9, 14)
# recomputed after every reorder: density rate, wall velocity for viscous terms (Adami no-slip)
DRHO, VWX, VWZ = range(14, 17)
# Riemann SPH with MUSCL (riemann.py, 2D): gradients of p, vx, vz of fluid and buffer particles,
# recomputed before every force pass
GPX, GPZ, GUX, GUZ, GWX, GWZ = range(17, 23)
# no-penetration velocity correction of fluid particles at a wall face (wall_contact.py),
# recomputed in every force pass and added by the kick / corrector
DVNX, DVNZ = range(23, 25)
# fluid: the pressure its wall neighbours feel from it, p or max(p, 0) (wcsph.fluid_pass), read
# by the body loads so they are the reaction of what the fluid felt (not carried by a sort)
PW = 25
# the y components (3D scenes; zero in 2D): carried y, vy, ay (and yn, vyn of the
# predictor-corrector), recomputed vwy, dvny
Y, VY, AY, YN, VYN, VWY, DVNY = range(26, 33)
N_FIELDS = 33
N_SORTED_KDK = 9
N_SORTED_PC = 14
N_SORTED_Y_KDK = 3     # y, vy, ay
N_SORTED_Y_PC = 5      # ... yn, vyn

FIELD_NAMES = ("x", "z", "vx", "vz", "ax", "az", "rho", "p", "m",
               "xn", "zn", "vxn", "vzn", "rhon", "drho", "vwx", "vwz",
               "gpx", "gpz", "gux", "guz", "gwx", "gwz", "dvnx", "dvnz", "pw",
               "y", "vy", "ay", "yn", "vyn", "vwy", "dvny")


@dataclass
class Checkpoint:
    """An exact copy of a particle set and its clock."""

    f: np.ndarray
    kind: np.ndarray
    ids: np.ndarray
    n: int
    next_id: int
    t: float
    dt: float
    steps: int
    cell: np.ndarray | None = None        # cell lists of the copy (set by the Simulation), so a
    cell_start: np.ndarray | None = None  # restore needs no re-sort and continues bit for bit
    open_state: Any = None                # open_ends.OpenState of a run with open ends
    body_state: Any = None                # bodies.BodySet state (q, qd, acc, load) of a run with bodies


class ParticleSet:
    """Structure-of-arrays particle storage with twin buffers and spare capacity."""

    def __init__(self, capacity: int, dtype: Any = np.float64) -> None:
        if capacity <= 0:
            raise ValueError(f"capacity: must be > 0, got {capacity}")
        self.capacity = int(capacity)
        # float32 stores half the bytes; the kernels compile for either and compute in float64
        # wherever a float64 operand (dt, h, Params) enters (docs/studies/float32_storage.md)
        self.f = np.zeros((N_FIELDS, self.capacity), dtype=np.dtype(dtype))
        self.f2 = np.zeros_like(self.f)
        self.kind = np.full(self.capacity, INACTIVE, dtype=np.int8)
        self.kind2 = self.kind.copy()
        self.ids = np.full(self.capacity, -1, dtype=np.int64)
        self.ids2 = self.ids.copy()
        self.cell = np.zeros(self.capacity, dtype=np.int64)
        self.cell2 = np.zeros(self.capacity, dtype=np.int64)
        self.n = 0
        self.next_id = 0
        self._views()

    def _views(self) -> None:
        from .state import particles_view

        self.view = particles_view(self.f, self.kind, self.ids, self.cell)
        self.view2 = particles_view(self.f2, self.kind2, self.ids2, self.cell2)

    def add(self, x: np.ndarray, z: np.ndarray, kind: int, rho: np.ndarray, mass: np.ndarray,
            y: np.ndarray | float = 0.0) -> np.ndarray:
        """Append particles at rest at (x, y, z) (y 0: a 2D scene); return their ids."""
        x = np.asarray(x, dtype=float)
        k = x.size
        if self.n + k > self.capacity:
            raise ValueError(f"capacity: {self.capacity} too small for {self.n + k} particles")
        s = slice(self.n, self.n + k)
        self.f[:, s] = 0.0
        self.f[X, s] = x
        self.f[Y, s] = y
        self.f[Z, s] = z
        self.f[RHO, s] = rho
        self.f[M, s] = mass
        self.kind[s] = kind
        new_ids = np.arange(self.next_id, self.next_id + k, dtype=np.int64)
        self.ids[s] = new_ids
        self.n += k
        self.next_id += k
        return new_ids

    def swap(self) -> None:
        """Exchange the live arrays with their twins (after a reorder into the twins)."""
        self.f, self.f2 = self.f2, self.f
        self.kind, self.kind2 = self.kind2, self.kind
        self.ids, self.ids2 = self.ids2, self.ids
        self.cell, self.cell2 = self.cell2, self.cell
        self.view, self.view2 = self.view2, self.view

    def field(self, row: int) -> np.ndarray:
        """View of one field over the slots in use."""
        return self.f[row, : self.n]

    def mask(self, kind: int) -> np.ndarray:
        return self.kind[: self.n] == kind

    def count(self, kind: int) -> int:
        return int(np.count_nonzero(self.mask(kind)))

    def snapshot(self, t: float, dt: float, steps: int) -> Checkpoint:
        n = self.n
        return Checkpoint(self.f[:, :n].copy(), self.kind[:n].copy(), self.ids[:n].copy(),
                          n, self.next_id, t, dt, steps)

    def restore(self, c: Checkpoint) -> None:
        if c.n > self.capacity:
            raise ValueError("checkpoint: more particles than this set's capacity")
        rows = c.f.shape[0]
        # a checkpoint of an older version has fewer rows: the ones it lacks are per-step
        # scratch (gradients, correction matrices) or the y rows of a 2D run, zero
        if not N_SORTED_PC <= rows <= N_FIELDS:
            raise ValueError(f"checkpoint: {rows} particle fields, this version reads "
                             f"{N_SORTED_PC}..{N_FIELDS}")
        self.f[:rows, : c.n] = c.f
        self.f[rows:, : c.n] = 0.0
        self.kind[: c.n] = c.kind
        self.kind[c.n:] = INACTIVE
        self.ids[: c.n] = c.ids
        self.n = c.n
        self.next_id = c.next_id
