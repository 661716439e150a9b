"""The command line never surprises (issue 16 items 6-7): refuses to overwrite, honours or
refuses every option, one-line errors, exit 130 on Ctrl-C, defaults in --help, progress that
suits a terminal and a log."""

from __future__ import annotations

import argparse
import importlib
import io
import json
import socket
import tomllib
from pathlib import Path
from types import SimpleNamespace

import pytest

import wavesph.cli
from sph_core import progress

ROOT = Path(__file__).resolve().parents[1]
TANK = ROOT / "examples" / "scenes" / "still_water_tank.toml"


def test_version(capsys):
    with pytest.raises(SystemExit) as exc:
        wavesph.cli.main(["--version"])
    assert exc.value.code == 0 and capsys.readouterr().out.startswith("wavesph ")


@pytest.mark.parametrize("name", sorted(wavesph.cli.COMMANDS))
def test_every_option_with_a_default_shows_it_in_help(name):
    parser = argparse.ArgumentParser(formatter_class=wavesph.cli.HelpFormatter)
    importlib.import_module(wavesph.cli.COMMANDS[name][0]).add_arguments(parser)
    text = parser.format_help()
    for action in parser._actions:
        if action.option_strings and action.default not in (None, False, argparse.SUPPRESS):
            assert f"(default: {action.default})" in text or "default" in (action.help or ""), \
                action.option_strings


@pytest.mark.parametrize("name", ["run", "demo", "couple", "waves"])
def test_one_spelling_for_output(name):
    parser = argparse.ArgumentParser()
    importlib.import_module(wavesph.cli.COMMANDS[name][0]).add_arguments(parser)
    spellings = {o for a in parser._actions for o in a.option_strings}
    assert {"-o", "--out"} <= spellings and "--output" not in spellings


def test_license_is_an_spdx_expression():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["license"] == "MIT"


def test_run_refuses_a_non_empty_out(tmp_path, capsys):
    (tmp_path / "probes.csv").write_text("an earlier run")
    assert wavesph.cli.main(["run", str(TANK), "-o", str(tmp_path)]) == 2
    assert "not empty" in capsys.readouterr().err
    assert [p.name for p in tmp_path.iterdir()] == ["probes.csv"]


def test_run_options_are_honoured(tmp_path, capsys):
    out = tmp_path / "run"
    code = wavesph.cli.main(["run", str(TANK), "--dp", "0.05", "--t-end", "0.02",
                             "--snapshot-every", "0.01", "--threads", "1", "--no-progress",
                             "--out", str(out)])
    assert code == 0
    meta = json.loads((out / "meta.json").read_text())
    assert meta["config"]["dp"] == 0.05 and meta["t"] == pytest.approx(0.02)
    assert meta["config"]["output"]["snapshot_every"] == 0.01 and meta["threads"] == 1
    assert len(list((out / "snapshots").glob("*.vtu"))) == 3  # t = 0, 0.01, 0.02
    err = capsys.readouterr().err
    assert "t=" not in err  # --no-progress: no progress line


def test_python_api_runs_a_scene_as_the_command_does(tmp_path):
    import wavesph
    from sph_core.scene import make_scene

    scene = wavesph.load_scene(TANK)
    data = scene.model_dump(mode="json")
    scene = make_scene({**data, "dp": 0.05, "t_end": 0.02,
                        "output": {**data["output"], "snapshot_every": 0.02}})
    sim = wavesph.run_scene(scene, tmp_path / "run", progress=False)
    assert sim.status == "completed" and sim.t == pytest.approx(0.02)
    gauges = wavesph.read_gauges(tmp_path / "run" / "probes.csv")
    assert list(gauges["t"]) == pytest.approx([0.0, 0.01, 0.02])
    assert json.loads((tmp_path / "run" / "meta.json").read_text())["status"] == "completed"


def test_python_m_wavesph_is_the_command(tmp_path):
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-m", "wavesph", "--help"], capture_output=True,
                         text=True, timeout=60, cwd=tmp_path)
    assert out.returncode == 0 and "usage: wavesph" in out.stdout
    assert all(name in out.stdout for name in wavesph.cli.COMMANDS)


def test_run_rejects_bad_overrides(tmp_path, capsys):
    assert wavesph.cli.main(["run", str(TANK), "--snapshot-every", "9", "-o", str(tmp_path / "a")]) == 2
    assert "snapshot_every" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:
        wavesph.cli.main(["run", str(TANK), "--dp", "-1"])
    assert exc.value.code == 2


def test_ctrl_c_is_one_line_exit_130_with_partial_results(tmp_path, capsys, monkeypatch):
    def interrupting(t_end, desc, every=0.0, stream=None):
        def update(sim):
            raise KeyboardInterrupt
        return update

    monkeypatch.setattr(progress, "progress_lines", interrupting)
    out = tmp_path / "run"
    code = wavesph.cli.main(["run", str(TANK), "--dp", "0.05", "--t-end", "0.05", "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 130 and f"partial results in {out}" in err and "Traceback" not in err
    assert json.loads((out / "meta.json").read_text())["status"] == "interrupted"


def test_first_run_says_it_compiles(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(progress, "kernels_cached", lambda: False)
    out = tmp_path / "run"
    assert wavesph.cli.main(["run", str(TANK), "--dp", "0.05", "--t-end", "0.01", "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert err.index("compiling kernels (first run only") < err.index("still_water_tank: t=")


def test_progress_off_a_terminal_is_throttled_lines():
    """Not on a terminal: plain lines, at most one per `every` seconds, and one at the end."""
    stream = io.StringIO()
    update = progress.progress_lines(1.0, "tank", every=3600.0, stream=stream)
    for k in range(1, 11):
        update(SimpleNamespace(t=0.1 * k, steps=10 * k, wall_time=0.01 * k))
    lines = stream.getvalue().splitlines()
    assert "\r" not in stream.getvalue() and len(lines) == 1
    assert lines[0].startswith("tank: t=1.000/1.000 s (100%)")
    stream = io.StringIO()
    update = progress.progress_lines(1.0, "tank", every=0.0, stream=stream)
    for k in range(1, 5):
        update(SimpleNamespace(t=0.1 * k, steps=10 * k, wall_time=0.01 * k))
    assert len(stream.getvalue().splitlines()) == 4


def test_demo_dambreak_honours_dp_and_t_end(tmp_path):
    out = tmp_path / "demo"
    assert wavesph.cli.main(["demo", "--dambreak", "--dp", "0.01", "--t-end", "0.02",
                             "--no-plot", "-o", str(out)]) == 0
    meta = json.loads((out / "meta.json").read_text())
    assert meta["config"]["dp"] == pytest.approx(0.01) and meta["t"] == pytest.approx(0.02)


def test_demo_dambreak_refuses_a_dp_that_does_not_divide_the_column(tmp_path, capsys):
    assert wavesph.cli.main(["demo", "--dambreak", "--dp", "0.03", "-o", str(tmp_path / "d")]) == 2
    assert "--dp" in capsys.readouterr().err


@pytest.mark.parametrize("cached", [False, True])
def test_demo_says_it_compiles_kernels_on_a_cold_cache(tmp_path, capsys, monkeypatch, cached):
    """ux.md F3: before the coupled demo's first window (minutes of numba on a fresh install)
    the demo says so, and only then."""
    import wavesph.cases.demo_flume

    def interrupted(*args, **kwargs):  # stands for the run: the line must come before it
        raise KeyboardInterrupt

    monkeypatch.setattr(progress, "kernels_cached", lambda: cached)
    monkeypatch.setattr(wavesph.cases.demo_flume, "run_demo", interrupted)
    assert wavesph.cli.main(["demo", "--no-plot", "-o", str(tmp_path / "d")]) == 130
    said = "compiling SPH kernels (first run only" in capsys.readouterr().err
    assert said is not cached


def test_serve_on_a_busy_port_is_one_line(tmp_path, capsys):
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        code = wavesph.cli.main(["serve", "--port", str(port), "--tcp-port", "0",
                                 "--runs-dir", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 1 and f"--port {port}" in err and "not free" in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_device_cuda_without_a_gpu_is_one_line_before_any_output(tmp_path, capsys, monkeypatch):
    import sph_core.cuda

    monkeypatch.setattr(sph_core.cuda, "unavailable_reason",
                        lambda: "no CUDA GPU or driver found (test)")
    out = tmp_path / "run"
    assert wavesph.cli.main(["run", str(TANK), "--device", "cuda", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.splitlines()[-1] == "wavesph run: device cuda: no CUDA GPU or driver found (test)"
    assert "Traceback" not in err and not out.exists()
    for argv in (["demo", "--dambreak", "--device", "cuda", "-o", str(tmp_path / "demo")],
                 ["serve", "--device", "cuda", "--port", "0", "--tcp-port", "0"]):
        assert wavesph.cli.main(argv) == 2
        err = capsys.readouterr().err
        assert err == f"wavesph {argv[0]}: device cuda: no CUDA GPU or driver found (test)\n"
    assert not (tmp_path / "demo").exists()


def test_an_unknown_device_is_refused(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        wavesph.cli.main(["run", str(TANK), "--device", "tpu"])
    assert exc.value.code == 2 and "invalid choice: 'tpu'" in capsys.readouterr().err
    scene = tmp_path / "tank.toml"
    scene.write_text(TANK.read_text() + '\n[run]\ndevice = "tpu"\n')
    assert wavesph.cli.main(["run", str(scene), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "run.device" in err and "'cpu' or 'cuda'" in err and len(err.splitlines()) == 1


@pytest.mark.parametrize("change, words", [
    (lambda text: text.replace("t_end = ", "t_end = inf #", 1), "t_end"),
    (lambda text: text.replace("dp = ", "dp = nan #", 1), "finite"),
    (lambda text: text.replace("dp = ", "dp = 1e-6 #", 1), "particles, above --max-particles"),
    (lambda text: text.encode() + b"\n# \xff\xfe", "not UTF-8"),
    (None, "cannot be read"),
])
def test_run_refuses_bad_scene_files_in_one_line(tmp_path, capsys, change, words):
    """No traceback, no allocation of 1e12 particles: one line naming the problem, rc 2."""
    scene = tmp_path / "scene.toml"
    if change is None:
        scene.mkdir()  # a directory given as the scene
    else:
        new = change(TANK.read_text())
        scene.write_bytes(new if isinstance(new, bytes) else new.encode())
    assert wavesph.cli.main(["run", str(scene), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("wavesph run: ") and "\n" not in err and words in err, err


@pytest.mark.parametrize("table, command", [('\n[source]\ntheory = "stokes"\nH = 0.04\nT = 1.4\n',
                                             "wavesph submit"),
                                            ('mode = "coupled"\n', "wavesph couple --scene")])
def test_run_refuses_a_scene_whose_open_ends_a_server_drives(tmp_path, capsys, table, command):
    # the same file makes waves through `submit`; `run` would step still water without a word
    demo = (ROOT / "examples" / "scenes" / "demo_beach_flume.toml").read_text()
    scene = tmp_path / "waves.toml"
    scene.write_text(table + demo if table.startswith("mode") else demo + table)
    assert wavesph.cli.main(["run", str(scene), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and command in err
    assert not (tmp_path / "out").exists()
