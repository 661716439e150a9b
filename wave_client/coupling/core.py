"""Sans-I/O coupling client: what to send next, given the wave model and the server's replies.

Client side of seed 001, Algorithm 2 (explicit coupling, one exchange per window) with the
active-absorption correction of seed 002 (Altomare et al. 2017), on the wire format of
`protocol/PROTOCOL.md`. No sockets here: `transport.py` moves the bytes, `runner.py` loops.

Per window [t0, t1]:
  1. advance the wave model to t1;
  2. sample u, w at the boundary nodes and eta at their x; correct u (below);
  3. SET(t0, t1, u, w, eta) + SOLVE  ->  RESULT(eta, wet, u_ref, w_ref at the gauges, at t1);
  4. mismatch at the inlet/outlet gauges: d_eta = eta_measured - eta_model(gauge x, t1);
     ``model.impose(x_b, eta_measured, u_ref)`` at the inlet boundary x_b (mean x of the inlet
     nodes) with the inlet gauge's readings, Alg. 2 line 4 (two-way models use it, theories
     ignore it).

Correction (seed 002, shallow-water active absorption; opt-in, ``absorb=True``), applied to the
next window's u, with c = sqrt(g/d), g and d from WELCOME, and the mismatch
m = eta_measured - eta_model at the side's gauge:
    inlet:   u_in  = u_model - m_f * c        (= u_model - (eta_in,measured - eta_model) c)
    outlet:  u_out = u_model + m_f * c        (= u_model - (eta_model - eta_out,measured) c)
Only the horizontal velocity is corrected, uniformly over depth.

m_f is m through a first-order low-pass, tau dm_f/dt = m - m_f, tau = 1 / (2 pi f_c), discretised
per window as m_f += a (m - m_f), a = dt_w / (tau + dt_w); f_c = ``absorb_cutoff`` (default
3 / wave period; infinity gives the unfiltered formula). Why: the exchange is explicit, so the
measurement of window n only corrects window n+1; with the gauge distance this delays the
absorber by tau_d ~ one window, and an absorber of gain 1 and delay tau_d re-emits a wave of
frequency f with amplitude |1 - exp(-2 pi i f tau_d)| of the incoming one: > 1 above
f = 1 / (6 tau_d). In a lossless flume such components grow without bound (test_client_absorption);
the low-pass keeps the correction at the wave frequencies and starves the amplifying band.

Do not combine with absorption on the SPH side: sph_core's open boundaries apply the same
correction every sub-step (scene ``open_boundaries[].absorb``, no window lag); both together
double the gain. The client's correction is for servers whose boundaries impose the values as sent.
"""

from __future__ import annotations

import asyncio
import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, TypeVar

import numpy as np

from protocol import (NO_SCENE_HASH, Bye, Capability, ClientSession, Error, ErrorCode, Gauges,
                      GetGauges, GetNodes, Hello, Message, Nodes, ProtocolError, Result, Set, Side,
                      Solve, Welcome)
from protocol.session import TIME_RTOL  # the server matches window times with the same tolerance
from wave_client.model import WaveModel

CLIENT_NAME = "wavesph-couple/0.1"
_M = TypeVar("_M", bound=Message)


class CouplingError(RuntimeError):
    """The coupled run could not go on; the message says why and what to change."""


class ServerEnded(CouplingError):
    """The server said BYE before the client was done (run cancelled, server stopping)."""


@dataclass(frozen=True)
class CouplingOptions:
    """Client-side choices of a coupled run.

    window:   coupling window [s]; None: min(WELCOME.window_max, model period / 50) (or window_max
              for a model without ``period``). Boundary data are interpolated linearly in time
              over a window, so it must resolve the wave period.
    t_end:    stop at this time [s] (None: the server's t_end).
    absorb:   apply the seed 002 correction at the inlet and outlet (off by default: the SPH
              side normally absorbs itself, see the module docstring).
    absorb_wave: "total": the mismatch is eta_measured - eta_model at the gauge (seed 002);
              "incident": the mismatch of the incident (right-going) characteristic at the inlet
              gauge, R = (eta + u_ref / r) / 2 measured minus the model's, r the model's
              ``progressive_ratio`` (else sqrt(g/d)): it leaves SPH's reflected wave alone, which
              a two-way model's boundary lets out itself, and corrects only what SPH's inlet
              makes of the incident wave (level and wave). The outlet keeps "total".
    absorb_cutoff: low-pass cutoff f_c [Hz] of the measured mismatch; None: 3 / model period
              (50 windows' period for a model without ``period``); math.inf: no filter.
    x_offset: model x = SPH x + x_offset [m] (the two codes may use different x origins); None:
              put the SPH inlet at the model's ``x_couple`` if it has one (Boussinesq), else 0.
    inlet_gauge, outlet_gauge: index of the gauge that measures eta for that side's correction;
              None: the gauge nearest that side's nodes (and nearer to it than to the other side).
    depth_rtol: largest relative difference accepted between the model's depth and WELCOME.depth.
    zone_nodes: ask for the columns inside the SPH zone's relaxation zones (protocol 1.2,
              ZONE_NODES; a server grants it for runs that have them, ISPH's) and send the
              model's wave there too, so that the zones pull towards the wave as it is at each x;
              False: the faces' nodes only (the zones pull towards the face's profile).
    """

    window: float | None = None
    t_end: float | None = None
    absorb: bool = False
    absorb_wave: str = "total"
    absorb_cutoff: float | None = None
    x_offset: float | None = None
    inlet_gauge: int | None = None
    outlet_gauge: int | None = None
    depth_rtol: float = 0.01
    zone_nodes: bool = True


@dataclass
class WindowRecord:
    """What one window sent and got back (all SI, z up from still water)."""

    t0: float
    t1: float
    steps: int                 # SPH sub-steps the server took
    eta: np.ndarray            # measured elevation at each gauge at t1 [m]
    wet: np.ndarray            # 1 where the gauge found water
    u_ref: np.ndarray          # measured velocity at z_ref at each gauge [m/s]
    w_ref: np.ndarray
    eta_model: np.ndarray      # wave-model elevation at each gauge at t1 [m] (NaN: outside the model)
    du_inlet: float            # correction added to u at the inlet nodes in this window [m/s]
    du_outlet: float           # ... at the outlet nodes [m/s]


ModelSource = WaveModel | Callable[[Welcome], WaveModel]


def _span(xs: np.ndarray) -> str:
    """'x' for one abscissa, 'x_min..x_max' for several (error messages)."""
    a, b = float(xs.min()), float(xs.max())
    return f"{a}" if a == b else f"{a}..{b}"


@dataclass
class _Side:
    """Nodes of one open boundary, grouped by x so the model is asked one vertical at a time."""

    index: np.ndarray                                  # node indices of this side
    columns: list[tuple[float, np.ndarray]] = field(default_factory=list)  # (x, node indices)
    gauge: int | None = None


class CouplingCore:
    """State machine of the client; every method returns the bytes to send (if any).

    ``model`` is a `WaveModel`, or a callable building one from the server's WELCOME (so its
    depth can be taken from the scene). Use: ``hello()``, ``on_welcome(seq, msg)`` ->
    GETNODES frame, ``on_nodes(seq, msg)``, then while ``windows_left``: ``next_window()`` ->
    [SET, SOLVE] frames, ``on_result(seq, msg)`` -> `WindowRecord`; finally ``bye()``.
    """

    def __init__(self, model: ModelSource, options: CouplingOptions | None = None, *,
                 run_id: str = "", scene_hash: bytes = NO_SCENE_HASH,
                 client_name: str = CLIENT_NAME) -> None:
        self._model_source = model
        self.model: WaveModel | None = model if isinstance(model, WaveModel) else None
        if self.model is None and not callable(model):
            raise TypeError("model must be a WaveModel or a callable(Welcome) -> WaveModel")
        self.options = options or CouplingOptions()
        self.run_id = run_id
        self.scene_hash = scene_hash
        self.client_name = client_name
        self.session = ClientSession()
        self.welcome: Welcome | None = None
        self.nodes: Nodes | None = None
        self.gauge_info: Gauges | None = None  # 1.1 servers: what each gauge is (GETGAUGES)
        self.times: np.ndarray = np.zeros(0)   # window ends t_1 .. t_n, t_0 = t_start
        self.window = 0.0                      # s, coupling window (the last may be shorter)
        self.window_index = 0                  # windows solved so far
        self._sides: dict[Side, _Side] = {}
        self._mismatch = {Side.INLET: 0.0, Side.OUTLET: 0.0}  # low-passed eta_meas - eta_model [m]
        self.filter_tau = 0.0                  # s, low-pass time constant of the mismatch
        self.x_offset = 0.0                    # m, model x = SPH x + x_offset
        self.x_inlet: float | None = None      # m, SPH x of the inlet boundary (mean node x)
        self._pending: tuple[float, float, float, float] | None = None  # t0, t1, du_in, du_out

    # --- handshake ------------------------------------------------------------------------
    def hello(self) -> bytes:
        # 1.1: GAUGE_INFO (gauge names) and KEEPALIVE (WORKING frames while the first window
        # waits for the solver's compile); 1.2: ZONE_NODES (the wave inside the SPH zone's
        # relaxation zones, where the run has them); an older server ignores the bits
        caps = Capability.GAUGE_INFO | Capability.KEEPALIVE
        if self.options.zone_nodes:
            caps |= Capability.ZONE_NODES
        return self.session.request(Hello(int(caps), self.scene_hash, self.run_id, self.client_name))

    def on_welcome(self, seq: int, msg: Message) -> bytes:
        """Check the offer against the model; the GETNODES frame to send."""
        welcome = self._reply(seq, msg, Welcome)
        self.welcome = welcome
        if self.model is None:
            self.model = self._model_source(welcome)  # type: ignore[operator]
            if not isinstance(self.model, WaveModel):
                raise CouplingError("the model factory did not return a WaveModel")
        d_model, d_sph = float(self.model.depth), welcome.depth
        if abs(d_model - d_sph) > self.options.depth_rtol * d_sph:
            raise CouplingError(
                f"depth mismatch: the wave model has depth={d_model} m, the SPH scene has "
                f"{d_sph} m at the inlet (tolerance {self.options.depth_rtol:.0%}); "
                "set the model's depth to the scene's")
        t_stop = welcome.t_end if self.options.t_end is None else self.options.t_end
        if not t_stop > welcome.t_start or t_stop > welcome.t_end * (1 + TIME_RTOL):
            raise CouplingError(f"t_end={t_stop} s must lie in ({welcome.t_start}, "
                                f"{welcome.t_end}] s, the server's run time")
        window = self.options.window
        if window is None:
            period = getattr(self.model, "period", None)
            window = welcome.window_max if period is None else min(welcome.window_max, period / 50)
        if not (math.isfinite(window) and window > 0):
            raise CouplingError(f"window must be a positive number of seconds, got {window}")
        if window > welcome.window_max * (1 + TIME_RTOL):
            raise CouplingError(f"window={window} s exceeds the server's window_max="
                                f"{welcome.window_max} s")
        n = max(1, math.ceil((t_stop - welcome.t_start) / window - 1e-9))
        self.times = welcome.t_start + window * np.arange(1, n + 1)
        self.times[-1] = t_stop  # the last window ends exactly at t_stop
        self.window = window
        period = getattr(self.model, "period", None) or 50.0 * window
        f_c = self.options.absorb_cutoff if self.options.absorb_cutoff is not None else 3.0 / period
        if not f_c > 0:
            raise CouplingError(f"absorb_cutoff must be > 0 Hz, got {f_c}")
        self.filter_tau = 1.0 / (2.0 * math.pi * f_c)
        if self.options.absorb and window > period / 40:
            warnings.warn(f"window={window:.4g} s is longer than period/40 = {period / 40:.4g} s: "
                          "the lagged client-side absorption may amplify short waves", stacklevel=2)
        self.model.advance_to(welcome.t_start)
        return self.session.request(GetNodes())

    def on_nodes(self, seq: int, msg: Message) -> None:
        """Group the boundary nodes by side and column; pick the correction gauges."""
        nodes = self._reply(seq, msg, Nodes)
        self.nodes = nodes
        known = [Side.INLET, Side.OUTLET]
        if self.welcome is not None and self.welcome.capabilities & Capability.ZONE_NODES:
            known += [Side.INLET_ZONE, Side.OUTLET_ZONE]   # 1.2: the model's wave there too
        for side in known:
            idx = np.flatnonzero(nodes.side == side)
            if idx.size:
                xs = nodes.x[idx]
                cols = [(float(x), idx[xs == x]) for x in np.unique(xs)]
                self._sides[side] = _Side(idx, cols)
        unknown = set(np.unique(nodes.side).tolist()) - {int(s) for s in known}
        if unknown:
            raise ProtocolError(ErrorCode.BAD_VALUE, f"NODES.side has unknown values {sorted(unknown)}")
        n_g = nodes.gauge_x.size
        for side, chosen in ((Side.INLET, self.options.inlet_gauge),
                             (Side.OUTLET, self.options.outlet_gauge)):
            if side not in self._sides:
                continue
            if chosen is not None:
                if not 0 <= chosen < n_g:
                    name = "inlet_gauge" if side is Side.INLET else "outlet_gauge"
                    raise CouplingError(f"{name}={chosen}: the scene has {n_g} gauges")
                self._sides[side].gauge = chosen
            else:
                self._sides[side].gauge = self._nearest_gauge(side)
        if Side.INLET in self._sides:
            self.x_inlet = float(nodes.x[self._sides[Side.INLET].index].mean())
        x_couple = getattr(self.model, "x_couple", None)
        if self.options.x_offset is not None:
            self.x_offset = float(self.options.x_offset)
        elif x_couple is not None and self.x_inlet is not None:
            self.x_offset = float(x_couple) - self.x_inlet

    def gauges_request(self) -> bytes | None:
        """GETGAUGES if the server granted GAUGE_INFO (1.1), else None (a 1.0 server)."""
        assert self.welcome is not None
        if not self.welcome.capabilities & Capability.GAUGE_INFO:
            return None
        return self.session.request(GetGauges())

    def on_gauges(self, seq: int, msg: Message) -> None:
        info = self._reply(seq, msg, Gauges)
        assert self.welcome is not None
        if len(info.names) != self.welcome.n_gauges or info.kind.size != self.welcome.n_gauges:
            raise ProtocolError(ErrorCode.SHAPE_MISMATCH, f"GAUGES has {len(info.names)} names and "
                                f"{info.kind.size} kinds, WELCOME {self.welcome.n_gauges} gauges")
        self.gauge_info = info

    def gauge_labels(self) -> list[str]:
        """One label per gauge for logs: the server's names (1.1), else the gauge index."""
        assert self.nodes is not None
        if self.gauge_info is not None:
            return list(self.gauge_info.names)
        return [str(i) for i in range(self.nodes.gauge_x.size)]

    def _nearest_gauge(self, side: Side) -> int | None:
        assert self.nodes is not None
        gx = self.nodes.gauge_x
        if gx.size == 0:
            return None
        own = abs(gx - self.nodes.x[self._sides[side].index].mean())
        other_side = Side.OUTLET if side is Side.INLET else Side.INLET
        ok = np.ones(gx.size, bool)
        if other_side in self._sides:
            ok = own < abs(gx - self.nodes.x[self._sides[other_side].index].mean())
        return int(np.flatnonzero(ok)[np.argmin(own[ok])]) if ok.any() else None

    def metadata(self) -> dict[str, Any]:
        """Run metadata as JSON fields (the gauge log's ``.meta.json``), after the handshake:
        names and numbers, short (0.028, not 0.027999999999999997), no Python reprs."""
        w, n = self.welcome, self.nodes
        assert w is not None and n is not None
        labels = self.gauge_labels()
        gauges = self.gauges
        return {
            "model": model_description(self.model),
            "run_id": w.run_id, "server": w.server,
            "g_m_s2": _short(w.g), "depth_m": _short(w.depth),
            "still_water_level_m": _short(w.still_water_level),   # absolute SPH z
            "z_ref_m": _short(w.z_ref),                           # up from still water
            "window_s": _short(self.window), "windows": int(self.times.size),
            "t_start_s": _short(w.t_start), "t_end_s": _short(float(self.times[-1])),
            "gauges": [{"name": name, "x_m": _short(float(x))} for name, x in zip(labels, n.gauge_x)],
            "gauges_named_by": "server" if self.gauge_info is not None else "index (a 1.0 server)",
            "correction": {"on": bool(self.options.absorb),
                           "low_pass_tau_s": _short(self.filter_tau) if self.options.absorb else None,
                           **{f"{side}_gauge": None if i is None else labels[i]
                              for side, i in gauges.items()}},
            "model_x_minus_sph_x_m": _short(self.x_offset),
        }

    def describe(self) -> list[str]:
        """Run metadata as text lines (for a person), after the handshake."""
        m = self.metadata()
        c = m["correction"]
        return [
            f"model: {m['model']['name']} "
            + " ".join(f"{k}={v}" for k, v in m["model"]["parameters"].items()),
            f"run_id: {m['run_id']}; server: {m['server']}",
            f"g = {m['g_m_s2']} m/s^2; depth = {m['depth_m']} m; still_water_level = "
            f"{m['still_water_level_m']} m (absolute SPH z); z_ref = {m['z_ref_m']} m (up from "
            "still water)",
            f"windows: {m['windows']} of {m['window_s']} s from t = {m['t_start_s']} s to "
            f"{m['t_end_s']} s",
            "gauges: " + " ".join(f"{g['name']} (x = {g['x_m']} m)" for g in m["gauges"]),
            f"client-side correction (seed 002): "
            + (f"on, low-pass tau = {c['low_pass_tau_s']} s" if c["on"] else "off")
            + f", inlet gauge {c.get('inlet_gauge')}, outlet gauge {c.get('outlet_gauge')}; "
            f"model x = SPH x + {m['model_x_minus_sph_x_m']} m",
        ]

    @property
    def gauges(self) -> dict[str, int | None]:
        """Gauge index used for each side's correction (None: no correction there)."""
        return {("inlet" if s is Side.INLET else "outlet"): v.gauge for s, v in self._sides.items()
                if s in (Side.INLET, Side.OUTLET)}

    # --- windows --------------------------------------------------------------------------
    @property
    def windows_left(self) -> int:
        return int(self.times.size - self.window_index)

    def next_window(self) -> list[bytes]:
        """[SET, SOLVE] frames for the next window (model advanced to its end)."""
        assert self.welcome is not None and self.nodes is not None and self.model is not None
        if self.windows_left <= 0:
            raise CouplingError("no window left: the run reached t_end")
        t0 = self.welcome.t_start if self.window_index == 0 else float(self.times[self.window_index - 1])
        t1 = float(self.times[self.window_index])
        self.model.advance_to(t1)
        x_off = self.x_offset
        n = self.nodes.x.size
        u, w, eta = np.zeros(n), np.zeros(n), np.zeros(n)
        for key, side in self._sides.items():
            xs = np.array([x for x, _ in side.columns])
            try:
                z0 = self.nodes.z[side.columns[0][1]]
                if all(np.array_equal(self.nodes.z[idx], z0) for _, idx in side.columns):
                    # columns on one set of levels (a zone's): one call for them all, as a
                    # Boussinesq model differentiates its whole grid per call
                    uc, wc = (np.broadcast_to(a, (xs.size, z0.size)) for a in
                              self.model.velocity(xs[:, None] + x_off, z0[None, :]))
                else:
                    uc, wc = zip(*(self.model.velocity(x + x_off, self.nodes.z[idx])
                                   for x, idx in side.columns))
                ec = np.asarray(self.model.elevation(xs + x_off), float).reshape(xs.size)
                front = getattr(self.model, "front_factor", None)
                if key in (Side.INLET_ZONE, Side.OUTLET_ZONE) and front is not None:
                    # a theory's ramp holds at every x at once: a zone gets the wave as it
                    # arrives, all its columns scaled by the factor at the zone's x nearest the
                    # wavemaker, its face included (as in-process,
                    # sph_core.boundary_data.WaveModelBoundary.velocity_along)
                    face = self._sides.get(Side(int(key) - 2))
                    x_near = min(xs.min(), *(x for x, _ in face.columns)) if face else xs.min()
                    f = float(np.asarray(front(x_near + x_off), dtype=float))
                    uc, wc = np.asarray(uc) * f, np.asarray(wc) * f
            except ValueError as exc:  # e.g. a node outside the model's grid
                raise CouplingError(
                    f"the wave model cannot give the {key.name.lower()} nodes at SPH x = "
                    f"{_span(xs)} m (model x = {_span(xs + x_off)} m): {exc}") from exc
            for k, (_, idx) in enumerate(side.columns):
                u[idx], w[idx], eta[idx] = uc[k], wc[k], ec[k]
        c = math.sqrt(self.welcome.g / self.welcome.depth)
        du_in = du_out = 0.0
        if self.options.absorb:
            du_in = 0.0 - self._mismatch[Side.INLET] * c  # u_in = u - (eta_meas - eta_model) c
            du_out = self._mismatch[Side.OUTLET] * c   # u_out = u - (eta_model - eta_meas) c
            if Side.INLET in self._sides:
                u[self._sides[Side.INLET].index] += du_in
            if Side.OUTLET in self._sides:
                u[self._sides[Side.OUTLET].index] += du_out
        for name, a in (("u", u), ("w", w), ("eta", eta)):
            if not np.all(np.isfinite(a)):
                raise CouplingError(f"the wave model returned non-finite {name} at t={t1} s")
        self._pending = (t0, t1, du_in, du_out)
        return [self.session.request(Set(t0, t1, u, w, eta)), self.session.request(Solve())]

    def on_result(self, seq: int, msg: Message) -> WindowRecord:
        """Take the RESULT of the window: record it, compute the next correction, feed back."""
        assert self.welcome is not None and self.nodes is not None and self.model is not None
        if self._pending is None:
            raise CouplingError("RESULT without a window in flight")
        result = self._reply(seq, msg, Result)
        t0, t1, du_in, du_out = self._pending
        if abs(result.t - t1) > TIME_RTOL * max(1.0, abs(t1)):
            raise ProtocolError(ErrorCode.TIME_MISMATCH,
                                f"RESULT.t={result.t} s, the window ended at t1={t1} s")
        x_off = self.x_offset
        gx = self.nodes.gauge_x
        eta_model = self._model_at_gauges(gx + x_off)
        a = (t1 - t0) / (self.filter_tau + (t1 - t0))  # 1 when unfiltered (tau = 0)
        for side, s in self._sides.items():
            if side not in self._mismatch:   # a relaxation zone's columns: no gauge of their own
                continue
            g = s.gauge
            if g is not None and not math.isfinite(eta_model[g]):
                raise CouplingError(f"the {side.name.lower()} gauge {g} at SPH x = {gx[g]} m lies "
                                    "outside the wave model: choose another gauge")
            # a dry gauge measured nothing: no correction rather than a spurious one
            m = float(result.eta[g] - eta_model[g]) if g is not None and result.wet[g] else 0.0
            if (m != 0.0 or result.wet[g]) and side is Side.INLET \
                    and self.options.absorb_wave == "incident" and g is not None:
                m = self._incident_mismatch(float(gx[g] + x_off), float(result.eta[g]),
                                            float(result.u_ref[g]), float(eta_model[g]))
            self._mismatch[side] += a * (m - self._mismatch[side])
        inlet = self._sides.get(Side.INLET)
        if inlet is not None and inlet.gauge is not None and result.wet[inlet.gauge]:
            g = inlet.gauge
            assert self.x_inlet is not None
            self.model.impose(self.x_inlet + x_off, float(result.eta[g]), float(result.u_ref[g]))
        self._pending = None
        self.window_index += 1
        return WindowRecord(t0, t1, int(result.steps), result.eta.copy(), result.wet.copy(),
                            result.u_ref.copy(), result.w_ref.copy(), eta_model, du_in, du_out)

    def _incident_mismatch(self, x: float, eta: float, u_ref: float, eta_model: float) -> float:
        """(eta + u_ref / r)/2 measured minus the model's at model x (see absorb_wave)."""
        assert self.model is not None and self.welcome is not None
        ratio = getattr(self.model, "progressive_ratio", None)
        r = ratio(self.welcome.depth) if ratio else math.sqrt(self.welcome.g / self.welcome.depth)
        u_model = float(np.asarray(self.model.velocity(np.array([x]),
                                                       np.array([self.welcome.z_ref]))[0])[0])
        return 0.5 * ((eta + u_ref / r) - (eta_model + u_model / r))

    def _model_at_gauges(self, x: np.ndarray) -> np.ndarray:
        """Model elevation at the gauges; NaN (in the log only) where the model has no value,
        e.g. SPH-zone gauges beyond a Boussinesq grid."""
        assert self.model is not None
        try:
            return np.asarray(self.model.elevation(x), dtype=float).reshape(x.size)
        except ValueError:
            out = np.full(x.size, np.nan)
            for i, xi in enumerate(x):
                try:
                    out[i] = float(np.asarray(self.model.elevation(np.array([xi])), float)[0])
                except ValueError:
                    pass
            return out

    def _reply(self, seq: int, msg: Message, expect: type[_M]) -> _M:
        if isinstance(msg, Bye):
            raise ServerEnded(f"the server ended the run: {msg.reason or '(no reason given)'}")
        return self.session.reply(seq, msg, expect=expect)

    # --- ending ---------------------------------------------------------------------------
    def bye(self, reason: str = "done") -> bytes:
        return self.session.request(Bye(reason))

    def on_bye(self, seq: int, msg: Message) -> None:
        self.session.reply(seq, msg, expect=Bye)

    def error_frame(self, exc: BaseException) -> bytes:
        """ERROR frame telling the server why the client stops (sent before closing)."""
        if isinstance(exc, ProtocolError):
            code, text = exc.code, exc.text
        elif isinstance(exc, (KeyboardInterrupt, asyncio.CancelledError)):
            code, text = ErrorCode.CANCELLED, "client: interrupted by its user"
        elif isinstance(exc, TimeoutError):
            code, text = ErrorCode.TIMEOUT, f"client: {exc}"
        else:
            code, text = ErrorCode.INTERNAL, f"client: {type(exc).__name__}: {exc}"
        return self.session.request(Error(int(code), text.encode()[:4000].decode(errors="ignore")))


def _short(v: float) -> float:
    """A float printed short in JSON: 9 significant digits (0.028, not 0.027999999999999997)."""
    return float(f"{v:.9g}")


def model_description(model: object) -> dict[str, Any]:
    """A wave model as {"name": its class, "parameters": its public scalar settings} (numbers
    short): what a meta file can hold instead of ``<... object at 0x7f...>``."""
    params: dict[str, Any] = {}
    for k, v in vars(model).items() if hasattr(model, "__dict__") else ():
        if k.startswith("_"):
            continue
        if isinstance(v, bool):
            params[k] = v
        elif isinstance(v, (int, np.integer)):
            params[k] = int(v)
        elif isinstance(v, (float, np.floating)) and math.isfinite(v):
            params[k] = _short(float(v))
        elif isinstance(v, str) and len(v) <= 80:
            params[k] = v
    return {"name": type(model).__name__, "parameters": params}
