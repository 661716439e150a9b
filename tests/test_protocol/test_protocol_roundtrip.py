"""Every message survives serialize -> parse and encode -> decode, whole or cut into any chunks."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from protocol import FrameDecoder, decode_frame, encode_frame
from protocol.messages import MESSAGE_CLASSES

from protocol_strategies import messages, u32


@given(messages)
def test_payload_round_trip(msg):
    assert MESSAGE_CLASSES[msg.TYPE].parse(msg.serialize()) == msg


@given(messages, u32)
def test_frame_round_trip(msg, seq):
    assert decode_frame(encode_frame(msg, seq)) == (seq, msg)


@given(st.lists(messages, min_size=1, max_size=5), st.data())
def test_stream_round_trip_any_chunking(msgs, data):
    stream = b"".join(encode_frame(msg, i + 1) for i, msg in enumerate(msgs))
    cuts = sorted(data.draw(st.lists(st.integers(0, len(stream)), max_size=8)))
    decoder = FrameDecoder()
    got = []
    for a, b in zip([0, *cuts], [*cuts, len(stream)]):
        got += decoder.feed(stream[a:b])
    decoder.eof()
    assert got == [(i + 1, msg) for i, msg in enumerate(msgs)]
    assert decoder.buffered == 0
