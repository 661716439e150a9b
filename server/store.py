"""Run store on disk: one directory per run, written as the run goes, rebuilt on restart.

    <runs_dir>/<run_id>/
        request.json   the POST /runs body as validated (scene, mode, coupling options)
        scene.json     the canonical scene bytes (the protocol's scene hash is their SHA-256)
        meta.json      RunInfo: status, progress, speed, stability, last gauges (atomic rewrite)
        gauges.csv     coupled runs: one row per solved window, flushed at once
        state.npz      coupled runs: the engine state at a window boundary (to resume the run;
                       sph_core.checkpoint_file: numpy arrays + a JSON tree, no pickle)
        state.npz.sha256  its seal: a state that does not match it is not resumed
        sph/           standalone runs: sph_core's own outputs (probes.csv, meta.json, snapshots/)
"""

from __future__ import annotations

import csv
import fcntl
import hashlib
import json
import logging
import os
import re
import shutil
from pathlib import Path
from typing import IO, Any, Callable

from sph_core.output import format_time, write_json_atomic

from .schemas import RunInfo

META = "meta.json"
RUN_ID = re.compile(r"[A-Za-z0-9_-]{1,64}")  # a run's directory name: never a path

log = logging.getLogger("wavesph.server")


LOCK = ".lock"  # held (flock) by the one server that uses the store


class StoreLocked(RuntimeError):
    """Another server holds the run store: two would write the same runs' files."""


class RunStore:
    def __init__(self, root: Path) -> None:
        self.root = Path(root)
        self.root.mkdir(parents=True, exist_ok=True)
        self._lock = lock_store(self.root)

    def close(self) -> None:
        """Release the store's lock (the server stops)."""
        if self._lock is not None:
            self._lock.close()
            self._lock = None

    def run_dir(self, run_id: str) -> Path:
        """The run's directory, inside the store whatever the id says (ValueError if not a name)."""
        if not RUN_ID.fullmatch(run_id):
            raise ValueError(f"run id {run_id[:80]!r} is not a plain name ({RUN_ID.pattern})")
        return self.root / run_id

    def create(self, run_id: str, request: dict[str, Any], scene_bytes: bytes) -> Path:
        d = self.run_dir(run_id)
        d.mkdir()
        try:
            write_json_atomic(d / "request.json", request)
            (d / "scene.json").write_bytes(scene_bytes)
        except OSError:  # a full disk: no half-made run left to be found at the next start
            shutil.rmtree(d, ignore_errors=True)
            raise
        return d

    def save(self, info: RunInfo) -> None:
        write_json_atomic(self.run_dir(info.id) / META, info.model_dump(mode="json"))

    def load_all(self) -> list[tuple[RunInfo, dict[str, Any]]]:
        """Every run found on disk with its request. The directory's name is the run's id (a
        directory moved or copied keeps working); an entry that cannot be read is skipped with
        a log line, never stops the server."""
        out = []
        for d in sorted(self.root.iterdir()):
            if d.is_symlink():  # its records would be written outside the store
                log.warning("run store: skipping %s: a symbolic link, not a run directory", d)
                continue
            if d.name == LOCK:
                continue
            if not d.is_dir() or not RUN_ID.fullmatch(d.name):
                log.warning("run store: skipping %s: not a run directory", d)
                continue
            try:
                info = RunInfo.model_validate_json((d / META).read_text())
                request = json.loads((d / "request.json").read_text())
            except (OSError, ValueError) as exc:
                log.warning("run store: skipping %s: %s", d, str(exc).splitlines()[0][:200])
                continue
            if info.id != d.name:
                log.warning("run store: %s names run %r; the run is %r, its directory's name",
                            d / META, info.id[:80], d.name)
                info = info.model_copy(update={"id": d.name})
            out.append((info, request))
        return out


def lock_store(root: Path) -> IO[str]:
    """An exclusive lock on ``root``'s lock file, held while the returned file is open; it
    names this process. StoreLocked (naming the holder) if another server holds it. The OS
    releases it when the process ends, even on kill -9."""
    f = open(root / LOCK, "a+")
    try:
        fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        f.seek(0)
        holder = f.read().strip()[:40] or "unknown"
        f.close()
        raise StoreLocked(f"runs dir {root} is in use by another wavesph server (pid {holder}); "
                          f"give each server its own --runs-dir") from None
    f.seek(0)
    f.truncate()
    f.write(f"{os.getpid()}\n")
    f.flush()
    return f


def store_in_use(root: Path) -> str | None:
    """Why a server cannot use the store ``root`` now (another holds it), or None."""
    if not (Path(root) / LOCK).exists():
        return None
    try:
        lock_store(Path(root)).close()
    except StoreLocked as exc:
        return str(exc)
    return None


def _seal_path(path: Path) -> Path:
    return path.with_name(path.name + ".sha256")


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def save_sealed(save: Callable[[Path], None], path: Path) -> None:
    """``save(path)``, then its SHA-256 beside it: a state is trusted only if it matches (a crash
    between the two leaves a state without a valid seal, which is not resumed). ``save`` must
    replace ``path`` atomically: if it fails (a full disk), the state before and its seal stay."""
    save(path)
    write_text_atomic(_seal_path(path), _sha256(path) + "\n")


def write_text_atomic(path: Path, text: str) -> None:
    """``text`` to ``path`` through a temporary file, removed if the write fails."""
    tmp = path.with_name(path.name + ".tmp")
    try:
        tmp.write_text(text)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def fresh_path(folder: Path, stem: str, suffix: str = "") -> Path:
    """``stem+suffix`` in ``folder``, else the first free ``stem.1+suffix``, ``stem.2+suffix``, ...:
    each session of a resumed run writes its own, never over an earlier one's."""
    k, path = 0, folder / f"{stem}{suffix}"
    while path.exists():
        k += 1
        path = folder / f"{stem}.{k}{suffix}"
    return path


def has_seal(path: Path) -> bool:
    """``path`` and its seal exist (cheap; ``is_sealed`` reads the file)."""
    return path.exists() and _seal_path(path).exists()


def is_sealed(path: Path) -> bool:
    """``path`` matches its seal: not damaged, not cut short, not from another save."""
    try:
        return _seal_path(path).read_text().strip() == _sha256(path)
    except OSError:
        return False


class GaugeWriter:
    """gauges.csv of a coupled run: t, steps, then eta / u_ref / w_ref per gauge (empty if dry).

    Each row is flushed as written. ``mark()`` before a window and ``rewind()`` on GOBACK drop
    the rows of a window that is being redone, so the file always holds one row per window."""

    def __init__(self, path: Path, gauge_names: list[str], resume_at: float | None = None) -> None:
        self.columns = ["t", "steps"] + [f"{g}_{q}" for g in gauge_names for q in ("eta", "u_ref", "w_ref")]
        keep: list[list[str]] = []
        if resume_at is not None and path.exists():
            # a resumed run continues the file: rows after the resumed state are dropped
            with open(path, newline="") as f:
                rows = list(csv.reader(f))[1:]
            keep = [r for r in rows if r and float(r[0]) <= resume_at * (1 + 1e-12) + 1e-12]
            os.replace(path, path.with_name(path.name + ".before-resume"))
        self._f = open(path, "w", newline="")
        self._csv = csv.writer(self._f)
        self._csv.writerow(self.columns)
        self._csv.writerows(keep)
        self.rows_kept = len(keep)
        self._f.flush()
        self._mark = self._f.tell()

    def row(self, t: float, steps: int, values: dict[str, float | None]) -> None:
        self._csv.writerow([format_time(t), steps] +
                           ["" if values.get(c) is None else repr(float(values[c]))
                            for c in self.columns[2:]])
        self._f.flush()

    def mark(self) -> None:
        self._mark = self._f.tell()

    def rewind(self) -> None:
        self._f.seek(self._mark)
        self._f.truncate()
        self._f.flush()

    def close(self) -> None:
        self._f.close()


def read_gauge_rows(path: Path) -> tuple[list[str], list[dict[str, float | None]]]:
    """A gauge CSV as columns and rows; a dry gauge (empty, or 'dry' in older files) is None."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return [], []
    cols = rows[0]
    return cols, [{c: (None if v in ("", "dry") else float(v)) for c, v in zip(cols, r)}
                  for r in rows[1:] if r]
