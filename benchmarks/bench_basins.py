"""Benchmark: basin maps of paper Eq. 1 (Fig. 2 right), compiled kernel against its peers.

Case: gamma = 0.1, p = 0.8, omega = 2.1 (the paper's coexistence case), initial conditions on
an N x N grid of ``[-pi, pi) x [-3, 3]`` at t = 0, budget 300 forcing periods, 128 RK4 steps
per period. Contestants, timed in one process (machines here are shared and noisy, so the
ratios are what counts; the load average is printed):

1. ``basin_map(engine="numba")`` (this project): the compiled kernel, parallel over the
   cores, early termination by capture of the verified attractors and by lag-k convergence,
   the (phi, phi') -> (-phi, -phi') symmetry (half the grid integrated). Timed after a
   warm-up call that loads the JIT cache (the first compile, about 30 s, is printed
   separately).
2. A plain compiled integrator (:func:`parapend.dynamics._kernel.full_time_kernel`): the same
   RK4 arithmetic, SIMD lanes and threads, but every trajectory runs the full 300 periods
   on the whole grid (no early termination, no symmetry): what a straightforward
   numba port of "integrate, then look at the end" costs. Timed on an evenly spaced sample
   of the grid and extrapolated linearly (the cost per trajectory is the same for all).
3. The NumPy engine (``basin_map(engine="numpy")``, the previous default), on a smaller grid
   ``--numpy-resolution`` (default 300) and compared with the compiled kernel on that grid.
4. A SciPy loop: ``solve_ivp`` (DOP853, rtol = atol = 1e-8) for each point over 300 periods,
   on ``--ivp-sample`` points (default 6), extrapolated to N x N.

Usage::

    python benchmarks/bench_basins.py [--resolution 1000] [--periods 300] [--quick]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import time

import numpy as np
from scipy.integrate import solve_ivp

from parapend.dynamics import _kernel
from parapend.dynamics.basins import _theta_grid, basin_map, grid
from parapend.dynamics.simulate import _RK4Map, rhs

CASE = (0.1, 0.8, 2.1)


def _load() -> str:
    try:
        return "{:.2f} {:.2f} {:.2f}".format(*os.getloadavg())
    except OSError:
        return "n/a"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--resolution", type=int, default=1000)
    ap.add_argument("--periods", type=int, default=300)
    ap.add_argument("--plain-sample", type=int, default=20000,
                    help="grid points run by the plain kernel (extrapolated)")
    ap.add_argument("--numpy-resolution", type=int, default=300)
    ap.add_argument("--ivp-sample", type=int, default=6)
    ap.add_argument("--quick", action="store_true", help="small sizes, for a smoke test")
    a = ap.parse_args()
    if a.quick:
        a.resolution, a.plain_sample, a.numpy_resolution, a.ivp_sample = 200, 2000, 100, 2
    n, periods = a.resolution, a.periods
    g, p, om = CASE
    print(f"basin benchmark: gamma={g}, p={p}, omega={om}, {n} x {n}, {periods} periods, "
          f"128 RK4 steps/period")
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores; "
          f"numba threads {_kernel.nb.config.NUMBA_NUM_THREADS}; load before: {_load()}")

    t = time.perf_counter()
    basin_map(*CASE, n_phi=40, n_dphi=40, periods=periods)
    print(f"warm-up 40 x 40 (loads or compiles the kernel): {time.perf_counter() - t:.1f} s")

    t = time.perf_counter()
    cpu = time.process_time()
    ds = basin_map(*CASE, n_phi=n, n_dphi=n, periods=periods)
    t_ours = time.perf_counter() - t
    cpu_ours = time.process_time() - cpu
    frac = ds["basin_fraction"].values
    names = list(ds["name"].values)
    mean_periods = float(ds["periods_used"].values.mean())
    print(f"ours (compiled, early termination): {t_ours:.2f} s wall, {cpu_ours:.1f} s CPU "
          f"(all threads), load {_load()}; mean periods "
          f"per point {mean_periods:.1f}; "
          + ", ".join(f"{nm} {100 * f:.2f}%" for nm, f in zip(names, frac)))
    acc = json.loads(ds.attrs["accuracy"])
    t = time.perf_counter()
    cpu = time.process_time()
    basin_map(*CASE, n_phi=n, n_dphi=n, periods=periods, accuracy_sample=0)
    print(f"  of which the accuracy check ({acc['sample']} points, uncertain labels "
          f"{100 * acc['mislabel_fraction']:.2f} %): the map without it took "
          f"{time.perf_counter() - t:.2f} s wall, {time.process_time() - cpu:.1f} s CPU")

    # plain compiled integrator on a sample of the full grid, every point for all periods
    phi, dphi = grid(n, n)
    th = np.broadcast_to(_theta_grid(n)[None, :], (n, n)).ravel()
    v = np.broadcast_to(dphi[:, None], (n, n)).ravel()
    sel = np.linspace(0, n * n - 1, min(a.plain_sample, n * n)).round().astype(np.int64)
    m = _RK4Map(g, p, om, 128)
    _kernel.full_time_kernel(th[sel[:64]].copy(), v[sel[:64]].copy(), m.a, m.gamma, m.h,
                             m.steps, 1)
    t = time.perf_counter()
    cpu = time.process_time()
    _kernel.full_time_kernel(th[sel].copy(), v[sel].copy(), m.a, m.gamma, m.h, m.steps,
                             periods)
    t_plain = (time.perf_counter() - t) * (n * n) / sel.size
    cpu_plain = (time.process_time() - cpu) * (n * n) / sel.size
    print(f"plain compiled kernel, full {periods} periods, whole grid: {t_plain:.1f} s "
          f"wall, {cpu_plain:.0f} s CPU (extrapolated from {sel.size} points), load {_load()}")

    # NumPy engine against ours on a smaller grid
    k = a.numpy_resolution
    t = time.perf_counter()
    dn = basin_map(*CASE, n_phi=k, n_dphi=k, periods=periods, engine="numpy")
    t_np = time.perf_counter() - t
    t = time.perf_counter()
    dc = basin_map(*CASE, n_phi=k, n_dphi=k, periods=periods, engine="numba")
    t_nb = time.perf_counter() - t
    same = int(np.count_nonzero(dn["attractor"].values == dc["attractor"].values))
    dfrac = float(np.max(np.abs(dn["basin_fraction"].values - dc["basin_fraction"].values)))
    print(f"{k} x {k}: NumPy engine {t_np:.2f} s, compiled {t_nb:.2f} s; identical labels "
          f"{same}/{k * k}, max fraction difference {dfrac:.1e}, load {_load()}")

    # SciPy solve_ivp loop on a sample
    f = rhs(g, p, om)
    T = 2 * math.pi / om
    rng = np.random.default_rng(1)
    pts = rng.integers(0, n * n, a.ivp_sample)
    t = time.perf_counter()
    for i in pts:
        solve_ivp(f, (0.0, periods * T), [th[i] - math.pi, v[i]], method="DOP853",
                  rtol=1e-8, atol=1e-8, t_eval=T * np.arange(periods + 1))
    per = (time.perf_counter() - t) / pts.size
    t_ivp = per * n * n
    print(f"SciPy solve_ivp DOP853 loop (rtol 1e-8), {periods} periods per point: "
          f"{per:.3f} s per point, {t_ivp / 3600:.1f} h for the grid (extrapolated from "
          f"{pts.size} points)")

    print()
    print(f"| {n} x {n}, {periods} periods | time | ratio to ours |")
    print("|---|---|---|")
    print(f"| ours: compiled kernel, early termination | {t_ours:.1f} s ({cpu_ours:.0f} s CPU)"
          " | 1 |")
    print(f"| plain compiled kernel, full time (extrapolated) | {t_plain:.0f} s "
          f"({cpu_plain:.0f} s CPU) | {t_plain / t_ours:.1f}x (CPU {cpu_plain / cpu_ours:.1f}x) |")
    print(f"| NumPy engine (measured at {k} x {k}, ratio) | | {t_np / t_nb:.1f}x |")
    print(f"| SciPy solve_ivp loop (extrapolated) | {t_ivp / 3600:.1f} h | "
          f"{t_ivp / t_ours:.0f}x |")
    print(f"load average at the end: {_load()}")


if __name__ == "__main__":
    main()
