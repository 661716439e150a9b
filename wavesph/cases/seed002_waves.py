"""The regular waves of seed 002's validation table (cases I-VI) and the theory each is run with.

    row = read_cases()["I"]                      # test, theory, H, T, d, L, dp (strings)
    wave = case_theory("standing", height=0.15, period=2.0, depth=0.7, ramp_time=2.0)

One table and one theory per name for the flume bench (bench/flume_accuracy.py), the accuracy
sweep (wavesph.studies.sweeps) and the tests. The table names a theory but not always its order:
"standing" is run to second order (case I, H/d 0.21: its mean set-up (k A^2/4) coth 2kd is 2.0 mm
at the antinode and its second harmonic 5.8 mm, 8 % of A; the linear reference lacks both, and
open ends imposing the linear level at the nodes fill the flume by twice the set-up:
docs/studies/absorption.md "Case I against the second-order standing wave").
"""

from __future__ import annotations

import csv
from importlib import resources
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:   # wave_client.theories imports raschii: only when a theory is built
    from wave_client.theories import WaveTheory

# the table's theory name -> (wave_client theory, its options)
THEORY_OF: dict[str, tuple[str, dict[str, Any]]] = {
    "standing": ("standing", {"order": 2}), "linear": ("linear", {}),
    "stokes2": ("stokes", {"order": 2}), "stokes3": ("stokes", {"order": 3}),
    "stokes4": ("stokes", {"order": 4}), "stokes5": ("stokes", {"order": 5}),
    "stream_function": ("stream", {"n_fourier": 16}), "irregular": ("irregular", {}),
}


def read_cases() -> dict[str, dict[str, str]]:
    """Seed 002's validation table by test name (shipped in wavesph/cases/data; the tests' copy
    is tests/data/wave_cases_seed002.csv)."""
    text = resources.files("wavesph.cases").joinpath("data/wave_cases_seed002.csv").read_text()
    return {r["test"]: r for r in csv.DictReader(ln for ln in text.splitlines()
                                                 if not ln.startswith("#"))}


def case_theory(theory: str, *, height: float, period: float, depth: float,
                ramp_time: float = 0.0, **options: Any) -> WaveTheory:
    """The wave_client theory of table name ``theory`` (THEORY_OF; another name is passed to
    wave_client.theories.build_theory as it is); ``options`` (e.g. ``order``) replace the
    table's."""
    from wave_client.theories import build_theory

    name, opts = THEORY_OF.get(theory, (theory, {}))
    return build_theory(name, height=height, period=period, depth=depth, ramp_time=ramp_time,
                        **{**opts, **options})
