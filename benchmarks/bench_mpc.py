r"""Time one receding-horizon update: parapend's horizon solve against CasADi + IPOPT.

The problem (:mod:`parapend.control.plan`): the README's sea state (JONSWAP, Hs 2 m, Tp 8 s,
seed 0, 100-wave record) on a 1 m, 10 kg point-mass pendulum, gamma = 0.01, a horizon of
``--horizon`` peak periods on ``K`` cubic Hermite intervals (``--intervals`` per peak
period), the motion from the measured state, the torque by inverse dynamics, the objective
``int (q sin(theta) theta' - gamma theta'^2) + E(t)`` (kappa = 1, lossless) by the 4-point
Gauss rule, ``|T| <= --torque-limit`` at ``tau = 0, 1/2, 1`` of every interval. With
``--efficiency ETA_G ETA_M`` the objective is the electrical work (kappa = ETA_G) with the
motoring kink smoothed at the last ``eps`` of :data:`parapend.control.plan.KINK_SMOOTHING`,
written out the same way in CasADi (``eps`` a parameter), and both continue ``eps`` through
``KINK_SMOOTHING`` as ``solve_plan`` does, each stage warm-started from the last (IPOPT at
the last ``eps`` directly ran into its iteration limit); the times and iterations are the
sums over the stages, IPOPT's status its last stage's.

1. **parapend**: the banded Newton / primal-dual interior point of
   :mod:`parapend.optimal.hermite` (:func:`parapend.control.plan.solve_plan`).
2. **CasADi + IPOPT**: the same discrete problem written out in CasADi (SX, exact Hessian):
   the same nodes, Gauss rule, torque points and bounds; the state and ``q`` are parameters,
   so the graph and the solver are built once, outside the timing. IPOPT ``tol`` 1e-10.

The updates are those of a closed-loop run (``mpc_run``, perfect forecast, from rest, 6
peak periods) on the record: its horizon problems and the starts it gave the solver (the
previous plan shifted by one update interval, continued by the unforced motion) are
captured, and 40 consecutive ones from one peak period after the hand-over are solved again
by both, from the same start. Where that start leaves the torque limit (its first interval),
parapend's time includes its repair (elastic mode, inside ``solve_plan``); IPOPT accepts it
as it is.
"Equal accuracy": both solve to convergence; the relative difference of the objectives is
printed (median and largest over the updates where both converged). Ratio: IPOPT's median
time over parapend's. The load average is printed (the machine may be shared).

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_mpc.py``.
"""

from __future__ import annotations

import argparse
import math
import os
import time

import numpy as np


def casadi_solver(k, h, gamma, tmax, efficiency=None):
    import casadi as ca

    from parapend.control.plan import _TAU_G
    from parapend.optimal.hermite import TORQUE_TAU, _hermite_rows

    z = ca.SX.sym("z", 2 * k)
    par = ca.SX.sym("p", 2 + 4 * k + 3 * k + 1)
    th = [par[0]] + [z[2 * i] for i in range(k)]
    v = [par[1]] + [z[2 * i + 1] for i in range(k)]
    qg = par[2:2 + 4 * k]
    qc = par[2 + 4 * k:2 + 7 * k]
    eps = par[2 + 7 * k]  # the kink's smoothing
    rg, rc = _hermite_rows(_TAU_G, h), _hermite_rows(TORQUE_TAU, h)
    w = np.polynomial.legendre.leggauss(4)[1] / 2 * h
    eg, em = (1.0, 1.0) if efficiency is None else efficiency
    kink = max(1.0 / em - eg, 0.0)
    obj, cons = 0, []
    for j in range(k):
        y = [th[j], v[j], th[j + 1], v[j + 1]]
        for p in range(4):
            a = sum(rg[0][p, i] * y[i] for i in range(4))
            b = sum(rg[1][p, i] * y[i] for i in range(4))
            obj += eg * w[p] * (qg[4 * j + p] * ca.sin(a) * b - gamma * b * b)
            if kink:
                c = sum(rg[2][p, i] * y[i] for i in range(4))
                pm = (c + gamma * b - (1 + qg[4 * j + p]) * ca.sin(a)) * b  # power motored
                obj -= kink * w[p] * (pm + ca.sqrt(pm * pm + eps * eps)) / 2
        for p in range(3):
            a = sum(rc[0][p, i] * y[i] for i in range(4))
            b = sum(rc[1][p, i] * y[i] for i in range(4))
            c = sum(rc[2][p, i] * y[i] for i in range(4))
            cons.append(c + gamma * b - (1 + qc[3 * j + p]) * ca.sin(a))
    nlp = {"x": z, "p": par, "f": -obj, "g": ca.vertcat(*cons)}
    return ca.nlpsol("s", "ipopt", nlp, {"ipopt.print_level": 0, "print_time": 0,
                                         "ipopt.tol": 1e-10, "ipopt.max_iter": 3000,
                                         "ipopt.sb": "yes"})


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--horizon", type=float, default=2.0, help="peak periods")
    ap.add_argument("--intervals", type=int, default=32, help="Hermite intervals per Tp")
    ap.add_argument("--torque-limit", type=float, default=1.0)
    ap.add_argument("--update", type=float, default=1 / 32, help="peak periods")
    ap.add_argument("--updates", type=int, default=40)
    ap.add_argument("--efficiency", type=float, nargs=2, default=None,
                    metavar=("ETA_G", "ETA_M"), help="generator and motor efficiency")
    ap.add_argument("--out", default=None, help="also write the table here")
    a = ap.parse_args()

    from parapend.control.mpc import mpc_run
    from parapend.control.plan import (
        KINK_SMOOTHING,
        solve_plan,
    )
    from parapend.seas import sea_record
    from parapend.units import Units

    units = Units(1.0, 10.0)
    exc = sea_record(units, hs=2.0, tp=8.0, seed=0)
    tp = 8.0 / units.time
    gamma, tmax = 0.01, a.torque_limit
    eff = None if a.efficiency is None else tuple(a.efficiency)
    eg = 1.0 if eff is None else eff[0]
    k = int(round(a.horizon * a.intervals))
    h = a.horizon * tp / k
    dt = tp / 64
    m = max(1, int(round(a.update * tp / dt)))
    # the closed loop (from rest, 6 peak periods): its horizon problems, with the starts and
    # anchors it gave solve_plan, are captured, and the updates below solve them again
    import parapend.control.plan as plan_module

    captured = []

    def capture(pr, start, **kw):
        captured.append((pr, np.array(start, dtype=float), kw.get("anchor")))
        return solve_plan(pr, start, **kw)

    plan_module.solve_plan = capture
    try:
        mpc_run(exc.q, gamma=gamma, horizon=a.horizon * tp, update_interval=m * dt, dt=dt,
                torque_limit=tmax, efficiency=eff, t_end=6 * tp,
                interval_samples=max(1, 64 // a.intervals))
    finally:
        plan_module.solve_plan = solve_plan
    first = -(-64 // m)  # one peak period after the hand-over
    if len(captured) < first + a.updates:
        raise SystemExit(f"the closed loop made {len(captured)} solves, fewer than "
                         f"{first + a.updates}")
    t0 = time.perf_counter()
    solver = casadi_solver(k, h, gamma, tmax, eff)
    eps_seq = KINK_SMOOTHING if eff is not None else KINK_SMOOTHING[-1:]
    build = time.perf_counter() - t0
    rows = []
    for u, (pr, start, anchor) in enumerate(captured[first:first + a.updates]):
        if pr.k != k:
            raise SystemExit(f"the closed loop's plans have {pr.k} intervals, not {k}")
        x0, qg, qc = pr.x0, pr.q_g, pr.q_c
        # a start outside the limit (its first interval, by the measured state's departure
        # from the plan) is repaired inside solve_plan, in the timing; IPOPT starts from the
        # same point (it accepts an infeasible start)
        t1 = time.perf_counter()
        sol = solve_plan(pr, start, anchor=anchor)
        tp_ = time.perf_counter() - t1
        tc, it_c, xc = 0.0, 0, start
        for eps in eps_seq:
            par = np.concatenate((x0, qg.ravel(), qc.ravel(), [eps]))
            t1 = time.perf_counter()
            r = solver(x0=xc, p=par, lbg=-tmax, ubg=tmax)
            tc += time.perf_counter() - t1
            it_c += solver.stats()["iter_count"]
            xc = np.asarray(r["x"]).ravel()
        e0 = 0.5 * x0[1] ** 2 + math.cos(x0[0])
        jc = -float(r["f"]) + eg * e0
        st = solver.stats()["return_status"]
        rows.append((u, tp_, tc, sol.value, jc, sol.status, st, sol.iterations, it_c))
    both = [r for r in rows if r[5] == "converged" and r[6] in (
        "Solve_Succeeded", "Solved_To_Acceptable_Level")]
    rel = np.array([abs(r[3] - r[4]) / max(1.0, abs(r[4])) for r in both])
    same = rel < 1e-6
    tpar = np.array([r[1] for r in rows])
    tcas = np.array([r[2] for r in rows])
    tps, tcs = tpar[[r[0] for r in both]], tcas[[r[0] for r in both]]
    ts = m * dt * units.time
    load = os.getloadavg()
    lines = [
        f"bench_mpc: README sea state (Hs 2 m, Tp 8 s, seed 0), 1 m 10 kg pendulum, gamma "
        f"{gamma}, horizon {a.horizon:g} Tp = {k} Hermite intervals ({a.intervals}/Tp), "
        f"|T| <= {tmax:g}, update every {a.update:g} Tp = {ts:.3g} s"
        + ("" if eff is None else f", efficiency {eff[0]:g} / {eff[1]:g} (kink smoothed, "
           f"eps {KINK_SMOOTHING[-1]:g})"),
        f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f} (2 cores); CasADi graph "
        f"and IPOPT built in {build:.2f} s (not timed below)",
        "",
        f"{'solver':<22}{'median (ms)':>12}{'max (ms)':>10}{'iterations (median)':>22}",
        f"{'parapend (banded IP)':<22}{1e3 * np.median(tpar):>12.2f}{1e3 * np.max(tpar):>10.2f}"
        f"{np.median([r[7] for r in rows]):>22g}",
        f"{'CasADi + IPOPT':<22}{1e3 * np.median(tcas):>12.2f}{1e3 * np.max(tcas):>10.2f}"
        f"{np.median([r[8] for r in rows]):>22g}",
        "",
        f"{len(rows)} updates; parapend converged on "
        f"{sum(r[5] == 'converged' for r in rows)}, IPOPT on "
        f"{sum(r[6] in ('Solve_Succeeded', 'Solved_To_Acceptable_Level') for r in rows)}, "
        f"both on {len(both)}; of those, the same optimum "
        f"(|J_ipopt - J| / max(1, |J|) < 1e-6) on {int(np.sum(same))}: median difference "
        f"{np.median(rel) if rel.size else math.nan:.2e}, largest "
        f"{np.max(rel) if rel.size else math.nan:.2e}",
        f"ratio of median times, IPOPT / parapend, over the updates at the same optimum: "
        f"{np.median(tcs[same]) / np.median(tps[same]) if np.any(same) else math.nan:.1f}",
        f"update interval {ts:.3g} s physical: parapend's median solve is "
        f"{np.median(tpar) / ts:.2%} of it, its slowest {np.max(tpar) / ts:.2%}",
    ]
    for r in rows:
        if r[5] != "converged":
            lines.append(f"  update {r[0]}: parapend {r[5]} after {r[7]} iterations, J = "
                         f"{r[3]:.8g} (IPOPT {r[6]}, {r[4]:.8g})")
    diff = [r for r in both if abs(r[3] - r[4]) / max(1.0, abs(r[4])) >= 1e-6]
    for r in diff:
        lines.append(f"  update {r[0]}: different local optima, J = {r[3]:.8g} (parapend), "
                     f"{r[4]:.8g} (IPOPT)")
    text = "\n".join(lines)
    print(text)
    if a.out:
        with open(a.out, "w") as f:
            f.write(text + "\n")


if __name__ == "__main__":
    main()
