r"""Time one horizon solve of the hull's receding-horizon planner (``hull_mpc``'s
:class:`parapend.hydro.hull_control.HullHorizon`: L-BFGS-B on the exact adjoint gradient of
the plant's own scheme) against CasADi + IPOPT on the same discrete problem.

Problem: the embedded barge (10 x 4 x 1 m, its 2000 kg, 1 m pendulum on the pivot 0.5 m
above O), its default sea state (Hs 1 m, Tp 6 s, seed 0), the horizon of 2 peak periods in
48 held torques of 6 RK4 steps each with the 3 x 3 radiation memory of 2 peak periods, the
torque bound ``4 m g l``: the problem of one update of ``hull_mpc``, posed at several
instants of a run (the plant advanced there under a swinging torque).

The same discrete problem (the same RK4 steps, the memory's quadratic extrapolation inside a
step and its trapezoidal sum over the velocities of the past and of the horizon, the
objective's work, terminal energy and speed penalty) is written once more in CasADi
symbolics (MX, one step function) and solved by IPOPT with its limited-memory Hessian and
the torque bounds, from the same start (zero torque) and to a comparable tolerance; the
objectives at the two answers are printed side by side, then the median over the cases of
each tool's time per solve (the best of ``--repeat`` after one untimed warm-up) and the
ratio.

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_hull_mpc.py``.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

from parapend.hydro import control as bc  # noqa: E402
from parapend.hydro import hull_control as hc  # noqa: E402

TP = 6.0


def setup():
    """The default barge's plant, its record's force nodes and the horizon's sizes."""
    from parapend.hydro.api import hull_problem
    from parapend.hydro.declared import default_of
    from parapend.hydro.hull import make_case
    from parapend.hydro.inputs import _irregular_wave
    from parapend.units import Units

    p = hull_problem()
    pend = p["pendulum"]
    wave, _ = _irregular_wave(1.0, TP, "jonswap", 3.3, 4 * TP, 0, default_of("cutoff", None),
                              None, default_of("taper", None),
                              Units(pend.length, pend.mass, 9.81, pend.inertia))
    kw = wave.amplitudes.size
    case = make_case(p["hull"], pend, wave, winding=0, harmonics=kw, hull_harmonics=kw,
                     pivot=p["pivot"])
    per, ps = 4 * hc.SAMPLES, hc.PLANT_STEPS
    n = 2 * hc.SAMPLES
    h = 4 * TP / per / ps
    total = 3 * per
    fn = bc.force_nodes(p["hull"], wave, per, ps, 2 * (total + n) * ps + 1)
    xi0, xid0, history = hc._free_start(case)
    plant = hc.HullPlant(p["hull"], pend, case, h, total * ps, hc.MEMORY_PERIODS * TP, xi0,
                         xid0, history)
    return plant, fn, n, ps, pend.mass * 9.81 * pend.length


def casadi_solver(plant, n, ps, tu, fseg, prob):
    """IPOPT on the same discrete problem as ``prob.fun`` from the plant's current state."""
    import casadi as ca

    h, w, nk = plant.h, plant.w, plant.nk
    m, ell, inertia, c, g = plant.par
    ml = m * ell
    gm, mt, cp = plant.gm, plant.mt, plant.cp
    ns = n * ps
    y = ca.MX.sym("y", 8)
    mu = ca.MX.sym("mu", 3)
    f = ca.MX.sym("f", 3)
    tq = ca.MX.sym("tau")
    s, co = ca.sin(y[3]), ca.cos(y[3])
    cvec = ml * (ca.DM(gm[0]) * co - ca.DM(gm[1]) * s)
    bvec = ca.DM(gm[0]) * s + ca.DM(gm[1]) * co
    mm = ca.vertcat(ca.horzcat(ca.DM(mt), cvec), ca.horzcat(cvec.T, inertia))
    vr = y[7] - y[6]
    rh = f - mu - ca.mtimes(ca.DM(cp), y[:3]) + ml * bvec * y[7] ** 2
    rh = rh + ca.vertcat(0, 0, c * vr - tq)
    rp = tq - c * vr + ml * g * s
    acc = ca.solve(mm, ca.vertcat(rh, rp))
    accel = ca.Function("acc", [y, mu, f, tq], [acc])
    # the start: the plant's state, its memory's three values and its past velocities
    u = ca.MX.sym("u", n)
    yy = ca.DM(plant.y)
    m0, m1, m2 = (ca.DM(plant.mus[k]) for k in range(3))
    past = plant.vel[plant.k0:plant.k0 + nk + 1]  # oldest first; the last is now
    vels = []  # the horizon's velocities after each step (MX)
    ys = [yy]
    from parapend.hydro._hull_plant import _END as end
    from parapend.hydro._hull_plant import _MID as mid
    for i in range(ns):
        tau = u[i // ps] * tu
        mh = mid[0] * m0 + mid[1] * m1 + mid[2] * m2
        me = end[0] * m0 + end[1] * m1 + end[2] * m2
        ks = []
        st = yy
        for q, (mu_q, node, frac) in enumerate(((m0, 2 * i, 0.0), (mh, 2 * i + 1, 0.5 * h),
                                                (mh, 2 * i + 1, 0.5 * h),
                                                (me, 2 * i + 2, h))):
            if q:
                st = yy + frac * ks[-1]
            a = accel(st, mu_q, ca.DM(fseg[node]), tau)
            ks.append(ca.vertcat(st[4:8], a))
        yy = yy + h / 6.0 * (ks[0] + 2 * ks[1] + 2 * ks[2] + ks[3])
        vels.append(yy[4:7])
        # m0 at the new step: the horizon's velocities and the past's
        e = i + 1
        tot = ca.DM.zeros(3)
        for q in range(nk + 1):
            j = e - q
            v = vels[j - 1] if j >= 1 else ca.DM(past[nk + j])
            tot = tot + ca.mtimes(ca.DM(w[q]), v)
        m2, m1, m0 = m1, m0, tot
        if (i + 1) % ps == 0:
            ys.append(yy)

    def energy(yv):
        v = yv[4:8]
        s, co = ca.sin(yv[3]), ca.cos(yv[3])
        cv = ml * (ca.DM(gm[0]) * co - ca.DM(gm[1]) * s)
        mmv = ca.vertcat(ca.horzcat(ca.DM(mt), cv), ca.horzcat(cv.T, inertia))
        return (0.5 * ca.dot(v, ca.mtimes(mmv, v)) + 0.5 * ca.dot(yv[:3], ca.mtimes(
            ca.DM(cp), yv[:3])) + ml * g * co)
    th = [yv[3] - yv[2] for yv in ys]
    eg, em = prob.eta
    a_, b_ = 0.5 * (eg + 1.0 / em), 0.5 * (eg - 1.0 / em)
    obj = 0
    for j in range(n):
        wk = -u[j] * (th[j + 1] - th[j])
        obj -= a_ * wk + b_ * (ca.sqrt(wk * wk + prob.width ** 2) - prob.width)
        over = ca.fmax(ca.fabs(ys[j + 1][7] - ys[j + 1][6]) - prob.speed, 0)
        obj += hc.SPEED_WEIGHT * over ** 2
    obj -= prob.kappa * (energy(ys[-1]) - energy(ys[0])) / tu
    solver = ca.nlpsol("s", "ipopt", {"x": u, "f": obj},
                       {"ipopt.print_level": 0, "print_time": 0, "ipopt.tol": 1e-8,
                        "ipopt.sb": "yes", "ipopt.max_iter": 500,
                        "ipopt.hessian_approximation": "limited-memory"})
    return solver, ca.Function("obj", [u], [obj])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", type=int, default=3)
    ap.add_argument("--repeat", type=int, default=2)
    a = ap.parse_args()
    load0 = os.getloadavg()[0]
    plant, fn, n, ps, tu = setup()
    prob = hc.HullHorizon(plant, n, ps, tu, hc.DEFAULT_LIMIT, None)
    lim = hc.DEFAULT_LIMIT
    rows = []
    for case in range(a.cases):
        # advance the plant a peak period under a swinging torque: another start
        per = hc.SAMPLES
        k0 = plant.k0 // ps
        u_run = 0.5 * tu * np.sign(np.sin(2 * math.pi * (k0 + np.arange(per)) / per))
        plant.step(u_run, ps, fn[2 * k0 * ps:2 * (k0 + per) * ps + 1])
        k0 = plant.k0 // ps
        fseg = fn[2 * k0 * ps:2 * (k0 + n) * ps + 1]
        u0 = np.zeros(n)
        times = []
        for _ in range(a.repeat + 1):
            t = time.perf_counter()
            res = prob.solve(plant, fseg, u0, max_iter=hc.MAX_ITER * 10, tol=1e-10)
            times.append(time.perf_counter() - t)
        ours = min(times[1:])
        f_ours = prob.fun(res.x, None, fseg)[0] + prob.offset
        solver, objf = casadi_solver(plant, n, ps, tu, fseg, prob)
        check = float(objf(np.full(n, 0.3))) - (prob.fun(np.full(n, 0.3), None, fseg)[0]
                                                + prob.offset)
        times = []
        for _ in range(a.repeat + 1):
            t = time.perf_counter()
            sol = solver(x0=u0, lbx=-lim, ubx=lim)
            times.append(time.perf_counter() - t)
        theirs = min(times[1:])
        f_ip = float(sol["f"])
        rows.append((ours, theirs))
        print(f"case {case}: objective (units m g l rad) L-BFGS-B {f_ours:.8f} "
              f"({res.nit} iterations), IPOPT {f_ip:.8f} "
              f"({solver.stats()['iter_count']} iterations); the two models differ by "
              f"{abs(check):.2e} at u = 0.3; time {ours * 1e3:.1f} ms against "
              f"{theirs * 1e3:.1f} ms", flush=True)
    ours = float(np.median([r[0] for r in rows]))
    theirs = float(np.median([r[1] for r in rows]))
    print(f"median per solve: parapend {ours * 1e3:.1f} ms, CasADi/IPOPT {theirs * 1e3:.1f} "
          f"ms: ratio {theirs / ours:.1f}x (load {load0:.1f} -> {os.getloadavg()[0]:.1f})")


if __name__ == "__main__":
    main()
