r"""Receding-horizon (model predictive) control of the pendulum in an irregular sea.

Every ``update_interval`` the controller measures the state ``(theta, theta')``, takes the
excitation ``q`` over the next ``horizon`` from a forecast, and solves the horizon problem
on the full nonlinear Eq. 14 with the motion as the unknown (:mod:`parapend.control.plan`):
a ``C^1`` cubic Hermite on ``K`` intervals from the measured state, free at the end, the
torque defined by the motion (inverse dynamics), maximizing the electrical work plus the
terminal value ``kappa E(t + H)``, ``E = theta'^2 / 2 + cos(theta)`` (docs/control.md: the
energy the pendulum keeps is worth ``kappa = eta_g`` of harvested energy), with ``|T| <=
T_max``. The solver is the banded Newton / primal-dual interior point of
:mod:`parapend.optimal.hermite`, warm-started from the previous plan shifted by one update.

The plan is applied as held torque samples of ``dt`` (zero-order hold): each sample holds
the plan's torque averaged over the sample (3-point Gauss rule; the plan's ``q`` is the
forecast's), clipped to ``T_max``. The plant is Eq. 14 integrated by RK4 with
``plant_steps`` steps per torque sample, driven by the record's true ``q``.

From the hanging rest the horizon problem has a stationary point at the rest itself (no work
is done on a pendulum at rest, to first order), so the swing-up of :mod:`.swingup` (energy
pumping) runs until the pendulum rotates forward above the top's energy, then the MPC takes
over.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError, check_int, check_range
from ..results import _Result
from .swingup import pump_torque, ready_to_catch

__all__ = ["HorizonProblem", "MPCResult", "MPCTrackResult", "horizon_problem", "mpc_run",
           "track_mpc", "update_seconds"]

#: the estimate of long work is logged here (INFO); the command line prints it on stderr
log = logging.getLogger("parapend.control")

#: q samples (RK4 steps) per torque sample in the ``qn`` of :class:`HorizonProblem`
MODEL_STEPS = 4
#: RK4 steps per torque sample in the plant
PLANT_STEPS = 16
#: torque samples per Hermite interval of the plan (32 intervals per peak period in
#: ``track`` and ``horizon``, 64 samples)
INTERVAL_SAMPLES = 2
#: natural frequency (pendulum units) of the tracking feedback between re-plans
TRACKING = 1.0
#: interior-point (Newton) iterations per horizon solve
MAX_ITER = 200
#: the swing-up hands over above the top's energy by this margin (as track)
CATCH_MARGIN = 0.05
#: a run stops as "unresolved" when ``|theta'| dt`` exceeds this (rad per held sample)
RESOLVED_TURN = 2 * math.pi
#: least damping the plans price (docs/control.md: at gamma = 0 without a torque limit the
#: horizon problem has no optimum; its supremum is the gamma -> 0 limit's instant flips)
PLAN_DAMPING = 3e-3
#: least seconds between two calls of a run's ``progress``
PROGRESS_EVERY = 0.25
#: work estimated above this many seconds is announced (``log``, INFO)
ANNOUNCE_SECONDS = 30.0


def update_seconds(horizon_periods: float, torque_limit=None, forecast: str = "perfect"
                   ) -> float:
    """A rough wall time (s) of one update at 64 torque samples per peak period, for the
    estimate announced before long work: the means measured on the paper case on one core
    of the development machine (docs/control.md, "Real time"), rounded up: about
    ``3 + 3 H`` ms a solve (``H`` the horizon in peak periods), 6 ms more under a torque
    limit, and ``8 + 6 H`` ms more for the AR forecast. Only an estimate: the progress
    bar reports the run's own rate."""
    h = float(horizon_periods)
    sec = 0.003 + 0.003 * h + (0.006 if torque_limit is not None else 0.0)
    if forecast == "ar":
        sec += 0.008 + 0.006 * h
    return sec


@dataclass(frozen=True, eq=False, repr=False)
class MPCResult(_Result):
    """One receding-horizon run (non-dimensional, pendulum units; theta from the upright).

    Attributes
    ----------
    t : ndarray (n + 1,)
        Sample times.
    theta, theta_dot : ndarray (n + 1,)
        Measured (plant) state at the sample times.
    torque : ndarray (n,)
        Torque held over each sample ``[t_k, t_k+1)``.
    power_series : ndarray (n,)
        Mean mechanical power of each sample, ``-T_k (theta_k+1 - theta_k) / dt`` (exact for
        the held torque; positive = harvested).
    electrical_series : ndarray (n,)
        The same through the efficiency model (equal without one).
    mean_power, mean_electrical_power : float
        Over ``t >= average_from``: the harvested energy plus the change of the stored
        energy, per unit time (``energy_account``; electrically the stored energy counts
        at ``eta_g``).
    harvested_power, harvested_electrical_power : float
        The harvested energy alone per unit time over ``t >= average_from`` (the means of
        the series; a storage swing moves them).
    harvested_energy, stored_energy_change, averaged_time : float
        ``W``, ``E(end) - E(average_from)`` (``E = theta'^2 / 2 + cos(theta)``) and the time
        they are over.
    solve_times, forecast_times, update_times : ndarray
        Wall time (s) of each horizon solve, of each forecast, and of each whole update
        (forecast, problem, warm start, solve, held torques).
    failed_kept_previous : int
        Failed solves whose iterate was not finite, after which the previous plan went on
        (the others applied their last iterate).
    speed_exceeded_fraction, speed_peak : float or None
        With ``speed_limit``: the fraction of samples after the hand-over with ``|theta'|``
        above it, and the largest ``|theta'|`` there (the limit is a penalty).
    iterations : ndarray
        Newton (interior-point) iterations of each solve.
    catch_time : float or None
        When the swing-up handed over to the MPC (None: never).
    """

    t: np.ndarray
    theta: np.ndarray
    theta_dot: np.ndarray
    torque: np.ndarray
    power_series: np.ndarray
    electrical_series: np.ndarray
    mean_power: float
    mean_electrical_power: float
    energy: float
    solve_times: np.ndarray
    iterations: np.ndarray
    update_interval: float
    horizon: float
    dt: float
    gamma: float
    torque_limit: float | None
    efficiency: tuple | None
    terminal_weight: float
    average_from: float
    catch_time: float | None
    solves: int
    failed_solves: int
    peak_torque: float
    forecast: str
    success: bool
    status: str
    message: str
    speed_limit: float | None = None
    harvested_power: float = math.nan
    harvested_electrical_power: float = math.nan
    harvested_energy: float = math.nan
    stored_energy_change: float = math.nan
    averaged_time: float = 0.0
    forecast_times: np.ndarray = field(default_factory=lambda: np.zeros(0))
    update_times: np.ndarray = field(default_factory=lambda: np.zeros(0))
    failed_kept_previous: int = 0
    speed_exceeded_fraction: float | None = None
    speed_peak: float | None = None
    plan_damping: float = 0.0
    convention: str = ("theta from the upright (hanging at rest is theta = pi); power "
                       "positive when harvested, P = -<T theta'>; torque units m g l")
    extra: dict = field(default_factory=dict)

    command = "mpc"
    headline = ("mean_power", "mean_electrical_power", "solves", "failed_solves", "status")

    def to_dict(self) -> dict:
        """The scalars (the series are in ``to_dataset()``)."""
        return {k: v for k, v in super().to_dict().items() if not isinstance(v, list)}

    def _series(self):
        from ..results import series

        pad = np.append  # sample k's torque and power hold over [t_k, t_k+1)
        return series({"time": self.t, "theta": self.theta, "theta_dot": self.theta_dot,
                       "torque": pad(self.torque, np.nan),
                       "sample_power": pad(self.power_series, np.nan),
                       "sample_electrical_power": pad(self.electrical_series, np.nan)})

    def _figure(self):
        from .figures import plot_mpc_track

        return plot_mpc_track(self)


def _q_function(q_record):
    """A vectorized ``q(t)`` from an excitation (``.q``), a callable or samples ``(t, q)``
    (linear interpolation)."""
    if hasattr(q_record, "q") and callable(q_record.q):
        return q_record.q
    if callable(q_record):
        return lambda t: np.asarray(q_record(np.asarray(t, dtype=float)), dtype=float)
    try:
        ts, qs = (np.asarray(a, dtype=float) for a in q_record)
    except (TypeError, ValueError):
        raise ParameterError("q_record: expected an excitation, a callable q(t) or samples "
                             "(t, q)") from None
    if ts.ndim != 1 or ts.shape != qs.shape or ts.size < 2 or np.any(np.diff(ts) <= 0):
        raise ParameterError("q_record: samples (t, q) must be two 1-D arrays of equal "
                             "length >= 2 with t increasing")
    return lambda t: np.interp(t, ts, qs)


def _gauss3(dt):
    """Offsets and weights of the 3-point Gauss rule on a sample ``[0, dt]`` (mean)."""
    x, w = np.polynomial.legendre.leggauss(3)
    return dt * (x + 1) / 2, w / 2


def held_torques(plan, q_of_lead, m, dt, torque_limit=None):
    """The first ``m`` held torques of a plan: its torque (Eq. 14 with the plan's ``q``)
    averaged over each sample by the 3-point Gauss rule, clipped to the limit."""
    off, w = _gauss3(dt)
    s = (dt * np.arange(m))[:, None] + off[None, :]
    u = plan.torque(s, q_of_lead(s)) @ w
    if torque_limit is not None:
        u = np.clip(u, -torque_limit, torque_limit)
    return u


class HorizonProblem:
    """The horizon problem of one update in the torque-sample interface: ``n`` held torques
    of ``dt`` from ``x0`` with ``q`` at the half-step nodes ``qn`` (``2 n steps + 1``, spacing
    ``dt / (2 steps)``).

    :meth:`solve` poses the motion problem of :mod:`parapend.control.plan` (``ceil(n / 2)`` Hermite
    intervals over ``n dt``, ``q`` interpolated from ``qn`` by a cubic spline), starts it from
    the motion of the held torques ``u0`` (RK4 through ``qn``), solves it, and returns the
    plan's torque averaged over each sample (``held_torques``).
    """

    def __init__(self, n, dt, steps, gamma, torque_limit=None, efficiency=None,
                 kappa=None):
        self.n, self.dt, self.steps, self.gamma = int(n), float(dt), int(steps), float(gamma)
        self.eta = (1.0, 1.0) if efficiency is None else tuple(efficiency)
        self.efficiency = efficiency
        self.kappa = self.eta[0] if kappa is None else float(kappa)
        self.torque_limit = torque_limit
        self.k = max(1, -(-self.n // INTERVAL_SAMPLES))
        self.h = self.n * self.dt / self.k

    def problem(self, x0, q_of_lead):
        """The :class:`~parapend.control.plan.PlanProblem` from ``x0`` with ``q`` a callable
        of the lead."""
        from .plan import PlanProblem, gauss_leads

        lg, lc = gauss_leads(self.k, self.h)
        return PlanProblem(x0, self.h, q_of_lead(lg), q_of_lead(lc), self.gamma,
                           torque_limit=self.torque_limit, efficiency=self.efficiency,
                           kappa=self.kappa)

    def solve(self, x0, qn, u0, max_iter=MAX_ITER, tol=1e-10):
        """Solve from the motion of ``u0``; returns a ``scipy.optimize.OptimizeResult``:
        ``x`` the ``n`` held torques, ``fun`` minus the plan's objective ``J``, ``success``,
        ``status`` (the interior point's), ``nit``,
        ``plan`` (:class:`~parapend.control.plan.HorizonPlan`)."""
        from scipy.interpolate import CubicSpline
        from scipy.optimize import OptimizeResult

        from . import _mpc_kernel as km
        from .plan import free_motion, solve_plan

        qn = np.asarray(qn, dtype=float)
        tq = 0.5 * self.dt / self.steps * np.arange(qn.size)
        spline = CubicSpline(tq, qn)
        pr = self.problem(x0, spline)
        th = np.empty(self.n + 1)
        v = np.empty(self.n + 1)
        u0 = np.asarray(u0, dtype=float)
        km.simulate(u0, float(x0[0]), float(x0[1]), qn, self.dt / self.steps, self.steps,
                    self.gamma, th, v)
        ts = self.dt * np.arange(self.n + 1)
        tn = self.h * np.arange(self.k + 1)
        start = pr.start(np.interp(tn, ts, th), np.interp(tn, ts, v))
        anchor = None
        if self.torque_limit is not None:
            fth, fv = free_motion(x0, self.h, self.k, self.gamma,
                                  spline(0.5 * self.h * np.arange(2 * self.k + 1)))
            anchor = pr.start(fth, fv)
        sol = solve_plan(pr, start, anchor=anchor, gap_tol=tol, maxiter=max_iter)
        u = held_torques(sol.plan, spline, self.n, self.dt, self.torque_limit)
        return OptimizeResult(x=u, fun=-sol.value, success=sol.success, status=sol.status,
                              nit=sol.iterations, plan=sol.plan)


def horizon_problem(n, dt, *, gamma, steps=MODEL_STEPS, torque_limit=None, efficiency=None,
                    terminal_weight=None) -> HorizonProblem:
    """The horizon problem (for benchmarks and tests); see :class:`HorizonProblem`."""
    return HorizonProblem(n, dt, steps, gamma, torque_limit, efficiency, terminal_weight)


def _electrical(p, eta):
    return np.where(p > 0, eta[0] * p, p / eta[1])


def stored_energy(theta, theta_dot):
    """The pendulum's mechanical energy ``E = theta'^2 / 2 + cos(theta)`` (units ``m g l``;
    theta from the upright: ``E = -1`` hanging at rest, ``1`` at rest on top), the energy of
    Eq. 14's balance ``dE/dt = q sin(theta) theta' - gamma theta'^2 + T theta'``."""
    return 0.5 * np.asarray(theta_dot, dtype=float) ** 2 + np.cos(theta)


def energy_account(t, theta, theta_dot, p, pe, start, eta_g=1.0):
    """The energy account of a sampled run over ``t >= start``: the harvested energy
    ``W = sum p_k dt`` (``p_k`` the power of held sample ``k``, exact), the change of the
    stored energy ``dE = E(end) - E(start)`` (:func:`stored_energy`), the time ``tau``, and
    the powers ``harvested_power = W / tau`` and ``mean_power = (W + dE) / tau`` (the energy
    still in the pendulum counted as harvested, energy drawn from it as not); electrically
    ``(W_e + eta_g dE) / tau`` (stored energy is harvested at ``eta_g``). A dict."""
    t = np.asarray(t, dtype=float)
    if t.size < 2:
        nan = math.nan
        return {"harvested_energy": nan, "stored_energy_change": nan, "averaged_time": 0.0,
                "harvested_power": nan, "harvested_electrical_power": nan,
                "mean_power": nan, "mean_electrical_power": nan}
    dt = t[1] - t[0]
    i0 = int(np.searchsorted(t, start - 1e-9 * dt))
    i0 = min(i0, t.size - 1)
    tau = float(t[-1] - t[i0])
    w = float(np.sum(p[i0:]) * dt)
    we = float(np.sum(pe[i0:]) * dt)
    e = stored_energy(theta[[i0, -1]], theta_dot[[i0, -1]])
    de = float(e[1] - e[0])
    ok = tau > 0
    return {"harvested_energy": w, "stored_energy_change": de, "averaged_time": tau,
            "harvested_power": w / tau if ok else math.nan,
            "harvested_electrical_power": we / tau if ok else math.nan,
            "mean_power": (w + de) / tau if ok else math.nan,
            "mean_electrical_power": (we + eta_g * de) / tau if ok else math.nan}


def mpc_run(q_record, *, gamma, horizon, update_interval, dt, torque_limit=None,
            efficiency=None, forecast=None, theta0=math.pi, theta_dot0=0.0, t_end=None,
            warm=True, seed=0, terminal_weight=None, average_from=0.0,
            interval_samples=INTERVAL_SAMPLES, plant_steps=PLANT_STEPS, max_iter=MAX_ITER,
            pump_level=1.0, tracking=TRACKING, terminal="energy", speed_limit=None,
            speed_weight=None, plan_damping=None, progress=None, deadline=None) -> MPCResult:
    """Receding-horizon control of Eq. 14 driven by the record ``q_record``.

    Parameters
    ----------
    q_record : Excitation, callable or (t, q) samples
        The sea's ``q(t)`` (non-dimensional time, as :mod:`parapend.seas` records).
    gamma : float
        Viscous damping of Eq. 14.
    horizon, update_interval, dt : float
        Horizon ``H``, update interval and torque sample (non-dimensional time); ``H`` and
        the update interval are rounded to whole samples (at least one).
    torque_limit : float or None
        ``T_max``: bound of the planned torque at the plan's torque points and of every held
        torque (also the swing-up's pump, at most ``pump_level``).
    efficiency : (eta_g, eta_m) or None
        The efficiency model of :mod:`parapend.pto`, in the objective and the electrical
        series.
    forecast : None or object with ``predict(t_now, past_t, past_q, lead_times)``
        None: perfect (the record's own future). Otherwise the predicted ``q`` at
        ``t_now + lead_times``, given the measured ``q`` at the past sample times. A
        forecast with an attribute ``reach`` (not None; non-dimensional time) caps the
        horizon at it.
    theta0, theta_dot0 : float
        Initial state (default hanging at rest).
    t_end : float
        Length of the run (required for a callable or an excitation; samples: their end).
    warm : bool
        Warm-start each solve from the previous plan shifted (else from the unforced
        motion).
    seed : int
        Seeds nothing random here (kept for the forecasts' interface).
    terminal_weight : float or None
        ``kappa`` of the terminal value ``kappa E``; None: ``eta_g`` (1 without an
        efficiency); 0: no terminal value.
    average_from : float
        The means are over ``t >= average_from``.
    interval_samples : int
        Torque samples per Hermite interval of the plan (``K = ceil(n / interval_samples)``
        intervals over the horizon's ``n`` samples).
    plant_steps : int
        RK4 steps of the plant per torque sample.
    max_iter : int
        Newton iterations per horizon solve.
    terminal : {"energy", "limited"}
        The terminal value ``kappa V(E)``: ``V = E`` (default), or ``"limited"``, the energy a
        torque ``T_max`` harvests braking the rotation against ``gamma``
        (:meth:`~.plan.PlanProblem.terminal_value`; docs/control.md: about the same power
        as ``kappa E``).
    speed_limit : float or None
        Rated speed ``w_max`` priced in the plans: the penalty ``rho / 2 h sum
        max(|theta'_k| - w_max, 0)^2`` at the plan's nodes
        (:meth:`~.plan.PlanProblem.speed_penalty`), a penalty and not a hard bound: the
        result reports the fraction of samples above it and the peak speed; None: none
        (docs/control.md: it costs power).
    speed_weight : float or None
        ``rho`` of that penalty (None: ``parapend.control.plan.SPEED_WEIGHT``, 100).
    plan_damping : float or None
        Least damping the plans' objective prices, ``max(gamma, plan_damping)`` (the torque
        keeps ``gamma``); None: ``PLAN_DAMPING``. At ``gamma = 0`` without it the horizon
        problem has no optimum (docs/control.md) and the plans spin the pendulum up.
    progress : callable or None
        Called ``progress(done, total)`` in torque samples of the run, at most every
        ``PROGRESS_EVERY`` seconds and at the end.
    deadline : float or None
        A ``time.monotonic`` time (:func:`parapend.deadline.deadline`): once it has
        passed, the run stops before its next update (after at least one) with the status
        "time_limit" (``success`` False): a partial run, its powers over the samples run
        (NaN if it stopped before ``average_from``).

    A run whose speed exceeds a turn per held torque sample stops with the status
    "unresolved" (``success`` False).
    """
    from . import _mpc_kernel as k
    from .plan import PlanProblem, free_motion, gauss_leads, solve_plan

    gamma = check_range("gamma", gamma, 0.0, 1e3)
    dt = check_range("dt", dt, 1e-4, 1e3)
    # forecast reach: a forecast with a finite ``reach`` (non-dimensional time, e.g.
    # ARForecast) is not planned on beyond it; the result's ``horizon`` is the one used
    reach = getattr(forecast, "reach", None)
    if reach is not None and horizon > reach:
        horizon = max(float(reach), dt)
    if not horizon >= dt:
        raise ParameterError(f"horizon: expected at least one sample dt = {dt:g}, got "
                             f"{horizon!r}")
    n = max(1, int(round(horizon / dt)))
    m = max(1, min(n, int(round(update_interval / dt))))
    if terminal not in ("energy", "limited"):
        raise ParameterError(f"terminal: expected energy or limited, got {terminal!r:.40}")
    interval_samples = check_int("interval_samples", interval_samples, 1, 1024)
    plant_steps = check_int("plant_steps", plant_steps, 1, 4096)
    if torque_limit is not None:
        torque_limit = check_range("torque-limit", torque_limit, 1e-9, 1e6)
    if speed_limit is not None:
        speed_limit = check_range("speed-limit", speed_limit, 1e-9, 1e6)
    plan_damping = PLAN_DAMPING if plan_damping is None else check_range(
        "plan-damping", plan_damping, 0.0, 1e3)
    qf = _q_function(q_record)
    if t_end is None:
        if isinstance(q_record, tuple) or isinstance(q_record, list):
            t_end = float(np.asarray(q_record[0])[-1])
        else:
            raise ParameterError("t_end: expected the length of the run")
    total = int(math.floor(t_end / dt + 1e-9))
    if total < 1:
        raise ParameterError(f"t_end: expected at least one sample dt = {dt:g}")
    # q on the plant's half-step grid over the run
    hp = dt / plant_steps
    nodes = 2 * total * plant_steps + 1
    qp = np.empty(nodes)
    chunk = 1 << 16
    for a in range(0, nodes, chunk):
        b = min(nodes, a + chunk)
        qp[a:b] = qf(0.5 * hp * np.arange(a, b))
    eta = (1.0, 1.0) if efficiency is None else tuple(float(e) for e in efficiency)
    kappa = eta[0] if terminal_weight is None else float(terminal_weight)
    # the plan: K Hermite intervals of h over the horizon
    kk = max(1, -(-n // interval_samples))
    hh = n * dt / kk
    lg, lc = gauss_leads(kk, hh)
    off, w3 = _gauss3(dt)
    smp = (dt * np.arange(m))[:, None] + off[None, :]
    ls = smp.ravel()
    lf = 0.5 * hh * np.arange(2 * kk + 1)
    leads = np.concatenate((lg.ravel(), lc.ravel(), ls, lf))
    cuts = np.cumsum([lg.size, lc.size, ls.size])

    th = np.empty(total + 1)
    v = np.empty(total + 1)
    u_all = np.zeros(total)
    th[0], v[0] = float(theta0), float(theta_dot0)
    level = pump_level if torque_limit is None else min(torque_limit, pump_level)
    caught = None
    braking = False
    plan = None
    since = 0
    solve_times, forecast_times, update_times, iters = [], [], [], []
    failed = 0
    kept = 0  # failed solves whose iterate was not finite: the previous plan continued
    # a held torque over a whole turn resolves nothing (and the plant's RK4 steps then
    # exceed 2 pi / plant_steps rad): the run stops as unresolved
    max_speed = RESOLVED_TURN / dt
    status = "ok"
    t_samples = dt * np.arange(total + 1)
    q_samples = qp[::2 * plant_steps]
    tn = hh * np.arange(kk + 1)
    j = 0
    ticked = time.monotonic()
    while j < total:
        if progress is not None and time.monotonic() - ticked >= PROGRESS_EVERY:
            progress(j, total)
            ticked = time.monotonic()
        x = (th[j], v[j])
        if caught is None and ready_to_catch(x[0], x[1], CATCH_MARGIN):
            caught = j
        if caught is None:
            tq, braking = pump_torque(x[0], x[1], level, CATCH_MARGIN, braking)
            steps_now = 1
            seg = np.array([tq])
        elif plan is None or since >= m:
            if plan is not None and deadline is not None and time.monotonic() >= deadline:
                status, total = "time_limit", j  # before this update: a partial run
                break
            tj = t_samples[j]
            tu = time.perf_counter()
            if forecast is None:
                qall = np.asarray(qf(tj + leads), dtype=float)
            else:
                qall = np.asarray(forecast.predict(tj, t_samples[:j + 1], q_samples[:j + 1],
                                                   leads), dtype=float)
            forecast_times.append(time.perf_counter() - tu)
            qg, qc, qs, qfree = np.split(qall, cuts)
            pr = PlanProblem(x, hh, qg.reshape(lg.shape), qc.reshape(lc.shape), gamma,
                             torque_limit=torque_limit, efficiency=efficiency, kappa=kappa,
                             terminal=terminal, speed_limit=speed_limit,
                             speed_weight=speed_weight, plan_damping=plan_damping)
            anchor = None
            if torque_limit is not None or plan is None or not warm:
                fth, fv = free_motion(x, hh, kk, gamma, qfree)
                anchor = pr.start(fth, fv)
            if warm and plan is not None:
                # the previous plan shifted by the samples since it was made, continued at
                # its end speed (with a torque limit: by the unforced motion)
                s = tn + dt * since
                th_o, v_o, _ = plan.evaluate(s)
                beyond = s > plan.horizon * (1 + 1e-12)
                if torque_limit is None:
                    th_o = np.where(beyond, plan.theta[-1] + plan.v[-1] * (s - plan.horizon),
                                    th_o)
                    v_o = np.where(beyond, plan.v[-1], v_o)
                elif np.any(beyond):
                    # beyond the plan's end the unforced motion: strictly inside the limit
                    i0 = max(int(np.argmax(beyond)) - 1, 0)
                    fth, fv = free_motion((th_o[i0], v_o[i0]), hh, kk - i0, gamma,
                                          qfree[2 * i0:])
                    th_o[i0:], v_o[i0:] = fth, fv
                # the plan's angle continued through the measured one (whole turns)
                th_o = th_o + 2 * math.pi * round((x[0] - th_o[0]) / (2 * math.pi))
                start = pr.start(th_o, v_o)
            else:
                start = anchor
            t0 = time.perf_counter()
            sol = solve_plan(pr, start, anchor=anchor, maxiter=max_iter)
            solve_times.append(time.perf_counter() - t0)
            iters.append(int(sol.iterations))
            if not sol.success:
                failed += 1
            if np.all(np.isfinite(sol.x)):
                plan = sol.plan
            else:
                kept += 1
            since = 0
            u_open = plan.torque(smp, qs.reshape(m, -1)) @ w3  # the plan's sample means
            q_mean = qs.reshape(m, -1) @ w3
            update_times.append(time.perf_counter() - tu)
        if caught is not None:
            # the plan's held torque plus the tracking feedback on the measured state
            i = since
            tp_, vp_, _ = plan.evaluate(i * dt)
            e, ed = x[0] - float(tp_), x[1] - float(vp_)
            tq = float(u_open[i])
            if tracking:
                tq += (gamma * ed - (1.0 + q_mean[i]) * (math.sin(x[0]) - math.sin(float(tp_)))
                       - tracking**2 * e - 2.0 * tracking * ed)
            if torque_limit is not None:
                tq = min(max(tq, -torque_limit), torque_limit)
            seg = np.array([tq])
            steps_now = 1
        a = 2 * j * plant_steps
        qseg = qp[a:a + 2 * steps_now * plant_steps + 1]
        st, sv = np.empty(steps_now + 1), np.empty(steps_now + 1)
        ok = k.simulate(seg, th[j], v[j], qseg, hp, plant_steps, gamma, st, sv)
        u_all[j:j + steps_now] = seg
        th[j + 1:j + steps_now + 1] = st[1:]
        v[j + 1:j + steps_now + 1] = sv[1:]
        if not ok:
            status = "diverged"
            total = j + steps_now
            break
        if not np.max(np.abs(sv)) <= max_speed:
            status = "unresolved"
            total = j + steps_now
            break
        j += steps_now
        if plan is not None:
            since += steps_now
    th, v, u_all = th[:total + 1], v[:total + 1], u_all[:total]
    if progress is not None:
        progress(total, total)
    t = dt * np.arange(total + 1)
    p = -u_all * np.diff(th) / dt
    pe = _electrical(p, eta)
    acc = energy_account(t, th, v, p, pe, average_from, eta[0])
    mean_p, mean_e = acc["mean_power"], acc["mean_electrical_power"]
    st_arr = np.asarray(solve_times)
    if status == "ok" and not math.isfinite(mean_p):
        status = "nonfinite"
    success = status == "ok"
    done = (f"{len(solve_times)} horizon solves, {failed} not converged"
            + (f" (applied: the last iterate of {failed - kept}, the previous plan "
               f"continued for {kept})" if failed else ""))
    msg = {"ok": done,
           "diverged": "the closed loop diverged (|theta'| > 1e6)",
           "unresolved": (f"stopped at t = {t[-1]:.4g}: |theta'| reached "
                          f"{float(np.max(np.abs(v))):.4g}, more than a turn per held torque "
                          f"sample (dt = {dt:.4g}); the sampled loop does not resolve the "
                          f"motion, its numbers mean nothing; {done}"),
           "nonfinite": "non-finite power",
           "time_limit": (f"time limit reached at t = {t[-1]:.6g} of {t_end:.6g}, after "
                          f"{done} (a partial run: its powers over the samples run)")}[status]
    after = t >= (caught if caught is not None else total + 1) * dt - 1e-9 * dt
    speed = np.abs(v[after])
    exceed = peak = None
    if speed_limit is not None and speed.size:
        exceed = float(np.mean(speed > speed_limit))
        peak = float(np.max(speed))
    return MPCResult(
        t=t, theta=th, theta_dot=v, torque=u_all, power_series=p, electrical_series=pe,
        mean_power=mean_p, mean_electrical_power=mean_e,
        harvested_power=acc["harvested_power"],
        harvested_electrical_power=acc["harvested_electrical_power"],
        harvested_energy=acc["harvested_energy"],
        stored_energy_change=acc["stored_energy_change"],
        averaged_time=acc["averaged_time"],
        forecast_times=np.asarray(forecast_times), update_times=np.asarray(update_times),
        failed_kept_previous=kept, speed_exceeded_fraction=exceed, speed_peak=peak,
        plan_damping=plan_damping,
        energy=float(np.sum(p) * dt), solve_times=st_arr,
        iterations=np.asarray(iters, dtype=int), update_interval=m * dt, horizon=n * dt,
        dt=dt, gamma=gamma, torque_limit=torque_limit,
        efficiency=None if efficiency is None else tuple(eta),
        terminal_weight=kappa, average_from=float(average_from),
        catch_time=None if caught is None else float(caught * dt), solves=len(solve_times),
        failed_solves=failed, peak_torque=float(np.max(np.abs(u_all))) if total else 0.0,
        forecast="perfect" if forecast is None else type(forecast).__name__,
        success=success, status=status, message=msg, speed_limit=speed_limit)


# --- track --controller mpc ----------------------------------------------------------------
#: MPC torque samples per peak (forcing) period in ``track``
TRACK_SAMPLES = 64
#: periods at the start of a ``track`` run left out of its powers (swing-up and catch)
WARMUP_PERIODS = 10


def timing_summary(update_times, interval_s=None) -> dict:
    """Wall times (s) of the updates: the first apart (it loads or compiles the kernels),
    the median, 99th percentile and largest of the others; with the update interval in
    seconds, whether the 99th percentile fits in it (``realtime_fits``)."""
    ut = np.asarray(update_times, dtype=float)
    rest = ut[1:]
    out = {"update_time_first": float(ut[0]) if ut.size else None,
           "update_time_median": float(np.median(rest)) if rest.size else None,
           "update_time_p99": float(np.percentile(rest, 99)) if rest.size else None,
           "update_time_max": float(np.max(rest)) if rest.size else None}
    out["realtime_fits"] = (None if interval_s is None or out["update_time_p99"] is None
                            else bool(out["update_time_p99"] <= interval_s))
    return out


@dataclass(frozen=True, eq=False, repr=False)
class MPCTrackResult(_Result):
    """``parapend track --controller mpc`` (fields = JSON keys).

    Powers are over the run after the stated start-up (``warm_up_periods``, swing-up and
    catch): ``t`` from ``warm_up_periods`` forcing (peak) periods to the end.

    Attributes
    ----------
    mean_power : float
        The headline: (harvested energy + change of the stored energy) / time after the
        start-up (``energy_account``), the energy left in the pendulum counted as
        harvested and energy drawn from it as not; exact for the held torque.
    harvested_power : float
        The harvested energy alone over the same time (a storage swing moves it).
    harvested_energy, stored_energy_change, averaged_time : float
        ``W``, ``E(end) - E(start)`` (``E = theta'^2 / 2 + cos(theta)``, units ``m g l``)
        and the time, non-dimensional.
    electrical_power : float
        ``mean_power`` through the efficiency model (stored energy at ``eta_g``).
    record_power : float or None
        With ``irregular`` and at least ``warm_up_periods + 100`` periods: the same
        storage-corrected power over the last whole repeat of the record (100 peak
        periods), the number comparable with ``parapend sea`` on the same record.
    horizon, update_interval : float
        In peak (forcing) periods.
    update_time_first : float
        Wall time (s) of the first update (forecast + solve; it loads or compiles the
        kernels), reported apart.
    update_time_median, update_time_p99, update_time_max : float
        Wall time (s) of one update (forecast, problem, warm start, solve, held torques)
        over the updates after the first, on this process (the kernels are single-threaded).
    forecast_time_median, solve_time_median : float
        Their forecast and solve parts (median, after the first).
    realtime_fits : bool or None
        Whether ``update_time_p99`` fits in the update interval in seconds (with a device:
        ``length`` and ``mass``; None without).
    failed_solves, failed_kept_previous : int
        Solves that did not converge; of them, those whose iterate was not finite, after
        which the previous plan went on (the others applied their last iterate).
    speed_limit : float or None
        The plans' rated-speed penalty (not a hard bound).
    speed_exceeded_fraction, speed_peak : float or None
        With it: the fraction of samples after the hand-over with ``|theta'|`` above it,
        and the largest ``|theta'|`` there.
    """

    controller: str
    mean_power: float
    harvested_power: float
    harvested_energy: float
    stored_energy_change: float
    averaged_time: float
    warm_up_periods: int
    record_power: float | None
    electrical_power: float
    catch_period: float | None
    peak_torque: float
    horizon: float
    update_interval: float
    samples_per_period: int
    forecast: str
    terminal_weight: float
    plan_damping: float
    solves: int
    failed_solves: int
    failed_kept_previous: int
    update_time_first: float | None
    update_time_median: float | None
    update_time_p99: float | None
    update_time_max: float | None
    forecast_time_median: float | None
    solve_time_median: float | None
    iterations_median: float
    success: bool
    status: str
    message: str
    gamma: float
    omega: float
    torque_limit: float | None
    periods: int
    seed: int
    irregular: bool
    speed_limit: float | None = None
    speed_exceeded_fraction: float | None = None
    speed_peak: float | None = None
    excitation: dict = field(default_factory=dict)
    sea: dict | None = None
    units: dict | None = None
    mean_power_w: float | None = None
    harvested_power_w: float | None = None
    stored_energy_change_j: float | None = None
    record_power_w: float | None = None
    peak_torque_nm: float | None = None
    torque_limit_nm: float | None = None
    period_s: float | None = None
    update_interval_s: float | None = None
    realtime_fits: bool | None = None
    convention: str = ("theta from the upright (hanging at rest is theta = pi); power "
                       "positive when harvested, P = -<T theta'>; torque units m g l; "
                       "mean_power = (harvested energy + change of stored energy) / time "
                       "after warm_up_periods")
    _run: object = field(default=None, repr=False)
    _q: object = field(default=None, repr=False)

    command = "track"
    headline = ("mean_power", "mean_power_w", "harvested_power", "stored_energy_change",
                "record_power", "failed_solves", "status")

    def __post_init__(self):
        # with a device (``units``, added by dataclasses.replace) the SI fields and whether
        # the updates fit in its update interval in seconds
        if self.update_interval_s is not None and self.update_time_p99 is not None:
            object.__setattr__(self, "realtime_fits",
                               bool(self.update_time_p99 <= self.update_interval_s))
        if self.units is not None:
            from ..units import Units

            u = Units.from_description(self.units)
            object.__setattr__(self, "harvested_power_w", u.to_watts(self.harvested_power))
            object.__setattr__(self, "stored_energy_change_j",
                               u.to_joules(self.stored_energy_change))

    @property
    def run(self):
        """The receding-horizon run (:class:`MPCResult`: ``t``, ``theta``, ``theta_dot``,
        ``torque`` held over each sample, the power of each sample), non-dimensional."""
        return self._run

    def q(self, t):
        """The plant's excitation ``q(t)`` (base acceleration over g) at times ``t``."""
        return self._q(t)

    @property
    def physical_units(self):
        """The pendulum's :class:`~parapend.units.Units` (None without length and mass)."""
        from ..units import Units

        return Units.from_description(self.units)

    def _series(self):
        from ..results import series

        r = self._run
        pad = np.append  # the torque and power of sample k hold over [t_k, t_k+1)
        return series({"time": r.t, "theta": r.theta, "theta_dot": r.theta_dot,
                       "torque": pad(r.torque, np.nan), "sample_power": pad(r.power_series, np.nan),
                       "q": self._q(r.t)}, self.physical_units)

    def _figure(self):
        from ..units import si_figure
        from .figures import plot_mpc_track

        return si_figure(plot_mpc_track(self), self.physical_units)


def track_mpc(excitation, *, gamma, horizon=2.0, update_interval=0.03125, forecast="perfect",
              torque_limit=None, efficiency=None, periods=100, seed=0, irregular=False,
              theta0=math.pi, theta_dot0=0.0, terminal_weight=None,
              samples=TRACK_SAMPLES, terminal="energy", speed_limit=None,
              speed_weight=None, plan_damping=None, progress=None,
              time_limit=None) -> MPCTrackResult:
    """Receding-horizon control of the case ``excitation`` (or, with ``irregular``, of the
    seeded sea record of ``parapend.control.track.design_sea`` built from it, the same
    record as ``track --irregular`` with the same seed); ``horizon`` and ``update_interval``
    in forcing (peak) periods. The powers are over the run after ``WARMUP_PERIODS``
    (:class:`MPCTrackResult`). ``progress(done, total)``: in torque samples (:func:`mpc_run`);
    a run estimated to take more than ``ANNOUNCE_SECONDS`` is announced on ``log``. Without
    ``time_limit`` (s) a run estimated above ``parapend.limits.MAX_UNTIMED_SECONDS`` is
    refused; with it the run stops at its first update after the limit, marked
    "time_limit" (:mod:`parapend.deadline`)."""
    from .. import limits
    from ..deadline import check_time_limit, deadline, duration, refuse_untimed
    from .track import SEA_WAVES, _check_state, _on_grid, check_flag, design_sea

    time_limit = check_time_limit(time_limit)
    until = deadline(time_limit)
    theta0, theta_dot0 = _check_state((theta0, theta_dot0))
    irregular = check_flag("irregular", irregular)
    horizon = check_range("horizon", horizon, 0.01, 20.0)
    update_interval = check_range("update-interval", update_interval, 1.0 / samples, 20.0)
    if update_interval > horizon:
        raise ParameterError(f"update-interval: expected at most the horizon {horizon:g} "
                             f"peak periods, got {update_interval:g}")
    if forecast not in ("perfect", "ar"):
        raise ParameterError(f"forecast: expected perfect or ar, got {forecast!r:.40}")
    if progress is not None and not callable(progress):
        raise ParameterError(f"progress: expected a callable progress(done, total) or None, "
                             f"got {progress!r:.40}")
    tp = excitation.period
    omega = excitation.omega
    sea_info = None
    if irregular:
        rng = np.random.default_rng(seed)
        rms = math.sqrt(float(np.mean(excitation.q_uniform(1024) ** 2)))
        sea, sea_info = design_sea(omega, rms, int(rng.integers(0, 2**63 - 1)))
        # the seed the user gave; the record's phases come from the one it drew
        sea_info = {**sea_info, "seed": seed, "record_seed": sea_info["seed"]}
        qf = _on_grid(sea, SEA_WAVES * 2 * samples * PLANT_STEPS)
    else:
        qf = excitation.q
    fo = None
    if forecast == "ar":
        try:
            from .forecast import make_forecast
        except ImportError:
            raise ParameterError("forecast: 'ar' needs parapend.control.forecast, which this "
                                 "installation lacks") from None
        fo = make_forecast("ar", qf, tp)
    dt = tp / samples
    # the swing-up takes a few periods without solves; counted as updates here (an upper
    # bound)
    updates = math.ceil(periods / max(round(update_interval * samples), 1) * samples)
    each = update_seconds(horizon, torque_limit, forecast)
    est = updates * each
    most = int(limits.MAX_UNTIMED_SECONDS / (each * updates / periods))
    refuse_untimed("periods", f"a receding-horizon run of {periods} periods (about {updates} "
                   f"updates of a {horizon:g}-period horizon)", est,
                   f"use --periods at most {most}" if most >= 20 else
                   "use a shorter --horizon or a longer --update-interval", time_limit)
    if est > ANNOUNCE_SECONDS:
        log.info("track --controller mpc: %d periods = about %d updates of a %g-period "
                 "horizon (%s forecast): roughly %s on one core%s (the progress bar gives the "
                 "rate; Ctrl-C stops it)", periods, updates, horizon, forecast,
                 duration(est), "" if time_limit is None else
                 f", stopped after the time limit {time_limit:g} s")
    r = mpc_run(qf, gamma=gamma, horizon=horizon * tp, update_interval=update_interval * tp,
                dt=dt, torque_limit=torque_limit, efficiency=efficiency, forecast=fo,
                theta0=theta0, theta_dot0=theta_dot0, t_end=periods * tp, seed=seed,
                terminal_weight=terminal_weight, average_from=WARMUP_PERIODS * tp,
                terminal=terminal, speed_limit=speed_limit, speed_weight=speed_weight,
                plan_damping=plan_damping, progress=progress, deadline=until)
    record_power = None
    n_rec = SEA_WAVES * samples
    if irregular and r.power_series.size >= (SEA_WAVES + WARMUP_PERIODS) * samples:
        eg = 1.0 if r.efficiency is None else r.efficiency[0]
        record_power = energy_account(r.t, r.theta, r.theta_dot, r.power_series,
                                      r.electrical_series, r.t[-1 - n_rec], eg)["mean_power"]
    tm = timing_summary(r.update_times)
    rest = slice(1, None)
    return MPCTrackResult(
        controller="mpc", mean_power=r.mean_power, harvested_power=r.harvested_power,
        harvested_energy=r.harvested_energy, stored_energy_change=r.stored_energy_change,
        averaged_time=r.averaged_time, warm_up_periods=WARMUP_PERIODS,
        record_power=record_power, electrical_power=r.mean_electrical_power,
        catch_period=None if r.catch_time is None else r.catch_time / tp,
        peak_torque=r.peak_torque, horizon=r.horizon / tp,
        update_interval=r.update_interval / tp, samples_per_period=samples,
        forecast=forecast, terminal_weight=r.terminal_weight, plan_damping=r.plan_damping,
        solves=r.solves, failed_solves=r.failed_solves,
        failed_kept_previous=r.failed_kept_previous,
        update_time_first=tm["update_time_first"], update_time_median=tm["update_time_median"],
        update_time_p99=tm["update_time_p99"], update_time_max=tm["update_time_max"],
        forecast_time_median=(float(np.median(r.forecast_times[rest]))
                              if r.forecast_times.size > 1 else None),
        solve_time_median=(float(np.median(r.solve_times[rest]))
                           if r.solve_times.size > 1 else None),
        iterations_median=float(np.median(r.iterations)) if r.iterations.size else 0.0,
        success=r.success, status=r.status, message=r.message, gamma=r.gamma, omega=omega,
        torque_limit=torque_limit, periods=periods, seed=seed, irregular=bool(irregular),
        speed_limit=r.speed_limit, speed_exceeded_fraction=r.speed_exceeded_fraction,
        speed_peak=r.speed_peak, excitation=excitation.describe(), sea=sea_info, _run=r,
        _q=qf)
