"""Linear waves: the dispersion relation, the group velocity and the energy flux of a
wave of given amplitudes (what the capture width of :mod:`.result` divides by)."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["energy_flux", "group_velocity", "wavenumber"]


def wavenumber(omega: float, depth: float, g: float) -> float:
    """``k`` of ``omega^2 = g k tanh(k h)`` (deep water where ``h`` is infinite)."""
    k0 = omega * omega / g
    if not math.isfinite(depth):
        return k0
    from scipy.optimize import brentq

    lo, hi = k0 * 0.5, max(k0, omega / math.sqrt(g * depth)) * 2 + 1e-12
    return float(brentq(lambda k: g * k * math.tanh(k * depth) - omega * omega, lo, hi,
                        xtol=1e-14, rtol=1e-14, maxiter=200))


def group_velocity(omega: float, depth: float = math.inf, g: float = 9.81) -> float:
    """Group velocity of linear waves, m/s: ``g / (2 omega)`` in deep water, ``(omega/k) (1 +
    2 k h / sinh(2 k h)) / 2`` in depth ``h``."""
    if not math.isfinite(depth):
        return g / (2 * omega)
    k = wavenumber(omega, depth, g)
    kh2 = 2 * k * depth
    return 0.5 * omega / k * (1 + (kh2 / math.sinh(kh2) if kh2 < 700 else 0.0))


def energy_flux(omega: float, amplitudes, rho: float = 1025.0, g: float = 9.81,
                depth: float = math.inf) -> float:
    """Energy flux per metre of crest, W/m, of the wave ``Re sum_k a_k exp(i k omega t)``:
    ``J = rho g sum_k |a_k|^2 c_g(k omega) / 2``; a regular wave in deep water gives
    ``rho g^2 H^2 T / (32 pi)``. One amplitude may be given as a scalar or a 0-d array."""
    a = np.atleast_1d(np.asarray(amplitudes))
    if a.ndim != 1:
        from ..errors import ParameterError

        raise ParameterError(f"amplitudes: expected a 1-d sequence, got shape {a.shape}")
    total = 0.0
    for k, ak in enumerate(a, start=1):
        if ak != 0:
            total += 0.5 * abs(ak) ** 2 * group_velocity(k * omega, depth, g)
    return rho * g * total
