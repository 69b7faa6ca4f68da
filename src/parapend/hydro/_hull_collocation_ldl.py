r"""Compiled (numba) sparse ``L D L^T`` of the hull collocation NLP's whole KKT matrix
(:mod:`._hull_collocation_ipm`), the inertia counted from ``D``.

The KKT matrix of the barrier problem's Newton step

    [K + delta_w I + eps I        J^T          ]
    [      J            -(delta_c + eps) I     ]

(``K`` the Lagrangian's Hessian plus the barrier's weights, ``J`` the equality rows'
Jacobian) is factored without pivoting in a fill-reducing order fixed once per problem
(the approximate minimum degree of its pattern: QDLDL's, from the ``qdldl`` package), its
numeric factors anew every iteration by QDLDL's up-looking algorithm (Davis, *Direct
Methods for Sparse Linear Systems*, 2006, 4.7: the elimination tree once, then every column
of ``L`` from a sparse triangular solve along it) compiled here; the trailing columns that
are (nearly) full (the memory's rows couple every velocity node: their clique ends the
order) are left as their dense Schur complement, factored by LAPACK's Bunch-Kaufman ``L D
L^T`` (``dsytrf``: blocked, its 1 x 1 and 2 x 2 pivots' signs the complement's inertia;
the compiled loop it replaced took twice its time). ``eps`` (:data:`EPS`) is a
static regularization: with it the matrix is quasi-definite where ``K + delta_w I`` is
positive definite, and a quasi-definite matrix has an ``L D L^T`` in every symmetric order
(Vanderbei, SIAM J. Optim. 5, 1995); its error in the step is taken out by iterative
refinement on the matrix without it. By Sylvester's law of inertia ``D``'s signs are the
matrix's inertia, which IPOPT's inertia correction asks to be ``(n, m, 0)`` (``n``
unknowns, ``m`` rows; Wächter and Biegler, Math. Program. 106, 2006, 3.1): the
factorization stops at its ``(m + 1)``-th negative pivot, or at a zero one, and reports it
(in the dense complement both are counted once LAPACK has factored it).
"""

from __future__ import annotations

import numba as nb
import numpy as np
from scipy.linalg.lapack import dsytrf, dsytrf_lwork, dsytrs

from .._jit import announce_compiles

announce_compiles()  # log a first-use compile (parapend._jit)

#: the static regularization of both diagonal blocks (refined away)
EPS = 1e-9
#: the trailing columns of L at least this full are factored as one dense block, where at
#: least DENSE_MIN of them
DENSE = 0.7
DENSE_MIN = 32


@nb.njit(cache=True)
def etree(n, ap, ai, lnz, parent):
    """The elimination tree ``parent`` and the column counts ``lnz`` of ``L`` of the upper
    triangle ``(ap, ai)`` (CSC, diagonal included); the number of ``L``'s entries."""
    work = np.empty(n, np.int64)
    for i in range(n):
        work[i] = -1
        lnz[i] = 0
        parent[i] = -1
    for j in range(n):
        work[j] = j
        for p in range(ap[j], ap[j + 1]):
            i = ai[p]
            while work[i] != j:
                if parent[i] == -1:
                    parent[i] = j
                lnz[i] += 1
                work[i] = j
                i = parent[i]
    tot = 0
    for i in range(n):
        tot += lnz[i]
    return tot


@nb.njit(cache=True)
def _reach(b, bound, parent, mark, eb, yi, ny):
    """The unmarked nodes of the elimination tree's path from ``b`` (below ``bound``)
    marked and appended to ``yi`` (its first ``ny`` entries kept) so that ``yi`` read
    backwards is in topological order; the new count (``eb``: work space)."""
    if mark[b]:
        return ny
    mark[b] = True
    eb[0] = b
    ne = 1
    c = parent[b]
    while c != -1 and c < bound:
        if mark[c]:
            break
        mark[c] = True
        eb[ne] = c
        ne += 1
        c = parent[c]
    while ne > 0:
        ne -= 1
        yi[ny] = eb[ne]
        ny += 1
    return ny


@nb.njit(cache=True)
def factor(n, ap, ai, ax, parent, lp, li, lx, d, dinv, maxneg, nxt):
    """``L D L^T`` of the upper triangle ``(ap, ai, ax)`` into ``(lp, li, lx)`` (unit
    diagonal implied) and ``d``; returns the number of positive pivots, ``-1`` at a zero or
    non-finite pivot, ``-2`` past ``maxneg`` negative ones (the factors then partial).
    ``nxt``: every column's entries' end (out)."""
    mark = np.zeros(n, np.bool_)
    yv = np.zeros(n)
    yi = np.empty(n, np.uint32)
    eb = np.empty(n, np.uint32)
    for c in range(n):
        nxt[c] = lp[c]
    npos = 0
    nneg = 0
    for k in range(n):
        ny = 0
        dk = 0.0
        for q in range(ap[k], ap[k + 1]):
            b = ai[q]
            if b == k:
                dk = ax[q]
                continue
            yv[b] = ax[q]
            ny = _reach(b, k, parent, mark, eb, yi, ny)
        for t in range(ny - 1, -1, -1):
            c = yi[t]
            e = nxt[c]
            yc = yv[c]
            j0 = lp[c]
            for j in range(e - j0):  # (unsigned row indices: no wraparound checks)
                yv[li[j0 + j]] -= lx[j0 + j] * yc
            li[e] = k
            lx[e] = yc * dinv[c]
            dk -= yc * lx[e]
            nxt[c] = e + 1
            yv[c] = 0.0
            mark[c] = False
        d[k] = dk
        if dk == 0.0 or not np.isfinite(dk):
            return -1
        if dk > 0.0:
            npos += 1
        else:
            nneg += 1
            if nneg > maxneg:
                return -2
        dinv[k] = 1.0 / dk
    return npos


@nb.njit(cache=True)
def solve_lower(n, s, lp, li, lx, dinv, perm, b, x):
    """The first half of :meth:`SparseLDL.solve`: ``x = P^T b`` through ``L``'s sparse
    columns (the first ``s``) and ``D``'s first ``s`` pivots; its rows from ``s`` on then
    wait for the dense Schur complement's solve."""
    for k in range(n):
        x[k] = b[perm[k]]
    for i in range(s):
        xi = x[i]
        if xi != 0.0:
            j0 = lp[i]
            for j in range(lp[i + 1] - j0):
                x[li[j0 + j]] -= lx[j0 + j] * xi
    for i in range(s):
        x[i] *= dinv[i]


@nb.njit(cache=True)
def solve_upper(n, s, lp, li, lx, perm, x, out):
    """The second half of :meth:`SparseLDL.solve`: ``L^T``'s sparse columns backwards and
    the order undone into ``out``."""
    for i in range(s - 1, -1, -1):
        t = x[i]
        j0 = lp[i]
        for j in range(lp[i + 1] - j0):
            t -= lx[j0 + j] * x[li[j0 + j]]
        x[i] = t
    for k in range(n):
        out[perm[k]] = x[k]


@nb.njit(cache=True)
def inertia(a, ipiv):
    """The positive and the negative eigenvalues' numbers of LAPACK's ``dsytrf`` factors
    (``lower``: the 1 x 1 and 2 x 2 blocks of ``D`` on ``a``'s diagonal and below it, a 2 x
    2 block where ``ipiv[k] = ipiv[k + 1] < 0``), or ``(-1, 0)`` where ``D`` is singular or
    not finite (Sylvester's law: ``D``'s inertia is the matrix's)."""
    m = a.shape[0]
    npos = 0
    nneg = 0
    k = 0
    while k < m:
        if ipiv[k] < 0 and k + 1 < m:
            p, q, r = a[k, k], a[k + 1, k], a[k + 1, k + 1]
            det = p * r - q * q
            if det == 0.0 or not np.isfinite(det):
                return -1, 0
            if det < 0.0:
                npos += 1
                nneg += 1
            elif p > 0.0:
                npos += 2
            else:
                nneg += 2
            k += 2
        else:
            dk = a[k, k]
            if dk == 0.0 or not np.isfinite(dk):
                return -1, 0
            if dk > 0.0:
                npos += 1
            else:
                nneg += 1
            k += 1
    return npos, nneg


@nb.njit(cache=True)
def scatter(pos, val, out):
    """``out[pos[i]] += val[i]`` over ``out`` zeroed."""
    for i in range(out.size):
        out[i] = 0.0
    for i in range(pos.size):
        out[pos[i]] += val[i]


def amd_order(n, rows, cols):
    """The approximate minimum degree order of the symmetric pattern ``(rows, cols)`` (both
    triangles or either, the diagonal added): QDLDL's, from ``qdldl``."""
    import qdldl
    import scipy.sparse as sp

    r = np.concatenate((rows, cols, np.arange(n)))
    c = np.concatenate((cols, rows, np.arange(n)))
    off = r != c
    a = sp.csc_matrix((np.where(off, 1.0, 0.0), (r, c)), shape=(n, n))
    a.setdiag(float(n))  # diagonally dominant: its factors exist
    return np.asarray(qdldl.Solver(a).factors()[2], dtype=np.int64)


class SparseLDL:
    """The ``L D L^T`` of the symmetric matrices of the pattern ``(rows, cols)`` (``n x n``;
    every entry once, either triangle; the diagonal included by the caller) in the order
    :func:`amd_order`: :meth:`factor` of the entries' values in that pattern's order, then
    :meth:`solve`."""

    def __init__(self, n, rows, cols):
        self.n = n
        perm = amd_order(n, rows, cols)
        pinv = np.empty(n, np.int64)
        pinv[perm] = np.arange(n)
        pr, pc = pinv[rows], pinv[cols]
        r, c = np.minimum(pr, pc), np.maximum(pr, pc)
        keys = c.astype(np.int64) * n + r
        uniq, inv = np.unique(keys, return_inverse=True)
        self.ai = (uniq % n).astype(np.uint32)
        self.ap = np.searchsorted(uniq // n, np.arange(n + 1)).astype(np.int64)
        self.pos = inv.astype(np.int64)
        self.ax = np.zeros(uniq.size)
        self.perm = perm
        self.parent = np.empty(n, np.int64)
        lnz = np.empty(n, np.int64)
        nl = etree(n, self.ap, self.ai, lnz, self.parent)
        # the trailing columns of L that are (nearly) full: factored dense (the memory's
        # rows couple every velocity node: their clique ends the minimum-degree order)
        full = lnz >= DENSE * (n - 1 - np.arange(n))
        s = n
        while s > 0 and full[s - 1]:
            s -= 1
        self.s = s if n - s >= DENSE_MIN else n
        self.sm = np.zeros((n - self.s, n - self.s))
        self.ipiv = np.zeros(n - self.s, np.int32)
        self.lwork = max(1, int(dsytrf_lwork(n - self.s, lower=1)[0])) if self.s < n else 1
        self.lp = np.zeros(n + 1, np.int64)
        self.lp[1:] = np.cumsum(lnz)
        self.li, self.lx = np.empty(nl, np.uint32), np.empty(nl)
        self.d, self.dinv, self.nxt = np.empty(n), np.empty(n), np.empty(n, np.int64)
        self.ok = False

    def factor(self, values, maxneg):
        """Factor the values ``values`` (the pattern's order); the positive pivots' number,
        or -1 (a zero pivot), -2 (more than ``maxneg`` negative ones)."""
        scatter(self.pos, values, self.ax)
        s = self.s
        out = factor(s, self.ap, self.ai, self.ax, self.parent, self.lp, self.li,
                     self.lx, self.d, self.dinv, maxneg, self.nxt)
        if out >= 0 and s < self.n:
            tail(s, self.n, self.ap, self.ai, self.ax, self.parent, self.lp, self.li,
                 self.lx, self.dinv, self.sm, self.nxt)
            # the Schur complement (its upper triangle in sm, C order: the lower one of
            # sm.T, Fortran's) by LAPACK's Bunch-Kaufman L D L^T in place
            fac, self.ipiv, info = dsytrf(self.sm.T, lower=1, lwork=self.lwork,
                                          overwrite_a=1)
            npos, nneg = (-1, 0) if info != 0 else inertia(fac, self.ipiv)
            if npos < 0:
                out = -1
            elif nneg > maxneg - (s - out):
                out = -2
            else:
                out += npos
        self.ok = out >= 0
        return out

    def solve(self, b):
        n, s = self.n, self.s
        x, out = np.empty(n), np.empty(n)
        solve_lower(n, s, self.lp, self.li, self.lx, self.dinv, self.perm,
                    np.ascontiguousarray(b, dtype=float), x)
        if s < n:
            x[s:], _ = dsytrs(self.sm.T, self.ipiv, x[s:], lower=1, overwrite_b=1)
        solve_upper(n, s, self.lp, self.li, self.lx, self.perm, x, out)
        return out


@nb.njit(cache=True)
def tail(s, n, ap, ai, ax, parent, lp, li, lx, dinv, sm, nxt):
    """The rows ``s..n-1`` of ``L`` in the columns before ``s`` (after :func:`factor` of
    the first ``s``, ``nxt`` its), and the Schur complement of the first ``s`` rows and
    columns into the dense ``sm`` (its upper triangle): the up-looking rows, the updates of
    the trailing rows gathered in ``sm``."""
    m = n - s
    mark = np.zeros(s, np.bool_)
    yv = np.zeros(s)
    yi = np.empty(s, np.uint32)
    eb = np.empty(s, np.uint32)
    top = nxt[:s].copy()  # the end of every column's rows before s
    low = np.zeros((m, m))  # the complement's lower triangle, row by row
    for k in range(s, n):
        ny = 0
        kk = k - s
        for q in range(ap[k], ap[k + 1]):
            b = ai[q]
            if b >= s:
                low[kk, b - s] = ax[q]
                continue
            yv[b] = ax[q]
            ny = _reach(b, s, parent, mark, eb, yi, ny)
        for t in range(ny - 1, -1, -1):
            c = yi[t]
            e = nxt[c]
            yc = yv[c]
            j0 = lp[c]
            for j in range(top[c] - j0):
                yv[li[j0 + j]] -= lx[j0 + j] * yc
            j0 = top[c]
            for j in range(e - j0):
                low[kk, li[j0 + j] - s] -= lx[j0 + j] * yc
            li[e] = k
            lx[e] = yc * dinv[c]
            low[kk, kk] -= yc * lx[e]
            nxt[c] = e + 1
            yv[c] = 0.0
            mark[c] = False
    for i in range(m):
        for j in range(i, m):
            sm[i, j] = low[j, i]
