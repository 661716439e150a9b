"""Shared pytest setup. Long physics runs are marked ``slow`` and excluded by default."""

import shutil
import subprocess
from pathlib import Path

import pytest

C_CLIENT_SOURCE = Path(__file__).resolve().parents[1] / "examples" / "c_client" / "wsph_client.c"


@pytest.fixture(scope="session")
def c_client(tmp_path_factory) -> Path:
    """The C example client, built once with the build line of examples/c_client/README.md."""
    gcc = shutil.which("gcc")
    if gcc is None:
        pytest.skip("gcc not found on PATH: the C example client cannot be compiled here")
    exe = tmp_path_factory.mktemp("cbuild") / "wsph_client"
    build = subprocess.run([gcc, "-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", "-O2",
                            "-o", str(exe), str(C_CLIENT_SOURCE), "-lm"], capture_output=True, text=True)
    assert build.returncode == 0, build.stderr
    return exe
