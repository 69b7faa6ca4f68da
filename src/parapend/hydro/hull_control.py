r"""Receding-horizon (causal) control of a pendulum in a hull that surges, heaves and pitches:
:func:`hull_mpc`, the hull's counterpart of :func:`parapend.hydro.control.buoy_mpc`.

The plant is the nonlinear pendulum in the 3-DOF hull integrated in the time domain
(:mod:`._hull_plant`: Cummins' equation with the 3 x 3 radiation memory, its kernels
tapered to a passive memory (:func:`memory_window`), and ``A_inf``, the
pendulum's reaction through the 4 x 4 mass matrix, RK4 on a fixed step). The memory kernels
``K_ij(t) = (2/pi) int B_ij(w) cos(w t) dw`` and ``A_inf,ij`` are the heaving buoy's
(:func:`.timedomain.radiation_kernel`, :func:`.timedomain.a_infinity`) applied to every
entry of the hull's ``B(w)``, ``A(w)`` as :meth:`.bem.HullHydro.coefficients` interpolates
them.

At every update (every ``update_interval`` peak periods) the planner solves the horizon
problem over ``H`` (default two peak periods): the held torques ``u_0..u_{n-1}`` (one per
torque sample, ``|u| <= T_max``) that maximize

    J = sum_j e(-u_j (theta_{j+1} - theta_j)) + kappa (E(t + H) - E(t)),

the (electrical, ``e`` the efficiency model smoothed at 0; mechanical without one) work of
the held torques plus the mechanical energy of hull and pendulum left at the horizon's end
(``kappa``: ``COLLOCATION_TERMINAL_WEIGHT`` = 0.5 times ``eta_g`` with the default planner,
``eta_g`` with L-BFGS-B; ``terminal="pendulum"``: the pendulum's alone), where the motion over
the horizon is the plant's own model run forward from the measured state and the memory of
the hull's past motion (the radiation over the horizon included exactly, not frozen) under
the forecast excitation of all three degrees of freedom: the record itself (``perfect``) or
an AR forecast of each fitted on the force measured so far (``ar``,
:class:`parapend.control.forecast.ARForecast`, as the buoy's; its window reaches before the
run's start, into the sea that set the hull's free motion). The default planner
(``planner="collocation"``, :mod:`._hull_collocation`) poses it with the motion as the
unknown, the plant's equations at Hermite-Simpson collocation points and a bound on the
generator's speed, solved by a compiled interior point on the exact Hessian
(:mod:`._hull_collocation_ipm`); ``planner="lbfgsb"`` shoots the held torques through the
plant's model instead, with the exact gradient (the plant's scheme run backwards,
:func:`._hull_plant.adjoint`) and L-BFGS-B with the torque bounds (the buoy's ``coupled``
planner, :class:`.control.CoupledHorizon`). Either is warm-started from the previous plan
shifted. The first update interval of the plan is applied to the plant, and the controller
moves on.

The mode (:func:`start_mode`, from the record optimum's motion): where the optimum rotates
or swings through the upright the run starts with the buoy's swing-up pump and hands over
once the pendulum turns over the top (in the optimum's sense: the pump mirrored where the
optimum turns against the sense of a positive pitch); a swing that stays below the upright
is planned from the hanging pendulum from the start. The headline, its storage correction
over whole repeats after the warm-up, the failed solves and the update times are
:func:`.control.closed_loop_result`'s.
"""

from __future__ import annotations

import math
import time
from types import SimpleNamespace

import numpy as np

from ..errors import ParameterError, check_int, check_range
from . import control as bc
from . import timedomain as td

__all__ = ["a_infinity_matrix", "check_timing", "hull_mpc", "hull_mpc_command", "memory_weights",
           "memory_window", "start_mode"]

#: torque samples per peak period, RK4 steps per sample (plant and model)
SAMPLES = 24
PLANT_STEPS = 6
#: the longest horizon (peak periods)
MAX_HORIZON = 10.0
#: without a torque limit, this many m g l bound the planned torque (the hull's record
#: optimum on its default sea peaks near 3 m g l)
DEFAULT_LIMIT = 4.0
#: the horizon's solver by default (``planner=None``): ``"collocation"``, the motion as the
#: unknown, solved by the compiled interior point (``_hull_collocation.SOLVER``; no CasADi),
#: or ``"lbfgsb"``, L-BFGS-B on the held torques shot through the plant's model. On the
#: default barge's 20-minute record (Hs 1 m, Tp 6 s, seed 0, 2 Tp of horizon, 4 of warm-up,
#: perfect forecast) L-BFGS-B realized 25.6 % of the record optimum (227.9 of 888.5 W; 337
#: of 1631 solves ended abnormally) and the collocation planner 98.0 % (871.1 W, none; 91.5 %
#: with the AR forecast)
PLANNER = "collocation"
#: each planner's controller name (the power matrix's ``buoy_controller``, ``horizon``'s
#: cost key): ``hull`` is L-BFGS-B's, its name from before collocation was the default
CONTROLLERS = {"lbfgsb": "hull", "collocation": "hull-collocation"}
#: L-BFGS-B iterations per horizon solve at most
MAX_ITER = 60
#: interior-point iterations per horizon solve at most (``planner="collocation"``): IPOPT's,
#: and the compiled solver's (the default) (a capped solve is applied): with 40 in place of
#: 100 the default barge's seeds 0 to 9 (perfect forecast) realized 92.2 % of the record
#: optimum (90.2 % with 100: the closed loop is chaotic), no solve failed, and the update's
#: p99 fell from 0.3 to 2.3 s to 0.63 to 1.12 s (benchmarks/hull_collocation_table.out.txt;
#: measured with its null-space step; with its KKT step and 100, the Te 8 s bin's closed
#: loop realized 243.5 W perfect and 316.4 W AR, a solve failed, against 40's 228.2 and
#: 165.1 W: a chaotic loop, 40 kept for the update's time)
COLLOCATION_ITER = 100
COMPILED_ITER = 40
#: the collocation planner's terminal weight by default, times ``eta_g``: with 0.5 it
#: realized 94.5 % (perfect forecast) and 87.7 % (AR) of the record optimum on the default
#: barge's seeds 0 to 9, with 1 73.2 % and 89.4 % (benchmarks/hull_collocation_table.out.txt)
COLLOCATION_TERMINAL_WEIGHT = 0.5
#: the planned generator speed is penalized beyond this turn (rad) per plant step, with this
#: weight (units m g l rad per (rad/s)^2)
RESOLVED_TURN = 0.2
SPEED_WEIGHT = 10.0
#: the radiation memory by default, in peak periods, its kernels tapered by
#: :func:`memory_window` (a BEM's kernels, cut at its highest frequency, ring for a minute at
#: a few per cent of ``K(0)``): 10 peak periods keep the damping within 1 % of ``B(w)`` from
#: 0.5 to 2.5 times the peak frequency (the embedded barge, Tp 5.5 to 9 s; 4 peak periods:
#: 3 %, 2: 9 %). The collocation planner's cost does not grow with it (its memory couples
#: the horizon's own motion, and the past's is one sum an update); the L-BFGS-B planner's
#: gradient does
MEMORY_PERIODS = 10.0


def _entry(hull, i, j):
    """One entry ``(i, j)`` of the hull's coefficients in the form the heaving buoy's
    time-domain functions read (``omega``, ``radiation_damping``, ``added_mass``)."""
    return SimpleNamespace(omega=hull.omega, radiation_damping=hull.radiation_damping[:, i, j],
                           added_mass=hull.added_mass[:, i, j])


def radiation_kernels(hull, t) -> np.ndarray:
    """``K_ij(t)`` (t.shape + (3, 3)): :func:`.timedomain.radiation_kernel` of every entry
    (the matrix is symmetric)."""
    t = np.asarray(t, dtype=float)
    out = np.empty(t.shape + (3, 3))
    for i in range(3):
        for j in range(i, 3):
            out[..., i, j] = out[..., j, i] = td.radiation_kernel(_entry(hull, i, j), t)
    return out


def a_infinity_matrix(hull) -> np.ndarray:
    """``A_inf`` (3, 3): the median of :func:`.timedomain.a_infinity`'s estimates per entry."""
    out = np.empty((3, 3))
    for i in range(3):
        for j in range(i, 3):
            out[i, j] = out[j, i] = float(np.median(td.a_infinity(_entry(hull, i, j))))
    return out


def memory_window(x):
    """Bohman's window on ``x = t / L`` in [0, 1] (zero beyond): ``(1 - x) cos(pi x) +
    sin(pi x) / pi``, the autocorrelation of a half cosine, so its Fourier transform is not
    negative. The kernels times it have the damping ``B(w)`` smoothed by that transform:
    positive semi-definite at every frequency as ``B(w)`` is (a passive memory; cut without
    a taper, the kernel's integral, its damping at zero frequency, is anything from -370 to
    +320 N s/m in the embedded barge's surge, which has no restoring force: a negative one
    drifts the hull away)."""
    x = np.clip(np.asarray(x, dtype=float), 0.0, 1.0)
    return (1.0 - x) * np.cos(math.pi * x) + np.sin(math.pi * x) / math.pi


def memory_weights(hull, h, memory=None):
    """Trapezoidal weights ``W_q`` (nk + 1, 3, 3) of ``mu = sum_q W_q xi'(t - q h)`` and
    ``nk``: the kernels times :func:`memory_window` over a memory ``memory`` seconds long,
    or (None) until every entry has fallen below 1e-4 of ``sqrt(K_ii(0) K_jj(0))`` (the
    buoy's rule, :func:`.timedomain._memory_weights`), at most 60 s."""
    if memory is None:
        tk = np.arange(0.0, 60.0 + h, h)
        kk = radiation_kernels(hull, tk)
        d0 = np.sqrt(np.abs(np.diagonal(kk[0])))
        ref = np.outer(d0, d0)
        big = np.nonzero(np.any(np.abs(kk) > 1e-4 * ref, axis=(1, 2)))[0]
        last = int(big[-1]) if big.size else 0
        nk = min(tk.size - 1, max(2, int(1.2 * last) + 2))
        kern = kk[:nk + 1]
    else:
        nk = max(2, math.ceil(check_range("memory", memory, 1e-6, 600.0, why="s") / h))
        kern = radiation_kernels(hull, np.arange(nk + 1) * h)
    w = kern * (h * memory_window(np.arange(nk + 1) / nk))[:, None, None]
    w[0] *= 0.5
    w[-1] *= 0.5
    return np.ascontiguousarray(w), nk


class HullPlant:
    """The closed loop's plant (:mod:`._hull_plant`): state, the hull's velocity history and
    memory force, and the model's matrices ``M_t``, ``C'``, ``G``."""

    def __init__(self, hull, pendulum, case, h, total_steps, memory, xi, xid, history):
        self.h = h
        self.w, self.nk = memory_weights(hull, h, memory)
        self.a_inf = a_infinity_matrix(hull)
        gm = np.asarray(case.G, dtype=float)
        self.gm = np.ascontiguousarray(gm)
        self.mt = np.ascontiguousarray(np.asarray(case.Mh, float) + self.a_inf
                                       + pendulum.mass * gm.T @ gm)
        self.mti = np.linalg.inv(self.mt)
        self.cp = np.ascontiguousarray(case.stiffness())
        self.g = float(hull.g)
        self.par = np.array([pendulum.mass, pendulum.length, pendulum.inertia,
                             pendulum.damping_coefficient, self.g])
        nk = self.nk
        self.vel = np.zeros((nk + total_steps + 1, 3))
        self.vel[:nk] = history(-np.arange(nk, 0, -1) * h)
        self.vel[nk] = xid
        mu0 = np.einsum("qij,qj->i", self.w, self.vel[:nk + 1][::-1])
        self.mus = np.array([mu0, mu0, mu0])
        self.k0 = 0
        self.y = np.concatenate((xi, [math.pi], xid, [0.0]))
        self.acc = np.zeros(3)

    def energy(self, y=None) -> float:
        """The mechanical energy of hull and pendulum (J; :func:`._hull_plant.energy`)."""
        from ._hull_plant import energy

        return float(energy(self.y if y is None else y, self.mt, self.cp, self.gm, self.par))

    def step(self, u, steps, fn):
        """Advance the plant over the held torques ``u`` (N m); True unless it diverged."""
        ok, ys, _ = self.roll(u, steps, fn, commit=True)
        return ok, ys

    def roll(self, u, steps, fn, keep=False, commit=False):
        """The plant (``commit``) or its model from the current state (a copy) over ``u``:
        ``(ok, ys, jac)``, ``jac`` the stages' Jacobians with ``keep``
        (:func:`._hull_plant.adjoint`)."""
        from ._hull_plant import roll

        n = u.size
        ns = n * steps
        ys = np.empty((n + 1, 8))
        jac = np.empty((ns if keep else 0, 4, 4, 12))
        if commit:
            y, vel, k0, mus, acc = self.y, self.vel, self.k0, self.mus, self.acc
        else:
            nk = self.nk
            vel = np.empty((nk + 1 + ns, 3))
            vel[:nk + 1] = self.vel[self.k0:self.k0 + nk + 1]
            y, k0, mus, acc = self.y.copy(), 0, self.mus.copy(), np.zeros(3)
        ok = roll(y, vel, k0, mus, np.ascontiguousarray(u, dtype=float), steps,
                  np.ascontiguousarray(fn), self.h, self.w, self.mti, self.cp, self.gm, self.par,
                  ys, acc, jac)
        if commit:
            self.k0 += ns
        return ok, ys, jac


class HullHorizon(bc.CoupledHorizon):
    """The hull's horizon problem of one update (module docstring): ``n`` held torques (units
    ``m g l``) of ``steps`` RK4 steps, the plant's model with its memory over the horizon,
    the exact gradient; :class:`.control.CoupledHorizon`'s L-BFGS-B."""

    def __init__(self, plant, n, steps, tu, torque_limit=None, efficiency=None, kappa=None,
                 terminal="total"):
        super().__init__(n, plant.h, steps, None, tu, torque_limit, efficiency, kappa)
        self.pendulum_only = terminal == "pendulum"
        self.plant = plant
        self.width = 1e-3  # the efficiency's kink smoothed over this work (units m g l rad)
        self.speed = RESOLVED_TURN / plant.h  # rad/s
        self.tol = 1e-9  # L-BFGS-B's ftol

    def hull_part(self, y) -> float:
        """The hull's own energy ``1/2 xi'^T M_t xi' + 1/2 xi^T C' xi`` (J) where the
        terminal value leaves it out (``terminal="pendulum"``), else 0."""
        if not self.pendulum_only:
            return 0.0
        pl = self.plant
        return float(0.5 * y[4:7] @ pl.mt @ y[4:7] + 0.5 * y[:3] @ pl.cp @ y[:3])

    def _reference(self, u0, y0, fnet):
        return y0  # the objective's offset alone (the hull's energy needs no reference)

    def fun(self, u, y0, fnet):
        from ._hull_plant import adjoint, denergy, energy

        pl, tu, n = self.plant, self.tu, self.n
        u = np.asarray(u, dtype=float)
        ok, ys, jac = pl.roll(u * tu, self.steps, fnet, keep=True)
        if not ok or not np.all(np.isfinite(ys)):
            self.grad[:] = 0.0
            return math.inf, self.grad.copy()
        th = ys[:, 3] - ys[:, 2]
        dw = np.diff(th)  # per sample
        wk = -u * dw  # work (units m g l rad)
        eg, em = self.eta
        a, b = 0.5 * (eg + 1.0 / em), 0.5 * (eg - 1.0 / em)
        root = np.sqrt(wk * wk + self.width ** 2)
        e = a * wk + b * (root - self.width)
        de = a + b * wk / root
        e_end = energy(ys[-1], pl.mt, pl.cp, pl.gm, pl.par) - self.hull_part(ys[-1])
        e_0 = energy(ys[0], pl.mt, pl.cp, pl.gm, pl.par) - self.hull_part(ys[0])
        # the speed the plant's steps resolve: a plan past it would be planned on the
        # integration's error (RK4 gains energy from a pendulum turning too fast per step)
        v = ys[1:, 7] - ys[1:, 6]
        over = np.maximum(np.abs(v) - self.speed, 0.0)
        f = (-(float(np.sum(e)) + self.kappa * (e_end - e_0) / tu)
             + SPEED_WEIGHT * float(np.sum(over * over)))
        # dJ / dy at the samples' ends: theta = phi - beta in the work, v in the penalty, E
        seeds = np.zeros((n + 1, 8))
        dth = np.zeros(n + 1)
        dth[1:] += de * u
        dth[:-1] -= de * u
        seeds[:, 3] += dth
        seeds[:, 2] -= dth
        pen = 2.0 * SPEED_WEIGHT * over * np.sign(v)
        seeds[1:, 7] += pen
        seeds[1:, 6] -= pen
        de_end = np.empty(8)
        denergy(ys[-1], np.eye(8), pl.mt, pl.cp, pl.gm, pl.par, de_end)
        if self.pendulum_only:
            de_end[:3] -= pl.cp @ ys[-1, :3]
            de_end[4:7] -= pl.mt @ ys[-1, 4:7]
        seeds[n] -= self.kappa * de_end / tu
        self.grad[:] = de * dw + tu * adjoint(jac, pl.w, self.steps, pl.h, seeds)
        return f - self.offset, self.grad.copy()


def _forecast(fn, j, a, span, dt, ps, ar, leads, before=None):
    """The force (nodes, 3) the planner is given at sample ``j`` (plant node ``a``): the
    record over the horizon (``ar`` None: perfect) or each DOF's AR forecast from the force
    measured at every torque sample up to now, after ``before`` (samples, 3): the force
    measured at the samples before the run's start."""
    if ar is None:
        return fn[a:a + span]
    nb = 0 if before is None else before.shape[0]
    past_t = dt * np.arange(-nb, j + 1)
    past = fn[:a + 1:2 * ps]
    if nb:
        past = np.concatenate((before, past))
    return np.stack([f.predict(j * dt, past_t, past[:, d], leads)
                     for d, f in enumerate(ar)], axis=1)


def _plan(prob, y0, fseg, u0, max_iter):
    """One horizon solve (a hook the causality tests wrap)."""
    return prob.solve(y0, fseg, u0, max_iter=max_iter, tol=prob.tol)


def _record_force(case, t):
    """The record's excitation (t.shape + (3,)): ``Re sum_k F(k w) a_k exp(i k w t)``."""
    fk = case.wave_force()
    wk = case.omega * np.arange(fk.shape[0])
    return np.real(np.exp(1j * np.multiply.outer(t, wk)) @ fk)


def _free_start(case):
    """The free hull's periodic motion (the pendulum's mass lumped at the pivot):
    ``(xi(0), xi'(0), history)``, ``history(t)`` the velocity (t.shape + (3,))."""
    nh = case.hull_harmonics
    fk = case.wave_force()
    xk = np.zeros((nh + 1, 3), dtype=complex)
    for k in range(1, nh + 1):
        xk[k] = np.linalg.solve(case.impedance(k), fk[k])
    wk = case.omega * np.arange(nh + 1)

    def history(t):
        return np.real(np.exp(1j * np.multiply.outer(t, wk)) @ (1j * wk[:, None] * xk))
    return np.real(np.sum(xk, 0)), history(np.zeros(1))[0], history


def hull_mpc(hull, pendulum, wave, *, peak_period, pivot=(0.0, 0.0), pitch_inertia=None,
             horizon=2.0, update_interval=0.125, samples=SAMPLES, plant_steps=PLANT_STEPS,
             warmup=4.0, repeats=1, torque_limit=None, efficiency=None, forecast="perfect",
             mode="swing", max_iter=None, memory=None, terminal_weight=None,
             terminal="total", planner=None, time_limit=None,
             deadline=None) -> bc.BuoyMPCResult:
    """Receding-horizon control of the pendulum in a surging, heaving, pitching hull in a
    periodic record (module docstring).

    Parameters
    ----------
    hull : parapend.hydro.bem.HullHydro
    pendulum : parapend.hydro.coupled.Pendulum
    wave : parapend.hydro.coupled.Wave
        The periodic record at the hull.
    peak_period : float
        ``Tp`` (s): the unit of ``horizon``, ``update_interval``, ``warmup`` and of the torque
        sample ``Tp / samples`` (rounded so that the record holds whole samples).
    pivot, pitch_inertia : the pivot ``(offset, height)`` from O (m) and the hull's pitch
        inertia (kg m^2; None: the hull's), as :func:`parapend.hydro.hull.make_case`.
    horizon, update_interval, warmup : float
        In peak periods.
    repeats : int
        Repeats of the record in the averaging window.
    torque_limit : float or None
        N m (None: ``DEFAULT_LIMIT`` times ``m g l``).
    efficiency : float, (eta_g, eta_m) or None
        Priced in the horizon objective and the electrical power.
    forecast : "perfect" or "ar"
    mode : "swing", "rotate" or "rotate-reversed"
        The start: planned from the hanging pendulum, or the swing-up pump until the
        pendulum turns over the top in the sense of a positive pitch (``rotate``) or
        against it (``rotate-reversed``: the pump mirrored, ``phi -> -phi``).
    max_iter : int or None
        Iterations per solve at most (None: ``MAX_ITER`` for L-BFGS-B,
        ``COMPILED_ITER`` for the collocation planner's compiled solver, ``COLLOCATION_ITER``
        for IPOPT).
    memory : float or None
        The radiation memory (s), its kernels tapered over it (:func:`memory_window`);
        None: ``MEMORY_PERIODS`` peak periods.
    terminal_weight : float or None
        ``kappa``, the weight of the energy left at the horizon's end (None: ``eta_g``;
        with ``planner="collocation"`` ``COLLOCATION_TERMINAL_WEIGHT`` times ``eta_g``).
    terminal : "total" or "pendulum"
        The energy the terminal value counts: all of ``E`` (hull and pendulum, the buoy's
        default), or the pendulum's (``E`` less the hull's own ``1/2 xi'^T M_t xi' + 1/2
        xi^T C' xi``; on the default barge, seeds 0 and 1, it harvested 40 and 110 W where
        ``total`` harvested 368 and 262 W).
    planner : "lbfgsb", "collocation" or None
        The horizon solve: L-BFGS-B on the held torques shot through the plant's model
        (module docstring), or the motion as the unknown, direct collocation solved by an
        interior point on the exact Hessian (``_hull_collocation``: the compiled one, or
        CasADi's IPOPT with ``_hull_collocation.SOLVER = "ipopt"``; ``plant_steps`` even).
        None: ``PLANNER``.
    time_limit, deadline : as :func:`.control.buoy_mpc`.

    Returns
    -------
    parapend.hydro.control.BuoyMPCResult
        ``theta`` the generator's angle ``phi - beta``; the series also hold ``x``, ``z``,
        ``beta`` (m, m, rad) and ``phi``.
    """
    from ..control.swingup import pump_torque, ready_to_catch
    from .hull import make_case

    tp = check_range("tp", peak_period, 1e-3, 1e4, why="s")
    samples = check_int("samples", samples, 4, 512)
    horizon, update_interval = check_timing(horizon, update_interval, samples)
    warmup = check_range("warmup", warmup, 0.0, 1e3, why="peak periods")
    repeats = check_int("repeats", repeats, 1, 100)
    ps = check_int("plant_steps", plant_steps, 1, 1024)
    planner = PLANNER if planner is None else planner
    if planner not in ("lbfgsb", "collocation"):
        raise ParameterError(f"planner: expected lbfgsb or collocation, got {planner!r:.40}")
    if max_iter is None and planner == "collocation":
        from . import _hull_collocation

        max_iter = COMPILED_ITER if _hull_collocation.SOLVER == "compiled" else COLLOCATION_ITER
    elif max_iter is None:
        max_iter = MAX_ITER
    max_iter = check_int("max_iter", max_iter, 1, 10000)
    if forecast not in ("perfect", "ar"):
        raise ParameterError(f"forecast: expected perfect or ar, got {forecast!r:.40}")
    if mode not in ("swing", "rotate", "rotate-reversed"):
        raise ParameterError(f"mode: expected swing, rotate or rotate-reversed, got "
                             f"{mode!r:.40}")
    sense = -1.0 if mode == "rotate-reversed" else 1.0  # the pump's, mirrored if reversed
    eta = bc._efficiency(efficiency)
    g = float(hull.g)
    tu = pendulum.mass * g * pendulum.length
    t0 = math.sqrt(pendulum.inertia / tu)
    limit_given = torque_limit is not None
    torque_limit = (DEFAULT_LIMIT * tu if torque_limit is None
                    else check_range("torque-limit", torque_limit, 1e-9, 1e12, why="N m"))
    tr = 2 * math.pi / wave.omega
    per_record = max(1, int(round(tr / (tp / samples))))
    dt = tr / per_record
    n = max(1, int(round(horizon * tp / dt)))
    m = max(1, min(n, int(round(update_interval * tp / dt))))
    warm_samples = int(round(warmup * tp / dt))
    total = planned = warm_samples + repeats * per_record
    bc._check_work(total, n, m, 1, warm_samples, repeats, dt, time_limit)
    if deadline is None and time_limit is not None:
        from ..deadline import deadline as _deadline

        deadline = _deadline(time_limit)
    h = dt / ps
    kw = wave.amplitudes.size
    case = make_case(hull, pendulum, wave, winding=0, harmonics=kw, hull_harmonics=kw,
                     pivot=pivot, pitch_inertia=pitch_inertia)
    fn = bc.force_nodes(hull, wave, per_record, ps, 2 * (total + n) * ps + 1)
    xi0, xid0, history = _free_start(case)
    memory = MEMORY_PERIODS * tp if memory is None else memory
    plant = HullPlant(hull, pendulum, case, h, total * ps, memory, xi0, xid0, history)
    ar = leads = before = None
    if forecast == "ar":
        from ..control.forecast import ARForecast

        ar = [ARForecast(tp) for _ in range(3)]
        leads = 0.5 * h * np.arange(2 * n * ps + 1)
        # the sea was there before the run (it set the hull's free motion at the start):
        # its force at the samples of the AR's window before t = 0, from the record's
        # harmonics (not from the run's nodes)
        nb = int(math.ceil(ar[0].window * tp / dt))
        before = _record_force(case, dt * np.arange(-nb, 0))
    if terminal_weight is not None:
        terminal_weight = check_range("terminal_weight", terminal_weight, 0.0, 10.0)
    if terminal not in ("pendulum", "total"):
        raise ParameterError(f"terminal: expected pendulum or total, got {terminal!r:.40}")
    if planner == "collocation":
        from ._hull_collocation import HullCollocation

        if terminal_weight is None:
            terminal_weight = COLLOCATION_TERMINAL_WEIGHT * (1.0 if eta is None else eta[0])
        prob = HullCollocation(plant, n, ps, tu, torque_limit / tu, eta, terminal_weight,
                               terminal, max_iter=max_iter)
        prob.shift = m
    else:
        prob = HullHorizon(plant, n, ps, tu, torque_limit / tu, eta, terminal_weight, terminal)
    level = min(torque_limit / tu, 1.0)
    ys = np.empty((total + 1, 8))
    ys[0] = plant.y
    acc = np.zeros((total + 1, 3))
    energy = np.empty(total + 1)
    energy[0] = plant.energy()
    u_all = np.zeros(total)
    caught = 0 if mode == "swing" else None
    braking = False
    plan = np.zeros(n)
    times = []
    solves = failed = kept = 0
    status = "ok"
    j = 0
    while j < total:
        phi, om = sense * plant.y[3], sense * plant.y[7] * t0
        if caught is None and ready_to_catch(phi, om, bc.CATCH_MARGIN):
            caught = j
        if caught is None:
            tq, braking = pump_torque(phi, om, level, bc.CATCH_MARGIN, braking)
            seg = np.array([sense * tq])
        else:
            if solves and deadline is not None and time.monotonic() >= deadline:
                status, total = "time_limit", j
                break
            a = 2 * j * ps
            tic = time.perf_counter()  # the forecast is part of the update's time
            fseg = _forecast(fn, j, a, 2 * n * ps + 1, dt, ps, ar, leads, before)
            u0 = np.concatenate((plan[m:], np.full(m, plan[-1]))) if solves else plan
            res = _plan(prob, plant, fseg, u0, max_iter)
            u, bad = bc._check_solve(res, plan)
            times.append(time.perf_counter() - tic)
            solves += 1
            failed += bad > 0
            kept += bad == 2
            plan = u
            seg = plan[:min(m, total - j)]
        done, ok = bc.apply_segment(plant, seg, j, tu, ps, fn, ys, acc, energy, u_all)
        if not ok:
            status, total = "diverged", j + done
            break
        j += done
    ys, acc, energy, u_all = ys[:total + 1], acc[:total + 1], energy[:total + 1], u_all[:total]
    series = {"theta": ys[:, 3] - ys[:, 2], "theta_dot": ys[:, 7] - ys[:, 6], "z": ys[:, 1],
              "z_dot": ys[:, 5], "x": ys[:, 0], "x_dot": ys[:, 4], "beta": ys[:, 2],
              "beta_dot": ys[:, 6], "phi": ys[:, 3]}
    ai = np.diagonal(plant.a_inf)
    return bc.closed_loop_result(
        series, acc, energy, u_all, status=status, caught=caught, dt=dt, h=h,
        per_record=per_record, repeats=repeats, planned=planned, warm_samples=warm_samples,
        n=n, m=m, eta=eta, times=times, changes=[], residuals=[], solves=solves,
        failed=failed, kept=kept, iterations=1, solves_per_update=1, relaxation=1.0,
        controller=f"hull-{mode}" if planner == "lbfgsb" else f"hull-{planner}-{mode}",
        forecast=forecast, torque_limit=torque_limit,
        limit_given=limit_given, pendulum=pendulum, plant=plant,
        units={"time_s": t0, "torque_nm": tu, "power_w": tu / t0, "a_inf_surge_kg": ai[0],
               "a_inf_heave_kg": ai[1], "a_inf_pitch_kg_m2": ai[2],
               "memory_s": plant.nk * h, "memory_window": "bohman",
               "plant_step_s": h})


def check_timing(horizon, update_interval, samples=SAMPLES, name="horizon") -> tuple:
    """The horizon and the update interval (peak periods) :func:`hull_mpc` takes, checked
    (one line naming the option): a horizon of 0.05 to ``MAX_HORIZON``, an update of at
    least one torque sample (``1 / samples``) and at most the horizon. For the commands
    that run it later (the power matrix, ``horizon``: a value it refuses is refused
    before any work; ``name``: the horizon's option)."""
    horizon = check_range(name, horizon, 0.05, MAX_HORIZON, why="peak periods")
    update_interval = check_range("update-interval", update_interval, 1.0 / samples, 20.0,
                                  why="peak periods")
    if update_interval > horizon:
        raise ParameterError(f"update-interval: expected at most the horizon {horizon:g} peak "
                             f"periods, got {update_interval:g}")
    return horizon, update_interval


def start_mode(winding, mean_angle_deg=None, swing_amplitude_deg=None) -> str:
    """The closed loop's start from the record optimum's motion: ``"rotate"`` (the swing-up
    pump until the pendulum turns over the top, in the optimum's sense: ``"rotate-reversed"``
    where its winding is negative) when the optimum rotates (``winding`` not 0)
    or swings through the upright (a multiple of 360 degrees within ``mean_angle_deg +-
    swing_amplitude_deg``, the absolute angle from the upward vertical), else ``"swing"``
    (planned from the hanging pendulum). Measured on the default barge's seas, whose
    optima swing through the upright: the pump's start reached 44 % of the optimum where the
    hanging start reached 30 % (mean over seeds 0 to 5, docs/hull.md)."""
    from .result import through_upright

    if winding:  # rotation, or a swing with net turns (over the top: through the upright)
        return "rotate" if winding > 0 else "rotate-reversed"
    if mean_angle_deg is None or swing_amplitude_deg is None:
        return "swing"
    return "rotate" if through_upright(mean_angle_deg, swing_amplitude_deg) else "swing"


def hull_mpc_command(problem, wave, info, sol, *, horizon, update_interval, forecast,
                     planner=None, deadline=None):
    """``parapend buoy --dofs surge,heave,pitch --controller mpc``: the record's non-causal
    optimum ``sol`` (:func:`parapend.hydro.api.solve_record`, rotation and swinging) and the
    closed loop on the record in its mode (4 peak periods of warm-up, one repeat), the
    storage-corrected mean beside it: ``optimum_fraction`` is the electrical power over the
    optimum's (with the problem's torque limit and efficiency in both)."""
    import dataclasses

    winding = int(sol.winding) if sol.winding is not None else 0
    pto = problem["pto"]
    r = hull_mpc(problem["hull"], problem["pendulum"], wave, peak_period=float(info["tp"]),
                 pivot=problem["pivot"], pitch_inertia=problem["pitch_inertia"],
                 horizon=horizon, update_interval=update_interval, forecast=forecast,
                 torque_limit=pto.torque_limit, efficiency=pto.efficiency,
                 mode=start_mode(winding, sol.mean_angle_deg, sol.swing_amplitude_deg),
                 planner=planner, deadline=deadline)
    opt = float(sol.power_w) if sol.success and sol.power_w is not None else None
    frac = (r.electrical_power_w / opt if opt is not None and opt > 0
            and math.isfinite(r.electrical_power_w) else None)
    warnings = r.warnings
    if frac is not None and frac > 1 + bc.REFERENCE_TOL:
        warnings += (f"the causal run reaches {frac:.4g} of the non-causal reference, above "
                     "1: the reference is not the record's optimum on this plant (its "
                     "memory and steps differ from the frequency domain's)",)
    return dataclasses.replace(r, optimum_power_w=opt, optimum_fraction=frac,
                               optimum_resolved=bool(sol.success), optimum_winding=winding,
                               wave=info, warnings=warnings)
