"""Bounded property test of POST /runs (issue 15's fault sweep kept as a test): whatever a client
puts in a field, the answer is a 201 or a 4xx with a strict-JSON body, never a 500."""

from __future__ import annotations

import json

import pytest
from fastapi.testclient import TestClient
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from server.main import create_app
from server.settings import Settings

from server_harness import scene
from sph_engine_double import EngineDouble

# where a value goes: the fields of a coupled run's body, nested ones included
PATHS = [
    ("scene", "dp"), ("scene", "t_end"), ("scene", "t_start"), ("scene", "still_water_level"),
    ("scene", "name"), ("scene", "tank"), ("scene", "tank", "x1"), ("scene", "tank", "z0"),
    ("scene", "water_blocks"), ("scene", "water_blocks", 0, "z1"), ("scene", "beds"),
    ("scene", "probes"), ("scene", "probes", 0, "x"), ("scene", "probes", 0, "name"),
    ("scene", "constants"), ("scene", "constants", "g"), ("scene", "constants", "h_over_dp"),
    ("scene", "open_boundaries"), ("scene", "open_boundaries", 0, "side"),
    ("scene", "open_boundaries", 0, "gauge_offset"), ("scene", "output", "probe_every"),
    ("coupling",), ("coupling", "window_max"), ("coupling", "z_ref"), ("source",), ("mode",),
]

leaves = (st.none() | st.booleans() | st.integers(-10**400, 10**400)
          | st.floats(allow_nan=True, allow_infinity=True) | st.text(max_size=12)
          | st.sampled_from([1e308, -1e308, 5e-324, 1e-300, 0.0, -0.0]))
values = st.recursive(leaves, lambda inner: st.lists(inner, max_size=3)
                      | st.dictionaries(st.text(max_size=6), inner, max_size=3), max_leaves=6)


def _strict(token: str):
    raise AssertionError(f"{token} in a reply: not JSON")


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    s = Settings(runs_dir=tmp_path_factory.mktemp("fuzz") / "runs", tcp_port=None,
                 max_queued=1000, max_waiting=1)
    with TestClient(create_app(s, lambda request, run_dir: EngineDouble(request)),
                    base_url="http://127.0.0.1") as c:  # a loopback server checks the Host
        yield c


def _put(body: dict, path: tuple, value) -> None:
    target = body
    for key in path[:-1]:
        if isinstance(target, dict):
            target = target.setdefault(key, {})
        elif isinstance(target, list) and isinstance(key, int) and key < len(target):
            target = target[key]
        else:
            return
    if isinstance(target, dict):
        target[path[-1]] = value
    elif isinstance(target, list) and isinstance(path[-1], int) and path[-1] < len(target):
        target[path[-1]] = value


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(changes=st.lists(st.tuples(st.sampled_from(PATHS), values), min_size=1, max_size=3))
def test_any_field_value_is_answered_without_a_500(client, changes):
    body = {"scene": scene(open_boundaries=[{"side": "left"}]), "mode": "coupled"}
    for path, value in changes:
        _put(body, path, value)
    r = client.post("/runs", content=json.dumps(body, allow_nan=True),
                    headers={"content-type": "application/json"})
    assert r.status_code in (201, 400, 413, 422, 429), (r.status_code, r.text[:500])
    reply = json.loads(r.text, parse_constant=_strict)
    if r.status_code == 422:
        assert all(set(e) == {"loc", "msg", "type"} for e in reply["detail"])
