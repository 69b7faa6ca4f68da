"""Compiled (numba) kernels of :class:`parapend.optimal.hermite.HermiteProblem`.

One pass over the ``K`` intervals per call: the barrier objective and the constraints of a
trial point (the line search), the banded Newton matrix with its right-hand side, and the
linearized constraint step. With NumPy the same work was about a hundred array calls per
interior-point iteration, each on ``(K, 4, 4)`` arrays: call overhead, not arithmetic, set
the time (0.7 ms per iteration at ``K = 128``).

Notation as in :mod:`parapend.optimal.hermite`: ``y = (theta_a, v_a, theta_b, v_b)`` of an
interval, ``theta = b0 . y``, ``theta' = b1 . y`` and the torque (Eq. 14 solved for ``T``)
``T = lin . y - (1 + q) sin(theta)`` with ``lin = b2 + gamma b1``, at the Gauss points
(``*_g``) and at the constraint points ``tau = 0, 1/2, 1`` (``*_c``).

Constraint modes (``mode``): 0 none; 1 the torque limit, ``+-T s_j - 1 <= 0`` with
``s_j = 1 / T_max,j`` per interval (tightened limits); 2 phase 1, ``+-T - t <= 0``; 3 elastic,
``+-T - (L + t) <= 0`` and ``-t <= 0``. Constraints are laid out as ``(c+, c-)`` over
intervals and points (``j * 3 + c``), then the elastic ``-t``.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .._jit import announce_compiles

NONE, LIMIT, PHASE1, ELASTIC = 0, 1, 2, 3

announce_compiles()  # log a first-use compile (parapend._jit)


@nb.njit(cache=True)
def interval_vector(x, j, k, wrap):
    """``y`` of interval ``j``: periodic (``x`` of ``K`` nodes), the last wraps to node 0
    plus ``wrap`` turns; open (``x`` of ``K + 1`` nodes, the receding horizon of
    :mod:`parapend.control.plan`), interval ``j`` ends at node ``j + 1``."""
    jn = j + 1 if 2 * (j + 1) < x.size else 0
    y = np.empty(4)
    y[0] = x[2 * j]
    y[1] = x[2 * j + 1]
    y[2] = x[2 * jn] + (wrap if jn == 0 else 0.0)
    y[3] = x[2 * jn + 1]
    return y


@nb.njit(cache=True)
def _row(m, r, y):
    """``sum_i m[r, i] y[i]`` over the four unknowns ``y`` of an interval: at one point, the
    value that row ``r`` of a basis matrix ``m`` gives (theta, theta' or the torque's linear
    part)."""
    s = 0.0
    for i in range(4):
        s += m[r, i] * y[i]
    return s


@nb.njit(cache=True)
def torques(x, k, wrap, b0, lin, q1):
    """``T`` at the points of rows ``b0, lin`` (shape (P, 4)) of every interval: (K, P)."""
    p = b0.shape[0]
    out = np.empty((k, p))
    for j in range(k):
        y = interval_vector(x, j, k, wrap)
        for c in range(p):
            out[j, c] = _row(lin, c, y) - q1[j, c] * math.sin(_row(b0, c, y))
    return out


@nb.njit(cache=True)
def power_terms(x, k, wrap, b0g, b1g, ling, q1g, wg, gamma):
    """``(P, <T^2>)``: the mean mechanical power (Eq. 15, state form) and mean square
    torque by the Gauss rule (``wg``: the weights of the mean on one interval)."""
    p = 0.0
    t2 = 0.0
    for j in range(k):
        y = interval_vector(x, j, k, wrap)
        for g in range(b0g.shape[0]):
            thd = _row(b1g, g, y)
            ln = _row(ling, g, y)
            sn = math.sin(_row(b0g, g, y))
            tq = ln - q1g[j, g] * sn
            p += wg[g] * (q1g[j, g] * sn * thd - gamma * thd * thd)
            t2 += wg[g] * tq * tq
    return p, t2


@nb.njit(cache=True)
def constraints(x, t, k, wrap, b0c, linc, q1c, mode, scale, limit):
    """The constraints ``c <= 0`` (layout in the module docstring)."""
    if mode == NONE:
        return np.zeros(0)
    pc = b0c.shape[0]
    nc = k * pc
    out = np.empty(2 * nc + (1 if mode == ELASTIC else 0))
    tq = torques(x, k, wrap, b0c, linc, q1c)
    for j in range(k):
        for c in range(pc):
            i = j * pc + c
            if mode == LIMIT:
                out[i] = tq[j, c] * scale[j] - 1.0
                out[nc + i] = -tq[j, c] * scale[j] - 1.0
            elif mode == PHASE1:
                out[i] = tq[j, c] - t
                out[nc + i] = -tq[j, c] - t
            else:
                out[i] = tq[j, c] - (limit + t)
                out[nc + i] = -tq[j, c] - (limit + t)
    if mode == ELASTIC:
        out[2 * nc] = -t
    return out


@nb.njit(cache=True)
def newton(x, t, lam, mu, k, wrap, b0g, b1g, ling, q1g, wg, gamma, copper, b0c, linc, q1c,
           mode, scale, limit, elastic, gvar, jtc):
    """Banded Newton matrix of the barrier problem and its right-hand side.

    Returns ``(ab, rhs, border, rhs_t, d_tt)``, ``ab`` the lower band (bandwidth 5) in the
    folded order of ``gvar`` (the folded positions of every interval's four variables);
    fills ``jtc`` (K, 3, 4) with ``dT/dy`` at the constraint points for the step.
    """
    n = x.size
    ab = np.zeros((6, n))
    g = np.zeros(n)
    border = np.zeros(n)
    d_tt = 0.0
    g_t = 0.0
    ng = b0g.shape[0]
    pc = b0c.shape[0]
    nc = k * pc
    blk = np.zeros((4, 4))
    gr = np.zeros(4)
    bd = np.zeros(4)
    jt = np.zeros(4)
    for j in range(k):
        y = interval_vector(x, j, k, wrap)
        blk[:, :] = 0.0
        gr[:] = 0.0
        bd[:] = 0.0
        if mode != PHASE1:
            # minimize -sum w f, f = q1 sin(theta) theta' - gamma theta'^2 (+ r T^2 loss)
            for q in range(ng):
                th = _row(b0g, q, y)
                thd = _row(b1g, q, y)
                ln = _row(ling, q, y)
                sn = math.sin(th)
                cs = math.cos(th)
                a = wg[q] * q1g[j, q]
                c0 = a * cs * thd
                c1 = a * sn - 2.0 * gamma * wg[q] * thd
                h00 = a * sn * thd
                h01 = a * cs
                h11 = 2.0 * gamma * wg[q]
                for i in range(4):
                    gr[i] -= c0 * b0g[q, i] + c1 * b1g[q, i]
                    for m in range(4):
                        blk[i, m] += (h00 * b0g[q, i] * b0g[q, m]
                                      - h01 * (b0g[q, i] * b1g[q, m] + b1g[q, i] * b0g[q, m])
                                      + h11 * b1g[q, i] * b1g[q, m])
                if copper != 0.0:
                    tq = ln - q1g[j, q] * sn
                    for i in range(4):
                        jt[i] = ling[q, i] - q1g[j, q] * cs * b0g[q, i]
                    r2 = 2.0 * copper * wg[q]
                    ht = tq * q1g[j, q] * sn
                    for i in range(4):
                        gr[i] += r2 * tq * jt[i]
                        for m in range(4):
                            blk[i, m] += r2 * (jt[i] * jt[m] + ht * b0g[q, i] * b0g[q, m])
        if mode != NONE:
            for c in range(pc):
                th = _row(b0c, c, y)
                ln = _row(linc, c, y)
                sn = math.sin(th)
                cs = math.cos(th)
                tq = ln - q1c[j, c] * sn
                for i in range(4):
                    jtc[j, c, i] = linc[c, i] - q1c[j, c] * cs * b0c[c, i]
                if mode == LIMIT:
                    s = scale[j]
                    sp = 1.0 - tq * s
                    sm = 1.0 + tq * s
                else:
                    s = 1.0
                    b = t if mode == PHASE1 else limit + t
                    sp = b - tq
                    sm = b + tq
                lp = lam[j * pc + c]
                lm = lam[nc + j * pc + c]
                gc = s * (mu / sp - mu / sm)
                sig = (lp / sp + lm / sm) * s * s
                hc = s * (lp - lm) * q1c[j, c] * sn
                for i in range(4):
                    gr[i] += gc * jtc[j, c, i]
                    for m in range(4):
                        blk[i, m] += sig * jtc[j, c, i] * jtc[j, c, m] + hc * b0c[c, i] * b0c[c, m]
                if mode != LIMIT:
                    for i in range(4):
                        bd[i] -= (lp / sp - lm / sm) * jtc[j, c, i]
                    d_tt += lp / sp + lm / sm
                    g_t -= mu / sp + mu / sm
        for a in range(4):
            ia = gvar[j, a]
            g[ia] += gr[a]
            border[ia] += bd[a]
            for b in range(4):
                ib = gvar[j, b]
                if ia >= ib:
                    ab[ia - ib, ib] += blk[a, b]
    if mode == PHASE1:
        g_t += 1.0
    elif mode == ELASTIC:
        d_tt += lam[2 * nc] / t
        g_t += elastic - mu / t
    return ab, -g, border, -g_t, d_tt


@nb.njit(cache=True)
def constraint_step(dx, dt, k, jtc, mode, scale):
    """``J d``: the linearized change of :func:`constraints` along ``(dx, dt)``."""
    if mode == NONE:
        return np.zeros(0)
    pc = jtc.shape[1]
    nc = k * pc
    out = np.empty(2 * nc + (1 if mode == ELASTIC else 0))
    for j in range(k):
        y = interval_vector(dx, j, k, 0.0)
        for c in range(pc):
            d = 0.0
            for i in range(4):
                d += jtc[j, c, i] * y[i]
            i = j * pc + c
            if mode == LIMIT:
                out[i] = d * scale[j]
                out[nc + i] = -d * scale[j]
            else:
                out[i] = d - dt
                out[nc + i] = -d - dt
    if mode == ELASTIC:
        out[2 * nc] = -dt
    return out


@nb.njit(cache=True)
def _q1(spec, omega, t):
    """``1 + q(t)``, ``q = Re sum_k Q[k] exp(i k omega t)`` (the excitation's spectrum).

    ``exp(i k s)`` by the rotation recurrence (one complex product per harmonic instead of
    a sine and a cosine: 20 to 30 times faster on spectra of thousands of harmonics; the
    rounding grows like ``k`` eps, below 1e-12 at the 2^14 harmonics of the largest file)."""
    s = omega * t
    c1 = math.cos(s)
    s1 = math.sin(s)
    cr = 1.0
    ci = 0.0
    out = 1.0
    for m in range(spec.size):
        out += spec[m].real * cr - spec[m].imag * ci
        cr, ci = cr * c1 - ci * s1, cr * s1 + ci * c1
    return out


@nb.njit(cache=True)
def _abs_torque(y, tau, h, gamma, q1):
    """``|T|`` at local ``tau`` of the interval ``y`` (cubic Hermite, Eq. 14 for ``T``)."""
    t2 = tau * tau
    t3 = t2 * tau
    th = ((2 * t3 - 3 * t2 + 1) * y[0] + h * (t3 - 2 * t2 + tau) * y[1]
          + (-2 * t3 + 3 * t2) * y[2] + h * (t3 - t2) * y[3])
    thd = ((6 * t2 - 6 * tau) / h * y[0] + (3 * t2 - 4 * tau + 1) * y[1]
           + (-6 * t2 + 6 * tau) / h * y[2] + (3 * t2 - 2 * tau) * y[3])
    thdd = ((12 * tau - 6) / (h * h) * y[0] + (6 * tau - 4) / h * y[1]
            + (-12 * tau + 6) / (h * h) * y[2] + (6 * tau - 2) / h * y[3])
    return abs(thdd + gamma * thd - q1 * math.sin(th))


@nb.njit(cache=True)
def interval_peaks(x, k, wrap, h, gamma, spec, omega, samples, floor, q1s):
    """``max |T|`` over each interval, shape (K,): ``samples + 1`` points per interval
    (both ends: ``T`` jumps at the nodes), then, where the sampled maximum reaches 95 % of
    ``floor`` (``floor < 0``: of the largest sample), a zoom on it: 9 points across the
    bracket of the neighbouring samples, the bracket shrunk fourfold around the best point,
    six times (spacing ``1 / (samples 4^6)`` of the interval). ``q1s`` (K samples + 1,):
    ``1 + q`` on the uniform grid of the samples (``t = i h / samples``, the last point the
    end of the period), precomputed exactly by the caller (one FFT); the zoom points
    evaluate the spectrum."""
    best = np.empty(k)
    arg = np.empty(k)
    for j in range(k):
        y = interval_vector(x, j, k, wrap)
        b = -1.0
        for i in range(samples + 1):
            tau = i / samples
            v = _abs_torque(y, tau, h, gamma, q1s[j * samples + i])
            if v > b:
                b = v
                arg[j] = tau
        best[j] = b
    top = np.max(best) if floor < 0 else floor
    out = best.copy()
    for j in range(k):
        if best[j] < 0.95 * top:
            continue
        y = interval_vector(x, j, k, wrap)
        centre = arg[j]
        half = 1.0 / samples
        for _ in range(6):
            bv = -1.0
            bs = centre
            for i in range(9):
                s = min(max(centre + half * (-1.0 + 0.25 * i), 0.0), 1.0)
                v = _abs_torque(y, s, h, gamma, _q1(spec, omega, h * (j + s)))
                if v > bv:
                    bv = v
                    bs = s
            out[j] = max(out[j], bv)
            centre = bs
            half = half / 4
    return out


@nb.njit(cache=True)
def jt_apply(w, k, jtc, mode, scale, gvar):
    """``J^T w`` for a vector ``w`` over the constraints: ``(x part in the folded order,
    t part)`` (the constraints' ``dT/dy`` from the last :func:`newton`)."""
    gx = np.zeros(np.max(gvar) + 1)
    gt = 0.0
    if mode == NONE:
        return gx, gt
    pc = jtc.shape[1]
    nc = k * pc
    for j in range(k):
        for c in range(pc):
            i = j * pc + c
            d = w[i] - w[nc + i]
            if mode == LIMIT:
                d *= scale[j]
            else:
                gt -= w[i] + w[nc + i]
            for a in range(4):
                gx[gvar[j, a]] += d * jtc[j, c, a]
    if mode == ELASTIC:
        gt -= w[2 * nc]
    return gx, gt


@nb.njit(cache=True)
def max_step(v, dv, fraction):
    """The largest ``alpha <= 1`` with ``v + alpha dv >= (1 - fraction) v`` (``v > 0``)."""
    a = 1.0
    for i in range(v.size):
        if dv[i] < 0.0:
            a = min(a, -fraction * v[i] / dv[i])
    return a


@nb.njit(cache=True)
def trial(x, dx, alpha, t, dt, s, mu, floor, k, wrap, b0g, b1g, ling, q1g, wg, gamma, copper,
          b0c, linc, q1c, mode, scale, limit, elastic):
    """A trial point of the line search: ``x + alpha dx`` (and ``t + alpha dt``).

    Returns ``(ok, barrier, xn, tn, sn, phi)``: ``ok`` when every slack ``sn = -c`` exceeds
    ``floor`` times its old value ``s``; ``phi`` the objective (minimized: ``-P + r <T^2>``,
    ``+ elastic t``, or ``t`` in phase 1) and ``barrier = phi - mu sum log sn``.
    """
    xn = x + alpha * dx
    tn = t + alpha * dt
    c = constraints(xn, tn, k, wrap, b0c, linc, q1c, mode, scale, limit)
    sn = -c
    for i in range(sn.size):
        if not sn[i] > floor * s[i]:
            return False, 0.0, xn, tn, sn, 0.0
    if mode == PHASE1:
        phi = tn
    else:
        p, t2 = power_terms(xn, k, wrap, b0g, b1g, ling, q1g, wg, gamma)
        phi = -p + copper * t2
        if mode == ELASTIC:
            phi += elastic * tn
    logs = 0.0
    for i in range(sn.size):
        logs += math.log(sn[i])
    return True, phi - mu * logs, xn, tn, sn, phi
