"""The ``parapend`` console script: loads the command line inside its own Ctrl-C handler.

Loading NumPy, SciPy and matplotlib takes about a second. An interrupt then would otherwise
print a traceback from the import machinery, or, inside an extension module's
initialization, turn into an ``ImportError`` (pybind11 modules do this). The handler below
raises ``KeyboardInterrupt`` as Python's default one does, and remembers that it ran: any
exception that follows an interrupt ends in the one line every command gives, exit code
130."""

from __future__ import annotations

import signal
import sys

EXIT_INTERRUPTED = 130

_interrupted = False


def _on_sigint(signum, frame):
    global _interrupted
    _interrupted = True
    raise KeyboardInterrupt


def interrupted() -> bool:
    """Whether this process has received SIGINT under the console script's handler."""
    return _interrupted


def main(argv=None) -> int:
    """Run ``parapend``; one line and exit code 130 when interrupted at any point."""
    try:
        signal.signal(signal.SIGINT, _on_sigint)
    except ValueError:  # not the main thread: leave the handler alone
        pass
    try:
        from .cli import main as cli_main

        return cli_main(argv)
    except Exception as exc:
        if not _interrupted:
            raise
        del exc
    except KeyboardInterrupt:
        pass
    try:
        print("parapend: interrupted", file=sys.stderr)
    except (OSError, ValueError):
        pass
    return EXIT_INTERRUPTED
