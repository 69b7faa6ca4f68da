"""The resume tests' interrupted run: a call made in another Python process, killed with
SIGKILL once its progress has counted enough, and a store's files by content."""

from __future__ import annotations

import hashlib
import os
import signal
import subprocess
import sys
from pathlib import Path

import parapend

SRC = str(Path(parapend.__file__).resolve().parents[1])


def store_files(store) -> dict:
    """Each file of the directory ``store``, relative path to its SHA-256."""
    store = Path(store)
    return {str(p.relative_to(store)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(store.rglob("*")) if p.is_file()}


def kill_after(imports: str, call: str, store, count: int) -> None:
    """Run ``call`` (Python source after ``imports``; the store is ``sys.argv[1]``, the
    progress callback ``slow``, which prints its count and sleeps 0.3 s) in a child process
    and kill it with SIGKILL once the count reaches ``count``."""
    code = (f"import sys, time; {imports}\n"
            "def slow(done, total):\n"
            "    print(done, flush=True)\n"
            "    time.sleep(0.3)\n"
            f"{call}\n")
    proc = subprocess.Popen([sys.executable, "-c", code, str(store)],
                            env={**os.environ, "PYTHONPATH": SRC}, stdout=subprocess.PIPE,
                            text=True)
    for line in proc.stdout:
        if int(line) >= count:
            break
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    proc.stdout.close()
    assert proc.returncode == -signal.SIGKILL
