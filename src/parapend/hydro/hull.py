r"""A pendulum in a hull that surges, heaves and pitches: the objective in ``phi`` alone.

Model (SI; docs/hull.md, issue 30). Hull DOFs ``xi = (x, z, beta)`` about the rotation
centre O; the pivot at ``(d_p, h_p)`` from O moves by ``p = G xi``,
``G = [[1, 0, h_p], [0, 1, -d_p]]``; ``phi`` is the pendulum's absolute angle from the
upward vertical (centre of mass at ``p + l (sin phi, cos phi)``), ``theta = phi - beta``
the generator's angle, ``phi(t + T) = phi(t) + 2 pi K``::

    (P)  I phi'' + c (phi' - beta') - m l [(g + p_z'') sin phi - p_x'' cos phi] = tau
    (H)  (M_h + A) xi'' + B xi' + C xi = F a - G^T f + e_beta (-tau + c (phi' - beta'))
         f = m (p'' + l ((sin phi)'', (cos phi)'')),     P = -<tau (phi' - beta')>

Discretization (the issue's, shared with the independent IPOPT reference of
tests/hull_reference.py): ``phi = K s + x_0 + sum_n x_n sin(ns) + x_{N+n} cos(ns)``
(``s = w t``), the hull's harmonics ``k = 0..Nh``, (H) projected on them with the grid's
DFT (M points), the means on the grid. Given ``phi``, (H) is linear in ``xi`` but with
coefficients that vary with ``phi`` (the pivot's acceleration times ``sin phi``, ``cos phi``
in the reaction torque), so the hull's harmonics are solved together:

    S(phi) y = b(phi),   S = Z - m l Pi_beta [sin(phi) Q_z - cos(phi) Q_x]

``y`` the real hull unknowns, ``Z`` block diagonal (``Z_k = -(k w)^2 (M_h + A_k + m G^T G)
+ i k w B_k + C'``, ``C' = C - m g h_p e_beta e_beta^T``), ``Q`` the pivot's acceleration
on the grid. The power ``P(phi) = P(phi, y(phi))`` is maximized over ``x`` alone (reduced
space): its gradient by the adjoint ``S^T lambda = dP/dy``, its Hessian exactly, by the
sensitivity ``T = S^{-1} g_x`` (``S^{-1}`` by Woodbury's identity: only ``S``'s pitch rows
move with ``phi``, and ``Z`` is inverted once, block by block):

    H = L_xx + L_xy T + T^T L_yx + T^T L_yy T

with ``L`` the Lagrangian, whose dependence on ``x`` and ``y`` is a sum over grid points of
a function of ``(phi, phi', phi'', p_x'', p_z'', beta')`` (``hydro/_hull_kernel.py``): every
block is a weighted Gram matrix of the grid maps. With the hull fixed at its free response
(``coupled=False``) the same code gives the one-way problem (``T = 0``, no adjoint).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from ._hull_kernel import (
    gradient_and_weights,
    grid_motion,
    hull_state,
    hull_torque,
    reduced_hessian,
)
from ._trig import FusedGram, GramPlan, TrigColumns, spectra
from .pto import PTOObjective, _abs

__all__ = ["HullCase", "HullProblem", "hull_points"]

#: grid variables of the pointwise functions, in this order
_VARS = ("phi", "phi1", "phi2", "qx", "qz", "b1")
#: the pairs of them on which the objective's second derivative can be non-zero: every
#: pair with a ``tau_tau`` term (an efficiency, a copper loss, a limit); else those of
#: ``tau``'s own second derivative and those that hold ``v = phi' - b1``
_PAIRS = {"all": [(u, w) for i, u in enumerate(_VARS) for w in _VARS[i:]]}
_PAIRS["lossless"] = [(u, w) for u, w in _PAIRS["all"] if (u, w) in (
    ("phi", "phi"), ("phi", "qx"), ("phi", "qz")) or {u, w} & {"phi1", "b1"}]
#: the pairs on which the hull's reaction weighted by the adjoint has second derivatives
_CONSTRAINT_PAIRS = (("phi", "phi"), ("phi", "phi1"), ("phi", "phi2"), ("phi", "qx"),
                     ("phi", "qz"), ("phi1", "phi1"))


def hull_points(harmonics: int, hull_harmonics: int, winding: int, wave_harmonics: int) -> int:
    """A power of two with 8 points per harmonic of the motion and of the wave, and 4 per
    harmonic of the products ``sin(phi) xi''`` that the hull's projection reads."""
    need = max(64, 8 * (harmonics + winding), 8 * (wave_harmonics + 1),
               4 * (hull_harmonics + harmonics + winding))
    return 1 << int(math.ceil(math.log2(need)))


@dataclass(frozen=True, eq=False)
class HullCase:
    """The discretized hull problem's data (SI).

    ``A``, ``B`` (Nh+1, 3, 3) and ``F`` (Nh+1, 3) at ``k w``, k = 0..Nh (``F`` complex per
    metre of wave amplitude, ``exp(+i w t)``); ``C`` the hull's hydrostatic stiffness (the
    whole floating mass at O; the pendulum's weight at the pivot is added here); ``Mh`` the
    hull's mass matrix without the pendulum; ``pivot = (d_p, h_p)``; ``amplitudes`` the
    wave's ``a_k``, k = 1..Kw.
    """

    omega: float
    amplitudes: np.ndarray
    winding: int
    harmonics: int
    hull_harmonics: int
    points: int
    A: np.ndarray = field(repr=False)
    B: np.ndarray = field(repr=False)
    F: np.ndarray = field(repr=False)
    C: np.ndarray = field(repr=False)
    Mh: np.ndarray = field(repr=False)
    m: float = 1.0
    l: float = 1.0  # noqa: E741  (the pendulum's length, as in the paper)
    I: float = 1.0  # noqa: E741
    c: float = 0.0
    g: float = 9.81
    pivot: tuple = (0.0, 0.0)

    def __post_init__(self):
        nh = int(self.hull_harmonics)
        for name, shape in (("A", (nh + 1, 3, 3)), ("B", (nh + 1, 3, 3)), ("F", (nh + 1, 3))):
            if np.shape(getattr(self, name)) != shape:
                raise ParameterError(f"hull: {name}: expected shape {shape}, got "
                                     f"{np.shape(getattr(self, name))}")
        if self.points < 2 * (nh + self.harmonics + self.winding) + 2:
            raise ParameterError("hull: too few grid points for the harmonics")

    @property
    def G(self) -> np.ndarray:
        d, h = self.pivot
        return np.array([[1.0, 0.0, h], [0.0, 1.0, -d]])

    def stiffness(self) -> np.ndarray:
        """``C'``: the hull's stiffness with the pendulum's weight at the pivot."""
        c = 0.5 * (np.asarray(self.C, dtype=float) + np.asarray(self.C, dtype=float).T)
        c[2, 2] -= self.m * self.g * self.pivot[1]
        return c

    def impedance(self, k: int) -> np.ndarray:
        """``Z_k`` (3 x 3 complex): the hull with the pendulum's mass lumped at the pivot."""
        wk = k * self.omega
        def sym(a):
            return (0.5 * (a + a.T))
        mass = np.asarray(self.Mh, float) + sym(np.asarray(self.A[k], float)) \
            + self.m * self.G.T @ self.G
        return -wk**2 * mass + 1j * wk * sym(np.asarray(self.B[k], float)) + self.stiffness()

    def wave_force(self) -> np.ndarray:
        """``F(k w) a_k`` (Nh+1, 3), 0 at k = 0 and above the wave's harmonics."""
        out = np.zeros((self.hull_harmonics + 1, 3), dtype=complex)
        a = np.asarray(self.amplitudes, dtype=complex)
        top = min(a.size, self.hull_harmonics)
        out[1:top + 1] = np.asarray(self.F, dtype=complex)[1:top + 1] * a[:top, None]
        return out


class HullProblem(PTOObjective):
    """Power, exact gradient and Hessian of the hull problem in the ``phi`` coefficients.

    ``coupled=False``: the hull moves as if the pendulum were not there (its free response,
    the pendulum's mass lumped at the pivot): the one-way problem.

    A real power take-off (``parapend.hydro.pto.PTOObjective``): ``eta = (eta_g,
    eta_m)`` makes the objective the electrical power ``<e(p)>`` of the generator's
    mechanical power ``p = -tau (phi' - beta')`` (its kink smoothed by ``width``),
    ``copper_loss`` ``r`` (W per (N m)^2) subtracts the winding loss ``r <tau^2>`` (holding
    an angle then costs power), and ``set_limit`` penalizes ``|tau|`` above a torque
    limit on the grid; :func:`parapend.hydro.pto.maximize` drives the continuation. Without
    them the objective is the mechanical power.
    """

    hessian = None  # dense (the drivers of :mod:`.pto` read it)

    def __init__(self, case: HullCase, coupled: bool = True, eta=None,
                 copper_loss: float = 0.0):
        self.case = case
        self.coupled = coupled
        self.set_efficiency(eta)
        self.copper_loss = float(copper_loss)
        n, nh, m = case.harmonics, case.hull_harmonics, case.points
        w, kw = case.omega, case.winding
        self.harmonics, self.points, self.winding, self.omega = n, m, kw, w
        s = 2 * math.pi * np.arange(m) / m
        self.s = s
        kn = np.arange(1, n + 1)
        # the hull's unknowns y: Xi_0 on the DOFs with stiffness, then (Re, Im) Xi_k
        cp = case.stiffness()
        self.static = [d for d in range(3) if cp[d, d] > 0]
        j0 = len(self.static)
        ny = j0 + 6 * nh
        self.ny = ny
        kh = np.arange(1, nh + 1)
        # the maps x -> (phi, phi', phi'') and y -> (p_x'', p_z'', beta') on the grid, the
        # projection of the hull's equations and their transposes, as sums over the tables
        # cos(k s_j), sin(k s_j), k = 1..max(N, Nh) (hydro/_hull_kernel.py's pivot_grid)
        kt = np.arange(1, max(n, nh) + 1)
        dp, hp = case.pivot
        self._geo = (n, nh, j0, np.array(self.static, dtype=np.int64), float(w), float(hp),
                     float(dp), np.cos(np.outer(kt, s)), np.sin(np.outer(kt, s)))
        # the uncoupled problem's absent blocks, typed as the kernel expects
        self._none2 = np.zeros((0, 0))
        self._none3 = FusedGram.empty()
        self._trig_maps(kn, kh, j0)
        # Z (real form) and the wave's force
        Z = np.zeros((ny, ny))
        Z[:j0, :j0] = cp[np.ix_(self.static, self.static)]
        fa = case.wave_force()
        rhs = np.zeros(ny)
        for k in kh:
            zk = case.impedance(int(k))
            o = j0 + 6 * (k - 1)
            Z[o:o + 3, o:o + 3] = zk.real
            Z[o:o + 3, o + 3:o + 6] = -zk.imag
            Z[o + 3:o + 6, o:o + 3] = zk.imag
            Z[o + 3:o + 6, o + 3:o + 6] = zk.real
            rhs[o:o + 3] = fa[k].real
            rhs[o + 3:o + 6] = fa[k].imag
        self.Z, self.fa_real = Z, rhs
        self.y_free = np.linalg.solve(Z, rhs)
        # Z's blocks (the static one, then one per hull harmonic), its inverse block by
        # block, and the pitch rows: the only ones of the hull matrix that move with phi
        # (hydro/_hull_kernel.py's hull_inverse)
        starts = ([0] if j0 else []) + [j0 + 6 * k for k in range(nh + 1)]
        self._blocks = np.array(starts, dtype=np.int64)
        zinv = np.zeros((ny, ny))
        for lo, hi in zip(starts[:-1], starts[1:]):
            zinv[lo:hi, lo:hi] = np.linalg.inv(Z[lo:hi, lo:hi])
        self._Zinv = zinv
        self._prow = np.flatnonzero(self._pitch_rows)
        self._Zp = np.ascontiguousarray(zinv[:, self._prow])
        # a power scale for the solvers' tolerances (W): m g l w
        self.w = np.array([case.m * case.g * case.l * w])

    def _trig_maps(self, kn, kh, j0):
        """The maps as trigonometric columns (:mod:`._trig`): the Gram matrices of the
        Hessian, the sensitivity and the hull matrix from one FFT of each weight."""
        n, w, m = self.harmonics, self.omega, self.points
        z1, o1 = np.zeros(1), np.ones(1)
        fx = np.concatenate(([0], kn, kn))
        kx = np.concatenate(([0], np.ones(n), np.zeros(n)))
        cols = {"phi": TrigColumns(fx, kx, np.concatenate((o1, np.ones(2 * n)))),
                "phi1": TrigColumns(fx, 1 - kx, np.concatenate((z1, w * kn, -w * kn))),
                "phi2": TrigColumns(fx, kx, np.concatenate((z1, -w**2 * kn**2,
                                                            -w**2 * kn**2)))}
        ny = self.ny
        freq = np.zeros(ny, dtype=np.int64)
        dof = np.zeros(ny, dtype=np.int64)
        part = np.zeros(ny, dtype=np.int64)  # 0 static, 1 real, 2 imaginary
        for i, d in enumerate(self.static):
            dof[i] = d
        for d in range(3):
            re = j0 + 6 * (kh - 1) + d
            freq[re], freq[re + 3] = kh, kh
            dof[re], dof[re + 3] = d, d
            part[re], part[re + 3] = 1, 2
        wk = w * freq
        # xi_d'' columns: Re: -(w k)^2 cos, Im: (w k)^2 sin; xi_d': Re: -w k sin, Im: -w k cos
        k2 = np.where(part == 1, 0, np.where(part == 2, 1, 0))
        s2 = np.where(part == 1, -wk**2, np.where(part == 2, wk**2, 0.0))
        k1 = np.where(part == 1, 1, 0)
        s1 = np.where(part == 0, 0.0, -wk)
        dp, hp = self.case.pivot
        on = {d: (dof == d).astype(float) for d in range(3)}
        cols["qx"] = TrigColumns(freq, k2, s2 * (on[0] + hp * on[2]))
        cols["qz"] = TrigColumns(freq, k2, s2 * (on[1] - dp * on[2]))
        cols["b1"] = TrigColumns(freq, k1, s1 * on[2])
        self._pitch_rows = dof == 2
        # the projection's rows (2/M cos, -2/M sin; 1/M for the static ones) as columns
        kp = np.where(part == 2, 1, 0)
        sp = np.where(part == 0, 1.0 / m, np.where(part == 1, 2.0 / m, -2.0 / m))
        self._cols = cols
        self._pi_cols = [TrigColumns(freq, kp, sp * on[d]) for d in range(3)]
        self._plans = {}
        self._fused_plans = {}
        self._key_cache = {}
        self._hull_gram = FusedGram([(self._plan("pi2", "qz"), 0, False),
                                     (self._plan("pi2", "qx"), 1, False)], self.points)
        # the frequencies of the reaction's weights that the hull matrix reads, and their
        # cos, sin tables (hydro/_hull_kernel.py's spectra_at)
        half = self.points // 2 + 1
        loc = np.unique(self._hull_gram.idx % (2 * half))
        self._hull_freqs = np.unique(np.where(loc < half, loc, loc - half)).astype(np.int64)
        arg = 2 * math.pi * np.outer(self._hull_freqs, np.arange(self.points)) / self.points
        self._hull_cos, self._hull_sin = np.cos(arg), np.sin(arg)
        self._last = None
        self._constants = {}

    def _plan(self, a: str, b: str) -> GramPlan:
        key = (a, b)
        if key not in self._plans:
            ca = self._pi_cols[int(a[2:])] if a.startswith("pi") else self._cols[a]
            self._plans[key] = GramPlan(ca, self._cols[b], self.points)
        return self._plans[key]

    def _fused(self, keys: tuple, coupled: bool) -> list:
        """The Hessian's blocks ``xx``, ``xy``, ``yy`` and the sensitivity's right side
        ``sens`` as :class:`FusedGram` s over the weights in the order :meth:`evaluate`
        stacks them (the pairs ``keys``, then the nine sensitivity weights), as the
        compiled gather's arguments (an absent block: an empty one)."""
        ck = (keys, coupled)
        if ck not in self._fused_plans:
            xv = ("phi", "phi1", "phi2")
            blocks = {"xx": [], "xy": [], "yy": [], "sens": []}
            for k, (u, w) in enumerate(keys):
                plan = self._plan(u, w)
                blk = "xx" if w in xv else ("xy" if u in xv else "yy")
                blocks[blk].append((plan, k, False))
                if u != w and blk != "xy":
                    blocks[blk].append((plan, k, True))
            if coupled:
                for j, (d, i) in enumerate((d, i) for d in range(3) for i in range(3)):
                    blocks["sens"].append((self._plan(f"pi{d}", xv[i]), len(keys) + j, False))
            fused = {b: FusedGram(t, self.points, symmetric=b in ("xx", "yy"))
                     for b, t in blocks.items() if t}
            self._fused_plans[ck] = [fused.get(b, self._none3).arrays() for b in blocks]
        return self._fused_plans[ck]

    # --------------------------------------------------------------------------------------
    def _at(self, x) -> tuple:
        """``(st, S^{-1})`` at ``x``: the grid state (:meth:`grid_state`) and the hull
        matrix's inverse (None when not coupled). One compiled call
        (``hydro/_hull_kernel.py``'s ``hull_state``; uncoupled, two). The last point's is
        kept: the line search's power and the next Newton step's evaluation share it."""
        x = np.asarray(x, dtype=float)
        key = x.tobytes()
        if self._last is not None and self._last[0] == key:
            return self._last[1]
        cs = self.case
        ml = cs.m * cs.l
        if self.coupled:
            f, f1, f2, sn, co, sinv, y, qx, qz, b1, tau, v, p = hull_state(
                x, self._geo, self.s, float(self.winding), ml, cs.I, cs.g,
                self._hull_freqs, self._hull_cos, self._hull_sin, *self._hull_gram.arrays(),
                self.Z, self._Zinv, self._Zp, self._prow, self._blocks, self.fa_real, cs.c)
        else:
            f, f1, f2, _, _, sn, co = grid_motion(x, self._geo, self.s, float(self.winding),
                                                  ml, cs.I, cs.g)
            sinv, y = None, self.y_free
            qx, qz, b1, tau, v, p = hull_torque(y, self._geo, sn, co, f1, f2, cs.I, cs.c, ml,
                                                cs.g)
        st = {"phi": f, "phi1": f1, "phi2": f2, "qx": qx, "qz": qz, "b1": b1, "y": y,
              "tau": tau, "relative_speed": v, "power": p, "sin_phi": sn, "cos_phi": co}
        self._last = (key, (st, sinv))
        return self._last[1]

    def solve_hull(self, x) -> np.ndarray:
        """The hull's unknowns ``y`` at ``phi(x)`` (the free response when not coupled)."""
        return self._at(x)[0]["y"]

    def grid_state(self, x) -> dict:
        """Everything on the grid at ``x``: phi and its derivatives, the hull's ``y``, the
        pivot's acceleration, the pitch rate, the torque and the power."""
        return self._at(x)[0]

    @property
    def lossless(self) -> bool:
        """The objective is the mechanical power (no efficiency, loss or limit)."""
        return self.b == 0.0 and self.a == 1.0 and self.copper_loss == 0.0 and \
            self.limit is None

    def state(self, x) -> dict:
        """The grid state with the generator's mechanical power ``p = -tau v`` per point."""
        st = dict(self.grid_state(x))
        st["p"] = -st["tau"] * st["relative_speed"]
        return st

    def mechanical(self, x) -> float:
        """``<p>``: the mechanical power on the grid."""
        return self.grid_state(x)["power"]

    def exact(self, x) -> float:
        """The objective unsmoothed and without the limit's penalty: ``a <p> + b <|p|> - r
        <tau^2>`` (the kink integrated on the piecewise-linear interpolant of ``p``)."""
        st = self.state(x)
        p = st["p"]
        val = self.a * float(np.mean(p))
        if self.b != 0.0:
            val += self.b * _abs(p)
        if self.copper_loss:
            val -= self.copper_loss * float(np.mean(st["tau"] ** 2))
        return val

    def power(self, x) -> float:
        """The objective the solvers climb: the mechanical power, or the smoothed electrical
        power less the copper loss and the limit's penalty."""
        if self.lossless:
            return self.grid_state(x)["power"]
        return float(np.mean(self._objective(self.state(x))[0]))

    def _objective(self, st):
        """The objective's pointwise value ``f(tau, v)`` and its derivatives ``(f, f_tau,
        f_v, f_tt, f_tv, f_vv)`` (None: zero) on the grid."""
        tau, v = st["tau"], st["relative_speed"]
        p = -tau * v
        if self.b == 0.0:
            a = self.a
            f, ft, fv, ftt, ftv, fvv = a * p, -a * v, -a * tau, None, -a, None
        else:
            e, e1, e2 = self._e(p)
            f, ft, fv = e, -e1 * v, -e1 * tau
            ftt, ftv, fvv = e2 * v * v, e2 * tau * v - e1, e2 * tau * tau
        r = self.copper_loss
        if r:
            f = f - r * tau * tau
            ft = ft - 2 * r * tau
            ftt = -2 * r if ftt is None else ftt - 2 * r
        if self.limit is not None:
            q0, q1, q2 = self._penalty(tau)
            f, ft = f + q0, ft + q1
            ftt = q2 if ftt is None else ftt + q2
        return f, ft, fv, ftt, ftv, fvv

    def _full(self, t) -> np.ndarray:
        """A pointwise term as an array on the grid (None: zero; a scalar: constant; the
        constant ones kept: the kernel only reads them; writeable, as a read-only array
        would compile the kernel again)."""
        if t is not None and np.ndim(t) != 0:
            return t
        v = 0.0 if t is None else float(t)
        arr = self._constants.get(v)
        if arr is None:
            if len(self._constants) > 8:
                self._constants.clear()
            arr = self._constants[v] = np.full(self.points, v)
        return arr

    # --------------------------------------------------------------------------------------
    def _keys(self, lossless: bool, coupled: bool) -> tuple:
        """The pairs of ``_VARS`` whose second-derivative weights can be non-zero (in
        ``_PAIRS["all"]``'s order), and their rows there."""
        ck = (lossless, coupled)
        if ck not in self._key_cache:
            need = set(_PAIRS["lossless" if lossless else "all"])
            xv = ("phi", "phi1", "phi2")
            if coupled:
                need |= set(_CONSTRAINT_PAIRS)
            else:
                need = {(u, w) for u, w in need if u in xv and w in xv}
            keys = tuple(p for p in _PAIRS["all"] if p in need)
            rows = np.array([_PAIRS["all"].index(p) for p in keys], dtype=np.int64)
            self._key_cache[ck] = (keys, rows)
        return self._key_cache[ck]

    def evaluate(self, x):
        """``(P, gradient, Hessian)`` of the (reduced) power in ``x``.

        The Lagrangian ``<f(tau, v)> + mu . rho`` (``mu`` the adjoint of the hull's
        equations ``S y = b``, ``S^T lambda = d<f>/dy``) has pointwise derivatives in
        ``_VARS``; the gradient maps the first ones back to ``x``, the Hessian's blocks are
        their Gram matrices (one FFT per weight), reduced by the sensitivity ``T = S^{-1}
        g_x``: ``H = L_xx + L_xy T + T^T L_yx + T^T L_yy T`` (``hydro/_hull_kernel.py``: the
        work before and after each FFT one compiled call)."""
        st, sinv = self._at(x)
        cs = self.case
        terms = self._objective(st)
        coupled = self.coupled
        keys, rows = self._keys(terms[3] is None, coupled)
        if not coupled:
            sinv = self._none2
        grad, w = gradient_and_weights(
            st["sin_phi"], st["cos_phi"], st["phi1"], st["phi2"], st["qx"], st["qz"],
            *(self._full(t) for t in terms[1:]), rows, coupled, sinv, self._geo, self.ny,
            cs.m * cs.l, cs.I, cs.c, cs.g)
        blocks = self._fused(keys, coupled)
        h = reduced_hessian(spectra(w).ravel(), *blocks, coupled, sinv)
        val = st["power"] if self.lossless else float(np.mean(terms[0]))
        return val, grad, h

    # --------------------------------------------------------------------------------------
    def harmonics_of(self, y) -> np.ndarray:
        """The hull's complex harmonics ``Xi_k`` (Nh+1, 3) from ``y``."""
        nh, j0 = self.case.hull_harmonics, len(self.static)
        xi = np.zeros((nh + 1, 3), dtype=complex)
        for i, d in enumerate(self.static):
            xi[0, d] = y[i]
        body = y[j0:].reshape(nh, 2, 3)
        xi[1:] = body[:, 0, :] + 1j * body[:, 1, :]
        return xi

    def balance(self, x) -> tuple[float, float, float]:
        """``(P, hull side, residual)`` of the energy balance
        ``P + c <(phi' - beta')^2> = sum_k Re((F a)_k^H U_k) / 2 - U_k^H B_k U_k / 2``, the
        residual relative to the larger of the wave's and the radiated power."""
        st = self.grid_state(x)
        xi = self.harmonics_of(st["y"])
        cs = self.case
        fa = cs.wave_force()
        absorbed = radiated = 0.0
        for k in range(1, cs.hull_harmonics + 1):
            u = 1j * k * cs.omega * xi[k]
            bk = 0.5 * (cs.B[k] + cs.B[k].T)
            absorbed += 0.5 * float(np.real(np.vdot(fa[k], u)))
            radiated += 0.5 * float(np.real(np.vdot(u, bk @ u)))
        lhs = st["power"] + cs.c * float(np.mean(st["relative_speed"] ** 2))
        hull = absorbed - radiated
        scale = max(abs(absorbed), abs(radiated), abs(lhs), 1e-300)
        return st["power"], hull, abs(lhs - hull) / scale
