"""Argument helpers shared by the subcommands (one rule for output directories and numbers)."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from sph_core.scene import DEVICES


def positive_float(text: str) -> float:
    """argparse type: a finite number > 0."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not (v > 0 and math.isfinite(v)):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text}")
    return v


def add_device_argument(parser: argparse.ArgumentParser, what: str) -> None:
    """``--device cpu|cuda``: where the SPH steps run (``what`` says for which runs)."""
    parser.add_argument("--device", choices=DEVICES, default=None,
                        help=f"where the SPH steps run{what}: cpu, or cuda (an NVIDIA GPU; "
                             "closed tanks with the kdk integrator, docs/developer/gpu.md) "
                             "(default: the scene's [run] device, else cpu)")


def device_problem(command: str, device: str | None) -> bool:
    """True (after a one-line message) if ``device`` is cuda and no GPU (or simulator) is here."""
    if device != "cuda":
        return False
    from sph_core.cuda import unavailable_reason

    reason = unavailable_reason()
    if reason is not None:
        print(f"wavesph {command}: device cuda: {reason}", file=sys.stderr)
        return True
    return False


def refuse_non_empty(command: str, out: Path) -> bool:
    """True (after a one-line message) if ``out`` exists and is not an empty directory: a run
    never overwrites an earlier one's files."""
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        print(f"wavesph {command}: --out {out} exists and is not empty: choose a new directory",
              file=sys.stderr)
        return True
    return False
