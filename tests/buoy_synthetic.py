"""A synthetic, exactly causal heave dataset for the buoy tests (no BEM needed).

The radiation force has the transfer function ``H(s) = k s / (s^2 + 2 zeta w0 s + w0^2)``
(``s = i w``): ``B(w) = Re H(i w)``, ``A(w) = A_inf + Im H(i w) / w`` (Kramers-Kronig holds
exactly), impulse response ``K(t) = k exp(-zeta w0 t) (cos(wd t) - zeta w0 / wd sin(wd t))``.
"""

import numpy as np

from parapend.buoy.hydro import Hydro

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
