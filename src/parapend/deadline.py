"""Long work under a time limit: one mechanism for every command with long work
(``buoy --optimize-design``, its period sweeps and ``--controller mpc``, ``horizon``,
``track --controller mpc``, ``power-matrix``; docs/limits-of-input.md).

Each command estimates its work before it starts. Without ``time_limit`` work estimated
above :data:`parapend.limits.MAX_UNTIMED_SECONDS` is refused in one line
(:func:`refuse_untimed`: the estimate, the option to change with the largest value that fits,
and ``--time-limit``). With ``time_limit`` it runs; the loop checks :func:`expired` between
its units (a design evaluation, a wave period, an update, a record, a bin) and, once the
deadline has passed, stops at the next one: the result says ``status`` ``"time_limit"``,
``success`` False and how much was done, and holds only finished units (at least one).
This is what ``parapend.dynamics.continuation.rotation_boundaries`` does for
``rotations --time-limit``; as there, the command line prints the partial result and exits
with code 0.
"""

from __future__ import annotations

import time

from . import limits
from .errors import ParameterError, check_positive

__all__ = ["TIME_LIMIT", "check_time_limit", "deadline", "duration", "expired",
           "refuse_untimed"]

#: the status of a result cut short by its time limit (as ``rotations``')
TIME_LIMIT = "time_limit"


def check_time_limit(time_limit) -> float | None:
    """``time_limit`` (s) checked: None, or a number in (0, MAX_TIME_LIMIT]."""
    if time_limit is None:
        return None
    x = check_positive("time-limit", time_limit)
    if x > limits.MAX_TIME_LIMIT:
        raise ParameterError(f"time-limit: expected seconds in (0, {limits.MAX_TIME_LIMIT:g}]"
                             f" (a week), got {x:g}")
    return x


def deadline(time_limit) -> float | None:
    """The ``time.monotonic`` time at which ``time_limit`` seconds from now run out
    (None: no limit); ``time_limit`` is checked (:func:`check_time_limit`)."""
    t = check_time_limit(time_limit)
    return None if t is None else time.monotonic() + t


def expired(when) -> bool:
    """Whether the deadline ``when`` (from :func:`deadline`, or None) has passed."""
    return when is not None and time.monotonic() >= when


def duration(seconds: float) -> str:
    """A rough duration in words: ``"45 s"``, ``"143 s"``, ``"12 minutes"``, ``"3 hours"``
    (seconds below 5 minutes: "2 minutes" beside the 120 s cap read as no more than it)."""
    for unit, size, least in (("days", 86400.0, 2), ("hours", 3600.0, 2), ("minutes", 60.0, 5)):
        if seconds >= least * size:
            return f"{seconds / size:.0f} {unit}"
    return f"{seconds:.0f} s"


def refuse_untimed(option: str, what: str, seconds: float, fix: str,
                   time_limit=None, cap: float | None = None) -> None:
    """Raise the one-line refusal of work estimated at ``seconds`` when no ``time_limit`` is
    given and the estimate exceeds ``cap`` (default
    :data:`parapend.limits.MAX_UNTIMED_SECONDS`): ``option`` names the option to change,
    ``what`` the work, ``fix`` the largest value that fits (e.g. ``"use --records at most
    3"``). Returns without a word otherwise."""
    cap = limits.MAX_UNTIMED_SECONDS if cap is None else cap
    if time_limit is not None or not seconds > cap:
        return
    raise ParameterError(f"{option}: {what} is estimated at roughly {duration(seconds)}, more "
                         f"than the {cap:g} s a command runs without a time limit; {fix}, or "
                         "give --time-limit SECONDS (a partial result, marked time_limit)")
