"""Periodic orbits of paper Eq. 1 by shooting, their Floquet multipliers, and continuation.

Conventions are those of paper Eq. 1 (``phi`` from the hanging position, excitation ``p``);
internally the project model ``theta = phi + pi`` is integrated (see
:mod:`parapend.dynamics.simulate`).

Shooting. A period-k orbit with winding ``r`` (net turns per ``k`` forcing periods; the
period-1 rotation of paper Eqs. 3-4 is ``k = 1, r = +-1``) is a zero of::

    F(x0) = Phi_{kT}(x0) - x0 - (2*pi*r, 0),    x0 = (phi(t0), phi'(t0)),  T = 2*pi/omega

where ``Phi`` is the flow of Eq. 1 from ``t0`` to ``t0 + k*T``. Newton's method uses the
exact Jacobian ``M - I``, with ``M`` the monodromy matrix from the variational equations
``d/dt dx = J(t) dx``, ``J = [[0, 1], [-(1 + p cos(omega t)) cos(phi), -gamma]]``,
integrated with the orbit by DOP853 (``rtol = 1e-11``).

Floquet multipliers are the eigenvalues of ``M``; the orbit is asymptotically stable when
both have modulus < 1. Liouville's formula gives ``det M = exp(-gamma*k*T)`` exactly
(``tr J = -gamma``): a closed-form check of every computed monodromy matrix.

Continuation (:func:`continue_rotation`). Pseudo-arclength continuation of the period-1
rotation in ``p`` at fixed ``omega``, with the extra variational equation for
``d Phi/dp``. Along the branch, sign changes of ``det(M - I)`` (a multiplier through +1:
fold, where the rotation is born, curve J of paper Fig. 2 left) and of ``det(M + I)``
(a multiplier through -1: period doubling, where the rotation loses (curve G) or regains
(curve E) stability) are located by secant refinement. :func:`rotation_boundaries`
repeats this over a list of ``omega`` to trace J, G and E in the ``(omega, p)`` plane.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike
from scipy.integrate import solve_ivp

from ..errors import ParameterError, SolverError, check_finite, check_int, check_positive
from .simulate import _check_params

__all__ = [
    "Bifurcation",
    "Branch",
    "PeriodicOrbit",
    "continue_rotation",
    "floquet",
    "periodic_orbit",
    "RotationBoundaries",
    "rotation_boundaries",
    "rotation_boundaries_at",
]

_TWO_PI = 2 * math.pi


def _wrap(x: float) -> float:
    return float(x - _TWO_PI * math.floor((x + math.pi) / _TWO_PI))


def _flow(x0, gamma, p, omega, t0, duration, *, dp: bool = False, rtol=1e-11, atol=1e-12):
    """Integrate Eq. 1 with its variational equations (theta convention inside).

    Returns the final state (phi, phi'), the monodromy matrix, d(state)/dp (if ``dp``)
    and the number of right-hand-side evaluations.
    """

    def f(t, y):
        th, v = y[0], y[1]
        c = math.cos(omega * t)
        a = 1.0 + p * c
        s, co = math.sin(th), math.cos(th)
        out = np.empty_like(y)
        out[0] = v
        out[1] = a * s - gamma * v
        # variational: J = [[0, 1], [a cos(theta), -gamma]] (theta convention; same matrix
        # as Eq. 1's since cos(theta) = -cos(phi))
        j21 = a * co
        out[2] = y[4]
        out[3] = y[5]
        out[4] = j21 * y[2] - gamma * y[4]
        out[5] = j21 * y[3] - gamma * y[5]
        if dp:
            out[6] = y[7]
            out[7] = j21 * y[6] - gamma * y[7] + c * s
        return out

    y0 = np.zeros(8 if dp else 6)
    y0[0] = x0[0] + math.pi
    y0[1] = x0[1]
    y0[2] = 1.0   # Phi = [[y2, y3], [y4, y5]]
    y0[5] = 1.0
    r = solve_ivp(f, (t0, t0 + duration), y0, method="DOP853", rtol=rtol, atol=atol)
    if not r.success:
        raise SolverError(f"shooting: integration failed: {r.message}")
    y = r.y[:, -1]
    state = np.array([y[0] - math.pi, y[1]])
    mono = np.array([[y[2], y[3]], [y[4], y[5]]])
    sens = np.array([y[6], y[7]]) if dp else None
    return state, mono, sens, int(r.nfev)


@dataclass(frozen=True, eq=False)
class PeriodicOrbit:
    """A period-k orbit of paper Eq. 1 found by shooting.

    Attributes
    ----------
    phi0, dphi0 : float
        Point on the orbit at ``t0`` (``phi`` from hanging, wrapped to ``[-pi, pi)``).
    period : int
        ``k``, forcing periods.
    winding : int
        Net turns of ``phi`` per ``k`` periods (+ anticlockwise, ``phi`` increasing).
    duration : float
        ``k*2*pi/omega``.
    multipliers : ndarray of complex, shape (2,)
        Floquet multipliers (eigenvalues of the monodromy matrix), sorted by decreasing
        modulus.
    monodromy : ndarray, shape (2, 2)
        ``d x(t0 + k T)/d x(t0)`` in ``(phi, phi')``.
    stable : bool
        ``max |multiplier| < 1``.
    success : bool
    status : str
        ``"converged"``, ``"max_iterations"`` or ``"diverged"``.
    message : str
    iterations : int
        Newton iterations.
    residual : float
        ``max |F(x0)|`` at the returned point.
    gamma, p, omega, t0 : float
    nfev : int
        Right-hand-side evaluations in total.
    """

    phi0: float
    dphi0: float
    period: int
    winding: int
    duration: float
    multipliers: np.ndarray
    monodromy: np.ndarray
    stable: bool
    success: bool
    status: str
    message: str
    iterations: int
    residual: float
    gamma: float
    p: float
    omega: float
    t0: float = 0.0
    nfev: int = 0

    @property
    def liouville_error(self) -> float:
        """``|det M - exp(-gamma k T)|`` (zero in exact arithmetic, Liouville's formula)."""
        return abs(float(np.linalg.det(self.monodromy)) - math.exp(-self.gamma * self.duration))

    def to_dict(self) -> dict:
        return {"phi0": self.phi0, "dphi0": self.dphi0, "period": self.period,
                "winding": self.winding, "duration": self.duration,
                "multipliers_real": [float(z.real) for z in self.multipliers],
                "multipliers_imag": [float(z.imag) for z in self.multipliers],
                "stable": self.stable, "success": self.success, "status": self.status,
                "message": self.message, "iterations": self.iterations,
                "residual": self.residual, "gamma": self.gamma, "p": self.p,
                "omega": self.omega, "t0": self.t0}


def _sorted_eigs(m: np.ndarray) -> np.ndarray:
    ev = np.linalg.eigvals(m).astype(complex)
    return ev[np.argsort(-np.abs(ev), kind="stable")]


def floquet(phi0: float, dphi0: float, gamma: float, p: float, omega: float, *,
            period: int = 1, t0: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Monodromy matrix and Floquet multipliers at a point of a period-k orbit of Eq. 1.

    Parameters
    ----------
    phi0, dphi0 : float
        Point at ``t0`` (``phi`` from hanging); for a true periodic orbit see
        :func:`periodic_orbit`.
    gamma, p, omega : float
    period : int
        ``k``: the matrix maps perturbations over ``k*2*pi/omega``.
    t0 : float

    Returns
    -------
    multipliers : ndarray of complex, shape (2,)
        Sorted by decreasing modulus.
    monodromy : ndarray, shape (2, 2)
    """
    gamma, p, omega = _check_params(gamma, p, omega)
    k = check_int("period", period, 1)
    x0 = np.array([check_finite("phi0", phi0), check_finite("dphi0", dphi0)])
    _, mono, _, _ = _flow(x0, gamma, p, omega, check_finite("t0", t0), k * _TWO_PI / omega)
    return _sorted_eigs(mono), mono


def _guess_rotation(gamma, p, omega, t0, k, r, n=24):
    """Best of ``n`` starts on the uniform rotation ``phi' = r*omega/k`` (smallest residual)."""
    best, best_res = None, math.inf
    for phi in -math.pi + _TWO_PI * np.arange(n) / n:
        x0 = np.array([phi, r * omega / k])
        try:
            xe, _, _, _ = _flow(x0, gamma, p, omega, t0, k * _TWO_PI / omega, rtol=1e-6,
                                atol=1e-8)
        except SolverError:
            continue
        res = float(np.max(np.abs(xe - x0 - np.array([_TWO_PI * r, 0.0]))))
        if res < best_res:
            best, best_res = x0, res
    return best


def periodic_orbit(gamma: float, p: float, omega: float, *, phi0: float | None = None,
                   dphi0: float | None = None, period: int = 1, winding: int = 1,
                   t0: float = 0.0, tol: float = 1e-10, maxiter: int = 40,
                   throw: bool = False) -> PeriodicOrbit:
    """Periodic orbit of paper Eq. 1 by Newton shooting on the stroboscopic map.

    Parameters
    ----------
    gamma, p, omega : float
        Damping (>= 0), excitation strength and frequency (> 0) of Eq. 1.
    phi0, dphi0 : float, optional
        Initial guess at ``t0``. Without one (period-1 rotations and other ``winding != 0``
        orbits only), the best of 24 starts ``phi0`` on ``[-pi, pi)`` with the uniform speed
        ``dphi0 = winding*omega/period`` is used.
    period : int
        ``k`` (forcing periods).
    winding : int
        Net turns per ``k`` periods: ``+1`` (anticlockwise) or ``-1`` (clockwise) for the
        period-1 rotation of paper Eqs. 3-4; 0 for an oscillation.
    t0 : float
        Phase of the Poincare section.
    tol : float
        Convergence: ``max |F| < tol``.
    maxiter : int
        Newton iterations at most.
    throw : bool
        Raise :class:`parapend.SolverError` if not converged (default: report it in
        ``status``).

    Returns
    -------
    PeriodicOrbit
    """
    gamma, p, omega = _check_params(gamma, p, omega)
    k = check_int("period", period, 1)
    try:
        r = int(winding)
    except (TypeError, ValueError):
        raise ParameterError(f"winding: expected an integer, got {winding!r}") from None
    if r != winding:
        raise ParameterError(f"winding: expected an integer, got {winding!r}")
    t0 = check_finite("t0", t0)
    tol = check_positive("tol", tol)
    maxiter = check_int("maxiter", maxiter, 1)
    duration = k * _TWO_PI / omega
    if phi0 is None or dphi0 is None:
        if phi0 is not None or dphi0 is not None:
            raise ParameterError("phi0, dphi0: give both initial guesses or neither")
        if r == 0:
            raise ParameterError("phi0, dphi0: an initial guess is needed for an "
                                 "oscillation (winding = 0)")
        x = _guess_rotation(gamma, p, omega, t0, k, r)
        if x is None:
            raise SolverError("shooting: no start could be integrated")
    else:
        x = np.array([check_finite("phi0", phi0), check_finite("dphi0", dphi0)])
    shift = np.array([_TWO_PI * r, 0.0])
    nfev = 0
    status, it, res = "max_iterations", 0, math.inf
    mono = np.eye(2)
    for it in range(1, maxiter + 1):  # noqa: B007 (it is reported after the loop)
        xe, mono, _, nf = _flow(x, gamma, p, omega, t0, duration)
        nfev += nf
        fx = xe - x - shift
        res = float(np.max(np.abs(fx)))
        if not math.isfinite(res):
            status = "diverged"
            break
        if res < tol:
            status = "converged"
            break
        try:
            dx = np.linalg.solve(mono - np.eye(2), -fx)
        except np.linalg.LinAlgError:
            status = "diverged"
            break
        step = float(np.max(np.abs(dx)))
        if step > 0.5:                      # damp long steps (Newton from far away)
            dx *= 0.5 / step
        x = x + dx
    else:
        it = maxiter
    if status == "converged":
        # the monodromy at the converged point (the loop broke before updating x)
        message = f"converged in {it} Newton iterations, max |F| = {res:.2e}"
    elif status == "diverged":
        message = "Newton iteration diverged (singular Jacobian or non-finite residual)"
    else:
        message = f"no convergence in {maxiter} iterations, max |F| = {res:.2e}"
    if throw and status != "converged":
        raise SolverError(f"shooting: {message}")
    mult = _sorted_eigs(mono)
    return PeriodicOrbit(
        phi0=_wrap(float(x[0])), dphi0=float(x[1]), period=k, winding=r, duration=duration,
        multipliers=mult, monodromy=mono, stable=bool(np.max(np.abs(mult)) < 1.0),
        success=status == "converged", status=status, message=message, iterations=it,
        residual=res, gamma=gamma, p=p, omega=omega, t0=t0, nfev=nfev)


# --- continuation ------------------------------------------------------------------------
@dataclass(frozen=True)
class Bifurcation:
    """A bifurcation of the period-1 rotation located along a branch.

    Attributes
    ----------
    kind : str
        ``"fold"`` (multiplier +1; curve J of paper Fig. 2 left) or ``"period_doubling"``
        (multiplier -1; curve G where stability is lost with increasing p, E where it is
        regained).
    label : str
        ``"J"``, ``"G"`` or ``"E"`` (``"PD"`` for further period doublings).
    p, omega : float
    phi0, dphi0 : float
        Point of the orbit at ``t0``.
    """

    kind: str
    label: str
    p: float
    omega: float
    phi0: float
    dphi0: float


@dataclass(frozen=True, eq=False)
class Branch:
    """Period-1 rotation branch at fixed ``omega`` (see :func:`continue_rotation`).

    Attributes
    ----------
    data : xarray.Dataset
        Along dimension ``s`` (continuation step): ``p``, ``phi0``, ``dphi0``,
        ``mult_abs`` (s, 2), ``mult_real``, ``mult_imag``, ``stable``.
    bifurcations : tuple of Bifurcation
    success : bool
    status, message : str
    """

    data: xr.Dataset
    bifurcations: tuple
    success: bool
    status: str
    message: str
    extra: dict = field(default_factory=dict)


def _residual(X, gamma, omega, t0, r, dp=True):
    x0 = X[:2]
    xe, mono, sens, nf = _flow(x0, gamma, X[2], omega, t0, _TWO_PI / omega, dp=dp)
    fx = xe - x0 - np.array([_TWO_PI * r, 0.0])
    jac = np.hstack((mono - np.eye(2), sens[:, None]))
    return fx, jac, mono


def _tangent(jac, prev=None):
    """Unit null vector of the 2x3 Jacobian, oriented like ``prev`` (or with dp > 0)."""
    _, _, vt = np.linalg.svd(jac)
    t = vt[-1]
    ref = prev if prev is not None else np.array([0.0, 0.0, 1.0])
    return t if np.dot(t, ref) >= 0 else -t


def _tests(mono):
    tr, det = np.trace(mono), np.linalg.det(mono)
    return 1.0 - tr + det, 1.0 + tr + det     # det(M - I), det(M + I)


def continue_rotation(gamma: float, omega: float, p_start: float, *, direction: int = 1,
                      p_min: float = 0.0, p_max: float = 3.0, winding: int = 1,
                      t0: float = 0.0, ds: float = 0.02, max_steps: int | None = None,
                      stop_at_fold: bool = True, tol: float = 1e-10,
                      deadline: float | None = None) -> Branch:
    """Continue the period-1 rotation of Eq. 1 in ``p`` at fixed ``omega`` (pseudo-arclength).

    Parameters
    ----------
    gamma, omega : float
    p_start : float
        Where a period-1 rotation exists (found by :func:`periodic_orbit`).
    direction : int
        +1 to start towards larger ``p``, -1 towards smaller.
    p_min, p_max : float
        Stop when ``p`` leaves this interval.
    winding : int
        +1 or -1 (the two rotations are mirror images; their bifurcations coincide).
    t0 : float
    ds : float
        Arclength step in ``(phi0, phi0', p)`` (adapted between ``ds/16`` and ``4*ds``).
    max_steps : int, optional
        Default ``400 * max(1, (p_max - p_min)/3)`` (400 reach p = 3 with room).
    stop_at_fold : bool
        Stop at the first fold (the birth of the rotation, curve J).
    tol : float
        Corrector tolerance.
    deadline : float, optional
        A ``time.monotonic()`` value: past it the continuation stops with status
        ``"time_limit"`` (``success`` False; ``extra["p_reached"]`` says how far it got).

    Returns
    -------
    Branch
    """
    gamma, p_start, omega = _check_params(gamma, p_start, omega)
    if direction not in (1, -1):
        raise ParameterError(f"direction: expected +1 or -1, got {direction!r}")
    ds = check_positive("ds", ds)
    if max_steps is None:
        max_steps = int(400 * max(1.0, (p_max - p_min) / 3.0))
    max_steps = check_int("max_steps", max_steps, 1)
    orb = periodic_orbit(gamma, p_start, omega, winding=winding, t0=t0, tol=tol)
    if not orb.success:
        return Branch(xr.Dataset(), (), False, "no_start",
                      f"no period-1 rotation found at p = {p_start}: {orb.message}")
    X = np.array([orb.phi0, orb.dphi0, p_start])
    fx, jac, mono = _residual(X, gamma, omega, t0, winding)
    t = _tangent(jac) * direction
    rows = [(X.copy(), mono)]
    bifs: list[Bifurcation] = []
    h = ds
    status, message = "max_steps", f"stopped after {max_steps} steps"
    for _ in range(max_steps):
        if deadline is not None and time.monotonic() > deadline:
            status, message = "time_limit", (f"time limit reached at p = {X[2]:.6g}; the branch "
                                             "beyond was not followed")
            break
        ok = False
        while h >= ds / 16:
            Xp = X + h * t
            Y = Xp.copy()
            for _it in range(8):
                fx, jac, mono = _residual(Y, gamma, omega, t0, winding)
                g = np.append(fx, np.dot(t, Y - Xp))
                if np.max(np.abs(fx)) < tol:
                    ok = True
                    break
                A = np.vstack((jac, t))
                Y = Y + np.linalg.solve(A, -g)
            if ok:
                break
            h /= 2
        if not ok:
            status, message = "corrector_failed", f"corrector failed near p = {X[2]:.6g}"
            break
        t_new = _tangent(jac, t)
        f_old, f_new = _tests(rows[-1][1]), _tests(mono)
        # fold: dp/ds changes sign (equivalently det(M - I) = 0)
        if np.sign(t_new[2]) != np.sign(t[2]) and t[2] != 0:
            Z = _refine(rows[-1][0], Y, gamma, omega, t0, winding, 0, tol)
            label = "F" if any(b.kind == "fold" for b in bifs) else "J"
            bifs.append(Bifurcation("fold", label, float(Z[2]), omega, _wrap(Z[0]),
                                    float(Z[1])))
            if stop_at_fold:
                rows.append((Y.copy(), mono))
                status, message = "fold", f"fold (curve J) at p = {Z[2]:.6g}"
                break
        if np.sign(f_new[1]) != np.sign(f_old[1]):
            Z = _refine(rows[-1][0], Y, gamma, omega, t0, winding, 1, tol)
            # G: stable below, unstable above (in p); E: the reverse; PD: unstable on both
            # sides (a saddle's second multiplier through -1)
            stab_a = bool(np.max(np.abs(np.linalg.eigvals(rows[-1][1]))) < 1)
            stab_b = bool(np.max(np.abs(np.linalg.eigvals(mono))) < 1)
            if Y[2] < rows[-1][0][2]:
                stab_a, stab_b = stab_b, stab_a
            label = "PD" if stab_a == stab_b else ("G" if stab_a else "E")
            bifs.append(Bifurcation("period_doubling", label, float(Z[2]), omega,
                                    _wrap(Z[0]), float(Z[1])))
        rows.append((Y.copy(), mono))
        X, t = Y, t_new
        h = min(h * 1.5, 4 * ds)
        if not p_min <= X[2] <= p_max:
            status, message = "p_range", f"left [{p_min}, {p_max}] at p = {X[2]:.6g}"
            break
    ps = np.array([r[0][2] for r in rows])
    mults = np.array([_sorted_eigs(r[1]) for r in rows])
    data = xr.Dataset(
        {"p": ("s", ps), "phi0": ("s", [_wrap(r[0][0]) for r in rows]),
         "dphi0": ("s", [r[0][1] for r in rows]),
         "mult_abs": (("s", "i"), np.abs(mults)), "mult_real": (("s", "i"), mults.real),
         "mult_imag": (("s", "i"), mults.imag),
         "stable": ("s", np.max(np.abs(mults), axis=1) < 1)},
        attrs={"gamma": gamma, "omega": omega, "winding": winding, "t0": t0,
               "convention": "paper Eq. 1 (phi from hanging)"})
    success = status in ("fold", "p_range", "max_steps")
    return Branch(data, tuple(bifs), success, status, message,
                  {"p_reached": float(np.max(ps)) if direction > 0 else float(np.min(ps))})


def _refine(Xa, Xb, gamma, omega, t0, r, which, tol, iters=30):
    """Zero of test function ``which`` (0: det(M-I), 1: det(M+I)) between two branch points.

    Regula falsi on the chord parameter, each trial point corrected onto the branch with
    the chord direction as the arclength constraint.
    """
    d = Xb - Xa
    d /= np.linalg.norm(d)

    def point(lam):
        Xp = Xa + lam * (Xb - Xa)
        Y = Xp.copy()
        for _ in range(10):
            fx, jac, mono = _residual(Y, gamma, omega, t0, r)
            if np.max(np.abs(fx)) < tol:
                break
            Y = Y + np.linalg.solve(np.vstack((jac, d)), -np.append(fx, np.dot(d, Y - Xp)))
        return Y, _tests(mono)[which]

    a, b = 0.0, 1.0
    fa, fb = point(a)[1], point(b)[1]
    Y = Xb
    for _ in range(iters):
        c = b - fb * (b - a) / (fb - fa) if fb != fa else 0.5 * (a + b)
        c = min(max(c, a + 1e-3 * (b - a)), b - 1e-3 * (b - a))
        Y, fc = point(c)
        if abs(fc) < 1e-10 or (b - a) < 1e-10:
            break
        if np.sign(fc) == np.sign(fa):
            a, fa = c, fc
        else:
            b, fb = c, fc
    return Y


def rotation_boundaries(gamma: float, omegas: ArrayLike, *, p_start: float | None = None,
                        p_max: float = 3.0, ds: float = 0.02, progress=None,
                        time_limit: float | None = None) -> xr.Dataset:
    """Curves J (birth, fold), G (loss of stability) and E (regain) of paper Fig. 2 left.

    For each ``omega``, a period-1 rotation is found by shooting at ``p_start`` (default:
    the smallest of 0.3, 0.6, ... 3.0 where shooting converges) and continued both ways
    (through folds) until ``p`` leaves ``[0, p_max]``. J is the lowest fold, G the lowest
    period doubling where the rotation turns unstable with increasing ``p``, E the next
    one above it where it turns stable again.

    Parameters
    ----------
    gamma : float
    omegas : array_like
        Excitation frequencies.
    p_start : float, optional
    p_max : float
    ds : float
    progress : callable, optional
        ``progress(done, total)`` after each ``omega`` (for a progress display).
    time_limit : float, optional
        Seconds for the whole map; past them every branch stops where it is and the
        remaining values of ``omega`` are not computed (attribute ``status`` is then
        ``"time_limit"``; ``p_reached`` says how far each branch was followed).

    Returns
    -------
    xarray.Dataset
        ``p_J``, ``p_G``, ``p_E`` along ``omega`` (NaN where not found: no start found by
        shooting, the bifurcation lies above ``p_max`` or above ``p_reached``), ``p_start``
        and ``p_reached`` (largest ``p`` followed; NaN: not computed).
    """
    omegas = np.atleast_1d(np.asarray(omegas, dtype=float))
    deadline = None if time_limit is None else time.monotonic() + check_positive(
        "time_limit", time_limit)
    out = {"p_J": [], "p_G": [], "p_E": [], "p_start": [], "p_reached": []}
    status = "ok"
    for i, om in enumerate(omegas):
        bifs, p0, info = _bifurcations_at(gamma, om, p_start, p_max, ds, deadline)
        if info["status"] == "time_limit":
            status = "time_limit"
        pj, pg, pe = _lowest_jge(bifs)
        out["p_J"].append(pj)
        out["p_G"].append(pg)
        out["p_E"].append(pe)
        out["p_start"].append(p0)
        out["p_reached"].append(info["p_reached"])
        if progress is not None:
            progress(i + 1, omegas.size)
    return xr.Dataset({k: ("omega", np.array(v)) for k, v in out.items()},
                      coords={"omega": omegas},
                      attrs={"gamma": gamma, "p_max": float(p_max),
                             "convention": "paper Eq. 1 (p, omega)", "status": status})


def _bifurcations_at(gamma, om, p_start, p_max, ds, deadline=None):
    """Bifurcations along the period-1 rotation at one ``omega``, the start used, and a dict
    ``status`` (``"ok"``, ``"time_limit"``, ``"no_rotation_found"``),
    ``message``, ``p_reached`` (the largest ``p`` followed)."""
    starts = [p_start] if p_start is not None else list(np.arange(1, 11) * 0.3)
    for ps in starts:
        if deadline is not None and time.monotonic() > deadline:
            return (), math.nan, {"status": "time_limit", "p_reached": math.nan,
                                  "message": "time limit reached before a rotation was found"}
        orb = periodic_orbit(gamma, ps, om)
        if not orb.success:
            continue
        # down through the fold and back up the other branch (the start may be on the
        # saddle branch), then up from the start
        down = continue_rotation(gamma, om, ps, direction=-1, p_max=p_max, ds=ds,
                                 stop_at_fold=False, deadline=deadline)
        up = continue_rotation(gamma, om, ps, direction=1, p_max=p_max, ds=ds,
                               stop_at_fold=False, deadline=deadline)
        # how far up in p the start's branch was followed (the down branch turns at the
        # fold J and comes back up on the saddle branch)
        reached = float(up.data["p"].max()) if "p" in up.data else float(ps)
        info = {"status": "ok", "message": "", "p_reached": min(reached, p_max)}
        for br in (down, up):
            if br.status == "time_limit":
                info.update(status=br.status, message=br.message, p_reached=min(reached,
                                                                                 p_max))
        return down.bifurcations + up.bifurcations, float(ps), info
    return (), math.nan, {"status": "no_rotation_found", "p_reached": math.nan, "message": ""}


def _lowest_jge(bifs):
    """J: lowest fold; G: lowest loss of stability; E: lowest regain not below G."""
    folds = [b.p for b in bifs if b.kind == "fold"]
    pj = min(folds) if folds else math.nan
    gs = [b.p for b in bifs if b.label == "G"]
    pg = min(gs) if gs else math.nan
    es = [b.p for b in bifs if b.label == "E" and not b.p < pg]
    pe = min(es) if es else math.nan
    return pj, pg, pe


def _distinct(values, tol=1e-6):
    out = []
    for v in sorted(values):
        if not out or v - out[-1] > tol:
            out.append(float(v))
    return tuple(out)


@dataclass(frozen=True, eq=False)
class RotationBoundaries:
    """Bifurcations of the period-1 rotation of paper Eq. 1 at one ``omega`` (Fig. 2 left).

    Attributes
    ----------
    gamma, omega, p_max : float
    p_J, p_G, p_E : tuple of float
        Every fold (J, birth), loss of stability (G) and regain (E) found on ``[0, p_max]``,
        increasing; usually one value each or none.
    lowest_J, lowest_G, lowest_E : float
        The values :func:`rotation_boundaries` reports (NaN when absent): the lowest fold,
        the lowest G and the lowest E not below it.
    p_start : float
        Where shooting started the branch (NaN: no period-1 rotation found by shooting).
    bifurcations : tuple of Bifurcation
    success : bool
        A branch was found and followed over ``[0, p_max]``.
    status, message : str
        ``"ok"``, ``"no_rotation_found"`` or ``"time_limit"`` (the branch was followed only
        up to ``p_reached``).
    p_reached : float
        Largest ``p`` the branch was followed to (``p_max`` unless the time ran out).
    """

    gamma: float
    omega: float
    p_max: float
    p_J: tuple
    p_G: tuple
    p_E: tuple
    lowest_J: float
    lowest_G: float
    lowest_E: float
    p_start: float
    bifurcations: tuple
    success: bool
    status: str
    message: str
    p_reached: float = math.nan

    def to_dict(self) -> dict:
        return {"gamma": self.gamma, "omega": self.omega, "p_max": self.p_max,
                "p_J": list(self.p_J), "p_G": list(self.p_G), "p_E": list(self.p_E),
                "lowest_J": self.lowest_J, "lowest_G": self.lowest_G,
                "lowest_E": self.lowest_E, "p_start": self.p_start,
                "bifurcations": [{"label": b.label, "kind": b.kind, "p": b.p,
                                  "phi0": b.phi0, "dphi0": b.dphi0} for b in self.bifurcations],
                "success": self.success, "status": self.status, "message": self.message,
                "p_reached": self.p_reached}


def rotation_boundaries_at(gamma: float, omega: float, *, p_start: float | None = None,
                           p_max: float = 3.0, ds: float = 0.02,
                           time_limit: float | None = None) -> RotationBoundaries:
    """Curves J, G, E of paper Fig. 2 left at one ``omega``, every occurrence listed.

    The same computation as one column of :func:`rotation_boundaries` (whose values are
    ``lowest_J``, ``lowest_G``, ``lowest_E``), keeping every bifurcation found.

    Parameters
    ----------
    gamma, omega : float
        Damping and excitation frequency of Eq. 1.
    p_start : float, optional
        Where to start the branch (default: the first of 0.3, 0.6, ..., 3.0 where shooting
        converges).
    p_max : float
        Largest excitation strength ``p`` followed.
    ds : float
        Continuation step.
    time_limit : float, optional
        Seconds: past them the continuation stops where it is, with status
        ``"time_limit"``, ``success`` False and ``p_reached`` the largest ``p`` followed.

    Returns
    -------
    RotationBoundaries
    """
    gamma, _, omega = _check_params(gamma, 0.0, omega)
    p_max = check_positive("p_max", p_max)
    deadline = None if time_limit is None else time.monotonic() + check_positive(
        "time_limit", time_limit)
    bifs, p0, info = _bifurcations_at(gamma, omega, p_start, p_max, ds, deadline)
    pj, pg, pe = _lowest_jge(bifs)
    ok = not math.isnan(p0) and info["status"] == "ok"
    bifs = tuple(sorted(bifs, key=lambda b: b.p))
    if info["status"] == "time_limit":
        status, message = "time_limit", (f"{info['message']} (time limit {time_limit:g} s); "
                                         "curves above it are not reported")
    elif ok:
        status, message = "ok", ""
    else:
        status, message = "no_rotation_found", (
            f"no period-1 rotation found by shooting at p = 0.3, 0.6, ..., 3 "
            f"(omega = {omega:g}); give p_start where one exists")
    return RotationBoundaries(
        gamma, omega, p_max,
        _distinct([b.p for b in bifs if b.kind == "fold"]),
        _distinct([b.p for b in bifs if b.label == "G"]),
        _distinct([b.p for b in bifs if b.label == "E"]),
        pj, pg, pe, p0, bifs, ok, status, message, info["p_reached"])
