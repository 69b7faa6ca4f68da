r"""The buoy's causal controller with a perfect and an autoregressive forecast of the
excitation force (issue 31's acceptance: the default buoy in its default irregular sea,
seeds 0-9; ``parapend buoy --hs 0.5 --tp 2.5 --repeat-period 25 --seed S --controller mpc
--horizon H [--forecast ar]``).

Per seed and setting: the storage-corrected mean power over the repeat after the 4-peak-
period warm-up, its fraction of the record's coupled non-causal optimum, and the update
time's p99 (forecast and solve) against the update interval. Settings: the ``coupled``
controller at a horizon of 2 peak periods (the acceptance's) with both forecasts, and
``plan`` (the radiation in its horizon model) at 1.5 and 2 peak periods with the perfect
forecast and at 2 with the AR forecast (``--settings`` picks some; timings with
``--workers 1`` on an otherwise idle machine).

    OPENBLAS_NUM_THREADS=1 python benchmarks/buoy_mpc_forecast.py [--seeds 0-9] [--workers 2]
        [--settings plan:2:perfect,plan:2:ar]

Output: ``benchmarks/buoy_mpc_forecast.out.txt``.
"""

from __future__ import annotations

import argparse
import os
import platform
from concurrent.futures import ProcessPoolExecutor

import numpy as np

SETTINGS = [("coupled", 2.0, "perfect"), ("coupled", 2.0, "ar"),
            ("plan", 1.5, "perfect"), ("plan", 2.0, "perfect"), ("plan", 2.0, "ar")]


def one(args):
    seed, controller, horizon, forecast = args
    import dataclasses

    from parapend.hydro import api
    from parapend.hydro import control as bc

    # the command line's mpc with the controller named (the rest of the command unchanged)
    real = bc.buoy_mpc

    def named(*a, **kw):
        return real(*a, **{**kw, "controller": controller,
                           **({"iterations": 1} if controller == "plan" else {})})
    bc.buoy_mpc = named
    r = api.buoy(hs=0.5, tp=2.5, repeat_period=25.0, seed=seed, controller="mpc",
                 horizon=horizon, forecast=forecast, time_limit=900)
    d = dataclasses.asdict(r) if not hasattr(r, "to_dict") else r.to_dict()
    return (seed, controller, horizon, forecast, d["mean_power_w"], d["optimum_power_w"],
            d["optimum_fraction"], d["update_time_p99_s"], d["update_interval_s"],
            d["status"])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", default="0-9")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--settings", default=None,
                    help="controller:horizon:forecast,... (default: all of SETTINGS)")
    a = ap.parse_args()
    lo, hi = (int(x) for x in a.seeds.split("-"))
    settings = SETTINGS
    if a.settings:
        settings = [(c, float(h), f) for c, h, f in
                    (x.split(":") for x in a.settings.split(","))]
    jobs = [(s, *st) for st in settings for s in range(lo, hi + 1)]
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores; one BLAS thread a process")
    with ProcessPoolExecutor(a.workers) as ex:
        rows = list(ex.map(one, jobs))
    print(f"{'controller':10s} {'H (Tp)':>6s} {'forecast':8s} {'seed':>4s} {'P (W)':>9s} "
          f"{'optimum':>9s} {'fraction':>9s} {'p99 (ms)':>9s} {'interval':>9s} status")
    for s, c, h, f, p, opt, frac, p99, iv, st in rows:
        print(f"{c:10s} {h:6.2g} {f:8s} {s:4d} {p:9.4g} {opt:9.4g} {frac:9.3f} "
              f"{1e3 * p99:9.1f} {1e3 * iv:9.1f} {st}")
    print()
    for c, h, f in settings:
        sel = [r for r in rows if r[1:4] == (c, h, f)]
        fr = np.array([r[6] for r in sel])
        pw = np.array([r[4] for r in sel])
        fits = sum(r[7] <= r[8] for r in sel)
        print(f"{c} H {h:g} {f}: mean fraction {fr.mean():.3f} (min {fr.min():.3f}, max "
              f"{fr.max():.3f}), mean power {pw.mean():.4g} W, positive {np.sum(pw > 0)} of "
              f"{pw.size}, p99 inside the interval {fits} of {len(sel)}")


if __name__ == "__main__":
    main()
