r"""Dynamic programme over time and angle: candidate optima when patterns are too many to list.

With ``2m`` extrema of ``q`` per period the limit motion has ``C(2m, m - 1)`` half-turn
direction patterns (:func:`.limit.pattern_count`); at gamma > 0 they lead to different
local optima, and for a record with dozens of extrema they cannot be enumerated. Instead
the power functional (Eq. 15 integrated by parts, see :mod:`parapend.power`)::

    P = <q'(t) cos(theta)> - gamma <theta'^2>,   theta(t + T) = theta(t) + 2 pi

is maximized *globally* over paths on a grid: ``M`` uniform times ``t_i = i h`` and the
angle lifted onto ``K`` points per turn, ``theta = theta_0 + j 2 pi / K``. The discrete
objective is (rectangle rule for the first mean, forward differences for the second)::

    P_h = (1/M) sum_i [ q'(t_i) cos(theta_i) - gamma_eff (theta_{i+1} - theta_i)^2 / h^2 ]

with ``theta_M = theta_0 + 2 pi``. For each start angle ``theta_0`` on the grid, Bellman's
recursion over ``i`` with the lifted offset ``j`` as state gives the best closed path in
``O(M K^2 D)`` operations (``D`` the largest jump per step), with no enumeration of patterns:
the path chooses at every extremum whether, and in which direction, to turn.

``gamma_eff = max(gamma, gamma_N)``: a motion with N harmonics cannot turn faster than
about ``T / (2N)``; ``gamma_N`` is the damping whose boundary layer (width
``(2 gamma / |q''|)^{1/3}``, from the inner solution of Eq. 13 near an extremum) has that
width, so that at gamma = 0 the programme still prefers the patterns a truncated series
realizes best. The best path of every start angle, deduplicated, projected onto N
harmonics, is a seed for the Newton polish in :mod:`.fourier`, which decides.

Winding K (records of irregular seas, ``theta_M = theta_0 + 2 pi K``): the lifted angle of
a path with K turns would need ``K`` turns of states; :func:`best_paths_winding` keeps only
a window of ``WINDOW`` turns either side of the uniform rotation ``2 pi K t / T``, moving
with it, so the cost is ``O(M starts (2 WINDOW K + 1) D)`` whatever K.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["best_paths", "best_paths_winding", "propose_seeds"]

#: Angle points per turn.
ANGLES = 32
#: Largest jump per time step, in angle points (a quarter turn).
MAX_JUMP = ANGLES // 4


def _effective_gamma(excitation, harmonics: int, gamma: float) -> float:
    """``max(gamma, gamma_N)`` with the boundary layer of width ``T/(2N)`` at typical |q''|."""
    spec = excitation.spectrum
    k = np.arange(spec.size)
    qdd = excitation.omega**2 * math.sqrt(float(np.sum((k * k * np.abs(spec)) ** 2)) / 2.0)
    width = excitation.period / (2.0 * harmonics)
    return max(gamma, 0.5 * qdd * width**3)


def best_paths(excitation, gamma: float, steps: int, angles: int = ANGLES,
               max_jump: int = MAX_JUMP):
    """Best closed path of the discrete programme for every start angle.

    Returns
    -------
    values : ndarray, shape (angles,)
        ``P_h`` of the best path from each start angle ``2 pi s / angles``.
    paths : ndarray, shape (angles, steps + 1)
        The lifted angles ``theta_i``, ``theta_steps = theta_0 + 2 pi``.
    """
    period = excitation.period
    h = period / steps
    t = h * np.arange(steps)
    dq = excitation.dq(t)
    lo, hi = -angles, 2 * angles  # lifted offsets j in [lo, hi]
    offs = np.arange(lo, hi + 1)
    nstate = offs.size
    starts = np.arange(angles)
    dth = 2 * math.pi / angles
    # reward of node i for start s at offset j: q'(t_i) cos(theta_0 + j dth) / M
    cos_tab = np.cos(dth * (starts[:, None] + offs[None, :]))  # (angles, nstate)
    jumps = np.arange(-max_jump, max_jump + 1)
    jump_cost = gamma * (jumps * dth) ** 2 / h**2 / steps
    v = np.full((angles, nstate), -np.inf)
    v[:, -lo] = 0.0
    arg = np.empty((steps, angles, nstate), dtype=np.int8)
    for i in range(steps):
        v = v + (dq[i] / steps) * cos_tab
        best = np.full_like(v, -np.inf)
        barg = np.zeros(v.shape, dtype=np.int8)
        for d, c in zip(jumps, jump_cost):
            # new offset j' = j + d
            if d >= 0:
                cand = np.full_like(v, -np.inf)
                cand[:, d:] = v[:, :nstate - d] - c
            else:
                cand = np.full_like(v, -np.inf)
                cand[:, :d] = v[:, -d:] - c
            better = cand > best
            best = np.where(better, cand, best)
            barg = np.where(better, np.int8(d), barg)
        v = best
        arg[i] = barg
    end = -lo + angles
    values = v[:, end]
    paths = np.empty((angles, steps + 1))
    j = np.full(angles, end)
    rows = np.arange(angles)
    for i in range(steps, -1, -1):
        paths[:, i] = dth * (starts + offs[j])
        if i > 0:
            j = j - arg[i - 1, rows, j]
    return values, paths


#: Turns either side of the uniform rotation ``K s`` that a winding-K path may lag or lead.
WINDOW = 3


def best_paths_winding(excitation, gamma: float, steps: int, winding: int,
                       angles: int = ANGLES, max_jump: int = MAX_JUMP, starts: int = 8,
                       window: int = WINDOW):
    """Best closed paths with ``theta_steps = theta_0 + 2 pi K`` (see the module docstring).

    The state is the lifted angle index relative to the uniform rotation's,
    ``c_i = round(K angles i / steps)``, within ``+-window`` turns; ``starts`` start angles
    evenly spread over one turn. Returns ``(values, paths)`` as :func:`best_paths`.
    """
    period = excitation.period
    h = period / steps
    t = h * np.arange(steps)
    dq = excitation.dq(t)
    if winding * angles > max_jump * steps // 2:
        raise ValueError("steps: too few for the winding (K angles must be <= steps D / 2)")
    half = window * angles
    rel = np.arange(-half, half + 1)
    nstate = rel.size
    first = (np.arange(starts) * angles) // starts  # start offsets in angle points
    dth = 2 * math.pi / angles
    centre = np.rint(winding * angles * np.arange(steps + 1) / steps).astype(int)
    jumps = np.arange(-max_jump, max_jump + 1)
    jump_cost = gamma * (jumps * dth) ** 2 / h**2 / steps
    v = np.full((starts, nstate), -np.inf)
    v[:, half] = 0.0
    arg = np.empty((steps, starts, nstate), dtype=np.int8)
    base = first[:, None] + rel[None, :]
    for i in range(steps):
        v = v + (dq[i] / steps) * np.cos(dth * (base + centre[i]))
        shift = centre[i + 1] - centre[i]
        best = np.full_like(v, -np.inf)
        barg = np.zeros(v.shape, dtype=np.int8)
        for d, c in zip(jumps, jump_cost):
            e = int(d) - shift  # r' = r + d - shift
            cand = np.full_like(v, -np.inf)
            if e >= 0:
                cand[:, e:] = v[:, :nstate - e] - c
            else:
                cand[:, :e] = v[:, -e:] - c
            better = cand > best
            best = np.where(better, cand, best)
            barg = np.where(better, np.int8(d), barg)
        v = best
        arg[i] = barg
    values = v[:, half]
    paths = np.empty((starts, steps + 1))
    r = np.full(starts, half)
    rows = np.arange(starts)
    for i in range(steps, -1, -1):
        paths[:, i] = dth * (first + rel[r] + centre[i])
        if i > 0:
            r = r - arg[i - 1, rows, r] + (centre[i] - centre[i - 1])
    return values, paths


def _project(path: np.ndarray, omega: float, harmonics: int, winding: int = 1) -> np.ndarray:
    """Packed N-harmonic coefficients of a lifted path sampled at ``t_i = i T / M``."""
    m = path.size - 1
    s = 2 * math.pi * np.arange(m) / m
    x = np.fft.rfft(path[:-1] - (s if winding == 1 else winding * s)) / m
    n = np.arange(1, harmonics + 1)
    c = np.zeros(harmonics, dtype=complex)
    k = min(harmonics, m // 2 - 1)
    c[:k] = 2 * x[1:k + 1]
    c *= np.sinc(n / (harmonics + 1))  # Lanczos: no Gibbs overshoot at the turns
    return np.concatenate(([x[0].real], -c.imag, c.real))


#: Time steps of the winding programme: at most this many (8 per extremum of q below it).
MAX_STEPS_WINDING = 16384


def propose_seeds(excitation, harmonics: int, gamma: float, count: int, winding: int = 1):
    """Up to ``count`` distinct seeds from the best paths, best first, as ``(name, x)``."""
    if winding == 1:
        steps = int(min(4096, max(128, 4 * harmonics, 8 * excitation.extrema.t.size)))
        values, paths = best_paths(excitation,
                                   _effective_gamma(excitation, harmonics, gamma), steps)
    else:
        steps = int(min(MAX_STEPS_WINDING, max(128, 2 * harmonics,
                                               8 * excitation.extrema.t.size, 8 * winding)))
        values, paths = best_paths_winding(
            excitation, _effective_gamma(excitation, harmonics, gamma), steps, winding)
    out, seen = [], []
    for s in np.argsort(-values, kind="stable"):
        if not math.isfinite(values[s]):
            continue
        x = _project(paths[s], excitation.omega, harmonics, winding)
        # same path up to the start angle: same seed
        if any(np.max(np.abs(x - y)) < 0.3 for y in seen):
            continue
        seen.append(x)
        out.append((f"dp-{len(out) + 1}", x))
        if len(out) >= count:
            break
    return out
