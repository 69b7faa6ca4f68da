r"""The coupled optimum of a pendulum inside a heaving buoy: :func:`coupled_optimum`.

The problem in ``theta`` alone (:mod:`.coupled`) is solved by the safeguarded Newton method
of :mod:`parapend.optimal.fourier` (dense Hessian for a regular wave, matrix-free Newton-CG
for a record), started from several seeds (global search):

- the one-way optimum (the free buoy's motion fed to the uncoupled global search) and every
  other distinct local maximum that search found;
- the same motions with their periodic part halved (a heavy pendulum moves the buoy less);
- uniform rotations at 8 phases;
- swinging-back motions ``K s + alpha sin(K s + psi)`` with ``alpha > 1`` (the rotation
  runs backwards for part of the cycle: a heavy pendulum can have such a second maximum).

Every optimum is re-evaluated on a grid four times finer; a run whose power changes there by
more than :data:`ALIAS_TOL` (relative) is rejected (aliasing: on a coarse grid the objective
can be driven to absurd values by large coefficients). The harmonics ``N`` are chosen from
the problem and checked by one refinement (``2N`` polished from the ``N`` optimum).

In a regular wave (odd harmonics only) the optimum ``theta(t)`` and its half-period image
``theta(t + T/2) + pi`` (:func:`half_period_image`) have the same power exactly, and differ
in their torque; a search returns either, as rounding falls. The result is the one with the
smaller peak torque (peaks within :data:`IMAGE_TIE`: a fixed rule on the coefficients),
before a take-off or a torque limit starts from it.

Checks reported in every result: the energy balance
``P + c <theta'^2> = <F_exc z'> - sum_k 1/2 B_k (k w)^2 |Z_k|^2`` (the left side from the
torque in the time domain on a fine grid, the right side from the heave harmonics), the
radiation bound ``sum_k |F_k a_k|^2 / (8 B_k)``, and the coupled ``c = 0`` supremum
(:func:`coupled_limit`): with ``c = 0``, ``P = m l <z_w''' u> - 1/2 sum beta_k |U_k|^2``
depends on ``u = cos(theta)`` only, and a rotation can approach any measurable
``u(t)`` in ``[-1, 1]`` (fast turns cost nothing without damping), so the supremum is the
concave box-constrained quadratic programme over ``u``, solved on a fine grid; without the
box its value is the radiation bound.

A power take-off (:mod:`parapend.hydro.pto`), from the ideal optimum: an efficiency makes the motion
maximize the electrical power (a smoothed kink with a continuation in its width and in the
harmonics, trust-region Newton on the exact derivatives; the result's electrical power is
evaluated exactly on a fine grid); a torque limit is imposed at every grid point by an
augmented Lagrangian with the same inner solver, at N and 2N, and the peak between the grid
points is checked on the motion's dense evaluation. Where the limit is small enough for the
constant brake (``T = -T_max`` at every instant) to exist, that rotation is solved directly
by harmonic balance (:func:`_brake`) and returned: it attains ``T_max K omega``, the bound of
every rotation that never turns back. Both together: the limit at every width of the last
two harmonic stages.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import ParameterError, check_int
from ..excitation import _evaluate
from ..optimal.fourier import _pad, motion_distance, newton_maximize, search_fourier
from ..optimal.limit import limit as uncoupled_limit
from .coupled import CoupledProblem, Pendulum, Wave, free_excitation, scales
from .pto import _abs_mean

__all__ = ["CoupledSolution", "coupled_limit", "coupled_optimum", "half_period_image",
           "radiation_bound"]

#: relative change of the optimum's power between its grid and one four times finer above
#: which the optimum is rejected as aliased
ALIAS_TOL = 1e-8
#: relative energy-balance residual every result must meet
BALANCE_TOL = 1e-9
#: harmonics of the motion per turn (regular wave) and per mean wave (record)
HARMONICS_PER_TURN = 24
HARMONICS_PER_WAVE = 16
#: a torque-limited optimum may exceed the limit between its grid points by this fraction
TORQUE_SLACK = 1e-3
#: change of the electrical power between a fine grid and one twice as fine, relative to
#: ``<|p|>``, above which the electrical optimum is not a success
ELECTRICAL_GRID_TOL = 1e-6
#: relative change of the electrical optimum from N/2 to N harmonics above which the status
#: says so
ELECTRICAL_REFINE_TOL = 1e-3
#: relative change of the exact electrical power over the last two widths of the
#: continuation below which it counts as converged
ELECTRICAL_SETTLED = 1e-5
#: peak torques of an optimum and its half-period image closer than this (relative) do not
#: decide between them (:func:`_canonical_copy`)
IMAGE_TIE = 1e-6
#: dense Hessian for a regular wave up to this many harmonics, matrix-free Newton-CG above
#: and for every record (the dense Newton from the swinging-back seeds took minutes at N = 192)
DENSE_MAX = 96

#: inner (trust-region Newton) iterations of each stage of the torque-limited optimum: on
#: the fine grid an iteration costs tens of ms and a tight limit (1 N m at the default design)
#: ran 200 per outer step for 40 outer steps, minutes; past the budget the status is
#: "stalled" (the answer is then marked unconverged, not waited for)
LIMITED_MAX_INNER = 300


@dataclass(frozen=True, eq=False)
class CoupledSolution:
    """The coupled optimum (SI units).

    Attributes
    ----------
    success, status : bool, str
        ``success``: the Newton run converged, the fine-grid re-evaluation agrees and the
        energy balance holds to ``BALANCE_TOL``; ``status`` says what was found
        (at ``c = 0`` that the power is a lower bound of ``limit``).
    power : float
        ``P = -<tau theta'>``, W.
    harmonics : int
        N of the motion (chosen from the problem, checked by one refinement).
    theta_coefficients : dict
        ``{"x": [a0, a_1..a_N, b_1..b_N], "winding": K, "omega": w}``: ``theta(t) = K w t +
        a0 + sum a_n sin(n w t) + b_n cos(n w t)``.
    heave : ndarray, complex
        ``Z_k``, k = 0..N (m).
    energy_balance_residual : float
        ``|P + c<theta'^2> - (<F_exc z'> - sum 1/2 B_k (kw)^2 |Z_k|^2)| / scale`` (one-way:
        the pendulum's balance ``P + c<theta'^2> = m l <z''' cos(theta)>``).
    radiation_bound : float
        ``sum_k |F_k a_k|^2 / (8 B_k)``, W.
    limit : float
        The coupled ``c = 0`` supremum (one-way: the uncoupled ``w TV(q) / 2 pi``), W.
    evidence : dict
        The global search: starts, converged, abandoned, rejected (aliased), the distinct
        maxima (power in W and seed), the seed of the optimum.
    one_way : bool
        The pendulum's reaction left out (the pivot moves as the free buoy).
    refinement_change : float
        ``|P(2N) - P(N)|``, W.
    limit_change : float
        Change of ``limit`` under one refinement of its grid, W.
    free_heave : ndarray, complex
        The free buoy's ``Z_k = F_k a_k / D_k``, k = 0..K (m).
    efficiency : (eta_g, eta_m) or None
        With an efficiency the motion maximizes the electrical power and ``power`` is its
        mechanical power; None: the ideal (mechanical) optimum.
    electrical_power : float or None
        ``<e(p)>``, ``e(p) = eta_g p`` generating, ``p / eta_m`` motoring, W (the kink
        integrated exactly on a fine grid's piecewise-linear ``p``).
    ideal_power : float or None
        The ideal (lossless) optimum's mechanical power, W: a bound, as ``e(p) <= eta_g p``
        gives ``electrical_power <= eta_g ideal_power``.
    generated_power, motoring_power : float or None
        ``<max(p, 0)>`` and ``<max(-p, 0)>``, W (their difference is ``power``).
    electrical_refinement_change : float or None
        Change of the electrical optimum from N/2 to N harmonics, W.
    """

    success: bool
    status: str
    power: float
    harmonics: int
    theta_coefficients: dict
    heave: np.ndarray
    energy_balance_residual: float
    radiation_bound: float
    limit: float
    evidence: dict
    one_way: bool = False
    refinement_change: float = 0.0
    limit_change: float = 0.0
    free_heave: np.ndarray = field(default=None, repr=False)
    omega: float = 0.0
    winding: int = 1
    _full_heave: np.ndarray = field(default=None, repr=False)
    _pendulum: Pendulum = field(default=None, repr=False)
    _g: float = 9.81
    efficiency: tuple | None = None
    electrical_power: float | None = None
    ideal_power: float | None = None
    generated_power: float | None = None
    motoring_power: float | None = None
    electrical_refinement_change: float | None = None

    @property
    def period(self) -> float:
        """The period of the motion, s."""
        return 2 * math.pi / self.omega

    def sample(self, t) -> dict:
        """``theta`` (rad), ``theta_dot`` (rad/s), ``theta_ddot``, ``z`` (m), ``z_dot``,
        ``z_ddot`` and ``tau`` (N m) at times ``t`` (s)."""
        t = np.asarray(t, dtype=float)
        w, kw = self.omega, self.winding
        x = np.asarray(self.theta_coefficients["x"], dtype=float)
        n = (x.size - 1) // 2
        spec = np.zeros(n + 1, dtype=complex)
        spec[0] = x[0]
        spec[1:] = x[n + 1:] - 1j * x[1:n + 1]
        k = np.arange(n + 1)
        s = w * t
        th = kw * s + _evaluate(spec, s)
        thd = w * (kw + _evaluate(1j * k * spec, s))
        thdd = w**2 * _evaluate(-(k**2) * spec, s)
        zf = self._full_heave
        kz = np.arange(zf.size) * w
        z = _evaluate(zf, s)
        zd = _evaluate(1j * kz * zf, s)
        zdd = _evaluate(-(kz**2) * zf, s)
        p = self._pendulum
        tau = (p.inertia * thdd + p.damping_coefficient * thd
               - p.mass * p.length * (self._g + zdd) * np.sin(th))
        return {"theta": th, "theta_dot": thd, "theta_ddot": thdd, "z": z, "z_dot": zd,
                "z_ddot": zdd, "tau": tau}

    def torque_grid(self, m: int) -> np.ndarray:
        """``tau`` (N m) at ``t_j = j T / m``, j = 0..m-1 (``m`` even; by FFTs)."""
        w = self.omega
        x = np.asarray(self.theta_coefficients["x"], dtype=float)
        th, ths, thss = _grid_motion(x, self.winding, m)
        zf = self._full_heave[: m // 2]
        c = np.zeros(m // 2 + 1, dtype=complex)
        c[: zf.size] = -((np.arange(zf.size) * w) ** 2) * zf * (m / 2.0)
        zdd = np.fft.irfft(c, m)
        p = self._pendulum
        return (p.inertia * w**2 * thss + p.damping_coefficient * w * ths
                - p.mass * p.length * (self._g + zdd) * np.sin(th))

    def peak_torque(self) -> float:
        """``max |tau|`` over one period, N m: on a grid, the largest local maxima refined."""
        from scipy.optimize import minimize_scalar

        m = 1 << int(math.ceil(math.log2(max(2048, 16 * self.harmonics,
                                                4 * self._full_heave.size))))
        a = np.abs(self.torque_grid(m))
        dt = self.period / m
        best = float(np.max(a))
        for j in np.argsort(a)[-3:]:
            r = minimize_scalar(lambda tt: -abs(float(self.sample(np.array([tt]))["tau"][0])),
                                bounds=(j * dt - dt, j * dt + dt), method="bounded",
                                options={"xatol": 1e-10 * self.period})
            best = max(best, -float(r.fun))
        return best


# ------------------------------------------------------------------------------------------
def _grid_motion(x: np.ndarray, winding: int, m: int):
    """``theta``, ``dtheta/ds``, ``d2theta/ds2`` on ``m`` points of one period of ``s``."""
    n = (x.size - 1) // 2
    c = np.zeros(m // 2 + 1, dtype=complex)
    c[0] = m * x[0]
    c[1:n + 1] = 0.5 * m * (x[n + 1:] - 1j * x[1:n + 1])
    k = np.arange(m // 2 + 1)
    s = 2 * np.pi * np.arange(m) / m
    th = winding * s + np.fft.irfft(c, m)
    ths = winding + np.fft.irfft(1j * k * c, m)
    thss = np.fft.irfft(-(k**2) * c, m)
    return th, ths, thss


def _heave_and_balance(hydro, pendulum: Pendulum, wave: Wave, x: np.ndarray, winding: int,
                       m: int, coupled: bool, torque: bool = False):
    """Power from the torque in the time domain, the heave harmonics and the energy balance.

    Returns ``(power_w, heave, residual)``: ``heave`` the ``Z_k``, k = 0..m/2 - 1; with
    ``torque``, ``(power_w, heave, residual, tau)``, ``tau`` (N m) on the ``m`` points.
    """
    w = wave.omega
    mass, l_, inertia = pendulum.mass, pendulum.length, pendulum.inertia
    c = pendulum.damping_coefficient
    g = float(hydro.g)
    th, ths, thss = _grid_motion(x, winding, m)
    thd, thdd = w * ths, w**2 * thss
    u = np.cos(th)
    kk = np.arange(m // 2)
    ch = 2.0 * np.fft.rfft(u)[: m // 2] / m
    ch[0] = 0.0
    om = kk * w
    fa = np.zeros(m // 2, dtype=complex)
    ka = min(wave.amplitudes.size, m // 2 - 1)
    _, _, F = hydro.coefficients(om[1:ka + 1])
    fa[1:ka + 1] = F * wave.amplitudes[:ka]
    A, B, _ = hydro.coefficients(om)
    D = -om**2 * (hydro.mass + A) + 1j * om * B + hydro.hydrostatic_stiffness
    Z = np.zeros(m // 2, dtype=complex)
    Z[1:] = (fa[1:] + (mass * l_ * om[1:] ** 2 * ch[1:] if coupled else 0.0)) / D[1:]
    zspec = np.zeros(m // 2 + 1, dtype=complex)
    zspec[: m // 2] = -(om**2) * Z * (m / 2.0)
    zdd = np.fft.irfft(zspec, m)
    tau = inertia * thdd + c * thd - mass * l_ * (g + zdd) * np.sin(th)
    p = -float(np.mean(tau * thd))
    diss = c * float(np.mean(thd**2))
    if coupled:
        exc = 0.5 * float(np.sum((fa * np.conj(1j * om * Z)).real))
        rad = 0.5 * float(np.sum(B * om**2 * np.abs(Z) ** 2))
        rhs = exc - rad
        scale = max(abs(p), diss, abs(exc), rad, 1e-300)
    else:
        # the pendulum's own balance: P + c<theta'^2> = m l <z''' cos(theta)>
        rhs = mass * l_ * 0.5 * float(np.sum(((-1j * om**3) * Z * np.conj(ch)).real))
        scale = max(abs(p), diss, abs(rhs), 1e-300)
    if torque:
        return p, Z, abs(p + diss - rhs) / scale, tau
    return p, Z, abs(p + diss - rhs) / scale


# ------------------------------------------------------------------------------------------
def half_period_image(x: np.ndarray, winding: int) -> np.ndarray:
    r"""The packed coefficients of ``theta(s + pi) + pi`` from those of ``theta(s)``.

    ``theta(s) = K s + a0 + sum a_n sin(ns) + b_n cos(ns)``: the image has ``a_n`` and
    ``b_n`` times ``(-1)^n`` and ``a0 + (K + 1) pi``, taken as ``a0`` for odd ``K`` (a whole
    number of turns) and ``a0 + pi`` for even ``K``.

    In a wave of odd harmonics only (a regular wave), ``q_w(s + pi) = -q_w(s)``. The image
    ``theta~(s) = theta(s + pi) + pi`` has ``cos(theta~(s)) = -cos(theta(s + pi))``, so the
    reaction's heave (linear in ``cos(theta)``) and the wave's both change sign:
    ``z~(s) = -z(s + pi)``. The mean power ``P = -c <theta'^2> + m l <z'' theta' sin(theta)>``
    (``I <theta'' theta'>`` and ``g <theta' sin(theta)>`` vanish: exact derivatives) is the
    same for both, on every even grid (the shift by ``pi`` maps its points onto themselves),
    and so is the heave amplitude. The torques are not:
    ``tau~(s) = tau(s + pi) + 2 m l g sin(theta(s + pi))`` (gravity's part, which averages
    to nothing in ``P``), nor is anything else that depends on more than the mean power:
    the peak torque, the electrical power through a take-off, the torque-limited optimum
    started from the motion.
    """
    x = np.asarray(x, dtype=float)
    n = (x.size - 1) // 2
    sign = (-1.0) ** np.arange(1, n + 1)
    y = x.copy()
    y[1:n + 1] *= sign
    y[n + 1:] *= sign
    if winding % 2 == 0:
        y[0] += math.pi
    return y


def _canonical_copy(hydro, pendulum, wave, x, winding, m, coupled):
    """Of the optimum ``x`` and its :func:`half_period_image` (the same power: which of the
    two a search returns is decided by rounding), the one with the smaller peak torque on
    ``m`` points; peaks within :data:`IMAGE_TIE` (relative) of each other: the one whose first
    odd harmonic (``a_1, b_1, a_3, b_3, ...``) above 1e-6 rad is positive (even ``K`` and
    no such harmonic: ``a0`` modulo 2 pi below pi). Returns ``(x, peak, image_peak)``
    (N m), the peaks None where the wave has even harmonics above 1e-12 of its largest
    (no such symmetry)."""
    a = np.abs(np.asarray(wave.amplitudes))
    if a.size > 1 and float(np.max(a[1::2])) > 1e-12 * float(np.max(a)):
        return x, None, None
    y = half_period_image(x, winding)
    p0, _, _, t0 = _heave_and_balance(hydro, pendulum, wave, x, winding, m, coupled, True)
    p1, _, _, t1 = _heave_and_balance(hydro, pendulum, wave, y, winding, m, coupled, True)
    if not abs(p1 - p0) <= 1e-9 * max(abs(p0), abs(p1), 1e-300):
        return x, None, None  # not the symmetry this relies on: keep the search's choice
    a, b = float(np.max(np.abs(t0))), float(np.max(np.abs(t1)))
    if abs(a - b) > IMAGE_TIE * max(a, b):
        swap = b < a
    else:
        n = (x.size - 1) // 2
        odd = np.column_stack((x[1:n + 1:2], x[n + 1::2])).ravel()
        big = odd[np.abs(odd) > 1e-6]
        if big.size:
            swap = bool(big[0] < 0)
        else:
            swap = winding % 2 == 0 and abs(math.remainder(float(x[0]) - math.pi / 2,
                                                            2 * math.pi)) >= math.pi / 2
    return (y, b, a) if swap else (x, a, b)


# ------------------------------------------------------------------------------------------
def _dual(w: np.ndarray, beta: np.ndarray, lam0: np.ndarray | None = None):
    """Minimize the dual ``D(lam) = <|w - rho|> + sum |lam_k|^2 / (2 beta_k)``,
    ``rho = 2 Re sum lam_k e^{iks}``, over ``lam`` (2 Kc reals; L-BFGS).

    By weak duality every ``D(lam)`` bounds the box QP from above; at the minimum the
    optimal ``u`` is ``sign(w - rho)`` (bang-bang, as ``w - rho`` is band-limited).
    """
    from scipy.optimize import minimize

    m = w.size
    kc = min(beta.size, m // 2 - 1)
    b = beta[:kc]
    pos = b > 0

    if not pos.any():
        return _abs_mean(w)[0], np.zeros(kc, dtype=complex)
    sb = np.sqrt(b[pos])  # lam = sqrt(beta) mu: the quadratic term is |mu|^2 / 2

    def unpack(z):
        lam = np.zeros(kc, dtype=complex)
        h = pos.sum()
        lam[pos] = sb * (z[:h] + 1j * z[h:])
        return lam

    def f(z):
        lam = unpack(z)
        c = np.zeros(m // 2 + 1, dtype=complex)
        c[1:kc + 1] = m * lam  # irfft: Re sum 2 lam_k e^{iks}
        rho = np.fft.irfft(c, m)
        v, gf = _abs_mean(w - rho)
        v += 0.5 * float(np.dot(z, z))
        # d/d lam of <|w - rho|>: -sum_j gf_j * 2 e^{iks_j} (Re, Im parts)
        G = np.fft.rfft(gf)[1:kc + 1][pos]  # sum_j gf_j e^{-iks_j}
        return v, np.concatenate((-2 * G.real * sb, -2 * G.imag * sb)) + z

    z0 = np.zeros(2 * int(pos.sum())) if lam0 is None else np.concatenate(
        (lam0[:kc][pos].real / sb, lam0[:kc][pos].imag / sb))
    r = minimize(f, z0, jac=True, method="L-BFGS-B",
                 options={"maxiter": 5000, "maxcor": 10, "ftol": 1e-15, "gtol": 1e-12})
    lam = unpack(r.x)
    return float(r.fun), lam


def coupled_limit(sc, points: int = 1024) -> tuple[float, float, np.ndarray]:
    """The coupled ``c = 0`` supremum (non-dimensional) by its dual, on ``points`` and on
    twice as many.

    Returns ``(value, change, u)``: the dual value on the finer grid (an upper bound of the
    box QP up to the linear interpolation of ``w - rho`` between grid points), its change
    from the coarser grid, and the optimal ``u = cos(theta) = sign(w - rho)`` there.
    """
    exc = free_excitation(sc)
    beta = np.asarray(sc.beta_nd, dtype=float)
    m = max(points, 1 << int(math.ceil(math.log2(8 * max(beta.size, exc.spectrum.size)))))
    v1, lam = _dual(exc.dq_grid(m), beta)
    w2 = exc.dq_grid(2 * m)
    v2, lam2 = _dual(w2, beta, lam)
    c = np.zeros(m + 1, dtype=complex)
    c[1:lam2.size + 1] = 2 * m * lam2
    u = np.sign(w2 - np.fft.irfft(c, 2 * m))
    return v2, abs(v2 - v1), u


# ------------------------------------------------------------------------------------------
def _check_args(winding, harmonics, torque_limit, efficiency, starts):
    if torque_limit is not None and not (
            isinstance(torque_limit, (int, float, np.floating)) and math.isfinite(torque_limit)
            and torque_limit > 0):
        raise ParameterError(f"torque-limit: expected a positive torque in N m, got "
                             f"{torque_limit!r}")
    k = check_int("winding", winding, 1, 4096)
    n = None if harmonics is None else check_int("harmonics", harmonics, 1, 8192)
    if n is not None and n < 2 * k:
        raise ParameterError(f"harmonics: expected at least 2 K = {2 * k} harmonics to draw "
                             f"{k} turns, got {n}")
    if starts is not None:
        starts = check_int("starts", starts, 1, 1000)
    return k, n, starts


def _check_hydro(hydro, wave: Wave):
    a = np.abs(wave.amplitudes)
    sig = np.nonzero(a >= 1e-3 * a.max())[0]
    fr = wave.frequencies
    hydro.check_covers(float(fr[sig[0]]), float(fr[sig[-1]]))
    top = wave.omega * (1 + np.nonzero(a > 1e-9 * a.max())[0][-1])
    if bool(np.any(hydro.above_range(np.array([top])))):
        warnings.warn("wave: components above the dataset's highest frequency are taken "
                      "with B = F = 0", RuntimeWarning, stacklevel=3)


def radiation_bound(hydro, wave: Wave) -> float:
    """``sum_k |F_k a_k|^2 / (8 B_k)`` over the wave's components with ``B_k > 0``, W (each
    component's bound for a heaving body; the harmonics of a periodic motion are orthogonal
    in the mean power, so the bounds add)."""
    _, b, f = hydro.coefficients(wave.frequencies)
    b = np.asarray(b, dtype=float)
    e = np.abs(np.asarray(f) * wave.amplitudes) ** 2
    ok = b > 0
    return float(np.sum(e[ok] / (8.0 * b[ok])))


def _default_harmonics(sc, winding: int, regular: bool) -> int:
    if regular:
        return HARMONICS_PER_TURN * winding
    e = np.abs(sc.free_heave) ** 2
    k = np.arange(e.size)
    km = max(1, int(round(float(np.sum(k * e) / np.sum(e))))) if np.sum(e) > 0 else 1
    return min(HARMONICS_PER_WAVE * max(km, winding), 8192)


def _seeds(one_way_runs, n: int, winding: int, best_x, count):
    """Seeds of the coupled search (see the module docstring)."""
    out = [("one-way", _pad(best_x, n))]
    distinct = []
    for r in sorted((r for r in one_way_runs if r.status == "converged"),
                    key=lambda r: -r.power):
        xr = _pad(r.x, n)
        if all(motion_distance(xr, d) > 1e-6 for d in [out[0][1], *distinct]):
            distinct.append(xr)
    out += [(f"one-way-{i + 2}", d) for i, d in enumerate(distinct[:4])]
    half = out[0][1].copy()
    half[1:] *= 0.5
    out.append(("one-way-half", half))
    for j in range(8):
        x = np.zeros(2 * n + 1)
        x[0] = 2 * math.pi * j / 8
        out.append((f"uniform-{j}", x))
    if n >= winding:
        for alpha in (1.5, 3.0):
            for j in range(4):
                psi = 2 * math.pi * j / 4
                x = np.zeros(2 * n + 1)
                x[winding] = alpha * math.cos(psi)       # a_K sin(K s)
                x[n + winding] = alpha * math.sin(psi)   # b_K cos(K s)
                out.append((f"swing-back-{alpha:g}-{j}", x))
    return out[:count] if count is not None else out


def _polish(problem, seeds, fine_points):
    """Newton from every seed; reject aliased runs. Returns ``(best, runs, rejected)``."""
    runs, rejected = [], 0
    scale = float(np.max(np.abs(problem.w)))
    bar = -math.inf
    best = None
    for name, x0 in seeds:
        r = newton_maximize(problem, x0, name, abandon_below=bar if runs else -math.inf)
        runs.append(r)
        if r.status == "abandoned" or not math.isfinite(r.power):
            continue
        fine = CoupledProblem(problem.excitation, problem.beta, problem.harmonics,
                              problem.gamma, fine_points, winding=problem.winding,
                              hessian="operator")
        pf = fine.power(r.x)
        if abs(pf - r.power) > ALIAS_TOL * max(abs(r.power), abs(pf), scale):
            rejected += 1
            runs[-1] = type(r)(r.x, r.power, r.gradient_norm, r.iterations, "aliased", r.seed,
                               r.points, r.strict_maximum)
            continue
        if best is None or r.power > best.power:
            best = r
        bar = max(bar, r.power)
    return best, runs, rejected


class _Torque:
    """Non-dimensional torque ``tau = Omega^2 theta_ss + gamma Omega theta_s - (1 + q)
    sin(theta)`` on the problem's grid and its Jacobian, ``q = q_w + L cos(theta)`` with
    ``L`` the pendulum's reaction on the buoy (harmonics ``-(kw)^4 m l / (g D_k)``; every
    harmonic of the grid, the reactive ones above the dataset included)."""

    def __init__(self, problem, hydro, pendulum, wave, coupled: bool):
        self.pr = problem
        m = problem.points
        k = np.arange(m // 2 + 1)
        om = k * wave.omega
        gk = np.zeros(m // 2 + 1, dtype=complex)
        if coupled:
            d = hydro.impedance(om[1:m // 2])
            gk[1:m // 2] = -(om[1:m // 2] ** 4) * pendulum.mass * pendulum.length / (
                float(hydro.g) * d)
        self.gk = gk
        self.qw = problem.excitation.q_grid(m)
        self.basis = problem.basis()
        n = problem.harmonics
        kk = np.arange(1, n + 1)[:, None]
        s = problem.s[None, :]
        self.d1 = np.vstack((np.zeros((1, m)), kk * np.cos(kk * s), -kk * np.sin(kk * s)))
        self.d2 = np.vstack((np.zeros((1, m)), -(kk**2) * np.sin(kk * s),
                             -(kk**2) * np.cos(kk * s)))

    def _l(self, f):
        m = self.pr.points
        return np.fft.irfft(self.gk * np.fft.rfft(f, axis=-1), m, axis=-1)

    def __call__(self, x):
        pr = self.pr
        om, k = pr.omega, pr.winding
        th = pr.theta(x)
        ths = k + x @ self.d1
        thss = x @ self.d2
        sn, cs = np.sin(th), np.cos(th)
        q = self.qw + self._l(cs)
        tau = om**2 * thss + pr.gamma * om * ths - (1 + q) * sn
        jac = (om**2 * self.d2 + pr.gamma * om * self.d1 - ((1 + q) * cs) * self.basis
               + sn * self._l(sn * self.basis))
        return tau, jac.T


def _limited(hydro, pendulum, wave, sc, exc, x_ideal, n, n2, k, regular, limit_nd, coupled,
             ideal_power=math.inf):
    """The torque-limited optimum (:func:`parapend.hydro.pto.torque_limited`) with ``n``
    harmonics from the ideal optimum, then with ``n2`` from that; None when the ideal
    optimum already keeps ``|tau| <= limit`` on the ``n2`` grid.

    First the constant brake (:func:`_brake`), where it can exist: its power
    ``T_max K omega`` is at most the ideal optimum's ``ideal_power`` (non-dimensional; a
    rotation under the limit is a rotation). It attains the bound of every rotation that
    never turns back, so when it exists it is returned without the augmented Lagrangian,
    which approaches it only slowly (a piecewise smooth optimum, the torque at the limit
    everywhere): at the default design a limit of 1 N m stalled after 567 Newton steps at
    3.434 W, 0.1 N m at 0.2779 W and 3 N m at 10.452 W, each short of the brake's
    3.491 W, 0.3491 W and 10.47 W. Rotations that turn back under the limit are then not
    searched (as in :mod:`parapend.pto`, whose brake wins wherever it beats the solver).
    """
    from .pto import ElectricalProblem, torque_limited

    def make(nn):
        hess = "dense" if regular and nn <= DENSE_MAX else "operator"
        base = CoupledProblem(exc, sc.beta_nd, nn, sc.gamma, winding=k, hessian=hess)
        return ElectricalProblem(base, _Torque(base, hydro, pendulum, wave, coupled).gk,
                                 (1.0, 1.0), 0.0)

    pf = make(n2)
    if float(np.max(np.abs(pf.state(_pad(x_ideal, n2))["tau"]))) <= limit_nd:
        return None
    bound = limit_nd * k * pf.omega
    if bound <= ideal_power:
        found = _brake(hydro, pendulum, wave, sc, exc, [x_ideal] + [
            np.eye(1, 2 * n + 1, 0).ravel() * (2 * math.pi * j / 8) for j in range(8)],
            n, k, limit_nd, coupled)
        if found is not None:
            x, nb, change = found
            points = CoupledProblem(exc, sc.beta_nd, nb, sc.gamma, winding=k,
                                    hessian="operator").points
            return {"x": x, "power": bound, "change": 0.0, "points": points,
                    "status": "converged", "outer": 0, "inner": 0, "brake": nb,
                    "brake_change": change}
    pc = make(n)
    xc, oc, _, out_c, in_c, _ = torque_limited(pc, _pad(x_ideal, n), limit_nd,
                                                  max_inner=LIMITED_MAX_INNER)
    xf, of, _, out_f, in_f, st_f = torque_limited(pf, _pad(xc, n2), limit_nd,
                                                  max_inner=LIMITED_MAX_INNER)
    # the coarse stage only starts the fine one: the answer is the fine stage's, and so is
    # its status (a coarse stage cut at its Newton budget is not a defect of the answer)
    ok = st_f == "converged"
    return {"x": xf, "power": of, "change": abs(of - oc), "points": pf.points,
            "status": "converged" if ok else "stalled", "outer": out_c + out_f,
            "inner": in_c + in_f}


#: the constant brake (:func:`_brake`): at most this many harmonics; its Gauss-Newton stops
#: when the torque is ``-T_max`` on the grid to this (non-dimensional, ``m g l`` units)
BRAKE_MAX_HARMONICS = 256
BRAKE_TOL = 1e-9
#: a start is given up unless its first resolution's residual falls below this (a brake
#: resolved on ``n`` harmonics is there to about ``1e-5`` at the default design)
BRAKE_START_TOL = 1e-3


def _brake(hydro, pendulum, wave, sc, exc, starts, n, k, limit_nd, coupled):
    r"""The coupled rotation under the constant torque ``T = -T_max`` (the constant brake of
    :mod:`parapend.optimal.brake`, with the buoy's reaction): a rotation that never turns
    back extracts at most ``T_max <theta'> = T_max K omega``, with equality only for
    ``T = -T_max`` at every instant; where such a rotation exists it is the torque-limited
    optimum of every rotation that never turns back.

    Gauss-Newton on ``tau(x) + T_max = 0`` at the grid points of the coupled torque
    (:class:`_Torque`, its exact Jacobian), from each of ``starts`` in turn, ``N`` doubled
    from ``n`` until the coefficients move by less than ``BRAKE_TOL`` and the grid's torque
    is ``-T_max`` within it. Returns ``(x, harmonics, change)`` (``change``: the largest
    coefficient change at the last doubling) of the first start that converges to a
    rotation with ``theta' > 0`` on a dense grid, or None.
    """
    for x_start in starts:
        got = _one_brake(hydro, pendulum, wave, sc, exc, x_start, n, k, limit_nd, coupled)
        if got is not None:
            return got
    return None


def _one_brake(hydro, pendulum, wave, sc, exc, x_start, n, k, limit_nd, coupled):
    """:func:`_brake` from one start: harmonic balance (Newton on the residual's Fourier
    coefficients, the square Galerkin system of the torque's exact Jacobian), ``N``
    doubled while the grid's residual is above ``BRAKE_TOL``."""
    prev = None
    nn = n
    while nn <= BRAKE_MAX_HARMONICS:
        base = CoupledProblem(exc, sc.beta_nd, nn, sc.gamma, winding=k, hessian="operator")
        tq = _Torque(base, hydro, pendulum, wave, coupled)
        proj = tq.basis / base.points

        def residual(z, tq=tq, proj=proj):
            tau, jac = tq(z)
            r = tau + limit_nd
            return r, proj @ r, jac

        x = _pad(x_start if prev is None else prev, nn)
        x0 = x.copy()
        r, rh, jac = residual(x)
        for _ in range(30):
            size = float(np.max(np.abs(rh)))
            if not math.isfinite(size):
                return None
            if size <= 1e-3 * BRAKE_TOL:
                break
            try:
                dx = np.linalg.solve(proj @ jac, -rh)
            except np.linalg.LinAlgError:
                return None
            alpha = 1.0
            while alpha > 1e-4:  # backtracking on the projected residual
                got = residual(x + alpha * dx)
                if float(np.max(np.abs(got[1]))) < size:
                    break
                alpha *= 0.5
            else:
                break
            x = x + alpha * dx
            r, rh, jac = got
        norm = float(np.max(np.abs(r)))
        if not norm <= BRAKE_START_TOL:
            return None  # not near a brake: another start
        if prev is not None and norm <= BRAKE_TOL:
            change = float(np.max(np.abs(x - x0)))
            if change <= BRAKE_TOL:
                _, ths, _ = _grid_motion(x, k, 16 * (2 * nn + 1))
                if float(np.min(ths)) <= 0.0:
                    return None
                return x, nn, change
        prev = x
        nn *= 2
    return None


def _electrical(hydro, pendulum, wave, sc, exc, x_ideal, n, k, regular, eta, coupled,
                limit=None):
    """The electrical optimum with ``n`` harmonics (:func:`parapend.hydro.pto.ladder` from
    the ideal optimum ``x_ideal``): a dict of the motion, its exact electrical and
    mechanical power (non-dimensional, on its grid) and the status."""
    from .pto import ElectricalProblem, ladder

    def make(nn):
        hess = "dense" if regular and nn <= DENSE_MAX else "operator"
        base = CoupledProblem(exc, sc.beta_nd, nn, sc.gamma, winding=k, hessian=hess)
        return ElectricalProblem(base, _Torque(base, hydro, pendulum, wave, coupled).gk, eta,
                                 0.0)

    start = max(2 * k, n // 4)
    x, ex, coarse, log = ladder(make, x_ideal, n, start, limit)
    pr = make(n)
    last = [r[1] for r in log[-1][2] if math.isfinite(r[1])]
    settled = len(last) >= 2 and abs(last[-1] - last[-2]) <= ELECTRICAL_SETTLED * max(
        abs(ex), 1e-300)
    return {"x": x, "exact": ex, "coarse": coarse, "mechanical": pr.mechanical(x),
            "status": "converged" if settled and math.isfinite(ex) else "stalled",
            "iterations": sum(r[3] for stage in log for r in stage[2]), "points": pr.points,
            "harmonics": n, "log": log}


def _electrical_fine(hydro, pendulum, x, winding, omega, m, heave, eta):
    """``(<e(p)>, <p+>, <p->, change)`` in W on ``m`` points (the kink exact on the
    piecewise-linear ``p``), ``change`` against ``m / 2`` points."""
    from .pto import electrical_power

    out = []
    for mm in (m // 2, m):
        th, ths, thss = _grid_motion(x, winding, mm)
        zf = heave[: mm // 2]
        c = np.zeros(mm // 2 + 1, dtype=complex)
        c[: zf.size] = -((np.arange(zf.size) * omega) ** 2) * zf * (mm / 2.0)
        zdd = np.fft.irfft(c, mm)
        thd = omega * ths
        tau = (pendulum.inertia * omega**2 * thss + pendulum.damping_coefficient * thd
               - pendulum.mass * pendulum.length * (float(hydro.g) + zdd) * np.sin(th))
        out.append(electrical_power(-tau * thd, eta))
    return out[1][0], out[1][1], out[1][2], abs(out[1][0] - out[0][0])


def _distinct_maxima(runs, pu):
    out = []
    for r in sorted((r for r in runs if r.status == "converged"), key=lambda r: -r.power):
        if all(motion_distance(r.x, o[2]) > 1e-6 and abs(r.power - o[0] / pu) > 1e-10
               for o in out):
            out.append((r.power * pu, r.seed, r.x))
    return [{"power": p, "found_by": s} for p, s, _ in out]


def coupled_optimum(hydro, pendulum: Pendulum, wave: Wave, *, winding: int = 1,
                    harmonics: int | None = None, torque_limit=None, efficiency=None,
                    starts: int | None = None, one_way: bool = False) -> CoupledSolution:
    """The best periodic rotation of a pendulum inside a heaving buoy (see module docstring).

    Parameters
    ----------
    hydro : Hydro
        The buoy's heave coefficients.
    pendulum : Pendulum
    wave : Wave
        A regular wave or one period of a periodic record.
    winding : int
        K, turns per period of the wave (or of the record).
    harmonics : int or None
        N; None: 24 K (regular wave) or 16 per mean wave of the free heave (record), then
        checked by one refinement (the result is the ``2N`` optimum).
    torque_limit : float or None
        ``|tau| <= torque_limit`` (N m), a regular wave or a record: an augmented
        Lagrangian on the grid's torques (:func:`parapend.hydro.pto.torque_limited`: exact
        gradient and Hessian, trust-region Newton), from the ideal optimum, at N and 2N;
        the peak between grid points is checked (within ``TORQUE_SLACK``, else
        ``success`` is False) and stated in ``status``. A limit whose constant brake
        exists (``T_max K omega`` at most the ideal power) gets the brake instead
        (``_limited``).
    efficiency : float, (eta_g, eta_m), "ETA_G[,ETA_M]" or None
        Maximize the electrical power ``<e(p)>`` instead (:mod:`parapend.hydro.pto`): a
        smoothed kink with a continuation to zero width and in the harmonics (N/4 to N),
        started from the ideal optimum; its exact value on a fine grid is ``electrical_power``. With
        ``torque_limit`` every width of the last two harmonic stages is solved under the
        limit. 1 both ways is the ideal problem (the ideal optimum is returned).
    starts : int or None
        At most this many seeds of the global search (None: all).
    one_way : bool
        Leave the pendulum's reaction out: the pivot moves as the free buoy (the uncoupled
        global search of ``parapend.optimal.fourier.search_fourier``).
    """
    if not isinstance(pendulum, Pendulum):
        raise ParameterError("pendulum: expected a Pendulum(mass, length, inertia, "
                             "damping_coefficient)")
    if not isinstance(wave, Wave):
        raise ParameterError("wave: expected a Wave (Wave.regular or Wave.from_record)")
    k, n, starts = _check_args(winding, harmonics, torque_limit, efficiency, starts)
    from .pto import efficiency_pair

    eta = efficiency_pair(efficiency)
    _check_hydro(hydro, wave)
    regular = wave.amplitudes.size == 1
    sc = scales(hydro, pendulum, wave, coupled=not one_way)
    exc = free_excitation(sc)
    pu = sc.power_unit
    if n is None:
        n = _default_harmonics(sc, k, regular)
    hess = "dense" if regular and n <= DENSE_MAX else "operator"
    bound = radiation_bound(hydro, wave)
    kw = {"winding": k, "hessian": hess}
    if not regular:
        kw["propose"] = 4
    ow = search_fourier(exc, n, sc.gamma, **kw)
    if one_way:
        best, runs, rejected = ow.best, ow.runs, 0
        problem_n = CoupledProblem(exc, sc.beta_nd, n, sc.gamma, winding=k, hessian=hess)
        lim_nd, lim_change = uncoupled_limit(exc).power, 0.0
    else:
        problem_n = CoupledProblem(exc, sc.beta_nd, n, sc.gamma, winding=k, hessian=hess)
        best, runs, rejected = _polish(problem_n, _seeds(ow.runs, n, k, ow.best.x, starts),
                                       4 * problem_n.points)
        lim_nd, lim_change, _ = coupled_limit(sc, 1024)
    if best is None:
        return _failed(sc, wave, n, k, bound, lim_nd * pu, runs, rejected, one_way, hydro,
                       pendulum)
    # one refinement: 2N from the N optimum
    n2 = 2 * n
    hess2 = "dense" if regular and n2 <= DENSE_MAX else "operator"
    fine = CoupledProblem(exc, sc.beta_nd, n2, sc.gamma, winding=k, hessian=hess2)
    ref = newton_maximize(fine, _pad(best.x, n2), best.seed)
    change = abs(ref.power - best.power)
    sol = best
    if ref.status == "converged" and ref.power >= best.power - 1e-12 * max(1.0, abs(
            best.power)):
        sol, n = ref, n2
    # a regular wave: the optimum and its half-period image tie in power; take one by rule
    mf = max(4096, 4 * fine.points)
    x_c, peak_c, peak_i = _canonical_copy(hydro, pendulum, wave, sol.x, k, mf, not one_way)
    if x_c is not sol.x:
        sol = replace(sol, x=x_c)
    tl_note = None
    elec = None
    if eta is not None and eta != (1.0, 1.0):
        lim_e = None if torque_limit is None else torque_limit / sc.torque_unit
        elec = _electrical(hydro, pendulum, wave, sc, exc, sol.x, n, k, regular, eta,
                           not one_way, lim_e)
        ideal_nd = sol.power
        sol = type(sol)(elec["x"], float("nan"), 0.0, elec["iterations"], elec["status"],
                        sol.seed, elec["points"], False)
        n = elec["harmonics"]
    if torque_limit is not None and elec is not None:
        tl_note = (f"torque limit {torque_limit:g} N m imposed on the electrical optimum "
                   "(augmented Lagrangian at every width of the last two harmonic "
                   "stages)")
    elif torque_limit is not None:
        tl = _limited(hydro, pendulum, wave, sc, exc, sol.x, problem_n.harmonics, n2, k,
                      regular, torque_limit / sc.torque_unit, not one_way, sol.power)
        if tl is None:
            tl_note = "torque limit inactive: the ideal optimum stays within it"
        elif "brake" in tl:
            change = tl["change"]
            sol = type(sol)(tl["x"], tl["power"], 0.0, 0, tl["status"], best.seed,
                            tl["points"], False)
            n = tl["brake"]
            mf = max(mf, 4 * tl["points"])
            tl_note = (f"torque limit {torque_limit:g} N m active: the constant brake (T = "
                       f"-T_max at every instant, {n} harmonics), the bound T_max K omega of "
                       "every rotation that never turns back")
        else:
            change = tl["change"]
            sol = type(sol)(tl["x"], tl["power"], 0.0, tl["inner"], tl["status"], best.seed,
                            tl["points"], False)
            n = n2
            tl_note = (f"torque limit {torque_limit:g} N m active (augmented Lagrangian on "
                       f"the {tl['points']}-point grid: {tl['status']}, {tl['outer']} "
                       f"multiplier updates, {tl['inner']} Newton steps)")
    # fine grid: the power from the torque, the heave, the energy balance
    p_w, Z, resid = _heave_and_balance(hydro, pendulum, wave, sol.x, k, mf, not one_way)
    if elec is not None:
        # the electrical optimum's grid: its own mechanical power there
        alias = abs(p_w - elec["mechanical"] * pu) / max(abs(p_w),
                                                          float(np.max(np.abs(fine.w))) * pu)
    else:
        alias = abs(p_w - sol.power * pu) / max(abs(p_w), float(np.max(np.abs(fine.w))) * pu)
    ok = sol.status == "converged" and resid <= BALANCE_TOL and alias <= ALIAS_TOL
    parts = [f"{'one-way' if one_way else 'coupled'} optimum: {sol.status} (found by "
             f"{sol.seed})"]
    if not ok:
        if resid > BALANCE_TOL:
            parts.append(f"energy balance residual {resid:.2g} above {BALANCE_TOL:g}")
        if alias > ALIAS_TOL:
            parts.append(f"power on a fine grid differs by {alias:.2g} (relative)")
    if tl_note:
        parts.append(tl_note)
    if p_w <= 0:
        parts.append("no power: the best motion extracts nothing (P <= 0; the damping is too "
                     "large or the buoy barely moves)")
    if pendulum.damping_coefficient == 0:
        parts.append("c = 0: the supremum (limit) is approached by switching motions and not "
                     "attained; this finite-N power is a lower bound of it")
    efields = {}
    if elec is not None:
        e_w, gen, mot, e_chk = _electrical_fine(hydro, pendulum, sol.x, k, wave.omega,
                                                max(mf, 16384, 1 << int(math.ceil(
                                                    math.log2(128 * (n + k))))),
                                                Z, eta)
        e_change = abs(elec["exact"] - elec["coarse"]) * pu if elec["coarse"] is not None \
            else 0.0
        efields = {"efficiency": eta, "electrical_power": e_w, "ideal_power": ideal_nd * pu,
                   "generated_power": gen, "motoring_power": mot,
                   "electrical_refinement_change": e_change}
        parts.append(f"electrical optimum (efficiency {eta[0]:g} generating, {eta[1]:g} "
                     f"motoring): {elec['status']}, {elec['harmonics']} harmonics")
        if e_chk > ELECTRICAL_GRID_TOL * max(gen + mot, 1e-300):
            ok = False
            parts.append(f"electrical power on a finer grid differs by {e_chk:.2g} W")
        if e_change > ELECTRICAL_REFINE_TOL * max(abs(e_w), 1e-300):
            parts.append(f"refinement N/2 -> N changed the electrical power by "
                         f"{e_change:.3g} W")
        if e_w > eta[0] * ideal_nd * pu * (1 + 1e-9) + 1e-12 * abs(ideal_nd * pu):
            ok = False
            parts.append("electrical power above eta_g times the ideal optimum: not "
                         "resolved")
    if elec is None and change > 1e-6 * max(abs(sol.power), 1e-300):
        parts.append(f"refinement N -> 2N changed the power by {change * pu:.3g} W")
    evid = {"starts": len(runs), "converged": sum(r.status == "converged" for r in runs),
            "abandoned": sum(r.status == "abandoned" for r in runs), "rejected_aliased":
            rejected, "maxima": _distinct_maxima(runs, pu), "found_by": sol.seed,
            "one_way_power": ow.best.power * pu, "one_way_strategy": ow.evidence.strategy,
            "ideal_peak_torque": peak_c, "image_peak_torque": peak_i}
    second = [d["power"] for d in evid["maxima"][1:]]
    evid["second_power"] = second[0] if second else None
    zfull = Z
    nz = np.nonzero(np.abs(zfull) > 1e-15 * max(float(np.max(np.abs(zfull))), 1e-300))[0]
    zfull = zfull[: (nz[-1] + 1 if nz.size else 1)]
    heave = np.zeros(n + 1, dtype=complex)
    heave[: min(n + 1, Z.size)] = Z[: n + 1]
    res = CoupledSolution(
        success=bool(ok), status="; ".join(parts), power=float(p_w), harmonics=n,
        theta_coefficients={"x": np.asarray(sol.x), "winding": k, "omega": wave.omega},
        heave=heave, energy_balance_residual=float(resid), radiation_bound=float(bound),
        limit=float(lim_nd * pu), evidence=evid, one_way=bool(one_way),
        refinement_change=float(change * pu), limit_change=float(lim_change * pu),
        free_heave=np.asarray(sc.free_heave), omega=wave.omega, winding=k,
        _full_heave=zfull, _pendulum=pendulum, _g=float(hydro.g), **efields)
    if torque_limit is not None:
        # the limit is imposed on the solve grid: check it between the points
        peak = res.peak_torque()
        if peak > torque_limit * (1 + 1e-12):
            over = peak / torque_limit - 1
            res = replace(res, success=res.success and over <= TORQUE_SLACK,
                          status=res.status + f"; between the grid points the peak torque is "
                          f"{peak:.6g} N m ({over:.1e} above the limit)")
    return res


def _failed(sc, wave, n, k, bound, lim, runs, rejected, one_way, hydro, pendulum):
    return CoupledSolution(
        success=False, status=f"no acceptable local maximum: {len(runs)} starts, {rejected} "
        "rejected as aliased", power=float("nan"), harmonics=n,
        theta_coefficients={"x": np.zeros(2 * n + 1), "winding": k, "omega": wave.omega},
        heave=np.zeros(n + 1, dtype=complex), energy_balance_residual=float("nan"),
        radiation_bound=float(bound), limit=float(lim),
        evidence={"starts": len(runs), "rejected_aliased": rejected, "maxima": []},
        one_way=bool(one_way), free_heave=np.asarray(sc.free_heave), omega=wave.omega,
        winding=k, _full_heave=np.zeros(1, dtype=complex), _pendulum=pendulum,
        _g=float(hydro.g))
