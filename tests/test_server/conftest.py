"""Server test fixtures (helpers in server_harness.py)."""

from __future__ import annotations

import pytest

from server_harness import live_server
from sph_engine_double import EngineDouble


@pytest.fixture
def engines():
    """The engine doubles built by the server, in order, for inspection."""
    return []


@pytest.fixture
def factory(engines):
    def make(request, run_dir, **kw):
        engine = EngineDouble(request, **kw)
        engines.append(engine)
        return engine
    return make


@pytest.fixture
def srv(tmp_path, factory):
    with live_server(tmp_path, factory, idle_timeout=10.0, hello_timeout=5.0) as s:
        yield s
