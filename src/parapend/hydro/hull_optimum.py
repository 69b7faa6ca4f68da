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

__all__ = ["HARMONICS_PER_TURN", "HullSolution", "aliased", "hull_search", "make_case",
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


def aliased(problem: HullProblem, x) -> bool:
    """True when the power at ``x`` on a grid four times finer differs by more than
    ``ALIAS_TOL`` (relative): the grid's mean has become aliasing (large coefficients push
    the harmonics of ``sin(phi)`` past the grid's Nyquist frequency), not a power."""
    fine = HullProblem(dataclasses.replace(problem.case, points=4 * problem.case.points),
                       coupled=problem.coupled)
    p, pf = problem.power(x), fine.power(x)
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


def hull_search(make, *, refine: bool = True) -> HullSolution:
    """The best coupled maximum over the starts, with the one-way answer beside it.

    ``make(scale)`` returns the :class:`HullCase` with ``scale`` times the default
    harmonics (1, and 2 for the refinement)."""
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

    while scale < MAX_SCALE and 2 * scale * sol.case.harmonics <= max(
            HULL_MAX_REFINED_HARMONICS, 2 * sol.case.harmonics):
        scale *= 2
        case = make(scale)
        pr = HullProblem(case)
        r = newton_maximize(pr, _pad(x, case.harmonics), "refined", gtol=GTOL)
        if r.status != "converged":
            status, ok = f"refinement to {case.harmonics} harmonics: {r.status}", False
        change = abs(r.power - power)
        x, power = r.x, float(r.power)
        if change <= REFINE_TOL * max(abs(power), 1e-300):
            break
    if change > UNRESOLVED * max(abs(power), 1e-300):
        status = (f"not resolved: {case.harmonics} harmonics still change the power by "
                  f"{change:.3g} W")
        ok = False
    pr = HullProblem(case)
    _, _, resid = pr.balance(x)
    one = HullProblem(case, coupled=False)
    r1 = newton_maximize(one, _pad(sol.one_way_x, case.harmonics), "one-way", gtol=GTOL)
    return dataclasses.replace(sol, case=case, x=x, power=power, status=status, success=ok,
                               refinement_change=float(change),
                               energy_balance_residual=float(resid),
                               one_way_power=float(r1.power), one_way_x=r1.x)


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
