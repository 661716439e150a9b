"""Run manager: run records, the queue and its caps, standalone stepping in workers.

Three caps, so that runs whose client never comes cannot block the server:
- ``max_runs`` stepping slots: a standalone run holds one while it steps, a coupled run from the
  moment its client attaches to the end of the session. A coupled run that waits for its client
  holds none; a client's HELLO reserves its run (``reserve``) and waits in ``attach`` while the
  run is queued or every slot is busy.
- ``max_waiting`` coupled runs built (engine in memory) and waiting for their client;
- ``max_queued`` runs of each kind in the queue (coupled runs waiting for a client, and the
  others, counted apart: clientless coupled POSTs never lock standalone runs out); one more is
  refused (HTTP 429 with Retry-After).

A coupled run whose client does not come within ``client_wait_timeout`` of its POST (queued or
built) fails, freeing its places. A run resumed by its owner goes to the head of the queue and
needs no waiting place: it is never stuck behind clientless runs of strangers, and a resume is
never refused for a full queue. A queued run whose client has said HELLO goes to the head of
the queue too, and takes the next waiting place.

Everything here runs on the event loop except the SPH work, which goes to a thread pool
(``Run.executor``): numba releases the GIL in its parallel loops, and Python threads switch every
few milliseconds otherwise, so the loop keeps answering HTTP while a run steps.
"""

from __future__ import annotations

import asyncio
import logging
import math
import threading
import time
import uuid
from collections import deque
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any, Awaitable, Callable

from protocol.session import set_payload_size

from .engine import CouplingEngine, EngineFactory
from .schemas import (CANCELLED, FAILED, FINISHED, QUEUED, RUNNING, TERMINAL, UNSTABLE, WAITING,
                      RunInfo, RunRequest, canonical_scene)
from .settings import Settings
from .store import GaugeWriter, RunStore, has_seal, is_sealed, read_gauge_rows

log = logging.getLogger("wavesph.server")


class Cancelled(Exception):
    """Raised inside a worker when the run's owner cancelled it."""


class QueueFull(Exception):
    """The queue holds ``max_queued`` runs already (HTTP 429)."""


class Run:
    """One run: its record (``info``, mirrored to meta.json) and its live parts."""

    def __init__(self, info: RunInfo, request: RunRequest, run_dir: Path) -> None:
        self.info = info
        self.request = request
        self.dir = run_dir
        self.scene_bytes = canonical_scene(request.scene)
        self.cancel_flag = threading.Event()       # seen by worker threads
        self.cancelled = asyncio.Event()           # seen by the coupling door
        self.attached = asyncio.Event()            # a coupling client took the run
        self.session_done = asyncio.Event()        # its session ended (state already set)
        self.engine: CouplingEngine | None = None
        self.gauges: GaugeWriter | None = None
        self.task: asyncio.Task | None = None
        self.task_client: asyncio.Task | None = None   # the built-in theory client, if any
        self.client_attached = False
        self.resume_from: Path | None = None
        self.wait_deadline = math.inf             # monotonic [s]: no client by then, it fails
        self._saved_at = 0.0

    @property
    def state_file(self) -> Path:
        return self.dir / "state.npz"

    def reset_live_parts(self) -> None:
        """Fresh events and engine slots for a resumed session."""
        self.cancel_flag = threading.Event()
        self.cancelled = asyncio.Event()
        self.attached = asyncio.Event()
        self.session_done = asyncio.Event()
        self.engine, self.gauges, self.task, self.client_attached = None, None, None, False

    @property
    def terminal(self) -> bool:
        return self.info.state in TERMINAL

    @property
    def resumed_here(self) -> bool:
        """Its owner asked for it again (resume): it takes no waiting place."""
        return self.resume_from is not None


SourceDriver = Callable[["RunManager", Run], Awaitable[None]]
"""Drives an attached run with its request's built-in wave source (theory_client.serve_theory)."""


class RunManager:
    def __init__(self, settings: Settings, engine_factory: EngineFactory,
                 source_driver: SourceDriver | None = None) -> None:
        self.settings = settings
        self.engine_factory = engine_factory
        self.source_driver = source_driver
        self.store = RunStore(settings.runs_dir)
        self.runs: dict[str, Run] = {}
        self.queue: deque[str] = deque()
        self.active: set[str] = set()    # runs holding a stepping slot
        self.waiting: set[str] = set()   # coupled runs built or being built, no client yet
        # stepping: one worker per slot; building engines has its own worker, so a run being
        # built never delays the windows of the runs that step
        self.executor = ThreadPoolExecutor(max_workers=settings.max_runs, thread_name_prefix="sph")
        self.builder = ThreadPoolExecutor(max_workers=1, thread_name_prefix="sph-build")
        self.stopping = False
        self.unsaved: set[str] = set()   # runs whose last meta.json write failed (disk full)
        self._changed = asyncio.Event()
        self._load_existing()

    # ------------------------------------------------------------------ records
    def _load_existing(self) -> None:
        """Runs left on disk by an earlier server: listed with their data. Runs that had not
        started (queued, or waiting for their client) are queued again; runs that were stepping
        are failed (a coupled one resumable from its last saved state)."""
        requeue: list[Run] = []
        for info, request in self.store.load_all():
            try:
                req = RunRequest.model_validate(request)
            except ValueError as exc:
                log.warning("run store: skipping run %s: its request.json is not valid: %s",
                            info.id, str(exc).splitlines()[0][:200])
                continue
            run = Run(info, req, self.store.run_dir(info.id))
            self.runs[info.id] = run
            self._catch_up_with_gauges(run)
            if run.info.state in (QUEUED, WAITING):  # nothing stepped yet: queue it again
                requeue.append(run)
            elif not run.terminal:
                self._set_state(run, FAILED, "server stopped before the run ended")
            if run.info.resumable and not self.state_intact(run):
                self.save(run)
        for run in sorted(requeue, key=lambda r: r.info.created):
            if run.info.resumed:  # queued to resume: from its saved state
                if not is_sealed(run.state_file):
                    self._set_state(run, FAILED, "server stopped before the run was resumed, "
                                                 "and its saved state is damaged")
                    continue
                run.resume_from = run.state_file
            run.info.ended = None
            self.queue.append(run.info.id)
            self._wait_for_client(run)
            self._set_state(run, QUEUED)
            log.info("run %s: queued again (it had not started when the server stopped)",
                     run.info.id)
        if self.queue:
            self._schedule()

    def _catch_up_with_gauges(self, run: Run) -> None:
        """meta.json is rewritten at most every meta_interval, gauges.csv row by row: after a
        crash, the gauge rows say how far a coupled run got."""
        path = run.dir / "gauges.csv"
        if not _windowed(run.request) or not path.exists():
            return
        try:
            _, rows = read_gauge_rows(path)
        except (OSError, ValueError) as exc:
            log.warning("run %s: gauges.csv unreadable (%s); its record is kept as it was",
                        run.info.id, exc)
            return
        if len(rows) != run.info.windows and rows:
            last = rows[-1]
            run.info.windows, run.info.t = len(rows), float(last["t"])
            run.info.steps = int(sum(r["steps"] or 0 for r in rows))
            run.info.last_gauges = {k: v for k, v in last.items() if k not in ("t", "steps")}
            log.warning("run %s: meta.json lagged gauges.csv; now %d windows to t = %g s",
                        run.info.id, run.info.windows, run.info.t)

    def state_intact(self, run: Run) -> bool:
        """The saved state matches its seal; if not, the run is no longer resumable (says why).
        Reads the whole state file: call it off the event loop for a live server."""
        if is_sealed(run.state_file):
            return True
        if run.info.resumable:
            run.info.resumable = False
            run.info.reason = f"{run.info.reason or run.info.state}; its saved state is damaged"
            if run.info.state in (FAILED, UNSTABLE):
                run.info.status = f"{run.info.state}: {run.info.reason}"
            log.warning("run %s: state.npz does not match its seal: not resumable", run.info.id)
        return False

    def save_due(self, run: Run, force: bool = False) -> bool:
        """meta.json is rewritten at most every ``meta_interval`` unless forced."""
        return force or time.monotonic() - run._saved_at >= self.settings.meta_interval

    def save(self, run: Run, force: bool = True) -> None:
        """meta.json of the run; a failed write (a full disk) is logged, never raised: the run's
        state in memory still moves on and its slot is released (written again when it can)."""
        if not self.save_due(run, force):
            return
        run._saved_at = time.monotonic()
        try:
            self.store.save(run.info)
        except OSError as exc:
            self.unsaved.add(run.info.id)
            log.error("run %s: could not write meta.json: %s", run.info.id, exc)
            return
        self.unsaved.discard(run.info.id)
        for rid in list(self.unsaved):  # the disk has room again: records that missed a write
            try:
                self.store.save(self.runs[rid].info)
            except OSError:
                return
            self.unsaved.discard(rid)

    def _set_state(self, run: Run, state: str, reason: str | None = None) -> None:
        run.info.state = state
        run.info.reason = reason
        run.info.status = state
        if reason and state in (FAILED, UNSTABLE):  # "unstable at step ...", not "unstable: unstable at"
            run.info.status = reason if reason.startswith(state) else f"{state}: {reason}"
        run.info.resumable = (state in (FAILED, CANCELLED) and _windowed(run.request)
                              and has_seal(run.state_file))
        if state in TERMINAL or state == QUEUED:  # no stale "building" after a restart
            run.info.detail = None
        if state in TERMINAL:
            run.info.ended = time.time()
            run.info.queue_position = None
        log.info("run %s: %s", run.info.id, run.info.status)
        self.save(run)
        self._pulse()
        if state in TERMINAL and (run.info.id in self.active or run.info.id in self.waiting):
            self._release(run)  # a run that says it ended holds no slot (its engine may still close)

    def _queue_positions(self) -> None:
        for i, rid in enumerate(self.queue):
            self.runs[rid].info.queue_position = i + 1

    # ------------------------------------------------------------------ lifecycle
    def _check_queue_room(self, request: RunRequest) -> None:
        kind = _waits_for_client(request)
        queued = sum(1 for rid in self.queue if _waits_for_client(self.runs[rid].request) == kind)
        if queued >= self.settings.max_queued:
            what = "coupled runs waiting for a client" if kind else "standalone runs"
            raise QueueFull(f"the queue holds {queued} {what}, the server's max_queued: "
                            f"retry when a run has ended")

    def _wait_for_client(self, run: Run) -> None:
        """A coupled run fails if no client comes within client_wait_timeout from now (queued
        or built: a queue of clientless runs empties by itself)."""
        if not _waits_for_client(run.request):
            return
        timeout = self.settings.client_wait_timeout
        run.wait_deadline = time.monotonic() + timeout
        deadline = run.wait_deadline

        def expire() -> None:
            if (run.wait_deadline == deadline and run.info.id in self.queue
                    and not run.client_attached):
                self.queue.remove(run.info.id)
                self._set_state(run, FAILED, f"no client connected within {timeout:g} s")
                self._queue_positions()
        asyncio.get_running_loop().call_later(timeout, expire)

    def submit(self, request: RunRequest) -> Run:
        self._check_queue_room(request)
        run_id = uuid.uuid4().hex  # 128 random bits: also the credential on the TCP port
        scene_bytes = canonical_scene(request.scene)
        from protocol import scene_hash

        info = RunInfo(id=run_id, name=request.scene.name, mode=request.mode,
                       device=request.scene.run.device, state=QUEUED, status=QUEUED,
                       created=time.time(), t_end=request.scene.t_end,
                       scene_hash=scene_hash(scene_bytes).hex(),
                       gauges_file="gauges.csv" if _windowed(request) else "sph/probes.csv")
        run_dir = self.store.create(run_id, request.model_dump(mode="json"), scene_bytes)
        run = Run(info, request, run_dir)
        self.runs[run_id] = run
        self.queue.append(run_id)
        self._wait_for_client(run)
        self._queue_positions()
        self.save(run)
        self._schedule()
        return run

    def resume(self, run: Run) -> None:
        """Queue a failed or cancelled coupled run again, from its saved state."""
        if run.info.resumable and not has_seal(run.state_file):
            run.info.resumable = False
        if not run.info.resumable:
            raise ValueError(f"run {run.info.id} is {run.info.status}: only a failed or cancelled "
                             f"coupled run with a saved state can be resumed")
        run.reset_live_parts()
        run.resume_from = run.state_file
        run.info.resumed += 1
        run.info.ended = None
        self._set_state(run, QUEUED)
        self.queue.appendleft(run.info.id)  # its owner's run: ahead of strangers' new ones
        self._wait_for_client(run)
        self._queue_positions()
        self._schedule()

    def _schedule(self) -> None:
        """Start every queued run that has room, in queue order: a coupled run needs a waiting
        place, any other run a stepping slot (so one kind never waits behind the other)."""
        if self.stopping:
            return
        # runs whose client is here first, in queue order (a stable sort), then the others
        for rid in sorted(self.queue, key=lambda r: not self.runs[r].client_attached):
            run = self.runs[rid]
            if _waits_for_client(run.request):
                places = sum(1 for w in self.waiting if not self.runs[w].resumed_here)
                if places >= self.settings.max_waiting and not run.resumed_here:
                    continue
                self.waiting.add(rid)
            else:
                if len(self.active) >= self.settings.max_runs:
                    continue
                self.active.add(rid)
            self.queue.remove(rid)
            run.info.queue_position = None
            body = self._coupled(run) if _windowed(run.request) else self._standalone(run)
            run.task = asyncio.get_running_loop().create_task(body, name=f"run-{run.info.id}")
        self._queue_positions()

    def _release(self, run: Run) -> None:
        self.active.discard(run.info.id)
        self.waiting.discard(run.info.id)
        self._schedule()
        self._pulse()

    def cancel(self, run: Run) -> None:
        if run.terminal:
            return
        run.cancel_flag.set()
        run.cancelled.set()
        if run.info.id in self.queue:  # not started yet (a started run may still say queued)
            self.queue.remove(run.info.id)
            self._set_state(run, CANCELLED, "cancelled by the user")
            self._queue_positions()
        elif run.info.state == QUEUED and not self.stopping:  # its engine is being built: the
            self._set_state(run, CANCELLED, "cancelled by the user")  # build's end is dropped
        # a starting, waiting or running run ends in its own task, which sets the state

    @property
    def cancel_reason(self) -> tuple[str, str]:
        """(state, reason) of a run stopped by DELETE or by the server stopping."""
        if self.stopping:
            return FAILED, "server stopped before the run ended"
        return CANCELLED, "cancelled by the user"

    async def shutdown(self) -> None:
        self.stopping = True
        self._pulse()
        for run in list(self.runs.values()):
            if not run.terminal:
                run.cancel_flag.set()
                run.cancelled.set()
        tasks = [r.task for r in self.runs.values() if r.task and not r.task.done()]
        if tasks:
            await asyncio.wait(tasks, timeout=10)
        for run in self.runs.values():
            if not run.terminal and run.info.state != QUEUED:  # queued ones run after a restart
                self._set_state(run, FAILED, "server stopped before the run ended")
        self.executor.shutdown(wait=False, cancel_futures=True)
        self.builder.shutdown(wait=False, cancel_futures=True)
        self.store.close()

    # ------------------------------------------------------------------ standalone
    async def _standalone(self, run: Run) -> None:
        loop = asyncio.get_running_loop()
        run.info.started = time.time()
        self._set_state(run, RUNNING)
        try:
            await loop.run_in_executor(self.executor, self._step_standalone, run)
            self._set_state(run, FINISHED)
        except Cancelled:
            self._set_state(run, *self.cancel_reason)
        except Exception as exc:  # noqa: BLE001 -- every failure becomes a run status
            self._fail(run, exc)
        finally:
            self._release(run)

    def _step_standalone(self, run: Run) -> None:
        """Worker thread: build and advance the sph_core Simulation, reporting progress."""
        from sph_core.simulation import Simulation

        run.info.detail = compile_detail("building the run")
        sim = Simulation(run.request.scene, run_dir=run.dir / "sph")
        run.info.particles = sim.n_particles
        run.info.detail = compile_detail("first steps")

        def progress(s: Simulation) -> None:
            info = run.info
            info.detail = None
            info.t, info.steps = s.t, s.steps
            info.particle_steps_per_s = (s.n_particles * s.steps / s.wall_time if s.wall_time > 0
                                         else None)
            info.stability = simulation_stability(s)
            if s.history:
                info.last_gauges = {k: v for k, v in s.history[-1].items() if k != "t"}
            self.save(run, force=False)
            if run.cancel_flag.is_set():
                raise Cancelled()

        try:
            sim.advance_to(run.request.scene.t_end, progress=progress)
            progress(sim)
        finally:
            sim.close()

    def _fail(self, run: Run, exc: BaseException) -> None:
        from sph_core.simulation import DeviceError, UnstableError

        if isinstance(exc, DeviceError):   # one line, no traceback: the scene, not the server
            log.info("run %s: %s", run.info.id, exc)
            self._set_state(run, FAILED, str(exc))
        elif isinstance(exc, UnstableError):
            run.info.stability = {**run.info.stability, "unstable_step": exc.step, "unstable_t": exc.t}
            self._set_state(run, UNSTABLE, str(exc))
        else:
            log.exception("run %s failed", run.info.id, exc_info=exc)
            self._set_state(run, FAILED, f"{type(exc).__name__}: {exc}")

    # ------------------------------------------------------------------ coupled
    async def _coupled(self, run: Run) -> None:
        """Build the engine, then hold the slot until the client's session ends (see doors.py)."""
        loop = asyncio.get_running_loop()
        try:
            run.engine = await loop.run_in_executor(self.builder, self._build, run)
            if hasattr(run.engine, "cancel"):  # it stops a long window when the run is cancelled
                run.engine.cancel = run.cancel_flag
            run.info.detail = None
            if run.resume_from is not None:
                await loop.run_in_executor(self.builder, run.engine.load_state, run.resume_from)
            if run.terminal:  # cancelled while it was built (state already set)
                return
            run.info.particles = run.engine.n_particles
            run.info.t, run.info.steps = run.engine.t, run.engine.steps
            need = set_payload_size(run.engine.nodes().x.size)
            if need > self.settings.max_frame:
                raise ValueError(f"the scene's {run.engine.nodes().x.size} boundary nodes need SET frames "
                                 f"of {need} bytes, above the server's max_frame {self.settings.max_frame}")
            names = run.engine.nodes().gauge_names or [f"g{j}" for j in range(run.engine.nodes().gauge_x.size)]
            run.gauges = GaugeWriter(run.dir / "gauges.csv", names,
                                     resume_at=run.engine.t if run.resume_from is not None else None)
            run.info.windows = run.gauges.rows_kept
            run.info.started = time.time()
            self._set_state(run, WAITING)
            if run.request.source is not None:  # standalone, driven by a built-in theory client
                if self.source_driver is None:
                    raise RuntimeError("this server has no driver for built-in wave sources")
                run.client_attached = True  # it took its stepping slot when it left the queue
                run.info.detail = compile_detail("first window")
                run.attached.set()
                run.task_client = asyncio.get_running_loop().create_task(self.source_driver(self, run))
            while True:  # a reserving client waits for a slot: its run does not expire then
                left = run.wait_deadline - time.monotonic()
                woke = await _first_of(run.attached, run.cancelled, None if math.isinf(left)
                                       else max(left, 1.0 if run.client_attached else 0.0))
                if woke is None and run.client_attached:
                    continue  # its client is connected (reserved it) and waits for a slot
                break
            if woke is None:
                self._set_state(run, FAILED, f"no client connected within "
                                             f"{self.settings.client_wait_timeout:g} s")
            elif woke is run.cancelled and not run.attached.is_set():
                if self.stopping:  # nothing stepped: queued again when the server restarts
                    self._set_state(run, QUEUED)
                else:
                    self._set_state(run, *self.cancel_reason)  # a reserving client: its door says
            else:
                await run.session_done.wait()  # the door sets the final state
        except Exception as exc:  # noqa: BLE001
            if not run.terminal:  # a run cancelled while it was built stays cancelled
                self._fail(run, exc)
        finally:
            try:  # closing flushes files: on a full disk it raises, and the slot must still go
                if run.gauges:
                    run.gauges.close()
                if run.engine:
                    await loop.run_in_executor(self.builder, run.engine.close)
            except Exception as exc:  # noqa: BLE001
                log.error("run %s: closing its files failed: %s", run.info.id, exc)
            finally:
                self._release(run)

    def _build(self, run: Run) -> CouplingEngine:
        """Builder thread: the run's engine (the detail's check imports sph_core off the loop)."""
        run.info.detail = compile_detail("building the run")
        return self.engine_factory(run.request, run.dir)

    # ------------------------------------------------------------------ coupling clients
    def reserve(self, run_id: str) -> Run:
        """A client's HELLO names a coupled run: the run is its own from now on (another HELLO
        naming it is refused), even while it is queued or every stepping slot is busy; the door
        then waits in ``attach``. ValueError says why not (sent as ERROR BUSY)."""
        run = self.runs.get(run_id)
        if run is None:
            raise ValueError(f"no run {run_id!r} on this server")
        if run.client_attached and not run.terminal:  # an ended run says it has ended
            raise ValueError(f"run {run_id} already has a coupling client")
        if run.info.state not in (QUEUED, WAITING) or not _waits_for_client(run.request):
            raise ValueError(f"run {run_id} is {run.info.status}: it takes no coupling client")
        run.client_attached = True
        if run.info.id in self.queue:  # its client is here: ahead of clientless runs
            self._schedule()
        return run

    def unreserve(self, run: Run) -> None:
        """The reserving client left before its session began."""
        if not run.attached.is_set():
            run.client_attached = False
            if run.info.id in self.queue:  # clientless again: it expires again
                self._wait_for_client(run)

    async def attach(self, run: Run) -> None:
        """Wait until the reserved run is built and a stepping slot is free, then take the slot.
        ValueError if the run ended meanwhile (cancelled, failed)."""
        while True:
            if self.stopping:
                raise ValueError("the server is stopping")
            if run.terminal:
                raise ValueError(f"run {run.info.id} is {run.info.status}")
            if run.info.state == WAITING and len(self.active) < self.settings.max_runs:
                self.waiting.discard(run.info.id)
                self.active.add(run.info.id)
                if run.info.windows == 0:  # cleared by the first window's progress
                    run.info.detail = compile_detail("first window")
                run.attached.set()
                self._schedule()  # its waiting place is free for the next queued coupled run
                return
            await self._changed.wait()

    def _pulse(self) -> None:
        """Wake every door waiting in ``attach``: a state or a slot changed."""
        self._changed.set()
        self._changed = asyncio.Event()


def compile_detail(doing: str) -> str:
    """``doing``, with "compiling SPH kernels (first run only)" while numba's cache lacks them:
    on a fresh install the first build and window of a server take minutes (ux.md F3)."""
    try:
        from sph_core.progress import kernels_cached
        cold = not kernels_cached()
    except Exception:  # noqa: BLE001 -- a detail for the page, never a failure
        cold = False
    return f"{doing}: compiling SPH kernels (first run only)" if cold else doing


def _waits_for_client(request: RunRequest) -> bool:
    """Coupled runs wait for a client without a stepping slot; theory-driven ones do not wait."""
    return request.mode == "coupled"


def _windowed(request: RunRequest) -> bool:
    """Runs on the coupled path (engine + windows): coupled ones and theory-driven standalone ones."""
    return request.mode == "coupled" or request.source is not None


async def _first_of(a: asyncio.Event, b: asyncio.Event,
                    timeout: float | None) -> asyncio.Event | None:
    """Whichever event is set first, or None after ``timeout`` seconds (None: no limit)."""
    waits = {asyncio.ensure_future(a.wait()): a, asyncio.ensure_future(b.wait()): b}
    done, pending = await asyncio.wait(waits, timeout=timeout, return_when=asyncio.FIRST_COMPLETED)
    for f in pending:
        f.cancel()
    if a.is_set():
        return a
    return b if b.is_set() else None


def simulation_stability(sim: Any) -> dict[str, float]:
    """Stability figures of an sph_core Simulation."""
    mass0 = sim.fluid_mass0
    return {"dt": sim.dt, "v_max": sim.v_max, "c0": sim.c0,
            "mach": sim.v_max / sim.c0 if sim.c0 else 0.0,
            "mass_drift": sim.fluid_mass() / mass0 - 1.0 if mass0 else 0.0}
