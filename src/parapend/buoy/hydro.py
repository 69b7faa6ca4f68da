"""Stand-in for the hydrodynamic coefficients of a heaving buoy (the interface of ``Hydro``).

Only the dataclass and its evaluation methods: the BEM front ends (Capytaine) live in the
full module. Coefficients between the given frequencies are interpolated linearly in ``w``
(real and imaginary parts separately); above the highest frequency ``A`` is held and
``B = F = 0``; below the lowest ``A`` is held and ``B``, ``F`` go linearly to ``B(0) = 0``,
``F(0) = C``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError

__all__ = ["Hydro"]


@dataclass(frozen=True)
class Hydro:
    """Heave coefficients of a floating body (SI, convention ``exp(+i w t)``)."""

    omega: np.ndarray
    added_mass: np.ndarray
    radiation_damping: np.ndarray
    excitation: np.ndarray
    hydrostatic_stiffness: float
    mass: float
    rho: float = 1025.0
    g: float = 9.81
    water_depth: float = math.inf
    description: str = ""

    def coefficients(self, w):
        """``(A, B, F)`` at frequencies ``w`` (rad/s)."""
        w = np.asarray(w, dtype=float)
        om = np.concatenate(([0.0], np.asarray(self.omega, dtype=float)))
        a = np.asarray(self.added_mass, dtype=float)
        b = np.concatenate(([0.0], np.asarray(self.radiation_damping, dtype=float)))
        f = np.concatenate(([complex(self.hydrostatic_stiffness)],
                            np.asarray(self.excitation, dtype=complex)))
        A = np.interp(w, om[1:], a)
        B = np.interp(w, om, b, right=0.0)
        F = np.interp(w, om, f.real, right=0.0) + 1j * np.interp(w, om, f.imag, right=0.0)
        return A, B, F

    def above_range(self, w) -> np.ndarray:
        return np.asarray(w, dtype=float) > float(np.asarray(self.omega)[-1])

    def impedance(self, w):
        A, B, _ = self.coefficients(w)
        w = np.asarray(w, dtype=float)
        return -w**2 * (self.mass + A) + 1j * w * B + self.hydrostatic_stiffness

    def free_response(self, w):
        _, _, F = self.coefficients(w)
        return F / self.impedance(w)

    def radiation_bound(self, w, amplitude) -> float:
        _, B, F = self.coefficients(w)
        B = np.atleast_1d(B)
        e = np.atleast_1d(np.abs(F * amplitude) ** 2)
        ok = B > 0
        return float(np.sum(e[ok] / (8.0 * B[ok])))

    def check_covers(self, w_min, w_max, name="wave-period"):
        lo, hi = float(np.asarray(self.omega)[0]), float(np.asarray(self.omega)[-1])
        if w_min < lo * (1 - 1e-12) or w_max > hi * (1 + 1e-12):
            raise ParameterError(
                f"{name}: expected wave frequencies within the dataset's [{lo:.4g}, {hi:.4g}] "
                f"rad/s, got [{w_min:.4g}, {w_max:.4g}] rad/s")
