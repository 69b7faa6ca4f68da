"""Results and profiles shared by the power take-off solvers.

:class:`PTOSolution` is the outcome of one PTO solve as :func:`parapend.pto.optimize_pto`
reports it (from :mod:`parapend.optimal.hermite`, the torque-limited optimum, or
:mod:`parapend.optimal.collocation`, the efficiency and copper-loss optima);
:func:`pto_profile` gives the torque ``T(t)`` (Eq. 14 solved for ``T``, the motion's own
torque) and the instantaneous power ``p = -T theta'`` of any motion over one period, with
the energy harvested and the energy the machine puts back (motoring) per cycle.

(The efficiency was solved here on the Fourier series of Eq. 10 with a softplus-smoothed
kink, 17 times slower than IPOPT; :mod:`parapend.optimal.collocation` replaced it, see
docs/units.md.)
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..model import peak_torque

__all__ = ["PTOSolution", "pto_profile"]


@dataclass(frozen=True)
class PTOSolution:
    """Outcome of one PTO solve (:func:`parapend.pto.optimize_pto`'s time-domain methods).

    Attributes
    ----------
    x : ndarray
        The solver's unknowns (the nodes' ``theta, v`` and, for the collocation, ``u``).
    power : float
        Mean mechanical power ``P = -<T theta'>`` (Eq. 15), m g l / t0.
    electrical_power : float
        Mean electrical power with the unsmoothed efficiency model and the copper loss
        (equals ``power`` without either).
    peak_torque : float
        ``max |T|`` on the motion's dense evaluation, m g l.
    max_violation : float
        ``max(peak_torque / T_max - 1, 0)`` (0 without a limit).
    status : str
        "converged", "infeasible" (the limit could not be met: ``T_max`` is below the
        smallest peak torque of any period-1 rotation found), "stalled" or "max_iterations".
    iterations : int
        Interior-point iterations over all stages.
    outer_iterations : int
        Stages (barrier solves, tightenings).
    gradient_norm : float
        The final KKT error of the collocation (NaN for the Hermite method).
    points : int
        Points of the discretization (nodes and midpoints of the collocation).
    """

    x: np.ndarray
    power: float
    electrical_power: float
    peak_torque: float
    max_violation: float
    status: str
    iterations: int
    outer_iterations: int
    gradient_norm: float
    points: int = 0
    stages: list = field(default_factory=list)


def pto_profile(motion, excitation, gamma: float, points: int = 4096,
                efficiency=None) -> dict:
    """Torque and power of a motion over one period, and what the machine must deliver.

    Parameters
    ----------
    motion : FourierMotion (or any motion with ``on_grid`` or theta/theta_dot/theta_ddot)
    excitation : Excitation
    gamma : float
        Viscous damping >= 0 (Eq. 14).
    points : int
        Uniform samples of one period.
    efficiency : (eta_g, eta_m) or None
        For the electrical power column.

    Returns
    -------
    dict
        Arrays ``t``, ``tau`` (= t/period), ``theta``, ``theta_dot``, ``torque`` (Eq. 14,
        m g l), ``power`` (``p = -T theta'``, positive harvested) and, with an efficiency,
        ``electrical_power``; scalars ``peak_torque`` (``max |T|``, dense), ``peak_power``
        (``max p``), ``peak_motoring_power`` (``max -p``, >= 0), ``harvested_energy``
        (``int max(p, 0) dt``) and ``motoring_energy`` (``int max(-p, 0) dt``, the energy put
        back into the pendulum each cycle), both m g l per forcing period.
    """
    period = excitation.period
    t = period * np.arange(points) / points
    if hasattr(motion, "on_grid") and points > 2 * motion.harmonics:
        th, thd, thdd = motion.on_grid(points)
    else:
        th, thd, thdd = motion.theta(t), motion.theta_dot(t), motion.theta_ddot(t)
    tq = thdd + gamma * thd - (1.0 + excitation.q_uniform(points)) * np.sin(th)
    p = -tq * thd
    dt = period / points
    out = {"t": t, "tau": t / period, "theta": th, "theta_dot": thd, "torque": tq,
           "power": p,
           "peak_torque": peak_torque(motion, excitation, gamma, points=points),
           "peak_power": float(np.max(p)), "peak_motoring_power": float(max(-np.min(p), 0.0)),
           "harvested_energy": float(np.sum(np.maximum(p, 0.0)) * dt),
           "motoring_energy": float(np.sum(np.maximum(-p, 0.0)) * dt)}
    if efficiency is not None:
        eg, em = efficiency
        out["electrical_power"] = np.where(p > 0, eg * p, p / em)
    return out
