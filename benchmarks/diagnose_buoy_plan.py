r"""Where does ``buoy_mpc(controller="plan")`` lose against the coupled non-causal optimum?
(docs/buoy.md, "Experimental: the motion as the unknown").

For one seeded record of the default buoy and sea (cylinder 0.5 m x 0.5 m, 80 kg / 0.3 m
pendulum, JONSWAP Hs 0.5 m, Tp 2.5 s, a repeat period of 25 s; perfect forecast of 2 peak
periods, 4 peak periods of warm-up, one repeat averaged) it prints:

1. the energy account of the closed loop against the record's coupled optimum (winding 10):
   the power the buoy absorbs from the waves ``<(F_exc - mu) z'>``, the pendulum's damping
   ``c <theta'^2>``, the rms heave and heave speed (the optimum's from its periodic motion,
   the closed loop's over the averaging window);
2. the model's error where it matters to the loop: at the end of each update interval (5
   torque samples), the plan's predicted heave and angle against the plant's (Cummins,
   radiation memory) replay of the held torques from the same state;
3. the same closed loop with each update's solve ALSO started from the non-causal optimum's
   own motion over the horizon (shifted to the measured angle) and the better horizon
   optimum kept (``--start both``), or started from it alone (``--start optimum``): whether
   the loop's shortfall is a basin of the non-convex horizon problem (it would then follow
   the optimum's turn per wave and its power) or the horizon problem itself;
4. the plan's MOTION (not its torques, which open loop do not keep a rotating pendulum on
   the plan) replayed in the plant over the whole horizon: the heave error and the horizon
   objective of that motion in the model and in the plant.

``--frozen``: the planner without the radiation's marginal cost (``radiation_cost=False``);
``--frozen-model``: the memory force predicted under the previous plan frozen in the
horizon model's dynamics (``radiation_model=False``, the planner before the radiation was
put inside its model; ``--frozen`` applies to it alone).

    OPENBLAS_NUM_THREADS=1 python benchmarks/diagnose_buoy_plan.py --seed 0 [--horizon 1.5]
        [--start previous|both|optimum] [--frozen] [--frozen-model]

One closed loop takes 20 to 60 s on one core; the output of the cases docs/buoy.md quotes is
in ``benchmarks/diagnose_buoy_plan.out.txt``.
"""

from __future__ import annotations

import argparse
import copy
import math

import numpy as np

from parapend.hydro import api
from parapend.hydro import control as bc
from parapend.hydro.result import _solve


def setup(seed):
    """The command line's buoy, pendulum and record (``parapend buoy --hs 0.5 --tp 2.5
    --repeat-period 25 --seed S``), taken where ``buoy`` hands them to the controller."""
    got = {}

    def grab(hydro, pendulum, wave, info, **kw):
        got.update(hydro=hydro, pend=pendulum, wave=wave)
        raise StopIteration

    orig = bc.mpc_command
    bc.mpc_command = grab
    try:
        api.buoy(hs=0.5, tp=2.5, seed=seed, repeat_period=25.0, controller="mpc")
    except StopIteration:
        pass
    finally:
        bc.mpc_command = orig
    return got["hydro"], got["pend"], got["wave"]


class Probe:
    """Wraps ``_MotionPlanner.plan`` (and ``_Plant.step`` for the clock): the model's error
    over the update interval, and the optional start from the optimum's motion."""

    def __init__(self, sol, start):
        self.sol, self.start, self.t = sol, start, 0.0
        self.err_z, self.err_th, self.kept_opt, self.updates = [], [], 0, 0
        self.motion = []

    def install(self):
        orig_step, orig_plan, probe = bc._Plant.step, bc._MotionPlanner.plan, self

        def step(plant, u, steps, fn):
            probe.t += u.size * steps * plant.h
            return orig_step(plant, u, steps, fn)

        def plan(mp, plant, u0, fseg, iterations, relaxation, shift, residual):
            if probe.start == "previous":
                out = orig_plan(mp, plant, u0, fseg, iterations, relaxation, shift, residual)
            else:
                out = probe.plan_from_optimum(mp, plant, u0, fseg, shift)
            probe.replay(mp, plant, out[0], fseg)
            return out

        bc._Plant.step, bc._MotionPlanner.plan = step, plan
        return lambda: (setattr(bc._Plant, "step", orig_step),
                        setattr(bc._MotionPlanner, "plan", orig_plan))

    def plan_from_optimum(self, mp, plant, u0, fseg, shift):
        pr = mp.prob
        y0 = plant.y.copy()
        if mp.radiation:
            mp.set_radiation_start(plant, fseg)
        else:
            out = plant.predict(u0 * mp.tu, mp.ps, fseg, memory_force=True)
            mu = out[1] if out is not None else np.full(fseg.size, plant.mus[0])
            fm = fseg - mu
            pr.set_start(y0, lambda s, fm=fm: np.interp(s, mp.tf, fm))
        sm = self.sol.sample(self.t + mp.tn)
        xo = np.empty(2 * mp.k)
        xo[0::2] = (sm["theta"] - sm["theta"][0] + y0[2])[1:]
        xo[1::2] = sm["theta_dot"][1:]
        starts = [("optimum", xo)]
        if self.start == "both":
            starts.insert(0, ("previous", mp.start(y0, shift)))
        best = None
        for name, x in starts:
            with bc._blas_controller().limit(limits=1, user_api="blas"):
                xs, _, _ = pr.solve(x, max_iter=bc.PLAN_MAX_ITER)
            if not np.all(np.isfinite(xs)):
                continue
            feasible = np.max(np.abs(pr.constraint_torques(xs))) <= mp.tmax * (1 + 1e-3)
            val = pr.objective(xs)
            if feasible and (best is None or val < best[0]):
                best = (val, name, xs)
        self.updates += 1
        if best is None:
            return u0, [], None, 1, (1, 1)
        self.kept_opt += best[1] == "optimum"
        x = best[2]
        u = np.clip(pr.torques(x).reshape(mp.n, 3) @ mp.w3, -mp.tmax, mp.tmax) / mp.tu
        full = pr.full(x)
        mp.nodes = (full[0::2].copy(), full[1::2].copy())
        return u, [], None, 1, (0, 0)

    def replay(self, mp, plant, u, fseg):
        """The plan's heave and angle at the update's end against the plant's replay."""
        from parapend.control.plan import HorizonPlan

        if mp.nodes is None:
            return
        m = 5  # the default update interval, Tp / 8, in samples of Tp / 64
        pl = copy.deepcopy(plant)
        pl.vel = np.concatenate((pl.vel, np.zeros(2 * m * mp.ps + 8)))
        for k in range(m):
            _, ys = pl.step(np.array([u[k] * mp.tu]), mp.ps,
                            fseg[2 * k * mp.ps:2 * (k + 1) * mp.ps + 1])
        lead = np.array([m * mp.dt])
        nodes = np.column_stack((mp.nodes[0][1:], mp.nodes[1][1:])).ravel()
        z = mp.prob.heave(nodes, lead)[0]
        th = HorizonPlan(mp.hh, mp.nodes[0], mp.nodes[1], 0.0).evaluate(lead)[0][0]
        self.err_z.append(abs(z - ys[1, 0]))
        self.err_th.append(abs(th - ys[1, 2]))
        self.motion.append(replay_motion(mp, plant, fseg))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--start", choices=("previous", "both", "optimum"), default="previous")
    ap.add_argument("--horizon", type=float, default=2.0, help="peak periods")
    ap.add_argument("--frozen", action="store_true",
                    help="the memory force frozen alone in the objective (radiation_cost=False)")
    ap.add_argument("--frozen-model", action="store_true",
                    help="the memory force frozen in the horizon model's dynamics "
                         "(radiation_model=False, the planner before)")
    a = ap.parse_args()
    hydro, pend, wave = setup(a.seed)
    sol, _, _ = _solve(hydro, pend, wave, winding=10, harmonics=None, torque_limit=None,
                       efficiency=None, one_way=False)
    t = np.linspace(0.0, 25.0, 20001)[:-1]
    sm = sol.sample(t)
    damp = pend.damping_coefficient * float(np.mean(sm["theta_dot"] ** 2))
    print(f"seed {a.seed}, horizon {a.horizon:g} Tp, start {a.start}, "
          + ("model mu frozen, objective "
             + ("F - mu (frozen)" if a.frozen else "F - mu - a (radiation_cost)")
             if a.frozen_model else
             "model radiation (Cummins), objective F - mu_past less the radiated energy"))
    print(f"optimum (winding 10): power {sol.power:7.2f} W, absorbed {sol.power + damp:7.2f} W, "
          f"damping {damp:6.2f} W, rms heave {np.sqrt(np.mean(sm['z'] ** 2)):.3f} m, rms "
          f"heave speed {np.sqrt(np.mean(sm['z_dot'] ** 2)):.3f} m/s, 10 turns")
    probe = Probe(sol, a.start)
    restore = probe.install()
    try:
        r = bc.buoy_mpc(hydro, pend, wave, peak_period=2.5, horizon=a.horizon, controller="plan",
                        iterations=1, radiation_cost=not a.frozen,
                        radiation_model=not a.frozen_model)
    finally:
        restore()
    a0 = int(round(r.average_from_s / r.dt_s))
    s = r.series
    turns = (s["theta"][-1] - s["theta"][a0]) / (2 * math.pi)
    print(f"closed loop: power {r.mean_power_w:7.2f} W ({100 * r.mean_power_w / sol.power:.1f} "
          f"%), absorbed {r.absorbed_w:7.2f} W, damping {r.damping_w:6.2f} W, stored "
          f"{r.stored_w:6.2f} W, rms heave {np.sqrt(np.mean(s['z'][a0:] ** 2)):.3f} m, rms "
          f"heave speed {np.sqrt(np.mean(s['z_dot'][a0:] ** 2)):.3f} m/s, {turns:.2f} turns")
    if a.start != "previous":
        print(f"  solves kept from the optimum's start: {probe.kept_opt} of {probe.updates}")
    print(f"model error at the update's end (median, max over the updates): heave "
          f"{1e3 * np.median(probe.err_z):.3f}, {1e3 * np.max(probe.err_z):.3f} mm; angle "
          f"{np.median(probe.err_th):.4f}, {np.max(probe.err_th):.4f} rad")
    mo = np.array(probe.motion)
    print(f"the plan's motion over the whole horizon, replayed in the plant (median over the "
          f"updates): rms heave error {100 * np.median(mo[:, 0]):.2f} % of the rms heave; "
          f"objective int (F - mu) z' - c theta'^2: the model's {np.median(mo[:, 1]):.1f} J, "
          f"the plant's {np.median(mo[:, 2]):.1f} J (model - plant: median "
          f"{np.median(mo[:, 1] - mo[:, 2]):.1f} J, "
          f"{100 * np.mean(mo[:, 1] > mo[:, 2]):.0f} % of the updates over)")



def replay_motion(mp, plant, fseg):
    """The plant's heave (Cummins, its radiation memory and its RK4 scheme) under the plan's
    MOTION (the angle prescribed over the whole horizon, not the torques), and the horizon
    objective ``int (F - mu) z' - c theta'^2`` of that motion in the plant and in the plan's
    model (both by Simpson's rule on the plant's half steps); returns ``(rms heave error /
    rms heave, J_model, J_plant)``."""
    from parapend.control.plan import HorizonPlan

    hp = HorizonPlan(mp.hh, mp.nodes[0], mp.nodes[1], 0.0)
    h = plant.h
    ns = mp.n * mp.ps
    th, thd, thdd = hp.evaluate(0.5 * h * np.arange(2 * ns + 1))
    cdd = -np.cos(th) * thd ** 2 - np.sin(th) * thdd
    mtot, cst, ml, c = plant.p[0], plant.p[1], plant.p[2], plant.p[4]
    w, nk = plant.w, plant.nk
    vel = np.concatenate((plant.vel[plant.k0:plant.k0 + nk + 1], np.zeros(ns)))
    m0, m1, m2 = plant.mus
    z, zd = plant.y[0], plant.y[1]
    zs, zds, mus = [z], [zd], [m0]
    for i in range(ns):
        d1 = 0.5 * (3.0 * m0 - 4.0 * m1 + m2)
        d2 = 0.5 * (m0 - 2.0 * m1 + m2)
        mh, me = m0 + 0.5 * d1 + 0.25 * d2, m0 + d1 + d2

        def acc(zz, zzd, mu, k):
            return (fseg[k] - mu - cst * zz - ml * cdd[k]) / mtot
        a1 = acc(z, zd, m0, 2 * i)
        a2 = acc(z + 0.5 * h * zd, zd + 0.5 * h * a1, mh, 2 * i + 1)
        a3 = acc(z + 0.5 * h * (zd + 0.5 * h * a1), zd + 0.5 * h * a2, mh, 2 * i + 1)
        a4 = acc(z + h * (zd + 0.5 * h * a2), zd + h * a3, me, 2 * i + 2)
        z = z + h / 6.0 * (zd + (zd + 0.5 * h * a1) * 2 + (zd + 0.5 * h * a2) * 2
                           + (zd + h * a3))
        zd = zd + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
        e = nk + i + 1
        vel[e] = zd
        m2, m1, m0 = m1, m0, float(w @ vel[e - nk:e + 1][::-1])
        zs.append(z)
        zds.append(zd)
        mus.append(m0)
    zs, zds, mus = np.array(zs), np.array(zds), np.array(mus)
    tn = h * np.arange(ns + 1)
    pr = mp.prob
    nodes = np.column_stack((mp.nodes[0][1:], mp.nodes[1][1:])).ravel()
    zm = pr.heave(nodes, tn)
    err = float(np.sqrt(np.mean((zm - zs) ** 2)) / np.sqrt(np.mean(zs ** 2)))
    # the model's z' by differences of its z on the half steps (Simpson on the whole steps)
    zmh = pr.heave(nodes, 0.5 * h * np.arange(2 * ns + 1))
    zdm = np.gradient(zmh, 0.5 * h)[::2]
    fmod = np.interp(tn, mp.tf, pr.fm(mp.tf)) if callable(pr.fm) else None
    om = thd[::2]
    j_plant = _simpson((fseg[::2] - mus) * zds - c * om ** 2, h)
    j_model = _simpson(fmod * zdm - c * om ** 2, h)
    if getattr(pr, "free", None) is not None:
        # the radiation in the model: its own objective, F less the past's memory force
        # against z' and the radiated energy of the plan's own motion (Gauss rules)
        j_model = -pr.objective(nodes)
    return err, j_model, j_plant


def _simpson(v, h):
    n = v.size - 1
    if n % 2:
        return float(h * (np.sum(v[:-1]) + np.sum(v[1:])) / 2)
    return float(h / 3.0 * (v[0] + v[-1] + 4.0 * np.sum(v[1:-1:2]) + 2.0 * np.sum(v[2:-1:2])))


if __name__ == "__main__":
    main()
