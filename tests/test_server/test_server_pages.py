"""The run monitor at / and the offline API docs (issue 16 item 2)."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from server_harness import live_server, scene


def test_page_and_its_chart_are_served_without_a_cdn(srv):
    page = srv.http.get("/")
    assert page.status_code == 200 and page.headers["content-type"].startswith("text/html")
    html = page.text
    for needle in ('src="/static/plot.js"', "/runs/", "/events", 'id="runs"', 'id="plot"',
                   'id="cancel"', 'id="resume"', 'id="start"', "format=csv"):
        assert needle in html, needle
    assert "http://" not in html.replace("http://127", "") and "https://" not in html
    js = srv.http.get("/static/plot.js")
    assert js.status_code == 200 and "wavesphPlot" in js.text and "SPDX-License-Identifier: MIT" in js.text


def test_api_docs_come_from_the_package(srv):
    docs = srv.http.get("/docs")
    assert docs.status_code == 200
    assert "/static/swagger/swagger-ui-bundle.js" in docs.text and "cdn" not in docs.text.lower()
    bundle = srv.http.get("/static/swagger/swagger-ui-bundle.js")
    assert bundle.status_code == 200 and len(bundle.content) > 500_000
    assert srv.http.get("/static/swagger/swagger-ui.css").status_code == 200
    redoc = srv.http.get("/redoc")
    assert redoc.status_code == 200 and "/static/swagger/redoc.standalone.js" in redoc.text
    assert "fonts.googleapis" not in redoc.text
    assert srv.http.get("/static/swagger/redoc.standalone.js").status_code == 200
    assert srv.http.get("/openapi.json").json()["paths"]  # the schema the docs read


def test_the_bundled_swagger_ui_reads_the_served_openapi_version(srv):
    """Swagger UI 4 renders "Unable to render this definition" for OpenAPI 3.1, which FastAPI
    writes; 3.1 is read from Swagger UI 5.0.0 on. The version is the bundle's own
    PACKAGE_VERSION, what the browser runs."""
    import re

    spec = srv.http.get("/openapi.json").json()["openapi"]
    bundle = srv.http.get("/static/swagger/swagger-ui-bundle.js").text
    found = re.search(r'PACKAGE_VERSION:"(\d+)\.(\d+)\.(\d+)"', bundle)
    assert found, "no PACKAGE_VERSION in the served Swagger UI bundle"
    ui = tuple(int(v) for v in found.groups())
    oas = tuple(int(v) for v in spec.split(".")[:2])
    supported = (3, 0) if ui < (5, 0, 0) else (3, 1)
    assert oas <= supported, f"Swagger UI {ui} cannot render OpenAPI {spec}"


def test_api_docs_render_in_a_headless_browser(srv):
    """What the browser shows: Chromium's DOM of /docs after the scripts ran lists the
    operations (POST /runs), not "Unable to render this definition"."""
    import subprocess

    chromium = _chromium()
    if chromium is None:
        pytest.skip("no Chromium (apt-get install chromium, or WAVESPH_CHROMIUM)")
    try:
        dom = subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu",
                              "--virtual-time-budget=15000", "--dump-dom", f"{srv.url}/docs"],
                             capture_output=True, text=True, timeout=120).stdout
    except subprocess.TimeoutExpired:
        pytest.skip("Chromium did not finish in 120 s (a loaded machine)")
    assert "Unable to render" not in dom
    assert "opblock-summary-path" in dom and 'data-path="/runs"' in dom, dom[-2000:]


def _chromium() -> str | None:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return os.environ.get("WAVESPH_CHROMIUM")


def test_page_in_a_real_browser_follows_a_run(tmp_path):
    """Headless Chromium (Debian's, through Playwright): start a *coupled* run from the page,
    couple a wave client to it (a linear wave, in a thread), see its progress move, a gauge
    trace drawn and the last snapshot's particles scattered; the screenshot is kept as an
    artifact (WAVESPH_ARTIFACTS, default tmp)."""
    playwright = pytest.importorskip("playwright.sync_api", reason="Playwright for Python is not installed")
    browser_path = _chromium()
    if browser_path is None:
        pytest.skip("no Chromium installed (apt-get install chromium)")
    import json
    import threading

    from wave_client.coupling import CouplingOptions, couple
    from wave_client.theories import build_theory

    body = {"mode": "coupled", "coupling": {"window_max": 0.05},
            "scene": scene(t_end=3.0, dp=0.02, open_boundaries=[{"side": "left"}],
                           output={"probe_every": 0.05, "snapshot_every": 0.5})}
    with live_server(tmp_path) as srv, playwright.sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=browser_path, headless=True)
        page = browser.new_page()
        page.goto(srv.url + "/")
        page.fill("#body", json.dumps(body))
        page.click("#start")
        page.wait_for_function("document.querySelector('#selected').textContent !== 'none'")
        run_id = page.text_content("#selected")

        def client() -> None:
            try:
                couple(f"ws://127.0.0.1:{srv.port}/runs/{run_id}/couple",
                                     lambda w: build_theory("linear", height=0.02, period=1.0,
                                                            depth=w.depth, ramp_time=1.0),
                                     CouplingOptions(window=0.05), timeout=300, progress=False)
            except Exception:  # noqa: BLE001 -- the cancel at the end closes the socket
                pass

        thread = threading.Thread(target=client, daemon=True)
        thread.start()
        page.wait_for_function("Number(document.querySelector('#plot').dataset.points || 0) > 5",
                               timeout=240_000)
        first = page.text_content("#progress")
        page.wait_for_function(f"document.querySelector('#progress').textContent !== {json.dumps(first)}",
                               timeout=60_000)
        page.wait_for_function("Number(document.querySelector('#particles').dataset.points || 0) > 100",
                               timeout=60_000)
        page.select_option("#field", "speed")
        page.wait_for_function("document.querySelector('#snapinfo').textContent.startsWith('t = ')")
        out = Path(os.environ.get("WAVESPH_ARTIFACTS", tmp_path))
        out.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(out / "run_monitor.png"), full_page=True)
        browser.close()
        assert srv.http.get(f"/runs/{run_id}").json()["windows"] >= 2   # the client drove it
        srv.http.delete(f"/runs/{run_id}")   # the client then sees the server close the socket
        thread.join(timeout=60)


def test_particles_endpoint_serves_the_last_snapshot(tmp_path):
    """GET /runs/{id}/particles: the newest snapshot's positions and the chosen field; 404 before
    the first snapshot (here a standalone still tank, snapshots every 0.1 s)."""
    with live_server(tmp_path) as srv:
        r = srv.http.post("/runs", json={"mode": "standalone", "scene": scene(
            t_end=0.2, output={"probe_every": 0.05, "snapshot_every": 0.1})})
        run_id = r.json()["id"]
        srv.wait_state(run_id, "finished", timeout=300)
        d = srv.http.get(f"/runs/{run_id}/particles", params={"field": "pressure"}).json()
        assert d["t"] == pytest.approx(0.2) and len(d["x"]) == len(d["z"]) == len(d["value"]) > 50
        fluid = [v for v, k in zip(d["value"], d["kind"]) if k == 0]
        assert max(fluid) == pytest.approx(1000 * 9.81 * 0.3, rel=0.25)   # hydrostatic at the floor
        s = srv.http.get(f"/runs/{run_id}/particles", params={"field": "speed"}).json()
        assert all(v >= 0 for v in s["value"])
        assert srv.http.get(f"/runs/{run_id}/particles", params={"field": "rho"}).status_code == 422
        r2 = srv.http.post("/runs", json={"mode": "standalone", "scene": scene(t_end=0.05)})
        srv.wait_state(r2.json()["id"], "finished", timeout=300)
        assert srv.http.get(f"/runs/{r2.json()['id']}/particles").status_code == 404


DEMO_TOML = Path(__file__).resolve().parents[2] / "examples" / "scenes" / "demo_beach_flume.toml"


def test_page_errors_stay_as_sentences_and_the_form_takes_a_scene_file(srv):
    """Headless Chromium: a refused start reads one line per field and survives the table's
    refresh (it was wiped within 2 s); a TOML scene file starts a run, listed with its scene's
    name; no runs yet is said, not a blank table."""
    playwright = pytest.importorskip("playwright.sync_api", reason="Playwright for Python is not installed")
    browser_path = _chromium()
    if browser_path is None:
        pytest.skip("no Chromium installed (apt-get install chromium)")
    with playwright.sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=browser_path, headless=True)
        page = browser.new_page()
        page.goto(srv.url + "/")
        page.wait_for_function("document.querySelector('#runs').textContent.includes('no runs yet')")
        assert page.is_disabled("#cancel") and page.is_disabled("#resume")   # nothing selected
        page.fill("#body", '{"mode": "coupled", "scene": {"t_end": 1.0}}')
        page.click("#start")
        page.wait_for_function("document.querySelector('#err').textContent.includes('HTTP 422')")
        page.evaluate("refresh()")                  # a table refresh no longer wipes it
        err = page.text_content("#err")
        assert "scene.dp: Field required" in err.splitlines() and "[{" not in err
        page.fill("#body", "{not json")
        page.click("#start")
        assert page.text_content("#err").startswith("The body is not valid JSON")
        page.click("#dismiss")
        assert page.text_content("#err") == ""
        page.fill("#body", DEMO_TOML.read_text())   # the file as it is: coupled, waits for a client
        page.click("#start")
        page.wait_for_function("document.querySelector('#selected').textContent !== 'none'")
        run_id = page.text_content("#selected")
        page.evaluate("refresh()")
        row = page.text_content(f"tr[data-id='{run_id}']")
        assert "wavesph-demo" in row and page.text_content("#err") == ""
        page.wait_for_function("document.querySelector('#progress').textContent.startsWith('waiting_for_client')")
        assert page.is_enabled("#cancel") and page.is_disabled("#resume")
        page.select_option("#show", "force")        # the probe picker: no SPH probes here yet
        # the server unreachable (a restart): said once, the status not left at "waiting";
        # back: the notice goes and the live stream is reopened
        page.route("**/runs", lambda route: route.abort())
        page.evaluate("refresh()")
        assert page.text_content("#conn").startswith("server unreachable")
        assert page.text_content("#progress") == "status unknown: server unreachable"
        page.unroute("**/runs")
        page.evaluate("refresh()")
        assert page.text_content("#conn") == ""
        page.wait_for_function("document.querySelector('#progress').textContent.startsWith('waiting_for_client')")
        browser.close()
    assert srv.http.get(f"/runs/{run_id}").json()["name"] == "wavesph-demo"
