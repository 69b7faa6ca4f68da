"""Period-1 rotations ``theta(t)`` (Eqs. 3-4): Fourier series, sampled, piecewise-constant.

Every motion gives ``theta``, ``theta_dot`` and ``theta_ddot`` at arbitrary times and
satisfies ``theta(t + 2*pi/omega) = theta(t) + 2*pi*K`` (``K = winding`` turns per period,
1 unless given: the paper's period-1 rotation; records of irregular seas use more).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["FourierMotion", "PiecewiseConstantMotion", "SampledMotion"]


@dataclass(frozen=True, eq=False)
class FourierMotion:
    """Truncated Fourier rotation of paper Eq. 10, with ``s = omega*t``.

    The motion is::

        theta = s + a0 + sum_{n=1}^{N} (a[n-1] sin(n s) + b[n-1] cos(n s))

    Parameters
    ----------
    omega : float
        Forcing frequency.
    a0 : float
        Phase offset (radians).
    a, b : ndarray, shape (N,)
        Sine and cosine coefficients (radians).
    """

    omega: float
    a0: float
    a: np.ndarray
    b: np.ndarray
    winding: int = 1

    @classmethod
    def from_vector(cls, omega: float, x: np.ndarray, winding: int = 1) -> FourierMotion:
        """Build from the packed vector ``x = [a0, a_1..a_N, b_1..b_N]``."""
        n = (x.size - 1) // 2
        return cls(omega, float(x[0]), np.array(x[1:n + 1]), np.array(x[n + 1:]), winding)

    @property
    def harmonics(self) -> int:
        return int(np.size(self.a))

    @property
    def vector(self) -> np.ndarray:
        """Packed coefficients ``[a0, a_1..a_N, b_1..b_N]``."""
        return np.concatenate(([self.a0], self.a, self.b))

    def _trig(self, t):
        s = self.omega * np.asarray(t, dtype=float)
        n = np.arange(1, self.harmonics + 1)
        ns = np.multiply.outer(s, n)
        return s, n, np.sin(ns), np.cos(ns)

    def theta(self, t):
        s, _, sn, cn = self._trig(t)
        return self.winding * s + self.a0 + sn @ self.a + cn @ self.b

    def theta_dot(self, t):
        """Eq. 11 (with ``K`` in place of the leading 1 for winding ``K``)."""
        _, n, sn, cn = self._trig(t)
        return self.omega * (self.winding + cn @ (n * self.a) - sn @ (n * self.b))

    def theta_ddot(self, t):
        _, n, sn, cn = self._trig(t)
        return -self.omega**2 * (sn @ (n * n * self.a) + cn @ (n * n * self.b))

    def on_grid(self, points: int):
        """``theta, theta', theta''`` at ``t_j = j T / points`` by inverse FFTs (O(M log M)).

        ``points`` must exceed ``2 N``.
        """
        n, m = self.harmonics, points
        if m <= 2 * n:
            raise ValueError(f"points: expected more than 2N = {2 * n}, got {m}")
        k = np.arange(1, n + 1)
        c = np.zeros(m // 2 + 1, dtype=complex)
        c[1:n + 1] = (0.5 * m) * (self.b - 1j * self.a)  # Re((b - ia) e^{iks})
        s = 2 * np.pi * np.arange(m) / m
        theta = self.winding * s + self.a0 + np.fft.irfft(c, m)
        d = np.zeros_like(c)
        d[1:n + 1] = c[1:n + 1] * (1j * k)
        theta_dot = self.omega * (self.winding + np.fft.irfft(d, m))
        d[1:n + 1] *= 1j * k
        theta_ddot = self.omega**2 * np.fft.irfft(d, m)
        return theta, theta_dot, theta_ddot

    def mean_square_speed(self) -> float:
        """``<theta'^2> = omega^2 (K^2 + sum n^2 (a_n^2 + b_n^2)/2)`` (Parseval, exact)."""
        n = np.arange(1, self.harmonics + 1)
        ab2 = self.a**2 + self.b**2
        return float(self.omega**2 * (self.winding**2 + 0.5 * np.sum(n * n * ab2)))


@dataclass(frozen=True, eq=False)
class SampledMotion:
    """A rotation given on a uniform grid of one period, interpolated trigonometrically.

    ``theta - omega*t`` is periodic; it is represented by its FFT so derivatives are
    spectral. ``theta`` has shape (m,) on ``t_j = j*T/m``.
    """

    omega: float
    theta_samples: np.ndarray

    def to_fourier(self) -> FourierMotion:
        m = self.theta_samples.size
        s = 2 * np.pi * np.arange(m) / m
        x = np.fft.rfft(self.theta_samples - s) / m
        n = m // 2 - 1 if m % 2 == 0 else m // 2
        c = 2 * x[1:n + 1]
        # Re(c e^{ins}) = c.real cos - c.imag sin
        return FourierMotion(self.omega, float(x[0].real), -c.imag, c.real)


@dataclass(frozen=True, eq=False)
class PiecewiseConstantMotion:
    """The gamma -> 0 limit motion: dwells at 0 or pi, instantaneous half-turns.

    Parameters
    ----------
    omega : float
        Forcing frequency.
    switch_times : ndarray, shape (m,)
        Instants of the half-turns in ``[0, 2*pi/omega)``, increasing.
    directions : ndarray of int, shape (m,)
        +1 (forward) or -1 (backward) for each half-turn; they sum to 2 (one net turn).
    theta_start : float
        The angle held on ``[0, switch_times[0])`` (0 upright or pi hanging).
    """

    omega: float
    switch_times: np.ndarray
    directions: np.ndarray
    theta_start: float
    winding: int = 1

    def theta(self, t):
        t = np.asarray(t, dtype=float)
        period = 2 * math.pi / self.omega
        turns = np.floor(t / period)
        tm = t - turns * period
        steps = np.searchsorted(self.switch_times, tm, side="right")
        cum = np.concatenate(([0.0], np.cumsum(self.directions)))
        return self.theta_start + math.pi * cum[steps] + 2 * math.pi * self.winding * turns
