"""The controlled pendulum of paper Eqs. 14 and 20 and the torque a motion requires.

Angle ``theta`` from the upright, non-dimensional time (unit ``sqrt(l/g)``)::

    theta'' + gamma*theta' - (1 + q(t))*sin(theta) = T(t)          (Eq. 14 / Eq. 20)

``T`` is the torque applied by the power take-off (control included): positive ``T``
drives the pendulum forward.
"""

from __future__ import annotations

import numpy as np

__all__ = ["peak_torque", "rhs", "torque"]


def torque(motion, excitation, damping: float, t):
    """Torque ``T(t)`` that makes the pendulum follow ``motion`` exactly (Eq. 14 solved for T).

    Parameters
    ----------
    motion : object with ``theta``, ``theta_dot``, ``theta_ddot``
    excitation : Excitation
    damping : float
        Viscous damping ``gamma`` >= 0.
    t : array_like
        Times (non-dimensional).
    """
    th = motion.theta(t)
    return (motion.theta_ddot(t) + damping * motion.theta_dot(t)
            - (1.0 + excitation.q(t)) * np.sin(th))


def peak_torque(motion, excitation, damping: float, points: int = 4096) -> float:
    """``max |T(t)|`` over one period: the largest of ``points`` uniform samples, refined by a
    bounded scalar search around it.

    Fourier motions are sampled by inverse FFTs (``FourierMotion.on_grid``) and ``q`` by a
    folded inverse FFT (``Excitation.q_uniform``): O(M log M) time and O(M + K) memory for a
    spectrum of K harmonics (no dense K x M matrix). Other motions are sampled pointwise.
    """
    from scipy.optimize import minimize_scalar

    period = 2 * np.pi / motion.omega
    t = period * np.arange(points) / points
    if hasattr(motion, "on_grid") and points > 2 * motion.harmonics:
        th, thd, thdd = motion.on_grid(points)
        tq = np.abs(thdd + damping * thd - (1.0 + excitation.q_uniform(points)) * np.sin(th))
    else:
        tq = np.abs(torque(motion, excitation, damping, t))
    i = int(np.argmax(tq))
    h = period / points
    r = minimize_scalar(lambda x: -abs(float(torque(motion, excitation, damping, x))),
                        bounds=(t[i] - h, t[i] + h), method="bounded",
                        options={"xatol": 1e-10 * period})
    return float(max(tq[i], -r.fun))


def rhs(excitation, damping: float, control=None):
    """Right-hand side ``f(t, y)``, ``y = (theta, theta')``, of Eq. 14 for ``solve_ivp``.

    ``control(t, theta, theta_dot)`` gives the applied torque (zero if None).
    """

    def f(t, y):
        th, om = y
        tq = 0.0 if control is None else control(t, th, om)
        return np.array([om, (1.0 + excitation.q(t)) * np.sin(th) - damping * om + tq])

    return f
