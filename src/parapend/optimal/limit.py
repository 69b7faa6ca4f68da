r"""The gamma -> 0 limit for any periodic excitation (paper Eqs. 9, 19, 21, 24, 32 generalized).

Integrating the power by parts (see :mod:`parapend.power`), for gamma = 0::

    P = <q'(t) cos(theta(t))> <= <|q'(t)|> = (omega / 2 pi) * TV(q)

where TV(q) is the total variation of ``q`` over one period. The bound is approached by
``cos(theta) = sign(q')``: the pendulum stands upright (theta = 0 mod 2 pi) while ``q``
rises and hangs down (theta = pi mod 2 pi) while ``q`` falls, with an instantaneous
half-turn at every extremum of ``q`` (the Euler-Lagrange condition ``q' sin(theta) = 0``,
Eq. 21). With extrema ``t_1 < ... < t_{2m}``::

    P_limit = (omega / 2 pi) * sum_i |q(t_{i+1}) - q(t_i)|

Harmonic ``q = delta sin(omega t)``: TV = 4|delta|, ``P = 2 omega |delta| / pi`` (Eq. 19).
Two extrema ``t_1, t_2`` of Eq. 23: ``P = (omega/pi)|q(t_2) - q(t_1)|``, which is Eq. 24.
Square wave of amplitude delta: TV = 4|delta|, Eq. 32.

Directions. Each extremum needs a half-turn (+pi or -pi: either flips cos(theta)); the
period-1 condition (Eq. 3) needs them to sum to +2 pi. With one maximum and one minimum per
period both are forward. With m > 1 maxima the limit power does not depend on which m - 1
are reversed (the limit motion is non-unique); this module's canonical choice turns forward
at the global minimum and the global maximum, and alternates backward/forward at the others,
so that the pendulum rocks between the same upright and hanging positions during the smaller
swings of ``q``.

Winding K (``theta(t + T) = theta(t) + 2 pi K``, records of irregular seas): the bound and
the supremum are the same, ``omega TV(q) / 2 pi`` for every integer K (docs/limit.md): the
half-turns now sum to ``2 pi K``, ``m + K`` forward and ``m - K`` backward when ``m >= K``;
with fewer extrema the missing ``K - m`` full turns are added at extrema, since an
instantaneous full turn does no work at gamma = 0. The canonical pattern for K != 1 keeps
the net angle close to the uniform rotation ``K omega t`` (see :func:`_winding_directions`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..trajectory import FourierMotion, PiecewiseConstantMotion

__all__ = ["LimitResult", "all_patterns", "direction_patterns", "limit", "limit_seed",
           "pattern_count"]


@dataclass(frozen=True, eq=False)
class LimitResult:
    """Supremum of extractable power as gamma -> 0 and the motion that approaches it.

    Attributes
    ----------
    power : float
        ``omega * TV(q) / (2 pi)``, the supremum for gamma -> 0.
    total_variation : float
        Total variation of q over one period.
    motion : PiecewiseConstantMotion
        Switching instants (the extrema of q), direction of each half-turn, start angle.
    """

    power: float
    total_variation: float
    motion: PiecewiseConstantMotion
    winding: int = 1

    @property
    def switch_times(self) -> np.ndarray:
        return self.motion.switch_times

    @property
    def directions(self) -> np.ndarray:
        return self.motion.directions


def _winding_directions(t: np.ndarray, period: float, winding: int) -> np.ndarray:
    """Half-turn directions (odd integers, in units of pi) summing to ``2 K``, close to K s.

    Greedy in time: at each extremum turn forward when the net angle is behind the uniform
    rotation ``2 pi K t / T``, else backward, while the remaining extrema can still reach
    the total. With fewer than ``2K`` extrema every half-turn is forward and the missing
    full turns (``+2`` each) are spread evenly over the extrema.
    """
    e = t.size
    if e < 2 * winding:
        d = np.ones(e, dtype=int)
        extra = winding - e // 2
        for i in range(extra):
            d[int((i + 0.5) * e / extra) % e] += 2
        return d
    n_back = (e - 2 * winding) // 2
    d = np.empty(e, dtype=int)
    cum = 0
    back = 0
    for j in range(e):
        left = e - j
        ideal = 2.0 * winding * t[j] / period
        if n_back - back >= left:
            d[j] = -1
        elif n_back - back <= 0:
            d[j] = 1
        else:
            d[j] = 1 if cum <= ideal else -1
        back += d[j] < 0
        cum += d[j]
    return d


def limit(excitation, winding: int = 1) -> LimitResult:
    """Closed-form gamma -> 0 limit of paper Eqs. 19/24/32 for any periodic excitation.

    ``winding``: K turns per period of ``q`` (the supremum does not depend on it; the
    canonical limit motion does).
    """
    from ..excitation import Excitation

    if not isinstance(excitation, Excitation):
        from ..errors import ParameterError

        raise ParameterError(f"excitation: expected an Excitation (parapend.harmonic(...), "
                             f"parapend.build_excitation(...)), got {type(excitation).__name__}")
    ext = excitation.extrema
    tv = excitation.total_variation
    power = excitation.omega * tv / (2 * math.pi)
    m = ext.t.size
    if m == 0:  # constant q: no power can be extracted; the limit motion is uniform-like
        motion = PiecewiseConstantMotion(excitation.omega, np.array([0.0, excitation.period / 2]),
                                         np.array([winding, winding]), 0.0, winding)
        return LimitResult(0.0, 0.0, motion, winding)
    theta_start = 0.0 if ext.is_max[0] else math.pi
    if winding != 1:
        directions = _winding_directions(ext.t, excitation.period, winding)
        motion = PiecewiseConstantMotion(excitation.omega, ext.t.copy(), directions,
                                         theta_start, winding)
        return LimitResult(power, tv, motion, winding)
    directions = np.empty(m, dtype=int)
    i_min = int(np.argmin(ext.q))
    i_max = int(np.argmax(ext.q))
    # forward at global min and max; between them (cyclically) alternate -1, +1, ...
    directions[i_min] = directions[i_max] = 1
    for start, stop in ((i_min, i_max), (i_max, i_min)):
        j, sgn = (start + 1) % m, -1
        while j != stop:
            directions[j] = sgn
            sgn = -sgn
            j = (j + 1) % m
    # dwell before the first extremum: q rises into a maximum (upright, 0) or falls into a
    # minimum (hanging, pi)
    motion = PiecewiseConstantMotion(excitation.omega, ext.t.copy(), directions, theta_start)
    return LimitResult(power, tv, motion)


def pattern_count(lim: LimitResult) -> int:
    """Number of half-turn direction patterns of the limit motion: ``C(2m, m - 1)``.

    With ``2m`` extrema per period, ``m + 1`` half-turns go forward and ``m - 1`` backward
    (one net turn, Eq. 3); every choice of the backward ones gives the same limit power.
    Winding K: ``C(2m, m - K)`` (1 when ``m <= K``: only the canonical pattern is used).
    """
    e = int(np.size(lim.directions))
    k = lim.winding
    return 1 if e <= 2 * k else math.comb(e, (e - 2 * k) // 2)


def all_patterns(lim: LimitResult):
    """Every half-turn direction pattern, canonical first (a generator; see pattern_count)."""
    from itertools import combinations

    d0 = np.asarray(lim.directions)
    e = d0.size
    yield d0
    if e <= 2 * lim.winding:
        return
    for back in combinations(range(e), (e - 2 * lim.winding) // 2):
        d = np.ones(e, dtype=int)
        d[list(back)] = -1
        if not np.array_equal(d, d0):
            yield d


def direction_patterns(lim: LimitResult, count: int = 8, seed: int = 0) -> list[np.ndarray]:
    """Up to ``count`` distinct half-turn direction patterns of the limit motion.

    All patterns (``m + 1`` forward and ``m - 1`` backward half-turns) give the same limit
    power, but at gamma > 0 they lead to different local optima. The canonical pattern
    comes first; when there are more than ``count`` patterns the rest are drawn with a seeded
    generator (reproducible).
    """
    d0 = np.asarray(lim.directions)
    m = d0.size
    if pattern_count(lim) <= count:
        return list(all_patterns(lim))
    n_back = (m - 2 * lim.winding) // 2
    rng = np.random.default_rng(seed)
    out = [d0]
    seen = {tuple(d0)}
    for _ in range(50 * count):
        d = np.ones(m, dtype=int)
        d[rng.choice(m, n_back, replace=False)] = -1
        if tuple(d) not in seen:
            seen.add(tuple(d))
            out.append(d)
        if len(out) >= count:
            break
    return out


def limit_seed(lim: LimitResult, harmonics: int, directions=None) -> FourierMotion:
    """Project the limit motion onto ``harmonics`` Fourier terms (Eq. 10), Lanczos-smoothed.

    A starting point for the Fourier optimizer near the basin of the global optimum;
    ``directions`` replaces the canonical half-turn directions (see
    :func:`direction_patterns`).
    """
    motion = lim.motion
    if directions is not None:
        motion = PiecewiseConstantMotion(motion.omega, motion.switch_times,
                                         np.asarray(directions), motion.theta_start,
                                         lim.winding)
    omega = motion.omega
    m = max(1024, 32 * harmonics)
    t = (2 * math.pi / omega) * (np.arange(m) + 0.5) / m
    s = omega * t
    x = np.fft.rfft(motion.theta(t) - (s if lim.winding == 1 else lim.winding * s)) / m
    n = np.arange(1, harmonics + 1)
    # the samples sit at half-steps: undo that phase
    c = 2 * x[1:harmonics + 1] * np.exp(1j * n * math.pi / m)
    sigma = np.sinc(n / (harmonics + 1))
    return FourierMotion(omega, float(x[0].real), -c.imag * sigma, c.real * sigma, lim.winding)
