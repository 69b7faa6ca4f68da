"""Input checking: one-line errors that name the parameter and what was expected."""

from __future__ import annotations

import math
import numbers
from decimal import Decimal

__all__ = ["OutputError", "ParameterError", "SolverError", "check_finite", "check_int",
           "check_nonnegative", "check_positive", "check_range"]


class ParameterError(ValueError):
    """A user-supplied parameter is invalid; the message names it and what was expected."""


class OutputError(ParameterError):
    """An output file or directory cannot be written; the message is one line naming the path
    and the operating system's reason (see :mod:`parapend.fileio`)."""


class SolverError(RuntimeError):
    """Raised only when the caller asks for it (``throw=True``) and a solver did not converge."""


def _short(value) -> str:
    """``repr`` of a value, cut to one short line for a message."""
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _as_float(name: str, value) -> float:
    """``value`` as a finite float: any real number is accepted (``numbers.Real``: int,
    float, Fraction, NumPy scalars and 0-d arrays; and ``decimal.Decimal``), converted with
    ``float``; anything else (bool, str, complex, sequences, None) is refused."""
    if getattr(value, "ndim", None) == 0 and hasattr(value, "item"):
        value = value.item()  # a 0-d NumPy array
    if isinstance(value, bool) or not isinstance(value, (numbers.Real, Decimal)):
        raise ParameterError(f"{name}: expected a real number, got {_short(value)}")
    try:
        x = float(value)
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(f"{name}: expected a number, got {_short(value)}") from None
    if not math.isfinite(x):
        raise ParameterError(f"{name}: expected a finite number, got {_short(value)}")
    return x


def check_finite(name: str, value) -> float:
    """Return ``value`` as a float, or raise if it is not a finite number."""
    return _as_float(name, value)


def check_positive(name: str, value) -> float:
    """Return ``value`` as a float, or raise unless it is finite and > 0."""
    x = _as_float(name, value)
    if x <= 0:
        raise ParameterError(f"{name}: expected a number > 0, got {_short(value)}")
    return x


def check_nonnegative(name: str, value) -> float:
    """Return ``value`` as a float, or raise unless it is finite and >= 0."""
    x = _as_float(name, value)
    if x < 0:
        raise ParameterError(f"{name}: expected a number >= 0, got {_short(value)}")
    return x


def check_range(name: str, value, lo: float, hi: float, *, absolute: bool = False,
                why: str = "") -> float:
    """Return ``value`` as a float, or raise unless it is finite and in ``[lo, hi]``.

    With ``absolute=True`` the bound applies to ``|value|`` (``lo`` is then ignored and 0 is
    admissible). ``why`` is appended to the message (the reason for the bound).
    """
    x = _as_float(name, value)
    bad = abs(x) > hi if absolute else not lo <= x <= hi
    if bad:
        rng = f"|{name}| <= {hi:g}" if absolute else f"a number in [{lo:g}, {hi:g}]"
        tail = f" ({why})" if why else ""
        raise ParameterError(f"{name}: expected {rng}, got {_short(value)}{tail}")
    return x


def check_int(name: str, value, minimum: int = 1, maximum: int | None = None) -> int:
    """Return ``value`` as an int, or raise unless it is an integer in [minimum, maximum]."""
    try:
        ok = int(value) == value
    except (TypeError, ValueError, OverflowError):
        ok = False
    if not ok or isinstance(value, (bool, str, bytes)):
        raise ParameterError(f"{name}: expected an integer >= {minimum}, got {_short(value)}")
    n = int(value)
    if n < minimum or (maximum is not None and n > maximum):
        rng = f">= {minimum}" if maximum is None else f"in [{minimum}, {maximum}]"
        raise ParameterError(f"{name}: expected an integer {rng}, got {_short(value)}")
    return n
