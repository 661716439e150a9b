"""Boundary-data sources: validation, the wave-model adapter's datum."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sph_core.boundary_data import (BoundaryData, BoundaryDataError, BoundaryNodes,
                                    BoundarySample, WaveModelBoundary, validate_sample)

SWL = 0.5


def nodes(n: int = 6) -> BoundaryNodes:
    return BoundaryNodes("left", 0.0, np.linspace(0.0, 0.8, n), 0.0, 0.8, x_gauge=0.05)


class LinearShallowModel:
    """A WaveModel duck type with known values: eta = a x + b t, u = z (z from still water)."""

    def __init__(self, depth: float = SWL) -> None:
        self.t = 0.0
        self.depth = depth

    def advance_to(self, t: float) -> None:
        self.t = t

    def elevation(self, x):
        return 0.01 * np.asarray(x, dtype=float) + 0.001 * self.t

    def velocity(self, x, z):
        z = np.asarray(z, dtype=float)
        return z.copy(), np.full(z.shape, self.t)

    def impose(self, x, eta, u_ref):
        pass


def test_nodes_reject_unordered_levels_and_bad_side():
    with pytest.raises(BoundaryDataError, match="z: levels"):
        BoundaryNodes("left", 0.0, np.array([0.0, 0.2, 0.1]), 0.0, 1.0)
    with pytest.raises(BoundaryDataError, match="side"):
        BoundaryNodes("top", 0.0, np.array([0.0, 0.1]), 0.0, 1.0)  # type: ignore[arg-type]
    with pytest.raises(BoundaryDataError, match="within"):
        BoundaryNodes("left", 0.0, np.array([0.0, 1.5]), 0.0, 1.0)


@pytest.mark.parametrize("bad, match", [
    (dict(u=np.array([0, 0, np.nan, 0, 0, 0.0])), r"left\.u: non-finite value nan at node 2"),
    (dict(w=np.zeros(5)), r"left\.w: expected 6 values"),
    (dict(eta=math.inf), r"left\.eta: must be finite"),
    (dict(eta=0.4), r"left\.eta: surface z = 0\.9.* outside the tank"),
    (dict(eta=-0.6), r"left\.eta: surface .* outside the tank"),
    (dict(t=math.nan), r"left\.t: must be finite"),
])
def test_bad_samples_name_what_is_wrong(bad, match):
    nd = nodes()
    good = dict(t=1.0, u=np.zeros(6), w=np.zeros(6), eta=0.0)
    with pytest.raises(BoundaryDataError, match=match):
        validate_sample(BoundarySample(**{**good, **bad}), nd, SWL, where="left")


def test_wave_model_adapter_converts_the_datum_and_reads_the_gauge():
    nd = nodes()
    src = WaveModelBoundary(LinearShallowModel(), nd, SWL, x_model=2.0)
    assert isinstance(src, BoundaryData)
    s = src.sample(3.0)
    # u = z measured from still water: node z (absolute) minus the still-water level
    np.testing.assert_allclose(s.u, nd.z - SWL)
    np.testing.assert_allclose(s.w, 3.0)
    assert s.eta == pytest.approx(0.01 * 2.0 + 0.003)
    # the gauge stands 0.05 m inside the face: the model is read there too
    assert s.gauge_eta == pytest.approx(0.01 * 2.05 + 0.003)


class FrontModel(LinearShallowModel):
    """u = x, w = z at every point, with a front: the wave has reached x < 2.1 m only."""

    def velocity(self, x, z):
        x, z = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(z, dtype=float))
        return x.copy(), z.copy()

    def front_factor(self, x):
        return np.where(np.asarray(x, dtype=float) < 2.1, 0.5, 0.0)


def test_wave_model_adapter_gives_the_wave_inside_the_domain():
    """velocity_along: the model at x_model + dx at the nodes' heights, for ISPH's relaxation
    zones; with a front, every column scaled by the front factor at the one nearest the
    wavemaker (smallest model x)."""
    nd = nodes()
    dx = np.array([0.0, 0.1, 0.2])
    u, w = WaveModelBoundary(LinearShallowModel(), nd, SWL, x_model=2.0).velocity_along(1.5, dx)
    assert u.shape == w.shape == (3, nd.size)
    np.testing.assert_allclose(u, np.tile(nd.z - SWL, (3, 1)))
    np.testing.assert_allclose(w, 1.5)
    src = WaveModelBoundary(FrontModel(), nd, SWL, x_model=2.0)
    u, w = src.velocity_along(1.0, dx)
    np.testing.assert_allclose(u, 0.5 * (2.0 + dx)[:, None] * np.ones(nd.size))
    np.testing.assert_allclose(w, 0.5 * np.tile(nd.z - SWL, (3, 1)))
    u, _ = src.velocity_along(1.0, -dx + 0.2)   # the outlet's way: columns at 2.2 ... 2.0 m
    np.testing.assert_allclose(u[:, 0], 0.5 * (2.2 - dx))
    u, _ = WaveModelBoundary(FrontModel(), nd, SWL, x_model=2.15).velocity_along(1.0, dx)
    assert np.all(u == 0.0)   # ahead of the front: still water


def test_wave_model_adapter_refuses_a_depth_mismatch():
    with pytest.raises(BoundaryDataError, match="model.depth"):
        WaveModelBoundary(LinearShallowModel(depth=0.7), nodes(), SWL, x_model=0.0)
