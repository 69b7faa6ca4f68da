r"""The hull's horizon problem with the MOTION as the unknown (``planner="collocation"`` of
:func:`parapend.hydro.hull_control.hull_mpc`): direct collocation, solved on the exact
Hessian by a compiled interior point (:mod:`._hull_collocation_ipm`, the default) or by
IPOPT on the same NLP built in CasADi (``solver="ipopt"``).

The unknowns are the hull's ``xi = (x, z, beta)`` and the pendulum's absolute angle ``phi``
with their velocities at the points ``t + k s``, ``k = 0..2 r n`` (``r`` Hermite-Simpson
intervals ``[2 i s, (2 i + 2) s]`` a torque sample, ``INTERVALS`` = 3 on the default 6
plant steps: ``s`` the plant's step), the accelerations of every interval at its ends and
midpoint, and the held torque ``u_j`` of every sample (``|u_j| <= T_max``,
units ``m g l``). The constraints are the plant's four equations (:mod:`._hull_plant`)

    M_t xi'' + m l G^T a phi'' = F - mu - C' xi + m l G^T b phi'^2 + e_beta (c v - tau)
    m l a^T G xi'' + I phi''   = tau - c v + m l g sin(phi)

at every point of every interval under its sample's torque (the pendulum's equation is the
inverse dynamics that ties the motion to the held torque, so the plan is one the plant can
follow: no torque has to be read off a planned motion), Hermite-Simpson's interpolation
and quadrature of positions and velocities on every interval, and the measured state at
``k = 0``. The radiation memory ``mu(t) = int K(s) xi'(t - s) ds`` (the plant's kernels,
cut at its memory) is split into the known past (the plant's trapezoid over its stored
velocities before ``t``: a parameter) and the horizon's own part, the trapezoid over the
horizon's velocities at every ``MEMORY_STRIDE``-th point (the memory's nodes, unknowns
tied to it by dense lower-triangular rows; the memory linear between them: with the
memory at every point IPOPT's factorizations took 0.4 s an iteration, at every third 0.05
s). Against the plant (RK4, its memory's trapezoid on the step) the collocation's motion
under fixed torques converges at second order (the memory's trapezoid) as the interval
halves (tests/test_hull_collocation.py). The objective (minimized, units ``m g
l rad``) is :class:`.hull_control.HullHorizon`'s: minus the exact work of every held torque
``-u_j (theta_(j+1) - theta_j)`` (electrical ``e(.)`` with an efficiency, its kink
smoothed) and minus ``kappa`` times the mechanical energy gained at the horizon's end. In
place of its speed penalty the generator's speed ``phi' - beta'`` is bounded at every point
by ``MAX_TURN`` rad per plant step (0.4: 9.6 rad/s on the default barge's step, past the
record optimum's 7.8 to 8.6 rad/s; without a bound the plans of the default barge spun
the pendulum to 16 rad/s, where the plant's steps no longer follow them, and the run
ended unresolved).

The NLP is built once per run (the start, the memory's past part and the forecast are its
parameters) and warm-started from the previous solution shifted by the update interval.
The compiled solver takes its Newton steps in the null space of the square Jacobian of the
equality rows in the unknowns other than the torques (:mod:`._hull_collocation_linalg`)
while the torques' sensitivities stay moderate, and where they grow large (the motion's
linearization unstable over the horizon), as IPOPT does (MUMPS), from a factorization of
the whole sparse KKT matrix (:mod:`._hull_collocation_ldl`), most of whose cost is the
memory's dense rows (:data:`._hull_collocation_ipm.STEP`).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from ..errors import ParameterError

#: IPOPT's options of the horizon solve (exact Hessian, MUMPS)
IPOPT_OPTIONS = {"tol": 1e-6, "acceptable_tol": 1e-4, "print_level": 0,
                 "hessian_approximation": "exact", "linear_solver": "mumps",
                 "sb": "yes", "mu_strategy": "adaptive"}
#: Hermite-Simpson intervals per torque sample at most (the most that hold whole plant
#: steps: 3 on the default 6 steps, every point a plant step)
INTERVALS = 3
#: the horizon's own memory is summed over every this many points (and is linear between):
#: its constraint rows are dense (lower triangular), the rest of the NLP is banded
MEMORY_STRIDE = 3
#: the generator's planned speed at most, rad per plant step (None: unbounded)
MAX_TURN = 0.4
#: a capped plan is applied only where the plant's model rolled under its torques up to the
#: next update keeps the generator within this many rad of the planned angle (a capped
#: iterate of the default barge's runs: 3e-3 rad at most; one whose torques its motion did
#: not follow, 0.8 rad, turned the pendulum of a Hs 0.5 m bin past the plant's step)
CAPPED_ANGLE_TOL = 0.05
#: the horizon's solver: ``"compiled"`` (:mod:`._hull_collocation_ipm`, no CasADi: the same
#: NLP; its Newton step :data:`._hull_collocation_ipm.STEP`, ``"auto"``) or ``"ipopt"``
#: (CasADi's IPOPT, ``parapend[collocation]``). In the closed loop of the default barge's
#: seeds 0 to 9 (40 iterations at most; the plant's memory then cut at 2 peak periods, 94.3
#: and 86.2 % with today's tapered one, docs/hull.md) the compiled solver realized 95.3 % of
#: the record optimum with the perfect forecast and 87.9 % with AR (IPOPT: 94.5 and 87.7 %),
#: no failed solve; on the power matrix's Hs 1 m, Te 8 s bin (Tp 8.9 s: a 17.8 s horizon; 4 waves,
#: seed 0) 276.8 W perfect and 292.4 W AR, none failed, against IPOPT's 277.2 and 333.7 W
#: (benchmarks/hull_collocation_table.out.txt, hull_collocation_solver.out.txt); a horizon
#: 2.1 to 2.6 times faster than IPOPT's (median). The compiled solver is the default (the
#: collocation planner is the hull's default, ``hull_control.PLANNER``: it runs without the
#: extra, and faster); IPOPT is there to check it against
SOLVER = "compiled"
#: the compiled solver's status names (``ipopt`` field of :meth:`HullCollocation.solve`)
_COMPILED_STATUS = ("solved", "capped", "failed")
#: IPOPT return statuses counted as a solved horizon (0) or an iteration cap (1)
_SOLVED = ("Solve_Succeeded", "Solved_To_Acceptable_Level")
_CAPPED = ("Maximum_Iterations_Exceeded", "Maximum_CpuTime_Exceeded",
           "Maximum_WallTime_Exceeded")


def _casadi():
    try:
        import casadi
    except ImportError:  # pragma: no cover - depends on the environment
        raise ParameterError("planner: collocation needs CasADi; install parapend[collocation]"
                             ) from None
    return casadi


def available(solver: str | None = None) -> None:
    """Raise the one-line error naming the extra where ``solver`` (None: :data:`SOLVER`)
    needs CasADi and it is not installed (before a long run starts)."""
    if (SOLVER if solver is None else solver) == "ipopt":
        _casadi()


class HullCollocation:
    """The collocation horizon problem of one update (module docstring) on ``plant``
    (:class:`.hull_control.HullPlant`): ``n`` held torques of ``steps`` plant steps
    (``steps`` even), torque limit ``torque_limit`` (units ``m g l``)."""

    def __init__(self, plant, n, steps, tu, torque_limit, efficiency=None, kappa=None,
                 terminal="total", max_iter=100, intervals=None, options=None, solver=None):
        if intervals is None:  # the most up to INTERVALS that hold whole plant steps
            intervals = max(r for r in range(1, INTERVALS + 1) if steps % (2 * r) == 0
                            ) if steps % 2 == 0 else 1
        intervals = int(intervals)
        self.max_turn = MAX_TURN
        if steps % (2 * intervals):
            raise ParameterError(f"plant_steps: expected a multiple of {2 * intervals} with "
                                 f"the collocation planner, got {steps}")
        self.plant, self.n, self.steps, self.tu = plant, n, steps, tu
        self.intervals = intervals
        self.ratio = steps // (2 * intervals)  # plant steps per point
        self.spacing = plant.h * self.ratio
        self.stride = MEMORY_STRIDE if 2 * n * intervals % MEMORY_STRIDE == 0 else 1
        self.ncp = 2 * n * intervals // self.stride + 1
        self.torque_limit = torque_limit
        self.eta = (1.0, 1.0) if efficiency is None else tuple(efficiency)
        self.kappa = self.eta[0] if kappa is None else float(kappa)
        self.pendulum_only = terminal == "pendulum"
        self.tol = IPOPT_OPTIONS["tol"]
        self.options = dict(IPOPT_OPTIONS, max_iter=int(max_iter), **(options or {}))
        self.npt = 2 * n * intervals + 1
        self.prev = None  # the previous solution (x, lam_x, lam_g) for the warm start
        self.shift = 0
        self.solver_name = SOLVER if solver is None else solver
        if self.solver_name not in ("compiled", "ipopt"):
            raise ParameterError(f"solver: expected compiled or ipopt, got "
                                 f"{self.solver_name!r:.40}")
        self.nx, self.na = 8 * self.npt, 12 * ((self.npt - 1) // 2)
        lb = -np.inf * np.ones(self.nx + self.na + n + 3 * self.ncp)
        ub = -lb
        lb[self.nx + self.na:self.nx + self.na + n] = -self.torque_limit
        ub[self.nx + self.na:self.nx + self.na + n] = self.torque_limit
        self.lbx, self.ubx = lb, ub
        if self.solver_name == "ipopt":
            self._build()
        else:
            from ._hull_collocation_ipm import CompiledSolver

            self.compiled = CompiledSolver(self)

    # -- the NLP ---------------------------------------------------------------------------
    def _layout(self):
        npt, ni = self.npt, (self.npt - 1) // 2
        nx, na = 8 * npt, 12 * ni
        return npt, ni, nx, na

    def _build(self):
        ca = _casadi()
        pl = self.plant
        npt, ni, nx, na = self._layout()
        n, tu, hh = self.n, self.tu, self.spacing
        m, ell, inertia, c, g = (float(v) for v in pl.par)
        ml = m * ell
        gm, mt, cp = ca.DM(pl.gm), ca.DM(pl.mt), ca.DM(pl.cp)
        ms, ncp = self.stride, self.ncp
        xs = ca.SX.sym("x", nx + na + n + 3 * ncp)
        ys = ca.reshape(xs[:nx], 8, npt)  # columns: points
        acc = ca.reshape(xs[nx:nx + na], 4, 3 * ni)  # columns: (interval, start/mid/end)
        u = xs[nx + na:nx + na + n]
        muc = ca.reshape(xs[nx + na + n:], 3, ncp) * tu  # the memory at the memory's nodes
        p_y0 = ca.SX.sym("y0", 8)
        p_mu = ca.SX.sym("mu", 3, ncp)  # the memory's past part at the memory's nodes
        p_f = ca.SX.sym("f", 3, npt)
        # the horizon's own memory at its nodes: mu_j = past_j + sum_i Wh[j, i] v_i (the
        # velocities at the nodes), lower triangular; linear between the nodes
        wmat = ca.DM(self._weight_matrix())
        vel = ca.reshape(ys[4:7, ::ms], 3 * ncp, 1)
        mem = ca.reshape(p_mu, 3 * ncp, 1) + ca.mtimes(wmat, vel)
        cons_mem = (ca.reshape(muc, 3 * ncp, 1) - mem) / tu
        mu = ca.mtimes(muc, ca.DM(self._interpolation()))

        def residual(y, a, tau, muk, fk):
            s, co = ca.sin(y[3]), ca.cos(y[3])
            cvec = ml * (gm[0, :].T * co - gm[1, :].T * s)
            bvec = gm[0, :].T * s + gm[1, :].T * co
            v = y[7] - y[6]
            rh = (ca.mtimes(mt, a[:3]) + cvec * a[3] - fk + muk + ca.mtimes(cp, y[:3])
                  - ml * bvec * y[7] ** 2)
            rh[2] = rh[2] - (c * v - tau)
            rp = ca.dot(cvec, a[:3]) + inertia * a[3] - (tau - c * v + ml * g * s)
            return ca.vertcat(rh, rp) / tu

        def energy(y):
            s, co = ca.sin(y[3]), ca.cos(y[3])
            cvec = ml * (gm[0, :].T * co - gm[1, :].T * s)
            qd = y[4:7]
            e = (0.5 * ca.dot(qd, ca.mtimes(mt, qd)) + ca.dot(cvec, qd) * y[7]
                 + 0.5 * inertia * y[7] ** 2 + 0.5 * ca.dot(y[:3], ca.mtimes(cp, y[:3]))
                 + ml * g * co)
            if self.pendulum_only:
                e -= 0.5 * ca.dot(qd, ca.mtimes(mt, qd)) + 0.5 * ca.dot(y[:3], ca.mtimes(cp, y[:3]))
            return e

        eg, em = self.eta
        ae, be = 0.5 * (eg + 1.0 / em), 0.5 * (eg - 1.0 / em)
        width = 1e-3  # the kink smoothed over this work (m g l rad), as HullHorizon's

        def elec(pw):
            if be == 0.0:
                return ae * pw
            return ae * pw + be * (ca.sqrt(pw * pw + width ** 2) - width)

        cons = [ys[:, 0] - p_y0, cons_mem]
        work = 0
        hi = 2.0 * hh
        for i in range(ni):
            tau = u[i // self.intervals] * tu
            k0, km, k1 = 2 * i, 2 * i + 1, 2 * i + 2
            a0, am, a1 = acc[:, 3 * i], acc[:, 3 * i + 1], acc[:, 3 * i + 2]
            y0_, ym, y1 = ys[:, k0], ys[:, km], ys[:, k1]
            for k, y, a in ((k0, y0_, a0), (km, ym, am), (k1, y1, a1)):
                cons.append(residual(y, a, tau, mu[:, k], p_f[:, k]))
            q0, qm, q1 = y0_[:4], ym[:4], y1[:4]
            v0, vm, v1 = y0_[4:], ym[4:], y1[4:]
            cons.append(qm - 0.5 * (q0 + q1) - hi / 8.0 * (v0 - v1))
            cons.append(vm - 0.5 * (v0 + v1) - hi / 8.0 * (a0 - a1))
            cons.append(q1 - q0 - hi / 6.0 * (v0 + 4.0 * vm + v1))
            cons.append(v1 - v0 - hi / 6.0 * (a0 + 4.0 * am + a1))
        # the exact work of each held torque, -u_j (theta_(j+1) - theta_j) (m g l rad)
        th = ys[3, ::2 * self.intervals] - ys[2, ::2 * self.intervals]
        for j in range(n):
            work += elec(-u[j] * (th[j + 1] - th[j]))
        obj = -(work + self.kappa * (energy(ys[:, -1]) - energy(p_y0)) / tu)
        par = ca.vertcat(p_y0, ca.reshape(p_mu, -1, 1), ca.reshape(p_f, -1, 1))
        neq = ca.vertcat(*cons).shape[0]
        # the generator's speed within what the plant's steps resolve
        cons.append((ys[7, 1:] - ys[6, 1:]).T)
        gcat = ca.vertcat(*cons)
        self.ng = gcat.shape[0]
        vmax = self.max_turn / pl.h if self.max_turn else np.inf
        self.lbg = np.concatenate((np.zeros(neq), np.full(npt - 1, -vmax)))
        self.ubg = -self.lbg
        self._obj = ca.Function("obj", [xs, par], [obj])
        self._sym = (xs, par, obj, gcat)  # the NLP's expressions (the compiled one's check)
        self.solver = ca.nlpsol("hullcol", "ipopt", {"x": xs, "p": par, "f": obj, "g": gcat},
                                {"ipopt": self.options, "print_time": False})

    # -- the parameters of one update --------------------------------------------------------
    def kernel(self):
        """``K(q h)`` (nk + 1, 3, 3) from the plant's trapezoidal weights."""
        k = self.plant.w / self.plant.h
        k[0] *= 2.0
        k[-1] *= 2.0
        return k

    def horizon_weights(self):
        """``Wh`` (ncp, ncp, 3, 3): the memory of the horizon's own velocities at every memory
        node, the trapezoid on the nodes over ``[t, t_j]`` (cut at the memory's end)."""
        kern, sr, hs = self.kernel(), self.ratio * self.stride, self.spacing * self.stride
        nk = kern.shape[0] - 1
        ncp = self.ncp
        out = np.zeros((ncp, ncp, 3, 3))
        for k in range(1, ncp):
            for i in range(k + 1):  # the lag k - i
                lag = (k - i) * sr
                if lag > nk:
                    continue
                c = 0.5 if (i == k or i == 0 or lag == nk) else 1.0
                out[k, i] = c * hs * kern[lag]
        return out

    def _weight_matrix(self):
        """:meth:`horizon_weights` as a (3 ncp, 3 ncp) matrix on ``(node, dof)`` (kept: the
        plant's kernels are fixed)."""
        if getattr(self, "_wmat", None) is None:
            wh = self.horizon_weights()
            self._wmat = wh.transpose(0, 2, 1, 3).reshape(3 * self.ncp, 3 * self.ncp)
        return self._wmat

    def _interpolation(self):
        """(ncp, npt): the memory at every point, linear between its nodes."""
        out = np.zeros((self.ncp, self.npt))
        for k in range(self.npt):
            j, r = divmod(k, self.stride)
            f = r / self.stride
            out[j, k] += 1.0 - f
            if f:
                out[j + 1, k] += f
        return out

    def past_memory(self):
        """The memory force of the velocities before now at every memory node (3, ncp): the
        plant's trapezoid on its step over ``[t_j - memory, t]``."""
        pl = self.plant
        kern, nk, h = self.kernel(), pl.nk, pl.h
        past = pl.vel[pl.k0:pl.k0 + nk + 1]  # oldest first; the last is now
        out = np.zeros((3, self.ncp))
        for k in range(self.ncp):
            j = k * self.ratio * self.stride
            if j >= nk:
                break
            q = np.arange(j, nk + 1)
            c = np.ones(q.size)
            c[0] = c[-1] = 0.5
            out[:, k] = h * np.einsum("q,qij,qj->i", c, kern[q], past[nk - (q - j)])
        return out

    def guess(self, u0, fseg):
        """The plant's model rolled from the measured state under ``u0`` (m g l), held: the
        states at every point and the accelerations by differences."""
        pl, steps = self.plant, self.steps
        _, ys, _ = pl.roll(np.repeat(np.asarray(u0, float) * self.tu, steps), 1, fseg)
        ys = ys[::self.ratio]
        if not np.all(np.isfinite(ys)):
            ys = np.repeat(pl.y[None], self.npt, axis=0)
        return self._pack(ys, u0)

    def _with_memory(self, x, par):
        """``x`` with its memory nodes set from its velocities (the constraint's root)."""
        x = x.copy()
        vel = x[:self.nx].reshape(self.npt, 8)[::self.stride, 4:7].ravel()
        past = par[8:8 + 3 * self.ncp]
        x[self.nx + self.na + self.n:] = (past + self._weight_matrix() @ vel) / self.tu
        return x

    def _pack(self, ys, u0):
        npt, ni, nx, na = self._layout()
        a = np.gradient(ys[:, 4:], self.spacing, axis=0)  # (npt, 4)
        idx = np.stack([2 * np.arange(ni), 2 * np.arange(ni) + 1, 2 * np.arange(ni) + 2], 1)
        acc = a[idx.ravel()]  # (3 ni, 4)
        return np.concatenate((ys.ravel(), acc.ravel(), np.asarray(u0, float),
                               np.zeros(3 * self.ncp)))

    def shifted(self, m):
        """The previous solution shifted by ``m`` samples (the tail: its last point held at
        its velocity, the last torque repeated)."""
        x = self.prev
        npt, ni, nx, na = self._layout()
        ys = x[:nx].reshape(npt, 8)
        acc = x[nx:nx + na].reshape(ni, 3, 4)
        u = x[nx + na:nx + na + self.n]
        k = 2 * m * self.intervals
        ii = k // 2
        last = ys[-1].copy()
        tail_t = self.spacing * np.arange(1, k + 1)
        tail = np.repeat(last[None], k, axis=0)
        tail[:, :4] += tail_t[:, None] * last[None, 4:]
        ys = np.concatenate((ys[k:], tail))
        acc = np.concatenate((acc[ii:], np.zeros((ii, 3, 4))))
        u = np.concatenate((u[m:], np.full(m, u[-1])))
        return np.concatenate((ys.ravel(), acc.ravel(), u, np.zeros(3 * self.ncp)))

    def _params(self, fseg):
        """The NLP's parameters: the plant's state, the memory's past part, the forecast at
        the points (``fseg`` at the plant's half steps)."""
        return np.concatenate((self.plant.y, self.past_memory().ravel(order="F"),
                               fseg[::2 * self.ratio][:self.npt].T.ravel(order="F")))

    def simulate(self, u, fseg):
        """The collocation's motion (npt, 8) under the held torques ``u`` (m g l) from the
        plant's state: the NLP with the torques fixed (its only feasible point), from the
        plant's model rolled under them."""
        fseg = np.asarray(fseg)
        u = np.asarray(u, dtype=float)
        par = self._params(fseg)
        lb, ub = self.lbx.copy(), self.ubx.copy()
        sl = slice(self.nx + self.na, self.nx + self.na + self.n)
        lb[sl] = ub[sl] = u
        x0 = self._with_memory(self.guess(u, fseg), par)
        if self.solver_name == "compiled":
            return self.compiled.simulate(x0, par)[:self.nx].reshape(self.npt, 8)
        r = self.solver(x0=x0, p=par, lbx=lb, ubx=ub, lbg=self.lbg, ubg=self.ubg)
        return np.asarray(r["x"]).ravel()[:self.nx].reshape(self.npt, 8)

    # -- one solve --------------------------------------------------------------------------
    def start(self, fseg, u0):
        """The solve's start ``(x0, par)``: the previous solution shifted (``self.shift``
        samples; the first: the model rolled under ``u0``) at the plant's state, its memory
        nodes from its velocities, and the NLP's parameters."""
        fseg = np.asarray(fseg)
        par = self._params(fseg)
        if self.solver_name == "compiled":  # its last restoration: the model rolled
            self.compiled.rollout = lambda u: self._with_memory(self.guess(u, fseg), par)
        if self.prev is None:
            x0 = self.guess(u0, fseg)
        else:
            x0 = self.shifted(self.shift)
            x0[:8] = self.plant.y
        return self._with_memory(x0, par), par

    def solve(self, y0, fseg, u0, max_iter=None, tol=None):
        """The solver from :meth:`start` (:meth:`solve_from`), the solution kept for the next
        start. ``y0``: the plant."""
        x0, par = self.start(fseg, u0)
        warm = self.prev is not None
        r = self.solve_from(x0, par, max_iter, tol, warm=warm)
        if self.solver_name == "compiled" and r.status == 2:
            # a failed solve is tried again from the same start with the other barrier
            # update (monotone: another path), then from the model rolled under ``u0``
            nit = r.nit
            r = self.solve_from(x0, par, max_iter, tol, warm=warm, strategy="monotone")
            r.nit += nit
            if warm and r.status == 2:
                nit = r.nit
                xg = self._with_memory(self.guess(u0, fseg), par)
                r = self.solve_from(xg, par, max_iter, tol)
                r.nit += nit
        if r.status == 1 and (self.unfollowable(r.states) or self.drifts(r, fseg)):
            # a capped iterate whose motion turns faster than the plant's step resolves, or
            # whose torques the model does not follow, is not a plan (far from feasible:
            # such torques drove the pendulum of Hs 0.5 m bins past that speed, the runs
            # unresolved): a failed solve
            r.status, r.success, r.ipopt = 2, False, "failed"
        if r.status == 2 and (self.solver_name == "compiled" or self.unfollowable(r.states)):
            # failed: its start is the plan (the previous one continued) and the next start
            self.prev = x0
            u = np.clip(x0[self.nx + self.na:self.nx + self.na + self.n],
                        -self.torque_limit, self.torque_limit)
            r.x, r.full, r.states = u, x0, x0[:self.nx].reshape(self.npt, 8)
        return r

    def unfollowable(self, states):
        """Whether a planned motion ``states`` (npt, 8) turns the generator faster than the
        plant's step resolves (:data:`.control.RESOLVED` rad a step; the plan's bound is
        :data:`MAX_TURN`)."""
        from .control import RESOLVED

        speed = np.abs(states[1:, 7] - states[1:, 6]) * self.plant.h
        return bool(not np.all(speed <= RESOLVED))

    def drifts(self, r, fseg):
        """Whether the plant's model rolled under the torques of solve ``r`` applied before
        the next update (``self.shift`` samples, at least one; the forecast ``fseg``) leaves
        the planned generator angle by more than :data:`CAPPED_ANGLE_TOL` rad at a point:
        the plan's primal infeasibility where it is applied."""
        m, pl = max(1, min(self.shift, self.n)), self.plant
        ok, ys, _ = pl.roll(np.repeat(r.x[:m] * self.tu, self.steps), 1, np.asarray(fseg))
        rolled = ys[::self.ratio]
        planned = r.states[:rolled.shape[0]]
        gap = np.abs((rolled[:, 3] - rolled[:, 2]) - (planned[:, 3] - planned[:, 2]))
        return bool(not (ok and np.all(gap <= CAPPED_ANGLE_TOL)))

    def solve_from(self, x0, par, max_iter=None, tol=None, warm=False, strategy=None):
        """The solver (:data:`SOLVER` or the constructor's) from ``x0`` on the parameters
        ``par``. ``max_iter`` and ``tol``: IPOPT's are the constructor's (its options are
        fixed when the NLP is built), the compiled solver's these (None: the constructor's;
        ``warm``: ``x0`` a shifted solution; ``strategy``: its barrier update, None its
        default :data:`._hull_collocation_ipm.MU_STRATEGY`). Returns ``x`` (the held
        torques, m g l), ``fun``, ``status`` (0 solved, 1 capped, 2 failed), ``success``,
        ``nit``, ``ipopt``
        (the solver's status: IPOPT's return status, or solved, capped, failed) and
        ``states`` (the planned motion at the points, (npt, 8))."""
        if self.solver_name == "compiled":
            mi = self.options["max_iter"] if max_iter is None else int(max_iter)
            x, fun, status, nit = self.compiled.solve(
                x0, par, mi, self.tol if tol is None else float(tol), warm=warm,
                strategy=strategy)
            name = _COMPILED_STATUS[status]
        else:
            r = self.solver(x0=x0, p=par, lbx=self.lbx, ubx=self.ubx, lbg=self.lbg,
                            ubg=self.ubg)
            st = self.solver.stats()
            name = st.get("return_status", "")
            x, fun = np.asarray(r["x"]).ravel(), float(r["f"])
            status = 0 if name in _SOLVED else (1 if name in _CAPPED else 2)
            nit = int(st.get("iter_count", 0))
        if np.all(np.isfinite(x)):
            self.prev = x
        # IPOPT relaxes its bounds by 1e-8 relative: the torque applied is held to the limit
        u = np.clip(x[self.nx + self.na:self.nx + self.na + self.n], -self.torque_limit,
                    self.torque_limit)
        return SimpleNamespace(x=u, fun=fun, status=status, success=status == 0,
                               nit=nit, ipopt=name, states=x[:self.nx].reshape(self.npt, 8),
                               full=x)
