r"""Mean annual energy production from a scatter diagram or a time series of sea states.

``AEP = 8766 h * sum_ij P_ij f_ij`` (IEC TS 62600-100; MHKiT's
``mean_annual_energy_production_matrix`` is ``8766 sum CW_ij J_ij f_ij`` with ``CW = P/J``,
the same sum). ``P_ij`` is the bin's mean power (W), ``f_ij`` its share of the year.

Scatter CSV, long format, one row per bin: ``hs,te,frequency`` (or ``hs,tp,...``). The
``frequency`` column holds shares of the year that must sum to 1 within 1e-6 (MHKiT's
rule); a column named ``count`` instead holds occurrences, any non-negative numbers,
divided by their total; a column named ``hours`` holds hours, divided by their total too,
with a warning (logged) when they do not sum to a year (8766 h, or 8760, within 1 %).
Each row's centres must be centres of the matrix (to a relative 1e-9); bins of the
matrix missing from the CSV have frequency 0. A time series
CSV ``hs,te`` (or ``hs,tp``), one row per sea state, is binned with the matrix's edges
(MHKiT's: half-open bins, the last one closed); rows outside every bin are counted and
reported, and their share of the year contributes nothing (stated, never silent).
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np

from ..errors import ParameterError

__all__ = ["HOURS_PER_YEAR", "annual_energy", "bin_power", "bin_series", "capacity_factor",
           "read_scatter", "read_series"]

#: average length of a year in hours (MHKiT, IEC TS 62600-100)
HOURS_PER_YEAR = 8766.0
_SUM_TOL = 1e-6
_MATCH = 1e-9
#: ``hours`` summing to a year within this (relative) are not warned about
_YEAR_TOL = 0.01
log = logging.getLogger(__name__)


def _read_rows(path, name: str, what: str) -> tuple[list, list]:
    """The header (lower case) and the rows of a site CSV, read as the older commands read
    ``--file``: only a regular file (a FIFO or a device such as ``/dev/zero``, or a link to
    one, is refused, never read), at most :data:`parapend.limits.MAX_BYTES_FILE` bytes or
    64 a row, UTF-8 with or without a byte-order mark, no field longer than a number needs
    (a field of 131072 characters was a ``_csv.Error`` traceback)."""
    import csv

    from .. import limits
    from ..excitation import _read_bounded

    if not isinstance(path, (str, Path)) or not str(path):
        raise ParameterError(f"{name}: expected a CSV path, got {path!r:.60}")
    rows = limits.MAX_FILE_ROWS
    try:
        text = _read_bounded(Path(path), f"a CSV of at most {rows} rows {what}",
                             max_bytes=max(limits.MAX_BYTES_FILE, 64 * rows))
    except ParameterError as exc:  # name the option the user gave, not "file"
        msg = str(exc)
        raise ParameterError(f"{name}:{msg[5:]}" if msg.startswith("file:") else msg) from None
    try:
        table = [r for r in csv.reader(text.splitlines())
                 if r and any(c.strip() for c in r)]
    except csv.Error as exc:
        raise ParameterError(f"{name}: not a CSV of numbers {what} in {path} ({exc})") \
            from None
    if not table:
        return [], []
    return [c.strip().lower() for c in table[0]], table[1:]


def _numbers(rows: list, width: int, path, name: str) -> np.ndarray:
    """The rows as finite numbers, ``width`` a row (one line naming the first bad line)."""
    from .. import limits

    if len(rows) > limits.MAX_FILE_ROWS:
        raise ParameterError(f"{name}: expected at most {limits.MAX_FILE_ROWS} rows in {path}, "
                             f"got {len(rows)}")
    out = np.empty((len(rows), width))
    for i, r in enumerate(rows):
        try:
            if len(r) != width:
                raise ValueError
            vals = [float(c) for c in r]
            if not all(math.isfinite(v) for v in vals):
                raise ValueError
        except ValueError:
            raise ParameterError(f"{name}: expected {width} finite numbers on line {i + 2} "
                                 f"of {path}, got {','.join(r)!r:.60}") from None
        out[i] = vals
    return out


def _index(values, centres, name: str, axis: str) -> np.ndarray:
    c = np.asarray(centres, dtype=float)
    out = []
    for v in values:
        k = np.flatnonzero(np.abs(c - v) <= _MATCH * np.maximum(1.0, np.abs(c)))
        if k.size != 1:
            raise ParameterError(
                f"{name}: {axis} = {v:g} is not a bin centre of the matrix ({axis} centres "
                f"{', '.join(f'{x:g}' for x in c)}): the scatter's bins must be the matrix's")
        out.append(int(k[0]))
    return np.array(out, dtype=int)


def read_scatter(path, hm0, period, period_kind: str, name: str = "scatter") -> np.ndarray:
    """The frequency of each bin of the matrix (shape ``(len(hm0), len(period))``) from a
    long-format scatter CSV; see the module text."""
    head, body = _read_rows(path, name, f"'hs,{period_kind},frequency'")
    if len(head) != 3 or head[0] != "hs" or head[1] not in ("te", "tp") \
            or head[2] not in ("frequency", "count", "hours"):
        raise ParameterError(f"{name}: expected a CSV header 'hs,{period_kind},frequency' (or "
                             f"'hs,{period_kind},count', 'hs,{period_kind},hours') in {path}")
    if head[1] != period_kind:
        raise ParameterError(f"{name}: its periods are {head[1]}, the matrix's {period_kind}; "
                             f"give the matrix with --{head[1]} or the scatter in "
                             f"{period_kind}")
    rows = _numbers(body, 3, path, name)
    if rows.shape[0] == 0:
        raise ParameterError(f"{name}: expected at least one bin in {path}, got none")
    if np.any(rows[:, 0] <= 0) or np.any(rows[:, 1] <= 0):
        raise ParameterError(f"{name}: expected positive heights and periods in {path}")
    if np.any(rows[:, 2] < 0):
        raise ParameterError(f"{name}: expected non-negative {head[2]}s in {path}")
    i = _index(rows[:, 0], hm0, name, "hs")
    j = _index(rows[:, 1], period, name, period_kind)
    freq = np.zeros((len(hm0), len(period)))
    seen = set()
    for a, b, f in zip(i, j, rows[:, 2]):
        if (a, b) in seen:
            raise ParameterError(f"{name}: bin hs = {hm0[a]:g}, {period_kind} = "
                                 f"{period[b]:g} appears twice in {path}")
        seen.add((a, b))
        freq[a, b] = f
    if head[2] in ("count", "hours"):
        # scaled by the largest first: counts near the float range's top summed to inf
        # (every share 0, an AEP of 0 marked complete), subnormal ones lost their digits
        top = float(freq.max())
        if not top > 0:
            raise ParameterError(f"{name}: expected a positive total {head[2]} in {path}")
        freq = freq / top
        total = float(freq.sum())
        if head[2] == "hours":
            hours = total * top
            if min(abs(hours - y) / y for y in (HOURS_PER_YEAR, 8760.0)) > _YEAR_TOL:
                log.warning("%s: the hours in %s sum to %.6g h, not a year (%g h): each bin's "
                            "share of the year is taken as its hours over their total",
                            name, path, hours, HOURS_PER_YEAR)
        return freq / total
    total = float(freq.sum())
    if abs(total - 1.0) >= _SUM_TOL:
        raise ParameterError(f"{name}: expected frequencies summing to 1 (within 1e-6), got "
                             f"{total:.10g} in {path}; give shares of the year, or name the "
                             "column 'count' for occurrences or hours")
    return freq


def bin_series(hs, per, hm0_edges, period_edges) -> tuple[np.ndarray, int]:
    """Counts of sea states per bin (MHKiT's edges: half-open, the last bin closed) and the
    number of sea states outside every bin."""
    hs = np.asarray(hs, dtype=float)
    per = np.asarray(per, dtype=float)

    def which(x, e):
        k = np.searchsorted(e, x, side="right") - 1
        k = np.where(x == e[-1], e.size - 2, k)
        return np.where((x < e[0]) | (x > e[-1]), -1, k)

    i, j = which(hs, hm0_edges), which(per, period_edges)
    inside = (i >= 0) & (j >= 0)
    counts = np.zeros((hm0_edges.size - 1, period_edges.size - 1))
    np.add.at(counts, (i[inside], j[inside]), 1.0)
    return counts, int(np.count_nonzero(~inside))


def read_series(path, period_kind: str, name: str = "timeseries") -> tuple:
    """``(hs, period)`` arrays of a sea-state time series CSV ``hs,te`` (or ``hs,tp``)."""
    head, body = _read_rows(path, name, f"'hs,{period_kind}'")
    if head not in (["hs", "te"], ["hs", "tp"]):
        raise ParameterError(f"{name}: expected a CSV header 'hs,{period_kind}' in {path}")
    if head[1] != period_kind:
        raise ParameterError(f"{name}: its periods are {head[1]}, the matrix's {period_kind}; "
                             f"give the matrix with --{head[1]}")
    rows = _numbers(body, 2, path, name)
    if rows.shape[0] == 0:
        raise ParameterError(f"{name}: expected at least one sea state in {path}, got none")
    if np.any(rows <= 0):
        raise ParameterError(f"{name}: expected positive heights and periods in {path}")
    return rows[:, 0], rows[:, 1]


def bin_power(mean_power) -> np.ndarray:
    """The power a device delivers in each bin: ``max(P, 0)`` of the bin's mean optimum
    ``P`` (NaN stays NaN: no result). Where the optimum is negative (every motion costs
    more than it harvests, e.g. a forced turn per wave at a large damping) a real device
    stops the pendulum and delivers nothing: the bin is at rest, never a loss."""
    p = np.asarray(mean_power, dtype=float)
    with np.errstate(invalid="ignore"):
        return np.where(np.isfinite(p), np.maximum(p, 0.0), np.nan)


def annual_energy(mean_power, frequency, outside_frequency: float = 0.0,
                  bound=None, bound_name: str = "bound") -> dict:
    """AEP (Wh, MWh) of a matrix of mean powers (W) and bin frequencies: ``8766 h sum P f``
    over the bins with a frequency and a power, each power :func:`bin_power` (never below
    0). Bins with a frequency and no power are listed (``missing``); their share and that
    of the sea states outside the matrix (``outside_frequency``) is ``missing_frequency``
    (positive exactly when ``complete`` is false; ``missing_bin_frequency`` the bins' part).
    Incomplete, ``wh_bounds`` is the AEP with that share at zero power (``wh``, the sum over
    the bins counted) and at a true bound of the power there: ``bound``, each bin's upper
    bound of its mean power (W; the device's radiation bound or gamma -> 0 limit, named
    ``bound_name``). The upper end is None (no upper bound, ``upper_bound_note`` says why)
    where a missing bin has no finite bound or sea states lie outside the matrix (nothing
    bounds them): never the largest finished bin, which bounds nothing."""
    p = bin_power(mean_power)
    f = np.asarray(frequency, dtype=float)
    used = f > 0
    missing = used & ~np.isfinite(p)
    counted = used & ~missing
    # the sum scaled by the largest power: powers near the float range's top do not
    # overflow, and each term stays P f exactly as 8766 h sum P f states
    wh = HOURS_PER_YEAR * float(np.sum(np.where(counted, p * f, 0.0)))
    outside = float(outside_frequency or 0.0)
    in_bins = float(f[missing].sum())
    uncounted = in_bins + outside
    out = {"wh": wh, "mwh": wh / 1e6, "missing": np.argwhere(missing).tolist(),
           "missing_frequency": uncounted, "missing_bin_frequency": in_bins,
           "mean_power_w": wh / HOURS_PER_YEAR, "complete": uncounted == 0.0,
           "hours_per_year": HOURS_PER_YEAR, "counted_frequency": float(f[counted].sum()),
           "rest_frequency": float(f[counted & (p == 0.0)].sum())}
    if uncounted:
        b = None if bound is None else np.broadcast_to(np.asarray(bound, float), f.shape)
        upper, note = None, None
        if outside:
            note = (f"{outside:.4g} of the year lies outside the matrix's bins, where "
                    "nothing bounds the power: no upper bound")
        elif b is None or not np.all(np.isfinite(b[missing])):
            note = (f"no {bound_name} for every bin without power: no upper bound")
        else:
            upper = wh + HOURS_PER_YEAR * float(np.sum(np.maximum(b[missing], 0.0)
                                                       * f[missing]))
            note = f"the bins without power at their {bound_name}"
        out["uncounted_frequency"] = uncounted
        out["wh_bounds"] = [wh, upper]
        out["mwh_bounds"] = [wh / 1e6, None if upper is None else upper / 1e6]
        out["upper_bound_note"] = note
    return out


def capacity_factor(aep_wh: float, rated_power: float) -> float:
    return aep_wh / (HOURS_PER_YEAR * rated_power) if math.isfinite(aep_wh) else math.nan
