r"""Time parapend's power take-off optimizers against CasADi + IPOPT direct collocation.

Problems (paper case ``q = -0.3 sin(1.8 t)``), issue 9: the torque-limited optimum
``|T| <= T_max`` and the optimum of the electrical power with efficiency ``eta``
(``eta p`` generating, ``p / eta`` motoring).

1. **parapend**: the ideal optimum (``parapend.optimize``, N = 24) then
   - torque limit: :func:`parapend.optimal.hermite.solve_hermite` on K cubic Hermite
     intervals (primal-dual interior point on the banded Newton system, dense feasibility
     check included);
   - efficiency: :func:`parapend.optimal.collocation.solve_collocation` on K intervals:
     the same Hermite-Simpson collocation as IPOPT's below (so equal K, equal discrete
     problem and error), by a full-space primal-dual interior point on the banded KKT system.
   Wall time of everything, the best of ``--repeat`` runs after one untimed warm-up, from
   one of two starts (``--start``): ``ideal``, the ideal optimum computed first and
   included in the time (what ``optimize_pto`` does: it reports the ideal power too), or
   ``uniform``, the best uniform rotation (Eq. 17), the start IPOPT is given: the two
   solvers compared on the same problem from the same start.
2. **CasADi + IPOPT**: ``tests/casadi_pto.py``, Hermite-Simpson collocation on K intervals,
   piecewise-linear torque as the control, exact efficiency through slacks. IPOPT's solve
   time only (the graph built before it is not counted), the best of ``--repeat``.

The error is against a reference: the collocation with K = 600. For each accuracy level
the fastest configuration of each tool that reaches it is compared: the ratio is CasADi's
time over ours (above 1: parapend faster). Timings depend on the machine and its load;
read the ratios (both tools run in this one process, alternately; the best of the repeats
is the least disturbed by other load).

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_pto.py``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import numpy as np  # noqa: E402
from _timing import best_of  # noqa: E402  (benchmarks/_timing.py)

import parapend  # noqa: E402
from parapend.optimal.collocation import solve_collocation  # noqa: E402
from parapend.optimal.hermite import solve_hermite  # noqa: E402
from parapend.power import uniform_power  # noqa: E402
from parapend.trajectory import FourierMotion  # noqa: E402

CASES = [(0.03, {"torque_limit": 2.5}), (0.05, {"torque_limit": 2.0}),
         (0.03, {"torque_limit": 1.0}), (0.03, {"efficiency": (0.9, 0.9)}),
         (0.05, {"efficiency": (0.7, 0.7)})]
LEVELS = (1e-5, 1e-6, 1e-7)
SIZES = (25, 50, 75, 100, 150, 200)  # IPOPT's collocation intervals


def ours(gamma, kw, size, start="ideal"):
    exc = parapend.harmonic(-0.3, 1.8)
    if start == "ideal":
        motion = parapend.optimize(gamma=gamma, harmonics=24).motion
    else:
        _, phi = uniform_power(exc, gamma)
        motion = FourierMotion(exc.omega, phi, np.zeros(1), np.zeros(1))
    if "torque_limit" in kw:
        return solve_hermite(exc, gamma, size, motion, **kw)
    return solve_collocation(exc, gamma, size, motion, **kw)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--problems", choices=["all", "torque-limit", "efficiency"], default="all",
                    help="which rows to run")
    ap.add_argument("--start", choices=["ideal", "uniform"], default="ideal",
                    help="parapend's start: the ideal optimum (timed too) or, as IPOPT's, "
                         "the best uniform rotation")
    a = ap.parse_args()
    from casadi_pto import collocate

    exc = parapend.harmonic(-0.3, 1.8)
    print(f"{'case':30s} {'method':18s} {'time s':>8s} {'value':>12s} {'|error|':>9s}")
    summary = []
    for gamma, kw in CASES:
        if a.problems != "all" and ("torque_limit" in kw) != (a.problems == "torque-limit"):
            continue
        ref = collocate(exc, gamma, intervals=600, **kw)["electrical_power"]
        name = f"gamma={gamma} " + ", ".join(f"{k}={v}" for k, v in kw.items())
        rows = []
        # K: Hermite intervals (torque limit) or collocation intervals (efficiency, the
        # same discrete problem as IPOPT's at equal K)
        sizes = (32, 48, 64, 96, 128, 192, 256, 512) if "torque_limit" in kw else SIZES
        label = "K"
        for n in sizes:
            t, s = best_of(lambda n=n, g=gamma, k=kw: ours(g, k, n, a.start), a.repeat)
            rows.append(("parapend", f"{label}={n}", t, s.electrical_power))
        for k in SIZES:
            ts = []
            for _ in range(a.repeat):
                c = collocate(exc, gamma, intervals=k, **kw)
                ts.append(c["solve_time"])
            rows.append(("casadi", f"K={k}", min(ts), c["electrical_power"]))
        for tool, m, t, v in rows:
            print(f"{name:30s} {tool + ' ' + m:18s} {t:8.3f} {v:12.8f} {abs(v - ref):9.1e}",
                  flush=True)
        print(f"{name:30s} {'reference K=600':18s} {'':8s} {ref:12.8f}", flush=True)
        for lev in LEVELS:
            best = {}
            for tool, m, t, v in rows:
                if abs(v - ref) <= lev and (tool not in best or t < best[tool][0]):
                    best[tool] = (t, m)
            summary.append((name, lev, best.get("parapend"), best.get("casadi")))
    print()
    print(f"{'case':30s} {'error <=':>8s} {'parapend':>16s} {'casadi':>16s} {'ratio':>7s}")
    for name, lev, p, c in summary:
        ps = f"{p[0]:.3f} ({p[1]})" if p else "not reached"
        cs = f"{c[0]:.3f} ({c[1]})" if c else "not reached"
        ratio = f"{c[0] / p[0]:7.1f}" if p and c else "      -"
        print(f"{name:30s} {lev:8.0e} {ps:>16s} {cs:>16s} {ratio}")


if __name__ == "__main__":
    main()
