"""The coupled Boussinesq-SPH flume (wavesph/cases/coupled_flume.py): the coupling client with the
Boussinesq model of a `wavesph waves` scene (as `wavesph couple --model boussinesq` runs it) drives an SPH zone with a 1:10 beach over a real socket; the SPH gauge on the flat bed follows a
Boussinesq-only run of the same flume. Two-way and absorption-only coupling."""

from __future__ import annotations

import math
import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from wavesph.cases.coupled_flume import (ISPH_WAVES, ISPH_WAVES_CONSTANTS, OUTLET_ZONE, FlumeCase,
                                         correlation, reference_run, rmse_over_h, run_coupled,
                                         sph_only_scene, sph_zone_scene, to_toml, wave_scene)
from server.schemas import RunRequest
from wave_client.boussinesq.wave_scene import WaveScene, build_model

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "coupled"
# short and coarse: 2 wavelengths of Boussinesq, H/dp = 1, 2 periods compared (~20 s each)
COARSE = FlumeCase(wavelengths=2.0, compare_periods=2.0)
COARSE_DP = 0.04


@pytest.fixture
def passive_omp(monkeypatch):
    monkeypatch.setenv("OMP_WAIT_POLICY", "passive")  # shared cores; kept out of other tests


@pytest.mark.parametrize("two_way,transport,wavelengths", [(True, "ws", 2.0), (False, "tcp", 4.0)])
def test_coarse_coupled_flume_follows_the_boussinesq_only_run(tmp_path, passive_omp, two_way,
                                                              transport, wavelengths):
    """Two-way (the model's boundary lets SPH's reflection out) over WebSocket, absorption-only
    (`wavesph couple --absorb`) over TCP. Finishes with every gauge wet and finite, and the
    flat-bed gauge follows the Boussinesq-only run: correlation >= 0.9 (phase error below
    ~25 deg; a wrong x offset of L/4 gives ~0, a sign error -1, no wave NaN) and RMSE/H <= 0.25:
    at H/dp = 1 the kernel gauge's surface is uncertain by ~dp/4 = H/4 (the fine-dp goal is the
    slow test's). Over 4 wavelengths the SPH zone starts late (t_sph_start > 0)."""
    c = replace(COARSE, wavelengths=wavelengths).at(COARSE_DP)
    assert (c.t_sph_start > 0) == (wavelengths > 2)
    res = run_coupled(c, COARSE_DP, tmp_path, two_way=two_way, transport=transport)
    assert res["exit_code"] == 0 and res["state"] == "finished", res["status"]
    assert res["absorb"] == ("incident" if two_way else "client")  # one absorber, never two
    assert res["windows"] == math.ceil((c.t_end - c.t_sph_start) / c.window - 1e-9)
    t, eta = res["t"], res["eta"]
    assert t[0] == pytest.approx(c.t_sph_start + c.window)  # a row per window end
    assert t[-1] == pytest.approx(c.t_end)
    assert set(eta) == {"left_boundary", "flat", "toe", "beach"}
    for name, series in eta.items():
        assert np.all(np.isfinite(series)), f"{name} dry or non-finite"
    ref = reference_run(c, t)["flat"]
    assert np.ptp(ref[t >= c.compare_from]) > 0.8 * c.height  # full waves in the compared span
    assert correlation(t, eta["flat"], ref, c.compare_from) >= 0.9
    assert rmse_over_h(t, eta["flat"], ref, c) <= 0.25
    # the client wrote its log: the same windows
    log = (tmp_path / "client_gauges.csv").read_text().splitlines()
    assert sum(1 for line in log if line and line[0].isdigit()) == res["windows"]


def test_coarse_isph_zone_with_an_outlet_follows_the_boussinesq_only_run(tmp_path, passive_omp):
    """A coupled ISPH run: the zone open at both ends, both fed by the model, absorption-only,
    with ISPH's wave options (relaxation zones at both ends). It finishes, and every gauge
    follows the model alone over the same flat flume (measured at this dp: RMSE/H 3.0 % at the
    compared gauge, correlation 0.997; WCSPH 9.1 % at H/dp 1); an outlet the client fed zero
    velocity did not (correlation 0.950)."""
    c = replace(COARSE, **OUTLET_ZONE).at(COARSE_DP)
    res = run_coupled(c, COARSE_DP, tmp_path, two_way=False, scheme=ISPH_WAVES,
                      constants=ISPH_WAVES_CONSTANTS)
    assert res["exit_code"] == 0 and res["state"] == "finished", res["status"]
    t, eta = res["t"], res["eta"]
    assert set(eta) == {"left_boundary", "right_boundary", "flat", "mid", "far"}
    refs = reference_run(c, t)
    for name in ("flat", "mid", "far"):
        assert np.all(np.isfinite(eta[name])), f"{name} dry or non-finite"
        assert correlation(t, eta[name], refs[name], c.compare_from) >= 0.97, name
    assert rmse_over_h(t, eta["flat"], refs["flat"], c) <= 0.08


def test_sph_zone_starts_while_its_water_is_still():
    """Before t_sph_start the Boussinesq model's elevation at the SPH inlet stays below
    1e-3 H: the SPH zone, at rest until then, misses nothing of the waves."""
    c = FlumeCase().at(0.02)
    assert c.t_quiet - c.t_sph_start == pytest.approx(c.settle_periods * c.period)
    assert c.t_sph_start > 0.3 * c.t_end  # worth it: the SPH zone skips a third of the run
    model = build_model(WaveScene.model_validate(wave_scene(c, two_way=False)))
    peak = 0.0
    for t in np.arange(0.0, c.t_quiet, c.window):
        model.advance_to(float(t))
        peak = max(peak, float(np.abs(model.elevation(np.array([c.x_couple])))[0]))
    assert peak < 1e-3 * c.height
    late = []  # and the waves do come after it
    for t in np.arange(c.compare_from - c.period, c.compare_from, c.window):
        model.advance_to(float(t))
        late.append(float(model.elevation(np.array([c.x_couple]))[0]))
    assert np.ptp(late) > 0.8 * c.height
    assert sph_zone_scene(c, 0.02)["t_start"] == pytest.approx(c.t_sph_start)


def test_sph_scenes_take_a_scheme_table():
    """bench/coupled_vs_sph.py --scheme ...: both SPH scenes carry the [scheme] table they are
    given and the server accepts it; without one they keep the scene's default (WCSPH)."""
    dp = 0.02
    c = FlumeCase().at(dp)
    table = {"kind": "isph", "isph_relaxation_zone": 0.4, "isph_wall_stop": 100.0}
    zone = RunRequest.model_validate({"scene": sph_zone_scene(c, dp, scheme=table)}).scene
    full = RunRequest.model_validate({"scene": sph_only_scene(c, dp, scheme=table)}).scene
    for scene in (zone, full):
        assert scene.scheme.kind == "isph" and scene.scheme.isph_relaxation_zone == 0.4
        assert scene.scheme.isph_wall_stop == 100.0
    assert "scheme" not in sph_zone_scene(c, dp)
    assert RunRequest.model_validate({"scene": sph_zone_scene(c, dp)}).scene.scheme.kind == "wcsph"


def test_scenes_are_one_flume():
    """The coupled model, the reference and the SPH scenes describe the same flume: the SPH
    inlet at the model's coupling point, equal depth, z_ref = the model's reference level,
    gauges at the same places; the reference beach is the SPH beach down to depth d/3."""
    dp = 0.02
    c = FlumeCase().at(dp)
    coupled = build_model(WaveScene.model_validate(wave_scene(c, two_way=True)))
    ref = build_model(WaveScene.model_validate(wave_scene(c, reference=True)))
    zone = RunRequest.model_validate({"scene": sph_zone_scene(c, dp)}).scene
    full = RunRequest.model_validate({"scene": sph_only_scene(c, dp)}).scene
    assert c.wavelengths >= 10 and coupled.x_couple == pytest.approx(c.x_couple)
    assert coupled.x1 > c.x_couple + c.wavelength  # overlap: the coupling point is inside
    assert coupled.depth == pytest.approx(zone.still_water_level) == pytest.approx(0.24)
    assert coupled.reference_level == pytest.approx(-0.531 * c.depth)
    assert not WaveScene.model_validate(wave_scene(c, two_way=False)).coupling.two_way
    (bed,) = zone.beds
    (x_toe, _), (x_end, z_end) = bed.points
    assert x_toe == pytest.approx(c.x_flat) and z_end > zone.still_water_level
    assert (z_end / (x_end - x_toe)) == pytest.approx(c.slope)
    for x in (c.x_toe - 0.1, c.x_toe + 0.5, c.x_toe + 1.0):  # same beach in the reference
        assert ref.depth_at(x) == pytest.approx(c.depth - c.slope * max(0.0, x - c.x_toe))
    assert ref.depth_at(ref.x1) == pytest.approx(c.depth / 3)
    (fbed,) = full.beds
    assert full.tank.x1 - zone.tank.x1 == pytest.approx(fbed.points[0][0] - x_toe, abs=dp)
    assert abs(fbed.points[0][0] - c.x_toe) <= dp / 2  # SPH-only x = model x
    x0 = fbed.points[0][0] - c.x_flat  # the SPH-only flume's x of the SPH zone's inlet
    assert [p.x for p in full.probes] == pytest.approx([x0 + p.x for p in zone.probes])


def test_zone_with_an_outlet_is_fed_by_the_model_at_both_ends(tmp_path):
    """FlumeCase(end="outlet"): flat bed throughout, open at both ends, the model's grid running
    on past the outlet (a wavelength, then its sponge) so the client can feed the outlet's
    nodes, and the reference the same flat flume; two-way coupling is refused (the model's
    boundary stands at the inlet only)."""
    dp = 0.02
    c = FlumeCase(**OUTLET_ZONE, wavelengths=2.0).at(dp)
    zone = RunRequest.model_validate({"scene": sph_zone_scene(c, dp)}).scene
    assert not zone.beds and zone.tank.x1 == pytest.approx(2.4)
    assert [(b.side, b.elevation) for b in zone.open_boundaries] == [("left", "imposed"),
                                                                    ("right", "extrapolated")]
    (water,) = zone.water_blocks
    assert water.x1 == pytest.approx(zone.tank.x1)
    assert [p.x for p in zone.probes] == pytest.approx([0.8, 1.2, 1.6])
    for waves in (wave_scene(c, two_way=False), wave_scene(c, reference=True)):
        x_sponge = waves["grid"]["x_end"] - waves["sponge"]["right"]
        assert x_sponge >= c.x_couple + c.x_flat + c.wavelength - 1e-6
        model = build_model(WaveScene.model_validate(waves))
        assert model.depth_at(np.array([x_sponge])) == pytest.approx(c.depth)
    assert c.reflection_pair == ("flat", "mid")
    with pytest.raises(ValueError, match="absorption-only"):
        run_coupled(c, dp, tmp_path, two_way=True)
    with pytest.raises(ValueError, match="'beach' or 'outlet'"):
        FlumeCase(end="weir")
    with pytest.raises(ValueError, match="inside the zone"):
        FlumeCase(end="outlet", x_flat=0.6)


@pytest.mark.parametrize("name,kind", [("wave_two_way.toml", "two_way"),
                                       ("wave_absorption_only.toml", "absorption_only"),
                                       ("wave_reference.toml", "reference"),
                                       ("sph_zone.toml", "sph_zone"),
                                       ("wave_outlet.toml", "outlet"),
                                       ("sph_zone_outlet_isph.toml", "zone_outlet_isph")])
def test_example_files_are_the_generated_scenes(name, kind):
    c = FlumeCase().at(0.02)
    outlet = replace(c, **OUTLET_ZONE)
    want = {"two_way": lambda: wave_scene(c, True), "absorption_only": lambda: wave_scene(c, False),
            "reference": lambda: wave_scene(c, reference=True),
            "sph_zone": lambda: sph_zone_scene(c, 0.02),
            "outlet": lambda: wave_scene(outlet, two_way=False),
            "zone_outlet_isph": lambda: sph_zone_scene(outlet, 0.02, constants=ISPH_WAVES_CONSTANTS,
                                                       scheme=ISPH_WAVES)}[kind]()
    assert tomllib.loads((EXAMPLES / name).read_text()) == tomllib.loads(to_toml(want))


@pytest.mark.slow
@pytest.mark.parametrize("two_way", [
    pytest.param(True, marks=pytest.mark.xfail(strict=True, reason=(
        "measured (dp = 0.01): RMSE/H 10.8 % (free-slip walls 12.8 %): the two-way boundary "
        "does not hold the zone's mean level (+2.9 mm at the gauge: its characteristic split "
        "uses the wave's u/eta ratio for the mean too, and feeds SPH's gauge bias back) and "
        "the wave reaches the gauge 13 % low (absorption-only: 8.5 %)"))),
    False,
])
def test_coupled_flume_matches_boussinesq_only_within_5_percent(tmp_path, passive_omp, two_way):
    """The issue's goal at the benchmark's resolution (dp = 0.01, H/dp = 4, 12 wavelengths of
    Boussinesq, ~10 min): RMSE/H <= 5 % at the flat-bed gauge against the Boussinesq-only run.
    Absorption-only measured 4.95 % (phase within 0.003 rad, amplitude 8.5 % low): it passes
    with little room."""
    c = FlumeCase().at(0.01)
    t, eta, ref = _coupled_flat_gauge(c, 0.01, tmp_path, two_way)
    assert rmse_over_h(t, eta, ref, c) <= 0.05


def _coupled_flat_gauge(c: FlumeCase, dp: float, out: Path, two_way: bool):
    """(t, SPH eta, Boussinesq-only eta) at the flat-bed gauge of a finished coupled run."""
    res = run_coupled(c, dp, out, two_way=two_way)
    assert res["state"] == "finished", res["status"]
    return res["t"], res["eta"]["flat"], reference_run(c, res["t"])["flat"]


@pytest.mark.slow
def test_coupling_adds_no_loss_to_the_sph_wave(tmp_path, passive_omp):
    """The coupled wave's shortfall is SPH's, not the coupling's: its first-harmonic amplitude at
    the flat-bed gauge (over the reference's) is no lower than that of a theory-driven SPH flume
    of the same wave, dp and constants at the same distance from its inlet (wavesph.cases.wave_decay,
    no coupling there). Written first as equality within 3 %, which failed: measured at dp =
    0.02, coupled 0.928, theory-driven 0.864 (that flume, one wavelength long with an outlet at
    2 m, loses more); so the one-sided claim, with 0.02 for run-to-run scatter."""
    from wavesph.analysis import harmonic_amplitude
    from wavesph.cases.wave_decay import amplitude_profile
    from wave_client.theories import build_theory

    dp = 0.02
    c = FlumeCase().at(dp)
    t, eta, ref = _coupled_flat_gauge(c, dp, tmp_path, two_way=False)
    sel = np.nonzero(t >= c.compare_from - 1e-9)[0]
    sel = sel[: int(round(math.floor((t[-1] - t[sel[0]]) / c.period) * c.period / (t[1] - t[0])))]
    coupled = (abs(harmonic_amplitude(t[sel], eta[sel], c.omega))
               / abs(harmonic_amplitude(t[sel], ref[sel], c.omega)))
    model = build_theory("stokes", height=c.height, period=c.period, depth=c.depth,
                         ramp_time=c.period, order=2)
    alone = amplitude_profile(model, ramp=c.period, height=c.height, period=c.period,
                              depth=c.depth, dp=dp, **sph_zone_scene(c, dp)["constants"])
    assert coupled < 0.97  # the loss is real (most of the coupled RMSE/H) ...
    assert coupled >= alone.ratio_at(c.gauge) - 0.02  # ... and no worse than SPH's own
