"""Wave cases of the seed 002 validation table through the open-boundary flume.

The table is tests/data/wave_cases_seed002.csv (read, and each case's theory built, by
wavesph/cases/seed002_waves.py from the package's copy). The default suite runs case V
(stream-function wave in shallow water: the cheapest) at a coarse resolution; the accuracy goal
of issue 3 (RMSE/H <= 5 % at H/dp >= 10, seed 002 reports <= 4.3 %), the reflection of the
absorbing outlet and the long-run water level are slow tests (``pytest -m slow``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from wavesph.cases.seed002_waves import case_theory, read_cases
from wavesph.cases.wave_flume import flume_case
from wavesph.studies.planning import depth_divisor

theories = pytest.importorskip("wave_client.theories")



# measured (docs/studies/schemes.md "ISPH open ends: the buffers in the projection"): the open
# ends' buffers hold still water and a through-flow, but under a progressive wave the surface
# rows next to a face and the inlet's buffer after an outflow break down (2.49 s before the
# buffers had rows of their own)
ISPH_WAVE_FLUME = ("ISPH: unstable at t = 3.94 s (2 particles excluded before, then one over the "
                   "tank top); measured, not tuned away")


def cases() -> dict[str, dict]:
    """The package's copy of the table (test_sweeps checks it is tests/data's)."""
    return read_cases()


def run_case(test: str, dp: float, periods: float, ramp_periods: float = 1.0, **kw) -> dict:
    row = cases()[test]
    h, t, d = float(row["H"]), float(row["T"]), float(row["d"])
    model = case_theory(row["theory"], height=h, period=t, depth=d, ramp_time=ramp_periods * t)
    return flume_case(model, height=h, period=t, depth=d, wavelength=model.length, dp=dp,
                      periods=periods, ramp=ramp_periods * t,
                      standing=row["theory"] == "standing", **kw)


def test_case_table_wavelengths_are_linear_dispersion():
    """The table's L is the linear-theory wavelength (the flume uses the nonlinear one, e.g.
    3.32 m instead of 3.26 m for the stream-function wave of case V)."""
    c = cases()
    assert list(c) == ["I", "II", "III", "IV", "V", "VI"]
    for test, row in c.items():
        if row["L"]:
            k = theories.wavenumber(2 * math.pi / float(row["T"]), float(row["d"]))
            assert 2 * math.pi / float(k) == pytest.approx(float(row["L"]), abs=0.006), test


# the coarse case under every scheme; Riemann SPH and ISPH cost 2.5-10x WCSPH's time: slow
@pytest.mark.parametrize("scheme", ["wcsph", pytest.param("riemann", marks=pytest.mark.slow),
                                    pytest.param("isph", marks=[pytest.mark.slow, pytest.mark.xfail(
                                        strict=True, reason=ISPH_WAVE_FLUME)])])
def test_case_V_coarse_flume_generates_the_wave(scheme):
    """H/dp = 3, one period measured after a 1-period ramp and the travel to mid-flume: a coarse
    check that the inlet makes the right wave and the outlet lets it out. Bounds: twice and
    three times the goals that hold at H/dp >= 10 (5 %, below)."""
    res = run_case("V", dp=0.02, periods=1.0, scheme={"kind": scheme})
    assert res["rmse_over_H"] < 0.10, res
    assert res["reflection"] < 0.15, res
    counts = res["boundary_counts"]
    assert res["fluid_change"] == sum(c["in"] - c["out"] for c in counts.values())
    # the bench's speed watch reads mid-flume's fluid at the wave's own crest speed (particle
    # noise adds a little), so a face speed many times it means a disordered end
    assert 0.8 < res["speed_max_m_s"]["mid"] / crest_speed("V") < 1.5, res["speed_max_m_s"]
    assert set(res["speed_max_m_s"]) == {"left", "right", "mid"}


def crest_speed(test: str) -> float:
    """The largest horizontal fluid speed of the case's wave (at the crest's surface) [m/s]."""
    row = cases()[test]
    model = case_theory(row["theory"], height=float(row["H"]), period=float(row["T"]),
                        depth=float(row["d"]))
    model.advance_to(0.0)
    x = np.linspace(0.0, float(model.length), 201)
    u, _ = model.velocity(x, model.elevation(x))
    return float(np.max(np.abs(u)))


@pytest.mark.slow
@pytest.mark.parametrize("test", ["I", "III", "IV", "V"])
def test_case_meets_the_accuracy_goal_at_ten_particles_per_height(test):
    row = cases()[test]
    # H/dp >= 10 on a dp that divides the depth (whole rows: the particles fill to still water)
    dp = depth_divisor(float(row["d"]), float(row["H"]) / 10.0)
    res = run_case(test, dp=dp, periods=5.0)
    assert res["rmse_over_H"] <= 0.05, res


@pytest.mark.slow
def test_absorbing_outlet_reflects_less_than_five_percent_and_far_less_without_correction():
    """Seed 002's correction on both ends vs off on both ends, case V at H/dp = 3, 3 periods
    (bench/flume_accuracy.py, measured: K_R = 0.020 with (three-gauge fit 0.040), 0.60 without;
    RMSE/H 0.060 and 0.28; ~50 s each): without it the outlet imposes the theory's velocity
    whatever arrives (the SPH wave reaches it 20 % smaller), and the mismatch goes back."""
    with_corr = run_case("V", dp=0.02, periods=3.0)
    without = run_case("V", dp=0.02, periods=3.0, absorb=(False, False))
    assert with_corr["reflection"] < 0.05, with_corr
    assert without["reflection"] > 5.0 * with_corr["reflection"], (with_corr, without)
    assert without["rmse_over_H"] > 2.0 * with_corr["rmse_over_H"], (with_corr, without)


@pytest.mark.slow
def test_absorbing_outlet_reflects_less_than_five_percent_at_six_particles_per_height():
    """Case V at H/dp = 6, 4 periods (measured: K_R = 0.019, three-gauge fit 0.040; RMSE/H
    0.042; ~9 min)."""
    res = run_case("V", dp=0.01, periods=4.0)
    assert res["reflection"] < 0.05, res


@pytest.mark.slow
def test_mean_water_level_drifts_less_than_half_a_particle_over_twenty_periods():
    """Case V at H/dp = 4, 20 periods after the ramp: the flume's water volume per length
    against still water, and the gauges' mean level over the last period against the model's
    (measured: +1.3 mm and -1.7 mm, limit 7.5 mm; ~10 min); the first rests on the exact mass
    balance."""
    dp = 0.015
    res = run_case("V", dp=dp, periods=20.0)
    assert abs(res["level_drift_m"]) < 0.5 * dp, res
    assert abs(res["level_last_period_m"]) < 0.5 * dp, res
    counts = res["boundary_counts"]
    assert res["fluid_change"] == sum(c["in"] - c["out"] for c in counts.values())
    assert math.isfinite(res["rmse_over_H"])


@pytest.mark.slow
def test_filter_absorbs_a_kd_1_2_wave():
    """Stream-function wave, kd 1.2 (H 0.02, d 0.2, T 0.897 s), H/dp 2, h/dp 2, wall AV off, 2
    periods (bench/flume_accuracy.py; measured: reflection 2.3 % with the filter, 6.2 % with
    the retired linear gain, docs/decisions/absorption.md; ~1-3 min): below 4 %."""
    period = 2 * math.pi / math.sqrt(9.81 * 1.2 / 0.2 * math.tanh(1.2))
    model = theories.build_theory("stream", height=0.02, period=period, depth=0.2,
                                  ramp_time=period, n_fourier=16)
    res = flume_case(model, height=0.02, period=period, depth=0.2, wavelength=model.length,
                     dp=0.01, periods=2.0, ramp=period, h_over_dp=2.0, alpha_wall_factor=0.0)
    assert res["reflection"] < 0.04, res


def test_flume_case_passes_its_device_to_the_simulation(monkeypatch):
    """``flume_case(device=...)`` (the flume benches' --device) reaches the Simulation: asking for
    cuda where none is found stops with the one-line DeviceError before a step is taken."""
    import sph_core.cuda
    from sph_core.simulation import DeviceError

    monkeypatch.setattr(sph_core.cuda, "unavailable_reason", lambda: "no CUDA GPU (test)")
    model = theories.build_theory("linear", height=0.02, period=1.0, depth=0.2, ramp_time=1.0)
    with pytest.raises(DeviceError, match=r"^device cuda: no CUDA GPU \(test\)$"):
        flume_case(model, height=0.02, period=1.0, depth=0.2, wavelength=float(model.length),
                   dp=0.02, periods=1.0, ramp=1.0, device="cuda")
