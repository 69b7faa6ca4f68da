"""The controlled pendulum of paper Eqs. 14 and 20 and the torque a motion requires.

Angle ``theta`` from the upright, non-dimensional time (unit ``sqrt(l/g)``)::

    theta'' + gamma*theta' - (1 + q(t))*sin(theta) = T(t)          (Eq. 14 / Eq. 20)

``T`` is the torque applied by the power take-off (control included): positive ``T``
drives the pendulum forward.
"""

from __future__ import annotations

import numpy as np

__all__ = ["peak_torque", "rhs", "torque"]


def torque(motion, excitation, gamma: float, t):
    """Torque ``T(t)`` that makes the pendulum follow ``motion`` exactly (Eq. 14 solved for T).

    Parameters
    ----------
    motion : object with ``theta``, ``theta_dot``, ``theta_ddot``
    excitation : Excitation
    gamma : float
        Viscous damping >= 0 (Eq. 14), non-dimensional.
    t : array_like
        Times (non-dimensional).
    """
    th = motion.theta(t)
    return (motion.theta_ddot(t) + gamma * motion.theta_dot(t)
            - (1.0 + excitation.q(t)) * np.sin(th))


def _sample_points(motion, excitation) -> int:
    """Uniform samples per period that resolve a Fourier motion's torque: a power of two
    with at least 16 points per top harmonic of the motion and of ``q``, at most 2^20.

    The cap bounds memory (a square wave's spectrum reaches 2^20 harmonics: 16 points each
    took 2.4 GB); ``q`` enters the torque only through its value, which is bounded, so
    missing its sharpest jumps can only miss the instant, not a larger peak of ``q``.
    """
    k = max(int(getattr(motion, "harmonics", 0)), int(np.size(excitation.spectrum)) - 1, 256)
    return min(1 << int(np.ceil(np.log2(16 * k))), 1 << 20)


def peak_torque(motion, excitation, gamma: float, points: int | None = None) -> float:
    """``max |T(t)|`` over one period, taken from the motion's own resolution.

    The samples come from the motion itself: a motion with its own ``peak_torque`` (the
    time-domain PTO's Hermite motion, whose torque jumps at the nodes) gives it; a motion
    with ``sample_times()`` (the BVP's
    spectral elements: points inside every element, so a boundary layer a thousandth of the
    period wide is sampled as finely as the rest) gives its own; a Fourier motion is
    sampled by inverse FFTs on a grid with 16 points per top harmonic
    (``FourierMotion.on_grid``; ``points`` overrides) and ``q`` by a folded inverse FFT
    (``Excitation.q_uniform``: O(M log M) time, O(M + K) memory for K harmonics). The
    largest sample is then refined by a bounded scalar search between its neighbours.
    """
    from scipy.optimize import minimize_scalar

    if hasattr(motion, "peak_torque"):
        return motion.peak_torque(excitation, gamma)
    period = 2 * np.pi / motion.omega
    if points is None and hasattr(motion, "sample_times"):
        t = np.asarray(motion.sample_times(), dtype=float)
        tq = np.abs(torque(motion, excitation, gamma, t))
    else:
        points = points or _sample_points(motion, excitation)
        t = period * np.arange(points) / points
        if hasattr(motion, "on_grid") and points > 2 * motion.harmonics:
            th, thd, thdd = motion.on_grid(points)
            tq = np.abs(thdd + gamma * thd
                        - (1.0 + excitation.q_uniform(points)) * np.sin(th))
        else:
            tq = np.abs(torque(motion, excitation, gamma, t))
    i = int(np.argmax(tq))
    lo = t[i - 1] if i > 0 else t[-1] - period
    hi = t[i + 1] if i + 1 < t.size else t[0] + period
    r = minimize_scalar(lambda x: -abs(float(torque(motion, excitation, gamma, x))),
                        bounds=(lo, hi), method="bounded",
                        options={"xatol": 1e-12 * period})
    return float(max(tq[i], -r.fun))


def rhs(excitation, gamma: float, control=None):
    """Right-hand side ``f(t, y)``, ``y = (theta, theta')``, of Eq. 14 for ``solve_ivp``.

    ``control(t, theta, theta_dot)`` gives the applied torque (zero if None).
    """

    def f(t, y):
        th, om = y
        tq = 0.0 if control is None else control(t, th, om)
        return np.array([om, (1.0 + excitation.q(t)) * np.sin(th) - gamma * om + tq])

    return f
