"""`wavesph` command line: a thin dispatcher.

Each subcommand is one module of this package (run, serve, couple, waves, demo) exposing
``add_arguments(parser)`` and ``main(args) -> int``; those two names are the subcommand interface,
the same in every module by design. Only the chosen subcommand's module is imported, and each
imports its own layer only (``couple`` and ``waves``: wave_client and protocol), so a wave-model
user running ``wavesph couple`` never loads the SPH solver (or numba).
"""

from __future__ import annotations

import argparse
import importlib
import sys

# name -> (module, one-line help)
COMMANDS: dict[str, tuple[str, str]] = {
    "demo": ("wavesph.cli.demo", "coupled wave-SPH flume with a beach on embedded defaults "
                                 "(--dambreak: the standalone dam break)"),
    "run": ("wavesph.cli.run", "run an SPH scene (TOML) standalone"),
    "serve": ("wavesph.cli.serve", "start the SPH coupling server (HTTP + WebSocket + TCP)"),
    "submit": ("wavesph.cli.submit", "create a run on a server from a scene file (TOML)"),
    "couple": ("wavesph.cli.couple", "couple a wave model to a run on a server (--scene: "
                                     "create it from a scene file first)"),
    "waves": ("wavesph.cli.waves", "run the Boussinesq wave model alone"),
    "bench": ("wavesph.cli.bench", "speed-accuracy sweep and stability suite on dask "
                                   "(accuracy | stability)"),
    "analyse": ("wavesph.cli.analyse", "wave height and period per gauge, mean overtopping "
                                       "discharge and load peaks of a run directory"),
    "plan": ("wavesph.cli.plan", "propose dp, SPH zone, coupling window and method for a scene, "
                                 "with predicted error and wall time"),
}

OUR_PACKAGES = {"protocol", "sph_core", "wave_client", "server", "wavesph"}


def version() -> str:
    """The installed wavesph version (from its metadata), or "unknown" in a bare checkout."""
    from importlib import metadata

    try:
        return metadata.version("wavesph")
    except metadata.PackageNotFoundError:
        return "unknown"


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Defaults in every --help: "(default: X)" after each option that has one."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        # an option whose default is None/False says its default in words (or has none)
        if action.default in (None, False) or "default" in (action.help or ""):
            return action.help
        return super()._get_help_string(action)


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(prog="wavesph", description=__doc__.splitlines()[0],
                                     formatter_class=HelpFormatter)
    parser.add_argument("--version", action="version", version=f"wavesph {version()}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (_, help_text) in COMMANDS.items():
        sub.add_parser(name, help=help_text, add_help=False)
    if not argv or argv[0] not in COMMANDS:
        parser.parse_args(argv or ["--help"])  # --help / --version exit here
        return 2
    name = argv[0]
    module_name, help_text = COMMANDS[name]
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        if exc.name and exc.name.split(".")[0] in OUR_PACKAGES:  # a build without that layer
            print(f"wavesph {name}: not available in this build ({exc})", file=sys.stderr)
            return 2
        raise
    cmd_parser = argparse.ArgumentParser(prog=f"wavesph {name}", description=help_text,
                                         formatter_class=HelpFormatter)
    module.add_arguments(cmd_parser)
    args = cmd_parser.parse_args(argv[1:])
    try:
        return int(module.main(args) or 0)
    except KeyboardInterrupt:  # a subcommand that does not say more about its partial results
        print(f"\nwavesph {name}: interrupted", file=sys.stderr)
        return 130

