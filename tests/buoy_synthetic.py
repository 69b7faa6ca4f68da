"""Synthetic heave datasets for the buoy tests and benchmark (no BEM needed).

:func:`synthetic`: an exactly causal dataset. The radiation force has the transfer
function ``H(s) = k s / (s^2 + 2 zeta w0 s + w0^2)`` (``s = i w``): ``B(w) = Re H(i w)``,
``A(w) = A_inf + Im H(i w) / w`` (Kramers-Kronig holds exactly), impulse response
``K(t) = k exp(-zeta w0 t) (cos(wd t) - zeta w0 / wd sin(wd t))``.

:func:`toy_hydro`: an analytic, passive set sized by a radius (tests/test_buoy_kernel.py,
benchmarks/bench_buoy.py).
"""

import math

import numpy as np

from parapend.hydro.bem import Hydro

K, ZETA, W0, A_INF = 2000.0, 0.5, 2.5, 800.0
C, M = 17769.0, 1358.5


def h_of(w):
    s = 1j * np.asarray(w, dtype=float)
    return K * s / (s * s + 2 * ZETA * W0 * s + W0 * W0)


def exact(w):
    """A, B, F at ``w`` (F: a smooth causal-looking excitation, F(0) = C)."""
    w = np.asarray(w, dtype=float)
    h = h_of(w)
    a = A_INF + h.imag / w
    b = h.real
    f = C * np.exp(-0.08 * w * w) + 1j * w * b * np.exp(-0.05 * w * w)
    return a, b, f


def kernel(t):
    wd = W0 * np.sqrt(1 - ZETA**2)
    t = np.asarray(t, dtype=float)
    return K * np.exp(-ZETA * W0 * t) * (np.cos(wd * t) - ZETA * W0 / wd * np.sin(wd * t))


def synthetic(n=400, w_max=60.0, w_min=0.05):
    w = np.linspace(w_min, w_max, n)
    a, b, f = exact(w)
    return Hydro(omega=w, added_mass=a, radiation_damping=b, excitation=f,
                 hydrostatic_stiffness=C, mass=M, description="synthetic")


def toy_hydro(radius=1.0, rho=1025.0, g=9.81, n=200, top=8.0) -> Hydro:
    """A passive heave model: constant A, B(w) >= 0 vanishing at 0, |F|^2 from B (the
    Haskind relation of deep water), the stiffness and mass of a floating body of this
    radius."""
    w = np.linspace(0.05, top, n)
    c = rho * g * math.pi * radius**2
    mass = rho * (2 / 3) * math.pi * radius**3 * 1.5
    a = 0.5 * mass * np.ones_like(w)
    b = 0.3 * mass * w**2 / (1 + (w / 2) ** 4) * np.exp(-0.1 * w)
    f = np.sqrt(2 * rho * g**3 * b / w**3) * np.exp(-0.2j * w)
    return Hydro(omega=w, added_mass=a, radiation_damping=b, excitation=f,
                 hydrostatic_stiffness=c, mass=mass, rho=rho, g=g)
