"""``parapend sea``: the best rotation over a record of irregular sea (docs/seas.md)."""

from __future__ import annotations

from . import _output
from ._common import (
    FIGURE_SUFFIXES,
    SAVE_TABLE,
    _check_output,
    _finite_float,
    _fmt,
    _int,
    _run,
    _table,
    add_output_options,
    add_pendulum_options,
    add_sea_options,
)


def _winding(text):
    t = text.strip()
    return t if t == "auto" else _int(t)


def add_parsers(sub) -> None:
    p = sub.add_parser("sea", help="best rotation over an irregular sea record (JONSWAP, PM, "
                                   "or a measured heave record)",
                       description="Optimal rotation of a pendulum over a periodic record of "
                                   "irregular sea, in watts, beside the uniform rotation at "
                                   "the mean wave frequency and the gamma -> 0 limit "
                                   "(docs/seas.md).")
    g = p.add_argument_group("sea state (IEC TS 62600-2 spectra) or a measured record")
    add_sea_options(g)
    g.add_argument("--response", metavar="CSV",
                   help="heave response of the buoy, CSV 'f,gain,phase' (Hz, m/m, rad); "
                        "default: the base follows the surface (a small buoy)")
    g.add_argument("--record", metavar="CSV",
                   help="measured heave record, CSV 't,z' (s, m), instead of a sea state")
    g.add_argument("--taper", type=_finite_float("taper"),
                   help="with --record: fraction of the record under the Tukey taper that "
                        "makes it periodic (default 0.1)")
    g = p.add_argument_group("pendulum (SI units)")
    add_pendulum_options(g, gamma_note="; docs/defaults.md")
    g = p.add_argument_group("motion")
    g.add_argument("--winding", type=_winding,
                   help="K turns over the record, theta(t + T_r) = theta(t) + 2 pi K, or "
                        "'auto': K = 1 and fractions of the mean-wave-frequency K (default 1)")
    g.add_argument("--harmonics", type=_int,
                   help="N (default 16 per mean wave, then checked at 2N)")
    add_output_options(p, plot="the record, the motion and the energy",
                       save="the record and the motion over it (time_s, heave_m, q, theta, "
                            "theta_dot_rad_per_s, instantaneous_power_w, energy_j, "
                            "uniform_energy_j) and the "
                            "result's scalars")


def _cmd_sea(a) -> dict | str:
    _check_output(a.plot, "--plot", FIGURE_SUFFIXES)
    _check_output(a.save, "--save", SAVE_TABLE)
    r = _run(a)
    if a.save:
        _output.save_result(r, a.save)
    if a.plot:
        _output.save_plot(r, a.plot)
    if a.json:
        return r.to_dict()
    rec, u = r.record, r.units
    if "hs" in rec:
        head = (f"sea: {rec['spectrum']}, Hs = {rec['hs']:g} m, Tp = {rec['tp']:g} s"
                + (f", gamma_peak = {rec['gamma_peak']:g}" if "gamma_peak" in rec else "")
                + f", seed {rec['seed']}, {rec['components']} components up to "
                  f"{rec['cutoff']:g} fp; base heave: {rec['response']}")
    else:
        head = (f"record: {rec['record']} ({rec['rows']} rows, taper {rec['taper']:g}), "
                f"{rec['components']} components up to {rec['cutoff']:g} x its peak")
    rows = [[f"uniform rotation at the mean wave frequency (K = {r.uniform_winding})",
             _fmt(r.uniform_power), f"{r.uniform_power_w:.6g}"],
            [f"optimum, winding K = {r.winding}, N = {r.harmonics}", _fmt(r.power),
             f"{r.power_w:.6g}"],
            ["upper bound limit - gamma K^2 omega_r^2", _fmt(r.upper_bound),
             f"{r.upper_bound_w:.6g}"],
            ["limit gamma -> 0, omega_r TV(q) / 2 pi", _fmt(r.limit_power),
             f"{r.limit_power_w:.6g}"]]
    out = [head,
           f"record: T_r = {rec['repeat_period']:.6g} s, Hs (4 std z) = "
           f"{rec['hs_record']:.4g} m, mean period {rec['mean_period']:.4g} s, "
           f"{rec['extrema']} extrema of q, max |q| = {rec['max_abs_q']:.4g}",
           f"pendulum: l = {u['length_m']:g} m, m = {u['mass_kg']:g} kg, I = "
           f"{u['inertia_kg_m2']:g} kg m^2, gamma = {r.gamma:g} (c = "
           f"{r.gamma * u['inertia_kg_m2'] / u['time_unit_s']:.4g} N m s/rad); power unit "
           f"{u['power_unit_w']:.6g} W", "",
           _table(rows, ["motion", "power P", "watts"]), ""]
    if len(r.windings) > 1:
        out += [_table([[str(w["winding"]), _fmt(w["power"]), f"{w['power_w']:.6g}",
                         w["status"]] for w in r.windings],
                       ["winding K", "power P", "watts", "status"]), ""]
    out += [f"status: {r.status}; found from the {r.found_by} seed ({r.search}: "
            f"{r.polished} runs polished, {r.abandoned} abandoned); refinement N -> 2N "
            f"changed P by {r.refinement_change:.2g}"]
    if r.refinement_change > 1e-6 * abs(r.power):
        out.append(f"note: the power changed by {r.refinement_change / abs(r.power):.1e} "
                   "(relative) when N was doubled; give more --harmonics for more digits")
    if a.save:
        out.append(f"record and motion written to {a.save}")
    if a.plot:
        out.append(f"figure written to {a.plot}")
    return "\n".join(out)


COMMANDS = {"sea": _cmd_sea}
