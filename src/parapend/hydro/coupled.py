r"""The coupled objective: a pendulum inside a heaving buoy, as a problem in ``theta`` alone.

Model (SI; docs/buoy.md). Pendulum ``I theta'' + c theta' - m l (g + z'') sin(theta) = tau``;
buoy, per harmonic ``k`` of the fundamental ``w`` (``x(t) = Re sum X_k exp(i k w t)``)::

    D_k Z_k = F_k a_k + m l (k w)^2 Chat_k,   D_k = -(k w)^2 (M + A_k) + i k w B_k + C

with ``Chat_k`` the harmonics of ``u = cos(theta)``. The heave is the free response
``z_w`` (``Z_k = F_k a_k / D_k``) plus a part linear in ``u``. With the harvested power
``P = -<tau theta'> = m l <z''' u> - c <theta'^2>`` (integration by parts), the reactive
part of the coupling drops out of the mean and what is left is the power the pendulum's
reaction radiates away::

    P = m l <z_w''' u>  -  1/2 sum_k beta_k |U_k|^2  -  c <theta'^2>,
    beta_k = (m l)^2 (k w)^6 B_k / |D_k|^2,   U_k = 2 <u exp(-i k w t)>.

Non-dimensional as the uncoupled kernel (time unit ``t0 = sqrt(I / (m g l))``, torque
``m g l``): ``q_w = z_w'' / g`` is the free buoy's excitation of the existing Fourier
kernel, ``gamma = c t0 / I``, and the coupling adds the concave quadratic
``-1/2 sum beta_k |U_k|^2`` (``beta_k`` divided by the power unit ``m g l / t0``). With
``beta = 0`` this is exactly :class:`parapend.optimal.fourier.FourierProblem`.

Derivatives. With ``r = R u`` (``R`` the symmetric, negative semidefinite operator of the
quadratic: harmonics ``-2 beta_k U_k``) and ``w_eff = q_w' + r``, the gradient is the
uncoupled one with ``w_eff`` in place of ``q'``, and the Hessian is the uncoupled one with
``w_eff`` plus ``Phi^T sin(theta) R sin(theta) Phi`` (dense: from the FFTs of
``sin(theta) phi_i``; operator: two more FFTs per product).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from ..optimal.fourier import FourierProblem, HessianOperator
from ..seas import SeaExcitation

__all__ = ["CoupledProblem", "Pendulum", "Wave", "scales"]


@dataclass(frozen=True)
class Pendulum:
    """The pendulum inside the buoy (SI): mass (kg), length to the centre of mass (m),
    inertia about the pivot (kg m^2, at least ``m l^2``), viscous damping (N m s/rad)."""

    mass: float
    length: float
    inertia: float
    damping_coefficient: float = 0.0

    def __post_init__(self):
        for name, v in (("mass", self.mass), ("length", self.length),
                        ("inertia", self.inertia)):
            if not (isinstance(v, (int, float, np.floating)) and math.isfinite(v) and v > 0):
                raise ParameterError(f"{name}: expected a positive number, got {v!r}")
        c = self.damping_coefficient
        if not (isinstance(c, (int, float, np.floating)) and math.isfinite(c) and c >= 0):
            raise ParameterError(f"damping-coefficient: expected a number >= 0 N m s/rad, "
                                 f"got {c!r}")
        ml2 = self.mass * self.length**2
        if self.inertia < ml2 * (1 - 1e-12):
            raise ParameterError(f"inertia: expected at least m l^2 = {ml2:.6g} kg m^2 (the "
                                 f"inertia about the pivot), got {self.inertia!r}")


@dataclass(frozen=True)
class Wave:
    """A periodic wave at the buoy: ``eta(t) = Re sum_k a_k exp(i k omega t)``, k = 1..K.

    ``omega`` is the wave's frequency (regular) or ``2 pi / T_r`` (a record repeating with
    period ``T_r``), rad/s; ``amplitudes`` the complex ``a_k`` (m).
    """

    omega: float
    amplitudes: np.ndarray = field(repr=False)

    def __post_init__(self):
        w = self.omega
        if not (isinstance(w, (int, float, np.floating)) and math.isfinite(w) and w > 0):
            raise ParameterError(f"wave-period: expected a positive frequency, got {w!r}")
        a = np.atleast_1d(np.asarray(self.amplitudes, dtype=complex))
        if a.ndim != 1 or a.size == 0 or not np.all(np.isfinite(a)) or not np.any(a != 0):
            raise ParameterError("wave: expected a finite, nonzero list of amplitudes a_k")
        object.__setattr__(self, "omega", float(w))
        object.__setattr__(self, "amplitudes", a)

    @classmethod
    def regular(cls, height: float, period: float) -> Wave:
        """Regular wave of height ``H`` (m, crest to trough) and period ``T`` (s):
        ``eta = H/2 cos(2 pi t / T)``."""
        for name, v in (("wave-height", height), ("wave-period", period)):
            if not (isinstance(v, (int, float, np.floating)) and math.isfinite(v) and v > 0):
                raise ParameterError(f"{name}: expected a positive number, got {v!r}")
        return cls(2 * math.pi / period, np.array([0.5 * height], dtype=complex))

    @classmethod
    def from_record(cls, t, eta) -> Wave:
        """One period of a periodic record: uniform times ``t`` (s, the endpoint excluded)
        and the elevation ``eta`` (m) there. The Nyquist component is dropped."""
        t = np.asarray(t, dtype=float)
        eta = np.asarray(eta, dtype=float)
        if t.ndim != 1 or t.size < 4 or eta.shape != t.shape:
            raise ParameterError("record: expected at least 4 samples t, eta of equal length")
        dt = np.diff(t)
        if not (np.all(dt > 0) and np.allclose(dt, dt[0], rtol=1e-9, atol=0)):
            raise ParameterError("record: expected uniform, increasing sample times")
        n = t.size
        period = n * float(dt[0])
        k = np.arange(1, (n + 1) // 2)
        a = 2.0 * np.fft.rfft(eta)[1:(n + 1) // 2] / n
        a = a * np.exp(-1j * k * 2 * math.pi * t[0] / period)
        return cls(2 * math.pi / period, a)

    @classmethod
    def from_spectrum(cls, *, hs: float = 2.0, tp: float = 8.0, spectrum: str = "jonswap",
                      gamma_peak: float = 3.3, repeat_period: float | None = None,
                      seed: int = 0, cutoff: float = 3.0) -> Wave:
        """The periodic record of :func:`parapend.seas.sea_record` (same phases, same
        seed): components ``k / T_r`` up to ``cutoff / tp``."""
        from ..seas import sea_record
        from ..units import Units

        exc = sea_record(Units(1.0, 1.0), hs=hs, tp=tp, spectrum=spectrum,
                         gamma_peak=gamma_peak, repeat_period=repeat_period, seed=seed,
                         cutoff=cutoff)
        tr = exc.info["repeat_period"]
        return cls(2 * math.pi / tr, np.asarray(exc.heave[1:], dtype=complex))

    @property
    def frequencies(self) -> np.ndarray:
        """``k omega``, k = 1..K (rad/s)."""
        return self.omega * np.arange(1, self.amplitudes.size + 1)


@dataclass(frozen=True)
class Scales:
    """What the coupled problem needs, in SI and non-dimensional (``*_nd``) form."""

    t0: float              # time unit, s
    power_unit: float      # m g l / t0, W
    torque_unit: float     # m g l, N m
    omega_nd: float        # omega t0
    gamma: float           # c t0 / I
    q_spec: np.ndarray     # free buoy's q_w = z_w'' / g, harmonics 0..K
    beta_nd: np.ndarray    # beta_k / power unit, k = 1..Kc (0 where B = 0)
    wave_force: np.ndarray  # F_k a_k, k = 0..K, N
    free_heave: np.ndarray  # F_k a_k / D_k, k = 0..K, m


def scales(hydro, pendulum: Pendulum, wave: Wave, coupling_harmonics: int | None = None,
           coupled: bool = True) -> Scales:
    """Non-dimensional data of the coupled problem (``coupled=False``: ``beta = 0``).

    ``coupling_harmonics`` Kc: the harmonics of ``cos(theta)`` whose radiation counts;
    default every ``k`` with ``k omega`` within the dataset (above it ``B = 0``).
    """
    m, l_, inertia = pendulum.mass, pendulum.length, pendulum.inertia
    g = float(hydro.g)
    t0 = math.sqrt(inertia / (m * g * l_))
    pu = m * g * l_ / t0
    w = wave.omega
    kk = np.arange(1, wave.amplitudes.size + 1)
    _, _, F = hydro.coefficients(kk * w)
    D = hydro.impedance(kk * w)
    fa = np.concatenate(([0.0], F * wave.amplitudes))
    zf = np.concatenate(([0.0], F * wave.amplitudes / D))
    q = -((np.arange(zf.size) * w) ** 2) * zf / g
    if coupling_harmonics is None:
        top = float(np.asarray(hydro.omega)[-1])
        coupling_harmonics = max(1, int(math.floor(top / w * (1 + 1e-12))))
    kc = np.arange(1, coupling_harmonics + 1)
    if coupled:
        _, B, _ = hydro.coefficients(kc * w)
        Dc = hydro.impedance(kc * w)
        beta = (m * l_) ** 2 * (kc * w) ** 6 * np.asarray(B, dtype=float) / np.abs(Dc) ** 2
    else:
        beta = np.zeros(kc.size)
    return Scales(t0=t0, power_unit=pu, torque_unit=m * g * l_, omega_nd=w * t0,
                  gamma=pendulum.damping_coefficient * t0 / inertia, q_spec=q,
                  beta_nd=beta / pu, wave_force=fa, free_heave=zf)


def free_excitation(sc: Scales) -> SeaExcitation:
    """The free buoy's ``q_w`` as an excitation of the uncoupled kernel (one-way problem)."""
    return SeaExcitation(sc.omega_nd, np.asarray(sc.q_spec, dtype=complex),
                         np.asarray(sc.free_heave, dtype=complex),
                         {"source": "free buoy"})


def _coupled_points(harmonics: int, winding: int, kc: int, k_wave: int) -> int:
    """A power of two with 8 points per harmonic of the motion and the wave, and at least
    4 per coupling harmonic (so that the harmonics of ``cos(theta)`` up to Kc are read
    without aliasing from the band of ``cos(theta)`` itself)."""
    need = max(64, 8 * (harmonics + winding), 8 * (k_wave + 1), 4 * (kc + harmonics))
    return 1 << int(math.ceil(math.log2(need)))


class CoupledProblem(FourierProblem):
    """Objective, exact gradient and Hessian of the coupled problem on an M-point grid.

    Parameters
    ----------
    excitation : Excitation
        The free buoy's ``q_w`` (``free_excitation``), non-dimensional.
    beta : ndarray
        Non-dimensional ``beta_k``, k = 1..Kc (radiation of the pendulum's reaction).
    harmonics, gamma, points, winding, hessian :
        As :class:`~parapend.optimal.fourier.FourierProblem` (``points`` default: also 4
        per coupling harmonic).
    """

    def __init__(self, excitation, beta: np.ndarray, harmonics: int, gamma: float,
                 points: int | None = None, winding: int = 1, hessian: str = "dense"):
        beta = np.asarray(beta, dtype=float)
        if points is None:
            points = _coupled_points(harmonics, winding, beta.size,
                                     excitation.spectrum.size - 1)
        super().__init__(excitation, harmonics, gamma, points, winding=winding,
                         hessian=hessian)
        m = self.points
        kc = min(beta.size, m // 2 - 1)
        self.beta = beta[:kc]
        self.coupling_harmonics = kc

    # --------------------------------------------------------------------------------------
    def _coupling(self, u: np.ndarray):
        """``(P_c, r)``: the coupling's power ``-2 sum beta_k |<u e^{-iks}>|^2`` and its
        gradient ``r = R u`` on the grid."""
        m, kc = self.points, self.coupling_harmonics
        if kc == 0:
            return 0.0, np.zeros(m)
        uh = np.fft.rfft(u)[1:kc + 1] / m
        pc = -2.0 * float(np.dot(self.beta, uh.real**2 + uh.imag**2))
        c = np.zeros(m // 2 + 1, dtype=complex)
        c[1:kc + 1] = -2.0 * m * self.beta * uh
        return pc, np.fft.irfft(c, m)

    def apply_coupling(self, f: np.ndarray) -> np.ndarray:
        """``R f`` on the grid (harmonics ``-2 beta_k F_k``)."""
        return self._coupling(f)[1]

    def coupling_power(self, x: np.ndarray) -> float:
        """The coupling's part of ``P`` (<= 0): the pendulum's reaction radiated away."""
        return self._coupling(np.cos(self.theta(x)))[0]

    def power(self, x: np.ndarray) -> float:
        u = np.cos(self.theta(x))
        pc, _ = self._coupling(u)
        return float(np.mean(self.w * u)) + pc - self.gamma * self.kinetic(x)

    def evaluate(self, x: np.ndarray):
        """``(P, gradient, Hessian)`` (dense array or ``CoupledOperator``)."""
        n, m = self.harmonics, self.points
        th = self.theta(x)
        sn, cs = np.sin(th), np.cos(th)
        pc, r = self._coupling(cs)
        weff = self.w + r
        u = weff * sn
        v = weff * cs
        U = np.fft.rfft(u)[: n + 1] / m
        V = np.fft.rfft(v)[: 2 * n + 1] / m
        gw = self.gamma * self.omega**2
        p = float(np.mean(self.w * cs)) + pc - gw * (self._k0 + 0.5 * float(
            np.dot(self._k2, x * x)))
        g = np.empty(2 * n + 1)
        g[0] = -U[0].real
        g[1:n + 1] = U[1:].imag
        g[n + 1:] = -U[1:].real
        g -= gw * self._k2 * x
        if self.hessian == "operator":
            return p, g, CoupledOperator(self, v, V, gw, sn)
        X = np.concatenate((V.real, -V.imag))
        h = -(self._coef[0] * X[self._idx[0]] + self._coef[1] * X[self._idx[1]])
        h.flat[:: h.shape[0] + 1] -= gw * self._k2
        kc = self.coupling_harmonics
        if kc:
            W = self._sine_products(sn, kc)
            sb = np.sqrt(self.beta)
            wr, wi = W.real * sb, W.imag * sb
            h -= 4.0 * (wr @ wr.T + wi @ wi.T)
        return p, g, h

    def _sine_products(self, sn: np.ndarray, kc: int) -> np.ndarray:
        """``W[i, j] = <sin(theta) phi_i e^{-ijs}>``, j = 1..Kc, from the FFT of
        ``sin(theta)`` alone (products of trigonometric functions as sums at ``j -+ n``)."""
        n, m = self.harmonics, self.points
        top = min(n + kc, m // 2)
        S = np.zeros(n + kc + 1, dtype=complex)
        S[: top + 1] = np.fft.rfft(sn)[: top + 1] / m
        j = np.arange(1, kc + 1)[None, :]
        k = np.arange(1, n + 1)[:, None]
        d = j - k
        lo = np.where(d >= 0, S[np.abs(d)], np.conj(S[np.abs(d)]))
        hi = S[j + k]
        W = np.empty((2 * n + 1, kc), dtype=complex)
        W[0] = S[1:kc + 1]
        W[1:n + 1] = (lo - hi) / 2j
        W[n + 1:] = (lo + hi) / 2
        return W

    def basis(self) -> np.ndarray:
        """The (2N+1) x M matrix of ``1, sin(ns), cos(ns)`` on the grid."""
        n = self.harmonics
        k = np.arange(1, n + 1)[:, None]
        ks = k * self.s[None, :]
        return np.vstack((np.ones((1, self.points)), np.sin(ks), np.cos(ks)))


class CoupledOperator(HessianOperator):
    """The coupled Hessian as an operator: the uncoupled product with ``w_eff`` plus
    ``<sin(theta) phi_i R(sin(theta) Phi d)>`` (two more real FFTs)."""

    def __init__(self, problem: CoupledProblem, v, V, gw, sn):
        super().__init__(problem, v, V, gw)
        self.sn = sn

    def matvec(self, d: np.ndarray) -> np.ndarray:
        pr = self.problem
        n, m = pr.harmonics, pr.points
        c = np.zeros(m // 2 + 1, dtype=complex)
        c[0] = m * d[0]
        c[1:n + 1] = (0.5 * m) * (d[n + 1:] - 1j * d[1:n + 1])
        phid = np.fft.irfft(c, m)
        f = self.v * phid
        if pr.coupling_harmonics:
            f = f - self.sn * pr.apply_coupling(self.sn * phid)
        G = np.fft.rfft(f)[: n + 1] / m
        out = np.empty(2 * n + 1)
        out[0] = G[0].real
        out[1:n + 1] = -G[1:].imag
        out[n + 1:] = G[1:].real
        return -out - self.gw * pr._k2 * d
