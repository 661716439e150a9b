"""The 1D-horizontal Nwogu Boussinesq wave model behind the `WaveModel` contract.

Solves Nwogu's (1993) extended Boussinesq equations (z_alpha = -0.531 h) on a uniform grid with
variable depth, by the scheme of seed 001 Algorithm 1 / Wei & Kirby (1995): 4th-order finite
differences, Adams-Bashforth (3rd-order) predictor and iterated Adams-Moulton (4th-order)
corrector, a constant tridiagonal system for u_alpha factored once, internal wave generation by a
source function (Wei, Kirby & Sinha 1999), sponge layers and a Shapiro smoothing filter.
Equations and discretisation: `stepping.py`; source: `source.py`; velocity profile: `profile.py`.

Note on seed 001 Algorithm 1: its corrector line for U uses E where F belongs (a typo); we
implement the standard 4th-order Adams-Moulton corrector of Wei & Kirby (1995) for both eta and
U, and its convergence test between successive iterates (the seed compares with the predictor).

Coordinates: x [m] along the flume; z [m] up from the still-water level; the bed is at z = -h(x).
The ends of the grid are reflective walls; put sponge layers in front of them to absorb waves.
"""

from __future__ import annotations

import copy
import math
from collections import deque
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from tqdm import tqdm

from wave_client.progress_bars import TQDM_INTERVAL

from . import stepping
from .dispersion import BETA, G, nwogu_wavenumber
from .profile import reconstruct_velocity
from .source import SourceFunction, components_from_series, make_source


MEAN_SPLIT = "model"  # experiment switch: "sph" (SPH's mean u_ref) or "model"


class BoussinesqUnstableError(RuntimeError):
    """The solution became non-finite: raised with the step, time and cause."""

    def __init__(self, step: int, t: float, cause: str):
        super().__init__(f"Boussinesq model unstable at step {step} (t = {t:.6g} s): {cause}")
        self.step, self.t, self.cause = step, t, cause


@dataclass
class _Checkpoint:
    step: int
    t: float
    dt: float
    n_hist: int
    arrays: tuple[np.ndarray, ...]
    pins: dict[int, tuple[float, float]]
    free: "BoussinesqModel | None"
    recent: tuple[tuple[float, float, float], ...] = ()


def sponge_profile(x: np.ndarray, x0: float, x1: float, width_left: float, width_right: float,
                   damping: float) -> np.ndarray:
    """Damping rate w_s(x) [1/s] of the sponge layers at both ends of [x0, x1].

    w_s = damping * (exp(s^2) - 1) / (e - 1), s in [0, 1] the relative depth into the layer
    (smooth onset, so the layer itself reflects little; cf. Wei, Kirby & Sinha 1999).
    """
    w = np.zeros_like(x)
    if width_left > 0:
        s = np.clip((x0 + width_left - x) / width_left, 0.0, 1.0)
        w += damping * (np.exp(s * s) - 1.0) / (math.e - 1.0)
    if width_right > 0:
        s = np.clip((x - (x1 - width_right)) / width_right, 0.0, 1.0)
        w += damping * (np.exp(s * s) - 1.0) / (math.e - 1.0)
    return w


def _lagrange_weights(s: np.ndarray) -> np.ndarray:
    """Cubic Lagrange weights for nodes -1, 0, 1, 2 at fractional position s in [0, 1]."""
    return np.stack([
        -s * (s - 1.0) * (s - 2.0) / 6.0,
        (s + 1.0) * (s - 1.0) * (s - 2.0) / 2.0,
        -(s + 1.0) * s * (s - 2.0) / 2.0,
        (s + 1.0) * s * (s - 1.0) / 6.0,
    ])


class BoussinesqModel:
    """Nwogu Boussinesq model on [x0, x1] satisfying `wave_client.model.WaveModel`.

    Parameters
    ----------
    x0, x1, dx:
        Grid extent and spacing [m]; the node count is round((x1 - x0)/dx) + 1 (dx is adjusted).
    bathymetry:
        Still-water depth h [m]: a constant, or (x_points, depth_points) of a piecewise-linear
        profile (held constant beyond the end points). Must be > 0 everywhere (no dry land).
    dt:
        Largest time step [s] (default courant * dx / sqrt(g h_max)); `advance_to` may use a
        slightly shorter one so that windows end exactly on their times.
    sponge_left, sponge_right:
        Widths [m] of the sponge layers at the ends (0: a reflective wall).
    sponge_damping:
        Peak damping rate of the sponges [1/s]; default 1.5 * 2 pi sqrt(g h_max) / width
        (`_default_damping`).
    filter_every:
        Apply the Shapiro filter to eta and u every this many steps (0: never).
    tol, max_iter:
        Corrector convergence threshold (relative change of eta and u) and iteration cap.
    x_couple:
        The coupling boundary position [m] whose depth is `depth` (default x1).
    two_way:
        If False, `impose` is ignored (absorption-only coupling: SPH absorbs at its own inlet).
    """

    def __init__(self, x0: float, x1: float, dx: float, bathymetry: float | tuple[ArrayLike, ArrayLike],
                 *, dt: float | None = None, courant: float = 0.4, sponge_left: float = 0.0,
                 sponge_right: float = 0.0, sponge_damping: float | None = None, filter_every: int = 0,
                 tol: float = 1e-4, max_iter: int = 20, x_couple: float | None = None,
                 two_way: bool = True, beta: float = BETA, g: float = G):
        if not (x1 > x0):
            raise ValueError(f"grid: x1 ({x1}) must be greater than x0 ({x0})")
        if not dx > 0:
            raise ValueError(f"grid: dx must be > 0, got {dx}")
        nm = int(round((x1 - x0) / dx)) + 1
        if nm < 8:
            raise ValueError(f"grid: at least 8 nodes needed, got {nm} (dx = {dx} too coarse)")
        self.x0, self.x1, self.g, self.beta = float(x0), float(x1), float(g), float(beta)
        self.dx = (self.x1 - self.x0) / (nm - 1)
        self.x = self.x0 + self.dx * np.arange(nm)
        if np.isscalar(bathymetry):
            self._bx, self._bd = np.array([self.x0, self.x1]), np.full(2, float(bathymetry))
        else:
            bx, bd = (np.asarray(a, float) for a in bathymetry)
            if bx.ndim != 1 or bx.shape != bd.shape or bx.size < 1 or np.any(np.diff(bx) <= 0):
                raise ValueError("bathymetry: x must increase strictly and match depth in length")
            self._bx, self._bd = bx, bd
        h = self.depth_at(self.x)
        if np.any(h <= 0):
            raise ValueError("bathymetry: depth must be > 0 on the whole grid (no dry land)")
        self.h_nodes = h
        h_max = float(h.max())
        self.dt_max = float(dt) if dt is not None else courant * self.dx / math.sqrt(g * h_max)
        if not self.dt_max > 0:
            raise ValueError(f"dt must be > 0, got {self.dt_max}")
        self.dt = self.dt_max  # the step in use; advance_to may shorten it to end exactly on t
        self.filter_every = int(filter_every)
        self.tol, self.max_iter = float(tol), int(max_iter)
        self.two_way = bool(two_way)
        self.x_couple = self.x1 if x_couple is None else float(x_couple)
        self.depth = float(self.depth_at(self.x_couple))

        n = nm + 2 * stepping.NG
        self._n = n
        ng = stepping.NG
        pad = lambda a: np.concatenate([a[ng:0:-1], a, a[-2:-ng - 2:-1]])  # noqa: E731 (even mirror)
        self._h = pad(h)
        za = beta * self._h
        self._coef_a = (0.5 * za * za - self._h**2 / 6.0) * self._h
        self._coef_b = (za + 0.5 * self._h) * self._h
        self._a2 = 0.5 * (beta * h) ** 2
        self._b2 = beta * h
        self._sponge_widths = (float(sponge_left), float(sponge_right))
        damping = self._default_damping() if sponge_damping is None else float(sponge_damping)
        self.sponge_damping = damping
        self._sponge = pad(sponge_profile(self.x, self.x0, self.x1, sponge_left, sponge_right, damping))
        self._src_shape = np.zeros(n)
        self._src_amp = np.zeros(0)
        self._src_omega = np.zeros(0)
        self._src_phase = np.zeros(0)
        self._src_ramp = 0.0

        z = lambda: np.zeros(n)  # noqa: E731
        self._eta, self._u, self._uu = z(), z(), z()
        self._e_hist, self._f_hist = np.zeros((3, n)), np.zeros((3, n))
        self._scratch = [z() for _ in range(9)]
        self._stats = np.zeros(3)
        self._step = 0
        self._t = 0.0
        self._n_hist = 0
        self._pins: dict[int, tuple[float, float]] = {}  # coupling-boundary node -> (L, r)
        self._pin_idx, self._pin_in, self._pin_ratio = np.zeros(0, np.int64), np.zeros(0), np.zeros(0)
        self.coupling_omega: float | None = None  # frequency of the u/eta split at the boundary
        self._free: BoussinesqModel | None = None  # uncoupled twin, answers beyond the boundary
        self._recent: deque[tuple[float, float, float]] = deque()  # (t, u_ref, u_b) of impose
        self._lower, self._diag, self._upper = np.zeros(nm), np.zeros(nm), np.zeros(nm)
        self._cprime, self._minv = np.zeros(nm), np.zeros(nm)
        self._factor()
        self._refresh_rhs()

    # ------------------------------------------------------------------ set-up
    @property
    def n_nodes(self) -> int:
        return self.x.size

    @property
    def t(self) -> float:
        """Model time [s]."""
        return self._t

    @property
    def reference_level(self) -> float:
        """z_alpha = beta h [m] (up from still water) at the coupling point: the level at which SPH
        should measure the u_ref handed to `impose` (protocol WELCOME.z_ref)."""
        return self.beta * self.depth

    def depth_at(self, x: ArrayLike) -> np.ndarray:
        """Still-water depth h(x) [m] of the piecewise-linear bathymetry."""
        return np.interp(np.asarray(x, float), self._bx, self._bd)

    def _default_damping(self) -> float:
        # about 1.5 times the angular frequency of a wave one sponge width long: a round trip
        # through the layer then damps it by ~exp(-0.54 * 2 pi * 1.5) ~ 1e-2.
        width = max(self._sponge_widths)
        if width <= 0:
            return 0.0
        c = math.sqrt(self.g * float(self.h_nodes.max()))
        return 1.5 * 2.0 * math.pi * c / width

    def _factor(self) -> None:
        """Assemble and factor U = M u (rows of walls and pinned nodes are identity)."""
        nm, dx2 = self.n_nodes, self.dx * self.dx
        h = self.h_nodes
        i = np.arange(1, nm - 1)
        self._lower[:] = 0.0
        self._upper[:] = 0.0
        self._diag[:] = 1.0
        self._lower[i] = (self._a2[i] + self._b2[i] * h[i - 1]) / dx2
        self._diag[i] = 1.0 - 2.0 * (self._a2[i] + self._b2[i] * h[i]) / dx2
        self._upper[i] = (self._a2[i] + self._b2[i] * h[i + 1]) / dx2
        p = self._pin_idx
        self._lower[p], self._diag[p], self._upper[p] = 0.0, 1.0, 0.0
        stepping.thomas_factor(self._lower, self._diag, self._upper, self._cprime, self._minv)

    def _refresh_rhs(self) -> None:
        """Recompute U = M u and the newest history level from the current state (restart the
        multistep history: used after the state is set from outside)."""
        stepping.fill_ghosts(self._eta, self._u)
        stepping.close_boundary(self._eta, self._u, self._uu, self._pin_idx)
        stepping.apply_operator(self._lower, self._diag, self._upper, self._u, self._uu, stepping.NG)
        src = stepping.source_signal(self.t, self._src_amp, self._src_omega, self._src_phase, self._src_ramp)
        wq, wd = self._scratch[7], self._scratch[8]
        stepping.rhs(self._eta, self._u, self._h, self._coef_a, self._coef_b, self._sponge, self._src_shape,
              src, self.g, self.dx, wq, wd, self._e_hist[0], self._f_hist[0])
        self._n_hist = 1

    def set_state(self, eta: ArrayLike, u: ArrayLike) -> None:
        """Set eta [m] and u_alpha [m/s] on the grid nodes (e.g. an initial solitary wave)."""
        eta, u = np.asarray(eta, float), np.asarray(u, float)
        if eta.shape != self.x.shape or u.shape != self.x.shape:
            raise ValueError(f"set_state: eta and u must have shape {self.x.shape}")
        self._eta[stepping.NG:-stepping.NG] = eta
        self._u[stepping.NG:-stepping.NG] = u
        self._refresh_rhs()

    def set_source(self, source: SourceFunction) -> None:
        """Use a prepared source function (see `source.make_source`)."""
        if source.shape.shape != self.x.shape:
            raise ValueError("source: shape must be sampled on the model grid")
        self._src_shape[stepping.NG:-stepping.NG] = source.shape
        self._src_amp = np.ascontiguousarray(source.amplitude, float)
        self._src_omega = np.ascontiguousarray(source.omega, float)
        self._src_phase = np.ascontiguousarray(source.phase, float)
        self._src_ramp = source.ramp
        self._refresh_rhs()

    def _check_source_site(self, x_s: float, wavelength: float, delta: float) -> float:
        if not (self.x0 < x_s < self.x1):
            raise ValueError(f"wave.x_source = {x_s} m lies outside the grid [{self.x0}, {self.x1}]")
        half = delta * wavelength
        hs = self.depth_at(np.linspace(x_s - half, x_s + half, 21))
        if np.ptp(hs) > 1e-6 * hs.max():
            raise ValueError(f"wave.x_source = {x_s} m: the depth must be constant over the source "
                             f"width (+-{half:.3g} m) for the source amplitude to hold")
        return float(hs[0])

    def set_regular_wave(self, x_s: float, height: float, period: float, ramp_periods: float = 3.0,
                         delta: float = 0.5, phase: float = 0.0) -> None:
        """Generate regular waves eta = H/2 cos(2 pi t / T - phase) radiating from x_s."""
        if not height > 0 or not period > 0:
            raise ValueError("wave: height and period must be > 0")
        omega = 2.0 * math.pi / period
        wl = 2.0 * math.pi / self._k(omega, x_s)
        d = self._check_source_site(x_s, wl, delta)
        self.coupling_omega = omega
        self.set_source(make_source(self.x, x_s, d, np.array([height / 2]), np.array([omega]),
                                    np.array([phase]), wl, delta, ramp_periods * period,
                                    self.beta, self.g))

    def set_series_wave(self, x_s: float, t: ArrayLike, eta: ArrayLike, ramp: float = 0.0,
                        delta: float = 0.5, kd_max: float = 3.0) -> None:
        """Generate the elevation series eta(t) [m] (uniform t, periodic over its duration) at x_s.

        The Gaussian width follows the wavelength of the most energetic component.
        """
        d = float(self.depth_at(x_s))
        a, omega, phi = components_from_series(np.asarray(t, float), np.asarray(eta, float), d, kd_max,
                                               self.beta, self.g)
        if a.size == 0:
            raise ValueError("wave series: no component within the model's dispersion range")
        wl = 2.0 * math.pi / float(nwogu_wavenumber(omega[np.argmax(a)], d, self.beta, self.g))
        d = self._check_source_site(x_s, wl, delta)
        self.coupling_omega = float(omega[np.argmax(a)])
        self.set_source(make_source(self.x, x_s, d, a, omega, phi, wl, delta, ramp, self.beta, self.g))

    def _k(self, omega: float, x: float) -> float:
        return float(nwogu_wavenumber(omega, float(self.depth_at(x)), self.beta, self.g))

    # ------------------------------------------------------------------ time stepping
    def advance_steps(self, n_steps: int) -> None:
        """Advance n_steps time steps; raises BoussinesqUnstableError on a non-finite state."""
        if n_steps <= 0:
            return
        if self._free is not None:
            self._free.advance_steps(n_steps)
        s = self._scratch
        res = stepping.advance_steps(
            n_steps, self.t, self.dt, self._n_hist, self.tol, self.max_iter, self.filter_every, self._step,
            self._eta, self._u, self._uu, self._e_hist, self._f_hist,
            self._h, self._coef_a, self._coef_b, self._lower, self._diag, self._upper,
            self._cprime, self._minv, self._sponge, self._src_shape, self._src_amp, self._src_omega,
            self._src_phase, self._src_ramp, self.g, self.dx,
            self._pin_idx, self._pin_in, self._pin_ratio,
            s[0], s[1], s[2], s[3], s[4], s[5], s[6], s[7], s[8], self._stats)
        if res < 0:
            self._step += -res
            self._t += -res * self.dt
            raise BoussinesqUnstableError(self._step, self.t, "non-finite elevation or velocity")
        self._step += n_steps
        self._t += n_steps * self.dt
        self._n_hist = res

    def advance_to(self, t: float, progress: bool = False) -> None:
        """Advance to exactly time t [s].

        If the interval to t is not a whole number of steps, the step becomes interval/n with
        n = ceil(interval / dt_max) and the multistep history restarts (RK4 start); with
        equal coupling windows this happens once, at the first window.
        """
        interval = float(t) - self._t
        if interval <= 1e-9 * self.dt:
            return
        n = int(round(interval / self.dt))
        if n < 1 or abs(n * self.dt - interval) > 1e-9 * self.dt:
            n = max(1, math.ceil(interval / self.dt_max * (1 - 1e-12)))
            for m in (self, self._free):
                if m is not None:
                    m.dt = interval / n
                    m._refresh_rhs()
        todo = n
        chunk = max(1, min(todo, 2000))
        with tqdm(total=todo, disable=not progress, unit="step", desc="boussinesq",
                  mininterval=TQDM_INTERVAL) as bar:
            while todo > 0:
                m = min(chunk, todo)
                self.advance_steps(m)
                todo -= m
                bar.update(m)
        self._t = float(t)  # no round-off drift across windows
        if self._free is not None:
            self._free._t = self._t

    @property
    def corrector_stats(self) -> dict[str, float]:
        """Mean and max corrector iterations per step, and the steps stopped at max_iter."""
        steps = max(self._step, 1)
        return {"mean_iterations": self._stats[0] / steps, "max_iterations": self._stats[1],
                "unconverged_steps": self._stats[2]}

    # ------------------------------------------------------------------ fields
    @property
    def eta_nodes(self) -> np.ndarray:
        """eta [m] at the grid nodes (a view)."""
        return self._eta[stepping.NG:-stepping.NG]

    @property
    def u_nodes(self) -> np.ndarray:
        """u_alpha [m/s] at the grid nodes (a view)."""
        return self._u[stepping.NG:-stepping.NG]

    def _interp(self, f_padded: np.ndarray, x: np.ndarray) -> np.ndarray:
        """Cubic Lagrange interpolation of a padded nodal field at positions x."""
        if np.any((x < self.x0 - 1e-9 * self.dx) | (x > self.x1 + 1e-9 * self.dx)):
            raise ValueError(f"x outside the model grid [{self.x0}, {self.x1}]")
        if self._pin_idx.size:
            x_b = self.x0 + self._pin_idx[-1] * self.dx
            if np.any(x > x_b + 1e-9 * self.dx):
                raise ValueError(
                    f"x = {np.max(x):.6g} m lies beyond the two-way coupling boundary x_b = {x_b:.6g} m "
                    "set by impose(): the grid beyond it is inactive")
        r = (x - self.x0) / self.dx
        j = np.clip(np.floor(r).astype(int), 0, self.n_nodes - 2)
        w = _lagrange_weights(r - j)
        jp = j + stepping.NG
        return w[0] * f_padded[jp - 1] + w[1] * f_padded[jp] + w[2] * f_padded[jp + 1] + w[3] * f_padded[jp + 2]

    def _beyond(self, x: np.ndarray) -> np.ndarray | None:
        """Mask of x beyond the two-way boundary (answered by the uncoupled twin), or None."""
        if self._free is None or not self._pin_idx.size:
            return None
        x_b = self.x0 + self._pin_idx[-1] * self.dx
        mask = x > x_b + 1e-9 * self.dx
        return mask if mask.any() else None

    def elevation(self, x: ArrayLike) -> np.ndarray:
        """eta(x) [m] above the still-water level at self.t (cubic interpolation).

        Beyond a two-way coupling boundary (inside the SPH zone) the model reports its free,
        uncoupled field there (the incident wave it predicts: the reference of the seed 002
        mismatch), computed by a twin that never received SPH data.
        """
        x = np.asarray(x, float)
        beyond = self._beyond(x)
        if beyond is None:
            return self._interp(self._eta, x)
        out = np.empty(x.shape)
        out[beyond] = self._free.elevation(x[beyond])
        out[~beyond] = self._interp(self._eta, x[~beyond])
        return out

    def velocity(self, x: ArrayLike, z: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """(u, w) [m/s] at (x, z), z up from the still-water level, from Nwogu's profile.

        See `profile.reconstruct_velocity`. z is clipped to [-h(x), eta(x)]: above the surface
        the surface value is returned, below the bed the bed value.
        """
        x, z = np.broadcast_arrays(np.asarray(x, float), np.asarray(z, float))
        beyond = self._beyond(x)
        if beyond is not None:
            u_out, w_out = np.empty(x.shape), np.empty(x.shape)
            u_out[beyond], w_out[beyond] = self._free.velocity(x[beyond], z[beyond])
            if (~beyond).any():
                u_out[~beyond], w_out[~beyond] = self.velocity(x[~beyond], z[~beyond])
            return u_out, w_out
        dx = self.dx
        u = self._u
        hu = self._h * u
        d1 = lambda f: (f[2:] - f[:-2]) / (2 * dx)  # noqa: E731 (padded index 1..n-2)
        d2 = lambda f: (f[2:] - 2 * f[1:-1] + f[:-2]) / (dx * dx)  # noqa: E731

        def padded(a: np.ndarray) -> np.ndarray:
            out = np.zeros(self._n)
            out[1:-1] = a
            return out

        ua = self._interp(u, x)
        ux = self._interp(padded(d1(u)), x)
        uxx = self._interp(padded(d2(u)), x)
        hux = self._interp(padded(d1(hu)), x)
        huxx = self._interp(padded(d2(hu)), x)
        h = self.depth_at(x)
        eta = self._interp(self._eta, x)
        zc = np.clip(z, -h, eta)
        return reconstruct_velocity(zc, h, ua, ux, uxx, hux, huxx, self.beta)

    # ------------------------------------------------------------------ coupling
    def impose(self, x: float, eta: float, u_ref: float) -> None:
        """Two-way feedback (seed 001 Alg. 2, line 4): the elevation eta [m] and velocity u_ref
        [m/s] measured by SPH at x become the right-hand boundary of the model for the
        following steps.

        The grid node nearest x, b, ends the active grid (ghosts beyond: `stepping.close_boundary`;
        further right the grid is inactive). It is a characteristic boundary (`stepping.apply_pins`):
        the model keeps its own outgoing, right-going wave there and takes from SPH only the
        incoming, left-going part L = (eta - u_ref / r) / 2, r = u/eta of a progressive wave
        (linear Nwogu, at `coupling_omega`: the generated wave's (peak) frequency; long-wave
        r = sqrt(g/h) if none). So the model at b carries the far-field incident wave plus the
        reflection SPH saw, and driving SPH's inlet from b is not a closed loop. u_ref is the
        velocity at the reference depth z_alpha = beta h, the model's own variable. A later call
        moves the boundary if x differs. Beyond the boundary `elevation`/`velocity` answer from
        an uncoupled twin of the model (started at the first call), i.e. the model's own
        incident-wave prediction inside the SPH zone. Ignored when the model was built with
        two_way=False (absorption-only coupling).
        """
        if not self.two_way:
            return
        i = int(round((float(x) - self.x0) / self.dx))
        if not (4 <= i <= self.n_nodes - 3):
            raise ValueError(f"impose: x = {x} m must lie inside the grid, at least 4 nodes from x0 "
                             f"and 2 from x1 ([{self.x0}, {self.x1}])")
        if not (math.isfinite(eta) and math.isfinite(u_ref)):
            raise ValueError(f"impose: eta ({eta}) and u_ref ({u_ref}) must be finite")
        r = self.progressive_ratio(float(self.h_nodes[i]))
        if self._free is None:  # the uncoupled twin starts from the state before any feedback
            self._free = copy.deepcopy(self)
        moved = i not in self._pins
        u_split = self._mean_corrected_velocity(float(u_ref), float(self.u_nodes[i]), moved)
        self._pins = {i: (0.5 * (float(eta) - u_split / r), r)}
        self._sync_pins(refactor=moved)

    def _mean_corrected_velocity(self, u_ref: float, u_model: float, restart: bool) -> float:
        """SPH's velocity with its mean over the last wave period replaced by the model's own at
        the boundary (MEAN_SPLIT; see `impose`)."""
        if MEAN_SPLIT == "sph" or self.coupling_omega is None:
            return u_ref
        if restart:
            self._recent.clear()
        period = 2.0 * math.pi / self.coupling_omega
        self._recent.append((self.t, u_ref, u_model))
        while self._recent and self._recent[0][0] <= self.t - period * (1.0 - 1e-9):
            self._recent.popleft()
        n = len(self._recent)
        u_sph_mean = sum(v[1] for v in self._recent) / n
        u_model_mean = sum(v[2] for v in self._recent) / n
        return u_ref - u_sph_mean + u_model_mean

    def progressive_ratio(self, h: float) -> float:
        """u_alpha / eta [1/s] of a linear progressive Nwogu wave at `coupling_omega` in depth h:
        g k / (omega (1 - alpha (kh)^2)); sqrt(g/h) (long waves) when no frequency is known."""
        if self.coupling_omega is None:
            return math.sqrt(self.g / h)
        w = self.coupling_omega
        k = float(nwogu_wavenumber(w, h, self.beta, self.g))
        al = 0.5 * self.beta**2 + self.beta
        return self.g * k / (w * (1.0 - al * (k * h) ** 2))

    def _sync_pins(self, refactor: bool) -> None:
        idx = np.array(sorted(self._pins), dtype=np.int64)
        self._pin_idx = idx
        self._pin_in = np.array([self._pins[i][0] for i in idx], float)
        self._pin_ratio = np.array([self._pins[i][1] for i in idx], float)
        if refactor:
            self._factor()
            self._refresh_rhs()

    def checkpoint(self) -> _Checkpoint:
        """An exact copy of the state, for the protocol's `goback`."""
        arrays = (self._eta.copy(), self._u.copy(), self._uu.copy(), self._e_hist.copy(),
                  self._f_hist.copy(), self._stats.copy())
        return _Checkpoint(self._step, self._t, self.dt, self._n_hist, arrays, dict(self._pins),
                           copy.deepcopy(self._free), tuple(self._recent))

    def restore(self, cp: _Checkpoint) -> None:
        """Return to a state saved by `checkpoint`."""
        refactor = set(cp.pins) != set(self._pins)
        self._pins = dict(cp.pins)
        self._sync_pins(refactor)
        for dst, src in zip((self._eta, self._u, self._uu, self._e_hist, self._f_hist, self._stats), cp.arrays):
            dst[...] = src
        self._step, self._t, self.dt, self._n_hist = cp.step, cp.t, cp.dt, cp.n_hist
        self._free = copy.deepcopy(cp.free)
        self._recent = deque(cp.recent)

