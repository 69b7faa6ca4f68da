r"""Time one horizon solve of the buoy's motion planner (``buoy_mpc(controller="plan")``)
against CasADi + IPOPT on the same discretization.

Problem: the horizon problem of :class:`parapend.hydro._buoy_plan.CoupledPlan` with the
default design's coefficients (``(M + A_inf, C, m l, I, c, g)`` of the default cylinder and
its 80 kg, 0.3 m pendulum, as ``buoy_mpc`` builds them), a horizon of 2 peak periods of
2.5 s in 32 Hermite intervals (4 torque samples each, as ``buoy_mpc``), the torque bound
``2 m g l``, and an excitation less memory force ``f(t)`` of a few wave components of the
size the closed loop sees (std about 400 N). Several starts: the measured state drawn at
random (swinging and rotating), the start of the solve a rotation at the measured speed.

The same discrete problem (the same points, convolution weights and Hermite rows, taken
from the planner's own arrays) is written once more in CasADi symbolics (the angle at the
points by the Hermite rows, ``y`` by the same convolution weights, the torque by inverse
dynamics) and solved by IPOPT with its exact (AD) Hessian, from the same start and to the
same tolerance; the objectives at the two optima are printed side by side (equal accuracy:
their difference), then the median over the cases of each tool's time per solve (the best
of ``--repeat`` after one untimed warm-up, which compiles or loads the kernels) and the
ratio. The old ``coupled`` controller's L-BFGS-B problem is not on this discretization
(held torques, RK4) and is not timed here.

With ``--radiation`` the model of ``buoy_mpc``'s default (the radiation inside it: the
default buoy's impulse response from its plant's memory, the radiated energy in the
objective; a free heave of the closed loop's size).

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_buoy_mpc.py [--radiation]``.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402
from _timing import best_of  # noqa: E402  (benchmarks/_timing.py)

from parapend.hydro._buoy_plan import CoupledPlan  # noqa: E402

# the default design as buoy_mpc's _Plant has it (M + A_inf, C, m l, I, c, g)
P = np.array([638.283099, 7879.56710, 24.0, 7.2, 1.0, 9.81])
TP = 2.5
K = 32
H = 2 * TP / K
TMAX = 2.0 * 80 * 9.81 * 0.3


def forcing(rng):
    w = 2 * math.pi / TP * rng.uniform(0.7, 1.5, 6)
    a = rng.normal(size=6) * 160.0
    ph = rng.uniform(0, 2 * math.pi, 6)

    def f(t):
        t = np.asarray(t, dtype=float)
        return np.sum(a * np.sin(np.multiply.outer(t, w) + ph), axis=-1)
    return f


def default_response():
    """The impulse response of the default buoy's plant (its memory weights on the plant's
    step of ``Tp / 512``, as ``buoy_mpc`` builds them)."""
    import parapend
    from parapend.hydro import control as bc
    from parapend.hydro._buoy_plan import Response
    from parapend.hydro.coupled import Pendulum

    opt = parapend.buoy(hs=0.5, tp=2.5, repeat_period=25, seed=0)
    h = TP / 64 / 8
    plant = bc._Plant(opt._hydro, Pendulum(80.0, 0.3, 7.2, 1.0), h, 1, None, None, 0.0, 0.0,
                      None)
    P[:] = plant.p
    return Response(plant.p[0], plant.p[1], plant.w, h, K * H + h)


def free_heave(rng):
    """A free heave ``(z, z', z'')`` of the size the closed loop sees (rms about 0.2 m)."""
    w = 2 * math.pi / TP * rng.uniform(0.7, 1.5, 4)
    a = rng.normal(size=4) * 0.1
    ph = rng.uniform(0, 2 * math.pi, 4)

    def free(t):
        arg = np.multiply.outer(np.asarray(t, dtype=float), w) + ph
        return (np.sum(a * np.sin(arg), -1), np.sum(a * w * np.cos(arg), -1),
                np.sum(-a * w * w * np.sin(arg), -1))
    return free


def scatter(rows, j, nfull):
    out = np.zeros((rows.shape[0], nfull))
    for a in range(4):
        out[np.arange(rows.shape[0]), 2 * j + a] += rows[:, a]
    return out


def casadi_solver(pr: CoupledPlan):
    """IPOPT on the same discrete problem as ``pr`` (after ``set_start``): minimize ``-J``
    subject to ``|tau| <= T_max`` at the torque points."""
    import casadi as ca

    k, tg = pr.k, pr.tg
    nfull = 2 * k + 2
    nt = tg.t.size
    ml, inertia, c, g = pr.p[2], pr.p[3], pr.p[4], pr.p[5]
    r, kap = pr.r, pr.kap
    f_t, yc, ydc = pr._fixed[0]
    e0, e1, e2 = (ca.DM(scatter(b, tg.j, nfull)) for b in (tg.b0, tg.b1, tg.b2))
    ef = ca.DM(scatter(np.tile(pr.b0g, (k, 1)), np.repeat(np.arange(k), 4), nfull))
    ep = ca.DM(scatter(tg.bp0.reshape(-1, 4), np.repeat(tg.j, 4), nfull))
    # the partial rules as one sparse block row per point
    sel = np.zeros((nt, 4 * nt))
    sel_b = np.zeros((nt, 4 * nt))
    for t in range(nt):
        sel[t, 4 * t:4 * t + 4] = tg.a_part[t]
        sel_b[t, 4 * t:4 * t + 4] = tg.b_part[t]
    x = ca.SX.sym("x", 2 * k)
    full = ca.vertcat(pr.x0[2], pr.x0[3], x)
    th, thd, thdd = ca.mtimes(e0, full), ca.mtimes(e1, full), ca.mtimes(e2, full)
    cf, cp = ca.cos(ca.mtimes(ef, full)), ca.cos(ca.mtimes(ep, full))
    # y'' less its point's own term (the a_* weights) and y' (the b_* weights)
    ydd = ca.DM(yc) + ca.mtimes(ca.DM(tg.af2), cf) + ca.mtimes(ca.DM(sel), cp)
    yd = ca.DM(ydc) + ca.mtimes(ca.DM(tg.bf2), cf) + ca.mtimes(ca.DM(sel_b), cp)
    s, co = ca.sin(th), ca.cos(th)
    zd = yd + r * s * thd
    ft = ca.DM(f_t)
    phi = ca.dot(ca.DM(pr.wgt), -ft * zd + c * thd * thd)
    if pr.wrad.shape[0]:
        zg = zd[:pr.ng]
        phi += 0.5 * ca.dot(zg, ca.mtimes(ca.DM(pr.wrad), zg))
    tau = ((inertia - ml * r * s * s) * thdd + c * thd
           - ml * s * (g + r * co * thd * thd) - ml * s * (ydd + kap * co))
    tau_c = tau[pr.ng:]
    return ca.nlpsol("s", "ipopt", {"x": x, "f": phi, "g": tau_c},
                     {"ipopt.print_level": 0, "print_time": 0, "ipopt.tol": 1e-8,
                      "ipopt.sb": "yes", "ipopt.max_iter": 500})


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", type=int, default=8)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--radiation", action="store_true",
                    help="the radiation inside the model (buoy_mpc's default): the default "
                         "buoy's plant kernel, its radiated energy in the objective")
    a = ap.parse_args()
    load0 = os.getloadavg()[0]
    rng = np.random.default_rng(0)
    rows = []
    resp = default_response() if a.radiation else None
    for case in range(a.cases):
        pr = CoupledPlan(K, H, P, TMAX, response=resp)
        om0 = rng.choice([rng.uniform(-3, 3), rng.uniform(4, 8)])
        y0 = np.array([rng.normal() * 0.2, rng.normal() * 0.3, rng.uniform(0, 2 * math.pi),
                       om0])
        f = forcing(rng)
        pr.set_start(y0, f, free=free_heave(rng) if a.radiation else None)
        tn = H * np.arange(1, K + 1)
        x0 = np.empty(2 * K)
        x0[0::2], x0[1::2] = y0[2] + om0 * tn, om0
        t_new, (xs, st, it) = best_of(lambda pr=pr, x0=x0: pr.solve(x0), a.repeat)
        solver = casadi_solver(pr)
        t_ip, res = best_of(lambda s=solver, x0=x0: s(x0=x0, lbg=-TMAX, ubg=TMAX), a.repeat)
        sti = solver.stats()
        f_new, f_ip = pr.objective(xs), float(res["f"])
        rows.append((t_new, t_ip, f_new, f_ip))
        print(f"case {case}: plan {st} {it} it {1e3 * t_new:8.1f} ms  J = {-f_new:10.3f} J | "
              f"ipopt {sti['return_status']} {sti['iter_count']} it {1e3 * t_ip:8.1f} ms  "
              f"J = {-f_ip:10.3f} J")
    tn_, ti_ = np.median([r[0] for r in rows]), np.median([r[1] for r in rows])
    print(f"median time per horizon solve: plan {1e3 * tn_:.1f} ms, casadi+ipopt "
          f"{1e3 * ti_:.1f} ms (solve only; building the CasADi problem not counted): "
          f"ratio {ti_ / tn_:.2f}")
    print(f"load average at start {load0:.2f}, at end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
