"""``parapend.control.track``: put the pendulum on the optimal rotation from rest and hold it.

The pieces: the target orbit (:mod:`.target`: the optimum of :func:`parapend.optimize`, or
under a torque limit the torque-limited optimum of :func:`parapend.pto.optimize_pto`), the
periodic LQR (:mod:`.riccati`), the swing-up (:mod:`.swingup`) and the sampled closed loop on
the full nonlinear Eq. 14 (:mod:`.closedloop`).

Under a torque limit ``T_max`` the controller tracks the optimum computed for
``(1 - torque_margin) T_max``: on the torque-limited optimum the torque rides the limit on
arcs, where feedback has no authority in one direction; the margin keeps
``torque_margin T_max`` of authority everywhere. Its price is the difference between the
optimum at ``T_max`` (``optimum_at_torque_limit``) and the tracked one
(``predicted_power``), both reported.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import limits
from ..errors import ParameterError, SolverError, check_finite, check_int, check_range
from ..results import _Result
from .closedloop import Diverged, energy_series, mechanical_energy, run_closed_loop
from .riccati import periodic_lqr
from .target import build_target

__all__ = ["TrackResult", "design_sea", "lock_analysis", "prepare", "track"]

#: controller (and saved series) samples per forcing period
SAMPLES = 256
#: periods the mean power is averaged over (the last ones of the run)
AVERAGE_PERIODS = 10


@dataclass(frozen=True, eq=False, repr=False)
class TrackResult(_Result):
    """One closed-loop run (fields = JSON keys of ``parapend track --json``).

    Attributes
    ----------
    locked : bool
        The run ends locked: every one of at least the last ``10`` periods stays within
        ``lock_tolerance`` (rad) of the orbit (angle error wrapped to a turn).
    lock_period : int or None
        Number of forcing periods before the lock (the first period of the locked tail).
    catch_period : float or None
        Time (periods) when the swing-up handed over to tracking.
    mean_power : float
        From the lock to the end (not locked: over the last 10 periods): the harvested
        energy ``-sum T_k (theta_{k+1} - theta_k)`` (exact for the held torque; positive =
        harvested) plus the change of the pendulum's stored energy ``E = theta'^2 / 2 +
        cos(theta)`` over that span, divided by its duration.
    harvested_power : float
        The harvested energy alone over the same span, per unit time.
    stored_energy_change : float
        ``E(end) - E(start of the span)`` (m g l).
    average_start_period, averaged_periods : int
        The span: its first period (the lock period when locked) and its length.
    predicted_power : float
        Power of the optimum the controller tracks.
    optimum_at_torque_limit : float or None
        Power of the torque-limited optimum at ``torque_limit`` itself (when a margin was
        reserved; None otherwise).
    peak_torque : float
        Largest ``|T|`` applied during the run.
    sea : dict or None
        With ``irregular``: the sea record that drove the plant (:func:`design_sea`).
    tracked_peak_torque : float
        Peak torque of the tracked optimum.
    energy_before_lock : float or None
        Extracted energy up to the lock (negative: the energy spent on swing-up and catch).
    payback_periods : float or None
        Periods after the lock until the locked power has returned that energy
        (``-energy_before_lock / (mean_power * period)``; 0 if nothing was spent; None if
        not locked, or if energy was spent and the locked power is not positive).
    optimum_status : str
        Status of the tracked optimum's solve (``optimize`` or ``optimize_pto``):
        "converged", "no_power" (its power is not positive), "stalled", ...
    tracking_error : float
        Largest wrapped angle error over the last 10 periods (rad).
    open_loop_multipliers, closed_loop_multipliers : list of [re, im]
        Floquet multipliers of the orbit with the feedforward alone and with the periodic
        LQR feedback (largest modulus first).
    """

    locked: bool
    lock_period: int | None
    catch_period: float | None
    mean_power: float
    harvested_power: float
    stored_energy_change: float
    average_start_period: int
    averaged_periods: int
    predicted_power: float
    optimum_at_torque_limit: float | None
    peak_torque: float
    tracked_peak_torque: float
    energy_before_lock: float | None
    payback_periods: float | None
    tracking_error: float
    open_loop_multipliers: list
    closed_loop_multipliers: list
    optimum_status: str
    success: bool
    status: str
    message: str
    gamma: float
    omega: float
    torque_limit: float | None
    design_torque_limit: float | None
    periods: int
    samples_per_period: int
    lock_tolerance: float
    seed: int
    plant_gamma: float
    delta_error: float
    noise_theta: float
    noise_speed: float
    irregular: bool
    riccati_sweeps: int
    riccati_residual: float
    excitation: dict = field(default_factory=dict)
    sea: dict | None = None
    units: dict | None = None
    mean_power_w: float | None = None
    predicted_power_w: float | None = None
    peak_torque_nm: float | None = None
    torque_limit_nm: float | None = None
    period_s: float | None = None
    convention: str = ("theta from the upright (hanging at rest is theta = pi); power "
                       "positive when harvested, P = -<T theta'>; torque units m g l")
    _run: object = field(default=None, repr=False)
    _target: object = field(default=None, repr=False)
    _lqr: object = field(default=None, repr=False)

    command = "track"
    headline = ("mean_power", "mean_power_w", "predicted_power", "locked", "lock_period",
                "status")

    @property
    def run(self):
        """The closed-loop run (``parapend.control.closedloop.ClosedLoopRun``: ``t``,
        ``theta``, ``theta_dot``, ``torque``, ``q``, ``mode``), non-dimensional."""
        return self._run

    @property
    def target(self):
        """The target orbit (``parapend.control.target.Target``)."""
        return self._target

    @property
    def physical_units(self):
        """The pendulum's :class:`~parapend.units.Units` (None without length and mass)."""
        from ..units import Units

        return Units.from_description(self.units)

    def _series(self):
        from ..results import series

        r = self._run
        return series({"time": r.t, "theta": r.theta, "theta_dot": r.theta_dot,
                       "torque": r.torque, "q": r.q}, self.physical_units)

    def _figure(self):
        from ..units import si_figure
        from .figures import plot_track

        return si_figure(plot_track(self), self.physical_units)


def _multipliers(ev) -> list:
    return [[float(z.real), float(z.imag)] for z in ev]


@dataclass(frozen=True, eq=False)
class Design:
    """What a run needs besides the plant: target, gains, the optima's powers."""

    target: object
    lqr: object
    torque_limit: float | None
    design_limit: float | None
    optimum_at_torque_limit: float | None
    status: str
    message: str


def prepare(*, torque_limit=None, torque_margin: float = 0.1, r_weight: float = 0.1,
            **optimize_args) -> Design:
    """Target and periodic LQR gains for a case (``optimize_args`` as :func:`parapend.optimize`).

    Without a torque limit, or when the ideal optimum's peak torque is within
    ``(1 - torque_margin) torque_limit``, the ideal optimum is tracked; otherwise the
    torque-limited optimum at ``(1 - torque_margin) torque_limit``.
    """
    from ..api import optimize

    margin = check_range("torque-margin", torque_margin, 0.0, 0.9)
    r_weight = check_range("r-weight", r_weight, 1e-6, 1e6)
    if torque_limit is not None:
        torque_limit = check_range("torque-limit", torque_limit, 0.0, limits.MAX_TORQUE_LIMIT)
        if torque_limit <= 0:
            raise ParameterError(f"torque-limit: expected a number > 0, got {torque_limit!r}")
    ideal = optimize(**optimize_args)
    check_sampling(ideal._excitation, ideal.gamma)
    chosen, design, at_limit = ideal, None, None
    status, message = ideal.status, ideal.message
    if torque_limit is not None and ideal.peak_torque > (1 - margin) * torque_limit:
        # only optimize_pto(torque_limit=..., **optimize_args) and its result's power,
        # peak_torque, status, torque_limit and motion are relied on
        from ..pto import optimize_pto

        design = (1 - margin) * torque_limit
        chosen = optimize_pto(torque_limit=design, **optimize_args)
        status = chosen.status
        message = getattr(chosen, "message", status)
        if margin > 0:
            at_limit = optimize_pto(torque_limit=torque_limit, **optimize_args).power
    target = build_target(chosen, SAMPLES, excitation=ideal._excitation, gamma=ideal.gamma)
    lqr = periodic_lqr(target, r_weight=r_weight)
    return Design(target, lqr, torque_limit, design, at_limit, status, message)


#: largest relative model error of a plant (``gamma_error``, ``delta_error``)
MAX_MODEL_ERROR = 0.9


def check_sampling(exc, gamma: float) -> None:
    """Refuse a case whose plant the sampled loop cannot resolve.

    The controller samples ``SAMPLES`` times per forcing period, ``h = 2 pi/(omega SAMPLES)``,
    and the plant is integrated by RK4 over ``h/4``. Its fastest rates are the damping
    ``gamma`` and the frequency ``sqrt(1 + max|q|)`` of small swings about the top, each up
    to ``1 + MAX_MODEL_ERROR`` times larger in a plant with model error. Required:
    ``h * max(rates) <= limits.TRACK_MAX_STEP_RATE`` (at least 2 pi samples per fastest
    swing; ``omega = 1e-3`` with ``h = 24.5`` gave NaN gains, ``gamma = 1e3`` with
    ``h gamma = 13.6`` an unstable RK4 and a math domain error).
    """
    from ..excitation import max_abs_q

    f = 1.0 + MAX_MODEL_ERROR
    h = exc.period / SAMPLES
    qmax = max_abs_q(exc)
    swing = math.sqrt(1.0 + f * qmax)
    c = limits.TRACK_MAX_STEP_RATE
    if h * f * gamma > c and f * gamma >= swing:
        raise ParameterError(
            f"gamma: expected gamma <= {c / (f * h):.4g} for track at omega = {exc.omega:g} "
            f"(the sample interval 2 pi/({SAMPLES} omega) = {h:.3g} times the plant's "
            f"damping rate, up to {f:g} gamma with model error, must be at most {c:g}), got "
            f"{gamma:g}")
    if h * swing > c:
        omin = 2 * math.pi * swing / (SAMPLES * c)
        raise ParameterError(
            f"omega: expected omega >= {omin:.4g} for track with this excitation (max |q| = "
            f"{qmax:.4g}: the sample interval 2 pi/({SAMPLES} omega) = {h:.3g} times the "
            f"swing rate sqrt(1 + {f:g} max|q|) = {swing:.4g} must be at most {c:g}), got "
            f"{exc.omega:g}")


def lock_analysis(run, target, tol: float):
    """Per-period largest wrapped angle error, the lock period (None if the run does not end
    locked for at least ``AVERAGE_PERIODS`` periods) and the error over the last ones."""
    m = target.samples
    k = run.t.size - 1
    idx = np.arange(k)
    err = np.angle(np.exp(1j * (run.theta[:k] - target.theta[idx % m]
                                - 2 * math.pi * (idx // m))))
    per = np.abs(err).reshape(k // m, m).max(axis=1)
    bad = np.nonzero(per > tol)[0]
    first = 0 if bad.size == 0 else int(bad[-1]) + 1
    lock = first if per.size - first >= AVERAGE_PERIODS else None
    return per, lock, float(per[-AVERAGE_PERIODS:].max())


def _check_state(state0):
    """``(theta0, theta_dot0)`` as floats, each named in its message as the CLI names it."""
    try:
        th, om = state0
    except (TypeError, ValueError):
        raise ParameterError("state0: expected (theta0, theta_dot0), two numbers") from None
    return (check_range("theta0", th, 0.0, 1e3, absolute=True),
            check_range("theta-dot0", om, 0.0, 1e3, absolute=True))


def check_flag(name: str, value) -> bool:
    """``value`` as a bool: True, False (or a NumPy bool); anything else is refused (a
    string such as ``"no"`` would otherwise count as true)."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    raise ParameterError(f"{name}: expected True or False, got {value!r:.40}")


#: peak periods in one repeat of the irregular record (``T_r = SEA_WAVES T_p``)
SEA_WAVES = 100
#: peak period (s) of the sea state behind an irregular run; only a choice of time unit
#: (the record in the pendulum's units depends on ``omega`` and ``rms`` alone)
SEA_TP = 1.0


def design_sea(omega: float, rms: float, seed: int):
    """The irregular sea of a robustness run, in the pendulum's units: a JONSWAP record of
    :func:`parapend.seas.sea_record` (peak enhancement 3.3, cutoff 3 peak frequencies,
    ``SEA_WAVES`` peak periods per repeat, phases seeded ``seed``) whose peak frequency is
    the design frequency ``omega`` and whose ``q`` has the root mean square ``rms`` (that of
    the design excitation).

    ``sea_record`` takes a sea state in SI units and a pendulum; the record in non-dimensional
    time depends only on ``Tp / t0`` and ``Hs / (g t0^2)``. So the pendulum is the one whose
    time unit puts ``Tp = SEA_TP`` at ``omega``, ``t0 = Tp omega / 2 pi`` (a point mass of
    length ``g t0^2``), and ``Hs`` is set from the record's mean square, which is linear in
    ``Hs^2``: ``<q^2> = sum |Q_k|^2 / 2``. Returns the excitation and its description
    (``hs`` in units of ``g t0^2``, the pendulum length for a point mass).
    """
    from ..seas import sea_record, steepness_unchecked
    from ..units import STANDARD_GRAVITY, Units

    t0 = SEA_TP * omega / (2 * math.pi)
    units = Units(STANDARD_GRAVITY * t0**2, 1.0)

    def record(hs):
        with steepness_unchecked():  # a scaled q record, not a sea state in water
            return sea_record(units, hs=hs, tp=SEA_TP, spectrum="jonswap",
                              repeat_period=SEA_WAVES * SEA_TP, seed=seed)

    unit = record(1.0)
    hs = rms / math.sqrt(0.5 * float(np.sum(np.abs(unit.spec) ** 2)))
    if not limits.SEA_MIN_HS <= hs <= limits.SEA_MAX_HS:
        raise ParameterError(f"irregular: the design excitation's rms {rms:.3g} needs a sea "
                             f"state of Hs = {hs:.3g} m at Tp = {SEA_TP:g} s, outside "
                             f"[{limits.SEA_MIN_HS:g}, {limits.SEA_MAX_HS:g}] m")
    sea = record(hs)
    info = {"spectrum": "jonswap", "gamma_peak": 3.3, "peak_omega": omega,
            "hs": hs / units.length, "repeat_periods": SEA_WAVES,
            "components": sea.info["components"], "cutoff": sea.info["cutoff"],
            "seed": seed, "rms_q": rms}
    return sea, info


def _on_grid(sea, points: int):
    """``q`` of a periodic record as a vectorized function of time, exact on the grid of
    ``points`` uniform times per repeat (by one FFT, :meth:`Excitation.q_uniform`) and by the
    direct sum elsewhere. The closed loop asks for ``q`` at its RK4 half steps, which are
    this grid for ``points = 8 x samples`` per design period (4 RK4 steps per sample)."""
    table = sea.q_uniform(points)
    scale = points * sea.omega / (2 * math.pi)

    def q(t):
        t = np.asarray(t, dtype=float)
        x = t * scale
        j = np.rint(x)
        if np.all(np.abs(x - j) < 1e-6):
            return table[j.astype(np.int64) % points]
        return sea.q(t)

    return q


def simulate_design(d: Design, *, periods: int, seed: int = 0, gamma_error: float = 0.0,
                    delta_error: float = 0.0, noise_theta: float = 0.0,
                    noise_speed: float = 0.0, irregular: bool = False,
                    lock_tolerance: float = 0.1, state0=(math.pi, 0.0), rng=None):
    """One closed-loop run of a prepared design; returns ``(run, fields)``."""
    tg = d.target
    given = rng is None  # the run's generator is the user's seed (not a batch's stream)
    rng = np.random.default_rng(seed) if rng is None else rng
    plant_gamma = tg.gamma * (1.0 + gamma_error)
    sea_info = None
    if irregular:
        rms = math.sqrt(float(np.mean(tg.excitation.q_uniform(1024) ** 2)))
        sea, sea_info = design_sea(tg.omega, rms, int(rng.integers(0, 2**63 - 1)))
        if given:  # the seed the user gave; the record's phases come from the one it drew
            sea_info = {**sea_info, "seed": seed, "record_seed": sea_info["seed"]}
        base_q = _on_grid(sea, SEA_WAVES * 8 * tg.samples)
    else:
        base_q = tg.excitation.q
    scale = 1.0 + delta_error

    def plant_q(t):
        return scale * base_q(t)

    run = run_closed_loop(tg, d.lqr.gains, periods=periods, torque_limit=d.torque_limit,
                          plant_q=plant_q, plant_gamma=plant_gamma, state0=state0,
                          noise=(noise_theta, noise_speed), rng=rng)
    m = tg.samples
    w = energy_series(run)
    per, lock, err = lock_analysis(run, tg, lock_tolerance)
    # the account from the lock to the end (else the last AVERAGE_PERIODS periods): the
    # harvested energy plus the change of the pendulum's stored energy, per unit time
    start = lock if lock is not None else max(per.size - AVERAGE_PERIODS, 0)
    span = (per.size - start) * tg.period
    i0 = start * m
    harvested = float(w[-1] - w[i0])
    e = mechanical_energy(run)
    stored = float(e[-1] - e[i0])
    mean_power = (harvested + stored) / span
    catch = np.nonzero(run.mode)[0]
    e_lock = None if lock is None else float(w[lock * m])
    payback = None
    if e_lock is not None:
        # None: energy was spent and the locked power never returns it
        payback = 0.0 if e_lock >= 0 else (-e_lock / (mean_power * tg.period)
                                           if mean_power > 0 else None)
    fields = {"locked": lock is not None, "lock_period": lock,
              "catch_period": float(catch[0] / m) if catch.size else None,
              "mean_power": mean_power, "harvested_power": harvested / span,
              "stored_energy_change": stored, "average_start_period": start,
              "averaged_periods": per.size - start,
              "peak_torque": float(np.max(np.abs(run.torque))),
              "energy_before_lock": e_lock, "payback_periods": payback,
              "tracking_error": err, "plant_gamma": plant_gamma, "sea": sea_info}
    return run, fields


def track(*, torque_limit=None, torque_margin: float = 0.1, periods: int = 100,
          seed: int = 0, gamma_error: float = 0.0, delta_error: float = 0.0,
          noise_theta: float = 0.0, noise_speed: float = 0.0, irregular: bool = False,
          lock_tolerance: float = 0.1, r_weight: float = 0.1, theta0: float = math.pi,
          theta_dot0: float = 0.0, throw: bool = False, design=None,
          **optimize_args) -> TrackResult:
    """Swing up from ``(theta0, theta_dot0)`` (default hanging at rest), catch and hold the
    optimal rotation of a case under ``|T| <= torque_limit``; simulate ``periods`` forcing
    periods of the full nonlinear Eq. 14.

    Parameters
    ----------
    torque_limit : float or None
        ``T_max`` (units m g l); None: no saturation.
    torque_margin : float
        Fraction of ``T_max`` kept for feedback (module docstring), in [0, 0.9].
    periods : int
        Forcing periods simulated, in [20, 2000].
    seed : int
        Seeds the measurement noise and the irregular excitation.
    gamma_error, delta_error : float
        Model error: the plant's damping is ``gamma (1 + gamma_error)`` and its excitation
        ``(1 + delta_error) q(t)``, while the controller keeps the design model;
        each in [-0.9, 0.9].
    noise_theta, noise_speed : float
        Standard deviations of the Gaussian measurement noise on theta (rad) and theta'.
    irregular : bool
        The plant is driven by a seeded irregular sea (:func:`design_sea`: a JONSWAP record
        of :mod:`parapend.seas` peaked at the design frequency, with the design
        excitation's rms) instead of the design excitation.
    lock_tolerance : float
        Largest wrapped angle error (rad) of a locked period.
    r_weight : float
        Torque weight ``R`` of the LQR (``Q = I``).
    design : Design or None
        A design from :func:`prepare` to reuse (then the case, ``torque_limit``,
        ``torque_margin`` and ``r_weight`` come from it and are not given).
    **optimize_args
        The case, as :func:`parapend.optimize` (``gamma``, ``omega``, ``delta``,
        ``harmonics``, ``excitation``, ...).
    """
    periods = check_int("periods", periods, 2 * AVERAGE_PERIODS, limits.MAX_TRACK_PERIODS)
    seed = check_int("seed", seed, 0, 2**63 - 1)
    gamma_error = check_range("gamma-error", gamma_error, -0.9, 0.9)
    delta_error = check_range("delta-error", delta_error, -0.9, 0.9)
    noise_theta = check_range("noise-theta", noise_theta, 0.0, 1.0)
    noise_speed = check_range("noise-speed", noise_speed, 0.0, 10.0)
    lock_tolerance = check_range("lock-tolerance", lock_tolerance, 1e-6, math.pi)
    state0 = _check_state((theta0, theta_dot0))
    check_finite("r-weight", r_weight)
    d = _design(design, torque_limit, torque_margin, r_weight, optimize_args)
    return _result(d, periods=periods, seed=seed, gamma_error=gamma_error,
                   delta_error=delta_error, noise_theta=noise_theta, noise_speed=noise_speed,
                   irregular=check_flag("irregular", irregular),
                   lock_tolerance=lock_tolerance, state0=state0,
                   throw=throw)


def _design(design, torque_limit, torque_margin, r_weight, optimize_args) -> Design:
    if design is None:
        return prepare(torque_limit=torque_limit, torque_margin=torque_margin,
                       r_weight=r_weight, **optimize_args)
    if not isinstance(design, Design):
        raise ParameterError(f"design: expected a Design from prepare(), got "
                             f"{type(design).__name__}")
    if optimize_args or torque_limit is not None:
        raise ParameterError("design: a prepared design fixes the case and the torque "
                             "limit; drop " + ", ".join(sorted(optimize_args) or
                                                       ["torque_limit"]))
    return design


def _result(d: Design, *, periods, seed, gamma_error, delta_error, noise_theta, noise_speed,
            irregular, lock_tolerance, state0, throw, rng=None) -> TrackResult:
    tg = d.target
    failed = {"locked": False, "lock_period": None, "catch_period": None,
              "mean_power": math.nan, "harvested_power": math.nan,
              "stored_energy_change": math.nan, "average_start_period": 0,
              "averaged_periods": 0, "peak_torque": math.nan, "energy_before_lock": None,
              "payback_periods": None, "tracking_error": math.nan, "plant_gamma": math.nan}
    if d.status == "infeasible":
        msg = f"no rotation within the design torque limit: {d.message}"
        if throw:
            raise SolverError(f"track: {msg}")
        run, fields, status = None, failed, "infeasible"
    else:
        try:
            run, fields = simulate_design(d, periods=periods, seed=seed,
                                          gamma_error=gamma_error, delta_error=delta_error,
                                          noise_theta=noise_theta, noise_speed=noise_speed,
                                          irregular=irregular, lock_tolerance=lock_tolerance,
                                          state0=state0, rng=rng)
        except Diverged as exc:
            run, fields, status = None, failed, "diverged"
            msg = (f"the closed loop diverged after {exc.sample / tg.samples:.4g} periods "
                   "(|theta'| unbounded): the sampled controller does not hold this plant")
        else:
            status = "locked" if fields["locked"] else "not_locked"
            msg = (f"locked after {fields['lock_period']} periods and held to the end"
                   if fields["locked"] else
                   f"not locked: the last {AVERAGE_PERIODS} periods are not all within "
                   f"{lock_tolerance:g} rad of the orbit; more --periods, a larger "
                   "--torque-limit or --lock-tolerance")
        if throw and status != "locked":
            raise SolverError(f"track: {msg}")
    return TrackResult(
        **fields, predicted_power=tg.power, optimum_at_torque_limit=d.optimum_at_torque_limit,
        tracked_peak_torque=tg.peak_torque,
        open_loop_multipliers=_multipliers(d.lqr.open_loop_multipliers),
        closed_loop_multipliers=_multipliers(d.lqr.closed_loop_multipliers),
        optimum_status=d.status, success=status == "locked", status=status, message=msg,
        gamma=tg.gamma, omega=tg.omega, torque_limit=d.torque_limit,
        design_torque_limit=d.design_limit,
        periods=periods, samples_per_period=tg.samples, lock_tolerance=lock_tolerance,
        seed=seed, delta_error=delta_error, noise_theta=noise_theta,
        noise_speed=noise_speed, irregular=irregular, riccati_sweeps=d.lqr.sweeps,
        riccati_residual=d.lqr.residual, excitation=tg.excitation.describe(),
        _run=run, _target=tg, _lqr=d.lqr)
