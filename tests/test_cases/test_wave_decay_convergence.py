"""The SPH wave's own loss falls with resolution (slow: about 10 min on one loaded core).

The closed-tank standing wave of wavesph.cases.standing_wave (the wave of bench/wave_decay.py without
inlet, outlet or gauge; docs/studies/wave_decay_study.md) at three resolutions with the scene's
defaults: h/dp 2, alpha 0.01, no artificial viscosity against the walls (alpha_wall_factor 0:
with it the loss does not converge, 6.09 -> 4.73 %/m). Measured on the study's machine
(6 periods): equivalent decay 2.28, 1.80 and 1.24 %/m at dp 0.025, 0.02 and 0.01 (order 0.67
overall, 0.54 over the last halving), noise <= 0.23 % of the wave's kinetic energy -- far from
the issue's target of 1.5: the remaining loss converges slowly (see the study). The
assertions hold what was measured as achievable, with margin for round-off and load only.
"""

import math

import numpy as np
import pytest

from wavesph.cases.standing_wave import standing_wave_decay
from wavesph.analysis import harmonic_amplitude
from wavesph.cases.wave_decay import (beat_wavenumber, convergence_orders, convergence_record,
                                      group_decays, modulated_decay)
from sph_core.scene import Constants

DPS = [0.025, 0.02, 0.01]   # tank 1.0 m long: whole numbers of spacings (no gap at the wall)


@pytest.mark.slow
def test_standing_wave_loss_converges_with_resolution():
    # the scene defaults: h/dp 2, alpha 0.01, alpha_wall_factor 0 (pinned by the first assertion)
    c = Constants()
    assert (c.h_over_dp, c.alpha, c.alpha_wall_factor) == (2.0, 0.01, 0.0)
    runs = [standing_wave_decay(dp=dp, periods=6.0) for dp in DPS]
    decays = [r.equiv_decay_per_m for r in runs]
    for r in runs:
        # particle-scale noise stays a small share of the wave's kinetic energy
        assert r.noise_ke_fraction < 0.02, r
    assert decays[0] > decays[1] > decays[2] > 0, decays
    orders = convergence_orders(DPS, decays)
    overall = math.log(decays[0] / decays[2]) / math.log(DPS[0] / DPS[2])
    assert overall >= 0.4, (decays, orders, overall)
    # H/dp 4 (dp 0.01): <= 3 % per wavelength (measured 2.4 %; issue target 2 %)
    assert runs[2].loss_per_wavelength(2.0) <= 0.03, decays


@pytest.mark.slow
def test_at_one_smoothing_length_more_neighbours_lose_less():
    # in the closed tank the floor under the loss at fixed h/dp 2 is the particles'
    # discretisation, not the h-proportional terms (artificial viscosity, delta-SPH): at the same
    # h = 0.04 m (the same alpha c0 h and delta h c0) h/dp 3 loses less than h/dp 2. Measured (6
    # periods): 1.80 against 1.28 %/m, noise 0.10 against 0.03 % of the wave's kinetic energy
    # (docs/studies/wave_decay_study.md, "At one smoothing length, more neighbours")
    h = 0.04
    runs = [standing_wave_decay(dp=h / hdp, periods=6.0, h_over_dp=hdp) for hdp in (2.0, 3.0)]
    two, three = (r.equiv_decay_per_m for r in runs)
    assert 0.0 < three < 0.85 * two, (two, three)
    assert runs[1].noise_ke_fraction < runs[0].noise_ke_fraction, runs


def test_convergence_record_is_the_benches_summary_line():
    # decay halves when dp halves: order 1; a non-positive decay has no order
    record = convergence_record([0.02, 0.01, 0.005], [0.040004, 0.02, -0.01], "decay_per_m")
    assert list(record) == ["dp", "decay_per_m", "convergence_order"]
    assert record["decay_per_m"] == [0.04, 0.02, -0.01]
    assert record["convergence_order"] == [1.0, None]


def test_modulated_decay_reads_the_decay_under_a_beat_and_a_ripple():
    # the long flume's wave (T 1.4 s, d 0.24 m, L 1.97 m): 0.7 %/m with a 0.5 % beat of the free
    # second harmonic (period ~2.96 m) and a 0.3 % reflection ripple, gauges over 2.25 L
    k = 2 * math.pi / 1.971
    kb = beat_wavenumber(k, 1.4, 0.24)
    assert 2 * math.pi / kb == pytest.approx(2.96, abs=0.02)
    x = np.linspace(0.014, 4.48, 36)
    noise = 1e-3 * np.random.default_rng(1).standard_normal(x.size)
    ratio = np.exp(-0.007 * x + 0.005 * np.cos(kb * x + 2.0) + 0.003 * np.cos(2 * k * x + 1.0)
                   + noise)
    decay, ripple, beat = modulated_decay(x, ratio, k, kb)
    assert decay == pytest.approx(0.007, abs=5e-4)
    assert ripple == pytest.approx(0.003, abs=7e-4) and beat == pytest.approx(0.005, abs=7e-4)
    # the plain log-linear fit over the first half of the gauges reads a fifth of it (the
    # measured flume's pattern: 0.17 and 0.83 %/m over its halves)
    half = x < 2.25
    assert abs(-np.polyfit(x[half], np.log(ratio[half]), 1)[0] - 0.007) > 0.0035
    # a span shorter than the beat fits the ripple only
    assert math.isnan(modulated_decay(x[half], ratio[half], k, kb)[2])


def test_group_decays_do_not_read_the_inlets_envelope_as_decay(tmp_path):
    # the long flume's case: the wave loses 0.9 %/m while the inlet's amplitude falls 2.5 % over
    # t 8.5-12.7 s; read at one time from 12.7 s the far gauges still see the older waves
    period, cg, k, x = 1.4, 1.193, 2 * math.pi / 1.971, np.linspace(0.014, 4.43, 36)
    t = np.arange(0.0, 12.7 + 12 * period, period / 40)
    omega, decay, t0 = 2 * math.pi / period, 0.009, 12.7
    tau = t[None, :] - x[:, None] / cg
    envelope = 1.0 - 0.025 * np.clip((tau - 8.5) / 4.2, 0.0, 1.0)
    theory = np.cos(omega * t[None, :] - k * x[:, None])
    eta = envelope * np.exp(-decay * x[:, None]) * theory
    kb = beat_wavenumber(k, period, 0.24)
    along = group_decays(t, eta, theory, x, t0=t0, period=period, cg=cg, k=k, k_beat=kb)
    assert along.size == 9   # 12 periods of record, 3.7 s of them the last gauge's lag
    assert np.allclose(along, decay, atol=2e-4)
    win = slice(int(np.searchsorted(t, t0 - 1e-9)), int(np.searchsorted(t, t0 - 1e-9)) + 40)
    fixed = np.array([abs(harmonic_amplitude(t[win], e[win], omega))
                      / abs(harmonic_amplitude(t[win], th[win], omega))
                      for e, th in zip(eta, theory)])
    assert modulated_decay(x, fixed, k, kb)[0] < decay - 0.003
    # the bench's --records npz (scalars as 0-d arrays) fits again to the same figures, and an
    # earlier t0 follows the groups the window's start left out
    np.savez(tmp_path / "r.npz", t=t, x=x, eta=eta, theory=theory, t0=t0, period=period, cg=cg,
             k=k, k_beat=kb)
    rec = dict(np.load(tmp_path / "r.npz"))
    assert np.array_equal(group_decays(**rec), along)
    rec["t0"] = rec["t0"] - 3 * period
    assert np.array_equal(group_decays(**rec)[3:], along)


def test_velocity_probes_follow_the_wave_at_their_height_and_fit_along_the_groups():
    # a coarse flume (dp 0.04, two periods: one group reaches the last gauge): the probes'
    # velocity is the SPH wave's at their height, and the theory is read at the same height (the
    # model's z is measured from the still water, the scene's from the floor; read at the
    # surface, both heights would get the same theory): its orbital speed lower near the floor,
    # the SPH's the theory's within the coarse flume's loss
    from wave_client.theories import build_theory
    from wavesph.cases.wave_decay import amplitude_profile

    period, depth = 1.4, 0.24
    model = build_theory("stokes", height=0.04, period=period, depth=depth, ramp_time=period,
                         order=2)
    with pytest.raises(ValueError, match="velocity_z"):
        amplitude_profile(model, ramp=period, height=0.04, period=period, depth=depth, dp=0.04,
                          periods=1.0, velocity_z=(0.3,))
    prof = amplitude_profile(model, ramp=period, height=0.04, period=period, depth=depth,
                             dp=0.04, periods=2.0, n_gauges=4, flume_wavelengths=2.0,
                             gauge_wavelengths=0.5, velocity_z=(0.04, 0.2))
    rec, omega = {**prof.records, **prof.velocity_records}, 2 * math.pi / period
    sel = slice(int(np.searchsorted(rec["t"], rec["t0"] - 1e-9)), None)

    def amp(series):
        n = int(round(period / (rec["t"][1] - rec["t"][0])))
        return abs(harmonic_amplitude(rec["t"][sel][:n], series[sel][:n], omega))

    u, u_th = rec["u"], rec["u_theory"]
    assert u.shape == u_th.shape == (2, 4, rec["t"].size)
    assert amp(u_th[0, 0]) < amp(u_th[1, 0])        # orbital speed grows towards the surface
    for j in range(2):
        assert 0.8 < amp(u[j, 0]) / amp(u_th[j, 0]) < 1.1
    decays = prof.velocity_group_decay_per_period
    assert set(decays) == {0.04, 0.2} and all(v.size >= 1 for v in decays.values())


def test_bench_prints_an_unstable_flume_as_a_line_and_goes_on(monkeypatch, capsys):
    """bench/wave_decay.py: a dp whose flume goes unstable prints a JSON line saying so (state,
    t_stop, steps) instead of a traceback, the next dp still runs, and the exit status is 1."""
    import json
    from pathlib import Path

    from sph_core.simulation import UnstableError

    monkeypatch.syspath_prepend(str(Path(__file__).resolve().parents[2] / "bench"))
    import wave_decay as bench

    ran = []

    def fake_profile(model, *, dp, **kwargs):
        ran.append(dp)
        raise UnstableError(7828, 8.40995, "fluid particle left the tank")

    monkeypatch.setattr(bench, "amplitude_profile", fake_profile)
    assert bench.main(["--dp", "0.02", "0.01", "--scheme", "isph"]) == 1
    lines = [json.loads(x) for x in capsys.readouterr().out.splitlines()]
    assert ran == [0.02, 0.01] and [x["dp"] for x in lines] == [0.02, 0.01]
    assert lines[1]["state"] == "unstable" and lines[1]["t_stop"] == 8.41
    assert lines[1]["steps"] == 7828 and lines[1]["scheme"]["kind"] == "isph"
