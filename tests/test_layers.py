"""The package layering and the project's names cannot rot silently.

- The import-linter contracts of pyproject.toml ([tool.importlinter]; docs/developer/architecture.md says
  why each holds) are kept.
- `wavesph couple` with a theory runs without loading the SPH solver, numba, the server or the
  cases.
- Every public top-level name (function, class, module-level constant) and every module name is
  defined once across the packages; the deliberate exceptions are listed below with their reason.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from collections import defaultdict
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("protocol", "sph_core", "wave_client", "server", "wavesph")
SCRIPTS = ("bench", "examples")  # scripts: their names are checked, their own `main` is not

# name -> the files that may define it, and why. A name defined in one more place, or no longer
# defined twice, fails the test: update this list with the code.
ALLOWED: dict[str, tuple[set[str], str]] = {
    # deliberate
    "module couple": ({"wavesph/cli/couple.py", "server/routers/couple.py"},
                      "`wavesph couple` and the /runs/{id}/couple endpoint: each named for its "
                      "command or URL"),
    "log": ({"server/doors.py", "server/main.py", "server/run_manager.py", "server/store.py",
             "server/tcp.py", "server/theory_client.py"},
            "the logging convention: one `log` per module"),
    "router": ({"server/routers/couple.py", "server/routers/runs.py"},
               "the FastAPI convention: one `router` per routers module"),
    "load_scene": ({"sph_core/scene.py", "wavesph/__init__.py"},
                   "the public API's one-line wrapper: `import wavesph` loads no solver (numba) "
                   "until a call needs it"),
}
# the subcommand interface (wavesph/cli/*.py) and a script's entry point: the same by design
INTERFACE = {"main", "add_arguments"}


def _top_level_names(path: Path) -> list[str]:
    names = []
    for node in ast.parse(path.read_text(), filename=str(path)).body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.append(node.name)
        elif isinstance(node, ast.Assign):
            names += [t.id for t in node.targets if isinstance(t, ast.Name)]
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.append(node.target.id)
    return [n for n in names if not n.startswith("_")]


def defined_names() -> dict[str, set[str]]:
    """Public name -> the files (relative to the repo root) defining it at top level; module
    names of the packages as "module <name>"."""
    where: dict[str, set[str]] = defaultdict(set)
    for top in PACKAGES + SCRIPTS:
        for path in sorted((ROOT / top).rglob("*.py")):
            rel = path.relative_to(ROOT).as_posix()
            for name in _top_level_names(path):
                if name in INTERFACE and (top in SCRIPTS or rel.startswith("wavesph/cli/")):
                    continue
                where[name].add(rel)
            if top in PACKAGES and path.stem not in ("__init__", "__main__"):
                where[f"module {path.stem}"].add(rel)
    return where


def test_public_names_are_unique_or_listed():
    where = defined_names()
    twice = {name: files for name, files in where.items() if len(files) > 1}
    unlisted = {n: sorted(f) for n, f in twice.items() if n not in ALLOWED or f != ALLOWED[n][0]}
    assert not unlisted, f"names defined in more than one place (rename, or list with a reason): {unlisted}"
    stale = sorted(n for n in ALLOWED if n not in twice)
    assert not stale, f"listed as duplicates but defined once now: remove from ALLOWED: {stale}"


def test_import_contracts_are_kept():
    importlinter_cli = pytest.importorskip("importlinter.cli")
    code = importlinter_cli.lint_imports(config_filename=str(ROOT / "pyproject.toml"),
                                         no_cache=True, no_logo=True)
    assert code == 0, "an import crosses the layering of pyproject.toml [tool.importlinter]: see above"


def test_couple_with_a_theory_loads_no_sph_solver_numba_or_server():
    # a fresh interpreter: this one has numba loaded already. Port 1 refuses at once, so the
    # command goes through argument checks, the theory and the client's connect, then exits 1.
    probe = (
        "import sys, wavesph.cli\n"
        "code = wavesph.cli.main(['couple', '--url', 'tcp://127.0.0.1:1', '--run-id', 'r1',\n"
        "    '--model', 'stokes', '--H', '0.04', '--T', '1.4', '--d', '0.24', '--no-progress'])\n"
        "heavy = ('numba', 'sph_core', 'server', 'wavesph.cases', 'wavesph.studies',\n"
        "         'wavesph.local_server')\n"
        "loaded = [h for h in heavy if any(m == h or m.startswith(h + '.') for m in sys.modules)]\n"
        "print(code, ','.join(loaded))\n")
    out = subprocess.run([sys.executable, "-c", probe], cwd=ROOT, capture_output=True, text=True,
                         timeout=120, env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    code, _, loaded = out.stdout.strip().rpartition("\n")[2].partition(" ")
    assert code == "1", out.stdout + out.stderr  # the connection was refused: the run failed
    assert loaded == "", f"`wavesph couple --model stokes` loaded {loaded}"
