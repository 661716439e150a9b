"""Protocol 1.2: the ZONE_NODES capability, NODES with the columns inside the relaxation zones;
older clients served as before."""

from __future__ import annotations

import numpy as np
import pytest

from protocol import (Capability, ErrorCode, GetNodes, Hello, Nodes, ProtocolError, Set, Side,
                      SphSession, Welcome, decode_frame)
from protocol.session import Reply, SetWindow, set_payload_size

WELCOME = Welcome(int(Capability.GOBACK), bytes(32), g=9.81, depth=0.3, still_water_level=0.3,
                  z_ref=-0.15, t_start=0.0, t_end=1.0, dt_sph=1e-4, window_max=0.05,
                  idle_timeout=10.0, n_nodes=4, n_gauges=1, max_payload=0, run_id="r1")
Z = np.array([-0.3, 0.0])
NODES = Nodes(np.array([0.0, 0.0, 1.2, 1.2]), np.tile(Z, 2),
              np.array([0, 0, 1, 1], np.uint32), np.array([0.6]))
# two columns in each zone: x 0.1, 0.2 (inlet) and 1.1, 1.0 (outlet), the face's z levels
ZONE = Nodes(np.concatenate([NODES.x, np.repeat([0.1, 0.2, 1.1, 1.0], 2)]), np.tile(Z, 6),
             np.concatenate([NODES.side, np.repeat(np.array([2, 2, 3, 3], np.uint32), 2)]),
             NODES.gauge_x)


def _hello(session: SphSession, caps: int) -> Welcome:
    action = session.receive(1, Hello(caps, bytes(32), "r1", "test"))
    assert isinstance(action, Reply)
    return decode_frame(action.data)[1]


def _nodes(session: SphSession) -> Nodes:
    return decode_frame(session.receive(2, GetNodes()).data)[1]


def test_a_1_2_client_gets_the_zones_columns_and_sends_them():
    session = SphSession(WELCOME, NODES, zone_nodes=ZONE)
    welcome = _hello(session, Capability.GOBACK | Capability.ZONE_NODES)
    assert welcome.capabilities == Capability.GOBACK | Capability.ZONE_NODES
    assert welcome.n_nodes == 12 and welcome.max_payload >= set_payload_size(12)
    nodes = _nodes(session)
    assert nodes.side.tolist() == ZONE.side.tolist() and np.array_equal(nodes.x, ZONE.x)
    assert {int(Side.INLET_ZONE), int(Side.OUTLET_ZONE)} <= set(nodes.side.tolist())
    action = session.receive(3, Set(0.0, 0.05, np.ones(12), np.zeros(12), np.zeros(12)))
    assert isinstance(action, SetWindow) and action.u.size == 12


def test_an_older_client_is_served_the_face_nodes_and_cannot_send_the_zones():
    session = SphSession(WELCOME, NODES, zone_nodes=ZONE)
    welcome = _hello(session, Capability.GOBACK)   # a 1.0/1.1 client never sets the bit
    assert welcome.capabilities == Capability.GOBACK and welcome.n_nodes == 4
    assert _nodes(session).side.tolist() == [0, 0, 1, 1]
    with pytest.raises(ProtocolError) as exc:
        session.receive(3, Set(0.0, 0.05, np.ones(12), np.zeros(12), np.zeros(12)))
    assert exc.value.code is ErrorCode.SHAPE_MISMATCH


def test_a_run_without_zones_does_not_grant_the_bit():
    welcome = _hello(SphSession(WELCOME, NODES), Capability.GOBACK | Capability.ZONE_NODES)
    assert welcome.capabilities == Capability.GOBACK and welcome.n_nodes == 4


def test_zone_nodes_must_extend_the_face_nodes():
    bad = Nodes(ZONE.x[::-1].copy(), ZONE.z, ZONE.side, ZONE.gauge_x)
    with pytest.raises(ValueError, match="zone_nodes"):
        SphSession(WELCOME, NODES, zone_nodes=bad)
