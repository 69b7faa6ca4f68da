r"""Time the hull's coupled optimum (surge, heave, pitch; a pendulum that rotates or swings)
against the independent CasADi + IPOPT implementation of the same model on the same
discretization (tests/hull_reference.py: the pendulum's and the hull's coefficients both
variables, the projected hull equations as constraints, IPOPT with CasADi's exact AD
Hessian, MUMPS).

Cases: the two synthetic bodies of tests/test_hull_ipopt.py (a box barge's magnitudes, and a
causal hull whose A and B come from one set of damped modes), K = 0 (swinging) and K = 1
(rotation), N = 12 and 24 harmonics of phi, Nh = 8 hull harmonics.

1. **local**: one local solve from the same start (the one-way optimum): parapend's
   safeguarded Newton on the reduced problem (:class:`parapend.hydro.hull.HullProblem`:
   the hull solved at each phi, exact gradient by the adjoint and Hessian by the
   sensitivity) against IPOPT on the full space. "IPOPT (s)" is its solve alone (the
   comparison favours IPOPT); "IPOPT+setup" the whole call, CasADi's graph and IPOPT's
   set-up included (what a new case costs a CasADi user: the data are in the graph).
2. **search**: parapend's whole search (:func:`parapend.hydro.hull.hull_search`
   without refinement: the one-way maxima from every start, then the coupled problem from
   them and from the starts) against IPOPT from its eight starts.

Both in this one process, alternately; the best of ``--local-repeat`` local solves (30: a
few milliseconds each, and this machine's timings of one solve vary by a third from run to
run) and of ``--repeat`` searches, after one warm-up;
the powers are printed beside the times (they agree to 1e-12 where both reach the same
maximum; a local IPOPT solve that ends at another point gets no ratio). BLAS on one thread.

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_hull.py --repeat 5``.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from _timing import best_of  # noqa: E402  (benchmarks/_timing.py)
from hull_reference import box_case, hull_reference  # noqa: E402
from test_hull_ipopt import _causal, _hull_case  # noqa: E402

from parapend.hydro.hull import (  # noqa: E402
    GTOL,
    HullProblem,  # noqa: E402
    hull_search,
)
from parapend.optimal.fourier import newton_maximize  # noqa: E402


def cases(harmonics):
    return {f"box K=0 N={harmonics}": box_case(winding=0, harmonics=harmonics,
                                                 hull_harmonics=8),
            f"box K=1 N={harmonics}": box_case(winding=1, harmonics=harmonics,
                                                 hull_harmonics=8),
            f"causal K=0 N={harmonics}": _causal(0, harmonics),
            f"causal K=1 N={harmonics}": _causal(1, harmonics)}


def _timed(fn, repeat):
    """``repeat`` calls of ``fn``: their results and the shortest wall time (CasADi's graph
    and IPOPT's set-up included)."""
    out, best = [], float("inf")
    for _ in range(repeat):
        t = time.perf_counter()
        out.append(fn())
        best = min(best, time.perf_counter() - t)
    return out, best


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=3, help="runs of each search")
    ap.add_argument("--local-repeat", type=int, default=30,
                    help="runs of each local solve (IPOPT's: as --repeat where one takes "
                         "over a second)")
    ap.add_argument("--harmonics", default="12,24")
    a = ap.parse_args()
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"Python {platform.python_version()}")
    head = (f"{'case':20s} {'kind':7s} {'parapend (s)':>12s} {'IPOPT (s)':>10s} "
            f"{'ratio':>7s} {'IPOPT+setup':>12s} {'ratio':>7s} {'P parapend (W)':>16s} "
            f"{'P IPOPT (W)':>16s}")
    print(head)
    print("-" * len(head))
    for n in (int(s) for s in a.harmonics.split(",")):
        for name, kw in cases(n).items():
            cs = _hull_case(kw)
            one = newton_maximize(HullProblem(cs, coupled=False),
                                  hull_search(lambda s, cs=cs: cs, refine=False).one_way_x,
                                  "one-way", gtol=GTOL)
            x0 = one.x
            pr = HullProblem(cs)
            t_ours, r = best_of(lambda pr=pr, x0=x0: newton_maximize(pr, x0, "s", gtol=GTOL),
                                a.local_repeat)
            first = hull_reference(**kw, x0=x0)
            ref, walls = _timed(lambda kw=kw, x0=x0: hull_reference(**kw, x0=x0),
                                a.local_repeat if first["time_s"] < 1.0 else a.repeat)
            t_ref = min(x["time_s"] for x in ref)
            same = abs(ref[0]["power"] - r.power) <= 1e-6 * abs(r.power)
            ratio = (f"{t_ref / t_ours:7.1f}", f"{walls / t_ours:7.1f}") if same else ("-",) * 2
            print(f"{name:20s} {'local':7s} {t_ours:12.4f} {t_ref:10.4f} "
                  f"{ratio[0]:>7s} {walls:12.4f} {ratio[1]:>7s} "
                  f"{r.power:16.10g} {ref[0]['power']:16.10g}"
                  + ("" if same else "  (IPOPT ends elsewhere: no ratio)"))
            t_ours, s = best_of(lambda cs=cs: hull_search(lambda k: cs, refine=False),
                                a.repeat)
            ref, walls = _timed(lambda kw=kw: hull_reference(**kw, starts=8), a.repeat)
            t_ref = min(x["time_s"] for x in ref)
            print(f"{name:20s} {'search':7s} {t_ours:12.4f} {t_ref:10.4f} "
                  f"{t_ref / t_ours:7.1f} {walls:12.4f} {walls / t_ours:7.1f} "
                  f"{s.power:16.10g} {ref[0]['power']:16.10g}")


if __name__ == "__main__":
    main()
