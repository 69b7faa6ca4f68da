"""The periodic orbit a controller tracks: an optimal rotation and its feedforward torque.

The target is the ideal optimum of :func:`parapend.optimize` or, under a torque limit, the
torque-limited optimum of :func:`parapend.pto.optimize_pto`. Only the motion's ``theta``,
``theta_dot`` and ``theta_ddot`` (vectorized callables of time) are used; the feedforward
torque is Eq. 14 solved for ``T`` on the motion (:func:`parapend.model.torque`).

The controller is sampled: ``samples`` per forcing period ``2 pi / omega`` (256 by default,
the rate of the saved series), torque held over each sample interval (zero-order hold).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model import torque as _torque

__all__ = ["Target", "build_target"]


@dataclass(frozen=True, eq=False)
class Target:
    """One forcing period of the tracked orbit on the controller's sample grid.

    Attributes
    ----------
    excitation : Excitation
        The design excitation ``q(t)`` (the controller's model).
    gamma : float
        The design damping.
    motion : object
        The optimal motion (``theta``, ``theta_dot``, ``theta_ddot`` of time).
    power : float
        The optimum's mean power (positive = harvested), the controller's prediction.
    peak_torque : float
        ``max |T|`` of the optimum (from its own result).
    design_limit : float or None
        The torque limit the optimum was computed under (None: unconstrained).
    samples : int
        Controller samples per forcing period, ``M``.
    t : ndarray, shape (M,)
        Sample times ``j h`` in one period, ``h = (2 pi/omega) / M``.
    theta, theta_dot : ndarray, shape (M,)
        The orbit at the sample times (``theta`` unwrapped, from the upright).
    feedforward : ndarray, shape (M,)
        Eq. 14 torque at the interval midpoints ``t_j + h/2`` (midpoint rule: the held
        torque whose mean over the interval matches the motion's to O(h^2)).
    """

    excitation: object
    gamma: float
    motion: object
    power: float
    peak_torque: float
    design_limit: float | None
    samples: int
    t: np.ndarray
    theta: np.ndarray
    theta_dot: np.ndarray
    feedforward: np.ndarray

    @property
    def omega(self) -> float:
        return float(self.excitation.omega)

    @property
    def period(self) -> float:
        return 2 * math.pi / self.excitation.omega

    @property
    def step(self) -> float:
        return self.period / self.samples


def build_target(result, samples: int = 256, *, excitation=None, gamma=None) -> Target:
    """The target of an optimize / optimize_pto result.

    Only ``power``, ``peak_torque``, ``torque_limit`` (if any) and ``motion`` of the result
    are read, with ``excitation`` and ``gamma`` (default: the result's ``_excitation`` and
    ``gamma``, as :func:`parapend.optimize` gives them).
    """
    exc = result._excitation if excitation is None else excitation
    gamma = float(result.gamma if gamma is None else gamma)
    motion = result.motion
    period = 2 * math.pi / exc.omega
    h = period / samples
    t = h * np.arange(samples)
    ff = _torque(motion, exc, gamma, t + 0.5 * h)
    return Target(excitation=exc, gamma=gamma, motion=motion,
                  power=float(result.power), peak_torque=float(result.peak_torque),
                  design_limit=getattr(result, "torque_limit", None), samples=int(samples),
                  t=t, theta=np.asarray(motion.theta(t), dtype=float),
                  theta_dot=np.asarray(motion.theta_dot(t), dtype=float),
                  feedforward=np.asarray(ff, dtype=float))
