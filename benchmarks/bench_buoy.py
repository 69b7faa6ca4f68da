r"""Time the coupled buoy-pendulum optimum against CasADi + IPOPT on the same discretization.

Problem: a heavy pendulum inside a heaving buoy in a regular wave (an analytic, passive set
of heave coefficients: constant added mass, ``B(w) >= 0``, an excitation force with a phase;
the same arrays for both tools). The coupled objective in ``theta`` alone
(:mod:`parapend.hydro.coupled`) with N harmonics on the same M-point grid, the same coupling
harmonics ``Kc`` and the same coefficients, is written once more in CasADi symbolics
(``theta = K s + Phi x``, ``u = cos(theta)``, ``P = <q_w' u> - 2 sum beta_k |<u e^{-iks}>|^2
- gamma <theta'^2>``) and maximized by IPOPT with its exact (AD) Hessian.

1. **local**: one local solve from the same start (the one-way optimum): parapend's
   safeguarded Newton (:func:`parapend.optimal.fourier.newton_maximize` on
   :class:`~parapend.hydro.coupled.CoupledProblem`) against IPOPT.
2. **search**: every seed of parapend's global search polished by each tool (IPOPT from
   the same seeds), best power; and parapend's whole :func:`coupled_optimum` (one-way search,
   coupled search, refinement, fine-grid check, energy balance, c = 0 limit) for reference.

Both tools run in this one process, alternately; the best of ``--repeat`` runs after one
warm-up. Powers are compared at equal accuracy (the difference is printed). Then the
irregular record of 100 waves (JONSWAP hs 2 m, tp 8 s, repeat period 800 s): the whole
:func:`coupled_optimum`, timed once.

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_buoy.py``.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import numpy as np  # noqa: E402
from _timing import best_of  # noqa: E402  (benchmarks/_timing.py)
from buoy_synthetic import toy_hydro  # noqa: E402  (the tests' toy heave coefficients)

from parapend.hydro.coupled import (  # noqa: E402
    CoupledProblem,
    Pendulum,
    Wave,
    free_excitation,
    scales,
)
from parapend.hydro.optimum import _seeds, coupled_optimum  # noqa: E402
from parapend.optimal.fourier import newton_maximize, search_fourier  # noqa: E402


def casadi_problem(pr: CoupledProblem):
    """IPOPT solver for the same discrete objective as ``pr`` (minimize -P)."""
    import casadi as ca

    n, m, kc = pr.harmonics, pr.points, pr.coupling_harmonics
    s = pr.s
    k = np.arange(1, n + 1)
    phi = np.hstack((np.ones((m, 1)), np.sin(np.outer(s, k)), np.cos(np.outer(s, k))))
    x = ca.SX.sym("x", 2 * n + 1)
    th = pr.winding * s + ca.mtimes(ca.DM(phi), x)
    u = ca.cos(th)
    kk = np.arange(1, kc + 1)
    cr = ca.DM(np.cos(np.outer(kk, s)) / m)
    ci = ca.DM(np.sin(np.outer(kk, s)) / m)
    ur, ui = ca.mtimes(cr, u), ca.mtimes(ci, u)
    beta = ca.DM(pr.beta)
    pc = -2 * ca.dot(beta, ur * ur + ui * ui)
    k2 = ca.DM(pr._k2)
    kin = pr.omega**2 * (pr._k0 + 0.5 * ca.dot(k2, x * x))
    p = ca.dot(ca.DM(pr.w), u) / m + pc - pr.gamma * kin
    solver = ca.nlpsol("s", "ipopt", {"x": x, "f": -p},
                       {"ipopt.print_level": 0, "print_time": 0, "ipopt.tol": 1e-12,
                        "ipopt.sb": "yes", "ipopt.max_iter": 500})
    return solver


def ipopt_run(solver, x0):
    r = solver(x0=x0)
    st = solver.stats()
    return -float(r["f"]), np.asarray(r["x"]).ravel(), st["return_status"], st["iter_count"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--harmonics", type=int, default=24)
    ap.add_argument("--skip-irregular", action="store_true")
    a = ap.parse_args()
    load0 = os.getloadavg()[0]
    hydro = toy_hydro(radius=1.5)
    pend = Pendulum(4000.0, 1.0, 4500.0, 40.0)
    wave = Wave.regular(1.5, 6.0)
    sc = scales(hydro, pend, wave)
    exc = free_excitation(sc)
    n = a.harmonics
    pr = CoupledProblem(exc, sc.beta_nd, n, sc.gamma)
    pu = sc.power_unit
    ow = search_fourier(exc, n, sc.gamma)
    seeds = _seeds(ow.runs, n, 1, ow.best.x, None)
    t_build = time.perf_counter()
    solver = casadi_problem(pr)
    t_build = time.perf_counter() - t_build
    print(f"# python benchmarks/bench_buoy.py --repeat {a.repeat} --harmonics {n}  "
          f"(machine: {os.cpu_count()} cores; load before/after in the last line)")
    print(f"# regular wave H 1.5 m T 6 s, pendulum m 4000 kg l 1 m I 4500 kg m^2 c 40 N m s/rad;"
          f" N = {n}, M = {pr.points}, Kc = {pr.coupling_harmonics}; CasADi graph built in "
          f"{t_build:.3f} s (not counted)")
    print(f"{'case':<10} {'tool':<22} {'time s':>9} {'power W':>16} {'|dP| W':>9} "
          f"{'ratio':>7}")
    # 1. local from the one-way optimum
    x0 = seeds[0][1]
    t_ours, r = best_of(lambda: newton_maximize(pr, x0, "one-way"), a.repeat)
    t_ip, (p_ip, _, st, it) = best_of(lambda: ipopt_run(solver, x0), a.repeat)
    p_ours = r.power * pu
    print(f"{'local':<10} {'parapend Newton':<22} {t_ours:9.4f} {p_ours:16.9f} {'':>9} ")
    print(f"{'local':<10} {'casadi+ipopt ' + str(it) + ' it':<22} {t_ip:9.4f} "
          f"{p_ip * pu:16.9f} {abs(p_ip * pu - p_ours):9.2e} {t_ip / t_ours:7.1f}")

    # 2. the same seeds polished by each tool
    def ours_all():
        return max(newton_maximize(pr, x, name).power for name, x in seeds)

    def ipopt_all():
        return max(ipopt_run(solver, x)[0] for _, x in seeds)

    t_ours, p1 = best_of(ours_all, max(1, a.repeat // 2))
    t_ip, p2 = best_of(ipopt_all, max(1, a.repeat // 2))
    print(f"{'search':<10} {'parapend ' + str(len(seeds)) + ' seeds':<22} {t_ours:9.4f} "
          f"{p1 * pu:16.9f}")
    print(f"{'search':<10} {'casadi+ipopt ' + str(len(seeds)) + ' seeds':<22} {t_ip:9.4f} "
          f"{p2 * pu:16.9f} {abs(p2 - p1) * pu:9.2e} {t_ip / t_ours:7.1f}")
    t_full, full = best_of(lambda: coupled_optimum(hydro, pend, wave, harmonics=n), 1)
    print(f"{'full':<10} {'coupled_optimum':<22} {t_full:9.4f} {full.power:16.9f}   "
          f"(N -> {full.harmonics} refined, balance {full.energy_balance_residual:.1e}, "
          f"limit {full.limit:.6g} W, bound {full.radiation_bound:.6g} W)")
    print(f"{'full':<10} {'vs ipopt ' + str(len(seeds)) + ' seeds':<22} {'':>9} {'':>16} "
          f"{abs(full.power - p2 * pu):9.2e} {t_ip / t_full:7.1f}   (the whole search and "
          "its checks against IPOPT's multi-start alone)")
    if not a.skip_irregular:
        hyd2 = toy_hydro(radius=2.0, top=6.0)
        p2_ = Pendulum(2000.0, 1.0, 2500.0, 50.0)
        rec = Wave.from_spectrum(hs=2.0, tp=8.0, repeat_period=800.0, seed=0)
        t = time.perf_counter()
        r = coupled_optimum(hyd2, p2_, rec)
        t = time.perf_counter() - t
        print(f"{'record':<10} {'coupled_optimum':<22} {t:9.2f} {r.power:16.9f}   "
              f"(100 waves, N = {r.harmonics}, {r.evidence['starts']} starts, success "
              f"{r.success}, balance {r.energy_balance_residual:.1e}, one-way "
              f"{r.evidence['one_way_power']:.6g} W, limit {r.limit:.6g} W)")
    print(f"# load before: {load0:.2f}  after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
