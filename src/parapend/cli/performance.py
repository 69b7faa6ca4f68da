"""``parapend power-matrix``: the power matrix over sea states, capture width and annual
energy (docs/performance.md). A thin shell over :mod:`parapend.performance`."""

from __future__ import annotations

import shlex
import sys

from ..defaults import HULL, POWER_MATRIX
from ..hydro.api import PLANNERS
from ..hydro.declared import Body, Controller, Pendulum, PowerTakeOff, Sea
from . import _output
from ._common import (
    FIGURE_SUFFIXES,
    Unresolved,
    _check_output,
    _finite_float,
    _int,
    _run,
    add_body_options,
    add_declared,
    hull_options,
)
from .sweep import _NEGATIVE_VALUE, _EtaProgress

_BINS = "FROM:TO:N (N centres, ends included) or a comma list"
#: the out-of-memory line: only options this command has
OUT_OF_MEMORY = ("out of memory; use fewer --hs or --te/--tp bins, fewer --realizations, "
                 "shorter records (--waves), fewer --harmonics or --workers; with --store "
                 "the finished bins are kept: run the same command again to resume")


def _winding(text):
    t = text.strip()
    return t if t == "auto" else _int(t)


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "power-matrix", help="power matrix over Hs x Te bins, capture width, annual energy",
        description="Mean, std, min, max and count of the power over seeded records in each "
                    "sea-state bin (the non-causal optimum, the gamma -> 0 limit, the uniform "
                    "rotation; with --device buoy the coupled optimum, the radiation bound, "
                    "the one-way answer; with --controller mpc the causal controller on "
                    "the same records beside them), the wave energy flux and capture width "
                    "of each "
                    "bin, and the mean annual energy at a site (IEC TS 62600-100; MHKiT's layout). "
                    "Resumable with --store.")
    p._negative_number_matcher = _NEGATIVE_VALUE
    g = p.add_argument_group("bins (bin centres: " + _BINS + ")")
    # the sea's, the pendulum's, the body's, the take-off's and the causal column's options:
    # generated from their declarations (parapend.hydro.declared), with what they state
    # for power-matrix (its bins, its defaults)
    add_declared(g, Sea, ("hs",), command="power-matrix")
    g.add_argument("--te", help="energy period, s (default 6:10:3)")
    add_declared(g, Sea, ("tp",), command="power-matrix")
    g.add_argument("--realizations", type=_int,
                   help="seeded records per bin (default 3)")
    g.add_argument("--waves", type=_finite_float("waves"),
                   help="record length in peak periods, 2 to 400 (default "
                        f"{POWER_MATRIX['waves']:g}; with --dofs surge,heave,pitch "
                        f"{HULL['matrix_waves']:g} or {HULL['matrix_record_s'] / 60:g} minutes, "
                        "the longer, as far as the hull's solver takes it, with an ideal "
                        "take-off; with --efficiency, --copper-loss or --torque-limit "
                        f"{HULL['matrix_waves_lossy']:g}, their solver's cost)")
    # the sea's and the pendulum's options: generated from their declarations
    # (parapend.hydro.declared), with the defaults they state for power-matrix
    add_declared(g, Sea, ("seed", "spectrum", "gamma_peak", "cutoff"),
                 command="power-matrix")
    g.add_argument("--response", metavar="CSV",
                   help="heave response 'f,gain,phase' (default: the base follows the "
                        "surface)")
    g = p.add_argument_group("device")
    g.add_argument("--device", choices=["prescribed-heave", "buoy"],
                   help="the prescribed-heave pendulum, or the coupled buoy (the body "
                        "below, the pendulum in SI as parapend buoy)")
    add_declared(g, Pendulum, ("length", "mass", "inertia"), command="power-matrix")
    g.add_argument("--gravity", type=_finite_float("gravity"),
                   help="m/s^2 (default 9.81; also the waves')")
    g.add_argument("--gamma", type=_finite_float("gamma"),
                   help="viscous damping, non-dimensional (default 0.01)")
    add_declared(g, Pendulum, ("damping_coefficient",), command="power-matrix")
    g.add_argument("--winding", type=_winding, help="as sea (default 1)")
    g.add_argument("--harmonics", type=_int, help="as sea (default 16 per wave)")
    add_declared(g, PowerTakeOff, ("efficiency", "torque_limit"), command="power-matrix")
    g = p.add_argument_group("the causal column (--device prescribed-heave, as parapend "
                             "horizon; and the heaving --device buoy, as parapend buoy "
                             "--controller mpc: perfect forecast, horizon 2, update 1/8; "
                             "docs/performance.md)")
    add_declared(g, Controller, ("controller", "horizon", "forecast", "update_interval"),
                 command="power-matrix")
    g.add_argument("--warm-up", type=_finite_float("warm-up"),
                   help="peak periods from the hanging rest left out of the mean, which is "
                        "over one repeat of the record after it (default 4 with "
                        "--controller mpc)")
    g.add_argument("--plan-samples", type=_int,
                   help="torque samples per Hermite interval of the plan, 1 to 64 (default "
                        "2 with --controller mpc, as horizon)")
    g.add_argument("--planner", choices=[*PLANNERS["heave"], *PLANNERS["hull"]],
                   help="--device buoy: the horizon's solver, as parapend buoy --controller "
                        "mpc --planner: the heaving buoy's plan (default) or coupled (default "
                        "with --efficiency); the hull's collocation (default) or lbfgsb "
                        "(faster, far from the optimum)")
    g.add_argument("--speed-limit", type=float,
                   help="rated speed priced in the plans, units sqrt(g/l): a penalty, as "
                        "parapend horizon's; inf for none, horizon's default (default 4 "
                        "with --controller mpc: without it the plans spun the pendulum "
                        "past a turn per torque sample in steep seas, a failed run)")
    g = p.add_argument_group("the buoy's body (--device buoy; as parapend buoy)")
    add_body_options(g, command="power-matrix")
    g = p.add_argument_group("hull: surge, heave and pitch (--device buoy; as parapend buoy, "
                             "docs/hull.md)")
    add_declared(g, Body, ("dofs",), command="power-matrix")
    hull_options(g)
    add_declared(g, PowerTakeOff, ("copper_loss",))
    g = p.add_argument_group("resource and site")
    g.add_argument("--depth", type=_finite_float("depth"),
                   help="water depth, m (default deep water; with --device buoy also "
                        "the body's BEM)")
    g.add_argument("--density", type=_finite_float("density"),
                   help="water density, kg/m^3 (default 1025; with --device buoy also "
                        "the body's)")
    g.add_argument("--width", type=_finite_float("width"),
                   help="characteristic width, m: adds the capture-width ratio (buoy "
                        "default: the body's diameter)")
    g.add_argument("--scatter", metavar="CSV",
                   help="scatter diagram 'hs,te,frequency' (shares summing to 1), "
                        "'hs,te,count' (occurrences) or 'hs,te,hours' (warned unless they "
                        "sum to a year); bin centres of the matrix")
    g.add_argument("--timeseries", metavar="CSV",
                   help="sea states 'hs,te', one a row, binned with the matrix's edges")
    g.add_argument("--rated-power", type=_finite_float("rated-power"),
                   help="W: adds the capacity factor")
    g = p.add_argument_group("engine and output")
    g.add_argument("--store",
                   help="Zarr store of the per-realization results, resumed if it holds this "
                        "matrix (default: in memory)")
    g.add_argument("--overwrite", action="store_true",
                   help="replace a store that holds another matrix")
    g.add_argument("--workers", type=_int, help="local processes (default all)")
    g.add_argument("--scheduler", metavar="ADDRESS", help="Dask scheduler tcp://host:8786")
    g.add_argument("--netcdf", metavar="FILE.nc", help="the full Dataset as NetCDF")
    g.add_argument("--zarr", metavar="DIR", help="the full Dataset as a Zarr store")
    g.add_argument("--csv", metavar="FILE.csv", help="the matrix as a table, one row a bin")
    g.add_argument("--time-limit", type=_finite_float("time-limit"), metavar="SECONDS",
                   help="start no bin after this long: a partial matrix marked time_limit "
                        "(with --store a rerun computes the rest); without it or --store, "
                        "a matrix estimated over 2 minutes is refused")
    p.add_argument("--plot", metavar="PREFIX",
                   help="figures PREFIX-matrix.png, PREFIX-capture-width.png and, with a "
                        "site, PREFIX-scatter.png")
    p.add_argument("--json", action="store_true",
                   help="print one JSON object (annual energy, matrix, statistics)")


def _cmd_power_matrix(a) -> dict | str:
    from ..performance import figures
    from ._notice import install

    install("parapend.performance")  # the library's estimate of long work, on stderr

    if a.plot:
        for s in ("matrix", "capture-width", "scatter"):
            _check_output(f"{a.plot}-{s}.png", "--plot", FIGURE_SUFFIXES)
    argv = sys.argv[1:] if sys.argv and sys.argv[0] else []
    try:
        rec = _run(a, command="parapend " + " ".join(shlex.quote(x) for x in argv),
                   progress=_EtaProgress("power-matrix"))
    except MemoryError:
        # the generic message names --points, which this command has not
        from ..errors import SolverError

        raise SolverError(OUT_OF_MEMORY) from None
    ds = rec.dataset
    drawn = []
    if a.plot:
        _output.plot(figures.plot_matrix, ds, f"{a.plot}-matrix.png")
        _output.plot(figures.plot_capture_width, ds, f"{a.plot}-capture-width.png")
        drawn += [f"{a.plot}-matrix.png", f"{a.plot}-capture-width.png"]
        if "frequency" in ds:
            _output.plot(figures.plot_scatter, ds, f"{a.plot}-scatter.png")
            drawn.append(f"{a.plot}-scatter.png")
    out = rec.to_dict()
    # with a site, the annual energy is the headline: incomplete, it is null (its bounds
    # and the share missing beside it) and the command exits with status 3
    aep_unresolved = out["annual_energy"] is not None and not out["annual_energy_complete"]
    if a.json:
        return Unresolved(out) if aep_unresolved else out
    text = figures.text_report(ds, out, drawn)
    if out["status"] == "time_limit":
        text += (f"\nstatus: time_limit: PARTIAL matrix, bins {out['bins_finished']} of "
                 f"{out['bins']} finished (time limit {a.time_limit:g} s; the rest NaN, "
                 "not counted in the annual energy)"
                 + ("; run the same command again to compute them" if a.store else ""))
    return Unresolved(text) if aep_unresolved else text


COMMANDS = {"power-matrix": _cmd_power_matrix}
