"""Check every internal link of the built site: files, images, scripts and anchors.

Usage: ``python docs/check_links.py docs/_build/html``. Every ``href`` and ``src`` of every
HTML page that points inside the site must name an existing file, and a ``#fragment`` must
name an ``id`` (or ``name``) in the page it points to. External links (``http:``,
``https:``, ``mailto:``, ...) are not fetched: the check runs offline. Exit status 0 when
all resolve, 1 with one line per broken link otherwise.
"""

from __future__ import annotations

import sys
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit


class _Page(HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.links: list[str] = []
        self.ids: set[str] = set()

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        for key in ("id", "name") if tag == "a" else ("id",):
            if a.get(key):
                self.ids.add(a[key])
        for key in ("href", "src"):
            if a.get(key) is not None and not (tag == "link" and a.get("rel") in
                                                ("preconnect", "dns-prefetch")):
                self.links.append(a[key])


def _parse(path: Path, cache: dict) -> _Page:
    if path not in cache:
        page = _Page()
        page.feed(path.read_text(encoding="utf-8", errors="replace"))
        cache[path] = page
    return cache[path]


def broken_links(root: Path) -> list[str]:
    """Every internal link under ``root`` that does not resolve, as ``page: link (why)``."""
    root = root.resolve()
    cache: dict[Path, _Page] = {}
    problems = []
    for page_path in sorted(root.rglob("*.html")):
        if page_path.relative_to(root).parts[0] == "_static":
            continue  # the theme's template fragments, not pages
        for link in _parse(page_path, cache).links:
            parts = urlsplit(link)
            if parts.scheme or parts.netloc or link.startswith("//"):
                continue  # external (or data:, mailto:, javascript:): not fetched
            target = page_path
            if parts.path:
                target = (page_path.parent / unquote(parts.path)).resolve()
                if target.is_dir():
                    target = target / "index.html"
            where = f"{page_path.relative_to(root)}: {link}"
            if root not in target.parents and target != root:
                problems.append(f"{where} (outside the site)")
            elif not target.is_file():
                problems.append(f"{where} (no such file)")
            elif parts.fragment and target.suffix == ".html":
                if unquote(parts.fragment) not in _parse(target, cache).ids:
                    problems.append(f"{where} (no anchor #{parts.fragment})")
    return problems


def main(argv=None) -> int:
    args = sys.argv[1:] if argv is None else argv
    root = Path(args[0] if args else "docs/_build/html")
    if not (root / "index.html").is_file():
        print(f"check_links: no built site at {root} (index.html missing)", file=sys.stderr)
        return 2
    problems = broken_links(root)
    for p in problems:
        print(p)
    pages = sum(1 for _ in root.rglob("*.html"))
    print(f"check_links: {pages} pages, {len(problems)} broken internal links",
          file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
