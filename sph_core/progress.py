"""Progress over simulated time for a Simulation run from a terminal (`wavesph run`, the
dam-break demo, bench/dambreak_reference.py).

On a terminal: a tqdm bar. Elsewhere (a CI log, a pipe): one plain line every ``LINE_EVERY_S``
seconds of wall time, never a bar's carriage-return stream. Before the first step, the jitted
loop is compiled (or loaded from numba's cache) with a line saying so, so the bar's rate and ETA
measure stepping only."""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Callable

from . import step
from .simulation import Simulation, UnstableError

LINE_EVERY_S = 30.0  # wall seconds between progress lines when stderr is not a terminal


def kernels_cached() -> bool:
    """Whether numba's on-disk cache holds the time loop (so the first run need not compile)."""
    try:
        return Path(step.run._cache._cache_file._index_path).exists()
    except AttributeError:  # a numba without this (private) layout: assume the worst
        return False


def warm_up(sim: Simulation) -> None:
    """Compile (or load) the time loop by a call that takes no step; its wall time is not
    counted as stepping."""
    if not kernels_cached():
        print("compiling kernels (first run only, ~1-2 min) ...", file=sys.stderr, flush=True)
    wall = sim.wall_time
    sim.advance_steps(0)
    sim.wall_time = wall


def _rate(sim: Simulation) -> float:
    return sim.steps / sim.wall_time if sim.wall_time > 0 else 0.0


def progress_bar(t_end: float, desc: str):
    """A tqdm bar over simulated time showing steps/s; returns (bar, callback for advance_to)."""
    from tqdm import tqdm

    bar = tqdm(total=t_end, desc=desc, unit="s(sim)", bar_format=(
        "{desc}: {percentage:3.0f}%|{bar}| t={n:.3f}/{total:.3f} s [{elapsed}<{remaining}{postfix}]"))

    def update(sim: Simulation) -> None:
        bar.n = min(sim.t, t_end)
        bar.set_postfix_str(f"{_rate(sim):,.0f} steps/s, step {sim.steps}", refresh=False)
        bar.refresh()

    return bar, update


def progress_lines(t_end: float, desc: str, every: float = LINE_EVERY_S,
                   stream=None) -> Callable[[Simulation], None]:
    """A callback printing one line ``desc: t=../.. s (..%), .. steps/s, ETA .. s`` at most every
    ``every`` wall seconds (and at the end)."""
    out = stream or sys.stderr
    last = [time.perf_counter()]
    t0 = [None]

    def update(sim: Simulation) -> None:
        now = time.perf_counter()
        if t0[0] is None:
            t0[0] = (sim.t, sim.wall_time)
        done = sim.t >= t_end
        if now - last[0] < every and not done:
            return
        last[0] = now
        ts, ws = t0[0]
        speed = (sim.t - ts) / (sim.wall_time - ws) if sim.wall_time > ws else 0.0
        eta = f"{(t_end - sim.t) / speed:.0f} s" if speed > 0 else "?"
        print(f"{desc}: t={sim.t:.3f}/{t_end:.3f} s ({100 * min(sim.t / t_end, 1):.0f}%), "
              f"{_rate(sim):,.0f} steps/s, step {sim.steps}, ETA {eta}", file=out, flush=True)

    return update


def advance_with_progress(sim: Simulation, t_end: float, desc: str, show: bool = True) -> int:
    """Advance to t_end with progress (a bar on a terminal, lines otherwise, none if not
    ``show``), then close the run. Returns a process exit code: 0 finished, 3 stopped unstable
    (the cause on stderr). KeyboardInterrupt propagates (meta.json says ``interrupted``)."""
    warm_up(sim)
    bar = None
    update: Callable[[Simulation], None] | None = None
    if show and sys.stderr.isatty():
        bar, update = progress_bar(t_end, desc)
    elif show:
        update = progress_lines(t_end, desc)
    try:
        sim.advance_to(t_end, progress=update)
    except UnstableError as exc:
        if bar is not None:
            bar.close()
        print(f"run stopped, status unstable: {exc}", file=sys.stderr)
        return 3
    finally:
        if bar is not None:
            bar.close()
        sim.close()
    return 0
