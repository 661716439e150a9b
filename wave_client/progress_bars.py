"""Progress bars that suit a terminal and a log: off a terminal (CI, a pipe) tqdm redraws at
most every 30 s, so a log gets a few short updates instead of one 100 kB line."""

from __future__ import annotations

import sys

TQDM_INTERVAL = 0.1 if sys.stderr.isatty() else 30.0  # tqdm mininterval [s]
