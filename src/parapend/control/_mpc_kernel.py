"""Compiled (numba) plant of the receding-horizon controller (:mod:`.mpc`).

The state ``x = (theta, v)`` of Eq. 14,
``theta' = v, v' = (1 + q(t)) sin(theta) - gamma v + T``, integrated by RK4 with ``S`` steps
of ``h`` per torque sample (the torque ``u_j`` held over sample ``j``); ``q`` is given at the
half-step nodes, ``qn[2 i]`` at step ``i``'s start and ``qn[2 i + 1]`` at its midpoint.
"""

from __future__ import annotations

import math

import numba as nb

from .._jit import announce_compiles

announce_compiles()  # log a first-use compile (parapend._jit)


@nb.njit(cache=True)
def _rk4(th, v, u, q0, qm, q1, h, gamma):
    k1t = v
    k1v = (1.0 + q0) * math.sin(th) - gamma * v + u
    bt = th + 0.5 * h * k1t
    bv = v + 0.5 * h * k1v
    k2t = bv
    k2v = (1.0 + qm) * math.sin(bt) - gamma * bv + u
    ct = th + 0.5 * h * k2t
    cv = v + 0.5 * h * k2v
    k3t = cv
    k3v = (1.0 + qm) * math.sin(ct) - gamma * cv + u
    dt_ = th + h * k3t
    dv = v + h * k3v
    k4t = dv
    k4v = (1.0 + q1) * math.sin(dt_) - gamma * dv + u
    return (th + h / 6.0 * (k1t + 2.0 * k2t + 2.0 * k3t + k4t),
            v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v))


@nb.njit(cache=True)
def simulate(u, th0, v0, qn, h, steps, gamma, th, v):
    """Integrate the held torques ``u`` (``steps`` RK4 steps each) and return the states at
    the sample boundaries in ``th, v`` (``len(u) + 1``); False if the state left
    ``|v| < 1e6``."""
    a = th0
    b = v0
    th[0] = a
    v[0] = b
    for j in range(u.size):
        for s in range(steps):
            i = j * steps + s
            a, b = _rk4(a, b, u[j], qn[2 * i], qn[2 * i + 1], qn[2 * i + 2], h, gamma)
        th[j + 1] = a
        v[j + 1] = b
        if not abs(b) < 1e6:
            return False
    return True
