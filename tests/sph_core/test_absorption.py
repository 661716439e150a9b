"""The open ends' absorption gain (sph_core.absorption) and how a flume picks it."""

from __future__ import annotations

import math

import pytest

from sph_core.absorption import absorption_gain, linear_wavenumber, source_period
from sph_core.boundary_data import WaveModelBoundary
from sph_core.open_ends import OpenBoundaries, flume_nodes
from sph_core.scene import make_scene
from wave_client.theories import build_theory
from wave_client.theories import wavenumber as theory_wavenumber

G, D = 9.81, 0.3


@pytest.mark.parametrize("kd", [0.3, 0.75, 1.2, 2.0])
def test_linear_gain_is_the_depth_mean_velocity_of_a_linear_wave(kd):
    """G = omega/(k d): the depth mean of Airy's u = a omega cosh k(z+d)/sinh kd over the
    elevation amplitude a (integrated numerically here), = sqrt(g/d) sqrt(tanh kd / kd)."""
    k = kd / D
    omega = math.sqrt(G * k * math.tanh(kd))
    gain = absorption_gain("linear", G, D, 2 * math.pi / omega)
    n = 2000
    mean_u = sum(omega * math.cosh(k * (D * (j + 0.5) / n)) / math.sinh(kd) for j in range(n)) / n
    assert gain == pytest.approx(mean_u, rel=1e-6)
    assert gain == pytest.approx(math.sqrt(G / D * math.tanh(kd) / kd), rel=1e-9)
    assert gain < absorption_gain("shallow", G, D, 2 * math.pi / omega)


def test_linear_gain_tends_to_the_shallow_water_gain_for_long_waves():
    shallow = math.sqrt(G / D)
    assert absorption_gain("shallow", G, D, 1.0) == shallow
    for period, tol in ((20.0, 2e-3), (200.0, 2e-5)):  # kd ~ 0.08, 0.008: error ~ (kd)^2 / 6
        assert absorption_gain("linear", G, D, period) == pytest.approx(shallow, rel=tol)
    assert absorption_gain("linear", G, D, None) == shallow  # no period known: its limit
    with pytest.raises(ValueError, match="absorption"):
        absorption_gain("deep", G, D, 1.0)
    with pytest.raises(ValueError, match="period"):
        absorption_gain("linear", G, D, -1.0)


def test_wavenumber_agrees_with_the_wave_client_dispersion():
    for period in (0.5, 1.4, 3.0):
        omega = 2 * math.pi / period
        assert linear_wavenumber(omega, D, G) == pytest.approx(float(theory_wavenumber(omega, D)),
                                                        rel=1e-6)


def _ends(absorption: str, period_field: float | None = None) -> OpenBoundaries:
    sides = [{"side": s, "elevation": e, "absorption": absorption,
              "absorption_period": period_field}
             for s, e in (("left", "imposed"), ("right", "extrapolated"))]
    scene = make_scene({
        "dp": 0.02, "t_end": 1.0, "still_water_level": D,
        "tank": {"x0": 0.0, "x1": 0.6, "z0": 0.0, "z1": D + 0.12},
        "water_blocks": [{"x0": 0.0, "x1": 0.6, "z0": 0.0, "z1": D}],
        "constants": {"c0": 10.0 * math.sqrt(G * D)}, "open_boundaries": sides})
    model = build_theory("linear", height=0.01, period=1.0, depth=D, ramp_time=1.0)
    sources = {side: WaveModelBoundary(model, nd, D, nd.x_face)
               for side, nd in flume_nodes(scene).items()}
    return OpenBoundaries.from_scene(scene, sources, 0.02)


def test_flume_takes_the_gain_of_its_scene_and_the_source_period():
    """linear (default): omega/(k d) at the source theory's period, or at the scene's
    absorption_period; shallow: sqrt(g/d) (seed 002)."""
    lin = _ends("linear")
    assert source_period(lin.sources["left"]) == 1.0
    for b in (0, 1):
        assert lin.ends.sqgd[b] == pytest.approx(absorption_gain("linear", G, D, 1.0))
    assert _ends("linear", 2.5).ends.sqgd[0] == pytest.approx(
        absorption_gain("linear", G, D, 2.5))
    assert _ends("shallow").ends.sqgd[1] == pytest.approx(math.sqrt(G / D))
    assert absorption_gain("linear", G, D, 1.0) < 0.85 * math.sqrt(G / D)  # kd 1.38: 20 % below
