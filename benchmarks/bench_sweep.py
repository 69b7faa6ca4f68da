"""Design-map benchmark (issue 13): a 128 x 128 (omega, delta) map at gamma = 0.01, N = 24.

Times ``parapend.sweep`` (local processes, Zarr store written block by block) against a plain
loop of ``parapend.optimize`` over the same points in this one process, checks that every
point agrees, and prints the ratio. Goal: at least 3 times faster on 2 cores, under 30 s.

    python benchmarks/bench_sweep.py              # the full map (the loop takes ~45 s)
    python benchmarks/bench_sweep.py --size 32    # a quicker look
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import tempfile
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import parapend  # noqa: E402
from parapend.maps import sweep  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=128, help="points per axis (default 128)")
    ap.add_argument("--workers", type=int, default=None, help="processes (default: CPUs)")
    a = ap.parse_args()
    n = a.size
    omegas = np.linspace(1.2, 2.4, n)
    deltas = np.linspace(-0.5, -0.05, n)
    print(f"{n} x {n} (omega, delta) map, gamma = 0.01, N = 24; {os.cpu_count()} CPU(s), "
          f"{platform.processor() or platform.machine()}, Python {platform.python_version()}, "
          f"NumPy {np.__version__}; load average {os.getloadavg()[0]:.2f}")
    tmp = tempfile.mkdtemp(prefix="bench-sweep-")
    try:
        t = time.perf_counter()
        run = sweep(os.path.join(tmp, "map.zarr"), omega=f"1.2:2.4:{n}",
                    delta=f"-0.5:-0.05:{n}", gamma=0.01, workers=a.workers)
        t_sweep = time.perf_counter() - t
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    ds = run.dataset
    # CPU time per point, which other jobs on a shared machine disturb less than wall time:
    # the sweep's engine in this one process (no pool) and the optimize loop over the same
    # first rows, alternated three times (the least of each)
    rows = max(1, n // 16)
    cpu_sweep = cpu_opt = float("inf")
    for _ in range(3):
        c = time.process_time()
        part = sweep(None, omega=omegas[:rows].tolist(), delta=f"-0.5:-0.05:{n}",
                     gamma=0.01, workers=1)
        cpu_sweep = min(cpu_sweep, (time.process_time() - c) / (rows * n))
        c = time.process_time()
        for o in omegas[:rows]:
            for d in deltas:
                parapend.optimize(omega=float(o), delta=float(d), gamma=0.01, harmonics=24)
        cpu_opt = min(cpu_opt, (time.process_time() - c) / (rows * n))
    t = time.perf_counter()
    loop = np.empty((n, n))
    status = np.empty((n, n), dtype=object)
    for i, o in enumerate(omegas):
        for j, d in enumerate(deltas):
            r = parapend.optimize(omega=float(o), delta=float(d), gamma=0.01, harmonics=24)
            loop[i, j], status[i, j] = r.power, r.status
    t_loop = time.perf_counter() - t
    same_rows = bool(np.array_equal(part.dataset["power"].values, ds["power"].values[:rows]))
    diff = float(np.max(np.abs(ds["power"].values - loop)))
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    print()
    print("| method | points | time | per point | ratio |")
    print("|---|---|---|---|---|")
    print(f"| plain loop of parapend.optimize, one process | {n * n} | {t_loop:.1f} s | "
          f"{1e3 * t_loop / (n * n):.2f} ms | {t_loop / t_sweep:.2f} |")
    print(f"| parapend.sweep ({run.executor}, Zarr store) | {n * n} | {t_sweep:.1f} s | "
          f"{1e3 * t_sweep / (n * n):.2f} ms | 1 |")
    print(f"| CPU per point, first {rows} rows alternated: optimize {1e3 * cpu_opt:.2f} ms, "
          f"sweep engine in one process {1e3 * cpu_sweep:.2f} ms | | | | "
          f"{cpu_opt / cpu_sweep:.2f} per core, {2 * cpu_opt / cpu_sweep:.2f} on 2 |")
    print()
    print(f"in-process rows equal to the pool's: {same_rows}")
    print(f"max |power(sweep) - power(optimize)| = {diff:.1e}; statuses: "
          f"{dict(zip(*np.unique(status.astype(str), return_counts=True)))}; "
          f"largest branch_gap {float(ds['branch_gap'].max()):.1e}")


if __name__ == "__main__":
    main()
