"""Protocol 1.1: the GAUGE_INFO capability, GETGAUGES -> GAUGES; 1.0 clients served as before."""

from __future__ import annotations

import struct

import numpy as np
import pytest

from protocol import (NO_GAUGE, Capability, ClientSession, ErrorCode, GaugeKind, Gauges, GetGauges,
                      Hello, Nodes, ProtocolError, SphSession, Welcome, decode_frame, encode_frame)
from protocol.session import Reply

WELCOME = Welcome(int(Capability.GOBACK), bytes(32), g=9.81, depth=0.3, still_water_level=0.3,
                  z_ref=-0.15, t_start=0.0, t_end=1.0, dt_sph=1e-4, window_max=0.05,
                  idle_timeout=10.0, n_nodes=2, n_gauges=3, max_payload=0, run_id="r1")
NODES = Nodes(np.zeros(2), np.array([-0.3, 0.0]), np.zeros(2, np.uint32), np.array([0.08, 0.6, 1.1]))
GAUGES = Gauges(["left_boundary", "g1", "right_boundary"],
                [GaugeKind.BOUNDARY, GaugeKind.PROBE, GaugeKind.BOUNDARY], [0, 2])


def test_gauges_round_trip_with_unicode_names():
    g = Gauges(["inlet", "Pegel ü", ""], [0, 1, 1], [0, NO_GAUGE])
    seq, back = decode_frame(encode_frame(g, 7))
    assert seq == 7 and back == g and back.names == ["inlet", "Pegel ü", ""]


def test_gauges_with_a_count_beyond_the_payload_is_malformed():
    payload = struct.pack("<I", 1_000_000) + b"\0" * 8
    with pytest.raises(ProtocolError) as exc:
        Gauges.parse(payload)
    assert exc.value.code is ErrorCode.MALFORMED


def _hello(session: SphSession, caps: int) -> Welcome:
    action = session.receive(1, Hello(caps, bytes(32), "r1", "test"))
    assert isinstance(action, Reply)
    return decode_frame(action.data)[1]


def test_a_1_1_client_asks_for_the_gauges():
    session = SphSession(WELCOME, NODES, GAUGES)
    welcome = _hello(session, Capability.GOBACK | Capability.GAUGE_INFO)
    assert welcome.capabilities == Capability.GOBACK | Capability.GAUGE_INFO
    client = ClientSession()
    client.welcome = welcome
    client.seq = 2
    action = session.receive(2, GetGauges())
    got = client.reply(*decode_frame(action.data), expect=Gauges)
    assert got.names == GAUGES.names and got.eta_gauge.tolist() == [0, 2]


def test_a_1_0_client_is_served_as_before_and_cannot_ask():
    session = SphSession(WELCOME, NODES, GAUGES)
    welcome = _hello(session, Capability.GOBACK)  # a 1.0 client knows only GOBACK
    assert welcome.capabilities == Capability.GOBACK
    with pytest.raises(ProtocolError) as exc:
        session.receive(2, GetGauges())
    assert exc.value.code is ErrorCode.OUT_OF_ORDER and "GAUGE_INFO" in exc.value.text


def test_a_server_without_gauge_info_does_not_offer_it():
    welcome = _hello(SphSession(WELCOME, NODES), Capability.GOBACK | Capability.GAUGE_INFO)
    assert welcome.capabilities == Capability.GOBACK


def test_gauges_must_match_welcome():
    with pytest.raises(ValueError, match="gauges"):
        SphSession(WELCOME, NODES, Gauges(["a"], [0], [0, 0]))


def test_getnodes_and_getgauges_after_set_are_out_of_order():
    from protocol import GetNodes, Set

    for seq, msg in ((3, GetNodes()), (3, GetGauges())):
        s = SphSession(WELCOME, NODES, GAUGES)
        _hello(s, Capability.GOBACK | Capability.GAUGE_INFO)
        s.receive(2, Set(0.0, 0.05, np.zeros(2), np.zeros(2), np.zeros(2)))
        with pytest.raises(ProtocolError) as exc:
            s.receive(seq, msg)
        assert exc.value.code is ErrorCode.OUT_OF_ORDER and "after SET" in exc.value.text
