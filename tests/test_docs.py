"""The generated docs pages are up to date, and every relative link in the docs resolves.

Pure Python and fast: the generators read pydantic models and JSON lines, no kernel runs.
"""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path
from types import ModuleType

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _load(name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(name, ROOT / "docs" / "tools" / f"{name}.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("tool, page", [
    ("scene_reference", "docs/user/scene_reference.md"),
    ("validation_tables", "docs/validation.md"),
])
def test_generated_page_is_current(tool: str, page: str) -> None:
    fresh = _load(tool).render()
    committed = (ROOT / page).read_text(encoding="utf-8")
    assert committed == fresh, (
        f"{page} is stale: regenerate it with `python docs/tools/{tool}.py > {page}`")


@pytest.mark.parametrize("tool, page", [
    ("scene_reference", "docs/user/scene_reference.md"),
    ("validation_tables", "docs/validation.md"),
])
def test_check_flag_exits_1_with_the_regenerate_command_when_stale(tool, page, monkeypatch, capsys) -> None:
    mod = _load(tool)
    assert mod.main(["--check"]) == 0
    monkeypatch.setattr(mod, "render", lambda: "not the page\n")
    assert mod.main(["--check"]) == 1
    assert capsys.readouterr().err.strip() == f"{page} is stale: run python docs/tools/{tool}.py > {page}"
    assert mod.main([]) == 0 and capsys.readouterr().out == "not the page\n"


def test_speed_accuracy_rows_are_the_shipped_sweeps() -> None:
    """The validation page's speed-accuracy rows and its chart come from the sweep data the plan
    fits (docs/tools/accuracy_chart.py), repeats merged into one row with their range."""
    import json

    from wavesph.studies import sweeps

    tool = _load("accuracy_chart")
    shipped = [json.loads(ln) for ln in tool.ROWS.read_text(encoding="utf-8").splitlines()]
    assert shipped == tool.all_rows(), "stale: run python docs/tools/accuracy_chart.py"
    for tables, figure, _ in tool.CHARTS:
        for data in tables:
            meta = tool.meta_of(data)
            records = sweeps.read_csv(data)
            rows = tool.result_rows(records, meta)
            assert len(rows) == len({(r["case"], r["method"], r["dp"]) for r in records})
            assert all(r["command"] == meta["made_by"] and r["date"] for r in rows)
        assert figure.exists()
    merged = tool.result_rows([{"case": "flume_V", "method": "m", "dp": 0.02, "H_over_dp": 3.0,
                                "error": e, "wall_s": w, "particles": 9, "status": s}
                               for e, w, s in ((0.05, 10.0, "ok"), (0.07, 14.0, "ok"),
                                               (None, None, "unstable"))], meta)
    assert [r["measured"] for r in merged] == [{
        "method": "m", "dp_m": 0.02, "resolution": "H/dp 3", "error": "6.00 % (5.00-7.00)",
        "wall_s": 12.0, "particles": 9, "status": "2 of 3 ok (unstable)"}]


def test_scene_reference_lists_every_scene_key() -> None:
    """Each root key and each table's key of the Scene model has a row on the page."""
    from sph_core.scene import Constants, OpenBoundary, Scene, Scheme

    page = (ROOT / "docs/user/scene_reference.md").read_text(encoding="utf-8")
    for model in (Scene, Constants, Scheme, OpenBoundary):
        for name in model.model_fields:
            assert f"| `{name}` |" in page, f"{model.__name__}.{name} missing from the reference"


_LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")


def _doc_files() -> list[Path]:
    return [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def relative_targets(path: Path) -> list[str]:
    """The relative link targets of a markdown file (no URLs; '#x' for an anchor in the file
    itself), code spans and fenced blocks left out."""
    text = re.sub(r"```.*?```", "", path.read_text(encoding="utf-8"), flags=re.S)
    text = re.sub(r"`[^`\n]*`", "", text)
    out = []
    for target in _LINK.findall(text):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target):
            continue
        out.append(target)
    return out


def relative_links(path: Path) -> list[str]:
    """The relative files a markdown file links to, without their #anchors."""
    return [t.split("#", 1)[0] for t in relative_targets(path) if not t.startswith("#")]


def anchors(path: Path) -> set[str]:
    """GitHub's heading anchors of a markdown file, and its explicit <a id="..."> anchors."""
    text = re.sub(r"```.*?```", "", path.read_text(encoding="utf-8"), flags=re.S)
    out = set(re.findall(r'<a id="([^"]+)"', text))
    for heading in re.findall(r"^#+\s+(.*)$", text, flags=re.M):
        out.add(re.sub(r"[^\w\- ]", "", heading.lower()).replace(" ", "-"))
    return out


def test_relative_links_resolve() -> None:
    broken = []
    for path in _doc_files():
        for target in relative_targets(path):
            file, _, anchor = target.partition("#")
            dest = path.parent / file if file else path
            if not dest.exists():
                broken.append(f"{path.relative_to(ROOT)} -> {target}")
            elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
                broken.append(f"{path.relative_to(ROOT)} -> {target} (no such heading)")
    assert not broken, "broken links:\n" + "\n".join(broken)


def test_scene_files_example_is_a_valid_scene() -> None:
    """The scene in docs/user/scene_files.md loads as it is written."""
    import tomllib

    from sph_core.scene import make_scene

    text = (ROOT / "docs/user/scene_files.md").read_text(encoding="utf-8")
    block = re.search(r"```toml\n(.*?)```", text, flags=re.S)
    assert block is not None
    scene = make_scene(tomllib.loads(block.group(1)))
    assert scene.dp == 0.02 and scene.probes[0].kind == "front"


def test_link_checker_sees_a_broken_link(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text("# A title\n[ok](page.md#a-title) [gone](missing.md#x) `[code](nope.md)` "
                    "[web](https://x.org)\n", encoding="utf-8")
    links = relative_links(page)
    assert links == ["page.md", "missing.md"]
    assert not (tmp_path / links[1]).exists()
    assert anchors(page) == {"a-title"}


def test_readme_is_short_and_starts_with_the_two_commands() -> None:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 160
    block = re.search(r"```sh\n(.*?)```", text, flags=re.S)
    assert block is not None and text.index("```sh") < 200
    commands = [ln.split("#")[0].strip() for ln in block.group(1).splitlines()]
    assert commands == ["make demo", "make test"]
