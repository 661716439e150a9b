"""The conformance kit's scripted server (``python -m protocol.conformance --serve PORT``) checks
a client: our C example client passes every check; a client that breaks the protocol fails the
check named for what it broke (and the kit exits 1)."""

from __future__ import annotations

import socket
import subprocess
import sys
import threading
from pathlib import Path
from typing import Callable

import numpy as np

from protocol import Error, ErrorCode, FrameDecoder, GetNodes, Hello, Set, Solve, Welcome, encode_frame
from protocol.conformance import Report, main, check_client

ROOT = Path(__file__).resolve().parents[2]


def test_the_c_client_passes_the_scripted_server(c_client):
    kit = subprocess.Popen([sys.executable, "-m", "protocol.conformance", "--serve", "0",
                            "--t-end", "0.2"], cwd=ROOT, stdout=subprocess.PIPE, text=True)
    try:
        port = int(kit.stdout.readline().split()[-1])
        out = subprocess.run([str(c_client), "127.0.0.1", str(port), "conformance", "4",
                              "0.02", "1.0", "0.05"], capture_output=True, text=True, timeout=60)
        lines = kit.stdout.read().splitlines()
        assert kit.wait(timeout=30) == 0, lines
    finally:
        kit.kill()
    assert out.returncode == 0, out.stderr
    assert lines[-1] == "ALL PASSED" and "PASS BYE at the end -- after 4 windows, t = 0.2 s" in lines


def _scripted(run_client) -> Report:
    """The scripted server on an ephemeral port, ``run_client(port)`` in a thread."""
    rep = Report(echo=False)
    with socket.create_server(("127.0.0.1", 0)) as srv:
        port = srv.getsockname()[1]
        th = threading.Thread(target=run_client, args=(port,), daemon=True)
        th.start()
        sock, _ = srv.accept()
        with sock:
            check_client(sock, rep)
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
