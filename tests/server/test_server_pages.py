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
    assert srv.http.get("/redoc", follow_redirects=False).headers["location"] == "/docs"
    assert srv.http.get("/openapi.json").json()["paths"]  # the schema the docs read


def _chromium() -> str | None:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return os.environ.get("WAVESPH_CHROMIUM")


def test_page_in_a_real_browser_follows_a_run(tmp_path):
    """Headless Chromium (Debian's, through Playwright): start a standalone run from the page,
    see its progress move and a gauge trace drawn; the screenshot is kept as an artifact
    (WAVESPH_ARTIFACTS, default tmp)."""
    playwright = pytest.importorskip("playwright.sync_api", reason="Playwright for Python is not installed")
    browser_path = _chromium()
    if browser_path is None:
        pytest.skip("no Chromium installed (apt-get install chromium)")
    body = {"mode": "standalone", "scene": scene(t_end=3.0, dp=0.02)}
    import json

    with live_server(tmp_path) as srv, playwright.sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=browser_path, headless=True)
        page = browser.new_page()
        page.goto(srv.url + "/")
        page.fill("#body", json.dumps(body))
        page.click("#start")
        page.wait_for_function("document.querySelector('#selected').textContent !== 'none'")
        page.wait_for_function("Number(document.querySelector('#plot').dataset.points || 0) > 5",
                               timeout=120_000)
        first = page.text_content("#progress")
        page.wait_for_function(f"document.querySelector('#progress').textContent !== {json.dumps(first)}",
                               timeout=60_000)
        out = Path(os.environ.get("WAVESPH_ARTIFACTS", tmp_path))
        out.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(out / "run_monitor.png"))
        browser.close()
