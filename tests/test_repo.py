"""The repository's own promises: CI runs exactly the README's test command."""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _readme_test_command() -> str:
    lines = (ROOT / "README.md").read_text().splitlines()
    cmds = [ln.strip() for ln in lines if ln.startswith("    ") and "python -m pytest" in ln]
    assert len(cmds) == 1, cmds
    return cmds[0]


def test_ci_runs_the_readme_test_command():
    if not (ROOT / ".ci" / "run").exists():
        pytest.skip("not a source checkout")
    script = (ROOT / ".ci" / "run").read_text().splitlines()
    assert "set -euo pipefail" in script
    cmd = _readme_test_command()
    assert cmd in script
    assert "sudo" not in cmd and "apt-get install -y -qq chromium" in cmd


def test_gitignore_covers_reports():
    ignored = (ROOT / ".gitignore").read_text().split()
    assert "/report/" in ignored and "/parapend-report/" in ignored
