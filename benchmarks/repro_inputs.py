"""Reproductions of the second audit's input defects, each under ``/usr/bin/time -v``.

Every case must end within 2 minutes and 2 GB with a one-line error (exit 2), a correct
result, or a result whose status says what failed. Prints one row per case: exit code,
wall seconds, peak resident memory (MB), the number of stderr lines and the last one.
Not collected by pytest.

    PYTHONPATH=src python benchmarks/repro_inputs.py
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

SRC = str(Path(__file__).resolve().parents[1] / "src")


def _rows(path: Path, header: str, a, b) -> str:
    path.write_text(header + "\n" + "\n".join(f"{float(x)!r},{float(y)!r}"
                                              for x, y in zip(a, b)))
    return str(path)


def cases(d: Path) -> list[list[str]]:
    tau = 0.5 + np.linspace(0.0, 0.000063, 32)
    narrow = _rows(d / "narrow.csv", "tau,q", tau, 900 * np.sin(np.linspace(0, 6, 32)))
    t32 = np.arange(32) / 32
    sub = _rows(d / "sub.csv", "tau,q", t32, 1e-320 * np.sin(2 * np.pi * t32))
    t = np.arange(400) * 0.1
    subrec = _rows(d / "subrec.csv", "t,z", t, 1e-320 * np.sin(t))
    t = np.append(np.arange(40) * 0.01, 3e5)
    late = _rows(d / "late.csv", "t,z", t, 0.1 * np.sin(t))
    fifo = d / "fifo.csv"
    os.mkfifo(fifo)
    return [
        ["optimize", "--file", narrow],
        ["optimize", "--fourier", "1:1000,1:1000,1:1000,1:1000"],
        ["optimize", "--delta", "5e-324"],
        ["optimize", "--fourier", "1:1e-320"],
        ["optimize", "--file", sub],
        ["threshold", "--delta", "5e-324"],
        ["track", "--delta", "5e-324", "--periods", "20"],
        ["sea", "--record", subrec],
        ["optimize", "--length", "1e308", "--mass", "1"],
        ["optimize", "--length", "1e-320", "--mass", "1"],
        ["optimize", "--length", "1", "--mass", "1e308"],
        ["track", "--gamma", "1e3", "--periods", "20"],
        ["track", "--omega", "1e-3", "--periods", "20"],
        ["threshold", "--omega", "1e-3", "--delta", "1e3"],
        ["sea", "--gravity", "1e-3"],
        ["optimize", "--file", str(fifo)],
        ["sea", "--record", late],
        ["optimize", "--delta", "-3e-100", "--harmonics", "8"],
    ]


def main() -> int:
    env = {**os.environ, "PYTHONPATH": SRC}
    bad = 0
    with tempfile.TemporaryDirectory() as tmp:
        for argv in cases(Path(tmp)):
            cmd = ["/usr/bin/time", "-v", sys.executable, "-m", "parapend", *argv]
            try:
                r = subprocess.run(cmd, capture_output=True, text=True, timeout=150, env=env)
            except subprocess.TimeoutExpired:
                print(f"TIMEOUT  {' '.join(argv)}")
                bad += 1
                continue
            err = r.stderr
            rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", err)[1])
            wall = re.search(r"Elapsed \(wall clock\) time .*: (\S+)", err)[1]
            mins, secs = wall.split(":")[-2:]
            secs = 60 * float(mins) + float(secs)
            own = [ln for ln in err[:err.index("\tCommand being timed")].splitlines()
                   if not ln.startswith("Command exited with non-zero status")]
            code = int(re.search(r"Exit status: (\d+)", err)[1])
            last = own[-1] if own else (r.stdout.strip().splitlines() or [""])[0]
            ok = secs < 120 and rss < 2 << 20 and (code == 0 or (code == 2 and len(own) == 1))
            bad += not ok
            print(f"{'ok' if ok else 'BAD':4} exit {code}  {secs:6.2f} s  {rss / 1024:6.0f} MB  "
                  f"{len(own)} line(s)  {' '.join(argv)[:60]}\n      {last[:150]}")
    print(f"{bad} case(s) outside the rules")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
