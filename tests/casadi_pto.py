"""Independent formulation of the power take-off problems: CasADi + IPOPT direct collocation.

Hermite-Simpson collocation (separated form) of the controlled pendulum, Eq. 14,
``theta' = v, v' = -gamma v + (1 + q(t)) sin(theta) + T``, with the torque ``T`` as the
control at every node and midpoint, over one forcing period, periodic up to one turn
(``theta(T_p) = theta(0) + 2 pi``, ``v(T_p) = v(0)``). It shares nothing with parapend's
solvers but the excitation's ``q(t)``; :mod:`parapend.optimal.collocation` solves this
same discrete problem with its own interior point (tests/test_collocation.py compares
them at equal K):

- torque limit: the bounds ``-T_max <= T <= T_max`` on the control;
- efficiency: exact (not smoothed), with slacks ``p = p+ - p-``, ``p+, p- >= 0`` and the
  objective ``eta_g p+ - p- / eta_m`` (since ``eta_g <= 1/eta_m``, at the optimum one of
  the two slacks is zero: the kink needs no smoothing here);
- the mean is Simpson's rule over the nodes and midpoints; the torque is piecewise linear
  (its midpoint value is the mean of the nodes': a free midpoint torque lets a bang-bang
  torque exploit the rule and overshoot the true optimum), and the mechanical power is
  the state form of Eq. 15, ``<(1 + q) sin(theta) theta'> - gamma <theta'^2>``.

Used by the cross-check tests and by ``benchmarks/bench_pto.py``.
"""

from __future__ import annotations

import math

import numpy as np


def collocate(excitation, gamma: float, *, intervals: int = 200, torque_limit=None,
              efficiency=None, guess=None, tol: float = 1e-10, winding: int = 1,
              max_iter: int = 3000, copper_loss: float = 0.0):
    """Maximize the mean (electrical) power by direct collocation.

    Parameters
    ----------
    guess : callable ``t -> (theta, v, T)`` or None
        Initial guess; None starts from the best uniform rotation (Eq. 17).
    winding : int
        K turns per period: ``theta(T_p) = theta(0) + 2 pi K`` (records of irregular seas).
    copper_loss : float
        ``r`` of a winding loss ``r <T^2>`` subtracted from the electrical power (Simpson's
        rule: exact for the piecewise-linear torque); with it and no efficiency the power
        is the mean of ``-T v``, not the state form.

    Returns
    -------
    dict with ``power`` (mechanical, Simpson mean of ``-T v``), ``electrical_power``
    (after the efficiency and the copper loss),
    ``peak_torque`` (over nodes), ``status`` (IPOPT's return status), ``t``, ``theta``,
    ``v``, ``torque`` (nodes and midpoints, ``2 K + 1`` points), ``solve_time`` (s, IPOPT
    only, the graph built before it).
    """
    import casadi as ca

    from parapend.power import uniform_power

    k = intervals
    om = excitation.omega
    period = 2 * math.pi / om
    h = period / k
    t = np.linspace(0.0, period, 2 * k + 1)  # nodes at even, midpoints at odd indices
    q1 = 1.0 + excitation.q(t)
    opti = ca.Opti()
    th = opti.variable(2 * k + 1)
    v = opti.variable(2 * k + 1)
    u = opti.variable(2 * k + 1)

    def f(i):
        return v[i], -gamma * v[i] + q1[i] * ca.sin(th[i]) + u[i]

    for j in range(k):
        a, m, b = 2 * j, 2 * j + 1, 2 * j + 2
        fa, fm, fb = f(a), f(m), f(b)
        opti.subject_to(th[m] == 0.5 * (th[a] + th[b]) + h / 8 * (fa[0] - fb[0]))
        opti.subject_to(v[m] == 0.5 * (v[a] + v[b]) + h / 8 * (fa[1] - fb[1]))
        opti.subject_to(th[b] == th[a] + h / 6 * (fa[0] + 4 * fm[0] + fb[0]))
        opti.subject_to(v[b] == v[a] + h / 6 * (fa[1] + 4 * fm[1] + fb[1]))
        opti.subject_to(u[m] == 0.5 * (u[a] + u[b]))  # piecewise-linear torque
    opti.subject_to(th[2 * k] == th[0] + 2 * math.pi * winding)
    opti.subject_to(v[2 * k] == v[0])
    w = np.ones(2 * k + 1)
    w[1::2] = 4.0
    w[2:-1:2] = 2.0
    w *= h / 6 / period  # Simpson weights of the mean
    p = -u * v
    if efficiency is None and copper_loss:
        obj = ca.dot(ca.DM(w), p)
    elif efficiency is None:
        # P = <(1 + q) sin(theta) theta'> - gamma <theta'^2> (Eq. 15; = -<T theta'> by the
        # energy balance): the torque does not enter, so it cannot chatter to exploit the rule
        obj = ca.dot(ca.DM(w), q1 * ca.sin(th) * v - gamma * v * v)
    else:
        eg, em = efficiency
        pp = opti.variable(2 * k + 1)
        pm = opti.variable(2 * k + 1)
        opti.subject_to(pp >= 0)
        opti.subject_to(pm >= 0)
        opti.subject_to(pp - pm == p)
        obj = ca.dot(ca.DM(w), eg * pp - pm / em)
    if copper_loss:
        obj = obj - copper_loss * ca.dot(ca.DM(w), u * u)
    if torque_limit is not None:
        opti.subject_to(opti.bounded(-torque_limit, u, torque_limit))
    opti.minimize(-obj)
    if guess is None:
        _, phi = (uniform_power(excitation, gamma) if winding == 1
                  else uniform_power(excitation, gamma, winding))
        g_th = winding * om * t + phi
        g_v = winding * om * np.ones_like(t)
        g_u = gamma * om - q1 * np.sin(g_th)
        if torque_limit is not None:
            g_u = np.clip(g_u, -torque_limit, torque_limit)
    else:
        g_th, g_v, g_u = guess(t)
    opti.set_initial(th, g_th)
    opti.set_initial(v, g_v)
    opti.set_initial(u, g_u)
    if efficiency is not None:
        g_p = -g_u * g_v
        opti.set_initial(pp, np.maximum(g_p, 0))
        opti.set_initial(pm, np.maximum(-g_p, 0))
    opti.solver("ipopt", {"print_time": False},
                {"print_level": 0, "sb": "yes", "tol": tol, "max_iter": max_iter})
    import time

    start = time.perf_counter()
    try:
        sol = opti.solve()
        stats = sol.stats()
        get = sol.value
    except RuntimeError:
        stats = opti.stats()
        get = opti.debug.value
    solve_time = time.perf_counter() - start
    uu, vv, tt = np.asarray(get(u)).ravel(), np.asarray(get(v)).ravel(), np.asarray(get(th))
    pv = -uu * vv
    ele = pv if efficiency is None else np.where(pv > 0, efficiency[0] * pv,
                                                  pv / efficiency[1])
    ele = ele - copper_loss * uu * uu
    return {"power": float(w @ pv), "electrical_power": float(w @ ele),
            "peak_torque": float(np.max(np.abs(uu))), "status": stats["return_status"],
            "iterations": stats.get("iter_count"), "t": t, "theta": tt.ravel(), "v": vv,
            "torque": uu, "solve_time": solve_time}
