"""Bad bytes are refused with a typed ProtocolError: never another exception, never a hang."""

from __future__ import annotations

import struct

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from protocol import ErrorCode, FrameDecoder, ProtocolError, decode_frame, encode_frame
from protocol.messages import Bye, Hello, Nodes, Result, Set, Solve
from protocol.wire import HEADER, HEADER_SIZE, MAGIC, MAX_PAYLOAD, MessageType

from protocol_strategies import messages, u32


def _decode_or_refuse(data: bytes) -> None:
    try:
        decode_frame(data)
    except ProtocolError:
        pass


@given(st.binary(max_size=200))
def test_random_bytes_as_one_frame(data):
    _decode_or_refuse(data)


@given(st.binary(max_size=200))
def test_random_payload_behind_a_valid_header(payload):
    for mtype in MessageType:
        _decode_or_refuse(HEADER.pack(MAGIC, 1, mtype, 1, len(payload)) + payload)


@given(messages, u32, st.data())
def test_truncated_frame_is_refused(msg, seq, data):
    frame = encode_frame(msg, seq)
    cut = data.draw(st.integers(0, len(frame) - 1))
    with pytest.raises(ProtocolError) as exc:
        decode_frame(frame[:cut])
    assert exc.value.code is ErrorCode.MALFORMED


@given(messages, u32, st.data())
def test_truncated_payload_with_matching_length_is_refused(msg, seq, data):
    """A frame whose header agrees with a cut payload: the fields themselves must not fit."""
    payload = msg.serialize()
    if not payload:
        return
    cut = data.draw(st.integers(0, len(payload) - 1))
    with pytest.raises(ProtocolError):
        decode_frame(HEADER.pack(MAGIC, 1, msg.TYPE, seq, cut) + payload[:cut])


@given(messages, u32, st.data())
def test_mutated_frame_decodes_or_is_refused(msg, seq, data):
    frame = bytearray(encode_frame(msg, seq))
    for _ in range(data.draw(st.integers(1, 4))):
        i = data.draw(st.integers(0, len(frame) - 1))
        frame[i] = data.draw(st.integers(0, 255))
    _decode_or_refuse(bytes(frame))


@given(st.lists(st.binary(max_size=64), max_size=8))
def test_stream_of_random_chunks(chunks):
    decoder = FrameDecoder()
    try:
        for chunk in chunks:
            decoder.feed(chunk)
        decoder.eof()
    except ProtocolError:
        pass


@given(messages, st.data())
def test_stream_cut_short_is_reported_at_eof(msg, data):
    frame = encode_frame(msg, 1)
    cut = data.draw(st.integers(1, len(frame) - 1))
    decoder = FrameDecoder()
    assert decoder.feed(frame[:cut]) == []
    with pytest.raises(ProtocolError) as exc:
        decoder.eof()
    assert exc.value.code is ErrorCode.MALFORMED


def _code(data: bytes, max_payload: int = MAX_PAYLOAD) -> ErrorCode:
    with pytest.raises(ProtocolError) as exc:
        decode_frame(data, max_payload)
    return exc.value.code


def test_each_header_fault_has_its_code():
    good = encode_frame(Solve(), 1)
    assert _code(b"HTTP" + good[4:]) is ErrorCode.MALFORMED
    assert _code(good[:4] + struct.pack("<H", 2) + good[6:]) is ErrorCode.UNSUPPORTED_VERSION
    assert _code(good[:6] + struct.pack("<H", 99) + good[8:]) is ErrorCode.UNKNOWN_TYPE
    assert _code(HEADER.pack(MAGIC, 1, MessageType.SET, 1, 1000)) is ErrorCode.MALFORMED  # no payload
    assert _code(HEADER.pack(MAGIC, 1, MessageType.SET, 1, 1000), max_payload=999) is ErrorCode.FRAME_TOO_LARGE
    assert _code(good + b"\0") is ErrorCode.MALFORMED


def test_nan_and_infinity_are_refused_in_both_directions():
    nan_set = Set(0.0, 0.1, [0.0, np.nan], [0.0, 0.0], [0.0, 0.0])
    with pytest.raises(ProtocolError, match=r"SET.u\[1\]") as exc:
        nan_set.serialize()
    assert exc.value.code is ErrorCode.BAD_VALUE
    good = encode_frame(Set(0.0, 0.1, [0.0, 1.0], [0.0, 0.0], [0.0, 0.0]), 1)
    bad = good.replace(struct.pack("<d", 1.0), struct.pack("<d", float("inf")))
    with pytest.raises(ProtocolError, match=r"SET.u\[1\]") as exc:
        decode_frame(bad)
    assert exc.value.code is ErrorCode.BAD_VALUE
    t_nan = bytearray(good)
    t_nan[HEADER_SIZE:HEADER_SIZE + 8] = struct.pack("<d", float("nan"))
    with pytest.raises(ProtocolError, match="SET.t0"):
        decode_frame(bytes(t_nan))


def test_array_count_larger_than_payload_is_refused_before_allocation():
    # count claims 2**31 values inside a 16-byte payload: must fail on the count, not on memory
    payload = struct.pack("<ddI", 0.0, 0.1, 2**31)
    with pytest.raises(ProtocolError, match="SET.u") as exc:
        decode_frame(HEADER.pack(MAGIC, 1, MessageType.SET, 1, len(payload)) + payload)
    assert exc.value.code is ErrorCode.MALFORMED


def test_invalid_utf8_and_overlong_text():
    payload = struct.pack("<I", 2) + b"\xff\xfe"
    with pytest.raises(ProtocolError, match="BYE.reason"):
        decode_frame(HEADER.pack(MAGIC, 1, MessageType.BYE, 1, len(payload)) + payload)
    with pytest.raises(ProtocolError, match="BYE.reason") as exc:
        Bye("x" * 5000).serialize()
    assert exc.value.code is ErrorCode.BAD_VALUE


def test_stream_refuses_garbage_and_oversize_without_waiting_for_the_payload():
    with pytest.raises(ProtocolError, match="magic"):
        FrameDecoder().feed(b"GET / HTTP/1.1")
    with pytest.raises(ProtocolError, match="magic"):
        FrameDecoder().feed(b"WX")  # refused on the second byte, before a full header
    decoder = FrameDecoder(max_payload=100)
    with pytest.raises(ProtocolError) as exc:
        decoder.feed(HEADER.pack(MAGIC, 1, MessageType.SET, 1, 10**9))
    assert exc.value.code is ErrorCode.FRAME_TOO_LARGE
    assert decoder.buffered == HEADER_SIZE  # nothing of the announced gigabyte was awaited
    with pytest.raises(ProtocolError):      # and the decoder stays failed
        decoder.feed(encode_frame(Solve(), 2))


def test_sender_refuses_values_the_receiver_would_refuse():
    with pytest.raises(ProtocolError, match="HELLO.scene_hash"):
        Hello(0, b"short").serialize()
    with pytest.raises(ProtocolError, match="HELLO.capabilities"):
        Hello(-1).serialize()
    with pytest.raises(ProtocolError, match="RESULT.wet"):
        Result(0.0, 0, [0.0], [-1], [0.0], [0.0]).serialize()
    with pytest.raises(ProtocolError, match="NODES.x"):
        Nodes(np.zeros((2, 2)), [0.0], [0], []).serialize()
    with pytest.raises(ProtocolError, match="seq"):
        encode_frame(Solve(), 2**32)
