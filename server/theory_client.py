"""Standalone runs of open-boundary scenes, driven by a built-in wave theory (theory_source.py).

The theory is wave_client's, driven by wave_client's own coupling core (``CouplingCore``). Its
frames go through an in-memory transport (``TheoryClient``) to the same door logic
(``server.doors.serve_client``) that a WebSocket or TCP client reaches. So the run takes the
coupled run's path exactly: the theory samples the boundary nodes window by window as the client
would, the engine solves the same windows, and gauges.csv, progress, saved states and resume are
those of a coupled run; only the socket is missing. A coupled run of the same scene with the same
theory and options gives the same gauges to round-off (tests/test_server/test_standalone_theory.py).
The theory's own elevation at the gauges is written beside them, to theory.csv.
"""

from __future__ import annotations

import logging
from pathlib import Path

from protocol import (MAX_PAYLOAD, Bye, Error, Gauges, Message, Nodes, Result, Welcome,
                      decode_frame)
from protocol.session import HELLO_LIMIT
from wave_client.coupling import CouplingCore, CouplingOptions, GaugeLog

from .doors import serve_client
from .run_manager import Run, RunManager
from .store import fresh_path  # theory.csv, then theory.1.csv ... for resumed sessions

log = logging.getLogger("wavesph.server")


class TheoryClient:
    """A coupling client in this process: the door's DoorTransport, with a CouplingCore behind it.

    ``send`` hands each server frame to the core at once and queues the core's answer, which
    ``recv`` returns; an empty queue means the client is done (closed). Frames are encoded and
    decoded as on a socket, so the door's checks (sequence, sizes, limits) all apply."""

    def __init__(self, core: CouplingCore, log_path: Path) -> None:
        self.core = core
        self.max_payload = HELLO_LIMIT
        self._out: list[tuple[int, Message]] = []
        self._log_path = log_path
        self._log: GaugeLog | None = None
        self._bye_sent = False

    def first(self) -> list[tuple[int, Message]]:
        return [decode_frame(self.core.hello(), self.max_payload)]

    async def recv(self) -> list[tuple[int, Message]] | None:
        out, self._out = self._out, []
        return out or None

    async def send(self, data: bytes) -> None:
        seq, msg = decode_frame(data, MAX_PAYLOAD)  # the server's own frames
        try:
            frames = self._answer(seq, msg)
        except Exception as exc:  # noqa: BLE001 -- the model failed: tell the door, as a client would
            log.warning("theory source failed: %s", exc)
            frames = [self.core.error_frame(exc)]
        self._out.extend(decode_frame(f, self.max_payload) for f in frames)

    def _start(self) -> list[bytes]:
        """The gauge log, then the first window."""
        core = self.core
        self._log = GaugeLog(self._log_path, "built-in theory source: gauges measured by SPH "
                             "and the theory (<gauge>_eta_model)\nSI units; eta up from "
                             "the still-water level; t is the SPH time")
        self._log.labels = core.gauge_labels()
        self._log.describe(core.metadata())
        return core.next_window()

    def _answer(self, seq: int, msg: Message) -> list[bytes]:
        core = self.core
        if isinstance(msg, Welcome):
            return [core.on_welcome(seq, msg)]
        if isinstance(msg, Nodes):
            core.on_nodes(seq, msg)
            ask = core.gauges_request()   # the gauges' names for theory.csv's columns
            return [ask] if ask is not None else self._start()
        if isinstance(msg, Gauges):
            core.on_gauges(seq, msg)
            return self._start()
        if isinstance(msg, Result):
            record = core.on_result(seq, msg)
            if self._log is not None:
                self._log.write(record)
            if core.windows_left:
                return core.next_window()
            self._bye_sent = True
            return [core.bye()]
        if isinstance(msg, Bye):
            if self._bye_sent:  # the echo of our BYE; one out of turn just ends the session
                core.on_bye(seq, msg)
            return []
        if isinstance(msg, Error):  # the door ends the session and sets the run's state
            return []
        if core.session.keepalive(seq, msg):  # KEEPALIVE: a window solving longer than
            return []                           # keepalive_every (a compile, a loaded machine)
        raise RuntimeError(f"theory source: unexpected {msg.TYPE.name} from the server")

    async def close(self) -> None:
        if self._log is not None:
            self._log.close()


async def serve_theory(manager: RunManager, run: Run) -> None:
    """Drive an attached run with its request's theory source until the session ends."""
    source = run.request.source
    assert source is not None
    core = CouplingCore(lambda welcome: source.build(welcome.depth),
                        CouplingOptions(window=source.window), run_id=run.info.id,
                        scene_hash=bytes.fromhex(run.info.scene_hash),
                        client_name=f"wavesph built-in {source.theory} theory")
    client = TheoryClient(core, fresh_path(run.dir, "theory", ".csv"))
    await serve_client(manager, run, client, client.first())
