r"""Time parapend's power take-off optimizer against CasADi + IPOPT direct collocation.

Problems (paper case ``q = -0.3 sin(1.8 t)``): the torque-limited optimum ``|T| <= T_max``
and the optimum of the electrical power with efficiency ``eta`` (``eta p`` generating,
``p / eta`` motoring), issue 9.

1. **parapend**: the ideal optimum (``parapend.optimize``, N harmonics) then
   :func:`parapend.optimal.constrained.solve_pto` from it (augmented Lagrangian /
   softplus-continued efficiency on the exact-Hessian Fourier Newton kernel). Wall time of
   both, median of ``--repeat`` runs after one untimed warm-up.
2. **CasADi + IPOPT**: ``tests/casadi_pto.py``, Hermite-Simpson collocation on K intervals,
   piecewise-linear torque as the control, exact efficiency through slacks. IPOPT's solve
   time only (graph construction excluded), median of ``--repeat``.

Accuracy is measured against a reference: the collocation with K = 400 (its values rise
monotonically with K and agree with Fourier N = 48 to about 1e-5). Timings are machine- and
load-dependent; read the ratios.

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_pto.py``.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import parapend  # noqa: E402
from parapend.optimal.constrained import solve_pto  # noqa: E402

CASES = [(0.03, {"torque_limit": 2.5}), (0.05, {"torque_limit": 2.0}),
         (0.03, {"efficiency": (0.9, 0.9)}), (0.05, {"efficiency": (0.7, 0.7)})]


def ours(gamma, kw, n):
    r = parapend.optimize(gamma=gamma, harmonics=n)
    return solve_pto(r._excitation, n, gamma, r.motion.vector, **kw)


def median_time(fn, repeat):
    fn()
    ts, out = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t)
    return statistics.median(ts), out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    from casadi_pto import collocate

    exc = parapend.harmonic(-0.3, 1.8)
    print(f"{'case':28s} {'method':18s} {'time s':>8s} {'value':>12s} {'|error|':>9s}")
    for gamma, kw in CASES:
        ref = collocate(exc, gamma, intervals=400, **kw)["electrical_power"]
        name = f"gamma={gamma} " + ", ".join(f"{k}={v}" for k, v in kw.items())
        rows = []
        for n in (16, 24, 32):
            t, s = median_time(lambda n=n, g=gamma, k=kw: ours(g, k, n), a.repeat)
            rows.append((f"parapend N={n}", t, s.electrical_power))
        for k in (50, 100, 150):
            ts = []
            for _ in range(a.repeat):
                c = collocate(exc, gamma, intervals=k, **kw)
                ts.append(c["solve_time"])
            rows.append((f"casadi K={k}", statistics.median(ts), c["electrical_power"]))
        for m, t, v in rows:
            print(f"{name:28s} {m:18s} {t:8.3f} {v:12.8f} {abs(v - ref):9.1e}", flush=True)
        print(f"{name:28s} {'reference K=400':18s} {'':8s} {ref:12.8f}", flush=True)


if __name__ == "__main__":
    main()
