"""Base excitations ``q(t)``: base acceleration over g, periodic with period ``2*pi/omega``.

Every excitation is, internally, a Fourier series in the phase ``s = omega*t``::

    q(s) = Re( sum_{k=0}^{K} Q[k] * exp(1j*k*s) )          (one-sided spectrum Q)

which is exact for the harmonic, two-harmonic and Fourier-series excitations, exact to
rounding for the tanh-smoothed square wave of Eq. 26 (closed-form coefficients, truncated
where they fall below 1e-17 of the first), and the trigonometric interpolant of the samples
for a sampled (CSV) excitation. The optimizers only ever need this spectrum; the square wave
also evaluates ``q`` and ``dq/dt`` from its own formula.

Each excitation gives ``q``, ``dq`` (= dq/dt, non-dimensional time), its extrema within one
period and its total variation over one period (the quantity that sets the gamma -> 0
limit of extractable power, see :mod:`parapend.optimal.limit`).
"""

from __future__ import annotations

import csv
import math
import os
import stat
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from . import limits
from .errors import ParameterError, check_finite, check_int, check_range

__all__ = [
    "Excitation",
    "Extrema",
    "FourierExcitation",
    "SampledExcitation",
    "SquareExcitation",
    "check_excitation",
    "fourier",
    "from_csv",
    "harmonic",
    "max_abs_q",
    "parse_fourier_terms",
    "square",
    "two_harmonic",
]


@dataclass(frozen=True)
class Extrema:
    """Extrema of ``q`` within one period, in increasing time.

    Attributes
    ----------
    t : ndarray, shape (m,)
        Times in ``[0, 2*pi/omega)``.
    q : ndarray, shape (m,)
        Values of ``q`` there.
    is_max : ndarray of bool, shape (m,)
        True at a maximum, False at a minimum; maxima and minima alternate.
    """

    t: np.ndarray
    q: np.ndarray
    is_max: np.ndarray


class Excitation:
    """Common interface of all excitations (see module docstring for the spectral form)."""

    omega: float
    name: str

    # -- spectrum ------------------------------------------------------------------------
    @property
    def spectrum(self) -> np.ndarray:
        """One-sided complex spectrum ``Q[k]``, k = 0..K, of ``q`` in the phase ``s``."""
        raise NotImplementedError

    @property
    def period(self) -> float:
        """Forcing period ``2*pi/omega`` (non-dimensional time)."""
        return 2.0 * math.pi / self.omega

    def dq_spectrum(self) -> np.ndarray:
        """One-sided spectrum of ``dq/dt`` (non-dimensional time): ``1j*k*omega*Q[k]``."""
        q = self.spectrum
        return 1j * self.omega * np.arange(q.size) * q

    def dq_grid(self, m: int) -> np.ndarray:
        """``dq/dt`` at ``s_j = 2*pi*j/m``, j = 0..m-1, band-limited to harmonics < m/2.

        Band-limiting (rather than sampling a sharp ``dq/dt`` and letting it alias) keeps
        the periodic trapezoidal rule exact for products with any trigonometric polynomial
        of degree below ``m/2``.
        """
        return _synthesize(self.dq_spectrum(), m)

    def q_grid(self, m: int) -> np.ndarray:
        """``q`` at ``s_j = 2*pi*j/m``, band-limited to harmonics < m/2."""
        return _synthesize(self.spectrum, m)

    def q_uniform(self, m: int) -> np.ndarray:
        """``q`` exactly (not band-limited) at ``t_j = j T/m``, j = 0..m-1 (by spectrum folding)."""
        return _evaluate_uniform(self.spectrum, m)

    # -- pointwise -------------------------------------------------------------------------
    def q(self, t):
        """Base acceleration over g at time(s) ``t``."""
        return _evaluate(self.spectrum, self.omega * np.asarray(t, dtype=float))

    def dq(self, t):
        """Time derivative ``dq/dt`` at time(s) ``t``."""
        return _evaluate(self.dq_spectrum(), self.omega * np.asarray(t, dtype=float))

    # -- extrema and total variation -------------------------------------------------------
    @cached_property
    def extrema(self) -> Extrema:
        """Maxima and minima of ``q`` in one period (roots of ``dq/dt`` with a sign change)."""
        return _extrema_from_roots(self)

    @property
    def total_variation(self) -> float:
        """Total variation of ``q`` over one period (sum of |jumps| between successive extrema)."""
        e = self.extrema
        if e.q.size < 2:
            return 0.0
        return float(np.sum(np.abs(np.diff(np.append(e.q, e.q[0])))))

    @property
    def first_harmonic(self) -> complex:
        """Complex amplitude ``Q[1]`` of the first harmonic (sets the best uniform rotation)."""
        q = self.spectrum
        return complex(q[1]) if q.size > 1 else 0j

    def describe(self) -> dict:
        """Parameters that define this excitation (JSON-ready)."""
        raise NotImplementedError


def max_abs_q(exc: Excitation, cap: float | None = None) -> float:
    """``max |q(t)|`` over one period, of the excitation as it is evaluated (its spectrum).

    ``q`` is a trigonometric polynomial of degree ``K`` in the phase ``s``; on ``m = 16 K``
    uniform points (by one FFT) the largest ``|q|`` is within a factor ``1 - pi K / m``
    (Bernstein's inequality ``|q'| <= K max|q|`` over half a grid step) of the true maximum.
    When that bracket straddles ``cap`` (or no ``cap`` is given) the maximum is taken
    exactly at the extrema of ``q`` (the roots of ``dq/dt``, ``Excitation.extrema``),
    where ``|q|`` attains it. With a ``cap``, any value above it is returned as soon as it is
    certain to exceed it.
    """
    if isinstance(exc, SquareExcitation):
        return abs(exc.delta)  # |H| < 1 in Eq. 26: tanh plateaus of height 1
    spec = np.ascontiguousarray(exc.spectrum, dtype=complex)
    return _max_abs_spectrum(spec.tobytes(), cap)


@lru_cache(maxsize=64)
def _max_abs_spectrum(spec_bytes: bytes, cap: float | None) -> float:
    """:func:`max_abs_q` of a spectrum (as bytes): it does not depend on omega, so a map over
    omega computes it once."""
    spec = np.frombuffer(spec_bytes, dtype=complex)
    k = spec.size - 1
    if k == 0 or not np.any(spec[1:] != 0):
        return abs(float(spec[0].real))
    m = 16 * k
    on_grid = float(np.max(np.abs(_evaluate_uniform(spec, m))))
    upper = on_grid / (1.0 - math.pi * k / m)
    if cap is not None and (upper <= cap or on_grid > cap):
        return on_grid
    shape = np.ascontiguousarray(spec[1:] / float(np.max(np.abs(spec[1:]))), dtype=complex)
    s, _ = _phase_extrema(shape.tobytes())
    return max(on_grid, float(np.max(np.abs(_evaluate(spec, s))))) if s.size else on_grid


def check_excitation(exc: Excitation, name: str, hint: str = "") -> Excitation:
    """The checks every excitation built from data shares (a Fourier series, a file, a sea
    record): its largest harmonic is 0 or at least :data:`parapend.limits.MIN_AMPLITUDE`
    (smaller amplitudes reach the subnormal range inside the solvers), and ``max |q(t)|``
    of the series as it is evaluated, not only at its samples or term by term, is at most
    :data:`parapend.limits.MAX_AMPLITUDE`. ``name`` is the parameter the error names,
    ``hint`` (a parenthesis) what sets the size of q."""
    spec = exc.spectrum
    amp = float(np.max(np.abs(spec[1:]))) if spec.size > 1 else 0.0
    if 0.0 < amp < limits.MIN_AMPLITUDE:
        raise ParameterError(
            f"{name}: expected q to vary by 0 (constant) or with harmonics of at least "
            f"{limits.MIN_AMPLITUDE:g} (base acceleration over g), got a largest harmonic of "
            f"{amp:.3g}; give 0 for no excitation or scale q up")
    top = max_abs_q(exc, limits.MAX_AMPLITUDE)
    # a series that peaks at the cap itself is within it: its maximum is evaluated to a few
    # ulp, and which side of 1e3 those fall on depends on the BLAS kernel's rounding
    if top > limits.MAX_AMPLITUDE * (1.0 + 1e-12):
        raise ParameterError(
            f"{name}: expected |q(t)| <= {limits.MAX_AMPLITUDE:g} (base acceleration over g) "
            f"everywhere in the period, got q reaching |q| = {top:.7g}"
            + (hint or _SERIES_HINT.get(type(exc).__name__, "")))
    return exc


_SERIES_HINT = {
    "FourierExcitation": " (the terms are summed)",
    "SampledExcitation": " (the interpolant between the samples)",
}


def _synthesize(spec: np.ndarray, m: int) -> np.ndarray:
    """Real samples on ``m`` uniform points of ``Re sum Q[k] exp(iks)``, truncated at k < m/2."""
    kmax = min(spec.size, (m + 1) // 2)
    x = np.zeros(m // 2 + 1, dtype=complex)
    x[0] = spec[0].real * m
    x[1:kmax] = spec[1:kmax] * (m / 2.0)
    return np.fft.irfft(x, m)


def _evaluate(spec: np.ndarray, s: np.ndarray) -> np.ndarray:
    """``Re sum_k Q[k] exp(iks)`` at phases ``s`` (any shape), in chunks of bounded memory.

    The dense ``exp(i s k)`` matrix is built for at most ``2**20`` entries at a time (16 MB),
    so a long spectrum (a sampled excitation with many rows) never needs gigabytes.
    """
    s = np.asarray(s, dtype=float)
    flat = s.ravel()
    k = np.arange(spec.size)
    out = np.empty(flat.size)
    step = max(1, (1 << 20) // max(spec.size, 1))
    for i in range(0, flat.size, step):
        out[i:i + step] = (np.exp(1j * np.multiply.outer(flat[i:i + step], k)) @ spec).real
    return out.reshape(s.shape) if s.ndim else out[0]


def _evaluate_uniform(spec: np.ndarray, m: int) -> np.ndarray:
    """Exact ``Re sum_k Q[k] exp(iks)`` at ``s_j = 2 pi j/m``, j = 0..m-1, in O(K + m log m).

    On the grid ``exp(iks_j)`` depends on ``k mod m`` only: fold the spectrum, one inverse FFT.
    """
    folded = np.zeros(m, dtype=complex)
    np.add.at(folded, np.arange(spec.size) % m, spec)
    return (np.fft.ifft(folded) * m).real


def _extrema_from_roots(exc: Excitation) -> Extrema:
    """Extrema from the roots of ``dq``, found in the phase ``s = omega t`` for the shape of q.

    Where ``dq/dt`` vanishes depends only on the *shape* of the spectrum: the roots of
    ``dq/dt = omega Re sum_k i k Q[k] e^{iks}`` in ``s`` are those of the same sum with
    ``Q`` divided by its largest harmonic amplitude, whatever ``omega`` and the amplitude
    (``delta``). They are found once per shape (:func:`_phase_extrema`, cached: a design map
    over omega and delta has one or two shapes) and scaled, ``t = s / omega``; ``q`` is
    evaluated at each.
    """
    spec = exc.spectrum
    kmax = spec.size - 1
    if kmax == 0 or np.max(np.abs(spec[1:])) == 0.0:
        return Extrema(np.empty(0), np.empty(0), np.empty(0, dtype=bool))
    shape = np.ascontiguousarray(spec[1:] / float(np.max(np.abs(spec[1:]))), dtype=complex)
    s, ismax = _phase_extrema(shape.tobytes())
    ts = s / exc.omega
    qs = np.array([float(exc.q(t)) for t in ts])
    return Extrema(ts, qs, ismax.copy())


@lru_cache(maxsize=256)
def _phase_extrema(shape_bytes: bytes):
    """Phases ``s`` in ``[0, 2 pi)`` where ``Re sum_k i k S[k] e^{iks}`` changes sign (``S``:
    the harmonics k >= 1 of a spectrum, as bytes), and whether each is a maximum of q.

    Sign changes on a fine grid (at least 64 points per top harmonic), each refined by
    Brent's method.
    """
    shape = np.frombuffer(shape_bytes, dtype=complex)
    kmax = shape.size
    dspec = np.zeros(kmax + 1, dtype=complex)
    dspec[1:] = 1j * np.arange(1, kmax + 1) * shape
    m = int(max(4096, 64 * kmax))
    s = 2 * np.pi * np.arange(m) / m
    d = _synthesize(dspec, m)
    scale = np.max(np.abs(d))
    d = np.where(np.abs(d) < 1e-13 * scale, 0.0, d)
    sign = np.sign(d)
    # carry signs forward over exact zeros so a root on a grid point is counted once
    nz = np.flatnonzero(sign)
    sign = sign[nz]
    idx = nz
    change = np.flatnonzero(sign != np.roll(sign, -1))
    ss, ismax = [], []

    def f(x):
        return float(_evaluate(dspec, x))

    for c in change:
        i0, i1 = idx[c], idx[(c + 1) % idx.size]
        s0 = s[i0]
        s1 = s[i1] if i1 > i0 else s[i1] + 2 * np.pi
        f0, f1 = f(s0), f(s1)
        if f0 == 0.0:
            r = s0
        elif f1 == 0.0:
            r = s1
        elif f0 * f1 > 0:  # grid sign flip not confirmed by the exact derivative
            continue
        else:
            r = brentq(f, s0, s1, xtol=1e-15)
        ss.append(r % (2 * np.pi))
        ismax.append(sign[c] > 0)
    order = np.argsort(ss)
    out = np.asarray(ss, dtype=float)[order], np.asarray(ismax, dtype=bool)[order]
    for a in out:
        a.flags.writeable = False
    return out


# ---------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class FourierExcitation(Excitation):
    """``q(t) = mean + sum_k amp_k * sin(k*omega*t + phase_k)`` (harmonic is k = 1 only).

    Parameters
    ----------
    omega : float
        Forcing frequency (> 0), non-dimensional (unit ``sqrt(g/l)``).
    terms : tuple of (int, float, float)
        ``(k, amp_k, phase_k)`` with harmonic number k >= 1, phase in radians.
    mean : float
        Constant part of ``q`` (it does not change the extracted power).
    name : str
        Label used in output ("harmonic", "two-harmonic", "fourier").
    """

    omega: float
    terms: tuple = ()
    mean: float = 0.0
    name: str = "fourier"
    _spec: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        object.__setattr__(self, "omega", _check_omega(self.omega))
        object.__setattr__(self, "mean", check_range("mean", self.mean, 0,
                                                     limits.MAX_AMPLITUDE, absolute=True))
        object.__setattr__(self, "terms", _check_terms(self.terms))
        kmax = max(k for k, _, _ in self.terms)
        spec = np.zeros(kmax + 1, dtype=complex)
        spec[0] = self.mean
        for k, amp, ph in self.terms:
            # amp*sin(k s + ph) = Re(-1j*amp*exp(1j*ph) * exp(1j*k*s))
            spec[int(k)] += -1j * amp * np.exp(1j * ph)
        object.__setattr__(self, "_spec", spec)
        if self.name == "fourier":
            # harmonic and two-harmonic are parameterized by |delta| <= 1e3 (max |q| is
            # |delta| and 1.101 |delta|); a general series is checked as summed
            check_excitation(self, "fourier")

    @property
    def spectrum(self) -> np.ndarray:
        return self._spec

    def describe(self) -> dict:
        d = {"excitation": self.name, "omega": self.omega}
        if self.name == "harmonic":
            d["delta"] = self.terms[0][1]
        elif self.name == "two-harmonic":
            d["delta"] = self.terms[0][1]
        else:
            d["terms"] = [list(map(float, t)) for t in self.terms]
            d["mean"] = self.mean
        return d


def _check_omega(omega) -> float:
    return check_range("omega", omega, *limits.OMEGA_RANGE,
                       why="forcing frequency in units sqrt(g/l); see docs/limits-of-input.md")


def _check_amplitude(name: str, value, why: str = "base acceleration amplitude over g"):
    """An amplitude: ``|value| <= MAX_AMPLITUDE``, and 0 or ``|value| >= MIN_AMPLITUDE``
    (subnormal amplitudes broke the root finder of the extrema; docs/limits-of-input.md)."""
    x = check_range(name, value, 0, limits.MAX_AMPLITUDE, absolute=True, why=why)
    if 0.0 < abs(x) < limits.MIN_AMPLITUDE:
        raise ParameterError(f"{name}: expected 0 or {limits.MIN_AMPLITUDE:g} <= |{name}| <= "
                             f"{limits.MAX_AMPLITUDE:g}, got {value!r} ({why})")
    return x


def _check_delta(delta) -> float:
    return _check_amplitude("delta", delta)


def _check_terms(terms) -> tuple:
    """Validate Fourier terms ``(k, amp[, phase])``: integer 1 <= k <= MAX_FOURIER_K, finite
    bounded amplitude and phase. Returns a tuple of ``(int, float, float)``."""
    if isinstance(terms, (str, bytes)) or not hasattr(terms, "__iter__"):
        raise ParameterError(f"fourier: expected a sequence of (k, amp, phase) terms, "
                             f"got {terms!r:.60}")
    out = []
    for term in terms:
        if isinstance(term, (str, bytes)) or not hasattr(term, "__len__") \
                or len(term) not in (2, 3):
            raise ParameterError(f"fourier: expected each term as (k, amp) or (k, amp, phase), "
                                 f"got {term!r:.60}")
        k = check_int("fourier k", term[0], 1, limits.MAX_FOURIER_K)
        # each term at most 1e3; the smallest amplitude applies to the series (its largest
        # harmonic, check_excitation): a tiny term beside others is harmless
        amp = check_range("fourier amplitude", term[1], 0, limits.MAX_AMPLITUDE,
                          absolute=True)
        ph = check_range("fourier phase", term[2] if len(term) == 3 else 0.0, 0,
                         limits.MAX_PHASE, absolute=True)
        out.append((k, amp, ph))
    if not out:
        raise ParameterError("fourier: expected at least one term k:amp:phase, got none")
    return tuple(out)


def harmonic(delta: float = -0.3, omega: float = 1.8) -> FourierExcitation:
    """Harmonic excitation ``q = delta*sin(omega*t)`` (paper Eq. 2)."""
    delta = _check_delta(delta)
    return FourierExcitation(omega, ((1, float(delta), 0.0),), name="harmonic")


def two_harmonic(delta: float = -0.3, omega: float = 1.8) -> FourierExcitation:
    """Two-harmonic excitation ``q = delta*(sin(omega t) + sin(2 omega t)/4)`` (paper Eq. 23)."""
    delta = _check_delta(delta)
    return FourierExcitation(
        omega, ((1, float(delta), 0.0), (2, float(delta) / 4.0, 0.0)), name="two-harmonic"
    )


def fourier(terms, omega: float = 1.8, mean: float = 0.0) -> FourierExcitation:
    """General Fourier-series excitation ``q = mean + sum amp_k sin(k omega t + phase_k)``.

    ``terms``: ``(k, amp)`` or ``(k, amp, phase)`` with integer ``1 <= k <= 1024``
    (:data:`parapend.limits.MAX_FOURIER_K`); a non-integer k is refused, not truncated.
    """
    return FourierExcitation(_check_omega(omega), _check_terms(terms),
                             mean=check_range("mean", mean, 0, limits.MAX_AMPLITUDE,
                                              absolute=True), name="fourier")


def parse_fourier_terms(text: str) -> tuple:
    """Parse ``"k:amp:phase,k:amp:phase"`` (phase optional, radians) into terms."""
    terms = []
    for item in text.split(","):
        item = item.strip()
        if not item:
            continue
        parts = item.split(":")
        if len(parts) not in (2, 3):
            raise ParameterError(f"--fourier: expected terms 'k:amp[:phase]', got {item!r}")
        try:
            k = int(parts[0]) if len(parts[0].strip()) <= 30 else None
            amp = float(parts[1])
            ph = float(parts[2]) if len(parts) == 3 else 0.0
        except ValueError:
            k = None
        if k is None:
            raise ParameterError(
                f"--fourier: expected integer k and numbers amp, phase, got {item!r:.60}")
        if not 1 <= k <= limits.MAX_FOURIER_K:
            raise ParameterError(f"--fourier: harmonic number k must be an integer in "
                                 f"[1, {limits.MAX_FOURIER_K}], got {k}")
        terms.append((k, amp, ph))
    if not terms:
        raise ParameterError("--fourier: expected at least one term 'k:amp[:phase]', got none")
    return tuple(terms)


# ---------------------------------------------------------------------------------------
SQUARE_MAX_HARMONICS = 1 << 20


@dataclass(frozen=True, eq=False)
class SquareExcitation(Excitation):
    """tanh-smoothed square wave ``q = delta*H(t)`` of paper Eq. 26 (Eq. 30 scales it by delta).

    On one period ``0 <= t < T = 2*pi/omega``::

        H(t) = tanh((t-T)/alpha) - tanh((t-T/2)/alpha) + tanh(t/alpha)/2 - tanh(-t/alpha)/2

    which is about +1 on the first half period and -1 on the second. Its spectrum is
    closed-form: with ``F(nu) = pi*nu*alpha/sinh(pi*nu*alpha/2)`` (the Fourier transform of
    ``sech(u/alpha)**2/alpha``), ``Q[k] = -4j*delta*F(k*omega)/(2*pi*k)`` for odd k, 0 for
    even k; exact up to terms of order ``exp(-T/alpha)``.
    """

    omega: float
    delta: float = -0.3
    alpha: float = 0.001
    name: str = "square"

    def __post_init__(self):
        object.__setattr__(self, "omega", _check_omega(self.omega))
        object.__setattr__(self, "delta", _check_delta(self.delta))
        alpha = check_finite("square-alpha", self.alpha)
        object.__setattr__(self, "alpha", alpha)
        lo, hi = limits.SQUARE_ALPHA_MIN * self.period, self.period / 8
        if not lo <= alpha <= hi:
            raise ParameterError(
                f"square-alpha: expected a smoothing width in [{limits.SQUARE_ALPHA_MIN:g} T, "
                f"T/8] = [{lo:.4g}, {hi:.4g}] (T = 2 pi/omega), got {self.alpha!r}")

    @cached_property
    def spectrum(self) -> np.ndarray:
        # |Q_k| ~ 4|delta|/(pi k) * exp(-pi k omega alpha/2): keep k while above 1e-17 of Q_1,
        # but at most SQUARE_MAX_HARMONICS (the optimizers' grids never resolve more; only
        # alpha * omega < ~2.4e-5 is affected, and q, dq/dt, extrema use the formula anyway)
        kmax = min(int(math.ceil(2 * 40.0 / (math.pi * self.omega * self.alpha))),
                   SQUARE_MAX_HARMONICS) | 1
        k = np.arange(kmax + 1, dtype=float)
        x = math.pi * k * self.omega * self.alpha
        with np.errstate(divide="ignore", invalid="ignore"):
            f = np.where(k > 0, x / np.sinh(x / 2), 2.0)
            spec = np.where(k % 2 == 1, -4j * self.delta * f / (2 * np.pi * np.maximum(k, 1)), 0)
        return spec.astype(complex)

    def q_uniform(self, m: int) -> np.ndarray:
        return self.q(self.period * np.arange(m) / m)

    def q(self, t):
        T, a = self.period, self.alpha
        t = np.mod(np.asarray(t, dtype=float), T)
        h = (np.tanh((t - T) / a) - np.tanh((t - T / 2) / a)
             + 0.5 * np.tanh(t / a) - 0.5 * np.tanh(-t / a))
        return self.delta * h

    def dq(self, t):
        T, a = self.period, self.alpha
        t = np.mod(np.asarray(t, dtype=float), T)

        def sech2(x):
            return 1.0 / np.cosh(np.clip(x, -350, 350)) ** 2

        return self.delta / a * (sech2((t - T) / a) - sech2((t - T / 2) / a) + sech2(t / a))

    @cached_property
    def extrema(self) -> Extrema:
        # dq/dt vanishes (to exp(-T/alpha)) on the plateaus; by symmetry of Eq. 26 the extrema
        # are at T/4 and 3T/4.
        t = np.array([self.period / 4, 3 * self.period / 4])
        return Extrema(t, np.asarray(self.q(t)), np.array([self.delta > 0, self.delta <= 0]))

    def describe(self) -> dict:
        return {"excitation": "square", "omega": self.omega, "delta": self.delta,
                "square_alpha": self.alpha}


def square(delta: float = -0.3, omega: float = 1.8, alpha: float = 0.001) -> SquareExcitation:
    """tanh-smoothed square-wave excitation of paper Eq. 26, amplitude ``delta``."""
    return SquareExcitation(_check_omega(omega), _check_delta(delta),
                            check_finite("square-alpha", alpha))


# ---------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class SampledExcitation(Excitation):
    """One period of ``q`` given by samples at ``tau = omega*t/(2*pi)`` in ``[0, 1)``.

    Uniform samples define the trigonometric interpolant (band-limited to half the sample
    count); non-uniform samples are first interpolated by a periodic cubic spline and
    resampled on ``8 * 2**ceil(log2(rows))`` uniform points, at least 256 and at most 4096
    (:func:`_resample_points`): eight points per sample spacing, where the spline's spectrum
    has decayed like ``k**-4``, and no more harmonics than the data can define (a record of
    up to 256 rows stays within the 1024 harmonics a power take-off solve follows).
    """

    omega: float
    tau: tuple
    values: tuple
    source: str = ""
    name: str = "file"

    def __post_init__(self):
        object.__setattr__(self, "omega", _check_omega(self.omega))
        where = f" in {self.source}" if self.source else ""
        try:
            tau = np.asarray(self.tau, dtype=float)
            q = np.asarray(self.values, dtype=float)
        except (TypeError, ValueError):
            raise ParameterError(f"file: expected numbers in tau and q{where}") from None
        if tau.ndim != 1 or tau.shape != q.shape:
            raise ParameterError(f"file: expected equal-length tau and q columns{where}")
        if tau.size < 16:
            raise ParameterError(f"file: expected at least 16 samples of one period{where}, "
                                 f"got {tau.size}")
        if tau.size > limits.MAX_FILE_ROWS:
            raise ParameterError(f"file: expected at most {limits.MAX_FILE_ROWS} samples of one "
                                 f"period{where}, got {tau.size} (resample the record)")
        if not (np.all(np.isfinite(tau)) and np.all(np.isfinite(q))):
            raise ParameterError(f"file: expected finite numbers in tau and q{where}")
        if np.max(np.abs(q)) > limits.MAX_AMPLITUDE:
            raise ParameterError(f"file: expected |q| <= {limits.MAX_AMPLITUDE:g} (base "
                                 f"acceleration over g){where}, got {np.max(np.abs(q)):.4g}")
        if tau[0] < 0 or tau[-1] >= 1:
            raise ParameterError(
                f"file: expected tau in [0, 1) (one period, endpoint not repeated){where}, "
                f"got tau from {tau[0]:g} to {tau[-1]:g}")
        if np.any(np.diff(tau) <= 0):
            raise ParameterError(f"file: expected strictly increasing tau{where}")
        gap = float(np.min(np.diff(tau)))
        if gap < 1e-6 / tau.size:
            raise ParameterError(f"file: expected tau spacings of at least 1e-6 of the mean "
                                 f"spacing{where}, got a gap of {gap:.3g}")
        # the samples must cover the period: across a wider gap the interpolant is not
        # drawn by data (the periodic spline over a gap of 0.99994 reached |q| = 2842 from
        # samples within |q| <= 1e3)
        gaps = np.diff(np.append(tau, tau[0] + 1.0))
        widest = int(np.argmax(gaps))
        if gaps[widest] > limits.MAX_FILE_GAP:
            raise ParameterError(
                f"file: expected samples spread over the whole period (no gap in tau wider "
                f"than {limits.MAX_FILE_GAP:g}){where}, got a gap of {gaps[widest]:.4g} after "
                f"tau = {tau[widest]:.6g}")
        check_excitation(self, "file")

    @cached_property
    def spectrum(self) -> np.ndarray:
        tau = np.asarray(self.tau, dtype=float)
        q = np.asarray(self.values, dtype=float)
        n = tau.size
        h = 1.0 / n
        uniform = np.allclose(tau, tau[0] + h * np.arange(n), rtol=0, atol=1e-9 * h)
        if not uniform:
            from scipy.interpolate import CubicSpline

            spline = CubicSpline(np.append(tau, tau[0] + 1.0), np.append(q, q[0]),
                                 bc_type="periodic")
            n = _resample_points(n)
            grid = tau[0] + np.arange(n) / n
            q = spline(grid)
        x = np.fft.rfft(q) / n
        spec = 2 * x
        spec[0] = x[0]
        if n % 2 == 0:
            spec[-1] = x[-1].real  # Nyquist term enters once: the real (cosine) interpolant
        # the samples start at tau[0], not at 0: shift the phase
        k = np.arange(spec.size)
        spec = spec * np.exp(-2j * np.pi * k * tau[0])
        return spec

    def describe(self) -> dict:
        return {"excitation": "file", "omega": self.omega, "file": self.source,
                "samples": len(self.tau)}


def _resample_points(rows: int) -> int:
    """Uniform points on which a non-uniform record's periodic spline is resampled: eight per
    sample (rounded up to a power of two), from 256 to 4096."""
    return int(min(4096, max(256, 8 * (1 << max(0, int(rows) - 1).bit_length()))))


def _read_bounded(path: Path, expected: str | None = None, max_bytes: int | None = None) -> str:
    """The text of ``path``: at most ``max_bytes`` (default ``MAX_BYTES_FILE``) bytes, UTF-8
    (a BOM is accepted). ``expected`` says what the file should hold, for the message when it
    is too large (default: one period of ``tau,q``).

    Only a regular file is read: the file is opened without blocking (a FIFO would wait for
    a writer forever), then refused unless ``fstat`` says it is a regular file, and refused
    before reading if its size is over the cap; the read itself is bounded as well (a
    file that grows meanwhile)."""
    expected = expected or f"one period of at most {limits.MAX_FILE_ROWS} rows 'tau,q'"
    cap = int(max_bytes or limits.MAX_BYTES_FILE)
    if path.is_dir():
        raise ParameterError(f"file: expected a CSV file, got the directory {str(path)!r}")
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0)
                     | getattr(os, "O_NOCTTY", 0))
    except OSError as exc:
        raise ParameterError(f"file: cannot read {path}: {exc.strerror or exc}") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            kind = ("a FIFO (named pipe)" if stat.S_ISFIFO(st.st_mode) else
                    "a character device" if stat.S_ISCHR(st.st_mode) else
                    "a block device" if stat.S_ISBLK(st.st_mode) else
                    "a socket" if stat.S_ISSOCK(st.st_mode) else "not a regular file")
            raise ParameterError(f"file: expected a regular CSV file, got {kind}: {path} "
                                 "(save the data to a file first)")
        if st.st_size > cap:
            raise ParameterError(f"file: {path} is larger than {cap >> 20} MiB; "
                                 f"expected {expected}")
        if hasattr(os, "set_blocking"):
            os.set_blocking(fd, True)
        with os.fdopen(fd, "rb") as fh:
            fd = None
            data = fh.read(cap + 1)
    except OSError as exc:
        raise ParameterError(f"file: cannot read {path}: {exc.strerror or exc}") from None
    finally:
        if fd is not None:
            os.close(fd)
    if len(data) > cap:
        raise ParameterError(f"file: {path} is larger than {cap >> 20} MiB; expected {expected}")
    if b"\0" in data:
        raise ParameterError(f"file: {path} is not a text CSV (it contains NUL bytes: binary, "
                             "or UTF-16); save it as UTF-8")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ParameterError(f"file: {path} is not UTF-8 text (byte {exc.start}); save it as "
                             "UTF-8") from None


def from_csv(path, omega: float = 1.8) -> SampledExcitation:
    """Read one period of ``q`` from a CSV file with header ``tau,q`` (DESIGN.md section 4).

    The file must be UTF-8 (a byte-order mark is accepted), at most
    :data:`parapend.limits.MAX_BYTES_FILE` bytes and :data:`parapend.limits.MAX_FILE_ROWS`
    rows; it is never read beyond that size.
    """
    if not isinstance(path, (str, Path)) or not str(path):
        raise ParameterError(f"file: expected a CSV path, got {path!r:.60}")
    _check_omega(omega)
    path = Path(path)
    text = _read_bounded(path)
    try:
        rows = list(csv.reader(text.splitlines()))
    except csv.Error as exc:
        raise ParameterError(f"file: not a CSV file {path}: {exc}") from None
    rows = [r for r in rows if r and any(c.strip() for c in r)]
    if not rows or [c.strip().lower() for c in rows[0]] != ["tau", "q"]:
        raise ParameterError(f"file: expected a CSV header 'tau,q' in {path}")
    if len(rows) - 1 > limits.MAX_FILE_ROWS:
        raise ParameterError(f"file: expected at most {limits.MAX_FILE_ROWS} rows in {path}, "
                             f"got {len(rows) - 1} (resample the record)")
    tau, q = [], []
    for i, r in enumerate(rows[1:], start=2):
        try:
            if len(r) != 2:
                raise ValueError
            tau.append(float(r[0]))
            q.append(float(r[1]))
        except ValueError:
            raise ParameterError(f"file: expected two numbers on line {i} of {path}, "
                                 f"got {','.join(r)!r:.60}") from None
    return SampledExcitation(float(omega), tuple(tau), tuple(q), source=str(path))
