r"""The wave resource of a bin: the Te/Tp relation of a spectrum, the record's spectrum, the
wave energy flux ``J`` (deep water and finite depth) and the bin edges.

Conventions are MHKiT's ``wave.resource`` and ``wave.performance`` (IEC TS 62600-100/-101):

- ``J = rho g sum_i S(f_i) c_g(f_i) df`` over the record's components ``f_i = i / T_r``
  (``i >= 1``, ``df = 1 / T_r``, up to the cutoff): the flux of the sea the device sees.
  Deep water: ``c_g = g / (4 pi f)``, so ``J = rho g^2 m_{-1} / (4 pi)`` (MHKiT's
  ``rho g^2 Hm0^2 Te / (64 pi)``). Finite depth ``h``: ``k`` from ``(2 pi f)^2 = g k tanh kh``
  (Newton, to machine precision) and ``c_g = (pi f / k) (1 + 2 kh / sinh 2kh)``; where
  ``h`` exceeds two wavelengths the deep-water ``c_g = pi f / k`` (MHKiT's depth check, a
  relative difference below 1e-9 there).
- ``Te = m_{-1} / m0`` and ``Hm0 = 4 sqrt(m0)``; the ratio ``Te / Tp`` of a spectrum shape is
  fixed (it does not depend on Hs or Tp) and integrated here from the spectrum's formula:
  Pierson-Moskowitz ``Gamma(5/4) (5/4)^{-1/4} = 0.857`` exactly, JONSWAP by quadrature
  (0.9 at gamma_p = 3.3, within 0.5 % of the ITTC fit MHKiT uses).
- Bin edges from centres as MHKiT's ``_performance_matrix``: 0, the midpoints, and the last
  centre plus half the last step.
"""

from __future__ import annotations

import math

import numpy as np

from .. import limits
from ..errors import ParameterError
from ..seas import jonswap, pierson_moskowitz

__all__ = ["bin_edges", "energy_flux", "record_spectrum", "repeat_period", "te_over_tp",
           "wave_number"]

#: water density (kg/m^3), MHKiT's default
DENSITY = 1025.0
#: MHKiT's depth check: deeper than this many wavelengths is deep water
DEEP_RATIO = 2.0


def te_over_tp(spectrum: str = "jonswap", gamma_peak: float = 3.3) -> float:
    """``Te / Tp = m_{-1} / m0`` of the spectrum shape (any Hs, any Tp)."""
    if spectrum == "pierson-moskowitz":
        return math.gamma(1.25) * 1.25 ** -0.25
    from scipy.integrate import quad

    def s(f):
        return float(jonswap(np.array([f]), 1.0, 1.0, gamma_peak)[0])

    pts = [0.9, 1.0, 1.1]
    m0 = quad(s, 0.2, 20.0, points=pts, limit=200, epsabs=0, epsrel=1e-13)[0]
    m1 = quad(lambda f: s(f) / f, 0.2, 20.0, points=pts, limit=200, epsabs=0,
              epsrel=1e-13)[0]
    # the tails below 0.2 fp (exp(-1.25 * 625): nothing) and above 20 fp (S ~ f^-5, the PM
    # tail with the JONSWAP factor at 1): added in closed form
    tail = (1.0 - 0.287 * math.log(gamma_peak)) * 0.3125
    m0 += tail * 20.0 ** -4 / 4.0
    m1 += tail * 20.0 ** -5 / 5.0
    return m1 / m0


def record_spectrum(hs: float, tp: float, repeat_period: float, *, spectrum: str = "jonswap",
                    gamma_peak: float = 3.3, cutoff: float = 3.0):
    """The frequencies (Hz) and the spectrum (m^2/Hz) of the record of ``sea``: ``f_i = i /
    T_r`` for ``i = 1 .. floor(cutoff T_r / tp)``, as :func:`parapend.seas.sea_record`."""
    kmax = int(math.floor(cutoff * repeat_period / tp))
    f = np.arange(1, kmax + 1) / repeat_period
    s = (jonswap(f, hs, tp, gamma_peak) if spectrum == "jonswap"
         else pierson_moskowitz(f, hs, tp))
    return f, s


def wave_number(f, depth: float, gravity: float) -> np.ndarray:
    """``k`` (1/m) of ``(2 pi f)^2 = g k tanh(k h)`` by Newton's method from the deep-water
    root (monotone convergence: the function is concave in k), to machine precision."""
    w2 = (2 * math.pi * np.asarray(f, dtype=float)) ** 2
    k = np.maximum(w2 / gravity, np.sqrt(w2 / (gravity * depth)))
    for _ in range(100):
        t = np.tanh(k * depth)
        fk = gravity * k * t - w2
        dk = fk / (gravity * (t + k * depth * (1.0 - t * t)))
        k = k - dk
        if np.all(np.abs(dk) <= 4e-16 * k):
            break
    return k


def _spectrum_arrays(f, s):
    """``f`` and ``s`` as 1-d float arrays, checked (see :func:`energy_flux`)."""
    out = []
    for name, v in (("f", f), ("s", s)):
        try:
            a = np.asarray(v, dtype=float)
        except (TypeError, ValueError):
            raise ParameterError(f"{name}: expected a sequence of numbers, got "
                                 f"{type(v).__name__}") from None
        if a.ndim != 1 or a.size < 2:
            raise ParameterError(f"{name}: expected a 1-d sequence of at least 2 numbers, got "
                                 + (f"shape {a.shape}" if a.ndim != 1 else f"{a.size}"))
        if not np.all(np.isfinite(a)):
            raise ParameterError(f"{name}: expected finite numbers")
        out.append(a)
    f, s = out
    if f.size != s.size:
        raise ParameterError(f"s: expected as many values as f ({f.size}), got {s.size}")
    if f[0] <= 0 or np.any(np.diff(f) <= 0):
        raise ParameterError("f: expected positive, increasing frequencies (Hz)")
    if np.any(s < 0):
        raise ParameterError("s: expected a spectrum that is nowhere negative (m^2/Hz)")
    return f, s


def energy_flux(f, s, *, depth: float | None = None, density: float = DENSITY,
                gravity: float = 9.80665) -> float:
    """``J`` (W/m) of the spectrum ``s`` (m^2/Hz) on the evenly spaced frequencies ``f`` (Hz,
    ``df = f[1] - f[0]`` as MHKiT); ``depth`` None: deep water. ``f`` and ``s`` are
    sequences of the same length, at least 2 (one frequency has no ``df``), ``f`` positive
    and increasing, ``s`` finite and not negative; else :class:`ParameterError`."""
    f, s = _spectrum_arrays(f, s)
    df = np.empty_like(f)
    df[0] = f[1] - f[0]
    df[1:] = np.diff(f)
    if depth is None:
        cg = gravity / (4 * math.pi * f)
    else:
        k = wave_number(f, depth, gravity)
        deep = depth / (2 * math.pi / k) > DEEP_RATIO
        x = 2 * k * depth
        with np.errstate(over="ignore"):
            cg = np.where(deep, math.pi * f / k,
                          (math.pi * f / k) * (1 + x / np.sinh(np.where(deep, 1.0, x))))
    return float(density * gravity * np.sum(s * cg * df))


def bin_edges(centres) -> np.ndarray:
    """Edges of the bins of ``centres`` as MHKiT draws them: 0, the midpoints, and the last
    centre plus half the last step."""
    c = np.asarray(centres, dtype=float)
    mids = [float(np.mean([c[i], c[i + 1]])) for i in range(c.size - 1)]
    return np.array([0.0, *mids, float(c[-1] + np.diff(c[-2:])[0] / 2)])


def repeat_period(waves: float, tp: float) -> float:
    """``waves * tp`` (s), one ulp lower where the product's rounding would put the record
    above ``parapend sea``'s longest (``waves = 400`` at some Tp read back as 400.0000001
    peak periods and every bin was refused)."""
    rp = waves * tp
    while rp / tp > limits.SEA_WAVES_RANGE[1]:
        rp = math.nextafter(rp, 0.0)
    return rp
