r"""Compiled (numba) pointwise weights and Gram gathers of the hull problem (:mod:`.hull`).

:meth:`parapend.hydro.hull.HullProblem.evaluate` needs, on each of the grid's ``M``
points, the first and second derivatives of the Lagrangian's pointwise part in the six grid
variables ``(phi, phi', phi'', p_x'', p_z'', beta')`` (``_VARS``; the 21 pairs ``u <= w``
in that order), the weights of the sensitivity's right side, and Gram matrices gathered
from the weights' spectra (:class:`parapend.hydro._trig.FusedGram`). Written with NumPy
these are some two hundred small array operations per evaluation, whose call overhead (not
their arithmetic) was most of a Newton step on the hull's harmonics (tens of points). Here
an evaluation is three compiled calls around one FFT: :func:`hull_state` (phi and the
reaction on the grid, the hull matrix from the reaction's spectra, its inverse by Woodbury's
identity, the hull's unknowns, the torque and the power), :func:`gradient_and_weights` and
:func:`reduced_hessian`. Their sums are loops rather than
array expressions, each of which compiles apart (up to a second each); the products are
BLAS's (``np.dot``, the maps stored in the orientation each product reads). The kernel
compiles in about 10 s of CPU on first use, then loads from numba's cache.

The formulas are those of the hull's module docstring, point by point:

- the torque ``tau = I phi'' + c v - m l [(g + p_z'') sin phi - p_x'' cos phi]``,
  ``v = phi' - beta'``, and the objective ``f(tau, v)`` with its derivatives
  ``(f_tau, f_v, f_tautau, f_tauv, f_vv)`` given (:meth:`.hull.HullProblem._objective`):
  :func:`objective_weights`, the chain rule through ``tau`` divided by ``M`` (the mean);
- the hull's projected equation's reaction ``rho = (r_x, r_z, r_beta)`` weighted by the
  adjoint's ``mu`` (3, M): :func:`constraint_weights`, with the reaction's own
  derivatives (the sensitivity's weights).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .._jit import announce_compiles

announce_compiles()  # log a first-use compile (parapend._jit)

__all__ = ["constraint_weights", "fused_gram", "grid_motion", "gradient_and_weights",
           "hull_inverse", "hull_solve", "hull_state", "hull_torque", "lift",
           "objective_weights", "phi_gradient", "pivot_adjoint", "pivot_grid", "project",
           "reaction", "reduced_hessian", "spectra_at", "torque"]


@nb.njit(cache=True)
def _pair(u, w):
    """Row of the pair ``(u, w)``, ``u <= w``, among the 21 pairs of six variables."""
    return u * 6 - (u * (u - 1)) // 2 + (w - u)


@nb.njit(cache=True)
def _tx(a, x):
    """``a^T x`` (``a`` C order): a sum of ``a``'s rows, the zero entries of ``x`` skipped
    (a loop: NumPy's product with a transposed operand compiles apart)."""
    k, n = a.shape
    out = np.zeros(n)
    for j in range(k):
        xj = x[j]
        if xj != 0.0:
            for i in range(n):
                out[i] += xj * a[j, i]
    return out


@nb.njit(cache=True)
def torque(sn, co, f1, f2, qx, qz, b1, inertia, c, ml, g):
    """``(tau, v, P)`` on the grid: the generator's torque (P) ``tau = I phi'' + c v -
    m l [(g + p_z'') sin phi - p_x'' cos phi]``, the relative speed ``v = phi' - beta'``
    and the mechanical power ``P = -<tau v>`` (``sn``, ``co``: ``sin phi``, ``cos phi``)."""
    m = sn.size
    tau = np.empty(m)
    v = np.empty(m)
    acc = 0.0
    for j in range(m):
        v[j] = f1[j] - b1[j]
        tau[j] = (inertia * f2[j] + c * v[j]
                  - ml * ((g + qz[j]) * sn[j] - qx[j] * co[j]))
        acc += tau[j] * v[j]
    return tau, v, -acc / m


@nb.njit(cache=True)
def objective_weights(sin_phi, cos_phi, qx, qz, ft, fv, ftt, ftv, fvv, ml, inertia, c, g):
    """``(d1, d2)``: the mean ``<f(tau, v)>``'s derivatives in the six grid variables,
    pointwise ((6, M) and (21, M), divided by ``M``), by the chain rule through ``tau``
    (``d tau = (-m l w_phi, c, I, m l cos, -m l sin, -c)``, ``d v = (0, 1, 0, 0, 0, -1)``,
    ``tau``'s own second derivatives on ``(phi, phi)``, ``(phi, p_x'')``, ``(phi, p_z'')``)."""
    m = sin_phi.size
    d1 = np.zeros((6, m))
    d2 = np.zeros((21, m))
    dt = np.empty(6)
    dv = np.zeros(6)
    dv[1] = 1.0
    dv[5] = -1.0
    for j in range(m):
        sn, co = sin_phi[j], cos_phi[j]
        wgt = (g + qz[j]) * sn - qx[j] * co
        wph = (g + qz[j]) * co + qx[j] * sn
        dt[0], dt[1], dt[2] = -ml * wph, c, inertia
        dt[3], dt[4], dt[5] = ml * co, -ml * sn, -c
        a, b = ft[j] / m, fv[j] / m
        aa, ab, bb = ftt[j] / m, ftv[j] / m, fvv[j] / m
        for u in range(6):
            d1[u, j] = a * dt[u] + b * dv[u]
            for w in range(u, 6):
                d2[_pair(u, w), j] = (aa * dt[u] * dt[w] + ab * (dt[u] * dv[w] + dv[u] * dt[w])
                                      + bb * dv[u] * dv[w])
        d2[0, j] += a * ml * wgt
        d2[3, j] += -a * ml * sn
        d2[4, j] += -a * ml * co
    return d1, d2


@nb.njit(cache=True)
def reaction(f, f1, f2, ml, inertia, g, dp, hp):
    """The pendulum's reaction on the hull at rest in the hull's frame, on the grid:
    ``(r_x, r_z, r_beta)`` (3, M) with the weight's ``m l g sin phi`` (the pivot's
    acceleration's part enters the hull matrix), and ``-m l sin phi``, ``m l cos phi``: the
    weights of the hull matrix's ``p_z''`` and ``p_x''`` parts; and ``sin phi``,
    ``cos phi`` (every later pointwise function reads them)."""
    m = f.size
    r = np.empty((3, m))
    s = np.empty((2, m))
    sin_phi = np.empty(m)
    cos_phi = np.empty(m)
    for j in range(m):
        sn, co = math.sin(f[j]), math.cos(f[j])
        sin_phi[j], cos_phi[j] = sn, co
        rx = -ml * (co * f2[j] - sn * f1[j] ** 2)
        rz = ml * (sn * f2[j] + co * f1[j] ** 2)
        r[0, j], r[1, j] = rx, rz
        r[2, j] = hp * rx - dp * rz - inertia * f2[j] + ml * g * sn
        s[0, j], s[1, j] = -ml * sn, ml * co
    return r, s, sin_phi, cos_phi


@nb.njit(cache=True, fastmath={"reassoc"})
def _analysis(rows, kmax, ct, st):
    """``(A_c, A_s)``, (R, kmax) each: ``sum_j rows[r, j] cos(k s_j)`` and ``sin(k s_j)``
    for ``k = 1..kmax`` (``ct``, ``st``: the tables, row ``k - 1``; the sums reassociated
    so that they vectorize)."""
    nr, m = rows.shape
    ac = np.empty((nr, kmax))
    asn = np.empty((nr, kmax))
    for r in range(nr):
        for k in range(kmax):
            a = 0.0
            b = 0.0
            for j in range(m):
                a += rows[r, j] * ct[k, j]
                b += rows[r, j] * st[k, j]
            ac[r, k] = a
            asn[r, k] = b
    return ac, asn


@nb.njit(cache=True)
def grid_motion(x, geo, s, winding, ml, inertia, g):
    """``(phi, phi', phi'', r, wz, sin phi, cos phi)`` on the grid from the coefficients
    ``x``: ``phi = K s + x_0 + sum_n x_n sin(n s) + x_{N+n} cos(n s)`` and its derivatives
    (``geo``: :func:`pivot_grid`'s), and :func:`reaction` there."""
    n, _, _, _, om, hp, dp, ct, st = geo
    m = s.size
    f = np.empty(m)
    f1 = np.empty(m)
    f2 = np.zeros(m)
    for j in range(m):
        f[j] = winding * s[j] + x[0]
        f1[j] = om * winding
    for k in range(n):
        a, b = x[1 + k], x[1 + n + k]
        c1 = om * (k + 1)
        c2 = c1 * c1
        for j in range(m):
            sj, cj = st[k, j], ct[k, j]
            f[j] += a * sj + b * cj
            f1[j] += c1 * (a * cj - b * sj)
            f2[j] -= c2 * (a * sj + b * cj)
    r, wz, sn, co = reaction(f, f1, f2, ml, inertia, g, dp, hp)
    return f, f1, f2, r, wz, sn, co


@nb.njit(cache=True)
def phi_gradient(d1, geo):
    """The reduced gradient ``P^T d1``: ``d1``'s rows 0-2 (the weights of ``phi``, ``phi'``,
    ``phi''`` on the grid) mapped back to ``phi``'s coefficients (:func:`grid_motion`'s
    map transposed, by :func:`_analysis`)."""
    n, _, _, _, om, _, _, ct, st = geo
    grad = np.empty(2 * n + 1)
    acc = 0.0
    for j in range(d1.shape[1]):
        acc += d1[0, j]
    grad[0] = acc
    ac, asn = _analysis(d1[:3], n, ct, st)
    for k in range(n):
        c1 = om * (k + 1)
        c2 = c1 * c1
        grad[1 + k] = asn[0, k] - c2 * asn[2, k] + c1 * ac[1, k]
        grad[1 + n + k] = ac[0, k] - c2 * ac[2, k] - c1 * asn[1, k]
    return grad


@nb.njit(cache=True)
def project(r, geo, b0):
    """``b0 + Pi r``: the hull's equations' right side, the reaction ``r`` (3, M) projected
    on the hull's unknowns (the static DOFs' means; ``2/M sum cos``, ``-2/M sum sin`` for
    the real and imaginary parts of each harmonic)."""
    _, nh, j0, static, _, _, _, ct, st = geo
    m = r.shape[1]
    b = b0.copy()
    for i in range(j0):
        acc = 0.0
        for j in range(m):
            acc += r[static[i], j]
        b[i] += acc / m
    ac, asn = _analysis(r, nh, ct, st)
    for k in range(nh):
        for d in range(3):
            o = j0 + 6 * k + d
            b[o] += 2.0 / m * ac[d, k]
            b[o + 3] -= 2.0 / m * asn[d, k]
    return b


@nb.njit(cache=True)
def lift(lam, geo, m):
    """``Pi^T lambda`` (3, M): :func:`project`'s transpose."""
    _, nh, j0, static, _, _, _, ct, st = geo
    mu = np.zeros((3, m))
    for i in range(j0):
        v = lam[i] / m
        for j in range(m):
            mu[static[i], j] += v
    for k in range(nh):
        for d in range(3):
            o = j0 + 6 * k + d
            cr, ci = 2.0 / m * lam[o], -2.0 / m * lam[o + 3]
            for j in range(m):
                mu[d, j] += cr * ct[k, j] + ci * st[k, j]
    return mu


@nb.njit(cache=True)
def pivot_grid(y, geo, m):
    """``(p_x'', p_z'', beta')`` on the grid from the hull's unknowns ``y``: ``xi_d'' =
    sum_k -(k w)^2 (Re cos - Im sin)``, ``xi_d' = sum_k -k w (Re sin + Im cos)``,
    ``p'' = G xi''``. ``geo = (N, Nh, j0, static, w, h_p, d_p, cos, sin)``: the harmonics of
    phi and of the hull, the static unknowns and their DOFs, the frequency, the pivot and
    the tables ``cos(k s_j)``, ``sin(k s_j)`` (row ``k - 1``, up to ``max(N, Nh)``)."""
    _, nh, j0, _, om, hp, dp, ct, st = geo
    qx = np.zeros(m)
    qz = np.zeros(m)
    b1 = np.zeros(m)
    for k in range(nh):
        c1 = om * (k + 1)
        c2 = c1 * c1
        o = j0 + 6 * k
        xc, xs = -c2 * (y[o] + hp * y[o + 2]), c2 * (y[o + 3] + hp * y[o + 5])
        zc, zs = -c2 * (y[o + 1] - dp * y[o + 2]), c2 * (y[o + 4] - dp * y[o + 5])
        bc, bs = -c1 * y[o + 5], -c1 * y[o + 2]
        for j in range(m):
            cj, sj = ct[k, j], st[k, j]
            qx[j] += xc * cj + xs * sj
            qz[j] += zc * cj + zs * sj
            b1[j] += bc * cj + bs * sj
    return qx, qz, b1


@nb.njit(cache=True)
def pivot_adjoint(d1, geo, ny):
    """:func:`pivot_grid`'s map transposed on ``d1``'s rows 3-5 (the weights of ``p_x''``,
    ``p_z''``, ``beta'``): ``d<f>/dy``."""
    _, nh, j0, _, om, hp, dp, ct, st = geo
    gy = np.zeros(ny)
    ac, asn = _analysis(d1[3:], nh, ct, st)
    for k in range(nh):
        c1 = om * (k + 1)
        c2 = c1 * c1
        o = j0 + 6 * k
        gy[o], gy[o + 3] = -c2 * ac[0, k], c2 * asn[0, k]
        gy[o + 1], gy[o + 4] = -c2 * ac[1, k], c2 * asn[1, k]
        gy[o + 2] = -c2 * (hp * ac[0, k] - dp * ac[1, k]) - c1 * asn[2, k]
        gy[o + 5] = c2 * (hp * asn[0, k] - dp * asn[1, k]) - c1 * ac[2, k]
    return gy


@nb.njit(cache=True)
def hull_torque(y, geo, sn, co, f1, f2, inertia, c, ml, g):
    """``(p_x'', p_z'', beta', tau, v, P)`` on the grid for the hull's unknowns ``y``
    (:func:`pivot_grid`, :func:`torque`)."""
    qx, qz, b1 = pivot_grid(y, geo, sn.size)
    tau, v, p = torque(sn, co, f1, f2, qx, qz, b1, inertia, c, ml, g)
    return qx, qz, b1, tau, v, p


@nb.njit(cache=True)
def hull_inverse(gp, zinv, zp, prow, blocks):
    """``S^{-1}`` of the hull matrix ``S = Z + E gp`` by Woodbury's identity: only the pitch
    rows ``prow`` (``E`` puts ``gp``'s rows there) of ``S`` depend on the motion, and
    ``Z`` is block diagonal (the static block, then one 6 x 6 block per hull harmonic;
    ``blocks`` their starts and the end) with its inverse ``zinv`` computed once
    (``zp = zinv[:, prow]``):

        S^{-1} = Z^{-1} - zp (I + gp zp)^{-1} (gp Z^{-1}),

    a ``len(prow)``-square inverse (``2 Nh + 1`` against ``6 Nh + 2``) and products that
    skip ``Z^{-1}``'s zero blocks (:func:`hull_solve` checks the result)."""
    r, n = gp.shape
    if r == 0:
        return zinv.copy()
    ra = np.zeros((r, n))  # gp Z^{-1}, block by block
    for b in range(blocks.size - 1):
        lo, hi = blocks[b], blocks[b + 1]
        for i in range(r):
            for k in range(lo, hi):
                g = gp[i, k]
                if g != 0.0:
                    for c in range(lo, hi):
                        ra[i, c] += g * zinv[k, c]
    cap = np.empty((r, r))
    for i in range(r):
        for j in range(r):
            cap[i, j] = ra[i, prow[j]]
        cap[i, i] += 1.0
    corr = np.dot(np.dot(zp, np.linalg.inv(cap)), ra)
    sinv = np.empty((n, n))
    for i in range(n):
        for k in range(n):
            sinv[i, k] = zinv[i, k] - corr[i, k]
    return sinv


@nb.njit(cache=True)
def hull_solve(v, ptr, idx, coef, n1, n2, symmetric, z, zinv, zp, prow, blocks, b0, r, geo,
               sn, co, f1, f2, inertia, c, ml, g):
    """``(S^{-1}, y, p_x'', p_z'', beta', tau, v, P)``: the hull's unknowns at the motion
    whose reaction is ``r`` (3, M) and whose hull-matrix weights have the spectra ``v``,
    ``y = S^{-1} (b0 + Pi r)`` (:func:`project`) with ``S = Z + G(v)`` (the gathers of
    :func:`fused_gram`, non-zero on the pitch rows ``prow`` only; :func:`hull_inverse`), and
    :func:`hull_torque` there. The inverse, not a factorization: the adjoint and the
    sensitivity's right sides are products with it in :func:`gradient_and_weights` and
    :func:`reduced_hessian`, and nearly every point whose power is asked is then evaluated
    (a line search's first trial is accepted)."""
    gm = fused_gram(v, ptr, idx, coef, n1, n2, symmetric)
    gp = np.empty((prow.size, gm.shape[1]))
    for i in range(prow.size):
        for k in range(gm.shape[1]):
            gp[i, k] = gm[prow[i], k]
    sinv = hull_inverse(gp, zinv, zp, prow, blocks)
    b = project(r, geo, b0)
    y = np.dot(sinv, b)
    # the check: y's backward error |S y - b| / (|S| |y| + |b|) (max norms) at rounding's
    # scale; above 1e-10 (Woodbury's small matrix ill-conditioned where S is not), S is
    # inverted directly (LAPACK getrf and getri)
    res = np.dot(z, y)
    gy = np.dot(gp, y)
    for i in range(prow.size):
        res[prow[i]] += gy[i]
    worst, srow, ymax, bmax = 0.0, 0.0, 0.0, 0.0
    for i in range(b.size):
        worst = max(worst, abs(res[i] - b[i]))
        ymax = max(ymax, abs(y[i]))
        bmax = max(bmax, abs(b[i]))
        acc = 0.0
        for k in range(b.size):
            acc += abs(z[i, k])
        srow = max(srow, acc)
    for i in range(prow.size):
        acc = 0.0
        for k in range(b.size):
            acc += abs(z[prow[i], k]) + abs(gp[i, k])
        srow = max(srow, acc)
    scale = srow * ymax + bmax
    if not worst <= 1e-10 * scale:
        s = z.copy()
        for i in range(prow.size):
            for k in range(s.shape[1]):
                s[prow[i], k] += gp[i, k]
        sinv = np.ascontiguousarray(np.linalg.inv(s))
        y = np.dot(sinv, b)
    return (sinv, y) + hull_torque(y, geo, sn, co, f1, f2, inertia, c, ml, g)


@nb.njit(cache=True)
def spectra_at(w, freqs, ctab, stab):
    """``[Re R, Im R]`` of the rows of ``w`` (K, M) flattened, ``R`` the half spectrum
    (``rfft``; :func:`parapend.hydro._trig.spectra`'s layout), at the frequencies ``freqs``
    only (the others zero), by direct sums with the tables ``ctab``, ``stab`` (``cos``,
    ``sin`` of ``2 pi f j / M``): the hull matrix reads the weights' spectra up to ``2 Nh``
    only, fewer operations than an FFT's call."""
    k, m = w.shape
    half = m // 2 + 1
    v = np.zeros(k * 2 * half)
    for r in range(k):
        for q in range(freqs.size):
            a = 0.0
            b = 0.0
            for j in range(m):
                a += w[r, j] * ctab[q, j]
                b += w[r, j] * stab[q, j]
            v[r * 2 * half + freqs[q]] = a
            v[r * 2 * half + half + freqs[q]] = -b
    return v


@nb.njit(cache=True)
def hull_state(x, geo, s, winding, ml, inertia, g, freqs, ctab, stab, ptr, idx, coef, n1,
               n2, symmetric, z, zinv, zp, prow, blocks, b0, c):
    """The coupled problem's state at ``x`` in one call: ``(phi, phi', phi'', sin phi,
    cos phi)`` (:func:`grid_motion`), then :func:`hull_solve`'s ``(S^{-1}, y, p_x'', p_z'',
    beta', tau, v, P)`` with the hull matrix's spectra by :func:`spectra_at`."""
    f, f1, f2, r, wz, sn, co = grid_motion(x, geo, s, winding, ml, inertia, g)
    v = spectra_at(wz, freqs, ctab, stab)
    out = hull_solve(v, ptr, idx, coef, n1, n2, symmetric, z, zinv, zp, prow, blocks, b0, r,
                     geo, sn, co, f1, f2, inertia, c, ml, g)
    return (f, f1, f2, sn, co) + out


@nb.njit(cache=True)
def constraint_weights(sin_phi, cos_phi, f1, f2, qx, qz, mu, ml, inertia, g, dp, hp):
    """``(c1, c2, sens)``: the derivatives of ``sum_d mu_d rho_d`` pointwise in the six grid
    variables ((6, M), (21, M)), and the reaction's derivatives ``d rho_d / d(phi, phi',
    phi'')`` (9, M), row ``3 d + i``: the sensitivity's weights."""
    m = sin_phi.size
    c1 = np.zeros((6, m))
    c2 = np.zeros((21, m))
    sens = np.empty((9, m))
    for j in range(m):
        sn, co = sin_phi[j], cos_phi[j]
        p1, p2 = f1[j], f2[j]
        wgt = (g + qz[j]) * sn - qx[j] * co
        wph = (g + qz[j]) * co + qx[j] * sn
        e = mu[2, j]
        a = mu[0, j] + hp * e
        b = mu[1, j] - dp * e
        x = a * sn + b * co
        y = b * sn - a * co
        c1[0, j] = ml * e * wph + ml * (p2 * x - p1 * p1 * y)
        c1[1, j] = 2.0 * ml * p1 * x
        c1[2, j] = ml * y - inertia * e
        c1[3, j] = -ml * e * co
        c1[4, j] = ml * e * sn
        c2[0, j] = -ml * e * wgt + ml * (-p2 * y - p1 * p1 * x)
        c2[1, j] = -2.0 * ml * p1 * y
        c2[2, j] = ml * x
        c2[3, j] = ml * e * sn
        c2[4, j] = ml * e * co
        c2[6, j] = 2.0 * ml * x
        rx = -ml * (co * p2 - sn * p1 * p1)
        rz = ml * (sn * p2 + co * p1 * p1)
        dx0, dx1, dx2 = rz, 2.0 * ml * sn * p1, -ml * co
        dz0, dz1, dz2 = -rx, 2.0 * ml * co * p1, ml * sn
        sens[0, j], sens[1, j], sens[2, j] = dx0, dx1, dx2
        sens[3, j], sens[4, j], sens[5, j] = dz0, dz1, dz2
        sens[6, j] = hp * dx0 - dp * dz0 + ml * wph
        sens[7, j] = hp * dx1 - dp * dz1
        sens[8, j] = hp * dx2 - dp * dz2 - inertia
    return c1, c2, sens


@nb.njit(cache=True)
def fused_gram(v, ptr, idx, coef, n1, n2, symmetric):
    """The (n1, n2) sum of :class:`.FusedGram`: entry ``e = i n2 + k`` is
    ``sum coef[j] v[idx[j]]`` over ``j`` in ``ptr[e]:ptr[e + 1]`` (``v`` the stacked
    spectra flattened); ``symmetric``: only the entries on and above the diagonal are
    stored, mirrored."""
    out = np.zeros((n1, n2))
    for i in range(n1):
        for k in range(i if symmetric else 0, n2):
            e = i * n2 + k
            acc = 0.0
            for j in range(ptr[e], ptr[e + 1]):
                acc += coef[j] * v[idx[j]]
            out[i, k] = acc
            if symmetric:
                out[k, i] = acc
    return out


@nb.njit(cache=True)
def gradient_and_weights(sn, co, f1, f2, qx, qz, ft, fv, ftt, ftv, fvv, rows, coupled, sinv,
                         geo, ny, ml, inertia, c, g):
    """The first half of an evaluation: the Lagrangian's pointwise derivatives (the
    objective's; with ``coupled``, plus the hull's reaction weighted by the adjoint ``mu``,
    ``S^T lambda = d<f>/dy``, ``mu = Pi^T lambda``), the reduced gradient ``P^T d1`` and
    the weights whose spectra give the Hessian: the pairs ``rows`` of the second
    derivatives, then (coupled) the nine sensitivity weights. ``sinv`` is ``S^{-1}``,
    ``geo`` the maps' (:func:`pivot_grid`), ``ny`` the hull's unknowns."""
    _, _, _, _, _, hp, dp, _, _ = geo
    m = sn.size
    d1, d2 = objective_weights(sn, co, qx, qz, ft, fv, ftt, ftv, fvv, ml, inertia, c, g)
    nr = rows.size
    w = np.empty((nr + (9 if coupled else 0), m))
    if coupled:
        gy = pivot_adjoint(d1, geo, ny)
        lam = _tx(sinv, gy)  # S^{-T} gy
        mu = lift(lam, geo, m)
        c1, c2, sens = constraint_weights(sn, co, f1, f2, qx, qz, mu, ml, inertia, g, dp, hp)
        for j in range(m):  # loops, not array expressions: each of those compiles apart
            for u in range(6):
                d1[u, j] += c1[u, j]
            for u in range(21):
                d2[u, j] += c2[u, j]
            for u in range(9):
                w[nr + u, j] = sens[u, j]
    for i in range(nr):
        for j in range(m):
            w[i, j] = d2[rows[i], j]
    return phi_gradient(d1, geo), w


@nb.njit(cache=True)
def reduced_hessian(v, xx, xy, yy, sens, coupled, sinv):
    """The second half: the Hessian's blocks gathered from the weights' spectra ``v``
    (flattened; each block the arguments of :func:`fused_gram` after ``v``), reduced by
    the sensitivity ``T = S^{-1} g_x``: ``H = L_xx + L_xy T + T^T L_yx + T^T L_yy T``,
    symmetrized."""
    hxx = fused_gram(v, *xx)
    if coupled:
        hxy = fused_gram(v, *xy)
        hyy = fused_gram(v, *yy)
        # the matrix products by BLAS (np.dot; tens by tens, up to 2N + 1 columns)
        t = np.dot(sinv, fused_gram(v, *sens))
        ht = np.dot(hxy, t)
        tt = np.dot(t.T, np.dot(hyy, t))
        for i in range(hxx.shape[0]):
            for k in range(hxx.shape[1]):
                hxx[i, k] += ht[i, k] + ht[k, i] + tt[i, k]
    n = hxx.shape[0]
    h = np.empty((n, n))
    for i in range(n):
        for k in range(n):
            h[i, k] = 0.5 * (hxx[i, k] + hxx[k, i])
    return h
