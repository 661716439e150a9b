"""Frames: a 16-byte header then the payload. Sans-I/O: bytes in, messages out.

A WebSocket binary message carries exactly one frame (``decode_frame``); a TCP stream carries
frames back to back and is cut by ``FrameDecoder.feed``. The header is checked (magic first,
as soon as its bytes arrive) before a single payload byte is buffered.
"""

from __future__ import annotations

from dataclasses import dataclass

from .errors import ErrorCode, ProtocolError
from .messages import MESSAGE_CLASSES, Message
from .wire import HEADER, HEADER_SIZE, MAGIC, MAX_PAYLOAD, SUPPORTED_VERSIONS, VERSION, MessageType


@dataclass(frozen=True)
class Header:
    version: int
    type: MessageType
    seq: int
    length: int


def encode_frame(message: Message, seq: int) -> bytes:
    """Header + payload of ``message`` with sequence number ``seq`` (u32)."""
    if not 0 <= seq <= 0xFFFFFFFF:
        raise ProtocolError(ErrorCode.BAD_VALUE, f"seq {seq} is not a u32")
    payload = message.serialize()
    if len(payload) > MAX_PAYLOAD:
        raise ProtocolError(ErrorCode.FRAME_TOO_LARGE,
                            f"{message.TYPE.name} payload {len(payload)} bytes > limit {MAX_PAYLOAD}")
    return HEADER.pack(MAGIC, VERSION, message.TYPE, seq, len(payload)) + payload


def _check_magic_prefix(data: bytes) -> None:
    head = bytes(data[:len(MAGIC)])
    if head != MAGIC[:len(head)]:
        raise ProtocolError(ErrorCode.MALFORMED, f"bad magic {head!r}, expected {MAGIC!r}")


def parse_header(data: bytes, max_payload: int = MAX_PAYLOAD) -> Header:
    """The header in the first 16 bytes of ``data``; checks magic, version, type and length."""
    if len(data) < HEADER_SIZE:
        raise ProtocolError(ErrorCode.MALFORMED, f"frame of {len(data)} bytes is shorter than the "
                                                 f"{HEADER_SIZE}-byte header")
    _check_magic_prefix(data)
    _, version, mtype, seq, length = HEADER.unpack_from(data)
    if version not in SUPPORTED_VERSIONS:
        raise ProtocolError(ErrorCode.UNSUPPORTED_VERSION,
                            f"protocol version {version}; this peer speaks {sorted(SUPPORTED_VERSIONS)}")
    try:
        mtype = MessageType(mtype)
    except ValueError:
        raise ProtocolError(ErrorCode.UNKNOWN_TYPE, f"message type {mtype} is not defined", seq) from None
    if length > max_payload:
        raise ProtocolError(ErrorCode.FRAME_TOO_LARGE,
                            f"{mtype.name} payload of {length} bytes > limit {max_payload}", seq)
    return Header(version, mtype, seq, length)


def _parse_payload(header: Header, payload: bytes) -> Message:
    """The message of a frame whose header was read; a refusal carries the frame's seq."""
    try:
        return MESSAGE_CLASSES[header.type].parse(payload)
    except ProtocolError as exc:
        exc.seq = header.seq
        raise


def decode_frame(data: bytes, max_payload: int = MAX_PAYLOAD) -> tuple[int, Message]:
    """(seq, message) from bytes holding exactly one frame (one WebSocket message)."""
    header = parse_header(data, max_payload)
    if len(data) != HEADER_SIZE + header.length:
        raise ProtocolError(ErrorCode.MALFORMED,
                            f"{header.type.name} header says {header.length} payload bytes, "
                            f"frame has {len(data) - HEADER_SIZE}", header.seq)
    return header.seq, _parse_payload(header, bytes(data[HEADER_SIZE:]))


class FrameDecoder:
    """Cuts a byte stream (TCP) into (seq, message) pairs.

    ``max_payload`` may be lowered at any time (the session lowers it to the largest message the
    client may send for its scene once the handshake is done). After an error the decoder stays
    failed: the connection must be closed.
    """

    def __init__(self, max_payload: int = MAX_PAYLOAD) -> None:
        self.max_payload = max_payload
        self._buf = bytearray()
        self._header: Header | None = None
        self._failed: ProtocolError | None = None

    @property
    def buffered(self) -> int:
        """Bytes received but not yet returned as a message (non-zero at EOF means truncation)."""
        return len(self._buf)

    def feed(self, data: bytes) -> list[tuple[int, Message]]:
        """Append received bytes; return every frame now complete, in order."""
        if self._failed:
            raise self._failed
        self._buf += data
        out: list[tuple[int, Message]] = []
        try:
            while True:
                if self._header is None:
                    if len(self._buf) < HEADER_SIZE:
                        _check_magic_prefix(self._buf)  # garbage is refused without waiting
                        break
                    self._header = parse_header(self._buf, self.max_payload)
                end = HEADER_SIZE + self._header.length
                if len(self._buf) < end:
                    break
                payload = bytes(self._buf[HEADER_SIZE:end])
                del self._buf[:end]
                header, self._header = self._header, None
                out.append((header.seq, _parse_payload(header, payload)))
        except ProtocolError as exc:
            self._failed = exc
            raise
        return out

    def eof(self) -> None:
        """The peer closed: raise if a frame was cut short."""
        if self._buf:
            raise ProtocolError(ErrorCode.MALFORMED, f"connection closed inside a frame "
                                                     f"({len(self._buf)} bytes buffered)")
