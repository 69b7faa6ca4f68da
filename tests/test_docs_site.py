"""The documentation site's browser check fails on a broken image and passes a good page.

``docs/check_site.py`` opens pages of the built site in headless Chromium. Here it runs on
tiny hand-made pages, so the check itself is tested without building the site. Like the
report's browser test, it skips without Chromium unless ``CI`` is set.
"""

import base64
import importlib.util
import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
CHECKER = ROOT / "docs" / "check_site.py"
LINKS = ROOT / "docs" / "check_links.py"

# a 2 x 1 PNG (one red, one blue pixel)
PNG = base64.b64decode(
    "iVBORw0KGgoAAAANSUhEUgAAAAIAAAABCAIAAAB7QOjdAAAAEElEQVR4nGP4z8DAwMDwHwAE/gH/"
    "t+1dVgAAAABJRU5ErkJggg==")


def _load(path: Path):
    if not path.exists():
        pytest.skip("not a source checkout")
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def checker():
    module = _load(CHECKER)
    exe = module.chromium()
    if exe is None:
        if os.environ.get("CI", "").lower() not in ("", "0", "false"):
            pytest.fail("CI is set but chromium is not installed: run the README's test "
                        "command (.ci/run), which installs it")
        pytest.skip("chromium is not installed (the README's test command installs it)")
    return module, exe


def _page(tmp_path: Path, body: str, name: str = "page.html") -> Path:
    (tmp_path / "fig.png").write_bytes(PNG)
    page = tmp_path / name
    page.write_text(f"<!doctype html><html><head><title>t</title></head><body>"
                    f"<main>{body}</main></body></html>")
    return page


@pytest.mark.slow
def test_good_page_passes_broken_image_and_overflow_fail(checker, tmp_path, capsys):
    """One Chromium run per page (each takes seconds): a good page, a broken image, a page
    wider than the window; the exit status and one line per problem."""
    module, _ = checker
    _page(tmp_path, '<p>text</p><img src="fig.png" width="40">', "good.html")
    _page(tmp_path, '<img src="fig.png"><img src="missing.png">', "bad.html")
    _page(tmp_path, '<div style="width: 5000px">wide</div>', "wide.html")
    assert module.main([str(tmp_path), "good.html", "bad.html", "wide.html"]) == 1
    out = capsys.readouterr()
    lines = out.out.splitlines()
    assert [ln for ln in lines if ln.startswith("good.html")] == []
    assert [ln for ln in lines if ln.startswith("bad.html")] == [
        "bad.html: image did not load: missing.png"]
    wide = [ln for ln in lines if ln.startswith("wide.html")]
    assert wide and all("overflows horizontally" in ln for ln in wide)
    assert "good.html: ok" in out.err
    assert not list(tmp_path.glob(".check-site-*"))  # the probes are removed
    assert module.main([str(tmp_path), "good.html"]) == 0
    assert module.main([str(tmp_path), "absent.html"]) == 2


def test_link_checker_finds_broken_links_and_anchors(tmp_path):
    links = _load(LINKS)
    (tmp_path / "sub").mkdir()
    (tmp_path / "index.html").write_text(
        '<a href="sub/a.html#here">ok</a><a href="sub/a.html#gone">bad anchor</a>'
        '<a href="nowhere.html">bad file</a><a href="https://example.org/x">external</a>'
        '<img src="sub/fig.png"><a href="#top" id="top">self</a>')
    (tmp_path / "sub" / "a.html").write_text('<h1 id="here">A</h1><a href="../index.html">up</a>')
    (tmp_path / "sub" / "fig.png").write_bytes(PNG)
    problems = links.broken_links(tmp_path)
    assert len(problems) == 2
    assert any("#gone" in p and "no anchor" in p for p in problems)
    assert any("nowhere.html" in p and "no such file" in p for p in problems)
    assert links.main([str(tmp_path)]) == 1
    (tmp_path / "index.html").write_text('<a href="sub/a.html#here">ok</a>')
    assert links.main([str(tmp_path)]) == 0
