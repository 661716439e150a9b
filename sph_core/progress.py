"""A progress bar over simulated time for a Simulation run from a terminal (`wavesph run`, the
dam-break demo, bench/dambreak_reference.py)."""

from __future__ import annotations

import sys
from typing import Callable

from tqdm import tqdm

from .simulation import Simulation, UnstableError


def progress_bar(t_end: float, desc: str) -> tuple[tqdm, Callable[[Simulation], None]]:
    """A tqdm bar over simulated time showing steps/s; returns (bar, callback for advance_to)."""
    bar = tqdm(total=t_end, desc=desc, unit="s(sim)", bar_format=(
        "{desc}: {percentage:3.0f}%|{bar}| t={n:.3f}/{total:.3f} s [{elapsed}<{remaining}{postfix}]"))

    def update(sim: Simulation) -> None:
        bar.n = min(sim.t, t_end)
        rate = sim.steps / sim.wall_time if sim.wall_time > 0 else 0.0
        bar.set_postfix_str(f"{rate:,.0f} steps/s, step {sim.steps}", refresh=False)
        bar.refresh()

    return bar, update


def advance_with_progress(sim: Simulation, t_end: float, desc: str) -> int:
    """Advance to t_end with a progress bar, then close the run. Returns a process exit code:
    0 finished, 3 stopped unstable (the cause on stderr)."""
    bar, update = progress_bar(t_end, desc)
    try:
        sim.advance_to(t_end, progress=update)
    except UnstableError as exc:
        bar.close()
        print(f"run stopped, status unstable: {exc}", file=sys.stderr)
        return 3
    finally:
        bar.close()
        sim.close()
    return 0
