"""The coupling client against a small fake SPH peer built from the protocol package.

The fake peer (WebSocket via websockets.serve, TCP via asyncio.start_server, 127.0.0.1,
ephemeral port) runs `protocol.SphSession`; its toy engine "measures" at each gauge the
theory's elevation plus a fixed offset, so the seed 002 correction the client must apply next
window is known exactly: u_in = u_th - (eta_in,meas - eta_th) sqrt(g/d),
u_out = u_th - (eta_th - eta_out,meas) sqrt(g/d).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import math
import time

import numpy as np
import pytest

from protocol import (Bye, ErrorCode, FrameDecoder, Nodes, ProtocolError, Result, SphSession, Welcome,
                      decode_frame, encode_frame)
from protocol.session import PeerError, Reply, SetWindow, SolveWindow, set_payload_size
from wave_client.coupling import (CouplingCore, CouplingError, CouplingOptions, CouplingTimeout,
                                  GaugeLog, ServerEnded, ServerError, parse_url, run_coupling)
from wave_client.theories import AiryWave
from wavesph.cli import couple as couple_cli

G, DEPTH = 9.81, 1.0
C = math.sqrt(G / DEPTH)
H, T = 0.08, 2.0
T_END, WINDOW = 0.5, 0.05
# inlet: two columns (x = 0, 0.02), outlet: one column (x = 10); some nodes above the surface
Z_COL = np.linspace(-0.975, 0.075, 8)
NODE_X = np.concatenate([np.zeros(8), np.full(8, 0.02), np.full(8, 10.0)])
NODE_Z = np.tile(Z_COL, 3)
NODE_SIDE = np.array([0] * 16 + [1] * 8)
GAUGE_X = np.array([0.5, 5.0, 9.5])           # inlet gauge, middle gauge, outlet gauge
OFFSETS = np.array([0.01, 0.003, -0.02])       # measured - theory at each gauge [m]


def make_welcome(**overrides) -> Welcome:
    fields = dict(capabilities=1, scene_hash=bytes(32), g=G, depth=DEPTH, still_water_level=1.0,
                  z_ref=-0.5, t_start=0.0, t_end=T_END, dt_sph=1e-4, window_max=0.1,
                  idle_timeout=10.0, n_nodes=NODE_X.size, n_gauges=GAUGE_X.size,
                  max_payload=set_payload_size(NODE_X.size), run_id="r1", server="fake-sph")
    fields.update(overrides)
    return Welcome(**fields)


def make_nodes() -> Nodes:
    return Nodes(NODE_X, NODE_Z, NODE_SIDE, GAUGE_X)


class FakeSph:
    """Toy SPH peer. behaviour: 'ok', 'still' (measures still water), 'refuse_set' (ERROR on
    the 3rd SET), 'stall' (never answers the 2nd SOLVE), 'hangup' (closes on the 2nd SOLVE),
    'bye' (BYE instead of the 2nd RESULT)."""

    def __init__(self, behaviour: str = "ok", nodes: Nodes | None = None) -> None:
        self.behaviour = behaviour
        self.theory = AiryWave(H, T, DEPTH)
        self.nodes = nodes or make_nodes()
        self.welcome = make_welcome(n_nodes=self.nodes.x.size, n_gauges=self.nodes.gauge_x.size,
                                    max_payload=set_payload_size(self.nodes.x.size))
        self.sets: list[SetWindow] = []
        self.peer_errors: list[PeerError] = []
        self.done = asyncio.Event()

    def measure(self, t: float, last: SetWindow) -> Result:
        self.theory.advance_to(t)
        gx = self.nodes.gauge_x
        eta = self.theory.elevation(gx) + OFFSETS[:gx.size]
        u_ref = np.full(gx.size, float(np.mean(last.u)))
        if self.behaviour == "still":
            eta, u_ref = 0.0 * eta, 0.0 * u_ref
        return Result(t, 40, eta, np.ones(gx.size, np.uint32), u_ref, np.zeros(gx.size))

    async def serve(self, recv, send) -> None:
        session = SphSession(self.welcome, self.nodes)
        try:
            while True:
                try:
                    seq, msg = await asyncio.wait_for(recv(), 5.0)  # bounded: stops by itself
                except (TimeoutError, ConnectionError):
                    return
                try:
                    action = session.receive(seq, msg)
                except ProtocolError as exc:
                    await send(session.error_frame(exc))
                    return
                if isinstance(action, Reply):
                    await send(action.data)
                    if action.close:
                        return
                elif isinstance(action, SetWindow):
                    self.sets.append(action)
                    if self.behaviour == "refuse_set" and len(self.sets) == 3:
                        await send(session.error_frame(ProtocolError(
                            ErrorCode.TIME_MISMATCH, "SET window starts at t0=9 s, SPH is at t=0.1 s")))
                        return
                elif isinstance(action, SolveWindow):
                    if len(self.sets) == 2 and self.behaviour == "stall":
                        await asyncio.sleep(1.0)
                        continue  # swallow the SOLVE; the client must time out
                    if len(self.sets) == 2 and self.behaviour == "hangup":
                        return
                    if len(self.sets) == 2 and self.behaviour == "bye":
                        # a BYE out of turn (a v1 server sends BYE only to answer one)
                        await send(encode_frame(Bye("run cancelled by its owner"), seq))
                        return
                    await send(session.result(action, self.measure(action.t1, self.sets[-1])))
                elif isinstance(action, PeerError):
                    self.peer_errors.append(action)
                    return
        finally:
            self.done.set()


class PeerServer:
    """Context manager: the fake peer on 127.0.0.1 over 'ws' or 'tcp'; .url to connect to."""

    def __init__(self, fake: FakeSph, transport: str) -> None:
        self.fake, self.transport = fake, transport

    async def __aenter__(self) -> "PeerServer":
        if self.transport == "ws":
            from websockets.asyncio.server import serve

            async def handler(ws):
                async def recv():
                    return decode_frame(await ws.recv())

                await self.fake.serve(recv, ws.send)

            self._server = await serve(handler, "127.0.0.1", 0, compression=None)
            port = self._server.sockets[0].getsockname()[1]
            self.url = f"ws://127.0.0.1:{port}/runs/r1/couple"
        else:
            async def handler(reader, writer):
                dec, ready = FrameDecoder(), []

                async def recv():
                    while not ready:
                        data = await reader.read(65536)
                        if not data:
                            raise ConnectionError("client closed")
                        ready.extend(dec.feed(data))
                    return ready.pop(0)

                async def send(data):
                    writer.write(data)
                    await writer.drain()

                await self.fake.serve(recv, send)
                writer.close()

            self._server = await asyncio.start_server(handler, "127.0.0.1", 0)
            port = self._server.sockets[0].getsockname()[1]
            self.url = f"tcp://127.0.0.1:{port}"
        return self

    async def __aexit__(self, *exc) -> None:
        self._server.close()
        await asyncio.wait_for(self._server.wait_closed(), 5.0)


def run(coro, limit: float = 20.0):
    """Run a test coroutine with a hard bound: a hang fails the test instead of the suite."""
    return asyncio.run(asyncio.wait_for(coro, limit))


def expected_u(t1: float, x: np.ndarray, z: np.ndarray) -> np.ndarray:
    ref = AiryWave(H, T, DEPTH)
    ref.advance_to(t1)
    return np.array([ref.velocity(xi, zi)[0] for xi, zi in zip(x, z)])


# --- end to end over both transports --------------------------------------------------------
@pytest.mark.parametrize("transport", ["ws", "tcp"])
def test_coupled_run_applies_seed002_correction(transport, tmp_path):
    fake = FakeSph()
    log = tmp_path / "gauges.csv"

    async def scenario():
        async with PeerServer(fake, transport) as peer:
            # unfiltered (cutoff = inf): the correction must be the seed 002 formula exactly
            options = CouplingOptions(window=WINDOW, absorb=True, absorb_cutoff=math.inf)
            report = await run_coupling(peer.url, AiryWave(H, T, DEPTH), options, run_id="r1",
                                        timeout=5.0, log_path=log, progress=False)
            await asyncio.wait_for(fake.done.wait(), 5.0)
            return report

    report = run(scenario())
    n = round(T_END / WINDOW)
    assert len(report.records) == len(fake.sets) == n
    assert report.gauges == {"inlet": 0, "outlet": 2}
    np.testing.assert_allclose([s.t1 for s in fake.sets], WINDOW * np.arange(1, n + 1), rtol=1e-12)
    assert fake.sets[-1].t1 == T_END
    # gauge values came back: measured = theory + offsets, and eta_model is the theory
    ref = AiryWave(H, T, DEPTH)
    for rec in report.records:
        ref.advance_to(rec.t1)
        np.testing.assert_allclose(rec.eta_model, ref.elevation(GAUGE_X), atol=1e-15)
        np.testing.assert_allclose(rec.eta, ref.elevation(GAUGE_X) + OFFSETS, atol=1e-15)
        assert rec.steps == 40
    inlet, outlet = NODE_SIDE == 0, NODE_SIDE == 1
    # window 1: nothing measured yet, pure theory
    np.testing.assert_allclose(fake.sets[0].u, expected_u(WINDOW, NODE_X, NODE_Z), atol=1e-14)
    # later windows: the correction formula of seed 002, exactly
    for s in fake.sets[1:]:
        u_th = expected_u(s.t1, NODE_X, NODE_Z)
        np.testing.assert_allclose(s.u[inlet], u_th[inlet] - (OFFSETS[0]) * C, atol=1e-14)
        np.testing.assert_allclose(s.u[outlet], u_th[outlet] - (-OFFSETS[2]) * C, atol=1e-14)
        ref.advance_to(s.t1)
        np.testing.assert_allclose(s.eta, ref.elevation(NODE_X), atol=1e-15)
        assert np.all(np.isfinite(s.w))
    assert all(r.du_inlet == pytest.approx(-0.01 * C) for r in report.records[1:])
    # the CSV log has a row per window and one header row; its metadata (units, model, gauges)
    # is in <stem>.meta.json beside it
    lines = log.read_text().splitlines()
    meta = json.loads(log.with_suffix(".meta.json").read_text())
    assert "SI units" in "\n".join(meta["notes"])
    # fields, not reprs: the model's name and settings, gauges, window, short numbers
    assert meta["model"]["name"] == "AiryWave" and meta["model"]["parameters"]["height"] == 0.08
    assert [g["x_m"] for g in meta["gauges"]] == [0.5, 5.0, 9.5]
    assert " at 0x" not in json.dumps(meta) and "{'" not in json.dumps(meta)
    rows = lines
    assert rows[0].startswith("t,steps,0_eta,0_wet") and len(rows) == n + 1   # a 1.0 server: indices
    assert float(rows[-1].split(",")[0]) == pytest.approx(T_END)


def test_by_default_the_pure_theory_is_sent():
    # the SPH side absorbs by itself unless told otherwise: the client must not add its own
    fake = FakeSph()

    async def scenario():
        async with PeerServer(fake, "tcp") as peer:
            await run_coupling(peer.url, AiryWave(H, T, DEPTH),
                               CouplingOptions(window=WINDOW, t_end=0.2),
                               run_id="r1", timeout=5.0, progress=False)

    run(scenario())
    assert len(fake.sets) == 4
    for s in fake.sets:
        np.testing.assert_allclose(s.u, expected_u(s.t1, NODE_X, NODE_Z), atol=1e-14)


def test_two_way_feedback_reaches_the_model():
    class Recording(AiryWave):
        def __init__(self) -> None:
            super().__init__(H, T, DEPTH)
            self.imposed: list[tuple[float, float, float, float]] = []

        def impose(self, x, eta, u_ref):
            self.imposed.append((self.t, x, eta, u_ref))

    fake, model = FakeSph(), Recording()

    async def scenario():
        async with PeerServer(fake, "ws") as peer:
            await run_coupling(peer.url, model, CouplingOptions(window=WINDOW, t_end=0.15,
                                                                x_offset=100.0),
                               timeout=5.0, progress=False)

    run(scenario())
    assert len(model.imposed) == 3
    ref = AiryWave(H, T, DEPTH)
    for (t, x, eta, u_ref), s in zip(model.imposed, fake.sets):
        ref.advance_to(t)
        assert t == pytest.approx(s.t1)
        assert x == pytest.approx(100.01)  # inlet boundary (mean node x) in model coordinates
        assert eta == pytest.approx(float(ref.elevation(0.5)) + OFFSETS[0], abs=1e-15)
        assert u_ref == pytest.approx(float(np.mean(s.u)))


# --- failures: clear exceptions, never a hang -----------------------------------------------
async def couple_airy(fake: "FakeSph", transport: str, run_id: str | None = "r1"):
    """Couple the Airy wave of these tests to ``fake`` over ``transport`` until the run ends."""
    async with PeerServer(fake, transport) as peer:
        return await run_coupling(peer.url, AiryWave(H, T, DEPTH), CouplingOptions(window=WINDOW),
                                  run_id=run_id, timeout=5.0, progress=False)


@pytest.mark.parametrize("transport", ["ws", "tcp"])
def test_server_error_frame_becomes_clear_exception(transport):
    fake = FakeSph("refuse_set")
    with pytest.raises(ServerError, match="TIME_MISMATCH.*t0=9 s") as info:
        run(couple_airy(fake, transport))
    assert info.value.code is ErrorCode.TIME_MISMATCH


@pytest.mark.parametrize("transport", ["ws", "tcp"])
def test_vanished_peer_times_out(transport):
    fake = FakeSph("stall")

    async def scenario():
        async with PeerServer(fake, transport) as peer:
            t0 = time.perf_counter()
            with pytest.raises(CouplingTimeout, match=r"within 0.4 s \(window 2/10\)"):
                await run_coupling(peer.url, AiryWave(H, T, DEPTH), CouplingOptions(window=WINDOW),
                                   run_id="r1", timeout=0.4, progress=False)
            assert time.perf_counter() - t0 < 10.0  # the 0.4 s timeout, not the 120 s default
            await asyncio.wait_for(fake.done.wait(), 5.0)

    run(scenario())
    # the client said why it left before closing
    assert fake.peer_errors and fake.peer_errors[0].code == ErrorCode.TIMEOUT


@pytest.mark.parametrize("transport", ["ws", "tcp"])
def test_peer_hangup_is_connection_lost(transport):
    fake = FakeSph("hangup")
    with pytest.raises(CouplingError, match="connection lost at window 2/10") as info:
        run(couple_airy(fake, transport))
    assert len(info.value.report.records) == 1  # the window solved before the hangup is kept


def test_server_bye_mid_run_ends_the_run_clearly():
    fake = FakeSph("bye")
    with pytest.raises(ServerEnded, match="ended the run: run cancelled by its owner .at window 2/10"):
        run(couple_airy(fake, "ws", run_id=None))


def test_model_failure_is_reported_to_the_server_then_raised():
    class Broken(AiryWave):
        def velocity(self, x, z):
            if self.t > 0.12:
                raise RuntimeError("wave model blew up")
            return super().velocity(x, z)

    fake = FakeSph()

    async def scenario():
        async with PeerServer(fake, "tcp") as peer:
            with pytest.raises(RuntimeError, match="blew up"):
                await run_coupling(peer.url, Broken(H, T, DEPTH), CouplingOptions(window=WINDOW),
                                   run_id="r1", timeout=5.0, progress=False)
            await asyncio.wait_for(fake.done.wait(), 5.0)

    run(scenario())
    assert fake.peer_errors[0].code == ErrorCode.INTERNAL
    assert "wave model blew up" in fake.peer_errors[0].text


def test_refused_connection_is_a_coupling_error():
    async def scenario():
        server = await asyncio.start_server(lambda r, w: None, "127.0.0.1", 0)
        port = server.sockets[0].getsockname()[1]
        server.close()
        await server.wait_closed()
        await run_coupling(f"tcp://127.0.0.1:{port}", AiryWave(H, T, DEPTH), run_id="r1",
                           connect_timeout=2.0, progress=False)

    with pytest.raises(CouplingError, match="cannot connect"):
        run(scenario())


# --- the sans-I/O core without any server ---------------------------------------------------
def handshake(core: CouplingCore, welcome: Welcome | None = None) -> None:
    seq, hello = decode_frame(core.hello())
    assert seq == 1 and hello.run_id == "r1"
    seq, msg = decode_frame(core.on_welcome(1, welcome or make_welcome()))
    assert seq == 2 and type(msg).__name__ == "GetNodes"
    core.on_nodes(2, make_nodes())


def window(core: CouplingCore, result_eta: np.ndarray, wet=(1, 1, 1)):
    set_frame, solve_frame = core.next_window()
    _, s = decode_frame(set_frame)
    seq, _ = decode_frame(solve_frame)
    res = Result(s.t1, 10, result_eta, np.array(wet, np.uint32), np.zeros(3), np.zeros(3))
    return s, core.on_result(seq, res)


def test_core_model_factory_takes_depth_from_welcome_and_default_window():
    seen = []

    def factory(welcome: Welcome):
        seen.append(welcome.depth)
        return AiryWave(H, T, welcome.depth)

    core = CouplingCore(factory, run_id="r1")
    handshake(core, make_welcome(depth=0.7, window_max=0.1))
    assert seen == [0.7] and core.model.depth == 0.7
    assert core.window == pytest.approx(T / 50)  # < window_max
    assert core.times[-1] == T_END and core.times.size == math.ceil(T_END / (T / 50) - 1e-9)


def test_core_aligns_the_inlet_with_the_models_coupling_point():
    class Placed(AiryWave):
        x_couple = 30.0  # like BoussinesqModel: where the SPH inlet sits in model x

    core = CouplingCore(Placed(H, T, DEPTH), CouplingOptions(window=WINDOW), run_id="r1")
    handshake(core)
    assert core.x_inlet == pytest.approx(0.01) and core.x_offset == pytest.approx(29.99)
    _, s = decode_frame(core.next_window()[0])
    ref = AiryWave(H, T, DEPTH)
    ref.advance_to(s.t1)
    np.testing.assert_allclose(s.eta, ref.elevation(NODE_X + 29.99), atol=1e-15)
    core = CouplingCore(Placed(H, T, DEPTH), CouplingOptions(x_offset=0.0), run_id="r1")
    handshake(core)
    assert core.x_offset == 0.0  # an explicit offset wins


def test_core_last_window_is_snapped_to_t_end():
    core = CouplingCore(AiryWave(H, T, DEPTH), CouplingOptions(window=0.03, t_end=0.1), run_id="r1")
    handshake(core)
    np.testing.assert_allclose(core.times, [0.03, 0.06, 0.09, 0.1])


@pytest.mark.parametrize(
    "options,welcome,match",
    [
        (CouplingOptions(), dict(depth=1.3), "depth mismatch"),
        (CouplingOptions(window=0.2), {}, "window=0.2 s exceeds"),
        (CouplingOptions(t_end=3.0), {}, "t_end=3.0"),
    ],
)
def test_core_refuses_inconsistent_setup(options, welcome, match):
    core = CouplingCore(AiryWave(H, T, DEPTH), options, run_id="r1")
    core.hello()
    with pytest.raises(CouplingError, match=match):
        core.on_welcome(1, make_welcome(**welcome))


def test_core_gauge_choice_and_bad_index():
    core = CouplingCore(AiryWave(H, T, DEPTH), CouplingOptions(inlet_gauge=1), run_id="r1")
    handshake(core)
    assert core.gauges == {"inlet": 1, "outlet": 2}
    core = CouplingCore(AiryWave(H, T, DEPTH), CouplingOptions(outlet_gauge=3), run_id="r1")
    core.hello()
    core.on_welcome(1, make_welcome())
    with pytest.raises(CouplingError, match="outlet_gauge=3"):
        core.on_nodes(2, make_nodes())


def test_core_low_pass_of_the_mismatch():
    # constant mismatch m at the inlet gauge: after n results m_f = m (1 - (1 - a)^n),
    # a = dt / (tau + dt), tau = 1 / (2 pi f_c)
    f_c = 2.0
    core = CouplingCore(AiryWave(H, T, DEPTH),
                        CouplingOptions(window=WINDOW, absorb=True, absorb_cutoff=f_c), run_id="r1")
    handshake(core)
    tau = 1 / (2 * np.pi * f_c)
    assert core.filter_tau == pytest.approx(tau)
    a = WINDOW / (tau + WINDOW)
    ref = AiryWave(H, T, DEPTH)
    inlet = NODE_SIDE == 0
    for n in range(6):
        set_frame, solve_frame = core.next_window()
        _, s = decode_frame(set_frame)
        seq, _ = decode_frame(solve_frame)
        m_f = OFFSETS[0] * (1 - (1 - a) ** n)
        np.testing.assert_allclose(s.u[inlet], expected_u(s.t1, NODE_X, NODE_Z)[inlet] - m_f * C,
                                   atol=1e-14)
        ref.advance_to(s.t1)
        core.on_result(seq, Result(s.t1, 10, ref.elevation(GAUGE_X) + OFFSETS,
                                   np.ones(3, np.uint32), np.zeros(3), np.zeros(3)))
    # default cutoff: 3 / period of the model
    core = CouplingCore(AiryWave(H, T, DEPTH), CouplingOptions(absorb=True), run_id="r1")
    handshake(core)
    assert core.filter_tau == pytest.approx(T / (2 * np.pi * 3))


def test_core_dry_gauge_gives_no_correction_and_result_time_is_checked():
    core = CouplingCore(AiryWave(H, T, DEPTH),
                        CouplingOptions(window=WINDOW, absorb=True, absorb_cutoff=math.inf),
                        run_id="r1")
    handshake(core)
    _, rec = window(core, np.array([0.5, 0.0, 0.5]), wet=(0, 1, 1))  # inlet gauge dry
    s, rec = window(core, np.zeros(3))
    ref = AiryWave(H, T, DEPTH)
    ref.advance_to(s.t1)
    inlet = NODE_SIDE == 0
    np.testing.assert_allclose(s.u[inlet], expected_u(s.t1, NODE_X, NODE_Z)[inlet], atol=1e-14)
    assert rec.du_inlet == 0.0 and rec.du_outlet != 0.0
    set_frame, solve_frame = core.next_window()
    seq, _ = decode_frame(solve_frame)
    with pytest.raises(ProtocolError, match="RESULT.t=9.0"):
        core.on_result(seq, Result(9.0, 1, np.zeros(3), np.ones(3, np.uint32), np.zeros(3), np.zeros(3)))


def test_core_names_the_nodes_a_model_cannot_serve():
    class Short(AiryWave):  # a model whose grid ends at x = 2 m, like a Boussinesq domain
        def velocity(self, x, z):
            if np.any(np.asarray(x) > 2.0):
                raise ValueError("x outside the model grid [-20.0, 2.0]")
            return super().velocity(x, z)

    core = CouplingCore(Short(H, T, DEPTH), CouplingOptions(window=WINDOW), run_id="r1")
    handshake(core)
    with pytest.raises(CouplingError, match=r"outlet nodes at SPH x = 10.0 m .*outside the model grid"):
        core.next_window()


def test_core_sends_the_wave_inside_the_relaxation_zones_when_granted():
    """Protocol 1.2 ZONE_NODES: the client asks by default; granted, NODES may carry columns
    inside the zones (sides 2, 3) and the client sends the model's wave at each one's x and z
    (the face's absorption correction only at the faces); not granted, such a side is refused."""
    from protocol import Capability, Set

    zx = np.array([0.1, 0.2])   # two columns of the inlet's zone on the face's levels
    nodes = Nodes(np.concatenate([NODE_X, np.repeat(zx, 8)]), np.tile(Z_COL, 5),
                  np.concatenate([NODE_SIDE, np.full(16, 2)]).astype(np.uint32), GAUGE_X)
    welcome = make_welcome(capabilities=int(Capability.ZONE_NODES), n_nodes=nodes.x.size)
    core = CouplingCore(AiryWave(H, T, DEPTH), CouplingOptions(window=WINDOW, absorb=True),
                        run_id="r1")
    assert decode_frame(core.hello())[1].capabilities & Capability.ZONE_NODES
    core.on_welcome(1, welcome)
    core.on_nodes(2, nodes)
    set_frame, _ = core.next_window()
    s: Set = decode_frame(set_frame)[1]
    wave = AiryWave(H, T, DEPTH)
    wave.advance_to(WINDOW)
    for x in zx:
        col = nodes.x == x
        u, w = wave.velocity(x, Z_COL)
        np.testing.assert_allclose(s.u[col], u, rtol=1e-12)
        np.testing.assert_allclose(s.w[col], w, rtol=1e-12)
        np.testing.assert_allclose(s.eta[col], wave.elevation(np.array([x]))[0], rtol=1e-12)
    assert set(core.gauges) == {"inlet", "outlet"}   # the zones have no correction gauge
    core = CouplingCore(AiryWave(H, T, DEPTH), CouplingOptions(window=WINDOW), run_id="r1")
    core.hello()
    core.on_welcome(1, make_welcome(n_nodes=nodes.x.size))   # a server that did not grant it
    with pytest.raises(ProtocolError, match=r"NODES.side has unknown values \[2\]"):
        core.on_nodes(2, nodes)
    off = CouplingCore(AiryWave(H, T, DEPTH), CouplingOptions(zone_nodes=False), run_id="r1")
    assert not decode_frame(off.hello())[1].capabilities & Capability.ZONE_NODES
    # a theory's start-up ramp: a zone gets the wave as it arrives, one front factor at its x
    # nearest the wavemaker (the inlet's face: 1, the theory's ramped wave; an outlet zone
    # ahead of the front: still water)
    oz = np.array([9.9, 9.8])
    both = Nodes(np.concatenate([nodes.x, np.repeat(oz, 8)]), np.tile(Z_COL, 7),
                 np.concatenate([nodes.side, np.full(16, 3)]).astype(np.uint32), GAUGE_X)
    ramped = CouplingCore(AiryWave(H, T, DEPTH, ramp_time=1.0), CouplingOptions(window=WINDOW),
                          run_id="r1")
    ramped.hello()
    ramped.on_welcome(1, make_welcome(capabilities=int(Capability.ZONE_NODES),
                                      n_nodes=both.x.size))
    ramped.on_nodes(2, both)
    window(ramped, np.zeros(3))
    s = decode_frame(ramped.next_window()[0])[1]
    wave = AiryWave(H, T, DEPTH, ramp_time=1.0)
    wave.advance_to(2 * WINDOW)
    for x in zx:
        np.testing.assert_allclose(s.u[both.x == x], wave.velocity(x, Z_COL)[0], rtol=1e-12)
    assert np.abs(wave.velocity(9.9, Z_COL)[0]).max() > 1e-3   # the theory has it there ...
    assert np.all(s.u[both.side == 3] == 0.0) and np.all(s.w[both.side == 3] == 0.0)  # ... not yet


def test_core_refuses_non_finite_model_output():
    class NaNWave(AiryWave):
        def elevation(self, x):
            return np.full(np.shape(x), np.nan)

    core = CouplingCore(NaNWave(H, T, DEPTH), CouplingOptions(window=WINDOW), run_id="r1")
    handshake(core)
    with pytest.raises(CouplingError, match="non-finite eta"):
        core.next_window()


# --- command line ---------------------------------------------------------------------------
def cli_args(*argv: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    couple_cli.add_arguments(parser)
    return parser.parse_args(list(argv))


def test_cli_couples_over_tcp_and_writes_the_series(tmp_path, capsys):
    fake, out = FakeSph(), tmp_path / "g.csv"

    async def scenario():
        async with PeerServer(fake, "tcp") as peer:
            args = cli_args("--url", peer.url, "--run-id", "r1", "--model", "stokes", "--H", "0.08",
                            "--T", "2", "--order", "2", "--window", "0.05", "--t-end", "0.2",
                            "--out", str(out), "--no-progress", "--timeout", "5")
            return await asyncio.to_thread(couple_cli.main, args)

    assert run(scenario()) == 0
    assert len(fake.sets) == 4
    assert "coupled 4 windows" in capsys.readouterr().out
    assert len([ln for ln in out.read_text().splitlines() if not ln.startswith("#")]) == 5
    # the same output path again: refused, the first run's data is kept
    assert couple_cli.main(cli_args("--url", "tcp://127.0.0.1:1", "--run-id", "r1", "--model",
                                    "linear", "--H", "0.08", "--T", "2", "--out", str(out))) == 2
    assert "refusing to overwrite" in capsys.readouterr().err


BOUSSINESQ_SCENE = """
[grid]
x_start = -20.0
x_end = 2.0
dx = 0.1
t_end = 10.0
[bathymetry]
x = [0.0]
depth = [1.0]
[wave]
kind = "regular"
height = 0.08
period = 2.0
x_source = -12.0
[sponge]
left = 4.0
[gauges]
x = [0.0]
[coupling]
x = 0.0
"""


def test_cli_couples_the_boussinesq_model(tmp_path, capsys):
    pytest.importorskip("wave_client.boussinesq.wave_scene")
    config = tmp_path / "bsq.toml"
    config.write_text(BOUSSINESQ_SCENE)
    # an SPH zone with an inlet only (a beach at its end): the grid ends 2 m into it
    fake = FakeSph("still", Nodes(np.zeros(8), Z_COL, np.zeros(8, np.uint32), np.array([0.5, 5.0])))

    async def scenario():
        async with PeerServer(fake, "ws") as peer:
            args = cli_args("--url", peer.url, "--model", "boussinesq", "--config", str(config),
                            "--t-end", "0.2", "--no-progress", "--timeout", "60")
            return await asyncio.to_thread(couple_cli.main, args)

    assert run(scenario(), limit=90.0) == 0, capsys.readouterr().err
    assert len(fake.sets) == 5  # default window T/50 = 0.04 s from the scene's wave period
    assert all(np.all(np.isfinite(s.u)) for s in fake.sets)
    assert "coupled 5 windows" in capsys.readouterr().out
    # the waves have not reached x = 0 yet (source at -12 m, ramped) and SPH measures still
    # water, imposed back on the model (two-way): still water is sent
    assert max(np.abs(s.u).max() + np.abs(s.eta).max() for s in fake.sets) < 1e-6


@pytest.mark.parametrize(
    "argv,message",
    [
        (["--model", "stokes", "--H", "0.08"], "needs --H and --T"),
        (["--model", "boussinesq"], "needs --config"),
        (["--model", "linear", "--H", "0.9", "--T", "2", "--d", "1"], "height=0.9"),
        (["--model", "linear", "--H", "0.08", "--T", "2"], "--run-id is required"),
    ],
)
def test_cli_bad_arguments_exit_2_with_a_reason(argv, message, capsys):
    assert couple_cli.main(cli_args("--url", "tcp://127.0.0.1:1", *argv)) == 2
    assert message in capsys.readouterr().err


def test_core_error_frames_say_why_the_client_leaves():
    core = CouplingCore(AiryWave(H, T, DEPTH), run_id="r1")
    handshake(core)
    cases = [(TimeoutError("no reply"), ErrorCode.TIMEOUT, "no reply"),
             (KeyboardInterrupt(), ErrorCode.CANCELLED, "interrupted"),
             (ProtocolError(ErrorCode.MALFORMED, "bad magic"), ErrorCode.MALFORMED, "bad magic"),
             (RuntimeError("model diverged"), ErrorCode.INTERNAL, "RuntimeError: model diverged")]
    for exc, code, text in cases:
        seq, msg = decode_frame(core.error_frame(exc))
        assert seq == core.session.seq and msg.code == code and text in msg.text


@pytest.mark.parametrize(
    "url,message",
    [("http://127.0.0.1:1/runs/a/couple", "ws://, wss:// or tcp://"),
     ("tcp://127.0.0.1", "needs a port"), ("ws:///runs/a/couple", "no host")],
)
def test_bad_urls_are_refused_before_connecting(url, message):
    with pytest.raises(ValueError, match=message):
        parse_url(url)


def test_url_gives_the_run_id():
    assert parse_url("ws://h:8000/runs/r7/couple") == ("ws", "h", 8000, "r7")
    assert parse_url("tcp://h:8766") == ("tcp", "h", 8766, "")


def test_log_in_a_missing_directory_is_a_clear_error(tmp_path):
    with pytest.raises(ValueError, match="log_path .*cannot create it"):
        GaugeLog(tmp_path / "no" / "such" / "dir.csv", "header")
