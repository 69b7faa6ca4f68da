"""The ``parapend`` command line: a thin layer over :mod:`parapend.api`.

Every command has ``--help``, defaults to the paper's case (harmonic excitation,
delta = -0.3, omega = 1.8), prints a plain-text table or, with ``--json``, one JSON object.
User errors print one line and exit with code 2; this is the only module that prints.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import math
import os
import sys
import tempfile
from pathlib import Path

from . import __version__
from .errors import ParameterError, SolverError
from .results import CONVENTION, to_jsonable

EXIT_USAGE = 2


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line (no usage dump) with exit code 2."""

    def error(self, message):
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


def _finite_float(name):
    def conv(text):
        try:
            x = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
        if not math.isfinite(x):
            raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
        return x

    conv.__name__ = name
    return conv


def _int(text):
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None


def _add_excitation(p):
    g = p.add_argument_group("excitation q(t) (base acceleration over g)")
    g.add_argument("--excitation", default="harmonic",
                   choices=["harmonic", "two-harmonic", "square", "fourier", "file"],
                   help="harmonic: delta sin(omega t); two-harmonic: Eq. 23; square: Eq. 26; "
                        "fourier: --fourier terms; file: --file CSV (default: harmonic)")
    g.add_argument("--omega", type=_finite_float("omega"), default=1.8,
                   help="forcing frequency, units sqrt(g/l) (default 1.8)")
    g.add_argument("--delta", type=_finite_float("delta"), default=-0.3,
                   help="excitation amplitude (default -0.3)")
    g.add_argument("--square-alpha", type=_finite_float("square-alpha"), default=0.001,
                   help="tanh smoothing width alpha of Eq. 26 (default 0.001)")
    g.add_argument("--fourier", metavar="TERMS",
                   help="'k:amp:phase,...' for q = sum amp sin(k omega t + phase)")
    g.add_argument("--file", metavar="CSV",
                   help="one period of q: CSV header 'tau,q', tau = omega t/2pi in [0, 1)")


def _excitation_kwargs(a) -> dict:
    return {"excitation": a.excitation, "omega": a.omega, "delta": a.delta,
            "square_alpha": a.square_alpha, "fourier": a.fourier, "file": a.file}


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="parapend", description=(
        "Optimal energy extraction from period-1 rotations of a parametrically excited "
        "pendulum: theta'' + gamma theta' - (1 + q(t)) sin(theta) = T(t). Power P = -<T "
        "theta'> is positive when harvested."))
    parser.add_argument("--version", action="version", version=f"parapend {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True

    p = sub.add_parser("optimize", help="optimal period-1 rotation (Fourier Eq. 10, BVP Eq. 22)",
                       description="Optimal period-1 rotation by truncated Fourier series "
                                   "(Eqs. 10-11) or the penalized Euler-Lagrange BVP (Eqs. 13, "
                                   "22, 27), beside the best uniform rotation (Eq. 17) and the "
                                   "gamma -> 0 limit (Eqs. 19, 24, 32 generalized).")
    _add_excitation(p)
    p.add_argument("--gamma", type=_finite_float("gamma"), default=0.0,
                   help="viscous damping gamma >= 0 (default 0)")
    p.add_argument("--harmonics", type=_int, default=24, help="number N of harmonics (default 24)")
    p.add_argument("--method", choices=["fourier", "bvp", "all"], default="fourier",
                   help="fourier: Eq. 10 with N harmonics; bvp: Euler-Lagrange BVP (Eqs. 13, "
                        "22, 27; needs gamma > 0); all: uniform, Fourier, BVP and limit side "
                        "by side (default fourier)")
    p.add_argument("--plot", metavar="PNG", help="draw theta(tau) and torque (PNG or SVG)")
    p.add_argument("--save", metavar="CSV",
                   help="write one period of the motion: t,tau,theta,theta_dot,torque")
    p.add_argument("--json", action="store_true", help="print one JSON object")

    p = sub.add_parser("threshold", help="damping gamma* beyond which no power is extracted",
                       description="Damping threshold gamma* where the optimal power "
                                   "vanishes (paper Fig. 6: 0.0856 at delta=-0.3, omega=1.8).")
    _add_excitation(p)
    p.add_argument("--harmonics", type=_int, default=None,
                   help="fixed N (default: doubled from 8 until gamma* converges)")
    p.add_argument("--json", action="store_true", help="print one JSON object")

    p = sub.add_parser("damping-sweep", help="optimal power against damping (paper Fig. 6)",
                       description="Optimal and uniform power against damping gamma, from 0 "
                                   "to 1.25 gamma* by default (paper Fig. 6).")
    _add_excitation(p)
    p.add_argument("--harmonics", type=_int, default=32, help="N (default 32)")
    p.add_argument("--gamma-max", type=_finite_float("gamma-max"), default=None,
                   help="largest damping (default 1.25 gamma*)")
    p.add_argument("--points", type=_int, default=41, help="number of dampings (default 41)")
    p.add_argument("--plot", metavar="PNG", help="draw power against damping (PNG or SVG)")
    p.add_argument("--save", metavar="NC", help="write the sweep as a NetCDF file (.nc)")
    p.add_argument("--json", action="store_true", help="print one JSON object")

    p = sub.add_parser("harmonics", help="optimal power against the number of harmonics",
                       description="Fourier optimum for N = FROM..TO by continuation in N "
                                   "(nondecreasing in N), beside the uniform and limit powers.")
    _add_excitation(p)
    p.add_argument("--gamma", type=_finite_float("gamma"), default=0.0,
                   help="viscous damping gamma >= 0 (default 0)")
    p.add_argument("--from", dest="n_from", type=_int, default=2, help="smallest N (default 2)")
    p.add_argument("--to", dest="n_to", type=_int, default=64, help="largest N (default 64)")
    p.add_argument("--plot", metavar="PNG", help="draw power against N (PNG or SVG)")
    p.add_argument("--save", metavar="NC", help="write the table as a NetCDF file (.nc)")
    p.add_argument("--json", action="store_true", help="print one JSON object")

    p = sub.add_parser("figure", help="recompute one of the paper's figures",
                       description="Recompute one of the paper's figures and save it: 1 "
                                   "(uncontrolled motions), 2a/2b (rotation boundaries, "
                                   "basins), 4-10 (optima; 5, 7 and 10 are Euler-Lagrange BVP "
                                   "solutions).")
    p.add_argument("number", choices=["1", "2a", "2b", "4", "5", "6", "7", "8", "9", "10"],
                   help="figure number in the paper")
    p.add_argument("--plot", metavar="PNG", required=True, help="output file (PNG or SVG)")
    p.add_argument("--json", action="store_true", help="print the figure's numbers as JSON")

    p = sub.add_parser("reproduce", help="regenerate the paper's tables and figures, with a report",
                       description="Recompute every table and figure of the paper, compare each "
                                   "number with the paper's and write DIR/report.html, "
                                   "DIR/figures/, DIR/tables/ and DIR/results.json.")
    p.add_argument("--out", default="parapend-report", metavar="DIR",
                   help="output directory (default: parapend-report)")
    p.add_argument("--json", action="store_true", help="print results.json to stdout")
    return parser


# ---------------------------------------------------------------------------------------
def _check_output(path: str | None, what: str, suffixes) -> None:
    """Fail early (before any work) if an output path cannot be written."""
    if path is None:
        return
    p = Path(path)
    if p.suffix.lower() not in suffixes:
        raise ParameterError(f"{what}: expected a file name ending in {' or '.join(suffixes)}, "
                             f"got {path!r}")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise ParameterError(f"{what}: directory {str(parent)!r} does not exist")
    if p.is_dir():
        raise ParameterError(f"{what}: {path!r} is a directory, expected a file name")


def _write_atomic(path: str, text: str) -> None:
    p = Path(path)
    fd, tmp = tempfile.mkstemp(dir=p.parent if str(p.parent) else ".", prefix=".tmp-")
    try:
        with os.fdopen(fd, "w", newline="") as fh:
            fh.write(text)
        os.replace(tmp, p)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


class _Progress:
    """A one-line progress bar on stderr, only when stderr is a terminal."""

    def __init__(self, label: str):
        self.label = label
        self.on = sys.stderr.isatty()

    def __call__(self, done: int, total: int) -> None:
        if not self.on:
            return
        width = 30
        k = int(width * done / max(total, 1))
        sys.stderr.write(f"\r{self.label} [{'#' * k}{'.' * (width - k)}] {done}/{total}")
        if done >= total:
            sys.stderr.write("\r" + " " * (len(self.label) + width + 16) + "\r")
        sys.stderr.flush()


def _fmt(x, digits=6):
    """Fixed decimals for ordinary magnitudes, significant digits for tiny or huge ones."""
    if x is None:
        return "-"
    if x != 0 and not 1e-3 <= abs(x) < 1e6:
        return f"{x:.{digits}g}"
    return f"{x:.{digits}f}"


def _is_number(text: str) -> bool:
    try:
        float(text.replace("%", "").replace("+", ""))
        return True
    except ValueError:
        return text in ("", "-")


def _table(rows, header) -> str:
    """Plain-text table: numeric columns right-aligned, text columns left-aligned."""
    cols = [header] + rows
    widths = [max(len(str(r[i])) for r in cols) for i in range(len(header))]
    numeric = [all(_is_number(str(r[i])) for r in rows) for i in range(len(header))]
    lines = ["  ".join(str(v).rjust(w) if num else str(v).ljust(w)
                       for v, w, num in zip(r, widths, numeric)).rstrip() for r in cols]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def _describe(exc: dict) -> str:
    return ", ".join(f"{k}={v}" for k, v in exc.items())


# ---------------------------------------------------------------------------------------
def _cmd_optimize(a) -> dict | str:
    from .api import motion_samples, optimize

    _check_output(a.plot, "--plot", (".png", ".svg"))
    _check_output(a.save, "--save", (".csv",))
    kw = {"gamma": a.gamma, "harmonics": a.harmonics, **_excitation_kwargs(a)}
    if a.method == "all":
        return _optimize_all(a, kw)
    r = optimize(method=a.method, **kw)
    if a.save:
        s = motion_samples(r)
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(["t", "tau", "theta", "theta_dot", "torque"])
        for row in zip(s["t"], s["tau"], s["theta"], s["theta_dot"], s["torque"]):
            w.writerow([repr(float(v)) for v in row])
        _write_atomic(a.save, buf.getvalue())
    if a.plot:
        from .plotting import plot_optimum

        plot_optimum(r, a.plot)
    if a.json:
        return r.to_dict()
    name = (f"Fourier optimum, N = {r.harmonics} (Eq. 10)" if r.method == "fourier"
            else f"BVP optimum, epsilon = {2 * r.damping:g} (Eq. 22)")
    rows = [
        ["best uniform rotation (Eq. 17)", _fmt(r.uniform_power), ""],
        [name, _fmt(r.power), _gain(r.power, r.uniform_power)],
        ["limit gamma -> 0 (Eqs. 19/24/32)", _fmt(r.limit_power),
         _gain(r.limit_power, r.uniform_power)],
    ]
    how = (f"{r.iterations} Newton iterations, found from the {r.found_by} seed, "
           f"{len(r.local_maxima)} distinct local maxima" if r.method == "fourier" else
           f"{r.mesh_nodes} mesh nodes, max residual {r.max_residual:.2g}, "
           f"{r.continuation_steps} continuation steps, found from the {r.found_by} start")
    out = [f"excitation: {_describe(r.excitation)}; damping gamma = {r.damping:g}", "",
           _table(rows, ["motion", "power P", "vs uniform"]), "",
           f"status: {r.status} ({how})",
           f"peak torque |T|: {r.peak_torque:.6g}    mean theta'^2: {r.mean_square_speed:.6g}",
           f"convention: {CONVENTION}"]
    if a.save:
        out.append(f"motion written to {a.save}")
    if a.plot:
        out.append(f"figure written to {a.plot}")
    return "\n".join(out)


def _gain(p, pu) -> str:
    return f"{100 * (p / pu - 1):+.2f} %" if pu > 0 else "-"


def _optimize_all(a, kw) -> dict | str:
    """Uniform, Fourier, BVP (gamma > 0 only) and limit for one case."""
    from .api import optimize

    if a.save or a.plot:
        raise ParameterError("--method all: --save and --plot need a single method "
                             "(fourier or bvp)")
    f = optimize(method="fourier", **kw)
    b = optimize(method="bvp", **kw) if a.gamma > 0 else None
    if a.json:
        return {"uniform_power": f.uniform_power, "limit_power": f.limit_power,
                "damping": f.damping, "omega": f.omega, "excitation": f.excitation,
                "fourier": f.to_dict(), "bvp": None if b is None else b.to_dict()}
    rows = [["best uniform rotation (Eq. 17)", _fmt(f.uniform_power, 10), "", "closed form"],
            [f"Fourier, N = {f.harmonics} (Eq. 10)", _fmt(f.power, 10),
             _gain(f.power, f.uniform_power), f.status],
            [f"BVP, epsilon = {2 * f.damping:g} (Eq. 22)",
             "-" if b is None else _fmt(b.power, 10),
             "-" if b is None else _gain(b.power, f.uniform_power),
             "needs gamma > 0" if b is None else
             f"{b.status}, {b.mesh_nodes} nodes, residual {b.max_residual:.1e}"],
            ["limit gamma -> 0 (Eqs. 19/24/32)", _fmt(f.limit_power, 10),
             _gain(f.limit_power, f.uniform_power), "closed form, no damping"]]
    out = [f"excitation: {_describe(f.excitation)}; damping gamma = {f.damping:g}", "",
           _table(rows, ["method", "power P", "vs uniform", "status"])]
    if b is not None:
        out += ["", f"Fourier - BVP: {f.power - b.power:+.3e}  (agree when N resolves the "
                    "boundary layers)"]
    return "\n".join(out)


def _cmd_threshold(a) -> dict | str:
    from .api import threshold

    r = threshold(harmonics=a.harmonics, **_excitation_kwargs(a))
    if a.json:
        return r.to_dict()
    return "\n".join([
        f"excitation: {_describe(r.excitation)}",
        f"damping threshold gamma*: {r.damping_threshold:.10f}  (optimal power vanishes)",
        f"uniform-rotation threshold: {r.uniform_threshold:.10f}  (|Q1| / 2 omega)",
        f"status: {r.status} (N = {r.harmonics}, {r.iterations} Newton steps in gamma)",
    ])


def _write_dataset(ds, path: str) -> None:
    """Write a Dataset to NetCDF through a temporary file (an old file is never half-written)."""
    p = Path(path)
    fd, tmp = tempfile.mkstemp(dir=p.parent if str(p.parent) else ".", prefix=".tmp-",
                               suffix=".nc")
    os.close(fd)
    try:
        ds.to_netcdf(tmp)
        os.replace(tmp, p)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def _dataset_json(ds) -> dict:
    """A one-dimensional Dataset as JSON: its coordinate, every variable, every attribute."""
    out = {name: ds[name].values for name in ds.coords}
    out.update({name: ds[name].values for name in ds.data_vars})
    return {**out, **ds.attrs}


def _cmd_damping_sweep(a) -> dict | str:
    from .api import damping_sweep

    _check_output(a.plot, "--plot", (".png", ".svg"))
    _check_output(a.save, "--save", (".nc",))
    ds = damping_sweep(harmonics=a.harmonics, gamma_max=a.gamma_max, points=a.points,
                       progress=_Progress("damping sweep"), **_excitation_kwargs(a))
    if a.plot:
        from .plotting import plot_damping_sweep

        plot_damping_sweep(ds, a.plot)
    if a.save:
        _write_dataset(ds, a.save)
    if a.json:
        return _dataset_json(ds)
    rows = [[f"{g:.6f}", _fmt(p), _fmt(u), f"{t:.4g}", str(s)] for g, p, u, t, s in zip(
        ds["damping"].values, ds["power"].values, ds["uniform_power"].values,
        ds["peak_torque"].values, ds["status"].values)]
    out = [f"excitation: {ds.attrs['excitation']}, omega={ds.attrs['omega']}; "
           f"N = {ds.attrs['harmonics']}", "",
           _table(rows, ["gamma", "optimal P", "uniform P", "peak |T|", "status"]), "",
           f"damping threshold gamma*: {ds.attrs['damping_threshold']:.10f}"]
    if a.plot:
        out.append(f"figure written to {a.plot}")
    return "\n".join(out)


def _cmd_harmonics(a) -> dict | str:
    from .api import harmonic_table

    _check_output(a.plot, "--plot", (".png", ".svg"))
    _check_output(a.save, "--save", (".nc",))
    if a.n_from < 1 or a.n_to < a.n_from:
        raise ParameterError(f"--from/--to: expected 1 <= from <= to, got {a.n_from}..{a.n_to}")
    ds = harmonic_table(range(a.n_from, a.n_to + 1), gamma=a.gamma,
                        progress=_Progress("harmonics"), **_excitation_kwargs(a))
    if a.plot:
        from .plotting import plot_harmonic_table

        plot_harmonic_table(ds, a.plot)
    if a.save:
        _write_dataset(ds, a.save)
    if a.json:
        return _dataset_json(ds)
    rows = [[str(n), _fmt(p, 8), str(s)] for n, p, s in zip(
        ds["harmonics"].values, ds["power"].values, ds["status"].values)]
    out = [_table(rows, ["N", "optimal P", "status"]), "",
           f"best uniform: {ds.attrs['uniform_power']:.8f}    "
           f"limit gamma -> 0: {ds.attrs['limit_power']:.8f}"]
    if a.plot:
        out.append(f"figure written to {a.plot}")
    return "\n".join(out)


def _cmd_figure(a) -> dict | str:
    from .plotting import save_figure
    from .report import paper_figure

    _check_output(a.plot, "--plot", (".png", ".svg"))
    fig, numbers = paper_figure(f"fig{a.number}")
    save_figure(fig, a.plot)
    if a.json:
        return {"figure": a.number, "file": a.plot, "numbers": numbers}
    return f"figure {a.number} written to {a.plot}"


def _cmd_reproduce(a) -> dict | str:
    from .report import reproduce

    out = Path(a.out)
    if out.exists() and not out.is_dir():
        raise ParameterError(f"--out: expected a directory, got the file {a.out!r}")
    if not out.parent.is_dir():
        raise ParameterError(f"--out: parent directory {str(out.parent)!r} does not exist")
    bar = _Progress("reproduce")
    res = reproduce(out, progress=lambda done, total, label: bar(done, total))
    if a.json:
        return res
    rows = []
    for key in ("table1", "table2", "table3", "scalars"):
        for r in res["tables"][key]:
            rows.append([key, r["quantity"], _fmt(r["paper"], 4), _fmt(r["parapend"]),
                         _fmt(r["difference"])])
    return "\n".join([_table(rows, ["table", "quantity", "paper", "parapend", "difference"]),
                      "", f"report: {out / 'report.html'}",
                      f"figures: {out / 'figures'}  tables: {out / 'tables'}  "
                      f"numbers: {out / 'results.json'}"])


COMMANDS = {"optimize": _cmd_optimize, "threshold": _cmd_threshold,
            "damping-sweep": _cmd_damping_sweep, "harmonics": _cmd_harmonics,
            "figure": _cmd_figure, "reproduce": _cmd_reproduce}


def main(argv=None) -> int:
    parser = build_parser()
    a = parser.parse_args(argv)
    try:
        out = COMMANDS[a.command](a)
    except ParameterError as exc:
        print(f"parapend {a.command}: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except SolverError as exc:
        print(f"parapend {a.command}: solver error: {exc}", file=sys.stderr)
        return 1
    try:
        if isinstance(out, dict):
            print(json.dumps(to_jsonable(out), indent=2))
        else:
            print(out)
        sys.stdout.flush()
    except BrokenPipeError:  # e.g. `parapend optimize | head`: the reader left, not an error
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
