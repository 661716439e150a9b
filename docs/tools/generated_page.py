"""The command line of every page generator in docs/tools: the page on stdout, or with
``--check`` exit 1 (and say how to regenerate it) when the committed page differs from a fresh one."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Callable

ROOT = Path(__file__).resolve().parents[2]


def page_main(argv: list[str] | None, description: str, tool: Path, page: Path,
              render: Callable[[], str]) -> int:
    """The ``main`` of generator script ``tool``, which writes ``page`` with ``render()``."""
    tool, page = tool.resolve().relative_to(ROOT), page.resolve().relative_to(ROOT)
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--check", action="store_true", help=f"exit 1 if {page} differs from a fresh one")
    args = ap.parse_args(argv)
    text = render()
    if args.check:
        if (ROOT / page).read_text(encoding="utf-8") != text:
            print(f"{page} is stale: run python {tool} > {page}", file=sys.stderr)
            return 1
        return 0
    sys.stdout.write(text)
    return 0
