"""The ``parapend`` console script: loads the command line inside its own Ctrl-C handler.

Loading NumPy, SciPy and matplotlib takes about a second. An interrupt then would otherwise
print a traceback from the import machinery, or, inside an extension module's
initialization, turn into an ``ImportError`` (pybind11 modules do this). The handler below
raises ``KeyboardInterrupt`` as Python's default one does, and remembers that it ran: any
exception that follows an interrupt ends in the one line every command gives, exit code
130.

An interrupt can also land inside a callback whose exceptions Python ignores (a weakref
callback of the import machinery, a finalizer): CPython then prints "Exception ignored in"
with a traceback and carries on. :func:`parapend._interrupt.on_unraisable` keeps that
``KeyboardInterrupt`` silent and remembers it, and a command that then runs to its end still
reports the interrupt (one line, exit code 130). The handlers and that state live in
:mod:`parapend._interrupt`, which the command line reads too."""

from __future__ import annotations

import functools
import signal
import sys

from . import _interrupt
from ._interrupt import interrupted

__all__ = ["EXIT_INTERRUPTED", "interrupted", "main"]

EXIT_INTERRUPTED = 130


def main(argv=None) -> int:
    """Run ``parapend``; one line and exit code 130 when interrupted at any point."""
    try:
        signal.signal(signal.SIGINT, _interrupt.on_sigint)
    except ValueError:  # not the main thread: leave the handler alone
        pass
    previous = sys.unraisablehook
    sys.unraisablehook = functools.partial(_interrupt.on_unraisable, default=previous)
    try:
        from .cli import main as cli_main

        code = cli_main(argv)
        if not _interrupt.swallowed():
            return code
    except Exception as exc:
        if not _interrupt.interrupted():
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
