"""The closed loop: the full nonlinear Eq. 14 under the sampled controller.

Plant (Eq. 14, ``theta`` from the upright)::

    theta'' + gamma_p theta' - (1 + q_p(t)) sin(theta) = T(t)

with the plant's own damping ``gamma_p`` and excitation ``q_p`` (which differ from the
design's under model error or irregular excitation). The controller samples the state
``M`` times per forcing period (``h = 2 pi / (omega M)``), optionally with Gaussian
measurement noise, and holds its torque over the interval (zero-order hold):

- pump (:mod:`.swingup`) until the pendulum rotates forward with energy above the top's,
  and again whenever tracking has been a quarter turn or more off the orbit for a whole
  period (lost: a limited torque could not pull it in);
- then track: ``T_k = sat(T_ff,k - K_k e_k)``, ``e_k = (wrap(theta_k - theta*_k),
  theta'_k - theta*'_k)``, the feedforward of Eq. 14 on the optimal motion plus the
  periodic LQR gain (:mod:`.riccati`), saturated at ``|T| <= T_max``. Wrapping the angle
  error to ``(-pi, pi]`` makes the error that of the nearest copy of the rotation
  (``theta* + 2 pi n``), so a rotation that slipped a turn is caught again, not unwound.

Between samples the plant is integrated by classical RK4 with ``substeps`` steps per
interval on ``q_p`` precomputed at the stage times; the held torque makes the extracted
energy over an interval exact: ``-T_k (theta_{k+1} - theta_k)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .swingup import pump_torque, ready_to_catch

__all__ = ["ClosedLoopRun", "Diverged", "run_closed_loop"]

PUMP, TRACK = 0, 1
#: |theta'| beyond which a run is abandoned as diverged (the sampled loop or the RK4 steps
#: are unstable for this plant; ``track`` refuses such plants, this is the safety net)
DIVERGED_SPEED = 1e12


class Diverged(ArithmeticError):
    """The closed loop left every bounded state (``|theta'| > DIVERGED_SPEED`` or NaN) at
    sample ``k`` (attribute ``sample``)."""

    def __init__(self, sample: int):
        super().__init__(f"the closed loop diverged at sample {sample}")
        self.sample = sample


@dataclass(frozen=True, eq=False)
class ClosedLoopRun:
    """Samples ``k = 0 .. K`` (``K = periods * M``) of one closed-loop run.

    ``t, theta, theta_dot, q`` are the plant's true values at ``t_k = k h``; ``torque[k]``
    is the torque held on ``[t_k, t_k + h)`` (the last one is what the controller would
    apply next); ``mode[k]`` is 0 (pump) or 1 (track).
    """

    t: np.ndarray
    theta: np.ndarray
    theta_dot: np.ndarray
    torque: np.ndarray
    q: np.ndarray
    mode: np.ndarray


def wrap(x: float) -> float:
    """``x`` mapped to ``[-pi, pi)``."""
    return (x + math.pi) % (2 * math.pi) - math.pi


def held_torque_step(th: float, om: float, u: float, qg, i: int, dt: float,
                     gamma: float) -> tuple[float, float]:
    """One classical Runge-Kutta step of length ``dt`` of Eq. 14 under the torque ``u`` held
    constant (the sampled controller's zero-order hold): ``qg[i]``, ``qg[i + 1]`` and
    ``qg[i + 2]`` are ``q`` at the step's start, middle and end, ``gamma`` the plant's
    damping. Returns ``(theta, theta')`` at the step's end (floats, a plain Python loop's
    arithmetic: the closed loops call it once a substep)."""
    sin = math.sin
    qa, qb, qc = qg[i], qg[i + 1], qg[i + 2]
    a1 = om
    b1 = (1.0 + qa) * sin(th) - gamma * om + u
    a2 = om + 0.5 * dt * b1
    b2 = (1.0 + qb) * sin(th + 0.5 * dt * a1) - gamma * a2 + u
    a3 = om + 0.5 * dt * b2
    b3 = (1.0 + qb) * sin(th + 0.5 * dt * a2) - gamma * a3 + u
    a4 = om + dt * b3
    b4 = (1.0 + qc) * sin(th + dt * a3) - gamma * a4 + u
    return (th + dt / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4),
            om + dt / 6.0 * (b1 + 2 * b2 + 2 * b3 + b4))


def run_closed_loop(target, gains, *, periods: int, torque_limit: float | None,
                    plant_q, plant_gamma: float, state0=(math.pi, 0.0),
                    noise=(0.0, 0.0), rng=None, pump_level: float = 1.0,
                    catch_margin: float = 0.05, substeps: int = 4,
                    start_tracking: bool = False) -> ClosedLoopRun:
    """Simulate the sampled closed loop from ``state0`` (default hanging at rest).

    Parameters
    ----------
    target : Target
    gains : ndarray, shape (M, 2)
        Periodic LQR gains ``K_k``.
    periods : int
        Forcing periods simulated.
    torque_limit : float or None
        ``T_max`` (None: no saturation; the pump then uses ``pump_level``).
    plant_q : callable
        ``q_p(t)``, vectorized (the plant's excitation).
    plant_gamma : float
        The plant's damping.
    noise : (float, float)
        Standard deviations of the measurement noise on ``theta`` and ``theta'``.
    rng : numpy.random.Generator or None
        Source of the noise (needed when ``noise`` is not zero).
    pump_level : float
        Pump torque ``T_p`` (capped at ``T_max``).
    start_tracking : bool
        Start in the tracking mode (no swing-up): for a state near the orbit.
    """
    m, h = target.samples, target.step
    nk = periods * m
    dt = h / substeps
    tq = 0.5 * dt * np.arange(2 * substeps * nk + 1)
    qg = np.asarray(plant_q(tq), dtype=float).tolist()
    if noise[0] > 0 or noise[1] > 0:
        nz = rng.standard_normal((nk + 1, 2)) * np.asarray(noise, dtype=float)
        nz_th, nz_om = nz[:, 0].tolist(), nz[:, 1].tolist()
    else:
        nz_th = nz_om = [0.0] * (nk + 1)
    tmax = math.inf if torque_limit is None else float(torque_limit)
    level = min(pump_level, tmax)
    ref_th = target.theta.tolist()
    ref_om = target.theta_dot.tolist()
    ff = target.feedforward.tolist()
    k1s, k2s = gains[:, 0].tolist(), gains[:, 1].tolist()
    gamma_p = float(plant_gamma)
    two_pi = 2 * math.pi
    th, om = float(state0[0]), float(state0[1])
    out_th = [0.0] * (nk + 1)
    out_om = [0.0] * (nk + 1)
    out_t = [0.0] * (nk + 1)
    out_mode = [0] * (nk + 1)
    mode, braking, astray = (TRACK if start_tracking else PUMP), False, 0
    for k in range(nk + 1):
        out_th[k], out_om[k] = th, om
        y0, y1 = th + nz_th[k], om + nz_om[k]
        j = k % m
        if mode == PUMP and ready_to_catch(y0, y1, catch_margin):
            mode, astray = TRACK, 0
        if mode == TRACK:
            n = k // m
            e0 = wrap(y0 - ref_th[j] - two_pi * n)
            e1 = y1 - ref_om[j]
            astray = astray + 1 if abs(e0) > 0.5 * math.pi else 0
            if astray > m:  # a quarter turn or more off for a whole period: pump again
                mode, braking = PUMP, False
        if mode == PUMP:
            u, braking = pump_torque(y0, y1, level, catch_margin, braking)
        else:
            u = ff[j] - k1s[j] * e0 - k2s[j] * e1
            if u > tmax:
                u = tmax
            elif u < -tmax:
                u = -tmax
        out_t[k] = u
        out_mode[k] = mode
        if k == nk:
            break
        base = 2 * substeps * k
        for s in range(substeps):
            th, om = held_torque_step(th, om, u, qg, base + 2 * s, dt, gamma_p)
            if not -DIVERGED_SPEED < om < DIVERGED_SPEED:  # also NaN
                raise Diverged(k)
    t = h * np.arange(nk + 1)
    return ClosedLoopRun(t=t, theta=np.array(out_th), theta_dot=np.array(out_om),
                         torque=np.array(out_t), q=np.asarray(qg[::2 * substeps]),
                         mode=np.array(out_mode, dtype=np.int8))


def energy_series(run) -> np.ndarray:
    """Cumulative extracted energy ``W_k = -sum_{j<k} T_j (theta_{j+1} - theta_j)`` (exact
    for the held torque; positive = harvested), shape (K + 1,)."""
    w = -run.torque[:-1] * np.diff(run.theta)
    return np.concatenate(([0.0], np.cumsum(w)))


def mechanical_energy(run) -> np.ndarray:
    """``E_k`` of :func:`.swingup.energy` along the run."""
    return 0.5 * run.theta_dot**2 + np.cos(run.theta)

