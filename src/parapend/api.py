"""Public entry points; they take the command line's parameter names (DESIGN.md section 4)."""

from __future__ import annotations

import logging
import math

import numpy as np

from . import excitation as exc_mod
from .errors import (
    ParameterError,
    SolverError,
    check_finite,
    check_int,
    check_nonnegative,
    check_positive,
)
from .model import peak_torque as _peak_torque
from .optimal.fourier import solve_fourier
from .optimal.limit import limit
from .power import uniform_power
from .results import OptimizeResult, ThresholdResult
from .trajectory import FourierMotion

__all__ = ["EXCITATIONS", "METHODS", "build_excitation", "damping_sweep", "harmonic_table",
           "motion_samples", "optimize", "threshold"]

log = logging.getLogger(__name__)

EXCITATIONS = ("harmonic", "two-harmonic", "square", "fourier", "file")
MAX_HARMONICS = 4096


def build_excitation(excitation: str = "harmonic", *, omega: float = 1.8, delta: float = -0.3,
                     square_alpha: float = 0.001, fourier=None, file=None):
    """Build an :class:`~parapend.excitation.Excitation` from command-line style parameters.

    Parameters
    ----------
    excitation : {"harmonic", "two-harmonic", "square", "fourier", "file"}
    omega : float
        Forcing frequency (> 0).
    delta : float
        Amplitude for harmonic, two-harmonic (Eq. 23) and square (Eq. 26) excitations.
    square_alpha : float
        Smoothing width alpha of Eq. 26.
    fourier : str or sequence of (k, amp, phase)
        Terms for ``excitation="fourier"``, e.g. ``"1:-0.3:0,3:0.1:0.5"``.
    file : path
        CSV with header ``tau,q`` for ``excitation="file"``.
    """
    if isinstance(excitation, exc_mod.Excitation):
        return excitation
    omega = check_positive("omega", omega)
    delta = check_finite("delta", delta)
    if excitation == "harmonic":
        return exc_mod.harmonic(delta, omega)
    if excitation == "two-harmonic":
        return exc_mod.two_harmonic(delta, omega)
    if excitation == "square":
        return exc_mod.square(delta, omega, check_positive("square-alpha", square_alpha))
    if excitation == "fourier":
        if fourier is None:
            raise ParameterError("fourier: expected terms 'k:amp[:phase],...' with "
                                 "excitation 'fourier'")
        terms = exc_mod.parse_fourier_terms(fourier) if isinstance(fourier, str) else fourier
        return exc_mod.fourier(terms, omega)
    if excitation == "file":
        if file is None:
            raise ParameterError("file: expected a CSV path with excitation 'file'")
        return exc_mod.from_csv(file, omega)
    raise ParameterError(f"excitation: expected one of {', '.join(EXCITATIONS)}, "
                         f"got {excitation!r}")


def _attrs(exc) -> dict:
    """Excitation parameters as Dataset attributes (NetCDF-safe: numbers and strings)."""
    import json

    return {k: v if isinstance(v, (int, float, str)) else json.dumps(v)
            for k, v in exc.describe().items()}


def _message(status: str) -> str:
    return {
        "converged": "converged: gradient below tolerance at a local maximum",
        "stalled": "stalled: no step increases the power, but the gradient is not small; "
                   "try more harmonics or a different damping",
        "max_iterations": "maximum number of Newton iterations reached",
        "nonfinite": "non-finite power encountered",
    }[status]


METHODS = ("fourier", "bvp")


def optimize(*, omega: float = 1.8, delta: float = -0.3, gamma: float = 0.0, harmonics: int = 24,
             excitation="harmonic", square_alpha: float = 0.001, fourier=None, file=None,
             method: str = "fourier", warm=None, throw: bool = False) -> OptimizeResult:
    """Optimal period-1 rotation for any excitation.

    Parameters mirror ``parapend optimize``. ``gamma`` is the viscous damping (>= 0).
    ``method="fourier"`` optimizes the truncated Fourier series of Eqs. 10-11 with
    ``harmonics`` = N terms; ``method="bvp"`` solves the penalized Euler-Lagrange equation
    (Eqs. 13, 22, 27, epsilon = 2 gamma, needs gamma > 0) and reports the N-harmonic Fourier
    projection of its motion as ``coefficients``. ``warm`` is an optional packed coefficient
    vector ``[a0, a_1..a_K, b_1..b_K]`` to start the Fourier method from (continuation). With
    ``throw=True`` a non-converged solve raises :class:`~parapend.errors.SolverError`;
    otherwise it is reported in ``success``/``status``.
    """
    exc = build_excitation(excitation, omega=omega, delta=delta, square_alpha=square_alpha,
                           fourier=fourier, file=file)
    gamma = check_nonnegative("gamma", gamma)
    n = check_int("harmonics", harmonics, 1, MAX_HARMONICS)
    if method not in METHODS:
        raise ParameterError(f"method: expected one of {', '.join(METHODS)}, got {method!r}")
    pu, _ = uniform_power(exc, gamma)
    lim = limit(exc)
    common = {"uniform_power": pu, "limit_power": lim.power, "harmonics": n, "gamma": gamma,
              "omega": exc.omega, "excitation": exc.describe(), "_excitation": exc}
    if method == "bvp":
        res = _optimize_bvp(exc, gamma, n, common)
    else:
        best, runs = solve_fourier(exc, n, gamma, warm=warm)
        motion = FourierMotion.from_vector(exc.omega, best.x)
        maxima = sorted({round(r.power, 12) for r in runs if r.status == "converged"},
                        reverse=True)
        res = OptimizeResult(
            power=best.power,
            gain_over_uniform=(best.power / pu - 1.0) if pu > 0 else None,
            success=best.status == "converged",
            status=best.status,
            message=_message(best.status),
            iterations=best.iterations,
            coefficients=_coefficients(motion),
            peak_torque=_peak_torque(motion, exc, gamma),
            found_by=best.seed,
            local_maxima=maxima,
            gradient_norm=best.gradient_norm,
            strict_maximum=best.strict_maximum,
            quadrature_points=best.points,
            mean_square_speed=motion.mean_square_speed(),
            _motion=motion,
            **common,
        )
    if throw and not res.success:
        raise SolverError(f"optimize: {res.message}")
    return res


def _coefficients(motion: FourierMotion) -> dict:
    return {"a0": motion.a0, "a": motion.a.tolist(), "b": motion.b.tolist()}


def _optimize_bvp(exc, gamma: float, n: int, common: dict) -> OptimizeResult:
    from .optimal.bvp import solve_bvp_optimum
    from .trajectory import SampledMotion

    if gamma <= 0:
        raise ParameterError("gamma: expected a number > 0 with method 'bvp' (epsilon = 2 "
                             "gamma; gamma = 0 has no smooth optimum), got 0")
    sol = solve_bvp_optimum(exc, gamma)
    motion = sol.motion()
    m = max(4096, 8 * n)
    t = exc.period * np.arange(m) / m
    proj = SampledMotion(exc.omega, motion.theta(t)).to_fourier()
    proj = FourierMotion(exc.omega, proj.a0, proj.a[:n], proj.b[:n])
    pu = common["uniform_power"]
    return OptimizeResult(
        power=sol.power,
        gain_over_uniform=(sol.power / pu - 1.0) if pu > 0 else None,
        success=sol.success,
        status=sol.status,
        message=sol.message,
        iterations=sol.iterations,
        coefficients=_coefficients(proj),
        peak_torque=_peak_torque(motion, exc, gamma),
        method="bvp",
        found_by=sol.found_by,
        local_maxima=sorted({round(v, 12) for v in sol.candidates.values()
                             if v is not None and math.isfinite(v)}, reverse=True),
        strict_maximum=sol.strict_maximum,
        mean_square_speed=sol.mean_square_speed,
        mesh_nodes=sol.mesh_nodes,
        max_residual=sol.max_residual,
        continuation_steps=sol.continuation_steps,
        _motion=motion,
        **common,
    )


def harmonic_table(harmonics=range(2, 65), *, gamma: float = 0.0, progress=None,
                   **excitation_args):
    """Optimal power against N, by continuation in N (each solve warm-started from the last).

    Because the warm start embeds the (N-1)-harmonic optimum, whose power is already reached,
    and the Newton iteration never lowers the power, the table is nondecreasing in N.
    Returns an ``xarray.Dataset`` over ``harmonics``.
    """
    import xarray as xr

    exc = build_excitation(**excitation_args)
    gamma = check_nonnegative("gamma", gamma)
    ns = [check_int("harmonics", n, 1, MAX_HARMONICS) for n in harmonics]
    powers, status, found = [], [], []
    warm = None
    for i, n in enumerate(ns):
        best, _ = solve_fourier(exc, n, gamma, warm=warm)
        warm = best.x
        powers.append(best.power)
        status.append(best.status)
        found.append(best.seed)
        if progress is not None:
            progress(i + 1, len(ns))
    pu, _ = uniform_power(exc, gamma)
    return xr.Dataset(
        {"power": ("harmonics", np.array(powers)), "status": ("harmonics", status),
         "found_by": ("harmonics", found)},
        coords={"harmonics": np.array(ns)},
        attrs={"uniform_power": pu, "limit_power": limit(exc).power, "gamma": gamma,
               **_attrs(exc)},
    )


def _threshold_at(exc, n: int, gamma0: float, warm, tol: float, maxiter: int):
    """Newton iteration on gamma for P*(gamma) = 0, with dP*/dgamma = -<theta'^2> (envelope).

    P* is a maximum of functions affine in gamma, hence convex and nonincreasing; started
    where P* >= 0, each Newton step stays left of the root and the iteration is monotone.
    """
    g = gamma0
    p = kin = math.nan
    x = warm
    status = "max_iterations"
    for it in range(1, maxiter + 1):
        best, _ = solve_fourier(exc, n, g, warm=x)
        x = best.x
        p = best.power
        kin = FourierMotion.from_vector(exc.omega, x).mean_square_speed()
        if best.status != "converged":
            return g, p, kin, x, it, best.status
        step = p / kin
        g += step
        if abs(step) <= tol * max(g, 1e-300):
            status = "converged"
            break
    return g, p, kin, x, it, status


def threshold(*, omega: float = 1.8, delta: float = -0.3, harmonics=None, excitation="harmonic",
              square_alpha: float = 0.001, fourier=None, file=None, tol: float = 1e-12,
              throw: bool = False) -> ThresholdResult:
    """Damping threshold gamma* beyond which no power can be extracted (paper Fig. 6, 0.0856).

    ``harmonics=None`` doubles N from 8 until gamma* changes by less than 1e-10 (relative).
    """
    exc = build_excitation(excitation, omega=omega, delta=delta, square_alpha=square_alpha,
                           fourier=fourier, file=file)
    pu0, _ = uniform_power(exc, 0.0)
    gamma_u = pu0 / exc.omega**2  # where omega|Q1|/2 - gamma omega^2 = 0
    if limit(exc).power <= 0:
        return ThresholdResult(0.0, 0.0, 0.0, 0, exc.omega, True, "converged",
                               "constant excitation: no power can be extracted", 0,
                               excitation=exc.describe())
    ns = [check_int("harmonics", harmonics, 1, MAX_HARMONICS)] if harmonics is not None \
        else [8, 16, 32, 64, 128, 256]
    g_prev = None
    x = None
    total = 0
    g, p, kin, status, n = gamma_u, math.nan, math.nan, "max_iterations", ns[0]
    for n in ns:
        g, p, kin, x, it, status = _threshold_at(exc, n, g if g_prev else gamma_u, x, tol, 60)
        total += it
        if status != "converged":
            break
        if g_prev is not None and abs(g - g_prev) <= 1e-10 * g:
            break
        g_prev = g
    success = status == "converged"
    msg = ("converged: optimal power vanishes at this damping" if success
           else f"threshold iteration did not converge ({status})")
    res = ThresholdResult(g, gamma_u, p, n, exc.omega, success, status, msg, total,
                          mean_square_speed=kin, excitation=exc.describe())
    if throw and not success:
        raise SolverError(f"threshold: {msg}")
    return res


def damping_sweep(*, omega: float = 1.8, delta: float = -0.3, harmonics: int = 32,
                  excitation="harmonic", square_alpha: float = 0.001, fourier=None, file=None,
                  gamma_max=None, points: int = 41, progress=None):
    """Optimal and uniform power against damping (paper Fig. 6), with the threshold gamma*.

    ``gamma_max=None`` sweeps to 1.25 gamma*. Solves run from the largest damping down,
    each warm-started from the previous optimum. Returns an ``xarray.Dataset`` over
    ``gamma`` (the damping).
    """
    import xarray as xr

    exc = build_excitation(excitation, omega=omega, delta=delta, square_alpha=square_alpha,
                           fourier=fourier, file=file)
    n = check_int("harmonics", harmonics, 1, MAX_HARMONICS)
    npts = check_int("points", points, 2, 100000)
    thr = threshold(excitation=exc)
    gmax = 1.25 * thr.damping_threshold if gamma_max is None else check_positive("gamma-max",
                                                                                 gamma_max)
    gammas = np.linspace(0.0, gmax, npts)
    power = np.empty(npts)
    kin = np.empty(npts)
    torque = np.empty(npts)
    status = []
    warm = None
    for i in range(npts - 1, -1, -1):
        best, _ = solve_fourier(exc, n, float(gammas[i]), warm=warm)
        warm = best.x
        motion = FourierMotion.from_vector(exc.omega, best.x)
        power[i] = best.power
        kin[i] = motion.mean_square_speed()
        torque[i] = _peak_torque(motion, exc, float(gammas[i]))
        status.append(best.status)
        if progress is not None:
            progress(npts - i, npts)
    status.reverse()
    pu = np.array([uniform_power(exc, float(g))[0] for g in gammas])
    return xr.Dataset(
        {"power": ("gamma", power), "uniform_power": ("gamma", pu),
         "mean_square_speed": ("gamma", kin), "peak_torque": ("gamma", torque),
         "status": ("gamma", status)},
        coords={"gamma": gammas},
        attrs={"damping_threshold": thr.damping_threshold,
               "uniform_threshold": thr.uniform_threshold, "limit_power": limit(exc).power,
               "harmonics": n, **_attrs(exc)},
    )


def motion_samples(result, points: int = 1000) -> dict:
    """One period of an optimum on ``points`` uniform times: t, tau, theta, theta_dot, torque.

    ``torque`` is Eq. 14 solved for T with the result's damping.
    """
    from .model import torque

    npts = check_int("points", points, 2)
    exc = result._excitation
    motion = result.motion
    t = exc.period * np.arange(npts) / npts
    return {"t": t, "tau": t / exc.period, "theta": motion.theta(t),
            "theta_dot": motion.theta_dot(t), "torque": torque(motion, exc, result.gamma, t)}
