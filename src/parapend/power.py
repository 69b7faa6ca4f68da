"""Mean extracted power of a period-1 rotation (paper Eqs. 7, 8, 15, 16).

Positive power is harvested. Over one forcing period ``T = 2*pi/omega``, with ``< >`` the
mean over the period::

    P = -<T theta'> = <(1 + q) sin(theta) theta'> - gamma <theta'^2>        (Eqs. 15-16)

The term ``<theta'' theta'>`` of Eq. 7 vanishes by periodicity (Eq. 4). Integrating by parts
(``cos(theta)`` is periodic for a period-1 rotation) gives the equivalent form used by the
optimizers::

    P = <q'(t) cos(theta)> - gamma <theta'^2>

Both are periodic integrands, so the trapezoidal rule on a uniform grid is spectrally
accurate; :func:`mean_power` uses the first form and the optimizer the second, which makes
them an independent check of each other.
"""

from __future__ import annotations

import math

import numpy as np

from . import limits
from .errors import ParameterError, check_int, check_range

__all__ = ["limit_motion_power", "mean_power", "power_by_parts", "uniform_power"]


def _grid(omega: float, points: int) -> np.ndarray:
    return (2 * math.pi / omega) * np.arange(points) / points


def _check_excitation(excitation):
    from .excitation import Excitation

    if not isinstance(excitation, Excitation):
        raise ParameterError(f"excitation: expected an Excitation (parapend.harmonic(...), "
                             f"parapend.build_excitation(...)), got {type(excitation).__name__}")
    return excitation


def _check_motion(motion):
    if not all(hasattr(motion, a) for a in ("omega", "theta", "theta_dot")):
        raise ParameterError(f"motion: expected a motion with omega, theta and theta_dot "
                             f"(e.g. OptimizeResult.motion), got {type(motion).__name__}")
    return motion


def _check_common(motion, excitation, gamma, points):
    _check_motion(motion)
    _check_excitation(excitation)
    gamma = check_range("gamma", gamma, 0.0, limits.MAX_GAMMA)
    npts = check_int("points", points, 2, 1 << 24)
    return gamma, npts


def mean_power(motion, excitation, gamma: float = 0.0, points: int = 4096) -> float:
    """Mean extracted power (Eqs. 15-16) of a smooth motion by the periodic trapezoidal rule.

    Parameters
    ----------
    motion : FourierMotion or any object with ``theta`` and ``theta_dot``
    excitation : Excitation
    gamma : float
        Viscous damping >= 0 (Eq. 14), non-dimensional.
    points : int
        Quadrature points per period.
    """
    gamma, points = _check_common(motion, excitation, gamma, points)
    t = _grid(motion.omega, points)
    th, thd = motion.theta(t), motion.theta_dot(t)
    q = excitation.q(t)
    return float(np.mean((1.0 + q) * np.sin(th) * thd) - gamma * np.mean(thd * thd))


def power_by_parts(motion, excitation, gamma: float = 0.0, points: int = 4096) -> float:
    """Same power in the integrated-by-parts form ``<q' cos(theta)> - gamma <theta'^2>``."""
    gamma, points = _check_common(motion, excitation, gamma, points)
    t = _grid(motion.omega, points)
    th, thd = motion.theta(t), motion.theta_dot(t)
    return float(np.mean(excitation.dq(t) * np.cos(th)) - gamma * np.mean(thd * thd))


def uniform_power(excitation, gamma: float = 0.0, winding: int = 1) -> tuple[float, float]:
    """Best uniform rotation ``theta = omega t + phi`` (Eq. 17 generalized): (power, phi).

    Only the first harmonic ``Q1`` of ``q`` does work on a uniform rotation:
    ``<q' cos(s + phi)> = omega |Q1| cos(phi - arg(1j Q1)) / 2``, so the best phase is
    ``phi = arg(1j*Q1)`` and ``P = omega |Q1| / 2 - gamma omega^2``. For ``q = delta sin(omega
    t)``: ``P = omega |delta| / 2`` (Eq. 17), reached at ``phi = pi`` when ``delta < 0``.

    Winding K, ``theta = K omega t + phi``: only the K-th harmonic works,
    ``P = K omega |Q_K| / 2 - gamma K^2 omega^2`` at ``phi = arg(1j Q_K)``.
    """
    _check_excitation(excitation)
    gamma = check_range("gamma", gamma, 0.0, limits.MAX_GAMMA)
    if winding != 1:
        spec = excitation.spectrum
        qk = complex(spec[winding]) if 0 < winding < spec.size else 0j
        om = excitation.omega * winding
        phi = float(np.angle(1j * qk)) if qk != 0 else 0.0
        return float(om * abs(qk) / 2 - gamma * om * om), phi
    q1 = excitation.first_harmonic
    om = excitation.omega
    phi = float(np.angle(1j * q1)) if q1 != 0 else 0.0
    return float(om * abs(q1) / 2 - gamma * om * om), phi


def limit_motion_power(motion, excitation) -> float:
    """Power of a piecewise-constant motion (Eq. 18 in the limit alpha -> 0).

    Across an instantaneous turn at ``t_k`` from ``theta-`` to ``theta+``,
    ``int (1+q) sin(theta) dtheta = (1 + q(t_k)) (cos(theta-) - cos(theta+))``; the dwells
    contribute nothing. Damping is not included (its cost diverges for jumps).
    """
    cum = motion.theta_start + math.pi * np.concatenate(([0.0], np.cumsum(motion.directions)))
    work = (1.0 + excitation.q(motion.switch_times)) * (np.cos(cum[:-1]) - np.cos(cum[1:]))
    return float(np.sum(work) * motion.omega / (2 * math.pi))
