"""Simulation of the uncontrolled parametrically excited pendulum (paper Eq. 1).

Public functions use the convention of paper Eq. 1 and Figs. 1-2: angle ``phi`` from the
*hanging* position, excitation strength ``p``, non-dimensional time (unit ``sqrt(l/g)``)::

    phi'' + gamma*phi' + (1 + p*cos(omega*t))*sin(phi) = 0                      (Eq. 1)

Internally the project's single model (``parapend.model``, paper Eqs. 2/14 with no torque)
is integrated, with ``theta`` from the upright::

    theta'' + gamma*theta' - (1 + q(t))*sin(theta) = 0,   theta = phi + pi,  q = p*cos(omega*t)

which is the same equation because ``sin(phi) = sin(theta - pi) = -sin(theta)``. Conversion
happens only at the edges (:func:`phi_to_theta`, :func:`theta_to_phi`).

Two integrators:

* :func:`stroboscopic` -- a fixed-step classic Runge-Kutta (RK4) integrator vectorized over
  NumPy arrays of initial conditions, sampling the Poincare section ``t = t0 + k*T``,
  ``T = 2*pi/omega`` (the stroboscopic map). The step is ``T/steps_per_period`` exactly, so
  sampling times carry no accumulated rounding and the discrete map is exactly
  ``T``-periodic in time. ``sin`` is evaluated by a Cody-Waite range reduction and a
  degree-17 minimax polynomial (about 1 ulp, 4-5x faster than ``numpy.sin`` on machines
  without a SIMD double-precision ``sin``); see :func:`fast_sin`.
* :func:`trajectory` -- one dense trajectory with :func:`scipy.integrate.solve_ivp`
  (DOP853, ``rtol = atol = 1e-11`` by default) for plots and as the reference solution.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.integrate import solve_ivp

from ..errors import ParameterError, check_finite, check_int, check_nonnegative, check_positive

__all__ = [
    "CONVENTION",
    "Stroboscopic",
    "Trajectory",
    "energy",
    "fast_sin",
    "phi_to_theta",
    "rhs",
    "trajectory",
    "stroboscopic",
    "theta_to_phi",
]

CONVENTION = ("paper Eq. 1: phi from the hanging position (phi = theta - pi, theta from the "
              "upright), phi'' + gamma phi' + (1 + p cos(omega t)) sin(phi) = 0, "
              "non-dimensional time (unit sqrt(l/g)); Poincare section t = t0 + k 2 pi/omega")

# --- fast sine ---------------------------------------------------------------------------
_INV_PI = 1.0 / math.pi
_PI1 = 3.1415926534682512283  # pi to 33 bits: k*_PI1 is exact for |k| < 2**20
_PI2 = 1.2154201013012384e-10  # pi - _PI1 rounded to double; |pi - _PI1 - _PI2| < 1e-26
# minimax-like (Chebyshev) coefficients of (sin(y) - y)/y**3 in z = y**2 on |y| <= pi/2,
# highest power first (y**17 ... y**3); max error of the sine 3.3e-16 (1.5 ulp)
_SIN_C = (2.7215749422983443e-15, -7.643026557971632e-13, 1.605894087848656e-10,
          -2.505210689056952e-08, 2.7557319211229606e-06, -0.00019841269841208676,
          0.008333333333333186, -0.16666666666666666)


def fast_sin(x: np.ndarray, out: np.ndarray | None = None,
             work: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """``sin(x)`` for float64 arrays, to about 1.5 ulp, allocation-free when buffers are given.

    ``x = k*pi + y`` with ``k = rint(x/pi)`` (Cody-Waite reduction, exact for ``|x| < 1e6``),
    ``sin(x) = sin((-1)**k * y)``, and the sine on ``|y| <= pi/2`` is a degree-17 odd
    polynomial. Accurate for ``|x|`` up to about ``1e6``; the stroboscopic integrator keeps
    the angle within a few turns of the origin.

    Parameters
    ----------
    x : ndarray of float64
        Arguments (radians); not modified.
    out : ndarray, optional
        Output array, same shape as ``x`` (must not be ``x``).
    work : (ndarray, ndarray), optional
        Two scratch arrays of the same shape.

    Returns
    -------
    ndarray
        ``sin(x)``, in ``out`` if given.
    """
    x = np.asarray(x, dtype=float)
    if out is None:
        out = np.empty_like(x)
    k, t = work if work is not None else (np.empty_like(x), np.empty_like(x))
    np.multiply(x, _INV_PI, out=k)
    np.rint(k, out=k)
    np.multiply(k, _PI1, out=t)
    np.subtract(x, t, out=out)
    np.multiply(k, _PI2, out=t)
    out -= t                           # y in [-pi/2, pi/2]
    # sign (-1)**k: t = k - 2*rint(k/2) in {-1, 0, 1}; sign = 1 - 2 t**2
    np.multiply(k, 0.5, out=t)
    np.rint(t, out=t)
    t *= -2.0
    t += k
    np.multiply(t, t, out=t)
    t *= -2.0
    t += 1.0
    out *= t                           # y' = (-1)**k y; sin(x) = sin(y')
    np.multiply(out, out, out=k)       # z = y'**2
    np.multiply(k, _SIN_C[0], out=t)
    for c in _SIN_C[1:]:
        t += c
        t *= k
    t *= out
    out += t
    return out


# --- conventions -------------------------------------------------------------------------
def phi_to_theta(phi: ArrayLike) -> np.ndarray:
    """Angle from the upright (project model) from the angle from hanging (Eq. 1)."""
    return np.asarray(phi, dtype=float) + math.pi


def theta_to_phi(theta: ArrayLike) -> np.ndarray:
    """Angle from hanging (Eq. 1) from the angle from the upright (project model)."""
    return np.asarray(theta, dtype=float) - math.pi


def _check_params(gamma, p, omega) -> tuple[float, float, float]:
    return (check_nonnegative("gamma", gamma), check_finite("p", p),
            check_positive("omega", omega))


def rhs(gamma: float, p: float, omega: float) -> Callable[[float, np.ndarray], np.ndarray]:
    """Right-hand side ``f(t, y)``, ``y = (phi, phi')``, of paper Eq. 1 for ``solve_ivp``.

    Evaluated through the project model (``theta = phi + pi``,
    ``theta'' = -gamma theta' + (1 + p cos(omega t)) sin(theta)``).
    """
    gamma, p, omega = _check_params(gamma, p, omega)

    def f(t, y):
        th = y[0] + math.pi
        return np.array([y[1], (1.0 + p * math.cos(omega * t)) * math.sin(th) - gamma * y[1]])

    return f


def energy(phi: ArrayLike, dphi: ArrayLike) -> np.ndarray:
    """Energy of the unforced pendulum in Eq. 1's convention, ``dphi**2/2 + 1 - cos(phi)``.

    Conserved when ``gamma = 0`` and ``p = 0``; zero at rest hanging down.
    """
    phi = np.asarray(phi, dtype=float)
    dphi = np.asarray(dphi, dtype=float)
    return 0.5 * dphi**2 + 1.0 - np.cos(phi)


# --- dense single trajectory -------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class Trajectory:
    """A dense trajectory of paper Eq. 1 (``phi`` from hanging, unwrapped).

    Attributes
    ----------
    t : ndarray, shape (m,)
        Times (non-dimensional).
    phi, dphi : ndarray, shape (m,)
        Angle from the hanging position (radians, not wrapped) and its rate.
    gamma, p, omega : float
        Parameters of Eq. 1.
    success : bool
    message : str
        From :func:`scipy.integrate.solve_ivp`.
    nfev : int
        Right-hand-side evaluations.
    sol : callable or None
        Dense output ``sol(t) -> (phi, dphi)`` (DOP853 interpolant), None if not requested.
    """

    t: np.ndarray
    phi: np.ndarray
    dphi: np.ndarray
    gamma: float
    p: float
    omega: float
    success: bool
    message: str
    nfev: int
    sol: object = None

    @property
    def theta(self) -> np.ndarray:
        """Angle from the upright (project convention), ``phi + pi``."""
        return phi_to_theta(self.phi)


def trajectory(phi0: float, dphi0: float, gamma: float, p: float, omega: float,
               t_end: float, *, t0: float = 0.0, t_eval: ArrayLike | None = None,
               points_per_period: int = 64, rtol: float = 1e-11, atol: float = 1e-11,
               dense: bool = False) -> Trajectory:
    """Integrate one trajectory of paper Eq. 1 with ``solve_ivp`` (DOP853).

    Parameters
    ----------
    phi0, dphi0 : float
        Initial angle from the hanging position (rad) and angular rate at ``t0``.
    gamma, p, omega : float
        Damping (>= 0), excitation strength and frequency (> 0) of Eq. 1.
    t_end : float
        Final time (> t0).
    t0 : float
        Initial time (the forcing phase is ``omega*t``).
    t_eval : array_like, optional
        Output times; default ``points_per_period`` uniform samples per forcing period.
    points_per_period : int
        Samples per period ``2*pi/omega`` when ``t_eval`` is not given.
    rtol, atol : float
        Tolerances of DOP853.
    dense : bool
        Keep the dense-output interpolant in ``Trajectory.sol``.

    Returns
    -------
    Trajectory
    """
    gamma, p, omega = _check_params(gamma, p, omega)
    phi0, dphi0 = check_finite("phi0", phi0), check_finite("dphi0", dphi0)
    t0, t_end = check_finite("t0", t0), check_finite("t_end", t_end)
    if t_end <= t0:
        raise ParameterError(f"t_end: expected a time after t0 = {t0:g}, got {t_end:g}")
    if t_eval is None:
        n = check_int("points_per_period", points_per_period, 2)
        period = 2 * math.pi / omega
        m = int(math.ceil((t_end - t0) / period * n))
        t_eval = np.linspace(t0, t_end, m + 1)
    f = rhs(gamma, p, omega)
    r = solve_ivp(f, (t0, t_end), [phi0, dphi0], method="DOP853", t_eval=t_eval,
                  rtol=rtol, atol=atol, dense_output=dense)
    return Trajectory(t=r.t, phi=r.y[0], dphi=r.y[1], gamma=gamma, p=p, omega=omega,
                      success=bool(r.success), message=str(r.message), nfev=int(r.nfev),
                      sol=r.sol if dense else None)


# --- vectorized stroboscopic map -----------------------------------------------------------
class _RK4Map:
    """Fixed-step RK4 over one forcing period, in place, for a batch of trajectories.

    State in the project convention: ``theta`` (from the upright) and ``v = theta'``. The
    forcing ``a(t) = 1 + p cos(omega t)`` is tabulated at the step starts and midpoints of
    one period, so every period uses identical coefficients.
    """

    def __init__(self, gamma: float, p: float, omega: float, steps: int, t0: float = 0.0):
        self.gamma = float(gamma)
        self.steps = int(steps)
        self.period = 2 * math.pi / omega
        self.h = self.period / self.steps
        j = np.arange(2 * self.steps + 1)
        # phase omega*(t0 + j*h/2) = omega*t0 + pi*j/steps: evaluate without accumulation
        self.a = 1.0 + p * np.cos(omega * t0 + math.pi * j / self.steps)
        self._n = -1

    def _buffers(self, n: int):
        if n != self._n:
            self._b = [np.empty(n) for _ in range(8)]
            self._n = n
        return self._b

    def advance(self, th: np.ndarray, v: np.ndarray, periods: int = 1) -> None:
        """Advance ``th``, ``v`` (1-D float arrays, modified in place) by whole periods."""
        n = th.size
        s, tt, vv, kk, ath, av, w1, w2 = self._buffers(n)
        work = (w1, w2)
        gamma, h = self.gamma, self.h
        h2, h6 = 0.5 * h, h / 6.0
        a = self.a
        for _ in range(periods):
            for j in range(self.steps):
                a0, ah, a1 = a[2 * j], a[2 * j + 1], a[2 * j + 2]
                # stage 1
                fast_sin(th, s, work)
                np.multiply(s, a0, out=kk)
                np.multiply(v, gamma, out=w1)
                kk -= w1
                np.copyto(ath, v)
                np.copyto(av, kk)
                np.multiply(v, h2, out=tt)
                tt += th
                np.multiply(kk, h2, out=vv)
                vv += v
                # stages 2, 3
                for c in (h2, h):
                    fast_sin(tt, s, work)
                    np.multiply(s, ah, out=kk)
                    np.multiply(vv, gamma, out=w1)
                    kk -= w1
                    np.multiply(vv, 2.0, out=w1)
                    ath += w1
                    np.multiply(kk, 2.0, out=w1)
                    av += w1
                    np.multiply(vv, c, out=tt)
                    tt += th
                    np.multiply(kk, c, out=vv)
                    vv += v
                # stage 4
                fast_sin(tt, s, work)
                np.multiply(s, a1, out=kk)
                np.multiply(vv, gamma, out=w1)
                kk -= w1
                ath += vv
                av += kk
                ath *= h6
                th += ath
                av *= h6
                v += av


def _check_steps(steps_per_period) -> int:
    return check_int("steps_per_period", steps_per_period, 8)


@dataclass(frozen=True, eq=False)
class Stroboscopic:
    """Poincare (stroboscopic) samples of paper Eq. 1 at ``t_k = t0 + k*2*pi/omega``.

    Attributes
    ----------
    t : ndarray, shape (periods + 1,)
        Sampling times.
    phi, dphi : ndarray, shape ``(periods + 1, *shape)``
        Angle from hanging (unwrapped, radians) and rate; ``shape`` is the broadcast shape
        of the initial conditions.
    gamma, p, omega : float
    steps_per_period : int
        RK4 steps per forcing period.
    """

    t: np.ndarray
    phi: np.ndarray
    dphi: np.ndarray
    gamma: float
    p: float
    omega: float
    steps_per_period: int

    @property
    def turns(self) -> np.ndarray:
        """Net turns since ``t0``, ``round((phi_k - phi_0)/(2 pi))``; shape like ``phi``."""
        return np.rint((self.phi - self.phi[0]) / (2 * math.pi))


def initial_conditions(phi0, dphi0) -> tuple[np.ndarray, np.ndarray]:
    """Broadcast initial ``(phi, phi')`` to float arrays of one shape; reject non-finite ones."""
    phi0, dphi0 = np.broadcast_arrays(np.asarray(phi0, dtype=float),
                                      np.asarray(dphi0, dtype=float))
    if not (np.all(np.isfinite(phi0)) and np.all(np.isfinite(dphi0))):
        raise ParameterError("phi0, dphi0: expected finite initial conditions")
    return phi0, dphi0


def stroboscopic(phi0: ArrayLike, dphi0: ArrayLike, gamma: float, p: float, omega: float,
                 periods: int, *, steps_per_period: int = 256, t0: float = 0.0) -> Stroboscopic:
    """Stroboscopic map of paper Eq. 1 for many initial conditions at once (fixed-step RK4).

    Parameters
    ----------
    phi0, dphi0 : array_like
        Initial angle from the hanging position (rad) and rate at ``t0``; broadcast together
        to a common shape.
    gamma, p, omega : float
        Damping (>= 0), excitation strength and frequency (> 0) of Eq. 1.
    periods : int
        Number of forcing periods ``T = 2*pi/omega`` (>= 0).
    steps_per_period : int
        RK4 steps per period (>= 8). The error scales as ``steps_per_period**-4``: over
        ten periods at ``omega = 2.1`` it is about 1e-6 (64 steps), 1e-7 (128) and 5e-9
        (256) against DOP853 at ``rtol = 1e-13``, up to 50 times more for transients that
        pass near the upright (see ``tests/test_dynamics.py``).
    t0 : float
        Initial time; samples are taken at ``t0 + k*T``.

    Returns
    -------
    Stroboscopic
        Samples for ``k = 0..periods``; memory ``16*(periods + 1)*size`` bytes.
    """
    gamma, p, omega = _check_params(gamma, p, omega)
    periods = check_int("periods", periods, 0)
    steps = _check_steps(steps_per_period)
    t0 = check_finite("t0", t0)
    phi0, dphi0 = initial_conditions(phi0, dphi0)
    shape = phi0.shape
    # unwrapped phi = (theta + 2 pi turns) - pi; theta is kept within [-pi, pi) each period
    th = phi_to_theta(phi0).ravel().copy()
    turns = np.rint(th / (2 * math.pi))
    th -= 2 * math.pi * turns
    v = dphi0.ravel().copy()
    phi_out = np.empty((periods + 1, th.size))
    dphi_out = np.empty((periods + 1, th.size))
    phi_out[0] = phi0.ravel()
    dphi_out[0] = v
    m = _RK4Map(gamma, p, omega, steps, t0)
    for k in range(1, periods + 1):
        m.advance(th, v)
        w = np.rint(th / (2 * math.pi))
        th -= 2 * math.pi * w
        turns += w
        phi_out[k] = theta_to_phi(th) + 2 * math.pi * turns
        dphi_out[k] = v
    t = t0 + m.period * np.arange(periods + 1)
    return Stroboscopic(t=t, phi=phi_out.reshape((periods + 1,) + shape),
                        dphi=dphi_out.reshape((periods + 1,) + shape), gamma=gamma, p=p,
                        omega=omega, steps_per_period=steps)
