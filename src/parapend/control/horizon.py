r"""The horizon curve: mean power of causal control against the forecast horizon.

For a sea state and a pendulum (as :func:`parapend.irregular.sea` takes them), over
``records`` seeded records (seeds ``seed .. seed + records - 1``), each one repeat
``T_r`` long, run from the hanging rest:

- the receding-horizon controller (:func:`parapend.control.mpc.mpc_run`) with each forecast
  (:mod:`.forecast`: "perfect", the record's own future, and "ar", the autoregressive
  predictor fitted on the past) at each horizon (in peak periods);
- the causal baselines (:mod:`.baselines`: the regular-wave "tracker" and the half-turn
  rule "extremum");

and report each run's mean electrical power over the whole record (start-up from rest
included; with ``warm_up``, over one whole repeat after it), storage-corrected: the
harvested energy plus the change of the pendulum's stored energy ``E = theta'^2 / 2 +
cos(theta)`` (at ``eta_g``) per unit time, the change reported beside it, as a fraction of
the record's non-causal optimum (``sea`` on the same record:
the best periodic rotation knowing every wave) and of its ``gamma -> 0`` limit. Beside them,
the autoregressive forecast's normalized rms prediction error against lead time on the same
records.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import limits
from ..defaults import HORIZON, SEA
from ..errors import ParameterError, check_int, check_positive, check_range
from ..results import _Result
from .curve_options import MAX_RECORDS, _horizons, _names, _stats, update_time_stats

__all__ = ["HorizonResult", "horizon_curve", "plot_horizon", "horizon_dataset"]

#: lead times (peak periods) of the reported AR prediction error
AR_LEADS = (0.0, 0.05, 0.1, 0.25, 0.5, 1.0, 2.0)


@dataclass(frozen=True, eq=False, repr=False)
class HorizonResult(_Result):
    """Mean power against horizon (fields = JSON keys of ``parapend horizon --json``).

    Powers are non-dimensional (``m g l / t0``) and in watts (``*_w``). Indices: ``[f][h][r]``
    for forecast ``forecasts[f]``, horizon ``horizons[h]`` (peak periods), record ``r``
    (seed ``seeds[r]``); ``[b][r]`` for baseline ``baselines[b]``.

    Attributes
    ----------
    mpc_power, baseline_power : nested lists of float
        Mean electrical power of each run over the record (NaN: the run failed),
        storage-corrected: ``(W_e + eta_g dE) / time``.
    mpc_harvested_power, baseline_harvested_power : nested lists of float
        The harvested electrical energy alone per unit time (no storage correction).
    mpc_stored_energy_change, baseline_stored_energy_change : nested lists of float
        ``dE = E(end) - E(start)`` of each run (units ``m g l``; ``*_j``: joules).
    mpc_update_time_first, mpc_update_time_median, mpc_update_time_p99, mpc_update_time_max :
        ``[f][h]``: wall time (s) of one receding-horizon update (forecast + solve), the
        first update of the first record apart (kernel load), the others pooled over the
        records.
    update_interval_s : float
        The update interval in seconds for this pendulum; ``realtime_fits``: whether every
        ``mpc_update_time_p99`` fits in it (measured on one process).
    mpc_failed_solves : nested list of int ``[f][h][r]``
        Horizon solves that did not converge (the last iterate applied, or the previous
        plan where that was not finite); ``mpc_failed_kept_previous``: of them, those after
        which the previous plan went on.
    mpc_speed_exceeded_fraction, mpc_speed_peak : nested lists ``[f][h][r]``
        With ``speed_limit`` (a penalty, not a hard bound): the fraction of samples after
        the hand-over with ``|theta'|`` above it and the largest ``|theta'|``.
    optimum_power, limit_power : list of float
        Per record: the non-causal optimum of ``sea`` and the ``gamma -> 0`` limit.
    mpc_fraction, baseline_fraction : nested lists of float
        Power over the record's optimum.
    mpc_fraction_mean, mpc_fraction_min, mpc_fraction_max : ``[f][h]`` over the records.
    baseline_fraction_mean, baseline_fraction_min, baseline_fraction_max : ``[b]``.
    mpc_limit_fraction_mean, baseline_limit_fraction_mean : the same over the limit.
    mpc_status : nested list of str ``[f][h][r]``; the solver's status of each run.
    ar_leads, ar_error : lead times (peak periods) and the AR forecast's normalized rms
        error at each (over the records; 1 is the error of predicting 0), when "ar" is
        among the forecasts.
    mpc_horizon_used : nested list of float ``[f][h]``
        The horizon the controller planned over (peak periods): the one asked for, or
        the forecast's reach where that is shorter (an ``ARForecast`` given
        ``reach_periods``).
    """

    horizons: list
    forecasts: list
    baselines: list
    seeds: list
    mpc_power: list
    baseline_power: list
    optimum_power: list
    limit_power: list
    mpc_fraction: list
    baseline_fraction: list
    mpc_fraction_mean: list
    mpc_fraction_min: list
    mpc_fraction_max: list
    baseline_fraction_mean: list
    baseline_fraction_min: list
    baseline_fraction_max: list
    mpc_limit_fraction_mean: list
    baseline_limit_fraction_mean: list
    mpc_status: list
    baseline_status: list
    ar_leads: list
    ar_error: list
    peak_period: float
    update_interval: float
    gamma: float
    torque_limit: float | None
    efficiency: float | None
    record: dict
    units: dict
    success: bool
    status: str
    message: str
    warm_up: float = 0.0
    speed_limit: float | None = None
    optimum_power_w: list = field(default_factory=list)
    limit_power_w: list = field(default_factory=list)
    mpc_power_w: list = field(default_factory=list)
    baseline_power_w: list = field(default_factory=list)
    mpc_horizon_used: list = field(default_factory=list)
    mpc_harvested_power: list = field(default_factory=list)
    mpc_stored_energy_change: list = field(default_factory=list)
    mpc_stored_energy_change_j: list = field(default_factory=list)
    baseline_harvested_power: list = field(default_factory=list)
    baseline_stored_energy_change: list = field(default_factory=list)
    baseline_stored_energy_change_j: list = field(default_factory=list)
    mpc_update_time_first: list = field(default_factory=list)
    mpc_update_time_median: list = field(default_factory=list)
    mpc_update_time_p99: list = field(default_factory=list)
    mpc_update_time_max: list = field(default_factory=list)
    update_interval_s: float | None = None
    realtime_fits: bool | None = None
    mpc_failed_solves: list = field(default_factory=list)
    mpc_failed_kept_previous: list = field(default_factory=list)
    mpc_speed_exceeded_fraction: list = field(default_factory=list)
    mpc_speed_peak: list = field(default_factory=list)
    convention: str = ("power positive when harvested; (harvested energy + change of the "
                       "stored energy theta'^2/2 + cos(theta), at eta_g) per unit time over "
                       "the whole record from the hanging rest, the receding horizon's over "
                       "one repeat after warm_up; fractions of the record's non-causal "
                       "optimum from sea and of its gamma -> 0 limit")

    command = "horizon"
    headline = ("horizons", "mpc_fraction_mean", "baseline_fraction_mean", "status")

    def _series(self):
        return horizon_dataset(self)

    def _figure(self):
        return plot_horizon(self)


#: rough wall time (s) per peak period of a record of its non-causal optimum (``sea``) and of
#: each baseline, for the estimate: one record with both baselines took 2.8 s (20 waves), 5.7
#: s (20 waves, a torque limit and an efficiency) and 16 s (100 waves) on 2 cores at a load
#: of 4; ``RECORD_SECONDS * (1 + baselines)`` a peak period counts 6 s and 30 s
RECORD_SECONDS = 0.1


def _longest_record(exc, warm_up, tp_n, mpc_est, rec_est, cap) -> float:
    """The longest record (pendulum time) one record's estimate fits in ``cap`` seconds with:
    ``mpc_est`` (s, its receding-horizon runs) is in proportion to each run's length, the
    record ``exc`` plus the warm-up, ``rec_est`` (its optimum and baselines) to the record's."""
    run, rec = exc.period + warm_up * tp_n, exc.period
    a, b = mpc_est / run, rec_est / rec  # seconds per unit time of run and of record
    return max((cap - a * warm_up * tp_n) / (a + b), 0.0)


def horizon_curve(*, hs=None, tp=None, spectrum: str = "jonswap", gamma_peak: float = 3.3,
                  repeat_period=None, seed=None, cutoff: float = 3.0,
                  length=None, mass=None, inertia=None,
                  gravity=None, gamma=None, damping_coefficient=None,
                  torque_limit=None, torque_limit_nm=None, efficiency=None,
                  horizons=None, forecasts=HORIZON["forecasts"],
                  baselines=None, records: int = HORIZON["records"],
                  update_interval=None, progress=None,
                  warm_up=None, speed_limit=HORIZON["speed_limit"], time_limit=None,
                  device: str = "pendulum", body=None, radius=None, draft=None, mesh=None,
                  hydro=None, planner=None, dofs=None, controller=None, sea=None,
                  pendulum=None, pto=None):
    """Mean power of causal control against the horizon, as a fraction of the record's
    non-causal optimum and of its limit (command ``horizon``: ``parapend.horizon`` is this
    function; module docstring). With ``device="buoy"``: the pendulum inside the floating
    buoy (:func:`parapend.hydro.horizon.buoy_horizon_curve`, a
    :class:`~parapend.hydro.horizon.BuoyHorizonResult`).

    Parameters
    ----------
    device : "pendulum" or "buoy"
        The prescribed-heave pendulum (default) or the pendulum inside the buoy, coupled
        both ways (``parapend buoy``'s body and pendulum, in SI; the options below marked
        pendulum only are refused with it).
    body, radius, draft, mesh, hydro, planner :
        ``device="buoy"`` only: the floating body as ``parapend buoy`` takes it, and the
        planner of :func:`parapend.hydro.control.buoy_mpc` (``"coupled"`` or ``"plan"``;
        None: its default; the result's ``planner``).
    controller : None or Controller
        The planner's former name, refused in one line that names ``planner``
        (``controller`` is ``parapend buoy``'s optimum, mpc or one-way-mpc); a
        :class:`~parapend.hydro.device.Controller` gives its update interval.
    sea, pendulum, body, pto, device : the input objects of :mod:`parapend.hydro.device`
        (``device`` a ``Device``: ``device="buoy"`` with its body, pendulum and take-off), as
        :func:`parapend.buoy` takes them: their fields are the keywords here.
    dofs : ``device="buoy"`` only: the body's degrees of freedom, ``"heave"`` (default,
        the heaving buoy) or ``"surge,heave,pitch"``: the hull's controller
        (``parapend.hydro.hull_control.hull_mpc``) against the horizon, on the hull's
        own defaults (the embedded barge, 4-peak-period records).
    hs, tp, spectrum, gamma_peak, repeat_period, seed, cutoff :
        The sea state (:func:`parapend.seas.sea_record`; ``repeat_period`` in s, default
        ``20 tp``, ``parapend.defaults.HORIZON["repeat_periods"]`` peak periods, not ``sea``'s
        100); record ``r`` has the seed ``seed + r``. ``hs``, ``tp``, ``seed`` None:
        2 m, 8 s, 0 (``parapend.defaults.SEA``).
    length, mass, inertia, gravity, gamma, damping_coefficient :
        The pendulum, as :func:`parapend.irregular.sea` (default 1 m, 10 kg, ``gravity``
        9.81, ``gamma = 0.01``; the buoy's: ``parapend buoy``'s design, in SI, with
        ``damping_coefficient``; ``gravity`` and ``gamma`` pendulum only).
    torque_limit : float or None
        ``T_max`` (units ``m g l``) for every controller.
    torque_limit_nm : float or None
        The torque limit in N m instead (not both).
    efficiency : float or None
        PTO efficiency (generating and motoring) as :mod:`parapend.pto`, for every
        controller; the optimum and the limit stay mechanical.
    horizons : str or sequence of float
        Horizons in peak periods (0.05 to 20; default ``HORIZON["horizons"]``, the buoy's
        ``parapend.hydro.horizon.BUOY_HORIZON["horizons"]``).
    forecasts, baselines : str or sequence of str
        Subsets of ("perfect", "ar") and ("tracker", "extremum"); "none" for neither
        (default ``HORIZON``'s; baselines pendulum only).
    records : int
        Seeded records, 1 to 20.
    update_interval : float
        MPC update interval in peak periods (default ``HORIZON["update_interval"]``, the
        buoy's 0.125).
    progress : callable or None
        Called ``progress(done, total)`` as the work goes, in torque samples (64 a peak
        period): every run counts its samples (the non-causal optimum and each baseline
        the record's); within a receding-horizon run at most every 0.25 s. A curve estimated
        to take more than 30 s (``time_limit``) is announced on the
        ``parapend.control`` logger (INFO) before any work.
    warm_up : float
        Peak periods of the receding-horizon runs left out of their mean (start-up from
        rest); the run is then ``warm_up`` plus one whole repeat of the record long, so the
        mean is over one repeat (the baselines still average the whole record from rest).
        Default 0, the buoy's 4.
    speed_limit : float or None
        Rated-speed penalty of the receding-horizon plans, not a hard bound (its exceedance
        is reported; units ``sqrt(g / l)``;
        :func:`parapend.control.mpc.mpc_run`); None: none. Pendulum only.
    time_limit : float or None
        Seconds for the whole curve: without it, a curve estimated above
        ``parapend.limits.MAX_UNTIMED_SECONDS`` (its receding-horizon updates at
        :func:`parapend.control.mpc.update_seconds`, its records' optima and baselines at
        ``RECORD_SECONDS`` a peak period each) is refused, naming the most records that fit
        or the longest record; with it the work stops at the first run (a record's optimum,
        receding-horizon run or baseline) after the limit: the runs not finished are NaN
        with the status ``"time_limit"``, and the result's ``status`` is ``"time_limit"``
        (``success`` False; :mod:`parapend.deadline`).
    """
    if _has_inputs(locals()):  # the input objects of parapend.hydro.device
        return horizon_curve(**_expanded(locals()))
    if controller is not None:
        raise ParameterError("controller: renamed planner here (--planner coupled|plan; "
                             "--controller is parapend buoy's optimum|mpc|one-way-mpc)")
    if device == "buoy":
        return _buoy(locals())
    if device != "pendulum":
        raise ParameterError(f"device: expected pendulum or buoy, got {device!r:.40}")
    for name in ("body", "radius", "draft", "mesh", "hydro", "planner", "dofs"):
        if locals()[name] is not None:
            raise ParameterError(f"{name}: an option of the buoy; needs --device buoy")
    length = SEA["length"] if length is None else length
    mass = SEA["mass"] if mass is None else mass
    gravity = SEA["gravity"] if gravity is None else gravity
    horizons = HORIZON["horizons"] if horizons is None else horizons
    baselines = HORIZON["baselines"] if baselines is None else baselines
    update_interval = HORIZON["update_interval"] if update_interval is None else update_interval
    warm_up = HORIZON["warm_up"] if warm_up is None else warm_up
    from ..deadline import check_time_limit, deadline, duration, expired, refuse_untimed
    from ..irregular import sea
    from ..seas import sea_record
    from ..units import Units
    from .baselines import BASELINES, extremum_baseline, tracker_baseline
    from .forecast import FORECASTS, ARForecast, prediction_error
    from .mpc import stored_energy

    time_limit = check_time_limit(time_limit)
    until = deadline(time_limit)
    units = Units(length, mass, gravity, inertia)
    hs = SEA["hs"] if hs is None else hs
    tp = SEA["tp"] if tp is None else tp
    seed = SEA["seed"] if seed is None else seed
    if repeat_period is None:  # the curve's own record length, not sea's 100 waves
        from ..seas import _check_sea

        tp = _check_sea(hs, tp, spectrum, gamma_peak, None, cutoff)[1]
        repeat_period = HORIZON["repeat_periods"] * tp
    if torque_limit_nm is not None:
        if torque_limit is not None:
            raise ParameterError("torque-limit-nm: give either --torque-limit or "
                                 "--torque-limit-nm, not both")
        torque_limit = units.from_newton_metres(
            check_positive("torque-limit-nm", torque_limit_nm))
    if gamma is not None and damping_coefficient is not None:
        raise ParameterError("gamma: give either gamma or damping-coefficient, not both")
    if damping_coefficient is not None:
        gamma = units.gamma(damping_coefficient)
    gamma = check_range("gamma", 0.01 if gamma is None else gamma, 0.0, limits.MAX_GAMMA)
    if progress is not None and not callable(progress):
        raise ParameterError(f"progress: expected a callable progress(done, total) or None, "
                             f"got {progress!r:.40}")
    hz = _horizons(horizons)
    fc = _names(forecasts, FORECASTS, "forecasts")
    bl = _names(baselines, BASELINES, "baselines")
    if not fc and not bl:
        raise ParameterError("forecasts: expected at least one forecast or baseline, got none")
    records = check_int("records", records, 1, MAX_RECORDS)
    seed = check_int("seed", seed, 0, 2**63 - 1 - MAX_RECORDS)
    upd = check_range("update-interval", update_interval, 1e-3, 1.0)
    warm_up = check_range("warm-up", warm_up, 0.0, 100.0)
    if speed_limit is not None:
        speed_limit = check_range("speed-limit", speed_limit, 1e-9, 1e6)
    if torque_limit is not None:
        torque_limit = check_range("torque-limit", torque_limit, 0.0, limits.MAX_TORQUE_LIMIT)
        if torque_limit <= 0:
            raise ParameterError(f"torque-limit: expected a number > 0, got {torque_limit!r}")
    eff = None
    if efficiency is not None:
        from ..pto import efficiencies

        eff = efficiencies(efficiency)
    sea_kw = dict(hs=hs, tp=tp, spectrum=spectrum, gamma_peak=gamma_peak,
                  repeat_period=repeat_period, cutoff=cutoff)
    excs = [sea_record(units, seed=seed + r, **sea_kw) for r in range(records)]
    tp_n = tp / units.time
    wp = 2 * math.pi / tp_n
    # progress and the estimate in torque samples (dt = tp_n / 64) of every run
    rec_samples = [int(math.floor(exc.period / (tp_n / 64) + 1e-9)) for exc in excs]
    mpc_samples = [int(math.floor((exc.period + warm_up * tp_n) / (tp_n / 64) + 1e-9))
                   for exc in excs]
    total = (sum(rec_samples) * (1 + len(bl)) + sum(mpc_samples) * len(fc) * len(hz))
    done = 0

    def tick(samples):
        nonlocal done
        done += samples
        if progress is not None:
            progress(done, total)

    def within(now, _total):
        if progress is not None:
            progress(done + now, total)

    from .mpc import ANNOUNCE_SECONDS, log, update_seconds

    upd_samples = max(1, round(upd * 64))
    # the estimate: the receding-horizon updates, and each record's optimum and baselines
    per_update = sum(update_seconds(h, torque_limit, f) for f in fc for h in hz)
    mpc_est = [math.ceil(n / upd_samples) * per_update for n in mpc_samples]
    rec_est = [RECORD_SECONDS * (1 + len(bl)) * exc.period / tp_n for exc in excs]
    est = sum(mpc_est) + sum(rec_est)
    cap = limits.MAX_UNTIMED_SECONDS
    most = int(cap / (est / records))
    longest = _longest_record(excs[0], warm_up, tp_n, mpc_est[0], rec_est[0], cap) * units.time
    what = (f"{records} record(s) x {len(fc)} forecast(s) x {len(hz)} horizon(s) of "
            f"receding-horizon runs, {math.ceil(mpc_samples[0] / upd_samples)} updates each, "
            "with the records' optima and baselines," if fc else
            f"{records} record(s) of {excs[0].period / tp_n:.4g} peak periods (their optima "
            "and baselines)")
    refuse_untimed("records" if most >= 1 else "repeat-period", what, est,
                   f"use --records at most {most}" if most >= 1 else
                   f"use --repeat-period at most {longest:.4g} s (one record)"
                   + (", or fewer --horizons or --forecasts" if fc else ""),
                   time_limit, cap)
    if est > ANNOUNCE_SECONDS:
        log.info("horizon: %s: roughly %s on one core%s (the progress bar gives the rate; "
                 "Ctrl-C stops it)", what.rstrip(","), duration(est),
                 "" if time_limit is None else
                 f" (stopped after the time limit {time_limit:g} s)")
    runs_done = [0]  # runs finished; the time limit is checked before each next one
    stopped = [False]

    def out_of_time() -> bool:
        if not stopped[0] and runs_done[0] and expired(until):
            stopped[0] = True
        return stopped[0]

    opt, lim = [], []
    for r in range(records):
        if out_of_time():
            opt.append(math.nan)
            lim.append(math.nan)
            continue
        s = sea(seed=seed + r, length=length, mass=mass, inertia=inertia, gravity=gravity,
                gamma=gamma, **sea_kw)
        opt.append(s.power)
        lim.append(s.limit_power)
        runs_done[0] += 1
        tick(rec_samples[r])
    mpc_p = [[[math.nan] * records for _ in hz] for _ in fc]
    mpc_st = [[[""] * records for _ in hz] for _ in fc]
    mpc_w, mpc_de, mpc_fail, mpc_kept, mpc_xf, mpc_xp = (
        [[[math.nan] * records for _ in hz] for _ in fc] for _ in range(6))
    times = [[[] for _ in hz] for _ in fc]
    first = [[math.nan for _ in hz] for _ in fc]
    used = [[h for h in hz] for _ in fc]
    if fc:
        from .mpc import mpc_run

        for i, name in enumerate(fc):
            for j, h in enumerate(hz):
                for r, exc in enumerate(excs):
                    if out_of_time():
                        mpc_st[i][j][r] = "time_limit"
                        continue
                    fo = None if name == "perfect" else ARForecast(tp_n)
                    res = mpc_run(exc.q, gamma=gamma, horizon=h * tp_n,
                                  update_interval=upd * tp_n, dt=tp_n / 64,
                                  average_from=warm_up * tp_n,
                                  torque_limit=torque_limit, efficiency=eff,
                                  forecast=fo, t_end=exc.period + warm_up * tp_n, seed=seed + r,
                                  speed_limit=speed_limit, progress=within,
                                  deadline=until)
                    if res.status == "time_limit":  # cut short: not a finished run
                        stopped[0] = True
                    else:
                        runs_done[0] += 1
                    mpc_p[i][j][r] = (float(res.mean_electrical_power) if res.success
                                      else math.nan)
                    mpc_st[i][j][r] = str(res.status)
                    if res.success:
                        mpc_w[i][j][r] = float(getattr(res, "harvested_electrical_power",
                                                       math.nan))
                        mpc_de[i][j][r] = float(getattr(res, "stored_energy_change", math.nan))
                    mpc_fail[i][j][r] = int(getattr(res, "failed_solves", 0))
                    mpc_kept[i][j][r] = int(getattr(res, "failed_kept_previous", 0))
                    mpc_xf[i][j][r] = getattr(res, "speed_exceeded_fraction", None)
                    mpc_xp[i][j][r] = getattr(res, "speed_peak", None)
                    ut = np.asarray(getattr(res, "update_times", ()), dtype=float)
                    if ut.size:
                        if r == 0:
                            first[i][j] = float(ut[0])
                        times[i][j].append(ut[1:] if r == 0 else ut)
                    used[i][j] = float(getattr(res, "horizon", h * tp_n)) / tp_n
                    tick(mpc_samples[r])
    base_p = [[math.nan] * records for _ in bl]
    base_st = [[""] * records for _ in bl]
    base_w = [[math.nan] * records for _ in bl]
    base_de = [[math.nan] * records for _ in bl]
    eta_g = 1.0 if eff is None else float(eff[0])
    for b, name in enumerate(bl):
        fn = tracker_baseline if name == "tracker" else extremum_baseline
        for r, exc in enumerate(excs):
            if out_of_time():
                base_st[b][r] = "time_limit"
                continue
            run = fn(exc.q, peak_omega=wp, gamma=gamma, t_end=exc.period,
                     torque_limit=torque_limit, efficiency=efficiency)
            if run.success:
                # the stored energy's change over the record, counted at eta_g
                de = float(stored_energy(run.theta[-1], run.theta_dot[-1])
                           - stored_energy(run.theta[0], run.theta_dot[0]))
                span = float(run.t[-1] - run.t[0])
                base_w[b][r] = float(run.mean_power)
                base_de[b][r] = de
                base_p[b][r] = float(run.mean_power) + eta_g * de / span
            base_st[b][r] = run.status
            runs_done[0] += 1
            tick(rec_samples[r])
    leads, err = [], []
    if "ar" in fc and not stopped[0]:  # (a partial curve: not after the time limit)
        leads = list(AR_LEADS)
        errs = [prediction_error(ARForecast(tp_n), exc.q, t_start=min(45 * tp_n,
                                 0.5 * exc.period), t_end=exc.period, dt=tp_n / 64,
                                 leads=tp_n * np.asarray(leads), origins=100)
                for exc in excs]
        err = [float(v) for v in np.mean(errs, axis=0)]
    o = np.asarray(opt)
    li = np.asarray(lim)
    mf = (np.asarray(mpc_p) / o).tolist() if fc else []
    bf = (np.asarray(base_p) / o).tolist() if bl else []
    mst = [[_stats(np.asarray(mpc_p[i][j]) / o) for j in range(len(hz))]
           for i in range(len(fc))]
    bst = [_stats(np.asarray(base_p[b]) / o) for b in range(len(bl))]
    nan_runs = int(np.sum(~np.isfinite(np.asarray(mpc_p)))) if fc else 0
    nan_runs += int(np.sum(~np.isfinite(np.asarray(base_p)))) if bl else 0
    ok = nan_runs == 0 and not stopped[0]
    msg = (f"{records} record(s) of {excs[0].period * units.time:g} s; "
           + ("every run finished" if ok else f"{nan_runs} run(s) failed (NaN power)"))
    if stopped[0]:
        runs = records * (1 + len(fc) * len(hz) + len(bl))
        msg = (f"time limit reached ({time_limit:g} s): {runs_done[0]} of {runs} runs "
               f"finished (the records' optima, {len(fc) * len(hz)} receding-horizon runs "
               f"and {len(bl)} baseline(s) per record), the rest NaN with the status "
               f"time_limit; a partial curve of {records} record(s) of "
               f"{excs[0].period * units.time:g} s")
    rec = {k: v for k, v in excs[0].describe().items() if k not in ("omega", "seed")}
    w = units.to_watts
    t_med, t_p99, t_max = update_time_stats(times, len(fc), len(hz))
    upd_s = upd * tp
    fits = None
    if fc and np.all(np.isfinite(t_p99)):
        fits = bool(np.max(t_p99) <= upd_s)
    joules = units.to_joules

    def opt_list(a):
        return [[[None if v is None or (isinstance(v, float) and math.isnan(v)) else v
                  for v in col] for col in row] for row in a]

    return HorizonResult(
        horizons=hz, forecasts=fc, baselines=bl, seeds=[seed + r for r in range(records)],
        mpc_power=mpc_p, baseline_power=base_p, optimum_power=opt, limit_power=lim,
        mpc_fraction=mf, baseline_fraction=bf,
        mpc_fraction_mean=[[m[0] for m in row] for row in mst],
        mpc_fraction_min=[[m[1] for m in row] for row in mst],
        mpc_fraction_max=[[m[2] for m in row] for row in mst],
        baseline_fraction_mean=[m[0] for m in bst],
        baseline_fraction_min=[m[1] for m in bst],
        baseline_fraction_max=[m[2] for m in bst],
        mpc_limit_fraction_mean=[[_stats(np.asarray(mpc_p[i][j]) / li)[0]
                                  for j in range(len(hz))] for i in range(len(fc))],
        baseline_limit_fraction_mean=[_stats(np.asarray(base_p[b]) / li)[0]
                                      for b in range(len(bl))],
        mpc_status=mpc_st, baseline_status=base_st, ar_leads=leads, ar_error=err,
        peak_period=tp_n, update_interval=upd, gamma=gamma, torque_limit=torque_limit,
        efficiency=efficiency, record=rec, units=units.describe(), success=ok,
        status="done" if ok else ("time_limit" if stopped[0] else "failed_runs"),
        message=msg, warm_up=warm_up,
        speed_limit=speed_limit,
        optimum_power_w=[w(v) for v in opt], limit_power_w=[w(v) for v in lim],
        mpc_power_w=[[[w(v) for v in col] for col in row] for row in mpc_p],
        baseline_power_w=[[w(v) for v in row] for row in base_p],
        mpc_horizon_used=used, mpc_harvested_power=mpc_w, mpc_stored_energy_change=mpc_de,
        mpc_stored_energy_change_j=[[[joules(v) for v in col] for col in row]
                                    for row in mpc_de],
        baseline_harvested_power=base_w, baseline_stored_energy_change=base_de,
        baseline_stored_energy_change_j=[[joules(v) for v in row] for row in base_de],
        mpc_update_time_first=first, mpc_update_time_median=t_med,
        mpc_update_time_p99=t_p99, mpc_update_time_max=t_max, update_interval_s=upd_s,
        realtime_fits=fits,
        mpc_failed_solves=[[[int(v) if v == v else None for v in col] for col in row]
                           for row in mpc_fail],
        mpc_failed_kept_previous=[[[int(v) if v == v else None for v in col] for col in row]
                                  for row in mpc_kept],
        mpc_speed_exceeded_fraction=opt_list(mpc_xf), mpc_speed_peak=opt_list(mpc_xp))


#: options of the pendulum's curve the buoy's has not (refused by name with device="buoy")
PENDULUM_ONLY = ("gravity", "gamma", "baselines", "speed_limit")


def _has_inputs(opts: dict) -> bool:
    from ..hydro.declared import has_inputs

    return has_inputs(opts)


def _expanded(opts: dict) -> dict:
    """The curve's keywords with the input objects of :mod:`parapend.hydro.device` replaced
    by their fields (:func:`~parapend.hydro.device.expand_inputs`); of a ``Controller``
    the curve takes the update interval (it runs mpc and sweeps the horizon itself)."""
    import dataclasses

    from ..hydro.api import refuse_hull
    from ..hydro.declared import Body, Controller, PowerTakeOff, expand_inputs

    for body in (opts.get("body"), getattr(opts.get("device"), "body", None)):
        if isinstance(body, Body):  # a hull first: its own options are not the curve's
            refuse_hull(body.dofs, "horizon --device buoy")
    controller = opts.get("controller")
    if isinstance(controller, Controller):
        if controller.controller not in (None, "mpc"):
            raise ParameterError(f"controller: the horizon curve runs the coupled receding-"
                                 f"horizon controller (mpc), got {controller.controller!r:.40}")
        opts = dict(opts, controller=dataclasses.replace(controller, controller=None))
    # the take-off's torque limit is in N m: the curve's torque_limit_nm (its torque_limit
    # is in units m g l)
    for key in ("pto", "device"):
        holder = opts.get(key)
        pto = getattr(holder, "pto", holder)
        if isinstance(pto, PowerTakeOff) and pto.torque_limit is not None:
            if opts.get("torque_limit_nm") is not None:
                raise ParameterError("torque-limit-nm: given twice (in a keyword and "
                                     f"{key}=); give it once")
            opts = dict(opts, torque_limit_nm=pto.torque_limit)
            moved = dataclasses.replace(pto, torque_limit=None)
            opts[key] = moved if holder is pto else dataclasses.replace(holder, pto=moved)
    return expand_inputs(horizon_curve, opts)


def _buoy(opts: dict):
    """``device="buoy"``: the pendulum-only options refused by name, the rest handed on."""
    from ..hydro.horizon import buoy_horizon_curve

    for name in PENDULUM_ONLY:
        if opts[name] is not None:
            raise ParameterError(f"{name.replace('_', '-')}: an option of the prescribed-heave "
                                 "pendulum; not with --device buoy"
                                 + (" (give --damping-coefficient, N m s/rad)"
                                    if name == "gamma" else ""))
    return buoy_horizon_curve(**{k: v for k, v in opts.items()
                                 if k not in (*PENDULUM_ONLY, "device",
                                              "controller", "sea", "pendulum", "pto")})


def horizon_dataset(r: HorizonResult):
    """The result as an ``xarray.Dataset`` (dims ``forecast``, ``horizon``, ``baseline``,
    ``record``) for NetCDF."""
    import xarray as xr

    nr = len(r.seeds)
    coords = {"record": np.arange(nr), "horizon": np.asarray(r.horizons, dtype=float)}
    data = {"seed": (("record",), np.asarray(r.seeds, dtype=np.int64)),
            "optimum_power": (("record",), np.asarray(r.optimum_power)),
            "limit_power": (("record",), np.asarray(r.limit_power)),
            "optimum_power_w": (("record",), np.asarray(r.optimum_power_w)),
            "limit_power_w": (("record",), np.asarray(r.limit_power_w))}
    if r.forecasts:
        coords["forecast"] = np.asarray(r.forecasts, dtype=str)
        dims = ("forecast", "horizon", "record")
        data["mpc_power"] = (dims, np.asarray(r.mpc_power, dtype=float))
        data["mpc_power_w"] = (dims, np.asarray(r.mpc_power_w, dtype=float))
        data["mpc_fraction"] = (dims, np.asarray(r.mpc_fraction, dtype=float))
        if r.mpc_horizon_used:
            data["mpc_horizon_used"] = (("forecast", "horizon"),
                                        np.asarray(r.mpc_horizon_used, dtype=float))
        for name in ("mpc_harvested_power", "mpc_stored_energy_change",
                     "mpc_stored_energy_change_j"):
            if getattr(r, name):
                data[name] = (dims, np.asarray(getattr(r, name), dtype=float))
        for name in ("mpc_failed_solves", "mpc_failed_kept_previous"):
            if getattr(r, name):
                data[name] = (dims, np.asarray(
                    [[[-1 if v is None else v for v in c] for c in row]
                     for row in getattr(r, name)], dtype=np.int64))
        for name in ("first", "median", "p99", "max"):
            v = getattr(r, f"mpc_update_time_{name}")
            if v:
                data[f"mpc_update_time_{name}"] = (("forecast", "horizon"),
                                                   np.asarray(v, dtype=float))
    if r.baselines:
        coords["baseline"] = np.asarray(r.baselines, dtype=str)
        data["baseline_power"] = (("baseline", "record"),
                                  np.asarray(r.baseline_power, dtype=float))
        data["baseline_power_w"] = (("baseline", "record"),
                                    np.asarray(r.baseline_power_w, dtype=float))
        data["baseline_fraction"] = (("baseline", "record"),
                                     np.asarray(r.baseline_fraction, dtype=float))
        for name in ("baseline_harvested_power", "baseline_stored_energy_change",
                     "baseline_stored_energy_change_j"):
            if getattr(r, name):
                data[name] = (("baseline", "record"),
                              np.asarray(getattr(r, name), dtype=float))
    if r.ar_leads:
        coords["lead"] = np.asarray(r.ar_leads, dtype=float)
        data["ar_error"] = (("lead",), np.asarray(r.ar_error, dtype=float))
    ds = xr.Dataset(data, coords=coords)
    p_unit = "m g l sqrt(g/l)"
    described = {
        "mpc_power": (p_unit, "storage-corrected mean electrical power"),
        "baseline_power": (p_unit, "storage-corrected mean electrical power"),
        "mpc_power_w": ("W", "storage-corrected mean electrical power"),
        "baseline_power_w": ("W", "storage-corrected mean electrical power"),
        "mpc_harvested_power": (p_unit, "harvested electrical energy / time"),
        "baseline_harvested_power": (p_unit, "harvested electrical energy / time"),
        "mpc_stored_energy_change": ("m g l", "change of the stored energy"),
        "baseline_stored_energy_change": ("m g l", "change of the stored energy"),
        "mpc_stored_energy_change_j": ("J", "change of the stored energy"),
        "baseline_stored_energy_change_j": ("J", "change of the stored energy"),
        "mpc_failed_solves": ("1", "horizon solves not converged (-1: no run)"),
        "mpc_failed_kept_previous": ("1", "of them, the previous plan kept (-1: no run)"),
        **{f"mpc_update_time_{k}": ("s", f"wall time of an update (forecast + solve), {k}")
           for k in ("first", "median", "p99", "max")}}
    for name, (unit, long_name) in described.items():
        if name in ds.variables:
            ds[name].attrs.update(units=unit, long_name=long_name)
    ds["horizon"].attrs["units"] = "peak periods"
    if "lead" in ds.coords:
        ds["lead"].attrs["units"] = "peak periods"
    ds.attrs.update({"gamma": r.gamma, "peak_period": r.peak_period,
                     "update_interval_peak_periods": r.update_interval,
                     "warm_up_peak_periods": r.warm_up,
                     "update_interval_s": ("none" if r.update_interval_s is None
                                           else r.update_interval_s),
                     "realtime_fits": ("unknown" if r.realtime_fits is None
                                       else int(r.realtime_fits)),
                     "torque_limit": "none" if r.torque_limit is None else r.torque_limit,
                     "speed_limit": "none" if r.speed_limit is None else r.speed_limit,
                     "efficiency": "none" if r.efficiency is None else r.efficiency,
                     "convention": r.convention, "status": r.status,
                     "power_unit_w": r.units["power_unit_w"],
                     **{f"record_{k}": str(v) for k, v in r.record.items()}})
    return ds


def plot_horizon(r: HorizonResult, path=None):
    """Fraction of the non-causal optimum against the horizon: each forecast's mean over
    the records with its min-max band, the baselines as horizontal lines with theirs."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from ..plotting import _finish, _horizon_axes
    from ..style import figure_style

    hz = np.asarray(r.horizons, dtype=float)
    with figure_style():
        fig, ax = plt.subplots(figsize=(7.0, 4.6), layout="constrained")
        for i, name in enumerate(r.forecasts):
            mean = np.asarray(r.mpc_fraction_mean[i])
            line, = ax.plot(hz, mean, "o-", lw=1.2, label=f"receding horizon, {name} forecast")
            if len(r.seeds) > 1:
                ax.fill_between(hz, r.mpc_fraction_min[i], r.mpc_fraction_max[i],
                                color=line.get_color(), alpha=0.2, lw=0)
        styles = {"tracker": "--", "extremum": ":"}
        labels = {"tracker": "regular-wave tracker", "extremum": "half-turn rule at extrema"}
        x = [hz.min() / 1.25, hz.max() * 1.25]
        for b, name in enumerate(r.baselines):
            line, = ax.plot(x, [r.baseline_fraction_mean[b]] * 2, styles[name], lw=1.2,
                            color=f"C{len(r.forecasts) + b}", label=labels[name])
            if len(r.seeds) > 1:
                ax.fill_between(x, r.baseline_fraction_min[b], r.baseline_fraction_max[b],
                                color=line.get_color(), alpha=0.12, lw=0)
        _horizon_axes(ax, hz, x, "mean power / non-causal optimum (-)")
        u = r.units
        rec = r.record
        ax.set_title(f"{rec.get('spectrum', '')} Hs = {rec.get('hs', '')} m, Tp = "
                     f"{rec.get('tp', '')} s, {len(r.seeds)} record(s); l = "
                     f"{u['length_m']:g} m, m = {u['mass_kg']:g} kg, $\\gamma$ = {r.gamma:g}",
                     fontsize=9)
        ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.08), ncol=2, frameon=False,
                  borderaxespad=0.2)
        return _finish(fig, path, layout=False)
