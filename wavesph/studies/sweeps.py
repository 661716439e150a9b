"""Speed against accuracy: sweeps of independent runs (case, method, dp) on dask.distributed.

    points = accuracy_points(quick=True)
    records = run_sweep(points, Path("runs/accuracy"), scheduler=None)   # LocalCluster
    write_csv(records, out / "accuracy.csv"); plot_accuracy(records, out / "accuracy.png")

A point is one run, scored by ``run_point`` (module-level, so a dask worker can import it). Each
finished point is one JSON file ``DIR/points/<key>.json`` (the run store): a sweep run again skips
the points already there (``retry_failed`` re-runs those that raised). A run the solver stopped
(UnstableError) is a result, status ``unstable`` with the reason; any other exception is status
``failed`` with its text; neither stops the sweep.

Cases (``error`` is always a relative error, smaller is better):
  flume_I ... flume_V  seed 002's validation waves (tests/data/wave_cases_seed002.csv) through the
                       open-boundary flume of wavesph.cases.wave_flume: RMSE/H of the mid-flume gauge
                       against the theory. H_over_dp: wave height / dp.
  dambreak             Martin & Moyce's dam break (column a x 2a): RMS relative error of the surge
                       front against Martin & Moyce for T = t sqrt(2g/a) <= 3 (Koshizuka & Oka's
                       in ``extra``). H_over_dp: column height 2a / dp.
  coupled              the coupled Boussinesq-SPH flume with a beach (wavesph.cases.coupled_flume), two
                       methods: ``coupled`` (Boussinesq far field + SPH zone) and ``sph_only``
                       (SPH over the same length): RMSE/H at the same flat-bed gauge against the
                       Boussinesq-only reference. Runs with the default SPH method only (the
                       server builds its scenes).

Methods are a registry, name -> scene-constant overrides: adding a scheme or option is one line.
"""

from __future__ import annotations

import csv
import json
import math
import os
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable

from sph_core.scene import ISPH_H_OVER_DP

from ..cases.schemes import RIEMANN_VARIANTS
from ..cases.seed002_waves import read_cases

# name -> sph_core.scene.Constants overrides, and "scheme": the scene's [scheme] table (every
# case builder takes ``scheme=``). The solver's schemes and options today: delta-SPH
# WCSPH with the leapfrog (kdk, one force pass per step) or the DualSPHysics-style symplectic
# predictor-corrector (two passes), the smoothing length h/dp (sqrt 2 or 2, the default), the
# wall artificial viscosity (factor 0, the default, or 1) and particle shifting; Riemann SPH
# (wavesph.cases.schemes.RIEMANN_VARIANTS) with h/dp 2 and no wall dissipation. A new scheme or option is
# one line here. Every method names its h/dp and wall factor: the shipped sweep data
# (wavesph/cases/data/accuracy_sweep.csv) were measured when the defaults were h/dp sqrt 2 and factor 1,
# and a method must keep meaning what its rows measured.
OLD_DEFAULTS = {"h_over_dp": 1.4142, "alpha_wall_factor": 1.0}
METHODS: dict[str, dict[str, Any]] = {
    "wcsph_kdk": {**OLD_DEFAULTS},
    "wcsph_symplectic": {"integrator": "symplectic_pc", **OLD_DEFAULTS},
    "wcsph_kdk_h2": {"h_over_dp": 2.0, "alpha_wall_factor": 1.0},
    "wcsph_symplectic_h2": {"integrator": "symplectic_pc", "h_over_dp": 2.0,
                            "alpha_wall_factor": 1.0},
    # no artificial viscosity against walls: the wave-decay study's main finding
    # (docs/studies/wave_decay_study.md), and particle shifting on top of it
    "wcsph_kdk_h2_wallav0": {"h_over_dp": 2.0, "alpha_wall_factor": 0.0},
    "wcsph_kdk_h2_wallav0_shift": {"h_over_dp": 2.0, "alpha_wall_factor": 0.0,
                                   "shifting": "fickian"},
    **{name: {"h_over_dp": 2.0, "alpha_wall_factor": 0.0, "scheme": sch}
       for name, sch in RIEMANN_VARIANTS.items()},
    # ISPH at its defaults (h/dp sqrt 2): its quick flume points run through one scored period
    # at 3-30 % RMSE/H, and some realisations stop unstable (docs/studies/speed_accuracy.md), so
    # the plan keeps it out of wave runs
    "isph_amg": {"h_over_dp": ISPH_H_OVER_DP, "alpha_wall_factor": 0.0,
                 "scheme": {"kind": "isph", "ppe_solver": "amg"}},
    "isph_bicgstab": {"h_over_dp": ISPH_H_OVER_DP, "alpha_wall_factor": 0.0,
                      "scheme": {"kind": "isph", "ppe_solver": "bicgstab"}},  # ISPH's default
    # ISPH with the settings that carry waves (docs/physics/isph.md), its flumes' relaxation
    # zones and ramp in FLUME_WAVE_SETTINGS
    "isph_waves": {"h_over_dp": 1.2, "alpha_wall_factor": 0.0,
                   "scheme": {"kind": "isph", "ppe_solver": "bicgstab",
                              "isph_density_relaxation": 0.05, "isph_wall_stop": 100.0}},
}
# a method's flume settings that follow the case: relaxation zones of this fraction of the
# flume's length at each end (the wave-decay bench's 0.4 m of its 2 m flume; the mid-flume gauge
# stays 0.3 lengths from either), and a start-up ramp this many times the preset's (at H/dp 4 a
# one-period start breaks ISPH's inlet face: docs/studies/schemes.md, "The start-up ramp")
FLUME_WAVE_SETTINGS: dict[str, dict[str, float]] = {
    "isph_waves": {"zone_flume_fraction": 0.2, "ramp_factor": 2.0}}
# the coupled case's two ways to compute the same flume
COUPLED_METHODS = ("coupled", "sph_only")

ACCURACY_COLUMNS = ["case", "method", "dp", "repeat", "H_over_dp", "error", "wall_s", "particles",
                    "steps", "status", "reason"]
# a repeat of a flume point starts its ramp 0.1 % longer per repeat: the step is deterministic,
# and a round-off-sized change is what makes another realisation (case III at H/dp 6 scored
# 2.7-8.6 % RMSE/H over three, docs/studies/absorption.md "Case III at H/dp 6"); the dam break and
# the coupled flume repeat as they are (their scatter is the wall time's)
REPEAT_RAMP_STEP = 1e-3
FLUME_CASES = ("I", "II", "III", "IV", "V")


@dataclass(frozen=True)
class Point:
    """One run of a sweep. ``options``: case settings (durations, sizes) of the preset."""

    case: str
    method: str
    dp: float
    options: dict[str, Any] = field(default_factory=dict, hash=False, compare=False)
    repeat: int = 0   # the realisation (REPEAT_RAMP_STEP); 0: the point itself

    @property
    def key(self) -> str:
        base = f"{self.case}__{self.method}__dp{self.dp:.6g}"
        return f"{base}__r{self.repeat}" if self.repeat else base


# ---------------------------------------------------------------------------- presets
def accuracy_points(quick: bool = False, methods: Iterable[str] | None = None,
                    repeats: int = 1, cases: Iterable[str] | None = None) -> list[Point]:
    """The points of the accuracy sweep. quick: <= 10 min on 2 quiet cores (two methods, two or
    three coarse spacings, one measured period, flume cases I, IV, V); full: every method, three
    spacings, every case (thousands of core-hours: case II at H/dp = 8 has 0.5 M particles,
    docs/studies/speed_accuracy.md). ``repeats``: realisations of every point
    (REPEAT_RAMP_STEP), for the chart's run-to-run scatter. ``cases``: a subset of the preset's
    cases (flume_I ... flume_V, dambreak, coupled)."""
    if int(repeats) != repeats or repeats < 1:
        raise ValueError(f"repeats must be an integer >= 1, got {repeats!r}")
    if cases is not None:
        cases = list(cases)
        known = [f"flume_{c}" for c in FLUME_CASES] + ["dambreak", "coupled"]
        if unknown := [c for c in cases if c not in known]:
            raise ValueError(f"unknown cases {unknown}; known: {known}")
        return [p for p in accuracy_points(quick, methods, repeats) if p.case in cases]
    if methods is None:
        methods = ["wcsph_kdk", "wcsph_symplectic"] if quick else list(METHODS)
    methods = list(methods)
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        raise ValueError(f"unknown methods {unknown}; known: {sorted(METHODS)}")
    cases = read_cases()
    pts: list[Point] = []
    flumes = ("I", "IV", "V") if quick else FLUME_CASES   # quick: the cheap ones (few particles)
    ratios = (2.0, 3.0) if quick else (3.0, 5.0, 8.0)          # H/dp of the wave cases
    flume_opts = {"periods": 1.0 if quick else 3.0, "ramp_periods": 1.0}
    for name in flumes:
        h, d = float(cases[name]["H"]), float(cases[name]["d"])
        # dp: the divisor of the depth nearest H / ratio (a scene whose particles miss the
        # still-water level is refused: its gauges would read up to -dp/2 in still water)
        pts += [Point(f"flume_{name}", m, round(d / round(d * r / h), 9), flume_opts)
                for m in methods for r in ratios]
    a = 0.25 if quick else 0.5                                   # dam-break column width [m]
    db_ratios = (6, 9, 12) if quick else (10, 20, 40)           # column height 2a / dp
    pts += [Point("dambreak", m, round(2 * a / r, 6), {"a": a}) for m in methods for r in db_ratios]
    c_opts = {"wavelengths": 2.0 if quick else 6.0, "compare_periods": 2.0 if quick else 4.0}
    c_dps = (0.03,) if quick else (0.04, 0.02, 0.01)
    pts += [Point("coupled", m, dp, c_opts) for m in COUPLED_METHODS for dp in c_dps]
    return [p if j == 0 else _repeat(p, j) for j in range(int(repeats)) for p in pts]


def _repeat(point: Point, j: int) -> Point:
    opts = dict(point.options)
    if point.case.startswith("flume_"):
        opts["ramp_periods"] = opts.get("ramp_periods", 1.0) * (1.0 + REPEAT_RAMP_STEP * j)
    return Point(point.case, point.method, point.dp, opts, repeat=j)


def flume_constants(method: str, flume_length: float) -> dict[str, Any]:
    """``method``'s scene overrides for a flume ``flume_length`` [m] long: METHODS' entry with
    its relaxation zones (FLUME_WAVE_SETTINGS) sized to the flume."""
    consts = dict(METHODS.get(method, {}))   # the coupled case's methods: the scene's own
    frac = FLUME_WAVE_SETTINGS.get(method, {}).get("zone_flume_fraction")
    if frac:
        consts["scheme"] = {**consts["scheme"],
                            "isph_relaxation_zone": round(frac * flume_length, 4)}
    return consts


def _data_text(name: str) -> str:
    from importlib import resources

    return resources.files("wavesph.cases").joinpath(f"data/{name}").read_text()


# ---------------------------------------------------------------------------- one point
def _threads(n: int = 1) -> None:
    """One numba thread per worker: dask runs one point per core."""
    import numba

    numba.set_num_threads(max(1, min(n, numba.config.NUMBA_NUM_THREADS)))


def run_point(point: Point) -> dict[str, Any]:
    """Run and score one point; never raises: the record's status says what happened."""
    _threads(int(os.environ.get("WAVESPH_POINT_THREADS", "1")))
    from sph_core.simulation import UnstableError

    rec: dict[str, Any] = {"key": point.key, "case": point.case, "method": point.method,
                           "dp": point.dp, "repeat": point.repeat, "options": point.options}
    tic = time.perf_counter()
    try:
        rec["warmup_s"] = round(warm_up_method(point.method), 3)
        rec.update(_RUNNERS[point.case.split("_")[0]](point))
        rec.setdefault("status", "ok")
    except UnstableError as exc:
        rec.update(status="unstable", reason=str(exc), t_fail=exc.t)
    except Exception as exc:  # a failed point is a result of the sweep, not its end
        rec.update(status="failed", reason=f"{type(exc).__name__}: {exc}",
                   traceback=traceback.format_exc(limit=5))
    rec["elapsed_s"] = round(time.perf_counter() - tic, 3)
    _assert_finite(rec)
    return rec


_WARM: set[str] = set()


def warm_up_method(method: str) -> float:
    """Compile (or load from numba's cache) the jitted step of ``method`` for closed and open
    tanks before a timed run, once per process: wall_s then measures the run, not the JIT
    (a cold compile took 4 min of wall on the loaded 2-core machine). Returns its seconds."""
    consts = METHODS.get(method, {})
    sig = json.dumps(consts, sort_keys=True)   # the scheme table is a dict: not hashable
    if sig in _WARM:
        return 0.0
    tic = time.perf_counter()
    from sph_core.simulation import Simulation
    from wave_client.theories import build_theory

    from ..cases.dambreak import dambreak_scene
    from ..cases.wave_flume import run_wave_flume, wave_flume_scene

    sim = Simulation(dambreak_scene(a=0.1, dp=0.05, t_end=0.05, **consts))
    sim.advance_to(0.01)
    model = build_theory("linear", height=0.02, period=1.0, depth=0.2, ramp_time=1.0)
    scene = wave_flume_scene(depth=0.2, wavelength=float(model.length), height=0.02, dp=0.05,
                             t_end=0.1, probe_every=0.02,
                             **flume_constants(method, float(model.length)))
    run_wave_flume(scene, model, window=0.02, t_end=0.04)
    _WARM.add(sig)
    return time.perf_counter() - tic


def _assert_finite(rec: dict[str, Any]) -> None:
    """No NaN/inf in a record: a non-finite score means the run went wrong and says so."""
    for k in ("error", "wall_s"):
        v = rec.get(k)
        if v is not None and not math.isfinite(v):
            rec[k] = None
            if rec.get("status") == "ok":
                rec.update(status="unstable", reason=f"non-finite {k}")


def _flume(point: Point) -> dict[str, Any]:
    from ..cases.seed002_waves import case_theory
    from ..cases.wave_flume import flume_case, flume_length

    row = read_cases()[point.case.split("_", 1)[1]]
    h, t, d = float(row["H"]), float(row["T"]), float(row["d"])
    wave = FLUME_WAVE_SETTINGS.get(point.method, {})
    ramp = point.options.get("ramp_periods", 1.0) * wave.get("ramp_factor", 1.0) * t
    model = case_theory(row["theory"], height=h, period=t, depth=d, ramp_time=ramp)
    standing = row["theory"] == "standing"
    length = flume_length(float(model.length), standing)
    res = flume_case(model, height=h, period=t, depth=d, wavelength=float(model.length),
                     dp=point.dp, periods=point.options.get("periods", 1.0), ramp=ramp,
                     standing=standing, name=point.key,
                     **flume_constants(point.method, length))
    return {"H_over_dp": h / point.dp, "error": res["rmse_over_H"], "wall_s": res["wall_s"],
            "particles": res["particles"], "steps": res["steps"],
            "extra": {"reflection": res["reflection"], "H": h, "T": t, "d": d,
                      "simulated_s": None, "mean_level_m": res["mean_level_m"]}}


def _dambreak(point: Point) -> dict[str, Any]:
    import numpy as np

    from sph_core.simulation import Simulation

    from ..cases.dambreak import dambreak_scene, front_errors

    a = float(point.options.get("a", 0.5))
    t_end = 3.0 * math.sqrt(a / (2 * 9.81)) * 1.02   # T = t sqrt(2g/a) = 3, the table's span
    scene = dambreak_scene(a=a, dp=point.dp, t_end=t_end, probe_every=0.005 * math.sqrt(a),
                           **METHODS[point.method])
    sim = Simulation(scene)
    sim.advance_to(t_end)
    hist = np.array([(r["t"], r["front_x"]) for r in sim.history if r["front_x"] is not None])
    mm = front_errors(hist[:, 0], hist[:, 1], a, t_max=3.0)
    ko = front_errors(hist[:, 0], hist[:, 1], a, t_max=3.0, table=_koshizuka_oka())
    return {"H_over_dp": 2 * a / point.dp, "error": mm["rms_rel_error"], "wall_s": sim.wall_time,
            "particles": sim.n_particles, "steps": sim.steps,
            "extra": {"max_rel_error": mm["max_rel_error"], "ko_rms_rel_error": ko["rms_rel_error"],
                      "a": a, "simulated_s": t_end}}


def _koshizuka_oka() -> tuple[Any, Any]:
    import numpy as np

    text = _data_text("dambreak_koshizuka_oka_1996.csv")
    rows = [ln for ln in text.splitlines() if ln and not ln.startswith("#")][1:]
    data = np.array([[float(v) for v in r.split(",")] for r in rows])
    return data[:, 0], data[:, 1]


def _coupled(point: Point) -> dict[str, Any]:
    import contextlib
    import io
    import shutil
    import tempfile

    from ..cases.coupled_flume import FlumeCase, reference_run, rmse_over_h, run_coupled, run_sph_only

    c = FlumeCase(wavelengths=point.options.get("wavelengths", 2.0),
                  compare_periods=point.options.get("compare_periods", 2.0)).at(point.dp)
    log = io.StringIO()   # run_coupled reports a failed coupling on stderr: keep it as the reason
    # the run's directory (meta.json, gauges, saved states) goes only when the point succeeded:
    # a failed one keeps it to look into (or resume, POST /runs/{id}/resume on a server there)
    tmp = Path(tempfile.mkdtemp(prefix="wavesph-sweep-"))
    try:
        if point.method == "coupled":
            with contextlib.redirect_stderr(log):
                res = run_coupled(c, point.dp, tmp, two_way=True)
        elif point.method == "sph_only":
            res = run_sph_only(c, point.dp, tmp)
        else:
            raise ValueError(f"coupled case: method must be one of {COUPLED_METHODS}")
    except BaseException as exc:
        exc.add_note(f"run data kept in {tmp}")
        raise
    if res["state"] != "finished" or "t" not in res:
        failed = res.get("exit_code") == 1 or "unstable" not in str(res["status"])
        return {"H_over_dp": c.height / point.dp, "status": "failed" if failed else "unstable",
                "reason": f"run ended {res['state']}: {res['status']}"
                          + (f"; client: {log.getvalue().strip()[-300:]}" if log.getvalue() else "")
                          + f"; run data kept in {tmp}",
                "wall_s": res["wall_s"],
                "particles": res["particles"], "steps": res["steps"]}
    shutil.rmtree(tmp, ignore_errors=True)
    t, eta = res["t"], res["eta"]["flat"]
    err = rmse_over_h(t, eta, reference_run(c, t)["flat"], c)
    return {"H_over_dp": c.height / point.dp, "error": err, "wall_s": res["wall_s"],
            "particles": res["particles"], "steps": res["steps"],
            "extra": {"simulated_s": c.t_end, "wavelengths": c.wavelengths}}


_RUNNERS: dict[str, Callable[[Point], dict[str, Any]]] = {
    "flume": _flume, "dambreak": _dambreak, "coupled": _coupled}


# ---------------------------------------------------------------------------- the sweep
def _store(out: Path) -> Path:
    d = out / "points"
    d.mkdir(parents=True, exist_ok=True)
    return d


def load_record(out: Path, point: Point) -> dict[str, Any] | None:
    path = out / "points" / f"{point.key}.json"
    return json.loads(path.read_text()) if path.exists() else None


def save_record(out: Path, rec: dict[str, Any]) -> None:
    path = _store(out) / f"{rec['key']}.json"
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(rec, indent=1, default=float))
    tmp.replace(path)   # a sweep killed mid-write leaves no half record behind


def pending(points: list[Point], out: Path, retry_failed: bool = False) -> list[Point]:
    """The points without a record in the store (and, with retry_failed, those that failed)."""
    todo = []
    for p in points:
        rec = load_record(out, p)
        if rec is None or (retry_failed and rec.get("status") == "failed"):
            todo.append(p)
    return todo


def run_sweep(points: list[Point], out: Path, scheduler: str | None = None,
              n_workers: int | None = None, retry_failed: bool = False, progress: bool = True,
              runner: Callable[[Point], dict[str, Any]] = run_point,
              desc: str = "sweep") -> list[dict[str, Any]]:
    """Run the points not yet in ``out``'s store on dask.distributed (``scheduler``: an existing
    scheduler's address, else a LocalCluster of processes, one thread each), saving each record as
    it arrives; return the records of all ``points`` in order."""
    from tqdm import tqdm

    out = Path(out)
    _store(out)
    todo = pending(points, out, retry_failed)
    if todo:
        from dask.distributed import Client, LocalCluster, as_completed

        cluster = None
        if scheduler is None:
            n = n_workers or max(1, min(len(todo), os.cpu_count() or 1))
            # one numba/OpenMP thread per worker process (the workers are the parallelism); set
            # only while the workers spawn: numba in this process refuses a changed thread count
            saved = {v: os.environ.get(v) for v in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS")}
            os.environ.update({v: "1" for v in saved})
            try:
                cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                       dashboard_address=":0")   # any free port: no clash
            finally:
                for v, old in saved.items():
                    if old is None:
                        os.environ.pop(v, None)
                    else:
                        os.environ[v] = old
        client = Client(scheduler or cluster)
        try:
            futures = client.map(runner, todo, key=[f"{desc}-{p.key}" for p in todo], pure=False)
            where = {f.key: p for f, p in zip(futures, todo)}
            bar = tqdm(total=len(points), initial=len(points) - len(todo), desc=desc,
                       unit="point", disable=not progress)
            for fut in as_completed(futures):
                p = where[fut.key]
                try:
                    rec = fut.result()
                except Exception as exc:   # the worker died (KilledWorker) or the task could not run
                    rec = {"key": p.key, "case": p.case, "method": p.method, "dp": p.dp,
                           "repeat": p.repeat, "options": p.options, "status": "failed",
                           "reason": f"{type(exc).__name__}: {exc}"}
                save_record(out, rec)
                bar.set_postfix_str(f"{p.key}: {rec.get('status')}", refresh=False)
                bar.update(1)
            bar.close()
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    return [load_record(out, p) for p in points]   # type: ignore[misc]


# ---------------------------------------------------------------------------- outputs
def write_table(rows: list[dict[str, Any]], path: Path, columns: list[str],
                formats: dict[str, str], command: str = "") -> None:
    """A CSV of ``columns``, one row per record; numbers in ``formats`` columns written with that
    format spec. accuracy.csv and stability.csv both. One header row and nothing else, as every
    wavesph CSV (pandas.read_csv reads it): ``command``, the date and the machine go to
    ``<stem>.meta.json`` beside it (a chart made from the CSV says where its wall times come from)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    meta = path.with_suffix(".meta.json")
    if command:
        meta.write_text(json.dumps({"csv": path.name, "made_by": command, **machine_note()},
                                   indent=1) + "\n")
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=columns, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            row = {k: r.get(k) for k in columns}
            for k, spec in formats.items():
                if isinstance(row[k], (int, float)) and not isinstance(row[k], bool):
                    row[k] = format(row[k], spec)
            w.writerow(row)


def machine_note() -> dict[str, str]:
    """When and where the wall times were taken: the UTC date, the machine's cores and Python, and
    its load average over the last 15 minutes when the table is written (above the core count:
    other jobs shared the cores)."""
    import datetime
    import platform

    cores = os.cpu_count() or 1
    load = os.getloadavg()[2] if hasattr(os, "getloadavg") else float("nan")
    return {"date": datetime.datetime.now(datetime.timezone.utc).date().isoformat(),
            "machine": f"{cores} cores, {platform.machine()}, Python {platform.python_version()}, "
                       f"load average {load:.1f} over the last 15 min"}


def chart_title(meta: dict[str, str]) -> str:
    """A chart's title from its table's meta.json: the command, and when and where its wall times
    were taken."""
    return meta["made_by"] + "".join(f"\n{meta[k]}" for k in ("date", "machine") if k in meta)


def write_csv(records: list[dict[str, Any]], path: Path, command: str = "") -> None:
    """accuracy.csv: ACCURACY_COLUMNS, one row per point (``command`` in accuracy.meta.json)."""
    write_table(records, path, ACCURACY_COLUMNS,
                {"error": ".6g", "wall_s": ".6g", "H_over_dp": ".6g"}, command)


def read_csv(path: Path) -> list[dict[str, Any]]:
    """Rows of an accuracy.csv with numbers parsed (empty cells: None; files of earlier
    versions began with a # line, skipped)."""
    with open(path) as fh:
        rows = list(csv.DictReader(ln for ln in fh if not ln.startswith("#")))
    num = {"dp": float, "repeat": int, "H_over_dp": float, "error": float, "wall_s": float,
           "particles": int, "steps": int}
    out = [{k: (num[k](v) if k in num and v not in ("", None) else (None if v == "" else v))
            for k, v in r.items()} for r in rows]
    for r in out:   # files of earlier versions have no repeat column
        if r.get("repeat") is None:
            r["repeat"] = 0
    return out


def pareto_front(points: Iterable[tuple[float, float]]) -> list[tuple[float, float]]:
    """The (cost, error) pairs no other pair beats on both (cheaper or as cheap, and at least
    as accurate, one of them strictly), by rising cost: the runs worth their cost."""
    front: list[tuple[float, float]] = []
    for c, e in sorted(points, key=lambda p: (p[0], p[1])):
        if not front or e < front[-1][1]:
            front.append((c, e))
    return front


def repeat_groups(records: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The finished records (status ok, error and wall time known) grouped by (case, method, dp)
    over their repeats: n, the mean error and wall time, and their smallest and largest, by
    case, method and falling dp."""
    groups: dict[tuple[str, str, float], list[dict[str, Any]]] = {}
    for r in records:
        if r.get("status") == "ok" and r.get("error") and r.get("wall_s"):
            groups.setdefault((r["case"], r["method"], float(r["dp"])), []).append(r)
    out = []
    for (case, method, dp), rs in sorted(groups.items(), key=lambda kv: (*kv[0][:2], -kv[0][2])):
        err = [float(r["error"]) for r in rs]
        wall = [float(r["wall_s"]) for r in rs]
        out.append({"case": case, "method": method, "dp": dp, "n": len(rs),
                    "error": sum(err) / len(err), "error_min": min(err), "error_max": max(err),
                    "wall_s": sum(wall) / len(wall), "wall_min": min(wall), "wall_max": max(wall)})
    return out


def plot_accuracy(records: list[dict[str, Any]], path: Path, title: str = "") -> None:
    """Error (log y) against wall seconds (log x), one panel per case, one line per method, each
    point labelled with its dp (3 significant digits). Repeats of a point (``--repeats``) are
    drawn at their mean with bars from the smallest to the largest error and wall time: the
    run-to-run scatter a rise or fall along a line must exceed to mean anything. Each method's
    Pareto front (pareto_front over the means: the points that buy accuracy with time) is drawn
    filled, its dominated points hollow (a refinement that cost more and erred more); the
    case's front over all methods is the dashed grey line. Unstable/failed points are not drawn
    (see the CSV); a case none of whose points ran through is an empty panel that says so."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter, LogLocator

    cases = sorted({r["case"] for r in records})
    n = max(1, len(cases))
    ncol = min(3, n)
    nrow = math.ceil(n / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(4.6 * ncol, 3.8 * nrow), squeeze=False)
    # one colour per method on every panel, so a line reads the same across cases
    methods = sorted({r["method"] for r in records})
    colour = {m: f"C{k % 10}" for k, m in enumerate(methods)}
    groups = repeat_groups(records)
    for ax, case in zip(axes.flat, cases):
        for method in sorted({r["method"] for r in records if r["case"] == case}):
            pts = [g for g in groups if g["case"] == case and g["method"] == method]
            bad = sum(1 for r in records if r["case"] == case and r["method"] == method
                      and r.get("status") != "ok")
            if not pts:  # named in the legend, so a missing line is not read as not run
                ax.plot([], [], "x", color=colour[method], label=f"{method} (all {bad} unstable/failed)")
                continue
            label = method + (f" ({bad} unstable/failed)" if bad else "")
            xy = [(r["wall_s"], r["error"]) for r in pts]
            ax.plot(*zip(*xy), "-", color=colour[method], alpha=0.5)
            front = set(pareto_front(xy))
            on = [p for p in xy if p in front]
            off = [p for p in xy if p not in front]
            ax.plot(*zip(*on), "o", color=colour[method], label=label)
            if off:
                ax.plot(*zip(*off), "o", mfc="none", color=colour[method])
            for g in pts:
                if g["n"] > 1:   # the run-to-run scatter of the repeats
                    # (a mean of equal values can land an ulp outside them: clip at 0)
                    ax.errorbar(g["wall_s"], g["error"], fmt="none", color=colour[method],
                                alpha=0.6, lw=1, capsize=2,
                                xerr=[[max(0.0, g["wall_s"] - g["wall_min"])],
                                      [max(0.0, g["wall_max"] - g["wall_s"])]],
                                yerr=[[max(0.0, g["error"] - g["error_min"])],
                                      [max(0.0, g["error_max"] - g["error"])]])
                ax.annotate(f"{g['dp']:.3g}" + (f" ×{g['n']}" if g["n"] > 1 else ""),
                            (g["wall_s"], g["error"]), fontsize=7, xytext=(3, 3),
                            textcoords="offset points")
        ax.set_title(case, fontsize=10)
        if not any(g["case"] == case for g in groups):   # no point ran through: no log axes
            ax.text(0.5, 0.5, "no point ran through\n(the CSV says why)", ha="center",
                    va="center", transform=ax.transAxes, fontsize=8)
            ax.set_xticks([])
            ax.set_yticks([])
            ax.legend(fontsize=7)
            continue
        best = pareto_front((g["wall_s"], g["error"]) for g in groups if g["case"] == case)
        if len(best) > 1:
            ax.step(*zip(*best), where="post", ls="--", color="0.5", lw=1, label="front, all methods")
        ax.set_xscale("log")
        ax.set_yscale("log")
        # wall times as plain numbers at 1, 2, 5 x 10^n: a panel within one decade still has
        # labels, and the default minor labels (every integer multiple) overlap
        plain = FuncFormatter(lambda v, _: f"{v:g}")
        ax.xaxis.set_minor_locator(LogLocator(base=10.0, subs=(2.0, 5.0)))
        ax.xaxis.set_major_formatter(plain)
        ax.xaxis.set_minor_formatter(plain)
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("error (relative)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    for ax in list(axes.flat)[n:]:
        ax.set_visible(False)
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def records_summary(records: list[dict[str, Any]]) -> dict[str, int]:
    out: dict[str, int] = {}
    for r in records:
        out[r.get("status", "?")] = out.get(r.get("status", "?"), 0) + 1
    return out


def point_from_dict(d: dict[str, Any]) -> Point:
    return Point(d["case"], d["method"], float(d["dp"]), dict(d.get("options") or {}),
                 int(d.get("repeat") or 0))

