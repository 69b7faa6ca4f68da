"""Design questions in one call: the best pendulum for a buoy and a sea, and power against
wave period (docs/buoy.md).

:func:`optimize_design` is an outer bounded search over pendulum parameters around the
inner exact coupled optimum: a small grid over the box (the inner optimum is a global search
of its own, but the outer objective can have several maxima: a light pendulum that rotates
easily against a heavy one that loads the buoy), then a bounded polish from the best grid
point (``minimize_scalar`` on one variable, Nelder-Mead within the bounds on several). The
physical pendulum has ``I >= m l^2``: where the box holds ``I < m l^2`` the design is the point
mass, ``I = m l^2`` (reported as the inertia used).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from ..results import _Result
from .result import BuoySweepResult, optimum

__all__ = ["DesignResult", "optimize_design", "period_sweep"]

#: grid points per variable before the polish, by the number of variables
GRID = {1: 7, 2: 5, 3: 3, 4: 3}

#: inner solves of the polish at most, by the number of variables (bounded Brent on one: at
#: about 25 with its tolerance; Nelder-Mead: its ``maxfev`` of 40 per variable)
POLISH = {1: 25, 2: 80, 3: 120, 4: 160}


def design_solves(count: int) -> int:
    """The inner solves of a search over ``count`` variables at most (the grid and the
    polish): the estimate ``parapend buoy`` checks and the progress bar counts."""
    return GRID[count] ** count + POLISH[count]


#: a best value within this fraction of its box's width from a bound lies on the bound
BOUND_TOL = 1e-3


@dataclass(frozen=True, eq=False)
class DesignResult(_Result):
    """The best pendulum within the bounds (SI units).

    Attributes
    ----------
    variables : the parameters searched; bounds : their ``[lo, hi]``.
    best : the best design, every pendulum parameter (``inertia`` the one used, at least
        ``m l^2``); power_w : the coupled optimum there.
    evaluations : inner optima solved; grid_best_w : the best on the grid before the polish.
    failed : inner solves that did not succeed (counted as no power).
    at_bound : ``{name: "lower" | "upper"}`` for each variable whose best value lies on a
        bound of its box (within 1e-3 of the box's width): the search stopped there, and
        the best design may lie beyond it (widen the bounds).
    status, message : ``"ok"``, or ``"time_limit"`` when the time limit stopped the search
        (``best`` is then the best of the ``evaluations`` made, of at most ``total``).
    total : the inner solves the whole search makes at most (``design_solves``).
    """

    variables: list
    bounds: dict
    best: dict
    power_w: float
    grid_best_w: float
    evaluations: int
    failed: int
    method: str
    at_bound: dict = dataclasses.field(default_factory=dict)
    status: str = "ok"
    message: str = ""
    total: int = 0
    _pendulum: object = dataclasses.field(default=None, repr=False)

    @property
    def pendulum(self):
        """The best design as a :class:`~parapend.hydro.coupled.Pendulum`."""
        return self._pendulum


def _physical(pend, names, x):
    kw = {n: float(v) for n, v in zip(names, x)}
    m, length = kw.get("mass", pend.mass), kw.get("length", pend.length)
    ml2 = m * length ** 2
    if "inertia" not in names:
        # the pendulum keeps its shape: I scales with m l^2 when they change
        kw["inertia"] = pend.inertia / (pend.mass * pend.length ** 2) * ml2
    else:
        kw["inertia"] = max(kw["inertia"], ml2)
    return dataclasses.replace(pend, **kw)


class _TimeUp(Exception):
    """The search's time limit ran out (raised between two inner solves)."""


def optimize_design(solve, pendulum, variables, bounds, *, check=None,
                    progress=None, deadline=None) -> DesignResult:
    """The pendulum parameters ``variables`` (within ``bounds``) that maximize the coupled
    power ``solve(pendulum).power``.

    Parameters
    ----------
    solve : callable
        ``solve(Pendulum) -> CoupledSolution``, the inner exact optimum.
    pendulum : Pendulum
        The fixed parameters (and the starting design).
    variables : sequence of str
        Names among ``mass``, ``length``, ``inertia``, ``damping_coefficient``.
    bounds : dict
        ``name -> (lo, hi)``.
    check : callable or None
        ``check(Pendulum)`` raising ParameterError for a design out of reach (a pendulum
        heavier than the body); such designs count as no power.
    progress : callable or None
        Called ``progress(done, total)`` after every inner solve (``total`` the most the
        search makes, ``design_solves``), and ``progress(total, total)`` at the end.
    deadline : float or None
        A ``time.monotonic`` time (:func:`parapend.deadline.deadline`): once it has
        passed, the search stops before its next inner solve (once a design that harvests
        power is found) and returns the best design evaluated, with ``status``
        ``"time_limit"``.
    """
    from scipy.optimize import minimize, minimize_scalar

    from ..deadline import expired
    from ..errors import ParameterError

    names = list(variables)
    lo = np.array([bounds[n][0] for n in names], dtype=float)
    hi = np.array([bounds[n][1] for n in names], dtype=float)
    cache: dict = {}
    points: dict = {}  # the designs evaluated (box coordinates), by the cache's key
    failed = [0]
    total = design_solves(len(names))

    def power(u):
        u = np.clip(np.asarray(u, dtype=float), 0.0, 1.0)
        key = tuple(np.round(u, 12))
        if key in cache:
            return cache[key]
        if expired(deadline) and any(v > 0 for v in cache.values()):
            raise _TimeUp  # (a design that harvests power is found first: it is the answer)
        p = _physical(pendulum, names, lo + u * (hi - lo))
        try:
            if check is not None:
                check(p)
            sol = solve(p)
            # with an efficiency the electrical optimum's electrical power
            elec = getattr(sol, "electrical_power", None)
            best = sol.power if elec is None else elec
            val = float(best) if sol.success else -math.inf
            if not sol.success:
                failed[0] += 1
        except ParameterError:
            val = -math.inf
        cache[key] = val
        points[key] = u
        if progress is not None:
            progress(min(len(cache), total - 1), total)
        return val

    g = GRID[len(names)]
    try:
        u0, grid_best, cand, method = _search(power, names, g, minimize, minimize_scalar)
        best_u = max([u0, *cand], key=lambda u: power(u))
        status, message = "ok", ""
    except _TimeUp:
        vals = {k: v for k, v in cache.items() if math.isfinite(v) and v > 0}
        if not vals:
            raise ParameterError(f"time-limit: no design that harvests power was found in "
                                 f"the time limit ({len(cache)} of at most {total} inner "
                                 "solves); give a longer --time-limit") from None
        key = max(vals, key=vals.get)
        best_u = points[key]
        grid_best = max(vals.values())
        method = f"grid of {g}^{len(names)}, stopped by the time limit"
        status = "time_limit"
        message = (f"time limit reached after {len(cache)} of at most {total} inner solves: "
                   "the best design evaluated, not the search's optimum")
    best_u = np.clip(best_u, 0, 1)
    p = _physical(pendulum, names, lo + best_u * (hi - lo))
    at_bound = {n: ("lower" if u <= BOUND_TOL else "upper") for n, u in zip(names, best_u)
                if u <= BOUND_TOL or u >= 1 - BOUND_TOL}
    if progress is not None:
        progress(total, total)
    return DesignResult(
        variables=names, bounds={n: [float(a), float(b)] for n, a, b in zip(names, lo, hi)},
        best={"mass_kg": p.mass, "length_m": p.length, "inertia_kg_m2": p.inertia,
              "damping_coefficient_nm_s_per_rad": p.damping_coefficient},
        power_w=power(best_u), grid_best_w=grid_best, evaluations=len(cache),
        failed=failed[0], method=method, at_bound=at_bound, status=status, message=message,
        total=total, _pendulum=p)


def _search(power, names, g, minimize, minimize_scalar):
    """The grid over the box, then the polish from its best point: ``(u0, grid_best,
    candidates, method)`` (box coordinates in [0, 1])."""
    from ..errors import ParameterError

    axes = [np.linspace(0.0, 1.0, g)] * len(names)
    grid = np.array(np.meshgrid(*axes, indexing="ij")).reshape(len(names), -1).T
    vals = np.array([power(u) for u in grid])
    if not np.isfinite(vals).any() or np.max(vals) <= 0:
        raise ParameterError("optimize-design: no design within the bounds harvests power; "
                             "widen the bounds")
    u0 = grid[int(np.argmax(vals))]
    grid_best = float(np.max(vals))

    def neg(u):
        v = power(u)
        return -v if math.isfinite(v) else 1e300

    if len(names) == 1:
        step = 1.0 / (g - 1)
        a, b = max(0.0, u0[0] - step), min(1.0, u0[0] + step)
        r = minimize_scalar(lambda s: neg([s]), bounds=(a, b), method="bounded",
                            options={"xatol": 1e-4})
        cand = [np.array([r.x])]
        method = f"grid of {g}, then bounded Brent"
    else:
        r = minimize(neg, u0, method="Nelder-Mead", bounds=[(0.0, 1.0)] * len(names),
                     options={"xatol": 1e-4, "fatol": 1e-9, "maxfev": 40 * len(names),
                              "initial_simplex": _simplex(u0, 0.5 / (g - 1))})
        cand = [np.asarray(r.x)]
        method = f"grid of {g}^{len(names)}, then Nelder-Mead within the bounds"
    return u0, grid_best, cand, method


def _simplex(u0, step):
    n = u0.size
    pts = [u0.copy()]
    for i in range(n):
        v = u0.copy()
        v[i] = v[i] + step if v[i] + step <= 1 else v[i] - step
        pts.append(v)
    return np.array(pts)


def period_sweep(hydro, width, pendulum, height, periods, *, winding=1, harmonics=None,
                 torque_limit=None, efficiency=None, coarse=None, geometry=None,
                 deadline=None):
    """Coupled and one-way optima of one design in regular waves of height ``height`` (m)
    over ``periods`` (s): a :class:`~parapend.hydro.result.BuoySweepResult`. Each period is
    solved as alone (the same body, mesh and frequencies); ``coarse`` (the body on the
    error estimate's mesh, or None) gives ``mesh_error_w``, ``geometry`` (draft and
    freeboard, or None) the validity checks. ``deadline`` (a ``time.monotonic`` time,
    :func:`parapend.deadline.deadline`): once it has passed, the periods not yet begun (all
    but the first at least) are left out, NaN with the status ``"time_limit"``, and the
    sweep is no success."""
    from ..deadline import TIME_LIMIT, expired
    from .coupled import Wave
    from .hull import HullPTO

    pto = HullPTO(efficiency=efficiency, torque_limit=torque_limit)
    rows = []
    for period in periods:
        if rows and expired(deadline):
            break
        wave = Wave.regular(height, float(period))
        info = {"kind": "regular", "height_m": height, "period_s": float(period)}
        rows.append(optimum(hydro, pendulum, wave, wave_info=info, winding=winding,
                            harmonics=harmonics, pto=pto, geometry=geometry, width=width,
                            coarse=coarse))

    left = len(periods) - len(rows)  # periods the time limit left out

    def col(name):
        return np.array([np.nan if getattr(r, name) is None else getattr(r, name)
                         for r in rows] + [np.nan] * left, dtype=float)

    above = sum(1 for r in rows if r.warnings)
    notes = ([f"at {above} of {len(rows)} periods, harmonics of the motion lie above the "
              f"dataset's highest frequency {float(max(hydro.omega)):.4g} rad/s: there A is "
              "held and B = F = 0 (each period's note: the results in _results)"]
             if above else [])
    if left:
        notes.append(f"time limit reached: {len(rows)} of {len(periods)} periods solved, the "
                     f"other {left} left out (NaN, status {TIME_LIMIT}); a partial sweep")
    return BuoySweepResult(
        period_s=np.asarray(periods, dtype=float), power_w=col("power_w"),
        one_way_power_w=col("one_way_power_w"), radiation_bound_w=col("radiation_bound_w"),
        limit_w=col("limit_w"), bound_fraction=col("bound_fraction"),
        capture_width_m=col("capture_width_m"), heave_amplitude_m=col("heave_amplitude_m"),
        free_heave_amplitude_m=col("free_heave_amplitude_m"),
        energy_balance_residual=col("energy_balance_residual"),
        status=[r.status for r in rows] + [TIME_LIMIT] * left,
        success=not left and all(r.success for r in rows),
        wave_height_m=height, pendulum=rows[0].pendulum, body=rows[0].body, warnings=notes,
        _results=tuple(rows),
        electrical_power_w=None if efficiency is None else col("electrical_power_w"),
        mechanical_power_w=None if efficiency is None else col("mechanical_power_w"),
        mesh_error_w=None if coarse is None else col("mesh_error_w"),
        grid_error_w=col("grid_error_w"),
        validity_warnings=[f"T = {r.wave['period_s']:g} s: {w}" for r in rows
                           for w in r.validity_warnings])
