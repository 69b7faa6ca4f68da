"""The ``parapend`` console script: loads the command line inside its own Ctrl-C handler.

Loading NumPy, SciPy and matplotlib takes about a second. An interrupt then would otherwise
print a traceback from the import machinery, or, inside an extension module's
initialization, turn into an ``ImportError`` (pybind11 modules do this). The handler below
raises ``KeyboardInterrupt`` as Python's default one does, and remembers that it ran: any
exception that follows an interrupt ends in the one line every command gives, exit code
130.

An interrupt can also land inside a callback whose exceptions Python ignores (a weakref
callback of the import machinery, a finalizer): CPython then prints "Exception ignored in"
with a traceback and carries on. :func:`_on_unraisable` keeps that ``KeyboardInterrupt``
silent and remembers it, and a command that then runs to its end still reports the
interrupt (one line, exit code 130)."""

from __future__ import annotations

import functools
import signal
import sys

EXIT_INTERRUPTED = 130

_interrupted = False


def _on_sigint(signum, frame):
    global _interrupted
    _interrupted = True
    raise KeyboardInterrupt


_swallowed = False


def _on_unraisable(unraisable, default=sys.__unraisablehook__):
    """``sys.unraisablehook``: an interrupt that a callback swallowed is remembered, not
    printed; any other unraisable exception goes to Python's hook."""
    global _swallowed, _interrupted
    if isinstance(unraisable.exc_value, KeyboardInterrupt) or (
            unraisable.exc_type is not None
            and issubclass(unraisable.exc_type, KeyboardInterrupt)):
        _swallowed = _interrupted = True
        return
    default(unraisable)


def interrupted() -> bool:
    """Whether this process has received SIGINT under the console script's handler."""
    return _interrupted


def main(argv=None) -> int:
    """Run ``parapend``; one line and exit code 130 when interrupted at any point."""
    try:
        signal.signal(signal.SIGINT, _on_sigint)
    except ValueError:  # not the main thread: leave the handler alone
        pass
    previous = sys.unraisablehook
    sys.unraisablehook = functools.partial(_on_unraisable, default=previous)
    try:
        from .cli import main as cli_main

        code = cli_main(argv)
        if not _swallowed:
            return code
    except Exception as exc:
        if not _interrupted:
            raise
        del exc
    except KeyboardInterrupt:
        pass
    finally:
        sys.unraisablehook = previous
    try:
        print("parapend: interrupted", file=sys.stderr)
    except (OSError, ValueError):
        pass
    return EXIT_INTERRUPTED
