"""Scripted pass over hostile inputs of the command line and the API (issue 8).

Each case runs in its own subprocess under a wall-clock timeout (120 s) and an address-space
limit (RLIMIT_AS, 3 GB); the script reports, per case and in total: tracebacks, runs over
2 minutes, runs over 2 GB peak resident memory, and exit codes. Not collected by pytest.

    PYTHONPATH=src python benchmarks/audit_inputs.py [--quick] [--only WORD] [--json out.json]

``--quick`` skips the cases that are expected to take over 10 s (the caps at their limits).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import shlex
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

TIMEOUT = 120.0
AS_LIMIT = 3 << 30
RSS_LIMIT_KB = 2 << 20  # 2 GB in KB (ru_maxrss is in KB on Linux)
SRC = str(Path(__file__).resolve().parents[1] / "src")


def _files(d: Path) -> dict:
    """Hostile and ordinary input files, written once into ``d``."""
    import numpy as np

    f = {}

    def w(name, data):
        p = d / name
        p.write_bytes(data if isinstance(data, bytes) else data.encode())
        f[name] = str(p)

    def rows(n, q=None, start=0.0):
        tau = start + np.arange(n) / n
        q = -0.3 * np.sin(2 * np.pi * tau) if q is None else q
        return "tau,q\n" + "\n".join(f"{a!r},{b!r}" for a, b in zip(tau.tolist(),
                                                                    np.asarray(q).tolist()))

    rng = np.random.default_rng(0)
    w("good.csv", rows(64))
    w("bom.csv", b"\xef\xbb\xbf" + rows(64).encode())
    w("latin1.csv", "tau,q\n0,0\n0.5,caf\xe9\n".encode("latin-1"))
    w("utf16.csv", rows(32).encode("utf-16"))
    w("binary.csv", bytes(range(256)) * 64)
    w("empty.csv", b"")
    w("header_only.csv", "tau,q\n")
    w("rows15.csv", rows(15))
    w("huge_q.csv", rows(32, q=np.full(32, 1e308)))
    w("nan_q.csv", "tau,q\n0.0,nan\n" + rows(32).split("\n", 2)[2])
    w("tiny_gap.csv", "tau,q\n0.0,0.0\n1e-300,0.0\n" + "\n".join(
        f"{i / 32!r},{math.sin(2 * math.pi * i / 32)!r}" for i in range(2, 32)))
    w("unsorted.csv", "tau,q\n" + "\n".join(f"{(i * 7 % 32) / 32},{i}" for i in range(32)))
    w("tau_ge1.csv", rows(32, start=0.5))
    w("semicolon.csv", rows(32).replace(",", ";"))
    w("three_cols.csv", rows(32).replace("\n", ",1\n"))
    w("long_line.csv", "tau,q\n" + "1" * 3_000_000 + ",1\n")
    w("noisy4096.csv", rows(4096, q=-0.3 * np.sin(2 * np.pi * np.arange(4096) / 4096)
                            + 0.01 * rng.standard_normal(4096)))
    w("noisy16384.csv", rows(16384, q=-0.3 * np.sin(2 * np.pi * np.arange(16384) / 16384)
                             + 0.01 * rng.standard_normal(16384)))
    w("rows16385.csv", rows(16385))
    w("rows100000.csv", rows(100000))
    f["dir"] = str(d)
    f["missing"] = str(d / "missing.csv")
    afile = d / "afile"
    afile.write_text("x")
    f["afile"] = str(afile)
    return f


def cli_cases(f: dict, out: str) -> list[tuple[str, list[str], dict]]:
    """(label, argv, options); options: heavy (expected > 10 s), stdout ('full'|'closed')."""
    c = []

    def add(*argv, heavy=False, stdout=None):
        c.append((" ".join(shlex.quote(a) for a in argv), list(argv),
                  {"heavy": heavy, "stdout": stdout}))

    # no command, help, version, unknown things
    add()
    add("--help")
    add("--version")
    add("bogus")
    add("optimize", "--bogus")
    add("optimize", "--help")
    add("optimize", "extra-positional")
    # numbers: nan, inf, '', '1e', hex, huge, tiny, negative scientific
    for v in ("nan", "inf", "-inf", "", "1e", "0x10", "1e155", "1e-308", "1e-320", "1e308",
              "-1", "0", "1_000", "--", "1e3", "1e-3"):
        add("optimize", "--omega", v)
    for v in ("1e308", "-1e-3", "-1E+2", "nan", "0", "1e-300", "1000", "1001"):
        add("optimize", f"--delta={v}")
    for v in ("-0.1", "1e300", "0.09", "1e-320", "inf", "1e3"):
        add("optimize", "--gamma", v)
    for v in ("0", "-3", "2.5", "1e3", "9" * 5000, "4096", "2048", "1025"):
        add("optimize", "--harmonics", v)
    add("optimize", "--harmonics", "1024", heavy=True)
    # excitations
    for v in ("1e-308", "0", "-1", "1e9", "nan", "1e-9", "3.49e-9", "3.5e-9", "0.4363"):
        add("optimize", "--excitation", "square", "--square-alpha", v)
    for v in ("", ",", "1", "1:2:3:4", "0:1", "-1:0.3", "1:nan", "1:inf", "a:b", "2.9:0.3",
              "1000000:0.3", "999999999999:0.3", "1:0.3:1e300", "1:1e300", "1" * 400 + ":1",
              "1:-0.3,3:0.1:0.5", "1024:0.3"):
        add("optimize", "--fourier", v)
    add("optimize", "--excitation", "fourier")
    add("optimize", "--excitation", "file")
    add("optimize", "--excitation", "sawtooth")
    add("optimize", "--excitation", "harmonic", "--file", f["good.csv"])
    add("optimize", "--excitation", "square", "--fourier", "1:0.3")
    add("optimize", "--fourier", "1:0.3", "--delta", "0.2")
    add("optimize", "--fourier", "1:0.3", "--file", f["good.csv"])
    add("optimize", "--square-alpha", "0.01")
    add("optimize", "--file", f["good.csv"], "--delta", "-0.3")
    add("optimize", "--delta", "0")
    add("optimize", "--delta", "0", "--method", "bvp", "--gamma", "0.01")
    add("optimize", "--delta", "0", "--method", "all", "--gamma", "0.01")
    # files
    for name in ("good.csv", "bom.csv", "latin1.csv", "utf16.csv", "binary.csv", "empty.csv",
                 "header_only.csv", "rows15.csv", "huge_q.csv", "nan_q.csv", "tiny_gap.csv",
                 "unsorted.csv", "tau_ge1.csv", "semicolon.csv", "three_cols.csv",
                 "long_line.csv", "rows16385.csv", "rows100000.csv", "dir", "missing",
                 "noisy4096.csv"):
        add("optimize", "--file", f[name])
    add("optimize", "--file", "/dev/zero")
    add("optimize", "--file", "/dev/null")
    add("optimize", "--file", "")
    add("optimize", "--file", f["noisy16384.csv"], heavy=True)
    add("optimize", "--file", f["noisy4096.csv"], "--method", "bvp", "--gamma", "1e-4")
    add("optimize", "--file", f["good.csv"], "--method", "bvp", "--gamma", "1e-4")
    add("threshold", "--file", f["noisy4096.csv"], heavy=True)
    # methods
    add("optimize", "--method", "bvp")
    add("optimize", "--method", "bvp", "--gamma", "1e-7")
    add("optimize", "--method", "bvp", "--gamma", "1e3")
    add("optimize", "--method", "all", "--gamma", "0.01")
    add("optimize", "--method", "all", "--save", f"{out}/x.csv")
    add("optimize", "--method", "nope")
    # outputs
    for flag, path in (("--save", "/proc/x.csv"), ("--plot", "/sys/x.png"),
                       ("--save", "x" * 300 + ".csv"), ("--save", f"{f['afile']}/sub.csv"),
                       ("--save", f"{out}/nodir/x.csv"), ("--save", f"{out}/x.txt"),
                       ("--plot", f"{out}/x"), ("--plot", f"{out}/x.pdf"),
                       ("--plot", f"{out}/x.svg"), ("--save", ""), ("--save", f["dir"]),
                       ("--plot", f"{out}/x.PNG")):
        add("optimize", "--harmonics", "8", flag, path)
    add("optimize", stdout="full")
    add("optimize", stdout="closed")
    add("optimize", "--json", stdout="full")
    add("threshold", stdout="closed")
    # threshold, sweeps, tables
    add("threshold", "--omega", "1e-320")
    add("threshold", "--harmonics", "1024")
    add("threshold", "--harmonics", "512", heavy=True)
    add("threshold", "--delta", "0")
    for v in ("100000", "1", "0", "-5", "1001", "1002"):
        add("damping-sweep", "--points", v)
    add("damping-sweep", "--points", "1001", "--harmonics", "32", heavy=True)
    add("damping-sweep", "--points", "16", "--harmonics", "256", heavy=True)
    add("damping-sweep", "--points", "1000", "--harmonics", "64")
    add("damping-sweep", "--harmonics", "257")
    add("damping-sweep", "--delta", "0")
    add("damping-sweep", "--delta", "0", "--gamma-max", "0.1", "--points", "3")
    for v in ("-1", "0", "1e300", "nan"):
        add("damping-sweep", "--gamma-max", v)
    add("damping-sweep", "--points", "5", "--save", f"{out}/s.nc", "--plot", f"{out}/s.pdf")
    add("damping-sweep", "--points", "5", "--save", "/proc/s.nc")
    for v in ("4096", "512", "1000000000", "0", "-1", "129"):
        add("harmonics", "--to", v)
    add("harmonics", "--to", "128", heavy=True)
    add("harmonics", "--from", "0")
    add("harmonics", "--from", "10", "--to", "5")
    add("harmonics", "--to", "8", "--save", f"{out}/h.nc")
    # figures and report
    for v in ("3", "11", "2c", ""):
        add("figure", v)
    add("figure", "8", "--plot", f"{out}/f8.txt")
    add("figure", "8", "--plot", "/proc/f8.png")
    add("figure", "8", "--plot", f"{out}/f8.pdf")
    add("reproduce", "--out", "/proc/x")
    add("reproduce", "--out", "")
    add("reproduce", "--out", f"{f['afile']}/sub")
    add("reproduce", "--out", f["afile"])
    add("reproduce", "--out", f"{out}/missing/parent/dir")
    return c


API_CASES = [
    "p.optimize(omega=1e155)", "p.optimize(omega='1.8')", "p.optimize(omega=None)",
    "p.optimize(omega=[1])", "p.optimize(omega=True)", "p.optimize(omega=10**400)",
    "p.optimize(delta=1e308)", "p.optimize(delta=complex(1, 1))", "p.optimize(gamma=-1)",
    "p.optimize(gamma=float('nan'))", "p.optimize(harmonics=2.5)", "p.optimize(harmonics='8')",
    "p.optimize(harmonics=None)", "p.optimize(harmonics=10**30)", "p.optimize(method=None)",
    "p.optimize(method='BVP')", "p.optimize(method='bvp', gamma=1e-320)",
    "p.optimize(fourier=[(2.9, 0.3, 0)])", "p.optimize(fourier=[(1,)])",
    "p.optimize(fourier=[(1, 2, 3, 4)])", "p.optimize(fourier=5)", "p.optimize(fourier=[])",
    "p.optimize(fourier=[('a', 1)])", "p.optimize(fourier=[(10**12, 0.3)])",
    "p.optimize(fourier=[(True, 0.3)])", "p.optimize(fourier=b'1:0.3')",
    "p.optimize(fourier='1:0.3', delta=1)", "p.optimize(file=5)", "p.optimize(file='')",
    "p.optimize(file=b'x.csv')", "p.optimize(excitation=3)",
    "p.optimize(excitation='square', square_alpha=-1)",
    "p.optimize(excitation='harmonic', file='x.csv')", "p.optimize(warm='x')",
    "p.optimize(warm=[1, 2])", "p.optimize(warm=[float('nan')] * 3)",
    "p.optimize(bogus=1)", "p.optimize(delta=0, gamma=0.1, method='bvp')",
    "p.optimize(delta=0)", "p.optimize(gamma=0.09)",
    "p.threshold(harmonics=0)", "p.threshold(harmonics=10**6)", "p.threshold(tol=-1)",
    "p.threshold(omega=1e-320)", "p.damping_sweep(points=0)", "p.damping_sweep(points=10**9)",
    "p.damping_sweep(points=3, gamma_max=-1)", "p.damping_sweep(delta=0, points=3)",
    "p.damping_sweep(delta=0, points=3, gamma_max=0.1)",
    "p.harmonic_table(5)", "p.harmonic_table([])", "p.harmonic_table([2, 4096])",
    "p.harmonic_table(['a'])", "p.harmonic_table([2], gamma=-1)", "p.harmonic_table([2], x=1)",
    "p.mean_power(p.optimize(harmonics=2).motion, p.harmonic(), points=0)",
    "p.mean_power(None, p.harmonic())", "p.mean_power(p.optimize(harmonics=2).motion, 'x')",
    "p.uniform_power(p.harmonic(), -1)", "p.uniform_power('harmonic')",
    "p.harmonic(delta='x')", "p.harmonic(omega=0)", "p.square(alpha=1e-308)",
    "p.square(alpha=10)", "p.two_harmonic(delta=float('inf'))", "p.fourier([(0, 1)])",
    "p.fourier([(1, 1)], mean=float('nan'))", "p.from_csv('/dev/zero')",
    "p.from_csv('/nonexistent')", "p.from_csv(None)", "p.build_excitation('nope')",
    "p.limit('x')", "p.solve_bvp_optimum(p.harmonic(), 0)",
    "p.solve_bvp_optimum(p.harmonic(), 0.01, tol=0)",
]


def _limits():
    resource.setrlimit(resource.RLIMIT_AS, (AS_LIMIT, AS_LIMIT))
    os.setsid()


def run_one(argv: list[str], stdout: str | None, cwd: str) -> dict:
    env = {**os.environ, "PYTHONPATH": SRC, "OPENBLAS_NUM_THREADS": "1",
           "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
    out_target = subprocess.PIPE
    fh = None
    if stdout == "full":
        fh = open("/dev/full", "w")  # noqa: SIM115
        out_target = fh
    cmd = [sys.executable, *argv]
    if stdout == "closed":
        cmd = ["/bin/sh", "-c", " ".join(shlex.quote(a) for a in cmd) + " >&-"]
        out_target = subprocess.DEVNULL
    cmd = ["/usr/bin/time", "-f", "__MAXRSS_KB__ %M", *cmd]  # peak RSS of this case alone
    t0 = time.monotonic()
    proc = subprocess.Popen(cmd, stdout=out_target, stderr=subprocess.PIPE, cwd=cwd, env=env,
                            preexec_fn=_limits)
    timed_out = False
    try:
        _, err = proc.communicate(timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        _, err = proc.communicate()
        timed_out = True
    wall = time.monotonic() - t0
    if fh is not None:
        fh.close()
    text = err.decode("utf-8", "replace")
    peak = None
    keep = []
    for line in text.splitlines():
        if line.startswith("__MAXRSS_KB__"):
            peak = int(line.split()[1])
        elif not line.startswith("Command exited with non-zero status"):
            keep.append(line)
    return {"rc": proc.returncode, "wall": wall, "timed_out": timed_out,
            "stderr": "\n".join(keep), "peak_kb": peak}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="skip cases expected over 10 s")
    ap.add_argument("--only", default=None, help="run only cases whose label contains this")
    ap.add_argument("--json", default=None, help="write every case's record here")
    a = ap.parse_args()
    work = Path(tempfile.mkdtemp(prefix="parapend-audit-"))
    out = work / "out"
    out.mkdir()
    f = _files(work)
    cases = [("cli", lbl, ["-m", "parapend", *argv], o) for lbl, argv, o in cli_cases(f, out)]
    for code in API_CASES:
        snippet = ("import sys, parapend as p\n"
                   f"try:\n    r = {code}\nexcept p.ParameterError as e:\n"
                   "    print('ParameterError:', e, file=sys.stderr); sys.exit(2)\n")
        cases.append(("api", code, ["-c", snippet], {"heavy": False, "stdout": None}))
    if a.quick:
        cases = [c for c in cases if not c[3]["heavy"]]
    if a.only:
        cases = [c for c in cases if a.only in c[1]]
    records = []
    for kind, label, argv, o in cases:
        r = run_one(argv, o["stdout"], str(out))
        r.update(kind=kind, label=label + (f" [stdout {o['stdout']}]" if o["stdout"] else ""))
        tb = "Traceback" in r["stderr"]
        lines = [ln for ln in r["stderr"].splitlines() if ln.strip()]
        r["traceback"] = tb
        r["over_time"] = r["timed_out"] or r["wall"] > TIMEOUT
        r["over_memory"] = (r["peak_kb"] or 0) > RSS_LIMIT_KB or "MemoryError" in r["stderr"]
        r["stderr_lines"] = len(lines)
        records.append(r)
        flag = ("TRACEBACK " if tb else "") + ("TIMEOUT " if r["over_time"] else "") + \
               ("MEMORY " if r["over_memory"] else "")
        last = lines[-1][:110] if lines else ""
        mb = (r["peak_kb"] or 0) // 1024
        print(f"{kind} rc={r['rc']:>4} {r['wall']:6.1f}s {mb:5d}MB {flag}{r['label'][:60]!s:60}"
              f" | {last}", flush=True)
    n = len(records)
    codes = {}
    for r in records:
        codes[r["rc"]] = codes.get(r["rc"], 0) + 1
    summary = {
        "cases": n, "cli": sum(r["kind"] == "cli" for r in records),
        "api": sum(r["kind"] == "api" for r in records),
        "tracebacks": sum(r["traceback"] for r in records),
        "over_2_minutes": sum(r["over_time"] for r in records),
        "over_2_GB": sum(r["over_memory"] for r in records),
        "multi_line_errors": sum(r["rc"] not in (0, None) and r["stderr_lines"] > 1
                                 and r["label"] not in ("", "--help") for r in records),
        "exit_codes": dict(sorted(codes.items(), key=lambda kv: str(kv[0]))),
        "slowest_s": round(max(r["wall"] for r in records), 1),
        "peak_rss_MB": round(max(r["peak_kb"] or 0 for r in records) / 1024),
    }
    print(json.dumps(summary, indent=2))
    if a.json:
        Path(a.json).write_text(json.dumps({"summary": summary, "cases": records}, indent=1))
    return 1 if summary["tracebacks"] or summary["over_2_minutes"] or summary["over_2_GB"] else 0


if __name__ == "__main__":
    sys.exit(main())
