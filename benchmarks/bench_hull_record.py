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

``--take-off limit|efficiency|both``: the same records with a real take-off instead
(``--torque-limit`` ``--limit`` N m, default 60 kN m, about 64 % of the ideal optimum's
peak torque on the 10-wave record; ``--efficiency 0.9,0.85``), matrix-free from
``KRYLOV_HARMONICS`` on: per record its time, the power against the ideal's (``--ideal``,
the table's powers), the peak torque between the grid's points against the limit, the
status, the energy balance and the refinement's history.

Run: ``nice python benchmarks/bench_hull_record.py [--waves 10,25,50,100,200]
[--dense 10,25] [--dense-timeout 900] [--take-off limit --limit 60000 [--lift-caps]]``;
the machine,
its load before and after, and the table go to stdout (benchmarks/bench_hull_record.out.txt
holds a run).
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
from parapend import limits
from parapend.hydro import hull
waves, dense = float(sys.argv[1]), sys.argv[2] == "dense"
pto = json.loads(sys.argv[3]) if len(sys.argv) > 3 else {}
if len(sys.argv) > 4 and sys.argv[4] == "lift":  # past the take-off's record caps
    limits.HULL_MAX_HARMONICS = limits.HULL_MAX_PTO_RECORD_HARMONICS = 10**6
if dense:
    hull.KRYLOV_HARMONICS = hull.LONG_RECORD_HARMONICS = 10**9
t, c = time.perf_counter(), time.process_time()
r = parapend.buoy(dofs="surge,heave,pitch", hs=1.5, tp=6.0, repeat_period=waves * 6.0,
                  seed=0, **pto)
best = max(r.modes[:-1], key=lambda m: m["power_w"] if m["power_w"] == m["power_w"] else -1e300)
print(json.dumps({"seconds": time.perf_counter() - t, "power_w": r.power_w,
                  "cpu_seconds": time.process_time() - c,
                  "harmonics": r.harmonics, "status": r.status,
                  "peak_torque_nm": best["peak_torque_nm"],
                  "mechanical_power_w": best["mechanical_power_w"],
                  "history": [m["refinement_history"] for m in r.modes[:-1]],
                  "energy_balance": [m["energy_balance_residual"] for m in r.modes[:-1]],
                  "scaled": [m.get("hessian_scaled_largest_eigenvalue") for m in r.modes[:-1]],
                  "rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""


def run(waves: float, dense: bool, timeout: float, pto=None, lift=False) -> dict | None:
    env = dict(os.environ)
    try:
        out = subprocess.run([sys.executable, "-c", CHILD, str(waves),
                              "dense" if dense else "krylov", json.dumps(pto or {}),
                              "lift" if lift else "keep"],
                             capture_output=True,
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
    ap.add_argument("--take-off", choices=("limit", "efficiency", "both"), default=None)
    ap.add_argument("--limit", type=float, default=60e3, help="the torque limit, N m")
    ap.add_argument("--lift-caps", action="store_true",
                    help="measure records past the take-off's caps (limits.HULL_MAX_HARMONICS, "
                    "HULL_MAX_PTO_RECORD_HARMONICS), as the measurements that set them")
    # the ideal take-off's optima (25 waves: with its net turns searched, 3 net turns; the
    # two modes' 1637.09744 W)
    ap.add_argument("--ideal", default="10:1744.54666,25:1715.10395,50:1652.99164,"
                    "100:1641.27472,200:1633.99607", help="WAVES:POWER of the ideal take-off")
    a = ap.parse_args()
    if a.take_off:
        take_off(a)
        return
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


def take_off(a) -> None:
    """The records with a torque limit, an efficiency, or both (one table)."""
    pto = {}
    if a.take_off in ("limit", "both"):
        pto["torque_limit"] = a.limit
    if a.take_off in ("efficiency", "both"):
        pto["efficiency"] = "0.9,0.85"
    ideal = {float(k): float(v) for k, v in (p.split(":") for p in a.ideal.split(","))}
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, Python "
          f"{platform.python_version()}; load average before: {os.getloadavg()}; "
          f"take-off {pto}")
    head = (f"{'waves':>6} {'N':>6} {'time (s)':>9} {'CPU (s)':>8} {'RSS (MB)':>9} "
            f"{'P (W)':>12} {'P/ideal':>8} {'peak/limit-1':>13}  status")
    print(head)
    print("-" * len(head))
    for w in (float(v) for v in a.waves.split(",")):
        r = run(w, False, a.timeout, pto, a.lift_caps)
        if r is None or "error" in r:
            why = f"did not finish in {a.timeout:g} s" if r is None else r["error"]
            print(f"{w:6g}  {why}", flush=True)
            continue
        over = (r["peak_torque_nm"] / a.limit - 1) if "torque_limit" in pto else math.nan
        ratio = r["power_w"] / ideal[w] if w in ideal else math.nan
        print(f"{w:6g} {r['harmonics']:6d} {r['seconds']:9.1f} {r['cpu_seconds']:8.1f} "
              f"{r['rss_mb']:9.0f} {r['power_w']:12.6f} {ratio:8.4f} {over:13.2e}  "
              f"{r['status']}; energy balance {max(r['energy_balance']):.1e}; refinement "
              f"(rotation, swinging): {r['history']}", flush=True)
    stamp = time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())
    print(f"load average after: {os.getloadavg()}; {stamp}")


if __name__ == "__main__":
    main()
