r"""The best rotation over a record of irregular sea: ``parapend.sea`` (command ``sea``).

The record (:mod:`parapend.seas`) is periodic with the repeat period ``T_r``; the motion has
winding K, ``theta(t + T_r) = theta(t) + 2 pi K``, and is the Fourier motion of Eq. 10 with
``K s`` in place of ``s`` (``s = omega_r t``), optimized by the global search of
:func:`parapend.optimal.fourier.search_fourier` with the matrix-free Newton-CG kernel.

Reported beside the optimum, all in watts for the given pendulum:

- the gamma -> 0 limit ``omega_r TV(q) / 2 pi`` (the same for every K; docs/limit.md) and
  the bound ``limit - gamma K^2 omega_r^2`` that no motion of winding K exceeds;
- the uniform rotation at the mean wave frequency, ``theta = K_m omega_r t + phi`` with
  ``K_m = round(m1/m0 T_r)`` turns per record (only the ``K_m``-th harmonic of ``q`` works
  on it: ``K_m omega_r |Q_{K_m}| / 2 - gamma K_m^2 omega_r^2``).

Resolution: ``N = HARMONICS_PER_WAVE`` harmonics per mean wave (``N = 16 max(K, K_m)``),
checked by one refinement: the optimum is polished again at ``2N`` from the ``N`` optimum
and the change is ``refinement_change``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import limits
from .defaults import SEA
from .errors import ParameterError, SolverError, check_int, check_range
from .optimal.fourier import FourierProblem, _pad, newton_maximize, search_fourier
from .optimal.limit import limit
from .power import uniform_power
from .results import _Result
from .trajectory import FourierMotion
from .units import Units

__all__ = ["SeaResult", "sea"]

#: harmonics of the motion per mean wave of the record
HARMONICS_PER_WAVE = 16
#: seeds proposed by the dynamic programme (and sampled patterns) over a record
SEA_PROPOSE = 4
#: windings tried by ``winding="auto"``: 1 and these fractions of the mean-frequency K_m
AUTO_FRACTIONS = (0.25, 0.5, 0.75, 1.0, 1.25, 1.5)


@dataclass(frozen=True, eq=False, repr=False)
class SeaResult(_Result):
    """The best rotation over one sea record (field names = JSON keys of ``parapend sea``).

    Non-dimensional powers (unit ``m g l / t0``) and the same in watts (``*_w``).

    Attributes
    ----------
    power, power_w : the optimum of winding ``winding`` with ``harmonics`` harmonics.
    limit_power, limit_power_w : the gamma -> 0 supremum ``omega_r TV(q) / 2 pi``.
    upper_bound, upper_bound_w : ``limit - gamma K^2 omega_r^2``: no motion of winding K
        extracts more.
    uniform_power, uniform_power_w, uniform_winding : the best uniform rotation at the mean
        wave frequency (``uniform_winding = K_m`` turns per record).
    windings : list of dict
        Every winding solved (``winding``, ``power``, ``power_w``, ``status``): one row, or
        the scan of ``winding="auto"``.
    refinement_change : float
        ``|P(2N) - P(N)|``; ``power`` is the ``2N`` value.
    record : dict
        What defines the record (sea state or file, repeat period in s, components, cutoff,
        seed, response) and its measured numbers: ``hs_record`` (``4 std z``, m),
        ``mean_period`` (``m0/m1``, s), ``extrema`` of ``q``, ``max_abs_q`` (peak base
        acceleration over g).
    """

    power: float
    power_w: float
    limit_power: float
    limit_power_w: float
    upper_bound: float
    upper_bound_w: float
    uniform_power: float
    uniform_power_w: float
    uniform_winding: int
    winding: int
    windings: list
    harmonics: int
    gamma: float
    omega: float
    success: bool
    status: str
    message: str
    found_by: str
    search: str
    polished: int
    abandoned: int
    second_power: float | None
    refinement_change: float
    quadrature_points: int
    record: dict
    units: dict
    _excitation: object = field(default=None, repr=False)
    _motion: object = field(default=None, repr=False)
    _units: object = field(default=None, repr=False)

    @property
    def motion(self) -> FourierMotion:
        return self._motion

    @property
    def excitation(self):
        return self._excitation

    @property
    def physical_units(self):
        """The pendulum's :class:`~parapend.units.Units`."""
        return self._units

    command = "sea"
    headline = ("power_w", "limit_power_w", "uniform_power_w", "winding", "status")

    def samples(self, points: int | None = None) -> dict:
        """The record and the optimal motion over one repeat period (``sea_samples``)."""
        return sea_samples(self, points)

    def _series(self):
        import xarray as xr

        s = sea_samples(self)
        names = {"t": "time_s", "z": "heave_m", "q": "q", "theta": "theta",
                 "theta_dot": "theta_dot_rad_per_s", "power": "instantaneous_power_w",
                 "energy": "energy_j", "energy_uniform": "uniform_energy_j"}
        return xr.Dataset({names[k]: ("time_s", v) for k, v in s.items() if k != "t"},
                          coords={"time_s": s["t"]})

    def _figure(self):
        return plot_sea(self)


def _solve(exc, k: int, gamma: float, n: int):
    return search_fourier(exc, n, gamma, winding=k, hessian="operator", propose=SEA_PROPOSE)


def sea(*, hs: float | None = None, tp: float | None = None, spectrum: str = "jonswap",
        gamma_peak: float = 3.3, repeat_period: float | None = None, seed: int | None = None,
        cutoff: float = 3.0, response=None, record=None, taper: float = 0.1,
        length: float = SEA["length"], mass: float = SEA["mass"], inertia: float | None = None,
        gravity: float = SEA["gravity"], gamma: float | None = None,
        damping_coefficient: float | None = None, winding=1, harmonics: int | None = None,
        throw: bool = False) -> SeaResult:
    """The best rotation of a pendulum over a record of irregular sea, in watts (command
    ``sea``: ``parapend.sea`` is this function).

    Parameters
    ----------
    hs, tp, spectrum, gamma_peak, repeat_period, seed, cutoff, response :
        The sea state and record (:func:`parapend.seas.sea_record`; ``repeat_period`` in s,
        default ``100 tp``); ``hs``, ``tp``, ``seed`` None: 2 m, 8 s, 0
        (``parapend.defaults.SEA``).
    record : path or None
        A measured heave record, CSV ``t,z`` (s, m), instead of a sea state
        (:func:`parapend.seas.measured_record`, with ``taper`` and ``cutoff``); then
        ``hs``, ``tp``, ``seed``, ``repeat_period`` and ``response`` are refused.
    length, mass, inertia, gravity : the pendulum (m, kg, kg m^2, m/s^2).
    gamma, damping_coefficient : viscous damping, non-dimensional or N m s/rad (one of
        them; default ``gamma = 0.01``).
    winding : int or "auto"
        K, turns per record (default 1); "auto" solves K = 1 and ``K_m`` times
        ``AUTO_FRACTIONS`` and keeps the best.
    harmonics : int or None
        N; None: ``16 max(K, K_m)``.
    throw : bool
        Raise :class:`~parapend.errors.SolverError` when the solve does not converge.
    """
    from .seas import measured_record, sea_record

    units = Units(length, mass, gravity, inertia)
    if gamma is not None and damping_coefficient is not None:
        raise ParameterError("gamma: give either gamma or damping-coefficient, not both")
    if damping_coefficient is not None:
        gamma = units.gamma(damping_coefficient)
    gamma = check_range("gamma", 0.01 if gamma is None else gamma, 0.0, limits.MAX_GAMMA)
    if record is not None:
        bad = [n for n, v in (("hs", hs), ("tp", tp), ("seed", seed),
                              ("repeat-period", repeat_period), ("response", response))
               if v is not None]
        if bad:
            raise ParameterError(f"{', '.join(bad)}: not used with --record; drop it")
        exc = measured_record(units, record, taper=taper, cutoff=cutoff)
    else:
        exc = sea_record(units, hs=SEA["hs"] if hs is None else hs,
                         tp=SEA["tp"] if tp is None else tp, spectrum=spectrum,
                         gamma_peak=gamma_peak, repeat_period=repeat_period,
                         seed=SEA["seed"] if seed is None else seed, cutoff=cutoff,
                         response=response)
    km = max(1, int(round(exc.mean_frequency_harmonic)))
    if isinstance(winding, str):
        if winding != "auto":
            raise ParameterError(f"winding: expected a positive integer or 'auto', got "
                                 f"{winding!r:.60}")
        ks = sorted({1} | {max(1, int(round(f * km))) for f in AUTO_FRACTIONS})
    else:
        ks = [check_int("winding", winding, 1, limits.SEA_MAX_HARMONICS // 8)]
    if harmonics is not None:
        n = check_int("harmonics", harmonics, 1, limits.SEA_MAX_HARMONICS // 2)
    else:
        n = min(HARMONICS_PER_WAVE * max(km, max(ks)), limits.SEA_MAX_HARMONICS // 2)
    if n < 2 * max(ks):
        raise ParameterError(f"harmonics: expected at least 2 K = {2 * max(ks)} harmonics to "
                             f"draw {max(ks)} turns, got {n}")
    lim = limit(exc)
    rows, best = [], None
    for k in ks:
        found = _solve(exc, k, gamma, n)
        rows.append({"winding": k, "power": found.best.power,
                     "power_w": units.to_watts(found.best.power),
                     "status": found.best.status, "found_by": found.best.seed})
        if best is None or found.best.power > best[1].best.power:
            best = (k, found)
    k, found = best
    sol = found.best
    # one refinement: polish at 2N from the N optimum
    fine = FourierProblem(exc, 2 * n, gamma, winding=k, hessian="operator")
    if fine.points < 2 * sol.points:
        fine = FourierProblem(exc, 2 * n, gamma, 2 * sol.points, winding=k, hessian="operator")
    ref = newton_maximize(fine, _pad(sol.x, 2 * n), sol.seed)
    change = abs(ref.power - sol.power)
    if ref.status == "converged" and ref.power >= sol.power:
        sol, n = ref, 2 * n
    pu, _ = uniform_power(exc, gamma, km) if km != 1 else uniform_power(exc, gamma)
    bound = lim.power - gamma * (k * exc.omega) ** 2
    m = 8192
    z = exc.z(exc.period * np.arange(m) / m)
    q = exc.q_uniform(m)
    heave = np.abs(exc.heave) ** 2
    kk = np.arange(heave.size)
    rec = {**exc.describe(), "hs_record": 4.0 * float(np.std(z)),
           "mean_period": exc.info["repeat_period"] * float(np.sum(heave) / np.sum(kk * heave)),
           "extrema": int(exc.extrema.t.size), "max_abs_q": float(np.max(np.abs(q))),
           "mean_frequency_winding": km}
    rec.pop("omega", None)
    status = sol.status
    msg = {"converged": "converged: gradient below tolerance at a local maximum",
           "stalled": "stalled: no step increases the power, but the gradient is not small",
           "max_iterations": "maximum number of Newton iterations reached",
           "nonfinite": "non-finite power encountered"}.get(status, status)
    motion = FourierMotion.from_vector(exc.omega, sol.x, k)
    res = SeaResult(
        power=sol.power, power_w=units.to_watts(sol.power),
        limit_power=lim.power, limit_power_w=units.to_watts(lim.power),
        upper_bound=bound, upper_bound_w=units.to_watts(bound),
        uniform_power=pu, uniform_power_w=units.to_watts(pu), uniform_winding=km,
        winding=k, windings=rows, harmonics=n, gamma=gamma, omega=exc.omega,
        success=status == "converged", status=status, message=msg, found_by=sol.seed,
        search=found.evidence.strategy, polished=found.evidence.polished,
        abandoned=found.evidence.abandoned, second_power=found.evidence.second_power,
        refinement_change=change, quadrature_points=sol.points, record=rec,
        units=units.describe(), _excitation=exc, _motion=motion, _units=units)
    if throw and not res.success:
        raise SolverError(f"sea: {msg}")
    if not math.isfinite(res.power):
        raise SolverError("sea: non-finite power")
    return res


def sea_samples(result: SeaResult, points: int | None = None) -> dict:
    """The record and the optimal motion on a uniform grid over one repeat period.

    Keys: ``t`` (s), ``z`` (m), ``q``, ``theta`` (rad), ``theta_dot`` (rad/s), ``power``
    (instantaneous ``-T theta'`` in W, Eq. 15's integrand), ``energy`` (J harvested since
    ``t = 0``; its end value over ``T_r`` is ``power_w``), and the uniform rotation's
    ``energy_uniform``. Default ``points``: 8 per harmonic of the motion (at least 4096).
    """
    from scipy.integrate import cumulative_trapezoid

    from .model import torque

    exc, units, motion = result._excitation, result._units, result._motion
    m = points or max(4096, 8 * motion.harmonics)
    m = check_int("points", m, 16, 1 << 22)
    tn = exc.period * np.arange(m + 1) / m
    # every array by FFT on the grid (O(m log m)): Eq. 14 solved for T
    th, thd, thdd = motion.on_grid(m)
    q = exc.q_uniform(m)
    tq = thdd + result.gamma * thd - (1.0 + q) * np.sin(th)
    th = np.append(th, th[0] + 2 * math.pi * motion.winding)
    thd, tq, q = np.append(thd, thd[0]), np.append(tq, tq[0]), np.append(q, q[0])
    p = -tq * thd
    km = result.uniform_winding
    _, phi = uniform_power(exc, result.gamma, km) if km != 1 else uniform_power(exc, result.gamma)
    uni = FourierMotion(exc.omega, phi, np.zeros(1), np.zeros(1), km)
    pu = -torque(uni, exc, result.gamma, tn) * uni.theta_dot(tn)
    t_s = tn * units.time
    to_w = units.power
    z = np.fft.irfft(np.concatenate(([0], exc.heave[1:] * (m / 2.0),
                                     np.zeros(max(0, m // 2 + 1 - exc.heave.size)))), m) \
        if exc.heave.size <= m // 2 else exc.z(tn[:-1])
    z = np.append(z, z[0])
    return {"t": t_s, "z": z, "q": q, "theta": th,
            "theta_dot": thd / units.time, "power": p * to_w,
            "energy": cumulative_trapezoid(p * to_w, t_s, initial=0.0),
            "energy_uniform": cumulative_trapezoid(pu * to_w, t_s, initial=0.0)}


def plot_sea(result: SeaResult, path=None, zoom_waves: float = 8.0):
    """Record, motion and harvested energy over the record, and a zoom of a few waves."""
    from .style import use_agg

    use_agg()
    import matplotlib.pyplot as plt

    from .plotting import _finish
    from .style import figure_style

    s = sea_samples(result)
    t = s["t"]
    tp = result.record.get("tp", result.record.get("peak_period"))
    t_zoom = min(float(t[-1]), zoom_waves * tp)
    above = {"loc": "lower left", "bbox_to_anchor": (0.0, 1.0), "ncol": 3, "frameon": False,
             "borderaxespad": 0.2}
    with figure_style():
        fig, ax = plt.subplots(4, 1, figsize=(8.0, 10.0), layout="constrained")
        ax[0].plot(t, s["z"], lw=0.6)
        ax[0].set_ylabel("heave $z$ (m)")
        ax[0].set_title(_title(result), fontsize=9)
        turns = s["theta"] / (2 * math.pi)
        ax[1].plot(t, turns, lw=0.8, label=f"optimum (winding K = {result.winding})")
        ax[1].plot(t, turns[0] + result.uniform_winding * t / t[-1], "--", lw=0.8,
                   label=f"uniform, K = {result.uniform_winding} (mean wave frequency)")
        ax[1].set_ylabel(r"$\theta / 2\pi$ (turns)")
        ax[1].legend(**above)
        ax[2].plot(t, s["energy"] / 1e3, lw=0.9,
                   label=f"optimum: {result.power_w:.4g} W mean")
        ax[2].plot(t, s["energy_uniform"] / 1e3, "--", lw=0.9,
                   label=f"uniform: {result.uniform_power_w:.3g} W mean")
        ax[2].plot(t, t * result.limit_power_w / 1e3, ":", lw=0.9,
                   label=f"limit $\\gamma \\to 0$: {result.limit_power_w:.4g} W")
        ax[2].set_ylabel("energy harvested (kJ)")
        ax[2].legend(**above)
        sel = t <= t_zoom
        ax[3].plot(t[sel], s["q"][sel] / max(np.max(np.abs(s["q"])), 1e-300), lw=0.9,
                   label=r"$q / \max|q|$ (excitation)")
        ax[3].plot(t[sel], np.cos(s["theta"][sel]), lw=0.9,
                   label=r"$\cos\theta$ (1 upright, -1 hanging)")
        ax[3].set_ylabel(r"$q/\max|q|$, $\cos\theta$ (-)")
        ax[3].legend(**above)
        ax[3].set_xlim(0, t_zoom)
        for a in ax[:3]:
            a.set_xlim(0, t[-1])
            a.axvspan(0, t_zoom, color="0.9", lw=0, zorder=0)
        for a in ax[:3]:
            a.set_xlabel("time (s)")
        ax[3].set_xlabel(f"time (s): zoom on the first {zoom_waves:g} peak periods "
                         "(shaded above)")
        return _finish(fig, path, layout=False)


def _title(r: SeaResult) -> str:
    rec = r.record
    if "hs" in rec:
        head = (f"{rec['spectrum']} Hs = {rec['hs']:g} m, Tp = {rec['tp']:g} s, "
                f"T_r = {rec['repeat_period']:g} s, seed {rec['seed']}")
    else:
        head = f"record {rec['record']}, T_r = {rec['repeat_period']:.4g} s"
    u = r.units
    return (f"{head}; pendulum l = {u['length_m']:g} m, m = {u['mass_kg']:g} kg, "
            f"$\\gamma$ = {r.gamma:g}")
