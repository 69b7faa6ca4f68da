"""``parapend sweep`` and ``parapend map``: resumable design maps and their heat maps.

A thin shell over :mod:`parapend.maps` (docs/sweep.md).
"""

from __future__ import annotations

import re
import shlex
import sys
import time

from .. import limits
from . import pto as _pto
from ._common import (
    FIGURE_SUFFIXES,
    _check_output,
    _finite_float,
    _fmt,
    _int,
    _Progress,
    _run,
)

# '-0.5:-0.05:128' and '-0.3,-0.2' are values, not options
_NEGATIVE_VALUE = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|infinity|nan)$"
                             r"|^-[\d.][^\s]*[:,]", re.IGNORECASE)

_AXIS_HELP = "one value, START:STOP:COUNT (COUNT values, ends included) or a comma list"


class _EtaProgress(_Progress):
    """The progress bar with the points per second of this run and the time left (the
    points found finished in the store not counted)."""

    time_left = False

    def __init__(self, label: str):
        super().__init__(label)
        self.first = None

    def __call__(self, done: int, total: int, label: str | None = None) -> None:
        now = time.monotonic()
        if self.first is None:
            self.first = (now, done)  # points found finished in the store are not counted
            return super().__call__(done, total, label)
        t0, d0 = self.first
        rate = (done - d0) / max(now - t0, 1e-9)
        eta = (total - done) / rate if rate > 0 else float("inf")
        text = f"ETA {eta:.0f} s" if eta < 1e7 else "ETA -"
        return super().__call__(done, total, text if label is None else f"{label}, {text}")


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "sweep", help="design map: the optimum over a grid of parameters (resumable)",
        description="Optimal, uniform and limit power (and on request the damping threshold "
                    "gamma*) at every point of a grid over omega, delta, gamma, the torque "
                    "limit and the efficiency, written block by block to a Zarr store. Run "
                    "the same command again after an interruption to resume it.")
    p._negative_number_matcher = _NEGATIVE_VALUE
    g = p.add_argument_group("axes (" + _AXIS_HELP + ")")
    g.add_argument("--omega", help="forcing frequency (default 1.8)")
    g.add_argument("--delta", help="excitation amplitude (default -0.3)")
    g.add_argument("--gamma", help="viscous damping (default 0)")
    g.add_argument("--torque-limit",
                   help="T_max of the power take-off, units m g l (each point then solves "
                        "the power take-off problem: 0.2 to 2 s a point)")
    g.add_argument("--efficiency",
                   help="efficiency of the power take-off in (0, 1] (as --torque-limit)")
    e = p.add_argument_group("excitation q(t)")
    e.add_argument("--excitation",
                   choices=["harmonic", "two-harmonic", "square", "fourier"],
                   help="default harmonic (fourier with --fourier)")
    e.add_argument("--square-alpha", type=_finite_float("square-alpha"),
                   help="tanh width of Eq. 26, square only")
    e.add_argument("--fourier", metavar="TERMS", help="'k:amp:phase,...' (omega axis only)")
    p.add_argument("--harmonics", type=_int,
                   help=f"N of every solve, at most {limits.MAP_MAX_HARMONICS} (default 24)")
    p.add_argument("--threshold", action="store_true",
                   help="also compute gamma* at every (omega, delta): several solves each")
    # default None, as parapend.sweep's (which then writes nothing); _cmd_sweep names the file
    p.add_argument("--store",
                   help="Zarr store (a directory; default map.zarr), resumed if it holds "
                        "this sweep")
    p.add_argument("--overwrite", action="store_true",
                   help="replace a store that holds a different sweep (a parapend store "
                        "only: no other directory is ever deleted)")
    p.add_argument("--netcdf", metavar="FILE.nc", help="also export the finished map to NetCDF")
    p.add_argument("--workers", type=_int,
                   help="local processes (default: all CPUs)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on an existing Dask distributed cluster (tcp://host:8786); "
                        "needs the 'distributed' package")
    p.add_argument("--block-points", type=_int,
                   help="points per block, one chunk of the store (default 512, 8 with a "
                        "power take-off)")
    _pto.add_unit_options(p, damping=False, excitation=False)
    p.add_argument("--json", action="store_true", help="print one JSON object")

    m = sub.add_parser("map", help="heat map of a sweep store over two of its axes",
                       description="Heat map of one quantity of a sweep store (power, gain "
                                   "over the uniform rotation, gamma*, ...) over two axes, "
                                   "with contour lines, failed points crossed and the "
                                   "paper's case marked.")
    m._negative_number_matcher = _NEGATIVE_VALUE
    m.add_argument("--store",
                   help="a sweep store (Zarr directory) or its NetCDF export")
    from ..maps import MAP_QUANTITIES

    m.add_argument("--variable", choices=MAP_QUANTITIES,
                   help="gain = power / uniform_power - 1 in percent (default power)")
    axes = ["omega", "delta", "gamma", "torque-limit", "efficiency"]
    m.add_argument("--x", choices=axes, help="horizontal axis (default: the "
                                             "first swept)")
    m.add_argument("--y", choices=axes, help="vertical axis (default: the "
                                             "second swept)")
    m.add_argument("--at", action="append", metavar="AXIS=VALUE",
                   help="value of a further axis (nearest; default its first value); "
                        "repeatable")
    m.add_argument("--plot", metavar="PNG",
                   help="figure file, PNG, SVG or PDF (default map.png)")
    _pto.add_unit_options(m, damping=False, excitation=False)
    m.add_argument("--json", action="store_true", help="print one JSON object")


def _command_line() -> str:
    argv = sys.argv[1:] if sys.argv and sys.argv[0] else []
    return "parapend " + " ".join(shlex.quote(a) for a in argv)


def _cmd_sweep(a) -> dict | str:
    _check_output(a.netcdf, "--netcdf", (".nc",))
    if a.store is None:
        a.store = SWEEP_STORE
    from ._notice import install

    install("parapend.maps")  # the estimate of long work, on stderr (piped or not)
    rec = _run(a, command=_command_line(), progress=_EtaProgress("sweep"))
    run, out = rec.run, rec.to_dict()
    counts, best = out["status_counts"], out["largest_power"]
    if a.json:
        return out
    lines = [f"map over {' x '.join(f'{d} ({n})' for d, n in out['dims'].items())}: "
             f"{run.points} points in {run.blocks} blocks, store {run.store}",
             f"computed now {run.computed_points}, found finished {run.resumed_points}; "
             f"{run.seconds:.1f} s ({run.executor})"
             + (f"\n{run.repaired_points} of the points computed now were marked finished in "
                "the store but their data were missing or unreadable"
                if run.repaired_points else ""),
             "status: " + ", ".join(f"{s} {n}" for s, n in counts.items())]
    if best is not None:
        where = ", ".join(f"{k} = {v:.6g}" for k, v in best.items()
                          if k not in ("power", "mechanical_power"))
        watts = (f" ({out['largest_power_w']:.6g} W)" if out.get("largest_power_w") is not None
                 else "")
        if "mechanical_power" in best:  # an efficiency: the headline is the electrical power
            mech = out.get("largest_power_mechanical_w")
            lines.append(f"largest electrical power {_fmt(best['power'], 8)}{watts} at {where} "
                         f"(mechanical {_fmt(best['mechanical_power'], 8)}"
                         + (f", {mech:.6g} W)" if mech is not None else ")"))
        else:
            lines.append(f"largest power {_fmt(best['power'], 8)}{watts} at {where}")
    if out["largest_branch_gap"]:
        lines.append(f"continuation found a higher branch than the global search, by up to "
                     f"{out['largest_branch_gap']:.3g} (variable branch_gap)")
    if a.netcdf:
        lines.append(f"NetCDF written to {a.netcdf}")
    lines.append("heat map: parapend map --store " + shlex.quote(str(run.store)))
    return "\n".join(lines)


def _cmd_map(a) -> dict | str:
    _check_output(a.plot, "--plot", FIGURE_SUFFIXES)
    rec = _run(a)
    out = rec.to_dict()
    xn, yn, title, label = out["x"], out["y"], out["fixed"], rec.label
    finite = out["min"] is not None
    if a.json:
        return out
    lines = [f"heat map of {a.variable} over ({xn}, {yn}) written to {a.plot}"
             + (f" ({title})" if title else "")]
    if finite:
        si = (f" = {out['min_si']:.6g} to {out['max_si']:.6g} {out['unit_si']}"
              if out.get("unit_si") else "")
        lines.append(f"range {_fmt(out['min'], 6)} to {_fmt(out['max'], 6)} ({label}){si}; "
                     f"largest at {xn} = {out['max_at'][xn]:.6g}, {yn} = "
                     f"{out['max_at'][yn]:.6g}")
    lines.append(f"{out['points']} points: {out['failed']} failed, {out['not_computed']} not "
                 "computed (grey)")
    return "\n".join(lines)


#: the store of ``parapend sweep`` without --store (the Python function's default is None:
#: in memory, nothing written)
SWEEP_STORE = "map.zarr"

COMMANDS = {"sweep": _cmd_sweep, "map": _cmd_map}
