"""wavesph.cases.particle_noise: the local-fit noise measure sees particle-scale velocity noise and not a
smooth wave field resolved by ~100 particles per wavelength."""

import numpy as np

from wavesph.cases.particle_noise import binned_noise, noise_energy


def _wave_lattice(dp: float = 0.02, length: float = 2.0, depth: float = 0.24):
    xs, zs = np.arange(dp / 2, length, dp), np.arange(dp / 2, depth, dp)
    x, z = (a.ravel() for a in np.meshgrid(xs, zs))
    k, omega, a = 2 * np.pi / 1.99, 4.488, 0.02   # the wave of bench/wave_decay.py
    u = a * omega * np.cosh(k * z) / np.sinh(k * depth) * np.cos(k * x)
    w = a * omega * np.sinh(k * z) / np.sinh(k * depth) * np.sin(k * x)
    return x, z, u, w, np.full(x.size, 1000.0 * dp * dp), 0.5 * 1000.0 * 9.81 * a * a * length


def test_smooth_wave_field_has_no_noise_and_white_noise_is_recovered():
    x, z, u, w, m, energy = _wave_lattice()
    smooth = noise_energy(x, z, u, w, m, 0.02).sum() / energy
    assert smooth < 1e-5, smooth        # the fit's truncation on a linear wave
    rng = np.random.default_rng(3)
    s = 0.02 * 0.02 * 4.488             # 2 % of the orbital speed, per component
    du, dw = s * rng.standard_normal(x.size), s * rng.standard_normal(x.size)
    true = np.sum(0.5 * m * (du * du + dw * dw)) / energy
    got = noise_energy(x, z, u + du, w + dw, m, 0.02).sum() / energy
    # the fit takes up ~6 of each particle's 40 neighbours' worth: 80-95 % of white noise is seen
    assert 0.75 * true < got < 1.0 * true, (got, true)


def test_binned_noise_sums_per_bin():
    x = np.array([0.1, 0.2, 0.6, 0.9])
    e = np.array([1.0, 2.0, 3.0, 4.0])
    assert np.allclose(binned_noise(x, e, np.array([0.0, 0.5, 1.0])), [3.0, 7.0])
