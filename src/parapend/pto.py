"""A realistic power take-off from Python: torque limit, efficiency, physical units.

Mirrors ``parapend optimize --torque-limit/--efficiency...`` and ``parapend pto-curve``::

    import parapend.pto as pto
    r = pto.optimize_pto(gamma=0.03, torque_limit=2.5, efficiency=0.9)
    r.power, r.electrical_power, r.peak_torque
    ds = pto.pto_curve(vary="torque-limit", gamma=0.03)

Two methods, both warm-started from the ideal optimum of :func:`parapend.optimize`:

- a torque limit (alone or with a copper loss): :mod:`parapend.optimal.hermite`, the motion
  as K cubic Hermite intervals and a primal-dual interior point on the banded Newton
  system (the optimal torque is bang-bang: a local basis resolves its jumps, a Fourier
  series does not); K from the excitation, checked by one doubling;
- an efficiency (with or without a limit), or a copper loss without a limit:
  :mod:`parapend.optimal.collocation`, Hermite-Simpson collocation with the torque as an
  unknown (the efficiency exact through two slacks per point) and a full-space primal-dual
  interior point on the banded KKT system; K from the excitation, checked by one doubling.

Under a torque limit without a copper loss, where either fails or comes within 10 % of the
bound ``T_max K omega`` of every monotone rotation, the constant brake
(:mod:`parapend.optimal.brake`) is tried, and returned when it is at least as good. An
efficiency of 1 both ways is no efficiency: the problem is solved as without one.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from . import limits
from .api import _coefficients, build_excitation, optimize
from .errors import ParameterError, SolverError, check_finite, check_int, check_range
from .optimal.profile import PTOSolution, pto_profile
from .power import uniform_power
from .style import figure_style
from .trajectory import FourierMotion

__all__ = ["VARY", "efficiencies", "optimize_pto", "physical_fields", "pto_curve",
           "uniform_under_pto"]

VARY = ("torque-limit", "efficiency")


def efficiencies(efficiency=None, efficiency_generating=None, efficiency_motoring=None):
    """``(eta_g, eta_m)`` from the options, or None when none is given; each in (0, 1]."""
    if efficiency is None and efficiency_generating is None and efficiency_motoring is None:
        return None
    base = 1.0 if efficiency is None else _eta("efficiency", efficiency)
    eg = base if efficiency_generating is None else _eta("efficiency-generating",
                                                         efficiency_generating)
    em = base if efficiency_motoring is None else _eta("efficiency-motoring",
                                                       efficiency_motoring)
    return eg, em


def _lossy(eff):
    """``eff`` when it loses power, None when it is None or 1 both ways (lossless: the
    problem without an efficiency, solved by the same method)."""
    return None if eff is None or eff == (1.0, 1.0) else eff


def _eta(name, value) -> float:
    x = check_finite(name, value)
    if not 0.0 < x <= 1.0:
        raise ParameterError(f"{name}: expected a number in (0, 1] (a fraction of the power "
                             f"converted), got {value!r}")
    return x


def _torque_limit(value):
    if value is None:
        return None
    return check_range("torque-limit", value, limits.MIN_TORQUE_LIMIT, limits.MAX_TORQUE_LIMIT,
                       why="units m g l; below, the limit is under the rounding of the "
                           "torque's evaluation; see docs/limits-of-input.md")


def _check_warm(warm):
    """``warm`` as given (None, or a motion with ``theta`` and ``theta_dot``), or as a float
    vector ``[a0, a_1..a_N, b_1..b_N]``; anything else is a :class:`ParameterError`."""
    if warm is None or (hasattr(warm, "theta") and hasattr(warm, "theta_dot")):
        return warm
    try:
        x = np.asarray(warm, dtype=float)
    except (TypeError, ValueError):
        x = None
    if x is None or x.ndim != 1 or x.size < 3 or x.size % 2 != 1 or \
            not np.all(np.isfinite(x)):
        shape = "?" if x is None else x.shape
        raise ParameterError(f"warm: expected a motion or a finite vector [a0, a_1..a_N, "
                             f"b_1..b_N] of odd length >= 3, got {type(warm).__name__} of "
                             f"shape {shape}")
    return x


def check_pto_excitation(exc) -> None:
    """Refuse an excitation whose ``q`` has more harmonics than the time-domain PTO mesh can
    follow (:data:`parapend.limits.MAX_PTO_Q_HARMONICS`): the solve would not resolve it and
    its dense torque checks cost O(harmonics) per point."""
    n = int(np.size(exc.spectrum)) - 1
    if n <= limits.MAX_PTO_Q_HARMONICS:
        return
    a_min = 80.0 / (math.pi * exc.omega * (limits.MAX_PTO_Q_HARMONICS - 1))
    hint = {"square": f"raise --square-alpha to at least {a_min:.3g} (the tanh width of "
                      "Eq. 26 sets the harmonics)",
            "file": "resample the record uniformly to at most "
                    f"{2 * limits.MAX_PTO_Q_HARMONICS} rows (a non-uniform record to at most "
                    "256 rows) or smooth it"}.get(exc.name, "use fewer terms")
    raise ParameterError(f"excitation: a power take-off is solved on at most "
                         f"{limits.MAX_PTO_INTERVALS} intervals, which follow q up to "
                         f"{limits.MAX_PTO_Q_HARMONICS} harmonics; this q has {n}: {hint}")


def physical_fields(result, units) -> dict:
    """The unit-suffixed fields (W, N m, J) of a result, for :func:`dataclasses.replace`."""
    if units is None:
        return {}
    period = 2 * math.pi / result.omega
    out = {"units": units.describe(), "power_w": units.to_watts(result.power),
           "uniform_power_w": units.to_watts(result.uniform_power),
           "limit_power_w": units.to_watts(result.limit_power),
           "peak_torque_nm": units.to_newton_metres(result.peak_torque),
           "energy_per_cycle_j": units.to_joules(result.power * period),
           "omega_rad_per_s": result.omega / units.time,
           "damping_coefficient": units.damping_coefficient(result.gamma)}
    if result.electrical_power is not None:
        out["electrical_power_w"] = units.to_watts(result.electrical_power)
    if result.motoring_energy is not None:
        out["motoring_energy_j"] = units.to_joules(result.motoring_energy)
    if getattr(result, "uniform_pto_power", None) is not None:
        out["uniform_pto_power_w"] = units.to_watts(result.uniform_pto_power)
        out["uniform_pto_electrical_power_w"] = units.to_watts(
            result.uniform_pto_electrical_power)
    return out


def _uniform_fields(res, exc, tmax, eff, r_cu) -> dict:
    """The ``uniform_pto_*`` fields of a PTO result: the best uniform rotation through the
    same take-off, and the like-for-like gain over it."""
    u = uniform_under_pto(exc, res.gamma, torque_limit=tmax, efficiency=eff,
                          copper_loss=r_cu, winding=res.winding)
    mine = res.electrical_power if res.electrical_power is not None else res.power
    base = u["electrical_power"]
    return {"uniform_pto_feasible": u["feasible"], "uniform_pto_power": u["power"],
            "uniform_pto_electrical_power": base,
            "uniform_pto_peak_torque": u["peak_torque"], "uniform_pto_phase": u["phase"],
            "gain_over_uniform_pto": (mine / base - 1.0) if base is not None and base > 0
            else None}


def optimize_pto(*, torque_limit=None, efficiency=None, efficiency_generating=None,
                 efficiency_motoring=None, copper_loss: float = 0.0, units=None,
                 warm=None, throw: bool = False, ideal=None, max_intervals=None,
                 **optimize_args):
    """Optimal period-1 rotation through a real power take-off.

    Parameters
    ----------
    torque_limit : float or None
        ``T_max`` (units m g l): ``|T(t)| <= T_max`` on the motion's dense evaluation.
    efficiency, efficiency_generating, efficiency_motoring : float or None
        In (0, 1]: electrical power ``eta_g p`` when ``p = -T theta' > 0`` (generating) and
        ``p / eta_m`` when motoring; ``efficiency`` sets both.
    copper_loss : float
        ``r >= 0`` of a winding loss ``r T^2`` (non-dimensional ``R / k_t^2`` times
        ``(m g l)^2`` over the power unit), subtracted from the electrical power.
    units : parapend.units.Units or None
        Adds the W / N m / J fields to the result.
    warm : ndarray or None
        Start (packed Eq. 10 coefficients) instead of the ideal optimum (continuation).
    ideal : OptimizeResult or None
        The ideal optimum, when already computed.
    max_intervals : int or None
        Cap of the time-domain mesh, 2 to :data:`parapend.limits.MAX_PTO_INTERVALS` (the
        default): a smaller cap bounds the work; a result not settled within it is
        "unresolved".
    **optimize_args
        As :func:`parapend.optimize` (``harmonics`` at most 128 here, method "fourier").

    Returns
    -------
    OptimizeResult
        ``power`` is the mechanical power of the PTO optimum, ``electrical_power`` the
        electrical, ``unconstrained_power`` the ideal optimum; ``status`` "converged",
        "no_power", "infeasible" (no rotation found within the torque limit),
        "unresolved" (the last doubling of the mesh moved the power by more than 1e-6, or
        failed), "above_bound" (a power above ``limit - gamma K^2 omega^2``, which no
        rotation can beat), "violated", "stalled" or "max_iterations"; ``success`` only for
        "converged" and "no_power". ``peak_torque_converged`` says whether the peak torque
        moved by less than 1 % at the last doubling (False: an impulsive or singular
        braking, whose peak is a property of the mesh; ``torque_impulse`` is then the
        converging quantity). Lossless and unlimited (``efficiency`` 1 or None, no limit, no
        copper loss) is the ideal problem: the ideal optimum is returned.
    """
    tmax = _torque_limit(torque_limit)
    eff = efficiencies(efficiency, efficiency_generating, efficiency_motoring)
    r_cu = check_range("copper-loss", copper_loss, 0.0, 1e6)
    warm = _check_warm(warm)
    if optimize_args.get("method", "fourier") != "fourier":
        raise ParameterError("method: a power take-off is optimized with method 'fourier'")
    n = check_int("harmonics", optimize_args.get("harmonics", 24), 1,
                  limits.MAX_PTO_HARMONICS)
    # an efficiency of 1 both ways is no efficiency: solved as the problem without one (the
    # result still reports the efficiencies given)
    eff_solve = _lossy(eff)
    lossless = tmax is None and r_cu == 0.0 and eff_solve is None
    if ideal is None and not lossless:  # refuse before the ideal optimum's work
        check_pto_excitation(build_excitation(**{
            k: optimize_args[k] for k in ("excitation", "omega", "delta", "square_alpha",
                                          "fourier", "file") if k in optimize_args}))
    ideal = ideal if ideal is not None else optimize(**optimize_args)
    exc = ideal._excitation
    gamma = ideal.gamma
    if lossless:
        # lossless and unlimited: the ideal problem itself. (At gamma = 0 its supremum, the
        # limit power, is approached only by ever faster flips; the time-domain mesh then
        # turns several radians per interval, Simpson's rule aliases, and the discrete
        # problem's optimum was 114 against a bound of 0.41. The N-harmonic optimum is the
        # answer to the question asked, the same as without the options.)
        res = ideal
        prof = pto_profile(ideal.motion, exc, gamma)
        res = dataclasses.replace(res, electrical_power=ideal.power,
                                  unconstrained_power=ideal.power,
                                  efficiency_generating=None if eff is None else eff[0],
                                  efficiency_motoring=None if eff is None else eff[1],
                                  peak_power=prof["peak_power"],
                                  motoring_energy=prof["motoring_energy"],
                                  harvested_energy=prof["harvested_energy"])
        res = dataclasses.replace(res, **_uniform_fields(res, exc, tmax, eff, r_cu))
        return dataclasses.replace(res, **physical_fields(res, units))
    check_pto_excitation(exc)
    cap = limits.MAX_PTO_INTERVALS if max_intervals is None else \
        check_int("max-intervals", max_intervals, 2, limits.MAX_PTO_INTERVALS)
    if eff_solve is None and tmax is not None:
        sol, motion, extra = _time_domain(exc, gamma, ideal, tmax, r_cu, warm, cap=cap)
    else:
        sol, motion, extra = _collocation(exc, gamma, ideal, tmax, r_cu, eff_solve, warm,
                                          cap=cap)
    coefficients = _coefficients(_projection(motion, exc, n))
    prof = pto_profile(motion, exc, gamma, efficiency=eff_solve)
    pu = ideal.uniform_power
    status = sol.status
    bound = ideal.upper_bound
    if status == "converged" and sol.electrical_power <= 0:
        status = "no_power"  # converged, but every rotation costs energy through this PTO
    if status in ("converged", "no_power", "unresolved") and \
            not sol.power <= bound + 1e-6 * max(1.0, abs(bound)):
        # no rotation does better than limit - gamma K^2 omega^2 (<theta'^2> >= K^2 omega^2)
        status = "above_bound"
    elif status in ("converged", "no_power") and tmax is not None and \
            not sol.peak_torque - tmax <= 1e-6 * tmax + 1e-12 * _torque_scale(exc):
        status = "violated"  # beyond the rounding of the torque's evaluation
    peak_conv = extra.pop("peak_torque_converged")
    msg = {"no_power": "converged, but no positive power is delivered: every period-1 "
                       "rotation costs energy through this power take-off (the power shown "
                       "is the smallest loss)",
           "converged": "converged: optimum of the power take-off problem",
           "infeasible": f"infeasible: no rotation found with |T| <= {tmax}; raise the "
                         "torque limit",
           "unresolved": "not resolved: the power still moved by more than 1e-6 "
                         f"at the last doubling of the intervals (cap {cap}), or the "
                         "finer mesh failed; the coarser optimum is shown",
           "above_bound": f"failed: the power {sol.power:.6g} exceeds the bound "
                          f"{bound:.6g} that no rotation can beat (limit - gamma K^2 omega^2): "
                          "the time-domain mesh does not resolve this motion",
           "violated": f"failed: the motion exceeds the torque limit by "
                       f"{sol.max_violation:.2g} (relative)",
           "stalled": ("stalled: the interior point could not meet the limit between its "
                       "points, or its last steps made no progress; the motion is reported as "
                       "it is (see max_violation)" if extra["method"] == "hermite" else
                       "stalled: the interior point's line search found no acceptable "
                       "point; the motion is reported as it is"),
           "singular": "singular: no regularization of the KKT matrix gave a descent "
                       "step; the motion is reported as it is",
           "max_iterations": "maximum number of Newton iterations reached",
           "nonfinite": "non-finite power encountered"}.get(status, status)
    if peak_conv is False:
        msg += ("; the peak torque is not converged under mesh refinement (see "
                "peak_torque_coarse, torque_impulse)")
    if tmax is not None and tmax >= ideal.peak_torque and \
            sol.power > ideal.power + 1e-6 * max(1.0, abs(ideal.power)):
        msg += (f"; the limit does not bind at the {ideal.harmonics}-harmonic ideal optimum "
                f"(peak {ideal.peak_torque:.6g}), and this optimum exceeds it by "
                f"{sol.power - ideal.power:.3g}: the Fourier series does not resolve the "
                "motion, the ideal optimum is a lower bound (raise --harmonics)")
    res = dataclasses.replace(
        ideal, power=sol.power,
        gain_over_uniform=(sol.power / pu - 1.0) if pu > 0 else None,
        success=status in ("converged", "no_power"), status=status,
        message=msg,
        iterations=sol.iterations, coefficients=coefficients,
        peak_torque=sol.peak_torque, found_by="warm" if warm is not None else "ideal optimum",
        local_maxima=[], gradient_norm=sol.gradient_norm, strict_maximum=False,
        quadrature_points=sol.points,
        mean_square_speed=motion.mean_square_speed(),
        bound_gap=bound - sol.power, second_power=None,
        torque_limit=tmax, efficiency_generating=None if eff is None else eff[0],
        efficiency_motoring=None if eff is None else eff[1],
        electrical_power=sol.electrical_power, unconstrained_power=ideal.power,
        peak_power=prof["peak_power"], motoring_energy=prof["motoring_energy"],
        harvested_energy=prof["harvested_energy"], max_violation=sol.max_violation,
        peak_torque_converged=peak_conv, _motion=motion, **extra)
    res = dataclasses.replace(res, **_uniform_fields(res, exc, tmax, eff, r_cu))
    res = dataclasses.replace(res, **physical_fields(res, units))
    if throw and not res.success:
        raise SolverError(f"optimize: {res.message}")
    return res


def uniform_under_pto(exc, gamma: float, *, torque_limit=None, efficiency=None,
                      copper_loss: float = 0.0, winding: int = 1, points: int = 4096,
                      phases: int = 720) -> dict:
    """The best uniform rotation ``theta = K omega t + phi`` through the same power take-off.

    The uniform rotation's torque (Eq. 14 with ``theta'' = 0``) is ``T(t) = gamma K omega -
    (1 + q(t)) sin(K omega t + phi)``; its mechanical power is ``p = -T K omega``, its
    electrical power ``eta_g p`` generating and ``p / eta_m`` motoring, less ``r T^2``. The
    phase maximizes the mean electrical power (the mechanical power without an efficiency or
    copper loss) among the phases whose peak ``|T|`` is within ``torque_limit``: a scan of
    ``phases`` phases on ``points`` samples of the period, then Brent's method on the best
    one's neighbourhood on 16 times as many samples (the means are rectangle rules, exact
    to rounding for the smooth lossless integrand and second order across the kinks of
    the efficiency: about 1e-9 relative here), cut where the peak torque reaches the limit
    (Brent's root finder).

    Returns
    -------
    dict
        ``feasible`` (some phase meets the limit), ``phase``, ``power`` (mechanical),
        ``electrical_power``, ``peak_torque``; the last four None when infeasible.
    """
    from scipy.optimize import brentq, minimize_scalar

    k = int(winding)
    om = k * exc.omega
    eg, em = (1.0, 1.0) if efficiency is None else efficiency
    r_cu = float(copper_loss)

    def on_grid(m):
        t = exc.period * np.arange(m) / m
        one_q = 1.0 + exc.q_uniform(m)
        return one_q * np.sin(om * t), one_q * np.cos(om * t)

    coarse, fine = on_grid(points), on_grid(16 * points)

    def measures(phi, grid=fine):
        a, b = grid
        phi = np.atleast_1d(phi)[:, None]
        tq = gamma * om - a * np.cos(phi) - b * np.sin(phi)
        p = -tq * om
        elec = np.where(p > 0, eg * p, p / em) - r_cu * tq * tq
        return p.mean(axis=1), elec.mean(axis=1), np.abs(tq).max(axis=1)

    grid = 2 * math.pi * np.arange(phases) / phases
    elec, peak = np.empty(phases), np.empty(phases)
    for i in range(0, phases, 64):  # the scan on the coarse grid, 64 phases at a time
        _, elec[i:i + 64], peak[i:i + 64] = measures(grid[i:i + 64], coarse)
    ok = np.ones(phases, bool) if torque_limit is None else peak <= torque_limit
    none = {"feasible": False, "phase": None, "power": None, "electrical_power": None,
            "peak_torque": None}
    if not ok.any():
        return none
    j = int(np.argmax(np.where(ok, elec, -np.inf)))
    h = 2 * math.pi / phases

    def excess(x):
        return measures(x)[2][0] - torque_limit

    def side(step):
        """The end of the best phase's bracket: the next grid phase, or where the peak
        torque reaches the limit on the way to it (the fine grid decides)."""
        x = grid[j] + step
        if torque_limit is None or (ok[(j + int(np.sign(step))) % phases] and excess(x) <= 0):
            return x
        if excess(grid[j]) > 0 or excess(x) <= 0:
            return grid[j]
        return brentq(excess, grid[j], x, xtol=1e-13)

    lo, hi = side(-h), side(h)
    cand = [grid[j], lo, hi]
    if hi > lo:
        cand.append(minimize_scalar(lambda x: -measures(x)[1][0], bounds=(lo, hi),
                                    method="bounded", options={"xatol": 1e-10}).x)
    cand = np.array(cand)
    mech, elec, peak = measures(cand)
    if torque_limit is not None:
        elec = np.where(peak <= torque_limit * (1 + 1e-12), elec, -np.inf)
        if not np.isfinite(elec).any():
            return none
    i = int(np.argmax(elec))
    return {"feasible": True, "phase": float(cand[i] % (2 * math.pi)), "power": float(mech[i]),
            "electrical_power": float(elec[i]), "peak_torque": float(peak[i])}


def _torque_scale(exc) -> float:
    """``1 + max |q|``: the size of the terms of Eq. 14 whose rounding the torque carries."""
    q = exc.extrema.q
    return 1.0 + (float(np.max(np.abs(q))) if q.size else abs(float(np.real(
        exc.spectrum[0]))))


#: relative change of the peak torque between the last two meshes below which it counts as
#: converged (smooth optima: 0.1 to 0.3 % from 64 to 128 intervals; singular or impulsive
#: braking: 2.6 % to 100 %)
PEAK_RTOL = 1e-2


def _peak_converged(fine: float, coarse) -> bool | None:
    if coarse is None or not math.isfinite(coarse):
        return None
    return bool(abs(fine - coarse) <= PEAK_RTOL * max(abs(fine), abs(coarse)))


def torque_impulse(u: np.ndarray, h: float) -> float:
    """``int |T| dt`` over the arc around the peak of a piecewise-linear torque (node values
    ``u`` on a periodic mesh of step ``h``) on which ``T`` keeps the sign of its peak: the
    impulse of the braking (or driving) arc. Exact for the piecewise-linear torque; where
    the peak grows with the mesh (an impulsive optimum) this converges."""
    u = np.asarray(u, dtype=float)
    k = u.size
    j0 = int(np.argmax(np.abs(u)))
    sgn = 1.0 if u[j0] >= 0 else -1.0
    w = sgn * np.roll(u, -j0)  # the peak at 0, positive
    total = 0.0
    for direction in (1, -1):
        i = 0
        while True:
            a = w[i % k]
            nxt = i + direction
            b = w[nxt % k]
            if b > 0:
                total += 0.5 * h * (a + b)
            else:
                total += 0.5 * h * a * a / (a - b) if a > 0 else 0.0
                break
            i = nxt
            if abs(i) >= k:
                return float(np.sum(np.abs(u)) * h)  # one sign throughout: the whole period
    return float(total)


def _projection(motion, exc, n: int) -> FourierMotion:
    """The N-harmonic Fourier projection of a motion (for ``coefficients``)."""
    from .trajectory import SampledMotion

    m = max(4096, 8 * n)
    t = exc.period * np.arange(m) / m
    proj = SampledMotion(exc.omega, motion.theta(t)).to_fourier()
    return FourierMotion(exc.omega, proj.a0, proj.a[:n], proj.b[:n])


def intervals_for(exc) -> int:
    """Starting number of Hermite intervals: 64, or 8 per harmonic of ``q``, a power of
    two, at most half :data:`parapend.limits.MAX_PTO_INTERVALS` (then doubled until the
    power moves by less than 1e-6: there is always one doubling to check the result)."""
    k = 8 * max(1, int(np.size(exc.spectrum)) - 1)
    return int(min(limits.MAX_PTO_INTERVALS // 2,
                   max(64, 1 << int(math.ceil(math.log2(k))))))


def _settled(prev, power, k, cap, rtol):
    """``(done, change)`` of the doubling of the intervals after a converged solve on ``k``:
    ``change`` is the move of the electrical power from the coarser mesh's ``prev`` (NaN
    without one); done when it is within ``rtol`` (relative, absolute below 1) or the next
    doubling would pass the cap."""
    change = float("nan") if prev is None else abs(power - prev)
    return 2 * k > cap or change <= rtol * max(1.0, abs(power)), change


def _time_domain(exc, gamma, ideal, tmax, copper_loss, warm, rtol: float = 1e-6,
                 cap: int = limits.MAX_PTO_INTERVALS):
    """Torque-limited optimum on Hermite intervals, doubled until the power settles."""
    from .optimal.hermite import solve_hermite

    start = ideal.motion if warm is None or isinstance(warm, np.ndarray) else warm
    k = min(intervals_for(exc), max(cap // 2, 1))
    prev = None
    iters = 0
    change = float("nan")
    anchor = last = None
    coarse_peak = None
    wind = ideal.winding
    # every monotone rotation: P <= T_max <theta'> = T_max K omega
    bound = tmax * wind * exc.omega
    brake_tried = copper_loss != 0.0
    while True:
        sol = solve_hermite(exc, gamma, k, start, torque_limit=tmax, copper_loss=copper_loss,
                            anchor=anchor, winding=wind)
        iters += sol.iterations
        if not brake_tried and (sol.status != "converged" or sol.power >= 0.9 * bound):
            # near the bound: the constant brake attains it, if it exists; then no monotone
            # rotation (the Hermite optimum, refined or not) can do better
            brake_tried = True
            brake = _constant_brake(exc, gamma, tmax, sol.motion, iters, wind)
            if brake is not None and brake[0].power >= sol.power:
                return brake
        if sol.status != "converged" and prev is None and 2 * k <= cap:
            # the smallest peak torque falls with the resolution, and near a free rotation
            # (tiny limits) a coarse mesh may stall: try a finer one
            k *= 2
            continue
        if sol.status != "converged":
            if last is not None and not sol.power > last[0].power:
                sol, k = last  # the converged coarser optimum is better: keep it, unresolved
                coarse_peak = None
            break
        if last is not None:
            coarse_peak = last[0].peak_torque
        last = sol, k
        anchor = sol.anchor  # strictly inside the limit: the finer solve starts towards it
        motion = sol.motion
        done, change = _settled(prev, sol.electrical_power, k, cap, rtol)
        if done:
            break
        prev = sol.electrical_power
        start = motion
        k *= 2
    motion = sol.motion
    status = sol.status
    if status == "converged" and not change <= rtol * max(1.0, abs(sol.electrical_power)):
        status = "unresolved"
    viol = max(sol.peak_torque / tmax - 1.0, 0.0)
    out = PTOSolution(x=sol.x, power=sol.power, electrical_power=sol.electrical_power,
                      peak_torque=sol.peak_torque, max_violation=viol, status=status,
                      iterations=iters, outer_iterations=len(sol.stages),
                      gradient_norm=float("nan"), stages=sol.stages)
    return out, motion, {"method": "hermite", "intervals": k, "refinement_change": change,
                         "peak_torque_coarse": coarse_peak,
                         "peak_torque_converged": _peak_converged(sol.peak_torque,
                                                                  coarse_peak)}


def _constant_brake(exc, gamma, tmax, start, iters, winding: int = 1):
    """The rotation under the constant torque ``-T_max`` (:mod:`parapend.optimal.brake`),
    as ``(PTOSolution, motion, extra)``, or None when there is none near ``start``."""
    from .model import peak_torque
    from .optimal.brake import constant_brake
    from .power import mean_power

    found = constant_brake(exc, gamma, tmax, start, winding=winding)
    if found is None:
        return None
    motion, n, _ = found
    power = mean_power(motion, exc, gamma, points=max(4096, 16 * n))
    # the resolution check: the power on half the harmonics (the coefficients above N/2
    # are what the doubling added)
    half = FourierMotion(exc.omega, motion.a0, motion.a[:n // 2], motion.b[:n // 2],
                         winding)
    change = abs(power - mean_power(half, exc, gamma, points=max(4096, 16 * n)))
    peak = peak_torque(motion, exc, gamma)
    out = PTOSolution(x=motion.vector, power=power, electrical_power=power, peak_torque=peak,
                      max_violation=max(peak / tmax - 1.0, 0.0), status="converged",
                      iterations=iters, outer_iterations=0, gradient_norm=float("nan"),
                      stages=[("constant-brake", n, "converged")])
    # the torque is -T_max by construction; the dense peak of the motion checks the solve
    return out, motion, {"method": "constant-brake", "harmonics": n,
                         "refinement_change": change, "peak_torque_converged": True}


def _collocation(exc, gamma, ideal, tmax, copper_loss, eff, warm, rtol: float = 1e-6,
                 cap: int = limits.MAX_PTO_INTERVALS):
    """Efficiency / copper-loss optimum by Hermite-Simpson collocation
    (:mod:`parapend.optimal.collocation`), the intervals doubled until the electrical power
    moves by less than ``rtol``."""
    from .optimal.collocation import solve_collocation

    if warm is None:
        start = ideal.motion
    elif isinstance(warm, np.ndarray):
        start = FourierMotion.from_vector(exc.omega, np.asarray(warm, dtype=float))
    else:
        start = warm
    k = min(intervals_for(exc), max(cap // 2, 1))
    prev = last = coarse = None
    iters = 0
    change = float("nan")
    refined = False
    while True:
        sol = solve_collocation(exc, gamma, k, start, efficiency=eff, torque_limit=tmax,
                                copper_loss=copper_loss, winding=ideal.winding)
        iters += sol.iterations
        if sol.status != "converged" and last is None and start is not ideal.motion:
            # a warm start (continuation) that failed: from the ideal optimum instead
            start = ideal.motion
            continue
        if sol.status != "converged" and last is None and not refined and 2 * k <= cap:
            # the ideal optimum with its torque clipped to the limit is off the dynamics;
            # on a coarse mesh the interior point can stall there, at defects of 1e-2 and
            # a power above any rotation's: try a finer mesh once, as _time_domain does
            refined = True
            k *= 2
            continue
        if sol.status != "converged":
            if last is not None:
                sol, k = last  # the converged coarser optimum: kept, "unresolved"
                coarse = None
            break
        if last is not None:
            coarse = last[0]
        last = sol, k
        done, change = _settled(prev, sol.electrical_power, k, cap, rtol)
        if done:
            break
        prev = sol.electrical_power
        start = sol.motion
        k *= 2
    if tmax is not None and copper_loss == 0.0 and (
            sol.status != "converged" or sol.power >= 0.9 * tmax * ideal.winding * exc.omega):
        # as in _time_domain: where the interior point failed, or near the bound of every
        # monotone rotation (P <= T_max K omega), the constant brake attains that bound if it
        # exists; it only generates (theta' > 0), so its electrical power is eta_g P, the
        # bound of every monotone rotation through the efficiency too
        brake = _constant_brake(exc, gamma, tmax, sol.motion, iters, ideal.winding)
        eg = 1.0 if eff is None else eff[0]
        if brake is not None and (sol.status != "converged" or
                                  eg * brake[0].power >= sol.electrical_power):
            out, motion, extra = brake
            return dataclasses.replace(out, electrical_power=eg * out.power), motion, extra
    status = sol.status
    if status == "converged" and not change <= rtol * max(1.0, abs(sol.electrical_power)):
        status = "unresolved"
    if status != "converged" and tmax is not None and last is None and \
            not sol.infeasibility <= 1e-6:
        # no motion meeting the dynamics was found within the limit (below the smallest
        # peak torque of a rotation, the interior point stalls far from the dynamics)
        status = "infeasible"
    viol = 0.0 if tmax is None else max(sol.peak_torque / tmax - 1.0, 0.0)
    out = PTOSolution(x=np.concatenate([sol.motion.theta_nodes, sol.motion.v_nodes,
                                        sol.motion.u_nodes]),
                      power=sol.power, electrical_power=sol.electrical_power,
                      peak_torque=sol.peak_torque, max_violation=viol, status=status,
                      iterations=iters, outer_iterations=1, gradient_norm=sol.kkt_error,
                      points=2 * k)
    period = 2 * math.pi / exc.omega
    imp = torque_impulse(sol.motion.u_nodes, period / k)
    imp_c = None if coarse is None else torque_impulse(coarse.motion.u_nodes,
                                                       period / coarse.intervals)
    return out, sol.motion, {
        "method": "collocation", "intervals": k, "refinement_change": change,
        "peak_torque_coarse": None if coarse is None else coarse.peak_torque,
        "peak_torque_converged": _peak_converged(
            sol.peak_torque, None if coarse is None else coarse.peak_torque),
        "torque_impulse": imp,
        "torque_impulse_change": None if imp_c is None else abs(imp - imp_c)}


def _smallest_limit(ideal):
    """The smallest peak torque of a rotation (phase 1 of :mod:`parapend.optimal.hermite`
    from the best uniform rotation, on twice :func:`intervals_for` intervals): ``(dense
    peak of that motion, status)``. Any smaller limit is infeasible near it; this limit is
    met (by that motion). When the pendulum has a free period-1 rotation (Eq. 14 with
    ``T = 0``, :func:`parapend.optimal.brake.constant_brake` at zero torque, from the best
    uniform rotation), it is 0 exactly, status "free rotation"."""
    from .optimal.brake import constant_brake
    from .optimal.hermite import minimum_peak_torque

    exc = ideal._excitation
    wind = ideal.winding
    _, phi = uniform_power(exc, ideal.gamma, wind)
    uniform = FourierMotion(exc.omega, phi, np.zeros(1), np.zeros(1), wind)
    if constant_brake(exc, ideal.gamma, 0.0, uniform, winding=wind) is not None:
        return 0.0, "free rotation"
    sol, _ = minimum_peak_torque(exc, ideal.gamma, 2 * intervals_for(exc), uniform,
                                 winding=wind)
    return float(sol.peak_torque), sol.status


def pto_curve(vary: str = "torque-limit", *, values=None, points: int = 12,
              efficiency=None, efficiency_generating=None, efficiency_motoring=None,
              torque_limit=None, units=None, progress=None, **optimize_args):
    """Optimal power against the torque limit or the efficiency.

    Parameters
    ----------
    vary : {"torque-limit", "efficiency"}
        ``torque-limit``: from the ideal optimum's peak torque down (geometrically) to the
        smallest feasible limit (the smallest peak torque of any rotation found, phase 1 of
        :mod:`parapend.optimal.hermite`, but at least 2 % of the top; 0.2 % of the top when
        the pendulum has a free rotation, which makes it 0), each solve warm-started from
        the previous; with an efficiency, down to 2 % of the top
        (:mod:`parapend.optimal.collocation`), stopping at the first infeasible value;
        ``efficiency``: ``eta = eta_g = eta_m`` from 1 down to 0.5 (or ``values``).
    values : sequence of float or None
        The limits (m g l) or efficiencies to use instead of the defaults.
    points : int
        Number of values (2 to 101).

    Returns
    -------
    xarray.Dataset
        Over ``value``: ``power`` (mechanical), ``electrical_power``, ``peak_torque``,
        ``motoring_energy``, ``peak_torque_converged`` (1, 0: not converged under mesh
        refinement, the peak is a property of the mesh; -1: not checked, the ideal
        optimum), ``status``; attrs ``vary``, ``unconstrained_power``, and, for
        the torque limit, ``smallest_solved_limit`` (the smallest value solved feasibly),
        ``smallest_feasible_limit`` and ``smallest_feasible_status`` (phase 1, no
        efficiency).
    """
    import xarray as xr

    if not isinstance(vary, str) or vary not in VARY:
        raise ParameterError(f"vary: expected one of {', '.join(VARY)}, got {vary!r:.40}")
    npts = check_int("points", points, 2, limits.MAX_PTO_POINTS)
    check_pto_excitation(build_excitation(**{
        k: optimize_args[k] for k in ("excitation", "omega", "delta", "square_alpha",
                                      "fourier", "file") if k in optimize_args}))
    ideal = optimize(**optimize_args)
    if vary == "torque-limit":
        if torque_limit is not None:
            raise ParameterError("torque-limit: it is the varied quantity; drop it")
        eff = efficiencies(efficiency, efficiency_generating, efficiency_motoring)
        tmin = _smallest_limit(ideal) if _lossy(eff) is None else None
        if values is None:
            top = ideal.peak_torque
            # down to the smallest feasible limit; with a free rotation (smallest limit 0)
            # to 0.2 % of the top, through the constant brake's P = T_max omega
            low = 0.02 * top if tmin is None else 0.002 * top if tmin[0] == 0.0 else \
                min(top, max(tmin[0] * (1 + 2e-3), 0.02 * top))
            vals = list(top * np.geomspace(1.0, low / top, npts))
        else:
            vals = sorted((_torque_limit(v) for v in values), reverse=True)
    else:
        eff = None
        if any(v is not None for v in (efficiency, efficiency_generating,
                                       efficiency_motoring)):
            raise ParameterError("efficiency: it is the varied quantity; drop it")
        vals = list(np.linspace(1.0, 0.5, npts)) if values is None else \
            [_eta("efficiency", v) for v in values]
    k0 = intervals_for(ideal._excitation)
    if len(vals) * k0 > limits.MAX_PTO_CURVE_WORK:
        raise ParameterError(
            f"points: expected at most {max(limits.MAX_PTO_CURVE_WORK // k0, 1)} values for "
            f"this excitation (values x intervals <= {limits.MAX_PTO_CURVE_WORK}; each "
            f"solve starts on {k0} intervals, 8 per harmonic of q), got {len(vals)}")
    rows = []
    warm = None
    for i, v in enumerate(vals):
        kw = {"torque_limit": v, "efficiency": None if eff is None else eff[0],
              "efficiency_motoring": None if eff is None else eff[1]} \
            if vary == "torque-limit" else {"efficiency": v, "torque_limit": torque_limit}
        r = optimize_pto(units=units, warm=warm, ideal=ideal, **kw, **optimize_args)
        rows.append(r)
        if progress is not None:
            progress(i + 1, len(vals))
        if vary == "torque-limit" and r.status == "infeasible":
            break  # below the smallest feasible limit: smaller ones are infeasible too
        warm = r.motion
    feas = [r.torque_limit for r in rows if r.status != "infeasible"]
    ds = xr.Dataset(
        {"power": ("value", [r.power for r in rows]),
         "electrical_power": ("value", [r.electrical_power for r in rows]),
         "peak_torque": ("value", [r.peak_torque for r in rows]),
         "motoring_energy": ("value", [r.motoring_energy for r in rows]),
         "peak_torque_converged": ("value", np.array(
             [-1 if r.peak_torque_converged is None else int(r.peak_torque_converged)
              for r in rows], dtype=np.int8)),
         "status": ("value", [r.status for r in rows]),
         # the best uniform rotation through the same take-off (NaN: none within the limit)
         "uniform_pto_power": ("value", [np.nan if r.uniform_pto_power is None
                                         else r.uniform_pto_power for r in rows]),
         "uniform_pto_electrical_power": ("value", [
             np.nan if r.uniform_pto_electrical_power is None
             else r.uniform_pto_electrical_power for r in rows])},
        coords={"value": [float(v) for v in vals[:len(rows)]]},
        attrs={"vary": vary, "unconstrained_power": ideal.power,
               "uniform_power": ideal.uniform_power, "harmonics": ideal.harmonics,
               "gamma": ideal.gamma, "omega": ideal.omega,
               "convention": "power: mechanical P = -<T theta'>; torque units m g l"})
    if vary == "torque-limit":
        ds.attrs["smallest_solved_limit"] = min(feas) if feas else float("nan")
        if tmin is not None:
            ds.attrs["smallest_feasible_limit"] = tmin[0]
            ds.attrs["smallest_feasible_status"] = tmin[1]
    if units is not None:
        ds["power_w"] = ds["power"] * units.power
        ds["electrical_power_w"] = ds["electrical_power"] * units.power
        ds["peak_torque_nm"] = ds["peak_torque"] * units.torque
    return ds


@figure_style()
def electrical_headline(result):
    """An optimum through a lossy take-off as the user reads it: ``power`` and ``power_w``
    the electrical power (what the take-off delivers, the headline of the text), the
    mechanical one as ``mechanical_power`` and ``mechanical_power_w``."""
    return dataclasses.replace(result, power=result.electrical_power,
                               power_w=result.electrical_power_w,
                               mechanical_power=result.power,
                               mechanical_power_w=result.power_w)


def electrical_curve(ds) -> None:
    """A ``pto_curve`` Dataset through a lossy take-off, in place: ``power`` and ``power_w``
    the electrical power, the mechanical one as ``mechanical_power`` and
    ``mechanical_power_w`` (as :func:`electrical_headline`)."""
    for suffix in ("", "_w"):
        if f"power{suffix}" in ds:
            ds[f"mechanical_power{suffix}"] = ds[f"power{suffix}"]
            ds[f"power{suffix}"] = ds[f"electrical_power{suffix}"].copy()
            ds[f"power{suffix}"].attrs["long_name"] = (
                "mean electrical power (the take-off's output)")


def plot_pto_profile(result, path=None, points: int = 2000):
    """Torque ``T(t)`` and instantaneous power ``p = -T theta'`` of an optimum over one period.

    The torque limit (if any) is drawn as dashed lines; motoring (``p < 0``) is shaded.
    Returns the figure (saved through :func:`parapend.plotting.save_figure` if ``path``).
    """
    from .plotting import TAU_LABEL, _finish, plt

    exc = result.excitation_function
    eff = None if result.efficiency_generating is None else (result.efficiency_generating,
                                                              result.efficiency_motoring)
    k = getattr(result.motion, "intervals", None)
    if k:  # a grid through every node: the vertices of a piecewise-linear torque drawn
        points = k * -(-points // k)
    prof = pto_profile(result.motion, exc, result.gamma, points=points, efficiency=eff)
    units = result.physical_units  # SI axes, title and legend with the pendulum in SI
    kt, kp = (1.0, 1.0) if units is None else (units.torque, units.power)
    tau = prof["tau"]
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True)
    ax1.plot(tau, kt * prof["torque"], color="C3", lw=1.2)
    if result.torque_limit is not None:
        for s in (1, -1):
            ax1.axhline(s * kt * result.torque_limit, color="k", ls="--", lw=0.8)
    if units is None:
        ax1.set_ylabel("torque $T$ ($mgl$)")
        mech = ("" if result.mechanical_power is None else
                f" (mechanical {result.mechanical_power:.5f})")
        ax1.set_title(f"Power take-off: $P$ = {result.power:.5f}{mech}, peak $|T|$ = "
                      f"{result.peak_torque:.4g}, $\\gamma$ = {result.gamma:g}", fontsize=9)
    else:
        from .plotting import si_title

        ax1.set_ylabel("torque $T$ (N m)")
        head = (f"$P$ = {units.to_watts(result.power):.4g} W"
                + ("" if result.mechanical_power is None else
                   f" (mechanical {units.to_watts(result.mechanical_power):.4g} W)")
                + f", peak $|T|$ = {units.to_newton_metres(result.peak_torque):.4g} N m")
        ax1.set_title(f"Power take-off: {head}\n{si_title(result, units)}", fontsize=9)
    ax1.grid(alpha=0.3)
    p = kp * prof["power"]
    ax2.plot(tau, p, color="C0", lw=1.2, label=r"mechanical $p = -T\dot\theta$")
    if np.any(p < 0):  # a legend entry only for what is drawn
        ax2.fill_between(tau, p, 0, where=p < 0, color="C1", alpha=0.4,
                         label="motoring ($p < 0$)")
    if "electrical_power" in prof:
        ax2.plot(tau, kp * prof["electrical_power"], color="C2", lw=1, label="electrical")
    ax2.set_ylabel(r"power $p$ ($mgl/t_0$)" if units is None else "power $p$ (W)")
    ax2.set_xlabel(TAU_LABEL)
    ax2.grid(alpha=0.3)
    ax2.legend(fontsize=8, loc="best")
    ax2.set_xlim(0, 1)
    return _finish(fig, path)


@figure_style()
def plot_pto_curve(ds, path=None):
    """Optimal (mechanical and electrical) power against the varied PTO parameter."""
    from .plotting import _finish, plt

    fig, ax = plt.subplots(figsize=(7, 4.2))
    ok = np.isin(ds["status"].values, ["converged", "no_power"])
    v = ds["value"].values
    mp = ds["mechanical_power" if "mechanical_power" in ds else "power"]
    mech, elec = mp.values, ds["electrical_power"].values
    lossless = np.allclose(mech[ok], elec[ok], rtol=1e-12, atol=1e-14)
    ax.plot(v[ok], mech[ok], "o-",
            label="mechanical = electrical $P$ (lossless)" if lossless else "mechanical $P$")
    if not lossless:  # a curve of its own only where it differs
        ax.plot(v[ok], elec[ok], "s--", label="electrical")
    if not ok.all():
        ax.plot(v[~ok], mech[~ok], "x", color="C3", ms=8,
                label="not converged (status)")
    ax.axhline(ds.attrs["unconstrained_power"], color="k", ls=":", lw=1,
               label="ideal optimum")
    ax.axhline(ds.attrs["uniform_power"], color="gray", ls=":", lw=1, label="best uniform")
    if ds.attrs["vary"] == "torque-limit":
        # the bound of every rotation that never turns back, reached by the constant brake
        tb = np.geomspace(v.min(), v.max(), 200)
        keep = tb * ds.attrs["omega"] <= ds.attrs["unconstrained_power"]
        ax.plot(tb[keep], tb[keep] * ds.attrs["omega"], color="C2", ls="-.", lw=1,
                label=r"$T_{\max}\,\omega$ (constant brake)")
        ax.set_xscale("log")
        ax.set_xlabel(r"torque limit $T_{\max}$ ($mgl$)")
    else:
        ax.set_xlabel(r"efficiency $\eta$ (generating = motoring) (-)")
    ax.set_ylabel(r"mean power $P$ ($mgl/t_0$)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    return _finish(fig, path)
