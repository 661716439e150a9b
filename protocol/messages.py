"""Message dataclasses: ``serialize()`` gives the payload bytes, ``parse(payload)`` the message.

Payload field order and types are those of PROTOCOL.md, section "Messages". Scalars are
little-endian u32 or float64; an array is a u32 count followed by count little-endian items;
text is a u32 byte length followed by UTF-8. No NaN or infinity anywhere. Both directions
check the same rules, so a sender cannot produce what a receiver would reject.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass, field, fields
from typing import Callable, ClassVar

import numpy as np

from .errors import ErrorCode, ProtocolError
from .wire import MAX_COUNT, MAX_TEXT, NO_SCENE_HASH, SCENE_HASH_SIZE, MessageType

_U32 = struct.Struct("<I")
_LE_F64 = np.dtype("<f8")
_F64 = struct.Struct("<d")
_U32_MAX = 0xFFFFFFFF


def _bad(code: ErrorCode, where: str, text: str) -> ProtocolError:
    return ProtocolError(code, f"{where}: {text}")


class _Reader:
    """Reads payload fields in order; every read checks the bytes left before touching them."""

    def __init__(self, payload: bytes, what: str) -> None:
        self.buf = memoryview(payload)
        self.pos = 0
        self.what = what

    def _take(self, n: int, name: str) -> memoryview:
        left = len(self.buf) - self.pos
        if n > left:
            raise _bad(ErrorCode.MALFORMED, f"{self.what}.{name}",
                       f"needs {n} bytes, payload has {left} left")
        view = self.buf[self.pos:self.pos + n]
        self.pos += n
        return view

    # the reads below unpack in place (unpack_from, frombuffer at an offset) and build a field's
    # name only to refuse it: a SET's decoding was a tenth of a null window's server time

    def u32(self, name: str) -> int:
        pos = self.pos
        if pos + 4 > len(self.buf):
            self._take(4, name)  # raises, naming the field
        self.pos = pos + 4
        return _U32.unpack_from(self.buf, pos)[0]

    def f64(self, name: str) -> float:
        pos = self.pos
        if pos + 8 > len(self.buf):
            self._take(8, name)  # raises, naming the field
        self.pos = pos + 8
        value = _F64.unpack_from(self.buf, pos)[0]
        if not math.isfinite(value):
            raise _bad(ErrorCode.BAD_VALUE, f"{self.what}.{name}", f"{value} is not finite")
        return value

    def text(self, name: str) -> str:
        n = self.u32(f"{name}.length")
        if n > MAX_TEXT:
            raise _bad(ErrorCode.BAD_VALUE, f"{self.what}.{name}",
                       f"{n} bytes of text, limit {MAX_TEXT}")
        try:
            return bytes(self._take(n, name)).decode("utf-8")
        except UnicodeDecodeError as exc:
            raise _bad(ErrorCode.MALFORMED, f"{self.what}.{name}", f"not UTF-8 ({exc.reason})") from None

    def hash(self, name: str) -> bytes:
        return bytes(self._take(SCENE_HASH_SIZE, name))

    def _count(self, name: str, item: int) -> int:
        if self.pos + 4 > len(self.buf):
            self._take(4, f"{name}.count")  # raises, naming the field
        n = _U32.unpack_from(self.buf, self.pos)[0]
        self.pos += 4
        left = len(self.buf) - self.pos
        # checked before any allocation: the count must fit in the bytes actually received
        if n > MAX_COUNT or n * item > left:
            raise _bad(ErrorCode.MALFORMED, f"{self.what}.{name}",
                       f"count {n} x {item} bytes does not fit the {left} bytes left (limit {MAX_COUNT})")
        return n

    def f64_array(self, name: str) -> np.ndarray:
        n = self._count(name, 8)  # the count fits the bytes left
        arr = np.frombuffer(self.buf, dtype=_LE_F64, count=n, offset=self.pos).astype(np.float64)
        self.pos += 8 * n
        if not np.isfinite(arr).all():
            i = int(np.flatnonzero(~np.isfinite(arr))[0])
            raise _bad(ErrorCode.BAD_VALUE, f"{self.what}.{name}[{i}]", f"{arr[i]} is not finite")
        return arr

    def u32_array(self, name: str) -> np.ndarray:
        n = self._count(name, 4)
        return np.frombuffer(self._take(4 * n, name), dtype="<u4").astype(np.uint32)

    def text_array(self, name: str) -> list[str]:
        n = self._count(name, 4)  # every text takes its 4-byte length at least
        return [self.text(f"{name}[{i}]") for i in range(n)]

    def end(self) -> None:
        left = len(self.buf) - self.pos
        if left:
            raise _bad(ErrorCode.MALFORMED, self.what, f"{left} bytes after the last field")


class _Writer:
    """Writes payload fields, refusing what a reader would refuse."""

    def __init__(self, what: str) -> None:
        self.parts: list[bytes] = []
        self.what = what

    def u32(self, name: str, value: int) -> None:
        if not (isinstance(value, (int, np.integer)) and 0 <= value <= _U32_MAX):
            raise _bad(ErrorCode.BAD_VALUE, f"{self.what}.{name}", f"{value!r} is not a u32")
        self.parts.append(_U32.pack(int(value)))

    def f64(self, name: str, value: float) -> None:
        value = float(value)
        if not math.isfinite(value):
            raise _bad(ErrorCode.BAD_VALUE, f"{self.what}.{name}", f"{value} is not finite")
        self.parts.append(_F64.pack(value))

    def text(self, name: str, value: str) -> None:
        data = value.encode("utf-8")
        if len(data) > MAX_TEXT:
            raise _bad(ErrorCode.BAD_VALUE, f"{self.what}.{name}",
                       f"{len(data)} bytes of text, limit {MAX_TEXT}")
        self.parts += [_U32.pack(len(data)), data]

    def hash(self, name: str, value: bytes) -> None:
        if len(value) != SCENE_HASH_SIZE:
            raise _bad(ErrorCode.BAD_VALUE, f"{self.what}.{name}",
                       f"{len(value)} bytes, expected {SCENE_HASH_SIZE}")
        self.parts.append(bytes(value))

    def _array(self, name: str, value: np.ndarray, dtype: str) -> None:
        arr = np.asarray(value)
        if arr.ndim != 1 or arr.size > MAX_COUNT:
            raise _bad(ErrorCode.BAD_VALUE, f"{self.what}.{name}",
                       f"shape {arr.shape}: expected one dimension of at most {MAX_COUNT}")
        self.parts += [_U32.pack(arr.size), np.ascontiguousarray(arr, dtype=dtype).tobytes()]

    def f64_array(self, name: str, value: np.ndarray) -> None:
        arr = np.asarray(value, dtype=np.float64)
        if not np.isfinite(arr).all():
            i = int(np.flatnonzero(~np.isfinite(arr.ravel()))[0])
            raise _bad(ErrorCode.BAD_VALUE, f"{self.what}.{name}[{i}]", "not finite")
        self._array(name, arr, "<f8")

    def u32_array(self, name: str, value: np.ndarray) -> None:
        arr = np.asarray(value)
        if arr.size and arr.dtype != np.uint32 and (arr.dtype.kind not in "iu" or arr.min() < 0
                                                    or arr.max() > _U32_MAX):
            raise _bad(ErrorCode.BAD_VALUE, f"{self.what}.{name}", "values are not u32")
        self._array(name, arr, "<u4")

    def text_array(self, name: str, value: list[str]) -> None:
        if len(value) > MAX_COUNT:
            raise _bad(ErrorCode.BAD_VALUE, f"{self.what}.{name}", f"{len(value)} texts > {MAX_COUNT}")
        self.parts.append(_U32.pack(len(value)))
        for i, text in enumerate(value):
            self.text(f"{name}[{i}]", text)

    def bytes(self) -> bytes:
        return b"".join(self.parts)


# Field codecs, in wire order: (attribute, kind). Kinds: u32, f64, text, hash, f64[], u32[],
# text[] (1.1: a u32 count, then that many texts).
_READ = {"u32": _Reader.u32, "f64": _Reader.f64, "text": _Reader.text, "hash": _Reader.hash,
         "f64[]": _Reader.f64_array, "u32[]": _Reader.u32_array, "text[]": _Reader.text_array}
_WRITE = {"u32": _Writer.u32, "f64": _Writer.f64, "text": _Writer.text, "hash": _Writer.hash,
          "f64[]": _Writer.f64_array, "u32[]": _Writer.u32_array, "text[]": _Writer.text_array}


class Message:
    """Base of all messages. Subclasses declare TYPE and LAYOUT (wire order of their fields)."""

    TYPE: ClassVar[MessageType]
    LAYOUT: ClassVar[tuple[tuple[str, str], ...]] = ()
    _ARRAYS: ClassVar[tuple[tuple[str, Callable[[object], object]], ...]] = ()

    def __init_subclass__(cls, **kw: object) -> None:
        super().__init_subclass__(**kw)
        # the array fields, once per class: __post_init__ runs for every frame (a fifth of a
        # null window's server time went to walking LAYOUT)
        cls._ARRAYS = tuple((name, _COERCE[kind]) for name, kind in cls.LAYOUT if kind in _COERCE)

    def __post_init__(self) -> None:
        # array fields hold what the wire gives back (float64, uint32, list), so a message
        # compares equal to its own round trip; LAYOUT says which fields are arrays
        for name, coerce in self._ARRAYS:
            setattr(self, name, coerce(getattr(self, name)))

    def serialize(self) -> bytes:
        """The payload bytes (without the frame header)."""
        w = _Writer(self.TYPE.name)
        for name, kind in self.LAYOUT:
            _WRITE[kind](w, name, getattr(self, name))
        return w.bytes()

    @classmethod
    def parse(cls, payload: bytes) -> "Message":
        """The message from its payload bytes; ProtocolError on anything malformed."""
        r = _Reader(payload, cls.TYPE.name)
        values = {name: _READ[kind](r, name) for name, kind in cls.LAYOUT}
        r.end()
        return cls(**values)

    def __eq__(self, other: object) -> bool:  # arrays compare by value
        if type(other) is not type(self):
            return NotImplemented
        return all(np.array_equal(getattr(self, f.name), getattr(other, f.name))
                   for f in fields(self))  # type: ignore[arg-type]

    __hash__ = None  # type: ignore[assignment]


def _f64s(a: object) -> np.ndarray:
    if type(a) is np.ndarray and a.dtype == np.float64:  # as the wire gives it
        return a
    return np.asarray(a, dtype=np.float64)


def _u32s(a: object) -> np.ndarray:
    arr = np.asarray(a)
    if arr.dtype == np.uint32:  # as the wire gives it: nothing to check
        return arr
    if arr.size == 0:
        return np.zeros(0, np.uint32)
    if arr.dtype.kind in "iu" and arr.min() >= 0 and arr.max() <= _U32_MAX:
        return arr.astype(np.uint32)
    return arr  # left as given: serialize() names the field it refuses


_COERCE = {"f64[]": _f64s, "u32[]": _u32s, "text[]": list}


@dataclass(eq=False)
class Hello(Message):
    """Client -> server, first frame. ``scene_hash`` all zeros means "do not check";
    ``run_id`` selects the run on the TCP port (on WebSocket it is empty or equals the URL's)."""

    TYPE = MessageType.HELLO
    LAYOUT = (("capabilities", "u32"), ("scene_hash", "hash"), ("run_id", "text"), ("client", "text"))
    capabilities: int
    scene_hash: bytes = NO_SCENE_HASH
    run_id: str = ""
    client: str = ""


@dataclass(eq=False)
class Welcome(Message):
    """Server -> client: accepted capabilities and the scene summary every later length is checked against."""

    TYPE = MessageType.WELCOME
    LAYOUT = (("capabilities", "u32"), ("scene_hash", "hash"),
              ("g", "f64"), ("depth", "f64"), ("still_water_level", "f64"), ("z_ref", "f64"),
              ("t_start", "f64"), ("t_end", "f64"), ("dt_sph", "f64"), ("window_max", "f64"),
              ("idle_timeout", "f64"), ("n_nodes", "u32"), ("n_gauges", "u32"),
              ("max_payload", "u32"), ("run_id", "text"), ("server", "text"))
    capabilities: int
    scene_hash: bytes
    g: float                  # gravity [m/s^2]
    depth: float              # still-water depth at the inlet [m]
    still_water_level: float  # absolute z of the still-water level in the SPH frame [m]
    z_ref: float              # reference depth of RESULT velocities, up from still water [m] (<= 0)
    t_start: float            # SPH time when the first window starts [s]
    t_end: float              # last time a window may end [s]
    dt_sph: float             # nominal SPH time step [s] (informative: the solver adapts it)
    window_max: float         # longest coupling window accepted [s]
    idle_timeout: float       # the server closes after this long without a frame [s]
    n_nodes: int              # boundary nodes: length of every node array
    n_gauges: int             # gauges: length of every gauge array
    max_payload: int          # largest frame payload the server accepts [bytes]
    run_id: str = ""
    server: str = ""


@dataclass(eq=False)
class GetNodes(Message):
    """Client -> server: ask for the boundary nodes and gauge positions."""

    TYPE = MessageType.GETNODES


@dataclass(eq=False)
class Nodes(Message):
    """Server -> client: boundary node positions (x absolute, z up from still water), sides, gauge x."""

    TYPE = MessageType.NODES
    LAYOUT = (("x", "f64[]"), ("z", "f64[]"), ("side", "u32[]"), ("gauge_x", "f64[]"))
    x: np.ndarray = field(default_factory=lambda: np.zeros(0))
    z: np.ndarray = field(default_factory=lambda: np.zeros(0))
    side: np.ndarray = field(default_factory=lambda: np.zeros(0, np.uint32))
    gauge_x: np.ndarray = field(default_factory=lambda: np.zeros(0))


@dataclass(eq=False)
class Set(Message):
    """Client -> server: boundary values at the window end t1; the window is [t0, t1]."""

    TYPE = MessageType.SET
    LAYOUT = (("t0", "f64"), ("t1", "f64"), ("u", "f64[]"), ("w", "f64[]"), ("eta", "f64[]"))
    t0: float
    t1: float
    u: np.ndarray    # horizontal velocity at each node at t1 [m/s]
    w: np.ndarray    # vertical velocity at each node at t1 [m/s]
    eta: np.ndarray  # wave-model elevation above still water at each node's x, at t1 [m]


@dataclass(eq=False)
class Solve(Message):
    """Client -> server: advance SPH over the window given by the last SET."""

    TYPE = MessageType.SOLVE


@dataclass(eq=False)
class Get(Message):
    """Client -> server: ask for the current measurements without advancing."""

    TYPE = MessageType.GET


@dataclass(eq=False)
class Result(Message):
    """Server -> client: measurements at the gauges at SPH time t (reply to SOLVE, GET, GOBACK)."""

    TYPE = MessageType.RESULT
    LAYOUT = (("t", "f64"), ("steps", "u32"), ("eta", "f64[]"), ("wet", "u32[]"),
              ("u_ref", "f64[]"), ("w_ref", "f64[]"))
    t: float           # SPH time of the measurement [s]
    steps: int         # SPH sub-steps taken in the window just solved (0 for GET/GOBACK)
    eta: np.ndarray    # elevation above still water at each gauge [m] (0 where dry)
    wet: np.ndarray    # 1 where the gauge found water, 0 where dry
    u_ref: np.ndarray  # horizontal velocity at z_ref at each gauge [m/s] (0 where dry)
    w_ref: np.ndarray  # vertical velocity at z_ref at each gauge [m/s] (0 where dry)


@dataclass(eq=False)
class GoBack(Message):
    """Client -> server: return to the state at the start of the last solved window."""

    TYPE = MessageType.GOBACK


@dataclass(eq=False)
class Error(Message):
    """Either direction: what went wrong; the sender closes the connection after it."""

    TYPE = MessageType.ERROR
    LAYOUT = (("code", "u32"), ("text", "text"))
    code: int
    text: str = ""


@dataclass(eq=False)
class Bye(Message):
    """Either direction: orderly end. The server answers a client BYE with BYE, then closes."""

    TYPE = MessageType.BYE
    LAYOUT = (("reason", "text"),)
    reason: str = ""


@dataclass(eq=False)
class GetGauges(Message):
    """Client -> server (1.1, GAUGE_INFO in force): ask what each gauge is."""

    TYPE = MessageType.GETGAUGES


@dataclass(eq=False)
class Gauges(Message):
    """Server -> client (1.1): per gauge, in RESULT order, its name and kind (GaugeKind); per
    side (Side order: inlet, outlet), the gauge whose elevation the SPH side's own absorber at
    that end measures, NO_GAUGE if the end is not open or does not absorb."""

    TYPE = MessageType.GAUGES
    LAYOUT = (("names", "text[]"), ("kind", "u32[]"), ("eta_gauge", "u32[]"))
    names: list[str] = field(default_factory=list)
    kind: np.ndarray = field(default_factory=lambda: np.zeros(0, np.uint32))
    eta_gauge: np.ndarray = field(default_factory=lambda: np.zeros(0, np.uint32))


@dataclass(eq=False)
class Working(Message):
    """Server -> client (1.1, KEEPALIVE in force): the reply to the request with this frame's seq
    is still being computed, ``elapsed`` seconds so far. Not a reply: the client keeps waiting."""

    TYPE = MessageType.WORKING
    LAYOUT = (("elapsed", "f64"),)
    elapsed: float = 0.0


MESSAGE_CLASSES: dict[MessageType, type[Message]] = {
    cls.TYPE: cls for cls in (Hello, Welcome, GetNodes, Nodes, Set, Solve, Get, Result, GoBack, Error,
                              Bye, GetGauges, Gauges, Working)
}
