"""Standalone runs of open-boundary scenes, driven by a built-in wave theory.

    POST /runs {"scene": {... open_boundaries ...}, "mode": "standalone",
                "source": {"theory": "stokes", "H": 0.04, "T": 1.4, "order": 2, "ramp_periods": 2}}

The theory is wave_client's, driven by wave_client's own coupling core (``CouplingCore``). Its
frames go through an in-memory transport (``TheoryClient``) to the same door logic
(``server.coupling.serve_client``) that a WebSocket or TCP client reaches. So the run takes the
coupled run's path exactly: the theory samples the boundary nodes window by window as the client
would, the engine solves the same windows, and gauges.csv, progress, saved states and resume are
those of a coupled run; only the socket is missing. A coupled run of the same scene with the same
theory and options gives the same gauges to round-off (tests/server/test_standalone_theory.py).
The theory's own elevation at the gauges is written beside them, to theory.csv.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from protocol import MAX_PAYLOAD, Bye, Error, Message, Nodes, Result, Welcome, decode_frame
from protocol.session import HELLO_LIMIT
from wave_client.coupling import CouplingCore, CouplingOptions, GaugeLog
from wave_client.theories import build_theory

if TYPE_CHECKING:
    from sph_core.scene import Scene

    from .runs import Run, RunManager

log = logging.getLogger("wavesph.server")

# options each theory takes beyond H, T (build_theory keyword names)
THEORY_OPTIONS: dict[str, tuple[str, ...]] = {
    "linear": (), "stokes": ("order",), "stream": ("n_fourier",),
    "irregular": ("gamma", "n_components", "seed"),
}
# first word of a build_theory error -> the body field it is about
_ERROR_FIELD = {"height": "H", "period": "T", "hs": "H", "tp": "T", "order": "order",
                "n_fourier": "n_fourier", "gamma": "gamma", "n_components": "n_components"}


class TheorySource(BaseModel):
    """A built-in wave source for a standalone run (``wave_client.theories``), SI units.

    Waves travel towards +x; the model's x origin is the SPH inlet face (x_model = x_SPH - x0)."""

    model_config = ConfigDict(extra="forbid")

    theory: Literal["linear", "stokes", "stream", "irregular"] = Field(
        description="linear (Airy), stokes (order 2-5), stream (Fenton stream function), "
                    "irregular (JONSWAP; H = Hs, T = Tp)")
    H: float = Field(gt=0, description="wave height [m] (Hs for irregular)")
    T: float = Field(gt=0, description="wave period [s] (Tp for irregular)")
    ramp_periods: float = Field(2.0, ge=0, description="start-up ramp length in periods")
    window: float | None = Field(None, gt=0, description="coupling window [s]; default "
                                                         "min(coupling.window_max, T/50)")
    order: int | None = Field(None, description="stokes: order 2-5 (default 5)")
    n_fourier: int | None = Field(None, description="stream: Fourier terms 2-64 (default 10)")
    gamma: float | None = Field(None, gt=0, description="irregular: JONSWAP peak enhancement")
    n_components: int | None = Field(None, gt=0, description="irregular: number of components")
    seed: int | None = Field(None, description="irregular: random phases seed")

    def options(self) -> dict[str, Any]:
        return {k: getattr(self, k) for k in THEORY_OPTIONS[self.theory] if getattr(self, k) is not None}

    def build(self, depth: float) -> Any:
        """The wave model at still-water depth ``depth`` [m] (ValueError names the parameter)."""
        return build_theory(self.theory, height=self.H, period=self.T, depth=depth,
                            ramp_time=self.ramp_periods * self.T, **self.options())


def source_errors(scene: "Scene", mode: str, source: TheorySource | None,
                  window_max: float = math.inf) -> list[tuple[list[str], str]]:
    """(location in the POST body, message) of what is wrong with ``source`` for this scene."""
    if source is None:
        if mode == "standalone" and scene.open_boundaries:
            return [(["source"], "a standalone run of a scene with open boundaries needs a wave "
                                 "source, e.g. {\"theory\": \"stokes\", \"H\": 0.04, \"T\": 1.4, "
                                 "\"order\": 2}; or use mode 'coupled' with a client")]
        return []
    if mode != "standalone" or not scene.open_boundaries:
        return [(["source"], "a wave source drives the open boundaries of a standalone run: "
                             "only for mode 'standalone' and a scene with open_boundaries")]
    errors = [(["source", name], f"the {source.theory} theory takes no {name} (it takes "
                       f"{list(THEORY_OPTIONS[source.theory]) or 'only H, T, ramp_periods, window'})")
              for name in ("order", "n_fourier", "gamma", "n_components", "seed")
              if getattr(source, name) is not None and name not in THEORY_OPTIONS[source.theory]]
    if source.window is not None and source.window > window_max:
        errors.append((["source", "window"], f"{source.window} s exceeds coupling.window_max = "
                                             f"{window_max} s"))
    if errors:
        return errors
    depth = float(scene.still_water_level) - scene.tank.z0
    try:
        source.build(depth)
    except ValueError as exc:
        word = str(exc).split("=")[0].split()[0].strip(":").lower()
        return [(["source", _ERROR_FIELD.get(word, "H")], f"{exc} (depth {depth:g} m at the inlet)")]
    return []


class TheoryClient:
    """A coupling client in this process: the door's Transport, with a CouplingCore behind it.

    ``send`` hands each server frame to the core at once and queues the core's answer, which
    ``recv`` returns; an empty queue means the client is done (closed). Frames are encoded and
    decoded as on a socket, so the door's checks (sequence, sizes, limits) all apply."""

    def __init__(self, core: CouplingCore, log_path: Path) -> None:
        self.core = core
        self.max_payload = HELLO_LIMIT
        self._out: list[tuple[int, Message]] = []
        self._log_path = log_path
        self._log: GaugeLog | None = None
        self._bye_sent = False

    def first(self) -> list[tuple[int, Message]]:
        return [decode_frame(self.core.hello(), self.max_payload)]

    async def recv(self) -> list[tuple[int, Message]] | None:
        out, self._out = self._out, []
        return out or None

    async def send(self, data: bytes) -> None:
        seq, msg = decode_frame(data, MAX_PAYLOAD)  # the server's own frames
        try:
            frames = self._answer(seq, msg)
        except Exception as exc:  # noqa: BLE001 -- the model failed: tell the door, as a client would
            log.warning("theory source failed: %s", exc)
            frames = [self.core.error_frame(exc)]
        self._out.extend(decode_frame(f, self.max_payload) for f in frames)

    def _answer(self, seq: int, msg: Message) -> list[bytes]:
        core = self.core
        if isinstance(msg, Welcome):
            return [core.on_welcome(seq, msg)]
        if isinstance(msg, Nodes):
            core.on_nodes(seq, msg)
            self._log = GaugeLog(self._log_path, "built-in theory source: gauges measured by SPH "
                                 "and the theory (eta_model_i)\nSI units; eta up from the "
                                 "still-water level; t is the SPH time")
            for line in core.describe():
                self._log.note(line)
            return core.next_window()
        if isinstance(msg, Result):
            record = core.on_result(seq, msg)
            if self._log is not None:
                self._log.write(record)
            if core.windows_left:
                return core.next_window()
            self._bye_sent = True
            return [core.bye()]
        if isinstance(msg, Bye):
            if self._bye_sent:  # the echo of our BYE; one out of turn just ends the session
                core.on_bye(seq, msg)
            return []
        if isinstance(msg, Error):  # the door ends the session and sets the run's state
            return []
        raise RuntimeError(f"theory source: unexpected {msg.TYPE.name} from the server")

    async def close(self) -> None:
        if self._log is not None:
            self._log.close()


def _log_path(run_dir: Path) -> Path:
    """theory.csv, then theory.1.csv ... for resumed sessions: never overwrite a run's data."""
    k, path = 0, run_dir / "theory.csv"
    while path.exists():
        k += 1
        path = run_dir / f"theory.{k}.csv"
    return path


async def serve_theory(manager: "RunManager", run: "Run") -> None:
    """Drive an attached run with its request's theory source until the session ends."""
    from .coupling import serve_client  # coupling imports runs, which imports us lazily

    source = run.request.source
    assert source is not None
    core = CouplingCore(lambda welcome: source.build(welcome.depth),
                        CouplingOptions(window=source.window), run_id=run.info.id,
                        scene_hash=bytes.fromhex(run.info.scene_hash),
                        client_name=f"wavesph built-in {source.theory} theory")
    client = TheoryClient(core, _log_path(run.dir))
    await serve_client(manager, run, client, client.first())
