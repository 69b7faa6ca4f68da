r"""A pendulum in a hull that surges, heaves and pitches: the objective in ``phi`` alone.

Model (SI; docs/hull.md). Hull DOFs ``xi = (x, z, beta)`` about the rotation
centre O; the pivot at ``(d_p, h_p)`` from O moves by ``p = G xi``,
``G = [[1, 0, h_p], [0, 1, -d_p]]``; ``phi`` is the pendulum's absolute angle from the
upward vertical (centre of mass at ``p + l (sin phi, cos phi)``), ``theta = phi - beta``
the generator's angle, ``phi(t + T) = phi(t) + 2 pi K``::

    (P)  I phi'' + c (phi' - beta') - m l [(g + p_z'') sin phi - p_x'' cos phi] = tau
    (H)  (M_h + A) xi'' + B xi' + C xi = F a - G^T f + e_beta (-tau + c (phi' - beta'))
         f = m (p'' + l ((sin phi)'', (cos phi)'')),     P = -<tau (phi' - beta')>

Discretization (shared with the independent IPOPT reference of
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

The optimum (:func:`hull_search`): a global search over starts, one winding at a time, and
the checks every answer carries. The one-way problem (the hull moving as if the pendulum were
not there; no linear solve per evaluation) is maximized from a set of starts (K = 0: mean
angles around hanging and away from it, phases and amplitudes of the swing; K >= 1: phase
offsets of the turn), then the coupled problem from every distinct one-way maximum and from
the same starts; the best converged maximum wins, and how many distinct maxima were found is
reported (the evidence). The answer is then solved once more with twice the harmonics (and
twice the hull's), from the answer: the change of the power is the stated discretization
error (``refinement_change_w``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from ..optimal.fourier import DISTINCT_RMS, _pad, motion_distance, newton_maximize
from ._hull_kernel import (
    gradient_and_weights,
    grid_motion,
    hull_state,
    hull_torque,
    reduced_hessian,
)
from ._trig import FusedGram, GramPlan, TrigColumns, spectra
from .pto import PTOObjective, _abs

__all__ = ["HARMONICS_PER_TURN", "HullCase", "HullPTO", "HullProblem", "HullSolution", "aliased",
           "hold_limit", "hull_points", "hull_search", "ideal_problem", "make_case",
           "radiation_bound", "waves_in"]

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
    turns = abs(winding)
    need = max(64, 8 * (harmonics + turns), 8 * (wave_harmonics + 1),
               4 * (hull_harmonics + harmonics + turns))
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
        return self._impedances(np.array([int(k)]))[0]

    def impedances(self, top: int) -> np.ndarray:
        """``Z_k`` for ``k = 1..top`` (top, 3, 3), in one pass."""
        return self._impedances(np.arange(1, top + 1))

    def _impedances(self, k) -> np.ndarray:
        wk = (k * self.omega)[:, None, None]
        a = np.asarray(self.A, float)[k]
        b = np.asarray(self.B, float)[k]
        mass = np.asarray(self.Mh, float) + 0.5 * (a + a.transpose(0, 2, 1)) \
            + self.m * self.G.T @ self.G
        return (-wk**2 * mass + 1j * wk * (0.5 * (b + b.transpose(0, 2, 1)))
                + self.stiffness())

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
        zks = case.impedances(nh)
        for k in kh:
            zk = zks[k - 1]
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


#: harmonics of phi per turn (K >= 1) or per wave (K = 0) by default
HARMONICS_PER_TURN = 12
#: the Newton iterations' gradient tolerance, relative to m g l w
GTOL = 1e-10
#: the harmonics are doubled until the power changes by at most this (relative), up to
#: MAX_SCALE times the default
REFINE_TOL = 1e-7
#: a change above this (relative) at the most harmonics allowed is not an answer
UNRESOLVED = 1e-3
MAX_SCALE = 8
#: relative change of the power at a maximum on a grid four times finer above which the
#: maximum is rejected as aliased (the grid's mean of an unresolved motion)
ALIAS_TOL = 1e-8
#: singular values of B_k below this fraction of the largest are cut in the bound's
#: pseudo-inverse (B's surge-pitch block is near singular: both radiate the same waves)
BOUND_RCOND = 1e-8
#: harmonics of phi from which the ideal problem is solved matrix-free
#: (:mod:`._hull_krylov`: time and memory near-linear in the harmonics) rather than dense
#: (its cost grows as their cube): the dense solver's regular waves stay dense up to their
#: finest refinement (96 harmonics), and from about 60 harmonics the matrix-free one is
#: the faster (benchmarks/bench_hull_record.py)
KRYLOV_HARMONICS = 100
#: ... and an efficiency's (its kink smoothed, :class:`HullPTO`) from this many: the
#: kink's curvature makes the conjugate gradients' Newton steps dear (about 300 products a
#: step), so below it the dense trust region is the faster. Measured on the default sea's
#: 4-peak-period record at efficiency 0.9, the rotation's refinement from 60 to 120
#: harmonics: 501 s matrix-free (554 Newton steps, 295711 products), 54 to 64 s dense
#: (800 trust-region steps); at 240 harmonics dense 199 s, matrix-free 352 s. An
#: efficiency's record is refused past ``limits.HULL_MAX_HARMONICS`` and refined to at most
#: ``limits.HULL_MAX_REFINED_HARMONICS``, so it is dense throughout unless the caps are
#: lifted (benchmarks/bench_hull_record.py's ``--lift-caps``)
KINK_KRYLOV_HARMONICS = 512
#: harmonics of phi from which a record's search runs on coarser discretizations first (the starts
#: on the coarsest, each finer one from the coarser answer: :func:`._hull_krylov.continued_search`)
LONG_RECORD_HARMONICS = 200


#: the matrix-free solver: ``{"problem": class, "search": function}``, registered by
#: :mod:`._hull_krylov` when it is imported (it builds on this module; hydro/result.py,
#: where answers are made, imports it). Unregistered, every problem is dense.
MATRIX_FREE: dict = {}


def ideal_problem(case: HullCase, coupled: bool = True) -> HullProblem:
    """The ideal (lossless) problem of ``case``: :class:`HullProblem`, or from
    ``KRYLOV_HARMONICS`` harmonics its matrix-free twin
    (:class:`parapend.hydro._hull_krylov.KrylovHullProblem`; the same objective, gradient
    and Hessian, the Hessian an operator)."""
    if case.harmonics >= KRYLOV_HARMONICS and MATRIX_FREE:
        return MATRIX_FREE["problem"](case, coupled=coupled)
    return HullProblem(case, coupled=coupled)


def _lossy_problem(case: HullCase, coupled: bool = True, eta=None,
                  copper_loss: float = 0.0) -> HullProblem:
    """A take-off's problem of ``case`` (an efficiency ``eta``, a ``copper_loss``; the
    torque limit is set on it by the drivers): :class:`HullProblem`, or from
    ``KRYLOV_HARMONICS`` harmonics its matrix-free twin, as :func:`ideal_problem` (the
    same objective, gradient and Hessian; its drivers line-search Newton with truncated
    conjugate gradients, :func:`parapend.hydro._hull_krylov.pto_maximize`); an
    efficiency's from ``KINK_KRYLOV_HARMONICS`` on."""
    first = KRYLOV_HARMONICS if eta is None or eta[0] * eta[1] == 1 else KINK_KRYLOV_HARMONICS
    if case.harmonics >= first and MATRIX_FREE:
        return MATRIX_FREE["problem"](case, coupled=coupled, eta=eta,
                                      copper_loss=copper_loss)
    return HullProblem(case, coupled=coupled, eta=eta, copper_loss=copper_loss)


def make_case(hull, pendulum, wave, *, winding, harmonics=None, hull_harmonics=None,
              pivot=(0.0, 0.0), pitch_inertia=None) -> HullCase:
    """The discretized problem: the hull's coefficients at ``k w`` (k = 0..Nh), its mass
    matrix without the pendulum, the wave's amplitudes."""
    n = harmonics or HARMONICS_PER_TURN * max(1, abs(winding), waves_in(wave))
    nh = hull_harmonics or n + max(1, abs(winding))
    w = wave.omega
    kk = np.arange(nh + 1) * w
    a, b, f = hull.coefficients(kk)
    mh = hull.mass_matrix(pendulum.mass, pitch_inertia)
    c = np.asarray(hull.hydrostatic_stiffness, float)
    c55 = float(c[2, 2]) - pendulum.mass * float(hull.g) * float(pivot[1])
    if not c55 > 0:
        top = float(c[2, 2]) / (pendulum.mass * float(hull.g))
        raise ParameterError(
            f"pivot-height: with the pendulum's {pendulum.mass:g} kg at {pivot[1]:g} m the "
            f"hull is unstable in pitch (C55 = {float(c[2, 2]):.4g} - m g h_p = {c55:.4g} "
            f"N m/rad <= 0); lower the pivot (below {top:.4g} m) "
            "or the pendulum's mass")
    return HullCase(omega=w, amplitudes=wave.amplitudes, winding=int(winding), harmonics=n,
                    hull_harmonics=nh, points=hull_points(n, nh, winding,
                                                          wave.amplitudes.size),
                    A=np.asarray(a, float), B=np.asarray(b, float), F=np.asarray(f, complex),
                    C=np.asarray(hull.hydrostatic_stiffness, float), Mh=mh, m=pendulum.mass,
                    l=pendulum.length, I=pendulum.inertia, c=pendulum.damping_coefficient,
                    g=float(hull.g), pivot=tuple(float(v) for v in pivot))


def waves_in(wave) -> int:
    """The wave's mean harmonic (energy-weighted): 1 for a regular wave, about the number
    of waves in a record."""
    a = np.abs(np.asarray(wave.amplitudes)) ** 2
    k = np.arange(1, a.size + 1)
    return max(1, int(round(float(np.sum(k * a) / np.sum(a)))))


def _starts(n: int, winding: int) -> list[tuple[str, np.ndarray]]:
    out = []
    if winding == 0:
        for mean in (math.pi, math.pi - 1.0, math.pi + 1.0):
            for amp in (0.5, 1.5):
                for j in range(4):
                    x = np.zeros(2 * n + 1)
                    x[0] = mean
                    ph = j * math.pi / 2
                    x[1], x[n + 1] = amp * math.cos(ph), amp * math.sin(ph)
                    out.append((f"swing-{mean:.2f}-{amp:g}-{j}", x))
    else:
        for j in range(8):
            x = np.zeros(2 * n + 1)
            x[0] = j * math.pi / 4
            out.append((f"phase-{j}", x))
    return out


@dataclass(frozen=True)
class HullPTO:
    """The power take-off of the hull problem (SI): ``efficiency`` ``(eta_g, eta_m)`` or
    None, ``copper_loss`` ``r`` of the winding loss ``r tau^2`` (W per (N m)^2), and
    ``torque_limit`` (N m) or None. Inactive (all absent): the ideal, lossless PTO."""

    efficiency: tuple | None = None
    copper_loss: float = 0.0
    torque_limit: float | None = None

    @property
    def active(self) -> bool:
        return (self.efficiency is not None and tuple(self.efficiency) != (1.0, 1.0)) or \
            self.copper_loss > 0 or self.torque_limit is not None

    @property
    def smoothed(self) -> bool:
        """The objective has the efficiency's kink (a continuation in its smoothing)."""
        return self.efficiency is not None and self.efficiency[0] * self.efficiency[1] != 1

    def problem(self, case: HullCase, coupled: bool = True) -> HullProblem:
        return _lossy_problem(case, coupled=coupled, eta=self.efficiency if self.smoothed
                             else None, copper_loss=self.copper_loss)


@dataclass(frozen=True, eq=False)
class HullSolution:
    """One winding's optimum on one discretization (SI)."""

    case: HullCase = field(repr=False)
    x: np.ndarray = field(repr=False)
    power: float
    one_way_power: float
    one_way_x: np.ndarray = field(repr=False)
    status: str
    success: bool
    found_by: str
    distinct_maxima: int
    runs: int
    iterations: int
    energy_balance_residual: float
    refinement_change: float | None = None
    #: the mechanical power ``<-tau (phi' - beta')>`` (= ``power`` for an ideal PTO)
    mechanical_power: float | None = None
    pto: HullPTO = HullPTO()
    #: the powers (W) of the distinct converged maxima the search found, best first
    maxima_powers: tuple = ()
    #: ``(harmonics, power)`` of each stage of the refinement, coarsest first
    refinement_history: tuple = ()
    #: ``(harmonics, power)`` of each level of a long record's continuation below its own
    #: harmonics (``_hull_krylov.continued_search``), coarsest first
    level_history: tuple = ()
    #: a ``screen`` of :func:`hull_search` stopped it at this (unrefined) answer
    screened: bool = False
    #: a take-off's objective that the answer maximizes (None: the ideal power's):
    #: ``(width, limit, rho, lam_hi, lam_lo)``, the efficiency's smoothing width of the
    #: climb that gave the answer, and under a limit its augmented Lagrangian's penalty and
    #: multipliers (``parapend.hydro.pto.PTOObjective.climbed_state``)
    pto_state: tuple | None = None


def aliased(problem: HullProblem, x) -> bool:
    """True when the power at ``x`` on a grid four times finer differs by more than
    ``ALIAS_TOL`` (relative): the grid's mean has become aliasing (large coefficients push
    the harmonics of ``sin(phi)`` past the grid's Nyquist frequency), not a power."""
    fine = type(problem)(dataclasses.replace(problem.case, points=4 * problem.case.points),
                         coupled=problem.coupled)
    # the mechanical power, a smooth function of the motion, also under a PTO (whose
    # kink the finer grid integrates differently: that is the refinement's business)
    p, pf = problem.mechanical(x), fine.mechanical(x)
    return not abs(p - pf) <= ALIAS_TOL * max(abs(pf), float(problem.w[0]))


def _search(problem: HullProblem, seeds, gtol: float):
    runs = []
    best = None
    for name, x0 in seeds:
        r = newton_maximize(problem, x0, name, gtol=gtol, maxiter=200,
                            abandon_below=(best.power if best is not None else -math.inf))
        if r.status == "converged" and aliased(problem, r.x):
            r = dataclasses.replace(r, status="aliased")
        runs.append(r)
        if math.isfinite(r.power) and r.status == "converged" and (
                best is None or r.power > best.power):
            best = r
    return best, runs


def _distinct(runs, best) -> int:
    return max(1, len(_maxima(runs))) if best is not None else 0


def _maxima(runs) -> tuple:
    """The powers (W) of the distinct converged maxima among ``runs`` (motions apart by more
    than ``1e3 DISTINCT_RMS``), best first."""
    seen = []
    for r in sorted(runs, key=lambda r: -r.power if math.isfinite(r.power) else math.inf):
        if r.status != "converged" or not math.isfinite(r.power):
            continue
        if all(motion_distance(r.x, s.x) > 1e3 * DISTINCT_RMS for s in seen):
            seen.append(r)
    return tuple(float(r.power) for r in seen)


def hull_search(make, *, refine: bool = True, pto: HullPTO | None = None,
                screen=None) -> HullSolution:
    """The best coupled maximum over the starts, with the one-way answer beside it.

    ``make(scale)`` returns the :class:`HullCase` with ``scale`` times the default
    harmonics (1, and 2 for the refinement). With an active ``pto`` the ideal search's
    distinct maxima start the PTO's optimum (``_pto_stage``). ``screen(sol)`` (an ideal
    take-off's): called on the converged answer before its refinement (and on a long
    record, on each level's answer of the continuation); False returns that answer
    unrefined, marked ``screened`` (the refined answer is the same as without a screen)."""
    case = make(1)
    if case.harmonics >= LONG_RECORD_HARMONICS and MATRIX_FREE:
        return MATRIX_FREE["search"](make, refine=refine, pto=pto, screen=screen)
    n, kw = case.harmonics, case.winding
    one = ideal_problem(case, coupled=False)
    starts = _starts(n, kw)
    best_one, runs_one = _search(one, starts, GTOL)
    coupled = ideal_problem(case)
    seeds = []
    if best_one is not None:
        for r in sorted((r for r in runs_one if r.status == "converged"),
                        key=lambda r: -r.power):
            if all(motion_distance(r.x, s[1]) > 1e3 * DISTINCT_RMS for s in seeds):
                seeds.append((f"one-way:{r.seed}", r.x))
    best, runs = _search(coupled, seeds + starts, GTOL)
    if best is None:
        best = max(runs, key=lambda r: r.power if math.isfinite(r.power) else -math.inf)
        status, ok = f"no start converged (best: {best.status})", False
    else:
        status, ok = "converged", True
    if pto is not None and pto.active:
        return _pto_stage(case, make, pto, runs, best_one, refine)
    _, _, resid = coupled.balance(best.x)
    sol = HullSolution(case=case, x=best.x, power=float(coupled.power(best.x)),
                       one_way_power=float(best_one.power) if best_one else math.nan,
                       one_way_x=best_one.x if best_one else starts[0][1], status=status,
                       success=ok, found_by=best.seed, distinct_maxima=_distinct(runs, best),
                       maxima_powers=_maxima(runs),
                       runs=len(runs) + len(runs_one),
                       iterations=sum(r.iterations for r in runs + runs_one),
                       energy_balance_residual=float(resid))
    if refine and ok and screen is not None and not screen(sol):
        return dataclasses.replace(sol, screened=True)
    if refine and ok:
        sol = _refine(sol, make, best.x)
    return sol


def _refine(sol: HullSolution, make, x) -> HullSolution:
    """Double the harmonics (of phi and of the hull), from the answer, until the power
    changes by at most ``REFINE_TOL`` (relative) or ``MAX_SCALE`` is reached: the finest
    answer is returned, with its change from the one before as the stated error."""
    scale, power, case = 1, sol.power, sol.case
    status, ok = sol.status, sol.success
    change = math.inf
    from ..limits import HULL_MAX_RECORD_HARMONICS, HULL_MAX_REFINED_HARMONICS

    pto = sol.pto
    x1, p1 = sol.one_way_x, sol.one_way_power
    kkt = sol.pto_state
    history = [(case.harmonics, float(power))]
    top = PTO_MAX_SCALE if pto.active else MAX_SCALE
    # a lossy take-off's problem is dense (its cost the cube of the harmonics): one doubling
    # past its cap; an ideal one's is matrix-free from KRYLOV_HARMONICS on (near-linear in
    # the harmonics), so its doublings go as far as a record's cap, and past it one more
    # while the last one leaves the answer unresolved (the 200-wave barge record at Hs 2 m,
    # Tp 6 s: 1.02e-3 at 5616 harmonics, 2e-5 at 11232)
    cap = HULL_MAX_REFINED_HARMONICS if pto.active else HULL_MAX_RECORD_HARMONICS
    h0 = sol.case.harmonics

    def another(n):
        """Whether to refine to ``n`` harmonics."""
        if n <= max(cap, 2 * h0):
            return True
        return (not pto.active and n <= 4 * h0 and math.isfinite(change)
                and change > UNRESOLVED * max(abs(power), 1e-300))

    while scale < top and another(2 * scale * h0):
        scale *= 2
        case = make(scale)
        if pto.active:
            pr = pto.problem(case)
            xr, pr_power, st, _ = _pto_maximize(pr, _pad(x, case.harmonics), pto, False,
                                                width=_width(kkt))
            kr = pr.answer
            if not math.isfinite(pr_power):
                # no motion within the limit in the budget: the coarser answer stands, its
                # resolution unchecked (not a success)
                case = make(scale // 2)
                status, ok = (f"refinement to {2 * case.harmonics} harmonics: {st}; the "
                              f"answer has {case.harmonics}, unchecked"), False
                change = math.nan
                break
            # the one-way answer follows, doubling by doubling
            x1n, p1n, _, _ = _pto_maximize(pto.problem(case, coupled=False),
                                           _pad(x1, case.harmonics), pto, False,
                                           width=_width(kkt))
            x1, p1 = (x1n, p1n) if math.isfinite(p1n) else (_pad(x1, case.harmonics),
                                                            math.nan)
        else:
            pr = ideal_problem(case)
            r = newton_maximize(pr, _pad(x, case.harmonics), "refined", gtol=GTOL)
            xr, pr_power, st, kr = r.x, r.power, r.status, None
        if st != "converged":
            status, ok = f"refinement to {case.harmonics} harmonics: {st}", False
        elif pto.active:  # the answer is the finest stage's, and so is its status
            status, ok = "converged", True
        change = abs(pr_power - power)
        x, power, kkt = xr, float(pr_power), kr
        history.append((case.harmonics, power))
        if change <= (PTO_REFINE_TOL if pto.active else REFINE_TOL) * max(abs(power),
                                                                          1e-300):
            break
    if not math.isnan(change) and change > UNRESOLVED * max(abs(power), 1e-300):
        if pto.active:  # algebraic convergence (the kink, the limit's corners): stated
            status = (f"{status}; the last doubling to {case.harmonics} harmonics changed "
                      f"the power by {change:.3g} W")
        else:
            status = (f"not resolved: {case.harmonics} harmonics still change the power by "
                      f"{change:.3g} W")
            ok = False
    pr = ideal_problem(case)  # the mechanics (a take-off's objective aside)
    _, _, resid = pr.balance(x)
    if pto.active:
        mech = float(pr.mechanical(x))
    else:
        r1 = newton_maximize(ideal_problem(case, coupled=False),
                             _pad(sol.one_way_x, case.harmonics), "one-way", gtol=GTOL)
        x1, p1, mech = r1.x, r1.power, None
    return dataclasses.replace(sol, case=case, x=x, power=power, status=status, success=ok,
                               refinement_change=None if math.isnan(change) else float(change),
                               refinement_history=tuple(history),
                               energy_balance_residual=float(resid),
                               one_way_power=float(p1), one_way_x=x1, mechanical_power=mech,
                               pto_state=kkt)


#: a torque limit is held between the grid's points to within this fraction (the overshoot
#: of the reported motion's peak torque), by at most HOLD_STEPS solves with the grid's
#: limit lowered (:func:`hold_limit`)
HOLD_TOL = 1e-4
HOLD_STEPS = 3


def hold_limit(sol: HullSolution, peak_torque=None) -> HullSolution:
    """The answer ``sol`` with its torque limit held between the grid's points.

    The limit is imposed at the grid's points; between them the torque of a limited optimum
    overshoots (0.1 to 0.2 % on the default barge), and the answer is reported on a finer
    hull, whose pendulum reaction moves the peak again. ``peak_torque(case, x)``: the peak
    torque (N m) of the motion as it is reported (None: on a grid eight times the solve's,
    on its own hull). Its overshoot ``o`` lowers the grid's limit by ``1 + o`` and the
    optimum is solved again from the answer, until ``|o| <= HOLD_TOL`` or ``HOLD_STEPS``
    solves: a fixed point (one lowering, measured on the solve's own hull, left 3e-4 of a
    1.8e-3 overshoot on the default barge's record at 60 kN m); a peak that falls short
    raises the grid's limit again, never past the limit. Its power is then the take-off's
    objective at the true limit (no penalty); the status says how far the grid's limit was
    lowered (the answer's own check then states a peak left above the limit), and its
    ``pto_state`` is the lowered limit's (the objective the answer maximizes)."""
    pto = sol.pto
    if pto.torque_limit is None or not math.isfinite(sol.power):
        return sol
    case, limit = sol.case, pto.torque_limit
    if peak_torque is None:
        fine = ideal_problem(dataclasses.replace(case, points=8 * case.points))

        def peak_torque(cs, x):
            return float(np.max(np.abs(fine.grid_state(x)["tau"])))

    def overshoot(x):
        return peak_torque(case, x) / limit - 1

    x, over, grid, steps, its = sol.x, overshoot(sol.x), limit, 0, 0
    state = sol.pto_state
    # (a lowered grid limit whose answer's peak falls short is raised again, never past
    # the limit: the power given away)
    while (over > HOLD_TOL or (over < -HOLD_TOL and grid < limit)) and steps < HOLD_STEPS:
        lower = dataclasses.replace(pto, torque_limit=min(limit, grid / (1 + over)))
        low = lower.problem(case)
        if state is not None and state[1] is not None:
            # the same grid: the last solve's penalty and multipliers start this one
            low.set_limit(lower.torque_limit, state[2], state[3], state[4])
        xr, ex, _, n = _pto_maximize(low, x, lower, False, width=_width(state),
                                     same_grid=True)
        its += n
        if not math.isfinite(ex):
            break
        x, grid, steps, state = xr, lower.torque_limit, steps + 1, low.answer
        over = overshoot(x)
    if steps == 0:
        return sol
    mech = ideal_problem(case)
    return dataclasses.replace(
        sol, x=x, power=float(pto.problem(case).exact(x)),
        status=(f"{sol.status}; the grid's limit lowered by {limit / grid - 1:.2g} to hold "
                f"the limit between its points ({steps} solve{'s' if steps > 1 else ''})"),
        iterations=sol.iterations + its, energy_balance_residual=float(mech.balance(x)[2]),
        mechanical_power=float(mech.mechanical(x)), pto_state=state)


#: distinct ideal maxima that start the PTO's optimum
PTO_STARTS = 4
#: change of the exact objective over the continuation's last two widths, relative to the
#: larger of it and the pendulum's power scale ``m g l w``, below which it counts as settled
#: (the kink's last widths move it by the grid's resolution of the kink; the refinement
#: states the error)
PTO_SETTLED = 1e-5
#: with a PTO the harmonics are doubled until the objective changes by at most this
#: (relative): the kink of the electrical power and the limit's active arcs make the
#: convergence algebraic, not spectral
PTO_REFINE_TOL = 1e-4
#: ... up to this many times the default harmonics (each doubling of a torque-limited solve
#: costs about four times the one before); a larger last change is stated in the status
PTO_MAX_SCALE = 4


#: Newton iterations of a matrix-free least-torque start (:func:`_free_motion`) at most: on
#: the barge's 10-wave record (144 harmonics, the rotation's 12 turns) none of the four
#: starts converged in 200 (9 to 13 s each: the least-torque rotations are many and flat),
#: and from them the limited optima at 60 kN m were 1296 to 1406 W (30 steps: 1195 to 1384 W,
#: 0.4 to 0.7 s each) against the search's 1480 W from an ideal maximum; at 30 kN m the
#: climbs from either crawled (100 to 170 s each) to 1225 to 1350 W
FREE_MAX_NEWTON = 30


def _free_motion(case: HullCase, winding: int, coupled: bool = True):
    """The motion of least mean squared torque (``max -<tau^2>`` from the pendulum hanging,
    or from each quarter-turn phase of the turn): the free pendulum's periodic motion where
    one exists. It satisfies any torque limit it meets and costs no copper loss, so it
    starts the PTO's optimum where the ideal maxima, with their large torques, are far from
    what the limit or the loss allows."""
    pr = _lossy_problem(case, coupled=coupled, copper_loss=1.0)
    pr.a = 0.0  # the objective is -<tau^2> alone
    maximize = _maximizer(pr)
    out = []
    for name, x0 in _starts(case.harmonics, winding)[:: 6 if winding == 0 else 2]:
        if winding == 0:
            x0 = np.zeros_like(x0)
            x0[0] = math.pi
            name = "hanging"
        if pr.hessian == "operator":  # a start: a few Newton steps (FREE_MAX_NEWTON)
            r = newton_maximize(pr, x0, "least-torque", gtol=GTOL, maxiter=FREE_MAX_NEWTON,
                                saddle=False)
            x, ex = r.x, r.power
        else:
            x, ex, _ = maximize(pr, x0, (1.0,))
        if math.isfinite(ex):
            out.append((f"least-torque:{name}", x))
        if winding == 0:
            break
    return out


#: Newton iterations per width of a torque-limited solve from one start: from an ideal
#: maximum far above the limit the augmented Lagrangian crawls (thousands of iterations,
#: tens of seconds), while the least-torque start reaches the same optimum in a few hundred
PTO_MAX_INNER = 400
#: ... and per width of a refinement stage (from the coarser optimum: the new grid points
#: start outside the limit, and the multipliers start from zero)
PTO_MAX_INNER_REFINE = 1000


def _maximizer(pr: HullProblem):
    """The take-off's continuation driver for ``pr``: :func:`parapend.hydro.pto.maximize`
    (trust-exact) for a dense problem, the matrix-free one's
    (:func:`parapend.hydro._hull_krylov.pto_maximize`, the same signature) for an
    operator."""
    if pr.hessian == "operator" and "maximize" in MATRIX_FREE:
        return MATRIX_FREE["maximize"]
    from .pto import maximize

    return maximize


def _pto_maximize(pr: HullProblem, x, pto: HullPTO, first: bool, widths=None,
                  scale=None, width=None, start=None, same_grid=False):
    """The PTO's optimum from ``x``: the smoothing continuation (an efficiency) under the
    torque limit (:func:`parapend.hydro.pto.maximize`). Returns ``(x, exact, status,
    iterations)``. ``widths``: these widths (relative to ``scale``, the matrix-free
    driver's, or to the largest ``|p|`` at ``x``) instead of the continuation's; a screening
    (:func:`_screened`) when they end above the last one: "converged" then when the last
    width's climb converged.

    Matrix-free, an efficiency's continuation stops once settled from ``PTO_SETTLE_WIDTH``
    of the largest ``|p|`` on (:func:`settled`), and ``width``
    (W; a refinement's, a finer level's or a held limit's start: the smoothing width of the
    answer ``x`` continues, its ``pto_state``) starts it there: ``WIDTHS_WARM`` relative to
    it (from the answer's width itself on the answer's grid, ``same_grid``), stopping once
    settled from the answer's width on (the dense driver: ``WIDTHS_REFINE`` whole). ``start``: the
    exact objective of ``x`` at the width before ``widths`` (a screened start's). Settled
    ("converged"): the kept iterate's exact objective within ``PTO_SETTLED`` of its
    neighbouring width's (or ``start``)."""
    from .pto import WIDTHS, WIDTHS_REFINE

    screening = widths is not None and widths[-1] > WIDTHS[-1]
    free = pr.hessian == "operator" and "maximize" in MATRIX_FREE
    kw = {}
    if free and pto.smoothed:
        if widths is None and width is not None and width > 0:
            # the widths above the answer's are the path (LEVEL_GTOL)
            widths, scale, kw["settle"] = WIDTHS_WARM, width, width * (1 + 1e-9)
            if same_grid:
                widths = WIDTHS_WARM[WIDTHS_WARM.index(1.0):]
        else:
            p0 = scale if scale is not None else float(np.max(np.abs(
                pr.state(np.asarray(x, dtype=float))["p"])))
            kw["settle"] = PTO_SETTLE_WIDTH * p0
        kw["start"] = start
    if widths is None and pto.smoothed and not (first or free or same_grid):
        # a dense refinement: the continuation's ladder from 1e-2 of the largest |p|, and
        # its stop once settled (as the matrix-free one's)
        widths = WIDTHS[WIDTHS.index(REFINE_WIDTH):]
        kw["settle"] = (PTO_SETTLE_WIDTH, lambda before, after: settled(before, after, pr))
    if widths is None:
        widths = (WIDTHS if first else WIDTHS_REFINE) if pto.smoothed else (1.0,)
    if scale is not None:
        kw["scale"] = scale
    x, ex, log = _maximizer(pr)(pr, np.asarray(x, dtype=float), widths, pto.torque_limit,
                                max_inner=PTO_MAX_INNER if first else PTO_MAX_INNER_REFINE,
                                **kw)
    its = sum(r[3] for r in log)
    if not math.isfinite(ex):
        return x, ex, "no motion within the torque limit", its
    if screening:
        ok = log[-1][2] == "converged"
    elif pto.smoothed:
        ok = _settled_at(log, ex, start, max(abs(ex), float(pr.w[0])))
    elif pto.torque_limit is None:
        # a copper loss alone: smooth; trust-exact's "stalled" at a maximum is its precision
        ok = log[-1][2] == "converged" or float(np.max(np.abs(pr.evaluate(x)[1]))) <= \
            1e-8 * float(pr.w[0])
    else:
        ok = log[-1][2] == "converged"
    return x, ex, "converged" if ok else f"stalled ({log[-1][2]})", its


def settled(before: float, after: float, problem) -> bool:
    """Whether an efficiency's continuation stops after a width whose exact objective is
    ``after``, the width before's ``before``: it moved by at most ``PTO_SETTLED`` of the
    larger of it and ``m g l w`` (the settled check), or it fell (the smaller widths sample
    the kink on the grid's points, which the exact power integrates between them: on the
    barge's 10-wave record both modes' exact powers peak at 3e-5 of the largest ``|p|`` and
    fall after, 499.078, 499.072, 499.045 W swinging at 3e-5, 1e-5, 1e-6, the last two
    widths half the continuation's time)."""
    size = max(abs(after), float(problem.w[0]))
    return after < before or abs(after - before) <= PTO_SETTLED * size


def _width(state) -> float | None:
    """The smoothing width (W) of a take-off's ``pto_state`` (None: none)."""
    return None if state is None else state[0]


def _settled_at(log, ex, start, size) -> bool:
    """Whether the kept exact objective ``ex`` (the last width's of ``log`` that has it) is
    within ``PTO_SETTLED * size`` of a neighbouring width's (the one before, the one
    after, or ``start`` before the first)."""
    vals = ([] if start is None else [start]) + [r[1] for r in log]
    j = max(i for i, v in enumerate(vals) if v == ex) if ex in vals else -1
    near = [vals[i] for i in (j - 1, j + 1) if 0 <= i < len(vals) and j >= 0]
    return any(math.isfinite(v) and abs(v - ex) <= PTO_SETTLED * size for v in near)


#: a matrix-free efficiency's continuation stops once settled from this width on (relative
#: to the largest ``|p|`` at its start: the screening's last, ``WIDTHS[PTO_SCREEN - 1]``),
#: those widths climbed to ``GTOL`` (the ones above are the path)
PTO_SETTLE_WIDTH = 1e-4
#: a dense efficiency's refinement (the doubled harmonics, from the coarser answer) climbs
#: the continuation's widths from this one (relative to the largest ``|p|``; factors of
#: about 3) and stops once settled from ``PTO_SETTLE_WIDTH`` on. Measured on the default
#: sea's 4-peak-period record at efficiency 0.9 (the rotation, 60 to 120 harmonics): from
#: 1e-2 33 s, 365 trust-region steps, 173.5552 W; from 1e-1 42 s, 364 steps, 173.5565 W;
#: the four widths 1e-3 to 1e-6 (factors of 10) 54 s, 800 steps (every width stopped at
#: its 200), 172.9581 W; at 240 harmonics from 1e-2 152 s, 175.2390 W, against 199 s,
#: 175.2334 W
REFINE_WIDTH = 1e-2
#: the widths of a matrix-free efficiency's continuation that starts from an answer
#: (a refinement, a finer level, a held limit), relative to that answer's width: it stops
#: once settled. From ten times the answer's width: the doubled harmonics move the optimum
#: (the barge's 10-wave rotation: 378.2 W at 144 harmonics, its padded motion 372.7 W at
#: 288, the maximum there above 405 W), and climbed at the answer's own width that climb
#: crawled (over 4 minutes of CPU), at ten times it 25 s; ``WIDTHS_REFINE``'s four,
#: relative to the padded answer's own largest ``|p|`` (30 times smaller than the ideal
#: optimum's there), ended at 1e-6 of it, 30 times below the coarse answer's width
WIDTHS_WARM = (10.0, 3.0, 1.0, 1.0 / 3.0, 0.1, 1.0 / 30.0)


#: a matrix-free efficiency's search screens its starts: each start's continuation runs
#: over the widths down to ``WIDTHS[PTO_SCREEN - 1]`` (1e-4 of the largest ``|p|``), and only
#: the best start's (and the best one-way start's) goes on over the last ones, whose climbs
#: cost the most (the 10-wave barge record from the ideal optimum: 6.7 s of 59 s down to
#: 1e-4, the last width alone 41 s)
PTO_SCREEN = 7


def _screened(pr: HullProblem, pto: HullPTO) -> tuple:
    """``(screening widths, last widths)`` of a matrix-free efficiency's search
    (:data:`PTO_SCREEN`); ``()`` for a dense problem or without an efficiency (each start's
    continuation whole)."""
    from .pto import WIDTHS

    if not (pto.smoothed and pr.hessian == "operator" and "maximize" in MATRIX_FREE):
        return ()
    return WIDTHS[:PTO_SCREEN], WIDTHS[PTO_SCREEN:]


def _finish_screened(pr: HullProblem, pto: HullPTO, x, scale: float, widths, start=None):
    """A screened start's continuation over the last ``widths`` from its screened iterate
    ``x``, the widths relative to the screening's ``scale`` (W; the largest ``|p|`` over
    the search's starts: as the whole continuation's); ``start``: the screened iterate's
    exact objective. Returns :func:`_pto_maximize`'s tuple."""
    return _pto_maximize(pr, x, pto, True, widths, scale, start=start)


def _pto_stage(case, make, pto: HullPTO, runs, best_one, refine: bool) -> HullSolution:
    """The PTO's optimum (efficiency, copper loss, torque limit) from the ideal search's
    distinct converged maxima (at most ``PTO_STARTS``, best first), then its refinement."""
    seeds = []
    for r in sorted((r for r in runs if math.isfinite(r.power) and r.status in (
            "converged", "max_iterations", "stalled")), key=lambda r: -r.power):
        if all(motion_distance(r.x, s[1]) > 1e3 * DISTINCT_RMS for s in seeds):
            seeds.append((r.seed, r.x))
        if len(seeds) == PTO_STARTS:
            break
    seeds += _free_motion(case, case.winding)
    pr = pto.problem(case)
    screen = _screened(pr, pto)
    # the screening's widths relative to one |p| for every start (a least-torque motion's
    # own is small: its widths then the kink's dearest, 67 s on the barge's 10-wave
    # rotation for a start 960 W below the best)
    scale = max((float(np.max(np.abs(pr.state(x0)["p"]))) for _, x0 in seeds),
                default=None) if screen else None
    best, tried, its = None, [], 0
    for name, x0 in seeds:
        x, ex, status, it = _pto_maximize(pr, x0, pto, True, *screen[:1], scale=scale)
        kkt = pr.answer
        its += it
        if status == "converged" and aliased(pr, x):
            status = "aliased"
        tried.append((ex, status))
        # every iterate is a motion whose power is evaluated exactly: the largest wins, and
        # its status says whether its continuation settled
        if math.isfinite(ex) and (best is None or ex > best[1] + (
                1e-9 * max(abs(ex), float(pr.w[0])) if best[2] == "converged" else 0.0)):
            best = (x, ex, status, name, x0, kkt)
    one_pr = pto.problem(case, coupled=False)
    one = None
    for x1 in ([best_one.x] if best_one is not None else []) + [
            x for _, x in _free_motion(case, case.winding, coupled=False)]:
        r = _pto_maximize(one_pr, x1, pto, True, *screen[:1], scale=scale)
        its += r[3]
        if one is None or (math.isfinite(r[1]) and not r[1] <= one[1]):
            one = r
    if screen and best is not None:  # the screening's best, on to the last widths
        x, ex, status, it = _finish_screened(pr, pto, best[0], scale, screen[1],
                                             start=best[1])
        its += it
        if math.isfinite(ex):
            best = (x, ex, status, best[3], best[4], pr.answer)
    if screen and one is not None and math.isfinite(one[1]):
        r = _finish_screened(one_pr, pto, one[0], scale, screen[1], start=one[1])
        its += r[3]
        if math.isfinite(r[1]):
            one = r
    if best is None:
        x = seeds[0][1] if seeds else np.zeros(2 * case.harmonics + 1)
        return HullSolution(case=case, x=x, power=math.nan, one_way_power=math.nan,
                            one_way_x=x, status="no motion found for this power take-off",
                            success=False, found_by="", distinct_maxima=0, runs=len(tried),
                            iterations=its, energy_balance_residual=math.nan, pto=pto)
    x, ex, status, name = best[:4]
    ok = status == "converged"
    distinct = len({round(e, 9) for e, st in tried if st == "converged"})
    sol = HullSolution(case=case, x=x, power=float(ex),
                       one_way_power=float(one[1]) if one else math.nan,
                       one_way_x=one[0] if one else x, status=status, success=ok,
                       found_by=name, distinct_maxima=max(distinct, 1),
                       maxima_powers=tuple(sorted({round(e, 9) for e, st in tried
                                                   if st == "converged"}, reverse=True)),
                       runs=len(tried) + 1, iterations=its,
                       energy_balance_residual=float(ideal_problem(case).balance(x)[2]),
                       mechanical_power=float(pr.mechanical(x)), pto=pto,
                       pto_state=best[5])
    if refine:  # a stalled continuation may settle with more harmonics: the status says
        sol = _refine(sol, make, x)
    return sol


def radiation_bound(case: HullCase, rcond: float = BOUND_RCOND) -> tuple[float, int]:
    """``sum_k (F a)_k^H B_k^+ (F a)_k / 8`` (W) and the number of singular values cut
    (below ``rcond`` of the largest, per harmonic): no mechanism inside the hull absorbs
    more. ``rcond``: at least ``BOUND_RCOND``; the data's noise
    (:attr:`parapend.hydro.bem.HullHydro.damping_noise`): a direction of ``B`` whose damping
    is within the noise is not resolved, and its ``1 / sigma`` would be the noise's."""
    rcond = max(float(rcond), BOUND_RCOND)
    fa = case.wave_force()
    total, cut = 0.0, 0
    for k in range(1, case.hull_harmonics + 1):
        if not np.any(fa[k]):
            continue
        b = 0.5 * (case.B[k] + case.B[k].T)
        sv = np.linalg.svd(b, compute_uv=False)
        if sv[0] <= 0:
            continue
        cut += int(np.sum(sv < rcond * sv[0]))
        binv = np.linalg.pinv(b, rcond=rcond)
        total += float(np.real(np.vdot(fa[k], binv @ fa[k]))) / 8.0
    return total, cut


def bound_error(case: HullCase, noise: float) -> float:
    """The radiation bound's error from the noise of ``B`` (W), to first order: each kept
    direction's term ``|u_i^H (F a)_k|^2 / (8 sigma_i)`` changes by the factor
    ``delta / sigma_i`` when its ``sigma_i`` moves by ``delta = noise sigma_max`` (the
    noise relative to the largest, :attr:`parapend.hydro.bem.HullHydro.damping_noise`),
    capped at the term itself; the directions cut add nothing. Not the mesh's error: the
    noise a BEM's asymmetry shows is a lower estimate of it (docs/hull.md)."""
    rcond = max(float(noise), BOUND_RCOND)
    fa = case.wave_force()
    err = 0.0
    for k in range(1, case.hull_harmonics + 1):
        if not np.any(fa[k]):
            continue
        b = 0.5 * (case.B[k] + case.B[k].T)
        lam, vec = np.linalg.eigh(b)
        top = float(np.max(np.abs(lam)))
        if top <= 0:
            continue
        keep = lam >= rcond * top
        proj = np.abs(vec.conj().T @ fa[k]) ** 2
        terms = proj[keep] / lam[keep] / 8.0
        err += float(np.sum(terms * np.minimum(1.0, noise * top / lam[keep])))
    return err
