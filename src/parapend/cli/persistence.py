"""``parapend persistence``: does the rotation survive a real sea? (docs/persistence.md). A
thin shell over :func:`parapend.dynamics.persistence.persistence`."""

from __future__ import annotations

import shlex
import sys

from ..defaults import PERSISTENCE
from . import _output
from ._common import (
    FIGURE_SUFFIXES,
    _check_output,
    _finite_float,
    _int,
    _run,
    _table,
    add_output_options,
)
from .sweep import _NEGATIVE_VALUE, _EtaProgress

_AXIS = "a value, a comma list or FROM:TO:N"


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "persistence", help="probability that a rotating pendulum keeps rotating in an "
                            "irregular sea (passive generator; omniscient and controlled "
                            "beside it)",
        description="Per sea state over a grid of Hs x Tp: the fraction of seeded records on "
                    "which a pendulum started rotating (theta = pi, theta' = 2 pi / Tp) keeps "
                    "at least half a turn per peak period (P_rot), the fraction rotating "
                    "throughout, the mean rotation ratio and the mean harvested power of a "
                    "passive generator, with 95 % intervals (docs/persistence.md).")
    p._negative_number_matcher = _NEGATIVE_VALUE
    g = p.add_argument_group("pendulum and generator (SI units)")
    g.add_argument("--mass", type=_finite_float("mass"),
                   help=f"kg (default {PERSISTENCE['mass']:g})")
    g.add_argument("--length", type=_finite_float("length"),
                   help=f"pivot to centre of mass, m (default {PERSISTENCE['length']:g})")
    g.add_argument("--inertia", type=_finite_float("inertia"),
                   help="about the pivot, kg m^2 (default m l^2)")
    g.add_argument("--gravity", type=_finite_float("gravity"), help="m/s^2 (default 9.81)")
    g.add_argument("--damping-coefficient", type=_finite_float("damping-coefficient"),
                   help="bearing damping c, N m s/rad (default "
                        f"{PERSISTENCE['damping_coefficient']:g})")
    g.add_argument("--generator-damping", metavar="C",
                   help="generator damping c_g, N m s/rad: " + _AXIS + ", or 'best' (per sea "
                        "state the largest mean power, searched on the same records) "
                        f"(default {PERSISTENCE['generator_damping']:g})")
    g = p.add_argument_group("sea states and records (as parapend sea)")
    g.add_argument("--hs", help=f"significant wave height, m: {_AXIS} (default "
                                f"{PERSISTENCE['hs']:g})")
    g.add_argument("--tp", help=f"peak period, s: {_AXIS} (default {PERSISTENCE['tp']:g})")
    g.add_argument("--spectrum", choices=["jonswap", "pierson-moskowitz"])
    g.add_argument("--gamma-peak", type=_finite_float("gamma-peak"),
                   help="JONSWAP peak enhancement (default 3.3)")
    g.add_argument("--cutoff", type=_finite_float("cutoff"),
                   help="highest component, in units of 1/Tp (default 3)")
    g.add_argument("--response", metavar="CSV",
                   help="heave response of a buoy 'f,gain,phase' (default: the base follows "
                        "the surface)")
    g.add_argument("--duration", type=_finite_float("duration"),
                   help="record length T_r, s (its repeat period; default "
                        f"{PERSISTENCE['duration']:g})")
    g.add_argument("--transient", type=_finite_float("transient"),
                   help="left out before the window, s (default 10 Tp)")
    g.add_argument("--realizations", type=_int,
                   help=f"records per sea state (default {PERSISTENCE['realizations']})")
    g.add_argument("--seed", type=_int,
                   help="seed of realization 0; realization r has seed + r (default 0)")
    g = p.add_argument_group("beside the passive generator (coarse grids: they cost more)")
    g.add_argument("--omniscient", type=_int, metavar="N",
                   help="the omniscient optimum (parapend sea) of the first N records of "
                        "each sea state, and the passive power as a fraction of it "
                        "(default 0)")
    g.add_argument("--controller", choices=["track"],
                   help="a causal controller on the same records: track, the regular-wave "
                        "tracker of parapend track --irregular (default none)")
    g = p.add_argument_group("engine")
    g.add_argument("--store", help="Zarr store of the per-realization results, resumed if "
                                   "it holds this map (default: in memory)")
    g.add_argument("--overwrite", action="store_true",
                   help="replace a store that holds another map")
    g.add_argument("--workers", type=_int,
                   help="local processes (default one, its threads over the realizations)")
    g.add_argument("--scheduler", metavar="ADDRESS", help="Dask scheduler tcp://host:8786")
    g.add_argument("--gpu", action="store_true",
                   help="integrate on the GPU (numba.cuda; refused without one)")
    g.add_argument("--time-limit", type=_finite_float("time-limit"), metavar="SECONDS",
                   help="start no block after this long: a partial map marked time_limit "
                        "(with --store a rerun computes the rest)")
    add_output_options(p, plot="the maps of P_rot and of the mean power with their "
                               "intervals", save="the statistics over Hs x Tp", table=False)


def _cmd_persistence(a) -> dict | str:
    _check_output(a.plot, "--plot", FIGURE_SUFFIXES)
    _check_output(a.save, "--save", (".nc", ".json"))
    from ._notice import install

    install("parapend.dynamics")  # the estimate of long work, on stderr (piped or not)
    argv = sys.argv[1:] if sys.argv and sys.argv[0] else []
    r = _run(a, command="parapend " + " ".join(shlex.quote(x) for x in argv),
             progress=_EtaProgress("persistence"))
    if a.save:
        _output.save_result(r, a.save)
    if a.plot:
        _output.save_plot(r, a.plot)
    if a.json:
        return r.to_dict()

    def ci(v):
        return "-" if v[0] is None else f"[{v[0]:.3g}, {v[1]:.3g}]"

    d = r.to_dict()
    rows = [[f"{s['hs_m']:g}", f"{s['tp_s']:g}", f"{s['tp_over_t0']:.3g}",
             "-" if s["generator_damping_nm_s_per_rad"] is None
             else f"{s['generator_damping_nm_s_per_rad']:.4g}",
             "-" if s["p_rot"] is None else f"{s['p_rot']:.3f}", ci(s["p_rot_ci"]),
             "-" if s["p_throughout"] is None else f"{s['p_throughout']:.3f}",
             "-" if s["rho_mean"] is None else f"{s['rho_mean']:.3f}",
             "-" if s["power_mean_w"] is None else f"{s['power_mean_w']:.4g}",
             ci(s["power_mean_ci_w"])] for s in d["sea_states"]]
    out = [f"persistence: {r.realizations} realizations of {r.duration_s:g} s records per "
           f"sea state; m = {r.mass_kg:g} kg, l = {r.length_m:g} m, I = {r.inertia_kg_m2:g} "
           f"kg m^2, c = {r.damping_coefficient_nm_s_per_rad:g} N m s/rad, T0 = "
           f"{r.small_swing_period_s:.4g} s", "",
           _table(rows, ["Hs m", "Tp s", "Tp/T0", "c_g N m s/rad", "P_rot", "95 %",
                         "throughout", "rho", "power W", "95 %"]), ""]
    c = d["step_check"]
    if c:
        out.append(f"step {c['step_s']:.4g} s ({c['steps_per_peak_period']:.3g} per Tp); "
                   f"halved on {c['realizations']} records of Hs {c['hs_m']:g} m, Tp "
                   f"{c['tp_s']:g} s: theta after one Tp changed by "
                   f"{c['theta_change_rad']:.2g} rad, energy identity residual "
                   f"{c['energy_residual_max']:.2g}")
    out.append(f"status: {r.status}; {r.message}; {r.executor}, {r.seconds:.1f} s")
    if a.save:
        out.append(f"statistics written to {a.save}")
    if a.plot:
        out.append(f"figure written to {a.plot}")
    return "\n".join(out)


COMMANDS = {"persistence": _cmd_persistence}
