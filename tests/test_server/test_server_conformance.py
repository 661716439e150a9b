"""The conformance kit (protocol.conformance) against our own server on loopback, both doors:
every check passes, and the runs end as the kit says (the first finished, the second failed by
the out-of-order SOLVE)."""

from __future__ import annotations

import pytest

from protocol.conformance import Report, check_server


@pytest.mark.parametrize("door", ["tcp", "ws"])
def test_the_kit_passes_against_our_server(srv, engines, door):
    run, spare = srv.create(t_end=1.0), srv.create(t_end=1.0)
    for r in (run, spare):
        srv.wait_state(r["id"], "waiting_for_client")
    url = (f"tcp://127.0.0.1:{srv.tcp_port}" if door == "tcp"
           else f"ws://127.0.0.1:{srv.port}/runs/{run['id']}/couple")
    rep = check_server(url, run["id"], spare["id"], windows=3, timeout=30.0,
                       report=Report(echo=False))
    assert rep.ok, rep.lines
    names = [n for v, n, _ in rep.lines if v == "PASS"]
    assert len(names) == 15 and not [n for v, n, _ in rep.lines if v == "SKIP"]
    assert srv.wait_state(run["id"], "finished")["windows"] == 3
    assert srv.wait_state(spare["id"], "failed")["status"].startswith("failed: protocol error")


def test_the_kit_checks_working_frames_of_a_slow_server(tmp_path, factory):
    """A server whose windows take longer than its keep-alive interval sends WORKING (1.1): the
    kit asked for KEEPALIVE, checks each frame's seq and elapsed, and still passes."""
    from server_harness import live_server

    with live_server(tmp_path, lambda r, d: factory(r, d, solve_delay=0.2), keepalive_every=0.05) as srv:
        run = srv.create(t_end=1.0)
        srv.wait_state(run["id"], "waiting_for_client")
        rep = check_server(f"tcp://127.0.0.1:{srv.tcp_port}", run["id"], windows=2, timeout=30.0,
                           report=Report(echo=False))
    assert rep.ok, rep.lines
    [(verdict, detail)] = [(v, d) for v, n, d in rep.lines if n.startswith("KEEPALIVE")]
    assert verdict == "PASS" and int(detail.split()[0]) >= 4, detail  # >= 2 per slow window
