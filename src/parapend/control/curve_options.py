"""The options and statistics a curve of causal control against the horizon shares between
the devices (:func:`parapend.control.horizon.horizon_curve`, the pendulum's, and
:func:`parapend.hydro.horizon.buoy_horizon_curve`, the buoy's): a module of its own, so that
the buoy's curve reads them without importing the pendulum's."""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError, check_range

#: most records of one curve
MAX_RECORDS = 20
#: most horizons of one curve
MAX_HORIZONS = 16


def _names(value, allowed, what):
    expected = f"names from {', '.join(allowed)} (comma separated, or none)"
    if isinstance(value, str):
        items = [s.strip() for s in value.split(",") if s.strip()]
        if items == ["none"]:
            items = []
    elif isinstance(value, (list, tuple)):
        items = list(value)
    else:
        raise ParameterError(f"{what}: expected {expected}, got {value!r:.40}")
    for s in items:
        if s not in allowed:
            raise ParameterError(f"{what}: expected {expected}, got {s!r:.40}")
    if len(set(items)) != len(items):
        raise ParameterError(f"{what}: expected distinct names, got {','.join(items)}")
    return items


def _horizons(value):
    if isinstance(value, str):
        try:
            hs = [float(s) for s in value.split(",") if s.strip()]
        except ValueError:
            raise ParameterError(f"horizons: expected a comma list of numbers, got "
                                 f"{value!r:.60}") from None
    else:
        # a sequence or array of real numbers; the CLI's message for anything else (None,
        # bytes, a bool, strings, nested lists)
        bad = ParameterError(f"horizons: expected a comma list of numbers, got "
                             f"{value!r:.60}")
        if isinstance(value, (bytes, bool, np.bool_)) or value is None:
            raise bad
        try:
            arr = np.asarray(value)
        except (TypeError, ValueError):
            raise bad from None
        if arr.ndim > 1 or arr.dtype.kind not in "iuf":
            raise bad
        hs = [float(v) for v in np.atleast_1d(arr)]
    if not 1 <= len(hs) <= MAX_HORIZONS:
        raise ParameterError(f"horizons: expected 1 to {MAX_HORIZONS} horizons, got {len(hs)}")
    for h in hs:
        check_range("horizons", h, 0.05, 20.0)
    return hs


def _stats(a):
    a = np.asarray(a, dtype=float)
    ok = np.isfinite(a)
    if not ok.any():
        return math.nan, math.nan, math.nan
    return float(np.mean(a[ok])), float(np.min(a[ok])), float(np.max(a[ok]))


def update_time_stats(times, forecasts: int, horizons: int) -> tuple:
    """``(median, p99, max)`` (s), each a ``forecasts x horizons`` list, of the update times
    pooled over the records: ``times[i][j]`` the list of each record's array of update
    times of forecast ``i`` at horizon ``j`` (NaN where none)."""

    def pooled(i, j, fn):
        a = np.concatenate(times[i][j]) if times[i][j] else np.zeros(0)
        return float(fn(a)) if a.size else math.nan

    return tuple([[pooled(i, j, fn) for j in range(horizons)] for i in range(forecasts)]
                 for fn in (np.median, lambda a: np.percentile(a, 99), np.max))
