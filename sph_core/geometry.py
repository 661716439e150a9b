"""Particle positions for a scene: fluid on a lattice, dummy wall particles in layers.

Fluid particles sit on the lattice (x0 + (i + 1/2) dp, z0 + (j + 1/2) dp) anchored at the tank's
lower-left inner corner. Wall layers are ``n_layers = ceil(2h/dp)`` deep so that a fluid particle
at the wall sees a full kernel support (2h) of dummy particles. The side walls are columns dp/2,
3dp/2, ... outside their faces x0 and x1, running down through the corners; the bottom rows (and
sloping beds) between them are spaced ``wall_dx`` = (x1 - x0) / round((x1 - x0) / dp), so that
they meet both columns one spacing away whatever the tank length. (On the dp lattice a tank
402.5 dp long left a gap of 1.5 dp at the right corner in every layer, through which a violent
impact pushed fluid out of the tank: docs/studies/wall_pressure.md.) A bed's dummies are those
lattice points below its line (a staircase along a slope), or with ``layout = "along_slope"``
rows parallel to each segment (a smooth bed: more run-up, docs/studies/runup.md).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from .scene import Bed, Rect, Scene


@dataclass
class Layout:
    """Initial particle positions of a scene."""

    fluid_x: np.ndarray
    fluid_z: np.ndarray
    fluid_surface: np.ndarray  # z of the free surface above each fluid particle (hydrostatics)
    wall_x: np.ndarray
    wall_z: np.ndarray
    n_layers: int
    fluid_y: np.ndarray | None = None   # 3D scenes (geometry3d.py); None: the x-z plane
    wall_y: np.ndarray | None = None


def wall_layers(scene: Scene) -> int:
    return int(math.ceil(2.0 * scene.h / scene.dp - 1e-9))


def buffer_layers(scene: Scene, width: float | None) -> int:
    """Columns of an open end's buffer ``width`` [m] wide (rounded up), at least the walls'
    ``wall_layers``; None: the walls'."""
    nl = wall_layers(scene)
    return nl if width is None else max(nl, int(math.ceil(width / scene.dp - 1e-9)))


def wall_dx(scene: Scene) -> float:
    """x spacing of the bottom rows and beds: the tank length over a whole number of spacings
    closest to dp, so the rows end about one spacing from both side walls' first columns."""
    length = scene.tank.x1 - scene.tank.x0
    return length / max(1, round(length / scene.dp))


def _lattice(scene: Scene, xa: float, xb: float, za: float, zb: float,
             dx: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Lattice points with xa < x < xb and za < z < zb (x spacing ``dx``, default dp)."""
    dp, t = scene.dp, scene.tank
    dx = dp if dx is None else dx
    i0 = math.floor((xa - t.x0) / dx - 0.5) - 1
    i1 = math.ceil((xb - t.x0) / dx - 0.5) + 1
    j0 = math.floor((za - t.z0) / dp - 0.5) - 1
    j1 = math.ceil((zb - t.z0) / dp - 0.5) + 1
    xs = t.x0 + (np.arange(i0, i1 + 1) + 0.5) * dx
    zs = t.z0 + (np.arange(j0, j1 + 1) + 0.5) * dp
    eps = 1e-9 * dp
    xs = xs[(xs > xa + eps) & (xs < xb - eps)]
    zs = zs[(zs > za + eps) & (zs < zb - eps)]
    gx, gz = np.meshgrid(xs, zs, indexing="ij")
    return gx.ravel(), gz.ravel()


def _polyline_distance(bed: Bed, x: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance of points to the polyline, and whether each point is below it (within its x range)."""
    pts = np.asarray(bed.points, dtype=float)
    dist = np.full(x.shape, np.inf)
    for (ax, az), (bx, bz) in zip(pts[:-1], pts[1:]):
        ex, ez = bx - ax, bz - az
        s = np.clip(((x - ax) * ex + (z - az) * ez) / (ex * ex + ez * ez), 0.0, 1.0)
        dist = np.minimum(dist, np.hypot(x - (ax + s * ex), z - (az + s * ez)))
    inside = (x >= pts[0, 0]) & (x <= pts[-1, 0])
    below = inside & (z < np.interp(x, pts[:, 0], pts[:, 1]))
    return dist, below


def _along_slope(bed: Bed, dp: float, n_layers: int, x0: float, x1: float, z0: float,
                 lattice_x: np.ndarray, lattice_z: np.ndarray, other_x: np.ndarray,
                 other_z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Wall particles of an ``along_slope`` bed: ``n_layers`` rows parallel to each segment,
    (k + 1/2) dp below it and spaced its length over a whole number of spacings closest to dp,
    inside x0 < x < x1 and above the tank's floor z0 (whose rows hold the rest). Where segments
    or the tank's walls (``other``) meet, a row point closer than 0.7 dp to one kept before is
    dropped (concave joints); the staircase's ``lattice`` points farther than 0.8 dp from every
    row point fill the wedges the rows leave at convex joints."""
    pts = np.asarray(bed.points, dtype=float)
    kx, kz = [other_x], [other_z]
    for (ax, az), (bx, bz) in zip(pts[:-1], pts[1:]):
        length = math.hypot(bx - ax, bz - az)
        tx, tz = (bx - ax) / length, (bz - az) / length        # along the segment
        m = max(1, round(length / dp))
        s = (np.arange(m) + 0.5) * length / m
        k = (np.arange(n_layers) + 0.5) * dp
        gs, gk = np.meshgrid(s, k, indexing="ij")
        x = (ax + gs * tx + gk * tz).ravel()            # (tz, -tx): the normal into the bed
        z = (az + gs * tz - gk * tx).ravel()
        keep = (x > x0) & (x < x1) & (z > z0)
        x, z = x[keep], z[keep]
        near = cKDTree(np.column_stack([np.concatenate(kx), np.concatenate(kz)])).query(
            np.column_stack([x, z]), distance_upper_bound=0.7 * dp)[0]
        kx.append(x[np.isinf(near)])
        kz.append(z[np.isinf(near)])
    rx, rz = np.concatenate(kx[1:]), np.concatenate(kz[1:])
    if rx.size:
        far = np.isinf(cKDTree(np.column_stack([rx, rz])).query(
            np.column_stack([lattice_x, lattice_z]), distance_upper_bound=0.8 * dp)[0])
        rx, rz = np.concatenate([rx, lattice_x[far]]), np.concatenate([rz, lattice_z[far]])
    return rx, rz


def _rect_shell(scene: Scene, r: Rect, thickness: float) -> tuple[np.ndarray, np.ndarray]:
    x, z = _lattice(scene, r.x0, r.x1, r.z0, r.z1)
    d = np.minimum.reduce([x - r.x0, r.x1 - x, z - r.z0, r.z1 - z])
    keep = d < thickness
    return x[keep], z[keep]


def build_layout(scene: Scene, buffers: Mapping[str, int] | None = None) -> Layout:
    """Place fluid and wall particles for a 2D ``scene`` (3D: geometry3d.build_layout_3d).
    ``buffers``: side -> columns of an open end's buffer (``buffer_layers``) where it is wider
    than the walls; those columns are wall columns here, which open_ends turns into the buffer."""
    if scene.dim != 2:
        raise ValueError("build_layout: a 2D scene's; geometry3d.build_layout_3d places a 3D one")
    dp, t = scene.dp, scene.tank
    nl = wall_layers(scene)
    th = nl * dp
    # tank walls: left and right columns (including the corners), bottom rows
    zs = t.z0 + (np.arange(-nl, math.ceil((t.z1 - t.z0) / dp)) + 0.5) * dp
    zs = zs[zs <= t.z1]
    dx = wall_dx(scene)
    xs_bottom = t.x0 + (np.arange(round((t.x1 - t.x0) / dx)) + 0.5) * dx
    wx, wz = [], []
    for k in range(nl):
        for xw in (t.x0 - (k + 0.5) * dp, t.x1 + (k + 0.5) * dp):
            wx.append(np.full(zs.size, xw))
            wz.append(zs)
        wx.append(xs_bottom)
        wz.append(np.full(xs_bottom.size, t.z0 - (k + 0.5) * dp))
    for side, nb in (buffers or {}).items():   # a wider open end: more columns outside its face
        for k in range(nl, nb):
            wx.append(np.full(zs.size, t.x0 - (k + 0.5) * dp if side == "left"
                              else t.x1 + (k + 0.5) * dp))
            wz.append(zs)
    # sloping beds: lattice points below the line, within the wall thickness of it
    for bed in scene.beds:
        pts = np.asarray(bed.points)
        bx, bz = _lattice(scene, max(pts[:, 0].min(), t.x0), min(pts[:, 0].max(), t.x1),
                          max(pts[:, 1].min() - th, t.z0), min(pts[:, 1].max(), t.z1), dx)
        d, below = _polyline_distance(bed, bx, bz)
        keep = below & (d < th)
        bx, bz = bx[keep], bz[keep]
        if bed.layout == "along_slope":
            bx, bz = _along_slope(bed, dp, nl, t.x0, t.x1, t.z0, bx, bz,
                                  np.concatenate(wx), np.concatenate(wz))
        wx.append(bx)
        wz.append(bz)
    for s in scene.structures:
        sx, sz = _rect_shell(scene, s, th)
        keep = (sx > t.x0) & (sx < t.x1) & (sz > t.z0)
        wx.append(sx[keep])
        wz.append(sz[keep])
    wall_x = np.concatenate(wx)
    wall_z = np.concatenate(wz)
    # remove duplicates (beds and structures may overlap the tank walls or each other)
    key = np.round(np.stack([wall_x, wall_z]) / (0.25 * dp)).astype(np.int64)
    _, first = np.unique(key, axis=1, return_index=True)
    first.sort()
    wall_x, wall_z = wall_x[first], wall_z[first]

    # fluid: lattice points of every water block, inside the tank, outside beds and structures
    fx, fz, fs = [], [], []
    for b in scene.water_blocks:
        x, z = _lattice(scene, b.x0, b.x1, b.z0, b.z1)
        fx.append(x)
        fz.append(z)
        fs.append(np.full(x.size, b.z1))
    fluid_x, fluid_z, surf = np.concatenate(fx), np.concatenate(fz), np.concatenate(fs)
    key = np.round(np.stack([fluid_x, fluid_z]) / (0.25 * dp)).astype(np.int64)
    _, first = np.unique(key, axis=1, return_index=True)
    first.sort()
    fluid_x, fluid_z = fluid_x[first], fluid_z[first]
    # surface above a point: the highest block top among blocks covering its x
    surf = np.full(fluid_x.size, -np.inf)
    for b in scene.water_blocks:
        cover = (fluid_x > b.x0) & (fluid_x < b.x1)
        surf[cover] = np.maximum(surf[cover], b.z1)
    half = 0.5 * dp * (1 - 1e-6)
    keep = (fluid_x > t.x0 + half) & (fluid_x < t.x1 - half) & (fluid_z > t.z0 + half)
    # a bed splits the lattice: every point below its polyline (within the wall thickness) is a
    # dummy, every point above it fluid, with no gap band, so each lattice column meets the bed
    # at the flat floor's fluid-to-dummy spacing dp. (A band of dp/2 left a one-particle void in
    # about half of the columns along a slope: the shoreline wedge went into tension and burst,
    # docs/studies/SHORELINE_JET.md.)
    for bed in scene.beds:
        _, below = _polyline_distance(bed, fluid_x, fluid_z)
        keep &= ~below
    for s in scene.structures:
        inside = ((fluid_x > s.x0 - half) & (fluid_x < s.x1 + half)
                  & (fluid_z > s.z0 - half) & (fluid_z < s.z1 + half))
        keep &= ~inside
    if not keep.any():
        raise ValueError("water_blocks: no fluid particle left after removing beds and structures")
    _warn_right_wall_gap(scene, fluid_x[keep])
    return Layout(fluid_x[keep], fluid_z[keep], surf[keep], wall_x, wall_z, nl)


def _warn_right_wall_gap(scene: Scene, fluid_x: np.ndarray) -> None:
    """Warn when water reaches the right wall (or open end) of a tank that is not a whole number
    of dp long: the lattice, anchored at x0, then leaves a gap of a fraction of dp there, and the
    water slumps into it at the start (measured, still water d 0.24 m, dp 0.02, 0.5 s: 0.32 m/s
    in a 1.99 m tank against 0.027 m/s in a 2.00 m one under WCSPH; under ISPH 1.3 m/s in a
    0.61 m tank against 0.002 m/s in a 0.60 m one)."""
    dp, t = scene.dp, scene.tank
    near = fluid_x[fluid_x > t.x1 - 1.5 * dp]   # none: a beach or a structure holds the corner
    if near.size == 0:
        return
    gap = t.x1 - float(near.max()) - 0.5 * dp
    if gap > 0.05 * dp:
        warnings.warn(f"tank: x1 - x0 = {t.x1 - t.x0:.6g} m is {(t.x1 - t.x0) / dp:.4g} dp, so the "
                      f"water ends {gap / dp:.2f} dp short of the right wall and slumps into the "
                      f"gap at the start; make the tank length a whole number of dp",
                      stacklevel=3)
