r"""Compiled (numba) solves with the square Jacobian ``J_d`` of the hull's collocation NLP
(:mod:`._hull_collocation_ipm`: the equality rows in the unknowns other than the torques),
by its structure: the collocation integrates the plant forward in time.

Each interval's 28 rows hold its 28 own unknowns (the states of its midpoint and end, its
three accelerations: the block ``D_i``), the state at its start (the previous interval's
end: ``E_i``) and the memory at the nodes its points lie between (``B_i``, constant); the
memory's rows hold their node's memory and the velocities at the nodes up to theirs
(``-W / tu``, constant, lower triangular). A node's memory is used by the points on either
side of it, before its own velocity is known, so the intervals and nodes are solved in
groups (3 intervals and 2 nodes on the default grid): the group's intervals forward
(``D_i`` by LU with partial pivoting) with its own nodes' memory set to zero, then the
nodes' memory from their rows (the small system ``S_g``, the group's response to its own
nodes precomputed once a factorization), then the intervals corrected. The transposed
solve runs the same groups backwards. A torque's column of ``J_u`` is zero before its
sample, so its solve starts at its sample's group (``first``).
"""

from __future__ import annotations

import numba as nb
import numpy as np

from .._jit import announce_compiles

announce_compiles()  # log a first-use compile (parapend._jit)

#: nodes of the memory an interval's points use, at most
NB = 3


@nb.njit(cache=True)
def _lu(a, piv):
    """LU with partial pivoting of the square ``a`` in place; False where singular."""
    n = a.shape[0]
    for k in range(n):
        p = k
        big = abs(a[k, k])
        for i in range(k + 1, n):
            if abs(a[i, k]) > big:
                big = abs(a[i, k])
                p = i
        piv[k] = p
        if big == 0.0 or not np.isfinite(big):
            return False
        if p != k:
            for j in range(n):
                t = a[k, j]
                a[k, j] = a[p, j]
                a[p, j] = t
        inv = 1.0 / a[k, k]
        for i in range(k + 1, n):
            a[i, k] *= inv
            f = a[i, k]
            if f != 0.0:
                for j in range(k + 1, n):
                    a[i, j] -= f * a[k, j]
    return True


@nb.njit(cache=True)
def _lu_solve(a, piv, b):
    """``b`` (n, m) overwritten by ``A^-1 b`` (``a``, ``piv`` from :func:`_lu`)."""
    n, m = b.shape
    for k in range(n):
        p = piv[k]
        if p != k:
            for j in range(m):
                t = b[k, j]
                b[k, j] = b[p, j]
                b[p, j] = t
    for i in range(n):
        for k in range(i):
            f = a[i, k]
            if f != 0.0:
                for j in range(m):
                    b[i, j] -= f * b[k, j]
    for i in range(n - 1, -1, -1):
        for k in range(i + 1, n):
            f = a[i, k]
            if f != 0.0:
                for j in range(m):
                    b[i, j] -= f * b[k, j]
        inv = 1.0 / a[i, i]
        for j in range(m):
            b[i, j] *= inv


@nb.njit(cache=True)
def _lu_solve_t(a, piv, b):
    """``b`` (n, m) overwritten by ``A^-T b``."""
    n, m = b.shape
    for i in range(n):  # U^T
        for k in range(i):
            f = a[k, i]
            if f != 0.0:
                for j in range(m):
                    b[i, j] -= f * b[k, j]
        inv = 1.0 / a[i, i]
        for j in range(m):
            b[i, j] *= inv
    for i in range(n - 1, -1, -1):  # L^T (unit)
        for k in range(i + 1, n):
            f = a[k, i]
            if f != 0.0:
                for j in range(m):
                    b[i, j] -= f * b[k, j]
    for k in range(n - 1, -1, -1):
        p = piv[k]
        if p != k:
            for j in range(m):
                t = b[k, j]
                b[k, j] = b[p, j]
                b[p, j] = t


@nb.njit(cache=True)
def scatter(data, kind, blk, r, c, dmat, emat, bmat):
    """The blocks ``D``, ``E``, ``B`` (zeroed) from ``J_d``'s CSC data by the map of every
    entry (``kind`` 1, 2, 3; 0: a memory row's, constant)."""
    dmat[:] = 0.0
    emat[:] = 0.0
    bmat[:] = 0.0
    for t in range(data.size):
        k = kind[t]
        if k == 1:
            dmat[blk[t], r[t], c[t]] += data[t]
        elif k == 2:
            emat[blk[t], r[t], c[t]] += data[t]
        elif k == 3:
            bmat[blk[t], r[t], c[t]] += data[t]


@nb.njit(cache=True)
def _group_forward(g, gi, gq, lc, pc, bq, vnode, dmat, piv, emat, bmat, rin, out, m):
    """The group ``g``'s intervals forward on the columns ``0..m``: the rows' right sides
    ``rin`` (rows' order), the earlier unknowns read from ``out`` (unknowns' order), the
    group's own nodes' memory taken as zero; the intervals' unknowns written to ``out``."""
    qa = gq[g]
    t = np.empty((28, m))
    for iv in range(gi[g], gi[g + 1]):
        for a in range(28):
            for j in range(m):
                t[a, j] = rin[28 * iv + a, j]
        if pc[iv, 0] >= 0:
            for b in range(8):
                cb = pc[iv, b]
                for a in range(28):
                    f = emat[iv, a, b]
                    if f != 0.0:
                        for j in range(m):
                            t[a, j] -= f * out[cb, j]
        for q in range(NB):
            node = bq[iv] + q
            if node >= qa or node >= vnode.shape[0]:
                continue
            for d in range(3):
                cb = vnode[node, 3 + d]
                for a in range(28):
                    f = bmat[iv, a, 3 * q + d]
                    if f != 0.0:
                        for j in range(m):
                            t[a, j] -= f * out[cb, j]
        _lu_solve(dmat[iv], piv[iv], t)
        for a in range(28):
            ca = lc[iv, a]
            for j in range(m):
                out[ca, j] = t[a, j]


@nb.njit(cache=True)
def factor(gi, gq, lc, pc, bq, vnode, wmat, tu, dmat, piv, emat, bmat, sz, sg, sgp, tz, tg,
           tgp, nd):
    """LU of every ``D_i``; every group's response ``sz`` of its intervals' unknowns to its
    own nodes' memory and its nodes' system ``S_g`` (LU in ``sg``), and the same for the
    transposed solve (``tz``, ``tg``). False where a block is singular."""
    ni = dmat.shape[0]
    for iv in range(ni):
        if not _lu(dmat[iv], piv[iv]):
            return False
    ng = gi.size - 1
    maxq = sz.shape[2]
    rin = np.zeros((nd, maxq))
    out = np.zeros((nd, maxq))
    ys = np.zeros((nd, maxq))
    for g in range(ng):
        qa, qb = gq[g], gq[g + 1]
        nq = 3 * (qb - qa)
        i0, i1 = gi[g], gi[g + 1]
        # forward: the rows' right side -B_i e_k (a unit memory at an own node moved over)
        for iv in range(i0, i1):
            for q in range(NB):
                node = bq[iv] + q
                if node < qa or node >= qb:
                    continue
                for d in range(3):
                    k = 3 * (node - qa) + d
                    for a in range(28):
                        rin[28 * iv + a, k] -= bmat[iv, a, 3 * q + d]
        _group_forward(g, gi, gq, lc, pc, bq, vnode, dmat, piv, emat, bmat, rin, out, nq)
        for iv in range(i0, i1):
            for a in range(28):
                for k in range(nq):
                    sz[iv, a, k] = out[lc[iv, a], k]
                    rin[28 * iv + a, k] = 0.0
        # S_g = I - W_QQ / tu times the own velocities' response
        for k in range(nq):
            for c in range(nq):
                sg[g, k, c] = 1.0 if k == c else 0.0
        for k in range(nq):
            q, d = qa + k // 3, k % 3
            for i in range(qa, q + 1):
                if vnode[i, 0] < 0:
                    continue
                for e in range(3):
                    w = wmat[3 * q + d, 3 * i + e] / tu
                    if w != 0.0:
                        cv = vnode[i, 0] + e
                        for c in range(nq):
                            sg[g, k, c] -= w * out[cv, c]
        for iv in range(i0, i1):  # (the next group reads these as its earlier unknowns)
            for a in range(28):
                for k in range(nq):
                    out[lc[iv, a], k] = 0.0
        if not _lu(sg[g, :nq, :nq], sgp[g, :nq]):
            return False
        # transposed: the response of the intervals' multipliers to unit own memory rows'
        _group_backward(g, gi, gq, lc, pc, bq, vnode, wmat, tu, dmat, piv, emat, ys, nq, True)
        for iv in range(i0, i1):
            for a in range(28):
                for k in range(nq):
                    tz[iv, a, k] = ys[28 * iv + a, k]
                    ys[28 * iv + a, k] = 0.0
        for k in range(nq):
            for c in range(nq):
                tg[g, k, c] = 1.0 if k == c else 0.0
        for iv in range(i0, i1):
            for q in range(NB):
                node = bq[iv] + q
                if node < qa or node >= qb:
                    continue
                for d in range(3):
                    k = 3 * (node - qa) + d
                    for a in range(28):
                        f = bmat[iv, a, 3 * q + d]
                        if f != 0.0:
                            for c in range(nq):
                                tg[g, k, c] += f * tz[iv, a, c]
        if not _lu(tg[g, :nq, :nq], tgp[g, :nq]):
            return False
    return True


@nb.njit(cache=True)
def forward(gi, gq, lc, pc, bq, vnode, wmat, tu, dmat, piv, emat, bmat, sz, sg, sgp, rin,
            active, nloc):
    """``J_d^-1 rin`` (rin (nd, m) in the rows' order; the result in the unknowns' order);
    on group ``g`` only the columns ``0..active[g]`` (the later ones zero there)."""
    nd, m = rin.shape
    ng = gi.size - 1
    out = np.zeros((nd, m))
    for g in range(ng):
        ma = active[g]
        if ma == 0:
            continue
        qa, qb = gq[g], gq[g + 1]
        nq = 3 * (qb - qa)
        _group_forward(g, gi, gq, lc, pc, bq, vnode, dmat, piv, emat, bmat, rin, out, ma)
        # the nodes' memory: rows  mu_q - sum_(i <= q) W_qi v_i / tu = r_q
        rm = np.empty((nq, ma))
        for k in range(nq):
            q, d = qa + k // 3, k % 3
            for j in range(ma):
                rm[k, j] = rin[nloc + 3 * qa + k, j]
            for i in range(0, q + 1):
                if vnode[i, 0] < 0:
                    continue
                for e in range(3):
                    w = wmat[3 * q + d, 3 * i + e] / tu
                    if w != 0.0:
                        cv = vnode[i, 0] + e
                        for j in range(ma):
                            rm[k, j] += w * out[cv, j]
        _lu_solve(sg[g, :nq, :nq], sgp[g, :nq], rm)
        for k in range(nq):
            cm = vnode[qa + k // 3, 3 + k % 3]
            for j in range(ma):
                out[cm, j] = rm[k, j]
        for iv in range(gi[g], gi[g + 1]):
            for a in range(28):
                ca = lc[iv, a]
                for k in range(nq):
                    f = sz[iv, a, k]
                    if f != 0.0:
                        for j in range(ma):
                            out[ca, j] += f * rm[k, j]
    return out


@nb.njit(cache=True)
def _group_backward(g, gi, gq, lc, pc, bq, vnode, wmat, tu, dmat, piv, emat, y, m, unit):
    """The transposed solve's intervals of group ``g`` backwards on ``y`` (nd, m): with
    ``unit`` the response to a unit multiplier of each own memory row (column ``k``; the
    rest of the right side zero), else ``y`` holds at ``28 i + a`` the right side of the
    interval's unknown ``a`` (less what later groups contribute); overwritten by the
    multipliers of the intervals' rows (rows' order)."""
    qa = gq[g]
    t = np.empty((28, m))
    for iv in range(gi[g + 1] - 1, gi[g] - 1, -1):
        for a in range(28):
            for j in range(m):
                t[a, j] = 0.0 if unit else y[28 * iv + a, j]
        if iv + 1 < gi[g + 1]:  # the next interval's E^T y, within the group
            for b in range(8):
                for r in range(28):
                    f = emat[iv + 1, r, b]
                    if f != 0.0:
                        for j in range(m):
                            t[8 + b, j] -= f * y[28 * (iv + 1) + r, j]
        if unit:  # the own memory rows' unit multipliers on the velocities at their nodes
            for k in range(m):
                q, d = qa + k // 3, k % 3
                for i in range(qa, q + 1):
                    if vnode[i, 1] != iv:
                        continue
                    for e in range(3):
                        t[vnode[i, 2] + e, k] += wmat[3 * q + d, 3 * i + e] / tu
        _lu_solve_t(dmat[iv], piv[iv], t)
        for a in range(28):
            for j in range(m):
                y[28 * iv + a, j] = t[a, j]


@nb.njit(cache=True)
def backward(gi, gq, lc, pc, bq, vnode, wmat, tu, dmat, piv, emat, bmat, tz, tg, tgp, rhs,
             nloc):
    """``J_d^-T rhs`` (rhs in the unknowns' order, the result in the rows' order)."""
    nd = rhs.size
    ng = gi.size - 1
    ni = pc.shape[0]
    ncp = vnode.shape[0]
    y = np.zeros((nd, 1))
    part = np.zeros((nd, 1))  # (only the group's rows are used)
    for g in range(ng - 1, -1, -1):
        qa, qb = gq[g], gq[g + 1]
        nq = 3 * (qb - qa)
        i0, i1 = gi[g], gi[g + 1]
        for iv in range(i0, i1):
            for a in range(28):
                part[28 * iv + a, 0] = rhs[lc[iv, a]]
        if i1 < ni:  # the next group's first interval: E^T y
            for b in range(8):
                for r in range(28):
                    f = emat[i1, r, b]
                    if f != 0.0:
                        part[28 * (i1 - 1) + 8 + b, 0] -= f * y[28 * i1 + r, 0]
        for i in range(qa, qb):  # the later nodes' memory rows on the velocities here
            if vnode[i, 0] < 0:
                continue
            iv = vnode[i, 1]
            for e in range(3):
                s = 0.0
                for q in range(qb, ncp):
                    for d in range(3):
                        s += wmat[3 * q + d, 3 * i + e] * y[nloc + 3 * q + d, 0]
                part[28 * iv + vnode[i, 2] + e, 0] += s / tu
        _group_backward(g, gi, gq, lc, pc, bq, vnode, wmat, tu, dmat, piv, emat, part, 1,
                        False)
        # the own nodes' memory columns: its row's multiplier + sum_i B_i^T y_i = rhs
        rm = np.empty((nq, 1))
        for k in range(nq):
            rm[k, 0] = rhs[vnode[qa + k // 3, 3 + k % 3]]
        for iv in range(i0, min(i1 + NB, ni)):
            for q in range(NB):
                node = bq[iv] + q
                if node < qa or node >= qb:
                    continue
                for d in range(3):
                    k = 3 * (node - qa) + d
                    for a in range(28):
                        f = bmat[iv, a, 3 * q + d]
                        if f != 0.0:
                            rm[k, 0] -= f * (part[28 * iv + a, 0] if iv < i1
                                             else y[28 * iv + a, 0])
        _lu_solve(tg[g, :nq, :nq], tgp[g, :nq], rm)
        for k in range(nq):
            y[nloc + 3 * qa + k, 0] = rm[k, 0]
        for iv in range(i0, i1):
            for a in range(28):
                v = part[28 * iv + a, 0]
                for k in range(nq):
                    v += tz[iv, a, k] * rm[k, 0]
                y[28 * iv + a, 0] = v
    return y[:, 0]


class Structured:
    """The structure of ``J_d`` of :class:`._hull_collocation_ipm.CompiledSolver` ``sv``
    (module docstring) and its solves: :meth:`factor` from the Jacobian's CSC data, then
    :meth:`solve` and :meth:`solve_t`."""

    def __init__(self, sv):
        prob = sv.prob
        ni, st, ncp = sv.ni, prob.stride, sv.ncp
        cmap, nx, mo = sv.cmap, sv.nx, sv.mo
        self.nloc, self.nd, self.tu = sv.nloc, sv.nd, float(prob.tu)
        self.wmat = np.ascontiguousarray(sv.wmat)
        lc = np.empty((ni, 28), np.int64)
        for iv in range(ni):
            lc[iv, :8] = cmap[8 * (2 * iv + 1) + np.arange(8)]
            lc[iv, 8:16] = cmap[8 * (2 * iv + 2) + np.arange(8)]
            lc[iv, 16:] = cmap[nx + 4 * 3 * iv + np.arange(12)]
        pc = np.full((ni, 8), -1, np.int64)
        pc[1:] = lc[:-1, 8:16]
        bq = (2 * np.arange(ni)) // st
        vnode = np.full((ncp, 6), -1, np.int64)
        for q in range(ncp):
            vnode[q, 3:] = cmap[mo + 3 * q + np.arange(3)]
            if q:
                p = st * q
                iv = (p - 1) // 2
                vnode[q, :3] = cmap[8 * p + 4], iv, (0 if p == 2 * iv + 1 else 8) + 4

        def top(iv):
            return max(p // st + (1 if p % st else 0) for p in (2 * iv, 2 * iv + 1, 2 * iv + 2))

        def owner(q):
            return (st * q - 1) // 2 if q else -1

        gi, gq = [0], [0]
        while gi[-1] < ni:
            i0 = gi[-1]
            i1 = i0 + 1
            while owner(max(top(iv) for iv in range(i0, i1))) >= i1:
                i1 = owner(max(top(iv) for iv in range(i0, i1))) + 1
            gi.append(i1)
            gq.append(sum(1 for q in range(ncp) if owner(q) < i1))
        assert gq[-1] == ncp
        self.gi, self.gq = np.array(gi, np.int64), np.array(gq, np.int64)
        self.lc, self.pc, self.bq, self.vnode = lc, pc, bq, vnode
        group_of = np.searchsorted(self.gi, np.arange(ni), side="right") - 1
        self.group_of = group_of
        ng = len(gi) - 1
        maxq = int(3 * np.max(np.diff(self.gq)))
        self.ng, self.maxq = ng, maxq
        # the map of J_d's CSC entries onto the blocks
        where = {}
        for iv in range(ni):
            for a in range(28):
                where[int(lc[iv, a])] = (iv, a)
        node_of = {int(vnode[q, 3 + d]): (q, d) for q in range(ncp) for d in range(3)}
        nnz = int(sv.jptr[self.nd])
        kind = np.zeros(nnz, np.int64)
        blk, rr, cc = (np.zeros(nnz, np.int64) for _ in range(3))
        cols = np.repeat(np.arange(self.nd), np.diff(sv.jptr[:self.nd + 1]))
        for t in range(nnz):
            row, col = int(sv.jind[t]), int(cols[t])
            if row >= self.nloc:
                continue
            iv, a = divmod(row, 28)
            if col in where and where[col][0] == iv:
                kind[t], cc[t] = 1, where[col][1]
            elif col in where and where[col][0] == iv - 1 and 8 <= where[col][1] < 16:
                kind[t], cc[t] = 2, where[col][1] - 8
            elif col in node_of and 0 <= node_of[col][0] - bq[iv] < NB:
                kind[t], cc[t] = 3, 3 * (node_of[col][0] - bq[iv]) + node_of[col][1]
            else:  # pragma: no cover - the kernel's pattern
                raise AssertionError(f"J_d entry ({row}, {col}) outside its blocks")
            blk[t], rr[t] = iv, a
        self.map = (kind, blk, rr, cc)
        self.nnz = nnz
        self.dmat = np.zeros((ni, 28, 28))
        self.emat = np.zeros((ni, 28, 8))
        self.bmat = np.zeros((ni, 28, 3 * NB))
        self.piv = np.zeros((ni, 28), np.int64)
        self.sz, self.tz = np.zeros((ni, 28, maxq)), np.zeros((ni, 28, maxq))
        self.sg, self.tg = np.zeros((ng, maxq, maxq)), np.zeros((ng, maxq, maxq))
        self.sgp, self.tgp = np.zeros((ng, maxq), np.int64), np.zeros((ng, maxq), np.int64)
        self.one = np.ones(ng, np.int64)
        # a torque's column is zero before its sample's group
        first = group_of[np.arange(sv.n) * prob.intervals]
        self.active_u = np.array([int(np.sum(first <= g)) for g in range(ng)], np.int64)

    def _args(self):
        return (self.gi, self.gq, self.lc, self.pc, self.bq, self.vnode, self.wmat, self.tu,
                self.dmat, self.piv, self.emat, self.bmat)

    def factor(self, data):
        """From ``J_d``'s CSC data; False where singular."""
        scatter(data[:self.nnz], *self.map, self.dmat, self.emat, self.bmat)
        return bool(factor(*self._args(), self.sz, self.sg, self.sgp, self.tz, self.tg,
                           self.tgp, self.nd))

    def solve(self, rin, torques=False):
        """``J_d^-1 rin`` (rin (nd,) or (nd, m) in the rows' order; ``torques``: the columns
        of ``J_u``, zero before their samples)."""
        vec = rin.ndim == 1
        r2 = np.ascontiguousarray(rin[:, None] if vec else rin, dtype=float)
        act = self.active_u if torques else self.one * r2.shape[1]
        out = forward(*self._args(), self.sz, self.sg, self.sgp, r2, act, self.nloc)
        return out[:, 0] if vec else out

    def solve_t(self, rhs):
        """``J_d^-T rhs``."""
        return backward(*self._args(), self.tz, self.tg, self.tgp,
                        np.ascontiguousarray(rhs, dtype=float), self.nloc)
