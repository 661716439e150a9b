"""POST /runs bodies checked for everything a run needs, before the run exists (201 or 4xx).

``parse_run_request`` runs in a worker thread (it parses and validates up to ``max_body`` bytes
and builds the wave source once), never on the event loop. Its errors are FastAPI-shaped
(``loc``, ``msg``, ``type``) and never echo the input: a NaN or a 20 MB string cannot come back.
"""

from __future__ import annotations

import json
import math
import tomllib
from typing import Any

from pydantic import ValidationError

from sph_core.scene import split_scene_file

from .schemas import RunRequest, estimate_particles
from .settings import Settings
from .theory_source import source_errors

MAX_WINDOWS = 10_000_000   # windows of one run: below, window sizes are sane for a clock in float64
MAX_STEPS = 1e9            # time steps of one run (c0 1e300 m/s: steps of 1e-302 s)
MAX_ERRORS = 20            # listed in one 422 reply
MAX_MSG = 500              # characters of one message


class BodyNotJson(ValueError):
    """The body is not JSON at all (HTTP 400)."""


class RequestInvalid(ValueError):
    """The body is JSON but not a run this server can make (HTTP 422); ``errors`` name fields."""

    def __init__(self, errors: list[dict[str, Any]]) -> None:
        super().__init__("; ".join(f"{'.'.join(map(str, e['loc']))}: {e['msg']}" for e in errors))
        self.errors = errors[:MAX_ERRORS]


def error(loc: list[str | int], msg: str, kind: str = "value_error") -> dict[str, Any]:
    return {"loc": ["body", *loc], "msg": msg[:MAX_MSG], "type": kind}


def clean_errors(errors: list[dict[str, Any]], prefix: tuple[str, ...] = ()) -> list[dict[str, Any]]:
    """pydantic/FastAPI errors as loc, msg, type only (no input, no context objects)."""
    return [{"loc": [*prefix, *e.get("loc", ())], "msg": str(e.get("msg", ""))[:MAX_MSG],
             "type": str(e.get("type", "value_error"))} for e in errors[:MAX_ERRORS]]


def _non_finite(value: Any, loc: list[str | int], out: list[dict[str, Any]]) -> None:
    """Every NaN / Infinity (or a number too big for a float, which JSON parsing makes inf)."""
    stack = [(value, loc)]
    while stack and len(out) < MAX_ERRORS:
        v, where = stack.pop()
        if isinstance(v, float) and not math.isfinite(v):
            out.append(error(where, "must be a finite number: NaN, Infinity and numbers beyond "
                                    "±1.8e308 are refused", "finite_number"))
        elif isinstance(v, dict):
            stack.extend((x, [*where, k]) for k, x in reversed(v.items()))
        elif isinstance(v, list):
            stack.extend((x, [*where, i]) for i, x in reversed(list(enumerate(v))))


def request_from_scene_file(data: dict[str, Any]) -> dict[str, Any]:
    """A parsed scene file (TOML) as a RunRequest body: its `mode`, `[coupling]` and `[source]`
    (sph_core.scene.RUN_TABLES) beside the scene. Without a `mode`: standalone if it has a
    source or no open end, else coupled."""
    scene, run = split_scene_file(data)
    mode = "standalone" if "source" in run or not scene.get("open_boundaries") else "coupled"
    return {"scene": scene, "mode": mode, **run}


def parse_run_request(raw: bytes, settings: Settings, toml: bool = False) -> RunRequest:
    """The validated request, or BodyNotJson / RequestInvalid naming what is wrong. ``toml``: the
    body is a scene file (request_from_scene_file), not a JSON RunRequest."""
    try:
        data = request_from_scene_file(tomllib.loads(raw.decode())) if toml else json.loads(raw)
    except (ValueError, RecursionError) as exc:  # TOMLDecodeError and UnicodeDecodeError too
        raise BodyNotJson(f"the body is not {'TOML' if toml else 'JSON'}: {str(exc)[:200]}") from None
    errors: list[dict[str, Any]] = []
    _non_finite(data, [], errors)
    if errors:
        raise RequestInvalid(errors)
    probes = data.get("scene", {}).get("probes") if isinstance(data, dict) and isinstance(
        data.get("scene"), dict) else None
    if isinstance(probes, list) and len(probes) > settings.max_probes:
        raise RequestInvalid([error(["scene", "probes"], f"{len(probes)} probes, the server's "
                                                          f"max_probes is {settings.max_probes}")])
    try:
        body = RunRequest.model_validate(data)
    except ValidationError as exc:
        raise RequestInvalid(clean_errors(exc.errors(include_url=False, include_context=False,
                                                     include_input=False), ("body",))) from None
    body = with_device(body, settings)
    errors = run_errors(body, settings)
    if errors:
        raise RequestInvalid(errors)
    return body


def with_device(body: RunRequest, settings: Settings) -> RunRequest:
    """The request with the server's default device where its scene names none ([run] device),
    so the run record and the Simulation see the device the run uses."""
    run = body.scene.run
    if "device" in run.model_fields_set or run.device == settings.device:
        return body
    own = run.model_copy(update={"device": settings.device})
    scene = body.scene.model_copy(update={"run": own})
    return body.model_copy(update={"scene": scene})


def run_errors(body: RunRequest, settings: Settings) -> list[dict[str, Any]]:
    """What a valid scene and request still cannot run as (the rules across fields)."""
    scene, coupling = body.scene, body.coupling
    n = estimate_particles(scene)
    if n > settings.max_particles:
        return [error(["scene", "dp"], f"the scene needs about {n:.3g} particles, the server's cap "
                                       f"is {settings.max_particles:.3g}: increase dp or shrink "
                                       f"the tank and water blocks")]
    if body.mode == "coupled" and not scene.open_boundaries:
        return [error(["scene", "open_boundaries"],
                      "a coupled run needs at least one open end for the client to drive")]
    errors = []
    if scene.run.device == "cuda":
        from sph_core.cuda import unavailable_reason

        reason = unavailable_reason()
        if reason is not None:
            errors.append(error(["scene", "run", "device"], f"device cuda: {reason}"))
    duration = scene.t_end - scene.t_start
    c = scene.constants
    floor = math.sqrt(2.0 * c.g * scene.water_height)  # the speed of water falling its height
    if c.c0 is not None and c.c0 < floor:
        errors.append(error(["scene", "constants", "c0"], f"{c.c0:g} m/s is below "
                            f"sqrt(2 g H) = {floor:.3g} m/s: the water would be compressible"))
    steps = duration * scene.c0 / (c.cfl * scene.h)  # the fewest a run takes: dt <= cfl h / c0
    if not steps <= MAX_STEPS:
        errors.append(error(["scene", "constants", "c0" if c.c0 is not None else "c0_factor"],
                            f"c0 = {scene.c0:.3g} m/s makes more than {MAX_STEPS:.0e} time steps "
                            f"of the run's {duration:g} s"))
    if scene.open_boundaries:
        from sph_core.open_ends import check_open_end_layout

        try:  # the engine would refuse it when built, after the 201
            check_open_end_layout(scene)
        except ValueError as exc:
            field, _, msg = str(exc).partition(": ")
            errors.append(error(["scene", *[int(p) if p.isdigit() else p
                                            for p in field.split(".")]], msg))
    windows = [(["coupling", "window_max"], coupling.window_max)]
    if body.source is not None and body.source.window is not None:
        windows.append((["source", "window"], body.source.window))
    for loc, window in windows:
        if duration / window > MAX_WINDOWS:
            errors.append(error(loc, f"{window:g} s makes more than {MAX_WINDOWS:,} windows of "
                                     f"the run's {duration:g} s"))
    if scene.open_boundaries and coupling.z_ref is not None:
        depth = float(scene.still_water_level) - scene.tank.z0
        if not -depth < coupling.z_ref <= 0:
            errors.append(error(["coupling", "z_ref"], f"{coupling.z_ref} m is not in the water "
                                                       f"column (-{depth:g}, 0] m"))
    errors += [error(loc, msg) for loc, msg in source_errors(scene, body.mode, body.source,
                                                             coupling.window_max)]
    return errors
