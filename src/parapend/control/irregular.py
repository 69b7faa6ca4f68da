"""A seeded irregular excitation for robustness runs: random-phase harmonics, JONSWAP-shaped.

A stand-in until the real-seas module (``seas.py``) lands; it should then be replaced by
that generator. ``q(t) = sum_i a_i sin(w_i t + phi_i)`` with ``n`` frequencies, one drawn
uniformly in each of ``n`` equal bins of ``[0.5, 2.5] omega`` (so the record does not repeat
with a short period), phases uniform in ``[0, 2 pi)``, and amplitudes
``a_i = sqrt(2 S_a(w_i) dw)`` from the base-acceleration spectrum ``S_a(w) = w^4 S(w)``,
``S`` the JONSWAP elevation spectrum (DNV-RP-C205, Eq. 3.5.5.1) with peak frequency ``omega``
(the design frequency), peak enhancement ``3.3`` and widths ``0.07 / 0.09``. The amplitudes
are scaled so that the mean square of ``q`` equals ``rms**2`` (default: that of the design
excitation, ``delta^2 / 2`` for the harmonic case).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["IrregularExcitation", "irregular", "jonswap"]


def jonswap(w, peak: float, enhancement: float = 3.3):
    """Shape of the JONSWAP elevation spectrum at angular frequencies ``w`` (peak ``peak``),
    up to a constant factor."""
    w = np.asarray(w, dtype=float)
    sigma = np.where(w <= peak, 0.07, 0.09)
    r = np.exp(-((w - peak) ** 2) / (2 * sigma**2 * peak**2))
    return w**-5.0 * np.exp(-1.25 * (peak / w) ** 4) * enhancement**r


@dataclass(frozen=True, eq=False)
class IrregularExcitation:
    """``q(t) = sum a_i sin(w_i t + phi_i)`` (shapes (n,))."""

    frequencies: np.ndarray
    amplitudes: np.ndarray
    phases: np.ndarray

    def q(self, t):
        t = np.asarray(t, dtype=float)
        out = np.zeros_like(t)
        for w, a, p in zip(self.frequencies, self.amplitudes, self.phases):
            out += a * np.sin(w * t + p)
        return out

    @property
    def mean_square(self) -> float:
        """Mean of ``q^2`` over a long time: ``sum a_i^2 / 2``."""
        return float(0.5 * np.sum(self.amplitudes**2))


def irregular(omega: float, rms: float, rng, harmonics: int = 64,
              enhancement: float = 3.3) -> IrregularExcitation:
    """A seeded random-phase record around ``omega`` (module docstring)."""
    edges = np.linspace(0.5 * omega, 2.5 * omega, harmonics + 1)
    dw = edges[1] - edges[0]
    w = edges[:-1] + dw * rng.random(harmonics)
    ph = 2 * math.pi * rng.random(harmonics)
    a = np.sqrt(2 * w**4 * jonswap(w, omega, enhancement) * dw)
    a *= rms / math.sqrt(0.5 * np.sum(a**2))
    return IrregularExcitation(w, a, ph)
