"""The coupling door logic shared by the WebSocket and TCP endpoints.

A transport (transports.DoorTransport) gives ``recv()`` and ``send(bytes)``; ``serve_client`` runs the protocol session (protocol.SphSession) against the
run's engine. Engine calls go to the worker pool, except windows the engine solves in under
``INLINE_SOLVE_S`` (a null or tiny engine), which run on the loop: the thread hop and the GIL
hand-over back cost more than such a window. Every read has a timeout; the run's state says how
the session ended, and the gauge rows of every solved window are on disk already.
"""

from __future__ import annotations

import asyncio
import logging
import time
from collections import deque
from typing import Callable

import numpy as np

from protocol import (NO_SCENE_HASH, Capability, ErrorCode, GaugeKind, Gauges, Nodes, ProtocolError,
                      Result, SphSession, Welcome, encode_frame)
from protocol.messages import Error, Hello, Message, Working
from protocol.session import (Measure, PeerError, Reply, Restore, SetWindow, SolveWindow,
                              set_payload_size)

from .engine import CouplingEngine, Measurement, SolveCancelled
from .run_manager import Run, RunManager
from .schemas import FAILED, FINISHED, RUNNING, UNSTABLE
from .store import save_sealed
from .transports import DoorTransport, PeerGone

log = logging.getLogger("wavesph.server")

SERVER_NAME = "wavesph-server 0.1 (protocol 1.1)"
INLINE_SOLVE_S = 1e-3   # [s] windows this quick (the last INLINE_HISTORY of them) run on the loop
INLINE_HISTORY = 8


class _SessionEnd(Exception):
    def __init__(self, state: str, reason: str | None, frame: bytes | None = None) -> None:
        super().__init__(reason)
        self.state, self.reason, self.frame = state, reason, frame


def error_frame(code: ErrorCode, text: str, seq: int = 0) -> bytes:
    """An ERROR frame outside a session (before the run is known)."""
    return encode_frame(Error(int(code), text[:4000]), seq)


async def admit(manager: RunManager, transport: DoorTransport,
                run_id_of: Callable[[Hello], str]) -> tuple[Run, list[tuple[int, Message]]] | None:
    """The first frame, HELLO, within ``hello_timeout``: the run it names (``run_id_of`` gives
    the id, or raises ProtocolError where the door refuses it) claimed, with the frames read so
    far. None if the client left first (the transport is left to the caller) or was refused
    (ERROR sent, transport closed)."""
    seq = 0
    try:
        frames = await asyncio.wait_for(transport.recv(), manager.settings.hello_timeout)
        if frames is None:
            return None
        seq, msg = frames[0]
        if not isinstance(msg, Hello):
            raise ProtocolError(ErrorCode.OUT_OF_ORDER, f"{msg.TYPE.name} before HELLO")
        run = await claim_run(manager, run_id_of(msg), msg, transport, seq)
        if run is None:
            await transport.close()
            return None
    except ProtocolError as exc:  # a refused frame's own seq where its header was read
        await _refuse(transport, exc.code, exc.text, seq if exc.seq is None else exc.seq)
        return None
    except TimeoutError:
        await _refuse(transport, ErrorCode.TIMEOUT, f"no HELLO within {manager.settings.hello_timeout:g} s", 0)
        return None
    return run, frames


async def _refuse(transport: DoorTransport, code: ErrorCode, text: str, seq: int) -> None:
    try:  # bounded: a peer that reads nothing must not hold the door
        await asyncio.wait_for(transport.send(error_frame(code, text, seq)), 5.0)
    except Exception:  # noqa: BLE001 -- the peer may already be gone
        pass
    await transport.close()


async def claim_run(manager: RunManager, run_id: str, hello: Hello,
                    transport: DoorTransport, seq: int = 1) -> Run | None:
    """The run a client's HELLO (frame ``seq``) names, reserved for it at once and attached (a
    stepping slot taken) when it is built and a slot is free; the client waits for WELCOME
    meanwhile, with a WORKING frame every ``keepalive_every`` s if it asked for KEEPALIVE (1.1).
    None if the client left while waiting; ProtocolError (BUSY, CANCELLED, OUT_OF_ORDER,
    SCENE_MISMATCH) to refuse it. A refused client leaves the run as it was."""
    known = manager.runs.get(run_id)
    if known is None:
        raise ProtocolError(ErrorCode.NOT_FOUND, f"no run {run_id[:64]!r} on this server")
    if hello.scene_hash not in (NO_SCENE_HASH, bytes.fromhex(known.info.scene_hash)):
        raise ProtocolError(ErrorCode.SCENE_MISMATCH,
                            f"client expects scene {hello.scene_hash.hex()[:16]}..., run {run_id} "
                            f"has {known.info.scene_hash[:16]}... (GET /runs/{run_id}/scene); "
                            f"the run keeps waiting for its client")
    try:
        run = manager.reserve(run_id)
    except ValueError as exc:
        raise ProtocolError(ErrorCode.BUSY, str(exc)) from None
    attach = asyncio.ensure_future(manager.attach(run))
    recv = asyncio.ensure_future(transport.recv())
    # the build (a first run compiles the SPH kernels) or a busy server can take minutes: a
    # 1.1 client that asked is told the server is alive, so its read timeout need not cover it
    every = manager.settings.keepalive_every if hello.capabilities & Capability.KEEPALIVE else None
    tic = time.perf_counter()
    try:
        while not (await asyncio.wait({attach, recv}, timeout=every,
                                      return_when=asyncio.FIRST_COMPLETED))[0]:
            try:
                await transport.send(encode_frame(Working(time.perf_counter() - tic), seq))
            except PeerGone:
                return None
        if recv.done():
            if recv.result() is None:  # the client left; a ProtocolError passes through
                return None
            raise ProtocolError(ErrorCode.OUT_OF_ORDER, "a frame after HELLO, before WELCOME: "
                                                        "wait for WELCOME")
        try:
            attach.result()
        except ValueError as exc:
            code = ErrorCode.CANCELLED if run.info.state == "cancelled" else ErrorCode.BUSY
            raise ProtocolError(code, str(exc)) from None
        return run
    finally:
        for task in (attach, recv):
            task.cancel()
        # the cancelled read must be over before the session reads (a stream has one reader)
        await asyncio.gather(recv, return_exceptions=True)
        if not run.attached.is_set():
            manager.unreserve(run)


def welcome_for(run: Run, engine: CouplingEngine, idle_timeout: float, max_frame: int
                ) -> tuple[Welcome, Nodes, Gauges, Nodes | None]:
    """WELCOME (the scene summary), NODES, for 1.1 clients GAUGES, and for 1.2 clients the
    NODES with the relaxation zones' columns (None: the engine has no zones, or their SET would
    not fit in ``max_frame``) of a run's engine."""
    s, nodes = engine.summary, engine.nodes()
    welcome = Welcome(int(Capability.GOBACK | Capability.KEEPALIVE), bytes.fromhex(run.info.scene_hash), g=s.g, depth=s.depth,
                      still_water_level=s.still_water_level, z_ref=s.z_ref, t_start=s.t_start,
                      t_end=s.t_end, dt_sph=s.dt_sph, window_max=run.request.coupling.window_max,
                      idle_timeout=idle_timeout, n_nodes=nodes.x.size, n_gauges=nodes.gauge_x.size,
                      max_payload=0, run_id=run.info.id, server=SERVER_NAME)
    n = nodes.gauge_x.size
    gauges = Gauges(nodes.gauge_names or [f"g{j}" for j in range(n)],
                    nodes.gauge_kind if nodes.gauge_kind is not None
                    else np.full(n, GaugeKind.PROBE, np.uint32), np.array(nodes.eta_gauge, np.uint32))
    zone = getattr(engine, "zone_nodes", lambda: None)()
    if zone is not None and set_payload_size(zone.x.size) > max_frame:
        zone = None
    return (welcome, Nodes(nodes.x, nodes.z, nodes.side, nodes.gauge_x), gauges,
            None if zone is None else Nodes(zone.x, zone.z, zone.side, zone.gauge_x))


async def serve_client(manager: RunManager, run: Run, transport: DoorTransport,
                       first: list[tuple[int, Message]]) -> None:
    """Run one client's session on ``run`` (already attached); sets the run's final state."""
    settings, engine = manager.settings, run.engine
    assert engine is not None and run.gauges is not None
    loop = asyncio.get_running_loop()
    welcome, nodes, gauges, zone_nodes = welcome_for(run, engine, settings.idle_timeout,
                                                     settings.max_frame)
    session = SphSession(welcome, nodes, gauges, zone_nodes)
    names = engine.nodes().gauge_names or [f"g{j}" for j in range(nodes.gauge_x.size)]
    pending = list(first)
    connected = time.perf_counter()
    solve_time = 0.0
    timeout = settings.hello_timeout
    window: SetWindow | None = None
    at_boundary = True          # engine state is a window boundary (safe to save for resuming)
    saved_at, saved_t = time.monotonic(), engine.t
    recent: deque[float] = deque([float("inf")], maxlen=INLINE_HISTORY)  # solve times [s]
    reader = _Reader(transport, run)
    end: _SessionEnd

    def sync_limits() -> None:
        transport.max_payload = min(session.max_payload, settings.max_frame)

    sync_limits()
    try:
        while True:
            if not pending:
                pending = await reader.recv(timeout)
            seq, msg = pending.pop(0)
            action = session.receive(seq, msg)
            sync_limits()
            timeout = settings.idle_timeout
            if isinstance(action, Reply):
                if isinstance(msg, Hello):
                    run.info.client = msg.client or "unnamed client"
                    manager._set_state(run, RUNNING)
                await transport.send(action.data)
                if action.close:
                    raise _SessionEnd(FINISHED, None)
            elif isinstance(action, SetWindow):
                window = action  # handed to the engine with SOLVE: one worker hop per window
            elif isinstance(action, SolveWindow):
                tic = time.perf_counter()
                at_boundary = False
                goback = bool(session.capabilities & Capability.GOBACK)
                if max(recent) < INLINE_SOLVE_S:
                    measured = _solve(engine, run, window, goback)
                else:
                    measured = await _working(session, transport, settings.keepalive_every, run,
                                              loop.run_in_executor(manager.executor, _solve, engine,
                                                                   run, window, goback))
                at_boundary = True
                took = time.perf_counter() - tic
                recent.append(took)
                solve_time += took
                reply = session.result(action, _result(measured))
                values = _gauge_values(names, measured)
                run.gauges.row(engine.t, measured.steps, values)  # on disk before the reply
                try:
                    await transport.send(reply)
                finally:  # the run's progress (and, twice a second, meta.json) off the round trip
                    _progress(manager, run, engine, values, connected, solve_time)
                if (time.monotonic() - saved_at >= settings.checkpoint_every
                        or engine.t - saved_t >= settings.checkpoint_every_t * (1 - 1e-9)):
                    await _save_state(manager, run)  # by wall time and by simulated progress
                    saved_at, saved_t = time.monotonic(), engine.t
            elif isinstance(action, Measure):
                measured = await _working(session, transport, settings.keepalive_every, run,
                                          loop.run_in_executor(manager.executor, engine.measure))
                await transport.send(session.result(action, _result(measured)))
            elif isinstance(action, Restore):
                window = None
                at_boundary = False
                measured = await _working(session, transport, settings.keepalive_every, run,
                                          loop.run_in_executor(manager.executor, _goback, engine))
                at_boundary = True
                run.gauges.rewind()
                run.info.windows = max(run.info.windows - 1, 0)
                _progress(manager, run, engine, {}, connected, solve_time)
                await transport.send(session.result(action, _result(measured)))
            elif isinstance(action, PeerError):
                raise _SessionEnd(FAILED, f"client error {action.code}: {action.text}")
            if run.cancelled.is_set():
                raise _Cancel()
    except _SessionEnd as exc:
        end = exc
    except (_Cancel, SolveCancelled):
        state, reason = manager.cancel_reason
        end = _SessionEnd(state, reason, session.error_frame(ProtocolError(ErrorCode.CANCELLED, reason)))
    except (_Gone, PeerGone):
        end = _SessionEnd(FAILED, "client disconnected")
    except TimeoutError:
        end = _SessionEnd(FAILED, f"client timed out (silent for {timeout:g} s)",
                          session.error_frame(ProtocolError(
                              ErrorCode.TIMEOUT, f"no frame for {timeout:g} s; the run is failed")))
    except ProtocolError as exc:
        end = _SessionEnd(FAILED, f"protocol error: {exc}", session.error_frame(exc))
    except Exception as exc:  # noqa: BLE001 -- engine failures become run states, never a crash
        from sph_core.simulation import UnstableError

        if isinstance(exc, UnstableError):
            end = _SessionEnd(UNSTABLE, str(exc), session.error_frame(
                ProtocolError(ErrorCode.ENGINE_FAILED, str(exc))))
            run.info.stability = {**run.info.stability, "unstable_step": exc.step, "unstable_t": exc.t}
        else:
            log.exception("run %s: coupling failed", run.info.id)
            end = _SessionEnd(FAILED, f"{type(exc).__name__}: {exc}", session.error_frame(exc))
    reader.close()
    if end.frame is not None:
        try:
            await asyncio.wait_for(transport.send(end.frame), 5.0)
        except Exception:  # noqa: BLE001 -- the peer may be gone; the run state says it all
            pass
    try:
        await asyncio.wait_for(transport.close(), 5.0)
    except Exception:  # noqa: BLE001
        pass
    try:
        if at_boundary and end.state != UNSTABLE and run.info.windows > 0:
            await _save_state(manager, run)  # what a resumed session starts from
        _progress(manager, run, engine, None, connected, solve_time)
    finally:  # whatever failed above (a full disk), the run ends and its slot is released
        manager._set_state(run, end.state, end.reason)
        run.session_done.set()


class _Gone(Exception):
    """The peer closed the connection without BYE."""


class _Cancel(Exception):
    pass


class _Reader:
    """The session's reads: next frames, or _Gone / TimeoutError / _Cancel; ProtocolError passes
    through. One watcher per session ends a read when the run is cancelled (no task per read:
    two tasks and an asyncio.wait per frame were a fifth of a null window)."""

    def __init__(self, transport: DoorTransport, run: Run) -> None:
        self.transport, self.run = transport, run
        self.task = asyncio.current_task()
        self.reading = False
        self.watcher = asyncio.ensure_future(run.cancelled.wait())
        self.watcher.add_done_callback(self._on_cancel)

    def _on_cancel(self, _: object) -> None:
        if self.reading and self.task is not None and not self.watcher.cancelled():
            self.task.cancel()

    async def recv(self, timeout: float) -> list[tuple[int, Message]]:
        if self.run.cancelled.is_set():
            raise _Cancel()
        self.reading = True
        try:
            async with asyncio.timeout(timeout):
                frames = await self.transport.recv()
        except asyncio.CancelledError:
            if self.run.cancelled.is_set() and self.task is not None and self.task.uncancel() == 0:
                raise _Cancel() from None
            raise
        finally:
            self.reading = False
        if frames is None:
            raise _Gone()
        return frames

    def close(self) -> None:
        self.watcher.cancel()


async def _working(session: SphSession, transport: DoorTransport, every: float, run: Run,
                   job: asyncio.Future) -> Measurement:
    """``job``'s result; meanwhile a WORKING frame every ``every`` seconds if the client asked
    for KEEPALIVE (1.1): the first window waits for the solver's JIT compile. A client found
    gone by a WORKING frame stops the window (the run's cancel flag, server/engine.py), and
    PeerGone is raised only once the worker is done with the engine (it is closed next)."""
    if session.working_frame(0.0) is None:
        return await job
    tic = time.perf_counter()
    while True:
        done, _ = await asyncio.wait({job}, timeout=every)
        if done:
            return job.result()
        frame = session.working_frame(time.perf_counter() - tic)
        assert frame is not None
        try:
            await transport.send(frame)
        except PeerGone:
            run.cancel_flag.set()
            await asyncio.wait({job})
            job.exception()  # retrieved: SolveCancelled, or none; the client's leaving says it
            raise


def _solve(engine: CouplingEngine, run: Run, window: SetWindow, checkpoint: bool) -> Measurement:
    """Worker thread: checkpoint (for GOBACK, state at t0), set the window, solve it."""
    if checkpoint:
        engine.checkpoint()
        run.gauges.mark()
    engine.set_window(window.t0, window.t1, window.u, window.w, window.eta)
    return engine.solve_window()


async def _save_state(manager: RunManager, run: Run) -> None:
    """Engine state to the run directory, in a worker; a failure is logged, never fatal."""
    save = getattr(run.engine, "save_state", None)
    if save is None:
        return
    try:
        await asyncio.get_running_loop().run_in_executor(manager.executor, save_sealed, save,
                                                         run.state_file)
    except Exception:  # noqa: BLE001 -- the run's data are in gauges.csv; only resuming is lost
        log.exception("run %s: could not save the engine state", run.info.id)


def _goback(engine: CouplingEngine) -> Measurement:
    engine.goback()
    return engine.measure()


def _result(m: Measurement) -> Result:
    wet = np.asarray(m.wet, dtype=bool)
    if wet.all():  # nothing to blank out
        return Result(0.0, int(m.steps), m.eta, np.ones(wet.size, np.uint32), m.u_ref, m.w_ref)
    z = np.zeros(wet.size)
    return Result(0.0, int(m.steps), np.where(wet, m.eta, z), wet.astype(np.uint32),
                  np.where(wet, m.u_ref, z), np.where(wet, m.w_ref, z))


def _gauge_values(names: list[str], m: Measurement) -> dict[str, float | None]:
    out: dict[str, float | None] = {}
    for j, name in enumerate(names):
        wet = bool(m.wet[j])
        out[f"{name}_eta"] = float(m.eta[j]) if wet else None
        out[f"{name}_u_ref"] = float(m.u_ref[j]) if wet else None
        out[f"{name}_w_ref"] = float(m.w_ref[j]) if wet else None
    return out


def _progress(manager: RunManager, run: Run, engine: CouplingEngine,
              values: dict[str, float | None] | None, connected: float, solve_time: float) -> None:
    info = run.info
    info.t, info.steps, info.particles = engine.t, engine.steps, engine.n_particles
    if values:
        info.last_gauges = values
        info.windows += 1
        info.detail = None
    wall = time.perf_counter() - connected
    if solve_time > 0:
        info.particle_steps_per_s = engine.n_particles * engine.steps / solve_time
    info.coupling_overhead_share = max(0.0, 1.0 - solve_time / wall) if wall > 0 else None
    if manager.save_due(run, force=values is None):  # stability figures cost a pass over the
        info.stability = {**info.stability, **engine.stability()}  # particles: as often as meta.json
        manager.save(run)
