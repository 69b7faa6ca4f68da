r"""Power take-off with a generator efficiency: Hermite-Simpson collocation and a full-space
primal-dual interior point on a banded KKT system.

**Discrete problem** (the one :mod:`tests.casadi_pto` gives IPOPT). ``K`` uniform intervals
of the forcing period ``T_p = 2 pi / omega``, step ``h = T_p / K``. Unknowns at the nodes
``t_j = j h``: ``theta_j``, ``v_j`` and the torque ``u_j``; the torque is piecewise linear,
periodic, and the motion periodic up to ``W`` turns (``theta_K = theta_0 + 2 pi W``,
``v_K = v_0``). The state equations are Eq. 14, ``theta' = v``,
``v' = f = -gamma v + (1 + q(t)) sin(theta) + u``; Hermite-Simpson collocation in the
separated form, the midpoint states given by the nodes of the interval::

    theta_m = (theta_a + theta_b) / 2 + h/8 (v_a - v_b)
    v_m     = (v_a + v_b) / 2 + h/8 (f_a - f_b),       u_m = (u_a + u_b) / 2
    theta_b - theta_a - h/6 (v_a + 4 v_m + v_b) = 0
    v_b - v_a - h/6 (f_a + 4 f_m + f_b) = 0

(2 equations per interval). The mechanical power at the ``2K`` points (nodes and
midpoints) is ``p = -u v``; its mean (``P``, Eq. 15) is Simpson's rule (weights 1/3K at
nodes, 2/3K at midpoints), as is the copper loss ``r <u^2>`` (exact for a piecewise-linear
``u``). The efficiency is exact, through two slacks per point: ``p+ - p- = p``, ``p+, p- >= 0``,
objective ``eta_g p+ - p- / eta_m`` (maximized; ``eta_g <= 1/eta_m``, so at the optimum one
of the two vanishes). Optional bounds ``|u_j| <= T_max`` (at the nodes: the torque is
linear between them, so this is ``|u(t)| <= T_max`` everywhere).

**Solver.** A primal-dual interior point in the manner of IPOPT (Waechter & Biegler 2006):
log barrier on the bounds, the Fiacco-McCormick rule ``mu <- max(mu_min, min(mu/5,
mu^1.5))`` once the barrier problem is solved to ``10 mu``, fraction to the boundary 0.995,
a filter line search (without restoration phase: a filter that blocks the whole step is
reset), least-squares multipliers at the start. Per point, the slacks, their bound
multipliers and the multiplier of ``p+ - p- = p`` are eliminated in closed form (a rank-one
term ``Sigma+ Sigma- / (Sigma+ + Sigma-) grad p grad p^T``), the torque-bound multipliers
likewise (diagonal). What remains is the symmetric indefinite KKT system in
``(theta_j, v_j, u_j)`` and the two collocation multipliers per interval; ordered by node
as ``0, K-1, 1, K-2, ...`` (the periodic wrap becomes local) it is banded with half
bandwidth 14. It is factored as a banded ``L D L^T`` without pivoting: by Sylvester's law
the signs of ``D`` give its inertia, which must show exactly ``2K`` negative eigenvalues
(the reduced Hessian positive definite; else ``delta I`` is added to the primal block,
IPOPT's inertia correction, and the factorization repeated). The step comes from the same
factors with one step of iterative refinement (LAPACK's banded LU with partial pivoting,
``dgbsv``, when the residual stays above 1e-10). The inertia-free curvature test of Chiang
& Zavala (2016) was tried first: it let the iterates converge to saddle points.

Assembly, step recovery and merit are compiled with numba.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba as nb
import numpy as np
from scipy.linalg.lapack import dgbsv

from .._jit import announce_compiles
from .hermite import _fold, locate, q_on_intervals  # _fold: node order 0, K-1, 1, K-2, ...

announce_compiles()  # log a first-use compile (parapend._jit)

__all__ = ["CollocationMotion", "CollocationSolution", "solve_collocation"]

_KL = 14  # half bandwidth of the folded KKT matrix
_NB = 5  # unknowns per node block: theta, v, u, and the two multipliers of its interval
_FRACTION = 0.995


# -- compiled kernels ---------------------------------------------------------------------------


@nb.njit(cache=True)
def _interval(j, k, th, v, u, q1n, q1m, h, gamma, wrap, g):
    """Midpoint state, defects and their gradients for interval ``j``.

    ``g`` (9, 6) receives the gradients (local order ``theta_a, v_a, u_a, theta_b, v_b,
    u_b``) of: 0 theta_m, 1 v_m, 2 u_m, 3 f_m, 4 c1, 5 c2, 6 p_m, 7 f_a, 8 f_b. Returns
    ``(c1, c2, v_m, u_m, p_m, hva, hvb, qm_sm, sa_q, sb_q)`` with ``hva, hvb`` the two
    nonzero Hessian entries of ``v_m`` ((0,0) and (3,3)), ``qm_sm = q_m sin theta_m``,
    ``sa_q = q_a sin theta_a`` and ``sb_q``."""
    jb = j + 1 if j + 1 < k else 0
    tha = th[j]
    thb = th[jb] + (wrap if jb == 0 else 0.0)
    va, vb, ua, ub = v[j], v[jb], u[j], u[jb]
    qa, qb, qm = q1n[j], q1n[jb], q1m[j]
    sa, ca = math.sin(tha), math.cos(tha)
    sb, cb = math.sin(thb), math.cos(thb)
    fa = -gamma * va + qa * sa + ua
    fb = -gamma * vb + qb * sb + ub
    thm = 0.5 * (tha + thb) + h / 8 * (va - vb)
    vm = 0.5 * (va + vb) + h / 8 * (fa - fb)
    um = 0.5 * (ua + ub)
    sm, cm = math.sin(thm), math.cos(thm)
    fm = -gamma * vm + qm * sm + um
    for i in range(9):
        for c in range(6):
            g[i, c] = 0.0
    # f_a, f_b
    g[7, 0] = qa * ca
    g[7, 1] = -gamma
    g[7, 2] = 1.0
    g[8, 3] = qb * cb
    g[8, 4] = -gamma
    g[8, 5] = 1.0
    g[0, 0] = 0.5
    g[0, 1] = h / 8
    g[0, 3] = 0.5
    g[0, 4] = -h / 8
    g[2, 2] = 0.5
    g[2, 5] = 0.5
    for c in range(6):
        g[1, c] = h / 8 * (g[7, c] - g[8, c])
    g[1, 1] += 0.5
    g[1, 4] += 0.5
    for c in range(6):
        g[3, c] = -gamma * g[1, c] + qm * cm * g[0, c] + g[2, c]
        g[4, c] = -4 * h / 6 * g[1, c]
        g[5, c] = -h / 6 * (g[7, c] + 4 * g[3, c] + g[8, c])
        g[6, c] = -(vm * g[2, c] + um * g[1, c])
    g[4, 0] -= 1.0
    g[4, 1] -= h / 6
    g[4, 3] += 1.0
    g[4, 4] -= h / 6
    g[5, 1] -= 1.0
    g[5, 4] += 1.0
    c1 = thb - tha - h / 6 * (va + 4 * vm + vb)
    c2 = vb - va - h / 6 * (fa + 4 * fm + fb)
    hva = -h / 8 * qa * sa
    hvb = h / 8 * qb * sb
    return c1, c2, vm, um, -um * vm, hva, hvb, qm * sm, qa * sa, qb * sb


@nb.njit(cache=True)
def _put(ab, row, col, val):
    # general band storage of dgbsv: A[i, j] at ab[2 KL + i - j, j]
    ab[2 * _KL + row - col, col] += val


@nb.njit(cache=True)
def _slack_point(i, w, p, a, b, xi, za, zb, mu, eg, em, slack, dpc, prim_inf, dual_inf, comp):
    """The slacks ``p+ - p- = p`` of point ``i`` (weight ``w``, power ``p``) eliminated:
    ``(lam, coef, rank, prim_inf, dual_inf, comp)`` with the multiplier ``lam`` of ``p`` in
    the Lagrangian, ``coef`` (also into ``dpc[i]``) and ``rank`` of the rank-one term, and
    the three errors updated; without slacks (efficiency 1 both ways) ``lam = w eta_g``."""
    if not slack:
        return w * eg, 0.0, 0.0, prim_inf, dual_inf, comp
    sa_ = za[i] / a[i]
    sb_ = zb[i] / b[i]
    ra = -w * eg + xi[i] - mu / a[i]
    rb = w / em - xi[i] - mu / b[i]
    rxi = a[i] - b[i] - p
    dd = 1.0 / sa_ + 1.0 / sb_
    coef = (rxi - ra / sa_ + rb / sb_) / dd
    dpc[i] = coef
    prim_inf = max(prim_inf, abs(rxi))
    dual_inf = max(dual_inf, abs(-w * eg + xi[i] - za[i]), abs(w / em - xi[i] - zb[i]))
    comp = max(comp, abs(a[i] * za[i] - mu), abs(b[i] * zb[i] - mu))
    return xi[i], coef, 1.0 / dd, prim_inf, dual_inf, comp


@nb.njit(cache=True)
def _kkt(th, v, u, a, b, xi, za, zb, y, al, be, q1n, q1m, h, gamma, wrap, pos, mu, eg, em,
         r, tmax, slack, ab, rhs, dpc, gp):
    """Assemble the condensed KKT matrix (band storage, without the regularization) and its
    right-hand side; ``dpc`` (2K,) receives ``coef`` of the slack elimination (the part of
    ``dxi`` independent of ``dz``), ``gp`` (2K, 6) the local gradients of ``p`` (node
    points: columns 0-2). Returns ``(dual infeasibility, primal infeasibility,
    complementarity error)`` at this ``mu`` (max norms)."""
    k = th.size
    ab[:, :] = 0.0
    rhs[:] = 0.0
    g = np.zeros((9, 6))
    hl = np.zeros((6, 6))
    idx = np.zeros(6, dtype=np.int64)
    rz = np.zeros(3 * k)  # gradient of the Lagrangian (true duals) for the error
    dual_inf = 0.0
    prim_inf = 0.0
    comp = 0.0
    limited = tmax > 0.0
    for j in range(k):
        jb = j + 1 if j + 1 < k else 0
        base_a = _NB * pos[j]
        base_b = _NB * pos[jb]
        for c in range(3):
            idx[c] = base_a + c
            idx[3 + c] = base_b + c
        c1, c2, vm, um, pm, hva, hvb, qmsm, saq, sbq = _interval(
            j, k, th, v, u, q1n, q1m, h, gamma, wrap, g)
        prim_inf = max(prim_inf, abs(c1), abs(c2))
        y1 = y[2 * j]
        y2 = y[2 * j + 1]
        # midpoint point i = 2j + 1, weight 2
        im = 2 * j + 1
        w = 2.0
        lam, coef, rank, prim_inf, dual_inf, comp = _slack_point(
            im, w, pm, a, b, xi, za, zb, mu, eg, em, slack, dpc, prim_inf, dual_inf, comp)
        for c in range(6):
            gp[im, c] = g[6, c]
        # Hessian of the Lagrangian, local 6x6: y1 Hc1 + y2 Hc2 - lam Hpm + rank gp gp^T
        # + 2 r w gum gum^T
        for c in range(6):
            for d in range(6):
                hl[c, d] = (rank * g[6, c] * g[6, d] + 2 * r * w * g[2, c] * g[2, d]
                            + lam * (g[2, c] * g[1, d] + g[1, c] * g[2, d])
                            + y2 * (-h / 6) * 4 * (-qmsm) * g[0, c] * g[0, d])
        # diagonal Hessians: Hvm (0,0) = hva, (3,3) = hvb; Hfa (0,0) = -saq; Hfb (3,3) = -sbq
        # Hfm = -gamma Hvm - qm sm g_thm g_thm^T (the last term is above)
        # Hc1 = -4h/6 Hvm; Hc2 = -h/6 (Hfa + 4 Hfm + Hfb); Hpm = ... - um Hvm
        hl[0, 0] += (y1 * (-4 * h / 6) * hva + y2 * (-h / 6) * (-saq - 4 * gamma * hva)
                     + lam * um * hva)
        hl[3, 3] += (y1 * (-4 * h / 6) * hvb + y2 * (-h / 6) * (-sbq - 4 * gamma * hvb)
                     + lam * um * hvb)
        for c in range(6):
            for d in range(c + 1):
                _put(ab, idx[c], idx[d], hl[c, d])
                if d != c:
                    _put(ab, idx[d], idx[c], hl[c, d])
        # Jacobian rows of the defects: multipliers at base_a + 3, + 4
        r1 = base_a + 3
        r2 = base_a + 4
        for c in range(6):
            _put(ab, r1, idx[c], g[4, c])
            _put(ab, idx[c], r1, g[4, c])
            _put(ab, r2, idx[c], g[5, c])
            _put(ab, idx[c], r2, g[5, c])
        rhs[r1] = -c1
        rhs[r2] = -c2
        # gradient of the Lagrangian (rhs = -grad + rank-one correction)
        for c in range(6):
            gr = y1 * g[4, c] + y2 * g[5, c] - lam * g[6, c] + 2 * r * w * um * g[2, c]
            rhs[idx[c]] += -gr + coef * g[6, c]
            jj = j if c < 3 else jb
            rz[3 * jj + c % 3] += gr
    # node points i = 2j, weight 1
    for j in range(k):
        base = _NB * pos[j]
        i = 2 * j
        w = 1.0
        pn = -u[j] * v[j]
        gp[i, 0] = 0.0
        gp[i, 1] = -u[j]
        gp[i, 2] = -v[j]
        lam, coef, rank, prim_inf, dual_inf, comp = _slack_point(
            i, w, pn, a, b, xi, za, zb, mu, eg, em, slack, dpc, prim_inf, dual_inf, comp)
        # Hessian: -lam Hpn (Hpn[1,2] = -1) + rank gp gp^T + 2 r w e_u e_u^T + Sigma_u
        hvv = rank * u[j] * u[j]
        huu = rank * v[j] * v[j] + 2 * r * w
        hvu = rank * u[j] * v[j] + lam
        gu = 2 * r * w * u[j]
        if limited:
            gup = tmax - u[j]
            gdn = tmax + u[j]
            huu += al[j] / gup + be[j] / gdn
            rhs[base + 2] += -(mu / gup - mu / gdn)
            rz[3 * j + 2] += al[j] - be[j]
            comp = max(comp, abs(al[j] * gup - mu), abs(be[j] * gdn - mu))
        _put(ab, base + 1, base + 1, hvv)
        _put(ab, base + 2, base + 2, huu)
        _put(ab, base + 1, base + 2, hvu)
        _put(ab, base + 2, base + 1, hvu)
        rhs[base + 1] += -(lam * u[j]) + coef * (-u[j])
        rhs[base + 2] += -(gu + lam * v[j]) + coef * (-v[j])
        rz[3 * j + 1] += lam * u[j]
        rz[3 * j + 2] += gu + lam * v[j]
    for i in range(3 * k):
        dual_inf = max(dual_inf, abs(rz[i]))
    return dual_inf, prim_inf, comp


@nb.njit(cache=True)
def _ldl(band, kl):
    """Banded ``L D L^T`` without pivoting of the symmetric matrix with lower band
    ``band[d, j] = A[j + d, j]``, in place (``band[0]`` becomes ``D``, ``band[d, j]`` the
    multiplier ``L[j + d, j]``). Returns the number of negative pivots, which by Sylvester's
    law is the number of negative eigenvalues, and whether a pivot was zero (the count and
    the factors are then unusable)."""
    n = band.shape[1]
    a = band
    neg = 0
    for j in range(n):
        d = a[0, j]
        if abs(d) <= 1e-200 or not math.isfinite(d):
            return neg, True
        if d < 0:
            neg += 1
        top = min(kl, n - 1 - j)
        for i in range(1, top + 1):
            lij = a[i, j] / d
            if lij != 0.0:
                for c in range(i, top + 1):
                    # A[j + c, j + i] -= A[j + c, j] A[j + i, j] / d
                    a[c - i, j + i] -= a[c, j] * lij
        for i in range(1, top + 1):
            a[i, j] /= d
    return neg, False


def _inertia(band, kl):
    """Number of negative eigenvalues of a symmetric banded matrix (:func:`_ldl` on a
    copy), and whether the factorization broke down."""
    return _ldl(band.copy(), kl)


@nb.njit(cache=True)
def _ldl_solve(fac, kl, ab, rhs):
    """Solve with the factors of :func:`_ldl` and one step of iterative refinement on the
    matrix ``ab`` (general band storage, half bandwidth ``kl``). Returns the solution and
    the relative residual after refinement (max norm)."""
    n = rhs.size
    x = _ldl_subst(fac, kl, rhs)
    r = rhs - _band_mult(ab, kl, x)
    x += _ldl_subst(fac, kl, r)
    r = rhs - _band_mult(ab, kl, x)
    big = 0.0
    res = 0.0
    for i in range(n):
        big = max(big, abs(rhs[i]))
        res = max(res, abs(r[i]))
    return x, res / max(big, 1e-300)


@nb.njit(cache=True)
def _ldl_subst(fac, kl, b):
    n = b.size
    x = b.copy()
    for j in range(n):  # L y = b
        xj = x[j]
        for i in range(1, min(kl, n - 1 - j) + 1):
            x[j + i] -= fac[i, j] * xj
    for j in range(n):
        x[j] /= fac[0, j]
    for j in range(n - 1, -1, -1):  # L^T x = y
        acc = x[j]
        for i in range(1, min(kl, n - 1 - j) + 1):
            acc -= fac[i, j] * x[j + i]
        x[j] = acc
    return x


@nb.njit(cache=True)
def _band_mult(ab, kl, x):
    """``A x`` for ``A`` in LAPACK's general band storage (``A[i, j]`` at
    ``ab[2 kl + i - j, j]``)."""
    n = x.size
    y = np.zeros(n)
    for j in range(n):
        xj = x[j]
        for i in range(max(0, j - kl), min(n, j + kl + 1)):
            y[i] += ab[2 * kl + i - j, j] * xj
    return y


@nb.njit(cache=True)
def _recover(dz, gp, dpc, a, b, xi, za, zb, mu, eg, em):
    """The eliminated per-point unknowns along the step ``dz`` (K, 3): ``dxi`` (multiplier
    of ``p+ - p- = p``), ``dp+``, ``dp-`` and their bound multipliers' steps."""
    k = dz.shape[0]
    n2 = 2 * k
    dxi = np.empty(n2)
    da = np.empty(n2)
    db = np.empty(n2)
    dza = np.empty(n2)
    dzb = np.empty(n2)
    for i in range(n2):
        j = i // 2
        if i % 2 == 0:  # node: grad p = (0, -u, -v)
            gdz = gp[i, 1] * dz[j, 1] + gp[i, 2] * dz[j, 2]
            w = 1.0
        else:  # midpoint: the interval's two nodes
            jb = j + 1 if j + 1 < k else 0
            gdz = 0.0
            for c in range(3):
                gdz += gp[i, c] * dz[j, c] + gp[i, 3 + c] * dz[jb, c]
            w = 2.0
        sa = za[i] / a[i]
        sb = zb[i] / b[i]
        dxi[i] = dpc[i] - gdz / (1.0 / sa + 1.0 / sb)
        ra = -w * eg + xi[i] - mu / a[i]
        rb = w / em - xi[i] - mu / b[i]
        da[i] = (-ra - dxi[i]) / sa
        db[i] = (-rb + dxi[i]) / sb
        dza[i] = mu / a[i] - za[i] - sa * da[i]
        dzb[i] = mu / b[i] - zb[i] - sb * db[i]
    return dxi, da, db, dza, dzb


@nb.njit(cache=True)
def _to_boundary(x, dx, cur, frac):
    """Largest step ``<= cur`` with ``x + alpha dx >= (1 - frac) x``."""
    for i in range(x.size):
        if dx[i] < 0:
            cur = min(cur, -frac * x[i] / dx[i])
    return cur


@nb.njit(cache=True)
def _merit(th, v, u, a, b, q1n, q1m, h, gamma, wrap, mu, eg, em, r, tmax, slack):
    """``(barrier objective, infeasibility sum |c| + |e|)`` (scaled objective ``3K`` times
    the negated mean electrical power); ``inf`` barrier outside the bounds."""
    k = th.size
    g = np.zeros((9, 6))
    obj = 0.0
    bar = 0.0
    inf = 0.0
    for j in range(k):
        c1, c2, vm, um, pm, hva, hvb, qmsm, saq, sbq = _interval(
            j, k, th, v, u, q1n, q1m, h, gamma, wrap, g)
        inf += abs(c1) + abs(c2)
        for node in range(2):
            if node == 0:
                i, w, p, uu = 2 * j + 1, 2.0, pm, um
            else:
                i, w, p, uu = 2 * j, 1.0, -u[j] * v[j], u[j]
            obj += r * w * uu * uu
            if slack:
                if a[i] <= 0.0 or b[i] <= 0.0:
                    return math.inf, math.inf
                obj += w * (-eg * a[i] + b[i] / em)
                bar -= mu * (math.log(a[i]) + math.log(b[i]))
                inf += abs(a[i] - b[i] - p)
            else:
                obj -= w * eg * p
        if tmax > 0.0:
            gup = tmax - u[j]
            gdn = tmax + u[j]
            if gup <= 0.0 or gdn <= 0.0:
                return math.inf, math.inf
            bar -= mu * (math.log(gup) + math.log(gdn))
    return obj + bar, inf


@nb.njit(cache=True)
def _points(th, v, u, q1n, q1m, h, gamma, wrap):
    """``p`` at the 2K points (node 2j, midpoint 2j+1), and the midpoint ``theta, v, u``."""
    k = th.size
    g = np.zeros((9, 6))
    p = np.empty(2 * k)
    mid = np.empty((k, 3))
    for j in range(k):
        c1, c2, vm, um, pm, hva, hvb, qmsm, saq, sbq = _interval(
            j, k, th, v, u, q1n, q1m, h, gamma, wrap, g)
        jb = j + 1 if j + 1 < k else 0
        thb = th[jb] + (wrap if jb == 0 else 0.0)
        mid[j, 0] = 0.5 * (th[j] + thb) + h / 8 * (v[j] - v[jb])
        mid[j, 1] = vm
        mid[j, 2] = um
        p[2 * j] = -u[j] * v[j]
        p[2 * j + 1] = pm
    return p, mid


# -- motion -------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class CollocationMotion:
    """The collocation's motion: ``theta`` the cubic Hermite interpolant of
    ``(theta_j, v_j)``, ``theta_dot`` the state ``v`` (cubic Hermite of ``(v_j, f_j)``), the
    torque ``u`` piecewise linear; ``theta_ddot`` is the acceleration the dynamics give,
    ``f = -gamma v + (1 + q) sin(theta) + u`` (Eq. 14), so that the inverse dynamics of
    :func:`parapend.model.torque` return ``u`` exactly."""

    omega: float
    theta_nodes: np.ndarray
    v_nodes: np.ndarray
    u_nodes: np.ndarray
    excitation: object
    gamma: float
    winding: int = 1

    @property
    def intervals(self) -> int:
        return int(self.theta_nodes.size)

    @property
    def period(self) -> float:
        return 2 * math.pi / self.omega

    def _locate(self, t):
        tau, h, j, off = locate(t, self.period, self.intervals, self.winding)
        return tau, h, j, (j + 1) % self.intervals, off

    def _f_nodes(self):
        tn = self.period / self.intervals * np.arange(self.intervals)
        return (-self.gamma * self.v_nodes
                + (1.0 + self.excitation.q(tn)) * np.sin(self.theta_nodes) + self.u_nodes)

    def theta(self, t):
        s, h, j, jb, off = self._locate(t)
        thb = self.theta_nodes[jb] + np.where(jb == 0, 2 * math.pi * self.winding, 0.0)
        return _cubic(s, h, self.theta_nodes[j], self.v_nodes[j], thb, self.v_nodes[jb]) + off

    def theta_dot(self, t):
        s, h, j, jb, _ = self._locate(t)
        f = self._f_nodes()
        return _cubic(s, h, self.v_nodes[j], f[j], self.v_nodes[jb], f[jb])

    def torque(self, t):
        """The torque ``u(t)``, piecewise linear between the nodes (m g l)."""
        s, _, j, jb, _ = self._locate(t)
        return (1.0 - s) * self.u_nodes[j] + s * self.u_nodes[jb]

    def theta_ddot(self, t):
        t = np.asarray(t, dtype=float)
        return (-self.gamma * self.theta_dot(t)
                + (1.0 + self.excitation.q(t)) * np.sin(self.theta(t)) + self.torque(t))

    def peak_torque(self, excitation=None, gamma=None) -> float:
        """``max |u|``: at a node (the torque is linear in between), exact."""
        return float(np.max(np.abs(self.u_nodes)))

    def mean_square_speed(self) -> float:
        """``<v^2>`` by Gauss-Legendre quadrature on every interval (4 points)."""
        x, w = np.polynomial.legendre.leggauss(4)
        k = self.intervals
        t = self.period / k * (np.arange(k)[:, None] + (x[None, :] + 1) / 2)
        return float(np.sum(self.theta_dot(t) ** 2 * w) / (2 * k))


def _cubic(s, h, ya, da, yb, db):
    return ((2 * s**3 - 3 * s**2 + 1) * ya + h * (s**3 - 2 * s**2 + s) * da
            + (-2 * s**3 + 3 * s**2) * yb + h * (s**3 - s**2) * db)


# -- solver -------------------------------------------------------------------------------------


@dataclass
class CollocationSolution:
    """Outcome of :func:`solve_collocation`.

    ``power``: Simpson mean of ``p = -u v`` (mechanical); ``electrical_power``: the mean of
    ``eta_g p`` / ``p / eta_m`` at the points, exact (not the slacks), minus the copper
    loss; ``peak_torque``: ``max |u_j|``; ``status`` "converged", "max_iterations",
    "stalled" (the line search failed), "singular" or "nonfinite"; ``kkt_error``: the
    final KKT error (max norm, scaled objective); ``infeasibility``: the largest defect of
    the collocation equations at the returned motion (0 up to roundoff when converged).
    """

    motion: CollocationMotion
    power: float
    electrical_power: float
    peak_torque: float
    status: str
    iterations: int
    intervals: int
    kkt_error: float
    mu: float
    history: list = field(default_factory=list)
    infeasibility: float = math.nan


def solve_collocation(excitation, gamma: float, intervals: int, start, *,
                      efficiency=None, torque_limit=None, copper_loss: float = 0.0,
                      winding: int = 1, tol: float = 1e-10, maxiter: int = 200,
                      mu0: float | None = None) -> CollocationSolution:
    """Optimal PTO motion on ``intervals`` Hermite-Simpson intervals, from ``start`` (a
    motion with ``theta``, ``theta_dot`` and ``theta_ddot``, or a
    :class:`CollocationMotion`), maximizing the mean electrical power.

    ``efficiency``: ``(eta_g, eta_m)`` or None (mechanical power); ``torque_limit``: bounds
    ``|u| <= T_max`` or None; ``copper_loss``: ``r`` of ``r <u^2>``. ``tol``: KKT error
    (max norm; the objective is scaled by ``3K``) and the final barrier parameter is
    ``tol / 10``.
    """
    from ..model import torque as inverse_dynamics

    k = int(intervals)
    om = excitation.omega
    period = 2 * math.pi / om
    h = period / k
    tn = h * np.arange(k)
    qnm = q_on_intervals(excitation, k, (0.0, 0.5))
    q1n = 1.0 + np.ascontiguousarray(qnm[:, 0])
    q1m = 1.0 + np.ascontiguousarray(qnm[:, 1])
    wrap = 2 * math.pi * winding
    eg, em = (1.0, 1.0) if efficiency is None else (float(efficiency[0]),
                                                     float(efficiency[1]))
    slack = (1.0 / em - eg) > 1e-12
    r = float(copper_loss)
    tmax = float(torque_limit) if torque_limit is not None else -1.0
    pos = _fold(k).astype(np.int64)
    # start
    if isinstance(start, CollocationMotion) and start.intervals == k:
        th, v, u = start.theta_nodes.copy(), start.v_nodes.copy(), start.u_nodes.copy()
    else:
        th = np.asarray(start.theta(tn), dtype=float).copy()
        v = np.asarray(start.theta_dot(tn), dtype=float).copy()
        u = (np.asarray(start.torque(tn), dtype=float).copy() if hasattr(start, "torque")
             else np.asarray(inverse_dynamics(start, excitation, gamma, tn), dtype=float))
    if tmax > 0:
        u = np.clip(u, -0.99 * tmax, 0.99 * tmax)
    if mu0 is None:
        # on the objective scaled by 3K (Simpson weights 1 and 2, slack multipliers of
        # order 1): 1 took the fewest steps of 0.01 to 3 over 120 cases (docs/units.md)
        mu0 = 1.0
    mu = mu0
    mu_min = tol / 10
    n2 = 2 * k
    p, _ = _points(th, v, u, q1n, q1m, h, gamma, wrap)
    w = np.tile([1.0, 2.0], k)
    push = 1e-2 * max(1.0, float(np.max(np.abs(p))))
    if slack:
        a = np.maximum(p, 0.0) + push
        b = np.maximum(-p, 0.0) + push
        za = mu / a
        zb = mu / b
        xi = np.where(p > 0, w * eg, w / em)
    else:
        a = b = za = zb = xi = np.zeros(n2)
    al = mu / (tmax - u) if tmax > 0 else np.zeros(k)
    be = mu / (tmax + u) if tmax > 0 else np.zeros(k)
    y = np.zeros(n2)
    n = _NB * k
    ab = np.zeros((3 * _KL + 1, n))
    rhs = np.zeros(n)
    dpc = np.zeros(n2)
    gp = np.zeros((n2, 6))
    # positions of the unknowns in the folded order
    zi = (_NB * pos[:, None] + np.arange(3)[None, :]).ravel()  # (theta, v, u) of node j
    yi = (_NB * pos[:, None] + np.arange(3, 5)[None, :]).ravel()
    zdiag = np.zeros(n, dtype=bool)
    zdiag[zi] = True
    ydiag = ~zdiag
    theta_max = theta_min = None
    filt = []  # (theta, phi) pairs of the filter, reset when mu changes
    delta_last = 0.0
    delta_c = 1e-12
    resets = 0
    ls_multipliers = True
    status = "max_iterations"
    history = []
    jb = np.roll(np.arange(k), -1)
    err0 = math.inf
    it = 0
    for it in range(1, maxiter + 1):  # noqa: B007
        dual_inf, prim_inf, comp = _kkt(th, v, u, a, b, xi, za, zb, y, al, be, q1n, q1m, h,
                                        gamma, wrap, pos, mu, eg, em, r, tmax, slack, ab,
                                        rhs, dpc, gp)
        err_mu = max(dual_inf, prim_inf, comp)
        # the error of the unperturbed KKT conditions: complementarity without mu
        err0 = max(dual_inf, prim_inf, comp + mu)
        if not math.isfinite(err_mu):
            status = "nonfinite"
            break
        if err0 <= tol and mu <= mu_min * (1 + 1e-12):
            status = "converged"
            break
        if err_mu <= 10 * mu and mu > mu_min * (1 + 1e-12):
            mu = max(mu_min, min(0.2 * mu, mu**1.5))
            filt = []
            continue
        if ls_multipliers:
            # least-squares multipliers of the defects at the start (IPOPT's
            # initialization): the system with W replaced by a large multiple of I and no
            # change of the defects gives dy = (J J^T)^-1 J rhs_z
            ls_multipliers = False
            m = ab.copy()
            m[2 * _KL, zdiag] += 1e8
            rl = rhs.copy()
            rl[yi] = 0.0
            x = dgbsv(_KL, _KL, m, rl)[2]
            y = y + x[yi]
            continue
        # inertia correction (IPOPT, Alg. IC): the smallest delta (0, or tried from a third
        # of the last, growing 8-fold) for which the matrix has exactly 2K negative
        # eigenvalues, i.e. W + delta I is positive definite on the null space of the
        # defects' Jacobian (else the step may lead to a saddle point); the inertia from
        # the signs of a banded LDL^T, the step from the same factors
        delta = 0.0
        sol = None
        for _ in range(60):
            m = ab.copy()
            m[2 * _KL, zdiag] += delta
            m[2 * _KL, ydiag] -= delta_c
            fac = m[2 * _KL:].copy()
            neg, tiny = _ldl(fac, _KL)
            if neg == n2 and not tiny:
                x, res = _ldl_solve(fac, _KL, m, rhs)
                if not res <= 1e-10:
                    # the factorization without pivoting lost accuracy: banded LU with
                    # partial pivoting (the inertia count stands)
                    x, info = dgbsv(_KL, _KL, m, rhs)[2:]
                    if info != 0:
                        x = x + math.nan
                if np.all(np.isfinite(x)):
                    sol = x
                    break
            if tiny:
                delta_c = max(delta_c, 1e-9)
            if delta == 0.0:
                delta = delta_last / 3 if delta_last > 0 else 1e-4
            else:
                delta *= 8 if delta_last > 0 else 100
            if delta > 1e10:
                break
        if sol is None:
            status = "singular"
            break
        delta_last = delta
        dz = sol[zi].reshape(k, 3)
        dy = sol[yi]
        dth, dv, du = dz[:, 0], dz[:, 1], dz[:, 2]
        # eliminated unknowns
        if slack:
            dxi, da, db, dza, dzb = _recover(dz, gp, dpc, a, b, xi, za, zb, mu, eg, em)
        if tmax > 0:
            gup, gdn = tmax - u, tmax + u
            dal = mu / gup - al + al / gup * du
            dbe = mu / gdn - be - be / gdn * du
        # fraction to the boundary
        amax = 1.0
        dmax = 1.0
        if slack:
            amax = _to_boundary(b, db, _to_boundary(a, da, amax, _FRACTION), _FRACTION)
            dmax = _to_boundary(zb, dzb, _to_boundary(za, dza, dmax, _FRACTION), _FRACTION)
        if tmax > 0:
            amax = _to_boundary(gdn, du, _to_boundary(gup, -du, amax, _FRACTION), _FRACTION)
            dmax = _to_boundary(be, dbe, _to_boundary(al, dal, dmax, _FRACTION), _FRACTION)
        # filter line search (Waechter & Biegler 2006, without restoration): a trial point
        # is accepted if it reduces the infeasibility theta or the barrier objective phi
        # enough and is not dominated by the filter; an objective step (theta small, phi
        # decreasing along the step) must satisfy Armijo on phi
        phi0, th0 = _merit(th, v, u, a, b, q1n, q1m, h, gamma, wrap, mu, eg, em, r, tmax,
                           slack)
        if theta_max is None:
            theta_max = 1e4 * max(1.0, th0)
            theta_min = 1e-4 * max(1.0, th0)
        slope = _slope(th, v, u, a, b, dz, da if slack else None, db if slack else None,
                       q1n, q1m, h, gamma, wrap, mu, eg, em, r, tmax, w, slack, gp, jb)
        alpha = amax
        accepted = False
        ftype = False
        for _ in range(40):
            thn, vn, un = th + alpha * dth, v + alpha * dv, u + alpha * du
            an = a + alpha * da if slack else a
            bn = b + alpha * db if slack else b
            phi1, th1 = _merit(thn, vn, un, an, bn, q1n, q1m, h, gamma, wrap, mu, eg, em,
                               r, tmax, slack)
            if math.isfinite(phi1) and th1 <= theta_max and not any(
                    th1 >= tf and phi1 >= pf for tf, pf in filt):
                switching = slope < 0 and alpha * (-slope) ** 2.3 > th0 ** 1.1 and \
                    th0 <= theta_min
                noise = 1e-13 * (1 + abs(phi0))
                if switching:
                    if phi1 <= phi0 + 1e-4 * alpha * slope + noise:
                        accepted = ftype = True
                        break
                elif th1 <= (1 - 1e-5) * th0 or phi1 <= phi0 - 1e-5 * th0 + noise:
                    accepted = True
                    break
            alpha *= 0.5
            if alpha < 1e-12:
                break
        if not accepted and filt and resets < 5:
            # the filter blocks every point along the step (no restoration phase here):
            # forget it (IPOPT's filter reset heuristic) and try again
            filt = []
            resets += 1
            continue
        if not accepted:
            # no acceptable point along the step: at the final barrier parameter with the
            # KKT error within 1000 tol this is the floor of the arithmetic (IPOPT's
            # "acceptable level"), otherwise a failure
            status = "converged" if mu <= mu_min * (1 + 1e-12) and err0 <= 1e3 * tol \
                else "stalled"
            break
        if not ftype:
            filt.append(((1 - 1e-5) * th0, phi0 - 1e-5 * th0))
        history.append((mu, err_mu, delta, alpha))
        th, v, u, a, b = thn, vn, un, an, bn
        y = y + alpha * dy
        if slack:
            xi = xi + alpha * dxi
            za = za + dmax * dza
            zb = zb + dmax * dzb
        if tmax > 0:
            al = al + dmax * dal
            be = be + dmax * dbe
    motion = CollocationMotion(om, th, v, u, excitation, float(gamma), int(winding))
    p, mid = _points(th, v, u, q1n, q1m, h, gamma, wrap)
    uu = np.empty(n2)
    uu[0::2] = u
    uu[1::2] = mid[:, 2]
    ws = w / (3 * k)
    mech = float(ws @ p)
    ele = float(ws @ np.where(p > 0, eg * p, p / em)) - r * float(ws @ (uu * uu))
    g = np.zeros((9, 6))
    defect = max((max(abs(c[0]), abs(c[1])) for c in (
        _interval(j, k, th, v, u, q1n, q1m, h, gamma, wrap, g) for j in range(k))),
        default=0.0)
    # iterations: the Newton steps (KKT solves), not the barrier updates
    return CollocationSolution(motion, mech, ele, float(np.max(np.abs(u))), status,
                               len(history), k, err0, mu, history, float(defect))


def _slope(th, v, u, a, b, dz, da, db, q1n, q1m, h, gamma, wrap, mu, eg, em, r, tmax, w,
           slack, gp, jb):
    """Directional derivative of the barrier objective (without the penalty) along the
    step."""
    k = th.size
    du = dz[:, 2]
    s = 0.0
    # copper loss: sum w u^2 at nodes and midpoints (u_m linear)
    if r:
        um = 0.5 * (u + u[jb])
        dum = 0.5 * (du + du[jb])
        s += 2 * r * (float(u @ du) + 2 * float(um @ dum))
    if slack:
        s += float(np.sum(w * (-eg * da + db / em) - mu * (da / a + db / b)))
    else:
        loc = np.concatenate([dz, dz[jb]], axis=1)
        gdz = np.empty(2 * k)
        gdz[0::2] = gp[0::2, 1] * dz[:, 1] + gp[0::2, 2] * du
        gdz[1::2] = np.sum(gp[1::2] * loc, axis=1)
        s -= eg * float(w @ gdz)
    if tmax > 0:
        s += float(np.sum(mu * du / (tmax - u) - mu * du / (tmax + u)))
    return s
