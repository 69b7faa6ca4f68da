r"""Power take-off problems in the time domain: a piecewise cubic Hermite motion and a
primal-dual interior point on a banded Newton system.

Why not the Fourier series of Eq. 10 here: under a torque limit the optimal torque is
bang-bang with singular arcs (Eq. 14 is linear in ``T``, and so is ``P = -<T theta'>``,
Eq. 15). ``theta''`` then jumps, the Fourier coefficients decay like ``1/n^3``, and N
harmonics cost dense ``(2N+1)^2`` Hessians for slowly falling errors; a local basis
resolves the jumps at the cost of ``O(K)`` work per Newton step.

**Motion.** ``K`` uniform intervals of the forcing period ``T_p = 2 pi / omega``, nodes
``t_k = k h``. The unknowns are ``theta_k`` and ``v_k = theta'(t_k)``; on each interval
``theta`` is the cubic Hermite interpolant (``C^1``: ``theta''`` and so the torque may jump
at the nodes), and ``theta(t + T_p) = theta(t) + 2 pi W`` (winding ``W``, 1 for the paper's
period-1 rotation). The torque is *defined* by the motion (Eq. 14 solved for ``T``, the
inverse dynamics of :func:`parapend.model.torque`), so there are no dynamics constraints::

    T = theta'' + gamma theta' - (1 + q(t)) sin(theta)

**Objective** (maximized), Gauss-Legendre quadrature with 4 points per interval: the
mechanical power, the state form of Eq. 15,
``P = <(1 + q) sin(theta) theta'> - gamma <theta'^2>`` (``= -<T theta'>``: ``<theta''
theta'> = 0`` for a ``C^1`` periodic motion, exactly under the quadrature), minus a copper
loss ``r <T^2>`` (winding loss ``R (T / k_t)^2``) when one is given. (An efficiency is
solved by :mod:`parapend.optimal.collocation`, with the torque as a variable: here, with
the torque eliminated, its kink at ``p = 0`` left this interior point without a reliable
convergence, see docs/units.md.)

**Torque limit** ``|T| <= T_max`` at ``tau = 0, 1/2, 1`` of every interval (both sides of
every node), then checked on the motion's own dense evaluation
(:meth:`HermiteMotion.peak_torque`): the grid limit is tightened by any excess between
the points (by twice the excess, with a margin of ``5e-8`` relative on every interval at
the limit) and the solve repeated.

**Solver.** A feasible primal-dual interior point (Nocedal & Wright, Alg. 19.1 with the
slacks eliminated: every iterate is strictly feasible), barrier parameter ``mu`` reduced by
the Fiacco-McCormick rule of IPOPT (``mu <- max(mu_min, min(mu / 5, mu^1.3))`` once the
barrier problem is solved to ``10 mu``; IPOPT's power is 1.5), the first step at the new
``mu`` a Mehrotra predictor-corrector step (the affine step's products ``ds dlambda``
corrected, same factorization), Armijo backtracking on the barrier function, fraction to
the boundary 0.995 for primal and dual steps. Objective, constraints, line-search trials
and the Newton matrix are compiled loops over the intervals
(:mod:`parapend.optimal._hermite_kernel`). The Newton matrix
``H_L + J^T diag(lambda / s) J`` couples only neighbouring nodes; ordered
``0, K-1, 1, K-2, ...`` the cyclic block-tridiagonal matrix becomes banded (lower
bandwidth 5) and is factored by LAPACK's banded Cholesky, with a multiple of the identity
added when it is not positive definite (inertia correction). A border variable ``t`` (one
dense row)
makes the *phase-1* problem ``min t`` s.t. ``|T| <= t``: its optimum is the smallest peak
torque of any rotation near the start, and stopping it below ``T_max`` gives a strictly
feasible start.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.linalg import LinAlgError
from scipy.linalg.lapack import dpbtrf, dpbtrs

from . import _hermite_kernel as _k

__all__ = ["HermiteMotion", "HermiteProblem", "HermiteSolution", "interior_point",
           "minimum_peak_torque", "solve_hermite"]

GAUSS_POINTS = 4
TORQUE_TAU = np.array([0.0, 0.5, 1.0])
_FRACTION = 0.995
# barrier parameter update (IPOPT's rule with a milder superlinear power: fewer damped
# steps after each decrease; measured over 42 limit/damping/K cases)
_MU_FACTOR, _MU_POWER = 0.2, 1.3
#: relative Newton decrement below which a failed line search at the final barrier
#: parameter is the arithmetic's limit (status converged), not a stall
ROUNDING_DECREMENT = 1e-10
# tightening: a margin of _MARGIN tol on every interval within _NEAR of the limit
_NEAR, _MARGIN = 1e-3, 50
_BAND = 5  # lower bandwidth of the folded Newton matrix


def _hermite_rows(tau: np.ndarray, h: float):
    """Rows mapping ``y = (theta_a, v_a, theta_b, v_b)`` to ``theta, theta', theta''``."""
    t = np.asarray(tau, dtype=float)
    one = np.ones_like(t)
    b0 = np.stack([2 * t**3 - 3 * t**2 + 1, h * (t**3 - 2 * t**2 + t), -2 * t**3 + 3 * t**2,
                   h * (t**3 - t**2)], axis=-1)
    b1 = np.stack([(6 * t**2 - 6 * t) / h, 3 * t**2 - 4 * t + one, (-6 * t**2 + 6 * t) / h,
                   3 * t**2 - 2 * t], axis=-1)
    b2 = np.stack([(12 * t - 6) / h**2, (6 * t - 4) / h, (-12 * t + 6) / h**2,
                   (6 * t - 2) / h], axis=-1)
    return b0, b1, b2


def locate(t, period: float, k: int, winding: int):
    """Interval of times ``t`` on ``K`` uniform intervals of a period: ``(tau, h, j, off)``,
    the local coordinate in [0, 1], the step, the interval index and the angle ``2 pi W``
    per whole period before ``t``."""
    t = np.asarray(t, dtype=float)
    h = period / k
    turns = np.floor(t / period)
    tt = t - turns * period
    j = np.minimum(np.floor(tt / h), k - 1).astype(int)
    return tt / h - j, h, j, 2 * math.pi * winding * turns


def _fold(k: int) -> np.ndarray:
    """Position of node ``i`` in the order ``0, K-1, 1, K-2, ...`` (cyclic -> banded)."""
    i = np.arange(k)
    return np.where(i <= (k - 1) // 2, 2 * i, 2 * (k - i) - 1)


@dataclass(frozen=True, eq=False)
class HermiteMotion:
    """Piecewise cubic Hermite rotation: nodes ``t_k = k T_p / K``, ``theta_k``, ``v_k``
    (``C^1``: ``theta''`` and the torque jump at the nodes; at a node ``theta_ddot`` gives
    the right-hand limit, :meth:`peak_torque` takes both)."""

    omega: float
    theta_nodes: np.ndarray
    v_nodes: np.ndarray
    winding: int = 1

    @property
    def intervals(self) -> int:
        return int(self.theta_nodes.size)

    def local(self):
        """``y`` of every interval, shape (K, 4): ``theta_j, v_j, theta_{j+1}, v_{j+1}``."""
        nxt = np.roll(np.arange(self.intervals), -1)
        th_b = self.theta_nodes[nxt].copy()
        th_b[-1] += 2 * math.pi * self.winding
        return np.stack([self.theta_nodes, self.v_nodes, th_b, self.v_nodes[nxt]], axis=1)

    @property
    def period(self) -> float:
        return 2 * math.pi / self.omega

    def _locate(self, t):
        tau, h, j, off = locate(t, self.period, self.intervals, self.winding)
        return tau, h, self.local()[j], off

    def theta(self, t):
        tau, h, y, off = self._locate(t)
        return np.sum(_hermite_rows(tau, h)[0] * y, axis=-1) + off

    def theta_dot(self, t):
        tau, h, y, _ = self._locate(t)
        return np.sum(_hermite_rows(tau, h)[1] * y, axis=-1)

    def theta_ddot(self, t):
        tau, h, y, _ = self._locate(t)
        return np.sum(_hermite_rows(tau, h)[2] * y, axis=-1)

    def profile_on(self, tau: np.ndarray):
        """``t, theta, theta', theta''`` at local ``tau`` of every interval, shape (K, len)."""
        k = self.intervals
        h = self.period / k
        b0, b1, b2 = _hermite_rows(np.asarray(tau, dtype=float), h)
        y = self.local()
        t = h * (np.arange(k)[:, None] + np.asarray(tau)[None, :])
        return t, y @ b0.T, y @ b1.T, y @ b2.T

    def peak_torque(self, excitation, gamma: float, samples: int = 16) -> float:
        """``max |T|`` of the motion (:meth:`interval_peaks`)."""
        return float(np.max(self.interval_peaks(excitation, gamma, samples=samples)))

    def interval_peaks(self, excitation, gamma: float, floor: float | None = None,
                       samples: int = 16) -> np.ndarray:
        """``max |T|`` over each interval, shape (K,): every interval sampled at
        ``samples + 1`` points (both ends: ``T`` jumps at nodes), and those whose sampled
        maximum reaches 95 % of ``floor`` (a torque limit; default the largest sample)
        refined by zooming on it (:func:`parapend.optimal._hermite_kernel.interval_peaks`);
        the others keep their samples (their true maximum lies below: the samples miss at
        most ``(h/16)^2 |T''| / 8``)."""
        x = np.empty(2 * self.intervals)
        x[0::2] = self.theta_nodes
        x[1::2] = self.v_nodes
        m = self.intervals * int(samples)
        q1s = 1.0 + np.asarray(excitation.q_uniform(m), dtype=float)
        q1s = np.append(q1s, q1s[0])  # the end of the period
        return _k.interval_peaks(x, self.intervals, 2 * math.pi * self.winding,
                                 self.period / self.intervals, float(gamma),
                                 np.asarray(excitation.spectrum, dtype=complex),
                                 float(self.omega), int(samples),
                                 -1.0 if floor is None else float(floor), q1s)

    def mean_square_speed(self) -> float:
        """``<theta'^2>`` by Gauss-Legendre quadrature (exact: a polynomial of degree 4)."""
        x, w = np.polynomial.legendre.leggauss(3)
        _, _, thd, _ = self.profile_on((x + 1) / 2)
        return float(np.sum(thd * thd * w) / (2 * self.intervals))


#: spectra longer than this are evaluated on the intervals by FFT (folded, exact), shorter
#: ones pointwise
_FOLD_ABOVE = 64


def q_on_intervals(excitation, k: int, taus) -> np.ndarray:
    """``q`` at ``t = h (j + tau)``, ``h = T / k``, j = 0..k-1, for each ``tau``: shape
    ``(k, len(taus))``.

    Exact either way: pointwise (:meth:`Excitation.q`) for short spectra and closed forms
    (the square wave), otherwise one folded inverse FFT per ``tau`` on the spectrum shifted
    by ``h tau``, O(S + k log k) instead of O(S k) (a 16384-row file has S = 8193: 18 s of a
    torque-limited solve went into pointwise evaluation)."""
    from ..excitation import Excitation, _evaluate_uniform

    taus = np.asarray(taus, dtype=float)
    h = excitation.period / k
    spec = np.asarray(excitation.spectrum, dtype=complex)
    if type(excitation).q is not Excitation.q or spec.size <= _FOLD_ABOVE:
        return np.asarray(excitation.q(h * (np.arange(k)[:, None] + taus[None, :])),
                          dtype=float)
    kk = np.arange(spec.size)
    out = np.empty((k, taus.size))
    for i, tau in enumerate(taus):
        out[:, i] = _evaluate_uniform(spec * np.exp(1j * kk * (excitation.omega * h * tau)), k)
    return out


class HermiteProblem:
    """Objective and constraints of one PTO problem on ``K`` Hermite intervals.

    Parameters
    ----------
    excitation : Excitation
    intervals : int
        ``K``.
    gamma : float
        Viscous damping >= 0 (Eq. 14).
    torque_limit : float or None
        ``T_max`` (m g l); with ``phase1=True`` ignored (the bound is the variable ``t``).
    copper_loss : float
        ``r >= 0`` of the loss ``r <T^2>``.
    phase1 : bool
        Minimize the peak torque ``t`` instead (no power objective): ``|T| <= t``.
    elastic : float or None
        Elastic mode (a start from anywhere): ``|T| <= torque_limit + t``, ``t >= 0``, and
        ``elastic * t`` added to the minimized ``-P`` (an exact penalty once ``elastic``
        exceeds the limit's multipliers).
    winding : int
        Turns per forcing period.
    """

    def __init__(self, excitation, intervals: int, gamma: float, *, torque_limit=None,
                 copper_loss: float = 0.0, phase1: bool = False,
                 elastic: float | None = None, winding: int = 1):
        self.excitation = excitation
        self.omega = om = excitation.omega
        self.k = k = int(intervals)
        self.gamma = float(gamma)
        self.period = period = 2 * math.pi / om
        self.h = h = period / k
        self.winding = int(winding)
        self.phase1 = phase1
        self.elastic = elastic
        self.border = "phase1" if phase1 else ("elastic" if elastic is not None else None)
        self.torque_limit = torque_limit
        self.copper_loss = float(copper_loss)
        self.mode = (_k.PHASE1 if phase1 else _k.ELASTIC if elastic is not None else
                     _k.LIMIT if torque_limit is not None else _k.NONE)
        self.grid_limit = torque_limit
        xg, wg = np.polynomial.legendre.leggauss(GAUSS_POINTS)
        self.tau_g = (xg + 1) / 2
        self.wg = wg / 2 * h / period  # mean = sum over intervals of wg . f
        self.rows_g = _hermite_rows(self.tau_g, h)
        self.rows_c = _hermite_rows(TORQUE_TAU, h)
        self.q1_g = 1.0 + q_on_intervals(excitation, k, self.tau_g)
        self.q1_c = 1.0 + q_on_intervals(excitation, k, TORQUE_TAU)
        # torque rows, linear part: theta'' + gamma theta'
        self.lin_g = self.rows_g[2] + gamma * self.rows_g[1]
        self.lin_c = self.rows_c[2] + gamma * self.rows_c[1]
        self.wrap_turns = 2 * math.pi * self.winding
        # folded positions of every interval's variables (the banded assembly)
        pos = _fold(k)
        nxt = np.roll(np.arange(k), -1)
        self._gvar = np.stack([2 * pos, 2 * pos + 1, 2 * pos[nxt], 2 * pos[nxt] + 1], axis=1)
        self.n = n = 2 * k
        self.perm = np.empty(n, dtype=int)  # folded position of variable (node, component)
        self.perm[0::2] = 2 * pos
        self.perm[1::2] = 2 * pos + 1
        self.wrap = np.zeros((k, 4))
        self.wrap[-1, 2] = self.wrap_turns
        self._next = nxt
        self._jtc = np.zeros((k, TORQUE_TAU.size, 4))

    @property
    def grid_limit(self):
        """The limit at the constraint points: ``T_max`` or, tightened, one per interval."""
        return self._grid_limit

    @grid_limit.setter
    def grid_limit(self, value):
        self._grid_limit = value
        lim = 1.0 if value is None else np.asarray(value, dtype=float).ravel()
        self._scale = np.ascontiguousarray(np.broadcast_to(1.0 / lim, (self.k,)))

    # -- motion <-> variables ------------------------------------------------------------------
    def local(self, x: np.ndarray) -> np.ndarray:
        """Interval vectors ``y``, shape (K, 4), from ``x = (theta_0, v_0, theta_1, ...)``."""
        xr = x.reshape(self.k, 2)
        return np.concatenate([xr, xr[self._next]], axis=1) + self.wrap

    def motion(self, x: np.ndarray) -> HermiteMotion:
        return HermiteMotion(self.omega, x[0::2].copy(), x[1::2].copy(), self.winding)

    def start(self, motion) -> np.ndarray:
        """Variables interpolating ``motion`` at the nodes."""
        t = self.h * np.arange(self.k)
        x = np.empty(self.n)
        x[0::2] = motion.theta(t)
        x[1::2] = motion.theta_dot(t)
        return x

    # -- pointwise quantities (compiled kernels: parapend.optimal._hermite_kernel) -------------
    def torque_points(self, x) -> np.ndarray:
        """``T`` at the constraint points, shape (K, 3)."""
        return _k.torques(np.asarray(x, dtype=float), self.k, self.wrap_turns,
                          self.rows_c[0], self.lin_c, self.q1_c)

    def _power_terms(self, x):
        return _k.power_terms(np.asarray(x, dtype=float), self.k, self.wrap_turns,
                              self.rows_g[0], self.rows_g[1], self.lin_g, self.q1_g,
                              self.wg, self.gamma)

    def power(self, x) -> float:
        """Mean mechanical power ``P`` (Eq. 15, state form)."""
        return float(self._power_terms(x)[0])

    def electrical(self, x) -> float:
        """Mean power delivered after the copper loss, ``P - r <T^2>``."""
        p, t2 = self._power_terms(x)
        return float(p - self.copper_loss * t2)

    # -- the pieces of the interior point --------------------------------------------------------
    def constraints(self, x, t=None):
        """The torque constraints ``c <= 0`` at the constraint points, flat."""
        return _k.constraints(np.asarray(x, dtype=float), 0.0 if t is None else float(t),
                              self.k, self.wrap_turns, self.rows_c[0], self.lin_c,
                              self.q1_c, self.mode, self._scale,
                              float(self.torque_limit or 0.0))

    def constraint_step(self, dx, dt=None) -> np.ndarray:
        """``J d``: the linearized change of :meth:`constraints` along a step, at the point
        of the last :meth:`newton` call."""
        return _k.constraint_step(np.asarray(dx, dtype=float), 0.0 if dt is None else
                                  float(dt), self.k, self._jtc, self.mode, self._scale)

    def jt_apply(self, w):
        """``J^T w`` over the constraints at the point of the last :meth:`newton` call:
        ``(x part in the folded order, t part)``."""
        return _k.jt_apply(w, self.k, self._jtc, self.mode, self._scale, self._gvar)

    def barrier_count(self) -> int:
        """Number of barrier terms (the barrier's duality gap is this times ``mu``)."""
        if self.mode == _k.NONE:
            return 0
        return 2 * TORQUE_TAU.size * self.k + (self.mode == _k.ELASTIC)

    def objective(self, x, mu: float = 0.0, t=None) -> float:
        """``phi`` to minimize: ``-(power)`` or, in phase 1, ``t`` (``mu`` unused: the
        barrier terms are added by :func:`interior_point`)."""
        if self.phase1:
            return float(t)
        p, t2 = self._power_terms(x)
        f = -float(p) + self.copper_loss * float(t2)
        return f + (self.elastic * float(t) if self.elastic is not None else 0.0)

    def trial(self, x, dx, alpha, t, dt, s, mu, floor):
        """Line-search trial ``x + alpha dx``: ``(ok, barrier, xn, tn, sn, phi)``
        (:func:`parapend.optimal._hermite_kernel.trial`)."""
        return _k.trial(x, dx, float(alpha), 0.0 if t is None else float(t),
                        0.0 if dt is None else float(dt), s, float(mu), float(floor), self.k,
                        self.wrap_turns, self.rows_g[0], self.rows_g[1], self.lin_g,
                        self.q1_g, self.wg, self.gamma, self.copper_loss, self.rows_c[0],
                        self.lin_c, self.q1_c, self.mode, self._scale,
                        float(self.torque_limit or 0.0), float(self.elastic or 0.0))

    def newton(self, x, t, lam, mu):
        """Banded Newton matrix and right-hand side of the barrier problem.

        Returns ``(ab, rhs, border, rhs_t, d_tt)``: ``ab`` the lower band of the Newton
        matrix in the folded order, ``rhs`` minus the barrier gradient, ``border`` the
        column ``M_xt`` and ``rhs_t``, ``d_tt`` its entries for ``t`` (phase 1, elastic
        mode; else None, 0, 0).
        """
        ab, rhs, border, rhs_t, d_tt = _k.newton(
            np.asarray(x, dtype=float), 0.0 if t is None else float(t),
            np.asarray(lam, dtype=float), float(mu), self.k, self.wrap_turns,
            self.rows_g[0], self.rows_g[1], self.lin_g, self.q1_g, self.wg, self.gamma,
            self.copper_loss, self.rows_c[0], self.lin_c, self.q1_c, self.mode, self._scale,
            float(self.torque_limit or 0.0), float(self.elastic or 0.0), self._gvar,
            self._jtc)
        if self.mode in (_k.PHASE1, _k.ELASTIC):
            return ab, rhs, border, float(rhs_t), float(d_tt)
        return ab, rhs, None, 0.0, 0.0


@dataclass
class HermiteSolution:
    """Outcome of :func:`interior_point` / :func:`solve_hermite`."""

    x: np.ndarray
    t: float | None
    status: str
    iterations: int
    mu: float
    power: float = math.nan
    electrical_power: float = math.nan
    peak_torque: float = math.nan
    intervals: int = 0
    stages: list = field(default_factory=list)
    motion: object = None
    anchor: object = None  # the strictly feasible motion the solve started towards


def _factor(ab, delta):
    """LAPACK's banded Cholesky (dpbtrf) of ``ab + delta I``; LinAlgError when it is not
    positive definite."""
    a = ab.copy()
    a[0] += delta
    c, info = dpbtrf(a, lower=1)
    if info != 0:
        raise LinAlgError("not positive definite")
    return c


def _solve(c, rhs, border, rhs_t, d_tt, delta):
    """Solve the (bordered) banded system from its factor ``c`` (:func:`_factor`)."""
    if border is None:
        return dpbtrs(c, rhs, lower=1)[0], 0.0
    both = dpbtrs(c, np.stack([rhs, border], axis=1), lower=1)[0]
    # the border's Schur complement is positive in exact arithmetic (the phase-1 matrix is
    # J^T Sigma J + ... with J = [J_x, -1]); cancellation may leave it at roundoff
    schur = max(d_tt + delta - border @ both[:, 1], 1e-12 * (d_tt + delta))
    dt = (rhs_t - border @ both[:, 0]) / schur
    return both[:, 0] - both[:, 1] * dt, dt


def _predictor_corrector(pr, fac, rhs, border, rhs_t, d_tt, delta, s, lam, mu, mu_new):
    """Mehrotra's predictor-corrector step into the barrier problem at ``mu_new``, from the
    factor of the Newton matrix at ``mu`` (it does not depend on ``mu``).

    The affine step (``mu = 0``) predicts the products ``ds_i dlambda_i`` that a linear step
    misses; the corrector aims at ``s_i lambda_i = mu_new - ds_i dlambda_i`` (Nocedal &
    Wright, Eq. 19.12 adapted to eliminated slacks). Returns ``(dx (folded), dt, slope,
    target)``, ``slope`` the derivative of the barrier function at ``mu_new`` along the step
    and ``target`` the dual estimate it aims at; None when the step is not a descent step.
    """
    if not lam.size:
        return None
    ones = pr.jt_apply(1.0 / s)
    rhs0, rhs_t0 = rhs + mu * ones[0], rhs_t + mu * ones[1]  # the right-hand side at mu = 0
    dx_a, dt_a = _solve(fac, rhs0, border, rhs_t0, d_tt, delta)
    ds_a = -pr.constraint_step(dx_a[pr.perm], dt_a)
    dlam_a = -lam - lam / s * ds_a
    target = (mu_new - ds_a * dlam_a) / s
    jw = pr.jt_apply(target)
    dx_f, dt = _solve(fac, rhs0 - jw[0], border, rhs_t0 - jw[1], d_tt, delta)
    rhs_new, rhs_t_new = rhs0 - mu_new * ones[0], rhs_t0 - mu_new * ones[1]
    slope = -float(rhs_new @ dx_f) - (rhs_t_new * dt if border is not None else 0.0)
    if not slope < 0:
        return None
    return dx_f, dt, slope, target


def interior_point(problem: HermiteProblem, x, *, t=None, mu0: float | None = None,
                   gap_tol: float = 1e-10, maxiter: int = 300,
                   stop_below: float | None = None) -> HermiteSolution:
    """Minimize the problem's barrier objective from a strictly feasible ``(x, t)``.

    ``gap_tol``: the final barrier parameter times the number of barrier terms (a bound on
    the objective's distance to the optimum of the discrete problem). ``stop_below``: in
    phase 1, stop as soon as ``t`` falls below it (a strictly feasible start for that
    limit). Status "converged", "feasible" (phase 1 stopped), "max_iterations", "stalled"
    (the line search failed), "singular" or "infeasible_start".
    """
    pr = problem
    x = np.array(x, dtype=float)
    if pr.phase1 and t is None:
        t = float(np.max(np.abs(pr.torque_points(x)))) * 1.05 + 0.05
    if pr.elastic is not None and t is None:
        lim = pr.torque_limit
        t = max(float(np.max(np.abs(pr.torque_points(x)))) - lim, 0.0) + 0.05 * lim + 1e-3
    c = pr.constraints(x, t)
    if c.size and np.max(c) >= 0:
        return HermiteSolution(x, t, "infeasible_start", 0, math.nan)
    m = max(pr.barrier_count(), 1)
    phi = pr.objective(x, 0.0, t)
    # the barrier's own gap is m mu: start it at a tenth of the objective's scale
    mu = mu0 if mu0 is not None else 0.1 * max(abs(phi), 1e-3) / m
    mu_min = min(gap_tol / m, mu)
    phi = pr.objective(x, mu, t)
    s = -c
    lam = mu / s
    status = "max_iterations"
    delta_last = 0.0
    # consecutive steps that changed the barrier function by < 1e-14 relative: the barrier
    # problem is solved as far as the arithmetic (or a jam at the boundary) allows
    stagnant = 0
    it = 0
    for it in range(1, maxiter + 1):  # noqa: B007 (returned: the iteration count)
        ab, rhs, border, rhs_t, d_tt = pr.newton(x, t, lam, mu)
        delta = 0.0  # inertia correction: the smallest delta I that makes it definite
        for _ in range(30):
            try:
                fac = _factor(ab, delta)
                break
            except LinAlgError:
                # first try: a third of the last shift, or 1e-8 of the median diagonal (the
                # largest entries are those of the active constraints, up to lambda^2/mu)
                delta = 8 * delta if delta else max(
                    delta_last / 3, 1e-8 * max(1e-6, float(np.median(np.abs(ab[0])))))
        else:
            status = "singular"
            break
        delta_last = delta
        dx_f, dt = _solve(fac, rhs, border, rhs_t, d_tt, delta)
        dx = dx_f[pr.perm]
        slope = -float(rhs @ dx_f) - (rhs_t * dt if border is not None else 0.0)
        # -slope is the Newton decrement squared: about twice the distance of the barrier
        # function to its minimum at this mu
        # (floored at the precision to which the barrier function can be compared)
        target = mu / s  # the dual estimate the step aims at (lambda_i s_i = mu)
        if -slope <= max(2e-2 * m * mu, 1e-12 * (1.0 + abs(phi))) or stagnant >= 5:
            if mu <= mu_min * (1 + 1e-12):
                status = "converged"
                break
            mu_new = max(mu_min, min(_MU_FACTOR * mu, mu**_MU_POWER))
            stagnant = 0
            pc = _predictor_corrector(pr, fac, rhs, border, rhs_t, d_tt, delta, s, lam, mu,
                                      mu_new)
            mu = mu_new
            phi = pr.objective(x, mu, t)
            if pc is None:
                continue
            dx_f, dt, slope, target = pc
            dx = dx_f[pr.perm]
        b0 = phi - mu * float(np.sum(np.log(s)))
        # fraction to the boundary on the linearized slacks (s + alpha ds >= (1 - tau) s)
        ds = -pr.constraint_step(dx, dt)
        alpha = _k.max_step(s, ds, _FRACTION)
        for _ in range(50):
            ok, bn, xn, tn, sn, phin = pr.trial(x, dx, alpha, t, dt, s, mu,
                                                0.1 * (1 - _FRACTION))
            if ok and (bn <= b0 + 1e-4 * alpha * min(slope, 0.0)
                       or abs(bn - b0) <= 1e-15 * (1 + abs(b0))):
                break
            alpha *= 0.5
        else:
            # at the final barrier parameter, with a Newton decrement at the precision to
            # which the barrier function can be compared, the point is the optimum to
            # rounding; otherwise the line search failed
            final = mu <= mu_min * (1 + 1e-12)
            status = ("converged" if final and -slope <= ROUNDING_DECREMENT * (1.0 + abs(phi))
                      else "stalled")
            break
        if t is None:
            tn = None
        if lam.size:  # dual step, fraction to the boundary
            dlam = target - lam - lam / s * ds  # mu/s - lam + Sigma J dx
            lam = np.maximum(lam + _k.max_step(lam, dlam, _FRACTION) * dlam, 1e-30)
        stagnant = stagnant + 1 if abs(bn - b0) <= 1e-14 * (
            1 + abs(b0)) else 0
        x, t, s, phi = xn, tn, sn, phin
        if stop_below is not None and t is not None and t < stop_below:
            status = "feasible"
            break
    return HermiteSolution(x, t, status, it, mu)


def _blend_feasible(problem: HermiteProblem, x, anchor, t=None):
    """The point ``(1 - beta) x + beta anchor`` with the smallest ``beta`` in
    ``0, 2^-30, ..., 1/2, 1`` that is strictly feasible (``anchor`` must be); None if none."""
    for beta in (0.0, *2.0 ** -np.arange(30, -1, -1)):
        xb = (1.0 - beta) * x + beta * anchor
        c = problem.constraints(xb, t)
        if not c.size or np.max(c) < 0:
            return xb
    return None


def _elastic(excitation, gamma, k, x, torque_limit, copper_loss, winding, stages):
    """Elastic mode from ``x``: ``|T| <= L + t``, ``t >= 0``, penalty ``M t``, ``M`` raised
    tenfold until ``t`` vanishes (at most ``1e5``); ``L`` a little below the limit so that
    the optimum is strictly inside. Returns ``(x, t, iterations)``."""
    weight = 10.0 * max(1.0, excitation.omega)
    t, iters = None, 0
    while True:
        el = HermiteProblem(excitation, k, gamma, torque_limit=torque_limit * (1 - 1e-4),
                            copper_loss=copper_loss, elastic=weight, winding=winding)
        sol = interior_point(el, x, t=t)
        iters += sol.iterations
        stages.append(("elastic", weight, sol.t, sol.status))
        x, t = sol.x, sol.t
        if t < 1e-5 * torque_limit or weight >= 1e5 or sol.status == "infeasible_start":
            return x, t, iters
        weight *= 10.0
        t = t * 1.5 + 1e-3 * torque_limit  # strictly inside again


def minimum_peak_torque(excitation, gamma: float, intervals: int, start, *,
                        stop_below: float | None = None, winding: int = 1):
    """Phase 1: the rotation of smallest peak torque near ``start`` (a motion).

    Returns ``(HermiteSolution, problem)``; ``solution.t`` is the peak at the constraint
    points (``stop_below``: stop once it is below that).
    """
    pr = HermiteProblem(excitation, intervals, gamma, phase1=True, winding=winding)
    x0 = pr.start(start)
    sol = interior_point(pr, x0, stop_below=stop_below)
    sol.peak_torque = pr.motion(sol.x).peak_torque(excitation, gamma)
    sol.intervals = intervals
    return sol, pr


def solve_hermite(excitation, gamma: float, intervals: int, start, *, torque_limit=None,
                  copper_loss: float = 0.0, tol: float = 1e-9,
                  anchor=None, winding: int = 1) -> HermiteSolution:
    """Optimal PTO motion on ``intervals`` Hermite intervals, from the motion ``start``.

    ``anchor``: a motion strictly inside the torque limit (default: the best uniform
    rotation); the start is blended towards it until strictly feasible. Without such an
    anchor, elastic mode (``|T| <= T_max + t``, penalty on ``t``) from the start itself finds
    a strictly feasible point near the optimum. The result satisfies
    ``|T| <= torque_limit (1 + tol)`` on the motion's dense evaluation
    (:meth:`HermiteMotion.peak_torque`), or has status "infeasible" (no rotation near the
    start has a peak torque below the limit: ``t`` is the smallest peak found by phase 1).
    """
    from ..power import uniform_power
    from ..trajectory import FourierMotion

    k = int(intervals)
    pr = HermiteProblem(excitation, k, gamma, torque_limit=torque_limit,
                        copper_loss=copper_loss, winding=winding)
    x = pr.start(start)
    stages = []
    iters = 0
    x_start = x
    if torque_limit is not None:
        if anchor is None:
            _, phi = uniform_power(excitation, gamma, winding)
            anchor = FourierMotion(excitation.omega, phi, np.zeros(1), np.zeros(1), winding)
        xa = pr.start(anchor)
        # blend towards the anchor when it is strictly inside; otherwise elastic mode below
        # (a phase-1 motion as the anchor was tried: near a free rotation it leads into the
        # basin of a poor local optimum)
        inside = np.max(np.abs(pr.torque_points(xa))) < torque_limit * (1 - 1e-3)
        x = _blend_feasible(pr, x, xa) if inside else None
    if x is not None:
        sol = interior_point(pr, x)
        iters += sol.iterations
        stages.append(("solve", torque_limit, sol.status))
    if torque_limit is not None and (x is None or sol.status != "converged"):
        # no strictly feasible start, or the solve from it stalled: elastic mode from the
        # start itself (it keeps the start's basin)
        xe, te, it_e = _elastic(excitation, gamma, k, x_start, torque_limit, copper_loss,
                                winding, stages)
        iters += it_e
        if not te < 1e-5 * torque_limit:
            # the limit is not met near the start: the smallest peak near it (phase 1)
            ph1, _ = minimum_peak_torque(excitation, gamma, k, pr.motion(xe),
                                         winding=winding)
            iters += ph1.iterations
            stages.append(("phase1", ph1.t, ph1.status))
            return HermiteSolution(ph1.x, ph1.t, "infeasible", iters, ph1.mu,
                                   power=pr.power(ph1.x), electrical_power=pr.electrical(ph1.x),
                                   peak_torque=ph1.peak_torque, intervals=k, stages=stages,
                                   motion=pr.motion(ph1.x))
        xa = x = xe  # strictly inside the limit, and near its optimum already
        sol = interior_point(pr, x, mu0=1e-4 * abs(pr.objective(x)) / pr.barrier_count())
        iters += sol.iterations
        stages.append(("solve", torque_limit, sol.status))

    motion = pr.motion(sol.x)
    peaks = motion.interval_peaks(excitation, gamma, torque_limit)
    peak = float(np.max(peaks))
    # the optimum on the untightened grid bounds every motion within the limit everywhere
    bound = pr.power(sol.x) if sol.status == "converged" else math.inf
    for _ in range(6):
        if torque_limit is None or peak <= torque_limit * (1 + tol) or \
                sol.status != "converged":
            break
        # the dense peak lies between constraint points: tighten the limit of each interval
        # by its own excess, and restart close to the last optimum with a small barrier
        lim = np.broadcast_to(np.asarray(pr.grid_limit, dtype=float), (k, 1)).copy()
        over = peaks > torque_limit
        # (twice the excess: the optimum presses against the new limit and the peak between
        # the points moves with it)
        lim[over, 0] *= (torque_limit / peaks[over]) ** 2
        # and a margin of 20 tol on every interval at the limit: the peaks move with the
        # new optimum, and an excess of a few tol elsewhere would cost another round
        lim[peaks > torque_limit * (1 - _NEAR), 0] *= 1 - _MARGIN * tol
        pr.grid_limit = lim
        x = _blend_feasible(pr, sol.x, xa)
        if x is None:  # the anchor is not inside the tightened limits: a new one, or stop
            ph1, _ = minimum_peak_torque(excitation, gamma, k, pr.motion(xa),
                                         stop_below=float(np.min(lim)) * (1 - 1e-3),
                                         winding=winding)
            iters += ph1.iterations
            x = _blend_feasible(pr, sol.x, ph1.x) if ph1.t < np.min(lim) else None
            if x is None:
                break
            xa = ph1.x
        # the barrier restarts at the scale of the change: 1e-4 of the objective, less when
        # the excess was small (a last interval 3e-7 over needs no wide restart)
        scale = min(1e-4, 100.0 * (peak / torque_limit - 1.0))
        sol = interior_point(pr, x, mu0=scale * abs(pr.objective(x)) / pr.barrier_count())
        iters += sol.iterations
        stages.append(("tighten", float(np.min(lim)), sol.status))
        motion = pr.motion(sol.x)
        peaks = motion.interval_peaks(excitation, gamma, torque_limit)
        peak = float(np.max(peaks))
    status = sol.status
    if torque_limit is not None and peak > torque_limit * (1 + tol) and status == "converged":
        status = "stalled"
    if torque_limit is not None and status == "max_iterations" and \
            peak <= torque_limit * (1 + tol) and \
            pr.power(sol.x) >= bound - 1e-8 * max(1.0, abs(bound)):
        # a tightened solve slowed down (near a free rotation every constraint is active),
        # but its motion meets the limit everywhere and is within 1e-8 of the untightened
        # optimum, an upper bound: optimal to that
        status = "converged"
        stages.append(("bound", bound, "certified"))
    sol.status = status
    sol.iterations = iters
    sol.power = pr.power(sol.x)
    sol.electrical_power = pr.electrical(sol.x)
    sol.peak_torque = peak
    sol.intervals = k
    sol.stages = stages
    sol.motion = motion
    sol.anchor = None if torque_limit is None else pr.motion(xa)
    return sol
