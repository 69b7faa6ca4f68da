"""The command line's notice of a first-use compile (records of :mod:`parapend._jit`).

The library logs, the command line prints: :func:`install` attaches a handler to the
``parapend._jit`` logger that writes each record as one line on stderr, such as
``parapend: compiling the basin-map kernel (first use only, about 15 s)``. Standard output
is untouched, so ``--json`` stays one JSON object. Only the process that installed the
handler prints (a worker process forked by a sweep inherits the handler but stays quiet).
"""

from __future__ import annotations

import logging
import os
import sys

__all__ = ["install"]

_LOGGER = "parapend._jit"


class _Notice(logging.Handler):
    def __init__(self):
        super().__init__(logging.INFO)
        self.pid = os.getpid()

    def emit(self, record: logging.LogRecord) -> None:
        if os.getpid() != self.pid:
            return
        stream = sys.stderr or sys.__stderr__
        try:
            # on a terminal, start from a clean line (a progress bar may be drawn there)
            clear = "\r\033[K" if stream.isatty() else ""
            stream.write(f"{clear}parapend: {record.getMessage()}\n")
            stream.flush()
        except (OSError, ValueError, AttributeError):
            pass


def install(name: str = _LOGGER) -> None:
    """Print the INFO records of logger ``name`` of this process on stderr, one line each
    (idempotent): the compile notices, and the estimate of long work a command announces
    (``parapend.performance``)."""
    logger = logging.getLogger(name)
    if not any(isinstance(h, _Notice) for h in logger.handlers):
        logger.addHandler(_Notice())
    if logger.level == logging.NOTSET or logger.level > logging.INFO:
        logger.setLevel(logging.INFO)
