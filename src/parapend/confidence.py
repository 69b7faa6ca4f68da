r"""Confidence intervals of a mean over seeded realizations (the statistics of a sea state).

A sea state's mean power is estimated by the mean of ``R`` realizations (records of the same
spectrum with independent random phases, seeds ``seed, seed + 1, ...``). Their powers
``P_1 .. P_R`` are independent draws, so the two-sided ``level`` interval of the mean is
Student's t-interval (the ``t`` distribution with ``R - 1`` degrees of freedom)::

    mean +- t_{(1 + level) / 2, R - 1} s / sqrt(R),    s^2 = sum (P_r - mean)^2 / (R - 1)

It assumes the realizations' powers are roughly normal; with few realizations it is wide,
as it should be. Below two realizations no interval exists (None).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["LEVEL", "METHOD", "t_interval"]

#: the intervals' confidence level
LEVEL = 0.95
#: how the interval is computed (stated beside every interval)
METHOD = ("Student t-interval of the mean over the realizations (t with R - 1 degrees of "
          "freedom, sample standard deviation ddof 1), 95 %")


def t_interval(values, level: float = LEVEL) -> dict:
    """The mean of the finite ``values`` and its two-sided ``level`` t-interval.

    Returns
    -------
    dict
        ``mean``, ``count`` (finite values used), ``std`` (ddof 1; None below 2),
        ``half_width``, ``low``, ``high`` (None below 2 values), ``dof`` (``count - 1``).
    """
    from scipy.stats import t

    v = np.asarray(values, dtype=float).ravel()
    v = v[np.isfinite(v)]
    n = int(v.size)
    if n == 0:
        return {"mean": None, "count": 0, "std": None, "half_width": None, "low": None,
                "high": None, "dof": None}
    mean = float(np.mean(v))
    if n < 2:
        return {"mean": mean, "count": 1, "std": None, "half_width": None, "low": None,
                "high": None, "dof": 0}
    s = float(np.std(v, ddof=1))
    half = float(t.ppf(0.5 + level / 2, n - 1)) * s / math.sqrt(n)
    return {"mean": mean, "count": n, "std": s, "half_width": half, "low": mean - half,
            "high": mean + half, "dof": n - 1}
