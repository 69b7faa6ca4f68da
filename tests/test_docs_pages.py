"""The documentation is written for users: no issue numbers, no development history."""

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"

#: words that belong in a development log or a commit message, not in a user's page
HISTORY = [
    r"\b(issue|ticket|pull request|PR|bug)\s*#?\s*\d+",
    r"(?<![\w&/])#\d{1,5}\b(?![0-9a-fA-F])",
    r"\bthe helper'?s?\b", r"\bthe lead\b(?! time)",
    r"\bthis replaced\b", r"\b(was|were|has been|have been) replaced\b",
    r"\bpreviously\b", r"\bformerly\b", r"\bused to be\b",
    r"\bthe old (method|code|version|implementation)\b", r"\bnot (yet )?installed\b",
    r"\bwas not installed\b", r"\bin this session\b", r"\bwe (changed|fixed|replaced)\b",
    r"\b(is|are) now\b", r"\bnow (uses|runs|computes|checks|reports)\b",
]


def _pages() -> list[Path]:
    skip = {"_build", "generated", "jupyter_execute", ".ipynb_checkpoints"}
    return sorted(p for p in DOCS.rglob("*") if p.suffix in (".md", ".rst")
                  and not skip & set(p.relative_to(DOCS).parts))


@pytest.mark.skipif(not DOCS.exists(), reason="not a source checkout")
def test_no_page_speaks_of_issues_or_history():
    pages = _pages()
    assert len(pages) >= 10
    found = []
    for page in pages:
        for n, line in enumerate(page.read_text().splitlines(), 1):
            for pattern in HISTORY:
                m = re.search(pattern, line, re.IGNORECASE)
                if m:
                    found.append(f"{page.relative_to(ROOT)}:{n}: {m.group(0)!r}: {line.strip()}")
    assert not found, "pages must be written for users, in the present tense:\n" + "\n".join(
        found)


def test_the_history_patterns_catch_what_they_should():
    bad = ["see issue 9", "Issue #12 fixed this", "the helper's run", "the Fourier method "
           "this replaced", "MHKiT was not installed", "it used to be truncated", "fixed in #42"]
    good = ["the tests in tests/test_seas.py", "colour #1f77b4", "an installed package",
            "the Fourier method replaces", "a helper function",
            "the error grows with the lead time"]
    for text in bad:
        assert any(re.search(p, text, re.IGNORECASE) for p in HISTORY), text
    for text in good:
        assert not any(re.search(p, text, re.IGNORECASE) for p in HISTORY), text


def _documented_docs_command() -> str:
    """CONTRIBUTING.md's docs command: its one indented line that runs Sphinx."""
    lines = (ROOT / "CONTRIBUTING.md").read_text().splitlines()
    cmds = [ln.strip() for ln in lines if ln.startswith("    ") and "python -m sphinx" in ln]
    assert len(cmds) == 1, cmds
    return cmds[0]


def test_ci_builds_the_site_with_the_documented_command_and_checks_it():
    """.ci/run runs the docs command of CONTRIBUTING.md: its install as a stage of its own
    (before the stages that run beside the tests), then its Sphinx build verbatim, warnings
    as errors, then the link and browser checks of the built site."""
    run = ROOT / ".ci" / "run"
    if not run.exists():
        pytest.skip("not a source checkout")
    cmd = _documented_docs_command()
    assert "-W" in cmd.split() and "'.[docs]'" in cmd
    install, _, build = cmd.partition(" && ")
    assert install == "python -m pip install '.[docs]'" and build.startswith("python -m sphinx")
    script = run.read_text().splitlines()
    assert build in script
    installs = [i for i, ln in enumerate(script) if ln.startswith(install)]
    assert installs and installs[0] < script.index(build)
    after = script[script.index(build):]
    assert any(ln.startswith("python docs/check_links.py ") for ln in after)
    assert any(ln.startswith("python docs/check_site.py ") for ln in after)
