"""Whether this process has been interrupted (SIGINT) under the console script's handler.

The state shared by :mod:`parapend._entry` (which installs the handlers before it loads the
command line) and :mod:`parapend.cli` (which turns an error that follows an interrupt into
the one interrupted line): kept here, below both, so that neither imports the other.

The SIGINT handler raises ``KeyboardInterrupt`` as Python's default one does, and remembers
that it ran. An interrupt can also land inside a callback whose exceptions Python ignores (a
weakref callback of the import machinery, a finalizer): CPython then prints "Exception
ignored in" with a traceback and carries on; :func:`on_unraisable` keeps that
``KeyboardInterrupt`` silent and remembers it (``_swallowed``)."""

from __future__ import annotations

import sys

_interrupted = False
_swallowed = False


def on_sigint(signum, frame):
    """The SIGINT handler: remember the interrupt, then raise ``KeyboardInterrupt``."""
    global _interrupted
    _interrupted = True
    raise KeyboardInterrupt


def on_unraisable(unraisable, default=sys.__unraisablehook__):
    """``sys.unraisablehook``: an interrupt that a callback swallowed is remembered, not
    printed; any other unraisable exception goes to ``default`` (Python's hook)."""
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


def swallowed() -> bool:
    """Whether a callback swallowed an interrupt (see :func:`on_unraisable`)."""
    return _swallowed
