r"""Time the persistence kernel against a plain compiled scalar RK4 loop, and the acceptance
map of ``parapend persistence``.

1. **Steps per second**: the same records (Hs 2 cm, Tp 0.3 s, 400 peak periods, the 0.3 m
   pendulum) through :func:`parapend.dynamics._persist_kernel.run_batch` (lanes in
   lockstep, ``prange`` over groups, the package's fast sine, the accumulations inside) and
   through a plain ``numba.njit`` RK4 loop, one realization at a time, ``math.sin``, the
   same z'' grid, no accumulations: RK4 steps per second side by side and their ratio.
2. **The acceptance map**: 20 Hs x 20 Tp (Tp / T0 from 0.15 to 0.6 for the 0.3 m pendulum,
   T0 = 1.1 s; Hs 0.0025 to 0.05 m, where rotation both persists and dies) x 1000
   realizations of 400-peak-period records, through ``parapend.persistence`` with a store
   in a temporary directory. ``--realizations R``, ``--grid G`` and ``--columns K`` (K of
   the Tp columns, at full size the faithful reduction: every block as in the full map) run
   a reduced map; the printed extrapolation scales the measured time by the work (RK4
   steps) of the full map over the reduced map's.

Run: ``python benchmarks/bench_persistence.py [--realizations 1000] [--grid 20]
[--gpu]``. The numbers depend on the machine and its load; read the ratios.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time
from pathlib import Path

import numba as nb
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _timing import best_of  # noqa: E402

import parapend  # noqa: E402
from parapend.dynamics import persistence as P  # noqa: E402
from parapend.dynamics._persist_kernel import run_batch  # noqa: E402

MASS, LENGTH = 1.0, 0.3
C, CG = 2e-4, 5e-4


@nb.njit(cache=True)
def scalar_rk4(zdd, a, g, b, th, om, h):
    """The plain loop: one record, classical RK4, ``math.sin``; returns the final state."""
    n2 = zdd.size
    for j in range(n2 // 2):
        z1, z2, z3 = zdd[2 * j], zdd[2 * j + 1], zdd[(2 * j + 2) % n2]
        f1 = a * (g + z1) * math.sin(th) - b * om
        t2, w2 = th + 0.5 * h * om, om + 0.5 * h * f1
        f2 = a * (g + z2) * math.sin(t2) - b * w2
        t3, w3 = th + 0.5 * h * w2, om + 0.5 * h * f2
        f3 = a * (g + z2) * math.sin(t3) - b * w3
        t4, w4 = th + h * w3, om + h * f3
        f4 = a * (g + z3) * math.sin(t4) - b * w4
        th, om = th + h / 6 * (om + 2 * w2 + 2 * w3 + w4), om + h / 6 * (f1 + 2 * f2 + 2 * f3
                                                                       + f4)
    return th, om


def _spec(**kw):
    args = {"mass": MASS, "length": LENGTH, "inertia": None, "gravity": 9.81,
            "damping_coefficient": C, "generator_damping": CG, "hs": 0.02, "tp": 0.3,
            "spectrum": "jonswap", "gamma_peak": 3.3, "cutoff": 3.0, "response": None,
            "duration": 400 * 0.3, "transient": None, "realizations": 64, "seed": 0,
            "omniscient": 0, "controller": None, "gpu": False}
    args.update(kw)
    return P.persistence_spec(**args)


def steps_per_second(records: int = 64) -> None:
    spec = _spec(realizations=records)
    plan = P.cell_plan(spec, 0, 0)
    zdd = P.acceleration(spec, plan, list(range(records)))
    inertia = MASS * LENGTH**2
    a, b = MASS * LENGTH / inertia, (C + CG) / inertia
    kw = {"a": a, "g": 9.81, "th0": math.pi, "om0": plan["om0"], "h": plan["h"],
          "k0": plan["k0"], "twin": 2 * plan["tp"], "nwin": plan["nwin"]}
    tk, (out, _) = best_of(lambda: run_batch(zdd, b, **kw), 3)

    def scalar():
        return [scalar_rk4(zdd[r], a, 9.81, b, math.pi, plan["om0"], plan["h"])
                for r in range(records)]

    ts, ref = best_of(scalar, 3)
    steps = records * plan["m"]
    dev = max(abs(out[r, 2] - ref[r][0]) for r in range(records))
    print(f"records: {records} x {plan['m']} steps (h = {plan['h']:.4g} s, "
          f"{plan['tp'] / plan['h']:.3g} per Tp), numba threads {nb.get_num_threads()}, "
          f"CPUs {os.cpu_count()}")
    print(f"  kernel (batched, accumulations inside): {steps / tk / 1e6:8.2f} M steps/s "
          f"({tk:.3f} s)")
    print(f"  plain scalar RK4 loop (math.sin)      : {steps / ts / 1e6:8.2f} M steps/s "
          f"({ts:.3f} s)")
    print(f"  ratio kernel / scalar: {ts / tk:.2f}; largest |theta| difference at the end "
          f"{dev:.2g} rad (chaotic records part over 400 Tp: the two sines differ in the "
          "last bit)")


def acceptance_map(grid: int, realizations: int, gpu: bool, columns: int | None = None) -> None:
    t0 = 2 * math.pi * math.sqrt(LENGTH / 9.81)
    hs = f"0.0025:0.05:{grid}"
    # 400 peak periods at every Tp: one map per Tp column (the record's length is the
    # map's; on the GPU a column is one block, one launch), timed together
    total, work, states = 0.0, 0.0, []
    # compiled (the CPU kernel, the GPU kernel, CuPy's FFT plans) before the clock starts
    parapend.persistence(mass=MASS, length=LENGTH, damping_coefficient=C,
                         generator_damping=CG, hs="0.01,0.02", tp=0.15 * t0,
                         duration=40 * 0.15 * t0, realizations=8, gpu=gpu)
    with tempfile.TemporaryDirectory() as tmp:
        tps = np.linspace(0.15 * t0, 0.6 * t0, grid)
        if columns is not None and columns < grid:  # evenly spread Tp columns of the grid
            tps = tps[np.unique(np.linspace(0, grid - 1, columns).round().astype(int))]
        for j, t in enumerate(tps):
            start = time.perf_counter()
            r = parapend.persistence(mass=MASS, length=LENGTH, damping_coefficient=C,
                                     generator_damping=CG, hs=hs, tp=float(t),
                                     duration=400 * float(t), realizations=realizations,
                                     store=str(Path(tmp) / f"m{j}.zarr"), gpu=gpu)
            total += time.perf_counter() - start
            work += P.estimate_steps(P.persistence_spec(
                mass=MASS, length=LENGTH, inertia=None, gravity=9.81,
                damping_coefficient=C, generator_damping=CG, hs=hs, tp=float(t),
                spectrum="jonswap", gamma_peak=3.3, cutoff=3.0, response=None,
                duration=400 * float(t), transient=None, realizations=realizations,
                seed=0, omniscient=0, controller=None, gpu=False))
            states += r.sea_states
            check = r.step_check
    full_work = work * (20 * 20 * 1000) / (grid * len(tps) * realizations)
    print(f"map {grid} Hs x {len(tps)} Tp x {realizations} realizations of 400 Tp "
          f"({'GPU' if gpu else 'CPU'}): {total:.1f} s, {work / total / 1e6:.2f} M steps/s "
          f"(step check on the last column: {check['steps_per_peak_period']:.3g} steps per "
          f"Tp, theta after one Tp changed by {check['theta_change_rad']:.2g} rad "
          f"when halved, energy residual {check['energy_residual_max']:.2g})")
    if (grid, len(tps), realizations) != (20, 20, 1000):
        print(f"  extrapolated to 20 x 20 x 1000 by the work: {total * full_work / work:.0f} "
              "s")
    p = np.array([s["p_rot"] for s in states])
    print(f"  P_rot over the map: min {p.min():.3f}, max {p.max():.3f}; cells with P_rot > "
          f"0.9: {int(np.sum(p > 0.9))}, < 0.1: {int(np.sum(p < 0.1))}")
    print("  Tp/T0   Hs m    P_rot  [95 %]           rho   power W")
    for s in states[:: max(1, len(states) // 12)]:
        print(f"  {s['tp_over_t0']:.3f}  {s['hs_m']:.4f}  {s['p_rot']:.3f}  "
              f"[{s['p_rot_ci'][0]:.3f}, {s['p_rot_ci'][1]:.3f}]  {s['rho_mean']:.3f}  "
              f"{s['power_mean_w']:.4g}")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--realizations", type=int, default=1000)
    ap.add_argument("--grid", type=int, default=20)
    ap.add_argument("--columns", type=int, default=None,
                    help="run only this many Tp columns of the grid (evenly spread)")
    ap.add_argument("--gpu", action="store_true")
    ap.add_argument("--skip-kernel", action="store_true")
    a = ap.parse_args(argv)
    if not a.skip_kernel:
        steps_per_second()
    acceptance_map(a.grid, a.realizations, a.gpu, a.columns)


if __name__ == "__main__":
    main()
