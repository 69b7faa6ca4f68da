"""Shared pieces of the command line: parser, number parsing, tables, errors, progress."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from ..errors import ParameterError

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


def _dataset_json(ds) -> dict:
    """A one-dimensional Dataset as JSON: its coordinate, every variable, every attribute."""
    out = {name: ds[name].values for name in ds.coords}
    out.update({name: ds[name].values for name in ds.data_vars})
    return {**out, **ds.attrs}
