"""Run directory: meta.json (config, versions, progress, status), probes.csv, VTK snapshots.

Everything is written as it comes: the CSV is flushed after each row, meta.json is replaced
atomically (write + rename), so a crash or an unstable stop leaves the last good outputs on disk.
"""

from __future__ import annotations

import csv
import json
import os
import platform
import sys
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np


def package_versions() -> dict[str, str]:
    out = {"python": sys.version.split()[0], "platform": platform.platform()}
    for name in ("wavesph", "numpy", "numba", "pydantic", "pyevtk"):
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = "not installed"
    return out


def format_time(t: float) -> str:
    """A time [s] for a CSV: 12 significant digits, so 0.027999999999999997 reads 0.028."""
    return f"{float(t):.12g}"


def load_gauges(path: str | Path) -> dict[str, np.ndarray]:
    """Any wavesph gauge CSV (a run's probes.csv, the server's gauges.csv, a coupling client's
    log, `wavesph waves` output) as {column: float array}: a dry gauge (an empty field) is NaN.
    Files of earlier versions are read too (``#`` lines skipped, the word ``dry`` is NaN).
    ``wavesph.read_gauges`` gives the same as a pandas DataFrame."""
    with open(path, newline="") as fh:
        rows = list(csv.reader(line for line in fh if line.strip() and not line.startswith("#")))
    if not rows:
        raise ValueError(f"{path}: no header row")
    header, body = rows[0], rows[1:]
    cols: dict[str, np.ndarray] = {}
    for k, name in enumerate(header):
        try:
            cols[name] = np.array([np.nan if r[k] in ("", "dry") else float(r[k]) for r in body])
        except ValueError as exc:
            raise ValueError(f"{path}: column {name!r}: {exc}") from None
    return cols


def write_json_atomic(path: Path, data: dict[str, Any]) -> None:
    tmp = path.with_suffix(path.suffix + ".tmp")
    try:
        tmp.write_text(json.dumps(data, indent=2, default=str))
        os.replace(tmp, path)
    except BaseException:  # a full disk: no half-written .tmp left behind
        tmp.unlink(missing_ok=True)
        raise


class RunWriter:
    """Writes one run's outputs into ``run_dir``."""

    def __init__(self, run_dir: str | Path, columns: list[str], config: dict[str, Any]) -> None:
        self.dir = Path(run_dir)
        self.dir.mkdir(parents=True, exist_ok=True)
        (self.dir / "snapshots").mkdir(exist_ok=True)
        self.meta: dict[str, Any] = {"config": config, "versions": package_versions(),
                                     "status": "created"}
        self.columns = ["t", "step"] + columns
        self._csv_file = open(self.dir / "probes.csv", "w", newline="")
        self._csv = csv.writer(self._csv_file)
        self._csv.writerow(self.columns)
        self._csv_file.flush()
        self.snapshots: list[tuple[float, str]] = []
        self.update_meta()

    def update_meta(self, **fields: Any) -> None:
        self.meta.update(fields)
        write_json_atomic(self.dir / "meta.json", self.meta)

    def probe_row(self, t: float, step: int, values: dict[str, float | None]) -> None:
        """One CSV row; a dry gauge is an empty field (NaN to pandas.read_csv), never a word in a
        numeric column. Times are printed short."""
        row: list[Any] = [format_time(t), step]
        for c in self.columns[2:]:
            v = values.get(c)
            row.append("" if v is None else repr(float(v)))
        self._csv.writerow(row)
        self._csv_file.flush()

    def snapshot(self, t: float, x: np.ndarray, z: np.ndarray, data: dict[str, Any],
                 y: np.ndarray | None = None) -> Path:
        """Particles as VTK unstructured points (.vtu) plus a ParaView collection (run.pvd);
        a tuple value of ``data`` is a vector field (x, y, z components); y None: the x-z plane."""
        from pyevtk.hl import pointsToVTK

        k = len(self.snapshots)
        stem = self.dir / "snapshots" / f"particles_{k:05d}"
        y = np.zeros_like(x) if y is None else y
        path = pointsToVTK(str(stem), np.ascontiguousarray(x), np.ascontiguousarray(y),
                           np.ascontiguousarray(z),
                           data={key: (tuple(np.ascontiguousarray(c) for c in v)
                                       if isinstance(v, tuple) else np.ascontiguousarray(v))
                                 for key, v in data.items()})
        self.snapshots.append((t, Path(path).name))
        entries = "\n".join(f'    <DataSet timestep="{format_time(tt)}" file="snapshots/{name}"/>'
                            for tt, name in self.snapshots)
        pvd = ('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n  <Collection>\n'
               f"{entries}\n  </Collection>\n</VTKFile>\n")
        tmp = self.dir / "run.pvd.tmp"
        tmp.write_text(pvd)
        os.replace(tmp, self.dir / "run.pvd")
        self._last_snapshot(t, x, z, data, y)
        return Path(path)

    def _last_snapshot(self, t: float, x: np.ndarray, z: np.ndarray, data: dict[str, Any],
                       y: np.ndarray) -> None:
        """snapshots/last.npz: the newest snapshot's positions, pressure, speed and kind in
        float32, for the run monitor's particle scatter (GET /runs/{id}/particles); replaced
        atomically, so a reader never sees half a file. (A 3D run's monitor shows the x-z slice
        of width 2h about a y: its y and h are stored too.)"""
        tmp = self.dir / "snapshots" / "last.npz.tmp"
        h = np.asarray(data.get("h", [0.0]))
        with open(tmp, "wb") as fh:
            np.savez(fh, t=np.float64(t), x=x.astype(np.float32), z=z.astype(np.float32),
                     y=y.astype(np.float32), h=np.float64(h[0] if h.size else 0.0),
                     pressure=np.asarray(data["pressure"], np.float32),
                     speed=np.asarray(data["speed"], np.float32),
                     kind=np.asarray(data["kind"], np.int8))
        os.replace(tmp, self.dir / "snapshots" / "last.npz")

    def close(self) -> None:
        if not self._csv_file.closed:
            self._csv_file.close()


def write_geometry_vtk(scene: Any, path: Path) -> Path:
    """The scene's outlines as VTK line cells (``path`` without suffix; returns the .vtu): the
    tank's inner faces, each bed's polyline, each structure's rectangle, each open end's face,
    one two-point cell per segment (a 3D scene: the edges of the tank's and structures' boxes,
    the beds' polylines on both side walls and across). Cell data ``part``: 0 tank, 1 bed,
    2 structure, 3 open end. (Poly-line cells, VTK type 4, opened in ParaView but not in
    meshio 5.)"""
    from pyevtk.hl import unstructuredGridToVTK
    from pyevtk.vtk import VtkLine

    t = scene.tank
    P = tuple[float, float, float]
    segments: list[tuple[P, P, int]] = []

    def poly(pts: list[tuple[float, float]], part: int, y: float = 0.0) -> None:
        segments.extend(((a[0], y, a[1]), (b[0], y, b[1]), part) for a, b in zip(pts[:-1], pts[1:]))

    def box(r: Any, part: int) -> None:
        for y in (r.y0, r.y1):
            poly([(r.x0, r.z0), (r.x1, r.z0), (r.x1, r.z1), (r.x0, r.z1), (r.x0, r.z0)], part, y)
        segments.extend(((x, r.y0, z), (x, r.y1, z), part) for x in (r.x0, r.x1) for z in (r.z0, r.z1))

    if scene.dim == 3:
        box(t, 0)
        for bed in scene.beds:
            for y in (t.y0, t.y1):
                poly([tuple(p) for p in bed.points], 1, y)
            segments.extend(((p[0], t.y0, p[1]), (p[0], t.y1, p[1]), 1) for p in bed.points)
        for s in scene.structures:
            box(s, 2)
    else:
        poly([(t.x0, t.z1), (t.x0, t.z0), (t.x1, t.z0), (t.x1, t.z1)], 0)
        for bed in scene.beds:
            poly([tuple(p) for p in bed.points], 1)
        for s in scene.structures:
            poly([(s.x0, s.z0), (s.x1, s.z0), (s.x1, s.z1), (s.x0, s.z1), (s.x0, s.z0)], 2)
    top = scene.still_water_level if scene.still_water_level is not None else t.z1
    for x in (t.x0 if o.side == "left" else t.x1 for o in scene.open_boundaries):
        poly([(x, t.z0), (x, top)], 3)
    pts = np.array([p for a, b, _ in segments for p in (a, b)], dtype=float)
    n = len(segments)   # pyevtk's linesToVTK writes NumberOfCells="5.0", which meshio refuses
    out = unstructuredGridToVTK(
        str(path), np.ascontiguousarray(pts[:, 0]), np.ascontiguousarray(pts[:, 1]),
        np.ascontiguousarray(pts[:, 2]), connectivity=np.arange(2 * n, dtype=np.int64),
        offsets=2 * np.arange(1, n + 1, dtype=np.int64),
        cell_types=np.full(n, VtkLine.tid, dtype=np.uint8),
        cellData={"part": np.array([k for _, _, k in segments], dtype=np.int32)})
    return Path(out)
