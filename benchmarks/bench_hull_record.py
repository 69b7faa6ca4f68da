r"""Time and memory of the hull's record optimum against the record's length.

The embedded barge (``parapend.buoy(dofs="surge,heave,pitch", hs=1.5, tp=6.0,
repeat_period=W * tp)``, the default pendulum and pivot, seed 0) for records of ``W`` = 10,
25, 50, 100 and 200 peak periods: the whole optimum (rotation and swinging, every start,
the continuation, the refinement, the checks) in a fresh subprocess per size, its wall time,
its CPU time (the process's, all threads) and its peak resident memory (``ru_maxrss``; the
BEM's coefficients come from the cache after the first size). Beside it, where it finishes
within ``--dense-timeout``, the same optimum by the dense solver alone (``KRYLOV_HARMONICS``
and ``LONG_RECORD_HARMONICS`` set past the record's harmonics: the method before the
matrix-free one), and the ratio.
Then the log-log slope of time against waves from 25 to 200 (least squares).

Run: ``nice python benchmarks/bench_hull_record.py [--waves 10,25,50,100,200]
[--dense 10,25] [--dense-timeout 900]``; the machine, its load before and after, and the
table go to stdout (benchmarks/bench_hull_record.out.txt holds a run).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import subprocess
import sys
import time

CHILD = r"""
import json, resource, sys, time
import parapend
from parapend.hydro import hull
waves, dense = float(sys.argv[1]), sys.argv[2] == "dense"
if dense:
    hull.KRYLOV_HARMONICS = hull.LONG_RECORD_HARMONICS = 10**9
t, c = time.perf_counter(), time.process_time()
r = parapend.buoy(dofs="surge,heave,pitch", hs=1.5, tp=6.0, repeat_period=waves * 6.0,
                  seed=0)
print(json.dumps({"seconds": time.perf_counter() - t, "power_w": r.power_w,
                  "cpu_seconds": time.process_time() - c,
                  "harmonics": r.harmonics, "status": r.status,
                  "scaled": [m.get("hessian_scaled_largest_eigenvalue") for m in r.modes[:-1]],
                  "rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""


def run(waves: float, dense: bool, timeout: float) -> dict | None:
    env = dict(os.environ)
    try:
        out = subprocess.run([sys.executable, "-c", CHILD, str(waves),
                              "dense" if dense else "krylov"], capture_output=True,
                             text=True, timeout=timeout, env=env, check=True)
    except subprocess.TimeoutExpired:
        return None
    except subprocess.CalledProcessError as err:
        last = (err.stderr or "").strip().splitlines()[-1:] or ["(no message)"]
        return {"error": last[0]}
    return json.loads(out.stdout.strip().splitlines()[-1])


def slope(xs, ys) -> float:
    lx, ly = [math.log(v) for v in xs], [math.log(v) for v in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--waves", default="10,25,50,100,200")
    ap.add_argument("--dense", default="10,25", help="sizes also solved by the dense solver")
    ap.add_argument("--dense-timeout", type=float, default=900.0)
    ap.add_argument("--timeout", type=float, default=1800.0)
    a = ap.parse_args()
    sizes = [float(v) for v in a.waves.split(",")]
    dense_sizes = {float(v) for v in a.dense.split(",") if v}
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, Python "
          f"{platform.python_version()}; load average before: {os.getloadavg()}")
    run(4.0, False, a.timeout)  # the BEM's cache and the compiled kernels, once
    head = (f"{'waves':>6} {'N':>6} {'time (s)':>9} {'CPU (s)':>8} {'RSS (MB)':>9} "
            f"{'P (W)':>14} "
            f"{'dense (s)':>10} {'dense MB':>9} {'ratio':>7} {'P dense (W)':>14}  status")
    print(head)
    print("-" * len(head))
    times, cpus = {}, {}
    for w in sizes:
        r = run(w, False, a.timeout)
        if r is None or "error" in r:
            why = f"did not finish in {a.timeout:g} s" if r is None else r["error"]
            print(f"{w:6g}  {why}", flush=True)
            continue
        times[w], cpus[w] = r["seconds"], r["cpu_seconds"]
        d = run(w, True, a.dense_timeout) if w in dense_sizes else None
        if d is not None and "error" in d:
            d = None
        if w in dense_sizes and d is None:
            dcols = f"{'>' + format(a.dense_timeout, 'g'):>10} {'':>9} {'':>7} {'':>14}"
        elif d is None:
            dcols = f"{'-':>10} {'':>9} {'':>7} {'':>14}"
        else:
            dcols = (f"{d['seconds']:10.1f} {d['rss_mb']:9.0f} "
                     f"{d['seconds'] / r['seconds']:7.1f} {d['power_w']:14.9g}")
        print(f"{w:6g} {r['harmonics']:6d} {r['seconds']:9.1f} {r['cpu_seconds']:8.1f} "
              f"{r['rss_mb']:9.0f} "
              f"{r['power_w']:14.9g} {dcols}  {r['status']}; scaled Hessian's largest "
              f"eigenvalue (rotation, swinging): {r.get('scaled')}", flush=True)
    fit = [w for w in sorted(times) if 25 <= w <= 200]
    if len(fit) >= 2:
        print(f"log-log slope of time against waves, {fit[0]:g} to {fit[-1]:g} waves: "
              f"{slope(fit, [times[w] for w in fit]):.2f} (wall), "
              f"{slope(fit, [cpus[w] for w in fit]):.2f} (CPU)")
    stamp = time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())
    print(f"load average after: {os.getloadavg()}; {stamp}")


if __name__ == "__main__":
    main()
