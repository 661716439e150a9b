"""`wavesph` command line: a thin dispatcher.

Each subcommand lives in the package that owns it and exposes ``add_arguments(parser)`` and
``main(args) -> int``. Only the chosen subcommand's module is imported, so a wave-model user
running ``wavesph couple`` never loads the SPH solver (or numba).
"""

from __future__ import annotations

import argparse
import importlib
import sys

# name -> (module, one-line help)
COMMANDS: dict[str, tuple[str, str]] = {
    "demo": ("server.demo_cli", "coupled wave-SPH flume with a beach on embedded defaults "
                                "(--dambreak: the standalone dam break)"),
    "run": ("sph_core.cli", "run an SPH scene (TOML) standalone"),
    "serve": ("server.cli", "start the SPH coupling server (HTTP + WebSocket + TCP)"),
    "couple": ("wave_client.couple_cli", "couple a wave model to a running server"),
    "waves": ("wave_client.waves_cli", "run the Boussinesq wave model alone"),
}


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(prog="wavesph", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (_, help_text) in COMMANDS.items():
        sub.add_parser(name, help=help_text, add_help=False)
    if not argv or argv[0] not in COMMANDS:
        parser.parse_args(argv or ["--help"])
        return 2
    name = argv[0]
    module_name, help_text = COMMANDS[name]
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        if exc.name and module_name.startswith(exc.name):
            print(f"wavesph {name}: not available in this build ({exc})", file=sys.stderr)
            return 2
        raise
    cmd_parser = argparse.ArgumentParser(prog=f"wavesph {name}", description=help_text)
    module.add_arguments(cmd_parser)
    return int(module.main(cmd_parser.parse_args(argv[1:])) or 0)


if __name__ == "__main__":
    raise SystemExit(main())
