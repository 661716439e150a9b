"""Physics of the client's seed 002 correction: does it actually absorb a reflected wave?

The "SPH side" here is a toy 1D linear shallow-water flume (staggered grid, symplectic Euler),
driven through the sans-I/O `CouplingCore` exactly as the server would be: the inlet face
velocity is the depth mean of the SET's node velocities, interpolated linearly in time inside
each window (PROTOCOL.md, SET); a wall closes the far end; one gauge near the inlet reports eta.
The flume length is one wavelength, a resonant length for a wavemaker facing a wall.

Reference (no tuning): with an ideal absorbing wavemaker the reflected wave leaves through the
inlet, so the steady state is a standing wave of antinode amplitude 2a = H. A pure velocity
wavemaker (no correction) re-reflects it, and at resonance the amplitude grows every round trip.
The flume has no dissipation at all, so any frequency the lagged absorber amplifies grows too:
the unfiltered correction does (see `wave_client.coupling.core`), the low-passed one must not.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from protocol import Nodes, Result, Welcome, decode_frame
from wave_client.coupling import CouplingCore, CouplingOptions
from wave_client.theories import AiryWave

G, D, H, T = 9.81, 0.5, 0.02, 8.0   # long wave: kd = 0.18, shallow-water theory applies


def run_flume(options: CouplingOptions, n_periods: int) -> np.ndarray:
    """Envelope max|eta| over the flume per wave period, for the whole run."""
    model = AiryWave(H, T, D, ramp_time=2 * T)
    length = model.length
    dx = length / 200
    dt = 0.4 * dx / math.sqrt(G * D)
    eta = np.zeros(200)
    u = np.zeros(201)                     # faces; u[0] inlet, u[-1] = 0 wall
    x_c = (np.arange(200) + 0.5) * dx
    gauge = 5                              # cell of the gauge, 0.14 m from the inlet
    node_z = np.linspace(-D + 0.025, 0.0, 10)
    window = options.window
    t_end = n_periods * T
    welcome = Welcome(capabilities=0, scene_hash=bytes(32), g=G, depth=D, still_water_level=D,
                      z_ref=-0.25, t_start=0.0, t_end=t_end, dt_sph=dt, window_max=window,
                      idle_timeout=60.0, n_nodes=node_z.size, n_gauges=1, max_payload=10_000)
    nodes = Nodes(np.zeros(node_z.size), node_z, np.zeros(node_z.size, np.uint32),
                  np.array([x_c[gauge]]))
    core = CouplingCore(model, options)
    core.hello()
    core.on_welcome(1, welcome)
    core.on_nodes(2, nodes)
    u_prev, t = 0.0, 0.0
    envelope = np.zeros(n_periods)
    while core.windows_left:
        set_frame, solve_frame = core.next_window()
        _, s = decode_frame(set_frame)
        seq, _ = decode_frame(solve_frame)
        u_next = float(np.mean(s.u))      # depth-mean velocity imposed at the inlet face
        n_sub = math.ceil((s.t1 - s.t0) / dt)
        h = (s.t1 - s.t0) / n_sub
        for k in range(1, n_sub + 1):
            u[0] = u_prev + (u_next - u_prev) * k / n_sub
            u[1:-1] -= h * G * np.diff(eta) / dx
            eta -= h * D * np.diff(u) / dx
        t = s.t1
        u_prev = u_next
        period = min(int(t / T - 1e-9), n_periods - 1)
        envelope[period] = max(envelope[period], np.abs(eta).max())
        core.on_result(seq, Result(t, n_sub, eta[[gauge]], np.ones(1, np.uint32),
                                   np.array([u[gauge]]), np.zeros(1)))
    return envelope


@pytest.mark.parametrize("window", [T / 50, T / 100])  # T/50: the client's default window
def test_correction_absorbs_the_reflected_wave(window):
    env = run_flume(CouplingOptions(window=window, absorb=True), n_periods=40)
    # standing wave of antinode amplitude H (incident + one reflection), steady for 30 periods
    late = env[10:]
    assert np.all(np.abs(late - H) < 0.05 * H), late / H
    assert np.ptp(late) < 0.02 * H


def test_without_correction_the_flume_resonates():
    env = run_flume(CouplingOptions(window=T / 50), n_periods=16)
    # the wavemaker re-reflects: the amplitude keeps growing, far beyond the absorbed case
    assert env[-1] > 3 * H, env / H
    assert np.all(np.diff(env[-8:]) > 0)


def test_unfiltered_lagged_correction_amplifies_short_waves():
    # why the low-pass exists: absorbs at first, then a short-wave band grows without bound
    env = run_flume(CouplingOptions(window=T / 50, absorb=True, absorb_cutoff=math.inf),
                    n_periods=40)
    assert abs(env[5] - H) < 0.05 * H
    assert env[-1] > 10 * H, env / H


def test_incident_mismatch_ignores_the_reflected_wave_and_reads_the_inlet_deficit():
    """absorb_wave="incident" (two-way models): the mismatch is that of the right-going
    characteristic (eta + u_ref/r)/2 at the inlet gauge, so SPH's reflected wave (which the
    two-way boundary lets out itself) adds nothing, and an incident wave 10 % short reads as
    -10 % of it."""
    from types import SimpleNamespace

    r, a, k, omega = 5.0, 0.01, 2.0, 4.0

    class Progressive:
        t, depth, x_couple = 0.0, D, 0.0

        def progressive_ratio(self, h):
            return r

        def advance_to(self, t):
            self.t = t

        def elevation(self, x):
            return a * np.cos(k * np.asarray(x, float) - omega * self.t)

        def velocity(self, x, z):
            return r * self.elevation(x), np.zeros_like(np.asarray(x, float))

        def impose(self, x, eta, u_ref):
            pass

    model = Progressive()
    core = CouplingCore(model, CouplingOptions(absorb=True, absorb_wave="incident"))
    core.welcome = SimpleNamespace(depth=D, g=G, z_ref=-0.2)
    for t in np.linspace(0.0, 1.5, 7):
        model.advance_to(t)
        x = 0.3
        inc = float(model.elevation(x))
        refl = 0.3 * a * math.cos(-k * x - omega * t + 0.4)
        m = core._incident_mismatch(x, inc + refl, r * (inc - refl), inc)
        assert m == pytest.approx(0.0, abs=1e-15)
        short = core._incident_mismatch(x, 0.9 * inc + refl, r * (0.9 * inc - refl), inc)
        assert short == pytest.approx(-0.1 * inc, abs=1e-15)
