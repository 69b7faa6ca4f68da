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
solved on the Fourier series, :mod:`parapend.optimal.constrained`: its kink at ``p = 0`` left
this interior point without a reliable convergence, see docs/units.md.)

**Torque limit** ``|T| <= T_max`` at ``tau = 0, 1/2, 1`` of every interval (both sides of
every node), then checked on the motion's own dense evaluation
(:meth:`HermiteMotion.peak_torque`): the grid limit is tightened by any excess between
the points and the solve repeated.

**Solver.** A feasible primal-dual interior point (Nocedal & Wright, Alg. 19.1 with the
slacks eliminated: every iterate is strictly feasible), barrier parameter ``mu`` reduced by
the Fiacco-McCormick rule of IPOPT (``mu <- max(mu_min, min(mu / 5, mu^1.5))`` once the
barrier problem is solved to ``10 mu``), Armijo backtracking on the barrier function,
fraction to the boundary 0.995 for the duals. The Newton matrix
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

__all__ = ["HermiteMotion", "HermiteProblem", "HermiteSolution", "interior_point",
           "minimum_peak_torque", "solve_hermite"]

GAUSS_POINTS = 4
TORQUE_TAU = np.array([0.0, 0.5, 1.0])
_FRACTION = 0.995
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
        t = np.asarray(t, dtype=float)
        k = self.intervals
        h = self.period / k
        turns = np.floor(t / self.period)
        tt = t - turns * self.period
        j = np.minimum(np.floor(tt / h), k - 1).astype(int)
        return tt / h - j, h, self.local()[j], 2 * math.pi * self.winding * turns

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

    def peak_torque(self, excitation, damping: float, samples: int = 16) -> float:
        """``max |T|`` of the motion (:meth:`interval_peaks`)."""
        return float(np.max(self.interval_peaks(excitation, damping, samples=samples)))

    def interval_peaks(self, excitation, damping: float, floor: float | None = None,
                       samples: int = 16) -> np.ndarray:
        """``max |T|`` over each interval, shape (K,): every interval sampled at
        ``samples + 1`` points (both ends: ``T`` jumps at nodes), and those whose sampled
        maximum reaches 95 % of ``floor`` (a torque limit; default the largest sample)
        refined by zooming on it, vectorized; the others keep their samples (their true
        maximum lies below: the samples miss at most ``(h/16)^2 |T''| / 8``)."""
        k = self.intervals
        h = self.period / k
        tau = np.linspace(0.0, 1.0, samples + 1)
        t, th, thd, thdd = self.profile_on(tau)
        tq = np.abs(thdd + damping * thd - (1.0 + excitation.q(t)) * np.sin(th))
        i = np.argmax(tq, axis=1)
        best = tq[np.arange(k), i]
        top = float(np.max(best)) if floor is None else floor
        sel = np.nonzero(best >= 0.95 * top)[0]
        if sel.size == 0:
            return best
        y = self.local()[sel]
        base = h * sel
        # zoom: 9 points across the bracket around the best sample, the bracket shrunk to
        # the two neighbouring points, six times (spacing 1/16 -> 1/16 / 4^6 of the interval)
        centre = tau[i[sel]]
        half = np.full(sel.size, 1.0 / samples)
        grid = np.linspace(-1.0, 1.0, 9)
        top_v = best[sel]
        for _ in range(6):
            s = np.clip(centre[:, None] + half[:, None] * grid[None, :], 0.0, 1.0)
            b0, b1, b2 = _hermite_rows(s, h)
            val = np.abs(np.einsum("ksi,ki->ks", b2 + damping * b1, y)
                         - (1.0 + excitation.q(base[:, None] + h * s))
                         * np.sin(np.einsum("ksi,ki->ks", b0, y)))
            j = np.argmax(val, axis=1)
            top_v = np.maximum(top_v, val[np.arange(sel.size), j])
            centre = s[np.arange(sel.size), j]
            half = half / 4
        out = best.copy()
        out[sel] = top_v
        return out

    def mean_square_speed(self) -> float:
        """``<theta'^2>`` by Gauss-Legendre quadrature (exact: a polynomial of degree 4)."""
        x, w = np.polynomial.legendre.leggauss(3)
        _, _, thd, _ = self.profile_on((x + 1) / 2)
        return float(np.sum(thd * thd * w) / (2 * self.intervals))


class HermiteProblem:
    """Objective and constraints of one PTO problem on ``K`` Hermite intervals.

    Parameters
    ----------
    excitation : Excitation
    intervals : int
        ``K``.
    damping : float
        gamma >= 0.
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

    def __init__(self, excitation, intervals: int, damping: float, *, torque_limit=None,
                 copper_loss: float = 0.0, phase1: bool = False,
                 elastic: float | None = None, winding: int = 1):
        self.excitation = excitation
        self.omega = om = excitation.omega
        self.k = k = int(intervals)
        self.damping = float(damping)
        self.period = period = 2 * math.pi / om
        self.h = h = period / k
        self.winding = int(winding)
        self.phase1 = phase1
        self.elastic = elastic
        self.border = "phase1" if phase1 else ("elastic" if elastic is not None else None)
        self.torque_limit = torque_limit
        self.grid_limit = torque_limit
        self.copper_loss = float(copper_loss)
        xg, wg = np.polynomial.legendre.leggauss(GAUSS_POINTS)
        self.tau_g = (xg + 1) / 2
        self.weight = np.tile(wg / 2 * h / period, (k, 1))  # mean = sum weight * f
        self.rows_g = _hermite_rows(self.tau_g, h)
        self.rows_c = _hermite_rows(TORQUE_TAU, h)
        b0g, b1g, _ = self.rows_g
        b0c = self.rows_c[0]

        def outer(a, b):
            return (a[:, :, None] * b[:, None, :]).reshape(a.shape[0], 16)

        self._g00, self._g01, self._g11 = outer(b0g, b0g), outer(b0g, b1g), outer(b1g, b1g)
        self._c00 = outer(b0c, b0c)
        base = h * np.arange(k)[:, None]
        self.q1_g = 1.0 + excitation.q(base + h * self.tau_g[None, :])
        self.q1_c = 1.0 + excitation.q(base + h * TORQUE_TAU[None, :])
        # torque rows, linear part: theta'' + gamma theta'
        self.lin_g = self.rows_g[2] + damping * self.rows_g[1]
        self.lin_c = self.rows_c[2] + damping * self.rows_c[1]
        # banded assembly of the 4x4 interval blocks (lower band, folded node order)
        pos = _fold(k)
        nxt = np.roll(np.arange(k), -1)
        gvar = np.stack([2 * pos, 2 * pos + 1, 2 * pos[nxt], 2 * pos[nxt] + 1], axis=1)
        self.n = n = 2 * k
        self.perm = np.empty(n, dtype=int)  # folded position of variable (node, component)
        self.perm[0::2] = 2 * pos
        self.perm[1::2] = 2 * pos + 1
        self.wrap = np.zeros((k, 4))
        self.wrap[-1, 2] = 2 * math.pi * self.winding
        self._next = nxt
        gi = np.repeat(gvar, 4, axis=1)  # row index of entry a*4+b
        gj = np.tile(gvar, (1, 4))
        keep = gi >= gj
        self._flat = ((gi - gj) * n + gj)[keep]
        self._sel = keep
        self._gvar = gvar

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

    # -- pointwise quantities --------------------------------------------------------------------
    def _at(self, y, rows, q1, lin):
        b0, b1, _ = rows
        th = y @ b0.T
        thd = y @ b1.T
        sn, cs = np.sin(th), np.cos(th)
        tq = y @ lin.T - q1 * sn
        return th, thd, sn, cs, tq

    def torque_points(self, x) -> np.ndarray:
        """``T`` at the constraint points, shape (K, 3)."""
        return self._at(self.local(x), self.rows_c, self.q1_c, self.lin_c)[4]

    def power(self, x) -> float:
        """Mean mechanical power ``P`` (Eq. 15, state form)."""
        _, thd, sn, _, _ = self._at(self.local(x), self.rows_g, self.q1_g, self.lin_g)
        return float(np.sum(self.weight * (self.q1_g * sn * thd - self.damping * thd * thd)))

    def electrical(self, x) -> float:
        """Mean power delivered after the copper loss, ``P - r <T^2>``."""
        _, thd, sn, _, tq = self._at(self.local(x), self.rows_g, self.q1_g, self.lin_g)
        e = self.q1_g * sn * thd - self.damping * thd * thd
        return float(np.sum(self.weight * (e - self.copper_loss * tq * tq)))

    # -- the pieces of the interior point --------------------------------------------------------
    def constraints(self, x, t=None):
        """The torque constraints ``c <= 0`` at the constraint points, flat."""
        if self.border is None and self.grid_limit is None:
            return np.zeros(0)
        tq = self._at(self.local(x), self.rows_c, self.q1_c, self.lin_c)[4]
        if self.phase1:
            return np.concatenate([(tq - t).ravel(), (-tq - t).ravel()])
        if self.elastic is not None:
            b = self.torque_limit + t
            return np.concatenate([(tq - b).ravel(), (-tq - b).ravel(), [-t]])
        lim = self.grid_limit
        return np.concatenate([(tq / lim - 1.0).ravel(), (-tq / lim - 1.0).ravel()])

    def constraint_step(self, dx, dt=None) -> np.ndarray:
        """``J d``: the linearized change of :meth:`constraints` along a step, at the point
        of the last :meth:`newton` call."""
        if self.border is None and self.grid_limit is None:
            return np.zeros(0)
        dy = self.local(dx) - self.wrap
        dtq = np.einsum("kci,ki->kc", self._jtc, dy)
        if self.phase1:
            return np.concatenate([(dtq - dt).ravel(), (-dtq - dt).ravel()])
        if self.elastic is not None:
            return np.concatenate([(dtq - dt).ravel(), (-dtq - dt).ravel(), [-dt]])
        lim = self.grid_limit
        return np.concatenate([(dtq / lim).ravel(), (-dtq / lim).ravel()])

    def barrier_count(self) -> int:
        """Number of barrier terms (the barrier's duality gap is this times ``mu``)."""
        n = 0
        if self.border is not None or self.grid_limit is not None:
            n += 2 * self.rows_c[0].shape[0] * self.k
        return n + (self.elastic is not None)

    def objective(self, x, mu: float = 0.0, t=None) -> float:
        """``phi`` to minimize: ``-(power)`` or, in phase 1, ``t`` (``mu`` unused: the
        barrier terms are added by :func:`interior_point`)."""
        if self.phase1:
            return float(t)
        y = self.local(x)
        _, thd, sn, _, tq = self._at(y, self.rows_g, self.q1_g, self.lin_g)
        f = np.sum(self.weight * (self.q1_g * sn * thd - self.damping * thd * thd))
        if self.copper_loss:
            f -= self.copper_loss * np.sum(self.weight * tq * tq)
        return -float(f) + (self.elastic * float(t) if self.elastic is not None else 0.0)

    def newton(self, x, t, lam, mu):
        """Banded Newton matrix and right-hand side of the barrier problem.

        Returns ``(ab, rhs, border, rhs_t, d_tt)``: ``ab`` the lower band of the Newton
        matrix in the folded order, ``rhs`` minus the barrier gradient, ``border`` the
        column ``M_xt`` and ``rhs_t``, ``d_tt`` its entries for ``t`` (phase 1).
        """
        k = self.k
        y = self.local(x)
        blocks = np.zeros((k, 4, 4))
        grad = np.zeros((k, 4))  # gradient of the barrier function in y
        b0g, b1g, _ = self.rows_g
        thg, thdg, sng, csg, tqg = self._at(y, self.rows_g, self.q1_g, self.lin_g)
        w = self.weight
        if not self.phase1:
            # f = q1 sin(th) th' - gamma th'^2, minimize -sum w f
            a = w * self.q1_g
            gf = (a * csg * thdg)[..., None] * b0g + ((a * sng) - 2 * self.damping * w *
                                                     thdg)[..., None] * b1g
            grad -= gf.sum(1)
            hb = -((a * sng * thdg) @ self._g00).reshape(k, 4, 4)
            cross = ((a * csg) @ self._g01).reshape(k, 4, 4)
            hb += cross + cross.transpose(0, 2, 1)
            hb -= 2 * self.damping * (w @ self._g11).reshape(k, 4, 4)
            blocks -= hb
            if self.copper_loss:
                r = self.copper_loss
                jtg = self.lin_g[None] - (self.q1_g * csg)[..., None] * b0g[None]
                grad += 2 * r * np.einsum("kg,kgi->ki", w * tqg, jtg)
                blocks += 2 * r * (np.einsum("kg,kgi,kgj->kij", w, jtg, jtg)
                                   + ((w * tqg * self.q1_g * sng) @ self._g00).reshape(k, 4, 4))
        border = None
        rhs_t = d_tt = 0.0
        if self.border is not None or self.grid_limit is not None:
            b0c = self.rows_c[0]
            _, _, snc, csc, tqc = self._at(y, self.rows_c, self.q1_c, self.lin_c)
            jtc = self.lin_c[None] - (self.q1_c * csc)[..., None] * b0c[None]  # dT/dy
            self._jtc = jtc
            htc = self.q1_c * snc  # d2T/dy2 = htc b0 b0^T
            n_c = tqc.size
            if self.border is not None:
                scale = 1.0
                b = t if self.phase1 else self.torque_limit + t
                sp, sm = b - tqc, b + tqc
            else:
                scale = 1.0 / self.grid_limit
                sp, sm = 1.0 - tqc * scale, 1.0 + tqc * scale
            lp = lam[:n_c].reshape(tqc.shape)
            lm = lam[n_c:2 * n_c].reshape(tqc.shape)
            # c+- = +-scale T - (t or 1): grad c+- = +-scale jt, hess c+- = +-scale hess T
            grad += np.einsum("kc,kci->ki", scale * (mu / sp - mu / sm), jtc)
            sig = (lp / sp + lm / sm) * scale * scale
            blocks += (jtc * sig[..., None]).transpose(0, 2, 1) @ jtc
            blocks += ((scale * (lp - lm) * htc) @ self._c00).reshape(k, 4, 4)
            if self.border is not None:
                # grad_t c+- = -1 (and, elastic, c_t = -t)
                border = -np.einsum("kc,kci->ki", lp / sp - lm / sm, jtc)
                d_tt = float(np.sum(lp / sp + lm / sm))
                g_t = 1.0 - float(np.sum(mu / sp + mu / sm))
                if self.elastic is not None:
                    d_tt += float(lam[-1]) / t
                    g_t += self.elastic - 1.0 - mu / t
                rhs_t = -g_t
        n = self.n
        nb = _BAND + 1
        ab = np.bincount(self._flat, weights=blocks.reshape(k, 16)[self._sel],
                         minlength=nb * n)[:nb * n].reshape(nb, n)
        g = np.bincount(self._gvar.ravel(), weights=grad.ravel(), minlength=n)
        if border is not None:
            border = np.bincount(self._gvar.ravel(), weights=border.ravel(), minlength=n)
        return ab, -g, border, rhs_t, d_tt


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


def _solve(ab, rhs, border, rhs_t, d_tt, delta):
    """Solve the (bordered) banded system by LAPACK's banded Cholesky (dpbtrf/dpbtrs);
    LinAlgError when ``ab + delta I`` is not positive definite."""
    a = ab.copy()
    a[0] += delta
    c, info = dpbtrf(a, lower=1)
    if info != 0:
        raise LinAlgError("not positive definite")
    if border is None:
        return dpbtrs(c, rhs, lower=1)[0], 0.0
    both = dpbtrs(c, np.stack([rhs, border], axis=1), lower=1)[0]
    # the border's Schur complement is positive in exact arithmetic (the phase-1 matrix is
    # J^T Sigma J + ... with J = [J_x, -1]); cancellation may leave it at roundoff
    schur = max(d_tt + delta - border @ both[:, 1], 1e-12 * (d_tt + delta))
    dt = (rhs_t - border @ both[:, 0]) / schur
    return both[:, 0] - both[:, 1] * dt, dt


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
                dx_f, dt = _solve(ab, rhs, border, rhs_t, d_tt, delta)
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
        dx = dx_f[pr.perm]
        slope = -float(rhs @ dx_f) - (rhs_t * dt if border is not None else 0.0)
        # -slope is the Newton decrement squared: about twice the distance of the barrier
        # function to its minimum at this mu
        # (floored at the precision to which the barrier function can be compared)
        if -slope <= max(2e-2 * m * mu, 1e-12 * (1.0 + abs(phi))) or stagnant >= 5:
            if mu <= mu_min * (1 + 1e-12):
                status = "converged"
                break
            if mu > mu_min * (1 + 1e-12):
                mu = max(mu_min, min(0.2 * mu, mu**1.5))
            phi = pr.objective(x, mu, t)
            stagnant = 0
            continue
        b0 = phi - mu * float(np.sum(np.log(s)))
        # fraction to the boundary on the linearized slacks (s + alpha ds >= (1 - tau) s)
        ds = -pr.constraint_step(dx, dt)
        neg = ds < 0
        alpha = min(1.0, float(np.min(_FRACTION * s[neg] / -ds[neg]))) if np.any(neg) else 1.0
        for _ in range(50):
            xn = x + alpha * dx
            tn = None if t is None else t + alpha * dt
            cn = pr.constraints(xn, tn)
            if not cn.size or np.max(cn) < 0:
                sn = -cn
                if np.all(sn > 0.1 * (1 - _FRACTION) * s):
                    phin = pr.objective(xn, mu, tn)
                    bn = phin - mu * float(np.sum(np.log(sn)))
                    if bn <= b0 + 1e-4 * alpha * min(slope, 0.0) or abs(bn - b0) <= 1e-15 * (
                            1 + abs(b0)):
                        break
            alpha *= 0.5
        else:
            status = "stalled"
            break
        if lam.size:  # dual step, fraction to the boundary
            dlam = mu / s - lam - lam / s * ds  # mu/s - lam + Sigma J dx
            neg = dlam < 0
            amax = 1.0
            if np.any(neg):
                amax = min(1.0, float(np.min(-_FRACTION * lam[neg] / dlam[neg])))
            lam = np.clip(lam + amax * dlam, 1e-30, None)
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


def _elastic(excitation, damping, k, x, torque_limit, copper_loss, winding, stages):
    """Elastic mode from ``x``: ``|T| <= L + t``, ``t >= 0``, penalty ``M t``, ``M`` raised
    tenfold until ``t`` vanishes (at most ``1e5``); ``L`` a little below the limit so that
    the optimum is strictly inside. Returns ``(x, t, iterations)``."""
    weight = 10.0 * max(1.0, excitation.omega)
    t, iters = None, 0
    while True:
        el = HermiteProblem(excitation, k, damping, torque_limit=torque_limit * (1 - 1e-4),
                            copper_loss=copper_loss, elastic=weight, winding=winding)
        sol = interior_point(el, x, t=t)
        iters += sol.iterations
        stages.append(("elastic", weight, sol.t, sol.status))
        x, t = sol.x, sol.t
        if t < 1e-5 * torque_limit or weight >= 1e5 or sol.status == "infeasible_start":
            return x, t, iters
        weight *= 10.0
        t = t * 1.5 + 1e-3 * torque_limit  # strictly inside again


def minimum_peak_torque(excitation, damping: float, intervals: int, start, *,
                        stop_below: float | None = None, winding: int = 1):
    """Phase 1: the rotation of smallest peak torque near ``start`` (a motion).

    Returns ``(HermiteSolution, problem)``; ``solution.t`` is the peak at the constraint
    points (``stop_below``: stop once it is below that).
    """
    pr = HermiteProblem(excitation, intervals, damping, phase1=True, winding=winding)
    x0 = pr.start(start)
    sol = interior_point(pr, x0, stop_below=stop_below)
    sol.peak_torque = pr.motion(sol.x).peak_torque(excitation, damping)
    sol.intervals = intervals
    return sol, pr


def solve_hermite(excitation, damping: float, intervals: int, start, *, torque_limit=None,
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
    pr = HermiteProblem(excitation, k, damping, torque_limit=torque_limit,
                        copper_loss=copper_loss, winding=winding)
    x = pr.start(start)
    stages = []
    iters = 0
    x_start = x
    if torque_limit is not None:
        if anchor is None:
            _, phi = uniform_power(excitation, damping)
            anchor = FourierMotion(excitation.omega, phi, np.zeros(1), np.zeros(1))
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
        xe, te, it_e = _elastic(excitation, damping, k, x_start, torque_limit, copper_loss,
                                winding, stages)
        iters += it_e
        if not te < 1e-5 * torque_limit:
            # the limit is not met near the start: the smallest peak near it (phase 1)
            ph1, _ = minimum_peak_torque(excitation, damping, k, pr.motion(xe),
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
    peaks = motion.interval_peaks(excitation, damping, torque_limit)
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
        lim[over, 0] *= (torque_limit / peaks[over]) ** 2 * (1 - 0.1 * tol)
        pr.grid_limit = lim
        x = _blend_feasible(pr, sol.x, xa)
        if x is None:  # the anchor is not inside the tightened limits: a new one, or stop
            ph1, _ = minimum_peak_torque(excitation, damping, k, pr.motion(xa),
                                         stop_below=float(np.min(lim)) * (1 - 1e-3),
                                         winding=winding)
            iters += ph1.iterations
            x = _blend_feasible(pr, sol.x, ph1.x) if ph1.t < np.min(lim) else None
            if x is None:
                break
            xa = ph1.x
        sol = interior_point(pr, x, mu0=1e-4 * abs(pr.objective(x)) / pr.barrier_count())
        iters += sol.iterations
        stages.append(("tighten", float(np.min(lim)), sol.status))
        motion = pr.motion(sol.x)
        peaks = motion.interval_peaks(excitation, damping, torque_limit)
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
