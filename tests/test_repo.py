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


def test_ci_portability_step_names_tests_that_exist():
    """.ci/run runs named tests without the JIT; a renamed test must not drop out silently."""
    run = ROOT / ".ci" / "run"
    if not run.exists():
        pytest.skip("not a source checkout")
    text = run.read_text()
    assert "OPENBLAS_CORETYPE=" in text and "NUMBA_DISABLE_JIT=1 python -m pytest" in text
    step = text.split("NUMBA_DISABLE_JIT=1 python -m pytest", 1)[1].split("\n#", 1)[0]
    names = [w for w in step.replace("\\", " ").split() if w.startswith("tests/")]
    assert names
    for name in names:
        path, _, func = name.partition("::")
        assert (ROOT / path).is_file(), name
        if func:
            assert f"def {func}(" in (ROOT / path).read_text(), name


def _tracked_files() -> list[Path]:
    """Every file git tracks in this checkout (skips outside a git checkout)."""
    import shutil
    import subprocess

    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    out = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True)
    return [ROOT / name for name in out.stdout.decode().split("\0") if name]


#: the largest file git may track: the repository holds source, text and small data, no binaries
MAX_TRACKED_BYTES = 1_000_000


def test_no_large_file_or_build_output_is_tracked():
    files = _tracked_files()
    assert len(files) > 100 and ROOT / "README.md" in files
    big = [f"{p.relative_to(ROOT)}: {p.stat().st_size} bytes" for p in files
           if p.is_file() and p.stat().st_size > MAX_TRACKED_BYTES]
    assert not big, "files over 1 MB are tracked by git:\n" + "\n".join(big)
    built = [str(p.relative_to(ROOT)) for p in files
             if p.name.endswith((".whl", ".tar.gz", ".so", ".o", ".pyc"))]
    assert not built, f"build outputs are tracked by git: {built}"


def test_gitignore_covers_build_outputs():
    ignored = (ROOT / ".gitignore").read_text().split()
    for pattern in ("*.whl", "*.tar.gz", "build/", "dist/", "*.egg-info/", "__pycache__/"):
        assert pattern in ignored, pattern
