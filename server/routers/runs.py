"""/runs: create, list, inspect, cancel runs; their gauges, scene and a live event stream."""

from __future__ import annotations

import asyncio
import json
import math
from pathlib import Path
from typing import Literal

from fastapi import APIRouter, HTTPException, Query, Request, Response
from fastapi.responses import FileResponse, StreamingResponse
from starlette.requests import ClientDisconnect

from ..deps import Auth, Manager, RunDep
from ..run_manager import QueueFull, Run
from ..schemas import TERMINAL, RunInfo
from ..store import read_gauge_rows
from ..validation import BodyNotJson, RequestInvalid, parse_run_request

router = APIRouter(prefix="/runs", tags=["runs"], dependencies=[Auth], responses={
    401: {"description": "missing or wrong API token (Authorization: Bearer <token>)"}})

EVENT_POLL_S = 0.25
RETRY_AFTER_S = 30  # what a refused POST is told to wait: about one short run


def _with_port(info: RunInfo, request: Request) -> RunInfo:
    """``info`` as sent: with this server's TCP coupling port, so clients can find it."""
    return info.model_copy(update={"tcp_port": getattr(request.app.state, "tcp_port", None)})


def _queue_full(exc: QueueFull) -> HTTPException:
    return HTTPException(429, str(exc), headers={"Retry-After": str(RETRY_AFTER_S)})


def _detail(description: str) -> dict:
    return {"description": description, "content": {"application/json": {"schema": {
        "type": "object", "properties": {"detail": {}}}}}}


NOT_FOUND = {404: _detail("no such run")}


DRAIN_BODIES = 64   # an oversized body is read and dropped up to this many max_body ...
DRAIN_S = 5.0       # ... and this many seconds, so that its 413 reaches the client


async def _drain(request: Request, budget: int) -> None:
    """Read and drop the rest of the body, bounded. A client that writes the whole body before
    it reads (Python's urllib) would otherwise get a connection reset instead of the 413: the
    kernel resets a socket closed with unread data."""
    try:
        async with asyncio.timeout(DRAIN_S):
            async for chunk in request.stream():
                budget -= len(chunk)
                if budget < 0:
                    return
    except (TimeoutError, ClientDisconnect):
        pass


async def _read_body(request: Request, limit: int) -> bytes:
    """The body, refused (413) as soon as it exceeds ``limit`` bytes, declared or streamed."""
    declared = request.headers.get("content-length")
    close = {"Connection": "close"}
    if declared is not None and declared.isdigit() and int(declared) > limit:
        if int(declared) <= DRAIN_BODIES * limit:
            await _drain(request, DRAIN_BODIES * limit)
        raise HTTPException(413, f"the body has {declared} bytes, the server's max_body is {limit}",
                            headers=close)
    chunks, size = [], 0
    async for chunk in request.stream():
        size += len(chunk)
        if size > limit:
            await _drain(request, DRAIN_BODIES * limit - size)
            raise HTTPException(413, f"the body exceeds the server's max_body of {limit} bytes",
                                headers=close)
        chunks.append(chunk)
    return b"".join(chunks)


@router.post("", status_code=201, response_model=RunInfo, openapi_extra={"requestBody": {
    "required": True, "content": {
        "application/json": {"schema": {"$ref": "#/components/schemas/RunRequest"}},
        # a scene file as it is: its mode, [coupling] and [source] tables beside the scene
        "application/toml": {"schema": {"type": "string"}}}}},
             responses={400: _detail("the body is not JSON (or not TOML, with Content-Type "
                                     "application/toml)"),
                        413: _detail("the body exceeds max_body"),
                        415: _detail("the Content-Type is not application/json or application/toml"),
                        422: _detail("a field, or a rule across fields, is not met: `detail` lists "
                                     "loc, msg, type (never the input); numbers must be finite; "
                                     "the scene within max_particles and max_probes; "
                                     "mode 'coupled' needs open_boundaries; 'source' only for a "
                                     "standalone run with open_boundaries (and required there); "
                                     "coupling.z_ref in the water column; windows at most 1e7"),
                        429: _detail("the queue is full (max_queued); see Retry-After"),
                        507: _detail("the run store cannot write (disk full)")})
async def create_run(request: Request, manager: Manager) -> RunInfo:
    """Create a run from a scene (body: RunRequest as JSON, or a scene file as TOML with
    Content-Type application/toml: its mode, [coupling] and [source] tables beside the
    scene; without a mode it is standalone if it has a source or no open end). Coupled runs
    wait for a client on
    `/runs/{id}/couple` (WebSocket) or the TCP coupling port; standalone runs start stepping when
    a slot is free. Everything the run needs is checked before the 201."""
    kind = request.headers.get("content-type", "").split(";")[0].strip().lower()
    if "json" not in kind and "toml" not in kind:
        # text/plain, a form or none: what a web page may send without asking (CSRF)
        raise HTTPException(415, "Content-Type must be application/json (a RunRequest) or "
                                 "application/toml (a scene file)")
    raw = await _read_body(request, manager.settings.max_body)
    try:  # parsing and validation off the event loop: a big scene never stalls other requests
        body = await asyncio.to_thread(parse_run_request, raw, manager.settings,
                                       "toml" in request.headers.get("content-type", ""))
    except BodyNotJson as exc:
        raise HTTPException(400, str(exc)) from None
    except RequestInvalid as exc:
        raise HTTPException(422, exc.errors) from None
    try:
        return _with_port(manager.submit(body).info, request)
    except QueueFull as exc:
        raise _queue_full(exc) from None
    except OSError as exc:  # the store cannot write (disk full): say so, no 500
        raise HTTPException(507, f"the run store cannot write: {exc.strerror or exc}") from None


@router.get("", response_model=list[RunInfo])
async def list_runs(manager: Manager, request: Request) -> list[RunInfo]:
    """Every run this server knows, including finished runs of earlier server processes."""
    return [_with_port(i, request) for i in sorted((r.info for r in manager.runs.values()),
                                                   key=lambda i: i.created)]


@router.get("/{run_id}", response_model=RunInfo, responses=NOT_FOUND)
async def read_run(run: RunDep, request: Request) -> RunInfo:
    return _with_port(run.info, request)


@router.get("/{run_id}/scene", responses=NOT_FOUND)
async def get_scene(run: RunDep) -> Response:
    """The canonical scene bytes: the protocol's scene hash is their SHA-256."""
    return Response(run.scene_bytes, media_type="application/json")


@router.get("/{run_id}/gauges", responses={404: _detail("no such run, or no gauge data yet")})
async def get_gauges(run: RunDep, format: Literal["csv", "json"] = Query("csv")) -> Response:
    """Gauge series as CSV (a dry gauge an empty field) or JSON (`null` where dry)."""
    path = run.dir / (run.info.gauges_file or "gauges.csv")
    if not path.is_file():  # a directory in its place (a damaged store) is no data either
        raise HTTPException(404, f"run {run.info.id} has no gauge data yet")
    return await _table(path, f"{run.info.id}-gauges.csv", format)


async def _table(path: Path, filename: str, format: str) -> Response:
    """A CSV record of the run as the file itself (``filename``) or as JSON columns and rows."""
    if format == "csv":
        return FileResponse(path, media_type="text/csv", filename=filename)
    columns, rows = await asyncio.to_thread(read_gauge_rows, path)
    return Response(json.dumps({"columns": columns, "rows": rows}), media_type="application/json")


async def _newest_sph_table(run: Run, name: str, missing: str, format: str) -> Response:
    """The SPH side's ``<name>.csv`` (a coupled run restarted into sph.<k>/ has several: the
    newest) through _table; 404 "run <id> <missing>" where there is none."""
    paths = sorted(run.dir.glob(f"sph*/{name}.csv"), key=lambda p: p.stat().st_mtime)
    if not paths:
        raise HTTPException(404, f"run {run.info.id} {missing}")
    return await _table(paths[-1], f"{run.info.id}-{name}.csv", format)


@router.get("/{run_id}/probes", responses=NOT_FOUND)
async def get_probes(run: RunDep, format: Literal["csv", "json"] = Query("csv")) -> Response:
    """Every probe of the SPH side (sph_core probes.csv: elevation, point, front, force,
    pressure-line and overtopping columns) as CSV or JSON; a coupled run restarted into
    sph.<k>/ serves the newest. /gauges is the coupling gauges' record."""
    return await _newest_sph_table(run, "probes", "has no probe data yet", format)


@router.get("/{run_id}/bodies", responses=NOT_FOUND)
async def get_bodies(run: RunDep, format: Literal["csv", "json"] = Query("csv")) -> Response:
    """Rigid-body series (sph_core bodies.csv: per body x, z, theta, u, w, omega, fx, fz, my) as
    CSV or JSON; 404 if the scene has no bodies. A coupled run restarted into sph.<k>/ serves the
    newest."""
    return await _newest_sph_table(run, "bodies", "has no body data", format)


MAX_SCATTER = 40_000   # particles sent to the page's scatter (every k-th beyond it)


def _last_particles(run_dir, field: str, y_at: float | None = None) -> dict | None:
    import numpy as np

    paths = sorted(run_dir.glob("sph*/snapshots/last.npz"), key=lambda p: p.stat().st_mtime)
    if not paths:
        return None
    with np.load(paths[-1], allow_pickle=False) as z:
        x, zz, value, kind = z["x"], z["z"], z[field], z["kind"]
        t = float(z["t"])
        y = z["y"] if "y" in z.files else None
        h = float(z["h"]) if "h" in z.files else 0.0
    cut = None
    if y is not None and np.ptp(y) > 0:   # a 3D run: the slice |y - y_at| <= h
        fluid = y[kind == 0] if np.any(kind == 0) else y
        y_at = float(0.5 * (fluid.min() + fluid.max())) if y_at is None else y_at
        sel = np.abs(y - y_at) <= h
        x, zz, value, kind = x[sel], zz[sel], value[sel], kind[sel]
        cut = {"y": round(y_at, 6), "half_width": round(h, 6)}
    stride = max(1, -(-x.size // MAX_SCATTER))
    r = lambda a: [round(float(v), 6) for v in a[::stride]]  # noqa: E731
    return {"t": t, "field": field, "stride": stride, "x": r(x), "z": r(zz), "value": r(value),
            "kind": [int(k) for k in kind[::stride]], "slice": cut}


@router.get("/{run_id}/particles", responses={**NOT_FOUND, 404: _detail(
    "no run, or no snapshot yet (the scene's output.snapshot_every)")})
async def get_particles(run: RunDep, field: Literal["pressure", "speed"] = Query("pressure"),
                        y: float | None = Query(None, description=(
                            "3D runs: the y [m] of the x-z slice (default: the fluid's mid-width)"))
                        ) -> Response:
    """The newest snapshot's particles for a scatter plot: t [s], x, z [m], `value` (pressure
    [Pa] or speed [m/s]) and `kind` (0 fluid, 1 wall/bed/structure, 2/3 open-end buffers), at
    most 40 000 (every `stride`-th beyond that). A 3D run's are the slice within h of `y`
    (`slice`: its y and half-width; null for a 2D run)."""
    if y is not None and not math.isfinite(y):
        raise HTTPException(422, "y: must be a finite number [m]")
    data = await asyncio.to_thread(_last_particles, run.dir, field, y)
    if data is None:
        raise HTTPException(404, f"run {run.info.id} has no snapshot yet (set the scene's "
                                 "output.snapshot_every)")
    return Response(json.dumps(data), media_type="application/json")


@router.delete("/{run_id}", response_model=RunInfo, responses=NOT_FOUND)
async def cancel_run(run: RunDep, manager: Manager) -> RunInfo:
    """Cancel a queued, waiting or running run; its data so far stays on disk."""
    manager.cancel(run)
    for _ in range(40):  # give a waiting or coupled run a moment to settle into `cancelled`
        if run.info.state in TERMINAL:
            break
        await asyncio.sleep(0.05)
    return run.info


@router.post("/{run_id}/resume", status_code=202, response_model=RunInfo, responses={
    **NOT_FOUND, 409: _detail("the run is not resumable"), 429: _detail("the queue is full")})
async def resume_run(run: RunDep, manager: Manager) -> RunInfo:
    """Queue a coupled run that failed or was cancelled again, from its last saved window
    boundary (`resumable` in its record); a client then couples from WELCOME's t_start."""
    try:
        if not await asyncio.to_thread(manager.state_intact, run):
            manager.save(run)
        manager.resume(run)
    except QueueFull as exc:
        raise _queue_full(exc) from None
    except ValueError as exc:
        raise HTTPException(409, str(exc)) from None
    return run.info


@router.get("/{run_id}/events", responses=NOT_FOUND)
async def run_events(run: RunDep, request: Request) -> StreamingResponse:
    """Server-Sent Events: a `progress` event with the run record whenever it changes; the
    stream ends after the event that shows a final state, or when the server is stopping (the
    page reconnects to the next server)."""
    stopping = getattr(request.app.state, "stopping", None)

    async def stream():
        last = None
        while True:
            data = run.info.model_dump_json()
            if data != last:
                last = data
                yield f"event: progress\ndata: {data}\n\n"
            if run.info.state in TERMINAL or (stopping is not None and stopping.is_set()):
                return
            await asyncio.sleep(EVENT_POLL_S)

    return StreamingResponse(stream(), media_type="text/event-stream",
                             headers={"Cache-Control": "no-cache"})
