"""Particle positions of a 3D scene (``dim = 3``): the 2D layout's rules (geometry.py) on a box.

Fluid particles sit on the lattice (x0 + (i + 1/2) dp, y0 + (j + 1/2) dp, z0 + (k + 1/2) dp)
anchored at the tank's inner corner (x0, y0, z0). The tank's walls are ``n_layers`` (as in 2D:
ceil(2h/dp)) layers of dummy particles dp/2, 3dp/2, ... behind each face: the two x walls span the
whole y range including the y walls' layers and run down through the floor's layers (the
corners and edges), the two y walls span the tank's x range and run down likewise, the floor
spans the tank's inside. Inside spacings along the floor and the y walls are the tank's length
(width) over a whole number of spacings closest to dp (geometry.wall_dx's rule), so each row ends
one spacing from the walls across it whatever the tank's size. Beds are the 2D polylines
extruded across the width; structures are boxes, a shell of the walls' thickness on a lattice
of the box's own (spacings closest to dp that fit it whole, so its faces are where the scene
puts them), or vertical cylinders of concentric rings (``_cylinder_shell``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from .geometry import Layout, _along_slope, _polyline_distance, wall_layers
from .scene import Rect, Scene


def _even(a: float, b: float, dp: float) -> np.ndarray:
    """Centres of round((b - a) / dp) equal cells spanning [a, b]."""
    m = max(1, round((b - a) / dp))
    return a + (np.arange(m) + 0.5) * (b - a) / m


def _layers(a: float, b: float, dp: float, nl: int) -> tuple[np.ndarray, np.ndarray]:
    """The wall layers' centres behind a (below a) and beyond b."""
    k = np.arange(nl) + 0.5
    return a - k * dp, b + k * dp


def _grid(*axes: np.ndarray) -> tuple[np.ndarray, ...]:
    g = np.meshgrid(*axes, indexing="ij")
    return tuple(a.ravel() for a in g)


def _lattice3(scene: Scene, b: Rect) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lattice points strictly inside the box ``b`` (the fluid lattice anchored at the tank's
    inner corner)."""
    dp, t = scene.dp, scene.tank
    eps = 1e-9 * dp

    def axis(lo: float, hi: float, origin: float) -> np.ndarray:
        i0 = math.floor((lo - origin) / dp - 0.5) - 1
        i1 = math.ceil((hi - origin) / dp - 0.5) + 1
        c = origin + (np.arange(i0, i1 + 1) + 0.5) * dp
        return c[(c > lo + eps) & (c < hi - eps)]

    return _grid(axis(b.x0, b.x1, t.x0), axis(b.y0, b.y1, t.y0), axis(b.z0, b.z1, t.z0))


def _cylinder_shell(s: Rect, dp: float, nl: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A vertical cylinder's wall particles: ``nl`` rings at radii R - (k + 1/2) dp (the ring's
    circumference over a whole number of spacings closest to dp), stacked every ~dp from z0 to
    z1, and discs of the same rings inside them as the top and bottom caps."""
    xc, yc, r = 0.5 * (s.x0 + s.x1), 0.5 * (s.y0 + s.y1), 0.5 * (s.x1 - s.x0)
    zs = _even(s.z0, s.z1, dp)
    rings = [(r - (k + 0.5) * dp) for k in range(int(r / dp + 0.5))]
    out = []
    for k, rk in enumerate(rings):
        m = max(1, round(2 * np.pi * rk / dp))
        a = (np.arange(m) + 0.5 * (k % 2)) * 2 * np.pi / m
        # the outer nl rings over the whole height; the inner ones only within nl layers of the
        # top and the bottom (the caps)
        z = zs if k < nl else zs[(zs - s.z0 < nl * dp) | (s.z1 - zs < nl * dp)]
        gx, gz = np.meshgrid(xc + rk * np.cos(a), z, indexing="ij")
        gy, _ = np.meshgrid(yc + rk * np.sin(a), z, indexing="ij")
        out.append((gx.ravel(), gy.ravel(), gz.ravel()))
    return tuple(np.concatenate([o[i] for o in out]) for i in range(3))


def _unique(x: np.ndarray, y: np.ndarray, z: np.ndarray, dp: float) -> np.ndarray:
    """Indices of the first of each group of points closer than ~dp/4 (kept in order)."""
    key = np.round(np.stack([x, y, z]) / (0.25 * dp)).astype(np.int64)
    _, first = np.unique(key, axis=1, return_index=True)
    first.sort()
    return first


def build_layout_3d(scene: Scene, buffers: Mapping[str, int] | None = None) -> Layout:
    """Place fluid and wall particles for a 3D ``scene``; ``buffers`` as geometry.build_layout's
    (the extra columns span the y walls too: those beyond the tank's width stay walls, the
    buffer's sides)."""
    dp, t = scene.dp, scene.tank
    nl = wall_layers(scene)
    th = nl * dp
    xin = _even(t.x0, t.x1, dp)                      # inside rows along x (floor, y walls)
    yin = _even(t.y0, t.y1, dp)
    xlo, xhi = _layers(t.x0, t.x1, dp, nl)
    ylo, yhi = _layers(t.y0, t.y1, dp, nl)
    zfl, _ = _layers(t.z0, t.z1, dp, nl)              # floor layers
    zup = t.z0 + (np.arange(math.ceil((t.z1 - t.z0) / dp)) + 0.5) * dp
    zcol = np.concatenate([zfl[::-1], zup[zup <= t.z1]])   # walls run down through the floor
    yall = np.concatenate([ylo[::-1], yin, yhi])
    parts = [_grid(np.concatenate([xlo, xhi]), yall, zcol),     # x walls with the edges
             _grid(xin, np.concatenate([ylo, yhi]), zcol),       # y walls
             _grid(xin, yin, zfl)]                               # floor
    for side, nb in (buffers or {}).items():                     # wider open ends
        k = np.arange(nl, nb) + 0.5
        parts.append(_grid(t.x0 - k * dp if side == "left" else t.x1 + k * dp, yall, zcol))
    for bed in scene.beds:                                       # extruded across the width
        pts = np.asarray(bed.points)
        bx = _even(t.x0, t.x1, dp)
        bz = t.z0 + (np.arange(math.floor((pts[:, 1].min() - th - t.z0) / dp) - 1,
                               math.ceil((pts[:, 1].max() - t.z0) / dp) + 1) + 0.5) * dp
        gx, gz = _grid(bx, bz[(bz > t.z0) & (bz < t.z1)])
        d, below = _polyline_distance(bed, gx, gz)
        keep = below & (d < th)
        x2, z2 = gx[keep], gz[keep]
        if bed.layout == "along_slope":      # against the tank's x-z section: floor, x walls
            sx, sz = _grid(xin, zfl)
            cx, cz = _grid(np.concatenate([xlo, xhi]), zcol)
            x2, z2 = _along_slope(bed, dp, nl, t.x0, t.x1, t.z0, x2, z2,
                                  np.concatenate([sx, cx]), np.concatenate([sz, cz]))
        parts.append((np.repeat(x2, yin.size), np.tile(yin, x2.size), np.repeat(z2, yin.size)))
    for s in scene.structures:
        if s.shape == "cylinder":
            sx, sy, sz = _cylinder_shell(s, dp, nl)
        else:
            # on the box's own lattice (its faces dp/2 outside the outer layer, whatever the
            # box's size): on the fluid's lattice a face that falls on a lattice point loses it
            sx, sy, sz = _grid(_even(s.x0, s.x1, dp), _even(s.y0, s.y1, dp), _even(s.z0, s.z1, dp))
            d = np.minimum.reduce([sx - s.x0, s.x1 - sx, sy - s.y0, s.y1 - sy, sz - s.z0,
                                   s.z1 - sz])
            sx, sy, sz = sx[d < th], sy[d < th], sz[d < th]
        keep = (sx > t.x0) & (sx < t.x1) & (sy > t.y0) & (sy < t.y1) & (sz > t.z0)
        parts.append((sx[keep], sy[keep], sz[keep]))
    wx, wy, wz = (np.concatenate([p[k] for p in parts]) for k in range(3))
    first = _unique(wx, wy, wz, dp)
    wx, wy, wz = wx[first], wy[first], wz[first]

    fx, fy, fz = [], [], []
    for b in scene.water_blocks:
        x, y, z = _lattice3(scene, b)
        fx.append(x)
        fy.append(y)
        fz.append(z)
    x, y, z = np.concatenate(fx), np.concatenate(fy), np.concatenate(fz)
    first = _unique(x, y, z, dp)
    x, y, z = x[first], y[first], z[first]
    surf = np.full(x.size, -np.inf)      # the highest block top over each particle
    for b in scene.water_blocks:
        cover = (x > b.x0) & (x < b.x1) & (y > b.y0) & (y < b.y1)
        surf[cover] = np.maximum(surf[cover], b.z1)
    half = 0.5 * dp * (1 - 1e-6)
    keep = ((x > t.x0 + half) & (x < t.x1 - half) & (y > t.y0 + half) & (y < t.y1 - half)
            & (z > t.z0 + half))
    for bed in scene.beds:
        _, below = _polyline_distance(bed, x, z)
        keep &= ~below
    for s in scene.structures:
        vertical = (z > s.z0 - half) & (z < s.z1 + half)
        if s.shape == "cylinder":
            r = 0.5 * (s.x1 - s.x0)
            across = np.hypot(x - 0.5 * (s.x0 + s.x1), y - 0.5 * (s.y0 + s.y1)) < r + half
        else:
            across = (x > s.x0 - half) & (x < s.x1 + half) & (y > s.y0 - half) & (y < s.y1 + half)
        keep &= ~(vertical & across)
    if not keep.any():
        raise ValueError("water_blocks: no fluid particle left after removing beds and structures")
    return Layout(x[keep], z[keep], surf[keep], wx, wz, nl, fluid_y=y[keep], wall_y=wy)
