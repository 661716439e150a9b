"""A Simulation checkpoint as a portable ``.npz`` file: numpy arrays plus a JSON tree, no pickle.

Loading never runs code from the file (``numpy.load(allow_pickle=False)``); the tree may name only
the dataclasses in ``_CLASSES``. Anything numpy can read (any language with an npz reader) can
inspect the arrays: member ``tree`` is UTF-8 JSON, member ``aK`` the array the tree calls ``{"array": K}``.
"""

from __future__ import annotations

import dataclasses
import io
import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from .boundary_data import BoundarySample
from .open_ends import OpenState
from .particles import Checkpoint

FORMAT = "wavesph-checkpoint/1"
_CLASSES: dict[str, type] = {c.__name__: c for c in (Checkpoint, OpenState, BoundarySample)}


def _encode(obj: Any, arrays: list[np.ndarray]) -> Any:
    if obj is None or isinstance(obj, (bool, int, float, str)):
        return obj
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        if obj.dtype == object:
            raise TypeError("checkpoint: object arrays cannot be stored without pickle")
        arrays.append(obj)
        return {"array": len(arrays) - 1}
    if dataclasses.is_dataclass(obj) and type(obj).__name__ in _CLASSES:
        return {"class": type(obj).__name__,
                "fields": {f.name: _encode(getattr(obj, f.name), arrays) for f in dataclasses.fields(obj)}}
    if isinstance(obj, dict) and all(isinstance(k, str) for k in obj):
        return {"dict": {k: _encode(v, arrays) for k, v in obj.items()}}
    if isinstance(obj, (list, tuple)):
        return {type(obj).__name__: [_encode(v, arrays) for v in obj]}
    raise TypeError(f"checkpoint: cannot store a {type(obj).__name__}")


def _decode(node: Any, arrays: dict[str, np.ndarray]) -> Any:
    if not isinstance(node, dict):
        return node
    if "array" in node:
        return arrays[f"a{node['array']}"]
    if "class" in node:
        cls = _CLASSES.get(node["class"])
        if cls is None:
            raise ValueError(f"checkpoint: unknown class {node['class']!r}")
        return cls(**{k: _decode(v, arrays) for k, v in node["fields"].items()})
    if "dict" in node:
        return {k: _decode(v, arrays) for k, v in node["dict"].items()}
    if "tuple" in node:
        return tuple(_decode(v, arrays) for v in node["tuple"])
    if "list" in node:
        return [_decode(v, arrays) for v in node["list"]]
    raise ValueError(f"checkpoint: malformed node {sorted(node)}")


def save_checkpoint(path: str | Path, checkpoint: Checkpoint) -> None:
    """Write ``checkpoint`` to ``path`` atomically (a temporary file, fsync, rename)."""
    arrays: list[np.ndarray] = []
    tree = json.dumps({"format": FORMAT, "state": _encode(checkpoint, arrays)})
    buf = io.BytesIO()
    np.savez(buf, tree=np.frombuffer(tree.encode(), dtype=np.uint8),
             **{f"a{k}": a for k, a in enumerate(arrays)})
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    try:
        with open(tmp, "wb") as f:
            f.write(buf.getvalue())
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:  # a full disk: no half-written .tmp left behind
        tmp.unlink(missing_ok=True)
        raise


def load_checkpoint(path: str | Path) -> Checkpoint:
    """Read a file written by ``save_checkpoint``; ValueError if it is not one."""
    with np.load(path, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    try:
        doc = json.loads(arrays.pop("tree").tobytes().decode())
    except (KeyError, ValueError) as exc:
        raise ValueError(f"{path}: not a wavesph checkpoint ({exc})") from None
    if doc.get("format") != FORMAT:
        raise ValueError(f"{path}: checkpoint format {doc.get('format')!r}, expected {FORMAT!r}")
    state = _decode(doc["state"], arrays)
    if not isinstance(state, Checkpoint):
        raise ValueError(f"{path}: the file holds no Checkpoint")
    return state
