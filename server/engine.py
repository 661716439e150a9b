"""The SPH side of a coupled run, as the coupling doors see it.

A coupled run drives an object with this interface. The doors (WebSocket, TCP) speak the
protocol and call it from a worker thread, never on the event loop; per window they call
``checkpoint()`` (when the client may GOBACK), ``set_window(...)`` and ``solve_window()`` in one
worker call. The production engine is server/flume_engine.py (an sph_core Simulation with open ends); the tests
of the doors use a deterministic double. ``solve_window`` raises protocol.ProtocolError
(BAD_VALUE) for boundary data the solver cannot use, UnstableError when the run blows up.

An engine with a ``cancel`` attribute gets the run's cancel flag (a threading.Event) there
once built; its ``solve_window`` checks it between chunks of steps and raises SolveCancelled
(the flume once the window has solved 2 s: a short window still ends on its boundary), so
DELETE or a server stop ends even a window that takes hours.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Protocol

import numpy as np

from .schemas import RunRequest


class SolveCancelled(Exception):
    """The run was cancelled while its engine solved a window (state mid-window: not saved)."""


@dataclass(frozen=True)
class SceneSummary:
    """What WELCOME tells the client (PROTOCOL.md, WELCOME). SI units."""

    g: float                  # [m/s^2]
    depth: float              # still-water depth at the inlet [m]
    still_water_level: float  # absolute z of the still-water level [m]
    z_ref: float              # reference level of RESULT velocities, up from still water [m]
    t_start: float            # [s]
    t_end: float              # [s]
    dt_sph: float             # nominal SPH step [s]


@dataclass(frozen=True)
class EngineNodes:
    """Boundary nodes (z up from still water) and gauges, in the order of every array."""

    x: np.ndarray
    z: np.ndarray
    side: np.ndarray           # 0 inlet, 1 outlet (2, 3: columns inside their relaxation zones)
    gauge_x: np.ndarray
    gauge_names: list[str] = field(default_factory=list)
    gauge_kind: np.ndarray | None = None   # protocol.GaugeKind per gauge; None: all probes
    eta_gauge: tuple[int, int] = (0xFFFFFFFF, 0xFFFFFFFF)  # per side: the gauge its absorber reads


@dataclass(frozen=True)
class Measurement:
    """Gauge readings at the engine's current time; eta/u_ref/w_ref are 0 where dry."""

    eta: np.ndarray            # [m] above still water
    wet: np.ndarray            # bool
    u_ref: np.ndarray          # [m/s] at z_ref
    w_ref: np.ndarray          # [m/s] at z_ref
    steps: int = 0             # SPH sub-steps of the window just solved


class CouplingEngine(Protocol):
    summary: SceneSummary
    t: float                   # current time [s]
    steps: int                 # SPH steps since the start
    n_particles: int

    def nodes(self) -> EngineNodes: ...
    # optional (protocol 1.2, ZONE_NODES): ``zone_nodes() -> EngineNodes | None``, the nodes
    # followed by the columns inside the relaxation zones (sides 2, 3); a SET of that many
    # nodes gives the zones their local targets (server/flume_engine.py)
    def set_window(self, t0: float, t1: float, u: np.ndarray, w: np.ndarray, eta: np.ndarray) -> None:
        """Boundary values at t1; the values in force at t0 are those of the previous window."""
    def solve_window(self) -> Measurement:
        """Advance from t0 to t1, interpolating boundary values linearly in time."""
    def measure(self) -> Measurement: ...
    def checkpoint(self) -> None:
        """Remember the state (particles, clock, boundary values in force) for ``goback``."""
    def goback(self) -> None: ...
    def stability(self) -> dict[str, float]:
        """Figures such as dt, v_max/c0, mass drift, for GET /runs/{id}."""
    def save_state(self, path: Path) -> None:
        """Write the state at the current window boundary to ``path`` (for resuming the run)."""
    def load_state(self, path: Path) -> None:
        """Continue from a state written by ``save_state`` (t, particles, boundary values)."""
    def close(self) -> None: ...


EngineFactory = Callable[[RunRequest, Path], CouplingEngine]
