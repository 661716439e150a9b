"""The SPH-side session: which message may come when, and checks against the handshake."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from protocol import (Bye, Capability, ClientSession, Error, ErrorCode, Get, GetNodes, GoBack, Hello,
                      Nodes, ProtocolError, RemoteError, Result, Set, Solve, SphSession, Welcome,
                      decode_frame, scene_hash)
from protocol_strategies import messages
from protocol.session import Measure, PeerError, Reply, Restore, SetWindow, SolveWindow, State

HASH = scene_hash(b'{"scene": 1}')
N, G = 3, 2


def make_session(capabilities: int = Capability.GOBACK) -> SphSession:
    welcome = Welcome(capabilities, HASH, g=9.81, depth=0.5, still_water_level=0.5, z_ref=-0.25,
                      t_start=0.0, t_end=1.0, dt_sph=1e-4, window_max=0.1, idle_timeout=30.0,
                      n_nodes=N, n_gauges=G, max_payload=0, run_id="r1", server="test")
    nodes = Nodes(np.zeros(N), np.linspace(-0.5, 0, N), np.zeros(N, np.uint32), [1.0, 2.0])
    return SphSession(welcome, nodes)


def result(t: float = 0.0) -> Result:
    return Result(t, 7, np.full(G, 0.01), np.ones(G, np.uint32), np.zeros(G), np.zeros(G))


def window(t0: float, t1: float, n: int = N) -> Set:
    return Set(t0, t1, np.ones(n), np.zeros(n), np.zeros(n))


class Peer:
    """Client side talking to the session through real bytes."""

    def __init__(self, session: SphSession) -> None:
        self.s, self.c = session, ClientSession()

    def send(self, msg):
        return self.s.receive(*decode_frame(self.c.request(msg), self.s.max_payload))

    def expect(self, data: bytes, cls):
        return self.c.reply(*decode_frame(data), expect=cls)


def handshake(peer: Peer) -> Welcome:
    action = peer.send(Hello(Capability.GOBACK, HASH, "r1", "pytest"))
    return peer.expect(action.data, Welcome)


def test_a_full_coupled_run():
    s = make_session()
    peer = Peer(s)
    welcome = handshake(peer)
    assert welcome.capabilities == Capability.GOBACK and welcome.n_nodes == N
    nodes = peer.expect(peer.send(GetNodes()).data, Nodes)
    assert nodes.gauge_x.tolist() == [1.0, 2.0]
    t = 0.0
    for _ in range(3):
        action = peer.send(window(t, t + 0.1))
        assert isinstance(action, SetWindow) and action.u.tolist() == [1.0] * N
        action = peer.send(Solve())
        assert action == SolveWindow(t, t + 0.1)
        reply = peer.expect(s.result(action, result()), Result)
        t += 0.1
        assert reply.t == pytest.approx(t) and reply.steps == 7
    # iterate the last window: back to its start, then set it again
    action = peer.send(GoBack())
    assert isinstance(action, Restore) and action.t == pytest.approx(0.2)
    assert peer.expect(s.result(action, result()), Result).t == pytest.approx(0.2)
    with pytest.raises(ProtocolError, match="no solved window"):
        peer.send(GoBack())


def test_goback_only_once_and_then_set_at_window_start():
    s = make_session()
    peer = Peer(s)
    handshake(peer)
    peer.send(window(0.0, 0.1))
    s.result(peer.send(Solve()), result())
    s.result(peer.send(GoBack()), result())
    with pytest.raises(ProtocolError) as exc:
        peer.send(window(0.1, 0.2))  # the clock went back to 0
    assert exc.value.code is ErrorCode.TIME_MISMATCH


@pytest.mark.parametrize("first", [GetNodes(), Set(0.0, 0.1, [0.0] * N, [0.0] * N, [0.0] * N), Solve(),
                                   Get(), GoBack()])
def test_nothing_before_hello(first):
    with pytest.raises(ProtocolError, match="before HELLO") as exc:
        Peer(make_session()).send(first)
    assert exc.value.code is ErrorCode.OUT_OF_ORDER


@pytest.mark.parametrize("bad, code, text", [
    (lambda: Solve(), ErrorCode.OUT_OF_ORDER, "SOLVE without a SET"),
    (lambda: GoBack(), ErrorCode.OUT_OF_ORDER, "no solved window"),
    (lambda: Hello(0), ErrorCode.OUT_OF_ORDER, "HELLO"),
    (lambda: result(), ErrorCode.OUT_OF_ORDER, "server only"),
    (lambda: window(0.0, 0.1, n=N + 1), ErrorCode.SHAPE_MISMATCH, "SET.u has 4 values"),
    (lambda: window(0.5, 0.6), ErrorCode.TIME_MISMATCH, "t0=0.5"),
    (lambda: window(0.0, 0.0), ErrorCode.BAD_VALUE, "empty"),
    (lambda: window(0.0, 0.2), ErrorCode.BAD_VALUE, "window_max"),
])
def test_refusals_name_the_problem(bad, code, text):
    peer = Peer(make_session())
    handshake(peer)
    with pytest.raises(ProtocolError, match=text) as exc:
        peer.send(bad())
    assert exc.value.code is code


def test_set_after_t_end_is_refused():
    s = make_session()
    peer = Peer(s)
    handshake(peer)
    t = 0.0
    for _ in range(10):
        peer.send(window(t, t + 0.1))
        s.result(peer.send(Solve()), result())
        t += 0.1
    with pytest.raises(ProtocolError, match="t_end") as exc:
        peer.send(window(t, t + 0.05))
    assert exc.value.code is ErrorCode.BAD_VALUE


def test_scene_hash_and_run_id_checked_zero_hash_accepted():
    with pytest.raises(ProtocolError) as exc:
        Peer(make_session()).send(Hello(0, scene_hash(b"other"), "r1"))
    assert exc.value.code is ErrorCode.SCENE_MISMATCH
    with pytest.raises(ProtocolError) as exc:
        Peer(make_session()).send(Hello(0, HASH, "r2"))
    assert exc.value.code is ErrorCode.BAD_VALUE
    peer = Peer(make_session())
    assert isinstance(peer.send(Hello(0)), Reply)  # zero hash, no run id: accepted


def test_goback_needs_the_capability():
    s = make_session()
    peer = Peer(s)
    peer.expect(peer.send(Hello(0, HASH)).data, Welcome)
    peer.send(window(0.0, 0.1))
    s.result(peer.send(Solve()), result())
    with pytest.raises(ProtocolError, match="capability"):
        peer.send(GoBack())


def test_wrong_seq_is_refused():
    s = make_session()
    s.receive(1, Hello(0))
    with pytest.raises(ProtocolError, match="seq 3, expected 2") as exc:
        s.receive(3, GetNodes())
    assert exc.value.code is ErrorCode.OUT_OF_ORDER


def test_bye_error_and_closed_state():
    s = make_session()
    peer = Peer(s)
    handshake(peer)
    action = peer.send(Bye("done"))
    assert isinstance(action, Reply) and action.close
    assert isinstance(decode_frame(action.data)[1], Bye)
    with pytest.raises(ProtocolError, match="closed"):
        peer.send(Get())
    s2 = make_session()
    assert Peer(s2).send(Error(5, "model blew up")) == PeerError(5, "model blew up")
    assert s2.state is State.CLOSED


def test_error_frame_reaches_the_client_as_remote_error():
    s = make_session()
    peer = Peer(s)
    handshake(peer)
    try:
        peer.send(Solve())
    except ProtocolError as exc:
        frame = s.error_frame(exc)
    with pytest.raises(RemoteError, match="SOLVE without a SET") as exc:
        peer.expect(frame, Result)
    assert exc.value.code is ErrorCode.OUT_OF_ORDER


def test_max_payload_follows_the_handshake():
    s = make_session()
    assert s.max_payload == 4 + 32 + 2 * (4 + 4096)  # before HELLO: at most a HELLO
    welcome = decode_frame(s.receive(1, Hello(0)).data)[1]
    assert s.max_payload == welcome.max_payload == max(16 + 3 * (4 + 8 * N), 4104)
    n = 1000
    offer = Welcome(0, HASH, 9.81, 1.0, 1.0, -0.5, 0.0, 1.0, 1e-4, 0.1, 30.0, n, 0, 0)
    big = SphSession(offer, Nodes(np.zeros(n), np.zeros(n), np.zeros(n, np.uint32), []))
    welcome = decode_frame(big.receive(1, Hello(0)).data)[1]
    assert big.max_payload == welcome.max_payload == 16 + 3 * (4 + 8 * n)


def test_get_is_allowed_any_time_after_hello_and_does_not_move_the_clock():
    s = make_session()
    peer = Peer(s)
    handshake(peer)
    action = peer.send(Get())
    assert isinstance(action, Measure)
    assert peer.expect(s.result(action, result(t=99.0)), Result).t == 0.0


_windows = st.builds(window, st.sampled_from([0.0, 0.05, 0.1, 0.3]), st.sampled_from([0.05, 0.1, 0.2]))


@given(st.lists(st.tuples(st.one_of(st.none(), st.integers(0, 12)),
                          st.one_of(messages, _windows, st.sampled_from([Hello(1), Solve(), GoBack()]))),
                max_size=12))
def test_any_message_sequence_gives_actions_or_protocol_errors(seq_msgs):
    """Whatever a client sends, in any order with any seq (None: the right one), the session
    answers with an action or a ProtocolError -- never another exception -- and stays closed."""
    s = make_session()
    for i, (seq, msg) in enumerate(seq_msgs):
        seq = i + 1 if seq is None else seq
        try:
            action = s.receive(seq, msg)
        except ProtocolError:
            s.error_frame(ProtocolError(ErrorCode.OUT_OF_ORDER, "x"))
            assert s.state is State.CLOSED
            break
        if isinstance(action, (SolveWindow, Measure, Restore)):
            decode_frame(s.result(action, result()))
        elif isinstance(action, Reply):
            decode_frame(action.data)


def _refusal(s: SphSession, frame: bytes, max_payload: int | None = None) -> tuple[int, Error]:
    """The ERROR (seq, message) the SPH side sends for ``frame``, as a door does it: decoding
    and the session's check both refuse through ProtocolError."""
    try:
        s.receive(*decode_frame(frame, s.max_payload if max_payload is None else max_payload))
    except ProtocolError as exc:
        seq, msg = decode_frame(s.error_frame(exc))
        assert isinstance(msg, Error)
        return seq, msg
    raise AssertionError("the frame was accepted")


def _set_frame(seq: int, t0: float, t1: float, u0: float = 1.0) -> bytes:
    from protocol import encode_frame

    frame = bytearray(encode_frame(window(t0, t1), seq))
    if u0 != 1.0:  # patched in: the encoder itself refuses NaN
        import struct

        struct.pack_into("<d", frame, 16 + 16 + 4, u0)
    return bytes(frame)


@pytest.mark.parametrize("frame_of, code", [
    (lambda: _set_frame(3, 0.0, 0.05, u0=float("nan")), ErrorCode.BAD_VALUE),  # refused decoding
    (lambda: _set_frame(3, 0.01, 0.05), ErrorCode.TIME_MISMATCH),             # refused by the session
    (lambda: _set_frame(3, 0.0, 0.5), ErrorCode.BAD_VALUE),                   # window > window_max
    (lambda: _set_frame(9, 0.0, 0.05), ErrorCode.OUT_OF_ORDER),               # a wrong seq: its own
])
def test_an_error_refusing_a_frame_carries_that_frames_seq(frame_of, code):
    """PROTOCOL.md, section 3: the ERROR refusing a frame carries the seq of that frame (as sent,
    a wrong one included), whether the bytes or the session refused it."""
    s = make_session()
    peer = Peer(s)
    handshake(peer)
    peer.send(GetNodes())                      # seq 2 accepted
    frame = frame_of()
    seq, err = _refusal(s, frame)
    assert err.code == code, err.text
    assert seq == int.from_bytes(frame[8:12], "little")


def test_an_error_for_an_unreadable_header_carries_the_last_accepted_seq():
    s = make_session()
    handshake(Peer(s))
    try:
        decode_frame(b"XSPH" + bytes(12))
    except ProtocolError as exc:
        seq, err = decode_frame(s.error_frame(exc))
    assert err.code == ErrorCode.MALFORMED and seq == 1
