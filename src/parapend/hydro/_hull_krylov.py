r"""The hull problem matrix-free: long records at a cost near-linear in the harmonics.

The same model and discretization as :class:`parapend.hydro.hull.HullProblem` (docs/hull.md;
the equations of that module's docstring), with every matrix applied as FFTs and pointwise
products on the grid instead of formed. The pendulum's coefficients
``x = (x_0, a_1..a_N, b_1..b_N)``, ``phi = K s + x_0 + sum_n a_n sin(ns) + b_n cos(ns)``
(``s = w t``, ``M`` grid points ``s_j = 2 pi j / M``); the hull's harmonics
``Xi_k`` (3 complex DOFs, ``k = 1..Nh``) and its static offsets ``Xi_0`` on the DOFs with
stiffness. The maps between coefficients and the grid:

- ``P x = (phi, phi', phi'')``: an inverse real FFT of ``C_n = b_n - i a_n`` times
  ``1, i n w, -(n w)^2``; its transpose ``P^T (w_0, w_1, w_2)``: ``W_u = rfft(w_u)``,
  ``U_n = sum_u beta_u conj(W_u)_n``, ``d/db_n = Re U_n``, ``d/da_n = Im U_n``;
- ``Q y = (p_x'', p_z'', beta')``: ``xi_d'' = Re sum_k -(k w)^2 Xi_{k,d} e^{iks}``,
  ``beta' = Re sum_k i k w Xi_{k,beta} e^{iks}``, ``p'' = G xi''``; the transpose of
  ``X -> Re(alpha X e^{iks})`` is ``w -> conj(alpha) W_k`` (the gradient of a complex unknown
  written ``d/dRe + i d/dIm``);
- ``Pi r``: the Galerkin projection, ``(2 / M) rfft(r)_k`` (``k >= 1``), the mean for the
  static rows; ``Pi^T lambda = (2 / M) Re sum_k lambda_k e^{iks}`` (plus ``lambda_0 / M``).

The hull's equations at ``phi``, ``S(phi) y = b(phi)`` (Eq. H projected)::

    S y = Z y + Pi_beta [m l (cos(phi) p_x''(y) - sin(phi) p_z''(y))],   b = F a + Pi r(phi)

with ``Z`` block diagonal in frequency (``Z_k``, 3 x 3 complex, inverted once) and ``r``
the pendulum's reaction at rest in the hull (:func:`._hull_kernel.reaction`). ``S y = b``,
the adjoint ``S^T lambda = d<f>/dy`` and the sensitivities are solved by GMRES
(:func:`gmres`) preconditioned by ``Z^{-1}``: each iteration two FFTs
of the grid, ``O(M log M)``. The Lagrangian's pointwise derivatives are the compiled ones
of the dense solver (:mod:`._hull_kernel`: ``objective_weights``, ``constraint_weights``),
so the gradient ``P^T d_1`` is the dense solver's to the GMRES tolerance, and the reduced
Hessian ``H = L_xx + L_xy T + T^T L_yx + T^T L_yy T`` is applied to a vector ``v`` as

    z = (P v, Q T v),  T v = S^{-1} Pi (rho_X P v),
    H v = P^T (D_2 z)_X + T^T Q^T (D_2 z)_Q,   T^T u = P^T rho_X^T Pi^T S^{-T} u,

``D_2`` the pointwise 6 x 6 second derivatives, ``rho_X`` the reaction's derivatives in
``(phi, phi', phi'')`` (two GMRES solves per product, nothing of size ``N^2`` stored).
Newton's step is then truncated, preconditioned conjugate gradients
(:func:`parapend.optimal.fourier.newton_maximize`'s operator path) with the exact diagonal
of ``L_xx`` as the preconditioner (the reduced Hessian's own diagonal is 1.2 to 2.6 times
it at the 50-wave barge's maximum, and its rows are far from diagonal at low harmonics).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import scipy.fft
from scipy.sparse.linalg import LinearOperator

from ..optimal.fourier import HessianOperator, _pad, newton_maximize
from . import hull as _hull
from ._hull_kernel import constraint_weights, objective_weights, reaction, torque
from .hull import (
    GTOL,
    HullCase,
    HullProblem,
    HullSolution,
    _refine,
    aliased,
    hull_points,
    hull_search,
    ideal_problem,
    settled,
)

__all__ = ["KrylovHullProblem", "KrylovHessian"]

#: GMRES's relative residual for the hull's state and the adjoint (their error is the
#: gradient's, and so the optimum's): rounding's scale
STATE_RTOL = 1e-14
#: ... and for the sensitivities inside a Hessian product (Newton's step only needs the
#: product to the CG's forcing term, at least 1e-4)
PRODUCT_RTOL = 1e-8
#: the energy balance's residual above which a coupled state is the grid's aliasing, not a
#: motion (its power is then NaN: the line search steps back); at an answer it is ~1e-12
BALANCE_TOL = 1e-4
#: GMRES's restart length and its restarts at most
RESTART, MAX_RESTARTS = 40, 20


def _rfft(a):
    return scipy.fft.rfft(a, axis=-1)


def _irfft(c, m):
    return scipy.fft.irfft(c, m, axis=-1)


def gmres(apply_a, apply_m, b, *, rtol, x0=None, restart=RESTART,
          max_restarts=MAX_RESTARTS) -> tuple[np.ndarray, bool, int]:
    """``A^{-1} b`` by restarted GMRES, right-preconditioned by ``M`` (``apply_a``,
    ``apply_m``: the products), from ``x0`` (None: zero, no product spent on it): until
    ``||b - A x|| <= rtol ||b||``. Returns ``(x, converged, iterations)``.

    Right preconditioning makes the least-squares residual of the Arnoldi relation the true
    residual (in exact arithmetic), so no product is spent to check it (orthogonalization:
    classical Gram-Schmidt twice, which keeps the basis orthogonal to rounding); the solve
    ends once that residual is within ``rtol``, or after ``max_restarts`` cycles of
    ``restart`` iterations, each cycle restarted from the true residual. On the hull's
    states (five to seven iterations at the tolerance of rounding)
    :func:`scipy.sparse.linalg.gmres` (left-preconditioned) spent two products more a
    solve (the start's residual and the end's check) and about as much again in its
    per-iteration Python: the record of Hs 1.5 m, Te 6 s of the 6 x 6 barge matrix (5616
    harmonics) took 128 s of CPU with it, 102 s with this one, the same optimum to 2e-14."""
    b = np.asarray(b, dtype=float)
    n = b.size
    bn = float(np.linalg.norm(b))
    if bn == 0.0:
        return np.zeros(n), True, 0
    if not math.isfinite(bn):  # nothing to solve: a NaN state, at once
        return np.full(n, np.nan), False, 0
    tol = rtol * bn
    if x0 is None:
        x, r = np.zeros(n), b.copy()
    else:
        x = np.array(x0, dtype=float)
        r = b - apply_a(x)
    rn = float(np.linalg.norm(r))
    its = 0
    for _ in range(max_restarts):
        if rn <= tol:
            return x, True, its
        v = np.empty((restart + 1, n))
        h = np.zeros((restart + 1, restart))
        cs, sn = np.zeros(restart), np.zeros(restart)
        g = np.zeros(restart + 1)
        v[0] = r / rn
        g[0] = rn
        k, done = restart, False
        for j in range(restart):
            w = apply_a(apply_m(v[j]))
            basis = v[:j + 1]
            c1 = basis @ w
            w -= c1 @ basis
            c2 = basis @ w
            w -= c2 @ basis
            hn = float(np.linalg.norm(w))
            if not math.isfinite(hn):  # the operator gave NaN: no restart mends that
                return np.full(n, np.nan), False, its + 1
            col = h[:, j]
            col[:j + 1] = c1 + c2
            col[j + 1] = hn
            for i in range(j):  # the earlier rotations
                a0, a1 = col[i], col[i + 1]
                col[i], col[i + 1] = cs[i] * a0 + sn[i] * a1, cs[i] * a1 - sn[i] * a0
            rho = math.hypot(col[j], hn)
            cs[j], sn[j] = (col[j] / rho, hn / rho) if rho > 0 else (1.0, 0.0)
            col[j], col[j + 1] = rho, 0.0
            g[j + 1] = -sn[j] * g[j]
            g[j] *= cs[j]
            its += 1
            if hn > 0.0:
                v[j + 1] = w / hn
            if abs(g[j + 1]) <= tol or hn == 0.0:
                k, done = j + 1, True
                break
        y = _upper_solve(h[:k, :k], g[:k])
        x += apply_m(y @ v[:k])
        if done:
            return x, True, its
        r = b - apply_a(x)
        rn = float(np.linalg.norm(r))
    return x, rn <= tol, its


def _upper_solve(r, g) -> np.ndarray:
    """``r^{-1} g`` for the upper triangular ``r`` (a zero pivot's component left zero)."""
    y = np.zeros(g.size)
    for i in range(g.size - 1, -1, -1):
        if r[i, i] != 0.0:
            y[i] = (g[i] - r[i, i + 1:] @ y[i + 1:]) / r[i, i]
    return y


class KrylovHullProblem(HullProblem):
    """:class:`~parapend.hydro.hull.HullProblem`'s objective, gradient and Hessian
    (an operator) without any matrix of the harmonics' size: memory ``O(M)``, each
    evaluation a few GMRES solves of ``O(M log M)`` iterations.

    The same constructor's arguments and the same methods (``power``, ``evaluate``,
    ``grid_state``, ``balance``, ``solve_hull``, ``harmonics_of``); ``evaluate`` returns a
    :class:`KrylovHessian` for the Hessian (``hessian = "operator"``)."""

    hessian = "operator"

    def __init__(self, case: HullCase, coupled: bool = True, eta=None,
                 copper_loss: float = 0.0):
        self.case = case
        self.coupled = coupled
        self.set_efficiency(eta)
        self.copper_loss = float(copper_loss)
        n, nh, m = case.harmonics, case.hull_harmonics, case.points
        w = case.omega
        self.harmonics, self.points, self.winding, self.omega = n, m, case.winding, w
        self.s = 2 * math.pi * np.arange(m) / m
        cp = case.stiffness()
        self.static = [d for d in range(3) if cp[d, d] > 0]
        j0 = len(self.static)
        self.ny = j0 + 6 * nh
        self._kn = w * np.arange(1, n + 1)  # n w
        self._kh = w * np.arange(1, nh + 1)  # k w
        zk = case.impedances(nh) if nh else \
            np.zeros((0, 3, 3), complex)
        self._zk = zk
        self._zkinv = np.linalg.inv(zk) if nh else zk
        # the blocks as (3, 3, Nh), and their conjugate transposes (the adjoint's)
        self._zt = np.ascontiguousarray(zk.transpose(1, 2, 0))
        self._zth = np.ascontiguousarray(zk.conj().transpose(2, 1, 0))
        self._zinvt = np.ascontiguousarray(self._zkinv.transpose(1, 2, 0))
        self._zinvth = np.ascontiguousarray(self._zkinv.conj().transpose(2, 1, 0))
        self._z0 = cp[np.ix_(self.static, self.static)]
        self._z0inv = np.linalg.inv(self._z0) if j0 else self._z0
        self._fa = case.wave_force()[1:]
        self._pitch_static = self.static.index(2) if 2 in self.static else -1
        self.y_free = self._flat(np.zeros(j0), np.einsum("kij,kj->ki", self._zkinv,
                                                         self._fa))
        self.w = np.array([case.m * case.g * case.l * w])
        self._last = None
        self._y_guess = None
        self._constants = {}
        self.gmres_iterations = 0
        self.products = 0

    # -- layout: y = [Xi_0 (static DOFs), (Re Xi_k, Im Xi_k) per k] as the dense solver's ----
    def _flat(self, y0, xk) -> np.ndarray:
        nh = xk.shape[0]
        body = np.empty((nh, 2, 3))
        body[:, 0, :], body[:, 1, :] = xk.real, xk.imag
        return np.concatenate((np.asarray(y0, float), body.ravel()))

    def _split(self, y):
        j0 = len(self.static)
        body = np.asarray(y[j0:]).reshape(-1, 2, 3)
        return np.asarray(y[:j0]), body[:, 0, :] + 1j * body[:, 1, :]

    def harmonics_of(self, y) -> np.ndarray:
        y0, xk = self._split(y)
        xi = np.zeros((xk.shape[0] + 1, 3), dtype=complex)
        for i, d in enumerate(self.static):
            xi[0, d] = y0[i]
        xi[1:] = xk
        return xi

    # -- the grid maps ------------------------------------------------------------------------
    def _synth(self, c):
        """``Re sum_k c_k e^{iks}`` on the grid (``c``: (..., K), k = 1..K)."""
        m = self.points
        full = np.zeros(c.shape[:-1] + (m // 2 + 1,), dtype=complex)
        full[..., 1:c.shape[-1] + 1] = c * (0.5 * m)
        return _irfft(full, m)

    def _motion(self, x):
        """``(phi, phi', phi'')`` on the grid (3, M): ``P x`` plus the winding."""
        n, w, k = self.harmonics, self.omega, self.winding
        cn = x[n + 1:] - 1j * x[1:n + 1]
        g = self._synth(np.stack((cn, 1j * self._kn * cn, -self._kn**2 * cn)))
        g[0] += k * self.s + x[0]
        g[1] += w * k
        return g

    def _dmotion(self, v):
        """``P v`` (3, M): the motion's linear part."""
        n = self.harmonics
        cn = v[n + 1:] - 1j * v[1:n + 1]
        g = self._synth(np.stack((cn, 1j * self._kn * cn, -self._kn**2 * cn)))
        g[0] += v[0]
        return g

    def _motion_t(self, w3):
        """``P^T (w_0, w_1, w_2)``."""
        n = self.harmonics
        wf = np.conj(_rfft(w3)[:, 1:n + 1])
        u = wf[0] + 1j * self._kn * wf[1] - self._kn**2 * wf[2]
        out = np.empty(2 * n + 1)
        out[0] = float(np.sum(w3[0]))
        out[1:n + 1] = u.imag
        out[n + 1:] = u.real
        return out

    def _pivot(self, xk):
        """``Q y = (p_x'', p_z'', beta')`` (3, M) from the harmonics ``xk`` (Nh, 3)."""
        dp, hp = self.case.pivot
        k2 = -self._kh**2
        c = np.stack((k2 * (xk[:, 0] + hp * xk[:, 2]), k2 * (xk[:, 1] - dp * xk[:, 2]),
                      1j * self._kh * xk[:, 2]))
        return self._synth(c)

    def _pivot_t(self, w3):
        """``Q^T (w_x, w_z, w_b)``: (Nh, 3) complex (``d/dRe + i d/dIm``)."""
        dp, hp = self.case.pivot
        nh = self._kh.size
        wf = _rfft(w3)[:, 1:nh + 1]
        k2 = -self._kh**2
        out = np.empty((nh, 3), dtype=complex)
        out[:, 0] = k2 * wf[0]
        out[:, 1] = k2 * wf[1]
        out[:, 2] = k2 * (hp * wf[0] - dp * wf[1]) - 1j * self._kh * wf[2]
        return out

    def _project(self, r):
        """``Pi r``: ``(static means, (2/M) rfft(r)_k)`` of the reaction ``r`` (3, M)."""
        m, nh = self.points, self._kh.size
        y0 = np.array([float(np.mean(r[d])) for d in self.static])
        return y0, (2.0 / m) * _rfft(r)[:, 1:nh + 1].T

    def _lift(self, y0, lk):
        """``Pi^T lambda`` (3, M)."""
        m = self.points
        mu = self._synth((2.0 / m) * lk.T)
        for i, d in enumerate(self.static):
            mu[d] += y0[i] / m
        return mu

    # -- the hull matrix S and its transpose, on GMRES's real vectors -------------------------
    # GMRES works in its own layout: the static offsets, then the complex (3, Nh) harmonics
    # (DOF-major) viewed as reals, so that a vector's harmonics are a view, not a copy, and
    # Z's 3 x 3 blocks apply as nine products of length Nh
    def _to_inner(self, y) -> np.ndarray:
        y0, xk = self._split(y)
        return np.concatenate((y0, np.ascontiguousarray(xk.T).ravel().view(float)))

    def _from_inner(self, u) -> np.ndarray:
        y0, xt = self._inner(u)
        return self._flat(y0, xt.T)

    def _inner(self, u):
        j0 = len(self.static)
        return u[:j0], np.ascontiguousarray(u[j0:]).view(complex).reshape(3, -1)

    @staticmethod
    def _outer(y0, xt) -> np.ndarray:
        return np.concatenate((y0, np.ascontiguousarray(xt).ravel().view(float)))

    @staticmethod
    def _blocks(z, xt):
        """``z_k x_k`` for each harmonic: ``z`` (3, 3, Nh), ``xt`` (3, Nh)."""
        out = z[:, 0] * xt[0]
        out += z[:, 1] * xt[1]
        out += z[:, 2] * xt[2]
        return out

    def _apply_s(self, u, sn, co, transpose=False):
        """``S y`` (``S^T y``) in GMRES's layout: ``Z`` block by block, and the coupling's
        pitch rows by three FFTs (the pivot's acceleration, and the pitch moment's
        projection; transposed, the pitch row lifted to the grid, and the acceleration's
        transpose)."""
        y0, xt = self._inner(u)
        ml = self.case.m * self.case.l
        dp, hp = self.case.pivot
        m, nh = self.points, self._kh.size
        k2 = -self._kh**2
        ps = self._pitch_static
        if not transpose:
            z0 = self._z0 @ y0
            zx = self._blocks(self._zt, xt)
            q = self._synth(np.stack((k2 * (xt[0] + hp * xt[2]), k2 * (xt[1] - dp * xt[2]))))
            h = ml * (co * q[0] - sn * q[1])
            if ps >= 0:
                z0[ps] += float(np.mean(h))
            zx[2] += (2.0 / m) * _rfft(h)[1:nh + 1]
            return self._outer(z0, zx)
        z0 = self._z0.T @ y0
        zx = self._blocks(self._zth, xt)
        mu2 = self._synth((2.0 / m) * xt[2])
        if ps >= 0:
            mu2 += y0[ps] / m
        wf = _rfft(np.stack((ml * co * mu2, -ml * sn * mu2)))[:, 1:nh + 1]
        zx[0] += k2 * wf[0]
        zx[1] += k2 * wf[1]
        zx[2] += k2 * (hp * wf[0] - dp * wf[1])
        return self._outer(z0, zx)

    def _apply_zinv(self, u, transpose=False):
        """``Z^{-1} y`` (``Z^{-T} y``) in GMRES's layout."""
        y0, xt = self._inner(u)
        if transpose:
            return self._outer(self._z0inv.T @ y0, self._blocks(self._zinvth, xt))
        return self._outer(self._z0inv @ y0, self._blocks(self._zinvt, xt))

    def _solve_s(self, b, sn, co, transpose=False, rtol=STATE_RTOL, x0=None):
        """``S^{-1} b`` (``S^{-T} b``) by GMRES right-preconditioned by ``Z^{-1}``
        (:func:`gmres`; flat vectors in the dense solver's layout)."""
        n = b.size
        if not self.coupled:
            return self._from_inner(self._apply_zinv(self._to_inner(b), transpose))
        bi = self._to_inner(b)
        y, ok, its = gmres(lambda v: self._apply_s(v, sn, co, transpose),
                           lambda v: self._apply_zinv(v, transpose), bi, rtol=rtol,
                           x0=None if x0 is None else self._to_inner(x0))
        self.gmres_iterations += its
        if not ok:  # not reached: the residual it has is checked by the caller's scale
            res = np.linalg.norm(self._apply_s(y, sn, co, transpose) - bi)
            if not res <= 1e3 * rtol * max(float(np.linalg.norm(bi)), 1e-300):
                return np.full(n, np.nan)
        return self._from_inner(y)

    # -- the state ------------------------------------------------------------------------------
    def _at(self, x) -> tuple:
        x = np.asarray(x, dtype=float)
        key = x.tobytes()
        if self._last is not None and self._last[0] == key:
            return self._last[1]
        cs = self.case
        ml = cs.m * cs.l
        dp, hp = cs.pivot
        f, f1, f2 = self._motion(x)
        r, _, sn, co = reaction(f, f1, f2, ml, cs.I, cs.g, dp, hp)
        if self.coupled:
            b0, bk = self._project(r)
            b = self._flat(b0, self._fa + bk)
            y = self._solve_s(b, sn, co, x0=self._y_guess)
            if np.all(np.isfinite(y)):
                self._y_guess = y
        else:
            y = self.y_free
        _, xk = self._split(y)
        qx, qz, b1 = self._pivot(xk)
        tau, v, p = torque(sn, co, f1, f2, qx, qz, b1, cs.I, cs.c, ml, cs.g)
        if not np.all(np.isfinite(y)):
            p = math.nan
        elif self.coupled and not self._balance(y, p, v)[2] <= BALANCE_TOL:
            # the grid's products alias (a motion far outside the answer's band: the hull's
            # response then grows without bound, its power an artefact): no candidate
            p = math.nan
        st = {"phi": f, "phi1": f1, "phi2": f2, "qx": qx, "qz": qz, "b1": b1, "y": y,
              "tau": tau, "relative_speed": v, "power": p, "sin_phi": sn, "cos_phi": co}
        self._last = (key, (st, None))
        return self._last[1]

    def _balance(self, y, p, v):
        """:meth:`balance`'s ``(P, hull side, residual)`` from the state's ``y``, power and
        relative speed (vectorized over the harmonics)."""
        cs = self.case
        _, xk = self._split(y)
        u = 1j * self._kh[:, None] * xk
        b = 0.5 * (cs.B[1:] + np.swapaxes(cs.B[1:], 1, 2))
        absorbed = 0.5 * float(np.sum(np.real(np.conj(self._fa) * u)))
        radiated = 0.5 * float(np.real(np.einsum("ki,kij,kj->", np.conj(u), b, u)))
        lhs = p + cs.c * float(np.mean(v**2))
        hull = absorbed - radiated
        scale = max(abs(absorbed), abs(radiated), abs(lhs), 1e-300)
        return p, hull, abs(lhs - hull) / scale

    def balance(self, x) -> tuple[float, float, float]:
        """:meth:`~parapend.hydro.hull.HullProblem.balance`, vectorized."""
        st = self.grid_state(x)
        return self._balance(st["y"], st["power"], st["relative_speed"])

    def evaluate(self, x):
        """``(P, gradient, Hessian operator)`` of the reduced power in ``x``: the
        Lagrangian's pointwise derivatives (the adjoint ``S^T lambda = d<f>/dy`` by GMRES),
        the gradient ``P^T d_1``, and :class:`KrylovHessian`."""
        st, _ = self._at(x)
        cs = self.case
        ml = cs.m * cs.l
        dp, hp = cs.pivot
        terms = self._objective(st)
        full = [self._full(t) for t in terms[1:]]
        sn, co = st["sin_phi"], st["cos_phi"]
        d1, d2 = objective_weights(sn, co, st["qx"], st["qz"], *full, ml, cs.I, cs.c, cs.g)
        sens = None
        if self.coupled:
            g0 = np.zeros(len(self.static))
            gy = self._flat(g0, self._pivot_t(d1[3:]))
            lam = self._solve_s(gy, sn, co, transpose=True)
            mu = self._lift(*self._split(lam))
            c1, c2, sens = constraint_weights(sn, co, st["phi1"], st["phi2"], st["qx"],
                                              st["qz"], mu, ml, cs.I, cs.g, dp, hp)
            d1 = d1 + c1
            d2 = d2 + c2
        grad = self._motion_t(d1[:3])
        val = st["power"] if self.lossless else float(np.mean(terms[0]))
        return val, grad, KrylovHessian(self, st, d2, sens)

    # -- the sensitivities ----------------------------------------------------------------------
    def sensitivity(self, v, st, sens):
        """``T v = S^{-1} Pi (rho_X P v)`` (flat y)."""
        dx = self._dmotion(v)
        drho = np.stack([sum(sens[3 * d + i] * dx[i] for i in range(3)) for d in range(3)])
        b0, bk = self._project(drho)
        return self._solve_s(self._flat(b0, bk), st["sin_phi"], st["cos_phi"],
                             rtol=PRODUCT_RTOL)

    def sensitivity_t(self, u, st, sens):
        """``T^T u = P^T rho_X^T Pi^T S^{-T} u``."""
        return self._motion_t(self._sensitivity_t_grid(u, st, sens))

    def _sensitivity_t_grid(self, u, st, sens):
        """``rho_X^T Pi^T S^{-T} u`` on the grid (3, M): :meth:`sensitivity_t` before its
        ``P^T`` (which the Hessian's product shares with ``L_xx``'s)."""
        lam = self._solve_s(u, st["sin_phi"], st["cos_phi"], transpose=True,
                            rtol=PRODUCT_RTOL)
        mu = self._lift(*self._split(lam))
        return np.stack([sum(sens[3 * d + i] * mu[d] for d in range(3)) for i in range(3)])


#: the rows of the 21 pointwise pairs (``_hull_kernel._pair``) as a symmetric 6 x 6 table
_PAIR = np.array([[u * 6 - (u * (u - 1)) // 2 + (w - u) if w >= u else
                   w * 6 - (w * (w - 1)) // 2 + (u - w) for w in range(6)] for u in range(6)])


class KrylovHessian(HessianOperator):
    """The reduced Hessian of :class:`KrylovHullProblem` at one point as an operator:
    ``matvec(v) = H v`` (two GMRES solves, a few FFTs), ``diagonal`` an estimate of
    ``-H``'s diagonal for the conjugate gradients' preconditioner: ``L_xx``'s exact diagonal
    (from the FFTs of its weights at frequencies 0 and 2n), the hull's terms left out."""

    mostly_positive = False

    def __init__(self, problem: KrylovHullProblem, st, d2, sens):
        self.problem = problem
        self.st = st
        self.d2 = d2
        self.sens = sens
        self._d6 = None
        self._low = None
        self.diagonal = -self._diag_xx()

    def _diag_xx(self):
        pr = self.problem
        n, kn = pr.harmonics, pr._kn
        rows = [_PAIR[u, w] for u, w in ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))]
        wf = _rfft(self.d2[rows])
        c0 = wf[:, 0].real[:, None]
        two = wf[:, 2:2 * n + 1:2]
        c2, s2 = two.real, -two.imag
        ss, cc, sc = 0.5 * (c0 - c2), 0.5 * (c0 + c2), 0.5 * s2
        w00, w01, w02, w11, w12, w22 = range(6)
        da = (ss[w00] + 2 * kn * sc[w01] - 2 * kn**2 * ss[w02] + kn**2 * cc[w11]
              - 2 * kn**3 * sc[w12] + kn**4 * ss[w22])
        db = (cc[w00] - 2 * kn * sc[w01] - 2 * kn**2 * cc[w02] + kn**2 * ss[w11]
              + 2 * kn**3 * sc[w12] + kn**4 * cc[w22])
        return np.concatenate(([c0[w00, 0]], da, db))

    def matvec(self, v):
        """``H v``."""
        pr = self.problem
        pr.products += 1
        v = np.asarray(v, dtype=float).ravel()
        dx = pr._dmotion(v)
        z = np.zeros((6, pr.points))
        z[:3] = dx
        if pr.coupled:
            ty = pr.sensitivity(v, self.st, self.sens)
            z[3:] = pr._pivot(pr._split(ty)[1])
        if self._d6 is None:  # the pointwise 6 x 6 matrices, once per point
            self._d6 = np.ascontiguousarray(self.d2[_PAIR])
        wz = np.einsum("uwm,wm->um", self._d6, z)
        wx = wz[:3]
        if pr.coupled:  # P^T (w_X + rho_X^T Pi^T S^{-T} Q^T w_Q): one P^T for both
            u = pr._flat(np.zeros(len(pr.static)), pr._pivot_t(wz[3:]))
            wx = wx + pr._sensitivity_t_grid(u, self.st, self.sens)
        return pr._motion_t(wx)

    def precondition(self, r):  # the diagonal only (``mostly_positive`` is False)
        return r / np.abs(self.diagonal)

    def low_rank(self):
        """The conjugate gradients' preconditioner for a smoothed efficiency's kink (None
        without one): ``M = D' + G W G^T``, applied by Woodbury's identity.

        The kink's curvature ``e''(p_j) = b s^2 / (p_j^2 + s^2)^{3/2}`` is a rank-one term
        ``|e''_j| g_j g_j^T / M`` of ``-H`` per grid point, ``g_j = dp_j / dx``: at the
        last widths a few hundred points near ``p = 0`` carry curvatures ``|b| / s`` that
        the diagonal does not tame (the 10-wave barge record's last width: 1234
        conjugate-gradient products per step to 1e-4 on its diagonal, 31 on this one). The
        points ``|p_j| < KINK_BAND s`` are taken, ``g_j`` is their row of ``p``'s
        Jacobian: the pendulum's part exactly, the hull's through ``Z^{-T}`` in place of
        ``S^{-T}`` (:meth:`_kink_rows`); ``D'`` is ``L_xx``'s exact diagonal less those
        points' kink part (floored at ``1e-6`` of itself)."""
        if self._low is None:
            self._low = (self._kink_preconditioner(),)
        return self._low[0]

    def _kink_preconditioner(self):
        from scipy.linalg import cho_factor, cho_solve

        pr = self.problem
        if pr.b == 0.0 or pr.width <= 0.0:
            return None
        st = self.st
        p = -st["tau"] * st["relative_speed"]
        band = np.nonzero(np.abs(p) < KINK_BAND * pr.width)[0]
        if band.size == 0 or band.size > KINK_SHARE * p.size:
            return None  # no kink, or a width that smooths it over the grid
        w = np.abs(pr._e(p[band])[2]) / pr.points
        g0, gh = self._kink_rows(band)
        g = g0 if gh is None else g0 + gh
        dg = np.abs(self.diagonal)
        dp = np.maximum(self.diagonal - np.einsum("ik,k,ik->i", g0, w, g0),
                        1e-6 * dg + 1e-300)
        try:
            if band.size >= dp.size:  # more points than unknowns: M itself
                full = cho_factor(np.diag(dp) + (g * w) @ g.T)
                return lambda r: cho_solve(full, r)
            dinv = 1.0 / dp
            dgv = dinv[:, None] * g
            cap = cho_factor(np.diag(1.0 / w) + g.T @ dgv)
        except np.linalg.LinAlgError:
            return None

        def apply(r):
            y = dinv * r
            return y - dgv @ cho_solve(cap, g.T @ y)

        return apply

    def _kink_rows(self, band):
        """The rows ``dp_j / dx`` (columns of the result, ``(2N + 1, K)``) of the points
        ``band``: the pendulum's part ``P^T (dp_j / d(phi, phi', phi''))`` exactly (the
        trigonometric basis at ``s_j``), and the hull's ``T^T Q^T (dp_j / dq)`` with
        ``S^{-T}`` replaced by the frequency-diagonal ``Z^{-T}`` (None one-way)."""
        pr, st = self.problem, self.st
        cs = pr.case
        ml = cs.m * cs.l
        n, kn = pr.harmonics, pr._kn
        sn, co = st["sin_phi"][band], st["cos_phi"][band]
        tau, v = st["tau"][band], st["relative_speed"][band]
        qx, qz = st["qx"][band], st["qz"][band]
        # dp = -(v dtau + tau dv), dtau = (-m l w_phi, c, I, m l cos, -m l sin, -c)
        c0 = v * ml * ((cs.g + qz) * co + qx * sn)
        c1 = -(v * cs.c + tau)
        c2 = -v * cs.I
        ang = np.outer(pr.s[band], np.arange(1, n + 1))
        sa, ca = np.sin(ang), np.cos(ang)
        k1, k2 = kn[None, :], kn[None, :] ** 2
        a = c0[:, None] * sa + c1[:, None] * k1 * ca - c2[:, None] * k2 * sa
        b = c0[:, None] * ca - c1[:, None] * k1 * sa - c2[:, None] * k2 * ca
        g0 = np.concatenate((c0[:, None], a, b), axis=1).T
        if not pr.coupled:
            return g0, None
        dpv, hp = cs.pivot
        kh = pr._kh
        m = pr.points
        cx, cz, cb = -v * ml * co, v * ml * sn, v * cs.c + tau
        gh = np.empty_like(g0)
        chunk = max(1, (1 << 22) // (3 * m))
        for lo in range(0, band.size, chunk):
            sl = slice(lo, lo + chunk)
            e = np.exp(-1j * np.outer(pr.s[band[sl]], kh))  # the deltas' spectra
            wx, wz, wb = cx[sl, None] * e, cz[sl, None] * e, cb[sl, None] * e
            q = np.stack((-kh**2 * wx, -kh**2 * wz,
                          -kh**2 * (hp * wx - dpv * wz) - 1j * kh * wb), axis=1)
            lam = np.einsum("ijk,njk->nik", pr._zinvth, q)
            mu = pr._synth((2.0 / m) * lam)
            grid = np.stack([sum(self.sens[3 * d + i] * mu[:, d] for d in range(3))
                             for i in range(3)], axis=1)
            wf = np.conj(_rfft(grid)[..., 1:n + 1])
            u = wf[:, 0] + 1j * kn * wf[:, 1] - kn**2 * wf[:, 2]
            gh[0, sl] = np.sum(grid[:, 0], axis=-1)
            gh[1:n + 1, sl] = u.imag.T
            gh[n + 1:, sl] = u.real.T
        return g0, gh


#: the kink's preconditioner (:meth:`KrylovHessian.low_rank`) takes the grid points with
#: ``|p| < KINK_BAND s``: there the kink's curvature is above ``1 / KINK_BAND^3`` of its
#: peak (on the 10-wave barge record 3 and 30 gave 38 and 29 products where 10 gave 29)
KINK_BAND = 10.0
#: ... when they are at most this share of the grid's points (at the first widths the band
#: holds the whole grid: the diagonal serves there, and the rows would cost ``O(M^2)``)
KINK_SHARE = 0.25

#: each coarser discretization of :func:`continued_search` has this many times fewer
#: harmonics
COARSENING = 2
#: ... and this many times the points :func:`.hull.hull_points` gives: few harmonics per
#: turn make a rough motion whose products with the hull's the usual grid aliases (the
#: 50-wave barge's coarsest search ended on aliased maxima only)
COARSE_POINTS = 2


def coarsened(case: HullCase, harmonics: int) -> HullCase:
    """``case`` with ``harmonics`` harmonics of phi and ``harmonics + max(1, K)`` of the hull
    (the coefficients at the first ones kept, the wave cut above them, ``COARSE_POINTS``
    times the grid that :func:`.hull.hull_points` gives the rest)."""
    nh = min(case.hull_harmonics, harmonics + max(1, abs(case.winding)))
    amps = np.asarray(case.amplitudes)[:nh]
    return dataclasses.replace(
        case, harmonics=harmonics, hull_harmonics=nh, amplitudes=amps,
        points=COARSE_POINTS * hull_points(harmonics, nh, case.winding, amps.size),
        A=np.asarray(case.A)[:nh + 1], B=np.asarray(case.B)[:nh + 1],
        F=np.asarray(case.F)[:nh + 1])


#: the gradient tolerance (relative to m g l w, as :data:`.hull.GTOL`) of the continuation's
#: climbs whose maximum is not an answer but the next finer discretization's start (the
#: finer one's maximum moves from it by far more: the 200-wave barge's padded maxima start
#: 0.1 % to 1 % below the finer maxima), and of a refined answer's first stage (climbed
#: again on twice the harmonics to GTOL; its power, in the refinement's history, within
#: 2e-9 of the GTOL one's on that barge, the refinement's change 1e-3): the last Newton
#: steps are the dearest (the most conjugate-gradient products each), and on that barge
#: 1e-4 cut a level and the next together by a fifth against GTOL, to the same maximum
#: (1e-3 stops while Newton still creeps: the next level pays it back and more)
LEVEL_GTOL = 1e-4


def continued_search(make, *, refine: bool = True, level: bool = False, pto=None,
                     screen=None):
    """:func:`.hull.hull_search` of a long record by continuation in the harmonics: the
    search over the starts on the record with ``COARSENING`` times fewer harmonics (itself
    continued while it has at least ``LONG_RECORD_HARMONICS``), then its best coupled and
    one-way maxima padded to these harmonics and climbed by Newton (matrix-free), then the
    refinement as for any answer. The evidence (starts, distinct maxima) is the coarsest
    search's; the iterations are all the levels'. A ``level`` (a finer search's start) and
    an answer still to be refined are climbed to ``LEVEL_GTOL``, an answer to ``GTOL``.

    With an active take-off ``pto`` (:class:`.hull.HullPTO`) the coarsest search is the
    take-off's (its ideal maxima and least-torque motions start the smoothing's
    continuation under the limit), and each finer level continues the take-off's optimum
    and its one-way twin from the coarser ones (:func:`_continued_pto`). ``screen``: as
    :func:`.hull.hull_search`'s (an ideal take-off's answer only), called on each level's
    answer above the coarsest search and on the answer before its refinement: the first
    False ends the climb there (that level's answer, ``screened``). Each level's power
    joins the answer's ``level_history``."""
    case = make(1)
    coarse = coarsened(case, max(2, case.harmonics // COARSENING))
    if coarse.harmonics >= _hull.LONG_RECORD_HARMONICS:
        sol = continued_search(lambda scale: coarse, refine=False, level=True, pto=pto,
                               screen=screen)
        if sol.screened:
            return sol
    else:
        sol = hull_search(lambda scale: coarse, refine=False, pto=pto)
    if pto is not None and pto.active:
        return _continued_pto(case, make, sol, pto, refine)
    n = case.harmonics
    gtol = LEVEL_GTOL if level or refine else GTOL
    one = newton_maximize(ideal_problem(case, coupled=False), _pad(sol.one_way_x, n),
                          "one-way:continued", gtol=gtol)
    pr = ideal_problem(case)
    r = newton_maximize(pr, _pad(sol.x, n), f"{sol.found_by}:continued", gtol=gtol)
    status, ok = r.status, r.status == "converged"
    if ok and aliased(pr, r.x):
        status, ok = "aliased", False
    # the coarser answer is a start: what its own search said goes with it into found_by
    how = "" if sol.success else f"; the coarser search: {sol.status}"
    out = HullSolution(case=case, x=r.x, power=float(r.power),
                       one_way_power=float(one.power), one_way_x=one.x, status=status,
                       success=ok, found_by=f"{sol.found_by} (continued from "
                       f"{coarse.harmonics} harmonics{how})",
                       distinct_maxima=sol.distinct_maxima,
                       maxima_powers=sol.maxima_powers, runs=sol.runs + 2,
                       iterations=sol.iterations + r.iterations + one.iterations,
                       energy_balance_residual=float(pr.balance(r.x)[2]),
                       level_history=sol.level_history + (
                           (sol.case.harmonics, float(sol.power)),))
    if ok and (level or refine) and screen is not None and not screen(out):
        return dataclasses.replace(out, screened=True)
    if refine and ok:
        out = _refine(out, make, r.x)
    return out


def _continued_pto(case: HullCase, make, sol: HullSolution, pto, refine: bool):
    """One finer level of a take-off's long record: the coarser optimum ``sol`` (and its
    one-way twin) padded to ``case``'s harmonics and continued by the take-off's maximizer
    (:func:`.hull._pto_maximize`, the refinement's widths; the limit's multipliers from zero:
    the coarser grid's, interpolated, sit beside the finer grid's touching points, and on the
    25-wave barge record at 60 kN m they sent the climb astray where a cold start took 21
    s). The levels are the refinement: each level's power joins the
    refinement's history, and the answer's stated change is its level's against the coarser
    one (no doubling past the record's harmonics: under a limit the augmented Lagrangian's
    climbs on twice them cost more than all the levels before)."""
    n = case.harmonics
    if not math.isfinite(sol.power):
        return dataclasses.replace(sol, case=case, x=_pad(sol.x, n),
                                   one_way_x=_pad(sol.one_way_x, n), success=False)
    pr = pto.problem(case)
    width = _hull._width(sol.pto_state)
    x, ex, status, its = _hull._pto_maximize(pr, _pad(sol.x, n), pto, False, width=width)
    kkt = pr.answer
    x1, ex1, _, its1 = _hull._pto_maximize(pto.problem(case, coupled=False),
                                           _pad(sol.one_way_x, n), pto, False, width=width)
    if not math.isfinite(ex):
        return dataclasses.replace(sol, case=case, x=_pad(sol.x, n), power=math.nan,
                                   one_way_x=_pad(sol.one_way_x, n), success=False,
                                   status=f"continued to {n} harmonics: {status}")
    how = "" if sol.success else f"; the coarser search: {sol.status}"
    history = (sol.refinement_history or ((sol.case.harmonics, float(sol.power)),)) + (
        (n, float(ex)),)
    change = abs(float(ex) - float(sol.power))
    ok = status == "converged"
    if refine and change > _hull.UNRESOLVED * max(abs(ex), 1e-300):
        status = (f"{status}; the last level, {sol.case.harmonics} to {n} harmonics, changed "
                  f"the power by {change:.3g} W")
    mech = ideal_problem(case)
    return dataclasses.replace(
        sol, case=case, x=x, power=float(ex), status=status, success=ok,
        one_way_power=float(ex1) if math.isfinite(ex1) else math.nan,
        one_way_x=x1 if math.isfinite(ex1) else _pad(sol.one_way_x, n),
        found_by=f"{sol.found_by} (continued from {sol.case.harmonics} harmonics{how})",
        runs=sol.runs + 2, iterations=sol.iterations + its + its1,
        energy_balance_residual=float(mech.balance(x)[2]),
        mechanical_power=float(mech.mechanical(x)), refinement_history=history,
        refinement_change=change if refine else None, pto_state=kkt)


#: the torque limit's augmented Lagrangian, matrix-free (:func:`limited`): the first inner
#: climb stops at this gradient (relative to m g l w, as :data:`.hull.GTOL`), each next one
#: at a tenth of the one before, down to the width's tolerance (an inexact augmented
#: Lagrangian: the early multipliers are rough, and a climb to GTOL under them is wasted)
AL_GTOL = 1e-4
#: ... at most this many outer steps, and Newton iterations per inner climb
AL_MAX_OUTER, AL_MAX_NEWTON = 40, 200


def limited(problem: KrylovHullProblem, x, limit: float, gtol: float, warm: bool = False):
    """Maximize ``problem``'s objective under ``|tau| <= limit`` on its grid by the
    augmented Lagrangian of :func:`parapend.hydro.pto.torque_limited` (PHR: the same
    penalty, multiplier update and penalty growth), each inner climb by Newton with
    truncated conjugate gradients (:func:`parapend.optimal.fourier.newton_maximize`: the
    matrix-free Hessian's products, preconditioned by its diagonal), inexact: the k-th
    climb to ``max(gtol, AL_GTOL / 10^k)``. ``warm``: keep the multipliers and penalty the
    problem holds for this limit. Returns ``(x, violation, status, iterations)``;
    "converged" when the violation is at most ``LIMIT_TOL`` of the limit after a climb
    that converged to ``gtol``."""
    from .pto import LIMIT_TOL

    x = np.array(x, dtype=float)
    scale = float(problem.w[0])
    if not (warm and problem.limit == limit):
        problem.limit = None
        st = problem.state(x)
        p0 = max(abs(float(np.mean(problem._e(st["p"])[0]))), 1e-3 * scale)
        problem.set_limit(limit, 10.0 * p0 / limit**2)
    inner, prev, status, viol = 0, math.inf, "max_iterations", math.inf
    tol = max(gtol, AL_GTOL)
    for _ in range(AL_MAX_OUTER):
        r = newton_maximize(problem, x, "limit", gtol=tol, maxiter=AL_MAX_NEWTON,
                            saddle=False)
        if not (math.isfinite(r.power) and np.all(np.isfinite(r.x))):
            status = "stalled"
            break
        x = r.x
        inner += r.iterations
        viol = problem.update_multipliers(x)
        if viol <= LIMIT_TOL * limit and tol <= gtol:
            status = "converged" if r.status == "converged" else r.status
            break
        if viol > 0.25 * prev:
            problem.rho *= 10.0
        prev = viol
        tol = max(gtol, 0.1 * tol)
    return x, viol, status, inner


def pto_maximize(problem: KrylovHullProblem, x0, widths=None, limit=None,
                 max_inner: int | None = None, scale: float | None = None,
                 settle: float | None = None, start: float | None = None):
    """:func:`parapend.hydro.pto.maximize` matrix-free: the continuation in the
    efficiency's smoothing width ``s -> 0`` (``widths`` relative to the largest ``|p|`` at
    ``x0``), each width climbed by Newton with truncated conjugate gradients, under the
    torque limit by :func:`limited` (the multipliers carried from width to width). The
    widths above ``settle`` before the last two are only the path: climbed to
    ``LEVEL_GTOL``, the others (whose exact powers :func:`.hull._pto_maximize` compares) to
    ``GTOL``. Returns ``(x, exact, runs)`` as that function: the iterate with the largest
    exact (unsmoothed) objective among those within the limit, and per width ``(s, exact,
    status, iterations)``. ``max_inner``: unused (the inexact climbs bound themselves).
    ``scale``: the ``|p|`` the widths are relative to (by default the largest at ``x0``; a
    screened start's last widths, :func:`.hull._finish_screened`, keep its start's).

    ``settle``: a width (W) at or below which the continuation stops once the exact
    objective has settled (:func:`settled`: moved by at most ``PTO_SETTLED`` from the width
    before, or fell), None: every width. ``start``: the exact objective of ``x0`` when it
    is the maximum of the width before ``widths[0]`` (a continuation resumed), compared
    with the first width's."""
    from .pto import LIMIT_TOL, WIDTHS

    widths = WIDTHS if widths is None else widths
    x = np.array(x0, dtype=float)
    p0 = float(np.max(np.abs(problem.state(x)["p"]))) if scale is None else float(scale)
    best_x, best = x.copy(), (problem.exact(x) if limit is None else -math.inf)
    problem.answer = None
    runs = []
    prev = start
    for i, rel in enumerate(widths):
        problem.width = rel * p0
        near = settle is not None and problem.width <= settle
        gtol = GTOL if near or i >= len(widths) - 2 else LEVEL_GTOL
        if limit is None:
            r = newton_maximize(problem, x, "width", gtol=gtol, maxiter=AL_MAX_NEWTON,
                                saddle=False)
            x, viol, status, nit = r.x, 0.0, r.status, r.iterations
        else:
            x, viol, status, nit = limited(problem, x, limit, gtol, warm=True)
        ex = problem.exact(x)
        runs.append((rel * p0, ex, status, nit))
        ok = math.isfinite(ex) and (limit is None or viol <= LIMIT_TOL * limit)
        if ok and ex >= best:
            best, best_x = ex, np.array(x)
            problem.answer = (problem.climbed_state() if limit is None else
                              problem.climbed)
        if near and ok and prev is not None and settled(prev, ex, problem):
            break
        prev = ex if ok else None
    problem.limit = None
    return best_x, best, runs


#: Lanczos (ARPACK) for the largest eigenvalue of the reduced Hessian scaled by its diagonal
#: (below): Lanczos vectors, restarts at most, and the relative tolerance (the check is its
#: sign). Unscaled, the barge's records (240 to 5616 harmonics: the top of the spectrum
#: clusters against its width, which grows as the harmonic's fourth power) had not converged
#: within 20 restarts; scaled, a 12-wave record's converge in 51 to 71 products
#: Lanczos's budget for the second-order check (:func:`optimality`): 40 vectors and 25
#: restarts, at most about a thousand products. The scaled Hessian's spectrum crowds at its
#: top (the 100- and 200-wave rotations of the embedded barge: -0.0146 and -0.0175 over a
#: span of about 1.5), and with 20 vectors ARPACK had not converged after 20 restarts (221
#: products) where with 30 to 60 it converged in 211 to 226 (to the value shift-invert gives).
#: The tolerance is not loosened: on the 234-wave swinging record of the 4 x 4 matrix's
#: Hs 1 m, Te 7 s bin (largest -0.0300 in 141 to 211 products at 1e-2, from any start) 1e-1
#: stopped after 81 products at -0.0383, an eigenvalue below the largest
LANCZOS_VECTORS, LANCZOS_RESTARTS, LANCZOS_TOL = 40, 25, 1e-2


def _scaled(d):
    d = np.abs(np.asarray(d, dtype=float))
    return 1.0 / np.sqrt(np.maximum(d, 1e-300 + 1e-14 * float(np.max(d, initial=0.0))))


def optimality(problem: HullProblem, x) -> tuple[float, float | None, float | None]:
    """First- and second-order optimality at ``x``: the gradient's largest entry (W/rad),
    the reduced Hessian's largest eigenvalue (W/rad^2; dense only, by LAPACK; None for an
    operator), and the largest eigenvalue of the Hessian scaled by its diagonal
    ``D^-1/2 H D^-1/2`` (dimensionless; by Sylvester's law of inertia negative exactly
    where ``H`` is negative definite: a strict maximum). ``D`` is ``|diag H|`` for a dense
    Hessian, for an operator the conjugate gradients' estimate of it (its ``diagonal``),
    and the eigenvalue is then Lanczos's on the scaled products
    (:func:`scipy.sparse.linalg.eigsh`, at most ``LANCZOS_VECTORS x LANCZOS_RESTARTS``
    products; None when it has not converged to ``LANCZOS_TOL``)."""
    _, g, h = problem.evaluate(np.asarray(x, dtype=float))
    gn = float(np.max(np.abs(g)))
    if isinstance(h, np.ndarray):
        hs = 0.5 * (h + h.T)
        s = _scaled(np.diag(hs))
        return (gn, float(np.linalg.eigvalsh(hs)[-1]),
                float(np.linalg.eigvalsh(s[:, None] * hs * s[None, :])[-1]))
    n = g.size
    s = _scaled(h.diagonal)
    op = LinearOperator((n, n), matvec=lambda v: s * h.matvec(s * np.ravel(v)), dtype=float)
    return gn, None, largest_eigenvalue(op)


def largest_eigenvalue(op) -> float | None:
    """The largest eigenvalue of the symmetric operator ``op`` by Lanczos (ARPACK's implicit
    restarts, at most ``LANCZOS_VECTORS x LANCZOS_RESTARTS`` products, relative tolerance
    ``LANCZOS_TOL``); None when it has not converged."""
    from scipy.sparse.linalg import ArpackNoConvergence, eigsh

    n = op.shape[0]
    try:
        lam = eigsh(op, k=1, which="LA", ncv=min(n, LANCZOS_VECTORS), tol=LANCZOS_TOL,
                    maxiter=LANCZOS_RESTARTS, v0=np.ones(n), return_eigenvectors=False)
    except ArpackNoConvergence:
        return None
    return float(lam[0])


_hull.MATRIX_FREE.update(problem=KrylovHullProblem, search=continued_search,
                         maximize=pto_maximize)
