"""The ``parapend`` command line: a thin layer over :mod:`parapend.api`.

Every command has ``--help``, defaults to the paper's case (harmonic excitation,
delta = -0.3, omega = 1.8), prints a plain-text table or, with ``--json``, one JSON object.
User errors print one line and exit with code 2; only this package prints.

Modules: :mod:`._common` (parser helpers, number parsing, tables, progress),
:mod:`._output` (every file written), :mod:`.optimize` (optimize, threshold, damping-sweep,
harmonics), :mod:`.paper` (figure, reproduce).
"""

from __future__ import annotations

import json
import os
import sys

from .. import __version__
from ..errors import ParameterError, SolverError
from ..results import to_jsonable
from . import optimize as _optimize_cmds
from . import paper as _paper_cmds
from ._common import EXIT_USAGE, _Parser

__all__ = ["build_parser", "main"]

COMMANDS = {**_optimize_cmds.COMMANDS, **_paper_cmds.COMMANDS}


def build_parser():
    """The ``parapend`` argument parser with every subcommand."""
    parser = _Parser(prog="parapend", description=(
        "Optimal energy extraction from period-1 rotations of a parametrically excited "
        "pendulum: theta'' + gamma theta' - (1 + q(t)) sin(theta) = T(t). Power P = -<T "
        "theta'> is positive when harvested."))
    parser.add_argument("--version", action="version", version=f"parapend {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    _optimize_cmds.add_parsers(sub)
    _paper_cmds.add_parsers(sub)
    return parser


def main(argv=None) -> int:
    """Run ``parapend`` with ``argv`` (default ``sys.argv[1:]``); return the exit code."""
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
