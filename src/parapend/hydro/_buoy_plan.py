r"""The buoy's horizon problem with the pendulum's MOTION as the unknown (``controller="plan"``
of :func:`parapend.hydro.control.buoy_mpc`).

On the horizon ``[t, t + H]`` the angle is a ``C^1`` piecewise cubic Hermite on ``K`` uniform
intervals of ``h`` (nodes ``theta_k, v_k``, node 0 the measured state), as the pendulum's
planner :mod:`parapend.control.plan`. The heave over the horizon is not an unknown: it is
Cummins' equation of the plant (:mod:`.timedomain`) driven by the excitation and the
pendulum's reaction,

    M z'' + int_-inf^t K(t - s) z'(s) ds + C z = F_exc - m l (cos theta)''   (M = mass + A_inf),

linear in its forcing. With ``g`` its impulse response from rest (``g(0) = 0``, ``g'(0) = 1 /
M``; :class:`Response`) the heave is the buoy's FREE response ``z_F`` (from the measured
``z, z'`` and the memory of the past under ``F_exc``, no pendulum: the plant's own model run
forward, :meth:`parapend.hydro.control._MotionPlanner.free_heave`) plus the convolution of
``-m l (cos theta)''`` with ``g``. Integrated by parts twice, with ``y = z + r cos(theta)``,
``r = m l / M``,

    y(t) = z_F + m l (g(t) c'(0) + g'(t) c(0)) - m l int_0^t g''(t - s) c(s) ds,
    c = cos(theta),

a lower-triangular (causal) linear map of ``cos(theta)`` over the horizon, and ``y'``, ``y''``
the same with ``g'''``, ``g''''`` (and ``y''`` the point's own ``m l (K(0) + C) / M^2
c(t)``). Without radiation (``K = 0``, the default :class:`Response`, and the frozen model
of ``radiation_model=False``: ``F_exc`` less a frozen memory force ``f``) ``g = sin(w s) /
(M w)``, ``w^2 = C / M``, and ``-m l g'' = kappa g``, ``kappa = C m l / M``. The integrals
are 4-point Gauss-Legendre rules: on every whole interval before a point, and on the part of
its own interval before it (the angle there from the Hermite, so the rule is exact to the
quadrature's order, not to a step).

The torque follows by the pendulum's inverse dynamics on that heave,

    tau = I theta'' + c theta' - m l sin(theta) (g + z''),
    z'' = y'' + r (cos(theta) theta'^2 + sin(theta) theta''),

bounded, ``|tau| <= T_max``, at ``tau = 0, 1/2, 1`` of every interval. The objective is the
harvested work plus the mechanical energy of buoy AND pendulum at the horizon's end (the
terminal value of the ``coupled`` controller, docs/buoy.md); by the energy balance of the
coupled model this is, up to the start's energy,

    J = int (f z' - c theta'^2) dt - 1/2 int int K(|t - s|) z'(t) z'(s) dt ds,
    z' = y' + r sin(theta) theta',

``f = F_exc - mu_past`` (the memory force of the speeds before now) and the double integral
the energy the plan's own motion radiates in the horizon (by the same Gauss rules, within
one interval over the cubic through its Gauss points: ``K(|t - s|)`` may have a kink on the
diagonal). Its linear part is a sum of terms each of one interval's nodes (``y'`` is linear
in the ``cos(theta)`` of the points before it); the radiated energy and the torque
constraints couple the whole horizon, so the Newton matrix is dense but small (``2 K``).

**Solver.** A primal-dual interior point with slacks (``g(x) + s = 0``, ``s > 0``; an
infeasible warm start needs no repair), the exact Hessian of the Lagrangian (objective and
constraints), an inertia correction (Cholesky of ``H + J^T S^-1 Lambda J + delta I``) and a
backtracking line search on the merit ``phi - mu sum log s + rho |g + s|_1`` (``rho`` 1.1 times the
largest multiplier before or after the step).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import LinAlgError, cho_factor, cho_solve

from ..optimal.hermite import _hermite_rows

_XG, _WG = np.polynomial.legendre.leggauss(4)
TAU_G = (_XG + 1.0) / 2.0
W_G = _WG / 2.0
TORQUE_TAU = np.array([0.0, 0.5, 1.0])
#: the barrier's first weight, relative to the objective's largest derivative
MU0 = 1e-2
STATUS = ("converged", "max_iter", "line_search", "nonfinite")


class Response:
    r"""The heave's impulse response ``g`` and its derivatives: ``M z'' + int_0^t K(t - s)
    z'(s) ds + C z = delta(t)`` from rest (``g(0) = 0``, ``g'(0) = 1 / M``).

    Without ``weights`` the undamped oscillator ``g = sin(w t) / (M w)`` (``K = 0``,
    ``w^2 = C / M``). With the plant's memory ``weights`` on its step ``h``
    (:func:`.timedomain._memory_weights`: ``K(q h) h``, halved at both ends) ``g`` is
    tabulated on the plant's steps over ``length`` seconds by the plant's own scheme (RK4,
    the memory a trapezoid over ``[0, t]``, extrapolated quadratically inside a step), ``g''``
    exactly from the equation at the steps; between them ``g`` and ``g'`` are cubic Hermites
    and ``g''`` a cubic spline, whose first and second derivatives give ``g'''`` and
    ``g''''``.
    """

    def __init__(self, mtot, cst, weights=None, h=None, length=None):
        self.mtot, self.cst = float(mtot), float(cst)
        self.w = math.sqrt(self.cst / self.mtot)
        self.k0 = 0.0
        self.table = None
        if weights is None:
            return
        from scipy.interpolate import CubicHermiteSpline, CubicSpline

        w = np.asarray(weights, dtype=float)
        nk = w.size - 1
        kq = w / h
        kq[0] *= 2.0
        kq[-1] *= 2.0  # K(q h), q = 0..nk
        self.k0 = float(kq[0])
        n = max(4, int(math.ceil(length / h)) + 2)
        mt, cs = self.mtot, self.cst
        g = np.zeros(n + 1)
        v = np.zeros(n + 1)
        mu = np.zeros(n + 1)
        v[0] = 1.0 / mt

        def memory(i):
            # trapezoid of int_0^t_i K(t_i - s) v(s) ds over the steps (v = 0 before 0)
            q = np.arange(min(i, nk) + 1)
            vals = kq[q] * v[i - q]
            return h * (float(np.sum(vals)) - 0.5 * vals[0] - 0.5 * vals[-1])

        # mu(t) ~ K(0) v(0) t near 0: its values at -h, -2h continue it for the first step
        m0, m1, m2 = 0.0, -self.k0 * v[0] * h, -2.0 * self.k0 * v[0] * h
        for i in range(n):
            d1 = 0.5 * (3 * m0 - 4 * m1 + m2)
            d2 = 0.5 * (m0 - 2 * m1 + m2)
            mh, me = m0 + 0.5 * d1 + 0.25 * d2, m0 + d1 + d2
            z, zd = g[i], v[i]
            a1 = -(m0 + cs * z) / mt
            z2, zd2 = z + 0.5 * h * zd, zd + 0.5 * h * a1
            a2 = -(mh + cs * z2) / mt
            z3, zd3 = z + 0.5 * h * zd2, zd + 0.5 * h * a2
            a3 = -(mh + cs * z3) / mt
            z4, zd4 = z + h * zd3, zd + h * a3
            a4 = -(me + cs * z4) / mt
            g[i + 1] = z + h / 6.0 * (zd + 2 * zd2 + 2 * zd3 + zd4)
            v[i + 1] = zd + h / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4)
            mu[i + 1] = memory(i + 1)
            m2, m1, m0 = m1, m0, mu[i + 1]
        t = h * np.arange(n + 1)
        a = -(mu + cs * g) / mt
        self.table = (CubicHermiteSpline(t, g, v), CubicHermiteSpline(t, v, a),
                      CubicSpline(t, a))
        self.length = t[-1]
        self._kernel = CubicSpline(h * np.arange(nk + 1), kq)
        self.memory = nk * h

    def kernel(self, s):
        """``K(s)`` (N s/m per s) at lags ``s >= 0``: a cubic spline through the plant's
        values, zero beyond its memory."""
        s = np.asarray(s, dtype=float)
        return np.where(s <= self.memory, self._kernel(np.minimum(s, self.memory)), 0.0)

    def __call__(self, s, order):
        """``g`` (``order`` 0) to its fourth derivative (4) at lags ``s >= 0`` (s)."""
        s = np.asarray(s, dtype=float)
        if self.table is None:
            w, mt = self.w, self.mtot
            ws = w * s
            return (np.sin(ws) / (mt * w), np.cos(ws) / mt, -w * np.sin(ws) / mt,
                    -w * w * np.cos(ws) / mt, w ** 3 * np.sin(ws) / mt)[order]
        if order < 2:
            return self.table[order](s)
        return self.table[2](s, order - 2)

    def point(self):
        """``-g'''(0) = (K(0) + C) / M^2``: the weight of ``cos(theta)(t)`` itself in ``y''``
        (per ``m l``)."""
        return (self.k0 + self.cst) / self.mtot ** 2


class _Targets:
    """Points ``(j, tau)`` of the horizon (interval, local coordinate) where the heave is
    needed, with the weights of the convolutions that give ``y'`` (``b_*``) and ``y''``
    (``a_*``) there: ``-m l g'''`` and ``-m l g''''`` at the lags (the module docstring)."""

    def __init__(self, j, tau, k, h, resp, ml):
        self.j = np.asarray(j, dtype=np.int64)
        self.tau = np.asarray(tau, dtype=float)
        self.t = (self.j + self.tau) * h
        self.b0, self.b1, self.b2 = _hermite_rows(self.tau, h)
        src = (np.arange(k)[:, None] + TAU_G[None, :]) * h  # (K, 4) whole intervals
        lag = self.t[:, None, None] - src[None, :, :]
        before = (np.arange(k)[None, :] < self.j[:, None])[:, :, None]
        wq = h * W_G[None, None, :]
        lag = np.where(before, lag, 0.0)
        self.a_full = np.where(before, -ml * wq * resp(lag, 4), 0.0)
        self.b_full = np.where(before, -ml * wq * resp(lag, 3), 0.0)
        self.y_full = np.where(before, -ml * wq * resp(lag, 2), 0.0)
        # the part of the point's own interval before it
        tp = self.tau[:, None] * TAU_G[None, :]
        self.part_t = (self.j[:, None] + tp) * h
        lagp = self.t[:, None] - self.part_t
        wp = self.tau[:, None] * h * W_G[None, :]
        self.a_part = -ml * wp * resp(lagp, 4)
        self.b_part = -ml * wp * resp(lagp, 3)
        self.y_part = -ml * wp * resp(lagp, 2)
        self.bp0 = _hermite_rows(tp, h)[0]  # (T, 4, 4)
        # the start's terms: g, g', g'', g''' at the points
        self.gs = [resp(self.t, q) for q in range(4)]
        nt = self.t.size
        # flat and outer-product forms for the matrix products of the derivatives
        self.af2 = self.a_full.reshape(nt, 4 * k)
        self.bf2 = self.b_full.reshape(nt, 4 * k)
        self.bpo = (self.bp0[:, :, :, None] * self.bp0[:, :, None, :]).reshape(nt, 4, 16)
        self.inc = np.zeros((k, nt))
        self.inc[self.j, np.arange(nt)] = 1.0


class CoupledPlan:
    """The horizon problem of one update (module docstring) in SI units.

    Parameters
    ----------
    k, h : int, float
        Hermite intervals and their length (s).
    p : array
        ``(M + A_inf, C, m l, I, c, g)`` (:class:`parapend.hydro.control._Plant`).
    torque_limit : float
        ``T_max`` (N m).
    sample_leads : array or None
        Lead times (s) where :meth:`torques` gives the plan's torque (the held torques'
        quadrature points).
    response : Response or None
        The heave's impulse response (default: the undamped oscillator, no radiation).
    """

    def __init__(self, k, h, p, torque_limit, sample_leads=None, response=None):
        self.k, self.h = int(k), float(h)
        self.p = np.asarray(p, dtype=float)
        mtot, cst, ml = self.p[0], self.p[1], self.p[2]
        self.resp = Response(mtot, cst) if response is None else response
        self.w = math.sqrt(cst / mtot)
        self.r = ml / mtot
        self.kap = ml * self.resp.point()  # the weight of cos(theta)(t) in y''
        self.tmax = float(torque_limit)
        kk = np.arange(k)
        jg, tg = np.repeat(kk, 4), np.tile(TAU_G, k)
        jc, tc = np.repeat(kk, 3), np.tile(TORQUE_TAU, k)
        self.ng = 4 * k
        self.nc = 3 * k
        self.tg = _Targets(np.concatenate((jg, jc)), np.concatenate((tg, tc)), k, h,
                           self.resp, ml)
        self.wgt = np.concatenate((np.tile(h * W_G, k), np.zeros(self.nc)))
        self.b0g = _hermite_rows(TAU_G, h)[0]  # (4, 4) the whole intervals' sources
        self.b0o = (self.b0g[:, :, None] * self.b0g[:, None, :]).reshape(4, 16)
        self.samples = None
        if sample_leads is not None:
            s = np.asarray(sample_leads, dtype=float)
            js = np.minimum(np.floor(s / h), k - 1).astype(np.int64)
            self.samples = _Targets(js, s / h - js, k, h, self.resp, ml)
        self.n = 2 * k
        self.x0 = np.zeros(4)
        self._work = None
        # the radiated energy over the horizon, 1/2 int int K(|t - s|) z'(t) z'(s) dt ds, by
        # the objective's Gauss rules (K smooth and even): 1/2 z'^T wrad z'
        self.wrad = np.zeros((0, 0))
        if self.resp.table is not None:
            tq = self.tg.t[:self.ng]
            wq = self.wgt[:self.ng]
            kern = self.resp.kernel(np.abs(np.subtract.outer(tq, tq)))
            wrad = wq[:, None] * kern * wq[None, :]
            # K(|t - s|) has a kink on the diagonal (K'(0) need not vanish): within one
            # interval, z' as the cubic through its Gauss points, integrated exactly
            blk = _diagonal_block(self.resp.kernel, h)
            for i in range(k):
                wrad[4 * i:4 * i + 4, 4 * i:4 * i + 4] = blk
            self.wrad = np.ascontiguousarray(wrad)

    def _radiated(self, zd):
        if self.wrad.shape[0] == 0:
            return 0.0
        z = zd[:self.ng]
        return 0.5 * float(z @ (self.wrad @ z))

    # -- the update's data -------------------------------------------------------------------
    def set_start(self, y0, fm, fobj=None, free=None):
        """The measured ``(z, z', theta, theta')`` and ``f = F - mu`` (N) as a vectorized
        callable of the lead time (s); ``fobj`` (same form, default ``fm``): the force that
        weights ``z'`` in the objective, ``int (fobj z' - c theta'^2) dt``
        (:func:`parapend.hydro.control.marginal_radiation`). ``free``: a callable of the lead
        time giving ``(z, z', z'')`` of the buoy WITHOUT the pendulum from the measured state
        (its radiation memory included) under the forecast excitation (the plant's model):
        the dynamics then take the heave from it and the :class:`Response`, and ``fm`` only
        weights the objective; without it (undamped response only) ``f = fm`` drives the
        buoy's oscillator."""
        self.x0 = np.asarray(y0, dtype=float).copy()
        self.fm = fm
        self.free = free
        if free is None and self.resp.table is not None:
            raise ValueError("free: the radiation's response needs the free heave")
        z, zd, th, om = self.x0
        self.c0, self.c1 = math.cos(th), -math.sin(th) * om
        self.yy0 = z + self.r * math.cos(th)
        self.yd0 = zd - self.r * math.sin(th) * om
        src = (np.arange(self.k)[:, None] + TAU_G[None, :]) * self.h
        self.f_full = np.asarray(fm(src), dtype=float) if free is None else None
        self._fixed = [self._constant(self.tg)]
        f_t, yc, ydc = self._fixed[0]
        f_t = f_t.copy()
        f_t[:self.ng] = np.asarray((fm if fobj is None else fobj)(self.tg.t[:self.ng]),
                                   dtype=float)
        self._fixed[0] = (f_t, yc, ydc)
        if self.samples is not None:
            self._fixed.append(self._constant(self.samples))

    def _constant(self, tg, heave=False):
        """``f`` at the points, and the parts of ``y''`` (``y`` with ``heave``) and ``y'``
        that do not depend on the motion (the free response from the start, with the
        start's angle, and the response to ``f``)."""
        f_t = np.asarray(self.fm(tg.t), dtype=float)
        ml = self.p[2]
        g0, g1, g2, g3 = tg.gs
        if self.free is not None:
            zf, zfd, zfdd = self.free(tg.t)
            yc = zf + ml * (g0 * self.c1 + g1 * self.c0)
            ydc = zfd + ml * (g1 * self.c1 + g2 * self.c0)
            ycc = zfdd + ml * (g2 * self.c1 + g3 * self.c0)
            return f_t, (yc if heave else ycc), ydc
        w = self.w
        mtot, cst = self.p[0], self.p[1]
        cw, sw = np.cos(w * tg.t), np.sin(w * tg.t)
        f_p = np.asarray(self.fm(tg.part_t), dtype=float)
        k = self.k
        src = (np.arange(k)[:, None] + TAU_G[None, :]) * self.h
        lag = tg.t[:, None, None] - src[None, :, :]
        before = (np.arange(k)[None, :] < tg.j[:, None])[:, :, None]
        wq = self.h * W_G[None, None, :]
        lagp = tg.t[:, None] - tg.part_t
        wp = tg.tau[:, None] * self.h * W_G[None, :]
        sf = np.where(before, wq * np.sin(w * lag), 0.0).reshape(tg.t.size, -1)
        cf = np.where(before, wq * np.cos(w * lag), 0.0).reshape(tg.t.size, -1)
        ff = self.f_full.ravel()
        yc = (self.yy0 * cw + self.yd0 * sw / w
              + (sf @ ff + np.sum(wp * np.sin(w * lagp) * f_p, 1)) / (mtot * w))
        ydc = (-self.yy0 * w * sw + self.yd0 * cw
               + (cf @ ff + np.sum(wp * np.cos(w * lagp) * f_p, 1)) / mtot)
        # M y'' + C y = f + kappa cos(theta): the constant part of y''
        return f_t, (yc if heave else (f_t - cst * yc) / mtot), ydc

    def full(self, x):
        return np.concatenate((self.x0[2:], np.asarray(x, dtype=float)))

    def _local(self, f):
        return np.stack([f[0:-2:2], f[1:-2:2], f[2::2], f[3::2]], axis=1)

    def _motion(self, tg, loc, yc, derivative=False):
        """Angle, speed, acceleration at the points, the angle at the sources, and ``y''``
        less its point term (or ``y'``)."""
        lt = loc[tg.j]
        th = np.sum(tg.b0 * lt, 1)
        thd = np.sum(tg.b1 * lt, 1)
        thdd = np.sum(tg.b2 * lt, 1)
        thf = loc @ self.b0g.T
        thp = np.matmul(tg.bp0, lt[:, :, None])[:, :, 0]
        cf, cp = np.cos(thf), np.cos(thp)
        af, ap = (tg.bf2, tg.b_part) if derivative else (tg.af2, tg.a_part)
        y = yc + af @ cf.ravel() + np.sum(ap * cp, 1)
        return th, thd, thdd, thf, thp, y

    # -- values ------------------------------------------------------------------------------
    def _torque(self, th, thd, thdd, ydd):
        """``I theta'' + c theta' - m l sin(theta) (g + z'')``, ``z'' = y'' - r (cos
        theta)''``, ``ydd``: ``y''`` less its point's own term ``kap cos(theta)``."""
        ml, inertia, c, g = self.p[2], self.p[3], self.p[4], self.p[5]
        r, kap = self.r, self.kap
        s, co = np.sin(th), np.cos(th)
        return ((inertia - ml * r * s * s) * thdd + c * thd
                - ml * s * (g + r * co * thd * thd) - ml * s * (ydd + kap * co))

    def objective(self, x):
        """The minimized ``-J`` (module docstring; J without the start's energy)."""
        loc = self._local(self.full(x))
        tg = self.tg
        f_t, _, ydc = self._fixed[0]
        th, thd, _, _, _, yd = self._motion(tg, loc, ydc, derivative=True)
        zd = yd + self.r * np.sin(th) * thd
        return (float(np.sum(self.wgt * (-f_t * zd + self.p[4] * thd * thd)))
                + self._radiated(zd))

    def values(self, x):
        """The minimized ``-J`` and the constraint torques (N m, ``(3K,)``) together."""
        loc = self._local(self.full(x))
        tg = self.tg
        f_t, yc, ydc = self._fixed[0]
        th, thd, thdd, thf, thp, y = self._motion(tg, loc, yc)
        yd = ydc + tg.bf2 @ np.cos(thf).ravel() + np.sum(tg.b_part * np.cos(thp), 1)
        zd = yd + self.r * np.sin(th) * thd
        phi = float(np.sum(self.wgt * (-f_t * zd + self.p[4] * thd * thd))) + self._radiated(zd)
        return phi, self._torque(th, thd, thdd, y)[self.ng:]

    def constraint_torques(self, x):
        """The torque (N m) at the constraint points, ``(K, 3)``."""
        loc = self._local(self.full(x))
        f_t, yc, _ = self._fixed[0]
        th, thd, thdd, _, _, y = self._motion(self.tg, loc, yc)
        return self._torque(th, thd, thdd, y)[self.ng:]

    def torques(self, x):
        """The plan's torque (N m) at ``sample_leads``."""
        loc = self._local(self.full(x))
        f_t, yc, _ = self._fixed[1]
        th, thd, thdd, _, _, y = self._motion(self.samples, loc, yc)
        return self._torque(th, thd, thdd, y)

    def heave(self, x, leads):
        """``z`` (m) at lead times (s) of the plan (for tests and diagnostics)."""
        s = np.asarray(leads, dtype=float)
        j = np.minimum(np.floor(s / self.h), self.k - 1).astype(np.int64)
        tg = _Targets(j, s / self.h - j, self.k, self.h, self.resp, self.p[2])
        _, yc, _ = self._constant(tg, heave=True)
        loc = self._local(self.full(x))
        th = np.sum(tg.b0 * loc[tg.j], 1)
        thf = loc @ self.b0g.T
        thp = np.matmul(tg.bp0, loc[tg.j][:, :, None])[:, :, 0]
        y = (yc + tg.y_full.reshape(s.size, -1) @ np.cos(thf).ravel()
             + np.sum(tg.y_part * np.cos(thp), 1))
        return y - self.r * np.cos(th)

    # -- derivatives -------------------------------------------------------------------------
    def _scatter_hess(self, hloc, nfull):
        """Dense matrix from per-interval 4x4 blocks ``(K, 4, 4)``."""
        hm = np.zeros((nfull, nfull))
        for i in range(self.k):
            hm[2 * i:2 * i + 4, 2 * i:2 * i + 4] += hloc[i]
        return hm

    def _scatter_rows(self, rows, j, nfull):
        """Dense ``(T, nfull)`` from per-point rows ``(T, 4)`` at intervals ``j``."""
        out = np.zeros((rows.shape[0], nfull))
        idx = np.arange(rows.shape[0])
        for a in range(4):
            out[idx, 2 * j + a] += rows[:, a]
        return out

    def derivatives(self, x, nu=None):
        """``phi`` (minimized), its gradient and Hessian, the constraint torques, their
        Jacobian (``(3K, 2K)``), and with ``nu`` (per torque point) the Hessian of
        ``phi + nu . tau`` (all over the free variables)."""
        k = self.k
        nfull = 2 * k + 2
        loc = self._local(self.full(x))
        tg = self.tg
        f_t, yc, ydc = self._fixed[0]
        ml, inertia, c, g = self.p[2], self.p[3], self.p[4], self.p[5]
        r, kap = self.r, self.kap
        th, thd, thdd, thf, thp, y = self._motion(tg, loc, yc)
        yd = ydc + tg.bf2 @ np.cos(thf).ravel() + np.sum(tg.b_part * np.cos(thp), 1)
        s, co = np.sin(th), np.cos(th)
        sf, cf, sp, cp = np.sin(thf), np.cos(thf), np.sin(thp), np.cos(thp)
        wgt = self.wgt
        zd = yd + r * s * thd
        phi = float(np.sum(wgt * (-f_t * zd + c * thd * thd))) + self._radiated(zd)
        # objective: the sources' cos(theta) weighted by the adjoint of y' (and z')
        lam_t = -wgt * f_t
        quad = self.wrad.shape[0] > 0
        if quad:
            lam_t = lam_t.copy()
            lam_t[:self.ng] += self.wrad @ zd[:self.ng]
        lam_f = (lam_t @ tg.bf2).reshape(k, 4)
        lam_p = lam_t[:, None] * tg.b_part
        gloc = np.zeros((k, 4))
        hloc = np.zeros((k, 4, 4))
        gloc += (-lam_f * sf) @ self.b0g
        hloc += ((-lam_f * cf) @ self.b0o).reshape(k, 4, 4)
        gp = np.matmul((-lam_p * sp)[:, None, :], tg.bp0)[:, 0]
        hp = np.matmul((-lam_p * cp)[:, None, :], tg.bpo)[:, 0].reshape(-1, 4, 4)
        # the points' own terms
        d_th = lam_t * r * co * thd
        d_thd = lam_t * r * s + 2.0 * c * wgt * thd
        gp += d_th[:, None] * tg.b0 + d_thd[:, None] * tg.b1
        h_tt = -lam_t * r * s * thd
        h_td = lam_t * r * co
        h_dd = 2.0 * c * wgt
        b0, b1, b2 = tg.b0, tg.b1, tg.b2
        hp += (h_tt[:, None, None] * b0[:, :, None] * b0[:, None, :]
               + h_td[:, None, None] * (b0[:, :, None] * b1[:, None, :]
                                        + b1[:, :, None] * b0[:, None, :])
               + h_dd[:, None, None] * b1[:, :, None] * b1[:, None, :])
        # the torque at the constraint points
        cs = slice(self.ng, None)
        sc, cc = s[cs], co[cs]
        thc, thdc, thddc, ycc = th[cs], thd[cs], thdd[cs], y[cs]
        tau = self._torque(thc, thdc, thddc, ycc)
        c2, s2 = np.cos(2 * thc), np.sin(2 * thc)
        t_th = (-ml * r * s2 * thddc - ml * cc * g - ml * r * c2 * thdc * thdc
                - ml * cc * ycc - ml * kap * c2)
        t_thd = c - ml * r * s2 * thdc
        t_thdd = inertia - ml * r * sc * sc
        jc = tg.j[cs]
        b0c, b1c, b2c = b0[cs], b1[cs], b2[cs]
        jl = t_th[:, None] * b0c + t_thd[:, None] * b1c + t_thdd[:, None] * b2c
        jac = self._scatter_rows(jl, jc, nfull)
        # the heave's part: -m l sin(theta) dy'', dy'' = sum A (-sin theta_s) row_s
        af, ap = tg.a_full[cs], tg.a_part[cs]
        mf = (af * (-sf)[None]) @ self.b0g
        dy = np.zeros((self.nc, nfull))
        for a in range(4):
            dy[:, a:a + 2 * k:2] += mf[:, :, a]
        mp = np.matmul((ap * (-sp[cs]))[:, None, :], tg.bp0[cs])[:, 0]
        dy += self._scatter_rows(mp, jc, nfull)
        jac += (-ml * sc)[:, None] * dy
        gz = None
        if quad:
            # the gradient of z' at the objective's points (dense rows)
            og = slice(0, self.ng)
            mz = (tg.b_full[og] * (-sf)[None]) @ self.b0g
            gz = np.zeros((self.ng, nfull))
            for a in range(4):
                gz[:, a:a + 2 * k:2] += mz[:, :, a]
            own = np.matmul((tg.b_part[og] * (-sp[og]))[:, None, :], tg.bp0[og])[:, 0]
            own += (r * co * thd)[og, None] * b0[og] + (r * s)[og, None] * b1[og]
            gz += self._scatter_rows(own, tg.j[og], nfull)
        gfull = np.zeros(nfull)
        hloc += (tg.inc @ hp.reshape(-1, 16)).reshape(k, 4, 4)
        gloc += tg.inc @ gp
        for a in range(4):
            gfull[a:a + 2 * k:2] += gloc[:, a]
        hess = None
        if nu is not None:
            nu = np.asarray(nu, dtype=float)
            p_tt = (-2.0 * ml * r * c2 * thddc + ml * sc * g + 2.0 * ml * r * s2 * thdc * thdc
                    + ml * sc * ycc + 2.0 * ml * kap * s2)
            p_td = -2.0 * ml * r * c2 * thdc
            p_tdd = -ml * r * s2
            p_dd = -ml * r * s2
            hc = nu[:, None, None] * (
                p_tt[:, None, None] * b0c[:, :, None] * b0c[:, None, :]
                + p_td[:, None, None] * (b0c[:, :, None] * b1c[:, None, :]
                                         + b1c[:, :, None] * b0c[:, None, :])
                + p_tdd[:, None, None] * (b0c[:, :, None] * b2c[:, None, :]
                                          + b2c[:, :, None] * b0c[:, None, :])
                + p_dd[:, None, None] * b1c[:, :, None] * b1c[:, None, :])
            inc_c = tg.inc[:, cs]
            hloc += (inc_c @ hc.reshape(-1, 16)).reshape(k, 4, 4)
            # the second derivative of y'': sources weighted by mu_s = sum nu (-m l sin) A
            wv = -ml * nu * sc
            mu_f = (wv @ tg.af2[cs]).reshape(k, 4)
            hloc += ((-mu_f * cf) @ self.b0o).reshape(k, 4, 4)
            mu_p = wv[:, None] * ap
            hpp = np.matmul((-mu_p * cp[cs])[:, None, :], tg.bpo[cs])[:, 0]
            hloc += (inc_c @ hpp).reshape(k, 4, 4)
            hess = self._scatter_hess(hloc, nfull)
            # the cross terms -nu m l cos(theta) (row0 dy^T + dy row0^T)
            e0 = self._scatter_rows(b0c, jc, nfull)
            cross = e0.T @ ((-ml * nu * cc)[:, None] * dy)
            hess += cross + cross.T
        else:
            hess = self._scatter_hess(hloc, nfull)
        if quad:
            hess += gz.T @ (self.wrad @ gz)
        return phi, gfull[2:], hess[2:, 2:], tau, jac[:, 2:]

    def compiled(self, x, nu=None, order=2):
        """:meth:`derivatives` (``order`` 1 without ``nu``, 2 with it) or :meth:`values`
        (``order`` 0) by the compiled kernel (:mod:`._buoy_plan_kernel`)."""
        from ._buoy_plan_kernel import evaluate

        k, tg = self.k, self.tg
        nfull = 2 * k + 2
        f_t, yc, ydc = self._fixed[0]
        if self._work is None:
            self._work = (np.empty(nfull), np.empty((nfull, nfull)), np.empty(self.nc),
                          np.empty((self.nc, nfull)))
        grad, hess, tau, jac = self._work
        nu = np.zeros(self.nc) if nu is None else np.asarray(nu, dtype=float)
        phi = evaluate(self.full(x), tg.j, tg.b0, tg.b1, tg.b2, tg.a_full, tg.b_full,
                       tg.a_part, tg.b_part, tg.bp0, self.b0g, self.wgt, f_t, yc, ydc,
                       self.ng, self.p, self.r, self.kap, self.wrad, nu, order, grad, hess,
                       tau, jac)
        if order == 0:
            return phi, tau.copy()
        return phi, grad[2:].copy(), hess[2:, 2:].copy(), tau.copy(), jac[:, 2:].copy()

    # -- the solver --------------------------------------------------------------------------
    def solve(self, x, *, max_iter=100, tol=1e-8):
        """The interior point (module docstring) from ``x`` (need not be feasible), compiled
        (:func:`._buoy_plan_kernel.solve`). Returns ``(x, status, iterations)``."""
        from ._buoy_plan_kernel import solve

        tg = self.tg
        f_t, yc, ydc = self._fixed[0]
        xs, st, it = solve(np.ascontiguousarray(x, dtype=float), self.x0[2:].copy(), tg.j,
                           tg.b0, tg.b1, tg.b2, tg.a_full, tg.b_full, tg.a_part, tg.b_part,
                           tg.bp0, self.b0g, self.wgt, f_t, yc, ydc, self.ng, self.p, self.r,
                           self.kap, self.wrad, self.tmax, int(max_iter), float(tol), MU0)
        return xs, STATUS[st], int(it)

    def solve_python(self, x, *, max_iter=100, tol=1e-8):
        """:meth:`solve` with the loop in Python (the reference of the compiled one)."""
        from ._buoy_plan_kernel import MAX_CORRECTIONS

        x = np.asarray(x, dtype=float).copy()
        tm = self.tmax
        nc = self.nc
        phi, gr, _, tau, jac = self.compiled(x, None, 1)
        gv = np.concatenate((tau / tm - 1.0, -tau / tm - 1.0))
        scale = max(1.0, float(np.max(np.abs(gr))))
        mu = MU0 * scale
        s = np.maximum(-gv, 1e-2)
        lam = mu / s
        rho = 0.0
        status = 1
        it = 0
        delta_last = 0.0
        while it < max_iter:
            it += 1
            nu = (lam[:nc] - lam[nc:]) / tm
            phi, gr, hess, tau, jac = self.compiled(x, nu)
            if not (np.isfinite(phi) and np.all(np.isfinite(gr))):
                status = 3
                break
            jg = np.concatenate((jac, -jac)) / tm
            gv = np.concatenate((tau / tm - 1.0, -tau / tm - 1.0))
            rd = gr + jg.T @ lam
            rp = gv + s
            comp = float(s @ lam) / s.size
            if (np.max(np.abs(rd)) < tol * scale and np.max(np.abs(rp)) < 1e-7
                    and comp < tol * scale):
                status = 0
                break
            # the barrier's weight falls once its problem is solved to about its size
            err = max(np.max(np.abs(rd)) / scale, np.max(np.abs(rp)),
                      np.max(np.abs(s * lam - mu)) / scale)
            if err <= 10.0 * mu / scale:
                mu = max(min(0.2 * mu, mu ** 1.5 / scale ** 0.5), 0.1 * tol * scale)
            sig = lam / s
            kmat = hess + jg.T @ (sig[:, None] * jg)
            rhs = -(gr + jg.T @ (mu / s + sig * rp))
            delta = 0.0
            dmin = 1e-8 * max(1.0, float(np.max(np.abs(np.diag(hess)))))
            fac = None
            for _ in range(MAX_CORRECTIONS):
                try:
                    fac = cho_factor(kmat + delta * np.eye(self.n), check_finite=False)
                    break
                except LinAlgError:
                    delta = max(dmin, delta_last / 3.0, 8.0 * delta)
            if fac is None or not np.all(np.isfinite(fac[0])):
                status = 3  # no shift makes it definite (a NaN in the Hessian)
                break
            delta_last = delta if delta else delta_last
            dx = cho_solve(fac, rhs, check_finite=False)
            ds = -rp - jg @ dx
            dl = mu / s - lam - sig * ds
            # fraction to the boundary
            ap = _max_step(s, ds, 0.995)
            ad = _max_step(lam, dl, 0.995)
            # the exact penalty's weight from the multipliers now and after the step (not
            # held at its largest: the kernel's comment)
            rho = 1.1 * max(float(np.max(np.abs(lam))),
                            float(np.max(np.abs(lam + min(ad, 1.0) * dl))))
            m0 = phi - mu * float(np.sum(np.log(s))) + rho * float(np.sum(np.abs(rp)))
            dm = (gr @ dx - mu * float(np.sum(ds / s)) - rho * float(np.sum(np.abs(rp))))
            a = ap
            ok = False
            for _ in range(30):
                xt = x + a * dx
                st = s + a * ds
                ft, tt = self.compiled(xt, order=0)
                gt = np.concatenate((tt / tm - 1.0, -tt / tm - 1.0))
                mt = (ft - mu * float(np.sum(np.log(st)))
                      + rho * float(np.sum(np.abs(gt + st))))
                if np.isfinite(mt) and mt <= m0 + 1e-4 * a * min(dm, 0.0):
                    ok = True
                    break
                a *= 0.5
            if not ok:
                if np.max(np.abs(rp)) < 1e-6 and comp < 10 * tol * scale:
                    status = 0
                else:
                    status = 2
                break
            x = xt
            s = st
            lam = lam + min(ad, 1.0) * dl
        return x, STATUS[status], it


def _diagonal_block(kernel, h, n=16):
    """``int int K(|t - s|) L_a(t) L_b(s) dt ds`` over one interval of ``h`` (``L_a`` the
    Lagrange cubics through its Gauss points): twice the triangle ``s < t``, where
    ``K(t - s)`` is smooth, by ``n``-point Gauss rules in ``t`` and in ``s`` on ``[0, t]``."""
    x, w = np.polynomial.legendre.leggauss(n)
    u, wu = (x + 1.0) / 2.0, w / 2.0

    def lag(v):
        out = np.ones((v.size, 4))
        for a in range(4):
            for b in range(4):
                if a != b:
                    out[:, a] *= (v - TAU_G[b]) / (TAU_G[a] - TAU_G[b])
        return out
    lu = lag(u)  # (n, 4)
    tri = np.zeros((4, 4))
    for i in range(n):
        v = u[i] * u  # inner points on [0, u_i]
        kv = kernel(h * (u[i] - v))
        inner = (u[i] * wu * kv) @ lag(v)  # (4,)
        tri += wu[i] * np.outer(lu[i], inner)
    return h * h * (tri + tri.T)


def _max_step(v, dv, frac):
    neg = dv < 0
    if not np.any(neg):
        return 1.0
    return float(min(1.0, frac * np.min(-v[neg] / dv[neg])))
