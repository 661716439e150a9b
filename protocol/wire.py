"""Wire constants: magic, version, header layout, message types, limits (PROTOCOL.md)."""

from __future__ import annotations

import struct
from enum import IntEnum

MAGIC = b"WSPH"
VERSION = 1
SUPPORTED_VERSIONS = frozenset({VERSION})

# magic[4], version u16, type u16, seq u32, payload length u32 -- all little-endian
HEADER = struct.Struct("<4sHHII")
HEADER_SIZE = HEADER.size  # 16

# Limits (PROTOCOL.md, "Limits"). A receiver may announce lower ones in WELCOME.
MAX_PAYLOAD = 16 * 1024 * 1024   # bytes of payload in one frame
MAX_TEXT = 4096                  # bytes of UTF-8 in one text field
MAX_COUNT = 1_000_000            # boundary nodes or gauges in one scene
SCENE_HASH_SIZE = 32             # SHA-256
NO_SCENE_HASH = bytes(SCENE_HASH_SIZE)  # all zeros: "do not check the scene"


class MessageType(IntEnum):
    """Numeric message types (u16 in the header)."""

    HELLO = 1
    WELCOME = 2
    GETNODES = 3
    NODES = 4
    SET = 5
    SOLVE = 6
    GET = 7
    RESULT = 8
    GOBACK = 9
    ERROR = 10
    BYE = 11
    GETGAUGES = 12   # 1.1, with the GAUGE_INFO capability
    GAUGES = 13      # 1.1, with the GAUGE_INFO capability
    WORKING = 14     # 1.1, with the KEEPALIVE capability


class Capability(IntEnum):
    """Bits of the u32 capability mask in HELLO/WELCOME. Unknown bits are ignored."""

    GOBACK = 1 << 0       # client may send GOBACK (implicit / iterated coupling)
    GAUGE_INFO = 1 << 1   # protocol 1.1: GETGAUGES -> GAUGES (names, kinds, the SPH-side eta gauges)
    KEEPALIVE = 1 << 2    # protocol 1.1: WORKING frames while a reply takes long (the JIT compile)
    ZONE_NODES = 1 << 3   # protocol 1.2: NODES also lists columns inside the SPH zone's relaxation zones


class Side(IntEnum):
    """Which open boundary a node belongs to (u32 in NODES)."""

    INLET = 0
    OUTLET = 1
    INLET_ZONE = 2    # 1.2 (ZONE_NODES): a column inside the inlet's relaxation zone
    OUTLET_ZONE = 3   # 1.2 (ZONE_NODES): a column inside the outlet's relaxation zone


class GaugeKind(IntEnum):
    """What a gauge is (u32 in GAUGES)."""

    BOUNDARY = 0   # an open end's own gauge (a few h inside its face)
    PROBE = 1      # an elevation probe of the scene


NO_GAUGE = 0xFFFFFFFF  # GAUGES.eta_gauge of an end that is not open, or does not absorb
