r"""Compiled (numba) interior point of the horizon problem (:mod:`parapend.control.plan`).

The same algorithm as :func:`parapend.optimal.hermite.interior_point` (barrier parameter
rule, Mehrotra predictor-corrector, inertia correction, Armijo backtracking, fraction to the
boundary) on the open chain of :class:`parapend.control.plan.PlanProblem` without a border
variable (no torque limit, or the torque limit; elastic mode stays in Python), as one
compiled call: the Newton matrix and the line-search trials of
:mod:`parapend.optimal._hermite_kernel`, the terminal value and the smoothed kink of
:meth:`PlanProblem._extra` / :meth:`PlanProblem._extra_newton`, and a banded Cholesky of
lower bandwidth 3 (the open chain in natural order: interval ``j`` couples variables
``2 j - 2 .. 2 j + 1``) in place of LAPACK's ``dpbtrf`` / ``dpbtrs``. The Python loop
around those kernels takes about two thirds of a solve (benchmarks/bench_mpc.py, 30
iterations at ``K = 64``: a median of 4.1 ms at load 0.9 with it, 1.05 ms at load 2.8 as
one compiled call; docs/control.md).

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
# a literal, not an import: numba's cache of this file keys on this file only
ROUNDING_DECREMENT = 1e-10  # as parapend.optimal.hermite
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
def extra(f, k, b0, b1, lin, q1, w, kappa, eta_g, a, kink, eps, wmax, rho_h):
    """``terminal + kink + rated-speed penalty`` of the minimized objective
    (:meth:`PlanProblem._extra`; ``wmax = inf``: no rated speed, ``rho_h = rho h``)."""
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
    if math.isfinite(wmax):
        acc = 0.0
        for i in range(3, f.size, 2):
            r = abs(f[i]) - wmax
            if r > 0.0:
                acc += r * r
        val += 0.5 * rho_h * acc
    return val


@nb.njit(cache=True)
def extra_newton(f, ab, rhs, k, b0, b1, lin, q1, w, kappa, eta_g, a, kink, eps, wmax, rho_h):
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
    if math.isfinite(wmax):
        for i in range(3, n, 2):
            r = abs(f[i]) - wmax
            if r > 0.0:
                rhs[i] -= rho_h * r * (1.0 if f[i] > 0.0 else -1.0)
                ab[0, i] += rho_h
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
def cho_solve(c, b, x):
    """Solve ``L L^T x = b`` into ``x`` from the band factor ``c`` of :func:`cholesky`.

    (Into an argument: an array returned to Python from a kernel that numba also compiled
    as a callee of :func:`solve`, loaded from its disk cache, failed in
    ``NRT_adapt_ndarray_to_python`` with numba 0.68.)"""
    p = c.shape[0] - 1
    n = c.shape[1]
    for i in range(n):
        x[i] = b[i]
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
def newton(f, lam, mu, k, b0g, b1g, ling, qg, wk, gamma, b0c, linc, q1c, limit_on, scale,
           ab, g, jtc, sb, cb):
    """The Newton matrix (lower band ``ab``, bandwidth 3, full order: node 0 included) and
    the barrier gradient ``g`` of the horizon problem without its extra terms: the open
    chain's case of :func:`parapend.optimal._hermite_kernel.newton` (the kernel's ``q1g``
    is ``q``, its weights ``wk``), the lower triangle of each interval's block only, the
    Gauss point's Hessian ``h00 b0 b0' - h01 (b0 b1' + b1 b0') + h11 b1 b1'`` as
    ``(h00 b0 - h01 b1) b0' + (h11 b1 - h01 b0) b1'``. ``sb, cb`` (K, 7): ``sin, cos`` of
    the angle at the Gauss points and the torque points of every interval at ``f``
    (:func:`trial`, :func:`cosines`). Fills ``jtc`` (``dT/dy`` at the torque points)."""
    ab[:, :] = 0.0
    g[:] = 0.0
    ng = b0g.shape[0]
    pc = b0c.shape[0]
    nc = k * pc
    y = np.empty(4)
    p = np.empty(4)
    r = np.empty(4)
    for j in range(k):
        o = 2 * j
        for i in range(4):
            y[i] = f[o + i]
        for q in range(ng):
            thd = 0.0
            for i in range(4):
                thd += b1g[q, i] * y[i]
            sn = sb[j, q]
            cs = cb[j, q]
            a = wk[q] * qg[j, q]
            c0 = a * cs * thd
            c1 = a * sn - 2.0 * gamma * wk[q] * thd
            h00 = a * sn * thd
            h01 = a * cs
            h11 = 2.0 * gamma * wk[q]
            for i in range(4):
                g[o + i] -= c0 * b0g[q, i] + c1 * b1g[q, i]
                p[i] = h00 * b0g[q, i] - h01 * b1g[q, i]
                r[i] = h11 * b1g[q, i] - h01 * b0g[q, i]
            for i in range(4):
                for m in range(i + 1):
                    ab[i - m, o + m] += p[i] * b0g[q, m] + r[i] * b1g[q, m]
        if not limit_on:
            continue
        sc = scale[j]
        for c in range(pc):
            ln = 0.0
            for i in range(4):
                ln += linc[c, i] * y[i]
            sn = sb[j, ng + c]
            cs = cb[j, ng + c]
            tq = ln - q1c[j, c] * sn
            for i in range(4):
                jtc[j, c, i] = linc[c, i] - q1c[j, c] * cs * b0c[c, i]
            sp = 1.0 - tq * sc
            sm = 1.0 + tq * sc
            lp = lam[j * pc + c]
            lm = lam[nc + j * pc + c]
            gc = sc * (mu / sp - mu / sm)
            sig = (lp / sp + lm / sm) * sc * sc
            hc = sc * (lp - lm) * q1c[j, c] * sn
            for i in range(4):
                g[o + i] += gc * jtc[j, c, i]
                for m in range(i + 1):
                    ab[i - m, o + m] += (sig * jtc[j, c, i] * jtc[j, c, m]
                                         + hc * b0c[c, i] * b0c[c, m])


@nb.njit(cache=True)
def slack_step(dxf, k, jtc, scale, out):
    """``ds = -J d`` (the slacks' linearized change along ``dxf``, full order) into ``out``
    (:func:`parapend.optimal._hermite_kernel.constraint_step`, mode LIMIT)."""
    pc = jtc.shape[1]
    nc = k * pc
    for j in range(k):
        for c in range(pc):
            d = 0.0
            for i in range(4):
                d += jtc[j, c, i] * dxf[2 * j + i]
            out[j * pc + c] = -d * scale[j]
            out[nc + j * pc + c] = d * scale[j]


@nb.njit(cache=True)
def jt_apply(w, k, jtc, scale, out):
    """``J^T w`` into ``out`` (full order; :func:`parapend.optimal._hermite_kernel.jt_apply`,
    mode LIMIT)."""
    out[:] = 0.0
    pc = jtc.shape[1]
    nc = k * pc
    for j in range(k):
        for c in range(pc):
            d = (w[j * pc + c] - w[nc + j * pc + c]) * scale[j]
            for i in range(4):
                out[2 * j + i] += d * jtc[j, c, i]


@nb.njit(cache=True)
def trial(f, dxf, alpha, s, floor, k, b0g, b1g, qg, wk, gamma, b0c, linc, q1c, limit_on,
          scale, xn, sn, sb):
    """The trial point ``xn = f + alpha dxf`` and its slacks ``sn`` (into the buffers);
    returns ``(ok, phi, log_sum)``: ``ok`` when every slack exceeds ``floor`` times its old
    value, ``phi = -P`` (:func:`parapend.optimal._hermite_kernel.trial` without the
    allocations, mode NONE or LIMIT). The sines of the angle at the Gauss points and the
    torque points go to ``sb`` (K, 7) for :func:`newton`."""
    for i in range(f.size):
        xn[i] = f[i] + alpha * dxf[i]
    pc = b0c.shape[0]
    nc = k * pc
    logs = 0.0
    if limit_on:
        for j in range(k):
            o = 2 * j
            for c in range(pc):
                th = 0.0
                ln = 0.0
                for i in range(4):
                    th += b0c[c, i] * xn[o + i]
                    ln += linc[c, i] * xn[o + i]
                sv = math.sin(th)
                sb[j, b0g.shape[0] + c] = sv
                tq = (ln - q1c[j, c] * sv) * scale[j]
                i1 = j * pc + c
                i2 = nc + i1
                sn[i1] = 1.0 - tq
                sn[i2] = 1.0 + tq
                if not (sn[i1] > floor * s[i1] and sn[i2] > floor * s[i2]):
                    return False, 0.0, 0.0
        for i in range(2 * nc):
            logs += math.log(sn[i])
    p = 0.0
    for j in range(k):
        o = 2 * j
        for q in range(b0g.shape[0]):
            th = 0.0
            thd = 0.0
            for i in range(4):
                th += b0g[q, i] * xn[o + i]
                thd += b1g[q, i] * xn[o + i]
            sv = math.sin(th)
            sb[j, q] = sv
            p += wk[q] * (qg[j, q] * sv * thd - gamma * thd * thd)
    return True, -p, logs


@nb.njit(cache=True)
def cosines(f, k, b0g, b0c, limit_on, cb):
    """``cos`` of the angle at the Gauss points and (with the limit) the torque points of
    every interval into ``cb`` (K, 7), the angle summed as :func:`trial` sums it."""
    ng = b0g.shape[0]
    for j in range(k):
        o = 2 * j
        for q in range(ng):
            th = 0.0
            for i in range(4):
                th += b0g[q, i] * f[o + i]
            cb[j, q] = math.cos(th)
        if limit_on:
            for c in range(b0c.shape[0]):
                th = 0.0
                for i in range(4):
                    th += b0c[c, i] * f[o + i]
                cb[j, ng + c] = math.cos(th)


@nb.njit(cache=True)
def _dot(a, b):
    acc = 0.0
    for i in range(a.size):
        acc += a[i] * b[i]
    return acc


@nb.njit(cache=True)
def _median_abs(v):
    """The median of ``|v|`` (the inertia correction's scale)."""
    return float(np.median(np.abs(v)))


@nb.njit(cache=True)
def _corrector(fac, rhs, s, lam, mu, mu_new, k, jtc, scale, ones, jw, dxf, ds):
    """Mehrotra's predictor-corrector step (``_predictor_corrector`` of
    :mod:`parapend.optimal.hermite`, mode LIMIT): ``(dx, slope, target)``; ``slope >= 0``
    when it is not a descent step."""
    nb_ = s.size
    n = rhs.size
    w = np.empty(nb_)
    for i in range(nb_):
        w[i] = 1.0 / s[i]
    jt_apply(w, k, jtc, scale, ones)
    rhs0 = np.empty(n)
    for i in range(n):
        rhs0[i] = rhs[i] + mu * ones[i + 2]
    cho_solve(fac, rhs0, dxf[2:])
    slack_step(dxf, k, jtc, scale, ds)
    tg = np.empty(nb_)
    for i in range(nb_):
        dlam_a = -lam[i] - lam[i] / s[i] * ds[i]
        tg[i] = (mu_new - ds[i] * dlam_a) / s[i]
    jt_apply(tg, k, jtc, scale, jw)
    r = np.empty(n)
    for i in range(n):
        r[i] = rhs0[i] - jw[i + 2]
    dx = np.empty(n)
    cho_solve(fac, r, dx)
    sl = 0.0
    for i in range(n):
        sl -= (rhs0[i] - mu_new * ones[i + 2]) * dx[i]
    return dx, sl, tg


@nb.njit(cache=True)
def _dual_step(lam, target, s, ds):
    """The dual step towards ``target`` with the fraction to the boundary, in place."""
    dlam = np.empty(lam.size)
    for i in range(lam.size):
        dlam[i] = target[i] - lam[i] - lam[i] / s[i] * ds[i]
    a = _k.max_step(lam, dlam, _FRACTION)
    for i in range(lam.size):
        lam[i] = max(lam[i] + a * dlam[i], 1e-30)


@nb.njit(cache=True)
def _full(x0, x):
    f = np.empty(x.size + 2)
    f[0] = x0[0]
    f[1] = x0[1]
    f[2:] = x
    return f


@nb.njit(cache=True)
def solve(x, x0, k, b0g, b1g, ling, qg, wk, gamma, b0c, linc, q1c, limit_on, scale, q1g, w,
          kappa, eta_g, a, kink, eps, wmax, rho_h, gap_tol, maxiter, mu0):
    """The interior point of :func:`parapend.optimal.hermite.interior_point` on the horizon
    problem (variables ``x``, node 0 fixed to ``x0``; ``limit_on``: the torque limit
    ``|T| scale_j <= 1``, else none; ``mu0`` NaN: the default start).

    Returns ``(x, status, iterations, mu)``, ``status`` an index into :data:`STATUS`.
    """
    n = x.size
    nf = n + 2
    pc = b0c.shape[0]
    nb_ = 2 * k * pc if limit_on else 0
    f = _full(x0, x)
    xn = np.empty(nf)
    s = np.ones(nb_)
    sn = np.empty(nb_)
    dxf = np.zeros(nf)
    npt = b0g.shape[0] + pc
    sb = np.zeros((k, npt))  # sin and cos at the points of f, and sin at the trial point
    cb = np.zeros((k, npt))
    sbn = np.zeros((k, npt))
    ok, phi, logs = trial(f, dxf, 0.0, s, -math.inf, k, b0g, b1g, qg, wk, gamma, b0c, linc,
                          q1c, limit_on, scale, xn, s, sb)
    cosines(f, k, b0g, b0c, limit_on, cb)
    for i in range(nb_):
        if not s[i] > 0.0:
            return x.copy(), _INFEASIBLE, 0, math.nan
    m = max(nb_, 1)
    phi += extra(f, k, b0g, b1g, ling, q1g, w, kappa, eta_g, a, kink, eps, wmax, rho_h)
    mu = mu0 if not math.isnan(mu0) else 0.1 * max(abs(phi), 1e-3) / m
    mu_min = min(gap_tol / m, mu)
    lam = np.empty(nb_)
    for i in range(nb_):
        lam[i] = mu / s[i]
    status = _MAXIT
    delta_last = 0.0
    stagnant = 0
    it = 0
    ab6 = np.empty((_BW + 1, nf))
    g6 = np.empty(nf)
    jtc = np.zeros((k, pc, 4))
    ab = np.empty((_BW + 1, n))
    fac = np.empty((_BW + 1, n))
    ds = np.empty(nb_)
    ones = np.empty(nf)
    jw = np.empty(nf)
    floor = 0.1 * (1 - _FRACTION)
    for it in range(1, maxiter + 1):  # noqa: B007 (returned: the iteration count)
        newton(f, lam, mu, k, b0g, b1g, ling, qg, wk, gamma, b0c, linc, q1c, limit_on, scale,
               ab6, g6, jtc, sb, cb)
        for i in range(nf):
            g6[i] = -g6[i]  # the right-hand side
        extra_newton(f, ab6, g6, k, b0g, b1g, ling, q1g, w, kappa, eta_g, a, kink, eps,
                     wmax, rho_h)
        for r in range(_BW + 1):
            for i in range(n):
                ab[r, i] = ab6[r, i + 2]
        rhs = g6[2:].copy()
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
                            1e-8 * max(1e-6, _median_abs(ab[0])))
        if not ok:
            status = _SINGULAR
            break
        delta_last = delta
        dx = np.empty(n)
        cho_solve(fac, rhs, dx)
        slope = -_dot(rhs, dx)
        target = np.empty(nb_)
        for i in range(nb_):
            target[i] = mu / s[i]
        if -slope <= max(2e-2 * m * mu, 1e-12 * (1.0 + abs(phi))) or stagnant >= 5:
            if mu <= mu_min * (1 + 1e-12):
                status = _CONVERGED
                break
            mu_new = max(mu_min, min(_MU_FACTOR * mu, mu**_MU_POWER))
            stagnant = 0
            # Mehrotra's predictor-corrector (interior_point's _predictor_corrector)
            pc_ok = False
            if nb_:
                dx_c, sl, tg = _corrector(fac, rhs, s, lam, mu, mu_new, k, jtc, scale, ones,
                                          jw, dxf, ds)
                if sl < 0:
                    pc_ok = True
                    dx = dx_c
                    slope = sl
                    target = tg
            mu = mu_new
            if not pc_ok:
                continue
        b0 = phi
        for i in range(nb_):
            b0 -= mu * math.log(s[i])
        dxf[2:] = dx
        if nb_:
            slack_step(dxf, k, jtc, scale, ds)
        alpha = _k.max_step(s, ds, _FRACTION)
        found = False
        bn = 0.0
        phin = 0.0
        for _ in range(50):
            okt, phin, logs = trial(f, dxf, alpha, s, floor, k, b0g, b1g, qg, wk, gamma, b0c,
                                    linc, q1c, limit_on, scale, xn, sn, sbn)
            if okt:
                phin += extra(xn, k, b0g, b1g, ling, q1g, w, kappa, eta_g, a, kink, eps,
                              wmax, rho_h)
                bn = phin - mu * logs
                if (bn <= b0 + 1e-4 * alpha * min(slope, 0.0)
                        or abs(bn - b0) <= 1e-15 * (1 + abs(b0))):
                    found = True
                    break
            alpha *= 0.5
        if not found:
            # at the final barrier parameter, with a Newton decrement at the precision to
            # which the barrier function can be compared, the point is the optimum to
            # rounding (as interior_point)
            if mu <= mu_min * (1 + 1e-12) and -slope <= ROUNDING_DECREMENT * (1.0 + abs(phi)):
                status = _CONVERGED
            else:
                status = _STALLED
            break
        if nb_:
            _dual_step(lam, target, s, ds)
        stagnant = stagnant + 1 if abs(bn - b0) <= 1e-14 * (1 + abs(b0)) else 0
        f, xn = xn, f
        s, sn = sn, s
        sb, sbn = sbn, sb
        cosines(f, k, b0g, b0c, limit_on, cb)
        phi = phin
    return f[2:].copy(), status, it, mu
