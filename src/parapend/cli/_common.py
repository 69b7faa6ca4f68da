"""Shared pieces of the command line: parser, number parsing, tables, errors, progress."""

from __future__ import annotations

import argparse
import inspect
import math
import os
import re
import sys
import time
from pathlib import Path

from ..defaults import OMEGA, Default, given  # noqa: F401  (Default, given re-exported)
from ..errors import ParameterError

EXIT_USAGE = 2
#: the command ran but has no resolved answer: its headline is null (the reason printed
#: with it) or its status says the number is not one (a causal run that loses energy)
EXIT_UNRESOLVED = 3


class Unresolved:
    """A command's output (its text or its JSON dict) printed as any other, after which the
    command exits with :data:`EXIT_UNRESOLVED`: it ran, and its result says that its headline
    is not a resolved answer (``headline_reason``, or a status such as ``loses_energy``)."""

    def __init__(self, out):
        self.out = out


def unresolved_if(out, result):
    """``out`` wrapped in :class:`Unresolved` when ``result`` has no resolved answer: a
    null headline with its reason (``headline_reason``; a sweep's, one per period: any of
    them) or the status ``loses_energy``."""
    reason = getattr(result, "headline_reason", None)
    if isinstance(reason, (list, tuple)):
        reason = any(reason)
    if reason or getattr(result, "status", None) == "loses_energy":
        return Unresolved(out)
    return out


# a leading '-' followed by a number in any notation (-1, -.5, -1e-3, -1E+2, -inf) is a
# value, not an option: argparse's own matcher knows only -1 and -1.5
# (and so is a Fourier term list starting with a negative number, '-1:0.3', refused later)
_NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|infinity|nan)$"
                              r"|^-[\d.][^\s]*:", re.IGNORECASE)


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line (no usage dump) with exit code 2, and which
    reads ``-1e-3`` as a negative number (``--delta -1e-3``).

    A command's parser takes its options' defaults from the signature of the command's
    function (``declared_by``, a callable returning it): the default of an option is declared
    once, where the function declares its parameter (:meth:`declare_defaults`)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = _NEGATIVE_NUMBER
        self.declared_by = None
        self.declared = False

    def error(self, message):
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")

    def declare_defaults(self) -> None:
        """Set the default of every option that is a parameter of the command's function to
        the parameter's default (once; the function is imported here, so the command line
        imports only the function of the command it runs)."""
        if self.declared_by is None or self.declared:
            return
        self.declared = True
        params = inspect.signature(self.declared_by()).parameters
        for action in self._actions:
            param = params.get(action.dest)
            if (not action.option_strings or param is None
                    or param.default is inspect.Parameter.empty):
                continue
            # argparse appends to the default of an "append" option: a fresh list of it
            action.default = (list(param.default) if isinstance(action, argparse._AppendAction)
                              else param.default)

    def parse_known_args(self, args=None, namespace=None):
        self.declare_defaults()
        return super().parse_known_args(args, namespace)


def _finite_float(name):
    def conv(text):
        try:
            x = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a number, got {text!r:.40}") from None
        if not math.isfinite(x):
            raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r:.40}")
        return x

    conv.__name__ = name
    return conv



def hull_options(g) -> None:
    """The hull's placement options (``buoy`` and ``power-matrix`` with ``--dofs
    surge,heave,pitch``): the pivot, the hull's pitch inertia, the barge's size, generated
    from their declarations (:class:`parapend.hydro.device.Body`)."""
    from ..hydro.device import Body

    add_declared(g, Body, ("pivot_height", "pivot_offset", "hull_pitch_inertia",
                           "barge_length", "barge_beam", "barge_draft"))


def _int(text):
    t = text.strip()
    if len(t) > 30:  # int() of a thousand-digit string is slow and never a valid count
        raise argparse.ArgumentTypeError(f"expected an integer, got {text[:20]!r}... "
                                         f"({len(t)} characters)")
    try:
        return int(t)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer, got {text!r:.40}") from None


def _add_excitation(p):
    g = p.add_argument_group("excitation q(t) (base acceleration over g)")
    g.add_argument("--excitation",
                   choices=["harmonic", "two-harmonic", "square", "fourier", "file"],
                   help="harmonic: delta sin(omega t); two-harmonic: Eq. 23; square: Eq. 26; "
                        "fourier: --fourier terms; file: --file CSV (default: file if --file "
                        "is given, fourier if --fourier is given, else harmonic)")
    g.add_argument("--omega", type=_finite_float("omega"),
                   help="forcing frequency in [1e-3, 1e3], units sqrt(g/l) (default 1.8)")
    g.add_argument("--delta", type=_finite_float("delta"),
                   help="amplitude of harmonic, two-harmonic, square, |delta| <= 1e3 "
                        "(default -0.3)")
    g.add_argument("--square-alpha", type=_finite_float("square-alpha"),
                   help="tanh smoothing width alpha of Eq. 26, square only (default 0.001)")
    g.add_argument("--fourier", metavar="TERMS",
                   help="'k:amp:phase,...' for q = sum amp sin(k omega t + phase), integer "
                        "1 <= k <= 1024")
    g.add_argument("--file", metavar="CSV",
                   help="one period of q: UTF-8 CSV header 'tau,q', tau = omega t/2pi in "
                        "[0, 1), 16 to 16384 rows")


def _excitation_kwargs(a) -> dict:
    return {"excitation": a.excitation, "omega": a.omega, "delta": a.delta,
            "square_alpha": a.square_alpha, "fourier": a.fourier, "file": a.file}


def add_sea_options(g, *, repeat_period: str = "the record repeats with it",
                    seed: str = "seed of the random phases (default 0)",
                    cutoff: str = "highest frequency, in units of the peak frequency, 1.5 "
                                  "to 10 (default 3)",
                    repeat_default: float = 100) -> None:
    """The sea state of ``sea`` and ``horizon`` into the argument group ``g``: ``--hs --tp
    --spectrum --gamma-peak --repeat-period --seed --cutoff`` (the defaults are
    :func:`parapend.seas` 's). ``repeat_period`` (what the record length is), ``seed`` and
    ``cutoff`` are the commands' own help texts, ``repeat_default`` the default record in
    peak periods."""
    from .. import limits

    g.add_argument("--hs", type=_finite_float("hs"),
                   help="significant wave height, m (default 2)")
    g.add_argument("--tp", type=_finite_float("tp"),
                   help="peak period, s (default 8)")
    g.add_argument("--spectrum", choices=["jonswap", "pierson-moskowitz"],
                   help="spectrum shape (default jonswap)")
    g.add_argument("--gamma-peak", type=_finite_float("gamma-peak"),
                   help="JONSWAP peak enhancement in [1, 20] (default 3.3)")
    g.add_argument("--repeat-period", type=_finite_float("repeat-period"),
                   help=f"T_r, s: {repeat_period}; {limits.SEA_WAVES_RANGE[0]:g} "
                        f"to {limits.SEA_WAVES_RANGE[1]:g} peak periods (default "
                        f"{repeat_default:g} Tp)")
    g.add_argument("--seed", type=_int, help=seed)
    g.add_argument("--cutoff", type=_finite_float("cutoff"), help=cutoff)


def add_pendulum_options(g, *, gamma_note: str = "") -> None:
    """The pendulum in SI units of ``sea`` and ``horizon`` into the argument group ``g``:
    ``--length --mass --inertia --gravity --gamma --damping-coefficient`` (defaults
    ``defaults.SEA``); ``gamma_note`` ends the help of ``--gamma``'s default."""

    g.add_argument("--length", type=_finite_float("length"),
                   help="pivot to centre of mass, m (default 1)")
    g.add_argument("--mass", type=_finite_float("mass"),
                   help="kg (default 10)")
    g.add_argument("--inertia", type=_finite_float("inertia"),
                   help="about the pivot, kg m^2 (default m l^2)")
    g.add_argument("--gravity", type=_finite_float("gravity"),
                   help="m/s^2 (default 9.81)")
    g.add_argument("--gamma", type=_finite_float("gamma"),
                   help=f"viscous damping, non-dimensional (default 0.01{gamma_note})")
    g.add_argument("--damping-coefficient", type=_finite_float("damping-coefficient"),
                   help="viscous damping c, N m s/rad (instead of --gamma)")


def add_declared(g, cls, names, command: str | None = None) -> None:
    """The options ``--NAME`` of the parameters ``names`` of an input object ``cls``
    (:mod:`parapend.hydro.device`) into the argument group ``g``, generated from their
    declarations: the help, the unit and the default stated, the type, the choices
    (``command``'s where its declaration states its own)."""
    import dataclasses

    from ..hydro.device import option_help

    meta = {f.name: f.metadata for f in dataclasses.fields(cls)}
    for name in names:
        m, flag = meta[name], name.replace("_", "-")
        m = {**m, **m["commands"].get(command, {})}
        kw = {"help": option_help(meta[name], command)}
        if m["choices"]:
            kw["choices"] = list(m["choices"])
        elif m["kind"] == "float":
            kw["type"] = _finite_float(flag)
        elif m["kind"] == "int":
            kw["type"] = _int
        if m["metavar"]:
            kw["metavar"] = m["metavar"]
        g.add_argument(f"--{flag}", **kw)


def add_body_options(g, command: str | None = None) -> None:
    """The body of ``buoy``, ``horizon`` and ``power-matrix --device buoy`` into the argument
    group ``g``: ``--body --radius --draft --mesh --hydro``, generated from their
    declarations (:class:`parapend.hydro.device.Body`; ``command``'s help and choices of
    ``--body`` and ``--hydro`` where the declaration states them)."""
    from ..hydro.device import Body

    add_declared(g, Body, ("body", "radius", "draft", "mesh", "hydro"), command=command)


FIGURE_SUFFIXES = (".png", ".svg", ".pdf")
#: what ``--save`` writes by extension (:meth:`parapend.results.Result.save`): a result with
#: one table, and one with several dimensions (no CSV)
SAVE_TABLE = (".csv", ".nc", ".json")
SAVE_GRID = (".nc", ".json")
#: every format a result's ``save`` writes (:data:`parapend.results.SAVE_SUFFIXES`)
SAVE_ALL = (".csv", ".nc", ".json", ".png", ".svg", ".pdf")


def add_output_options(p, *, plot: str, save: str, table: bool = True,
                       figures: bool = False) -> None:
    """``--plot``, ``--save`` and ``--json``: how a command's result is drawn, written and
    printed (:meth:`~parapend.results.Result.plot`, :meth:`~parapend.results.Result.save`,
    :meth:`~parapend.results.Result.to_dict`). ``plot`` and ``save`` say what is drawn and
    written; ``table`` is False for a result of several dimensions (no CSV); ``figures``:
    ``--save`` also writes the figure (``SAVE_ALL``: every format the result writes)."""
    p.add_argument("--plot", metavar="PNG", help=f"draw {plot} (PNG, SVG or PDF)")
    kinds = ".csv (with a row of units), .nc or .json" if table else ".nc or .json"
    if figures:
        kinds = ".csv (with a row of units), .nc, .json, or the figure as .png, .svg or .pdf"
    p.add_argument("--save", metavar="FILE", help=f"write {save}: {kinds}")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def _blocking_file(p: Path) -> Path | None:
    """The first ancestor of ``p`` (nearest the root) that exists but is not a directory."""
    for anc in reversed(p.parents):
        if anc.exists() and not anc.is_dir():
            return anc
    return None


def _check_output(path: str | None, what: str, suffixes) -> None:
    """Fail early (before any work) if an output path cannot be written."""
    if path is None:
        return
    if not path.strip():
        raise ParameterError(f"{what}: expected a file name, got an empty string")
    p = Path(path)
    if p.suffix.lower() not in suffixes:
        raise ParameterError(f"{what}: expected a file name ending in {' or '.join(suffixes)}, "
                             f"got {path!r:.80}")
    try:
        max_name = os.pathconf(p.parent if str(p.parent) else ".", "PC_NAME_MAX")
    except (OSError, ValueError):
        max_name = 255
    if len(os.fsencode(p.name)) + 16 > max_name:  # + room for the temporary file's prefix
        raise ParameterError(f"{what}: file name too long ({len(p.name)} characters; the file "
                             f"system allows {max_name})")
    blocker = _blocking_file(p)
    if blocker is not None:
        raise ParameterError(f"{what}: {str(blocker)!r} is a file, not a directory")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise ParameterError(f"{what}: directory {str(parent)!r} does not exist")
    if p.is_dir():
        raise ParameterError(f"{what}: {path!r} is a directory, expected a file name")
    from ..fileio import named_fifo

    if named_fifo(p):
        raise ParameterError(f"{what}: {path!r} is a FIFO (named pipe), which waits for a "
                             "reader for ever; expected a regular file")
    from ._output import OutputError, probe_dir

    try:
        probe_dir(parent, path)
    except OutputError as exc:
        raise ParameterError(f"{what}: {exc}") from None


class _Ticker:
    """Context manager: on a terminal, an elapsed-time line on stderr for work without
    natural steps (one figure); silent for the first ``delay`` seconds and when piped."""

    def __init__(self, label: str, delay: float = 2.0):
        self.label = label
        self.delay = delay
        self.thread = None

    def __enter__(self):
        import threading

        try:
            on = sys.stderr is not None and sys.stderr.isatty()
        except (ValueError, OSError):
            on = False
        if on:
            self.stop = threading.Event()
            self.thread = threading.Thread(target=self._run, daemon=True)
            self.thread.start()
        return self

    def _run(self):
        start = time.monotonic()
        drawn = False
        while not self.stop.wait(0.5):
            el = time.monotonic() - start
            if el >= self.delay:
                try:
                    sys.stderr.write(f"\r{self.label}: working, {el:4.0f} s")
                    sys.stderr.flush()
                    drawn = True
                except (OSError, ValueError):
                    return
        if drawn:
            try:
                sys.stderr.write("\r" + " " * (len(self.label) + 20) + "\r")
                sys.stderr.flush()
            except (OSError, ValueError):
                pass

    def __exit__(self, *exc):
        if self.thread is not None:
            self.stop.set()
            self.thread.join()
        return False


class _Progress:
    """A one-line progress bar on stderr, only when stderr is a terminal.

    Call it as ``bar(done, total)`` (or ``bar(done, total, label)``); it draws nothing for
    the first ``delay`` seconds, so quick runs stay silent, and erases itself at the end.
    Once a step is done it shows the time left, the elapsed time per step times the steps
    left (``about 40 s left``).
    """

    #: the clock (seconds; a test sets its own)
    clock = staticmethod(time.monotonic)
    #: show the time left (a subclass with its own estimate turns it off)
    time_left = True

    def __init__(self, label: str, delay: float = 1.0):
        self.label = label
        self.delay = delay
        self.start = self.clock()
        self.drawn = False
        try:
            self.on = sys.stderr is not None and sys.stderr.isatty()
        except (ValueError, OSError):
            self.on = False

    def __call__(self, done: int, total: int, label: str | None = None) -> None:
        elapsed = self.clock() - self.start
        if not self.on or (not self.drawn and elapsed < self.delay and done < total):
            return
        width = 30
        k = int(width * done / max(total, 1))
        what = self.label if label is None else f"{self.label}: {label}"
        line = f"{what[:40]} [{'#' * k}{'.' * (width - k)}] {done}/{total}"
        if self.time_left and 0 < done < total:
            line += f", about {_duration(elapsed / done * (total - done))} left"
        try:
            if done >= total:
                if self.drawn:
                    sys.stderr.write("\r" + " " * len(line) + "\r")
            else:
                sys.stderr.write("\r" + line)
                self.drawn = True
            sys.stderr.flush()
        except (OSError, ValueError):
            self.on = False


def _duration(seconds: float) -> str:
    """``seconds`` for a person: ``8 s``, ``3 min``, ``2.5 h``."""
    if seconds < 90:
        return f"{max(seconds, 1.0):.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


def _fmt(x, digits=6):
    """A number for a table: exact zero as ``0``, fixed decimals for ordinary magnitudes,
    significant digits for tiny or huge ones (never ``0.000000`` for a nonzero value)."""
    if x is None:
        return "-"
    x = float(x)
    if not math.isfinite(x):
        return str(x)
    if x == 0:
        return "0"
    if not 1e-3 <= abs(x) < 1e6:
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


def _dataset_json(ds) -> dict:
    """A one-dimensional Dataset as JSON: its coordinate, every variable, every attribute."""
    out = {name: ds[name].values for name in ds.coords}
    out.update({name: ds[name].values for name in ds.data_vars})
    return {**out, **ds.attrs}


def _run(a, **extra):
    """Call the command's public function (:mod:`parapend.commands`, the command's name with
    underscores) with every option of the command but the presentation ones."""
    from .. import commands

    skip = commands.presentation(a.command) | {"command"}
    opts = {k: v for k, v in vars(a).items() if k not in skip}
    return getattr(commands, a.command.replace("-", "_"))(**opts, **extra)
