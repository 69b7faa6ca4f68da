"""The repository's own promises: CI runs exactly the README's test command, times its
stages and fails when one fails; git holds no binaries."""

import os
import shutil
import subprocess
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


_FAKE_PYTHON = """#!/bin/sh
# stands in for python: prints its arguments, fails (exit 3) when they contain $FAILPAT
if [ "$*" = ".ci/blas_kernel.py" ]; then echo Sandybridge; exit 0; fi
echo "python $*"
case "$*" in *"$FAILPAT"*) [ -n "$FAILPAT" ] && { echo "failing: $*"; exit 3; } ;; esac
exit 0
"""


def _run_ci_with_stubs(tmp_path, failpat: str):
    """.ci/run on a copy of itself, with `python` and `chromium` replaced by stubs: the
    stages' control flow alone, in a second."""
    if shutil.which("bash") is None or not (ROOT / ".ci" / "run").exists():
        pytest.skip("needs bash and a source checkout")
    repo, bin_ = tmp_path / "repo", tmp_path / "bin"
    (repo / ".ci").mkdir(parents=True)
    bin_.mkdir()
    shutil.copy(ROOT / ".ci" / "run", repo / ".ci" / "run")
    (bin_ / "python").write_text(_FAKE_PYTHON)
    (bin_ / "chromium").write_text("#!/bin/sh\nexit 0\n")
    for f in bin_.iterdir():
        f.chmod(0o755)
    env = {**os.environ, "PATH": f"{bin_}{os.pathsep}{os.environ['PATH']}",
           "FAILPAT": failpat, "PARAPEND_CACHE": str(tmp_path / "cache")}
    proc = subprocess.run(["bash", ".ci/run"], cwd=repo, env=env, capture_output=True,
                          text=True, timeout=60)
    table = proc.stdout.split("seconds per stage", 1)
    assert len(table) == 2, proc.stdout + proc.stderr
    rows = [ln for ln in table[1].splitlines()[1:] if ln.strip()]
    return proc, rows


STAGES = ["README's command", "install '.[docs]'", "the slow set, main", "OPENBLAS_CORETYPE=",
          "NUMBA_DISABLE_JIT=1", "sphinx build", "links and anchors", "slow set, beside"]


def test_ci_prints_every_stages_time(tmp_path):
    proc, rows = _run_ci_with_stubs(tmp_path, "")
    assert proc.returncode == 0, proc.stdout
    for name in STAGES:
        (row,) = [r for r in rows if name in r]
        assert row.endswith(" ok") and row.split()[-2].isdigit(), row
    assert rows[-1].startswith("the whole run") and rows[-1].endswith(" ok")


@pytest.mark.parametrize("failpat,stage", [
    ("--ignore=tests/test_global.py", "the slow set, main"),
    ("-m slow -p no:cacheprovider tests/", "slow set, beside"),
    ("pip install -q .[test]", "README's command"),
    ("tests/test_hermite.py", "NUMBA_DISABLE_JIT=1"),
    ("check_site", "links and anchors"),
])
def test_a_failing_stage_fails_the_run_and_the_table_still_prints(tmp_path, failpat, stage):
    proc, rows = _run_ci_with_stubs(tmp_path, failpat)
    assert proc.returncode == 3, proc.stdout
    (row,) = [r for r in rows if stage in r]
    assert row.endswith("FAILED (exit 3)"), row
    assert rows[-1].startswith("the whole run") and rows[-1].endswith("FAILED (exit 3)")
    # nothing after a failed stage of its own sequence runs
    if stage == "README's command":
        assert not any("slow set" in r for r in rows)


def test_ci_splits_the_slow_set_into_files_that_exist():
    """The slow set runs in two sessions: the files listed in slow_beside, and every other
    file (--ignore of the same list): together the whole set, each test once."""
    import re

    run = ROOT / ".ci" / "run"
    if not run.exists():
        pytest.skip("not a source checkout")
    text = run.read_text()
    (listed,) = re.findall(r"^slow_beside=\(([^)]*)\)$", text, re.M)
    names = listed.split()
    assert names and len(set(names)) == len(names)
    for name in names:
        assert (ROOT / name).is_file() and "pytest.mark.slow" in (ROOT / name).read_text(), name
    lines = text.splitlines()
    assert 'python -m pytest -m slow "${slow_beside[@]/#/--ignore=}"' in lines
    assert '  python -m pytest -m slow -p no:cacheprovider "${slow_beside[@]}"' in lines
