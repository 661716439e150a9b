"""Verification runs shared by the tests and `bench/boussinesq.py` (one way to measure a thing).

Each returns measured figures only; the references they are judged against (Nwogu's and Airy's
dispersion relations, sqrt(g (d + H))) are applied by the callers.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import curve_fit

from .dispersion import G, nwogu_celerity
from .solitary import kdv_solitary, nwogu_solitary
from .solver import BoussinesqModel


def standing_wave_speed(kd: float, depth: float, ppw: int = 32, courant: float = 0.25,
                        periods: float = 3.0) -> float:
    """Phase speed omega/k [m/s] of a small standing wave eta = a cos(kx) cos(omega t), a = 1e-4 d,
    in a closed tank one wavelength long (the walls mirror the mode exactly), from a least-squares
    fit of the elevation series at the wall over `periods` periods."""
    k = kd / depth
    wl = 2 * np.pi / k
    m = BoussinesqModel(0.0, wl, wl / ppw, depth, courant=courant)
    a = 1e-4 * depth
    m.set_state(a * np.cos(k * m.x), np.zeros_like(m.x))
    omega0 = k * float(nwogu_celerity(kd, depth))
    n = int(round(periods * 2 * np.pi / omega0 / m.dt))
    ts, es = np.empty(n), np.empty(n)
    for i in range(n):
        m.advance_steps(1)
        ts[i], es[i] = m.t, m.eta_nodes[0]
    (omega, _, _), _ = curve_fit(lambda t, w, amp, ph: amp * np.cos(w * t + ph), ts, es, p0=[omega0, a, 0.0])
    return float(omega / k)


def solitary_run(height_ratio: float = 0.1, depth: float = 1.0, distance: float = 50.0,
                 dx_ratio: float = 0.05, samples: int = 40, profile: str = "kdv") -> dict[str, np.ndarray | float]:
    """A solitary wave over a flat bed, `distance` depths; crest tracked by a parabola through the
    three highest nodes.

    profile="kdv": the KdV-type initial profile (`solitary.kdv_solitary`), not the exact solitary
    wave of Nwogu's equations: the crest settles within the first depths of travel and sheds a
    small dispersive tail. profile="nwogu": the model's exact solitary wave
    (`solitary.nwogu_solitary`). Returns crest times [s], positions [m], heights [m], the
    reference c = sqrt(g (d + H)) and the profile's own speed c_profile.
    """
    d, height = depth, height_ratio * depth
    c = float(np.sqrt(G * (d + height)))
    x0 = 20.0 * d
    m = BoussinesqModel(0.0, x0 + distance * d + 25.0 * d, dx_ratio * d, d)
    if profile == "kdv":
        eta, u, c_profile = kdv_solitary(m.x, height, d, x0)
    elif profile == "nwogu":
        c_profile, shape = nwogu_solitary(height, d)
        eta, u = shape(m.x - x0)
    else:
        raise ValueError(f"profile must be 'kdv' or 'nwogu', got {profile!r}")
    m.set_state(eta, u)
    t_end = distance * d / c
    rec = np.empty((samples, 3))
    for i in range(samples):
        m.advance_to((i + 1) * t_end / samples)
        j = int(np.argmax(m.eta_nodes))
        a2, a1, a0 = np.polyfit(m.x[j - 1:j + 2] - m.x[j], m.eta_nodes[j - 1:j + 2], 2)
        rec[i] = (m.t, m.x[j] - a1 / (2 * a2), a0 - a1 * a1 / (4 * a2))
    return {"t": rec[:, 0], "x": rec[:, 1], "height": rec[:, 2], "c": c, "c_profile": c_profile,
            "H": height, "d": d}


def harmonics(t: np.ndarray, y: np.ndarray, omega: float, n: int = 3) -> np.ndarray:
    """Complex amplitudes A_k e^{i phi_k}, k = 1..n, of y = mean + sum A_k cos(k omega t - phi_k)
    by least squares (any record length; whole periods are not needed)."""
    t = np.asarray(t, float)
    cols = [f(k * omega * t) for k in range(1, n + 1) for f in (np.cos, np.sin)] + [np.ones_like(t)]
    c, *_ = np.linalg.lstsq(np.column_stack(cols), np.asarray(y, float), rcond=None)
    return c[0:-1:2] + 1j * c[1:-1:2]


def read_gauge_csv(path) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """(time, values[:, gauge], column names) of a gauge CSV ('#' comments, one header row)."""
    lines = [ln for ln in open(path, encoding="utf-8").read().splitlines() if ln and not ln.startswith("#")]
    header = lines[0].split(",")
    data = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]])
    return data[:, 0], data[:, 1:], header[1:]


def compare_with_measurement(scene_path, data_path, still_level: float, periods: int = 6,
                             progress: bool = False) -> dict:
    """Run a regular-wave `wavesph waves` scene and fit harmonics 1-3 at its gauges, for the model
    (its last `periods` periods) and for a measured record (gauge CSV in the scene's gauge order,
    levels above the floor: `still_level` is subtracted).

    Returns {"x": gauge positions, "model": (gauges, 3) complex amplitudes [m], "measured": same,
    "t_model", "eta_model", "t_measured", "eta_measured"}.
    """
    import tempfile
    from pathlib import Path

    from .standalone import run_wave_scene
    from .wave_scene import load_wave_scene

    scene_path = Path(scene_path)
    scene = load_wave_scene(scene_path)
    period = scene.wave.period
    omega = 2 * np.pi / period
    with tempfile.TemporaryDirectory() as tmp:
        csv = Path(tmp) / "model.csv"
        run_wave_scene(scene, csv, base_dir=scene_path.parent, progress=progress)
        tm, em, _ = read_gauge_csv(csv)
    td, ed, _ = read_gauge_csv(data_path)
    ed = ed - still_level
    if ed.shape[1] != len(scene.gauges.x):
        raise ValueError(f"{data_path}: {ed.shape[1]} gauge columns, the scene has {len(scene.gauges.x)}")
    keep = tm > tm[-1] - periods * period
    tm, em = tm[keep], em[keep]
    model = np.array([harmonics(tm, em[:, j], omega) for j in range(em.shape[1])])
    measured = np.array([harmonics(td, ed[:, j], omega) for j in range(ed.shape[1])])
    return {"x": list(scene.gauges.x), "model": model, "measured": measured, "period": period,
            "t_model": tm, "eta_model": em, "t_measured": td, "eta_measured": ed}
