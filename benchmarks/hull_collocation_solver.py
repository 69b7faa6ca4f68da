"""The hull's collocation planner (``hull_mpc(planner="collocation")``): its compiled solver
(:mod:`parapend.hydro._hull_collocation_ipm`) against CasADi/IPOPT on the same horizon NLP.

1. Per horizon: the embedded barge, its default sea, perfect forecast, the pump's start,
   terminal weight 0.5, the first ``--updates`` updates of a run planned by IPOPT; at every
   update both solvers start from the same point (IPOPT's previous solution shifted) on the
   same parameters, in this process: the time of each, the ratio, the iterations, the
   statuses, the objective's relative difference and the largest torque difference
   (m g l).
2. ``--kkt``: the linear algebra of one iteration on the sixth horizon: SciPy's SuperLU
   and qdldl on the whole quasi-definite KKT matrix, the compiled solver's own ``L D L^T``
   of it (its default step), and its structured factors of ``J_d`` with the 48 torque
   sensitivities (its null-space step).
3. The whole default run (``hull_mpc(..., planner="collocation", terminal_weight=0.5)``,
   seed ``--seed``) with each solver: the update time's median and p99 against the 0.75 s
   interval, the failed and the capped solves, and the electrical power (``--forecast``;
   ``--no-ipopt-run`` skips IPOPT's).

``--te8``: items 1 and 3 on the power matrix's Hs 1 m, Te 8 s bin of the default barge
(Tp 8.9 s, a 17.8 s horizon; seed 0, 4 waves, started rotating as its optimum: the
matrix's causal run, :func:`parapend.performance.causal.run_hull_record`) in place of the
default sea.

    nice python benchmarks/hull_collocation_solver.py --updates 20 --seed 0
    nice python benchmarks/hull_collocation_solver.py --seed 1 --step auto kkt nullspace \\
        --no-ipopt-run
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from parapend.hydro import _hull_collocation as hcol
from parapend.hydro import hull_control as hc
from parapend.hydro.api import hull_problem
from parapend.hydro.declared import default_of
from parapend.hydro.inputs import _irregular_wave
from parapend.units import Units


def case(seed):
    """The embedded barge and its default sea (``seed``): ``(problem, wave)``."""
    p = hull_problem()
    pend = p["pendulum"]
    wave, _ = _irregular_wave(1.0, 6.0, "jonswap", 3.3, 24.0, seed,
                              default_of("cutoff", None), None, default_of("taper", None),
                              Units(pend.length, pend.mass, 9.81, pend.inertia))
    return p, wave


def run(p, wave, forecast="perfect"):
    return hc.hull_mpc(p["hull"], p["pendulum"], wave, peak_period=6.0, pivot=p["pivot"],
                       mode="rotate", planner="collocation", terminal_weight=0.5,
                       forecast=forecast)


def run_bin(forecast="perfect"):
    """The power matrix's causal run of its Hs 1 m, Te 8 s bin (Tp 8.9 s: a 17.8 s horizon)
    on the default barge, seed 0, 4 waves, started rotating (as its optimum)."""
    from parapend.performance import matrix_spec
    from parapend.performance.causal import run_hull_record

    spec = matrix_spec(hs="1,2", te="6,8", realizations=1, waves=4, device="buoy",
                       dofs="surge,heave,pitch", controller="mpc", forecast="perfect,ar",
                       planner="collocation")
    return run_hull_record(spec, 0, 1, 0, forecast, "rotate")


def beside(prob, max_iter, solver):
    """The problem ``prob`` (same plant and options) with the solver ``solver``."""
    return hcol.HullCollocation(prob.plant, prob.n, prob.steps, prob.tu, prob.torque_limit,
                                prob.eta, prob.kappa,
                                "pendulum" if prob.pendulum_only else "total",
                                max_iter=max_iter, solver=solver)


def per_horizon(seed, updates, te8=False, steps=None):
    """Both solvers on the first ``updates`` horizons of an IPOPT run (module docstring;
    ``te8``: of :func:`run_bin`); with ``steps`` the compiled solver once with each of
    these Newton steps (:data:`parapend.hydro._hull_collocation_ipm.STEP`) from the same
    start: ``{step: rows}``."""
    from parapend.hydro import _hull_collocation_ipm as ipm

    steps = [ipm.STEP] if not steps else list(steps)
    rows, comp = {st: [] for st in steps}, {}
    plan0, step0 = hc._plan, ipm.STEP
    hcol.SOLVER = "ipopt"

    def plan(prob, plant, fseg, u0, max_iter):
        if not comp:
            comp["q"] = beside(prob, max_iter, "compiled")
        q = comp["q"]
        x0, par = prob.start(fseg, u0)
        warm = prob.prev is not None
        out = []
        for st in steps:
            ipm.STEP = st
            if not rows[st]:  # the kernels' first call (numba's cache) out of the timing
                q.compiled.solve(x0, par, 2, prob.tol, warm)
            t = time.perf_counter()
            rc = q.solve_from(x0, par, max_iter, prob.tol, warm=warm)
            out.append((st, rc, time.perf_counter() - t))
        t = time.perf_counter()
        ri = prob.solve_from(x0, par)
        ti = time.perf_counter() - t
        for st, rc, tc in out:
            rows[st].append((tc, ti, rc.nit, ri.nit, rc.status, ri.status,
                             abs(rc.fun - ri.fun) / max(abs(ri.fun), 1e-12),
                             float(np.max(np.abs(rc.x - ri.x)))))
        if len(rows[steps[0]]) >= updates:
            raise StopIteration
        return ri

    hc._plan = plan
    try:
        if te8:
            run_bin()
        else:
            run(*case(seed))
    except StopIteration:
        pass
    finally:
        hc._plan, ipm.STEP = plan0, step0
    return {st: np.array(r) for st, r in rows.items()}


def kkt_baseline(seed, k=5):
    """The linear algebra of one iteration at the start of the horizon ``k`` (item 2)."""
    import scipy.sparse as sp
    from scipy.sparse.linalg import splu

    p, wave = case(seed)
    got = {}

    def plan(prob, plant, fseg, u0, max_iter):
        if len(got) == k:
            got["q"] = beside(prob, max_iter, "compiled")
            got["start"] = prob.start(fseg, u0)
            raise StopIteration
        got[len(got)] = prob.solve(plant, fseg, u0)
        return got[len(got) - 1]

    plan0, hc._plan, hcol.SOLVER = hc._plan, plan, "ipopt"
    try:
        run(p, wave)
    except StopIteration:
        pass
    finally:
        hc._plan = plan0
    cs = got["q"].compiled
    x0, par = got["start"]
    cs._setup(par)
    _, _, _, jv, _, hv = cs._eval(x0, np.ones(cs.nloc), 2, cs.fk, cs.e0)
    jac = cs.jacobian(jv)
    cs.sig_s = np.ones(cs.npt - 1)
    kr = cs.krows
    kc = cs.hessian(hv, np.ones(cs.nf)).tocoo()
    kmat = sp.coo_matrix((kc.data, (kr[kc.row], kr[kc.col])), shape=(cs.nf, cs.nf))
    kkt = sp.bmat([[kmat + 1e-8 * sp.identity(cs.nf), jac.T],
                   [jac, -1e-8 * sp.identity(cs.neq)]], format="csc")
    print(f"KKT matrix {kkt.shape[0]} rows, {kkt.nnz} nonzeros (horizon {k}, seed {seed}):")
    for spec in ("COLAMD", "MMD_AT_PLUS_A"):
        t = time.perf_counter()
        lu = splu(kkt, permc_spec=spec, diag_pivot_thresh=0.0,
                  options={"SymmetricMode": spec != "COLAMD"})
        print(f"  SuperLU {spec:14s} factor {1000 * (time.perf_counter() - t):7.1f} ms, "
              f"nnz(L + U) {lu.L.nnz + lu.U.nnz}")
    try:
        import qdldl
    except ImportError:
        print("  qdldl not installed")
    else:
        solver = qdldl.Solver(kkt)
        t = time.perf_counter()
        solver.update(kkt)
        print(f"  qdldl (AMD) numeric refactor {1000 * (time.perf_counter() - t):7.1f} ms")
    kh = cs.hessian(hv, np.ones(cs.nf))
    cs._kkt(kh, jac, 0.1, 0.0)
    ldl = cs.ldl
    vals = np.concatenate((kh.data[cs.kkt_ksel], jac.data,
                           np.r_[np.full(cs.nf, 1e-8), np.full(cs.neq, -1e-8)]))
    t = time.perf_counter()
    for _ in range(10):
        ldl.factor(vals, cs.neq)
    tf = (time.perf_counter() - t) / 10
    t = time.perf_counter()
    for _ in range(10):
        ldl.solve(np.ones(ldl.n))
    print(f"  the compiled solver's L D L^T (its dense tail {ldl.n - ldl.s} rows): factor "
          f"{1000 * tf:7.1f} ms, solve {100 * (time.perf_counter() - t):7.2f} ms, "
          f"nnz(L) {ldl.li.size}")
    cs._factor(jac)
    t = time.perf_counter()
    for _ in range(10):
        lin = cs._factor(jac)
        lin.solve(jac[:, cs.nd:].toarray(), torques=True)
    print(f"  structured factors of J_d and the 48 sensitivities "
          f"{100 * (time.perf_counter() - t):7.1f} ms", flush=True)


def print_horizons(a, step, r):
    """The per-horizon table of the Newton step ``step`` (rows of :func:`per_horizon`)."""
    print(f"{'Hs 1 m, Te 8 s bin' if a.te8 else f'seed {a.seed}'}, {len(r)} horizons, "
          f"both from the same start (the compiled solver's step {step}):")
    print("  update  compiled_s  ipopt_s  ratio  it_c  it_i  st_c st_i  rel_obj  max_du")
    for k, row in enumerate(r):
        print(f"  {k:6d} {row[0]:10.4f} {row[1]:8.4f} {row[1] / row[0]:6.1f} "
              f"{row[2]:5.0f} {row[3]:5.0f} {row[4]:4.0f} {row[5]:4.0f} {row[6]:8.1e} "
              f"{row[7]:7.1e}")
    ratio = r[:, 1] / r[:, 0]
    for name, col in (("compiled_s", r[:, 0]), ("ipopt_s", r[:, 1]), ("ratio", ratio)):
        print(f"  {name:10s} median {np.median(col):8.4f}  p99 {np.percentile(col, 99):8.4f}"
              f"  min {np.min(col):8.4f}")
    solved = (r[:, 4] == 0) & (r[:, 5] == 0)
    same = solved & (r[:, 6] < 1e-6)
    print(f"  iterations median: compiled {np.median(r[:, 2]):.0f}, ipopt "
          f"{np.median(r[:, 3]):.0f}; both solved to the same objective (1e-6 relative): "
          f"{int(same.sum())}/{len(r)}, of which the torques within 1e-4 m g l: "
          f"{int(np.sum(same & (r[:, 7] < 1e-4)))}, 1e-3: "
          f"{int(np.sum(same & (r[:, 7] < 1e-3)))}; compiled failed "
          f"{int(np.sum(r[:, 4] == 2))}, capped {int(np.sum(r[:, 4] == 1))}; ipopt failed "
          f"{int(np.sum(r[:, 5] == 2))}, capped {int(np.sum(r[:, 5] == 1))}", flush=True)
    ms = 1000 * r[:, 0] / np.maximum(r[:, 2], 1), 1000 * r[:, 1] / np.maximum(r[:, 3], 1)
    print(f"  time an iteration (ms), median: compiled {np.median(ms[0]):.1f}, ipopt "
          f"{np.median(ms[1]):.1f}", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--updates", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--forecast", default="perfect")
    ap.add_argument("--no-ipopt-run", action="store_true")
    ap.add_argument("--skip-horizons", action="store_true")
    ap.add_argument("--no-runs", action="store_true", help="the per-horizon tables only")
    ap.add_argument("--kkt", action="store_true")
    ap.add_argument("--step", nargs="+", default=None, choices=["auto", "kkt", "nullspace"],
                    help="the compiled solver's Newton steps compared per horizon (default "
                         "_hull_collocation_ipm.STEP; the first for the whole runs)")
    ap.add_argument("--te8", action="store_true",
                    help="the power matrix's Hs 1 m, Te 8 s bin (Tp 8.9 s), seed 0, in place "
                         "of the default sea")
    a = ap.parse_args()
    if a.kkt:
        from parapend.hydro.control import _blas_controller

        with _blas_controller().limit(limits=1, user_api="blas"):
            kkt_baseline(a.seed)
        return
    print(f"load average {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f}", flush=True)
    if a.step:
        from parapend.hydro import _hull_collocation_ipm as ipm

        ipm.STEP = a.step[0]
    if not a.skip_horizons:
        for step, r in per_horizon(a.seed, a.updates, a.te8, a.step).items():
            print_horizons(a, step, r)
    print(f"load average {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f}", flush=True)
    if a.no_runs:
        return
    p, wave = case(a.seed)
    plan0, statuses = hc._plan, []

    def plan(*args):
        r = plan0(*args)
        statuses.append(r.status)
        return r

    hc._plan = plan
    for solver in ("compiled",) + (() if a.no_ipopt_run else ("ipopt",)):
        hcol.SOLVER = solver
        statuses.clear()
        t = time.perf_counter()
        res = run_bin(a.forecast) if a.te8 else run(p, wave, a.forecast)
        wall = time.perf_counter() - t
        st = np.asarray(res._update_times)
        from parapend.hydro import _hull_collocation_ipm as ipm

        name = f"{solver} ({ipm.STEP})" if solver == "compiled" else solver
        print(f"whole run, {'Te 8 s bin' if a.te8 else f'seed {a.seed}'}, {a.forecast}, "
              f"{name}: electrical "
              f"{res.electrical_power_w:.4f} W, status {res.status}, {res.solves} solves, "
              f"{res.failed_solves} failed, {statuses.count(1)} capped; update median "
              f"{np.median(st):.3f} s, p99 "
              f"{np.percentile(st, 99):.3f} s, max {np.max(st):.3f} s (interval 0.75 s); "
              f"wall {wall:.1f} s", flush=True)
        print(f"load average {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f}", flush=True)


if __name__ == "__main__":
    main()
