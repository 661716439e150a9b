"""Wave-record analysis: RMSE against theory, reflection coefficient (flume validation), and the
post-processing of a run (wave height and period per gauge, mean overtopping discharge, run-up
Ru2%, load peaks: ``wave_statistics``, ``mean_overtopping``, ``runup_statistics``, ``peaks``,
``analyse_run``; the command `wavesph analyse RUN_DIR`; the design formulas they are compared
with are in ``wavesph.eurotop``).

Reflection by least squares over two or more gauges (Goda & Suzuki 1976 for two gauges;
Mansard & Funke 1980 for more): at the angular frequency omega each gauge j's complex amplitude
    A_j = (2/N) sum_n eta_j(t_n) exp(-i omega t_n)     (over a whole number of periods)
is fitted by an incident and a reflected progressive wave,
    A_j = a_I exp(-i k x_j) + a_R exp(+i k x_j),
and the reflection coefficient is K_R = |a_R| / |a_I|. Gauge spacing must avoid multiples of
half a wavelength (the 2 x 2 system is singular there); L/4 is best.

A coarse SPH flume damps its waves (case V at H/dp = 3: amplitude -7 % per metre), and a decaying
incident wave fitted with constant amplitudes reads as reflection: 6.5 % from mid-flume and L/8
either side where the decay-aware fit over 9 gauges within L/4 of it gives 4.0 % (same run). With
``decay=True`` both waves decay along their direction of travel at one rate delta [1/m],
    A_j = a_I exp(-(i k + delta) x_j) + a_R exp(+(i k + delta) x_j),   x_j from the array centre,
delta chosen by least squares too, and K_R is the ratio at the centre of the gauge array.

Per harmonic (``separate_harmonics``): the n-th harmonic n omega of the records is separated the
same way with the wavenumber the caller gives for it: n k for the bound harmonics of a steady
nonlinear wave (they travel at the fundamental's phase speed), the linear-dispersion k(n omega)
for free waves (e.g. spurious harmonics emitted by a boundary). Mansard & Funke (1980) fit the
same least squares with a residual ("noise") term: uncorrelated noise adds only to the residual
returned here. ``reflected_wave`` turns a separation's reflected first harmonic into a record at one
position, to take it out of a measured one.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy.optimize import minimize_scalar


def group_velocity(wavelength: float, period: float, depth: float) -> float:
    """Linear group velocity [m/s] of a wave of ``wavelength`` and ``period`` in ``depth``."""
    kd = 2.0 * math.pi / wavelength * depth
    return 0.5 * (wavelength / period) * (1.0 + 2.0 * kd / math.sinh(2.0 * kd))


def rmse_over_height(eta: np.ndarray, eta_theory: np.ndarray, height: float) -> float:
    """sqrt(mean((eta - eta_theory)^2)) / H.

    A dry sample (NaN) has no elevation to compare, and any stand-in value would be arbitrary:
    dry or non-finite samples raise ValueError (a gauge mid-flume must stay wet)."""
    eta = np.asarray(eta, dtype=float)
    eta_theory = np.asarray(eta_theory, dtype=float)
    if eta.shape != eta_theory.shape or eta.size == 0:
        raise ValueError(f"eta: shape {eta.shape} does not match eta_theory {eta_theory.shape}")
    if not np.all(np.isfinite(eta)):
        raise ValueError(f"eta: {int(np.sum(~np.isfinite(eta)))} dry or non-finite samples")
    return float(np.sqrt(np.mean((eta - eta_theory) ** 2)) / height)


def harmonic_amplitude(t: np.ndarray, eta: np.ndarray, omega: float) -> complex:
    """Complex amplitude A of the component Re(A exp(i omega t)) of a uniformly sampled record
    spanning a whole number of periods (the caller trims it)."""
    t = np.asarray(t, dtype=float)
    eta = np.asarray(eta, dtype=float) - np.mean(eta)
    return complex(2.0 / t.size * np.sum(eta * np.exp(-1j * omega * t)))


def _separate(amp: np.ndarray, xs: np.ndarray, k: float, delta: float
              ) -> tuple[complex, complex, float]:
    """Least squares (a_I, a_R, residual norm) of
    A_j = a_I exp(-(i k + delta) x_j) + a_R exp((i k + delta) x_j)."""
    a = np.stack([np.exp(-(1j * k + delta) * xs), np.exp((1j * k + delta) * xs)], axis=1)
    (a_i, a_r), *_ = np.linalg.lstsq(a, amp, rcond=None)
    return complex(a_i), complex(a_r), float(np.linalg.norm(a @ np.array([a_i, a_r]) - amp))


@dataclass(frozen=True)
class Separation:
    """Incident and reflected components of one harmonic (amplitudes [m] and phases [rad] of
    Re(a exp(i omega t)) at the array centre with ``decay``, else at x = 0), the fitted decay
    rate [1/m] (0 without ``decay``) and the least-squares residual norm [m]."""

    harmonic: int
    kr: float
    a_incident: float
    a_reflected: float
    phase_incident: float
    phase_reflected: float
    decay: float
    residual: float


def _whole_periods(t: np.ndarray, etas: np.ndarray, xs: np.ndarray, period: float,
                   n_gauges: int) -> int:
    """Checks the records; returns the sample count spanning the most whole periods."""
    if etas.shape != (xs.size, t.size) or xs.size < n_gauges:
        raise ValueError(f"etas: expected shape ({xs.size}, {t.size}) with >= {n_gauges} "
                         f"gauges, got {etas.shape}")
    if not np.all(np.isfinite(etas)):
        raise ValueError("etas: records contain dry or non-finite samples")
    dt = t[1] - t[0]
    n_per = math.floor((t[-1] - t[0] + dt) / period + 1e-9)
    if n_per < 1:
        raise ValueError(f"t: records shorter than one period ({period} s)")
    return int(round(n_per * period / dt))


def separate_harmonics(t: np.ndarray, etas: np.ndarray, xs: np.ndarray, period: float,
                       wavenumbers: list[float] | np.ndarray, decay: bool = False
                       ) -> list[Separation]:
    """Incident/reflected separation of harmonics 1..len(wavenumbers) of records
    ``etas[j, :]`` at gauge positions ``xs[j]`` [m] (uniform ``t``, trimmed to whole periods).

    ``wavenumbers[n - 1]``: the wavenumber [1/m] of harmonic n (see the module docstring).
    Two gauges suffice without ``decay`` (Goda & Suzuki 1976), three or more with it (the
    decay rate is fitted per harmonic). Gauge spacings near a multiple of half the harmonic's
    wavelength make its fit ill-conditioned."""
    t = np.asarray(t, dtype=float)
    etas = np.atleast_2d(np.asarray(etas, dtype=float))
    xs = np.asarray(xs, dtype=float)
    m = _whole_periods(t, etas, xs, period, 3 if decay else 2)
    omega = 2.0 * math.pi / period
    out = []
    for n, k in enumerate(np.asarray(wavenumbers, dtype=float), start=1):
        amp = np.array([harmonic_amplitude(t[:m], e[:m], n * omega) for e in etas])
        dl = 0.0
        x = xs
        if decay:
            x = xs - 0.5 * (xs.min() + xs.max())
            # residual vs delta is smooth with one minimum for |delta| well below k (a decay by
            # e over a wavelength/(2 pi) is far beyond any usable flume)
            fit = minimize_scalar(lambda d: _separate(amp, x, k, d)[2], bounds=(-0.5 * k, 0.5 * k),
                                  method="bounded", options={"xatol": 1e-6 * k})
            dl = float(fit.x)
        a_i, a_r, res = _separate(amp, x, k, dl)
        out.append(Separation(n, float(abs(a_r) / abs(a_i)), float(abs(a_i)), float(abs(a_r)),
                              float(np.angle(a_i)), float(np.angle(a_r)), dl, res))
    return out


def reflection_coefficient(t: np.ndarray, etas: np.ndarray, xs: np.ndarray, period: float,
                           k: float, decay: bool = False) -> tuple[float, float, float]:
    """(K_R, |a_I|, |a_R|) of the first harmonic (``separate_harmonics``) from records
    ``etas[j, :]`` at gauge positions ``xs[j]`` [m]; with ``decay`` (>= 3 gauges) the
    amplitudes are those at the centre of the gauge array."""
    s = separate_harmonics(t, etas, xs, period, [k], decay=decay)[0]
    return s.kr, s.a_incident, s.a_reflected


def reflected_wave(s: Separation, t: np.ndarray, period: float, k: float, x: float) -> np.ndarray:
    """The reflected wave of a first-harmonic ``Separation`` (``separate_harmonics`` without
    decay, with wavenumber ``k``) at position ``x`` [m] over ``t``: subtracted from a record at x
    it leaves the incident wave and the harmonics, e.g. to score a flume against a reference
    whose end reflects differently."""
    omega = 2.0 * math.pi / period
    return s.a_reflected * np.cos(omega * np.asarray(t, dtype=float) + k * x + s.phase_reflected)


# ---------------------------------------------------------------------------- post-processing
# What an engineer reads off a run: wave height and period per gauge, the mean overtopping
# discharge, force and pressure peaks. Functions of (t, series) arrays, and ``analyse_run`` on a
# run directory (`wavesph analyse RUN_DIR`).

@dataclass(frozen=True)
class WaveStats:
    """Wave statistics of one elevation record [m, s].

    Hm0 = 4 sqrt(m0), m0 the variance of eta about its mean (the spectrum's zeroth moment);
    Tp = 1 / the frequency of the periodogram's peak; from the zero-down-crossing waves
    (each wave from one down-crossing of the mean level to the next, its height max - min):
    H1_3 the mean of the highest third of heights, Hmax the highest, Tm the mean period.
    H1_3, Hmax and Tm are None without one whole wave."""

    Hm0: float
    Tp: float
    H1_3: float | None
    Hmax: float | None
    Tm: float | None
    n_waves: int
    t_from: float
    t_to: float


def _window(t: np.ndarray, y: np.ndarray, t_from: float | None, what: str
            ) -> tuple[np.ndarray, np.ndarray]:
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    if t.shape != y.shape or t.ndim != 1:
        raise ValueError(f"{what}: t and the series differ in shape ({t.shape}, {y.shape})")
    sel = t >= (t[0] if t_from is None else t_from) - 1e-12
    t, y = t[sel], y[sel]
    if t.size < 3:
        raise ValueError(f"{what}: fewer than 3 samples after t = {t_from} s")
    return t, y


def wave_statistics(t: np.ndarray, eta: np.ndarray, t_from: float | None = None) -> WaveStats:
    """WaveStats of the record ``eta(t)`` [m] from ``t_from`` [s] on (skip the start-up ramp).

    The record must be uniformly sampled (a probe's probe_every, a coupled run's windows) and
    wet: a dry sample (NaN) raises ValueError, as no stand-in height would be right."""
    t, eta = _window(t, eta, t_from, "eta")
    if not np.all(np.isfinite(eta)):
        raise ValueError(f"eta: {int(np.sum(~np.isfinite(eta)))} dry or non-finite samples "
                         "(a gauge that runs dry has no wave height)")
    dt = np.diff(t)
    if np.ptp(dt) > 1e-6 * max(float(np.mean(dt)), 1e-300) + 1e-9:
        raise ValueError("t: the record is not uniformly sampled")
    e = eta - eta.mean()
    hm0 = 4.0 * float(np.sqrt(np.mean(e ** 2)))
    spec = np.abs(np.fft.rfft(e)) ** 2
    freq = np.fft.rfftfreq(e.size, float(np.mean(dt)))
    k = 1 + int(np.argmax(spec[1:]))     # not the mean (f = 0)
    tp = float(1.0 / freq[k])
    # zero-down-crossings: e >= 0 then < 0; crossing time by linear interpolation
    i = np.flatnonzero((e[:-1] >= 0.0) & (e[1:] < 0.0))
    tc = t[i] + e[i] / (e[i] - e[i + 1]) * (t[i + 1] - t[i])
    heights = np.array([e[a:b + 1].max() - e[a:b + 1].min() for a, b in zip(i[:-1], i[1:])])
    if heights.size == 0:
        return WaveStats(hm0, tp, None, None, None, 0, float(t[0]), float(t[-1]))
    top = np.sort(heights)[::-1][:max(1, heights.size // 3)]
    return WaveStats(hm0, tp, float(top.mean()), float(heights.max()), float(np.mean(np.diff(tc))),
                     int(heights.size), float(t[0]), float(t[-1]))


def mean_overtopping(t: np.ndarray, volume: np.ndarray, t_from: float | None = None) -> float:
    """Mean overtopping discharge q [m^2/s] (per metre of width) from ``t_from`` [s] to the
    record's end: the change of an overtopping probe's cumulative ``<name>_volume`` [m^3/m]
    over the time between."""
    t, v = _window(t, volume, t_from, "volume")
    ok = np.isfinite(v)
    if ok.sum() < 2:
        raise ValueError("volume: fewer than 2 recorded samples")
    t, v = t[ok], v[ok]
    return float((v[-1] - v[0]) / (t[-1] - t[0]))


@dataclass(frozen=True)
class RunupStats:
    """Run-up of one shoreline record [m above still water]: Ru2 the level that 2 % of the
    incident waves' run-ups exceed (EurOtop's Ru2%), Rmax the highest, n_events the run-up events
    (maxima between up-crossings of the record's mean), n_waves the incident waves counted."""

    Ru2: float
    Rmax: float
    n_events: int
    n_waves: int


def runup_statistics(t: np.ndarray, rise: np.ndarray, t_from: float | None = None,
                     n_waves: int | None = None) -> RunupStats:
    """RunupStats of ``rise(t)``, a run-up probe's shoreline elevation minus the still-water
    level [m], from ``t_from`` [s] on. Each run-up event is the highest sample between two
    up-crossings of the record's mean (a swash that stays above the mean merges with its
    neighbour: only the high events are told apart, which are the ones Ru2 ranks). Ru2 is the
    event maximum of rank ceil(0.02 n_waves) from the top, with n_waves the incident waves (a
    toe gauge's wave count: EurOtop's definition); without it, the events' own count. Samples
    with no shoreline (NaN) are left out."""
    t, r = _window(t, rise, t_from, "rise")
    ok = np.isfinite(r)
    if ok.sum() < 3:
        raise ValueError("rise: fewer than 3 recorded samples")
    t, r = t[ok], r[ok]
    e = r - r.mean()
    up = np.flatnonzero((e[:-1] < 0.0) & (e[1:] >= 0.0)) + 1
    events = np.array([r[a:b].max() for a, b in zip(up[:-1], up[1:])])
    if events.size == 0:
        raise ValueError("rise: no whole run-up event (fewer than two up-crossings of the mean)")
    n = events.size if n_waves is None else int(n_waves)
    if n < 1:
        raise ValueError(f"n_waves: must be >= 1, got {n_waves}")
    rank = min(math.ceil(0.02 * n), events.size)
    return RunupStats(float(np.sort(events)[::-1][rank - 1]), float(events.max()),
                      int(events.size), n)


@dataclass(frozen=True)
class Peaks:
    """Extremes of a load record (force [N/m], moment [N m/m] or pressure [Pa]) and, given the
    wave period, of its per-period maxima: their mean and the mean of their highest tenth."""

    max: float
    t_max: float
    min: float
    t_min: float
    mean: float
    mean_of_period_maxima: float | None = None
    highest_tenth_mean: float | None = None
    n_periods: int = 0


def peaks(t: np.ndarray, y: np.ndarray, t_from: float | None = None,
          period: float | None = None) -> Peaks:
    """Peaks of ``y(t)`` from ``t_from`` [s] on; with ``period`` [s], also per-period maxima
    (whole periods from the first sample; the last partial period left out). Empty samples
    (NaN: no fluid near a pressure point) are left out."""
    t, y = _window(t, y, t_from, "series")
    ok = np.isfinite(y)
    if not ok.any():
        raise ValueError("series: no recorded sample")
    t, y = t[ok], y[ok]
    i, j = int(np.argmax(y)), int(np.argmin(y))
    per_max = per_tenth = None
    n = 0
    if period is not None:
        if not period > 0:
            raise ValueError(f"period: must be > 0 s, got {period}")
        n = int((t[-1] - t[0]) // period)
        maxima = [y[(t >= t[0] + k * period) & (t < t[0] + (k + 1) * period)] for k in range(n)]
        maxima = np.array([m.max() for m in maxima if m.size])
        n = int(maxima.size)
        if n:
            top = np.sort(maxima)[::-1][:max(1, n // 10)]
            per_max, per_tenth = float(maxima.mean()), float(top.mean())
    return Peaks(float(y[i]), float(t[i]), float(y[j]), float(t[j]), float(y.mean()),
                 per_max, per_tenth, n)


RUN_CSVS = ("probes.csv", "gauges.csv", "sph/probes.csv")   # a `wavesph run` dir, a server run's


def analyse_run(run_dir: str | Path, t_from: float | None = None,
                period: float | None = None) -> dict[str, Any]:
    """Every gauge of a run directory, analysed: {"waves": {gauge: WaveStats fields},
    "overtopping": {probe: {"q_m2_s": ...}}, "loads": {column: Peaks fields}, "skipped":
    {column: why}, "files": [...]}. Elevation from ``<g>_eta`` columns (gauges.csv first, then
    probes.csv), overtopping from ``<name>_volume``, loads from force (``_fx``, ``_fz``,
    ``_my``) and pressure-line (``_p<k>``) columns."""
    from sph_core.output import load_gauges

    run_dir = Path(run_dir)
    files = [run_dir / f for f in RUN_CSVS if (run_dir / f).is_file()]
    if not files:
        raise ValueError(f"{run_dir}: no {', '.join(RUN_CSVS)} here (a run directory of "
                         "`wavesph run` or of the server)")
    out: dict[str, Any] = {"files": [str(f.relative_to(run_dir)) for f in files], "t_from": t_from,
                           "period": period, "waves": {}, "overtopping": {}, "runup": {},
                           "loads": {}, "skipped": {}}
    shorelines: list[tuple[str, np.ndarray, np.ndarray]] = []
    for f in files:
        cols = load_gauges(f)
        t = cols.get("t")
        if t is None or t.size < 3:
            continue
        for name, y in cols.items():
            try:
                if name.endswith("_eta") and name[:-4] not in out["waves"]:
                    out["waves"][name[:-4]] = asdict(wave_statistics(t, y, t_from))
                elif name.endswith("_volume"):
                    out["overtopping"][name[:-7]] = {"q_m2_s": mean_overtopping(t, y, t_from)}
                elif name.endswith("_z") and name[:-2] + "_R" in cols:   # a run-up probe
                    shorelines.append((name[:-2], t, y))
                elif _is_load(name) and name not in out["loads"]:
                    out["loads"][name] = asdict(peaks(t, y, t_from, period))
            except ValueError as exc:
                out["skipped"][name] = str(exc)
    # run-up counts the incident waves of the first elevation gauge (put the toe gauge first)
    n_waves = next((w["n_waves"] for w in out["waves"].values() if w["n_waves"]), None)
    swl = _still_water_level(run_dir) if shorelines else None
    for name, t, z in shorelines:
        if swl is None:
            out["skipped"][name + "_z"] = "no still_water_level in the run's meta.json"
            continue
        try:
            out["runup"][name] = asdict(runup_statistics(t, z - swl, t_from, n_waves))
        except ValueError as exc:
            out["skipped"][name + "_z"] = str(exc)
    return out


def _still_water_level(run_dir: Path) -> float | None:
    """The scene's still-water level from the run's meta.json (`wavesph run`, or a server
    run's sph/), None if neither names one."""
    for meta in (run_dir / "meta.json", run_dir / "sph" / "meta.json"):
        try:
            swl = json.loads(meta.read_text())["config"].get("still_water_level")
        except (OSError, ValueError, KeyError, AttributeError):
            continue
        if swl is not None:
            return float(swl)
    return None


def _is_load(name: str) -> bool:
    stem, _, q = name.rpartition("_")
    return bool(stem) and (q in ("fx", "fz", "my") or (q[:1] == "p" and q[1:].isdigit()))
