r"""Compiled (numba) kernel of the hull's closed loop (:mod:`.hull_control`): the pendulum in
a hull that surges, heaves and pitches, Cummins' equation in three degrees of freedom with
the 3 x 3 radiation memory, advanced by the buoy's scheme (:mod:`._control_kernel`: RK4 on a
fixed step ``h``, the memory a trapezoidal sum over the stored velocities, extrapolated
quadratically inside a step), the torque held over each sample of ``steps`` steps.

The model is :mod:`.hull`'s (docs/hull.md) with the added mass at infinite frequency and the
memory in place of ``A(w)``, ``B(w)``: hull ``xi = (x, z, beta)``, the pivot at ``p = G xi``,
``phi`` the pendulum's absolute angle from the upward vertical, ``theta = phi - beta`` the
generator's,

    M_t xi'' + m l G^T a phi'' = F - mu - C' xi + m l G^T b phi'^2 + e_beta (c v - tau)
    m l a^T G xi'' + I phi''   = tau - c v + m l g sin(phi)

with ``a = (cos phi, -sin phi)``, ``b = (sin phi, cos phi)``, ``v = phi' - beta'``,
``M_t = M_h + A_inf + m G^T G`` and ``C' = C - m g h_p e_beta e_beta^T``: the symmetric 4 x 4
mass matrix of the Lagrangian ``1/2 xi'^T M_t xi' + m l phi' a^T G xi' + 1/2 I phi'^2``, so
that the mechanical energy ``E = 1/2 q'^T M q' + 1/2 xi^T C' xi + m g l cos(phi)`` obeys
``E' = (F - mu) . xi' - c v^2 + tau v`` and the harvested power is ``-tau v``.

State ``y = (x, z, beta, phi, x', z', beta', phi')`` (SI). ``vel[k0 + j]``, ``j = 0..nk``,
the hull's velocity at ``t - (nk - j) h``; :func:`roll` appends the new ones after it.
``mus[0..2]``: the memory force at ``t``, ``t - h``, ``t - 2 h``. ``par = (m, l, I, c, g)``.

With ``jac`` of one row per step :func:`roll` also keeps every stage's Jacobian of the
accelerations with respect to ``(y, mu, tau)``; :func:`adjoint` then runs the same scheme
backwards (the memory of the motion since the start included): the exact gradient of a
function of the states at the samples' ends with respect to every held torque, at the cost
of about one more pass (the horizon problem's, :mod:`.hull_control`).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .._jit import announce_compiles

announce_compiles()  # log a first-use compile (parapend._jit)


@nb.njit(cache=True)
def _accel(y, mu, f, tau, mt, cp, gm, par, acc, minv, cvec, bvec):
    """The accelerations ``(xi'', phi'')`` of the state ``y`` into ``acc``; ``minv`` the
    inverse mass matrix, ``cvec = m l G^T a`` and ``bvec = G^T b`` at ``phi`` (in place).
    ``mt``: ``M_t^-1``."""
    m, ell, inertia, c, g = par[0], par[1], par[2], par[3], par[4]
    ml = m * ell
    s = math.sin(y[3])
    co = math.cos(y[3])
    for i in range(3):
        cvec[i] = ml * (gm[0, i] * co - gm[1, i] * s)
        bvec[i] = gm[0, i] * s + gm[1, i] * co
    # the inverse by the Schur complement of the constant block M_t (``mt`` holds M_t^-1)
    q = np.empty(3)
    for i in range(3):
        v = 0.0
        for j in range(3):
            v += mt[i, j] * cvec[j]
        q[i] = v
    sc = inertia
    for i in range(3):
        sc -= cvec[i] * q[i]
    for i in range(3):
        for j in range(3):
            minv[i, j] = mt[i, j] + q[i] * q[j] / sc
        minv[i, 3] = minv[3, i] = -q[i] / sc
    minv[3, 3] = 1.0 / sc
    vr = y[7] - y[6]
    r = np.empty(4)
    for i in range(3):
        v = f[i] - mu[i] + ml * bvec[i] * y[7] * y[7]
        for j in range(3):
            v -= cp[i, j] * y[j]
        r[i] = v
    r[2] += c * vr - tau
    r[3] = tau - c * vr + ml * g * s
    for i in range(4):
        v = 0.0
        for j in range(4):
            v += minv[i, j] * r[j]
        acc[i] = v


@nb.njit(cache=True)
def _daccel(y, dy, dmu, dtau, acc, minv, cvec, bvec, cp, par, out):
    """The tangent of :func:`_accel` (after it, at the same state) along the columns of
    ``dy`` (8, nc), ``dmu`` (3, nc) and ``dtau`` (nc,) into ``out`` (4, nc)."""
    m, ell, c, g = par[0], par[1], par[3], par[4]
    ml = m * ell
    co = math.cos(y[3])
    nc = out.shape[1]
    r = np.empty(4)
    for k in range(nc):
        dphi, dphid, dbd = dy[3, k], dy[7, k], dy[6, k]
        dv = dphid - dbd
        for i in range(3):
            v = -dmu[i, k] + cvec[i] * y[7] * y[7] * dphi + 2.0 * ml * bvec[i] * y[7] * dphid
            for j in range(3):
                v -= cp[i, j] * dy[j, k]
            # the mass matrix's own change: d(cvec)/dphi = -m l bvec
            v += ml * bvec[i] * acc[3] * dphi
            r[i] = v
        r[2] += c * dv - dtau[k]
        r[3] = dtau[k] - c * dv + ml * g * co * dphi
        sb = 0.0
        for i in range(3):
            sb += bvec[i] * acc[i]
        r[3] += ml * sb * dphi
        for i in range(4):
            v = 0.0
            for j in range(4):
                v += minv[i, j] * r[j]
            out[i, k] = v


@nb.njit(cache=True)
def energy(y, mt, cp, gm, par):
    """The mechanical energy ``E`` (J) of hull and pendulum (module docstring)."""
    m, ell, inertia, g = par[0], par[1], par[2], par[4]
    ml = m * ell
    s = math.sin(y[3])
    co = math.cos(y[3])
    e = 0.5 * inertia * y[7] * y[7] + ml * g * co
    for i in range(3):
        ci = ml * (gm[0, i] * co - gm[1, i] * s)
        e += ci * y[7] * y[4 + i]
        for j in range(3):
            e += 0.5 * mt[i, j] * y[4 + i] * y[4 + j] + 0.5 * cp[i, j] * y[i] * y[j]
    return e


@nb.njit(cache=True)
def denergy(y, dy, mt, cp, gm, par, out):
    """The tangent of :func:`energy` along the columns of ``dy`` (8, nc) into ``out``."""
    m, ell, inertia, g = par[0], par[1], par[2], par[4]
    ml = m * ell
    s = math.sin(y[3])
    co = math.cos(y[3])
    nc = out.size
    for k in range(nc):
        v = inertia * y[7] * dy[7, k] - ml * g * s * dy[3, k]
        for i in range(3):
            ci = ml * (gm[0, i] * co - gm[1, i] * s)
            dci = -ml * (gm[0, i] * s + gm[1, i] * co)
            v += ci * (dy[7, k] * y[4 + i] + y[7] * dy[4 + i, k])
            v += dci * dy[3, k] * y[7] * y[4 + i]
            for j in range(3):
                v += mt[i, j] * y[4 + j] * dy[4 + i, k] + cp[i, j] * y[j] * dy[i, k]
        out[k] = v


#: the memory's quadratic extrapolation to a step's midpoint and end from its values at the
#: step and the two before (:mod:`._control_kernel`): ``mu = sum c_k m_k``
_MID = (1.875, -1.25, 0.375)
_END = (3.0, -3.0, 1.0)
#: unit columns of ``(y, mu, tau)``
_UNIT = np.eye(12)


@nb.njit(cache=True)
def _stage_jacobian(y, acc, minv, cvec, bvec, cp, par, out):
    """``d acc / d (y, mu, tau)`` (4, 12) of one stage (:func:`_daccel` on unit columns)."""
    _daccel(y, _UNIT[:8], _UNIT[8:11], _UNIT[11], acc, minv, cvec, bvec, cp, par, out)


@nb.njit(cache=True)
def roll(y, vel, k0, mus, u, steps, fn, h, w, mti, cp, gm, par, ys, acc, jac):
    """Advance ``y`` over ``len(u)`` held torques (N m) of ``steps`` RK4 steps of ``h``.

    ``fn`` (nodes, 3): the excitation (N, N, N m) at the half-step nodes (``2 len(u) steps
    + 1``); ``w`` (nk + 1, 3, 3) the memory's weights; ``mti`` ``M_t^-1``. On exit
    ``ys[k]`` is the state after ``k`` samples (``ys[0]`` the start) and ``acc``
    accumulates the RK4 quadratures of the power the hull absorbs ``(F - mu) . xi'``
    (``acc[0]``), of the damping ``c v^2`` (``acc[1]``) and the exact work of the held
    torque ``-tau (theta_1 - theta_0)`` (``acc[2]``), J. ``jac`` (steps in all, 4, 4, 12)
    or empty: every stage's Jacobian (:func:`adjoint`). Returns False if ``|phi'|`` left
    ``1e6``.
    """
    nk = w.shape[0] - 1
    keep = jac.shape[0] > 0
    c = par[3]
    n = u.size
    m0, m1, m2 = mus[0].copy(), mus[1].copy(), mus[2].copy()
    mh = np.empty(3)
    me = np.empty(3)
    minv = np.empty((4, 4))
    cvec = np.empty(3)
    bvec = np.empty(3)
    ka = np.empty((4, 4))
    st = np.empty((4, 8))
    vr = np.empty(4)
    yy = y.copy()
    ys[0] = yy
    ok = True
    for j in range(n):
        tau = u[j]
        for s in range(steps):
            i = j * steps + s
            for d in range(3):
                mh[d] = _MID[0] * m0[d] + _MID[1] * m1[d] + _MID[2] * m2[d]
                me[d] = _END[0] * m0[d] + _END[1] * m1[d] + _END[2] * m2[d]
            # the four stages: st[q] the stage's state, ka[q] its accelerations
            for q in range(4):
                if q == 0:
                    st[0] = yy
                else:
                    frac = 0.5 * h if q < 3 else h
                    for a in range(4):
                        st[q, a] = yy[a] + frac * st[q - 1, 4 + a]
                        st[q, 4 + a] = yy[4 + a] + frac * ka[q - 1, a]
                node = 2 * i if q == 0 else (2 * i + 1 if q < 3 else 2 * i + 2)
                mu = m0 if q == 0 else (mh if q < 3 else me)
                _accel(st[q], mu, fn[node], tau, mti, cp, gm, par, ka[q], minv, cvec, bvec)
                if keep:
                    _stage_jacobian(st[q], ka[q], minv, cvec, bvec, cp, par, jac[i, q])
            f0, fm, f1 = fn[2 * i], fn[2 * i + 1], fn[2 * i + 2]
            pa = 0.0
            for d in range(3):
                pa += ((f0[d] - m0[d]) * st[0, 4 + d] + (fm[d] - mh[d])
                       * (st[1, 4 + d] + st[2, 4 + d]) * 2.0 + (f1[d] - me[d]) * st[3, 4 + d])
            acc[0] += h / 6.0 * pa
            for q in range(4):
                vr[q] = st[q, 7] - st[q, 6]
            acc[1] += h / 6.0 * c * (vr[0] ** 2 + 2.0 * vr[1] ** 2 + 2.0 * vr[2] ** 2
                                     + vr[3] ** 2)
            th0 = yy[3] - yy[2]
            for a in range(4):
                yy[a] += h / 6.0 * (st[0, 4 + a] + 2.0 * st[1, 4 + a] + 2.0 * st[2, 4 + a]
                                    + st[3, 4 + a])
                yy[4 + a] += h / 6.0 * (ka[0, a] + 2.0 * ka[1, a] + 2.0 * ka[2, a] + ka[3, a])
            acc[2] -= tau * (yy[3] - yy[2] - th0)
            # the memory at the new step point: trapezoid over the stored velocity
            e = k0 + nk + i + 1
            m2[:] = m1
            m1[:] = m0
            for d in range(3):
                vel[e, d] = yy[4 + d]
            for d in range(3):
                v = 0.0
                for q in range(nk + 1):
                    for b in range(3):
                        v += w[q, d, b] * vel[e - q, b]
                m0[d] = v
        ys[j + 1] = yy
        if not abs(yy[7]) < 1e6:
            ok = False
            break
    y[:] = yy
    mus[0], mus[1], mus[2] = m0, m1, m2
    return ok


@nb.njit(cache=True)
def adjoint(jac, w, steps, h, seeds):
    """The gradient ``dJ / dtau_j`` (N m^-1 units of ``J``) of a function ``J`` of the
    states at the samples' ends, ``seeds[k] = dJ / dy`` at sample ``k`` (``(n + 1, 8)``),
    through :func:`roll`'s scheme backwards from the stage Jacobians ``jac`` it kept: the
    memory of the motion since the start (not of the velocities before it, which are
    fixed) carried as the transposed convolution."""
    nk = w.shape[0] - 1
    ns = jac.shape[0]
    n = ns // steps
    grad = np.zeros(n)
    ly = seeds[n].copy()
    lm0 = np.zeros(3)
    lm1 = np.zeros(3)
    lm2 = np.zeros(3)
    lvel = np.zeros((ns + 1, 3))
    lk = np.empty((4, 8))
    ls = np.empty(8)
    la = np.empty(4)
    lmu = np.empty((4, 3))
    wq = (1.0, 2.0, 2.0, 1.0)
    cq = (0.0, 0.5 * h, 0.5 * h, h)
    for i in range(ns - 1, -1, -1):
        j = i // steps
        # the memory at the step's end, m0 = sum_q W_q vel_(i+1-q) over the run's steps
        for d in range(3):
            ly[4 + d] += lvel[i + 1, d]
        for q in range(min(nk, i) + 1):
            for b in range(3):
                v = 0.0
                for d in range(3):
                    v += w[q, d, b] * lm0[d]
                if q == 0:
                    ly[4 + b] += v
                else:
                    lvel[i + 1 - q, b] += v
        # the memory's shift: m1' = m0, m2' = m1
        nm0 = lm1.copy()
        nm1 = lm2.copy()
        nm2 = np.zeros(3)
        # RK4 backwards: y' = y + h/6 sum w_q k_q, k_q = (s_q[4:], a_q), s_q = y + c_q k_(q-1)
        for q in range(4):
            for a in range(8):
                lk[q, a] = h / 6.0 * wq[q] * ly[a]
        lyn = ly.copy()
        for q in range(3, -1, -1):
            for a in range(4):
                la[a] = lk[q, 4 + a]
            for a in range(8):
                v = 0.0
                for r in range(4):
                    v += jac[i, q, r, a] * la[r]
                ls[a] = v
            for a in range(4):
                ls[4 + a] += lk[q, a]
            for d in range(3):
                v = 0.0
                for r in range(4):
                    v += jac[i, q, r, 8 + d] * la[r]
                lmu[q, d] = v
            tq = 0.0
            for r in range(4):
                tq += jac[i, q, r, 11] * la[r]
            grad[j] += tq
            for a in range(8):
                lyn[a] += ls[a]
                if q > 0:
                    lk[q - 1, a] += cq[q] * ls[a]
        for d in range(3):
            mid = lmu[1, d] + lmu[2, d]
            nm0[d] += lmu[0, d] + _MID[0] * mid + _END[0] * lmu[3, d]
            nm1[d] += _MID[1] * mid + _END[1] * lmu[3, d]
            nm2[d] += _MID[2] * mid + _END[2] * lmu[3, d]
        lm0, lm1, lm2 = nm0, nm1, nm2
        ly = lyn
        if i % steps == 0 and i > 0:
            for a in range(8):
                ly[a] += seeds[j, a]
    return grad
