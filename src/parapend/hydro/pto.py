r"""The power take-off of the pendulum inside a buoy: the electrical power's optimum.

The generator converts the mechanical power ``p = -tau theta'`` with efficiency ``eta_g``
while generating and charges ``1 / eta_m`` while motoring::

    e(p) = eta_g p  (p > 0),   p / eta_m  (p < 0),   e(p) = a p + b |p|,
    a = (eta_g + 1/eta_m) / 2,   b = (eta_g - 1/eta_m) / 2 <= 0.

The torque is the inverse dynamics of the motion, ``tau = I theta'' + c theta' - m l (g +
z'') sin(theta)``, with the heave acceleration ``z'' = z_w'' + L cos(theta)`` (``L`` the
circulant operator of the pendulum's reaction on the buoy, harmonics ``-(kw)^4 m l / D_k``,
every harmonic of the grid; ``L = 0`` one-way). The objective ``<e(p)>`` is not smooth at
``p = 0``; it is maximized over the Fourier coefficients of ``theta`` with the kink smoothed,
``|p| ~ sqrt(p^2 + s^2)`` (concave in ``p`` as ``b <= 0``, and below ``e`` by at most
``|b| s``), by a trust-region Newton method (SciPy's ``trust-exact`` on the dense Hessian,
``trust-krylov`` on Hessian-vector products, the coefficients scaled by the Hessian's
estimated diagonal, :meth:`ElectricalProblem.diagonal`) with the exact gradient and Hessian (below)
and a continuation ``s -> 0`` (:func:`maximize`) and in the harmonics (:func:`ladder`);
every iterate's exact (unsmoothed) value decides which one is returned.

A torque limit ``|tau| <= T`` at the grid points is an augmented Lagrangian on the same
objective (:func:`torque_limited`): the penalty's derivatives are those of ``tau`` again.

Derivatives, with ``phi_i`` the basis of ``theta``, ``d1_i``, ``d2_i`` its derivatives in
``s = w t``, ``q = z'' / g`` and everything non-dimensional (:mod:`.coupled`)::

    dtau_i = Om^2 d2_i + gamma Om d1_i - (1 + q) cos(theta) phi_i
             + sin(theta) L(sin(theta) phi_i)
    dp_i   = -(dtau_i theta' + tau Om d1_i)
    H d    = <e'' dp[d] dp_i> + <e' d2p_i[d]>

where ``d2p_i[d]`` needs ``L`` and its adjoint ``L^T`` (the conjugate multiplier) only: a
Hessian-vector product is a few real FFTs of the grid (:meth:`ElectricalProblem.hessp`),
the dense Hessian the same product applied to the identity.
"""

from __future__ import annotations

import contextlib
import math
import numbers
import warnings
from decimal import Decimal

import numpy as np

from .. import limits
from ..errors import ParameterError

__all__ = ["ElectricalProblem", "PTOObjective", "efficiency_pair", "electrical_power", "ladder",
           "maximize", "torque_limited"]


def efficiency_pair(efficiency) -> tuple[float, float] | None:
    """``(eta_g, eta_m)`` from ``efficiency``: None, a number (both ways), a pair, or the
    text ``"ETA_G[,ETA_M]"``; each in (0, 1]."""
    if efficiency is None:
        return None
    vals = efficiency
    if isinstance(efficiency, str):
        parts = [s.strip() for s in efficiency.split(",")]
        try:
            vals = [float(s) for s in parts]
        except ValueError:
            raise ParameterError(f"efficiency: expected ETA_G or ETA_G,ETA_M (numbers in "
                                 f"(0, 1]), got {efficiency!r:.40}") from None
    elif isinstance(efficiency, (numbers.Real, Decimal)) and not isinstance(efficiency, bool):
        vals = [float(efficiency)]
    else:
        try:
            vals = [float(v) for v in efficiency]
        except (TypeError, ValueError):
            raise ParameterError(f"efficiency: expected a number in (0, 1] or a pair "
                                 f"(eta_g, eta_m), got {efficiency!r:.40}") from None
    if len(vals) not in (1, 2):
        raise ParameterError(f"efficiency: expected ETA_G or ETA_G,ETA_M, got "
                             f"{len(vals)} values")
    lo = limits.BUOY_MIN_EFFICIENCY
    for v in vals:
        if not (math.isfinite(v) and lo <= v <= 1.0):
            raise ParameterError(f"efficiency: expected numbers in (0, 1], at least {lo:g} "
                                 f"(the fraction of the power converted), got {v!r}")
    return (vals[0], vals[-1])


def _abs_mean(f: np.ndarray):
    """``<|f|>`` of the piecewise-linear periodic interpolant of the samples ``f``, exactly,
    and its gradient with respect to the samples (continuous: the dual below is C^1)."""
    m = f.size
    a, b = f, np.roll(f, -1)
    aa, ab = np.abs(a), np.abs(b)
    same = a * b >= 0
    den = np.where(same, 1.0, aa + ab)
    val = np.where(same, 0.5 * (aa + ab), (a * a + b * b) / (2 * den))
    sa, sb = np.sign(a), np.sign(b)
    ga = np.where(same, 0.5 * sa, (2 * a * den - (a * a + b * b) * sa) / (2 * den**2))
    gb = np.where(same, 0.5 * sb, (2 * b * den - (a * a + b * b) * sb) / (2 * den**2))
    return float(np.sum(val)) / m, (ga + np.roll(gb, 1)) / m


def electrical_power(p: np.ndarray, eta: tuple[float, float]) -> tuple[float, float, float]:
    """``(<e(p)>, <p+>, <p->)`` of the periodic samples ``p``, the kink of ``e`` integrated
    exactly on the piecewise-linear interpolant of the samples (``<p+> - <p-> = <p>``)."""
    p = np.asarray(p, dtype=float)
    mean = float(np.mean(p))
    absm = _abs_mean(p)[0]
    pos, neg = 0.5 * (absm + mean), 0.5 * (absm - mean)
    return eta[0] * pos - neg / eta[1], pos, neg


class _Operator:
    """The Hessian as an operator: ``matvec`` (for ``trust-krylov``) and ``dense`` (tests)."""

    def __init__(self, problem, state, size):
        self.problem = problem
        self.state = state
        self.size = size

    def matvec(self, d):
        return self.problem.hessp(self.state, d)

    def dense(self):
        return self.problem.hessp(self.state, np.eye(self.size))


class PTOObjective:
    """The power take-off's pointwise objective, shared by the heaving buoy's
    :class:`ElectricalProblem` and the hull's :class:`~parapend.hydro.hull.HullProblem`:
    the smoothed electrical power ``e_s(p) = a p + b sqrt(p^2 + s^2)`` (``a``, ``b`` from
    the efficiencies, ``s`` the ``width``) and the torque limit's augmented-Lagrangian
    penalty. A subclass provides ``points`` and ``state(x)`` (with ``"tau"`` and ``"p"``
    on the grid)."""

    a, b, width = 1.0, 0.0, 0.0
    limit = None

    def set_efficiency(self, eta) -> None:
        """``a``, ``b`` of ``e(p) = a p + b |p|`` from ``(eta_g, eta_m)`` (None: lossless)."""
        eg, em = (1.0, 1.0) if eta is None else eta
        self.a = 0.5 * (eg + 1.0 / em)
        self.b = 0.5 * (eg - 1.0 / em)

    def _e(self, p):
        s = self.width
        if s == 0.0 or self.b == 0.0:  # the kink itself (one-sided derivatives)
            return (self.a * p + self.b * np.abs(p), self.a + self.b * np.sign(p),
                    np.zeros_like(p))
        r = np.sqrt(p * p + s * s)
        return self.a * p + self.b * r, self.a + self.b * p / r, self.b * s * s / r**3

    def set_limit(self, limit: float, rho: float, lam_hi=None, lam_lo=None):
        """Penalize ``|tau| > limit`` on the grid (PHR augmented Lagrangian, per point
        ``tau - limit <= 0`` and ``-tau - limit <= 0`` with multipliers ``lam_hi``,
        ``lam_lo`` and penalty ``rho``)."""
        m = self.points
        self.limit = float(limit)
        self.rho = float(rho)
        self.lam_hi = np.zeros(m) if lam_hi is None else lam_hi
        self.lam_lo = np.zeros(m) if lam_lo is None else lam_lo

    def _penalty(self, tau):
        """``(phi, phi', phi'')`` per grid point, ``phi = -(max(0, lam + rho g)^2 - lam^2) /
        (2 rho)`` summed over both constraints ``g = +-tau - limit``."""
        r = self.rho
        hi = np.maximum(0.0, self.lam_hi + r * (tau - self.limit))
        lo = np.maximum(0.0, self.lam_lo + r * (-tau - self.limit))
        phi = -(hi * hi - self.lam_hi**2 + lo * lo - self.lam_lo**2) / (2 * r)
        return phi, -hi + lo, -r * ((hi > 0).astype(float) + (lo > 0))

    #: ``(width, limit, rho, lam_hi, lam_lo)`` of the objective that the last climb
    #: maximized (:meth:`climbed_state`), and of the iterate a driver returned (``answer``:
    #: :func:`maximize`, the hull's matrix-free twin), None before any
    climbed = None
    answer = None

    def climbed_state(self) -> tuple:
        """The objective the last climb maximized: its smoothing width, and under a limit
        the penalty and the multipliers before their last update (the augmented
        Lagrangian whose maximum the climb's iterate is)."""
        if self.limit is None:
            return (self.width, None, None, None, None)
        return self.climbed

    def set_climbed(self, state) -> None:
        """Make the objective the one ``state`` (:meth:`climbed_state`) names."""
        self.width = state[0]
        if state[1] is None:
            self.limit = None
        else:
            self.set_limit(state[1], state[2], state[3], state[4])

    def update_multipliers(self, x):
        """``lam <- max(0, lam + rho g)``; returns the largest violation ``max |tau| -
        limit`` on the grid."""
        self.climbed = (self.width, self.limit, self.rho, self.lam_hi, self.lam_lo)
        tau = self.state(x)["tau"]
        self.lam_hi = np.maximum(0.0, self.lam_hi + self.rho * (tau - self.limit))
        self.lam_lo = np.maximum(0.0, self.lam_lo + self.rho * (-tau - self.limit))
        return float(np.max(np.abs(tau))) - self.limit


class ElectricalProblem(PTOObjective):
    """``<e_s(p)>`` on the grid of a :class:`~parapend.hydro.coupled.CoupledProblem`, with
    its exact gradient and Hessian (dense, or an operator with ``hessian="operator"``).

    Parameters
    ----------
    base : CoupledProblem
        Harmonics, grid, winding, damping and the free buoy's excitation.
    gk : ndarray, complex
        The multiplier of ``L`` on the ``m // 2 + 1`` real-FFT harmonics (``q = q_w + L
        cos(theta)``; zeros one-way).
    eta : (eta_g, eta_m)
    width : float
        The smoothing ``s`` of the kink (non-dimensional power); 0: the exact objective
        (for :meth:`power` only: its derivatives are then those of the kink's one side).
    """

    def __init__(self, base, gk: np.ndarray, eta, width: float, hessian: str | None = None):
        self.base = base
        self.harmonics = base.harmonics
        self.points = base.points
        self.winding = base.winding
        self.omega = base.omega
        self.gamma = base.gamma
        self.w = base.w  # the excitation's scale (tolerances)
        self.hessian = base.hessian if hessian is None else hessian
        self.gk = np.asarray(gk, dtype=complex)
        self.qw = base.excitation.q_grid(base.points)
        self.set_efficiency(eta)
        self.width = float(width)
        m, n = self.points, self.harmonics
        k = np.arange(m // 2 + 1, dtype=float)
        self._k = k
        self._kn = k[: n + 1]

    # ---- synthesis and projection ----------------------------------------------------
    def _spec(self, d):
        """Real-FFT coefficients of ``Phi^T d`` (``d`` a vector or columns)."""
        n, m = self.harmonics, self.points
        d = np.asarray(d, dtype=float)
        c = np.zeros(d.shape[1:] + (m // 2 + 1,), dtype=complex)
        dt = np.moveaxis(d, 0, -1)
        c[..., 0] = m * dt[..., 0]
        c[..., 1:n + 1] = (0.5 * m) * (dt[..., n + 1:] - 1j * dt[..., 1:n + 1])
        return c

    def _synth(self, d):
        """``phi``, ``d1``, ``d2`` of ``d`` on the grid (last axis the grid)."""
        m = self.points
        c = self._spec(d)
        k = self._k
        return (np.fft.irfft(c, m), np.fft.irfft(1j * k * c, m),
                np.fft.irfft(-(k * k) * c, m))

    def _project(self, a, b=None, c=None):
        """``sum_t a phi_i + b d1_i + c d2_i`` for every basis function ``i`` (first axis)."""
        n = self.harmonics
        kn = self._kn
        y = np.fft.rfft(a)[..., : n + 1]
        if b is not None:
            y = y - 1j * kn * np.fft.rfft(b)[..., : n + 1]
        if c is not None:
            y = y - kn * kn * np.fft.rfft(c)[..., : n + 1]
        out = np.empty(y.shape[:-1] + (2 * n + 1,))
        out[..., 0] = y[..., 0].real
        out[..., 1:n + 1] = -y[..., 1:].imag
        out[..., n + 1:] = y[..., 1:].real
        return np.moveaxis(out, -1, 0)

    def _l(self, f):
        return np.fft.irfft(self.gk * np.fft.rfft(f, axis=-1), self.points, axis=-1)

    def _lt(self, f):
        return np.fft.irfft(np.conj(self.gk) * np.fft.rfft(f, axis=-1), self.points, axis=-1)

    # ---- the motion, the torque, the power ---------------------------------------------
    def state(self, x):
        """Grid quantities at ``x``: theta and its derivatives, q, tau, p."""
        om, gam = self.omega, self.gamma
        ph, d1, d2 = self._synth(x)
        th = self.winding * self.base.s + ph
        ths = self.winding + d1
        sn, cs = np.sin(th), np.cos(th)
        q = self.qw + self._l(cs)
        tau = om * om * d2 + gam * om * ths - (1.0 + q) * sn
        thd = om * ths
        p = -tau * thd
        return {"sn": sn, "cs": cs, "q": q, "tau": tau, "thd": thd, "p": p}

    def exact(self, x) -> float:
        """The unsmoothed ``<e(p)>`` on the grid (the kink integrated on the piecewise-linear
        interpolant)."""
        p = self.state(x)["p"]
        return float(self.a * np.mean(p) + self.b * _abs(p))

    def mechanical(self, x) -> float:
        """``<p>`` on the grid."""
        return float(np.mean(self.state(x)["p"]))

    def power(self, x) -> float:
        """The smoothed objective ``<e_s(p)>`` (less the torque penalty, if any)."""
        st = self.state(x)
        val = float(np.mean(self._e(st["p"])[0]))
        if self.limit is not None:
            val += float(np.mean(self._penalty(st["tau"])[0]))
        return val

    def _dtau_t(self, st, w):
        """``sum_t w dtau_i`` (the transpose of the torque's Jacobian applied to ``w``)."""
        om, gam = self.omega, self.gamma
        sn, cs, q = st["sn"], st["cs"], st["q"]
        return self._project(-(1.0 + q) * cs * w + sn * self._lt(sn * w), gam * om * w,
                             om * om * w)

    def _dtau(self, st, ph, d1, d2):
        om, gam = self.omega, self.gamma
        sn, cs, q = st["sn"], st["cs"], st["q"]
        return om * om * d2 + gam * om * d1 - (1.0 + q) * cs * ph + sn * self._l(sn * ph)

    def evaluate(self, x):
        """``(E_s, gradient, Hessian)``; the Hessian dense or an operator."""
        st = self.state(x)
        e, e1, e2 = self._e(st["p"])
        st["e1"], st["e2"] = e1, e2
        m = self.points
        om = self.omega
        val = float(np.mean(e))
        wt = -e1 * st["thd"]
        if self.limit is not None:
            ph0, ph1, ph2 = self._penalty(st["tau"])
            val += float(np.mean(ph0))
            wt = wt + ph1
            st["ph1"], st["ph2"] = ph1, ph2
        g = (self._dtau_t(st, wt) + self._project(np.zeros(m), -om * e1 * st["tau"])) / m
        nx = 2 * self.harmonics + 1
        if self.hessian == "operator":
            return val, g, _Operator(self, st, nx)
        h = self.hessp(st, np.eye(nx))
        h = 0.5 * (h + h.T)
        return val, g, h

    def diagonal(self, st) -> np.ndarray:
        """An estimate of the Hessian's diagonal in the Fourier basis, the scaling that
        preconditions ``trust-krylov``: the kink's term ``<e'' dp_i^2>`` alone, with the
        reaction ``L`` left out and ``cos^2, sin^2`` by their mean 1/2. With ``dp_i = A
        phi_i + B d1_i + C d2_i`` (``A = (1 + q) cos(theta) theta'``, ``B = -Om (gamma
        theta' + tau)``, ``C = -Om^2 theta'``) harmonic ``k`` has ``<|e''| ((A - k^2 C)^2 +
        k^2 B^2)> / 2``: its ``k^4`` growth is what the scaling takes out."""
        om, gam = self.omega, self.gamma
        thd = st["thd"]
        e2 = np.abs(st["e2"])
        a = (1.0 + st["q"]) * st["cs"] * thd
        b = -om * (gam * thd + st["tau"])
        c = -om * om * thd
        k2 = self._kn[1:] ** 2

        def mean(f):
            return float(np.mean(e2 * f))

        aa, ac, cc, bb = mean(a * a), mean(a * c), mean(c * c), mean(b * b)
        dk = 0.5 * (aa - 2.0 * k2 * ac + k2 * k2 * cc + k2 * bb)
        d = np.concatenate([[aa], dk, dk])
        top = float(np.max(d))
        return np.maximum(d, 1e-12 * top if top > 0 else 1.0)

    def hessp(self, st, d):
        """``H d`` (``d`` a vector, or columns: the result has the same shape).

        Every term is a projection ``sum_t a phi_i + b d1_i + c d2_i`` (the torque's
        transposed Jacobian is one too), so the terms are summed on the grid and projected
        once, and ``L(sin(theta) phi)`` is shared by ``dtau`` and its second derivative:
        the product costs 3 inverse FFTs, 3 forward ones and 3 pairs for ``L``."""
        om, gam = self.omega, self.gamma
        m = self.points
        sn, cs, q, tau, thd = st["sn"], st["cs"], st["q"], st["tau"], st["thd"]
        e1, e2 = st["e1"], st["e2"]
        ph, d1, d2 = self._synth(d)
        lsp = self._l(sn * ph)
        dtau = om * om * d2 + gam * om * d1 - (1.0 + q) * cs * ph + sn * lsp
        dp = -(dtau * thd + tau * om * d1)
        w1 = e2 * dp
        bb = -e1 * thd
        # the weight on the torque's Jacobian (transposed)
        wt = -w1 * thd - om * e1 * d1
        if self.limit is not None:
            bb = bb + st["ph1"]
            wt = wt + st["ph2"] * dtau
        if "lt_bb_sn" not in st:
            st["lt_bb_sn"] = self._lt(bb * sn)
        a = (-(1.0 + q) * cs * wt + sn * self._lt(sn * wt + bb * cs * ph)
             + bb * cs * lsp + bb * (1.0 + q) * sn * ph + cs * ph * st["lt_bb_sn"])
        b = gam * om * wt - om * w1 * tau - om * e1 * dtau
        return self._project(a, b, om * om * wt) / m


def _abs(p) -> float:
    return _abs_mean(np.asarray(p, dtype=float))[0]


#: smoothing widths of the continuation, relative to the largest |p| of the start
WIDTHS = (1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 1e-6)
#: widths after a doubling of the harmonics (started from the coarser optimum)
WIDTHS_REFINE = (1e-3, 1e-4, 1e-5, 1e-6)
#: Newton iterations per width (at the small widths Newton creeps along the kinks)
MAXITER = 200


def maximize(problem: ElectricalProblem, x0: np.ndarray, widths=None, limit=None,
             max_inner: int | None = None, settle=None):
    """Continuation ``s -> 0`` from ``x0``: a trust-region Newton method at each width from
    the last optimum (``trust-exact`` on the dense Hessian, ``trust-krylov`` on the
    operator's products: the smoothed objective is not concave in the coefficients, and a
    trust region follows its directions of positive curvature where a shifted Newton step
    creeps).

    With ``limit`` each width is solved under ``|tau| <= limit`` on the grid
    (:func:`torque_limited`, at most ``max_inner`` Newton iterations per width), and only
    iterates within the limit count.

    Returns ``(x, exact, runs)``: the iterate with the largest exact (unsmoothed) ``<e(p)>``
    on the grid, that value, and per width ``(s, exact, status, iterations)``.

    ``settle``: ``(width, settled)``, the continuation stops after a width at or below
    ``width`` (relative, as ``widths``) where ``settled(before, after)`` holds for the
    exact objectives of the width before and this one (None: every width).
    """
    from scipy.optimize import minimize

    p0 = float(np.max(np.abs(problem.state(x0)["p"])))
    widths = WIDTHS if widths is None else widths
    x = np.array(x0, dtype=float)
    best_x, best = x.copy(), problem.exact(x)
    runs = []
    gtol = 1e-9 * max(float(np.max(np.abs(problem.w))), 1e-300)
    dense = problem.hessian != "operator"
    problem.answer = None
    prev = None

    def stop(rel, ex, ok):
        """Whether the continuation stops after this width (``settle``)."""
        nonlocal prev
        done = (settle is not None and ok and prev is not None
                and rel <= settle[0] * (1 + 1e-12) and settle[1](prev, ex))
        prev = ex if ok else None
        return done

    if limit is not None:
        best = -math.inf
        for rel in widths:
            problem.width = rel * p0
            x, _, viol, _, inner, status = torque_limited(problem, x, limit, warm=True,
                                                          max_inner=max_inner)
            ex = problem.exact(x)
            runs.append((rel * p0, ex, status, inner))
            ok = math.isfinite(ex) and viol <= LIMIT_TOL * limit
            if ok and ex >= best:
                best, best_x = ex, np.array(x)
                problem.answer = problem.climbed
            if stop(rel, ex, ok):
                break
        problem.limit = None
        return best_x, best, runs
    for rel in widths:
        problem.width = rel * p0
        cache = {}

        def ev(z, cache=cache):
            key = z.tobytes()
            if key not in cache:
                cache.clear()
                cache[key] = problem.evaluate(z)
            return cache[key]

        if dense:
            r = minimize(lambda z: -ev(z)[0], x, jac=lambda z: -ev(z)[1],
                         hess=lambda z: -ev(z)[2], method="trust-exact",
                         options={"gtol": gtol, "maxiter": MAXITER})
            status = {0: "converged", 1: "max_iterations"}.get(r.status, "stalled")
            nit = int(r.nit)
        else:
            r, status, nit = _scaled_krylov(problem, ev, x, gtol)
        ex = problem.exact(r.x)
        runs.append((rel * p0, ex, status, nit))
        if math.isfinite(ex) and ex >= best:
            best, best_x = ex, np.array(r.x)
            problem.answer = problem.climbed_state()
        x = np.array(r.x)
        if stop(rel, ex, math.isfinite(ex)):
            break
    return best_x, best, runs


class _ZeroedNumpy:
    """numpy with ``empty`` allocating zeros (:func:`_trlib_zeroed`)."""

    def __getattr__(self, name):
        return getattr(np, name)

    @staticmethod
    def empty(shape, dtype=float, order="C", **kw):
        return np.zeros(shape, dtype=dtype, order=order, **kw)


@contextlib.contextmanager
def _trlib_zeroed():
    """Run ``trust-krylov`` with its workspace allocated zeroed.

    SciPy's trlib wrapper (``scipy.optimize._trlib``, ``TRLIBQuadraticSubproblem``)
    allocates trlib's floating-point workspace ``fwork`` with ``np.empty``, and
    ``trlib_krylov_prepare_memory`` sets only two slices of it; ``trlib_krylov_min`` reads
    other entries before writing them on some subproblems, so its steps depended on stale
    heap contents and a solve differed run to run in the last bits (then more, through the
    continuation). The wrapper takes ``np.empty`` from its module's ``np``: that is made a
    numpy whose ``empty`` is ``zeros`` for the duration (the allocation the workspace
    would have with ``np.zeros``). Left alone when the wrapper has no such name.

    Not covered: trlib's inverse iteration for the leftmost eigenvector (the hard case,
    ``trlib_eigen_inverse``) seeds its start vector with ``time(NULL)``, so a solve that
    reaches it can still differ in its last bits between runs started in different
    seconds."""
    try:
        from scipy.optimize._trlib import _trlib as mod
    except ImportError:  # pragma: no cover - another SciPy layout
        mod = None
    old = getattr(mod, "np", None)
    if old is None:  # pragma: no cover - another SciPy layout
        yield
        return
    mod.np = _ZeroedNumpy()
    try:
        yield
    finally:
        mod.np = old


#: restarts of a preconditioned trust-krylov solve that stalled short of the tolerance
RESTARTS = 8
#: iterations of the truncated-CG fallback per width
FALLBACK_MAXITER = 50
#: a width is settled when the smoothed value moved by at most PLATEAU_TOL (relative, the
#: rounding of a mean over the grid) in PLATEAU trust-region iterations
PLATEAU = 10
PLATEAU_TOL = 1e-13


def _plateau():
    """A SciPy callback that stops a minimization when its value has stopped moving at the
    rounding level (no step can be verified), and the list it marks when it does."""
    hist, halted = [], []

    def settled(intermediate_result):
        hist.append(float(intermediate_result.fun))
        if len(hist) > PLATEAU and hist[-PLATEAU - 1] - hist[-1] <= PLATEAU_TOL * abs(
                hist[-1]):
            halted.append(True)
            raise StopIteration

    return settled, halted


def _scaled_krylov(problem, ev, x0, gtol):
    """``trust-krylov`` on the coefficients scaled by the Hessian's estimated diagonal
    (``x = D y``, ``D = diag^(-1/2)``, :meth:`ElectricalProblem.diagonal`: a Jacobi
    preconditioner, which trlib does not take otherwise), restarted with a fresh scaling
    when trlib stalls (a step that predicts no improvement) short of ``gtol`` on the
    unscaled gradient's largest component. Returns ``(result, status, iterations)``."""
    from scipy.optimize import minimize

    x = np.array(x0, dtype=float)
    nit = 0
    status = "stalled"
    r = None
    method = "trust-krylov"
    for _ in range(RESTARTS):
        d = 1.0 / np.sqrt(problem.diagonal(ev(x)[2].state))
        settled, halted = _plateau()

        with np.errstate(invalid="ignore", over="ignore"), warnings.catch_warnings(), \
                _trlib_zeroed():
            warnings.simplefilter("ignore", RuntimeWarning)
            r = minimize(lambda y, d=d: -ev(d * y)[0], x / d,
                         jac=lambda y, d=d: -d * ev(d * y)[1],
                         hessp=lambda y, v, d=d: -d * ev(d * y)[2].matvec(d * v),
                         method=method, callback=settled,
                         options={"gtol": gtol * float(np.min(d)),
                                  "maxiter": MAXITER if method == "trust-krylov" else
                                  FALLBACK_MAXITER})
        nit += int(r.nit)
        xn = d * r.x
        if not np.all(np.isfinite(xn)):
            break
        f0, f1 = ev(x)[0], ev(xn)[0]
        moved = f1 > f0 + PLATEAU_TOL * abs(f1)
        x = xn if f1 >= f0 else x
        g = float(np.max(np.abs(ev(x)[1])))
        if g <= gtol:
            status = "converged"
            break
        if halted:
            status = "settled"
            break
        if r.status == 1:
            status = "max_iterations"
            break
        if not moved:
            if method == "trust-ncg":
                break
            # trlib found no step that predicts an improvement (at the smallest widths):
            # Steihaug's truncated CG from here
            method = "trust-ncg"
    r.x = x
    return r, status, nit


def ladder(make, x_ideal: np.ndarray, harmonics: int, start: int, limit=None):
    """The electrical optimum with ``harmonics`` terms by continuation in the harmonics:
    the full width continuation with ``start`` terms from the ideal optimum cut to them,
    then doubling (each from the last optimum, ``WIDTHS_REFINE``) up to ``harmonics``.

    ``limit``: ``|tau| <= limit`` on the grid in the last two stages. ``make(n)`` builds the
    :class:`ElectricalProblem` with ``n`` harmonics. Returns ``(x,
    exact, coarse_exact, log)``: the optimum, its exact value on its grid, the value one
    doubling before (None when ``start == harmonics``) and per stage ``(n, exact, runs)``.
    """
    from ..optimal.fourier import _pad

    ns = [harmonics]
    while ns[-1] // 2 >= start:
        ns.append(ns[-1] // 2)
    ns = ns[::-1]
    x = _pad(x_ideal, ns[0])
    log, coarse, ex = [], None, None
    for i, n in enumerate(ns):
        pr = make(n)
        x = _pad(x, n)
        coarse = ex
        # the limit in the last two stages (the refinement compares limited optima); the
        # first stages only find the basin
        lim = limit if i >= len(ns) - 2 else None
        x, ex, runs = maximize(pr, x, WIDTHS if i == 0 else WIDTHS_REFINE, lim)
        log.append((n, ex, runs))
    return x, ex, coarse, log


#: the torque limit holds on the grid to this fraction of it
LIMIT_TOL = 1e-7


def torque_limited(problem: ElectricalProblem, x0: np.ndarray, limit: float, *,
                   tol: float = LIMIT_TOL, max_outer: int = 40, warm: bool = False,
                   max_inner: int | None = None):
    """Maximize the problem's objective subject to ``|tau| <= limit`` on its grid by an
    augmented Lagrangian (PHR): each outer step a trust-region Newton solve of the
    penalized objective (exact gradient and Hessian), then ``lam <- max(0, lam + rho g)``,
    and ``rho`` times 10 when the violation fell by less than a factor 4.

    Returns ``(x, objective, violation, outer, inner, status)``: ``violation`` the largest
    ``max |tau| - limit`` on the grid at ``x``; status "converged" when it is at most
    ``tol * limit`` and the last inner solve converged. ``warm``: keep the multipliers and
    the penalty the problem holds for this limit (a continuation). ``max_inner``: at most
    so many inner iterations in all (then status "max_iterations"): each costs O(N^3).
    """
    from scipy.optimize import minimize

    x = np.array(x0, dtype=float)
    st = problem.state(x)
    scale = max(float(np.max(np.abs(problem.w))), 1e-300)
    p0 = max(abs(float(np.mean(problem._e(st["p"])[0]))), 1e-3 * scale)
    if not (warm and problem.limit == limit):
        problem.set_limit(limit, 10.0 * p0 / limit**2)
    gtol = 1e-10 * scale
    dense = problem.hessian != "operator"
    viol_prev = math.inf
    inner = 0
    status = "max_iterations"
    viol = float(np.max(np.abs(st["tau"]))) - limit
    outer = 0
    while outer < max_outer:
        if max_inner is not None and inner >= max_inner:
            break
        outer += 1
        cache = {}

        def ev(z, cache=cache):
            key = z.tobytes()
            if key not in cache:
                cache.clear()
                cache[key] = problem.evaluate(z)
            return cache[key]

        kw = ({"hess": lambda z: -ev(z)[2]} if dense else
              {"hessp": lambda z, d: -ev(z)[2].matvec(d)})
        # trlib (trust-krylov) can form 0 * inf in a step it then rejects: not an error
        with np.errstate(invalid="ignore", over="ignore"), warnings.catch_warnings(), \
                _trlib_zeroed():
            warnings.simplefilter("ignore", RuntimeWarning)
            r = minimize(lambda z: -ev(z)[0], x, jac=lambda z: -ev(z)[1],
                         method="trust-exact" if dense else "trust-krylov",
                         options={"gtol": gtol, "maxiter": MAXITER if max_inner is None
                                  else max(1, min(MAXITER, max_inner - inner))}, **kw)
        if not np.all(np.isfinite(r.x)):
            status = "stalled"
            break
        x = np.array(r.x)
        inner += int(r.nit)
        viol = problem.update_multipliers(x)
        if viol <= tol * limit and r.status != 1:
            status = "converged"
            break
        if viol > 0.25 * viol_prev:
            problem.rho *= 10.0
        viol_prev = viol
    lam_hi, lam_lo, rho = problem.lam_hi, problem.lam_lo, problem.rho
    problem.limit = None
    obj = float(np.mean(problem._e(problem.state(x)["p"])[0]))
    problem.set_limit(limit, rho, lam_hi, lam_lo)
    return x, obj, viol, outer, inner, status
