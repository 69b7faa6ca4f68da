"""Compiled (numba) evaluation of the buoy's horizon problem (:mod:`._buoy_plan`): the
objective, the torques at the constraint points and, on request, the gradient, the Jacobian
and the Hessian of the Lagrangian, in one pass over the points (the same formulas as
:meth:`._buoy_plan.CoupledPlan.derivatives`, written as loops)."""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .._jit import announce_compiles
from ..optimal._hermite_kernel import max_step

announce_compiles()  # log a first-use compile (parapend._jit)


@nb.njit(cache=True)
def evaluate(full, j, b0, b1, b2, af, bf, ap, bp, bp0, b0g, wgt, f_t, yc, ydc, ng, p, r, kap,
             wrad, nu, order, grad, hess, tau, jac):
    """``phi`` (returned) and ``tau`` (the constraint points, in place); with ``order >= 1``
    also ``grad``, ``jac`` and the objective's Hessian in ``hess`` (over the full node vector,
    zeroed here); with ``order == 2`` the Hessian of ``phi + nu . tau``. ``yc``: the constant
    part of ``y''`` (``y'`` in ``ydc``); ``af``, ``ap`` the weights of ``y''``, ``bf``, ``bp``
    of ``y'``; ``kap``: the weight of the point's own ``cos(theta)`` in ``y''``; ``wrad``
    ``(ng, ng)`` (or empty): the radiated energy ``1/2 z'^T wrad z'`` over the objective's
    points added to ``phi``."""
    k = af.shape[1]
    nt = j.size
    nfull = full.size
    ml, inertia, c, g = p[2], p[3], p[4], p[5]
    thf = np.empty((k, 4))
    for i in range(k):
        for q in range(4):
            v = 0.0
            for a in range(4):
                v += b0g[q, a] * full[2 * i + a]
            thf[i, q] = v
    cf = np.cos(thf)
    sf = np.sin(thf)
    th = np.empty(nt)
    thd = np.empty(nt)
    thdd = np.empty(nt)
    thp = np.empty((nt, 4))
    y = np.empty(nt)
    yd = np.empty(nt)
    for t in range(nt):
        jt = j[t]
        v0 = 0.0
        v1 = 0.0
        v2 = 0.0
        for a in range(4):
            la = full[2 * jt + a]
            v0 += b0[t, a] * la
            v1 += b1[t, a] * la
            v2 += b2[t, a] * la
        th[t], thd[t], thdd[t] = v0, v1, v2
        sa = 0.0
        sb = 0.0
        for i in range(jt):
            for q in range(4):
                sa += af[t, i, q] * cf[i, q]
                sb += bf[t, i, q] * cf[i, q]
        for q in range(4):
            v = 0.0
            for a in range(4):
                v += bp0[t, q, a] * full[2 * jt + a]
            thp[t, q] = v
            cq = math.cos(v)
            sa += ap[t, q] * cq
            sb += bp[t, q] * cq
        y[t] = yc[t] + sa
        yd[t] = ydc[t] + sb
    phi = 0.0
    zdv = np.empty(ng)
    for t in range(ng):
        zd = yd[t] + r * math.sin(th[t]) * thd[t]
        zdv[t] = zd
        phi += wgt[t] * (-f_t[t] * zd + c * thd[t] * thd[t])
    quad = wrad.shape[0] > 0
    # the adjoint of z' at the objective's points: -w f, plus wrad z' with the radiation
    lam = np.empty(ng)
    for t in range(ng):
        lam[t] = -wgt[t] * f_t[t]
    if quad:
        wz = wrad @ zdv
        for t in range(ng):
            phi += 0.5 * zdv[t] * wz[t]
            lam[t] += wz[t]
    for t in range(ng, nt):
        s = math.sin(th[t])
        co = math.cos(th[t])
        tau[t - ng] = ((inertia - ml * r * s * s) * thdd[t] + c * thd[t]
                       - ml * s * (g + r * co * thd[t] * thd[t])
                       - ml * s * (y[t] + kap * co))
    if order == 0:
        return phi
    grad[:] = 0.0
    hess[:, :] = 0.0
    jac[:, :] = 0.0
    # objective: the sources weighted by the adjoint of y', and the points' own terms
    lam_f = np.zeros((k, 4))
    gz = np.zeros((ng if quad else 0, nfull))
    for t in range(ng):
        jt = j[t]
        lt = lam[t]
        for i in range(jt):
            for q in range(4):
                lam_f[i, q] += lt * bf[t, i, q]
        for q in range(4):
            lp = lt * bp[t, q]
            c1 = -lp * math.sin(thp[t, q])
            c2 = -lp * math.cos(thp[t, q])
            for a in range(4):
                grad[2 * jt + a] += c1 * bp0[t, q, a]
                for b in range(4):
                    hess[2 * jt + a, 2 * jt + b] += c2 * bp0[t, q, a] * bp0[t, q, b]
        s = math.sin(th[t])
        co = math.cos(th[t])
        w = wgt[t]
        d_th = lt * r * co * thd[t]
        d_thd = lt * r * s + 2.0 * c * w * thd[t]
        h_tt = -lt * r * s * thd[t]
        h_td = lt * r * co
        h_dd = 2.0 * c * w
        if quad:
            # the gradient of z' here: the sources, its own interval's part, its own terms
            for i in range(jt):
                for q in range(4):
                    wq = -bf[t, i, q] * sf[i, q]
                    for a in range(4):
                        gz[t, 2 * i + a] += wq * b0g[q, a]
            for q in range(4):
                wq = -bp[t, q] * math.sin(thp[t, q])
                for a in range(4):
                    gz[t, 2 * jt + a] += wq * bp0[t, q, a]
            for a in range(4):
                gz[t, 2 * jt + a] += r * co * thd[t] * b0[t, a] + r * s * b1[t, a]
        for a in range(4):
            grad[2 * jt + a] += d_th * b0[t, a] + d_thd * b1[t, a]
            for b in range(4):
                hess[2 * jt + a, 2 * jt + b] += (h_tt * b0[t, a] * b0[t, b]
                                                 + h_td * (b0[t, a] * b1[t, b]
                                                           + b1[t, a] * b0[t, b])
                                                 + h_dd * b1[t, a] * b1[t, b])
    mu_f = np.zeros((k, 4))
    nc = nt - ng
    dy = np.zeros((nc, nfull))
    for t in range(ng, nt):
        jt = j[t]
        row = t - ng
        s = math.sin(th[t])
        co = math.cos(th[t])
        c2 = math.cos(2.0 * th[t])
        s2 = math.sin(2.0 * th[t])
        t_th = (-ml * r * s2 * thdd[t] - ml * co * g
                - ml * r * c2 * thd[t] * thd[t] - ml * co * y[t] - ml * kap * c2)
        t_thd = c - ml * r * s2 * thd[t]
        t_thdd = inertia - ml * r * s * s
        for a in range(4):
            jac[row, 2 * jt + a] += t_th * b0[t, a] + t_thd * b1[t, a] + t_thdd * b2[t, a]
        for i in range(jt):
            for q in range(4):
                wq = -af[t, i, q] * sf[i, q]
                for a in range(4):
                    dy[row, 2 * i + a] += wq * b0g[q, a]
        for q in range(4):
            wq = -ap[t, q] * math.sin(thp[t, q])
            for a in range(4):
                dy[row, 2 * jt + a] += wq * bp0[t, q, a]
        for col in range(nfull):
            jac[row, col] += -ml * s * dy[row, col]
        if order == 2:
            n_t = nu[row]
            p_tt = (-2.0 * ml * r * c2 * thdd[t] + ml * s * g
                    + 2.0 * ml * r * s2 * thd[t] * thd[t] + ml * s * y[t]
                    + 2.0 * ml * kap * s2)
            p_td = -2.0 * ml * r * c2 * thd[t]
            p_tdd = -ml * r * s2
            p_dd = -ml * r * s2
            for a in range(4):
                for b in range(4):
                    hess[2 * jt + a, 2 * jt + b] += n_t * (
                        p_tt * b0[t, a] * b0[t, b]
                        + p_td * (b0[t, a] * b1[t, b] + b1[t, a] * b0[t, b])
                        + p_tdd * (b0[t, a] * b2[t, b] + b2[t, a] * b0[t, b])
                        + p_dd * b1[t, a] * b1[t, b])
            wv = -ml * n_t * s
            for i in range(jt):
                for q in range(4):
                    mu_f[i, q] += wv * af[t, i, q]
            for q in range(4):
                c2q = -wv * ap[t, q] * math.cos(thp[t, q])
                for a in range(4):
                    for b in range(4):
                        hess[2 * jt + a, 2 * jt + b] += c2q * bp0[t, q, a] * bp0[t, q, b]
            cr = -ml * n_t * co
            for a in range(4):
                e = cr * b0[t, a]
                for col in range(nfull):
                    v = e * dy[row, col]
                    hess[2 * jt + a, col] += v
                    hess[col, 2 * jt + a] += v
    if quad:
        # the radiated energy's gz^T wrad gz (its wrad z' term is in the adjoint lam)
        hq = gz.T @ (wrad @ gz)
        for a in range(nfull):
            for b in range(nfull):
                hess[a, b] += hq[a, b]
    for i in range(k):
        for q in range(4):
            c2 = -(lam_f[i, q] + mu_f[i, q]) * cf[i, q]
            c1 = -lam_f[i, q] * sf[i, q]
            for a in range(4):
                grad[2 * i + a] += c1 * b0g[q, a]
                for b in range(4):
                    hess[2 * i + a, 2 * i + b] += c2 * b0g[q, a] * b0g[q, b]
    return phi


@nb.njit(cache=True)
def _cholesky(a, out):
    """Lower Cholesky factor of ``a`` into ``out``; False if ``a`` is not positive definite."""
    n = a.shape[0]
    for i in range(n):
        for j in range(i + 1):
            v = a[i, j]
            for k in range(j):
                v -= out[i, k] * out[j, k]
            if i == j:
                if not v > 0.0:
                    return False
                out[i, i] = math.sqrt(v)
            else:
                out[i, j] = v / out[j, j]
        for j in range(i + 1, n):
            out[i, j] = 0.0
    return True


@nb.njit(cache=True)
def _cho_solve(low, b):
    n = b.size
    y = np.empty(n)
    for i in range(n):
        v = b[i]
        for k in range(i):
            v -= low[i, k] * y[k]
        y[i] = v / low[i, i]
    x = np.empty(n)
    for i in range(n - 1, -1, -1):
        v = y[i]
        for k in range(i + 1, n):
            v -= low[k, i] * x[k]
        x[i] = v / low[i, i]
    return x


#: the inertia correction's shifts at most (each 8 times the last: from 1e-8 of the
#: Hessian's diagonal past any finite matrix's spectrum); a matrix that no shift makes
#: definite (a NaN in it) ends the solve as not finite rather than looping
MAX_CORRECTIONS = 100


@nb.njit(cache=True)
def solve(x, start, j, b0, b1, b2, af, bf, ap, bp, bp0, b0g, wgt, f_t, yc, ydc, ng, p, r,
          kap, wrad, tmax, max_iter, tol, mu0):
    """The interior point of :meth:`._buoy_plan.CoupledPlan.solve` as one compiled call:
    returns ``(x, status, iterations)`` (status 0 converged, 1 iteration limit, 2 line
    search, 3 not finite)."""
    n = x.size
    nfull = n + 2
    nt = j.size
    nc = nt - ng
    m = 2 * nc
    full = np.empty(nfull)
    full[0], full[1] = start[0], start[1]
    x = x.copy()
    full[2:] = x
    grad = np.empty(nfull)
    hess = np.empty((nfull, nfull))
    tau = np.empty(nc)
    jac = np.empty((nc, nfull))
    nu = np.zeros(nc)
    evaluate(full, j, b0, b1, b2, af, bf, ap, bp, bp0, b0g, wgt, f_t, yc, ydc, ng, p, r, kap,
             wrad, nu, 1, grad, hess, tau, jac)
    scale = 1.0
    for i in range(n):
        scale = max(scale, abs(grad[2 + i]))
    mu = mu0 * scale
    s = np.empty(m)
    gv = np.empty(m)
    for i in range(nc):
        gv[i] = tau[i] / tmax - 1.0
        gv[nc + i] = -tau[i] / tmax - 1.0
    for i in range(m):
        s[i] = max(-gv[i], 1e-2)
    lam = mu / s
    rho = 0.0
    status = 1
    it = 0
    delta_last = 0.0
    low = np.empty((n, n))
    kmat = np.empty((n, n))
    tau_t = np.empty(nc)
    while it < max_iter:
        it += 1
        for i in range(nc):
            nu[i] = (lam[i] - lam[nc + i]) / tmax
        phi = evaluate(full, j, b0, b1, b2, af, bf, ap, bp, bp0, b0g, wgt, f_t, yc, ydc, ng,
                       p, r, kap, wrad, nu, 2, grad, hess, tau, jac)
        fin = math.isfinite(phi)
        for i in range(n):
            fin = fin and math.isfinite(grad[2 + i])
        if not fin:
            status = 3
            break
        gr = grad[2:].copy()
        jc = jac[:, 2:].copy()
        for i in range(nc):
            gv[i] = tau[i] / tmax - 1.0
            gv[nc + i] = -tau[i] / tmax - 1.0
        rd = gr + jc.T @ nu
        rp = gv + s
        comp = 0.0
        for i in range(m):
            comp += s[i] * lam[i]
        comp /= m
        rdm = np.max(np.abs(rd))
        rpm = np.max(np.abs(rp))
        if rdm < tol * scale and rpm < 1e-7 and comp < tol * scale:
            status = 0
            break
        err = max(rdm / scale, rpm, np.max(np.abs(s * lam - mu)) / scale)
        if err <= 10.0 * mu / scale:
            mu = max(min(0.2 * mu, mu ** 1.5 / scale ** 0.5), 0.1 * tol * scale)
        sig = lam / s
        wj = (sig[:nc] + sig[nc:]) / (tmax * tmax)
        v = mu / s + sig * rp
        vv = (v[:nc] - v[nc:]) / tmax
        rhs = -(gr + jc.T @ vv)
        hm = hess[2:, 2:]
        jw = jc * wj.reshape(-1, 1)
        kmat[:, :] = hm + jc.T @ jw
        dmin = 1.0
        for a in range(n):
            dmin = max(dmin, abs(hm[a, a]))
        dmin *= 1e-8
        delta = 0.0
        ok = False
        for _ in range(MAX_CORRECTIONS):
            for a in range(n):
                kmat[a, a] += delta
            ok = _cholesky(kmat, low)
            for a in range(n):
                kmat[a, a] -= delta
            if ok or not math.isfinite(delta):
                break
            delta = max(dmin, delta_last / 3.0, 8.0 * delta)
        if not ok:  # a Hessian with a NaN (or no shift that makes it definite): no step
            status = 3
            break
        if delta > 0.0:
            delta_last = delta
        dx = _cho_solve(low, rhs)
        jdx = jc @ dx
        ds = np.empty(m)
        for i in range(nc):
            ds[i] = -rp[i] - jdx[i] / tmax
            ds[nc + i] = -rp[nc + i] + jdx[i] / tmax
        dl = mu / s - lam - sig * ds
        a_p = max_step(s, ds, 0.995)
        a_d = max_step(lam, dl, 0.995)
        # the exact penalty's weight from the multipliers now and after the step, not held at
        # its largest: a weight the early multipliers left far above them makes the merit
        # reject every step on which the torque bends away from its linearization
        rho = 1.1 * max(np.max(np.abs(lam)), np.max(np.abs(lam + min(a_d, 1.0) * dl)))
        m0 = phi - mu * np.sum(np.log(s)) + rho * np.sum(np.abs(rp))
        dm = gr @ dx - mu * np.sum(ds / s) - rho * np.sum(np.abs(rp))
        a = a_p
        ok = False
        for _ in range(30):
            for i in range(n):
                full[2 + i] = x[i] + a * dx[i]
            st = s + a * ds
            ft = evaluate(full, j, b0, b1, b2, af, bf, ap, bp, bp0, b0g, wgt, f_t, yc, ydc,
                          ng, p, r, kap, wrad, nu, 0, grad, hess, tau_t, jac)
            mt = ft - mu * np.sum(np.log(st))
            for i in range(nc):
                mt += rho * (abs(tau_t[i] / tmax - 1.0 + st[i])
                             + abs(-tau_t[i] / tmax - 1.0 + st[nc + i]))
            if math.isfinite(mt) and mt <= m0 + 1e-4 * a * min(dm, 0.0):
                ok = True
                break
            a *= 0.5
        if not ok:
            for i in range(n):
                full[2 + i] = x[i]
            if rpm < 1e-6 and comp < 10.0 * tol * scale:
                status = 0
            else:
                status = 2
            break
        for i in range(n):
            x[i] = full[2 + i]
        s = st
        lam = lam + min(a_d, 1.0) * dl
    return x, status, it
