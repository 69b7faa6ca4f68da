r"""Why did the buoy planner (``parapend buoy --controller mpc``, ``controller="plan"``) with
a PERFECT forecast lose to its own AR forecast in short steep seas (Hs 0.8 m, Tp 3 s)? What
each plan does at its end.

For one seeded record (``parapend buoy --hs 0.8 --tp 3 --repeat-period 36 --seed S``, the
default buoy, pendulum, torque limit and horizon of 2 peak periods) it runs the closed loop
with each forecast and records, for every horizon solve, the mechanical energy of buoy and
pendulum now (``E0``, the plant's), at the forecast's end ``H`` and at the plan's end
``T`` (``ET``, from the plan's heave and angle there), the plan's objective ``J = W + ET -
E0`` (its harvested work ``W`` follows), and the buoy's speed and the pendulum's at the
plan's end. Then the closed loop's power and its account over the averaging window
(absorbed, the pendulum's damping, stored). ``--tail T``: the horizon model run ``T`` peak
periods past the forecast's horizon with no excitation
(:data:`parapend.hydro.control.PLAN_TAIL`; 0: the planner before, its end at the
forecast's).

    OPENBLAS_NUM_THREADS=1 python benchmarks/diagnose_buoy_plan_tail.py --seed 0 --tail 0,1

Output: ``benchmarks/diagnose_buoy_plan_tail.out.txt``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from parapend.control.plan import HorizonPlan
from parapend.hydro import api
from parapend.hydro import control as bc


def run(seed, forecast, tail, repeat_period=36.0, hs=0.8, tp=3.0, horizon=2.0):
    rec = []
    orig = bc._MotionPlanner.plan_radiation

    def probe(self, plant, fseg, shift):
        e0 = plant.energy()
        out = orig(self, plant, fseg, shift)
        if self.nodes is not None:
            th, v = self.nodes
            x = np.empty(2 * self.k)
            x[0::2], x[1::2] = th[1:], v[1:]
            end, eps = self.hh * self.k, 1e-4
            hf = self.n_out * self.dt  # the forecast's end
            z = self.prob.heave(x, np.array([end - eps, end, hf - eps, hf]))
            zd = (z[1] - z[0]) / eps
            et = plant.energy(np.array([z[1], zd, th[-1], v[-1]]))
            ah, vh, _ = HorizonPlan(self.hh, th, v, 0.0).evaluate(np.array([hf]))
            eh = plant.energy(np.array([z[3], (z[3] - z[2]) / eps, ah[0], vh[0]]))
            rec.append(dict(E0=e0, ET=et, EH=eh, J=-self.prob.values(x)[0], zdT=zd,
                            omT=v[-1]))
        return out

    bc._MotionPlanner.plan_radiation = probe
    old_tail = bc.PLAN_TAIL
    bc.PLAN_TAIL = tail
    try:
        r = api.buoy(hs=hs, tp=tp, seed=seed, repeat_period=repeat_period, controller="mpc",
                     forecast=forecast, horizon=horizon)
    finally:
        bc._MotionPlanner.plan_radiation = orig
        bc.PLAN_TAIL = old_tail
    return r, {k: np.array([d[k] for d in rec]) for k in rec[0]}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--tail", default="0,1", help="peak periods, a comma list")
    ap.add_argument("--repeat-period", type=float, default=36.0)
    a = ap.parse_args()
    for tail in (float(x) for x in a.tail.split(",")):
        for fc in ("perfect", "ar"):
            t0 = time.perf_counter()
            r, d = run(a.seed, fc, tail, a.repeat_period)
            w = d["J"] - (d["ET"] - d["E0"])
            s = r.series
            sel = s["t"] >= r.average_from_s
            print(f"seed {a.seed}, tail {tail:g} Tp, {fc}: {r.mean_power_w:.2f} W of the "
                  f"optimum {r.optimum_power_w:.2f} W ({r.mean_power_w / r.optimum_power_w:.1%}"
                  f"), {r.failed_solves} of {r.solves} solves abnormal, "
                  f"{time.perf_counter() - t0:.0f} s")
            print(f"  plans (median): objective J {np.median(d['J']):.1f} J, harvested W "
                  f"{np.median(w):.1f} J, stored ET - E0 {np.median(d['ET'] - d['E0']):.1f} J "
                  f"(E0 mean {d['E0'].mean():.1f} J), at the forecast's end "
                  f"{np.median(d['EH'] - d['E0']):.1f} J; at the plan's end |z'| "
                  f"{np.median(np.abs(d['zdT'])):.3f} m/s, |theta'| "
                  f"{np.median(np.abs(d['omT'])):.2f} rad/s")
            print(f"  closed loop over the window: absorbed {r.absorbed_w:.2f} W, the "
                  f"pendulum's damping {r.damping_w:.2f} W, stored {r.stored_w:.2f} W; mean "
                  f"|theta'| {np.mean(np.abs(s['theta_dot'][sel])):.2f} rad/s, rms z' "
                  f"{np.sqrt(np.mean(s['z_dot'][sel] ** 2)):.3f} m/s")


if __name__ == "__main__":
    main()
