"""Open boundaries in a small flume: still water stays still, particles cross both ways with
exact bookkeeping, bad boundary data stop the run before any step, checkpoints are exact, and a
pushed-window source drives the flume exactly like the source it was sampled from. The physics
tests run for every scheme (SCHEMES: the scene's [scheme] tables; ISPH steps with its own loop,
sph_core.isph, around the same open-end hooks)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from sph_core import open_boundary as ob
from sph_core.boundary_data import BoundaryDataError, BoundaryNodes, BoundarySample
from sph_core.open_ends import flume_nodes
from sph_core.particles import AX, AZ, FLUID, INLET, OUTLET, P, X, Z
from sph_core.scene import make_scene
from sph_core.simulation import Simulation

D = 0.3          # still-water depth [m]; the tank floor is z = 0
DP = 0.02
G = 9.81
SCHEMES = {"wcsph": {}, "riemann": {"kind": "riemann"}, "isph": {"kind": "isph"}}
scheme_params = pytest.mark.parametrize("scheme", list(SCHEMES))


def flume_scene(length: float = 0.6, integrator: str = "kdk", scheme: str = "wcsph",
                **extra) -> object:
    return make_scene({"scheme": SCHEMES[scheme],
        "dp": DP, "t_end": 10.0, "still_water_level": D,
        "tank": {"x0": 0.0, "x1": length, "z0": 0.0, "z1": D + 0.12},
        "water_blocks": [{"x0": 0.0, "x1": length, "z0": 0.0, "z1": D}],
        "constants": {"c0": 10.0 * math.sqrt(G * D), "integrator": integrator},
        "open_boundaries": [{"side": "left", "elevation": "imposed"},
                            {"side": "right", "elevation": "extrapolated"}],
        **extra})


class Oscillating:
    """Uniform horizontal flow u = U sin(2 pi t / T) through both ends, still surface."""

    def __init__(self, nodes: BoundaryNodes, amplitude: float = 0.2, period: float = 1.0) -> None:
        self.nodes = nodes
        self.amplitude = amplitude
        self.period = period

    def sample(self, t: float) -> BoundarySample:
        u = self.amplitude * math.sin(2 * math.pi * t / self.period)
        return BoundarySample(t, np.full(self.nodes.size, u), np.zeros(self.nodes.size), 0.0)


@pytest.fixture(scope="module", params=list(SCHEMES))
def still_flume(request):
    fl = Simulation(flume_scene(scheme=request.param))  # no sources: the ends hold still water
    fl.advance_to(1.0)
    return fl


def test_still_water_with_open_ends_stays_still(still_flume):
    fl = still_flume
    st = fl.fluid_state()
    assert fl.n_fluid == fl.n_fluid0
    speed = np.hypot(st["vx"], st["vz"])
    assert speed.max() < 0.01 * math.sqrt(G * D)
    for side, eta in fl.boundary_gauges().items():
        assert eta is not None and abs(eta) < 0.5 * DP, side


def test_still_water_with_open_ends_is_hydrostatic(still_flume, request):
    if request.node.callspec.params["still_flume"] == "isph":
        request.applymarker(pytest.mark.xfail(strict=True, reason=(
            "ISPH: 5.8 % below rho0 g (d - z) in the lower half at 1 s (6.1-6.9 % over 0.1-0.9 "
            "s), as in its closed tank: p = 0 sits on the surface particles' centres, dp/2 below "
            "the surface "
            "(rho0 g dp/2 = 98 Pa at dp 0.02); docs/studies/schemes.md '## ISPH'. Measured, not tuned")))
    st = still_flume.fluid_state()
    low = st["z"] < 0.5 * D
    p_ref = 1000.0 * G * (D - st["z"][low])
    assert np.max(np.abs(st["p"][low] - p_ref) / p_ref) < 0.03


def test_isph_still_open_flume_stays_still_for_two_seconds():
    """ISPH's buffer particles enter div u* with u_b + dt g (the step's gravity, as the fluid's
    u* carries it) and have PPE rows of their own: with the imposed velocity itself the
    buffers at rest were a source of divergence at the surface rows and the bed, and this flume
    reached 0.98 m/s at 1.5 s and had lost 13 particles over the top by 2 s; now 7 mm/s at 2 s
    (docs/studies/schemes.md "ISPH open ends: the buffers in the projection")."""
    fl = Simulation(flume_scene(scheme="isph"))
    fl.advance_to(2.0)
    st = fl.fluid_state()
    assert fl.n_fluid == fl.n_fluid0
    assert np.hypot(st["vx"], st["vz"]).max() < 0.01 * math.sqrt(G * D)


def test_outlet_pressure_extrapolated_from_a_hydrostatic_column_is_hydrostatic():
    """The initial fluid is an exact hydrostatic column, p = rho0 g (swl - z) (Tait EOS of the
    hydrostatic density); the ghost nodes carry it into the outlet buffer to round-off, from the
    floor (fluid on one side in z) up to the surface row, where the support is cut off."""
    sc = flume_scene()
    fl = Simulation(sc)
    assert fl.open.ends.ghost[1] and not fl.open.ends.ghost[0]  # the defaults
    ps = fl.particles
    kind, z = ps.kind[: ps.n], ps.f[Z, : ps.n]
    fluid = kind == FLUID
    np.testing.assert_allclose(ps.f[P, : ps.n][fluid], 1000.0 * G * (D - z[fluid]), rtol=1e-9)
    out = kind == OUTLET
    ps.f[P, : ps.n][out] = 0.0
    ob.buffer_extrapolate(ps.view, ps.n, fl.cells, fl.open.ends, fl.prm)
    # the buffer: as many columns as the wall layers, ceil(2h/dp), up to the surface
    assert out.sum() == fl.n_layers * round(D / DP)
    np.testing.assert_allclose(ps.f[P, : ps.n][out], 1000.0 * G * (D - z[out]), rtol=1e-9,
                               atol=1e-6)


@pytest.mark.parametrize("integrator, scheme", [("kdk", "wcsph"), ("symplectic_pc", "wcsph"),
                                                ("kdk", "riemann"), ("kdk", "isph")])
def test_oscillating_flow_crosses_both_ways_with_exact_mass_balance(integrator, scheme):
    """Any integrator and scheme runs open ends: the same buffer hooks in each step skeleton."""
    sc = flume_scene(integrator=integrator, scheme=scheme)
    nodes = flume_nodes(sc)
    fl = Simulation(sc, sources={s: Oscillating(n) for s, n in nodes.items()}, window=0.02)
    capacity = fl.particles.capacity
    fl.advance_to(1.0)
    counts = fl.boundary_counts()
    for side in ("left", "right"):
        c = counts[side]
        # the flow reverses: particles enter and leave the fluid through each end
        assert c["in"] > 0 and c["out"] > 0, (side, c)
        assert c["created"] > 0 and c["removed"] > 0, (side, c)
    net = sum(c["in"] - c["out"] for c in counts.values())
    assert fl.n_fluid - fl.n_fluid0 == net
    ps = fl.particles
    ids = ps.ids[: ps.n][ps.kind[: ps.n] >= 0]
    assert np.unique(ids).size == ids.size  # identity kept across creation and removal
    assert ps.capacity == capacity  # no reallocation
    # fluid pushed into a buffer against its inflow stays fluid for at most dp
    st = fl.fluid_state()
    assert st["x"].min() >= -DP and st["x"].max() <= sc.tank.x1 + DP


def test_isph_buffers_carry_their_imposed_acceleration():
    """ISPH's buffer rows take each buffer particle's imposed acceleration into its pressure
    (Params.buffer_acceleration; isph.passes.buffer_rows): with u = U sin(omega t) through both
    ends, every buffer particle's (ax, az) after a step is the imposed velocity's change over it,
    the slope of the window's samples. WCSPH's buffers keep none (its step is unchanged).
    A particle that entered a buffer in the step still carries its fluid acceleration."""
    ends = [{"side": "left", "elevation": "imposed", "absorb": False},
            {"side": "right", "elevation": "extrapolated", "absorb": False}]
    for scheme in ("isph", "wcsph"):
        sc = flume_scene(scheme=scheme, open_boundaries=ends)
        nodes = flume_nodes(sc)
        src = {s: Oscillating(n) for s, n in nodes.items()}
        fl = Simulation(sc, sources=src, window=0.02)
        fl.advance_to(0.5)   # the last step inside the window [0.48, 0.50]
        ps = fl.particles
        buf = ps.kind[: ps.n] >= INLET
        ax, az = ps.f[AX, : ps.n][buf], ps.f[AZ, : ps.n][buf]
        assert buf.sum() > 50
        if scheme == "wcsph":   # zero but where fluid entered in the last step (its own)
            assert (ax == 0.0).mean() > 0.95 and (az == 0.0).mean() > 0.95
            continue
        u = [src["left"].sample(t).u[0] for t in (0.48, 0.50)]
        slope = (u[1] - u[0]) / 0.02
        assert slope < -1.2   # U omega cos(omega t) at t 0.49: -1.25 m/s^2
        # all but the particles that entered a buffer in the last step (they carry the fluid's)
        close = np.abs(ax - slope) < 1e-6 * abs(slope)
        assert close.mean() > 0.95, (slope, ax[~close])
        assert np.all(np.abs(az) < 1e-9)


def test_isph_relaxation_zone_pulls_the_fluid_towards_the_source():
    """Scheme.isph_relaxation_zone (open_boundary.relax_to_source): a fluid particle at rest at
    distance s < L from a face moves towards the end's source velocity by a = 1 - exp(-dt q^2 /
    tau), q = 1 - s / L; beyond L nothing changes. Here u = U sin(omega t) through both ends, the
    source's u at the window's end (0.25 s) is U; the run up to then has the zone on."""
    zone, tau, dt = 0.1, 0.2, 0.003
    ends = [{"side": "left", "elevation": "imposed", "absorb": False},
            {"side": "right", "elevation": "extrapolated", "absorb": False}]
    sc = flume_scene(scheme="isph", open_boundaries=ends)
    sc = sc.model_copy(update={"scheme": sc.scheme.model_copy(update={
        "isph_relaxation_zone": zone, "isph_relaxation_time": tau})})
    src = {s: Oscillating(n) for s, n in flume_nodes(sc).items()}
    fl = Simulation(sc, sources=src, window=0.05)
    fl.advance_to(0.25)
    ps = fl.particles
    n = ps.n
    fluid = ps.kind[:n] == FLUID
    ps.view.vx[:n][fluid] = 0.0
    ps.view.vz[:n][fluid] = 0.0
    assert not fl.open.zone.local.any()   # a source of face data only: the face's profile
    ob.relax_to_source(ps.view, n, 0.25, dt, fl.open.ends, zone, tau, fl.open.zone)
    x = ps.f[X, :n][fluid]
    s = np.minimum(x, sc.tank.x1 - x)
    q = np.where(s < 0.0, 0.0, np.clip(1.0 - s / zone, 0.0, None))   # s < 0: in a buffer's face
    expected = (1.0 - np.exp(-dt * q * q / tau)) * src["left"].sample(0.25).u[0]
    assert np.allclose(ps.view.vx[:n][fluid], expected, rtol=1e-9, atol=1e-12)
    assert np.all(ps.view.vz[:n][fluid] == 0.0)
    inside = (s >= 0.0) & (s < zone)
    assert inside.sum() > 20 and (~inside).sum() > 20
    assert np.all(ps.view.vx[:n][fluid][~inside] == 0.0)
    assert expected.max() > 0.01 * 0.2   # the pull at the face: ~1.5 % of U a step


def test_isph_relaxation_zone_pulls_towards_the_wave_where_a_model_knows_it():
    """Where an end's source is a wave model (WaveModelBoundary), the zone's target is the wave's
    own velocity at the particle (the model evaluated there, open_ends.zone_targets), not the
    face's profile: a zone 0.3 m long holds a sixth of this 1.7 m wave, whose phase turns by a
    rad across it. Checked against the model at each particle to the stations' interpolation."""
    from sph_core.boundary_data import WaveModelBoundary
    from wave_client.theories.linear import AiryWave

    zone, tau, dt, t = 0.3, 0.2, 0.003, 0.25
    sc = flume_scene(length=1.0, scheme="isph")
    sc = sc.model_copy(update={"scheme": sc.scheme.model_copy(update={
        "isph_relaxation_zone": zone, "isph_relaxation_time": tau})})
    wave = AiryWave(0.02, 1.1, D)
    src = {s: WaveModelBoundary(wave, nd, D, nd.x_face) for s, nd in flume_nodes(sc).items()}
    fl = Simulation(sc, sources=src, window=0.05)
    assert fl.open.zone.local.all() and fl.open.zone.ds <= DP
    assert fl.stepper.zone_targets is fl.open.zone
    fl.advance_to(t)
    ps = fl.particles
    n = ps.n
    fluid = ps.kind[:n] == FLUID
    ps.view.vx[:n][fluid] = 0.0
    ps.view.vz[:n][fluid] = 0.0
    ob.relax_to_source(ps.view, n, t, dt, fl.open.ends, zone, tau, fl.open.zone)
    x, z = ps.f[X, :n][fluid], ps.f[Z, :n][fluid]
    s = np.minimum(x, sc.tank.x1 - x)
    inside = (s >= 0.0) & (s < zone)
    assert inside.sum() > 100
    a = 1.0 - np.exp(-dt * (1.0 - s[inside] / zone) ** 2 / tau)
    wave.advance_to(t)
    u, w = wave.velocity(x[inside], z[inside] - D)
    vx, vz = ps.view.vx[:n][fluid][inside], ps.view.vz[:n][fluid][inside]
    scale = a * 0.01 * wave.omega / math.tanh(wave.k * D)   # a times the surface orbit speed
    # nodes, not exact heights, and stations DP apart: within 5 % of the orbit speed
    assert np.max(np.abs(vx - a * u) / scale) < 0.05
    assert np.max(np.abs(vz - a * w) / scale) < 0.05
    # the face's profile (the old target) is a wave's sixth off at the zone's end: far from it
    nd = flume_nodes(sc)["left"]
    u_face = a * np.interp(z[inside], nd.z, src["left"].sample(t).u)
    far = s[inside] > 0.2
    assert np.max(np.abs(vx - u_face)[far] / scale[far]) > 0.5
    assert np.all(ps.view.vx[:n][fluid][~inside] == 0.0)


def test_isph_relaxation_zone_takes_the_wave_given_from_outside():
    """A client that knows the wave inside the domain (a coupled run's wave model) gives it at
    the zone's columns with each window (``advance_window(zone=...)``): the zone pulls towards
    it, station 0 being the face's sample; a window without it falls back to the face's
    profile; a checkpoint keeps the window start's targets; bad shapes are refused."""
    from sph_core.boundary_data import BoundaryDataError, WaveModelBoundary
    from wave_client.theories.linear import AiryWave

    zone = 0.3
    sc = flume_scene(length=1.0, scheme="isph")
    sc = sc.model_copy(update={"scheme": sc.scheme.model_copy(update={
        "isph_relaxation_zone": zone})})
    wave = AiryWave(0.02, 1.1, D)
    nodes = flume_nodes(sc)
    src = {s: WaveModelBoundary(wave, nd, D, nd.x_face) for s, nd in nodes.items()}
    fl = Simulation(sc, window=0.05)          # fed from outside: no source of its own
    cols = fl.zone_columns
    assert set(cols) == {"left", "right"} and not fl.open.zone.local.any()
    assert np.all(np.diff(cols["left"]) > 0) and np.all(np.diff(cols["right"]) < 0)
    assert cols["left"][-1] == pytest.approx(zone) and cols["right"][-1] == pytest.approx(1 - zone)

    def given(t):
        wave.advance_to(t)
        return {s: wave.velocity(c[:, None], nodes[s].z[None, :] - D) for s, c in cols.items()}

    def window(t1, zone_data):
        fl.advance_window(t1, left=src["left"].sample(t1), right=src["right"].sample(t1),
                          zone=zone_data)

    window(0.05, given(0.05))
    z = fl.open.zone
    assert z.local.all()
    for b, s in enumerate(("left", "right")):
        u1, w1 = given(0.05)[s]
        np.testing.assert_allclose(z.u[b, 1:, 1], u1)
        np.testing.assert_allclose(z.w[b, 1:, 1], w1)
        np.testing.assert_allclose(z.u[b, 0, 1], src[s].sample(0.05).u)
        np.testing.assert_allclose(z.u[b, :, 0], z.u[b, :, 1])   # the first window holds
    saved = fl.checkpoint()
    window(0.10, given(0.10))
    np.testing.assert_allclose(z.u[0, 1:, 0], given(0.05)["left"][0])   # t0: the last t1's
    np.testing.assert_allclose(z.u[0, 1:, 1], given(0.10)["left"][0])
    z.u[:] = 0.0                               # the checkpoint, not the arrays, carries them
    fl.restore(saved)
    window(0.10, given(0.10))
    np.testing.assert_allclose(z.u[0, 1:, 0], given(0.05)["left"][0])
    window(0.15, None)
    assert not z.local.any()                   # no zone data: the face's profile
    bad = given(0.20)
    bad["left"] = (bad["left"][0][1:], bad["left"][1][1:])
    with pytest.raises(BoundaryDataError, match="left.zone.u: shape"):
        window(0.20, bad)


class Straining:
    """No flow at the faces, w = w0 + A (z - z0) at every node."""

    def __init__(self, nodes: BoundaryNodes, w0: float, rate: float, z0: float) -> None:
        self.nodes = nodes
        self.w = w0 + rate * (np.asarray(nodes.z) - z0)

    def sample(self, t: float) -> BoundarySample:
        return BoundarySample(t, np.zeros(self.nodes.size), self.w.copy(), 0.0)


@pytest.mark.parametrize("w0, rate", [(0.01, 0.0), (0.0, 0.5)])
def test_buffer_particles_move_as_the_incompressible_flow_they_carry(w0, rate):
    """A buffer particle follows the orbit whose velocity it carries, in z as in x, and the
    buffer keeps its area: with u = 0 at the face and w = A (z - z0), continuity gives
    u = -A (x - x_f) off the face, so x - x_f shrinks as exp(-A t) while z - z0 grows as
    exp(A t). Held at its height, a particle sits off its orbit by the orbit's vertical excursion
    (2-4 dp at H/dp 4-8); moved in x by the face's u alone, the buffer's density breathes with
    the wave (a spurious second-order flux through the face)."""
    z0 = D / 2
    # no absorption: its correction would move the buffer in x by what the gauges see
    sc = flume_scene(open_boundaries=[{"side": "left", "elevation": "imposed", "absorb": False},
                                      {"side": "right", "elevation": "extrapolated",
                                       "absorb": False}])
    fl = Simulation(sc, sources={s: Straining(n, w0, rate, z0)
                                 for s, n in flume_nodes(sc).items()}, window=0.02)
    faces = {ob.INLET: 0.0, ob.INLET_IDLE: 0.0, ob.OUTLET: sc.tank.x1, ob.OUTLET_IDLE: sc.tank.x1}

    def buffer_state() -> dict[int, tuple[float, float]]:
        ps = fl.particles
        k = ps.kind[: ps.n]
        sel = np.isin(k, list(faces))
        xf = np.array([faces[int(kk)] for kk in k[sel]])
        return dict(zip(ps.ids[: ps.n][sel].tolist(),
                        zip((ps.f[X, : ps.n][sel] - xf).tolist(), ps.f[Z, : ps.n][sel].tolist())))

    fl.advance_to(0.1)
    t0, s0 = fl.t, buffer_state()
    fl.advance_to(0.3)
    s1 = buffer_state()
    assert len(s0) > 0 and s1.keys() == s0.keys()  # no flow across the faces
    dx0, zz0 = np.array([s0[i] for i in s0]).T
    dx1, zz1 = np.array([s1[i] for i in s0]).T
    t = fl.t - t0
    # within the nodes and clear of the bed and the tank top (where the profile is clamped)
    inside = (zz0 > 0.03) & (zz0 < D - 0.03)
    assert inside.sum() > 10
    np.testing.assert_allclose((zz1 - z0)[inside],
                               (w0 * t + (zz0 - z0) * np.exp(rate * t))[inside], rtol=1e-3,
                               atol=1e-7)
    np.testing.assert_allclose(dx1[inside], dx0[inside] * np.exp(-rate * t), rtol=1e-3)
    if rate:   # the area (x - x_f)(z - z0) kept while each factor changed by ~10 %
        np.testing.assert_allclose((dx1 * (zz1 - z0))[inside], (dx0 * (zz0 - z0))[inside],
                                   rtol=1e-3)


@pytest.mark.parametrize("bad, match", [
    (lambda nd: BoundarySample(0.1, np.full(nd.size, np.nan), np.zeros(nd.size), 0.0),
     r"left\.u: non-finite"),
    (lambda nd: BoundarySample(0.1, np.zeros(nd.size + 1), np.zeros(nd.size + 1), 0.0),
     r"left\.u: expected \d+ values"),
    (lambda nd: BoundarySample(0.1, np.zeros(nd.size), np.zeros(nd.size), 0.2),
     r"left\.eta: surface .* outside the tank"),
])
def test_bad_boundary_data_stop_the_run_and_keep_its_data(tmp_path, bad, match):
    sc = flume_scene(output={"probe_every": 0.01},
                     probes=[{"kind": "elevation", "name": "mid", "x": 0.3}])
    fl = Simulation(sc, run_dir=tmp_path)
    fl.advance_window(0.05, left=BoundarySample(0.05, np.zeros(fl.nodes["left"].size),
                                                np.zeros(fl.nodes["left"].size), 0.0))
    before = fl.fluid_state()
    steps = fl.steps
    with pytest.raises(BoundaryDataError, match=match):
        fl.advance_window(0.1, left=bad(fl.nodes["left"]))
    assert fl.t == pytest.approx(0.05) and fl.steps == steps
    after = fl.fluid_state()
    for k in ("x", "z", "vx", "rho"):
        np.testing.assert_array_equal(before[k], after[k])
    meta = json.loads((tmp_path / "meta.json").read_text())
    assert meta["status"] == "failed" and "boundary data" in meta["cause"]
    rows = (tmp_path / "probes.csv").read_text().splitlines()
    assert len(rows) >= 6  # header + the probes of [0, 0.05] s are kept


@scheme_params
def test_checkpoint_restore_is_exact(scheme):
    sc = flume_scene(scheme=scheme)
    fl = Simulation(sc, sources={s: Oscillating(n) for s, n in flume_nodes(sc).items()})
    fl.advance_to(0.3)
    cp = fl.checkpoint()
    fl.advance_to(0.5)
    first = fl.fluid_state()
    counts = fl.boundary_counts()
    fl.restore(cp)
    assert fl.t == pytest.approx(0.3)
    fl.advance_to(0.5)
    again = fl.fluid_state()
    assert fl.boundary_counts() == counts
    for k in ("id", "x", "z", "vx", "vz", "rho"):
        np.testing.assert_array_equal(first[k], again[k])


@scheme_params
def test_pushed_windows_drive_the_flume_like_the_source_they_sample(scheme):
    """The coupled path (the server pushes each window's data) against the pulled one."""
    sc = flume_scene(scheme=scheme)
    nodes = flume_nodes(sc)
    theory = {s: Oscillating(n) for s, n in nodes.items()}
    a = Simulation(sc, sources=theory, window=0.05)
    b = Simulation(sc, window=0.05)
    for k in range(1, 9):
        t1 = 0.05 * k
        a.advance_to(t1)  # pulls theory samples at t1
        b.advance_window(t1, **{s: theory[s].sample(t1) for s in nodes})  # pushed, as the server
    sa, sb = a.fluid_state(), b.fluid_state()
    assert a.boundary_counts() == b.boundary_counts()
    for k in ("id", "x", "z", "vx", "rho"):
        np.testing.assert_array_equal(sa[k], sb[k])


@pytest.mark.parametrize("scheme", ["wcsph", "riemann", pytest.param("isph", marks=[
    pytest.mark.slow, pytest.mark.xfail(strict=True, reason=(
        "ISPH: a particle leaves over the tank top on the beach (x = 1.31 m, t = 1.389 s; the "
        "run reaches 1.5 s at 1.84 m/s, 1.498 s and unstable above the block before the buffers "
        "had PPE rows), so the count is one short: ISPH's jets (docs/studies/schemes.md "
        "'## ISPH'); measured, not tuned away"))])])
def test_inlet_with_a_beach_and_a_structure_keeps_running_and_counting(scheme):
    """Left inlet driving a shallow-water wave onto a 1:4 beach with a block on the bed; the right
    end is a wall. The run stays stable, water goes up the beach, the bookkeeping stays exact."""
    sc = make_scene({
        "dp": DP, "t_end": 10.0, "still_water_level": 0.2,
        "tank": {"x0": 0.0, "x1": 1.6, "z0": 0.0, "z1": 0.4},
        "water_blocks": [{"x0": 0.0, "x1": 1.6, "z0": 0.0, "z1": 0.2}],
        "beds": [{"points": [[0.8, 0.0], [1.6, 0.2 + 0.0]]}],
        "structures": [{"x0": 0.4, "x1": 0.5, "z0": 0.0, "z1": 0.06}],
        "constants": {"c0": 10.0 * math.sqrt(G * 0.2)},
        "open_boundaries": [{"side": "left", "elevation": "imposed"}],
        "scheme": SCHEMES[scheme],
    })
    nodes = flume_nodes(sc)["left"]
    c = math.sqrt(G * 0.2)

    class Push:
        """Shallow-water long wave entering: eta = a sin(w t), u = eta c / d (uniform)."""

        def __init__(self) -> None:
            self.nodes = nodes

        def sample(self, t: float) -> BoundarySample:
            eta = 0.02 * math.sin(2 * math.pi * t / 1.0) * min(t / 0.5, 1.0)
            return BoundarySample(t, np.full(nodes.size, eta * c / 0.2), np.zeros(nodes.size), eta)

    fl = Simulation(sc, sources={"left": Push()}, window=0.02)
    fl.advance_to(1.5)
    counts = fl.boundary_counts()["left"]
    assert counts["in"] > 0 and counts["out"] > 0
    assert fl.n_fluid - fl.n_fluid0 == counts["in"] - counts["out"]
    st = fl.fluid_state()
    # no fluid inside the block or below the beach
    inside = (st["x"] > 0.4) & (st["x"] < 0.5) & (st["z"] < 0.06)
    below = (st["x"] > 0.8) & (st["z"] < 0.25 * (st["x"] - 0.8) - 0.5 * DP)
    assert not inside.any() and not below.any()
    assert np.hypot(st["vx"], st["vz"]).max() > 0.05  # the wave is there


def test_snapshots_leave_out_idle_buffer_particles(tmp_path):
    # idle buffer particles (above the end's surface, in no pass) hung in the air in ParaView
    # and on the page: snapshots hold kinds 0-3 only
    sim = Simulation(flume_scene(), run_dir=tmp_path)
    kinds = set(sim.particles.kind[: sim.particles.n].tolist())
    assert kinds & {4, 5}, kinds          # the buffers have idle particles above the surface
    sim.write_snapshot()
    sim.close()
    snap = np.load(tmp_path / "snapshots" / "last.npz")
    assert set(snap["kind"].astype(int).tolist()) <= {0, 1, 2, 3}
    assert snap["z"][snap["kind"] >= 2].max() < D


def test_a_wide_buffer_keeps_its_columns_and_its_mass_balance():
    """``buffer_width``: the buffer is that many columns outside the face (the orbit of the
    wave at the face fits in it: docs/physics/open_boundaries.md, 'Buffer width'), and
    through-flow keeps the exact count of a narrow one."""
    sc = flume_scene(open_boundaries=[{"side": "left", "elevation": "imposed",
                                       "buffer_width": 0.25},
                                      {"side": "right", "elevation": "extrapolated"}])
    nodes = flume_nodes(sc)
    fl = Simulation(sc, sources={s: Oscillating(n) for s, n in nodes.items()}, window=0.02)
    e = fl.open.ends
    assert e.length[0] == pytest.approx(13 * DP) and e.length[1] == pytest.approx(4 * DP)
    ps = fl.particles
    left = np.isin(ps.kind[: ps.n], [ob.INLET, ob.INLET_IDLE])
    cols = np.unique(np.round(ps.f[X, : ps.n][left] / DP - 0.5))
    np.testing.assert_array_equal(cols, -np.arange(13, 0, -1))
    n0 = fl.n_fluid
    fl.advance_to(1.0)   # one period of 0.2 m/s in and out: 3 dp each way
    c = fl.boundary_counts()
    assert c["left"]["in"] > 0 and c["left"]["out"] > 0
    assert fl.n_fluid - n0 == (c["left"]["in"] - c["left"]["out"]
                               + c["right"]["in"] - c["right"]["out"])
    x = fl.particles.f[X, : fl.particles.n][np.isin(fl.particles.kind[: fl.particles.n],
                                                    [ob.INLET, ob.INLET_IDLE])]
    assert x.min() > -e.length[0] - DP and x.max() < DP
