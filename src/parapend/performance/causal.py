r"""The causal column of a power matrix (``--controller mpc``): per bin and record, the
receding-horizon controller of :func:`parapend.control.mpc.mpc_run` on the record the
non-causal column solves (same seed, same heave), with each forecast asked for.

One record's run is the one :func:`parapend.control.horizon.horizon_curve` makes: from the
hanging rest, 64 torque samples a peak period, ``warm_up`` peak periods left out of the mean
and then one whole repeat of the record, the mean electrical power storage-corrected
(``(W_e + eta_g dE) / tau``: the harvested energy plus the change of the pendulum's stored
energy ``E = theta'^2 / 2 + cos(theta)`` per unit time). Only the planner's samples per
Hermite interval are an option here (``plan_samples``, :data:`CAUSAL`: 2, ``horizon``'s). The
horizon, the update interval and the warm-up are in peak periods, as ``horizon`` and
``track --controller mpc`` take them.

Per bin the causal power is the best of the controller's run and rest: ``max(P, 0)`` of the
mean over the records (a real device stops the pendulum where the controller loses energy);
the choice is recorded (``causal_<forecast>_mode``).

With ``--device buoy`` (the heaving buoy) the column is the buoy's causal controller,
:func:`parapend.hydro.control.buoy_mpc` (:data:`BUOY_CONTROLLER`), on the record the buoy's
optimum solves (same seed, same wave): from the hanging rest with the buoy in its free
periodic motion, 64 torque samples a peak period, ``warm_up`` peak periods and then one whole
repeat of the record, its storage-corrected power (the harvested energy plus the change of
the mechanical energy of buoy AND pendulum, per unit time; electrical with an efficiency,
the stored energy counted at ``eta_g``). Its horizon defaults to the controller's
(:data:`BUOY_HORIZON`: 2 peak periods for ``plan``, as ``parapend buoy --controller mpc``),
its update interval and warm-up to :data:`BUOY_CAUSAL`'s; the perfect forecast, the AR one
(``buoy_mpc(forecast="ar")``: the excitation force over the horizon from
:class:`parapend.control.forecast.ARForecast` fitted at each update on the force measured so
far), or both; neither ``plan_samples`` nor ``speed_limit`` (options of the pendulum's
planner).
"""

from __future__ import annotations

import logging
import math

import numpy as np

from ..errors import ParameterError, check_int, check_range

__all__ = ["BUOY_CAUSAL", "BUOY_CONTROLLER", "BUOY_HORIZON", "CAUSAL", "FORECASTS", "causal_json",
           "causal_quantities", "check_causal", "run_buoy_record", "solve_causal"]

log = logging.getLogger(__name__)

#: the forecasts of the causal column (:mod:`parapend.control.forecast`)
FORECASTS = ("perfect", "ar")
#: the causal column's defaults: horizon, update interval and warm-up in peak periods,
#: the forecasts, the planner's torque samples per Hermite interval and the plans' rated
#: speed (units sqrt(g / l), a penalty). Measured on 50-wave records (docs/performance.md):
#: a horizon of 1 peak period gave the power of 2 (``track``'s default) to 5 digits at Hs
#: 1, 2 and 3 m, in two thirds of the time; an update interval of 1/16 (``horizon``'s is
#: 1/32) lost 13 % of the power; 4 samples an interval (``horizon``'s 2) cost a third less
#: with the same power (to 0.03 %) but ran away (|theta'| past a turn a sample,
#: "unresolved") at Hs 3 m, Te 6 s. Unlike ``horizon``, the plans price a rated speed:
#: without it 2 of 3 records at Hs 3 m, Te 6 s ran away and one reached 98.1 % of the
#: optimum; with 4 all reached 99.98 %, and at Hs 2 m, Tp 8 s and Hs 1 m, Te 10 s the power
#: was the same
CAUSAL = {"horizon": 1.0, "forecast": "perfect", "update_interval": 0.03125,
          "warm_up": 4.0, "plan_samples": 2, "speed_limit": 4.0}
#: ``--device buoy``: the causal column's defaults: a plan every 1/8 peak period and the
#: prescribed device's warm-up; the horizon is the controller's (:data:`BUOY_HORIZON`)
BUOY_CAUSAL = {"horizon": None, "forecast": "perfect", "update_interval": 0.125,
               "warm_up": 4.0}
#: ``--device buoy``: which of :func:`parapend.hydro.control.buoy_mpc`'s controllers runs
#: (``controller=``; recorded in the spec and the output's metadata): "plan", the default's,
#: at a horizon of 2 peak periods; with an efficiency (which ``plan`` does not price)
#: "coupled" at 1. Measured on the default buoy (80 kg, 0.3 m pendulum in the 0.5 m
#: cylinder), the matrix's 10-wave records, seed 0, a plan every 1/8 peak period, 4 peak
#: periods of warm-up (docs/buoy.md): ``plan`` at 2 gave 46.84, 25.39, 84.36 and 41.28 W at
#: Hs 0.5 and 1 m, Tp 2.5 and 3 s, where ``coupled`` at 1 gave 29.33, 14.26, 77.76 and
#: 39.47 W (and at 2, 97.14 W out of real time and -14.24 W at Hs 1 m)
BUOY_CONTROLLER = "plan"
#: the buoy's default horizon (peak periods) per controller; ``hull``: the hull's
#: (:func:`parapend.hydro.hull_control.hull_mpc`, ``--dofs surge,heave,pitch``)
BUOY_HORIZON = {"plan": 2.0, "coupled": 1.0, "hull": 2.0, "hull-collocation": 2.0}
#: the hull's controllers (``buoy_controller``) and the planner each runs
#: (:func:`parapend.hydro.hull_control.hull_mpc`'s ``planner``; ``hull_control.CONTROLLERS``
#: inverted)
HULL_PLANNERS = {"hull": "lbfgsb", "hull-collocation": "collocation"}


def check_causal(*, controller, horizon, forecast, update_interval, warm_up, plan_samples,
                 device: str, heave: bool, speed_limit=None, lossy: bool = False,
                 planner=None) -> dict | None:
    """The causal column's options, checked (one line naming the option); None without a
    controller (then every other option of it is refused). ``lossy``: the device has an
    efficiency (the buoy's ``plan`` controller prices none: were it
    :data:`BUOY_CONTROLLER`, ``coupled`` would run). ``planner`` (``--device buoy``): the
    heaving buoy's ``plan`` or ``coupled``, the hull's ``lbfgsb`` or ``collocation``, as
    ``parapend buoy --controller mpc --planner`` takes it (None: the model's default); the
    controller that runs is recorded as ``buoy_controller`` (:data:`BUOY_HORIZON`'s
    keys)."""
    opts = {"horizon": horizon, "forecast": forecast, "update-interval": update_interval,
            "warm-up": warm_up, "plan-samples": plan_samples, "speed-limit": speed_limit,
            "planner": planner}
    if controller is None or controller == "none":
        given = [k for k, v in opts.items() if v is not None]
        if given:
            raise ParameterError(f"{given[0]}: an option of the causal column; needs "
                                 "--controller mpc")
        return None
    if controller != "mpc":
        raise ParameterError(f"controller: expected mpc (or none), got {controller!r:.40}")
    buoy = device == "buoy"
    if buoy:
        for name, v in (("plan-samples", plan_samples), ("speed-limit", speed_limit)):
            if v is not None:
                raise ParameterError(f"{name}: an option of the prescribed-heave pendulum's "
                                     "planner; drop it with --device buoy")
        from ..hydro.api import _check_planner

        _check_planner(planner, "mpc", "heave" if heave else "hull", True if lossy else None)
    elif planner is not None:
        raise ParameterError("planner: an option of --device buoy's controller (the "
                             "prescribed-heave pendulum has one planner)")
    base = BUOY_CAUSAL if buoy else CAUSAL
    if not heave:
        from ..hydro.hull_control import CONTROLLERS, PLANNER

        buoy_controller = CONTROLLERS[planner or PLANNER]
        if buoy_controller == "hull-collocation":
            from ..hydro._hull_collocation import available

            available()  # CasADi, where its solver is IPOPT: one line naming the extra
    else:
        buoy_controller = planner or ("coupled" if lossy and BUOY_CONTROLLER == "plan"
                                      else BUOY_CONTROLLER)
    if horizon is None:
        horizon = (BUOY_HORIZON[buoy_controller] if buoy else base["horizon"])
    horizon = check_range("horizon", horizon, 0.05, 20.0, why="peak periods")
    forecast = base["forecast"] if forecast is None else forecast
    if isinstance(forecast, str):
        names = [s.strip() for s in forecast.split(",") if s.strip()]
    elif isinstance(forecast, (list, tuple)):
        names = list(forecast)
    else:
        raise ParameterError(f"forecast: expected perfect, ar or perfect,ar, got "
                             f"{forecast!r:.40}")
    if not names or any(n not in FORECASTS for n in names) or len(set(names)) != len(names):
        raise ParameterError(f"forecast: expected perfect, ar or perfect,ar, got "
                             f"{forecast!r:.40}")
    upd = base["update_interval"] if update_interval is None else update_interval
    upd = check_range("update-interval", upd, 1e-3, 1.0, why="peak periods")
    if buoy and upd < 1.0 / 64:
        raise ParameterError(f"update-interval: expected at least one torque sample (1/64 "
                             f"peak period) with --device buoy, got {upd:g}")
    if buoy and upd > horizon:
        raise ParameterError(f"update-interval: expected at most the horizon {horizon:g} peak "
                             f"periods with --device buoy, got {upd:g}")
    if buoy and not heave:  # the hull's controller's own ranges
        from ..hydro.hull_control import check_timing

        check_timing(horizon, upd)
    warm = base["warm_up"] if warm_up is None else warm_up
    warm = check_range("warm-up", warm, 0.0, 100.0, why="peak periods")
    if buoy:
        return {"controller": "mpc", "horizon": float(horizon),
                "forecasts": tuple(n for n in FORECASTS if n in names),
                "update_interval": float(upd), "warm_up": float(warm), "plan_samples": None,
                "speed_limit": None,
                "buoy_controller": buoy_controller}
    ps = CAUSAL["plan_samples"] if plan_samples is None else plan_samples
    ps = check_int("plan-samples", ps, 1, 64)
    if speed_limit is None:
        speed_limit = CAUSAL["speed_limit"]
    try:
        none = float(speed_limit) == math.inf  # none: horizon's default
    except (TypeError, ValueError, OverflowError):
        none = False
    speed_limit = None if none else float(check_range(
        "speed-limit", speed_limit, 1e-9, 1e6, why="units sqrt(g / l); inf for none"))
    return {"controller": "mpc", "horizon": float(horizon),
            "forecasts": tuple(n for n in FORECASTS if n in names),
            "update_interval": float(upd), "warm_up": float(warm), "plan_samples": int(ps),
            "speed_limit": speed_limit}


def causal_quantities(forecasts) -> tuple:
    """The stored per-record quantities (W) of the causal column, per forecast: the
    storage-corrected power and the harvested power alone."""
    return tuple(q for f in forecasts
                 for q in (f"causal_{f}_power", f"causal_{f}_harvested_power"))


def long_names(forecasts) -> dict:
    """Long names of :func:`causal_quantities`."""
    out = {}
    for f in forecasts:
        what = "perfect forecast" if f == "perfect" else "autoregressive forecast (past only)"
        out[f"causal_{f}_power"] = (
            f"causal receding-horizon control, {what}: mean electrical power after the "
            "warm-up, storage-corrected (harvested energy + eta_g x change of the stored "
            "energy, per unit time)")
        out[f"causal_{f}_harvested_power"] = (
            f"causal receding-horizon control, {what}: harvested electrical energy per unit "
            "time after the warm-up (no storage correction)")
    return out


class ShiftedQ:
    """The record's ``q(t)`` for :func:`parapend.control.mpc.mpc_run`, cheaper on the perfect
    forecast's repeated leads: ``q(t0 + d) = Re sum_k Q_k exp(i k w t0) exp(i k w d)``, the
    matrix ``exp(i k w d)`` of a set of offsets ``d`` (the horizon's leads, the same at every
    update up to round-off) built once and kept, so an update costs a matrix-vector product
    instead of the matrix's complex exponentials (they were half of a record's causal run:
    docs/performance.md). An offset set is recognised by ``d`` rounded to 1e-9 of
    the peak period ``tp`` and evaluated at the offsets of its first call: the leads
    ``(t_j + leads) - t_j`` differ from one update to the next by the round-off of ``t_j``
    (1e-16 of the run's length), so ``q`` is the direct evaluation's to round-off (the
    direct one rounds ``k w t`` at that length too); a set that differs by more than
    ``5e-10 tp`` is another set. Arrays of other sizes than 8 to 8192, and scalars, are
    the excitation's own :meth:`parapend.excitation.Excitation.q`.

    Parameters
    ----------
    exc : parapend.excitation.Excitation
        The record (``spectrum``, ``omega``, ``q``).
    tp : float
        The peak period (the record's time unit): the offsets' resolution.
    """

    #: offset sets kept (the leads; a few others are evaluated directly)
    KEEP = 4

    def __init__(self, exc, tp: float):
        self.exc = exc
        self.spec = np.asarray(exc.spectrum, dtype=complex)
        self.kw = np.arange(self.spec.size) * float(exc.omega)
        self.res = 1e-9 * float(tp)
        self.cache = {}

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        if t.ndim != 1 or not 8 <= t.size <= 8192:
            return self.exc.q(t)
        t0 = float(t[0])
        d = t - t0
        key = np.round(d / self.res).tobytes()
        e = self.cache.get(key)
        if e is None:
            if len(self.cache) >= self.KEEP:
                return self.exc.q(t)
            e = self.cache[key] = np.exp(1j * np.multiply.outer(d, self.kw))
        return (e @ (self.spec * np.exp(1j * self.kw * t0))).real


def run_record(spec, exc, units, j: int, r: int, forecast: str):
    """The receding-horizon run of one record ``exc`` (bin period ``j``, realization ``r``)
    with ``forecast``: :func:`parapend.control.mpc.mpc_run` with the arguments
    :func:`parapend.control.horizon.horizon_curve` gives it (and ``plan_samples``)."""
    from ..control.forecast import ARForecast
    from ..control.mpc import mpc_run

    eff = None
    if spec.efficiency is not None:
        from ..pto import efficiencies

        eff = efficiencies(spec.efficiency)
    tp_n = spec.tp[j] / units.time
    fo = None if forecast == "perfect" else ARForecast(tp_n)
    return mpc_run(ShiftedQ(exc, tp_n), gamma=spec.gamma, horizon=spec.horizon * tp_n,
                   update_interval=spec.update_interval * tp_n, dt=tp_n / 64,
                   average_from=spec.warm_up * tp_n, torque_limit=None, efficiency=eff,
                   forecast=fo, t_end=exc.period + spec.warm_up * tp_n,
                   seed=int(spec.seeds[r]), speed_limit=spec.speed_limit,
                   interval_samples=spec.plan_samples)


def run_buoy_record(spec, i: int, j: int, r: int, forecast: str = "perfect"):
    """The buoy's causal run of bin ``(i, j)``, realization ``r`` (``--device buoy``) with
    ``forecast``:
    :func:`parapend.hydro.control.buoy_mpc` on the body, pendulum and record
    :func:`parapend.performance.buoy_device.solve_buoy_bin` solves (same seed, same wave),
    ``warm_up`` peak periods then one repeat, the matrix's efficiency. The run's work is not
    capped here (the matrix estimates and limits its own time: a bin is never started past
    ``--time-limit``)."""
    from .. import limits
    from ..hydro.control import buoy_mpc
    from .buoy_device import body_hydro, pendulum, wave_of

    h, _ = body_hydro(spec)
    wave, _ = wave_of(spec, i, j, r)
    kw = {"iterations": 1} if spec.buoy_controller == "plan" else {}
    eta = spec.efficiency
    return buoy_mpc(h, pendulum(spec), wave, peak_period=spec.tp[j], horizon=spec.horizon,
                    update_interval=spec.update_interval, warmup=spec.warm_up, repeats=1,
                    controller=spec.buoy_controller, forecast=forecast,
                    efficiency=None if eta is None or eta == 1.0 else eta,
                    time_limit=limits.MAX_TIME_LIMIT, deadline=math.inf, **kw)


def run_hull_record(spec, i: int, j: int, r: int, forecast: str = "perfect", mode="swing"):
    """The hull's causal run of bin ``(i, j)``, realization ``r`` (``--device buoy --dofs
    surge,heave,pitch``): :func:`parapend.hydro.hull_control.hull_mpc` on the hull, pendulum
    and record :func:`parapend.performance.hull_device.solve_hull_bin` solves, started as
    its optimum's motion says (``mode``), ``warm_up`` peak periods then one repeat, with the
    planner of ``spec.buoy_controller`` (:data:`HULL_PLANNERS`)."""
    from .. import limits
    from ..hydro.hull_control import hull_mpc
    from .buoy_device import wave_of
    from .hull_device import problem

    p = problem(spec)
    wave, _ = wave_of(spec, i, j, r)
    pto = p["pto"]
    return hull_mpc(p["hull"], p["pendulum"], wave, peak_period=spec.tp[j], pivot=p["pivot"],
                    pitch_inertia=p["pitch_inertia"], horizon=spec.horizon,
                    update_interval=spec.update_interval, warmup=spec.warm_up, repeats=1,
                    forecast=forecast, mode=mode, torque_limit=pto.torque_limit,
                    efficiency=pto.efficiency, planner=HULL_PLANNERS[spec.buoy_controller],
                    time_limit=limits.MAX_TIME_LIMIT, deadline=math.inf)


def solve_causal(spec, i: int, j: int, r: int, mode: str = "swing") -> dict:
    """The causal quantities (W) of bin ``(i, j)``, realization ``r``: NaN where a run did
    not succeed (or raised: logged). ``mode``: the hull's start (from its optimum's motion)."""
    from threadpoolctl import threadpool_limits

    from .check import _record, _units

    buoy = spec.device == "buoy"
    if not buoy:
        units = _units(spec)
        exc = _record(spec, units, i, j, r)
    out = {}
    for f in spec.forecasts:
        p = w = math.nan
        try:
            # one BLAS thread, as the command line's own process has it: the engine's worker
            # processes do not, and the record's q (a small complex matrix-vector product
            # at every update) ran 2 to 3 times slower with threads that only spin
            with threadpool_limits(1, user_api="blas"):
                res = (run_hull_record(spec, i, j, r, f, mode)
                       if spec.buoy_controller in HULL_PLANNERS
                       else run_buoy_record(spec, i, j, r, f)
                       if buoy else run_record(spec, exc, units, j, r, f))
            # a run that loses energy is a measurement (the bin then rests: max(P, 0))
            if buoy and (res.success or res.status == "loses_energy"):
                p = float(res.electrical_power_w)
                w = float(res.harvested_electrical_power_w)
            elif buoy and res.status == "not_caught" and res.catch_time_s is None:
                p = w = 0.0  # the swing-up never reached the top: the device rests
            elif res.success:
                p = units.to_watts(float(res.mean_electrical_power))
                w = units.to_watts(float(res.harvested_electrical_power))
            else:
                log.warning("power matrix bin hm0=%g %s=%g realization %d: the causal run "
                            "(%s forecast) ended %s", spec.hm0[i], spec.period_kind,
                            spec.period[j], r, f, res.status)
        except Exception as err:  # noqa: BLE001 - a NaN in the column, logged
            log.warning("power matrix bin hm0=%g %s=%g realization %d: the causal run (%s "
                        "forecast) failed: %s: %s", spec.hm0[i], spec.period_kind,
                        spec.period[j], r, f, type(err).__name__, err)
        out[f"causal_{f}_power"] = p
        out[f"causal_{f}_harvested_power"] = w
    return out



def _planner(buoy_controller: str) -> str:
    """The planner's name as ``--planner`` takes it, of the controller that ran."""
    return HULL_PLANNERS.get(buoy_controller, buoy_controller)


def causal_json(ds, grid) -> dict:
    """The causal column of ``parapend power-matrix --json`` (``causal``): the controller's
    settings, each forecast's power matrix and choice per bin (``grid`` turns a variable
    into nested lists, None for NaN), and the annual energy of each column side by side
    (MWh; None where incomplete, the bounds beside it)."""
    forecasts = ds.attrs["causal_forecasts"].split(",")
    out = {"controller": ds.attrs["controller"], "forecasts": forecasts,
           "horizon_peak_periods": float(ds.attrs["causal_horizon_peak_periods"]),
           "update_interval_peak_periods":
               float(ds.attrs["causal_update_interval_peak_periods"]),
           "warm_up_peak_periods": float(ds.attrs["causal_warm_up_peak_periods"]),
           "plan_samples": (int(ds.attrs["causal_plan_samples"])
                            if "causal_plan_samples" in ds.attrs else None),
           "speed_limit": (None if ds.attrs.get("causal_speed_limit", "none") == "none"
                           else float(ds.attrs["causal_speed_limit"])),
           "convention": ds.attrs["causal_convention"],
           **({"buoy_controller": ds.attrs["causal_buoy_controller"],
               "planner": _planner(ds.attrs["causal_buoy_controller"])}
              if "causal_buoy_controller" in ds.attrs else {}),
           "power_matrix": {f: grid(f"causal_{f}_power_matrix") for f in forecasts},
           "above_optimum": {f: int(ds[f"causal_{f}_power"].attrs.get("above_optimum", 0))
                             for f in forecasts},
           "mode": {f: [[{1: "controller", 0: "rest"}.get(int(v)) for v in row]
                        for row in ds[f"causal_{f}_mode"].values] for f in forecasts}}
    if "annual_energy" in ds:
        def num(v):
            v = float(v)
            return v if math.isfinite(v) else None

        cols = ds["column"].attrs["flag_meanings"].split()
        side = {}
        for k, c in enumerate(cols):
            e = {"annual_energy_mwh": num(ds["annual_energy"].values[k]),
                 "complete": bool(ds["annual_energy_complete"].values[k]),
                 "annual_energy_mwh_bounds": [num(ds["annual_energy_lower"].values[k]),
                                              num(ds["annual_energy_upper"].values[k])]}
            if "capacity_factor" in ds:
                e["capacity_factor"] = num(ds["capacity_factor"].values[k])
                e["capacity_factor_bounds"] = [num(ds["capacity_factor_lower"].values[k]),
                                               num(ds["capacity_factor_upper"].values[k])]
            side[c] = e
        out["annual_energy"] = side
    return out
