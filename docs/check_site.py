"""Open pages of the built site in headless Chromium: every image loads, nothing overflows.

Usage::

    python docs/check_site.py docs/_build/html [PAGE.html ...]

Without pages it checks three: the index, the first tutorial that has a figure, and the
API reference. For each page it checks, once the page has loaded, that every ``<img>``
decoded with a size (``naturalWidth > 0``) and that nothing is wider than the window
(``scrollWidth <= clientWidth`` for the document, the body and the main content). Exit
status 0 when every page passes, 1 with one line per failure, 2 when Chromium or the site
is missing. The browser is Debian's ``chromium`` (or ``chromium-browser``); nothing is
fetched from the network.
"""

from __future__ import annotations

import html
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

#: window of the check, CSS pixels (a laptop screen)
WINDOW = (1280, 900)

_PROBE = """<script>
window.addEventListener('load', () => setTimeout(() => {
  const imgs = [...document.images];
  const bad = imgs.filter(i => !(i.complete && i.naturalWidth > 0 && i.naturalHeight > 0))
                  .map(i => i.getAttribute('src'));
  const boxes = {document: document.documentElement, body: document.body,
                 main: document.querySelector('main, [role=main], .bd-article, article')};
  const wide = Object.entries(boxes).filter(([k, e]) => e && e.scrollWidth > e.clientWidth)
                     .map(([k, e]) => k + ' ' + e.scrollWidth + ' > ' + e.clientWidth);
  const out = document.createElement('pre');
  out.id = 'check-site-result';
  out.textContent = JSON.stringify({images: imgs.length, broken: bad, overflow: wide});
  document.body.appendChild(out);
}, 200));
</script>"""

_RESULT = re.compile(r'<pre id="check-site-result">(.*?)</pre>', re.S)


def chromium() -> str | None:
    """Path of the Chromium executable, or None."""
    for name in ("chromium", "chromium-browser"):
        path = shutil.which(name)
        if path:
            return path
    return None


def check_page(page: Path, exe: str, timeout: float = 120.0) -> list[str]:
    """Problems of one page: broken images and horizontal overflow (empty when it passes)."""
    page = page.resolve()
    text = page.read_text(encoding="utf-8")
    if "</body>" not in text:
        return [f"{page.name}: no </body>"]
    # the probe sits beside the page, so that its relative links resolve the same way
    fd, probe_name = tempfile.mkstemp(prefix=".check-site-", suffix=".html", dir=page.parent)
    probe = Path(probe_name)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text.replace("</body>", _PROBE + "</body>", 1))
        with tempfile.TemporaryDirectory(prefix="check-site-profile-") as profile:
            flags = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                     "--no-first-run", "--disable-background-networking",
                     "--disable-component-update", "--disable-sync",
                     "--disable-dev-shm-usage", "--hide-scrollbars",
                     f"--window-size={WINDOW[0]},{WINDOW[1]}", f"--user-data-dir={profile}",
                     "--virtual-time-budget=10000", "--dump-dom"]
            run = subprocess.run([exe, *flags, probe.as_uri()], capture_output=True,
                                 text=True, timeout=timeout)
    finally:
        probe.unlink(missing_ok=True)
    m = _RESULT.search(run.stdout)
    if m is None:
        return [f"{page.name}: the page did not finish loading in Chromium "
                f"(exit {run.returncode})"]
    result = json.loads(html.unescape(m.group(1)))
    problems = [f"{page.name}: image did not load: {src}" for src in result["broken"]]
    problems += [f"{page.name}: overflows horizontally: {w}" for w in result["overflow"]]
    return problems


def default_pages(root: Path) -> list[Path]:
    """The index, the first tutorial with a figure, and the API reference."""
    tutorials = sorted((root / "tutorials").glob("*.html"))
    with_figure = [p for p in tutorials if "<img" in p.read_text(encoding="utf-8")]
    if not with_figure:
        raise FileNotFoundError(f"no tutorial with a figure under {root / 'tutorials'}")
    return [root / "index.html", with_figure[0], root / "api.html"]


def main(argv=None) -> int:
    args = sys.argv[1:] if argv is None else list(argv)
    root = Path(args[0] if args else "docs/_build/html")
    exe = chromium()
    if exe is None:
        print("check_site: chromium is not installed", file=sys.stderr)
        return 2
    try:
        pages = [root / a for a in args[1:]] or default_pages(root)
    except FileNotFoundError as exc:
        print(f"check_site: {exc}", file=sys.stderr)
        return 2
    missing = [str(p) for p in pages if not p.is_file()]
    if missing:
        print(f"check_site: no such page: {', '.join(missing)}", file=sys.stderr)
        return 2
    problems = []
    for page in pages:
        found = check_page(page, exe)
        problems += found
        print(f"check_site: {page.relative_to(root)}: {'FAILED' if found else 'ok'}",
              file=sys.stderr)
    for p in problems:
        print(p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
