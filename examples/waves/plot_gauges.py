"""Plot the gauge series written by `wavesph waves` (one panel per gauge) to a PNG.

    wavesph waves examples/waves/beji_battjes.toml -o runs/beji_battjes.csv
    .venv/bin/python examples/waves/plot_gauges.py runs/beji_battjes.csv --last 10 -o bar.png
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("csv", type=Path)
    p.add_argument("-o", "--output", type=Path, default=None, help="PNG path (default: CSV name .png)")
    p.add_argument("--last", type=float, default=None, help="plot only the last this many seconds")
    a = p.parse_args()
    header = next(ln for ln in a.csv.read_text().splitlines() if not ln.startswith("#")).split(",")
    data = np.genfromtxt(a.csv, delimiter=",", comments="#", skip_header=0)
    data = data[~np.isnan(data).any(axis=1)]
    t = data[:, 0]
    if a.last:
        keep = t >= t[-1] - a.last
        data, t = data[keep], t[keep]
    n = len(header) - 1
    fig, axes = plt.subplots(n, 1, figsize=(8, 1.3 * n + 1), sharex=True, sharey=True)
    for j, ax in enumerate(np.atleast_1d(axes)):
        ax.plot(t, data[:, j + 1] * 100, lw=0.8)
        ax.set_ylabel("η [cm]")
        ax.text(0.99, 0.85, header[j + 1], transform=ax.transAxes, ha="right", fontsize=8)
        ax.grid(alpha=0.3)
    np.atleast_1d(axes)[-1].set_xlabel("t [s]")
    fig.suptitle(f"surface elevation at the gauges ({a.csv.name})", fontsize=10)
    fig.tight_layout()
    out = a.output or a.csv.with_suffix(".png")
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
