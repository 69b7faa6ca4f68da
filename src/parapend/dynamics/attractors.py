"""Long-term motion of paper Eq. 1: period-k oscillations and rotations on the Poincare map.

Conventions are those of paper Eq. 1 (``phi`` from the hanging position, see
:mod:`parapend.dynamics.simulate`). On the stroboscopic map ``P_m = (phi, phi')`` at
``t = t0 + m*T``, ``T = 2*pi/omega``, a trajectory has settled on a

* **period-k oscillation** if ``P_{m+k} = P_m`` with no net turn of ``phi`` (winding
  ``r = 0``); the hanging rest ``phi = phi' = 0`` is reported separately as ``"rest"``;
* **period-k rotation** if ``P_{m+k} = P_m`` up to ``phi -> phi + 2*pi*r``, ``r != 0``
  net turns per ``k`` periods. ``r > 0`` (``phi`` increasing) is called anticlockwise
  ``(+)``, ``r < 0`` clockwise ``(-)``. The period-1 rotation of the paper (Eqs. 3-4) is
  ``k = 1, r = +-1``;

with the smallest such ``k <= max_period``. Equality is to a tolerance ``tol`` on
``max(|wrapped d phi|, |d phi'|)`` and must hold, with the same ``r``, for ``k + 2``
consecutive periods (more than two full cycles). A focus whose spiral turns by about
``2*pi/k`` per period repeats at lag ``k`` before it repeats at lag 1, so a period ``k``
is not accepted while a proper divisor ``d`` of ``k`` repeats to within ``100*tol``: the
true period ``d`` is awaited. Anything else within the period budget is ``"other"``
(chaotic, a long transient, or a period above ``max_period``).

Two entry points:

* :func:`classify` -- classify given stroboscopic samples (e.g. from
  :func:`parapend.dynamics.stroboscopic` or a DOP853 trajectory): a direct,
  unvectorized check of the tail of one sequence; the reference implementation.
* :func:`find_attractors` -- vectorized engine for many initial conditions: integrates all
  of them together (fixed-step RK4 of :mod:`.simulate`), retires each trajectory as soon as
  it is decided, and builds a catalogue of the distinct attractors found.

Capture (the engine's speed-up). Deciding by ``tol``-convergence alone costs about 90
periods per trajectory at ``gamma = 0.1`` (contraction ``exp(-gamma*T/2)`` per period);
being within 0.05 of an attractor takes about 20. So: a *pilot* run (256 evenly spaced
initial conditions, a quarter of the steps, no capture) lists the attractors; each is then
*verified* at full steps by probe trajectories (eight on a circle of radius
``capture_radius`` around each of its Poincare points, which must all come back to within
a tenth of that radius before any other attractor claims them). Only then does a
trajectory that comes within ``capture_radius`` of the attractor get its label without
waiting for full convergence. An *anchor* trajectory started on each pilot attractor is
run to ``tol`` convergence at full steps and replaces the pilot's Poincare points.
New attractors found later go through the same verification. ``capture_radius=0``
switches all this off (slower, assumption-free); tests check both give the same labels.
"""

from __future__ import annotations

import math
import signal
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from ..errors import ParameterError, check_finite, check_int, check_positive
from .simulate import (
    _check_params,
    _check_steps,
    _RK4Map,
    initial_conditions,
    phi_to_theta,
)

__all__ = ["Attractor", "AttractorSearch", "Classification", "classify", "find_attractors"]

_TWO_PI = 2 * math.pi
_EXTRA = 2          # consecutive matches beyond k required for convergence
_PROBES = 8
_THREAD_MIN = 2048  # trajectories per thread below which the batch is not split
_NEAR = 100.0       # a lag-d distance below _NEAR*tol means period d, not a multiple of d


def _divisors(k: int) -> list[int]:
    """Proper divisors of ``k``."""
    return [d for d in range(1, k) if k % d == 0]


def _wrap(x):
    """Wrap angles to ``[-pi, pi)``."""
    return x - _TWO_PI * np.floor((x + math.pi) / _TWO_PI)


def _name(kind: str, k: int, r: int) -> str:
    if kind == "rest":
        return "rest (hanging)"
    if kind == "oscillation":
        return f"P{k} oscillation"
    sign = "+" if r > 0 else "-"
    extra = "" if abs(r) == k else f" ({abs(r)} turns/{k} periods)"
    return f"P{k} rotation ({sign}){extra}"


def _direction(r: int) -> str:
    return "none" if r == 0 else ("anticlockwise" if r > 0 else "clockwise")


@dataclass(frozen=True, eq=False)
class Attractor:
    """One attractor on the stroboscopic map of paper Eq. 1.

    Attributes
    ----------
    code : int
        Label used in basin arrays (>= 1; 0 means "other").
    name : str
        E.g. ``"P1 rotation (+)"``, ``"P2 oscillation"``, ``"rest (hanging)"``; a suffix
        ``" #2"`` distinguishes distinct attractors of the same type.
    kind : str
        ``"rest"``, ``"oscillation"`` or ``"rotation"``.
    period : int
        ``k``, in forcing periods.
    winding : int
        Net turns of ``phi`` per ``k`` periods (> 0 anticlockwise, ``phi`` increasing).
    direction : str
        ``"anticlockwise"``, ``"clockwise"`` or ``"none"``.
    phi, dphi : ndarray, shape (k,)
        Poincare points in time order, ``phi`` wrapped to ``[-pi, pi)`` (Eq. 1 convention).
    count : int
        Initial conditions that reached it (in the search that found it).
    capture_verified : bool
        Whether the capture radius was verified for it (see module docstring).
    """

    code: int
    name: str
    kind: str
    period: int
    winding: int
    direction: str
    phi: np.ndarray
    dphi: np.ndarray
    count: int = 0
    capture_verified: bool = False

    def to_dict(self) -> dict:
        return {"code": self.code, "name": self.name, "kind": self.kind, "period": self.period,
                "winding": self.winding, "direction": self.direction,
                "phi": [float(x) for x in self.phi], "dphi": [float(x) for x in self.dphi],
                "count": self.count, "capture_verified": self.capture_verified}


@dataclass(frozen=True, eq=False)
class Classification:
    """Result of :func:`classify` for one stroboscopic sequence.

    Attributes
    ----------
    name : str
        As ``Attractor.name``, or ``"other"``.
    kind : str
        ``"rest"``, ``"oscillation"``, ``"rotation"`` or ``"other"``.
    period, winding : int
        ``k`` and net turns per ``k`` periods (0 and 0 for ``"other"``).
    direction : str
    phi, dphi : ndarray, shape (k,)
        The last ``k`` Poincare points (``phi`` wrapped to ``[-pi, pi)``), empty for "other".
    residual : float
        ``max |P_{m} - P_{m-k}|`` over the checked window (NaN for "other").
    """

    name: str
    kind: str
    period: int
    winding: int
    direction: str
    phi: np.ndarray
    dphi: np.ndarray
    residual: float


def _kind(k: int, r: int, phi: np.ndarray, dphi: np.ndarray, tol: float) -> str:
    if r != 0:
        return "rotation"
    if k == 1 and abs(_wrap(phi[0])) <= 10 * tol and abs(dphi[0]) <= 10 * tol:
        return "rest"
    return "oscillation"


def classify(phi: ArrayLike, dphi: ArrayLike, *, tol: float = 1e-6,
             max_period: int = 8) -> Classification:
    """Classify the tail of one stroboscopic sequence of paper Eq. 1.

    Parameters
    ----------
    phi, dphi : array_like, shape (n,)
        Poincare samples ``phi`` (from hanging, unwrapped or not) and ``phi'`` at
        ``t0 + m*T``, m = 0..n-1, transients included.
    tol : float
        Tolerance on ``max(|wrapped d phi|, |d phi'|)``.
    max_period : int
        Largest ``k`` tried.

    Returns
    -------
    Classification
        The smallest ``k`` for which the last ``2*k + 2`` samples repeat with period ``k``
        (same net turn ``r`` for each of the ``k + 2`` pairs), or ``"other"``.
    """
    phi = np.asarray(phi, dtype=float)
    dphi = np.asarray(dphi, dtype=float)
    if phi.ndim != 1 or phi.shape != dphi.shape:
        raise ParameterError(f"phi, dphi: expected two 1-D arrays of equal length, got shapes "
                             f"{phi.shape} and {dphi.shape}")
    tol = check_positive("tol", tol)
    kmax = check_int("max_period", max_period, 1)
    n = phi.size
    for k in range(1, kmax + 1):
        m = k + _EXTRA
        if n < m + k:
            break
        d = phi[n - m:] - phi[n - m - k:n - k]
        r = np.rint(d / _TWO_PI)
        res = np.maximum(np.abs(d - _TWO_PI * r), np.abs(dphi[n - m:] - dphi[n - m - k:n - k]))
        if np.all(res < tol) and np.all(r == r[0]):
            for dv in _divisors(k):
                # a converging focus can repeat at lag k before lag d | k: report period d
                dd = phi[n - k - 1:] - phi[n - k - 1 - dv:n - dv]
                rd = np.rint(dd / _TWO_PI)
                resd = np.maximum(np.abs(dd - _TWO_PI * rd),
                                  np.abs(dphi[n - k - 1:] - dphi[n - k - 1 - dv:n - dv]))
                if np.all(resd < _NEAR * tol) and np.all(rd == rd[0]):
                    k, r, res = dv, rd, resd
                    break
            rr = int(r[0])
            ph, dp = _wrap(phi[n - k:]), dphi[n - k:].copy()
            kind = _kind(k, rr, ph, dp, tol)
            return Classification(_name(kind, k, rr), kind, k, rr, _direction(rr), ph, dp,
                                  float(np.max(res)))
    return Classification("other", "other", 0, 0, "none", np.empty(0), np.empty(0), math.nan)


# --- vectorized engine ------------------------------------------------------------------
@dataclass
class _Entry:
    """An attractor as found (internal; theta convention, theta wrapped to [-pi, pi))."""

    period: int
    winding: int
    theta: np.ndarray   # (k,) Poincare points in time order
    v: np.ndarray
    kind: str
    refined: bool = False     # points come from tol-convergence of the full-step map
    probes_left: int = 0
    probes_ok: bool = True
    capture: bool = False


@dataclass(frozen=True, eq=False)
class AttractorSearch:
    """Result of :func:`find_attractors`.

    Attributes
    ----------
    labels : ndarray of int, shape like the initial conditions
        Attractor code (see ``attractors``), 0 for "other".
    phase : ndarray of int, same shape
        For a period-k attractor, the index ``j`` (into ``Attractor.phi``) of the Poincare
        point visited at ``t0 + m*T`` with ``m = 0 mod k`` (0 for k = 1, -1 for "other").
    periods_used : ndarray of int, same shape
        Forcing periods integrated before the trajectory was retired.
    attractors : tuple of Attractor
        Distinct attractors, ``attractors[c - 1].code == c``, in canonical order (rest,
        oscillations, rotations; then by period, then anticlockwise first).
    legend : dict
        ``{code: name}`` including ``0: "other"``.
    gamma, p, omega : float
    steps_per_period, max_periods, max_period : int
    tol, capture_radius : float
    stats : dict
        Work done: ``"periods"`` (total trajectory-periods on the grid), ``"probe_periods"``,
        ``"pilot_periods"``, ``"pilot_size"``, ``"captured"``, ``"converged"``.
    """

    labels: np.ndarray
    phase: np.ndarray
    periods_used: np.ndarray
    attractors: tuple
    legend: dict
    gamma: float
    p: float
    omega: float
    steps_per_period: int
    max_periods: int
    max_period: int
    tol: float
    capture_radius: float
    stats: dict = field(default_factory=dict)

    def code_of(self, name: str) -> int:
        """Code of the attractor called ``name`` (KeyError if absent)."""
        for a in self.attractors:
            if a.name == name:
                return a.code
        raise KeyError(f"no attractor named {name!r}; found {[a.name for a in self.attractors]}")


def _dist(th, v, th0, v0):
    """``max(|wrap(th - th0)|, |v - v0|)`` (theta convention, vectorized)."""
    d = th - th0
    d -= _TWO_PI * np.rint(d / _TWO_PI)
    return np.maximum(np.abs(d), np.abs(v - v0))


def _dist_set(th, v, ent: _Entry):
    """Distance of points to the nearest Poincare point of an entry."""
    return np.min([_dist(th, v, a, b) for a, b in zip(ent.theta, ent.v)], axis=0)


class _Search:
    """Synchronous fixed-step integration of a shrinking batch with convergence bookkeeping.

    Each trajectory has a ``role`` and an ``owner``: role 0 an initial condition (owner its
    index), role 1 a capture-verification probe of entry ``owner``, role 2 an anchor of
    entry ``owner`` (started on its pilot Poincare point, run to ``tol`` convergence to
    refine the points at full steps).
    """

    def __init__(self, gamma, p, omega, steps, t0, tol, kmax, max_periods, capture_radius,
                 workers):
        self.maps = [_RK4Map(gamma, p, omega, steps, t0) for _ in range(workers)]
        self.workers = workers
        self.tol, self.kmax, self.max_periods = tol, kmax, max_periods
        self.rcap = capture_radius
        self.match_tol = max(1e3 * tol, 1e-2)
        self.h = kmax + 1
        self.entries: list[_Entry] = []
        self._pending: list[tuple] = []
        self.stats = {"periods": 0, "probe_periods": 0, "captured": 0, "converged": 0}

    # state management -------------------------------------------------------------
    _FIELDS = ("th", "v", "turns", "owner", "role", "age", "hth", "hv", "hturns", "cnt",
               "wind")

    def _init_state(self, th, v, owner, role):
        n = th.size
        w = np.rint(th / _TWO_PI)
        self.th, self.v, self.turns = th - _TWO_PI * w, v.copy(), w
        self.owner = owner
        self.role = np.full(n, role, dtype=np.int64)
        self.age = np.zeros(n, dtype=np.int64)
        self.hth = np.zeros((self.h, n))
        self.hv = np.zeros((self.h, n))
        self.hturns = np.zeros((self.h, n))
        self.cnt = np.zeros((self.kmax, n), dtype=np.int64)
        self.wind = np.zeros((self.kmax, n))

    def _append(self, th, v, owner, role):
        old = [getattr(self, f) for f in self._FIELDS]
        self._init_state(th, v, owner, role)
        for f, a in zip(self._FIELDS, old):
            setattr(self, f, np.concatenate((a, getattr(self, f)), axis=a.ndim - 1))

    def _keep(self, keep):
        for name in ("th", "v", "turns", "owner", "role", "age"):
            setattr(self, name, getattr(self, name)[keep])
        for name in ("hth", "hv", "hturns", "cnt", "wind"):
            setattr(self, name, np.ascontiguousarray(getattr(self, name)[:, keep]))

    def _schedule_probes(self, e: int):
        """Eight probes on a circle of radius ``rcap`` around each Poincare point of ``e``."""
        ent = self.entries[e]
        a = _TWO_PI * np.arange(_PROBES) / _PROBES
        pth = (ent.theta[:, None] + self.rcap * np.cos(a)).ravel()
        pv = (ent.v[:, None] + self.rcap * np.sin(a)).ravel()
        ent.probes_left = pth.size
        self._pending.append((pth, pv, np.full(pth.size, e, dtype=np.int64), 1))

    def add_entry(self, ent: _Entry) -> int:
        self.entries.append(ent)
        e = len(self.entries) - 1
        if self.rcap > 0:
            self._schedule_probes(e)
        if not ent.refined:
            self._pending.append((ent.theta[:1].copy(), ent.v[:1].copy(),
                                  np.array([e], dtype=np.int64), 2))
        return e

    def _advance(self, pool):
        n = self.th.size
        if pool is None or n < _THREAD_MIN * self.workers:
            self.maps[0].advance(self.th, self.v)
            return
        edges = np.linspace(0, n, self.workers + 1).astype(int)
        futs = [pool.submit(self.maps[i].advance, self.th[edges[i]:edges[i + 1]],
                            self.v[edges[i]:edges[i + 1]]) for i in range(self.workers)]
        for f in futs:
            f.result()

    # main loop -------------------------------------------------------------------
    def run(self, th0, v0):
        """Integrate until every trajectory is retired.

        Returns raw labels (entry indices, -1 for "other"), periods used, and the state
        ``(theta, v)`` at retirement (which fixes the phase on a period-k attractor).
        """
        n0 = th0.size
        labels = np.full(n0, -1, dtype=np.int64)
        used = np.zeros(n0, dtype=np.int64)
        self.end_th = np.zeros(n0)
        self.end_v = np.zeros(n0)
        self._init_state(th0, v0, np.arange(n0), 0)
        self._flush()
        pool = ThreadPoolExecutor(self.workers) if self.workers > 1 else None
        try:
            m = 0
            while self.th.size:
                m += 1
                self._advance(pool)
                self._step(m, labels, used)
        finally:
            if pool is not None:
                pool.shutdown()
        return labels, used, self.end_th, self.end_v

    def _flush(self):
        for args in self._pending:
            self._append(*args)
        self._pending.clear()

    def _step(self, m, labels, used):
        tol, kmax, h = self.tol, self.kmax, self.h
        w = np.rint(self.th / _TWO_PI)
        self.th -= _TWO_PI * w
        self.turns += w
        self.age += 1
        th, v, turns, age, owner, role = (self.th, self.v, self.turns, self.age, self.owner,
                                          self.role)
        conv_k = np.zeros(th.size, dtype=np.int64)      # 0: not converged
        conv_r = np.zeros(th.size)
        dists = {}
        for k in range(1, kmax + 1):
            j = (m - k) % h
            d = th - self.hth[j]
            r = np.rint(d / _TWO_PI)
            d -= _TWO_PI * r
            dist = np.maximum(np.abs(d), np.abs(v - self.hv[j]))
            wind = turns - self.hturns[j] + r
            ok = (dist < tol) & (age >= k)
            c = self.cnt[k - 1]
            c[:] = np.where(ok, np.where(wind == self.wind[k - 1], c + 1, 1), 0)
            self.wind[k - 1] = wind
            hit = (c >= k + _EXTRA) & (conv_k == 0)
            for dv in _divisors(k):
                # a focus whose spiral turns by about 2 pi/k per period repeats at lag k
                # before it repeats at lag d | k: wait for the true period d
                hit &= dists[dv] >= _NEAR * tol
            dists[k] = dist
            conv_k[hit] = k
            conv_r[hit] = wind[hit]
        j = m % h
        self.hth[j] = th
        self.hv[j] = v
        self.hturns[j] = turns

        result = np.full(th.size, -2, dtype=np.int64)   # -2 active, -1 other, >= 0 entry
        grid = role == 0
        for e, ent in enumerate(self.entries):
            if ent.capture:
                near = (_dist_set(th, v, ent) < self.rcap) & (result == -2) & (role != 2)
                result[near] = e
                self.stats["captured"] += int(np.count_nonzero(near & grid))
            if ent.probes_left:
                mine = np.flatnonzero((owner == e) & (role == 1))
                if mine.size:
                    back = _dist_set(th[mine], v[mine], ent) < 0.1 * self.rcap
                    result[mine[back & (result[mine] == -2)]] = e
        idx = np.flatnonzero((conv_k > 0) & (result == -2))
        if idx.size:
            result[idx] = self._match(idx, conv_k[idx], conv_r[idx], m)
            self.stats["converged"] += int(np.count_nonzero(grid[idx]))
        result[(result == -2) & (age >= self.max_periods)] = -1
        done = result != -2
        if not np.any(done):
            self._flush()
            return
        g = done & grid
        labels[owner[g]] = result[g]
        used[owner[g]] = age[g]
        self.end_th[owner[g]] = th[g]
        self.end_v[owner[g]] = v[g]
        self.stats["periods"] += int(np.sum(age[g]))
        for i in np.flatnonzero(done & (role == 1)):
            e = owner[i]
            ent = self.entries[e]
            ent.probes_left -= 1
            self.stats["probe_periods"] += int(age[i])
            if result[i] != e:
                ent.probes_ok = False
            if ent.probes_left == 0:
                ent.capture = ent.probes_ok
        self._keep(~done)
        self._flush()

    def _cycle(self, i, k, m):
        """The last ``k`` Poincare points of active trajectory ``i``, from the current one on."""
        cols = [(m - k + 1 + j) % self.h for j in range(k - 1)]
        th = _wrap(np.array([self.th[i]] + [self.hth[c, i] for c in cols]))
        v = np.array([self.v[i]] + [self.hv[c, i] for c in cols])
        return th, v

    def _match(self, idx, ks, rs, m):
        """Entry index for each newly converged trajectory (new entries created as needed)."""
        out = np.full(idx.size, -1, dtype=np.int64)
        th, v = self.th[idx], self.v[idx]
        for e, ent in enumerate(self.entries):
            same = (ks == ent.period) & (rs == ent.winding) & (out < 0)
            if np.any(same):
                out[same & (_dist_set(th, v, ent) < self.match_tol)] = e
        for i in range(idx.size):
            if out[i] < 0:      # not in the catalogue when this period began
                for e, ent in enumerate(self.entries):
                    if (ent.period == ks[i] and ent.winding == rs[i]
                            and _dist_set(th[i], v[i], ent) < self.match_tol):
                        out[i] = e
                        break
            ent = self.entries[out[i]] if out[i] >= 0 else None
            if ent is not None and ent.refined:
                continue
            k, r = int(ks[i]), int(rs[i])
            cth, cv = self._cycle(idx[i], k, m)
            if ent is not None:      # pilot entry: replace its points by full-step ones
                ent.theta, ent.v, ent.refined = cth, cv, True
            else:
                kind = _kind(k, r, _wrap(cth - math.pi), cv, self.tol)
                out[i] = self.add_entry(_Entry(k, r, cth, cv, kind, refined=True))
        return out


def _canonical(entries: list[_Entry]) -> list[int]:
    """Order of entries: rest, oscillations, rotations; period; + before -; |winding|; phi."""
    rank = {"rest": 0, "oscillation": 1, "rotation": 2}

    def key(e):
        ent = entries[e]
        phi = _wrap(ent.theta - math.pi)
        return (rank[ent.kind], ent.period, -np.sign(ent.winding), abs(ent.winding),
                round(float(np.min(phi)), 3), round(float(np.min(ent.v)), 3))

    return sorted(range(len(entries)), key=key)


def _finalize(entries: list[_Entry], raw_labels, used, end_th, end_v):
    """Canonical codes (1..M, 0 = other), phases, Attractor objects and legend.

    Each attractor's Poincare points are rolled (time order kept) to start at the one with
    the smallest ``phi``. The phase of a trajectory on a period-k attractor is the index
    of the Poincare point it visits at periods ``m = 0 mod k`` (from its retirement state:
    near point ``i`` after ``m`` periods means point ``(i - m) mod k`` at ``m = 0``); -1 for
    "other". Entries that no initial condition reached (pilot-only) are dropped.
    """
    raw_labels = np.asarray(raw_labels)
    counts = np.bincount(raw_labels[raw_labels >= 0], minlength=len(entries))
    order = [e for e in _canonical(entries) if counts[e] > 0]
    code_of = np.zeros(len(entries) + 1, dtype=np.int64)   # last slot: raw -1 -> 0
    phase = np.full(raw_labels.shape, -1, dtype=np.int64)
    attractors = []
    names_seen: dict[str, int] = {}
    for c, e in enumerate(order, start=1):
        ent = entries[e]
        code_of[e] = c
        phi = _wrap(ent.theta - math.pi)
        roll = int(np.argmin(phi))
        phi, dphi = np.roll(phi, -roll), np.roll(ent.v, -roll)
        th = np.roll(ent.theta, -roll)
        mine = np.flatnonzero(raw_labels == e)
        d = np.array([_dist(end_th[mine], end_v[mine], a, b) for a, b in zip(th, dphi)])
        phase[mine] = (np.argmin(d, axis=0) - used[mine]) % ent.period
        base = _name(ent.kind, ent.period, ent.winding)
        names_seen[base] = names_seen.get(base, 0) + 1
        name = base if names_seen[base] == 1 else f"{base} #{names_seen[base]}"
        attractors.append(Attractor(c, name, ent.kind, ent.period, ent.winding,
                                    _direction(ent.winding), phi, dphi, int(counts[e]),
                                    bool(ent.capture)))
    labels = code_of[raw_labels]          # raw -1 indexes the last slot (0)
    legend = {0: "other"}
    legend.update({a.code: a.name for a in attractors})
    return labels, phase, tuple(attractors), legend


ENGINES = ("numba", "numpy")


def _check_engine(engine) -> str:
    if engine not in ENGINES:
        raise ParameterError(f"engine: expected one of {', '.join(ENGINES)}, got {engine!r:.40}")
    return engine


def _resolve_workers(workers, engine: str = "numpy") -> int:
    """Threads: ``None`` means 1 for the NumPy engine and every core numba sees for numba."""
    if workers is None:
        if engine == "numba":
            import numba

            return int(numba.config.NUMBA_NUM_THREADS)
        return 1
    return check_int("workers", workers, 1, 64)


def _check_search(tol, max_period, periods, capture_radius, steps_per_period):
    tol = check_positive("tol", tol)
    kmax = check_int("max_period", max_period, 1, 64)
    periods = check_int("periods", periods, 1)
    rcap = check_finite("capture_radius", capture_radius)
    if rcap < 0 or rcap >= 1:
        raise ParameterError(f"capture_radius: expected a number in [0, 1), got {rcap!r}")
    if 0 < rcap <= 100 * tol:
        raise ParameterError(f"capture_radius: expected 0 or a radius above 100*tol = "
                             f"{100 * tol:g}, got {rcap:g}")
    return tol, kmax, periods, rcap, _check_steps(steps_per_period)


_PILOT_SIZE = 256


def _run_search(th0, v0, gamma, p, omega, *, periods, steps, t0, tol, kmax, rcap, workers,
                pilot: bool, engine: str = "numpy", progress=None):
    """Pilot (coarse subsample, quarter steps, no capture) then the full search."""
    if engine == "numba":
        return _run_compiled(th0, v0, gamma, p, omega, periods=periods, steps=steps, t0=t0,
                             tol=tol, kmax=kmax, rcap=rcap, workers=workers,
                             pilot=pilot, progress=progress)
    s = _Search(gamma, p, omega, steps, t0, tol, kmax, periods, rcap, workers)
    n = th0.size
    pilot_periods = pilot_size = 0
    if pilot and rcap > 0 and n > 4 * _PILOT_SIZE:
        sel = np.unique(np.linspace(0, n - 1, _PILOT_SIZE).round().astype(np.int64))
        ps = _Search(gamma, p, omega, max(16, steps // 4), t0, tol, kmax, periods, 0.0, 1)
        ps.run(th0[sel], v0[sel])
        pilot_periods, pilot_size = ps.stats["periods"], sel.size
        for ent in ps.entries:
            s.add_entry(_Entry(ent.period, ent.winding, ent.theta, ent.v, ent.kind))
    raw, used, end_th, end_v = s.run(th0, v0)
    stats = dict(s.stats, pilot_periods=pilot_periods, pilot_size=pilot_size, engine=engine)
    return s.entries, raw, used, end_th, end_v, stats


_CHUNK_S = 0.5        # seconds per kernel call (Ctrl-C latency, progress steps)
_CHUNK_FIRST = 16384
_CHUNK_MIN = 64


def _groups(n: int, k) -> int:
    """Work units of one kernel call: at most ``k.MAX_GROUPS``, each at least 8 points per SIMD
    lane (a lane that finishes waits for the slowest of its group; with 2 points per lane
    the default map took 15 to 40 % more CPU time)."""
    return max(1, min(k.MAX_GROUPS, n // (8 * k.LANES)))


class _DeferredSigint:
    """Hold a Ctrl-C (SIGINT) while compiled code runs; :meth:`check` raises it between calls.

    A SIGINT that arrives inside a numba kernel sets Python's pending-signal flag, and the
    kernel's return then fails with a chain of ``SystemError`` (about 60 lines) instead of a
    ``KeyboardInterrupt``. Here Python's handler is replaced, while the block runs, by one
    that only records the signal; ``check()`` (called between kernel calls) and the exit of
    the block run the original handler, which raises ``KeyboardInterrupt``. Outside the main
    thread, when SIGINT is not handled by a Python function, or with ``NUMBA_DISABLE_JIT``
    (the kernel is then Python code, which a KeyboardInterrupt stops at once), nothing is
    changed.
    """

    def __enter__(self):
        import numba

        self.hit = False
        self.old = None
        if (threading.current_thread() is threading.main_thread()
                and not numba.config.DISABLE_JIT):
            old = signal.getsignal(signal.SIGINT)
            if callable(old):
                self.old = old
                signal.signal(signal.SIGINT, self._record)
        return self

    def _record(self, signum, frame):
        self.hit = True

    def check(self):
        if self.hit:
            self.hit = False
            self.old(signal.SIGINT, None)

    def __exit__(self, *exc):
        if self.old is not None:
            signal.signal(signal.SIGINT, self.old)
            if exc[0] is None:
                self.check()
        return False


class _Compiled:
    """Calls of the compiled kernel (:mod:`._kernel`) for one parameter set."""

    def __init__(self, gamma, p, omega, steps, t0, tol, kmax, max_periods, workers):
        from . import _kernel

        self.k = _kernel
        self.gamma, self.p, self.omega, self.t0 = gamma, p, omega, t0
        self.tol, self.kmax, self.max_periods = tol, kmax, max_periods
        self.match_tol = max(1e3 * tol, 1e-2)
        self.workers = workers
        self.steps = steps

    def run(self, th0, v0, entries, rcap, *, steps=None, capture=None, progress=None):
        """Kernel over ``(th0, v0)`` with catalogue ``entries``; capture radius ``rcap`` for
        the entries flagged in ``capture`` (default: their ``capture`` attribute)."""
        import numba

        m = _RK4Map(self.gamma, self.p, self.omega, steps or self.steps, self.t0)
        kmax = self.kmax
        ne = len(entries)
        ent_th = np.zeros((max(ne, 1), kmax))
        ent_v = np.zeros((max(ne, 1), kmax))
        for e, ent in enumerate(entries):
            ent_th[e, :ent.period] = ent.theta
            ent_v[e, :ent.period] = ent.v
        ent_k = np.array([ent.period for ent in entries], dtype=np.int64)
        ent_r = np.array([ent.winding for ent in entries], dtype=np.int64)
        if capture is None:
            capture = [bool(ent.capture) for ent in entries]
        ent_cap = np.array(capture, dtype=np.bool_).reshape(-1)[:ne]
        th0 = np.ascontiguousarray(th0, dtype=float)
        v0 = np.ascontiguousarray(v0, dtype=float)
        n = th0.size
        steps = m.steps
        parts = []
        before = numba.get_num_threads()
        numba.set_num_threads(min(self.workers, numba.config.NUMBA_NUM_THREADS))
        # calls of about _CHUNK_S seconds: between two of them a Ctrl-C (held by
        # _DeferredSigint while compiled code runs) is raised as KeyboardInterrupt and the
        # progress display moves. The first call is sized for the period budget (a second or
        # two if every point ran the whole budget; most stop after 20 to 40 periods), the
        # next ones from the measured time. Labels do not depend on the chunks: every point
        # is integrated on its own from a reset lane.
        size = min(n, max(_CHUNK_MIN, int(_CHUNK_FIRST * 38400 / (self.max_periods
                                                                   * m.steps))))
        i = 0
        try:
            with _DeferredSigint() as sig:
                while i < n:
                    j = min(n, i + max(1, size))
                    t = time.perf_counter()
                    parts.append(self.k.basin_kernel(
                        th0[i:j], v0[i:j], m.a, m.gamma, m.h, steps, self.tol, kmax,
                        self.max_periods, rcap, self.match_tol, ent_th, ent_v, ent_k, ent_r,
                        ent_cap, _groups(j - i, self.k)))
                    sig.check()
                    dt = time.perf_counter() - t
                    size = int(min(4 * (j - i), max(_CHUNK_MIN,
                                                    (j - i) * _CHUNK_S / max(dt, 1e-4))))
                    i = j
                    if progress is not None:
                        progress(int(i), n)
        finally:
            numba.set_num_threads(before)
        if not parts:
            parts.append(self.k.basin_kernel(
                th0, v0, m.a, m.gamma, m.h, steps, self.tol, kmax, self.max_periods, rcap,
                self.match_tol, ent_th, ent_v, ent_k, ent_r, ent_cap, 1))
        return tuple(np.concatenate(x) for x in zip(*parts))

    def catalogue(self, entries, raw, new_k, new_r, cyc_th, cyc_v):
        """Give every ``NEW`` point an entry (matching rule of ``_Search._match``; new
        entries appended in index order, refined). Modifies ``raw`` and ``entries``."""
        new = np.flatnonzero(raw == self.k.NEW)
        while new.size:
            i = new[0]
            k, r = int(new_k[i]), int(new_r[i])
            cth, cv = cyc_th[i, :k].copy(), cyc_v[i, :k].copy()
            e = -1
            for f, ent in enumerate(entries):
                if (ent.period == k and ent.winding == r
                        and _dist_set(cth[0], cv[0], ent) < self.match_tol):
                    e = f
                    break
            if e < 0:
                kind = _kind(k, r, _wrap(cth - math.pi), cv, self.tol)
                entries.append(_Entry(k, r, cth, cv, kind, refined=True))
                e = len(entries) - 1
            ent = entries[e]
            same = new[(new_k[new] == k) & (new_r[new] == r)]
            same = same[_dist_set(cyc_th[same, 0], cyc_v[same, 0], ent) < self.match_tol]
            raw[same] = e
            raw[i] = e
            new = new[raw[new] == self.k.NEW]


def _run_compiled(th0, v0, gamma, p, omega, *, periods, steps, t0, tol, kmax, rcap, workers,
                  pilot, progress=None):
    """The search with the compiled kernel: catalogue first, then every point on its own.

    1. Pilot (as the NumPy engine: 256 evenly spaced points, a quarter of the steps, no
       capture): the attractors found become entries.
    2. Anchors: one trajectory from each pilot entry at full steps, run to ``tol``
       convergence, replaces the entry's points (``refined``).
    3. Verification: eight probes on a circle of radius ``rcap`` around each Poincare point;
       an entry gets capture when all its probes come back to within ``rcap/10`` of it
       before reaching (within ``rcap/10``) or converging to any other entry.
    4. The grid, with capture by the verified entries; points that converged to an attractor
       outside the catalogue are catalogued afterwards in index order.
    """
    c = _Compiled(gamma, p, omega, steps, t0, tol, kmax, periods, workers)
    entries: list[_Entry] = []
    n = th0.size
    stats = {"pilot_periods": 0, "pilot_size": 0, "anchor_periods": 0, "probe_periods": 0}
    if pilot and rcap > 0 and n > 4 * _PILOT_SIZE:
        sel = np.unique(np.linspace(0, n - 1, _PILOT_SIZE).round().astype(np.int64))
        out = c.run(th0[sel], v0[sel], [], 0.0, steps=max(16, steps // 4))
        c.catalogue(entries, out[0], *out[4:])
        stats.update(pilot_periods=int(out[1].sum()), pilot_size=int(sel.size))
        if entries:
            # anchors: refine each entry's points at full steps (empty catalogue: each
            # converged anchor comes back NEW with its cycle)
            out = c.run(np.array([e.theta[0] for e in entries]),
                        np.array([e.v[0] for e in entries]), [], 0.0)
            stats["anchor_periods"] = int(out[1].sum())
            for e, ent in enumerate(entries):
                k = int(out[4][e])
                if (out[0][e] == c.k.NEW and k == ent.period and out[5][e] == ent.winding):
                    ent.theta, ent.v = out[6][e, :k].copy(), out[7][e, :k].copy()
                    ent.refined = True
            # verification probes
            a = _TWO_PI * np.arange(_PROBES) / _PROBES
            pth = np.concatenate([(ent.theta[:, None] + rcap * np.cos(a)).ravel()
                                  for ent in entries])
            pv = np.concatenate([(ent.v[:, None] + rcap * np.sin(a)).ravel()
                                 for ent in entries])
            owner = np.concatenate([np.full(ent.period * _PROBES, e)
                                    for e, ent in enumerate(entries)])
            out = c.run(pth, pv, entries, 0.1 * rcap, capture=[True] * len(entries))
            stats["probe_periods"] = int(out[1].sum())
            for e, ent in enumerate(entries):
                ent.capture = bool(np.all(out[0][owner == e] == e))
    n_cat = len(entries)
    raw, used, end_th, end_v, new_k, new_r, cyc_th, cyc_v = c.run(th0, v0, entries, rcap,
                                                                   progress=progress)
    decided = int(np.count_nonzero(raw >= 0))
    c.catalogue(entries, raw, new_k, new_r, cyc_th, cyc_v)
    stats.update(periods=int(np.sum(used)), decided_by_catalogue=decided,
                 catalogued_after=int(np.count_nonzero(raw >= 0)) - decided,
                 entries_before_grid=n_cat,
                 verified=int(sum(e.capture for e in entries)), engine="numba")
    return entries, raw, used, end_th, end_v, stats


def _rerun(th0, v0, entries: list[_Entry], gamma, p, omega, *, periods, steps, t0, tol, kmax,
           rcap, workers, engine):
    """Labels of ``(th0, v0)`` against an existing catalogue (no pilot, no new verification).

    The entries keep their capture flags; attractors outside the catalogue are appended to
    ``entries`` (same matching rules). Returns raw labels (indices into ``entries``, -1 for
    "other"), periods used and the state at retirement, as :func:`_run_search`.
    """
    if engine == "numba":
        c = _Compiled(gamma, p, omega, steps, t0, tol, kmax, periods, workers)
        out = c.run(th0, v0, entries, rcap)
        raw = out[0].copy()
        c.catalogue(entries, raw, *out[4:])
        return raw, out[1], out[2], out[3]
    s = _Search(gamma, p, omega, steps, t0, tol, kmax, periods, rcap, workers)
    for ent in entries:
        s.entries.append(_Entry(ent.period, ent.winding, ent.theta.copy(), ent.v.copy(),
                                ent.kind, refined=True, capture=ent.capture))
    n_old = len(entries)
    raw, used, end_th, end_v = s.run(np.asarray(th0, dtype=float), np.asarray(v0, dtype=float))
    entries.extend(s.entries[n_old:])
    return raw, used, end_th, end_v


def find_attractors(phi0: ArrayLike, dphi0: ArrayLike, gamma: float, p: float, omega: float, *,
                    periods: int = 300, steps_per_period: int = 128, t0: float = 0.0,
                    tol: float = 1e-6, max_period: int = 8, capture_radius: float = 0.05,
                    pilot: bool = True, workers: int = 1) -> AttractorSearch:
    """Long-term motion of paper Eq. 1 from many initial conditions at once.

    Parameters
    ----------
    phi0, dphi0 : array_like
        Initial angle from the hanging position (rad) and rate at ``t0`` (broadcast).
    gamma, p, omega : float
        Damping (>= 0), excitation strength and frequency (> 0) of Eq. 1.
    periods : int
        Budget of forcing periods per trajectory; unconverged trajectories are "other".
    steps_per_period : int
        RK4 steps per forcing period (see :func:`~parapend.dynamics.stroboscopic`).
    t0 : float
        Initial time (the Poincare section is ``t0 + m*T``).
    tol : float
        Convergence tolerance on the Poincare map (see module docstring).
    max_period : int
        Largest period ``k`` detected.
    capture_radius : float
        Radius (in ``max(|d phi|, |d phi'|)``) around a confirmed attractor within which a
        trajectory is assigned to it. Each attractor's radius is verified first: eight probe
        trajectories on a circle of that radius around each of its Poincare points must all
        come back to within a tenth of it, before any other attractor claims them.
        0 disables capture: every trajectory then needs full ``tol`` convergence (about
        five times slower, assumption-free).
    pilot : bool
        With capture on and more than 1024 initial conditions, first run an evenly spaced
        subsample of 256 of them with a quarter of the steps to find the attractors, so that
        capture (after verification at full steps) works from the first periods.
    workers : int
        Threads for the integration (NumPy releases the GIL in its loops). Results do not
        depend on it. Measured on a shared 2-core machine, two threads were *slower* than
        one below about 10^5 active trajectories (GIL hand-offs between the ~170 short
        NumPy calls per RK4 step), so the default is 1.

    Returns
    -------
    AttractorSearch
    """
    gamma, p, omega = _check_params(gamma, p, omega)
    tol, kmax, periods, rcap, steps = _check_search(tol, max_period, periods, capture_radius,
                                                    steps_per_period)
    t0 = check_finite("t0", t0)
    phi0, dphi0 = initial_conditions(phi0, dphi0)
    shape = phi0.shape
    entries, raw, used, end_th, end_v, stats = _run_search(
        phi_to_theta(phi0).ravel(), dphi0.ravel().copy(), gamma, p, omega, periods=periods,
        steps=steps, t0=t0, tol=tol, kmax=kmax, rcap=rcap,
        workers=_resolve_workers(workers), pilot=bool(pilot))
    labels, phase, attractors, legend = _finalize(entries, raw, used, end_th, end_v)
    return AttractorSearch(labels.reshape(shape), phase.reshape(shape), used.reshape(shape),
                           attractors, legend, gamma, p, omega, steps, periods, kmax, tol,
                           rcap, stats)
