"""/runs: create, list, inspect, cancel runs; their gauges, scene and a live event stream."""

from __future__ import annotations

import asyncio
import json
from typing import Literal

from fastapi import APIRouter, HTTPException, Query, Response
from fastapi.responses import FileResponse, StreamingResponse

from ..deps import Auth, Manager, RunDep
from ..runs import TERMINAL
from ..schemas import RunInfo, RunRequest, estimate_particles
from ..store import read_gauges
from ..theory_source import source_errors

router = APIRouter(prefix="/runs", tags=["runs"], dependencies=[Auth])

EVENT_POLL_S = 0.25


def _unprocessable(loc: list[str], msg: str) -> HTTPException:
    """A 422 shaped like FastAPI's own validation errors, naming the field."""
    return HTTPException(422, [{"loc": loc, "msg": msg, "type": "value_error"}])


@router.post("", status_code=201, response_model=RunInfo)
async def create_run(body: RunRequest, manager: Manager) -> RunInfo:
    """Create a run from a scene. Coupled runs wait for a client on `/runs/{id}/couple` (WebSocket)
    or the TCP coupling port; standalone runs start stepping when a slot is free."""
    n = estimate_particles(body.scene)
    cap = manager.settings.max_particles
    if n > cap:
        raise _unprocessable(["body", "scene", "dp"],
                             f"the scene needs about {n:.3g} particles, the server's cap is {cap:.3g}: "
                             f"increase dp or shrink the tank and water blocks")
    if body.mode == "coupled" and not body.scene.open_boundaries:
        raise _unprocessable(["body", "scene", "open_boundaries"],
                             "a coupled run needs at least one open end for the client to drive")
    for loc, msg in source_errors(body.scene, body.mode, body.source, body.coupling.window_max):
        raise _unprocessable(["body", *loc], msg)
    return manager.submit(body).info


@router.get("", response_model=list[RunInfo])
async def list_runs(manager: Manager) -> list[RunInfo]:
    """Every run this server knows, including finished runs of earlier server processes."""
    return sorted((r.info for r in manager.runs.values()), key=lambda i: i.created)


@router.get("/{run_id}", response_model=RunInfo)
async def get_run(run: RunDep) -> RunInfo:
    return run.info


@router.get("/{run_id}/scene")
async def get_scene(run: RunDep) -> Response:
    """The canonical scene bytes: the protocol's scene hash is their SHA-256."""
    return Response(run.scene_bytes, media_type="application/json")


@router.get("/{run_id}/gauges")
async def get_gauges(run: RunDep, format: Literal["csv", "json"] = Query("csv")) -> Response:
    """Gauge series as CSV (dry gauges written `dry`) or JSON (`null` where dry)."""
    path = run.dir / (run.info.gauges_file or "gauges.csv")
    if not path.exists():
        raise HTTPException(404, f"run {run.info.id} has no gauge data yet")
    if format == "csv":
        return FileResponse(path, media_type="text/csv", filename=f"{run.info.id}-gauges.csv")
    columns, rows = await asyncio.to_thread(read_gauges, path)
    return Response(json.dumps({"columns": columns, "rows": rows}), media_type="application/json")


@router.get("/{run_id}/bodies")
async def get_bodies(run: RunDep, format: Literal["csv", "json"] = Query("csv")) -> Response:
    """Rigid-body series (sph_core bodies.csv: per body x, z, theta, u, w, omega, fx, fz, my) as
    CSV or JSON; 404 if the scene has no bodies. A coupled run restarted into sph.<k>/ serves the
    newest."""
    paths = sorted(run.dir.glob("sph*/bodies.csv"), key=lambda p: p.stat().st_mtime)
    if not paths:
        raise HTTPException(404, f"run {run.info.id} has no body data")
    if format == "csv":
        return FileResponse(paths[-1], media_type="text/csv", filename=f"{run.info.id}-bodies.csv")
    columns, rows = await asyncio.to_thread(read_gauges, paths[-1])
    return Response(json.dumps({"columns": columns, "rows": rows}), media_type="application/json")


@router.delete("/{run_id}", response_model=RunInfo)
async def cancel_run(run: RunDep, manager: Manager) -> RunInfo:
    """Cancel a queued, waiting or running run; its data so far stays on disk."""
    manager.cancel(run)
    for _ in range(40):  # give a waiting or coupled run a moment to settle into `cancelled`
        if run.info.state in TERMINAL:
            break
        await asyncio.sleep(0.05)
    return run.info


@router.post("/{run_id}/resume", status_code=202, response_model=RunInfo)
async def resume_run(run: RunDep, manager: Manager) -> RunInfo:
    """Queue a coupled run that failed or was cancelled again, from its last saved window
    boundary (`resumable` in its record); a client then couples from WELCOME's t_start."""
    try:
        manager.resume(run)
    except ValueError as exc:
        raise HTTPException(409, str(exc)) from None
    return run.info


@router.get("/{run_id}/events")
async def run_events(run: RunDep) -> StreamingResponse:
    """Server-Sent Events: a `progress` event with the run record whenever it changes; the
    stream ends after the event that shows a final state."""

    async def stream():
        last = None
        while True:
            data = run.info.model_dump_json()
            if data != last:
                last = data
                yield f"event: progress\ndata: {data}\n\n"
            if run.info.state in TERMINAL:
                return
            await asyncio.sleep(EVENT_POLL_S)

    return StreamingResponse(stream(), media_type="text/event-stream",
                             headers={"Cache-Control": "no-cache"})
