r"""The constant brake: a rotation under the constant torque ``T = -T_max``.

Under a torque limit, a rotation that never turns back (``theta' > 0``) extracts at most

    P = -<T theta'> <= T_max <|theta'|> = T_max <theta'> = K omega T_max

(Eq. 15, ``K`` turns per forcing period), with equality only when ``T = -T_max`` at every
instant: the constant brake. When a period-``K`` rotation of Eq. 14 under that constant
torque exists, it attains the bound of every monotone rotation. For small limits it is the
torque-limited optimum, and the cubic Hermite solver (:mod:`parapend.optimal.hermite`)
approaches it only like ``K^-2``: a piecewise cubic cannot keep ``T`` constant, every
interval bulges between its constraint points, and the tightening that pushes the bulges
under the limit costs power (0.1799992 of the bound 0.18 at 2048 intervals, gamma = 0.01,
``T_max = 0.1``).

The rotation is solved here directly: the Fourier series of Eq. 10 (``theta = K s + a0 +
sum a_n sin(n s) + b_n cos(n s)``, ``s = omega t``) collocated at ``2N + 1`` points of one
period, Newton's method on Eq. 14 with ``T = -T_max``,

    R(t_j) = theta'' + gamma theta' - (1 + q) sin(theta) + T_max = 0,

``N`` doubled until the coefficients move by less than ``1e-12``. The motion is analytic,
so the coefficients fall geometrically and the torque of the Fourier motion is ``-T_max``
to rounding on its own dense evaluation.
"""

from __future__ import annotations

import math

import numpy as np

from ..trajectory import FourierMotion, SampledMotion

__all__ = ["constant_brake"]


def _residual(x, n, omega, gamma, q1, s, torque_limit, winding):
    """Eq. 14 residual at the collocation phases ``s`` and its Jacobian in ``x``."""
    k = np.arange(1, n + 1)
    ks = np.multiply.outer(s, k)
    sn, cs = np.sin(ks), np.cos(ks)
    a, b = x[1:n + 1], x[n + 1:]
    th = winding * s + x[0] + sn @ a + cs @ b
    thd = omega * (winding + cs @ (k * a) - sn @ (k * b))
    thdd = -omega**2 * (sn @ (k * k * a) + cs @ (k * k * b))
    r = thdd + gamma * thd - q1 * np.sin(th) + torque_limit
    jac = np.empty((s.size, 2 * n + 1))
    c = -q1 * np.cos(th)
    jac[:, 0] = c
    jac[:, 1:n + 1] = (-omega**2 * k * k) * sn + (gamma * omega * k) * cs + c[:, None] * sn
    jac[:, n + 1:] = (-omega**2 * k * k) * cs - (gamma * omega * k) * sn + c[:, None] * cs
    return r, jac


def _newton(x, n, omega, gamma, q1, s, torque_limit, winding, maxiter=50):
    scale = max(1.0, torque_limit)
    for _ in range(maxiter):
        r, jac = _residual(x, n, omega, gamma, q1, s, torque_limit, winding)
        norm = float(np.max(np.abs(r)))
        if not math.isfinite(norm):
            return x, False
        if norm <= 1e-13 * scale:
            return x, True
        try:
            dx = np.linalg.solve(jac, -r)
        except np.linalg.LinAlgError:
            return x, False
        alpha = 1.0
        while alpha > 1e-4:  # backtracking on the residual's max norm
            r2, _ = _residual(x + alpha * dx, n, omega, gamma, q1, s, torque_limit, winding)
            if np.max(np.abs(r2)) < norm:
                break
            alpha *= 0.5
        else:
            return x, False
        x = x + alpha * dx
    r, _ = _residual(x, n, omega, gamma, q1, s, torque_limit, winding)
    return x, bool(np.max(np.abs(r)) <= 1e-10 * scale)


def multipliers(motion, excitation, gamma: float) -> np.ndarray:
    """Floquet multipliers of a rotation under a constant torque: the eigenvalues of the
    monodromy matrix of Eq. 14 linearized about it, ``d(dtheta)/dt = dv``,
    ``d(dv)/dt = (1 + q) cos(theta) dtheta - gamma dv`` (SciPy DOP853 over one period)."""
    from scipy.integrate import solve_ivp

    def rhs(t, y):
        c = (1.0 + excitation.q(t)) * math.cos(float(motion.theta(t)))
        return [y[2], y[3], c * y[0] - gamma * y[2], c * y[1] - gamma * y[3]]

    y = solve_ivp(rhs, (0.0, 2 * math.pi / excitation.omega), [1.0, 0.0, 0.0, 1.0],
                  method="DOP853", rtol=1e-10, atol=1e-12).y[:, -1]
    return np.linalg.eigvals(y.reshape(2, 2))


def constant_brake(excitation, gamma: float, torque_limit: float, start, *,
                   winding: int = 1, max_harmonics: int = 1024, phases: int = 8):
    """The rotation under the constant torque ``-torque_limit``: Newton's method from
    ``start`` (a motion near it, e.g. the torque-limited optimum) and from the uniform
    rotations ``theta = K omega t + phi`` at ``phases`` phases.

    Every such rotation has the power ``K omega T_max``; there may be several (a saddle
    and a stable focus of the forced pendulum: two at ``gamma = 0.01``,
    ``T_max = 0.063``, Floquet multipliers 3.59 and 0.27 against a complex pair of modulus
    ``exp(-gamma T_p / 2)``).
    The one returned has the smallest largest multiplier: the one a controller holds most
    easily (docs/control.md).

    Returns ``(motion, harmonics, change)``: a :class:`FourierMotion` with ``theta' > 0``
    everywhere, its number of harmonics and the largest coefficient change at the last
    doubling; or None when no start converges (no such rotation, e.g. a limit too large to
    be sustained) or every rotation found turns back.
    """
    omega = excitation.omega
    starts = [start] + [FourierMotion(omega, 2 * math.pi * j / phases, np.zeros(1),
                                      np.zeros(1), winding) for j in range(phases)]
    found = []
    for st in starts:
        f = _one_brake(excitation, gamma, torque_limit, st, winding, max_harmonics)
        if f is None:
            continue
        t0 = np.array([0.0])
        key = (float(np.mod(f[0].theta(t0)[0], 2 * math.pi)), float(f[0].theta_dot(t0)[0]))
        if any(abs(key[0] - k[0]) < 1e-6 and abs(key[1] - k[1]) < 1e-6 for k, _ in found):
            continue
        found.append((key, f))
    if not found:
        return None
    if len(found) == 1:
        return found[0][1]
    worst = [float(np.max(np.abs(multipliers(f[0], excitation, gamma)))) for _, f in found]
    return found[int(np.argmin(worst))][1]


def _one_brake(excitation, gamma, torque_limit, start, winding, max_harmonics):
    """Newton's method from one start (:func:`constant_brake`), ``N`` doubled until the
    coefficients settle."""
    omega = excitation.omega
    period = 2 * math.pi / omega
    m = 4096
    t = period * np.arange(m) / m
    proj = SampledMotion(omega, start.theta(t) - (winding - 1) * omega * t).to_fourier()
    n = max(16, 4 * (int(np.size(excitation.spectrum)) - 1))
    prev = None
    while n <= max_harmonics:
        # start: the projection of the start motion, then the last resolution's solution
        src = np.concatenate(([proj.a0], proj.a, proj.b)) if prev is None else prev
        pn = (src.size - 1) // 2
        take = min(n, pn)
        x0 = np.zeros(2 * n + 1)
        x0[0] = src[0]
        x0[1:take + 1] = src[1:take + 1]
        x0[n + 1:n + 1 + take] = src[pn + 1:pn + 1 + take]
        s = 2 * math.pi * np.arange(2 * n + 1) / (2 * n + 1)
        q1 = 1.0 + excitation.q(s / omega)
        x, ok = _newton(x0, n, omega, gamma, q1, s, torque_limit, winding)
        if not ok:
            return None
        if prev is not None:
            change = float(np.max(np.abs(x - x0)))
            if change <= 1e-12:
                motion = FourierMotion(omega, float(x[0]), x[1:n + 1].copy(),
                                       x[n + 1:].copy(), winding)
                grid = np.linspace(0.0, period, 8 * n + 1)
                if float(np.min(motion.theta_dot(grid))) <= 0.0:
                    return None
                return motion, n, change
        prev = x
        n *= 2
    return None
