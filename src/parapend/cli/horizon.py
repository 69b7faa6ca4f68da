"""``parapend horizon``: mean power of causal control against the forecast horizon
(docs/control.md)."""

from __future__ import annotations

import argparse

from ..defaults import HORIZON
from ..hydro.api import PLANNERS
from ..hydro.declared import Body, Controller, Pendulum, PowerTakeOff, Sea
from ..hydro.horizon import BUOY_HORIZON
from . import _output
from ._common import (
    FIGURE_SUFFIXES,
    _check_output,
    _finite_float,
    _int,
    _run,
    _table,
    add_body_options,
    add_declared,
)


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "horizon", help="mean power of receding-horizon control against the forecast "
                        "horizon in an irregular sea, beside causal baselines",
        description="For a sea state and a pendulum: the mean power of receding-horizon "
                    "control with a perfect and an autoregressive forecast, against the "
                    "horizon, and of two causal baselines, as fractions of each record's "
                    "non-causal optimum (parapend sea) and of its limit (docs/control.md).")
    p.add_argument("--device", choices=["pendulum", "buoy"],
                   help="pendulum: the pendulum on a prescribed heave (default); buoy: the "
                        "pendulum inside the floating buoy, coupled both ways (parapend buoy's "
                        "body and pendulum; docs/buoy.md)")
    p.set_defaults(device="pendulum")
    # the sea's and the pendulum's options: generated from their declarations
    # (parapend.hydro.declared), with the defaults they state for horizon: the
    # prescribed-heave pendulum's, the buoy's with --device buoy, the curve's shorter records
    g = p.add_argument_group("sea state (IEC TS 62600-2 spectra)")
    add_declared(g, Sea, ("hs", "tp", "spectrum", "gamma_peak", "repeat_period", "seed",
                          "cutoff"), command="horizon")
    g.add_argument("--records", type=_int,
                   help="seeded records, 1 to 20 (default 1)")
    g = p.add_argument_group("pendulum (SI units) and power take-off")
    add_declared(g, Pendulum, ("length", "mass", "inertia"), command="horizon")
    g.add_argument("--gravity", type=_finite_float("gravity"),
                   help="m/s^2 (default 9.81; not with --device buoy)")
    g.add_argument("--gamma", type=_finite_float("gamma"),
                   help="viscous damping, non-dimensional (default 0.01; not with --device "
                        "buoy)")
    add_declared(g, Pendulum, ("damping_coefficient",), command="horizon")
    add_declared(g, PowerTakeOff, ("torque_limit",), command="horizon")
    g.add_argument("--torque-limit-nm", type=_finite_float("torque-limit-nm"),
                   help="the torque limit in N m (instead of --torque-limit; a "
                        "PowerTakeOff's torque_limit)")
    add_declared(g, PowerTakeOff, ("efficiency",), command="horizon")
    g = p.add_argument_group("--device buoy: the body (Capytaine; the BEM result is cached on "
                             "disk) and the controller")
    add_body_options(g, command="horizon")
    g.add_argument("--planner", choices=[*PLANNERS["heave"], *PLANNERS["hull"]],
                   help="the buoy's receding-horizon planner (parapend.hydro.control.buoy_mpc"
                        "; default plan, coupled with --efficiency); with --dofs "
                        "surge,heave,pitch the hull's: collocation (default) or lbfgsb")
    # the planner's former name: refused in one line naming --planner (parapend.horizon)
    g.add_argument("--controller", help=argparse.SUPPRESS)
    add_declared(g, Body, ("dofs",), command="horizon")
    g = p.add_argument_group("controllers")
    g.add_argument("--horizons",
                   help="horizons in peak periods, comma separated (default "
                        f"{HORIZON['horizons']}; {BUOY_HORIZON['horizons']} with --device "
                        "buoy)")
    g.add_argument("--forecasts",
                   help="forecasts of the receding-horizon controller: perfect, ar, or none "
                        f"(default {HORIZON['forecasts']})")
    g.add_argument("--baselines",
                   help="causal baselines: tracker, extremum, or none (default "
                        f"{HORIZON['baselines']}; not with --device buoy)")
    add_declared(g, Controller, ("update_interval",), command="horizon")
    g.add_argument("--warm-up", type=_finite_float("warm-up"),
                   help="peak periods of every receding-horizon run left out of its mean "
                        "(the run is then this plus one repeat long; default 0, "
                        f"{BUOY_HORIZON['warm_up']:g} with --device buoy)")
    g.add_argument("--speed-limit", type=_finite_float("speed-limit"),
                   help="rated-speed penalty of the receding-horizon plans (a penalty on "
                        "the plans' speeds above it, not a hard bound; the exceedance is "
                        "reported), in units of sqrt(g/l), > 0 (default none; "
                        "docs/control.md; not with --device buoy)")
    p.add_argument("--time-limit", type=_finite_float("time-limit"), metavar="SECONDS",
                   help="run for at most about this long, then stop with a partial curve "
                        "marked time_limit (without it, runs estimated over 2 minutes are "
                        "refused)")
    p.add_argument("--plot", metavar="PNG", help="draw the fraction of the optimum against "
                                                 "the horizon")
    p.add_argument("--save", metavar="FILE",
                   help="write the curve and every run: .nc or .json")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def _pct(x) -> str:
    return "nan" if x != x else f"{100 * x:.1f} %"


def _mean(values) -> str:
    v = [x for x in values if x is not None and x == x]
    return f"{sum(v) / len(v):.4g}" if v else "nan"


def _cmd_horizon(a) -> dict | str:
    from ._common import SAVE_GRID
    from ._notice import install
    from .sweep import _EtaProgress

    _check_output(a.plot, "--plot", FIGURE_SUFFIXES)
    _check_output(a.save, "--save", SAVE_GRID)
    install("parapend.control")  # the library's estimate of long work, on stderr
    r = _run(a, progress=_EtaProgress("horizon"))
    if a.save:
        _output.save_result(r, a.save)
    if a.plot:
        _output.save_plot(r, a.plot)
    if a.json:
        return r.to_dict()
    if getattr(r, "device", "pendulum") == "buoy":
        return "\n".join(_buoy_text(r, a))
    rec, u = r.record, r.units
    head = (f"horizon: {rec.get('spectrum')}, Hs = {rec.get('hs'):g} m, Tp = "
            f"{rec.get('tp'):g} s, records of {rec.get('repeat_period'):g} s, seeds "
            f"{r.seeds[0]}..{r.seeds[-1]}; pendulum l = {u['length_m']:g} m, m = "
            f"{u['mass_kg']:g} kg, gamma = {r.gamma:g}"
            + ("" if r.torque_limit is None else f", T_max = {r.torque_limit:g}")
            + ("" if r.efficiency is None else f", efficiency {r.efficiency:g}"))
    # the mean over the records whose optimum was solved (all, unless a time limit stopped)
    opt = [v for v in r.optimum_power_w if v == v] or [float("nan")]
    lim = [v for v in r.limit_power_w if v == v] or [float("nan")]
    nopt, nlim = sum(opt) / len(opt), sum(lim) / len(lim)
    rows = []
    for i, f in enumerate(r.forecasts):
        for j, h in enumerate(r.horizons):
            pw = [v for v in r.mpc_power_w[i][j] if v == v]
            hu = r.mpc_horizon_used[i][j] if r.mpc_horizon_used else h
            cell = f"{h:g}" if abs(hu - h) <= 1e-9 * h else f"{h:g} (plans {hu:.3g})"
            rows.append([f"receding horizon, {f} forecast", cell,
                         f"{sum(pw) / len(pw):.4g}" if pw else "nan",
                         _pct(r.mpc_fraction_mean[i][j]),
                         f"{_pct(r.mpc_fraction_min[i][j])} .. "
                         f"{_pct(r.mpc_fraction_max[i][j])}",
                         _pct(r.mpc_limit_fraction_mean[i][j]),
                         _mean(r.mpc_stored_energy_change_j[i][j])
                         if r.mpc_stored_energy_change_j else "-"])
    names = {"tracker": "regular-wave tracker (track --irregular)",
             "extremum": "half-turn rule at the extrema of q"}
    for b, name in enumerate(r.baselines):
        pw = [v for v in r.baseline_power_w[b] if v == v]
        rows.append([names[name], "-", f"{sum(pw) / len(pw):.4g}" if pw else "nan",
                     _pct(r.baseline_fraction_mean[b]),
                     f"{_pct(r.baseline_fraction_min[b])} .. "
                     f"{_pct(r.baseline_fraction_max[b])}",
                     _pct(r.baseline_limit_fraction_mean[b]),
                     _mean(r.baseline_stored_energy_change_j[b])
                     if r.baseline_stored_energy_change_j else "-"])
    out = [head, f"non-causal optimum (sea) {nopt:.4g} W, limit {nlim:.4g} W (mean over the "
                 "records); power = (harvested energy + change of the stored energy, "
                 "mean dE in the last column) / time; every run from the hanging rest over "
                 "the whole record"
                 + (f" (receding horizon: after {r.warm_up:g} peak periods)" if r.warm_up
                    else "")
                 + (f"; rated-speed penalty {r.speed_limit:g}" if r.speed_limit is not None
                    else ""),
                 "",
           _table(rows, ["controller", "horizon (Tp)", "power (W)", "of optimum",
                         "min .. max", "of limit", "dE (J)"])]
    if r.forecasts and r.mpc_update_time_p99:
        trows = []
        for i, f in enumerate(r.forecasts):
            for j, h in enumerate(r.horizons):
                fails = [v for v in r.mpc_failed_solves[i][j] if v is not None]
                kept = [v for v in (r.mpc_failed_kept_previous[i][j]
                                    if r.mpc_failed_kept_previous else []) if v is not None]
                row = [f, f"{h:g}", f"{1e3 * r.mpc_update_time_median[i][j]:.3g}",
                       f"{1e3 * r.mpc_update_time_p99[i][j]:.3g}",
                       f"{1e3 * r.mpc_update_time_max[i][j]:.3g}",
                       f"{1e3 * r.mpc_update_time_first[i][j]:.3g}",
                       f"{sum(fails)} ({sum(kept)})"]
                if r.speed_limit is not None:
                    xf = [v for v in r.mpc_speed_exceeded_fraction[i][j] if v is not None]
                    xp = [v for v in r.mpc_speed_peak[i][j] if v is not None]
                    row += [_pct(sum(xf) / len(xf)) if xf else "nan",
                            f"{max(xp):.4g}" if xp else "nan"]
                trows.append(row)
        cols = ["forecast", "horizon (Tp)", "median (ms)", "p99 (ms)", "max (ms)",
                "first (ms)", "failed solves (previous plan kept)"]
        if r.speed_limit is not None:
            cols += ["speed above the penalty's w", "peak |theta'|"]
        out += ["", f"receding-horizon updates (forecast + solve) against the update interval "
                    f"{1e3 * r.update_interval_s:.4g} ms: p99 "
                    + ("fits" if r.realtime_fits else "does NOT fit"
                       if r.realtime_fits is not None else "not known (runs not finished)")
                    + " (one process; the first update, kernel load, apart)",
                _table(trows, cols)]
    if r.ar_leads:
        out += ["", "AR forecast, normalized rms error of q against lead time (1: the "
                    "error of predicting 0):",
                _table([[f"{ld:g}", f"{e:.3f}"] for ld, e in zip(r.ar_leads, r.ar_error)],
                       ["lead (Tp)", "error"])]
    out += ["", f"status: {r.status}: {r.message}"]
    if a.save:
        out.append(f"curve written to {a.save}")
    if a.plot:
        out.append(f"figure written to {a.plot}")
    return "\n".join(out)


def _buoy_text(r, a) -> list:
    """The text of ``--device buoy`` (:class:`parapend.hydro.horizon.BuoyHorizonResult`)."""
    rec, p = r.record, r.pendulum
    seeds = (f"seed {r.seeds[0]}" if len(r.seeds) == 1 else
             f"seeds {r.seeds[0]}..{r.seeds[-1]}")
    out = [f"horizon, buoy ({r.body}): {rec.get('spectrum')}, Hs = {rec.get('hs'):g} m, Tp = "
           f"{rec.get('tp'):g} s, records of {rec.get('repeat_period'):g} s, {seeds}; "
           f"pendulum m = {p['mass_kg']:g} kg, l = {p['length_m']:g} m, I = "
           f"{p['inertia_kg_m2']:.4g} kg m^2, c = {p['damping_coefficient_nm_s_per_rad']:g} "
           f"N m s/rad; {r.planner} planner"
           + ("" if r.torque_limit_nm is None else f", torque limit {r.torque_limit_nm:.4g} N m")
           + ("" if r.efficiency is None else
              f", efficiency {r.efficiency[0]:g}/{r.efficiency[1]:g}")]
    opt = [v for v in r.optimum_power_w if v == v]
    out.append("coupled non-causal optimum (parapend buoy on each record) "
               + (f"{sum(opt) / len(opt):.4g} W" if opt else "nan")
               + f" (mean over the records); power = (harvested energy + change of the "
                 f"stored energy of buoy and pendulum, mean dE in the last column) / time "
                 f"over one repeat after {r.warm_up:g} peak periods from the hanging rest")
    rows = []
    for i, f in enumerate(r.forecasts):
        for j, h in enumerate(r.horizons):
            pw = [v for v in r.mpc_power_w[i][j] if v == v]
            hv = [v for v in r.mpc_harvested_power_w[i][j] if v == v]
            hu = r.mpc_horizon_used[i][j]
            rows.append([f"{f}", f"{h:g}" if abs(hu - h) <= 1e-9 * h else
                         f"{h:g} (plans {hu:.3g})",
                         f"{sum(pw) / len(pw):.4g}" if pw else "nan",
                         _pct(r.mpc_fraction_mean[i][j]),
                         f"{_pct(r.mpc_fraction_min[i][j])} .. "
                         f"{_pct(r.mpc_fraction_max[i][j])}",
                         f"{sum(hv) / len(hv):.4g}" if hv else "nan",
                         _mean(r.mpc_stored_energy_change_j[i][j])])
    out += ["", _table(rows, ["forecast", "horizon (Tp)", "power (W)", "of optimum",
                              "min .. max", "harvested (W)", "dE (J)"])]
    trows = []
    for i, f in enumerate(r.forecasts):
        for j, h in enumerate(r.horizons):
            fails = [v for v in r.mpc_failed_solves[i][j] if v is not None]
            kept = [v for v in r.mpc_failed_kept_previous[i][j] if v is not None]
            trows.append([f, f"{h:g}", f"{1e3 * r.mpc_update_time_median[i][j]:.3g}",
                          f"{1e3 * r.mpc_update_time_p99[i][j]:.3g}",
                          f"{1e3 * r.mpc_update_time_max[i][j]:.3g}",
                          f"{1e3 * r.mpc_update_time_first[i][j]:.3g}",
                          f"{sum(fails)} ({sum(kept)})"])
    out += ["", f"receding-horizon updates (forecast + solves) against the update interval "
                f"{1e3 * r.update_interval_s:.4g} ms: p99 "
                + ("fits" if r.realtime_fits else "does NOT fit"
                   if r.realtime_fits is not None else "not known (runs not finished)")
                + " (one process; the first update, kernel load, apart)",
            _table(trows, ["forecast", "horizon (Tp)", "median (ms)", "p99 (ms)", "max (ms)",
                           "first (ms)", "failed solves (previous plan kept)"]),
            "", f"status: {r.status}: {r.message}"]
    if a.save:
        out.append(f"curve written to {a.save}")
    if a.plot:
        out.append(f"figure written to {a.plot}")
    return out


COMMANDS = {"horizon": _cmd_horizon}
