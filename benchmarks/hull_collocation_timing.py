"""The update time of the hull's collocation planner (``hull_mpc(planner="collocation")``)
and IPOPT's options: on the horizon problems of the first ``--updates`` updates of a run
(the embedded barge, its default sea, seed 0, perfect forecast, the pump's start), every
variant solves the same problem from its own warm start (its previous solution shifted),
the default's plan is applied; per variant the median and p99 of the solve's time, the
median iterations, the solves IPOPT ended short of its tolerance, and the median of the
horizon objective it reached (units m g l rad, minimized; comparable between variants of the
same grid) relative to the default's.

Variants: ``default`` (:data:`parapend.hydro._hull_collocation.IPOPT_OPTIONS`), ``mu1e-3``
(``mu_init`` 1e-3 and ``warm_start_init_point``), ``monotone`` (``mu_strategy`` monotone),
``tol1e-4``, ``stride6`` (the horizon's memory on every 6th point), ``coarse`` (one
Hermite-Simpson interval a torque sample: a 3 times coarser grid).

    nice python benchmarks/hull_collocation_timing.py --updates 20
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from parapend.hydro import _hull_collocation as hcol
from parapend.hydro import hull_control as hc
from parapend.hydro.api import hull_problem
from parapend.hydro.declared import default_of
from parapend.hydro.inputs import _irregular_wave
from parapend.units import Units

VARIANTS = {
    "default": ({}, {}),
    "mu1e-3": ({"mu_init": 1e-3, "warm_start_init_point": "yes"}, {}),
    "monotone": ({"mu_strategy": "monotone"}, {}),
    "tol1e-4": ({"tol": 1e-4}, {}),
    "stride6": ({}, {"stride": 6}),
    "coarse": ({}, {"intervals": 1}),
}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--updates", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    p = hull_problem()
    pend = p["pendulum"]
    wave, _ = _irregular_wave(1.0, 6.0, "jonswap", 3.3, 24.0, a.seed,
                              default_of("cutoff", None), None, default_of("taper", None),
                              Units(pend.length, pend.mass, 9.81, pend.inertia))
    probs, rows = {}, {k: [] for k in VARIANTS}

    def plan(prob, plant, fseg, u0, max_iter):
        if not probs:
            for name, (opts, kw) in VARIANTS.items():
                if name == "default":
                    probs[name] = prob
                    continue
                stride = hcol.MEMORY_STRIDE
                hcol.MEMORY_STRIDE = kw.get("stride", stride)
                q = hcol.HullCollocation(plant, prob.n, prob.steps, prob.tu,
                                         prob.torque_limit, None, None,
                                         intervals=kw.get("intervals"), max_iter=max_iter,
                                         options=opts)
                hcol.MEMORY_STRIDE = stride
                q.shift = prob.shift
                probs[name] = q
        keep = None
        for name, q in probs.items():
            t = time.perf_counter()
            r = q.solve(plant, fseg, u0)
            rows[name].append((time.perf_counter() - t, r.nit, r.status != 0, r.fun))
            if name == "default":
                keep = r
        if len(rows["default"]) >= a.updates:
            raise StopIteration
        return keep

    hc._plan = plan
    try:
        hc.hull_mpc(p["hull"], pend, wave, peak_period=6.0, pivot=p["pivot"], mode="rotate",
                    planner="collocation")
    except StopIteration:
        pass
    ref = np.array([r[3] for r in rows["default"]])
    print(f"seed {a.seed}, {len(ref)} updates: variant median_s p99_s median_iterations "
          "capped median_objective (default's)")
    for name, rs in rows.items():
        t = np.array([r[0] for r in rs])
        f = np.array([r[3] for r in rs])
        print(f"  {name:9s} {np.median(t):6.2f} {np.percentile(t, 99):6.2f} "
              f"{np.median([r[1] for r in rs]):5.0f} {sum(r[2] for r in rs):3d}/{len(rs)} "
              f"{np.median(f):8.3f} ({np.median(ref):.3f})", flush=True)


if __name__ == "__main__":
    main()
