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
#: the rows are factored in this many groups, run in parallel on numba's threads where the
#: machine has a core to spare (:func:`threads`; the factors and the outcome are the same
#: to the bit whatever the threads): the sparse rows by whole subtrees of the elimination
#: tree, the trailing (the Schur complement's) dealt in turn. On the default barge's
#: horizon (8694 rows, 371 trailing, three subtrees) 2 threads took a factorization from
#: 10.7 to 6.2 ms (median, idle machine)
THREADS = 2


def threads():
    """The threads the groups run on: numba's (``NUMBA_NUM_THREADS``, at most
    :data:`THREADS`) where the load average leaves a core idle beside this process, else
    one (a thread that waits for a busy core makes every parallel section wait: the
    power matrix's worker processes run one thread each)."""
    import os

    most = min(THREADS, nb.get_num_threads())
    try:
        load = os.getloadavg()[0]
    except OSError:  # pragma: no cover - no load average on this platform
        return 1
    return most if load < nb.config.NUMBA_NUM_THREADS - 0.5 else 1


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


@nb.njit(parallel=True, cache=True)
def factor(n, ap, ai, ax, parent, lp, li, lx, d, dinv, maxneg, nxt, optr, orows):
    """``L D L^T`` of the upper triangle ``(ap, ai, ax)`` into ``(lp, li, lx)`` (unit
    diagonal implied) and ``d``; returns the number of positive pivots, ``-1`` at a zero or
    non-finite pivot, ``-2`` past ``maxneg`` negative ones (the factors then partial).
    ``nxt``: every column's entries' end (out). The rows are factored in the groups
    ``orows[optr[g]:optr[g + 1]]`` (each a union of whole subtrees of the elimination tree,
    in increasing order: a row's solve reaches only its own subtree), the groups in
    parallel; a group stops at its own zero pivot or past ``maxneg`` negative ones of its
    own, and the outcome is then read in the rows' order, as one pass would have found it
    (every row before the first such event is factored: the factors and the outcome do not
    depend on the threads)."""
    mark = np.zeros(n, np.bool_)
    yv = np.zeros(n)
    for c in range(n):
        nxt[c] = lp[c]
    for g in nb.prange(optr.size - 1):
        yi = np.empty(n, np.uint32)
        eb = np.empty(n, np.uint32)
        neg = 0
        for r in range(optr[g], optr[g + 1]):
            k = orows[r]
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
                break
            if dk < 0.0:
                neg += 1
                if neg > maxneg:
                    break
            dinv[k] = 1.0 / dk
    npos = 0
    nneg = 0
    for k in range(n):
        dk = d[k]
        if dk == 0.0 or not np.isfinite(dk):
            return -1
        if dk > 0.0:
            npos += 1
        else:
            nneg += 1
            if nneg > maxneg:
                return -2
    return npos


def subtree_groups(s, parent, lnz, groups):
    """The rows ``0..s-1`` in at most ``groups`` groups of whole subtrees of the elimination
    tree (its part on those rows), balanced by their work (the sum of the squared column
    counts; the largest subtree first into the lightest group), each group's rows in
    increasing order: ``(optr, orows)``."""
    root = np.arange(s)
    for j in range(s - 1, -1, -1):  # (a parent comes after its children)
        if 0 <= parent[j] < s:
            root[j] = root[parent[j]]
    work = np.bincount(root, weights=lnz[:s].astype(float) ** 2, minlength=s)
    roots = np.flatnonzero(root == np.arange(s))
    load = np.zeros(max(1, min(groups, roots.size)))
    owner = np.empty(s, np.int64)
    for r in roots[np.argsort(-work[roots], kind="stable")]:
        owner[r] = g = int(np.argmin(load))
        load[g] += work[r]
    of_row = owner[root]
    orows = np.argsort(of_row, kind="stable").astype(np.int64)
    optr = np.searchsorted(of_row[orows], np.arange(load.size + 1)).astype(np.int64)
    return optr, orows


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
        self.groups = THREADS
        self.optr, self.orows = subtree_groups(self.s, self.parent, lnz, self.groups)
        if self.s < n:  # the trailing rows' pattern, their entries' places (li set there)
            s, m = self.s, n - self.s
            self.top, self.tptr = np.empty(s, np.int64), np.empty(m + 1, np.int64)
            self.tcol, self.tpos = np.empty(nl, np.int64), np.empty(nl, np.int64)
            nt = tail_pattern(s, n, self.ap, self.ai, self.parent, self.lp, self.li,
                              self.top, self.tptr, self.tcol, self.tpos)
            self.tcol, self.tpos = self.tcol[:nt].copy(), self.tpos[:nt].copy()
            self.yval = np.empty(nt)
        self.ok = False

    def factor(self, values, maxneg):
        """Factor the values ``values`` (the pattern's order); the positive pivots' number,
        or -1 (a zero pivot), -2 (more than ``maxneg`` negative ones)."""
        scatter(self.pos, values, self.ax)
        s = self.s
        out = factor(s, self.ap, self.ai, self.ax, self.parent, self.lp, self.li,
                     self.lx, self.d, self.dinv, maxneg, self.nxt, self.optr, self.orows)
        if out >= 0 and s < self.n:
            low = np.zeros((self.n - s, self.n - s))
            tail_rows(s, self.n, self.ap, self.ai, self.ax, self.lp, self.li, self.lx,
                      self.dinv, self.top, self.tptr, self.tcol, self.tpos, self.yval, low,
                      self.groups)
            self.sm[...] = low.T  # (its lower triangle, sm's upper, is all LAPACK reads)
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
def tail_pattern(s, n, ap, ai, parent, lp, li, top, tptr, tcol, tpos):
    """The symbolic part of :func:`tail_rows`, once per pattern: every trailing row's
    columns before ``s`` in the order its up-looking solve visits them (``tcol[tptr[kk]:
    tptr[kk + 1]]``, row ``s + kk``), each entry's place in its column's storage
    (``tpos``, after the column's rows before ``s``, the rows in increasing order) with
    ``li`` set there, and ``top``: where every column's rows from ``s`` on start."""
    mark = np.zeros(s, np.bool_)
    yi = np.empty(s, np.uint32)
    eb = np.empty(s, np.uint32)
    cnt = np.zeros(s, np.int64)
    for k in range(s):  # the rows before s (as factor): every reached column an entry
        ny = 0
        for q in range(ap[k], ap[k + 1]):
            b = ai[q]
            if b != k:
                ny = _reach(b, k, parent, mark, eb, yi, ny)
        for t in range(ny):
            cnt[yi[t]] += 1
            mark[yi[t]] = False
    for c in range(s):
        top[c] = lp[c] + cnt[c]
    nt = 0
    tptr[0] = 0
    for k in range(s, n):
        ny = 0
        for q in range(ap[k], ap[k + 1]):
            b = ai[q]
            if b < s:
                ny = _reach(b, s, parent, mark, eb, yi, ny)
        for t in range(ny - 1, -1, -1):
            c = yi[t]
            e = lp[c] + cnt[c]
            cnt[c] += 1
            li[e] = k
            tcol[nt] = c
            tpos[nt] = e
            nt += 1
            mark[c] = False
        tptr[k - s + 1] = nt
    return nt


@nb.njit(parallel=True, cache=True)
def tail_rows(s, n, ap, ai, ax, lp, li, lx, dinv, top, tptr, tcol, tpos, yval, low,
              groups):
    """The rows ``s..n-1`` of ``L`` in the columns before ``s`` (after :func:`factor` of
    the first ``s``) and the Schur complement of the first ``s`` rows and columns into
    ``low`` (its lower triangle, zeroed by the caller): the up-looking rows along the
    pattern of :func:`tail_pattern`, then each row of the complement gathered from them.
    Every trailing row reads only the first ``s`` rows' factors (first pass) and the
    finished trailing rows (second pass), so they are dealt to ``groups`` groups run in
    parallel; each row's sums run in the same order whatever the threads (the factors are
    the same to the bit)."""
    m = n - s
    for th in nb.prange(groups):
        yv = np.zeros(s)
        for kk in range(th, m, groups):
            k = s + kk
            for q in range(ap[k], ap[k + 1]):
                b = ai[q]
                if b >= s:
                    low[kk, b - s] = ax[q]
                else:
                    yv[b] = ax[q]
            for t in range(tptr[kk], tptr[kk + 1]):
                c = tcol[t]
                yc = yv[c]
                j0 = lp[c]
                for j in range(top[c] - j0):  # (unsigned row indices: no wraparound checks)
                    yv[li[j0 + j]] -= lx[j0 + j] * yc
                yval[t] = yc
                lx[tpos[t]] = yc * dinv[c]
                yv[c] = 0.0
    for th in nb.prange(groups):
        for kk in range(th, m, groups):
            for t in range(tptr[kk], tptr[kk + 1]):
                c = tcol[t]
                yc = yval[t]
                e = tpos[t]
                j0 = top[c]
                for j in range(e - j0):
                    low[kk, li[j0 + j] - s] -= lx[j0 + j] * yc
                low[kk, kk] -= yc * lx[e]
