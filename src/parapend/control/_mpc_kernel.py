"""Compiled (numba) kernels of the receding-horizon controller (:mod:`.mpc`).

The horizon problem: the state ``x = (theta, v)`` of Eq. 14,
``theta' = v, v' = (1 + q(t)) sin(theta) - gamma v + T``, integrated by RK4 with ``S`` steps
of ``h`` per torque sample (the torque ``u_j`` held over sample ``j``); ``q`` is given at the
half-step nodes, ``qn[2 i]`` at step ``i``'s start and ``qn[2 i + 1]`` at its midpoint.

Objective (minimized; the negative of what is harvested):

    f(u) = -sum_i e(-u_{j(i)} (theta_{i+1} - theta_i)) - kappa (v_N^2 / 2 + cos theta_N)

with ``e(p) = eta_g p`` for ``p > 0`` (generating) and ``p / eta_m`` otherwise (motoring),
summed over the RK4 steps ``i`` (the work of the held torque over a step is exact given the
step's end states), and the terminal value ``kappa E(x_N)`` (docs/control.md). Its gradient
is the exact discrete adjoint of the RK4 steps: one forward pass storing the step states, one
backward pass through each step's stages (``J^T`` of ``f`` at each stage, recomputed).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

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
def _rk4_adjoint(th, v, u, q0, qm, q1, h, gamma, lt, lv):
    """Reverse-mode of one RK4 step: given the adjoint ``(lt, lv)`` of the step's end state,
    return the adjoint of its start state and the derivative with respect to ``u``."""
    k1t = v
    k1v = (1.0 + q0) * math.sin(th) - gamma * v + u
    bt = th + 0.5 * h * k1t
    bv = v + 0.5 * h * k1v
    k2v = (1.0 + qm) * math.sin(bt) - gamma * bv + u
    ct = th + 0.5 * h * bv
    cv = v + 0.5 * h * k2v
    dt_ = th + h * cv
    # adjoints of the stages
    g1t = h / 6.0 * lt
    g1v = h / 6.0 * lv
    g2t = h / 3.0 * lt
    g2v = h / 3.0 * lv
    g3t = h / 3.0 * lt
    g3v = h / 3.0 * lv
    g4t = h / 6.0 * lt
    g4v = h / 6.0 * lv
    gxt = lt
    gxv = lv
    gu = 0.0
    # k4 = f(d)
    gdt = (1.0 + q1) * math.cos(dt_) * g4v
    gdv = g4t - gamma * g4v
    gu += g4v
    # d = x + h k3
    gxt += gdt
    gxv += gdv
    g3t += h * gdt
    g3v += h * gdv
    # k3 = f(c)
    gct = (1.0 + qm) * math.cos(ct) * g3v
    gcv = g3t - gamma * g3v
    gu += g3v
    gxt += gct
    gxv += gcv
    g2t += 0.5 * h * gct
    g2v += 0.5 * h * gcv
    # k2 = f(b)
    gbt = (1.0 + qm) * math.cos(bt) * g2v
    gbv = g2t - gamma * g2v
    gu += g2v
    gxt += gbt
    gxv += gbv
    g1t += 0.5 * h * gbt
    g1v += 0.5 * h * gbv
    # k1 = f(x)
    gxt += (1.0 + q0) * math.cos(th) * g1v
    gxv += g1t - gamma * g1v
    gu += g1v
    return gxt, gxv, gu


@nb.njit(cache=True)
def objective(u, th0, v0, qn, h, steps, gamma, eta_g, eta_m, kappa, grad, th, v):
    """``f(u)`` (module docstring); its gradient in ``grad``; the step states in ``th, v``
    (``len(u) steps + 1`` each)."""
    n = u.size
    m = n * steps
    th[0] = th0
    v[0] = v0
    f = 0.0
    for j in range(n):
        for s in range(steps):
            i = j * steps + s
            th[i + 1], v[i + 1] = _rk4(th[i], v[i], u[j], qn[2 * i], qn[2 * i + 1],
                                       qn[2 * i + 2], h, gamma)
            p = -u[j] * (th[i + 1] - th[i])
            f -= eta_g * p if p > 0.0 else p / eta_m
    f -= kappa * (0.5 * v[m] * v[m] + math.cos(th[m]))
    # adjoint
    lt = kappa * math.sin(th[m])
    lv = -kappa * v[m]
    for j in range(n - 1, -1, -1):
        gj = 0.0
        for s in range(steps - 1, -1, -1):
            i = j * steps + s
            dth = th[i + 1] - th[i]
            p = -u[j] * dth
            w = eta_g if p > 0.0 else 1.0 / eta_m
            # f -= w p, p = -u (th_{i+1} - th_i)
            gj += w * dth
            lt += w * u[j]          # d f / d th_{i+1}
            at, av, au = _rk4_adjoint(th[i], v[i], u[j], qn[2 * i], qn[2 * i + 1],
                                      qn[2 * i + 2], h, gamma, lt, lv)
            lt = at - w * u[j]      # d f / d th_i from the step's work
            lv = av
            gj += au
        grad[j] = gj
    return f


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


def work(n: int, steps: int):
    """Scratch arrays for :func:`objective`."""
    return np.empty(n), np.empty(n * steps + 1), np.empty(n * steps + 1)
