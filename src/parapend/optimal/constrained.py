r"""A realistic power take-off: torque limit and generator efficiency on the Fourier problem.

The motion is the truncated Fourier rotation of paper Eq. 10, packed as
``x = [a0, a_1..a_N, b_1..b_N]``. On ``M`` uniform points ``s_j = 2 pi j / M`` of one period
the torque of the motion is (Eq. 14 solved for T)::

    T_j = theta''_j + gamma theta'_j - (1 + q_j) sin(theta_j)

It is linear in ``x`` through ``theta''`` and ``theta'`` and nonlinear only through
``sin(theta)``, so with the basis ``phi = (1, sin ns, cos ns)`` its derivatives are cheap::

    dT_j/dx     = omega^2 phi''_j + gamma omega phi'_j - (1 + q_j) cos(theta_j) phi_j
    d2T_j/dx dx = (1 + q_j) sin(theta_j) phi_j phi_j^T

The instantaneous mechanical power taken by the machine is ``p = -T theta'`` (positive when
harvested); its mean is the paper's ``P`` (Eq. 15).

Objective (maximized), with exact gradient and Hessian:

- mechanical: ``P(x)`` from :class:`~parapend.optimal.fourier.FourierProblem` (Eq. 15);
- electrical (``efficiency=(eta_g, eta_m)``): ``<e(p)>`` with ``e(p) = eta_g p`` for
  ``p > 0`` and ``p / eta_m`` for ``p < 0``. ``e`` has a kink at ``p = 0``; it is smoothed as
  ``e_w(p) = p / eta_m + (eta_g - 1/eta_m) w softplus(p / w)``, which is within
  ``|eta_g - 1/eta_m| w log 2`` of ``e`` everywhere, and ``w`` is continued from ``1`` to
  ``1e-7`` (power units), each stage warm-started from the last. The reported electrical
  power is that of the *unsmoothed* ``e`` at the final motion;
- copper loss (``copper_loss=r``): ``- r <T^2>`` (winding loss ``R (T/k_t)^2``, ``r`` its
  non-dimensional coefficient ``R/k_t^2 (m g l)^2 / power unit``), subtracted from the
  electrical power (or from ``P`` if no efficiency is given).

Torque limit ``|T(t)| <= T_max``: an augmented Lagrangian (Powell-Hestenes-Rockafellar, for
inequalities; Nocedal & Wright, Eq. 17.65) of the normalized constraints
``c_j = +-T_j / T_max - 1 <= 0`` at every grid point, weighted ``1/M`` (so the multipliers
approximate a constraint-force density)::

    F(x) = obj(x) - 1/(2 rho M) sum_j [max(0, lam_j + rho c_j)^2 - lam_j^2]

maximized by :func:`~parapend.optimal.fourier.newton_maximize` (safeguarded Newton on the
exact generalized Hessian), then ``lam <- max(0, lam + rho c)`` and ``rho`` raised when the
violation does not fall by 4. Warm-started from the unconstrained optimum, and along a
curve in ``T_max`` from the previous (larger) limit. The limit is then checked on the
motion's own dense evaluation (:func:`~parapend.model.peak_torque`): where the peak between
grid points exceeds ``T_max`` the grid limit is tightened by the excess and the solve
repeated, so the returned motion satisfies ``|T| <= T_max (1 + 1e-9)`` everywhere.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..model import peak_torque
from ..trajectory import FourierMotion
from .fourier import FourierProblem, _pad, newton_maximize

__all__ = ["PTOProblem", "PTOSolution", "pto_profile", "solve_pto"]


def _softplus(z: np.ndarray):
    """``log(1 + e^z)``, the logistic ``sigma(z)`` and ``sigma (1 - sigma)``, overflow-safe."""
    sp = np.logaddexp(0.0, z)
    sig = np.exp(z - sp)  # e^z / (1 + e^z)
    return sp, sig, sig * np.exp(-sp)  # sigma * (1 - sigma), 1 - sigma = e^{-sp}


def _grid_points(harmonics: int, excitation) -> int:
    k = max(16 * (2 * harmonics + 1), 2 * min(excitation.spectrum.size, 4 * harmonics + 8))
    return max(1024, 1 << int(math.ceil(math.log2(k))))


class PTOProblem:
    """Objective of one power take-off problem, with exact gradient and Hessian.

    Parameters
    ----------
    excitation : Excitation
    harmonics : int
        N >= 1 (Eq. 10).
    damping : float
        gamma >= 0 (Eq. 14).
    torque_limit : float or None
        ``T_max`` in units of ``m g l``; None for no limit.
    efficiency : (float, float) or None
        ``(eta_g, eta_m)`` in (0, 1]: generating and motoring efficiencies; None for the
        mechanical power.
    copper_loss : float
        ``r >= 0`` of the winding loss ``r T^2`` (power units per torque unit squared).
    points : int or None
        Grid points ``M`` (a power of two, at least 1024 and 32 N).

    Attributes ``w``, ``points``, ``power`` and ``evaluate`` make it a drop-in for
    :func:`~parapend.optimal.fourier.newton_maximize`.
    """

    def __init__(self, excitation, harmonics: int, damping: float, *,
                 torque_limit: float | None = None, efficiency=None, copper_loss: float = 0.0,
                 points: int | None = None):
        self.excitation = excitation
        self.omega = om = excitation.omega
        self.harmonics = n = harmonics
        self.damping = damping
        self.points = m = points or _grid_points(n, excitation)
        self.base = FourierProblem(excitation, n, damping, m)
        self.w = self.base.w
        self.s = s = 2 * np.pi * np.arange(m) / m
        k = np.arange(1, n + 1)
        ks = np.multiply.outer(s, k)
        sn, cs = np.sin(ks), np.cos(ks)
        one = np.ones((m, 1))
        zero = np.zeros((m, 1))
        self.phi = np.hstack((one, sn, cs))
        self.dphi = np.hstack((zero, k * cs, -k * sn))  # d/ds
        self.ddphi = np.hstack((zero, -(k * k) * sn, -(k * k) * cs))
        self.lin = om * om * self.ddphi + damping * om * self.dphi  # dT/dx, linear part
        self.q1 = 1.0 + excitation.q_uniform(m)
        self.torque_limit = torque_limit
        self.grid_limit = torque_limit
        self.efficiency = None if efficiency is None else (float(efficiency[0]),
                                                             float(efficiency[1]))
        self.copper_loss = float(copper_loss)
        self.width = 1.0
        self.rho = 10.0
        self.lam_plus = np.zeros(m)
        self.lam_minus = np.zeros(m)

    # -- motion on the grid -------------------------------------------------------------------
    def state(self, x: np.ndarray):
        """``theta, theta', T`` on the grid (radians, 1/time, m g l)."""
        om = self.omega
        th = self.s + self.phi @ x
        thd = om * (1.0 + self.dphi @ x)
        tq = om * om * (self.ddphi @ x) + self.damping * thd - self.q1 * np.sin(th)
        return th, thd, tq

    def electrical(self, x: np.ndarray, exact: bool = True) -> float:
        """Mean electrical power ``<e(p)> - r <T^2>`` (``exact``: the unsmoothed ``e``)."""
        _, thd, tq = self.state(x)
        p = -tq * thd
        if self.efficiency is not None:
            eg, em = self.efficiency
            if exact:
                e = np.where(p > 0, eg * p, p / em)
            else:
                e = p / em + (eg - 1.0 / em) * self.width * _softplus(p / self.width)[0]
        else:
            e = p
        return float(np.mean(e) - self.copper_loss * np.mean(tq * tq))

    def violation(self, x: np.ndarray) -> float:
        """``max(|T_j| / T_max - 1, 0)`` on the grid (0 without a limit)."""
        if self.torque_limit is None:
            return 0.0
        return max(float(np.max(np.abs(self.state(x)[2]))) / self.grid_limit - 1.0, 0.0)

    # -- objective ----------------------------------------------------------------------------
    def _terms(self, x, derivatives: bool):
        n2 = 2 * self.harmonics + 1
        m = self.points
        th, thd, tq = self.state(x)
        f = 0.0
        g = np.zeros(n2)
        h = np.zeros((n2, n2))
        plain = self.efficiency is None
        if plain:
            if derivatives:
                f, g, h = self.base.evaluate(x)
                g, h = g.copy(), h.copy()
            else:
                f = self.base.power(x)
        need_t = (not plain) or self.copper_loss or self.torque_limit is not None
        if not need_t:
            return f, g, h
        sn = np.sin(th)
        jt = self.lin - (self.q1 * np.cos(th))[:, None] * self.phi if derivatives else None
        ht = self.q1 * sn  # d2T_j = ht_j phi_j phi_j^T
        wsum = np.zeros(m)  # weights of phi phi^T (second derivative of T terms)
        if not plain:
            eg, em = self.efficiency
            kappa = eg - 1.0 / em
            wd = self.width
            p = -tq * thd
            sp, sig, dsig = _softplus(p / wd)
            f += float(np.mean(p / em + kappa * wd * sp))
            if derivatives:
                e1 = 1.0 / em + kappa * sig
                e2 = kappa * dsig / wd
                jp = -(thd[:, None] * jt + self.omega * tq[:, None] * self.dphi)
                g += jp.T @ e1 / m
                h += (jp.T * e2) @ jp / m
                cross = (self.omega * self.dphi.T * e1) @ jt / m
                h -= cross + cross.T
                wsum -= e1 * thd * ht
        if self.copper_loss:
            r = self.copper_loss
            f -= r * float(np.mean(tq * tq))
            if derivatives:
                g -= 2 * r * (jt.T @ tq) / m
                h -= 2 * r * (jt.T @ jt) / m
                wsum -= 2 * r * tq * ht
        if self.torque_limit is not None:
            lim, rho = self.grid_limit, self.rho
            cp = tq / lim - 1.0
            cm = -tq / lim - 1.0
            mp = np.maximum(0.0, self.lam_plus + rho * cp)
            mm = np.maximum(0.0, self.lam_minus + rho * cm)
            f -= float(np.sum(mp * mp - self.lam_plus**2 + mm * mm - self.lam_minus**2)
                       ) / (2 * rho * m)
            if derivatives:
                d = (mp - mm) / lim
                g -= jt.T @ d / m
                act = rho * ((mp > 0).astype(float) + (mm > 0)) / (lim * lim)
                h -= (jt.T * act) @ jt / m
                wsum -= d * ht
        if derivatives:
            h += (self.phi.T * (wsum / m)) @ self.phi
        return f, g, h

    def evaluate(self, x: np.ndarray):
        """``(F, gradient, Hessian)`` of the (smoothed, augmented) objective at ``x``."""
        return self._terms(x, True)

    def power(self, x: np.ndarray) -> float:
        """Objective ``F(x)`` only (the line search's value)."""
        return self._terms(x, False)[0]

    def update_multipliers(self, x: np.ndarray) -> None:
        """First-order multiplier update ``lam <- max(0, lam + rho c)``."""
        tq = self.state(x)[2]
        lim = self.grid_limit
        self.lam_plus = np.maximum(0.0, self.lam_plus + self.rho * (tq / lim - 1.0))
        self.lam_minus = np.maximum(0.0, self.lam_minus + self.rho * (-tq / lim - 1.0))


@dataclass(frozen=True)
class PTOSolution:
    """Outcome of :func:`solve_pto`.

    Attributes
    ----------
    x : ndarray, shape (2N+1,)
        Packed coefficients of Eq. 10.
    power : float
        Mean mechanical power ``P = -<T theta'>`` (Eq. 15), m g l / t0.
    electrical_power : float
        Mean electrical power with the unsmoothed efficiency model and the copper loss
        (equals ``power`` without either).
    peak_torque : float
        ``max |T|`` on the motion's dense evaluation, m g l.
    max_violation : float
        ``max(peak_torque / T_max - 1, 0)`` (0 without a limit).
    status : str
        "converged", "infeasible" (the limit could not be met: ``T_max`` is below the
        smallest peak torque of any period-1 rotation found), "stalled" or "max_iterations".
    iterations : int
        Newton iterations over all stages.
    outer_iterations : int
        Augmented-Lagrangian and smoothing stages.
    gradient_norm : float
        Max-norm of the gradient of the final stage's objective.
    """

    x: np.ndarray
    power: float
    electrical_power: float
    peak_torque: float
    max_violation: float
    status: str
    iterations: int
    outer_iterations: int
    gradient_norm: float
    points: int = 0
    stages: list = field(default_factory=list)


_CONTINUATION_HARMONICS = 24


def _inner(problem, x, gtol, maxiter):
    return newton_maximize(problem, x, "warm", gtol=gtol, maxiter=maxiter)


def solve_pto(excitation, harmonics: int, damping: float, x0: np.ndarray, *,
              torque_limit: float | None = None, efficiency=None, copper_loss: float = 0.0,
              tol: float = 1e-9, gtol: float = 1e-10, maxiter: int = 200,
              max_outer: int = 40, points: int | None = None) -> PTOSolution:
    """Optimal motion of a power take-off with a torque limit and/or losses.

    Parameters
    ----------
    excitation : Excitation
    harmonics : int
        N of Eq. 10.
    damping : float
        gamma >= 0.
    x0 : ndarray, shape (2N+1,)
        Start: the unconstrained optimum, or the solution at a nearby (larger) limit.
    torque_limit : float or None
        ``T_max`` (m g l).
    efficiency : (eta_g, eta_m) or None
        Generating and motoring efficiencies in (0, 1].
    copper_loss : float
        Coefficient ``r`` of the winding loss ``r T^2``.
    tol : float
        Feasibility: ``|T| <= T_max (1 + tol)`` on the dense evaluation.
    gtol : float
        Gradient tolerance of each Newton stage (relative to ``max |q'|``).

    Returns
    -------
    PTOSolution
    """
    x = np.array(x0, dtype=float)
    if harmonics > _CONTINUATION_HARMONICS:
        # continuation in N: from the unconstrained optimum with many harmonics (large,
        # oscillating instantaneous power) Newton creeps; the 24-harmonic PTO optimum,
        # padded, starts it within a few iterations of the answer
        small = solve_pto(excitation, _CONTINUATION_HARMONICS, damping,
                          _pad(x, _CONTINUATION_HARMONICS), torque_limit=torque_limit,
                          efficiency=efficiency, copper_loss=copper_loss, tol=tol, gtol=gtol,
                          maxiter=maxiter, max_outer=max_outer)
        x = _pad(small.x, harmonics)
    prob = PTOProblem(excitation, harmonics, damping, torque_limit=torque_limit,
                      efficiency=efficiency, copper_loss=copper_loss, points=points)
    iters = 0
    outer = 0
    stages = []
    status = "converged"
    last = None
    if efficiency is not None:
        # continuation of the smoothing width w (power units), from 1 to 1e-9
        for w in 10.0 ** -np.arange(0, 8):
            prob.width = float(w)
            if torque_limit is not None:
                last = _augmented(prob, x, gtol, maxiter, max_outer)
                x, it, out, status = last
                iters += it
                outer += out
            else:
                r = _inner(prob, x, gtol, maxiter)
                x, iters, outer = r.x, iters + r.iterations, outer + 1
                status = r.status
            stages.append(("width", float(w), prob.electrical(x)))
        # at the final widths Newton meets the kink (curvature ~ 1/w at p = 0) and may stop on
        # its iteration cap; the stage is converged when the exact electrical power no longer
        # moves between widths (by less than 10 |kappa| w; the smoothing error itself is below
        # |kappa| w log 2)
        kappa = abs(efficiency[0] - 1.0 / efficiency[1])
        if status in ("max_iterations", "stalled") and len(stages) > 1 and abs(
                stages[-1][2] - stages[-2][2]) <= max(1e-9, 10 * kappa * prob.width):
            status = "converged"
    elif torque_limit is not None:
        x, it, outer, status = _augmented(prob, x, gtol, maxiter, max_outer)
        iters += it
    else:
        r = _inner(prob, x, gtol, maxiter)
        x, iters, outer, status = r.x, r.iterations, 1, r.status

    motion = FourierMotion.from_vector(excitation.omega, x)
    peak = peak_torque(motion, excitation, damping, points=max(4096, 4 * prob.points))
    # dense check: tighten the grid limit by the excess between grid points
    for _ in range(5):
        if torque_limit is None or status == "infeasible" or peak <= torque_limit * (1 + tol):
            break
        prob.grid_limit *= (torque_limit / peak) * (1 - 0.1 * tol)
        x, it, out, status = _augmented(prob, x, gtol, maxiter, max_outer)
        iters += it
        outer += out
        motion = FourierMotion.from_vector(excitation.omega, x)
        peak = peak_torque(motion, excitation, damping, points=max(4096, 4 * prob.points))
    viol = 0.0 if torque_limit is None else max(peak / torque_limit - 1.0, 0.0)
    if torque_limit is not None and viol > tol and status == "converged":
        status = "infeasible"
    elif status == "infeasible" and viol <= tol:
        status = "stalled"  # feasible on the dense evaluation, multipliers not converged
    mech = prob.base.power(x)
    _, g, _ = prob.evaluate(x)
    return PTOSolution(x=x, power=float(mech), electrical_power=prob.electrical(x),
                       peak_torque=float(peak), max_violation=float(viol), status=status,
                       iterations=iters, outer_iterations=outer,
                       gradient_norm=float(np.max(np.abs(g))), points=prob.points,
                       stages=stages)


def _augmented(prob: PTOProblem, x, gtol, maxiter, max_outer):
    """Augmented-Lagrangian outer loop; returns ``(x, newton iterations, outer, status)``.

    Stops when the grid violation is below 1e-10 and the objective moved by less than
    1e-12 between two outer iterations; ``rho`` is raised tenfold (to at most 1e8) when
    the violation did not fall by 4. Multipliers and ``rho`` change only after an inner
    solve that converged (or stalled at its best point).
    """
    iters = 0
    viol_prev = math.inf
    f_prev = math.inf
    status = "max_iterations"
    k = 0
    unfinished = 0
    for _ in range(max_outer):
        k += 1
        r = _inner(prob, x, gtol, maxiter)
        x = r.x
        iters += r.iterations
        viol = prob.violation(x)
        f = prob.base.power(x) if prob.efficiency is None else prob.electrical(x, False)
        if r.status not in ("converged", "stalled") and unfinished < 1:
            # inner solve unfinished (iteration cap): continue it once before touching lam or
            # rho, else rho runs away on a violation that only reflects the unfinished solve
            # (at the smallest efficiency widths the kink keeps Newton below its tolerance,
            # so a second unfinished solve proceeds)
            unfinished += 1
            continue
        unfinished = 0
        prob.update_multipliers(x)
        if viol <= 1e-10 and abs(f - f_prev) <= 1e-12 * max(1.0, abs(f)):
            status = "converged"
            break
        f_prev = f
        if viol > 1e-10 and viol > 0.25 * viol_prev:
            if prob.rho >= 1e8:
                status = "infeasible" if viol > 1e-6 else "stalled"
                break
            prob.rho *= 10.0
        viol_prev = min(viol, viol_prev)
    return x, iters, k, status


def pto_profile(motion, excitation, damping: float, points: int = 4096,
                efficiency=None) -> dict:
    """Torque and power of a motion over one period, and what the machine must deliver.

    Parameters
    ----------
    motion : FourierMotion (or any motion with ``on_grid`` or theta/theta_dot/theta_ddot)
    excitation : Excitation
    damping : float
        gamma.
    points : int
        Uniform samples of one period.
    efficiency : (eta_g, eta_m) or None
        For the electrical power column.

    Returns
    -------
    dict
        Arrays ``t``, ``tau`` (= t/period), ``theta``, ``theta_dot``, ``torque`` (Eq. 14,
        m g l), ``power`` (``p = -T theta'``, positive harvested) and, with an efficiency,
        ``electrical_power``; scalars ``peak_torque`` (``max |T|``, dense), ``peak_power``
        (``max p``), ``peak_motoring_power`` (``max -p``, >= 0), ``harvested_energy``
        (``int max(p, 0) dt``) and ``motoring_energy`` (``int max(-p, 0) dt``, the energy put
        back into the pendulum each cycle), both m g l per forcing period.
    """
    period = excitation.period
    t = period * np.arange(points) / points
    if hasattr(motion, "on_grid") and points > 2 * motion.harmonics:
        th, thd, thdd = motion.on_grid(points)
    else:
        th, thd, thdd = motion.theta(t), motion.theta_dot(t), motion.theta_ddot(t)
    tq = thdd + damping * thd - (1.0 + excitation.q_uniform(points)) * np.sin(th)
    p = -tq * thd
    dt = period / points
    out = {"t": t, "tau": t / period, "theta": th, "theta_dot": thd, "torque": tq,
           "power": p,
           "peak_torque": peak_torque(motion, excitation, damping, points=points),
           "peak_power": float(np.max(p)), "peak_motoring_power": float(max(-np.min(p), 0.0)),
           "harvested_energy": float(np.sum(np.maximum(p, 0.0)) * dt),
           "motoring_energy": float(np.sum(np.maximum(-p, 0.0)) * dt)}
    if efficiency is not None:
        eg, em = efficiency
        out["electrical_power"] = np.where(p > 0, eg * p, p / em)
    return out
