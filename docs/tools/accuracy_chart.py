"""Redraw docs/figures/accuracy_quick.png from the shipped sweep data (no run).

    python docs/tools/accuracy_chart.py

The data, wavesph/cases/data/accuracy_sweep.csv, are the records of the command in its
.meta.json (``made_by``); `wavesph bench accuracy` writes the same chart beside its own CSV.
"""

from __future__ import annotations

import json
from pathlib import Path

from wavesph.studies import sweeps

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "wavesph" / "cases" / "data" / "accuracy_sweep.csv"
FIGURE = ROOT / "docs" / "figures" / "accuracy_quick.png"


def main() -> None:
    made_by = json.loads(DATA.with_suffix(".meta.json").read_text())["made_by"]
    sweeps.plot_accuracy(sweeps.read_csv(DATA), FIGURE, title=f"{made_by} (under load)")
    print(f"wrote {FIGURE.relative_to(ROOT)} from {DATA.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
