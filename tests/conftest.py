"""Shared pytest setup, and the test tiers (Makefile: test-unit, test, test-slow).

- ``slow``: long physics runs, marked in their modules, excluded by default (pyproject addopts).
- ``unit``: calls no numba kernel and takes under 1 s; applied here from ``UNIT`` (whole
  modules, minus ``NOT_UNIT``), so a new module starts outside the quick tier until it is
  listed. A ``unit`` test that compiles or loads a numba kernel fails with the kernel's name
  (the check sees a kernel's first call in the process, so ``make test-unit`` catches any).
- everything else is the default tier: steps a Simulation, a Boussinesq model or a demo.
"""

import shutil
import subprocess
from pathlib import Path

import pytest

from kernel_calls import KERNEL_CALLS as _kernels

C_CLIENT_SOURCE = Path(__file__).resolve().parents[1] / "examples" / "c_client" / "wsph_client.c"
TESTS = Path(__file__).resolve().parent

# the quick tier, as paths under tests/ (a folder ends with "/"): each test measured under 1 s
# (`pytest --durations=0`); kernel calls are checked by the hooks below (kernel_calls.py)
UNIT: tuple[str, ...] = (
    "test_protocol/", "test_server/", "test_cli.py", "test_layers.py", "test_analysis.py",
    "test_wave_client/test_theories.py", "test_wave_client/test_solitary_theory.py",
    "test_wave_client/test_client.py", "test_wave_client/test_client_absorption.py",
    "test_cases/test_particle_noise.py", "test_cases/test_wall_impact.py",
    "test_sph_core/test_scene.py", "test_sph_core/test_geometry.py",
)
NOT_UNIT: frozenset[str] = frozenset({  # "path" or "path::test_name" (any parametrisation)
    # numba kernels: a real SPH engine, a Simulation, the Boussinesq model
    "test_server/test_server_flume.py",
    "test_cases/test_wall_impact.py::test_gate_holds_the_column_above_its_edge",
    "test_server/test_server_basin_3d.py",
    "test_server/test_standalone_theory.py::test_standalone_theory_run_equals_the_coupled_run",
    "test_server/test_standalone_theory.py::test_cancelled_theory_run_keeps_its_data_and_resumes_to_the_end",
    "test_server/test_standalone_theory.py::test_standalone_solitary_source_brings_its_crest_to_the_inlet",
    "test_server/test_server_bodies.py::test_standalone_run_serves_its_body_series",
    "test_server/test_server_c_client.py::test_c_client_drives_the_sph_flume",
    "test_cli.py::test_run_options_are_honoured",
    "test_cli.py::test_python_api_runs_a_scene_as_the_command_does",
    "test_cli.py::test_demo_dambreak_honours_dp_and_t_end",
    "test_wave_client/test_client.py::test_cli_couples_the_boussinesq_model",
    "test_wave_client/test_solitary_theory.py::test_boussinesq_approach_delivers_the_theorys_wave_at_x0",
    "test_server/test_server_faults.py::test_waiting_coupled_runs_do_not_hold_the_stepping_slots",
    "test_cli.py::test_ctrl_c_is_one_line_exit_130_with_partial_results",
    "test_cli.py::test_first_run_says_it_compiles",
    "test_server/test_server_http.py::test_standalone_run_with_sph_core",
    "test_server/test_server_http.py::test_cancel_standalone_and_unknown_run",
    "test_server/test_server_pages.py::test_particles_endpoint_serves_the_last_snapshot",
    "test_server/test_server_pages.py::test_page_in_a_real_browser_follows_a_run",
    "test_server/test_server_pages.py::test_api_docs_render_in_a_headless_browser",
    "test_server/test_server_pages.py::test_page_errors_stay_as_sentences_and_the_form_takes_a_scene_file",
    # over 1 s (timeouts and delays scaled down, but still there)
    "test_server/test_server_ws_pings.py::test_a_client_busy_longer_than_the_ping_timeout_keeps_its_run",
    "test_server/test_server_ws_pings.py::test_a_client_dropped_by_an_opted_in_ping_timeout_keeps_its_data_and_resumes",
    "test_server/test_server_keepalive.py::test_working_frames_before_welcome_while_the_run_is_not_ready",
    "test_server/test_server_keepalive.py::test_working_frames_only_for_a_client_that_asked",
    "test_server/test_server_keepalive.py::test_wave_client_waits_through_working_frames",
    "test_server/test_server_coupling.py::test_silent_client_times_out",
    "test_server/test_server_http.py::test_serve_cli_refuses_public_bind_without_token",
    "test_server/test_server_wave_client.py::test_wavesph_couple_waits_while_its_run_is_queued",
    "test_wave_client/test_client.py::test_vanished_peer_times_out",
    "test_server/test_server_reliability.py::test_incomplete_request_head_is_closed_after_header_timeout",
})


def _is_unit(item: pytest.Item) -> bool:
    path = Path(str(item.fspath)).resolve().relative_to(TESTS).as_posix()
    if not any(path == u or (u.endswith("/") and path.startswith(u)) for u in UNIT):
        return False
    name = f"{path}::{getattr(item, 'originalname', item.name)}"
    return not {path, name} & NOT_UNIT and item.get_closest_marker("slow") is None


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        if _is_unit(item):
            item.add_marker(pytest.mark.unit)


_SEEN = pytest.StashKey[int]()


@pytest.hookimpl(wrapper=True)
def pytest_runtest_setup(item: pytest.Item):
    item.stash[_SEEN] = len(_kernels.names)
    return (yield)


@pytest.hookimpl(wrapper=True)
def pytest_runtest_call(item: pytest.Item):
    result = yield
    new = _kernels.names[item.stash.get(_SEEN, len(_kernels.names)):]
    if new and item.get_closest_marker("unit") is not None:
        pytest.fail(f"a `unit` test called numba kernels ({', '.join(sorted(set(new))[:5])}): "
                    "list it in NOT_UNIT (tests/conftest.py)", pytrace=False)
    return result


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
