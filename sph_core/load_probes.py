"""The engineer's probes: force and moment on a wall or structure, pressure along a wall, and
overtopping volume through a vertical section (scene kinds ``force``, ``pressure_line``,
``overtopping``; see their classes in sph_core.scene for the formulas and columns).

``LoadProbes`` is held by a Simulation: ``columns()`` names the CSV columns, ``values(...)``
measures them at the current state. Overtopping keeps, per particle id, the side of the section
the particle was on at the previous record, so the cumulative volume is the net volume
(m/rho) of the particles that crossed, whatever the particle order.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .particles import FLUID, M, RHO, WALL, X, Y, Z
from .probes import interpolate_points, wall_force
from .scene import ForceProbe, OvertoppingProbe, PressureLineProbe, Scene


class LoadProbes:
    """Force, pressure-line and overtopping probes of one scene."""

    def __init__(self, scene: Scene) -> None:
        self.dim = scene.dim
        self.forces = [p for p in scene.probes if isinstance(p, ForceProbe)]
        self.lines = [p for p in scene.probes if isinstance(p, PressureLineProbe)]
        self.overtopping = [p for p in scene.probes if isinstance(p, OvertoppingProbe)]
        pts = [xz for p in self.lines for xz in p.points]
        self._lx = np.array([xz[0] for xz in pts], dtype=float)
        self._lz = np.array([xz[1] for xz in pts], dtype=float)
        self._lx0, self._lz0 = self._lx.copy(), self._lz.copy()   # at t_start (follow)
        bounds = np.cumsum([0] + [len(p.points) for p in self.lines])
        self._follow = [(slice(a, b), p.follow) for a, b, p in zip(bounds[:-1], bounds[1:],
                                                                      self.lines) if p.follow]
        self._ly = np.array([p.y for p in self.lines for _ in p.points], dtype=float)
        self._lout = np.zeros((len(pts), 5))
        self._side: dict[str, np.ndarray] = {}       # id -> 1 if x >= section, 0 if not, -1 unknown
        self._volume = {p.name: 0.0 for p in self.overtopping}
        self._q = {p.name: 0.0 for p in self.overtopping}
        self._t_last: float | None = None

    def __bool__(self) -> bool:
        return bool(self.forces or self.lines or self.overtopping)

    def columns(self) -> list[str]:
        cols: list[str] = []
        for p in self.forces:
            cols += [f"{p.name}_fx", f"{p.name}_fz", f"{p.name}_my"]
            if self.dim == 3:
                cols += [f"{p.name}_fy", f"{p.name}_mx", f"{p.name}_mz"]
        for p in self.lines:
            cols += [f"{p.name}_p{k}" for k in range(len(p.points))]
        for p in self.overtopping:
            cols += [f"{p.name}_q", f"{p.name}_volume"]
        return cols

    def values(self, ps: Any, cells: Any, prm: Any, t: float,
               bodies: Any = None) -> dict[str, float | None]:
        """Every column at the current state of particle set ``ps`` (cell lists ``cells``,
        the run's Params ``prm``);
        ``bodies`` (a BodySet) places the pressure lines that follow a body."""
        out: dict[str, float | None] = {}
        for sl, name in self._follow:
            self._lx[sl], self._lz[sl] = bodies.follow(name, self._lx0[sl], self._lz0[sl])
        f, kind = ps.f, ps.kind
        n = ps.n
        x, y, z = f[X, :n], f[Y, :n], f[Z, :n]
        for p in self.forces:
            inside = (kind[:n] == WALL) & (x >= p.x0) & (x <= p.x1) & (z >= p.z0) & (z <= p.z1)
            if p.y0 is not None:
                inside &= (y >= p.y0) & (y <= p.y1)
            sel = np.nonzero(inside)[0]
            xm, ym, zm = p.axis()
            fx, fy, fz, mx, my, mz = wall_force(ps.view, cells, sel, xm, ym, zm, prm)
            out.update({f"{p.name}_fx": fx, f"{p.name}_fz": fz, f"{p.name}_my": my})
            if self.dim == 3:
                out.update({f"{p.name}_fy": fy, f"{p.name}_mx": mx, f"{p.name}_mz": mz})
        if self.lines:
            interpolate_points(ps.view, cells, self._lx, self._ly, self._lz, prm.h, prm.alpha_w,
                               self._lout)
            k = 0
            for p in self.lines:
                for j in range(len(p.points)):
                    wet = self._lout[k, 3] > 0.05
                    out[f"{p.name}_p{j}"] = float(self._lout[k, 2]) if wet else None
                    k += 1
        if self.overtopping:
            self._count_crossings(ps, t)
            for p in self.overtopping:
                out[f"{p.name}_q"] = self._q[p.name]
                out[f"{p.name}_volume"] = self._volume[p.name]
        return out

    def _count_crossings(self, ps: Any, t: float) -> None:
        n = ps.n
        fluid = ps.kind[:n] == FLUID
        ids = ps.ids[:n][fluid]
        x = ps.f[X, :n][fluid]
        vol = ps.f[M, :n][fluid] / ps.f[RHO, :n][fluid]
        size = int(ids.max()) + 1 if ids.size else 0
        dt = None if self._t_last is None else t - self._t_last
        for p in self.overtopping:
            side = self._side.get(p.name)
            if side is None or side.size < size:  # first record, or new (inflow) particles
                grown = np.full(max(size, 1), -1, dtype=np.int8)
                if side is not None:
                    grown[: side.size] = side
                side = self._side[p.name] = grown
            now = (x >= p.x).astype(np.int8)
            before = side[ids]
            known = before >= 0
            crossed = float(np.sum(vol[known] * (now[known] - before[known])))
            side[ids] = now
            self._volume[p.name] += crossed
            if dt is not None and dt > 0:
                self._q[p.name] = crossed / dt
        if dt is None or dt > 0:
            self._t_last = t

    def reset_sides(self) -> None:
        """Forget the particles' sides (after a restore): the next record starts counting anew
        from the restored positions; the cumulative volume is kept."""
        self._side.clear()
        self._t_last = None
