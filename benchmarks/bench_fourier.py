r"""Time parapend's Fourier optimizer against the paper's method and a general optimal-control tool.

Problem (non-dimensional, DESIGN.md section 1): ``theta'' + gamma theta' - (1 + q) sin(theta) = T``
with ``q = delta sin(omega t)``, paper case ``delta = -0.3, omega = 1.8``. Among period-1 rotations
``theta(t + 2 pi/omega) = theta(t) + 2 pi``, maximize the mean extracted power::

    P = <q'(t) cos(theta)> - gamma <theta'^2>

Methods, all run in this one process on the same machine:

1. **parapend** (ours): ``solve_fourier(exc, 40, gamma)``, the safeguarded Newton method with exact
   FFT gradient and Hessian on the N = 40 Fourier series of Eq. 10 (81 unknowns). The excitation
   is built once, outside the timing; the median of ``--repeat`` calls is reported after one
   untimed warm-up call (the first, cold call is reported separately). ``parapend.optimize``
   (the full public call: result object, peak torque, ...) and ``parapend.threshold`` (damping
   threshold gamma*, paper Fig. 6) are timed the same way.
2. **Nelder-Mead** (the paper's method; MATLAB ``fminsearch``): ``scipy.optimize.minimize(...,
   method="Nelder-Mead", adaptive=True)`` on the same 81 coefficients with the *same objective*,
   ``FourierProblem(exc, 40, 0).power`` (the same quadrature grid as ours), started from the best
   uniform rotation ``x0 = [pi, 0, ..., 0]`` with SciPy's default initial simplex (the rule
   ``fminsearch`` uses). Tolerances are set tiny so that it stops only when the simplex has
   collapsed or a wall-clock budget (``--nm-budget``) runs out. One run; the times at which it
   first came within 1e-3 and 1e-6 of our optimum are recorded inside the objective.
3. **CasADi + IPOPT**: direct trapezoidal collocation on 800 intervals over one period, states
   ``theta, theta'`` at the nodes, torque ``T`` piecewise constant per interval (so no spurious
   null mode), dynamics by the trapezoidal rule, periodicity ``theta(end) = theta(0) + 2 pi``,
   ``theta'(end) = theta'(0)``; objective: the trapezoidal mean of ``q' cos(theta) - gamma
   theta'^2``. SX graph, exact Hessian, MUMPS, ``tol = 1e-8``. Initial guess: the uniform
   rotation ``theta = omega t + pi`` with the torque that realizes it. The NLP is built once
   (build time reported); the median of ``--peer-repeat`` solves is reported.

Why the comparison is fair, and where it cannot be:

- Nelder-Mead optimizes exactly our finite-dimensional problem (same unknowns, same objective,
  same quadrature), so time and accuracy compare directly.
- For ``gamma = 0`` the continuous problem has no maximizer (the supremum ``2 omega |delta|/pi =
  0.34377`` is approached by a discontinuous, bang-bang motion). Ours and Nelder-Mead solve the
  well-posed N = 40 truncation; collocation with free torque solves a *different* finite problem
  whose optimum jumps by about pi between nodes (huge theta'), approximating the supremum.
  Its power gap to ours is then our truncation error, not its error; the row is kept because it
  is what a user of an optimal-control tool would get.
- For ``gamma = 0.01`` both formulations discretize the same well-posed problem: our N = 40
  optimum is converged to rounding (N = 80 gives the same power), while collocation on 800
  intervals has an O(h^2) error. There the comparison is also made at *matched accuracy*: ours
  at the smallest N whose power is as close to the converged optimum as the collocation's.

Machines are shared and noisy: read the ratios (peer time / our time, same run), not the
absolute times.

Run: ``python benchmarks/bench_fourier.py [--quick] [--repeat N] [--json PATH]``.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import statistics
import sys
import time
from dataclasses import asdict, dataclass, field

import numpy as np
import scipy
from scipy.optimize import minimize

import parapend
from parapend.api import build_excitation
from parapend.optimal.fourier import FourierProblem, solve_fourier

OMEGA, DELTA = 1.8, -0.3  # the paper's case
HARMONICS = 40
INTERVALS = 800
GAMMA_POSED = 0.01
ACCURACY_MARKS = (1e-3, 1e-6)


@dataclass
class Row:
    """One line of the table; ``time_s`` is a median unless the note says otherwise."""

    method: str
    time_s: float | None
    power: float | None
    gap: float | None
    ratio: float | None
    gamma: float
    notes: list[str] = field(default_factory=list)
    details: dict = field(default_factory=dict)


def machine_info() -> dict:
    """CPU count and model, library versions."""
    model = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    try:
        usable = len(os.sched_getaffinity(0))
    except AttributeError:
        usable = os.cpu_count()
    info = {"nproc": usable, "cpu_model": model, "python": platform.python_version(),
            "numpy": np.__version__, "scipy": scipy.__version__,
            "parapend": getattr(parapend, "__version__", "?")}
    try:
        import casadi

        info["casadi"] = casadi.__version__
    except ImportError:
        info["casadi"] = None
    return info


def median_time(fn, repeat: int):
    """Median wall time of ``fn()`` over ``repeat`` calls after one untimed warm-up call."""
    out = fn()
    times = []
    for _ in range(max(1, repeat)):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


# ---------------------------------------------------------------------------------------------
# ours


def bench_ours(exc, gamma: float, repeat: int, harmonics: int = HARMONICS):
    """Median time and result of ``solve_fourier(exc, harmonics, gamma)``."""
    t, (best, _) = median_time(lambda: solve_fourier(exc, harmonics, gamma), repeat)
    return t, best


def matched_harmonics(exc, gamma: float, reference: float, gap: float, upto: int) -> int:
    """Smallest N whose optimum is within ``gap`` of the converged ``reference`` power."""
    for n in range(1, upto + 1):
        if abs(solve_fourier(exc, n, gamma)[0].power - reference) <= gap:
            return n
    return upto


# ---------------------------------------------------------------------------------------------
# the paper's method: Nelder-Mead on the same coefficients and objective


class _Recorder:
    """Objective wrapper: counts evaluations, remembers when accuracy marks were first reached."""

    def __init__(self, problem: FourierProblem, reference: float):
        self.problem = problem
        self.reference = reference
        self.best = -math.inf
        self.nfev = 0
        self.marks: dict[float, float | None] = dict.fromkeys(ACCURACY_MARKS)
        self.t0 = time.perf_counter()

    def __call__(self, x: np.ndarray) -> float:
        p = self.problem.power(x)
        self.nfev += 1
        if p > self.best:
            self.best = p
            for tol, when in self.marks.items():
                if when is None and self.reference - p <= tol:
                    self.marks[tol] = time.perf_counter() - self.t0
        return -p


def bench_nelder_mead(exc, reference: float, budget: float) -> dict:
    """One adaptive Nelder-Mead run from the best uniform rotation, stopped after ``budget`` s."""
    problem = FourierProblem(exc, HARMONICS, 0.0)
    x0 = np.zeros(2 * HARMONICS + 1)
    x0[0] = math.pi
    rec = _Recorder(problem, reference)
    out_of_time = False

    def stop_on_budget(intermediate_result):
        nonlocal out_of_time
        if time.perf_counter() - rec.t0 > budget:
            out_of_time = True
            raise StopIteration

    rec.t0 = time.perf_counter()
    res = minimize(rec, x0, method="Nelder-Mead", callback=stop_on_budget,
                   options={"adaptive": True, "maxfev": 10**9, "maxiter": 10**9,
                            "xatol": 1e-12, "fatol": 1e-15})
    elapsed = time.perf_counter() - rec.t0
    return {"time_s": elapsed, "power": rec.best, "nfev": rec.nfev, "nit": int(res.nit),
            "stopped_by": "time budget" if out_of_time else res.message,
            "budget_s": budget, "marks": rec.marks}


# ---------------------------------------------------------------------------------------------
# CasADi + IPOPT direct trapezoidal collocation


def build_collocation(exc, gamma: float, intervals: int = INTERVALS):
    """NLP of the period-1 rotation problem by trapezoidal collocation; returns solver pieces."""
    import casadi as ca

    k = intervals
    period = 2 * math.pi / exc.omega
    h = period / k
    t = np.linspace(0.0, period, k + 1)
    q = np.asarray(exc.q(t), dtype=float)
    dq = np.asarray(exc.dq(t), dtype=float)
    th = ca.SX.sym("theta", k + 1)
    v = ca.SX.sym("theta_dot", k + 1)
    u = ca.SX.sym("torque", k)  # piecewise constant on each interval
    f = -gamma * v + (1 + q) * ca.sin(th)  # theta'' = T + f
    g = ca.vertcat(th[1:] - th[:-1] - 0.5 * h * (v[1:] + v[:-1]),
                   v[1:] - v[:-1] - h * u - 0.5 * h * (f[1:] + f[:-1]),
                   th[k] - th[0] - 2 * math.pi,
                   v[k] - v[0])
    w = np.full(k + 1, 1.0 / k)
    w[0] = w[-1] = 0.5 / k  # trapezoidal mean over one period
    power = ca.dot(ca.DM(w), ca.DM(dq) * ca.cos(th) - gamma * v**2)
    x = ca.vertcat(th, v, u)
    opts = {"ipopt.tol": 1e-8, "ipopt.print_level": 0, "ipopt.sb": "yes", "print_time": False}
    solver = ca.nlpsol("collocation", "ipopt", {"x": x, "f": -power, "g": g}, opts)
    power_fn = ca.Function("power", [x], [power])
    # initial guess: uniform rotation theta = omega t + pi and the torque that realizes it
    th0 = exc.omega * t + math.pi
    v0 = np.full(k + 1, exc.omega)
    f0 = -gamma * v0 + (1 + q) * np.sin(th0)
    u0 = -0.5 * (f0[1:] + f0[:-1])
    x0 = np.concatenate((th0, v0, u0))
    return solver, power_fn, x0


def bench_casadi(exc, gamma: float, repeat: int) -> dict:
    """Build once (timed separately), then the median IPOPT solve time from the same guess."""
    t0 = time.perf_counter()
    solver, power_fn, x0 = build_collocation(exc, gamma)
    build = time.perf_counter() - t0
    t, sol = median_time(lambda: solver(x0=x0, lbg=0, ubg=0), repeat)
    stats = solver.stats()
    x = np.asarray(sol["x"]).ravel()
    k = INTERVALS
    return {"time_s": t, "build_s": build, "power": float(power_fn(sol["x"])),
            "status": stats["return_status"], "success": bool(stats["success"]),
            "iterations": int(stats["iter_count"]),
            "max_abs_theta_dot": float(np.max(np.abs(x[k + 1:2 * k + 2])))}


# ---------------------------------------------------------------------------------------------
# report


def _fmt_time(t: float | None) -> str:
    if t is None:
        return "-"
    if t < 1.0:
        return f"{t * 1e3:.3g} ms"
    return f"{t:.3g} s"


def _fmt(x: float | None, spec: str) -> str:
    return "-" if x is None else format(x, spec)


def print_table(rows: list[Row], info: dict) -> None:
    print(f"machine: {info['nproc']} CPU(s), {info['cpu_model']}; python {info['python']}, "
          f"numpy {info['numpy']}, scipy {info['scipy']}, casadi {info['casadi']}")
    print(f"case: harmonic q = delta sin(omega t), delta = {DELTA}, omega = {OMEGA}; "
          "ratio = time / time(ours, same gamma)\n")
    head = f"{'method':<48} {'gamma':>5} {'time':>10} {'power':>14} {'|P - ours|':>10} " \
           f"{'ratio':>9}  notes"
    print(head)
    print("-" * len(head))
    marks = {}
    for r in rows:
        refs = []
        for note in r.notes:
            marks.setdefault(note, len(marks) + 1)
            refs.append(f"[{marks[note]}]")
        print(f"{r.method:<48} {r.gamma:>5g} {_fmt_time(r.time_s):>10} "
              f"{_fmt(r.power, '.10f'):>14} {_fmt(r.gap, '.2e'):>10} "
              f"{_fmt(r.ratio, '.3g'):>9}  {' '.join(refs)}")
    print()
    for note, i in marks.items():
        print(f"[{i}] {note}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    ap.add_argument("--repeat", type=int, default=None,
                    help="timed calls of our solver (median; default 200, 20 with --quick)")
    ap.add_argument("--peer-repeat", type=int, default=None,
                    help="timed CasADi solves (median; default 5, 2 with --quick)")
    ap.add_argument("--nm-budget", type=float, default=None,
                    help="wall-clock budget of the Nelder-Mead run in s (default 60, 10 quick)")
    ap.add_argument("--quick", action="store_true", help="fewer repeats, shorter budgets")
    ap.add_argument("--json", metavar="PATH", help="also write the numbers to PATH as JSON")
    args = ap.parse_args(argv)
    repeat = args.repeat or (20 if args.quick else 200)
    peer_repeat = args.peer_repeat or (2 if args.quick else 5)
    nm_budget = args.nm_budget or (10.0 if args.quick else 60.0)

    info = machine_info()
    exc = build_excitation("harmonic", omega=OMEGA, delta=DELTA)
    rows: list[Row] = []

    # -- ours ------------------------------------------------------------------------------
    t0 = time.perf_counter()
    solve_fourier(build_excitation("harmonic", omega=OMEGA, delta=DELTA), HARMONICS, 0.0)
    cold = time.perf_counter() - t0
    t_ours, best = bench_ours(exc, 0.0, repeat)
    p_ours = best.power
    rows.append(Row(f"parapend solve_fourier N={HARMONICS}", t_ours, p_ours, 0.0, 1.0, 0.0,
                    [f"median of {repeat}; status {best.status}, found by "
                     f"{best.seed!r}, {best.points} quadrature points"],
                    {"cold_first_call_s": cold, "status": best.status}))
    t_opt, res = median_time(
        lambda: parapend.optimize(omega=OMEGA, delta=DELTA, harmonics=HARMONICS),
        max(1, repeat // 4))
    rows.append(Row(f"parapend.optimize(harmonics={HARMONICS})", t_opt, res.power,
                    abs(res.power - p_ours), t_opt / t_ours, 0.0,
                    ["full public call: builds the excitation, result object, peak torque"]))

    # -- Nelder-Mead -----------------------------------------------------------------------
    nm = bench_nelder_mead(exc, p_ours, nm_budget)
    rows.append(Row(f"Nelder-Mead (paper), same {2 * HARMONICS + 1} coefficients",
                    nm["time_s"], nm["power"], abs(nm["power"] - p_ours),
                    nm["time_s"] / t_ours, 0.0,
                    [f"one run; adaptive NM, x0 = [pi, 0, ...], budget {nm_budget:g} s; "
                     f"{nm['nfev']} evaluations, stopped by: {nm['stopped_by']}"], nm))
    for tol in ACCURACY_MARKS:
        when = nm["marks"][tol]
        note = (f"time until the best NM value first came within {tol:g} of ours"
                if when is not None else
                f"NM did NOT come within {tol:g} of ours within its {nm_budget:g} s budget")
        rows.append(Row(f"  Nelder-Mead, to within {tol:g}", when, None, None,
                        None if when is None else when / t_ours, 0.0, [note]))

    # -- CasADi + IPOPT, gamma = 0 ---------------------------------------------------------
    try:
        import casadi  # noqa: F401

        have_casadi = True
    except ImportError:
        have_casadi = False
    cas_label = f"CasADi+IPOPT trapezoidal, {INTERVALS} intervals"

    def casadi_row(gamma: float, t_ref: float, p_ref: float, extra: str) -> dict | None:
        if not have_casadi:
            rows.append(Row(cas_label, None, None, None, None, gamma,
                            ["skipped: casadi is not installed (pip install casadi)"]))
            return None
        try:
            c = bench_casadi(exc, gamma, peer_repeat)
        except RuntimeError as err:  # e.g. the IPOPT plugin cannot be loaded
            rows.append(Row(cas_label, None, None, None, None, gamma,
                            [f"skipped: CasADi/IPOPT failed: {err}"]))
            return None
        rows.append(Row(cas_label, c["time_s"], c["power"], abs(c["power"] - p_ref),
                        c["time_s"] / t_ref, gamma,
                        [f"median of {peer_repeat} IPOPT solves (build {c['build_s'] * 1e3:.0f} ms "
                         f"not included); gamma={gamma:g}: {c['status']} in {c['iterations']} "
                         f"iterations, max|theta'| = {c['max_abs_theta_dot']:.3g}; {extra}"], c))
        return c

    casadi_row(0.0, t_ours, p_ours,
               "gamma=0 discrete problem is bang-bang (jumps between nodes): its power "
               "approximates the sup 2 omega |delta|/pi = "
               f"{2 * OMEGA * abs(DELTA) / math.pi:.6f}, not the N=40 optimum")

    # -- well-posed case gamma = 0.01 ------------------------------------------------------
    t_g, best_g = bench_ours(exc, GAMMA_POSED, repeat)
    p_g = best_g.power
    p_check = solve_fourier(exc, 2 * HARMONICS, GAMMA_POSED)[0].power
    rows.append(Row(f"parapend solve_fourier N={HARMONICS}", t_g, p_g, 0.0, 1.0, GAMMA_POSED,
                    [f"gamma={GAMMA_POSED:g}: N={HARMONICS} is converged, N={2 * HARMONICS} "
                     f"differs by {abs(p_check - p_g):.1e}; median of {repeat}"]))
    c = casadi_row(GAMMA_POSED, t_g, p_g, "same continuous problem; gap = O(h^2) error")
    if c is not None and c["success"]:
        gap = abs(c["power"] - p_g)
        n_match = matched_harmonics(exc, GAMMA_POSED, p_g, gap, HARMONICS)
        t_m, best_m = bench_ours(exc, GAMMA_POSED, repeat, n_match)
        rows.append(Row(f"parapend solve_fourier N={n_match} (CasADi's accuracy)", t_m,
                        best_m.power, abs(best_m.power - p_g), t_m / t_g, GAMMA_POSED,
                        [f"smallest N within CasADi's gap of the converged optimum; "
                         f"CasADi time / this time = {c['time_s'] / t_m:.3g}"]))

    # -- threshold -------------------------------------------------------------------------
    t_thr, thr = median_time(lambda: parapend.threshold(omega=OMEGA, delta=DELTA),
                             max(5, repeat // 10))
    rows.append(Row("parapend.threshold() -> gamma*", t_thr, None, None, t_thr / t_ours, 0.0,
                    [f"damping threshold gamma* = {thr.damping_threshold:.10f} "
                     f"(paper: 0.0856), N={thr.harmonics}; target <= 50 ms"]))

    print_table(rows, info)
    if args.json:
        payload = {"machine": info, "harmonics": HARMONICS, "intervals": INTERVALS,
                   "repeat": repeat, "peer_repeat": peer_repeat, "nm_budget_s": nm_budget,
                   "rows": [asdict(r) for r in rows]}
        with open(args.json, "w") as fh:
            json.dump(payload, fh, indent=2, default=_json_default)
        print(f"\nwrote {args.json}")
    return 0


def _json_default(obj):
    if isinstance(obj, np.generic):
        return obj.item()
    return str(obj)


if __name__ == "__main__":
    sys.exit(main())
