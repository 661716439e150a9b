"""Redraw the speed-accuracy charts (docs/figures/accuracy_*.png) and the validation page's
speed-accuracy rows (bench/results/accuracy_sweep.jsonl) from the shipped sweep data (no run).

    python docs/tools/accuracy_chart.py
    python docs/tools/validation_tables.py > docs/validation.md    # then the page

The data: wavesph/cases/data/accuracy_sweep.csv (the quick preset, with repeats: what `wavesph
plan` fits) and bench/results/accuracy_sweep_quick_isph_waves.csv (ISPH's wave settings on the
same points; one chart), bench/results/accuracy_sweep_full_defaults.csv,
accuracy_sweep_full_isph_waves.csv and accuracy_sweep_full_riemann_muscl.csv (the full preset's
spacings and windows for today's WCSPH defaults, ISPH's wave settings and Riemann SPH, the cases
a 2-core machine runs; one chart). Each table is the records of the command in its .meta.json
(``made_by``, with the date and machine);
`wavesph bench accuracy` writes the same chart beside its own CSV. Repeats of a point
(``--repeats``) make one row: the mean error, its range and the mean wall time.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from wavesph.studies import sweeps

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "wavesph" / "cases" / "data" / "accuracy_sweep.csv"
FULL = ROOT / "bench" / "results" / "accuracy_sweep_full_defaults.csv"
FULL_ISPH = ROOT / "bench" / "results" / "accuracy_sweep_full_isph_waves.csv"
FULL_RIEMANN = ROOT / "bench" / "results" / "accuracy_sweep_full_riemann_muscl.csv"
QUICK_ISPH = ROOT / "bench" / "results" / "accuracy_sweep_quick_isph_waves.csv"
# (tables, figure, what it shows): the validation page draws them first, in this order; a chart
# of several tables (one sweep each) draws their records together
CHARTS = [((FULL, FULL_ISPH, FULL_RIEMANN),
           ROOT / "docs" / "figures" / "accuracy_full_defaults.png",
           "Today's WCSPH defaults, ISPH's wave settings (`isph_waves`) and Riemann SPH "
           "(`riemann_muscl`) at the full preset's spacings (H/dp 3, 5, 8) and windows "
           "(3 periods), the cases a 2-core machine runs"),
          ((DATA, QUICK_ISPH), ROOT / "docs" / "figures" / "accuracy_quick.png",
           "Four methods at the quick preset's coarse spacings, each point three times (the data "
           "`wavesph plan` fits), and ISPH's wave settings (`isph_waves`, not planned: its "
           "relaxation zones are sized to each flume)")]
ROWS = ROOT / "bench" / "results" / "accuracy_sweep.jsonl"

SCORES = {"flume": "RMSE/H at mid-flume vs theory",
          "dambreak": "RMS front error vs Martin & Moyce (T ≤ 3)",
          "coupled": "RMSE/H at the flat-bed gauge vs Boussinesq-only"}


def meta_of(table: Path) -> dict[str, str]:
    """The command, date and machine that made ``table`` (its .meta.json)."""
    return json.loads(table.with_suffix(".meta.json").read_text())


def result_rows(records: list[dict[str, Any]], meta: dict[str, str]) -> list[dict[str, Any]]:
    """One results row per (case, method, dp): its repeats' mean error and range, mean wall time,
    and how many ran through; in the sweep's order."""
    groups: dict[tuple[str, str, float], list[dict[str, Any]]] = {}
    for r in records:
        groups.setdefault((r["case"], r["method"], float(r["dp"])), []).append(r)
    stats = {(g["case"], g["method"], g["dp"]): g for g in sweeps.repeat_groups(records)}
    rows = []
    for (case, method, dp), rs in groups.items():
        ok = [r for r in rs if r.get("status") == "ok" and r.get("error")]
        measured: dict[str, Any] = {"method": method, "dp_m": float(f"{dp:.4g}")}
        ratio = rs[0].get("H_over_dp")
        if ratio:
            measured["resolution"] = f"{'a' if case == 'dambreak' else 'H'}/dp {float(ratio):.3g}"
        if g := stats.get((case, method, dp)):   # the repeats that ran through
            measured["error"] = f"{100 * g['error']:.2f} %" + (
                f" ({100 * g['error_min']:.2f}-{100 * g['error_max']:.2f})" if g["n"] > 1 else "")
            measured["wall_s"] = float(f"{g['wall_s']:.3g}")
            measured["particles"] = ok[0].get("particles")
        statuses = sorted({r.get("status") for r in rs})
        measured["status"] = (f"{len(ok)} of {len(rs)} ok" if len(rs) > 1 else statuses[0]) + (
            "" if len(ok) == len(rs) else f" ({', '.join(s for s in statuses if s != 'ok')})")
        rows.append({"bench": "accuracy_sweep", "question": "accuracy",
                     "case": f"{case}: {SCORES[case.split('_')[0]]}", "measured": measured,
                     "command": meta["made_by"], "date": meta.get("date", ""),
                     "machine": meta.get("machine", "")})
    return rows


def all_rows() -> list[dict[str, Any]]:
    """The results rows of every chart's data, in CHARTS order."""
    return [row for tables, _, _ in CHARTS for data in tables
            for row in result_rows(sweeps.read_csv(data), meta_of(data))]


def main() -> None:
    for tables, figure, _ in CHARTS:
        records = [r for data in tables for r in sweeps.read_csv(data)]
        title = "\n".join(sweeps.chart_title(meta_of(data)) for data in tables)
        sweeps.plot_accuracy(records, figure, title=title)
        print(f"wrote {figure.relative_to(ROOT)} from "
              f"{', '.join(str(d.relative_to(ROOT)) for d in tables)}")
    ROWS.write_text("".join(json.dumps(r, ensure_ascii=False) + "\n" for r in all_rows()),
                    encoding="utf-8")
    print(f"wrote {ROWS.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
