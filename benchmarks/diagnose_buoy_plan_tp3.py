r"""Why do the buoy planner's horizon solves (``buoy_mpc(controller="plan")``) end abnormally
in short steep seas (Hs 0.8 m, Tp 3 s), where a perfect forecast lost to the AR forecast?

For one seeded short record (``parapend buoy --hs 0.8 --tp 3 --repeat-period 36 --seed S``,
the default buoy, pendulum and torque limit) it runs the closed loop with the given forecast
and records every horizon solve: its status (``converged``, ``max_iter``, ``line_search``),
its iterations, and at the end of a failed one the state of the interior point (the dual
residual against the objective's scale, the primal residual, the complementarity, the
barrier weight, the largest planned torque against the limit, the start's largest torque
violation). The record of each solve is the compiled solve's; the state at its end is the
Python reference loop (:meth:`CoupledPlan.solve_python`, the same iterations) rerun with a
trace.

    OPENBLAS_NUM_THREADS=1 python benchmarks/diagnose_buoy_plan_tp3.py --seed 0 \
        [--forecast perfect|ar] [--repeat-period 36]
"""

from __future__ import annotations

import argparse
import collections
import time

import numpy as np

from parapend.hydro import _buoy_plan as bp
from parapend.hydro import api
from parapend.hydro import control as bc


def run(seed, forecast, repeat_period, hs=0.8, tp=3.0, horizon=2.0):
    rec = []
    orig = bp.CoupledPlan.solve

    def solve(self, x, *, max_iter=100, tol=1e-8):
        tau0 = np.max(np.abs(self.constraint_torques(x))) / self.tmax
        xs, st, it = orig(self, x, max_iter=max_iter, tol=tol)
        tau1 = np.max(np.abs(self.constraint_torques(xs))) / self.tmax
        info = dict(status=st, it=it, tau0=tau0, tau1=tau1)
        if st != "converged":
            info.update(trace(self, x, max_iter, tol))
        rec.append(info)
        return xs, st, it

    bp.CoupledPlan.solve = solve
    t0 = time.perf_counter()
    try:
        r = api.buoy(hs=hs, tp=tp, seed=seed, repeat_period=repeat_period,
                     controller="mpc", forecast=forecast, horizon=horizon)
    finally:
        bp.CoupledPlan.solve = orig
    return r, rec, time.perf_counter() - t0


def trace(self, x, max_iter, tol):
    """The reference loop (:meth:`CoupledPlan.solve_python`, the same steps as the compiled
    one) rerun with a trace: the state of the interior point where it stops."""
    from scipy.linalg import LinAlgError, cho_factor, cho_solve

    x = np.asarray(x, dtype=float).copy()
    tm, nc = self.tmax, self.nc
    phi, gr, _, tau, jac = self.compiled(x, None, 1)
    gv = np.concatenate((tau / tm - 1.0, -tau / tm - 1.0))
    scale = max(1.0, float(np.max(np.abs(gr))))
    mu = bp.MU0 * scale
    s = np.maximum(-gv, 1e-2)
    lam = mu / s
    rho, it, delta_last, why = 0.0, 0, 0.0, "max_iter"
    hist = []
    while it < max_iter:
        it += 1
        nu = (lam[:nc] - lam[nc:]) / tm
        phi, gr, hess, tau, jac = self.compiled(x, nu)
        jg = np.concatenate((jac, -jac)) / tm
        gv = np.concatenate((tau / tm - 1.0, -tau / tm - 1.0))
        rd = gr + jg.T @ lam
        rp = gv + s
        comp = float(s @ lam) / s.size
        row = dict(rd=np.max(np.abs(rd)) / scale, rp=np.max(np.abs(rp)), comp=comp / scale,
                   mu=mu / scale, phi=phi, rho=rho, lam=float(np.max(lam)),
                   act=int(np.sum(s < 1e-3)))
        hist.append(row)
        if row["rd"] < tol and row["rp"] < 1e-7 and row["comp"] < tol:
            why = "converged"
            break
        err = max(row["rd"], row["rp"], np.max(np.abs(s * lam - mu)) / scale)
        if err <= 10.0 * mu / scale:
            mu = max(min(0.2 * mu, mu ** 1.5 / scale ** 0.5), 0.1 * tol * scale)
        sig = lam / s
        kmat = hess + jg.T @ (sig[:, None] * jg)
        rhs = -(gr + jg.T @ (mu / s + sig * rp))
        delta = 0.0
        dmin = 1e-8 * max(1.0, float(np.max(np.abs(np.diag(hess)))))
        while True:
            try:
                fac = cho_factor(kmat + delta * np.eye(self.n), check_finite=False)
                break
            except LinAlgError:
                delta = max(dmin, delta_last / 3.0, 8.0 * delta)
        delta_last = delta if delta else delta_last
        dx = cho_solve(fac, rhs, check_finite=False)
        ds = -rp - jg @ dx
        dl = mu / s - lam - sig * ds
        ap = bp._max_step(s, ds, 0.995)
        ad = bp._max_step(lam, dl, 0.995)
        # the solver's rule (before the fix: rho = max(rho, 1.1 max lam), held at its largest)
        rho = 1.1 * max(float(np.max(np.abs(lam))), float(np.max(np.abs(lam + ad * dl))))
        m0 = phi - mu * float(np.sum(np.log(s))) + rho * float(np.sum(np.abs(rp)))
        dm = gr @ dx - mu * float(np.sum(ds / s)) - rho * float(np.sum(np.abs(rp)))
        a, ok, tries = ap, False, 0
        # the constraint's nonlinearity along the step: the linearized residual at the full
        # step is (1 - ap) |rp|; the actual one
        ft, tt = self.compiled(x + ap * dx, order=0)
        gt = np.concatenate((tt / tm - 1.0, -tt / tm - 1.0))
        rp_full = float(np.sum(np.abs(gt + s + ap * ds)))
        w_k = np.linalg.eigvalsh(kmat + delta * np.eye(self.n))[0]
        for _ in range(30):
            tries += 1
            xt, st = x + a * dx, s + a * ds
            ft, tt = self.compiled(xt, order=0)
            gt = np.concatenate((tt / tm - 1.0, -tt / tm - 1.0))
            mt = ft - mu * float(np.sum(np.log(st))) + rho * float(np.sum(np.abs(gt + st)))
            if np.isfinite(mt) and mt <= m0 + 1e-4 * a * min(dm, 0.0):
                ok = True
                break
            a *= 0.5
        row.update(rp_sum=float(np.sum(np.abs(rp))), rp_full=rp_full,
                   rp_lin=(1.0 - ap) * float(np.sum(np.abs(rp))), eigK=w_k / scale,
                   dphi=ft - phi, dphi_lin=ap * float(gr @ dx))
        row.update(delta=delta, alpha_max=ap, alpha=a if ok else 0.0, tries=tries, dm=dm,
                   m0=m0, dxn=float(np.max(np.abs(dx))))
        if not ok:
            why = ("line_search (accepted)" if np.max(np.abs(rp)) < 1e-6
                   and comp < 10 * tol * scale else "line_search")
            break
        x, s = xt, st
        lam = lam + min(ad, 1.0) * dl
    return dict(why=why, hist=hist)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--forecast", choices=("perfect", "ar"), default="perfect")
    ap.add_argument("--repeat-period", type=float, default=36.0)
    ap.add_argument("--no-trace", action="store_true")
    ap.add_argument("--max-iter", type=int, default=None,
                    help="interior-point iterations per solve (default: the planner's)")
    ap.add_argument("--interval-samples", type=int, default=None,
                    help="torque samples per Hermite interval (default: the planner's)")
    ap.add_argument("--horizon", type=float, default=2.0, help="peak periods")
    ap.add_argument("--show", type=int, default=3, help="failed solves traced in full")
    a = ap.parse_args()
    if a.no_trace:
        global trace
        trace = lambda *args: {}  # noqa: E731
    if a.max_iter:
        bc.PLAN_MAX_ITER = a.max_iter
    if a.interval_samples:
        bc.PLAN_INTERVAL_SAMPLES = a.interval_samples
    r, rec, sec = run(a.seed, a.forecast, a.repeat_period, horizon=a.horizon)
    c = collections.Counter(d["status"] for d in rec)
    its = np.array([d["it"] for d in rec])
    print(f"seed {a.seed}, forecast {a.forecast}, repeat period {a.repeat_period:g} s, "
          f"horizon {a.horizon:g} Tp, {bc.PLAN_MAX_ITER} iterations at most, "
          f"{bc.PLAN_INTERVAL_SAMPLES} samples an interval: "
          f"power {r.mean_power_w:.2f} W, optimum {r.optimum_power_w:.2f} W, {sec:.0f} s")
    print(f"  {len(rec)} solves: " + ", ".join(f"{k} {v}" for k, v in sorted(c.items()))
          + f"; iterations median {np.median(its):.0f}, max {its.max()}")
    t0 = np.array([d["tau0"] for d in rec])
    t1 = np.array([d["tau1"] for d in rec])
    bad = np.array([d["status"] != "converged" for d in rec])
    print(f"  start's max |tau|/T_max: converged median {np.median(t0[~bad]):.3f}, failed "
          f"median {np.median(t0[bad]) if bad.any() else np.nan:.3f}; end's: converged "
          f"max {np.max(t1[~bad]):.4f}, failed max {np.max(t1[bad]) if bad.any() else 0:.4f}")
    shown = 0
    rows = [row for d in rec if "hist" in d for row in d["hist"] if "rp_full" in row]
    if rows:
        rej = [row for row in rows if row["alpha"] < row["alpha_max"]]
        print(f"  failed solves' iterations: {len(rows)}, of them {len(rej)} backtracked; in "
              f"those the step's largest change (median) "
              f"{np.median([q['dxn'] for q in rej]):.3g}"
              f" rad, the constraint residual sum at the longest step: linearized "
              f"{np.median([q['rp_lin'] for q in rej]):.3g}, actual "
              f"{np.median([q['rp_full'] for q in rej]):.3g} (median; before the step "
              f"{np.median([q['rp_sum'] for q in rej]):.3g}); objective change actual / "
              f"linearized {np.median([q['dphi'] / q['dphi_lin'] for q in rej]):.3f}; "
              f"smallest eigenvalue of the (corrected) Newton matrix / scale "
              f"{np.median([q['eigK'] for q in rej]):.3g}")
    for i, d in enumerate(rec):
        if d["status"] != "converged" and "hist" in d and shown < a.show:
            shown += 1
            h = d["hist"]
            print(f"  solve {i}: {d['status']} after {d['it']} (reference: {d['why']} after "
                  f"{len(h)}), start max|tau|/T_max {d['tau0']:.3f}, end {d['tau1']:.4f}")
            for q in sorted(set([0, 5, 10, 20, 40, 60, 80, len(h) - 1])):
                if 0 <= q < len(h):
                    print("    it", q, " ".join(f"{k}={v:.3g}" for k, v in h[q].items()))


if __name__ == "__main__":
    main()
