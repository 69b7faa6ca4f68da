r"""Compiled (numba) evaluation of the hull's collocation horizon problem
(:mod:`._hull_collocation`) for its interior point (:mod:`._hull_collocation_ipm`): the
objective, the local constraints (the plant's four equations at every point of every
interval, Hermite-Simpson's interpolation and quadrature) and, on request, the gradient, the
constraints' Jacobian and the Hessian of the Lagrangian, in one pass over the intervals.

The unknowns are :class:`._hull_collocation.HullCollocation`'s vector ``x``: the states at the
points ``x[8 k + j]``, the accelerations ``x[nx + 4 c + j]`` (``c = 3 i + e``: interval ``i``,
``e`` its start, midpoint, end), the held torques ``x[nx + na + j]`` and the memory at its
nodes ``x[nx + na + n + 3 q + d]`` (units ``m g l``). The local rows, ``28`` an interval: its
three points' residuals (4 each, divided by ``tu``: the hull's three, the pendulum's), the
interpolation of ``q`` and of ``v`` at the midpoint and the quadrature of ``q`` and ``v``
(4 each). With ``s = sin phi``, ``cvec = m l G^T a``, ``bvec = G^T b`` (their ``phi``
derivatives ``-m l bvec`` and ``cvec / (m l)``) the residuals are

    R_h = M_t xi'' + cvec phi'' - F + mu + C' xi - m l bvec phi'^2 - e_beta (c v - tau)
    R_p = cvec . xi'' + I phi'' - tau + c v - m l g s

whose only second derivatives are in ``(phi, phi', xi'', phi'')``: the Hessian has 12
entries a point. The Jacobian and the Hessian come as coordinate lists (rows, columns,
values) in a fixed order, so the caller builds their sparse patterns once.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .._jit import announce_compiles

announce_compiles()  # log a first-use compile (parapend._jit)

#: local rows an interval, Jacobian entries an interval, Hessian entries a point
ROWS = 28
JAC = 221
HESS = 12


@nb.njit(cache=True)
def _point(x, kp, c, tau, wa, wb, qa, qb, fk, mt, cp, gm, par, tu, lam, row, order, cons,
           jr, jc, jv, jn, hr, hc, hv, hn):
    """The residuals of point ``kp`` with the accelerations ``c`` (rows ``row..row+3``) under
    the torque ``tau`` (``tu`` units) and the memory ``wa x_qa + wb x_qb`` at the nodes ``qa``,
    ``qb`` (their first entries' indices); their Jacobian and the Hessian of ``lam`` times them
    when ``order`` asks. Returns the entries written ``(jn, hn)``."""
    m, ell, inertia, cc, g = par[0], par[1], par[2], par[3], par[4]
    ml = m * ell
    yi = 8 * kp
    ai = c
    phi = x[yi + 3]
    w7 = x[yi + 7]
    v = w7 - x[yi + 6]
    s = math.sin(phi)
    co = math.cos(phi)
    cvec = np.empty(3)
    bvec = np.empty(3)
    for i in range(3):
        cvec[i] = ml * (gm[0, i] * co - gm[1, i] * s)
        bvec[i] = gm[0, i] * s + gm[1, i] * co
    a3 = x[ai + 3]
    inv = 1.0 / tu
    rp = inertia * a3 - tau + cc * v - ml * g * s
    for i in range(3):
        r = (cvec[i] * a3 - fk[i] + (wa * x[qa + i] + wb * x[qb + i]) * tu
             - ml * bvec[i] * w7 * w7)
        for j in range(3):
            r += mt[i, j] * x[ai + j] + cp[i, j] * x[yi + j]
        if i == 2:
            r -= cc * v - tau
        cons[row + i] = r * inv
        rp += cvec[i] * x[ai + i]
    cons[row + 3] = rp * inv
    if order >= 1:
        for i in range(3):
            rr = row + i
            for j in range(3):
                jr[jn], jc[jn], jv[jn] = rr, ai + j, mt[i, j] * inv
                jn += 1
            jr[jn], jc[jn], jv[jn] = rr, ai + 3, cvec[i] * inv
            jn += 1
            for j in range(3):
                jr[jn], jc[jn], jv[jn] = rr, yi + j, cp[i, j] * inv
                jn += 1
            jr[jn], jc[jn] = rr, yi + 3
            jv[jn] = (-ml * bvec[i] * a3 - cvec[i] * w7 * w7) * inv
            jn += 1
            e2 = 1.0 if i == 2 else 0.0
            jr[jn], jc[jn], jv[jn] = rr, yi + 6, e2 * cc * inv
            jn += 1
            jr[jn], jc[jn], jv[jn] = rr, yi + 7, (-2.0 * ml * bvec[i] * w7 - e2 * cc) * inv
            jn += 1
            jr[jn], jc[jn], jv[jn] = rr, -1, e2  # the torque (column set by the caller)
            jn += 1
            jr[jn], jc[jn], jv[jn] = rr, qa + i, wa
            jn += 1
            jr[jn], jc[jn], jv[jn] = rr, qb + i, wb
            jn += 1
        rr = row + 3
        dphi = -ml * g * co
        for i in range(3):
            jr[jn], jc[jn], jv[jn] = rr, ai + i, cvec[i] * inv
            jn += 1
            dphi -= ml * bvec[i] * x[ai + i]
        jr[jn], jc[jn], jv[jn] = rr, ai + 3, inertia * inv
        jn += 1
        jr[jn], jc[jn], jv[jn] = rr, yi + 3, dphi * inv
        jn += 1
        jr[jn], jc[jn], jv[jn] = rr, yi + 6, -cc * inv
        jn += 1
        jr[jn], jc[jn], jv[jn] = rr, yi + 7, cc * inv
        jn += 1
        jr[jn], jc[jn], jv[jn] = rr, -1, -1.0
        jn += 1
    if order >= 2:
        l3 = lam[row + 3] * inv
        hpp = l3 * ml * g * s
        hpa3 = 0.0
        hp7 = 0.0
        h77 = 0.0
        for i in range(3):
            li = lam[row + i] * inv
            hpp += li * (-cvec[i] * a3 + ml * bvec[i] * w7 * w7) - l3 * cvec[i] * x[ai + i]
            hpa3 -= li * ml * bvec[i]
            hp7 -= 2.0 * li * cvec[i] * w7
            h77 -= 2.0 * li * ml * bvec[i]
        hr[hn], hc[hn], hv[hn] = yi + 3, yi + 3, hpp
        hn += 1
        hr[hn], hc[hn], hv[hn] = yi + 7, yi + 7, h77
        hn += 1
        hr[hn], hc[hn], hv[hn] = yi + 3, yi + 7, hp7
        hn += 1
        hr[hn], hc[hn], hv[hn] = yi + 7, yi + 3, hp7
        hn += 1
        hr[hn], hc[hn], hv[hn] = yi + 3, ai + 3, hpa3
        hn += 1
        hr[hn], hc[hn], hv[hn] = ai + 3, yi + 3, hpa3
        hn += 1
        for i in range(3):
            hr[hn], hc[hn], hv[hn] = yi + 3, ai + i, -l3 * ml * bvec[i]
            hn += 1
            hr[hn], hc[hn], hv[hn] = ai + i, yi + 3, -l3 * ml * bvec[i]
            hn += 1
    return jn, hn


@nb.njit(cache=True)
def _energy(x, yi, mt, cp, gm, par, pendulum_only, grad, hess):
    """The mechanical energy of the state at ``x[yi:yi + 8]`` (``E`` of :mod:`._hull_kernel`,
    the hull's kinetic and restoring parts left out with ``pendulum_only``); its gradient and
    Hessian (8, 8) into ``grad``, ``hess``."""
    m, ell, inertia, g = par[0], par[1], par[2], par[4]
    ml = m * ell
    y = x[yi:yi + 8]
    s = math.sin(y[3])
    co = math.cos(y[3])
    full = 0.0 if pendulum_only else 1.0
    for i in range(8):
        grad[i] = 0.0
        for j in range(8):
            hess[i, j] = 0.0
    e = 0.5 * inertia * y[7] * y[7] + ml * g * co
    grad[7] = inertia * y[7]
    grad[3] = -ml * g * s
    hess[7, 7] = inertia
    hess[3, 3] = -ml * g * co
    for i in range(3):
        ci = ml * (gm[0, i] * co - gm[1, i] * s)
        bi = ml * (gm[0, i] * s + gm[1, i] * co)  # -d(ci)/dphi
        e += ci * y[7] * y[4 + i]
        grad[4 + i] += ci * y[7]
        grad[7] += ci * y[4 + i]
        grad[3] -= bi * y[7] * y[4 + i]
        hess[4 + i, 7] += ci
        hess[7, 4 + i] += ci
        hess[4 + i, 3] -= bi * y[7]
        hess[3, 4 + i] -= bi * y[7]
        hess[7, 3] -= bi * y[4 + i]
        hess[3, 7] -= bi * y[4 + i]
        hess[3, 3] -= ci * y[7] * y[4 + i]
        for j in range(3):
            ms = 0.5 * (mt[i, j] + mt[j, i]) * full
            cs = 0.5 * (cp[i, j] + cp[j, i]) * full
            e += full * (0.5 * mt[i, j] * y[4 + i] * y[4 + j] + 0.5 * cp[i, j] * y[i] * y[j])
            grad[4 + i] += ms * y[4 + j]
            grad[i] += cs * y[j]
            hess[4 + i, 4 + j] += ms
            hess[i, j] += cs
    return e


@nb.njit(cache=True)
def evaluate(x, lam, order, npt, intervals, stride, n, hh, mt, cp, gm, par, tu, fk, kappa, ae,
             be, width, pendulum_only, e0, cons, grad, jr, jc, jv, hr, hc, hv):
    """The objective (returned, minimized, ``m g l rad``) and the local constraints into
    ``cons`` (``ROWS`` an interval); with ``order >= 1`` the objective's gradient (``grad``)
    and the constraints' Jacobian (``jr``, ``jc``, ``jv``: ``JAC`` an interval); with
    ``order == 2`` the Hessian of the objective plus ``lam . cons`` (``hr``, ``hc``, ``hv``).
    ``fk`` (npt, 3): the forecast force at the points (SI, as the plant's); ``e0`` the
    energy at the start (the objective's constant); ``par = (m, l, I, c, g)``. Returns
    ``(f, jacobian entries, hessian entries)``."""
    ni = (npt - 1) // 2
    nx = 8 * npt
    na = 12 * ni
    uo = nx + na
    mo = uo + n
    hi = 2.0 * hh  # the interval's length (``hh`` the points' spacing, s)
    jn = 0
    hn = 0
    if order >= 1:
        for i in range(grad.size):
            grad[i] = 0.0
    for iv in range(ni):
        tau = x[uo + iv // intervals] * tu
        row = ROWS * iv
        j0 = jn
        for e in range(3):
            kp = 2 * iv + e
            q, rr = kp // stride, kp % stride
            f = rr / stride
            qb = q + 1 if rr else q
            jn, hn = _point(x, kp, nx + 4 * (3 * iv + e), tau, 1.0 - f, f, mo + 3 * q,
                            mo + 3 * qb, fk[kp], mt, cp, gm, par, tu, lam, row + 4 * e, order,
                            cons, jr, jc, jv, jn, hr, hc, hv, hn)
        if order >= 1:  # the torque's column of the residuals
            for t in range(j0, jn):
                if jc[t] == -1:
                    jc[t] = uo + iv // intervals
        y0, ym, y1 = 8 * (2 * iv), 8 * (2 * iv + 1), 8 * (2 * iv + 2)
        c0 = nx + 4 * (3 * iv)
        cm, c1 = c0 + 4, c0 + 8
        for r in range(4):
            cons[row + 12 + r] = (x[ym + r] - 0.5 * (x[y0 + r] + x[y1 + r])
                                  - hi / 8.0 * (x[y0 + 4 + r] - x[y1 + 4 + r]))
            cons[row + 16 + r] = (x[ym + 4 + r] - 0.5 * (x[y0 + 4 + r] + x[y1 + 4 + r])
                                  - hi / 8.0 * (x[c0 + r] - x[c1 + r]))
            cons[row + 20 + r] = (x[y1 + r] - x[y0 + r] - hi / 6.0
                                  * (x[y0 + 4 + r] + 4.0 * x[ym + 4 + r] + x[y1 + 4 + r]))
            cons[row + 24 + r] = (x[y1 + 4 + r] - x[y0 + 4 + r] - hi / 6.0
                                  * (x[c0 + r] + 4.0 * x[cm + r] + x[c1 + r]))
        if order >= 1:
            for r in range(4):
                rr = row + 12 + r
                for col, val in ((ym + r, 1.0), (y0 + r, -0.5), (y1 + r, -0.5),
                                 (y0 + 4 + r, -hi / 8.0), (y1 + 4 + r, hi / 8.0)):
                    jr[jn], jc[jn], jv[jn] = rr, col, val
                    jn += 1
                rr = row + 16 + r
                for col, val in ((ym + 4 + r, 1.0), (y0 + 4 + r, -0.5), (y1 + 4 + r, -0.5),
                                 (c0 + r, -hi / 8.0), (c1 + r, hi / 8.0)):
                    jr[jn], jc[jn], jv[jn] = rr, col, val
                    jn += 1
                rr = row + 20 + r
                for col, val in ((y1 + r, 1.0), (y0 + r, -1.0), (y0 + 4 + r, -hi / 6.0),
                                 (ym + 4 + r, -4.0 * hi / 6.0), (y1 + 4 + r, -hi / 6.0)):
                    jr[jn], jc[jn], jv[jn] = rr, col, val
                    jn += 1
                rr = row + 24 + r
                for col, val in ((y1 + 4 + r, 1.0), (y0 + 4 + r, -1.0), (c0 + r, -hi / 6.0),
                                 (cm + r, -4.0 * hi / 6.0), (c1 + r, -hi / 6.0)):
                    jr[jn], jc[jn], jv[jn] = rr, col, val
                    jn += 1
    # the objective: the electrical work of every held torque and the terminal energy
    fobj = 0.0
    sp = 2 * intervals
    idx = np.empty(5, np.int64)
    gl = np.empty(5)
    for j in range(n):
        ka, kb = 8 * (sp * j), 8 * (sp * (j + 1))
        dth = (x[kb + 3] - x[kb + 2]) - (x[ka + 3] - x[ka + 2])
        u = x[uo + j]
        pw = -u * dth
        rt = math.sqrt(pw * pw + width * width)
        fobj -= ae * pw + be * (rt - width)
        if order >= 1:
            d1 = ae + be * pw / rt
            d2 = be * width * width / (rt * rt * rt)
            idx[0], idx[1], idx[2], idx[3], idx[4] = uo + j, kb + 3, kb + 2, ka + 3, ka + 2
            gl[0], gl[1], gl[2], gl[3], gl[4] = -dth, -u, u, u, -u
            for a in range(5):
                grad[idx[a]] -= d1 * gl[a]
            if order >= 2:
                for a in range(5):
                    for b in range(5):
                        val = -d2 * gl[a] * gl[b]
                        if a == 0 and b > 0:
                            val -= d1 * (-1.0 if b % 2 else 1.0) * (-1.0 if b > 2 else 1.0)
                        elif b == 0 and a > 0:
                            val -= d1 * (-1.0 if a % 2 else 1.0) * (-1.0 if a > 2 else 1.0)
                        hr[hn], hc[hn], hv[hn] = idx[a], idx[b], val
                        hn += 1
    ge = np.empty(8)
    he = np.empty((8, 8))
    yl = 8 * (npt - 1)
    en = _energy(x, yl, mt, cp, gm, par, pendulum_only, ge, he)
    wk = -kappa / tu
    fobj += wk * (en - e0)
    if order >= 1:
        for i in range(8):
            grad[yl + i] += wk * ge[i]
        if order >= 2:
            for i in range(8):
                for j in range(8):
                    hr[hn], hc[hn], hv[hn] = yl + i, yl + j, wk * he[i, j]
                    hn += 1
    return fobj, jn, hn
