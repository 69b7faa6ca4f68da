"""``parapend optimize | threshold | damping-sweep | harmonics``."""

from __future__ import annotations

import math

from .. import limits
from ..results import CONVENTION
from . import _output
from . import pto as _pto
from ._common import (
    FIGURE_SUFFIXES,
    SAVE_TABLE,
    _add_excitation,
    _check_output,
    _describe,
    _finite_float,
    _fmt,
    _int,
    _Progress,
    _run,
    _table,
    add_output_options,
)


def add_parsers(sub) -> None:
    """Add optimize, threshold, damping-sweep and harmonics to the subcommand parser."""
    p = sub.add_parser("optimize", help="optimal period-1 rotation (Fourier Eq. 10, BVP Eq. 22)",
                       description="Optimal period-1 rotation by truncated Fourier series "
                                   "(Eqs. 10-11) or the penalized Euler-Lagrange BVP (Eqs. 13, "
                                   "22, 27), beside the best uniform rotation (Eq. 17) and the "
                                   "gamma -> 0 limit (Eqs. 19, 24, 32 generalized).")
    _add_excitation(p)
    p.add_argument("--gamma", type=_finite_float("gamma"),
                   help="viscous damping gamma in [0, 1e3] (default 0; docs/defaults.md)")
    p.add_argument("--harmonics", type=_int,
                   help=f"number N of harmonics, at most {limits.MAX_HARMONICS} (default 24)")
    p.add_argument("--method", choices=["fourier", "bvp", "all"],
                   help="fourier: Eq. 10 with N harmonics; bvp: Euler-Lagrange BVP (Eqs. 13, "
                        "22, 27; needs gamma >= 1e-7); all: uniform, Fourier, BVP and limit "
                        "side by side (default fourier)")
    add_output_options(p, plot="theta(tau) and the torque",
                       save="one period of the motion (time, phase, theta, theta_dot, torque, "
                            "instantaneous_power = -T theta', instantaneous_electrical_power "
                            "with an efficiency; in SI with --length and --mass) and the "
                            "result's scalars")
    p.add_argument("--winding", type=_int,
                   help="K turns per forcing period, theta(t + 2 pi/omega) = theta(t) + 2 pi "
                        "K (default 1, the paper's period-1 rotation; K > 1: method fourier "
                        "with N >= 2K, or bvp; docs/seas.md)")
    _pto.add_pto_options(p)
    _pto.add_unit_options(p)

    p = sub.add_parser("threshold", help="damping gamma* beyond which no power is extracted",
                       description="Damping threshold gamma* where the optimal power "
                                   "vanishes (paper Fig. 6: 0.0856 at delta=-0.3, omega=1.8).")
    _add_excitation(p)
    p.add_argument("--harmonics", type=_int,
                   help=f"fixed N, at most {limits.MAX_THRESHOLD_HARMONICS} (default: doubled "
                        "from 8 until gamma* converges)")
    add_output_options(p, plot="power against damping up to beyond gamma*", save="the result")
    _pto.add_unit_options(p, damping=False)

    p = sub.add_parser("damping-sweep", help="optimal power against damping (paper Fig. 6)",
                       description="Optimal and uniform power against damping gamma, from 0 "
                                   "to 1.25 gamma* by default (paper Fig. 6).")
    _add_excitation(p)
    p.add_argument("--harmonics", type=_int,
                   help=f"N, at most {limits.MAX_SWEEP_HARMONICS} (default 32, or the "
                        "excitation's band when higher)")
    p.add_argument("--gamma-max", type=_finite_float("gamma-max"),
                   help="largest damping (default 1.25 gamma*)")
    p.add_argument("--points", type=_int,
                   help=f"number of dampings, 2 to {limits.MAX_POINTS}, with points x N^2 <= "
                        f"{limits.MAX_SWEEP_WORK} (default 41)")
    add_output_options(p, plot="power against damping", save="the sweep")
    _pto.add_unit_options(p, damping=False)

    p = sub.add_parser("harmonics", help="optimal power against the number of harmonics",
                       description="Fourier optimum for N = FROM..TO by continuation in N "
                                   "(nondecreasing in N), beside the uniform and limit powers.")
    _add_excitation(p)
    p.add_argument("--gamma", type=_finite_float("gamma"),
                   help="viscous damping gamma in [0, 1e3] (default 0; docs/defaults.md)")
    p.add_argument("--from", dest="n_from", type=_int, help="smallest N (default 2)")
    p.add_argument("--to", dest="n_to", type=_int,
                   help=f"largest N, at most {limits.MAX_TABLE_HARMONICS} (default 64)")
    add_output_options(p, plot="power against N", save="the table")
    _pto.add_unit_options(p)


def _cmd_optimize(a) -> dict | str:
    _check_output(a.plot, "--plot", FIGURE_SUFFIXES)
    _check_output(a.save, "--save", SAVE_TABLE)
    r = _run(a)
    _plot_and_save(r, a)
    if a.method == "all":
        return _optimize_all(a, r)
    pto = r.unconstrained_power is not None
    units = None if r.units is None else _pto.units_of(r)
    if a.json:
        return r.to_dict()
    name = (f"Fourier optimum, N = {r.harmonics} (Eq. 10)" if r.method == "fourier"
            else f"BVP optimum, epsilon = {2 * r.gamma:g} (Eq. 22)")
    if r.winding != 1:
        name += f", winding K = {r.winding}"
    if pto:
        name = (f"power take-off optimum, {r.intervals} intervals"
                if r.method in ("hermite", "collocation") else
                "power take-off optimum, constant brake" if r.method == "constant-brake" else
                f"power take-off optimum, N = {r.harmonics}")
        if r.winding != 1:
            name += f", winding K = {r.winding}"
    rows = [
        ["best uniform rotation (Eq. 17)", _fmt(r.uniform_power), ""],
        [name, _fmt(r.power), _gain(r.power, r.uniform_power)],
        ["limit gamma -> 0 (Eqs. 19/24/32)", _fmt(r.limit_power),
         _gain(r.limit_power, r.uniform_power)],
    ]
    if pto:
        rows = _pto.like_for_like_rows(r, name)
    if r.found_by == "constant excitation":
        how = "q is constant: the motion is the uniform rotation theta = omega t"
    elif r.method == "fourier":
        how = (f"{r.iterations} Newton iterations, found from the {r.found_by} seed, "
               f"{len(r.local_maxima)} distinct local maxima")
        search = (f"search: {r.search}, {r.patterns_tried} of {_count(r)} "
                  f"half-turn direction patterns tried, {r.polished} runs polished, "
                  f"{r.abandoned} abandoned as unable to win")
        if r.second_power is not None:
            search += (f"; best other polished maximum {_fmt(r.second_power)}"
                       + (f" ({r.second_distance:.2g} rad RMS away)"
                          if r.second_distance is not None else "")
                       + (" (abandoned runs are not polished: better ones may exist)"
                          if r.abandoned else ""))
    elif r.method == "hermite":
        how = (f"{r.iterations} interior-point iterations, {r.intervals} cubic Hermite "
               f"intervals, started from the {r.found_by}")
    elif r.method == "constant-brake":
        how = (f"the rotation under the constant torque -T_max, {r.harmonics} harmonics "
               f"collocated, Newton; its power T_max K omega bounds every rotation that "
               f"never turns back")
    elif r.method == "collocation":
        how = (f"{r.iterations} interior-point iterations, {r.intervals} Hermite-Simpson "
               f"intervals, started from the {r.found_by}")
    else:
        floor = (f" (rounding floor {r.residual_floor:.2g} near the layer centres)"
                 if r.residual_floor else "")
        how = (f"{r.mesh_nodes} mesh nodes, max residual {r.max_residual:.2g}{floor}, "
               f"{r.continuation_steps} continuation steps, found from the {r.found_by} start")
    out = [f"excitation: {_describe(r.excitation)}; damping gamma = {r.gamma:g}", "",
           _table(rows, ["motion", "power P", "vs uniform"]), "",
           f"status: {r.status} ({how})",
           f"upper bound limit - gamma {'' if r.winding == 1 else 'K^2 '}omega^2: "
           f"{_fmt(r.upper_bound)} "
           f"(gap {_fmt(r.bound_gap)})",
           f"peak torque |T|: {_peak(r)}    mean theta'^2: {r.mean_square_speed:.6g}",
           f"convention: {CONVENTION}"]
    if r.method == "fourier" and r.found_by != "constant excitation":
        out.insert(5, search)
    if r.status == "no_power" or (pto and (not r.success or "; " in r.message)):
        out.insert(5, f"note: {r.message}")
    out += _pto.pto_lines(r) if pto else []
    out += _pto.physical_lines(r, units)
    if a.save:
        out.append(f"motion written to {a.save}")
    if a.plot:
        out.append(f"figure written to {a.plot}")
    return "\n".join(out)


def _peak(r) -> str:
    """The peak torque, marked where it is not converged under mesh refinement."""
    if r.peak_torque_converged is False and r.method == "fourier":
        return (f"{r.peak_torque:.6g} (of the N = {r.harmonics} motion: at gamma = 0 it grows "
                "like N^2 as the optimum approaches the limit's instant flips)")
    if r.peak_torque_converged is False:
        grows = r.peak_torque_coarse is not None and r.peak_torque > 1.5 * r.peak_torque_coarse
        return (f"{'>= ' if grows else ''}{r.peak_torque:.6g} (not converged under mesh "
                "refinement, see below)")
    return f"{r.peak_torque:.6g}"


def _gain(p, pu) -> str:
    return f"{100 * (p / pu - 1):+.2f} %" if pu > 0 else "-"


def _optimize_all(a, rec) -> dict | str:
    """Uniform, Fourier, BVP (gamma > 0 only) and limit for one case."""
    f, b = rec.fourier_result, rec.bvp_result
    if a.json:
        return rec.to_dict()
    rows = [[f"best uniform rotation at gamma = {f.gamma:g} (Eq. 17)",
             _fmt(f.uniform_power, 10), "", "closed form"],
            [f"Fourier, N = {f.harmonics} (Eq. 10)", _fmt(f.power, 10),
             _gain(f.power, f.uniform_power), f.status],
            [f"BVP, epsilon = {2 * f.gamma:g} (Eq. 22)",
             "-" if b is None else _fmt(b.power, 10),
             "-" if b is None else _gain(b.power, f.uniform_power),
             f"needs gamma >= {limits.MIN_BVP_GAMMA:g}" if b is None else
             f"{b.status}, {b.mesh_nodes} nodes, residual {b.max_residual:.1e}"
             if b.mesh_nodes is not None else b.status],
            ["limit gamma -> 0, undamped (Eqs. 19/24/32)", _fmt(f.limit_power, 10),
             _gain(f.limit_power, f.uniform_power), "closed form, gamma = 0"]]
    out = [f"excitation: {_describe(f.excitation)}; damping gamma = {f.gamma:g}", "",
           _table(rows, ["method", "power P", "vs uniform", "status"])]
    if f.gamma > 0:
        out += ["", f"note: the limit row is the undamped (gamma = 0) supremum, an upper bound; "
                    f"the other rows are at gamma = {f.gamma:g}"]
    if b is not None:
        out += ["", f"Fourier - BVP: {f.power - b.power:+.3e}  (agree when N resolves the "
                    "boundary layers)"]
    return "\n".join(out + _written(a))


def _count(r) -> str:
    """``C(2m, m - 1)`` exactly when short, else as a power of ten (from log-gamma)."""
    if isinstance(r.candidate_patterns, int) and r.candidate_patterns < 10**9:
        return str(r.candidate_patterns)
    m = r.extrema_per_period // 2
    lg = (math.lgamma(2 * m + 1) - math.lgamma(m) - math.lgamma(m + 2)) / math.log(10)
    return f"about 10^{lg:.1f}"


def _cmd_threshold(a) -> dict | str:
    _check_output(a.plot, "--plot", FIGURE_SUFFIXES)
    _check_output(a.save, "--save", SAVE_TABLE)
    r = _run(a)
    _plot_and_save(r, a)
    if a.json:
        return r.to_dict()
    si = []
    if r.units is not None:
        u = r.units
        si = [f"damping threshold as a coefficient c*: {r.damping_threshold_coefficient:.6g} "
              f"N m s/rad (c = gamma I / t0; I = {u['inertia_kg_m2']:g} kg m^2, t0 = "
              f"{u['time_unit_s']:.6g} s)",
              f"uniform-rotation threshold as a coefficient: "
              f"{r.uniform_threshold_coefficient:.6g} N m s/rad"]
    return "\n".join([
        f"excitation: {_describe(r.excitation)}",
        f"damping threshold gamma*: {_fmt(r.damping_threshold, 10)}  (optimal power vanishes)",
        f"uniform-rotation threshold: {_fmt(r.uniform_threshold, 10)}  (|Q1| / 2 omega)",
        f"status: {r.status} (N = {r.harmonics}, {r.iterations} Newton steps in gamma; "
        f"change from N/2: {_fmt(r.refinement_change, 3)})",
        *si, *_written(a)])


def _si_table(ds, coord: str, cols) -> str:
    """The SI columns of a one-dimensional Dataset, beside its coordinate."""
    rows = [[_fmt(v)] + [f"{ds[c].values[i]:.6g}" for c, _ in cols]
            for i, v in enumerate(ds[coord].values)]
    return "in SI units:\n" + _table(rows, [coord] + [h for _, h in cols])


def _written(a) -> list[str]:
    return ([f"result written to {a.save}"] if a.save else []) + (
        [f"figure written to {a.plot}"] if a.plot else [])


def _plot_and_save(r, a) -> None:
    """``--plot`` and ``--save`` of a result (:mod:`parapend.results`)."""
    if a.plot:
        _output.save_plot(r, a.plot)
    if a.save:
        _output.save_result(r, a.save)


def _cmd_damping_sweep(a) -> dict | str:
    _check_output(a.plot, "--plot", FIGURE_SUFFIXES)
    _check_output(a.save, "--save", SAVE_TABLE)
    ds = _run(a, progress=_Progress("damping sweep"))
    _plot_and_save(ds, a)
    if a.json:
        return ds.to_dict()
    rows = [[_fmt(g), _fmt(p), _fmt(u), f"{t:.4g}" + ("*" if g == 0 else ""), str(s)]
            for g, p, u, t, s in zip(
        ds["gamma"].values, ds["power"].values, ds["uniform_power"].values,
        ds["peak_torque"].values, ds["status"].values)]
    out = [f"excitation: {ds.attrs['excitation']}, omega={ds.attrs['omega']}; "
           f"N = {ds.attrs['harmonics']}", "",
           _table(rows, ["gamma", "optimal P", "uniform P", "peak |T|", "status"]), "",
           f"damping threshold gamma*: {_fmt(ds.attrs['damping_threshold'], 10)}"
           + (f" (c* = {ds.attrs['damping_threshold_coefficient']:.6g} N m s/rad)"
              if "damping_threshold_coefficient" in ds.attrs else ""),
           f"resolution check: end points with 2N change by at most "
           f"{_fmt(ds.attrs['refinement_change'], 3)}"]
    if (ds["gamma"].values == 0).any():
        out.append(f"* {ds.attrs['peak_torque_note']}")
    if "power_w" in ds:
        out.append(_si_table(ds, "gamma", [("damping_coefficient", "c (N m s/rad)"),
                                           ("power_w", "optimal P (W)"),
                                           ("uniform_power_w", "uniform P (W)"),
                                           ("peak_torque_nm", "peak |T| (N m)")]))
    if a.plot:
        out.append(f"figure written to {a.plot}")
    return "\n".join(out)


def _cmd_harmonics(a) -> dict | str:
    _check_output(a.plot, "--plot", FIGURE_SUFFIXES)
    _check_output(a.save, "--save", SAVE_TABLE)
    ds = _run(a, progress=_Progress("harmonics"))
    _plot_and_save(ds, a)
    if a.json:
        return ds.to_dict()
    rows = [[str(n), _fmt(p, 8), str(s), "global" if g else "continued"]
            for n, p, s, g in zip(ds["harmonics"].values, ds["power"].values,
                                  ds["status"].values, ds["global_search"].values)]
    out = [_table(rows, ["N", "optimal P", "status", "search"]), "",
           f"best uniform: {_fmt(ds.attrs['uniform_power'], 8)}    "
           f"limit gamma -> 0 (undamped): {_fmt(ds.attrs['limit_power'], 8)}",
           f"band of q: {ds.attrs['spectrum_harmonics']} harmonics; last row with 2N changes "
           f"by {_fmt(ds.attrs['refinement_change'], 3)}"]
    if "power_w" in ds:
        out.append(f"in watts: best uniform {ds.attrs['uniform_power_w']:.6g} W, limit "
                   f"{ds.attrs['limit_power_w']:.6g} W; optimal P at N = "
                   f"{int(ds['harmonics'].values[-1])}: {float(ds['power_w'].values[-1]):.6g} W")
    if a.plot:
        out.append(f"figure written to {a.plot}")
    return "\n".join(out)


COMMANDS = {"optimize": _cmd_optimize, "threshold": _cmd_threshold,
            "damping-sweep": _cmd_damping_sweep, "harmonics": _cmd_harmonics}
