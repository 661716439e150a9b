"""The coupling loop over a real connection: handshake, windows, BYE; errors made clear.

    from wave_client.coupling import couple, CouplingOptions
    from wave_client.theories import StokesWave
    report = couple("ws://127.0.0.1:8000/runs/r1/couple", StokesWave(0.08, 2.0, 1.0, ramp_time=4.0),
                    CouplingOptions(window=0.04), log_path="gauges.csv")

On any failure the client sends an ERROR frame (when the connection still stands) and closes,
then raises: `ServerError` (the server sent ERROR), `CouplingTimeout` (no reply in time),
`ServerEnded` (the server said BYE early), `CouplingError` (anything else, connection lost
included); each carries ``.report``, the windows received so far. Every window is also appended
to the CSV log and flushed as it arrives, so a failed run keeps what it measured.
"""

from __future__ import annotations

import asyncio
import json
import math
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

import numpy as np
from tqdm import tqdm

from wave_client.progress_bars import TQDM_INTERVAL

from protocol import ErrorCode, ProtocolError, RemoteError, Welcome
from wave_client.coupling.core import (CouplingCore, CouplingError, CouplingOptions, ModelSource,
                                       ServerEnded, WindowRecord)
from wave_client.coupling.transport import TransportClosed, open_transport, parse_url

WAIT_NOTE_EVERY = 10.0  # [s] between "still waiting for the run to start" lines (1.0 server)
WAIT_NOTE_EVERY_WORKING = 60.0  # [s] between "still preparing" lines (WORKING before WELCOME)


class CouplingTimeout(CouplingError):
    """The server did not answer within the timeout (vanished or stuck)."""


class ServerError(CouplingError):
    """The server refused or failed: it sent an ERROR frame (``code``, ``text``)."""

    def __init__(self, code: ErrorCode, text: str) -> None:
        super().__init__(f"server error {code.name} ({int(code)}): {text}")
        self.code, self.text = code, text


@dataclass
class CouplingReport:
    """What a coupled run did: every window's record, and where the wall time went."""

    welcome: Welcome | None = None
    gauges: dict[str, int | None] = field(default_factory=dict)        # side -> gauge index
    gauge_names: dict[str, str | None] = field(default_factory=dict)   # side -> gauge name
    records: list[WindowRecord] = field(default_factory=list)
    wall_time: float = 0.0     # s, whole run
    model_time: float = 0.0    # s, spent in the wave model (advance + sampling + feedback)
    wait_time: float = 0.0     # s, waiting for the server (SPH solve + transport)

    @property
    def t(self) -> np.ndarray:
        return np.array([r.t1 for r in self.records])

    @property
    def eta(self) -> np.ndarray:
        """Measured elevation, shape (windows, gauges) [m]."""
        return np.array([r.eta for r in self.records]).reshape(len(self.records), -1)


class GaugeLog:
    """CSV of the gauge series, one row per window, flushed as it comes (nothing lost on a crash).

    Columns: t [s], steps, then per gauge g (its name from a 1.1 server, else its index), named
    ``<gauge>_<quantity>`` as in every wavesph CSV: g_eta [m] (measured), g_wet, g_u_ref, g_w_ref
    [m/s], g_eta_model [m]; finally du_inlet,
    du_outlet [m/s] (the seed 002 corrections applied). One header row, no comment lines (the
    README's CSV dialect): the run's metadata goes to ``<stem>.meta.json`` beside it.
    """

    def __init__(self, path: Path, header: str) -> None:
        self.path = Path(path)
        self.meta_path = self.path.with_suffix(".meta.json")
        for p in (self.path, self.meta_path):
            if p.exists():
                raise ValueError(f"log_path {p} exists: refusing to overwrite a run's data")
        try:
            self._f: TextIO = self.path.open("x", encoding="utf-8")
        except OSError as exc:
            raise ValueError(f"log_path {self.path}: cannot create it ({exc.strerror})") from exc
        self.notes: list[str] = header.splitlines()
        self.fields: dict[str, Any] = {}
        self._write_meta()
        self._columns_written = False
        self.labels: list[str] | None = None  # gauge names (1.1 server) or indices, per column

    def _write_meta(self) -> None:
        tmp = self.meta_path.with_name(self.meta_path.name + ".tmp")
        tmp.write_text(json.dumps({"csv": self.path.name, "notes": self.notes, **self.fields},
                                  indent=1))
        os.replace(tmp, self.meta_path)

    def note(self, line: str) -> None:
        """One line of run metadata (into ``<stem>.meta.json``)."""
        self.notes.append(line)
        self._write_meta()

    def describe(self, fields: dict[str, Any]) -> None:
        """The run's metadata as JSON fields (CouplingCore.metadata) into ``<stem>.meta.json``."""
        self.fields.update(fields)
        self._write_meta()

    def write(self, r: WindowRecord) -> None:
        n = r.eta.size
        if not self._columns_written:
            cols = ["t", "steps"]
            # <gauge>_<quantity>, as gauges.csv and probes.csv
            for label in (self.labels or [str(i) for i in range(n)]):
                cols += [f"{label}_eta", f"{label}_wet", f"{label}_u_ref", f"{label}_w_ref",
                         f"{label}_eta_model"]
            self._f.write(",".join(cols + ["du_inlet", "du_outlet"]) + "\n")
            self._columns_written = True
        row = [f"{r.t1:.12g}", str(r.steps)]
        for i in range(n):
            row += [f"{r.eta[i]:.9g}", str(int(r.wet[i])), f"{r.u_ref[i]:.9g}", f"{r.w_ref[i]:.9g}",
                    f"{r.eta_model[i]:.9g}"]
        self._f.write(",".join(row + [f"{r.du_inlet:.9g}", f"{r.du_outlet:.9g}"]) + "\n")
        self._f.flush()

    def close(self) -> None:
        self._f.close()


async def run_coupling(url: str, model: ModelSource, options: CouplingOptions | None = None, *,
                       run_id: str | None = None, scene_hash: bytes | None = None,
                       timeout: float = 120.0, connect_timeout: float = 10.0,
                       queue_timeout: float = 3600.0,
                       log_path: str | Path | None = None, progress: bool = True) -> CouplingReport:
    """Couple ``model`` to the SPH server at ``url`` until t_end; see the module docstring.

    ``timeout`` bounds every wait for a reply [s] (a RESULT takes as long as SPH needs for one
    window); WELCOME comes when the server has started the run and has a stepping slot for it
    (the run is reserved for this client meanwhile), so it is awaited up to ``queue_timeout``
    [s], with a line on stderr every 10 s when ``progress``. ``run_id`` defaults to the one in a
    ws:// url (required by the server on tcp://).
    """
    if not timeout > 0 or not connect_timeout > 0 or not queue_timeout > 0:
        raise ValueError("timeout, connect_timeout and queue_timeout must be > 0 s")
    _, _, _, url_run = parse_url(url)
    core = CouplingCore(model, options, run_id=run_id if run_id is not None else url_run,
                        **({} if scene_hash is None else {"scene_hash": scene_hash}))
    report = CouplingReport()
    log: GaugeLog | None = None
    if log_path is not None:
        log = GaugeLog(Path(log_path), f"wavesph couple: gauge series from {url}\n"
                       "SI units; eta up from the still-water level; t is the SPH time")
    start = time.perf_counter()
    try:
        transport = await open_transport(url, connect_timeout)
    except (OSError, TimeoutError) as exc:
        if log is not None:
            log.close()
        raise CouplingError(f"cannot connect to {url}: {exc or type(exc).__name__}") from exc
    bar = None
    stage = "handshake"
    try:
        await transport.send([core.hello()])
        stage, waited = f"waiting for the run to start (up to {queue_timeout:g} s)", timeout
        timeout = queue_timeout
        welcome = await _await_welcome(transport, core, queue_timeout, progress)
        stage, timeout = "handshake", waited
        await transport.send([core.on_welcome(*welcome)])
        core.on_nodes(*await transport.recv(timeout))
        ask = core.gauges_request()
        if ask is not None:
            await transport.send([ask])
            core.on_gauges(*await transport.recv(timeout))
        report.welcome, report.gauges = core.welcome, core.gauges
        labels = core.gauge_labels()
        report.gauge_names = {side: None if i is None else labels[i] for side, i in core.gauges.items()}
        if log is not None:
            log.labels = core.gauge_labels()
            log.describe(core.metadata())
        bar = tqdm(total=core.windows_left, unit="window", desc="coupling", disable=not progress,
                   mininterval=TQDM_INTERVAL)
        while core.windows_left:
            stage = f"window {core.window_index + 1}/{core.times.size}"
            t_a = time.perf_counter()
            frames = core.next_window()
            t_b = time.perf_counter()
            await transport.send(frames)
            reply = await _reply(transport, core, timeout)
            t_c = time.perf_counter()
            record = core.on_result(*reply)
            report.records.append(record)
            report.model_time += (t_b - t_a) + (time.perf_counter() - t_c)
            report.wait_time += t_c - t_b
            if log is not None:
                log.write(record)
            bar.update()
            bar.set_postfix(t=f"{record.t1:.3f}s", steps=record.steps)
        stage = "closing"
        await transport.send([core.bye()])
        try:
            core.on_bye(*await transport.recv(min(timeout, 5.0)))
        except (TimeoutError, TransportClosed, ProtocolError):
            pass  # the work is done and logged; a missing BYE echo loses nothing
    except RemoteError as exc:
        raise _keep(report, ServerError(exc.code, exc.text)) from exc
    except TimeoutError as exc:
        await _send_error(transport, core, TimeoutError(f"no reply within {timeout} s at {stage}"))
        raise _keep(report, CouplingTimeout(f"the server did not answer within {timeout} s "
                                            f"({stage}); it is stuck or gone")) from exc
    except TransportClosed as exc:
        raise _keep(report, CouplingError(f"connection lost at {stage}: {exc}")) from exc
    except ServerEnded as exc:
        raise _keep(report, ServerEnded(f"{exc} (at {stage})")) from exc
    except BaseException as exc:  # protocol violation, model failure, Ctrl-C: tell the server
        await _send_error(transport, core, exc)
        if isinstance(exc, ProtocolError):
            raise _keep(report, CouplingError(f"bad reply from the server at {stage}: {exc}")) from exc
        exc.add_note(f"wavesph couple: {len(report.records)} windows were received before this "
                     f"({stage})" + (f"; they are in {log_path}" if log_path else ""))
        raise
    finally:
        report.wall_time = time.perf_counter() - start
        if bar is not None:
            bar.close()
        if log is not None:
            log.close()
        await _close_quietly(transport)
    return report


async def _reply(transport, core: CouplingCore, timeout: float):
    """The next reply; WORKING frames (1.1 KEEPALIVE) restart the wait: ``timeout`` then bounds
    the silence of the server, not the solve of a window."""
    while True:
        reply = await transport.recv(timeout)
        if not core.session.keepalive(*reply):
            return reply


async def _await_welcome(transport, core: CouplingCore, limit: float, progress: bool):
    """The server's answer to HELLO, which waits while the run is queued, being built (a first
    run compiles the SPH kernels) or every stepping slot of the server is busy: up to ``limit``
    s. A 1.1 server sends WORKING meanwhile (KEEPALIVE): said once, then every
    WAIT_NOTE_EVERY_WORKING s; a silent (1.0) server is noted every WAIT_NOTE_EVERY s."""
    loop = asyncio.get_running_loop()
    start = loop.time()
    noted = -math.inf  # when the last "preparing" line was printed
    while True:
        left = limit - (loop.time() - start)
        if left <= 0:
            raise TimeoutError
        try:
            reply = await transport.recv(min(left, WAIT_NOTE_EVERY))
        except TimeoutError:
            if progress and loop.time() - start < limit:
                print(f"wavesph couple: no WELCOME yet (the run is queued, being built, or the "
                      f"server's stepping slots are busy); reserved for us, waiting "
                      f"{loop.time() - start:.0f} s", file=sys.stderr, flush=True)
            continue
        if not core.session.keepalive(*reply):
            return reply
        now = loop.time()
        if progress and now - noted >= WAIT_NOTE_EVERY_WORKING:
            print("wavesph couple: the server is preparing the run (a first run compiles the SPH "
                  "kernels, 1-5 min; or it waits for a stepping slot)..." if noted < 0 else
                  f"wavesph couple: the server is still preparing the run ({now - start:.0f} s)",
                  file=sys.stderr, flush=True)
            noted = now


def _keep(report: CouplingReport, err: CouplingError) -> CouplingError:
    """Attach what was received so far: a failed run still hands back its windows."""
    err.report = report  # type: ignore[attr-defined]
    return err


async def _send_error(transport, core: CouplingCore, exc: BaseException) -> None:
    try:
        await asyncio.wait_for(transport.send([core.error_frame(exc)]), 2.0)
    except Exception:  # the connection may already be gone: nothing more to tell
        pass


async def _close_quietly(transport) -> None:
    try:
        await asyncio.wait_for(transport.close(), 5.0)
    except Exception:
        pass


def couple(url: str, model: ModelSource, options: CouplingOptions | None = None,
           **kwargs) -> CouplingReport:
    """Blocking wrapper of `run_coupling` (same arguments)."""
    return asyncio.run(run_coupling(url, model, options, **kwargs))
