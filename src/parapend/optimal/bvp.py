r"""Penalized Euler-Lagrange boundary-value problem (paper Eqs. 12-15, 22, 27).

The optimal period-1 rotation with damping ``gamma > 0`` maximizes (Eq. 15)::

    P[theta] = <(1 + q) sin(theta) theta'> - gamma <theta'^2>
             = <q'(t) cos(theta)> - gamma <theta'^2>            (by parts, Eq. 4)

over ``theta(t + Tp) = theta(t) + 2 pi`` (Eq. 3), ``Tp = 2 pi / omega``. Its Euler-Lagrange
equation is the singularly perturbed nonlinear Mathieu equation of Eqs. 13, 22 and 27::

    epsilon theta'' - q'(t) sin(theta) = 0,        epsilon = 2 gamma.

As ``epsilon -> 0`` the solution tends to the piecewise-constant motion of
:mod:`parapend.optimal.limit`, with half-turns in boundary layers of width about
``(epsilon / |q''(t_k)|)**(1/3)`` at the extrema ``t_k`` of ``q``.

Method (see ``docs/bvp.md``)
----------------------------
*Ritz spectral-element discretization of the functional itself.* One period is cut into
``E`` elements; on each, ``theta`` is a polynomial of degree ``p`` (default 10) given by its
values at the ``p + 1`` Gauss-Lobatto-Legendre (GLL) points; ``theta`` is continuous (element
ends are shared; the last end is the first plus one turn, Eq. 3). The integrals are evaluated
by GLL quadrature, which makes the kinetic term exact and the excitation term diagonal::

    P_h = (1/Tp) [ sum_j W_j q'(t_j) cos(theta_j) - gamma theta^T K theta ]

``W`` are the assembled GLL weights and ``K`` the periodic spectral-element stiffness matrix
(``theta^T K theta = int theta'^2 dt``). Inside each element the stationarity conditions of
``P_h`` are collocation of Eq. 22 at the interior GLL points; at the element ends they are
the weak jump condition on ``theta'``. The Hessian ``-(diag(W q' cos theta) + 2 gamma K)/Tp``
is a cyclic band matrix of half-bandwidth ``p``; ordering the unknowns ``0, n-1, 1, n-2, ...``
turns it into a plain band of half-bandwidth about ``2p``, so a Newton step is one banded
Cholesky factorization (LAPACK ``pbtrf``), ``O(n p^2)`` operations. The factorization
doubles as the test of a strict discrete local *maximum* (``-H`` positive definite), so the
iteration cannot stop at a saddle: where ``-H`` is indefinite the step is a shifted Newton
step plus, near a saddle, the direction of most positive curvature; Armijo backtracking on
``P_h`` means ``P_h`` never decreases.

Each nodal angle is stored as ``theta_j = pi n_j + z_j`` (integer ``n_j``, ``|z_j| <= pi/2``
after each solve) and every element works with its values relative to ``pi n`` at its first
node. Where the pendulum dwells near ``n pi`` the stored numbers are then tiny and exact, so
``sin(theta)``, ``cos(theta)`` and the element derivatives keep full relative precision; this
is what lets the solver meet ``tol = 1e-8`` at ``epsilon = 1e-6``, where an absolute error of
``1e-15`` in ``theta`` changes ``q' sin(theta)/epsilon`` by ``1e-9``.

*Residual control and mesh adaptation.* After each Newton solve two indicators are computed
per element (:func:`_indicators`): the relative residual of the first-order system
``y = (theta, theta')`` as in SciPy's ``solve_bvp`` (root-mean-square over the element of
``(theta_h'' - f)/(1 + |f|)``, ``f = q' sin(theta_h)/epsilon``; the first component
vanishes identically), and the quadrature error of ``int q' cos(theta_h)``. While they are
far above ``tol`` the element sizes are re-equidistributed (element ``e`` asks for the density
``r_e/h_e``, ``r_e = (eta_e/(0.1 tol))**(1/(p-1))`` clipped to [1/2, 4], graded to a
neighbour ratio of at most 2, element ends at equal quantiles of the integrated density);
near ``tol`` only the offending elements are bisected. The old polynomial solution,
interpolated onto the new mesh, starts the next Newton solve. An element also passes when
its residual is below the residual's rounding floor (:func:`_indicators`): at the centre of
a boundary layer, for ``epsilon`` below about ``1e-15``, ``q'`` at times known to
``eps_mach Tp`` leaves more error in ``f`` than ``tol`` allows, and bisecting only raises it;
the result reports the largest such floor as ``residual_floor``. Newton steps whose
predicted gain is below the rounding of ``P_h`` (moving a layer of ``epsilon = 2e-18`` by
``1e-12``) are taken without the line search, which cannot judge them.

*Globalization.* Two candidate local maxima are computed and the better one is returned:

- ``"uniform"``: continuation in ``epsilon`` from ``epsilon_0 = 2 max|q'| / omega^2``
  (where the best uniform rotation ``theta = omega t + phi`` of Eq. 17 is nearly the
  solution) down to ``epsilon``, by geometric steps of 0.1, growing to 0.01 and 0.001 while
  the steps are easy and shrinking after a failed step; intermediate steps are solved to
  ``max(tol, 1e-5)``;
- ``"limit"``: the ``epsilon -> 0`` piecewise-constant motion of
  :mod:`parapend.optimal.limit` with every half-turn smoothed to its layer width
  ``(epsilon/|q''(t_k)|)**(1/3)`` on a mesh graded there, solved directly at ``epsilon``.

The uniform continuation alone can end on a poor local maximum (for example when ``q`` has
no first harmonic); the smoothed limit motion alone can keep half-turns that a finite penalty
does not pay for (small wiggles of ``q``, the square wave of Eq. 26).

*Accuracy.* Because ``theta_h`` is an admissible rotation, its exactly evaluated power is a
lower bound of the true optimum, with an error of the order of the squared ``H^1`` error of
``theta_h``; in practice the reported power agrees with the converged Fourier optimum to
``1e-13``. It is evaluated in the form of Eq. 15 by ``2p``-point Gauss-Legendre quadrature on
every element (``power_by_parts`` gives the integrated-by-parts form as a check).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
from numpy.polynomial import legendre as npleg
from scipy.linalg import LinAlgError, cho_solve_banded, cholesky_banded

from ..errors import ParameterError, SolverError, check_finite, check_int
from ..limits import MAX_HARMONICS
from ..power import uniform_power
from .limit import limit

__all__ = ["BVPSolution", "SpectralElementMotion", "solve_bvp_optimum"]

_MIN_ELEMENTS = 8
_MAX_PASSES = 12  # mesh-adaptation passes per epsilon
_NEWTON_MAXITER = 60
_STEP_TOL = 1e-11  # Newton stops when the full step moves theta by less than this (radians)
_EPS = float(np.finfo(float).eps)


# ---------------------------------------------------------------------------------------
# Gauss-Lobatto-Legendre reference element
@lru_cache(maxsize=16)
def _gll(p: int):
    """GLL nodes ``x`` (p+1,), weights ``w``, differentiation matrix ``D``, barycentric weights."""
    c = np.zeros(p + 1)
    c[p] = 1.0
    inner = np.sort(npleg.legroots(npleg.legder(c)).real)
    # polish the interior roots of P_p' by Newton's method
    d1, d2 = npleg.legder(c), npleg.legder(c, 2)
    for _ in range(3):
        inner = inner - npleg.legval(inner, d1) / npleg.legval(inner, d2)
    x = np.concatenate(([-1.0], inner, [1.0]))
    pp = npleg.legval(x, c)
    w = 2.0 / (p * (p + 1) * pp * pp)
    diff = x[:, None] - x[None, :]
    np.fill_diagonal(diff, 1.0)
    dmat = (pp[:, None] / pp[None, :]) / diff
    np.fill_diagonal(dmat, 0.0)
    np.fill_diagonal(dmat, -dmat.sum(axis=1))  # rows annihilate constants exactly
    lam = 1.0 / np.prod(diff, axis=1)
    lam /= np.max(np.abs(lam))
    for arr in (x, w, dmat, lam):
        arr.flags.writeable = False
    return x, w, dmat, lam


def _lagrange_matrix(xe: np.ndarray, x: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """Values of the GLL Lagrange basis at points ``xe`` (m,), shape (m, p+1) (barycentric)."""
    diff = xe[:, None] - x[None, :]
    exact = diff == 0.0
    diff[exact] = 1.0
    tmp = lam[None, :] / diff
    mat = tmp / tmp.sum(axis=1, keepdims=True)
    rows = np.flatnonzero(exact.any(axis=1))
    if rows.size:
        mat[rows] = exact[rows].astype(float)
    return mat


@lru_cache(maxsize=16)
def _gauss(m: int):
    x, w = npleg.leggauss(m)
    x.flags.writeable = False
    w.flags.writeable = False
    return x, w


# ---------------------------------------------------------------------------------------
class _Mesh:
    """Periodic spectral-element mesh: element ends ``edges`` (E+1,), degree ``p``.

    The unknowns are the angles at the ``n = E p`` distinct GLL nodes
    ``t[0] = 0 < t[1] < ... < t[n-1] < Tp``; element ``e`` uses nodes ``e p .. e p + p``
    (modulo ``n``), and its last node in the last element is the first node plus one turn
    (Eq. 3), or ``winding`` turns (``theta(t + Tp) = theta(t) + 2 pi K``), recorded in
    ``wrap`` (in units of pi).
    """

    def __init__(self, edges: np.ndarray, p: int, winding: int = 1):
        self.edges = np.asarray(edges, dtype=float)
        self.p = p
        self.winding = winding
        self.E = e = self.edges.size - 1
        self.n = n = e * p
        x, w, dmat, _ = _gll(p)
        self.h = h = np.diff(self.edges)
        self.t_el = self.edges[:-1, None] + 0.5 * h[:, None] * (x + 1.0)  # (E, p+1)
        self.t = self.t_el[:, :p].ravel()
        self.idx = (np.arange(e)[:, None] * p + np.arange(p + 1)[None, :]) % n
        self.wrap = np.zeros((e, p + 1), dtype=np.int64)
        self.wrap[-1, -1] = 2 * winding
        self.W = np.bincount(self.idx.ravel(), weights=(0.5 * h[:, None] * w).ravel(),
                             minlength=n)
        self.kref = dmat.T @ (w[:, None] * dmat)
        # interleaved ordering 0, n-1, 1, n-2, ... turns the cyclic band into a plain band
        order = np.empty(n, dtype=int)
        half = (n + 1) // 2
        order[0::2] = np.arange(half)
        order[1::2] = np.arange(n - 1, half - 1, -1)
        self.pos = np.empty(n, dtype=int)
        self.pos[order] = np.arange(n)
        pi = self.pos[self.idx][:, :, None]
        pj = self.pos[self.idx][:, None, :]
        vals = (2.0 / h)[:, None, None] * self.kref[None, :, :]
        lower = pi >= pj
        rows = (pi - pj)[lower]
        cols = np.broadcast_to(pj, lower.shape)[lower]
        self.bw = int(rows.max())
        kband = np.zeros((self.bw + 1, n))
        np.add.at(kband, (rows, cols), np.broadcast_to(vals, lower.shape)[lower])
        self.kband = kband

    def local(self, n: np.ndarray, z: np.ndarray):
        """Element values relative to their first node: ``(base (E,), local (E, p+1))``.

        ``theta = pi * base + local`` on each element; subtracting the integer multiple of
        pi keeps the values small where the pendulum dwells, so that derivatives of the
        element polynomials do not amplify rounding (see the module docstring).
        """
        big = n[self.idx] + self.wrap
        base = big[:, 0]
        return base, math.pi * (big - base[:, None]) + z[self.idx]

    def stiffness_apply(self, loc: np.ndarray) -> np.ndarray:
        """Assembled ``K theta`` (n,) from element values (E, p+1)."""
        ke = (2.0 / self.h)[:, None] * (loc @ self.kref)
        return np.bincount(self.idx.ravel(), weights=ke.ravel(), minlength=self.n)

    def kinetic(self, loc: np.ndarray) -> float:
        """``int_0^Tp theta'^2 dt`` (exact for the element polynomials)."""
        return float(np.sum((2.0 / self.h)[:, None] * loc * (loc @ self.kref)))


def _sign(n: np.ndarray) -> np.ndarray:
    """``(-1)**n`` for integer arrays."""
    return 1.0 - 2.0 * (n & 1)


def _split_angle(theta: np.ndarray):
    """``theta = pi * n + z`` with integer ``n`` and ``|z| <= pi/2``."""
    k = np.rint(theta / math.pi)
    return k.astype(np.int64), theta - math.pi * k


def _rebase(n: np.ndarray, z: np.ndarray):
    k = np.rint(z / math.pi)
    if not np.any(k):
        return n, z
    return n + k.astype(np.int64), z - math.pi * k


def _equidistribute(edges: np.ndarray, density: np.ndarray, min_elements: int) -> np.ndarray:
    """Element ends equidistributing a piecewise-constant ``density`` over ``edges``."""
    h = np.diff(edges)
    cum = np.concatenate(([0.0], np.cumsum(density * h)))
    total = cum[-1]
    m = max(min_elements, int(math.ceil(total - 1e-9)))
    target = total * np.arange(m + 1) / m
    new = np.interp(target, cum, edges)
    new[0], new[-1] = edges[0], edges[-1]
    return new


def _grade(rho: np.ndarray, ratio: float = 2.0) -> np.ndarray:
    """Raise densities so that neighbours (cyclically) differ by at most ``ratio``."""
    rho = rho.copy()
    for _ in range(rho.size):
        lifted = np.maximum(rho, np.maximum(np.roll(rho, 1), np.roll(rho, -1)) / ratio)
        if np.array_equal(lifted, rho):
            break
        rho = lifted
    return rho


# ---------------------------------------------------------------------------------------
class _Problem:
    """Discrete functional ``P_h`` on one mesh for one damping (module docstring).

    The state is ``theta_j = pi n_j + z_j`` at the nodes; ``n`` is fixed, ``z`` varies.
    """

    def __init__(self, mesh: _Mesh, excitation, gamma: float):
        self.mesh = mesh
        self.gamma = gamma
        self.period = excitation.period
        self.dq = np.asarray(excitation.dq(mesh.t), dtype=float)
        self.wq = mesh.W * self.dq
        self.kband2 = 2.0 * gamma * mesh.kband

    def power(self, n: np.ndarray, z: np.ndarray) -> float:
        _, loc = self.mesh.local(n, z)
        c = float(self.wq @ (_sign(n) * np.cos(z)))
        return (c - self.gamma * self.mesh.kinetic(loc)) / self.period

    def parts(self, n: np.ndarray, z: np.ndarray):
        """``(P_h, rhs, diag)``: rhs = Tp * gradient, diag = W q' cos(theta)."""
        _, loc = self.mesh.local(n, z)
        sg = _sign(n)
        c = self.wq * sg * np.cos(z)
        p = (float(c.sum()) - self.gamma * self.mesh.kinetic(loc)) / self.period
        rhs = -self.wq * sg * np.sin(z) - 2.0 * self.gamma * self.mesh.stiffness_apply(loc)
        return p, rhs, c

    def band(self, diag: np.ndarray, shift: float = 0.0, scale=None) -> np.ndarray:
        """Lower band of ``A = -Tp H + shift * diag(scale)`` in the interleaved ordering."""
        ab = self.kband2.copy()
        pos = self.mesh.pos
        ab[0, pos] += diag
        if shift:
            ab[0, pos] += shift * scale
        return ab

    def apply(self, diag: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``A v`` with ``A = -Tp H``."""
        loc = v[self.mesh.idx]
        return diag * v + 2.0 * self.gamma * self.mesh.stiffness_apply(loc)


def _solve_band(chol: np.ndarray, b: np.ndarray, pos: np.ndarray) -> np.ndarray:
    bp = np.empty_like(b)
    bp[pos] = b
    x = cho_solve_banded((chol, True), bp, check_finite=False)
    return x[pos]


def _factor(ab: np.ndarray):
    try:
        return cholesky_banded(ab, lower=True, check_finite=False)
    except (LinAlgError, ValueError):
        return None


@dataclass
class _NewtonInfo:
    iterations: int = 0
    status: str = "converged"
    maximum: bool = False


def _indefinite_step(prob: _Problem, diag: np.ndarray, rhs: np.ndarray):
    """Ascent step where ``A = -Tp H`` is not positive definite (Nocedal & Wright 4.3).

    With ``S = diag(|diag A|)``, the most negative generalized eigenpair ``A v = lam S v`` is
    found by inverse iteration with a positive definite shifted factor; the step solves
    ``(A + mu S) d = rhs`` with ``mu = 1.5 |lam|`` (a trust-region-like step that is long
    along the directions of positive curvature of ``P``), plus ``v`` itself, signed uphill,
    where the gradient is too small to leave a saddle (DESIGN.md section 5).
    """
    pos = prob.mesh.pos
    scale = np.maximum(np.abs(diag + prob.kband2[0][pos]), 1e-300)
    mu = 1e-6
    chol = None
    while chol is None:
        mu *= 10.0
        if mu > 1e12:
            return None
        chol = _factor(prob.band(diag, mu, scale))
    rng = np.random.default_rng(20120101)
    v = rng.standard_normal(diag.size)
    for _ in range(40):
        v = _solve_band(chol, scale * v, pos)
        v /= np.max(np.abs(v))
    lam = float(v @ prob.apply(diag, v)) / float(v @ (scale * v))
    if lam < 0:
        shift = 1.5 * -lam + 1e-12
        trial = None
        while trial is None and shift < mu:
            trial = _factor(prob.band(diag, shift, scale))
            if trial is None:
                shift *= 2.0
        if trial is not None:
            chol = trial
    d = _solve_band(chol, rhs, pos)
    if lam < 0 and float(np.max(np.abs(d))) < 1e-2:
        d = d + v * (0.5 if float(rhs @ v) >= 0 else -0.5)
    return d


def _newton(prob: _Problem, n: np.ndarray, z0: np.ndarray, maxiter: int = _NEWTON_MAXITER):
    """Safeguarded Newton ascent on ``P_h`` over ``z``; returns ``(z, P_h, info)``."""
    z = np.array(z0, dtype=float)
    pos = prob.mesh.pos
    p, rhs, diag = prob.parts(n, z)
    info = _NewtonInfo(status="max_iterations")
    prev_step = math.inf
    for it in range(1, maxiter + 1):
        info.iterations = it
        if not (math.isfinite(p) and np.all(np.isfinite(rhs))):
            info.status = "nonfinite"
            break
        chol = _factor(prob.band(diag))
        newton = chol is not None
        if newton:
            d = _solve_band(chol, rhs, pos)
        else:
            d = _indefinite_step(prob, diag, rhs)
            if d is None:
                info.status = "nonfinite"
                return z, p, info
        step = float(np.max(np.abs(d)))
        if step > 1.0:  # at most one radian per step
            d *= 1.0 / step
        slope = float(rhs @ d) / prob.period
        # rounding level of P_h; a Newton step whose predicted gain slope/2 is below it
        # cannot be judged by comparing P_h (epsilon ~ 1e-18: the step that moves a
        # boundary layer by ~1e-12 in t gains ~1e-23)
        ptol = 1e-15 * max(1.0, abs(p))
        blind = newton and 0.5 * slope <= ptol
        if newton and (step <= _STEP_TOL or (step > 0.25 * prev_step
                                             and (step < 1e-7 or blind))):
            # converged, or Newton steps no longer shrink: rounding level reached
            z = z + d
            p, rhs, diag = prob.parts(n, z)
            info.status = "converged"
            break
        prev_step = step if newton else math.inf
        t = 1.0
        accepted = False
        for _ in range(50):
            zn = z + t * d
            pn = prob.power(n, zn)
            if pn >= p + 1e-4 * t * slope or (newton and t == 1.0 and (step < 1e-6 or blind)
                                              and pn >= p - ptol):
                accepted = True
                break
            t *= 0.5
        if not accepted:
            # no measurable increase: a maximum up to rounding, or stalled
            info.status = "converged" if newton and step < 1e-8 else "stalled"
            break
        z = zn
        p, rhs, diag = prob.parts(n, z)
    info.maximum = _factor(prob.band(diag)) is not None
    return z, p, info


# ---------------------------------------------------------------------------------------
def _eval_elements(mesh: _Mesh, n: np.ndarray, z: np.ndarray, t: np.ndarray,
                   derivs: int = 2):
    """``(base, local, theta', theta'')`` of the element polynomials at ``t`` in ``[0, Tp]``.

    ``theta = pi * base + local``; ``derivs`` limits the derivatives computed.
    """
    x, _, dmat, lam = _gll(mesh.p)
    e = np.clip(np.searchsorted(mesh.edges, t, side="right") - 1, 0, mesh.E - 1)
    h = mesh.h[e]
    xe = 2.0 * (t - mesh.edges[e]) / h - 1.0
    lmat = _lagrange_matrix(xe, x, lam)
    base, loc = mesh.local(n, z)
    le = loc[e]
    out = [base[e], np.einsum("ij,ij->i", lmat, le)]
    if derivs >= 1:
        d1 = le @ dmat.T
        out.append(np.einsum("ij,ij->i", lmat, d1) * (2.0 / h))
    if derivs >= 2:
        d2 = d1 @ dmat.T
        out.append(np.einsum("ij,ij->i", lmat, d2) * (2.0 / h) ** 2)
    return out


def _element_points(mesh: _Mesh, m: int):
    """Gauss-Legendre points (E, m), weights (m,) and interpolation matrices (m, p+1)."""
    xg, wg = _gauss(m)
    x, _, dmat, lam = _gll(mesh.p)
    lmat = _lagrange_matrix(xg, x, lam)
    tg = mesh.edges[:-1, None] + 0.5 * mesh.h[:, None] * (xg + 1.0)
    return tg, wg, lmat, lmat @ dmat, lmat @ dmat @ dmat


@lru_cache(maxsize=16)
def _second_derivative_interpolation(p: int, m: int) -> np.ndarray:
    """Lagrange matrix (m, p-1) from the interior GLL points to m Gauss points."""
    x = _gll(p)[0][1:-1]
    diff = x[:, None] - x[None, :]
    np.fill_diagonal(diff, 1.0)
    lam = 1.0 / np.prod(diff, axis=1)
    mat = _lagrange_matrix(_gauss(m)[0], x, lam / np.max(np.abs(lam)))
    mat.flags.writeable = False
    return mat


def _indicators(mesh: _Mesh, n: np.ndarray, z: np.ndarray, excitation, epsilon: float,
                dq_nodes: np.ndarray, tol: float = 0.0):
    """Per-element error indicators ``(residual, quadrature, floor)``, each shape (E,).

    ``residual``: RMS over the element of ``(theta_h'' - f)/(1 + |f|)``,
    ``f = q' sin(theta_h)/epsilon``, the relative residual of the first-order system
    ``y = (theta, theta')`` as in SciPy's ``solve_bvp`` (its first component,
    ``theta_h' - y_2``, vanishes identically), by ``2p``-point Gauss-Legendre quadrature.
    ``theta_h''`` (degree ``p-2``) is evaluated from its values at the ``p-1`` interior GLL
    points, where the discrete stationarity conditions are exactly the collocation
    conditions ``epsilon theta_h'' = q' sin(theta_h)``; this equals differentiating the
    element polynomial twice but does not amplify the rounding of the nodal angles by
    ``~p^4/h^2`` (which would put a floor of about ``1e-7`` under the residual at the centre
    of thin layers).

    ``quadrature``: difference between the GLL and the ``2p``-point Gauss rules for
    ``int q' cos(theta_h) dt`` over the element, divided by ``h_e <|q'|>``; it flags
    elements that do not resolve the excitation where the pendulum dwells (there
    ``sin(theta) ~ 0`` hides ``q'`` from the residual).

    ``floor`` (computed where ``residual > tol``, 0 elsewhere): the residual's rounding
    floor, the same RMS of the error that ``f`` carries
    in double precision. A time in ``[0, Tp]`` is known to about ``eps_mach Tp`` (node times
    and phases ``k omega t`` are rounded), so ``q'`` to ``2 eps_mach Tp |q''|``;
    ``sin`` of an angle relative to the element's first node to ``eps_mach |theta_loc|``.
    Near the centre of a boundary layer ``q'`` passes through 0 and ``f`` is small, so this
    error is a large part of it: at ``epsilon = 2e-18`` the floor reaches ``1e-8`` in
    elements of ``1e-7``, and bisecting such an element raises it (the same error over a
    smaller ``|f|``). Measured against residuals that only grew under bisection (paper case,
    ``epsilon = 2e-18``; three harmonics and ``omega = 0.1`` at ``2e-17``): the residual
    there is 0.1 to 0.4 times this floor.
    """
    m = 2 * mesh.p
    tg, wg, lmat, _, _ = _element_points(mesh, m)
    _, w_gll, _, _ = _gll(mesh.p)
    base, loc = mesh.local(n, z)
    sg = _sign(base)[:, None]
    th = loc @ lmat.T
    dq = np.asarray(excitation.dq(tg.ravel()), dtype=float).reshape(tg.shape)
    f = dq * sg * np.sin(th) / epsilon
    f_nodes = dq_nodes[mesh.idx[:, 1:-1]] * sg * np.sin(loc[:, 1:-1]) / epsilon
    thdd = f_nodes @ _second_derivative_interpolation(mesh.p, m).T
    r = (thdd - f) / (1.0 + np.abs(f))
    residual = np.sqrt(0.5 * (r * r) @ wg)
    half = 0.5 * mesh.h
    gauss = half * ((dq * sg * np.cos(th)) @ wg)
    lobatto = half * ((dq_nodes[mesh.idx] * sg * np.cos(loc)) @ w_gll)
    qscale = max(float(np.sum(half[:, None] * np.abs(dq) * wg)) / excitation.period, 1e-300)
    quadrature = np.abs(gauss - lobatto) / (mesh.h * qscale)
    # rounding floor (see the docstring), only where the residual exceeds tol: the RMS of
    # the error f carries in double precision, relative to 1 + |f| as the residual is;
    # q'' by central differences 1/(64 p) of the element apart
    floor = np.zeros(mesh.E)
    sel = np.flatnonzero(residual > tol)
    if sel.size:
        tp = excitation.period
        ts = tg[sel]
        step = (mesh.h[sel] / (64 * mesh.p))[:, None]
        up = np.asarray(excitation.dq((ts + step).ravel()), dtype=float).reshape(ts.shape)
        down = np.asarray(excitation.dq((ts - step).ravel()), dtype=float).reshape(ts.shape)
        qdd = np.abs(up - down) / (2.0 * step)
        ths = th[sel]
        noise = _EPS * (2.0 * tp * qdd * np.abs(np.sin(ths)) + np.abs(ths * dq[sel])) / epsilon
        g = noise / (1.0 + np.abs(f[sel]))
        floor[sel] = np.sqrt(0.5 * (g * g) @ wg)
    return residual, quadrature, floor


def _accurate_power(mesh: _Mesh, n: np.ndarray, z: np.ndarray, excitation, gamma: float):
    """``(P_eq15, P_by_parts, <theta'^2>)`` by 2p-point Gauss-Legendre per element."""
    tg, wg, lmat, l1, _ = _element_points(mesh, 2 * mesh.p)
    base, loc = mesh.local(n, z)
    sg = _sign(base)[:, None]
    th = loc @ lmat.T
    thd = (loc @ l1.T) * (2.0 / mesh.h[:, None])
    tf = tg.ravel()
    q = np.asarray(excitation.q(tf), dtype=float).reshape(tg.shape)
    dq = np.asarray(excitation.dq(tf), dtype=float).reshape(tg.shape)
    jac = 0.5 * mesh.h[:, None] * wg[None, :]
    period = excitation.period
    kin = mesh.kinetic(loc) / period
    p15 = float(np.sum(jac * (1.0 + q) * sg * np.sin(th) * thd)) / period - gamma * kin
    pbp = float(np.sum(jac * dq * sg * np.cos(th))) / period - gamma * kin
    return p15, pbp, kin


def _interpolate(mesh: _Mesh, n: np.ndarray, z: np.ndarray, new: _Mesh):
    base, loc = _eval_elements(mesh, n, z, new.t, derivs=0)
    k, zz = _split_angle(loc)
    return base + k, zz


def _slope_jump(mesh: _Mesh, n: np.ndarray, z: np.ndarray) -> float:
    """Largest jump of ``theta_h'`` across element ends, relative to ``max |theta_h'|``."""
    _, _, dmat, _ = _gll(mesh.p)
    _, loc = mesh.local(n, z)
    d = (loc @ dmat.T) * (2.0 / mesh.h[:, None])
    jump = d[:, -1] - np.roll(d[:, 0], -1)
    return float(np.max(np.abs(jump))) / float(np.max(np.abs(d)))


# ---------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class SpectralElementMotion:
    """The BVP optimum as a motion: on each element ``theta`` is a polynomial of degree p.

    ``theta`` is continuous; ``theta'`` and ``theta''`` are the exact derivatives of the
    element polynomials (at an element end the element to the right is used; ``theta'``
    jumps there by at most :attr:`BVPSolution.slope_jump` relative to ``max|theta'|``).
    The period-1 extension ``theta(t + Tp) = theta(t) + 2 pi`` (Eq. 3) holds for any ``t``
    (``+ 2 pi K`` with ``winding`` K).
    Inside the period the interpolation error is that of the solution itself: the ODE
    residual is at most ``max_residual`` relative to ``1 + |theta''|``.

    Parameters
    ----------
    omega : float
        Forcing frequency.
    edges : ndarray, shape (E+1,)
        Element ends in ``[0, Tp]``.
    degree : int
        Polynomial degree ``p``.
    values : ndarray, shape (E, p+1)
        ``theta`` at the GLL points of each element (radians).
    winding : int
        Turns K per period: ``theta(t + Tp) = theta(t) + 2 pi K``.
    """

    omega: float
    edges: np.ndarray
    degree: int
    values: np.ndarray
    _mesh: _Mesh = field(repr=False, compare=False, default=None)
    _n: np.ndarray = field(repr=False, compare=False, default=None)
    _z: np.ndarray = field(repr=False, compare=False, default=None)
    winding: int = 1

    @classmethod
    def _from_state(cls, omega: float, mesh: _Mesh, n: np.ndarray,
                    z: np.ndarray, winding: int = 1) -> SpectralElementMotion:
        base, loc = mesh.local(n, z)
        values = math.pi * base[:, None] + loc
        return cls(omega, mesh.edges.copy(), mesh.p, values, mesh, n.copy(), z.copy(),
                   winding)

    @property
    def period(self) -> float:
        return 2 * math.pi / self.omega

    def _eval(self, t, k: int):
        t = np.asarray(t, dtype=float)
        turns = np.floor(t / self.period)
        tm = np.atleast_1d(t - turns * self.period).ravel()
        out = _eval_elements(self._mesh, self._n, self._z, tm, derivs=k)
        return out, turns, t.shape

    def theta(self, t):
        """``theta(t)`` (radians), any ``t`` (array_like)."""
        (base, loc), turns, shape = self._eval(t, 0)
        val = (math.pi * base + loc).reshape(shape) + 2 * math.pi * self.winding * turns
        return val if val.ndim else float(val)

    def theta_dot(self, t):
        """``theta'(t)``."""
        out, _, shape = self._eval(t, 1)
        val = out[2].reshape(shape)
        return val if val.ndim else float(val)

    def theta_ddot(self, t):
        """``theta''(t)``."""
        out, _, shape = self._eval(t, 2)
        val = out[3].reshape(shape)
        return val if val.ndim else float(val)

    def sample_times(self, per_element: int | None = None) -> np.ndarray:
        """Times in one period on the motion's own mesh: ``per_element`` (default ``4 p``)
        uniform points inside every element, so thin boundary layers are sampled as
        finely as their elements are."""
        k = per_element or 4 * self.degree
        h = np.diff(self.edges)
        return (self.edges[:-1, None] + h[:, None] * (np.arange(k) / k)[None, :]).ravel()

    def mean_square_speed(self) -> float:
        """``<theta'^2>`` (exact for the element polynomials)."""
        _, loc = self._mesh.local(self._n, self._z)
        return self._mesh.kinetic(loc) / self.period


@dataclass(frozen=True, eq=False)
class BVPSolution:
    """Optimal period-1 rotation from the penalized Euler-Lagrange BVP (Eqs. 13, 22, 27).

    Attributes
    ----------
    power : float
        Mean extracted power of Eq. 15 with damping,
        ``<(1+q) sin(theta) theta'> - gamma <theta'^2>``, by ``2p``-point Gauss-Legendre
        quadrature on every element of the final mesh (positive = harvested).
    power_by_parts : float
        The same power as ``<q' cos(theta)> - gamma <theta'^2>`` (an accuracy check).
    epsilon : float
        Penalty parameter of Eqs. 12-13, ``2 * gamma``.
    gamma : float
        Viscous damping (Eq. 14).
    omega : float
        Forcing frequency.
    t : ndarray, shape (mesh_nodes + 1,)
        Mesh nodes over one period, ``t[0] = 0``, ``t[-1] = Tp`` (the GLL points of all
        elements, shared element ends once).
    theta, theta_dot : ndarray, shape (mesh_nodes + 1,)
        ``theta`` and ``theta'`` at ``t`` (``theta[-1] = theta[0] + 2 pi K``; ``theta'`` from
        the element to the right of a node).
    mesh_nodes : int
        Distinct nodes (unknowns) per period, ``elements * degree``.
    elements, degree : int
        Number of spectral elements and their polynomial degree.
    max_residual : float
        Largest element RMS of the relative residual ``(theta'' - f)/(1 + |f|)``,
        ``f = q' sin(theta)/epsilon``, of the first-order system (SciPy ``solve_bvp``
        convention); on success every element's is ``<= tol`` or ``<=`` its rounding floor
        (``residual_floor``).
    residual_floor : float
        0 when every element met ``tol``; else the largest rounding floor of the residual
        among the elements that did not: the part of ``(theta'' - f)/(1 + |f|)`` that double
        precision cannot resolve, from ``q'`` at times known to ``~eps_mach Tp``. It
        matters only near the centres of boundary layers at ``epsilon`` below about 1e-15,
        where ``q'`` passes through 0 (docs/bvp.md, section 3).
    slope_jump : float
        Largest jump of ``theta'`` across element ends, relative to ``max|theta'|``.
    continuation_steps : int
        Number of epsilon values solved along the winning path (1: solved directly).
    success : bool
    status : str
        ``"converged"``, ``"max_nodes"`` (mesh limit reached before ``tol``),
        ``"not_converged"`` (Newton or mesh adaptation failed), ``"not_maximum"``.
    message : str
    iterations : int
        Newton iterations in total (all starts, continuation steps and meshes).
    strict_maximum : bool
        The discrete Hessian is negative definite at the solution.
    found_by : str
        ``"uniform"`` (continuation from the best uniform rotation) or ``"limit"`` (the
        smoothed gamma -> 0 motion).
    candidates : dict
        Power reached from each start, for the record.
    uniform_power, limit_power : float
        Best uniform rotation (Eq. 17) at this damping and the gamma -> 0 supremum.
    mean_square_speed : float
        ``<theta'^2>``.
    winding : int
        Turns K per period, ``theta(t + Tp) = theta(t) + 2 pi K`` (1: Eq. 3).
    """

    power: float
    power_by_parts: float
    epsilon: float
    gamma: float
    omega: float
    t: np.ndarray
    theta: np.ndarray
    theta_dot: np.ndarray
    mesh_nodes: int
    elements: int
    degree: int
    max_residual: float
    slope_jump: float
    continuation_steps: int
    success: bool
    status: str
    message: str
    iterations: int
    strict_maximum: bool
    found_by: str
    candidates: dict
    uniform_power: float
    limit_power: float
    mean_square_speed: float
    winding: int = 1
    residual_floor: float = 0.0
    _motion: SpectralElementMotion = field(repr=False, default=None)

    def motion(self) -> SpectralElementMotion:
        """The solution as a motion with ``theta``, ``theta_dot``, ``theta_ddot`` at any t."""
        return self._motion


# ---------------------------------------------------------------------------------------
@dataclass
class _Candidate:
    mesh: _Mesh
    n: np.ndarray
    z: np.ndarray
    power: float
    eta: float
    status: str
    maximum: bool
    steps: int
    iterations: int
    seed: str
    floor: float = 0.0


def _adapt_solve(exc, gamma: float, mesh: _Mesh, n: np.ndarray, z: np.ndarray,
                 tol: float, max_nodes: int):
    """Newton + residual-driven re-meshing at one damping until every element meets tol.

    Returns ``(mesh, n, z, P_h, max_residual, status, strict_maximum, iterations,
    residual_floor)``: an element passes when its residual is below ``tol`` or below its
    rounding floor (:func:`_indicators`); ``residual_floor`` is the largest floor an element
    needed (0 when every element met ``tol``).
    """
    eps = 2.0 * gamma
    its = 0
    status = "not_converged"
    info = _NewtonInfo()
    p_h = math.nan
    emax = math.inf
    efloor = 0.0
    p = mesh.p
    for npass in range(_MAX_PASSES):
        prob = _Problem(mesh, exc, gamma)
        z, p_h, info = _newton(prob, n, z)
        its += info.iterations
        n, z = _rebase(n, z)
        if info.status != "converged":
            status = "not_converged"
            break
        res, quad, floor = _indicators(mesh, n, z, exc, eps, prob.dq, tol)
        emax = float(np.max(res))
        # an element passes below tol, or below its residual's rounding floor: refining
        # it cannot help there (the floor grows as the element shrinks)
        allowed = np.maximum(tol, floor)
        bad = (res > allowed) | (quad > tol)
        efloor = float(np.max(floor, where=res > tol, initial=0.0))
        if not np.any(bad):
            status = "converged"
            break
        if npass == _MAX_PASSES - 1:
            status = "not_converged"
            break
        if (np.all((res < 100.0 * allowed) & (quad < 100.0 * tol))
                and np.count_nonzero(bad) <= 0.25 * mesh.E):
            # nearly there: bisect the offending elements only (no coarsening)
            edges = np.sort(np.concatenate((mesh.edges, mesh.edges[:-1][bad]
                                            + 0.5 * mesh.h[bad])))
        else:
            # re-equidistribute the density each element asks for
            excess = np.maximum(res / (0.1 * allowed), quad / (0.1 * tol))
            r = np.clip(excess ** (1.0 / (p - 1)), 0.5, 4.0)
            edges = _equidistribute(mesh.edges, _grade(r / mesh.h), _MIN_ELEMENTS)
        if (edges.size - 1) * p > max_nodes:
            status = "max_nodes"
            break
        new = _Mesh(edges, p, mesh.winding)
        n, z = _interpolate(mesh, n, z, new)
        mesh = new
    return mesh, n, z, p_h, emax, status, info.maximum, its, efloor


def _uniform_branch(exc, gamma: float, tol: float, max_nodes: int, p: int,
                    winding: int = 1) -> _Candidate:
    """Continuation in epsilon from the best uniform rotation (large epsilon) down.

    With winding K the start is ``theta = K omega t + phi`` (the best uniform rotation of
    winding K, :func:`parapend.power.uniform_power`), from ``epsilon_0 = 2 max|q'| /
    (K omega)^2``, on ``16 K`` elements (16 per turn).
    """
    eps_target = 2.0 * gamma
    _, phi = uniform_power(exc, gamma, winding)
    tp = exc.period
    tgrid = tp * np.arange(1024) / 1024
    dqmax = float(np.max(np.abs(exc.dq(tgrid))))
    eps = max(eps_target, 2.0 * dqmax / (winding * exc.omega) ** 2)
    mesh = _Mesh(np.linspace(0.0, tp, 16 * winding + 1), p, winding)
    n, z = _split_angle(winding * exc.omega * mesh.t + phi)
    factor = 0.1
    its = steps = 0
    tol_mid = max(tol, 1e-5)
    state = (mesh, n, z)
    eps_prev = eps
    while True:
        final = eps <= eps_target * (1 + 1e-12)
        res = _adapt_solve(exc, 0.5 * eps, *state, tol if final else tol_mid, max_nodes)
        its += res[7]
        status = res[5]
        if status == "converged":
            steps += 1
            if final:
                break
            state = res[:3]
            if res[7] <= 12:  # an easy step: take longer ones
                factor = max(factor * factor, 1e-3)
            eps_prev = eps
            eps = max(eps * factor, eps_target)
            continue
        # a failed step: retreat to a shorter one from the last accepted epsilon, unless
        # the mesh limit was hit (a shorter step cannot help) or the steps are already short
        factor = math.sqrt(factor)
        if steps == 0 or status == "max_nodes" or factor > 0.9:
            break
        eps = max(eps_prev * factor, eps_target)
    mesh, n, z, p_h, eta, status, maximum, _, floor = res
    return _Candidate(mesh, n, z, p_h, eta, status, maximum, steps, its, "uniform", floor)


def _pattern_of(exc, motion):
    """Turns of ``motion`` at the extrema of q, in half-turns: ``(theta_start, d_k)``.

    The level (a multiple of pi, rounded) in the middle of each dwell between extrema,
    differenced: ``d_k`` is +-1 for a half-turn, 0 where the motion does not turn, +-2 for a
    full turn between two dwells. The ``d_k`` sum to ``2 K`` (K turns per period).
    """
    tk = np.asarray(exc.extrema.t, dtype=float)
    tp = exc.period
    mids = 0.5 * (tk + np.append(tk[1:], tk[0] + tp))
    levels = np.rint(np.asarray(motion.theta(np.append(mids[-1] - tp, mids))) / math.pi)
    return math.pi * levels[0], np.diff(levels)


def _limit_seed(exc, epsilon: float, p: int, pattern=None, winding: int = 1):
    """Mesh and start from the gamma -> 0 motion, half-turns smoothed to the layer widths.

    ``pattern = (theta_start, d_k)`` replaces the limit motion's canonical turns (see
    :func:`_pattern_of`). Winding K: the limit motion of ``limit(exc, K)``, whose turns sum
    to K per period (a ``d_k`` of 3 or more where q has fewer than 2 K extrema).
    """
    lim = limit(exc, winding)
    mot = lim.motion
    tp = exc.period
    tk = np.asarray(mot.switch_times, dtype=float)
    dk = np.asarray(mot.directions, dtype=float)
    theta_start = float(mot.theta_start)
    if pattern is not None:
        theta_start, dk = float(pattern[0]), np.asarray(pattern[1], dtype=float)
    hq = 1e-5 * tp
    qpp = np.abs((np.asarray(exc.dq(tk + hq)) - np.asarray(exc.dq(tk - hq))) / (2 * hq))
    wk = np.minimum((epsilon / np.maximum(qpp, 1e-300)) ** (1.0 / 3.0), tp / 16)
    # element density: 16 per period plus a Lorentzian bump of 1.5 elements per layer width
    # around each turn; its integral is closed-form, inverted on a grid graded at the turns
    grid = [tp * np.arange(4097) / 4096]
    for t0, w in zip(tk, wk, strict=True):
        grid.append(np.mod(t0 + 4.0 * w * np.tan(np.linspace(-1.55, 1.55, 801)), tp))
    grid = np.unique(np.concatenate(grid))

    def cumulative(t):
        c = 16.0 * t / tp
        for t0, w in zip(tk, wk, strict=True):
            for shift in (-tp, 0.0, tp):
                c = c + 6.0 * (np.arctan((t - t0 - shift) / (4.0 * w))
                               - np.arctan((-t0 - shift) / (4.0 * w)))
        return c

    cum = cumulative(grid)
    m = max(_MIN_ELEMENTS, int(math.ceil(cum[-1])))
    edges = np.interp(cum[-1] * np.arange(m + 1) / m, cum, grid)
    edges[0], edges[-1] = 0.0, tp
    mesh = _Mesh(edges, p, winding)
    t = mesh.t
    theta = np.full(t.size, theta_start)
    for t0, w, d in zip(tk, wk, dk, strict=True):
        s = -1.0
        for shift in (-tp, 0.0, tp):
            zz = np.clip((t - t0 - shift) / w, -50, 50)
            s = s + (2.0 / math.pi) * np.arctan(np.exp(1.5 * zz))
        theta += d * math.pi * s
    n, z = _split_angle(theta)
    return mesh, n, z


def _limit_branch(exc, gamma: float, tol: float, max_nodes: int, p: int,
                  pattern=None, name: str = "limit", winding: int = 1) -> _Candidate:
    mesh, n, z = _limit_seed(exc, 2.0 * gamma, p, pattern, winding)
    mesh, n, z, p_h, eta, status, maximum, its, floor = _adapt_solve(exc, gamma, mesh, n, z,
                                                                    tol, max_nodes)
    return _Candidate(mesh, n, z, p_h, eta, status, maximum, 1, its, name, floor)


#: Harmonics of the Fourier search whose optimum's turn pattern seeds the BVP.
_FOURIER_SEED_HARMONICS = 24


def _fourier_branch(exc, gamma: float, tol: float, max_nodes: int, p: int,
                    winding: int = 1) -> _Candidate:
    """Start from the turn pattern of the global Fourier optimum (docs/global.md): with
    several extrema per period the canonical limit pattern is often not the best one.
    Winding K: the Fourier optimum of winding K with ``max(24, 4 K)`` harmonics."""
    from ..trajectory import FourierMotion
    from .fourier import search_fourier

    if winding == 1:
        found = search_fourier(exc, _FOURIER_SEED_HARMONICS, gamma)
    else:
        nh = max(_FOURIER_SEED_HARMONICS, 4 * winding)
        found = search_fourier(exc, nh, gamma, winding=winding,
                               hessian="dense" if nh <= 256 else "operator")
    motion = FourierMotion.from_vector(exc.omega, found.best.x, winding)
    return _limit_branch(exc, gamma, tol, max_nodes, p, _pattern_of(exc, motion), "fourier",
                         winding)


_MESSAGES = {
    "converged": "converged: residual below tol at a strict local maximum of the power",
    "max_nodes": "mesh limit reached before the residual met tol; raise max_nodes or tol",
    "not_converged": "Newton iteration or mesh adaptation did not converge; try a larger "
                     "damping or a looser tol",
    "not_maximum": "converged to a stationary point that is not a strict maximum",
}


def solve_bvp_optimum(excitation, gamma: float, *, tol: float = 1e-8,
                      max_nodes: int = 200_000, degree: int = 10,
                      seeds: tuple[str, ...] = ("uniform", "limit", "fourier"),
                      winding: int = 1, throw: bool = False) -> BVPSolution:
    """Optimal period-1 rotation from the penalized Euler-Lagrange BVP (Eqs. 13, 22, 27).

    Parameters
    ----------
    excitation : Excitation
        Any excitation of :mod:`parapend.excitation` (harmonic, two-harmonic, Eq. 26
        square wave, Fourier series, sampled).
    gamma : float
        Viscous damping ``gamma > 0`` (Eq. 14); the penalty is ``epsilon = 2 gamma``.
        ``gamma = 0`` has no smooth optimum (use :func:`parapend.limit`).
    tol : float
        Bound on the element RMS of the relative residual (as SciPy's ``solve_bvp``).
    max_nodes : int
        Largest number of unknowns (GLL nodes per period) allowed.
    degree : int
        Polynomial degree ``p`` of the spectral elements (4..16).
    seeds : tuple of {"uniform", "limit", "fourier"}
        Starting points tried; the best converged local maximum wins. ``"fourier"`` (used
        only when q has several maxima per period) starts from the turn pattern of the
        global N = 24 Fourier optimum (``max(24, 4 K)`` for winding K).
    winding : int
        K >= 1 turns per period of q: ``theta(t + Tp) = theta(t) + 2 pi K`` replaces Eq. 3
        (docs/seas.md, docs/bvp.md); the Euler-Lagrange equation is the same, only the
        boundary condition and the starts change. K = 1 is the paper's period-1 rotation.
    throw : bool
        Raise :class:`~parapend.errors.SolverError` instead of returning an unsuccessful
        result.

    Returns
    -------
    BVPSolution
    """
    given = gamma
    gamma = check_finite("gamma", gamma)
    if gamma <= 0:
        raise ParameterError(f"gamma: expected a damping > 0 (epsilon = 2 gamma penalizes "
                             f"speed; for gamma = 0 use parapend.limit), got {given!r}")
    tol = check_finite("tol", tol)
    if not 1e-14 <= tol <= 1e-1:
        raise ParameterError(f"tol: expected a number in [1e-14, 0.1], got {tol!r}")
    degree = check_int("degree", degree, 4, 16)
    max_nodes = check_int("max_nodes", max_nodes, 16 * _MIN_ELEMENTS)
    if isinstance(seeds, str) or not seeds or any(s not in ("uniform", "limit", "fourier")
                                                   for s in seeds):
        raise ParameterError(f"seeds: expected a non-empty tuple of 'uniform', 'limit', "
                             f"'fourier', got {seeds!r}")
    winding = check_int("winding", winding, 1, MAX_HARMONICS // 2)
    p = int(degree)
    k = int(winding)
    lim = limit(excitation, k)
    cands = []
    tgrid = excitation.period * np.arange(1024) / 1024
    if not np.any(np.asarray(excitation.dq(tgrid), dtype=float)):
        # constant q: every uniform rotation is optimal (P = -gamma omega^2), none strictly
        mesh = _Mesh(np.linspace(0.0, excitation.period, _MIN_ELEMENTS * k + 1), p, k)
        n, z = _split_angle(k * excitation.omega * mesh.t)
        cands.append(_Candidate(mesh, n, z, -gamma * (k * excitation.omega) ** 2, 0.0,
                                "converged", True, 0, 0, "uniform"))
        seeds = ()
    for name in seeds:
        if name == "uniform":
            cands.append(_uniform_branch(excitation, gamma, tol, int(max_nodes), p, k))
        elif name == "limit" and lim.power > 0:
            cands.append(_limit_branch(excitation, gamma, tol, int(max_nodes), p,
                                       winding=k))
        elif name == "fourier" and np.size(lim.directions) > 2:
            cands.append(_fourier_branch(excitation, gamma, tol, int(max_nodes), p, k))
    iterations = sum(c.iterations for c in cands)
    good = [c for c in cands if c.status == "converged" and c.maximum]
    pool = good or [c for c in cands if math.isfinite(c.power)] or cands
    best = max(pool, key=lambda c: c.power if math.isfinite(c.power) else -math.inf)
    status = best.status
    if status == "converged" and not best.maximum:
        status = "not_maximum"
    mesh, n, z = best.mesh, best.n, best.z
    p15, pbp, kin = _accurate_power(mesh, n, z, excitation, gamma)
    om = excitation.omega
    t = np.append(mesh.t, excitation.period)
    th_nodes = math.pi * n + z
    _, _, dth = _eval_elements(mesh, n, z, mesh.t, derivs=1)
    motion = SpectralElementMotion._from_state(om, mesh, n, z, k)
    sol = BVPSolution(
        power=p15,
        power_by_parts=pbp,
        epsilon=2.0 * gamma,
        gamma=gamma,
        omega=om,
        t=t,
        theta=np.append(th_nodes, th_nodes[0] + 2 * math.pi * k),
        theta_dot=np.append(dth, dth[0]),
        mesh_nodes=mesh.n,
        elements=mesh.E,
        degree=p,
        max_residual=best.eta,
        slope_jump=_slope_jump(mesh, n, z),
        continuation_steps=best.steps,
        success=status == "converged",
        status=status,
        message=_MESSAGES.get(status, status) + (
            f" (or below the residual's rounding floor, at most {best.floor:.2g}, near the "
            f"centres of boundary layers)" if status == "converged" and best.floor else ""),
        iterations=iterations,
        strict_maximum=best.maximum,
        found_by=best.seed,
        candidates={c.seed: c.power for c in cands},
        uniform_power=uniform_power(excitation, gamma, k)[0],
        limit_power=lim.power,
        mean_square_speed=kin,
        winding=k,
        residual_floor=best.floor,
        _motion=motion,
    )
    if throw and not sol.success:
        raise SolverError(f"solve_bvp_optimum: {sol.message} (status {status!r}, "
                          f"max residual {best.eta:.3g})")
    return sol
