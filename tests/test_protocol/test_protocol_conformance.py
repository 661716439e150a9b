"""The conformance kit's scripted server (``python -m protocol.conformance --serve PORT [--ws]``)
checks a client over TCP or WebSocket, in three sessions (the run; a RESULT with a wrong seq; an
ERROR): our C example client and wave_client pass every check; a client that breaks the protocol
fails the check named for what it broke (and the kit exits 1)."""

from __future__ import annotations

import queue
import socket
import subprocess
import sys
import threading
from pathlib import Path
from typing import Callable

import numpy as np
import pytest

from protocol import (Bye, Error, ErrorCode, FrameDecoder, GetNodes, Hello, Set, Solve, Welcome,
                      encode_frame)
from protocol.conformance import (NAME_ERROR, NAME_NODES, NAME_WRONG_SEQ, Report, check_client, main,
                                  serve_scripted)

ROOT = Path(__file__).resolve().parents[2]


def test_the_c_client_passes_the_scripted_server(c_client):
    """Three runs of the C client: the scripted run, then a wrong-seq RESULT (it exits 4: the
    server broke the protocol) and an ERROR (it exits 3)."""
    kit = subprocess.Popen([sys.executable, "-m", "protocol.conformance", "--serve", "0",
                            "--t-end", "0.2"], cwd=ROOT, stdout=subprocess.PIPE, text=True)
    try:
        port = int(kit.stdout.readline().split()[-1])
        outs = [subprocess.run([str(c_client), "127.0.0.1", str(port), "conformance", "4",
                                "0.02", "1.0", "0.05"], capture_output=True, text=True, timeout=60)
                for _ in range(3)]
        lines = kit.stdout.read().splitlines()
        assert kit.wait(timeout=30) == 0, lines
    finally:
        kit.kill()
    assert [o.returncode for o in outs] == [0, 4, 3], [o.stderr for o in outs]
    assert lines[-1] == "ALL PASSED" and "PASS BYE at the end -- after 4 windows, t = 0.2 s" in lines
    assert "PASS a RESULT with a wrong seq is refused (ERROR or close, nothing more) -- the client closed" in lines
    assert ("PASS an ERROR from the server ends the session (the client sends nothing more) -- "
            "the client closed") in lines


def _scripted(run_client, fault: str | None = None) -> Report:
    """The scripted server on an ephemeral port, ``run_client(port)`` in a thread."""
    rep = Report(echo=False)
    with socket.create_server(("127.0.0.1", 0)) as srv:
        port = srv.getsockname()[1]
        th = threading.Thread(target=run_client, args=(port,), daemon=True)
        th.start()
        sock, _ = srv.accept()
        with sock:
            check_client(sock, rep, fault=fault)
        th.join(timeout=10)
    return rep


def _handshake(sock: socket.socket, dec: FrameDecoder) -> int:
    """HELLO, GETNODES; returns N."""
    sock.sendall(encode_frame(Hello(0, bytes(32), "x", "broken"), 1))
    welcome = dec.feed(sock.recv(1 << 16))[0][1]
    sock.sendall(encode_frame(GetNodes(), 2))
    dec.feed(sock.recv(1 << 16))
    return welcome.n_nodes


def _one_window_without_bye(solve_seq: int) -> Callable[[int], None]:
    """A client that couples one window, its SOLVE sent as frame ``solve_seq`` (4 in order), and
    leaves after the reply without BYE."""
    def client(port: int) -> None:
        with socket.create_connection(("127.0.0.1", port)) as sock:
            n = _handshake(sock, FrameDecoder())
            z = np.zeros(n)
            sock.sendall(encode_frame(Set(0.0, 0.05, z, z, z), 3) + encode_frame(Solve(), solve_seq))
            sock.recv(1 << 16)
    return client


def test_a_client_with_a_gap_in_its_seq_fails_the_seq_check():
    rep = _scripted(_one_window_without_bye(solve_seq=5))
    assert not rep.ok
    assert rep.failed()[0] == "message order and seq 1, 2, 3, ..."


def test_a_client_that_leaves_without_bye_fails_the_bye_check():
    rep = _scripted(_one_window_without_bye(solve_seq=4))
    assert rep.failed() == ["BYE at the end"]
    assert ("PASS", "at least one window solved", "1 windows") in rep.lines


def test_the_kit_exits_1_when_a_server_check_fails(capsys):
    # nothing listens on the port: the kit says which checks failed and exits 1 (never 0)
    with socket.create_server(("127.0.0.1", 0)) as s:
        port = s.getsockname()[1]
    assert main([f"tcp://127.0.0.1:{port}", "--run-id", "r", "--timeout", "2"]) == 1
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("FAIL malformed frame -> MALFORMED -- cannot connect")
    assert out[-1].startswith("FAILED: malformed frame -> MALFORMED, ")


def test_wave_client_waits_through_working_before_welcome_and_result():
    """wave_client asks for KEEPALIVE (1.1): the scripted server then sends WORKING before
    WELCOME and before the first RESULT, and the client must couple through them."""
    from wave_client.coupling import CouplingOptions, couple
    from wave_client.theories.linear import AiryWave

    def client(port: int) -> None:
        couple(f"tcp://127.0.0.1:{port}", AiryWave(height=0.02, period=1.0, depth=0.3),
               CouplingOptions(window=0.05), run_id="kit", timeout=30.0, progress=False)

    rep = _scripted(client)
    assert rep.ok, rep.lines
    assert ("PASS", "at least one window solved", "4 windows") in rep.lines


def test_a_client_that_asks_keepalive_but_rejects_early_working_fails():
    """A client that asked for KEEPALIVE and takes WORKING for the reply to HELLO breaks the
    session: the kit reports it."""
    def strict(port: int) -> None:
        with socket.create_connection(("127.0.0.1", port)) as sock:
            dec = FrameDecoder()
            sock.sendall(encode_frame(Hello(4, bytes(32), "x", "strict"), 1))
            seq, first = dec.feed(sock.recv(1 << 16))[0]
            if not isinstance(first, Welcome):  # a 1.1 client written before WORKING-before-WELCOME
                sock.sendall(encode_frame(Error(int(ErrorCode.OUT_OF_ORDER), "expected WELCOME"), 2))
            sock.settimeout(10)
            while sock.recv(1 << 16):  # until the kit closes: closing first races its sends
                pass

    rep = _scripted(strict)
    assert not rep.ok and "no ERROR from the client" in rep.failed()


@pytest.mark.parametrize("ws", [False, True])
def test_wave_client_passes_all_three_sessions_over_tcp_and_websocket(ws):
    """The scripted server over each transport: wave_client couples the run through its WORKING
    frames, refuses the wrong-seq RESULT with ERROR OUT_OF_ORDER, stops at the ERROR."""
    from wave_client.coupling import CouplingOptions, couple
    from wave_client.coupling.runner import CouplingError
    from wave_client.theories.linear import AiryWave

    ports: queue.Queue = queue.Queue()
    rep = Report(echo=False)
    kit = threading.Thread(target=serve_scripted, kwargs=dict(port=0, ws=ws, report=rep,
                                                              listening=ports.put), daemon=True)
    kit.start()
    port = ports.get(timeout=30)
    url = f"ws://127.0.0.1:{port}/runs/kit/couple" if ws else f"tcp://127.0.0.1:{port}"
    raised = []
    for _ in range(3):
        try:
            couple(url, AiryWave(height=0.02, period=1.0, depth=0.3), CouplingOptions(window=0.05),
                   run_id="kit", timeout=30.0, progress=False)
        except CouplingError as exc:  # the faults of sessions 2 and 3
            raised.append(type(exc).__name__)
    kit.join(timeout=60)
    assert not kit.is_alive() and rep.ok, rep.lines
    assert raised == ["CouplingError", "ServerError"]
    by_name = {n: (v, d) for v, n, d in rep.lines}
    assert by_name[NAME_WRONG_SEQ] == ("PASS", "it sent ERROR OUT_OF_ORDER seq=6: reply seq 4, "
                                               "request was 5")
    assert by_name[NAME_ERROR] == ("PASS", "the client closed")
    assert ("PASS", "at least one window solved", "4 windows") in rep.lines


def _trusting_client() -> Callable[[int], None]:
    """A client that checks neither seq nor type of its replies: one window, then the next
    window's SET, as if the reply were good."""
    def client(port: int) -> None:
        with socket.create_connection(("127.0.0.1", port)) as sock:
            dec = FrameDecoder()
            n = _handshake(sock, dec)
            z = np.zeros(n)
            sock.sendall(encode_frame(Set(0.0, 0.05, z, z, z), 3) + encode_frame(Solve(), 4))
            sock.settimeout(10)
            while not [f for f in dec.feed(sock.recv(1 << 16)) if f[1].TYPE.name in ("RESULT", "ERROR")]:
                pass
            sock.sendall(encode_frame(Set(0.05, 0.1, z, z, z), 5))
            try:
                while sock.recv(1 << 16):  # until the kit closes
                    pass
            except OSError:
                pass
    return client


@pytest.mark.parametrize("fault, name", [("wrong_seq", NAME_WRONG_SEQ), ("error", NAME_ERROR)])
def test_a_client_that_goes_on_after_a_faulty_reply_fails_the_fault_check(fault, name):
    rep = _scripted(_trusting_client(), fault=fault)
    assert rep.failed() == [name]
    [(detail,)] = [(d,) for v, n, d in rep.lines if n == name]
    assert detail.startswith("it went on: SET seq=5"), detail


def test_a_client_that_skips_getnodes_gets_a_note_not_a_failure():
    """Section 6 does not require GETNODES: a client that knows its nodes may skip it."""
    def client(port: int) -> None:
        with socket.create_connection(("127.0.0.1", port)) as sock:
            dec = FrameDecoder()
            sock.sendall(encode_frame(Hello(0, bytes(32), "x", "no-nodes"), 1))
            n = dec.feed(sock.recv(1 << 16))[0][1].n_nodes
            z = np.zeros(n)
            sock.sendall(encode_frame(Set(0.0, 0.05, z, z, z), 2) + encode_frame(Solve(), 3))
            dec.feed(sock.recv(1 << 16))
            sock.sendall(encode_frame(Bye(""), 4))
            sock.recv(1 << 16)

    rep = _scripted(client)
    assert rep.ok, rep.lines
    assert ("NOTE", NAME_NODES, "SET before GETNODES: the nodes were not asked for") in rep.lines
