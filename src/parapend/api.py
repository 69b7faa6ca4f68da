"""Public entry points; they take the command line's parameter names (DESIGN.md section 4)."""

from __future__ import annotations

import logging
import math

import numpy as np

from . import excitation as exc_mod
from . import limits
from .errors import (
    ParameterError,
    SolverError,
    check_int,
    check_range,
)
from .model import peak_torque as _peak_torque
from .optimal.fourier import search_fourier, solve_fourier
from .optimal.limit import limit
from .power import uniform_power
from .results import OptimizeResult, ThresholdResult
from .trajectory import FourierMotion

__all__ = ["EXCITATIONS", "METHODS", "build_excitation", "damping_sweep", "harmonic_table",
           "motion_samples", "optimize", "spectrum_harmonics", "threshold"]

log = logging.getLogger(__name__)

EXCITATIONS = ("harmonic", "two-harmonic", "square", "fourier", "file")
MAX_HARMONICS = limits.MAX_HARMONICS
DEFAULT_DELTA = -0.3
DEFAULT_SQUARE_ALPHA = 0.001
_USES_DELTA = ("harmonic", "two-harmonic", "square")


def infer_excitation(excitation=None, *, delta=None, square_alpha=None, fourier=None,
                     file=None) -> str:
    """The excitation kind a set of parameters asks for; refuses contradictions.

    ``excitation=None`` means: ``"file"`` if ``file`` is given, ``"fourier"`` if ``fourier``
    is given, else ``"harmonic"``. A parameter the chosen excitation would ignore is refused
    (one line naming it), never silently dropped: ``file`` only with "file", ``fourier``
    only with "fourier", ``delta`` only with harmonic, two-harmonic and square,
    ``square_alpha`` only with "square".
    """
    if excitation is None:
        if file is not None and fourier is not None:
            raise ParameterError("file, fourier: expected one excitation, got both a file and "
                                 "Fourier terms")
        excitation = "file" if file is not None else "fourier" if fourier is not None \
            else "harmonic"
    if not isinstance(excitation, str) or excitation not in EXCITATIONS:
        raise ParameterError(f"excitation: expected one of {', '.join(EXCITATIONS)}, "
                             f"got {excitation!r:.60}")
    ignored = []
    if file is not None and excitation != "file":
        ignored.append("file")
    if fourier is not None and excitation != "fourier":
        ignored.append("fourier")
    if delta is not None and excitation not in _USES_DELTA:
        ignored.append("delta")
    if square_alpha is not None and excitation != "square":
        ignored.append("square-alpha")
    if ignored:
        raise ParameterError(f"{', '.join(ignored)}: not used by excitation {excitation!r}; "
                             "drop it or choose the excitation that uses it")
    return excitation


def build_excitation(excitation: str | None = None, *, omega: float = 1.8, delta=None,
                     square_alpha=None, fourier=None, file=None):
    """Build an :class:`~parapend.excitation.Excitation` from command-line style parameters.

    Parameters
    ----------
    excitation : {"harmonic", "two-harmonic", "square", "fourier", "file"} or None
        None infers it (see :func:`infer_excitation`): ``file`` alone means "file",
        ``fourier`` alone means "fourier", otherwise "harmonic".
    omega : float
        Forcing frequency in [1e-3, 1e3] (units ``sqrt(g/l)``, docs/limits-of-input.md).
    delta : float or None
        Amplitude for harmonic, two-harmonic (Eq. 23) and square (Eq. 26) excitations,
        ``|delta| <= 1e3`` (default -0.3); refused with the other excitations.
    square_alpha : float or None
        Smoothing width alpha of Eq. 26 (default 0.001); only with "square".
    fourier : str or sequence of (k, amp[, phase])
        Terms for ``excitation="fourier"``, e.g. ``"1:-0.3:0,3:0.1:0.5"``; integer
        ``1 <= k <= 1024``.
    file : path
        CSV with header ``tau,q`` for ``excitation="file"`` (UTF-8, at most 16384 rows).
    """
    if isinstance(excitation, exc_mod.Excitation):
        return excitation
    kind = infer_excitation(excitation, delta=delta, square_alpha=square_alpha,
                            fourier=fourier, file=file)
    delta = DEFAULT_DELTA if delta is None else delta
    if kind == "harmonic":
        return exc_mod.harmonic(delta, omega)
    if kind == "two-harmonic":
        return exc_mod.two_harmonic(delta, omega)
    if kind == "square":
        return exc_mod.square(delta, omega,
                              DEFAULT_SQUARE_ALPHA if square_alpha is None else square_alpha)
    if kind == "fourier":
        if fourier is None:
            raise ParameterError("fourier: expected terms 'k:amp[:phase],...' with "
                                 "excitation 'fourier'")
        terms = exc_mod.parse_fourier_terms(fourier) if isinstance(fourier, str) else fourier
        return exc_mod.fourier(terms, omega)
    if file is None:
        raise ParameterError("file: expected a CSV path with excitation 'file'")
    return exc_mod.from_csv(file, omega)


def _check_gamma(gamma) -> float:
    return check_range("gamma", gamma, 0.0, limits.MAX_GAMMA,
                       why="viscous damping, units sqrt(g/l); see docs/limits-of-input.md")


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
        "no_power": "converged, but no positive power exists: the damping is at or above the "
                    "threshold gamma* (every period-1 rotation costs energy; the power shown "
                    "is the smallest loss)",
    }[status]


def _no_power_message(exc) -> str:
    return ("no power can be extracted: the excitation is constant (q has no variation), "
            "so only the uniform rotation's damping loss remains")


METHODS = ("fourier", "bvp")


def optimize(*, omega: float = 1.8, delta=None, gamma: float = 0.0, harmonics: int = 24,
             excitation=None, square_alpha=None, fourier=None, file=None,
             method: str = "fourier", warm=None, winding: int = 1,
             throw: bool = False) -> OptimizeResult:
    """Optimal period-1 rotation for any excitation.

    Parameters mirror ``parapend optimize``. ``gamma`` is the viscous damping (>= 0).
    ``method="fourier"`` optimizes the truncated Fourier series of Eqs. 10-11 with
    ``harmonics`` = N terms; ``method="bvp"`` solves the penalized Euler-Lagrange equation
    (Eqs. 13, 22, 27, epsilon = 2 gamma, needs gamma > 0) and reports the N-harmonic Fourier
    projection of its motion as ``coefficients``. ``warm`` is an optional packed coefficient
    vector ``[a0, a_1..a_K, b_1..b_K]`` to start the Fourier method from (continuation). With
    ``throw=True`` a non-converged solve raises :class:`~parapend.errors.SolverError`;
    otherwise it is reported in ``success``/``status``.

    ``success`` means the solver converged. Status ``"no_power"`` (with ``success=True``)
    says that it converged but the optimum is ``P <= 0``: the damping is at or above the
    threshold gamma* (the power is then the smallest loss), or the excitation is constant
    (``delta = 0``: nothing to extract; the motion is the uniform rotation). Parameter ranges:
    docs/limits-of-input.md; ``harmonics <= 1024``.

    ``winding`` K >= 1: ``theta(t + 2 pi/omega) = theta(t) + 2 pi K`` (docs/seas.md); K = 1
    is the paper's period-1 rotation and computes exactly as without it. K > 1 with method
    "fourier" needs ``harmonics >= 2 K``; with method "bvp" the Euler-Lagrange BVP is solved
    with ``theta(t + Tp) = theta(t) + 2 pi K`` (docs/bvp.md) and ``coefficients`` are the
    N-harmonic projection of ``theta - K omega t``.
    """
    exc = build_excitation(excitation, omega=omega, delta=delta, square_alpha=square_alpha,
                           fourier=fourier, file=file)
    gamma = _check_gamma(gamma)
    n = check_int("harmonics", harmonics, 1, MAX_HARMONICS)
    winding = check_int("winding", winding, 1, MAX_HARMONICS // 2)
    if not isinstance(method, str) or method not in METHODS:
        raise ParameterError(f"method: expected one of {', '.join(METHODS)}, "
                             f"got {method!r:.60}")
    if winding != 1:
        return _optimize_winding(exc, gamma, n, method, warm, winding, throw)
    if warm is not None:
        try:
            warm = np.asarray(warm, dtype=float)
        except (TypeError, ValueError):
            raise ParameterError("warm: expected a vector [a0, a_1..a_K, b_1..b_K] of "
                                 "numbers") from None
        if warm.ndim != 1 or warm.size % 2 != 1 or not np.all(np.isfinite(warm)):
            raise ParameterError(f"warm: expected a finite vector [a0, a_1..a_K, b_1..b_K] "
                                 f"of odd length, got shape {warm.shape}")
    pu, _ = uniform_power(exc, gamma)
    lim = limit(exc)
    common = {"uniform_power": pu, "limit_power": lim.power, "harmonics": n, "gamma": gamma,
              "omega": exc.omega, "excitation": exc.describe(), "_excitation": exc}
    if lim.power <= 0:
        res = _constant_excitation(exc, gamma, n, method, common)
    elif method == "bvp":
        res = _optimize_bvp(exc, gamma, n, common)
    else:
        found = search_fourier(exc, n, gamma, warm=warm)
        best, runs, ev = found.best, found.runs, found.evidence
        motion = FourierMotion.from_vector(exc.omega, best.x)
        maxima = sorted({round(r.power, 12) for r in runs if r.status == "converged"},
                        reverse=True)
        status = "no_power" if best.status == "converged" and best.power <= 0 else best.status
        res = OptimizeResult(
            power=best.power,
            gain_over_uniform=(best.power / pu - 1.0) if pu > 0 else None,
            success=best.status == "converged",
            status=status,
            message=_message(status),
            iterations=best.iterations,
            coefficients=_coefficients(motion),
            peak_torque=_peak_torque(motion, exc, gamma),
            found_by=best.seed,
            local_maxima=maxima,
            gradient_norm=best.gradient_norm,
            strict_maximum=best.strict_maximum,
            quadrature_points=best.points,
            mean_square_speed=motion.mean_square_speed(),
            search=ev.strategy,
            candidate_patterns=_json_count(ev.candidate_patterns),
            extrema_per_period=int(exc.extrema.t.size),
            patterns_tried=ev.patterns_tried,
            polished=ev.polished,
            abandoned=ev.abandoned,
            second_power=ev.second_power,
            second_distance=ev.second_distance,
            upper_bound=ev.upper_bound,
            peak_torque_converged=_fourier_peak_converged(gamma),
            bound_gap=ev.upper_bound - best.power,
            _motion=motion,
            **common,
        )
    if throw and not res.success:
        raise SolverError(f"optimize: {res.message}")
    return res


def _optimize_winding(exc, gamma: float, n: int, method: str, warm, winding: int,
                      throw: bool) -> OptimizeResult:
    """``optimize`` with K turns per period (Fourier method, or the BVP)."""
    if method == "fourier" and n < 2 * winding:
        raise ParameterError(f"harmonics: expected at least 2 K = {2 * winding} harmonics "
                             f"for winding {winding}, got {n}")
    lim = limit(exc, winding)
    pu, _ = uniform_power(exc, gamma, winding)
    if lim.power <= 0:
        raise ParameterError("winding: the excitation is constant; nothing to extract")
    if method == "bvp":
        common = {"uniform_power": pu, "limit_power": lim.power, "harmonics": n,
                  "gamma": gamma, "omega": exc.omega, "excitation": exc.describe(),
                  "winding": winding, "_excitation": exc}
        res = _optimize_bvp(exc, gamma, n, common, winding)
        if throw and not res.success:
            raise SolverError(f"optimize: {res.message}")
        return res
    found = search_fourier(exc, n, gamma, warm=warm, winding=winding,
                           hessian="dense" if n <= 256 else "operator")
    best, runs, ev = found.best, found.runs, found.evidence
    motion = FourierMotion.from_vector(exc.omega, best.x, winding)
    maxima = sorted({round(r.power, 12) for r in runs if r.status == "converged"},
                    reverse=True)
    status = "no_power" if best.status == "converged" and best.power <= 0 else best.status
    res = OptimizeResult(
        power=best.power, uniform_power=pu, limit_power=lim.power,
        gain_over_uniform=(best.power / pu - 1.0) if pu > 0 else None,
        harmonics=n, gamma=gamma, omega=exc.omega, success=best.status == "converged",
        status=status, message=_message(status), iterations=best.iterations,
        coefficients=_coefficients(motion), peak_torque=_peak_torque(motion, exc, gamma),
        found_by=best.seed, local_maxima=maxima, gradient_norm=best.gradient_norm,
        strict_maximum=best.strict_maximum, quadrature_points=best.points,
        mean_square_speed=motion.mean_square_speed(), search=ev.strategy,
        candidate_patterns=_json_count(ev.candidate_patterns),
        extrema_per_period=int(exc.extrema.t.size), patterns_tried=ev.patterns_tried,
        polished=ev.polished, abandoned=ev.abandoned, second_power=ev.second_power,
        second_distance=ev.second_distance, upper_bound=ev.upper_bound,
        bound_gap=ev.upper_bound - best.power,
        peak_torque_converged=_fourier_peak_converged(gamma),
        excitation=exc.describe(), winding=winding, _motion=motion, _excitation=exc)
    if throw and not res.success:
        raise SolverError(f"optimize: {res.message}")
    return res


def _fourier_peak_converged(gamma: float) -> bool | None:
    """False at gamma = 0: the N-harmonic optimum approaches the limit motion, whose flips
    are instantaneous (Eqs. 19-21), and its peak torque grows like N^2 (164, 587, 2215 at
    N = 12, 24, 48 on the paper's case); None otherwise (not checked: at gamma > 0 the
    motion is smooth, 4.158945 at N = 24 and 48 at gamma = 0.03)."""
    return False if gamma == 0 else None


def _json_count(n: int) -> int | float:
    """An exact count while JSON readers keep it exact (< 2^53), else a float (inf, shown as
    null, past 1e308: a noisy record's C(2m, m - 1) can have a thousand digits)."""
    if n < 2**53:
        return int(n)
    try:
        return float(n)
    except OverflowError:
        return math.inf


def _second(best: float, values) -> float | None:
    """Best value distinct from ``best`` by more than 1e-9 (relative), or None."""
    others = [v for v in values if v is not None and math.isfinite(v)
              and v < best - 1e-9 * max(1.0, abs(best))]
    return max(others) if others else None


def _constant_excitation(exc, gamma: float, n: int, method: str, common: dict):
    """No variation of q: nothing to extract. The cheapest period-1 rotation is uniform,
    ``theta = omega t`` (``P = -gamma omega^2``), and its torque is what it costs to hold it."""
    motion = FourierMotion(exc.omega, 0.0, np.zeros(n), np.zeros(n))
    return OptimizeResult(
        power=-gamma * exc.omega**2,
        gain_over_uniform=None,
        success=True,
        status="no_power",
        message=_no_power_message(exc),
        iterations=0,
        coefficients=_coefficients(motion),
        peak_torque=_peak_torque(motion, exc, gamma),
        method=method,
        found_by="constant excitation",
        local_maxima=[],
        gradient_norm=0.0,
        strict_maximum=False,
        mean_square_speed=motion.mean_square_speed(),
        _motion=motion,
        **common,
    )


def _coefficients(motion: FourierMotion) -> dict:
    return {"a0": motion.a0, "a": motion.a.tolist(), "b": motion.b.tolist()}


def _optimize_bvp(exc, gamma: float, n: int, common: dict, winding: int = 1) -> OptimizeResult:
    from .optimal.bvp import solve_bvp_optimum
    from .trajectory import SampledMotion

    if gamma < limits.MIN_BVP_GAMMA:
        raise ParameterError(f"gamma: expected a number >= {limits.MIN_BVP_GAMMA:g} with method "
                             f"'bvp' (epsilon = 2 gamma; gamma = 0 has no smooth optimum and "
                             f"smaller gamma needs boundary layers finer than the mesh cap), "
                             f"got {gamma!r}")
    extrema = exc.extrema.t.size
    if extrema > limits.MAX_BVP_EXTREMA:
        raise ParameterError(
            f"method: 'bvp' resolves a boundary layer at every extremum of q, and this q has "
            f"{extrema} extrema per period (at most {limits.MAX_BVP_EXTREMA}); smooth the "
            "excitation or use method 'fourier'")
    # bounded work: each residual evaluation costs (mesh nodes) x (harmonics of q); past the
    # node cap the solver returns status "max_nodes" instead of refining further
    k = 1 if isinstance(exc, exc_mod.SquareExcitation) else exc.spectrum.size
    max_nodes = int(min(200_000, max(2_000, limits.MAX_BVP_WORK // k)))
    if winding == 1:
        sol = solve_bvp_optimum(exc, gamma, max_nodes=max_nodes)
    else:
        sol = solve_bvp_optimum(exc, gamma, max_nodes=max_nodes, winding=winding)
    motion = sol.motion()
    m = max(4096, 8 * n)
    t = exc.period * np.arange(m) / m
    theta = motion.theta(t)
    if winding != 1:  # SampledMotion removes one turn; K - 1 more leave theta - K omega t
        theta = theta - (winding - 1) * 2 * np.pi * np.arange(m) / m
    proj = SampledMotion(exc.omega, theta).to_fourier()
    proj = FourierMotion(exc.omega, proj.a0, proj.a[:n], proj.b[:n], winding)
    pu = common["uniform_power"]
    return OptimizeResult(
        power=sol.power,
        gain_over_uniform=(sol.power / pu - 1.0) if pu > 0 else None,
        success=sol.success,
        status="no_power" if sol.success and sol.power <= 0 else sol.status,
        message=_message("no_power") if sol.success and sol.power <= 0 else sol.message,
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
        residual_floor=sol.residual_floor,
        search="bvp-starts",
        patterns_tried=len(sol.candidates),
        polished=sum(v is not None and math.isfinite(v) for v in sol.candidates.values()),
        second_power=_second(sol.power, sol.candidates.values()),
        upper_bound=common["limit_power"] - gamma * (winding * exc.omega) ** 2,
        bound_gap=common["limit_power"] - gamma * (winding * exc.omega) ** 2 - sol.power,
        continuation_steps=sol.continuation_steps,
        _motion=motion,
        **common,
    )


def harmonic_table(harmonics=range(2, 65), *, gamma: float = 0.0, progress=None,
                   **excitation_args):
    """Optimal power against N, by continuation in N (each solve warm-started from the last).

    Because the warm start embeds the (N-1)-harmonic optimum, whose power is already reached,
    and the Newton iteration never lowers the power, the table is nondecreasing in N. The
    global search (docs/global.md) runs at the first and last N and at every power of two
    (variable ``global_search``); the rows between continue the last one, so they are
    lower bounds of their N's optimum.
    ``harmonics``: integers in [1, 128] (:data:`parapend.limits.MAX_TABLE_HARMONICS`; the
    continuation to 128 takes about 10 s, to 512 it took 11 minutes).
    Returns an ``xarray.Dataset`` over ``harmonics``; its attributes carry the excitation's
    band (``spectrum_harmonics``: a table that stops below it misses part of q) and the
    change of the last optimum when N is doubled once (``refinement_change``).
    """
    import xarray as xr

    unknown = set(excitation_args) - {"excitation", "omega", "delta", "square_alpha",
                                      "fourier", "file"}
    if unknown:
        raise ParameterError(f"{', '.join(sorted(unknown))}: not a parameter of "
                             "harmonic_table")
    exc = build_excitation(**excitation_args)
    gamma = _check_gamma(gamma)
    if isinstance(harmonics, (str, bytes)) or not hasattr(harmonics, "__iter__"):
        raise ParameterError(f"harmonics: expected a sequence of integers, got {harmonics!r:.60}")
    ns = [check_int("harmonics", n, 1, limits.MAX_TABLE_HARMONICS) for n in harmonics]
    if not ns:
        raise ParameterError("harmonics: expected at least one number of harmonics, got none")
    powers, status, found, searched = [], [], [], []
    warm = None
    for i, n in enumerate(ns):
        # the global search at the first and last N and at every power of two; the rows in
        # between continue the last one (a global search at each of 128 rows took minutes)
        full = warm is None or i == len(ns) - 1 or n & (n - 1) == 0
        best, _ = solve_fourier(exc, n, gamma, warm=warm,
                                seeds=("limit", "uniform") if full else ())
        warm = best.x
        searched.append(full)
        powers.append(best.power)
        status.append(best.status)
        found.append(best.seed)
        if progress is not None:
            progress(i + 1, len(ns))
    pu, _ = uniform_power(exc, gamma)
    change = _refinement_change(exc, ns[-1], [(gamma, powers[-1])]) if ns else math.nan
    return xr.Dataset(
        {"power": ("harmonics", np.array(powers)), "status": ("harmonics", status),
         "found_by": ("harmonics", found), "global_search": ("harmonics", searched)},
        coords={"harmonics": np.array(ns)},
        attrs={"uniform_power": pu, "limit_power": limit(exc).power, "gamma": gamma,
               "spectrum_harmonics": spectrum_harmonics(exc), "refinement_change": change,
               **_attrs(exc)},
    )


def spectrum_harmonics(exc, rel: float = 1e-6) -> int:
    """Highest harmonic ``k`` of ``q`` with ``|Q_k| >= rel * max |Q|`` (the band a
    resolution N must cover; the square wave's is large, its tail falls like 1/k)."""
    mag = np.abs(np.asarray(exc.spectrum)[1:])
    if mag.size == 0 or mag.max() == 0:
        return 0
    return int(np.nonzero(mag >= rel * mag.max())[0][-1]) + 1


def _resolution(exc, lowest: int = 8, highest: int = 256) -> int:
    """Smallest power of two >= the excitation's band, within [lowest, highest]."""
    k = max(spectrum_harmonics(exc), 1)
    return int(min(highest, max(lowest, 1 << math.ceil(math.log2(k)))))


def _refinement_change(exc, n: int, points) -> float:
    """Largest ``|P*(2N) - P*(N)|`` over ``(gamma, P*(N))`` pairs: the check by refinement."""
    out = 0.0
    for g, p in points:
        fine, _ = solve_fourier(exc, 2 * n, g)
        out = max(out, abs(fine.power - p))
    return out


def _threshold_at(exc, n: int, gamma0: float, warm, tol: float, maxiter: int):
    """Newton iteration on gamma for P*(gamma) = 0, with dP*/dgamma = -<theta'^2> (envelope).

    P* is a maximum of functions affine in gamma, hence convex and nonincreasing; started
    where P* >= 0, each Newton step stays left of the root and the iteration is monotone.
    The steps follow the current local maximum (warm starts); where they have converged the
    global search runs at that gamma, and if it finds a higher maximum (another branch) the
    iteration goes on from there, so the root is that of the global optimum.
    """
    g = gamma0
    p = kin = math.nan
    x = warm
    status = "max_iterations"
    it = 0
    full = warm is None
    while it < maxiter:
        it += 1
        best, _ = solve_fourier(exc, n, g, warm=x, seeds=("limit", "uniform") if full else ())
        full = False
        x = best.x
        p = best.power
        kin = FourierMotion.from_vector(exc.omega, x).mean_square_speed()
        if best.status != "converged":
            return g, p, kin, x, it, best.status
        step = p / kin
        if abs(step) <= tol * max(g, 1e-300):
            glob, _ = solve_fourier(exc, n, g, warm=x)
            if glob.power <= p + 1e-13 * max(1.0, abs(p)):
                status = "converged"
                g += step
                break
            x = glob.x  # a better branch: continue the Newton iteration from it
            continue
        g += step
        _check_threshold_in_range(exc, g)  # the iterates stay below gamma*
    return g, p, kin, x, it, status


def _check_threshold_in_range(exc, gamma: float) -> None:
    """Refuse an excitation whose threshold lies above the admissible damping (``gamma`` is
    a lower bound of gamma*: the uniform rotation's threshold, or a Newton iterate), naming
    the excitation the user gave, not the damping of an internal solve."""
    if gamma <= limits.MAX_GAMMA:
        return
    desc = ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}"
                     for k, v in exc.describe().items() if k != "excitation")
    raise ParameterError(
        f"excitation: expected a damping threshold within the damping range [0, "
        f"{limits.MAX_GAMMA:g}], got an excitation ({exc.describe()['excitation']}, {desc}) "
        f"that still extracts power at gamma = {gamma:.4g}; use a smaller amplitude or "
        "a larger omega")


def threshold(*, omega: float = 1.8, delta=None, harmonics=None, excitation=None,
              square_alpha=None, fourier=None, file=None, tol: float = 1e-12,
              throw: bool = False) -> ThresholdResult:
    """Damping threshold gamma* beyond which no power can be extracted (paper Fig. 6, 0.0856).

    ``harmonics=None`` starts from N covering the excitation's spectrum (a power of two,
    at least 8; :func:`spectrum_harmonics`) and doubles N until gamma* changes by less than
    1e-8 (relative), so every answer is checked by at least one refinement.
    A fixed ``harmonics`` is at most 512 (:data:`parapend.limits.MAX_THRESHOLD_HARMONICS`).
    """
    exc = build_excitation(excitation, omega=omega, delta=delta, square_alpha=square_alpha,
                           fourier=fourier, file=file)
    pu0, _ = uniform_power(exc, 0.0)
    gamma_u = pu0 / exc.omega**2  # where omega|Q1|/2 - gamma omega^2 = 0
    if limit(exc).power <= 0:
        return ThresholdResult(0.0, 0.0, 0.0, 0, exc.omega, True, "converged",
                               "constant excitation: no power can be extracted", 0,
                               excitation=exc.describe(), _excitation=exc)
    tol = check_range("tol", tol, 1e-15, 1e-3)
    _check_threshold_in_range(exc, gamma_u)
    if harmonics is not None:
        ns = [check_int("harmonics", harmonics, 1, limits.MAX_THRESHOLD_HARMONICS)]
    else:
        n0 = _resolution(exc)
        ns = [n0 * 2**j for j in range(6) if n0 * 2**j <= max(256, 2 * n0)]
    g_prev = None
    x = None
    total = 0
    g, p, kin, status, n = gamma_u, math.nan, math.nan, "max_iterations", ns[0]
    change = math.nan
    for n in ns:
        g, p, kin, x, it, status = _threshold_at(exc, n, g if g_prev else gamma_u, x, tol, 60)
        total += it
        if status != "converged":
            break
        if g_prev is not None:
            change = abs(g - g_prev)
            if change <= 1e-8 * g:
                break
        g_prev = g
    success = status == "converged"
    if success and len(ns) > 1 and not change <= 1e-8 * g:
        status, success = "unresolved", False
        msg = (f"gamma* still changes by {change:.2e} between N = {n // 2} and N = {n}; "
               "the excitation's spectrum needs more harmonics (pass harmonics=)")
    else:
        msg = ("converged: optimal power vanishes at this damping" if success
               else f"threshold iteration did not converge ({status})")
    res = ThresholdResult(g, gamma_u, p, n, exc.omega, success, status, msg, total,
                          mean_square_speed=kin, refinement_change=change,
                          excitation=exc.describe(), _excitation=exc)
    if throw and not success:
        raise SolverError(f"threshold: {msg}")
    return res


def damping_sweep(*, omega: float = 1.8, delta=None, harmonics: int | None = None,
                  excitation=None, square_alpha=None, fourier=None, file=None,
                  gamma_max=None, points: int = 41, progress=None):
    """Optimal and uniform power against damping (paper Fig. 6), with the threshold gamma*.

    ``gamma_max=None`` sweeps to 1.25 gamma*. ``harmonics=None`` takes N = 32 or, when the
    excitation's spectrum reaches higher, the power of two covering it (at most 256).
    Solves run from the largest damping down, each warm-started from the previous
    optimum, and each is a global search (docs/global.md). The resolution is checked by
    one refinement: the sweep's end points are solved again with 2N, and the largest
    change is the attribute ``refinement_change``. Returns an ``xarray.Dataset`` over
    ``gamma`` (the damping).
    Bounded work: ``harmonics <= 256``, ``2 <= points <= 1001`` and
    ``points * harmonics**2 <= 2**20`` (about a minute; docs/limits-of-input.md).
    """
    import xarray as xr

    exc = build_excitation(excitation, omega=omega, delta=delta, square_alpha=square_alpha,
                           fourier=fourier, file=file)
    n = (max(32, _resolution(exc, highest=limits.MAX_SWEEP_HARMONICS)) if harmonics is None
         else check_int("harmonics", harmonics, 1, limits.MAX_SWEEP_HARMONICS))
    npts = check_int("points", points, 2, limits.MAX_POINTS)
    if npts * n * n > limits.MAX_SWEEP_WORK:
        raise ParameterError(
            f"points: expected points * harmonics^2 <= {limits.MAX_SWEEP_WORK} (about a "
            f"minute of work), got {npts} * {n}^2 = {npts * n * n}; lower --points or "
            f"--harmonics (at N = {n}, at most {max(limits.MAX_SWEEP_WORK // (n * n), 0)} "
            "points)")
    if gamma_max is not None:
        gamma_max = check_range("gamma-max", gamma_max, 0.0, limits.MAX_GAMMA)
        if gamma_max <= 0:
            raise ParameterError(f"gamma-max: expected a number > 0, got {gamma_max!r}")
    thr = threshold(excitation=exc)
    if gamma_max is None and thr.damping_threshold <= 0:
        raise ParameterError("gamma-max: the excitation is constant (no variation of q), so "
                             "nothing can be extracted at any damping and gamma* = 0; give "
                             "--gamma-max to sweep the losses anyway")
    gmax = 1.25 * thr.damping_threshold if gamma_max is None else gamma_max
    gammas = np.linspace(0.0, gmax, npts)
    power = np.empty(npts)
    kin = np.empty(npts)
    torque = np.empty(npts)
    status = []
    warm = None
    constant = thr.damping_threshold <= 0  # q constant: only the uniform rotation's loss
    for i in range(npts - 1, -1, -1):
        if constant:
            motion = FourierMotion(exc.omega, 0.0, np.zeros(n), np.zeros(n))
            power[i] = 0.0 - float(gammas[i]) * exc.omega**2
            st = "no_power"
        else:
            # the global search at every damping: continuing the previous optimum alone
            # followed a lower branch by up to 8.5e-3 on a 12-extremum excitation
            best, _ = solve_fourier(exc, n, float(gammas[i]), warm=warm)
            warm = best.x
            motion = FourierMotion.from_vector(exc.omega, best.x)
            power[i] = best.power
            st = best.status
        kin[i] = motion.mean_square_speed()
        torque[i] = _peak_torque(motion, exc, float(gammas[i]))
        status.append(st)
        if progress is not None:
            progress(npts - i, npts)
    status.reverse()
    change = 0.0 if constant else _refinement_change(exc, n, [(float(gammas[0]), power[0]),
                                                              (float(gammas[-1]), power[-1])])
    pu = np.array([uniform_power(exc, float(g))[0] for g in gammas])
    return xr.Dataset(
        {"power": ("gamma", power), "uniform_power": ("gamma", pu),
         "mean_square_speed": ("gamma", kin), "peak_torque": ("gamma", torque),
         "status": ("gamma", status)},
        coords={"gamma": gammas},
        attrs={"damping_threshold": thr.damping_threshold,
               "uniform_threshold": thr.uniform_threshold, "limit_power": limit(exc).power,
               "harmonics": n, "refinement_change": change,
               "peak_torque_note": "at gamma = 0 the peak torque is that of the N-harmonic "
                                   "motion and grows like N^2 (the limit motion flips "
                                   "instantly); at gamma > 0 it converges in N",
               **_attrs(exc)},
    )


def motion_samples(result, points: int = 1000) -> dict:
    """One period of an optimum on ``points`` uniform times: t, tau, theta, theta_dot, torque
    (:meth:`parapend.results.OptimizeResult.samples` under the older names).

    ``torque`` is Eq. 14 solved for T with the result's damping.
    """
    s = result.samples(points)
    return {"t": s["time"], "tau": s["phase"], "theta": s["theta"],
            "theta_dot": s["theta_dot"], "torque": s["torque"]}
