"""Server settings: one class, read from the environment (prefix WAVESPH_) or the CLI."""

from __future__ import annotations

import ipaddress
import os
from pathlib import Path
from typing import Literal

from pydantic import BaseModel, Field, ValidationError, model_validator

ENV_PREFIX = "WAVESPH_"
_NULLABLE = ("tcp_port", "token", "tcp_host", "ws_ping_interval", "ws_ping_timeout")  # "" -> None


class Settings(BaseModel):
    host: str = Field("127.0.0.1", description="HTTP/WebSocket bind address")
    port: int = Field(8765, ge=0, le=65535, description="HTTP port (0: ephemeral)")
    tcp_host: str | None = Field(None, description="TCP coupling bind address (default: host)")
    tcp_port: int | None = Field(8766, ge=0, le=65535, description="TCP coupling port; None disables it")
    runs_dir: Path = Field(Path("runs"), description="one sub-directory per run")
    token: str | None = Field(None, min_length=16, description="API token (required off loopback)")
    max_runs: int = Field(2, ge=1, description="runs stepping at once (a coupled run from its "
                                               "client's HELLO on)")
    max_waiting: int = Field(4, ge=1, description="coupled runs built and waiting for their client "
                                                  "(each holds its particles in memory)")
    max_queued: int = Field(32, ge=0, description="runs of each kind (coupled, standalone) in "
                                                 "the queue; beyond: HTTP 429 (a resume is "
                                                 "never refused)")
    max_particles: int = Field(2_000_000, ge=1, description="particle-count cap per run")
    device: Literal["cpu", "cuda"] = Field("cpu", description="where a run's SPH steps run when "
                                           "its scene does not say ([run] device)")
    max_probes: int = Field(1000, ge=0, description="probes of one scene")
    max_body: int = Field(1024 * 1024, ge=1024, description="largest POST /runs body [bytes]")
    max_frame: int = Field(16 * 1024 * 1024, ge=4104, le=16 * 1024 * 1024,
                           description="largest coupling frame payload [bytes]")
    header_timeout: float = Field(10.0, gt=0, description="[s] for an HTTP request's line and "
                                  "headers, from the connection or the previous response")
    hello_timeout: float = Field(30.0, gt=0, description="[s] for the first frame after connect")
    idle_timeout: float = Field(600.0, gt=0, description="[s] between client frames")
    keepalive_every: float = Field(5.0, gt=0, description="[s] between WORKING frames while a "
                                   "reply takes long (clients with the KEEPALIVE capability)")
    ws_ping_interval: float | None = Field(20.0, gt=0, description="[s] between WebSocket pings the "
                                           "server sends (traffic that keeps proxies and NATs from "
                                           "closing a quiet coupling connection); None: no pings")
    ws_ping_timeout: float | None = Field(None, gt=0, description="[s] a WebSocket client whose pong "
                                          "is this late is dropped; None (default): never, see "
                                          "server/asgi.py (a dead client is found by idle_timeout)")
    client_wait_timeout: float = Field(300.0, gt=0, description="[s] a coupled run waits for its "
                                       "client, queued or built, from its POST (or resume); then "
                                       "it fails and its places are free")
    meta_interval: float = Field(0.5, ge=0, description="[s] least time between meta.json rewrites")
    checkpoint_every: float = Field(60.0, gt=0, description="[s] wall time between saved states of "
                                                            "a coupled run (for resuming it)")
    checkpoint_every_t: float = Field(1.0, gt=0, description="[s] simulated time between saved "
                                                             "states (whichever comes first)")

    @property
    def loopback_only(self) -> bool:
        return all(_is_loopback(h) for h in (self.host, self.tcp_host or self.host))

    @model_validator(mode="after")
    def _token_off_loopback(self) -> "Settings":
        if not self.loopback_only and not self.token:
            public = [f"{name} {h!r}" for name, h in (("host", self.host),
                                                     ("tcp_host", self.tcp_host or self.host))
                      if not _is_loopback(h)]
            raise ValueError("token: an API token (>= 16 characters) is required when binding "
                             f"{' and '.join(public)}, not a loopback address")
        return self

    @classmethod
    def from_env(cls, environ: dict[str, str] | None = None, **overrides: object) -> "Settings":
        """Settings from WAVESPH_* variables, then ``overrides`` (e.g. CLI options) on top."""
        env = os.environ if environ is None else environ
        values: dict[str, object] = {}
        for name in cls.model_fields:
            raw = env.get(ENV_PREFIX + name.upper())
            if raw is not None:
                values[name] = None if raw == "" and name in _NULLABLE else raw
        values.update({k: v for k, v in overrides.items() if v is not None})
        return cls(**values)


def _is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


__all__ = ["Settings", "ValidationError"]
