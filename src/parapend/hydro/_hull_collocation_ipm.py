r"""The compiled solver of the hull's collocation horizon problem (:mod:`._hull_collocation`):
a primal-dual interior point on the same NLP IPOPT solves (same unknowns, constraints,
objective and bounds), its functions and exact derivatives from
:mod:`._hull_collocation_kernel`, its Newton step by the problem's structure.

**Structure.** The start's state is fixed (its rows are left out), so the equality rows
(the local rows of every interval and the memory's rows) are as many as the unknowns other
than the ``n`` held torques, and their Jacobian ``J = [J_d, J_u]`` in those unknowns ``d``
is square: the collocation's implicit integration of the plant under given torques (its
memory causal). The Newton step of the barrier problem

    [K  J^T] [dx]   [-r]
    [J   0 ] [l+] = [-c],   K = W + Sigma_u + D^T Sigma_s D

(``W`` the Hessian of the Lagrangian, ``Sigma`` the barrier's primal-dual weights of the
torques' bounds and of the slacks ``s`` of the generator's speeds ``D x``) is taken, as
IPOPT takes it, from a factorization of that whole sparse KKT matrix (``STEP = "kkt"``):
its ``L D L^T`` in a minimum-degree order (:mod:`._hull_collocation_ldl`; the memory's
rows, which couple every velocity node, end the order as a dense clique of about 370 rows,
their Schur complement factored by LAPACK), the inertia counted from ``D``, corrected as IPOPT's
(:meth:`CompiledSolver._kkt`: ``delta_w I`` on ``K`` until it is ``(n, m, 0)``,
``delta_c`` where singular), a static regularization 1e-9 refined away (at most
``REFINE`` steps of iterative refinement). ``STEP = "nullspace"`` takes it in the null
space of ``J`` instead: ``dx = Y p + Q w`` with ``J_d p = -c``, ``Q = Z R^-1`` the
orthonormal basis of the span of ``Z = [-J_d^-1 J_u; I]`` (``R`` Householder's),
``(Q^T K Q) w = -Q^T (r + K Y p)`` (``n x n``, dense, Cholesky with ``delta I`` added
until it succeeds), then ``J_d^T l+ = -(r + K dx)_d``, the factors of ``J_d`` by its time
structure (:mod:`._hull_collocation_linalg`). That condenses the motion over the whole
horizon: the torques' sensitivities ``Z`` reach 1e8 where the pendulum's linearization is
unstable over it. On 25 horizons captured from a run of the power matrix's Hs 1 m, Te 8 s
bin (Tp 8.9 s: a 17.8 s horizon; started swinging, 40 iterations) it failed 11 and capped
4, the KKT step (its first inertia correction then grown by 100, as IPOPT's) failed 1 and
capped 1, IPOPT none; on the default sea's 12 s horizons both solved the same (the
null-space step 2.3 times faster a horizon, median). ``STEP = "auto"`` (the default)
chooses every iteration: the null-space step where the sensitivities ``Z`` are at most
``SENS_MAX`` (1e8: its basis then holds the reduced Hessian), the KKT step where they are
larger; on the 20 captured horizons of that bin it failed none (capped 5, as the KKT
step), and on the first 20 of the default sea's seeds 0 and 1 it took the null-space step
on 302 of 364 and 183 of 306 iterations (that bin's: 588 of 891).

**Method.** IPOPT's: the slacks ``D x - s = 0`` of the speed bounds, the fraction to the
boundary ``max(0.99, 1 - mu)``, IPOPT's filter line search with its second-order
corrections and its watchdog (full steps after 10 shortened ones in a row, kept where the
filter takes them within 3 iterations), a trial's infeasibility held within
``THETA_GROWTH`` times the iterate's, IPOPT's scaled optimality error for the end (``tol``,
its ``s_max`` 100, and its acceptable level: 1e-4 on 15 iterations in a row). The
barrier's weight ``mu`` adaptive as IPOPT's default (``MU_STRATEGY``): in its free mode
chosen every iteration by IPOPT's quality function (the centering ``sigma`` minimizing the
linearized optimality error after the step of ``sigma`` times the mean complementarity:
the affine and the centering steps on the same factors), while the optimality error falls
(below 0.9999 times one of the last 4 iterates'); where it does not, a monotone phase
from 0.8 times the mean complementarity (``mu`` falling as ``min(0.2 mu, mu^1.5)`` once its
problem is solved to ``10 mu``, Fiacco-McCormick) until its barrier problem is solved.
From a shifted solution only the unknowns are warm: the bounds' multipliers start at 1
and ``mu`` at ``MU_INIT`` (IPOPT's; from multipliers ``mu / distance`` at ``mu`` 1e-3 the
adaptive barrier failed more of the closed loop's horizons). The restoration phase: first
Newton's method on the equality rows for the unknowns but the torques (the collocation's
motion under the iterate's torques), and where that is not taken (the motion's
linearization unstable over the horizon, its steps grow along it), IPOPT's restoration
in Gauss-Newton form (:meth:`CompiledSolver._restore_min_norm`: least-norm steps onto the
linearized rows in all the unknowns, to a point the filter takes with the infeasibility
lowered by a tenth); also where the inertia correction reaches ``MAX_DELTA``.
Measured on the default barge's horizons and closed loops: docs/hull.md and
benchmarks/hull_collocation_solver.out.txt.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.linalg import LinAlgError, cho_factor, cho_solve

from . import _hull_collocation_kernel as kern
from ._hull_collocation_ldl import EPS, SparseLDL, threads
from ._hull_collocation_linalg import Structured

#: the barrier's first weight (IPOPT's ``mu_init``) cold and from a shifted solution (the
#: same: with 1e-3 and the bounds' multipliers ``mu`` over their distances the adaptive
#: barrier failed more of the closed loop's horizons than from IPOPT's multipliers 1)
MU_INIT = 0.1
MU_WARM = 0.1
#: the barrier's update: ``"adaptive"`` (IPOPT's free mode with Mehrotra's probing, a
#: monotone phase where the error does not fall) or ``"monotone"`` (Fiacco-McCormick)
MU_STRATEGY = "adaptive"
#: the adaptive barrier's oracle: ``"quality"`` (IPOPT's default: the quality function) or
#: ``"probing"`` (Mehrotra's)
MU_ORACLE = "quality"
#: the adaptive barrier's bound (times the first mean complementarity) and its progress
#: test: the optimality error below REF_RED times one of the last REFS iterates'
MU_MAX_FACT = 1e3
#: IPOPT's acceptable level: the error within ACCEPTABLE_TOL (the infeasibility and the
#: complementarity within 1e-2) on this many iterations in a row ends the solve as solved
#: (IPOPT's ``acceptable_tol`` of the planner's options and its ``acceptable_iter``)
ACCEPTABLE_TOL = 1e-4
ACCEPTABLE_ITER = 15
#: IPOPT's watchdog: after WATCHDOG_SHORT shortened steps in a row, full steps for up to
#: WATCHDOG_TRIALS iterations, kept where the filter takes one against the point before
#: them, else back to that point
WATCHDOG_SHORT = 10
WATCHDOG_TRIALS = 3
REF_RED = 0.9999
REFS = 4
#: a trial step's infeasibility at most this times the iterate's, or THETA_FLOOR (IPOPT's
#: filter alone let the null-space step's iterates wander far from feasibility on the hull's
#: nonconvex horizons; with the KKT step, without the bound, the Te 8 s bin's closed loop
#: realized 321.3 W perfect, 209.0 W AR with a failed solve, against 228.2 and 165.1 W with
#: none: a chaotic loop, the bound kept for the failed solve)
THETA_GROWTH = 10.0
THETA_FLOOR = 1e-3
#: the inertia correction's tries at most (``delta`` times 8 each), and its largest ``delta``
#: (IPOPT's ``max_hessian_perturbation``): past it the solve fails
MAX_CORRECTIONS = 40
MAX_DELTA = 1e20
#: the equality rows' multipliers estimated anew (least squares) where they exceed this (at
#: the default barge's optima they are 5 to 10; on the closed loop's hard horizons they ran
#: to 1e5 within a few shortened steps, and the inertia correction to its bound)
LAM_RESET = 1e3
#: where the Newton's method on the equality rows (the torques held) is not taken, IPOPT's
#: restoration phase by least-norm steps in all the unknowns (:meth:`_restore_min_norm`)
RESTORATION = True
#: the Newton step (module docstring): ``"kkt"`` (the whole KKT matrix's sparse ``L D
#: L^T``), ``"nullspace"`` (condensed on the torques: faster on short horizons, fails on
#: long ones) or ``"auto"``: every iteration the null-space step where the torques'
#: sensitivities are at most SENS_MAX, the KKT step where they are larger
STEP = "auto"
#: the largest torque sensitivity ``max |J_d^-1 J_u|`` (units of the unknowns per m g l)
#: with which ``STEP = "auto"`` takes the null-space step. On the default sea's first 20
#: horizons of seed 0 it rose from 1e3 to 1e10 as the pendulum swung up, the null-space
#: step solving them all; on the Te 8 s bin's 20 it failed 8, where it reached 1e10 to
#: 1e13 (it solved those that stayed below 5e7). With 1e6 or 1e8 the auto step failed
#: none of these 60, as the KKT step; with 1e10 one of the Te 8 s bin's
SENS_MAX = 1e8
#: iterative refinement's steps at most on the KKT matrix
REFINE = 5


def _csc_pattern(rows, cols, nrow, ncol):
    """The CSC pattern of the entries ``(rows, cols)`` (duplicates summed): ``(indices,
    indptr, inverse)``, ``inverse`` the data position of every entry."""
    keys = cols.astype(np.int64) * nrow + rows
    uniq, inv = np.unique(keys, return_inverse=True)
    c = uniq // nrow
    indptr = np.searchsorted(c, np.arange(ncol + 1))
    return (uniq % nrow).astype(np.int32), indptr.astype(np.int32), inv


class CompiledSolver:
    """The interior point (module docstring) of :class:`._hull_collocation.HullCollocation`
    ``prob``; :meth:`solve` from a start ``x0`` on the parameters ``par``."""

    def __init__(self, prob):
        pl = prob.plant
        self.prob = prob
        self.trace = None  # a list: every iteration's (it, f, primal, dual, compl, mu, ...)
        self.lin = None
        # the plant's model rolled under held torques (n,) -> a start (nvar,) on the solve's
        # parameters, or None (set by the problem for each solve: the last restoration's)
        self.rollout = None
        self.why = ""  # what ended the last failed solve (nonfinite, singular; inertia,
        # restore: neither restoration reached a point the filter takes)
        npt, ni, nx, na = prob._layout()
        n, ncp, st = prob.n, prob.ncp, prob.stride
        self.npt, self.ni, self.nx, self.na, self.n, self.ncp = npt, ni, nx, na, n, ncp
        self.nvar = nx + na + n + 3 * ncp
        self.uo, self.mo = nx + na, nx + na + n
        self.nloc = kern.ROWS * ni
        self.neq = self.nloc + 3 * ncp
        self.args = (npt, prob.intervals, st, n, prob.spacing,
                     np.ascontiguousarray(pl.mt, dtype=float),
                     np.ascontiguousarray(pl.cp, dtype=float),
                     np.ascontiguousarray(pl.gm, dtype=float),
                     np.asarray(pl.par, dtype=float), float(prob.tu))
        eg, em = prob.eta
        self.obj = (float(prob.kappa), 0.5 * (eg + 1.0 / em), 0.5 * (eg - 1.0 / em), 1e-3,
                    bool(prob.pendulum_only))
        # the memory's rows: x_mu - (past + W v) / tu, v the velocities at the nodes
        self.wmat = prob._weight_matrix()
        self.vidx = (8 * st * np.arange(ncp)[:, None] + 4 + np.arange(3)).ravel()
        # the unknowns: the start's state fixed; the others d, then the torques
        free = np.arange(8, self.nvar)
        isu = (free >= self.uo) & (free < self.mo)
        self.dep, self.uix = free[~isu], free[isu]
        self.nd = self.dep.size
        assert self.nd == self.neq
        cmap = np.full(self.nvar, -1, np.int64)
        cmap[self.dep] = np.arange(self.nd)
        cmap[self.uix] = self.nd + np.arange(n)
        self.cmap = cmap
        nf = self.nd + n
        self.nf = nf
        # the speeds' rows D (on the reduced columns) and their bounds
        vmax = prob.max_turn / pl.h if prob.max_turn else np.inf
        self.vmax = vmax
        ks = np.arange(1, npt)
        self.speed = np.isfinite(vmax)
        self.d7, self.d6 = cmap[8 * ks + 7], cmap[8 * ks + 6]
        self.umax = float(prob.torque_limit)
        # the patterns: the kernel's entries at any point (its order is fixed)
        x = np.zeros(self.nvar)
        f, jr, jc, jv, hr, hc, hv = self._eval(x, np.zeros(self.nloc), 2, np.zeros((npt, 3)),
                                               0.0, raw=True)
        wr, wc = np.nonzero(self.wmat)
        mr = np.concatenate((self.nloc + np.arange(3 * ncp), self.nloc + wr))
        mc = np.concatenate((self.mo + np.arange(3 * ncp), self.vidx[wc]))
        mv = np.concatenate((np.ones(3 * ncp), -self.wmat[wr, wc] / prob.tu))
        fixed = cmap[mc] < 0  # the start's velocities: known
        mr, mc, self.mem_val = mr[~fixed], mc[~fixed], mv[~fixed]
        keep = cmap[jc] >= 0
        self.jkeep = keep
        rows = np.concatenate((jr[keep], mr))
        cols = np.concatenate((cmap[jc[keep]], cmap[mc]))
        self.jind, self.jptr, inv = _csc_pattern(rows, cols, self.neq, nf)
        self.jinv_var, self.jinv_mem = inv[:keep.sum()], inv[keep.sum():]
        self.jnnz = self.jind.size
        self.jmem = np.bincount(self.jinv_mem, weights=self.mem_val, minlength=self.jnnz)
        # J_u's entries (the last n columns of the CSC pattern)
        self.ju_rows = self.jind[self.jptr[self.nd]:]
        self.ju_cols = np.repeat(np.arange(n), np.diff(self.jptr[self.nd:]))
        hkeep = (cmap[hr] >= 0) & (cmap[hc] >= 0)
        self.hkeep = hkeep
        # K lives on the rows with more than the diagonal (the Hessian's, the speeds', the
        # torques'): compressed to those
        self.krows = np.unique(np.concatenate((cmap[hr[hkeep]], self.d7, self.d6,
                                               self.nd + np.arange(n))))
        nr = self.krows.size
        kpos = np.full(nf, -1, np.int64)
        kpos[self.krows] = np.arange(nr)
        diag = np.arange(nr)
        kr = np.concatenate((kpos[cmap[hr[hkeep]]], diag, kpos[self.d7], kpos[self.d6],
                             kpos[self.d7], kpos[self.d6]))
        kc = np.concatenate((kpos[cmap[hc[hkeep]]], diag, kpos[self.d7], kpos[self.d6],
                             kpos[self.d6], kpos[self.d7]))
        self.kind, self.kptr, kinv = _csc_pattern(kr, kc, nr, nr)
        nh = hkeep.sum()
        self.kinv_h, self.kinv_d = kinv[:nh], kinv[nh:nh + nr]
        self.kinv_s = kinv[nh + nr:]
        self.knnz = self.kind.size
        self.kpos = kpos
        # the whole KKT matrix's pattern (its upper triangle of K, J, the diagonal) and
        # the K entries of it (kmat's data order)
        kcol = np.repeat(np.arange(nr), np.diff(self.kptr))
        self.kkt_ksel = self.kind <= kcol
        jcol = np.repeat(np.arange(nf), np.diff(self.jptr))
        ntot = nf + self.neq
        self.kkt_rows = np.concatenate((self.krows[self.kind[self.kkt_ksel]],
                                        nf + self.jind.astype(np.int64), np.arange(ntot)))
        self.kkt_cols = np.concatenate((self.krows[kcol[self.kkt_ksel]], jcol,
                                        np.arange(ntot)))
        self.ldl = None
        self.threads = None

    # -- the functions --------------------------------------------------------------------
    def _eval(self, x, lam, order, fk, e0, raw=False):
        ni, n = self.ni, self.n
        cons = np.empty(self.nloc)
        grad = np.empty(self.nvar)
        nj = kern.JAC * ni if order >= 1 else 0
        nh = kern.HESS * 3 * ni + 25 * n + 64 if order >= 2 else 0
        jr, jc, jv = np.empty(nj, np.int64), np.empty(nj, np.int64), np.empty(nj)
        hr, hc, hv = np.empty(nh, np.int64), np.empty(nh, np.int64), np.empty(nh)
        f, jn, hn = kern.evaluate(x, lam, order, *self.args, fk, *self.obj, e0, cons, grad,
                                  jr, jc, jv, hr, hc, hv)
        if raw:
            return f, jr[:jn], jc[:jn], jv[:jn], hr[:hn], hc[:hn], hv[:hn]
        mem = x[self.mo:] - (self.past + self.wmat @ x[self.vidx]) / self.tu
        c = np.concatenate((cons, mem))
        return f, c, grad, jv[:jn], hr, hv[:hn]

    def _values(self, x):
        """Objective, equality rows and the speeds at ``x``."""
        f, c, _, _, _, _ = self._eval(x, self._nolam, 0, self.fk, self.e0)
        return f, c, x[8 * np.arange(1, self.npt) + 7] - x[8 * np.arange(1, self.npt) + 6]

    def jacobian(self, jv):
        data = np.bincount(self.jinv_var, weights=jv[self.jkeep], minlength=self.jnnz)
        data += self.jmem
        return sp.csc_matrix((data, self.jind, self.jptr), shape=(self.neq, self.nf))

    def hessian(self, hv, diag):
        """``K`` on its rows ``krows`` (its others are zero): the Lagrangian's Hessian ``hv``
        plus ``diag`` (nf,) on the diagonal and the speeds' weights (``self.sig_s``)."""
        data = np.bincount(self.kinv_h, weights=hv[self.hkeep], minlength=self.knnz)
        data += np.bincount(self.kinv_d, weights=diag[self.krows], minlength=self.knnz)
        if self.speed:
            ss = self.sig_s
            data += np.bincount(self.kinv_s, weights=np.concatenate((ss, ss, -ss, -ss)),
                                minlength=self.knnz)
        nr = self.krows.size
        return sp.csc_matrix((data, self.kind, self.kptr), shape=(nr, nr))

    # -- one solve --------------------------------------------------------------------------
    def _setup(self, par):
        npt, ncp = self.npt, self.ncp
        self.tu = float(self.prob.tu)
        self.past = par[8:8 + 3 * ncp]
        self.fk = np.ascontiguousarray(par[8 + 3 * ncp:].reshape(npt, 3))
        self.e0 = kern._energy(np.ascontiguousarray(par[:8], dtype=float), 0, *self.args[5:9],
                               self.obj[4], np.empty(8), np.empty((8, 8)))
        self._nolam = np.zeros(self.nloc)

    def _speeds(self, x):
        ks = np.arange(1, self.npt)
        return x[8 * ks + 7] - x[8 * ks + 6]

    def _barrier(self, f, x, s, mu):
        """The barrier function ``phi_mu`` at ``(x, s)``."""
        u = x[self.uo:self.uo + self.n]
        out = f - mu * _logs(u + self.umax, self.umax - u)
        if self.speed:
            out -= mu * _logs(s + self.vmax, self.vmax - s)
        return out

    def _theta(self, c, x, s):
        return float(np.sum(np.abs(c)) + (np.sum(np.abs(self._speeds(x) - s))
                                          if self.speed else 0.0))

    def solve(self, x0, par, max_iter, tol, warm=False, strategy=None):
        """The interior point from ``x0`` (its start's state is ``par``'s) on the parameters
        ``par`` (:meth:`._hull_collocation.HullCollocation._params`). Returns ``(x, f,
        status, iterations)``: status 0 solved to ``tol``, 1 stopped at ``max_iter``, 2
        failed (a singular step or a line search that found no acceptable point). One BLAS
        thread (its small products: a second thread waiting on a busy core cost 5 times); the
        compiled factorizations' parallel sections on the threads of
        :func:`._hull_collocation_ldl.threads` (chosen once per solver from the load: the
        numbers do not depend on them)."""
        import numba

        from .control import _blas_controller

        if self.threads is None:
            self.threads = threads()
        before = numba.get_num_threads()
        numba.set_num_threads(min(before, self.threads))
        try:
            with _blas_controller().limit(limits=1, user_api="blas"):
                return self._solve(x0, par, max_iter, tol, MU_WARM if warm else MU_INIT,
                                   THETA_GROWTH, MU_STRATEGY if strategy is None
                                   else strategy)
        finally:
            numba.set_num_threads(before)

    def _solve(self, x0, par, max_iter, tol, mu, growth, strategy):
        npt, n, nd, nf = self.npt, self.n, self.nd, self.nf
        self._setup(par)
        e0, fk = self.e0, self.fk
        x = np.array(x0, dtype=float)
        x[:8] = par[:8]
        um, vm, uo = self.umax, self.vmax, self.uo
        # the torques and the slacks strictly inside their bounds (IPOPT's bound push)
        x[uo:uo + n] = np.clip(x[uo:uo + n], -um + 1e-2 * min(1.0, um),
                               um - 1e-2 * min(1.0, um))
        s = self._speeds(x)
        if self.speed:
            pv = 1e-2 * min(1.0, vm)
            s = np.clip(s, -vm + pv, vm - pv)
        warm = mu < MU_INIT
        self.growth = growth
        ns = npt - 1 if self.speed else 0
        zl, zu = np.ones(n), np.ones(n)
        zls, zus = np.ones(ns), np.ones(ns)
        if warm:
            zl, zu = mu / (x[uo:uo + n] + um), mu / (um - x[uo:uo + n])
            if self.speed:
                zls, zus = mu / (s + vm), mu / (vm - s)
        lam = None
        lamd = zus - zls if self.speed else np.zeros(npt - 1)
        delta_last = 0.0
        status, it = 1, 0
        tau_min = 0.99
        filt = []
        theta_max = theta_min = None
        nrest = 0
        adaptive = strategy == "adaptive"
        nacc = 0
        wd, short = None, 0  # the watchdog's reference, the shortened steps in a row
        free, refs, mu_max, mu_min = True, [], None, min(1e-11, 0.5 * tol / 11.0)
        while True:
            lam_e = np.zeros(self.neq) if lam is None else lam
            f, c, grad, jv, _, hv = self._eval(x, lam_e[:self.nloc], 2, fk, e0)
            if not (np.isfinite(f) and np.all(np.isfinite(c)) and np.all(np.isfinite(grad))):
                status, self.why = 2, "nonfinite"
                break
            jac = self.jacobian(jv)
            # the factors of J_d: the null-space step's, and the multipliers' estimate
            reset = lam is None or np.max(np.abs(lam)) > LAM_RESET
            need = reset or STEP != "kkt"  # (auto: its sensitivities choose the step)
            lu = self._factor(jac) if need else None
            if need and lu is None:
                status, self.why = 2, "singular"
                break
            gf = np.concatenate((grad[self.dep], grad[self.uix]))  # on the reduced columns
            rd = self._speeds(x) - s if self.speed else np.zeros(0)
            gdl = self._dt(lamd) if self.speed else np.zeros(nf)
            if reset:
                # least-squares multipliers at the start (IPOPT's), after a restoration, and
                # where the steps' ran away (the Hessian then all their curvature)
                lam = lu.solve_t(-(gf[:nd] + gdl[:nd]))
                if not np.all(np.isfinite(lam)) or np.max(np.abs(lam)) > 1e3:
                    lam = np.zeros(self.neq)
                f, c, grad, jv, _, hv = self._eval(x, lam[:self.nloc], 2, fk, e0)
            u = x[uo:uo + n]
            sl_u, su_u = u + um, um - u
            sls, sus = s + vm, vm - s
            # the optimality error (IPOPT's, scaled)
            gl = gf + jac.T @ lam + gdl
            gl[nd:] += zu - zl
            comp = np.concatenate((sl_u * zl, su_u * zu, sls * zls, sus * zus))
            zsum = np.sum(zl) + np.sum(zu) + np.sum(zls) + np.sum(zus)
            nz = 2 * (n + ns)
            sd = max(100.0, (np.sum(np.abs(lam)) + np.sum(np.abs(lamd)) + zsum)
                     / (self.neq + ns + nz)) / 100.0
            sc = max(100.0, zsum / nz) / 100.0
            primal = max(np.max(np.abs(c)), np.max(np.abs(rd)) if ns else 0.0)
            dual = max(np.max(np.abs(gl)),
                       np.max(np.abs(-lamd - zls + zus)) if ns else 0.0)
            err0 = max(dual / sd, primal, np.max(np.abs(comp)) / sc)
            if err0 <= tol:
                status = 0
                break
            nacc = nacc + 1 if (err0 <= ACCEPTABLE_TOL and primal <= 1e-2
                                and np.max(np.abs(comp)) <= 1e-2) else 0
            if nacc >= ACCEPTABLE_ITER:  # IPOPT's acceptable level (its options')
                status = 0
                break
            if it >= max_iter:
                status = 1
                break
            it += 1
            # the Newton step (module docstring)
            diag = np.zeros(nf)
            diag[nd:] = zl / sl_u + zu / su_u
            self.sig_s = zls / sls + zus / sus if ns else np.zeros(0)
            kmat = self.hessian(hv, diag)
            zsens = None if STEP == "kkt" else self._sensitivities(jac, lu)
            if STEP == "kkt" or (STEP == "auto" and not np.max(np.abs(zsens)) <= SENS_MAX):
                lin, delta = self._kkt(kmat, jac, mu, delta_last)
            else:
                lin, delta = self._null_space(kmat, zsens, lu, delta_last)
            if lin is None:
                # no inertia correction up to MAX_DELTA: the restoration phase (IPOPT's),
                # the multipliers estimated anew after it
                theta = self._theta(c, x, s)
                filt.append((theta, self._barrier(f, x, s, mu)))
                xr, sr = (self._restore_min_norm(x, s, mu, theta, filt) if RESTORATION
                          else (None, None))
                if xr is None and RESTORATION:
                    xr, sr = self._restore_rolled(x, theta)
                    filt = [] if xr is not None else filt
                if xr is None:
                    status, self.why = 2, "inertia"
                    break
                x, s, lam, delta_last = xr, sr, None, 0.0
                nrest += 1
                continue
            if delta:
                delta_last = delta

            if adaptive:
                # IPOPT's adaptive barrier: free mode while the optimality error falls (by
                # a factor REF_RED on the last REFS points'), the weight Mehrotra's probing
                # of the affine step; else a monotone phase from 0.8 times the mean
                # complementarity until its barrier problem is solved to 10 mu
                avg = float(np.mean(comp)) if comp.size else 0.0
                if mu_max is None:
                    mu_max = MU_MAX_FACT * max(avg, mu)
                if free and refs and not any(err0 <= REF_RED * r for r in refs):
                    free = False
                    mu = max(mu_min, min(mu_max, 0.8 * avg))
                    filt = []
                elif not free and max(dual / sd, primal,
                                      np.max(np.abs(comp - mu)) / sc) <= 10.0 * mu:
                    free, refs = True, []
                if free:
                    refs = (refs + [err0])[-REFS:]
                    aff = _Newton(self, lin, gf, np.zeros(ns))
                    adx, ads = aff.step(c, rd, probe=True)[:2]
                    adu = adx[uo:uo + n]
                    slacks = np.concatenate((sl_u, su_u, sls, sus))
                    dsl = np.concatenate((adu, -adu, ads, -ads))
                    zz = np.concatenate((zl, zu, zls, zus))
                    if MU_ORACLE == "quality":
                        cg = np.zeros(nf)
                        cg[nd:] = -1.0 / sl_u + 1.0 / su_u
                        cen = _Newton(self, lin, cg,
                                      -1.0 / sls + 1.0 / sus if ns else np.zeros(0))
                        cdx, cds = cen.step(None, np.zeros(ns), probe=True)[:2]
                        cdu = cdx[uo:uo + n]
                        dsc = np.concatenate((cdu, -cdu, cds, -cds))
                        dsq = float(np.mean(gl ** 2) + (np.mean((lamd + zls - zus) ** 2)
                                                        if ns else 0.0))
                        psq = float(np.mean(c ** 2) + (np.mean(rd ** 2) if ns else 0.0))
                        mnew = _quality(slacks, zz, dsl, dsc, dsq, psq, avg) * avg
                    else:
                        dz_a = -zz - zz / slacks * dsl
                        a_p, a_d = _max_step(slacks, dsl, 1.0), _max_step(zz, dz_a, 1.0)
                        maff = float(np.mean((slacks + a_p * dsl) * (zz + a_d * dz_a)))
                        mnew = (maff / avg) ** 3 * avg
                    mnew = min(mu_max, max(mu_min, mnew))
                    if mnew != mu:
                        filt = []
                    mu = mnew
            else:
                # the barrier's weight falls once its problem is solved to 10 mu (IPOPT's
                # monotone update; the filter starts anew)
                while max(dual / sd, primal, np.max(np.abs(comp - mu)) / sc) <= 10.0 * mu \
                        and mu > tol / 10.0:
                    mu = max(tol / 10.0, min(0.2 * mu, mu ** 1.5))
                    filt = []
            tau_min = max(0.99, 1.0 - mu)
            gphi0 = gf.copy()
            gphi0[nd:] += -mu / sl_u + mu / su_u
            gphis = -mu / sls + mu / sus if ns else np.zeros(0)
            newton = _Newton(self, lin, gphi0, gphis)
            dx, ds, lam_new, lamd_new = newton.step(c, rd)
            ddu = dx[uo:uo + n]
            dzl = mu / sl_u - zl - zl / sl_u * ddu
            dzu = mu / su_u - zu + zu / su_u * ddu
            dzls = mu / sls - zls - zls / sls * ds
            dzus = mu / sus - zus + zus / sus * ds
            ap = self._alpha(sl_u, su_u, sls, sus, ddu, ds, tau_min)
            az = _max_step(np.concatenate((zl, zu, zls, zus)),
                           np.concatenate((dzl, dzu, dzls, dzus)), tau_min)
            # the filter line search (IPOPT's, with its second-order corrections)
            theta = self._theta(c, x, s)
            phi = self._barrier(f, x, s, mu)
            if theta_max is None:
                theta_max, theta_min = 1e4 * max(1.0, theta), 1e-4 * max(1.0, theta)
            gd = float(gf @ np.concatenate((dx[self.dep], ddu))
                       + np.sum((-mu / sl_u + mu / su_u) * ddu)
                       + (np.sum(gphis * ds) if ns else 0.0))
            if gd < 0.0:
                amin = 0.05 * min(1e-5, 1e-8 * theta / -gd, theta ** 1.1 / (-gd) ** 2.3)
            else:
                amin = 0.05 * 1e-5

            ls = _Search(self, x, s, mu, theta, phi, gd, theta_min, theta_max, filt)
            a = ap
            acc = None
            first = True
            if wd is not None:
                # the watchdog's iterates (IPOPT's): the current one against its reference
                xw, sw, fw, thw, nw = wd[0], wd[1], wd[8], wd[9], wd[10]
                phw = self._barrier(fw, xw, sw, mu)
                if (theta <= (1.0 - 1e-5) * thw or phi <= phw - 1e-8 * thw) and not any(
                        theta >= tf and phi >= pf for tf, pf in wd[11]):
                    wd = None
                elif nw < WATCHDOG_TRIALS:
                    wd = wd[:10] + (nw + 1, wd[11])
                    first = False  # a full step, not judged
                    acc = _forced(ls.trial(a, a * dx, a * ds))
                else:  # back to the reference, and its own line search
                    x, s, lam, lamd, zl, zu, zls, zus = wd[:8]
                    filt, wd, short = list(wd[11]), None, 0
                    continue
            elif short >= WATCHDOG_SHORT:
                wd = (x, s, lam, lamd, zl, zu, zls, zus, f, theta, 1, list(filt))
                short = 0
                acc = _forced(ls.trial(a, a * dx, a * ds))
            if acc is not None:
                a = ap
            while acc is None and a >= amin:
                res = ls.trial(a, a * dx, a * ds)
                if res is not None and res[0]:
                    acc = res
                    break
                if first and res is not None and res[4] >= theta:
                    # second-order corrections
                    csoc, rsoc, tprev, asoc = a * c, a * rd, theta, a
                    ct, xt, st = res[3], res[1], res[2]
                    for _ in range(4):
                        csoc = asoc * csoc + ct if _ else csoc + ct
                        rsoc = (asoc * rsoc if _ else rsoc) + (
                            self._speeds(xt) - st if ns else 0.0)
                        sdx, sds, _l, _ld = newton.step(csoc, rsoc)
                        asoc = self._alpha(sl_u, su_u, sls, sus, sdx[uo:uo + n], sds,
                                           tau_min)
                        rs = ls.trial(a, asoc * sdx, asoc * sds)
                        if rs is None:
                            break
                        if rs[0]:
                            acc = rs
                            break
                        if rs[4] > 0.99 * tprev:
                            break
                        tprev, ct, xt, st = rs[4], rs[3], rs[1], rs[2]
                    if acc is not None:
                        break
                first = False
                a *= 0.5
            if acc is None:
                # restoration: the equality rows solved for the unknowns but the torques
                # (Newton's method, the torques held), accepted where it lowers the
                # infeasibility by a tenth and the filter takes it
                filt.append((theta, phi))
                xr, sr = self._restore(x, s)
                tr = None if xr is None else self._theta(self._values(xr)[1], xr, sr)
                if tr is None or not tr <= 0.9 * theta or any(
                        tr >= tf and self._barrier(self._values(xr)[0], xr, sr, mu) >= pf
                        for tf, pf in filt):
                    xr, sr = (self._restore_min_norm(x, s, mu, theta, filt)
                              if RESTORATION else (None, None))
                if xr is None and RESTORATION:
                    xr, sr = self._restore_rolled(x, theta)
                    filt = [] if xr is not None else filt
                if xr is None:
                    status, self.why = 2, "restore"
                    break
                x, s, lam = xr, sr, None
                nrest += 1
                continue
            if self.trace is not None:
                self.trace.append((it, f, primal, dual / sd, np.max(np.abs(comp)), mu, ap, a,
                                   az, delta, len(filt)))
            short = short + 1 if a < ap else 0
            x, s = acc[1], acc[2]
            lam = lam + a * (lam_new - lam)
            lamd = lamd + a * (lamd_new - lamd)
            zl, zu = zl + az * dzl, zu + az * dzu
            zls, zus = zls + az * dzls, zus + az * dzus
            # the multipliers of the bounds kept within 1e10 of their central values
            u = x[uo:uo + n]
            zl = np.clip(zl, mu / (1e10 * (u + um)), 1e10 * mu / (u + um))
            zu = np.clip(zu, mu / (1e10 * (um - u)), 1e10 * mu / (um - u))
            if ns:
                zls = np.clip(zls, mu / (1e10 * (s + vm)), 1e10 * mu / (s + vm))
                zus = np.clip(zus, mu / (1e10 * (vm - s)), 1e10 * mu / (vm - s))
        self.lam, self.restorations = lam, nrest
        return x, float(f), status, it

    def _kkt(self, kmat, jac, mu, delta_last):
        """The whole KKT matrix factored with IPOPT's inertia correction: ``delta_w`` 0,
        then ``1e-4`` (or a third of the last one) times 8 until the inertia is ``(nf,
        neq, 0)`` (IPOPT grows its first correction by 100: that capped a captured horizon of
        the Te 8 s bin which 8 solved in 18 iterations); ``delta_c = 1e-8
        mu^(1/4)`` where the matrix is singular (a zero pivot, or too few negative ones).
        ``(None, delta)`` past MAX_DELTA."""
        if self.ldl is None:
            self.ldl = SparseLDL(self.nf + self.neq, self.kkt_rows, self.kkt_cols)
        kd, jd = kmat.data[self.kkt_ksel], jac.data
        nf, ne = self.nf, self.neq
        delta, dc = 0.0, 0.0
        diag = np.empty(nf + ne)
        for _ in range(MAX_CORRECTIONS):
            diag[:nf] = delta + EPS
            diag[nf:] = -(dc + EPS)
            npos = self.ldl.factor(np.concatenate((kd, jd, diag)), ne)
            if npos == nf:
                return _FullKKT(self, self.ldl, kmat, jac, delta, dc), delta
            if (npos == -1 or npos > nf) and dc == 0.0:
                dc = 1e-8 * mu ** 0.25
                continue
            if delta == 0.0:
                delta = 1e-4 if delta_last == 0.0 else max(1e-20, delta_last / 3.0)
            else:
                delta *= 8.0
            if delta > MAX_DELTA:
                break
        return None, delta

    def _sensitivities(self, jac, lu):
        """The null space's basis ``Z = [-J_d^-1 J_u; I]`` (nf, n): the torques'
        sensitivities."""
        n, nd = self.n, self.nd
        ju = np.zeros((nd, n))  # J_u dense, C order (SciPy's toarray: Fortran's, copied)
        ju[self.ju_rows, self.ju_cols] = jac.data[self.jptr[nd]:]
        zfull = np.empty((self.nf, n))
        np.negative(lu.solve(ju, torques=True), out=zfull[:nd])
        zfull[nd:] = np.eye(n)
        return zfull

    def _null_space(self, kmat, zfull, lu, delta_last):
        """The reduced Hessian on the orthonormal basis of the null space (``zfull``: its
        basis :meth:`_sensitivities`), Cholesky-factored with the inertia correction ``delta
        I`` (0, then the last one's third or ``1e-4``, times 8); ``(None, delta)`` past
        MAX_DELTA."""
        n = self.n
        # an orthonormal basis of the null space: the torques' sensitivities reach 1e8
        # where the linearized motion is unstable over the horizon, and Z^T K Z then
        # loses the reduced Hessian to rounding (Z R^-1 with Householder's R:
        # orthonormal to 1e-16 times Z's condition)
        zfull = zfull @ np.linalg.inv(np.linalg.qr(zfull, mode="r"))
        zr = zfull[self.krows]
        hred = zr.T @ (kmat @ zr)
        delta = 0.0  # (Q^T Q = I: delta I is IPOPT's delta_w)
        for _ in range(MAX_CORRECTIONS):
            if delta > MAX_DELTA:
                break
            try:
                fac = cho_factor(hred if delta == 0.0 else hred + delta * np.eye(n),
                                 check_finite=False)
                if np.all(np.isfinite(fac[0])):
                    return _NullSpace(self, lu, fac, zfull, kmat, delta), delta
            except LinAlgError:
                pass
            delta = ((1e-4 if delta_last == 0.0 else max(1e-20, delta_last / 3.0))
                     if delta == 0.0 else 8.0 * delta)
        return None, delta

    def _restore(self, x, s, max_iter=20):
        """``(x, s)`` with the equality rows solved by Newton's method on the unknowns but the
        torques (backtracking on ``|c|_1``), the slacks the speeds within their bounds; ``(None,
        None)`` where it does not converge."""
        x = x.copy()
        for _ in range(max_iter):
            _, c, _, jv, _, _ = self._eval(x, self._nolam, 1, self.fk, self.e0)
            th = np.sum(np.abs(c))
            if np.max(np.abs(c)) < 1e-10:
                break
            lu = self._factor(self.jacobian(jv))
            if lu is None:
                return None, None
            dz = lu.solve(-c)
            a = 1.0
            for _ in range(20):
                xt = x.copy()
                xt[self.dep] += a * dz
                ct = self._values(xt)[1]
                if np.sum(np.abs(ct)) < (1.0 - 1e-4 * a) * th:
                    break
                a *= 0.5
            else:
                return None, None
            x = xt
        s = self._speeds(x)
        if self.speed:
            pv = 1e-2 * min(1.0, self.vmax)
            s = np.clip(s, -self.vmax + pv, self.vmax - pv)
        return x, s

    def _restore_min_norm(self, x, s, mu, theta0, filt, max_iter=30):
        """IPOPT's restoration phase in Gauss-Newton form: steps of least norm onto the
        linearized equality rows, in all the unknowns (the torques within their bounds by
        the fraction to the boundary), backtracking on ``|c|_2``, until the infeasibility
        ``theta`` is at most 0.9 ``theta0`` at a point the filter ``filt`` takes (the barrier
        weight ``mu``); ``(None, None)`` where it does not get there. The least-norm step is
        ``Y p - Q Q^T Y p`` (``Q`` the orthonormal basis of the null space, ``Y p`` the step
        with the torques held)."""
        n, nd, nf, uo, um = self.n, self.nd, self.nf, self.uo, self.umax
        x = x.copy()
        for _ in range(max_iter):
            _, c, _, jv, _, _ = self._eval(x, self._nolam, 1, self.fk, self.e0)
            jac = self.jacobian(jv)
            lu = self._factor(jac)
            if lu is None:
                return None, None
            yp = np.zeros(nf)
            yp[:nd] = -lu.solve(c)
            zfull = self._sensitivities(jac, lu)
            q = zfull @ np.linalg.inv(np.linalg.qr(zfull, mode="r"))
            dxf = yp - q @ (q.T @ yp)
            if not np.all(np.isfinite(dxf)):
                return None, None
            u = x[uo:uo + n]
            du = dxf[nd:]
            a = _max_step(np.concatenate((u + um, um - u)), np.concatenate((du, -du)), 0.99)
            c2 = float(c @ c)
            for _ in range(30):
                xt = x.copy()
                xt[self.dep] += a * dxf[:nd]
                xt[self.uix] += a * du
                ct = self._values(xt)[1]
                if np.all(np.isfinite(ct)) and float(ct @ ct) <= (1.0 - 1e-4 * a) * c2:
                    break
                a *= 0.5
            else:
                return None, None
            x = xt
            st = self._speeds(x)
            if self.speed:
                pv = 1e-2 * min(1.0, self.vmax)
                st = np.clip(st, -self.vmax + pv, self.vmax - pv)
            ft, ct, _ = self._values(x)
            tr = self._theta(ct, x, st)
            if tr <= 0.9 * theta0 and not any(
                    tr >= tf and self._barrier(ft, x, st, mu) >= pf for tf, pf in filt):
                return x, st
        return None, None

    def _restore_rolled(self, x, theta0):
        """The last restoration: the plant's model rolled under the iterate's torques
        (``self.rollout``, forward in time: no Newton step over the whole horizon's unstable
        linearization), then Newton's method on the equality rows from it (:meth:`_restore`):
        the NLP's feasible point with those torques, where its infeasibility is below 0.9
        ``theta0`` (the caller starts the filter anew from it: the point is feasible, but
        its objective may be above the filter's); ``(None, None)`` else, or without a
        rollout."""
        if self.rollout is None:
            return None, None
        u = np.clip(x[self.uo:self.uo + self.n], -0.99 * self.umax, 0.99 * self.umax)
        xg = np.array(self.rollout(u), dtype=float)
        xg[:8] = x[:8]
        if not np.all(np.isfinite(xg)):
            return None, None
        xr, sr = self._restore(xg, self._speeds(xg))
        if xr is None:
            return None, None
        tr = self._theta(self._values(xr)[1], xr, sr)
        return (xr, sr) if tr <= 0.9 * theta0 else (None, None)

    def simulate(self, x0, par, max_iter=50):
        """The NLP's only feasible point with ``x0``'s torques (Newton's method on the
        equality rows from ``x0``; the collocation's motion under the torques)."""
        self._setup(par)
        x = np.array(x0, dtype=float)
        x[:8] = par[:8]
        for _ in range(max_iter):
            _, c, _, jv, _, _ = self._eval(x, self._nolam, 1, self.fk, self.e0)
            if np.max(np.abs(c)) < 1e-12:
                break
            lu = self._factor(self.jacobian(jv))
            if lu is None:
                break
            dz = lu.solve(-c)
            x[self.dep] += dz
            if np.max(np.abs(dz)) < 1e-13 * max(1.0, np.max(np.abs(x))):
                break
        return x

    def _factor(self, jac):
        """The structured factors of ``J_d`` (:mod:`._hull_collocation_linalg`), or None
        where singular."""
        if self.lin is None:
            self.lin = Structured(self)
        return self.lin if self.lin.factor(jac.data) else None

    def _dt(self, w):
        """``D^T w`` on the reduced columns."""
        out = np.zeros(self.nf)
        np.add.at(out, self.d7, w)
        np.add.at(out, self.d6, -w)
        return out

    def _alpha(self, sl_u, su_u, sls, sus, ddu, ds, tau):
        """The largest step to the fraction ``tau`` of the bounds' distances."""
        return _max_step(np.concatenate((sl_u, su_u, sls, sus)),
                         np.concatenate((ddu, -ddu, ds, -ds)), tau)



class _Newton:
    """The Newton step of one iteration (module docstring) for any constraints' right side
    (the second-order corrections reuse the factors ``lin``: :class:`_FullKKT` or
    :class:`_NullSpace`)."""

    def __init__(self, solver, lin, gphi0, gphis):
        self.sv, self.lin = solver, lin
        self.gphi0, self.gphis = gphi0, gphis

    def step(self, cr, rdr, probe=False):
        """``(dx, ds, l+, l_d+)`` for the constraints' values ``cr`` (None: zero) and speeds'
        ``rdr``; ``probe``: a step only the barrier's oracle reads (its ``dx`` and ``ds``:
        no multipliers, no iterative refinement)."""
        sv = self.sv
        nd = sv.nd
        ns = sv.sig_s.size
        gphi = self.gphi0 + sv._dt(sv.sig_s * rdr + self.gphis) if ns else self.gphi0
        dxf, lnew = self.lin.solve(gphi, cr, probe)
        if probe:
            lnew = None
        ds = dxf[sv.d7] - dxf[sv.d6] + rdr if ns else np.zeros(0)
        dx = np.zeros(sv.nvar)
        dx[sv.dep] = dxf[:nd]
        dx[sv.uix] = dxf[nd:]
        if probe:
            return dx, ds, None, None
        return dx, ds, lnew, sv.sig_s * ds + self.gphis if ns else np.zeros(sv.npt - 1)


def _kmul(sv, kmat, delta, v):
    """``(K + delta I) v`` (``kmat``: ``K`` on its rows ``sv.krows``)."""
    out = delta * v
    kr = sv.krows
    out[kr] += kmat @ v[kr]
    return out


class _FullKKT:
    """The Newton step from the ``L D L^T`` of the whole KKT matrix (``ldl``, its
    regularization refined away on ``[K + delta I, J^T; J, -delta_c I]``)."""

    def __init__(self, sv, ldl, kmat, jac, delta, delta_c):
        self.sv, self.ldl, self.kmat, self.jac = sv, ldl, kmat, jac
        self.delta, self.delta_c = delta, delta_c

    def mul(self, v):
        nf = self.sv.nf
        dx, lv = v[:nf], v[nf:]
        return np.concatenate((_kmul(self.sv, self.kmat, self.delta, dx) + self.jac.T @ lv,
                               self.jac @ dx - self.delta_c * lv))

    def solve(self, gphi, cr, probe=False):
        """``(dx, l+)`` of ``(K + delta I) dx + J^T l+ = -gphi``, ``J dx - delta_c l+ =
        -cr`` (``cr`` None: zero; iterative refinement: at most REFINE steps, until the
        residual is 1e-12 of the right side's, also for a ``probe``, the barrier oracle's
        steps: without it the oracle's weight moved by the static regularization's 1e-9,
        and a hard horizon of the Te 8 s bin that this step solved failed)."""
        nf = self.sv.nf
        rhs = np.zeros(nf + self.sv.neq)
        rhs[:nf] = -gphi
        if cr is not None:
            rhs[nf:] = -cr
        v = self.ldl.solve(rhs)
        scale = 1e-12 * max(1.0, float(np.max(np.abs(rhs))))
        last = np.inf
        for _ in range(REFINE):
            r = rhs - self.mul(v)
            res = float(np.max(np.abs(r)))
            if not res > scale or not res < 0.5 * last:
                break
            last = res
            v = v + self.ldl.solve(r)
        return v[:nf], v[nf:]


class _NullSpace:
    """The Newton step in the null space of ``J`` (``lu``: the factors of ``J_d``; ``fac``
    the Cholesky factor of the reduced Hessian, ``zfull`` the null space's orthonormal
    basis)."""

    def __init__(self, sv, lu, fac, zfull, kmat, delta):
        self.sv, self.lu, self.fac, self.zfull = sv, lu, fac, zfull
        self.kmat, self.delta = kmat, delta
        self.last = None  # (cr, yp, K yp) of the last right side (the same c: the
        # affine step's and the step's)

    def solve(self, gphi, cr, probe=False):
        """``(dx, l+)`` (``cr`` None: zero; ``l+`` None for a ``probe``)."""
        sv = self.sv
        nd = sv.nd
        if cr is None:
            yp, km = np.zeros(sv.nf), np.zeros(sv.nf)
        elif self.last is not None and self.last[0] is cr:
            yp, km = self.last[1], self.last[2]
        else:
            yp = np.zeros(sv.nf)
            yp[:nd] = -self.lu.solve(cr)
            km = _kmul(sv, self.kmat, self.delta, yp)
            self.last = (cr, yp, km)
        du = cho_solve(self.fac, -(self.zfull.T @ (gphi + km)), check_finite=False)
        dxf = yp + self.zfull @ du
        if probe:
            return dxf, None
        lnew = self.lu.solve_t(-(gphi + _kmul(sv, self.kmat, self.delta, dxf))[:nd])
        return dxf, lnew


class _Search:
    """One iteration's filter line search (IPOPT's): :meth:`trial` of a step."""

    def __init__(self, solver, x, s, mu, theta, phi, gd, theta_min, theta_max, filt):
        self.sv, self.x, self.s, self.mu = solver, x, s, mu
        self.theta, self.phi, self.gd = theta, phi, gd
        self.theta_min, self.theta_max, self.filt = theta_min, theta_max, filt

    def trial(self, a, dxa, dsa):
        """``None`` (out of the bounds) or ``(accepted, x, s, c, theta)`` of the step
        ``(dxa, dsa)`` (the search's ``a`` for the switching rule)."""
        sv = self.sv
        xt, st = self.x + dxa, self.s + dsa
        ut = xt[sv.uo:sv.uo + sv.n]
        um, vm = sv.umax, sv.vmax
        if np.any(ut + um <= 0) or np.any(um - ut <= 0) or (
                sv.speed and (np.any(st + vm <= 0) or np.any(vm - st <= 0))):
            return None
        ft, ct, _, _, _, _ = sv._eval(xt, sv._nolam, 0, sv.fk, sv.e0)
        tht, pht = sv._theta(ct, xt, st), sv._barrier(ft, xt, st, self.mu)
        theta, phi, gd = self.theta, self.phi, self.gd
        if not (np.isfinite(tht) and np.isfinite(pht)) or tht > self.theta_max or (
                tht > max(sv.growth * theta, THETA_FLOOR)):
            return False, xt, st, ct, tht
        if any(tht >= tf and pht >= pf for tf, pf in self.filt):
            return False, xt, st, ct, tht
        switch = gd < 0.0 and a * (-gd) ** 2.3 > theta ** 1.1
        armijo = pht <= phi + 1e-8 * a * gd
        if theta <= self.theta_min and switch:
            return armijo, xt, st, ct, tht
        ok = tht <= (1.0 - 1e-5) * theta or pht <= phi - 1e-8 * theta
        if ok and not (switch and armijo):
            self.filt.append(((1.0 - 1e-5) * theta, phi - 1e-8 * theta))
        return ok, xt, st, ct, tht


def _quality(slacks, z, dsl_a, dsl_c, dual_sq, primal_sq, avg, lo=1e-6, hi=1e2):
    """IPOPT's quality-function oracle: the centering ``sigma`` in ``[lo, hi]`` (golden
    section on its logarithm) that minimizes the linearized optimality error after the step
    of the barrier weight ``sigma avg``: ``(1 - a_d)^2`` the dual infeasibility's mean
    square ``dual_sq``, plus ``(1 - a_p)^2`` the primal one's ``primal_sq``, plus the mean
    square of the complementarity after the step (``a_p``, ``a_d`` to the fraction 0.99 of
    the bounds). The bounds' distances ``slacks`` step as ``dsl_a + mu dsl_c`` (the affine
    step and the centering one per unit weight), their multipliers ``z`` as ``mu / slacks -
    z - z / slacks * dsl``."""
    def q(lg):
        mu = 10.0 ** lg * avg
        dsl = dsl_a + mu * dsl_c
        dz = mu / slacks - z - z / slacks * dsl
        a_p, a_d = _max_step(slacks, dsl, 0.99), _max_step(z, dz, 0.99)
        comp = (slacks + a_p * dsl) * (z + a_d * dz)
        return (1.0 - a_d) ** 2 * dual_sq + (1.0 - a_p) ** 2 * primal_sq + float(
            np.mean(comp ** 2))

    a, b = np.log10(lo), np.log10(hi)
    g = 0.5 * (np.sqrt(5.0) - 1.0)
    c, d = b - g * (b - a), a + g * (b - a)
    qc, qd = q(c), q(d)
    for _ in range(20):
        if qc <= qd:
            b, d, qd = d, c, qc
            c = b - g * (b - a)
            qc = q(c)
        else:
            a, c, qc = c, d, qd
            d = a + g * (b - a)
            qd = q(d)
    return 10.0 ** (0.5 * (a + b))


def _forced(res):
    """A trial step taken whatever the filter says (the watchdog's), or None out of the
    bounds (or not finite)."""
    if res is None or not np.isfinite(res[4]):
        return None
    return (True,) + tuple(res[1:])


def _logs(a, b):
    with np.errstate(invalid="ignore", divide="ignore"):
        return float(np.sum(np.log(a)) + np.sum(np.log(b)))


def _max_step(v, dv, frac):
    neg = dv < 0
    if not np.any(neg):
        return 1.0
    return float(min(1.0, frac * np.min(-v[neg] / dv[neg])))
