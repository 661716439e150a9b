"""Boundary data of an open SPH boundary: what a wave source imposes at an inlet or outlet.

    nodes = BoundaryNodes(side="left", x_face=0.0, z=z_levels, z_bed=0.0, z_top=1.5)
    src = WaveModelBoundary(model, nodes, still_water_level=1.0, x_model=0.0)   # in-process theory
    s = src.sample(t)          # BoundarySample(t, u, w, eta, eta_gauge), validated

A source is any object with ``nodes`` and ``sample(t) -> BoundarySample``. The solver samples it
at the ends of each coupling window and interpolates linearly in time inside the window (seed 001,
Algorithm 2); data pushed from outside (the coupling server) come as BoundarySamples to
``Simulation.advance_window``.

Datum: ``BoundaryNodes.z`` are absolute SPH heights [m] (z up, tank floor usually 0). Wave models
measure z up from the still-water level; ``WaveModelBoundary`` converts, z_model = z - swl.
``eta`` is the target elevation [m] above the still-water level at the face; ``eta_gauge`` the
source's elevation at the boundary gauge (x_gauge), against which the measured one is compared in
the absorption correction of seed 002.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Literal, Protocol, runtime_checkable

import numpy as np


class BoundaryDataError(ValueError):
    """Boundary data are unusable (non-finite, wrong length, elevation outside the tank...)."""


@dataclass(frozen=True)
class BoundaryNodes:
    """Where a boundary wants data: the face x, the z levels of the velocity profile, the gauge.

    z: strictly increasing absolute heights [m] within [z_bed, z_top]; x_gauge: where the
    boundary gauge measures the elevation (inside the fluid)."""

    side: Literal["left", "right"]
    x_face: float
    z: np.ndarray
    z_bed: float
    z_top: float
    x_gauge: float = math.nan

    def __post_init__(self) -> None:
        if self.side not in ("left", "right"):
            raise BoundaryDataError(f"side: must be 'left' or 'right', got {self.side!r}")
        z = np.ascontiguousarray(self.z, dtype=float)
        object.__setattr__(self, "z", z)
        if z.ndim != 1 or z.size < 2:
            raise BoundaryDataError(f"z: need a 1-D array of at least 2 levels, got shape "
                                    f"{z.shape}")
        if not np.all(np.isfinite(z)) or not np.all(np.diff(z) > 0):
            raise BoundaryDataError("z: levels must be finite and strictly increasing")
        if not self.z_top > self.z_bed:
            raise BoundaryDataError(f"z_top: must exceed z_bed = {self.z_bed}, got {self.z_top}")
        if z[0] < self.z_bed - 1e-12 or z[-1] > self.z_top + 1e-12:
            raise BoundaryDataError(f"z: levels must lie within [z_bed, z_top] = "
                                    f"[{self.z_bed}, {self.z_top}]")

    @property
    def size(self) -> int:
        return int(self.z.size)


@dataclass(frozen=True)
class BoundarySample:
    """Data at one instant: velocity (u, w) [m/s] at the nodes, target elevation eta [m] above
    still water at the face, and the source's elevation at the boundary gauge (default: eta)."""

    t: float
    u: np.ndarray
    w: np.ndarray
    eta: float
    eta_gauge: float = field(default=math.nan)

    @property
    def gauge_eta(self) -> float:
        return self.eta if math.isnan(self.eta_gauge) else self.eta_gauge


def validate_sample(s: BoundarySample, nodes: BoundaryNodes, still_water_level: float,
                    where: str = "boundary") -> BoundarySample:
    """Return ``s`` with float arrays, or raise BoundaryDataError naming what is wrong.

    Checks: finite t, u, w, eta; u and w of one value per node; the surface
    still_water_level + eta strictly between the bed and the top of the tank at the boundary."""
    if not isinstance(s, BoundarySample):
        raise BoundaryDataError(f"{where}: expected a BoundarySample, got {type(s).__name__}")
    u = np.ascontiguousarray(s.u, dtype=float)
    w = np.ascontiguousarray(s.w, dtype=float)
    for name, a in (("u", u), ("w", w)):
        if a.shape != (nodes.size,):
            raise BoundaryDataError(f"{where}.{name}: expected {nodes.size} values (one per node), "
                                    f"got shape {a.shape}")
        if not np.all(np.isfinite(a)):
            bad = int(np.nonzero(~np.isfinite(a))[0][0])
            raise BoundaryDataError(f"{where}.{name}: non-finite value {a[bad]} at node {bad} "
                                    f"(z = {nodes.z[bad]:.6g} m)")
    for name in ("t", "eta"):
        v = float(getattr(s, name))
        if not math.isfinite(v):
            raise BoundaryDataError(f"{where}.{name}: must be finite, got {v}")
    if not math.isnan(s.eta_gauge) and not math.isfinite(s.eta_gauge):
        raise BoundaryDataError(f"{where}.eta_gauge: must be finite, got {s.eta_gauge}")
    zs = still_water_level + s.eta
    if not nodes.z_bed < zs < nodes.z_top:
        raise BoundaryDataError(
            f"{where}.eta: surface z = {zs:.6g} m (still_water_level {still_water_level} + eta "
            f"{s.eta:.6g}) outside the tank at the boundary (bed {nodes.z_bed}, top {nodes.z_top})")
    return BoundarySample(float(s.t), u, w, float(s.eta), float(s.eta_gauge))


@runtime_checkable
class BoundaryData(Protocol):
    """A source of boundary data: ``sample(t)`` gives velocity at ``nodes`` and the elevation."""

    nodes: BoundaryNodes

    def sample(self, t: float) -> BoundarySample: ...


def still_sample(nodes: BoundaryNodes, t: float = 0.0) -> BoundarySample:
    """Fluid at rest: zero velocity, zero elevation."""
    return BoundarySample(t, np.zeros(nodes.size), np.zeros(nodes.size), 0.0, 0.0)


class WaveModelBoundary:
    """Adapter from a wave model (``wave_client.model.WaveModel`` duck type) to boundary data.

    The model is evaluated at its own abscissa ``x_model`` for the face and
    ``x_model + (nodes.x_gauge - nodes.x_face)`` for the gauge; z_model = z - still_water_level.
    ``sample(t)`` calls ``model.advance_to(t)``, so calls must come in non-decreasing t for
    models with state (Boussinesq); analytic theories accept any order. Nodes above the model's
    surface get the model's value there (a theory returns the surface velocity)."""

    def __init__(self, model: Any, nodes: BoundaryNodes, still_water_level: float,
                 x_model: float) -> None:
        for attr in ("advance_to", "elevation", "velocity", "depth"):
            if not hasattr(model, attr):
                raise BoundaryDataError(f"model: has no '{attr}' (not a WaveModel)")
        depth = still_water_level - nodes.z_bed
        if abs(float(model.depth) - depth) > 1e-6 * max(depth, 1.0):
            raise BoundaryDataError(
                f"model.depth: {model.depth} m differs from the SPH depth at the {nodes.side} "
                f"boundary, still_water_level - z_bed = {depth:.6g} m")
        self.model = model
        self.nodes = nodes
        self.still_water_level = float(still_water_level)
        self.x_model = float(x_model)
        gx = nodes.x_gauge if math.isfinite(nodes.x_gauge) else nodes.x_face
        self._x_gauge_model = self.x_model + (gx - nodes.x_face)
        # nodes below the model's bed are round-off of the same datum: clamp onto it
        self._z_model = np.maximum(nodes.z - self.still_water_level, -float(model.depth))

    def sample(self, t: float) -> BoundarySample:
        self.model.advance_to(t)
        eta = np.asarray(self.model.elevation(np.array([self.x_model, self._x_gauge_model])),
                         dtype=float)
        u, w = self.model.velocity(self.x_model, self._z_model)
        s = BoundarySample(float(t), np.asarray(u, dtype=float), np.asarray(w, dtype=float),
                           float(eta[0]), float(eta[1]))
        return validate_sample(s, self.nodes, self.still_water_level, where=f"{self.nodes.side}")

    def velocity_along(self, t: float, dx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(u, w)[station, node] at time t at the nodes' heights of columns ``dx`` [m] from the
        face (the model at x_model + dx): the wave inside the SPH domain, for ISPH's relaxation
        zones (open_ends.OpenBoundaries). A model with ``front_factor(x)`` (a theory with a
        start-up ramp, which holds at every x at once) gives the wave as it arrives: the columns
        scaled alike by the front factor at the one nearest the wavemaker, so that a zone ahead
        of the front holds still water and the scaled field stays divergence-free (a factor
        varying along x would add a divergence that ISPH's projection turns into pressure)."""
        self.model.advance_to(t)
        x = self.x_model + np.asarray(dx, dtype=float)[:, None]
        u, w = self.model.velocity(x, self._z_model[None, :])
        shape = (x.shape[0], self.nodes.size)
        front = getattr(self.model, "front_factor", None)
        f = 1.0 if front is None else float(np.asarray(front(x.min()), dtype=float))
        u = np.array(np.broadcast_to(u * f, shape), dtype=float)
        w = np.array(np.broadcast_to(w * f, shape), dtype=float)
        if not (np.all(np.isfinite(u)) and np.all(np.isfinite(w))):
            raise BoundaryDataError(f"{self.nodes.side}: the model's velocity inside the domain "
                                    f"is not finite at t = {t}")
        return u, w
