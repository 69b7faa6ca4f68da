r"""Time ``parapend.sea`` against CasADi + IPOPT direct collocation over the same sea record.

Records: JONSWAP, Hs = 2 m, Tp = 8 s, seed 0, components up to 3 fp, repeat periods of
WAVES peak periods; pendulum l = 1 m, m = 10 kg, gamma = 0.01, winding K = 1.

1. **parapend**: :func:`parapend.irregular.sea` (record, global search with the dynamic
   programme's seeds and the matrix-free Newton-CG kernel at N = 16 harmonics per mean wave,
   and the refinement at 2N). Wall time of the whole call.
2. **CasADi + IPOPT**: ``tests/casadi_pto.py`` (Hermite-Simpson collocation of Eq. 14 with
   the torque as control, theta(T_r) = theta(0) + 2 pi K), ``INTERVALS`` per peak period,
   started from the uniform rotation (its default, as a user would) and, separately, from
   parapend's optimum sampled on its grid (how close IPOPT's own optimum is). IPOPT's solve
   time only (graph construction excluded).

The powers are printed beside each other: the collocation's ``-<T theta'>`` on its Simpson
rule and parapend's optimum. Timings depend on the machine and its load; read the ratios.

``--kernels [N ...]`` times one Newton run with the dense Hessian (Cholesky, O(N^3)) against
the operator Hessian (Newton-CG, FFTs) from the same seed instead.

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_sea.py [--waves 4 10 25]``. With 40
intervals per peak period IPOPT exploited the coarse rule (P = 9.6 against a limit of 0.02 on
10 waves): the turns of the optimum are about one time unit wide, so 150 are used.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from parapend.irregular import sea  # noqa: E402

INTERVALS = 150


def kernels(sizes):
    """One Newton run, dense Hessian (Cholesky) against the operator (Newton-CG), same seed."""
    from parapend.optimal.fourier import FourierProblem, newton_maximize
    from parapend.optimal.limit import limit, limit_seed

    r = sea(hs=2.0, tp=8.0, repeat_period=8.0 * 20, seed=0, harmonics=64)
    exc = r.excitation
    lim = limit(exc)
    print("| N | dense P | dense s | operator P | operator s | ratio |")
    print("|---|---|---|---|---|---|")
    for n in sizes:
        x0 = limit_seed(lim, n).vector
        out = []
        for h in ("dense", "operator"):
            pb = FourierProblem(exc, n, r.gamma, hessian=h)
            t = time.perf_counter()
            sol = newton_maximize(pb, x0, "limit")
            out.append((sol.power, time.perf_counter() - t))
        print(f"| {n} | {out[0][0]:.12f} | {out[0][1]:.2f} | {out[1][0]:.12f} | "
              f"{out[1][1]:.2f} | {out[0][1] / out[1][1]:.1f}x |", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--waves", type=int, nargs="+", default=[4, 10, 25])
    ap.add_argument("--kernels", type=int, nargs="*", default=None,
                    help="only time one Newton run, dense against operator Hessian, at these N "
                         "(20-wave record from its limit seed)")
    ap.add_argument("--intervals", type=int, default=INTERVALS,
                    help="collocation intervals per peak period")
    ap.add_argument("--max-iter", type=int, default=3000)
    a = ap.parse_args()
    if a.kernels is not None:
        kernels(a.kernels or [128, 256, 512, 1024])
        return
    from casadi_pto import collocate

    rows = []
    for w in a.waves:
        t0 = time.perf_counter()
        r = sea(hs=2.0, tp=8.0, repeat_period=8.0 * w, seed=0)
        t_ours = time.perf_counter() - t0
        exc = r.excitation
        k = a.intervals * w
        c = collocate(exc, r.gamma, intervals=k, winding=r.winding, tol=1e-8,
                      max_iter=a.max_iter)
        mot = r.motion

        def guess(t, mot=mot, exc=exc, g=r.gamma):
            th, thd = mot.theta(t), mot.theta_dot(t)
            thdd = mot.theta_ddot(t)
            return th, thd, thdd + g * thd - (1 + exc.q(t)) * np.sin(th)

        w_start = collocate(exc, r.gamma, intervals=k, winding=r.winding, tol=1e-8,
                            guess=guess, max_iter=a.max_iter)
        rows.append((w, r.harmonics, r.power, t_ours, k, c["power"], c["status"],
                     c["solve_time"], w_start["power"], w_start["solve_time"]))
        print(f"{w} waves: parapend N = {r.harmonics}, P = {r.power:.9f} ({r.power_w:.5g} W) "
              f"in {t_ours:.2f} s; IPOPT {k} intervals from uniform: P = {c['power']:.9f} "
              f"({c['status']}) in {c['solve_time']:.2f} s; from parapend's optimum: "
              f"P = {w_start['power']:.9f} in {w_start['solve_time']:.2f} s", flush=True)
    print()
    print("| waves | parapend N | parapend P | parapend s | IPOPT intervals | IPOPT P (uniform "
          "start) | IPOPT s | ratio | IPOPT P (parapend start) | IPOPT s |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for w, n, p, t, k, pc, st, tc, pw, tw in rows:
        print(f"| {w} | {n} | {p:.9f} | {t:.2f} | {k} | {pc:.9f} ({st}) | {tc:.2f} | "
              f"{tc / t:.1f}x | {pw:.9f} | {tw:.2f} |")


if __name__ == "__main__":
    main()
