"""HTTP request and response bodies."""

from __future__ import annotations

import json
import math
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from sph_core.geometry import wall_layers
from sph_core.scene import Scene

from .theory_source import TheorySource


class RunCouplingOptions(BaseModel):
    """The `coupling` part of POST /runs (the client's own options are wave_client's)."""

    model_config = ConfigDict(extra="forbid")

    window_max: float = Field(0.05, gt=0, description="longest coupling window the client may use [s]")
    z_ref: float | None = Field(None, le=0, description="reference level of returned velocities, up "
                                                        "from still water [m]; default -depth/2")


class RunRequest(BaseModel):
    """POST /runs body: the SPH scene and how the run is driven."""

    model_config = ConfigDict(extra="forbid")

    scene: Scene
    mode: Literal["coupled", "standalone"] = Field(
        "coupled", description="coupled: wait for a client on /runs/{id}/couple or the TCP port; "
                               "standalone: run the scene as it is (open ends: driven by `source`)")
    coupling: RunCouplingOptions = RunCouplingOptions()
    source: TheorySource | None = Field(None, description="built-in wave theory driving the open "
                                                          "ends of a standalone run")


# RunInfo.state's values, part of the HTTP surface: a client polling GET /runs/{id} waits for a
# state in TERMINAL (the run manager sets them)
QUEUED, WAITING, RUNNING = "queued", "waiting_for_client", "running"
FINISHED, CANCELLED, FAILED, UNSTABLE = "finished", "cancelled", "failed", "unstable"
TERMINAL = frozenset({FINISHED, CANCELLED, FAILED, UNSTABLE})


class RunInfo(BaseModel):
    """GET /runs/{id}. ``status`` is ``state`` plus the reason, e.g. 'failed: client disconnected'."""

    id: str
    name: str = ""              # the scene's name (runs of one scene share it; the id tells them apart)
    mode: str
    device: str = "cpu"         # where the SPH steps run (the scene's [run] device)
    state: str
    status: str
    reason: str | None = None
    detail: str | None = None   # what a started run does before it shows progress (building, compiling)
    created: float
    started: float | None = None
    ended: float | None = None
    queue_position: int | None = None
    t: float = 0.0
    t_end: float
    steps: int = 0
    windows: int = 0
    particles: int | None = None
    particle_steps_per_s: float | None = None
    coupling_overhead_share: float | None = None
    stability: dict[str, Any] = {}
    last_gauges: dict[str, float | None] = {}
    client: str | None = None
    resumable: bool = False     # a coupled run that stopped early with its state saved
    resumed: int = 0            # how many times the run was resumed
    scene_hash: str
    gauges_file: str | None = None
    # the serving process's TCP coupling port (PROTOCOL.md, Transports), set on the copy each
    # reply sends: a property of the server, not of the run (null in meta.json)
    tcp_port: int | None = Field(None, description="the server's TCP coupling port (null: the "
                                 "port is disabled); WebSocket clients use /runs/{id}/couple")


def canonical_scene(scene: Scene) -> bytes:
    """The bytes the protocol's scene hash is taken of (PROTOCOL.md, HELLO)."""
    return json.dumps(scene.model_dump(mode="json"), sort_keys=True, separators=(",", ":")).encode()


def estimate_particles(scene: Scene) -> float:
    """Upper estimate of fluid + wall particles, without building them (for the cap); math.inf
    when it overflows a float (a 1e308 m tank, a dp of 5e-324 m): never raises."""
    dp, t = scene.dp, scene.tank
    if scene.dim == 3:
        return _estimate_particles_3d(scene)
    # (a / dp) / dp, not a / dp**2: dp**2 underflows to 0 for a tiny dp; float * and / give inf
    # on overflow where ** and ceil would raise
    fluid = sum((b.x1 - b.x0) * (b.z1 - b.z0) / dp / dp for b in scene.water_blocks)
    layers = wall_layers(scene)
    walls = layers * (2 * (t.z1 - t.z0) + (t.x1 - t.x0)) / dp + 4 * layers * layers
    for bed in scene.beds:
        length = sum(math.dist(a, b) for a, b in zip(bed.points, bed.points[1:]))
        walls += layers * length / dp
    for s in scene.structures:
        walls += layers * 2 * ((s.x1 - s.x0) + (s.z1 - s.z0)) / dp
    n = fluid + walls
    return float(math.ceil(n)) if math.isfinite(n) else math.inf


def _estimate_particles_3d(scene: Scene) -> float:
    """estimate_particles of a 3D scene: volumes over dp^3, wall shells of ``layers`` over dp^2
    (the tank's box grown by its walls: the edges and corners counted)."""
    dp, t = scene.dp, scene.tank
    th = wall_layers(scene) * dp
    fluid = sum((b.x1 - b.x0) / dp * (b.y1 - b.y0) / dp * (b.z1 - b.z0) / dp
                for b in scene.water_blocks)
    lx, ly, lz = (t.x1 - t.x0) + 2 * th, (t.y1 - t.y0) + 2 * th, (t.z1 - t.z0) + th
    walls = th / dp * (lx * ly + 2 * lz * (lx + ly)) / dp / dp
    for bed in scene.beds:
        length = sum(math.dist(a, b) for a, b in zip(bed.points, bed.points[1:]))
        walls += th / dp * length / dp * ly / dp
    for s in scene.structures:
        a, b, c = s.x1 - s.x0, s.y1 - s.y0, s.z1 - s.z0
        walls += th / dp * 2 * (a * b + b * c + a * c) / dp / dp
    n = fluid + walls
    return float(math.ceil(n)) if math.isfinite(n) else math.inf
