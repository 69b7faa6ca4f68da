r"""Time one receding-horizon update: parapend's horizon solve against CasADi + IPOPT.

The problem (:mod:`parapend.control.mpc`): the README's sea state (JONSWAP, Hs 2 m, Tp 8 s,
seed 0, 100-wave record) on a 1 m, 10 kg point-mass pendulum, gamma = 0.01, horizon
``--horizon`` peak periods of ``n`` held torques (``--samples`` per peak period), 4 RK4 steps
per torque sample, the work of the held torque plus the terminal value ``E(x_N)``
(kappa = 1), ``|T| <= --torque-limit``.

1. **parapend**: the numba kernel (objective and exact adjoint gradient,
   :mod:`parapend.control._mpc_kernel`) under SciPy's L-BFGS-B with the bounds.
2. **CasADi + IPOPT**: the same discrete problem written in CasADi (SX): the same RK4 steps
   and held torques (single shooting), the same objective, the bounds on the torques;
   IPOPT with CasADi's exact Hessian (``--hessian exact``) or its L-BFGS approximation.
   IPOPT's solve only is timed (the graph and the solver are built once, outside).

Both start from the same point at every update: the previous parapend solution shifted by
one update interval (the warm start of ``mpc_run``); the state is advanced by parapend's
plan. The first solve (from the swing-up hand-over, cold) is reported separately. "Equal
accuracy": each solve's objective is compared, ``|f_casadi - f_parapend|`` relative to
``|f|`` is printed (the median and the largest), with IPOPT's ``tol`` 1e-8 and L-BFGS-B's
``ftol`` 1e-10. Ratio: CasADi's median time over parapend's.

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_mpc.py``.
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import time

import numpy as np


def casadi_problem(n, steps, dt, gamma, kappa, tmax, hessian):
    import casadi as ca

    u = ca.SX.sym("u", n)
    p = ca.SX.sym("p", 2 + 2 * n * steps + 1)
    th, v = p[0], p[1]
    qn = p[2:]
    h = dt / steps
    f = 0
    for j in range(n):
        for s in range(steps):
            i = j * steps + s
            q0, qm, q1 = qn[2 * i], qn[2 * i + 1], qn[2 * i + 2]

            def rhs(a, b, q, uj=u[j]):
                return b, (1 + q) * ca.sin(a) - gamma * b + uj

            k1 = rhs(th, v, q0)
            k2 = rhs(th + h / 2 * k1[0], v + h / 2 * k1[1], qm)
            k3 = rhs(th + h / 2 * k2[0], v + h / 2 * k2[1], qm)
            k4 = rhs(th + h * k3[0], v + h * k3[1], q1)
            th1 = th + h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
            v1 = v + h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
            f = f + u[j] * (th1 - th)
            th, v = th1, v1
    f = f - kappa * (0.5 * v * v + ca.cos(th))
    opts = {"ipopt.print_level": 0, "print_time": 0, "ipopt.tol": 1e-8,
            "ipopt.max_iter": 500}
    if hessian != "exact":
        opts["ipopt.hessian_approximation"] = "limited-memory"
    solver = ca.nlpsol("s", "ipopt", {"x": u, "p": p, "f": f}, opts)
    return solver, [-tmax] * n, [tmax] * n


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--horizon", type=float, default=2.0, help="peak periods")
    ap.add_argument("--samples", type=int, default=64, help="torque samples per peak period")
    ap.add_argument("--update", type=float, default=0.125, help="update interval, peak periods")
    ap.add_argument("--updates", type=int, default=12)
    ap.add_argument("--torque-limit", type=float, default=1.0)
    ap.add_argument("--hessian", choices=("exact", "lbfgs"), default="exact")
    a = ap.parse_args()

    from parapend.control import _mpc_kernel as k
    from parapend.control.mpc import horizon_problem
    from parapend.control.swingup import pump_torque, ready_to_catch
    from parapend.seas import sea_record
    from parapend.units import Units

    units = Units(1.0, 10.0)
    exc = sea_record(units, hs=2.0, tp=8.0, seed=0)
    tp = 8.0 / units.time
    gamma, steps, kappa = 0.01, 4, 1.0
    dt = tp / a.samples
    n = int(round(a.horizon * a.samples))
    m = int(round(a.update * a.samples))
    lead = 0.5 * dt / steps * np.arange(2 * n * steps + 1)
    prob = horizon_problem(n, dt, gamma=gamma, steps=steps, torque_limit=a.torque_limit,
                           terminal_weight=kappa)
    t_build = time.perf_counter()
    solver, lb, ub = casadi_problem(n, steps, dt, gamma, kappa, a.torque_limit, a.hessian)
    t_build = time.perf_counter() - t_build

    # swing-up by the pump to the hand-over, as mpc_run
    x = np.array([math.pi, 0.0])
    t = 0.0
    braking = False
    st, sv = np.empty(2), np.empty(2)
    while not ready_to_catch(x[0], x[1], 0.05):
        tq, braking = pump_torque(x[0], x[1], min(1.0, a.torque_limit), 0.05, braking)
        qn = exc.q(t + lead[:2 * steps + 1])
        k.simulate(np.array([tq]), x[0], x[1], qn, dt / steps, steps, gamma, st, sv)
        x = np.array([st[1], sv[1]])
        t += dt
    prob.solve(x, exc.q(t + lead), np.zeros(n))    # compile, untimed
    u0 = np.zeros(n)
    rows = []
    for i in range(a.updates):
        qn = exc.q(t + lead)
        t0 = time.perf_counter()
        r = prob.solve(x, qn, u0)
        tp_ = time.perf_counter() - t0
        fp = float(r.fun)
        t0 = time.perf_counter()
        rc = solver(x0=u0, p=np.concatenate((x, qn)), lbx=lb, ubx=ub)
        tc = time.perf_counter() - t0
        fc = float(rc["f"])
        stats = solver.stats()
        rows.append((i, tp_, tc, fp, fc, int(r.nit), int(stats["iter_count"]),
                     stats["return_status"]))
        plan = r.x
        qs = exc.q(t + lead[:2 * m * steps + 1])
        ths, vs = np.empty(m + 1), np.empty(m + 1)
        k.simulate(plan[:m], x[0], x[1], qs, dt / steps, steps, gamma, ths, vs)
        x = np.array([ths[-1], vs[-1]])
        t += m * dt
        u0 = np.concatenate((plan[m:], np.full(m, plan[-1])))

    print(f"bench_mpc: README sea state (Hs 2 m, Tp 8 s, seed 0), 1 m 10 kg pendulum, "
          f"gamma {gamma}, T_max {a.torque_limit:g}; horizon {a.horizon:g} Tp = {n} held "
          f"torques x {steps} RK4 steps; update {a.update:g} Tp = "
          f"{m * dt * units.time:.3g} s; IPOPT Hessian {a.hessian}; CasADi graph built in "
          f"{t_build:.2f} s (not counted)")
    print(f"{'update':>6} {'parapend s':>11} {'IPOPT s':>9} {'f parapend':>14} "
          f"{'f IPOPT':>14} {'rel diff':>9} {'it':>4} {'it IP':>5}  status")
    for i, tp_, tc, fp, fc, itp, itc, stc in rows:
        print(f"{i:>6} {tp_:>11.4f} {tc:>9.4f} {fp:>14.8f} {fc:>14.8f} "
              f"{abs(fc - fp) / max(abs(fp), 1e-12):>9.1e} {itp:>4} {itc:>5}  {stc}")
    warm = rows[1:]
    tpm = float(np.median([r[1] for r in warm]))
    tcm = float(np.median([r[2] for r in warm]))
    rd = [abs(r[4] - r[3]) / max(abs(r[3]), 1e-12) for r in warm]
    better = sum(r[3] <= r[4] + 1e-9 * abs(r[3]) for r in warm)
    print(f"warm-started updates: median parapend {1e3 * tpm:.2f} ms, IPOPT "
          f"{1e3 * tcm:.1f} ms, ratio {tcm / tpm:.1f}; objective relative difference median "
          f"{np.median(rd):.1e}, largest {max(rd):.1e}; parapend's objective as low or "
          f"lower in {better} of {len(warm)}")
    print(f"update interval {m * dt * units.time:.3g} s physical; parapend's median solve "
          f"is {tpm / (m * dt * units.time):.2%} of it, its slowest "
          f"{max(r[1] for r in rows) / (m * dt * units.time):.2%}")
    print("uptime:", subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip(),
          "| cores:", os.cpu_count())


if __name__ == "__main__":
    main()
