r"""Compiled (numba) interior point of the horizon problem (:mod:`parapend.control.plan`).

The same algorithm as :func:`parapend.optimal.hermite.interior_point` (barrier parameter
rule, Mehrotra predictor-corrector, inertia correction, Armijo backtracking, fraction to the
boundary) on the open chain of :class:`parapend.control.plan.PlanProblem` without a border
variable (no torque limit, or the torque limit; elastic mode stays in Python), as one
compiled call: the Newton matrix and the line-search trials of
:mod:`parapend.optimal._hermite_kernel`, the terminal value and the smoothed kink of
:meth:`PlanProblem._extra` / :meth:`PlanProblem._extra_newton`, and a banded Cholesky of
lower bandwidth 3 (the open chain in natural order: interval ``j`` couples variables
``2 j - 2 .. 2 j + 1``) in place of LAPACK's ``dpbtrf`` / ``dpbtrs``. In Python the loop
around those kernels cost about two thirds of every iteration (the 4 ms median of the
benchmark's 30 iterations at ``K = 64``); compiled, an iteration is a few microseconds.

The iterates agree with the Python loop to rounding (the Cholesky sums in another order than
LAPACK's); tests/test_plan_kernel.py compares the two.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .._jit import announce_compiles
from ..optimal import _hermite_kernel as _k

announce_compiles()  # log a first-use compile (parapend._jit)

#: status codes of :func:`solve`, in the order of these names
STATUS = ("converged", "max_iterations", "stalled", "singular", "infeasible_start")
_CONVERGED, _MAXIT, _STALLED, _SINGULAR, _INFEASIBLE = 0, 1, 2, 3, 4
_FRACTION = 0.995
_MU_FACTOR, _MU_POWER = 0.2, 1.3  # as parapend.optimal.hermite
_BW = 3  # lower bandwidth of the open chain's Newton matrix


@nb.njit(cache=True)
def terminal_value(e, a):
    """``V(E), V'(E), V''(E)`` (:meth:`PlanProblem.terminal_value`; ``a = inf``: ``V = E``)."""
    if not math.isfinite(a):
        return e, 1.0, 0.0
    w = math.sqrt(max(2.0 * (e + 1.0), 1e-12))
    return (a * w - a * a * math.log1p(w / a) - 1.0, a / (a + w),
            -a / ((a + w) ** 2 * w))


@nb.njit(cache=True)
def extra(f, k, b0, b1, lin, q1, w, kappa, eta_g, a, kink, eps):
    """``terminal + kink`` of the minimized objective (:meth:`PlanProblem._extra`)."""
    e_end = 0.5 * f[-1] ** 2 + math.cos(f[-2])
    if math.isfinite(a):
        val = -(kappa * terminal_value(e_end, a)[0] - eta_g * e_end)
    else:
        val = -(kappa - eta_g) * e_end
    if kink != 0.0:
        acc = 0.0
        for j in range(k):
            y = _k.interval_vector(f, j, k, 0.0)
            for g in range(b0.shape[0]):
                th = _k._row(b0, g, y)
                thd = _k._row(b1, g, y)
                z = (_k._row(lin, g, y) - q1[j, g] * math.sin(th)) * thd
                acc += (z + math.sqrt(z * z + eps * eps)) * 0.5 * w[g]
        val += kink * acc
    return val


@nb.njit(cache=True)
def extra_newton(f, ab, rhs, k, b0, b1, lin, q1, w, kappa, eta_g, a, kink, eps):
    """Add the gradient (to ``rhs``, minus) and Hessian (to the lower band ``ab``, full
    order) of :func:`extra` (:meth:`PlanProblem._extra_newton`)."""
    n = f.size
    th = f[n - 2]
    v = f[n - 1]
    _, v1, v2 = terminal_value(0.5 * v * v + math.cos(th), a)
    d = kappa * v1 - eta_g
    c = kappa * v2
    if d != 0.0 or c != 0.0:
        sn = math.sin(th)
        rhs[n - 2] -= d * sn
        rhs[n - 1] += d * v
        ab[0, n - 2] += d * math.cos(th) - c * sn * sn
        ab[0, n - 1] -= d + c * v * v
        ab[1, n - 2] += c * sn * v
    if kink == 0.0:
        return
    dt = np.empty(4)
    dz = np.empty(4)
    grad = np.empty(4)
    hess = np.empty((4, 4))
    for j in range(k):
        y = _k.interval_vector(f, j, k, 0.0)
        grad[:] = 0.0
        hess[:, :] = 0.0
        for g in range(b0.shape[0]):
            tg = _k._row(b0, g, y)
            thd = _k._row(b1, g, y)
            sn = math.sin(tg)
            cs = math.cos(tg)
            tq = _k._row(lin, g, y) - q1[j, g] * sn
            z = tq * thd
            r = math.sqrt(z * z + eps * eps)
            f1 = 0.5 * (1.0 + z / r) * kink * w[g]
            f2 = 0.5 * eps * eps / r**3 * kink * w[g]
            h0 = f1 * thd * q1[j, g] * sn
            for i in range(4):
                dt[i] = lin[g, i] - q1[j, g] * cs * b0[g, i]
                dz[i] = thd * dt[i] + tq * b1[g, i]
            for i in range(4):
                grad[i] += f1 * dz[i]
                for m in range(i + 1):
                    hess[i, m] += (f2 * dz[i] * dz[m] + f1 * dt[i] * b1[g, m]
                                   + f1 * b1[g, i] * dt[m] + h0 * b0[g, i] * b0[g, m])
        for i in range(4):
            rhs[2 * j + i] -= grad[i]
            for m in range(i + 1):
                ab[i - m, 2 * j + m] += hess[i, m]


@nb.njit(cache=True)
def cholesky(ab, delta, c):
    """Banded Cholesky of ``ab + delta I`` (lower band ``ab[d, j] = A[j + d, j]``, bandwidth
    ``ab.shape[0] - 1``) into ``c`` (same layout); False when not positive definite (a pivot
    not > 0, as LAPACK's ``dpbtrf``)."""
    p = ab.shape[0] - 1
    n = ab.shape[1]
    for j in range(n):
        d = ab[0, j] + delta
        for m in range(max(0, j - p), j):
            d -= c[j - m, m] * c[j - m, m]
        if not d > 0.0:
            return False
        ljj = math.sqrt(d)
        c[0, j] = ljj
        for i in range(j + 1, min(n, j + p + 1)):
            s = ab[i - j, j]
            for m in range(max(0, i - p), j):
                s -= c[i - m, m] * c[j - m, m]
            c[i - j, j] = s / ljj
    return True


@nb.njit(cache=True)
def cho_solve(c, b):
    """Solve ``L L^T x = b`` from the band factor ``c`` of :func:`cholesky`."""
    p = c.shape[0] - 1
    n = c.shape[1]
    x = b.copy()
    for i in range(n):
        s = x[i]
        for m in range(max(0, i - p), i):
            s -= c[i - m, m] * x[m]
        x[i] = s / c[0, i]
    for i in range(n - 1, -1, -1):
        s = x[i]
        for m in range(i + 1, min(n, i + p + 1)):
            s -= c[m - i, i] * x[m]
        x[i] = s / c[0, i]
    return x


@nb.njit(cache=True)
def _full(x0, x):
    f = np.empty(x.size + 2)
    f[0] = x0[0]
    f[1] = x0[1]
    f[2:] = x
    return f


@nb.njit(cache=True)
def solve(x, x0, k, b0g, b1g, ling, qg, wk, gamma, b0c, linc, q1c, mode, scale, limit, gvar,
          jtc, q1g, w, kappa, eta_g, a, kink, eps, gap_tol, maxiter, mu0):
    """The interior point of :func:`parapend.optimal.hermite.interior_point` on the horizon
    problem (variables ``x``, node 0 fixed to ``x0``; ``mode`` NONE or LIMIT of
    :mod:`parapend.optimal._hermite_kernel`; ``mu0`` NaN: the default start).

    Returns ``(x, status, iterations, mu)``, ``status`` an index into :data:`STATUS`.
    """
    n = x.size
    f = _full(x0, x)
    c = _k.constraints(f, 0.0, k, 0.0, b0c, linc, q1c, mode, scale, limit)
    if c.size and np.max(c) >= 0:
        return x.copy(), _INFEASIBLE, 0, math.nan
    m = max(c.size, 1)
    phi = (-_k.power_terms(f, k, 0.0, b0g, b1g, ling, qg, wk, gamma)[0]
           + extra(f, k, b0g, b1g, ling, q1g, w, kappa, eta_g, a, kink, eps))
    mu = mu0 if not math.isnan(mu0) else 0.1 * max(abs(phi), 1e-3) / m
    mu_min = min(gap_tol / m, mu)
    s = -c
    lam = mu / s
    status = _MAXIT
    delta_last = 0.0
    stagnant = 0
    it = 0
    ab = np.empty((_BW + 1, n))
    fac = np.empty((_BW + 1, n))
    dxf = np.zeros(n + 2)
    floor = 0.1 * (1 - _FRACTION)
    for it in range(1, maxiter + 1):  # noqa: B007 (returned: the iteration count)
        ab6, rhs6, _, _, _ = _k.newton(f, 0.0, lam, mu, k, 0.0, b0g, b1g, ling, qg, wk, gamma,
                                       0.0, b0c, linc, q1c, mode, scale, limit, 0.0, gvar, jtc)
        extra_newton(f, ab6, rhs6, k, b0g, b1g, ling, q1g, w, kappa, eta_g, a, kink, eps)
        ab[:, :] = ab6[:_BW + 1, 2:]
        rhs = rhs6[2:].copy()
        delta = 0.0  # inertia correction (interior_point's rule)
        ok = False
        for _ in range(30):
            if cholesky(ab, delta, fac):
                ok = True
                break
            if delta != 0.0:
                delta = 8.0 * delta
            else:
                delta = max(delta_last / 3.0,
                            1e-8 * max(1e-6, float(np.median(np.abs(ab[0])))))
        if not ok:
            status = _SINGULAR
            break
        delta_last = delta
        dx = cho_solve(fac, rhs)
        slope = -float(rhs @ dx)
        target = mu / s
        if -slope <= max(2e-2 * m * mu, 1e-12 * (1.0 + abs(phi))) or stagnant >= 5:
            if mu <= mu_min * (1 + 1e-12):
                status = _CONVERGED
                break
            mu_new = max(mu_min, min(_MU_FACTOR * mu, mu**_MU_POWER))
            stagnant = 0
            # Mehrotra's predictor-corrector (interior_point's _predictor_corrector)
            pc = False
            if lam.size:
                ones = _k.jt_apply(1.0 / s, k, jtc, mode, scale, gvar)[0][2:]
                rhs0 = rhs + mu * ones
                dx_a = cho_solve(fac, rhs0)
                dxf[2:] = dx_a
                ds_a = -_k.constraint_step(dxf, 0.0, k, jtc, mode, scale)
                dlam_a = -lam - lam / s * ds_a
                tg = (mu_new - ds_a * dlam_a) / s
                jw = _k.jt_apply(tg, k, jtc, mode, scale, gvar)[0][2:]
                dx_c = cho_solve(fac, rhs0 - jw)
                sl = -float((rhs0 - mu_new * ones) @ dx_c)
                if sl < 0:
                    pc = True
                    dx = dx_c
                    slope = sl
                    target = tg
            mu = mu_new
            if not pc:
                continue
        b0 = phi - mu * float(np.sum(np.log(s)))
        dxf[2:] = dx
        ds = -_k.constraint_step(dxf, 0.0, k, jtc, mode, scale)
        alpha = _k.max_step(s, ds, _FRACTION)
        found = False
        bn = 0.0
        xn = f
        sn = s
        phin = 0.0
        for _ in range(50):
            okt, bn, xn, _, sn, phin = _k.trial(f, dxf, alpha, 0.0, 0.0, s, mu, floor, k, 0.0,
                                                b0g, b1g, ling, qg, wk, gamma, 0.0, b0c, linc,
                                                q1c, mode, scale, limit, 0.0)
            if okt:
                ex = extra(xn, k, b0g, b1g, ling, q1g, w, kappa, eta_g, a, kink, eps)
                bn += ex
                phin += ex
                if (bn <= b0 + 1e-4 * alpha * min(slope, 0.0)
                        or abs(bn - b0) <= 1e-15 * (1 + abs(b0))):
                    found = True
                    break
            alpha *= 0.5
        if not found:
            status = _STALLED
            break
        if lam.size:
            dlam = target - lam - lam / s * ds
            lam = np.maximum(lam + _k.max_step(lam, dlam, _FRACTION) * dlam, 1e-30)
        stagnant = stagnant + 1 if abs(bn - b0) <= 1e-14 * (1 + abs(b0)) else 0
        f, s, phi = xn, sn, phin
    return f[2:].copy(), status, it, mu
