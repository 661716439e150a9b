"""The one exception the protocol package raises, with the numeric code sent in an ERROR frame."""

from __future__ import annotations

from enum import IntEnum


class ErrorCode(IntEnum):
    """Numeric error codes carried by ERROR frames (PROTOCOL.md, "Error codes")."""

    MALFORMED = 1            # bad magic, truncated frame, lengths that do not add up, bad UTF-8
    UNSUPPORTED_VERSION = 2  # header version is not one this peer speaks
    UNKNOWN_TYPE = 3         # message type value not in the table
    FRAME_TOO_LARGE = 4      # payload length above the stated limit
    BAD_VALUE = 5            # NaN/inf, value out of range, empty window, ...
    OUT_OF_ORDER = 6         # message not allowed in the current session state, or wrong seq
    SCENE_MISMATCH = 7       # HELLO scene hash differs from the run's scene
    SHAPE_MISMATCH = 8       # array length differs from the counts given in WELCOME
    TIME_MISMATCH = 9        # SET window does not start at the current SPH time
    TIMEOUT = 10             # peer silent for longer than the stated timeout
    ENGINE_FAILED = 11       # the SPH solve failed (unstable, NaN detected, ...)
    CANCELLED = 12           # the run was cancelled by its owner
    BUSY = 13                # run not accepting a coupling client (already coupled, finished, ...)
    INTERNAL = 14            # bug on the sending side
    NOT_FOUND = 15           # HELLO names a run the server does not know


class ProtocolError(Exception):
    """Anything wrong with bytes or message order. ``code`` is what goes on the wire; ``seq`` is
    the refused frame's own seq where its header could be read (None: the ERROR then carries
    the seq of the last frame accepted)."""

    def __init__(self, code: ErrorCode, text: str, seq: int | None = None) -> None:
        super().__init__(f"{code.name}: {text}")
        self.code = ErrorCode(code)
        self.text = text
        self.seq = seq
