r"""The horizon problem of the receding-horizon controller with the motion as the unknown.

On the horizon ``[t, t + H]`` the angle is a ``C^1`` piecewise cubic Hermite on ``K``
uniform intervals of ``h = H / K`` (nodes ``theta_k, v_k = theta'(t + k h)``, ``k = 0..K``),
the first node fixed to the measured state, the end free. The torque is defined by the
motion, Eq. 14 solved for it (inverse dynamics)::

    T = theta'' + gamma theta' - (1 + q) sin(theta)

so there are no dynamics constraints. The objective (maximized) is the electrical work plus
the terminal value ``kappa E(t + H)``, ``E = theta'^2 / 2 + cos(theta)``. With the energy
balance of Eq. 14, ``W = E(t) - E(t + H) + int (q sin(theta) theta' - gamma theta'^2)``
(mechanical work harvested, ``p = -T theta'``), and the efficiency model
``e(p) = eta_g p - (1 / eta_m - eta_g) max(-p, 0)`` of :mod:`parapend.pto`::

    J = eta_g E(t) + eta_g int (q sin(theta) theta' - gamma theta'^2) dt
        + (kappa - eta_g) E(t + H) - (1 / eta_m - eta_g) int max(T theta', 0) dt

For ``kappa = eta_g`` (the default) the terminal term vanishes and, without an efficiency,
``J`` is the integral plus a constant: first derivatives only, whose Euler-Lagrange equation
is ``2 gamma theta'' = q' sin(theta)`` with the natural end condition
``q sin(theta) = 2 gamma theta'`` at ``t + H``. The integrals are evaluated by the 4-point
Gauss-Legendre rule on every interval.

**Terminal value under a torque limit.** ``terminal="limited"`` replaces ``kappa E(t + H)``
by ``kappa V(E)``, ``V`` the energy a torque ``T_max`` harvests braking the rotation against
the damping (:meth:`PlanProblem.terminal_value`, docs/control.md); ``V -> E`` without a
limit.

**Least priced damping.** ``plan_damping=c`` makes the objective price the damping
``max(gamma, c) theta'^2`` while the torque keeps the model's ``gamma``. Without a torque
limit and at ``gamma = 0`` the objective depends on the motion only through ``int q sin(theta)
theta' dt``, whose supremum is the ``gamma -> 0`` limit's instant flips: the problem has no
optimum and its Newton iterates drift to ever faster turns (the receding horizon of
:mod:`.mpc` ran away to ``|theta'| ~ 2e4``); a small priced damping gives it one.

**Rated speed.** ``speed_limit=w_max`` adds the exterior penalty ``rho / 2 h sum_k
max(|v_k| - w_max, 0)^2`` over the free nodes (a generator's rated speed, the machine's
bound; docs/control.md: the controller harvests without it, and it costs power). A penalty,
not a constraint of the interior point: the measured state may lie above the bound (the
swing-up's catch, a wave group), where a hard bound on the path would have no feasible plan.

**Efficiency.** The kink of ``max(z, 0)`` (``z = T theta'``, the power motored) is smoothed,
``(z + sqrt(z^2 + eps^2)) / 2`` (above the kink by at most ``eps / 2``), with continuation
``eps = 1e-2, 1e-3, 1e-4`` (each solve warm-started from the last). A slack per Gauss point
(as :mod:`parapend.optimal.collocation` does with the torque as a variable) would make the
objective exact but adds ``4 K`` variables and ``8 K`` constraints that break the banded
Newton matrix of the eliminated torque; the smoothing keeps it, and its bias on ``J`` is at
most ``(1 / eta_m - eta_g) eps H / 2``.

**Solver.** The primal-dual interior point of :mod:`parapend.optimal.hermite`
(``parapend.optimal.hermite.interior_point``, its compiled kernels
:mod:`parapend.optimal._hermite_kernel` on the open chain of ``K + 1`` nodes) with the
torque limit ``|T| <= T_max`` at ``tau = 0, 1/2, 1`` of every interval; without a limit it
is Newton's method with the exact banded Hessian (bandwidth 3: the first node's two
variables removed), inertia correction and an Armijo line search. The smoothed kink and the
terminal value are added to the kernel's objective, gradient and Newton matrix here.
:meth:`PlanProblem.solve_compiled` runs the same iteration as one compiled call
(:mod:`parapend.control._plan_kernel`, used by :func:`solve_plan` outside elastic mode).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..optimal import _hermite_kernel as _k
from ..optimal.hermite import (
    GAUSS_POINTS,
    TORQUE_TAU,
    HermiteSolution,
    _blend_feasible,
    _hermite_rows,
    interior_point,
)

__all__ = ["HorizonPlan", "PlanProblem", "gauss_leads", "solve_plan"]

#: weight ``rho`` of the rated-speed penalty ``rho / 2 h sum max(|v_k| - w_max, 0)^2``
SPEED_WEIGHT = 100.0
#: penalty ``M`` per unit length of the elastic mode that repairs a start outside the limit
ELASTIC_WEIGHT = 100.0
#: smoothing of the efficiency's kink, in turn (continuation)
KINK_SMOOTHING = (1e-2, 1e-3, 1e-4)
_TAU_G = (np.polynomial.legendre.leggauss(GAUSS_POINTS)[0] + 1) / 2


def gauss_leads(k: int, h: float):
    """Lead times of the Gauss points ``(K, 4)`` and of the torque points ``(K, 3)``."""
    j = np.arange(k)[:, None]
    return h * (j + _TAU_G[None, :]), h * (j + TORQUE_TAU[None, :])


@dataclass(frozen=True, eq=False)
class HorizonPlan:
    """A planned motion: Hermite nodes ``theta_k, v_k`` at ``k h``, ``k = 0..K`` (time from
    the horizon's start), the excitation ``q`` of the plan (a callable of the lead time),
    ``gamma``."""

    h: float
    theta: np.ndarray
    v: np.ndarray
    gamma: float

    @property
    def intervals(self) -> int:
        return int(self.theta.size - 1)

    @property
    def horizon(self) -> float:
        return self.h * self.intervals

    def evaluate(self, s):
        """``theta, theta', theta''`` at lead times ``s`` (clipped to the horizon)."""
        s = np.clip(np.asarray(s, dtype=float), 0.0, self.horizon)
        k = self.intervals
        j = np.minimum(np.floor(s / self.h), k - 1).astype(int)
        tau = s / self.h - j
        b0, b1, b2 = _hermite_rows(tau, self.h)
        y = np.stack([self.theta[j], self.v[j], self.theta[j + 1], self.v[j + 1]], axis=-1)
        return (np.sum(b0 * y, axis=-1), np.sum(b1 * y, axis=-1), np.sum(b2 * y, axis=-1))

    def torque(self, s, q):
        """Eq. 14's torque at lead times ``s`` given ``q`` there."""
        th, thd, thdd = self.evaluate(s)
        return thdd + self.gamma * thd - (1.0 + np.asarray(q, dtype=float)) * np.sin(th)

    def energy_end(self) -> float:
        return 0.5 * float(self.v[-1]) ** 2 + math.cos(float(self.theta[-1]))


class PlanProblem:
    """One horizon problem (the interface ``parapend.optimal.hermite.interior_point``
    uses); the variables ``x = (theta_1, v_1, ..., theta_K, v_K)``, node 0 fixed to ``x0``.

    Parameters
    ----------
    x0 : (theta, theta')
        The measured state at the horizon's start.
    h : float
        Interval length.
    q_g, q_c : ndarray (K, 4), (K, 3)
        ``q`` at the Gauss points and at the torque points (:func:`gauss_leads`).
    gamma : float
    torque_limit : float or None
    efficiency : (eta_g, eta_m) or None
    kappa : float or None
        Terminal weight (None: ``eta_g``).
    elastic : float or None
        Elastic mode: ``|T| <= torque_limit + t``, ``t >= 0``, penalty ``elastic t``.
    terminal : {"energy", "limited"}
        The terminal value ``kappa V(E)`` (:meth:`terminal_value`).
    speed_limit : float or None
        Rated speed ``w_max``: the penalty :meth:`speed_penalty` on the nodes' speeds above
        it (None: none).
    speed_weight : float or None
        Its ``rho`` (None: ``SPEED_WEIGHT``, 100).
    plan_damping : float
        Least damping the objective prices (module docstring); the torque keeps ``gamma``.
    """

    phase1 = False

    def __init__(self, x0, h, q_g, q_c, gamma, *, torque_limit=None, efficiency=None,
                 kappa=None, elastic=None, smoothing=KINK_SMOOTHING[-1], terminal="energy",
                 speed_limit=None, speed_weight=None, plan_damping=0.0):
        self.x0 = np.asarray(x0, dtype=float).copy()
        self.q_g = np.ascontiguousarray(q_g, dtype=float)
        self.q_c = np.ascontiguousarray(q_c, dtype=float)
        self.k = k = self.q_g.shape[0]
        self.h = float(h)
        self.gamma = float(gamma)
        self.plan_damping = float(plan_damping)
        # the damping the objective prices (the torque keeps the model's gamma)
        self.gamma_objective = max(self.gamma, self.plan_damping)
        eg, em = (1.0, 1.0) if efficiency is None else (float(efficiency[0]),
                                                        float(efficiency[1]))
        self.efficiency = efficiency
        self.eta_g = eg
        self.kink = max(1.0 / em - eg, 0.0)
        self.kappa = eg if kappa is None else float(kappa)
        if terminal not in ("energy", "limited"):
            raise ParameterError(f"terminal: expected energy or limited, got {terminal!r:.40}")
        self.terminal = terminal
        # the scale T_max / gamma of the limited terminal value (inf: kappa E)
        self._a = (float(torque_limit) / float(gamma)
                   if terminal == "limited" and torque_limit is not None and gamma > 0
                   else math.inf)
        self.smoothing = float(smoothing)
        self.speed_limit = None if speed_limit is None else float(speed_limit)
        self.speed_weight = (SPEED_WEIGHT if speed_weight is None else float(speed_weight))
        xg, wg = np.polynomial.legendre.leggauss(GAUSS_POINTS)
        self.w = wg / 2 * self.h  # the integral over one interval
        self.wk = eg * self.w  # the kernel's objective weights (its q1g is q here)
        self.rows_g = _hermite_rows(_TAU_G, self.h)
        self.rows_c = _hermite_rows(TORQUE_TAU, self.h)
        self.lin_g = self.rows_g[2] + self.gamma * self.rows_g[1]
        self.lin_c = self.rows_c[2] + self.gamma * self.rows_c[1]
        self.q1_g = 1.0 + self.q_g
        self.q1_c = np.ascontiguousarray(1.0 + self.q_c)
        self.elastic = elastic
        self.torque_limit = torque_limit
        if elastic is not None:
            self.mode = _k.ELASTIC
        elif torque_limit is not None:
            self.mode = _k.LIMIT
        else:
            self.mode = _k.NONE
        lim = 1.0 if torque_limit is None else float(torque_limit)
        self._scale = np.full(k, 1.0 / lim)
        self._gvar = (2 * np.arange(k)[:, None] + np.arange(4)[None, :]).astype(np.int64)
        self._jtc = np.zeros((k, TORQUE_TAU.size, 4))
        self.n = 2 * k
        self.perm = np.arange(self.n)

    # -- variables -----------------------------------------------------------------------------
    def full(self, x):
        return np.concatenate((self.x0, np.asarray(x, dtype=float)))

    def plan(self, x) -> HorizonPlan:
        f = self.full(x)
        return HorizonPlan(self.h, f[0::2].copy(), f[1::2].copy(), self.gamma)

    def start(self, theta, v) -> np.ndarray:
        """Variables from nodes ``theta_k, v_k`` (k = 0..K; node 0 is replaced by x0)."""
        x = np.empty(self.n)
        x[0::2] = np.asarray(theta, dtype=float)[1:]
        x[1::2] = np.asarray(v, dtype=float)[1:]
        return x

    # -- the terms added to the kernel's ------------------------------------------------------
    def _local(self, f):
        return np.stack([f[0:-2:2], f[1:-2:2], f[2::2], f[3::2]], axis=1)

    def terminal_value(self, e):
        """``V(E)``, ``V'(E)``, ``V''(E)`` of the terminal value ``kappa V(E)``: ``V = E`` (the
        default), or with ``terminal="limited"`` the energy the limited torque extracts,
        ``V = a w - a^2 log(1 + w / a) - 1``, ``w = sqrt(2 (E + 1))``, ``a = T_max / gamma``
        (``V' = a / (a + w)``; ``V -> E`` as ``a -> inf``)."""
        a = self._a
        if not math.isfinite(a):
            return e, 1.0, 0.0
        w = math.sqrt(max(2.0 * (e + 1.0), 1e-12))
        return (a * w - a * a * math.log1p(w / a) - 1.0, a / (a + w),
                -a / ((a + w) ** 2 * w))

    def _extra(self, f):
        """``terminal + kink`` of the minimized objective at the full variables ``f``."""
        e_end = 0.5 * f[-1] ** 2 + math.cos(f[-2])
        if math.isfinite(self._a):
            val = -(self.kappa * self.terminal_value(e_end)[0] - self.eta_g * e_end)
        else:
            d = self.kappa - self.eta_g
            val = -d * e_end if d else 0.0
        if self.kink:
            y = self._local(f)
            th = y @ self.rows_g[0].T
            thd = y @ self.rows_g[1].T
            z = (y @ self.lin_g.T - self.q1_g * np.sin(th)) * thd
            e = self.smoothing
            val += self.kink * float(np.sum((z + np.sqrt(z * z + e * e)) * 0.5 * self.w))
        if self.speed_limit is not None:
            val += self.speed_penalty(f)
        return val

    def speed_penalty(self, f):
        """The rated-speed penalty ``rho / 2 h sum_k max(|v_k| - w_max, 0)^2`` over the
        free nodes ``k = 1..K`` of the full variables ``f``."""
        r = np.maximum(np.abs(f[3::2]) - self.speed_limit, 0.0)
        return 0.5 * self.speed_weight * self.h * float(np.sum(r * r))

    def _speed_args(self):
        """``(w_max, rho h)`` of the compiled kernel (``w_max = inf``: no rated speed)."""
        if self.speed_limit is None:
            return math.inf, 0.0
        return self.speed_limit, self.speed_weight * self.h

    def _speed_newton(self, f, ab, rhs):
        v = f[3::2]
        r = np.maximum(np.abs(v) - self.speed_limit, 0.0)
        c = self.speed_weight * self.h
        rhs[3::2] -= c * r * np.sign(v)
        ab[0, 3::2] += c * (r > 0)

    def _extra_newton(self, f, ab, rhs):
        """Add the gradient (to ``rhs``, minus) and Hessian (to the band ``ab``, full
        order) of :meth:`_extra`."""
        th, v = f[-2], f[-1]
        _, v1, v2 = self.terminal_value(0.5 * v * v + math.cos(th))
        d = self.kappa * v1 - self.eta_g
        c = self.kappa * v2
        if d or c:
            sn = math.sin(th)
            rhs[-2] -= d * sn
            rhs[-1] += d * v
            ab[0, -2] += d * math.cos(th) - c * sn * sn
            ab[0, -1] -= d + c * v * v
            ab[1, -2] += c * sn * v
        if self.speed_limit is not None:
            self._speed_newton(f, ab, rhs)
        if not self.kink:
            return
        b0, b1, _ = self.rows_g
        lin = self.lin_g
        y = self._local(f)
        th = y @ b0.T
        thd = y @ b1.T
        sn, cs = np.sin(th), np.cos(th)
        tq = y @ lin.T - self.q1_g * sn
        z = tq * thd
        e = self.smoothing
        r = np.sqrt(z * z + e * e)
        f1 = 0.5 * (1.0 + z / r) * self.kink * self.w
        f2 = 0.5 * e * e / r**3 * self.kink * self.w
        dt = lin[None, :, :] - (self.q1_g * cs)[:, :, None] * b0[None, :, :]  # (K, G, 4)
        dz = thd[:, :, None] * dt + tq[:, :, None] * b1[None, :, :]
        grad = np.einsum("kg,kga->ka", f1, dz)
        hess = (np.einsum("kg,kga,kgb->kab", f2, dz, dz)
                + np.einsum("kg,kga,gb->kab", f1, dt, b1)
                + np.einsum("kg,ga,kgb->kab", f1, b1, dt)
                + np.einsum("kg,ga,gb->kab", f1 * thd * self.q1_g * sn, b0, b0))
        k = self.k
        for a in range(4):
            rhs[a:a + 2 * k:2] -= grad[:, a]
            for b in range(a + 1):
                ab[a - b, b:b + 2 * k:2] += hess[:, a, b]

    # -- the interface of interior_point ------------------------------------------------------
    def torque_points(self, x):
        return _k.torques(self.full(x), self.k, 0.0, self.rows_c[0], self.lin_c, self.q1_c)

    def constraints(self, x, t=None):
        return _k.constraints(self.full(x), 0.0 if t is None else float(t), self.k, 0.0,
                              self.rows_c[0], self.lin_c, self.q1_c, self.mode, self._scale,
                              float(self.torque_limit or 0.0))

    def constraint_step(self, dx, dt=None):
        return _k.constraint_step(np.concatenate((np.zeros(2), dx)),
                                  0.0 if dt is None else float(dt), self.k, self._jtc,
                                  self.mode, self._scale)

    def jt_apply(self, w):
        gx, gt = _k.jt_apply(w, self.k, self._jtc, self.mode, self._scale, self._gvar)
        return gx[2:], gt

    def barrier_count(self) -> int:
        if self.mode == _k.NONE:
            return 0
        return 2 * TORQUE_TAU.size * self.k + (self.mode == _k.ELASTIC)

    def _kernel_power(self, f):
        return _k.power_terms(f, self.k, 0.0, self.rows_g[0], self.rows_g[1], self.lin_g,
                              self.q_g, self.wk, self.gamma_objective)[0]

    def objective(self, x, mu: float = 0.0, t=None) -> float:
        """The minimized ``-(J - eta_g E(t))`` (plus ``elastic t`` in elastic mode)."""
        f = self.full(x)
        phi = -float(self._kernel_power(f)) + self._extra(f)
        return phi + (self.elastic * float(t) if self.elastic is not None else 0.0)

    def value(self, x) -> float:
        """``J``: the electrical work over the horizon plus ``kappa E(t + H)``."""
        e0 = 0.5 * self.x0[1] ** 2 + math.cos(self.x0[0])
        f = self.full(x)
        return self.eta_g * e0 + float(self._kernel_power(f)) - self._extra(f)

    def trial(self, x, dx, alpha, t, dt, s, mu, floor):
        ok, bn, xn, tn, sn, phi = _k.trial(
            self.full(x), np.concatenate((np.zeros(2), dx)), float(alpha),
            0.0 if t is None else float(t), 0.0 if dt is None else float(dt), s, float(mu),
            float(floor), self.k, 0.0, self.rows_g[0], self.rows_g[1], self.lin_g, self.q_g,
            self.wk, self.gamma_objective, 0.0, self.rows_c[0], self.lin_c, self.q1_c,
            self.mode, self._scale, float(self.torque_limit or 0.0), float(self.elastic or 0.0))
        if ok:
            ex = self._extra(xn)
            bn += ex
            phi += ex
        return ok, bn, xn[2:], tn, sn, phi

    def solve_compiled(self, x, *, gap_tol=1e-10, maxiter=200, mu0=None) -> HermiteSolution:
        """``parapend.optimal.hermite.interior_point`` on this problem as one compiled
        call (``parapend.control._plan_kernel.solve``; not in elastic mode)."""
        if self.mode == _k.ELASTIC:
            raise ValueError("solve_compiled: elastic mode is solved by interior_point")
        from . import _plan_kernel as _pk

        xs, st, it, mu = _pk.solve(
            np.ascontiguousarray(x, dtype=float), self.x0, self.k, self.rows_g[0],
            self.rows_g[1], self.lin_g, self.q_g, self.wk, self.gamma_objective, self.rows_c[0],
            self.lin_c, self.q1_c, self.mode == _k.LIMIT, self._scale,
            np.ascontiguousarray(self.q1_g), self.w, self.kappa,
            self.eta_g, self._a, self.kink, self.smoothing, *self._speed_args(),
            float(gap_tol), int(maxiter),
            math.nan if mu0 is None else float(mu0))
        return HermiteSolution(xs, None, _pk.STATUS[st], int(it), float(mu))

    def newton(self, x, t, lam, mu):
        f = self.full(x)
        ab, rhs, border, rhs_t, d_tt = _k.newton(
            f, 0.0 if t is None else float(t), np.asarray(lam, dtype=float), float(mu), self.k,
            0.0, self.rows_g[0], self.rows_g[1], self.lin_g, self.q_g, self.wk,
            self.gamma_objective, 0.0, self.rows_c[0], self.lin_c, self.q1_c, self.mode,
            self._scale, float(self.torque_limit or 0.0), float(self.elastic or 0.0), self._gvar,
            self._jtc)
        self._extra_newton(f, ab, rhs)
        ab = np.ascontiguousarray(ab[:4, 2:])
        if self.mode == _k.ELASTIC:
            return ab, rhs[2:], border[2:], float(rhs_t), float(d_tt)
        return ab, rhs[2:], None, 0.0, 0.0


@dataclass
class PlanSolution:
    """Outcome of :func:`solve_plan`: the variables, the plan, ``J`` (:meth:`PlanProblem.value`),
    the status of the last interior-point solve and the Newton iterations in all."""

    x: np.ndarray
    plan: HorizonPlan
    value: float
    status: str
    iterations: int
    success: bool


def free_motion(x0, h, k, gamma, q_nodes):
    """Nodes of the unforced motion (``T = 0``) from ``x0``: RK4, one step per interval,
    ``q_nodes`` at ``0, h/2, h, ...`` (``2 K + 1``). A strictly feasible anchor of the torque
    limit when ``h`` resolves the motion."""
    th = np.empty(k + 1)
    v = np.empty(k + 1)
    th[0], v[0] = x0
    for j in range(k):
        a, b = th[j], v[j]
        q0, qm, q1 = q_nodes[2 * j], q_nodes[2 * j + 1], q_nodes[2 * j + 2]

        def rhs(p, w, q):
            return w, (1.0 + q) * math.sin(p) - gamma * w

        k1 = rhs(a, b, q0)
        k2 = rhs(a + h / 2 * k1[0], b + h / 2 * k1[1], qm)
        k3 = rhs(a + h / 2 * k2[0], b + h / 2 * k2[1], qm)
        k4 = rhs(a + h * k3[0], b + h * k3[1], q1)
        th[j + 1] = a + h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        v[j + 1] = b + h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
    return th, v


def solve_plan(problem: PlanProblem, x, *, anchor=None, gap_tol=1e-10, maxiter=200,
               mu0=None) -> PlanSolution:
    """The horizon optimum from the start ``x`` (variables).

    Without a torque limit: Newton (the interior point without barrier terms). With one: a
    start that violates the limit is repaired where it lies: elastic mode from it (``|T| <=
    T_max (1 - 1e-4) + t``, ``t >= 0``, penalty ``M t``), stopped as soon as ``t < 0.5e-4
    T_max`` (then strictly inside); only if that fails, blended towards ``anchor``
    (variables strictly inside, e.g. the unforced motion). A warm start (the previous plan
    shifted) leaves the limit only in its first interval, by the measured state's departure
    from the plan; the repair keeps it, where a blend towards the unforced motion would move
    it far (docs/control.md). With an efficiency, the kink's smoothing is continued
    (``KINK_SMOOTHING``).
    """
    pr = problem
    x = np.asarray(x, dtype=float)
    iters = 0
    if pr.mode == _k.LIMIT:
        if np.max(pr.constraints(x)) >= 0:
            el = PlanProblem(pr.x0, pr.h, pr.q_g, pr.q_c, pr.gamma,
                             torque_limit=pr.torque_limit * (1 - 1e-4),
                             efficiency=pr.efficiency, kappa=pr.kappa,
                             elastic=ELASTIC_WEIGHT * max(1.0, pr.h), smoothing=pr.smoothing,
                             terminal=pr.terminal, speed_limit=pr.speed_limit,
                             speed_weight=pr.speed_weight, plan_damping=pr.plan_damping)
            sol = interior_point(el, x, maxiter=maxiter,
                                 stop_below=0.5e-4 * pr.torque_limit)
            iters += sol.iterations
            xb = sol.x
            if np.max(pr.constraints(xb)) >= 0:
                xb = None if anchor is None else _blend_feasible(pr, x, np.asarray(anchor))
                if xb is None:
                    return PlanSolution(sol.x, pr.plan(sol.x), pr.value(sol.x), "infeasible",
                                        iters, False)
            x = xb
    eps_seq = [e for e in KINK_SMOOTHING if e > pr.smoothing] + [pr.smoothing] \
        if pr.kink else [pr.smoothing]
    final = pr.smoothing
    sol = None
    for e in eps_seq:
        pr.smoothing = e
        sol = pr.solve_compiled(x, gap_tol=gap_tol, maxiter=maxiter, mu0=mu0)
        iters += sol.iterations
        x = sol.x
    pr.smoothing = final
    ok = sol.status == "converged"
    return PlanSolution(sol.x, pr.plan(sol.x), pr.value(sol.x), sol.status, iters, ok)
