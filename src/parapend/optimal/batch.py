r"""Many Fourier problems at once: the global search of :func:`.fourier.search_fourier` over a
run of points, with the array work of every Newton iteration done for all points together.

A design map (:mod:`parapend.maps`) solves the same N-harmonic problem (Eqs. 10-11) at many
points that differ only in the numbers ``omega``, ``delta`` and ``gamma``. Point by point,
one Newton iteration at N = 24 is a few dozen small NumPy calls (two FFTs of 256 points, a
sine and a cosine, the Hessian read off the FFT tables) whose cost is mostly the call, not
the arithmetic. Here the iterations of all the points of a run go in lockstep: one FFT of a
``(points, M)`` array, one sine, one gather of the Hessians, one batched line-search
evaluation; only the Cholesky factorization and the scalar decisions of the safeguarded
Newton method stay per point.

Bit for bit. Every point follows exactly the arithmetic of
:func:`.fourier.newton_maximize` and :func:`.fourier.search_fourier`: the same seeds, the
same decisions in the same order, the same floating-point operations on the same numbers.
The batched operations are elementwise, or reductions and FFTs along the last (contiguous)
axis, which NumPy computes row by row with the 1-D algorithm (pairwise summation,
pocketfft on each row); the complex products in the synthesis are exact (times 0, 1 or a
power of two). Scalars (powers, kinetic terms, dot products) are computed per point with
the same Python expressions. ``tests/test_sweep.py`` checks every run of the search (``x``,
power, status, iterations, strictness) for equality with ``search_fourier``, and
``benchmarks/bench_sweep.py`` checks every point of its map against ``parapend.optimize``.

Scope: winding 1, dense Hessian, the default seeds (limit and uniform), and excitations with
a single half-turn direction pattern (two extrema per period: the harmonic excitation, and
any other whose ``q`` has one maximum and one minimum). Points outside it (several patterns:
the pattern seeds and the bar that prunes them run one after the other) are handed to
``search_fourier`` itself.
"""

from __future__ import annotations

import math

import numpy as np

from .fourier import (
    _ABANDON_SAFETY,
    _UNIFORM_HARMONICS,
    FourierProblem,
    FourierSearch,
    LocalSolution,
    SearchEvidence,
    _ascent_step,
    _best,
    _is_maximum,
    _pad,
    _problem_points,
    _uniform_seed,
    newton_maximize,
    search_fourier,
    second_maximum,
)
from .limit import limit, pattern_count

__all__ = ["ProblemBatch", "newton_maximize_batch", "search_fourier_batch"]


class ProblemBatch:
    """:class:`.fourier.FourierProblem` objects with one N and one grid M, evaluated together.

    ``power`` and ``evaluate`` take member indices and a ``(len(rows), 2N+1)`` array of
    coefficients and return, per member, what the member's own ``power``/``evaluate`` return.
    """

    def __init__(self, problems):
        p0 = problems[0]
        for p in problems:
            if (p.harmonics, p.points, p.winding, p.hessian) != (p0.harmonics, p0.points, 1,
                                                                 "dense"):
                raise ValueError("ProblemBatch: every problem needs the same N and M, winding "
                                 "1 and the dense Hessian")
        self.problems = list(problems)
        self.harmonics, self.points = p0.harmonics, p0.points
        self._ks, self._k0, self._k2 = p0._ks, p0._k0, p0._k2
        self._idx, self._coef = p0._idx, p0._coef
        self._diag = np.arange(2 * p0.harmonics + 1)
        self.w = np.stack([p.w for p in problems])
        # the scalars of FourierProblem.kinetic, .power and .evaluate, per member
        self.omega2 = [p.omega**2 for p in problems]
        self.gamma = [p.gamma for p in problems]
        self.gw = [p.gamma * p.omega**2 for p in problems]
        self.scale = [max(float(np.abs(p.w).max()), 1e-300) for p in problems]

    def _theta(self, x: np.ndarray) -> np.ndarray:
        n, m = self.harmonics, self.points
        c = np.zeros((x.shape[0], m // 2 + 1), dtype=complex)
        c[:, 1:n + 1] = (0.5 * m) * (x[:, n + 1:] - 1j * x[:, 1:n + 1])
        return self._ks + x[:, :1] + np.fft.irfft(c, m, axis=-1)

    def _dots(self, x: np.ndarray) -> list:
        k2 = self._k2
        return [float(np.dot(k2, r * r)) for r in x]

    def power(self, rows, x: np.ndarray) -> list:
        """``FourierProblem.power`` of member ``rows[j]`` at ``x[j]``, for every j."""
        means = np.mean(self.w[rows] * np.cos(self._theta(x)), axis=-1)
        k0 = self._k0
        return [float(mn) - self.gamma[i] * (self.omega2[i] * (k0 + 0.5 * dt))
                for i, mn, dt in zip(rows, means, self._dots(x))]

    def evaluate(self, rows, x: np.ndarray):
        """``FourierProblem.evaluate`` of every member: (list of P, gradients, Hessians)."""
        n, m = self.harmonics, self.points
        th = self._theta(x)
        w = self.w[rows]
        u = w * np.sin(th)
        v = w * np.cos(th)
        U = np.fft.rfft(u, axis=-1)[:, : n + 1] / m
        V = np.fft.rfft(v, axis=-1)[:, : 2 * n + 1] / m
        gw = [self.gw[i] for i in rows]
        k0 = self._k0
        p = [float(V[j, 0].real - gw[j] * (k0 + 0.5 * dt))
             for j, dt in enumerate(self._dots(x))]
        gwa = np.array(gw)[:, None]
        g = np.empty((len(rows), 2 * n + 1))
        g[:, 0] = -U[:, 0].real
        g[:, 1:n + 1] = U[:, 1:].imag
        g[:, n + 1:] = -U[:, 1:].real
        g -= gwa * self._k2 * x
        X = np.concatenate((V.real, -V.imag), axis=-1)
        # -(coef0 X[idx0] + coef1 X[idx1]) of FourierProblem.evaluate, in place: the
        # products are exact (coefficients 0, 1/2, 1), so the one rounding of the sum is the
        # same in any order
        h = np.take(X, self._idx[0], axis=1)
        h *= self._coef[0]
        t = np.take(X, self._idx[1], axis=1)
        t *= self._coef[1]
        h += t
        np.negative(h, out=h)
        h[:, self._diag, self._diag] -= gwa * self._k2
        return p, g, h


def newton_maximize_batch(batch: ProblemBatch, x0: np.ndarray, seeds, *, gtol: float = 1e-11,
                          maxiter: int = 200, max_step: float = 1.0,
                          abandon_below=None, certify: bool = True) -> list:
    """:func:`.fourier.newton_maximize` for every member of ``batch`` from ``x0[i]``.

    Returns one :class:`.fourier.LocalSolution` per member, equal to what
    ``newton_maximize(batch.problems[i], x0[i], seeds[i], ...)`` returns. The iterations
    run in lockstep: each round decides every active member's step (per member), then
    evaluates the line search's trial points of all members together, then the accepted
    points' gradients and Hessians together. ``certify=False`` leaves ``strict_maximum``
    False without factorizing the last Hessian (for runs whose ``x`` only is used).
    """
    size = len(batch.problems)
    x0 = np.array(x0, dtype=float)
    below = [-math.inf] * size if abandon_below is None else list(abandon_below)
    xs = [x0[i].copy() for i in range(size)]
    p, g, h = batch.evaluate(list(range(size)), x0)
    ps, gs, hs = list(p), [r.copy() for r in g], list(h)
    out: list = [None] * size

    def finish(i, status, it):
        gn = float(np.abs(gs[i]).max())
        out[i] = LocalSolution(xs[i], float(ps[i]), gn, it, status, seeds[i],
                               batch.points, certify and _is_maximum(hs[i]))

    active = list(range(size))
    for it in range(1, maxiter + 1):
        if not active:
            break
        search = []  # [member, d, slope, gn, t]
        for i in active:
            pi, gi, scale = ps[i], gs[i], batch.scale[i]
            if not math.isfinite(pi):
                finish(i, "nonfinite", it)
                continue
            gn = float(np.abs(gi).max())
            if gn <= gtol * scale:
                finish(i, "converged", it - 1)
                continue
            d, newton = _ascent_step(gi, hs[i])
            norm = float(np.abs(d).max())
            if below[i] > -math.inf and it > 1 and norm <= max_step and newton:
                gain = 0.5 * float(gi @ d)
                if pi + _ABANDON_SAFETY * gain < below[i] + 1e-10 * scale:
                    finish(i, "abandoned", it)
                    continue
            if norm > max_step:
                d *= max_step / norm
            slope = float(gi @ d)
            if slope <= 0:
                d, slope = gi / scale, float(gi @ gi) / scale
            if 0.5 * slope <= 1e-15 * scale and gn <= 1e-7 * scale:
                finish(i, "converged", it - 1)
                continue
            search.append([i, d, slope, gn, 1.0])
        accepted = []  # (member, x)
        for _ in range(40):
            if not search:
                break
            trial = [xs[e[0]] + e[4] * e[1] for e in search]
            pn = batch.power([e[0] for e in search], np.array(trial))
            left = []
            for e, xn, pv in zip(search, trial, pn):
                if pv >= ps[e[0]] + 1e-4 * e[4] * e[2]:
                    accepted.append((e[0], xn))
                else:
                    e[4] *= 0.5
                    left.append(e)
            search = left
        for e in search:  # no measurable increase: at a maximum up to rounding, or stalled
            i = e[0]
            finish(i, "converged" if e[3] <= 1e-7 * batch.scale[i] else "stalled", it)
        accepted.sort(key=lambda a: a[0])
        active = [i for i, _ in accepted]
        if active:
            for i, xn in accepted:
                xs[i] = xn
            p, g, h = batch.evaluate(active, np.array([xn for _, xn in accepted]))
            for j, i in enumerate(active):
                ps[i], gs[i], hs[i] = p[j], g[j].copy(), h[j]
    for i in active:
        finish(i, "max_iterations", maxiter)
    return out


def _problems(points, harmonics: int, grids=None) -> list:
    """``FourierProblem(excitation, harmonics, gamma, grid)`` for every point, with
    ``dq/dt`` on the grids of all points with the same M and spectrum length synthesized by
    one inverse FFT (row by row the numbers of ``Excitation.dq_grid``)."""
    ms = [_problem_points(harmonics, e, None if grids is None else grids[i], 1)
          for i, (e, _) in enumerate(points)]
    specs = [e.dq_spectrum() for e, _ in points]
    dq: list = [None] * len(points)
    for grp in _groups([(m, sp.size) for m, sp in zip(ms, specs)]):
        m, size = ms[grp[0]], specs[grp[0]].size
        kmax = min(size, (m + 1) // 2)
        x = np.zeros((len(grp), m // 2 + 1), dtype=complex)
        sp = np.array([specs[i] for i in grp])
        x[:, 0] = sp[:, 0].real * m
        x[:, 1:kmax] = sp[:, 1:kmax] * (m / 2.0)
        for i, w in zip(grp, np.fft.irfft(x, m, axis=-1)):
            dq[i] = w
    return [FourierProblem(e, harmonics, g, m, dq=w)
            for (e, g), m, w in zip(points, ms, dq)]


def _limit_seeds(lims, harmonics: int) -> np.ndarray:
    """``limit_seed(lim, harmonics).vector`` for every limit motion (winding 1, canonical
    directions): the samples of each motion, then one FFT of them all (row by row the
    numbers of :func:`.limit.limit_seed`)."""
    m = max(1024, 32 * harmonics)
    j = np.arange(m) + 0.5
    om = np.array([[lim.motion.omega] for lim in lims])
    period = np.array([[2 * math.pi / lim.motion.omega] for lim in lims])
    t = period * j / m
    s = om * t
    turns = np.floor(t / period)
    tm = t - turns * period
    cum = np.empty_like(t)
    for r, lim in enumerate(lims):
        mo = lim.motion
        steps = np.searchsorted(mo.switch_times, tm[r], side="right")
        cum[r] = np.concatenate(([0.0], np.cumsum(mo.directions)))[steps]
    start = np.array([[lim.motion.theta_start] for lim in lims])
    theta = start + math.pi * cum + 2 * math.pi * 1 * turns
    x = np.fft.rfft(theta - s, axis=-1) / m
    n = np.arange(1, harmonics + 1)
    c = 2 * x[:, 1:harmonics + 1] * np.exp(1j * n * math.pi / m)
    sigma = np.sinc(n / (harmonics + 1))
    out = np.empty((len(lims), 2 * harmonics + 1))
    out[:, 0] = x[:, 0].real
    out[:, 1:harmonics + 1] = -c.imag * sigma
    out[:, harmonics + 1:] = c.real * sigma
    return out


def _groups(keys):
    """Indices grouped by key, in order of first appearance."""
    out: dict = {}
    for i, k in enumerate(keys):
        out.setdefault(k, []).append(i)
    return list(out.values())


def search_fourier_batch(points, harmonics: int, *, gtol: float = 1e-11,
                         maxiter: int = 200, limits=None) -> list:
    """:func:`.fourier.search_fourier` ``(excitation, harmonics, gamma)`` for every
    ``(excitation, gamma)`` of ``points``, with the default seeds: one
    :class:`.fourier.FourierSearch` each, equal to search_fourier's (see the module text).

    ``limits``: the points' :func:`.limit.limit` results when the caller has them already.
    Returns also, per point, the N-harmonic :class:`FourierProblem` of its first grid (the
    problem of ``best`` when ``best.points`` equals its ``points``) as ``(search, problem)``.
    """
    npts = len(points)
    lims = list(limits) if limits is not None else [limit(e) for e, _ in points]
    out: list = [None] * npts
    batched = []
    for i, ((exc, gamma), lim) in enumerate(zip(points, lims)):
        if pattern_count(lim) > 1:  # pattern seeds, pruned one after the other
            out[i] = (search_fourier(exc, harmonics, gamma, gtol=gtol, maxiter=maxiter), None)
        else:
            batched.append(i)
    if not batched:
        return out
    sub = [points[i] for i in batched]
    problems = dict(zip(batched, _problems(sub, harmonics)))
    # uniform seed: the best uniform rotation, optimized first with 8 harmonics, then padded
    # (fourier._uniform_start)
    small_n = min(harmonics, _UNIFORM_HARMONICS)
    useed = {i: _uniform_seed(points[i][0], small_n, points[i][1]) for i in batched}
    if harmonics > _UNIFORM_HARMONICS:
        small = dict(zip(batched, _problems(sub, _UNIFORM_HARMONICS)))
        for grp in _groups([small[i].points for i in batched]):
            ids = [batched[j] for j in grp]
            runs = newton_maximize_batch(ProblemBatch([small[i] for i in ids]),
                                         np.array([useed[i] for i in ids]),
                                         ["uniform"] * len(ids), gtol=gtol, certify=False)
            for i, r in zip(ids, runs):
                useed[i] = _pad(r.x, harmonics)
    # the primary runs, limit then uniform, polished to convergence
    primary: dict = {}
    for grp in _groups([problems[i].points for i in batched]):
        ids = [batched[j] for j in grp]
        probs = [problems[i] for i in ids]
        x0 = [*_limit_seeds([lims[i] for i in ids], harmonics), *(useed[i] for i in ids)]
        runs = newton_maximize_batch(ProblemBatch(probs + probs), np.array(x0),
                                     ["limit"] * len(ids) + ["uniform"] * len(ids),
                                     gtol=gtol, maxiter=maxiter)
        for k, i in enumerate(ids):
            primary[i] = [runs[k], runs[len(ids) + k]]
    best = {i: _best(primary[i]) for i in batched}
    # grid refinement: the first check for all points together, the rare refinements alone
    fine = dict(zip(batched, _problems(sub, harmonics,
                                       [2 * problems[i].points for i in batched])))
    for grp in _groups([fine[i].points for i in batched]):
        ids = [batched[j] for j in grp]
        pf = ProblemBatch([fine[i] for i in ids]).power(list(range(len(ids))),
                                                        np.array([best[i].x for i in ids]))
        for i, v in zip(ids, pf):
            runs = primary[i]
            b = best[i]
            if abs(v - b.power) > 1e-14 * max(1.0, abs(b.power)):
                problem = fine[i]
                b = newton_maximize(problem, b.x, b.seed, gtol=gtol, maxiter=maxiter)
                runs.append(b)
                for _ in range(7):
                    f = FourierProblem(points[i][0], harmonics, points[i][1],
                                       2 * problem.points)
                    if abs(f.power(b.x) - b.power) <= 1e-14 * max(1.0, abs(b.power)):
                        break
                    problem = f
                    b = newton_maximize(problem, b.x, b.seed, gtol=gtol, maxiter=maxiter)
                    runs.append(b)
            exc, gamma = points[i]
            lim = lims[i]
            second, dist = second_maximum(runs, b)
            evidence = SearchEvidence(
                strategy="exhaustive", candidate_patterns=pattern_count(lim),
                patterns_tried=1, polished=sum(r.status == "converged" for r in runs),
                abandoned=sum(r.status == "abandoned" for r in runs),
                second_power=second, second_distance=dist,
                upper_bound=lim.power - gamma * exc.omega**2, screen_harmonics=None)
            out[i] = (FourierSearch(b, runs, evidence), problems[i])
    return out
