"""wavesph's user-facing helpers for scripts and notebooks (the CLI is `wavesph_cli`).

    import wavesph
    df = wavesph.read_gauges("runs/demo-.../gauges.csv")   # any wavesph gauge CSV
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import pandas


def read_gauges(path: str | Path) -> "pandas.DataFrame":
    """Any wavesph gauge CSV (probes.csv, the server's gauges.csv, a coupling client's log,
    `wavesph waves` output) as a pandas DataFrame: one column per CSV column (units in the
    README's Outputs table), a dry gauge NaN."""
    import pandas

    from sph_core.output import load_gauges

    return pandas.DataFrame(load_gauges(path))
