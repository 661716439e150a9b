"""Create a run on a wavesph server from a scene file (`wavesph submit`, `wavesph couple --scene`).

The scene file is sent as it is (POST /runs, Content-Type application/toml): the server reads
its `mode`, `[coupling]` and `[source]` tables beside the scene, so the file is the one record of
the run. Overrides (a mode, a source) are merged into the file's tables first. The wave side
needs no SPH code for this: TOML in, the server's JSON run record out.
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

DEFAULT_SERVER = "http://127.0.0.1:8765"


class SubmitError(ValueError):
    """The server refused the run (the message is the server's, one line) or is unreachable."""


def http_base(url: str) -> str:
    """http://HOST:PORT of a server address given as http(s)://..., ws(s)://... or HOST:PORT."""
    if "://" not in url:
        url = "http://" + url
    parts = urlsplit(url)
    scheme = {"ws": "http", "wss": "https"}.get(parts.scheme, parts.scheme)
    if scheme not in ("http", "https") or not parts.netloc:
        raise ValueError(f"--url {url}: give the server as http://HOST:PORT")
    return f"{scheme}://{parts.netloc}"


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def scene_file_body(path: str | Path, mode: str | None = None,
                    source: dict[str, Any] | None = None) -> bytes:
    """The file's bytes, with ``mode`` and a ``[source]`` table replacing the file's own (the
    file is checked to be TOML here, so a typo is reported before any request)."""
    try:
        text = Path(path).read_text()
    except OSError as exc:
        raise ValueError(f"scene file {path}: {exc.strerror}") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{path}: not valid TOML ({exc})") from None
    if mode is None and source is None:
        return text.encode()
    if source is not None and "source" in data:
        raise ValueError(f"{path} has a [source] table: drop it or --source")
    if mode is not None and "mode" in data:
        raise ValueError(f"{path} sets mode = {data['mode']!r}: drop it or the option")
    # top-level keys must come before the first table: put `mode` first, `[source]` last
    head = f"mode = {_toml_value(mode)}\n" if mode is not None else ""
    tail = ("\n[source]\n" + "".join(f"{k} = {_toml_value(v)}\n" for k, v in source.items())
            if source else "")
    return (head + text + tail).encode()


# what a coupling client replaces in a scene file: the run is coupled, and the client's model
# drives the open ends instead of a built-in [source]
CLIENT_REPLACES = ("mode", "source")


def coupled_run_body(path: str | Path) -> tuple[bytes, list[str]]:
    """The file as a coupled run's JSON body (POST /runs) for a client that brings its own wave
    model (`wavesph couple --scene`), and the names of CLIENT_REPLACES the file had: the same
    file that `wavesph submit` runs with its [source] couples as it is."""
    import json

    try:
        data = tomllib.loads(Path(path).read_text())
    except OSError as exc:
        raise ValueError(f"scene file {path}: {exc.strerror}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{path}: not valid TOML ({exc})") from None
    dropped = [k for k in CLIENT_REPLACES if k in data]
    body: dict[str, Any] = {"scene": {k: v for k, v in data.items()
                                      if k not in (*CLIENT_REPLACES, "coupling")},
                            "mode": "coupled"}
    if "coupling" in data:
        body["coupling"] = data["coupling"]
    return json.dumps(body).encode(), dropped


def submit_scene_file(server: str, path: str | Path, *, mode: str | None = None,
                      source: dict[str, Any] | None = None, token: str | None = None,
                      timeout: float = 30.0, body: bytes | None = None) -> dict[str, Any]:
    """POST the scene file to ``server``; the created run's record (id, state, ...). ``body``:
    a JSON body made from the file already (``coupled_run_body``), sent instead of the file."""
    import httpx

    headers = {"Content-Type": "application/json" if body is not None else "application/toml"}
    if body is None:
        body = scene_file_body(path, mode, source)
    if token:
        headers["Authorization"] = f"Bearer {token}"
    base = http_base(server)
    try:
        r = httpx.post(f"{base}/runs", content=body, headers=headers, timeout=timeout)
    except httpx.HTTPError as exc:
        raise SubmitError(f"cannot reach the server at {base} ({exc}); is `wavesph serve` running?") from None
    if r.status_code != 201:
        raise SubmitError(f"the server refused the run (HTTP {r.status_code}): {_detail(r)}")
    return r.json()


def _detail(r: Any) -> str:
    try:
        detail = r.json().get("detail")
    except ValueError:
        return r.text[:300]
    if isinstance(detail, list):
        return "; ".join(f"{'.'.join(str(p) for p in e.get('loc', [])[1:])}: {e.get('msg')}"
                         for e in detail)
    return str(detail)
