"""Two-way coupled Boussinesq-SPH flume with a 1:10 beach, and its two references.

One flume, three ways to compute it (x in the Boussinesq model's frame: source at x = 0):

    |sponge| source (x=0) ..... n wavelengths of flat bed d ..... x_c | flat x_flat | 1:10 beach |
                                                                  SPH inlet (open)

- coupled: the Boussinesq model (wave_client, a `wavesph waves` scene) covers the far field up to
  x_c plus an overlap of flat bed ending in a sponge; the SPH zone (server, an sph_core Simulation with open ends)
  starts with an open inlet at x_c. The client is `wavesph couple --model boussinesq --config
  <scene.toml>`, unchanged, over a real socket. ``two_way`` (the wave scene's ``[coupling]``):
  SPH's elevation and z_alpha velocity at the inlet gauge become the model's characteristic
  boundary at x_c (the beach's reflection travels on into the model, the inlet lets it out);
  False: absorption-only (the model never hears of SPH; the client's seed 002 correction,
  `--absorb`, absorbs the reflection at the SPH inlet). Why not the SPH boundary: `run_coupled`.
- reference: the Boussinesq model alone over the whole flume, the bathymetry continued with the
  same 1:10 beach. Nwogu's model has no dry land and no breaking: its beach stops at depth d/3
  (`H_MIN_FRACTION`) and continues flat into a sponge (no wall), so it reflects less than
  SPH's breaking beach; the gauge compared stands on the flat bed before the beach.
- sph_only: SPH over the whole length, an open inlet at the source position driven by a
  second-order Stokes theory (the server's standalone theory run), the same beach. Its inlet
  does not absorb: the beach's reflection would reach it only after t_end, and the boundary's
  own correction has the reference flaw described in `run_coupled`.

``FlumeCase(end="outlet")`` ends the SPH zone instead with an open outlet ``x_flat`` past the inlet,
flat bed throughout, fed by the model (which runs on past it over flat bed into its sponge): both
ends are the model's, absorption-only (the client absorbs at both), and the reference is the
model alone over the same flat flume. No beach, so what it scores is the coupling and the SPH
zone's own travel; and it runs schemes that cannot hold the beach's shoreline (ISPH).

Datum: SPH floor z = 0, still water z = d (`still_water_level`); the wave model measures z up
from still water. SPH x = model x - x_c.
"""

from __future__ import annotations

import json
import math
import sys
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from server.schemas import TERMINAL
from wave_client import G

from .wave_flume import buffer_width_for
from ..local_server import InProcessServer, wait_for_state

H_MIN_FRACTION = 1.0 / 3.0   # the reference Boussinesq beach ends at depth d/3 (then a sponge)
SHORE_ROWS = 2               # particle rows of the thinnest water filled at the shoreline


@dataclass(frozen=True)
class FlumeCase:
    """The coupled flume (SI units). ``depth`` is rounded to whole dp rows by `at`."""

    depth: float = 0.24           # still-water depth on the flat bed [m]
    height: float = 0.04          # wave height at the source [m]
    period: float = 1.4           # [s]
    slope: float = 0.1            # 1:10 beach
    wavelengths: float = 12.0     # Boussinesq source -> SPH inlet, in wavelengths
    x_flat: float = 1.2           # flat bed inside SPH, inlet -> beach toe [m]
    gauge: float = 0.8            # compared gauge on the flat bed, from the SPH inlet [m]
    ramp_periods: float = 2.0     # start-up ramp of the source [periods]
    compare_periods: float = 4.0  # periods compared after the ramped wave reached the gauge
    dx_per_wavelength: int = 40   # Boussinesq grid
    settle_periods: float = 2.0   # SPH zone at rest before the first waves reach it [periods]
    end: str = "beach"            # "beach": closed by the 1:10 beach; "outlet": open, x_flat on

    def __post_init__(self) -> None:
        if self.end not in ("beach", "outlet"):
            raise ValueError(f"FlumeCase.end: 'beach' or 'outlet', got {self.end!r}")
        if self.end == "outlet" and not 0.0 < self.gauge < self.x_flat:
            raise ValueError(f"FlumeCase: the gauge ({self.gauge} m) must lie inside the zone "
                             f"(0, x_flat = {self.x_flat} m)")

    def at(self, dp: float) -> "FlumeCase":
        """The case with its depth rounded to whole particle rows of spacing dp."""
        return replace(self, depth=depth_for_case(self.depth, dp))

    @property
    def omega(self) -> float:
        return 2.0 * math.pi / self.period

    @property
    def wavelength(self) -> float:
        """Nwogu wavelength on the flat bed [m] (what the Boussinesq model propagates)."""
        from wave_client.boussinesq import nwogu_wavenumber

        return 2.0 * math.pi / float(nwogu_wavenumber(self.omega, self.depth))

    @property
    def group_velocity(self) -> float:
        """Linear (Airy) group velocity on the flat bed [m/s]: the speed of the ramped front."""
        from wave_client.theories import wavenumber

        from ..analysis import group_velocity

        airy_wavelength = 2.0 * math.pi / float(wavenumber(self.omega, self.depth))
        return group_velocity(airy_wavelength, self.period, self.depth)

    @property
    def x_couple(self) -> float:
        """Model x of the SPH inlet [m]."""
        return self.wavelengths * self.wavelength

    @property
    def t_quiet(self) -> float:
        """Until this time [s] the SPH inlet sees (almost) still water: no linear wave outruns
        the long-wave speed sqrt(g d), and the source's signal starts half a wavelength
        up-flume of x_c's distance from x = 0. Measured (default case, dp = 0.02): the model's
        |eta| at x_c stays below 1e-4 H until 14.3 s, t_quiet = 14.8 s, 1e-3 H at 15.2 s."""
        return max(0.0, (self.x_couple - 0.5 * self.wavelength) / math.sqrt(G * self.depth))

    @property
    def t_sph_start(self) -> float:
        """Clock of the SPH zone's first step [s] (scene ``t_start``): the water has
        ``settle_periods`` to settle from its initial lattice before the waves arrive; the
        Boussinesq model runs alone up to it (WELCOME's t_start)."""
        return max(0.0, self.t_quiet - self.settle_periods * self.period)

    @property
    def x_toe(self) -> float:
        return self.x_couple + self.x_flat

    @property
    def gauges(self) -> dict[str, float]:
        """SPH-zone gauges, x [m] from the SPH inlet: flat bed (compared), toe, mid-beach; with
        an outlet: the compared one, mid-zone, and the compared one's mirror from the outlet."""
        if self.end == "outlet":
            return {"flat": self.gauge, "mid": 0.5 * self.x_flat, "far": self.x_flat - self.gauge}
        return {"flat": self.gauge, "toe": self.x_flat,
                "beach": self.x_flat + 0.5 * self.depth / self.slope}

    @property
    def reflection_pair(self) -> tuple[str, str]:
        """The two gauges (same depth) that split the first harmonic into incident and
        reflected waves: the far end's reflection (the beach's or the outlet's)."""
        return ("flat", "mid") if self.end == "outlet" else ("flat", "toe")

    @property
    def compare_from(self) -> float:
        """Start of the comparison [s]: the ramp, the front's travel to the gauge at the group
        velocity, and one period for the front's tail (before it, the gauge sees the front)."""
        travel = (self.x_couple + self.gauge) / self.group_velocity
        return (self.ramp_periods + 1.0) * self.period + travel

    @property
    def t_end(self) -> float:
        return self.compare_from + self.compare_periods * self.period

    @property
    def window(self) -> float:
        """Coupling window [s]: what `wavesph couple --model boussinesq` takes (T/50)."""
        return self.period / 50.0


def depth_for_case(depth: float, dp: float) -> float:
    """Depth [m] nearest ``depth`` holding whole dp rows (at least 4): the particles fill whole
    rows of dp, so any other depth would put the SPH surface up to dp/2 below still water."""
    return dp * max(4, round(depth / dp))


# ---------------------------------------------------------------------------- scenes
def _tank_end(c: FlumeCase, x_flat_end: float, dp: float) -> float:
    """x [m] of the tank's end, the flat bed ending at ``x_flat_end``: the outlet's face, or the
    closed end where the beach rises 0.1 m above still water (room for run-up)."""
    if c.end == "outlet":
        return dp * round(x_flat_end / dp)
    return dp * round((x_flat_end + (c.depth + 0.1) / c.slope) / dp)


def _sph_scene(c: FlumeCase, dp: float, t_end: float, x_flat_end: float,
               gauges: dict[str, float], name: str, absorb: bool,
               constants: dict[str, Any] | None = None,
               scheme: dict[str, Any] | None = None) -> dict[str, Any]:
    """The SPH scene of a flume whose flat bed ends at ``x_flat_end`` (the beach's toe, or the
    outlet's face)."""
    d = c.depth
    x1 = _tank_end(c, x_flat_end, dp)
    width = buffer_width_for(c.height, c.period, d, dp)
    x_water = x1 if c.end == "outlet" else x_flat_end + (d - SHORE_ROWS * dp) / c.slope
    # the outlet as the wave flume's (wave_flume_scene): its level from the fluid beside it
    ends = [("left", "imposed")] + ([("right", "extrapolated")] if c.end == "outlet" else [])
    return {
        "name": name, "dp": dp, "t_end": t_end, "still_water_level": d,
        # room above the beach's top (0.1 m above still water) for run-up and splashes: a drop
        # over the tank top ends the run (dp = 0.02 with the top at d + 2H + 4dp: t = 29.5 s)
        "tank": {"x0": 0.0, "x1": x1, "z0": 0.0, "z1": d + 0.1 + 2 * c.height + 4 * dp},
        # the shoreline wedge is filled only where it holds >= 2 particle rows: a thinner wedge
        # over the staircase bed jets particles out in still water (dp = 0.02: 1-2 m/s at t ~ 1 s,
        # density out of band, run unstable); the water spreads up the rest of the slope itself.
        # Cost: the level drops by ~ 2 dp^2 / (slope x wet length), 2.2 mm at dp = 0.02. The
        # absorption-only inlet refills it; the two-way one does not (measured mean -2.8 mm at
        # the flat gauge, 7 % of H in its RMSE/H of 9.5 %)
        "water_blocks": [{"x0": 0.0, "x1": x_water, "z0": 0.0, "z1": d}],
        **({} if c.end == "outlet" else
           {"beds": [{"points": [[x_flat_end, 0.0], [x1, c.slope * (x1 - x_flat_end)]]}]}),
        # c0 = 10 sqrt(g d) bounds orbital speeds x10. No-slip walls although both wave models
        # are inviscid: free slip left the thin film on the staircase beach undamped, and at
        # dp = 0.02 (late start, absorption-only) a run-up jet threw a particle over the tank
        # top at t = 15.6 s; no-slip ran through. Measured at the flat gauge (dp = 0.01,
        # absorption-only): RMSE/H 4.95 % no-slip, 6.0 % free slip.
        "constants": {"c0": 10.0 * math.sqrt(G * d), "wall_slip": "no_slip", **(constants or {})},
        **({"scheme": scheme} if scheme else {}),
        "output": {"probe_every": c.period / 20},
        "probes": [{"kind": "elevation", "name": n, "x": x} for n, x in gauges.items()],
        # the server gets its boundary data pushed, so the scene sizes the buffer from the
        # wave it is built for (sph_core.open_ends.buffer_widths)
        "open_boundaries": [{"side": side, "elevation": elevation, "absorb": absorb,
                             "buffer_width": width} for side, elevation in ends],
    }


def sph_zone_scene(c: FlumeCase, dp: float, absorb: bool = False,
                   constants: dict[str, Any] | None = None,
                   scheme: dict[str, Any] | None = None) -> dict[str, Any]:
    """The SPH zone of the coupled flume (server scene): inlet at SPH x = 0 (model x_c),
    clock from ``c.t_sph_start``, an open outlet at x_flat if ``c.end`` says so; ``constants``
    and ``scheme`` (the [scheme] table,
    wavesph.cases.schemes) override the scene's (e.g. h_over_dp, kind = "isph")."""
    c = c.at(dp)
    scene = _sph_scene(c, dp, c.t_end, c.x_flat, c.gauges, "coupled-flume-sph-zone", absorb,
                       constants, scheme)
    return {**scene, "t_start": round(c.t_sph_start, 6)}


def sph_only_scene(c: FlumeCase, dp: float, t_end: float | None = None,
                   scheme: dict[str, Any] | None = None) -> dict[str, Any]:
    """The whole flume in SPH: inlet at the source position (SPH x = model x)."""
    c = c.at(dp)
    x0 = dp * round(c.x_couple / dp)  # the SPH zone's inlet on the particle lattice
    gauges = {n: x0 + x for n, x in c.gauges.items()}
    return _sph_scene(c, dp, c.t_end if t_end is None else t_end, x0 + c.x_flat, gauges,
                      "sph-only-flume", absorb=False, scheme=scheme)


def wave_scene(c: FlumeCase, two_way: bool = True, reference: bool = False) -> dict[str, Any]:
    """The `wavesph waves` scene (dict of the TOML) of the coupled model, or of the
    Boussinesq-only reference of the whole flume (``reference=True``)."""
    wl = c.wavelength
    x_c = c.x_couple
    sponge_left = 1.5 * wl
    x_start = -(0.5 * wl + sponge_left)  # source half-width, then the sponge
    if reference and c.end == "beach":
        h_min = H_MIN_FRACTION * c.depth
        x_shelf = c.x_toe + (c.depth - h_min) / c.slope
        sponge_right = 2.5 * 2.0 * math.pi / _k(c.omega, h_min)  # 2.5 shallow wavelengths
        x_end = x_shelf + sponge_right
        bathy = {"x": [c.x_toe, x_shelf], "depth": [c.depth, h_min]}
    else:  # flat overlap past x_c (and an outlet's zone): one wavelength, then a sponge
        sponge_right = 2.0 * wl
        x_end = x_c + (c.x_flat if c.end == "outlet" else 0.0) + wl + sponge_right
        bathy = {"x": [x_start, x_end], "depth": [c.depth, c.depth]}
    xs = [round(x_c + x, 6) for x in c.gauges.values()]
    return {
        "grid": {"x_start": round(x_start, 6), "x_end": round(x_end, 6),
                 "dx": round(wl / c.dx_per_wavelength, 6), "courant": 0.4, "t_end": round(c.t_end, 6)},
        "bathymetry": {"x": [round(v, 6) for v in bathy["x"]], "depth": bathy["depth"]},
        "wave": {"kind": "regular", "height": c.height, "period": c.period, "x_source": 0.0,
                 "ramp_periods": c.ramp_periods},
        "sponge": {"left": round(sponge_left, 6), "right": round(sponge_right, 6)},
        "gauges": {"x": xs, "names": list(c.gauges)},
        "coupling": {"x": round(x_c, 6), "two_way": bool(two_way)},
    }


def _k(omega: float, h: float) -> float:
    from wave_client.boussinesq import nwogu_wavenumber

    return float(nwogu_wavenumber(omega, h))


def to_toml(data: dict[str, Any], header: str = "") -> str:
    """TOML text of a scene dict: scalars and flat lists, tables, arrays of tables (one level
    of nesting: all our scenes need)."""
    def val(v: Any) -> str:
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(val(x) for x in v) + "]"
        if isinstance(v, str):
            return json.dumps(v)
        return repr(float(v)) if isinstance(v, float) else str(v)

    def tables(v: Any) -> bool:
        return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)

    lines = [f"# {h}" for h in header.splitlines()]
    lines += [f"{k} = {val(v)}" for k, v in data.items() if not isinstance(v, dict) and not tables(v)]
    for key, body in data.items():
        if isinstance(body, dict):
            lines += ["", f"[{key}]"] + [f"{k} = {val(v)}" for k, v in body.items()]
        elif tables(body):
            for item in body:
                lines += ["", f"[[{key}]]"] + [f"{k} = {val(v)}" for k, v in item.items()]
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------- runs
def reference_run(c: FlumeCase, times: np.ndarray) -> dict[str, np.ndarray]:
    """Boussinesq-only elevation [m] at the SPH-zone gauges (by name) at ``times`` [s]."""
    from wave_client.boussinesq.wave_scene import WaveScene, build_model

    scene = WaveScene.model_validate(wave_scene(c, reference=True))
    model = build_model(scene)
    xs = np.array(scene.gauges.x)
    out = np.empty((times.size, xs.size))
    for i, t in enumerate(times):
        model.advance_to(float(t))
        out[i] = model.elevation(xs)
    return {n: out[:, j] for j, n in enumerate(scene.gauges.names)}


def rmse_over_h(t: np.ndarray, eta: np.ndarray, ref: np.ndarray, c: FlumeCase) -> float | None:
    """RMSE/H of eta against ref over [compare_from, t_end]; None if the run ended before."""
    from ..analysis import rmse_over_height

    sel = t >= c.compare_from - 1e-9
    if sel.sum() < 10:
        return None
    return rmse_over_height(eta[sel], ref[sel], c.height)


def correlation(t: np.ndarray, eta: np.ndarray, ref: np.ndarray, t0: float) -> float:
    """Pearson correlation of two series over t >= t0."""
    sel = t >= t0
    return float(np.corrcoef(eta[sel], ref[sel])[0, 1])


def _gauges_csv(path: Path) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """(t, {gauge name: eta}) of a server gauges.csv; dry samples become NaN."""
    from sph_core.output import load_gauges

    cols = load_gauges(path)
    eta = {col.removesuffix("_eta"): v for col, v in cols.items() if col.endswith("_eta")}
    return cols["t"], eta


def run_coupled(c: FlumeCase, dp: float, out: Path, two_way: bool = True,
                transport: str = "ws", absorb: str | None = None,
                constants: dict[str, Any] | None = None,
                scheme: dict[str, Any] | None = None, zone_nodes: bool = True) -> dict[str, Any]:
    """The coupled flume over a real socket: in-process server, the client as `wavesph couple
    --model boussinesq --config <out>/wave_scene.toml [--absorb]` runs it (its log beside it;
    the server's store is <out>/server, where a file of ours would be a stray entry). Figures
    and series.

    absorb: who absorbs the beach's reflection at the SPH inlet; exactly one absorber, or the
    gain doubles (docs/developer/architecture.md). Default: "incident" for two-way (measured best,
    docs/studies/absorption.md), "client" otherwise. ``constants`` and ``scheme`` override the
    SPH scene's.
      "none": two-way only: the model's characteristic boundary takes SPH's reflected wave
        L = (eta - u_ref / r) / 2 and hands it back in the inlet data, so the inlet passes it.
      "client": `wavesph couple --absorb`; mismatch = the inlet gauge's reading minus the
        model's elevation *at the gauge's x* (the uncoupled twin's beyond x_c in two-way mode).
      "incident": two-way, plus the client's correction on the incident characteristic only
        (`--absorb --absorb-wave incident`): the boundary lets SPH's reflection out, the
        correction makes SPH's inlet carry the model's incident wave and level
        (docs/studies/absorption.md; dp 0.02: RMSE/H 7.2 % against 9.1 % without, 6.6 %
        absorption-only).
      "sph": the scene's open boundary (`absorb = true`). Over the socket its reference is the
        elevation SET gives for the face (the protocol carries eta at the nodes' x only), not
        at its gauge 2h inside: off by k 2h (0.18 rad at dp = 0.02) of the incident wave.
        Measured (dp = 0.02, two-way, so also doubled): the SPH wave led the reference by
        0.25 rad and was 9 % low, RMSE/H 12 %. Kept to show it (bench --absorb sph).
    zone_nodes: the client sends the model's wave inside ISPH's relaxation zones too
    (`CouplingOptions.zone_nodes`; False: the faces only, `wavesph couple --no-zone-nodes`).
    """
    absorb = absorb or ("incident" if two_way else "client")
    if c.end == "outlet" and (two_way or absorb == "sph"):
        # the model's characteristic boundary stands at the inlet only, and the SPH absorber's
        # reference over the socket is the face's elevation (see "sph" above)
        raise ValueError("a coupled zone with an outlet runs absorption-only with the client "
                         "absorbing (two_way=False, absorb='client' or 'none')")
    if absorb not in ("none", "client", "incident", "sph"):
        raise ValueError(f"absorb: 'none', 'client', 'incident' or 'sph', got {absorb!r}")
    import httpx

    from wave_client.boussinesq.dispersion import BETA
    from wave_client.boussinesq.wave_scene import build_model, load_wave_scene
    from wave_client.coupling import CouplingError, CouplingOptions, couple

    c = c.at(dp)
    out.mkdir(parents=True, exist_ok=True)
    cfg = out / "wave_scene.toml"
    cfg.write_text(to_toml(wave_scene(c, two_way=two_way),
                           "coupled flume: Boussinesq far field (wavesph/cases/coupled_flume.py)"))
    scene = load_wave_scene(cfg)  # the file, as the CLI reads it

    z_ref = BETA * c.depth  # Nwogu's z_alpha: the model's reference_level at x_c (flat bed)
    tic = time.perf_counter()
    with InProcessServer(out / "server") as srv, \
            httpx.Client(base_url=f"http://127.0.0.1:{srv.port}", timeout=60) as http:
        zone = sph_zone_scene(c, dp, absorb == "sph", constants=constants, scheme=scheme)
        r = http.post("/runs", json={"scene": zone,
                                     "mode": "coupled",
                                     "coupling": {"window_max": c.window, "z_ref": z_ref}})
        r.raise_for_status()
        run = r.json()
        # building the engine includes numba's cold compile of the step: 429 s measured at load
        # ~15 on 2 cores (2026-11-23), past the 300 s waited before (the point ended "queued")
        info = wait_for_state(http, run["id"], {"waiting_for_client"} | TERMINAL, timeout=1800)
        url = (f"ws://127.0.0.1:{srv.port}/runs/{run['id']}/couple" if transport == "ws"
               else f"tcp://127.0.0.1:{srv.tcp_port}")
        code = None  # the client's exit status as `wavesph couple` would give it
        if info["state"] == "waiting_for_client":
            try:
                couple(url, lambda welcome: build_model(scene, base_dir=cfg.parent),
                       CouplingOptions(window=c.window, absorb=absorb in ("client", "incident"),
                                       absorb_wave="incident" if absorb == "incident" else "total",
                                       zone_nodes=zone_nodes),
                       run_id=run["id"], scene_hash=bytes.fromhex(run["scene_hash"]),
                       timeout=600.0, log_path=out / "client_gauges.csv", progress=False)
                code = 0
            except CouplingError as exc:
                print(f"coupled flume: coupling failed: {exc}", file=sys.stderr)
                code = 1
        info = wait_for_state(http, run["id"], TERMINAL, timeout=120)
    wall = time.perf_counter() - tic
    result = {"mode": "two_way" if two_way else "absorption_only", "absorb": absorb,
              "exit_code": code,
              "state": info["state"], "status": info["status"], "particles": info["particles"],
              "steps": info["steps"], "windows": info["windows"], "wall_s": wall,
              "coupling_overhead_share": info.get("coupling_overhead_share")}
    gauges = out / "server" / run["id"] / "gauges.csv"
    if gauges.exists():
        result["t"], result["eta"] = _gauges_csv(gauges)
    return result


def run_sph_only(c: FlumeCase, dp: float, out: Path, t_end: float | None = None,
                 scheme: dict[str, Any] | None = None) -> dict[str, Any]:
    """The whole flume in SPH (server standalone run, Stokes-2 inlet) to ``t_end`` (default the
    case's). wall_s: POST to finished; build_s: POST to the first window."""
    import httpx

    c = c.at(dp)
    scene = sph_only_scene(c, dp, t_end, scheme)
    source = {"theory": "stokes", "H": c.height, "T": c.period, "order": 2,
              "ramp_periods": c.ramp_periods, "window": c.window}
    out.mkdir(parents=True, exist_ok=True)
    tic = time.perf_counter()
    build = None
    with InProcessServer(out) as srv, httpx.Client(base_url=f"http://127.0.0.1:{srv.port}",
                                                   timeout=60) as http:
        r = http.post("/runs", json={"scene": scene, "mode": "standalone", "source": source,
                                     "coupling": {"window_max": c.window}})
        r.raise_for_status()
        run_id = r.json()["id"]
        while True:
            info = http.get(f"/runs/{run_id}").json()
            if build is None and (info.get("windows") or 0) > 0:
                build = time.perf_counter() - tic
            if info["state"] in TERMINAL:
                break
            time.sleep(0.05)
    wall = time.perf_counter() - tic
    result = {"state": info["state"], "status": info["status"], "particles": info["particles"],
              "steps": info["steps"], "windows": info["windows"], "wall_s": wall,
              "build_s": build if build is not None else wall, "t_end": scene["t_end"]}
    gauges = out / run_id / "gauges.csv"
    if gauges.exists():
        result["t"], result["eta"] = _gauges_csv(gauges)
    return result


# ---------------------------------------------------------------------------- examples
EXAMPLE_DP = 0.02
OUTLET_ZONE = {"end": "outlet", "x_flat": 2.4}   # the zone open at both ends: a wavelength and more
# ISPH's options for open-ended wave runs (docs/physics/isph.md, "What runs, what does not")
ISPH_WAVES = {"kind": "isph", "isph_density_relaxation": 0.05, "isph_wall_stop": 100.0,
              "isph_relaxation_zone": 0.4}
ISPH_WAVES_CONSTANTS = {"h_over_dp": 1.2}
EXAMPLE_FILES = {
    "wave_two_way.toml": ("the Boussinesq far field of the coupled flume, two-way coupling",
                          lambda c: wave_scene(c, two_way=True)),
    "wave_absorption_only.toml": ("the same, absorption-only: the SPH inlet absorbs, the model "
                                  "hears nothing back", lambda c: wave_scene(c, two_way=False)),
    "wave_reference.toml": ("Boussinesq-only reference of the whole flume: the 1:10 beach down to "
                            "depth d/3, then a sponge", lambda c: wave_scene(c, reference=True)),
    "sph_zone.toml": (f"the SPH zone (server scene, dp = {EXAMPLE_DP} m): open inlet at model "
                      "x = [coupling] x, flat bed, 1:10 beach", lambda c: sph_zone_scene(c, EXAMPLE_DP)),
    "wave_outlet.toml": ("the Boussinesq model of the zone open at both ends (absorption-only: "
                         "flat bed on past the outlet, then a sponge)",
                         lambda c: wave_scene(replace(c, **OUTLET_ZONE), two_way=False)),
    "sph_zone_outlet_isph.toml": (
        f"the SPH zone open at both ends under ISPH (server scene, dp = {EXAMPLE_DP} m): inlet at "
        "model x = [coupling] x, 2.4 m of flat bed, outlet; relaxation zones at both ends",
        lambda c: sph_zone_scene(replace(c, **OUTLET_ZONE), EXAMPLE_DP,
                                 constants=ISPH_WAVES_CONSTANTS, scheme=ISPH_WAVES)),
}


def write_examples(directory: Path) -> list[Path]:
    """examples/coupled/*.toml: the default case at dp = EXAMPLE_DP (generated, not hand-kept)."""
    c = FlumeCase().at(EXAMPLE_DP)
    directory.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, (what, make) in EXAMPLE_FILES.items():
        path = directory / name
        path.write_text(to_toml(make(c), f"{what}\nGenerated by `python -m "
                                         f"wavesph.cases.coupled_flume {directory}`; SI units."))
        paths.append(path)
    return paths


if __name__ == "__main__":
    for p in write_examples(Path(sys.argv[1] if len(sys.argv) > 1 else "examples/coupled")):
        print(p)
