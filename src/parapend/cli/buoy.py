"""``parapend buoy``: the pendulum inside a floating buoy, coupled both ways (docs/buoy.md)."""

from __future__ import annotations

import os
from pathlib import Path

from ..defaults import BUOY
from ..errors import ParameterError
from ..hydro.device import Body, Controller, Pendulum, PowerTakeOff, Sea
from ._common import (
    SAVE_ALL,
    _check_output,
    _finite_float,
    _fmt,
    _int,
    _Progress,
    _run,
    _table,
    add_declared,
    hull_options,
    unresolved_if,
)


def _text(name):
    def conv(text):
        return text

    conv.__name__ = name
    return conv


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "buoy", help="a pendulum inside a floating buoy: the coupled optimum, with Capytaine "
                     "hydrodynamics",
        description="The largest power a pendulum inside a heaving buoy harvests, with the "
                    "pendulum's reaction on the buoy (coupled both ways), beside the radiation "
                    "bound, the one-way answer (reaction left out) and the free buoy. SI "
                    "units. With no options: the embedded default design (docs/buoy.md, "
                    "docs/defaults.md).")
    # the sea's, the pendulum's, the take-off's and the controller's options: generated from
    # their declarations (parapend.hydro.device), the one place of each name, unit, default
    # and help
    g = p.add_argument_group("regular wave")
    add_declared(g, Sea, ("wave_height", "wave_period"))
    g = p.add_argument_group("irregular sea (as 'parapend sea' takes it)")
    add_declared(g, Sea, ("hs", "tp", "spectrum", "gamma_peak", "repeat_period", "seed",
                          "cutoff", "record", "taper"))
    g = p.add_argument_group("pendulum (SI units)")
    add_declared(g, Pendulum, ("mass", "length", "inertia", "damping_coefficient"))
    g = p.add_argument_group("body (Capytaine; the BEM result is cached on disk)")
    from ._common import add_body_options

    add_body_options(g, command="buoy")
    p.set_defaults(body=None)  # so that --body given beside --hydro or --mesh is refused
    add_declared(g, Sea, ("wave_direction",))

    g = p.add_argument_group("hull: surge, heave and pitch (docs/hull.md)")
    add_declared(g, Body, ("dofs",))
    hull_options(g)
    g = p.add_argument_group("motion and power take-off")
    g.add_argument("--winding", type=_int,
                   help="turns per wave (per record in an irregular sea) (default 1; with "
                        "--dofs surge,heave,pitch: rotation both ways (1, and -1 against "
                        "the sense of a positive pitch) and swinging (0) side by side)")
    g.add_argument("--harmonics", type=_int,
                   help="N of the motion (default chosen from the problem and checked)")
    add_declared(g, PowerTakeOff, ("torque_limit", "efficiency", "copper_loss"))
    g = p.add_argument_group("design")
    g.add_argument("--optimize-design", metavar="NAMES",
                   help="choose these pendulum parameters for the most power: a comma list "
                        "of mass, length, inertia, damping-coefficient")
    for name, what in (("mass", "kg"), ("length", "m"), ("inertia", "kg m^2"),
                       ("damping-coefficient", "N m s/rad")):
        g.add_argument(f"--{name}-bounds", metavar="LO:HI", default=None,
                       help=f"range of {name} searched, {what} (default "
                            + ("0:20" if name.startswith("damping") else
                               f"{BUOY['design_bounds'][name][0]:g} to "
                               f"{BUOY['design_bounds'][name][1]:g} x the design's") + ")")
    g = p.add_argument_group("causal control (an irregular sea, the coupled time-domain plant)")
    add_declared(g, Controller, ("controller", "horizon", "update_interval", "forecast"))
    g.add_argument("--planner", choices=("plan", "coupled", "lbfgsb", "collocation"),
                   help="with mpc, the horizon's solver: the heaving buoy's plan (default) or "
                        "coupled (default with --efficiency); the hull's collocation "
                        "(default: the motion as the unknown, a compiled interior point) or "
                        "lbfgsb (the held torques shot through the model, faster, far from "
                        "the optimum on long records)")
    g = p.add_argument_group("statistics of a sea state (--dofs surge,heave,pitch)")
    g.add_argument("--realizations", type=_int, metavar="R",
                   help="solve R records of the sea state (--hs, --tp), seeded --seed, "
                        "--seed + 1, ...: their mean power and its 95 %% t-interval (default: "
                        "one record)")
    p.add_argument("--time-limit", type=_finite_float("time-limit"), metavar="SECONDS",
                   help="run long work (--optimize-design, a period sweep, --controller mpc, "
                        "--realizations) "
                        "for at most about this long, then stop with a partial result marked "
                        "time_limit (without it, work estimated over 2 minutes is refused)")
    p.add_argument("--plot", metavar="DIR",
                   help="draw the figures (PNG and SVG) into this directory")
    p.add_argument("--save", metavar="FILE",
                   help="write the motion (or the sweep, or the causal run) by its extension: "
                        ".nc, .json, .csv (a row of units under the header), .png, .svg, .pdf")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def _check_dir(path):
    if path is None:
        return
    if not path.strip():
        raise ParameterError("plot: expected a directory name, got an empty string")
    d = Path(path)
    if d.exists() and not d.is_dir():
        raise ParameterError(f"plot: {path!r} is a file, expected a directory")
    parent = d if d.exists() else (d.parent if str(d.parent) else Path("."))
    if not parent.is_dir():
        raise ParameterError(f"plot: directory {str(parent)!r} does not exist")
    if not os.access(parent, os.W_OK):
        raise ParameterError(f"plot: directory {str(parent)!r} is not writable")
    # a probe before the work: access() says yes to root on /proc, where nothing is made
    try:
        if d.exists():
            import tempfile

            with tempfile.TemporaryFile(dir=d):
                pass
        else:
            d.mkdir()
            d.rmdir()
    except OSError as exc:
        raise ParameterError(f"plot: cannot write into {path!r}: "
                             f"{exc.strerror or exc}") from None


def _figures(r, directory) -> list:
    from ..fileio import output_error, save_figure
    from ..hydro.figures import plot_motion, plot_sweep

    d = Path(directory)
    try:
        d.mkdir(exist_ok=True)
    except OSError as exc:
        raise output_error(directory, exc) from None
    sweep = hasattr(r, "period_s")
    if hasattr(r, "update_interval_s"):  # a closed-loop run: its own time series
        fig, name = r.plot(), "buoy_mpc"
    else:
        fig = plot_sweep(r) if sweep else plot_motion(r)
        name = "buoy_power" if sweep else "buoy_motion"
    out = []
    for ext in ("png", "svg"):
        path = d / f"{name}.{ext}"
        save_figure(fig, path, close=ext == "svg")
        out.append(str(path))
    return out


def _cmd_buoy(a) -> dict | str:
    _check_dir(a.plot)
    _check_output(a.save, "--save", SAVE_ALL)
    try:
        if a.optimize_design or a.realizations:
            from ._notice import install

            install("parapend.hydro")  # the design search's estimate, on stderr
        bar = (_Progress("buoy: optimize-design" if a.optimize_design else
                         "buoy: realizations")
               if (a.optimize_design or a.realizations) and not a.json else None)
        r = _run(a, progress=bar)
    except MemoryError:
        # the generic message names --points, which this command has not
        from ..errors import SolverError

        raise SolverError("out of memory; use smaller --harmonics or --winding, a shorter "
                          "record (--repeat-period, --record), or a smaller --mesh") from None
    if hasattr(r, "planner"):  # a causal run (BuoyMPCResult)
        from ..hydro.control import mpc_text

        written = [a.save] if a.save else []
        if a.save:
            r.save(a.save)
        if a.plot:
            written += _figures(r, a.plot)
        return unresolved_if(r.to_dict() if a.json else "\n".join(
            mpc_text(r) + [f"written: {w}" for w in written]), r)
    if tuple(r.dofs) != ("heave",):
        return _hull_output(r, a)
    sweep = hasattr(r, "period_s")
    if not sweep and r.status == "no_power":
        head = r.message.split(":", 1)[0]
        if head in ("wave", "torque-limit"):
            raise ParameterError(r.message)
        name = "efficiency" if r.message.startswith("no electrical") else "damping-coefficient"
        raise ParameterError(f"{name}: {r.message}")
    written = []
    if a.save:
        r.save(a.save)
        written.append(a.save)
    if a.plot:
        written += _figures(r, a.plot)
    if a.json:
        return r.to_dict()
    out = _sweep_text(r) if sweep else _text_result(r)
    out += [f"written: {w}" for w in written]
    return "\n".join(out)


def _w(x):
    return "-" if x is None else f"{x:.6g}"


def _head(r) -> list:
    p, b = r.pendulum, r.body
    return [f"body: {b['description']}; M = {b['mass_kg']:.6g} kg (floating, pendulum "
            f"included), C = {b['hydrostatic_stiffness_n_per_m']:.6g} N/m",
            f"pendulum: m = {p['mass_kg']:g} kg, l = {p['length_m']:g} m, I = "
            f"{p['inertia_kg_m2']:.6g} kg m^2, c = "
            f"{p['damping_coefficient_nm_s_per_rad']:g} N m s/rad"]


def _text_result(r) -> list:
    w = r.wave
    if w["kind"] == "regular":
        wave = (f"wave: regular, H = {w['height_m']:g} m, T = {w['period_s']:g} s "
                f"(energy flux J = {r.energy_flux_w_per_m:.6g} W/m)")
    else:
        src = (f"{w['spectrum']}, Hs = {w['hs']:g} m, Tp = {w['tp']:g} s, seed {w['seed']}"
               if "hs" in w else f"record {w['record']}")
        wave = (f"wave: irregular, {src}, repeat period {w['repeat_period']:.6g} s "
                f"(energy flux J = {r.energy_flux_w_per_m:.6g} W/m)")
    rows = [["coupled optimum: power", _w(r.power_w), "W"],
            ["  heave amplitude (half peak-to-peak)", _w(r.heave_amplitude_m), "m"],
            ["  peak torque", _w(r.peak_torque_nm), "N m"],
            ["  capture width P / J", _w(r.capture_width_m), "m"],
            ["  capture-width ratio (over 2 radius)", _w(r.capture_width_ratio), "-"],
            ["radiation bound |F a|^2 / 8B", _w(r.radiation_bound_w), "W"],
            ["  its error from the data's noise", _w(r.bound_error_w), "W"],
            ["  fraction reached", _w(r.bound_fraction), "-"],
            ["capture-width limit J 3 lambda / (2 pi)", _w(r.capture_width_limit_w), "W"],
            ["coupled limit (c = 0 supremum)", _w(r.limit_w), "W"],
            ["one-way (reaction left out): power", _w(r.one_way_power_w), "W"],
            ["  one-way / coupled", _w(r.one_way_ratio), "-"],
            ["free buoy: heave amplitude", _w(r.free_heave_amplitude_m), "m"]]
    if r.grid_error_w is not None:
        rows.insert(1, ["  grid error estimate |P - P(every other frequency)|",
                        _w(r.grid_error_w), "W"])
    if r.mesh_error_w is not None:
        rows.insert(1, ["  mesh error estimate |P - P(coarser mesh)|", _w(r.mesh_error_w),
                        "W"])
    if r.torque_limit_nm is not None:
        rows.insert(3, ["  torque limit", _w(r.torque_limit_nm), "N m"])
    if r.electrical_power_w is not None:
        rows[0][0] = "coupled optimum: electrical power (maximized)"
        rows[1:1] = [["  mechanical power", _w(r.mechanical_power_w), "W"],
                     ["  take-off losses", _w(r.pto_loss_w), "W"],
                     ["  generated / motoring", f"{r.generated_power_w:.6g} / "
                      f"{r.motoring_power_w:.6g}", "W"],
                     ["  ideal (lossless) optimum", _w(r.ideal_power_w), "W"]]
        rows.append(["one-way: electrical power", _w(r.one_way_electrical_power_w), "W"])
    out = [wave, *_head(r), "", _table(rows, ["quantity", "value", "unit"]), ""]
    if r.design:
        d = r.design
        out.append(f"design: {', '.join(d['variables'])} chosen within "
                   + ", ".join(f"{k} [{lo:g}, {hi:g}]" for k, (lo, hi) in d["bounds"].items())
                   + f" ({d['method']}; {d['evaluations']} inner optima)")
        for k, side in d.get("at_bound", {}).items():
            lo, hi = d["bounds"][k]
            out.append(f"design: {k} lies on its {side} bound {lo if side == 'lower' else hi:g}"
                       f": the best design may lie beyond it (widen "
                       f"--{k.replace('_', '-')}-bounds)")
        if d.get("status") == "time_limit":
            out.append(f"design: PARTIAL: {d['message']}")
    out.append(f"status: {r.status}; N = {r.harmonics}, winding {r.winding}; energy balance "
               f"residual {r.energy_balance_residual:.1e}")
    out += [f"note: {n}" for n in r.warnings]
    out += [f"warning: {n}" for n in r.validity_warnings]
    return out


def _sweep_text(r) -> list:
    rows = [[f"{t:g}", _fmt(p), _fmt(o), _fmt(b), _fmt(lim), _fmt(f), _fmt(z), s]
            for t, p, o, b, lim, f, z, s in zip(r.period_s, r.power_w, r.one_way_power_w,
                                                r.radiation_bound_w, r.limit_w,
                                                r.bound_fraction, r.heave_amplitude_m,
                                                r.status)]
    head = ["T (s)", "power (W)", "one-way (W)", "bound (W)", "limit (W)", "fraction",
            "heave (m)", "status"]
    if r.mechanical_power_w is not None:
        for row, e in zip(rows, r.mechanical_power_w):
            row.insert(2, _fmt(e))
        head[1:2] = ["electrical (W)", "mechanical (W)"]
    for name, label in (("mesh_error_w", "mesh err (W)"), ("grid_error_w", "grid err (W)")):
        if getattr(r, name) is not None:
            for row, e in zip(rows, getattr(r, name)):
                row.insert(-1, _fmt(e))
            head.insert(-1, label)
    out = [f"regular waves, H = {r.wave_height_m:g} m", *_head(r), "",
           _table(rows, head)]
    out += [f"note: {n}" for n in r.warnings]
    out += [f"warning: {n}" for n in r.validity_warnings]
    return out


def _hull_output(r, a):
    """Text, JSON, NetCDF and figures of a hull result (``--dofs surge,heave,pitch``)."""
    written = []
    if a.save:
        r.save(a.save)
        written.append(a.save)
    if a.plot:
        from ..fileio import output_error, save_figure

        d = Path(a.plot)
        try:
            d.mkdir(exist_ok=True)
        except OSError as exc:
            raise output_error(a.plot, exc) from None
        fig = r.plot()
        name = "hull_power" if hasattr(r, "period_s") else "hull_motion"
        for ext in ("png", "svg"):
            save_figure(fig, d / f"{name}.{ext}", close=ext == "svg")
            written.append(str(d / f"{name}.{ext}"))
    if a.json:
        return unresolved_if(r.to_dict(), r)
    out = _hull_sweep_text(r) if hasattr(r, "period_s") else _hull_text(r)
    return unresolved_if("\n".join(out + [f"written: {w}" for w in written]), r)


def _hull_head(r) -> list:
    p, b, v = r.pendulum, r.body, r.pivot
    return [f"hull: {b['description']} (surge, heave, pitch)",
            f"pendulum: m = {p['mass_kg']:g} kg, l = {p['length_m']:g} m, I = "
            f"{p['inertia_kg_m2']:.6g} kg m^2, c = {p['damping_coefficient']:g} N m s/rad; "
            f"pivot {v['pivot_height_m']:g} m above and {v['pivot_offset_m']:g} m ahead of "
            "the rotation centre"]


def _hull_text(r) -> list:
    w = r.wave
    wave = (f"wave: regular, H = {w['height_m']:g} m, T = {w['period_s']:g} s"
            if w.get("kind") == "regular" else
            f"wave: irregular record, repeat period {w['repeat_period']:.6g} s")
    from ..hydro.result import best_label, mode_label

    modes = [[mode_label(m), _w(m["power_w"]), _w(m.get("one_way_power_w")),
              _w(m.get("mean_angle_deg")), _w(m.get("swing_amplitude_deg")),
              _w(m.get("peak_torque_nm")), str(m.get("distinct_maxima", "-")),
              m["status"]] for m in r.modes]
    rows = [["best mode", best_label(r), "-"],
            ["power" if r.efficiency is None and not r.copper_loss_w_per_nm2
             else "electrical power",
             _w(r.power_w), "W"],
            ["  change on the last doubling of the harmonics", _w(r.refinement_change_w),
             "W"],
            ["  discretization error estimate (not a bound)",
             "none: the doublings' changes do not shrink"
             if r.discretization_error_estimate_w is None and r.refinement_change_w is not None
             else _w(r.discretization_error_estimate_w), "W"],
            ["local maxima found (count; powers)", f"{r.maxima}; " + ", ".join(
                f"{v:.4g}" for v in (r.maxima_powers_w or [])[:6]), "-; W"],
            ["one-way (reaction left out)", _w(r.one_way_power_w), "W"],
            ["radiation bound of this mesh's B, F: (F a)^H B^+ (F a) / 8",
             _w(r.radiation_bound_w), "W"],
            ["  its error from the data's noise", _w(r.bound_error_w), "W"],
            ["  fraction reached", _w(r.bound_fraction), "-"],
            ["capture-width limit J 3 lambda / (2 pi)", _w(r.capture_width_limit_w), "W"],
            ["capture width P / J", _w(r.capture_width_m), "m"],
            ["surge amplitude / phase", f"{r.surge_amplitude_m:.4g} / "
             f"{_w(r.surge_phase_deg)}", "m / deg"],
            ["heave amplitude / phase", f"{r.heave_amplitude_m:.4g} / "
             f"{_w(r.heave_phase_deg)}", "m / deg"],
            ["pitch amplitude / phase", f"{r.pitch_amplitude_deg:.4g} / "
             f"{_w(r.pitch_phase_deg)}", "deg / deg"],
            ["mean heel", f"{r.mean_heel_deg:.4g}", "deg"],
            ["peak torque", _w(r.peak_torque_nm), "N m"],
            ["peak bearing load", _w(r.peak_pivot_force_n), "N"]]
    if r.efficiency is not None or r.copper_loss_w_per_nm2:
        pto = [f"efficiency {r.efficiency[0]:g} generating, {r.efficiency[1]:g} motoring"
               if r.efficiency is not None else None,
               f"copper loss {r.copper_loss_w_per_nm2:g} W/(N m)^2"
               if r.copper_loss_w_per_nm2 else None]
        rows.insert(4, ["  mechanical power (" + ", ".join(x for x in pto if x) + ")",
                        _w(r.mechanical_power_w), "W"])
    if r.torque_limit_nm is not None:
        rows.insert(4, ["  torque limit", _w(r.torque_limit_nm), "N m"])
    if r.headline_reason:
        rows[1][1] = "none (below)"
    out = [wave, *_hull_head(r), "",
           _table(modes, ["mode", "power (W)", "one-way (W)", "mean angle (deg)",
                          "swing (deg)", "peak torque (N m)", "maxima", "status"]), "",
           _table(rows, ["quantity", "value", "unit"]), "",
           f"status: {r.status}; N = {r.harmonics}, hull harmonics {r.hull_harmonics}; "
           f"energy balance residual {_w(r.energy_balance_residual)}"]
    if r.headline_reason:
        out.append(f"power: none, no resolved answer: {r.headline_reason}")
    if r.realizations is not None:
        out += ["", *_realizations_text(r)]
    out += [f"note: {n}" for n in r.warnings if not n.startswith("no resolved answer")]
    out += [f"warning: {n}" for n in r.validity_warnings]
    return out


def _realizations_text(r) -> list:
    """The sea state's realizations: each record's power and peaks, the mean and its
    interval."""
    rows = [[str(sd), _w(p), _w(t), _w(f), why or "resolved"] for sd, p, t, f, why in zip(
        r.realization_seeds, r.realization_powers_w, r.realization_peak_torques_nm,
        r.realization_peak_pivot_forces_n, r.realization_reasons)]
    out = [_table(rows, ["seed", "power (W)", "peak torque (N m)", "peak bearing load (N)",
                         "answer"])]
    ci = ("no interval (fewer than 2 resolved records)" if r.power_ci_w is None else
          f"95 % interval [{r.power_ci_w[0]:.6g}, {r.power_ci_w[1]:.6g}] W (+- "
          f"{r.power_ci_half_width_w:.3g} W; Student t, {r.realizations_solved - 1} "
          "degrees of freedom)")
    out.append(f"mean power over {r.realizations_solved} of {r.realizations} realizations: "
               f"{_w(r.mean_power_w)} W, {ci}")
    return out


def _hull_sweep_text(r) -> list:
    from ..hydro.result import best_label

    def best(x):  # the best mode's name, the rotation's sense with it ("": not solved)
        return "" if x is None or x.mode is None else best_label(x)

    solved = list(r.results) + [None] * (len(r.period_s) - len(r.results))

    rows = [[f"{t:g}", _fmt(p), _fmt(rp), "" if k is None else f"{k:+d}", _fmt(sp), best(x),
             _fmt(o), _fmt(b), _fmt(z), _fmt(pi)]
            for t, p, rp, k, sp, x, o, b, z, pi in zip(
                r.period_s, r.power_w, r.rotation_power_w, r.rotation_winding,
                r.swinging_power_w, solved, r.one_way_power_w, r.radiation_bound_w,
                r.heave_amplitude_m, r.pitch_amplitude_deg)]
    head = ["T (s)", "power (W)", "rotation (W)", "turns/wave", "swinging (W)", "best",
            "one-way (W)", "bound (W)", "heave (m)", "pitch (deg)"]
    out = [f"regular waves, H = {r.wave_height_m:g} m", *_hull_head(r), "",
           _table(rows, head), "", f"success: {r.success}"]
    none = [f"{t:g}" for t, why in zip(r.period_s, r.headline_reason or ()) if why]
    if none:
        out.append(f"power: none at T = {', '.join(none)} s, no resolved answer (the notes "
                   "say why)")
    return out + [f"note: {n}" for n in r.warnings]


COMMANDS = {"buoy": _cmd_buoy}
