"""The ``parapend`` command line: a thin layer over :mod:`parapend.commands`.

Each command parses its options, calls the function of the same name in
:mod:`parapend.commands` (every option but ``--json``, ``--plot``, ``--save``) and formats
its result.

Every command has ``--help`` and prints a plain-text table or, with ``--json``, one JSON
object. The defaults (docs/defaults.md) are the question's natural case: the paper's
(harmonic excitation, delta = -0.3, omega = 1.8) for optimize, threshold, damping-sweep,
harmonics, pto-curve, track and sweep (figure and reproduce draw the paper's own cases);
Eq. 1's coexistence case (gamma = 0.1, p = 0.8, omega = 2.1) for simulate, basins and
rotations; a JONSWAP sea (Hs = 2 m, Tp = 8 s, seed 0) and a 1 m, 10 kg pendulum with gamma =
0.01 for sea and horizon (horizons 0.25 to 4 peak periods); sea-state bins Hs 1:3:3 m,
Te 6:10:3 s with that pendulum for power-matrix; and an embedded buoy design (a 0.5 m x
0.5 m cylinder, an 80 kg, 0.3 m pendulum, a regular wave of 0.2 m and 1.8 s) for buoy.
User errors print one line and exit with code 2; only this package prints.

Exit codes: 0 success; 1 a file or standard output could not be written, or a solver
error; 2 a usage error (bad value, unknown option, unreadable input file, and a bare
``parapend`` with no command, which prints the list of commands to stderr); 3 the command
ran but has no resolved answer (its headline printed as none with the reason, or a status
that says the number is not one: a causal run that loses energy); 130 when
interrupted (Ctrl-C; a shell also reports 130 for a process that CPython ends by SIGINT,
as it does after an interrupt during an extension module's import). The console script
enters through :mod:`parapend._entry`, which loads this package inside its Ctrl-C handler.

Modules: :mod:`._common` (parser helpers, number parsing, tables, progress),
:mod:`._output` (every file written), :mod:`.optimize` (optimize, threshold, damping-sweep,
 harmonics), :mod:`.paper` (figure, reproduce), :mod:`.pto` (pto-curve; the power
 take-off and unit options of optimize), :mod:`.dynamics` (simulate, basins,
 rotations: the uncontrolled pendulum of paper Eq. 1), :mod:`.control` (track: the
 closed loop), :mod:`.sea` (sea: irregular seas), :mod:`.sweep` (sweep, map:
 design maps), :mod:`.buoy` (buoy: the pendulum inside a floating buoy), :mod:`.horizon`
 (horizon: causal control against the forecast horizon), :mod:`.persistence`
 (persistence: whether a rotation survives an irregular sea).
"""

from __future__ import annotations

import functools
import json
import os
import sys

from .. import __version__
from .._interrupt import interrupted as _interrupted
from ..errors import ParameterError, SolverError
from ..results import to_jsonable
from . import buoy as _buoy_cmds
from . import control as _control_cmds
from . import dynamics as _dynamics_cmds
from . import horizon as _horizon_cmds
from . import optimize as _optimize_cmds
from . import paper as _paper_cmds
from . import performance as _performance_cmds
from . import persistence as _persistence_cmds
from . import pto as _pto_cmds
from . import sea as _sea_cmds
from . import sweep as _sweep_cmds
from ._common import EXIT_UNRESOLVED, EXIT_USAGE, Unresolved, _Parser
from ._notice import install as _compile_notice
from ._output import OutputError

EXIT_FAILURE = 1

__all__ = ["build_parser", "main"]

COMMANDS = {**_optimize_cmds.COMMANDS, **_paper_cmds.COMMANDS, **_pto_cmds.COMMANDS,
            **_dynamics_cmds.COMMANDS, **_control_cmds.COMMANDS, **_sea_cmds.COMMANDS,
            **_sweep_cmds.COMMANDS,
            **_performance_cmds.COMMANDS, **_buoy_cmds.COMMANDS, **_horizon_cmds.COMMANDS,
            **_persistence_cmds.COMMANDS}


def _function(command: str):
    """The function of ``command`` (:mod:`parapend.commands`)."""
    from .. import commands

    return getattr(commands, command.replace("-", "_"))


def build_parser(*, declare: bool = True):
    """The ``parapend`` argument parser with every subcommand. Each command's options take
    their defaults from its function's signature: now (``declare``), or when the command is
    parsed (:meth:`._common._Parser.declare_defaults`; :func:`main` imports only the
    function of the command it runs)."""
    parser = _Parser(prog="parapend", description=(
        "Optimal energy extraction from period-1 rotations of a parametrically excited "
        "pendulum: theta'' + gamma theta' - (1 + q(t)) sin(theta) = T(t). Power P = -<T "
        "theta'> is positive when harvested."))
    parser.add_argument("--version", action="version", version=f"parapend {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser,
                                title="commands")
    _optimize_cmds.add_parsers(sub)
    _paper_cmds.add_parsers(sub)
    _pto_cmds.add_parsers(sub)
    _dynamics_cmds.add_parsers(sub)
    _control_cmds.add_parsers(sub)
    _sea_cmds.add_parsers(sub)
    _sweep_cmds.add_parsers(sub)
    _performance_cmds.add_parsers(sub)
    _buoy_cmds.add_parsers(sub)
    _horizon_cmds.add_parsers(sub)
    _persistence_cmds.add_parsers(sub)
    for name, p in sub.choices.items():
        p.declared_by = functools.partial(_function, name)
        if declare:
            p.declare_defaults()
    return parser


def _stdout_closed() -> bool:
    """True when file descriptor 1 is closed (``parapend ... >&-``)."""
    try:
        os.fstat(1)
        return False
    except OSError:
        return True


def _err(line: str) -> None:
    """One line on stderr; silent if stderr itself is gone."""
    try:
        print(line, file=sys.stderr or sys.__stderr__)
    except (OSError, ValueError, AttributeError):
        pass


def _quiet_after_interrupt() -> None:
    """After the one interrupted line, nothing more: work the interrupt cut short in other
    threads (a store's asynchronous writes, whose directory may be gone) must not report
    "Future exception was never retrieved" through asyncio's logger as the process ends."""
    import logging

    logging.getLogger("asyncio").setLevel(logging.CRITICAL + 1)


def _silence_stdout() -> None:
    """Point fd 1 at /dev/null so the interpreter's final flush cannot fail again."""
    try:
        fd = os.open(os.devnull, os.O_WRONLY)
        os.dup2(fd, 1)
        os.close(fd)
    except OSError:
        pass


def _one_blas_thread() -> None:
    """One BLAS thread unless the user chose (``OPENBLAS_NUM_THREADS`` and the like): every
    solve here is on small or banded matrices, where BLAS threads only spin (3 to 12 times
    slower on a loaded 2-core machine)."""
    if any(v in os.environ for v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS",
                                     "MKL_NUM_THREADS")):
        return
    from threadpoolctl import threadpool_limits

    threadpool_limits(1, user_api="blas")


def main(argv=None) -> int:
    """Run ``parapend`` with ``argv`` (default ``sys.argv[1:]``); return the exit code."""
    closed = argv is None and _stdout_closed()
    if closed:  # keep fd 1 from being reused by an output file opened later
        _silence_stdout()
    _one_blas_thread()
    _compile_notice()  # a first-use compile of the numba kernels: one line on stderr
    parser = build_parser(declare=False)
    try:
        a = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version (0) or a usage error (2, one line printed)
        return exc.code if isinstance(exc.code, int) else EXIT_USAGE
    if a.command is None:
        parser.print_help(sys.stderr)
        return EXIT_USAGE
    name = f"parapend {a.command}"
    try:
        try:
            out = COMMANDS[a.command](a)
        except Exception:
            # an interrupt that a library turned into its own error (numba while it compiles,
            # pybind11 while a module loads) is still an interrupt
            if _interrupted():
                raise KeyboardInterrupt from None
            raise
    except OutputError as exc:  # before ParameterError, of which it is a subclass
        _err(f"{name}: error: {exc}")
        return EXIT_FAILURE
    except ParameterError as exc:
        _err(f"{name}: error: {exc}")
        return EXIT_USAGE
    except SolverError as exc:
        _err(f"{name}: solver error: {exc}")
        return EXIT_FAILURE
    except OSError as exc:  # any other file-system failure: one line, not a traceback
        where = f" {exc.filename!r}" if getattr(exc, "filename", None) else ""
        _err(f"{name}: error: cannot write{where}: {exc.strerror or exc}")
        return EXIT_FAILURE
    except MemoryError:
        _err(f"{name}: error: out of memory; use smaller --harmonics, --points or input files")
        return EXIT_FAILURE
    except KeyboardInterrupt:
        _err(f"{name}: interrupted")
        _quiet_after_interrupt()
        return 130
    code = 0
    if isinstance(out, Unresolved):  # printed as any result, then exit status 3
        out, code = out.out, EXIT_UNRESOLVED
    if closed:
        _err(f"{name}: error: standard output is closed; the result was not printed")
        return EXIT_FAILURE
    try:
        if isinstance(out, dict):
            print(json.dumps(to_jsonable(out), indent=2))
        else:
            print(out)
        sys.stdout.flush()
    except BrokenPipeError:  # e.g. `parapend optimize | head`: the reader left, not an error
        _silence_stdout()
    except (OSError, ValueError) as exc:  # /dev/full, a closed or broken stream
        _silence_stdout()
        _err(f"{name}: error: cannot write to standard output: "
             f"{getattr(exc, 'strerror', None) or exc}")
        return EXIT_FAILURE
    return code
