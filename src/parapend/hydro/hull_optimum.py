"""The optimum of a pendulum in a surging, heaving, pitching hull (:mod:`.hull`): a global
search over starts, one winding at a time, and the checks every answer carries.

The search (issue 30 expects several local optima): the one-way problem (the hull moving
as if the pendulum were not there; no linear solve per evaluation) is maximized from a set
of starts (K = 0: mean angles around hanging and away from it, phases and amplitudes of the
swing; K >= 1: phase offsets of the turn), then the coupled problem from every distinct
one-way maximum and from the same starts; the best converged maximum wins, and how many
distinct maxima were found is reported (the evidence). The answer is then solved once more
with twice the harmonics (and twice the hull's), from the answer: the change of the power
is the stated discretization error (``refinement_change_w``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from ..optimal.fourier import DISTINCT_RMS, _pad, motion_distance, newton_maximize
from .hull import HullCase, HullProblem, hull_points

__all__ = ["HARMONICS_PER_TURN", "HullPTO", "HullSolution", "aliased", "hull_search", "make_case",
           "radiation_bound", "waves_in"]

#: harmonics of phi per turn (K >= 1) or per wave (K = 0) by default
HARMONICS_PER_TURN = 12
#: the Newton iterations' gradient tolerance, relative to m g l w
GTOL = 1e-10
#: the harmonics are doubled until the power changes by at most this (relative), up to
#: MAX_SCALE times the default
REFINE_TOL = 1e-7
#: a change above this (relative) at the most harmonics allowed is not an answer
UNRESOLVED = 1e-3
MAX_SCALE = 8
#: relative change of the power at a maximum on a grid four times finer above which the
#: maximum is rejected as aliased (the grid's mean of an unresolved motion)
ALIAS_TOL = 1e-8
#: singular values of B_k below this fraction of the largest are cut in the bound's
#: pseudo-inverse (B's surge-pitch block is near singular: both radiate the same waves)
BOUND_RCOND = 1e-8


def make_case(hull, pendulum, wave, *, winding, harmonics=None, hull_harmonics=None,
              pivot=(0.0, 0.0), pitch_inertia=None) -> HullCase:
    """The discretized problem: the hull's coefficients at ``k w`` (k = 0..Nh), its mass
    matrix without the pendulum, the wave's amplitudes."""
    n = harmonics or HARMONICS_PER_TURN * max(1, winding, waves_in(wave))
    nh = hull_harmonics or n + max(1, winding)
    w = wave.omega
    kk = np.arange(nh + 1) * w
    a, b, f = hull.coefficients(kk)
    mh = hull.mass_matrix(pendulum.mass, pitch_inertia)
    c = np.asarray(hull.hydrostatic_stiffness, float)
    c55 = float(c[2, 2]) - pendulum.mass * float(hull.g) * float(pivot[1])
    if not c55 > 0:
        top = float(c[2, 2]) / (pendulum.mass * float(hull.g))
        raise ParameterError(
            f"pivot-height: with the pendulum's {pendulum.mass:g} kg at {pivot[1]:g} m the "
            f"hull is unstable in pitch (C55 = {float(c[2, 2]):.4g} - m g h_p = {c55:.4g} "
            f"N m/rad <= 0); lower the pivot (below {top:.4g} m) "
            "or the pendulum's mass")
    return HullCase(omega=w, amplitudes=wave.amplitudes, winding=int(winding), harmonics=n,
                    hull_harmonics=nh, points=hull_points(n, nh, winding,
                                                          wave.amplitudes.size),
                    A=np.asarray(a, float), B=np.asarray(b, float), F=np.asarray(f, complex),
                    C=np.asarray(hull.hydrostatic_stiffness, float), Mh=mh, m=pendulum.mass,
                    l=pendulum.length, I=pendulum.inertia, c=pendulum.damping_coefficient,
                    g=float(hull.g), pivot=tuple(float(v) for v in pivot))


def waves_in(wave) -> int:
    """The wave's mean harmonic (energy-weighted): 1 for a regular wave, about the number
    of waves in a record."""
    a = np.abs(np.asarray(wave.amplitudes)) ** 2
    k = np.arange(1, a.size + 1)
    return max(1, int(round(float(np.sum(k * a) / np.sum(a)))))


def _starts(n: int, winding: int) -> list[tuple[str, np.ndarray]]:
    out = []
    if winding == 0:
        for mean in (math.pi, math.pi - 1.0, math.pi + 1.0):
            for amp in (0.5, 1.5):
                for j in range(4):
                    x = np.zeros(2 * n + 1)
                    x[0] = mean
                    ph = j * math.pi / 2
                    x[1], x[n + 1] = amp * math.cos(ph), amp * math.sin(ph)
                    out.append((f"swing-{mean:.2f}-{amp:g}-{j}", x))
    else:
        for j in range(8):
            x = np.zeros(2 * n + 1)
            x[0] = j * math.pi / 4
            out.append((f"phase-{j}", x))
    return out


@dataclass(frozen=True)
class HullPTO:
    """The power take-off of the hull problem (SI): ``efficiency`` ``(eta_g, eta_m)`` or
    None, ``copper_loss`` ``r`` of the winding loss ``r tau^2`` (W per (N m)^2), and
    ``torque_limit`` (N m) or None. Inactive (all absent): the ideal, lossless PTO."""

    efficiency: tuple | None = None
    copper_loss: float = 0.0
    torque_limit: float | None = None

    @property
    def active(self) -> bool:
        return (self.efficiency is not None and tuple(self.efficiency) != (1.0, 1.0)) or \
            self.copper_loss > 0 or self.torque_limit is not None

    @property
    def smoothed(self) -> bool:
        """The objective has the efficiency's kink (a continuation in its smoothing)."""
        return self.efficiency is not None and self.efficiency[0] * self.efficiency[1] != 1

    def problem(self, case: HullCase, coupled: bool = True) -> HullProblem:
        return HullProblem(case, coupled=coupled, eta=self.efficiency if self.smoothed
                           else None, copper_loss=self.copper_loss)


@dataclass(frozen=True, eq=False)
class HullSolution:
    """One winding's optimum on one discretization (SI)."""

    case: HullCase = field(repr=False)
    x: np.ndarray = field(repr=False)
    power: float
    one_way_power: float
    one_way_x: np.ndarray = field(repr=False)
    status: str
    success: bool
    found_by: str
    distinct_maxima: int
    runs: int
    iterations: int
    energy_balance_residual: float
    refinement_change: float | None = None
    #: the mechanical power ``<-tau (phi' - beta')>`` (= ``power`` for an ideal PTO)
    mechanical_power: float | None = None
    pto: HullPTO = HullPTO()


def aliased(problem: HullProblem, x) -> bool:
    """True when the power at ``x`` on a grid four times finer differs by more than
    ``ALIAS_TOL`` (relative): the grid's mean has become aliasing (large coefficients push
    the harmonics of ``sin(phi)`` past the grid's Nyquist frequency), not a power."""
    fine = HullProblem(dataclasses.replace(problem.case, points=4 * problem.case.points),
                       coupled=problem.coupled)
    # the mechanical power, a smooth function of the motion, also under a PTO (whose
    # kink the finer grid integrates differently: that is the refinement's business)
    p, pf = problem.mechanical(x), fine.mechanical(x)
    return not abs(p - pf) <= ALIAS_TOL * max(abs(pf), float(problem.w[0]))


def _search(problem: HullProblem, seeds, gtol: float):
    runs = []
    best = None
    for name, x0 in seeds:
        r = newton_maximize(problem, x0, name, gtol=gtol, maxiter=200,
                            abandon_below=(best.power if best is not None else -math.inf))
        if r.status == "converged" and aliased(problem, r.x):
            r = dataclasses.replace(r, status="aliased")
        runs.append(r)
        if math.isfinite(r.power) and r.status == "converged" and (
                best is None or r.power > best.power):
            best = r
    return best, runs


def _distinct(runs, best) -> int:
    seen = []
    for r in runs:
        if r.status != "converged" or not math.isfinite(r.power):
            continue
        if all(motion_distance(r.x, s.x) > 1e3 * DISTINCT_RMS for s in seen):
            seen.append(r)
    return max(1, len(seen)) if best is not None else 0


def hull_search(make, *, refine: bool = True, pto: HullPTO | None = None) -> HullSolution:
    """The best coupled maximum over the starts, with the one-way answer beside it.

    ``make(scale)`` returns the :class:`HullCase` with ``scale`` times the default
    harmonics (1, and 2 for the refinement). With an active ``pto`` the ideal search's
    distinct maxima start the PTO's optimum (:func:`_pto_stage`)."""
    case = make(1)
    n, kw = case.harmonics, case.winding
    one = HullProblem(case, coupled=False)
    starts = _starts(n, kw)
    best_one, runs_one = _search(one, starts, GTOL)
    coupled = HullProblem(case)
    seeds = []
    if best_one is not None:
        for r in sorted((r for r in runs_one if r.status == "converged"),
                        key=lambda r: -r.power):
            if all(motion_distance(r.x, s[1]) > 1e3 * DISTINCT_RMS for s in seeds):
                seeds.append((f"one-way:{r.seed}", r.x))
    best, runs = _search(coupled, seeds + starts, GTOL)
    if best is None:
        best = max(runs, key=lambda r: r.power if math.isfinite(r.power) else -math.inf)
        status, ok = f"no start converged (best: {best.status})", False
    else:
        status, ok = "converged", True
    if pto is not None and pto.active:
        return _pto_stage(case, make, pto, runs, best_one, refine)
    _, _, resid = coupled.balance(best.x)
    sol = HullSolution(case=case, x=best.x, power=float(coupled.power(best.x)),
                       one_way_power=float(best_one.power) if best_one else math.nan,
                       one_way_x=best_one.x if best_one else starts[0][1], status=status,
                       success=ok, found_by=best.seed, distinct_maxima=_distinct(runs, best),
                       runs=len(runs) + len(runs_one),
                       iterations=sum(r.iterations for r in runs + runs_one),
                       energy_balance_residual=float(resid))
    if refine and ok:
        sol = _refine(sol, make, best.x)
    return sol


def _refine(sol: HullSolution, make, x) -> HullSolution:
    """Double the harmonics (of phi and of the hull), from the answer, until the power
    changes by at most ``REFINE_TOL`` (relative) or ``MAX_SCALE`` is reached: the finest
    answer is returned, with its change from the one before as the stated error."""
    scale, power, case = 1, sol.power, sol.case
    status, ok = sol.status, sol.success
    change = math.inf
    from ..limits import HULL_MAX_REFINED_HARMONICS

    pto = sol.pto
    x1, p1 = sol.one_way_x, sol.one_way_power
    top = PTO_MAX_SCALE if pto.active else MAX_SCALE
    while scale < top and 2 * scale * sol.case.harmonics <= max(
            HULL_MAX_REFINED_HARMONICS, 2 * sol.case.harmonics):
        scale *= 2
        case = make(scale)
        if pto.active:
            pr = pto.problem(case)
            xr, pr_power, st, _ = _pto_maximize(pr, _pad(x, case.harmonics), pto, False)
            # the one-way answer follows, doubling by doubling
            x1, p1, _, _ = _pto_maximize(pto.problem(case, coupled=False),
                                         _pad(x1, case.harmonics), pto, False)
        else:
            pr = HullProblem(case)
            r = newton_maximize(pr, _pad(x, case.harmonics), "refined", gtol=GTOL)
            xr, pr_power, st = r.x, r.power, r.status
        if st != "converged":
            status, ok = f"refinement to {case.harmonics} harmonics: {st}", False
        elif pto.active:  # the answer is the finest stage's, and so is its status
            status, ok = "converged", True
        change = abs(pr_power - power)
        x, power = xr, float(pr_power)
        if change <= (PTO_REFINE_TOL if pto.active else REFINE_TOL) * max(abs(power),
                                                                          1e-300):
            break
    if change > UNRESOLVED * max(abs(power), 1e-300):
        if pto.active:  # algebraic convergence (the kink, the limit's corners): stated
            status = (f"{status}; the last doubling to {case.harmonics} harmonics changed "
                      f"the power by {change:.3g} W")
        else:
            status = (f"not resolved: {case.harmonics} harmonics still change the power by "
                      f"{change:.3g} W")
            ok = False
    pr = HullProblem(case)
    _, _, resid = pr.balance(x)
    if pto.active:
        mech = float(pr.mechanical(x))
    else:
        r1 = newton_maximize(HullProblem(case, coupled=False),
                             _pad(sol.one_way_x, case.harmonics), "one-way", gtol=GTOL)
        x1, p1, mech = r1.x, r1.power, None
    return dataclasses.replace(sol, case=case, x=x, power=power, status=status, success=ok,
                               refinement_change=float(change),
                               energy_balance_residual=float(resid),
                               one_way_power=float(p1), one_way_x=x1, mechanical_power=mech)


#: distinct ideal maxima that start the PTO's optimum
PTO_STARTS = 4
#: change of the exact objective over the continuation's last two widths, relative to the
#: larger of it and the pendulum's power scale ``m g l w``, below which it counts as settled
#: (the kink's last widths move it by the grid's resolution of the kink; the refinement
#: states the error)
PTO_SETTLED = 1e-5
#: with a PTO the harmonics are doubled until the objective changes by at most this
#: (relative): the kink of the electrical power and the limit's active arcs make the
#: convergence algebraic, not spectral
PTO_REFINE_TOL = 1e-4
#: ... up to this many times the default harmonics (each doubling of a torque-limited solve
#: costs about four times the one before); a larger last change is stated in the status
PTO_MAX_SCALE = 4


def _free_motion(case: HullCase, winding: int, coupled: bool = True):
    """The motion of least mean squared torque (``max -<tau^2>`` from the pendulum hanging,
    or from each quarter-turn phase of the turn): the free pendulum's periodic motion where
    one exists. It satisfies any torque limit it meets and costs no copper loss, so it
    starts the PTO's optimum where the ideal maxima, with their large torques, are far from
    what the limit or the loss allows."""
    from .pto import maximize

    pr = HullProblem(case, coupled=coupled, copper_loss=1.0)
    pr.a = 0.0  # the objective is -<tau^2> alone
    out = []
    for name, x0 in _starts(case.harmonics, winding)[:: 6 if winding == 0 else 2]:
        if winding == 0:
            x0 = np.zeros_like(x0)
            x0[0] = math.pi
            name = "hanging"
        x, ex, _ = maximize(pr, x0, (1.0,))
        if math.isfinite(ex):
            out.append((f"least-torque:{name}", x))
        if winding == 0:
            break
    return out


#: Newton iterations per width of a torque-limited solve from one start: from an ideal
#: maximum far above the limit the augmented Lagrangian crawls (thousands of iterations,
#: tens of seconds), while the least-torque start reaches the same optimum in a few hundred
PTO_MAX_INNER = 400


def _pto_maximize(pr: HullProblem, x, pto: HullPTO, first: bool):
    """The PTO's optimum from ``x``: the smoothing continuation (an efficiency) under the
    torque limit (:func:`parapend.hydro.pto.maximize`). Returns ``(x, exact, status,
    iterations)``."""
    from .pto import WIDTHS, WIDTHS_REFINE, maximize

    widths = (WIDTHS if first else WIDTHS_REFINE) if pto.smoothed else (1.0,)
    x, ex, log = maximize(pr, np.asarray(x, dtype=float), widths, pto.torque_limit,
                          max_inner=PTO_MAX_INNER)
    its = sum(r[3] for r in log)
    last = [r[1] for r in log if math.isfinite(r[1])]
    if not math.isfinite(ex):
        return x, ex, "no motion within the torque limit", its
    if pto.smoothed:
        scale = max(abs(ex), float(pr.w[0]))  # the power, or m g l w near zero
        ok = len(last) >= 2 and abs(last[-1] - last[-2]) <= PTO_SETTLED * scale
    else:
        ok = log[-1][2] == "converged"
    return x, ex, "converged" if ok else f"stalled ({log[-1][2]})", its


def _pto_stage(case, make, pto: HullPTO, runs, best_one, refine: bool) -> HullSolution:
    """The PTO's optimum (efficiency, copper loss, torque limit) from the ideal search's
    distinct converged maxima (at most ``PTO_STARTS``, best first), then its refinement."""
    seeds = []
    for r in sorted((r for r in runs if math.isfinite(r.power) and r.status in (
            "converged", "max_iterations", "stalled")), key=lambda r: -r.power):
        if all(motion_distance(r.x, s[1]) > 1e3 * DISTINCT_RMS for s in seeds):
            seeds.append((r.seed, r.x))
        if len(seeds) == PTO_STARTS:
            break
    seeds += _free_motion(case, case.winding)
    pr = pto.problem(case)
    best, tried, its = None, [], 0
    for name, x0 in seeds:
        x, ex, status, it = _pto_maximize(pr, x0, pto, True)
        its += it
        if status == "converged" and aliased(pr, x):
            status = "aliased"
        tried.append((ex, status))
        # every iterate is a motion whose power is evaluated exactly: the largest wins, and
        # its status says whether its continuation settled
        if math.isfinite(ex) and (best is None or ex > best[1]):
            best = (x, ex, status, name)
    one_pr = pto.problem(case, coupled=False)
    one = None
    for x1 in ([best_one.x] if best_one is not None else []) + [
            x for _, x in _free_motion(case, case.winding, coupled=False)]:
        r = _pto_maximize(one_pr, x1, pto, True)
        its += r[3]
        if one is None or (math.isfinite(r[1]) and not r[1] <= one[1]):
            one = r
    if best is None:
        x = seeds[0][1] if seeds else np.zeros(2 * case.harmonics + 1)
        return HullSolution(case=case, x=x, power=math.nan, one_way_power=math.nan,
                            one_way_x=x, status="no motion found for this power take-off",
                            success=False, found_by="", distinct_maxima=0, runs=len(tried),
                            iterations=its, energy_balance_residual=math.nan, pto=pto)
    x, ex, status, name = best
    ok = status == "converged"
    distinct = len({round(e, 9) for e, st in tried if st == "converged"})
    sol = HullSolution(case=case, x=x, power=float(ex),
                       one_way_power=float(one[1]) if one else math.nan,
                       one_way_x=one[0] if one else x, status=status, success=ok,
                       found_by=name, distinct_maxima=max(distinct, 1),
                       runs=len(tried) + 1, iterations=its,
                       energy_balance_residual=float(HullProblem(case).balance(x)[2]),
                       mechanical_power=float(pr.mechanical(x)), pto=pto)
    if refine:  # a stalled continuation may settle with more harmonics: the status says
        sol = _refine(sol, make, x)
    return sol


def radiation_bound(case: HullCase) -> tuple[float, int]:
    """``sum_k (F a)_k^H B_k^+ (F a)_k / 8`` (W) and the number of singular values cut
    (below ``BOUND_RCOND`` of the largest, per harmonic): no mechanism inside the hull
    absorbs more."""
    fa = case.wave_force()
    total, cut = 0.0, 0
    for k in range(1, case.hull_harmonics + 1):
        if not np.any(fa[k]):
            continue
        b = 0.5 * (case.B[k] + case.B[k].T)
        sv = np.linalg.svd(b, compute_uv=False)
        if sv[0] <= 0:
            continue
        cut += int(np.sum(sv < BOUND_RCOND * sv[0]))
        binv = np.linalg.pinv(b, rcond=BOUND_RCOND)
        total += float(np.real(np.vdot(fa[k], binv @ fa[k]))) / 8.0
    return total, cut
