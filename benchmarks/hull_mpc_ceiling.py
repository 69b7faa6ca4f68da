"""What limits the hull's causal controller: its optimizer or its formulation?

The embedded barge, its default sea state (Hs 1 m, Tp 6 s, JONSWAP 3.3, a record of 4 Tp),
:func:`parapend.hydro.hull_control.hull_mpc` with a perfect forecast of 2 Tp (4 Tp of
warm-up, the storage-corrected mean over one repeat, the pump's start), each planner variant
swapped in through the horizon-solve hook ``hull_control._plan`` (as the causality tests
do), the fraction of the record's non-causal optimum (``solve_record``) printed per seed:

- ``lbfgsb:N``: L-BFGS-B on the held torques, ``N`` iterations at most (``ftol`` 1e-12; the
  default planner is ``lbfgsb:60`` with ``ftol`` 1e-9);
- ``newton:N``: a bound-constrained trust-region Newton method (:func:`newton_tr`), the
  Hessian by forward differences of the planner's exact adjoint gradient (48 gradients an
  iteration), ``N`` iterations at most, from the same warm start;
- ``oracle:N``: L-BFGS-B from the shifted plan AND from the non-causal optimum's own
  torque over the horizon (not causal: a diagnosis), the better horizon objective applied;
- ``tail:N``: the buoy's zero-excitation tail of one peak period after the horizon (24 more
  torques planned, the first ``n`` applied), L-BFGS-B of ``N`` iterations (the default
  samples and update interval only);

with ``key=value`` pairs passed on to ``hull_mpc`` (``terminal_weight``, ``horizon``,
``plant_steps``, ``planner``: with ``planner=collocation`` the spec's solver is IPOPT's, its
``N`` ignored).

``--on-optimum``: the run started ON the non-causal optimum's motion at ``t = 0`` (the
hull's state and velocity history, the pendulum's angle and speed; planned from the start):
whether the receding horizon keeps the optimum once it is there.

``--first-horizon STEPS``: on the optimum's state at ``t = 0``, how far the plant under the
optimum's own torques (held over the samples) strays from its motion, and the horizon
objective of those torques against the planner's answer.

``--compare K``: on the horizons of the first ``K`` updates of a default run, the objective
each solver reaches from the same warm start (units m g l rad, minimized) and its time.

    nice python benchmarks/hull_mpc_ceiling.py lbfgsb:600 --seeds 0 1 2
    nice python benchmarks/hull_mpc_ceiling.py lbfgsb:60 terminal_weight=0.5 --seeds 0 1 2
    nice python benchmarks/hull_mpc_ceiling.py --compare 12 --seeds 0
"""

from __future__ import annotations

import argparse
import math
import time
from types import SimpleNamespace

import numpy as np

from parapend.hydro import hull_control as hc
from parapend.hydro.api import hull_problem, solve_record
from parapend.hydro.declared import default_of
from parapend.hydro.inputs import _irregular_wave
from parapend.units import Units


def _fd_hessian(fun, u, g, hi, eps=1e-6):
    """Forward differences of the exact gradient, column by column, symmetrized."""
    n = u.size
    hs = np.empty((n, n))
    for k in range(n):
        e = eps * max(1.0, abs(u[k]))
        s = e if u[k] + e <= hi else -e
        up = u.copy()
        up[k] += s
        hs[:, k] = (fun(up)[1] - g) / s
    return 0.5 * (hs + hs.T)


def _tr_step(hs, g, delta):
    """``min g.d + 1/2 d.H d`` on ``|d| <= delta`` by the eigendecomposition of ``H``
    (More and Sorensen's multiplier found by bisection)."""
    lam, v = np.linalg.eigh(hs)
    a = v.T @ g
    if lam[0] > 0:
        d = -v @ (a / lam)
        if np.linalg.norm(d) <= delta:
            return d
    lo = max(0.0, -lam[0]) + 1e-14 * max(1.0, abs(lam[0]))
    if np.linalg.norm(a / (lam + lo)) <= delta:  # the hard case: add the lowest mode
        d = -v @ (a / (lam + lo + 1e-12))
        rest = delta ** 2 - d @ d
        return d + math.sqrt(max(rest, 0.0)) * v[:, 0]
    hi = lo + np.linalg.norm(g) / delta + 1.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if np.linalg.norm(a / (lam + mid)) > delta else (lo, mid)
        if hi - lo < 1e-12 * max(1.0, hi):
            break
    return -v @ (a / (lam + hi))


def newton_tr(fun, u0, lim, max_iter=30, gtol=1e-7, delta=0.5):
    """Bound-constrained trust-region Newton (the variables at a bound whose gradient
    pushes outward held, the step projected on the box, the radius from the ratio of the
    actual to the predicted decrease); ``status`` 0 converged, 1 iterations, 2 the radius
    collapsed."""
    u = np.clip(np.asarray(u0, dtype=float), -lim, lim)
    f, g = fun(u)
    hs, status, nit = None, 1, 0
    for nit in range(max_iter):  # noqa: B007 (the count is returned)
        out = ((u >= lim) & (g < 0)) | ((u <= -lim) & (g > 0))
        if np.max(np.abs(np.where(out, 0.0, g))) < gtol:
            status = 0
            break
        if hs is None:
            hs = _fd_hessian(fun, u, g, lim)
        free = ~out
        d = np.zeros_like(u)
        d[free] = _tr_step(hs[np.ix_(free, free)], g[free], delta)
        un = np.clip(u + d, -lim, lim)
        dd = un - u
        pred = -(g @ dd + 0.5 * dd @ hs @ dd)
        fn, gn = fun(un)
        rho = (f - fn) / pred if pred > 0 and np.isfinite(fn) else -1.0
        if rho < 0.25:
            delta = 0.25 * np.linalg.norm(dd)
        elif rho > 0.75 and np.linalg.norm(d) > 0.99 * delta:
            delta = min(2.0 * delta, 10.0 * lim)
        if rho > 1e-4:
            u, f, g, hs = un, fn, gn, None
        if delta < 1e-10:
            status = 2
            break
    return SimpleNamespace(x=u, fun=f, jac=g, nit=nit, status=status, success=status == 0)


def _wave(seed, pend):
    return _irregular_wave(1.0, 6.0, "jonswap", 3.3, 24.0, seed, default_of("cutoff", None),
                           None, default_of("taper", None),
                           Units(pend.length, pend.mass, 9.81, pend.inertia))


#: per update of an ``oracle`` run: 1 where the optimum's torque as the start won
WINS = []


def _planner(spec, motion):
    """The horizon-solve hook for ``spec`` (module docstring)."""
    kind, iters = spec.split(":")
    iters = int(iters)
    state = {}

    def lbfgsb(prob, plant, fseg, u0):
        return prob.solve(plant, fseg, u0, max_iter=iters, tol=1e-12)

    def plan(prob, plant, fseg, u0, max_iter):
        if kind == "lbfgsb":
            return lbfgsb(prob, plant, fseg, u0)
        if kind == "newton":
            prob.offset = 0.0
            return newton_tr(lambda u: prob.fun(u, plant, fseg), u0, prob.torque_limit,
                             max_iter=iters)
        if kind == "oracle":
            j, dt = plant.k0 // prob.steps, prob.h * prob.steps
            tt = (j + np.arange(prob.n)[:, None] + (np.arange(8) + 0.5) / 8) * dt
            uo = motion(tt.ravel())["tau"].reshape(prob.n, 8).mean(axis=1) / prob.tu
            best = None
            for k, start in enumerate((u0, uo)):
                r = lbfgsb(prob, plant, fseg, start)
                f = r.fun + prob.offset  # each solve's offset is its start's objective
                if best is None or f < best[0]:
                    best = (f, r, k)
            WINS.append(best[2])
            return best[1]
        if kind == "tail":
            n, nt, m = prob.n, hc.SAMPLES, state.setdefault("m", 3)
            if "long" not in state:
                state["long"] = hc.HullHorizon(plant, n + nt, prob.steps, prob.tu,
                                               prob.torque_limit, None, prob.kappa)
                state["prev"] = np.zeros(n + nt)
            prev = state["prev"]
            u0 = np.concatenate((u0, prev[n + m:], np.full(m, prev[-1])))
            fseg = np.concatenate((fseg, np.zeros((2 * nt * prob.steps, 3))))
            r = lbfgsb(state["long"], plant, fseg, u0)
            state["prev"] = np.asarray(r.x, dtype=float).copy()
            r.x = state["prev"][:n]
            return r
        raise SystemExit(f"unknown planner {spec!r}")
    return plan


def _start_on(motion):
    """Patch the run's start onto the non-causal optimum's motion at ``t = 0`` (hull state,
    its velocity history, the pendulum's angle and speed): a diagnosis, not causal."""
    def free_start(case):
        def history(t):
            return np.asarray(motion(np.atleast_1d(t))["xi_dot"]).T
        d = motion(np.zeros(1))
        return np.asarray(d["xi"])[:, 0], history(np.zeros(1))[0], history

    class Plant(hc.HullPlant):
        def __init__(self, *a, **k):
            super().__init__(*a, **k)
            d = motion(np.zeros(1))
            self.y[3], self.y[7] = float(d["phi"][0]), float(d["phi_dot"][0])

    hc._free_start, hc.HullPlant = free_start, Plant


def closed_loop(spec, opts, seeds, on_optimum=False):
    opts = {"planner": "lbfgsb", **opts}  # the variants are L-BFGS-B's unless named
    p = hull_problem()
    pend = p["pendulum"]
    print(f"planner {spec} {opts}: seed optimum_w power_w fraction stored_w failed "
          "update_p99_s wall_s", flush=True)
    fracs = []
    for seed in seeds:
        wave, info = _wave(seed, pend)
        opt = solve_record(p, wave, info)
        hc._plan = _planner(spec, opt.motion)
        if on_optimum:
            _start_on(opt.motion)
        t = time.time()
        r = hc.hull_mpc(p["hull"], pend, wave, peak_period=6.0, pivot=p["pivot"],
                        forecast="perfect", mode="swing" if on_optimum else "rotate",
                        **opts)
        frac = r.mean_power_w / opt.power_w
        fracs.append(frac)
        print(f"  {seed} {opt.power_w:.1f} {r.mean_power_w:.1f} {frac:.3f} {r.stored_w:.1f} "
              f"{r.failed_solves}/{r.solves} {r.update_time_p99_s:.2f} {time.time() - t:.0f}"
              f" {r.status}" + (f" oracle start won {sum(WINS)}/{len(WINS)}" if WINS else ""),
              flush=True)
        WINS.clear()
    ok = [f for f in fracs if math.isfinite(f)]
    print(f"  mean {np.mean(ok) if ok else math.nan:.3f} over {len(ok)} of {len(fracs)}")


def compare(updates, seeds):
    """The horizon objective each solver reaches on the problems of a default run."""
    p = hull_problem()
    pend = p["pendulum"]
    rows = []

    def plan(prob, plant, fseg, u0, max_iter):
        fun = lambda u: prob.fun(u, plant, fseg)  # noqa: E731
        row = []
        for name, it in (("lbfgsb", 60), ("lbfgsb", 600), ("newton", 30)):
            t = time.perf_counter()
            if name == "lbfgsb":
                r = prob.solve(plant, fseg, u0, max_iter=it, tol=1e-12)
                f = r.fun + prob.offset
            else:
                off, prob.offset = prob.offset, 0.0
                r = newton_tr(fun, u0, prob.torque_limit, max_iter=it)
                f, prob.offset = r.fun, off
            row.append((f, time.perf_counter() - t))
            if it == 60:
                keep = r
        rows.append(row)
        print("  " + " ".join(f"{f:9.4f} ({s:5.2f} s)" for f, s in row), flush=True)
        if len(rows) >= updates:
            raise StopIteration
        return keep

    for seed in seeds:
        wave, _ = _wave(seed, pend)
        hc._plan = plan
        print(f"seed {seed}: objective (time) L-BFGS-B 60, L-BFGS-B 600, Newton-TR 30")
        try:
            hc.hull_mpc(p["hull"], pend, wave, peak_period=6.0, pivot=p["pivot"],
                        mode="rotate", planner="lbfgsb")
        except StopIteration:
            pass
        rows.clear()


def first_horizon(seeds, steps):
    """On the optimum's state at ``t = 0``: the plant under the optimum's own torques (held
    over the samples) against the optimum's motion, and the horizon objective of those
    torques against L-BFGS-B's answer (600 iterations) from zero and from them."""
    p = hull_problem()
    for seed in seeds:
        _first_horizon(p, seed, steps)


def _first_horizon(p, seed, steps):
    from parapend.hydro import control as bc
    from parapend.hydro.hull import make_case

    pend = p["pendulum"]
    tu = pend.mass * 9.81 * pend.length
    wave, info = _wave(seed, pend)
    motion = solve_record(p, wave, info).motion
    kw = wave.amplitudes.size
    case = make_case(p["hull"], pend, wave, winding=0, harmonics=kw, hull_harmonics=kw,
                     pivot=p["pivot"])
    per, n = 4 * hc.SAMPLES, 2 * hc.SAMPLES
    dt = 24.0 / per

    def history(t):
        return np.asarray(motion(np.atleast_1d(t))["xi_dot"]).T
    d0 = motion(np.zeros(1))

    def plant_at_start():
        pl = hc.HullPlant(p["hull"], pend, case, dt / steps, 2 * per * steps,
                          hc.MEMORY_PERIODS * 6.0, np.asarray(d0["xi"])[:, 0],
                          history(np.zeros(1))[0], history)
        pl.y[3], pl.y[7] = float(d0["phi"][0]), float(d0["phi_dot"][0])
        return pl
    fn = bc.force_nodes(p["hull"], wave, per, steps, 2 * (per + n) * steps + 1)
    tt = (np.arange(per)[:, None] + (np.arange(16) + 0.5) / 16) * dt
    uo = motion(tt.ravel())["tau"].reshape(per, 16).mean(axis=1)
    plant = plant_at_start()
    _, ys = plant.step(uo[:n], steps, fn)
    err = np.abs(ys[:, 3] - motion(dt * np.arange(n + 1))["phi"])
    print(f"seed {seed}, {steps} plant steps a sample: the optimum's held torques from its "
          "state leave its angle by " + ", ".join(
              f"{err[k]:.3f} rad after {k * dt:g} s" for k in (1, 2, 4, 8, 24)))
    plant = plant_at_start()
    prob = hc.HullHorizon(plant, n, steps, tu, hc.DEFAULT_LIMIT, None)
    fseg = fn[:2 * n * steps + 1]
    prob.offset = 0.0
    fo = prob.fun(uo[:n] / tu, plant, fseg)[0]
    out = []
    for name, u0 in (("zero", np.zeros(n)), ("the optimum's torques", uo[:n] / tu)):
        r = prob.solve(plant, fseg, u0, max_iter=600, tol=1e-12)
        out.append(f"from {name} {r.fun + prob.offset:.3f}")
    v = motion(np.linspace(0.0, 24.0, 2401))["relative_speed"]
    print(f"  horizon objective (m g l rad, minimized) of the optimum's torques {fo:.3f}; "
          "L-BFGS-B 600 " + ", ".join(out) + "; the optimum's |relative speed| peaks at "
          f"{np.max(np.abs(v)):.2f} rad/s, the planner's resolved speed "
          f"{hc.RESOLVED_TURN * steps / dt:.2f} rad/s", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("spec", nargs="*", default=["lbfgsb:60"])
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    ap.add_argument("--compare", type=int, default=0)
    ap.add_argument("--first-horizon", type=int, default=0, metavar="STEPS",
                    help="the optimum's torques on the first horizon, STEPS plant steps")
    ap.add_argument("--on-optimum", action="store_true",
                    help="start the run on the non-causal optimum's motion (a diagnosis)")
    a = ap.parse_args()
    if a.compare:
        compare(a.compare, a.seeds)
        return
    if a.first_horizon:
        first_horizon(a.seeds, a.first_horizon)
        return
    spec, *kv = a.spec
    opts = {}
    for item in kv:
        k, v = item.split("=")
        opts[k] = (int(v) if k in ("plant_steps", "samples") else v
                   if k == "planner" else float(v))
    closed_loop(spec, opts, a.seeds, a.on_optimum)


if __name__ == "__main__":
    main()
