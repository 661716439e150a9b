"""WebSocket keepalive pings must not cost a busy client its run (found 2026-11-23).

A coupling client answers the server's pings only while its asyncio loop runs; it runs its wave
model in that loop between frames (the accuracy sweep's Boussinesq model, compiling cold under
load, blocked it 53 s in window 1). uvicorn's defaults (ping every 20 s, pong due within 20 s)
dropped such a client: run failed "client disconnected", client "connection lost at window
1/392". Here uvicorn's defaults are scaled 1/100 so the test takes seconds, and the client
blocks its loop for BLOCK s in one window.
"""

from __future__ import annotations

import time

import pytest
import uvicorn

from server_harness import live_server
from sph_engine_double import EngineDouble
from wave_client.coupling import CouplingError, CouplingOptions, couple
from wave_client.theories.linear import AiryWave

SCALE = 0.01   # uvicorn's keepalive defaults (20 s, 20 s) -> 0.2 s, 0.2 s
BLOCK = 1.5    # [s] the client's loop is blocked: far beyond ping interval + timeout
WINDOW = 0.05  # [s]


class _ScaledDefaults(uvicorn.Config):
    """uvicorn.Config with its keepalive defaults scaled: what a server start that leaves them
    alone would get (an explicit value, as server.asgi passes, wins)."""

    def __init__(self, app, **kw) -> None:
        kw.setdefault("ws_ping_interval", 20.0 * SCALE)
        kw.setdefault("ws_ping_timeout", 20.0 * SCALE)
        super().__init__(app, **kw)


@pytest.fixture
def scaled_uvicorn(monkeypatch):
    monkeypatch.setattr(uvicorn, "Config", _ScaledDefaults)


class BusyWave(AiryWave):
    """A wave model whose advance to ``busy_at`` blocks the caller (the client's loop) for
    BLOCK s, as a numba compile or a long model step does."""

    def __init__(self, busy_at: float) -> None:
        super().__init__(height=0.02, period=1.0, depth=0.3)
        self.busy_at, self.blocked = busy_at, 0.0

    def advance_to(self, t: float) -> None:
        if t >= self.busy_at - 1e-9 and not self.blocked:
            tic = time.perf_counter()
            time.sleep(BLOCK)
            self.blocked = time.perf_counter() - tic
        super().advance_to(t)


def _engine(request, run_dir, **kw):
    return EngineDouble(request)


@pytest.mark.parametrize("door", ["ws", "tcp"])
def test_a_client_busy_longer_than_the_ping_timeout_keeps_its_run(tmp_path, scaled_uvicorn, door):
    # pings every 0.2 s (scaled default interval, also set explicitly so they flow after the fix)
    with live_server(tmp_path, _engine, ws_ping_interval=20.0 * SCALE) as srv:
        run = srv.create(t_end=4 * WINDOW)
        srv.wait_state(run["id"], "waiting_for_client")
        url = (f"ws://127.0.0.1:{srv.port}/runs/{run['id']}/couple" if door == "ws"
               else f"tcp://127.0.0.1:{srv.tcp_port}")
        model = BusyWave(busy_at=WINDOW)  # the first window, as the sweep's failure
        report = couple(url, model, CouplingOptions(window=WINDOW), run_id=run["id"],
                        timeout=30.0, progress=False)
        assert model.blocked >= BLOCK
        assert len(report.records) == 4
        info = srv.wait_state(run["id"], "finished")
        assert info["windows"] == 4


def test_a_client_dropped_by_an_opted_in_ping_timeout_keeps_its_data_and_resumes(tmp_path):
    # ws_ping_timeout set: a late pong drops the client (the old default behaviour, on purpose)
    with live_server(tmp_path, _engine, ws_ping_interval=0.1, ws_ping_timeout=0.2,
                     checkpoint_every_t=WINDOW) as srv:
        run = srv.create(t_end=6 * WINDOW)
        srv.wait_state(run["id"], "waiting_for_client")
        url = f"ws://127.0.0.1:{srv.port}/runs/{run['id']}/couple"
        gauges_log = tmp_path / "client_gauges.csv"
        with pytest.raises(CouplingError, match="connection lost at window 4/6") as err:
            couple(url, BusyWave(busy_at=4 * WINDOW), CouplingOptions(window=WINDOW),
                   timeout=30.0, log_path=gauges_log, progress=False)
        assert len(err.value.report.records) == 3  # the client hands back what it received
        assert len(gauges_log.read_text().splitlines()) == 1 + 3
        info = srv.wait_state(run["id"], "failed")
        assert info["status"] == "failed: client disconnected" and info["resumable"]
        run_dir = tmp_path / "runs" / run["id"]
        assert (run_dir / "meta.json").exists() and (run_dir / "state.npz").exists()
        rows = srv.http.get(f"/runs/{run['id']}/gauges", params={"format": "json"}).json()["rows"]
        assert [r["t"] for r in rows] == pytest.approx([WINDOW, 2 * WINDOW, 3 * WINDOW])
        # resume from the last window boundary; a client not blocking finishes the run
        assert srv.http.post(f"/runs/{run['id']}/resume").status_code == 202
        srv.wait_state(run["id"], "waiting_for_client")
        report = couple(url, AiryWave(height=0.02, period=1.0, depth=0.3),
                        CouplingOptions(window=WINDOW), timeout=30.0, progress=False)
        assert report.welcome.t_start == pytest.approx(3 * WINDOW) and len(report.records) == 3
        assert srv.wait_state(run["id"], "finished")["windows"] == 6
