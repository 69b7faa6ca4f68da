"""``parapend track``: swing up from rest, catch and hold the optimal rotation."""

from __future__ import annotations

from .. import limits
from . import _output
from ._common import (
    FIGURE_SUFFIXES,
    SAVE_TABLE,
    _add_excitation,
    _check_output,
    _finite_float,
    _fmt,
    _int,
    _Progress,
    _run,
)


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "track", help="closed loop: swing up from rest, catch and hold the optimal rotation",
        description="Simulate the full nonlinear model (Eq. 14) under a sampled controller "
                    "(256 samples per forcing period): energy pumping from the hanging rest, "
                    "then the optimal torque as feedforward plus a periodic LQR on the "
                    "wrapped error, saturated at |T| <= --torque-limit. Under a torque limit "
                    "the torque-limited optimum at (1 - --torque-margin) T_max is tracked. "
                    "theta is measured from the upright (hanging at rest is pi).")
    _add_excitation(p)
    p.add_argument("--gamma", type=_finite_float("gamma"),
                   help="viscous damping gamma in [0, 1e3] (default 0; docs/defaults.md)")
    p.add_argument("--harmonics", type=_int,
                   help=f"N of the optimum, at most {limits.MAX_PTO_HARMONICS} with a torque "
                        "limit (default 24)")
    g = p.add_argument_group("power take-off and controller")
    g.add_argument("--torque-limit", type=_finite_float("torque-limit"),
                   help="|T(t)| <= this, units m g l (> 0; default: no limit)")
    g.add_argument("--torque-margin", type=_finite_float("torque-margin"),
                   help="fraction of the torque limit kept for feedback, in [0, 0.9] "
                        "(default 0.1)")
    g.add_argument("--r-weight", type=_finite_float("r-weight"),
                   help="LQR torque weight R (Q = identity), in [1e-6, 1e6] (default 0.1)")
    g.add_argument("--lock-tolerance", type=_finite_float("lock-tolerance"),
                   help="largest angle error (rad) of a locked period (default 0.1)")
    g.add_argument("--theta0", type=_finite_float("theta0"),
                   help="initial angle from the upright (default pi: hanging)")
    g.add_argument("--theta-dot0", type=_finite_float("theta-dot0"),
                   help="initial angular speed (default 0)")
    g = p.add_argument_group("run and robustness (seeded)")
    g.add_argument("--periods", type=_int,
                   help=f"forcing periods simulated, 20 to {limits.MAX_TRACK_PERIODS} "
                        "(default 100)")
    g.add_argument("--seed", type=_int, help="seed of noise and irregular q")
    g.add_argument("--runs", type=_int,
                   help="seeded runs; with more than one, each run draws its model errors "
                        f"uniformly within +-the given ones (runs x periods <= "
                        f"{limits.MAX_TRACK_WORK}; default 1)")
    g.add_argument("--gamma-error", type=_finite_float("gamma-error"),
                   help="relative error of the plant's damping, in [-0.9, 0.9]")
    g.add_argument("--delta-error", type=_finite_float("delta-error"),
                   help="relative error of the plant's excitation amplitude, in [-0.9, 0.9]")
    g.add_argument("--noise-theta", type=_finite_float("noise-theta"),
                   help="std of the measurement noise on theta, rad, in [0, 1]")
    g.add_argument("--noise-speed", type=_finite_float("noise-speed"),
                   help="std of the measurement noise on theta', in [0, 10]")
    g.add_argument("--irregular", action="store_true",
                   help="drive the plant with a seeded JONSWAP sea record (parapend.seas) "
                        "peaked at omega, with the rms of q, instead of q")
    g = p.add_argument_group("receding-horizon control (--controller mpc)")
    from ..defaults import TRACK

    g.add_argument("--controller", choices=("lqr", "mpc"),
                   help="lqr: hold the regular-wave optimum (feedforward + periodic LQR); "
                        "mpc: receding-horizon control on the full model with a wave "
                        f"forecast (docs/control.md; default {TRACK['controller']})")
    g.add_argument("--horizon", type=_finite_float("horizon"),
                   help="MPC horizon in peak (forcing) periods, in [0.01, 20] (default "
                        f"{TRACK['horizon']:g})")
    g.add_argument("--update-interval", type=_finite_float("update-interval"),
                   help="MPC update interval in peak periods, at most the horizon "
                        f"(default {TRACK['update_interval']:g})")
    g.add_argument("--time-limit", type=_finite_float("time-limit"), metavar="SECONDS",
                   help="run the MPC for at most about this long, then stop with a partial "
                        "result marked time_limit (without it, a run estimated over 2 "
                        "minutes is refused)")
    g.add_argument("--forecast", choices=("perfect", "ar"),
                   help="MPC wave forecast: perfect (the record's own future) or ar "
                        f"(autoregressive, fitted on the past; default {TRACK['forecast']})")
    g.add_argument("--speed-limit", type=_finite_float("speed-limit"),
                   help="MPC rated-speed penalty: the plans pay rho/2 h sum max(|theta'_k| - "
                        "w, 0)^2 at their nodes, a penalty and not a hard bound (the measured "
                        "speed can exceed it; the run reports how often and how far), in "
                        "units of sqrt(g/l), > 0; default none (docs/control.md)")
    from .pto import add_unit_options

    add_unit_options(p, torque=True)
    p.add_argument("--save", metavar="FILE",
                   help="write the run (time, theta, theta_dot, torque held on [t, t + h), "
                        "q; in SI with --length and --mass) and the scalars: .csv (with a "
                        "row of units), .nc or .json; with --runs, each run's power")
    p.add_argument("--plot", metavar="PNG",
                   help="draw theta, torque and cumulative energy (PNG, SVG or PDF); one run")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def _mult(ms) -> str:
    return ", ".join(f"{complex(re, im):.4g} (|.| {abs(complex(re, im)):.4g})"
                     for re, im in ms)


def _si_lines(r) -> list[str]:
    """Watts, N m and seconds beside the non-dimensional numbers (with --length, --mass)."""
    if r.units is None:
        return []
    u = r.units
    return [f"physical (l = {u['length_m']:g} m, m = {u['mass_kg']:g} kg): forcing period "
            f"{r.period_s:.6g} s; mean power {r.mean_power_w:.6g} W (predicted "
            f"{r.predicted_power_w:.6g} W); peak torque {r.peak_torque_nm:.6g} N m"
            + (f", limit {r.torque_limit_nm:.6g} N m" if r.torque_limit_nm is not None
               else "")]


def _cmd_track(a) -> dict | str:
    _check_output(a.plot, "--plot", FIGURE_SUFFIXES)
    _check_output(a.save, "--save", SAVE_TABLE)
    if a.controller == "mpc":
        from ._notice import install
        from .sweep import _EtaProgress

        install("parapend.control")  # the library's estimate of long work, on stderr
        r = _run(a, progress=_EtaProgress("track"))
    else:
        r = _run(a, progress=_Progress("track")) if a.runs != 1 else _run(a)
    if getattr(r, "controller", None) == "mpc":
        return _mpc_out(a, r)
    if a.runs != 1:
        if a.save:
            _output.save_result(r, a.save)
        if a.plot:
            _output.save_plot(r, a.plot)
        if a.json:
            return r.to_dict()
        return "\n".join([
            f"{r.runs} seeded runs (seed {r.seed}), {r.periods} periods each, from the "
            f"hanging rest; gamma = {r.gamma:g}, omega = {r.omega:g}, T_max = "
            f"{_fmt(r.torque_limit)}",
            f"plant: gamma error within +-{r.gamma_error:g}, delta error within "
            f"+-{r.delta_error:g}, noise (theta, theta') = ({r.noise_theta:g}, "
            f"{r.noise_speed:g}), irregular q: {'yes' if r.irregular else 'no'}",
            f"locked: {sum(r.run_locked)} of {r.runs} runs ({100 * r.fraction_locked:.3g} %)"
            + (f", the latest after {r.lock_period_max} periods"
               if r.lock_period_max is not None else ""),
            f"mean power (each run's from its lock, else its last 10 periods, with the "
            f"change of stored energy): mean {_fmt(r.mean_power, 6)} (min "
            f"{_fmt(r.power_min, 6)}, max {_fmt(r.power_max, 6)}); locked runs "
            f"{_fmt(r.locked_mean_power, 6)}; predicted {_fmt(r.predicted_power, 6)}",
            f"peak torque {_fmt(r.peak_torque, 5)}", *_si_lines(r)])
    if a.save:
        _output.save_result(r, a.save)
    if a.plot:
        _output.save_plot(r, a.plot)
    if a.json:
        return r.to_dict()
    out = [f"{r.status}: {r.message}",
           f"gamma = {r.gamma:g}, omega = {r.omega:g}, T_max = {_fmt(r.torque_limit)}"
           + (f" (tracking the optimum at {r.design_torque_limit:.6g})"
              if r.design_torque_limit is not None else ""),
           f"mean power {_fmt(r.mean_power, 8)} over periods {r.average_start_period} to "
           f"{r.average_start_period + r.averaged_periods}"
           + (" (from the lock" if r.locked else " (the last ones: not locked")
           + f"; the harvested power {_fmt(r.harvested_power, 8)} with the span's change of "
           f"stored energy {_fmt(r.stored_energy_change, 6)} m g l); predicted "
           f"{_fmt(r.predicted_power, 8)}"
           + (f"; optimum at T_max {_fmt(r.optimum_at_torque_limit, 8)}"
              if r.optimum_at_torque_limit is not None else ""),
           f"swing-up handed over after {_fmt(r.catch_period, 4)} periods; energy before "
           f"the lock {_fmt(r.energy_before_lock, 6)} (m g l), " + (
               f"paid back in {_fmt(r.payback_periods, 4)} periods"
               if r.payback_periods is not None else
               "never paid back (the locked power is not positive)" if r.locked else
               "no payback (not locked)"),
           f"tracked optimum: status {r.optimum_status}",
           f"peak torque applied {_fmt(r.peak_torque, 5)} (the optimum's "
           f"{_fmt(r.tracked_peak_torque, 5)}); tracking error {r.tracking_error:.3g} rad",
           f"Floquet multipliers, open loop: {_mult(r.open_loop_multipliers)}",
           f"closed loop: {_mult(r.closed_loop_multipliers)}"]
    if r.sea is not None:
        out.append(_sea_line(r.sea))
    out += _si_lines(r)
    if a.save:
        out.append(f"run written to {a.save}")
    if a.plot:
        out.append(f"figure written to {a.plot}")
    return "\n".join(out)


def _sea_line(sea: dict) -> str:
    """The irregular sea of a ``track --irregular`` run, in one line."""
    return (f"irregular sea: JONSWAP peaked at omega {sea['peak_omega']:g}, Hs "
            f"{sea['hs']:.4g} (units g t0^2), rms of q {sea['rms_q']:.4g}, "
            f"{sea['components']} components, repeating every "
            f"{sea['repeat_periods']} peak periods, seed {sea['seed']}")


def _mpc_out(a, r) -> dict | str:
    """Save, plot and print a ``--controller mpc`` run."""
    if a.save:
        _output.save_result(r, a.save)
    if a.plot:
        _output.save_plot(r, a.plot)
    if a.json:
        return r.to_dict()
    out = [f"{r.status}: {r.message}",
           f"receding-horizon control, {r.forecast} forecast: horizon {r.horizon:g} "
           f"periods, update every {r.update_interval:g} periods, {r.samples_per_period} "
           f"torque samples per period; gamma = {r.gamma:g}, omega = {r.omega:g}, T_max = "
           f"{_fmt(r.torque_limit)}"
           + (f", rated-speed penalty {r.speed_limit:g}" if r.speed_limit is not None
              else ""),
           f"mean power {_fmt(r.mean_power, 6)} = (harvested energy "
           f"{_fmt(r.harvested_energy, 6)} + change of stored energy "
           f"{_fmt(r.stored_energy_change, 6)}) / time {_fmt(r.averaged_time, 6)}, from "
           f"period {r.warm_up_periods} to the end (energies in m g l, time in sqrt(l/g))",
           f"harvested alone {_fmt(r.harvested_power, 6)}; electrical "
           f"{_fmt(r.electrical_power, 6)}"
           + (f"; over the last repeat of the record {_fmt(r.record_power, 6)}"
              if r.record_power is not None else ""),
           f"swing-up handed over after {_fmt(r.catch_period, 4)} periods; peak torque "
           f"{_fmt(r.peak_torque, 5)}"]
    if r.speed_limit is not None and r.speed_exceeded_fraction is not None:
        out.append(f"rated-speed penalty {r.speed_limit:g}: |theta'| above it on "
                   f"{100 * r.speed_exceeded_fraction:.3g} % of the samples after the "
                   f"hand-over, peak {r.speed_peak:.4g} "
                   f"({100 * (r.speed_peak / r.speed_limit - 1):+.3g} %)")
    if r.update_time_median is not None:
        out.append(
            f"{r.solves} updates (forecast + solve), after the first: median "
            f"{1e3 * r.update_time_median:.3g} ms, p99 {1e3 * r.update_time_p99:.3g} ms, max "
            f"{1e3 * r.update_time_max:.3g} ms (forecast {1e3 * r.forecast_time_median:.3g}, "
            f"solve {1e3 * r.solve_time_median:.3g} ms median); the first "
            f"{1e3 * r.update_time_first:.3g} ms (kernel load); median "
            f"{r.iterations_median:g} Newton iterations; {r.failed_solves} not converged")
    if r.sea is not None:
        out.append(_sea_line(r.sea))
    if r.units is not None:
        u = r.units
        out.append(f"physical (l = {u['length_m']:g} m, m = {u['mass_kg']:g} kg): period "
                   f"{r.period_s:.6g} s; mean power {r.mean_power_w:.6g} W (harvested alone "
                   f"{r.harvested_power_w:.6g} W, stored energy change "
                   f"{r.stored_energy_change_j:.6g} J); peak torque {r.peak_torque_nm:.6g} "
                   "N m")
        if r.update_time_p99 is not None:
            out.append(f"real time: update interval {1e3 * r.update_interval_s:.4g} ms; "
                       f"p99 of an update {1e3 * r.update_time_p99:.3g} ms "
                       + ("fits in it" if r.realtime_fits else "does NOT fit in it")
                       + " (measured on one process, single-threaded kernels)")
    elif r.update_time_p99 is not None:
        out.append("real time: give --length and --mass to state the update interval in "
                   "seconds and whether the updates fit in it")
    if a.save:
        out.append(f"run written to {a.save}")
    if a.plot:
        out.append(f"figure written to {a.plot}")
    return "\n".join(out)


COMMANDS = {"track": _cmd_track}
