r"""The horizon curve of the buoy: ``parapend horizon --device buoy`` (docs/buoy.md).

For the pendulum inside the floating buoy (``parapend buoy``'s body and pendulum, SI units)
in a sea state, over ``records`` seeded records (seeds ``seed .. seed + records - 1``,
each ``repeat_period`` long): the receding-horizon controller on the coupled time-domain
plant (:func:`parapend.hydro.control.buoy_mpc`, called as ``parapend buoy --controller mpc``
calls it) with each forecast of the excitation force ("perfect": the record's own future;
"ar": autoregressive, fitted on the force measured so far) at each horizon (peak periods),
``warm_up`` peak periods of start-up from the hanging rest and then one whole repeat of the
record averaged. Each run's mean power is ``buoy_mpc``'s storage-corrected electrical
power (the harvested energy plus the change of the mechanical energy of buoy and pendulum,
at ``eta_g``, per unit time over the repeat), reported beside the harvested power and the
stored energy's change, as a fraction of the record's coupled non-causal optimum (what
``parapend buoy`` computes for the same record: one turn per record, no torque limit or
efficiency). The update times (forecast + solve) are pooled over the records, the first
update of the first record (the kernels' load) apart.

The keys are those of the pendulum's curve (:class:`parapend.control.horizon.HorizonResult`)
where the quantity is the same; in SI (``*_w``, ``*_j``, ``*_s``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import limits
from ..defaults import BUOY_HORIZON
from ..errors import ParameterError, check_int
from ..results import _Result

__all__ = ["BUOY_HORIZON", "BuoyHorizonResult", "buoy_horizon_curve", "plot_buoy_horizon"]

#: seconds per unit of a run's work (updates x horizon samples x solves per update), per
#: planner: ``coupled``'s from the default curve's run with it (work 1.0e5, 140 s of CPU
#: at a load of 2 to 3 on the 2 cores, docs/control.md); ``plan``'s from ``parapend buoy
#: --controller mpc``'s (1.06e5 counted as two solves an update, 87 s under load), which
#: over-estimates the default curve with the planner's radiation model (one solve an update,
#: work 5.0e4, 16.5 s of CPU) about 2.5 times
#: the hull's with L-BFGS-B (``hull``): its default sea's run (64 updates x 48 samples, 21 s
#: at a load of 3); with the collocation planner (``hull-collocation``, the default, its
#: compiled solver) a 20-minute record of the default sea (1631 updates x 48 samples, 500 s
#: of CPU at a load of 6, the record's optimum aside)
BUOY_MPC_SECONDS = {"coupled": 140.0 / 1.0e5, "plan": 87.0 / 1.06e5, "hull": 21.0 / 3.1e3,
                    "hull-collocation": 500.0 / 7.83e4}


@dataclass(frozen=True, eq=False, repr=False)
class BuoyHorizonResult(_Result):
    """The buoy's mean power against horizon (fields = JSON keys of ``parapend horizon
    --device buoy --json``). Indices ``[f][h][r]``: forecast ``forecasts[f]``, horizon
    ``horizons[h]`` (peak periods), record ``r`` (seed ``seeds[r]``).

    Attributes
    ----------
    device, planner : str
        ``"buoy"``; the planner of :func:`parapend.hydro.control.buoy_mpc` that ran
        (``coupled`` or ``plan``).
    mpc_power_w : nested list of float
        Each run's storage-corrected electrical power (W) over one repeat after the
        warm-up (``buoy_mpc``'s ``electrical_power_w``; NaN: the run failed or was not run).
    mpc_harvested_power_w, mpc_stored_energy_change_j : nested lists of float
        The harvested electrical energy alone per unit time, and the change of the
        mechanical energy of buoy and pendulum over the same window (J).
    optimum_power_w : list of float
        Per record: the coupled non-causal optimum (``parapend buoy`` on the record).
    mpc_fraction : nested list; ``mpc_fraction_mean``, ``_min``, ``_max`` ``[f][h]``
        Power over the record's optimum, and its mean, least and largest over the records.
    mpc_status : nested list of str
    mpc_failed_solves, mpc_failed_kept_previous : nested lists of int
    mpc_horizon_used : ``[f][h]``: the horizon planned over, peak periods (the samples).
    mpc_update_time_first, mpc_update_time_median, mpc_update_time_p99, mpc_update_time_max
        ``[f][h]``: wall time (s) of one update (forecast + solves), the first update of the
        first record apart, the others pooled over the records.
    update_interval_s : float
        The update interval in seconds; ``realtime_fits``: whether every
        ``mpc_update_time_p99`` fits in it (one process).
    seeds : list of int
        The records' seeds: the one given, then one more per record.
    """

    device: str
    planner: str
    horizons: list
    forecasts: list
    seeds: list
    mpc_power_w: list
    mpc_harvested_power_w: list
    mpc_stored_energy_change_j: list
    optimum_power_w: list
    mpc_fraction: list
    mpc_fraction_mean: list
    mpc_fraction_min: list
    mpc_fraction_max: list
    mpc_status: list
    mpc_failed_solves: list
    mpc_failed_kept_previous: list
    mpc_horizon_used: list
    mpc_update_time_first: list
    mpc_update_time_median: list
    mpc_update_time_p99: list
    mpc_update_time_max: list
    update_interval: float
    update_interval_s: float
    realtime_fits: bool | None
    warm_up: float
    torque_limit_nm: float | None
    efficiency: tuple | None
    record: dict
    pendulum: dict
    body: str
    success: bool
    status: str
    message: str
    convention: str = ("power positive when harvested; (harvested electrical energy + "
                       "change of the mechanical energy of buoy and pendulum, at eta_g) per "
                       "unit time over one repeat of the record after warm_up; fractions of "
                       "the record's coupled non-causal optimum (parapend buoy)")

    command = "horizon"
    headline = ("horizons", "mpc_fraction_mean", "status")

    def _series(self):
        import xarray as xr

        nr = len(self.seeds)
        dims = ("forecast", "horizon", "record")
        coords = {"record": np.arange(nr), "horizon": np.asarray(self.horizons, dtype=float),
                  "forecast": np.asarray(self.forecasts, dtype=str)}
        data = {"seed": (("record",), np.asarray(self.seeds, dtype=np.int64)),
                "optimum_power_w": (("record",), np.asarray(self.optimum_power_w, float))}
        for name in ("mpc_power_w", "mpc_harvested_power_w", "mpc_stored_energy_change_j",
                     "mpc_fraction"):
            data[name] = (dims, np.asarray(getattr(self, name), dtype=float))
        for name in ("mpc_failed_solves", "mpc_failed_kept_previous"):
            data[name] = (dims, np.asarray([[[-1 if v is None else v for v in c] for c in row]
                                            for row in getattr(self, name)], dtype=np.int64))
        for name in ("mpc_horizon_used", "mpc_fraction_mean", "mpc_fraction_min",
                     "mpc_fraction_max", "mpc_update_time_first", "mpc_update_time_median",
                     "mpc_update_time_p99", "mpc_update_time_max"):
            data[name] = (("forecast", "horizon"), np.asarray(getattr(self, name), float))
        ds = xr.Dataset(data, coords=coords)
        ds["horizon"].attrs["units"] = "peak periods"
        ds["mpc_horizon_used"].attrs["units"] = "peak periods"
        for name in ("mpc_failed_solves", "mpc_failed_kept_previous"):
            ds[name].attrs.update(units="1", long_name=name.replace("_", " ") + " (-1: no run)")
        return ds

    def _figure(self):
        return plot_buoy_horizon(self)


def _estimate(tp, tr, horizon, update, warm_up, iterations, hull=False) -> tuple:
    """A run's work as :func:`parapend.hydro.control.buoy_mpc` counts it (updates x horizon
    samples x solves per update) and its updates (the hull's samples with ``hull``)."""
    from .control import SAMPLES as BUOY_SAMPLES
    from .hull_control import SAMPLES as HULL_SAMPLES

    SAMPLES = HULL_SAMPLES if hull else BUOY_SAMPLES  # noqa: N806

    per_record = max(1, int(round(tr / (tp / SAMPLES))))
    dt = tr / per_record
    n = max(1, int(round(horizon * tp / dt)))
    m = max(1, min(n, int(round(update * tp / dt))))
    total = int(round(warm_up * tp / dt)) + per_record
    return math.ceil(total / m) * n * iterations, math.ceil(total / m)


def buoy_horizon_curve(*, hs=None, tp=None, spectrum="jonswap", gamma_peak=3.3,
                       repeat_period=None, seed=None, cutoff=3.0, mass=None, length=None,
                       inertia=None, damping_coefficient=None, body=None, radius=None,
                       draft=None, mesh=None, hydro=None, planner=None, torque_limit=None,
                       torque_limit_nm=None, efficiency=None, horizons=None,
                       forecasts="perfect,ar", records=1, update_interval=None, warm_up=None,
                       time_limit=None, progress=None, dofs=None) -> BuoyHorizonResult:
    """The buoy's horizon curve (``parapend.horizon(device="buoy", ...)`` calls this; the
    module docstring).

    Parameters
    ----------
    hs, tp, spectrum, gamma_peak, repeat_period, seed, cutoff :
        The sea state as ``parapend buoy`` takes it (default ``Hs`` 0.5 m, ``Tp`` 2.5 s,
        ``parapend.defaults.BUOY``; ``repeat_period`` default ten peak periods); record
        ``r`` has the seed ``seed + r``.
    mass, length, inertia, damping_coefficient :
        The pendulum, kg, m, kg m^2, N m s/rad (default the embedded design's).
    body, radius, draft, mesh, hydro :
        The floating body as ``parapend buoy`` takes it.
    planner : "coupled", "plan", "lbfgsb", "collocation" or None
        The heaving buoy's: :func:`parapend.hydro.control.buoy_mpc`'s planner, ``coupled``
        or ``plan``; the hull's: ``parapend.hydro.hull_control.hull_mpc``'s, ``lbfgsb``
        or ``collocation`` (None: the default; ``plan``
        with one solve per update, as the power matrix runs it).
    torque_limit, torque_limit_nm : float or None
        The torque bound in units ``m g l`` or in N m (not both; default ``buoy_mpc``'s,
        2 ``m g l``; a hull's ``hull_mpc``'s, 4 ``m g l``).
    efficiency : float, pair or None
        Of the power take-off (generating, motoring), in the plans and the power.
    horizons : str or sequence of float
        Peak periods (default ``BUOY_HORIZON["horizons"]``).
    forecasts : str or sequence of str
        Of ("perfect", "ar").
    records : int
        Seeded records, 1 to 20.
    update_interval, warm_up : float or None
        Peak periods (default 0.125 and 4, ``parapend buoy --controller mpc``'s).
    time_limit : float or None
        Seconds for the whole curve: without it a curve estimated above
        ``parapend.limits.MAX_UNTIMED_SECONDS`` is refused, naming the most records or the
        longest record that fits; with it the work stops at the first run after the limit
        (or within a run, before its next update): the runs not finished are NaN with the
        status ``"time_limit"``.
    progress : callable or None
        ``progress(done, total)`` after every run (the records' optima and the
        receding-horizon runs).
    dofs : ``"heave"`` (None, the buoy) or ``"surge,heave,pitch"``: the hull (the embedded
        barge, ``parapend.defaults.HULL``'s sea state, pendulum and pivot), its record
        optimum (:func:`parapend.hydro.api.solve_record`) and its receding-horizon runs
        (``parapend.hydro.hull_control.hull_mpc``, started from the optimum's motion,
        ``parapend.hydro.hull_control.start_mode``).
    """
    from ..control.curve_options import (
        MAX_RECORDS,
        _horizons,
        _names,
        _stats,
        update_time_stats,
    )
    from ..deadline import check_time_limit, deadline, duration, expired, refuse_untimed
    from ..defaults import HULL
    from ..units import Units
    from .api import _check_floats, _check_kinds, _check_planner, _hydro, parse_dofs
    from .control import buoy_mpc
    from .declared import default_of
    from .inputs import _irregular_wave, _pendulum
    from .result import _solve

    hull = dofs is not None and parse_dofs(dofs) != ("heave",)
    kind = "hull" if hull else "buoy"  # whose declared defaults
    time_limit = check_time_limit(time_limit)
    until = deadline(time_limit)
    if progress is not None and not callable(progress):  # called only after the first run
        raise ParameterError(f"progress: expected a callable progress(done, total) or None, "
                             f"got {progress!r:.40}")
    _check_kinds(mesh=mesh)  # a number for the path: one line, not os.fspath's TypeError
    pend = _pendulum(mass, length, inertia, damping_coefficient, kind)  # the declared defaults
    _check_planner(planner, "mpc", "hull" if hull else "heave", efficiency)
    mgl = pend.mass * 9.81 * pend.length
    if torque_limit is not None and torque_limit_nm is not None:
        raise ParameterError("torque-limit-nm: give either --torque-limit or "
                             "--torque-limit-nm, not both")
    from ..errors import check_range

    if torque_limit is not None:
        torque_limit_nm = mgl * check_range("torque-limit", torque_limit,
                                            limits.MIN_TORQUE_LIMIT, limits.MAX_TORQUE_LIMIT,
                                            why="units m g l")
    elif torque_limit_nm is not None:
        torque_limit_nm = check_range("torque-limit-nm", torque_limit_nm,
                                      limits.MIN_TORQUE_LIMIT * mgl,
                                      limits.MAX_TORQUE_LIMIT * mgl,
                                      why=f"N m: {limits.MIN_TORQUE_LIMIT:g} to "
                                          f"{limits.MAX_TORQUE_LIMIT:g} x m g l")
    if efficiency is not None:
        from .pto import efficiency_pair

        efficiency = efficiency_pair(efficiency)
        if efficiency == (1.0, 1.0):
            efficiency = None
    hz = _horizons(BUOY_HORIZON["horizons"] if horizons is None else horizons)
    fc = _names(forecasts, ("perfect", "ar"), "forecasts")
    if not fc:
        raise ParameterError("forecasts: expected perfect, ar or both for the buoy (it has no "
                             "causal baselines), got none")
    records = check_int("records", records, 1, MAX_RECORDS)
    seed = check_int("seed", 0 if seed is None else seed, 0, 2**63 - 1 - MAX_RECORDS)
    upd = check_range("update-interval", BUOY_HORIZON["update_interval"]
                      if update_interval is None else update_interval, 1 / 64, 1.0,
                      why="peak periods")
    if upd > min(hz):
        raise ParameterError(f"update-interval: expected at most the shortest horizon "
                             f"{min(hz):g} peak periods, got {upd:g}")
    if hull:  # the hull's controller's own ranges
        from .hull_control import check_timing

        for h in hz:
            check_timing(h, upd, name="horizons")
    warm_up = check_range("warm-up", BUOY_HORIZON["warm_up"] if warm_up is None else warm_up,
                          0.0, 100.0, why="peak periods")
    tp, hs = default_of("tp", tp, kind), default_of("hs", hs, kind)
    units = Units(pend.length, pend.mass, 9.81, pend.inertia)
    if repeat_period is None:
        from ..seas import _check_sea

        repeat_period = (HULL if hull else BUOY_HORIZON)["repeat_periods"] * _check_sea(
            hs, tp, spectrum, gamma_peak, None, cutoff)[1]
    waves = [_irregular_wave(hs, tp, spectrum, gamma_peak, repeat_period, seed + r, cutoff,
                             None, 0.1, units) for r in range(records)]
    tp = float(waves[0][1]["tp"])
    tr = float(waves[0][1]["repeat_period"])
    # the planner that will run: buoy_mpc's default when none is given
    if hull:
        from .hull_control import CONTROLLERS, PLANNER

        runs = CONTROLLERS[planner or PLANNER]
    else:
        runs = planner or ("coupled" if efficiency is not None else "plan")
    iterations = 1 if runs in ("plan", "hull", "hull-collocation") else 2
    work = [_estimate(tp, tr, h, upd, warm_up, iterations, hull) for h in hz]
    est = records * len(fc) * sum(w for w, _ in work) * BUOY_MPC_SECONDS[runs]
    cap = limits.MAX_UNTIMED_SECONDS
    most = int(cap / (est / records))
    # the longest record that fits, one record: a run's work grows with warm-up + record
    per_tp = est / records / (warm_up + tr / tp)
    longest = (cap / per_tp - warm_up) * tp if per_tp > 0 else math.inf
    what = (f"{records} record(s) x {len(fc)} forecast(s) x {len(hz)} horizon(s) of the "
            f"buoy's receding-horizon runs ({', '.join(str(u) for _, u in work)} updates)")
    if most >= 1:
        name, advice = "records", f"use --records at most {most}"
    elif longest >= tp:  # a record of at least one peak period fits
        name, advice = "repeat-period", (f"use --repeat-period at most {longest:.4g} s (one "
                                         "record), or fewer --horizons or --forecasts")
    else:  # the warm-up alone takes the time: no shorter record fits
        name, advice = "horizons", "use fewer --horizons or --forecasts"
    refuse_untimed(name, what, est, advice, time_limit, cap)
    from ..control.mpc import ANNOUNCE_SECONDS, log

    if est > ANNOUNCE_SECONDS:
        log.info("horizon: %s: roughly %s on one core%s (Ctrl-C stops it)", what,
                 duration(est), "" if time_limit is None else
                 f" (stopped after the time limit {time_limit:g} s)")
    # the body (the BEM, cached on disk) and the checks parapend buoy makes of a record
    if hull:
        from .api import hull_problem, solve_record
        from .hull_control import hull_mpc, start_mode

        problem = hull_problem(body=body, radius=radius, draft=draft, mesh=mesh, hydro=hydro,
                               mass=pend.mass, length=pend.length, inertia=pend.inertia,
                               damping_coefficient=pend.damping_coefficient)
        h = problem["hull"]
        for wave, info in waves:
            solve_record(problem, wave, info, check_only=True)
    else:
        h, _ = _hydro(body, radius, draft, mesh, hydro)
        for wave, _ in waves:
            amps = np.abs(np.asarray(wave.amplitudes))
            sig = np.nonzero(amps >= 1e-3 * amps.max())[0]
            h.check_covers(wave.omega * (sig[0] + 1), wave.omega * (sig[-1] + 1), name="tp")
        _check_floats(h, pend)
    modes = []
    total_runs = records * (1 + len(fc) * len(hz))
    done = [0]
    stopped = [False]

    def tick():
        done[0] += 1
        if progress is not None:
            progress(done[0], total_runs)

    def out_of_time() -> bool:
        if not stopped[0] and done[0] and expired(until):
            stopped[0] = True
        return stopped[0]

    opt = []
    for wave, info in waves:
        modes.append("swing")
        if out_of_time():
            opt.append(math.nan)
            continue
        if hull:  # parapend buoy --dofs surge,heave,pitch's optimum, its mode the run's
            sol = solve_record(problem, wave, info)
            modes[-1] = start_mode(sol.winding, sol.mean_angle_deg, sol.swing_amplitude_deg)
            opt.append(float(sol.power_w) if sol.success else math.nan)
        else:  # parapend buoy --controller mpc's optimum of the record (mpc_command)
            sol, _, _ = _solve(h, pend, wave, winding=1, harmonics=None, torque_limit=None,
                               efficiency=None, one_way=False)
            opt.append(float(sol.power) if sol.success else math.nan)
        tick()
    shape = [[[math.nan] * records for _ in hz] for _ in fc]
    power, harvested, stored = ([[list(c) for c in row] for row in shape] for _ in range(3))
    status = [[[""] * records for _ in hz] for _ in fc]
    fails = [[[None] * records for _ in hz] for _ in fc]
    kept = [[[None] * records for _ in hz] for _ in fc]
    used = [[h_ for h_ in hz] for _ in fc]
    times = [[[] for _ in hz] for _ in fc]
    first = [[math.nan for _ in hz] for _ in fc]
    upd_s = math.nan
    ctrl = planner  # the planner that ran (buoy_mpc's default when None)
    kw = {} if planner is None else {"controller": planner}
    if planner == "plan":
        kw["iterations"] = 1
    for i, f in enumerate(fc):
        for j, hor in enumerate(hz):
            for r, (wave, _) in enumerate(waves):
                if out_of_time():
                    status[i][j][r] = "time_limit"
                    continue
                run, more = ((hull_mpc, {"pivot": problem["pivot"], "mode": modes[r],
                                         "planner": planner})
                             if hull else (buoy_mpc, kw))
                res = run(h, pend, wave, peak_period=tp, horizon=hor,
                          update_interval=upd, warmup=warm_up, repeats=1,
                          torque_limit=torque_limit_nm, efficiency=efficiency,
                          forecast=f, time_limit=limits.MAX_TIME_LIMIT,
                          deadline=math.inf if until is None else until, **more)
                if res.status == "time_limit":
                    stopped[0] = True
                status[i][j][r] = str(res.status)
                ctrl = str(res.planner)
                if res.success or res.status == "loses_energy":  # a loss is measured
                    power[i][j][r] = float(res.electrical_power_w)
                    harvested[i][j][r] = float(res.harvested_electrical_power_w)
                    stored[i][j][r] = float(res.stored_energy_change_j)
                fails[i][j][r] = int(res.failed_solves)
                kept[i][j][r] = int(res.failed_kept_previous)
                used[i][j] = float(res.horizon_s) / tp
                upd_s = float(res.update_interval_s)
                ut = np.asarray(res._update_times, dtype=float)
                if ut.size:
                    if r == 0:
                        first[i][j] = float(ut[0])
                    times[i][j].append(ut[1:] if r == 0 else ut)
                if res.status != "time_limit":
                    tick()
    o = np.asarray(opt)
    frac = (np.asarray(power) / o).tolist()
    st = [[_stats(np.asarray(power[i][j]) / o) for j in range(len(hz))]
          for i in range(len(fc))]
    t_med, t_p99, t_max = update_time_stats(times, len(fc), len(hz))
    fits = bool(np.max(t_p99) <= upd_s) if np.all(np.isfinite(t_p99)) else None
    nan_runs = int(np.sum(~np.isfinite(np.asarray(power)))) + int(np.sum(~np.isfinite(o)))
    ok = nan_runs == 0 and not stopped[0]
    msg = (f"{records} record(s) of {tr:g} s; "
           + ("every run finished" if ok else f"{nan_runs} run(s) failed (NaN power)"))
    if stopped[0]:
        msg = (f"time limit reached ({time_limit:g} s): {done[0]} of {total_runs} runs "
               f"finished (the records' optima and {len(fc) * len(hz)} receding-horizon runs "
               "per record), the rest NaN with the status time_limit")
    rec = {k: v for k, v in waves[0][1].items() if k not in ("seed",)}
    if ctrl is None:  # no run started (a time limit): the planner that would have run
        import inspect

        ctrl = inspect.signature(buoy_mpc).parameters["controller"].default
    return BuoyHorizonResult(
        device="buoy", planner=ctrl, horizons=hz, forecasts=fc,
        seeds=[seed + r for r in range(records)], mpc_power_w=power,
        mpc_harvested_power_w=harvested, mpc_stored_energy_change_j=stored,
        optimum_power_w=opt, mpc_fraction=frac,
        mpc_fraction_mean=[[m[0] for m in row] for row in st],
        mpc_fraction_min=[[m[1] for m in row] for row in st],
        mpc_fraction_max=[[m[2] for m in row] for row in st],
        mpc_status=status, mpc_failed_solves=fails, mpc_failed_kept_previous=kept,
        mpc_horizon_used=used, mpc_update_time_first=first, mpc_update_time_median=t_med,
        mpc_update_time_p99=t_p99, mpc_update_time_max=t_max, update_interval=upd,
        update_interval_s=upd_s, realtime_fits=fits, warm_up=warm_up,
        torque_limit_nm=torque_limit_nm, efficiency=efficiency, record=rec,
        pendulum={"mass_kg": pend.mass, "length_m": pend.length,
                  "inertia_kg_m2": pend.inertia,
                  "damping_coefficient_nm_s_per_rad": pend.damping_coefficient},
        body=str(h.description), success=ok,
        status="done" if ok else ("time_limit" if stopped[0] else "failed_runs"),
        message=msg)


def plot_buoy_horizon(r: BuoyHorizonResult, path=None):
    """Fraction of the record's coupled optimum against the horizon, each forecast's mean
    over the records with its min-max band."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from ..plotting import _finish, _horizon_axes
    from ..style import figure_style

    hz = np.asarray(r.horizons, dtype=float)
    with figure_style():
        fig, ax = plt.subplots(figsize=(7.0, 4.6), layout="constrained")
        for i, name in enumerate(r.forecasts):
            line, = ax.plot(hz, np.asarray(r.mpc_fraction_mean[i], dtype=float), "o-", lw=1.2,
                            label=f"receding horizon, {name} forecast")
            if len(r.seeds) > 1:
                ax.fill_between(hz, r.mpc_fraction_min[i], r.mpc_fraction_max[i],
                                color=line.get_color(), alpha=0.2, lw=0)
        _horizon_axes(ax, hz, (hz.min() / 1.25, hz.max() * 1.25),
                      "mean power / coupled non-causal optimum (-)")
        rec, p = r.record, r.pendulum
        ax.set_title(f"buoy ({r.body}), {r.planner} planner: {rec.get('spectrum', '')} Hs = "
                     f"{rec.get('hs', '')} m, Tp = {rec.get('tp', '')} s, {len(r.seeds)} "
                     f"record(s); m = {p['mass_kg']:g} kg, l = {p['length_m']:g} m",
                     fontsize=9)
        ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.08), ncol=2, frameon=False,
                  borderaxespad=0.2)
        return _finish(fig, path, layout=False)
