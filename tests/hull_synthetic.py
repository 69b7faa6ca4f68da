"""A synthetic hull in surge, heave and pitch for the kernel's tests: smooth coefficients of
a 10 m x 4 m x 1 m box's magnitudes, B positive semidefinite, a surge-pitch coupling in A
and B, excitation with the signs of a wave travelling +x. Not a BEM answer: a test bed
for invariants (derivatives, energy balance, limits), independent of Capytaine."""

from __future__ import annotations

import math

import numpy as np

from parapend.hydro.hull import HullCase, hull_points

RHO, G = 1025.0, 9.81
L, BEAM, DRAFT = 10.0, 4.0, 1.0
MASS = RHO * L * BEAM * DRAFT
PITCH_INERTIA = MASS * (L**2 / 12 + DRAFT**2 / 3)


def coefficients(w):
    """``(A, B, F)`` at the frequencies ``w`` (rad/s), shapes (n, 3, 3), (n, 3, 3), (n, 3)."""
    w = np.atleast_1d(np.asarray(w, dtype=float))
    bb = w**3 / (1 + w**4)
    a = np.zeros((w.size, 3, 3))
    b = np.zeros((w.size, 3, 3))
    a[:, 0, 0] = 0.3 * MASS
    a[:, 1, 1] = 0.8 * MASS / (1 + 0.1 * w)
    a[:, 2, 2] = 0.1 * MASS * L**2 / 12
    a[:, 0, 2] = a[:, 2, 0] = 0.05 * MASS
    b[:, 0, 0] = 0.2 * MASS * bb
    b[:, 1, 1] = 0.5 * MASS * bb
    b[:, 2, 2] = 0.02 * MASS * L**2 * bb
    b[:, 0, 2] = b[:, 2, 0] = 0.03 * MASS * bb
    f = np.stack((0.5j * RHO * G * BEAM * DRAFT * w,
                  RHO * G * L * BEAM * np.exp(-0.3 * w) + 0j,
                  0.3j * RHO * G * BEAM * L**2 * w / (1 + w)), axis=1)
    return a, b, f


def stiffness():
    return np.diag([0.0, RHO * G * L * BEAM, RHO * G * BEAM * (L**3 / 12 - L * DRAFT**2 / 2)])


def case(*, winding=1, harmonics=8, hull_harmonics=None, omega=2 * math.pi / 5, height=1.0,
         m=2000.0, length=1.0, inertia=None, c=50.0, pivot=(0.5, 1.0), amplitudes=None):
    """A :class:`HullCase` on the synthetic hull (the pendulum's mass taken from the
    hull's, which floats at its draft with the pendulum aboard)."""
    nh = hull_harmonics or harmonics + max(winding, 1)
    a, b, f = coefficients(np.arange(nh + 1) * omega)
    amps = np.array([height / 2]) if amplitudes is None else np.asarray(amplitudes)
    return HullCase(omega=omega, amplitudes=amps, winding=winding, harmonics=harmonics,
                    hull_harmonics=nh, points=hull_points(harmonics, nh, winding, amps.size),
                    A=a, B=b, F=f, C=stiffness(),
                    Mh=np.diag([MASS - m, MASS - m, PITCH_INERTIA]), m=m, l=length,
                    I=inertia or 1.2 * m * length**2, c=c, g=G, pivot=pivot)
