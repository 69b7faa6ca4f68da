r"""Receding-horizon control of the pendulum inside the floating buoy (docs/buoy.md).

The PLANT is the coupled time-domain model of :mod:`.timedomain`: Cummins' equation with the
radiation memory for the heave, the pendulum's reaction ``m l (cos theta)''`` loading it, and
Eq. 1 for the pendulum, driven by the record's excitation force ``F_exc(t)`` and integrated
by the same scheme (:mod:`._control_kernel`; ``plant_steps`` RK4 steps per torque sample).

The CONTROLLER measures the pendulum's state and the buoy's (``z``, ``z'`` and the past
``z'`` the memory needs), knows ``F_exc`` over the horizon (perfect forecast), and plans the
torque with the pendulum's horizon problem (:class:`parapend.control.mpc.HorizonProblem`,
pendulum units: time ``t0 = sqrt(I / (m g l))``, torque ``m g l``, ``q = z'' / g``,
``gamma = c t0 / I``). Two controllers:

- ``"coupled"``: the horizon problem on the coupled model itself: heave and pendulum
  integrated together (the 2x2 mass matrix of :mod:`.timedomain`), maximizing the harvested
  work plus ``kappa`` times the mechanical energy of buoy AND pendulum at the horizon's end
  (docs/buoy.md: with the pendulum's energy alone the plan drains the buoy into the
  pendulum's spin), solved by L-BFGS-B with the exact adjoint gradient
  (:func:`._control_kernel.plan_objective`). The radiation memory force over the horizon
  is predicted by the plant's model under the current plan and frozen in the solve; it is
  predicted again under the new plan and the problem solved again, ``iterations`` times
  (with ``relaxation`` ``alpha``: ``mu <- (1 - alpha) mu + alpha mu(plan)``). The change of
  ``mu`` and its residual after the last solve are recorded.
- ``"one-way"``: the pendulum MPC planning on the FREE buoy's heave (the buoy's response to
  the record without the pendulum, from the same start, by the plant's own model), ignoring
  its reaction; one solve per update.
- ``"plan"``: the pendulum's MOTION as the unknown, as the pendulum's planner
  (:mod:`parapend.control.plan`): the angle a C1 cubic Hermite on the horizon, the heave
  Cummins' equation as the plant has it: the buoy's free response from its measured state
  and radiation memory under ``F_exc`` (the plant's own model, without the pendulum) plus
  the pendulum's reaction through the plant's impulse response, a causal convolution of
  ``cos(theta)``; the torque by inverse dynamics on that heave, bounded at three points per
  interval; the objective the ``coupled`` controller's (work plus the energy of buoy and
  pendulum at the end: ``F_exc`` less the past's memory force against ``z'``, less the
  energy the plan's own motion radiates), the model run on ``PLAN_TAIL`` peak periods past
  the forecast's horizon with no excitation (the stored energy valued at what can still be
  harvested from it: :class:`_MotionPlanner`); a dense primal-dual interior point with the
  exact Hessian (:mod:`._buoy_plan`), one solve an update, warm-started from the previous
  motion. The held torques are the plan's torque averaged over each sample. Without
  efficiency (mechanical only). ``radiation_model=False``: the planner before, the memory
  force predicted under the previous plan and frozen in an undamped oscillator.
- ``"fixed-point"``: the pendulum MPC planning on the heave the coupled model predicts under
  its current plan, predicted again under the new plan, ``iterations`` times (plan <->
  heave); it does not converge for a heavy pendulum (docs/buoy.md).

Both start from the hanging rest with the swing-up of :mod:`parapend.control.swingup` (the
buoy in its free periodic motion, the sea already running), as the pendulum MPC does, and
hand over to the horizon solves when the pendulum rotates forward above the top's energy.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError, check_int, check_range
from ..results import _Result
from .result import _solve

__all__ = ["BuoyMPCResult", "buoy_mpc", "record_force"]

#: torque samples per peak period
SAMPLES = 64
#: RK4 steps per torque sample in the horizon model / in the plant (and the prediction)
MODEL_STEPS = 4
PLANT_STEPS = 8
#: the swing-up hands over above the top's energy by this margin (as the pendulum MPC)
CATCH_MARGIN = 0.05
#: without a torque limit, this many m g l bound the planned torque
DEFAULT_LIMIT = 2.0
#: a run whose pendulum turns more than this (rad) in one plant step is not resolved
RESOLVED = 0.5
CONTROLLERS = ("coupled", "fixed-point", "one-way", "plan")
#: the non-causal reference is resolved when its refinement N -> 2N changed it by at most
#: this (relative), and a causal run's fraction of it may exceed 1 by at most this
REFERENCE_TOL = 1e-3
#: ``plan``: torque samples per Hermite interval of the motion
PLAN_INTERVAL_SAMPLES = 4
#: ``plan``: interior-point iterations per solve at most
PLAN_MAX_ITER = 100
#: ``plan``: the horizon model runs on this many peak periods past the forecast's horizon
#: ``H`` with no excitation (the value of the state at ``H``; :class:`_MotionPlanner`)
PLAN_TAIL = 1.0


@dataclass(frozen=True, eq=False, repr=False)
class BuoyMPCResult(_Result):
    """One closed-loop run of the receding-horizon controller on the buoy (SI units).

    Attributes
    ----------
    planner, forecast : str
        The planner that ran (:func:`buoy_mpc`'s ``controller``: ``plan``, ``coupled``,
        ``one-way`` or ``fixed-point``) and what it knew of the force over
        the horizon (``perfect`` or ``ar``).
    mean_power_w : float
        The headline: over the last ``repeats`` whole repeats of the record (after the
        start-up ``average_from_s``), the harvested (mechanical) energy plus the change of
        the stored energy (buoy and pendulum, ``stored_energy_change_j``) per unit time,
        ``harvested_power_w + stored_w``: the energy left in the device counted as
        harvested and energy drawn from it as not, so a storage swing cannot flip it;
        comparable with the record's periodic optimum (``parapend.buoy`` with the same
        record).
    electrical_power_w : float
        The same through the efficiency model, the stored energy counted at ``eta_g``
        (equal without one).
    harvested_power_w, harvested_electrical_power_w : float
        The harvested energy alone per unit time over the same window, ``-<tau theta'>``
        (exact for the held torque; the mean of the saved ``power`` series there), and its
        electrical counterpart.
    harvested_energy_j, stored_energy_change_j : float
        ``W``, and ``E(end) - E(average_from_s)`` of the mechanical energy of buoy and
        pendulum (``_Plant.energy``), in J.
    absorbed_w, damping_w, stored_w : float
        Over the same window: the mean power the buoy absorbs from the waves
        ``<(F_exc - mu) z'>`` (excitation less radiation, ``mu`` the memory force), the
        pendulum's damping ``c <theta'^2>``, and ``stored_energy_change_j`` divided by the
        window's length.
    energy_balance_residual : float
        ``|harvested + damping + stored - absorbed|`` over ``absorbed``: the plant's energy
        balance.
    fixed_point_change : list
        ``coupled``: median over the updates of the relative change of the predicted ``q``
        at each iteration (``||q_k - q_{k-1}|| / ||q_k||``, k = 1..iterations - 1).
    fixed_point_residual : float or None
        ``coupled``: median over the updates of ``||q(plan) - q|| / ||q||`` for the applied
        plan, the heave it makes against the heave it was planned on (one extra prediction
        per update, outside the timed part).
    update_time_first_s : float or None
        Wall time of the first update's planning (it loads or compiles the kernels),
        reported apart.
    update_time_median_s, update_time_p99_s, update_time_max_s : float or None
        Wall time of one update (the forecast, every solve and prediction; a perfect
        forecast is the record itself, precomputed) over the updates after the first, on
        this process.
    realtime_fits : bool or None
        Whether ``update_time_p99_s`` fits in ``update_interval_s``.
    failed_kept_previous : int
        Of ``failed_solves``, those whose iterate was not finite, after which the previous
        plan went on (the others applied their last iterate).
    """

    planner: str
    forecast: str
    mean_power_w: float
    electrical_power_w: float
    harvested_power_w: float
    harvested_electrical_power_w: float
    harvested_energy_j: float
    stored_energy_change_j: float
    absorbed_w: float
    damping_w: float
    stored_w: float
    energy_balance_residual: float
    peak_torque_nm: float
    heave_amplitude_m: float
    catch_time_s: float | None
    horizon_s: float
    update_interval_s: float
    dt_s: float
    average_from_s: float
    t_end_s: float
    iterations: int
    relaxation: float
    fixed_point_change: list
    fixed_point_residual: float | None
    solves: int
    failed_solves: int
    update_time_first_s: float | None
    update_time_median_s: float | None
    update_time_p99_s: float | None
    update_time_max_s: float | None
    realtime_fits: bool | None
    failed_kept_previous: int
    torque_limit_nm: float
    torque_limit_given: bool
    efficiency: tuple | None
    success: bool
    status: str
    message: str
    pendulum: dict
    units: dict
    headline_reason: str | None = None
    warnings: tuple = ()
    optimum_power_w: float | None = None
    optimum_fraction: float | None = None
    optimum_resolved: bool | None = None
    optimum_winding: int | None = None
    wave: dict | None = None
    convention: str = ("theta from the upright (hanging at rest is theta = pi), z up from "
                       "the static equilibrium; power positive when harvested, "
                       "P = -<tau theta'>")
    _samples: dict = field(default=None, repr=False)
    _plant: object = field(default=None, repr=False)
    #: every update's wall time (s), the first included: ``parapend horizon --device buoy``
    #: pools them over its records
    _update_times: object = field(default=None, repr=False)

    command = "buoy"
    headline = ("mean_power_w", "electrical_power_w", "harvested_power_w", "stored_w",
                "failed_solves", "status")

    @property
    def series(self) -> dict:
        """``t`` (s, sample times), ``theta``, ``theta_dot``, ``z``, ``z_dot`` there,
        ``torque`` (N m, held over ``[t_k, t_k+1)``) and ``power`` (W, each sample's mean)."""
        return self._samples

    def _series(self):
        """The series (SI; the torque's and power's last value ``nan``: no interval)."""
        import xarray as xr

        s = self._samples
        cols = {"theta": s["theta"], "theta_dot_rad_per_s": s["theta_dot"],
                "heave_m": s["z"], "heave_speed_m_per_s": s["z_dot"],
                "torque_nm": np.append(s["torque"], np.nan),
                "sample_power_w": np.append(s["power"], np.nan)}
        ds = xr.Dataset({k: ("time_s", v) for k, v in cols.items()},
                        coords={"time_s": s["t"]})
        ds["torque_nm"].attrs["hold"] = "over [t, t + dt)"
        return ds

    def _figure(self):
        """Heave, the generator's speed, held torque and harvested energy against time, the
        averaging window's start marked."""
        from ..plotting import plt
        from ..style import figure_style

        s = self._samples
        t = np.asarray(s["t"])
        e = np.concatenate(([0.0], np.cumsum(np.asarray(s["power"]) * np.diff(t))))
        with figure_style():
            fig, ax = plt.subplots(4, 1, figsize=(7, 8.5), sharex=True)
            ax[0].plot(t, s["z"], lw=1.0, color="C1")
            ax[0].set_ylabel("heave z (m)")
            ax[1].plot(t, s["theta_dot"], lw=0.8, color="C2")
            ax[1].set_ylabel(r"generator speed $\dot\theta$ (rad/s)")
            ax[2].step(t, np.append(s["torque"], s["torque"][-1]), where="post", lw=0.8,
                       color="C3")
            ax[2].set_ylabel(r"torque $\tau$ (N m)")
            ax[3].plot(t, e, lw=1.0, color="C0")
            ax[3].set_ylabel("harvested energy (J)")
            ax[3].set_xlabel("time t (s)")
            if self.average_from_s is not None:
                for a in ax:
                    a.axvline(self.average_from_s, color="0.6", lw=0.8, ls="--")
            head = (f"mean power {self.mean_power_w:.4g} W (harvested "
                    f"{self.harvested_power_w:.4g} W + stored {self.stored_w:.4g} W) from "
                    f"{self.average_from_s:.4g} s" if self.headline_reason is None else
                    f"no mean power ({self.status})")
            body = "hull" if self.planner.startswith("hull") else "buoy"
            ax[0].set_title(f"{body}, {self.planner}, {self.forecast} forecast:\n{head}",
                            fontsize=10)
            fig.tight_layout()
        return fig


def _periodic(coefs, omega, period, points, count):
    """``Re sum_k c_k exp(i k omega t)`` (k = 1..K) at ``t = j period / points``,
    ``j = 0..count - 1`` (the periodic record tiled)."""
    coefs = np.asarray(coefs, dtype=complex)
    k = coefs.size
    if k >= points // 2:
        raise ParameterError("samples: too few samples per record for its components")
    spec = np.zeros(points // 2 + 1, dtype=complex)
    spec[1:k + 1] = coefs * (points / 2.0)
    one = np.fft.irfft(spec, points)
    reps = -(-count // points)
    return np.tile(one, reps)[:count]


def record_force(hydro, wave):
    """The excitation force ``F_exc(t)`` (N) of a periodic wave at the buoy, as a vectorized
    callable (``Re sum_k F(k w) a_k exp(i k w t)``)."""
    kk = np.arange(1, wave.amplitudes.size + 1)
    _, _, f = hydro.coefficients(kk * wave.omega)
    c = f * np.asarray(wave.amplitudes)

    def force(t):
        t = np.asarray(t, dtype=float)
        return np.real(np.exp(1j * np.multiply.outer(t, kk * wave.omega)) @ c)
    return force


def _check_work(total, n, m, iterations, warm, repeats, dt, time_limit=None):
    """Refuse, before any work, a run whose horizon solves (updates x horizon samples x
    solves per update) exceed :data:`parapend.limits.BUOY_MAX_MPC_WORK`, naming the longest
    record that fits; with ``time_limit`` the run goes under it instead
    (:mod:`parapend.deadline`)."""
    from .. import limits

    cap = limits.BUOY_MAX_MPC_WORK
    work = math.ceil(total / m) * n * iterations
    if work <= cap or time_limit is not None:
        return
    most = (cap / (n * iterations) * m - warm) / repeats * dt
    fits = (f"use --repeat-period at most {most:.4g} s (or --record that long), or a shorter "
            "--horizon or a longer --update-interval" if most > 0 else
            "use a shorter --horizon or a longer --update-interval")
    raise ParameterError(f"repeat-period: a receding-horizon run of {math.ceil(total / m)} "
                         f"updates x {n} horizon samples x {iterations} solves is more than "
                         f"finishes in about two minutes ({cap:.3g}); {fits}, or give "
                         "--time-limit SECONDS (a partial result, marked time_limit)")


def force_nodes(hydro, wave, per_record, plant_steps, count):
    """``F_exc`` (N) at the plant's half-step nodes ``t = j T_r / (2 per_record
    plant_steps)``, ``j = 0..count - 1``; a hull's (:class:`.bem.HullHydro`) three, one
    column each (surge N, heave N, pitch N m)."""
    kk = np.arange(1, wave.amplitudes.size + 1)
    _, _, fk = hydro.coefficients(kk * wave.omega)
    a = np.asarray(wave.amplitudes)
    cols = (np.asarray(fk).reshape(a.size, -1) * a[:, None])
    out = np.stack([_periodic(cols[:, d], wave.omega, 2 * math.pi / wave.omega,
                              2 * per_record * plant_steps, count)
                    for d in range(cols.shape[1])], axis=1)
    return out if np.ndim(fk) == 2 else out[:, 0]


def free_motion(hydro, wave):
    """The free buoy's periodic heave: ``(Z_k, k w)`` with ``Z_k = F a_k / D`` (m)."""
    kk = np.arange(1, wave.amplitudes.size + 1)
    w = kk * wave.omega
    return hydro.free_response(w) * np.asarray(wave.amplitudes), w


class _Plant:
    """The coupled plant (and the controller's copy of it): state, velocity history, memory."""

    def __init__(self, hydro, pendulum, h, total_steps, memory, a_inf, z0, zd0, history):
        from . import timedomain as td

        self.h = h
        self.w, self.nk = td._memory_weights(hydro, h, memory)
        self.a_inf = td._a_inf(hydro, a_inf, None, td.a_infinity(hydro))
        m, ell = pendulum.mass, pendulum.length
        self.g = float(hydro.g)
        self.p = np.array([hydro.mass + self.a_inf, hydro.hydrostatic_stiffness, m * ell,
                           pendulum.inertia, pendulum.damping_coefficient, self.g])
        self.mgl = m * self.g * ell
        nk = self.nk
        self.vel = np.zeros(nk + total_steps + 1)
        if history is not None:
            self.vel[:nk] = np.asarray(history(-np.arange(nk, 0, -1) * h), dtype=float)
        self.vel[nk] = zd0
        mu0 = float(self.w @ self.vel[:nk + 1][::-1])
        self.mus = np.array([mu0, mu0, mu0])
        self.k0 = 0
        self.y = np.array([z0, zd0, math.pi, 0.0])
        self.acc = np.zeros(3)

    def energy(self, y=None) -> float:
        """Mechanical energy of buoy and pendulum (J), zero for both at rest, pendulum up."""
        z, zd, th, om = self.y if y is None else y
        mt, cst, ml, inertia = self.p[0], self.p[1], self.p[2], self.p[3]
        return (0.5 * mt * zd * zd - ml * math.sin(th) * zd * om + 0.5 * inertia * om * om
                + 0.5 * cst * z * z + ml * self.g * math.cos(th))

    def step(self, u, steps, fn):
        """Advance the plant over the held torques ``u`` (N m); True unless it diverged."""
        from ._control_kernel import advance

        n = u.size
        ys = np.empty((n + 1, 4))
        zdd = np.empty(2 * n * steps + 1)
        ok = advance(self.y, self.vel, self.k0, self.mus, np.asarray(u, float), steps, fn,
                     self.h, self.w, self.p, ys, zdd, self.acc, np.empty_like(zdd))
        self.k0 += n * steps
        return ok, ys

    def predict(self, u, steps, fn, memory_force=False, velocity=False):
        """The heave acceleration (m/s^2) at the half-step nodes under the held torques ``u``
        from the current state, without changing the plant (and, with ``memory_force``, the
        memory force there, N, and with ``velocity`` also the heave speed, m/s, at the step
        points from now on); None if it diverged."""
        from ._control_kernel import advance

        nk, n = self.nk, u.size
        vel = np.empty(nk + 1 + n * steps)
        vel[:nk + 1] = self.vel[self.k0:self.k0 + nk + 1]
        ys = np.empty((n + 1, 4))
        zdd = np.empty(2 * n * steps + 1)
        mun = np.empty_like(zdd)
        ok = advance(self.y.copy(), vel, 0, self.mus.copy(), np.asarray(u, float), steps, fn,
                     self.h, self.w, self.p, ys, zdd, np.zeros(3), mun)
        if not ok:
            return None
        if velocity:
            return zdd, mun, vel[nk:].copy()
        return (zdd, mun) if memory_force else zdd


_CONTROLLER = None


def _blas_controller():
    """A process-wide ``threadpoolctl.ThreadpoolController`` (one BLAS thread in the
    solves, as :mod:`parapend.control.mpc`)."""
    global _CONTROLLER
    if _CONTROLLER is None:
        from threadpoolctl import ThreadpoolController

        _CONTROLLER = ThreadpoolController()
    return _CONTROLLER


class CoupledHorizon:
    """The coupled horizon problem of one update (:func:`._control_kernel.plan_objective`):
    ``n`` held torques (units ``m g l``) of ``steps`` RK4 steps of ``h`` on the coupled heave
    and pendulum with the memory force frozen; L-BFGS-B with the exact gradient, as
    :class:`parapend.control.mpc.HorizonProblem`."""

    def __init__(self, n, h, steps, p, tu, torque_limit=None, efficiency=None, kappa=None,
                 terminal="total"):
        self.n, self.h, self.steps, self.p, self.tu = n, h, steps, p, tu
        self.total = 1.0 if terminal == "total" else 0.0
        self.eta = (1.0, 1.0) if efficiency is None else tuple(efficiency)
        self.kappa = self.eta[0] if kappa is None else float(kappa)
        self.torque_limit = torque_limit
        self.grad = np.empty(n)
        self.ys = np.empty((n * steps + 1, 4))
        self.offset = 0.0
        self.ref = np.zeros(2)

    def fun(self, u, y0, fnet):
        from ._control_kernel import plan_objective

        f = plan_objective(np.asarray(u, float), y0, fnet, self.h, self.steps, self.p,
                           self.tu, self.eta[0], self.eta[1], self.kappa, self.ref,
                           self.total, self.grad, self.ys)
        return f - self.offset, self.grad.copy()

    def _reference(self, u0, y0, fnet):
        """The start ``y0`` as the objective reads it, and the terminal energy's reference
        (the buoy's end state under ``u0``)."""
        y0 = np.asarray(y0, float)
        self.ref = np.zeros(2)
        self.fun(u0, y0, fnet)
        self.ref = self.ys[-1, :2].copy()
        return y0

    def solve(self, y0, fnet, u0, max_iter=200, tol=1e-10):
        from scipy.optimize import minimize

        bounds = (None if self.torque_limit is None
                  else [(-self.torque_limit, self.torque_limit)] * self.n)
        if bounds is not None:
            u0 = np.clip(u0, -self.torque_limit, self.torque_limit)
        # the objective relative to the start's, so that L-BFGS-B's relative reduction test
        # is not diluted by the buoy's energy (a constant when the pendulum is light)
        self.offset = 0.0
        y0 = self._reference(u0, y0, fnet)
        self.offset = self.fun(u0, y0, fnet)[0]
        with _blas_controller().limit(limits=1, user_api="blas"):
            return minimize(self.fun, u0, args=(y0, fnet), jac=True,
                            method="L-BFGS-B", bounds=bounds,
                            options={"maxiter": max_iter, "ftol": tol, "gtol": 1e-8,
                                     "maxcor": 20})


def _efficiency(efficiency):
    if efficiency is None:
        return None
    if isinstance(efficiency, (tuple, list)):
        eg, em = efficiency
    else:
        eg = em = efficiency
    eg = check_range("efficiency", eg, 0.0, 1.0, why="PTO efficiency")
    em = check_range("efficiency", em, 0.0, 1.0, why="PTO efficiency")
    if eg == 0 or em == 0:
        raise ParameterError("efficiency: expected a value in (0, 1], got 0")
    return (float(eg), float(em))


def _check_solve(res, u):
    """The plan to apply and whether the solve failed: a non-finite iterate keeps the
    previous plan ``u`` (``bad`` 2), a failed finite one is applied (``bad`` 1)."""
    x = np.asarray(res.x, dtype=float)
    if not np.all(np.isfinite(x)):
        return u, 2
    bad = not getattr(res, "success", True) and getattr(res, "status", 0) not in (0, 1)
    return x, int(bad)


def marginal_radiation(w, v):
    r"""The part of the marginal cost of radiation that the frozen memory force leaves out.

    With the memory force ``mu_i = sum_q w_q v_{i-q}`` (the plant's weights ``w``, ``q = 0..
    nk``, on its step ``h``) the energy radiated through it over the steps ``i >= 0``,
    ``R = h sum_i v_i mu_i``, changes with the speed ``v_i`` at a step of the horizon by
    ``dR / dv_i = h (mu_i + a_i)``, ``a_i = sum_q w_q v_{i+q}``: the memory force now, and the
    force this speed will exert on the later speeds. A plan with ``mu`` frozen sees only the
    first (its optimum drives the buoy past the absorption optimum: docs/buoy.md); ``plan``
    with ``radiation_cost`` and ``radiation_model=False`` weights ``z'`` in its objective by
    ``F - mu - a`` instead (with the radiation in its model the plan counts ``R`` itself).

    Parameters
    ----------
    w : array
        The memory weights ``(nk + 1,)`` (N s/m; :func:`.timedomain._memory_weights`).
    v : array
        The predicted speed (m/s) at the steps ``i = 0..`` of the horizon; zero after it.

    Returns
    -------
    array
        ``a`` (N) at the same steps.
    """
    v = np.asarray(v, dtype=float)
    # the weights beyond the horizon meet only the zeros after it
    w = np.asarray(w, dtype=float)[:v.size]
    return np.correlate(np.concatenate((v, np.zeros(w.size - 1))), w, mode="valid")


def _rel(a, b) -> float:
    return float(np.linalg.norm(a - b) / max(np.linalg.norm(a), 1e-300))


def _plan_coupled(plant, prob, u0, fseg, ps, stride, iterations, relaxation, max_iter,
                  residual, tic):
    """Plan on the coupled model: the memory force over the horizon predicted under the
    current plan and frozen; re-predicted after each solve (``iterations`` solves)."""
    tu = prob.tu
    out = plant.predict(u0 * tu, ps, fseg, memory_force=True)
    mu = out[1] if out is not None else np.full(fseg.size, plant.mus[0])
    y0 = plant.y.copy()
    u, ch, failed, kept = u0, [], 0, 0
    for it in range(iterations):
        if it:
            out = plant.predict(u * tu, ps, fseg, memory_force=True)
            if out is not None:
                ch.append(_rel(out[1], mu))
                mu = (1 - relaxation) * mu + relaxation * out[1]
        res = prob.solve(y0, (fseg - mu)[::stride], u, max_iter=max_iter)
        u, bad = _check_solve(res, u)
        failed += bad > 0
        kept += bad == 2
    res_fp = None
    if residual:
        t1 = time.perf_counter()
        out = plant.predict(u * tu, ps, fseg, memory_force=True)
        if out is not None:
            res_fp = (_rel(out[1], mu), time.perf_counter() - t1)
    return u, ch, res_fp, iterations, (int(failed), int(kept))


def _plan_fixed_point(plant, prob, x0, q, u0, fseg, ps, stride, rounds, relaxation, max_iter,
                      residual, g, tu):
    """Plan the pendulum alone (:class:`parapend.control.mpc.HorizonProblem`) on the heave
    ``q``; ``fixed-point``: the heave predicted again under the new plan, ``rounds`` times."""
    u, ch, failed, kept = u0, [], 0, 0
    for it in range(rounds):
        if it:
            zdd = plant.predict(u * tu, ps, fseg)
            if zdd is not None:
                qn = zdd[::stride] / g
                ch.append(_rel(qn, q))
                q = (1 - relaxation) * q + relaxation * qn
        # the pendulum's horizon problem through its documented call only
        res = prob.solve(x0, q, u)
        u, bad = _check_solve(res, u)
        failed += bad > 0
        kept += bad == 2
    res_fp = None
    if residual:
        t1 = time.perf_counter()
        zdd = plant.predict(u * tu, ps, fseg)
        if zdd is not None:
            res_fp = (_rel(zdd[::stride] / g, q), time.perf_counter() - t1)
    return u, ch, res_fp, rounds, (int(failed), int(kept))


class _MotionPlanner:
    r"""``controller="plan"``: the motion-as-unknown horizon problem
    (:class:`._buoy_plan.CoupledPlan`) of every update, warm-started from the previous
    motion shifted by the samples since.

    **The value of the state at the forecast's end.** The forecast ends at ``H``, the sea
    does not. The horizon objective ``J = W + E(T) - E(0)`` (the harvested work plus the
    change of the mechanical energy of buoy and pendulum, :mod:`._buoy_plan`) values the
    energy stored at its end ``T`` at par, as if all of it could still be harvested. It
    cannot: the pendulum's friction ``c theta'^2`` takes its share while the torque limit
    brakes it, and the buoy radiates its heave's energy away. With ``T = H`` a plan that
    knows the force exactly up to ``H`` buys stored energy at the horizon's end with the
    motor (Hs 0.8 m, Tp 3 s, seed 0, a horizon of 2 peak periods: a median plan harvests
    -415 J and ends with 775 J more stored, the buoy at 0.99 m/s and the pendulum at 7.6
    rad/s; the closed loop's damping loss 20 W against 8.6 W with the AR forecast), and
    the perfect forecast lost to the AR one, whose force fades over its horizon, so that
    its plans drain the store before their end (stored -323 J). With ``tail`` samples the
    model runs on past ``H`` to ``T = H + tail dt`` with no excitation (the expectation of
    a zero-mean sea the forecast does not cover; the memory force of the past still acts),
    so the state at ``H`` is worth the work the model itself can still draw from it net of
    friction, radiation and the torque limit, plus what is left at ``T`` at par (a lower
    bound: the sea's later help is not counted). The forecast is read up to ``H`` only
    (causality unchanged); the torques returned are the first ``n``. ``radiation_model``
    only (``memory``): the frozen model keeps ``T = H``.
    """

    def __init__(self, n, dt, ps, p, torque_limit, tu, radiation_cost=True, memory=None,
                 tail=0):
        from ..control.mpc import _gauss3
        from ._buoy_plan import CoupledPlan, Response

        # memory: the plant's weights and step; the radiation in the horizon model
        self.radiation = memory is not None
        # tail: samples after the forecast's horizon, no excitation (the radiation model only)
        self.tail = int(tail) if self.radiation else 0
        self.n_out = n
        n = n + self.tail
        self.n, self.dt, self.ps, self.tu = n, dt, ps, tu
        self.radiation_cost = bool(radiation_cost)
        self.k = max(1, -(-n // PLAN_INTERVAL_SAMPLES))
        self.hh = n * dt / self.k
        off, self.w3 = _gauss3(dt)
        leads = ((dt * np.arange(self.n_out))[:, None] + off[None, :]).ravel()
        resp = (None if memory is None
                else Response(p[0], p[1], memory[0], memory[1], n * dt + memory[1]))
        self.prob = CoupledPlan(self.k, self.hh, p, torque_limit, sample_leads=leads,
                                response=resp)
        self.tmax = torque_limit
        self.nodes = None
        self.tn = self.hh * np.arange(self.k + 1)
        self.tf = 0.5 * dt / ps * np.arange(2 * n * ps + 1)

    def start(self, y, shift):
        """Variables: the previous motion shifted by ``shift`` s, continued at its end speed
        beyond its end, through the measured angle (whole turns); at first a rotation at the
        measured speed."""
        from ..control.plan import HorizonPlan

        th0, om0 = float(y[2]), float(y[3])
        if self.nodes is None:
            th, v = th0 + om0 * self.tn, np.full(self.k + 1, om0)
        else:
            old = HorizonPlan(self.hh, self.nodes[0], self.nodes[1], 0.0)
            s = self.tn + shift
            th, v, _ = old.evaluate(s)
            beyond = s > old.horizon * (1 + 1e-12)
            th = np.where(beyond, old.theta[-1] + old.v[-1] * (s - old.horizon), th)
            v = np.where(beyond, old.v[-1], v)
            th = th + 2 * math.pi * round((th0 - th[0]) / (2 * math.pi))
        x = np.empty(2 * self.k)
        x[0::2], x[1::2] = th[1:], v[1:]
        return x

    def free_heave(self, plant, fseg):
        """``(z, z', z'')`` of the buoy without the pendulum from the plant's state (its
        memory of the past included) under the forecast ``fseg``, by the plant's own model
        (RK4 steps); a vectorized callable of the lead time (s): cubic Hermites of ``z`` and
        ``z'`` between the steps, ``z''`` linear between the half steps."""
        from scipy.interpolate import CubicHermiteSpline

        from ._control_kernel import advance

        nk, ns = plant.nk, self.n * self.ps
        vel = np.empty(nk + 1 + ns)
        vel[:nk + 1] = plant.vel[plant.k0:plant.k0 + nk + 1]
        ys = np.empty((ns + 1, 4))
        zdd = np.empty(2 * ns + 1)
        p0 = plant.p.copy()
        p0[2] = 0.0  # no pendulum on the buoy
        advance(plant.y.copy(), vel, 0, plant.mus.copy(), np.zeros(ns), 1, fseg, plant.h,
                plant.w, p0, ys, zdd, np.zeros(3), np.empty_like(zdd))
        ts = plant.h * np.arange(ns + 1)
        zs = CubicHermiteSpline(ts, ys[:, 0], ys[:, 1])
        zds = CubicHermiteSpline(ts, ys[:, 1], zdd[::2])
        tf = self.tf

        def free(s):
            return zs(s), zds(s), np.interp(s, tf, zdd)
        return free

    def past_memory(self, plant):
        """The memory force (N) at the plant's steps over the horizon of the heave speeds
        before now alone (the trapezoid's weight at ``s = 0`` halved: its other half is the
        horizon's, in the radiated energy of :class:`._buoy_plan.CoupledPlan`)."""
        nk, ns = plant.nk, self.n * self.ps
        u = plant.vel[plant.k0:plant.k0 + nk + 1][::-1]  # u_q: the speed at -q h
        # mu_i = sum_{q >= i} w_q u_{q - i}, i = 0..ns
        mu = np.correlate(np.concatenate((plant.w, np.zeros(ns))), u, "valid")
        m = min(ns + 1, nk + 1)
        mu[:m] -= 0.5 * plant.w[:m] * u[0]
        return mu

    def set_radiation_start(self, plant, fseg):
        """The horizon problem of this update with the radiation in its model: the plant's
        state, its free heave under ``fseg`` and ``F_exc`` less the past's memory force."""
        ts = plant.h * np.arange(self.n * self.ps + 1)
        free = self.free_heave(plant, fseg)
        mp = self.past_memory(plant)

        def fm(s):
            return np.interp(s, self.tf, fseg) - np.interp(s, ts, mp)
        self.prob.set_start(plant.y.copy(), fm, None, free)

    def plan_radiation(self, plant, fseg, shift):
        """``plan`` with the radiation in the horizon model: one solve."""
        pr = self.prob
        y0 = plant.y.copy()
        if self.tail:
            fseg = np.concatenate((fseg, np.zeros(2 * self.tail * self.ps)))
        self.set_radiation_start(plant, fseg)
        x = self.start(y0, shift)
        with _blas_controller().limit(limits=1, user_api="blas"):
            xs, status, _ = pr.solve(x, max_iter=PLAN_MAX_ITER)
        if not np.all(np.isfinite(xs)):
            return None, 1, 1
        held = pr.torques(xs).reshape(self.n_out, 3) @ self.w3
        full = pr.full(xs)
        self.nodes = (full[0::2].copy(), full[1::2].copy())
        return np.clip(held, -self.tmax, self.tmax) / self.tu, int(status != "converged"), 0

    def plan(self, plant, u0, fseg, iterations, relaxation, shift, residual):
        """The held torques (units ``tu``) of the horizon, the memory force's changes, the
        residual (and its untimed seconds), the solves and the failures."""
        if self.radiation:
            u, failed, kept = self.plan_radiation(plant, fseg, shift)
            return (u0 if u is None else u), [], None, 1, (failed, kept)
        pr = self.prob
        y0 = plant.y.copy()
        rc = self.radiation_cost
        ts = plant.h * np.arange(self.n * self.ps + 1)  # the plant's steps
        out = plant.predict(u0 * self.tu, self.ps, fseg, memory_force=True, velocity=rc)
        mu = out[1] if out is not None else np.full(fseg.size, plant.mus[0])
        adj = (marginal_radiation(plant.w, out[2]) if rc and out is not None
               else np.zeros(ts.size))
        x = self.start(y0, shift)
        u, ch, failed, kept = u0, [], 0, 0
        for it in range(iterations):
            if it:
                out = plant.predict(u * self.tu, self.ps, fseg, memory_force=True,
                                    velocity=rc)
                if out is not None:
                    ch.append(_rel(out[1], mu))
                    mu = (1 - relaxation) * mu + relaxation * out[1]
                    if rc:
                        adj = ((1 - relaxation) * adj
                               + relaxation * marginal_radiation(plant.w, out[2]))
            fm = fseg - mu
            fobj = None
            if rc:
                def fobj(s, fm=fm, adj=adj):
                    return np.interp(s, self.tf, fm) - np.interp(s, ts, adj)
            pr.set_start(y0, lambda s, fm=fm: np.interp(s, self.tf, fm), fobj)
            with _blas_controller().limit(limits=1, user_api="blas"):
                xs, status, _ = pr.solve(x, max_iter=PLAN_MAX_ITER)
            if not np.all(np.isfinite(xs)):
                failed += 1
                kept += 1
                continue
            failed += status != "converged"
            x = xs
            held = pr.torques(x).reshape(self.n_out, 3) @ self.w3
            u = np.clip(held, -self.tmax, self.tmax) / self.tu
            full = pr.full(x)
            self.nodes = (full[0::2].copy(), full[1::2].copy())
        res_fp = None
        if residual:
            t1 = time.perf_counter()
            out = plant.predict(u * self.tu, self.ps, fseg, memory_force=True)
            if out is not None:
                res_fp = (_rel(out[1], mu), time.perf_counter() - t1)
        return u, ch, res_fp, iterations, (int(failed), int(kept))


def buoy_mpc(hydro, pendulum, wave, *, peak_period, horizon=2.0, update_interval=0.125,
             controller=None, iterations=2, relaxation=1.0, samples=SAMPLES,
             warmup=4.0, repeats=1, torque_limit=None, efficiency=None, terminal_weight=None,
             model_steps=MODEL_STEPS, plant_steps=PLANT_STEPS, memory=None, a_inf=None,
             max_iter=None, residual=True, terminal="total", time_limit=None,
             deadline=None, radiation_cost=True, forecast="perfect",
             radiation_model=True) -> BuoyMPCResult:
    """Receding-horizon control of the pendulum inside the buoy in a periodic record.

    Parameters
    ----------
    hydro : Hydro
        The buoy's coefficients (its ``mass`` the floating mass, pendulum included).
    pendulum : parapend.hydro.coupled.Pendulum
    wave : parapend.hydro.coupled.Wave
        The periodic record at the buoy (``parapend.buoy``'s ``_wave``).
    peak_period : float
        ``Tp`` (s): the unit of ``horizon``, ``update_interval``, ``warmup`` and of the torque
        sample ``Tp / samples`` (rounded so that the record holds whole samples).
    horizon, update_interval : float
        In peak periods.
    controller : "plan", "coupled", "one-way", "fixed-point" or None
        The module docstring. None (default): ``plan``, or ``coupled`` where ``plan`` does
        not model what is asked (an efficiency, another terminal value or weight).
    iterations : int
        ``coupled``, ``plan`` with ``radiation_model=False``: solves per update (plan <->
        memory force), at least 1 (``plan`` gains nothing from a second: give 1); ``plan``
        with the radiation in its model solves once.
    relaxation : float
        ``alpha`` in (0, 1] of the fixed-point iteration.
    warmup : float
        Peak periods run before the averaging window (swing-up and catch).
    repeats : int
        Repeats of the record in the averaging window.
    torque_limit : float or None
        N m, on every held torque (and on the swing-up's pump); None: ``DEFAULT_LIMIT``
        (2) times ``m g l`` (without a bound the discrete horizon problem's optimum runs off
        to torques and speeds its steps do not resolve).
    efficiency : float, (eta_g, eta_m) or None
        The efficiency model of :mod:`parapend.pto` in the horizon objective and the
        electrical power.
    terminal_weight : float or None
        ``kappa`` of the horizon's terminal value (None: ``eta_g``).
    memory, a_inf : the plant's radiation memory (s) and infinite-frequency added mass (kg),
        as :func:`parapend.hydro.timedomain.simulate` (default: its defaults).
    terminal : "total" or "pendulum"
        ``coupled``: the terminal value counts the mechanical energy of buoy and pendulum
        (default) or the pendulum's alone (``I theta'^2 / 2 + m g l cos(theta)``, the
        pendulum MPC's; docs/buoy.md).
    residual : bool
        ``coupled``: also measure the fixed point's residual (one extra prediction per
        update, not timed).
    time_limit, deadline : float or None
        Seconds the run may take (work above the cap is then not refused) and the
        ``time.monotonic`` time it stops at (:func:`parapend.deadline.deadline`; default
        ``time_limit`` from now): once it has passed the run stops before its next update
        (after at least one) with the status ``"time_limit"``: a partial run, no success,
        its powers over the samples run.
    radiation_cost : bool
        ``plan`` with ``radiation_model=False``: weight the heave speed in the horizon
        objective by ``F_exc - mu - a`` (``marginal_radiation``: the radiation the plan's own
        motion causes later in the horizon, from the motion predicted under the previous
        plan) instead of ``F_exc - mu`` (False: the memory force frozen alone;
        docs/buoy.md). With the radiation in the model its objective counts that radiation
        exactly and this has no effect.
    forecast : "perfect" or "ar"
        What the controller knows of the excitation force over the horizon: the record's
        own future (``perfect``), or the autoregressive forecast of
        :class:`parapend.control.forecast.ARForecast` fitted at each update on the force
        measured so far (every torque sample from the run's start; ``ar``: causal). Not
        with ``one-way``, whose free heave is the record's.
    radiation_model : bool
        ``plan``: the radiation inside the horizon model as the plant has it (Cummins'
        memory: the heave through the plant's impulse response, the past's memory in the
        free response from the measured state; default), or (False) the memory force
        predicted under the previous plan and frozen in the dynamics (the planner before).
    """
    from ..control import mpc as _mpc
    from ..control.mpc import HorizonProblem
    from ..control.swingup import pump_torque, ready_to_catch

    if terminal not in ("total", "pendulum"):
        raise ParameterError(f"terminal: expected total or pendulum, got {terminal!r:.40}")
    if controller is None:
        lossy = (efficiency is not None or terminal != "total"
                 or terminal_weight not in (None, 1, 1.0))
        controller = "coupled" if lossy else "plan"
    if controller not in CONTROLLERS:
        raise ParameterError(f"controller: expected coupled, fixed-point, one-way or plan, "
                             f"got {controller!r:.40}")
    if controller == "plan" and (efficiency is not None or terminal != "total"
                                 or terminal_weight not in (None, 1, 1.0)):
        raise ParameterError("controller: plan maximizes the mechanical work plus the energy "
                             "of buoy and pendulum (no efficiency, terminal or "
                             "terminal_weight yet)")
    if forecast not in ("perfect", "ar"):
        raise ParameterError(f"forecast: expected perfect or ar, got {forecast!r:.40}")
    if forecast == "ar" and controller == "one-way":
        raise ParameterError("forecast: ar is not with the one-way controller (it plans on "
                             "the free buoy's heave, the record's own)")
    tp = check_range("tp", peak_period, 1e-3, 1e3)
    samples = check_int("samples", samples, 8, 4096)
    horizon = check_range("horizon", horizon, 1.0 / samples, 20.0, why="peak periods")
    update_interval = check_range("update-interval", update_interval, 1.0 / samples, 20.0,
                                  why="peak periods")
    if update_interval > horizon:
        raise ParameterError(f"update-interval: expected at most the horizon {horizon:g} peak "
                             f"periods, got {update_interval:g}")
    iterations = check_int("iterations", iterations, 1, 50)
    relaxation = check_range("relaxation", relaxation, 1e-3, 1.0)
    warmup = check_range("warmup", warmup, 0.0, 1e3, why="peak periods")
    repeats = check_int("repeats", repeats, 1, 100)
    model_steps = check_int("model_steps", model_steps, 1, 64)
    plant_steps = check_int("plant_steps", plant_steps, model_steps, 1024)
    if plant_steps % model_steps:
        raise ParameterError("plant_steps: expected a multiple of model_steps")
    if torque_limit is not None:
        torque_limit = check_range("torque-limit", torque_limit, 1e-9, 1e9, why="N m")
    eta = _efficiency(efficiency)
    limit_given = torque_limit is not None
    if max_iter is None:
        max_iter = getattr(_mpc, "MAX_ITER", 200)
    if not pendulum.mass < hydro.mass:
        raise ParameterError(f"mass: the pendulum's {pendulum.mass:g} kg is not less than the "
                             f"floating mass {hydro.mass:.6g} kg")

    g = float(hydro.g)
    t0 = math.sqrt(pendulum.inertia / (pendulum.mass * g * pendulum.length))
    tu = pendulum.mass * g * pendulum.length
    if torque_limit is None:
        # the horizon model's discrete optimum runs off to torques (and speeds) the steps
        # do not resolve when nothing bounds them: a bound is part of the planning problem
        torque_limit = DEFAULT_LIMIT * tu
    tr = 2 * math.pi / wave.omega
    per_record = max(1, int(round(tr / (tp / samples))))
    dt = tr / per_record
    n = max(1, int(round(horizon * tp / dt)))
    m = max(1, min(n, int(round(update_interval * tp / dt))))
    warm_samples = int(round(warmup * tp / dt))
    total = warm_samples + repeats * per_record
    solves_per_update = (1 if controller == "one-way"
                         or (controller == "plan" and radiation_model) else iterations)
    _check_work(total, n, m, solves_per_update, warm_samples,
                repeats, dt, time_limit)
    if deadline is None and time_limit is not None:
        from ..deadline import deadline as _deadline

        deadline = _deadline(time_limit)
    planned = total  # the samples asked for (a time limit may stop the run before)
    ps, ms = plant_steps, model_steps
    stride = ps // ms
    h = dt / ps

    # the record on the plant's half-step nodes, over the run and one horizon beyond
    nodes = 2 * (total + n) * ps + 1
    fn = force_nodes(hydro, wave, per_record, ps, nodes)
    zk, wk = free_motion(hydro, wave)
    qw = _periodic(-(wk**2) * zk / g, wave.omega, tr, 2 * per_record * ps, nodes)
    z0 = float(np.real(np.sum(zk)))
    zd0 = float(np.real(np.sum(1j * wk * zk)))

    def history(t):
        return np.real(np.exp(1j * np.multiply.outer(t, wk)) @ (1j * wk * zk))

    plant = _Plant(hydro, pendulum, h, total * ps, memory, a_inf, z0, zd0, history)
    if forecast == "ar":
        from ..control.forecast import ARForecast

        ar = ARForecast(tp)  # seconds and newtons: the force itself, fitted on its past
        leads = 0.5 * h * np.arange(2 * n * ps + 1)  # the horizon's half-step nodes
    if controller == "one-way":
        # the free buoy's heave as the plant's model gives it (the pendulum hanging at rest
        # exerts no reaction): what the pendulum MPC is told when the reaction is ignored
        zfree = plant.predict(np.zeros(total + n), ps, fn)
        if zfree is not None:
            qw = zfree / g
    tl_nd = None if torque_limit is None else torque_limit / tu
    if controller == "plan":
        prob = _MotionPlanner(n, dt, ps, plant.p, torque_limit, tu, radiation_cost,
                              (plant.w, h) if radiation_model else None,
                              int(round(PLAN_TAIL * tp / dt)))
    elif controller == "coupled":
        prob = CoupledHorizon(n, dt / ms, ms, plant.p, tu, tl_nd, eta, terminal_weight,
                              terminal)
    else:
        prob = HorizonProblem(n, dt / t0, ms, pendulum.damping_coefficient * t0 /
                              pendulum.inertia, tl_nd, eta, terminal_weight)
    level = 1.0 if tl_nd is None else min(tl_nd, 1.0)

    ys = np.empty((total + 1, 4))
    ys[0] = plant.y
    acc = np.zeros((total + 1, 3))
    energy = np.empty(total + 1)
    energy[0] = plant.energy()
    u_all = np.zeros(total)
    caught, braking = None, False
    plan = np.zeros(n)
    times, changes, residuals = [], [], []
    solves = failed = kept = 0
    status = "ok"
    j = 0
    while j < total:
        th, om = plant.y[2], plant.y[3] * t0
        if caught is None and ready_to_catch(th, om, CATCH_MARGIN):
            caught = j
        if caught is None:
            tq, braking = pump_torque(th, om, level, CATCH_MARGIN, braking)
            seg = np.array([tq])
        else:
            if solves and deadline is not None and time.monotonic() >= deadline:
                status, total = "time_limit", j  # before this update: a partial run
                break
            a = 2 * j * ps
            tic = time.perf_counter()  # the forecast is part of the update's time
            if forecast == "ar":
                # the force measured at every torque sample up to now, nothing later
                fseg = ar.predict(j * dt, dt * np.arange(j + 1), fn[:a + 1:2 * ps], leads)
            else:
                fseg = fn[a:a + 2 * n * ps + 1]
            u0 = (np.concatenate((plan[m:], np.full(m, plan[-1]))) if solves
                  else np.zeros(n))
            x0 = np.array([th, om])
            if controller == "plan":
                u, ch, res_fp, nsolve, nfail = prob.plan(
                    plant, u0, fseg, iterations, relaxation, m * dt if solves else 0.0,
                    residual)
            elif controller == "coupled":
                u, ch, res_fp, nsolve, nfail = _plan_coupled(
                    plant, prob, u0, fseg, ps, stride, iterations, relaxation, max_iter,
                    residual, tic)
            else:
                if controller == "one-way":
                    q = qw[a:a + 2 * n * ps + 1:stride]
                    rounds = 1
                else:
                    zdd = plant.predict(u0 * tu, ps, fseg)
                    q = (qw[a:a + 2 * n * ps + 1] if zdd is None else zdd)[::stride] / g
                    rounds = iterations
                u, ch, res_fp, nsolve, nfail = _plan_fixed_point(
                    plant, prob, x0, q, u0, fseg, ps, stride, rounds, relaxation, max_iter,
                    residual and controller == "fixed-point", g, tu)
            times.append(time.perf_counter() - tic - (0.0 if res_fp is None else res_fp[1]))
            solves += nsolve
            failed += nfail[0]
            kept += nfail[1]
            changes.append(ch)
            if res_fp is not None:
                residuals.append(res_fp[0])
            plan = u
            seg = plan[:min(m, total - j)]
        done, ok = apply_segment(plant, seg, j, tu, ps, fn, ys, acc, energy, u_all)
        if not ok:
            status, total = "diverged", j + done
            break
        j += done

    ys, acc, energy, u_all = ys[:total + 1], acc[:total + 1], energy[:total + 1], u_all[:total]
    series = {"theta": ys[:, 2], "theta_dot": ys[:, 3], "z": ys[:, 0], "z_dot": ys[:, 1]}
    return closed_loop_result(
        series, acc, energy, u_all, status=status, caught=caught, dt=dt, h=h,
        per_record=per_record, repeats=repeats, planned=planned, warm_samples=warm_samples,
        n=n, m=m, eta=eta, times=times, changes=changes, residuals=residuals, solves=solves,
        failed=failed, kept=kept, iterations=iterations, solves_per_update=solves_per_update,
        relaxation=relaxation, controller=controller, forecast=forecast,
        torque_limit=torque_limit, limit_given=limit_given, pendulum=pendulum, plant=plant,
        units={"time_s": t0, "torque_nm": tu, "power_w": tu / t0, "a_inf_kg": plant.a_inf,
               "memory_s": plant.nk * h, "plant_step_s": h})



def apply_segment(plant, seg, j, tu, ps, fn, ys, acc, energy, u_all):
    """Apply the held torques ``seg`` (units ``tu``) to the plant from sample ``j`` (``ps``
    steps each, the force ``fn`` at its half-step nodes), saving its state, accumulated
    energies and mechanical energy after each and the torque (N m): ``(samples applied,
    ok)``, ``ok`` False when the plant diverged (its last sample applied)."""
    for k, uk in enumerate(seg):
        ok, yk = plant.step(np.array([uk * tu]), ps, fn[2 * (j + k) * ps:
                                                      2 * (j + k + 1) * ps + 1])
        ys[j + k + 1] = yk[1]
        acc[j + k + 1] = plant.acc
        energy[j + k + 1] = plant.energy()
        u_all[j + k] = uk * tu
        if not ok:
            return k + 1, False
    return len(seg), True

def closed_loop_result(series, acc, energy, u_all, *, status, caught, dt, h, per_record,
                       repeats, planned, warm_samples, n, m, eta, times, changes, residuals,
                       solves, failed, kept, iterations, solves_per_update, relaxation,
                       controller, forecast, torque_limit, limit_given, pendulum, plant,
                       units) -> BuoyMPCResult:
    """The result of a closed-loop run on a floating body (the buoy's :func:`buoy_mpc`, the
    hull's :func:`parapend.hydro.hull_control.hull_mpc`): the storage-corrected headline over
    whole repeats after the warm-up, the energy balance, the status and the update times.

    ``series``: ``theta`` (the generator's angle, rad) and ``theta_dot`` at the samples'
    ends, ``z`` (the heave, m) and the body's other saved states; ``acc`` the plant's
    accumulated ``(absorbed, damping, work)`` (J) and ``energy`` its mechanical energy (J)
    there; ``u_all`` the held torques (N m)."""
    from ..control import mpc as _mpc

    total = u_all.size
    t = dt * np.arange(total + 1)
    p = -u_all * np.diff(series["theta"]) / dt
    pe = p if eta is None else np.where(p > 0, eta[0] * p, p / eta[1])
    a0 = max(0, total - repeats * per_record)
    span = (total - a0) * dt
    eta_g = 1.0 if eta is None else float(eta[0])
    if span > 0:
        # the harvested energy W and the stored energy's change dE over whole repeats of
        # the record after the start-up; the headline is (W + dE) / span
        work = float(np.sum(p[a0:]) * dt)
        work_e = float(np.sum(pe[a0:]) * dt)
        de = float(energy[-1] - energy[a0])
        harvested, harvested_e = work / span, work_e / span
        stored = de / span
        mean_p = harvested + stored
        mean_e = harvested_e + eta_g * stored
        d = (acc[-1] - acc[a0]) / span
    else:
        work = de = harvested = harvested_e = mean_p = mean_e = stored = math.nan
        d = np.full(3, math.nan)
    absorbed, damping = float(d[0]), float(d[1])
    resid = abs(harvested + damping + stored - absorbed) / max(abs(absorbed), 1e-300)
    if status == "ok" and not math.isfinite(mean_p):
        status = "nonfinite"
    if status == "ok" and float(np.max(np.abs(series["theta_dot"]))) * h > RESOLVED:
        status = "unresolved"
    if status == "ok" and solves and 2 * failed > solves:
        # a run whose plans mostly failed is not a success, whatever its power
        status = "solves_failed"
    if status == "ok" and (caught is None or caught > a0):
        # the window holds the swing-up, not the controller: no causal mean to report
        status = "not_caught"
    # the storage-corrected mean is exact for the plant up to its energy balance: a loss
    # beyond that residual is the controller's, not the integration's
    tol = resid * abs(absorbed) if math.isfinite(resid * absorbed) else 0.0
    if status == "ok" and min(mean_p, mean_e) < -tol:
        status = "loses_energy"
    st = np.asarray(times)
    timing = _mpc.timing_summary(st, m * dt)
    fp = []
    if controller != "one-way" and iterations > 1 and changes:
        for k in range(iterations - 1):
            col = [c[k] for c in changes if len(c) > k]
            fp.append(float(np.median(col)) if col else math.nan)
    applied = (f" (applied instead: the last iterate of {failed - kept}, the previous plan "
               f"continued for {kept})" if failed else "")
    msg = {"ok": f"{solves} horizon solves in {st.size} updates, {failed} ended abnormally"
                 + applied,
           "diverged": "the closed loop diverged (|theta'| > 1e6 rad/s)",
           "nonfinite": "non-finite power",
           "solves_failed": (f"{failed} of {solves} horizon solves ended abnormally: the "
                             "controller did not plan this run" + applied),
           "unresolved": (f"the pendulum turned more than {RESOLVED:g} rad in one plant step: "
                          "the integration does not resolve the run; lower the torque "
                          "limit"),
           "time_limit": (f"time limit reached after {st.size} updates: {total * dt:.6g} s of "
                          f"the {planned * dt:.6g} s run (a partial run: its energies over the "
                          f"samples run, from {a0 * dt:.4g} s)"),
           "not_caught": (f"the swing-up never handed over to the controller (0 horizon "
                          f"solves): the pendulum did not reach the top under the torque "
                          f"limit {torque_limit:.6g} N m" if caught is None else
                          f"the swing-up handed over at {caught * dt:.6g} s, inside the "
                          f"averaging window from {a0 * dt:.6g} s"),
           "loses_energy": (f"the controller loses energy: {mean_e:.6g} W over the last "
                            f"repeat ({solves} horizon solves in {st.size} updates, {failed} "
                            f"ended abnormally{applied})")}[status]
    warnings = []
    reason = None
    if status == "loses_energy":
        warnings.append(f"the causal run loses energy ({mean_e:.4g} W electrical, "
                        f"{mean_p:.4g} W mechanical): the pendulum at rest (0 W) does "
                        "better; its power is a measurement of this controller, not an "
                        "answer")
    elif status != "ok":
        # not a causal mean over a whole repeat after the warm-up: the headline is null
        reason = (f"the run stopped at {total * dt:.4g} s of {planned * dt:.4g} s (time "
                  "limit): no mean over one whole repeat of the record after the "
                  f"{warm_samples * dt:.4g} s warm-up" if status == "time_limit" else msg)
        mean_p = mean_e = harvested = harvested_e = math.nan
    series = {"t": t, **series, "torque": u_all, "power": p}
    zwin = series["z"][a0:]
    return BuoyMPCResult(
        planner=controller, forecast=forecast, mean_power_w=mean_p, electrical_power_w=mean_e,
        harvested_power_w=harvested, harvested_electrical_power_w=harvested_e,
        harvested_energy_j=work, stored_energy_change_j=de,
        absorbed_w=absorbed, damping_w=damping, stored_w=float(stored),
        energy_balance_residual=float(resid),
        peak_torque_nm=float(np.max(np.abs(u_all))) if total else 0.0,
        heave_amplitude_m=0.5 * float(np.ptp(zwin)) if zwin.size else math.nan,
        catch_time_s=None if caught is None else float(caught * dt), horizon_s=n * dt,
        update_interval_s=m * dt, dt_s=dt, average_from_s=a0 * dt, t_end_s=total * dt,
        iterations=solves_per_update, relaxation=relaxation,
        fixed_point_change=fp,
        fixed_point_residual=float(np.median(residuals)) if residuals else None,
        solves=solves, failed_solves=failed,
        **{f"{k}_s": v for k, v in timing.items() if k != "realtime_fits"},
        realtime_fits=timing["realtime_fits"], failed_kept_previous=kept,
        torque_limit_nm=torque_limit, torque_limit_given=limit_given, efficiency=eta,
        success=status == "ok", status=status, message=msg, headline_reason=reason,
        warnings=tuple(warnings), pendulum={"mass_kg": pendulum.mass, "length_m": pendulum.length,
                  "inertia_kg_m2": pendulum.inertia,
                  "damping_coefficient_nm_s_per_rad": pendulum.damping_coefficient},
        units=units,
        _samples=series, _plant=plant, _update_times=st)

def mpc_command(hydro, pendulum, wave, info, *, controller, horizon, update_interval, winding,
                harmonics, torque_limit, efficiency, irregular, design, time_limit=None,
                deadline=None, forecast="perfect", planner=None):
    """``parapend buoy --controller mpc|one-way-mpc``: the closed loop on the record (4 peak
    periods of warm-up, then one repeat) beside the record's coupled non-causal optimum
    (mechanical, without torque limit or efficiency, at ``winding`` turns per record);
    ``optimum_fraction`` is the electrical power over it. ``planner``: :func:`buoy_mpc`'s
    ``controller`` with ``"mpc"`` (None: its default)."""
    import dataclasses

    if design:
        raise ParameterError("optimize-design: not with --controller mpc")
    if not irregular or "tp" not in info:
        raise ParameterError("controller: mpc runs in an irregular sea state: give --hs and "
                             "--tp")
    r = buoy_mpc(hydro, pendulum, wave, peak_period=float(info["tp"]), horizon=horizon,
                 update_interval=update_interval,
                 controller=planner if controller == "mpc" else "one-way",
                 torque_limit=torque_limit, efficiency=efficiency, time_limit=time_limit,
                 deadline=deadline, forecast=forecast)
    sol, _, _ = _solve(hydro, pendulum, wave, winding=winding, harmonics=harmonics,
                       torque_limit=None, efficiency=None, one_way=False)
    opt = float(sol.power) if sol.success else None
    # with an efficiency the fraction includes the losses (as parapend horizon's)
    frac = (r.electrical_power_w / opt if opt is not None and opt > 0
            and math.isfinite(r.electrical_power_w) else None)
    resolved, note = _reference_verdict(sol, frac)
    warnings = r.warnings + ((note,) if note else ())
    return dataclasses.replace(r, optimum_power_w=opt, optimum_fraction=frac,
                               optimum_resolved=resolved, optimum_winding=int(winding),
                               wave=info, warnings=warnings)


def _reference_verdict(sol, fraction):
    """``(resolved, note)`` of the non-causal reference ``sol``: resolved when its solve
    succeeded, the refinement ``N -> 2N`` changed its power by at most ``REFERENCE_TOL``
    (relative) and no causal run beats it (``fraction`` at most ``1 + REFERENCE_TOL``: a
    causal controller cannot beat the non-causal optimum of the same record; one that does
    shows the reference is not that optimum). The note says why not (None when resolved)."""
    if not sol.success or not math.isfinite(sol.power):
        return None, None  # no reference at all: optimum_power_w is null
    change = float(getattr(sol, "refinement_change", 0.0) or 0.0)
    if change > REFERENCE_TOL * abs(sol.power):
        return False, (f"the non-causal reference is under-resolved: its refinement "
                       f"N -> 2N changed it by {change:.3g} W ({change / abs(sol.power):.1%}"
                       f", {sol.harmonics} harmonics); give more --harmonics (or none: the "
                       "default)")
    if fraction is not None and fraction > 1 + REFERENCE_TOL:
        return False, (f"the causal run reaches {fraction:.4g} of the non-causal reference, "
                       "above 1: the reference is not the record's optimum (a local "
                       "maximum; try another --winding)")
    return True, None


def _timing_line(r) -> str:
    """Planning time per update against the update interval (the first apart)."""
    if r.update_time_median_s is None:
        first = ("" if r.update_time_first_s is None else
                 f" (one update, {1e3 * r.update_time_first_s:.3g} ms with the kernel load)")
        return f"planning per update: too few updates to time{first}"
    return (f"planning per update after the first: median {1e3 * r.update_time_median_s:.3g} "
            f"ms, p99 {1e3 * r.update_time_p99_s:.3g} ms, max "
            f"{1e3 * r.update_time_max_s:.3g} ms against the update interval "
            f"{1e3 * r.update_interval_s:.4g} ms: p99 "
            + ("fits" if r.realtime_fits else "does NOT fit")
            + f" (one process); the first {1e3 * r.update_time_first_s:.3g} ms (kernel load)")


def mpc_text(r) -> list:
    """The text report of :func:`mpc_command`'s result."""
    def f(x, unit=""):
        return "-" if x is None or not math.isfinite(x) else f"{x:.6g}{unit}"
    w = r.wave or {}
    p = r.pendulum
    body = "hull" if str(r.planner).startswith("hull") else "buoy"
    out = [f"wave: irregular, {w.get('spectrum', '')}, Hs = {w.get('hs', math.nan):g} m, "
           f"Tp = {w.get('tp', math.nan):g} s, seed {w.get('seed', '-')}, repeat period "
           f"{w.get('repeat_period', math.nan):.6g} s",
           f"pendulum: m = {p['mass_kg']:g} kg, l = {p['length_m']:g} m, I = "
           f"{p['inertia_kg_m2']:.6g} kg m^2, c = {p['damping_coefficient_nm_s_per_rad']:g} "
           "N m s/rad",
           f"controller: receding horizon, {r.planner} planner, {r.forecast} forecast, horizon "
           f"{r.horizon_s:.4g} s, update "
           f"every {r.update_interval_s:.4g} s, torque held over {r.dt_s:.4g} s, limit "
           f"{r.torque_limit_nm:.6g} N m" + ("" if r.torque_limit_given else
                                            f" ({r.torque_limit_nm / r.units['torque_nm']:.3g}"
                                            " m g l, the default)"),
           "",
           f"mean power over the last repeat    {f(r.mean_power_w, ' W')} (harvested + "
           f"stored energy's change, after a {r.average_from_s:.4g} s start-up)",
           f"  harvested alone                  {f(r.harvested_power_w, ' W')}",
           f"  stored energy's change           {f(r.stored_energy_change_j, ' J')} "
           f"({body} and pendulum)",
           f"  electrical                       {f(r.electrical_power_w, ' W')}",
           f"non-causal coupled optimum         {f(r.optimum_power_w, ' W')} (winding "
           f"{r.optimum_winding})",
           f"  fraction reached (electrical)    {f(r.optimum_fraction)}"
           + ("  (the reference under-resolved)" if r.optimum_resolved is False else ""),
           f"absorbed by the {body}               {f(r.absorbed_w, ' W')}",
           f"  pendulum damping                 {f(r.damping_w, ' W')}",
           f"  stored (change / time)           {f(r.stored_w, ' W')}",
           f"  energy balance residual          {r.energy_balance_residual:.1e}",
           f"heave amplitude (half range)       {f(r.heave_amplitude_m, ' m')}",
           f"peak torque                        {f(r.peak_torque_nm, ' N m')}",
           _timing_line(r),
           f"status: {r.status}; {r.message}"]
    if r.headline_reason:
        out[4:5] = [f"mean power over the last repeat    none: {r.headline_reason}"]
    return out + [f"warning: {w}" for w in r.warnings]
