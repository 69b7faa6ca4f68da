r"""Truncated Fourier-series optimization of the period-1 rotation (paper Eqs. 10-11, 15).

Unknowns ``x = [a0, a_1..a_N, b_1..b_N]`` of Eq. 10, ``s = omega t``::

    theta(s) = s + a0 + sum_n a_n sin(n s) + b_n cos(n s)

Objective (maximized; extracted power, Eq. 15 integrated by parts)::

    P(x) = <q'(t) cos(theta)> - gamma * omega^2 * (1 + sum_n n^2 (a_n^2 + b_n^2) / 2)

The first mean is a periodic integral, evaluated on ``M`` uniform points (spectrally
accurate; ``q'`` is band-limited to the grid). With ``u = q' sin(theta)``,
``v = q' cos(theta)`` and their FFT means ``U_m = <u e^{-ims}>``, ``V_m``, the exact
gradient and Hessian are read off the FFTs::

    dP/da0 = -Re U_0        dP/da_n = Im U_n         dP/db_n = -Re U_n
    d2F/dx_i dx_k = -<v phi_i phi_k>,  phi = (1, sin ns, cos ns)

and products of trigonometric functions become sums of ``V`` at ``n +- k`` (index tables
built once per N). One Newton iteration for N = 40 costs two FFTs of a few hundred points
and an 81 x 81 Cholesky factorization.

Globalization (DESIGN.md section 5; docs/global.md). ``P`` is not concave, and the
uniform rotation is a stationary point for N = 1, so a local solver started there can stop
at a saddle. The solver here is a safeguarded Newton method that takes the Newton step when
``-H`` is positive definite and otherwise a shifted Newton step or the most positive
curvature direction (escaping saddles), with a backtracking line search that never
decreases ``P``. :func:`search_fourier` starts it from several seeds and keeps the best
local maximum:

- ``warm``: a previous solution (continuation in N or in gamma), padded with zeros;
- ``limit``: the gamma -> 0 piecewise-constant motion (:mod:`.limit`), projected onto N
  harmonics with Lanczos smoothing;
- ``uniform``: the best uniform rotation (Eq. 17), optimized first with 8 harmonics and
  then padded (continuation in N; see ``_uniform_start``);
- every other half-turn direction pattern of the limit motion (``limit-1``, ...) when there
  are at most ENUMERATE_MAX, else seeds from the dynamic programme of :mod:`.dynprog`
  (``dp-1``, ...), a seeded sample and, at gamma = 0, swaps (``swap-1``, ...). These runs
  are abandoned once their quadratic model cannot beat the best power so far.

The result records which seed gave the optimum (``found_by``), every run, and the evidence
(:class:`SearchEvidence`). The grid size ``M`` is doubled until the power changes by less
than 1e-14 between grids.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.linalg import eigh
from scipy.linalg.lapack import dpotrf, dpotrs

from ..power import uniform_power
from .limit import all_patterns, direction_patterns, limit, limit_seed, pattern_count

__all__ = ["FourierProblem", "FourierSearch", "LocalSolution", "SearchEvidence",
           "search_fourier", "solve_fourier"]


def _grid_size(harmonics: int, excitation) -> int:
    """Initial quadrature grid: a power of two with at least 8 points per top harmonic."""
    k = max(harmonics, min(excitation.spectrum.size - 1, 4 * harmonics))
    return max(64, 1 << int(math.ceil(math.log2(8 * (k + 1)))))


def _problem_points(harmonics: int, excitation, points: int | None, winding: int) -> int:
    """The grid M of :class:`FourierProblem`: ``points`` (or the initial grid), doubled until
    it holds 8 points per harmonic and turn."""
    m = points or _grid_size(harmonics, excitation)
    while m < 8 * harmonics + 8 * winding:
        m *= 2
    return m


@lru_cache(maxsize=64)
def _hessian_tables(n: int):
    """Index tables so that <v phi_i phi_k> = sum_j coef_j * X[idx_j] with X = [C | S]."""
    size = 2 * n + 1
    off = 2 * n + 1  # S_m stored at off + m
    idx = np.zeros((4, size, size), dtype=int)
    coef = np.zeros((4, size, size))
    kk = np.arange(1, n + 1)
    ia = kk  # positions of a_n
    ib = kk + n  # positions of b_n
    # (0,0): C_0
    idx[0, 0, 0], coef[0, 0, 0] = 0, 1.0
    # (0, a_n): S_n ; (0, b_n): C_n
    idx[0, 0, ia], coef[0, 0, ia] = off + kk, 1.0
    idx[0, ia, 0], coef[0, ia, 0] = off + kk, 1.0
    idx[0, 0, ib], coef[0, 0, ib] = kk, 1.0
    idx[0, ib, 0], coef[0, ib, 0] = kk, 1.0
    nn, mm = np.meshgrid(kk, kk, indexing="ij")
    d, s_ = np.abs(nn - mm), nn + mm
    sg = np.sign(nn - mm)
    A = np.ix_(ia, ia)
    B = np.ix_(ib, ib)
    AB = np.ix_(ia, ib)
    BA = np.ix_(ib, ia)
    # a-a: (C_{n-k} - C_{n+k})/2 ; b-b: (C_{n-k} + C_{n+k})/2
    idx[0][A], coef[0][A] = d, 0.5
    idx[1][A], coef[1][A] = s_, -0.5
    idx[0][B], coef[0][B] = d, 0.5
    idx[1][B], coef[1][B] = s_, 0.5
    # a_n-b_k: <v sin ns cos ks> = (S_{n+k} + S_{n-k})/2, S_{-j} = -S_j
    idx[0][AB], coef[0][AB] = off + s_, 0.5
    idx[1][AB], coef[1][AB] = off + d, 0.5 * sg
    idx[0][BA], coef[0][BA] = off + s_.T, 0.5
    idx[1][BA], coef[1][BA] = off + d.T, 0.5 * sg.T
    idx, coef = idx[:2], coef[:2]
    idx.flags.writeable = False
    coef.flags.writeable = False
    return idx, coef


#: Kinds of Hessian: the dense (2N+1)^2 matrix read off the FFT tables (Cholesky), or the
#: matrix-free operator (two FFTs per product, truncated conjugate gradients).
HESSIANS = ("dense", "operator")


class FourierProblem:
    """Objective, exact gradient and Hessian of the N-harmonic problem on an M-point grid.

    Parameters
    ----------
    excitation : Excitation
    harmonics : int
        N >= 1.
    gamma : float
        Viscous damping >= 0 (Eq. 14).
    points : int, optional
        Quadrature points M (power of two, > 4N); chosen from N and the excitation if None.
    winding : int, optional
        K, turns per period of ``q``: ``theta = K s + a0 + sum ...`` (Eq. 10 with K in place
        of 1; K = 1 is the paper's period-1 rotation and computes exactly as before).
    hessian : {"dense", "operator"}
        ``"dense"``: :meth:`evaluate` returns the (2N+1) x (2N+1) Hessian (O(N^2) memory,
        O(N^3) per Newton step). ``"operator"``: it returns a :class:`HessianOperator` whose
        product costs two FFTs of M points (records of irregular seas: N in the thousands).
    dq : ndarray, optional
        ``excitation.dq_grid(M)``, when the caller has it (the same numbers).
    """

    def __init__(self, excitation, harmonics: int, gamma: float, points: int | None = None,
                 winding: int = 1, hessian: str = "dense", dq: np.ndarray | None = None):
        if hessian not in HESSIANS:
            raise ValueError(f"hessian: expected one of {HESSIANS}, got {hessian!r}")
        self.excitation = excitation
        self.omega = excitation.omega
        self.harmonics = n = harmonics
        self.gamma = gamma
        self.winding = int(winding)
        self.hessian = hessian
        self.points = m = _problem_points(n, excitation, points, self.winding)
        self.s = 2 * np.pi * np.arange(m) / m
        # K s of theta = K s + periodic part (the same array, not a product, when K = 1)
        self._ks = self.s if self.winding == 1 else self.winding * self.s
        self._k0 = 1.0 if self.winding == 1 else float(self.winding) ** 2
        # dq: excitation.dq_grid(m) computed by the caller (optimal/batch.py: one inverse FFT
        # for many excitations, the same numbers)
        self.w = excitation.dq_grid(m) if dq is None else dq
        k = np.arange(1, n + 1)
        self._k2 = np.concatenate(([0.0], k * k, k * k)).astype(float)
        if hessian == "dense":
            self._idx, self._coef = _hessian_tables(n)

    # ------------------------------------------------------------------------------------
    def theta(self, x: np.ndarray) -> np.ndarray:
        """``theta`` on the grid, by one inverse real FFT of the coefficients."""
        n, m = self.harmonics, self.points
        c = np.zeros(m // 2 + 1, dtype=complex)
        c[1:n + 1] = (0.5 * m) * (x[n + 1:] - 1j * x[1:n + 1])  # Re((b - ia) e^{ins})
        return self._ks + x[0] + np.fft.irfft(c, m)

    def kinetic(self, x: np.ndarray) -> float:
        """``<theta'^2> = omega^2 (K^2 + sum n^2 (a_n^2 + b_n^2) / 2)`` (exact, Parseval)."""
        return self.omega**2 * (self._k0 + 0.5 * float(np.dot(self._k2, x * x)))

    def power(self, x: np.ndarray) -> float:
        """Objective ``P(x)`` only."""
        return float(np.mean(self.w * np.cos(self.theta(x)))) - self.gamma * self.kinetic(x)

    def evaluate(self, x: np.ndarray):
        """Return ``(P, gradient, Hessian)`` at ``x`` (exact to quadrature accuracy).

        The Hessian is an ndarray (``hessian="dense"``) or a :class:`HessianOperator`.
        """
        n, m = self.harmonics, self.points
        th = self.theta(x)
        sn, cs = np.sin(th), np.cos(th)
        u = self.w * sn
        v = self.w * cs
        U = np.fft.rfft(u)[: n + 1] / m
        V = np.fft.rfft(v)[: 2 * n + 1] / m
        gw = self.gamma * self.omega**2
        p = V[0].real - gw * (self._k0 + 0.5 * float(np.dot(self._k2, x * x)))
        g = np.empty(2 * n + 1)
        g[0] = -U[0].real
        g[1:n + 1] = U[1:].imag
        g[n + 1:] = -U[1:].real
        g -= gw * self._k2 * x
        if self.hessian == "operator":
            return float(p), g, HessianOperator(self, v, V, gw)
        X = np.concatenate((V.real, -V.imag))
        h = -(self._coef[0] * X[self._idx[0]] + self._coef[1] * X[self._idx[1]])
        h.flat[:: h.shape[0] + 1] -= gw * self._k2
        return float(p), g, h


class HessianOperator:
    """The Hessian of ``P`` as an operator: ``H d = -P_N(v * Phi d) - gamma omega^2 k^2 d``.

    ``v = q' cos(theta)`` on the grid, ``Phi d`` the trigonometric polynomial with
    coefficients ``d`` (one inverse FFT) and ``P_N`` the projection on the N harmonics (one
    FFT): the same matrix as the dense Hessian, ``-<v phi_i phi_k>`` plus the diagonal
    damping term, applied in O(M log M) without forming it.
    """

    def __init__(self, problem: FourierProblem, v: np.ndarray, V: np.ndarray, gw: float):
        self.problem = problem
        self.v = v
        self.gw = gw
        n = problem.harmonics
        k2 = problem._k2
        # diagonal of -H: <v> for a0, <v sin^2 ns> = (V0 - Re V_2n)/2, <v cos^2 ns> = (V0 +
        # Re V_2n)/2
        d = np.empty(2 * n + 1)
        d[0] = V[0].real
        v2 = V[2:2 * n + 1:2].real
        d[1:n + 1] = 0.5 * (V[0].real - v2)
        d[n + 1:] = 0.5 * (V[0].real + v2)
        self.diagonal = d + gw * k2  # of -H
        self._lu = None
        av = np.abs(v)
        # the banded preconditioner replaces v by |v|: good where v is mostly positive (near
        # a maximum, v = q' cos(theta) ~ |q'|), poor far from one
        self.mostly_positive = float(np.sum(av[v < 0])) <= BANDED_NEGATIVE * float(np.sum(av))

    def matvec(self, d: np.ndarray) -> np.ndarray:
        """``H d`` (Hessian of P times d): two real FFTs."""
        pr = self.problem
        n, m = pr.harmonics, pr.points
        c = np.zeros(m // 2 + 1, dtype=complex)
        c[0] = m * d[0]
        c[1:n + 1] = (0.5 * m) * (d[n + 1:] - 1j * d[1:n + 1])
        f = self.v * np.fft.irfft(c, m)
        G = np.fft.rfft(f)[: n + 1] / m
        out = np.empty(2 * n + 1)
        out[0] = G[0].real
        out[1:n + 1] = -G[1:].imag
        out[n + 1:] = G[1:].real
        return -out - self.gw * pr._k2 * d

    def precondition(self, r: np.ndarray) -> np.ndarray:
        """Approximate ``(-H)^{-1} r`` by a banded solve in time.

        In function space ``-H`` is ``L = v + 2 gamma omega^2 (-d^2/ds^2)`` between the
        synthesis ``Phi`` and the projection ``Phi^T <.>`` (Gram matrix
        ``G = diag(1, 1/2, ..)``). The preconditioner replaces ``v`` by ``|v| + mu`` and the
        second derivative by its three-point difference on the M-point grid (within 5 % of
        ``n^2`` up to ``n = N``, as ``M >= 8N``), and solves that cyclic tridiagonal system
        exactly: ``G^{-1} Phi^T <L~^{-1} Phi G^{-1} r>``, symmetric positive definite.
        """
        pr = self.problem
        n, m = pr.harmonics, pr.points
        if self._lu is None:
            from scipy.sparse import diags
            from scipy.sparse.linalg import splu

            ds = 2 * math.pi / m
            c = 2.0 * self.gw / ds**2
            av = np.abs(self.v)
            mu = 1e-2 * float(np.mean(av)) + 1e-300
            a = diags([np.full(m - 1, -c), av + mu + 2 * c, np.full(m - 1, -c),
                       [-c], [-c]], [-1, 0, 1, m - 1, -(m - 1)], shape=(m, m), format="csc")
            self._lu = splu(a)
        c = np.zeros(m // 2 + 1, dtype=complex)
        c[0] = m * r[0]
        c[1:n + 1] = m * (r[n + 1:] - 1j * r[1:n + 1])  # G^{-1}: twice the coefficients
        f = self._lu.solve(np.fft.irfft(c, m))
        F = np.fft.rfft(f)[: n + 1] / m
        out = np.empty(2 * n + 1)
        out[0] = F[0].real
        out[1:n + 1] = -2.0 * F[1:].imag
        out[n + 1:] = 2.0 * F[1:].real
        return out

    def dense(self) -> np.ndarray:
        """The full matrix (tests only: O(N^2) memory)."""
        e = np.eye(self.diagonal.size)
        return np.column_stack([self.matvec(c) for c in e])


#: The banded preconditioner is used when at most this fraction of ``int |v|`` has ``v < 0``.
BANDED_NEGATIVE = 0.05
#: Truncated conjugate gradients of the operator Newton step: at most this many iterations.
CG_MAXITER = 400


def _cg_ascent_step(g: np.ndarray, op: HessianOperator, scale: float, saddle: bool = True):
    """Newton-CG step for ``-H d = g``, preconditioned (:data:`PRECONDITIONER`).

    Truncated CG (Steihaug's rule without a radius; the caller caps the step and
    backtracks): the relative residual is brought below ``min(0.5, sqrt(|g|/scale))``
    (superlinear convergence), but never below 1e-4; if a direction of non-positive
    curvature of ``-H`` appears, CG stops with the iterate so far (or, at the first
    iteration, that direction, which is an ascent direction). Returns ``(d, newton)``:
    ``newton`` is True when CG converged with positive curvature throughout (``-H``
    positive definite on the Krylov space).
    At a saddle (no Newton step and a negligible gradient), the step follows the most
    positive curvature of P, found by Lanczos (:func:`scipy.sparse.linalg.eigsh`), unless
    ``saddle`` is False.
    """
    pre = np.abs(op.diagonal)
    pre = np.maximum(pre, 1e-3 * float(np.max(pre)) + 1e-300)
    gn = float(np.linalg.norm(g))
    d, newton = _cg_solve(g, op, pre, gn, scale)
    # a saddle: no Newton step and a negligible gradient (Lanczos only then: it costs
    # hundreds of products, and near a maximum CG needs a few tens)
    if saddle and not newton and float(np.max(np.abs(g))) <= 1e-8 * max(float(np.max(pre)),
                                                                         1e-12):
        from scipy.sparse.linalg import ArpackNoConvergence, LinearOperator, eigsh

        size = g.size
        a = LinearOperator((size, size), matvec=lambda z: -op.matvec(np.ravel(z)),
                           dtype=float)
        try:
            lam, vec = eigsh(a, k=1, which="SA", tol=1e-6, maxiter=20 * size,
                             v0=np.ones(size))
        except ArpackNoConvergence:  # no direction found (a take-off's kink, its clusters
            return d, newton  # of eigenvalues): the conjugate gradients' step
        if lam[0] < 0:
            e = vec[:, 0]
            return e * (1.0 if g @ e >= 0 else -1.0) * 0.5, False
    return d, newton


#: Preconditioner of the operator Newton-CG: "diagonal" (the exact diagonal of -H) or
#: "banded" (time-domain tridiagonal solve, :meth:`HessianOperator.precondition`). Measured
#: on a 20-wave record from the limit seed (bench_sea.py --kernels): banded needs 22 Hessian
#: products at every N from 256 to 4096, diagonal 67 to 90, but diagonal is faster up to
#: N = 4096 (0.31 s against 1.02 s; the sparse LU of each Newton step dominates).
PRECONDITIONER = "diagonal"


def _cg_solve(g, op, pre, gn, scale):
    # forcing term: superlinear while |g| is large, never below 1e-4 (below it CG only
    # stagnates at rounding, hundreds of products per step for nothing; the outer Newton
    # iteration still gains four digits per step)
    target = max(1e-4, min(0.5, math.sqrt(gn / scale))) * gn
    x = np.zeros_like(g)
    r = g.copy()
    # an operator may carry a preconditioner of its own (``low_rank``: the hull take-off's
    # smoothed kink, :class:`parapend.hydro._hull_krylov.KrylovHessian`), None where it has
    # none at this point
    own = getattr(op, "low_rank", None)
    own = own() if own is not None else None
    if own is not None:
        apply = own
    elif PRECONDITIONER == "banded" and op.mostly_positive:
        def apply(v):
            return op.precondition(v)
    else:
        def apply(v):
            return v / pre
    z = apply(r)
    p = z.copy()
    rz = float(r @ z)
    for it in range(CG_MAXITER):
        ap = -op.matvec(p)
        curv = float(p @ ap)
        if curv <= 1e-14 * float(p @ p) * float(np.max(pre)):
            return (p if it == 0 else x), False
        alpha = rz / curv
        x += alpha * p
        r -= alpha * ap
        if float(np.linalg.norm(r)) <= target:
            return x, True
        z = apply(r)
        rz_new = float(r @ z)
        p = z + (rz_new / rz) * p
        rz = rz_new
    return x, False


@dataclass(frozen=True)
class LocalSolution:
    """Outcome of one Newton run from one seed."""

    x: np.ndarray
    power: float
    gradient_norm: float
    iterations: int
    status: str
    seed: str
    points: int = 0
    strict_maximum: bool = False  # -H positive definite at the solution


def _cholesky_solve(a: np.ndarray, g: np.ndarray) -> np.ndarray | None:
    """Solve ``a p = g`` by Cholesky (LAPACK potrf/potrs); None if ``a`` is not positive definite.

    Called directly: for these small systems the wrappers' checks cost more than the work.
    """
    c, info = dpotrf(a, lower=0, clean=0, overwrite_a=0)
    if info != 0:
        return None
    p, info = dpotrs(c, g, lower=0)
    return p if info == 0 else None


def _ascent_step(g: np.ndarray, h: np.ndarray) -> tuple[np.ndarray, bool]:
    """Ascent step, and whether it is a Newton step (``-H`` positive definite).

    Newton where ``-H`` is positive definite, else a shifted Newton step:

    ``-H + mu I`` is factorized with ``mu`` raised until Cholesky succeeds (Nocedal & Wright,
    Alg. 3.3). Where the gradient is negligible but ``-H`` is indefinite (a saddle such as
    the uniform rotation), the step follows the eigenvector of the most positive curvature
    of ``P`` instead, since a gradient-based step would not move.
    """
    a = -h
    p = _cholesky_solve(a, g)
    if p is not None:
        return p, True
    scale = max(float(np.max(np.abs(np.diag(a)))), 1e-12)
    if float(np.max(np.abs(g))) <= 1e-8 * scale:
        # at (or very near) a saddle: a unit step along the most positive curvature of P;
        # the caller caps its length and backtracks, and P rises quadratically along it
        lam, vec = eigh(a, check_finite=False)
        d = vec[:, 0]
        return d * (1.0 if g @ d >= 0 else -1.0) * (0.5 if lam[0] < 0 else 0.0), False
    mu = 1e-3 * scale
    eye = np.eye(a.shape[0])
    while True:
        p = _cholesky_solve(a + mu * eye, g)
        if p is not None:
            return p, False
        mu *= 4.0


def _is_maximum(h: np.ndarray) -> bool:
    """True when ``-H`` is positive definite (a strict local maximum)."""
    return dpotrf(-h, lower=0, clean=0)[1] == 0


def newton_maximize(problem: FourierProblem, x0: np.ndarray, seed: str, *,
                    gtol: float = 1e-11, maxiter: int = 200, max_step: float = 1.0,
                    abandon_below: float = -math.inf, saddle: bool = True) -> LocalSolution:
    """Safeguarded Newton ascent with backtracking; never lowers ``P``.

    Stops when the gradient's max-norm is below ``gtol`` times the excitation scale, when
    no step increases ``P`` above rounding (stalled), or after ``maxiter`` iterations.

    ``abandon_below`` prunes a run that cannot win (status ``"abandoned"``): once the
    iterate is in the concave region (``-H`` positive definite, uncapped Newton step), the
    quadratic model predicts the remaining increase ``g^T (-H)^{-1} g / 2``; when even
    ``_ABANDON_SAFETY`` times that cannot lift ``P`` above ``abandon_below`` (the best power
    found so far) by more than 1e-10 of the excitation scale, the run stops: it leads to a
    lower maximum or to the same one again. Near a maximum Newton converges quadratically,
    so the model's prediction is accurate to its own square there.

    ``saddle``: with an operator Hessian, leave a saddle along its most positive curvature
    (Lanczos: hundreds of products); False where the objective's curvature is a smoothed
    kink's (a take-off's efficiency), whose huge diagonal makes every small gradient look
    like a saddle's, and the conjugate gradients' step serves.
    """
    x = np.array(x0, dtype=float)
    scale = max(float(np.max(np.abs(problem.w))), 1e-300)
    p, g, h = problem.evaluate(x)
    status = "max_iterations"
    operator = isinstance(h, HessianOperator)
    newton = False
    it = 0
    for it in range(1, maxiter + 1):
        if not math.isfinite(p):
            status = "nonfinite"
            break
        gn = float(np.max(np.abs(g)))
        if gn <= gtol * scale:
            status = "converged"
            it -= 1
            break
        d, newton = (_cg_ascent_step(g, h, scale, saddle) if operator
                     else _ascent_step(g, h))
        norm = float(np.max(np.abs(d)))
        if abandon_below > -math.inf and it > 1 and norm <= max_step and newton:
            gain = 0.5 * float(g @ d)
            if p + _ABANDON_SAFETY * gain < abandon_below + 1e-10 * scale:
                status = "abandoned"
                break
        if norm > max_step:
            d *= max_step / norm
        slope = float(g @ d)
        if slope <= 0:
            d, slope = g / scale, float(g @ g) / scale
        if 0.5 * slope <= 1e-15 * scale and gn <= 1e-7 * scale:
            # predicted increase below rounding of P: converged to working precision
            status = "converged"
            it -= 1
            break
        t = 1.0
        accepted = False
        for _ in range(40):
            xn = x + t * d
            pn = problem.power(xn)
            if pn >= p + 1e-4 * t * slope:
                accepted = True
                break
            t *= 0.5
        if not accepted:
            # no measurable increase: at a maximum up to rounding, or stalled
            status = "converged" if gn <= 1e-7 * scale else "stalled"
            break
        if t < 1.0 and pn - p <= _ROUNDING * abs(p) and gn <= 1e-7 * scale:
            # a backtracked step "accepted" at rounding's level (P unchanged): the gradient
            # is at its rounding floor above gtol, and each further iteration would cost a
            # Hessian solve and a 40-step line search for nothing
            status = "converged"
            it -= 1
            break
        x = xn
        p, g, h = problem.evaluate(x)
    gn = float(np.max(np.abs(g)))
    # operator Hessian: -H was positive definite on the last step's Krylov space (no O(N^3)
    # factorization to certify it on the whole space)
    strict = newton if operator else _is_maximum(h)
    return LocalSolution(x, float(p), gn, it, status, seed, problem.points, strict)


_ABANDON_SAFETY = 4.0
#: a line search's increase of ``P`` below this (relative) is rounding, not progress
_ROUNDING = 1e-14


def _uniform_seed(excitation, harmonics: int, gamma: float, winding: int = 1) -> np.ndarray:
    _, phi = (uniform_power(excitation, gamma) if winding == 1
              else uniform_power(excitation, gamma, winding))
    x = np.zeros(2 * harmonics + 1)
    x[0] = phi
    return x


_UNIFORM_HARMONICS = 8


def _uniform_start(excitation, harmonics: int, gamma: float, gtol: float) -> np.ndarray:
    """The best uniform rotation, first optimized with at most 8 harmonics, then padded.

    Continuation in N: from the uniform rotation a Newton run with many harmonics creeps
    along a long, nearly flat valley (hundreds of iterations at N = 256, and at N = 40 it can
    stop on a lower local maximum); with 8 harmonics it converges in a few steps, and the
    padded result starts the N-harmonic run with that power already reached.
    """
    x = _uniform_seed(excitation, min(harmonics, _UNIFORM_HARMONICS), gamma)
    if harmonics <= _UNIFORM_HARMONICS:
        return x
    small = FourierProblem(excitation, _UNIFORM_HARMONICS, gamma)
    return _pad(newton_maximize(small, x, "uniform", gtol=gtol).x, harmonics)


def _pad(x: np.ndarray, harmonics: int) -> np.ndarray:
    """Embed a packed vector with fewer (or more) harmonics into ``harmonics`` terms."""
    n0 = (x.size - 1) // 2
    out = np.zeros(2 * harmonics + 1)
    k = min(n0, harmonics)
    out[0] = x[0]
    out[1:k + 1] = x[1:k + 1]
    out[harmonics + 1:harmonics + 1 + k] = x[n0 + 1:n0 + 1 + k]
    return out


def _best(runs):
    """Highest power; a converged run wins over an unconverged one within rounding."""
    finite = [r for r in runs if math.isfinite(r.power) and r.status != "abandoned"] or runs
    top = max(finite, key=lambda r: r.power)
    conv = [r for r in finite if r.status == "converged"]
    if conv:
        c = max(conv, key=lambda r: r.power)
        if c.power >= top.power - 1e-13 * max(1.0, abs(top.power)):
            return c
    return top


#: Direction patterns are enumerated exhaustively up to this count (12 extrema per period
#: give C(12, 5) = 792); beyond it the dynamic programme of :mod:`.dynprog` proposes them.
ENUMERATE_MAX = 1024
#: Patterns proposed by the dynamic programme (and by seeded sampling) beyond ENUMERATE_MAX.
PROPOSE_COUNT = 16


@dataclass(frozen=True)
class SearchEvidence:
    """How the optimum was found, and how far it can be from the best possible.

    Attributes
    ----------
    strategy : str
        ``"exhaustive"`` (every half-turn direction pattern of the limit motion was a seed),
        ``"dynamic-programme"`` (too many patterns: candidates from the (t, theta) dynamic
        programme plus a seeded sample), or ``"local"`` (only the given seeds).
    candidate_patterns : int
        Number of half-turn direction patterns, ``C(2m, m - 1)`` for ``2m`` extrema.
    patterns_tried : int
        Seeds started from a pattern (or a dynamic-programme path).
    polished : int
        Runs carried to convergence.
    abandoned : int
        Runs stopped early because their quadratic model could not reach the best power.
    second_power : float or None
        Best other distinct local maximum among the runs polished to convergence
        (:func:`second_maximum`); runs abandoned as unable to win are not polished, so a
        better other maximum may exist (it is a lower bound of the second-best maximum).
    second_distance : float or None
        RMS distance over one period between that maximum's motion and the optimum's, rad.
    upper_bound : float
        ``limit - gamma omega^2``: every rotation has ``<theta'^2> >= omega^2``.
    screen_harmonics : int or None
        N at which the patterns were compared before the best few were polished at the
        full N (None: compared at the full N).
    """

    strategy: str
    candidate_patterns: int
    patterns_tried: int
    polished: int
    abandoned: int
    second_power: float | None
    upper_bound: float
    screen_harmonics: int | None = None
    second_distance: float | None = None


#: two converged runs whose motions differ by at most this RMS angle (rad) are the same
#: local maximum (Newton converges to gtol 1e-11; the optimum before and after a grid
#: refinement differs by about 1e-10)
DISTINCT_RMS = 1e-6


def motion_distance(x: np.ndarray, y: np.ndarray) -> float:
    """RMS over one period of the difference of two motions given by packed coefficients
    ``[a0, a_1..a_N, b_1..b_N]`` (Parseval: ``sqrt(da0^2 + sum(da_k^2 + db_k^2) / 2)``),
    ``da0`` taken modulo 2 pi (a motion and its copy a turn further are the same)."""
    d = np.asarray(x, dtype=float) - np.asarray(y, dtype=float)
    d0 = math.remainder(float(d[0]), 2 * math.pi)
    return float(math.sqrt(d0**2 + 0.5 * float(np.sum(d[1:] ** 2))))


def second_maximum(runs, best) -> tuple[float | None, float | None]:
    """``(power, distance)`` of the best converged run whose motion is distinct from
    ``best`` (RMS distance above :data:`DISTINCT_RMS`), or ``(None, None)``. Only runs
    polished to convergence count: abandoned runs never reached their maximum."""
    out = (None, None)
    for r in runs:
        if r.status != "converged" or not math.isfinite(r.power) or r.x.size != best.x.size:
            continue
        dist = motion_distance(r.x, best.x)
        if dist > DISTINCT_RMS and (out[0] is None or r.power > out[0]):
            out = (float(r.power), dist)
    return out


@dataclass(frozen=True)
class FourierSearch:
    """Outcome of :func:`search_fourier`: the best local maximum, every run, the evidence."""

    best: LocalSolution
    runs: list
    evidence: SearchEvidence


def _seeds(excitation, lim, harmonics: int, gamma: float, warm, seeds, gtol: float):
    """Primary seeds (polished to convergence): warm start, canonical limit, uniform.

    Winding K != 1: the uniform rotation ``K s + phi`` is padded without the 8-harmonic
    continuation (8 harmonics cannot describe a motion with K > 8 turns per period).
    """
    out = []
    if warm is not None:
        out.append(("warm", _pad(np.asarray(warm, dtype=float), harmonics)))
    for name in seeds:
        if name == "limit":
            out.append(("limit", limit_seed(lim, harmonics).vector))
        elif name == "uniform" and lim.winding != 1:
            out.append(("uniform", _uniform_seed(excitation, harmonics, gamma, lim.winding)))
        elif name == "uniform":
            out.append(("uniform", _uniform_start(excitation, harmonics, gamma, gtol)))
        else:
            raise ValueError(f"seeds: unknown seed {name!r}")
    return out


def _pattern_seeds(excitation, lim, harmonics: int, gamma: float,
                   propose: int = None):
    """Further seeds from the half-turn direction patterns: all, or proposed ones.

    Returns the strategy, the number of patterns and ``(name, x, pattern)`` triples
    (``pattern`` None for a dynamic-programme path).
    """
    count = pattern_count(lim)
    if lim.winding != 1:
        return _winding_seeds(excitation, lim, harmonics, gamma, count, propose)
    if count <= 1:
        return "exhaustive", count, []
    if count <= ENUMERATE_MAX:
        pats = list(all_patterns(lim))[1:]
        return "exhaustive", count, [(f"limit-{i + 1}", limit_seed(lim, harmonics, d).vector, d)
                                     for i, d in enumerate(pats)]
    from .dynprog import propose_seeds

    propose = PROPOSE_COUNT if propose is None else propose
    if lim.winding == 1:
        out = [(name, x, None) for name, x in
               propose_seeds(excitation, harmonics, gamma, propose)]
    else:
        out = [(name, x, None) for name, x in
               propose_seeds(excitation, harmonics, gamma, propose, winding=lim.winding)]
    pats = direction_patterns(lim, propose + 1, seed=0)[1:]
    out += [(f"limit-{i + 1}", limit_seed(lim, harmonics, d).vector, d)
            for i, d in enumerate(pats)]
    return "dynamic-programme", count, out


def _winding_seeds(excitation, lim, harmonics: int, gamma: float, count: int, propose):
    """Winding K != 1: the dynamic programme's seeds, always, then every pattern (at most
    ENUMERATE_MAX) or a seeded sample of them.

    The half-turn patterns of K != 1 do not cover the damped optima: with about as many
    extrema as turns (``m = K``) there is a single pattern, while a damped optimum may skip
    a small swing and turn twice elsewhere (measured: harmonics 8 to 12 of omega = 0.2,
    K = 10, gamma = 0.05: the one pattern gave -0.06559, the programme -0.05928, which an
    independent multi-start BFGS confirms). The programme models such motions.
    """
    from .dynprog import propose_seeds

    propose = PROPOSE_COUNT if propose is None else propose
    out = [(name, x, None) for name, x in
           propose_seeds(excitation, harmonics, gamma, propose, winding=lim.winding)]
    if count <= ENUMERATE_MAX:
        pats = list(all_patterns(lim))[1:]
        strategy = "patterns+dynamic-programme"
    else:
        pats = direction_patterns(lim, propose + 1, seed=0)[1:]
        strategy = "dynamic-programme"
    out += [(f"limit-{i + 1}", limit_seed(lim, harmonics, d).vector, d)
            for i, d in enumerate(pats)]
    return strategy, count, out


#: Above this many harmonics, and for gamma > 0, the patterns are compared at this N (cost
#: grows like N^3 per Newton step) and the SCREEN_KEEP best distinct maxima are polished at
#: the full N (4 above N = 128 and 2 above N = 512, where one Newton step costs 0.1 to 1 s).
SCREEN_HARMONICS = 32
SCREEN_KEEP = 8
#: Work allowed for comparing the patterns at the full N, in seeds x N^3 (792 patterns at
#: N = 96: a few seconds); beyond it, at gamma = 0, they are compared at the largest N
#: within it.
ENUMERATE_WORK = 792 * 96**3


def _screen_harmonics(count: int, harmonics: int, gamma: float) -> int | None:
    """N at which to compare the patterns, or None for the full N (docs/global.md).

    gamma > 0: N = SCREEN_HARMONICS (the ranking is that of the full N: checked). gamma = 0:
    the ranking depends on N itself, so the full N unless that exceeds ENUMERATE_WORK, and
    then the largest N within it (the evidence says so: ``screen_harmonics``).
    """
    if gamma > 0:
        return SCREEN_HARMONICS if harmonics > SCREEN_HARMONICS else None
    seeds = count if count <= ENUMERATE_MAX else 2 * PROPOSE_COUNT + SWAP_BUDGET
    if seeds * harmonics**3 <= ENUMERATE_WORK:
        return None
    n = round((ENUMERATE_WORK / seeds) ** (1.0 / 3.0))  # the integer cube root, exactly:
    while seeds * n**3 > ENUMERATE_WORK:
        n -= 1
    while seeds * (n + 1) ** 3 <= ENUMERATE_WORK:
        n += 1
    return max(SCREEN_HARMONICS, n)


#: Swaps of a forward and a backward half-turn at most this many extrema apart are tried by
#: the pattern local search; and at most SWAP_BUDGET of them in all.
SWAP_WINDOW = 4
SWAP_BUDGET = 64


def _swap_search(lim, harmonics: int, pattern, run):
    """Local search over patterns: swap a forward and a nearby backward half-turn.

    ``run(name, x)`` polishes a seed against the best so far and returns the run. Accepts
    the first improving swap and starts over, until none improves or the budget is spent.
    Each pass costs ``O(m * SWAP_WINDOW)`` polishes (``2m`` extrema), not ``C(2m, m - 1)``.
    """
    d = np.array(pattern)
    e = d.size
    tried, best = 0, None
    improved = True
    seen = {tuple(d)}
    while improved and tried < SWAP_BUDGET:
        improved = False
        for i in range(e):
            for k in range(1, SWAP_WINDOW + 1):
                j = (i + k) % e
                if d[i] == d[j]:
                    continue
                c = d.copy()
                c[i], c[j] = d[j], d[i]
                if tuple(c) in seen:
                    continue
                seen.add(tuple(c))
                tried += 1
                r, better = run(f"swap-{tried}", limit_seed(lim, harmonics, c).vector)
                if better:
                    d, best, improved = c, r, True
                    break
                if tried >= SWAP_BUDGET:
                    break
            if improved or tried >= SWAP_BUDGET:
                break
    return tried, best


def search_fourier(excitation, harmonics: int, gamma: float, *, warm: np.ndarray | None = None,
                   seeds: tuple[str, ...] = ("limit", "uniform"), gtol: float = 1e-11,
                   maxiter: int = 200, points: int | None = None, winding: int = 1,
                   hessian: str = "dense", propose: int | None = None) -> FourierSearch:
    """Global search for the N-harmonic optimum (see the module docstring and docs/global.md).

    The primary seeds (``warm``, ``limit``, ``uniform``) are polished to convergence; then,
    when ``"limit"`` is among ``seeds``, every other half-turn direction pattern of the limit
    motion (or, when there are more than :data:`ENUMERATE_MAX`, those the dynamic programme
    proposes) is started with ``abandon_below`` set to the best power so far.

    ``winding`` K: turns per period (``theta = K s + ...``; docs/seas.md). With K != 1 the
    patterns are always compared at the full N (no screening at N = 32, which could not
    draw K turns), the dynamic programme follows the uniform rotation ``K s`` (its window of
    lifted angles moves with it) and the uniform seed is ``K s + phi``.
    ``hessian="operator"``: matrix-free Newton-CG (:class:`HessianOperator`), for N in the
    thousands. ``propose``: dynamic-programme and sampled seeds (default PROPOSE_COUNT).
    """
    problem = FourierProblem(excitation, harmonics, gamma, points, winding=winding,
                             hessian=hessian)
    lim = limit(excitation) if winding == 1 else limit(excitation, winding)
    runs = [newton_maximize(problem, x0, name, gtol=gtol, maxiter=maxiter)
            for name, x0 in _seeds(excitation, lim, harmonics, gamma, warm, seeds, gtol)]
    strategy, count, extra = "local", pattern_count(lim), []
    screen = None
    if "limit" in seeds and count > 1 and winding == 1:
        screen = _screen_harmonics(count, harmonics, gamma)
    if screen is not None:
        # compare the patterns at N = screen, polish the best few at N
        coarse = search_fourier(excitation, screen, gamma, seeds=seeds, gtol=gtol,
                                maxiter=maxiter)
        strategy = coarse.evidence.strategy
        ranked = sorted((r for r in coarse.runs if r.status == "converged"),
                        key=lambda r: -r.power)
        kept: list = []
        for r in ranked:
            if all(abs(r.power - k.power) > 1e-12 for k in kept):
                kept.append(r)
            if len(kept) >= (SCREEN_KEEP if harmonics <= 128 else 4 if harmonics <= 512 else 2):
                break
        extra = [(f"{r.seed}@N={screen}", _pad(r.x, harmonics), None) for r in kept]
    elif "limit" in seeds:
        strategy, count, extra = _pattern_seeds(excitation, lim, harmonics, gamma, propose)
    best_pattern = np.asarray(lim.directions)
    # the best power so far (the bar a new run must beat), kept as runs finish rather than
    # recomputed over all runs for each of up to 1024 seeds
    bar = max((r.power for r in runs if math.isfinite(r.power)), default=-math.inf)

    def run(name, x0):
        nonlocal bar
        r = newton_maximize(problem, x0, name, gtol=gtol, maxiter=maxiter, abandon_below=bar)
        runs.append(r)
        better = r.status == "converged" and r.power > bar + 1e-13 * max(1.0, abs(bar))
        if r.status != "abandoned" and math.isfinite(r.power):
            bar = max(bar, r.power)
        return r, better

    for name, x0, pattern in extra:
        _, better = run(name, x0)
        if better and pattern is not None:
            best_pattern = pattern
    swaps = 0
    if strategy == "dynamic-programme" and gamma == 0 and screen is None:
        # at gamma = 0 the programme ranks patterns poorly (docs/global.md): search near the
        # best one by swaps
        swaps, _ = _swap_search(lim, harmonics, best_pattern, run)
    best = _best(runs)
    # grid refinement: double M until the power of the optimum no longer moves
    for _ in range(8):
        fine = FourierProblem(excitation, harmonics, gamma, 2 * problem.points,
                              winding=winding, hessian=hessian)
        if abs(fine.power(best.x) - best.power) <= 1e-14 * max(1.0, abs(best.power)):
            break
        problem = fine
        best = newton_maximize(problem, best.x, best.seed, gtol=gtol, maxiter=maxiter)
        runs.append(best)
    second, dist = second_maximum(runs, best)
    evidence = SearchEvidence(
        strategy=strategy,
        candidate_patterns=count,
        patterns_tried=(coarse.evidence.patterns_tried if screen else
                        len(extra) + swaps + ("limit" in seeds)),
        polished=sum(r.status == "converged" for r in runs),
        abandoned=sum(r.status == "abandoned" for r in runs),
        second_power=second,
        upper_bound=(lim.power - gamma * excitation.omega**2 if winding == 1
                     else lim.power - gamma * (winding * excitation.omega) ** 2),
        screen_harmonics=screen,
        second_distance=dist,
    )
    return FourierSearch(best, runs, evidence)


def solve_fourier(excitation, harmonics: int, gamma: float, *, warm: np.ndarray | None = None,
                  seeds: tuple[str, ...] = ("limit", "uniform"), gtol: float = 1e-11,
                  maxiter: int = 200, points: int | None = None):
    """Best local maximum of the N-harmonic problem (:func:`search_fourier` without evidence).

    Returns
    -------
    best : LocalSolution
        The best local maximum (ties: first seed), on a grid whose power is converged.
    runs : list of LocalSolution
        Every local run, for the record.
    """
    r = search_fourier(excitation, harmonics, gamma, warm=warm, seeds=seeds, gtol=gtol,
                       maxiter=maxiter, points=points)
    return r.best, r.runs
